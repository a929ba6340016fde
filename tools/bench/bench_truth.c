/* SPDX-License-Identifier: MIT */
/*
 * bench_truth - the default extraction judged against ground truth on
 * synthetic scenes (bsf_truth.h has the definitions), per scene, sensor and
 * noise, plus the paper's metrics on the four datasets.
 *
 *   bench_truth                  full table (docs/GROUND_TRUTH.md)
 *   bench_truth --quick --check  small run that fails (exit 1) when a target is missed (ctest)
 *   bench_truth --noise 10 --check-rows  every scene and sensor at 1 cm, mixed pixels
 *                                included: fails when precision or sparse-wall recall falls
 *                                below its regression bound (ctest)
 *   options: --poses N, --paper (paper-faithful configuration), --grazing / --no-grazing
 *            (SVED and LC join walls seen at grazing incidence; on by default),
 *            --evidence / --no-evidence (LC's corner evidence test,
 *            bsf_lc_params_t.corner_evidence; on by default), --tails / --no-tails
 *            (bsf_params_t.trim_tails; on by default), --fit-passes K
 *            (bsf_params_t.fit_passes: a bound on the fit's work; default 0, none),
 *            --fit-bin-length M (bsf_params_t.fit_bin_length; default the method's), --datasets DIR
 *            (also Gamma/eta/accuracy/bytes on the four logs in DIR/data),
 *            --scene NAME, --sensor N, --noise MM, --verbose (every missed corner,
 *            false vertex and stray curve), --oracle-reach M (how far from the vertex
 *            the oracle's lines take returns, metres; 0: the whole run; default LC's
 *            max_side); BENCH_TRUTH_DUMP=K prints pose K's ranges (a mixed pixel that
 *            is a hit on no wall marked "blend"), features and keypoints (for debugging
 *            one scan); BENCH_TRUTH_ORACLE_LOG=FILE writes one
 *            line per sparse-rule corner (bsf_truth_add_oracle)
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bsf/bsf.h"
#include "bench_scenes.h"
#include "bsf_scene.h"
#include "bsf_truth.h"
#include "carmen.h"

#define PI 3.14159265358979323846

typedef struct {
    const char *name;
    size_t beams;
    double increment_deg;
    int full_circle;
} sensor_t;

static const sensor_t sensors[] = {
    {"181/1.0/180", 181u, 1.0, 0}, {"361/0.75/270", 361u, 0.75, 0},
    {"541/0.5/270", 541u, 0.5, 0}, {"1081/0.25/270", 1081u, 0.25, 0},
    {"360/1.0/360", 360u, 1.0, 1}, {"3200/0.1125/360", 3200u, 0.1125, 1},
};
#define N_SENSORS (sizeof sensors / sizeof sensors[0])

typedef struct {
    const char *name;
    double sigma;
    int mixed;
} noise_t;

static const noise_t noises[] = {
    {"0", 0.0, 0}, {"5mm", 0.005, 0}, {"1cm", 0.01, 0}, {"3cm", 0.03, 0}, {"1cm+mix", 0.01, 1},
};
#define N_NOISES (sizeof noises / sizeof noises[0])

static const char *const scene_names[5] = {"office", "angles", "curved", "corridor", "clutter"};
#define N_SCENES 5
/* Scenes the targets are checked on (--check); the corridor and the
 * cluttered room are reported only. */
#define N_CHECKED_SCENES 3

static bsf_extractor_t ex;
static bsf_result_t res;
static float ranges[BSF_MAX_POINTS];
static float clean[BSF_MAX_POINTS];
static float unmixed[BSF_MAX_POINTS]; /* ranges before mixed pixels */
static int16_t hits[BSF_MAX_POINTS];
static int16_t on_shape[BSF_MAX_POINTS]; /* hits without the blends (bsf_truth_returns_on_shapes) */
static bsf_truth_acc_t acc;

static int paper_mode = 0;
/* 1 --grazing, 0 --no-grazing, -1 the default: SVED's and LC's joins of walls
 * seen at grazing incidence */
