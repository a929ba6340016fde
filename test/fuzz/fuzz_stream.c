/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: the wire format through its public API
 * (bsf_decoder_feed, bsf_frame_decode, bsf_cobs_encode/decode,
 * bsf_frame_encode, bsf_frame_encode_sink).
 *
 * Input: byte 0 = mode. Bits 0-5 pick the chunk size bytes are fed in;
 * bits 6-7 pick what the rest is:
 *  0x00 raw wire bytes (framing, COBS and CRC errors), followed by a 0x00
 *       and an intact reference frame: the reference must come out intact
 *       (resynchronisation after garbage);
 *  0x80 a frame PAYLOAD: the harness appends its CRC-32C, COBS-encodes it
 *       and adds the delimiter, so mutations reach the field parser; the
 *       decoder, bsf_frame_decode and bsf_cobs_decode must agree;
 *  0x40 an oversize frame: the rest repeated past BSF_FRAME_BODY_MAX_SIZE
 *       (byte 1 adds up to 8 KiB more), then the reference frame: the long
 *       frame is counted as oversize and skipped, the reference delivered;
 *  0xC0 direct calls: byte 1 % 4 picks bsf_cobs_decode, bsf_frame_decode,
 *       the encoder on a valid reference result edited by the rest, or the
 *       metadata encoder on edited defaults (each edit = 1 byte picking a
 *       field + 4 value bytes): every refusal path, BSF_ERR_BUFFER on short
 *       buffers, a sink that aborts.
 * Properties on every decoder run: each delivered features frame is within
 * the caps and finite and re-encodes to the same content, each metadata
 * frame is within its ranges and re-encodes to the same record, the
 * counters add up (every
 * delimited frame counted exactly once; delivered bytes + skipped bytes +
 * delimiters + the unfinished tail = the bytes fed), and the decoder makes
 * progress on every call.
 */
#include <string.h>

#include "fuzz_check.h"

static bsf_decoder_t dec;
static bsf_decoder_t dec2;
static bsf_map_rx_t map_rx;
static bsf_frame_t frame;
static bsf_frame_t again;
static bsf_frame_t direct;
static bsf_frame_t reference;
static bsf_result_t base;
static bsf_result_t edited;
static bsf_frame_info_t base_info;
static uint8_t wire[BSF_FRAME_MAX_SIZE];
static uint8_t wire2[BSF_FRAME_MAX_SIZE];
static uint8_t ref_wire[BSF_FRAME_MAX_SIZE];
static size_t ref_len;
static uint8_t body[BSF_FRAME_BODY_MAX_SIZE + 4u];
static uint8_t cobs_out[2u * BSF_FRAME_BODY_MAX_SIZE + 16u];
/* the longest stream one input becomes: oversize body + 8 KiB, COBS, + reference */
#define STREAM_CAP                                                                                 \
    (BSF_COBS_MAX_SIZE(BSF_FRAME_BODY_MAX_SIZE + 8192u + 64u) + BSF_FRAME_MAX_SIZE + 16u)
static uint8_t stream[STREAM_CAP];
static uint8_t long_body[BSF_FRAME_BODY_MAX_SIZE + 8192u + 64u];

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
    FUZZ_CHECK(fuzz_finite(fr->pose.x) && fabsf(fr->pose.x) <= BSF_POSE_XY_MAX);
    FUZZ_CHECK(fuzz_finite(fr->pose.y) && fabsf(fr->pose.y) <= BSF_POSE_XY_MAX);
    FUZZ_CHECK(fuzz_finite(fr->pose.theta) && fabsf(fr->pose.theta) <= 3.1416f);
    FUZZ_CHECK(fr->quant_step >= BSF_QUANT_STEP_MIN * 0.999f &&
               fr->quant_step <= BSF_QUANT_STEP_MAX * 1.001f);
    fuzz_check_result(&fr->result, 0);
}

/* A map frame the decoder delivered: the receiver applies it (or refuses a
 * step that differs from the stream's) and its pool stays consistent: the
 * points its features hold and its free list add up to the pool. */
