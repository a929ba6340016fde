/* SPDX-License-Identifier: MIT */
#include "demo_scan.h"

#include "unity.h"

static float ranges[BSF_MAX_POINTS];

void demo_scan_extract(const bsf_scene_t *scene, long k, long n, uint64_t seed, bsf_extractor_t *ex,
                       bsf_result_t *res, bsf_pose_t *pose)
{
    bsf_scene_rng_t rng;
    bsf_scan_t s;
    bsf_lidar_t l;
    double x;
    double y;
    double th;
    bsf_params_t p = bsf_params_default(BSF_METHOD_LC_SVED_PDM);
    bsf_scene_demo_pose(k, n, &x, &y, &th);
    l = bsf_lidar_default(x, y, th, 361u, 1.5 * 3.14159265358979);
    l.noise_sigma = 0.01;
    bsf_scene_rng_seed(&rng, seed);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(scene, &l, &rng, ranges, NULL, BSF_MAX_POINTS));
    s = bsf_scene_lidar_scan(&l, ranges);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(ex, &p));
    TEST_ASSERT_TRUE(bsf_extract(ex, &s, res) >= 0);
    pose->x = (float)x;
    pose->y = (float)y;
    pose->theta = (float)th;
}
