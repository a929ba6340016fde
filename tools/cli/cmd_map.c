/* SPDX-License-Identifier: MIT */
/*
 * cmd_map.c - bsf map: the final map of a map stream, as the receiver
 * rebuilds it, as JSON Lines and/or an SVG drawing.
 */
#include "tool.h"

static const char map_help[] =
    "Usage: bsf map IN [--json] [-o MAP.svg] [--points LOG] [--prior CSV] [--width PX]\n"
    "Rebuild the fused map a map stream carries (bsf extract --map; '-' reads\n"
    "standard input) with the library's receiver, frame by frame, and print it.\n"
    "\n"
    "  --json        one JSON object per map feature on stdout:\n"
    "                {\"id\": N, \"stale\": false, \"ctrl\": [[x, y], ...], \"vertex\": [0, 1, "
    "...]}\n"
    "                world-frame control points in metres of a clamped uniform\n"
    "                quadratic B-spline; a vertex (corner) is a control point given\n"
    "                twice, both copies flagged 1, as in a scan's features\n"
    "  -o MAP.svg    draw the map: the same grid, curves, vertices, robot path (from\n"
    "                the stream's pose records) and legend as bsf render\n"
    "  --points LOG  with -o: draw the raw points of a CARMEN log underneath (every\n"
    "                scan through its laser pose, thinned as bsf render thins them),\n"
    "                to judge the map against what the robot saw\n"
    "  --prior CSV   with -o: draw the odometry (prior) path that bsf extract --align\n"
    "                --prior-path wrote, dashed, beside the corrected path of the\n"
    "                stream's pose records\n"
    "  --width PX    drawing width in pixels (default 1600)\n"
    "  -h, --help    this help\n"
    "\n"
    "Without --json or -o, prints a summary: features, control points, vertices,\n"
    "curve length, frames and bytes. The summary goes to stderr otherwise. A feature\n"
    "is stale when the receiver cannot vouch for it: frames were lost since it was\n"
    "last confirmed, or a record of it could not apply, and no snapshot has repaired\n"
    "it yet. Missing: ids the robot sent that never arrived (no points to draw).\n"
    "Exits 1 when the input holds no map frame or the receiver refuses a frame.\n";

#define MAP_MAX_POINTS BSF_MAP_RX_MAX_CTRL

typedef struct {
    map_view_t view;
    unsigned long features_frames; /* per-scan frames seen (not part of the map) */
    int failed;
} map_ctx_t;

static int on_map_frame(void *vctx, const bsf_frame_t *f, size_t bytes)
{
    map_ctx_t *c = (map_ctx_t *)vctx;
    if (f->type == BSF_FRAME_TYPE_FEATURES) {
        ++c->features_frames;
    } else if (f->type == BSF_FRAME_TYPE_MAP && map_view_apply(&c->view, f, bytes, NULL) != 0) {
        c->failed = 1;
    }
    return 0;
}

/* Control points of feature id in metres: count (0: absent), or -1. */
static int feature_points(const map_view_t *v, uint32_t id, bsf_point_t *ctrl, uint8_t *vtx,
                          uint8_t *stale)
{
    const int n = bsf_map_rx_feature_ctrl(v->rx, id, ctrl, vtx, MAP_MAX_POINTS, stale);
    if (n > (int)MAP_MAX_POINTS) {
        fail_msg("feature %lu has %d control points, more than this tool holds", (unsigned long)id,
                 n);
        return -1;
    }
    return n;
}

static void print_json(const map_view_t *v, bsf_point_t *ctrl, uint8_t *vtx)
{
    const uint32_t limit = bsf_map_rx_id_limit(v->rx);
    uint32_t id;
    for (id = 0; id < limit; ++id) {
        uint8_t stale = 0;
        const int n = feature_points(v, id, ctrl, vtx, &stale);
        int k;
        if (n <= 0) {
            continue;
        }
        printf("{\"id\": %lu, \"stale\": %s, \"ctrl\": [", (unsigned long)id,
               stale ? "true" : "false");
        for (k = 0; k < n; ++k) {
            printf("%s[%.4f, %.4f]", k ? ", " : "", (double)ctrl[k].x, (double)ctrl[k].y);
        }
        printf("], \"vertex\": [");
        for (k = 0; k < n; ++k) {
            printf("%s%u", k ? ", " : "", (unsigned)vtx[k]);
        }
        printf("]}\n");
    }
}

