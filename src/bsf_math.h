/* SPDX-License-Identifier: MIT */
/*
 * bsf_math.h - internal: the transcendental functions the library needs,
 * computed with + - * / and sqrtf only (and, at the end, the range table
 * the parameter checks share).
 *
 * Why: those five operations are correctly rounded by IEEE 754 on every
 * target, while sinf, cosf, expf, atan2f and asinf differ in the last bits
 * between C libraries (glibc on the host, newlib on the Cortex-M4F). With
 * these, and no FMA contraction (-ffp-contract=off), a scan gives the same
 * bytes on every target (test_determinism checks host against QEMU).
 *
 * Accuracy: within a few float ulps of the true value (test_math checks
 * against the C library). Special values follow C99 Annex F where callers
 * can meet them: NaN in, NaN out; expf overflows to +inf and underflows to
 * 0; atan2f keeps the signs of zeros.
 */
#ifndef BSF_MATH_H
#define BSF_MATH_H

#include "bsf/bsf_config.h"

#include <float.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/*
 * Same bits on every target needs float arithmetic evaluated in float. A
 * compiler that evaluates float in double or long double (FLT_EVAL_METHOD
 * 1 or 2: GCC on s390x in ISO C mode, x87 without SSE) rounds intermediate
 * results differently and the frames would differ from the host's, so the
 * library refuses to build there rather than give different maps. The
 * flag: -fexcess-precision=fast or -std=gnu99 (GCC, e.g. s390x), -msse2
 * -mfpmath=sse (32-bit x86). bsf's CMake adds -fexcess-precision=fast when
 * that is enough; README, "Portability".
 */
#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error "bsf needs FLT_EVAL_METHOD == 0: add -fexcess-precision=fast (GCC) or -mfpmath=sse"
#endif

#include <math.h>
#include <stdint.h>

/*
 * floorf(x) with the same result for every float (-0 and the integers kept,
 * NaN in, NaN out), from one float-to-int conversion: newlib's floorf is a
 * software routine on the Cortex-M4F, and glibc's a call on x86-64 without
 * SSE4.1. test_math compares it with floorf on a large sample of floats.
 */
static inline float bsf_floorf(float x)
{
    if (fabsf(x) < 8388608.0f) {           /* below 2^23 a float may have a fraction */
        const float t = (float)(int32_t)x; /* x rounded toward zero */
        if (t == x) {
            return x; /* integral: keeps -0 */
        }
        return t > x ? t - 1.0f : t;
    }
    return x; /* integral already, infinite or NaN */
}

/* The binary32 bit pattern of v (memcpy: no aliasing questions). */
static inline uint32_t bsf_float_bits(float v)
{
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    return bits;
}

/* The float whose binary32 bit pattern is bits. */
static inline float bsf_bits_float(uint32_t bits)
{
    float v;
    memcpy(&v, &bits, sizeof v);
    return v;
}

/* Whether v is finite (not NaN, not +-inf): its exponent bits are not all
 * ones. The same answer as v == v && fabsf(v) <= FLT_MAX, in fewer
 * instructions on Cortex-M. */
static inline int bsf_finite_bits(float v)
{
    return (bsf_float_bits(v) & 0x7F800000u) != 0x7F800000u;
}

/* Internals of bsf_sinf, bsf_cosf and bsf_sincosf, inline so that a hot loop
 * (bsf_scan_to_points) pays no call: the same expressions give the same
 * bits wherever they are compiled (no contraction, FLT_EVAL_METHOD 0). */

/* pi/2 in three parts (Cody-Waite): k * each part is exact for |k| < 2^12,
 * so the reduced argument loses nothing for |x| up to about 6000. */
#define BSF_PIO2_1_F 1.5703125f
#define BSF_PIO2_2_F 4.83751296997070312500e-04f
#define BSF_PIO2_3_F 7.54978995489188216e-08f
#define BSF_TWO_OVER_PI_F 0.636619772367581f