static int grazing_mode = -1;
/* 1 --evidence, 0 --no-evidence, -1 the default: LC's corner evidence test */
static int evidence_mode = -1;
/* 1 --tails, 0 --no-tails, -1 the default: tail returns left off segment ends */
static int tails_mode = -1;
/* --fit-passes K: bsf_params_t.fit_passes (0, the default: no bound) */
static long fit_passes = 0;
/* --fit-bin-length M: bsf_params_t.fit_bin_length (< 0, the default: the method's) */
static double fit_bin_length = -1.0;

static bsf_params_t make_params(void)
{
    bsf_params_t p = paper_mode ? bsf_params_paper(BSF_METHOD_FALKO_SVED_PDM)
                                : bsf_params_default(BSF_METHOD_DEFAULT);
    if (grazing_mode >= 0) {
        p.sved.join_grazing = (uint8_t)grazing_mode;
        p.lc.join_grazing = (uint8_t)grazing_mode;
    }
    if (evidence_mode >= 0) {
        p.lc.corner_evidence = (uint8_t)evidence_mode;
    }
    if (tails_mode >= 0) {
        p.trim_tails = (uint8_t)tails_mode;
    }
    p.fit_passes = (uint8_t)fit_passes;
    if (fit_bin_length >= 0.0) {
        p.fit_bin_length = (float)fit_bin_length;
    }
    return p;
}

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

static int make_scene(int which, bsf_scene_t *sc)
{
    if (which == 0) {
        bsf_scene_demo_office(sc);
    } else if (which == 1) {
        bsf_scene_truth_angles(sc);
    } else if (which == 2) {
        bsf_scene_truth_curved(sc);
    } else if (which == 3) {
        return bench_truth_corridor(sc) == BSF_OK ? 0 : -1;
    } else {
        return bench_truth_clutter(sc) == BSF_OK ? 0 : -1;
    }
    return 0;
}

static void scene_pose(int which, long k, long n, double *x, double *y, double *th)
{
    if (which >= 3) {
        const bsf_scene_pose_t p =
            which == 3 ? bench_truth_corridor_pose(k, n) : bench_truth_clutter_pose(k, n);
        *x = p.x;
        *y = p.y;
        *th = p.theta;
    } else {
        bsf_scene_truth_pose(which, k, n, x, y, th);
    }
}

