/* SPDX-License-Identifier: MIT */
/*
 * bench_map - the fused map against the per-scan stream and an occupancy
 * grid, on the SLAM-corrected logs (poses are inputs) and on synthetic scenes
 * with known geometry and true poses. One column per input, one row per
 * figure; docs/MAP.md pastes the output.
 *
 *   bench_map [--data DIR] [--scans N] [--poses N] [--grid-out DIR] [--only NAME]
 *             [--pose-every K] [--map-param NAME=VALUE]... [--check]
 *
 * --data: the shared data directory (its alt/ holds the corrected logs;
 * default: the build's BSF_SHARED_DIR/data); a log that is absent is left out
 * with a message. --scans N: only the first N scans of each log (quick runs).
 * --poses N: poses per synthetic scene (default 300). --grid-out DIR: also
 * write each input's grid as NAME.pgm.gz and NAME.png. --only NAME: one input
 * (intel, mit, fr079, office, angles, curved). --pose-every K: a pose record
 * every K scans (default 1; 0: none), counted apart from the map.
 * --map-param NAME=VALUE: a field of bsf_map_params_t other than the default
 * (match_dist, match_angle, vertex_dist, ctrl_spacing, send_tol, weight_cap,
 * forget_after, frame_interval, match_dist_near, match_dist_per_m,
 * simplify_tol, snapshot_budget), to
 * measure a trade-off. --check: exit 1 unless every
 * scan was extracted and fused, the receiver's map equals the robot's sent
 * copy feature for feature, and every figure was measured (ctest runs it on
 * a short scene).
 *
 * Definitions:
 *  - valid raw point: a return the extractor would accept (bsf_range_is_valid
 *    with the log's range limits) no farther than 30 m, in the world frame
 *    through the scan's pose;
 *  - distance to the map: to the nearest point of any map curve (curves
 *    sampled 16 times per span; resolved up to 0.5 m);
 *  - previous scan's features: each scan's valid points against the features
 *    of the scan extracted before it (world frame); with the own-scan rows it
 *    bounds what a single map can reach when poses disagree;
 *  - per-scan stream: what `bsf extract --reproducible` writes (a features
 *    frame per scan with its pose, a metadata frame every 64 scans); its
 *    coverage is each point's distance to its own scan's features;
 *  - grid: 5 cm cells, every valid point ray-cast from its scan's sensor
 *    position (map_geom.h), gmapping's occupancy threshold, PGM gzip'd and PNG;
 *  - synthetic scenes (361 beams over 270 degrees, 1 cm range noise, true
 *    poses on a loop, tools/scene): curve to true surface every 1 cm along
 *    the curves (quantiles per length of curve); "surface seen" is the true surface hit by a valid
 * return (2 cm bins along each shape); a corner counts as seen in a scan when bsf_truth_corner_seen
 * says so, and as one map vertex when exactly one map vertex lies within 3 cm of it;
 *  - folds: places where a curve turns back on itself (mg_bspline_folds, map_geom.h): more than
 *    150 degrees between the chords 2 cm of arc before and after a point of the B-spline, the
 *    curve cut at its vertices; a vertex turning more than 150 degrees is counted apart.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "bsf_truth.h"
#include "carmen.h"
#include "carmen_bsf.h"
#include "map_geom.h"

#ifndef BSF_SHARED_DIR_DEFAULT
#define BSF_SHARED_DIR_DEFAULT "../shared"
#endif

#define PI 3.14159265358979323846
#define RAW_RANGE_MAX 30.0f
#define GRID_CELL 0.05
#define META_EVERY 64
#define CORNER_MIN_SCANS 5
#define CORNER_MATCH 0.03
#define SEEN_BIN 0.02
#define MAX_CORNERS 256

/* One column of the table. */
typedef struct {
    const char *name;
    int synthetic;
    unsigned long scans, failed;
    /* per-scan stream */
    size_t stream_bytes, stream_gz_bytes;
    mg_hist_t own_dist;   /* raw point to its own scan's features */
    mg_hist_t prev_dist;  /* raw point to the previous scan's features: how well poses agree */
    mg_hist_t own_truth;  /* per-scan feature samples to the true surface */
    mg_folds_t own_folds; /* folds of every scan's features (world frame), summed */
    /* grid */
    mg_grid_result_t grid;
    int grid_ok;
    /* the map */
    size_t map_update_bytes, map_pose_bytes, map_once_bytes;
    uint32_t record_bytes[6];                   /* of the update stream, by record type */
    unsigned long map_frames, map_once_missing; /* forgotten features not in the snapshot */
    unsigned long map_features, map_vertices, map_forgotten, map_dropped;
    unsigned long rx_mismatch, rx_compared, fuse_failed;
    unsigned long rx_points, robot_points; /* distinct control points */
    double map_length;
    mg_hist_t map_dist; /* raw point to the final map */
    unsigned long
        miss_own_near;          /* beyond 5 cm of the map, within 5 cm of its own scan's features */
    unsigned long miss_own_far; /* beyond 5 cm of both */
    mg_hist_t map_truth;        /* map curve samples to the true surface */
    mg_folds_t map_folds;       /* folds of the receiver's final map */
    double *fuse_us;            /* host time per fuse call */
    size_t n_fuse_us;
    /* synthetic truth */
    double seen_m;
    unsigned long corners_5, corners_one, corners_many;
} column_t;

static bsf_extractor_t g_ex;
static bsf_map_t g_map;
static bsf_map_t g_map_copy;
static bsf_pose_t g_last_pose; /* the pose of the last scan fused */
static long g_pose_every = 1;  /* --pose-every */
static unsigned long g_fused;  /* scans fused in the current column */
static bsf_map_rx_t g_rx;
static bsf_decoder_t g_dec;
static bsf_frame_t g_frame;
static bsf_result_t g_res;
static uint8_t g_buf[BSF_FRAME_MAX_SIZE + BSF_MAP_FRAME_MAX_SIZE];
static const char *g_grid_out = NULL;

