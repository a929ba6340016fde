/* SPDX-License-Identifier: MIT */
/* Wire format: CRC, COBS, golden frames of docs/FORMAT.md, round trips,
 * encoder validation and the stream decoder's handling of damaged input. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bsf/bsf.h"
#include "stream_fixtures.h"
#include "unity.h"

#ifdef __arm__
#define N_ROUND_TRIPS 150u
#else
#define N_ROUND_TRIPS 1000u
#endif

static bsf_result_t res;
static bsf_frame_t frame;
static bsf_decoder_t dec;
static uint8_t buf[BSF_FRAME_MAX_SIZE + 16u];
static uint8_t body[BSF_FRAME_BODY_MAX_SIZE + 16u];
static uint8_t scratch[BSF_FRAME_MAX_SIZE + 16u];

/* docs/FORMAT.md, examples 1 to 4 (byte for byte). */
static const uint8_t golden_minimal[] = {
    0x04, 0x21, 0x20, 0x10, 0x01, 0x05, 0x21, 0x54, 0x82, 0xa1, 0x0f, 0x63, 0x0d,
    0xf4, 0xa4, 0x39, 0x0a, 0x43, 0x91, 0x0a, 0x80, 0xa6, 0x38, 0x80, 0x6c, 0x00,
};
static const uint8_t golden_typical[] = {
    0x05, 0x21, 0x8b, 0xa5, 0xab, 0x56, 0xe1, 0x4a, 0x60, 0xc6, 0xaf, 0x1a, 0x88, 0x84, 0xf0, 0x0e,
    0xc1, 0x47, 0x38, 0x88, 0x51, 0x5a, 0xe5, 0x31, 0xa7, 0x97, 0x94, 0x1b, 0xb2, 0xe5, 0x28, 0x83,
    0xea, 0x3c, 0xa8, 0x22, 0x76, 0x84, 0x83, 0x3c, 0x08, 0x08, 0xe6, 0x53, 0x7b, 0x37, 0x6b, 0xb2,
    0x96, 0xc0, 0x6b, 0x49, 0x20, 0x95, 0xa6, 0x46, 0xeb, 0x08, 0x2e, 0x0a, 0xd8, 0x16, 0x10, 0xa4,
    0x33, 0xfa, 0x93, 0xa0, 0xe9, 0xf9, 0x8b, 0xcb, 0x08, 0x44, 0xd8, 0x4c, 0x46, 0xea, 0xc6, 0x0f,
    0xef, 0x8c, 0x98, 0x49, 0x8a, 0xd3, 0x80, 0xa6, 0x98, 0x2f, 0x6c, 0x00,
};
static const uint8_t golden_wrap_cut[] = {
    0x04, 0x21, 0x60, 0xf0, 0x24, 0x19, 0x21, 0x16, 0xc8, 0x32, 0x4c, 0x39, 0x26, 0x89,
    0xb6, 0xc0, 0xcc, 0x30, 0x78, 0xc5, 0xfe, 0x03, 0x4e, 0x7d, 0xdc, 0x6d, 0x80, 0xd3,
    0x37, 0xe3, 0xd0, 0x53, 0xf0, 0x09, 0x86, 0x40, 0x95, 0xec, 0x43, 0x1e, 0x00,
};
static const uint8_t golden_metadata[] = {
    0x18, 0x22, 0xba, 0x78, 0xeb, 0x85, 0x1e, 0x42, 0x29, 0xc9, 0x40, 0x48, 0x09, 0x04, 0x81,
    0xb4, 0xbf, 0xc9, 0x0f, 0xdb, 0x3c, 0x8e, 0xfa, 0x35, 0x01, 0x01, 0x01, 0x1e, 0x42, 0xa3,
    0xd1, 0xec, 0x80, 0x1e, 0x52, 0x41, 0x61, 0x9d, 0xbd, 0x41, 0x46, 0x96, 0xe7, 0x46, 0x56,
    0xc2, 0xe6, 0xc6, 0xf6, 0x72, 0xe6, 0x77, 0xa0, 0x4a, 0x01, 0x0e, 0x01, 0x00,
};
/* Example 1 as format version 1 wrote it: the decoder still reads it. */
static const uint8_t golden_minimal_v1[] = {
    0x04, 0x11, 0x40, 0x20, 0x01, 0x05, 0x42, 0xa9, 0x05, 0x42, 0x0e, 0xc6, 0x1b,
    0xe9, 0x48, 0x72, 0x14, 0x87, 0x22, 0x15, 0x42, 0xc9, 0xc6, 0x33, 0x00,
};

void setUp(void)
{
    bsf_decoder_init(&dec);
    memset(&frame, 0xA5, sizeof frame);
}

void tearDown(void)
{
}

/* Feeds data to dec in pieces of `chunk` bytes; returns frames delivered
 * (the last one is in `frame`). */
static unsigned feed_all(const uint8_t *data, size_t len, size_t chunk)
{
    unsigned frames = 0;
    size_t pos = 0;
    while (pos < len) {
        const size_t n = len - pos < chunk ? len - pos : chunk;
        size_t off = 0;
        while (off < n) {
            size_t used = 0;
            const int r = bsf_decoder_feed(&dec, data + pos + off, n - off, &used, &frame);
            TEST_ASSERT_TRUE(r == 0 || r == (int)BSF_FRAME_TYPE_FEATURES ||
                             r == (int)BSF_FRAME_TYPE_METADATA);
            TEST_ASSERT_TRUE(r == 0 || r == (int)frame.type);
            TEST_ASSERT_TRUE(used <= n - off);
            off += used;
            frames += r != 0 ? 1u : 0u;
        }
        pos += n;
    }
    return frames;
}

/* Payload (CRC stripped) of a golden frame. */
static size_t golden_payload(const uint8_t *golden, size_t len, uint8_t *out)
{
    size_t n = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_cobs_decode(golden, len - 1u, out, BSF_FRAME_BODY_MAX_SIZE, &n));
    return n - 4u;
}

/* Frames a hand-made payload: CRC, COBS, delimiter. Returns the wire length. */
static size_t reframe(const uint8_t *payload, size_t len, uint8_t *out)
{
    uint8_t tmp[BSF_FRAME_BODY_MAX_SIZE];
    const uint32_t crc = bsf_crc32c(0u, payload, len);
    size_t n = 0;
    unsigned i;
    memcpy(tmp, payload, len);
    for (i = 0; i < 4u; ++i) {
        tmp[len + i] = (uint8_t)(crc >> (8u * i));
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(tmp, len + 4u, out, BSF_FRAME_MAX_SIZE, &n));
    out[n] = 0u;
    return n + 1u;
}

