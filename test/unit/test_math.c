/* SPDX-License-Identifier: MIT */
/* The library's own sin, cos, exp, atan2 and asin (src/bsf_math.c): close to
 * the C library's, and the special values callers can meet. White-box. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "bsf_math.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

static void test_sin_and_cos_agree_with_libm_within_two_ulp_of_one(void)
{
    float worst = 0.0f;
    int i;
    for (i = -20000; i <= 20000; ++i) {
        /* beam angles as bsf_scan forms them, up to the validated 3400 rad */
        const float x = (float)i * 0.1703f;
        const float es = fabsf(bsf_sinf(x) - sinf(x));
        const float ec = fabsf(bsf_cosf(x) - cosf(x));
        worst = es > worst ? es : worst;
        worst = ec > worst ? ec : worst;
    }
    TEST_ASSERT_TRUE_MESSAGE(worst <= 2.5e-7f, "sin/cos error above 2.5e-7");
    TEST_ASSERT_EQUAL_FLOAT(0.0f, bsf_sinf(0.0f));
    TEST_ASSERT_EQUAL_FLOAT(1.0f, bsf_cosf(0.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-7f, 1.0f, bsf_sinf(1.5707964f));
    TEST_ASSERT_FLOAT_WITHIN(1e-7f, -1.0f, bsf_cosf(3.1415927f));
}

static void test_sin_and_cos_of_nan_and_inf_are_nan_and_huge_arguments_stay_in_range(void)
{
    TEST_ASSERT_TRUE(isnan(bsf_sinf(NAN)));
    TEST_ASSERT_TRUE(isnan(bsf_cosf(INFINITY)));
    TEST_ASSERT_TRUE(isnan(bsf_sinf(-INFINITY)));
    TEST_ASSERT_TRUE(fabsf(bsf_sinf(1.0e30f)) <= 1.0f);
    TEST_ASSERT_TRUE(fabsf(bsf_cosf(-3.0e38f)) <= 1.0f);
}

static uint32_t bits_of(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

static float float_of(uint32_t u)
{
    float v;
    memcpy(&v, &u, sizeof v);
    return v;
}

/* The same value as floorf, bit for bit (NaN: both NaN). */
static int floor_matches(float x)
{
    const float want = floorf(x);
    const float got = bsf_floorf(x);
    if (want != want) {
        return got != got;
    }
    return bits_of(want) == bits_of(got);
}

static void test_floor_is_floorf_bit_for_bit(void)
{
    uint32_t u;
    int i;
    unsigned long bad = 0;
    /* every float pattern at a prime stride: all exponents, both signs */
    for (u = 0u; u < 0xFFFFF000u; u += 4093u) {
        bad += floor_matches(float_of(u)) ? 0u : 1u;
    }
    /* around every quarter in [-2^14, 2^14], and the edges of the fast path */
    for (i = -65536; i <= 65536; ++i) {
        const float x = (float)i * 0.25f;
        bad += floor_matches(x) ? 0u : 1u;
        bad += floor_matches(nextafterf(x, -INFINITY)) ? 0u : 1u;
        bad += floor_matches(nextafterf(x, INFINITY)) ? 0u : 1u;
    }
    for (i = -3; i <= 3; ++i) {
        bad += floor_matches(8388608.0f + (float)i) ? 0u : 1u;
        bad += floor_matches(-8388608.0f + (float)i) ? 0u : 1u;
        bad += floor_matches(8388607.5f + (float)i) ? 0u : 1u;
        bad += floor_matches(-8388607.5f + (float)i) ? 0u : 1u;
    }
    bad += floor_matches(-0.0f) ? 0u : 1u;
    bad += floor_matches(INFINITY) && floor_matches(-INFINITY) && floor_matches(NAN) ? 0u : 1u;
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bad);
    TEST_ASSERT_EQUAL_HEX32(bits_of(-0.0f), bits_of(bsf_floorf(-0.0f)));
    TEST_ASSERT_EQUAL_FLOAT(-1.0f, bsf_floorf(-0.25f));
}

/* The sin and cos the library computed before bsf_sincosf (libm floorf for
 * the range reduction): the points of every scan, and so every stream byte,
 * depend on keeping exactly these bits. */