/* Point of span s (of `spans`) at u in [0, 1] of a clamped uniform quadratic
 * B-spline with any number of control points (bsf_bspline_eval stops at a
 * scan feature's cap; a map feature is longer). */
static void span_point(const bsf_point_t *c, size_t spans, size_t s, double u, double *x, double *y)
{
    const double a = (1.0 - u) * (1.0 - u), b = 2.0 * u * (1.0 - u), q = u * u;
    double w0 = 0.5 * a, w1 = 0.5 * a + b + 0.5 * q, w2 = 0.5 * q;
    if (spans == 1u) {
        w0 = a;
        w1 = b;
        w2 = q;
    } else if (s == 0u) {
        w0 = a;
        w1 = b + 0.5 * q;
    } else if (s + 1u == spans) {
        w1 = 0.5 * a + b;
        w2 = q;
    }
    *x = w0 * (double)c[s].x + w1 * (double)c[s + 1u].x + w2 * (double)c[s + 2u].x;
    *y = w0 * (double)c[s].y + w1 * (double)c[s + 1u].y + w2 * (double)c[s + 2u].y;
}

/* Totals of the map: features, control points (as given, vertices twice),
 * vertices, flagged features (stale output: unconfirmed, stale), ids sent but
 * never received (missing), curve length (polyline through 16 samples per span). */
typedef struct {
    unsigned long features, ctrl, vertices, stale, missing;
    double length;
} map_totals_t;

static map_totals_t totals_of(const map_view_t *v, bsf_point_t *ctrl, uint8_t *vtx)
{
    const uint32_t limit = bsf_map_rx_id_limit(v->rx);
    map_totals_t t;
    uint32_t id;
    memset(&t, 0, sizeof t);
    for (id = 0; id < limit; ++id) {
        uint8_t stale = 0;
        const int n = feature_points(v, id, ctrl, vtx, &stale);
        int k;
        size_t spans, s;
        double prev_x, prev_y;
        if (n == 0 && bsf_map_rx_feature_state(v->rx, id) == BSF_MAP_RX_MISSING) {
            ++t.missing;
        }
        if (n < 3) {
            continue;
        }
        ++t.features;
        t.ctrl += (unsigned long)n;
        t.stale += stale;
        for (k = 0; k + 1 < n; ++k) {
            if (vtx[k] && vtx[k + 1]) {
                ++t.vertices;
                ++k;
            }
        }
        spans = (size_t)n - 2u;
        prev_x = (double)ctrl[0].x;
        prev_y = (double)ctrl[0].y;
        for (s = 0; s < spans; ++s) {
            int j;
            for (j = 1; j <= 16; ++j) {
                double x, y;
                span_point(ctrl, spans, s, (double)j / 16.0, &x, &y);
                t.length += hypot(x - prev_x, y - prev_y);
                prev_x = x;
                prev_y = y;
            }
        }
    }
    return t;
}

