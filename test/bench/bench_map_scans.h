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
#include "bsf/bsf_scan.h"

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

/** Scan k as the library takes it. */
static inline bsf_scan_t bench_map_scan(size_t k)
{
    const bench_map_scan_t *sc = &bench_map_scans[k];
    bsf_scan_t s;
    s.ranges = &bench_map_ranges[sc->first];
    s.count = sc->count;
    s.angle_min = -1.57079633f;
    s.angle_increment = sc->angle_increment;
    s.range_min = 0.0f;
    s.range_max = 80.0f;
    return s;
}

#endif /* BSF_BENCH_MAP_SCANS_H */
