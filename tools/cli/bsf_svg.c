/* SPDX-License-Identifier: MIT */
#include "bsf_svg.h"

#include <math.h>
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
    return 2.0 * s->margin_px + (s->max_y - s->min_y) * s->px_per_m + 30.0;
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

void bsf_svg_text(bsf_svg_t *svg, double x, double y, double size_px, const char *text)
{
    fprintf(svg->f, "<text x=\"%.2f\" y=\"%.2f\" font-family=\"sans-serif\" font-size=\"%.1f\">",
            sx(svg, x), sy(svg, y), size_px);
    put_escaped(svg->f, text);
    fputs("</text>\n", svg->f);
}

int bsf_svg_end(bsf_svg_t *svg, const char *legend)
{
    /* Largest 1/2/5 x 10^k metres not longer than a quarter of the width. */
    const double span = svg->max_x - svg->min_x;
    const double target = span / 4.0;
    double len = pow(10.0, floor(log10(target)));
    double x0, y0, x1;
    if (2.0 * len <= target)
        len *= 2.0;
    if (2.5 * len <= target)
        len *= 2.5;
    x0 = svg->margin_px;
    y0 = height_px(svg) - 12.0;
    x1 = x0 + len * svg->px_per_m;
    fprintf(svg->f,
            "<g stroke=\"black\" stroke-width=\"2\"><line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" "
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
