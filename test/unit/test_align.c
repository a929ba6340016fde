/* SPDX-License-Identifier: MIT */
/*
 * test_align.c - aligning a scan to the fused map: a known offset of the
 * prior recovered in the demo office (from points and from features), a
 * long corridor whose axis is reported free and kept at the prior, and
 * declines and errors on bad input, never a NaN.
 */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "unity.h"

static bsf_extractor_t ex;
static bsf_result_t res;
static bsf_map_t map;
static bsf_align_work_t work;
static bsf_scene_t scene;
static float ranges[BSF_MAX_POINTS];

void setUp(void)
{
}

void tearDown(void)
{
}

#define N_SCANS 90
#define PI_D 3.14159265358979

/* Scan and extract from world pose (x, y, th) with the given lidar range. */
static void scan_at(double x, double y, double th, double range_max, uint64_t seed)
{
    bsf_scene_rng_t rng;
    bsf_scan_t s;
    bsf_lidar_t l;
    bsf_params_t p = bsf_params_default(BSF_METHOD_LC_SVED_PDM);
    l = bsf_lidar_default(x, y, th, 361u, 1.5 * PI_D);
    l.noise_sigma = 0.01;
    if (range_max > 0.0) {
        l.range_max = range_max;
    }
    bsf_scene_rng_seed(&rng, seed);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, &rng, ranges, NULL, BSF_MAX_POINTS));
    s = bsf_scene_lidar_scan(&l, ranges);
    if (range_max > 0.0) {
        s.range_max = (float)range_max;
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    TEST_ASSERT_TRUE(bsf_extract(&ex, &s, &res) >= 0);
}

/* The demo office's map, fused from the loop's true poses. */
static void office_map(void)
{
    long k;
    bsf_scene_demo_office(&scene);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_map_init(&map, NULL));
    for (k = 0; k < N_SCANS; ++k) {
        double x;
        double y;
        double th;
        bsf_pose_t pose;
        bsf_scene_demo_pose(k, N_SCANS, &x, &y, &th);
        scan_at(x, y, th, 0.0, 100u + (uint64_t)k);
        pose.x = (float)x;
        pose.y = (float)y;
        pose.theta = (float)th;
        TEST_ASSERT_TRUE(bsf_map_fuse(&map, &res, &pose) >= 0);
    }
    TEST_ASSERT_TRUE(bsf_map_feature_count(&map) > 0u);
}

static void assert_finite_result(const bsf_align_result_t *r)
{
    int i;
    TEST_ASSERT_TRUE(isfinite(r->pose.x) && isfinite(r->pose.y) && isfinite(r->pose.theta));
    TEST_ASSERT_TRUE(isfinite(r->rms) && isfinite(r->min_eig));
    for (i = 0; i < 9; ++i) {
        TEST_ASSERT_TRUE(isfinite(r->info[i]));
    }
}

/* A prior 12 cm and 2.3 degrees off is pulled back onto the true pose, from
 * the scan's points and from its features alone, at scans around the loop. */
static void test_align_recovers_known_offset(void)
{
    static const float off[4][3] = {{0.12f, -0.08f, 0.04f},
                                    {-0.10f, 0.10f, -0.04f},
                                    {0.0f, 0.15f, 0.02f},
                                    {0.15f, 0.0f, -0.03f}};
    long k;
    int n_checked = 0;
    office_map();
    for (k = 3; k < N_SCANS; k += 11) {
        double x;
        double y;
        double th;
        bsf_pose_t prior;
        bsf_align_result_t r;
        const float *o = off[(k / 11) % 4];
        bsf_scene_demo_pose(k, N_SCANS, &x, &y, &th);
        scan_at(x, y, th, 0.0, 9000u + (uint64_t)k); /* other noise than the map's */
        prior.x = (float)x + o[0];
        prior.y = (float)y + o[1];
        prior.theta = (float)th + o[2];
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_align_points(&work, NULL, &map, &ex.points, &res, &prior, &r));
        assert_finite_result(&r);
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ALIGN_ACCEPTED, r.declined,
                                      bsf_align_decline_str(r.declined));
        TEST_ASSERT_EQUAL_UINT8(0u, r.n_free);
        TEST_ASSERT_FLOAT_WITHIN(0.02f, (float)x, r.pose.x);
        TEST_ASSERT_FLOAT_WITHIN(0.02f, (float)y, r.pose.y);
        TEST_ASSERT_FLOAT_WITHIN(0.006f, (float)th, r.pose.theta);
        TEST_ASSERT_TRUE(r.n_matches >= 12u && r.n_points <= 96u);
        TEST_ASSERT_TRUE(r.rms < 0.03f);
        TEST_ASSERT_TRUE(r.min_eig > 3.0f);

        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_align_features(&work, NULL, &map, &res, &prior, &r));
        assert_finite_result(&r);
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ALIGN_ACCEPTED, r.declined,
                                      bsf_align_decline_str(r.declined));
        TEST_ASSERT_FLOAT_WITHIN(0.02f, (float)x, r.pose.x);
        TEST_ASSERT_FLOAT_WITHIN(0.02f, (float)y, r.pose.y);
        TEST_ASSERT_FLOAT_WITHIN(0.006f, (float)th, r.pose.theta);
        ++n_checked;
    }
    TEST_ASSERT_EQUAL_INT(8, n_checked);
}

