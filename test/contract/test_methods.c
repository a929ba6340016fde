/* SPDX-License-Identifier: MIT */
/*
 * Compile-time method selection (BSF_CONFIG_METHODS, bsf_config.h): this test
 * links a copy of the library built with the default method alone
 * (bsf_lc_only); the methods left out must be refused with
 * BSF_ERR_UNSUPPORTED everywhere they could be used, while the default still
 * extracts and encodes. Its companion in the full library
 * (test_methods_all) checks that every method is accepted there.
 */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "unity.h"

#define N_BEAMS 361

static bsf_extractor_t ex;
static bsf_result_t res;
static float ranges[N_BEAMS];
static uint8_t frame[BSF_FRAME_MAX_SIZE];

void setUp(void)
{
}

void tearDown(void)
{
}

/* 360 degrees from the centre of a 6 m x 4 m room: four walls, four corners. */
static bsf_scan_t room_scan(void)
{
    bsf_scan_t s;
    size_t i;
    for (i = 0; i < N_BEAMS; ++i) {
        const double a = -3.14159265358979 + 6.28318530717959 * (double)i / (double)N_BEAMS;
        const double c = cos(a);
        const double sn = sin(a);
        double t = 1e9;
        if (fabs(c) > 1e-9) {
            t = fmin(t, 3.0 / fabs(c));
        }
        if (fabs(sn) > 1e-9) {
            t = fmin(t, 2.0 / fabs(sn));
        }
        ranges[i] = (float)t;
    }
    s.ranges = ranges;
    s.count = N_BEAMS;
    s.angle_min = -3.14159265f;
    s.angle_increment = 6.28318531f / (float)N_BEAMS;
    s.range_min = 0.0f;
    s.range_max = 30.0f;
    return s;
}

static int compiled_in(bsf_method_t m)
{
    return ((BSF_CONFIG_METHODS) & (1 << (int)m)) != 0;
}

static void test_every_method_is_accepted_or_refused_as_configured(void)
{
    int m;
    int n_in = 0;
    for (m = 0; m < (int)BSF_METHOD_COUNT; ++m) {
        const bsf_params_t p = bsf_params_default((bsf_method_t)m);
        const bsf_status_t want = compiled_in((bsf_method_t)m) ? BSF_OK : BSF_ERR_UNSUPPORTED;
        TEST_ASSERT_EQUAL_INT_MESSAGE(want, bsf_params_check(&p), bsf_method_name((bsf_method_t)m));
        TEST_ASSERT_EQUAL_INT_MESSAGE(want, bsf_extractor_init(&ex, &p),
                                      bsf_method_name((bsf_method_t)m));
        n_in += compiled_in((bsf_method_t)m);
    }
#ifdef BSF_TEST_EXPECT_METHODS
    TEST_ASSERT_EQUAL_INT(BSF_TEST_EXPECT_METHODS, BSF_CONFIG_METHODS);
#endif
    TEST_ASSERT_TRUE(n_in >= 1);
    TEST_ASSERT_TRUE(compiled_in(BSF_METHOD_DEFAULT));
}

static void test_a_refused_method_leaves_the_extractor_unusable(void)
{
    int m;
    const bsf_scan_t scan = room_scan();
    for (m = 0; m < (int)BSF_METHOD_COUNT; ++m) {
        bsf_params_t ok = bsf_params_default(BSF_METHOD_DEFAULT);
        bsf_params_t p = bsf_params_default((bsf_method_t)m);
        if (compiled_in((bsf_method_t)m)) {
            continue;
        }
        /* A ready extractor re-initialised with a left-out method is not ready any more. */
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &ok));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_UNSUPPORTED, bsf_extractor_init(&ex, &p));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(&ex, &scan, &res));
        TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)res.n_features);
    }
}

static void test_unknown_method_is_still_a_parameter_error(void)
{
    bsf_params_t p = bsf_params_default(BSF_METHOD_DEFAULT);
    p.method = BSF_METHOD_COUNT;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_params_check(&p));
    p.method = (bsf_method_t)-1;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_params_check(&p));
}

static void test_status_text_names_the_build(void)
{
    TEST_ASSERT_EQUAL_STRING("method or feature not compiled into this build",
                             bsf_status_str(BSF_ERR_UNSUPPORTED));
}

static void test_default_method_extracts_and_encodes(void)
{
    const bsf_params_t p = bsf_params_default(BSF_METHOD_DEFAULT);
    const bsf_scan_t scan = room_scan();
    bsf_frame_info_t info;
    size_t len = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&ex, &scan, &res));
    /* Four walls, the four corners as vertices. */
    TEST_ASSERT_TRUE(res.n_features >= 1u && res.n_features <= 4u);
    TEST_ASSERT_TRUE(res.stats.n_keypoints >= 4u);
    bsf_frame_info_init(&info);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, frame, sizeof frame, &len));
    TEST_ASSERT_TRUE(len > 16u);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_every_method_is_accepted_or_refused_as_configured);
    RUN_TEST(test_a_refused_method_leaves_the_extractor_unusable);
    RUN_TEST(test_unknown_method_is_still_a_parameter_error);
    RUN_TEST(test_status_text_names_the_build);
    RUN_TEST(test_default_method_extracts_and_encodes);
    return UNITY_END();
}
