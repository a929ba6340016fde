/* SPDX-License-Identifier: MIT */
#include "bsf_linalg.h"
#include "bsf_math.h"

#include <math.h>

static int finite_f(float v)
{
    return bsf_finite_bits(v);
}

/* In-place banded Cholesky of factor (holding A + loading * I). Returns 0 on
 * a bad pivot. */
/* The written-out half-bandwidth-2 paths below are for speed only: the
 * compact variant (BSF_CONFIG_COMPACT) leaves them out and runs the general
 * loops, which do the same arithmetic in the same order (same results). */
#if !BSF_CONFIG_COMPACT
#define BSF_LINALG_BW2 1
#else
#define BSF_LINALG_BW2 0
#endif

#if BSF_LINALG_BW2
/* band_cholesky for half-bandwidth 2 (every PDM solve), written out: row i
 * holds (L[i][i], L[i][i-1], L[i][i-2]) at f[3i], f[3i+1], f[3i+2]. Same
 * arithmetic order and pivot test as the general loop. */
static int band_cholesky_bw2(float *f, size_t m, float loading)
{
    size_t i;
    for (i = 0; i < m; ++i) {
        float *r = f + i * 3u;
        const float diag = r[0] + loading;
        float sum = diag;
        if (i >= 2u) {
            r[2] = r[2] / f[(i - 2u) * 3u];
            sum -= r[2] * r[2];
        }
        if (i >= 1u) {
            float off = r[1];
            if (i >= 2u) {
                off -= r[2] * f[(i - 1u) * 3u + 1u];
            }
            r[1] = off / f[(i - 1u) * 3u];
            sum -= r[1] * r[1];
        }
        if (!(sum > BSF_LINALG_PIVOT_REL * diag) || !finite_f(sum)) {
            return 0;
        }
        r[0] = sqrtf(sum);
    }
    return 1;
}

/* The general substitutions below for half-bandwidth 2, written out (every
 * PDM solve): same arithmetic in the same order, so the same results. */
static bsf_status_t band_substitute_bw2(const float *f, size_t m, float *rx, float *ry)
{
    float zx[BSF_LINALG_MAX_M];
    float zy[BSF_LINALG_MAX_M];
    size_t i;
    for (i = 0; i < m; ++i) {
        const float *r = f + i * 3u;
        float sx = rx[i];
        float sy = ry[i];
        if (i >= 2u) {
            sx -= r[2] * zx[i - 2u];
            sy -= r[2] * zy[i - 2u];
        }
        if (i >= 1u) {
            sx -= r[1] * zx[i - 1u];
            sy -= r[1] * zy[i - 1u];
        }
        zx[i] = sx / r[0];
        zy[i] = sy / r[0];
    }
    for (i = m; i-- > 0u;) {
        float sx = zx[i];
        float sy = zy[i];
        if (i + 1u < m) {
            const float l = f[(i + 1u) * 3u + 1u];
            sx -= l * zx[i + 1u];
            sy -= l * zy[i + 1u];
        }
        if (i + 2u < m) {
            const float l = f[(i + 2u) * 3u + 2u];
            sx -= l * zx[i + 2u];
            sy -= l * zy[i + 2u];
        }
        zx[i] = sx / f[i * 3u];
        zy[i] = sy / f[i * 3u];
        if (!finite_f(zx[i]) || !finite_f(zy[i])) {
            return BSF_ERR_NUMERIC;
        }
    }
    for (i = 0; i < m; ++i) {
        rx[i] = zx[i];
        ry[i] = zy[i];
    }
    return BSF_OK;
}
#endif

static int band_cholesky(float *f, size_t m, size_t bw, float loading)
{
    const size_t w = bw + 1u;
    size_t i;
    size_t j;
    size_t k;

#if BSF_LINALG_BW2
    if (bw == 2u) {
        return band_cholesky_bw2(f, m, loading);
    }
#endif

    for (i = 0; i < m; ++i) {
        const size_t j0 = i > bw ? i - bw : 0u;
        f[i * w] += loading;
        for (j = j0; j <= i; ++j) {
            float sum = f[i * w + (i - j)];
            for (k = j0; k < j; ++k) {
                sum -= f[i * w + (i - k)] * f[j * w + (j - k)];
            }
            if (j < i) {
                f[i * w + (i - j)] = sum / f[j * w];
            } else {
                const float diag = f[i * w];
                /* f[i*w] still holds A[i][i] + loading here */
                if (!(sum > BSF_LINALG_PIVOT_REL * diag) || !finite_f(sum)) {
                    return 0;
                }
                f[i * w] = sqrtf(sum);
            }
        }
    }
    return 1;
}

bsf_status_t bsf_spd_band_solve2(const float *band, size_t m, size_t bw, float *factor, float *rx,
                                 float *ry, int *loaded)
{
    const size_t w = bw + 1u;
    size_t i;
    size_t k;
    int attempt;
    int ok = 0;
    float max_diag = 0.0f;

    if (band == NULL || factor == NULL || rx == NULL || ry == NULL || m == 0u || bw >= m) {
        return BSF_ERR_ARG;
    }
    if (m > (size_t)BSF_LINALG_MAX_M) {
        return BSF_ERR_CAPACITY;
    }
    for (i = 0; i < m; ++i) {
        const float d = band[i * w];
        if (!finite_f(d) || !finite_f(rx[i]) || !finite_f(ry[i])) {
            return BSF_ERR_NUMERIC;
        }
        if (d > max_diag) {
            max_diag = d;
        }
    }
    if (!(max_diag > 0.0f)) {
        return BSF_ERR_NUMERIC;
    }
    for (attempt = 0; attempt < 2 && !ok; ++attempt) {
        const float loading = attempt == 0 ? 0.0f : BSF_LINALG_LOADING_REL * max_diag;
        for (i = 0; i < m * w; ++i) {
            factor[i] = band[i];
        }
        ok = band_cholesky(factor, m, bw, loading);
        if (loaded != NULL) {
            *loaded = attempt;
        }
    }
    if (!ok) {
        return BSF_ERR_NUMERIC;
    }
#if BSF_LINALG_BW2
    if (bw == 2u) {
        return band_substitute_bw2(factor, m, rx, ry);
    }
#endif
    {
        /* Forward substitution L z = b, then back substitution L^T x = z,
         * both right-hand sides in the same sweep. The results go to the
         * caller only when every value is finite. */
        float zx[BSF_LINALG_MAX_M];
        float zy[BSF_LINALG_MAX_M];
        for (i = 0; i < m; ++i) {
            const size_t k0 = i > bw ? i - bw : 0u;
            float sx = rx[i];
            float sy = ry[i];
            for (k = k0; k < i; ++k) {
                const float l = factor[i * w + (i - k)];
                sx -= l * zx[k];
                sy -= l * zy[k];
            }
            zx[i] = sx / factor[i * w];
            zy[i] = sy / factor[i * w];
        }
        for (i = m; i-- > 0u;) {
            const size_t k1 = i + bw < m - 1u ? i + bw : m - 1u;
            float sx = zx[i];
            float sy = zy[i];
            for (k = i + 1u; k <= k1; ++k) {
                const float l = factor[k * w + (k - i)];
                sx -= l * zx[k];
                sy -= l * zy[k];
            }
            zx[i] = sx / factor[i * w];
            zy[i] = sy / factor[i * w];
            if (!finite_f(zx[i]) || !finite_f(zy[i])) {
                return BSF_ERR_NUMERIC;
            }
        }
        for (i = 0; i < m; ++i) {
            rx[i] = zx[i];
            ry[i] = zy[i];
        }
    }
    return BSF_OK;
}
