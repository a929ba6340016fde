/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: scan-to-map alignment (bsf_align_points,
 * bsf_align_features) on fuzzed maps, scans, priors and parameters.
 *
 * Input: byte 0 = mode. Bit 0: an empty map, else the room (fuzz_map_gen.h)
 * fused from 1..8 loop poses (byte 1); bit 1: align features, else points;
 * bit 2: parameters from raw float bits; bit 3: the prior from raw float bits
 * (NaN, inf, huge), else the true pose plus a fuzzed offset; bit 4: the scan
 * from fuzzed values (centimetres or raw bits per point, 1..n points or
 * features), else the room as seen from the true pose, cut to a fuzzed number
 * of points (one point included).
 * Properties: the status is BSF_OK, BSF_ERR_ARG or BSF_ERR_PARAM, and *out is
 * untouched on an error; on success the pose is finite, a decline keeps the
 * prior bit for bit and names a documented reason, an accepted correction
 * stays within max_xy and max_theta, and every figure of the result (rms,
 * information matrix, eigenvalue and eigenvector) is finite and within its
 * documented range.
 */
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "fuzz_map_gen.h"

static bsf_map_t map;
static bsf_align_work_t work;
static bsf_result_t scan;
static bsf_points_t points;
static bsf_align_result_t out;
static bsf_align_result_t untouched;

static float take_coord(input_t *in)
{
    const uint8_t how = take1(in);
    if (how & 0x80u) {
        return take_raw(in);
    }
    return (float)(int16_t)take2(in) * 0.01f;
}

/* The room's walls as a scan of points from pose, every 0.1 m, cut to n. */
static void room_points(const bsf_pose_t *pose, size_t n)
{
    size_t k;
    size_t c = 0u;
    memset(&points, 0, sizeof points);
    for (k = 0; k < 4u && c < n; ++k) {
        const float *a = fuzz_room[k];
        const float *b = fuzz_room[(k + 1u) % 4u];
        const float len = hypotf(b[0] - a[0], b[1] - a[1]);
        float s;
        for (s = 0.05f; s < len && c < n && c < BSF_MAX_POINTS; s += 0.1f, ++c) {
            const float t = s / len;
            points.pt[c] = fuzz_to_sensor(pose, a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]));
            points.range[c] = hypotf(points.pt[c].x, points.pt[c].y);
            points.valid[c] = 1u;
        }
    }
    points.count = c;
    points.n_valid = c;
    points.angle_min = -3.14159f;
    points.angle_increment = 0.01f;
}

static void fuzzed_points(input_t *in)
{
    const size_t n = (size_t)take2(in) % BSF_MAX_POINTS + 1u;
    size_t k;
    memset(&points, 0, sizeof points);
    points.count = n;
    for (k = 0; k < n; ++k) {
        points.valid[k] = (uint8_t)(take1(in) & 1u);
        points.pt[k].x = take_coord(in);
        points.pt[k].y = take_coord(in);
        points.range[k] = points.valid[k] ? hypotf(points.pt[k].x, points.pt[k].y) : 0.0f;
        points.n_valid += points.valid[k];
    }
    points.angle_min = -3.14159f;
    points.angle_increment = 0.01f;
}

static void fuzzed_features(input_t *in)
{
    const size_t nf = take1(in) % 6u;
    size_t f;
    size_t c = 0u;
    memset(&scan, 0, sizeof scan);
    for (f = 0; f < nf; ++f) {
        bsf_feature_t *ft = &scan.features[f];
        const size_t nc = take1(in) % 10u;
        size_t k;
        ft->ctrl_first = (uint16_t)c;
        ft->n_ctrl = (uint8_t)nc;
        for (k = 0; k < nc; ++k, ++c) {
            const uint8_t v = take1(in);
            scan.ctrl[c].x = take_coord(in);
            scan.ctrl[c].y = take_coord(in);
            scan.ctrl_is_vertex[c] = (uint8_t)(v & 1u);
        }
    }
    scan.n_features = (uint16_t)nf;
    scan.n_ctrl = (uint16_t)c;
}

