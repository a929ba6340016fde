/* SPDX-License-Identifier: MIT */
/*
 * bench_extract - time the whole pipeline (bsf_extract) per stage, per
 * dataset and per method, then how the time grows with the beam count.
 *
 *   bench_extract [--passes N] [--method NAME|all] [--max-scans N]
 *                 [--no-scaling] [--scaling-only] [--beams N]
 *                 [--adversarial] [--adversarial-only] [LOG ...]
 *
 * Without LOG: the four logs in ../shared/data (BSF_SHARED_DIR overrides the
 * shared directory): intel, mit-csail, fr079 and the first 1000 scans of
 * fr-clinic (as in the paper). Default 5 passes, every method.
 * Parameters are the library defaults; range_max is the log's declared
 * maximum range capped below the no-return codes, as the host tool does.
 *
 * Each stage's time comes from bsf_stats_t.stage_ns (CLOCK_MONOTONIC hook);
 * "whole" is stats.time_ns. "call" is the same call timed from outside with
 * no clock hook, i.e. what a user without timing pays. For every scan the
 * median over passes is taken; mean, median and p99 of those medians are
 * printed, plus scans/s = 1e6 / mean whole time. Numbers are printed, never
 * judged: run on one quiet core, e.g. taskset -c 1 build/tools/bench_extract.
 *
 * The scaling run ray-casts one synthetic room (tools/bsf_scene.h) with 180
 * to 4000 beams over 270 degrees; it needs a library built with
 * BSF_MAX_POINTS >= 4000 (target bench_extract links bsf_big, 4096 beams;
 * bench_extract_default links the default library and skips larger sizes).
 * --beams N runs only that size of the scaling list (for profiling). Every
 * pose of the scaling scene is checked to stand in free space (bench_scenes.h);
 * the run stops if one does not.
 * --adversarial adds the worst-case scans of bench_scenes.h (a sensor against
 * a pillar, pure clutter, a 4000-beam long wall), reported apart;
 * --adversarial-only runs just those.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "bsf/bsf.h"
#include "bsf_port_clock.h"
#include "bench_scenes.h"
#include "bsf_scene.h"
#include "carmen.h"

#define N_ROWS 6 /* 4 stages, whole (stats), call (outer timer) */
#define ROW_WHOLE 4
#define ROW_CALL 5

static const char *const row_name[N_ROWS] = {"points",  "corners", "segmentation",
                                             "fitting", "whole",   "call (no hook)"};

typedef struct {
    float *ranges;
    bsf_scan_t scan;
} stored_scan_t;

typedef struct {
    stored_scan_t *scans;
    size_t n;
} scan_set_t;

static bsf_extractor_t g_ex;
static bsf_extractor_t g_ex_noclock;
static bsf_result_t g_res;

static void *xmalloc(size_t n)
{
    void *p = malloc(n != 0u ? n : 1u);
    if (p == NULL) {
        fprintf(stderr, "bench_extract: out of memory\n");
        exit(1);
    }
    return p;
}

static void free_set(scan_set_t *set)
{
    size_t i;
    for (i = 0; i < set->n; ++i) {
        free(set->scans[i].ranges);
    }
    free(set->scans);
    set->scans = NULL;
    set->n = 0;
}

static int load_log(const char *path, size_t max_scans, scan_set_t *set)
{
    carmen_reader_t *rd = carmen_open(path, stderr);
    carmen_scan_t rec;
    size_t cap = 0;
    set->scans = NULL;
    set->n = 0;
    if (rd == NULL) {
        return -1;
    }
    while ((max_scans == 0u || set->n < max_scans) && carmen_next(rd, &rec) == 1) {
        stored_scan_t *st;
        if (rec.count > BSF_MAX_POINTS) {
            fprintf(stderr, "bench_extract: %s:%lu: %zu beams > BSF_MAX_POINTS, skipped\n", path,
                    rec.line, rec.count);
            continue;
        }
        if (set->n == cap) {
            stored_scan_t *grown;
            cap = cap ? 2 * cap : 1024;
            grown = realloc(set->scans, cap * sizeof *set->scans);
            if (grown == NULL) {
                fprintf(stderr, "bench_extract: out of memory\n");
                exit(1);
            }
            set->scans = grown;
        }
        st = &set->scans[set->n];
        st->ranges = xmalloc(rec.count * sizeof(float));
        memcpy(st->ranges, rec.ranges, rec.count * sizeof(float));
        st->scan.ranges = st->ranges;
        st->scan.count = rec.count;
        st->scan.angle_min = rec.angle_min;
        st->scan.angle_increment = rec.angle_increment;
        st->scan.range_min = 0.0f;
        st->scan.range_max = carmen_valid_range_max(&rec);
        ++set->n;
    }
    carmen_close(rd);
    return 0;
}

