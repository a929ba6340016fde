/* SPDX-License-Identifier: MIT */
/* Scan model: which readings become points, and which calls are refused. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_math.h"
#include "unity.h"

static bsf_points_t points;
static float ranges[BSF_MAX_POINTS + 1];

void setUp(void)
{
    memset(&points, 0xA5, sizeof points);
}

void tearDown(void)
{
}

static bsf_scan_t make_scan(size_t count)
{
    bsf_scan_t s;
    s.ranges = ranges;
    s.count = count;
    s.angle_min = -1.5707963f;
    s.angle_increment = 0.017453292f;
    s.range_min = 0.1f;
    s.range_max = 30.0f;
    return s;
}

static void test_valid_readings_become_points_at_their_beam_angle(void)
{
    bsf_scan_t s = make_scan(3);
    ranges[0] = 1.0f;
    ranges[1] = 2.0f;
    ranges[2] = 3.0f;
    s.angle_min = 0.0f;
    s.angle_increment = 1.5707963f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32(3u, (uint32_t)points.count);
    TEST_ASSERT_EQUAL_UINT32(3u, (uint32_t)points.n_valid);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.0f, points.pt[0].x);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.0f, points.pt[0].y);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.0f, points.pt[1].x);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 2.0f, points.pt[1].y);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, -3.0f, points.pt[2].x);
    TEST_ASSERT_FLOAT_WITHIN(1e-5f, 0.0f, points.pt[2].y);
    TEST_ASSERT_EQUAL_FLOAT(2.0f, points.range[1]);
    TEST_ASSERT_EQUAL_FLOAT(1.5707963f, points.angle_increment);
}

static void test_nan_inf_negative_zero_and_out_of_range_are_invalid(void)
{
    const float bad[] = {NAN, INFINITY, -INFINITY, -1.0f, 0.0f, 0.05f, 30.0f, 81.83f};
    const size_t n_bad = sizeof bad / sizeof bad[0];
    bsf_scan_t s = make_scan(n_bad + 1u);
    size_t i;
    for (i = 0; i < n_bad; ++i) {
        ranges[i] = bad[i];
    }
    ranges[n_bad] = 29.99f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)points.n_valid);
    for (i = 0; i < n_bad; ++i) {
        TEST_ASSERT_EQUAL_UINT8_MESSAGE(0u, points.valid[i], "invalid reading marked valid");
        TEST_ASSERT_EQUAL_FLOAT(0.0f, points.pt[i].x);
        TEST_ASSERT_EQUAL_FLOAT(0.0f, points.pt[i].y);
        TEST_ASSERT_EQUAL_FLOAT(0.0f, points.range[i]);
    }
    TEST_ASSERT_EQUAL_UINT8(1u, points.valid[n_bad]);
}

static void test_zero_reading_invalid_even_with_zero_range_min(void)
{
    bsf_scan_t s = make_scan(2);
    s.range_min = 0.0f;
    ranges[0] = 0.0f;
    ranges[1] = 1.0f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT8(0u, points.valid[0]);
    TEST_ASSERT_EQUAL_UINT8(1u, points.valid[1]);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)points.n_valid);
}

static void test_range_bounds_are_half_open(void)
{
    TEST_ASSERT_TRUE(bsf_range_is_valid(0.1f, 0.1f, 30.0f));
    TEST_ASSERT_FALSE(bsf_range_is_valid(30.0f, 0.1f, 30.0f));
    TEST_ASSERT_TRUE(bsf_range_is_valid(29.999f, 0.1f, 30.0f));
    TEST_ASSERT_TRUE(bsf_range_is_valid(1e6f, 0.1f, INFINITY));
    TEST_ASSERT_FALSE(bsf_range_is_valid(INFINITY, 0.1f, INFINITY));
}

static void test_count_above_capacity_is_refused_untouched(void)
{
    bsf_scan_t s = make_scan((size_t)BSF_MAX_POINTS + 1u);
    size_t i;
    for (i = 0; i <= BSF_MAX_POINTS; ++i) {
        ranges[i] = 1.0f;
    }
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_HEX8(0xA5u, points.valid[0]);
}

static void test_count_at_capacity_is_accepted(void)
{
    bsf_scan_t s = make_scan((size_t)BSF_MAX_POINTS);
    size_t i;
    s.angle_increment = 0.001f;
    for (i = 0; i < BSF_MAX_POINTS; ++i) {
        ranges[i] = 2.0f;
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32((uint32_t)BSF_MAX_POINTS, (uint32_t)points.n_valid);
}

static void test_null_arguments_are_refused(void)
{
    bsf_scan_t s = make_scan(3);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(NULL, &points));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, NULL));
    s.ranges = NULL;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_HEX8(0xA5u, points.valid[0]);
}

static void test_bad_geometry_is_refused(void)
{
    bsf_scan_t s;
    ranges[0] = 1.0f;
    ranges[1] = 1.0f;
    s = make_scan(2);
    s.angle_increment = 0.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    s.angle_increment = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    s.angle_increment = 1e30f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    s = make_scan(2);
    s.angle_min = INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    s = make_scan(2);
    s.range_min = -0.5f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    s = make_scan(2);
    s.range_max = s.range_min;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    s.range_max = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_HEX8(0xA5u, points.valid[0]);
}

static void test_negative_increment_scans_clockwise(void)
{
    bsf_scan_t s = make_scan(2);
    s.angle_min = 0.0f;
    s.angle_increment = -1.5707963f;
    ranges[0] = 1.0f;
    ranges[1] = 1.0f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, -1.0f, points.pt[1].y);
}

static void test_empty_and_all_invalid_scans_give_no_points(void)
{
    bsf_scan_t s = make_scan(0);
    s.ranges = NULL;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)points.count);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)points.n_valid);
    s = make_scan(4);
    ranges[0] = NAN;
    ranges[1] = 81.83f;
    ranges[2] = -2.0f;
    ranges[3] = 0.0f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)points.count);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)points.n_valid);
}

static uint32_t bits_of(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

/* The loop's shortcuts (one bound test, fused sin/cos) agree with
 * bsf_range_is_valid and with r * bsf_cosf, r * bsf_sinf, bit for bit, at
 * the edges of every range bound. */
