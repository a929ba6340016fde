/* SPDX-License-Identifier: MIT */
/* Caps past the input cut a cluttered scan's output instead of failing it
 * (docs/DESIGN.md, "Cut policy"): synthetic clutter scans that exceed the keypoint, segment and
 * control-point caps in turn keep the features that fit by the documented
 * rule, report the cut in their stats, still encode within
 * BSF_FRAME_MAX_SIZE and decode to the same features. Built twice: against
 * the default library (1081 beams) and against a copy with
 * BSF_MAX_POINTS = 3200, where the full-circle 3200-beam scans run too. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_nms.h"
#include "bsf_scene.h"
#include "unity.h"

#define PI_D 3.14159265358979323846

static bsf_extractor_t ex;
static bsf_result_t res;
static bsf_scene_t scene;
static float ranges[BSF_MAX_POINTS];
static bsf_keypoint_t all_keypoints[BSF_MAX_POINTS];
static bsf_falko_work_t falko_work;
static bsf_lc_work_t lc_work;
static uint8_t frame[BSF_FRAME_MAX_SIZE];
static uint8_t body[BSF_FRAME_MAX_SIZE];
static bsf_frame_t decoded;

void setUp(void)
{
}

void tearDown(void)
{
}

typedef struct {
    size_t beams;
    double fov;
    size_t n_teeth, n_posts, n_boxes;
    double half_w, half_h, clear, tooth_depth, noise;
    uint64_t seed;
} clutter_case_t;

/* Simulate the case's scan and extract it with the default parameters. */
static bsf_status_t extract_case(const clutter_case_t *cc)
{
    bsf_scene_clutter_t c;
    bsf_scene_rng_t rng;
    bsf_lidar_t l;
    bsf_scan_t scan;
    const bsf_params_t p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    memset(&c, 0, sizeof c);
    c.half_w = cc->half_w;
    c.half_h = cc->half_h;
    c.n_teeth = cc->n_teeth;
    c.tooth_depth = cc->tooth_depth;
    c.n_posts = cc->n_posts;
    c.n_boxes = cc->n_boxes;
    c.clear = cc->clear;
    bsf_scene_init(&scene);
    bsf_scene_rng_seed(&rng, cc->seed);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_clutter_room(&scene, &c, &rng));
    l = bsf_lidar_default(0.0, 0.0, 0.3, cc->beams, cc->fov);
    l.noise_sigma = cc->noise;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, &rng, ranges, NULL, BSF_MAX_POINTS));
    scan = bsf_scene_lidar_scan(&l, ranges);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    return bsf_extract(&ex, &scan, &res);
}

/* What every cut result must be: within every cap, features by first beam
 * with their control points laid out in that order, points accounted for. */
static void assert_cut_result_is_well_formed(void)
{
    uint32_t ctrl = 0u;
    uint32_t points = 0u;
    size_t i;
    TEST_ASSERT_TRUE(res.stats.cut != 0u);
    TEST_ASSERT_TRUE(res.n_features <= BSF_MAX_SEGMENTS);
    TEST_ASSERT_TRUE(res.n_ctrl <= BSF_MAX_CTRL_POINTS);
    TEST_ASSERT_TRUE(res.stats.n_keypoints <= BSF_MAX_KEYPOINTS);
    TEST_ASSERT_TRUE(res.n_features > 0u);
    for (i = 0; i < res.n_features; ++i) {
        const bsf_feature_t *f = &res.features[i];
        TEST_ASSERT_EQUAL_UINT16(ctrl, f->ctrl_first);
        if (i > 0u && f->first_beam <= f->last_beam) { /* beam order; a wrapping one last */
            TEST_ASSERT_TRUE(res.features[i - 1u].first_beam < f->first_beam);
        }
        ctrl += f->n_ctrl;
        points += f->n_points;
    }
    TEST_ASSERT_EQUAL_UINT32(ctrl, res.n_ctrl);
    TEST_ASSERT_EQUAL_UINT32(ctrl, res.stats.n_ctrl);
    TEST_ASSERT_EQUAL_UINT32(points, res.stats.n_in_features);
    TEST_ASSERT_EQUAL_UINT32(res.n_features, res.stats.n_features);
    TEST_ASSERT_TRUE(res.stats.n_in_features + res.stats.n_cut_points <= res.stats.n_valid);
    TEST_ASSERT_EQUAL_INT((res.stats.cut & BSF_CUT_KEYPOINTS) != 0u,
                          res.stats.n_cut_keypoints > 0u);
    TEST_ASSERT_EQUAL_INT((res.stats.cut & (BSF_CUT_SEGMENTS | BSF_CUT_CTRL)) != 0u,
                          res.stats.n_cut_segments > 0u);
}

