/* SPDX-License-Identifier: MIT */
#include "live_scene.h"

#include "bsf_scene.h"

static bsf_scene_t g_scene;
static bsf_scene_rng_t g_rng;
static bsf_extractor_t g_extractor;
static bsf_result_t g_result;
static float g_ranges[LIVE_SCENE_BEAMS];

bsf_status_t live_scene_start(void)
{
    const bsf_params_t params = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    bsf_scene_demo_office(&g_scene);
    bsf_scene_rng_seed(&g_rng, 2026u);
    return bsf_extractor_init(&g_extractor, &params);
}

bsf_status_t live_scene_scan(uint32_t k, bsf_frame_info_t *info, const bsf_result_t **result)
{
    double x, y, theta;
    bsf_lidar_t lidar;
    bsf_scan_t scan;
    bsf_status_t st;
    bsf_scene_demo_pose((long)(k % LIVE_SCENE_SCANS), (long)LIVE_SCENE_SCANS, &x, &y, &theta);
    lidar = bsf_lidar_default(x, y, theta, LIVE_SCENE_BEAMS, 1.5 * 3.14159265358979323846);
    lidar.noise_sigma = 0.01;
    lidar.range_max = 20.0;
    lidar.no_return = 81.83f;
    st = bsf_scene_scan(&g_scene, &lidar, &g_rng, g_ranges, NULL, LIVE_SCENE_BEAMS);
    if (st != BSF_OK) {
        return st;
    }
    scan = bsf_scene_lidar_scan(&lidar, g_ranges);
    scan.range_min = 0.05f;
    scan.range_max = 30.0f;
    st = bsf_extract(&g_extractor, &scan, &g_result);
    if (st != BSF_OK) {
        return st;
    }
    bsf_frame_info_init(info);
    info->seq = k;
    info->timestamp_ms = (uint64_t)k * LIVE_SCENE_PERIOD_MS;
    info->has_pose = 1u;
    info->pose_x = (float)x;
    info->pose_y = (float)y;
    info->pose_theta = (float)theta;
    *result = &g_result;
    return BSF_OK;
}