/* The growing per-scan stream (for its gzip'd size). */
static uint8_t *g_stream;
static size_t g_stream_n, g_stream_cap;

static int stream_append(const uint8_t *p, size_t n)
{
    if (g_stream_n + n > g_stream_cap) {
        size_t nc = g_stream_cap ? 2u * g_stream_cap : 65536u;
        uint8_t *q;
        while (nc < g_stream_n + n) {
            nc *= 2u;
        }
        q = (uint8_t *)realloc(g_stream, nc);
        if (q == NULL) {
            return -1;
        }
        g_stream = q;
        g_stream_cap = nc;
    }
    memcpy(g_stream + g_stream_n, p, n);
    g_stream_n += n;
    return 0;
}

/* One scan into the per-scan stream, as bsf extract writes it. */
/* The source name and time origin the metadata frame carries (as bsf extract). */
static const char *g_source = "";
static int64_t g_origin_us;

static int stream_scan(const bsf_scan_t *sc, uint32_t seq, int64_t t_us, double x, double y,
                       double th, column_t *col)
{
    bsf_frame_info_t info;
    size_t len = 0;
    static long since;
    if (seq == 0u || t_us < g_origin_us || since >= META_EVERY) {
        bsf_metadata_t m;
        bsf_metadata_init(&m);
        m.method = (uint8_t)g_ex.params.method;
        m.target_rms = g_ex.params.pdm.target_rms;
        m.quant_step = BSF_QUANT_STEP_DEFAULT;
        m.n_beams = (uint32_t)sc->count;
        m.angle_min = sc->angle_min;
        m.angle_increment = sc->angle_increment;
        m.range_min = sc->range_min;
        m.range_max = sc->range_max;
        if (seq == 0u || t_us < g_origin_us) {
            g_origin_us = t_us;
        }
        since = 0;
        m.has_time_origin = 1u;
        m.time_origin_us = g_origin_us;
        m.source_len = (uint8_t)strlen(g_source);
        memcpy(m.source, g_source, (size_t)m.source_len + 1u);
        if (bsf_metadata_encode(&m, g_buf, sizeof g_buf, &len) != BSF_OK ||
            stream_append(g_buf, len) != 0) {
            return -1;
        }
    }
    bsf_frame_info_init(&info);
    info.seq = seq;
    info.timestamp_ms = t_us > g_origin_us ? (uint64_t)((t_us - g_origin_us + 500) / 1000) : 0u;
    info.has_pose = 1u;
    info.pose.x = (float)x;
    info.pose.y = (float)y;
    info.pose.theta = (float)remainder(th, 2.0 * PI);
    if (bsf_frame_encode(&info, &g_res, g_buf, sizeof g_buf, &len) != BSF_OK ||
        stream_append(g_buf, len) != 0) {
        return -1;
    }
    col->stream_bytes = g_stream_n;
    ++since;
    return 0;
}

static void to_world(double px, double py, double pth, double sx, double sy, double *wx, double *wy)
{
    const double c = cos(pth), s = sin(pth);
    *wx = px + c * sx - s * sy;
    *wy = py + s * sx + c * sy;
}

/* g_res's features in the world frame (pose px, py, pth) into c; their
 * folds added to *folds. */
static int result_curves(mg_curves_t *c, double px, double py, double pth, mg_folds_t *folds)
{
    static double xy[2u * BSF_MAX_CTRL_PER_FEATURE];
    size_t i, k;
    mg_curves_clear(c);
    for (i = 0; i < g_res.n_features; ++i) {
        const bsf_feature_t *f = &g_res.features[i];
        if (f->n_ctrl < 3u || (size_t)f->ctrl_first + f->n_ctrl > g_res.n_ctrl) {
            continue;
        }
        for (k = 0; k < f->n_ctrl; ++k) {
            const bsf_point_t *p = &g_res.ctrl[f->ctrl_first + k];
            to_world(px, py, pth, (double)p->x, (double)p->y, &xy[2u * k], &xy[2u * k + 1u]);
        }
        if (mg_curves_add_bspline(c, xy, f->n_ctrl, &g_res.ctrl_is_vertex[f->ctrl_first]) != 0 ||
            mg_bspline_folds(xy, f->n_ctrl, &g_res.ctrl_is_vertex[f->ctrl_first], folds) != 0) {
            return -1;
        }
    }
    return 0;
}

/* Each raw point's distance to its own scan's features, kept to split the
 * map's misses by cause (index as in the run's mg_points_t). */
static float *g_own_dist;
static size_t g_own_cap;

static int own_dist_keep(size_t i, double d)
{
    if (i >= g_own_cap) {
        const size_t cap = g_own_cap > 0u ? 2u * g_own_cap : 65536u;
        float *bigger = realloc(g_own_dist, (cap > i ? cap : i + 1u) * sizeof *bigger);
        if (bigger == NULL) {
            return -1;
        }
        g_own_dist = bigger;
        g_own_cap = cap > i ? cap : i + 1u;
    }
    g_own_dist[i] = (float)d;
    return 0;
}

/* Distance from each point [first, n) of pts to the curves of one scan, brute force
 * (a scan has a few hundred segments); kept per point when keep is set. */
static int own_scan_distances(const mg_points_t *pts, size_t first, const mg_curves_t *c,
                              mg_hist_t *h, int keep)
{
    size_t i, k;
    for (i = first; i < pts->n; ++i) {
        const double x = (double)pts->xy[2u * i], y = (double)pts->xy[2u * i + 1u];
        double best = 1e300;
        for (k = 0; k < c->n_seg; ++k) {
            const float *s = &c->seg[4u * k];
            const double ax = (double)s[0], ay = (double)s[1];
            const double dx = (double)s[2] - ax, dy = (double)s[3] - ay;
            const double l2 = dx * dx + dy * dy;
            double t = l2 > 0.0 ? ((x - ax) * dx + (y - ay) * dy) / l2 : 0.0;
            double ex, ey;
            t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
            ex = ax + t * dx - x;
            ey = ay + t * dy - y;
            best = fmin(best, ex * ex + ey * ey);
        }
        best = sqrt(best);
        mg_hist_add(h, best < MG_DIST_MAX ? best : MG_DIST_MAX);
        if (keep && own_dist_keep(i, best) != 0) {
            return -1;
        }
    }
    return 0;
}

