/* SPDX-License-Identifier: MIT */
#include "det_core.h"

#include <string.h>

#include "bsf_scene.h"

static bsf_extractor_t ex;
static bsf_result_t res;
static bsf_decoder_t dec;
static bsf_frame_t decoded;
static uint8_t wire[BSF_FRAME_MAX_SIZE];
static float ranges[BSF_MAX_POINTS];

uint32_t det_fnv1a(uint32_t h, const uint8_t *p, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 16777619u;
    }
    return h;
}

uint32_t det_hash_u32(uint32_t h, uint32_t v)
{
    uint8_t le[4];
    le[0] = (uint8_t)(v & 0xffu);
    le[1] = (uint8_t)((v >> 8) & 0xffu);
    le[2] = (uint8_t)((v >> 16) & 0xffu);
    le[3] = (uint8_t)(v >> 24);
    return det_fnv1a(h, le, sizeof le);
}

uint32_t det_hash_floats(uint32_t h, const float *p, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        uint32_t bits;
        memcpy(&bits, &p[i], sizeof bits);
        h = det_hash_u32(h, bits);
    }
    return h;
}

static float float_of_bits(uint32_t bits)
{
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* The decoded values that must not depend on the target: header, pose and
 * every feature with its control points. */
static uint32_t hash_frame(uint32_t h, const bsf_frame_t *f)
{
    uint16_t i;
    h = det_hash_u32(h, f->seq);
    h = det_hash_u32(h, (uint32_t)(f->timestamp_ms & 0xffffffffu));
    h = det_hash_u32(h, (uint32_t)(f->timestamp_ms >> 32));
    h = det_hash_u32(h, f->has_pose);
    h = det_hash_floats(h, &f->pose.x, 1u);
    h = det_hash_floats(h, &f->pose.y, 1u);
    h = det_hash_floats(h, &f->pose.theta, 1u);
    h = det_hash_floats(h, &f->quant_step, 1u);
    h = det_hash_u32(h, f->result.n_features);
    h = det_hash_u32(h, f->result.n_ctrl);
    for (i = 0; i < f->result.n_features; ++i) {
        const bsf_feature_t *ft = &f->result.features[i];
        h = det_hash_u32(h, ((uint32_t)ft->first_beam << 16) | ft->last_beam);
        h = det_hash_u32(h, ((uint32_t)ft->n_ctrl << 8) | ft->kind);
        h = det_hash_floats(h, &ft->e_curve, 1u);
    }
    for (i = 0; i < f->result.n_ctrl; ++i) {
        h = det_hash_floats(h, &f->result.ctrl[i].x, 1u);
        h = det_hash_floats(h, &f->result.ctrl[i].y, 1u);
        h = det_hash_u32(h, f->result.ctrl_is_vertex[i]);
    }
    return h;
}

/* Extract scan with method m, encode it with info, decode the frame again
 * through the byte-stream decoder, and fold everything into *out. */
static bsf_status_t det_frame(const bsf_scan_t *scan, const bsf_frame_info_t *info, bsf_method_t m,
                              det_summary_t *out,
                              void (*frame_cb)(void *ctx, const uint8_t *frame, size_t len),
                              void *ctx)
{
    const bsf_params_t p = bsf_params_default(m);
    size_t len = 0u;
    size_t used = 0u;
    bsf_status_t st = bsf_extractor_init(&ex, &p);
    if (st == BSF_OK) {
        st = bsf_extract(&ex, scan, &res);
    }
    if (st < 0) { /* a cut result (BSF_OK_CUT) is output too */
        return st;
    }
    st = bsf_frame_encode(info, &res, wire, sizeof wire, &len);
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
    bsf_decoder_init(&dec);
    if (bsf_decoder_feed(&dec, wire, len, &used, &decoded) == 1) {
        out->decoded_hash = hash_frame(out->decoded_hash, &decoded);
        ++out->frames_decoded;
    }
    return BSF_OK;
}

static void summary_init(det_summary_t *out)
{
    memset(out, 0, sizeof *out);
    out->ranges_hash = DET_FNV_INIT;
    out->stream_hash = DET_FNV_INIT;
    out->decoded_hash = DET_FNV_INIT;
}

static const bsf_method_t det_methods[DET_METHODS] = {BSF_METHOD_FALKO_SVED_PDM,
                                                      BSF_METHOD_RPOS_LSBA};

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
    unsigned k;
    unsigned m;
    summary_init(out);
    for (k = 0; k < DET_SCANS; ++k) {
        bsf_scan_t scan;
        bsf_status_t st = det_simulate(k, ranges, &scan);
        if (st != BSF_OK) {
            return st;
        }
        if (ranges_in != NULL) {
            memcpy(ranges, ranges_in + (size_t)k * DET_BEAMS, DET_BEAMS * sizeof ranges[0]);
        }
        out->ranges_hash = det_hash_floats(out->ranges_hash, ranges, DET_BEAMS);
        for (m = 0; m < DET_METHODS; ++m) {
            bsf_frame_info_t info;
            bsf_frame_info_init(&info);
            info.seq = k * DET_METHODS + m;
            info.timestamp_ms = 100u * k;
            st = det_frame(&scan, &info, det_methods[m], out, frame_cb, ctx);
            if (st != BSF_OK) {
                return st;
            }
        }
    }
    return BSF_OK;
}

