/* SPDX-License-Identifier: MIT */
/*
 * cmd_render.c - bsf render: a stream drawn as an SVG map in the world frame.
 */
#include "tool.h"

static const char render_help[] =
    "Usage: bsf render IN -o MAP.svg [--scans K..L] [--points LOG] [--prior CSV] [--width PX]\n"
    "Draw the stream's B-spline features (exact quadratic curves) in the world\n"
    "frame (poses from the stream) over a grid labelled in metres, with the robot's\n"
    "path and last pose, vertices as red squares, a legend and a scale bar.\n"
    "--scans keeps the frames with sequence numbers K..L (K..K: one scan);\n"
    "--points draws those scans' raw points from LOG underneath (same numbering:\n"
    "the n-th laser scan of the log), thinned to one per pixel-sized cell, so a\n"
    "whole log stays a few megabytes.\n"
    "--prior draws the odometry (prior) path of a CSV that bsf extract --align\n"
    "--prior-path wrote as a dashed line beside the stream's (corrected) path\n"
    "(its rows of the scans --scans keeps).\n"
    "--width sets the drawing's width in pixels (default 1600). The stream is read\n"
    "several times (a pipe is spooled to a temporary file), so memory does not grow\n"
    "with its length. Exits 1 when a non-empty input holds no valid frame.\n";

typedef struct {
    double x, y, c, s;
} pose2_t;

static pose2_t pose_of(const bsf_frame_t *f)
{
    pose2_t p;
    const double th = f->has_pose ? (double)f->pose.theta : 0.0;
    p.x = f->has_pose ? (double)f->pose.x : 0.0;
    p.y = f->has_pose ? (double)f->pose.y : 0.0;
    p.c = cos(th);
    p.s = sin(th);
    return p;
}

static void to_world(const pose2_t *p, double sx, double sy, double *wx, double *wy)
{
    *wx = p->x + p->c * sx - p->s * sy;
    *wy = p->y + p->s * sx + p->c * sy;
}

/* Visit every curve sample of a frame in world coordinates. */
typedef void (*sample_fn)(void *ctx, int new_curve, double wx, double wy);

static void for_each_curve_sample(const bsf_frame_t *fr, sample_fn fn, void *ctx)
{
    const bsf_result_t *r = &fr->result;
    const pose2_t pose = pose_of(fr);
    size_t i;
    for (i = 0; i < r->n_features; ++i) {
        const bsf_feature_t *f = &r->features[i];
        const size_t spans = f->n_ctrl >= 3u ? (size_t)f->n_ctrl - 2u : 1u;
        const size_t samples = spans * 8u;
        size_t k;
        for (k = 0; k <= samples; ++k) {
            bsf_point_t p;
            double wx, wy;
            if (bsf_bspline_eval(&r->ctrl[f->ctrl_first], f->n_ctrl, (float)k / (float)samples, &p,
                                 NULL, NULL) != BSF_OK) {
                break;
            }
            to_world(&pose, (double)p.x, (double)p.y, &wx, &wy);
            fn(ctx, k == 0u, wx, wy);
        }
    }
}

/*
 * Robust map bounds: the central 99 % of the curve samples in x and in y, so
 * that a few stray features (a reflection, a bad pose) do not shrink the map
 * to a corner. Memory must not grow with the stream, so instead of keeping
 * every sample the stream is read twice: once for the extremes and the
 * count, once into a fine histogram per axis between them; a quantile is
 * then known to one bin (a millionth of the extent), and the bounds are
 * rounded outwards to whole bins.
 */
#define BOUNDS_BINS (1u << 20)

typedef struct {
    int pass; /* 0: extremes, 1: histograms */
    double min[2], max[2];
    unsigned long long n;
    uint32_t *hist[2];
    long lo, hi;              /* sequence range drawn */
    unsigned long frames;     /* features frames in range */
    unsigned long no_pose;    /* of which without a pose */
    unsigned long map_frames; /* map-update frames (not drawn here: bsf map) */
    uint32_t max_seq;         /* largest sequence number in the stream */
    int have_seq;
} bounds_ctx_t;

static size_t bin_of(const bounds_ctx_t *b, int axis, double v)
{
    const double w = b->max[axis] - b->min[axis];
    double t = w > 0.0 ? (v - b->min[axis]) / w : 0.0;
    size_t i;
    if (t < 0.0) {
        t = 0.0;
    }
    i = (size_t)(t * (double)BOUNDS_BINS);
    return i < BOUNDS_BINS ? i : BOUNDS_BINS - 1u;
}

