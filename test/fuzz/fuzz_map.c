/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: the robot's map (bsf_map_fuse, bsf_map_encode) driven by
 * fuzzed scan features and poses, and a receiver fed every frame it writes.
 *
 * Input: byte 0 = mode (bit 0: parameters from raw float bits in the next
 * 24 bytes, else byte 1-3 pick frame_interval, snapshot_budget and the step
 * among valid values). Then steps until the input ends, each one op byte:
 *  op & 3 == 0: the room's corners seen from a loop pose (fuzz_map_gen.h)
 *               with a fuzzed reach and a pose offset;
 *  op & 3 == 1: fuzzed features: counts, control points as centimetres
 *               (int16) or raw float bits (NaN, inf, huge), vertex flags,
 *               n_ctrl below 3 or past the pool;
 *  op & 3 == 2: an empty scan (time passes: transients expire, snapshots go);
 *  op & 3 == 3: the room scan at a pose of raw float bits.
 * bits 2-3 of op: the encoder's pose (none, the scan's, raw bits); bits 4-5:
 * its buffer (the largest frame, a fuzzed cap from 0, the smallest allowed).
 * Properties: fuse returns a count <= the scan's features or a documented
 * error, and an error leaves the map byte for byte unchanged; encode returns
 * a documented status and a frame within its cap; every frame goes through
 * the stream decoder and applies with no record skipped, advancing no
 * feature's update count by more than 4; after every call
 * the map's fused control points are finite and within the caps, and the
 * receiver holds exactly the robot's sent copy of every feature, none
 * flagged (snapshots on or off: a snapshot of a feature the receiver can
 * vouch for leaves it whole), whenever no map change waits to be sent
 * (bsf_map_pending).
 */
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_input.h"
#include "fuzz_map_gen.h"

static bsf_map_t map;
static bsf_map_t map_before;
static bsf_map_rx_t rx;
static bsf_decoder_t dec;
static bsf_frame_t frame;
static bsf_result_t scan;
static uint8_t buf[BSF_MAP_FRAME_MAX_SIZE];
static bsf_point_t pts[2u * BSF_MAP_MAX_CTRL];
static int32_t q_robot[2u * BSF_MAP_MAX_CTRL];
static int32_t q_rx[2u * BSF_MAP_MAX_CTRL];
static uint8_t v_robot[BSF_MAP_MAX_CTRL];
static uint8_t v_rx[BSF_MAP_MAX_CTRL];

/* centimetres as int16: up to 327 m */
static float take_cm(input_t *in)
{
    return (float)(int16_t)take2(in) * 0.01f;
}

static void fuzzed_scan(input_t *in)
{
    const uint8_t nf = take1(in);
    size_t f;
    size_t c = 0u;
    memset(&scan, 0, sizeof scan);
    scan.n_features = (uint16_t)(nf % 9u);
    for (f = 0; f < scan.n_features; ++f) {
        const uint8_t spec = take1(in);
        bsf_feature_t *ft = &scan.features[f];
        size_t k;
        /* n_ctrl 0..15: below 3 is refused; the last feature may claim
         * points past the pool (bit 4 of spec) */
        ft->n_ctrl = (uint8_t)(spec & 0x0Fu);
        ft->ctrl_first = (uint16_t)c;
        ft->first_beam = (uint16_t)(f * 10u);
        ft->last_beam = (uint16_t)(f * 10u + 9u);
        ft->n_points = 10u;
        for (k = 0; k < ft->n_ctrl && c < BSF_MAX_CTRL_POINTS; ++k, ++c) {
            const uint8_t how = take1(in);
            if (how & 0x80u) {
                scan.ctrl[c].x = take_raw(in);
                scan.ctrl[c].y = take_raw(in);
            } else {
                scan.ctrl[c].x = take_cm(in);
                scan.ctrl[c].y = take_cm(in);
            }
            scan.ctrl_is_vertex[c] = (uint8_t)(how & 1u);
        }
    }
    scan.n_ctrl = (uint16_t)c;
    if (scan.n_features > 0u && (take1(in) & 0x10u)) {
        scan.n_ctrl = (uint16_t)(c > 0u ? c - 1u : 0u); /* the last feature reaches past it */
    }
    scan.stats.n_features = scan.n_features;
    scan.stats.n_ctrl = scan.n_ctrl;
}

