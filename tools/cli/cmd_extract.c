/* SPDX-License-Identifier: MIT */
/*
 * cmd_extract.c - bsf extract: a CARMEN log into a bsf stream.
 */
#include "align_odometry.h"
#include "tool.h"

static const char extract_help[] =
    "Usage: bsf extract LOG [options]\n"
    "Extract B-spline features from every laser scan of a CARMEN log (plain or .gz;\n"
    "'-' reads standard input) and write them as a bsf stream (docs/FORMAT.md).\n"
    "\n"
    "  --method M       lc-sved-pdm (default), falko-sved-pdm (the paper's, FALKOLib keypoints),\n"
    "                   bid-sved-pdm or rpos-lsba\n"
    "  --first K        skip the first K scans (default 0)\n"
    "  --count N        process at most N scans (default: all)\n"
    "  --range-max M    readings >= M metres are invalid (default: the log's declared\n"
    "                   maximum range, capped below the 81.83/81.91 no-return codes)\n"
    "  --no-return V    the sensor's no-return code: a reading of exactly V metres is\n"
    "                   never a point; 'off' stops recognising undeclared codes (by\n"
    "                   default, a run of 5 or more identical readings at the scan's\n"
    "                   maximum, 10 % above its neighbours, is one, and so is a value\n"
    "                   that keeps recurring as the scan's isolated maximum (20 scans\n"
    "                   of evidence, halved every 64): dropped from then on); may be\n"
    "                   repeated\n"
    "  --fit-passes K   bound the fit's work per scan: at most K footpoint passes per\n"
    "                   fitted point on average (default 0: no bound; docs/PERFORMANCE.md)\n"
    "  --fit-bin-length M  fit the means of bins of consecutive returns at most M metres\n"
    "                   long on dense scans (0..1; default 0: every return)\n"
    "  --quant STEP     control point quantisation step in metres (default 0.005)\n"
    "  --meta-every K   repeat the metadata frame at least every K scans (default 64)\n"
    "  --reproducible   no measured extraction time: the same log gives the same bytes\n"
    "  --map            fuse every scan into the robot's map (bsf_map.h) with its pose from\n"
    "                   the log and write map-update frames instead of per-scan features:\n"
    "                   only what changed (new features, appended spans, moved control\n"
    "                   points, merges, removals); bsf map rebuilds the map\n"
    "  --pose-every K   with --map: a pose record every K scans (default 1; 0: none);\n"
    "                   pose bytes are counted apart from the map's\n"
    "  --snapshot-budget B  with --map: up to B bytes per map frame of snapshots of the\n"
    "                   features the robot holds, round robin (default 0: none), so that\n"
    "                   a receiver that joined late or lost frames catches up\n"
    "  --align          with --map: align each scan to the map before fusing it\n"
    "                   (bsf_align.h), its prior the previous aligned pose moved by the\n"
    "                   odometry; the map and the pose records get the aligned poses\n"
    "  --odometry SRC   with --align: 'log' (default) the motion between the log's\n"
    "                   odometry poses (ROBOTLASER1 robot pose, FLASER odom pose);\n"
    "                   'edges' the '#SEQUENTIAL' EDGE2 edges of the log's pose graph\n"
    "  --prior-path CSV with --align: per fused scan, its laser poses as CSV\n"
    "                   (docs/TOOL.md): the odometry alone, the prior, the aligned pose;\n"
    "                   bsf map/render --prior draw the odometry path dashed\n"
    "  -o OUT           output stream file, '-' for stdout (default '-')\n"
    "  -h, --help       this help\n";
