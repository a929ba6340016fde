/* SPDX-License-Identifier: MIT */
#include "det_core.h"

#include <string.h>

#include "bsf_scene.h"

static bsf_extractor_t ex;
static bsf_result_t res;
static uint8_t wire[BSF_FRAME_MAX_SIZE];
static float ranges[DET_BEAMS];

uint32_t det_fnv1a(uint32_t h, const uint8_t *p, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 16777619u;
    }
    return h;
}

static bsf_lidar_t det_lidar(unsigned k)
{
    double x, y, th;
    bsf_lidar_t lid;
    bsf_scene_demo_pose((long)k * (60L / (long)DET_SCANS), 60L, &x, &y, &th);
    lid = bsf_lidar_default(x, y, th, DET_BEAMS, 1.5 * 3.14159265358979323846);
    lid.noise_sigma = 0.01;
    lid.range_max = 20.0;
    lid.no_return = 81.83f;
    return lid;
}

bsf_status_t det_simulate(unsigned k, float *out, bsf_scan_t *scan)
{
    static bsf_scene_t scene;
    bsf_scene_rng_t rng;
    const bsf_lidar_t lid = det_lidar(k);
    bsf_status_t st;
    bsf_scene_demo_office(&scene);
    bsf_scene_rng_seed(&rng, 2026u + k);
    st = bsf_scene_scan(&scene, &lid, &rng, out, NULL, DET_BEAMS);
    *scan = bsf_scene_lidar_scan(&lid, out);
    scan->range_min = 0.05f;
    scan->range_max = 30.0f;
    return st;
}

bsf_status_t det_run(const float *ranges_in, det_summary_t *out,
                     void (*frame_cb)(void *ctx, const uint8_t *frame, size_t len), void *ctx)
{
    static const bsf_method_t methods[DET_METHODS] = {BSF_METHOD_FALKO_SVED_PDM,
                                                      BSF_METHOD_RPOS_LSBA};
    unsigned k;
    unsigned m;
    memset(out, 0, sizeof *out);
    out->ranges_hash = DET_FNV_INIT;
    out->stream_hash = DET_FNV_INIT;
    for (k = 0; k < DET_SCANS; ++k) {
        bsf_scan_t scan;
        bsf_status_t st = det_simulate(k, ranges, &scan);
        if (st != BSF_OK) {
            return st;
        }
        if (ranges_in != NULL) {
            memcpy(ranges, ranges_in + (size_t)k * DET_BEAMS, sizeof ranges);
        }
        out->ranges_hash = det_fnv1a(out->ranges_hash, (const uint8_t *)ranges, sizeof ranges);
        for (m = 0; m < DET_METHODS; ++m) {
            const bsf_params_t p = bsf_params_default(methods[m]);
            bsf_frame_info_t info;
            size_t len = 0u;
            st = bsf_extractor_init(&ex, &p);
            if (st == BSF_OK) {
                st = bsf_extract(&ex, &scan, &res);
            }
            if (st < 0) { /* a cut result (BSF_OK_CUT) is output too */
                return st;
            }
            bsf_frame_info_init(&info);
            info.seq = k * DET_METHODS + m;
            info.timestamp_ms = 100u * k;
            st = bsf_frame_encode(&info, &res, wire, sizeof wire, &len);
            if (st != BSF_OK) {
                return st;
            }
            out->stream_hash = det_fnv1a(out->stream_hash, wire, len);
            out->stream_bytes += (uint32_t)len;
            out->n_features += res.n_features;
            out->n_ctrl += res.n_ctrl;
            if (frame_cb != NULL) {
                frame_cb(ctx, wire, len);
            }
        }
    }
    return BSF_OK;
}
