/* SPDX-License-Identifier: MIT */
/*
 * carmen_number.h - exact fast paths for the decimal numbers of CARMEN logs
 * (host only; included by carmen.c and by its tests, so every build of the
 * reader, the Python extension's included, gets it without a new source).
 *
 * Each parser either gives exactly the value strtof / strtod / strtol would
 * give for the whole token and returns 1, or returns 0 and the caller asks
 * the C library (so anything unusual keeps the library's judgement and the
 * reader's error messages stay as they were).
 *
 * Handled form: [+-]? digits [. digits]? ([eE] [+-]? digits)? followed by
 * a blank (space, tab) or the end of the string, with at least one digit
 * before the exponent and at most 19 digits in all. The decimal value is
 * m * 10^k with an integer m. When m and 10^|k| are both exactly
 * representable (float: m <= 2^24 and |k| <= 10, since 5^10 < 2^24; double:
 * m <= 2^53 and |k| <= 22, since 5^22 < 2^53), one IEEE multiplication or
 * division of exact operands is correctly rounded, which is what glibc's
 * strtof/strtod are (Clinger's fast path). That covers every reading, angle
 * and pose a CARMEN log writes ("81.83", "-1.570796", "975001234.512345").
 * Evaluation must be in the operands' own precision (FLT_EVAL_METHOD 0, as
 * on x86-64 SSE, AArch64, s390x); otherwise the fast paths stay off.
 */
#ifndef BSF_TOOLS_CARMEN_NUMBER_H
#define BSF_TOOLS_CARMEN_NUMBER_H

#include <float.h>
#include <stddef.h>
#include <stdint.h>

#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD == 0
#define CARMEN_NUMBER_FAST 1
#else
#define CARMEN_NUMBER_FAST 0
#endif

/* A token ends at a blank or at the end of the line's string. */
static inline int carmen_is_token_end(char c)
{
    return c == ' ' || c == '\t' || c == '\0';
}

/* The decimal m * 10^k (sign apart) of s when s has the handled form:
 * returns 1 with *end at the token's end, else 0. Digit counts come from
 * pointer differences: the loops do nothing but accumulate. */
static inline int carmen_scan_decimal(const char *s, const char **end, int *negative,
                                      uint64_t *mantissa, int *exp10)
{
    const char *p = s;
    const char *digits_start;
    uint64_t m = 0u;
    unsigned d;
    int digits, frac = 0, e = 0;
    *negative = *p == '-';
    p += *p == '-' || *p == '+';
    digits_start = p;
    while ((d = (unsigned)(unsigned char)*p - '0') <= 9u) {
        m = m * 10u + d;
        ++p;
    }
    digits = (int)(p - digits_start);
    if (*p == '.') {
        const char *frac_start = ++p;
        while ((d = (unsigned)(unsigned char)*p - '0') <= 9u) {
            m = m * 10u + d;
            ++p;
        }
        frac = (int)(p - frac_start);
        digits += frac;
    }
    /* 19 digits always fit 64 bits; more may have wrapped. */
    if (digits == 0 || digits > 19) {
        return 0;
    }
    if ((*p | 0x20) == 'e') {
        const char *exp_start;
        int eneg;
        ++p;
        eneg = *p == '-';
        p += *p == '-' || *p == '+';
        exp_start = p;
        while ((d = (unsigned)(unsigned char)*p - '0') <= 9u) {
            if (p - exp_start == 4) {
                return 0; /* 4 digits are plenty; more go to the library */
            }
            e = e * 10 + (int)d;
            ++p;
        }
        if (p == exp_start) {
            return 0;
        }
        if (eneg) {
            e = -e;
        }
    }
    if (!carmen_is_token_end(*p)) {
        return 0;
    }
    *end = p;
    *mantissa = m;
    *exp10 = e - frac;
    return 1;
}

/**
 * strtof's value of the token at s when it is exactly computable here.
 * @return 1 with *value and *end (the token's end) set, 0: ask strtof.
 */