/* Split from the options: C99 compilers need only take 4095-character strings. */
static const char extract_help_notes[] =
    "\n"
    "The stream starts with a metadata frame (method, parameters, caps, scan geometry,\n"
    "the log's absolute time of timestamp 0, the log's name), sent again whenever the\n"
    "range limits or the time origin change and at least every K scans, so that a\n"
    "receiver joining a live link learns it within K frames; a scan whose beam count\n"
    "or angles differ from the metadata carries its own in its frame. Frames carry\n"
    "the laser pose and the time in ms since that origin (the log's first scan).\n"
    "A malformed log line is reported as FILE:LINE and skipped; so is a scan whose\n"
    "time is not finite, negative or beyond 1e11 s. A scan with more keypoints,\n"
    "segments or control points than the library's caps is kept with the features\n"
    "that fit and reported as cut (not failed). The summary goes to stderr; progress\n"
    "too, when stderr is a terminal. A line longer than 1 MiB (no CARMEN message is)\n"
    "is reported and skipped without reading it into memory. Exits 1 when the log\n"
    "holds no laser line, any scan was skipped or any line was longer than 1 MiB.\n";

/* Largest log time accepted, seconds since 1970 (year 5138): a larger one is
 * a corrupt field, and its microseconds would not fit the metadata frame. */
#define EXTRACT_TIME_MAX_S 1e11

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
    double range_max;      /* <= 0: from the log */
    double no_return;      /* > 0: the sensor's no-return code */
    int no_return_off;     /* 1: no recognition of undeclared codes */
    long fit_passes;       /* bsf_params_t.fit_passes (0: no bound) */
    double fit_bin_length; /* bsf_params_t.fit_bin_length; < 0: the method's default */
    double quant;
    long meta_every;
    int reproducible;
    int map;                /* write map-update frames */
    long pose_every;        /* with map: a pose record every K scans, 0 none */
    long snapshot_budget;   /* with map: snapshot bytes per frame */
    int align;              /* with map: align each scan before fusing it */
    int odo_edges;          /* with align: odometry from the sequential edges */
    const char *prior_path; /* with align: CSV of prior and aligned poses */
    const char *out;
} extract_opts_t;

/* The robot's map (--map): fixed size, as on the robot. */
static bsf_map_t g_map;
/* Alignment (--align): its work area, the odometry and the counts. */
static bsf_align_work_t g_align_work;
typedef struct {
    odo_edges_t edges;
    int odo_edges;            /* odometry from the edges, not the log's poses */
    int have_prev;            /* a scan was placed */
    unsigned long prev_index; /* its index in the log */
    odo_pose_t prev_odo;      /* its odometry pose (log source) */
    bsf_pose_t prev_pose;     /* its aligned laser pose */
    odo_pose_t dead;          /* the odometry alone, chained from the first pose */
    unsigned long n_aligned, n_free;
    unsigned long declined[BSF_ALIGN_DECLINE_COUNT];
} align_state_t;
static align_state_t g_as;

/* The laser pose scan `index` is fused at: the log's for the first scan,
 * then the previous aligned pose moved by the odometry and aligned to the
 * map. *prior_out gets the pose alignment started from, *dead_out the
 * odometry alone chained from the first scan's pose (both the log's for the
 * first scan). 0, or -1 with a message when the odometry lacks the motion. */
