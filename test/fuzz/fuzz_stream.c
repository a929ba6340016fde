/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: the stream decoder fed arbitrary bytes in arbitrary
 * chunks. Every delivered frame must be within the caps and finite, and
 * re-encoding it must give a frame that decodes to the same content.
 *
 * Input: byte 0 = mode. Bits 0-5 pick the chunk size the bytes are fed in.
 * Bit 7 set: the rest is a frame PAYLOAD; the harness appends its CRC-32C,
 * COBS-encodes it and adds the delimiter, so mutations reach the field
 * parser instead of dying at the CRC check. Bit 7 clear: the rest is fed as
 * raw wire bytes (framing, COBS and CRC errors, resynchronisation).
 */
#include <string.h>

#include "fuzz_check.h"

static bsf_decoder_t dec;
static bsf_decoder_t dec2;
static bsf_frame_t frame;
static bsf_frame_t again;
static uint8_t wire[BSF_FRAME_MAX_SIZE];
static uint8_t body[BSF_FRAME_BODY_MAX_SIZE + 4u];
static uint8_t framed[BSF_COBS_MAX_SIZE(BSF_FRAME_BODY_MAX_SIZE + 4u) + 1u];

/* A delivered metadata frame is within its documented ranges and
 * re-encodes to a frame that decodes to the same record. */
static void check_metadata(const bsf_frame_t *fr)
{
    const bsf_metadata_t *m = &fr->metadata;
    size_t len = 0u;
    size_t used = 0u;
    FUZZ_CHECK(fr->version == 2u);
    FUZZ_CHECK(fuzz_finite(m->target_rms) && m->target_rms >= 0.0f);
    FUZZ_CHECK(fuzz_finite(m->angle_min) && fuzz_finite(m->angle_increment));
    FUZZ_CHECK(fuzz_finite(m->range_max) && m->range_min >= 0.0f && m->range_max >= m->range_min);
    FUZZ_CHECK(m->max_points >= 1u && m->max_points <= 65535u && m->n_beams <= 65535u);
    FUZZ_CHECK(m->source_len <= BSF_METADATA_SOURCE_MAX && m->source[m->source_len] == '\0');
    FUZZ_CHECK(bsf_metadata_encode(m, wire, sizeof wire, &len) == BSF_OK);
    FUZZ_CHECK(len <= BSF_METADATA_MAX_SIZE && len <= BSF_FRAME_MAX_SIZE);
    bsf_decoder_init(&dec2);
    FUZZ_CHECK(bsf_decoder_feed(&dec2, wire, len, &used, &again) == BSF_FRAME_TYPE_METADATA);
    FUZZ_CHECK(memcmp(&again.metadata.target_rms, &m->target_rms, sizeof(float)) == 0);
    FUZZ_CHECK(again.metadata.time_origin_us == m->time_origin_us);
    FUZZ_CHECK(again.metadata.source_len == m->source_len &&
               memcmp(again.metadata.source, m->source, m->source_len) == 0);
}

static void check_frame(const bsf_frame_t *fr)
{
    FUZZ_CHECK(fr->version == 1u || fr->version == BSF_FORMAT_VERSION);
    FUZZ_CHECK(fr->type == BSF_FRAME_TYPE_FEATURES);
    FUZZ_CHECK(fr->has_pose <= 1u);
    FUZZ_CHECK(fuzz_finite(fr->pose_x) && fabsf(fr->pose_x) <= BSF_POSE_XY_MAX);
    FUZZ_CHECK(fuzz_finite(fr->pose_y) && fabsf(fr->pose_y) <= BSF_POSE_XY_MAX);
    FUZZ_CHECK(fuzz_finite(fr->pose_theta) && fabsf(fr->pose_theta) <= 3.1416f);
    FUZZ_CHECK(fr->quant_step >= BSF_QUANT_STEP_MIN * 0.999f &&
               fr->quant_step <= BSF_QUANT_STEP_MAX * 1.001f);
    fuzz_check_result(&fr->result, 0);
}

