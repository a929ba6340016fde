/* SPDX-License-Identifier: MIT */
/*
 * bench_m4_icount - instructions per scan of bsf_extract on the Cortex-M4F,
 * counted under QEMU (mps2-an386) with -icount, for every method, on a fixed
 * set of scans: synthetic scenes (tools/bsf_scene.h) and, when the build found
 * ../shared/data/intel.log.gz, real Intel scans compiled in at build time
 * (tools/gen_scan_array.py; BSF_BENCH_HAVE_LOG).
 *
 * Counting: with -icount shift=S every guest instruction advances virtual
 * time by 2^S ns, and SysTick (25 MHz on this board) counts that time, so
 * delta ticks / (2^S * 0.025) = instructions executed (25.6 at S=10, 3.2 at
 * S=7). The ratio is not assumed: a calibration loop of known length measures
 * it first. SysTick is 24 bits wide (655 k instructions at shift=10); its
 * interrupt counts the wraps, so long scans are counted exactly too (the
 * handler adds about 10 instructions per 655 k). These are instruction counts, not cycles:
 * QEMU models no pipeline, flash wait states or FPU latencies.
 *
 * Also the stack high-water mark of the calls (painted stack, bytes below
 * the caller's frame; libm included, unlike tools/stack_report.py).
 *
 * Sources (each printed under a [tag] line): synthetic rooms, a cluttered
 * room, the demo office from 8 poses checked to stand in free space (1081
 * beams over 270 degrees), the adversarial scans of tools/bench/bench_scenes.h
 * (a sensor against a pillar, pure clutter; reported apart) and the Intel
 * scans. Built with BSF_BENCH_BIG (bench_m4_icount_big, a library with room
 * for 4096 beams) it runs the office with 3200 beams over 360 degrees and the
 * 4000-beam long wall instead.
 *
 * On the office, the adversarial and the Intel scans the default method runs
 * a second time with the fit's work bounded (bsf_params_t.fit_passes
 * BENCH_FIT_PASSES, the row "lc-sved-pdm/fK"): what a firmware that must
 * keep up with a dense LIDAR in its worst scan pays; and a third time with
 * the fit also on bin means (bsf_params_t.fit_bin_length BENCH_FIT_BIN_CM
 * centimetres, the row "lc-sved-pdm/fKbC", where the build has them).
 *
 * Prints numbers, judges none; fails only if an extraction fails or a pose
 * is not in free space. Run:
 *   ctest --test-dir build-m4 -R bench_m4_icount -V
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_scenes.h"
#include "bsf/bsf.h"
#include "m4_counter.h"
#include "bsf_scene.h"

#ifdef BSF_BENCH_HAVE_LOG
#include "bench_log_scans.h"
#endif

#define MAX_SCANS 4096
/* The bound on the fit's work of the extra default-method row. */
#define BENCH_FIT_PASSES 4u
#define BENCH_FIT_BIN_CM 3u
#define N_SYNTH_SCENES 3
#define N_SYNTH_POSES 2

static bsf_extractor_t g_ex;
static bsf_result_t g_res;

/* Per-scan results of one method on one set. */
static uint32_t g_whole[MAX_SCANS];
static uint32_t g_stage[BSF_STAGE_COUNT][MAX_SCANS];
static uint32_t g_sorted[MAX_SCANS];
static uint32_t g_encode[MAX_SCANS];
static uint8_t g_frame[BSF_FRAME_MAX_SIZE];

static uint32_t g_stack_bytes;

/* SysTick counts down through 24 bits; its interrupt counts the wraps, so a
 * count of any length is exact. The interrupt runs through a vector table of
 * our own in RAM (VTOR), leaving the shared startup code alone. */

/* Stack high-water mark: paint the free stack below the caller's frame,
 * run, then find the deepest word overwritten. Counts everything bsf_extract
 * uses, libm included. */

typedef struct {
    const bsf_scan_t *(*get)(size_t i, bsf_scan_t *tmp);
    size_t n;
    const char *tag;  /* short name tools/scripts/perf_table.py looks for */
    const char *name; /* what the scans are */
    unsigned methods; /* bit m: run bsf_method_t m */
    int bounded;      /* 1: the default method again with fit_passes BENCH_FIT_PASSES */
} scan_source_t;

#define ALL_METHODS ((1u << BSF_METHOD_COUNT) - 1u)
/* BID is the paper's slow baseline (quadratic corner stage): left out of the
 * long scans, where it would take minutes under QEMU and bounds nothing. */
