/* SPDX-License-Identifier: MIT */
/*
 * bench_align - aligning each scan to the map before fusing it, against
 * drifting odometry. For every drift source three maps are fused from the
 * same scans: with the corrected (or true) poses, with the odometry prior
 * alone, and with each prior aligned to the map (bsf_align_points). One
 * column per source; docs/ALIGN.md pastes the output.
 *
 *   bench_align [--data DIR] [--scans N] [--poses N] [--only NAME] [--seed S] [--check]
 *
 * --check: exit 1 unless, in every column, every figure is finite and the
 * aligned trajectory's RMS translation and heading errors are below the
 * prior's (ctest runs it on a short synthetic run).
 *
 * Drift sources:
 *  - intel-seq, mit-seq, fr079-seq: the logs' `#SEQUENTIAL` EDGE2 edges
 *    (scan-matched relative motions between consecutive scans, no loop
 *    closures) chained from the first corrected pose; truth = the
 *    corrected poses (VERTEX2, the ROBOTLASER1 laser pose).
 *  - mit-raw: mit-csail.log.gz's scans and corrected poses, with the raw
 *    wheel odometry of the same run (alt/mit-csail-slameval.clf.gz, FLASER
 *    odometry poses matched by time stamp).
 *  - intel-sim-2, intel-kf-sim-2: intel.log.gz (2672 scans) and the
 *    corrected keyframe log alt/intel-corrected.log.gz (910 scans, about
 *    1 m apart) with their corrected motions perturbed by the drift model
 *    below at 2 %.
 *  - office-1, office-2, office-5: the demo office loop (tools/scene, 361
 *    beams over 270 degrees, 1 cm noise) with its true poses; each relative
 *    motion perturbed by the drift model below at 1 %, 2 % and 5 %.
 *  - corridor-2: a corridor 60 m long and 2 m wide seen with a 6 m range,
 *    driven along its axis, drift model at 2 %.
 * Drift model (seeded xorshift, --seed): a relative motion of length d and
 * turn a gets translation noise N(0, (s d)^2) along and across the motion,
 * a scale bias of s/2 along it, heading noise N(0, (h d)^2 + (0.01 a)^2)
 * and a heading bias of h d / 2, with s = level (0.01, 0.02, 0.05) and
 * h = level * 50 degrees per metre (1 degree per metre at 2 %); and in 1 %
 * of the steps a slip: an extra 5..15 cm along the motion and 1..3 degrees.
 *
 * Rows: trajectory error of the laser pose against the truth (translation
 * and heading, RMS and max) with the prior alone and after alignment; for
 * the corridor also the largest along-axis error, prior vs aligned; the
 * receiver's final map curve length and the bytes of the final map (one
 * snapshot round of every feature the robot holds) and of the whole map
 * update stream, relative to the map fused with the true poses; the share
 * of scans where alignment declined, by reason, and where it left a
 * direction free; host time per alignment.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <zlib.h>

#include "bench_util.h"
#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "carmen.h"
#include "carmen_bsf.h"
#include "map_geom.h"

#ifndef BSF_SHARED_DIR_DEFAULT
#define BSF_SHARED_DIR_DEFAULT "../shared"
#endif

#define PI 3.14159265358979323846
#define MAX_COLS 12
#define SNAP_BUDGET 128u

typedef struct {
    double x, y, t;
} pose_d;

static pose_d compose(pose_d a, pose_d b)
{
    pose_d r;
    const double c = cos(a.t), s = sin(a.t);
    r.x = a.x + c * b.x - s * b.y;
    r.y = a.y + s * b.x + c * b.y;
    r.t = a.t + b.t;
    return r;
}

static pose_d inverse(pose_d a)
{
    pose_d r;
    const double c = cos(a.t), s = sin(a.t);
    r.x = -(c * a.x + s * a.y);
    r.y = -(-s * a.x + c * a.y);
    r.t = -a.t;
    return r;
}

static double wrap(double a)
{
    while (a > PI) {
        a -= 2.0 * PI;
    }
    while (a <= -PI) {
        a += 2.0 * PI;
    }
    return a;
}

/* One scan of a run: its ranges and geometry, its true laser pose, the
 * laser's mount on the robot, and the odometry motion of the robot from the
 * previous scan (unused for scan 0). */