static int init_both(bsf_method_t method)
{
    bsf_params_t p = bsf_params_default(method);
    if (bsf_extractor_init(&g_ex_noclock, &p) != BSF_OK) {
        return -1;
    }
    p.clock = bsf_port_clock_monotonic_ns;
    p.clock_user = NULL;
    p.clock_hz = 1000000000u;
    return bsf_extractor_init(&g_ex, &p) == BSF_OK ? 0 : -1;
}

typedef struct {
    double mean, median, p99, max;
} summary_t;

/* What one method did on one set of scans. */
typedef struct {
    summary_t whole;           /* whole-extraction us per scan */
    double row_median[N_ROWS]; /* median us per scan of each row */
    double features;           /* per scan */
    double in_features;        /* share of valid points kept in features */
} method_result_t;

/* samples[scan * passes + pass] -> per-scan medians (sorted in place) -> summary. */
static summary_t summarise(double *samples, size_t n_scans, int passes, double *per_scan)
{
    summary_t s;
    s.mean = per_scan_medians(samples, n_scans, passes, per_scan) / (double)n_scans;
    s.median = per_scan[n_scans / 2];
    s.p99 = per_scan[(n_scans * 99u) / 100u];
    s.max = per_scan[n_scans - 1u];
    return s;
}

/* Run one method over a set of scans; fills whole-time summary in *whole.
 * @return 0, 1 when the method is not available (skipped), -1 on an error. */
static int bench_method(const scan_set_t *set, bsf_method_t method, int passes, int print,
                        method_result_t *out)
{
    double *samples[N_ROWS];
    double *per_scan = xmalloc(set->n * sizeof(double));
    size_t i, r;
    unsigned long feat = 0, kp = 0, unfit = 0, ctrl = 0, valid = 0, kept = 0;
    int p, rc = 0;

    if (init_both(method) != 0) {
        /* A method this library build does not provide yet (its params are refused). */
        if (print) {
            printf("  %s: SKIPPED: bsf_extractor_init refuses it in this build\n",
                   bsf_method_name(method));
        }
        free(per_scan);
        return 1;
    }
    for (r = 0; r < N_ROWS; ++r) {
        samples[r] = xmalloc(set->n * (size_t)passes * sizeof(double));
    }
    for (p = 0; p < passes && rc == 0; ++p) {
        for (i = 0; i < set->n; ++i) {
            const size_t k = i * (size_t)passes + (size_t)p;
            double t0, t1;
            bsf_status_t st = bsf_extract(&g_ex, &set->scans[i].scan, &g_res);
            if (st < 0) { /* a cut scan (BSF_OK_CUT) is timed like the others */
                fprintf(stderr, "bench_extract: %s scan %zu: %s\n", bsf_method_name(method), i,
                        bsf_status_str(st));
                rc = -1;
                break;
            }
            for (r = 0; r < BSF_STAGE_COUNT; ++r) {
                samples[r][k] = (double)g_res.stats.stage_ns[r] * 1e-3;
            }
            samples[ROW_WHOLE][k] = (double)g_res.stats.time_ns * 1e-3;
            if (p == 0) {
                feat += g_res.stats.n_features;
                kp += g_res.stats.n_keypoints;
                unfit += g_res.stats.n_unfitted;
                ctrl += g_res.stats.n_ctrl;
                valid += g_res.stats.n_valid;
                kept += g_res.stats.n_in_features;
            }
            t0 = now_us();
            st = bsf_extract(&g_ex_noclock, &set->scans[i].scan, &g_res);
            t1 = now_us();
            if (st < 0) {
                rc = -1;
                break;
            }
            samples[ROW_CALL][k] = t1 - t0;
        }
    }
    if (rc == 0) {
        const double n = (double)set->n;
        out->features = (double)feat / n;
        out->in_features = valid > 0u ? (double)kept / (double)valid : 0.0;
        if (print) {
            printf("  %s: %.2f features, %.2f keypoints, %.1f control points, %.3f unfitted"
                   " per scan\n",
                   bsf_method_name(method), (double)feat / n, (double)kp / n, (double)ctrl / n,
                   (double)unfit / n);
            printf("    %-16s %10s %10s %10s %10s\n", "us/scan", "mean", "median", "p99", "max");
        }
        for (r = 0; r < N_ROWS; ++r) {
            summary_t s = summarise(samples[r], set->n, passes, per_scan);
            if (print) {
                printf("    %-16s %10.2f %10.2f %10.2f %10.2f\n", row_name[r], s.mean, s.median,
                       s.p99, s.max);
            }
            out->row_median[r] = s.median;
            if (r == ROW_WHOLE) {
                out->whole = s;
            }
        }
        if (print) {
            printf("    scans/s (1e6 / mean whole): %.0f\n", 1e6 / out->whole.mean);
        }
    }
    for (r = 0; r < N_ROWS; ++r) {
        free(samples[r]);
    }
    free(per_scan);
    return rc;
}

