/* SPDX-License-Identifier: MIT */
/*
 * bench_log_scans.h - real scans compiled into a benchmark image. The
 * definitions are generated at build time by tools/gen_scan_array.py from a
 * CARMEN log in the shared data directory (never committed); the benchmark is
 * built without them (BSF_BENCH_HAVE_LOG undefined) when the log is absent.
 */
#ifndef BSF_BENCH_LOG_SCANS_H
#define BSF_BENCH_LOG_SCANS_H

#include <stddef.h>
#include <stdint.h>

/** One scan: its readings are bench_log_ranges[first .. first + count - 1]. */
typedef struct {
    uint32_t first;
    uint16_t count;
    float angle_min;       /**< radians */
    float angle_increment; /**< radians */
    float range_max;       /**< metres, below the log's no-return codes */
} bench_log_scan_t;

extern const float bench_log_ranges[];
extern const bench_log_scan_t bench_log_scans[];
extern const size_t bench_log_n_scans;
extern const char bench_log_description[];

#endif /* BSF_BENCH_LOG_SCANS_H */
