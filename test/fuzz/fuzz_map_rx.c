/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: hostile map-update payloads into the receiver's map
 * (bsf_map_rx_apply), beyond the stream decoder's own checks.
 *
 * Input: byte 0 = mode. Bit 0: first apply the map frames of a small robot
 * map (a room fused from a few poses, made once), so that the hostile
 * records meet features with points, vertices and update counts. Bit 1:
 * each fuzzed payload goes through the stream decoder (CRC added, COBS,
 * delimiter) rather than straight to the receiver. The rest is a sequence of
 * payloads, each a 2-byte little-endian length then that many bytes (cut at
 * the end of the input).
 * Properties after every apply: the return is a skip count or a documented
 * error; a refused payload leaves the receiver byte for byte unchanged; every
 * held control point is within the wire's range (|q| <= 2^23 - 1) and finite
 * in metres; the id limit and the points held stay within the caps, and the
 * held points plus the free list add up to the pool; a feature that turns
 * flagged (unconfirmed, stale or missing) does so only in a frame that
 * reported skipped records, carried a snapshot in parts, followed a gap in
 * the sequence numbers, or named a larger id than any before (ids below it
 * that never arrived are missing); after the robot's frames, lost nothing,
 * every feature is confirmed.
 */
#include <string.h>

#include "fuzz_check.h"
#include "fuzz_map_gen.h"

#define WIRE_Q_MAX 8388607 /* 2^23 - 1: the largest quantised coordinate on the wire */
#define PRELUDE_MAX 64

static bsf_map_rx_t rx;
static bsf_map_rx_t before;
static bsf_map_t robot;
static bsf_decoder_t dec;
static bsf_frame_t frame;
static bsf_result_t scan;
static uint8_t stale_before[BSF_MAP_RX_MAX_FEATURES];
static uint8_t prelude[PRELUDE_MAX][BSF_MAP_FRAME_MAX_SIZE];
static size_t prelude_len[PRELUDE_MAX];
static size_t n_prelude;
static int made;
static uint8_t body[0x10000 + 4u];
static uint8_t wire[BSF_COBS_MAX_SIZE(0x10000 + 4u) + 1u];

/* The map frames of a room fused from 16 poses, with a frame every call. */
static void make_prelude(void)
{
    bsf_map_params_t p;
    unsigned k;
    bsf_map_params_default(&p);
    p.frame_interval = 1u;
    p.snapshot_budget = 24u;
    FUZZ_CHECK(bsf_map_init(&robot, &p) == BSF_OK);
    for (k = 0; k < 16u && n_prelude < PRELUDE_MAX; ++k) {
        const bsf_pose_t pose = fuzz_room_pose(k);
        size_t len = 0u;
        fuzz_room_scan(&pose, 0.6f + 0.15f * (float)k, &scan);
        FUZZ_CHECK(bsf_map_fuse(&robot, &scan, &pose) >= 0);
        FUZZ_CHECK(bsf_map_encode(&robot, &pose, prelude[n_prelude], BSF_MAP_FRAME_MAX_SIZE,
                                  &len) == BSF_OK);
        if (len > 0u) {
            prelude_len[n_prelude++] = len;
        }
    }
    FUZZ_CHECK(n_prelude >= 2u);
    made = 1;
}

static void snapshot_stale(void)
{
    uint32_t id;
    for (id = 0; id < bsf_map_rx_id_limit(&rx); ++id) {
        uint8_t st = 0u;
        FUZZ_CHECK(bsf_map_rx_feature_ctrl(&rx, id, NULL, NULL, 0u, &st) >= 0);
        stale_before[id] = st;
    }
}

