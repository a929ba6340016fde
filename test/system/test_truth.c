/* SPDX-License-Identifier: MIT */
/*
 * Ground truth on the demo office (bsf_scene_demo_office, the size of a real
 * office: 14 m x 10 m, corners up to 8 m away) with the default method:
 * corner recall by range, vertex precision and position error, and the
 * largest distance of any curve from the true walls. The bounds are the
 * ground-truth targets (docs/GROUND_TRUTH.md, which has the full benchmark,
 * bench_truth); the FALKO-SVED-PDM of before (FALKOLib's corners, free
 * vertices) fails every one of them (recall 2-12 %, vertex error median
 * 5 cm, curves up to 20 cm off the walls), so each test would catch a return
 * to it.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "bsf_truth.h"
#include "unity.h"

#define PI 3.14159265358979323846
#define N_POSES 40

static bsf_extractor_t ex;
static bsf_result_t res;
static float clean[BSF_MAX_POINTS];
static float ranges[BSF_MAX_POINTS];
static int16_t hits[BSF_MAX_POINTS];
static bsf_truth_acc_t acc;

void setUp(void)
{
}

void tearDown(void)
{
}

/* The demo office seen by a sensor of n_beams over fov (radians) with range
 * noise sigma, along the demo's loop; the default method. */
static void run_office(size_t n_beams, double fov, double sigma, bsf_truth_summary_t *s)
{
    static bsf_scene_t sc;
    bsf_scene_rng_t rng;
    const bsf_params_t p = bsf_params_default(BSF_METHOD_DEFAULT);
    long k;
    bsf_scene_demo_office(&sc);
    bsf_scene_rng_seed(&rng, 14u);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    bsf_truth_acc_init(&acc);
    for (k = 0; k < N_POSES; ++k) {
        double x, y, th;
        bsf_lidar_t lid;
        bsf_scan_t scan;
        size_t i;
        bsf_scene_demo_pose(k, N_POSES, &x, &y, &th);
        lid = bsf_lidar_default(x, y, th, n_beams, fov);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&sc, &lid, NULL, clean, hits, BSF_MAX_POINTS));
        for (i = 0; i < n_beams; ++i) {
            ranges[i] = clean[i];
            if (hits[i] >= 0) {
                ranges[i] = (float)((double)clean[i] + sigma * bsf_scene_rng_gauss(&rng));
            }
        }
        scan = bsf_scene_lidar_scan(&lid, ranges);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&ex, &scan, &res));
        TEST_ASSERT_EQUAL_INT(0, bsf_truth_add(&acc, &sc, &lid, clean, hits, &res, 0u, 0.0));
    }
    bsf_truth_summary(&acc, s);
}

static void print_summary(const char *what, const bsf_truth_summary_t *s)
{
    printf("%s: %lu visible corners, recall %.3f (<3 m %.3f, 3-6 m %.3f, 6-8 m %.3f), precision "
           "%.3f, vertex error median %.4f p90 %.4f m, curve p99 %.4f max %.4f m\n",
           what, (unsigned long)s->visible, s->recall, s->recall_band[0], s->recall_band[1],
           s->recall_band[2], s->precision, s->verr_median, s->verr_p90, s->curve_p99,
           s->curve_max);
}

static void test_office_361_beams_finds_corners_at_every_range(void)
{
    bsf_truth_summary_t s;
    int b;
    run_office(361u, 1.5 * PI, 0.01, &s);
    print_summary("office 361/0.75/270 sigma 1 cm", &s);
    TEST_ASSERT_TRUE(s.visible >= 30u);
    for (b = 0; b < BSF_TRUTH_BANDS; ++b) {
        TEST_ASSERT_TRUE_MESSAGE(acc.visible[b] > 0u, "no visible corner in a range band");
        TEST_ASSERT_TRUE_MESSAGE(s.recall_band[b] >= 0.90,
                                 "corner recall below 90 % in a range band");
    }
    TEST_ASSERT_TRUE_MESSAGE(s.precision >= 0.95, "vertex precision below 95 %");
    /* A corner whose side the split of its run cut to three points was lost
     * (LC judged that side curved: a circle fits any three points), and PDM
     * rounded it: recall 98.0 %, curve p99 3.5 cm before. */
    TEST_ASSERT_TRUE_MESSAGE(s.recall >= 0.99, "corner recall below 99 %");
    TEST_ASSERT_TRUE_MESSAGE(s.curve_p99 <= 0.03, "curve-to-wall p99 above 3 cm");
}