static void check_map(const bsf_frame_t *fr)
{
    size_t held = 0u;
    uint32_t id;
    int r;
    FUZZ_CHECK(fr->type == BSF_FRAME_TYPE_MAP && fr->payload != NULL && fr->payload_len >= 3u);
    r = bsf_map_rx_apply(&map_rx, fr->payload, fr->payload_len);
    FUZZ_CHECK(r >= 0 || r == BSF_ERR_FORMAT);
    FUZZ_CHECK(bsf_map_rx_id_limit(&map_rx) <= BSF_MAP_RX_MAX_FEATURES);
    for (id = 0; id < bsf_map_rx_id_limit(&map_rx); ++id) {
        const int n = bsf_map_rx_feature_q(&map_rx, id, NULL, NULL, 0u);
        FUZZ_CHECK(n >= 0);
        held += (size_t)n;
    }
    FUZZ_CHECK(held + map_rx.n_free_ctrl == BSF_MAP_RX_MAX_CTRL);
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
    if (!(same_pose(a->pose.x, b->pose.x) && same_pose(a->pose.y, b->pose.y))) {
        fprintf(stderr, "pose %.9g %.9g -> %.9g %.9g\n", (double)a->pose.x, (double)a->pose.y,
                (double)b->pose.x, (double)b->pose.y);
    }
    FUZZ_CHECK(same_pose(a->pose.x, b->pose.x) && same_pose(a->pose.y, b->pose.y));
    FUZZ_CHECK(a->pose.theta == b->pose.theta);
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
    info.pose.x = fr->pose.x;
    info.pose.y = fr->pose.y;
    info.pose.theta = fr->pose.theta;
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

/* A valid result with a plain feature and one with a vertex: the base the
 * encoder edits start from, and the reference frame that must survive any
 * garbage before it. */
static void make_reference(void)
{
    static const float xy[7][2] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {2.0f, 0.0f},
                                   {3.0f, 0.0f}, {3.0f, 0.0f}, {3.0f, 1.0f}};
    size_t k, used = 0u;
    memset(&base, 0, sizeof base);
    base.n_features = 2u;
    base.n_ctrl = 7u;
    base.features[0].first_beam = 0u;
    base.features[0].last_beam = 10u;
    base.features[0].n_points = 11u;
    base.features[0].ctrl_first = 0u;
    base.features[0].n_ctrl = 3u;
    base.features[0].e_curve = 0.01f;
    base.features[1].first_beam = 12u;
    base.features[1].last_beam = 30u;
    base.features[1].n_points = 19u;
    base.features[1].ctrl_first = 3u;
    base.features[1].n_ctrl = 4u;
    base.features[1].kind = 1u;
    base.features[1].e_curve = 0.02f;
    for (k = 0; k < 7u; ++k) {
        base.ctrl[k].x = xy[k][0];
        base.ctrl[k].y = xy[k][1];
    }
    base.ctrl_is_vertex[4] = 1u;
    base.ctrl_is_vertex[5] = 1u;
    base.stats.n_valid = 40u;
    base.stats.n_in_features = 30u;
    base.stats.n_features = 2u;
    base.stats.n_ctrl = 7u;
    bsf_frame_info_init(&base_info);
    base_info.seq = 4242u;
    base_info.timestamp_ms = 123456u;
    base_info.has_pose = 1u;
    base_info.pose.x = 1.5f;
    base_info.pose.y = -2.25f;
    base_info.pose.theta = 0.5f;
    /* With its geometry the frame carries its beam count, so a metadata
     * frame in the garbage before it cannot change what it decodes to. */
    base.stats.n_beams = 40u;
    base_info.has_geometry = 1u;
    base_info.angle_min = -1.0f;
    base_info.angle_increment = 0.01f;
    FUZZ_CHECK(bsf_frame_encode(&base_info, &base, ref_wire, sizeof ref_wire, &ref_len) == BSF_OK);
    bsf_decoder_init(&dec2);
    FUZZ_CHECK(bsf_decoder_feed(&dec2, ref_wire, ref_len, &used, &reference) ==
               (int)BSF_FRAME_TYPE_FEATURES);
    FUZZ_CHECK(used == ref_len);
}

/* Feeds stream[0..n) in chunks and checks every delivered frame and the
 * counters. Returns the number of frames delivered; *last_delivered_at is
 * the stream offset just past the last delivered frame (0 if none). */
