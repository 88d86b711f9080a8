/* What the history stream (fd_history_stream.f90) needs from C besides fd_fileops.c: rows
 * formatted without the heap.
 *
 * gfortran's internal WRITE allocates on every call (it parses the format each time: five
 * allocations a row), and the time-step loop allocates nothing; its formatted file writes
 * lose a full disk. The digits are the correctly rounded ones that gfortran's ES24.16E3 edit
 * descriptor prints (libgfortran formats with snprintf("%.16E")): from 64-bit integer
 * arithmetic where that decides them, else from snprintf itself (below); the exponent has
 * three digits and the field is right-justified to 24 characters, so that a row here is byte
 * for byte the row `write (buf, '(n(es24.16e3,:,","))') x` would give. No state:
 * every function works on its arguments only (the library's rule). The file itself is written
 * with fd_fileops.c's POSIX calls (every error seen). */
#define _GNU_SOURCE
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- The fast path: the 17 significant digits from 64-bit integer arithmetic.
 *
 * glibc's "%.16E" is exact because it works in multiple precision (about 5000 instructions a
 * value, more than a whole Newmark step of a small model). Here y = |x| 10^(16 - E) is formed
 * as a fixed-point number of 128 bits from |x|'s 53-bit significand and a 128-bit 10^k (relative
 * error below 2^-123, absolute below 2^-65 for y < 2^58), so that round(y) is the 17-digit
 * integer mantissa whenever y is farther than FRAC_MARGIN from a half-integer; otherwise, and
 * for 0, NaN and infinities, format_es24 takes the exact path, snprintf. Exact ties do occur
 * (1 + 2^-17 = 1.00000762939453125 is halfway between two 17-digit decimals; only for |x| from
 * about 1e-8 to 1e16, where y is computed exactly): they are within the margin, and snprintf
 * rounds them half to even. Integers only: no libm call and no floating-point rounding to
 * reason about (the double-double arithmetic this replaces called frexp and fma, and its
 * exactness rested on fma being fused), and no range limit: subnormals and the largest
 * doubles take the fast path too.
 * tests/unit/test_fd_stream.f90 compares both paths with gfortran's own ES24.16E3 writes. */

/* hi:lo = a b, the full 128-bit product. */
static void mul_64x64(uint64_t a, uint64_t b, uint64_t *hi, uint64_t *lo)
{
#ifdef __SIZEOF_INT128__ /* GCC and Clang on 64-bit targets: one multiply instruction */
    __extension__ typedef unsigned __int128 u128;
    u128 p = (u128)a * b;
    *hi = (uint64_t)(p >> 64);
    *lo = (uint64_t)p;
#else /* schoolbook on 32-bit halves */
    uint64_t a0 = a & 0xffffffffu, a1 = a >> 32, b0 = b & 0xffffffffu, b1 = b >> 32;
    uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    uint64_t mid = (p00 >> 32) + (p01 & 0xffffffffu) + (p10 & 0xffffffffu);
    *hi = p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
    *lo = (mid << 32) | (p00 & 0xffffffffu);
#endif
}