static int aligned_pose(const char *log, unsigned long line, unsigned long index,
                        const carmen_scan_t *rec, bsf_pose_t *pose, odo_pose_t *prior_out,
                        odo_pose_t *dead_out)
{
    const odo_pose_t odo = {rec->robot_pose.x, rec->robot_pose.y, rec->robot_pose.theta};
    if (g_as.have_prev) {
        odo_pose_t m = {0.0, 0.0, 0.0};
        odo_pose_t prior;
        const odo_pose_t prev = {(double)g_as.prev_pose.x, (double)g_as.prev_pose.y,
                                 (double)g_as.prev_pose.theta};
        bsf_pose_t p;
        bsf_align_result_t ar;
        bsf_status_t st;
        if (g_as.odo_edges) {
            unsigned long k;
            for (k = g_as.prev_index + 1u; k <= index; ++k) {
                if (k >= g_as.edges.n || !g_as.edges.have[k]) {
                    fprintf(stderr, "%s:%lu: scan %lu: no sequential edge from scan %lu\n", log,
                            line, index, k - 1u);
                    return -1;
                }
                m = odo_compose(m, g_as.edges.motion[k]);
            }
        } else {
            m = odo_between(g_as.prev_odo, odo);
        }
        prior = odo_compose(prev, m);
        prior.t = remainder(prior.t, 2.0 * M_PI);
        *prior_out = prior;
        *dead_out = odo_compose(g_as.dead, m);
        dead_out->t = remainder(dead_out->t, 2.0 * M_PI);
        p.x = (float)prior.x;
        p.y = (float)prior.y;
        p.theta = (float)prior.t;
        st = bsf_align_points(&g_align_work, NULL, &g_map, &g_ex.points, &g_res, &p, &ar);
        if (st != BSF_OK) {
            fprintf(stderr, "%s:%lu: scan %lu not aligned: %s\n", log, line, index,
                    bsf_status_str(st));
            return -1;
        }
        ++g_as.n_aligned;
        ++g_as.declined[ar.declined];
        g_as.n_free += ar.n_free > 0u;
        *pose = ar.pose;
        pose->theta = (float)remainder((double)pose->theta, 2.0 * M_PI);
    } else {
        pose->x = (float)rec->laser_pose.x;
        pose->y = (float)rec->laser_pose.y;
        pose->theta = (float)remainder(rec->laser_pose.theta, 2.0 * M_PI);
        prior_out->x = (double)pose->x;
        prior_out->y = (double)pose->y;
        prior_out->t = (double)pose->theta;
        *dead_out = *prior_out;
    }
    g_as.dead = *dead_out;
    g_as.have_prev = 1;
    g_as.prev_index = index;
    g_as.prev_odo = odo;
    g_as.prev_pose = *pose;
    return 0;
}

/* Every map change waiting, as frames of at most BSF_MAP_FRAME_MAX_SIZE
 * bytes; pose (may be NULL) rides in the first. 0, or -1 on an error. */
static int write_map_frames(FILE *out, const char *out_name, const bsf_pose_t *pose,
                            unsigned long long *bytes)
{
    const size_t cap =
        sizeof g_frame_buf < BSF_MAP_FRAME_MAX_SIZE ? sizeof g_frame_buf : BSF_MAP_FRAME_MAX_SIZE;
    int first = 1;
    while (first || bsf_map_pending(&g_map)) {
        size_t len = 0;
        const bsf_status_t st = bsf_map_encode(&g_map, first ? pose : NULL, g_frame_buf, cap, &len);
        if (st != BSF_OK) {
            fail_msg("cannot encode a map frame: %s", bsf_status_str(st));
            return -1;
        }
        if (len == 0u) {
            break;
        }
        if (fwrite(g_frame_buf, 1, len, out) != len) {
            fail_msg("write error on %s", out_name);
            return -1;
        }
        *bytes += len;
        first = 0;
    }
    return 0;
}

/* The stream's current metadata and when it was last sent. */
typedef struct {
    bsf_metadata_t meta;
    int sent;
    long frames_since;
    unsigned long n_sent;
} meta_state_t;

/* The beams of sc are where the metadata says (count and angles, bit for bit). */
static int same_beams(const bsf_metadata_t *m, const bsf_scan_t *sc)
{
    return m->n_beams == (uint32_t)sc->count &&
           memcmp(&m->angle_min, &sc->angle_min, sizeof(float)) == 0 &&
           memcmp(&m->angle_increment, &sc->angle_increment, sizeof(float)) == 0;
}

static int same_ranges(const bsf_metadata_t *m, const bsf_scan_t *sc)
{
    return memcmp(&m->range_min, &sc->range_min, sizeof(float)) == 0 &&
           memcmp(&m->range_max, &sc->range_max, sizeof(float)) == 0;
}

