/* SPDX-License-Identifier: MIT */
/*
 * bench_util.h - the host benchmarks' clock and sort order. Include after
 * defining _POSIX_C_SOURCE (clock_gettime).
 */
#ifndef BSF_BENCH_UTIL_H
#define BSF_BENCH_UTIL_H

#include <stddef.h>
#include <stdlib.h>
#include <time.h>

/* Monotonic time, microseconds. */
static inline double now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

/* qsort order of doubles, ascending. */
static inline int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a;
    const double y = *(const double *)b;
    return (x > y) - (x < y);
}

/* samples[scan * passes + pass] -> each scan's median over its passes in
 * per_scan (each scan's samples and then per_scan sorted in place); returns
 * the sum of the medians. */
static inline double per_scan_medians(double *samples, size_t n_scans, int passes, double *per_scan)
{
    double sum = 0.0;
    size_t i;
    for (i = 0; i < n_scans; ++i) {
        double *v = &samples[i * (size_t)passes];
        qsort(v, (size_t)passes, sizeof *v, cmp_double);
        per_scan[i] = v[passes / 2];
        sum += per_scan[i];
    }
    qsort(per_scan, n_scans, sizeof *per_scan, cmp_double);
    return sum;
}

#endif
