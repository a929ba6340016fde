/* SPDX-License-Identifier: MIT */
/*
 * bench_segment - time SVED, RPOS and classification, and report how many
 * points they keep, on a CARMEN log and on a synthetic 180-beam scene.
 *
 *   bench_segment [log] [passes] [range_max]
 *
 * Defaults: ../shared/data/intel.log.gz (BSF_SHARED_DIR overrides the shared
 * directory), 50 passes, range_max 81.0 m (below the 81.83 no-return code).
 * Points and FALKO keypoints (the interest points for classification) are
 * computed once, outside the timing. Each scan is processed `passes` times
 * in a row (hot cache, as in the pipeline right after bsf_scan_to_points);
 * the whole run is timed with CLOCK_MONOTONIC and reported as ns per scan,
 * so the clock's own cost does not count; the fastest of BENCH_REPEATS
 * runs is reported (other load on the machine only adds time). Kept share = points in kept segments
 * / N (the segmentation's bound on the paper's retrievability). Run it on one core, e.g. taskset -c
 * 1 ./build/tools/bench_segment.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bsf/bsf.h"
#include "bsf/bsf_falko.h"
#include "bsf_scene.h"
#include "carmen.h"

/* The machine may be shared: the fastest of a few repeats is reported. */
#define BENCH_REPEATS 5

typedef struct {
    bsf_points_t pts;
    uint16_t interest[BSF_MAX_KEYPOINTS];
    size_t n_interest;
} bench_scan_t;

static bsf_falko_work_t falko_work;
static bsf_keypoint_t kps[BSF_MAX_POINTS];
static bsf_segment_t segs[BSF_MAX_SEGMENTS];
static float ranges[BSF_MAX_POINTS];

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

static int cmp_u16(const void *a, const void *b)
{
    const uint16_t x = *(const uint16_t *)a;
    const uint16_t y = *(const uint16_t *)b;
    return (x > y) - (x < y);
}

static int add_keypoints(bench_scan_t *s)
{
    size_t n_kp = 0;
    size_t i;
    const bsf_falko_params_t prm = bsf_falko_params_default();
    if (bsf_falko_detect(&s->pts, &prm, &falko_work, kps, BSF_MAX_POINTS, &n_kp) != BSF_OK) {
        return -1;
    }
    s->n_interest = n_kp < BSF_MAX_KEYPOINTS ? n_kp : BSF_MAX_KEYPOINTS;
    for (i = 0; i < s->n_interest; ++i) {
        s->interest[i] = kps[i].index;
    }
    qsort(s->interest, s->n_interest, sizeof s->interest[0], cmp_u16);
    return 0;
}

/* Times one method over all scans; prints ns/scan, segments and kept share. */
static int run(const char *name, int method, bench_scan_t *scans, size_t n_scans, int passes)
{
    double t0;
    double t1;
    double t_cls = 0.0;
    double t_seg = 0.0;
    int rep;
    size_t n_valid = 0;
    size_t n_wasted_all = 0;
    size_t n_segs_all = 0;
    size_t n_aux = 0;
    size_t i;
    int p;
    /* Each scan is segmented `passes` times in a row: its points are in
     * cache, as they are right after bsf_scan_to_points in the pipeline. */
    for (rep = 0; rep < BENCH_REPEATS; ++rep) {
        t0 = now_ns();
        for (i = 0; i < n_scans; ++i) {
            for (p = 0; p < passes; ++p) {
                size_t n_segs = 0;
                size_t n_wasted = 0;
                const bsf_status_t st =
                    method == 0 ? bsf_segment_sved(&scans[i].pts, NULL, segs, BSF_MAX_SEGMENTS,
                                                   &n_segs, &n_wasted)
                                : bsf_segment_rpos(&scans[i].pts, NULL, segs, BSF_MAX_SEGMENTS,
                                                   &n_segs, &n_wasted);
                if (st != BSF_OK) {
                    fprintf(stderr, "bench_segment: %s scan %zu: %s\n", name, i,
                            bsf_status_str(st));
                    return 1;
                }
                if (p == 0 && rep == 0) {
                    n_valid += scans[i].pts.n_valid;
                    n_wasted_all += n_wasted;
                    n_segs_all += n_segs;
                }
            }
        }
        t1 = now_ns();
        if (rep == 0 || t1 - t0 < t_seg) {
            t_seg = t1 - t0;
        }
    }
    /* Classification timed separately, on this method's segments. */
    for (i = 0; i < n_scans; ++i) {
        size_t n_segs = 0;
        size_t k;
        double c0;
        double c1;
        if ((method == 0
                 ? bsf_segment_sved(&scans[i].pts, NULL, segs, BSF_MAX_SEGMENTS, &n_segs, NULL)
                 : bsf_segment_rpos(&scans[i].pts, NULL, segs, BSF_MAX_SEGMENTS, &n_segs, NULL)) !=
            BSF_OK) {
            return 1;
        }
        c0 = now_ns();
        for (p = 0; p < passes; ++p) {
            if (bsf_segment_classify(segs, n_segs, &scans[i].pts, scans[i].interest,
                                     scans[i].n_interest) != BSF_OK) {
                fprintf(stderr, "bench_segment: classify scan %zu failed\n", i);
                return 1;
            }
        }
        c1 = now_ns();
        t_cls += c1 - c0;
        for (k = 0; k < n_segs; ++k) {
            n_aux += segs[k].kind == BSF_FEATURE_AUXILIARY ? 1u : 0u;
        }
    }
    printf("%-5s %8.0f ns/scan  classify %6.0f ns/scan  segments/scan %6.2f  auxiliary %5.1f %%"
           "  kept share %5.1f %%\n",
           name, t_seg / ((double)passes * (double)n_scans),
           t_cls / ((double)passes * (double)n_scans), (double)n_segs_all / (double)n_scans,
           n_segs_all ? 100.0 * (double)n_aux / (double)n_segs_all : 0.0,
           n_valid ? 100.0 * (1.0 - (double)n_wasted_all / (double)n_valid) : 0.0);
    return 0;
}