/* The log's file name as the source (at most BSF_METADATA_SOURCE_MAX bytes). */
static void set_source(bsf_metadata_t *m, const char *log)
{
    const char *base = strrchr(log, '/');
    size_t n;
    base = base != NULL ? base + 1 : log;
    if (strcmp(log, "-") == 0) {
        m->source_len = 0u;
        return;
    }
    n = strlen(base);
    if (n > BSF_METADATA_SOURCE_MAX) {
        n = BSF_METADATA_SOURCE_MAX;
        while (n > 0u && ((unsigned char)base[n] & 0xC0u) == 0x80u) {
            --n; /* do not cut a UTF-8 sequence */
        }
    }
    memcpy(m->source, base, n);
    m->source[n] = '\0';
    m->source_len = (uint8_t)n;
}

static int write_metadata(meta_state_t *ms, FILE *out, const char *out_name,
                          unsigned long long *bytes)
{
    size_t len = 0;
    bsf_status_t st = bsf_metadata_encode(&ms->meta, g_frame_buf, sizeof g_frame_buf, &len);
    if (st == BSF_ERR_ARG && ms->meta.source_len > 0u) {
        ms->meta.source_len = 0u; /* a file name that is not clean UTF-8 is left out */
        ms->meta.source[0] = '\0';
        st = bsf_metadata_encode(&ms->meta, g_frame_buf, sizeof g_frame_buf, &len);
    }
    if (st != BSF_OK) {
        fail_msg("cannot encode the metadata frame: %s", bsf_status_str(st));
        return -1;
    }
    if (fwrite(g_frame_buf, 1, len, out) != len) {
        fail_msg("write error on %s", out_name);
        return -1;
    }
    *bytes += len;
    ms->sent = 1;
    ms->frames_since = 0;
    ++ms->n_sent;
    return 0;
}

/* Header of the --prior-path CSV (bsf map --prior and bsf render --prior read it). */
static const char prior_csv_header[] =
    "scan,time_s,odometry_x,odometry_y,odometry_theta,prior_x,prior_y,prior_theta,aligned_x,"
    "aligned_y,aligned_theta\n";

