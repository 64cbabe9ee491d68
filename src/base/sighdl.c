/* Signal handling for batch schedulers: SIGTERM and SIGINT set a flag that the outer
 * iteration polls; the run then writes a checkpoint and its result flagged
 * "interrupted" and exits with code 4. Only async-signal-safe work in the handler. */
#include <signal.h>
#include <string.h>

#include "sighdl.h"

static volatile sig_atomic_t rc_stop_flag = 0;
static volatile sig_atomic_t rc_stop_signal = 0;

static void rc_handler(int sig)
{
    rc_stop_flag = 1;
    rc_stop_signal = sig;
}

int rc_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = rc_handler;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    if (sigaction(SIGTERM, &sa, NULL) != 0) return -1;
    if (sigaction(SIGINT, &sa, NULL) != 0) return -1;
    return 0;
}

int rc_signals_pending(void)
{
    return rc_stop_flag ? (int)rc_stop_signal : 0;
}