static uint32_t feed_and_check(size_t n, size_t chunk, size_t *last_delivered_at)
{
    size_t pos = 0u;
    size_t i;
    uint32_t delivered = 0u;
    uint32_t metadata = 0u;
    uint32_t delimited = 0u;
    size_t delivered_bytes = 0u;
    size_t nonzero = 0u;
    size_t tail = 0u;
    const bsf_decoder_stats_t *st = &dec.stats;
    *last_delivered_at = 0u;
    bsf_decoder_init(&dec);
    while (pos < n) {
        const size_t len = (n - pos < chunk) ? n - pos : chunk;
        size_t used = 0u;
        const int got = bsf_decoder_feed(&dec, stream + pos, len, &used, &frame);
        FUZZ_CHECK(got == 0 || got == (int)BSF_FRAME_TYPE_FEATURES ||
                   got == (int)BSF_FRAME_TYPE_METADATA || got == (int)BSF_FRAME_TYPE_MAP);
        FUZZ_CHECK(got == 0 || got == (int)frame.type);
        FUZZ_CHECK(used <= len);
        FUZZ_CHECK(got != 0 || used == len);
        FUZZ_CHECK(used > 0u); /* progress on every call */
        pos += used;
        if (got != 0) {
            size_t start = pos - 1u; /* the delimiter that ended the frame */
            FUZZ_CHECK(stream[pos - 1u] == 0u);
            while (start > 0u && stream[start - 1u] != 0u) {
                --start;
            }
            delivered_bytes += pos - 1u - start;
            ++delivered;
            *last_delivered_at = pos;
            if (got == (int)BSF_FRAME_TYPE_METADATA) {
                ++metadata;
                check_metadata(&frame);
            } else if (got == (int)BSF_FRAME_TYPE_MAP) {
                check_map(&frame);
            } else {
                check_frame(&frame);
                reencode(&frame);
            }
        }
    }
    /* Counters: every non-empty delimited frame is counted exactly once, and
     * every non-zero byte is in a delivered frame, a skipped one, or the
     * unfinished tail. */
    for (i = 0; i < n; ++i) {
        if (stream[i] == 0u) {
            delimited += tail > 0u;
            tail = 0u;
        } else {
            ++nonzero;
            ++tail;
        }
    }
    FUZZ_CHECK(st->frames_ok == delivered); /* metadata frames included */
    FUZZ_CHECK(st->metadata == metadata);
    FUZZ_CHECK(st->frames_ok + st->bad_crc + st->malformed + st->unsupported_version +
                   st->unknown_type + st->oversize ==
               delimited);
    FUZZ_CHECK(delivered_bytes + st->bytes_skipped + tail == nonzero);
    FUZZ_CHECK(dec.len <= sizeof dec.body);
    return delivered;
}

/* Appends a 0x00 and the reference frame; after feeding, the last frame
 * delivered must be the reference, intact. */
static void feed_with_reference(size_t n, size_t chunk)
{
    size_t end = 0u;
    stream[n++] = 0u;
    memcpy(stream + n, ref_wire, ref_len);
    n += ref_len;
    FUZZ_CHECK(feed_and_check(n, chunk, &end) >= 1u);
    FUZZ_CHECK(end == n && frame.type == BSF_FRAME_TYPE_FEATURES);
    check_equal(&reference, &frame);
}

