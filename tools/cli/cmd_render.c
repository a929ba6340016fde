/* SPDX-License-Identifier: MIT */
/*
 * cmd_render.c - bsf render: a stream drawn as an SVG map in the world frame.
 */
#include "tool.h"

static const char render_help[] =
    "Usage: bsf render IN -o MAP.svg [--scans K..L] [--points LOG] [--width PX]\n"
    "Draw the stream's B-spline features in the world frame (poses from the\n"
    "stream), vertices as squares, with a scale bar. --scans keeps the frames with\n"
    "sequence numbers K..L; --points draws those scans' raw points from LOG\n"
    "underneath (same sequence numbering: the n-th laser scan of the log).\n";

typedef struct {
    double x, y, c, s;
} pose2_t;

static pose2_t pose_of(const bsf_frame_t *f)
{
    pose2_t p;
    const double th = f->has_pose ? (double)f->pose_theta : 0.0;
    p.x = f->has_pose ? (double)f->pose_x : 0.0;
    p.y = f->has_pose ? (double)f->pose_y : 0.0;
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

/* Curve samples gathered for robust map bounds: a few stray features (a
 * reflection, a bad pose) must not shrink the whole map to a corner. */
typedef struct {
    double *x, *y;
    size_t n, cap;
    int oom;
} samples_t;

static void bounds_sample(void *ctx, int new_curve, double wx, double wy)
{
    samples_t *s = (samples_t *)ctx;
    (void)new_curve;
    if (s->oom) {
        return;
    }
    if (s->n == s->cap) {
        const size_t cap = s->cap ? 2u * s->cap : 4096u;
        double *nx = (double *)realloc(s->x, cap * sizeof *nx);
        double *ny = nx ? (double *)realloc(s->y, cap * sizeof *ny) : NULL;
        if (nx != NULL) {
            s->x = nx;
        }
        if (ny == NULL) {
            s->oom = 1;
            return;
        }
        s->y = ny;
        s->cap = cap;
    }
    s->x[s->n] = wx;
    s->y[s->n] = wy;
    s->n++;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a;
    const double y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Bounds holding the central 99 % of the samples in x and in y, widened by
 * 5 %; all of them when there are few. */
static void robust_bounds(samples_t *s, bsf_bounds_t *b)
{
    size_t lo, hi;
    double mx, my;
    if (s->n == 0) {
        return;
    }
    qsort(s->x, s->n, sizeof *s->x, cmp_double);
    qsort(s->y, s->n, sizeof *s->y, cmp_double);
    lo = s->n >= 1000u ? s->n / 200u : 0u;
    hi = s->n - 1u - lo;
    mx = 0.05 * (s->x[hi] - s->x[lo]);
    my = 0.05 * (s->y[hi] - s->y[lo]);
    bsf_bounds_add(b, s->x[lo] - mx, s->y[lo] - my);
    bsf_bounds_add(b, s->x[hi] + mx, s->y[hi] + my);
}

typedef struct {
    bsf_svg_t *svg;
    int open;
} draw_ctx_t;

static void draw_sample(void *vctx, int new_curve, double wx, double wy)
{
    draw_ctx_t *ctx = (draw_ctx_t *)vctx;
    if (new_curve) {
        if (ctx->open) {
            bsf_svg_path_end(ctx->svg, "#1f5fbf", 1.6);
        }
        bsf_svg_path_begin(ctx->svg);
        ctx->open = 1;
    }
    bsf_svg_path_point(ctx->svg, wx, wy);
}

static int in_range(uint32_t seq, long lo, long hi)
{
    return (long)seq >= lo && (hi < 0 || (long)seq <= hi);
}

static int draw_log_points(bsf_svg_t *svg, const char *log, long lo, long hi, const frame_list_t *l,
                           bsf_bounds_t *bounds)
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
            (l->n && hi < 0 && index > l->frames[l->n - 1].seq)) {
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
            if (svg != NULL) {
                bsf_svg_dot(svg, wx, wy, 0.6, "#b0b0b0");
            } else {
                bsf_bounds_add(bounds, wx, wy);
            }
        }
        ++index;
    }
    carmen_close(rd);
    return r < 0 ? -1 : 0;
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
            bsf_svg_path_end(svg, "#c8c8c8", 5.0);
        }
    }
}

