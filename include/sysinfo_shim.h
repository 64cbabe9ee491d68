/* Process information for robin_contact (see src/base/sysinfo_shim.c). */
#ifndef RC_SYSINFO_SHIM_H
#define RC_SYSINFO_SHIM_H
/* Peak resident set size of this process so far [MiB]; 0 if unavailable. */
double rc_peak_rss_mb(void);
/* Memory this process may use [MiB]; 0 if unknown. which: RC_LIMIT_ALL (MemAvailable,
 * cgroup memory.max, ulimit -v), RC_LIMIT_NODE (the first two), RC_LIMIT_PROCESS (ulimit -v). */
enum { RC_LIMIT_ALL = 0, RC_LIMIT_NODE = 1, RC_LIMIT_PROCESS = 2 };
double rc_memory_limit_mb(int which);
/* Write n bytes to standard output (write(2)); 0 on success, else errno. */
int rc_stdout_write(const char *buf, int n);
#endif
