/* SPDX-License-Identifier: MIT */
/*
 * Bad-input matrix: every public function of include/bsf/ (every header) fed NULL
 * pointers, empty and maximal counts, counts above the caps, non-finite and
 * out-of-domain values, degenerate geometry and out-of-range parameters.
 * Each case asserts the exact status, and that outputs are either untouched
 * (pre-filled with a sentinel byte pattern) or valid (finite, consistent).
 */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "unity.h"

#define SENTINEL 0xA5u

/* Large working memory is static: the target's stack is small. */
static bsf_points_t points;
static float ranges[BSF_MAX_POINTS + 1];
static bsf_point_t pts[BSF_MAX_POINTS + 1];
static bsf_segment_t segs[BSF_MAX_SEGMENTS + 1];
static bsf_falko_work_t falko_work;
static bsf_bid_work_t bid_work;
static bsf_keypoint_t keypoints[BSF_MAX_KEYPOINTS];
static bsf_pdm_work_t pdm_work;
static bsf_point_t ctrl[BSF_MAX_CTRL_PER_FEATURE];
static uint8_t is_vertex[BSF_MAX_CTRL_PER_FEATURE];
static bsf_extractor_t extractor;
static bsf_result_t result;
static bsf_frame_t frame;
static bsf_decoder_t decoder;
static uint8_t frame_buf[BSF_FRAME_MAX_SIZE];
static uint8_t bytes[2048];
static bsf_encoder_t encoder;

void setUp(void)
{
}

void tearDown(void)
{
}

static void fill(void *p, size_t n)
{
    memset(p, (int)SENTINEL, n);
}

static int untouched(const void *p, size_t n)
{
    const uint8_t *b = (const uint8_t *)p;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (b[i] != SENTINEL) {
            return 0;
        }
    }
    return 1;
}

#define ASSERT_UNTOUCHED(obj)                                                                      \
    TEST_ASSERT_TRUE_MESSAGE(untouched(&(obj), sizeof(obj)), #obj " was written")

static int finite_f(float v)
{
    return v == v && fabsf(v) <= 3.402823466e38f;
}

static bsf_scan_t make_scan(size_t count, float r)
{
    bsf_scan_t s;
    size_t i;
    for (i = 0; i < count && i < BSF_MAX_POINTS + 1u; ++i) {
        ranges[i] = r;
    }
    s.ranges = ranges;
    s.count = count;
    s.angle_min = -2.0f;
    s.angle_increment = 4.0f / 360.0f;
    s.range_min = 0.05f;
    s.range_max = 30.0f;
    return s;
}

/* Points of a straight wall y = 2 seen from the origin, beams 0..n-1. */
static void wall_points(size_t n)
{
    bsf_scan_t s = make_scan(n, 0.0f);
    size_t i;
    s.angle_min = 0.6f;
    s.angle_increment = 1.9f / (float)n;
    for (i = 0; i < n; ++i) {
        ranges[i] = 2.0f / sinf(s.angle_min + (float)i * s.angle_increment);
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
}

/* Every feature of a result is consistent and finite. */
static void assert_result_valid(const bsf_result_t *r)
{
    size_t f;
    size_t k;
    uint32_t sum_points = 0u;
    TEST_ASSERT_TRUE(r->n_features <= BSF_MAX_SEGMENTS);
    TEST_ASSERT_TRUE(r->n_ctrl <= BSF_MAX_CTRL_POINTS);
    for (f = 0; f < r->n_features; ++f) {
        const bsf_feature_t *ft = &r->features[f];
        TEST_ASSERT_TRUE(ft->first_beam <= ft->last_beam);
        TEST_ASSERT_TRUE(ft->last_beam < BSF_MAX_POINTS);
        TEST_ASSERT_TRUE(ft->n_ctrl >= 3u && ft->n_ctrl <= BSF_MAX_CTRL_PER_FEATURE);
        TEST_ASSERT_TRUE((size_t)ft->ctrl_first + ft->n_ctrl <= r->n_ctrl);
        TEST_ASSERT_TRUE(ft->kind <= 1u);
        TEST_ASSERT_TRUE(finite_f(ft->e_curve) && ft->e_curve >= 0.0f);
        sum_points += ft->n_points;
    }
    for (k = 0; k < r->n_ctrl; ++k) {
        TEST_ASSERT_TRUE(finite_f(r->ctrl[k].x) && finite_f(r->ctrl[k].y));
        TEST_ASSERT_TRUE(r->ctrl_is_vertex[k] <= 1u);
    }
    TEST_ASSERT_EQUAL_UINT32(r->n_features, r->stats.n_features);
    TEST_ASSERT_EQUAL_UINT32(r->n_ctrl, r->stats.n_ctrl);
    TEST_ASSERT_EQUAL_UINT32(sum_points, r->stats.n_in_features);
    TEST_ASSERT_TRUE(r->stats.n_in_features <= r->stats.n_valid);
}

/* ---- bsf_common.h --------------------------------------------------------------- */

static void test_status_str_names_every_status_and_unknown_codes(void)
{
    int s;
    for (s = -12; s <= 3; ++s) {
        const char *str = bsf_status_str((bsf_status_t)s);
        TEST_ASSERT_NOT_NULL(str);
        TEST_ASSERT_TRUE(str[0] != '\0');
    }
    TEST_ASSERT_EQUAL_STRING("unknown status", bsf_status_str((bsf_status_t)-100));
}

/* ---- bsf_scan.h ------------------------------------------------------------------- */

static void test_range_is_valid_rejects_nan_inf_negative_and_zero(void)
{
    TEST_ASSERT_FALSE(bsf_range_is_valid(NAN, 0.0f, 30.0f));
    TEST_ASSERT_FALSE(bsf_range_is_valid(INFINITY, 0.0f, INFINITY));
    TEST_ASSERT_FALSE(bsf_range_is_valid(-INFINITY, 0.0f, 30.0f));
    TEST_ASSERT_FALSE(bsf_range_is_valid(-1.0f, 0.0f, 30.0f));
    TEST_ASSERT_FALSE(bsf_range_is_valid(0.0f, 0.0f, 30.0f));
    TEST_ASSERT_FALSE(bsf_range_is_valid(-0.0f, 0.0f, 30.0f));
    TEST_ASSERT_FALSE(bsf_range_is_valid(1.0f, NAN, 30.0f));
    TEST_ASSERT_FALSE(bsf_range_is_valid(1.0f, 0.0f, NAN));
    TEST_ASSERT_TRUE(bsf_range_is_valid(1.0f, 0.0f, INFINITY));
}

static void test_scan_to_points_refuses_null_pointers_and_leaves_out_untouched(void)
{
    bsf_scan_t s = make_scan(10u, 1.0f);
    fill(&points, sizeof points);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(NULL, &points));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, NULL));
    s.ranges = NULL;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    ASSERT_UNTOUCHED(points);
    /* no beams: NULL ranges are fine */
    s.count = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)points.count);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)points.n_valid);
}

static void test_scan_to_points_counts_at_and_above_capacity(void)
{
    bsf_scan_t s = make_scan(BSF_MAX_POINTS + 1u, 3.0f);
    size_t i;
    fill(&points, sizeof points);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_scan_to_points(&s, &points));
    ASSERT_UNTOUCHED(points);
    s.count = (size_t)-1;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_scan_to_points(&s, &points));
    ASSERT_UNTOUCHED(points);
    s.count = BSF_MAX_POINTS;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_POINTS, (uint32_t)points.n_valid);
    for (i = 0; i < BSF_MAX_POINTS; ++i) {
        TEST_ASSERT_TRUE(finite_f(points.pt[i].x) && finite_f(points.pt[i].y));
        TEST_ASSERT_FLOAT_WITHIN(
            1e-4f, 3.0f, sqrtf(points.pt[i].x * points.pt[i].x + points.pt[i].y * points.pt[i].y));
    }
}

static void test_scan_to_points_refuses_bad_geometry_untouched(void)
{
    const float bad_increment[] = {0.0f, -0.0f, NAN, INFINITY, -INFINITY, 1.0e30f, 3.5f, -3.5f};
    const float bad_angle_min[] = {NAN, INFINITY, -INFINITY, 1.0e30f, -100.0f};
    size_t i;
    fill(&points, sizeof points);
    for (i = 0; i < sizeof bad_increment / sizeof bad_increment[0]; ++i) {
        bsf_scan_t s = make_scan(20u, 1.0f);
        s.angle_increment = bad_increment[i];
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    }
    for (i = 0; i < sizeof bad_angle_min / sizeof bad_angle_min[0]; ++i) {
        bsf_scan_t s = make_scan(20u, 1.0f);
        s.angle_min = bad_angle_min[i];
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    }
    {
        bsf_scan_t s = make_scan(20u, 1.0f);
        s.range_min = -0.1f;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
        s.range_min = NAN;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
        s.range_min = INFINITY;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
        s.range_min = 1.0f;
        s.range_max = 1.0f;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
        s.range_max = NAN;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
        s.range_max = -INFINITY;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scan_to_points(&s, &points));
    }
    ASSERT_UNTOUCHED(points);
}

