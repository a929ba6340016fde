/* SPDX-License-Identifier: MIT */
/*
 * bsf_svg.h - a minimal SVG writer for maps in world coordinates (metres,
 * y up). Host-only helper of the bsf tool.
 */
#ifndef BSF_SVG_H
#define BSF_SVG_H

#include <stdio.h>

typedef struct {
    FILE *f;
    double min_x, min_y, max_x, max_y; /* world bounds, metres */
    double px_per_m;                   /* scale */
    double margin_px;
    int open_path; /* a polyline is being written */
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

/** A filled circle of radius r_px (pixels) at a world point. */
void bsf_svg_dot(bsf_svg_t *svg, double x, double y, double r_px, const char *fill);

/** An open square marker (vertex) of half-size h_px at a world point. */
void bsf_svg_square(bsf_svg_t *svg, double x, double y, double h_px, const char *stroke);

/** Text at a world point, font size in px. The text is XML-escaped. */
void bsf_svg_text(bsf_svg_t *svg, double x, double y, double size_px, const char *text);

/** A scale bar of a round length (1, 2, 5 x 10^k m) in the lower-left corner,
 *  a legend line, then the closing tag. Returns 0, or -1 on a write error. */
int bsf_svg_end(bsf_svg_t *svg, const char *legend);

#endif /* BSF_SVG_H */
