/* SPDX-License-Identifier: MIT */
/*
 * bsf_linalg.h - small symmetric positive definite solves for the spline
 * fitters (internal to the library).
 *
 * Matrices are banded and stored by lower band rows: with w = bw + 1,
 * band[i * w + d] holds A[i][i - d] for d = 0..bw (entries with i - d < 0 are
 * unused). A dense matrix is the case bw = m - 1. B-spline normal matrices of
 * degree 2 have bw = 2: each data point touches three consecutive control
 * points, so a solve costs O(m) instead of O(m^3).
 */
#ifndef BSF_LINALG_H
#define BSF_LINALG_H

#include "bsf/bsf_common.h"

/** Largest order m of a solve. */
#define BSF_LINALG_MAX_M BSF_MAX_CTRL_PER_FEATURE

/* Relative size of a pivot, against its diagonal entry, below which the
 * matrix is taken as not positive definite. */
#define BSF_LINALG_PIVOT_REL 1e-6f

/* Diagonal loading of the one retry, relative to the largest diagonal entry. */
#define BSF_LINALG_LOADING_REL 1e-5f

/*
 * Solve A X = B for two right-hand sides that share A (x and y coordinates).
 * Cholesky A = L L^T on the band; on a non-positive (or negligible) pivot the
 * factorisation is retried once with delta * I added, delta =
 * BSF_LINALG_LOADING_REL * max_i A[i][i].
 *
 * band:   A, m * (bw + 1) floats, not modified
 * factor: scratch of m * (bw + 1) floats (receives L)
 * rx, ry: m right-hand sides in, m solutions out
 * loaded: set to 1 when the retry with loading was needed, else 0; may be NULL
 * Returns BSF_OK; BSF_ERR_ARG for NULL pointers, m == 0 or bw >= m;
 * BSF_ERR_CAPACITY for m > BSF_LINALG_MAX_M; BSF_ERR_NUMERIC when A is not
 * positive definite even after the retry, or a value is not finite
 * (rx and ry are then left unchanged).
 */
bsf_status_t bsf_spd_band_solve2(const float *band, size_t m, size_t bw, float *factor, float *rx,
                                 float *ry, int *loaded);

#endif /* BSF_LINALG_H */
