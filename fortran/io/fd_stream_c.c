/* What the history stream (fd_history_stream.f90) needs from C besides fd_fileops.c: rows
 * formatted without the heap.
 *
 * gfortran's internal WRITE allocates on every call (it parses the format each time: five
 * allocations a row), and the time-step loop allocates nothing; its formatted file writes
 * lose a full disk. snprintf("%.16E") gives the same correctly rounded digits that gfortran's
 * ES24.16E3 edit descriptor prints (libgfortran formats with snprintf too); the exponent is
 * widened to three digits and the field right-justified to 24 characters, so that a row here
 * is byte for byte the row `write (buf, '(n(es24.16e3,:,","))') x` would give. No state:
 * every function works on its arguments only (the library's rule). The file itself is written
 * with fd_fileops.c's POSIX calls (every error seen). */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* The row x[0..n-1] as "v,v,...,v\n" (25 n bytes) into buf; *nbytes: the bytes written
 * (a subroutine, not a function, so that Fortran can declare it pure). */
void fd_format_row(const double *x, int n, char *buf, long *nbytes)
{
    for (int i = 0; i < n; i++) {
        format_es24(x[i], buf + 25 * (long)i);
        buf[25 * (long)i + 24] = (i + 1 < n) ? ',' : '\n';
    }
    *nbytes = 25 * (long)n;
}