static int write_svg(const char *out_path, const char *title, const map_view_t *v, double width,
                     const char *points_log, const char *prior_csv, bsf_point_t *ctrl, uint8_t *vtx,
                     const map_totals_t *t)
{
    const uint32_t limit = bsf_map_rx_id_limit(v->rx);
    bsf_bounds_t b;
    bsf_svg_t svg;
    render_path_t path;
    char caption[200];
    double *xy;
    FILE *out;
    uint32_t id;
    size_t i;
    int rc;
    unsigned long pts_read = 0, pts_drawn = 0, prior_poses = 0;
    double cell_m = 0.0;
    bsf_bounds_init(&b);
    for (id = 0; id < limit; ++id) {
        const int n = feature_points(v, id, ctrl, vtx, NULL);
        int k;
        for (k = 0; k < n; ++k) {
            bsf_bounds_add(&b, (double)ctrl[k].x, (double)ctrl[k].y);
        }
    }
    for (i = 0; i < v->n_path; ++i) {
        bsf_bounds_add(&b, v->path[3u * i], v->path[3u * i + 1u]);
    }
    /* the whole prior path is in the picture, however far it drifted */
    if (prior_csv != NULL && render_prior_path(NULL, prior_csv, 0, -1, &b, NULL) != 0) {
        return -1;
    }
    if (b.empty && points_log != NULL &&
        render_log_points(NULL, points_log, &b, NULL, NULL, NULL) != 0) {
        return -1;
    }
    xy = (double *)malloc(2u * MAP_MAX_POINTS * sizeof(double));
    if (xy == NULL) {
        fail_msg("out of memory");
        return -1;
    }
    out = open_out(out_path, 0);
    if (out == NULL) {
        free(xy);
        return -1;
    }
    if (bsf_svg_begin(&svg, out, &b, width, title) != 0) {
        fail_msg("write error on %s", out_path);
        if (out != stdout) {
            fclose(out);
        }
        free(xy);
        return -1;
    }
    bsf_svg_grid(&svg);
    if (points_log != NULL &&
        render_log_points(&svg, points_log, NULL, &pts_read, &pts_drawn, &cell_m) != 0) {
        if (out != stdout) {
            fclose(out);
        }
        free(xy);
        return -1;
    }
    bsf_svg_curves_begin(&svg, RENDER_CURVE_COLOUR, 1.6);
    for (id = 0; id < limit; ++id) {
        const int n = feature_points(v, id, ctrl, vtx, NULL);
        int k;
        if (n < 3) {
            continue;
        }
        for (k = 0; k < n; ++k) {
            xy[2 * k] = (double)ctrl[k].x;
            xy[2 * k + 1] = (double)ctrl[k].y;
        }
        bsf_svg_curve_bspline2(&svg, xy, (size_t)n);
    }
    bsf_svg_curves_end(&svg);
    if (prior_csv != NULL && render_prior_path(&svg, prior_csv, 0, -1, NULL, &prior_poses) != 0) {
        if (out != stdout) {
            fclose(out);
        }
        free(xy);
        return -1;
    }
    memset(&path, 0, sizeof path);
    for (i = 0; i < v->n_path; ++i) {
        render_path_point(&svg, &path, v->path[3u * i], v->path[3u * i + 1u], v->path[3u * i + 2u]);
    }
    render_path_end(&svg, &path);
    for (id = 0; id < limit; ++id) {
        const int n = feature_points(v, id, ctrl, vtx, NULL);
        int k;
        for (k = 0; k + 1 < n; ++k) {
            if (vtx[k] && vtx[k + 1]) {
                bsf_svg_vertex(&svg, (double)ctrl[k].x, (double)ctrl[k].y, 3.5,
                               RENDER_VERTEX_COLOUR);
                ++k;
            }
        }
    }
    render_legend(&svg, v->n_path > 0u, points_log != NULL, 0, prior_csv != NULL);
    snprintf(caption, sizeof caption,
             "map: %lu features, %lu vertices, %.1f m of curve; %lu frames", t->features,
             t->vertices, t->length, v->frames);
    if (prior_csv != NULL) {
        const size_t len = strlen(caption);
        snprintf(caption + len, sizeof caption - len, "; %lu prior poses", prior_poses);
    }
    if (points_log != NULL) {
        const size_t len = strlen(caption);
        snprintf(caption + len, sizeof caption - len, "; %lu raw points, %lu drawn (%.0f cm grid)",
                 pts_read, pts_drawn, 100.0 * cell_m);
    }
    rc = bsf_svg_end(&svg, caption) != 0 || close_out(out, out_path) != 0 ? -1 : 0;
    free(xy);
    return rc;
}