static void test_points_and_validity_match_the_reference_at_every_bound(void)
{
    static const float mins[] = {0.0f, -0.0f, 1.4e-45f, 1.17549435e-38f, 0.1f, 1.0f};
    static const float maxs[] = {30.0f, INFINITY};
    size_t a;
    size_t b;
    for (a = 0; a < sizeof mins / sizeof mins[0]; ++a) {
        for (b = 0; b < sizeof maxs / sizeof maxs[0]; ++b) {
            const float lo = mins[a];
            const float hi = maxs[b];
            const float probe[] = {0.0f,
                                   -0.0f,
                                   1.4e-45f,
                                   2.8e-45f,
                                   lo,
                                   nextafterf(lo, -INFINITY),
                                   nextafterf(lo, INFINITY),
                                   hi,
                                   nextafterf(hi, 0.0f),
                                   INFINITY,
                                   -INFINITY,
                                   NAN,
                                   -1.0f,
                                   5.0f};
            const size_t n = sizeof probe / sizeof probe[0];
            bsf_scan_t s = make_scan(n);
            size_t i;
            s.angle_min = -2.3561945f;
            s.angle_increment = 0.4f;
            s.range_min = lo;
            s.range_max = hi;
            memcpy(ranges, probe, sizeof probe);
            TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
            for (i = 0; i < n; ++i) {
                const float ang = s.angle_min + (float)i * s.angle_increment;
                const int want = bsf_range_is_valid(probe[i], lo, hi);
                TEST_ASSERT_EQUAL_INT(want, points.valid[i] != 0u);
                if (want) {
                    TEST_ASSERT_EQUAL_HEX32(bits_of(probe[i] * bsf_cosf(ang)),
                                            bits_of(points.pt[i].x));
                    TEST_ASSERT_EQUAL_HEX32(bits_of(probe[i] * bsf_sinf(ang)),
                                            bits_of(points.pt[i].y));
                }
            }
        }
    }
}

static void test_status_strings_name_every_code(void)
{
    TEST_ASSERT_EQUAL_STRING("ok", bsf_status_str(BSF_OK));
    TEST_ASSERT_EQUAL_STRING("capacity exceeded", bsf_status_str(BSF_ERR_CAPACITY));
    TEST_ASSERT_EQUAL_STRING("unknown status", bsf_status_str((bsf_status_t)-100));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_valid_readings_become_points_at_their_beam_angle);
    RUN_TEST(test_nan_inf_negative_zero_and_out_of_range_are_invalid);
    RUN_TEST(test_zero_reading_invalid_even_with_zero_range_min);
    RUN_TEST(test_range_bounds_are_half_open);
    RUN_TEST(test_count_above_capacity_is_refused_untouched);
    RUN_TEST(test_count_at_capacity_is_accepted);
    RUN_TEST(test_null_arguments_are_refused);
    RUN_TEST(test_bad_geometry_is_refused);
    RUN_TEST(test_negative_increment_scans_clockwise);
    RUN_TEST(test_empty_and_all_invalid_scans_give_no_points);
    RUN_TEST(test_points_and_validity_match_the_reference_at_every_bound);
    RUN_TEST(test_status_strings_name_every_code);
    return UNITY_END();
}
