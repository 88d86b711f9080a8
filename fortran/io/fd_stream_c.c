/* What the history stream (fd_history_stream.f90) needs from C besides fd_fileops.c: rows
 * formatted without the heap.
 *
 * gfortran's internal WRITE allocates on every call (it parses the format each time: five
 * allocations a row), and the time-step loop allocates nothing; its formatted file writes
 * lose a full disk. The digits are the correctly rounded ones that gfortran's ES24.16E3 edit
 * descriptor prints (libgfortran formats with snprintf("%.16E")): from double-double
 * arithmetic where that decides them, else from snprintf itself (below); the exponent has
 * three digits and the field is right-justified to 24 characters, so that a row here is byte
 * for byte the row `write (buf, '(n(es24.16e3,:,","))') x` would give. No state:
 * every function works on its arguments only (the library's rule). The file itself is written
 * with fd_fileops.c's POSIX calls (every error seen). */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- The fast path: the 17 significant digits from double-double arithmetic.
 *
 * glibc's "%.16E" is exact because it works in multiple precision (about 5000 instructions a
 * value, more than a whole Newmark step of a small model). Here y = |x| 10^(16 - E) is formed
 * in double-double arithmetic (about 106 bits, relative error of order 1e-30 after the at most
 * ten products of the binary powering of 10^k), so that round(y) is the 17-digit integer
 * mantissa whenever y is farther than DD_MARGIN from a half-integer; otherwise, and for 0,
 * NaN, infinities and |x| outside [1e-290, 1e290] (where 10^(16 - E) would leave the range
 * of doubles), format_es24 takes the exact path, snprintf. An exact tie cannot occur: a
 * double is never halfway between two 17-digit decimals (the halfway point would need more
 * than 53 bits).
 * tests/unit/test_fd_stream.f90 compares both paths with gfortran's own ES24.16E3 writes. */
typedef struct {
    double hi, lo;
} dd_t;

static dd_t quick_two_sum(double a, double b)
{
    double s = a + b;
    return (dd_t){s, b - (s - a)};
}

static dd_t two_prod(double a, double b)
{
    double p = a * b;
    return (dd_t){p, fma(a, b, -p)}; /* fma: the rounding error of a b, exactly */
}

static dd_t dd_mul(dd_t x, dd_t y)
{
    dd_t p = two_prod(x.hi, y.hi);
    return quick_two_sum(p.hi, p.lo + (x.hi * y.lo + x.lo * y.hi));
}

/* a / b for a double a and a double-double b. */
static dd_t dd_div(double a, dd_t b)
{
    double q1 = a / b.hi;
    dd_t p = dd_mul((dd_t){q1, 0.0}, b);
    double r = ((a - p.hi) - p.lo);
    return quick_two_sum(q1, r / b.hi);
}

/* 10^k, 0 <= k <= 306, by binary powering from 10^(2^i) (exact up to 10^16 in one double). */
static dd_t dd_pow10(int k)
{
    dd_t r = {1.0, 0.0}, b = {10.0, 0.0};
    while (k > 0) {
        if (k & 1)
            r = dd_mul(r, b);
        k >>= 1;
        if (k > 0)
            b = dd_mul(b, b);
    }
    return r;
}

#define DD_MARGIN 1.0e-6 /* distance from a half-integer the fast path needs (its error: < 1e-12) */

/* The 17-digit mantissa m (10^16 <= m < 10^17) and exponent e of a = |x| (finite, 1e-290 <=
 * a <= 1e290) with a = m 10^(e - 16) correctly rounded; 0 when the fast path cannot decide. */
static int digits17(double a, long long *m, int *e)
{
    int ex = (int)floor(log10(a));
    for (int attempt = 0; attempt < 3; attempt++) {
        int k = 16 - ex;
        dd_t y = k >= 0 ? dd_mul((dd_t){a, 0.0}, dd_pow10(k)) : dd_div(a, dd_pow10(-k));
        if (y.hi < 9.5e15) { /* log10 rounded up: one exponent lower */
            ex--;
            continue;
        }
        if (y.hi > 1.05e17) {
            ex++;
            continue;
        }
        /* y.hi >= 2^53 is an integer and |y.lo| <= 8: floor(y) and the fraction, exactly */
        double fl = floor(y.lo);
        double frac = y.lo - fl;
        long long n = (long long)y.hi + (long long)fl;
        if (n < 10000000000000000LL) { /* y below 10^16: the exponent is one lower */
            ex--;
            continue;
        }
        if (n >= 100000000000000000LL) {
            ex++;
            continue;
        }
        if (fabs(frac - 0.5) < DD_MARGIN)
            return 0;
        if (frac > 0.5)
            n++;
        if (n == 100000000000000000LL) { /* rounded up to 10^17: 1.0...0 E(ex + 1) */
            n /= 10;
            ex++;
        }
        *m = n;
        *e = ex;
        return 1;
    }
    return 0;
}

/* One value as ES24.16E3 into out[0..23]. */
static void format_es24(double x, char *out)
{
    char tmp[40], full[64];
    const char *text = full;
    size_t len;
    double a = fabs(x);
    long long m;
    int e;
    if (isnan(x)) { /* first: an ordered comparison with a NaN raises FE_INVALID */
        text = "NaN";
    } else if (isinf(x)) {
        text = x > 0 ? "Infinity" : "-Infinity";
    } else if (a >= 1.0e-290 && a <= 1.0e290 && digits17(a, &m, &e)) {
        /* "-d.dddddddddddddddE+eee", right-justified */
        char *p = full;
        char dig[17];
        for (int i = 16; i >= 0; i--) {
            dig[i] = (char)('0' + m % 10);
            m /= 10;
        }
        if (x < 0)
            *p++ = '-';
        *p++ = dig[0];
        *p++ = '.';
        memcpy(p, dig + 1, 16);
        p += 16;
        *p++ = 'E';
        *p++ = e < 0 ? '-' : '+';
        e = e < 0 ? -e : e;
        *p++ = (char)('0' + e / 100);
        *p++ = (char)('0' + (e / 10) % 10);
        *p++ = (char)('0' + e % 10);
        *p = '\0';
    } else {
        /* the exact path: "-d.dddddddddddddddddE-xx" as printed, exponent widened to 3 digits */
        snprintf(tmp, sizeof tmp, "%.16E", x);
        char *ep = strchr(tmp, 'E');
        int ex = atoi(ep + 1);
        *ep = '\0';
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
