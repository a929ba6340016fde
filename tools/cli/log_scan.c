/* SPDX-License-Identifier: MIT */
/*
 * log_scan.c - the extractor the commands share (CARMEN records become scans in
 * tools/carmen/carmen_bsf.c, where fuzz_carmen reaches them).
 */
#include "tool.h"

bsf_extractor_t g_ex;
bsf_result_t g_res;
uint8_t g_frame_buf[BSF_FRAME_MAX_SIZE];

int init_extractor_params(const bsf_params_t *params, int timed)
{
    bsf_params_t p = *params;
    bsf_status_t st;
    if (timed) {
        p.clock = bsf_port_clock_monotonic_ns;
        p.clock_hz = 1000000000u;
    }
    st = bsf_extractor_init(&g_ex, &p);
    if (st == BSF_ERR_UNSUPPORTED && !((BSF_CONFIG_METHODS >> (unsigned)p.method) & 1u)) {
        /* Name what is missing and how to get it: the status alone cannot. */
        fail_msg("cannot initialise the extractor: the method %s is not compiled into this build "
                 "(configure with -DBSF_METHODS=all or a list that names it)",
                 bsf_method_name(p.method));
        return -1;
    }
    if (st == BSF_ERR_UNSUPPORTED && p.fit_bin_length != 0.0f && !BSF_CONFIG_FIT_BINS) {
        fail_msg("cannot initialise the extractor: the fit on bin means (--fit-bin-length) is not "
                 "compiled into this build (configure with -DBSF_FIT_BINS=ON)");
        return -1;
    }
    if (st != BSF_OK) {
        fail_msg("cannot initialise the extractor: %s", bsf_status_str(st));
        return -1;
    }
    return 0;
}

int init_extractor_timed(bsf_method_t method, int timed)
{
    const bsf_params_t p = bsf_params_default(method);
    return init_extractor_params(&p, timed);
}

int init_extractor_config(bsf_method_t method, int paper)
{
    const bsf_params_t p = paper ? bsf_params_paper(method) : bsf_params_default(method);
    return init_extractor_params(&p, 1);
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