static void test_scan_to_points_marks_nan_inf_negative_zero_ranges_invalid(void)
{
    const float bad[] = {NAN, INFINITY, -INFINITY, -1.0f, 0.0f, -0.0f, 1.0e-30f, 1.0e30f};
    const size_t n_bad = sizeof bad / sizeof bad[0];
    bsf_scan_t s = make_scan(n_bad, 1.0f);
    size_t i;
    memcpy(ranges, bad, sizeof bad);
    s.range_min = 0.0f;
    s.range_max = INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    /* only 1e-30 (> 0 and >= range_min 0) and 1e30 (< inf) are valid */
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)points.n_valid);
    for (i = 0; i < n_bad; ++i) {
        TEST_ASSERT_TRUE(finite_f(points.pt[i].x) && finite_f(points.pt[i].y));
        TEST_ASSERT_TRUE(finite_f(points.range[i]));
        if (i < 6u) {
            TEST_ASSERT_EQUAL_UINT8(0u, points.valid[i]);
            TEST_ASSERT_EQUAL_FLOAT(0.0f, points.range[i]);
        }
    }
}

static void test_scan_to_points_all_invalid_scan_gives_no_valid_point(void)
{
    bsf_scan_t s = make_scan(BSF_MAX_POINTS, NAN);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_POINTS, (uint32_t)points.count);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)points.n_valid);
}

/* ---- bsf_segment.h -------------------------------------------------------------- */

static void test_segment_params_check_refuses_null_and_out_of_range(void)
{
    bsf_sved_params_t sv = bsf_sved_params_default();
    bsf_rpos_params_t rp = bsf_rpos_params_default();
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_sved_params_check(&sv));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_rpos_params_check(&rp));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_sved_params_check(NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_rpos_params_check(NULL));
    sv.a = 0.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_sved_params_check(&sv));
    sv.a = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_sved_params_check(&sv));
    sv.a = INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_sved_params_check(&sv));
    sv = bsf_sved_params_default();
    sv.b = -0.1f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_sved_params_check(&sv));
    sv.b = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_sved_params_check(&sv));
    sv = bsf_sved_params_default();
    sv.min_segment_points = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_sved_params_check(&sv));
    sv.min_segment_points = BSF_MAX_POINTS + 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_sved_params_check(&sv));
    rp.alpha_max = 0.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_rpos_params_check(&rp));
    rp.alpha_max = 3.2f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_rpos_params_check(&rp));
    rp.alpha_max = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_rpos_params_check(&rp));
    rp = bsf_rpos_params_default();
    rp.eta = 0.99f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_rpos_params_check(&rp));
    rp.eta = INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_rpos_params_check(&rp));
    rp = bsf_rpos_params_default();
    rp.min_segment_points = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_rpos_params_check(&rp));
}

static void test_segment_refuses_null_bad_params_and_over_capacity_with_zero_counts(void)
{
    bsf_sved_params_t sv = bsf_sved_params_default();
    bsf_rpos_params_t rp = bsf_rpos_params_default();
    size_t n = 77u;
    size_t wasted = 77u;
    wall_points(50u);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_sved(NULL, NULL, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_sved(&points, NULL, segs, 4u, NULL, &wasted));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_sved(&points, NULL, NULL, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_rpos(NULL, NULL, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_rpos(&points, NULL, segs, 4u, NULL, &wasted));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_rpos(&points, NULL, NULL, 4u, &n, &wasted));
    sv.a = -1.0f;
    n = wasted = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_segment_sved(&points, &sv, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)wasted);
    rp.eta = NAN;
    n = wasted = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_segment_rpos(&points, &rp, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)wasted);
    /* a kept segment but no room for it */
    n = wasted = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_segment_sved(&points, NULL, NULL, 0u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)wasted);
    n = wasted = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_segment_rpos(&points, NULL, NULL, 0u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    /* a points struct claiming more beams than it can hold */
    points.count = BSF_MAX_POINTS + 1u;
    n = wasted = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_segment_sved(&points, NULL, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_segment_rpos(&points, NULL, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
}

static void test_segment_all_invalid_and_empty_scans_give_no_segment(void)
{
    bsf_scan_t s = make_scan(BSF_MAX_POINTS, -1.0f);
    size_t n = 77u;
    size_t wasted = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_segment_sved(&points, NULL, segs, BSF_MAX_SEGMENTS, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)wasted);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_segment_rpos(&points, NULL, segs, BSF_MAX_SEGMENTS, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    s.count = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_segment_sved(&points, NULL, NULL, 0u, &n, NULL));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_segment_rpos(&points, NULL, NULL, 0u, &n, NULL));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
}

static void test_segment_single_point_segments_are_kept_when_allowed(void)
{
    bsf_sved_params_t sv = bsf_sved_params_default();
    bsf_rpos_params_t rp = bsf_rpos_params_default();
    bsf_scan_t s = make_scan(9u, NAN);
    size_t n = 0u;
    size_t wasted = 0u;
    ranges[4] = 2.0f; /* one valid reading among invalid ones */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    sv.min_segment_points = 1u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_segment_sved(&points, &sv, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)wasted);
    TEST_ASSERT_EQUAL_UINT16(4u, segs[0].first);
    TEST_ASSERT_EQUAL_UINT16(4u, segs[0].last);
    TEST_ASSERT_EQUAL_UINT16(1u, segs[0].n_points);
    rp.min_segment_points = 1u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_segment_rpos(&points, &rp, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT16(1u, segs[0].n_points);
    /* with the defaults the lone point is wasted */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_segment_sved(&points, NULL, segs, 4u, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)wasted);
}

/* Sum of the kept points plus the wasted ones is every valid point. */
static void assert_segments_cover(size_t n, size_t wasted)
{
    size_t i;
    size_t kept = 0u;
    for (i = 0; i < n; ++i) {
        TEST_ASSERT_TRUE(segs[i].first <= segs[i].last);
        TEST_ASSERT_TRUE(segs[i].last < points.count);
        TEST_ASSERT_TRUE(points.valid[segs[i].first] && points.valid[segs[i].last]);
        kept += segs[i].n_points;
    }
    TEST_ASSERT_EQUAL_UINT32((uint32_t)points.n_valid, (uint32_t)(kept + wasted));
}

static void test_segment_duplicate_points_stay_together_and_are_counted(void)
{
    size_t i;
    size_t n = 0u;
    size_t wasted = 0u;
    /* every beam the same point: distance 0, spacings 0, no turn defined */
    memset(&points, 0, sizeof points);
    points.count = 40u;
    points.n_valid = 40u;
    points.angle_increment = 0.01f;
    for (i = 0; i < 40u; ++i) {
        points.pt[i].x = 1.0f;
        points.pt[i].y = 1.0f;
        points.range[i] = 1.4142135f;
        points.valid[i] = 1u;
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_segment_sved(&points, NULL, segs, BSF_MAX_SEGMENTS, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    assert_segments_cover(n, wasted);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_segment_rpos(&points, NULL, segs, BSF_MAX_SEGMENTS, &n, &wasted));
    assert_segments_cover(n, wasted);
}

static void test_segment_collinear_wall_is_one_segment(void)
{
    size_t n = 0u;
    size_t wasted = 0u;
    wall_points(200u);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_segment_sved(&points, NULL, segs, BSF_MAX_SEGMENTS, &n, &wasted));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT16(200u, segs[0].n_points);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_segment_rpos(&points, NULL, segs, BSF_MAX_SEGMENTS, &n, &wasted));
    TEST_ASSERT_TRUE(n >= 1u);
    assert_segments_cover(n, wasted);
}

static void test_segment_classify_refuses_bad_input_without_changing_segments(void)
{
    const uint16_t descending[] = {30u, 20u};
    const uint16_t repeated[] = {20u, 20u};
    const uint16_t beyond[] = {10u, 60000u};
    size_t n = 0u;
    wall_points(50u);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_segment_sved(&points, NULL, segs, BSF_MAX_SEGMENTS, &n, NULL));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    {
        const bsf_segment_t before = segs[0];
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_classify(NULL, 1u, &points, NULL, 0u));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_classify(segs, 1u, NULL, NULL, 0u));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_classify(segs, 1u, &points, NULL, 2u));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_classify(segs, 1u, &points, descending, 2u));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_classify(segs, 1u, &points, repeated, 2u));
        segs[1] = segs[0];
        segs[1].first = 40u;
        segs[1].last = 30u;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_classify(segs, 2u, &points, beyond, 1u));
        segs[1].first = 30u;
        segs[1].last = 50u; /* == count */
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_segment_classify(segs, 2u, &points, beyond, 1u));
        TEST_ASSERT_EQUAL_MEMORY(&before, &segs[0], sizeof before);
        points.count = BSF_MAX_POINTS + 1u;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY,
                              bsf_segment_classify(segs, 1u, &points, beyond, 2u));
        TEST_ASSERT_EQUAL_MEMORY(&before, &segs[0], sizeof before);
        points.count = 50u;
    }
    /* interest beams outside the scan are never inside a segment */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_segment_classify(segs, 1u, &points, beyond, 2u));
    TEST_ASSERT_EQUAL_UINT8(BSF_FEATURE_AUXILIARY, segs[0].kind);
    TEST_ASSERT_EQUAL_UINT8(1u, segs[0].n_interest);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_segment_classify(NULL, 0u, &points, NULL, 0u));
}

