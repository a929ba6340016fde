/* SPDX-License-Identifier: MIT */
/*
 * bsf_lc_internal.h - LC's corner detector for the extractor (not public).
 */
#ifndef BSF_LC_INTERNAL_H
#define BSF_LC_INTERNAL_H

#include <stdint.h>

#include "bsf/bsf_lc.h"

/* bsf_lc_detect keeping its grazing joins' verdicts in grazing_memo (see
 * bsf_grazing_join; NULL: none kept), so that SVED, asking about the
 * same steps on the same points, finds them there. */
bsf_status_t bsf_lc_detect_memo(const bsf_points_t *pts, const bsf_lc_params_t *p,
                                bsf_lc_work_t *work, bsf_keypoint_t *out, size_t out_cap,
                                size_t *n_out, uint8_t *grazing_memo);

#endif /* BSF_LC_INTERNAL_H */
