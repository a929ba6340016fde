/* SPDX-License-Identifier: MIT */
/* Quadratic B-spline evaluation, the banded Cholesky solve and LSBA. */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_linalg.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

static const bsf_point_t ctrl6[6] = {{0.0f, 0.0f}, {1.0f, 2.0f}, {2.5f, -1.0f},
                                     {4.0f, 1.5f}, {5.0f, 0.5f}, {6.0f, 3.0f}};

static void test_basis_sums_to_one_and_derivatives_sum_to_zero_on_every_span_kind(void)
{
    const size_t counts[] = {3u, 4u, 7u};
    size_t c;
    for (c = 0; c < 3u; ++c) {
        const size_t n_ctrl = counts[c];
        size_t span;
        for (span = 0; span + 2u < n_ctrl; ++span) {
            float u;
            for (u = 0.0f; u <= 1.0f; u += 0.125f) {
                float b[3];
                float d1[3];
                float d2[3];
                bsf_bspline_basis(n_ctrl, span, u, b, d1, d2);
                TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.0f, b[0] + b[1] + b[2]);
                TEST_ASSERT_FLOAT_WITHIN(1e-4f, 0.0f, d1[0] + d1[1] + d1[2]);
                TEST_ASSERT_FLOAT_WITHIN(1e-3f, 0.0f, d2[0] + d2[1] + d2[2]);
                TEST_ASSERT_TRUE(b[0] >= 0.0f && b[1] >= 0.0f && b[2] >= 0.0f);
            }
        }
    }
}

static void test_clamped_curve_starts_and_ends_at_its_end_control_points(void)
{
    bsf_point_t p;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(ctrl6, 6u, 0.0f, &p, NULL, NULL));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.0f, p.x);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.0f, p.y);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(ctrl6, 6u, 1.0f, &p, NULL, NULL));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 6.0f, p.x);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.0f, p.y);
}

static void test_interior_knot_is_midpoint_of_adjacent_control_points(void)
{
    /* 6 control points, 4 spans: knot 2/4 is (P2 + P3) / 2. */
    bsf_point_t p;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(ctrl6, 6u, 0.5f, &p, NULL, NULL));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.25f, p.x);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.25f, p.y);
}

static void test_derivatives_match_finite_differences(void)
{
    const float h = 1e-3f;
    float t;
    for (t = 0.01f; t < 0.99f; t += 0.0625f) {
        bsf_point_t p;
        bsf_point_t d1;
        bsf_point_t d2;
        bsf_point_t pm;
        bsf_point_t pp;
        bsf_point_t d1m;
        bsf_point_t d1p;
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(ctrl6, 6u, t, &p, &d1, &d2));
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(ctrl6, 6u, t - h, &pm, &d1m, NULL));
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(ctrl6, 6u, t + h, &pp, &d1p, NULL));
        TEST_ASSERT_FLOAT_WITHIN(0.05f, (pp.x - pm.x) / (2.0f * h), d1.x);
        TEST_ASSERT_FLOAT_WITHIN(0.05f, (pp.y - pm.y) / (2.0f * h), d1.y);
        /* The second derivative is constant on a span; skip t near knots. */
        if (fabsf(t * 4.0f - floorf(t * 4.0f + 0.5f)) > 0.01f) {
            TEST_ASSERT_FLOAT_WITHIN(0.5f, (d1p.x - d1m.x) / (2.0f * h), d2.x);
            TEST_ASSERT_FLOAT_WITHIN(0.5f, (d1p.y - d1m.y) / (2.0f * h), d2.y);
        }
    }
}

static void test_single_span_is_the_bernstein_quadratic(void)
{
    const bsf_point_t c[3] = {{0.0f, 0.0f}, {1.0f, 2.0f}, {2.0f, 0.0f}};
    bsf_point_t p;
    bsf_point_t d2;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(c, 3u, 0.5f, &p, NULL, &d2));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.0f, p.x);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.0f, p.y);
    TEST_ASSERT_FLOAT_WITHIN(1e-5f, 0.0f, d2.x);
    TEST_ASSERT_FLOAT_WITHIN(1e-5f, -8.0f, d2.y);
}