static int bench_log(const char *path, int passes, float range_max)
{
    bench_scan_t *scans = NULL;
    size_t n_scans = 0;
    size_t cap = 0;
    size_t n_beams_sum = 0;
    carmen_scan_t rec;
    carmen_reader_t *rd = carmen_open(path, stderr);
    int rc;
    if (rd == NULL) {
        printf("SKIPPED: log %s not found\n", path);
        return 0;
    }
    while (carmen_next(rd, &rec) == 1) {
        bsf_scan_t s;
        if (n_scans == cap) {
            cap = cap ? 2 * cap : 1024;
            scans = realloc(scans, cap * sizeof *scans);
            if (scans == NULL) {
                fprintf(stderr, "bench_segment: out of memory\n");
                return 1;
            }
        }
        s.ranges = rec.ranges;
        s.count = rec.count;
        s.angle_min = rec.angle_min;
        s.angle_increment = rec.angle_increment;
        s.range_min = 0.0f;
        s.range_max = range_max;
        if (bsf_scan_to_points(&s, &scans[n_scans].pts) != BSF_OK ||
            add_keypoints(&scans[n_scans]) != 0) {
            fprintf(stderr, "bench_segment: line %lu: scan rejected\n", rec.line);
            continue;
        }
        n_beams_sum += rec.count;
        ++n_scans;
    }
    carmen_close(rd);
    if (n_scans == 0) {
        fprintf(stderr, "bench_segment: no scan in %s\n", path);
        free(scans);
        return 1;
    }
    printf("log %s: %zu scans, %.0f beams/scan, %d passes\n", path, n_scans,
           (double)n_beams_sum / (double)n_scans, passes);
    rc = run("SVED", 0, scans, n_scans, passes);
    rc |= run("RPOS", 1, scans, n_scans, passes);
    free(scans);
    return rc;
}

static int bench_synthetic(int passes)
{
    /* Room with a pillar, 180 beams over 180 degrees, 1 cm noise, 100 poses. */
    static bench_scan_t scans[100];
    bsf_scene_t scene;
    bsf_scene_rng_t rng;
    size_t i;
    int rc;
    bsf_scene_init(&scene);
    bsf_scene_rng_seed(&rng, 2022u);
    if (bsf_scene_add_l_room(&scene, -4.0, -3.0, 12.0, 8.0, 5.0, 3.0) != BSF_OK ||
        bsf_scene_add_circle(&scene, 2.0, 0.5, 0.35) < 0) {
        return 1;
    }
    for (i = 0; i < 100u; ++i) {
        bsf_lidar_t l = bsf_lidar_default(-2.0 + 0.06 * (double)i, -1.0 + 0.02 * (double)i,
                                          0.05 * (double)i, 180u, 3.14159265358979);
        bsf_scan_t s;
        l.noise_sigma = 0.01;
        if (bsf_scene_scan(&scene, &l, &rng, ranges, NULL, BSF_MAX_POINTS) != BSF_OK) {
            return 1;
        }
        s = bsf_scene_lidar_scan(&l, ranges);
        if (bsf_scan_to_points(&s, &scans[i].pts) != BSF_OK || add_keypoints(&scans[i]) != 0) {
            return 1;
        }
    }
    printf("synthetic L-room with pillar: 100 scans, 180 beams, sigma 1 cm, %d passes\n",
           passes * 10);
    rc = run("SVED", 0, scans, 100u, passes * 10);
    rc |= run("RPOS", 1, scans, 100u, passes * 10);
    return rc;
}

int main(int argc, char **argv)
{
    char def_path[4096];
    const char *shared = getenv("BSF_SHARED_DIR");
    const char *path;
    int passes = (argc > 2) ? atoi(argv[2]) : 50;
    const float range_max = (argc > 3) ? (float)atof(argv[3]) : 81.0f;
    int rc;
    snprintf(def_path, sizeof def_path, "%s/data/intel.log.gz",
             shared != NULL ? shared : BSF_SHARED_DIR_DEFAULT);
    path = (argc > 1) ? argv[1] : def_path;
    if (passes < 1) {
        passes = 1;
    }
    rc = bench_synthetic(passes);
    rc |= bench_log(path, passes, range_max);
    return rc;
}
