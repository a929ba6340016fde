/* SPDX-License-Identifier: MIT */
/*
 * fuzz_map_gen.h - scan features of a rectangular room as a robot at a pose
 * would extract them (sensor frame), for the map harnesses: the corners of
 * the room as L-shaped features with a vertex, so that fusing them from a few
 * poses builds a map with merges, appends and vertices to start from.
 */
#ifndef BSF_FUZZ_MAP_GEN_H
#define BSF_FUZZ_MAP_GEN_H

#include <math.h>
#include <string.h>

#include "bsf/bsf.h"

/* Room corners (world, metres), counter-clockwise. */
static const float fuzz_room[4][2] = {{0.0f, 0.0f}, {8.0f, 0.0f}, {8.0f, 6.0f}, {0.0f, 6.0f}};

/* World point (wx, wy) in the frame of a sensor at pose. */
static inline bsf_point_t fuzz_to_sensor(const bsf_pose_t *pose, float wx, float wy)
{
    const float c = cosf(pose->theta);
    const float s = sinf(pose->theta);
    const float dx = wx - pose->x;
    const float dy = wy - pose->y;
    bsf_point_t p;
    p.x = c * dx + s * dy;
    p.y = -s * dx + c * dy;
    return p;
}

/* Each room corner as a feature: two points along the wall before it, the
 * corner (a vertex: two flagged slots), two points along the wall after it.
 * `reach` (metres, < 3) is how far along each wall the feature runs. */
static inline void fuzz_room_scan(const bsf_pose_t *pose, float reach, bsf_result_t *out)
{
    size_t k;
    size_t c = 0u;
    memset(out, 0, sizeof *out);
    for (k = 0; k < 4u; ++k) {
        const float *prev = fuzz_room[(k + 3u) % 4u];
        const float *cur = fuzz_room[k];
        const float *next = fuzz_room[(k + 1u) % 4u];
        const float lp = hypotf(prev[0] - cur[0], prev[1] - cur[1]);
        const float ln = hypotf(next[0] - cur[0], next[1] - cur[1]);
        const float ux = (prev[0] - cur[0]) / lp, uy = (prev[1] - cur[1]) / lp;
        const float vx = (next[0] - cur[0]) / ln, vy = (next[1] - cur[1]) / ln;
        bsf_feature_t *f = &out->features[k];
        f->first_beam = (uint16_t)(k * 40u);
        f->last_beam = (uint16_t)(k * 40u + 30u);
        f->n_points = 31u;
        f->ctrl_first = (uint16_t)c;
        f->n_ctrl = 6u;
        f->kind = 1u;
        f->e_curve = 0.005f;
        out->ctrl[c++] = fuzz_to_sensor(pose, cur[0] + reach * ux, cur[1] + reach * uy);
        out->ctrl[c++] =
            fuzz_to_sensor(pose, cur[0] + 0.5f * reach * ux, cur[1] + 0.5f * reach * uy);
        out->ctrl_is_vertex[c] = 1u;
        out->ctrl[c++] = fuzz_to_sensor(pose, cur[0], cur[1]);
        out->ctrl_is_vertex[c] = 1u;
        out->ctrl[c++] = fuzz_to_sensor(pose, cur[0], cur[1]);
        out->ctrl[c++] =
            fuzz_to_sensor(pose, cur[0] + 0.5f * reach * vx, cur[1] + 0.5f * reach * vy);
        out->ctrl[c++] = fuzz_to_sensor(pose, cur[0] + reach * vx, cur[1] + reach * vy);
    }
    out->n_features = 4u;
    out->n_ctrl = (uint16_t)c;
    out->stats.n_features = 4u;
    out->stats.n_ctrl = (uint32_t)c;
    out->stats.n_beams = 160u;
    out->stats.n_valid = 160u;
    out->stats.n_in_features = 124u;
}

/* A pose of a small loop inside the room, step k. */
static inline bsf_pose_t fuzz_room_pose(unsigned k)
{
    bsf_pose_t p;
    const float a = 0.4f * (float)k;
    p.x = 4.0f + 1.2f * cosf(a);
    p.y = 3.0f + 0.9f * sinf(a);
    p.theta = 0.3f * sinf(a);
    return p;
}

#endif /* BSF_FUZZ_MAP_GEN_H */
