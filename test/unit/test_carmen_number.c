/* SPDX-License-Identifier: MIT */
/*
 * The CARMEN reader's number fast paths (tools/carmen/carmen_number.h)
 * against the C library they stand in for: whenever a fast path answers,
 * its value must be strtof's / strtod's / strtol's bit for bit and strtoX
 * must consume exactly the same token. Exhaustive over the decimal forms
 * CARMEN logs write, randomised over everything else. Host only.
 *
 * BSF_NUMBER_EXHAUSTIVE=1 in the environment widens the exhaustive part to
 * every mantissa up to 2^24 at every power of ten the float path takes
 * (about 350 million strings; minutes, not for CI).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "carmen_number.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

static unsigned long g_checked, g_fast;

static void expect_strtof(const char *s, const char *end, float fast, const char *path)
{
    char *lib_end;
    const float lib = strtof(s, &lib_end);
    if (lib_end != end || memcmp(&lib, &fast, sizeof lib) != 0) {
        char msg[200];
        snprintf(msg, sizeof msg, "float '%s': %s %a (end +%ld), strtof %a (end +%ld)", s, path,
                 (double)fast, (long)(end - s), (double)lib, (long)(lib_end - s));
        TEST_FAIL_MESSAGE(msg);
    }
}

/* Compares both float fast paths with strtof on s; the token is all of s.
 * g_fast counts the strings the general path answers, g_short those the
 * short path (readings of at most 7 digits) answers. */
static unsigned long g_short;

static void check_float(const char *s)
{
    const char *end = NULL;
    float fast = 0.0f;
    ++g_checked;
    if (carmen_parse_float(s, &end, &fast)) {
        ++g_fast;
        expect_strtof(s, end, fast, "general path");
    }
    if (carmen_parse_short_float(s, &end, &fast)) {
        ++g_short;
        expect_strtof(s, end, fast, "short path");
    }
}

static void check_double(const char *s)
{
    const char *end = NULL;
    double fast = 0.0;
    char *lib_end;
    double lib;
    if (!carmen_parse_double(s, &end, &fast)) {
        return;
    }
    lib = strtod(s, &lib_end);
    if (lib_end != end || memcmp(&lib, &fast, sizeof lib) != 0) {
        char msg[160];
        snprintf(msg, sizeof msg, "double '%s': fast %a (end +%ld), strtod %a (end +%ld)", s, fast,
                 (long)(end - s), lib, (long)(lib_end - s));
        TEST_FAIL_MESSAGE(msg);
    }
}

static void check_count(const char *s)
{
    const char *end = NULL;
    long fast = 0;
    char *lib_end;
    long lib;
    if (!carmen_parse_count(s, &end, &fast)) {
        return;
    }
    lib = strtol(s, &lib_end, 10);
    if (lib_end != end || lib != fast) {
        char msg[160];
        snprintf(msg, sizeof msg, "count '%s': fast %ld, strtol %ld", s, fast, lib);
        TEST_FAIL_MESSAGE(msg);
    }
}

/* m written with `frac` digits after the point ("0.0123" for m 123,
 * frac 4; no point when frac is 0). */
static int format_fixed(char *buf, size_t cap, int negative, unsigned long m, int frac)
{
    unsigned long scale = 1u;
    int i;
    for (i = 0; i < frac; ++i) {
        scale *= 10u;
    }
    if (frac == 0) {
        return snprintf(buf, cap, "%s%lu", negative ? "-" : "", m);
    }
    return snprintf(buf, cap, "%s%lu.%0*lu", negative ? "-" : "", m / scale, frac, m % scale);
}

/* Every reading and angle form of the logs: every mantissa below 2^17 with
 * 0..6 digits after the point, both signs ("81.83", "-1.570796",
 * "0.017453", "50.000000"). All of them must take the fast path. */
static void test_float_fast_path_equals_strtof_on_every_short_decimal(void)
{
    char buf[64];
    unsigned long m;
    int frac, neg;
    g_checked = g_fast = g_short = 0u;
    for (neg = 0; neg < 2; ++neg) {
        for (frac = 0; frac <= 6; ++frac) {
            for (m = 0; m < (1ul << 17); ++m) {
                format_fixed(buf, sizeof buf, neg, m, frac);
                check_float(buf);
                check_double(buf);
            }
        }
    }
    if (CARMEN_NUMBER_FAST) {
        TEST_ASSERT_EQUAL_UINT32(g_checked, g_fast);
        TEST_ASSERT_EQUAL_UINT32(g_checked, g_short);
    }
}