/* Cut points are wasted in Gamma: the metrics see N, the kept points and the cut. */
static void assert_metrics_waste_the_cut_points(void)
{
    bsf_scan_counts_t c;
    bsf_scan_metrics_t m;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_counts(&res, &c));
    TEST_ASSERT_EQUAL_UINT32(res.stats.cut, c.cut);
    TEST_ASSERT_EQUAL_UINT32(res.stats.n_cut_points, c.n_cut_points);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_scan(&c, &m));
    TEST_ASSERT_TRUE(m.retrievability <= (float)(res.stats.n_valid - res.stats.n_cut_points) /
                                             (float)res.stats.n_valid);
}

/* The cut result travels: it encodes within BSF_FRAME_MAX_SIZE and decodes
 * to the same features. */
static void assert_frame_carries_the_result(void)
{
    bsf_frame_info_t info;
    size_t len = 0u;
    size_t body_len = 0u;
    size_t i;
    bsf_frame_info_init(&info);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, frame, sizeof frame, &len));
    TEST_ASSERT_TRUE(len <= BSF_FRAME_MAX_SIZE);
    TEST_ASSERT_EQUAL_HEX8(0u, frame[len - 1u]);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_decode(frame, len - 1u, body, sizeof body, &body_len));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_decode(body, body_len, &decoded));
    TEST_ASSERT_EQUAL_UINT16(res.n_features, decoded.result.n_features);
    /* the cut travels in the frame's header extension (FORMAT.md 3.1) */
    TEST_ASSERT_EQUAL_UINT32(res.stats.cut, decoded.result.stats.cut);
    TEST_ASSERT_EQUAL_UINT32(res.stats.n_cut_keypoints, decoded.result.stats.n_cut_keypoints);
    TEST_ASSERT_EQUAL_UINT32(res.stats.n_cut_segments, decoded.result.stats.n_cut_segments);
    TEST_ASSERT_EQUAL_UINT32(res.stats.n_cut_points, decoded.result.stats.n_cut_points);
    for (i = 0; i < res.n_features; ++i) {
        TEST_ASSERT_EQUAL_UINT16(res.features[i].first_beam, decoded.result.features[i].first_beam);
        TEST_ASSERT_EQUAL_UINT16(res.features[i].n_points, decoded.result.features[i].n_points);
    }
}

/* The keypoints kept are the strongest the detector found (FALKO: lowest
 * raw score), and the counts add up to what it found. */
static void assert_strongest_keypoints_kept(void)
{
    float worst_kept = -1.0f;
    float best_dropped = 3.4e38f;
    size_t n_all = 0u;
    size_t i;
    size_t k = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_detect(&ex.points, &ex.params.falko, &falko_work,
                                                   all_keypoints, BSF_MAX_POINTS, &n_all));
    TEST_ASSERT_EQUAL_UINT32(n_all, res.stats.n_keypoints + res.stats.n_cut_keypoints);
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_KEYPOINTS, res.stats.n_keypoints);
    for (i = 0; i < n_all; ++i) {
        const float s = all_keypoints[i].score;
        if (k < ex.n_keypoints && ex.keypoints[k].index == all_keypoints[i].index) {
            ++k;
            worst_kept = s > worst_kept ? s : worst_kept;
        } else {
            best_dropped = s < best_dropped ? s : best_dropped;
        }
    }
    TEST_ASSERT_EQUAL_UINT32(ex.n_keypoints, k); /* kept ones are a subset, in beam order */
    TEST_ASSERT_TRUE(worst_kept <= best_dropped);
}

