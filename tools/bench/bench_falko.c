/* SPDX-License-Identifier: MIT */
/*
 * bench_falko - time bsf_falko_detect on every scan of a CARMEN log.
 *
 *   bench_falko [log] [passes] [range_max]
 *
 * Defaults: ../shared/data/intel.log.gz (BSF_SHARED_DIR overrides the
 * shared directory), 20 passes, range_max 81.0 m (below the 81.83 no-return
 * code). As in a real pipeline, each scan is converted to points
 * (bsf_scan_to_points) just before detection, so the points are warm in
 * cache; the conversion is timed separately. Each call is timed with
 * CLOCK_MONOTONIC. For every scan the median over passes is taken; the
 * mean, median and 99th percentile of those per-scan medians are printed,
 * plus the mean over all calls.
 * Run it on one core, e.g. taskset -c 1 ./build/tools/bench_falko.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "bsf/bsf.h"
#include "bsf/bsf_falko.h"
#include "carmen.h"

typedef struct {
    float *ranges;
    bsf_scan_t scan;
} stored_scan_t;

static bsf_falko_work_t work;
static bsf_points_t points;
static bsf_keypoint_t kps[BSF_MAX_POINTS];

static void print_stats(const char *what, double *samples, size_t n_scans, int passes,
                        double *per_scan)
{
    size_t i;
    double mean, all = 0.0;
    for (i = 0; i < n_scans * (size_t)passes; ++i) {
        all += samples[i];
    }
    mean = per_scan_medians(samples, n_scans, passes, per_scan) / (double)n_scans;
    printf("%s us/scan (per-scan median over passes): mean %.2f  median %.2f  p99 %.2f  max %.2f;"
           " mean of all calls %.2f\n",
           what, mean, per_scan[n_scans / 2], per_scan[(n_scans * 99) / 100], per_scan[n_scans - 1],
           all / ((double)n_scans * (double)passes));
}

int main(int argc, char **argv)
{
    char def_path[4096];
    const char *shared = getenv("BSF_SHARED_DIR");
    const char *path;
    int passes = (argc > 2) ? atoi(argv[2]) : 20;
    float range_max = (argc > 3) ? (float)atof(argv[3]) : 81.0f;
    stored_scan_t *scans = NULL;
    size_t n_scans = 0, cap = 0, i, total_kp = 0;
    double *per_scan, *t_detect, *t_convert;
    carmen_reader_t *rd;
    carmen_scan_t rec;
    bsf_falko_params_t prm = bsf_falko_params_default();
    int p;

    snprintf(def_path, sizeof def_path, "%s/data/intel.log.gz",
             shared != NULL ? shared : BSF_SHARED_DIR_DEFAULT);
    path = (argc > 1) ? argv[1] : def_path;
    if (passes < 1) {
        passes = 1;
    }
    rd = carmen_open(path, stderr);
    if (rd == NULL) {
        fprintf(stderr, "bench_falko: cannot open %s\n", path);
        return 1;
    }
    while (carmen_next(rd, &rec) == 1) {
        stored_scan_t *st;
        if (rec.count > BSF_MAX_POINTS) {
            fprintf(stderr, "bench_falko: line %lu: %zu beams, more than BSF_MAX_POINTS\n",
                    rec.line, rec.count);
            continue;
        }
        if (n_scans == cap) {
            cap = cap ? 2 * cap : 1024;
            scans = realloc(scans, cap * sizeof *scans);
            if (scans == NULL) {
                fprintf(stderr, "bench_falko: out of memory\n");
                return 1;
            }
        }
        st = &scans[n_scans];
        st->ranges = malloc(rec.count * sizeof(float));
        if (st->ranges == NULL) {
            fprintf(stderr, "bench_falko: out of memory\n");
            return 1;
        }
        memcpy(st->ranges, rec.ranges, rec.count * sizeof(float));
        st->scan.ranges = st->ranges;
        st->scan.count = rec.count;
        st->scan.angle_min = rec.angle_min;
        st->scan.angle_increment = rec.angle_increment;
        st->scan.range_min = 0.0f;
        st->scan.range_max = range_max;
        ++n_scans;
    }
    carmen_close(rd);
    if (n_scans == 0) {
        fprintf(stderr, "bench_falko: no scan in %s\n", path);
        return 1;
    }
    per_scan = malloc(n_scans * sizeof *per_scan);
    t_detect = malloc((size_t)passes * n_scans * sizeof *t_detect);
    t_convert = malloc((size_t)passes * n_scans * sizeof *t_convert);
    if (per_scan == NULL || t_detect == NULL || t_convert == NULL) {
        fprintf(stderr, "bench_falko: out of memory\n");
        return 1;
    }
    for (p = 0; p < passes; ++p) {
        for (i = 0; i < n_scans; ++i) {
            size_t n_kp = 0;
            bsf_status_t st;
            double t0, t1, t2;
            t0 = now_us();
            st = bsf_scan_to_points(&scans[i].scan, &points);
            t1 = now_us();
            if (st == BSF_OK) {
                st = bsf_falko_detect(&points, &prm, &work, kps, BSF_MAX_POINTS, &n_kp);
            }
            t2 = now_us();
            if (st != BSF_OK) {
                fprintf(stderr, "bench_falko: scan %zu: %s\n", i, bsf_status_str(st));
                return 1;
            }
            t_convert[i * (size_t)passes + (size_t)p] = t1 - t0;
            t_detect[i * (size_t)passes + (size_t)p] = t2 - t1;
            if (p == 0) {
                total_kp += n_kp;
            }
        }
    }
    printf("log %s: %zu scans, %d passes, range_max %.2f m, FALKO defaults\n", path, n_scans,
           passes, (double)range_max);
    printf("keypoints: %zu total, %.3f per scan\n", total_kp, (double)total_kp / (double)n_scans);
    print_stats("bsf_falko_detect   ", t_detect, n_scans, passes, per_scan);
    print_stats("bsf_scan_to_points ", t_convert, n_scans, passes, per_scan);
    for (i = 0; i < n_scans; ++i) {
        free(scans[i].ranges);
    }
    free(scans);
    free(t_convert);
    free(t_detect);
    free(per_scan);
    return 0;
}