/* One configuration: scene x sensor x noise over n_poses poses. */
static int run_config(int which, const sensor_t *sen, const noise_t *nz, long n_poses,
                      bsf_truth_summary_t *out, long *failed)
{
    static bsf_scene_t sc;
    bsf_scene_rng_t rng;
    bsf_params_t p = make_params();
    long k;
    if (make_scene(which, &sc) != 0) {
        fprintf(stderr, "bench_truth: scene %s does not fit\n", scene_names[which]);
        return -1;
    }
    bsf_scene_rng_seed(&rng, 1234u + (uint64_t)which * 7u + (uint64_t)sen->beams);
    if (bsf_extractor_init(&ex, &p) != BSF_OK) {
        fprintf(stderr, "bench_truth: extractor init failed\n");
        return -1;
    }
    bsf_truth_acc_init(&acc);
    *failed = 0;
    for (k = 0; k < n_poses; ++k) {
        double x, y, th;
        bsf_lidar_t lid;
        bsf_scan_t scan;
        bsf_frame_info_t info;
        size_t bytes = 0;
        double t0;
        double t1;
        size_t i;
        scene_pose(which, k, n_poses, &x, &y, &th);
        if (which >= 3) {
            const bsf_scene_pose_t pz = {x, y, th};
            if (bench_poses_check(&sc, &pz, 1u, 0.3, NULL) >= 0) {
                fprintf(stderr, "bench_truth: %s pose %ld is not free\n", scene_names[which], k);
                return -1;
            }
        }
        lid = bsf_lidar_default(x, y, th, sen->beams,
                                (double)(sen->beams - 1u) * sen->increment_deg * PI / 180.0);
        if (sen->full_circle) {
            lid.angle_min = -PI;
            lid.angle_increment = 2.0 * PI / (double)sen->beams;
        }
        lid.noise_sigma = 0.0;
        if (bsf_scene_scan(&sc, &lid, NULL, clean, hits, BSF_MAX_POINTS) != BSF_OK) {
            fprintf(stderr, "bench_truth: scan failed\n");
            return -1;
        }
        for (i = 0; i < sen->beams; ++i) {
            ranges[i] = clean[i];
            if (hits[i] >= 0 && nz->sigma > 0.0) {
                double r = (double)clean[i] + nz->sigma * bsf_scene_rng_gauss(&rng);
                ranges[i] = (float)(r < 0.0 ? 0.0 : r);
            }
        }
        memcpy(unmixed, ranges, sen->beams * sizeof ranges[0]);
        if (nz->mixed) {
            (void)bsf_scene_mixed_pixels(ranges, sen->beams, lid.no_return, 0.3, 0.5, &rng);
        }
        /* A blend is a return on no wall: it neither makes a corner visible
         * nor counts in the oracle's lines (unless it lands within the
         * noise, 3 sigma, of its own wall). */
        (void)bsf_truth_returns_on_shapes(on_shape, hits, clean, ranges, unmixed, sen->beams,
                                          3.0 * nz->sigma);
        scan = bsf_scene_lidar_scan(&lid, ranges);
        t0 = now_ns();
        if (bsf_extract(&ex, &scan, &res) != BSF_OK) {
            /* Counted (a failed scan yields nothing, so its corners are
             * missed) and reported in the row. */
            ++*failed;
        }
        t1 = now_ns();
        bsf_frame_info_init(&info);
        if (bsf_frame_encode(&info, &res, NULL, 0u, &bytes) != BSF_OK) {
            fprintf(stderr, "bench_truth: encode failed\n");
            return -1;
        }
        if (bsf_truth_verbose) {
            printf("pose %ld: (%.3f, %.3f, %.3f)\n", k, x, y, th);
        }
        if (getenv("BENCH_TRUTH_DUMP") != NULL && atol(getenv("BENCH_TRUTH_DUMP")) == k) {
            size_t f2;
            for (i = 0; i < sen->beams; ++i) {
                printf("beam %lu range %.4f hit %d%s\n", (unsigned long)i, (double)ranges[i],
                       hits[i], on_shape[i] != hits[i] ? " blend" : "");
            }
            for (f2 = 0; f2 < res.n_features; ++f2) {
                const bsf_feature_t *ft = &res.features[f2];
                size_t q;
                printf("feature %lu beams %u-%u\n", (unsigned long)f2, ft->first_beam,
                       ft->last_beam);
                for (q = 0; q < ft->n_ctrl; ++q) {
                    printf("  ctrl %.4f %.4f %u\n", (double)res.ctrl[ft->ctrl_first + q].x,
                           (double)res.ctrl[ft->ctrl_first + q].y,
                           res.ctrl_is_vertex[ft->ctrl_first + q]);
                }
            }
            for (f2 = 0; f2 < res.stats.n_keypoints; ++f2) {
                printf("kp %u %.4f %.4f\n", ex.keypoints[f2].index,
                       (double)ex.keypoints[f2].point.x, (double)ex.keypoints[f2].point.y);
            }
        }
        bsf_truth_oracle_keypoints = ex.keypoints;
        bsf_truth_oracle_n_keypoints = res.stats.n_keypoints;
        if (bsf_truth_add(&acc, &sc, &lid, clean, on_shape, &res, bytes, t1 - t0) != 0 ||
            bsf_truth_add_oracle(&acc, &sc, &lid, clean, on_shape, ranges, &res) != 0) {
            return -1;
        }
    }
    bsf_truth_summary(&acc, out);
    return 0;
}

static void print_header(void)
{
    printf(
        "| scene | sensor | noise | visible | recall | <3m | 3-6m | 6-8m | precision | verr "
        "med/p90/max "
        "cm | curve rms/p99/max cm | stray>5cm | Gamma | eta | bytes/scan | us/scan | failed "
        "| sparse: visible | recall | 3-6m | verr med/p90 cm | obtuse cvx (n) | obtuse ccv (n) | "
        "seam behind (n) "
        "| ahead (n) | oracle med/p90 cm | oracle all med/p90 cm |\n");
    printf(
        "|---|---|---|---:|---:|---:|---:|---:|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:"
        "|---:|---|---|---|---|---|---|---|\n");
}

