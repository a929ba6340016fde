/* SPDX-License-Identifier: MIT */
/*
 * Host/target determinism: the frames the library makes for the demo
 * office's scans must be byte-identical on the host and on the Cortex-M4F.
 * det_expected.h holds the host's results (generated at build time by
 * det_expect, compiled with the host compiler even in a cross build), so on
 * the target this compares the emulated Cortex-M4F with the host, and on the
 * host it checks the reference is reproducible.
 *
 * Why identity holds: the library uses only + - * / sqrtf floorf fabsf
 * (correctly rounded everywhere) and its own sin/cos/exp/atan2/asin
 * (src/bsf_math.c), is compiled with -ffp-contract=off (no fused
 * multiply-add on either side), and evaluates float in float
 * (FLT_EVAL_METHOD 0: SSE on x86-64, the FPv4-SP unit on the M4F).
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
    TEST_ASSERT_TRUE(s.n_features > 0u);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_float_arithmetic_is_evaluated_in_float);
    RUN_TEST(test_simulated_scene_ranges_equal_the_host_bit_for_bit);
    RUN_TEST(test_frames_of_the_host_ranges_equal_the_host_byte_for_byte);
    return UNITY_END();
}