/* 10^j = s 2^e for j = 0..27, s = 5^j shifted to [2^63, 2^64): exact, since 5^27 < 2^63. */
typedef struct {
    uint64_t s;
    int e;
} pow10_small_t;
static const pow10_small_t pow10_small[28] = {
    {0x8000000000000000ULL, -63}, {0xa000000000000000ULL, -60}, /* 1e0, 1e1 */
    {0xc800000000000000ULL, -57}, {0xfa00000000000000ULL, -54}, /* 1e2, 1e3 */
    {0x9c40000000000000ULL, -50}, {0xc350000000000000ULL, -47}, /* 1e4, 1e5 */
    {0xf424000000000000ULL, -44}, {0x9896800000000000ULL, -40}, /* 1e6, 1e7 */
    {0xbebc200000000000ULL, -37}, {0xee6b280000000000ULL, -34}, /* 1e8, 1e9 */
    {0x9502f90000000000ULL, -30}, {0xba43b74000000000ULL, -27}, /* 1e10, 1e11 */
    {0xe8d4a51000000000ULL, -24}, {0x9184e72a00000000ULL, -20}, /* 1e12, 1e13 */
    {0xb5e620f480000000ULL, -17}, {0xe35fa931a0000000ULL, -14}, /* 1e14, 1e15 */
    {0x8e1bc9bf04000000ULL, -10}, {0xb1a2bc2ec5000000ULL, -7},  /* 1e16, 1e17 */
    {0xde0b6b3a76400000ULL, -4},  {0x8ac7230489e80000ULL, 0},   /* 1e18, 1e19 */
    {0xad78ebc5ac620000ULL, 3},   {0xd8d726b7177a8000ULL, 6},   /* 1e20, 1e21 */
    {0x878678326eac9000ULL, 10},  {0xa968163f0a57b400ULL, 13},  /* 1e22, 1e23 */
    {0xd3c21bcecceda100ULL, 16},  {0x84595161401484a0ULL, 20},  /* 1e24, 1e25 */
    {0xa56fa5b99019a5c8ULL, 23},  {0xcecb8f27f4200f3aULL, 26},  /* 1e26, 1e27 */
};

/* 10^(28 i) = (hi 2^64 + lo) 2^e for i = -11..12 (index i + 11), the 128-bit significand in
 * [2^127, 2^128) rounded to nearest (relative error below 2^-128): with pow10_small, 10^k for
 * every k from -308 to 363 is one more product, 10^(28 i) 10^j with k = 28 i + j.
 * Generated with Python's fractions (exact rationals), as were pow10_small's entries. */
typedef struct {
    uint64_t hi, lo;
    int e;
} pow10_big_t;
static const pow10_big_t pow10_big[24] = {
    {0xe61acf033d1a45dfULL, 0x6fb92487298e33beULL, -1151}, /* 1e-308 */
    {0xe858ad248f5c22c9ULL, 0xd1b3400f8f9cff69ULL, -1058}, /* 1e-280 */
    {0xea9c227723ee8bcbULL, 0x465e15a979c1cadcULL, -965},  /* 1e-252 */
    {0xece53cec4a314ebdULL, 0xa4f8bf5635246428ULL, -872},  /* 1e-224 */
    {0xef340a98172aace4ULL, 0x86fb897116c87c35ULL, -779},  /* 1e-196 */
    {0xf18899b1bc3f8ca1ULL, 0xdc44e6c3cb279ac2ULL, -686},  /* 1e-168 */
    {0xf3e2f893dec3f126ULL, 0x5a89dba3c3efccfbULL, -593},  /* 1e-140 */
    {0xf64335bcf065d37dULL, 0x4d4617b5ff4a16d6ULL, -500},  /* 1e-112 */
    {0xf8a95fcf88747d94ULL, 0x75a44c6397ce912aULL, -407},  /* 1e-84 */
    {0xfb158592be068d2eULL, 0xeed6e2f0f0d56713ULL, -314},  /* 1e-56 */
    {0xfd87b5f28300ca0dULL, 0x8bca9d6e188853fcULL, -221},  /* 1e-28 */
    {0x8000000000000000ULL, 0x0000000000000000ULL, -127},  /* 1e0 */
    {0x813f3978f8940984ULL, 0x4000000000000000ULL, -34},   /* 1e28 */
    {0x82818f1281ed449fULL, 0xbff8f10e7a8921a4ULL, 59},    /* 1e56 */
    {0x83c7088e1aab65dbULL, 0x792667c6da79e0faULL, 152},   /* 1e84 */
    {0x850fadc09923329eULL, 0x03e2cf6bc604ddb0ULL, 245},   /* 1e112 */
    {0x865b86925b9bc5c2ULL, 0x0b8a2392ba45a9b2ULL, 338},   /* 1e140 */
    {0x87aa9aff79042286ULL, 0x90fb44d2f05d0843ULL, 431},   /* 1e168 */
    {0x88fcf317f22241e2ULL, 0x441fece3bdf81f03ULL, 524},   /* 1e196 */
    {0x8a5296ffe33cc92fULL, 0x82bd6b70d99aaa70ULL, 617},   /* 1e224 */
    {0x8bab8eefb6409c1aULL, 0x1ad089b6c2f7548eULL, 710},   /* 1e252 */
    {0x8d07e33455637eb2ULL, 0xdb0b487b6423e1e8ULL, 803},   /* 1e280 */
    {0x8e679c2f5e44ff8fULL, 0x570f09eaa7ea7648ULL, 896},   /* 1e308 */
    {0x8fcac257558ee4e6ULL, 0x213a4f0aa5e8a7b2ULL, 989},   /* 1e336 */
};