static float wrap(float a)
{
    while (a > 3.14159265f) {
        a -= 6.28318531f;
    }
    while (a < -3.14159265f) {
        a += 6.28318531f;
    }
    return a;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    input_t in;
    uint8_t mode;
    bsf_align_params_t p;
    bsf_pose_t truth;
    bsf_pose_t prior;
    bsf_status_t st;
    size_t k;
    if (size < 2u) {
        return 0;
    }
    mode = data[0];
    in.p = data + 2;
    in.n = size - 2u;
    FUZZ_CHECK(bsf_map_init(&map, NULL) == BSF_OK);
    if (!(mode & 1u)) {
        const unsigned n_fuse = data[1] % 8u + 1u;
        unsigned j;
        for (j = 0; j < n_fuse; ++j) {
            const bsf_pose_t at = fuzz_room_pose(j);
            fuzz_room_scan(&at, 2.5f, &scan);
            FUZZ_CHECK(bsf_map_fuse(&map, &scan, &at) == 4);
        }
    }
    bsf_align_params_default(&p);
    if (mode & 4u) {
        p.max_dist = take_raw(&in);
        p.huber = take_raw(&in);
        p.max_xy = take_raw(&in);
        p.max_theta = take_raw(&in);
        p.vertex_weight = take_raw(&in);
        p.free_ratio = take_raw(&in);
        p.max_iter = (uint16_t)(take1(&in) % 64u);
        p.max_points = take2(&in);
        p.min_matches = take2(&in);
    }
    truth = fuzz_room_pose(take1(&in));
    if (mode & 8u) {
        prior.x = take_raw(&in);
        prior.y = take_raw(&in);
        prior.theta = take_raw(&in);
    } else {
        prior.x = truth.x + (float)(int8_t)take1(&in) * 0.005f;
        prior.y = truth.y + (float)(int8_t)take1(&in) * 0.005f;
        prior.theta = truth.theta + (float)(int8_t)take1(&in) * 0.002f;
    }
    if (mode & 16u) {
        if (mode & 2u) {
            fuzzed_features(&in);
        } else {
            fuzzed_points(&in);
        }
    } else {
        fuzz_room_scan(&truth, 0.3f + (float)(take1(&in) % 30u) * 0.1f, &scan);
        room_points(&truth, (size_t)take2(&in) % 300u + 1u);
    }
    memset(&out, 0xA5, sizeof out);
    memcpy(&untouched, &out, sizeof out);
    if (mode & 2u) {
        st = bsf_align_features(&work, &p, &map, &scan, &prior, &out);
    } else {
        st = bsf_align_points(&work, &p, &map, &points, (mode & 32u) ? &scan : NULL, &prior, &out);
    }
    fuzz_check_status(st);
    FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_ARG || st == BSF_ERR_PARAM);
    if (st != BSF_OK) {
        FUZZ_CHECK(memcmp(&out, &untouched, sizeof out) == 0);
        return 0;
    }
    FUZZ_CHECK(fuzz_finite(prior.x) && fuzz_finite(prior.y) && fuzz_finite(prior.theta));
    FUZZ_CHECK(fuzz_finite(out.pose.x) && fuzz_finite(out.pose.y) && fuzz_finite(out.pose.theta));
    FUZZ_CHECK(out.declined < BSF_ALIGN_DECLINE_COUNT);
    FUZZ_CHECK(bsf_align_decline_str(out.declined) != NULL);
    FUZZ_CHECK((out.flags & ~7u) == 0u && out.n_free <= 3u);
    FUZZ_CHECK(out.n_iter <= p.max_iter && out.n_matches <= out.n_points);
    FUZZ_CHECK(out.n_points <= p.max_points && out.n_points <= BSF_ALIGN_MAX_POINTS);
    FUZZ_CHECK(out.n_segs <= BSF_ALIGN_MAX_SEGS);
    if (out.declined != BSF_ALIGN_ACCEPTED) {
        FUZZ_CHECK(memcmp(&out.pose, &prior, sizeof prior) == 0);
    } else {
        FUZZ_CHECK(fabsf(out.pose.x - prior.x) <= p.max_xy * 1.0001f + 1e-6f);
        FUZZ_CHECK(fabsf(out.pose.y - prior.y) <= p.max_xy * 1.0001f + 1e-6f);
        FUZZ_CHECK(fabsf(wrap(out.pose.theta - prior.theta)) <= p.max_theta * 1.0001f + 1e-6f);
        FUZZ_CHECK(out.n_matches >= p.min_matches);
    }
    if ((mode & 1u) && out.n_points >= p.min_matches) {
        FUZZ_CHECK(out.declined == BSF_ALIGN_DECLINE_EMPTY_MAP); /* nothing to align to */
    }
    FUZZ_CHECK(fuzz_finite(out.rms) && out.rms >= 0.0f);
    FUZZ_CHECK(fuzz_finite(out.min_eig));
    for (k = 0; k < 9u; ++k) {
        FUZZ_CHECK(fuzz_finite(out.info[k]));
    }
    for (k = 0; k < 3u; ++k) {
        FUZZ_CHECK(fuzz_finite(out.min_eigvec[k]));
    }
    return 0;
}
