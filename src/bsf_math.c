/* SPDX-License-Identifier: MIT */
#include "bsf_math.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#define BSF_M_PI_F 3.14159265358979f
#define BSF_M_PI_2_F 1.57079632679490f
#define BSF_M_PI_6_F 0.523598775598299f
#define BSF_M_SQRT3_F 1.73205080756888f
/* tan(pi/12): above it, atan is reduced by pi/6 */
#define BSF_M_TAN_PI_12_F 0.267949192431123f

/* ln 2 in two parts: k * LN2_HI is exact for |k| <= 256. */
#define LN2_HI 6.93145751953125e-01f
#define LN2_LO 1.42860682030941723212e-06f
#define LOG2E 1.44269504088896f

static float pow2i(int k)
{
    /* 2^k for k in [-126, 127], built from its bits: exact everywhere. */
    const uint32_t bits = (uint32_t)(k + 127) << 23;
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* sin(x) turned on by quarter_turns quarter turns: cos(x) is
 * sin(x + pi/2), one quarter turn on in the reduced argument's quadrant, so
 * both share one copy of the reduction and the kernels (code size). */
static float sin_turned(float x, unsigned quarter_turns)
{
    unsigned q;
    float r;
    float v;
    if (!(fabsf(x) <= 3.402823466e38f)) {
        return x - x; /* NaN for NaN and +-inf */
    }
    r = bsf_trig_reduce(x, &q);
    switch ((q + quarter_turns) & 3u) {
    case 0u: v = bsf_sin_kernel(r); break;
    case 1u: v = bsf_cos_kernel(r); break;
    case 2u: v = -bsf_sin_kernel(r); break;
    default: v = -bsf_cos_kernel(r); break;
    }
    return bsf_clamp_unit(v);
}

float bsf_sinf(float x)
{
    return sin_turned(x, 0u);
}

float bsf_cosf(float x)
{
    return sin_turned(x, 1u);
}

float bsf_expf(float x)
{
    float k;
    float r;
    float y;
    int ki;
    if (x != x) {
        return x;
    }
    if (x > 88.7228f) {
        return HUGE_VALF;
    }
    if (x < -103.98f) {
        return 0.0f;
    }
    k = bsf_floorf(x * LOG2E + 0.5f);
    r = (x - k * LN2_HI) - k * LN2_LO; /* |r| <= about ln2 / 2 */
    /* Taylor series to degree 7: truncation below 5e-9 relative */
    y = 1.0f +
        r * (1.0f + r * (0.5f + r * (1.0f / 6.0f +
                                     r * (1.0f / 24.0f +
                                          r * (1.0f / 120.0f +
                                               r * (1.0f / 720.0f + r * (1.0f / 5040.0f)))))));
    ki = (int)k;
    if (ki > 127) {
        y *= 2.0f;
        ki -= 1;
    } else if (ki < -126) {
        y *= pow2i(-64); /* the subnormal range, scaled in two exact steps */
        ki += 64;
    }
    return y * pow2i(ki);
}

/* atan(t) for 0 <= t <= 1. */
static float atan_unit(float t)
{
    float base = 0.0f;
    float t2;
    if (t > BSF_M_TAN_PI_12_F) {
        /* atan(t) = pi/6 + atan((t*sqrt3 - 1) / (t + sqrt3)), |new t| <= tan(pi/12) */
        t = (t * BSF_M_SQRT3_F - 1.0f) / (t + BSF_M_SQRT3_F);
        base = BSF_M_PI_6_F;
    }
    t2 = t * t;
    /* alternating Taylor series to t^13: truncation below 3e-9 */
    return base +
           (t + t * t2 *
                    (-1.0f / 3.0f +
                     t2 * (1.0f / 5.0f +
                           t2 * (-1.0f / 7.0f + t2 * (1.0f / 9.0f + t2 * (-1.0f / 11.0f +
                                                                          t2 * (1.0f / 13.0f)))))));
}

float bsf_atan2f(float y, float x)
{
    const float ax = fabsf(x);
    const float ay = fabsf(y);
    float a;
    if (x != x || y != y) {
        return x + y;
    }
    if (ay == 0.0f && ax == 0.0f) {
        a = 0.0f;
    } else if (ax == ay) {
        a = 0.25f * BSF_M_PI_F; /* also both infinite */
    } else if (ay > ax) {
        a = BSF_M_PI_2_F - atan_unit(ax / ay);
    } else {
        a = atan_unit(ay / ax);
    }
    if (signbit(x)) {
        a = BSF_M_PI_F - a;
    }
    return signbit(y) ? -a : a;
}

float bsf_asinf(float x)
{
    if (!(fabsf(x) <= 1.0f)) {
        return NAN; /* out of the domain, or NaN */
    }
    return bsf_atan2f(x, sqrtf((1.0f - x) * (1.0f + x)));
}

#if BSF_CONFIG_COMPACT
int bsf_floats_in_range(const void *params, const bsf_float_range_t *ranges, size_t n)
{
    return bsf_floats_in_range_inline(params, ranges, n);
}
#endif