static void bounds_sample(void *vctx, int new_curve, double wx, double wy)
{
    bounds_ctx_t *b = (bounds_ctx_t *)vctx;
    (void)new_curve;
    if (b->pass == 0) {
        if (b->n == 0u) {
            b->min[0] = b->max[0] = wx;
            b->min[1] = b->max[1] = wy;
        }
        b->min[0] = wx < b->min[0] ? wx : b->min[0];
        b->max[0] = wx > b->max[0] ? wx : b->max[0];
        b->min[1] = wy < b->min[1] ? wy : b->min[1];
        b->max[1] = wy > b->max[1] ? wy : b->max[1];
        ++b->n;
    } else {
        ++b->hist[0][bin_of(b, 0, wx)];
        ++b->hist[1][bin_of(b, 1, wy)];
    }
}

/* The bin holding the sample of 0-based rank r. */
static size_t bin_of_rank(const uint32_t *hist, unsigned long long r)
{
    unsigned long long seen = 0;
    size_t i;
    for (i = 0; i < BOUNDS_BINS; ++i) {
        seen += hist[i];
        if (seen > r) {
            return i;
        }
    }
    return BOUNDS_BINS - 1u;
}

static double bin_edge(const bounds_ctx_t *b, int axis, size_t i)
{
    return b->min[axis] + (b->max[axis] - b->min[axis]) * (double)i / (double)BOUNDS_BINS;
}

static void robust_bounds(const bounds_ctx_t *b, bsf_bounds_t *out)
{
    const unsigned long long lo = b->n >= 1000u ? b->n / 200u : 0u;
    const unsigned long long hi = b->n - 1u - lo;
    double x0 = b->min[0], x1 = b->max[0], y0 = b->min[1], y1 = b->max[1];
    double mx, my;
    if (b->n == 0u) {
        return;
    }
    if (lo > 0u) {
        x0 = bin_edge(b, 0, bin_of_rank(b->hist[0], lo));
        x1 = bin_edge(b, 0, bin_of_rank(b->hist[0], hi) + 1u);
        y0 = bin_edge(b, 1, bin_of_rank(b->hist[1], lo));
        y1 = bin_edge(b, 1, bin_of_rank(b->hist[1], hi) + 1u);
    }
    mx = 0.05 * (x1 - x0);
    my = 0.05 * (y1 - y0);
    bsf_bounds_add(out, x0 - mx, y0 - my);
    bsf_bounds_add(out, x1 + mx, y1 + my);
}

/* A frame's features as exact curves in the world frame. */
static void draw_features(bsf_svg_t *svg, const bsf_frame_t *fr)
{
    const bsf_result_t *r = &fr->result;
    const pose2_t pose = pose_of(fr);
    double xy[2 * BSF_MAX_CTRL_PER_FEATURE];
    size_t i, k;
    for (i = 0; i < r->n_features; ++i) {
        const bsf_feature_t *f = &r->features[i];
        if (f->n_ctrl > BSF_MAX_CTRL_PER_FEATURE || (size_t)f->ctrl_first + f->n_ctrl > r->n_ctrl) {
            continue; /* the decoder never delivers these */
        }
        for (k = 0; k < f->n_ctrl; ++k) {
            const bsf_point_t *c = &r->ctrl[f->ctrl_first + k];
            to_world(&pose, (double)c->x, (double)c->y, &xy[2 * k], &xy[2 * k + 1]);
        }
        bsf_svg_curve_bspline2(svg, xy, f->n_ctrl);
    }
}

static int in_range(uint32_t seq, long lo, long hi)
{
    return (long)seq >= lo && (hi < 0 || (long)seq <= hi);
}

/* Raw points are thinned to one per cell of this size (and at least one
 * pixel): a map stays a few megabytes whatever the number of scans. */
#define RENDER_POINT_CELL_M 0.01
/* Diameter of a drawn point, metres (kept between 1.8 and 5 pixels). */
#define RENDER_POINT_DOT_M 0.03

/* The log's scans in the range, as world points: into the bounds (pts NULL)
 * or drawn (thinned) into pts. */
