/* SPDX-License-Identifier: MIT */
/*
 * align_odometry.c - odometry sources for `bsf extract --map --align`.
 */
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

#ifdef BSF_HAVE_ZLIB /* only the gzip edge reader stores edges */
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
#endif

int odo_edges_load(const char *path, odo_edges_t *e)
{
#ifdef BSF_HAVE_ZLIB
    char line[4096];
    int seq = 0;
    unsigned long n_edges = 0;
    gzFile gz;
    memset(e, 0, sizeof *e);
    gz = gzopen(path, "rb");
    if (gz == NULL) {
        fail_msg("%s: cannot open for its pose-graph edges", path);
        return -1;
    }
    while (gzgets(gz, line, (int)sizeof line) != NULL) {
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
                gzclose(gz);
                odo_edges_free(e);
                fail_msg("out of memory reading the edges of %s", path);
                return -1;
            }
            ++n_edges;
        }
    }
    gzclose(gz);
    if (n_edges == 0u) {
        odo_edges_free(e);
        fail_msg("%s: no sequential EDGE2 edges (a '#SEQUENTIAL' section of 'EDGE2 k k+1 dx dy "
                 "dtheta' lines) for --odometry edges",
                 path);
        return -1;
    }
    return 0;
#else
    memset(e, 0, sizeof *e);
    fail_msg("%s: --odometry edges needs a build with zlib", path);
    return -1;
#endif
}

void odo_edges_free(odo_edges_t *e)
{
    free(e->motion);
    free(e->have);
    memset(e, 0, sizeof *e);
}
