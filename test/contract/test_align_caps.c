/* SPDX-License-Identifier: MIT */
/*
 * test_align_caps.c - alignment against a copy of the library with tiny
 * alignment caps (BSF_ALIGN_MAX_SEGS, BSF_ALIGN_MAX_ENTRIES,
 * BSF_ALIGN_MAX_VERTICES): the caps cut the map curves near the prior, the
 * result says so, stays within the caps and finite, and the call still
 * declines or aligns as documented.
 */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "demo_scan.h"
#include "unity.h"

#if BSF_ALIGN_MAX_SEGS > 64
#error "test_align_caps needs the small alignment caps of its CMake target"
#endif

static bsf_extractor_t ex;
static bsf_result_t res;
static bsf_map_t map;
static bsf_align_work_t work;
static bsf_scene_t scene;

void setUp(void)
{
}

void tearDown(void)
{
}

#define N_SCANS 60

static void test_align_caps_cut_is_reported(void)
{
    long k;
    int n_cut = 0;
    bsf_scene_demo_office(&scene);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_map_init(&map, NULL));
    for (k = 0; k < N_SCANS; ++k) {
        bsf_pose_t pose;
        demo_scan_extract(&scene, k, N_SCANS, 300u + (uint64_t)k, &ex, &res, &pose);
        TEST_ASSERT_TRUE(bsf_map_fuse(&map, &res, &pose) >= 0);
    }
    for (k = 0; k < N_SCANS; k += 6) {
        bsf_pose_t truth;
        bsf_pose_t prior;
        bsf_align_result_t r;
        demo_scan_extract(&scene, k, N_SCANS, 800u + (uint64_t)k, &ex, &res, &truth);
        prior = truth;
        prior.x += 0.05f;
        prior.theta -= 0.01f;
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_align_points(&work, NULL, &map, &ex.points, &res, &prior, &r));
        TEST_ASSERT_TRUE(isfinite(r.pose.x) && isfinite(r.pose.y) && isfinite(r.pose.theta));
        TEST_ASSERT_TRUE(isfinite(r.rms) && isfinite(r.min_eig));
        TEST_ASSERT_TRUE(r.n_segs <= BSF_ALIGN_MAX_SEGS);
        TEST_ASSERT_TRUE(r.declined < BSF_ALIGN_DECLINE_COUNT);
        if (r.declined != BSF_ALIGN_ACCEPTED) {
            TEST_ASSERT_EQUAL_MEMORY(&prior, &r.pose, sizeof prior);
        } else {
            /* the chords kept are real map curves: no wild correction */
            TEST_ASSERT_TRUE(fabsf(r.pose.x - prior.x) <= 0.5f &&
                             fabsf(r.pose.y - prior.y) <= 0.5f);
        }
        n_cut += (r.flags & BSF_ALIGN_FLAG_CUT) != 0u;
    }
    TEST_ASSERT_TRUE(n_cut >= 8);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_align_caps_cut_is_reported);
    return UNITY_END();
}
