/* SPDX-License-Identifier: MIT */
#include "live_scene.h"

#include <string.h>

#include "bsf_scene.h"

static bsf_scene_t g_scene;
static bsf_scene_rng_t g_rng;
static bsf_extractor_t g_extractor;
static bsf_result_t g_result;
static float g_ranges[LIVE_SCENE_BEAMS];

/* The simulated LIDAR at a pose: 270 degrees, 1 cm noise, 20 m reach. */
static bsf_lidar_t live_lidar(double x, double y, double theta)
{
    bsf_lidar_t lidar =
        bsf_lidar_default(x, y, theta, LIVE_SCENE_BEAMS, 1.5 * 3.14159265358979323846);
    lidar.noise_sigma = 0.01;
    lidar.range_max = 20.0;
    lidar.no_return = 81.83f;
    return lidar;
}

/* What the extractor is told about the ranges. */
#define LIVE_RANGE_MIN 0.05f
#define LIVE_RANGE_MAX 30.0f

bsf_status_t live_scene_start(void)
{
    const bsf_params_t params = bsf_params_default(BSF_METHOD_DEFAULT);
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
    lidar = live_lidar(x, y, theta);
    st = bsf_scene_scan(&g_scene, &lidar, &g_rng, g_ranges, NULL, LIVE_SCENE_BEAMS);
    if (st != BSF_OK) {
        return st;
    }
    scan = bsf_scene_lidar_scan(&lidar, g_ranges);
    scan.range_min = LIVE_RANGE_MIN;
    scan.range_max = LIVE_RANGE_MAX;
    st = bsf_extract(&g_extractor, &scan, &g_result);
    if (st != BSF_OK) {
        return st;
    }
    bsf_frame_info_init(info);
    info->seq = k;
    info->timestamp_ms = (uint64_t)k * LIVE_SCENE_PERIOD_MS;
    info->has_pose = 1u;
    info->pose.x = (float)x;
    info->pose.y = (float)y;
    info->pose.theta = (float)theta;
    *result = &g_result;
    return BSF_OK;
}

void live_scene_metadata(bsf_metadata_t *m)
{
    static const char source[] = "uart_stream: demo office";
    const bsf_lidar_t lidar = live_lidar(0.0, 0.0, 0.0);
    const bsf_scan_t scan = bsf_scene_lidar_scan(&lidar, g_ranges);
    bsf_metadata_init(m);
    m->method = (uint8_t)g_extractor.params.method;
    m->target_rms = g_extractor.params.pdm.target_rms;
    m->n_beams = LIVE_SCENE_BEAMS;
    m->angle_min = scan.angle_min;
    m->angle_increment = scan.angle_increment;
    m->range_min = LIVE_RANGE_MIN;
    m->range_max = LIVE_RANGE_MAX;
    m->source_len = (uint8_t)(sizeof source - 1u);
    memcpy(m->source, source, sizeof source);
}

bsf_status_t live_scene_send(bsf_sink_fn sink, void *ctx, uint32_t *failed_scan)
{
    static bsf_encoder_t encoder;
    static const uint8_t delimiter = 0u;
    bsf_status_t st = live_scene_start();
    uint32_t k = 0;
    if (st == BSF_OK && sink(ctx, &delimiter, 1u) != 0) {
        st = BSF_ERR_BUFFER;
    }
    for (; st == BSF_OK && k < LIVE_SCENE_SCANS; ++k) {
        bsf_frame_info_t info;
        const bsf_result_t *result = NULL;
        if (k % LIVE_SCENE_META_EVERY == 0u) {
            static bsf_metadata_t meta;
            live_scene_metadata(&meta);
            st = bsf_metadata_encode_sink(&encoder, &meta, sink, ctx, NULL);
            if (st != BSF_OK) {
                break;
            }
        }
        st = live_scene_scan(k, &info, &result);
        if (st == BSF_OK) {
            st = bsf_frame_encode_sink(&encoder, &info, result, sink, ctx, NULL);
        }
        if (st != BSF_OK) {
            break;
        }
    }
    if (failed_scan != NULL) {
        *failed_scan = k;
    }
    return st;
}