static void print_row(int which, const sensor_t *sen, const noise_t *nz,
                      const bsf_truth_summary_t *s, long failed)
{
    printf(
        "| %s | %s | %s | %lu | %.1f%% | %.1f%% | %.1f%% | %.1f%% | %.1f%% | %.2f / %.2f / %.2f | "
        "%.2f / %.2f / %.2f | %.1f%% | %.1f%% | %.3f | %.0f | %.0f | %ld | %lu | %.1f%% | %.1f%% "
        "| %.2f / %.2f | %.0f%% (%lu) | %.0f%% (%lu) | %.0f%% (%lu) | %.0f%% (%lu) | %.2f / %.2f | "
        "%.2f / %.2f "
        "|\n",
        scene_names[which], sen->name, nz->name, (unsigned long)s->visible, 100.0 * s->recall,
        100.0 * s->recall_band[0], 100.0 * s->recall_band[1], 100.0 * s->recall_band[2],
        100.0 * s->precision, 100.0 * s->verr_median, 100.0 * s->verr_p90, 100.0 * s->verr_max,
        100.0 * s->curve_rms, 100.0 * s->curve_p99, 100.0 * s->curve_max, 100.0 * s->stray_share,
        100.0 * s->gamma, s->eta, s->bytes_per_scan, s->us_per_scan, failed,
        (unsigned long)s->visible_sparse, 100.0 * s->recall_sparse,
        100.0 * s->recall_sparse_band[1], 100.0 * s->verr_sparse_median, 100.0 * s->verr_sparse_p90,
        100.0 * s->recall_obtuse, (unsigned long)s->obtuse_visible,
        100.0 * s->recall_obtuse_concave, (unsigned long)s->obtuse_concave_visible,
        100.0 * s->recall_behind, (unsigned long)s->behind_visible, 100.0 * s->recall_ahead,
        (unsigned long)s->ahead_visible, 100.0 * s->oracle_found_median,
        100.0 * s->oracle_found_p90, 100.0 * s->oracle_all_median, 100.0 * s->oracle_all_p90);
}

/* The targets of docs/GROUND_TRUTH.md for office-like scenes (the demo office and the
 * angles office; the curved room is judged on precision and curves only).
 * Returns the number of failed checks. The curve targets (p99 <= 3 cm, max
 * <= 8 cm at sigma <= 1 cm) are not met everywhere yet (docs/GROUND_TRUTH.md
 * says where and why): a miss is printed as "GOAL NOT MET" and fails only
 * beyond the regression bounds CURVE_P99_BOUND and CURVE_MAX_BOUND, which the
 * code before LC fails. */
/* A target missed beyond its regression bound (counted in missed), or only
 * short of its goal (printed), for the row of which, sen and nz. */
#define MISS(cond, what)                                                                           \
    do {                                                                                           \
        if (cond) {                                                                                \
            printf("TARGET MISSED: %s %s %s: %s\n", scene_names[which], sen->name, nz->name,       \
                   what);                                                                          \
            ++missed;                                                                              \
        }                                                                                          \
    } while (0)
#define GOAL(cond, what)                                                                           \
    do {                                                                                           \
        if (cond) {                                                                                \
            printf("GOAL NOT MET: %s %s %s: %s\n", scene_names[which], sen->name, nz->name, what); \
        }                                                                                          \
    } while (0)
#define CURVE_P99_BOUND 0.045
#define CURVE_MAX_BOUND 0.12
#define SPARSE_RECALL_BOUND 0.70
static int check_targets(int which, const sensor_t *sen, const noise_t *nz,
                         const bsf_truth_summary_t *s)
{
    int missed = 0;
    const double want_recall = sen->beams >= 361u ? 0.90 : 0.70;
    if (which != 2 && s->visible > 0u) {
        MISS(s->recall < want_recall, "vertex recall (>= 90 % at 361+ beams, >= 70 % at 181)");
    }
    MISS(s->precision < 0.95, "vertex precision >= 95 %");
    if (which != 2 && s->visible_sparse > 0u) {
        /* Sparse-wall rule: the same recall targets, not met yet; a miss
         * fails only below SPARSE_RECALL_BOUND, under the code of its
         * introduction (74-100 % on the office-like rows). */
        GOAL(s->recall_sparse < want_recall,
             "sparse-wall recall (>= 90 % at 361+ beams, >= 70 % at 181)");
        MISS(s->recall_sparse < SPARSE_RECALL_BOUND,
             "sparse-wall recall >= 70 % (regression bound)");
    }
    if (s->obtuse_visible > 0u) {
        GOAL(s->recall_obtuse < 0.85, "recall on obtuse convex corners >= 85 %");
    }
    if (s->behind_visible > 0u && s->ahead_visible > 0u) {
        GOAL(s->recall_behind + 0.05 < s->recall_ahead,
             "a corner behind a full-circle sensor found as often as ahead");
    }
    if (nz->sigma <= 0.01 && !nz->mixed) {
        MISS(s->verr_median > 0.01, "vertex error median <= 1 cm");
        MISS(s->verr_p90 > 0.03, "vertex error p90 <= 3 cm");
        GOAL(s->curve_p99 > 0.03, "curve p99 <= 3 cm");
        GOAL(s->curve_max > 0.08, "curve max <= 8 cm");
        MISS(s->curve_p99 > CURVE_P99_BOUND, "curve p99 <= 4.5 cm (regression bound)");
        MISS(s->curve_max > CURVE_MAX_BOUND, "curve max <= 12 cm (regression bound)");
    }
    return missed;
}

