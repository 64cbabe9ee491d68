/* File-system calls of module files that Fortran cannot make portably: open(2) is
   variadic, struct stat has no fixed layout. */
#define _DEFAULT_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "files_shim.h"

int rc_run_token(char *buf, int n)
{
    char host[256] = "host";
    if (n < 1) return 0;
    if (gethostname(host, sizeof host) != 0) snprintf(host, sizeof host, "host");
    host[sizeof host - 1] = '\0';
    for (char *c = host; *c; c++) {
        int ok = (*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') ||
                 *c == '_' || *c == '-';
        if (!ok) *c = '_';
    }
    int len = snprintf(buf, (size_t) n, "%.64s.%ld", host, (long) getpid());
    return len < n ? len : n - 1;
}

int rc_lock_dir(const char *dir)
{
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) return -1;
    while (flock(fd, LOCK_EX) != 0) {
        if (errno != EINTR) {
            close(fd);
            return -1;
        }
    }
    return fd;
}

void rc_unlock_dir(int fd)
{
    if (fd >= 0) close(fd);
}

int rc_path_kind(const char *path)
{
    struct stat s;
    if (lstat(path, &s) != 0) return errno == ENOENT ? 0 : -1;
    if (S_ISREG(s.st_mode) || S_ISLNK(s.st_mode)) return 1;
    if (S_ISDIR(s.st_mode)) return 2;
    return 3;
}

int rc_file_kind(const char *path)
{
    struct stat s;
    if (stat(path, &s) != 0) return errno == ENOENT ? 0 : -1;
    if (S_ISREG(s.st_mode)) return 1;
    if (S_ISDIR(s.st_mode)) return 2;
    return 3;
}

long rc_name_max(const char *dir)
{
    errno = 0;
    long n = pathconf(dir, _PC_NAME_MAX);
    return n > 0 ? n : -1;
}

int rc_dir_writable(const char *dir)
{
    return access(dir, W_OK | X_OK) == 0;
}

/* The descriptor, or minus the errno value of the failure. */
int rc_open_data(const char *path)
{
    int fd;
    do {
        fd = open(path, O_WRONLY | O_CLOEXEC);
    } while (fd < 0 && errno == EINTR);
    if (fd < 0) return errno > 0 ? -errno : -EIO;
    return fd;
}

int rc_write_at(int fd, const void *buf, long long n, long long offset)
{
    const char *p = buf;
    while (n > 0) {
        ssize_t k = pwrite(fd, p, (size_t) n, (off_t) offset);
        if (k < 0) {
            if (errno == EINTR) continue;
            return errno > 0 ? errno : -1;
        }
        if (k == 0) return ENOSPC;
        p += k;
        n -= k;
        offset += k;
    }
    return 0;
}

int rc_close_data(int fd)
{
    if (fd < 0) return 0;
    return close(fd) == 0 ? 0 : (errno > 0 ? errno : -1);
}

/* The system's text of errno value e (strerror_r: the bodies' tasks may fail at once). */
int rc_error_text(int e, char *buf, int n)
{
    char text[160];
    if (n < 1) return 0;
#if (_POSIX_C_SOURCE >= 200112L) && !_GNU_SOURCE
    const char *t = strerror_r(e, text, sizeof text) == 0 ? text : "unknown error";
#else
    const char *t = strerror_r(e, text, sizeof text);   /* the GNU form returns the text */
#endif
    int len = snprintf(buf, (size_t) n, "%s", t);
    return len < n ? len : n - 1;
}