static int draw_log_points(bsf_svg_points_t *pts, const char *log, long lo, long hi,
                           const bounds_ctx_t *frames, bsf_bounds_t *bounds)
{
    carmen_reader_t *rd = open_log(log);
    carmen_scan_t rec;
    unsigned long index = 0;
    int r;
    if (rd == NULL) {
        return -1;
    }
    while ((r = carmen_next(rd, &rec)) > 0) {
        size_t i;
        pose2_t p;
        const float rmax = scan_range_max(&rec, 0.0);
        const double th = rec.laser_pose.theta;
        if (!in_range((uint32_t)index, lo, hi) ||
            (frames->have_seq && hi < 0 && index > frames->max_seq)) {
            ++index;
            if (hi >= 0 && (long)index > hi) {
                break;
            }
            continue;
        }
        p.x = rec.laser_pose.x;
        p.y = rec.laser_pose.y;
        p.c = cos(th);
        p.s = sin(th);
        for (i = 0; i < rec.count; ++i) {
            const float rg = rec.ranges[i];
            double wx, wy;
            const double a = (double)rec.angle_min + (double)i * (double)rec.angle_increment;
            if (!bsf_range_is_valid(rg, 0.0f, rmax)) {
                continue;
            }
            to_world(&p, (double)rg * cos(a), (double)rg * sin(a), &wx, &wy);
            if (pts != NULL) {
                bsf_svg_points_add(pts, wx, wy);
            } else {
                bsf_bounds_add(bounds, wx, wy);
            }
        }
        ++index;
    }
    carmen_close(rd);
    return r < 0 ? -1 : 0;
}

int render_log_points(bsf_svg_t *svg, const char *log, bsf_bounds_t *bounds, unsigned long *read,
                      unsigned long *drawn, double *cell_m)
{
    static bounds_ctx_t all; /* every scan: no sequence range, no stream */
    bsf_svg_points_t pts;
    int rc;
    memset(&all, 0, sizeof all);
    all.hi = -1;
    if (svg == NULL) {
        return draw_log_points(NULL, log, 0, -1, &all, bounds);
    }
    memset(&pts, 0, sizeof pts);
    if (bsf_svg_points_begin(&pts, svg, RENDER_POINT_CELL_M,
                             fmin(5.0, fmax(1.8, RENDER_POINT_DOT_M * svg->px_per_m)),
                             RENDER_POINT_COLOUR) != 0) {
        fail_msg("out of memory");
        return -1;
    }
    rc = draw_log_points(&pts, log, 0, -1, &all, NULL);
    *read = pts.kept + pts.merged + pts.outside;
    *drawn = pts.kept;
    *cell_m = pts.cell_m;
    bsf_svg_points_end(&pts);
    return rc;
}

/* The robot's path: poses fed in order to render_path_point(), one
 * polyline; a jump of more than 5 m (a new log segment, a relocalisation)
 * starts a new line. render_path_end() marks the last pose. */
void render_path_point(bsf_svg_t *svg, render_path_t *p, double x, double y, double theta)
{
    if (p->n == 0 || hypot(x - p->x, y - p->y) > 5.0) {
        bsf_svg_path_end(svg, RENDER_PATH_COLOUR, 1.4);
        bsf_svg_path_begin(svg);
    }
    bsf_svg_path_point(svg, x, y);
    p->x = x;
    p->y = y;
    p->theta = theta;
    ++p->n;
}

static void path_add(bsf_svg_t *svg, render_path_t *p, const bsf_frame_t *fr)
{
    if (fr->has_pose) {
        render_path_point(svg, p, (double)fr->pose.x, (double)fr->pose.y, (double)fr->pose.theta);
    }
}

void render_path_end(bsf_svg_t *svg, const render_path_t *p)
{
    bsf_svg_path_end(svg, RENDER_PATH_COLOUR, 1.4);
    if (p->n > 0) {
        bsf_svg_robot(svg, p->x, p->y, p->theta, RENDER_PATH_COLOUR);
    }
}

/* Longest line of a prior-path CSV: eleven numbers of at most ~25 characters. */
#define PRIOR_LINE_MAX 512
/* Largest coordinate accepted, metres: beyond it the file is not a robot's path. */
#define PRIOR_COORD_MAX 1e7

/* Columns of a prior-path CSV. */
#define PRIOR_COLUMNS 11

/* One row of a prior-path CSV: its scan index and odometry pose (x, y,
 * theta). 0, or -1. */