static void assert_round_trip(const bsf_frame_info_t *info, const bsf_result_t *in,
                              const bsf_frame_t *out)
{
    const float step = out->quant_step;
    uint16_t i;
    TEST_ASSERT_FLOAT_WITHIN(1e-7f, info->quant_step, step);
    TEST_ASSERT_EQUAL_UINT32(info->seq, out->seq);
    TEST_ASSERT_TRUE(info->timestamp_ms == out->timestamp_ms);
    TEST_ASSERT_EQUAL_UINT8(info->has_pose, out->has_pose);
    if (info->has_pose) {
        float dtheta = out->pose.theta - info->pose.theta;
        dtheta -= 6.2831853f * floorf(dtheta / 6.2831853f + 0.5f);
        TEST_ASSERT_FLOAT_WITHIN(0.0005f + 1e-5f * fabsf(info->pose.x), info->pose.x, out->pose.x);
        TEST_ASSERT_FLOAT_WITHIN(0.0005f + 1e-5f * fabsf(info->pose.y), info->pose.y, out->pose.y);
        TEST_ASSERT_FLOAT_WITHIN(0.5f * 9.5874e-5f + 1e-6f, 0.0f, dtheta);
    }
    TEST_ASSERT_EQUAL_UINT32(in->stats.n_valid, out->result.stats.n_valid);
    TEST_ASSERT_UINT32_WITHIN(500u, in->stats.time_ns, out->result.stats.time_ns);
    TEST_ASSERT_EQUAL_UINT16(in->n_features, out->result.n_features);
    TEST_ASSERT_EQUAL_UINT16(in->n_ctrl, out->result.n_ctrl);
    TEST_ASSERT_EQUAL_UINT32(in->n_ctrl, out->result.stats.n_ctrl);
    TEST_ASSERT_EQUAL_UINT32(in->stats.n_in_features, out->result.stats.n_in_features);
    for (i = 0; i < in->n_features; ++i) {
        const bsf_feature_t *a = &in->features[i];
        const bsf_feature_t *b = &out->result.features[i];
        uint16_t k;
        TEST_ASSERT_EQUAL_UINT16(a->first_beam, b->first_beam);
        TEST_ASSERT_EQUAL_UINT16(a->last_beam, b->last_beam);
        TEST_ASSERT_EQUAL_UINT16(a->n_points, b->n_points);
        TEST_ASSERT_EQUAL_UINT16(a->ctrl_first, b->ctrl_first);
        TEST_ASSERT_EQUAL_UINT8(a->n_ctrl, b->n_ctrl);
        TEST_ASSERT_EQUAL_UINT8(a->kind, b->kind);
        TEST_ASSERT_FLOAT_WITHIN(0.00025f + 1e-6f, a->e_curve, b->e_curve);
        for (k = a->ctrl_first; k < a->ctrl_first + a->n_ctrl; ++k) {
            const float tol =
                0.5f * step * 1.0001f + 4e-7f * (fabsf(in->ctrl[k].x) + fabsf(in->ctrl[k].y));
            TEST_ASSERT_FLOAT_WITHIN(tol, in->ctrl[k].x, out->result.ctrl[k].x);
            TEST_ASSERT_FLOAT_WITHIN(tol, in->ctrl[k].y, out->result.ctrl[k].y);
            TEST_ASSERT_EQUAL_UINT8(in->ctrl_is_vertex[k] != 0u, out->result.ctrl_is_vertex[k]);
        }
    }
}

/* ---- CRC and COBS ---- */

static void test_crc32c_check_value_and_chaining(void)
{
    const uint8_t check[] = "123456789";
    const uint32_t whole = bsf_crc32c(0u, check, 9u);
    TEST_ASSERT_EQUAL_HEX32(0xE3069283u, whole);
    TEST_ASSERT_EQUAL_HEX32(whole, bsf_crc32c(bsf_crc32c(0u, check, 4u), check + 4, 5u));
    TEST_ASSERT_EQUAL_HEX32(0u, bsf_crc32c(0u, check, 0u));
}

static void test_cobs_encodes_reference_vectors_and_decodes_them_back(void)
{
    static const uint8_t in1[] = {0x00};
    static const uint8_t out1[] = {0x01, 0x01};
    static const uint8_t in2[] = {0x11, 0x22, 0x00, 0x33};
    static const uint8_t out2[] = {0x03, 0x11, 0x22, 0x02, 0x33};
    static const uint8_t in3[] = {0x11, 0x00, 0x00, 0x00};
    static const uint8_t out3[] = {0x02, 0x11, 0x01, 0x01, 0x01};
    uint8_t in4[255];
    size_t n = 0;
    size_t i;

    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(in1, 1, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(out1, buf, 2);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(in2, 4, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(out2, buf, 5);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(in3, 4, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(out3, buf, 5);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_decode(out2, 5, body, sizeof body, &n));
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(in2, body, 4);

    /* 254 non-zero bytes fill one 0xFF block; the 255th starts another. */
    for (i = 0; i < sizeof in4; ++i) {
        in4[i] = (uint8_t)(1u + i % 255u);
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(in4, 254, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(BSF_COBS_MAX_SIZE(254u), (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8(0xFF, buf[0]);
    TEST_ASSERT_EQUAL_HEX8(0x01, buf[255]);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_decode(buf, n, body, sizeof body, &n));
    TEST_ASSERT_EQUAL_UINT32(254u, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(in4, body, 254);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(in4, 255, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(257u, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8(0x02, buf[255]);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_decode(buf, n, body, sizeof body, &n));
    TEST_ASSERT_EQUAL_UINT32(255u, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(in4, body, 255);
}

static void test_cobs_refuses_zero_bytes_truncation_and_small_buffers(void)
{
    static const uint8_t has_zero[] = {0x03, 0x11, 0x00};
    static const uint8_t truncated[] = {0x05, 0x11, 0x22};
    static const uint8_t in[] = {0x11, 0x22, 0x33};
    size_t n = 0;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_FORMAT, bsf_cobs_decode(has_zero, 3, body, sizeof body, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_FORMAT, bsf_cobs_decode(truncated, 3, body, sizeof body, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER, bsf_cobs_encode(in, 3, buf, 3, &n));
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)n);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER,
                          bsf_cobs_decode(golden_minimal, sizeof golden_minimal - 1u, body, 3, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_cobs_encode(NULL, 3, buf, sizeof buf, &n));
}

/* ---- Golden frames ---- */

static void test_golden_minimal_frame_matches_format_md_and_decodes(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    fx_example_minimal(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_minimal, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_minimal, buf, sizeof golden_minimal);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_minimal, sizeof golden_minimal, 5u));
    assert_round_trip(&info, &res, &frame);
    TEST_ASSERT_EQUAL_UINT8(BSF_FORMAT_VERSION, frame.version);
    TEST_ASSERT_EQUAL_UINT8(BSF_FRAME_TYPE_FEATURES, frame.type);
    TEST_ASSERT_EQUAL_FLOAT(0.5f, frame.result.ctrl[0].y);
    TEST_ASSERT_EQUAL_FLOAT(0.8f, frame.result.ctrl[1].y);
}

static void test_golden_typical_frame_matches_format_md_and_decodes(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    fx_example_typical(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    printf("typical synthetic frame (6 features, 26 ctrl, 4 vertex copies): %u bytes\n",
           (unsigned)n);
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_typical, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_typical, buf, sizeof golden_typical);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_typical, sizeof golden_typical, 1u));
    assert_round_trip(&info, &res, &frame);
    TEST_ASSERT_EQUAL_UINT16(26u, frame.result.n_ctrl);
    TEST_ASSERT_EQUAL_UINT8(1u, frame.result.ctrl_is_vertex[5]);
    TEST_ASSERT_EQUAL_UINT8(1u, frame.result.ctrl_is_vertex[6]);
    TEST_ASSERT_EQUAL_UINT8(0u, frame.result.ctrl_is_vertex[7]);
    TEST_ASSERT_EQUAL_FLOAT(frame.result.ctrl[5].x, frame.result.ctrl[6].x);
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.frames_ok);
}

static void test_one_shot_decode_reads_golden_body(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    fx_example_typical(&info, &res);
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_cobs_decode(golden_typical, sizeof golden_typical - 1u, body, sizeof body, &n));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_decode(body, n, &frame));
    assert_round_trip(&info, &res, &frame);
    body[7] ^= 0x40u;
    memset(&frame, 0x5A, sizeof frame);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CRC, bsf_frame_decode(body, n, &frame));
    TEST_ASSERT_EQUAL_HEX8(0x5A, frame.version); /* untouched */
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CRC, bsf_frame_decode(body, 4u, &frame));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_decode(NULL, n, &frame));
}

/* ---- Encoder ---- */

static void test_size_query_equals_written_length(void)
{
    fx_rng_t rng;
    bsf_frame_info_t info;
    unsigned i;
    fx_rng_seed(&rng, 11u);
    for (i = 0; i < 20u; ++i) {
        size_t need = 0;
        size_t n = 0;
        fx_random_result(&rng, 10u, &info, &res);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, NULL, 0u, &need));
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
        TEST_ASSERT_EQUAL_UINT32((uint32_t)need, (uint32_t)n);
        TEST_ASSERT_EQUAL_HEX8(0x00, buf[n - 1u]);
        TEST_ASSERT_NULL(memchr(buf, 0, n - 1u));
    }
}

