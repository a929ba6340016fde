/* SPDX-License-Identifier: MIT */
/* Metrics: per-scan definitions, undefined cases, dataset means and quantiles. */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

static bsf_scan_counts_t counts(uint32_t n_valid, uint32_t in_feat, uint32_t ctrl, uint32_t feats,
                                float sum_e, float t)
{
    bsf_scan_counts_t c;
    memset(&c, 0, sizeof c);
    c.n_valid = n_valid;
    c.n_in_features = in_feat;
    c.n_ctrl = ctrl;
    c.n_features = feats;
    c.sum_e_curve = sum_e;
    c.time_s = t;
    return c;
}

static void test_scan_metrics_follow_the_paper_definitions(void)
{
    bsf_scan_metrics_t m;
    bsf_scan_counts_t c = counts(180u, 166u, 43u, 5u, 0.05f, 0.0019f);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_scan(&c, &m));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 166.0f / 180.0f, m.retrievability);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 43.0f / 166.0f, m.compactness);
    TEST_ASSERT_FLOAT_WITHIN(1e-7f, 0.01f, m.accuracy);
    TEST_ASSERT_FLOAT_WITHIN(1e-9f, 0.0019f, m.time_s);
    TEST_ASSERT_TRUE(m.has_retrievability && m.has_compactness && m.has_accuracy && m.has_time);
}

static void test_undefined_metrics_are_flagged_not_nan(void)
{
    bsf_scan_metrics_t m;
    bsf_scan_counts_t c = counts(0u, 0u, 0u, 0u, 0.0f, -1.0f);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_scan(&c, &m));
    TEST_ASSERT_FALSE(m.has_retrievability);
    TEST_ASSERT_FALSE(m.has_compactness);
    TEST_ASSERT_FALSE(m.has_accuracy);
    TEST_ASSERT_FALSE(m.has_time);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, m.compactness);
    c = counts(100u, 0u, 0u, 0u, 0.0f, 1e-5f);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_scan(&c, &m));
    TEST_ASSERT_TRUE(m.has_retrievability);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, m.retrievability);
    TEST_ASSERT_FALSE(m.has_compactness);
}

static void test_inconsistent_counts_are_refused(void)
{
    bsf_scan_metrics_t m;
    bsf_scan_counts_t c = counts(10u, 11u, 4u, 1u, 0.0f, 0.0f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    c = counts(10u, 5u, 4u, 1u, NAN, 0.0f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    c = counts(10u, 5u, 4u, 0u, 0.0f, 0.0f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, &m));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(NULL, &m));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&c, NULL));
}

static void test_dataset_means_skip_undefined_scans(void)
{
    bsf_metrics_acc_t acc;
    bsf_metrics_summary_t s;
    bsf_scan_counts_t a = counts(100u, 80u, 20u, 4u, 0.04f, 0.001f);
    bsf_scan_counts_t b = counts(100u, 60u, 12u, 2u, 0.02f, 0.003f);
    bsf_scan_counts_t empty = counts(50u, 0u, 0u, 0u, 0.0f, 0.002f);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, NULL, 0u));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &a));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &b));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &empty));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_summary(&acc, &s));
    TEST_ASSERT_EQUAL_UINT32(3u, s.n_scans);
    TEST_ASSERT_EQUAL_UINT32(3u, s.n_retrievability);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, (0.8f + 0.6f + 0.0f) / 3.0f, s.retrievability);
    TEST_ASSERT_EQUAL_UINT32(2u, s.n_compactness);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, (0.25f + 0.2f) / 2.0f, s.compactness);
    TEST_ASSERT_FLOAT_WITHIN(1e-7f, 0.01f, s.accuracy);
    TEST_ASSERT_FLOAT_WITHIN(1e-8f, 0.002f, s.time_mean_s);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 2.0f, s.features_per_scan);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, s.time_median_s);
}