#define NO_BID (ALL_METHODS & ~(1u << BSF_METHOD_BID_SVED_PDM))

/* Measure every scan of a source with one method (its fit bounded by
 * fit_passes, 0: not; on bins of bin_cm centimetres, 0: not); print one
 * line. */
static int run_method(const scan_source_t *src, bsf_method_t method, unsigned fit_passes,
                      unsigned bin_cm)
{
    bsf_params_t p = bsf_params_default(method);
    char label[32];
    size_t i;
    unsigned long feats = 0;
    double mean = 0.0;
    uint32_t max_whole, med_whole, s;

    p.fit_passes = (uint8_t)fit_passes;
    p.fit_bin_length = 0.01f * (float)bin_cm;
    if (bin_cm != 0u) {
        snprintf(label, sizeof label, "%s/f%ub%u", bsf_method_name(method), fit_passes, bin_cm);
    } else if (fit_passes != 0u) {
        snprintf(label, sizeof label, "%s/f%u", bsf_method_name(method), fit_passes);
    } else {
        snprintf(label, sizeof label, "%s", bsf_method_name(method));
    }
    if (bsf_extractor_init(&g_ex, &p) != BSF_OK) {
        printf("  %-15s SKIPPED: not available in this build\n", label);
        return 0;
    }
    uint32_t *painted = m4_stack_paint();
    uint32_t stack_top_used;
    /* What the measuring itself leaves below the paint top (subtracted). */
    stack_top_used = m4_stack_used(painted);
    for (i = 0; i < src->n; ++i) {
        bsf_scan_t tmp;
        const bsf_scan_t *scan = src->get(i, &tmp);
        uint32_t t0, t1;
        bsf_status_t st;

        /* Whole call, no clock hook: what firmware without timing pays. */
        t0 = m4_ticks();
        st = bsf_extract(&g_ex, scan, &g_res);
        t1 = m4_ticks();
        if (st < 0) { /* BSF_OK_CUT is a result like any other */
            printf("  %s: scan %u: %s\n", label, (unsigned)i, bsf_status_str(st));
            return 1;
        }
        g_whole[i] = m4_instr(t1 - t0);
        mean += (double)g_whole[i];
        feats += g_res.stats.n_features;
    }
    g_stack_bytes = m4_stack_used(painted) - stack_top_used;
    /* Per-stage split with the hook (a few instructions more per stage). */
    p.clock = m4_clock_hook;
    p.clock_user = NULL;
    p.clock_hz = 1000000000u;
    if (bsf_extractor_init(&g_ex, &p) != BSF_OK) {
        return 1;
    }
    for (i = 0; i < src->n; ++i) {
        bsf_scan_t tmp;
        const bsf_scan_t *scan = src->get(i, &tmp);
        bsf_frame_info_t info;
        size_t len;
        uint32_t t0;
        if (bsf_extract(&g_ex, scan, &g_res) < 0) {
            return 1;
        }
        /* The scan's frame, as firmware sends it after extracting. */
        bsf_frame_info_init(&info);
        info.seq = (uint32_t)i;
        t0 = m4_ticks();
        if (bsf_frame_encode(&info, &g_res, g_frame, sizeof g_frame, &len) != BSF_OK) {
            printf("  %s: scan %u: frame not encoded\n", label, (unsigned)i);
            return 1;
        }
        g_encode[i] = m4_instr(m4_ticks() - t0);
        for (s = 0; s < BSF_STAGE_COUNT; ++s) {
            g_stage[s][i] = m4_instr(g_res.stats.stage_ns[s]);
        }
    }
    med_whole = m4_median(g_whole, src->n, g_sorted, &max_whole);
    printf("  %-15s %9lu %9lu %9lu |", label, (unsigned long)med_whole,
           (unsigned long)(mean / (double)src->n + 0.5), (unsigned long)max_whole);
    for (s = 0; s < BSF_STAGE_COUNT; ++s) {
        printf(" %8lu", (unsigned long)m4_median(g_stage[s], src->n, g_sorted, NULL));
    }
    printf(" | %8lu", (unsigned long)m4_median(g_encode, src->n, g_sorted, NULL));
    printf(" | %5.2f | %5lu\n", (double)feats / (double)src->n, (unsigned long)g_stack_bytes);
    return 0;
}

