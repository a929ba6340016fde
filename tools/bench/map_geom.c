/* SPDX-License-Identifier: MIT */
/*
 * map_geom.c - curves, nearest distances, histograms and the occupancy-grid
 * baseline of the map benchmark (map_geom.h).
 */
#include "map_geom.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    size_t nc;
    void *q;
    if (need <= *cap) {
        return 0;
    }
    nc = *cap ? *cap : 1024u;
    while (nc < need) {
        nc *= 2u;
    }
    q = realloc(*p, nc * elem);
    if (q == NULL) {
        return -1;
    }
    *p = q;
    *cap = nc;
    return 0;
}

void mg_curves_init(mg_curves_t *c)
{
    memset(c, 0, sizeof *c);
}

void mg_curves_free(mg_curves_t *c)
{
    free(c->seg);
    free(c->vtx);
    mg_curves_init(c);
}

void mg_curves_clear(mg_curves_t *c)
{
    c->n_seg = 0;
    c->n_vtx = 0;
    c->n_curves = 0;
    c->length = 0.0;
}

int mg_curves_add_polyline(mg_curves_t *c, const double *xy, size_t n)
{
    size_t k;
    if (n < 2u) {
        return -1;
    }
    if (grow((void **)&c->seg, &c->cap_seg, c->n_seg + n - 1u, 4u * sizeof(float)) != 0) {
        return -1;
    }
    for (k = 0; k + 1u < n; ++k) {
        float *s = &c->seg[4u * c->n_seg++];
        s[0] = (float)xy[2u * k];
        s[1] = (float)xy[2u * k + 1u];
        s[2] = (float)xy[2u * k + 2u];
        s[3] = (float)xy[2u * k + 3u];
        c->length += hypot(xy[2u * k + 2u] - xy[2u * k], xy[2u * k + 3u] - xy[2u * k + 1u]);
    }
    ++c->n_curves;
    return 0;
}

int mg_curves_add_vertex(mg_curves_t *c, double x, double y)
{
    if (grow((void **)&c->vtx, &c->cap_vtx, c->n_vtx + 1u, 2u * sizeof(double)) != 0) {
        return -1;
    }
    c->vtx[2u * c->n_vtx] = x;
    c->vtx[2u * c->n_vtx + 1u] = y;
    ++c->n_vtx;
    return 0;
}

/* The clamped uniform quadratic B-spline on span s of `spans` at u in [0, 1]:
 * the closed forms of bsf_bspline.h, in double. */
static void bspline_point(const double *xy, size_t spans, size_t s, double u, double *x, double *y)
{
    const double a = (1.0 - u) * (1.0 - u), b = 2.0 * u * (1.0 - u), c = u * u;
    double w0, w1, w2;
    if (spans == 1u) {
        w0 = a;
        w1 = b;
        w2 = c;
    } else if (s == 0u) {
        w0 = a;
        w1 = b + 0.5 * c;
        w2 = 0.5 * c;
    } else if (s + 1u == spans) {
        w0 = 0.5 * a;
        w1 = 0.5 * a + b;
        w2 = c;
    } else {
        w0 = 0.5 * a;
        w1 = 0.5 * a + b + 0.5 * c;
        w2 = 0.5 * c;
    }
    *x = w0 * xy[2u * s] + w1 * xy[2u * s + 2u] + w2 * xy[2u * s + 4u];
    *y = w0 * xy[2u * s + 1u] + w1 * xy[2u * s + 3u] + w2 * xy[2u * s + 5u];
}

int mg_curves_add_bspline(mg_curves_t *c, const double *xy, size_t n_ctrl, const uint8_t *vertex)
{
    static double pts[2u * (MG_SAMPLES_PER_SPAN * 4096u + 1u)];
    size_t spans, s, k, n = 0;
    if (n_ctrl < 3u || n_ctrl > 4096u) {
        return -1;
    }
    spans = n_ctrl - 2u;
    for (s = 0; s < spans; ++s) {
        for (k = (s == 0u ? 0u : 1u); k <= MG_SAMPLES_PER_SPAN; ++k) {
            bspline_point(xy, spans, s, (double)k / MG_SAMPLES_PER_SPAN, &pts[2u * n],
                          &pts[2u * n + 1u]);
            ++n;
        }
    }
    if (mg_curves_add_polyline(c, pts, n) != 0) {
        return -1;
    }
    if (vertex != NULL) {
        for (k = 0; k + 1u < n_ctrl; ++k) {
            if (vertex[k] && vertex[k + 1u]) {
                if (mg_curves_add_vertex(c, xy[2u * k], xy[2u * k + 1u]) != 0) {
                    return -1;
                }
                ++k;
            }
        }
    }
    return 0;
}