/* sin and cos of r in [-pi/4, pi/4]: Taylor series, truncation below 2e-9. */
static inline float bsf_sin_kernel(float r)
{
    const float r2 = r * r;
    return r + r * r2 *
                   (-1.0f / 6.0f +
                    r2 * (1.0f / 120.0f + r2 * (-1.0f / 5040.0f + r2 * (1.0f / 362880.0f))));
}

static inline float bsf_cos_kernel(float r)
{
    const float r2 = r * r;
    return 1.0f + r2 * (-0.5f + r2 * (1.0f / 24.0f +
                                      r2 * (-1.0f / 720.0f +
                                            r2 * (1.0f / 40320.0f + r2 * (-1.0f / 3628800.0f)))));
}

/* Finite x = k * pi/2 + r with |r| <= about pi/4; returns r and k mod 4.
 * k = floor(x * 2/pi + 0.5) in integers while that fits (|x| below about
 * 1.3e7), which is the value floorf gives; beyond, the float is integral. */
static inline float bsf_trig_reduce(float x, unsigned *quadrant)
{
    const float t = x * BSF_TWO_OVER_PI_F + 0.5f;
    float k;
    if (fabsf(t) < 8388608.0f) {
        int32_t ki = (int32_t)t;
        if ((float)ki > t) {
            --ki; /* t < 0 with a fraction: toward zero went up */
        }
        k = (float)ki;                 /* never -0: t is never -0 */
        *quadrant = (unsigned)ki & 3u; /* two's complement: k mod 4 */
    } else {
        k = t;
        /* from 2^24 on, floats are even; from 2^25 on, multiples of 4 */
        *quadrant = fabsf(k) < 2147483648.0f ? (unsigned)(int32_t)k & 3u : 0u;
    }
    return ((x - k * BSF_PIO2_1_F) - k * BSF_PIO2_2_F) - k * BSF_PIO2_3_F;
}

static inline float bsf_clamp_unit(float v)
{
    return v > 1.0f ? 1.0f : (v < -1.0f ? -1.0f : v);
}

/** sin(x) and cos(x) from one range reduction: the same bits as bsf_sinf(x)
 * and bsf_cosf(x) (test_math checks), about half their combined cost. */
static inline void bsf_sincosf(float x, float *sin_x, float *cos_x)
{
    unsigned q;
    float r;
    float s;
    float c;
    float vs;
    float vc;
    if (!(fabsf(x) <= 3.402823466e38f)) {
        *sin_x = x - x; /* NaN for NaN and +-inf */
        *cos_x = x - x;
        return;
    }
    r = bsf_trig_reduce(x, &q);
    s = bsf_sin_kernel(r);
    c = bsf_cos_kernel(r);
    switch (q) {
    case 0u:
        vs = s;
        vc = c;
        break;
    case 1u:
        vs = c;
        vc = -s;
        break;
    case 2u:
        vs = -s;
        vc = -c;
        break;
    default:
        vs = -c;
        vc = s;
        break;
    }
    if (!(fabsf(r) <= 0.8f)) {
        /* only for |x| far beyond the accurate range: the kernels stay
         * within [-1, 1] for |r| <= 0.8 */
        vs = bsf_clamp_unit(vs);
        vc = bsf_clamp_unit(vc);
    }
    *sin_x = vs;
    *cos_x = vc;
}

/**
 * bsf_sincosf for |x| <= 16384 (the beam angles bsf_scan_to_points can form,
 * |x| <= 4 pi + 4096 pi): the same bits, without the checks that only larger
 * or non-finite x need. There t stays far below 2^23 and the reduction
 * leaves |r| < 0.79, so the clamp to [-1, 1] never acts. Larger x: wrong.
 */
static inline void bsf_sincosf_bounded(float x, float *sin_x, float *cos_x)
{
    const float t = x * BSF_TWO_OVER_PI_F + 0.5f;
    int32_t ki = (int32_t)t;
    float k = (float)ki;
    float r;
    float s;
    float c;
    if (k > t) {
        k -= 1.0f; /* floorf(t), as bsf_trig_reduce */
        --ki;
    }
    r = ((x - k * BSF_PIO2_1_F) - k * BSF_PIO2_2_F) - k * BSF_PIO2_3_F;
    s = bsf_sin_kernel(r);
    c = bsf_cos_kernel(r);
    /* quadrant k mod 4 in two steps (two tests, where a switch takes up
     * to three): odd k turns (s, c) by 90 degrees, k & 2 by 180; negating
     * twice gives the same bits as not negating */
    if (((unsigned)ki & 1u) != 0u) {
        const float t90 = c;
        c = -s;
        s = t90;
    }
    if (((unsigned)ki & 2u) != 0u) {
        s = -s;
        c = -c;
    }
    *sin_x = s;
    *cos_x = c;
}

