/* SPDX-License-Identifier: MIT */
/*
 * map_geom.h - what the map benchmark measures, on curves already placed in
 * the world frame: curves as dense polylines, nearest-curve distances for
 * many points through a uniform grid index, distance histograms, and the
 * occupancy-grid baseline (ray-cast counts, PGM+gzip and PNG sizes).
 * Host-side (heap, zlib); not part of the library.
 */
#ifndef BSF_MAP_GEOM_H
#define BSF_MAP_GEOM_H

#include <stddef.h>
#include <stdint.h>

#include "bsf/bsf.h"

/** World-frame curves as polylines, plus their vertices (corners). */
typedef struct {
    float *seg; /* 4 floats per segment: x0 y0 x1 y1 */
    size_t n_seg, cap_seg;
    double *vtx; /* 2 doubles per vertex */
    size_t n_vtx, cap_vtx;
    size_t n_curves;
    double length; /* metres of curve */
} mg_curves_t;

void mg_curves_init(mg_curves_t *c);
void mg_curves_free(mg_curves_t *c);
void mg_curves_clear(mg_curves_t *c);
/** Add a polyline of n >= 2 points (xy[2k], xy[2k+1]). 0, or -1 out of memory. */
int mg_curves_add_polyline(mg_curves_t *c, const double *xy, size_t n);
/** Add a vertex. 0, or -1 out of memory. */
int mg_curves_add_vertex(mg_curves_t *c, double x, double y);

/** Samples per span when a quadratic B-spline becomes a polyline. */
#define MG_SAMPLES_PER_SPAN 16
/**
 * Add a clamped uniform quadratic B-spline with world control points xy
 * (n_ctrl >= 3; bsf_bspline.h's curve), sampled MG_SAMPLES_PER_SPAN times per
 * span; vertex flags mark pairs of equal control points (may be NULL).
 * 0, or -1 out of memory or a bad curve.
 */
int mg_curves_add_bspline(mg_curves_t *c, const double *xy, size_t n_ctrl, const uint8_t *vertex);

/**
 * Folds of a curve: places where it turns back on itself. The curve is
 * sampled MG_FOLD_SAMPLES_PER_SPAN times per span; at each sample the chord
 * from the curve MG_FOLD_CHORD metres of arc before it and the chord to the
 * curve MG_FOLD_CHORD after it are compared, and a run of samples where they
 * turn by more than MG_FOLD_TURN_DEG is one fold. Chords, not derivatives: at
 * a cusp the derivative vanishes. A circle turns that much between chords of
 * 2 cm only when its radius is under 8 mm, which no scan resolves, so a
 * real round surface never counts. The curve is cut at its vertices (the
 * map's corners, where the spans on either side are straight): a vertex's
 * own turn is the corner's angle, counted apart in sharp_vertices when it
 * exceeds MG_FOLD_TURN_DEG, since a true corner that acute is possible.
 */
#define MG_FOLD_SAMPLES_PER_SPAN 64
#define MG_FOLD_CHORD 0.02
#define MG_FOLD_TURN_DEG 150.0
typedef struct {
    unsigned long folds;          /* turns back within the smooth pieces */
    unsigned long sharp_vertices; /* vertices turning more than MG_FOLD_TURN_DEG */
} mg_folds_t;
/** Add the folds of the curve mg_curves_add_bspline takes to *f. 0, or -1 for a bad curve. */
int mg_bspline_folds(const double *xy, size_t n_ctrl, const uint8_t *vertex, mg_folds_t *f);

/** Largest distance a query resolves, metres; farther reads as this. */
#define MG_DIST_MAX 0.5
/** Uniform grid over the segments of a curve set, for nearest distances. */
typedef struct {
    const mg_curves_t *c;
    double x0, y0, cell;
    size_t nx, ny;
    uint32_t *start; /* nx*ny+1 offsets into idx */
    uint32_t *idx;
} mg_index_t;

/** Build the index (cell 0.1 m). 0, or -1 out of memory. */
int mg_index_build(mg_index_t *ix, const mg_curves_t *c);
void mg_index_free(mg_index_t *ix);
/** Distance from (x, y) to the nearest segment, at most MG_DIST_MAX. */
double mg_index_dist(const mg_index_t *ix, double x, double y);

/** Distance histogram: 0.1 mm bins up to MG_DIST_MAX. */
#define MG_HIST_BINS 5000
typedef struct {
    uint64_t bin[MG_HIST_BINS + 1];
    uint64_t n;
    double max;
} mg_hist_t;

void mg_hist_add(mg_hist_t *h, double d);
/** Quantile q (upper bin edge), metres; 0 when empty. */
double mg_hist_quantile(const mg_hist_t *h, double q);
/** Share of the samples at or below d (to one bin). */
double mg_hist_share_below(const mg_hist_t *h, double d);

/** Valid raw points of a whole run in the world frame, with their scan's sensor position. */
typedef struct {
    float *xy;         /* 2 per point */
    uint32_t *scan_of; /* scan index per point */
    size_t n, cap, cap_scan_of;
    double *origin; /* 2 per scan */
    size_t n_scans, cap_scans;
} mg_points_t;

void mg_points_init(mg_points_t *p);
void mg_points_free(mg_points_t *p);
/** Start a scan at sensor position (x, y). 0, or -1 out of memory. */
int mg_points_begin_scan(mg_points_t *p, double x, double y);
/** A valid point of the current scan. 0, or -1 out of memory. */
int mg_points_add(mg_points_t *p, double x, double y);

/** The occupancy-grid baseline: sizes of the map as files. */
typedef struct {
    double cell; /* metres */
    size_t nx, ny;
    size_t occupied, free_cells;
    size_t pgm_bytes, pgm_gz_bytes, png_bytes;
} mg_grid_result_t;

/**
 * Ray-cast every point of pts from its scan's origin on a grid of `cell`
 * metres (Bresenham; the end cell counts a hit, the cells before it a miss),
 * classify cells as ROS gmapping does (occupied when the hit share is above
 * its default occ_thresh 0.25, free when seen otherwise, unknown when never
 * crossed) and write them as map_saver does (0, 254, 205), then
 * size the map as a P5 PGM, gzip'd (zlib level 9) and as an 8-bit grey PNG.
 * pgm_path / png_path (may be NULL) also get the files written.
 * 0, or -1 out of memory or on a write error.
 */
int mg_grid_baseline(const mg_points_t *pts, double cell, const char *pgm_gz_path,
                     const char *png_path, mg_grid_result_t *out);

/** Bytes of buf gzip'd (zlib level 9, gzip wrapper); 0 on failure. */
size_t mg_gzip_size(const uint8_t *buf, size_t n);

/** Bytes of one round of the snapshot round robin over every feature the
 *  robot holds: the snapshot records only (no frame headers), written into
 *  `copy` (a copy of `map`, changed) in frames of `budget` snapshot bytes,
 *  fusing empty scans at `pose` in between. The round robin of a map that no
 *  longer changes is periodic in its state (next id, next point), recorded
 *  after each frame until one repeats; a state not above the one before
 *  means the round wrapped in that frame, and one period holds as many whole
 *  rounds as it wraps (a map smaller than one frame's budget, sent more than
 *  once per frame, reads high). -1 on failure. */
long mg_map_once_bytes(bsf_map_t *copy, const bsf_map_t *map, const bsf_pose_t *pose,
                       uint16_t budget);

#endif /* BSF_MAP_GEOM_H */
