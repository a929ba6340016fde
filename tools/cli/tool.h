/* SPDX-License-Identifier: MIT */
/*
 * tool.h - what the files of the host tool `bsf` share: one command per
 * cmd_*.c file, the shared command-line and stream helpers in cli_util.c,
 * stream_io.c and log_scan.c. Host only: libc, stdio, POSIX.
 */
#ifndef BSF_TOOL_H
#define BSF_TOOL_H

#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bsf/bsf.h"
#include "bsf/bsf_stream.h"
#include "bsf_port_clock.h"
#include "bsf_scene.h"
#include "bsf_svg.h"
#include "carmen.h"
#include "carmen_bsf.h"

#define TOOL_NAME "bsf"
#define EXIT_USAGE 2
#define EXIT_FAIL 1

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#if defined(__GNUC__) || defined(__clang__)
#define BSF_PRINTF_LIKE(f, a) __attribute__((format(printf, f, a)))
#else
#define BSF_PRINTF_LIKE(f, a)
#endif

/* ---- cli_util.c: messages, options, files, progress ---------------------- */

/** "bsf CMD", the prefix of every message. */
extern const char *g_cmd;

/** "bsf CMD: message" on stderr. */
void fail_msg(const char *fmt, ...) BSF_PRINTF_LIKE(1, 2);
/** fail_msg plus a pointer to --help; returns EXIT_USAGE. */
int usage_error(const char *fmt, ...) BSF_PRINTF_LIKE(1, 2);
/** A UTF-8 string (a metadata source, a method name) as a JSON string, safe
 *  on a terminal too: quote and backslash escaped, control characters and
 *  the bidirectional formatting characters (U+061C, U+200E, U+200F,
 *  U+202A..U+202E, U+2066..U+2069) written as \uXXXX. */
void print_json_string(FILE *f, const char *s);
/** Monotonic time, seconds. */
double now_s(void);
/** Whole decimal number in [lo, hi]: 0, or -1 when malformed or out of range. */
int parse_long(const char *s, long lo, long hi, long *out);
/** Finite number in [lo, hi]: 0, or -1 when malformed or out of range. */
int parse_float(const char *s, double lo, double hi, double *out);
/** Option value: "--opt=v" or "--opt v". Returns the value or NULL (and sets *err). */
const char *opt_value(int argc, char **argv, int *i, const char *name, int *err);
/** The drawing options of map and render. */
typedef struct {
    const char *out_path; /**< -o MAP.svg */
    const char *points;   /**< --points LOG: raw points under the map */
    const char *prior;    /**< --prior CSV: the odometry path, dashed */
    double width;         /**< --width PX (the caller's default when absent) */
} draw_opts_t;
/** 1 when argv[*i] is a drawing option (-o, --points, --prior, --width): its
 *  value stored, *i past it, and *err set when the value is missing or out of
 *  range; 0 when it is none of them. */
int draw_option(int argc, char **argv, int *i, draw_opts_t *o, int *err);
/** Is a an -h or --help? */
int is_help(const char *a);
/** A file to read, or stdin for "-"; NULL with a message on failure. */
FILE *open_in(const char *path);
/** A file to write, or stdout for "-" (refused for a binary stream on a terminal). */
FILE *open_out(const char *path, int binary);
/** Flush or close an output, reporting write errors: 0 or -1. */
int close_out(FILE *f, const char *path);

/** Progress on stderr, only when it is a terminal. */
typedef struct {
    int enabled;
    double t0;
    double last;
} progress_t;

void progress_init(progress_t *p);
void progress_tick(progress_t *p, unsigned long done, const char *what);
void progress_end(progress_t *p);

/** Open a CARMEN log (plain or .gz); NULL with a message on failure. */
carmen_reader_t *open_log(const char *path);

/* ---- stream_io.c: decoding a stream, metrics of frames ------------------- */

/** What decoding a whole stream found. */
typedef struct {
    bsf_decoder_stats_t stats;
    unsigned long seq_gaps;            /**< features frames missing according to sequence numbers */
    unsigned long long bytes_in;       /**< bytes read */
    unsigned long n_scans;             /**< features frames delivered */
    unsigned long n_metadata;          /**< metadata frames delivered */
    unsigned long long metadata_bytes; /**< their bytes on the wire */
    int have_seq;                      /**< internal: a sequence number was seen */
    uint32_t last_seq;                 /**< internal: the last one */
    unsigned long n_map_frames;        /**< map-update frames delivered */
    unsigned long long map_frame_bytes; /**< their bytes on the wire */
    unsigned long map_seq_gaps;         /**< map frames missing according to their numbers */
    int have_map_seq;                   /**< internal: a map frame number was seen */
    uint32_t last_map_seq;              /**< internal: the last one */
    unsigned long dropped_at_last_map;  /**< frames_dropped() when the last map frame came */
} stream_summary_t;