/* The receiver's invariants after an apply that returned r. */
static void check_rx(int r)
{
    uint32_t id;
    size_t held = 0u;
    int newly_stale = 0;
    FUZZ_CHECK(r >= 0 || r == BSF_ERR_FORMAT || r == BSF_ERR_VERSION);
    if (r < 0) {
        FUZZ_CHECK(memcmp(&rx, &before, sizeof rx) == 0);
        return;
    }
    FUZZ_CHECK(rx.stats.frames == before.stats.frames + 1u);
    FUZZ_CHECK(rx.stats.records_skipped == before.stats.records_skipped + (uint32_t)r);
    FUZZ_CHECK(fuzz_finite(rx.quant_step) && rx.quant_step > 0.0f);
    FUZZ_CHECK(bsf_map_rx_id_limit(&rx) <= BSF_MAP_RX_MAX_FEATURES);
    FUZZ_CHECK(bsf_map_rx_id_limit(&rx) >= bsf_map_rx_id_limit(&before));
    if (rx.has_pose) {
        FUZZ_CHECK(fuzz_finite(rx.pose.x) && fuzz_finite(rx.pose.y) && fuzz_finite(rx.pose.theta));
    }
    for (id = 0; id < bsf_map_rx_id_limit(&rx); ++id) {
        const bsf_map_rx_feature_t *f = &rx.features[id];
        uint16_t i;
        size_t n = 0u;
        uint8_t st = 0u;
        int m;
        for (i = f->head; i != 0xFFFFu; i = rx.ctrl[i].next) {
            const bsf_map_rx_ctrl_t *c = &rx.ctrl[i];
            FUZZ_CHECK(i < BSF_MAP_RX_MAX_CTRL);
            FUZZ_CHECK(c->qx >= -WIRE_Q_MAX && c->qx <= WIRE_Q_MAX);
            FUZZ_CHECK(c->qy >= -WIRE_Q_MAX && c->qy <= WIRE_Q_MAX);
            FUZZ_CHECK(c->vertex <= 1u);
            FUZZ_CHECK(fuzz_finite((float)c->qx * rx.quant_step) &&
                       fuzz_finite((float)c->qy * rx.quant_step));
            ++n;
            FUZZ_CHECK(n <= BSF_MAP_RX_MAX_CTRL); /* no cycle */
        }
        FUZZ_CHECK(n == f->n_ctrl);
        FUZZ_CHECK(bsf_map_rx_feature_q(&rx, id, NULL, NULL, 0u) == (int)n);
        m = bsf_map_rx_feature_ctrl(&rx, id, NULL, NULL, 0u, &st);
        FUZZ_CHECK(m >= (int)n && m <= 2 * (int)n);
        held += n;
        if (st && (id >= bsf_map_rx_id_limit(&before) || !stale_before[id])) {
            const int state = bsf_map_rx_feature_state(&rx, id);
            FUZZ_CHECK(state >= BSF_MAP_RX_UNCONFIRMED && state <= BSF_MAP_RX_MISSING);
            if (!(state == BSF_MAP_RX_MISSING && n == 0u &&
                  bsf_map_rx_id_limit(&rx) > bsf_map_rx_id_limit(&before))) {
                newly_stale = 1;
            }
        }
    }
    FUZZ_CHECK(held + rx.n_free_ctrl == BSF_MAP_RX_MAX_CTRL);
    /* a feature marked stale by this frame: the frame reported a skip, or
     * carried the first parts of a snapshot (the feature is incomplete and
     * flagged until its last part) */
    FUZZ_CHECK(!newly_stale || r > 0 || rx.stats.snapshots > before.stats.snapshots ||
               rx.lost != before.lost);
}

static void apply_direct(const uint8_t *p, size_t n)
{
    int r;
    memcpy(&before, &rx, sizeof rx);
    snapshot_stale();
    r = bsf_map_rx_apply(&rx, p, n);
    check_rx(r);
}

/* The payload as a frame on a link: CRC-32C, COBS, delimiter; what the
 * decoder delivers is applied, and a map frame it delivers is one the
 * receiver's own check accepts. */
static void apply_via_decoder(const uint8_t *p, size_t n)
{
    size_t wlen = 0u;
    size_t off = 0u;
    uint32_t crc;
    memcpy(body, p, n);
    crc = bsf_crc32c(0u, body, n);
    body[n] = (uint8_t)crc;
    body[n + 1u] = (uint8_t)(crc >> 8);
    body[n + 2u] = (uint8_t)(crc >> 16);
    body[n + 3u] = (uint8_t)(crc >> 24);
    FUZZ_CHECK(bsf_cobs_encode(body, n + 4u, wire, sizeof wire - 1u, &wlen) == BSF_OK);
    wire[wlen++] = 0u;
    while (off < wlen) {
        size_t used = 0u;
        const int got = bsf_decoder_feed(&dec, wire + off, wlen - off, &used, &frame);
        FUZZ_CHECK(used > 0u);
        off += used;
        if (got == (int)BSF_FRAME_TYPE_MAP) {
            int r;
            FUZZ_CHECK(frame.payload_len == n && memcmp(frame.payload, p, n) == 0);
            memcpy(&before, &rx, sizeof rx);
            snapshot_stale();
            r = bsf_map_rx_apply(&rx, frame.payload, frame.payload_len);
            /* the decoder checked the payload; only a change of step is
             * left for the receiver to refuse */
            FUZZ_CHECK(r >= 0 || r == BSF_ERR_FORMAT);
            check_rx(r);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t pos = 1u;
    uint8_t mode;
    if (size < 1u) {
        return 0;
    }
    if (!made) {
        make_prelude();
    }
    mode = data[0];
    bsf_map_rx_init(&rx);
    bsf_decoder_init(&dec);
    if (mode & 1u) {
        size_t k;
        for (k = 0; k < n_prelude; ++k) {
            size_t off = 0u;
            while (off < prelude_len[k]) {
                size_t used = 0u;
                const int got =
                    bsf_decoder_feed(&dec, prelude[k] + off, prelude_len[k] - off, &used, &frame);
                off += used;
                if (got == (int)BSF_FRAME_TYPE_MAP) {
                    apply_direct(frame.payload, frame.payload_len);
                }
            }
        }
        FUZZ_CHECK(rx.stats.records_skipped == 0u && rx.stats.frames == n_prelude);
        {
            uint32_t id;
            for (id = 0; id < bsf_map_rx_id_limit(&rx); ++id) {
                const int state = bsf_map_rx_feature_state(&rx, id);
                FUZZ_CHECK(state == BSF_MAP_RX_CONFIRMED || state == BSF_MAP_RX_NONE);
            }
        }
    }
    while (pos + 2u <= size) {
        size_t n = (size_t)data[pos] | ((size_t)data[pos + 1u] << 8);
        pos += 2u;
        if (n > size - pos) {
            n = size - pos;
        }
        if (mode & 2u) {
            apply_via_decoder(data + pos, n);
        } else {
            apply_direct(data + pos, n);
        }
        pos += n;
    }
    return 0;
}