typedef struct {
    float *ranges;
    size_t count;
    float angle_min, angle_increment, range_min, range_max;
    pose_d truth;  /* laser, world */
    pose_d mount;  /* laser in the robot frame */
    pose_d motion; /* odometry: robot k-1 -> robot k */
} run_scan_t;

typedef struct {
    run_scan_t *s;
    size_t n, cap;
    double axis_x, axis_y; /* unit axis for the along-axis row (0, 0: none) */
    double *stamps;        /* time stamps of the scans (logs) */
} run_t;

static int run_push(run_t *r, const float *ranges, size_t count, const bsf_scan_t *g)
{
    run_scan_t *s;
    if (r->n == r->cap) {
        size_t cap = r->cap ? 2u * r->cap : 1024u;
        run_scan_t *p = realloc(r->s, cap * sizeof *p);
        if (p == NULL) {
            return -1;
        }
        r->s = p;
        r->cap = cap;
    }
    s = &r->s[r->n];
    memset(s, 0, sizeof *s);
    s->ranges = malloc(count * sizeof(float));
    if (s->ranges == NULL) {
        return -1;
    }
    memcpy(s->ranges, ranges, count * sizeof(float));
    s->count = count;
    s->angle_min = g->angle_min;
    s->angle_increment = g->angle_increment;
    s->range_min = g->range_min;
    s->range_max = g->range_max;
    ++r->n;
    return 0;
}

static void run_free(run_t *r)
{
    size_t i;
    for (i = 0; i < r->n; ++i) {
        free(r->s[i].ranges);
    }
    free(r->s);
    free(r->stamps);
    memset(r, 0, sizeof *r);
}

/* ---- Sources ------------------------------------------------------------------ */

/* A log's scans with their corrected poses, and its sequential EDGE2 edges
 * as the robot's motions. 0, 1 when the log is absent, -1 on error. */
static int load_log(run_t *r, const char *path, long max_scans, int edges)
{
    carmen_reader_t *rd = carmen_open(path, NULL);
    carmen_scan_t rec;
    gzFile gz;
    char line[4096];
    int seq_section = 0;
    size_t n_edges = 0;
    pose_d *robot;
    size_t i;
    int rc;
    if (rd == NULL) {
        fprintf(stderr, "bench_align: %s: cannot open; column left out\n", path);
        return 1;
    }
    robot = NULL;
    while ((rc = carmen_next(rd, &rec)) > 0 && (max_scans < 0 || (long)r->n < max_scans)) {
        const bsf_scan_t g = scan_of_record(&rec, 0.0);
        pose_d l = {rec.laser_pose.x, rec.laser_pose.y, rec.laser_pose.theta};
        pose_d rb = {rec.robot_pose.x, rec.robot_pose.y, rec.robot_pose.theta};
        pose_d *p;
        if (run_push(r, rec.ranges, rec.count, &g) != 0) {
            carmen_close(rd);
            free(robot);
            return -1;
        }
        p = realloc(robot, r->n * sizeof *p);
        if (p == NULL) {
            carmen_close(rd);
            free(robot);
            return -1;
        }
        robot = p;
        robot[r->n - 1] = rb;
        {
            double *ts = realloc(r->stamps, r->n * sizeof *ts);
            if (ts == NULL) {
                carmen_close(rd);
                free(robot);
                return -1;
            }
            r->stamps = ts;
            ts[r->n - 1] = rec.timestamp;
        }
        r->s[r->n - 1].truth = l;
        r->s[r->n - 1].mount = compose(inverse(rb), l);
        r->s[r->n - 1].mount.t = wrap(r->s[r->n - 1].mount.t);
        /* the corrected motion (perturbed later), or NaN until an edge gives it */
        if (edges || r->n == 1u) {
            r->s[r->n - 1].motion.t = (double)NAN;
        } else {
            r->s[r->n - 1].motion = compose(inverse(robot[r->n - 2]), rb);
            r->s[r->n - 1].motion.t = wrap(r->s[r->n - 1].motion.t);
        }
    }
    carmen_close(rd);
    if (rc < 0) {
        free(robot);
        return -1;
    }
    if (!edges) {
        free(robot);
        return 0;
    }
    gz = gzopen(path, "rb");
    if (gz == NULL) {
        free(robot);
        return -1;
    }
    while (gzgets(gz, line, (int)sizeof line) != NULL) {
        unsigned long a, b;
        double dx, dy, dt;
        if (strncmp(line, "#SEQUENTIAL", 11) == 0) {
            seq_section = 1;
        } else if (line[0] == '#') {
            seq_section = 0;
        } else if (seq_section &&
                   sscanf(line, "EDGE2 %lu %lu %lf %lf %lf", &a, &b, &dx, &dy, &dt) == 5 &&
                   b == a + 1u && b < r->n) {
            r->s[b].motion.x = dx;
            r->s[b].motion.y = dy;
            r->s[b].motion.t = dt;
            ++n_edges;
        }
    }
    gzclose(gz);
    free(robot);
    for (i = 1; i < r->n; ++i) {
        if (!isfinite(r->s[i].motion.t)) {
            fprintf(stderr, "bench_align: %s: no sequential edge into scan %zu\n", path, i);
            return -1;
        }
    }
    (void)n_edges;
    return 0;
}