static int fuse_scan(column_t *col, double px, double py, double pth);

/* Everything a scan contributes once extracted: stream bytes, raw points,
 * own-scan coverage. ranges/geometry in sc; pose of the sensor in the world. */
static int take_scan(column_t *col, const bsf_scan_t *sc, uint32_t seq, int64_t t_us, double px,
                     double py, double pth, mg_points_t *pts, mg_curves_t *scratch)
{
    size_t i, first = pts->n;
    bsf_status_t st = bsf_extract(&g_ex, sc, &g_res);
    ++col->scans;
    if (st != BSF_OK && st != BSF_OK_CUT) {
        ++col->failed;
        return 1;
    }
    if (stream_scan(sc, seq, t_us, px, py, pth, col) != 0 ||
        mg_points_begin_scan(pts, px, py) != 0) {
        return -1;
    }
    for (i = 0; i < sc->count; ++i) {
        const float r = sc->ranges[i];
        const double a = (double)sc->angle_min + (double)i * (double)sc->angle_increment;
        double wx, wy;
        if (!bsf_range_is_valid(r, sc->range_min, sc->range_max) || r > RAW_RANGE_MAX) {
            continue;
        }
        to_world(px, py, pth, (double)r * cos(a), (double)r * sin(a), &wx, &wy);
        if (mg_points_add(pts, wx, wy) != 0) {
            return -1;
        }
    }
    /* scratch still holds the previous extracted scan's curves (none for the first) */
    if (scratch->n_seg > 0u) {
        (void)own_scan_distances(pts, first, scratch, &col->prev_dist, 0);
    }
    if (result_curves(scratch, px, py, pth, &col->own_folds) != 0) {
        return -1;
    }
    if (own_scan_distances(pts, first, scratch, &col->own_dist, 1) != 0) {
        return -1;
    }
    return fuse_scan(col, px, py, pth);
}

/* A map frame through the decoder into the receiver, as a link delivers it. */
static int to_receiver(const uint8_t *buf, size_t len)
{
    size_t off = 0;
    while (off < len) {
        size_t used = 0;
        const int r = bsf_decoder_feed(&g_dec, buf + off, len - off, &used, &g_frame);
        if (r < 0) {
            return -1;
        }
        off += used;
        if (r > 0) {
            if (g_frame.type != BSF_FRAME_TYPE_MAP ||
                bsf_map_rx_apply(&g_rx, g_frame.payload, g_frame.payload_len) < 0) {
                return -1;
            }
        } else if (used == 0u) {
            break;
        }
    }
    return 0;
}

/* Write (and deliver) every waiting map change; pose may be NULL. */
static int map_flush(column_t *col, const bsf_pose_t *pose)
{
    int first = 1;
    while (first || bsf_map_pending(&g_map)) {
        size_t len = 0;
        if (bsf_map_encode(&g_map, first ? pose : NULL, g_buf, BSF_MAP_FRAME_MAX_SIZE, &len) !=
            BSF_OK) {
            return -1;
        }
        if (len == 0u) {
            break;
        }
        ++col->map_frames;
        if (to_receiver(g_buf, len) != 0) {
            fprintf(stderr, "bench_map: %s: the receiver refused a map frame\n", col->name);
            return -1;
        }
        first = 0;
    }
    return 0;
}

/* Fuse g_res (the scan just extracted) at the sensor pose and send the changes. */
static int fuse_scan(column_t *col, double px, double py, double pth)
{
    bsf_pose_t pose;
    double t0;
    int r;
    pose.x = (float)px;
    pose.y = (float)py;
    pose.theta = (float)remainder(pth, 2.0 * PI);
    g_last_pose = pose;
    t0 = now_us();
    r = bsf_map_fuse(&g_map, &g_res, &pose);
    if (col->fuse_us != NULL) {
        col->fuse_us[col->n_fuse_us++] = now_us() - t0;
    }
    if (r < 0) {
        ++col->fuse_failed;
        return 0;
    }
    /* a pose record every g_pose_every scans (0: none), counted apart */
    ++g_fused;
    return map_flush(
        col, g_pose_every > 0 && (g_fused - 1u) % (unsigned long)g_pose_every == 0u ? &pose : NULL);
}

/* The bytes of the final map sent once: the snapshot records of one round
 * of the round robin over every feature the robot still holds, on a copy of
 * the map (the library has no call that writes the whole map at once), in
 * frames of SNAP_BUDGET snapshot bytes; frame headers are left out.
 * Features the robot forgot are not in it: the table scales the bytes by
 * the receiver's control points over the robot's. */
#define SNAP_BUDGET 128u
static int map_once_bytes(column_t *col)
{
    const long b = mg_map_once_bytes(&g_map_copy, &g_map, &g_last_pose, SNAP_BUDGET);
    if (b < 0) {
        return -1;
    }
    col->map_once_bytes = (size_t)b;
    col->map_once_missing = (unsigned long)g_map.stats.n_forgotten;
    return 0;
}