static void test_too_small_buffer_is_refused_without_writing(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    fx_example_typical(&info, &res);
    memset(buf, 0xEE, sizeof buf);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER,
                          bsf_frame_encode(&info, &res, buf, sizeof golden_typical - 1u, &n));
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_typical, (uint32_t)n);
    TEST_ASSERT_EACH_EQUAL_HEX8(0xEE, buf, sizeof golden_typical);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof golden_typical, &n));
}

typedef struct {
    size_t len;
    size_t calls;
    size_t largest;
    size_t fail_after; /* refuse the call with this index (0: never) */
} sink_log_t;

static int record_sink(void *ctx, const uint8_t *data, size_t len)
{
    sink_log_t *log = (sink_log_t *)ctx;
    ++log->calls;
    if (log->fail_after != 0u && log->calls >= log->fail_after) {
        return 1;
    }
    memcpy(scratch + log->len, data, len);
    log->len += len;
    if (len > log->largest) {
        log->largest = len;
    }
    return 0;
}

static void test_sink_gets_the_same_bytes_in_blocks_of_at_most_256(void)
{
    static bsf_encoder_t work;
    fx_rng_t rng;
    bsf_frame_info_t info;
    sink_log_t log;
    size_t n = 0;
    size_t written = 0;
    fx_rng_seed(&rng, 5u);
    fx_random_result(&rng, 40u, &info, &res);
    res.n_features = 0u;
    while (res.n_features < 20u) { /* make it long enough for several COBS blocks */
        fx_random_result(&rng, 40u, &info, &res);
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_TRUE(n > 600u);
    memset(&log, 0, sizeof log);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_frame_encode_sink(&work, &info, &res, record_sink, &log, &written));
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n, (uint32_t)written);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n, (uint32_t)log.len);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(buf, scratch, n);
    TEST_ASSERT_TRUE(log.largest <= 256u);
    TEST_ASSERT_TRUE(log.calls >= 3u);

    memset(&log, 0, sizeof log);
    log.fail_after = 2u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER,
                          bsf_frame_encode_sink(&work, &info, &res, record_sink, &log, &written));
    TEST_ASSERT_TRUE(written < n);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bsf_frame_encode_sink(&work, &info, &res, NULL, &log, &written));
}

static void test_random_results_round_trip_within_half_a_step(void)
{
    fx_rng_t rng;
    bsf_frame_info_t info;
    unsigned i;
    fx_rng_seed(&rng, 2024u);
    for (i = 0; i < N_ROUND_TRIPS; ++i) {
        size_t n = 0;
        fx_random_result(&rng, 10u, &info, &res);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
        TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 1u + fx_rng_range(&rng, 0u, 40u)));
        assert_round_trip(&info, &res, &frame);
    }
    TEST_ASSERT_EQUAL_UINT32(N_ROUND_TRIPS, dec.stats.frames_ok);
    TEST_ASSERT_EQUAL_UINT32(0u, dec.stats.bytes_skipped);
}

static void test_vertex_travels_once_and_is_expanded_on_decode(void)
{
    bsf_frame_info_t info;
    size_t with_vertex = 0;
    size_t n = 0;
    fx_example_minimal(&info, &res);
    /* b0, V, V, b1: the vertex's second copy costs no control point bytes. */
    res.ctrl[3] = res.ctrl[2];
    res.ctrl[2] = res.ctrl[1];
    res.ctrl_is_vertex[1] = 1u;
    res.ctrl_is_vertex[2] = 1u;
    res.features[0].n_ctrl = 4u;
    res.features[0].kind = BSF_FEATURE_AUXILIARY;
    res.n_ctrl = 4u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &with_vertex));
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, with_vertex, 64u));
    assert_round_trip(&info, &res, &frame);
    TEST_ASSERT_EQUAL_UINT8(4u, frame.result.features[0].n_ctrl);
    fx_example_minimal(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, NULL, 0u, &n));
    /* Only the vertex mask (1 byte) and a larger residual may be added. */
    TEST_ASSERT_TRUE(with_vertex <= n + 3u);
}

static void test_encoder_rejects_values_it_cannot_represent(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    unsigned c;
    for (c = 0; c < 19u; ++c) {
        bsf_status_t want = BSF_ERR_ARG;
        fx_example_typical(&info, &res);
        switch (c) {
        case 0: res.ctrl[2].x = NAN; break;
        case 1: res.ctrl[2].y = INFINITY; break;
        case 2: res.ctrl[0].x = 50000.0f; break; /* > 2^23 steps of 5 mm */
        case 3: info.quant_step = 0.0f; break;
        case 4: info.quant_step = 2.0f; break;
        case 5: info.quant_step = NAN; break;
        case 6: info.pose.theta = NAN; break;
        case 7: info.pose.x = 3e6f; break;
        case 8: res.ctrl_is_vertex[6] = 0u; break; /* vertex without its copy */
        case 9: res.ctrl[6].x += 0.01f; break;     /* copies differ */
        case 10: res.features[2].n_ctrl = 2u; break;
        case 11: res.features[5].n_ctrl = 5u; break; /* beyond result->n_ctrl */
        case 12: res.features[1].last_beam = 40u; break;
        case 13: res.features[1].n_points = 56u; break;
        case 14: res.features[1].kind = 2u; break;
        case 15: res.stats.n_valid = 100u; break; /* fewer than the points in features */
        case 16: res.features[0].e_curve = -0.001f; break;
        case 17:
            res.n_features = BSF_MAX_SEGMENTS + 1u;
            want = BSF_ERR_CAPACITY;
            break;
        default: res.features[5].last_beam = BSF_MAX_POINTS; break;
        }
        TEST_ASSERT_EQUAL_INT_MESSAGE(want, bsf_frame_encode(&info, &res, buf, sizeof buf, &n),
                                      "case");
        TEST_ASSERT_EQUAL_INT(want, bsf_frame_encode(&info, &res, NULL, 0u, &n));
    }
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(NULL, &res, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(&info, &res, buf, sizeof buf, NULL));
}

/* The edges of the representable range, in x and in y, for an anchor and a
 * precision point: at a step of 1 m, floor(v + 1/2) must stay within
 * +-(2^23 - 1); -8388608 rounds to -2^23 and is refused like 8388607.5. */
static void test_quantisation_range_edges_in_both_coordinates(void)
{
    static const struct {
        float v;
        bsf_status_t want;
    } edge[] = {{8388606.5f, BSF_OK},       {8388607.0f, BSF_OK},      {8388607.5f, BSF_ERR_ARG},
                {-8388607.0f, BSF_OK},      {-8388607.5f, BSF_OK},     {-8388608.0f, BSF_ERR_ARG},
                {-8388608.5f, BSF_ERR_ARG}, {-8388609.0f, BSF_ERR_ARG}};
    bsf_frame_info_t info;
    unsigned e;
    unsigned slot;
    for (e = 0; e < sizeof edge / sizeof edge[0]; ++e) {
        for (slot = 0; slot < 4u; ++slot) { /* point 0 or 1 (anchor, precision), x or y */
            size_t n = 0;
            fx_example_minimal(&info, &res);
            info.quant_step = 1.0f;
            if (slot % 2u == 0u) {
                res.ctrl[slot / 2u].x = edge[e].v;
            } else {
                res.ctrl[slot / 2u].y = edge[e].v;
            }
            TEST_ASSERT_EQUAL_INT_MESSAGE(
                edge[e].want, bsf_frame_encode(&info, &res, buf, sizeof buf, &n), "edge");
            TEST_ASSERT_EQUAL_INT(edge[e].want, bsf_frame_encode(&info, &res, NULL, 0u, &n));
            if (edge[e].want == BSF_OK) {
                TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
                TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 64u));
                TEST_ASSERT_EQUAL_FLOAT(floorf(edge[e].v + 0.5f),
                                        slot % 2u == 0u ? frame.result.ctrl[slot / 2u].x
                                                        : frame.result.ctrl[slot / 2u].y);
            }
        }
    }
}