static void test_doubled_control_point_is_passed_through_with_straight_neighbour_spans(void)
{
    /* P0, V, V, P3: two spans, vertex at t = 1/2, each span a segment. */
    const bsf_point_t c[4] = {{0.0f, 0.0f}, {2.0f, 1.0f}, {2.0f, 1.0f}, {3.0f, 4.0f}};
    bsf_point_t p;
    float t;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(c, 4u, 0.5f, &p, NULL, NULL));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 2.0f, p.x);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 1.0f, p.y);
    for (t = 0.0f; t <= 1.0f; t += 0.05f) {
        float cross;
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_bspline_eval(c, 4u, t, &p, NULL, NULL));
        if (t <= 0.5f) {
            cross = (p.x - 0.0f) * 1.0f - (p.y - 0.0f) * 2.0f;
        } else {
            cross = (p.x - 2.0f) * 3.0f - (p.y - 1.0f) * 1.0f;
        }
        TEST_ASSERT_FLOAT_WITHIN(1e-5f, 0.0f, cross);
    }
}

static void test_span_helper_clamps_parameter_and_maps_one_to_last_span(void)
{
    float u;
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bsf_bspline_span(6u, -0.5f, &u));
    TEST_ASSERT_EQUAL_FLOAT(0.0f, u);
    TEST_ASSERT_EQUAL_UINT32(3u, (uint32_t)bsf_bspline_span(6u, 1.0f, &u));
    TEST_ASSERT_EQUAL_FLOAT(1.0f, u);
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)bsf_bspline_span(6u, 0.625f, &u));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 0.5f, u);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bsf_bspline_span(6u, NAN, &u));
}