/* ---- bsf_falko.h ------------------------------------------------------------------ */

static void test_falko_params_check_refuses_null_and_each_out_of_range_field(void)
{
    bsf_falko_params_t p = bsf_falko_params_default();
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_params_check(&p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_params_check(NULL));
#define BAD_FALKO(field, value)                                                                    \
    do {                                                                                           \
        p = bsf_falko_params_default();                                                            \
        p.field = value;                                                                           \
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ERR_PARAM, bsf_falko_params_check(&p), #field);          \
    } while (0)
    BAD_FALKO(min_score_th, -1);
    BAD_FALKO(min_score_th, 101);
    BAD_FALKO(min_range, -1.0f);
    BAD_FALKO(min_range, NAN);
    BAD_FALKO(max_range, 0.0f);
    BAD_FALKO(max_range, INFINITY);
    BAD_FALKO(nms_radius, -0.1f);
    BAD_FALKO(nms_radius, NAN);
    BAD_FALKO(neigh_a, 0.0f);
    BAD_FALKO(neigh_a, INFINITY);
    BAD_FALKO(neigh_b, -0.1f);
    BAD_FALKO(neigh_b, NAN);
    BAD_FALKO(neigh_min_points, 0);
    BAD_FALKO(b_ratio, 0.0f);
    BAD_FALKO(b_ratio, NAN);
    BAD_FALKO(grid_sectors, 1);
    BAD_FALKO(grid_sectors, 65);
#undef BAD_FALKO
}

static void test_falko_detect_refuses_null_and_bad_geometry_with_zero_count(void)
{
    bsf_falko_params_t p = bsf_falko_params_default();
    size_t n = 77u;
    wall_points(100u);
    fill(keypoints, sizeof keypoints);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(NULL, &p, &falko_work, keypoints, 4u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    n = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_falko_detect(&points, NULL, &falko_work, keypoints, 4u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    n = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(&points, &p, NULL, keypoints, 4u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_falko_detect(&points, &p, &falko_work, keypoints, 4u, NULL));
    n = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(&points, &p, &falko_work, NULL, 4u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    points.angle_increment = 0.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_falko_detect(&points, &p, &falko_work, keypoints, 4u, &n));
    points.angle_increment = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_falko_detect(&points, &p, &falko_work, keypoints, 4u, &n));
    points.angle_increment = INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_falko_detect(&points, &p, &falko_work, keypoints, 4u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    points.angle_increment = 0.01f;
    points.count = BSF_MAX_POINTS + 1u;
    n = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY,
                          bsf_falko_detect(&points, &p, &falko_work, keypoints, 4u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    points.count = 100u;
    p.grid_sectors = 0;
    n = 77u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM,
                          bsf_falko_detect(&points, &p, &falko_work, keypoints, 4u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    ASSERT_UNTOUCHED(keypoints);
}

/* Two walls of a room, x = 3 and y = 2, meeting at (3, 2): one clear corner. */
static void corner_points(size_t n)
{
    bsf_scan_t s = make_scan(n, 0.0f);
    size_t i;
    s.angle_min = -1.2f;
    s.angle_increment = 2.4f / (float)n;
    for (i = 0; i < n; ++i) {
        const float a = s.angle_min + (float)i * s.angle_increment;
        const float c = cosf(a);
        const float sn = sinf(a);
        float r = 3.0f / c;
        if (sn > 0.0f && r * sn > 2.0f) {
            r = 2.0f / sn;
        }
        ranges[i] = r;
    }
    s.range_max = 80.0f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
}

static void test_falko_detect_degenerate_scans_give_finite_keypoints_or_none(void)
{
    bsf_falko_params_t p = bsf_falko_params_default();
    size_t n = 77u;
    size_t i;
    /* all invalid */
    bsf_scan_t s = make_scan(BSF_MAX_POINTS, INFINITY);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_falko_detect(&points, &p, &falko_work, keypoints, BSF_MAX_KEYPOINTS, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    /* fewer valid beams than a neighbourhood needs */
    s = make_scan(4u, 2.0f);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_detect(&points, &p, &falko_work, NULL, 0u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    /* a straight wall has no corner */
    wall_points(300u);
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_falko_detect(&points, &p, &falko_work, keypoints, BSF_MAX_KEYPOINTS, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    /* every beam the same point */
    for (i = 0; i < points.count; ++i) {
        points.pt[i].x = 1.0f;
        points.pt[i].y = 2.0f;
        points.range[i] = 2.236068f;
    }
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_falko_detect(&points, &p, &falko_work, keypoints, BSF_MAX_KEYPOINTS, &n));
    TEST_ASSERT_TRUE(n <= BSF_MAX_KEYPOINTS);
    for (i = 0; i < n; ++i) {
        TEST_ASSERT_TRUE(finite_f(keypoints[i].point.x) && finite_f(keypoints[i].point.y));
        TEST_ASSERT_TRUE(finite_f(keypoints[i].orientation) && finite_f(keypoints[i].score));
    }
}

static void test_falko_detect_reports_total_when_out_is_too_small(void)
{
    bsf_falko_params_t p = bsf_falko_params_default();
    size_t n = 0u;
    corner_points(400u);
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_falko_detect(&points, &p, &falko_work, keypoints, BSF_MAX_KEYPOINTS, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_FLOAT_WITHIN(0.05f, 3.0f, keypoints[0].point.x);
    TEST_ASSERT_FLOAT_WITHIN(0.05f, 2.0f, keypoints[0].point.y);
    n = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY,
                          bsf_falko_detect(&points, &p, &falko_work, NULL, 0u, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
}

/* ---- bsf_bid.h ---------------------------------------------------------------------- */

static void test_bid_params_check_refuses_null_and_each_out_of_range_field(void)
{
    bsf_bid_params_t p = bsf_bid_params_default();
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bid_params_check(&p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_params_check(NULL));
#define BAD_BID(field, value)                                                                      \
    do {                                                                                           \
        p = bsf_bid_params_default();                                                              \
        p.field = value;                                                                           \
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ERR_PARAM, bsf_bid_params_check(&p), #field);            \
    } while (0)
    BAD_BID(neigh_a, 0.0f);
    BAD_BID(neigh_a, NAN);
    BAD_BID(neigh_a, 1.0e9f);
    BAD_BID(neigh_b, -1.0f);
    BAD_BID(neigh_b, INFINITY);
    BAD_BID(t_th, 0.0f);
    BAD_BID(t_th, 1.0f);
    BAD_BID(t_th, NAN);
    BAD_BID(nms_radius, -0.1f);
    BAD_BID(min_side_points, 0u);
    BAD_BID(max_iterations, 0u);
    BAD_BID(max_iterations, BSF_PDM_MAX_ITERATIONS + 1u);
    BAD_BID(rel_tol, 0.0f);
    BAD_BID(rel_tol, 1.0f);
#undef BAD_BID
}

static void test_bid_detect_refuses_bad_input_and_handles_degenerate_scans(void)
{
    bsf_bid_params_t p = bsf_bid_params_default();
    size_t n = 77u;
    size_t i;
    wall_points(60u);
    fill(keypoints, sizeof keypoints);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(NULL, &p, &bid_work, keypoints, 4u, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(&points, &p, NULL, keypoints, 4u, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(&points, &p, &bid_work, keypoints, 4u, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(&points, &p, &bid_work, NULL, 4u, &n));
    points.angle_increment = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(&points, &p, &bid_work, keypoints, 4u, &n));
    points.angle_increment = 0.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(&points, &p, &bid_work, keypoints, 4u, &n));
    points.angle_increment = 0.01f;
    p.t_th = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_bid_detect(&points, &p, &bid_work, keypoints, 4u, &n));
    p = bsf_bid_params_default();
    points.count = BSF_MAX_POINTS + 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY,
                          bsf_bid_detect(&points, &p, &bid_work, keypoints, 4u, &n));
    ASSERT_UNTOUCHED(keypoints);
    /* all invalid, then every beam the same point: no crash, finite keypoints */
    {
        bsf_scan_t s = make_scan(200u, NAN);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
        TEST_ASSERT_EQUAL_INT(
            BSF_OK, bsf_bid_detect(&points, NULL, &bid_work, keypoints, BSF_MAX_KEYPOINTS, &n));
        TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    }
    wall_points(60u);
    for (i = 0; i < points.count; ++i) {
        points.pt[i].x = 1.0f;
        points.pt[i].y = 2.0f;
    }
    {
        const bsf_status_t st =
            bsf_bid_detect(&points, NULL, &bid_work, keypoints, BSF_MAX_KEYPOINTS, &n);
        TEST_ASSERT_TRUE(st == BSF_OK || st == BSF_ERR_CAPACITY);
        for (i = 0; i < n && i < BSF_MAX_KEYPOINTS; ++i) {
            TEST_ASSERT_TRUE(finite_f(keypoints[i].point.x) && finite_f(keypoints[i].score));
        }
    }
}

/* ---- bsf_bspline.h -------------------------------------------------------------- */

static void test_bspline_span_and_basis_clamp_bad_arguments(void)
{
    float u = -1.0f;
    float b[3] = {7.0f, 7.0f, 7.0f};
    float d1[3] = {7.0f, 7.0f, 7.0f};
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bsf_bspline_span(2u, 0.5f, &u));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bsf_bspline_span(0u, 0.5f, NULL));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bsf_bspline_span(10u, NAN, &u));
    TEST_ASSERT_TRUE(u >= 0.0f && u <= 1.0f);
    TEST_ASSERT_EQUAL_UINT32(7u, (uint32_t)bsf_bspline_span(10u, INFINITY, &u));
    TEST_ASSERT_TRUE(u >= 0.0f && u <= 1.0f);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bsf_bspline_span(10u, -INFINITY, &u));
    TEST_ASSERT_EQUAL_UINT32(7u, (uint32_t)bsf_bspline_span(10u, 1.0e30f, &u));
    bsf_bspline_basis(2u, 0u, 0.5f, b, d1, NULL);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, b[0] + b[1] + b[2]);
    bsf_bspline_basis(10u, 8u, 0.5f, b, NULL, NULL);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, b[0] + b[1] + b[2]);
    bsf_bspline_basis(10u, 3u, 0.5f, b, d1, NULL);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.0f, b[0] + b[1] + b[2]);
}

