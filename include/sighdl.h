/* Signal handling for robin_contact (see src/base/sighdl.c). */
#ifndef RC_SIGHDL_H
#define RC_SIGHDL_H
/* Install handlers for SIGTERM and SIGINT; 0 on success. */
int rc_signals_install(void);
/* The signal number received (SIGTERM or SIGINT), or 0 if none. */
int rc_signals_pending(void);
#endif