/** Called for every decoded frame (features and metadata: check f->type)
 *  with its own size on the wire (delimiter included); non-zero stops. */
typedef int (*frame_cb)(void *ctx, const bsf_frame_t *f, size_t bytes);

/**
 * Feed a byte stream through the decoder, read(2) by read(2) on in's
 * descriptor (a pipe delivers each frame as soon as its delimiter arrives;
 * do not read from in through stdio before). 0, or -1 with a message on a
 * read error, a callback error, or when non-empty input holds no valid frame.
 */
int decode_stream(FILE *in, const char *name, frame_cb on_frame, void *ctx, stream_summary_t *sum);
/** An input that can be read twice: a file as is, a pipe spooled to a
 *  temporary file ("-": stdin). NULL with a message on failure. */
FILE *open_seekable(const char *path);
/** Back to the start of an input from open_seekable: 0, or -1 with a message. */
int rewind_input(FILE *in, const char *name);
/** Close an input unless it is stdin. */
void close_in(FILE *in);
/** Frames dropped by the decoder (CRC, malformed, version, oversize). */
unsigned long frames_dropped(const bsf_decoder_stats_t *s);
/* Tell the map receiver about frames dropped after the last map frame of a
 * decoded stream (any of them may have been a map frame); nothing when none. */
void note_trailing_loss(bsf_map_rx_t *rx, const stream_summary_t *sum);
/** A result's metric counts (zeros when inconsistent). */
bsf_scan_counts_t counts_of_result(const bsf_result_t *r);

/** Nearest-rank percentile p in [0, 1] of v (sorted in place); 0 when n is 0. */
size_t nearest_rank_size(size_t *v, size_t n, double p);

/** The paper's metrics plus frame sizes and cap cuts over a stream. */
typedef struct {
    bsf_metrics_summary_t m;
    size_t bytes_median;
    size_t bytes_p95;
    double bytes_mean;
    unsigned long n_cut_scans; /**< scans whose frame says a cap cut them */
    unsigned long long cut_keypoints, cut_segments, cut_points;
} dataset_metrics_t;

/** Metrics of a whole stream in memory independent of its length (exact
 *  medians from counting histograms). 0, or -1 with a message. */
int metrics_of_stream(FILE *in, const char *name, dataset_metrics_t *out, stream_summary_t *sum);

/* ---- log_scan.c: log records as scans, the shared extractor -------------- */

/* scan_range_max and scan_of_record: tools/carmen/carmen_bsf.h */

extern bsf_extractor_t g_ex;
extern bsf_result_t g_res;
extern uint8_t g_frame_buf[BSF_FRAME_MAX_SIZE];

/** Initialise g_ex for a method with the monotonic clock (or none when
 *  reproducible: frames then carry extraction time 0). 0, or -1 with a message. */
int init_extractor_timed(bsf_method_t method, int timed);
/** init_extractor_timed(method, 1). */
int init_extractor(bsf_method_t method);
/** As init_extractor; paper != 0 takes bsf_params_paper (the paper-faithful configuration). */
int init_extractor_config(bsf_method_t method, int paper);
/** Initialise g_ex with these parameters (plus the monotonic clock when timed).
 *  0, or -1 with a message. */
int init_extractor_params(const bsf_params_t *params, int timed);
/** Metadata of a stream extracted by g_ex from scans like sc at step quant:
 *  this build's caps, g_ex's method and target RMS, sc's geometry; no time
 *  origin, no source. */
void fill_metadata(bsf_metadata_t *m, const bsf_scan_t *sc, float quant);

/* ---- the commands (cmd_*.c) ---------------------------------------------- */

int cmd_extract(int argc, char **argv);
int cmd_decode(int argc, char **argv);
int cmd_metrics(int argc, char **argv);
int cmd_render(int argc, char **argv);
int cmd_table1(int argc, char **argv);
int cmd_demo(int argc, char **argv);
int cmd_listen(int argc, char **argv);
int cmd_map(int argc, char **argv);

/* ---- cmd_render.c: the drawing conventions bsf render and bsf map share -- */