static void test_worst_case_frame_fits_the_max_size_macro(void)
{
    bsf_frame_info_t info;
    uint16_t i;
    uint16_t k;
    size_t n = 0;
    const float far = (float)BSF_QUANT_MAX_STEPS * 0.0001f;
    bsf_frame_info_init(&info);
    info.seq = UINT32_MAX;
    info.timestamp_ms = UINT64_MAX;
    info.has_pose = 1u;
    info.pose.x = -BSF_POSE_XY_MAX;
    info.pose.y = BSF_POSE_XY_MAX;
    info.pose.theta = 3.0f;
    info.quant_step = 0.0001f;
    memset(&res, 0, sizeof res);
    res.n_features = BSF_MAX_SEGMENTS;
    res.n_ctrl = BSF_MAX_CTRL_POINTS;
    for (i = 0; i < BSF_MAX_SEGMENTS; ++i) {
        bsf_feature_t *f = &res.features[i];
        f->ctrl_first = (uint16_t)(i * (BSF_MAX_CTRL_POINTS / BSF_MAX_SEGMENTS));
        f->n_ctrl = (uint8_t)(BSF_MAX_CTRL_POINTS / BSF_MAX_SEGMENTS);
        f->first_beam = (uint16_t)(i % 2u == 0u ? BSF_MAX_POINTS - 1u : 0u);
        f->last_beam = f->first_beam;
        f->n_points = 0u;
        f->e_curve = BSF_E_CURVE_MAX;
        f->kind = 1u;
        for (k = 0; k < f->n_ctrl; ++k) {
            res.ctrl[f->ctrl_first + k].x = (k + i) % 2u == 0u ? far : -far;
            res.ctrl[f->ctrl_first + k].y = (k + i) % 2u == 0u ? -far : far;
        }
    }
    res.stats.n_valid = BSF_MAX_POINTS;
    res.stats.time_ns = UINT32_MAX;
    /* The header extension at its largest: a wrap, every cut counter full. */
    res.features[BSF_MAX_SEGMENTS - 1u].first_beam = BSF_MAX_POINTS - 1u;
    res.features[BSF_MAX_SEGMENTS - 1u].last_beam = 0u;
    res.stats.n_beams = BSF_MAX_POINTS;
    res.stats.cut = BSF_CUT_KEYPOINTS | BSF_CUT_SEGMENTS | BSF_CUT_CTRL;
    res.stats.n_cut_keypoints = BSF_MAX_POINTS;
    res.stats.n_cut_segments = BSF_MAX_POINTS;
    res.stats.n_cut_points = BSF_MAX_POINTS;
    info.has_geometry = 1u;
    info.angle_min = -3.0f;
    info.angle_increment = 0.001f;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    printf("worst-case test frame: %u bytes (BSF_FRAME_MAX_SIZE %u)\n", (unsigned)n,
           (unsigned)BSF_FRAME_MAX_SIZE);
    TEST_ASSERT_TRUE(n <= BSF_FRAME_MAX_SIZE);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 700u));
    TEST_ASSERT_EQUAL_UINT16(BSF_MAX_CTRL_POINTS, frame.result.n_ctrl);
    TEST_ASSERT_FLOAT_WITHIN(0.0001f, far, frame.result.ctrl[0].x);
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_POINTS, frame.result.stats.n_cut_points);
    TEST_ASSERT_EQUAL_UINT16(0u, frame.result.features[BSF_MAX_SEGMENTS - 1u].last_beam);
}

/* ---- Stream decoder ---- */

static void test_decoder_delivers_each_of_two_frames_in_one_chunk(void)
{
    bsf_frame_info_t info;
    size_t n1 = 0;
    size_t n2 = 0;
    size_t used = 0;
    fx_example_minimal(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n1));
    info.seq = 7u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf + n1, sizeof buf - n1, &n2));
    TEST_ASSERT_EQUAL_INT(1, bsf_decoder_feed(&dec, buf, n1 + n2, &used, &frame));
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n1, (uint32_t)used);
    TEST_ASSERT_EQUAL_UINT32(0u, frame.seq);
    TEST_ASSERT_EQUAL_INT(1, bsf_decoder_feed(&dec, buf + n1, n2, &used, &frame));
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n2, (uint32_t)used);
    TEST_ASSERT_EQUAL_UINT32(7u, frame.seq);
    TEST_ASSERT_EQUAL_INT(0, bsf_decoder_feed(&dec, NULL, 0u, &used, &frame));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_decoder_feed(&dec, buf, 1u, NULL, &frame));
}

static void test_truncated_frames_are_never_delivered(void)
{
    size_t cut;
    unsigned delivered = 0;
    const uint8_t zero = 0u;
    for (cut = 1; cut < sizeof golden_typical - 1u; ++cut) {
        delivered += feed_all(golden_typical, cut, cut);
        delivered += feed_all(&zero, 1u, 1u);
    }
    TEST_ASSERT_EQUAL_UINT32(0u, delivered);
    TEST_ASSERT_EQUAL_UINT32(0u, dec.stats.frames_ok);
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_typical - 2u, dec.stats.bad_crc + dec.stats.malformed);
    /* Back in step right away. */
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_typical, sizeof golden_typical, 9u));
}

static void test_oversized_frame_is_skipped_and_counted(void)
{
    size_t i;
    unsigned delivered = 0;
    for (i = 0; i < sizeof scratch; ++i) {
        scratch[i] = (uint8_t)(1u + i % 200u);
    }
    delivered += feed_all(scratch, sizeof scratch, 1000u);
    delivered +=
        feed_all(golden_minimal, sizeof golden_minimal, 1000u); /* its 0x00 ends the junk */
    delivered += feed_all(golden_minimal, sizeof golden_minimal, 1000u);
    TEST_ASSERT_EQUAL_UINT32(1u, delivered);
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.oversize);
    TEST_ASSERT_EQUAL_UINT32(sizeof scratch + sizeof golden_minimal - 1u, dec.stats.bytes_skipped);
}

static void test_stream_of_only_delimiters_yields_nothing_and_counts_nothing(void)
{
    static const bsf_decoder_stats_t zero_stats;
    memset(scratch, 0, 1000u);
    TEST_ASSERT_EQUAL_UINT32(0u, feed_all(scratch, 1000u, 7u));
    TEST_ASSERT_EQUAL_MEMORY(&zero_stats, &dec.stats, sizeof zero_stats);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_minimal, sizeof golden_minimal, 3u));
}

static void test_garbage_before_the_first_frame_is_skipped(void)
{
    fx_rng_t rng;
    size_t i;
    fx_rng_seed(&rng, 99u);
    for (i = 0; i < 300u; ++i) {
        scratch[i] = (uint8_t)fx_rng_range(&rng, 1u, 255u);
    }
    scratch[300] = 0u;
    TEST_ASSERT_EQUAL_UINT32(0u, feed_all(scratch, 301u, 17u));
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_typical, sizeof golden_typical, 17u));
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.bad_crc + dec.stats.malformed);
    TEST_ASSERT_EQUAL_UINT32(300u, dec.stats.bytes_skipped);
    TEST_ASSERT_EQUAL_UINT32(1234u, frame.seq);
}

static void test_unknown_version_and_type_are_counted_and_skipped(void)
{
    uint8_t payload[64];
    const size_t len = golden_payload(golden_minimal, sizeof golden_minimal, payload);
    size_t n;
    payload[0] = 0x31; /* version 3 */
    n = reframe(payload, len, scratch);
    TEST_ASSERT_EQUAL_UINT32(0u, feed_all(scratch, n, 64u));
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.unsupported_version);
    payload[0] = 0x01; /* version 0 */
    n = reframe(payload, len, scratch);
    TEST_ASSERT_EQUAL_UINT32(0u, feed_all(scratch, n, 64u));
    TEST_ASSERT_EQUAL_UINT32(2u, dec.stats.unsupported_version);
    payload[0] = 0x12; /* version 1 has no metadata type */
    n = reframe(payload, len, scratch);
    TEST_ASSERT_EQUAL_UINT32(0u, feed_all(scratch, n, 64u));
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.unknown_type);
    payload[0] = 0x24; /* version 2, type 4 (type 3 is the map update) */
    n = reframe(payload, len, scratch);
    TEST_ASSERT_EQUAL_UINT32(0u, feed_all(scratch, n, 64u));
    TEST_ASSERT_EQUAL_UINT32(2u, dec.stats.unknown_type);
    payload[0] = 0x21;
    n = reframe(payload, len, scratch);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(scratch, n, 64u));
    TEST_ASSERT_EQUAL_UINT32(0u, dec.stats.malformed);
}

