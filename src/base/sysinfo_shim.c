/* Process information for module sysinfo: peak resident memory from getrusage. */
#include <sys/resource.h>

#include "sysinfo_shim.h"

double rc_peak_rss_mb(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0.0;
    return (double) ru.ru_maxrss / 1024.0;   /* ru_maxrss is in KiB on Linux */
}