static int same_pose(float a, float b)
{
    if (fabsf(a) <= 4096.0f) {
        return a == b;
    }
    return fabsf(a - b) <= fabsf(a) * 2.5e-7f;
}

/* A control point is code * step in float. Up to 2^21 steps, float rounding
 * (at most 2^-24 relative, twice) stays below a quarter step each way, so
 * re-quantising gives the same code; the format allows 2^23 - 1 steps, where
 * it may land one step off (reported as a precision limit). */
static int same_coord(float a, float b, float step)
{
    if (fabsf(a) <= 2097152.0f * step) {
        return a == b;
    }
    return fabsf(a - b) <= step + fabsf(a) * 1.2e-7f;
}

/* Same content: every field a frame carries, compared exactly. */
static void check_equal(const bsf_frame_t *a, const bsf_frame_t *b)
{
    const bsf_result_t *ra = &a->result;
    const bsf_result_t *rb = &b->result;
    size_t k;
    FUZZ_CHECK(a->seq == b->seq);
    FUZZ_CHECK(a->timestamp_ms == b->timestamp_ms);
    FUZZ_CHECK(a->has_pose == b->has_pose);
    /* Beyond 8192 m a float's step exceeds the 1 mm wire unit, so decode and
     * re-encode may move the pose by one float step there (reported). */
    if (!(same_pose(a->pose_x, b->pose_x) && same_pose(a->pose_y, b->pose_y))) {
        fprintf(stderr, "pose %.9g %.9g -> %.9g %.9g\n", (double)a->pose_x, (double)a->pose_y,
                (double)b->pose_x, (double)b->pose_y);
    }
    FUZZ_CHECK(same_pose(a->pose_x, b->pose_x) && same_pose(a->pose_y, b->pose_y));
    FUZZ_CHECK(a->pose_theta == b->pose_theta);
    FUZZ_CHECK(a->quant_step == b->quant_step);
    /* The decoder refuses a time_us that stats.time_ns cannot hold, so every
     * delivered frame's time and stats re-encode exactly. */
    FUZZ_CHECK(a->time_us == b->time_us);
    {
        /* The beam count travels only with a wrapping feature or the scan's
         * geometry; the stream decoder may have filled it in from a metadata
         * frame. */
        bsf_stats_t sa = ra->stats;
        int wraps = 0;
        for (k = 0; k < ra->n_features; ++k) {
            wraps |= ra->features[k].first_beam > ra->features[k].last_beam;
        }
        if (!wraps && !a->has_geometry) {
            sa.n_beams = 0u;
        }
        FUZZ_CHECK(a->has_geometry == b->has_geometry);
        FUZZ_CHECK(memcmp(&a->angle_min, &b->angle_min, sizeof(float)) == 0);
        FUZZ_CHECK(memcmp(&a->angle_increment, &b->angle_increment, sizeof(float)) == 0);
        FUZZ_CHECK(memcmp(&sa, &rb->stats, sizeof sa) == 0);
    }
    FUZZ_CHECK(ra->n_features == rb->n_features && ra->n_ctrl == rb->n_ctrl);
    for (k = 0; k < ra->n_features; ++k) {
        const bsf_feature_t *fa = &ra->features[k];
        const bsf_feature_t *fb = &rb->features[k];
        FUZZ_CHECK(fa->first_beam == fb->first_beam && fa->last_beam == fb->last_beam);
        FUZZ_CHECK(fa->n_points == fb->n_points && fa->kind == fb->kind);
        FUZZ_CHECK(fa->ctrl_first == fb->ctrl_first && fa->n_ctrl == fb->n_ctrl);
        FUZZ_CHECK(fa->e_curve == fb->e_curve);
    }
    for (k = 0; k < ra->n_ctrl; ++k) {
        FUZZ_CHECK(same_coord(ra->ctrl[k].x, rb->ctrl[k].x, a->quant_step));
        FUZZ_CHECK(same_coord(ra->ctrl[k].y, rb->ctrl[k].y, a->quant_step));
        FUZZ_CHECK(ra->ctrl_is_vertex[k] == rb->ctrl_is_vertex[k]);
    }
}

