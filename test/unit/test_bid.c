/* SPDX-License-Identifier: MIT */
/* BID: corners found on synthetic scans, nothing on walls and circles. */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "unity.h"

#define PI 3.14159265358979323846

static bsf_points_t points;
static bsf_bid_work_t work;
static float ranges[BSF_MAX_POINTS];
static bsf_keypoint_t kp[BSF_MAX_KEYPOINTS];

void setUp(void)
{
}

void tearDown(void)
{
}

/* Scan the scene from the origin (181 beams over 180 degrees, 5 mm noise)
 * and run BID with its defaults; returns the number of keypoints. */
static size_t detect(const bsf_scene_t *scene, bsf_lidar_t *lidar, uint64_t seed)
{
    bsf_scene_rng_t rng;
    bsf_scan_t scan;
    size_t n_kp = 99u;
    bsf_scene_rng_seed(&rng, seed);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(scene, lidar, &rng, ranges, NULL, BSF_MAX_POINTS));
    scan = bsf_scene_lidar_scan(lidar, ranges);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&scan, &points));
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_bid_detect(&points, NULL, &work, kp, BSF_MAX_KEYPOINTS, &n_kp));
    return n_kp;
}

/* A concave corner of the given opening at (d, lateral), facing the sensor. */
static void check_corner_found(double opening, double d, double lateral, uint64_t seed)
{
    bsf_scene_t scene;
    bsf_lidar_t lidar = bsf_lidar_default(0.0, 0.0, 0.0, 181u, PI);
    bsf_scene_corner_t c[2];
    size_t n_c = 0;
    size_t n_kp;
    size_t k;
    int found = 0;
    const double to_sensor = atan2(-lateral, -d);
    lidar.noise_sigma = 0.005;
    bsf_scene_init(&scene);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_scene_add_corner(&scene, d, lateral, to_sensor + opening / 2.0, 1.5,
                                               to_sensor - opening / 2.0, 1.5));
    n_kp = detect(&scene, &lidar, seed);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(&scene, &lidar, c, 2u, &n_c));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n_c);
    TEST_ASSERT_TRUE(c[0].visible);
    for (k = 0; k < n_kp; ++k) {
        const int off = (int)kp[k].index - c[0].beam;
        if (off >= -2 && off <= 2) {
            found = 1;
            TEST_ASSERT_TRUE(kp[k].score < 0.3f);
            TEST_ASSERT_FLOAT_WITHIN(0.1f, (float)c[0].x, kp[k].point.x);
            TEST_ASSERT_FLOAT_WITHIN(0.1f, (float)c[0].y, kp[k].point.y);
        }
    }
    TEST_ASSERT_TRUE_MESSAGE(found, "corner not found within 2 beams");
    /* Only the corner: the free wall ends are not interest points. */
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n_kp);
}

static void test_bid_finds_90_degree_corners(void)
{
    check_corner_found(PI / 2.0, 2.0, 0.0, 1u);
    check_corner_found(PI / 2.0, 3.0, -0.8, 2u);
    check_corner_found(PI / 2.0, 4.0, 0.5, 3u);
}

static void test_bid_finds_60_degree_corners(void)
{
    check_corner_found(PI / 3.0, 2.0, 0.0, 4u);
    check_corner_found(PI / 3.0, 2.5, 0.6, 5u);
}