/* The distance from a half-integer the fast path needs, in units of 2^-64 of y: 2^-32, far
 * above the error of y (below 2^-65), far below any distance a random value comes near. */
#define FRAC_MARGIN (1ULL << 32)
#define HALF (1ULL << 63)

/* The 17-digit mantissa m (10^16 <= m < 10^17) and exponent e of a = |x| (finite, nonzero)
 * with a = m 10^(e - 16) correctly rounded; 0 when the fast path cannot decide. */
static int digits17(double a, uint64_t *m, int *e)
{
    /* a = M 2^(e2 - 63), M in [2^63, 2^64): the significand normalized, so that e2 =
     * floor(log2 a) for subnormals too */
    uint64_t bits;
    memcpy(&bits, &a, sizeof bits);
    int bexp = (int)(bits >> 52) & 0x7ff;
    uint64_t M = bits & ((1ULL << 52) - 1);
    int e2;
    if (bexp != 0) { /* normal: a = (M + 2^52) 2^(bexp - 1075) */
        M = (M | (1ULL << 52)) << 11;
        e2 = bexp - 1023;
    } else { /* subnormal: a = M 2^-1074, M < 2^52 */
        e2 = -1074 + 63;
        while (!(M >> 63)) {
            M <<= 1;
            e2--;
        }
    }
    /* ex = floor(log10 2^e2), so 10^ex <= a < 2^(e2 + 1) < 2 10^(ex + 1) and y = a 10^(16 - ex)
     * lies in [10^16, 2 10^17): 78913 / 2^18 is log10(2) closely enough for every e2 of a
     * double (checked against exact rationals); the offset of 400 keeps the shift's operand
     * nonnegative, so that it floors */
    int ex = ((e2 * 78913 + (400 << 18)) >> 18) - 400;
    for (int attempt = 0; attempt < 2; attempt++) {
        /* y = a 10^k = (M s) B 2^(e2 - 63 + es + eb), k = 28 i + j (i = floor(k / 28):
         * k + 308 >= 0 for every k here, and 308 = 11 28) */
        int k = 16 - ex;
        const pow10_small_t *sm = &pow10_small[(k + 308) % 28];
        const pow10_big_t *bg = &pow10_big[(k + 308) / 28];
        uint64_t xh, xl; /* X = M s exactly, in [2^126, 2^128) */
        mul_64x64(M, sm->s, &xh, &xl);
        /* y = Z 2^-t, t = 64 + sh = -(65 + e2 + es + eb): 69..77 for every double (checked
         * for every e2); Z = floor(X B / 2^128) to within 3 (the three low partial products
         * dropped), in [2^125, 2^128), 2^-123 relative with B's rounding, or, for B = 2^127
         * (k = 0..27: |x| from about 1e-11 to 1e17, most of a history's values), X / 2 exactly: X
         * itself with one bit more of fraction */
        int sh = -(65 + e2 + sm->e + bg->e) - 64;
        uint64_t zh, zl;
        if (k >= 0 && k < 28) {
            zh = xh;
            zl = xl;
            sh++;
        } else {
            uint64_t ph, pl, q1, q2, junk;
            mul_64x64(xh, bg->hi, &ph, &pl);
            mul_64x64(xh, bg->lo, &q1, &junk);
            mul_64x64(xl, bg->hi, &q2, &junk);
            zl = pl + q1;
            zh = ph + (zl < q1);
            zl += q2;
            zh += (zl < q2);
        }
        /* the integer n = Z >> t and the first 64 bits frac of the fraction */
        uint64_t n = zh >> sh;
        uint64_t frac = (zh << (64 - sh)) | (zl >> sh);
        if (n >= 100000000000000000ULL) { /* y >= 10^17: a decade boundary lies in [2^e2,
                                           * 2^(e2 + 1)) and a is above it */
            ex++;
            continue;
        }
        if (frac - (HALF - FRAC_MARGIN) < 2 * FRAC_MARGIN) /* |frac - 1/2| < the margin */
            return 0;
        n += frac >> 63; /* rounded to nearest */
        if (n < 10000000000000000ULL) /* cannot happen (y >= 10^16 less its error) */
            return 0;
        if (n == 100000000000000000ULL) { /* rounded up to 10^17: 1.0...0 E(ex + 1) */
            n /= 10;
            ex++;
        }
        *m = n;
        *e = ex;
        return 1;
    }
    return 0;
}