static void test_office_181_beams_finds_most_corners(void)
{
    bsf_truth_summary_t s;
    run_office(181u, PI, 0.01, &s);
    print_summary("office 181/1.0/180 sigma 1 cm", &s);
    TEST_ASSERT_TRUE(s.visible >= 15u);
    TEST_ASSERT_TRUE_MESSAGE(s.recall >= 0.70, "corner recall below 70 % at 1 degree beams");
    TEST_ASSERT_TRUE_MESSAGE(s.precision >= 0.95, "vertex precision below 95 %");
}

static void test_office_vertices_sit_on_the_corners(void)
{
    bsf_truth_summary_t s;
    /* 541 beams: the code before LC finds some corners there (12 %), and
     * puts them 5.1 cm (median) and 6.3 cm (p90) off. */
    run_office(541u, 1.5 * PI, 0.01, &s);
    TEST_ASSERT_TRUE(acc.vertex_err.n >= 5u);
    TEST_ASSERT_TRUE_MESSAGE(s.verr_median <= 0.01, "vertex error median above 1 cm");
    TEST_ASSERT_TRUE_MESSAGE(s.verr_p90 <= 0.03, "vertex error p90 above 3 cm");
}

static void test_office_curves_never_stray_far_from_the_walls(void)
{
    bsf_truth_summary_t s;
    run_office(541u, 1.5 * PI, 0.01, &s);
    print_summary("office 541/0.5/270 sigma 1 cm", &s);
    TEST_ASSERT_TRUE(acc.curve.n > 1000u);
    /* The targets (the code before LC: p99 7.1 cm, max 20 cm). */
    TEST_ASSERT_TRUE_MESSAGE(s.curve_p99 <= 0.03, "curve-to-wall p99 above 3 cm");
    TEST_ASSERT_TRUE_MESSAGE(s.curve_max <= 0.08, "a curve strays more than 8 cm from the walls");
}

/* The oracle (bsf_truth_oracle_vertex): two total-least-squares lines
 * through the returns that truly lie on each wall. On a noiseless scan those
 * returns lie exactly on the walls, so the lines are the walls and the
 * oracle's vertex is the corner itself: any return of another surface, a
 * wrong fit or a wrong intersection would put it off. */
static void test_oracle_is_exact_without_noise(void)
{
    static bsf_scene_t sc;
    const bsf_params_t p = bsf_params_default(BSF_METHOD_DEFAULT);
    long k;
    bsf_scene_demo_office(&sc);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    bsf_truth_acc_init(&acc);
    for (k = 0; k < N_POSES; ++k) {
        double x, y, th;
        bsf_lidar_t lid;
        bsf_scan_t scan;
        bsf_scene_demo_pose(k, N_POSES, &x, &y, &th);
        lid = bsf_lidar_default(x, y, th, 361u, 1.5 * PI);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&sc, &lid, NULL, clean, hits, BSF_MAX_POINTS));
        scan = bsf_scene_lidar_scan(&lid, clean);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&ex, &scan, &res));
        TEST_ASSERT_EQUAL_INT(0, bsf_truth_add_oracle(&acc, &sc, &lid, clean, hits, clean, &res));
    }
    printf("oracle without noise: %lu corners, largest error %.2e m, %lu undefined\n",
           (unsigned long)acc.oracle_err_all.n, acc.oracle_err_all.max,
           (unsigned long)acc.oracle_undefined);
    TEST_ASSERT_TRUE(acc.oracle_err_all.n >= 20u);
    TEST_ASSERT_TRUE(acc.oracle_err_found.n >= 10u);
    TEST_ASSERT_TRUE(acc.oracle_err_found.n <= acc.oracle_err_all.n);
    TEST_ASSERT_TRUE_MESSAGE(acc.oracle_err_all.max <= 1e-5, "oracle off a corner without noise");
}

/* A corner of the noisy office whose walls have at least four returns each
 * (whole runs); fills *cn and the oracle's vertex. */
static int noisy_corner(const bsf_scene_t *sc, const bsf_lidar_t *lid, bsf_scene_corner_t *cn,
                        double *ox, double *oy)
{
    static bsf_scene_corner_t corners[256];
    size_t n = 0;
    size_t k;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(sc, lid, corners, 256u, &n));
    for (k = 0; k < n; ++k) {
        int n_side[2];
        if (corners[k].visible && corners[k].range <= 6.0 &&
            bsf_truth_oracle_vertex(&corners[k], lid, clean, hits, ranges, 0.0, ox, oy, n_side,
                                    NULL) == 0 &&
            n_side[0] >= 4 && n_side[1] >= 4) {
            *cn = corners[k];
            return 1;
        }
    }
    return 0;
}

/* The oracle takes the returns of the corner's two walls and no other, leaves
 * out a beam marked as a mixed pixel, and reaches as far as it is told. */
