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
 * in double-double arithmetic (about 106 bits, relative error of order 1e-31: 10^k from a table
 * and at most two products), so that round(y) is the 17-digit integer
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

/* 10^(16 a), a = 0..19, in double-double (hi the double nearest, lo the double nearest the
 * rest; both exact to 2^-106 relative), and 10^b, b = 0..15 (exact doubles): 10^k is then one
 * product, 10^(16 (k / 16)) 10^(k mod 16), instead of the up to ten of binary powering.
 * Generated with Python's fractions: float(10**n) and float(10**n - hi) are correctly rounded. */
static const dd_t pow10_16[20] = {
    {0x1.0000000000000p+0, 0x0.0p+0},                     /* 1e0 */
    {0x1.1c37937e08000p+53, 0x0.0p+0},                    /* 1e16 */
    {0x1.3b8b5b5056e17p+106, -0x1.3107f00000000p+52},     /* 1e32 */
    {0x1.5e531a0a1c873p+159, -0x1.14b4c7a76a406p+105},    /* 1e48 */
    {0x1.84f03e93ff9f5p+212, -0x1.2ac340948e389p+157},    /* 1e64 */
    {0x1.afcef51f0fb5fp+265, -0x1.08f322e84da10p+204},    /* 1e80 */
    {0x1.df67562d8b363p+318, -0x1.ae9d180b58861p+264},    /* 1e96 */
    {0x1.0a1f5b8132466p+372, 0x1.4f01f167b5e30p+318},     /* 1e112 */
    {0x1.27748f9301d32p+425, -0x1.901cc86649e4ap+371},    /* 1e128 */
    {0x1.4805738b51a75p+478, -0x1.18a0e9df9363ap+423},    /* 1e144 */
    {0x1.6c2d4256ffcc3p+531, -0x1.56a2119e533adp+474},    /* 1e160 */
    {0x1.945145230b378p+584, -0x1.b20a11c22bf0cp+527},    /* 1e176 */
    {0x1.c0e1ef1a724ebp+637, -0x1.4abd220ed605cp+583},    /* 1e192 */
    {0x1.f25c186a6f04cp+690, 0x1.45a7709a56ccep+635},     /* 1e208 */
    {0x1.14a52dffc6799p+744, 0x1.2f82bd6b70d9ap+689},     /* 1e224 */
    {0x1.33234de7ad7e3p+797, -0x1.34a66b24bc3ebp+741},    /* 1e240 */
    {0x1.54fdd7f73bf3cp+850, -0x1.7222446fe4670p+795},    /* 1e256 */
    {0x1.7a93a2954f3b8p+903, -0x1.beda693cdd93bp+849},    /* 1e272 */
    {0x1.a44df832b8d46p+956, -0x1.ce31f3444e400p+899},    /* 1e288 */
    {0x1.d2a1be4048f90p+1009, 0x1.fea3e35c17799p+955},    /* 1e304 */
};
static const double pow10_1[16] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7,
                                   1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};

/* 10^k, 0 <= k <= 306 (relative error below 2^-104). */
static dd_t dd_pow10(int k)
{
    dd_t big = pow10_16[k >> 4];
    double small = pow10_1[k & 15];
    if (big.hi == 1.0)
        return (dd_t){small, 0.0};
    return dd_mul(big, (dd_t){small, 0.0});
}

#define DD_MARGIN 1.0e-6 /* distance from a half-integer the fast path needs (its error: < 1e-12) */

/* The 17-digit mantissa m (10^16 <= m < 10^17) and exponent e of a = |x| (finite, 1e-290 <=
 * a <= 1e290) with a = m 10^(e - 16) correctly rounded; 0 when the fast path cannot decide. */
static int digits17(double a, long long *m, int *e)
{
    /* floor(log10 a), or one less, from the binary exponent without libm's log10 (a quarter
     * of a value's cost): with a = f 2^e2, 1/2 <= f < 1, the chord 2 f - 1 of log2(2 f) on
     * [1, 2) is below it by at most 0.086, so the estimate is low by less than 0.03 of a
     * decade; a low exponent is put right by the loop's first check, as log10's rounding was */
    int e2;
    double f = frexp(a, &e2);
    int ex = (int)floor(((double)(e2 - 1) + (2.0 * f - 1.0)) * 0.30102999566398120);
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

/* The 17 decimal digits of m (10^16 <= m < 10^17) into dig[0..16]: two digits a division by
 * 100 of a 32-bit half (a 64-bit division by 10 a digit was a third of a value's cost). */
static void put_digits17(long long m, char *dig)
{
    static const char pairs[201] =
                                "0001020304050607080910111213141516171819"
                                "2021222324252627282930313233343536373839"
                                "4041424344454647484950515253545556575859"
                                "6061626364656667686970717273747576777879"
                                "8081828384858687888990919293949596979899";
    unsigned hi = (unsigned)(m / 100000000LL); /* the first 9 digits */
    unsigned lo = (unsigned)(m % 100000000LL); /* the last 8 */
    for (int i = 16; i > 8; i -= 2) {
        unsigned q = lo % 100;
        lo /= 100;
        dig[i - 1] = pairs[2 * q];
        dig[i] = pairs[2 * q + 1];
    }
    for (int i = 8; i > 0; i -= 2) {
        unsigned q = hi % 100;
        hi /= 100;
        dig[i - 1] = pairs[2 * q];
        dig[i] = pairs[2 * q + 1];
    }
    dig[0] = (char)('0' + hi);
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
    } else if (a == 0.0) { /* what snprintf gives, widened; zeros are common in a history */
        text = signbit(x) ? "-0.0000000000000000E+000" : "0.0000000000000000E+000";
    } else if (a >= 1.0e-290 && a <= 1.0e290 && digits17(a, &m, &e)) {
        /* "-d.dddddddddddddddE+eee" or " d.dddddddddddddddE+eee": the 24 characters, written
         * in place (no justification pass) */
        char *p = out;
        char dig[17];
        put_digits17(m, dig);
        *p++ = x < 0 ? '-' : ' ';
        *p++ = dig[0];
        *p++ = '.';
        memcpy(p, dig + 1, 16);
        p += 16;
        *p++ = 'E';
        *p++ = e < 0 ? '-' : '+';
        e = e < 0 ? -e : e;
        *p++ = (char)('0' + e / 100);
        *p++ = (char)('0' + (e / 10) % 10);
        *p = (char)('0' + e % 10);
        return;
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