bsf_status_t det_run_log(const det_log_scan_t *scans, size_t n, const uint32_t *range_bits,
                         det_summary_t *out)
{
    size_t k, i, at = 0u;
    unsigned m;
    summary_init(out);
    for (k = 0; k < n; ++k) {
        const det_log_scan_t *s = &scans[k];
        bsf_scan_t scan;
        if (s->count > BSF_MAX_POINTS) {
            return BSF_ERR_CAPACITY;
        }
        for (i = 0; i < s->count; ++i) {
            ranges[i] = float_of_bits(range_bits[at + i]);
        }
        at += s->count;
        out->ranges_hash = det_hash_floats(out->ranges_hash, ranges, s->count);
        scan.ranges = ranges;
        scan.count = s->count;
        scan.angle_min = float_of_bits(s->angle_min);
        scan.angle_increment = float_of_bits(s->angle_increment);
        scan.range_min = 0.0f;
        scan.range_max = float_of_bits(s->range_max);
        for (m = 0; m < DET_METHODS; ++m) {
            bsf_frame_info_t info;
            bsf_status_t st;
            bsf_frame_info_init(&info);
            info.seq = (uint32_t)(k * DET_METHODS + m);
            info.timestamp_ms = s->timestamp_ms;
            info.has_pose = 1u;
            info.pose.x = float_of_bits(s->pose_x);
            info.pose.y = float_of_bits(s->pose_y);
            info.pose.theta = float_of_bits(s->pose_theta);
            st = det_frame(&scan, &info, det_methods[m], out, NULL, NULL);
            if (st != BSF_OK) {
                return st;
            }
        }
    }
    return BSF_OK;
}

/* ---- the fused map and alignment ---------------------------------------------- */

static bsf_map_t det_map;
static bsf_map_rx_t det_rx;
static bsf_align_work_t det_align_work;
static bsf_points_t det_points;
static uint8_t map_wire[BSF_MAP_FRAME_MAX_SIZE];

static bsf_status_t map_start(det_map_summary_t *out)
{
    bsf_map_params_t p;
    memset(out, 0, sizeof *out);
    out->stream_hash = DET_FNV_INIT;
    out->align_hash = DET_FNV_INIT;
    out->rx_hash = DET_FNV_INIT;
    bsf_map_params_default(&p);
    p.frame_interval = 1u;
    p.snapshot_budget = 32u;
    bsf_map_rx_init(&det_rx);
    bsf_decoder_init(&dec);
    return bsf_map_init(&det_map, &p);
}

/* One scan: extract (default method), align from a prior off `pose` once the
 * map holds something, fuse at the aligned pose, write a frame, apply it. */
static bsf_status_t map_step(const bsf_scan_t *scan, const bsf_pose_t *pose, unsigned k,
                             det_map_summary_t *out)
{
    const bsf_params_t p = bsf_params_default(BSF_METHOD_LC_SVED_PDM);
    bsf_pose_t at = *pose;
    size_t len = 0u;
    size_t off = 0u;
    int r;
    bsf_status_t st = bsf_extractor_init(&ex, &p);
    if (st == BSF_OK) {
        st = bsf_extract(&ex, scan, &res);
    }
    if (st < 0) {
        return st;
    }
    if (bsf_map_feature_count(&det_map) > 0u) {
        bsf_align_result_t ar;
        bsf_pose_t prior = *pose;
        prior.x += (k % 2u) ? 0.04f : -0.03f;
        prior.y += 0.02f;
        prior.theta += (k % 3u) ? 0.01f : -0.015f;
        st = bsf_scan_to_points(scan, &det_points);
        if (st != BSF_OK) {
            return st;
        }
        st = bsf_align_points(&det_align_work, NULL, &det_map, &det_points, &res, &prior, &ar);
        if (st != BSF_OK) {
            return st;
        }
        out->align_hash = det_hash_floats(out->align_hash, &ar.pose.x, 1u);
        out->align_hash = det_hash_floats(out->align_hash, &ar.pose.y, 1u);
        out->align_hash = det_hash_floats(out->align_hash, &ar.pose.theta, 1u);
        out->align_hash =
            det_hash_u32(out->align_hash, ((uint32_t)ar.declined << 16) | ar.n_matches);
        out->align_hash = det_hash_floats(out->align_hash, &ar.rms, 1u);
        if (ar.declined == BSF_ALIGN_ACCEPTED) {
            ++out->n_accepted;
            at = ar.pose;
        }
    }
    r = bsf_map_fuse(&det_map, &res, &at);
    if (r < 0) {
        return (bsf_status_t)r;
    }
    st = bsf_map_encode(&det_map, &at, map_wire, sizeof map_wire, &len);
    if (st != BSF_OK) {
        return st;
    }
    if (len > 0u) {
        out->stream_hash = det_fnv1a(out->stream_hash, map_wire, len);
        out->stream_bytes += (uint32_t)len;
        ++out->frames;
    }
    while (off < len) {
        size_t used = 0u;
        const int got = bsf_decoder_feed(&dec, map_wire + off, len - off, &used, &decoded);
        off += used;
        if (got == (int)BSF_FRAME_TYPE_MAP &&
            bsf_map_rx_apply(&det_rx, decoded.payload, decoded.payload_len) < 0) {
            return BSF_ERR_FORMAT;
        }
    }
    return BSF_OK;
}