/* A corridor 60 m long and 2 m wide seen with a 6 m range: nothing fixes
 * the position along it. The axis is reported free and the pose keeps the
 * prior along it, while the cross-axis offset and the heading are fixed. */
static void test_align_corridor_keeps_prior_along_axis(void)
{
    int k;
    bsf_pose_t prior;
    bsf_align_result_t r;
    bsf_scene_init(&scene);
    TEST_ASSERT_TRUE(bsf_scene_add_segment(&scene, -30.0, -1.0, 30.0, -1.0) >= 0);
    TEST_ASSERT_TRUE(bsf_scene_add_segment(&scene, -30.0, 1.0, 30.0, 1.0) >= 0);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_map_init(&map, NULL));
    for (k = 0; k <= 40; ++k) {
        const double x = -10.0 + 0.5 * k;
        bsf_pose_t pose;
        scan_at(x, 0.0, 0.0, 6.0, 500u + (uint64_t)k);
        pose.x = (float)x;
        pose.y = 0.0f;
        pose.theta = 0.0f;
        TEST_ASSERT_TRUE(bsf_map_fuse(&map, &res, &pose) >= 0);
    }
    for (k = 0; k < 3; ++k) {
        const float along = k == 0 ? 0.3f : (k == 1 ? -0.25f : 0.1f);
        scan_at(0.25 * k, 0.1, 0.05 * (k - 1), 6.0, 7000u + (uint64_t)k);
        prior.x = 0.25f * (float)k + along;
        prior.y = 0.1f - 0.12f;
        prior.theta = 0.05f * (float)(k - 1) + 0.03f;
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_align_points(&work, NULL, &map, &ex.points, &res, &prior, &r));
        assert_finite_result(&r);
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ALIGN_ACCEPTED, r.declined,
                                      bsf_align_decline_str(r.declined));
        TEST_ASSERT_TRUE((r.flags & BSF_ALIGN_FLAG_FREE) != 0u);
        TEST_ASSERT_EQUAL_UINT8(1u, r.n_free);
        TEST_ASSERT_TRUE(fabsf(r.min_eigvec[0]) > 0.95f); /* the free direction is the axis */
        TEST_ASSERT_TRUE(r.min_eig < 0.005f * r.info[4]);
        /* along the axis: never worse than the prior (kept within 5 mm) */
        TEST_ASSERT_FLOAT_WITHIN(0.005f, prior.x, r.pose.x);
        TEST_ASSERT_FLOAT_WITHIN(0.02f, 0.1f, r.pose.y);
        TEST_ASSERT_FLOAT_WITHIN(0.006f, 0.05f * (float)(k - 1), r.pose.theta);
    }
}

static void assert_declined(const bsf_align_result_t *r, int reason, const bsf_pose_t *prior)
{
    assert_finite_result(r);
    TEST_ASSERT_EQUAL_INT_MESSAGE(reason, r->declined, bsf_align_decline_str(r->declined));
    TEST_ASSERT_EQUAL_MEMORY(prior, &r->pose, sizeof *prior);
}

/* Bad input: clear error codes; input alignment cannot trust: declined
 * with the prior returned. */