/* Digit pairs: pairs[2 q], pairs[2 q + 1] are q's two digits, q = 0..99. */
static const char pairs[201] = "0001020304050607080910111213141516171819"
                               "2021222324252627282930313233343536373839"
                               "4041424344454647484950515253545556575859"
                               "6061626364656667686970717273747576777879"
                               "8081828384858687888990919293949596979899";

/* The 8 decimal digits of v < 10^8 into out[0..7], two at a time without a division: t is
 * v / 10^6 in fixed point with 32 fraction bits, t = floor(v ceil(2^48 / 10^6) / 2^16) + 1,
 * above v / 10^6 by at least 2^-32 and by less than 444 2^-32 (v 0.29 / 2^16 + 1 units); its
 * integer part is the first pair, and each multiplication of the fraction by 100 brings the next
 * pair into the integer part, the error growing to below 444 10^6 2^-32 < 0.11 at the last
 * pair, which is exact (an integer), and below the distance 10^-2n to the next integer of the
 * earlier ones: every pair comes out right (checked for every v < 10^8), with a multiplication,
 * a shift and a table look-up each (a division by 100 and a remainder each before). */
static void put_digits8(uint32_t v, char *out)
{
    uint64_t t = (((uint64_t)v * 281474977u) >> 16) + 1;
    memcpy(out, pairs + 2 * (t >> 32), 2);
    t = (t & 0xffffffffu) * 100;
    memcpy(out + 2, pairs + 2 * (t >> 32), 2);
    t = (t & 0xffffffffu) * 100;
    memcpy(out + 4, pairs + 2 * (t >> 32), 2);
    t = (t & 0xffffffffu) * 100;
    memcpy(out + 6, pairs + 2 * (t >> 32), 2);
}

/* One value as ES24.16E3 into out[0..23]. */
static void format_es24(double x, char *out)
{
    char tmp[40], full[64];
    const char *text = full;
    size_t len;
    double a = fabs(x);
    uint64_t m;
    int e;
    if (isnan(x)) { /* first: an ordered comparison with a NaN raises FE_INVALID */
        text = "NaN";
    } else if (isinf(x)) {
        text = x > 0 ? "Infinity" : "-Infinity";
    } else if (a == 0.0) { /* what snprintf gives, widened; zeros are common in a history */
        text = signbit(x) ? "-0.0000000000000000E+000" : "0.0000000000000000E+000";
    } else if (digits17(a, &m, &e)) {
        /* "-d.dddddddddddddddE+eee" or " d.dddddddddddddddE+eee": the 24 characters, written
         * in place (no justification pass); m = d0 10^16 + r, r's 16 digits as 8 + 8 */
        uint64_t d0 = m / 10000000000000000ULL;
        uint64_t r = m - d0 * 10000000000000000ULL;
        out[0] = x < 0 ? '-' : ' ';
        out[1] = (char)('0' + d0);
        out[2] = '.';
        put_digits8((uint32_t)(r / 100000000), out + 3);
        put_digits8((uint32_t)(r % 100000000), out + 11);
        out[19] = 'E';
        out[20] = e < 0 ? '-' : '+';
        e = e < 0 ? -e : e; /* 0..324 */
        out[21] = (char)('0' + e / 100);
        memcpy(out + 22, pairs + 2 * (e % 100), 2);
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
