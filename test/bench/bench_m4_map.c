/* SPDX-License-Identifier: MIT */
/*
 * bench_m4_map - instructions per scan of bsf_map_fuse and bsf_map_encode on
 * the Cortex-M4F, counted under QEMU (mps2-an386) with -icount as in
 * bench_m4_icount.c (SysTick ticks, calibrated by a loop of known length),
 * on the corrected Intel log's FLASER scans with their poses, compiled in at
 * build time (tools/scripts/gen_map_scans.py). Each scan is extracted with
 * LC-SVED-PDM (not counted), fused, and a frame encoded every call (map
 * records every params.frame_interval calls). Also the stack high-water mark
 * of the fuse call, the stream's bytes and sizeof(bsf_map_t).
 *
 * Prints numbers, judges none; fails only if a call fails. Run:
 *   ctest --test-dir build-m4 -R bench_m4_map -V
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_map_scans.h"
#include "bsf/bsf.h"

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYST_MASK 0x00FFFFFFu
#define SCB_ICSR (*(volatile uint32_t *)0xE000ED04u)
#define SCB_VTOR (*(volatile uint32_t *)0xE000ED08u)
#define ICSR_PENDSTSET (1u << 26)
#define N_VECTORS 16u
#define MAX_SCANS 4096u

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

/* SysTick through a vector table of our own in RAM; its interrupt counts
 * the 24-bit wraps, so long calls are counted exactly. */
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

static uint32_t ticks_of_spin(uint32_t n)
{
    const uint32_t t0 = ticks_now();
    spin(n);
    return ticks_now() - t0;
}

static uint32_t to_instr(uint32_t ticks)
{
    return (uint32_t)((double)ticks / g_ticks_per_instr + 0.5);
}

/* Stack high-water mark: paint below the caller's frame, run, find the
 * deepest word overwritten. */
#define PAINT_BYTES 16384u
#define PAINT_WORD 0xDEADBEEFu

static uint32_t *paint_base(void)
{
    uint32_t sp;
    __asm volatile("mov %0, sp" : "=r"(sp));
    return (uint32_t *)(uintptr_t)((sp - PAINT_BYTES - 256u) & ~7u);
}

static void __attribute__((noinline)) stack_paint(void)
{
    volatile uint32_t *p = paint_base();
    uint32_t i;
    for (i = 0; i < PAINT_BYTES / 4u; ++i) {
        p[i] = PAINT_WORD;
    }
}

static uint32_t __attribute__((noinline)) stack_used(uint32_t *base)
{
    uint32_t i = 0;
    while (i < PAINT_BYTES / 4u && base[i] == PAINT_WORD) {
        ++i;
    }
    return PAINT_BYTES - 4u * i;
}

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a;
    const uint32_t y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static uint32_t median_of(const uint32_t *v, size_t n, uint32_t *max_out)
{
    memcpy(g_sorted, v, n * sizeof *v);
    qsort(g_sorted, n, sizeof *g_sorted, cmp_u32);
    *max_out = g_sorted[n - 1u];
    return g_sorted[n / 2u];
}

int main(void)
{
    const bsf_params_t params = bsf_params_default(BSF_METHOD_LC_SVED_PDM);
    const size_t n = bench_map_n_scans < MAX_SCANS ? bench_map_n_scans : MAX_SCANS;
    uint32_t stack_max = 0u;
    uint32_t bytes = 0u;
    uint32_t fuse_max;
    uint32_t enc_max;
    uint32_t fuse_med;
    uint32_t enc_med;
    size_t k;
    systick_start();
    {
        const uint32_t a = ticks_of_spin(100000u);
        const uint32_t b = ticks_of_spin(300000u);
        g_ticks_per_instr = (double)(b - a) / 400000.0;
    }
    if (!(g_ticks_per_instr > 0.5)) {
        printf("no usable instruction clock (run QEMU with -icount shift=10)\n");
        return 1;
    }
    if (bsf_extractor_init(&g_ex, &params) != BSF_OK || bsf_map_init(&g_map, NULL) != BSF_OK) {
        printf("init failed\n");
        return 1;
    }
    for (k = 0; k < n; ++k) {
        const bench_map_scan_t *sc = &bench_map_scans[k];
        bsf_scan_t s;
        uint32_t t0;
        uint32_t t1;
        uint32_t t2;
        uint32_t *base;
        size_t len = 0;
        int st;
        s.ranges = &bench_map_ranges[sc->first];
        s.count = sc->count;
        s.angle_min = -1.57079633f;
        s.angle_increment = sc->angle_increment;
        s.range_min = 0.0f;
        s.range_max = 80.0f;
        if (bsf_extract(&g_ex, &s, &g_res) < 0) {
            printf("scan %u: extraction failed\n", (unsigned)k);
            return 1;
        }
        stack_paint();
        base = paint_base();
        t0 = ticks_now();
        st = bsf_map_fuse(&g_map, &g_res, &sc->pose);
        t1 = ticks_now();
        if (st < 0 || bsf_map_encode(&g_map, NULL, g_frame, sizeof g_frame, &len) != BSF_OK) {
            printf("scan %u: fuse or encode failed\n", (unsigned)k);
            return 1;
        }
        t2 = ticks_now();
        {
            const uint32_t used = stack_used(base);
            stack_max = used > stack_max ? used : stack_max;
        }
        g_fuse[k] = to_instr(t1 - t0);
        g_encode[k] = to_instr(t2 - t1);
        bytes += (uint32_t)len;
    }
    fuse_med = median_of(g_fuse, n, &fuse_max);
    enc_med = median_of(g_encode, n, &enc_max);
    printf("bench_m4_map: %s\n", bench_map_description);
    printf("bsf_map_fuse   instructions per scan: median %lu, max %lu\n", (unsigned long)fuse_med,
           (unsigned long)fuse_max);
    printf("bsf_map_encode instructions per call: median %lu, max %lu\n", (unsigned long)enc_med,
           (unsigned long)enc_max);
    printf("stack of fuse + encode (painted, libm included): %lu bytes\n",
           (unsigned long)stack_max);
    printf("update stream %lu bytes in %lu frames; %lu features in RAM, %lu made, %lu merged, "
           "%lu forgotten; sizeof(bsf_map_t) %lu\n",
           (unsigned long)bytes, (unsigned long)g_map.stats.n_frames,
           (unsigned long)bsf_map_feature_count(&g_map), (unsigned long)g_map.stats.n_new,
           (unsigned long)g_map.stats.n_merged, (unsigned long)g_map.stats.n_forgotten,
           (unsigned long)sizeof(bsf_map_t));
    return 0;
}