/* The receiver's final map as curves; robot and receiver compared value for value. */
static int final_map(column_t *col, mg_curves_t *map)
{
    static bsf_point_t ctrl[BSF_MAP_RX_MAX_CTRL];
    static uint8_t vtx[BSF_MAP_RX_MAX_CTRL];
    static double xy[2u * BSF_MAP_RX_MAX_CTRL];
    static int32_t qa[2u * BSF_MAP_RX_MAX_CTRL], qb[2u * BSF_MAP_RX_MAX_CTRL];
    static uint8_t va[BSF_MAP_RX_MAX_CTRL], vb[BSF_MAP_RX_MAX_CTRL];
    const uint32_t limit = bsf_map_rx_id_limit(&g_rx);
    size_t i;
    uint32_t id;
    mg_curves_clear(map);
    for (id = 0; id < limit; ++id) {
        const int n = bsf_map_rx_feature_ctrl(&g_rx, id, ctrl, vtx, BSF_MAP_RX_MAX_CTRL, NULL);
        int k;
        if (n < 3) {
            continue;
        }
        for (k = 0; k < n; ++k) {
            xy[2 * k] = (double)ctrl[k].x;
            xy[2 * k + 1] = (double)ctrl[k].y;
        }
        if (mg_curves_add_bspline(map, xy, (size_t)n, vtx) != 0 ||
            mg_bspline_folds(xy, (size_t)n, vtx, &col->map_folds) != 0) {
            return -1;
        }
    }
    for (id = 0; id < limit; ++id) {
        const int n = bsf_map_rx_feature_q(&g_rx, id, NULL, NULL, 0u);
        col->rx_points += n > 0 ? (unsigned long)n : 0u;
    }
    for (i = 0; i < bsf_map_feature_count(&g_map); ++i) {
        const int n = bsf_map_feature_q(&g_map, i, NULL, NULL, 0u, NULL);
        col->robot_points += n > 0 ? (unsigned long)n : 0u;
    }
    col->map_features = (unsigned long)map->n_curves;
    col->map_vertices = (unsigned long)map->n_vtx;
    col->map_length = map->length;
    for (i = 0; i < bsf_map_feature_count(&g_map); ++i) {
        uint32_t rid = 0;
        const int na = bsf_map_feature_q(&g_map, i, qa, va, BSF_MAP_RX_MAX_CTRL, &rid);
        const int nb = bsf_map_rx_feature_q(&g_rx, rid, qb, vb, BSF_MAP_RX_MAX_CTRL);
        ++col->rx_compared;
        if (na != nb || na < 0 ||
            memcmp(qa, qb, 2u * (size_t)(na > 0 ? na : 0) * sizeof(int32_t)) != 0 ||
            memcmp(va, vb, (size_t)(na > 0 ? na : 0)) != 0) {
            ++col->rx_mismatch;
        }
    }
    return 0;
}

/* Every raw point's distance to the final map. */
static int map_coverage(column_t *col, const mg_points_t *pts, const mg_curves_t *map)
{
    mg_index_t ix;
    size_t i;
    if (mg_index_build(&ix, map) != 0) {
        return -1;
    }
    col->miss_own_near = col->miss_own_far = 0u;
    for (i = 0; i < pts->n; ++i) {
        const double d = mg_index_dist(&ix, (double)pts->xy[2u * i], (double)pts->xy[2u * i + 1u]);
        mg_hist_add(&col->map_dist, d);
        /* a miss its own scan's features hold is a place the map lies elsewhere
         * (poses that disagree, surfaces averaged); one they do not is
         * clutter no scan's extraction made a feature of */
        if (d > 0.05 && i < g_own_cap) {
            if (g_own_dist[i] <= 0.05f) {
                ++col->miss_own_near;
            } else {
                ++col->miss_own_far;
            }
        }
    }
    mg_index_free(&ix);
    return 0;
}

/* The map's parameters: the defaults, changed by --map-param. */
static bsf_map_params_t g_map_params;

/* NAME=VALUE into g_map_params: 0, or -1 for an unknown name or a bad value
 * (the range is checked by bsf_map_init). */
static int set_map_param(const char *arg)
{
    static const char *const names[] = {"match_dist",       "match_angle",    "vertex_dist",
                                        "ctrl_spacing",     "send_tol",       "weight_cap",
                                        "forget_after",     "frame_interval", "match_dist_near",
                                        "match_dist_per_m", "simplify_tol",   "snapshot_budget"};
    const char *eq = strchr(arg, '=');
    char *end = NULL;
    double v;
    size_t k;
    if (eq == NULL) {
        return -1;
    }
    v = strtod(eq + 1, &end);
    if (end == eq + 1 || *end != '\0' || !(v >= 0.0 && v <= 1e6)) {
        return -1;
    }
    for (k = 0; k < sizeof names / sizeof names[0]; ++k) {
        if (strlen(names[k]) == (size_t)(eq - arg) &&
            strncmp(arg, names[k], (size_t)(eq - arg)) == 0) {
            break;
        }
    }
    switch (k) {
    case 0: g_map_params.match_dist = (float)v; break;
    case 1: g_map_params.match_angle = (float)v; break;
    case 2: g_map_params.vertex_dist = (float)v; break;
    case 3: g_map_params.ctrl_spacing = (float)v; break;
    case 4: g_map_params.send_tol = (float)v; break;
    case 5: g_map_params.weight_cap = (uint16_t)v; break;
    case 6: g_map_params.forget_after = (uint32_t)v; break;
    case 7: g_map_params.frame_interval = (uint16_t)v; break;
    case 8: g_map_params.match_dist_near = (float)v; break;
    case 9: g_map_params.match_dist_per_m = (float)v; break;
    case 10: g_map_params.simplify_tol = (float)v; break;
    case 11: g_map_params.snapshot_budget = (uint16_t)v; break;
    default: return -1;
    }
    return 0;
}

static int map_begin(column_t *col, size_t max_scans)
{
    if (bsf_map_init(&g_map, &g_map_params) != BSF_OK) {
        fprintf(stderr, "bench_map: the map parameters are out of range (bsf_map_init)\n");
        return -1;
    }
    bsf_map_rx_init(&g_rx);
    bsf_decoder_init(&g_dec);
    g_fused = 0u;
    col->fuse_us = (double *)malloc((max_scans ? max_scans : 1u) * sizeof(double));
    return col->fuse_us != NULL ? 0 : -1;
}

