/* SPDX-License-Identifier: MIT */
/*
 * bsf_segment_internal.h - SVED's mixed-pixel rule for the other stages (not
 * public).
 */
#ifndef BSF_SEGMENT_INTERNAL_H
#define BSF_SEGMENT_INTERNAL_H

#include "bsf/bsf_segment.h"

/* The beams of pts that bsf_segment_sved_labelled rejects as mixed pixels
 * off the line of a long run beside them (its second route), with params p
 * (trusted: checked by the caller; reject_mixed is not looked at),
 * ascending, into out[0..cap); returns how many it stored (it stops at
 * cap). */
size_t bsf_sved_mixed_beams(const bsf_points_t *pts, const bsf_sved_params_t *p, uint16_t *out,
                            size_t cap);

#endif /* BSF_SEGMENT_INTERNAL_H */
