/* SPDX-License-Identifier: MIT */
#include "bsf_svg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void bsf_bounds_init(bsf_bounds_t *b)
{
    b->min_x = b->min_y = 0.0;
    b->max_x = b->max_y = 0.0;
    b->empty = 1;
}

void bsf_bounds_add(bsf_bounds_t *b, double x, double y)
{
    if (!isfinite(x) || !isfinite(y)) {
        return;
    }
    if (b->empty) {
        b->min_x = b->max_x = x;
        b->min_y = b->max_y = y;
        b->empty = 0;
        return;
    }
    if (x < b->min_x)
        b->min_x = x;
    if (x > b->max_x)
        b->max_x = x;
    if (y < b->min_y)
        b->min_y = y;
    if (y > b->max_y)
        b->max_y = y;
}

static double sx(const bsf_svg_t *s, double x)
{
    return s->margin_px + (x - s->min_x) * s->px_per_m;
}

static double sy(const bsf_svg_t *s, double y)
{
    /* SVG's y grows downwards; the map's grows upwards. */
    return s->margin_px + (s->max_y - y) * s->px_per_m;
}

static double width_px(const bsf_svg_t *s)
{
    return 2.0 * s->margin_px + (s->max_x - s->min_x) * s->px_per_m;
}

static double height_px(const bsf_svg_t *s)
{
    /* below the map: a legend row, then the scale bar and caption row */
    return 2.0 * s->margin_px + (s->max_y - s->min_y) * s->px_per_m + 54.0;
}

static void put_escaped(FILE *f, const char *t)
{
    for (; *t != '\0'; ++t) {
        switch (*t) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*t, f); break;
        }
    }
}

int bsf_svg_begin(bsf_svg_t *svg, FILE *f, const bsf_bounds_t *bounds, double w_px,
                  const char *title)
{
    double cx, cy, span_x, span_y;
    memset(svg, 0, sizeof *svg);
    svg->f = f;
    svg->margin_px = 20.0;
    if (bounds->empty) {
        svg->min_x = -1.0;
        svg->max_x = 1.0;
        svg->min_y = -1.0;
        svg->max_y = 1.0;
    } else {
        svg->min_x = bounds->min_x;
        svg->max_x = bounds->max_x;
        svg->min_y = bounds->min_y;
        svg->max_y = bounds->max_y;
    }
    /* Show at least 1 m in each direction, centred on the content. */
    span_x = svg->max_x - svg->min_x;
    span_y = svg->max_y - svg->min_y;
    if (span_x < 1.0) {
        cx = 0.5 * (svg->min_x + svg->max_x);
        svg->min_x = cx - 0.5;
        svg->max_x = cx + 0.5;
        span_x = 1.0;
    }
    if (span_y < 1.0) {
        cy = 0.5 * (svg->min_y + svg->max_y);
        svg->min_y = cy - 0.5;
        svg->max_y = cy + 0.5;
    }
    if (w_px < 100.0) {
        w_px = 100.0;
    }
    svg->px_per_m = (w_px - 2.0 * svg->margin_px) / span_x;
    fprintf(f,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "viewBox=\"0 0 %.1f %.1f\">\n",
            width_px(svg), height_px(svg), width_px(svg), height_px(svg));
    fputs("<title>", f);
    put_escaped(f, title != NULL ? title : "bsf map");
    fputs("</title>\n", f);
    fprintf(f, "<rect x=\"0\" y=\"0\" width=\"%.1f\" height=\"%.1f\" fill=\"white\"/>\n",
            width_px(svg), height_px(svg));
    return ferror(f) ? -1 : 0;
}

void bsf_svg_path_begin(bsf_svg_t *svg)
{
    svg->open_path = 0;
}

void bsf_svg_path_point(bsf_svg_t *svg, double x, double y)
{
    if (!isfinite(x) || !isfinite(y)) {
        return;
    }
    if (!svg->open_path) {
        fprintf(svg->f, "<polyline points=\"");
        svg->open_path = 1;
    } else {
        fputc(' ', svg->f);
    }
    fprintf(svg->f, "%.2f,%.2f", sx(svg, x), sy(svg, y));
}

void bsf_svg_path_end(bsf_svg_t *svg, const char *stroke, double w)
{
    if (svg->open_path) {
        fprintf(svg->f,
                "\" fill=\"none\" stroke=\"%s\" stroke-width=\"%.2f\" "
                "stroke-linejoin=\"round\" stroke-linecap=\"round\"/>\n",
                stroke, w);
        svg->open_path = 0;
    }
}