static int parse_prior_row(const char *line, double *scan, double *x, double *y, double *theta)
{
    double v[PRIOR_COLUMNS];
    const char *p = line;
    int k;
    for (k = 0; k < PRIOR_COLUMNS; ++k) {
        char *end = NULL;
        errno = 0;
        v[k] = strtod(p, &end);
        if (end == p || errno != 0 || !isfinite(v[k])) {
            return -1;
        }
        p = end;
        if (k + 1 < PRIOR_COLUMNS) {
            if (*p != ',') {
                return -1;
            }
            ++p;
        }
    }
    for (k = 2; k < PRIOR_COLUMNS; ++k) {
        if (k % 3 != 1 && fabs(v[k]) > PRIOR_COORD_MAX) { /* x and y; theta is k % 3 == 1 */
            return -1;
        }
    }
    if (*p != '\0' || !(v[0] >= 0.0 && v[0] <= 4294967295.0) || v[0] != floor(v[0])) {
        return -1;
    }
    *scan = v[0];
    *x = v[2];
    *y = v[3];
    *theta = v[4];
    return 0;
}

int render_prior_path(bsf_svg_t *svg, const char *csv, long lo, long hi, bsf_bounds_t *bounds,
                      unsigned long *n)
{
    static const char header[] =
        "scan,time_s,odometry_x,odometry_y,odometry_theta,prior_x,prior_y,prior_theta,aligned_x,"
        "aligned_y,aligned_theta";
    char line[PRIOR_LINE_MAX];
    unsigned long lineno = 0, poses = 0;
    double last_x = 0.0, last_y = 0.0;
    int rc = 0;
    FILE *f = fopen(csv, "r");
    if (f == NULL) {
        fail_msg("cannot open %s: %s", csv, strerror(errno));
        return -1;
    }
    while (fgets(line, sizeof line, f) != NULL) {
        size_t len = strlen(line);
        double scan, x, y, th;
        ++lineno;
        if (len > 0u && line[len - 1u] == '\n') {
            line[--len] = '\0';
        } else if (!feof(f)) {
            fail_msg("%s:%lu: line longer than %d bytes: not a prior path (bsf extract "
                     "--prior-path writes one)",
                     csv, lineno, PRIOR_LINE_MAX - 2);
            rc = -1;
            break;
        }
        if (len > 0u && line[len - 1u] == '\r') {
            line[--len] = '\0';
        }
        if (lineno == 1u) {
            if (strcmp(line, header) != 0) {
                fail_msg("%s:1: not a prior path: the header must be %s (bsf extract "
                         "--prior-path writes it)",
                         csv, header);
                rc = -1;
                break;
            }
            continue;
        }
        if (parse_prior_row(line, &scan, &x, &y, &th) != 0) {
            fail_msg("%s:%lu: malformed row (%d finite numbers, coordinates within %g m)", csv,
                     lineno, PRIOR_COLUMNS, PRIOR_COORD_MAX);
            rc = -1;
            break;
        }
        if (!in_range((uint32_t)scan, lo, hi)) {
            continue;
        }
        if (bounds != NULL) {
            bsf_bounds_add(bounds, x, y);
        }
        if (svg != NULL) {
            if (poses == 0u || hypot(x - last_x, y - last_y) > 5.0) {
                bsf_svg_path_end_dashed(svg, RENDER_PRIOR_COLOUR, 1.4, "6,4");
                bsf_svg_path_begin(svg);
            }
            bsf_svg_path_point(svg, x, y);
        }
        last_x = x;
        last_y = y;
        ++poses;
    }
    if (rc == 0 && ferror(f)) {
        fail_msg("read error on %s", csv);
        rc = -1;
    }
    if (rc == 0 && lineno == 0u) {
        fail_msg("%s is empty: not a prior path (bsf extract --prior-path writes one)", csv);
        rc = -1;
    }
    if (rc == 0 && poses == 0u) {
        fail_msg("%s holds no pose%s", csv, lo > 0 || hi >= 0 ? " of the scans drawn" : "");
        rc = -1;
    }
    if (svg != NULL) {
        bsf_svg_path_end_dashed(svg, RENDER_PRIOR_COLOUR, 1.4, "6,4");
    }
    fclose(f);
    if (n != NULL) {
        *n = poses;
    }
    return rc;
}

/* A frame's vertices (pairs of flagged control points) as markers; returns
 * how many. */