/* Calls whose comparison was skipped: map changes held back (a merge made
 * by the robot shows in its sent copy before its record goes out). */
static unsigned long n_held;

/* compare: 0 while bsf_map_pending() says changes wait (frame_interval),
 * when only the robot's values are checked. */
static void check_receiver_equals_sent(int compare)
{
    size_t i;
    const size_t count = bsf_map_feature_count(&map);
    FUZZ_CHECK(count <= BSF_MAP_MAX_FEATURES);
    for (i = 0; i < count; ++i) {
        uint32_t id = 0u;
        uint32_t id2 = 0u;
        uint8_t stale = 1u;
        int k;
        const int n = bsf_map_feature_q(&map, i, q_robot, v_robot, BSF_MAP_MAX_CTRL, &id);
        const int nf = bsf_map_feature_ctrl(&map, i, 0, pts, NULL, 2u * BSF_MAP_MAX_CTRL, &id2);
        int m;
        FUZZ_CHECK(n >= 0 && n <= BSF_MAP_MAX_CTRL);
        FUZZ_CHECK(nf >= 0 && nf <= 2 * BSF_MAP_MAX_CTRL && id2 == id);
        for (k = 0; k < nf; ++k) {
            FUZZ_CHECK(fuzz_finite(pts[k].x) && fuzz_finite(pts[k].y));
        }
        if (!compare) {
            continue;
        }
        m = bsf_map_rx_feature_q(&rx, id, q_rx, v_rx, BSF_MAP_MAX_CTRL);
        FUZZ_CHECK(bsf_map_rx_feature_ctrl(&rx, id, NULL, NULL, 0u, &stale) >= 0);
        if (m != n) {
            fprintf(stderr, "feature %u: robot sent %d points, receiver holds %d\n", (unsigned)id,
                    n, m);
        }
        FUZZ_CHECK(m == n && stale == 0u);
        FUZZ_CHECK(memcmp(q_robot, q_rx, (size_t)n * 2u * sizeof q_robot[0]) == 0);
        FUZZ_CHECK(memcmp(v_robot, v_rx, (size_t)n) == 0);
    }
}

static void deliver(size_t len)
{
    size_t off = 0u;
    int maps = 0;
    while (off < len) {
        size_t used = 0u;
        const int got = bsf_decoder_feed(&dec, buf + off, len - off, &used, &frame);
        FUZZ_CHECK(used > 0u);
        off += used;
        FUZZ_CHECK(got == 0 || got == (int)BSF_FRAME_TYPE_MAP);
        if (got == (int)BSF_FRAME_TYPE_MAP) {
            /* a frame advances a feature's update count by at most 4 (what
             * lets a receiver confirm a feature by its count after a short
             * loss): counted here through the receiver's counts */
            static uint8_t upd[BSF_MAP_RX_MAX_FEATURES];
            static uint8_t held[BSF_MAP_RX_MAX_FEATURES];
            const uint32_t limit = bsf_map_rx_id_limit(&rx);
            uint32_t id;
            int skipped;
            for (id = 0; id < limit; ++id) {
                upd[id] = rx.features[id].upd;
                held[id] = bsf_map_rx_feature_state(&rx, id) == BSF_MAP_RX_CONFIRMED;
            }
            skipped = bsf_map_rx_apply(&rx, frame.payload, frame.payload_len);
            FUZZ_CHECK(skipped == 0); /* lost nothing: every record applies */
            for (id = 0; id < limit; ++id) {
                if (held[id] && bsf_map_rx_feature_state(&rx, id) == BSF_MAP_RX_CONFIRMED) {
                    FUZZ_CHECK((((unsigned)rx.features[id].upd - upd[id]) & 15u) <= 4u);
                }
            }
            ++maps;
        }
    }
    FUZZ_CHECK(maps == 1 && dec.len == 0u);
}

