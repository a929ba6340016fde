/* SPDX-License-Identifier: MIT */
#include "stream_fixtures.h"

#include <math.h>
#include <string.h>

void fx_rng_seed(fx_rng_t *rng, uint32_t seed)
{
    rng->state = seed != 0u ? seed : 0x9E3779B9u;
}

uint32_t fx_rng_next(fx_rng_t *rng)
{
    uint32_t x = rng->state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    rng->state = x;
    return x;
}

uint32_t fx_rng_range(fx_rng_t *rng, uint32_t lo, uint32_t hi)
{
    return lo + fx_rng_next(rng) % (hi - lo + 1u);
}

float fx_rng_float(fx_rng_t *rng, float lo, float hi)
{
    return lo + (hi - lo) * ((float)(fx_rng_next(rng) >> 8) / 16777216.0f);
}

typedef struct {
    uint16_t first_beam, last_beam, n_points;
    uint8_t kind;
    float e_curve;
    uint8_t n_ctrl;
    float xy[8][2];
    uint8_t vertex[8];
} fx_feature_def_t;

static void build(bsf_result_t *res, const fx_feature_def_t *defs, uint16_t n_defs,
                  uint32_t n_valid, uint32_t time_ns)
{
    uint16_t i;
    memset(res, 0, sizeof *res);
    for (i = 0; i < n_defs; ++i) {
        bsf_feature_t *f = &res->features[i];
        uint8_t k;
        f->first_beam = defs[i].first_beam;
        f->last_beam = defs[i].last_beam;
        f->n_points = defs[i].n_points;
        f->kind = defs[i].kind;
        f->e_curve = defs[i].e_curve;
        f->ctrl_first = res->n_ctrl;
        f->n_ctrl = defs[i].n_ctrl;
        for (k = 0; k < defs[i].n_ctrl; ++k) {
            res->ctrl[res->n_ctrl].x = defs[i].xy[k][0];
            res->ctrl[res->n_ctrl].y = defs[i].xy[k][1];
            res->ctrl_is_vertex[res->n_ctrl] = defs[i].vertex[k];
            ++res->n_ctrl;
        }
        res->stats.n_in_features += f->n_points;
    }
    res->n_features = n_defs;
    res->stats.n_features = n_defs;
    res->stats.n_ctrl = res->n_ctrl;
    res->stats.n_valid = n_valid;
    res->stats.time_ns = time_ns;
}

void fx_example_minimal(bsf_frame_info_t *info, bsf_result_t *res)
{
    static const fx_feature_def_t defs[1] = {
        {10, 29, 20, 0, 0.0050f, 3, {{1.000f, 0.500f}, {1.500f, 0.800f}, {2.000f, 1.000f}}, {0}},
    };
    bsf_frame_info_init(info);
    build(res, defs, 1, 20, 0);
}

void fx_example_typical(bsf_frame_info_t *info, bsf_result_t *res)
{
    static const fx_feature_def_t defs[6] = {
        {3,
         38,
         35,
         0,
         0.0058f,
         4,
         {{0.094f, -1.801f}, {0.512f, -1.797f}, {1.248f, -1.806f}, {1.662f, -1.812f}},
         {0}},
        {41,
         95,
         55,
         1,
         0.0094f,
         5,
         {{1.843f, -1.807f},
          {3.102f, -1.794f},
          {3.102f, -1.794f},
          {3.095f, -0.412f},
          {3.089f, 0.286f}},
         {0, 1, 1, 0, 0}},
        {99, 118, 20, 0, 0.0031f, 3, {{2.301f, 0.902f}, {2.052f, 1.217f}, {1.788f, 1.540f}}, {0}},
        {121,
         150,
         28,
         1,
         0.0112f,
         5,
         {{1.402f, 1.650f}, {0.901f, 1.652f}, {0.412f, 1.655f}, {0.412f, 1.655f}, {0.405f, 2.304f}},
         {0, 0, 1, 1, 0}},
        {153,
         170,
         18,
         0,
         0.0073f,
         5,
         {{-0.102f, 2.506f},
          {-0.351f, 2.498f},
          {-0.602f, 2.445f},
          {-0.803f, 2.352f},
          {-0.951f, 2.214f}},
         {0}},
        {172,
         178,
         7,
         0,
         0.0142f,
         4,
         {{-1.602f, 1.905f}, {-1.701f, 1.506f}, {-1.798f, 1.003f}, {-1.850f, 0.702f}},
         {0}},
    };
    bsf_frame_info_init(info);
    info->seq = 1234u;
    info->timestamp_ms = 700430u;
    info->has_pose = 1u;
    info->pose.x = 4.774f;
    info->pose.y = -5.846f;
    info->pose.theta = -1.408f;
    build(res, defs, 6, 176, 912345u);
}