static int map_end(column_t *col, const mg_points_t *pts, mg_curves_t *map)
{
    /* the end of the log: what waits for the frame interval goes out now */
    g_map.params.frame_interval = 1u;
    if (map_flush(col, NULL) != 0) {
        return -1;
    }
    col->map_update_bytes = g_map.stats.map_bytes;
    memcpy(col->record_bytes, g_map.stats.record_bytes, sizeof col->record_bytes);
    col->map_pose_bytes = g_map.stats.pose_bytes;
    col->map_forgotten = g_map.stats.n_forgotten;
    col->map_dropped = g_map.stats.n_dropped_obs;
    if (map_once_bytes(col) != 0) {
        fprintf(stderr, "bench_map: %s: snapshot cycle did not cover the map\n", col->name);
    }
    if (final_map(col, map) != 0 || map_coverage(col, pts, map) != 0) {
        return -1;
    }
    qsort(col->fuse_us, col->n_fuse_us, sizeof(double), cmp_double);
    return 0;
}

static int finish_baselines(column_t *col, const mg_points_t *pts)
{
    char pgm[1024], png[1024];
    col->stream_gz_bytes = mg_gzip_size(g_stream, g_stream_n);
    if (g_grid_out != NULL) {
        snprintf(pgm, sizeof pgm, "%s/%s.pgm.gz", g_grid_out, col->name);
        snprintf(png, sizeof png, "%s/%s.png", g_grid_out, col->name);
    }
    col->grid_ok = mg_grid_baseline(pts, GRID_CELL, g_grid_out ? pgm : NULL,
                                    g_grid_out ? png : NULL, &col->grid) == 0;
    if (!col->grid_ok) {
        fprintf(stderr, "bench_map: %s: grid baseline failed\n", col->name);
    }
    return 0;
}

static int run_log(column_t *col, const char *path, long max_scans)
{
    carmen_reader_t *rd = carmen_open(path, stderr);
    carmen_scan_t rec;
    mg_points_t pts;
    mg_curves_t scratch, map;
    uint32_t seq = 0;
    int r, rc = 0;
    if (rd == NULL) {
        fprintf(stderr, "bench_map: %s: cannot open; column left out\n", path);
        return 1;
    }
    mg_points_init(&pts);
    mg_curves_init(&scratch);
    mg_curves_init(&map);
    if (map_begin(col, max_scans > 0 ? (size_t)max_scans : 100000u) != 0) {
        carmen_close(rd);
        return -1;
    }
    g_stream_n = 0;
    g_source = strrchr(path, '/') != NULL ? strrchr(path, '/') + 1 : path;
    while ((r = carmen_next(rd, &rec)) > 0 && (max_scans < 0 || (long)seq < max_scans) &&
           seq < 100000u) {
        const bsf_scan_t sc = scan_of_record(&rec, 0.0);
        const int t = take_scan(col, &sc, seq, llround(rec.timestamp * 1e6), rec.laser_pose.x,
                                rec.laser_pose.y, rec.laser_pose.theta, &pts, &scratch);
        if (t < 0) {
            rc = -1;
            break;
        }
        ++seq;
    }
    carmen_close(rd);
    if (r < 0) {
        rc = -1;
    }
    if (rc == 0) {
        rc = finish_baselines(col, &pts);
    }
    if (rc == 0) {
        rc = map_end(col, &pts, &map);
    }
    mg_points_free(&pts);
    mg_curves_free(&scratch);
    mg_curves_free(&map);
    return rc;
}

/* True surface seen: 2 cm bins along every shape, marked by valid hits. */
typedef struct {
    uint8_t *bins[BSF_SCENE_MAX_SHAPES];
    size_t n_bins[BSF_SCENE_MAX_SHAPES];
} seen_t;

static double shape_length(const bsf_shape_t *s)
{
    return s->kind == BSF_SHAPE_CIRCLE ? 2.0 * PI * s->r : hypot(s->x1 - s->x0, s->y1 - s->y0);
}

static int seen_init(seen_t *sn, const bsf_scene_t *scene)
{
    size_t i;
    memset(sn, 0, sizeof *sn);
    for (i = 0; i < scene->n_shapes; ++i) {
        sn->n_bins[i] = (size_t)(shape_length(&scene->shape[i]) / SEEN_BIN) + 1u;
        sn->bins[i] = (uint8_t *)calloc(sn->n_bins[i], 1u);
        if (sn->bins[i] == NULL) {
            return -1;
        }
    }
    return 0;
}

static void seen_mark(seen_t *sn, const bsf_shape_t *s, size_t shape, double wx, double wy)
{
    double along;
    size_t b;
    if (s->kind == BSF_SHAPE_CIRCLE) {
        double a = atan2(wy - s->y0, wx - s->x0);
        a = a < 0.0 ? a + 2.0 * PI : a;
        along = a * s->r;
    } else {
        const double dx = s->x1 - s->x0, dy = s->y1 - s->y0, l = hypot(dx, dy);
        along = ((wx - s->x0) * dx + (wy - s->y0) * dy) / l;
    }
    along = along < 0.0 ? 0.0 : along;
    b = (size_t)(along / SEEN_BIN);
    sn->bins[shape][b < sn->n_bins[shape] ? b : sn->n_bins[shape] - 1u] = 1u;
}

static double seen_free(seen_t *sn, const bsf_scene_t *scene)
{
    double m = 0.0;
    size_t i, b;
    for (i = 0; i < scene->n_shapes; ++i) {
        const double bin_len = shape_length(&scene->shape[i]) / (double)sn->n_bins[i];
        for (b = 0; b < sn->n_bins[i]; ++b) {
            m += sn->bins[i][b] ? bin_len : 0.0;
        }
        free(sn->bins[i]);
    }
    return m;
}

static const char *const scene_names[3] = {"office", "angles", "curved"};

static void make_scene(int which, bsf_scene_t *sc)
{
    if (which == 0) {
        bsf_scene_demo_office(sc);
    } else if (which == 1) {
        bsf_scene_truth_angles(sc);
    } else {
        bsf_scene_truth_curved(sc);
    }
}

/* Per corner of a scene: in how many scans it was seen. */
static unsigned long g_corner_scans[MAX_CORNERS];
static bsf_scene_corner_t g_corners[MAX_CORNERS];
static size_t g_n_corners;

