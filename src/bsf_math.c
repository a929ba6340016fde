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

/* pi/2 in three parts (Cody-Waite): k * each part is exact for |k| < 2^12,
 * so the reduced argument loses nothing for |x| up to about 6000. */
#define PIO2_1 1.5703125f
#define PIO2_2 4.83751296997070312500e-04f
#define PIO2_3 7.54978995489188216e-08f
#define TWO_OVER_PI 0.636619772367581f

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

/* sin and cos of r in [-pi/4, pi/4]: Taylor series, truncation below 2e-9. */
static float sin_kernel(float r)
{
    const float r2 = r * r;
    return r + r * r2 *
                   (-1.0f / 6.0f +
                    r2 * (1.0f / 120.0f + r2 * (-1.0f / 5040.0f + r2 * (1.0f / 362880.0f))));
}

static float cos_kernel(float r)
{
    const float r2 = r * r;
    return 1.0f + r2 * (-0.5f + r2 * (1.0f / 24.0f +
                                      r2 * (-1.0f / 720.0f +
                                            r2 * (1.0f / 40320.0f + r2 * (-1.0f / 3628800.0f)))));
}

/* x = k * pi/2 + r with |r| <= about pi/4; returns r and the quadrant k mod 4. */
static float reduce(float x, unsigned *quadrant)
{
    const float k = floorf(x * TWO_OVER_PI + 0.5f);
    const float r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    /* k is an integer-valued float; its low two bits pick the quadrant */
    const float k4 = k - 4.0f * floorf(k * 0.25f);
    *quadrant = (unsigned)k4 & 3u;
    return r;
}

static float clamp_unit(float v)
{
    return v > 1.0f ? 1.0f : (v < -1.0f ? -1.0f : v);
}

float bsf_sinf(float x)
{
    unsigned q;
    float r;
    float v;
    if (!(fabsf(x) <= 3.402823466e38f)) {
        return x - x; /* NaN for NaN and +-inf */
    }
    r = reduce(x, &q);
    switch (q) {
    case 0u: v = sin_kernel(r); break;
    case 1u: v = cos_kernel(r); break;
    case 2u: v = -sin_kernel(r); break;
    default: v = -cos_kernel(r); break;
    }
    return clamp_unit(v);
}

float bsf_cosf(float x)
{
    unsigned q;
    float r;
    float v;
    if (!(fabsf(x) <= 3.402823466e38f)) {
        return x - x;
    }
    r = reduce(x, &q);
    switch (q) {
    case 0u: v = cos_kernel(r); break;
    case 1u: v = -sin_kernel(r); break;
    case 2u: v = -cos_kernel(r); break;
    default: v = sin_kernel(r); break;
    }
    return clamp_unit(v);
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
    k = floorf(x * LOG2E + 0.5f);
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