int cmd_map(int argc, char **argv)
{
    static map_ctx_t ctx;
    static bsf_point_t ctrl[MAP_MAX_POINTS];
    static uint8_t vtx[MAP_MAX_POINTS];
    const char *in_path = NULL;
    draw_opts_t draw = {NULL, NULL, NULL, 1600.0};
    int json = 0, i, err = 0, rc = 0;
    stream_summary_t sum;
    map_totals_t t;
    FILE *in, *info;
    for (i = 1; i < argc; ++i) {
        if (is_help(argv[i])) {
            fputs(map_help, stdout);
            return 0;
        } else if (strcmp(argv[i], "--json") == 0) {
            json = 1;
        } else if (draw_option(argc, argv, &i, &draw, &err)) {
            /* stored, or err set */
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            return usage_error("unknown option '%s'", argv[i]);
        } else if (in_path == NULL) {
            in_path = argv[i];
        } else {
            return usage_error("map takes one input, got '%s' too", argv[i]);
        }
        if (err) {
            return err;
        }
    }
    if (in_path == NULL) {
        return usage_error("map needs an input stream (or '-')");
    }
    if (draw.points != NULL && draw.out_path == NULL) {
        return usage_error("--points goes with -o MAP.svg");
    }
    if (draw.prior != NULL && draw.out_path == NULL) {
        return usage_error("--prior goes with -o MAP.svg");
    }
    if (json && draw.out_path != NULL && strcmp(draw.out_path, "-") == 0) {
        return usage_error("--json and -o - would both write to stdout");
    }
    memset(&ctx, 0, sizeof ctx);
    if (map_view_init(&ctx.view, 0) != 0) {
        return EXIT_FAIL;
    }
    in = open_in(in_path);
    if (in == NULL) {
        map_view_free(&ctx.view);
        return EXIT_FAIL;
    }
    if (decode_stream(in, in_path, on_map_frame, &ctx, &sum) != 0) {
        rc = -1;
    }
    close_in(in);
    if (rc == 0 && sum.n_map_frames == 0u) {
        fail_msg("%s: no map frame in the stream%s", in_path,
                 ctx.features_frames ? " (a per-scan stream: bsf render draws it; "
                                       "bsf extract --map writes a map stream)"
                                     : "");
        rc = -1;
    }
    if (rc == 0 && ctx.failed) {
        rc = -1;
    }
    if (rc != 0) {
        map_view_free(&ctx.view);
        return EXIT_FAIL;
    }
    note_trailing_loss(ctx.view.rx, &sum);
    t = totals_of(&ctx.view, ctrl, vtx);
    if (json) {
        print_json(&ctx.view, ctrl, vtx);
    }
    if (draw.out_path != NULL && write_svg(draw.out_path, in_path, &ctx.view, draw.width,
                                           draw.points, draw.prior, ctrl, vtx, &t) != 0) {
        rc = -1;
    }
    info = (json || (draw.out_path != NULL && strcmp(draw.out_path, "-") == 0)) ? stderr : stdout;
    if (draw.out_path != NULL && rc == 0) {
        fprintf(stderr, "%s: wrote %s\n", g_cmd, draw.out_path);
    }
    fprintf(info,
            "%s: %lu features, %lu control points, %lu vertices, %.1f m of curve, %lu stale, "
            "%lu missing; "
            "%lu map frames, %llu bytes (%lu pose-only frames, %llu bytes), %lu missing by "
            "sequence, %lu records skipped, %lu frames dropped\n",
            in_path, t.features, t.ctrl, t.vertices, t.length, t.stale, t.missing, ctx.view.frames,
            ctx.view.bytes, ctx.view.pose_only_frames, ctx.view.pose_only_bytes, sum.map_seq_gaps,
            (unsigned long)ctx.view.rx->stats.records_skipped, frames_dropped(&sum.stats));
    map_view_free(&ctx.view);
    if (close_out(stdout, "stdout") != 0) {
        rc = -1;
    }
    return rc == 0 ? 0 : EXIT_FAIL;
}