static unsigned long draw_vertices(bsf_svg_t *svg, const bsf_frame_t *fr)
{
    const pose2_t pose = pose_of(fr);
    unsigned long n = 0;
    size_t k;
    for (k = 0; k + 1u < fr->result.n_ctrl; ++k) {
        if (fr->result.ctrl_is_vertex[k] && fr->result.ctrl_is_vertex[k + 1u]) {
            double wx, wy;
            to_world(&pose, (double)fr->result.ctrl[k].x, (double)fr->result.ctrl[k].y, &wx, &wy);
            bsf_svg_vertex(svg, wx, wy, 3.5, RENDER_VERTEX_COLOUR);
            ++n;
            ++k;
        }
    }
    return n;
}

/* The legend row: the layers that are in the picture. */
void render_legend(bsf_svg_t *svg, int have_path, int have_points, int have_scene, int have_prior)
{
    bsf_svg_legend_item_t key[6];
    size_t n = 0;
    key[n].key = BSF_SVG_KEY_LINE;
    key[n].colour = RENDER_CURVE_COLOUR;
    key[n++].text = "B-spline features";
    key[n].key = BSF_SVG_KEY_VERTEX;
    key[n].colour = RENDER_VERTEX_COLOUR;
    key[n++].text = "vertices (corners)";
    if (have_path) {
        key[n].key = BSF_SVG_KEY_LINE;
        key[n].colour = RENDER_PATH_COLOUR;
        key[n++].text =
            have_prior ? "corrected path (aligned) and last pose" : "robot path and last pose";
    }
    if (have_prior) {
        key[n].key = BSF_SVG_KEY_DASH;
        key[n].colour = RENDER_PRIOR_COLOUR;
        key[n++].text = "prior path (odometry)";
    }
    if (have_points) {
        key[n].key = BSF_SVG_KEY_DOT;
        key[n].colour = RENDER_POINT_COLOUR;
        key[n++].text = "raw LIDAR points (thinned)";
    }
    if (have_scene) {
        key[n].key = BSF_SVG_KEY_LINE;
        key[n].colour = RENDER_WALL_COLOUR;
        key[n++].text = "true walls";
    }
    bsf_svg_legend(svg, key, n);
}

static int parse_scan_range(const char *v, long *lo, long *hi)
{
    const char *dots = strstr(v, "..");
    char a[32], b[32];
    size_t la;
    if (dots == NULL) {
        return -1;
    }
    la = (size_t)(dots - v);
    if (la == 0 || la >= sizeof a || strlen(dots + 2) >= sizeof b) {
        return -1;
    }
    memcpy(a, v, la);
    a[la] = '\0';
    strcpy(b, dots + 2);
    if (parse_long(a, 0, 2000000000L, lo) != 0) {
        return -1;
    }
    if (b[0] == '\0') {
        *hi = -1;
        return 0;
    }
    if (parse_long(b, 0, 2000000000L, hi) != 0 || *hi < *lo) {
        return -1;
    }
    return 0;
}

static void draw_scene(bsf_svg_t *svg, const bsf_scene_t *scene, bsf_bounds_t *b)
{
    size_t i;
    int k;
    for (i = 0; i < scene->n_shapes; ++i) {
        const bsf_shape_t *sh = &scene->shape[i];
        if (svg != NULL) {
            bsf_svg_path_begin(svg);
        }
        for (k = 0; k <= (sh->kind == BSF_SHAPE_CIRCLE ? 64 : 1); ++k) {
            double x, y;
            if (sh->kind == BSF_SHAPE_CIRCLE) {
                x = sh->x0 + sh->r * cos(2.0 * M_PI * k / 64.0);
                y = sh->y0 + sh->r * sin(2.0 * M_PI * k / 64.0);
            } else {
                x = k ? sh->x1 : sh->x0;
                y = k ? sh->y1 : sh->y0;
            }
            if (svg != NULL) {
                bsf_svg_path_point(svg, x, y);
            } else {
                bsf_bounds_add(b, x, y);
            }
        }
        if (svg != NULL) {
            bsf_svg_path_end(svg, RENDER_WALL_COLOUR, 5.0);
        }
    }
}

/* Pass over the stream: bounds (extremes, then histograms), curves, path, vertices. */
typedef enum { PASS_EXTREMES, PASS_HISTOGRAM, PASS_CURVES, PASS_PATH, PASS_VERTICES } render_pass_t;

typedef struct {
    render_pass_t pass;
    bounds_ctx_t *b;
    bsf_svg_t *svg;
    render_path_t path;
    unsigned long vertices;
} render_ctx_t;

