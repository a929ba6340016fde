/* SPDX-License-Identifier: MIT */
/*
 * cmd_extract.c - bsf extract: a CARMEN log into a bsf stream.
 */
#include "tool.h"

static const char extract_help[] =
    "Usage: bsf extract LOG [options]\n"
    "Extract B-spline features from every laser scan of a CARMEN log (plain or .gz)\n"
    "and write them as a bsf stream (docs/FORMAT.md).\n"
    "\n"
    "  --method M       lc-sved-pdm (default), falko-sved-pdm (the paper's, FALKOLib keypoints),\n"
    "                   bid-sved-pdm or rpos-lsba\n"
    "  --first K        skip the first K scans (default 0)\n"
    "  --count N        process at most N scans (default: all)\n"
    "  --range-max M    readings >= M metres are invalid (default: the log's declared\n"
    "                   maximum range, capped below the 81.83/81.91 no-return codes)\n"
    "  --quant STEP     control point quantisation step in metres (default 0.005)\n"
    "  -o OUT           output stream file, '-' for stdout (default '-')\n"
    "  -h, --help       this help\n"
    "\n"
    "Frames carry the laser pose and the time in ms since the log's first scan.\n"
    "A malformed log line is reported as FILE:LINE and skipped. A scan with more\n"
    "keypoints, segments or control points than the library's caps is kept with the\n"
    "features that fit and reported as cut (not failed). The summary goes to\n"
    "stderr; progress too, when stderr is a terminal.\n";

/* Scans a cap cut (BSF_OK_CUT): kept and written, counted apart from failures. */
typedef struct {
    unsigned long scans, keypoints, segments, points;
} cut_totals_t;

#define CUT_MESSAGES_MAX 10 /* per-scan lines; the totals cover the rest */

static void note_cut_scan(cut_totals_t *t, const char *log, unsigned long line, unsigned long index,
                          const bsf_stats_t *s)
{
    if (t->scans < CUT_MESSAGES_MAX) {
        fprintf(stderr,
                "%s:%lu: scan %lu cut by a cap: %lu keypoints, %lu segments (%lu points) "
                "left out%s\n",
                log, line, index, (unsigned long)s->n_cut_keypoints,
                (unsigned long)s->n_cut_segments, (unsigned long)s->n_cut_points,
                t->scans + 1u == CUT_MESSAGES_MAX ? " (further cut scans: totals only)" : "");
    }
    t->scans++;
    t->keypoints += s->n_cut_keypoints;
    t->segments += s->n_cut_segments;
    t->points += s->n_cut_points;
}

typedef struct {
    const char *log;
    bsf_method_t method;
    long first;
    long count;
    double range_max; /* <= 0: from the log */
    double quant;
    const char *out;
} extract_opts_t;

