/* SPDX-License-Identifier: MIT */
/*
 * log_scan.c - the extractor the commands share (CARMEN records become scans in
 * tools/carmen/carmen_bsf.c, where fuzz_carmen reaches them).
 */
#include "tool.h"

bsf_extractor_t g_ex;
bsf_result_t g_res;
uint8_t g_frame_buf[BSF_FRAME_MAX_SIZE];

int init_extractor(bsf_method_t method)
{
    bsf_params_t p = bsf_params_default(method);
    bsf_status_t st;
    p.clock = bsf_port_clock_monotonic_ns;
    p.clock_hz = 1000000000u;
    st = bsf_extractor_init(&g_ex, &p);
    if (st != BSF_OK) {
        fail_msg("cannot initialise the extractor: %s", bsf_status_str(st));
        return -1;
    }
    return 0;
}
