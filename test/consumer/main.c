/* SPDX-License-Identifier: MIT */
/* A downstream program, built each way a user adds bsf (see tests.cmake):
 * converts a three-beam scan and runs the extractor on a
 * circular arc, checks the header and library versions agree, and with
 * BSF_CONSUMER_PORT reads the installed POSIX clock hook. Exit 0 when the
 * library answers as documented. */
#include <stdio.h>
#include <string.h>

#include <bsf/bsf.h>
#ifdef BSF_CONSUMER_PORT
#include "bsf_port_clock.h"
#endif

static bsf_points_t points;
static bsf_extractor_t extractor;
static bsf_result_t result;

int main(void)
{
    static const float ranges[3] = {1.0f, -1.0f, 2.0f};
    static float arc[91];
    const bsf_scan_t scan = {ranges, 3u, 0.0f, 0.01f, 0.1f, 10.0f};
    const bsf_scan_t arc_scan = {arc, 91u, -0.7853982f, 0.01745329f, 0.05f, 30.0f};
    bsf_params_t params = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    size_t i;

    if (strcmp(bsf_version(), BSF_VERSION_STRING) != 0) {
        printf("library %s, headers %s\n", bsf_version(), BSF_VERSION_STRING);
        return 1;
    }
    if (bsf_scan_to_points(&scan, &points) != BSF_OK || points.n_valid != 2u) {
        return 2;
    }
    /* The robot in a round room: a 90-degree arc of radius 1.5 m. */
    for (i = 0; i < 91u; ++i) {
        arc[i] = 1.5f;
    }
#ifdef BSF_CONSUMER_PORT
    params.clock = bsf_port_clock_monotonic_ns;
    params.clock_hz = 1000000000u;
#endif
    if (bsf_extractor_init(&extractor, &params) != BSF_OK ||
        bsf_extract(&extractor, &arc_scan, &result) != BSF_OK) {
        return 3;
    }
    if (result.n_features == 0u) {
        return 4;
    }
    printf("bsf %s: %u feature(s)\n", bsf_version(), (unsigned)result.n_features);
    return 0;
}