/* The float path's whole domain at its edges: mantissas near 2^24 and near
 * powers of two and ten, at every power of ten it takes (and one beyond,
 * which must fall back). */
static void test_float_fast_path_at_its_limits(void)
{
    static const unsigned long bases[] = {1u,    2u,       5u,       10u,      999u,     1000u,
                                          1001u, 8388607u, 8388608u, 8388609u, 9999999u, 10000000u};
    char buf[64];
    size_t b;
    int k, d;
    g_checked = g_fast = g_short = 0u;
    for (k = -11; k <= 11; ++k) {
        for (b = 0; b < sizeof bases / sizeof bases[0]; ++b) {
            for (d = -3; d <= 3; ++d) {
                const long m = (long)bases[b] + d;
                if (m < 0) {
                    continue;
                }
                snprintf(buf, sizeof buf, "%lde%d", m, k);
                check_float(buf);
                check_double(buf);
                snprintf(buf, sizeof buf, "-%ldE%+d", m, k);
                check_float(buf);
            }
        }
        for (d = -3; d <= 3; ++d) {
            snprintf(buf, sizeof buf, "%lue%d", (1ul << 24) + (unsigned long)(d + 3), k);
            check_float(buf);
        }
    }
    /* 2^24 + 1 is not a float: it must never be answered here. */
    {
        const char *end;
        float v;
        TEST_ASSERT_EQUAL_INT(0, carmen_parse_float("16777217", &end, &v));
        TEST_ASSERT_EQUAL_INT(0, carmen_parse_float("1e11", &end, &v));
        TEST_ASSERT_EQUAL_INT(0, carmen_parse_float("1e-11", &end, &v));
        TEST_ASSERT_EQUAL_INT(CARMEN_NUMBER_FAST, carmen_parse_float("16777216", &end, &v));
        TEST_ASSERT_EQUAL_INT(CARMEN_NUMBER_FAST, carmen_parse_float("1e10", &end, &v));
    }
}

/* Timestamps and poses: the double path on "%.6f" of large times. */
static void test_double_fast_path_equals_strtod_on_log_times(void)
{
    char buf[64];
    unsigned long i;
    uint32_t x = 12345u;
    for (i = 0; i < 200000u; ++i) {
        x = x * 1664525u + 1013904223u;
        snprintf(buf, sizeof buf, "%lu.%06lu", 900000000ul + (unsigned long)(x >> 4),
                 (unsigned long)(x % 1000000u));
        check_double(buf);
        snprintf(buf, sizeof buf, "-%lu.%06lu", (unsigned long)(x >> 12),
                 (unsigned long)(x % 997u));
        check_double(buf);
        check_float(buf);
    }
}

/* Random strings over the characters numbers are made of (and a few that
 * end or spoil them): the fast paths answer only what the library agrees
 * with, to the bit and to the byte. */
static void test_random_strings_agree_with_the_library(void)
{
    static const char alphabet[] = "0123456789000000000.-+eE .x\tn9i";
    char buf[48];
    uint64_t x = 0x9E3779B97F4A7C15u;
    unsigned long i, fast_before;
    g_checked = g_fast = g_short = 0u;
    for (i = 0; i < 1500000u; ++i) {
        size_t n, j;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        n = 1u + (size_t)(x % 26u);
        for (j = 0; j < n; ++j) {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            /* digits most of the time, so long valid numbers occur */
            buf[j] = (x >> 40) % 4u != 0u ? (char)('0' + (x >> 20) % 10u)
                                          : alphabet[(x >> 24) % (sizeof alphabet - 1u)];
        }
        buf[n] = '\0';
        check_float(buf);
        check_double(buf);
        check_count(buf);
    }
    /* The test must reach the fast paths, not only their refusals. */
    fast_before = g_fast;
    TEST_ASSERT_TRUE(!CARMEN_NUMBER_FAST || (fast_before > 100000u && g_short > 50000u));
}

