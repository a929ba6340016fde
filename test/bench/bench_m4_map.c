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
#include "m4_counter.h"

#define MAX_SCANS 4096u

static bsf_extractor_t g_ex;
static bsf_result_t g_res;
static bsf_map_t g_map;
static uint8_t g_frame[BSF_MAP_FRAME_MAX_SIZE];
static uint32_t g_fuse[MAX_SCANS];
static uint32_t g_encode[MAX_SCANS];
static uint32_t g_sorted[MAX_SCANS];

/* Stack high-water mark: paint below the caller's frame, run, find the
 * deepest word overwritten. */

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
    if (!(m4_counter_start() > 0.5)) {
        printf("no usable instruction clock (run QEMU with -icount shift=10)\n");
        return 1;
    }
    if (bsf_extractor_init(&g_ex, &params) != BSF_OK || bsf_map_init(&g_map, NULL) != BSF_OK) {
        printf("init failed\n");
        return 1;
    }
    for (k = 0; k < n; ++k) {
        const bench_map_scan_t *sc = &bench_map_scans[k];
        const bsf_scan_t s = bench_map_scan(k);
        uint32_t t0;
        uint32_t t1;
        uint32_t t2;
        uint32_t *base;
        size_t len = 0;
        int st;
        if (bsf_extract(&g_ex, &s, &g_res) < 0) {
            printf("scan %u: extraction failed\n", (unsigned)k);
            return 1;
        }
        base = m4_stack_paint();
        t0 = m4_ticks();
        st = bsf_map_fuse(&g_map, &g_res, &sc->pose);
        t1 = m4_ticks();
        if (st < 0 || bsf_map_encode(&g_map, NULL, g_frame, sizeof g_frame, &len) != BSF_OK) {
            printf("scan %u: fuse or encode failed\n", (unsigned)k);
            return 1;
        }
        t2 = m4_ticks();
        {
            const uint32_t used = m4_stack_used(base);
            stack_max = used > stack_max ? used : stack_max;
        }
        g_fuse[k] = m4_instr(t1 - t0);
        g_encode[k] = m4_instr(t2 - t1);
        bytes += (uint32_t)len;
    }
    fuse_med = m4_median(g_fuse, n, g_sorted, &fuse_max);
    enc_med = m4_median(g_encode, n, g_sorted, &enc_max);
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
