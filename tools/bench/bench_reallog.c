/* SPDX-License-Identifier: MIT */
/*
 * bench_reallog - how far the sent curves lie from their own points on real
 * logs, where no ground truth exists: for every feature of every scan, the
 * largest distance of one of its points to its curve, and its E_curve.
 *
 *   bench_reallog DATA_DIR [--method M] [--check] [--verbose] [--what-if]
 *
 * reads DATA_DIR/{intel,mit-csail,fr079,fr-clinic}.log.gz whole, extracts as
 * `bsf extract` does (the log's own range limit), and prints per log: scans,
 * features, the p50 / p99 / max of the per-feature largest point-to-curve
 * distance, the same p99 over features whose points lie 10 m or farther on
 * average, and how many features have E_curve above BSF_REALLOG_E_MAX and
 * above BSF_REALLOG_E_TARGET. --check exits 1 when a log misses the targets
 * (p99 <= BSF_REALLOG_E_TARGET, no feature above BSF_REALLOG_E_MAX).
 * --verbose prints every feature over the target; --what-if what the p99
 * would be, and how many points would leave features, were the features
 * whose E_curve exceeds 0.2, 0.15, 0.1 or 0.075 m not sent as curves.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bsf/bsf.h"
#include "carmen.h"
#include "carmen_bsf.h"

/** Target for a feature's largest point-to-curve distance (p99), metres. */
#define BSF_REALLOG_E_TARGET 0.25
/** No feature whose E_curve exceeds this may be sent as a curve, metres. */
#define BSF_REALLOG_E_MAX 0.75
/** A feature is "far" when its points lie this far on average, metres. */
#define BSF_REALLOG_FAR 10.0
/** Curve samples per span for the point-to-curve distance. */
#define SAMPLES_PER_SPAN 32
#define MAX_SAMPLES (SAMPLES_PER_SPAN * BSF_MAX_CTRL_PER_FEATURE + 1)
/** Histogram: 1 mm bins up to 5 m. */
#define HBIN 0.001
#define HBINS 5000

typedef struct {
    unsigned long hist[HBINS + 1];
    unsigned long n;
    double max;
} hist_t;

static bsf_extractor_t ex;
static bsf_result_t res;
static hist_t h_all;
static hist_t h_far;
/* What-if: the p99 and the points lost were features with E_curve above
 * each of these bounds not sent as curves (--what-if). */
#define N_BOUNDS 4
static const double e_bounds[N_BOUNDS] = {0.20, 0.15, 0.10, 0.075};
static hist_t h_kept[N_BOUNDS];
static unsigned long pts_lost[N_BOUNDS];
static int verbose = 0;
static int what_if = 0;

static void hist_add(hist_t *h, double d)
{
    long b = (long)(d / HBIN);
    b = b < 0 ? 0 : (b > HBINS ? HBINS : b);
    h->hist[b]++;
    h->n++;
    h->max = d > h->max ? d : h->max;
}

static double hist_q(const hist_t *h, double q)
{
    unsigned long want;
    unsigned long seen = 0;
    long b;
    if (h->n == 0u) {
        return 0.0;
    }
    want = (unsigned long)ceil(q * (double)h->n);
    want = want < 1u ? 1u : want;
    for (b = 0; b <= HBINS; ++b) {
        seen += h->hist[b];
        if (seen >= want) {
            return b == HBINS ? h->max : (double)(b + 1) * HBIN;
        }
    }
    return h->max;
}

/* Distance from p to the polyline through s[0..n). */
static double dist_to_polyline(bsf_point_t p, const bsf_point_t *s, size_t n)
{
    double best = 1e300;
    size_t i;
    for (i = 0; i + 1u < n; ++i) {
        const double ax = (double)s[i].x;
        const double ay = (double)s[i].y;
        const double dx = (double)s[i + 1u].x - ax;
        const double dy = (double)s[i + 1u].y - ay;
        const double l2 = dx * dx + dy * dy;
        double t = l2 > 0.0 ? (((double)p.x - ax) * dx + ((double)p.y - ay) * dy) / l2 : 0.0;
        double d;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
        d = hypot((double)p.x - (ax + t * dx), (double)p.y - (ay + t * dy));
        best = d < best ? d : best;
    }
    return best;
}