static uint32_t take4(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static float as_float(uint32_t bits)
{
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static size_t sink_limit;
static size_t sink_got;

static int sink(void *ctx, const uint8_t *data, size_t len)
{
    (void)ctx;
    FUZZ_CHECK(len >= 1u && len <= 256u);
    if (sink_got + len > sink_limit) {
        return 1;
    }
    memcpy(wire2 + sink_got, data, len);
    sink_got += len;
    return 0;
}

/* Edits of the base result, then the encoder: a documented status, and a
 * frame that decodes back to the same values within the wire's steps. */
static void fuzz_encoder(const uint8_t *p, size_t n, uint8_t sel)
{
    bsf_frame_info_t info = base_info;
    bsf_encoder_t work;
    size_t len = 0u, used = 0u, written = 0u;
    bsf_status_t st;
    size_t k;
    edited = base;
    for (; n >= 5u; p += 5, n -= 5u) {
        const uint32_t v = take4(p + 1);
        const size_t f = (size_t)(p[0] >> 4) % BSF_MAX_SEGMENTS;
        const size_t c = (size_t)(v >> 16) % BSF_MAX_CTRL_POINTS;
        switch (p[0] & 0x0Fu) {
        case 0: info.pose.x = as_float(v); break;
        case 1: info.pose.y = as_float(v); break;
        case 2: info.pose.theta = as_float(v); break;
        case 3: info.quant_step = as_float(v); break;
        case 4: edited.ctrl[p[0] >> 4].x = as_float(v); break;
        case 5: edited.ctrl[p[0] >> 4].y = as_float(v); break;
        case 6: edited.features[f].e_curve = as_float(v); break;
        case 7: edited.features[f].n_ctrl = (uint8_t)v; break;
        case 8: edited.features[f].first_beam = (uint16_t)v; break;
        case 9: edited.features[f].last_beam = (uint16_t)v; break;
        case 10: edited.features[f].n_points = (uint16_t)v; break;
        case 11: edited.features[f].kind = (uint8_t)v; break;
        case 12: edited.ctrl_is_vertex[c] = (uint8_t)v; break;
        case 13: edited.n_features = (uint16_t)v; break;
        case 14: edited.n_ctrl = (uint16_t)v; break;
        default:
            info.has_pose = (uint8_t)(v & 1u);
            info.timestamp_ms = (uint64_t)v << (p[0] >> 4);
            edited.stats.n_valid = v >> 20;
            edited.stats.time_ns = v;
            break;
        }
    }
    st = bsf_frame_encode(&info, &edited, wire, sizeof wire, &len);
    fuzz_check_status(st);
    FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_ARG || st == BSF_ERR_CAPACITY);
    if (st != BSF_OK) {
        /* the sink variant refuses the same input before writing anything */
        sink_limit = sizeof wire2;
        sink_got = 0u;
        FUZZ_CHECK(bsf_frame_encode_sink(&work, &info, &edited, sink, NULL, &written) == st);
        FUZZ_CHECK(sink_got == 0u);
        return;
    }
    FUZZ_CHECK(len >= 2u && len <= BSF_FRAME_MAX_SIZE && wire[len - 1u] == 0u);
    /* a buffer one byte short is refused; so is a sink that stops early */
    FUZZ_CHECK(bsf_frame_encode(&info, &edited, wire2, len - 1u, &used) == BSF_ERR_BUFFER);
    sink_limit = (size_t)sel * 8u < len ? (size_t)sel * 8u : sizeof wire2;
    sink_got = 0u;
    st = bsf_frame_encode_sink(&work, &info, &edited, sink, NULL, &written);
    if (sink_limit < len) {
        FUZZ_CHECK(st == BSF_ERR_BUFFER);
    } else {
        FUZZ_CHECK(st == BSF_OK && written == len && sink_got == len);
        FUZZ_CHECK(memcmp(wire, wire2, len) == 0);
    }
    bsf_decoder_init(&dec2);
    FUZZ_CHECK(bsf_decoder_feed(&dec2, wire, len, &used, &again) == (int)BSF_FRAME_TYPE_FEATURES);
    FUZZ_CHECK(used == len);
    check_frame(&again);
    FUZZ_CHECK(again.seq == info.seq && again.timestamp_ms == info.timestamp_ms);
    FUZZ_CHECK(again.has_pose == info.has_pose);
    FUZZ_CHECK(again.result.n_features == edited.n_features);
    /* Each feature's slice of the pool travels (pool entries outside every
     * slice are not part of the result and are not sent). */
    for (k = 0; k < edited.n_features; ++k) {
        const bsf_feature_t *fe = &edited.features[k];
        const bsf_feature_t *fa = &again.result.features[k];
        size_t j;
        FUZZ_CHECK(fa->first_beam == fe->first_beam && fa->last_beam == fe->last_beam);
        FUZZ_CHECK(fa->n_ctrl == fe->n_ctrl && fa->n_points == fe->n_points);
        FUZZ_CHECK(fa->kind == fe->kind);
        FUZZ_CHECK(fabsf(fa->e_curve - fe->e_curve) <= 0.00025f + fe->e_curve * 2.4e-7f);
        for (j = 0; j < fe->n_ctrl; ++j) {
            const bsf_point_t *pe = &edited.ctrl[fe->ctrl_first + j];
            const bsf_point_t *pa = &again.result.ctrl[fa->ctrl_first + j];
            const float tol =
                0.5001f * again.quant_step + 2.4e-7f * fabsf(pe->x) + 2.4e-7f * fabsf(pe->y);
            FUZZ_CHECK(fabsf(pa->x - pe->x) <= tol && fabsf(pa->y - pe->y) <= tol);
            /* any non-zero flag marks a vertex; it decodes as 1 */
            FUZZ_CHECK(again.result.ctrl_is_vertex[fa->ctrl_first + j] ==
                       (edited.ctrl_is_vertex[fe->ctrl_first + j] != 0u));
        }
    }
}

/* Edits of a metadata record (each edit: 1 byte picking a field, 4 value
 * bytes), then bsf_metadata_encode and its sink variant: a documented
 * status, the same from both, BSF_ERR_BUFFER one byte short, and an
 * accepted record decoding back to the same values. */
static void fuzz_metadata_encoder(const uint8_t *p, size_t n, uint8_t sel)
{
    static bsf_metadata_t m;
    bsf_encoder_t work;
    size_t len = 0u, used = 0u, written = 0u;
    bsf_status_t st;
    bsf_metadata_init(&m);
    for (; n >= 5u; p += 5, n -= 5u) {
        const uint32_t v = take4(p + 1);
        switch (p[0] % 16u) {
        case 0: m.method = (uint8_t)v; break;
        case 1: m.target_rms = as_float(v); break;
        case 2: m.quant_step = as_float(v); break;
        case 3: m.max_points = v; break;
        case 4: m.max_segments = v >> (p[0] >> 4); break;
        case 5: m.n_beams = v >> (p[0] >> 4); break;
        case 6: m.angle_min = as_float(v); break;
        case 7: m.angle_increment = as_float(v); break;
        case 8: m.range_min = as_float(v); break;
        case 9: m.range_max = as_float(v); break;
        case 10: m.has_time_origin = (uint8_t)(v & 1u); break;
        case 11: m.time_origin_us = (int64_t)(int32_t)v * (int64_t)(1u << (p[0] >> 4)); break;
        case 12:
            /* append 4 source bytes */
            if (m.source_len + 4u <= BSF_METADATA_SOURCE_MAX) {
                memcpy(m.source + m.source_len, p + 1, 4u);
                m.source_len = (uint8_t)(m.source_len + 4u);
            }
            break;
        case 13: m.source_len = (uint8_t)v; break;
        case 14: m.max_ctrl_points = v >> (p[0] >> 4); break;
        default: m.lib_version_minor = (uint16_t)v; break;
        }
    }
    st = bsf_metadata_encode(&m, wire, sizeof wire, &len);
    fuzz_check_status(st);
    FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_ARG);
    sink_limit = sizeof wire2;
    sink_got = 0u;
    if (st != BSF_OK) {
        FUZZ_CHECK(bsf_metadata_encode_sink(&work, &m, sink, NULL, &written) == st);
        FUZZ_CHECK(sink_got == 0u);
        return;
    }
    FUZZ_CHECK(len >= 2u && len <= BSF_METADATA_MAX_SIZE && wire[len - 1u] == 0u);
    FUZZ_CHECK(bsf_metadata_encode(&m, wire2, len - 1u, &used) == BSF_ERR_BUFFER);
    sink_limit = (size_t)sel * 2u < len ? (size_t)sel * 2u : sizeof wire2;
    sink_got = 0u;
    st = bsf_metadata_encode_sink(&work, &m, sink, NULL, &written);
    if (sink_limit < len) {
        FUZZ_CHECK(st == BSF_ERR_BUFFER);
    } else {
        FUZZ_CHECK(st == BSF_OK && written == len && memcmp(wire, wire2, len) == 0);
    }
    bsf_decoder_init(&dec2);
    FUZZ_CHECK(bsf_decoder_feed(&dec2, wire, len, &used, &again) == (int)BSF_FRAME_TYPE_METADATA);
    FUZZ_CHECK(used == len);
    check_metadata(&again);
    FUZZ_CHECK(again.metadata.method == m.method && again.metadata.n_beams == m.n_beams);
    FUZZ_CHECK(memcmp(&again.metadata.angle_min, &m.angle_min, sizeof(float)) == 0);
    FUZZ_CHECK(memcmp(&again.metadata.range_max, &m.range_max, sizeof(float)) == 0);
    FUZZ_CHECK(again.metadata.source_len == m.source_len &&
               memcmp(again.metadata.source, m.source, m.source_len) == 0);
}