/* Index of the first sample after i (step +1) or before it (-1), within
 * [lo, hi], at least MG_FOLD_CHORD of arc away; -1 when there is none. */
static long fold_reach(const double *arc, long i, long lo, long hi, long step)
{
    long j = i + step;
    while (j >= lo && j <= hi && fabs(arc[j] - arc[i]) < MG_FOLD_CHORD) {
        j += step;
    }
    return j >= lo && j <= hi ? j : -1;
}

/* 1 when the chords a -> i and i -> b turn by more than MG_FOLD_TURN_DEG. */
static int folds_back(const double *p, long a, long i, long b)
{
    const double ux = p[2 * i] - p[2 * a], uy = p[2 * i + 1] - p[2 * a + 1];
    const double vx = p[2 * b] - p[2 * i], vy = p[2 * b + 1] - p[2 * i + 1];
    const double c = cos(MG_FOLD_TURN_DEG * 3.14159265358979323846 / 180.0);
    return ux * vx + uy * vy < c * hypot(ux, uy) * hypot(vx, vy);
}

int mg_bspline_folds(const double *xy, size_t n_ctrl, const uint8_t *vertex, mg_folds_t *f)
{
    static double pts[2u * (MG_FOLD_SAMPLES_PER_SPAN * 4096u + 1u)];
    static double arc[MG_FOLD_SAMPLES_PER_SPAN * 4096u + 1u];
    static uint8_t cut[4096u];
    size_t spans, s, k, n = 0;
    long lo = 0;
    if (n_ctrl < 3u || n_ctrl > 4096u) {
        return -1;
    }
    spans = n_ctrl - 2u;
    memset(cut, 0, spans + 1u);
    /* a vertex (slots k, k + 1) is the curve at the knot between spans k - 1 and k */
    for (k = 0; vertex != NULL && k + 1u < n_ctrl; ++k) {
        if (vertex[k] && vertex[k + 1u]) {
            cut[k] = k > 0u && k < spans;
            ++k;
        }
    }
    for (s = 0; s < spans; ++s) {
        for (k = (s == 0u ? 0u : 1u); k <= MG_FOLD_SAMPLES_PER_SPAN; ++k) {
            bspline_point(xy, spans, s, (double)k / MG_FOLD_SAMPLES_PER_SPAN, &pts[2u * n],
                          &pts[2u * n + 1u]);
            arc[n] = n == 0u ? 0.0
                             : arc[n - 1u] + hypot(pts[2u * n] - pts[2u * n - 2u],
                                                   pts[2u * n + 1u] - pts[2u * n - 1u]);
            ++n;
        }
    }
    /* smooth pieces between vertices (and the curve's ends) */
    for (s = 1; s <= spans; ++s) {
        const long hi = (long)(s * MG_FOLD_SAMPLES_PER_SPAN);
        long i;
        int in_fold = 0;
        if (s < spans && !cut[s]) {
            continue;
        }
        for (i = lo; i <= hi; ++i) {
            const long a = fold_reach(arc, i, lo, hi, -1);
            const long b = fold_reach(arc, i, lo, hi, 1);
            const int back = a >= 0 && b >= 0 && folds_back(pts, a, i, b);
            f->folds += back && !in_fold ? 1u : 0u;
            in_fold = back;
        }
        if (s < spans) {
            /* the vertex's own turn, between its two legs */
            const long a = fold_reach(arc, hi, lo, hi, -1);
            const long b = fold_reach(arc, hi, hi, (long)n - 1, 1);
            f->sharp_vertices += a >= 0 && b >= 0 && folds_back(pts, a, hi, b) ? 1u : 0u;
        }
        lo = hi;
    }
    return 0;
}

#define MG_CELL 0.1