static void test_time_quantiles_are_nearest_rank(void)
{
    static float samples[200];
    bsf_metrics_acc_t acc;
    bsf_metrics_summary_t s;
    uint32_t i;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, samples, 200u));
    for (i = 0; i < 200u; ++i) {
        /* 1..200 microseconds, added in a scrambled order */
        const uint32_t v = (i * 73u) % 200u + 1u;
        bsf_scan_counts_t c = counts(10u, 5u, 3u, 1u, 0.001f, (float)v * 1e-6f);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &c));
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_summary(&acc, &s));
    TEST_ASSERT_FLOAT_WITHIN(1e-9f, 100e-6f, s.time_median_s);
    TEST_ASSERT_FLOAT_WITHIN(1e-9f, 198e-6f, s.time_p99_s);
    TEST_ASSERT_FLOAT_WITHIN(1e-8f, 100.5e-6f, s.time_mean_s);
}

static void test_time_array_overflow_is_an_error_not_a_truncation(void)
{
    float samples[2];
    bsf_metrics_acc_t acc;
    bsf_scan_counts_t c = counts(10u, 5u, 3u, 1u, 0.001f, 1e-5f);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, samples, 2u));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &c));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &c));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_metrics_acc_add(&acc, &c));
    TEST_ASSERT_EQUAL_UINT32(2u, acc.n_scans);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_acc_init(&acc, NULL, 3u));
}

static void test_counts_of_a_result_sum_its_features(void)
{
    static bsf_result_t r;
    bsf_scan_counts_t c;
    memset(&r, 0, sizeof r);
    r.n_features = 2u;
    r.features[0].n_points = 30u;
    r.features[0].n_ctrl = 5u;
    r.features[0].e_curve = 0.01f;
    r.features[1].n_points = 12u;
    r.features[1].n_ctrl = 3u;
    r.features[1].e_curve = 0.02f;
    r.stats.n_valid = 50u;
    r.stats.time_ns = 12000u;
    r.stats.cut = BSF_CUT_SEGMENTS;
    r.stats.n_cut_segments = 2u;
    r.stats.n_cut_points = 7u;
    r.stats.n_cut_keypoints = 1u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_counts(&r, &c));
    TEST_ASSERT_EQUAL_UINT32(BSF_CUT_SEGMENTS, c.cut);
    TEST_ASSERT_EQUAL_UINT32(2u, c.n_cut_segments);
    TEST_ASSERT_EQUAL_UINT32(7u, c.n_cut_points);
    TEST_ASSERT_EQUAL_UINT32(1u, c.n_cut_keypoints);
    TEST_ASSERT_EQUAL_UINT32(50u, c.n_valid);
    TEST_ASSERT_EQUAL_UINT32(42u, c.n_in_features);
    TEST_ASSERT_EQUAL_UINT32(8u, c.n_ctrl);
    TEST_ASSERT_EQUAL_UINT32(2u, c.n_features);
    TEST_ASSERT_FLOAT_WITHIN(1e-7f, 0.03f, c.sum_e_curve);
    TEST_ASSERT_FLOAT_WITHIN(1e-10f, 12e-6f, c.time_s);
    r.stats.time_ns = 0u; /* no clock: time not measured */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_counts(&r, &c));
    TEST_ASSERT_TRUE(c.time_s < 0.0f);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_counts(NULL, &c));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_counts(&r, NULL));
}

/* Sums once kept in 32 bits wrapped (ctrl_per_scan 34.8 instead of 512
 * after 9 M full scans). The accumulator is brought to 8 388 607 full scans
 * (512 control points each: 2^32 - 512 in total, the last value a 32-bit sum
 * holds) as 9 M adds would leave it, then more full scans are added. */
static void test_long_runs_do_not_wrap_the_sums(void)
{
    bsf_metrics_acc_t acc;
    bsf_metrics_summary_t s;
    const uint32_t full_scans = 8388607u;
    bsf_scan_counts_t c = counts(1081u, 1000u, 512u, 128u, 1.28f, -1.0f);
    uint32_t i;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, NULL, 0u));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &c));
    acc.n_scans = full_scans;
    acc.sum_ctrl *= full_scans;
    acc.sum_features *= full_scans;
    acc.sum_points *= full_scans;
    acc.sum_valid *= full_scans;
    for (i = 0; i < 611393u; ++i) { /* to 9 M scans */
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &c));
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_summary(&acc, &s));
    TEST_ASSERT_EQUAL_UINT32(9000000u, s.n_scans);
    TEST_ASSERT_FLOAT_WITHIN(0.01f, 512.0f, s.ctrl_per_scan);
    TEST_ASSERT_FLOAT_WITHIN(0.01f, 128.0f, s.features_per_scan);
    TEST_ASSERT_TRUE(acc.sum_valid == (uint64_t)1081u * 9000000u);
    TEST_ASSERT_TRUE(acc.sum_points == (uint64_t)1000u * 9000000u);
}