static inline int carmen_parse_float(const char *s, const char **end, float *value)
{
    static const float pow10f[11] = {1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f,
                                     1e6f, 1e7f, 1e8f, 1e9f, 1e10f};
    int negative, k;
    uint64_t m;
    float v;
    if (!CARMEN_NUMBER_FAST || !carmen_scan_decimal(s, end, &negative, &m, &k)) {
        return 0;
    }
    if (m <= ((uint64_t)1 << 24) && (unsigned)(k + 10) <= 20u) {
        v = k < 0 ? (float)m / pow10f[-k] : (float)m * pow10f[k];
    } else if (m == 0u) {
        v = 0.0f; /* any exponent: zero, with its sign */
    } else {
        return 0;
    }
    *value = negative ? -v : v;
    return 1;
}

/**
 * strtod's value of the token at s when it is exactly computable here.
 * @return 1 with *value and *end (the token's end) set, 0: ask strtod.
 */
static inline int carmen_parse_double(const char *s, const char **end, double *value)
{
    static const double pow10d[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    int negative, k;
    uint64_t m;
    double v;
    if (!CARMEN_NUMBER_FAST || !carmen_scan_decimal(s, end, &negative, &m, &k)) {
        return 0;
    }
    if (m <= ((uint64_t)1 << 53) && (unsigned)(k + 22) <= 44u) {
        v = k < 0 ? (double)m / pow10d[-k] : (double)m * pow10d[k];
    } else if (m == 0u) {
        v = 0.0;
    } else {
        return 0;
    }
    *value = negative ? -v : v;
    return 1;
}

/**
 * strtol's value (base 10) of a token of plain digits, at most 18 of them.
 * @return 1 with *value and *end (the token's end) set, 0: ask strtol.
 */
static inline int carmen_parse_count(const char *s, const char **end, long *value)
{
    /* 18 digits fit a 64-bit long; with a 32-bit long, 9 do. */
    const long max_digits = sizeof(long) >= 8u ? 18 : 9;
    const char *p = s;
    long v = 0;
    while ((unsigned)(*p - '0') <= 9u) {
        if (p - s == max_digits) {
            return 0;
        }
        v = v * 10 + (long)(*p - '0');
        ++p;
    }
    if (p == s || !carmen_is_token_end(*p)) {
        return 0;
    }
    *end = p;
    *value = v;
    return 1;
}

/**
 * carmen_parse_float for the short tokens most readings are: an optional
 * '-', at most 7 digits with at most one point among them ("81.83",
 * "-1.570796"), so m < 10^7 < 2^24 over 10^f with f <= 7; fewer checks than
 * the general form.
 * @return 1 with *value and *end (the token's end) set, 0: not this form.
 */
static inline int carmen_parse_short_float(const char *s, const char **end, float *value)
{
    static const float pow10f[8] = {1e0f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f, 1e6f, 1e7f};
    const char *p = s + (*s == '-');
    const char *const start = p;
    uint32_t m = 0u;
    unsigned d, frac = 0u;
    size_t point = 0u;
    while ((d = (unsigned)(unsigned char)*p - '0') <= 9u) {
        m = m * 10u + d;
        ++p;
    }
    if (*p == '.') {
        const char *const frac_start = ++p;
        point = 1u;
        while ((d = (unsigned)(unsigned char)*p - '0') <= 9u) {
            m = m * 10u + d;
            ++p;
        }
        frac = (unsigned)(p - frac_start);
    }
    /* 1..7 digits (m has not wrapped), then the token's end */
    if (CARMEN_NUMBER_FAST && (size_t)(p - start) - point - 1u < 7u && carmen_is_token_end(*p)) {
        const float v = (float)m / pow10f[frac];
        *value = *s == '-' ? -v : v;
        *end = p;
        return 1;
    }
    return 0;
}

#endif /* BSF_TOOLS_CARMEN_NUMBER_H */