/* What must be left to the library (its judgement, its messages). */
static void test_unusual_forms_are_left_to_the_library(void)
{
    static const char *const refused[] = {
        "",     "-",   "+",   ".",   "-.",  "e5",   "1e",      "1e+",
        "1.5x", "inf", "nan", "0x1", "1,5", "1..2", "1e99999", "12345678901234567890",
        "--1",  "1-",
    };
    const char *end;
    float f;
    double d;
    long c;
    size_t i;
    for (i = 0; i < sizeof refused / sizeof refused[0]; ++i) {
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, carmen_parse_float(refused[i], &end, &f), refused[i]);
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, carmen_parse_double(refused[i], &end, &d), refused[i]);
    }
    /* The short path: at most 7 digits, one point, a '-' at most. */
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_short_float("12345678", &end, &f));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_short_float("0.1234567", &end, &f));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_short_float("+5", &end, &f));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_short_float("1e5", &end, &f));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_short_float("-", &end, &f));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_short_float(".", &end, &f));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_short_float("1.2.3", &end, &f));
    TEST_ASSERT_EQUAL_INT(CARMEN_NUMBER_FAST, carmen_parse_short_float("1234567", &end, &f));
    TEST_ASSERT_EQUAL_INT(CARMEN_NUMBER_FAST, carmen_parse_short_float("-.5", &end, &f));
    TEST_ASSERT_EQUAL_INT(CARMEN_NUMBER_FAST, carmen_parse_short_float("5.", &end, &f));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_count("-0", &end, &c));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_count("+5", &end, &c));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_count("1234567890123456789", &end, &c));
    TEST_ASSERT_EQUAL_INT(0, carmen_parse_count("5.0", &end, &c));
    /* A blank ends the token; the value stops there. */
    if (CARMEN_NUMBER_FAST) {
        const char *s = "-0.000 7";
        TEST_ASSERT_EQUAL_INT(1, carmen_parse_float(s, &end, &f));
        TEST_ASSERT_EQUAL_PTR(s + 6, end);
        TEST_ASSERT_TRUE(f == 0.0f && signbit(f));
        TEST_ASSERT_EQUAL_INT(1, carmen_parse_count("180\t3.5", &end, &c));
        TEST_ASSERT_EQUAL_INT32(180, c);
    }
}

/* Opt-in: every mantissa up to 2^24 at every power of ten of the float path. */
static void test_float_fast_path_exhaustive_when_asked(void)
{
    char buf[64];
    unsigned long m;
    int k;
    const char *env = getenv("BSF_NUMBER_EXHAUSTIVE");
    if (env == NULL || strcmp(env, "1") != 0) {
        TEST_IGNORE_MESSAGE("set BSF_NUMBER_EXHAUSTIVE=1 for the exhaustive float check");
    }
    g_checked = g_fast = g_short = 0u;
    for (k = -10; k <= 10; ++k) {
        for (m = 0; m <= (1ul << 24); ++m) {
            snprintf(buf, sizeof buf, "%lue%d", m, k);
            check_float(buf);
        }
    }
    printf("exhaustive: %lu strings, %lu on the fast path, all equal to strtof\n", g_checked,
           g_fast);
    TEST_ASSERT_EQUAL_UINT32(g_checked, g_fast);
    /* every reading of at most 7 digits, point anywhere, both signs */
    g_checked = g_fast = g_short = 0u;
    for (k = 0; k <= 7; ++k) {
        for (m = 0; m < 10000000ul; ++m) {
            format_fixed(buf, sizeof buf, (int)(m & 1u), m, k);
            check_float(buf);
        }
    }
    printf("exhaustive short forms: %lu strings, %lu on the short path, all equal to strtof\n",
           g_checked, g_short);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_float_fast_path_equals_strtof_on_every_short_decimal);
    RUN_TEST(test_float_fast_path_at_its_limits);
    RUN_TEST(test_double_fast_path_equals_strtod_on_log_times);
    RUN_TEST(test_random_strings_agree_with_the_library);
    RUN_TEST(test_unusual_forms_are_left_to_the_library);
    RUN_TEST(test_float_fast_path_exhaustive_when_asked);
    return UNITY_END();
}