static int bench_log(const char *path, size_t max_scans, const int *methods, int passes)
{
    scan_set_t set;
    method_result_t res;
    int m, rc = 0;
    if (load_log(path, max_scans, &set) != 0) {
        printf("SKIPPED: %s not found\n", path);
        return 0;
    }
    if (set.n == 0u) {
        fprintf(stderr, "bench_extract: no scan in %s\n", path);
        free_set(&set);
        return 1;
    }
    printf("\n%s: %zu scans, %zu beams (first scan), range_max %.2f m, %d passes\n", path, set.n,
           set.scans[0].scan.count, (double)set.scans[0].scan.range_max, passes);
    for (m = 0; m < BSF_METHOD_COUNT; ++m) {
        if (methods[m] && bench_method(&set, (bsf_method_t)m, passes, 1, &res) < 0) {
            rc = 1;
        }
    }
    free_set(&set);
    return rc;
}

/* ---- scaling on synthetic scans ---------------------------------------------- */

#define SCALE_POSES BENCH_SCALE_POSES
#define N_SCALE BENCH_SCALE_SIZES
#define scale_beams bench_scale_beams

/* Every pose of the scaling scene in free space (bench_scenes.h), or stop. */
static int check_scaling_poses(const bsf_scene_t *scene)
{
    bsf_scene_pose_t poses[SCALE_POSES];
    size_t i;
    int shape;
    int bad;
    for (i = 0; i < SCALE_POSES; ++i) {
        poses[i] = bench_scaling_pose(i);
    }
    bad = bench_poses_check(scene, poses, SCALE_POSES, BENCH_POSE_CLEARANCE, &shape);
    if (bad >= 0) {
        fprintf(stderr,
                "bench_extract: scaling pose %d (%.2f, %.2f) is not in free space (shape %d)\n",
                bad, poses[bad].x, poses[bad].y, shape);
        return 1;
    }
    printf("  all %d poses checked against all %zu shapes: free (clearance %.2f m), enclosed\n",
           SCALE_POSES, scene->n_shapes, BENCH_POSE_CLEARANCE);
    return 0;
}