/* KNOWN BUG (src/bsf_bspline.c, bsf_bspline_span): for a huge n_ctrl,
 * (float)(n_ctrl - 2) rounds up past SIZE_MAX and the float-to-size_t
 * conversion of t * n_span overflows (undefined behaviour; UBSan flags it).
 * The header promises a span in [0, n_ctrl - 3] for any n_ctrl >= 3. */
static void test_bspline_span_stays_in_range_for_huge_control_point_counts(void)
{
    float u = -1.0f;
    const size_t n = (size_t)-1;
    TEST_ASSERT_TRUE(bsf_bspline_span(n, 1.0f, &u) == n - 3u);
    TEST_ASSERT_TRUE(u >= 0.0f && u <= 1.0f);
    TEST_ASSERT_TRUE(bsf_bspline_span(n, 0.999f, &u) <= n - 3u);
}

static void test_bspline_eval_refuses_bad_arguments_untouched(void)
{
    bsf_point_t c[BSF_MAX_CTRL_PER_FEATURE + 1];
    bsf_point_t pt;
    bsf_point_t d1;
    size_t i;
    for (i = 0; i < BSF_MAX_CTRL_PER_FEATURE + 1u; ++i) {
        c[i].x = (float)i;
        c[i].y = 0.5f * (float)i;
    }
    fill(&pt, sizeof pt);
    fill(&d1, sizeof d1);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bspline_eval(NULL, 4u, 0.5f, &pt, &d1, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bspline_eval(c, 4u, 0.5f, NULL, &d1, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bspline_eval(c, 4u, NAN, &pt, &d1, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bspline_eval(c, 4u, INFINITY, &pt, &d1, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, bsf_bspline_eval(c, 2u, 0.5f, &pt, &d1, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, bsf_bspline_eval(c, 0u, 0.5f, &pt, &d1, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY,
                          bsf_bspline_eval(c, BSF_MAX_CTRL_PER_FEATURE + 1u, 0.5f, &pt, &d1, NULL));
    ASSERT_UNTOUCHED(pt);
    ASSERT_UNTOUCHED(d1);
    /* out-of-range t is clamped to the ends */
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_bspline_eval(c, BSF_MAX_CTRL_PER_FEATURE, -5.0f, &pt, NULL, NULL));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.0f, pt.x);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_bspline_eval(c, BSF_MAX_CTRL_PER_FEATURE, 1.0e30f, &pt, &d1, NULL));
    TEST_ASSERT_FLOAT_WITHIN(1e-4f, (float)(BSF_MAX_CTRL_PER_FEATURE - 1), pt.x);
    TEST_ASSERT_TRUE(finite_f(d1.x) && finite_f(d1.y));
}

/* ---- bsf_fit.h: LSBA ------------------------------------------------------------ */

static void line_pts(size_t n)
{
    size_t i;
    for (i = 0; i < n && i < BSF_MAX_POINTS + 1u; ++i) {
        pts[i].x = 1.0f + 0.01f * (float)i;
        pts[i].y = 2.0f - 0.02f * (float)i;
    }
}

static void test_lsba_refuses_bad_input_untouched(void)
{
    bsf_point_t out[4];
    float e = 0.0f;
    line_pts(BSF_MAX_POINTS + 1u);
    fill(out, sizeof out);
    fill(&e, sizeof e);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_lsba_fit(NULL, 10u, out, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_lsba_fit(pts, 10u, NULL, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, bsf_lsba_fit(pts, 3u, out, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, bsf_lsba_fit(pts, 0u, out, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_lsba_fit(pts, BSF_MAX_POINTS + 1u, out, &e));
    pts[5].x = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_lsba_fit(pts, 10u, out, &e));
    pts[5].x = INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_lsba_fit(pts, 10u, out, &e));
    pts[5].x = 2.0e6f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_lsba_fit(pts, 10u, out, &e));
    {
        size_t i;
        for (i = 0; i < 10u; ++i) {
            pts[i].x = 3.0f;
            pts[i].y = -1.0f;
        }
    }
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, bsf_lsba_fit(pts, 10u, out, &e));
    ASSERT_UNTOUCHED(out);
    ASSERT_UNTOUCHED(e);
}

static void test_lsba_collinear_duplicated_and_maximal_inputs_give_finite_fits(void)
{
    bsf_point_t out[4];
    float e = -1.0f;
    size_t k;
    line_pts(BSF_MAX_POINTS);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_lsba_fit(pts, BSF_MAX_POINTS, out, &e));
    TEST_ASSERT_TRUE(finite_f(e) && e >= 0.0f && e < 1e-3f);
    /* the same points, each twice */
    line_pts(BSF_MAX_POINTS);
    for (k = BSF_MAX_POINTS / 2u; k-- > 0u;) {
        pts[2u * k] = pts[k];
        pts[2u * k + 1u] = pts[k];
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_lsba_fit(pts, 400u, out, &e));
    TEST_ASSERT_TRUE(finite_f(e) && e >= 0.0f && e < 1e-3f);
    /* only two distinct points */
    for (k = 0; k < 10u; ++k) {
        pts[k].x = (k < 5u) ? 0.0f : 1.0f;
        pts[k].y = 0.0f;
    }
    {
        const bsf_status_t st = bsf_lsba_fit(pts, 10u, out, &e);
        TEST_ASSERT_TRUE(st == BSF_OK || st == BSF_ERR_NUMERIC || st == BSF_ERR_DEGENERATE);
        if (st == BSF_OK) {
            for (k = 0; k < 4u; ++k) {
                TEST_ASSERT_TRUE(finite_f(out[k].x) && finite_f(out[k].y));
            }
            TEST_ASSERT_TRUE(finite_f(e));
        }
    }
}

/* ---- bsf_fit.h: PDM ------------------------------------------------------------- */

static void test_pdm_params_check_refuses_null_and_each_out_of_range_field(void)
{
    bsf_pdm_params_t p;
    bsf_pdm_params_default(&p);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_pdm_params_check(&p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_pdm_params_check(NULL));
#define BAD_PDM(field, value)                                                                      \
    do {                                                                                           \
        bsf_pdm_params_default(&p);                                                                \
        p.field = value;                                                                           \
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ERR_PARAM, bsf_pdm_params_check(&p), #field);            \
    } while (0)
    BAD_PDM(precision_spacing, 0.0f);
    BAD_PDM(precision_spacing, NAN);
    BAD_PDM(lambda_per_metre, -1.0e-6f);
    BAD_PDM(lambda_per_metre, 1.5f);
    BAD_PDM(lambda_per_metre, NAN);
    BAD_PDM(rel_tol, 0.0f);
    BAD_PDM(rel_tol, 1.0f);
    BAD_PDM(target_rms, 0.0f);
    BAD_PDM(target_rms, INFINITY);
    BAD_PDM(max_iterations, 0u);
    BAD_PDM(max_iterations, BSF_PDM_MAX_ITERATIONS + 1u);
    BAD_PDM(max_ctrl, 2u);
    BAD_PDM(max_ctrl, BSF_MAX_CTRL_PER_FEATURE + 1u);
    BAD_PDM(footpoint_steps, 0u);
    BAD_PDM(footpoint_steps, 9u);
    BAD_PDM(refine, 2u);
    BAD_PDM(bias_window, 1u);
    BAD_PDM(bias_window, BSF_PDM_MAX_BIAS_WINDOW + 1u);
    BAD_PDM(bias_ratio, 0.0f);
    BAD_PDM(bias_ratio, 1.5f);
    BAD_PDM(bias_ratio, NAN);
#undef BAD_PDM
}