#define RENDER_CURVE_COLOUR "#1f5fbf"
#define RENDER_VERTEX_COLOUR "#d62728"
#define RENDER_PATH_COLOUR "#2ca02c"
#define RENDER_PRIOR_COLOUR "#ff7f0e"
#define RENDER_POINT_COLOUR "#9a9a9a"
#define RENDER_WALL_COLOUR "#c8c8c8"

/** The robot's path being drawn (render_path_point, render_path_end). */
typedef struct {
    unsigned long n;
    double x, y, theta;
} render_path_t;

/** Next pose of the path (world metres, radians); a jump over 5 m starts a new line. */
void render_path_point(bsf_svg_t *svg, render_path_t *p, double x, double y, double theta);
/** Close the path and mark the last pose. */
void render_path_end(bsf_svg_t *svg, const render_path_t *p);
/** Every valid point of a CARMEN log in the world frame (its laser poses):
 *  into bounds when svg is NULL, else drawn as bsf render draws them (thinned
 *  to one per cell; *read, *drawn and *cell_m say how many and at what cell).
 *  0, or -1 with a message. */
int render_log_points(bsf_svg_t *svg, const char *log, bsf_bounds_t *bounds, unsigned long *read,
                      unsigned long *drawn, double *cell_m);
/** The odometry (prior) path of a CSV that bsf extract --align --prior-path
 *  wrote (columns scan,time_s, then x,y,theta of the odometry alone, of the
 *  prior and of the aligned pose): its odometry poses into bounds when svg is
 *  NULL, else drawn as a dashed line (a jump over 5 m starts a new line).
 *  *n gets the number of poses drawn: the rows whose scan is in lo..hi
 *  (hi < 0: no upper bound).
 *  0, or -1 with a message (FILE:LINE for a malformed line). */
int render_prior_path(bsf_svg_t *svg, const char *csv, long lo, long hi, bsf_bounds_t *bounds,
                      unsigned long *n);
/** The legend row of bsf render: curves, vertices, and the optional layers;
 *  with a prior path, the robot's path is named the corrected one. */
void render_legend(bsf_svg_t *svg, int have_path, int have_points, int have_scene, int have_prior);

/* ---- map_view.c: the receiver's map of a map stream (bsf map, listen, metrics) */

/** What one map frame changed in the receiver's map, by feature. */
typedef struct {
    unsigned long created;  /**< features that appeared */
    unsigned long extended; /**< features that gained control points */
    unsigned long moved;    /**< features whose points changed, same count */
    unsigned long merged;   /**< features that vanished while another changed */
    unsigned long removed;  /**< features that vanished otherwise */
    unsigned long skipped;  /**< records the receiver could not apply */
    unsigned long snapshots, poses;
} map_change_t;

/** A receiver map plus the path of pose records and byte counts. */
typedef struct {
    bsf_map_rx_t *rx; /**< heap: the receiver is large */
    uint32_t *n_ctrl; /**< per id: points before the frame (change tracking) */
    uint32_t *hash;   /**< per id: hash of the points before the frame */
    double *path;     /**< x, y, theta per pose record */
    size_t n_path, cap_path;
    unsigned long frames, frames_bad, pose_only_frames;
    unsigned long long bytes, pose_only_bytes;
    unsigned long long pose_record_bytes; /**< pose records inside frames with map records */
    int track;                            /**< compute map_change_t in map_view_apply */
    unsigned long n_features;             /**< features the receiver holds (when tracking) */
} map_view_t;

/** Empty view; track != 0 makes map_view_apply report changes (costs a pass
 *  over the map per frame). 0, or -1 with a message when out of memory. */
int map_view_init(map_view_t *v, int track);
void map_view_free(map_view_t *v);
/** Apply a delivered map frame of `bytes` on the wire; chg (may be NULL) gets
 *  its changes when tracking. 0; -1 when the receiver refuses the payload
 *  (counted in frames_bad, message printed). */
int map_view_apply(map_view_t *v, const bsf_frame_t *f, size_t bytes, map_change_t *chg);

/** Print the metrics of a stream (cmd_metrics.c; also used by demo). */
void print_metrics(FILE *f, const char *name, const stream_summary_t *s,
                   const dataset_metrics_t *d);
/** Draw frames lo..hi (seq) of a stream as an SVG map width_px wide, optional
 *  raw points and scene (cmd_render.c). in must come from open_seekable (it
 *  is read several times, so memory does not grow with the stream). */
int write_map_svg(const char *out_path, FILE *in, const char *in_name, long lo, long hi,
                  const char *points_log, const bsf_scene_t *scene, const char *prior_csv,
                  const char *title, double width_px);

#endif /* BSF_TOOL_H */