static int init_map(input_t *in, uint8_t mode)
{
    bsf_map_params_t p;
    bsf_status_t st;
    bsf_map_params_default(&p);
    if (mode & 1u) {
        p.match_dist = take_raw(in);
        p.match_angle = take_raw(in);
        p.vertex_dist = take_raw(in);
        p.ctrl_spacing = take_raw(in);
        p.send_tol = take_raw(in);
        p.quant_step = take_raw(in);
        p.weight_cap = take1(in);
        p.snapshot_budget = take2(in);
        p.frame_interval = (uint16_t)(take1(in) % 20u);
    } else {
        static const float steps[4] = {0.005f, 0.001f, 0.02f, 0.0001f};
        p.frame_interval = (uint16_t)(take1(in) % 8u + 1u);
        p.snapshot_budget = (uint16_t)(take1(in) & 0x7Fu);
        p.quant_step = steps[take1(in) & 3u];
    }
    st = bsf_map_init(&map, &p);
    FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_PARAM);
    return st == BSF_OK;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    input_t in;
    unsigned step = 0u;
    if (size < 1u) {
        return 0;
    }
    in.p = data + 1;
    in.n = size - 1u;
    if (!init_map(&in, data[0])) {
        return 0;
    }
    bsf_map_rx_init(&rx);
    bsf_decoder_init(&dec);
    while (in.n > 0u && step < 400u) {
        const uint8_t op = take1(&in);
        bsf_pose_t pose = fuzz_room_pose(step);
        bsf_pose_t enc_pose;
        const bsf_pose_t *enc_arg = NULL;
        size_t cap = sizeof buf;
        size_t len = 0u;
        bsf_status_t st;
        int r;
        ++step;
        switch (op & 3u) {
        case 0:
            pose.x += (float)(int8_t)take1(&in) * 0.002f;
            pose.theta += (float)(int8_t)take1(&in) * 0.002f;
            fuzz_room_scan(&pose, 0.3f + (float)(take1(&in) % 25u) * 0.1f, &scan);
            break;
        case 1:
            pose.x = take_cm(&in);
            pose.y = take_cm(&in);
            pose.theta = (float)(int16_t)take2(&in) * 1e-4f;
            fuzzed_scan(&in);
            break;
        case 2: memset(&scan, 0, sizeof scan); break;
        default:
            pose.x = take_raw(&in);
            pose.y = take_raw(&in);
            pose.theta = take_raw(&in);
            fuzz_room_scan(&pose, 1.0f, &scan);
            break;
        }
        memcpy(&map_before, &map, sizeof map);
        r = bsf_map_fuse(&map, &scan, &pose);
        fuzz_check_status(r < 0 ? (bsf_status_t)r : BSF_OK);
        if (r < 0) {
            FUZZ_CHECK(r == BSF_ERR_ARG || r == BSF_ERR_CAPACITY);
            FUZZ_CHECK(memcmp(&map, &map_before, sizeof map) == 0);
        } else {
            FUZZ_CHECK(r <= (int)scan.n_features);
        }
        switch ((op >> 2) & 3u) {
        case 0: break;
        case 1: enc_arg = &pose; break;
        default:
            enc_pose.x = take_raw(&in);
            enc_pose.y = take_raw(&in);
            enc_pose.theta = take_raw(&in);
            enc_arg = &enc_pose;
            break;
        }
        switch ((op >> 4) & 3u) {
        case 0: break;
        case 1: cap = take2(&in) % (sizeof buf + 1u); break;
        default: cap = BSF_MAP_FRAME_MIN_SIZE + (op >> 6); break;
        }
        st = bsf_map_encode(&map, enc_arg, buf, cap, &len);
        fuzz_check_status(st);
        FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_ARG || st == BSF_ERR_BUFFER);
        FUZZ_CHECK(st != BSF_ERR_BUFFER || cap < BSF_MAP_FRAME_MIN_SIZE);
        if (st == BSF_OK && len > 0u) {
            FUZZ_CHECK(len <= cap && len <= BSF_MAP_FRAME_MAX_SIZE && buf[len - 1u] == 0u);
            deliver(len);
        }
        if (bsf_map_pending(&map)) {
            ++n_held;
        }
        check_receiver_equals_sent(!bsf_map_pending(&map));
    }
    return 0;
}