int mg_index_build(mg_index_t *ix, const mg_curves_t *c)
{
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    size_t i, pass, total = 0;
    size_t *fill = NULL;
    memset(ix, 0, sizeof *ix);
    ix->c = c;
    ix->cell = MG_CELL;
    for (i = 0; i < c->n_seg; ++i) {
        const float *s = &c->seg[4u * i];
        x0 = fmin(x0, fmin((double)s[0], (double)s[2]));
        x1 = fmax(x1, fmax((double)s[0], (double)s[2]));
        y0 = fmin(y0, fmin((double)s[1], (double)s[3]));
        y1 = fmax(y1, fmax((double)s[1], (double)s[3]));
    }
    if (c->n_seg == 0u) {
        x0 = y0 = x1 = y1 = 0.0;
    }
    ix->x0 = x0 - MG_CELL;
    ix->y0 = y0 - MG_CELL;
    ix->nx = (size_t)((x1 - x0) / MG_CELL) + 3u;
    ix->ny = (size_t)((y1 - y0) / MG_CELL) + 3u;
    ix->start = (uint32_t *)calloc(ix->nx * ix->ny + 1u, sizeof(uint32_t));
    fill = (size_t *)calloc(ix->nx * ix->ny, sizeof(size_t));
    if (ix->start == NULL || fill == NULL) {
        free(fill);
        mg_index_free(ix);
        return -1;
    }
    /* two passes: count per cell, then place */
    for (pass = 0; pass < 2u; ++pass) {
        for (i = 0; i < c->n_seg; ++i) {
            const float *s = &c->seg[4u * i];
            const size_t cx0 = (size_t)((fmin((double)s[0], (double)s[2]) - ix->x0) / MG_CELL);
            const size_t cx1 = (size_t)((fmax((double)s[0], (double)s[2]) - ix->x0) / MG_CELL);
            const size_t cy0 = (size_t)((fmin((double)s[1], (double)s[3]) - ix->y0) / MG_CELL);
            const size_t cy1 = (size_t)((fmax((double)s[1], (double)s[3]) - ix->y0) / MG_CELL);
            size_t cx, cy;
            for (cy = cy0; cy <= cy1 && cy < ix->ny; ++cy) {
                for (cx = cx0; cx <= cx1 && cx < ix->nx; ++cx) {
                    const size_t cell = cy * ix->nx + cx;
                    if (pass == 0u) {
                        ++ix->start[cell + 1u];
                    } else {
                        ix->idx[ix->start[cell] + fill[cell]++] = (uint32_t)i;
                    }
                }
            }
        }
        if (pass == 0u) {
            for (i = 0; i < ix->nx * ix->ny; ++i) {
                ix->start[i + 1u] += ix->start[i];
            }
            total = ix->start[ix->nx * ix->ny];
            ix->idx = (uint32_t *)malloc((total ? total : 1u) * sizeof(uint32_t));
            if (ix->idx == NULL) {
                free(fill);
                mg_index_free(ix);
                return -1;
            }
        }
    }
    free(fill);
    return 0;
}

void mg_index_free(mg_index_t *ix)
{
    free(ix->start);
    free(ix->idx);
    ix->start = NULL;
    ix->idx = NULL;
}

static double seg_dist2(const float *s, double x, double y)
{
    const double ax = (double)s[0], ay = (double)s[1];
    const double dx = (double)s[2] - ax, dy = (double)s[3] - ay;
    const double l2 = dx * dx + dy * dy;
    double t = l2 > 0.0 ? ((x - ax) * dx + (y - ay) * dy) / l2 : 0.0;
    double ex, ey;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    ex = ax + t * dx - x;
    ey = ay + t * dy - y;
    return ex * ex + ey * ey;
}

static double ring_search(const mg_index_t *ix, long cx, long cy, long r, double x, double y)
{
    double best = 1e300;
    long i, j;
    for (j = cy - r; j <= cy + r; ++j) {
        if (j < 0 || j >= (long)ix->ny) {
            continue;
        }
        for (i = cx - r; i <= cx + r; ++i) {
            size_t cell, k;
            if (i < 0 || i >= (long)ix->nx) {
                continue;
            }
            cell = (size_t)j * ix->nx + (size_t)i;
            for (k = ix->start[cell]; k < ix->start[cell + 1u]; ++k) {
                const double d2 = seg_dist2(&ix->c->seg[4u * ix->idx[k]], x, y);
                best = d2 < best ? d2 : best;
            }
        }
    }
    return sqrt(best);
}

double mg_index_dist(const mg_index_t *ix, double x, double y)
{
    const long cx = (long)floor((x - ix->x0) / ix->cell);
    const long cy = (long)floor((y - ix->y0) / ix->cell);
    double d;
    if (ix->c->n_seg == 0u) {
        return MG_DIST_MAX;
    }
    /* a segment within one cell of the point crosses one of the 3x3 cells */
    d = ring_search(ix, cx, cy, 1, x, y);
    if (d > ix->cell) {
        d = ring_search(ix, cx, cy, (long)ceil(MG_DIST_MAX / ix->cell), x, y);
    }
    return d < MG_DIST_MAX ? d : MG_DIST_MAX;
}

