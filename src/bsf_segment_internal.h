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
 * NULL), rather than finding them again, and its grazing joins' verdicts
 * kept in grazing_memo (bsf_grazing_join; NULL: none kept); no count
 * of wasted points. */
bsf_status_t bsf_segment_sved_marked(const bsf_points_t *pts, const bsf_sved_params_t *params,
                                     bsf_segment_t *out, size_t cap, uint16_t *label,
                                     const uint8_t *marks, uint8_t *grazing_memo, size_t *n_out);

/* A line through a side's returns w[1..n) (total least squares), as SVED's
 * mixed-pixel rule and the extractor's tail rule judge the return w[0]
 * next to them against it. */
typedef struct {
    float cx, cy;   /* centroid */
    float nx, ny;   /* unit normal */
    float var;      /* noise variance estimated from its residual (n - 3 degrees of freedom) */
    float reach_i;  /* variance of the distance of a return one step before w[0], in noise
                       variances, for evenly spaced returns */
    float d_near;   /* signed distance of w[0] from it */
    float reach_nr; /* the same variance for w[0] */
    int n;          /* returns, w[0] included; set by the caller, at least 4 */
} bsf_side_line_t;

/* Fits l (all but n, which the caller sets) to w[1..l->n) and measures w[0]. */
void bsf_side_fit(const bsf_point_t *w, bsf_side_line_t *l);

/* Signed distance of p from line l. */
static inline float bsf_side_distance(const bsf_side_line_t *l, const bsf_point_t *p)
{
    return l->nx * (p->x - l->cx) + l->ny * (p->y - l->cy);
}

#endif /* BSF_SEGMENT_INTERNAL_H */