/* Largest distance of feature f's points to its curve; *mean_range gets
 * their mean range. Reads the segment labels bsf_extract leaves behind. */
static double feature_max_dist(const bsf_feature_t *f, double *mean_range)
{
    static bsf_point_t samples[MAX_SAMPLES];
    const size_t spans = (size_t)f->n_ctrl - 2u;
    const size_t ns = SAMPLES_PER_SPAN * spans + 1u;
    double worst = 0.0;
    double sum_r = 0.0;
    size_t n_pts = 0;
    size_t worst_at = 0;
    size_t j;
    size_t b;
    for (j = 0; j < ns; ++j) {
        if (bsf_bspline_eval(&res.ctrl[f->ctrl_first], f->n_ctrl,
                             (float)((double)j / (double)(ns - 1u)), &samples[j], NULL,
                             NULL) != BSF_OK) {
            samples[j] = samples[j > 0u ? j - 1u : 0u];
        }
    }
    for (b = f->first_beam;; b = b + 1u < ex.points.count ? b + 1u : 0u) {
        if (ex.points.valid[b] && ex.scratch.seg.label[b] == f->first_beam) {
            const double d = dist_to_polyline(ex.points.pt[b], samples, ns);
            if (d > worst) {
                worst = d;
                worst_at = n_pts;
            }
            sum_r += (double)ex.points.range[b];
            ++n_pts;
        }
        if (b == f->last_beam) {
            break;
        }
    }
    *mean_range = n_pts > 0u ? sum_r / (double)n_pts : 0.0;
    if (verbose && worst > BSF_REALLOG_E_TARGET) {
        size_t nv = 0;
        for (j = 0; j < f->n_ctrl; ++j) {
            nv += res.ctrl_is_vertex[f->ctrl_first + j];
        }
        printf("far point %.3f m: point %lu of %lu, beams %u-%u, mean range %.1f m, %u ctrl "
               "(%lu vertex slots), E_curve %.3f m\n",
               worst, (unsigned long)worst_at, (unsigned long)n_pts, f->first_beam, f->last_beam,
               *mean_range, f->n_ctrl, (unsigned long)nv, (double)f->e_curve);
    }
    return worst;
}

