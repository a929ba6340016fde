/*
 * bench_falko - time bsf_falko_detect on every scan of a CARMEN log.
 *
 *   bench_falko [log] [passes] [range_max]
 *
 * Defaults: ../shared/data/intel.log.gz (BSF_SHARED_DIR overrides the
 * shared directory), 20 passes, range_max 81.0 m (below the 81.83 no-return
 * code). Points are computed once, outside the timing; each call to
 * bsf_falko_detect is timed with CLOCK_MONOTONIC. For every scan the median
 * over passes is taken; the mean, median and 99th percentile of those
 * per-scan medians are printed, plus the mean over all calls.
 * Run it on one core, e.g. taskset -c 1 ./build/tools/bench_falko.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bsf/bsf.h"
#include "bsf/bsf_falko.h"
#include "carmen.h"

static double now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a;
    const double y = *(const double *)b;
    return (x > y) - (x < y);
}

static bsf_falko_work_t work;
static bsf_keypoint_t kps[BSF_MAX_POINTS];

int main(int argc, char **argv)
{
    char def_path[4096];
    const char *shared = getenv("BSF_SHARED_DIR");
    const char *path;
    int passes = (argc > 2) ? atoi(argv[2]) : 20;
    float range_max = (argc > 3) ? (float)atof(argv[3]) : 81.0f;
    bsf_points_t *pts = NULL;
    size_t n_scans = 0, cap = 0, i, total_kp = 0;
    double *per_scan, *samples, sum_all = 0.0;
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
        bsf_scan_t s;
        if (n_scans == cap) {
            cap = cap ? 2 * cap : 1024;
            pts = realloc(pts, cap * sizeof *pts);
            if (pts == NULL) {
                fprintf(stderr, "bench_falko: out of memory\n");
                return 1;
            }
        }
        s.ranges = rec.ranges;
        s.count = rec.count;
        s.angle_min = rec.angle_min;
        s.angle_increment = rec.angle_increment;
        s.range_min = 0.0f;
        s.range_max = range_max;
        if (bsf_scan_to_points(&s, &pts[n_scans]) != BSF_OK) {
            fprintf(stderr, "bench_falko: line %lu: scan rejected\n", rec.line);
            continue;
        }
        ++n_scans;
    }
    carmen_close(rd);
    if (n_scans == 0) {
        fprintf(stderr, "bench_falko: no scan in %s\n", path);
        return 1;
    }
    per_scan = malloc(n_scans * sizeof *per_scan);
    samples = malloc((size_t)passes * n_scans * sizeof *samples);
    if (per_scan == NULL || samples == NULL) {
        fprintf(stderr, "bench_falko: out of memory\n");
        return 1;
    }
    for (p = 0; p < passes; ++p) {
        for (i = 0; i < n_scans; ++i) {
            size_t n_kp = 0;
            bsf_status_t st;
            const double t0 = now_us();
            st = bsf_falko_detect(&pts[i], &prm, &work, kps, BSF_MAX_POINTS, &n_kp);
            const double t1 = now_us();
            if (st != BSF_OK) {
                fprintf(stderr, "bench_falko: scan %zu: %s\n", i, bsf_status_str(st));
                return 1;
            }
            samples[i * (size_t)passes + (size_t)p] = t1 - t0;
            sum_all += t1 - t0;
            if (p == 0) {
                total_kp += n_kp;
            }
        }
    }
    for (i = 0; i < n_scans; ++i) {
        double *s = &samples[i * (size_t)passes];
        qsort(s, (size_t)passes, sizeof *s, cmp_double);
        per_scan[i] = s[passes / 2];
    }
    qsort(per_scan, n_scans, sizeof *per_scan, cmp_double);
    {
        double mean = 0.0;
        for (i = 0; i < n_scans; ++i) {
            mean += per_scan[i];
        }
        mean /= (double)n_scans;
        printf("log %s: %zu scans, %d passes\n", path, n_scans, passes);
        printf("keypoints: %zu total, %.3f per scan\n", total_kp,
               (double)total_kp / (double)n_scans);
        printf("us/scan (per-scan median over passes): mean %.2f  median %.2f  p99 %.2f  max %.2f\n",
               mean, per_scan[n_scans / 2], per_scan[(n_scans * 99) / 100],
               per_scan[n_scans - 1]);
        printf("us/scan mean over all %zu calls: %.2f\n", (size_t)passes * n_scans,
               sum_all / ((double)passes * (double)n_scans));
    }
    free(samples);
    free(per_scan);
    free(pts);
    return 0;
}