/* Two scans whose counts add up past 2^32 each: every sum holds them. */
static void test_sums_hold_more_than_32_bits(void)
{
    bsf_metrics_acc_t acc;
    bsf_scan_counts_t c = counts(3000000000u, 2500000000u, 3500000000u, 4000000000u, 0.0f, -1.0f);
    c.cut = BSF_CUT_SEGMENTS;
    c.n_cut_segments = 3000000000u;
    c.n_cut_points = 500000000u;
    c.n_cut_keypoints = 2200000000u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, NULL, 0u));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &c));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &c));
    TEST_ASSERT_TRUE(acc.sum_valid == 6000000000ull);
    TEST_ASSERT_TRUE(acc.sum_points == 5000000000ull);
    TEST_ASSERT_TRUE(acc.sum_ctrl == 7000000000ull);
    TEST_ASSERT_TRUE(acc.sum_features == 8000000000ull);
    TEST_ASSERT_TRUE(acc.sum_cut_segments == 6000000000ull);
    TEST_ASSERT_TRUE(acc.sum_cut_points == 1000000000ull);
    TEST_ASSERT_TRUE(acc.sum_cut_keypoints == 4400000000ull);
}

/* Cut scans are totalled; their cut points are wasted in Gamma, and counts
 * that claim more cut points than N has outside features are refused. */
static void test_cut_scans_are_totalled_and_their_points_wasted(void)
{
    bsf_metrics_acc_t acc;
    bsf_metrics_summary_t s;
    bsf_scan_metrics_t m;
    bsf_scan_counts_t whole = counts(100u, 90u, 20u, 4u, 0.04f, -1.0f);
    bsf_scan_counts_t cut = counts(100u, 60u, 12u, 2u, 0.02f, -1.0f);
    cut.cut = BSF_CUT_CTRL | BSF_CUT_KEYPOINTS;
    cut.n_cut_segments = 3u;
    cut.n_cut_points = 30u;
    cut.n_cut_keypoints = 5u;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_scan(&cut, &m));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.6f, m.retrievability);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, NULL, 0u));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &whole));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &cut));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &cut));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_summary(&acc, &s));
    TEST_ASSERT_EQUAL_UINT32(3u, s.n_scans);
    TEST_ASSERT_EQUAL_UINT32(2u, s.n_cut_scans);
    TEST_ASSERT_TRUE(s.cut_segments == 6u);
    TEST_ASSERT_TRUE(s.cut_points == 60u);
    TEST_ASSERT_TRUE(s.cut_keypoints == 10u);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, (0.9f + 0.6f + 0.6f) / 3.0f, s.retrievability);
    cut.n_cut_points = 41u; /* 60 in features + 41 cut > 100 valid */
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_metrics_scan(&cut, &m));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_scan_metrics_follow_the_paper_definitions);
    RUN_TEST(test_undefined_metrics_are_flagged_not_nan);
    RUN_TEST(test_inconsistent_counts_are_refused);
    RUN_TEST(test_dataset_means_skip_undefined_scans);
    RUN_TEST(test_time_quantiles_are_nearest_rank);
    RUN_TEST(test_time_array_overflow_is_an_error_not_a_truncation);
    RUN_TEST(test_counts_of_a_result_sum_its_features);
    RUN_TEST(test_long_runs_do_not_wrap_the_sums);
    RUN_TEST(test_sums_hold_more_than_32_bits);
    RUN_TEST(test_cut_scans_are_totalled_and_their_points_wasted);
    return UNITY_END();
}
