/* Signal handling for robin_contact (see src/base/sighdl.c). */
#ifndef RC_SIGHDL_H
#define RC_SIGHDL_H
/* Install handlers for SIGTERM, SIGINT and SIGUSR1; 0 on success. */
int rc_signals_install(void);
/* The signal number received (SIGTERM, SIGINT or SIGUSR1), or 0 if none. */
int rc_signals_pending(void);
#endif
