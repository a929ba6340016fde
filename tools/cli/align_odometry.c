/* SPDX-License-Identifier: MIT */
/*
 * align_odometry.c - odometry sources for `bsf extract --map --align`.
 */
/* popen/pclose for the gzip fallback without zlib */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "align_odometry.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef BSF_HAVE_ZLIB
#include <zlib.h>
#endif

#include "tool.h"

/* Largest scan index an edge may name (a corrupt line must not allocate
 * gigabytes). */
#define ODO_MAX_INDEX 10000000ul

odo_pose_t odo_compose(odo_pose_t a, odo_pose_t b)
{
    odo_pose_t r;
    const double c = cos(a.t), s = sin(a.t);
    r.x = a.x + c * b.x - s * b.y;
    r.y = a.y + s * b.x + c * b.y;
    r.t = a.t + b.t;
    return r;
}

odo_pose_t odo_between(odo_pose_t a, odo_pose_t b)
{
    odo_pose_t r;
    const double c = cos(a.t), s = sin(a.t);
    const double dx = b.x - a.x, dy = b.y - a.y;
    r.x = c * dx + s * dy;
    r.y = -s * dx + c * dy;
    r.t = remainder(b.t - a.t, 2.0 * M_PI);
    return r;
}

static int edges_put(odo_edges_t *e, unsigned long b, double dx, double dy, double dt)
{
    if (b >= e->n) {
        size_t n = e->n ? e->n : 1024u;
        odo_pose_t *m;
        uint8_t *h;
        while (n <= b) {
            n *= 2u;
        }
        m = realloc(e->motion, n * sizeof *m);
        if (m == NULL) {
            return -1;
        }
        e->motion = m;
        h = realloc(e->have, n);
        if (h == NULL) {
            return -1;
        }
        e->have = h;
        memset(e->have + e->n, 0, n - e->n);
        e->n = n;
    }
    e->motion[b].x = dx;
    e->motion[b].y = dy;
    e->motion[b].t = dt;
    e->have[b] = 1u;
    return 0;
}

/* Lines of a log, gzip or plain: zlib when the build has it, else the
 * system's `gzip -dcf` (which passes plain text through), as the CARMEN
 * reader does. */
typedef struct {
#ifdef BSF_HAVE_ZLIB
    gzFile gz;
#else
    FILE *pipe;
#endif
} line_src_t;

static int src_open(line_src_t *src, const char *path)
{
#ifdef BSF_HAVE_ZLIB
    src->gz = gzopen(path, "rb");
    return src->gz != NULL ? 0 : -1;
#else
    FILE *probe = fopen(path, "rb");
    if (probe == NULL) {
        return -1; /* a clear "cannot open" rather than gzip's complaint */
    }
    fclose(probe);
    src->pipe = carmen_gzip_pipe(path, "-dcf");
    return src->pipe != NULL ? 0 : -1;
#endif
}

static char *src_gets(line_src_t *src, char *line, int cap)
{
#ifdef BSF_HAVE_ZLIB
    return gzgets(src->gz, line, cap);
#else
    return fgets(line, cap, src->pipe);
#endif
}

/* 0 when the whole input was read without error. */
static int src_close(line_src_t *src)
{
#ifdef BSF_HAVE_ZLIB
    int err = 0;
    (void)gzerror(src->gz, &err);
    return (gzclose(src->gz) == Z_OK && (err == Z_OK || err == Z_STREAM_END)) ? 0 : -1;
#else
    return pclose(src->pipe) == 0 ? 0 : -1;
#endif
}

int odo_edges_load(const char *path, odo_edges_t *e)
{
    char line[4096];
    int seq = 0;
    unsigned long n_edges = 0;
    line_src_t src;
    memset(e, 0, sizeof *e);
    if (src_open(&src, path) != 0) {
        fail_msg("%s: cannot open for its pose-graph edges", path);
        return -1;
    }
    while (src_gets(&src, line, (int)sizeof line) != NULL) {
        unsigned long a, b;
        double dx, dy, dt;
        if (strncmp(line, "#SEQUENTIAL", 11) == 0) {
            seq = 1;
        } else if (line[0] == '#') {
            seq = 0;
        } else if (seq && sscanf(line, "EDGE2 %lu %lu %lf %lf %lf", &a, &b, &dx, &dy, &dt) == 5 &&
                   b == a + 1u && b < ODO_MAX_INDEX && isfinite(dx) && isfinite(dy) &&
                   isfinite(dt) && fabs(dx) < 1e6 && fabs(dy) < 1e6 && fabs(dt) < 1e3) {
            if (edges_put(e, b, dx, dy, dt) != 0) {
                (void)src_close(&src);
                odo_edges_free(e);
                fail_msg("out of memory reading the edges of %s", path);
                return -1;
            }
            ++n_edges;
        }
    }
    if (src_close(&src) != 0) {
        odo_edges_free(e);
        fail_msg("%s: read error (a damaged gzip file?) while reading its pose-graph edges", path);
        return -1;
    }
    if (n_edges == 0u) {
        odo_edges_free(e);
        fail_msg("%s: no sequential EDGE2 edges (a '#SEQUENTIAL' section of 'EDGE2 k k+1 dx dy "
                 "dtheta' lines) for --odometry edges",
                 path);
        return -1;
    }
    return 0;
}

void odo_edges_free(odo_edges_t *e)
{
    free(e->motion);
    free(e->have);
    memset(e, 0, sizeof *e);
}