void bsf_svg_path_end_dashed(bsf_svg_t *svg, const char *stroke, double w, const char *dash)
{
    if (svg->open_path) {
        fprintf(svg->f,
                "\" fill=\"none\" stroke=\"%s\" stroke-width=\"%.2f\" "
                "stroke-dasharray=\"%s\" stroke-linejoin=\"round\"/>\n",
                stroke, w, dash);
        svg->open_path = 0;
    }
}

/* Curves per <path> element. */
#define SVG_CURVES_PER_PATH 2000u

static void curves_close(bsf_svg_t *svg)
{
    if (svg->curves_in_path > 0u) {
        fprintf(svg->f,
                "\" fill=\"none\" stroke=\"%s\" stroke-width=\"%.2f\" "
                "stroke-linejoin=\"round\" stroke-linecap=\"round\"/>\n",
                svg->curve_stroke, svg->curve_width);
        svg->curves_in_path = 0u;
    }
}

void bsf_svg_curves_begin(bsf_svg_t *svg, const char *stroke, double width_px)
{
    svg->curve_stroke = stroke;
    svg->curve_width = width_px;
    svg->curves_in_path = 0u;
}

void bsf_svg_curve_bspline2(bsf_svg_t *svg, const double *xy, size_t n)
{
    size_t i;
    if (n < 3u) {
        return;
    }
    for (i = 0; i < 2u * n; ++i) {
        if (!isfinite(xy[i])) {
            return;
        }
    }
    if (svg->curves_in_path == 0u) {
        fputs("<path class=\"features\" d=\"", svg->f);
    }
    fprintf(svg->f, "M%.1f %.1f", sx(svg, xy[0]), sy(svg, xy[1]));
    for (i = 1; i + 1u < n; ++i) {
        const double *c = xy + 2u * i;
        const double ex = i + 2u == n ? c[2] : 0.5 * (c[0] + c[2]);
        const double ey = i + 2u == n ? c[3] : 0.5 * (c[1] + c[3]);
        fprintf(svg->f, "Q%.1f %.1f %.1f %.1f", sx(svg, c[0]), sy(svg, c[1]), sx(svg, ex),
                sy(svg, ey));
    }
    if (++svg->curves_in_path == SVG_CURVES_PER_PATH) {
        curves_close(svg);
    }
}

void bsf_svg_curves_end(bsf_svg_t *svg)
{
    curves_close(svg);
}

void bsf_svg_dot(bsf_svg_t *svg, double x, double y, double r_px, const char *fill)
{
    if (!isfinite(x) || !isfinite(y)) {
        return;
    }
    fprintf(svg->f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" fill=\"%s\"/>\n", sx(svg, x),
            sy(svg, y), r_px, fill);
}

void bsf_svg_square(bsf_svg_t *svg, double x, double y, double h, const char *stroke)
{
    if (!isfinite(x) || !isfinite(y)) {
        return;
    }
    fprintf(svg->f,
            "<rect x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" fill=\"none\" "
            "stroke=\"%s\" stroke-width=\"1\"/>\n",
            sx(svg, x) - h, sy(svg, y) - h, 2.0 * h, 2.0 * h, stroke);
}

void bsf_svg_robot(bsf_svg_t *svg, double x, double y, double theta, const char *stroke)
{
    const double r = 6.0;
    double cx, cy;
    if (!isfinite(x) || !isfinite(y) || !isfinite(theta)) {
        return;
    }
    cx = sx(svg, x);
    cy = sy(svg, y);
    fprintf(svg->f,
            "<g class=\"robot\" fill=\"none\" stroke=\"%s\" stroke-width=\"2\"><circle cx=\"%.1f\" "
            "cy=\"%.1f\" r=\"%.1f\"/><line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/></g>\n",
            stroke, cx, cy, r, cx, cy, cx + 2.2 * r * cos(theta), cy - 2.2 * r * sin(theta));
}

void bsf_svg_text(bsf_svg_t *svg, double x, double y, double size_px, const char *text)
{
    fprintf(svg->f, "<text x=\"%.2f\" y=\"%.2f\" font-family=\"sans-serif\" font-size=\"%.1f\">",
            sx(svg, x), sy(svg, y), size_px);
    put_escaped(svg->f, text);
    fputs("</text>\n", svg->f);
}

/* 1, 2 or 5 x 10^k: the round number nearest above raw. */
static double round_step(double raw)
{
    const double p = pow(10.0, floor(log10(raw)));
    const double m = raw / p;
    return (m <= 1.0 ? 1.0 : m <= 2.0 ? 2.0 : m <= 5.0 ? 5.0 : 10.0) * p;
}