static int run_extract(const extract_opts_t *o)
{
    static meta_state_t ms;
    /* An undeclared code that is not in runs is learnt across scans. */
    static bsf_no_return_learner_t learner;
    const int learn = !(o->no_return > 0.0) && !o->no_return_off;
    carmen_reader_t *rd;
    carmen_scan_t rec;
    FILE *out;
    progress_t prog;
    unsigned long index = 0, done = 0, failed = 0, bad_time = 0, malformed, overlong;
    unsigned long own_geometry = 0;
    cut_totals_t cut;
    unsigned long long bytes = 0;
    bsf_frame_info_t info;
    int r;
    int write_failed = 0;
    FILE *prior_csv = NULL;

    {
        bsf_params_t p = bsf_params_default(o->method);
        p.no_return.code = (float)o->no_return;
        if (o->no_return_off) {
            p.no_return.min_run = 0u;
        }
        p.fit_passes = (uint8_t)o->fit_passes;
        if (o->fit_bin_length >= 0.0) {
            p.fit_bin_length = (float)o->fit_bin_length;
        }
        if (init_extractor_params(&p, !o->reproducible) != 0) {
            return EXIT_FAIL;
        }
    }
    if (o->map) {
        bsf_map_params_t mp;
        bsf_status_t st;
        bsf_map_params_default(&mp);
        mp.quant_step = (float)o->quant;
        mp.snapshot_budget = (uint16_t)o->snapshot_budget;
        st = bsf_map_init(&g_map, &mp);
        if (st != BSF_OK) {
            fail_msg("cannot initialise the map: %s", bsf_status_str(st));
            return EXIT_FAIL;
        }
    }
    memset(&g_as, 0, sizeof g_as);
    g_as.odo_edges = o->odo_edges;
    if (o->align && o->odo_edges && odo_edges_load(o->log, &g_as.edges) != 0) {
        return EXIT_FAIL;
    }
    rd = open_log(o->log);
    if (rd == NULL) {
        odo_edges_free(&g_as.edges);
        return EXIT_FAIL;
    }
    /* the side file first: when it cannot be written, the stream is not touched */
    if (o->prior_path != NULL) {
        prior_csv = open_out(o->prior_path, 0);
        if (prior_csv == NULL || fputs(prior_csv_header, prior_csv) == EOF) {
            if (prior_csv != NULL) {
                fail_msg("write error on %s", o->prior_path);
                (void)close_out(prior_csv, o->prior_path);
            }
            carmen_close(rd);
            odo_edges_free(&g_as.edges);
            return EXIT_FAIL;
        }
    }
    out = open_out(o->out, 1);
    if (out == NULL) {
        carmen_close(rd);
        if (prior_csv != NULL) {
            (void)close_out(prior_csv, o->prior_path);
            (void)remove(o->prior_path); /* created just now, holds only its header */
        }
        odo_edges_free(&g_as.edges);
        return EXIT_FAIL;
    }
    memset(&ms, 0, sizeof ms);
    memset(&cut, 0, sizeof cut);
    bsf_no_return_learner_init(&learner);
    bsf_frame_info_init(&info);
    info.quant_step = (float)o->quant;
    progress_init(&prog);
    while ((r = carmen_next(rd, &rec)) > 0) {
        bsf_scan_t sc;
        bsf_status_t st;
        size_t len = 0;
        long long t_us;
        if ((long)index < o->first) {
            ++index;
            continue;
        }
        if (o->count >= 0 && (long)done >= o->count) {
            break;
        }
        if (!(isfinite(rec.timestamp) && rec.timestamp >= 0.0 &&
              rec.timestamp <= EXTRACT_TIME_MAX_S)) {
            fprintf(stderr,
                    "%s:%lu: scan %lu skipped: its time %g s is not a time bsf can carry "
                    "(finite, 0 .. %g s)\n",
                    o->log, rec.line, index, rec.timestamp, EXTRACT_TIME_MAX_S);
            ++bad_time;
            ++index;
            continue;
        }
        t_us = llround(rec.timestamp * 1e6);
        sc = scan_of_record(&rec, o->range_max);
        if (learn) {
            float code = 0.0f;
            if (bsf_no_return_learn(&learner, &sc, &code) == BSF_OK && code > 0.0f &&
                g_ex.params.no_return.code != code) {
                bsf_params_t p = g_ex.params;
                p.no_return.code = code;
                if (init_extractor_params(&p, !o->reproducible) != 0) {
                    carmen_close(rd);
                    (void)close_out(out, o->out);
                    return EXIT_FAIL;
                }
                fprintf(
                    stderr,
                    "%s:%lu: %g m is a no-return code (the scan's isolated maximum in %u or more "
                    "scans): readings of exactly %g m are no points from scan %lu on\n",
                    o->log, rec.line, (double)code, (unsigned)BSF_NO_RETURN_LEARN_SCANS,
                    (double)code, index);
            }
        }
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
        /* Metadata first: at the start, when the range limits change, when
         * the time goes back before the origin (a new origin), and every K
         * scans. A scan whose beams (count, angles) differ from the metadata
         * carries its own geometry instead: some logs change the start angle
         * on every scan, and 10 bytes in the frame cost less than a 60-byte
         * metadata frame per scan. */
        if (!ms.sent || !same_ranges(&ms.meta, &sc) || t_us < ms.meta.time_origin_us ||
            ms.frames_since >= o->meta_every) {
            if (ms.sent && t_us < ms.meta.time_origin_us) {
                fprintf(stderr,
                        "%s:%lu: scan %lu: time goes back %.6f s before the stream's time "
                        "origin; a metadata frame sets a new origin\n",
                        o->log, rec.line, index, 1e-6 * (double)(ms.meta.time_origin_us - t_us));
            }
            if (!ms.sent || t_us < ms.meta.time_origin_us) {
                fill_metadata(&ms.meta, &sc, info.quant_step);
                set_source(&ms.meta, o->log);
                ms.meta.has_time_origin = 1u;
                ms.meta.time_origin_us = t_us;
            } else {
                const int64_t origin = ms.meta.time_origin_us;
                char source[BSF_METADATA_SOURCE_MAX + 1u];
                const uint8_t source_len = ms.meta.source_len;
                memcpy(source, ms.meta.source, sizeof source);
                fill_metadata(&ms.meta, &sc, info.quant_step);
                memcpy(ms.meta.source, source, sizeof source);
                ms.meta.source_len = source_len;
                ms.meta.has_time_origin = 1u;
                ms.meta.time_origin_us = origin;
            }
            if (write_metadata(&ms, out, o->out, &bytes) != 0) {
                write_failed = 1;
                break;
            }
        }
        if (g_res.stats.n_beams == 0u) {
            g_res.stats.n_beams = (uint32_t)sc.count;
        }
        info.has_geometry = (uint8_t)(same_beams(&ms.meta, &sc) ? 0u : 1u);
        info.angle_min = sc.angle_min;
        info.angle_increment = sc.angle_increment;
        info.seq = (uint32_t)index;
        /* ms since the origin (the first scan): small numbers travel in
         * fewer bytes; the metadata frame carries the absolute origin. */
        info.timestamp_ms = (uint64_t)((t_us - ms.meta.time_origin_us + 500) / 1000);
        info.has_pose = 1u;
        info.pose.x = (float)rec.laser_pose.x;
        info.pose.y = (float)rec.laser_pose.y;
        info.pose.theta = (float)remainder(rec.laser_pose.theta, 2.0 * M_PI);
        if (o->map) {
            bsf_pose_t pose;
            odo_pose_t prior = {0.0, 0.0, 0.0}, dead = {0.0, 0.0, 0.0};
            int fused;
            pose.x = info.pose.x;
            pose.y = info.pose.y;
            pose.theta = info.pose.theta;
            if (o->align &&
                aligned_pose(o->log, rec.line, index, &rec, &pose, &prior, &dead) != 0) {
                ++failed;
                ++index;
                continue;
            }
            fused = bsf_map_fuse(&g_map, &g_res, &pose);
            if (fused < 0) {
                fprintf(stderr, "%s:%lu: scan %lu not fused into the map: %s\n", o->log, rec.line,
                        index, bsf_status_str((bsf_status_t)fused));
                ++failed;
                ++index;
                continue;
            }
            if (prior_csv != NULL &&
                fprintf(prior_csv, "%lu,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", index,
                        rec.timestamp, dead.x, dead.y, dead.t, prior.x, prior.y, prior.t,
                        (double)pose.x, (double)pose.y, (double)pose.theta) < 0) {
                fail_msg("write error on %s", o->prior_path);
                write_failed = 1;
                break;
            }
            if (write_map_frames(
                    out, o->out,
                    o->pose_every > 0 && done % (unsigned long)o->pose_every == 0u ? &pose : NULL,
                    &bytes) != 0) {
                write_failed = 1;
                break;
            }
            ++ms.frames_since;
            ++done;
            ++index;
            progress_tick(&prog, done, "extract");
            continue;
        }
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
            write_failed = 1;
            break;
        }
        own_geometry += info.has_geometry;
        ++ms.frames_since;
        bytes += len;
        ++done;
        ++index;
        progress_tick(&prog, done, "extract");
    }
    progress_end(&prog);
    if (o->map && !write_failed) {
        /* the end of the log: what waits for the frame interval goes out now */
        g_map.params.frame_interval = 1u;
        if (write_map_frames(out, o->out, NULL, &bytes) != 0) {
            write_failed = 1;
        }
    }
    malformed = carmen_malformed_count(rd);
    overlong = carmen_overlong_count(rd);
    carmen_close(rd);
    if (prior_csv != NULL && close_out(prior_csv, o->prior_path) != 0) {
        write_failed = 1;
    }
    if (close_out(out, o->out) != 0 || r < 0 || write_failed) {
        odo_edges_free(&g_as.edges);
        return EXIT_FAIL;
    }
    if (index == 0u) {
        fail_msg("%s: no laser line (FLASER or ROBOTLASER1) in the log%s", o->log,
                 malformed ? " that could be read" : "");
        return EXIT_FAIL;
    }
    fprintf(stderr,
            "%s: %lu scans extracted with %s, %llu bytes (%.1f per scan, %lu metadata "
            "frames, %lu scans with their own geometry), %lu cut by a cap, %lu failed, %lu "
            "with a bad time, %lu malformed lines\n",
            o->log, done, bsf_method_name(o->method), bytes,
            done ? (double)bytes / (double)done : 0.0, ms.n_sent, own_geometry, cut.scans, failed,
            bad_time, malformed);
    if (o->map) {
        const bsf_map_stats_t *m = &g_map.stats;
        fprintf(stderr,
                "%s: map: %lu frames, %lu bytes of map records and headers, %lu of pose records; "
                "%lu features in RAM (%lu created, %lu extended, %lu merged, %lu vertex merges), "
                "%lu forgotten (%lu control points; the receiver keeps them), %lu scan features "
                "left out (caps full), %lu bytes of RAM\n",
                o->log, (unsigned long)m->n_frames, (unsigned long)m->map_bytes,
                (unsigned long)m->pose_bytes, (unsigned long)bsf_map_feature_count(&g_map),
                (unsigned long)m->n_new, (unsigned long)m->n_extended, (unsigned long)m->n_merged,
                (unsigned long)m->n_vertex_merged, (unsigned long)m->n_forgotten,
                (unsigned long)m->n_forgotten_ctrl, (unsigned long)m->n_dropped_obs,
                (unsigned long)sizeof g_map);
    }
    if (o->align) {
        int d;
        fprintf(stderr,
                "%s: align: %lu scans aligned (odometry: %s), %lu with a direction left "
                "free; declined:",
                o->log, g_as.n_aligned, o->odo_edges ? "sequential edges" : "the log's poses",
                g_as.n_free);
        for (d = 1; d < BSF_ALIGN_DECLINE_COUNT; ++d) {
            fprintf(stderr, " %lu %s%s", g_as.declined[d], bsf_align_decline_str(d),
                    d + 1 < BSF_ALIGN_DECLINE_COUNT ? "," : "\n");
        }
    }
    odo_edges_free(&g_as.edges);
    if (cut.scans > 0u) {
        fprintf(stderr,
                "%s: the caps left out %lu keypoints, %lu segments and %lu points in %lu scans "
                "(kept: what fits, largest first; see the README's memory section)\n",
                o->log, cut.keypoints, cut.segments, cut.points, cut.scans);
    }
    if (overlong > 0u) {
        fail_msg("%s: %lu lines longer than %lu bytes (reported above): not a CARMEN log "
                 "as written",
                 o->log, overlong, (unsigned long)CARMEN_MAX_LINE);
    }
    return failed || bad_time || overlong ? EXIT_FAIL : 0;
}