/* A payload written field by field (FORMAT.md section 3), MSB first. */
typedef struct {
    uint8_t byte[160];
    size_t bits;
} bitbuf_t;

static void bb_bits(bitbuf_t *w, uint64_t v, unsigned n)
{
    while (n > 0u) {
        const unsigned bit = (unsigned)(v >> --n) & 1u;
        if (w->bits % 8u == 0u) {
            w->byte[w->bits / 8u] = 0u;
        }
        w->byte[w->bits / 8u] |= (uint8_t)(bit << (7u - w->bits % 8u));
        ++w->bits;
    }
}

static void bb_eg(bitbuf_t *w, uint64_t v, unsigned k)
{
    const uint64_t u = (v >> k) + 1u;
    unsigned n = 0;
    while ((u >> n) > 1u) {
        ++n;
    }
    bb_bits(w, 0u, n);
    bb_bits(w, u, n + 1u);
    bb_bits(w, v & (((uint64_t)1u << k) - 1u), k);
}

static void bb_seg(bitbuf_t *w, int64_t v, unsigned k)
{
    bb_eg(w, v < 0 ? ((uint64_t)(-(v + 1)) << 1) | 1u : (uint64_t)v << 1, k);
}

/* Example 1 of FORMAT.md with one defect (0: none); returns the payload length. */
static size_t example1_payload(unsigned defect, uint8_t *out)
{
    bitbuf_t w;
    size_t len;
    w.bits = 0;
    bb_bits(&w, 0x21u, 8u);
    bb_bits(&w, 0u, 1u);                                       /* no pose */
    bb_bits(&w, defect >= 13u && defect <= 17u ? 1u : 0u, 1u); /* extension */
    if (defect == 8u) {
        bb_bits(&w, 0u, 30u); /* seq: a zero run too long for 32 bits */
    }
    bb_eg(&w, 0u, 8u);                            /* seq */
    bb_eg(&w, 0u, 20u);                           /* timestamp */
    bb_eg(&w, defect == 3u ? 0u : 50u, 4u);       /* step code */
    bb_eg(&w, defect == 7u ? 5u : 20u, 6u);       /* N */
    bb_eg(&w, defect == 10u ? 4294968u : 0u, 5u); /* extraction time, us */
    bb_eg(&w, defect == 4u ? 2u : 1u, 2u);        /* features */
    bb_bits(&w, 8u, 5u);                          /* k_first */
    bb_bits(&w, 8u, 5u);                          /* k_anchor */
    bb_bits(&w, defect == 11u ? 26u : 0u, 5u);    /* k_precision */
    if (defect == 13u) {
        bb_bits(&w, 0u, 5u); /* an empty extension: no beam count, no geometry, no cut */
    } else if (defect == 14u) {
        bb_bits(&w, 1u, 1u); /* a beam count although no feature wraps, without geometry */
        bb_bits(&w, 0u, 4u);
        bb_eg(&w, 360u, 8u);
    } else if (defect == 16u) {
        bb_bits(&w, 0u, 1u); /* a geometry without its beam count */
        bb_bits(&w, 1u, 1u);
        bb_bits(&w, BSF_CUT_SEGMENTS, 3u);
        bb_bits(&w, 0x3F800000u, 32u);
        bb_bits(&w, 0x3C8EFA35u, 32u);
        bb_eg(&w, 0u, 2u);
        bb_eg(&w, 1u, 2u);
        bb_eg(&w, 0u, 4u);
    } else if (defect == 17u) {
        bb_bits(&w, 1u, 1u); /* a geometry whose angle is not finite */
        bb_bits(&w, 1u, 1u);
        bb_bits(&w, 0u, 3u);
        bb_eg(&w, 360u, 8u);
        bb_bits(&w, 0x7F800000u, 32u);
        bb_bits(&w, 0x3C8EFA35u, 32u);
    } else if (defect == 15u) {
        bb_bits(&w, 0u, 2u);
        bb_bits(&w, BSF_CUT_SEGMENTS, 3u);
        bb_eg(&w, 0u, 2u);
        bb_eg(&w, 1u, 2u);
        bb_eg(&w, 1u, 4u); /* a cut point although all 20 valid points are in features */
    }
    bb_bits(&w, 0u, 1u);                     /* bleak */
    bb_eg(&w, defect == 5u ? 0u : 1u, 1u);   /* m - 2 */
    bb_bits(&w, defect == 9u ? 1u : 0u, 1u); /* vertex mask follows */
    if (defect == 9u) {
        bb_bits(&w, 0u, 3u); /* a mask without any vertex */
    }
    bb_seg(&w, defect == 6u ? 1070 : 10, 2u); /* gap: first beam 10 (1070: beyond the caps) */
    bb_eg(&w, 19u, 3u);                       /* span */
    bb_eg(&w, 0u, 0u);                        /* missing */
    bb_eg(&w, 10u, 4u);                       /* E_curve, 0.5 mm */
    bb_seg(&w, 200, 8u);                      /* first point */
    bb_seg(&w, 100, 8u);
    bb_seg(&w, 200, 8u); /* last anchor - first */
    bb_seg(&w, 100, 8u);
    if (defect != 5u) {
        bb_seg(&w, 0, 0u); /* middle point - prediction */
        bb_seg(&w, 10, 0u);
    }
    if (defect == 12u) {
        bb_bits(&w, 1u, 1u); /* a set padding bit */
    }
    len = (w.bits + 7u) / 8u;
    if (defect == 1u) {
        w.byte[len++] = 0u; /* trailing byte */
    }
    if (defect == 2u) {
        --len; /* cut short */
    }
    memcpy(out, w.byte, len);
    return len;
}

static void test_field_by_field_payload_equals_the_golden_one(void)
{
    uint8_t golden[64];
    uint8_t built[64];
    const size_t len = golden_payload(golden_minimal, sizeof golden_minimal, golden);
    TEST_ASSERT_EQUAL_UINT32(len, example1_payload(0u, built));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden, built, len);
}

static void test_malformed_fields_are_dropped_and_counted(void)
{
    uint8_t payload[72];
    unsigned c;
    for (c = 1; c <= 17u; ++c) {
        const size_t plen = example1_payload(c, payload);
        const size_t n = reframe(payload, plen, scratch);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(0u, feed_all(scratch, n, 64u),
                                         "malformed frame delivered");
        TEST_ASSERT_EQUAL_UINT32(c, dec.stats.malformed);
    }
    TEST_ASSERT_EQUAL_UINT32(0u, dec.stats.bad_crc);
    TEST_ASSERT_EQUAL_UINT32(0u, dec.stats.frames_ok);
}

/* bsf_stats_t.time_ns is uint32 ns: 4 294 967 us is the last extraction time
 * a frame can carry and re-encode alike; one more is malformed. */
static void test_extraction_time_beyond_time_ns_range_is_refused(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    size_t len = 0;
    fx_example_minimal(&info, &res);
    res.stats.time_ns = UINT32_MAX;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 64u));
    TEST_ASSERT_EQUAL_UINT32(4294967u, frame.time_us);
    TEST_ASSERT_EQUAL_UINT32(4294967000u, frame.result.stats.time_ns);
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_frame_encode(&info, &frame.result, scratch, sizeof scratch, &len));
    TEST_ASSERT_EQUAL_UINT32(n, len);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(buf, scratch, n);
    /* One microsecond more: refused by the one-shot decoder too. */
    len = example1_payload(10u, body);
    {
        const uint32_t crc = bsf_crc32c(0u, body, len);
        unsigned i;
        for (i = 0; i < 4u; ++i) {
            body[len + i] = (uint8_t)(crc >> (8u * i));
        }
    }
    TEST_ASSERT_EQUAL_INT(BSF_ERR_FORMAT, bsf_frame_decode(body, len + 4u, &frame));
}

