/* SPDX-License-Identifier: MIT */
/*
 * bench_map_scans.h - real FLASER scans with their poses, compiled into the
 * map benchmark. The definitions are generated at build time by
 * tools/scripts/gen_map_scans.py from a CARMEN log in the shared data
 * directory (never committed).
 */
#ifndef BSF_BENCH_MAP_SCANS_H
#define BSF_BENCH_MAP_SCANS_H

#include <stddef.h>
#include <stdint.h>

#include "bsf/bsf_common.h"

/** One scan: its readings are bench_map_ranges[first .. first + count - 1],
 *  beam 0 at -pi/2, range_max 80 m; pose is the laser's in the world. */
typedef struct {
    uint32_t first;
    uint16_t count;
    float angle_increment; /**< radians */
    bsf_pose_t pose;
} bench_map_scan_t;

extern const float bench_map_ranges[];
extern const bench_map_scan_t bench_map_scans[];
extern const size_t bench_map_n_scans;
extern const char bench_map_description[];

#endif /* BSF_BENCH_MAP_SCANS_H */