static float ref_reduce(float x, unsigned *quadrant)
{
    const float k = floorf(x * BSF_TWO_OVER_PI_F + 0.5f);
    const float r = ((x - k * BSF_PIO2_1_F) - k * BSF_PIO2_2_F) - k * BSF_PIO2_3_F;
    const float k4 = k - 4.0f * floorf(k * 0.25f);
    *quadrant = (unsigned)k4 & 3u;
    return r;
}

static float ref_sin_cos(float x, int want_cos)
{
    unsigned q;
    float r;
    float v;
    if (!(fabsf(x) <= 3.402823466e38f)) {
        return x - x;
    }
    r = ref_reduce(x, &q);
    q = (q + (want_cos ? 1u : 0u)) & 3u; /* cos x = sin(x + pi/2) */
    switch (q) {
    case 0u: v = bsf_sin_kernel(r); break;
    case 1u: v = bsf_cos_kernel(r); break;
    case 2u: v = -bsf_sin_kernel(r); break;
    default: v = -bsf_cos_kernel(r); break;
    }
    return v > 1.0f ? 1.0f : (v < -1.0f ? -1.0f : v);
}

/* 1 when sincos, sin and cos of x all give the reference's bits. */
static int trig_matches(float x)
{
    float s;
    float c;
    const uint32_t want_s = bits_of(ref_sin_cos(x, 0));
    const uint32_t want_c = bits_of(ref_sin_cos(x, 1));
    bsf_sincosf(x, &s, &c);
    if (fabsf(x) <= 16384.0f) {
        float sb;
        float cb;
        bsf_sincosf_bounded(x, &sb, &cb);
        if (bits_of(sb) != want_s || bits_of(cb) != want_c) {
            return 0;
        }
    }
    if (x != x || !(fabsf(x) <= 3.402823466e38f)) {
        return s != s && c != c && bsf_sinf(x) != bsf_sinf(x) && bsf_cosf(x) != bsf_cosf(x);
    }
    return bits_of(s) == want_s && bits_of(c) == want_c && bits_of(bsf_sinf(x)) == want_s &&
           bits_of(bsf_cosf(x)) == want_c;
}

static void test_sincos_sin_and_cos_keep_the_reference_bits(void)
{
    static const float angle_min[] = {-3.14159265f, -2.35619449f, -1.57079633f, 0.0f, -12.5f};
    static const float increment[] = {0.0174532925f,  0.00436332313f, 0.00872664626f,
                                      0.00196349541f, -0.0174532925f, 3.0f};
    unsigned long bad = 0;
    uint32_t u;
    size_t a;
    size_t b;
    int i;
    /* beam angles exactly as bsf_scan_to_points forms them */
    for (a = 0; a < sizeof angle_min / sizeof angle_min[0]; ++a) {
        for (b = 0; b < sizeof increment / sizeof increment[0]; ++b) {
            for (i = 0; i < 4096; ++i) {
                bad += trig_matches(angle_min[a] + (float)i * increment[b]) ? 0u : 1u;
            }
        }
    }
    /* every float pattern at a prime stride: tiny, huge, NaN, both signs */
    for (u = 0u; u < 0xFFFFF000u; u += 40009u) {
        bad += trig_matches(float_of(u)) ? 0u : 1u;
    }
    /* densely where the quadrant changes, to the bounded variant's limit */
    for (i = -20861; i <= 20861; ++i) {
        const float x = (float)i * 0.785398163f;
        bad += trig_matches(x) ? 0u : 1u;
        bad += trig_matches(nextafterf(x, 0.0f)) ? 0u : 1u;
    }
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bad);
}