static void test_bad_crc_is_dropped_and_the_next_frame_decodes(void)
{
    memcpy(scratch, golden_typical, sizeof golden_typical);
    scratch[40] ^= 0x01u;
    TEST_ASSERT_EQUAL_UINT32(0u, feed_all(scratch, sizeof golden_typical, 50u));
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.bad_crc);
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_typical - 1u, dec.stats.bytes_skipped);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_typical, sizeof golden_typical, 50u));
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.frames_ok);
}

/* ---- Format version 1, header extension, wrapping features, metadata ---- */

static void test_version_1_frames_still_decode(void)
{
    bsf_frame_info_t info;
    fx_example_minimal(&info, &res);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_minimal_v1, sizeof golden_minimal_v1, 3u));
    assert_round_trip(&info, &res, &frame);
    TEST_ASSERT_EQUAL_UINT8(1u, frame.version);
    TEST_ASSERT_EQUAL_UINT8(BSF_FRAME_TYPE_FEATURES, frame.type);
    /* The same scan in version 2 costs one flag bit (here one byte, as the
     * version-1 frame ended exactly on a byte boundary). */
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_minimal_v1 + 1u, sizeof golden_minimal);
    TEST_ASSERT_EQUAL_UINT8(2u, golden_minimal[1] >> 4);
}

static void test_golden_wrap_cut_frame_carries_seam_and_cut(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    fx_example_wrap_cut(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_wrap_cut, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_wrap_cut, buf, sizeof golden_wrap_cut);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_wrap_cut, sizeof golden_wrap_cut, 4u));
    assert_round_trip(&info, &res, &frame);
    TEST_ASSERT_EQUAL_UINT16(350u, frame.result.features[1].first_beam);
    TEST_ASSERT_EQUAL_UINT16(9u, frame.result.features[1].last_beam);
    TEST_ASSERT_EQUAL_UINT32(360u, frame.result.stats.n_beams);
    TEST_ASSERT_EQUAL_UINT32(BSF_CUT_SEGMENTS, frame.result.stats.cut);
    TEST_ASSERT_EQUAL_UINT32(0u, frame.result.stats.n_cut_keypoints);
    TEST_ASSERT_EQUAL_UINT32(2u, frame.result.stats.n_cut_segments);
    TEST_ASSERT_EQUAL_UINT32(11u, frame.result.stats.n_cut_points);
    /* Decoded and encoded again: the same bytes. */
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          bsf_frame_encode(&info, &frame.result, scratch, sizeof scratch, &n));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_wrap_cut, scratch, sizeof golden_wrap_cut);
}

static void test_cut_alone_and_wrap_alone_round_trip(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    size_t plain = 0;
    fx_example_typical(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, NULL, 0u, &plain));
    res.stats.cut = BSF_CUT_KEYPOINTS | BSF_CUT_CTRL;
    res.stats.n_cut_keypoints = 5u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_TRUE(n > plain && n <= plain + 3u);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 13u));
    TEST_ASSERT_EQUAL_UINT32(BSF_CUT_KEYPOINTS | BSF_CUT_CTRL, frame.result.stats.cut);
    TEST_ASSERT_EQUAL_UINT32(5u, frame.result.stats.n_cut_keypoints);
    TEST_ASSERT_EQUAL_UINT32(0u, frame.result.stats.n_beams); /* no wrap, no metadata */

    fx_example_wrap_cut(&info, &res);
    res.stats.cut = 0u;
    res.stats.n_cut_segments = 0u;
    res.stats.n_cut_points = 0u;
    res.features[1].first_beam = 359u; /* one beam before the seam, 11 after */
    res.features[1].last_beam = 10u;
    res.features[1].n_points = 12u;
    res.stats.n_in_features = 39u + 12u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 64u));
    assert_round_trip(&info, &res, &frame);
    TEST_ASSERT_EQUAL_UINT32(0u, frame.result.stats.cut);
    TEST_ASSERT_EQUAL_UINT32(360u, frame.result.stats.n_beams);
}

static void test_encoder_refuses_inconsistent_seam_and_cut_stats(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    unsigned c;
    for (c = 0; c < 9u; ++c) {
        fx_example_wrap_cut(&info, &res);
        switch (c) {
        case 0: res.stats.n_beams = 0u; break;   /* a wrap needs the beam count */
        case 1: res.stats.n_beams = 350u; break; /* first beam outside the scan */
        case 2: res.features[0].last_beam = 360u; break;
        case 3: res.stats.cut = 0x8u; break;          /* not a BSF_CUT_* bit */
        case 4: res.stats.cut = 0u; break;            /* counters without a cut */
        case 5: res.stats.n_cut_points = 242u; break; /* 300 valid, 59 in features */
        case 6: res.stats.n_cut_segments = BSF_MAX_POINTS + 1u; break;
        case 7: res.stats.n_beams = 299u; break;        /* fewer beams than valid readings */
        default: res.features[1].n_points = 22u; break; /* the run has 20 beams */
        }
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ERR_ARG,
                                      bsf_frame_encode(&info, &res, buf, sizeof buf, &n), "case");
    }
    fx_example_wrap_cut(&info, &res);
    res.stats.n_cut_points = 241u; /* every valid point outside the features */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
}

/* Every field of two metadata records equal, floats bit for bit. */
static void assert_metadata_equal(const bsf_metadata_t *a, const bsf_metadata_t *b)
{
    TEST_ASSERT_EQUAL_UINT16(a->lib_version_major, b->lib_version_major);
    TEST_ASSERT_EQUAL_UINT16(a->lib_version_minor, b->lib_version_minor);
    TEST_ASSERT_EQUAL_UINT16(a->lib_version_patch, b->lib_version_patch);
    TEST_ASSERT_EQUAL_UINT8(a->method, b->method);
    TEST_ASSERT_EQUAL_MEMORY(&a->target_rms, &b->target_rms, sizeof(float));
    TEST_ASSERT_FLOAT_WITHIN(1e-7f, a->quant_step, b->quant_step);
    TEST_ASSERT_EQUAL_UINT32(a->max_points, b->max_points);
    TEST_ASSERT_EQUAL_UINT32(a->max_keypoints, b->max_keypoints);
    TEST_ASSERT_EQUAL_UINT32(a->max_segments, b->max_segments);
    TEST_ASSERT_EQUAL_UINT32(a->max_ctrl_per_feature, b->max_ctrl_per_feature);
    TEST_ASSERT_EQUAL_UINT32(a->max_ctrl_points, b->max_ctrl_points);
    TEST_ASSERT_EQUAL_UINT32(a->n_beams, b->n_beams);
    TEST_ASSERT_EQUAL_MEMORY(&a->angle_min, &b->angle_min, sizeof(float));
    TEST_ASSERT_EQUAL_MEMORY(&a->angle_increment, &b->angle_increment, sizeof(float));
    TEST_ASSERT_EQUAL_MEMORY(&a->range_min, &b->range_min, sizeof(float));
    TEST_ASSERT_EQUAL_MEMORY(&a->range_max, &b->range_max, sizeof(float));
    TEST_ASSERT_EQUAL_UINT8(a->has_time_origin, b->has_time_origin);
    TEST_ASSERT_TRUE(a->time_origin_us == b->time_origin_us);
    TEST_ASSERT_EQUAL_UINT8(a->source_len, b->source_len);
    TEST_ASSERT_EQUAL_MEMORY(a->source, b->source, a->source_len);
    TEST_ASSERT_EQUAL_HEX8(0, b->source[b->source_len]);
}