void mg_hist_add(mg_hist_t *h, double d)
{
    size_t b = d <= 0.0 ? 0u : (size_t)(d / (MG_DIST_MAX / MG_HIST_BINS));
    h->bin[b < MG_HIST_BINS ? b : MG_HIST_BINS]++;
    h->n++;
    h->max = d > h->max ? d : h->max;
}

double mg_hist_quantile(const mg_hist_t *h, double q)
{
    uint64_t want, seen = 0;
    size_t b;
    if (h->n == 0u) {
        return 0.0;
    }
    want = (uint64_t)ceil(q * (double)h->n);
    want = want < 1u ? 1u : want;
    for (b = 0; b <= MG_HIST_BINS; ++b) {
        seen += h->bin[b];
        if (seen >= want) {
            return b == MG_HIST_BINS ? h->max : (double)(b + 1u) * (MG_DIST_MAX / MG_HIST_BINS);
        }
    }
    return h->max;
}

double mg_hist_share_below(const mg_hist_t *h, double d)
{
    const size_t lim = (size_t)(d / (MG_DIST_MAX / MG_HIST_BINS) + 0.5);
    uint64_t seen = 0;
    size_t b;
    if (h->n == 0u) {
        return 0.0;
    }
    for (b = 0; b < lim && b < MG_HIST_BINS; ++b) {
        seen += h->bin[b];
    }
    return (double)seen / (double)h->n;
}

void mg_points_init(mg_points_t *p)
{
    memset(p, 0, sizeof *p);
}

void mg_points_free(mg_points_t *p)
{
    free(p->xy);
    free(p->scan_of);
    free(p->origin);
    mg_points_init(p);
}

int mg_points_begin_scan(mg_points_t *p, double x, double y)
{
    if (grow((void **)&p->origin, &p->cap_scans, p->n_scans + 1u, 2u * sizeof(double)) != 0) {
        return -1;
    }
    p->origin[2u * p->n_scans] = x;
    p->origin[2u * p->n_scans + 1u] = y;
    ++p->n_scans;
    return 0;
}

int mg_points_add(mg_points_t *p, double x, double y)
{
    if (p->n_scans == 0u) {
        return -1;
    }
    if (grow((void **)&p->xy, &p->cap, p->n + 1u, 2u * sizeof(float)) != 0 ||
        grow((void **)&p->scan_of, &p->cap_scan_of, p->n + 1u, sizeof(uint32_t)) != 0) {
        return -1;
    }
    p->xy[2u * p->n] = (float)x;
    p->xy[2u * p->n + 1u] = (float)y;
    p->scan_of[p->n] = (uint32_t)(p->n_scans - 1u);
    ++p->n;
    return 0;
}