static void test_exp_agrees_with_libm_within_three_ulp(void)
{
    float worst = 0.0f;
    int i;
    for (i = -10300; i <= 8870; ++i) {
        const float x = (float)i * 0.01f;
        const float ref = expf(x);
        float rel;
        if (ref < 1.17549435e-38f) {
            continue; /* subnormal results: checked below */
        }
        rel = fabsf(bsf_expf(x) - ref) / ref;
        worst = rel > worst ? rel : worst;
    }
    TEST_ASSERT_TRUE_MESSAGE(worst <= 3.6e-7f, "exp relative error above 3 ulp");
    TEST_ASSERT_EQUAL_FLOAT(1.0f, bsf_expf(0.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 2.7182817f, bsf_expf(1.0f));
}

/* The bounds the radius tests use to skip bsf_expf: checked once on every
 * float in [0, 1] (1 065 353 217 values, no failure); here every 997th. */
static void test_exp_bounds_hold_and_are_tight_on_zero_to_one(void)
{
    uint32_t bits;
    uint32_t end;
    float one = 1.0f;
    float widest = 0.0f;
    memcpy(&end, &one, sizeof end);
    for (bits = 0u; bits <= end; bits += 997u) {
        float x;
        float lo;
        float hi;
        float e;
        memcpy(&x, &bits, sizeof x);
        bsf_exp_bounds01(x, &lo, &hi);
        e = bsf_expf(x);
        if (!(lo <= e && e <= hi && bsf_exp_taylor4(x) <= hi)) {
            TEST_FAIL_MESSAGE("bsf_exp_bounds01 does not bracket bsf_expf");
        }
        widest = (hi - lo) / e > widest ? (hi - lo) / e : widest;
    }
    bsf_exp_bounds01(1.0f, &one, &widest); /* the end point itself */
    TEST_ASSERT_TRUE(one <= bsf_expf(1.0f) && bsf_expf(1.0f) <= widest);
    TEST_ASSERT_TRUE_MESSAGE((widest - one) / bsf_expf(1.0f) < 1e-2f, "bounds too loose at 1");
}

static void test_exp_overflows_to_inf_underflows_to_zero_and_keeps_nan(void)
{
    const float sub = bsf_expf(-100.0f); /* 3.72e-44, subnormal */
    TEST_ASSERT_TRUE(isinf(bsf_expf(89.0f)) && bsf_expf(89.0f) > 0.0f);
    TEST_ASSERT_TRUE(isinf(bsf_expf(INFINITY)));
    TEST_ASSERT_EQUAL_FLOAT(0.0f, bsf_expf(-104.0f));
    TEST_ASSERT_EQUAL_FLOAT(0.0f, bsf_expf(-INFINITY));
    TEST_ASSERT_TRUE(isnan(bsf_expf(NAN)));
    TEST_ASSERT_TRUE(sub > 0.0f && fabsf(sub - 3.7200760e-44f) <= 2.0e-45f);
    TEST_ASSERT_TRUE(bsf_expf(88.7f) > 3.0e38f && !isinf(bsf_expf(88.7f)));
}

static void test_atan2_agrees_with_libm_in_every_quadrant(void)
{
    float worst = 0.0f;
    int i;
    int j;
    for (i = -60; i <= 60; ++i) {
        for (j = -60; j <= 60; ++j) {
            const float y = (float)i * 0.37f;
            const float x = (float)j * 0.29f;
            const float e = fabsf(bsf_atan2f(y, x) - atan2f(y, x));
            worst = e > worst ? e : worst;
        }
    }
    TEST_ASSERT_TRUE_MESSAGE(worst <= 4.8e-7f, "atan2 error above 2 ulp of pi");
    TEST_ASSERT_FLOAT_WITHIN(1e-12f, 1.0e-20f, bsf_atan2f(1.0e-20f, 1.0f));
}

static void test_atan2_signed_zeros_infinities_and_nan_follow_c99(void)
{
    TEST_ASSERT_EQUAL_FLOAT(0.0f, bsf_atan2f(0.0f, 0.0f));
    TEST_ASSERT_FALSE(signbit(bsf_atan2f(0.0f, 1.0f)));
    TEST_ASSERT_TRUE(signbit(bsf_atan2f(-0.0f, 1.0f)));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.1415927f, bsf_atan2f(0.0f, -0.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, -3.1415927f, bsf_atan2f(-0.0f, -1.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.5707964f, bsf_atan2f(INFINITY, 5.0f));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, -2.3561945f, bsf_atan2f(-INFINITY, -INFINITY));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.1415927f, bsf_atan2f(1.0f, -INFINITY));
    TEST_ASSERT_TRUE(isnan(bsf_atan2f(NAN, 1.0f)));
    TEST_ASSERT_TRUE(isnan(bsf_atan2f(1.0f, NAN)));
}