static int run_source(const scan_source_t *src)
{
    int m, rc = 0;
    printf("\n[%s] %s: %u scans\n", src->tag, src->name, (unsigned)src->n);
    printf("  %-15s %9s %9s %9s | %8s %8s %8s %8s | %8s | %5s | %5s\n", "instructions", "median",
           "mean", "max", "points", "corners", "segment", "fit", "encode", "feat", "stack");
    printf("  %-15s %29s | %35s | %8s |\n", "", "whole bsf_extract per scan",
           "median per stage (with clock hook)", "frame");
    for (m = 0; m < BSF_METHOD_COUNT; ++m) {
        if ((src->methods & (1u << m)) != 0u) {
            rc |= run_method(src, (bsf_method_t)m, 0u, 0u);
        }
    }
    if (src->bounded && (src->methods & (1u << BSF_METHOD_DEFAULT)) != 0u) {
        rc |= run_method(src, BSF_METHOD_DEFAULT, BENCH_FIT_PASSES, 0u);
        rc |= run_method(src, BSF_METHOD_DEFAULT, BENCH_FIT_PASSES, BENCH_FIT_BIN_CM);
    }
    return rc;
}

/* The scene the synthetic scans are cast in (large: BSF_SCENE_MAX_SHAPES 1024). */
static bsf_scene_t g_clutter_scene;

#ifndef BSF_BENCH_BIG
/* ---- synthetic scenes ------------------------------------------------------ */

static float g_synth_ranges[N_SYNTH_SCENES * N_SYNTH_POSES * 2][361];
static bsf_scan_t g_synth_scans[N_SYNTH_SCENES * N_SYNTH_POSES * 2];

static const bsf_scan_t *get_synth(size_t i, bsf_scan_t *tmp)
{
    (void)tmp;
    return &g_synth_scans[i];
}

static int make_synthetic(size_t *n_out)
{
    bsf_scene_t scene;
    bsf_scene_rng_t rng;
    size_t sc, pose, res, n = 0;
    bsf_scene_rng_seed(&rng, 4242u);
    for (sc = 0; sc < N_SYNTH_SCENES; ++sc) {
        bsf_status_t st;
        bsf_scene_init(&scene);
        if (sc == 0u) {
            st = bsf_scene_add_rect_room(&scene, -3.0, -2.0, 5.0, 4.0);
        } else if (sc == 1u) {
            st = bsf_scene_add_l_room(&scene, -4.0, -3.0, 12.0, 8.0, 5.0, 3.0);
        } else {
            st = bsf_scene_add_room_with_pillar(&scene, -5.0, -4.0, 6.0, 5.0, 1.5, 1.0, 0.4);
        }
        if (st != BSF_OK) {
            return 1;
        }
        for (pose = 0; pose < N_SYNTH_POSES; ++pose) {
            for (res = 0; res < 2u; ++res) {
                const size_t beams = res == 0u ? 180u : 361u;
                bsf_lidar_t l =
                    bsf_lidar_default(-1.0 + 0.5 * (double)pose, -0.5 + 0.3 * (double)pose,
                                      0.7 * (double)pose, beams, 3.14159265358979);
                l.noise_sigma = 0.01;
                if (bsf_scene_scan(&scene, &l, &rng, g_synth_ranges[n], NULL, 361u) != BSF_OK) {
                    return 1;
                }
                g_synth_scans[n] = bsf_scene_lidar_scan(&l, g_synth_ranges[n]);
                ++n;
            }
        }
    }
    *n_out = n;
    return 0;
}

/* ---- cluttered room, 1081 beams: keypoint-cap cuts (docs/DESIGN.md) ------- */

#define N_CLUTTER_SCANS 4

static float g_clutter_ranges[N_CLUTTER_SCANS][1081];
static bsf_scan_t g_clutter_scans[N_CLUTTER_SCANS];

static const bsf_scan_t *get_clutter(size_t i, bsf_scan_t *tmp)
{
    (void)tmp;
    return &g_clutter_scans[i];
}

/* The zig-zag shelving room of test_caps.c: most seeds exceed 64 keypoints. */
static int make_clutter(size_t *n_out)
{
    size_t k;
    if (BSF_MAX_POINTS < 1081) {
        return 1;
    }
    for (k = 0; k < N_CLUTTER_SCANS; ++k) {
        bsf_scene_clutter_t c;
        bsf_scene_rng_t rng;
        bsf_lidar_t l = bsf_lidar_default(0.0, 0.0, 0.3, 1081u, 4.71238898038469);
        memset(&c, 0, sizeof c);
        c.half_w = 8.0;
        c.half_h = 4.0;
        c.n_teeth = 80u;
        c.tooth_depth = 0.1;
        c.n_posts = 20u;
        c.n_boxes = 5u;
        c.clear = 0.8;
        bsf_scene_init(&g_clutter_scene);
        bsf_scene_rng_seed(&rng, 1u + k);
        l.noise_sigma = 0.01;
        if (bsf_scene_add_clutter_room(&g_clutter_scene, &c, &rng) != BSF_OK ||
            bsf_scene_scan(&g_clutter_scene, &l, &rng, g_clutter_ranges[k], NULL, 1081u) !=
                BSF_OK) {
            return 1;
        }
        g_clutter_scans[k] = bsf_scene_lidar_scan(&l, g_clutter_ranges[k]);
    }
    *n_out = N_CLUTTER_SCANS;
    return 0;
}