static void test_eval_refuses_bad_arguments_without_touching_output(void)
{
    bsf_point_t p = {7.0f, 7.0f};
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bspline_eval(NULL, 4u, 0.5f, &p, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bspline_eval(ctrl6, 6u, NAN, &p, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_bspline_eval(ctrl6, 6u, 0.5f, NULL, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, bsf_bspline_eval(ctrl6, 2u, 0.5f, &p, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_bspline_eval(ctrl6, BSF_MAX_CTRL_PER_FEATURE + 1u,
                                                             0.5f, &p, NULL, NULL));
    TEST_ASSERT_EQUAL_FLOAT(7.0f, p.x);
}

static void test_band_cholesky_solves_pentadiagonal_system_for_two_right_hand_sides(void)
{
    /* A = 6 on the diagonal, -2 on the first and 1 on the second off-diagonal. */
    enum { M = 9 };
    float band[M * 3];
    float factor[M * 3];
    float x_true[M];
    float y_true[M];
    float rx[M];
    float ry[M];
    size_t i;
    int loaded = -1;
    for (i = 0; i < M; ++i) {
        band[i * 3u] = 6.0f;
        band[i * 3u + 1u] = i >= 1u ? -2.0f : 0.0f;
        band[i * 3u + 2u] = i >= 2u ? 1.0f : 0.0f;
        x_true[i] = (float)i - 3.0f;
        y_true[i] = 0.5f * (float)(i * i);
    }
    for (i = 0; i < M; ++i) {
        size_t j;
        rx[i] = 0.0f;
        ry[i] = 0.0f;
        for (j = 0; j < M; ++j) {
            const size_t d = i > j ? i - j : j - i;
            const float a = d == 0u ? 6.0f : (d == 1u ? -2.0f : (d == 2u ? 1.0f : 0.0f));
            rx[i] += a * x_true[j];
            ry[i] += a * y_true[j];
        }
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_spd_band_solve2(band, M, 2u, factor, rx, ry, &loaded));
    TEST_ASSERT_EQUAL_INT(0, loaded);
    for (i = 0; i < M; ++i) {
        TEST_ASSERT_FLOAT_WITHIN(1e-4f, x_true[i], rx[i]);
        TEST_ASSERT_FLOAT_WITHIN(1e-3f, y_true[i], ry[i]);
    }
}

static void test_singular_matrix_is_solved_after_one_diagonal_loading_retry(void)
{
    /* Rank one: [[1,1],[1,1]] stored with bw 1. */
    const float band[4] = {1.0f, 0.0f, 1.0f, 1.0f};
    float factor[4];
    float rx[2] = {2.0f, 2.0f};
    float ry[2] = {0.0f, 0.0f};
    int loaded = -1;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_spd_band_solve2(band, 2u, 1u, factor, rx, ry, &loaded));
    TEST_ASSERT_EQUAL_INT(1, loaded);
    TEST_ASSERT_FLOAT_WITHIN(1e-3f, 2.0f, rx[0] + rx[1]);
    TEST_ASSERT_FALSE(isnan(rx[0]) || isnan(rx[1]));
}

static void test_indefinite_matrix_fails_with_numeric_status_and_untouched_rhs(void)
{
    const float band[4] = {1.0f, 0.0f, -4.0f, 0.0f};
    float factor[4];
    float rx[2] = {1.0f, 2.0f};
    float ry[2] = {3.0f, 4.0f};
    TEST_ASSERT_EQUAL_INT(BSF_ERR_NUMERIC, bsf_spd_band_solve2(band, 2u, 1u, factor, rx, ry, NULL));
    TEST_ASSERT_EQUAL_FLOAT(2.0f, rx[1]);
    TEST_ASSERT_EQUAL_FLOAT(4.0f, ry[1]);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_spd_band_solve2(band, 2u, 2u, factor, rx, ry, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_spd_band_solve2(band, BSF_LINALG_MAX_M + 1u, 1u,
                                                                factor, rx, ry, NULL));
}

static void test_lsba_reproduces_a_straight_wall_exactly(void)
{
    bsf_point_t pts[20];
    bsf_point_t ctrl[4];
    float e = -1.0f;
    size_t i;
    for (i = 0; i < 20u; ++i) {
        pts[i].x = 1.0f + 0.1f * (float)i;
        pts[i].y = 2.0f - 0.05f * (float)i;
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_lsba_fit(pts, 20u, ctrl, &e));
    TEST_ASSERT_FLOAT_WITHIN(1e-5f, 0.0f, e);
    TEST_ASSERT_FLOAT_WITHIN(1e-4f, 1.0f, ctrl[0].x);
    TEST_ASSERT_FLOAT_WITHIN(1e-4f, 2.0f, ctrl[0].y);
    TEST_ASSERT_FLOAT_WITHIN(1e-4f, 2.9f, ctrl[3].x);
    TEST_ASSERT_FLOAT_WITHIN(1e-4f, 1.05f, ctrl[3].y);
}

static void test_lsba_fits_a_quarter_circle_within_a_few_millimetres(void)
{
    bsf_point_t pts[30];
    bsf_point_t ctrl[4];
    float e = -1.0f;
    size_t i;
    for (i = 0; i < 30u; ++i) {
        const float a = 1.5707963f * (float)i / 29.0f;
        pts[i].x = 3.0f + cosf(a);
        pts[i].y = -1.0f + sinf(a);
    }
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_lsba_fit(pts, 30u, ctrl, &e));
    TEST_ASSERT_TRUE(e >= 0.0f);
    TEST_ASSERT_TRUE(e < 0.005f);
}

static void test_lsba_degenerate_inputs_give_a_status_and_no_output(void)
{
    bsf_point_t pts[6] = {{1.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 1.0f},
                          {1.0f, 1.0f}, {1.0f, 1.0f}, {1.0f, 1.0f}};
    bsf_point_t ctrl[4];
    float e = 5.0f;
    memset(ctrl, 0, sizeof ctrl);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, bsf_lsba_fit(pts, 6u, ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_DEGENERATE, bsf_lsba_fit(pts, 3u, ctrl, &e));
    pts[2].x = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_lsba_fit(pts, 6u, ctrl, &e));
    pts[2].x = 1e30f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_lsba_fit(pts, 6u, ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_lsba_fit(NULL, 6u, ctrl, &e));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_lsba_fit(pts, BSF_MAX_POINTS + 1u, ctrl, &e));
    TEST_ASSERT_EQUAL_FLOAT(5.0f, e);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, ctrl[0].x);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_basis_sums_to_one_and_derivatives_sum_to_zero_on_every_span_kind);
    RUN_TEST(test_clamped_curve_starts_and_ends_at_its_end_control_points);
    RUN_TEST(test_interior_knot_is_midpoint_of_adjacent_control_points);
    RUN_TEST(test_derivatives_match_finite_differences);
    RUN_TEST(test_single_span_is_the_bernstein_quadratic);
    RUN_TEST(test_doubled_control_point_is_passed_through_with_straight_neighbour_spans);
    RUN_TEST(test_span_helper_clamps_parameter_and_maps_one_to_last_span);
    RUN_TEST(test_eval_refuses_bad_arguments_without_touching_output);
    RUN_TEST(test_band_cholesky_solves_pentadiagonal_system_for_two_right_hand_sides);
    RUN_TEST(test_singular_matrix_is_solved_after_one_diagonal_loading_retry);
    RUN_TEST(test_indefinite_matrix_fails_with_numeric_status_and_untouched_rhs);
    RUN_TEST(test_lsba_reproduces_a_straight_wall_exactly);
    RUN_TEST(test_lsba_fits_a_quarter_circle_within_a_few_millimetres);
    RUN_TEST(test_lsba_degenerate_inputs_give_a_status_and_no_output);
    return UNITY_END();
}
