/* SPDX-License-Identifier: MIT */
/*
 * bsf_compact.h - internal: which helpers the compact build variant
 * (BSF_CONFIG_COMPACT, size-optimised builds) keeps as one out-of-line copy
 * and which it inlines into their callers, where GCC's size heuristics
 * choose the larger code (measured on the extract + encode firmware,
 * docs/PERFORMANCE.md). Other builds leave both choices to the compiler.
 * Neither changes a result: the same operations run in the same order.
 */
#ifndef BSF_COMPACT_H
#define BSF_COMPACT_H

#include "bsf/bsf_config.h"

#if BSF_CONFIG_COMPACT && (defined(__GNUC__) || defined(__clang__))
/* one copy, called: inlined at several sites it costs more than the calls */
#define BSF_COMPACT_NOINLINE __attribute__((noinline))
/* inlined: the call costs more than the body (one or two callers) */
#define BSF_COMPACT_INLINE inline __attribute__((always_inline))
#else
#define BSF_COMPACT_NOINLINE
#define BSF_COMPACT_INLINE
#endif

#endif /* BSF_COMPACT_H */