static void test_align_declines_bad_input(void)
{
    bsf_align_params_t p;
    bsf_align_result_t r;
    bsf_pose_t prior;
    bsf_points_t one;
    double x;
    double y;
    double th;
    office_map();
    bsf_scene_demo_pose(20, N_SCANS, &x, &y, &th);
    scan_at(x, y, th, 0.0, 4242u);
    prior.x = (float)x;
    prior.y = (float)y;
    prior.theta = (float)th;

    /* errors */
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_align_points(NULL, NULL, &map, &ex.points, &res, &prior, &r));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_align_points(&work, NULL, NULL, &ex.points, &res, &prior, &r));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_align_points(&work, NULL, &map, NULL, &res, &prior, &r));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_align_features(&work, NULL, &map, NULL, &prior, &r));
    prior.theta = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_align_points(&work, NULL, &map, &ex.points, &res, &prior, &r));
    prior.theta = (float)th;
    prior.x = 1e30f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_align_features(&work, NULL, &map, &res, &prior, &r));
    prior.x = INFINITY;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_align_features(&work, NULL, &map, &res, &prior, &r));
    prior.x = (float)x;
    bsf_align_params_default(&p);
    p.huber = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM,
                          bsf_align_points(&work, &p, &map, &ex.points, &res, &prior, &r));
    bsf_align_params_default(&p);
    p.max_points = BSF_ALIGN_MAX_POINTS + 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_align_features(&work, &p, &map, &res, &prior, &r));
    bsf_align_params_default(&p);
    p.min_matches = 200u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_align_features(&work, &p, &map, &res, &prior, &r));
    res.features[0].n_ctrl = 2u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_align_features(&work, NULL, &map, &res, &prior, &r));
    scan_at(x, y, th, 0.0, 4242u);

    /* a scan of one point */
    memset(&one, 0, sizeof one);
    one.count = 1u;
    one.n_valid = 1u;
    one.valid[0] = 1u;
    one.pt[0].x = 1.0f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_align_points(&work, NULL, &map, &one, NULL, &prior, &r));
    assert_declined(&r, BSF_ALIGN_DECLINE_FEW_POINTS, &prior);
    TEST_ASSERT_EQUAL_UINT16(1u, r.n_points);
    one.pt[0].y = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_align_points(&work, NULL, &map, &one, NULL, &prior, &r));

    /* an empty map */
    {
        static bsf_map_t empty;
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_map_init(&empty, NULL));
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_align_points(&work, NULL, &empty, &ex.points, &res, &prior, &r));
        assert_declined(&r, BSF_ALIGN_DECLINE_EMPTY_MAP, &prior);
    }

    /* a prior 3 m away from where the map is: nothing corresponds */
    prior.x = (float)x + 40.0f;
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_align_points(&work, NULL, &map, &ex.points, &res, &prior, &r));
    TEST_ASSERT_TRUE(r.declined == BSF_ALIGN_DECLINE_EMPTY_MAP ||
                     r.declined == BSF_ALIGN_DECLINE_FEW_MATCHES);
    assert_declined(&r, r.declined, &prior);
    prior.x = (float)x;

    /* a correction larger than allowed */
    bsf_align_params_default(&p);
    p.max_xy = 0.05f;
    p.max_dist = 0.4f;
    prior.y = (float)y + 0.2f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_align_points(&work, &p, &map, &ex.points, &res, &prior, &r));
    assert_declined(&r, BSF_ALIGN_DECLINE_TOO_LARGE, &prior);

    /* the same prior with the default bounds is corrected */
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_align_points(&work, NULL, &map, &ex.points, &res, &prior, &r));
    TEST_ASSERT_EQUAL_INT(BSF_ALIGN_ACCEPTED, r.declined);
    TEST_ASSERT_FLOAT_WITHIN(0.02f, (float)y, r.pose.y);

    TEST_ASSERT_EQUAL_STRING("correction too large",
                             bsf_align_decline_str(BSF_ALIGN_DECLINE_TOO_LARGE));
    TEST_ASSERT_EQUAL_STRING("unknown", bsf_align_decline_str(99));
}

/* Scan vertices that disagree with the map (moved 0.25 m) pull the pose off
 * where the scan's points fit; with them weighted heavily, Gauss-Newton ends
 * where every point fits worse than at the (true) prior, and the call keeps
 * the prior. The same scan with its own vertices stays within 2 cm of it. */
static void test_align_declines_a_fit_worse_than_the_prior(void)
{
    static bsf_result_t moved;
    bsf_align_params_t p;
    int n_declined = 0;
    long k;
    office_map();
    bsf_align_params_default(&p);
    p.vertex_weight = 100.0f;
    for (k = 5; k < N_SCANS; k += 17) {
        double x;
        double y;
        double th;
        bsf_pose_t prior;
        bsf_align_result_t r;
        size_t j;
        int n_vertices = 0;
        bsf_scene_demo_pose(k, N_SCANS, &x, &y, &th);
        scan_at(x, y, th, 0.0, 7000u + (uint64_t)k);
        prior.x = (float)x;
        prior.y = (float)y;
        prior.theta = (float)th;
        memcpy(&moved, &res, sizeof moved);
        for (j = 0; j < moved.n_ctrl; ++j) {
            if (moved.ctrl_is_vertex[j]) {
                moved.ctrl[j].x += 0.25f;
                ++n_vertices;
            }
        }
        if (n_vertices == 0) {
            continue;
        }
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_align_points(&work, &p, &map, &ex.points, &moved, &prior, &r));
        assert_finite_result(&r);
        assert_declined(&r, BSF_ALIGN_DECLINE_NO_BETTER, &prior);
        TEST_ASSERT_TRUE(r.n_matches >= 12u);
        ++n_declined;

        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_align_points(&work, &p, &map, &ex.points, &res, &prior, &r));
        assert_finite_result(&r);
        TEST_ASSERT_TRUE(r.declined == BSF_ALIGN_ACCEPTED ||
                         r.declined == BSF_ALIGN_DECLINE_NO_BETTER);
        TEST_ASSERT_FLOAT_WITHIN(0.02f, (float)x, r.pose.x);
        TEST_ASSERT_FLOAT_WITHIN(0.02f, (float)y, r.pose.y);
        TEST_ASSERT_FLOAT_WITHIN(0.006f, (float)th, r.pose.theta);
    }
    TEST_ASSERT_TRUE(n_declined >= 3);
    TEST_ASSERT_EQUAL_STRING("no better than the prior",
                             bsf_align_decline_str(BSF_ALIGN_DECLINE_NO_BETTER));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_align_recovers_known_offset);
    RUN_TEST(test_align_corridor_keeps_prior_along_axis);
    RUN_TEST(test_align_declines_bad_input);
    RUN_TEST(test_align_declines_a_fit_worse_than_the_prior);
    return UNITY_END();
}