static void test_oracle_takes_only_its_walls_returns(void)
{
    static bsf_scene_t sc;
    static float unmixed[BSF_MAX_POINTS];
    static int16_t on_shape[BSF_MAX_POINTS];
    bsf_scene_rng_t rng;
    bsf_scene_corner_t cn;
    bsf_lidar_t lid;
    double x, y, th, ox, oy, qx, qy, o0;
    int n_whole[2], n_near[2];
    double len_whole[2], len_near[2];
    size_t i;
    size_t near_beam = 0;
    size_t other_beam = 0;
    double dmin = 1e300;
    bsf_scene_demo_office(&sc);
    bsf_scene_rng_seed(&rng, 5u);
    bsf_scene_demo_pose(3, 10, &x, &y, &th);
    lid = bsf_lidar_default(x, y, th, 361u, 1.5 * PI);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&sc, &lid, NULL, clean, hits, BSF_MAX_POINTS));
    for (i = 0; i < 361u; ++i) {
        ranges[i] = clean[i];
        if (hits[i] >= 0) {
            ranges[i] = (float)((double)clean[i] + 0.01 * bsf_scene_rng_gauss(&rng));
        }
    }
    TEST_ASSERT_TRUE(noisy_corner(&sc, &lid, &cn, &ox, &oy));
    o0 = hypot(ox - cn.x, oy - cn.y);
    printf("oracle at 1 cm noise: %.4f m off the corner at range %.2f m\n", o0, cn.range);
    /* noise moves it, but by millimetres */
    TEST_ASSERT_TRUE(o0 > 1e-5 && o0 < 0.02);
    /* the return on the first wall nearest the corner; a beam on neither wall */
    for (i = 0; i < 361u; ++i) {
        const double a = lid.angle_min + (double)i * lid.angle_increment;
        const double d = hypot((double)clean[i] * cos(a) - cn.x, (double)clean[i] * sin(a) - cn.y);
        if (hits[i] == cn.shape_a && d < dmin) {
            dmin = d;
            near_beam = i;
        }
        if (hits[i] >= 0 && hits[i] != cn.shape_a && hits[i] != cn.shape_b) {
            other_beam = i;
        }
    }
    TEST_ASSERT_TRUE(hits[other_beam] >= 0);
    /* another surface's return does not count */
    ranges[other_beam] += 0.5f;
    TEST_ASSERT_EQUAL_INT(
        0, bsf_truth_oracle_vertex(&cn, &lid, clean, hits, ranges, 0.0, &qx, &qy, NULL, NULL));
    TEST_ASSERT_TRUE(qx == ox && qy == oy);
    /* the wall's own return does */
    memcpy(unmixed, ranges, sizeof ranges);
    ranges[near_beam] += 0.5f;
    TEST_ASSERT_EQUAL_INT(
        0, bsf_truth_oracle_vertex(&cn, &lid, clean, hits, ranges, 0.0, &qx, &qy, NULL, NULL));
    TEST_ASSERT_TRUE(hypot(qx - cn.x, qy - cn.y) > o0 + 0.02);
    /* unless it is labelled a mixed pixel (its range not what the wall gave) */
    TEST_ASSERT_EQUAL_INT(
        1, (int)bsf_truth_returns_on_shapes(on_shape, hits, clean, ranges, unmixed, 361u, 0.03));
    TEST_ASSERT_EQUAL_INT(-1, on_shape[near_beam]);
    TEST_ASSERT_EQUAL_INT(
        0, bsf_truth_oracle_vertex(&cn, &lid, clean, on_shape, ranges, 0.0, &qx, &qy, NULL, NULL));
    TEST_ASSERT_TRUE(hypot(qx - cn.x, qy - cn.y) < 0.02);
    /* reach: returns within 0.6 m of the corner only */
    memcpy(ranges, unmixed, sizeof ranges);
    TEST_ASSERT_EQUAL_INT(0, bsf_truth_oracle_vertex(&cn, &lid, clean, hits, ranges, 0.0, &qx, &qy,
                                                     n_whole, len_whole));
    TEST_ASSERT_EQUAL_INT(0, bsf_truth_oracle_vertex(&cn, &lid, clean, hits, ranges, 0.6, &qx, &qy,
                                                     n_near, len_near));
    for (i = 0; i < 2u; ++i) {
        TEST_ASSERT_TRUE(len_near[i] <= 0.6);
        TEST_ASSERT_TRUE(n_near[i] <= n_whole[i]);
        TEST_ASSERT_TRUE(len_near[i] <= len_whole[i]);
    }
    TEST_ASSERT_TRUE(n_near[0] < n_whole[0] || n_near[1] < n_whole[1]);
}

