/* SPDX-License-Identifier: MIT */
/*
 * bench_scenes.h - the benchmark scenes of docs/PERFORMANCE.md, shared by bench_extract
 * (host time), bench_count (x86 instructions under callgrind) and
 * bench_m4_icount (Cortex-M4F instructions under QEMU).
 *
 * Realistic scenes: every sensor pose stands in free space, at least
 * BENCH_POSE_CLEARANCE from every surface and enclosed by the room; the
 * benchmarks check each pose against each shape (bench_poses_check) and
 * stop when one is not. Adversarial scenes bound the worst case and are
 * reported apart: a sensor pressed against a pillar, a scan of pure clutter
 * (no structure at all) and a 4000-beam scan of one long wall.
 *
 * Compile bench_scenes.c with the same BSF_SCENE_MAX_SHAPES and caps as
 * bsf_scene.c in the same program.
 */
#ifndef BENCH_SCENES_H
#define BENCH_SCENES_H

#include <stddef.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"

/** Closest a benchmark pose may be to any surface, metres (a sensor's body). */
#define BENCH_POSE_CLEARANCE 0.3

/** Poses of the scaling scene (bench_scaling_scene). */
#define BENCH_SCALE_POSES 20
/** Beam counts of the scaling run (270 degrees, 1 cm noise). */
#define BENCH_SCALE_SIZES 6
extern const size_t bench_scale_beams[BENCH_SCALE_SIZES];

/** The office scaling scene: a 12 m x 8 m L-shaped room, two round pillars
 *  and a free-standing corner. */
bsf_status_t bench_scaling_scene(bsf_scene_t *scene);
/** Pose i of BENCH_SCALE_POSES in the scaling scene (a diagonal walk). */
bsf_scene_pose_t bench_scaling_pose(size_t i);

/** Poses in the demo office (bsf_scene_demo_office) for the 1081-beam 270
 *  degree and 3200-beam 360 degree office scans. */
#define BENCH_OFFICE_POSES 8
bsf_scene_pose_t bench_office_pose(size_t i);

/**
 * Check poses[0..n) against every shape of the scene: none inside a circle
 * or a solid polygon, none within `clearance` of a surface, each enclosed by
 * the room (a ray in each of 360 directions hits a wall).
 * @return -1 when all are free; otherwise the index of the first bad pose,
 *         with *shape (may be NULL) the shape it collides with (-1: not
 *         enclosed).
 */
int bench_poses_check(const bsf_scene_t *scene, const bsf_scene_pose_t *poses, size_t n,
                      double clearance, int *shape);

/** Adversarial scene kinds. */
typedef enum {
    BENCH_ADV_PILLAR = 0,    /**< sensor 2..20 cm from a 0.3 m pillar, 1000 beams, 270 deg */
    BENCH_ADV_CLUTTER = 1,   /**< pure clutter: every range uniform in 0.3..8 m, 1000 beams */
    BENCH_ADV_LONG_WALL = 2, /**< one straight wall 0.5..4 m away, 4000 beams over 180 deg */
    BENCH_ADV_COUNT = 3
} bench_adv_t;

/** Scans per adversarial kind. */
#define BENCH_ADV_SCANS 4

/** Name of an adversarial kind ("pillar", "clutter", "long-wall"), or NULL. */
const char *bench_adv_name(int kind);
/** Beams of an adversarial kind's scans. */
size_t bench_adv_beams(int kind);

/**
 * Scan k (< BENCH_ADV_SCANS) of an adversarial kind into ranges[0..cap) and
 * *scan. The pillar poses are checked to stand outside the pillar (clearance
 * 0: they are meant to be close). @return BSF_OK; BSF_ERR_ARG for a bad kind,
 * k or NULL; BSF_ERR_CAPACITY when cap or BSF_MAX_POINTS is below the kind's
 * beams; another error when a pose check fails (BSF_ERR_DEGENERATE).
 */
bsf_status_t bench_adv_scan(int kind, size_t k, float *ranges, size_t cap, bsf_scan_t *scan);

/**
 * A long corridor for bench_truth: 24 m x 2 m, its two walls broken by
 * door recesses (1.2 m wide, 0.5 m deep, every 3.5 m, staggered between the
 * sides), so that most corners are seen at grazing incidence.
 * @return BSF_OK, or BSF_ERR_CAPACITY when the scene cannot hold it.
 */
bsf_status_t bench_truth_corridor(bsf_scene_t *scene);

/** Pose k of n in the corridor: down the centre line and back, heading along
 *  it with a wobble of +-0.4 rad. */
bsf_scene_pose_t bench_truth_corridor_pose(long k, long n);

/**
 * A cluttered room for bench_truth: bsf_scene_add_clutter_room, 10 m x 7 m,
 * zig-zag shelving along both long walls, 6 posts and 5 boxes, kept 1.5 m
 * clear of the origin, drawn from a fixed seed.
 * @return BSF_OK, or the error of bsf_scene_add_clutter_room.
 */
bsf_status_t bench_truth_clutter(bsf_scene_t *scene);

/** Pose k of n in the cluttered room: on a 0.8 m circle round the origin,
 *  headings turning once and a half round the circle. */
bsf_scene_pose_t bench_truth_clutter_pose(long k, long n);

#endif /* BENCH_SCENES_H */