static bsf_status_t pdm(size_t n, const uint16_t *vpos, size_t nv, const bsf_pdm_params_t *p,
                        size_t cap, size_t *n_ctrl, float *e)
{
    return bsf_pdm_fit(pts, n, vpos, nv, p, &pdm_work, ctrl, is_vertex, cap, n_ctrl, e, NULL);
}

static void test_pdm_refuses_bad_input_untouched(void)
{
    const uint16_t v_low[] = {1u};
    const uint16_t v_high[] = {18u};
    const uint16_t v_desc[] = {10u, 5u};
    uint16_t v_many[BSF_PDM_MAX_VERTICES + 1];
    bsf_pdm_params_t p;
    size_t n_ctrl = 0u;
    float e = 0.0f;
    size_t i;
    for (i = 0; i < BSF_PDM_MAX_VERTICES + 1u; ++i) {
        v_many[i] = (uint16_t)(2u + 2u * i);
    }
    line_pts(BSF_MAX_POINTS + 1u);
    fill(ctrl, sizeof ctrl);
    fill(is_vertex, sizeof is_vertex);
    fill(&n_ctrl, sizeof n_ctrl);
    fill(&e, sizeof e);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_pdm_fit(NULL, 20u, NULL, 0u, NULL, &pdm_work, ctrl,
                                                   is_vertex, 32u, &n_ctrl, &e, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_pdm_fit(pts, 20u, NULL, 0u, NULL, NULL, ctrl, is_vertex,
                                                   32u, &n_ctrl, &e, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_pdm_fit(pts, 20u, NULL, 0u, NULL, &pdm_work, NULL,
                                                   is_vertex, 32u, &n_ctrl, &e, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_pdm_fit(pts, 20u, NULL, 0u, NULL, &pdm_work, ctrl,
                                                   is_vertex, 32u, NULL, &e, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, pdm(20u, NULL, 1u, NULL, 32u, &n_ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, pdm(20u, v_low, 1u, NULL, 32u, &n_ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, pdm(20u, v_high, 1u, NULL, 32u, &n_ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, pdm(20u, v_desc, 2u, NULL, 32u, &n_ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY,
                          pdm(200u, v_many, BSF_PDM_MAX_VERTICES + 1u, NULL, 64u, &n_ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, pdm(2u, NULL, 0u, NULL, 32u, &n_ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, pdm(0u, NULL, 0u, NULL, 32u, &n_ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY,
                          pdm(BSF_MAX_POINTS + 1u, NULL, 0u, NULL, 32u, &n_ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER, pdm(20u, NULL, 0u, NULL, 2u, &n_ctrl, &e));
    bsf_pdm_params_default(&p);
    p.rel_tol = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, pdm(20u, NULL, 0u, &p, 32u, &n_ctrl, &e));
    pts[7].y = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, pdm(20u, NULL, 0u, NULL, 32u, &n_ctrl, &e));
    pts[7].y = -INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, pdm(20u, NULL, 0u, NULL, 32u, &n_ctrl, &e));
    pts[7].y = -1.0e7f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, pdm(20u, NULL, 0u, NULL, 32u, &n_ctrl, &e));
    for (i = 0; i < 20u; ++i) {
        pts[i].x = -4.0f;
        pts[i].y = 4.0f;
    }
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, pdm(20u, NULL, 0u, NULL, 32u, &n_ctrl, &e));
    ASSERT_UNTOUCHED(ctrl);
    ASSERT_UNTOUCHED(is_vertex);
    ASSERT_UNTOUCHED(n_ctrl);
    ASSERT_UNTOUCHED(e);
}

static void assert_pdm_output_valid(size_t n_ctrl, float e)
{
    size_t k;
    TEST_ASSERT_TRUE(n_ctrl >= 3u && n_ctrl <= BSF_MAX_CTRL_PER_FEATURE);
    for (k = 0; k < n_ctrl; ++k) {
        TEST_ASSERT_TRUE(finite_f(ctrl[k].x) && finite_f(ctrl[k].y));
        TEST_ASSERT_TRUE(is_vertex[k] <= 1u);
    }
    TEST_ASSERT_TRUE(finite_f(e) && e >= 0.0f);
}

static void test_pdm_collinear_duplicated_and_maximal_inputs_give_finite_fits(void)
{
    const uint16_t v_mid[] = {100u};
    size_t n_ctrl = 0u;
    float e = -1.0f;
    size_t k;
    line_pts(BSF_MAX_POINTS);
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, pdm(BSF_MAX_POINTS, NULL, 0u, NULL, BSF_MAX_CTRL_PER_FEATURE, &n_ctrl, &e));
    assert_pdm_output_valid(n_ctrl, e);
    TEST_ASSERT_TRUE(e < 1e-3f);
    /* a "vertex" on a straight line */
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          pdm(200u, v_mid, 1u, NULL, BSF_MAX_CTRL_PER_FEATURE, &n_ctrl, &e));
    assert_pdm_output_valid(n_ctrl, e);
    /* each point twice */
    for (k = 100u; k-- > 0u;) {
        pts[2u * k] = pts[k];
        pts[2u * k + 1u] = pts[k];
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, pdm(200u, NULL, 0u, NULL, BSF_MAX_CTRL_PER_FEATURE, &n_ctrl, &e));
    assert_pdm_output_valid(n_ctrl, e);
    /* three points, the minimum */
    line_pts(3u);
    TEST_ASSERT_EQUAL_INT(BSF_OK, pdm(3u, NULL, 0u, NULL, BSF_MAX_CTRL_PER_FEATURE, &n_ctrl, &e));
    assert_pdm_output_valid(n_ctrl, e);
}

/* ---- bsf_metrics.h -------------------------------------------------------------- */

static bsf_scan_counts_t counts(uint32_t n_valid, uint32_t in_f, uint32_t n_ctrl, uint32_t n_f,
                                float sum_e, float time_s)
{
    bsf_scan_counts_t c;
    memset(&c, 0, sizeof c);
    c.n_valid = n_valid;
    c.n_in_features = in_f;
    c.n_ctrl = n_ctrl;
    c.n_features = n_f;
    c.sum_e_curve = sum_e;
    c.time_s = time_s;
    return c;
}

static void test_metrics_scan_refuses_null_and_inconsistent_counts_untouched(void)
{
    bsf_scan_counts_t c = counts(100u, 50u, 10u, 2u, 0.01f, 0.001f);
    bsf_scan_metrics_t m;
    fill(&m, sizeof m);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(NULL, &m));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, NULL));
    c.n_in_features = 101u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    c = counts(100u, 50u, 10u, 2u, NAN, 0.001f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    c.sum_e_curve = -0.5f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    c.sum_e_curve = INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    ASSERT_UNTOUCHED(m);
}

static void test_metrics_scan_zero_counts_and_bad_time_give_undefined_not_nan(void)
{
    bsf_scan_counts_t c = counts(0u, 0u, 0u, 0u, 0.0f, NAN);
    bsf_scan_metrics_t m;
    /* a NaN time is corrupt input, not "not measured" */
    fill(&m, sizeof m);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    ASSERT_UNTOUCHED(m);
    /* control points or feature points without a feature are inconsistent */
    c = counts(10u, 5u, 0u, 0u, 0.0f, -1.0f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    c = counts(10u, 0u, 3u, 0u, 0.0f, -1.0f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    ASSERT_UNTOUCHED(m);
    c = counts(0u, 0u, 0u, 0u, 0.0f, -1.0f);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_scan(&c, &m));
    TEST_ASSERT_EQUAL_UINT8(0u, m.has_retrievability);
    TEST_ASSERT_EQUAL_UINT8(0u, m.has_compactness);
    TEST_ASSERT_EQUAL_UINT8(0u, m.has_accuracy);
    TEST_ASSERT_EQUAL_UINT8(0u, m.has_time);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, m.retrievability + m.compactness + m.accuracy + m.time_s);
    c = counts(0xFFFFFFFFu, 0xFFFFFFFFu, 0xFFFFFFFFu, 0xFFFFFFFFu, 3.0e38f, INFINITY);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_scan(&c, &m));
    TEST_ASSERT_EQUAL_UINT8(0u, m.has_time);
    TEST_ASSERT_TRUE(finite_f(m.retrievability) && finite_f(m.compactness) &&
                     finite_f(m.accuracy) && finite_f(m.time_s));
    c.time_s = -1.0f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_scan(&c, &m));
    TEST_ASSERT_EQUAL_UINT8(0u, m.has_time);
}