#endif /* !BSF_BENCH_BIG */

/* ---- the demo office and the adversarial scans (bench_scenes.h) ---------- */

#ifdef BSF_BENCH_BIG
#define OFFICE_BEAMS 3200u
#define OFFICE_FOV360 1
#else
#define OFFICE_BEAMS 1081u
#define OFFICE_FOV360 0
#endif
#define ADV_MAX_BEAMS 4000u

static float g_office_ranges[BENCH_OFFICE_POSES][OFFICE_BEAMS];
static bsf_scan_t g_office_scans[BENCH_OFFICE_POSES];
static float g_adv_ranges[BENCH_ADV_SCANS][ADV_MAX_BEAMS];
static bsf_scan_t g_adv_scans[BENCH_ADV_SCANS];

static const bsf_scan_t *get_office(size_t i, bsf_scan_t *tmp)
{
    (void)tmp;
    return &g_office_scans[i];
}

static const bsf_scan_t *get_adv(size_t i, bsf_scan_t *tmp)
{
    (void)tmp;
    return &g_adv_scans[i];
}

/* The demo office from poses checked to stand in free space: 1081 beams
 * over 270 degrees, or (big build) 3200 beams over 360 degrees. */
static int make_office(size_t *n_out)
{
    bsf_scene_pose_t poses[BENCH_OFFICE_POSES];
    bsf_scene_rng_t rng;
    size_t i;
    int shape;
    int bad;
    if (BSF_MAX_POINTS < (int)OFFICE_BEAMS) {
        return 1;
    }
    bsf_scene_demo_office(&g_clutter_scene);
    for (i = 0; i < BENCH_OFFICE_POSES; ++i) {
        poses[i] = bench_office_pose(i);
    }
    bad = bench_poses_check(&g_clutter_scene, poses, BENCH_OFFICE_POSES, BENCH_POSE_CLEARANCE,
                            &shape);
    if (bad >= 0) {
        printf("office pose %d is not in free space (shape %d)\n", bad, shape);
        return 2;
    }
    bsf_scene_rng_seed(&rng, 77u);
    for (i = 0; i < BENCH_OFFICE_POSES; ++i) {
        bsf_lidar_t l = bsf_lidar_default(poses[i].x, poses[i].y, poses[i].theta, OFFICE_BEAMS,
                                          OFFICE_FOV360 ? 6.28318530717959 : 4.71238898038469);
        if (OFFICE_FOV360) {
            l.angle_min = -3.14159265358979;
            l.angle_increment = 6.28318530717959 / (double)OFFICE_BEAMS;
        }
        l.noise_sigma = 0.01;
        if (bsf_scene_scan(&g_clutter_scene, &l, &rng, g_office_ranges[i], NULL, OFFICE_BEAMS) !=
            BSF_OK) {
            return 2;
        }
        g_office_scans[i] = bsf_scene_lidar_scan(&l, g_office_ranges[i]);
    }
    *n_out = BENCH_OFFICE_POSES;
    return 0;
}

/* One adversarial kind: 1 when it does not fit this build, 2 on a failure. */
static int make_adv(int kind, size_t *n_out)
{
    size_t k;
    if (bench_adv_beams(kind) > (size_t)BSF_MAX_POINTS || bench_adv_beams(kind) > ADV_MAX_BEAMS) {
        return 1;
    }
    for (k = 0; k < BENCH_ADV_SCANS; ++k) {
        if (bench_adv_scan(kind, k, g_adv_ranges[k], ADV_MAX_BEAMS, &g_adv_scans[k]) != BSF_OK) {
            return 2;
        }
    }
    *n_out = BENCH_ADV_SCANS;
    return 0;
}