/* Replace the motions of r (a log with ROBOTLASER1 time stamps) by those of
 * the raw odometry of another log of the same run (FLASER odometry poses),
 * matched by time stamp. 0, 1 when the odometry log is absent, -1 when a
 * scan has no match or on error. */
static int raw_odometry(run_t *r, const double *stamps, const char *odo_path)
{
    carmen_reader_t *rd = carmen_open(odo_path, NULL);
    carmen_scan_t rec;
    pose_d *odo;
    uint8_t *have;
    size_t k = 0, n_have = 0;
    int rc;
    if (rd == NULL) {
        fprintf(stderr, "bench_align: %s: cannot open; column left out\n", odo_path);
        return 1;
    }
    odo = calloc(r->n ? r->n : 1u, sizeof *odo);
    have = calloc(r->n ? r->n : 1u, 1u);
    if (odo == NULL || have == NULL) {
        free(odo);
        free(have);
        carmen_close(rd);
        return -1;
    }
    /* both logs are in time order: one merge pass */
    while ((rc = carmen_next(rd, &rec)) > 0 && k < r->n) {
        while (k < r->n && stamps[k] < rec.timestamp - 1e-4) {
            ++k;
        }
        if (k < r->n && fabs(stamps[k] - rec.timestamp) <= 1e-4) {
            odo[k].x = rec.robot_pose.x;
            odo[k].y = rec.robot_pose.y;
            odo[k].t = rec.robot_pose.theta;
            have[k] = 1u;
            ++n_have;
            ++k;
        }
    }
    carmen_close(rd);
    if (rc < 0 || n_have != r->n) {
        fprintf(stderr, "bench_align: %s: %zu of %zu scans matched by time stamp\n", odo_path,
                n_have, r->n);
        free(odo);
        free(have);
        return -1;
    }
    for (k = 1; k < r->n; ++k) {
        r->s[k].motion = compose(inverse(odo[k - 1]), odo[k]);
        r->s[k].motion.t = wrap(r->s[k].motion.t);
    }
    free(odo);
    free(have);
    return 0;
}