int cmd_extract(int argc, char **argv)
{
    extract_opts_t o;
    int i;
    int err = 0;
    int pose_every_set = 0;
    int odometry_set = 0;
    memset(&o, 0, sizeof o);
    o.method = BSF_METHOD_DEFAULT;
    o.count = -1;
    o.fit_bin_length = -1.0;
    o.quant = (double)BSF_QUANT_STEP_DEFAULT;
    o.meta_every = 64;
    o.pose_every = 1;
    o.out = "-";
    for (i = 1; i < argc; ++i) {
        const char *v;
        if (is_help(argv[i])) {
            fputs(extract_help, stdout);
            fputs(extract_help_notes, stdout);
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
        } else if ((v = opt_value(argc, argv, &i, "--no-return", &err)) != NULL) {
            if (strcmp(v, "off") == 0) {
                o.no_return_off = 1;
            } else if (parse_float(v, 1e-3, 1e4, &o.no_return) != 0) {
                return usage_error("--no-return needs metres > 0 or 'off', got '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--fit-passes", &err)) != NULL) {
            if (parse_long(v, 0, 255, &o.fit_passes) != 0) {
                return usage_error("--fit-passes needs a count in [0, 255], got '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--fit-bin-length", &err)) != NULL) {
            if (parse_float(v, 0.0, 1.0, &o.fit_bin_length) != 0) {
                return usage_error("--fit-bin-length needs metres in [0, 1], got '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--quant", &err)) != NULL) {
            if (parse_float(v, (double)BSF_QUANT_STEP_MIN, (double)BSF_QUANT_STEP_MAX, &o.quant) !=
                0) {
                return usage_error("--quant needs metres in [%g, %g], got '%s'",
                                   (double)BSF_QUANT_STEP_MIN, (double)BSF_QUANT_STEP_MAX, v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--meta-every", &err)) != NULL) {
            if (parse_long(v, 1, 1000000000L, &o.meta_every) != 0) {
                return usage_error("--meta-every needs a count >= 1, got '%s'", v);
            }
        } else if (strcmp(argv[i], "--reproducible") == 0) {
            o.reproducible = 1;
        } else if (strcmp(argv[i], "--map") == 0) {
            o.map = 1;
        } else if (strcmp(argv[i], "--align") == 0) {
            o.align = 1;
        } else if ((v = opt_value(argc, argv, &i, "--odometry", &err)) != NULL) {
            if (strcmp(v, "log") == 0) {
                o.odo_edges = 0;
            } else if (strcmp(v, "edges") == 0) {
                o.odo_edges = 1;
            } else {
                return usage_error("--odometry takes 'log' or 'edges', got '%s'", v);
            }
            odometry_set = 1;
        } else if ((v = opt_value(argc, argv, &i, "--prior-path", &err)) != NULL) {
            o.prior_path = v;
        } else if ((v = opt_value(argc, argv, &i, "--pose-every", &err)) != NULL) {
            if (parse_long(v, 0, 1000000000L, &o.pose_every) != 0) {
                return usage_error("--pose-every needs a count >= 0, got '%s'", v);
            }
            pose_every_set = 1;
        } else if ((v = opt_value(argc, argv, &i, "--snapshot-budget", &err)) != NULL) {
            if (parse_long(v, 0, BSF_MAP_FRAME_MAX_SIZE / 2, &o.snapshot_budget) != 0) {
                return usage_error("--snapshot-budget needs bytes in [0, %u], got '%s'",
                                   (unsigned)(BSF_MAP_FRAME_MAX_SIZE / 2), v);
            }
            pose_every_set = 1;
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
    if (pose_every_set && !o.map) {
        return usage_error("--pose-every and --snapshot-budget go with --map");
    }
    if (o.align && !o.map) {
        return usage_error("--align goes with --map");
    }
    if (odometry_set && !o.align) {
        return usage_error("--odometry goes with --align");
    }
    if (o.prior_path != NULL && !o.align) {
        return usage_error(
            "--prior-path goes with --align (without it the prior is the log's pose)");
    }
    if (o.prior_path != NULL &&
        (strcmp(o.prior_path, "-") == 0 || strcmp(o.prior_path, o.out) == 0)) {
        return usage_error("--prior-path needs a file of its own, not '%s'", o.prior_path);
    }
    return run_extract(&o);
}