int write_map_svg(const char *out_path, const frame_list_t *l, long lo, long hi,
                  const char *points_log, const bsf_scene_t *scene, const char *title)
{
    bsf_bounds_t b;
    bsf_svg_t svg;
    draw_ctx_t dc;
    FILE *out;
    size_t i, k;
    unsigned long drawn = 0, no_pose = 0;
    char legend[160];

    bsf_bounds_init(&b);
    {
        samples_t smp;
        memset(&smp, 0, sizeof smp);
        for (i = 0; i < l->n; ++i) {
            if (in_range(l->frames[i].seq, lo, hi)) {
                for_each_curve_sample(&l->frames[i], bounds_sample, &smp);
            }
        }
        robust_bounds(&smp, &b);
        free(smp.x);
        free(smp.y);
        if (smp.oom) {
            fail_msg("out of memory");
            return -1;
        }
    }
    if (b.empty && points_log != NULL && draw_log_points(NULL, points_log, lo, hi, l, &b) != 0) {
        return -1;
    }
    if (scene != NULL) {
        draw_scene(NULL, scene, &b);
    }
    out = open_out(out_path, 0);
    if (out == NULL) {
        return -1;
    }
    if (bsf_svg_begin(&svg, out, &b, 1600.0, title) != 0) {
        fail_msg("write error on %s", out_path);
        if (out != stdout) {
            fclose(out);
        }
        return -1;
    }
    if (points_log != NULL && draw_log_points(&svg, points_log, lo, hi, l, NULL) != 0) {
        if (out != stdout) {
            fclose(out);
        }
        return -1;
    }
    if (scene != NULL) {
        draw_scene(&svg, scene, NULL);
    }
    dc.svg = &svg;
    dc.open = 0;
    for (i = 0; i < l->n; ++i) {
        const bsf_frame_t *fr = &l->frames[i];
        if (!in_range(fr->seq, lo, hi)) {
            continue;
        }
        ++drawn;
        no_pose += fr->has_pose ? 0u : 1u;
        for_each_curve_sample(fr, draw_sample, &dc);
    }
    if (dc.open) {
        bsf_svg_path_end(&svg, "#1f5fbf", 1.6);
    }
    /* vertices on top */
    for (i = 0; i < l->n; ++i) {
        const bsf_frame_t *fr = &l->frames[i];
        const pose2_t pose = pose_of(fr);
        if (!in_range(fr->seq, lo, hi)) {
            continue;
        }
        for (k = 0; k + 1u < fr->result.n_ctrl; ++k) {
            if (fr->result.ctrl_is_vertex[k] && fr->result.ctrl_is_vertex[k + 1u]) {
                double wx, wy;
                to_world(&pose, (double)fr->result.ctrl[k].x, (double)fr->result.ctrl[k].y, &wx,
                         &wy);
                bsf_svg_square(&svg, wx, wy, 2.5, "#d02020");
                ++k;
            }
        }
    }
    snprintf(legend, sizeof legend, "%lu scans; blue: B-spline features; red squares: vertices%s",
             drawn, points_log ? "; grey: raw points" : (scene ? "; grey: true walls" : ""));
    if (bsf_svg_end(&svg, legend) != 0 || close_out(out, out_path) != 0) {
        return -1;
    }
    if (no_pose) {
        fprintf(stderr, "%s: %lu frames carry no pose; drawn in the sensor frame\n", g_cmd,
                no_pose);
    }
    return 0;
}

int cmd_render(int argc, char **argv)
{
    const char *in_path = NULL, *out_path = NULL, *points = NULL;
    long lo = 0, hi = -1;
    frame_list_t l;
    int i, err = 0, rc;
    for (i = 1; i < argc; ++i) {
        const char *v;
        if (is_help(argv[i])) {
            fputs(render_help, stdout);
            return 0;
        } else if ((v = opt_value(argc, argv, &i, "-o", &err)) != NULL) {
            out_path = v;
        } else if ((v = opt_value(argc, argv, &i, "--scans", &err)) != NULL) {
            if (parse_scan_range(v, &lo, &hi) != 0) {
                return usage_error("--scans needs K..L (or K..), got '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--points", &err)) != NULL) {
            points = v;
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
    if (in_path == NULL || out_path == NULL) {
        return usage_error("render needs an input stream and -o MAP.svg");
    }
    if (load_frames(in_path, &l) != 0) {
        frame_list_free(&l);
        return EXIT_FAIL;
    }
    rc = write_map_svg(out_path, &l, lo, hi, points, NULL, in_path);
    if (rc == 0) {
        fprintf(stderr, "%s: wrote %s (%zu frames in the stream)\n", g_cmd, out_path, l.n);
    }
    frame_list_free(&l);
    return rc == 0 ? 0 : EXIT_FAIL;
}
