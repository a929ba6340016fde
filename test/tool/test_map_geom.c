/* SPDX-License-Identifier: MIT */
/*
 * test_map_geom - the map benchmark's measuring tools (tools/bench/map_geom.h):
 * curve sampling, nearest distances through the grid index against brute
 * force, histogram quantiles, and the occupancy-grid baseline (cells, PGM
 * gzip and PNG) on a square room. Host only (heap, zlib).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "map_geom.h"
#include "unity.h"

/* Unity's double assertions may be compiled out: compare in double here. */
#define ASSERT_NEAR(tol, expected, actual)                                                         \
    TEST_ASSERT_TRUE_MESSAGE(fabs((double)(expected) - (double)(actual)) <= (tol), #actual)

void setUp(void)
{
}
void tearDown(void)
{
}

static double brute_dist(const mg_curves_t *c, double x, double y)
{
    double best = 1e300;
    size_t i;
    for (i = 0; i < c->n_seg; ++i) {
        const float *s = &c->seg[4u * i];
        const double ax = (double)s[0], ay = (double)s[1];
        const double dx = (double)s[2] - ax, dy = (double)s[3] - ay;
        const double l2 = dx * dx + dy * dy;
        double t = l2 > 0.0 ? ((x - ax) * dx + (y - ay) * dy) / l2 : 0.0;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
        best = fmin(best, hypot(ax + t * dx - x, ay + t * dy - y));
    }
    return best < MG_DIST_MAX ? best : MG_DIST_MAX;
}

static void test_bspline_with_a_vertex_is_two_straight_spans(void)
{
    /* (0,0) -> corner (1,0) -> (1,1): the corner given twice */
    const double xy[8] = {0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 1.0};
    const uint8_t vtx[4] = {0u, 1u, 1u, 0u};
    mg_curves_t c;
    size_t i;
    mg_curves_init(&c);
    TEST_ASSERT_EQUAL_INT(0, mg_curves_add_bspline(&c, xy, 4u, vtx));
    TEST_ASSERT_EQUAL_UINT(1u, c.n_curves);
    TEST_ASSERT_EQUAL_UINT(2u * MG_SAMPLES_PER_SPAN, c.n_seg);
    ASSERT_NEAR(1e-9, 2.0, c.length);
    TEST_ASSERT_EQUAL_UINT(1u, c.n_vtx);
    ASSERT_NEAR(1e-12, 1.0, c.vtx[0]);
    ASSERT_NEAR(1e-12, 0.0, c.vtx[1]);
    for (i = 0; i < c.n_seg; ++i) { /* every sample on one of the two legs */
        const float *s = &c.seg[4u * i];
        TEST_ASSERT_TRUE(fabsf(s[1]) < 1e-6f || fabsf(s[0] - 1.0f) < 1e-6f);
    }
    TEST_ASSERT_EQUAL_INT(-1, mg_curves_add_bspline(&c, xy, 2u, NULL));
    mg_curves_free(&c);
}

static void test_folds_count_turning_back_not_bends_or_corners(void)
{
    /* a straight wall, a 10 cm round pillar (control points on a regular
     * octagon, run past a full turn), a curve that runs out and back along
     * itself (a cusp), and a 10 degree wedge whose corner is a vertex */
    const double wall[10] = {0.0, 0.0, 0.5, 0.01, 1.0, 0.0, 1.5, -0.01, 2.0, 0.0};
    const double cusp[6] = {0.0, 0.0, 1.0, 0.0, 0.0, 0.0};
    const double wedge[8] = {0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.176};
    const uint8_t wedge_vtx[4] = {0u, 1u, 1u, 0u};
    double pillar[2u * 11u];
    mg_folds_t f;
    size_t k;
    for (k = 0; k < 11u; ++k) {
        pillar[2u * k] = 0.1 * cos(0.785398 * (double)k);
        pillar[2u * k + 1u] = 0.1 * sin(0.785398 * (double)k);
    }
    memset(&f, 0, sizeof f);
    TEST_ASSERT_EQUAL_INT(0, mg_bspline_folds(wall, 5u, NULL, &f));
    TEST_ASSERT_EQUAL_INT(0, mg_bspline_folds(pillar, 11u, NULL, &f));
    TEST_ASSERT_EQUAL_UINT(0u, f.folds + f.sharp_vertices);
    TEST_ASSERT_EQUAL_INT(0, mg_bspline_folds(cusp, 3u, NULL, &f));
    TEST_ASSERT_EQUAL_UINT(1u, f.folds);
    memset(&f, 0, sizeof f);
    TEST_ASSERT_EQUAL_INT(0, mg_bspline_folds(wedge, 4u, wedge_vtx, &f));
    TEST_ASSERT_EQUAL_UINT(0u, f.folds); /* the corner is the vertex's, counted apart */
    TEST_ASSERT_EQUAL_UINT(1u, f.sharp_vertices);
    TEST_ASSERT_EQUAL_INT(-1, mg_bspline_folds(wall, 2u, NULL, &f));
}

static void test_index_distance_equals_brute_force(void)
{
    mg_curves_t c;
    mg_index_t ix;
    unsigned seed = 12345u;
    int k;
    mg_curves_init(&c);
    for (k = 0; k < 60; ++k) {
        double xy[4];
        int j;
        for (j = 0; j < 4; ++j) {
            seed = seed * 1103515245u + 12345u;
            xy[j] = (double)((seed >> 8) % 10000u) / 1000.0; /* 0 .. 10 m */
        }
        xy[2] = xy[0] + (xy[2] - xy[0]) * 0.05; /* short pieces, as sampled curves are */
        xy[3] = xy[1] + (xy[3] - xy[1]) * 0.05;
        TEST_ASSERT_EQUAL_INT(0, mg_curves_add_polyline(&c, xy, 2u));
    }
    TEST_ASSERT_EQUAL_INT(0, mg_index_build(&ix, &c));
    for (k = 0; k < 2000; ++k) {
        double x, y;
        seed = seed * 1103515245u + 12345u;
        x = -1.0 + (double)((seed >> 8) % 12000u) / 1000.0;
        seed = seed * 1103515245u + 12345u;
        y = -1.0 + (double)((seed >> 8) % 12000u) / 1000.0;
        ASSERT_NEAR(1e-9, brute_dist(&c, x, y), mg_index_dist(&ix, x, y));
    }
    mg_index_free(&ix);
    mg_curves_free(&c);
}

static void test_histogram_quantiles_and_share(void)
{
    static mg_hist_t h;
    int k;
    memset(&h, 0, sizeof h);
    for (k = 1; k <= 100; ++k) {
        mg_hist_add(&h, 0.001 * k); /* 1 .. 100 mm */
    }
    ASSERT_NEAR(0.0002, 0.050, mg_hist_quantile(&h, 0.5));
    ASSERT_NEAR(0.0002, 0.099, mg_hist_quantile(&h, 0.99));
    ASSERT_NEAR(1e-12, 0.1, h.max);
    ASSERT_NEAR(0.011, 0.5, mg_hist_share_below(&h, 0.05));
    mg_hist_add(&h, 7.0); /* beyond the extent: counted, quantile 1 is the max */
    ASSERT_NEAR(1e-12, 7.0, mg_hist_quantile(&h, 1.0));
}

/* A 4 m x 3 m room scanned from its middle: every wall cell is hit. */
static void test_grid_baseline_on_a_square_room(void)
{
    mg_points_t p;
    mg_grid_result_t g;
    int k;
    mg_points_init(&p);
    TEST_ASSERT_EQUAL_INT(0, mg_points_begin_scan(&p, 2.0, 1.5));
    for (k = 0; k < 3600; ++k) {
        const double a = 2.0 * 3.14159265358979 * k / 3600.0, c = cos(a), s = sin(a);
        const double tx = c > 0 ? 2.0 / c : (c < 0 ? -2.0 / c : 1e9);
        const double ty = s > 0 ? 1.5 / s : (s < 0 ? -1.5 / s : 1e9);
        const double t = fmin(tx, ty);
        TEST_ASSERT_EQUAL_INT(0, mg_points_add(&p, 2.0 + t * c * 0.999, 1.5 + t * s * 0.999));
    }
    TEST_ASSERT_EQUAL_INT(0, mg_grid_baseline(&p, 0.05, NULL, NULL, &g));
    /* the wall ring: about 2 * (80 + 60) cells of 5 cm */
    TEST_ASSERT_TRUE(g.occupied >= 250u && g.occupied <= 330u);
    /* the inside is free: about 80 x 60 cells */
    TEST_ASSERT_TRUE(g.free_cells >= 4000u && g.free_cells <= 4900u);
    {
        char hdr[64];
        const int hl = snprintf(hdr, sizeof hdr, "P5\n%lu %lu\n255\n", (unsigned long)g.nx,
                                (unsigned long)g.ny);
        TEST_ASSERT_EQUAL_UINT(g.nx * g.ny + (size_t)hl, g.pgm_bytes);
    }
    TEST_ASSERT_TRUE(g.pgm_gz_bytes > 20u && g.pgm_gz_bytes < g.pgm_bytes);
    TEST_ASSERT_TRUE(g.png_bytes > 57u && g.png_bytes < g.pgm_bytes);
    mg_points_free(&p);
}

static void test_gzip_size_round_trips(void)
{
    static uint8_t buf[10000];
    static uint8_t out[20000];
    uLongf n = sizeof out;
    size_t i;
    for (i = 0; i < sizeof buf; ++i) {
        buf[i] = (uint8_t)(i % 7u);
    }
    TEST_ASSERT_TRUE(mg_gzip_size(buf, sizeof buf) > 18u);
    TEST_ASSERT_TRUE(mg_gzip_size(buf, sizeof buf) < sizeof buf / 10u);
    /* the gzip framing is 18 bytes over the raw deflate that compress2 wraps in 6 */
    TEST_ASSERT_EQUAL_INT(Z_OK, compress2(out, &n, buf, sizeof buf, 9));
    TEST_ASSERT_EQUAL_UINT((size_t)n + 12u, mg_gzip_size(buf, sizeof buf));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_bspline_with_a_vertex_is_two_straight_spans);
    RUN_TEST(test_folds_count_turning_back_not_bends_or_corners);
    RUN_TEST(test_index_distance_equals_brute_force);
    RUN_TEST(test_histogram_quantiles_and_share);
    RUN_TEST(test_grid_baseline_on_a_square_room);
    RUN_TEST(test_gzip_size_round_trips);
    return UNITY_END();
}