static uint64_t g_rng;
static double urand(void)
{
    g_rng ^= g_rng >> 12;
    g_rng ^= g_rng << 25;
    g_rng ^= g_rng >> 27;
    return (double)((g_rng * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
}

static double grand(void)
{
    double u = urand();
    const double v = urand();
    u = u < 1e-300 ? 1e-300 : u;
    return sqrt(-2.0 * log(u)) * cos(2.0 * PI * v);
}

/* The drift model of the header comment applied to the true motions. */
static void perturb(run_t *r, double level, uint64_t seed)
{
    const double hpm = level * 50.0 * PI / 180.0; /* heading noise, radians per metre */
    size_t i;
    g_rng = seed * 0x9E3779B97F4A7C15ull + 1u;
    for (i = 1; i < r->n; ++i) {
        pose_d m = r->s[i].motion;
        const double d = hypot(m.x, m.y);
        const double ux = d > 0.0 ? m.x / d : 1.0, uy = d > 0.0 ? m.y / d : 0.0;
        const double along = d * (level * 0.5 + level * grand());
        const double across = d * level * grand();
        double dt = hpm * d * 0.5 + sqrt(hpm * hpm * d * d + 1e-4 * m.t * m.t) * grand();
        double slip = 0.0;
        if (urand() < 0.01) {
            slip = 0.05 + 0.10 * urand();
            dt += (urand() < 0.5 ? -1.0 : 1.0) * (1.0 + 2.0 * urand()) * PI / 180.0;
        }
        m.x += ux * (along + slip) - uy * across;
        m.y += uy * (along + slip) + ux * across;
        m.t += dt;
        r->s[i].motion = m;
    }
}

/* Scans of a synthetic scene at poses; true motions (mount: identity). */
static int load_scene(run_t *r, const bsf_scene_t *sc, const pose_d *poses, size_t n,
                      double range_max, uint64_t seed)
{
    static float ranges[BSF_MAX_POINTS];
    size_t k;
    for (k = 0; k < n; ++k) {
        bsf_scene_rng_t rng;
        bsf_lidar_t l = bsf_lidar_default(poses[k].x, poses[k].y, poses[k].t, 361u, 1.5 * PI);
        bsf_scan_t g;
        l.noise_sigma = 0.01;
        if (range_max > 0.0) {
            l.range_max = range_max;
        }
        bsf_scene_rng_seed(&rng, seed + k);
        if (bsf_scene_scan(sc, &l, &rng, ranges, NULL, BSF_MAX_POINTS) != BSF_OK) {
            return -1;
        }
        g = bsf_scene_lidar_scan(&l, ranges);
        if (range_max > 0.0) {
            g.range_max = (float)range_max;
        }
        if (run_push(r, ranges, l.n_beams, &g) != 0) {
            return -1;
        }
        r->s[k].truth = poses[k];
        r->s[k].mount.x = r->s[k].mount.y = r->s[k].mount.t = 0.0;
        if (k > 0) {
            r->s[k].motion = compose(inverse(poses[k - 1]), poses[k]);
            r->s[k].motion.t = wrap(r->s[k].motion.t);
        }
    }
    return 0;
}

/* ---- One fused run -------------------------------------------------------------- */

typedef enum { MODE_TRUTH = 0, MODE_PRIOR = 1, MODE_ALIGN = 2 } mode_t_;

typedef struct {
    double err_rms, err_max, head_rms, head_max, along_max, along_corr_max, along_prior_max;
    double length;
    unsigned long stream_bytes, final_bytes;
    unsigned long declined[BSF_ALIGN_DECLINE_COUNT];
    unsigned long n_free, n_aligned;
    double align_us;
} run_result_t;

static bsf_extractor_t g_ex;
static bsf_result_t g_res;
static bsf_map_t g_map, g_map_copy;
static bsf_result_t g_empty;
static bsf_map_rx_t g_rx;
static bsf_decoder_t g_dec;
static bsf_frame_t g_frame;
static bsf_align_work_t g_work;
static uint8_t g_buf[BSF_MAP_FRAME_MAX_SIZE];

static int to_receiver(const uint8_t *buf, size_t len)
{
    size_t off = 0;
    while (off < len) {
        size_t used = 0;
        const int t = bsf_decoder_feed(&g_dec, buf + off, len - off, &used, &g_frame);
        if (t < 0) {
            return -1;
        }
        off += used;
        if (t == (int)BSF_FRAME_TYPE_MAP &&
            bsf_map_rx_apply(&g_rx, g_frame.payload, g_frame.payload_len) < 0) {
            return -1;
        }
    }
    return 0;
}

/* Bytes of one snapshot round of every feature the robot holds, on a copy
 * (as bench_map measures the final map). */
static long final_map_bytes(const bsf_pose_t *last)
{
    return mg_map_once_bytes(&g_map_copy, &g_map, last, SNAP_BUDGET);
}

/* Curve length of the receiver's final map. */
static double rx_length(void)
{
    static bsf_point_t ctrl[BSF_MAP_RX_MAX_CTRL];
    static uint8_t vtx[BSF_MAP_RX_MAX_CTRL];
    static double xy[2u * BSF_MAP_RX_MAX_CTRL];
    mg_curves_t c;
    const uint32_t limit = bsf_map_rx_id_limit(&g_rx);
    uint32_t id;
    double len;
    mg_curves_init(&c);
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
        if (mg_curves_add_bspline(&c, xy, (size_t)n, vtx) != 0) {
            mg_curves_free(&c);
            return -1.0;
        }
    }
    len = c.length;
    mg_curves_free(&c);
    return len;
}

static int fuse_run(const run_t *r, mode_t_ mode, run_result_t *out)
{
    const bsf_params_t ep = bsf_params_default(BSF_METHOD_LC_SVED_PDM);
    pose_d robot = {0.0, 0.0, 0.0};
    bsf_pose_t last = {0.0f, 0.0f, 0.0f};
    double se = 0.0, sh = 0.0;
    size_t k;
    memset(out, 0, sizeof *out);
    if (bsf_extractor_init(&g_ex, &ep) != BSF_OK || bsf_map_init(&g_map, NULL) != BSF_OK) {
        return -1;
    }
    bsf_map_rx_init(&g_rx);
    bsf_decoder_init(&g_dec);
    for (k = 0; k < r->n; ++k) {
        const run_scan_t *s = &r->s[k];
        bsf_scan_t sc;
        pose_d laser;
        bsf_pose_t p;
        size_t len = 0;
        double e, h;
        sc.ranges = s->ranges;
        sc.count = s->count;
        sc.angle_min = s->angle_min;
        sc.angle_increment = s->angle_increment;
        sc.range_min = s->range_min;
        sc.range_max = s->range_max;
        if (bsf_extract(&g_ex, &sc, &g_res) < 0) {
            return -1;
        }
        if (k == 0 || mode == MODE_TRUTH) {
            laser = s->truth;
            robot = compose(laser, inverse(s->mount));
        } else {
            robot = compose(robot, s->motion);
            laser = compose(robot, s->mount);
        }
        p.x = (float)laser.x;
        p.y = (float)laser.y;
        p.theta = (float)wrap(laser.t);
        if (mode == MODE_ALIGN && k > 0) {
            bsf_align_result_t ar;
            const double t0 = now_us();
            if (bsf_align_points(&g_work, NULL, &g_map, &g_ex.points, &g_res, &p, &ar) != BSF_OK) {
                return -1;
            }
            out->align_us += now_us() - t0;
            ++out->n_aligned;
            ++out->declined[ar.declined];
            out->n_free += ar.n_free > 0u;
            if (r->axis_x != 0.0 || r->axis_y != 0.0) {
                out->along_prior_max =
                    fmax(out->along_prior_max, fabs((laser.x - s->truth.x) * r->axis_x +
                                                    (laser.y - s->truth.y) * r->axis_y));
                out->along_corr_max =
                    fmax(out->along_corr_max, fabs((double)(ar.pose.x - p.x) * r->axis_x +
                                                   (double)(ar.pose.y - p.y) * r->axis_y));
            }
            if (ar.declined == BSF_ALIGN_ACCEPTED) {
                laser.x += (double)(ar.pose.x - p.x);
                laser.y += (double)(ar.pose.y - p.y);
                laser.t += (double)(ar.pose.theta - p.theta);
                p = ar.pose;
                robot = compose(laser, inverse(s->mount));
            }
        }
        e = hypot(laser.x - s->truth.x, laser.y - s->truth.y);
        h = fabs(wrap(laser.t - s->truth.t));
        se += e * e;
        sh += h * h;
        out->err_max = fmax(out->err_max, e);
        out->head_max = fmax(out->head_max, h);
        if (r->axis_x != 0.0 || r->axis_y != 0.0) {
            out->along_max = fmax(out->along_max, fabs((laser.x - s->truth.x) * r->axis_x +
                                                       (laser.y - s->truth.y) * r->axis_y));
        }
        if (bsf_map_fuse(&g_map, &g_res, &p) < 0 ||
            bsf_map_encode(&g_map, NULL, g_buf, sizeof g_buf, &len) != BSF_OK ||
            to_receiver(g_buf, len) != 0) {
            return -1;
        }
        last = p;
    }
    /* flush what the frame interval held back */
    for (k = 0; k < g_map.params.frame_interval + 1u; ++k) {
        size_t len = 0;
        memset(&g_empty, 0, sizeof g_empty);
        if (bsf_map_fuse(&g_map, &g_empty, &last) < 0 ||
            bsf_map_encode(&g_map, NULL, g_buf, sizeof g_buf, &len) != BSF_OK ||
            to_receiver(g_buf, len) != 0) {
            return -1;
        }
    }
    out->err_rms = sqrt(se / (double)(r->n ? r->n : 1u));
    out->head_rms = sqrt(sh / (double)(r->n ? r->n : 1u));
    out->length = rx_length();
    out->stream_bytes = g_map.stats.map_bytes;
    {
        const long b = final_map_bytes(&last);
        if (b < 0 || out->length < 0.0) {
            return -1;
        }
        out->final_bytes = (unsigned long)b;
    }
    return 0;
}

/* ---- Table ------------------------------------------------------------------------ */

typedef struct {
    const char *name;
    size_t n_scans;
    int has_axis;
    run_result_t res[3];
} column_t;

static column_t g_cols[MAX_COLS];
static size_t g_n_cols;

static int run_column(const char *name, run_t *r)
{
    column_t *c = &g_cols[g_n_cols];
    int m;
    c->name = name;
    c->n_scans = r->n;
    c->has_axis = r->axis_x != 0.0 || r->axis_y != 0.0;
    for (m = 0; m < 3; ++m) {
        if (fuse_run(r, (mode_t_)m, &c->res[m]) != 0) {
            fprintf(stderr, "bench_align: %s: a call failed\n", name);
            return -1;
        }
    }
    ++g_n_cols;
    return 0;
}

static void row(const char *what)
{
    printf("| %s |", what);
}

static void print_table(void)
{
    size_t i;
    int d;
    printf("| figure |");
    for (i = 0; i < g_n_cols; ++i) {
        printf(" %s |", g_cols[i].name);
    }
    printf("\n|---|");
    for (i = 0; i < g_n_cols; ++i) {
        printf("---|");
    }
    printf("\n");
#define ROW(label, fmt, ...)                                                                       \
    do {                                                                                           \
        row(label);                                                                                \
        for (i = 0; i < g_n_cols; ++i) {                                                           \
            const column_t *c = &g_cols[i];                                                        \
            printf(" " fmt " |", __VA_ARGS__);                                                     \
        }                                                                                          \
        printf("\n");                                                                              \
    } while (0)
    ROW("scans", "%zu", c->n_scans);
    ROW("prior only: translation error RMS / max, m", "%.3f / %.3f", c->res[1].err_rms,
        c->res[1].err_max);
    ROW("aligned: translation error RMS / max, m", "%.3f / %.3f", c->res[2].err_rms,
        c->res[2].err_max);
    ROW("prior only: heading error RMS / max, deg", "%.2f / %.2f", c->res[1].head_rms * 180.0 / PI,
        c->res[1].head_max * 180.0 / PI);
    ROW("aligned: heading error RMS / max, deg", "%.2f / %.2f", c->res[2].head_rms * 180.0 / PI,
        c->res[2].head_max * 180.0 / PI);
    row("along-axis error max, m: prior-only run / aligned run's priors / aligned run");
    for (i = 0; i < g_n_cols; ++i) {
        if (g_cols[i].has_axis) {
            printf(" %.3f / %.3f / %.3f |", g_cols[i].res[1].along_max,
                   g_cols[i].res[2].along_prior_max, g_cols[i].res[2].along_max);
        } else {
            printf(" – |");
        }
    }
    printf("\n");
    row("largest along-axis move by alignment, m");
    for (i = 0; i < g_n_cols; ++i) {
        if (g_cols[i].has_axis) {
            printf(" %.4f |", g_cols[i].res[2].along_corr_max);
        } else {
            printf(" – |");
        }
    }
    printf("\n");
    ROW("true-pose map: curve length m, final map bytes, update stream bytes", "%.1f, %lu, %lu",
        c->res[0].length, c->res[0].final_bytes, c->res[0].stream_bytes);
    ROW("curve length vs true-pose map, prior / aligned", "%+.1f %% / %+.1f %%",
        100.0 * (c->res[1].length / c->res[0].length - 1.0),
        100.0 * (c->res[2].length / c->res[0].length - 1.0));
    ROW("final map bytes vs true-pose map, prior / aligned", "%+.1f %% / %+.1f %%",
        100.0 * ((double)c->res[1].final_bytes / (double)c->res[0].final_bytes - 1.0),
        100.0 * ((double)c->res[2].final_bytes / (double)c->res[0].final_bytes - 1.0));
    ROW("update stream bytes vs true-pose map, prior / aligned", "%+.1f %% / %+.1f %%",
        100.0 * ((double)c->res[1].stream_bytes / (double)c->res[0].stream_bytes - 1.0),
        100.0 * ((double)c->res[2].stream_bytes / (double)c->res[0].stream_bytes - 1.0));
    for (d = 1; d < BSF_ALIGN_DECLINE_COUNT; ++d) {
        char label[96];
        snprintf(label, sizeof label, "declined: %s", bsf_align_decline_str(d));
        ROW(label, "%.1f %%",
            100.0 * (double)c->res[2].declined[d] /
                (double)(c->res[2].n_aligned ? c->res[2].n_aligned : 1u));
    }
    ROW("a direction left free (kept at the prior)", "%.1f %%",
        100.0 * (double)c->res[2].n_free /
            (double)(c->res[2].n_aligned ? c->res[2].n_aligned : 1u));
    ROW("host time per alignment, us", "%.0f",
        c->res[2].align_us / (double)(c->res[2].n_aligned ? c->res[2].n_aligned : 1u));
#undef ROW
}

int main(int argc, char **argv)
{
    const char *data = BSF_SHARED_DIR_DEFAULT "/data";
    const char *only = NULL;
    long max_scans = -1;
    long n_poses = 300;
    uint64_t seed = 1;
    int check = 0;
    int i;
    static const char *const logs[3] = {"intel", "mit-csail", "fr079"};
    static const char *const log_cols[3] = {"intel-seq", "mit-seq", "fr079-seq"};
    static const char *const office_cols[3] = {"office-1", "office-2", "office-5"};
    static const double levels[3] = {0.01, 0.02, 0.05};
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--data") == 0 && i + 1 < argc) {
            data = argv[++i];
        } else if (strcmp(argv[i], "--scans") == 0 && i + 1 < argc) {
            max_scans = strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--poses") == 0 && i + 1 < argc) {
            n_poses = strtol(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc) {
            only = argv[++i];
        } else if (strcmp(argv[i], "--check") == 0) {
            check = 1;
        } else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) {
            seed = (uint64_t)strtoull(argv[++i], NULL, 10);
        } else {
            fprintf(stderr, "usage: bench_align [--data DIR] [--scans N] [--poses N] "
                            "[--only NAME] [--seed S] [--check]\n");
            return 2;
        }
    }
    if (n_poses < 10 || n_poses > 100000) {
        fprintf(stderr, "bench_align: --poses must be in [10, 100000]\n");
        return 2;
    }
    for (i = 0; i < 3; ++i) {
        char path[4096];
        run_t r;
        int rc;
        if (only != NULL && strcmp(only, log_cols[i]) != 0) {
            continue;
        }
        memset(&r, 0, sizeof r);
        snprintf(path, sizeof path, "%s/%s.log.gz", data, logs[i]);
        rc = load_log(&r, path, max_scans, 1);
        if (rc < 0 || (rc == 0 && run_column(log_cols[i], &r) != 0)) {
            run_free(&r);
            return 1;
        }
        run_free(&r);
    }
    if (only == NULL || strcmp(only, "mit-raw") == 0) {
        char path[4096];
        char odo_path[4096];
        run_t r;
        int rc;
        memset(&r, 0, sizeof r);
        snprintf(path, sizeof path, "%s/mit-csail.log.gz", data);
        snprintf(odo_path, sizeof odo_path, "%s/alt/mit-csail-slameval.clf.gz", data);
        rc = load_log(&r, path, max_scans, 0);
        if (rc == 0) {
            rc = raw_odometry(&r, r.stamps, odo_path);
        }
        if (rc < 0 || (rc == 0 && run_column("mit-raw", &r) != 0)) {
            run_free(&r);
            return 1;
        }
        run_free(&r);
    }
    for (i = 0; i < 2; ++i) {
        static const char *const sim_logs[2] = {"intel", "alt/intel-corrected"};
        static const char *const sim_cols[2] = {"intel-sim-2", "intel-kf-sim-2"};
        char path[4096];
        run_t r;
        int rc;
        if (only != NULL && strcmp(only, sim_cols[i]) != 0) {
            continue;
        }
        memset(&r, 0, sizeof r);
        snprintf(path, sizeof path, "%s/%s.log.gz", data, sim_logs[i]);
        rc = load_log(&r, path, max_scans, 0);
        if (rc == 0) {
            perturb(&r, 0.02, seed + 20u + (uint64_t)i);
        }
        if (rc < 0 || (rc == 0 && run_column(sim_cols[i], &r) != 0)) {
            run_free(&r);
            return 1;
        }
        run_free(&r);
    }
    for (i = 0; i < 3; ++i) {
        bsf_scene_t sc;
        pose_d *poses;
        run_t r;
        long k;
        if (only != NULL && strcmp(only, office_cols[i]) != 0) {
            continue;
        }
        memset(&r, 0, sizeof r);
        bsf_scene_demo_office(&sc);
        poses = malloc((size_t)n_poses * sizeof *poses);
        if (poses == NULL) {
            return 1;
        }
        for (k = 0; k < n_poses; ++k) {
            bsf_scene_demo_pose(k, n_poses, &poses[k].x, &poses[k].y, &poses[k].t);
        }
        if (load_scene(&r, &sc, poses, (size_t)n_poses, 0.0, 1000u) != 0) {
            free(poses);
            return 1;
        }
        free(poses);
        perturb(&r, levels[i], seed + (uint64_t)i);
        if (run_column(office_cols[i], &r) != 0) {
            run_free(&r);
            return 1;
        }
        run_free(&r);
    }
    if (only == NULL || strcmp(only, "corridor-2") == 0) {
        bsf_scene_t sc;
        pose_d poses[121];
        run_t r;
        int k;
        memset(&r, 0, sizeof r);
        bsf_scene_init(&sc);
        if (bsf_scene_add_segment(&sc, -30.0, -1.0, 30.0, -1.0) < 0 ||
            bsf_scene_add_segment(&sc, -30.0, 1.0, 30.0, 1.0) < 0) {
            return 1;
        }
        for (k = 0; k < 121; ++k) {
            poses[k].x = -15.0 + 0.25 * k;
            poses[k].y = 0.3 * sin(0.1 * k);
            poses[k].t = 0.1 * cos(0.1 * k);
        }
        if (load_scene(&r, &sc, poses, 121u, 6.0, 5000u) != 0) {
            return 1;
        }
        r.axis_x = 1.0;
        perturb(&r, 0.02, seed + 10u);
        if (run_column("corridor-2", &r) != 0) {
            run_free(&r);
            return 1;
        }
        run_free(&r);
    }
    if (g_n_cols == 0u) {
        fprintf(stderr, "bench_align: nothing measured\n");
        return 1;
    }
    print_table();
    if (check) {
        size_t c;
        for (c = 0; c < g_n_cols; ++c) {
            const run_result_t *p = &g_cols[c].res[1], *a = &g_cols[c].res[2];
            if (!(isfinite(a->err_rms) && isfinite(a->head_rms) && isfinite(a->length) &&
                  a->length > 0.0 && a->err_rms < p->err_rms && a->head_rms < p->head_rms)) {
                fprintf(stderr, "bench_align: --check: %s: aligned no better than the prior\n",
                        g_cols[c].name);
                return 1;
            }
        }
    }
    return 0;
}
