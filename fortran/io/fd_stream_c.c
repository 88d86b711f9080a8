/* What the history stream (fd_history_stream.f90) needs from C: rows formatted without the
 * heap, and a file written with POSIX calls.
 *
 * gfortran's internal WRITE allocates on every call (it parses the format each time: five
 * allocations a row), and the time-step loop allocates nothing; its formatted file writes
 * lose a full disk. snprintf("%.16E") gives the same correctly rounded digits that gfortran's
 * ES24.16E3 edit descriptor prints (libgfortran formats with snprintf too); the exponent is
 * widened to three digits and the field right-justified to 24 characters, so that a row here
 * is byte for byte the row `write (buf, '(n(es24.16e3,:,","))') x` would give. No state:
 * every function works on its arguments only (the library's rule). */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* One value as ES24.16E3 into out[0..23]. */
static void format_es24(double x, char *out)
{
    char tmp[40], full[64];
    const char *text = full;
    size_t len;
    if (isnan(x)) {
        text = "NaN";
    } else if (isinf(x)) {
        text = x > 0 ? "Infinity" : "-Infinity";
    } else {
        /* "-d.dddddddddddddddddE-xx": mantissa as printed, exponent widened to 3 digits */
        snprintf(tmp, sizeof tmp, "%.16E", x);
        char *e = strchr(tmp, 'E');
        int ex = atoi(e + 1);
        *e = '\0';
        snprintf(full, sizeof full, "%sE%c%03d", tmp, ex < 0 ? '-' : '+', ex < 0 ? -ex : ex);
    }
    len = strlen(text);
    if (len > 24) {
        memset(out, '*', 24);
        return;
    }
    memset(out, ' ', 24 - len);
    memcpy(out + 24 - len, text, len);
}

/* The row x[0..n-1] as "v,v,...,v\n" (25 n bytes) into buf; returns the bytes written. */
long fd_format_row(const double *x, int n, char *buf)
{
    for (int i = 0; i < n; i++) {
        format_es24(x[i], buf + 25 * (long)i);
        buf[25 * (long)i + 24] = (i + 1 < n) ? ',' : '\n';
    }
    return 25 * (long)n;
}

/* Create a new file for writing (O_EXCL: EEXIST when the name exists); *fd on success.
 * Returns 0 or errno. */
int fd_stream_create(const char *path, int *fd)
{
    int f = open(path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (f < 0)
        return errno;
    *fd = f;
    return 0;
}

/* Write len bytes; 0 or errno (ENOSPC, EDQUOT, EIO, ...). */
int fd_stream_write(int fd, const char *buf, long len)
{
    while (len > 0) {
        ssize_t n = write(fd, buf, (size_t)len);
        if (n < 0) {
            if (errno == EINTR)
                continue;
            return errno;
        }
        buf += n;
        len -= n;
    }
    return 0;
}

/* fsync (a full disk or quota on NFS shows here at the latest) and close: 0 or errno. */
int fd_stream_close(int fd)
{
    int e = 0;
    if (fsync(fd) != 0 && errno != EINVAL && errno != EROFS)
        e = errno;
    if (close(fd) != 0 && e == 0)
        e = errno;
    return e;
}

/* unlink(path): 0 or errno. */
int fd_stream_unlink(const char *path)
{
    return unlink(path) == 0 ? 0 : errno;
}

/* rename(from, to): 0 or errno. */
int fd_stream_rename(const char *from, const char *to)
{
    return rename(from, to) == 0 ? 0 : errno;
}

/* The text of errno err into buf (NUL-terminated, at most len bytes). */
void fd_stream_errno_text(int err, char *buf, int len)
{
    char tmp[256];
    const char *m = strerror_r(err, tmp, sizeof tmp);
    snprintf(buf, (size_t)len, "%s", m);
}
