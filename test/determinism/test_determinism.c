/* SPDX-License-Identifier: MIT */
/*
 * Host/target determinism: the frames the library makes for the demo
 * office's scans and for a sample of recorded Intel scans must be
 * byte-identical on the host and on every target (the Cortex-M4F, the
 * big-endian s390x), and decoding them must give the same values.
 * det_expected.h holds the host's results (generated at build time by
 * det_expect, compiled with the host compiler even in a cross build), so on
 * a target this compares the emulated target with the host, and on the host
 * it checks the reference is reproducible. Hashes take every float as its
 * bit pattern in little-endian order, so they mean the same on any target.
 *
 * Why identity holds: the library uses only + - * / sqrtf floorf fabsf
 * (correctly rounded everywhere) and its own sin/cos/exp/atan2/asin
 * (src/bsf_math.c), is compiled with -ffp-contract=off (no fused
 * multiply-add on either side), and evaluates float in float
 * (FLT_EVAL_METHOD 0: SSE on x86-64, the FPv4-SP unit on the M4F, s390x
 * with -fexcess-precision=fast; the library refuses to build otherwise).
 */
#include <float.h>
#include <string.h>

#include "det_core.h"
#include "det_expected.h"
#include "unity.h"

static float host_ranges[DET_SCANS * DET_BEAMS];

void setUp(void)
{
}

void tearDown(void)
{
}

static void test_float_arithmetic_is_evaluated_in_float(void)
{
    /* x87 or other excess precision would make host results differ */
    TEST_ASSERT_EQUAL_INT(0, FLT_EVAL_METHOD);
#if defined(__i386__) && !defined(__SSE2_MATH__)
    TEST_FAIL_MESSAGE("32-bit x86 without SSE2 math: x87 excess precision");
#endif
    {
        /* 1 + 2^-24 rounds to 1 in float; with excess precision it would not */
        volatile float one = 1.0f;
        volatile float tiny = 5.9604645e-8f;
        const float sum = one + tiny;
        TEST_ASSERT_TRUE(sum == 1.0f);
    }
}

static void test_simulated_scene_ranges_equal_the_host_bit_for_bit(void)
{
    det_summary_t s;
    TEST_ASSERT_EQUAL_INT(BSF_OK, det_run(NULL, &s, NULL, NULL));
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_RANGES_HASH, s.ranges_hash,
                                    "tools/bsf_scene (double) simulated different ranges");
}

static void test_frames_of_the_host_ranges_equal_the_host_byte_for_byte(void)
{
    det_summary_t s;
    memcpy(host_ranges, det_host_range_bits, sizeof host_ranges);
    TEST_ASSERT_EQUAL_INT(BSF_OK, det_run(host_ranges, &s, NULL, NULL));
    TEST_ASSERT_EQUAL_HEX32(DET_EXPECT_RANGES_HASH, s.ranges_hash);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_FEATURES, s.n_features);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_CTRL, s.n_ctrl);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_STREAM_BYTES, s.stream_bytes);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_STREAM_HASH, s.stream_hash,
                                    "frame bytes differ from the host's");
    TEST_ASSERT_EQUAL_UINT32(DET_SCANS * DET_METHODS, s.frames_decoded);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_DECODED_HASH, s.decoded_hash,
                                    "decoded values differ from the host's");
    TEST_ASSERT_TRUE(s.n_features > 0u);
}

static void test_frames_of_recorded_intel_scans_equal_the_host_byte_for_byte(void)
{
    det_summary_t s;
    if (DET_LOG_SCANS_USED == 0u) {
        TEST_IGNORE_MESSAGE("intel.log.gz was not found when the reference was made");
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK,
                          det_run_log(det_log_scans, DET_LOG_SCANS_USED, det_log_range_bits, &s));
    TEST_ASSERT_EQUAL_HEX32(DET_EXPECT_LOG_RANGES_HASH, s.ranges_hash);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_LOG_FEATURES, s.n_features);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_LOG_STREAM_BYTES, s.stream_bytes);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_LOG_STREAM_HASH, s.stream_hash,
                                    "frame bytes of the Intel scans differ from the host's");
    TEST_ASSERT_EQUAL_UINT32(DET_LOG_SCANS_USED * DET_METHODS, s.frames_decoded);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_LOG_DECODED_HASH, s.decoded_hash,
                                    "decoded Intel frames differ from the host's");
    TEST_ASSERT_TRUE(s.n_features > 0u);
}