size_t mg_gzip_size(const uint8_t *buf, size_t n)
{
    z_stream zs;
    uint8_t out[65536];
    size_t total = 0;
    int rc;
    memset(&zs, 0, sizeof zs);
    if (deflateInit2(&zs, 9, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK) {
        return 0;
    }
    zs.next_in = (Bytef *)(uintptr_t)buf;
    zs.avail_in = (uInt)n;
    do {
        zs.next_out = out;
        zs.avail_out = sizeof out;
        rc = deflate(&zs, Z_FINISH);
        total += sizeof out - zs.avail_out;
    } while (rc == Z_OK);
    deflateEnd(&zs);
    return rc == Z_STREAM_END ? total : 0u;
}

/* zlib-compress buf into a fresh heap block (PNG's IDAT). */
static uint8_t *zlib_deflate(const uint8_t *buf, size_t n, size_t *out_n)
{
    uLongf cap = compressBound((uLong)n);
    uint8_t *out = (uint8_t *)malloc(cap);
    if (out == NULL || compress2(out, &cap, buf, (uLong)n, 9) != Z_OK) {
        free(out);
        return NULL;
    }
    *out_n = cap;
    return out;
}

static void put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

/* One PNG chunk's bytes (length, type, data, CRC) appended to f (may be NULL). */
static size_t png_chunk(FILE *f, const char *type, const uint8_t *data, size_t n)
{
    uint8_t hdr[8], crc[4];
    uLong c = crc32(0L, (const Bytef *)type, 4u);
    if (n > 0u) {
        c = crc32(c, data, (uInt)n);
    }
    put_be32(hdr, (uint32_t)n);
    memcpy(hdr + 4, type, 4u);
    put_be32(crc, (uint32_t)c);
    if (f != NULL) {
        fwrite(hdr, 1, 8u, f);
        if (n > 0u) {
            fwrite(data, 1, n, f);
        }
        fwrite(crc, 1, 4u, f);
    }
    return 12u + n;
}

int mg_grid_baseline(const mg_points_t *pts, double cell, const char *pgm_gz_path,
                     const char *png_path, mg_grid_result_t *out)
{
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    uint32_t *hit, *miss;
    uint8_t *img, *rows;
    size_t i, nx, ny, hdr_len, z_n = 0, png_n;
    char hdr[64];
    uint8_t *z;
    int rc = 0;
    memset(out, 0, sizeof *out);
    out->cell = cell;
    for (i = 0; i < pts->n; ++i) {
        x0 = fmin(x0, (double)pts->xy[2u * i]);
        x1 = fmax(x1, (double)pts->xy[2u * i]);
        y0 = fmin(y0, (double)pts->xy[2u * i + 1u]);
        y1 = fmax(y1, (double)pts->xy[2u * i + 1u]);
    }
    for (i = 0; i < pts->n_scans; ++i) {
        x0 = fmin(x0, pts->origin[2u * i]);
        x1 = fmax(x1, pts->origin[2u * i]);
        y0 = fmin(y0, pts->origin[2u * i + 1u]);
        y1 = fmax(y1, pts->origin[2u * i + 1u]);
    }
    if (pts->n == 0u) {
        return -1;
    }
    x0 -= cell;
    y0 -= cell;
    nx = (size_t)((x1 - x0) / cell) + 2u;
    ny = (size_t)((y1 - y0) / cell) + 2u;
    out->nx = nx;
    out->ny = ny;
    hit = (uint32_t *)calloc(nx * ny, sizeof(uint32_t));
    miss = (uint32_t *)calloc(nx * ny, sizeof(uint32_t));
    img = (uint8_t *)malloc(nx * ny + 64u);
    rows = (uint8_t *)malloc((nx + 1u) * ny);
    if (hit == NULL || miss == NULL || img == NULL || rows == NULL) {
        free(hit);
        free(miss);
        free(img);
        free(rows);
        return -1;
    }
    for (i = 0; i < pts->n; ++i) {
        const double *o = &pts->origin[2u * pts->scan_of[i]];
        long cx = (long)((o[0] - x0) / cell), cy = (long)((o[1] - y0) / cell);
        const long ex = (long)(((double)pts->xy[2u * i] - x0) / cell);
        const long ey = (long)(((double)pts->xy[2u * i + 1u] - y0) / cell);
        const long dx = labs(ex - cx), dy = -labs(ey - cy);
        const long sx = cx < ex ? 1 : -1, sy = cy < ey ? 1 : -1;
        long err = dx + dy;
        while (cx != ex || cy != ey) {
            const long e2 = 2 * err;
            ++miss[(size_t)cy * nx + (size_t)cx];
            if (e2 >= dy) {
                err += dy;
                cx += sx;
            }
            if (e2 <= dx) {
                err += dx;
                cy += sy;
            }
        }
        ++hit[(size_t)ey * nx + (size_t)ex];
    }
    /* PGM rows top (largest y) first, map_saver's values: 0 occupied, 254
     * free, 205 unknown */
    hdr_len = (size_t)snprintf(hdr, sizeof hdr, "P5\n%lu %lu\n255\n", (unsigned long)nx,
                               (unsigned long)ny);
    memcpy(img, hdr, hdr_len);
    for (i = 0; i < ny; ++i) {
        const size_t gy = ny - 1u - i;
        size_t gx;
        rows[i * (nx + 1u)] = 0u; /* PNG filter: none */
        for (gx = 0; gx < nx; ++gx) {
            const uint32_t h = hit[gy * nx + gx], m = miss[gy * nx + gx];
            uint8_t v = 205u;
            if (h + m > 0u) {
                const double p = (double)h / (double)(h + m);
                if (p > 0.25) {
                    v = 0u;
                    ++out->occupied;
                } else {
                    v = 254u;
                    ++out->free_cells;
                }
            }
            img[hdr_len + i * nx + gx] = v;
            rows[i * (nx + 1u) + 1u + gx] = v;
        }
    }
    out->pgm_bytes = hdr_len + nx * ny;
    out->pgm_gz_bytes = mg_gzip_size(img, out->pgm_bytes);
    z = zlib_deflate(rows, (nx + 1u) * ny, &z_n);
    if (out->pgm_gz_bytes == 0u || z == NULL) {
        rc = -1;
    } else {
        static const uint8_t sig[8] = {137u, 80u, 78u, 71u, 13u, 10u, 26u, 10u};
        uint8_t ihdr[13];
        FILE *f = png_path != NULL ? fopen(png_path, "wb") : NULL;
        if (png_path != NULL && f == NULL) {
            rc = -1;
        }
        put_be32(ihdr, (uint32_t)nx);
        put_be32(ihdr + 4, (uint32_t)ny);
        ihdr[8] = 8u;  /* bit depth */
        ihdr[9] = 0u;  /* greyscale */
        ihdr[10] = 0u; /* deflate */
        ihdr[11] = 0u; /* adaptive filtering (per-row filter byte) */
        ihdr[12] = 0u; /* no interlace */
        if (f != NULL) {
            fwrite(sig, 1, 8u, f);
        }
        png_n = 8u + png_chunk(f, "IHDR", ihdr, sizeof ihdr) + png_chunk(f, "IDAT", z, z_n) +
                png_chunk(f, "IEND", NULL, 0u);
        out->png_bytes = png_n;
        if (f != NULL && fclose(f) != 0) {
            rc = -1;
        }
    }
    if (rc == 0 && pgm_gz_path != NULL) {
        gzFile g = gzopen(pgm_gz_path, "wb9");
        if (g == NULL || gzwrite(g, img, (unsigned)out->pgm_bytes) != (int)out->pgm_bytes) {
            rc = -1;
        }
        if (g != NULL && gzclose(g) != Z_OK) {
            rc = -1;
        }
    }
    free(z);
    free(hit);
    free(miss);
    free(img);
    free(rows);
    return rc;
}

/* Frames before the state is recorded, so the robot's pending changes are out. */
#define MG_SNAP_WARMUP 8
#define MG_SNAP_STATES 8192

long mg_map_once_bytes(bsf_map_t *copy, const bsf_map_t *map, const bsf_pose_t *pose,
                       uint16_t budget)
{
    static uint32_t st_next[MG_SNAP_STATES], st_bytes[MG_SNAP_STATES];
    static uint16_t st_pos[MG_SNAP_STATES], st_wraps[MG_SNAP_STATES];
    static uint8_t buf[BSF_MAP_FRAME_MAX_SIZE];
    static bsf_result_t empty;
    size_t n_st = 0;
    unsigned wraps = 0;
    int guard = 0;
    if (bsf_map_feature_count(map) == 0u) {
        return 0;
    }
    memcpy(copy, map, sizeof *map);
    copy->params.snapshot_budget = budget;
    copy->snapshot_next = 0u;
    copy->snapshot_pos = 0u;
    copy->params.frame_interval = 1u;
    memset(&empty, 0, sizeof empty);
    while (guard++ < 100000) {
        size_t len = 0;
        size_t k;
        /* a scan without features lets the frame interval pass */
        if (bsf_map_fuse(copy, &empty, pose) < 0 ||
            bsf_map_encode(copy, NULL, buf, sizeof buf, &len) != BSF_OK || len == 0u) {
            return -1;
        }
        if (guard < MG_SNAP_WARMUP || bsf_map_pending(copy)) {
            continue;
        }
        if (n_st > 0u && (copy->snapshot_next < st_next[n_st - 1u] ||
                          (copy->snapshot_next == st_next[n_st - 1u] &&
                           copy->snapshot_pos <= st_pos[n_st - 1u]))) {
            ++wraps;
        }
        for (k = 0; k < n_st; ++k) {
            if (st_next[k] == copy->snapshot_next && st_pos[k] == copy->snapshot_pos) {
                const unsigned rounds = wraps - st_wraps[k];
                if (rounds == 0u) {
                    return -1;
                }
                return (long)((copy->stats.record_bytes[4] - st_bytes[k]) / rounds);
            }
        }
        if (n_st == MG_SNAP_STATES) {
            return -1;
        }
        st_next[n_st] = copy->snapshot_next;
        st_pos[n_st] = copy->snapshot_pos;
        st_bytes[n_st] = copy->stats.record_bytes[4];
        st_wraps[n_st] = (uint16_t)wraps;
        ++n_st;
    }
    return -1;
}
