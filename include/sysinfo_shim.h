/* Process information for robin_contact (see src/base/sysinfo_shim.c). */
#ifndef RC_SYSINFO_SHIM_H
#define RC_SYSINFO_SHIM_H
/* Peak resident set size of this process so far [MiB]; 0 if unavailable. */
double rc_peak_rss_mb(void);
#endif
