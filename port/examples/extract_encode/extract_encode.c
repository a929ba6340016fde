/* SPDX-License-Identifier: MIT */
/*
 * extract_encode - the smallest useful bsf firmware: extract the features of
 * a scan with the default method and encode them as one frame, as a robot's
 * sensor board does per scan. It exists to measure what such a firmware links
 * from libbsf (tools/scripts/size_report.py reads its link map) and to prove,
 * under QEMU, that a library built with only the default method
 * (-DBSF_METHODS=lc-sved-pdm, and -DBSF_FIT_BINS=OFF for the 32 KiB budget's
 * build: the default parameters never fit on bin means) still extracts and encodes.
 *
 * The scan: 1081 beams over 270 degrees from inside a 6 m x 4 m room with a
 * round pillar, computed in place (no scene code linked). Exit status 0 when
 * the frame was encoded and holds at least one feature.
 */
#include <math.h>

#include "bsf/bsf.h"

#define N_BEAMS 1081

static bsf_extractor_t g_ex;
static bsf_result_t g_res;
static float g_ranges[N_BEAMS];
static uint8_t g_frame[BSF_FRAME_MAX_SIZE];

/* Distance from the origin along (c, s) to the room's walls (x in [-2, 4],
 * y in [-1.5, 2.5]) or to the pillar (centre (2, 1), radius 0.3). */
static float range_along(float c, float s)
{
    float t = 1e9f;
    float b;
    float disc;
    if (c > 1e-6f) {
        t = fminf(t, 4.0f / c);
    } else if (c < -1e-6f) {
        t = fminf(t, -2.0f / c);
    }
    if (s > 1e-6f) {
        t = fminf(t, 2.5f / s);
    } else if (s < -1e-6f) {
        t = fminf(t, -1.5f / s);
    }
    b = 2.0f * c + 1.0f * s; /* ray . centre */
    disc = b * b - (2.0f * 2.0f + 1.0f * 1.0f - 0.3f * 0.3f);
    if (disc >= 0.0f && b - sqrtf(disc) > 0.0f) {
        t = fminf(t, b - sqrtf(disc));
    }
    return t;
}

int main(void)
{
    const float angle_min = -2.35619449f;
    const float increment = 4.71238898f / (float)(N_BEAMS - 1);
    bsf_params_t params = bsf_params_default(BSF_METHOD_DEFAULT);
    bsf_frame_info_t info;
    bsf_scan_t scan;
    size_t len = 0u;
    size_t i;

    for (i = 0; i < N_BEAMS; ++i) {
        const float a = angle_min + increment * (float)i;
        g_ranges[i] = range_along(cosf(a), sinf(a));
    }
    scan.ranges = g_ranges;
    scan.count = N_BEAMS;
    scan.angle_min = angle_min;
    scan.angle_increment = increment;
    scan.range_min = 0.0f;
    scan.range_max = 30.0f;

    if (bsf_extractor_init(&g_ex, &params) != BSF_OK || bsf_extract(&g_ex, &scan, &g_res) < 0 ||
        g_res.n_features == 0u) {
        return 1;
    }
    bsf_frame_info_init(&info);
    if (bsf_frame_encode(&info, &g_res, g_frame, sizeof g_frame, &len) != BSF_OK || len == 0u) {
        return 2;
    }
    return 0;
}