int main(int argc, char **argv)
{
    static const char *const logs[4] = {"intel", "mit-csail", "fr079", "fr-clinic"};
    bsf_method_t method = BSF_METHOD_DEFAULT;
    const char *dir = NULL;
    int check = 0;
    int missed = 0;
    int a;
    int d;
    for (a = 1; a < argc; ++a) {
        if (strcmp(argv[a], "--method") == 0 && a + 1 < argc) {
            method = bsf_method_from_name(argv[++a]);
            if (method == BSF_METHOD_COUNT) {
                fprintf(stderr, "bench_reallog: unknown method '%s'\n", argv[a]);
                return 2;
            }
        } else if (strcmp(argv[a], "--check") == 0) {
            check = 1;
        } else if (strcmp(argv[a], "--what-if") == 0) {
            what_if = 1;
        } else if (strcmp(argv[a], "--verbose") == 0) {
            verbose = 1; /* every feature over the target */
        } else if (argv[a][0] != '-' && dir == NULL) {
            dir = argv[a];
        } else {
            fprintf(stderr, "usage: %s DATA_DIR [--method M] [--check] [--verbose] [--what-if]\n",
                    argv[0]);
            return 2;
        }
    }
    if (dir == NULL) {
        fprintf(stderr, "usage: %s DATA_DIR [--method M] [--check] [--verbose] [--what-if]\n",
                argv[0]);
        return 2;
    }
    printf("bench_reallog: %s, per feature the largest point-to-curve distance\n",
           bsf_method_name(method));
    printf(
        "| log | scans | features | max dist p50 / p99 / max m | far (>= 10 m) features | far p99 "
        "m | E_curve > %.2f m | E_curve > %.2f m |\n|---|---:|---:|---|---:|---:|---:|---:|\n",
        BSF_REALLOG_E_MAX, BSF_REALLOG_E_TARGET);
    for (d = 0; d < 4; ++d) {
        char path[4096];
        carmen_reader_t *rd;
        carmen_scan_t rec;
        bsf_params_t p = bsf_params_default(method);
        unsigned long scans = 0;
        unsigned long over_max = 0;
        unsigned long over_target = 0;
        unsigned long n_in = 0;
        int r;
        snprintf(path, sizeof path, "%s/%s.log.gz", dir, logs[d]);
        rd = carmen_open(path, NULL);
        if (rd == NULL) {
            fprintf(stderr, "bench_reallog: cannot open %s\n", path);
            return 1;
        }
        if (bsf_extractor_init(&ex, &p) != BSF_OK) {
            fprintf(stderr, "bench_reallog: extractor init failed\n");
            carmen_close(rd);
            return 1;
        }
        memset(&h_all, 0, sizeof h_all);
        memset(&h_far, 0, sizeof h_far);
        memset(h_kept, 0, sizeof h_kept);
        memset(pts_lost, 0, sizeof pts_lost);
        while ((r = carmen_next(rd, &rec)) > 0) {
            const bsf_scan_t sc = scan_of_record(&rec, 0.0);
            size_t f;
            ++scans;
            if (bsf_extract(&ex, &sc, &res) != BSF_OK) {
                continue; /* counted by bsf extract; a failed scan sends nothing */
            }
            n_in += res.stats.n_in_features;
            for (f = 0; f < res.n_features; ++f) {
                double mean_r = 0.0;
                const double md = feature_max_dist(&res.features[f], &mean_r);
                hist_add(&h_all, md);
                if (mean_r >= BSF_REALLOG_FAR) {
                    hist_add(&h_far, md);
                }
                for (a = 0; a < N_BOUNDS; ++a) {
                    if ((double)res.features[f].e_curve > e_bounds[a]) {
                        pts_lost[a] += res.features[f].n_points;
                    } else {
                        hist_add(&h_kept[a], md);
                    }
                }
                over_max += (double)res.features[f].e_curve > BSF_REALLOG_E_MAX;
                over_target += (double)res.features[f].e_curve > BSF_REALLOG_E_TARGET;
            }
        }
        carmen_close(rd);
        if (r < 0) {
            fprintf(stderr, "bench_reallog: %s: read error\n", path);
            return 1;
        }
        printf("| %s | %lu | %lu | %.3f / %.3f / %.3f | %lu | %.3f | %lu | %lu |\n", logs[d], scans,
               h_all.n, hist_q(&h_all, 0.5), hist_q(&h_all, 0.99), h_all.max, h_far.n,
               hist_q(&h_far, 0.99), over_max, over_target);
        if (what_if) {
            for (a = 0; a < N_BOUNDS; ++a) {
                printf("  what if E_curve > %.3f m were not sent: p99 %.3f m, %lu points (%.2f %% "
                       "of the points in features) out of features\n",
                       e_bounds[a], hist_q(&h_kept[a], 0.99), pts_lost[a],
                       n_in > 0u ? 100.0 * (double)pts_lost[a] / (double)n_in : 0.0);
            }
        }
        fflush(stdout);
        if (hist_q(&h_all, 0.99) > BSF_REALLOG_E_TARGET || over_max > 0u) {
            ++missed;
        }
    }
    if (check) {
        printf("%d log(s) miss the targets\n", missed);
        return missed > 0 ? 1 : 0;
    }
    return 0;
}