/* bsf_cobs_decode on arbitrary bytes with a cap from the input. */
static void fuzz_cobs(const uint8_t *p, size_t n, uint8_t sel)
{
    const size_t cap = (sel & 1u) ? sizeof cobs_out : (size_t)sel * 4u;
    size_t out_len = 0u, enc_len = 0u, back_len = 0u;
    size_t k;
    int has_zero = 0;
    const bsf_status_t st = bsf_cobs_decode(p, n, cobs_out, cap, &out_len);
    fuzz_check_status(st);
    FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_FORMAT || st == BSF_ERR_BUFFER);
    for (k = 0; k < n; ++k) {
        has_zero |= p[k] == 0u;
    }
    if (has_zero) {
        FUZZ_CHECK(st != BSF_OK); /* FORMAT, or BUFFER when the cap is met first */
    }
    if (st != BSF_OK) {
        return;
    }
    FUZZ_CHECK(out_len <= cap && (n == 0u || out_len <= n - 1u));
    /* the canonical encoding of what came out decodes to the same bytes */
    FUZZ_CHECK(bsf_cobs_encode(cobs_out, out_len, wire, sizeof wire, &enc_len) == BSF_OK);
    FUZZ_CHECK(enc_len <= BSF_COBS_MAX_SIZE(out_len));
    for (k = 0; k < enc_len; ++k) {
        FUZZ_CHECK(wire[k] != 0u);
    }
    FUZZ_CHECK(bsf_cobs_decode(wire, enc_len, body, sizeof body, &back_len) == BSF_OK);
    FUZZ_CHECK(back_len == out_len && memcmp(body, cobs_out, out_len) == 0);
}