/* Distances from a curve segment (x0, y0, x1, y1) to the true surface,
 * every TRUTH_STEP along it: the quantiles are per length of curve, however
 * many control points (and so samples) a piece has. */
#define TRUTH_STEP 0.01
static void add_truth(mg_hist_t *h, const bsf_scene_t *scene, const float *seg)
{
    const double x0 = (double)seg[0];
    const double y0 = (double)seg[1];
    const double dx = (double)seg[2] - x0;
    const double dy = (double)seg[3] - y0;
    const size_t n = (size_t)(sqrt(dx * dx + dy * dy) / TRUTH_STEP) + 1u;
    size_t k;
    for (k = 0; k < n; ++k) {
        const double t = (double)k / (double)n;
        mg_hist_add(h, bsf_scene_distance_to_surface(scene, x0 + t * dx, y0 + t * dy, NULL));
    }
}

static int run_scene(column_t *col, int which, long n_poses)
{
    static bsf_scene_t scene;
    static float ranges[BSF_MAX_POINTS], clean[BSF_MAX_POINTS];
    static int16_t hits[BSF_MAX_POINTS];
    const size_t beams = 361u;
    bsf_scene_rng_t rng;
    mg_points_t pts;
    mg_curves_t scratch, map;
    seen_t seen;
    long k;
    size_t m;
    int rc = 0;
    make_scene(which, &scene);
    bsf_scene_rng_seed(&rng, 4321u + (uint64_t)which);
    mg_points_init(&pts);
    mg_curves_init(&scratch);
    mg_curves_init(&map);
    memset(g_corner_scans, 0, sizeof g_corner_scans);
    g_stream_n = 0;
    g_source = scene_names[which];
    if (seen_init(&seen, &scene) != 0 || map_begin(col, (size_t)n_poses) != 0) {
        return -1;
    }
    for (k = 0; k < n_poses && rc == 0; ++k) {
        double x, y, th;
        bsf_lidar_t lid;
        bsf_scan_t scan;
        size_t i, n_c = 0;
        int t;
        bsf_scene_truth_pose(which, k, n_poses, &x, &y, &th);
        lid = bsf_lidar_default(x, y, th, beams, 270.0 * PI / 180.0);
        lid.noise_sigma = 0.0;
        if (bsf_scene_scan(&scene, &lid, NULL, clean, hits, BSF_MAX_POINTS) != BSF_OK) {
            rc = -1;
            break;
        }
        for (i = 0; i < beams; ++i) {
            ranges[i] = clean[i];
            if (hits[i] >= 0) {
                const double r = (double)clean[i] + 0.01 * bsf_scene_rng_gauss(&rng);
                ranges[i] = (float)(r < 0.0 ? 0.0 : r);
            }
        }
        scan = bsf_scene_lidar_scan(&lid, ranges);
        for (i = 0; i < beams; ++i) {
            if (hits[i] >= 0 && bsf_range_is_valid(ranges[i], scan.range_min, scan.range_max)) {
                const double a = th + lid.angle_min + (double)i * lid.angle_increment;
                seen_mark(&seen, &scene.shape[hits[i]], (size_t)hits[i],
                          x + (double)clean[i] * cos(a), y + (double)clean[i] * sin(a));
            }
        }
        if (bsf_scene_corners(&scene, &lid, g_corners, MAX_CORNERS, &n_c) != BSF_OK) {
            rc = -1;
            break;
        }
        g_n_corners = n_c;
        for (i = 0; i < n_c; ++i) {
            g_corner_scans[i] += bsf_truth_corner_seen(&g_corners[i], &lid, clean, hits) ? 1u : 0u;
        }
        t = take_scan(col, &scan, (uint32_t)k, (int64_t)k * 100000, x, y, th, &pts, &scratch);
        if (t < 0) {
            rc = -1;
        } else if (t == 0) {
            size_t s;
            for (s = 0; s < scratch.n_seg; ++s) {
                add_truth(&col->own_truth, &scene, &scratch.seg[4u * s]);
            }
        }
    }
    col->seen_m = seen_free(&seen, &scene);
    if (rc == 0) {
        rc = finish_baselines(col, &pts);
    }
    if (rc == 0) {
        rc = map_end(col, &pts, &map);
    }
    if (rc == 0) {
        for (m = 0; m < map.n_seg; ++m) {
            add_truth(&col->map_truth, &scene, &map.seg[4u * m]);
        }
        for (m = 0; m < g_n_corners; ++m) {
            size_t v, near = 0;
            if (g_corner_scans[m] < CORNER_MIN_SCANS) {
                continue;
            }
            ++col->corners_5;
            for (v = 0; v < map.n_vtx; ++v) {
                near += hypot(map.vtx[2u * v] - g_corners[m].wx,
                              map.vtx[2u * v + 1u] - g_corners[m].wy) <= CORNER_MATCH
                            ? 1u
                            : 0u;
            }
            col->corners_one += near == 1u ? 1u : 0u;
            col->corners_many += near > 1u ? 1u : 0u;
        }
    }
    mg_points_free(&pts);
    mg_curves_free(&scratch);
    mg_curves_free(&map);
    return rc;
}

/* ---- the table ----------------------------------------------------------- */

#define MAX_COLS 6
static column_t g_cols[MAX_COLS];
static size_t g_n_cols;

static void row_begin(const char *what)
{
    printf("| %s |", what);
}

