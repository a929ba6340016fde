/* SPDX-License-Identifier: MIT */
/*
 * log_scan.c - CARMEN records as bsf scans, and the extractor the commands share.
 */
#include "tool.h"

float scan_range_max(const carmen_scan_t *s, double opt)
{
    return opt > 0.0 ? (float)opt : carmen_valid_range_max(s);
}

bsf_scan_t scan_of_record(const carmen_scan_t *s, double range_max_opt)
{
    bsf_scan_t sc;
    sc.ranges = s->ranges;
    sc.count = s->count;
    sc.angle_min = s->angle_min;
    sc.angle_increment = s->angle_increment;
    sc.range_min = 0.0f;
    sc.range_max = scan_range_max(s, range_max_opt);
    return sc;
}

bsf_extractor_t g_ex;
bsf_result_t g_res;
uint8_t g_frame_buf[BSF_FRAME_MAX_SIZE];

int init_extractor_timed(bsf_method_t method, int timed)
{
    bsf_params_t p = bsf_params_default(method);
    bsf_status_t st;
    if (timed) {
        p.clock = bsf_port_clock_monotonic_ns;
        p.clock_hz = 1000000000u;
    }
    st = bsf_extractor_init(&g_ex, &p);
    if (st != BSF_OK) {
        fail_msg("cannot initialise the extractor: %s", bsf_status_str(st));
        return -1;
    }
    return 0;
}

int init_extractor(bsf_method_t method)
{
    return init_extractor_timed(method, 1);
}

void fill_metadata(bsf_metadata_t *m, const bsf_scan_t *sc, float quant)
{
    bsf_metadata_init(m);
    m->method = (uint8_t)g_ex.params.method;
    m->target_rms = g_ex.params.pdm.target_rms;
    m->quant_step = quant;
    m->n_beams = (uint32_t)sc->count;
    m->angle_min = sc->angle_min;
    m->angle_increment = sc->angle_increment;
    m->range_min = sc->range_min;
    m->range_max = sc->range_max;
}