static int render_frame(void *vctx, const bsf_frame_t *fr, size_t bytes)
{
    render_ctx_t *rc = (render_ctx_t *)vctx;
    (void)bytes;
    if (fr->type == BSF_FRAME_TYPE_MAP && rc->pass == PASS_EXTREMES) {
        ++rc->b->map_frames;
    }
    if (fr->type != BSF_FRAME_TYPE_FEATURES) {
        return 0;
    }
    if (rc->pass == PASS_EXTREMES) {
        rc->b->max_seq = (!rc->b->have_seq || fr->seq > rc->b->max_seq) ? fr->seq : rc->b->max_seq;
        rc->b->have_seq = 1;
    }
    if (!in_range(fr->seq, rc->b->lo, rc->b->hi)) {
        return 0;
    }
    switch (rc->pass) {
    case PASS_EXTREMES:
        ++rc->b->frames;
        rc->b->no_pose += fr->has_pose ? 0u : 1u;
        /* fall through */
    case PASS_HISTOGRAM:
        for_each_curve_sample(fr, bounds_sample, rc->b);
        if (fr->has_pose) { /* the robot's positions belong in the picture */
            bounds_sample(rc->b, 0, (double)fr->pose.x, (double)fr->pose.y);
        }
        break;
    case PASS_CURVES: draw_features(rc->svg, fr); break;
    case PASS_PATH: path_add(rc->svg, &rc->path, fr); break;
    default: rc->vertices += draw_vertices(rc->svg, fr); break;
    }
    return 0;
}

static int render_pass(FILE *in, const char *in_name, render_ctx_t *rc, render_pass_t pass)
{
    stream_summary_t sum;
    rc->pass = pass;
    rc->b->pass = pass == PASS_EXTREMES ? 0 : 1;
    if (rewind_input(in, in_name) != 0) {
        return -1;
    }
    return decode_stream(in, in_name, render_frame, rc, &sum);
}

