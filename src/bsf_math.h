/* SPDX-License-Identifier: MIT */
/*
 * bsf_math.h - internal: the transcendental functions the library needs,
 * computed with + - * / and sqrtf only.
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

#include <float.h>

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

/** sin(x), radians. Full accuracy for |x| <= 8192; finite in [-1, 1] for any finite x. */
float bsf_sinf(float x);

/** cos(x), radians. As bsf_sinf. */
float bsf_cosf(float x);

/** e^x: +inf above 88.72, 0 below -103.98, subnormal results in between. */
float bsf_expf(float x);

/** Angle of (x, y) in [-pi, pi], radians, as atan2f (signed zeros, infinities). */
float bsf_atan2f(float y, float x);

/** asin(x) in [-pi/2, pi/2] for |x| <= 1; NaN outside. */
float bsf_asinf(float x);

#endif /* BSF_MATH_H */
