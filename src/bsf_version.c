/* SPDX-License-Identifier: MIT */
#include <float.h>

#include "bsf/bsf_version.h"

/* Build settings the library's results depend on, checked once here so that
 * a build that copies src/ into its own makefile cannot get them wrong
 * silently (README, "Copy the sources"). */
#ifdef __FAST_MATH__
#error "bsf must not be built with -ffast-math or -Ofast: its input checks rely on NaN and infinity"
#endif
#if defined(FLT_EVAL_METHOD) && FLT_EVAL_METHOD > 0
#error "bsf needs FLT_EVAL_METHOD 0 (float math in float): on 32-bit x86 use -msse2 -mfpmath=sse"
#endif

const char *bsf_version(void)
{
    return BSF_VERSION_STRING;
}