void fx_example_wrap_cut(bsf_frame_info_t *info, bsf_result_t *res)
{
    static const fx_feature_def_t defs[2] = {
        {100,
         140,
         39,
         0,
         0.0040f,
         3,
         {{-0.700f, 1.200f}, {-1.100f, 0.600f}, {-1.600f, 0.100f}},
         {0}},
        {350, 9, 20, 0, 0.0060f, 3, {{2.000f, -0.300f}, {2.010f, 0.000f}, {2.000f, 0.300f}}, {0}},
    };
    bsf_frame_info_init(info);
    info->seq = 7u;
    info->timestamp_ms = 25u;
    build(res, defs, 2, 300, 0);
    res->stats.n_beams = 360u;
    res->stats.cut = BSF_CUT_SEGMENTS;
    res->stats.n_cut_segments = 2u;
    res->stats.n_cut_points = 11u;
}

void fx_example_metadata(bsf_metadata_t *m)
{
    static const char source[] = "intel.log.gz";
    memset(m, 0, sizeof *m);
    m->lib_version_major = 0u;
    m->lib_version_minor = 1u;
    m->lib_version_patch = 0u;
    m->method = 0u;
    m->target_rms = 0.015f;
    m->quant_step = 0.005f;
    m->max_points = 1081u;
    m->max_keypoints = 64u;
    m->max_segments = 128u;
    m->max_ctrl_per_feature = 32u;
    m->max_ctrl_points = 512u;
    m->n_beams = 180u;
    m->angle_min = -1.5707964f;
    m->angle_increment = 0.017453292f;
    m->range_min = 0.0f;
    m->range_max = 81.91f;
    m->has_time_origin = 1u;
    m->time_origin_us = 1066286502361000LL;
    m->source_len = (uint8_t)(sizeof source - 1u);
    memcpy(m->source, source, sizeof source);
}

/* A wall from p in direction angle, length len, split at n_vertex corners
 * (turns of 60-120 degrees), sampled into n_ctrl control points of which
 * the corners are doubled. Returns the stored count. */
static uint8_t random_polyline(fx_rng_t *rng, float x0, float y0, bsf_point_t *out,
                               uint8_t *is_vertex, uint8_t n_ctrl, uint8_t n_vertex)
{
    /* unique points: n_ctrl - n_vertex, anchors: 2 + n_vertex */
    const uint8_t n_unique = (uint8_t)(n_ctrl - n_vertex);
    const uint8_t n_precision = (uint8_t)(n_unique - 2u - n_vertex);
    uint8_t per_piece[8];
    uint8_t piece;
    uint8_t i;
    uint8_t n = 0;
    float x = x0;
    float y = y0;
    float heading = fx_rng_float(rng, -3.14159f, 3.14159f);
    const float bend = fx_rng_float(rng, -0.05f, 0.05f); /* slight curvature */

    for (piece = 0; piece <= n_vertex; ++piece) {
        per_piece[piece] = 0;
    }
    for (i = 0; i < n_precision; ++i) {
        ++per_piece[fx_rng_range(rng, 0u, n_vertex)];
    }
    out[n].x = x;
    out[n].y = y;
    is_vertex[n++] = 0u;
    for (piece = 0; piece <= n_vertex; ++piece) {
        const float len = fx_rng_float(rng, 0.5f, 5.0f) / (float)(n_vertex + 1u);
        const uint8_t k = per_piece[piece];
        const float ex = x + len * cosf(heading);
        const float ey = y + len * sinf(heading);
        for (i = 1; i <= k; ++i) {
            const float t = ((float)i - 0.5f) / (float)k;
            const float sag = bend * len * 4.0f * t * (1.0f - t);
            out[n].x = x + t * (ex - x) - sag * sinf(heading) + fx_rng_float(rng, -0.004f, 0.004f);
            out[n].y = y + t * (ey - y) + sag * cosf(heading) + fx_rng_float(rng, -0.004f, 0.004f);
            is_vertex[n++] = 0u;
        }
        x = ex;
        y = ey;
        out[n].x = x;
        out[n].y = y;
        if (piece < n_vertex) {
            is_vertex[n++] = 1u;
            out[n] = out[n - 1u];
            is_vertex[n++] = 1u;
            heading += (fx_rng_range(rng, 0u, 1u) != 0u ? 1.0f : -1.0f) *
                       fx_rng_float(rng, 1.047f, 2.094f);
        } else {
            is_vertex[n++] = 0u;
        }
    }
    return n;
}

