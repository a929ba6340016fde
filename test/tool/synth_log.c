/* SPDX-License-Identifier: MIT */
/*
 * Writes a small synthetic CARMEN log (ROBOTLASER1 lines, plus lines a reader
 * must skip) and prints the metrics the library itself computes on the same
 * scans, as key=value lines, so the tool test can check that
 * `bsf extract | bsf metrics` reproduces them from the stream alone.
 * Usage: synth_log OUT.log N_SCANS [clutter|walls]
 * With `clutter`, the scans are 1081-beam views of a room of zig-zag shelves
 * whose corners exceed the keypoint cap in some scans (docs/DESIGN.md, Cut policy), and the
 * cut scans are counted too (cut_scans=). With `walls`, the default scene's
 * surfaces follow as shape=segment,x0,y0,x1,y1 and shape=circle,cx,cy,r lines
 * (the map tests check the fused map against them).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"

static bsf_extractor_t ex;
static bsf_result_t res;
static float ranges[BSF_MAX_POINTS];
static float times[1000];

int main(int argc, char **argv)
{
    bsf_scene_t scene;
    bsf_scene_rng_t rng;
    bsf_params_t p;
    bsf_metrics_acc_t acc;
    bsf_metrics_summary_t s;
    FILE *f;
    int n, k;
    const int clutter = argc == 4 && strcmp(argv[3], "clutter") == 0;
    const int walls = argc == 4 && strcmp(argv[3], "walls") == 0;
    if ((argc != 3 && !clutter && !walls) || (n = atoi(argv[2])) < 1 || n > 1000) {
        fprintf(stderr, "usage: synth_log OUT.log N_SCANS(1..1000) [clutter|walls]\n");
        return 2;
    }
    /* What `bsf extract` uses by default; for the clutter log FALKO, which
     * the test runs with --method: its keypoints on the 14 cm shelf teeth
     * exceed the keypoint cap, LC's corners (sides of 15 cm or more) do not. */
    p = bsf_params_default(clutter ? BSF_METHOD_FALKO_SVED_PDM : BSF_METHOD_DEFAULT);
    f = fopen(argv[1], "w");
    if (f == NULL || bsf_extractor_init(&ex, &p) != BSF_OK ||
        bsf_metrics_acc_init(&acc, times, 1000u) != BSF_OK) {
        return 1;
    }
    bsf_scene_init(&scene);
    bsf_scene_rng_seed(&rng, 42u);
    if (clutter) {
        bsf_scene_clutter_t c;
        memset(&c, 0, sizeof c);
        c.half_w = 8.0;
        c.half_h = 4.0;
        c.n_teeth = 80u;
        c.tooth_depth = 0.1;
        c.n_posts = 20u;
        c.n_boxes = 5u;
        c.clear = 0.8;
        if (bsf_scene_add_clutter_room(&scene, &c, &rng) != BSF_OK) {
            return 1;
        }
    } else if (bsf_scene_add_l_room(&scene, 0.0, 0.0, 8.0, 6.0, 3.0, 2.5) != BSF_OK ||
               bsf_scene_add_circle(&scene, 2.5, 2.0, 0.4) < 0) {
        return 1;
    }
    fprintf(f,
            "# synthetic log written by synth_log\nPARAM robot_front_laser_max 50.0 nohost 0 0\n");
    for (k = 0; k < n; ++k) {
        const double x =
            clutter ? -1.0 + 2.0 * (double)k / (double)n : 1.0 + 3.0 * (double)k / (double)n;
        const double y = clutter ? 0.0 : 1.2;
        bsf_lidar_t l = clutter ? bsf_lidar_default(x, y, 0.3, 1081u, 4.71238898)
                                : bsf_lidar_default(x, y, 0.3, 181u, 3.14159265);
        bsf_scan_t sc;
        bsf_scan_counts_t c;
        size_t i;
        l.noise_sigma = 0.01;
        l.no_return = 81.83f;
        if (bsf_scene_scan(&scene, &l, &rng, ranges, NULL, BSF_MAX_POINTS) != BSF_OK) {
            return 1;
        }
        /* %.9g round-trips a float, so the tool reads exactly these values */
        fprintf(f, "ROBOTLASER1 0 %.9g %.9g %.9g 50.0 0.01 0 %u", (double)(float)l.angle_min,
                (double)(float)(l.angle_increment * 180.0), (double)(float)l.angle_increment,
                (unsigned)l.n_beams);
        for (i = 0; i < l.n_beams; ++i) {
            fprintf(f, " %.9g", (double)ranges[i]);
        }
        fprintf(f, " 0 %.6f %.6f 0.3 %.6f %.6f 0.3 0 0 0 0 0 %.3f nohost %.3f\n", x, y, x, y,
                1000.0 + 0.1 * k, 0.1 * k);
        fprintf(f, "ODOM %.6f %.6f 0.3 0 0 0 %.3f nohost %.3f\n", x, y, 1000.0 + 0.1 * k, 0.1 * k);
        sc.ranges = ranges;
        sc.count = l.n_beams;
        sc.angle_min = (float)l.angle_min;
        sc.angle_increment = (float)l.angle_increment;
        sc.range_min = 0.0f;
        sc.range_max = 50.0f;
        if (bsf_extract(&ex, &sc, &res) < 0) {
            return 1;
        }
        if (bsf_metrics_counts(&res, &c) != BSF_OK) {
            return 1;
        }
        if (bsf_metrics_acc_add(&acc, &c) != BSF_OK) {
            return 1;
        }
    }
    if (fclose(f) != 0 || bsf_metrics_acc_summary(&acc, &s) != BSF_OK) {
        return 1;
    }
    printf(
        "scans=%lu\nretrievability=%.6f\ncompactness=%.6f\naccuracy=%.7f\nfeatures_per_scan=%.4f\n"
        "ctrl_per_scan=%.4f\ncut_scans=%lu\ncut_keypoints=%lu\n"
        "caps=BSF_MAX_POINTS=%d,BSF_MAX_KEYPOINTS=%d,BSF_MAX_SEGMENTS=%d,BSF_MAX_CTRL_POINTS=%d\n",
        (unsigned long)s.n_scans, 100.0 * (double)s.retrievability, (double)s.compactness,
        (double)s.accuracy, (double)s.features_per_scan, (double)s.ctrl_per_scan,
        (unsigned long)s.n_cut_scans, (unsigned long)s.cut_keypoints, BSF_MAX_POINTS,
        BSF_MAX_KEYPOINTS, BSF_MAX_SEGMENTS, BSF_MAX_CTRL_POINTS);
    if (walls) {
        size_t i;
        for (i = 0; i < scene.n_shapes; ++i) {
            const bsf_shape_t *sh = &scene.shape[i];
            if (sh->kind == BSF_SHAPE_CIRCLE) {
                printf("shape=circle,%.6f,%.6f,%.6f\n", sh->x0, sh->y0, sh->r);
            } else {
                printf("shape=segment,%.6f,%.6f,%.6f,%.6f\n", sh->x0, sh->y0, sh->x1, sh->y1);
            }
        }
    }
    return 0;
}