/* bsf_frame_decode on an arbitrary body (sel bit 0: with its CRC fixed). */
static void fuzz_frame_decode(const uint8_t *p, size_t n, uint8_t sel)
{
    bsf_status_t st;
    if (n > BSF_FRAME_BODY_MAX_SIZE - BSF_FRAME_CRC_SIZE) {
        n = BSF_FRAME_BODY_MAX_SIZE - BSF_FRAME_CRC_SIZE;
    }
    memcpy(body, p, n);
    if (sel & 1u) {
        const uint32_t crc = bsf_crc32c(0u, body, n);
        body[n++] = (uint8_t)crc;
        body[n++] = (uint8_t)(crc >> 8);
        body[n++] = (uint8_t)(crc >> 16);
        body[n++] = (uint8_t)(crc >> 24);
    }
    memset(&direct, 0x5A, sizeof direct);
    memset(&again, 0x5A, sizeof again);
    st = bsf_frame_decode(body, n, &direct);
    fuzz_check_status(st);
    FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_CRC || st == BSF_ERR_VERSION || st == BSF_ERR_FORMAT ||
               st == BSF_ERR_CAPACITY);
    if (n < 5u) {
        FUZZ_CHECK(st == BSF_ERR_CRC);
    }
    if (st != BSF_OK) {
        /* out is written only when the whole frame is valid */
        FUZZ_CHECK(memcmp(&direct, &again, sizeof direct) == 0);
        return;
    }
    if (direct.type == BSF_FRAME_TYPE_METADATA) {
        check_metadata(&direct);
    } else if (direct.type == BSF_FRAME_TYPE_MAP) {
        check_map(&direct);
    } else {
        check_frame(&direct);
        reencode(&direct);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t chunk;
    size_t n;
    size_t end;
    uint8_t mode;
    if (ref_len == 0u) {
        make_reference();
    }
    if (size == 0u) {
        return 0;
    }
    bsf_map_rx_init(&map_rx);
    chunk = (size_t)(data[0] & 0x3Fu) + 1u;
    mode = (uint8_t)(data[0] & 0xC0u);
    data++;
    size--;
    if (mode == 0x00u) {
        /* garbage, then the reference frame */
        n = size < STREAM_CAP - BSF_FRAME_MAX_SIZE - 2u ? size
                                                        : STREAM_CAP - BSF_FRAME_MAX_SIZE - 2u;
        memcpy(stream, data, n);
        feed_with_reference(n, chunk);
    } else if (mode == 0x80u) {
        /* a payload with a valid CRC: decoder, bsf_frame_decode and
         * bsf_cobs_decode agree */
        size_t enc = 0u, back = 0u;
        uint32_t crc;
        bsf_status_t st;
        uint32_t got;
        n = size;
        if (n > BSF_FRAME_BODY_MAX_SIZE - BSF_FRAME_CRC_SIZE) {
            n = BSF_FRAME_BODY_MAX_SIZE - BSF_FRAME_CRC_SIZE;
        }
        memcpy(body, data, n);
        crc = bsf_crc32c(0u, body, n);
        body[n] = (uint8_t)crc;
        body[n + 1u] = (uint8_t)(crc >> 8);
        body[n + 2u] = (uint8_t)(crc >> 16);
        body[n + 3u] = (uint8_t)(crc >> 24);
        n += 4u;
        FUZZ_CHECK(bsf_cobs_encode(body, n, stream, sizeof stream - 1u, &enc) == BSF_OK);
        FUZZ_CHECK(bsf_cobs_decode(stream, enc, cobs_out, sizeof cobs_out, &back) == BSF_OK);
        FUZZ_CHECK(back == n && memcmp(cobs_out, body, n) == 0);
        stream[enc++] = 0u;
        got = feed_and_check(enc, chunk, &end);
        st = bsf_frame_decode(body, n, &direct);
        FUZZ_CHECK((st == BSF_OK) == (got == 1u));
        if (got == 1u) {
            /* one frame from a fresh decoder: nothing to fill in from
             * earlier metadata, so both decode it the same */
            FUZZ_CHECK(direct.type == frame.type);
            if (frame.type == BSF_FRAME_TYPE_FEATURES) {
                check_equal(&frame, &direct);
            } else if (frame.type == BSF_FRAME_TYPE_MAP) {
                FUZZ_CHECK(direct.seq == frame.seq && direct.payload_len == frame.payload_len);
            } else {
                FUZZ_CHECK(direct.metadata.source_len == frame.metadata.source_len);
                FUZZ_CHECK(direct.metadata.time_origin_us == frame.metadata.time_origin_us);
            }
        }
    } else if (mode == 0x40u) {
        /* an oversize frame, then the reference frame */
        const size_t extra = size > 0u ? (size_t)data[0] * 32u : 0u;
        const size_t want = BSF_FRAME_BODY_MAX_SIZE + 1u + extra;
        size_t enc = 0u;
        size_t k;
        for (k = 0; k < want; ++k) {
            long_body[k] = size > 1u ? data[1u + k % (size - 1u)] : (uint8_t)k;
        }
        FUZZ_CHECK(bsf_cobs_encode(long_body, want, stream, sizeof stream, &enc) == BSF_OK);
        feed_with_reference(enc, chunk * 64u);
        FUZZ_CHECK(dec.stats.oversize == 1u);
    } else if (size >= 1u) {
        const uint8_t sel = data[0];
        switch (sel % 4u) {
        case 0: fuzz_cobs(data + 1, size - 1u, (uint8_t)(sel / 4u)); break;
        case 1: fuzz_frame_decode(data + 1, size - 1u, (uint8_t)(sel / 4u)); break;
        case 2: fuzz_encoder(data + 1, size - 1u, (uint8_t)(sel / 4u)); break;
        default: fuzz_metadata_encoder(data + 1, size - 1u, (uint8_t)(sel / 4u)); break;
        }
    }
    return 0;
}