static int bench_scaling(const int *methods, int passes, size_t only_beams)
{
    static float ranges[SCALE_POSES][BSF_MAX_POINTS];
    static double median_us[BSF_METHOD_COUNT][N_SCALE];
    static double feats[BSF_METHOD_COUNT][N_SCALE];
    static double kept[BSF_METHOD_COUNT][N_SCALE];
    static double stage_us[BSF_METHOD_COUNT][BSF_STAGE_COUNT][N_SCALE];
    stored_scan_t stored[SCALE_POSES];
    bsf_scene_t scene;
    bsf_scene_rng_t rng;
    size_t b, i;
    int m;

    if (bench_scaling_scene(&scene) != BSF_OK) {
        fprintf(stderr, "bench_extract: scene setup failed\n");
        return 1;
    }
    printf("\nscaling: synthetic L-room, 2 pillars, a free-standing corner; %d poses, 270 deg, "
           "sigma 1 cm, %d passes; BSF_MAX_POINTS %d\n",
           SCALE_POSES, passes, BSF_MAX_POINTS);
    if (check_scaling_poses(&scene) != 0) {
        return 1;
    }
    printf("  %-16s", "beams");
    for (b = 0; b < N_SCALE; ++b) {
        printf(" %9zu", scale_beams[b]);
    }
    printf("\n");
    for (m = 0; m < BSF_METHOD_COUNT; ++m) {
        if (!methods[m]) {
            continue;
        }
        for (b = 0; b < N_SCALE; ++b) {
            scan_set_t set;
            method_result_t res;
            int st;
            median_us[m][b] = -1.0;
            if (scale_beams[b] > BSF_MAX_POINTS ||
                (only_beams != 0u && scale_beams[b] != only_beams)) {
                continue;
            }
            bsf_scene_rng_seed(&rng, 2022u + b);
            for (i = 0; i < SCALE_POSES; ++i) {
                const bsf_scene_pose_t pose = bench_scaling_pose(i);
                bsf_lidar_t l =
                    bsf_lidar_default(pose.x, pose.y, pose.theta, scale_beams[b], 4.71238898);
                l.noise_sigma = 0.01;
                if (bsf_scene_scan(&scene, &l, &rng, ranges[i], NULL, BSF_MAX_POINTS) != BSF_OK) {
                    fprintf(stderr, "bench_extract: ray-cast failed\n");
                    return 1;
                }
                stored[i].ranges = ranges[i];
                stored[i].scan = bsf_scene_lidar_scan(&l, ranges[i]);
            }
            set.scans = stored;
            set.n = SCALE_POSES;
            st = bench_method(&set, (bsf_method_t)m, passes, 0, &res);
            if (st < 0) {
                return 1;
            }
            if (st == 0) {
                median_us[m][b] = res.whole.median;
                feats[m][b] = res.features;
                kept[m][b] = res.in_features;
                for (i = 0; i < BSF_STAGE_COUNT; ++i) {
                    stage_us[m][i][b] = res.row_median[i];
                }
            }
        }
        if (only_beams == 0u && median_us[m][0] < 0.0) {
            printf("  %-16s SKIPPED: not available in this build\n",
                   bsf_method_name((bsf_method_t)m));
            continue;
        }
        printf("  %-16s", bsf_method_name((bsf_method_t)m));
        for (b = 0; b < N_SCALE; ++b) {
            if (median_us[m][b] < 0.0) {
                printf(" %9s", "-");
            } else {
                printf(" %9.1f", median_us[m][b]);
            }
        }
        printf("  us/scan (median)\n  %-16s", "");
        for (b = 0; b < N_SCALE; ++b) {
            printf(" %9.2f", median_us[m][b] < 0.0 ? 0.0 : feats[m][b]);
        }
        printf("  features/scan\n  %-16s", "");
        for (b = 0; b < N_SCALE; ++b) {
            printf(" %9.3f", median_us[m][b] < 0.0 ? 0.0 : kept[m][b]);
        }
        printf("  share of valid points in features\n");
        for (i = 0; i < BSF_STAGE_COUNT; ++i) {
            printf("  %-16s", row_name[i]);
            for (b = 0; b < N_SCALE; ++b) {
                printf(" %9.1f", median_us[m][b] < 0.0 ? 0.0 : stage_us[m][i][b]);
            }
            printf("  us/scan (median of the stage)\n");
        }
    }
    for (m = 0; m < BSF_METHOD_COUNT; ++m) {
        if (!methods[m]) {
            continue;
        }
        for (b = 0; b < N_SCALE; ++b) {
            size_t q;
            for (q = b + 1; q < N_SCALE; ++q) {
                if (scale_beams[q] == 4u * scale_beams[b] && median_us[m][b] > 0.0 &&
                    median_us[m][q] > 0.0) {
                    printf("  %s: %zu -> %zu beams (4x): time x %.2f (budget <= 4.3)\n",
                           bsf_method_name((bsf_method_t)m), scale_beams[b], scale_beams[q],
                           median_us[m][q] / median_us[m][b]);
                }
            }
        }
    }
    return 0;
}

/* ---- adversarial scans (bench_scenes.h), reported apart ---------------------- */

static int bench_adversarial(const int *methods, int passes)
{
    static float ranges[BENCH_ADV_SCANS][BSF_MAX_POINTS];
    stored_scan_t stored[BENCH_ADV_SCANS];
    int kind, m;
    printf("\nadversarial scans (worst cases, not part of the scaling figures), %d passes; "
           "median us per scan of %d scans, max in brackets\n",
           passes, BENCH_ADV_SCANS);
    for (kind = 0; kind < BENCH_ADV_COUNT; ++kind) {
        scan_set_t set;
        size_t k;
        if (bench_adv_beams(kind) > BSF_MAX_POINTS) {
            printf("  %-10s SKIPPED: %zu beams > BSF_MAX_POINTS\n", bench_adv_name(kind),
                   bench_adv_beams(kind));
            continue;
        }
        for (k = 0; k < BENCH_ADV_SCANS; ++k) {
            if (bench_adv_scan(kind, k, ranges[k], BSF_MAX_POINTS, &stored[k].scan) != BSF_OK) {
                fprintf(stderr, "bench_extract: adversarial %s scan %zu failed\n",
                        bench_adv_name(kind), k);
                return 1;
            }
            stored[k].ranges = ranges[k];
        }
        set.scans = stored;
        set.n = BENCH_ADV_SCANS;
        printf("  %-10s %5zu beams:", bench_adv_name(kind), bench_adv_beams(kind));
        for (m = 0; m < BSF_METHOD_COUNT; ++m) {
            method_result_t res;
            int st;
            if (!methods[m]) {
                continue;
            }
            st = bench_method(&set, (bsf_method_t)m, passes, 0, &res);
            if (st < 0) {
                return 1;
            }
            if (st == 0) {
                printf("  %s %.1f (%.1f)", bsf_method_name((bsf_method_t)m), res.whole.median,
                       res.whole.max);
            }
        }
        printf("\n");
    }
    return 0;
}

