/* SPDX-License-Identifier: MIT */
/*
 * fuzz_check.h - invariants every harness checks on library output. A
 * violation prints what broke and aborts, which libFuzzer reports as a crash
 * and saves the input.
 */
#ifndef BSF_FUZZ_CHECK_H
#define BSF_FUZZ_CHECK_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bsf/bsf.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_CHECK(cond)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: invariant violated: %s\n", __FILE__, __LINE__, #cond);         \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

/* Every status the library returns has a non-empty message. */
static inline void fuzz_check_status(bsf_status_t st)
{
    const char *msg = bsf_status_str(st);
    FUZZ_CHECK(msg != NULL && msg[0] != '\0');
}

static inline int fuzz_finite(float v)
{
    return isfinite(v) != 0;
}

/* A result is within the caps, self-consistent and free of NaN/inf. With
 * `ordered`, features must also come in order of their first beams, a
 * wrapping one last (the extractor's promise; the wire format itself allows
 * any order). Their runs may overlap (the segmentation's look-back) and, on
 * a full-circle scan, wrap through the seam (first_beam > last_beam). */
static inline void fuzz_check_result(const bsf_result_t *r, int ordered)
{
    uint32_t sum_points = 0u;
    size_t next_ctrl = 0u;
    size_t f;
    size_t k;
    FUZZ_CHECK(r->n_features <= BSF_MAX_SEGMENTS);
    FUZZ_CHECK(r->n_ctrl <= BSF_MAX_CTRL_POINTS);
    for (f = 0; f < r->n_features; ++f) {
        const bsf_feature_t *ft = &r->features[f];
        const int wraps = ft->first_beam > ft->last_beam;
        /* first_beam > last_beam: the run wraps through the seam of a
         * full-circle scan of stats.n_beams beams. */
        const uint32_t span = ft->first_beam <= ft->last_beam
                                  ? (uint32_t)(ft->last_beam - ft->first_beam)
                                  : r->stats.n_beams - ft->first_beam + ft->last_beam;
        FUZZ_CHECK(ft->first_beam <= ft->last_beam || r->stats.n_beams > ft->first_beam);
        FUZZ_CHECK(ft->last_beam < BSF_MAX_POINTS);
        FUZZ_CHECK(ft->n_points <= span + 1u);
        FUZZ_CHECK(!ordered || ft->n_points >= 1u); /* the wire format allows 0 */
        FUZZ_CHECK(ft->n_ctrl >= 3u && ft->n_ctrl <= BSF_MAX_CTRL_PER_FEATURE);
        FUZZ_CHECK(ft->ctrl_first == next_ctrl); /* features own consecutive pool slices */
        FUZZ_CHECK(ft->kind <= 1u);
        FUZZ_CHECK(fuzz_finite(ft->e_curve) && ft->e_curve >= 0.0f);
        if (ordered && f > 0u) {
            const bsf_feature_t *pf = &r->features[f - 1u];
            /* by first beam, a wrapping feature last */
            FUZZ_CHECK((pf->first_beam > pf->last_beam ? 0x10000u : 0u) + pf->first_beam <
                       (wraps ? 0x10000u : 0u) + ft->first_beam);
        }
        next_ctrl += ft->n_ctrl;
        sum_points += ft->n_points;
    }
    FUZZ_CHECK(next_ctrl == r->n_ctrl);
    for (k = 0; k < r->n_ctrl; ++k) {
        FUZZ_CHECK(fuzz_finite(r->ctrl[k].x) && fuzz_finite(r->ctrl[k].y));
        FUZZ_CHECK(r->ctrl_is_vertex[k] <= 1u);
    }
    FUZZ_CHECK(r->stats.n_features == r->n_features);
    FUZZ_CHECK(r->stats.n_ctrl == r->n_ctrl);
    FUZZ_CHECK(r->stats.n_in_features == sum_points);
    FUZZ_CHECK(r->stats.n_in_features <= r->stats.n_valid);
    FUZZ_CHECK(r->stats.n_valid <= BSF_MAX_POINTS);
}

#endif /* BSF_FUZZ_CHECK_H */