static void test_asin_agrees_with_libm_and_is_nan_outside_its_domain(void)
{
    float worst = 0.0f;
    int i;
    for (i = -10000; i <= 10000; ++i) {
        const float x = (float)i * 1.0e-4f;
        const float e = fabsf(bsf_asinf(x) - asinf(x));
        worst = e > worst ? e : worst;
    }
    TEST_ASSERT_TRUE_MESSAGE(worst <= 2.5e-7f, "asin error above 2 ulp of pi/2");
    TEST_ASSERT_FLOAT_WITHIN(1e-7f, 1.5707964f, bsf_asinf(1.0f));
    TEST_ASSERT_TRUE(isnan(bsf_asinf(1.0001f)));
    TEST_ASSERT_TRUE(isnan(bsf_asinf(-INFINITY)));
    TEST_ASSERT_TRUE(isnan(bsf_asinf(NAN)));
}

/* The parameter checks' range table: 0 is in a closed lower bound and out
 * of an open one, hi likewise, NaN in none, and the first field out of its
 * range fails the whole table. */
typedef struct {
    float a;
    float b;
} two_floats_t;

static void test_floats_in_range_honours_open_and_closed_bounds_and_rejects_nan(void)
{
    static const bsf_float_range_t closed[] = {{2.0f, 0u, 0u}, {2.0f, 4u, 0u}};
    static const bsf_float_range_t open[] = {{2.0f, 0u, BSF_RANGE_LO_OPEN | BSF_RANGE_HI_OPEN},
                                             {2.0f, 4u, BSF_RANGE_LO_OPEN | BSF_RANGE_HI_OPEN}};
    two_floats_t p = {0.0f, 2.0f};
    TEST_ASSERT_EQUAL_size_t(4u, offsetof(two_floats_t, b));
    TEST_ASSERT_EQUAL_INT(1, bsf_floats_in_range(&p, closed, 2u));
    TEST_ASSERT_EQUAL_INT(0, bsf_floats_in_range(&p, open, 2u));
    TEST_ASSERT_EQUAL_INT(0, bsf_floats_in_range(&p, open, 1u)); /* a = 0: open at 0 */
    p.a = 1e-45f;                                                /* the least positive float */
    TEST_ASSERT_EQUAL_INT(1, bsf_floats_in_range(&p, open, 1u));
    TEST_ASSERT_EQUAL_INT(0, bsf_floats_in_range(&p, open, 2u)); /* b = hi: open at hi */
    p.b = 1.9999999f;
    TEST_ASSERT_EQUAL_INT(1, bsf_floats_in_range(&p, open, 2u));
    p.b = 2.0000002f;
    TEST_ASSERT_EQUAL_INT(0, bsf_floats_in_range(&p, closed, 2u));
    p.b = -0.0f; /* -0 >= 0 */
    TEST_ASSERT_EQUAL_INT(1, bsf_floats_in_range(&p, closed, 2u));
    p.b = -1e-45f;
    TEST_ASSERT_EQUAL_INT(0, bsf_floats_in_range(&p, closed, 2u));
    p.b = NAN;
    TEST_ASSERT_EQUAL_INT(0, bsf_floats_in_range(&p, closed, 2u));
    TEST_ASSERT_EQUAL_INT(1, bsf_floats_in_range(&p, closed, 1u)); /* only a is looked at */
    p.a = NAN;
    TEST_ASSERT_EQUAL_INT(0, bsf_floats_in_range(&p, closed, 1u));
    TEST_ASSERT_EQUAL_INT(1, bsf_floats_in_range(&p, closed, 0u)); /* an empty table */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_sin_and_cos_agree_with_libm_within_two_ulp_of_one);
    RUN_TEST(test_sin_and_cos_of_nan_and_inf_are_nan_and_huge_arguments_stay_in_range);
    RUN_TEST(test_floor_is_floorf_bit_for_bit);
    RUN_TEST(test_sincos_sin_and_cos_keep_the_reference_bits);
    RUN_TEST(test_exp_agrees_with_libm_within_three_ulp);
    RUN_TEST(test_exp_overflows_to_inf_underflows_to_zero_and_keeps_nan);
    RUN_TEST(test_exp_bounds_hold_and_are_tight_on_zero_to_one);
    RUN_TEST(test_atan2_agrees_with_libm_in_every_quadrant);
    RUN_TEST(test_atan2_signed_zeros_infinities_and_nan_follow_c99);
    RUN_TEST(test_asin_agrees_with_libm_and_is_nan_outside_its_domain);
    RUN_TEST(test_floats_in_range_honours_open_and_closed_bounds_and_rejects_nan);
    return UNITY_END();
}