/** sin(x), radians. Full accuracy for |x| <= 8192; finite in [-1, 1] for any finite x. */
float bsf_sinf(float x);

/** cos(x), radians. As bsf_sinf. */
float bsf_cosf(float x);

/** e^x: +inf above 88.72, 0 below -103.98, subnormal results in between. */
float bsf_expf(float x);

/*
 * Bounds on bsf_expf(x) for 0 <= x <= 1, from a few products: *lo <=
 * bsf_expf(x) <= *hi, and *hi is also at least bsf_exp_taylor4(x). A
 * threshold r(x) = k * bsf_expf(x) (k >= 0) then needs bsf_expf only for a
 * distance within about 1e-4 of it: monotonic rounding keeps k * lo <= k *
 * bsf_expf(x) <= k * hi in float. Why they hold: e^x lies between the
 * degree-4 Taylor sum and that sum plus e * x^5 / 120, and the margins of
 * 1e-5 cover the rounding of these sums and bsf_expf's error (about 1e-7).
 * Checked once on every float in [0, 1]; test_math checks every 997th.
 */
static inline float bsf_exp_taylor4(float x)
{
    return 1.0f + x * (1.0f + x * (0.5f + x * (0.16666667f + x * 0.041666668f)));
}

static inline void bsf_exp_bounds01(float x, float *lo, float *hi)
{
    const float t = bsf_exp_taylor4(x);
    const float x2 = x * x;
    *lo = t * 0.99999f;
    *hi = (t + 0.023f * (x2 * x2 * x)) * 1.00001f;
}

/** Angle of (x, y) in [-pi, pi], radians, as atan2f (signed zeros, infinities). */
float bsf_atan2f(float y, float x);

/** asin(x) in [-pi/2, pi/2] for |x| <= 1; NaN outside. */
float bsf_asinf(float x);

/* A float parameter's allowed range, for the parameter checks: the field's
 * byte offset in its struct, its upper bound, and which bounds are open.
 * The lower bound is always 0 (every checked float is a length, a count or
 * a ratio). A table of these is smaller code than written-out comparisons
 * (the extract + encode firmware's size budget). */
typedef struct {
    float hi;
    uint16_t offset;
    uint8_t open; /* BSF_RANGE_LO_OPEN | BSF_RANGE_HI_OPEN */
} bsf_float_range_t;

#define BSF_RANGE_LO_OPEN 1u /* value > 0, else value >= 0 */
#define BSF_RANGE_HI_OPEN 2u /* value < hi, else value <= hi */

/* 1 when each of the n fields of params that ranges name lies within its
 * range, else 0. NaN lies within none. */
static inline int bsf_floats_in_range_inline(const void *params, const bsf_float_range_t *ranges,
                                             size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        const bsf_float_range_t *r = &ranges[i];
        float v;
        memcpy(&v, (const unsigned char *)params + r->offset, sizeof v);
        /* written so that NaN fails both tests */
        if (!((r->open & BSF_RANGE_LO_OPEN) != 0u ? v > 0.0f : v >= 0.0f) ||
            !((r->open & BSF_RANGE_HI_OPEN) != 0u ? v < r->hi : v <= r->hi)) {
            return 0;
        }
    }
    return 1;
}

/* The compact build calls one copy; the speed build inlines it, where the
 * constant table folds into the comparisons it stands for. */
#if BSF_CONFIG_COMPACT
int bsf_floats_in_range(const void *params, const bsf_float_range_t *ranges, size_t n);
#else
#define bsf_floats_in_range bsf_floats_in_range_inline
#endif

#endif /* BSF_MATH_H */