static void test_golden_metadata_frame_round_trips_bit_exact(void)
{
    bsf_metadata_t m;
    size_t n = 0;
    fx_example_metadata(&m);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metadata_encode(&m, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_metadata, (uint32_t)n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_metadata, buf, sizeof golden_metadata);
    TEST_ASSERT_TRUE(n <= BSF_METADATA_MAX_SIZE);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(golden_metadata, sizeof golden_metadata, 5u));
    TEST_ASSERT_EQUAL_UINT8(BSF_FRAME_TYPE_METADATA, frame.type);
    TEST_ASSERT_EQUAL_UINT8(2u, frame.version);
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.metadata);
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.frames_ok);
    TEST_ASSERT_EQUAL_UINT16(0u, frame.result.n_features);
    TEST_ASSERT_EQUAL_UINT32(0u, frame.seq);
    /* Every field, floats bit for bit. */
    assert_metadata_equal(&m, &frame.metadata);
    TEST_ASSERT_EQUAL_STRING("intel.log.gz", frame.metadata.source);
}

static void test_metadata_sink_and_init(void)
{
    static bsf_encoder_t work;
    bsf_metadata_t m;
    sink_log_t log;
    size_t n = 0;
    size_t written = 0;
    bsf_metadata_init(&m);
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_POINTS, m.max_points);
    TEST_ASSERT_EQUAL_UINT32(BSF_MAX_CTRL_POINTS, m.max_ctrl_points);
    TEST_ASSERT_EQUAL_FLOAT(BSF_QUANT_STEP_DEFAULT, m.quant_step);
    TEST_ASSERT_EQUAL_UINT16(BSF_VERSION_MAJOR, m.lib_version_major);
    TEST_ASSERT_EQUAL_UINT16(BSF_VERSION_MINOR, m.lib_version_minor);
    TEST_ASSERT_EQUAL_UINT16(BSF_VERSION_PATCH, m.lib_version_patch);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metadata_encode(&m, NULL, 0u, &n));
    fx_example_metadata(&m);
    memset(&log, 0, sizeof log);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metadata_encode_sink(&work, &m, record_sink, &log, &written));
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_metadata, (uint32_t)written);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_metadata, scratch, sizeof golden_metadata);
    memset(&log, 0, sizeof log);
    log.fail_after = 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER,
                          bsf_metadata_encode_sink(&work, &m, record_sink, &log, &written));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_BUFFER,
                          bsf_metadata_encode(&m, buf, sizeof golden_metadata - 1u, &n));
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_metadata, (uint32_t)n);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metadata_encode(NULL, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metadata_encode_sink(&work, &m, NULL, &log, &written));
}

static void test_metadata_encoder_refuses_bad_fields(void)
{
    static const char *const bad_names[] = {
        "a\nb",             /* control character */
        "\xC3",             /* cut short */
        "\xC0\xAF",         /* overlong */
        "\xED\xA0\x80",     /* surrogate */
        "\xF4\x90\x80\x80", /* above U+10FFFF */
        "\xC2\x85",         /* C1 control */
        "\x7F",             /* DEL */
    };
    bsf_metadata_t m;
    size_t n = 0;
    unsigned c;
    for (c = 0; c < 14u; ++c) {
        fx_example_metadata(&m);
        switch (c) {
        case 0: m.range_max = NAN; break;
        case 1: m.angle_min = INFINITY; break;
        case 2: m.range_min = -0.1f; break;
        case 3: m.range_max = m.range_min - 1.0f; break;
        case 4: m.target_rms = -0.001f; break;
        case 5: m.quant_step = 0.0f; break;
        case 6: m.max_segments = 0u; break;
        case 7: m.max_ctrl_points = 65536u; break;
        case 8: m.n_beams = 65536u; break;
        case 9: m.time_origin_us = BSF_METADATA_TIME_ORIGIN_MAX + 1LL; break;
        case 10: m.source_len = BSF_METADATA_SOURCE_MAX + 1u; break;
        case 11: m.has_time_origin = 2u; break;
        case 12: m.angle_increment = NAN; break;
        default: m.time_origin_us = -BSF_METADATA_TIME_ORIGIN_MAX - 1LL; break;
        }
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ERR_ARG, bsf_metadata_encode(&m, buf, sizeof buf, &n),
                                      "case");
    }
    for (c = 0; c < sizeof bad_names / sizeof bad_names[0]; ++c) {
        fx_example_metadata(&m);
        m.source_len = (uint8_t)strlen(bad_names[c]);
        memcpy(m.source, bad_names[c], m.source_len);
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ERR_ARG, bsf_metadata_encode(&m, buf, sizeof buf, &n),
                                      "name");
    }
    fx_example_metadata(&m);
    m.source_len = 14u;
    memcpy(m.source, "caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80", 14u); /* 2-, 3-, 4-byte forms */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metadata_encode(&m, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 64u));
    assert_metadata_equal(&m, &frame.metadata);
}

static void bb_float(bitbuf_t *w, uint32_t bits)
{
    bb_bits(w, bits, 32u);
}

/* Example 4 of FORMAT.md written field by field, with one defect (0: none). */
static size_t metadata_payload(unsigned defect, uint8_t *out)
{
    static const char name[] = "intel.log.gz";
    bitbuf_t w;
    size_t len;
    size_t i;
    w.bits = 0;
    bb_bits(&w, 0x22u, 8u);
    bb_eg(&w, 0u, 1u); /* library 0.1.0 */
    bb_eg(&w, 1u, 1u);
    bb_eg(&w, 0u, 1u);
    bb_eg(&w, 0u, 0u);                                      /* method 0 */
    bb_float(&w, defect == 1u ? 0x7FC00000u : 0x3C75C28Fu); /* target RMS 0.015 (1: NaN) */
    bb_eg(&w, 50u, 4u);                                     /* step 5 mm */
    bb_eg(&w, 1081u, 8u);
    bb_eg(&w, 64u, 4u);
    bb_eg(&w, defect == 2u ? 0u : 128u, 4u); /* 2: a cap of 0 */
    bb_eg(&w, 32u, 2u);
    bb_eg(&w, 512u, 6u);
    bb_eg(&w, 180u, 8u);                                    /* beams */
    bb_float(&w, 0xBFC90FDBu);                              /* angle_min -pi/2 */
    bb_float(&w, 0x3C8EFA35u);                              /* increment pi/180 */
    bb_float(&w, defect == 3u ? 0x42A3D70Au : 0x00000000u); /* range_min (3: above range_max) */
    bb_float(&w, 0x42A3D1ECu);                              /* range_max 81.91 */
    bb_bits(&w, 1u, 1u);                                    /* time origin follows */
    bb_seg(&w, 1066286502361000LL, 40u);
    bb_eg(&w, defect == 4u ? 65u : 12u, 3u); /* name length (4: too long) */
    for (i = 0; i < 12u; ++i) {
        bb_bits(&w, defect == 5u && i == 3u ? 0x0Au : (uint8_t)name[i], 8u); /* 5: a newline */
    }
    if (defect == 6u) {
        bb_bits(&w, 1u, 1u); /* a set padding bit */
    }
    len = (w.bits + 7u) / 8u;
    if (defect == 7u) {
        w.byte[len++] = 0u; /* trailing byte */
    }
    memcpy(out, w.byte, len);
    return len;
}

static void test_metadata_field_by_field_and_malformed_fields(void)
{
    uint8_t golden[160];
    uint8_t built[160];
    unsigned c;
    const size_t len = golden_payload(golden_metadata, sizeof golden_metadata, golden);
    TEST_ASSERT_EQUAL_UINT32(len, metadata_payload(0u, built));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden, built, len);
    for (c = 1; c <= 7u; ++c) {
        const size_t plen = metadata_payload(c, built);
        const size_t n = reframe(built, plen, scratch);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(0u, feed_all(scratch, n, 64u), "malformed delivered");
        TEST_ASSERT_EQUAL_UINT32(c, dec.stats.malformed);
    }
    TEST_ASSERT_EQUAL_UINT32(0u, dec.stats.metadata);
}