static void report(const char *what, const clutter_case_t *cc)
{
    printf("%s, %u beams: kept %u features, %u ctrl, %u keypoints; cut 0x%x: %u keypoints, %u "
           "segments, %u of %u points\n",
           what, (unsigned)cc->beams, (unsigned)res.n_features, (unsigned)res.n_ctrl,
           (unsigned)res.stats.n_keypoints, (unsigned)res.stats.cut,
           (unsigned)res.stats.n_cut_keypoints, (unsigned)res.stats.n_cut_segments,
           (unsigned)res.stats.n_cut_points, (unsigned)res.stats.n_valid);
}

static void run_keypoint_case(const clutter_case_t *cc)
{
    TEST_ASSERT_EQUAL_INT(BSF_OK_CUT, extract_case(cc));
    report("keypoint cap", cc);
    TEST_ASSERT_EQUAL_UINT32(BSF_CUT_KEYPOINTS, res.stats.cut);
    assert_cut_result_is_well_formed();
    assert_strongest_keypoints_kept();
    assert_metrics_waste_the_cut_points();
    assert_frame_carries_the_result();
}

static const clutter_case_t k1081 = {1081u, 1.5 * PI_D, 80u, 20u, 5u, 8.0, 4.0, 0.8, 0.1, 0.01, 1u};

static void test_1081_beams_keypoint_cap_keeps_the_strongest(void)
{
    run_keypoint_case(&k1081);
}

/* A gear around the sensor: a star polygon of n_vertices corners
 * alternating between r_in and r_out, seen by 1081 beams over 270 degrees
 * (each beam's range from its ray's crossing with the edge it meets). */
static bsf_scan_t gear_scan(unsigned n_vertices, double r_in, double r_out)
{
    const double step = 2.0 * PI_D / (double)n_vertices;
    bsf_scan_t s;
    size_t i;
    memset(&s, 0, sizeof s);
    s.ranges = ranges;
    s.count = 1081u;
    s.angle_min = (float)(-0.75 * PI_D);
    s.angle_increment = (float)(1.5 * PI_D / 1080.0);
    s.range_min = 0.1f;
    s.range_max = 30.0f;
    for (i = 0; i < s.count; ++i) {
        const double a = (double)s.angle_min + (double)i * (double)s.angle_increment;
        const unsigned k = (unsigned)(fmod(a + 4.0 * PI_D, 2.0 * PI_D) / step) % n_vertices;
        const double r0 = k % 2u == 0u ? r_in : r_out;
        const double r1 = k % 2u == 0u ? r_out : r_in;
        const double x0 = r0 * cos(k * step);
        const double y0 = r0 * sin(k * step);
        const double ex_ = r1 * cos((k + 1u) * step) - x0;
        const double ey = r1 * sin((k + 1u) * step) - y0;
        ranges[i] = (float)((x0 * ey - y0 * ex_) / (cos(a) * ey - sin(a) * ex_));
    }
    return s;
}

/* LC has no strength order: over the keypoint cap it keeps the first
 * BSF_MAX_KEYPOINTS corners in beam order, exactly those LC finds first
 * with room for all, and counts the others as cut. (The gear's edges are
 * too short for features: this pins the keypoint rule alone.) */
static void test_lc_keypoint_cap_keeps_the_first_in_beam_order(void)
{
    const bsf_scan_t scan = gear_scan(120u, 3.0, 4.0);
    const bsf_params_t p = bsf_params_default(BSF_METHOD_LC_SVED_PDM);
    size_t n_all = 0u;
    size_t i;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    TEST_ASSERT_EQUAL_INT(BSF_OK_CUT, bsf_extract(&ex, &scan, &res));
    printf("LC keypoint cap, gear of 120 corners: kept %u keypoints, cut %u\n",
           (unsigned)res.stats.n_keypoints, (unsigned)res.stats.n_cut_keypoints);
    TEST_ASSERT_EQUAL_UINT32(BSF_CUT_KEYPOINTS, res.stats.cut);
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_KEYPOINTS, res.stats.n_keypoints);
    TEST_ASSERT_TRUE(res.stats.n_cut_keypoints > 0u);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_lc_detect(&ex.points, &ex.params.lc, &lc_work, all_keypoints,
                                                BSF_MAX_POINTS, &n_all));
    TEST_ASSERT_TRUE(n_all > (size_t)BSF_MAX_KEYPOINTS);
    TEST_ASSERT_EQUAL_UINT32(n_all, res.stats.n_keypoints + res.stats.n_cut_keypoints);
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_KEYPOINTS, ex.n_keypoints);
    for (i = 0; i < ex.n_keypoints; ++i) {
        TEST_ASSERT_EQUAL_UINT16(all_keypoints[i].index, ex.keypoints[i].index);
        TEST_ASSERT_EQUAL_FLOAT(all_keypoints[i].point.x, ex.keypoints[i].point.x);
        TEST_ASSERT_EQUAL_FLOAT(all_keypoints[i].point.y, ex.keypoints[i].point.y);
    }
    assert_frame_carries_the_result();
}