int write_map_svg(const char *out_path, FILE *in, const char *in_name, long lo, long hi,
                  const char *points_log, const bsf_scene_t *scene, const char *prior_csv,
                  const char *title, double width_px)
{
    static bounds_ctx_t bc;
    bsf_bounds_t b;
    bsf_svg_t svg;
    bsf_svg_points_t pts;
    render_ctx_t rc;
    FILE *out;
    char caption[200];
    int failed;
    unsigned long prior_poses = 0;

    memset(&bc, 0, sizeof bc);
    bc.lo = lo;
    bc.hi = hi;
    memset(&rc, 0, sizeof rc);
    rc.b = &bc;
    rc.svg = &svg;
    bsf_bounds_init(&b);
    if (render_pass(in, in_name, &rc, PASS_EXTREMES) != 0) {
        return -1;
    }
    if (bc.frames == 0u && bc.map_frames > 0u) {
        fail_msg("%s holds map-update frames, not per-scan features: bsf map %s -o MAP.svg "
                 "draws its map",
                 in_name, in_name);
        return -1;
    }
    if (bc.n >= 1000u) {
        bc.hist[0] = (uint32_t *)calloc(BOUNDS_BINS, sizeof(uint32_t));
        bc.hist[1] = (uint32_t *)calloc(BOUNDS_BINS, sizeof(uint32_t));
        failed = bc.hist[0] == NULL || bc.hist[1] == NULL;
        if (failed) {
            fail_msg("out of memory");
        } else {
            failed = render_pass(in, in_name, &rc, PASS_HISTOGRAM) != 0;
        }
        if (!failed) {
            robust_bounds(&bc, &b);
        }
        free(bc.hist[0]);
        free(bc.hist[1]);
        if (failed) {
            return -1;
        }
    } else {
        robust_bounds(&bc, &b);
    }
    if (b.empty && points_log != NULL && draw_log_points(NULL, points_log, lo, hi, &bc, &b) != 0) {
        return -1;
    }
    if (scene != NULL) {
        draw_scene(NULL, scene, &b);
    }
    /* the whole prior path is in the picture, however far it drifted */
    if (prior_csv != NULL && render_prior_path(NULL, prior_csv, lo, hi, &b, NULL) != 0) {
        return -1;
    }
    out = open_out(out_path, 0);
    if (out == NULL) {
        return -1;
    }
    if (bsf_svg_begin(&svg, out, &b, width_px, title) != 0) {
        fail_msg("write error on %s", out_path);
        if (out != stdout) {
            fclose(out);
        }
        return -1;
    }
    bsf_svg_grid(&svg);
    memset(&pts, 0, sizeof pts);
    if (points_log != NULL) {
        /* dots 3 cm wide, between 1.8 and 5 px: visible on a whole map,
         * clear on a one-scan close-up */
        const double dot_px = fmin(5.0, fmax(1.8, RENDER_POINT_DOT_M * svg.px_per_m));
        int prc =
            bsf_svg_points_begin(&pts, &svg, RENDER_POINT_CELL_M, dot_px, RENDER_POINT_COLOUR);
        if (prc != 0) {
            fail_msg("out of memory");
        } else {
            prc = draw_log_points(&pts, points_log, lo, hi, &bc, NULL);
        }
        bsf_svg_points_end(&pts);
        if (prc != 0) {
            if (out != stdout) {
                fclose(out);
            }
            return -1;
        }
    }
    if (scene != NULL) {
        draw_scene(&svg, scene, NULL);
    }
    bsf_svg_curves_begin(&svg, RENDER_CURVE_COLOUR, 1.6);
    failed = render_pass(in, in_name, &rc, PASS_CURVES) != 0;
    bsf_svg_curves_end(&svg);
    if (!failed && prior_csv != NULL) {
        failed = render_prior_path(&svg, prior_csv, lo, hi, NULL, &prior_poses) != 0;
    }
    if (!failed) {
        failed = render_pass(in, in_name, &rc, PASS_PATH) != 0;
        render_path_end(&svg, &rc.path);
    }
    /* vertices on top */
    if (!failed) {
        failed = render_pass(in, in_name, &rc, PASS_VERTICES) != 0;
    }
    render_legend(&svg, rc.path.n > 0, points_log != NULL, scene != NULL, prior_csv != NULL);
    snprintf(caption, sizeof caption, "%lu scans, %lu vertices", bc.frames, rc.vertices);
    if (prior_csv != NULL) {
        size_t len = strlen(caption);
        snprintf(caption + len, sizeof caption - len, "; %lu prior poses", prior_poses);
    }
    if (points_log != NULL) {
        size_t len = strlen(caption);
        snprintf(caption + len, sizeof caption - len, "; %lu raw points, %lu drawn (%.0f cm grid)",
                 pts.kept + pts.merged + pts.outside, pts.kept, 100.0 * pts.cell_m);
    }
    if (bsf_svg_end(&svg, caption) != 0 || close_out(out, out_path) != 0 || failed) {
        return -1;
    }
    if (bc.no_pose) {
        fprintf(stderr, "%s: %lu frames carry no pose; drawn in the sensor frame\n", g_cmd,
                bc.no_pose);
    }
    return 0;
}

int cmd_render(int argc, char **argv)
{
    const char *in_path = NULL;
    draw_opts_t draw = {NULL, NULL, NULL, 1600.0};
    long lo = 0, hi = -1;
    FILE *in;
    int i, err = 0, rc;
    for (i = 1; i < argc; ++i) {
        const char *v;
        if (is_help(argv[i])) {
            fputs(render_help, stdout);
            return 0;
        } else if (draw_option(argc, argv, &i, &draw, &err)) {
            /* stored, or err set */
        } else if ((v = opt_value(argc, argv, &i, "--scans", &err)) != NULL) {
            if (parse_scan_range(v, &lo, &hi) != 0) {
                return usage_error("--scans needs K..L (or K..), got '%s'", v);
            }
        } else if (err) {
            return err;
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            return usage_error("unknown option '%s'", argv[i]);
        } else if (in_path == NULL) {
            in_path = argv[i];
        } else {
            return usage_error("render takes one input, got '%s' too", argv[i]);
        }
        if (err) {
            return err;
        }
    }
    if (in_path == NULL || draw.out_path == NULL) {
        return usage_error("render needs an input stream and -o MAP.svg");
    }
    in = open_seekable(in_path);
    if (in == NULL) {
        return EXIT_FAIL;
    }
    rc = write_map_svg(draw.out_path, in, in_path, lo, hi, draw.points, NULL, draw.prior, in_path,
                       draw.width);
    close_in(in);
    if (rc == 0) {
        fprintf(stderr, "%s: wrote %s\n", g_cmd, draw.out_path);
    }
    return rc == 0 ? 0 : EXIT_FAIL;
}
