/* SPDX-License-Identifier: MIT */
/*
 * bsf_segment_internal.h - SVED's mixed-pixel rule for the other stages (not
 * public).
 */
#ifndef BSF_SEGMENT_INTERNAL_H
#define BSF_SEGMENT_INTERNAL_H

#include "bsf/bsf_segment.h"

/* SVED's mixed-pixel rule (bsf_segment_sved_labelled) on every beam of pts
 * with params p (trusted: checked by the caller; reject_mixed is not looked
 * at): bit b % 8 of marks[b / 8] set when it rejects beam b ((count + 7) / 8
 * bytes written; marks may be NULL), and the beams it rejects off the line of a long run
 * beside them (its second route) into off_line[0..cap), ascending; returns
 * how many of those it stored. */
size_t bsf_sved_mixed_marks(const bsf_points_t *pts, const bsf_sved_params_t *p, uint8_t *marks,
                            uint16_t *off_line, size_t cap);

/* bsf_segment_sved_labelled with the mixed pixels that
 * bsf_sved_mixed_marks marked on the same points and params (marks not
 * NULL), rather than finding them again; no count of wasted points. */
bsf_status_t bsf_segment_sved_marked(const bsf_points_t *pts, const bsf_sved_params_t *params,
                                     bsf_segment_t *out, size_t cap, uint16_t *label,
                                     const uint8_t *marks, size_t *n_out);

#endif /* BSF_SEGMENT_INTERNAL_H */