static void map_finish(det_map_summary_t *out)
{
    uint32_t id;
    for (id = 0; id < bsf_map_rx_id_limit(&det_rx); ++id) {
        static int32_t q[2u * BSF_MAP_MAX_CTRL];
        static uint8_t v[BSF_MAP_MAX_CTRL];
        const int n = bsf_map_rx_feature_q(&det_rx, id, q, v, BSF_MAP_MAX_CTRL);
        int i;
        out->rx_hash = det_hash_u32(out->rx_hash, id);
        out->rx_hash = det_hash_u32(out->rx_hash, (uint32_t)n);
        for (i = 0; i < n && i < (int)BSF_MAP_MAX_CTRL; ++i) {
            out->rx_hash = det_hash_u32(out->rx_hash, (uint32_t)q[2 * i]);
            out->rx_hash = det_hash_u32(out->rx_hash, (uint32_t)q[2 * i + 1]);
            out->rx_hash = det_hash_u32(out->rx_hash, v[i]);
        }
        out->rx_points += n > 0 ? (uint32_t)n : 0u;
    }
}

bsf_status_t det_run_map(const float *ranges_in, det_map_summary_t *out)
{
    unsigned j;
    bsf_status_t st = map_start(out);
    /* three rounds of the demo scans: features seen again are sent */
    for (j = 0; j < 3u * DET_SCANS && st == BSF_OK; ++j) {
        const unsigned k = j % DET_SCANS;
        bsf_scan_t scan;
        const bsf_lidar_t lid = det_lidar(k);
        bsf_pose_t pose;
        st = det_simulate(k, ranges, &scan);
        if (st != BSF_OK) {
            break;
        }
        if (ranges_in != NULL) {
            memcpy(ranges, ranges_in + (size_t)k * DET_BEAMS, DET_BEAMS * sizeof ranges[0]);
        }
        pose.x = (float)lid.pose.x;
        pose.y = (float)lid.pose.y;
        pose.theta = (float)lid.pose.theta;
        st = map_step(&scan, &pose, j, out);
    }
    if (st == BSF_OK) {
        map_finish(out);
    }
    return st;
}

bsf_status_t det_run_map_log(const det_log_scan_t *scans, size_t n, const uint32_t *range_bits,
                             det_map_summary_t *out)
{
    size_t k, i, at = 0u;
    bsf_status_t st = map_start(out);
    for (k = 0; k < n && st == BSF_OK; ++k) {
        const det_log_scan_t *s = &scans[k];
        bsf_scan_t scan;
        bsf_pose_t pose;
        if (s->count > BSF_MAX_POINTS) {
            return BSF_ERR_CAPACITY;
        }
        for (i = 0; i < s->count; ++i) {
            ranges[i] = float_of_bits(range_bits[at + i]);
        }
        at += s->count;
        scan.ranges = ranges;
        scan.count = s->count;
        scan.angle_min = float_of_bits(s->angle_min);
        scan.angle_increment = float_of_bits(s->angle_increment);
        scan.range_min = 0.0f;
        scan.range_max = float_of_bits(s->range_max);
        pose.x = float_of_bits(s->pose_x);
        pose.y = float_of_bits(s->pose_y);
        pose.theta = float_of_bits(s->pose_theta);
        st = map_step(&scan, &pose, (unsigned)k, out);
    }
    if (st == BSF_OK) {
        map_finish(out);
    }
    return st;
}