void bsf_svg_grid(bsf_svg_t *svg)
{
    const double span = fmax(svg->max_x - svg->min_x, svg->max_y - svg->min_y);
    const double step = round_step(span / 12.0);
    const double x_lo = ceil(svg->min_x / step), x_hi = floor(svg->max_x / step);
    const double y_lo = ceil(svg->min_y / step), y_hi = floor(svg->max_y / step);
    double k;
    fputs("<g id=\"grid\" stroke=\"#e2e2e2\" stroke-width=\"1\">\n", svg->f);
    for (k = x_lo; k <= x_hi; k += 1.0) {
        fprintf(svg->f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>\n",
                sx(svg, k * step), sy(svg, svg->min_y), sx(svg, k * step), sy(svg, svg->max_y));
    }
    for (k = y_lo; k <= y_hi; k += 1.0) {
        fprintf(svg->f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>\n",
                sx(svg, svg->min_x), sy(svg, k * step), sx(svg, svg->max_x), sy(svg, k * step));
    }
    fputs("</g>\n", svg->f);
    svg->grid_step = step;
}

/* Grid labels with a white halo, so a label over a wall stays readable; the
 * value 0 is written "0 m" so the unit is never in doubt. */
static void grid_labels(bsf_svg_t *svg)
{
    const double step = svg->grid_step;
    int layer;
    if (step <= 0.0) {
        return;
    }
    /* Twice: a white halo, then the text (paint-order is not understood by
     * every renderer). */
    for (layer = 0; layer < 2; ++layer) {
        double k;
        fprintf(svg->f, "<g %sfont-family=\"sans-serif\" font-size=\"11\" %s>\n",
                layer ? "id=\"grid-labels\" " : "",
                layer ? "fill=\"#707070\"" : "fill=\"white\" stroke=\"white\" stroke-width=\"3\"");
        for (k = ceil(svg->min_x / step); k <= floor(svg->max_x / step); k += 1.0) {
            fprintf(svg->f, "<text x=\"%.1f\" y=\"%.1f\">%g m</text>\n", sx(svg, k * step) + 2.0,
                    sy(svg, svg->min_y) - 3.0, k * step + 0.0);
        }
        for (k = ceil(svg->min_y / step); k <= floor(svg->max_y / step); k += 1.0) {
            fprintf(svg->f, "<text x=\"%.1f\" y=\"%.1f\">%g m</text>\n", sx(svg, svg->min_x) + 2.0,
                    sy(svg, k * step) - 3.0, k * step + 0.0);
        }
        fputs("</g>\n", svg->f);
    }
}

void bsf_svg_vertex(bsf_svg_t *svg, double x, double y, double h, const char *fill)
{
    if (!isfinite(x) || !isfinite(y)) {
        return;
    }
    fprintf(svg->f,
            "<rect class=\"vertex\" x=\"%.2f\" y=\"%.2f\" width=\"%.2f\" height=\"%.2f\" "
            "fill=\"%s\" stroke=\"white\" stroke-width=\"1\"/>\n",
            sx(svg, x) - h, sy(svg, y) - h, 2.0 * h, 2.0 * h, fill);
}

/* Dots per <path> element: keeps each attribute a manageable size. */
#define SVG_DOTS_PER_PATH 4000u

int bsf_svg_points_begin(bsf_svg_points_t *pts, bsf_svg_t *svg, double cell_m, double dot_px,
                         const char *fill)
{
    memset(pts, 0, sizeof *pts);
    pts->svg = svg;
    pts->fill = fill;
    pts->dot_px = dot_px;
    /* Never finer than a pixel: two points in one pixel look like one. */
    pts->cell_m = fmax(cell_m, 1.0 / svg->px_per_m);
    pts->nx = (size_t)ceil((svg->max_x - svg->min_x) / pts->cell_m) + 1u;
    pts->ny = (size_t)ceil((svg->max_y - svg->min_y) / pts->cell_m) + 1u;
    pts->seen = (unsigned char *)calloc((pts->nx * pts->ny + 7u) / 8u, 1u);
    return pts->seen != NULL ? 0 : -1;
}