static void test_metrics_accumulator_refuses_bad_input_and_keeps_state_on_capacity(void)
{
    static float samples[2];
    bsf_metrics_acc_t acc;
    bsf_metrics_acc_t before;
    bsf_metrics_summary_t s;
    const bsf_scan_counts_t good = counts(100u, 50u, 10u, 2u, 0.01f, 0.002f);
    const bsf_scan_counts_t bad = counts(10u, 50u, 10u, 2u, 0.01f, 0.002f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_acc_init(NULL, samples, 2u));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_acc_init(&acc, NULL, 2u));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, samples, 2u));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_acc_add(NULL, &good));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_acc_add(&acc, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_acc_add(&acc, &bad));
    TEST_ASSERT_EQUAL_UINT32(0u, acc.n_scans);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &good));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &good));
    before = acc;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_metrics_acc_add(&acc, &good));
    TEST_ASSERT_EQUAL_MEMORY(&before, &acc, sizeof acc);
    fill(&s, sizeof s);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_acc_summary(NULL, &s));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_acc_summary(&acc, NULL));
    ASSERT_UNTOUCHED(s);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_summary(&acc, &s));
    TEST_ASSERT_EQUAL_UINT32(2u, s.n_scans);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.002f, s.time_p99_s);
    /* an empty accumulator: everything 0, nothing NaN */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, NULL, 0u));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_summary(&acc, &s));
    TEST_ASSERT_EQUAL_UINT32(0u, s.n_scans);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, s.retrievability + s.compactness + s.accuracy + s.time_mean_s +
                                      s.time_median_s + s.time_p99_s + s.features_per_scan +
                                      s.ctrl_per_scan);
}

/* ---- bsf_extract.h -------------------------------------------------------------- */

static void test_method_names_and_params_refuse_unknown_values(void)
{
    bsf_params_t p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    TEST_ASSERT_NULL(bsf_method_name(BSF_METHOD_COUNT));
    TEST_ASSERT_NULL(bsf_method_name((bsf_method_t)-1));
    TEST_ASSERT_EQUAL_INT(BSF_METHOD_COUNT, bsf_method_from_name(NULL));
    TEST_ASSERT_EQUAL_INT(BSF_METHOD_COUNT, bsf_method_from_name(""));
    TEST_ASSERT_EQUAL_INT(BSF_METHOD_COUNT, bsf_method_from_name("FALKO-SVED-PDM"));
    TEST_ASSERT_EQUAL_INT(BSF_METHOD_RPOS_LSBA, bsf_method_from_name("rpos-lsba"));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_params_check(&p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_params_check(NULL));
    p.method = BSF_METHOD_COUNT;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_params_check(&p));
    p.method = (bsf_method_t)99;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_params_check(&p));
    p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    p.clock_hz = 0u;
    p.clock = (bsf_clock_fn)0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_params_check(&p));
    p.falko.neigh_a = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_params_check(&p));
    p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    p.sved.b = -1.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_params_check(&p));
    p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    p.pdm.max_ctrl = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_params_check(&p));
    p = bsf_params_default(BSF_METHOD_RPOS_LSBA);
    p.rpos.alpha_max = -1.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_params_check(&p));
}

static uint32_t fake_clock(void *user)
{
    uint32_t *t = (uint32_t *)user;
    *t += 1000u;
    return *t;
}

static void test_extractor_init_refuses_bad_params_and_extract_then_refuses_it(void)
{
    static uint32_t ticks;
    bsf_params_t p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    bsf_scan_t s = make_scan(100u, 2.0f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extractor_init(NULL, &p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extractor_init(&extractor, NULL));
    p.clock = fake_clock;
    p.clock_user = &ticks;
    p.clock_hz = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_extractor_init(&extractor, &p));
    fill(&result, sizeof result);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(&extractor, &s, &result));
    TEST_ASSERT_EQUAL_UINT16(0u, result.n_features);
    TEST_ASSERT_EQUAL_UINT16(0u, result.n_ctrl);
    /* never initialised at all */
    fill(&extractor, sizeof extractor);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(&extractor, &s, &result));
    p = bsf_params_default(BSF_METHOD_BID_SVED_PDM);
    p.bid.t_th = 1.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_extractor_init(&extractor, &p));
    p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&extractor, &p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(NULL, &s, &result));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(&extractor, NULL, &result));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(&extractor, &s, NULL));
}

static void assert_cleared(const bsf_result_t *r)
{
    static const bsf_stats_t zero;
    TEST_ASSERT_EQUAL_UINT16(0u, r->n_features);
    TEST_ASSERT_EQUAL_UINT16(0u, r->n_ctrl);
    TEST_ASSERT_EQUAL_MEMORY(&zero, &r->stats, sizeof zero);
}

static void test_extract_refuses_bad_scans_with_a_cleared_result(void)
{
    const float bad_inc[] = {0.0f, NAN, INFINITY, 1.0e30f};
    bsf_params_t p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    bsf_scan_t s;
    size_t i;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&extractor, &p));
    for (i = 0; i < sizeof bad_inc / sizeof bad_inc[0]; ++i) {
        s = make_scan(100u, 2.0f);
        s.angle_increment = bad_inc[i];
        fill(&result, sizeof result);
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(&extractor, &s, &result));
        assert_cleared(&result);
    }
    s = make_scan(100u, 2.0f);
    s.ranges = NULL;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(&extractor, &s, &result));
    assert_cleared(&result);
    s = make_scan(100u, 2.0f);
    s.range_max = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_extract(&extractor, &s, &result));
    assert_cleared(&result);
    s = make_scan(BSF_MAX_POINTS + 1u, 2.0f);
    fill(&result, sizeof result);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_extract(&extractor, &s, &result));
    assert_cleared(&result);
}

static void test_extract_empty_invalid_and_degenerate_scans_for_each_method(void)
{
    const bsf_method_t methods[] = {BSF_METHOD_FALKO_SVED_PDM, BSF_METHOD_RPOS_LSBA};
    const float fills[] = {NAN, INFINITY, -1.0f, 0.0f, 2.0f};
    size_t m;
    size_t k;
    for (m = 0; m < sizeof methods / sizeof methods[0]; ++m) {
        bsf_params_t p = bsf_params_default(methods[m]);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&extractor, &p));
        for (k = 0; k < sizeof fills / sizeof fills[0]; ++k) {
            bsf_scan_t s = make_scan(BSF_MAX_POINTS, fills[k]);
            fill(&result, sizeof result);
            TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&extractor, &s, &result));
            assert_result_valid(&result);
            if (k < 4u) {
                TEST_ASSERT_EQUAL_UINT16(0u, result.n_features);
                TEST_ASSERT_EQUAL_UINT32(0u, result.stats.n_valid);
            } else {
                /* an arc of constant range: one smooth feature */
                TEST_ASSERT_EQUAL_UINT32(BSF_MAX_POINTS, result.stats.n_valid);
            }
        }
        /* no beams at all */
        {
            bsf_scan_t s = make_scan(0u, 1.0f);
            s.ranges = NULL;
            TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&extractor, &s, &result));
            TEST_ASSERT_EQUAL_UINT16(0u, result.n_features);
        }
        /* a single valid beam */
        {
            bsf_scan_t s = make_scan(50u, NAN);
            ranges[25] = 3.0f;
            TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&extractor, &s, &result));
            TEST_ASSERT_EQUAL_UINT16(0u, result.n_features);
            TEST_ASSERT_EQUAL_UINT32(1u, result.stats.n_valid);
        }
        /* extreme but finite ranges alternate: every point its own segment */
        {
            bsf_scan_t s = make_scan(BSF_MAX_POINTS, 0.0f);
            s.range_min = 0.0f;
            s.range_max = INFINITY;
            for (k = 0; k < BSF_MAX_POINTS; ++k) {
                ranges[k] = (k & 1u) ? 1.0e-20f : 1.0e20f;
            }
            fill(&result, sizeof result);
            {
                const bsf_status_t st = bsf_extract(&extractor, &s, &result);
                TEST_ASSERT_TRUE(st == BSF_OK || st == BSF_ERR_CAPACITY);
                if (st == BSF_OK) {
                    assert_result_valid(&result);
                } else {
                    assert_cleared(&result);
                }
            }
        }
    }
}