static int run_office_and_adversarial(void)
{
    static char name[96];
    scan_source_t src;
    int rc = 0;
    int kind;
    int st = make_office(&src.n);
    if (st == 0) {
        src.get = get_office;
        src.tag = OFFICE_FOV360 ? "office-3200" : "office-1081";
        src.name = OFFICE_FOV360 ? "demo office, 8 free poses, 3200 beams over 360 deg, sigma 1 cm"
                                 : "demo office, 8 free poses, 1081 beams over 270 deg, sigma 1 cm";
        src.methods = NO_BID;
        src.bounded = 1;
        rc |= run_source(&src);
    } else if (st == 2) {
        printf("office scans: setup failed\n");
        return 1;
    }
    for (kind = 0; kind < BENCH_ADV_COUNT; ++kind) {
#ifdef BSF_BENCH_BIG
        if (bench_adv_beams(kind) <= 1081u) {
            continue; /* run by bench_m4_icount, with the default caps */
        }
#endif
        st = make_adv(kind, &src.n);
        if (st == 1) {
            printf("\n[adv-%s] SKIPPED: %u beams do not fit this build\n", bench_adv_name(kind),
                   (unsigned)bench_adv_beams(kind));
            continue;
        }
        if (st != 0) {
            printf("adversarial %s: setup failed\n", bench_adv_name(kind));
            return 1;
        }
        snprintf(name, sizeof name, "adversarial (worst case, reported apart): %s, %u beams",
                 bench_adv_name(kind), (unsigned)bench_adv_beams(kind));
        src.get = get_adv;
        src.tag = kind == BENCH_ADV_PILLAR    ? "adv-pillar"
                  : kind == BENCH_ADV_CLUTTER ? "adv-clutter"
                                              : "adv-long-wall";
        src.name = name;
        src.methods = NO_BID;
        src.bounded = 1;
        rc |= run_source(&src);
    }
    return rc;
}

#ifdef BSF_BENCH_HAVE_LOG
static const bsf_scan_t *get_log(size_t i, bsf_scan_t *tmp)
{
    const bench_log_scan_t *s = &bench_log_scans[i];
    tmp->ranges = &bench_log_ranges[s->first];
    tmp->count = s->count;
    tmp->angle_min = s->angle_min;
    tmp->angle_increment = s->angle_increment;
    tmp->range_min = 0.0f;
    tmp->range_max = s->range_max;
    return tmp;
}
#endif

int main(void)
{
#ifndef BSF_BENCH_BIG
    scan_source_t src;
#endif
    int rc = 0;

    const double ticks_per_instr = m4_counter_start();
    printf("bench_m4_icount: Cortex-M4F under QEMU -icount; %.4f SysTick ticks per "
           "instruction (calibrated; 25.6 expected at shift=10)\n",
           ticks_per_instr);
    printf("counts are instructions executed, not cycles; BSF_MAX_POINTS %d\n", BSF_MAX_POINTS);
    if (ticks_per_instr < 0.5) {
        printf("no usable instruction clock (run QEMU with -icount shift=10)\n");
        return 1;
    }

#ifndef BSF_BENCH_BIG
    if (make_synthetic(&src.n) != 0) {
        printf("synthetic scene setup failed\n");
        return 1;
    }
    src.get = get_synth;
    src.tag = "synthetic";
    src.name = "rect room, L-room, room with pillar; 2 poses; 180 and 361 beams over "
               "180 deg; sigma 1 cm";
    src.methods = ALL_METHODS;
    src.bounded = 0;
    rc |= run_source(&src);

    if (make_clutter(&src.n) == 0) {
        src.get = get_clutter;
        src.tag = "clutter-room";
        src.name = "1081 beams over 270 deg, zig-zag shelves, posts, boxes (some scans "
                   "cut by the keypoint cap)";
        src.methods = ALL_METHODS;
        src.bounded = 0;
        rc |= run_source(&src);
    } else {
        printf("\nSKIPPED: clutter scans (BSF_MAX_POINTS < 1081 or scene too small)\n");
    }
#endif

    rc |= run_office_and_adversarial();

#ifndef BSF_BENCH_BIG
#ifdef BSF_BENCH_HAVE_LOG
    src.get = get_log;
    src.n = bench_log_n_scans < MAX_SCANS ? bench_log_n_scans : MAX_SCANS;
    src.tag = "intel";
    src.name = bench_log_description;
    src.methods = ALL_METHODS;
    src.bounded = 1;
    rc |= run_source(&src);
#else
    printf("\nSKIPPED: intel.log.gz not found at build time: no real scans compiled in\n");
#endif
#endif
    return rc;
}
