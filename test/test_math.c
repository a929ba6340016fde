/* SPDX-License-Identifier: MIT */
/* The library's own sin, cos, exp, atan2 and asin (src/bsf_math.c): close to
 * the C library's, and the special values callers can meet. White-box. */
#include <math.h>

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

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_sin_and_cos_agree_with_libm_within_two_ulp_of_one);
    RUN_TEST(test_sin_and_cos_of_nan_and_inf_are_nan_and_huge_arguments_stay_in_range);
    RUN_TEST(test_exp_agrees_with_libm_within_three_ulp);
    RUN_TEST(test_exp_overflows_to_inf_underflows_to_zero_and_keeps_nan);
    RUN_TEST(test_atan2_agrees_with_libm_in_every_quadrant);
    RUN_TEST(test_atan2_signed_zeros_infinities_and_nan_follow_c99);
    RUN_TEST(test_asin_agrees_with_libm_and_is_nan_outside_its_domain);
    return UNITY_END();
}
