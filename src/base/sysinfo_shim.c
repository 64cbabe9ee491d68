/* Process information for module sysinfo: peak resident memory from getrusage, and the
 * memory limit a run must fit in. */
#include <errno.h>
#include <stdio.h>
#include <sys/resource.h>
#include <unistd.h>

#include "sysinfo_shim.h"

double rc_peak_rss_mb(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0.0;
    return (double) ru.ru_maxrss / 1024.0;   /* ru_maxrss is in KiB on Linux */
}

/* Memory this process may use [MiB]: the smallest of the memory the kernel reports as
 * available (MemAvailable), the cgroup v2 limit (memory.max) and the address-space
 * rlimit (ulimit -v); 0 if none can be read. */
double rc_memory_limit_mb(void)
{
    double lim = 0.0, v;
    char line[256];
    struct rlimit rl;
    FILE *f = fopen("/proc/meminfo", "r");
    if (f != NULL) {
        unsigned long long kb;
        while (fgets(line, sizeof line, f) != NULL)
            if (sscanf(line, "MemAvailable: %llu kB", &kb) == 1) { lim = (double) kb / 1024.0; break; }
        fclose(f);
    }
    f = fopen("/sys/fs/cgroup/memory.max", "r");
    if (f != NULL) {
        unsigned long long b;
        if (fgets(line, sizeof line, f) != NULL && sscanf(line, "%llu", &b) == 1) {
            v = (double) b / 1048576.0;
            if (lim == 0.0 || v < lim) lim = v;
        }
        fclose(f);
    }
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
        v = (double) rl.rlim_cur / 1048576.0;
        if (lim == 0.0 || v < lim) lim = v;
    }
    return lim;
}

/* Write n bytes to standard output with write(2), retrying short writes; 0 on success,
 * else errno. (gfortran's unit 6 does not report write errors, e.g. on /dev/full.) */
int rc_stdout_write(const char *buf, int n)
{
    while (n > 0) {
        ssize_t k = write(1, buf, (size_t) n);
        if (k < 0) {
            if (errno == EINTR) continue;
            return errno != 0 ? errno : EIO;
        }
        buf += k;
        n -= (int) k;
    }
    return 0;
}