#if BSF_MAX_POINTS >= 3200
/* The segments kept are those covering the most points: every cut segment
 * has at most as many points as the smallest kept one, and at least the
 * shortest kept length (checked on the counts, so whichever segmenter
 * bsf_extract uses). */
static void assert_largest_segments_kept(void)
{
    uint32_t min_kept = 0xFFFFu;
    size_t i;
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_SEGMENTS, ex.n_segments);
    for (i = 0; i < ex.n_segments; ++i) {
        min_kept = ex.segments[i].n_points < min_kept ? ex.segments[i].n_points : min_kept;
    }
    TEST_ASSERT_TRUE(res.stats.n_cut_segments > 0u);
    if ((res.stats.cut & BSF_CUT_CTRL) == 0u) {
        /* a rule that kept small segments would cut more points than this
         * (a control-point cut may also leave out a kept segment) */
        TEST_ASSERT_TRUE(res.stats.n_cut_points <= res.stats.n_cut_segments * min_kept);
    }
    TEST_ASSERT_TRUE(res.stats.n_cut_points >=
                     res.stats.n_cut_segments * ex.params.sved.min_segment_points);
}

/* Control points ran out: the pool is nearly full (a cut feature needed more
 * than was left, and later features only used room), and the segment
 * covering the most points is among the features. */
static void assert_ctrl_pool_filled_largest_first(void)
{
    uint32_t largest = 0u;
    int found = 0;
    size_t i;
    TEST_ASSERT_TRUE(res.n_ctrl > BSF_MAX_CTRL_POINTS - BSF_MAX_CTRL_PER_FEATURE);
    for (i = 0; i < ex.n_segments; ++i) {
        largest = ex.segments[i].n_points > largest ? ex.segments[i].n_points : largest;
    }
    for (i = 0; i < res.n_features; ++i) {
        found |= res.features[i].n_points == largest;
    }
    TEST_ASSERT_TRUE(found);
}

static void run_segment_case(const clutter_case_t *cc)
{
    TEST_ASSERT_EQUAL_INT(BSF_OK_CUT, extract_case(cc));
    report("segment cap", cc);
    TEST_ASSERT_TRUE((res.stats.cut & BSF_CUT_SEGMENTS) != 0u);
    assert_cut_result_is_well_formed();
    assert_largest_segments_kept();
    assert_metrics_waste_the_cut_points();
    assert_frame_carries_the_result();
}

static void run_ctrl_case(const clutter_case_t *cc)
{
    TEST_ASSERT_EQUAL_INT(BSF_OK_CUT, extract_case(cc));
    report("control-point cap", cc);
    TEST_ASSERT_TRUE((res.stats.cut & BSF_CUT_CTRL) != 0u);
    TEST_ASSERT_TRUE((res.stats.cut & BSF_CUT_SEGMENTS) == 0u);
    assert_cut_result_is_well_formed();
    assert_ctrl_pool_filled_largest_first();
    assert_metrics_waste_the_cut_points();
    assert_frame_carries_the_result();
}

#define FULL_3200 (2.0 * PI_D * 3199.0 / 3200.0)
static const clutter_case_t k3200 = {3200u, FULL_3200, 80u, 20u, 5u, 6.0, 4.0, 0.8, 0.25, 0.01, 1u};
static const clutter_case_t s3200 = {3200u, FULL_3200, 10u,  300u, 10u, 15.0,
                                     10.0,  2.5,       0.25, 0.01, 1u};