static void print_table(void)
{
    size_t c;
    printf("| figure |");
    for (c = 0; c < g_n_cols; ++c) {
        printf(" %s |", g_cols[c].name);
    }
    printf("\n|---|");
    for (c = 0; c < g_n_cols; ++c) {
        printf("---:|");
    }
    printf("\n");
#define ROW(label, fmt_expr)                                                                       \
    do {                                                                                           \
        row_begin(label);                                                                          \
        for (c = 0; c < g_n_cols; ++c) {                                                           \
            const column_t *col = &g_cols[c];                                                      \
            fmt_expr;                                                                              \
        }                                                                                          \
        printf("\n");                                                                              \
    } while (0)
    ROW("scans (extraction failed, fuse failed)",
        printf(" %lu (%lu, %lu) |", col->scans, col->failed, col->fuse_failed));
    ROW("**map: bytes of the final map, sent once** (snapshot records of the robot's RAM; "
        "in brackets, scaled to the receiver's control points when features were forgotten)",
        col->map_once_missing && col->robot_points
            ? printf(" %lu (%.0f) |", (unsigned long)col->map_once_bytes,
                     (double)col->map_once_bytes * (double)col->rx_points /
                         (double)col->robot_points)
            : printf(" %lu |", (unsigned long)col->map_once_bytes));
    ROW("**map: bytes of the whole update stream (map only)**",
        printf(" %lu |", (unsigned long)col->map_update_bytes));
    ROW("map: update records new / append / move / merge bytes, the rest frame overhead",
        printf(" %lu / %lu / %lu / %lu, %lu |", (unsigned long)col->record_bytes[0],
               (unsigned long)col->record_bytes[1], (unsigned long)col->record_bytes[2],
               (unsigned long)col->record_bytes[3],
               (unsigned long)(col->map_update_bytes - col->record_bytes[0] - col->record_bytes[1] -
                               col->record_bytes[2] - col->record_bytes[3] -
                               col->record_bytes[4])));
    ROW("map: pose bytes (pose records, counted apart)",
        printf(" %lu |", (unsigned long)col->map_pose_bytes));
    ROW("map: frames", printf(" %lu |", col->map_frames));
    ROW("**map: median point distance mm**",
        printf(" %.1f |", 1000.0 * mg_hist_quantile(&col->map_dist, 0.5)));
    ROW("**map: points within 5 cm**",
        printf(" %.1f %% |", 100.0 * mg_hist_share_below(&col->map_dist, 0.05)));
    ROW("map: points within 1 / 2 / 10 / 50 cm (where the misses lie)",
        printf(" %.1f / %.1f / %.1f / %.1f %% |", 100.0 * mg_hist_share_below(&col->map_dist, 0.01),
               100.0 * mg_hist_share_below(&col->map_dist, 0.02),
               100.0 * mg_hist_share_below(&col->map_dist, 0.10),
               100.0 * mg_hist_share_below(&col->map_dist, 0.50)));
    ROW("map: points beyond 5 cm that their own scan's features hold within 5 cm / that they do "
        "not",
        printf(" %.1f / %.1f %% |",
               100.0 * (double)col->miss_own_near /
                   (double)(col->map_dist.n > 0u ? col->map_dist.n : 1u),
               100.0 * (double)col->miss_own_far /
                   (double)(col->map_dist.n > 0u ? col->map_dist.n : 1u)));
    ROW("**map: curve to true surface p99 / max mm**",
        col->synthetic ? printf(" %.1f / %.1f |", 1000.0 * mg_hist_quantile(&col->map_truth, 0.99),
                                1000.0 * col->map_truth.max)
                       : printf(" – |"));
    ROW("**map: curve length per metre of true surface seen**",
        col->synthetic && col->seen_m > 0.0 ? printf(" %.3f |", col->map_length / col->seen_m)
                                            : printf(" – |"));
    ROW("**map: corners seen in >= 5 scans that are one map vertex within 3 cm**",
        col->synthetic
            ? printf(" %.1f %% (%lu of %lu; %lu with several) |",
                     col->corners_5 ? 100.0 * (double)col->corners_one / (double)col->corners_5
                                    : 0.0,
                     col->corners_one, col->corners_5, col->corners_many)
            : printf(" – |"));
    ROW("**map: folds (curve turning back > 150 deg within 2 cm of arc either side), vertices "
        "turning > 150 deg**",
        printf(" %lu, %lu |", col->map_folds.folds, col->map_folds.sharp_vertices));
    ROW("map: features, control points, vertices, curve m",
        printf(" %lu, %lu, %lu, %.1f |", col->map_features, col->rx_points, col->map_vertices,
               col->map_length));
    ROW("map: forgotten features, scan features left out",
        printf(" %lu, %lu |", col->map_forgotten, col->map_dropped));
    ROW("map: receiver = robot (features differing / compared)",
        printf(" %lu / %lu |", col->rx_mismatch, col->rx_compared));
    ROW("map: host fuse time median / max us",
        printf(" %.0f / %.0f |", col->n_fuse_us ? col->fuse_us[col->n_fuse_us / 2u] : 0.0,
               col->n_fuse_us ? col->fuse_us[col->n_fuse_us - 1u] : 0.0));
    ROW("per-scan stream bytes (bsf extract)", printf(" %lu |", (unsigned long)col->stream_bytes));
    ROW("per-scan stream, gzip'd", printf(" %lu |", (unsigned long)col->stream_gz_bytes));
    ROW("per-scan features: median point distance mm",
        printf(" %.1f |", 1000.0 * mg_hist_quantile(&col->own_dist, 0.5)));
    ROW("per-scan features: points within 5 cm",
        printf(" %.1f %% |", 100.0 * mg_hist_share_below(&col->own_dist, 0.05)));
    ROW("previous scan's features: points within 1 / 2 / 5 cm (how well consecutive poses agree)",
        printf(" %.1f / %.1f / %.1f %% |", 100.0 * mg_hist_share_below(&col->prev_dist, 0.01),
               100.0 * mg_hist_share_below(&col->prev_dist, 0.02),
               100.0 * mg_hist_share_below(&col->prev_dist, 0.05)));
    ROW("per-scan features: points within 1 / 2 / 10 / 50 cm",
        printf(" %.1f / %.1f / %.1f / %.1f %% |", 100.0 * mg_hist_share_below(&col->own_dist, 0.01),
               100.0 * mg_hist_share_below(&col->own_dist, 0.02),
               100.0 * mg_hist_share_below(&col->own_dist, 0.10),
               100.0 * mg_hist_share_below(&col->own_dist, 0.50)));
    ROW("per-scan features: folds, vertices turning > 150 deg (all scans, summed)",
        printf(" %lu, %lu |", col->own_folds.folds, col->own_folds.sharp_vertices));
    ROW("per-scan features to true surface p99 / max mm",
        col->synthetic ? printf(" %.1f / %.1f |", 1000.0 * mg_hist_quantile(&col->own_truth, 0.99),
                                1000.0 * col->own_truth.max)
                       : printf(" – |"));
    ROW("5 cm grid cells (occupied)",
        printf(" %lux%lu (%lu) |", (unsigned long)col->grid.nx, (unsigned long)col->grid.ny,
               (unsigned long)col->grid.occupied));
    ROW("5 cm grid, PGM gzip'd bytes", printf(" %lu |", (unsigned long)col->grid.pgm_gz_bytes));
    ROW("5 cm grid, PNG bytes", printf(" %lu |", (unsigned long)col->grid.png_bytes));
    ROW("true surface seen m", col->synthetic ? printf(" %.1f |", col->seen_m) : printf(" – |"));
#undef ROW
    printf("\nRAM of the map (sizeof bsf_map_t, this build's caps: %d features, %d control "
           "points): %lu bytes; receiver (sizeof bsf_map_rx_t): %lu bytes\n",
           BSF_MAP_MAX_FEATURES, BSF_MAP_MAX_CTRL, (unsigned long)sizeof(bsf_map_t),
           (unsigned long)sizeof(bsf_map_rx_t));
}

