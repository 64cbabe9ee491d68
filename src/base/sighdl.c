/* Signal handling for batch schedulers: SIGTERM, SIGINT and SIGUSR1 set a flag that the program
 * polls (the outer iteration, the phase boundaries, the monolithic solver); the run then
 * writes what it can save (checkpoint, result flagged "interrupted") and exits with code
 * 4. Only async-signal-safe work in the handler. SIGUSR1 is there for OpenMPI's mpirun,
 * which forwards SIGUSR1 and SIGUSR2 to its ranks but answers SIGTERM by killing them
 * (SIGTERM, then SIGKILL a second later): `kill -USR1 <mpirun>` is the checkpoint request
 * of an MPI run (doc/batch.md, "MPI and MUMPS").
 *
 * METIS (GKlib, bundled in Debian's libmetis) installs its own SIGTERM handler with
 * signal() around every ordering and restores ours afterwards: a SIGTERM from the
 * scheduler during an ordering then longjmp'ed out of METIS ("invalid input") or, when
 * it reached another thread, crashed the process. METIS uses that handler only for its
 * own raise(SIGTERM) on internal errors. So signal() calls for SIGTERM and SIGINT are
 * intercepted here (GKlib calls __sysv_signal, which the executable defines and the
 * dynamic linker binds first): the library's handler is remembered per thread and not
 * installed; our handler forwards a signal the thread raised itself (SI_TKILL from this
 * process) to it, and treats every other one (kill, scancel, Ctrl-C) as a stop request. */
#define _GNU_SOURCE
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include "sighdl.h"

typedef void (*rc_sighandler_t)(int);

static volatile sig_atomic_t rc_stop_flag = 0;
static volatile sig_atomic_t rc_stop_signal = 0;
static volatile sig_atomic_t rc_installed = 0;

/* A library's handler for SIGTERM [0] and SIGINT [1] on this thread, not installed. */
static __thread rc_sighandler_t rc_library_handler[2];

/* Returned to a library as "the previous handler" and recognised when it restores it. */
static void rc_previous(int sig) { (void)sig; }

static int slot(int sig) { return sig == SIGTERM ? 0 : 1; }

static void rc_handler(int sig, siginfo_t *si, void *ctx)
{
    rc_sighandler_t h = (sig == SIGTERM || sig == SIGINT) ? rc_library_handler[slot(sig)] : NULL;
    (void)ctx;
    if (h != NULL && h != SIG_DFL && h != SIG_IGN && si != NULL && si->si_code == SI_TKILL
        && si->si_pid == getpid()) {
        h(sig);   /* the library's own raise(): its error path */
        return;
    }
    rc_stop_flag = 1;
    rc_stop_signal = sig;
}

int rc_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_sigaction = rc_handler;
    sigemptyset(&sa.sa_mask);
    /* SA_NODEFER: a library handler reached from ours may longjmp out of it; the signal
     * must not stay blocked in that thread afterwards (the stop request would be lost) */
    sa.sa_flags = SA_RESTART | SA_SIGINFO | SA_NODEFER;
    if (sigaction(SIGTERM, &sa, NULL) != 0) return -1;
    if (sigaction(SIGINT, &sa, NULL) != 0) return -1;
    if (sigaction(SIGUSR1, &sa, NULL) != 0) return -1;
    rc_installed = 1;
    return 0;
}

int rc_signals_pending(void)
{
    return rc_stop_flag ? (int)rc_stop_signal : 0;
}

/* glibc's signal() with System V semantics, as libraries linked against it call it. */
rc_sighandler_t __sysv_signal(int sig, rc_sighandler_t handler)
{
    struct sigaction sa, old;
    if (rc_installed && (sig == SIGTERM || sig == SIGINT)) {
        rc_sighandler_t prev = rc_library_handler[slot(sig)];
        rc_library_handler[slot(sig)] = (handler == rc_previous) ? NULL : handler;
        return prev != NULL ? prev : rc_previous;
    }
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = handler;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND | SA_NODEFER;
    if (sigaction(sig, &sa, &old) != 0) return SIG_ERR;
    return old.sa_handler;
}