static void usage(void)
{
    fprintf(stderr, "usage: bench_extract [--passes N] [--method NAME|all] [--max-scans N]\n"
                    "                     [--no-scaling] [--scaling-only] [--beams N]\n"
                    "                     [--adversarial] [--adversarial-only] [LOG ...]\n");
}

int main(int argc, char **argv)
{
    static const char *const default_logs[] = {"intel.log.gz", "mit-csail.log.gz", "fr079.log.gz",
                                               "fr-clinic.log.gz"};
    static const size_t default_max[] = {0, 0, 0, 1000};
    const char *shared = getenv("BSF_SHARED_DIR");
    int methods[BSF_METHOD_COUNT] = {1, 1, 1, 1};
    int passes = 5, scaling = 1, logs = 1, adversarial = 0, n_paths = 0, a, rc = 0;
    long max_scans = 0, only_beams = 0;
    const char **paths = xmalloc((size_t)argc * sizeof *paths);

    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--passes") == 0 && a + 1 < argc) {
            passes = atoi(argv[++a]);
        } else if (strcmp(argv[a], "--max-scans") == 0 && a + 1 < argc) {
            max_scans = atol(argv[++a]);
        } else if (strcmp(argv[a], "--method") == 0 && a + 1 < argc) {
            const char *name = argv[++a];
            if (strcmp(name, "all") != 0) {
                bsf_method_t m = bsf_method_from_name(name);
                if (m == BSF_METHOD_COUNT) {
                    fprintf(stderr, "bench_extract: unknown method %s\n", name);
                    return 2;
                }
                memset(methods, 0, sizeof methods);
                methods[m] = 1;
            }
        } else if (strcmp(argv[a], "--beams") == 0 && a + 1 < argc) {
            only_beams = atol(argv[++a]);
        } else if (strcmp(argv[a], "--no-scaling") == 0) {
            scaling = 0;
        } else if (strcmp(argv[a], "--scaling-only") == 0) {
            logs = 0;
        } else if (strcmp(argv[a], "--adversarial") == 0) {
            adversarial = 1;
        } else if (strcmp(argv[a], "--adversarial-only") == 0) {
            adversarial = 1;
            logs = 0;
            scaling = 0;
        } else if (argv[a][0] == '-') {
            usage();
            return 2;
        } else {
            paths[n_paths++] = argv[a];
        }
    }
    if (passes < 1 || max_scans < 0 || only_beams < 0) {
        usage();
        return 2;
    }
    printf("bench_extract: BSF_MAX_POINTS %d, sizeof(bsf_extractor_t) %zu, "
           "sizeof(bsf_result_t) %zu\n",
           BSF_MAX_POINTS, sizeof(bsf_extractor_t), sizeof(bsf_result_t));
    if (logs && n_paths > 0) {
        for (a = 0; a < n_paths; ++a) {
            rc |= bench_log(paths[a], (size_t)max_scans, methods, passes);
        }
    } else if (logs) {
        size_t k;
        for (k = 0; k < sizeof default_logs / sizeof default_logs[0]; ++k) {
            char path[4096];
            snprintf(path, sizeof path, "%s/data/%s",
                     shared != NULL ? shared : BSF_SHARED_DIR_DEFAULT, default_logs[k]);
            rc |= bench_log(path, max_scans > 0 ? (size_t)max_scans : default_max[k], methods,
                            passes);
        }
    }
    if (scaling) {
        rc |= bench_scaling(methods, passes, (size_t)only_beams);
    }
    if (adversarial) {
        rc |= bench_adversarial(methods, passes);
    }
    free(paths);
    return rc;
}