static void test_bid_finds_nothing_on_straight_walls(void)
{
    const double tilts[] = {-0.6, 0.0, 0.6};
    size_t k;
    for (k = 0; k < 3u; ++k) {
        bsf_scene_t scene;
        bsf_lidar_t lidar = bsf_lidar_default(0.0, 0.0, 0.0, 181u, PI);
        const double d = 2.0 + 1.5 * (double)k;
        size_t q;
        size_t n_scored = 0;
        lidar.noise_sigma = 0.005;
        bsf_scene_init(&scene);
        TEST_ASSERT_TRUE(bsf_scene_add_segment(&scene, d - 4.0 * sin(tilts[k]),
                                               -4.0 * cos(tilts[k]), d + 4.0 * sin(tilts[k]),
                                               4.0 * cos(tilts[k])) >= 0);
        TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect(&scene, &lidar, 10u + k));
        /* A straight run scores about 1/2 (least-squares control points at
         * the Greville abscissae). */
        for (q = 0; q < points.count; ++q) {
            if (work.score[q] < 1.0f) {
                TEST_ASSERT_FLOAT_WITHIN(0.17f, 0.5f, work.score[q]);
                ++n_scored;
            }
        }
        TEST_ASSERT_TRUE(n_scored > 20u);
    }
}

static void test_bid_finds_nothing_on_circles(void)
{
    const double radii[] = {0.5, 1.0, 2.0};
    size_t k;
    for (k = 0; k < 3u; ++k) {
        bsf_scene_t scene;
        bsf_lidar_t lidar = bsf_lidar_default(0.0, 0.0, 0.0, 181u, PI);
        lidar.noise_sigma = 0.005;
        bsf_scene_init(&scene);
        TEST_ASSERT_TRUE(bsf_scene_add_circle(&scene, 2.0 + 2.0 * radii[k], 0.3, radii[k]) >= 0);
        TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect(&scene, &lidar, 20u + k));
    }
}

static void test_bid_refuses_bad_arguments_and_parameters(void)
{
    bsf_bid_params_t p = bsf_bid_params_default();
    size_t n_kp = 5u;
    memset(&points, 0, sizeof points);
    points.count = 10u;
    points.angle_increment = 0.01f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bid_params_check(&p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_params_check(NULL));
    p.t_th = 1.5f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_bid_params_check(&p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_bid_detect(&points, &p, &work, kp, 4u, &n_kp));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n_kp);
    p = bsf_bid_params_default();
    p.neigh_a = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_PARAM, bsf_bid_params_check(&p));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(NULL, NULL, &work, kp, 4u, &n_kp));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(&points, NULL, NULL, kp, 4u, &n_kp));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(&points, NULL, &work, NULL, 4u, &n_kp));
    points.angle_increment = 0.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bid_detect(&points, NULL, &work, kp, 4u, &n_kp));
    points.angle_increment = 0.01f;
    points.count = BSF_MAX_POINTS + 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_bid_detect(&points, NULL, &work, kp, 4u, &n_kp));
    /* No valid point: no keypoint, no error. */
    points.count = 10u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bid_detect(&points, NULL, &work, kp, 4u, &n_kp));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n_kp);
}

static void test_bid_reports_capacity_with_total_count(void)
{
    /* A rectangular room seen from inside: four corners, room for one. */
    bsf_scene_t scene;
    bsf_lidar_t lidar = bsf_lidar_default(0.0, 0.0, 0.0, 361u, 2.0 * PI * 360.0 / 361.0);
    bsf_scene_rng_t rng;
    bsf_scan_t scan;
    size_t n_kp = 0;
    bsf_scene_init(&scene);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_rect_room(&scene, -2.0, -1.5, 2.5, 2.0));
    bsf_scene_rng_seed(&rng, 7u);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_scene_scan(&scene, &lidar, &rng, ranges, NULL, BSF_MAX_POINTS));
    scan = bsf_scene_lidar_scan(&lidar, ranges);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&scan, &points));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_bid_detect(&points, NULL, &work, kp, 1u, &n_kp));
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)n_kp);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_bid_finds_90_degree_corners);
    RUN_TEST(test_bid_finds_60_degree_corners);
    RUN_TEST(test_bid_finds_nothing_on_straight_walls);
    RUN_TEST(test_bid_finds_nothing_on_circles);
    RUN_TEST(test_bid_refuses_bad_arguments_and_parameters);
    RUN_TEST(test_bid_reports_capacity_with_total_count);
    return UNITY_END();
}