static int run_extract(const extract_opts_t *o)
{
    carmen_reader_t *rd;
    carmen_scan_t rec;
    FILE *out;
    progress_t prog;
    unsigned long index = 0, done = 0, failed = 0, malformed;
    cut_totals_t cut;
    double t0 = 0.0;
    int have_t0 = 0;
    unsigned long long bytes = 0;
    bsf_frame_info_t info;
    int r;

    if (init_extractor(o->method) != 0) {
        return EXIT_FAIL;
    }
    rd = open_log(o->log);
    if (rd == NULL) {
        return EXIT_FAIL;
    }
    out = open_out(o->out, 1);
    if (out == NULL) {
        carmen_close(rd);
        return EXIT_FAIL;
    }
    memset(&cut, 0, sizeof cut);
    bsf_frame_info_init(&info);
    info.quant_step = (float)o->quant;
    progress_init(&prog);
    while ((r = carmen_next(rd, &rec)) > 0) {
        bsf_scan_t sc;
        bsf_status_t st;
        size_t len = 0;
        if ((long)index < o->first) {
            ++index;
            continue;
        }
        if (o->count >= 0 && (long)done >= o->count) {
            break;
        }
        sc = scan_of_record(&rec, o->range_max);
        st = bsf_extract(&g_ex, &sc, &g_res);
        if (st == BSF_OK_CUT) {
            note_cut_scan(&cut, o->log, rec.line, index, &g_res.stats);
        } else if (st != BSF_OK) {
            fprintf(stderr, "%s:%lu: scan %lu skipped: %s\n", o->log, rec.line, index,
                    bsf_status_str(st));
            ++failed;
            ++index;
            continue;
        }
        info.seq = (uint32_t)index;
        /* ms since the log's first scan: small numbers travel in fewer
         * bytes, and the metrics never need absolute time. */
        if (!have_t0) {
            t0 = rec.timestamp;
            have_t0 = 1;
        }
        info.timestamp_ms =
            (rec.timestamp > t0) ? (uint64_t)llround((rec.timestamp - t0) * 1000.0) : 0u;
        info.has_pose = 1u;
        info.pose_x = (float)rec.laser_pose.x;
        info.pose_y = (float)rec.laser_pose.y;
        info.pose_theta = (float)remainder(rec.laser_pose.theta, 2.0 * M_PI);
        st = bsf_frame_encode(&info, &g_res, g_frame_buf, sizeof g_frame_buf, &len);
        if (st != BSF_OK) {
            fprintf(stderr, "%s:%lu: scan %lu not encoded: %s\n", o->log, rec.line, index,
                    bsf_status_str(st));
            ++failed;
            ++index;
            continue;
        }
        if (fwrite(g_frame_buf, 1, len, out) != len) {
            fail_msg("write error on %s", o->out);
            break;
        }
        bytes += len;
        ++done;
        ++index;
        progress_tick(&prog, done, "extract");
    }
    progress_end(&prog);
    malformed = carmen_malformed_count(rd);
    carmen_close(rd);
    if (close_out(out, o->out) != 0 || r < 0) {
        return EXIT_FAIL;
    }
    fprintf(stderr,
            "%s: %lu scans extracted with %s, %llu bytes (%.1f per scan), %lu cut by a cap, "
            "%lu failed, %lu malformed lines\n",
            o->log, done, bsf_method_name(o->method), bytes,
            done ? (double)bytes / (double)done : 0.0, cut.scans, failed, malformed);
    if (cut.scans > 0u) {
        fprintf(stderr,
                "%s: the caps left out %lu keypoints, %lu segments and %lu points in %lu scans "
                "(kept: what fits, largest first; see the README's memory section)\n",
                o->log, cut.keypoints, cut.segments, cut.points, cut.scans);
    }
    return failed ? EXIT_FAIL : 0;
}

int cmd_extract(int argc, char **argv)
{
    extract_opts_t o;
    int i;
    int err = 0;
    memset(&o, 0, sizeof o);
    o.method = BSF_METHOD_DEFAULT;
    o.count = -1;
    o.quant = (double)BSF_QUANT_STEP_DEFAULT;
    o.out = "-";
    for (i = 1; i < argc; ++i) {
        const char *v;
        if (is_help(argv[i])) {
            fputs(extract_help, stdout);
            return 0;
        } else if ((v = opt_value(argc, argv, &i, "--method", &err)) != NULL) {
            o.method = bsf_method_from_name(v);
            if (o.method == BSF_METHOD_COUNT) {
                return usage_error(
                    "unknown method '%s' (lc-sved-pdm, falko-sved-pdm, bid-sved-pdm, rpos-lsba)",
                    v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--first", &err)) != NULL) {
            if (parse_long(v, 0, 1000000000L, &o.first) != 0) {
                return usage_error("--first needs a count >= 0, got '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--count", &err)) != NULL) {
            if (parse_long(v, 0, 1000000000L, &o.count) != 0) {
                return usage_error("--count needs a count >= 0, got '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--range-max", &err)) != NULL) {
            if (parse_float(v, 1e-3, 1e4, &o.range_max) != 0) {
                return usage_error("--range-max needs metres > 0, got '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--quant", &err)) != NULL) {
            if (parse_float(v, (double)BSF_QUANT_STEP_MIN, (double)BSF_QUANT_STEP_MAX, &o.quant) !=
                0) {
                return usage_error("--quant needs metres in [%g, %g], got '%s'",
                                   (double)BSF_QUANT_STEP_MIN, (double)BSF_QUANT_STEP_MAX, v);
            }
        } else if ((v = opt_value(argc, argv, &i, "-o", &err)) != NULL) {
            o.out = v;
        } else if (err) {
            return err;
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            return usage_error("unknown option '%s'", argv[i]);
        } else if (o.log == NULL) {
            o.log = argv[i];
        } else {
            return usage_error("extract takes one LOG, got '%s' too", argv[i]);
        }
        if (err) {
            return err;
        }
    }
    if (o.log == NULL) {
        return usage_error("extract needs a LOG file");
    }
    return run_extract(&o);
}