int main(int argc, char **argv)
{
    static const char *const log_names[3] = {"intel", "mit", "fr079"};
    static const char *const log_files[3] = {"intel-corrected.log.gz", "mit-csail-corrected.log.gz",
                                             "fr079-corrected.log.gz"};
    const char *data = BSF_SHARED_DIR_DEFAULT "/data";
    const char *only = NULL;
    long max_scans = -1, poses = 300;
    int check = 0;
    bsf_params_t p = bsf_params_default(BSF_METHOD_DEFAULT);
    int i;
    bsf_map_params_default(&g_map_params);
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--data") == 0 && i + 1 < argc) {
            data = argv[++i];
        } else if (strcmp(argv[i], "--scans") == 0 && i + 1 < argc) {
            max_scans = atol(argv[++i]);
        } else if (strcmp(argv[i], "--poses") == 0 && i + 1 < argc) {
            poses = atol(argv[++i]);
        } else if (strcmp(argv[i], "--grid-out") == 0 && i + 1 < argc) {
            g_grid_out = argv[++i];
        } else if (strcmp(argv[i], "--map-param") == 0 && i + 1 < argc) {
            if (set_map_param(argv[++i]) != 0) {
                fprintf(stderr,
                        "bench_map: --map-param needs NAME=VALUE with a name of "
                        "bsf_map_params_t (match_dist, match_angle, vertex_dist, "
                        "ctrl_spacing, send_tol, weight_cap, forget_after, "
                        "frame_interval, match_dist_near, match_dist_per_m, simplify_tol, "
                        "snapshot_budget), got '%s'\n",
                        argv[i]);
                return 2;
            }
        } else if (strcmp(argv[i], "--pose-every") == 0 && i + 1 < argc) {
            g_pose_every = atol(argv[++i]);
        } else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc) {
            only = argv[++i];
        } else if (strcmp(argv[i], "--check") == 0) {
            check = 1;
        } else {
            fprintf(stderr,
                    "usage: bench_map [--data DIR] [--scans N] [--poses N] [--grid-out DIR] "
                    "[--only NAME] [--pose-every K] [--map-param NAME=VALUE]... [--check]\n");
            return 2;
        }
    }
    if (g_pose_every < 0 || g_pose_every > 1000000) {
        fprintf(stderr, "bench_map: --pose-every needs 0 .. 1000000\n");
        return 2;
    }
    if (poses < 10 || poses > 100000) {
        fprintf(stderr, "bench_map: --poses needs 10 .. 100000\n");
        return 2;
    }
    if (bsf_extractor_init(&g_ex, &p) != BSF_OK) {
        fprintf(stderr, "bench_map: extractor init failed\n");
        return 1;
    }
    for (i = 0; i < 3; ++i) {
        char path[2048];
        column_t *col = &g_cols[g_n_cols];
        int r;
        if (only != NULL && strcmp(only, log_names[i]) != 0) {
            continue;
        }
        snprintf(path, sizeof path, "%s/alt/%s", data, log_files[i]);
        memset(col, 0, sizeof *col);
        col->name = log_names[i];
        r = run_log(col, path, max_scans);
        if (r < 0) {
            fprintf(stderr, "bench_map: %s failed\n", path);
            return 1;
        }
        g_n_cols += r == 0 ? 1u : 0u;
    }
    for (i = 0; i < 3; ++i) {
        column_t *col = &g_cols[g_n_cols];
        if (only != NULL && strcmp(only, scene_names[i]) != 0) {
            continue;
        }
        memset(col, 0, sizeof *col);
        col->name = scene_names[i];
        col->synthetic = 1;
        if (run_scene(col, i, poses) != 0) {
            fprintf(stderr, "bench_map: scene %s failed\n", scene_names[i]);
            return 1;
        }
        ++g_n_cols;
    }
    if (g_n_cols == 0u) {
        fprintf(stderr, "bench_map: no input\n");
        return 1;
    }
    print_table();
    free(g_stream);
    free(g_own_dist);
    for (i = 0; i < (int)g_n_cols; ++i) {
        free(g_cols[i].fuse_us);
    }
    if (check) {
        size_t c;
        int bad = 0;
        for (c = 0; c < g_n_cols; ++c) {
            const column_t *col = &g_cols[c];
            if (col->failed || col->fuse_failed || col->rx_mismatch || col->rx_compared == 0u ||
                col->map_update_bytes == 0u || col->map_once_bytes == 0u || col->map_dist.n == 0u ||
                !col->grid_ok || col->grid.pgm_gz_bytes == 0u || col->grid.png_bytes == 0u) {
                printf("CHECK FAILED: %s\n", col->name);
                bad = 1;
            }
        }
        return bad;
    }
    return 0;
}
