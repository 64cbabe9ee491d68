/* Process information for module sysinfo: peak resident memory from getrusage, and the
 * memory limit a run must fit in. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "sysinfo_shim.h"

double rc_peak_rss_mb(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0.0;
    return (double) ru.ru_maxrss / 1024.0;   /* ru_maxrss is in KiB on Linux */
}

/* The smallest memory limit [MiB] of this process's cgroup and its ancestors, 0 if none:
 * cgroup v2 (`0::/path`, files memory.max) or v1 (the `memory` controller's path, files
 * memory.limit_in_bytes). A batch scheduler's --mem is such a limit. */
/* True if the comma-separated controller list [a, end) holds exactly `name`. */
static int controller_is(const char *a, const char *end, const char *name)
{
    size_t n = strlen(name);
    while (a < end) {
        const char *c = memchr(a, ',', (size_t) (end - a));
        const char *e = c != NULL ? c : end;
        if ((size_t) (e - a) == n && strncmp(a, name, n) == 0) return 1;
        a = e + 1;
    }
    return 0;
}

static double cgroup_limit_mb(void)
{
    char line[1024], path[1200], file[1400];
    const char *root = NULL, *name = NULL;
    double lim = 0.0;
    FILE *f = fopen("/proc/self/cgroup", "r");
    if (f == NULL) return 0.0;
    path[0] = '\0';
    while (fgets(line, sizeof line, f) != NULL) {
        char *p = strchr(line, ':'), *q;
        if (p == NULL || (q = strchr(p + 1, ':')) == NULL) continue;
        q[strcspn(q, "\n")] = '\0';
        if (strncmp(line, "0::", 3) == 0 && root == NULL) {            /* v2 (unless v1 memory found) */
            snprintf(path, sizeof path, "%s", q + 1);
            root = "/sys/fs/cgroup"; name = "memory.max";
        } else if (controller_is(p + 1, q, "memory")) {                 /* v1 memory */
            snprintf(path, sizeof path, "%s", q + 1);
            root = "/sys/fs/cgroup/memory"; name = "memory.limit_in_bytes";
        }
    }
    fclose(f);
    if (root == NULL) return 0.0;
    for (;;) {   /* this cgroup, then each ancestor */
        FILE *g;
        snprintf(file, sizeof file, "%s%s/%s", root, strcmp(path, "/") == 0 ? "" : path, name);
        g = fopen(file, "r");
        if (g != NULL) {
            unsigned long long b;
            if (fgets(line, sizeof line, g) != NULL && sscanf(line, "%llu", &b) == 1 && b < (1ULL << 60)) {
                double v = (double) b / 1048576.0;
                if (lim == 0.0 || v < lim) lim = v;
            }
            fclose(g);
        }
        if (strcmp(path, "/") == 0 || path[0] == '\0') break;
        char *slash = strrchr(path, '/');
        if (slash == NULL) break;
        if (slash == path) strcpy(path, "/"); else *slash = '\0';
    }
    return lim;
}

/* Memory this process may use [MiB], 0 if none is known. which = RC_LIMIT_ALL: the
 * smallest of the memory the kernel reports as available (MemAvailable), the cgroup limit
 * (v1 or v2, this cgroup and its ancestors) and the address-space rlimit (ulimit -v);
 * RC_LIMIT_NODE: the first two only (shared by the processes of a node or a job's cgroup);
 * RC_LIMIT_PROCESS: the rlimit only (each process's own). */
double rc_memory_limit_mb(int which)
{
    double lim = 0.0, v;
    char line[256];
    struct rlimit rl;
    if (which != RC_LIMIT_PROCESS) {
        FILE *f = fopen("/proc/meminfo", "r");
        if (f != NULL) {
            unsigned long long kb;
            while (fgets(line, sizeof line, f) != NULL)
                if (sscanf(line, "MemAvailable: %llu kB", &kb) == 1) { lim = (double) kb / 1024.0; break; }
            fclose(f);
        }
        v = cgroup_limit_mb();
        if (v > 0.0 && (lim == 0.0 || v < lim)) lim = v;
    }
    if (which != RC_LIMIT_NODE && getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
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