/* The fused map's update frames, the alignments and the receiver's map, from
 * the host's demo ranges: byte for byte and bit for bit as on the host. */
static void test_map_stream_of_the_host_ranges_equals_the_host_byte_for_byte(void)
{
    det_map_summary_t m;
    memcpy(host_ranges, det_host_range_bits, sizeof host_ranges);
    TEST_ASSERT_EQUAL_INT(BSF_OK, det_run_map(host_ranges, &m));
    TEST_ASSERT_TRUE(m.frames > 0u && m.rx_points > 0u);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_MAP_FRAMES, m.frames);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_MAP_STREAM_BYTES, m.stream_bytes);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_MAP_STREAM_HASH, m.stream_hash,
                                    "map frame bytes differ from the host's");
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_MAP_ACCEPTED, m.n_accepted);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_MAP_ALIGN_HASH, m.align_hash,
                                    "aligned poses differ from the host's");
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_MAP_RX_POINTS, m.rx_points);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_MAP_RX_HASH, m.rx_hash,
                                    "the receiver's map differs from the host's");
}

static void test_map_stream_of_recorded_intel_scans_equals_the_host_byte_for_byte(void)
{
    det_map_summary_t m;
    if (DET_LOG_SCANS_USED == 0u) {
        TEST_IGNORE_MESSAGE("intel.log.gz was not found when the reference was made");
    }
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, det_run_map_log(det_log_scans, DET_LOG_SCANS_USED, det_log_range_bits, &m));
    TEST_ASSERT_TRUE(m.frames > 0u);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_LOG_MAP_FRAMES, m.frames);
    TEST_ASSERT_EQUAL_UINT32(DET_EXPECT_LOG_MAP_STREAM_BYTES, m.stream_bytes);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(DET_EXPECT_LOG_MAP_STREAM_HASH, m.stream_hash,
                                    "map frame bytes of the Intel scans differ from the host's");
    TEST_ASSERT_EQUAL_HEX32(DET_EXPECT_LOG_MAP_ALIGN_HASH, m.align_hash);
    TEST_ASSERT_EQUAL_HEX32(DET_EXPECT_LOG_MAP_RX_HASH, m.rx_hash);
}

static void test_hashes_do_not_depend_on_byte_order(void)
{
    /* FNV-1a of the bytes 00 00 80 3f (1.0f little-endian), whatever the
     * target's byte order: a native-order hash would differ on big-endian. */
    const float one = 1.0f;
    const uint8_t le_one[4] = {0x00u, 0x00u, 0x80u, 0x3fu};
    TEST_ASSERT_EQUAL_HEX32(det_fnv1a(DET_FNV_INIT, le_one, sizeof le_one),
                            det_hash_floats(DET_FNV_INIT, &one, 1u));
    TEST_ASSERT_EQUAL_HEX32(det_fnv1a(DET_FNV_INIT, le_one, sizeof le_one),
                            det_hash_u32(DET_FNV_INIT, 0x3f800000u));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_float_arithmetic_is_evaluated_in_float);
    RUN_TEST(test_simulated_scene_ranges_equal_the_host_bit_for_bit);
    RUN_TEST(test_hashes_do_not_depend_on_byte_order);
    RUN_TEST(test_frames_of_the_host_ranges_equal_the_host_byte_for_byte);
    RUN_TEST(test_frames_of_recorded_intel_scans_equal_the_host_byte_for_byte);
    RUN_TEST(test_map_stream_of_the_host_ranges_equals_the_host_byte_for_byte);
    RUN_TEST(test_map_stream_of_recorded_intel_scans_equals_the_host_byte_for_byte);
    return UNITY_END();
}