static void test_stream_decoder_takes_beam_count_from_metadata(void)
{
    bsf_frame_info_t info;
    bsf_metadata_t m;
    size_t used = 0;
    size_t n = 0;
    fx_example_metadata(&m);
    memcpy(buf, golden_metadata, sizeof golden_metadata);
    fx_example_typical(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf + sizeof golden_metadata,
                                                   sizeof buf - sizeof golden_metadata, &n));
    TEST_ASSERT_EQUAL_INT(BSF_FRAME_TYPE_METADATA,
                          bsf_decoder_feed(&dec, buf, sizeof golden_metadata + n, &used, &frame));
    TEST_ASSERT_EQUAL_UINT32(sizeof golden_metadata, (uint32_t)used);
    TEST_ASSERT_EQUAL_INT(BSF_FRAME_TYPE_FEATURES,
                          bsf_decoder_feed(&dec, buf + used, n, &used, &frame));
    TEST_ASSERT_EQUAL_UINT32(180u, frame.result.stats.n_beams);
    TEST_ASSERT_EQUAL_UINT32(1u, dec.stats.metadata);
    TEST_ASSERT_EQUAL_UINT32(2u, dec.stats.frames_ok);
    /* The one-shot decoder keeps no state: 0 = unknown. */
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_cobs_decode(buf + sizeof golden_metadata, n - 1u, body, sizeof body, &used));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_decode(body, used, &frame));
    TEST_ASSERT_EQUAL_UINT32(0u, frame.result.stats.n_beams);
    /* A beam count that the frame's beams exceed is not applied. */
    fx_example_wrap_cut(&info, &res);
    res.features[1].first_beam = 200u;
    res.features[1].last_beam = 219u;
    res.stats.n_beams = 0u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 64u));
    TEST_ASSERT_EQUAL_UINT32(0u, frame.result.stats.n_beams);
    /* bsf_decoder_init forgets the metadata. */
    bsf_decoder_init(&dec);
    fx_example_typical(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 64u));
    TEST_ASSERT_EQUAL_UINT32(0u, frame.result.stats.n_beams);
}

static void test_worst_case_metadata_fits_the_max_size_macros(void)
{
    bsf_metadata_t m;
    size_t n = 0;
    unsigned i;
    memset(&m, 0, sizeof m);
    m.lib_version_major = 65535u;
    m.lib_version_minor = 65535u;
    m.lib_version_patch = 65535u;
    m.method = 255u;
    m.target_rms = 1.0f;
    m.quant_step = 1.0f;
    m.max_points = m.max_keypoints = m.max_segments = 65535u;
    m.max_ctrl_per_feature = m.max_ctrl_points = m.n_beams = 65535u;
    m.range_max = 1.0f;
    m.has_time_origin = 1u;
    m.time_origin_us = -BSF_METADATA_TIME_ORIGIN_MAX;
    m.source_len = BSF_METADATA_SOURCE_MAX;
    for (i = 0; i < BSF_METADATA_SOURCE_MAX; i += 4u) {
        memcpy(&m.source[i], "\xF4\x8F\xBF\xBF", 4u); /* U+10FFFF */
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metadata_encode(&m, buf, sizeof buf, &n));
    printf("worst-case metadata frame: %u bytes (BSF_METADATA_MAX_SIZE %u)\n", (unsigned)n,
           (unsigned)BSF_METADATA_MAX_SIZE);
    TEST_ASSERT_TRUE(n <= BSF_METADATA_MAX_SIZE);
    TEST_ASSERT_TRUE(n + 3u >= BSF_METADATA_MAX_SIZE); /* the bound is tight */
    TEST_ASSERT_TRUE(BSF_METADATA_MAX_SIZE <= BSF_FRAME_MAX_SIZE);
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 100u));
    assert_metadata_equal(&m, &frame.metadata);
}

static void test_frame_geometry_round_trips_and_is_checked(void)
{
    bsf_frame_info_t info;
    size_t n = 0;
    size_t plain = 0;
    fx_example_typical(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, NULL, 0u, &plain));
    info.has_geometry = 1u;
    info.angle_min = -1.5577060f;
    info.angle_increment = 0.0174533f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    res.stats.n_beams = 181u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_TRUE(n > plain + 8u && n <= plain + 11u); /* two floats and a beam count */
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 7u));
    assert_round_trip(&info, &res, &frame);
    TEST_ASSERT_EQUAL_UINT8(1u, frame.has_geometry);
    TEST_ASSERT_EQUAL_MEMORY(&info.angle_min, &frame.angle_min, sizeof(float));
    TEST_ASSERT_EQUAL_MEMORY(&info.angle_increment, &frame.angle_increment, sizeof(float));
    TEST_ASSERT_EQUAL_UINT32(181u, frame.result.stats.n_beams);
    info.angle_increment = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    info.angle_increment = 0.0174533f;
    info.has_geometry = 2u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    res.stats.n_beams = 170u; /* feature 6 ends at beam 178 */
    info.has_geometry = 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    /* Without has_geometry the frame says nothing about it. */
    fx_example_typical(&info, &res);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, buf, sizeof buf, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, feed_all(buf, n, 64u));
    TEST_ASSERT_EQUAL_UINT8(0u, frame.has_geometry);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_crc32c_check_value_and_chaining);
    RUN_TEST(test_cobs_encodes_reference_vectors_and_decodes_them_back);
    RUN_TEST(test_cobs_refuses_zero_bytes_truncation_and_small_buffers);
    RUN_TEST(test_golden_minimal_frame_matches_format_md_and_decodes);
    RUN_TEST(test_golden_typical_frame_matches_format_md_and_decodes);
    RUN_TEST(test_one_shot_decode_reads_golden_body);
    RUN_TEST(test_size_query_equals_written_length);
    RUN_TEST(test_too_small_buffer_is_refused_without_writing);
    RUN_TEST(test_sink_gets_the_same_bytes_in_blocks_of_at_most_256);
    RUN_TEST(test_random_results_round_trip_within_half_a_step);
    RUN_TEST(test_vertex_travels_once_and_is_expanded_on_decode);
    RUN_TEST(test_encoder_rejects_values_it_cannot_represent);
    RUN_TEST(test_quantisation_range_edges_in_both_coordinates);
    RUN_TEST(test_worst_case_frame_fits_the_max_size_macro);
    RUN_TEST(test_decoder_delivers_each_of_two_frames_in_one_chunk);
    RUN_TEST(test_truncated_frames_are_never_delivered);
    RUN_TEST(test_oversized_frame_is_skipped_and_counted);
    RUN_TEST(test_stream_of_only_delimiters_yields_nothing_and_counts_nothing);
    RUN_TEST(test_garbage_before_the_first_frame_is_skipped);
    RUN_TEST(test_unknown_version_and_type_are_counted_and_skipped);
    RUN_TEST(test_field_by_field_payload_equals_the_golden_one);
    RUN_TEST(test_malformed_fields_are_dropped_and_counted);
    RUN_TEST(test_extraction_time_beyond_time_ns_range_is_refused);
    RUN_TEST(test_bad_crc_is_dropped_and_the_next_frame_decodes);
    RUN_TEST(test_version_1_frames_still_decode);
    RUN_TEST(test_golden_wrap_cut_frame_carries_seam_and_cut);
    RUN_TEST(test_cut_alone_and_wrap_alone_round_trip);
    RUN_TEST(test_encoder_refuses_inconsistent_seam_and_cut_stats);
    RUN_TEST(test_golden_metadata_frame_round_trips_bit_exact);
    RUN_TEST(test_metadata_sink_and_init);
    RUN_TEST(test_metadata_encoder_refuses_bad_fields);
    RUN_TEST(test_metadata_field_by_field_and_malformed_fields);
    RUN_TEST(test_stream_decoder_takes_beam_count_from_metadata);
    RUN_TEST(test_worst_case_metadata_fits_the_max_size_macros);
    RUN_TEST(test_frame_geometry_round_trips_and_is_checked);
    return UNITY_END();
}