/* 3 cm range noise (a low-cost sensor): more control points per feature */
static const clutter_case_t c3200 = {3200u, FULL_3200, 10u,  80u,  80u, 10.0,
                                     8.0,   0.8,       0.25, 0.03, 3u};

static void test_3200_beams_keypoint_cap_keeps_the_strongest(void)
{
    run_keypoint_case(&k3200);
}

static void test_3200_beams_segment_cap_keeps_the_largest(void)
{
    run_segment_case(&s3200);
}

static void test_3200_beams_ctrl_cap_fits_the_largest_first(void)
{
    run_ctrl_case(&c3200);
}
#endif

/* The keypoint rule itself: the cap best scores in either order, ties to the
 * lower beam, kept in beam order; negative and infinite scores order right. */
static void test_keep_best_keeps_the_strongest_in_beam_order(void)
{
    static float score[16];
    uint16_t peak[8] = {1u, 3u, 4u, 6u, 9u, 11u, 12u, 15u};
    uint16_t low[8];
    size_t n;
    score[1] = 5.0f;
    score[3] = -2.0f;
    score[4] = 7.0f;
    score[6] = 5.0f;
    score[9] = INFINITY;
    score[11] = 0.0f;
    score[12] = 5.0f;
    score[15] = -INFINITY;
    memcpy(low, peak, sizeof low);
    n = bsf_nms_keep_best(score, BSF_NMS_HIGHER_IS_BETTER, peak, 8u, 4u);
    TEST_ASSERT_EQUAL_UINT32(4u, n);
    TEST_ASSERT_EQUAL_UINT16(1u, peak[0]); /* 5: the first two of three tied 5s */
    TEST_ASSERT_EQUAL_UINT16(4u, peak[1]); /* 7 */
    TEST_ASSERT_EQUAL_UINT16(6u, peak[2]); /* 5 */
    TEST_ASSERT_EQUAL_UINT16(9u, peak[3]); /* +inf */
    n = bsf_nms_keep_best(score, BSF_NMS_LOWER_IS_BETTER, low, 8u, 3u);
    TEST_ASSERT_EQUAL_UINT32(3u, n);
    TEST_ASSERT_EQUAL_UINT16(3u, low[0]);  /* -2 */
    TEST_ASSERT_EQUAL_UINT16(11u, low[1]); /* 0 */
    TEST_ASSERT_EQUAL_UINT16(15u, low[2]); /* -inf */
    TEST_ASSERT_EQUAL_UINT32(2u, bsf_nms_keep_best(score, BSF_NMS_LOWER_IS_BETTER, low, 2u, 5u));
    TEST_ASSERT_EQUAL_UINT32(0u, bsf_nms_keep_best(score, BSF_NMS_LOWER_IS_BETTER, low, 3u, 0u));
}

/* The input is never truncated: a scan longer than BSF_MAX_POINTS stays an error. */
static void test_too_long_scan_is_still_an_error(void)
{
    bsf_scan_t s;
    const bsf_params_t p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    memset(&s, 0, sizeof s);
    s.ranges = ranges;
    s.count = (size_t)BSF_MAX_POINTS + 1u;
    s.angle_increment = 0.001f;
    s.range_max = 30.0f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_extract(&ex, &s, &res));
    TEST_ASSERT_EQUAL_UINT16(0u, res.n_features);
    TEST_ASSERT_EQUAL_UINT32(0u, res.stats.cut);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_1081_beams_keypoint_cap_keeps_the_strongest);
    RUN_TEST(test_lc_keypoint_cap_keeps_the_first_in_beam_order);
#if BSF_MAX_POINTS >= 3200
    RUN_TEST(test_3200_beams_keypoint_cap_keeps_the_strongest);
    RUN_TEST(test_3200_beams_segment_cap_keeps_the_largest);
    RUN_TEST(test_3200_beams_ctrl_cap_fits_the_largest_first);
#endif
    RUN_TEST(test_keep_best_keeps_the_strongest_in_beam_order);
    RUN_TEST(test_too_long_scan_is_still_an_error);
    return UNITY_END();
}
