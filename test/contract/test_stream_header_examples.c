/* SPDX-License-Identifier: MIT */
/* The "Example usage:" blocks of include/bsf/bsf_stream.h, compiled from the
 * header itself (test/CMakeLists.txt extracts them into
 * stream_header_examples.inc, so the header cannot drift from the API) and
 * run: a scan's features leave through send_scan, come back through
 * on_bytes a few bytes at a time, and arrive whole. */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "unity.h"

/* What the examples call and define. */
static int link_write(const uint8_t *data, size_t len);
static void use_features(const bsf_result_t *result, const bsf_pose_t *pose);
int send_scan(const bsf_result_t *result, uint32_t seq, uint64_t time_ms);
void on_bytes(const uint8_t *data, size_t len);

#include "stream_header_examples.inc"

static bsf_extractor_t ex;
static bsf_result_t sent;
static float ranges[61];
static uint8_t link_bytes[2u * BSF_FRAME_MAX_SIZE];
static size_t link_len;
static unsigned n_received;
static bsf_result_t got;
static int got_pose;

void setUp(void)
{
}

void tearDown(void)
{
}

static int link_write(const uint8_t *data, size_t len)
{
    if (len > sizeof link_bytes - link_len) {
        return -1;
    }
    memcpy(link_bytes + link_len, data, len);
    link_len += len;
    return 0;
}

static void use_features(const bsf_result_t *result, const bsf_pose_t *pose)
{
    ++n_received;
    got = *result;
    got_pose = pose != NULL;
}

/* 61 beams over 60 degrees facing two walls (x = 1.5 m and y = 0.6 m) that
 * meet in a corner: a scan with features. */
static void extract_corner(void)
{
    const bsf_params_t p = bsf_params_default(BSF_METHOD_DEFAULT);
    bsf_scan_t scan;
    size_t i;
    memset(&scan, 0, sizeof scan);
    scan.ranges = ranges;
    scan.count = 61u;
    scan.angle_min = -0.5235988f;
    scan.angle_increment = 0.01745329f;
    scan.range_min = 0.05f;
    scan.range_max = 30.0f;
    for (i = 0; i < scan.count; ++i) {
        const float a = scan.angle_min + (float)i * scan.angle_increment;
        const float to_x = 1.5f / cosf(a);
        ranges[i] = a > 0.0f && 0.6f / sinf(a) < to_x ? 0.6f / sinf(a) : to_x;
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&ex, &scan, &sent));
    TEST_ASSERT_TRUE(sent.n_features > 0u);
}

static void test_stream_examples_carry_a_scan_across_the_link(void)
{
    size_t off;
    size_t i;
    extract_corner();
    bsf_decoder_init(&decoder);
    link_len = 0u;
    TEST_ASSERT_EQUAL_INT(0, send_scan(&sent, 7u, 1234u));
    TEST_ASSERT_TRUE(link_len > 0u);
    TEST_ASSERT_EQUAL_UINT8(0u, link_bytes[link_len - 1u]); /* the delimiter */
    for (off = 0; off < link_len; off += 5u) {
        on_bytes(link_bytes + off, link_len - off < 5u ? link_len - off : 5u);
    }
    TEST_ASSERT_EQUAL_UINT(1u, n_received);
    TEST_ASSERT_FALSE(got_pose);
    TEST_ASSERT_EQUAL_UINT32(7u, received.seq);
    TEST_ASSERT_EQUAL_UINT64(1234u, received.timestamp_ms);
    TEST_ASSERT_EQUAL_UINT16(sent.n_features, got.n_features);
    TEST_ASSERT_EQUAL_UINT16(sent.n_ctrl, got.n_ctrl);
    for (i = 0; i < sent.n_ctrl; ++i) { /* quantised: within half a step */
        TEST_ASSERT_FLOAT_WITHIN(0.5f * BSF_QUANT_STEP_DEFAULT + 1e-6f, sent.ctrl[i].x,
                                 got.ctrl[i].x);
        TEST_ASSERT_FLOAT_WITHIN(0.5f * BSF_QUANT_STEP_DEFAULT + 1e-6f, sent.ctrl[i].y,
                                 got.ctrl[i].y);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_stream_examples_carry_a_scan_across_the_link);
    return UNITY_END();
}