static void test_extract_maximal_scan_of_an_l_corner_gives_valid_features(void)
{
    bsf_params_t p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&extractor, &p));
    corner_points(BSF_MAX_POINTS);
    {
        bsf_scan_t s = make_scan(BSF_MAX_POINTS, 0.0f);
        size_t i;
        s.angle_min = -1.2f;
        s.angle_increment = 2.4f / (float)BSF_MAX_POINTS;
        s.range_max = 80.0f;
        for (i = 0; i < BSF_MAX_POINTS; ++i) {
            ranges[i] = points.range[i];
        }
        fill(&result, sizeof result);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&extractor, &s, &result));
    }
    assert_result_valid(&result);
    TEST_ASSERT_TRUE(result.n_features >= 1u);
    TEST_ASSERT_EQUAL_UINT32(1u, result.stats.n_keypoints);
}

/* ---- bsf_stream.h ----------------------------------------------------------------- */

static void test_crc_and_cobs_refuse_null_and_report_small_buffers(void)
{
    const uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    const uint8_t data[] = {1u, 0u, 2u, 0u};
    uint8_t out[16];
    size_t len = 77u;
    TEST_ASSERT_EQUAL_HEX32(0u, bsf_crc32c(0u, NULL, 0u));
    TEST_ASSERT_EQUAL_HEX32(0xE3069283u, bsf_crc32c(0u, check, sizeof check));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_cobs_encode(NULL, 4u, out, sizeof out, &len));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_cobs_encode(data, 4u, NULL, sizeof out, &len));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_cobs_encode(data, 4u, out, sizeof out, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER, bsf_cobs_encode(data, 4u, out, 2u, &len));
    TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)len);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(NULL, 0u, out, sizeof out, &len));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)len);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(data, 4u, out, sizeof out, &len));
    TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)len);
    {
        uint8_t dec[16];
        uint8_t enc[5];
        size_t dlen = 77u;
        memcpy(enc, out, sizeof enc);
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_cobs_decode(NULL, 5u, dec, sizeof dec, &dlen));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_cobs_decode(enc, 5u, NULL, sizeof dec, &dlen));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_cobs_decode(enc, 5u, dec, sizeof dec, NULL));
        TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER, bsf_cobs_decode(enc, 5u, dec, 2u, &dlen));
        /* ends inside the second block (a prefix ending at a block end is valid) */
        TEST_ASSERT_EQUAL_INT(BSF_ERR_FORMAT, bsf_cobs_decode(enc, 3u, dec, sizeof dec, &dlen));
        enc[2] = 0u;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_FORMAT, bsf_cobs_decode(enc, 5u, dec, sizeof dec, &dlen));
        enc[0] = 200u; /* block longer than the input */
        enc[2] = 2u;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_FORMAT, bsf_cobs_decode(enc, 5u, dec, sizeof dec, &dlen));
    }
}

/* A small valid result: one feature of three control points. */
static void small_result(void)
{
    memset(&result, 0, sizeof result);
    result.n_features = 1u;
    result.n_ctrl = 3u;
    result.features[0].first_beam = 10u;
    result.features[0].last_beam = 20u;
    result.features[0].n_points = 11u;
    result.features[0].ctrl_first = 0u;
    result.features[0].n_ctrl = 3u;
    result.features[0].kind = BSF_FEATURE_BLEAK;
    result.features[0].e_curve = 0.01f;
    result.ctrl[0].x = 1.0f;
    result.ctrl[1].x = 1.5f;
    result.ctrl[1].y = 0.5f;
    result.ctrl[2].x = 2.0f;
    result.stats.n_valid = 100u;
    result.stats.n_in_features = 11u;
    result.stats.n_ctrl = 3u;
    result.stats.n_features = 1u;
}

static void test_frame_encode_refuses_unrepresentable_input_without_writing(void)
{
    bsf_frame_info_t info;
    size_t len = 0u;
    bsf_frame_info_init(&info);
    small_result();
    fill(frame_buf, sizeof frame_buf);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(NULL, &result, frame_buf, 64u, &len));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(&info, NULL, frame_buf, 64u, &len));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(&info, &result, frame_buf, 64u, NULL));
#define BAD_ENCODE(expect, stmt)                                                                   \
    do {                                                                                           \
        bsf_frame_info_init(&info);                                                                \
        small_result();                                                                            \
        stmt;                                                                                      \
        TEST_ASSERT_EQUAL_INT_MESSAGE(                                                             \
            expect, bsf_frame_encode(&info, &result, frame_buf, 64u, &len), #stmt);                \
    } while (0)
    BAD_ENCODE(BSF_ERR_ARG, result.ctrl[1].x = NAN);
    BAD_ENCODE(BSF_ERR_ARG, result.ctrl[1].y = -INFINITY);
    BAD_ENCODE(BSF_ERR_ARG, result.ctrl[1].y = 1.0e6f);
    BAD_ENCODE(BSF_ERR_ARG, info.quant_step = 0.0f);
    BAD_ENCODE(BSF_ERR_ARG, info.quant_step = NAN);
    BAD_ENCODE(BSF_ERR_ARG, info.quant_step = 2.0f);
    BAD_ENCODE(BSF_ERR_ARG, (info.has_pose = 1u, info.pose.x = NAN));
    BAD_ENCODE(BSF_ERR_ARG, (info.has_pose = 1u, info.pose.y = 3.0e6f));
    BAD_ENCODE(BSF_ERR_ARG, (info.has_pose = 1u, info.pose.theta = 30.0f));
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].e_curve = NAN);
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].e_curve = 2000.0f);
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].n_ctrl = 2u);
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].n_ctrl = BSF_MAX_CTRL_PER_FEATURE + 1u);
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].ctrl_first = 1u);
    BAD_ENCODE(BSF_ERR_ARG, result.ctrl_is_vertex[1] = 1u);
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].first_beam = 21u);
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].last_beam = BSF_MAX_POINTS);
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].n_points = 12u);
    BAD_ENCODE(BSF_ERR_ARG, result.features[0].kind = 2u);
    BAD_ENCODE(BSF_ERR_ARG, result.stats.n_valid = BSF_MAX_POINTS + 1u);
    BAD_ENCODE(BSF_ERR_ARG, result.stats.n_valid = 10u);
    BAD_ENCODE(BSF_ERR_CAPACITY, result.n_features = BSF_MAX_SEGMENTS + 1u);
    BAD_ENCODE(BSF_ERR_CAPACITY, result.n_ctrl = BSF_MAX_CTRL_POINTS + 1u);
#undef BAD_ENCODE
    bsf_frame_info_init(&info);
    small_result();
    len = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &result, NULL, 0u, &len));
    TEST_ASSERT_TRUE(len > 5u && len <= BSF_FRAME_MAX_SIZE);
    {
        size_t need = 0u;
        TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER,
                              bsf_frame_encode(&info, &result, frame_buf, len - 1u, &need));
        TEST_ASSERT_EQUAL_UINT32((uint32_t)len, (uint32_t)need);
    }
    ASSERT_UNTOUCHED(frame_buf);
    /* an empty result is a valid frame */
    memset(&result, 0, sizeof result);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_frame_encode(&info, &result, frame_buf, sizeof frame_buf, &len));
    TEST_ASSERT_EQUAL_UINT8(0u, frame_buf[len - 1u]);
}

typedef struct {
    size_t calls;
    size_t bytes;
    size_t fail_at; /* call number that fails, 0: never */
} sink_state_t;

static int counting_sink(void *ctx, const uint8_t *data, size_t len)
{
    sink_state_t *s = (sink_state_t *)ctx;
    (void)data;
    s->calls++;
    s->bytes += len;
    return (s->fail_at != 0u && s->calls >= s->fail_at) ? 1 : 0;
}

static void test_frame_encode_sink_refuses_null_and_reports_a_failing_sink(void)
{
    bsf_frame_info_t info;
    sink_state_t st = {0u, 0u, 0u};
    size_t written = 77u;
    size_t len = 0u;
    bsf_frame_info_init(&info);
    small_result();
    TEST_ASSERT_EQUAL_INT(
        BSF_ERR_ARG, bsf_frame_encode_sink(NULL, &info, &result, counting_sink, &st, &written));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_frame_encode_sink(&encoder, &info, &result, NULL, &st, &written));
    TEST_ASSERT_EQUAL_INT(
        BSF_ERR_ARG, bsf_frame_encode_sink(&encoder, NULL, &result, counting_sink, &st, &written));
    TEST_ASSERT_EQUAL_INT(
        BSF_ERR_ARG, bsf_frame_encode_sink(&encoder, &info, NULL, counting_sink, &st, &written));
    result.ctrl[0].x = NAN;
    TEST_ASSERT_EQUAL_INT(
        BSF_ERR_ARG, bsf_frame_encode_sink(&encoder, &info, &result, counting_sink, &st, &written));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)st.calls);
    small_result();
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &result, NULL, 0u, &len));
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_frame_encode_sink(&encoder, &info, &result, counting_sink, &st, NULL));
    TEST_ASSERT_EQUAL_UINT32((uint32_t)len, (uint32_t)st.bytes);
    st.calls = 0u;
    st.bytes = 0u;
    st.fail_at = 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER, bsf_frame_encode_sink(&encoder, &info, &result,
                                                                counting_sink, &st, &written));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)st.calls);
}

