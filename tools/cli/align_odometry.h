/* SPDX-License-Identifier: MIT */
/*
 * align_odometry.h - odometry for `bsf extract --map --align`: relative
 * motions between consecutive scans, from the log's own odometry poses or
 * from the sequential edges of its pose graph.
 */
#ifndef BSF_TOOLS_ALIGN_ODOMETRY_H
#define BSF_TOOLS_ALIGN_ODOMETRY_H

#include <stddef.h>
#include <stdint.h>

/** A planar pose or motion, metres and radians. */
typedef struct {
    double x, y, t;
} odo_pose_t;

/** a then b (b given in a's frame). */
odo_pose_t odo_compose(odo_pose_t a, odo_pose_t b);
/** b seen from a: the motion from a to b. */
odo_pose_t odo_between(odo_pose_t a, odo_pose_t b);

/** The motions of a pose graph's sequential edges: motion[k] takes scan k - 1
 *  to scan k when have[k] is 1. */
typedef struct {
    odo_pose_t *motion;
    uint8_t *have;
    size_t n;
} odo_edges_t;

/**
 * Read the `EDGE2 a b dx dy dtheta ...` lines of the log's `#SEQUENTIAL`
 * section (b = a + 1; a TORO pose graph whose vertex k is the k-th scan).
 * 0, or -1 with a message (cannot read, no such edge, out of memory, or
 * built without zlib for a .gz log).
 */
int odo_edges_load(const char *path, odo_edges_t *e);
void odo_edges_free(odo_edges_t *e);

#endif /* BSF_TOOLS_ALIGN_ODOMETRY_H */