/* A blend between two surfaces is no return on a wall: a corner whose wall
 * keeps a single return after mixing is visible under neither rule, and a
 * blend inside the wall's run breaks the run of consecutive returns; a
 * changed range within the tolerance of its own wall is still a return
 * there. */
static void test_a_mixed_pixel_is_no_hit_for_visibility(void)
{
    static bsf_scene_t sc;
    static bsf_scene_corner_t corners[256];
    static int16_t on_shape[BSF_MAX_POINTS];
    bsf_lidar_t lid;
    double x, y, th;
    size_t n = 0;
    size_t k;
    size_t i;
    size_t start = 0;
    size_t next = 0;
    size_t on_wall = 0;
    double dmin = 1e300;
    const bsf_scene_corner_t *cn = NULL;
    bsf_scene_demo_office(&sc);
    bsf_scene_demo_pose(3, 10, &x, &y, &th);
    lid = bsf_lidar_default(x, y, th, 361u, 1.5 * PI);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&sc, &lid, NULL, clean, hits, BSF_MAX_POINTS));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(&sc, &lid, corners, 256u, &n));
    for (k = 0; k < n && cn == NULL; ++k) {
        if (bsf_truth_corner_seen(&corners[k], &lid, clean, hits) &&
            bsf_truth_corner_seen_sparse(&corners[k], &lid, clean, hits)) {
            cn = &corners[k];
        }
    }
    TEST_ASSERT_NOT_NULL(cn);
    /* the wall's return nearest the vertex, and the next one along the wall */
    for (i = 0; i < 361u; ++i) {
        const double a = lid.angle_min + (double)i * lid.angle_increment;
        const double d =
            hypot((double)clean[i] * cos(a) - cn->x, (double)clean[i] * sin(a) - cn->y);
        if (hits[i] == cn->shape_a) {
            ++on_wall;
            if (d < dmin) {
                dmin = d;
                start = i;
            }
        }
    }
    TEST_ASSERT_TRUE(on_wall >= 4u);
    next = start > 0u && hits[start - 1u] == cn->shape_a ? start - 1u : start + 1u;
    TEST_ASSERT_EQUAL_INT(cn->shape_a, hits[next]);
    /* every return of the wall but the nearest blended with a nearer surface */
    memcpy(ranges, clean, sizeof ranges);
    for (i = 0; i < 361u; ++i) {
        if (hits[i] == cn->shape_a && i != start) {
            ranges[i] = clean[i] - 0.4f;
        }
    }
    TEST_ASSERT_EQUAL_INT((int)on_wall - 1, (int)bsf_truth_returns_on_shapes(
                                                on_shape, hits, clean, ranges, clean, 361u, 0.03));
    TEST_ASSERT_FALSE(bsf_truth_corner_seen(cn, &lid, clean, on_shape));
    TEST_ASSERT_FALSE(bsf_truth_corner_seen_sparse(cn, &lid, clean, on_shape));
    /* one blend, next to the nearest return: the run of consecutive returns ends */
    memcpy(ranges, clean, sizeof ranges);
    ranges[next] = clean[next] - 0.4f;
    TEST_ASSERT_EQUAL_INT(
        1, (int)bsf_truth_returns_on_shapes(on_shape, hits, clean, ranges, clean, 361u, 0.03));
    TEST_ASSERT_FALSE(bsf_truth_corner_seen_sparse(cn, &lid, clean, on_shape));
    /* a changed range within the tolerance of its wall is a return on it */
    ranges[next] = clean[next] - 0.02f;
    TEST_ASSERT_EQUAL_INT(
        0, (int)bsf_truth_returns_on_shapes(on_shape, hits, clean, ranges, clean, 361u, 0.03));
    TEST_ASSERT_TRUE(bsf_truth_corner_seen(cn, &lid, clean, on_shape));
    TEST_ASSERT_TRUE(bsf_truth_corner_seen_sparse(cn, &lid, clean, on_shape));
}

int main(void)
{
    bsf_truth_verbose = getenv("TRUTH_VERBOSE") != NULL;
    UNITY_BEGIN();
    RUN_TEST(test_office_361_beams_finds_corners_at_every_range);
    RUN_TEST(test_office_181_beams_finds_most_corners);
    RUN_TEST(test_office_vertices_sit_on_the_corners);
    RUN_TEST(test_office_curves_never_stray_far_from_the_walls);
    RUN_TEST(test_oracle_is_exact_without_noise);
    RUN_TEST(test_oracle_takes_only_its_walls_returns);
    RUN_TEST(test_a_mixed_pixel_is_no_hit_for_visibility);
    return UNITY_END();
}