void bsf_svg_points_add(bsf_svg_points_t *pts, double x, double y)
{
    double fx, fy;
    size_t cell;
    if (!isfinite(x) || !isfinite(y)) {
        return;
    }
    fx = (x - pts->svg->min_x) / pts->cell_m;
    fy = (y - pts->svg->min_y) / pts->cell_m;
    if (fx < 0.0 || fy < 0.0 || fx >= (double)pts->nx || fy >= (double)pts->ny) {
        ++pts->outside;
        return;
    }
    cell = (size_t)fy * pts->nx + (size_t)fx;
    if (pts->seen[cell / 8u] & (1u << (cell % 8u))) {
        ++pts->merged;
        return;
    }
    pts->seen[cell / 8u] = (unsigned char)(pts->seen[cell / 8u] | (1u << (cell % 8u)));
    if (pts->in_path == 0u) {
        fputs("<path class=\"points\" d=\"", pts->svg->f);
    }
    fprintf(pts->svg->f, "M%.1f %.1fh0", sx(pts->svg, x), sy(pts->svg, y));
    ++pts->kept;
    if (++pts->in_path == SVG_DOTS_PER_PATH) {
        fprintf(pts->svg->f, "\" stroke=\"%s\" stroke-width=\"%.2f\" stroke-linecap=\"round\"/>\n",
                pts->fill, pts->dot_px);
        pts->in_path = 0u;
    }
}

void bsf_svg_points_end(bsf_svg_points_t *pts)
{
    if (pts->in_path > 0u) {
        fprintf(pts->svg->f, "\" stroke=\"%s\" stroke-width=\"%.2f\" stroke-linecap=\"round\"/>\n",
                pts->fill, pts->dot_px);
        pts->in_path = 0u;
    }
    free(pts->seen);
    pts->seen = NULL;
}

void bsf_svg_legend(bsf_svg_t *svg, const bsf_svg_legend_item_t *items, size_t n)
{
    /* One row under the map, items side by side: nothing of the map hidden. */
    const double cy = height_px(svg) - 40.0;
    double kx = svg->margin_px;
    size_t i;
    fputs("<g id=\"legend\" font-family=\"sans-serif\" font-size=\"13\">\n", svg->f);
    for (i = 0; i < n; ++i) {
        switch (items[i].key) {
        case BSF_SVG_KEY_LINE:
        case BSF_SVG_KEY_DASH:
            fprintf(svg->f,
                    "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
                    "stroke-width=\"2.5\"%s/>\n",
                    kx, cy, kx + 22.0, cy, items[i].colour,
                    items[i].key == BSF_SVG_KEY_DASH ? " stroke-dasharray=\"5,3\"" : "");
            break;
        case BSF_SVG_KEY_DOT:
            fprintf(svg->f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>\n", kx + 11.0,
                    cy, items[i].colour);
            break;
        case BSF_SVG_KEY_VERTEX:
            fprintf(svg->f,
                    "<rect x=\"%.1f\" y=\"%.1f\" width=\"8\" height=\"8\" fill=\"%s\" "
                    "stroke=\"white\"/>\n",
                    kx + 7.0, cy - 4.0, items[i].colour);
            break;
        }
        fprintf(svg->f, "<text x=\"%.1f\" y=\"%.1f\">", kx + 28.0, cy + 4.5);
        put_escaped(svg->f, items[i].text);
        fputs("</text>\n", svg->f);
        kx += 28.0 + 7.0 * (double)strlen(items[i].text) + 24.0;
    }
    fputs("</g>\n", svg->f);
}

int bsf_svg_end(bsf_svg_t *svg, const char *legend)
{
    /* Largest 1/2/5 x 10^k metres not longer than a quarter of the width. */
    const double span = svg->max_x - svg->min_x;
    const double target = span / 4.0;
    double len = pow(10.0, floor(log10(target)));
    double x0, y0, x1;
    grid_labels(svg);
    if (2.0 * len <= target)
        len *= 2.0;
    if (2.5 * len <= target)
        len *= 2.5;
    x0 = svg->margin_px;
    y0 = height_px(svg) - 12.0;
    x1 = x0 + len * svg->px_per_m;
    fprintf(svg->f,
            "<g id=\"scale-bar\" stroke=\"black\" stroke-width=\"2\"><line x1=\"%.1f\" y1=\"%.1f\" "
            "x2=\"%.1f\" "
            "y2=\"%.1f\"/><line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/>"
            "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"/></g>\n",
            x0, y0, x1, y0, x0, y0 - 5.0, x0, y0 + 3.0, x1, y0 - 5.0, x1, y0 + 3.0);
    fprintf(svg->f,
            "<text x=\"%.1f\" y=\"%.1f\" font-family=\"sans-serif\" font-size=\"12\">%g m</text>\n",
            x1 + 6.0, y0 + 4.0, len);
    if (legend != NULL) {
        fprintf(svg->f, "<text x=\"%.1f\" y=\"%.1f\" font-family=\"sans-serif\" font-size=\"12\">",
                x1 + 60.0, y0 + 4.0);
        put_escaped(svg->f, legend);
        fputs("</text>\n", svg->f);
    }
    fputs("</svg>\n", svg->f);
    return ferror(svg->f) ? -1 : 0;
}
