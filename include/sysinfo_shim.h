/* Process information for robin_contact (see src/base/sysinfo_shim.c). */
#ifndef RC_SYSINFO_SHIM_H
#define RC_SYSINFO_SHIM_H
/* Peak resident set size of this process so far [MiB]; 0 if unavailable. */
double rc_peak_rss_mb(void);
/* Memory this process may use [MiB] (MemAvailable, cgroup memory.max, ulimit -v); 0 if unknown. */
double rc_memory_limit_mb(void);
/* Write n bytes to standard output (write(2)); 0 on success, else errno. */
int rc_stdout_write(const char *buf, int n);
#endif