/* --check-rows: every scene (corridor and cluttered room included) and
 * sensor at sigma <= 1 cm, mixed pixels included. The targets are 98 %
 * precision and a sparse-wall recall of 90 % at 361+ beams (here from 360: the
 * full circle at 1 degree), 70 % at 181; a miss is printed as "GOAL NOT MET"
 * and fails below the regression bounds, which the code before LC's
 * two-return side test and before blends stopped counting as wall returns
 * fails (precision 94.3 %, sparse-wall recall 82.2 % on the mixed rows). */
#define ROWS_PRECISION_BOUND 0.97
#define ROWS_SPARSE_RECALL_BOUND 0.88
static int check_rows(int which, const sensor_t *sen, const noise_t *nz,
                      const bsf_truth_summary_t *s)
{
    int missed = 0;
    const int wide = sen->beams >= 360u;
    if (!(nz->sigma <= 0.01)) {
        return 0;
    }
    GOAL(s->precision < 0.98, "vertex precision >= 98 %");
    MISS(s->precision < ROWS_PRECISION_BOUND, "vertex precision >= 97 % (regression bound)");
    if (s->visible_sparse > 0u) {
        GOAL(s->recall_sparse < (wide ? 0.90 : 0.70),
             "sparse-wall recall (>= 90 % from 360 beams, >= 70 % at 181)");
        MISS(s->recall_sparse < (wide ? ROWS_SPARSE_RECALL_BOUND : 0.70),
             "sparse-wall recall >= 88 % from 360 beams, >= 70 % at 181 (regression bound)");
    }
    return missed;
}

static int run_datasets(const char *dir)
{
    static const char *const logs[4] = {"intel", "fr079", "fr-clinic", "mit-csail"};
    static float times[1];
    int d;
    printf("\n| dataset | scans | Gamma %% | eta | accuracy mm | bytes/scan "
           "|\n|---|---:|---:|---:|---:|---:|\n");
    for (d = 0; d < 4; ++d) {
        char path[2048];
        carmen_reader_t *rd;
        carmen_scan_t rec;
        bsf_metrics_acc_t macc;
        bsf_metrics_summary_t sum;
        bsf_params_t p = make_params();
        double bytes = 0.0;
        int r;
        snprintf(path, sizeof path, "%s/data/%s.log.gz", dir, logs[d]);
        rd = carmen_open(path, NULL);
        if (rd == NULL) {
            printf("| %s | not found | | | | |\n", logs[d]);
            continue;
        }
        if (bsf_extractor_init(&ex, &p) != BSF_OK ||
            bsf_metrics_acc_init(&macc, times, 0u) != BSF_OK) {
            carmen_close(rd);
            return -1;
        }
        while ((r = carmen_next(rd, &rec)) > 0) {
            bsf_scan_t sc;
            bsf_scan_counts_t c;
            bsf_frame_info_t info;
            size_t len = 0;
            sc.ranges = rec.ranges;
            sc.count = rec.count;
            sc.angle_min = rec.angle_min;
            sc.angle_increment = rec.angle_increment;
            sc.range_min = 0.0f;
            sc.range_max = carmen_valid_range_max(&rec);
            bsf_frame_info_init(&info);
            if (bsf_extract(&ex, &sc, &res) != BSF_OK || bsf_metrics_counts(&res, &c) != BSF_OK ||
                bsf_metrics_acc_add(&macc, &c) != BSF_OK ||
                bsf_frame_encode(&info, &res, NULL, 0u, &len) != BSF_OK) {
                fprintf(stderr, "bench_truth: %s: extraction failed\n", logs[d]);
                carmen_close(rd);
                return -1;
            }
            bytes += (double)len;
        }
        carmen_close(rd);
        if (bsf_metrics_acc_summary(&macc, &sum) != BSF_OK) {
            return -1;
        }
        printf("| %s | %lu | %.2f | %.4f | %.2f | %.1f |\n", logs[d], (unsigned long)sum.n_scans,
               100.0 * (double)sum.retrievability, (double)sum.compactness,
               1000.0 * (double)sum.accuracy, sum.n_scans > 0u ? bytes / (double)sum.n_scans : 0.0);
    }
    return 0;
}

