/* SPDX-License-Identifier: MIT */
/*
 * stream_fixtures.h - results for the wire-format tests: the worked
 * examples of docs/FORMAT.md and a generator of plausible random results.
 */
#ifndef STREAM_FIXTURES_H
#define STREAM_FIXTURES_H

#include "bsf/bsf.h"

/** A small deterministic PRNG (xorshift32) so that runs are repeatable everywhere. */
typedef struct {
    uint32_t state;
} fx_rng_t;

void fx_rng_seed(fx_rng_t *rng, uint32_t seed);
uint32_t fx_rng_next(fx_rng_t *rng);
/** Uniform integer in [lo, hi]. */
uint32_t fx_rng_range(fx_rng_t *rng, uint32_t lo, uint32_t hi);
/** Uniform float in [lo, hi). */
float fx_rng_float(fx_rng_t *rng, float lo, float hi);

/** FORMAT.md example 1: one bleak feature of 3 control points, no pose. */
void fx_example_minimal(bsf_frame_info_t *info, bsf_result_t *res);

/** FORMAT.md example 2: a typical scan, 6 features, 26 control points, 2 vertices, with pose. */
void fx_example_typical(bsf_frame_info_t *info, bsf_result_t *res);

/** FORMAT.md example 3: a 360-beam full-circle scan with a feature that
 *  wraps through the seam and two segments cut by a cap. */
void fx_example_wrap_cut(bsf_frame_info_t *info, bsf_result_t *res);

/** FORMAT.md example 4: the metadata frame of an Intel stream. */
void fx_example_metadata(bsf_metadata_t *m);

/**
 * A random plausible result: 1..max_features walls of 0.5-5 m within 8 m,
 * 3..20 control points per feature, some vertices, beams in order over a
 * 360-beam scan; random seq, time stamp, pose (or none) and extraction time.
 */
void fx_random_result(fx_rng_t *rng, uint32_t max_features, bsf_frame_info_t *info,
                      bsf_result_t *res);

#endif /* STREAM_FIXTURES_H */
