/* SPDX-License-Identifier: MIT */
/*
 * bsf_svg.h - a minimal SVG writer for maps in world coordinates (metres,
 * y up). Host-only helper of the bsf tool.
 */
#ifndef BSF_SVG_H
#define BSF_SVG_H

#include <stddef.h>
#include <stdio.h>

typedef struct {
    FILE *f;
    double min_x, min_y, max_x, max_y; /* world bounds, metres */
    double px_per_m;                   /* scale */
    double margin_px;
    int open_path; /* a polyline is being written */
    /* the open batch of curves (bsf_svg_curves_begin) */
    const char *curve_stroke;
    double curve_width;
    size_t curves_in_path;
    double grid_step; /* metres between grid lines; 0: no grid drawn */
} bsf_svg_t;

/** Bounds accumulator: start empty, grow with points. */
typedef struct {
    double min_x, min_y, max_x, max_y;
    int empty;
} bsf_bounds_t;

void bsf_bounds_init(bsf_bounds_t *b);
void bsf_bounds_add(bsf_bounds_t *b, double x, double y);

/**
 * Start a document showing `bounds` scaled to about `width_px` pixels wide
 * (height follows the aspect ratio; at least 1x1 m is shown). Writes the
 * header, a white background and a title. Returns 0, or -1 on a write error.
 */
int bsf_svg_begin(bsf_svg_t *svg, FILE *f, const bsf_bounds_t *bounds, double width_px,
                  const char *title);

/** A polyline in world coordinates: begin, add points, end with a stroke colour and width (px). */
void bsf_svg_path_begin(bsf_svg_t *svg);
void bsf_svg_path_point(bsf_svg_t *svg, double x, double y);
void bsf_svg_path_end(bsf_svg_t *svg, const char *stroke, double width_px);
/** As bsf_svg_path_end, the stroke dashed: `dash` is an SVG stroke-dasharray
 *  in pixels, such as "6,4". */
void bsf_svg_path_end_dashed(bsf_svg_t *svg, const char *stroke, double width_px, const char *dash);

/**
 * Quadratic B-spline curves (clamped, uniform knots: bsf_bspline.h), drawn
 * exactly, as SVG quadratic Bezier pieces: span i runs from the midpoint of
 * P_i, P_i+1 (P_0 for the first) to the midpoint of P_i+1, P_i+2 (the last
 * point for the last span) with P_i+1 as its control point. Curves between
 * begin and end share one stroke and are batched into <path> elements.
 */
void bsf_svg_curves_begin(bsf_svg_t *svg, const char *stroke, double width_px);
/** One curve: n_ctrl >= 3 control points, xy[2k], xy[2k+1] in world metres. */
void bsf_svg_curve_bspline2(bsf_svg_t *svg, const double *xy, size_t n_ctrl);
void bsf_svg_curves_end(bsf_svg_t *svg);

/** A filled circle of radius r_px (pixels) at a world point. */
void bsf_svg_dot(bsf_svg_t *svg, double x, double y, double r_px, const char *fill);

/** An open square marker (vertex) of half-size h_px at a world point. */
void bsf_svg_square(bsf_svg_t *svg, double x, double y, double h_px, const char *stroke);

/** The robot at a pose: a ring with a tick pointing along the heading (radians). */
void bsf_svg_robot(bsf_svg_t *svg, double x, double y, double theta, const char *stroke);

/** Text at a world point, font size in px. The text is XML-escaped. */
void bsf_svg_text(bsf_svg_t *svg, double x, double y, double size_px, const char *text);

/** Light grid lines every round step (1, 2 or 5 x 10^k m, about 6-15 lines
 *  across). Draw it first; bsf_svg_end() labels the lines in metres along the
 *  left and bottom edges, on top of the map. */
void bsf_svg_grid(bsf_svg_t *svg);

/** A vertex marker: a filled square of half-size h_px with a white outline,
 *  visible on top of curves and points. */
void bsf_svg_vertex(bsf_svg_t *svg, double x, double y, double h_px, const char *fill);

/**
 * Raw points thinned on a grid: one point per cell of `cell_m` metres (at
 * least one pixel), kept or not by a bitmap over the drawing area, so memory
 * is fixed by the picture's size (not the number of points) and a dense map
 * stays small. Points outside the drawing area are not drawn. Drawn as
 * round dots of diameter dot_px, batched into compact <path> elements.
 */
typedef struct {
    bsf_svg_t *svg;
    unsigned char *seen; /* one bit per cell */
    size_t nx, ny;
    double cell_m;
    const char *fill;
    double dot_px;
    unsigned long kept, merged, outside;
    size_t in_path; /* dots in the open <path> */
} bsf_svg_points_t;

/** Start a point layer. Returns 0, or -1 when out of memory. */
int bsf_svg_points_begin(bsf_svg_points_t *pts, bsf_svg_t *svg, double cell_m, double dot_px,
                         const char *fill);
/** Offer one point (world metres); drawn only when its cell is new. */
void bsf_svg_points_add(bsf_svg_points_t *pts, double x, double y);
/** Close the layer and free its bitmap. */
void bsf_svg_points_end(bsf_svg_points_t *pts);

/** What a legend entry shows next to its text. */
typedef enum {
    BSF_SVG_KEY_LINE,
    BSF_SVG_KEY_DASH,
    BSF_SVG_KEY_DOT,
    BSF_SVG_KEY_VERTEX
} bsf_svg_key_t;

typedef struct {
    bsf_svg_key_t key;
    const char *colour;
    const char *text;
} bsf_svg_legend_item_t;

/** The legend: one row under the map, the items side by side. */
void bsf_svg_legend(bsf_svg_t *svg, const bsf_svg_legend_item_t *items, size_t n);

/** A scale bar of a round length (1, 2, 5 x 10^k m) in the lower-left corner,
 *  a caption line, then the closing tag. Returns 0, or -1 on a write error. */
int bsf_svg_end(bsf_svg_t *svg, const char *legend);

#endif /* BSF_SVG_H */