int main(int argc, char **argv)
{
    int quick = 0;
    int check = 0;
    int check_all_rows = 0;
    long n_poses = -1;
    const char *datasets = NULL;
    const char *only_scene = NULL;
    long only_sensor = -1;
    double only_noise = -1.0;
    int missed = 0;
    char oracle_key[64];
    double oracle_reach = 0.0;
    int oracle_reach_set = 0;
    int a;
    int w;
    size_t si;
    size_t ni;
    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[a], "--check") == 0) {
            check = 1;
        } else if (strcmp(argv[a], "--check-rows") == 0) {
            check_all_rows = 1;
        } else if (strcmp(argv[a], "--verbose") == 0) {
            bsf_truth_verbose = 1;
        } else if (strcmp(argv[a], "--paper") == 0) {
            paper_mode = 1;
        } else if (strcmp(argv[a], "--grazing") == 0) {
            grazing_mode = 1;
        } else if (strcmp(argv[a], "--no-grazing") == 0) {
            grazing_mode = 0;
        } else if (strcmp(argv[a], "--evidence") == 0) {
            evidence_mode = 1;
        } else if (strcmp(argv[a], "--no-evidence") == 0) {
            evidence_mode = 0;
        } else if (strcmp(argv[a], "--tails") == 0) {
            tails_mode = 1;
        } else if (strcmp(argv[a], "--no-tails") == 0) {
            tails_mode = 0;
        } else if (strcmp(argv[a], "--fit-passes") == 0 && a + 1 < argc) {
            char *end = NULL;
            fit_passes = strtol(argv[++a], &end, 10);
            if (end == argv[a] || *end != '\0' || fit_passes < 0 || fit_passes > 255) {
                fprintf(stderr, "bench_truth: --fit-passes needs a count in 0..255\n");
                return 2;
            }
        } else if (strcmp(argv[a], "--fit-bin-length") == 0 && a + 1 < argc) {
            char *end = NULL;
            fit_bin_length = strtod(argv[++a], &end);
            if (end == argv[a] || *end != '\0' ||
                !(fit_bin_length >= 0.0 && fit_bin_length <= 1.0)) {
                fprintf(stderr, "bench_truth: --fit-bin-length needs metres in 0..1\n");
                return 2;
            }
        } else if (strcmp(argv[a], "--oracle-reach") == 0 && a + 1 < argc) {
            char *end = NULL;
            oracle_reach = strtod(argv[++a], &end);
            oracle_reach_set = 1;
            if (end == argv[a] || *end != '\0') {
                oracle_reach = -1.0;
            }
        } else if (strcmp(argv[a], "--poses") == 0 && a + 1 < argc) {
            n_poses = strtol(argv[++a], NULL, 10);
        } else if (strcmp(argv[a], "--datasets") == 0 && a + 1 < argc) {
            datasets = argv[++a];
        } else if (strcmp(argv[a], "--scene") == 0 && a + 1 < argc) {
            only_scene = argv[++a];
        } else if (strcmp(argv[a], "--sensor") == 0 && a + 1 < argc) {
            only_sensor = strtol(argv[++a], NULL, 10);
        } else if (strcmp(argv[a], "--noise") == 0 && a + 1 < argc) {
            only_noise = strtod(argv[++a], NULL) / 1000.0;
        } else {
            fprintf(stderr,
                    "usage: %s [--quick] [--check] [--check-rows] [--verbose] [--paper] "
                    "[--[no-]grazing] "
                    "[--[no-]evidence] [--[no-]tails] [--fit-passes K] [--fit-bin-length M] "
                    "[--poses N] [--oracle-reach M] "
                    "[--scene NAME] "
                    "[--sensor BEAMS] [--noise MM] [--datasets SHARED_DIR]\n",
                    argv[0]);
            return 2;
        }
    }
    if (n_poses < 0) {
        n_poses = quick ? 16 : 80;
    }
    if (!(oracle_reach >= 0.0)) {
        fprintf(stderr, "bench_truth: --oracle-reach must be a number of metres >= 0\n");
        return 2;
    }
    /* The oracle's sides reach as far as LC's line fits do, unless told. */
    bsf_truth_oracle_reach =
        oracle_reach > 0.0 ? oracle_reach
                           : (oracle_reach_set ? 0.0 : (double)bsf_lc_params_default().max_side);
    if (getenv("BENCH_TRUTH_ORACLE_LOG") != NULL) {
        bsf_truth_oracle_log = fopen(getenv("BENCH_TRUTH_ORACLE_LOG"), "w");
        if (bsf_truth_oracle_log == NULL) {
            fprintf(stderr, "bench_truth: cannot write %s\n", getenv("BENCH_TRUTH_ORACLE_LOG"));
            return 2;
        }
    }
    if (n_poses < 1) {
        fprintf(stderr, "bench_truth: --poses must be >= 1\n");
        return 2;
    }
    printf("bench_truth: %s configuration%s%s%s, %ld poses per row",
           paper_mode ? "paper-faithful" : "default", grazing_mode ? " with grazing joins" : "",
           evidence_mode ? " with LC's corner evidence test" : "",
           tails_mode ? " with tail returns left off" : "", n_poses);
    if (fit_passes > 0) {
        printf(", at most %ld fit passes per point", fit_passes);
    }
    if (fit_bin_length > 0.0) {
        printf(", fit on bins of at most %g m", fit_bin_length);
    }
    printf("\n");
    print_header();
    for (w = 0; w < N_SCENES; ++w) {
        if (only_scene != NULL && strcmp(only_scene, scene_names[w]) != 0) {
            continue;
        }
        if (quick && only_scene == NULL && w >= N_CHECKED_SCENES) {
            continue;
        }
        for (si = 0; si < N_SENSORS; ++si) {
            if (only_sensor >= 0 && (size_t)only_sensor != sensors[si].beams) {
                continue;
            }
            if (quick && !(sensors[si].beams == 181u || sensors[si].beams == 361u ||
                           sensors[si].beams == 541u)) {
                continue;
            }
            for (ni = 0; ni < N_NOISES; ++ni) {
                bsf_truth_summary_t s;
                long failed = 0;
                if (only_noise >= 0.0 && fabs(only_noise - noises[ni].sigma) > 1e-9) {
                    continue;
                }
                if (quick && !(noises[ni].sigma == 0.01 && !noises[ni].mixed)) {
                    continue;
                }
                snprintf(oracle_key, sizeof oracle_key, "%s %s %s", scene_names[w],
                         sensors[si].name, noises[ni].name);
                bsf_truth_oracle_key = oracle_key;
                if (run_config(w, &sensors[si], &noises[ni], n_poses, &s, &failed) != 0) {
                    return 1;
                }
                print_row(w, &sensors[si], &noises[ni], &s, failed);
                fflush(stdout);
                if (check_all_rows) {
                    missed += check_rows(w, &sensors[si], &noises[ni], &s);
                }
                if (check && w < N_CHECKED_SCENES) {
                    missed += check_targets(w, &sensors[si], &noises[ni], &s);
                    if (failed > 0) {
                        printf("TARGET MISSED: %s %s %s: %ld scans failed\n", scene_names[w],
                               sensors[si].name, noises[ni].name, failed);
                        ++missed;
                    }
                }
            }
        }
    }
    if (datasets != NULL && run_datasets(datasets) != 0) {
        return 1;
    }
    if (bsf_truth_oracle_log != NULL) {
        fclose(bsf_truth_oracle_log);
    }
    if (check || check_all_rows) {
        printf("%d target(s) missed\n", missed);
        return missed > 0 ? 1 : 0;
    }
    return 0;
}