static size_t encode_small_body(uint8_t *body)
{
    /* payload || CRC: COBS-decode a valid frame */
    bsf_frame_info_t info;
    size_t len = 0u;
    size_t blen = 0u;
    bsf_frame_info_init(&info);
    small_result();
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_frame_encode(&info, &result, frame_buf, sizeof frame_buf, &len));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_decode(frame_buf, len - 1u, body, sizeof bytes, &blen));
    return blen;
}

static void test_frame_decode_refuses_short_corrupt_and_unknown_frames_untouched(void)
{
    const size_t blen = encode_small_body(bytes);
    fill(&frame, sizeof frame);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_decode(NULL, blen, &frame));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_decode(bytes, blen, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CRC, bsf_frame_decode(bytes, 0u, &frame));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CRC, bsf_frame_decode(bytes, 4u, &frame));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CRC, bsf_frame_decode(bytes, blen - 1u, &frame));
    bytes[3] ^= 0x10u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CRC, bsf_frame_decode(bytes, blen, &frame));
    bytes[3] ^= 0x10u;
    {
        /* a version after BSF_FORMAT_VERSION, with a CRC that matches */
        uint32_t crc;
        bytes[0] = (uint8_t)(((BSF_FORMAT_VERSION + 1u) << 4) | BSF_FRAME_TYPE_FEATURES);
        crc = bsf_crc32c(0u, bytes, blen - 4u);
        bytes[blen - 4u] = (uint8_t)crc;
        bytes[blen - 3u] = (uint8_t)(crc >> 8);
        bytes[blen - 2u] = (uint8_t)(crc >> 16);
        bytes[blen - 1u] = (uint8_t)(crc >> 24);
        TEST_ASSERT_EQUAL_INT(BSF_ERR_VERSION, bsf_frame_decode(bytes, blen, &frame));
    }
    ASSERT_UNTOUCHED(frame);
    encode_small_body(bytes);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_decode(bytes, blen, &frame));
    TEST_ASSERT_EQUAL_UINT16(1u, frame.result.n_features);
}

static void test_decoder_feed_refuses_null_and_survives_garbage_and_oversize(void)
{
    size_t used = 77u;
    size_t i;
    int r;
    bsf_decoder_init(&decoder);
    fill(&frame, sizeof frame);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_decoder_feed(NULL, bytes, 4u, &used, &frame));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_decoder_feed(&decoder, NULL, 4u, &used, &frame));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_decoder_feed(&decoder, bytes, 4u, NULL, &frame));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_decoder_feed(&decoder, bytes, 4u, &used, NULL));
    TEST_ASSERT_EQUAL_INT(0, bsf_decoder_feed(&decoder, NULL, 0u, &used, &frame));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)used);
    /* empty frames and garbage frames */
    for (i = 0; i < sizeof bytes; ++i) {
        bytes[i] = (uint8_t)((i * 37u + 11u) % 7u == 0u ? 0u : (i * 91u) & 0xFFu);
    }
    r = bsf_decoder_feed(&decoder, bytes, sizeof bytes, &used, &frame);
    TEST_ASSERT_EQUAL_INT(0, r);
    TEST_ASSERT_EQUAL_UINT32(sizeof bytes, (uint32_t)used);
    TEST_ASSERT_EQUAL_UINT32(0u, decoder.stats.frames_ok);
    TEST_ASSERT_TRUE(decoder.stats.bad_crc + decoder.stats.malformed > 0u);
    /* a frame longer than the largest body */
    memset(bytes, 0x55, sizeof bytes);
    for (i = 0; i <= BSF_FRAME_MAX_SIZE / sizeof bytes + 1u; ++i) {
        r = bsf_decoder_feed(&decoder, bytes, sizeof bytes, &used, &frame);
        TEST_ASSERT_EQUAL_INT(0, r);
    }
    bytes[0] = 0u;
    r = bsf_decoder_feed(&decoder, bytes, 1u, &used, &frame);
    TEST_ASSERT_EQUAL_INT(0, r);
    TEST_ASSERT_EQUAL_UINT32(1u, decoder.stats.oversize);
    ASSERT_UNTOUCHED(frame);
    /* still in step: a valid frame right after is delivered */
    {
        bsf_frame_info_t info;
        size_t len = 0u;
        bsf_frame_info_init(&info);
        small_result();
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_frame_encode(&info, &result, frame_buf, sizeof frame_buf, &len));
        r = bsf_decoder_feed(&decoder, frame_buf, len, &used, &frame);
        TEST_ASSERT_EQUAL_INT(1, r);
        TEST_ASSERT_EQUAL_UINT32((uint32_t)len, (uint32_t)used);
        TEST_ASSERT_EQUAL_UINT32(1u, decoder.stats.frames_ok);
        TEST_ASSERT_EQUAL_FLOAT(1.5f, frame.result.ctrl[1].x);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_status_str_names_every_status_and_unknown_codes);
    RUN_TEST(test_range_is_valid_rejects_nan_inf_negative_and_zero);
    RUN_TEST(test_scan_to_points_refuses_null_pointers_and_leaves_out_untouched);
    RUN_TEST(test_scan_to_points_counts_at_and_above_capacity);
    RUN_TEST(test_scan_to_points_refuses_bad_geometry_untouched);
    RUN_TEST(test_scan_to_points_marks_nan_inf_negative_zero_ranges_invalid);
    RUN_TEST(test_scan_to_points_all_invalid_scan_gives_no_valid_point);
    RUN_TEST(test_segment_params_check_refuses_null_and_out_of_range);
    RUN_TEST(test_segment_refuses_null_bad_params_and_over_capacity_with_zero_counts);
    RUN_TEST(test_segment_all_invalid_and_empty_scans_give_no_segment);
    RUN_TEST(test_segment_single_point_segments_are_kept_when_allowed);
    RUN_TEST(test_segment_duplicate_points_stay_together_and_are_counted);
    RUN_TEST(test_segment_collinear_wall_is_one_segment);
    RUN_TEST(test_segment_classify_refuses_bad_input_without_changing_segments);
    RUN_TEST(test_falko_params_check_refuses_null_and_each_out_of_range_field);
    RUN_TEST(test_falko_detect_refuses_null_and_bad_geometry_with_zero_count);
    RUN_TEST(test_falko_detect_degenerate_scans_give_finite_keypoints_or_none);
    RUN_TEST(test_falko_detect_reports_total_when_out_is_too_small);
    RUN_TEST(test_bid_params_check_refuses_null_and_each_out_of_range_field);
    RUN_TEST(test_bid_detect_refuses_bad_input_and_handles_degenerate_scans);
    RUN_TEST(test_bspline_span_and_basis_clamp_bad_arguments);
    RUN_TEST(test_bspline_eval_refuses_bad_arguments_untouched);
    RUN_TEST(test_lsba_refuses_bad_input_untouched);
    RUN_TEST(test_lsba_collinear_duplicated_and_maximal_inputs_give_finite_fits);
    RUN_TEST(test_pdm_params_check_refuses_null_and_each_out_of_range_field);
    RUN_TEST(test_pdm_refuses_bad_input_untouched);
    RUN_TEST(test_pdm_collinear_duplicated_and_maximal_inputs_give_finite_fits);
    RUN_TEST(test_metrics_scan_refuses_null_and_inconsistent_counts_untouched);
    RUN_TEST(test_metrics_scan_zero_counts_and_bad_time_give_undefined_not_nan);
    RUN_TEST(test_metrics_accumulator_refuses_bad_input_and_keeps_state_on_capacity);
    RUN_TEST(test_method_names_and_params_refuse_unknown_values);
    RUN_TEST(test_extractor_init_refuses_bad_params_and_extract_then_refuses_it);
    RUN_TEST(test_extract_refuses_bad_scans_with_a_cleared_result);
    RUN_TEST(test_extract_empty_invalid_and_degenerate_scans_for_each_method);
    RUN_TEST(test_extract_maximal_scan_of_an_l_corner_gives_valid_features);
    RUN_TEST(test_crc_and_cobs_refuse_null_and_report_small_buffers);
    RUN_TEST(test_frame_encode_refuses_unrepresentable_input_without_writing);
    RUN_TEST(test_frame_encode_sink_refuses_null_and_reports_a_failing_sink);
    RUN_TEST(test_frame_decode_refuses_short_corrupt_and_unknown_frames_untouched);
    RUN_TEST(test_decoder_feed_refuses_null_and_survives_garbage_and_oversize);
    /* Known bugs in other modules (see each test), last: under UBSan the
     * first one aborts the run, and every other case has run by then. */
    RUN_TEST(test_bspline_span_stays_in_range_for_huge_control_point_counts);
    return UNITY_END();
}