void fx_random_result(fx_rng_t *rng, uint32_t max_features, bsf_frame_info_t *info,
                      bsf_result_t *res)
{
    const uint32_t n_features = fx_rng_range(rng, 1u, max_features);
    uint32_t i;
    uint32_t beam = fx_rng_range(rng, 0u, 10u);
    uint32_t points = 0;
    const uint32_t beams_per_feature = 340u / n_features;

    memset(res, 0, sizeof *res);
    bsf_frame_info_init(info);
    info->seq = fx_rng_next(rng);
    info->timestamp_ms = ((uint64_t)fx_rng_next(rng) << 8) | fx_rng_range(rng, 0u, 255u);
    info->has_pose = (uint8_t)fx_rng_range(rng, 0u, 1u);
    if (info->has_pose) {
        info->pose.x = fx_rng_float(rng, -100.0f, 100.0f);
        info->pose.y = fx_rng_float(rng, -100.0f, 100.0f);
        info->pose.theta = fx_rng_float(rng, -3.14159f, 3.14159f);
    }
    info->quant_step = (float)fx_rng_range(rng, 1u, 100u) * 0.0001f;

    for (i = 0; i < n_features && res->n_ctrl + 20u <= BSF_MAX_CTRL_POINTS; ++i) {
        bsf_feature_t *f = &res->features[res->n_features];
        uint8_t n_vertex =
            (uint8_t)(fx_rng_range(rng, 0u, 3u) == 0u ? fx_rng_range(rng, 1u, 2u) : 0u);
        uint8_t n_ctrl = (uint8_t)fx_rng_range(rng, 3u, 20u);
        const float r = fx_rng_float(rng, 0.3f, 8.0f);
        const float a = fx_rng_float(rng, -3.14159f, 3.14159f);
        uint32_t span;

        if (n_ctrl < 2u + 3u * n_vertex) {
            n_ctrl = (uint8_t)(2u + 3u * n_vertex); /* room for the vertex copies */
        }
        f->ctrl_first = res->n_ctrl;
        f->n_ctrl = random_polyline(rng, r * cosf(a), r * sinf(a), &res->ctrl[res->n_ctrl],
                                    &res->ctrl_is_vertex[res->n_ctrl], n_ctrl, n_vertex);
        res->n_ctrl = (uint16_t)(res->n_ctrl + f->n_ctrl);
        f->kind = n_vertex > 0u ? 1u : 0u;
        span = fx_rng_range(rng, 2u, beams_per_feature > 4u ? beams_per_feature - 2u : 2u);
        f->first_beam = (uint16_t)beam;
        f->last_beam = (uint16_t)(beam + span);
        f->n_points =
            (uint16_t)(span + 1u -
                       (fx_rng_range(rng, 0u, 4u) == 0u ? fx_rng_range(rng, 1u, 2u) : 0u));
        f->e_curve = fx_rng_float(rng, 0.0f, 0.03f);
        beam += span + fx_rng_range(rng, 1u, 2u);
        points += f->n_points;
        ++res->n_features;
    }
    res->stats.n_valid = points + fx_rng_range(rng, 0u, 40u);
    res->stats.n_in_features = points;
    res->stats.n_ctrl = res->n_ctrl;
    res->stats.n_features = res->n_features;
    res->stats.time_ns = fx_rng_next(rng);
}
