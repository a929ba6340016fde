/* SPDX-License-Identifier: MIT */
/*
 * bench_m4_map - instructions per scan of bsf_map_fuse (and of bsf_map_encode)
 * on the Cortex-M4F, counted under QEMU (mps2-an386) with -icount, over every
 * scan of the SLAM-corrected Intel log (../shared/data/alt/intel-corrected.log.gz,
 * compiled in at build time by tools/scripts/gen_scan_array.py --with-poses)
 * with its poses: each scan is extracted (not counted), fused into one map at
 * the default caps, and its changes encoded, as a robot does.
 *
 * Counting is bench_m4_icount's: with -icount shift=S each instruction
 * advances virtual time by 2^S ns, SysTick (25 MHz) counts that time, a
 * calibration loop of known length gives ticks per instruction, and the
 * SysTick interrupt counts the 24-bit wraps. Instructions, not cycles.
 *
 * Prints numbers (median, p90, max per scan; the map's RAM); fails only when
 * an extraction, a fuse or an encode fails. Run:
 *   ctest --test-dir build-m4 -R bench_m4_map -V
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_log_scans.h"
#include "bsf/bsf.h"

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYST_MASK 0x00FFFFFFu
#define SCB_ICSR (*(volatile uint32_t *)0xE000ED04u)
#define SCB_VTOR (*(volatile uint32_t *)0xE000ED08u)
#define ICSR_PENDSTSET (1u << 26)
#define N_VECTORS 16u
#define MAX_SCANS 1024

static bsf_extractor_t g_ex;
static bsf_result_t g_res;
static bsf_map_t g_map;
static uint8_t g_frame[BSF_MAP_FRAME_MAX_SIZE];
static uint32_t g_fuse[MAX_SCANS];
static uint32_t g_encode[MAX_SCANS];
static uint32_t g_sorted[MAX_SCANS];
static double g_ticks_per_instr;

typedef void (*vector_t)(void);
static vector_t g_vectors[N_VECTORS] __attribute__((aligned(128)));
static volatile uint32_t g_wraps;

static void systick_isr(void)
{
    ++g_wraps;
}

static void systick_start(void)
{
    const vector_t *boot = (const vector_t *)(uintptr_t)SCB_VTOR;
    uint32_t i;
    for (i = 0; i < N_VECTORS; ++i) {
        g_vectors[i] = boot[i];
    }
    g_vectors[15] = systick_isr;
    SCB_VTOR = (uint32_t)(uintptr_t)g_vectors;
    __asm volatile("dsb\n\tisb" ::: "memory");
    g_wraps = 0u;
    SYST_RVR = SYST_MASK;
    SYST_CVR = 0u;
    SYST_CSR = 7u;
}

static uint32_t ticks_now(void)
{
    uint32_t w, v, pend;
    do {
        w = g_wraps;
        v = SYST_CVR & SYST_MASK;
        pend = SCB_ICSR & ICSR_PENDSTSET;
    } while (w != g_wraps);
    if (pend != 0u && v > SYST_MASK / 2u) {
        ++w;
    }
    return (w << 24) + (SYST_MASK - v);
}

/* Exactly 2 instructions per iteration (subs, bne). */
static void spin(uint32_t n)
{
    __asm volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
}

static void calibrate(void)
{
    uint32_t t0 = ticks_now(), a, b;
    spin(100000u);
    a = ticks_now() - t0;
    t0 = ticks_now();
    spin(300000u);
    b = ticks_now() - t0;
    g_ticks_per_instr = (double)(b - a) / 400000.0;
}

static uint32_t to_instr(uint32_t ticks)
{
    return (uint32_t)((double)ticks / g_ticks_per_instr + 0.5);
}

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static void print_dist(const char *what, const uint32_t *v, size_t n)
{
    memcpy(g_sorted, v, n * sizeof *v);
    qsort(g_sorted, n, sizeof *g_sorted, cmp_u32);
    printf("%-26s median %8lu  p90 %8lu  max %8lu instructions\n", what,
           (unsigned long)g_sorted[n / 2u], (unsigned long)g_sorted[(n * 9u) / 10u],
           (unsigned long)g_sorted[n - 1u]);
}

int main(void)
{
    const bsf_params_t p = bsf_params_default(BSF_METHOD_DEFAULT);
    const size_t n = bench_log_n_scans < MAX_SCANS ? bench_log_n_scans : MAX_SCANS;
    uint32_t map_bytes = 0;
    size_t k;
    systick_start();
    calibrate();
    printf("bench_m4_map: Cortex-M4F under QEMU -icount; %.4f SysTick ticks per instruction\n",
           g_ticks_per_instr);
    if (g_ticks_per_instr < 0.5) {
        printf("no usable instruction clock (run QEMU with -icount shift=10)\n");
        return 1;
    }
    if (bsf_extractor_init(&g_ex, &p) != BSF_OK || bsf_map_init(&g_map, NULL) != BSF_OK) {
        printf("init failed\n");
        return 1;
    }
    printf("%s; lc-sved-pdm; map caps %d features, %d control points; sizeof(bsf_map_t) %lu "
           "bytes\n",
           bench_log_description, BSF_MAP_MAX_FEATURES, BSF_MAP_MAX_CTRL,
           (unsigned long)sizeof(bsf_map_t));
    for (k = 0; k < n; ++k) {
        const bench_log_scan_t *s = &bench_log_scans[k];
        bsf_scan_t sc;
        bsf_pose_t pose;
        uint32_t t0, t1, t2;
        int fused;
        bsf_status_t st;
        size_t len = 0;
        sc.ranges = &bench_log_ranges[s->first];
        sc.count = s->count;
        sc.angle_min = s->angle_min;
        sc.angle_increment = s->angle_increment;
        sc.range_min = 0.0f;
        sc.range_max = s->range_max;
        st = bsf_extract(&g_ex, &sc, &g_res);
        if (st != BSF_OK && st != BSF_OK_CUT) {
            printf("scan %lu: extraction failed (%d)\n", (unsigned long)k, (int)st);
            return 1;
        }
        pose.x = bench_log_poses[3u * k];
        pose.y = bench_log_poses[3u * k + 1u];
        pose.theta = bench_log_poses[3u * k + 2u];
        t0 = ticks_now();
        fused = bsf_map_fuse(&g_map, &g_res, &pose);
        t1 = ticks_now();
        st = BSF_OK;
        do {
            st = bsf_map_encode(&g_map, NULL, g_frame, sizeof g_frame, &len);
        } while (st == BSF_OK && len > 0u && bsf_map_pending(&g_map));
        t2 = ticks_now();
        if (fused < 0 || st != BSF_OK) {
            printf("scan %lu: fuse %d, encode %d\n", (unsigned long)k, fused, (int)st);
            return 1;
        }
        g_fuse[k] = to_instr(t1 - t0);
        g_encode[k] = to_instr(t2 - t1);
    }
    map_bytes = g_map.stats.map_bytes;
    printf("%lu scans fused; %lu map features in RAM, %lu forgotten, %lu left out; %lu bytes of "
           "map frames\n",
           (unsigned long)n, (unsigned long)bsf_map_feature_count(&g_map),
           (unsigned long)g_map.stats.n_forgotten, (unsigned long)g_map.stats.n_dropped_obs,
           (unsigned long)map_bytes);
    print_dist("bsf_map_fuse per scan", g_fuse, n);
    print_dist("bsf_map_encode per scan", g_encode, n);
    return 0;
}
