/* SPDX-License-Identifier: MIT */
/*
 * bench_clutter - how large the caps must be for cluttered scenes: extracts
 * synthetic clutter scans (bsf_scene_add_clutter_room) for 541- and
 * 1081-beam 270-degree and 3200-beam full-circle sensors with a library
 * built without practical caps (target bsf_uncapped), and prints, per sensor
 * and clutter level, the keypoints, kept segments and control points one
 * scan needs (median, p99, max). The README's memory section is made from
 * its output:  build/tools/bench_clutter [SCANS_PER_ROW]
 * (or one custom row: SCANS TEETH POSTS BOXES HALF_W HALF_H CLEAR NOISE)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"

#define MAX_SCANS 1000

static bsf_extractor_t g_ex;
static bsf_result_t g_res;
static bsf_scene_t g_scene;
static float g_ranges[BSF_MAX_POINTS];
static uint32_t g_need[3][MAX_SCANS];

typedef struct {
    const char *name;
    size_t beams;
    double fov;
} sensor_t;

typedef struct {
    const char *name;
    size_t n_teeth;
    size_t n_posts;
    size_t n_boxes;
    double half_w;
    double half_h;
    double clear;
    double noise;
} clutter_t;

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a;
    const uint32_t y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static uint32_t rank(const uint32_t *v, size_t n, double p)
{
    size_t r = (size_t)(p * (double)n + 0.999999);
    if (r < 1u) {
        r = 1u;
    }
    return v[(r > n ? n : r) - 1u];
}

int main(int argc, char **argv)
{
    const double pi = 3.14159265358979323846;
    const sensor_t sensors[] = {{"541/270", 541u, 1.5 * pi},
                                {"1081/270", 1081u, 1.5 * pi},
                                {"3200/360", 3200u, 2.0 * pi * 3199.0 / 3200.0}};
    /* office: a few chairs; cluttered: a furnished room; dense: a store room */
    /* 12 m x 8 m rooms: an office with a few chairs, a furnished room, a
     * store room, the furnished room seen by a 3 cm-noise sensor; then a
     * 30 m x 20 m hall full of posts (nothing within 2.5 m). */
    clutter_t levels[] = {{"office", 6u, 12u, 4u, 6.0, 4.0, 0.8, 0.01},
                          {"cluttered", 12u, 40u, 12u, 6.0, 4.0, 0.8, 0.01},
                          {"store", 20u, 80u, 30u, 6.0, 4.0, 0.8, 0.01},
                          {"clut-3cm", 12u, 40u, 12u, 6.0, 4.0, 0.8, 0.03},
                          {"hall", 10u, 300u, 10u, 15.0, 10.0, 2.5, 0.01}};
    const size_t n_levels = sizeof levels / sizeof levels[0];
    const bsf_params_t p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    const size_t n_scans = argc > 1 ? (size_t)strtoul(argv[1], NULL, 10) : 200u;
    size_t si;
    size_t li;
    size_t first_level = 0u;
    if (argc == 9) { /* SCANS TEETH POSTS BOXES HALF_W HALF_H CLEAR NOISE: one custom level */
        clutter_t *c = &levels[n_levels - 1u];
        c->name = "custom";
        c->n_teeth = (size_t)strtoul(argv[2], NULL, 10);
        c->n_posts = (size_t)strtoul(argv[3], NULL, 10);
        c->n_boxes = (size_t)strtoul(argv[4], NULL, 10);
        c->half_w = strtod(argv[5], NULL);
        c->half_h = strtod(argv[6], NULL);
        c->clear = strtod(argv[7], NULL);
        c->noise = strtod(argv[8], NULL);
        first_level = n_levels - 1u;
    } else if (argc > 2) {
        fprintf(stderr, "usage: bench_clutter [SCANS [TEETH POSTS BOXES HALF_W HALF_H CLEAR "
                        "NOISE]]\n");
        return 2;
    }
    if (n_scans < 1u || n_scans > MAX_SCANS) {
        fprintf(stderr, "bench_clutter: SCANS_PER_ROW must be 1..%d\n", MAX_SCANS);
        return 2;
    }
    if (bsf_extractor_init(&g_ex, &p) != BSF_OK) {
        return 1;
    }
    printf("caps: points %d, keypoints %d, segments %d, ctrl %d (uncapped build)\n", BSF_MAX_POINTS,
           BSF_MAX_KEYPOINTS, BSF_MAX_SEGMENTS, BSF_MAX_CTRL_POINTS);
    printf("%-9s %-9s | keypoints p50 p99 max | segments p50 p99 max | ctrl p50 p99 max\n",
           "sensor", "clutter");
    for (si = 0; si < sizeof sensors / sizeof sensors[0]; ++si) {
        for (li = first_level; li < n_levels; ++li) {
            size_t k;
            for (k = 0; k < n_scans; ++k) {
                bsf_scene_rng_t rng;
                bsf_scene_clutter_t c;
                bsf_lidar_t l;
                bsf_scan_t scan;
                bsf_status_t st;
                memset(&c, 0, sizeof c);
                c.half_w = levels[li].half_w;
                c.half_h = levels[li].half_h;
                c.n_teeth = levels[li].n_teeth;
                c.tooth_depth = 0.25;
                c.n_posts = levels[li].n_posts;
                c.n_boxes = levels[li].n_boxes;
                c.clear = levels[li].clear;
                bsf_scene_init(&g_scene);
                bsf_scene_rng_seed(&rng, 1000u * si + 100000u * li + k);
                if (bsf_scene_add_clutter_room(&g_scene, &c, &rng) != BSF_OK) {
                    fprintf(stderr, "bench_clutter: scene does not fit BSF_SCENE_MAX_SHAPES\n");
                    return 1;
                }
                l = bsf_lidar_default(0.0, 0.0, 2.0 * pi * bsf_scene_rng_uniform(&rng),
                                      sensors[si].beams, sensors[si].fov);
                l.noise_sigma = levels[li].noise;
                if (bsf_scene_scan(&g_scene, &l, &rng, g_ranges, NULL, BSF_MAX_POINTS) != BSF_OK) {
                    return 1;
                }
                scan = bsf_scene_lidar_scan(&l, g_ranges);
                st = bsf_extract(&g_ex, &scan, &g_res);
                if (st != BSF_OK) {
                    fprintf(stderr, "bench_clutter: %s (the uncapped build cut or failed)\n",
                            bsf_status_str(st));
                    return 1;
                }
                g_need[0][k] = g_res.stats.n_keypoints;
                g_need[1][k] = g_res.stats.n_features + g_res.stats.n_unfitted;
                g_need[2][k] = g_res.stats.n_ctrl;
            }
            printf("%-9s %-9s |", sensors[si].name, levels[li].name);
            for (k = 0; k < 3u; ++k) {
                qsort(g_need[k], n_scans, sizeof g_need[k][0], cmp_u32);
                printf("  %5u %5u %5u    |", (unsigned)rank(g_need[k], n_scans, 0.5),
                       (unsigned)rank(g_need[k], n_scans, 0.99), (unsigned)g_need[k][n_scans - 1u]);
            }
            printf("\n");
        }
    }
    return 0;
}
