/* SPDX-License-Identifier: MIT */
/*
 * bench_m4_align - instructions per scan of bsf_align_points on the
 * Cortex-M4F, counted under QEMU (mps2-an386) with -icount as in
 * bench_m4_map.c, on the corrected Intel log's FLASER scans compiled in at
 * build time (tools/scripts/gen_map_scans.py). Each scan is extracted with
 * LC-SVED-PDM (not counted); its prior is the previous corrected pose moved
 * by the log's relative motion with 2 % more distance and 1 degree per metre
 * more turn (one step of drift); the scan is aligned to the map (counted)
 * and fused at its corrected pose (not counted), so that every scan meets
 * the map a corrected run would have (these keyframes are about 1 m apart,
 * and a run that fuses its own aligned poses drifts along corridors). Also the stack high-water
 * mark of the call, the declines and sizeof(bsf_align_work_t).
 *
 * Prints numbers, judges none; fails only if a call fails. Run:
 *   ctest --test-dir build-m4 -R bench_m4_align -V
 */
#include <math.h>
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
static bsf_align_work_t g_work;
static uint32_t g_align[MAX_SCANS];
static uint32_t g_sorted[MAX_SCANS];

/* Stack high-water mark: paint below the caller's frame, run, find the
 * deepest word overwritten. */

/* b in the frame of a (the motion from a to b). */
static bsf_pose_t relative(const bsf_pose_t *a, const bsf_pose_t *b)
{
    const float c = cosf(a->theta);
    const float s = sinf(a->theta);
    const float dx = b->x - a->x;
    const float dy = b->y - a->y;
    bsf_pose_t r;
    r.x = c * dx + s * dy;
    r.y = -s * dx + c * dy;
    r.theta = b->theta - a->theta;
    return r;
}

/* a moved by m (given in a's frame). */
static bsf_pose_t moved(const bsf_pose_t *a, const bsf_pose_t *m)
{
    const float c = cosf(a->theta);
    const float s = sinf(a->theta);
    bsf_pose_t r;
    r.x = a->x + c * m->x - s * m->y;
    r.y = a->y + s * m->x + c * m->y;
    r.theta = a->theta + m->theta;
    return r;
}

int main(void)
{
    const bsf_params_t params = bsf_params_default(BSF_METHOD_LC_SVED_PDM);
    const size_t n = bench_map_n_scans < MAX_SCANS ? bench_map_n_scans : MAX_SCANS;
    uint32_t stack_max = 0u;
    uint32_t med;
    uint32_t max;
    uint32_t declined[BSF_ALIGN_DECLINE_COUNT] = {0};
    uint32_t n_free = 0u;
    float err_sum = 0.0f;
    size_t k;
    size_t n_timed = 0;
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
        bsf_align_result_t ar;
        uint32_t t0;
        uint32_t t1;
        uint32_t *base;
        int st;
        if (bsf_extract(&g_ex, &s, &g_res) < 0) {
            printf("scan %u: extraction failed\n", (unsigned)k);
            return 1;
        }
        if (k > 0) {
            bsf_pose_t m = relative(&bench_map_scans[k - 1].pose, &sc->pose);
            const float d = sqrtf(m.x * m.x + m.y * m.y);
            bsf_pose_t prior;
            m.x *= 1.02f;
            m.y *= 1.02f;
            m.theta += d * 0.0174533f;
            prior = moved(&bench_map_scans[k - 1].pose, &m);
            base = m4_stack_paint();
            t0 = m4_ticks();
            st = bsf_align_points(&g_work, NULL, &g_map, &g_ex.points, &g_res, &prior, &ar);
            t1 = m4_ticks();
            if (st != BSF_OK) {
                printf("scan %u: alignment failed\n", (unsigned)k);
                return 1;
            }
            {
                const uint32_t used = m4_stack_used(base);
                stack_max = used > stack_max ? used : stack_max;
            }
            g_align[n_timed++] = m4_instr(t1 - t0);
            ++declined[ar.declined];
            n_free += ar.n_free > 0u;
            err_sum += sqrtf((ar.pose.x - sc->pose.x) * (ar.pose.x - sc->pose.x) +
                             (ar.pose.y - sc->pose.y) * (ar.pose.y - sc->pose.y));
        }
        if (bsf_map_fuse(&g_map, &g_res, &sc->pose) < 0) {
            printf("scan %u: fuse failed\n", (unsigned)k);
            return 1;
        }
    }
    if (n_timed == 0u) {
        printf("no scans\n");
        return 1;
    }
    med = m4_median(g_align, n_timed, g_sorted, &max);
    printf("bench_m4_align: %s\n", bench_map_description);
    printf("bsf_align_points instructions per scan: median %lu, max %lu (%lu scans)\n",
           (unsigned long)med, (unsigned long)max, (unsigned long)n_timed);
    printf("stack of bsf_align_points (painted, libm included): %lu bytes\n",
           (unsigned long)stack_max);
    printf("declined:");
    for (k = 1; k < BSF_ALIGN_DECLINE_COUNT; ++k) {
        printf(" %s %lu;", bsf_align_decline_str((int)k), (unsigned long)declined[k]);
    }
    printf(" a direction free: %lu; mean position error after alignment %.3f m\n",
           (unsigned long)n_free, (double)(err_sum / (float)n_timed));
    printf("sizeof(bsf_align_work_t) %lu\n", (unsigned long)sizeof(bsf_align_work_t));
    return 0;
}