static void reencode(const bsf_frame_t *fr)
{
    bsf_frame_info_t info;
    size_t len = 0u;
    size_t used = 0u;
    bsf_status_t st;
    int got;
    bsf_frame_info_init(&info);
    info.seq = fr->seq;
    info.timestamp_ms = fr->timestamp_ms;
    info.has_pose = fr->has_pose;
    info.pose_x = fr->pose_x;
    info.pose_y = fr->pose_y;
    info.pose_theta = fr->pose_theta;
    info.quant_step = fr->quant_step;
    info.has_geometry = fr->has_geometry;
    info.angle_min = fr->angle_min;
    info.angle_increment = fr->angle_increment;
    st = bsf_frame_encode(&info, &fr->result, wire, sizeof wire, &len);
    if (st != BSF_OK) {
        fprintf(stderr, "re-encoding a delivered frame failed: %s\n", bsf_status_str(st));
    }
    FUZZ_CHECK(st == BSF_OK);
    FUZZ_CHECK(len >= 2u && len <= BSF_FRAME_MAX_SIZE && wire[len - 1u] == 0u);
    bsf_decoder_init(&dec2);
    got = bsf_decoder_feed(&dec2, wire, len, &used, &again);
    FUZZ_CHECK(got == (int)BSF_FRAME_TYPE_FEATURES && used == len);
    check_equal(fr, &again);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t pos = 0u;
    size_t chunk;
    if (size == 0u) {
        return 0;
    }
    /* The first byte picks the chunk size, so split frames are exercised. */
    chunk = (size_t)(data[0] & 0x3Fu) + 1u;
    if (data[0] & 0x80u) {
        size_t n = size - 1u;
        size_t enc = 0u;
        uint32_t crc;
        if (n > BSF_FRAME_BODY_MAX_SIZE - BSF_FRAME_CRC_SIZE) {
            n = BSF_FRAME_BODY_MAX_SIZE - BSF_FRAME_CRC_SIZE;
        }
        memcpy(body, data + 1, n);
        crc = bsf_crc32c(0u, body, n);
        body[n] = (uint8_t)crc;
        body[n + 1u] = (uint8_t)(crc >> 8);
        body[n + 2u] = (uint8_t)(crc >> 16);
        body[n + 3u] = (uint8_t)(crc >> 24);
        FUZZ_CHECK(bsf_cobs_encode(body, n + 4u, framed, sizeof framed - 1u, &enc) == BSF_OK);
        framed[enc] = 0u;
        data = framed;
        size = enc + 1u;
    } else {
        data++;
        size--;
    }
    bsf_decoder_init(&dec);
    while (pos < size) {
        const size_t n = (size - pos < chunk) ? size - pos : chunk;
        size_t used = 0u;
        const int got = bsf_decoder_feed(&dec, data + pos, n, &used, &frame);
        FUZZ_CHECK(got == 0 || got == (int)BSF_FRAME_TYPE_FEATURES ||
                   got == (int)BSF_FRAME_TYPE_METADATA);
        FUZZ_CHECK(got == 0 || got == (int)frame.type);
        FUZZ_CHECK(used <= n);
        FUZZ_CHECK(got != 0 || used == n);
        FUZZ_CHECK(used > 0u); /* progress on every call */
        pos += used;
        if (got == (int)BSF_FRAME_TYPE_METADATA) {
            check_metadata(&frame);
        } else if (got == (int)BSF_FRAME_TYPE_FEATURES) {
            check_frame(&frame);
            reencode(&frame);
        }
    }
    FUZZ_CHECK(dec.len <= sizeof dec.body);
    return 0;
}
