/* SPDX-License-Identifier: MIT */
/*
 * bsf_wire.h - internal: rules shared by the frame encoder and decoder
 * (docs/FORMAT.md sections "Integers" and "Control points").
 */
#ifndef BSF_WIRE_H
#define BSF_WIRE_H

#include <stddef.h>
#include <stdint.h>

#include "bsf/bsf_config.h"

/* Exp-Golomb orders of the fixed-parameter fields (FORMAT.md section 3). */
#define BSF_WIRE_K_SEQ 8u
#define BSF_WIRE_K_TIMESTAMP 20u
#define BSF_WIRE_K_POSE 10u
#define BSF_WIRE_K_STEP 4u
#define BSF_WIRE_K_N 6u
#define BSF_WIRE_K_TIME_US 5u
#define BSF_WIRE_K_FEATURES 2u
#define BSF_WIRE_K_M 1u
#define BSF_WIRE_K_GAP 2u
#define BSF_WIRE_K_SPAN 3u
#define BSF_WIRE_K_MISSING 0u
#define BSF_WIRE_K_E_CURVE 4u
/* Header extension (format version 2): beam count and cap-cut counters. */
#define BSF_WIRE_CUT_BITS 3u
#define BSF_WIRE_K_N_BEAMS 8u
#define BSF_WIRE_K_CUT_KEYPOINTS 2u
#define BSF_WIRE_K_CUT_SEGMENTS 2u
#define BSF_WIRE_K_CUT_POINTS 4u

/* Metadata frame (format version 2, type 2). */
#define BSF_WIRE_K_LIB_VERSION 1u
#define BSF_WIRE_K_METHOD 0u
#define BSF_WIRE_K_CAP_POINTS 8u
#define BSF_WIRE_K_CAP_KEYPOINTS 4u
#define BSF_WIRE_K_CAP_SEGMENTS 4u
#define BSF_WIRE_K_CAP_CTRL_PER_FEATURE 2u
#define BSF_WIRE_K_CAP_CTRL_POINTS 6u
/* The caps a metadata frame carries, in wire order: X(field of
 * bsf_metadata_t, this build's cap, Exp-Golomb order). A cap joins the
 * frame by a line here, a field and a format version (FORMAT.md). */
#define BSF_WIRE_META_CAPS(X)                                                                      \
    X(max_points, BSF_MAX_POINTS, BSF_WIRE_K_CAP_POINTS)                                           \
    X(max_keypoints, BSF_MAX_KEYPOINTS, BSF_WIRE_K_CAP_KEYPOINTS)                                  \
    X(max_segments, BSF_MAX_SEGMENTS, BSF_WIRE_K_CAP_SEGMENTS)                                     \
    X(max_ctrl_per_feature, BSF_MAX_CTRL_PER_FEATURE, BSF_WIRE_K_CAP_CTRL_PER_FEATURE)             \
    X(max_ctrl_points, BSF_MAX_CTRL_POINTS, BSF_WIRE_K_CAP_CTRL_POINTS)
#define BSF_WIRE_K_META_N_BEAMS 8u
#define BSF_WIRE_K_TIME_ORIGIN 40u
#define BSF_WIRE_K_SOURCE_LEN 3u
#define BSF_WIRE_META_U16_MAX 65535u
#define BSF_WIRE_METHOD_MAX 255u

/* Control point value classes, each with its own per-frame order 0..25. */
#define BSF_WIRE_CLASS_FIRST 0u  /* first point of a feature */
#define BSF_WIRE_CLASS_ANCHOR 1u /* next anchor minus previous anchor */
#define BSF_WIRE_CLASS_PREC 2u   /* precision point minus its prediction */
#define BSF_WIRE_N_CLASSES 3u
#define BSF_WIRE_K_CTRL_BITS 5u
#define BSF_WIRE_K_CTRL_MAX 25u /* order at which any value below 2^25 costs 26 bits */

/* Wire codes and units. */
#define BSF_WIRE_STEP_CODE_MAX 10000u
#define BSF_WIRE_E_CURVE_PER_M 2000.0f /* E_curve unit 0.5 mm */
#define BSF_WIRE_E_CURVE_CODE_MAX 2000000u
#define BSF_WIRE_TIME_US_MAX 4294967u /* UINT32_MAX ns, the range of bsf_stats_t.time_ns */
#define BSF_WIRE_POSE_MM_MAX 2000000000L
#define BSF_WIRE_THETA_PER_RAD 10430.378350470453f     /* 65536 / (2 pi) */
#define BSF_WIRE_RAD_PER_THETA 9.5873799242852573e-05f /* 2 pi / 65536 */

/* CRC-32C of any body (payload followed by its own CRC, little-endian). */
#define BSF_WIRE_CRC_RESIDUE 0x48674BC7u

static inline uint64_t bsf_wire_zigzag(int64_t v)
{
    /* (v << 1) ^ (v >> 63) without shifting a negative value. */
    return v < 0 ? ((uint64_t)(-(v + 1)) << 1) | 1u : (uint64_t)v << 1;
}

static inline int64_t bsf_wire_unzigzag(uint64_t u)
{
    return (u & 1u) ? -(int64_t)(u >> 1) - 1 : (int64_t)(u >> 1);
}

/*
 * Prediction of precision control point s (1..k) between anchors a and b
 * (quantised, one coordinate): a + round((b - a) * (2s - 1) / (2k)), ties
 * up, with floor division, i.e. the Greville abscissae of a uniform
 * clamped quadratic along the chord. Exact integer arithmetic so that
 * encoder and decoder agree on every platform.
 */
static inline int64_t bsf_wire_predict(int64_t a, int64_t b, uint32_t s, uint32_t k)
{
    const int64_t den = 2 * (int64_t)k;
    const int64_t num = (b - a) * (2 * (int64_t)s - 1) + (int64_t)k;
    int64_t q;
    if (num >= -(int64_t)INT32_MAX && num <= (int64_t)INT32_MAX && den <= (int64_t)INT32_MAX) {
        /* the usual sizes: one 32-bit division (a library call in 64 bits
         * on 32-bit targets), the same quotient and remainder */
        const int32_t num32 = (int32_t)num;
        const int32_t den32 = (int32_t)den;
        int32_t q32 = num32 / den32;
        if (num32 % den32 != 0 && num32 < 0) {
            --q32;
        }
        return a + q32;
    }
    q = num / den;
    if (num % den != 0 && num < 0) {
        --q;
    }
    return a + q;
}

/* Bits of v: 0 for 0, else 1 + floor(log2 v): the count-leading-zeros
 * instruction where the compiler has one (x86 BSR/LZCNT, Arm CLZ), else a
 * binary search; the encoder evaluates it for every value it writes. */
static inline unsigned bsf_wire_bitlen32(uint32_t v)
{
#if defined(__GNUC__) || defined(__clang__)
    return v == 0u ? 0u : 32u - (unsigned)__builtin_clz(v);
#else
    unsigned n = 0;
    unsigned half;
    for (half = 16u; half > 0u; half >>= 1) {
        if ((v >> half) != 0u) {
            v >>= half;
            n += half;
        }
    }
    return n + (unsigned)v;
#endif
}

/* Bit length of v < 2^31 as floor(log2(2v + 1)): 2v + 1 is never 0, so the
 * count needs no test for 0 (x86 BSR, Arm CLZ). */
static inline unsigned bsf_wire_bitlen31(uint32_t v)
{
#if defined(__GNUC__) || defined(__clang__)
    return 31u ^ (unsigned)__builtin_clz(2u * v + 1u);
#else
    return bsf_wire_bitlen32(v);
#endif
}

static inline unsigned bsf_wire_bitlen(uint64_t v)
{
    const uint32_t hi = (uint32_t)(v >> 32);
    return hi != 0u ? 32u + bsf_wire_bitlen32(hi) : bsf_wire_bitlen32((uint32_t)v);
}

/* Length in bits of the Exp-Golomb code of order k of v (v >> k < 2^63). */
static inline unsigned bsf_wire_eg_bits(uint64_t v, unsigned k)
{
    return 2u * bsf_wire_bitlen((v >> k) + 1u) - 1u + k;
}

/*
 * Costs of one control point class at every order from one pass over its
 * values. The code of v at order k is v + 2^k written in 2 * bitlen(v + 2^k)
 * - 1 - k bits. With L = bitlen(v) and m = bitlen(v ^ (2^L - 1)) (the bits
 * below v's leading run of ones), bitlen(v + 2^k) is k + 1 for k >= L, L + 1
 * for m <= k < L (the carry runs through the ones) and L for k < m. So the
 * counts of L and of m give every order's total exactly.
 */
/* Bit lengths 0..26: the encoder's control point values stay below 2^26
 * (quantised coordinates within BSF_QUANT_MAX_STEPS = 2^23 - 1, so deltas
 * and residuals within 2^24, zigzag within 2^25). */
#define BSF_WIRE_EG_HIST 27u

/* Counts per class: a frame has at most 2 * BSF_MAX_CTRL_POINTS values. */
#if BSF_MAX_CTRL_POINTS <= 32767
typedef uint16_t bsf_wire_eg_count_t;
#else
typedef uint32_t bsf_wire_eg_count_t;
#endif

typedef struct {
    bsf_wire_eg_count_t n_len[BSF_WIRE_EG_HIST];   /* values per bit length L */
    bsf_wire_eg_count_t n_below[BSF_WIRE_EG_HIST]; /* values per m */
    uint32_t n;                                    /* values */
    uint32_t sum_len;                              /* sum of their L */
} bsf_wire_eg_tally_t;

/* One value v < 2^26. */
static inline void bsf_wire_eg_tally_add32(bsf_wire_eg_tally_t *t, uint32_t v)
{
    const unsigned len = bsf_wire_bitlen31(v);
    /* the len low bits set (none for v = 0), with no shift by 32 */
    const uint32_t ones = (0xFFFFFFFFu >> 1) >> (31u - len);
    t->n_len[len] += 1u;
    t->n_below[bsf_wire_bitlen31(v ^ ones)] += 1u;
    t->n += 1u;
    t->sum_len += len;
}

static inline void bsf_wire_eg_tally_add(bsf_wire_eg_tally_t *t, uint64_t v)
{
    bsf_wire_eg_tally_add32(t, (uint32_t)v);
}

/*
 * The totals follow from counts: with A(k) values of L <= k, B(k) values of
 * m <= k (m <= L, so B(k) - A(k) values carry at order k) and T(k) = the sum
 * of L over the values with L > k plus k A(k), the code lengths 2
 * bitlen(v + 2^k) - 1 - k sum to 2 T(k) + 2 B(k) - n (1 + k), where
 * bitlen(v + 2^k) is max(L, k + 1) plus one for a carry. T(0) is the sum of
 * all L and T(k) = T(k - 1) + A(k - 1).
 */

/* The number of values and the sum of their L (kept as they are tallied). */
static inline uint32_t bsf_wire_eg_tally_sums(const bsf_wire_eg_tally_t *t, uint32_t *sum_len)
{
    *sum_len = t->sum_len;
    return t->n;
}

/* cost[k] for k = 0..k_max (<= 25): total bits of the tallied values at order k. */
static inline void bsf_wire_eg_tally_costs(const bsf_wire_eg_tally_t *t, unsigned k_max,
                                           uint32_t *cost)
{
    uint32_t sum; /* T(k) */
    const uint32_t n = bsf_wire_eg_tally_sums(t, &sum);
    uint32_t a = 0;
    uint32_t b = 0;
    unsigned k;
    for (k = 0; k <= k_max; ++k) {
        sum += a;
        a += t->n_len[k];
        b += t->n_below[k];
        cost[k] = 2u * (sum + b) - n * (1u + k);
    }
}

/*
 * The order 0..BSF_WIRE_K_CTRL_MAX with the fewest bits for the tallied
 * values (ties to the smaller order), and those bits in *bits. Every code
 * at order k takes at least k + 1 bits, so the search stops once n (k + 1)
 * reaches the best total. That also ends it at most one order past the
 * longest value's bit length L: at k >= L every code takes exactly k + 1
 * bits, so order L costs n (L + 1), which the next floor n (L + 2) exceeds.
 */
static inline unsigned bsf_wire_eg_tally_best(const bsf_wire_eg_tally_t *t, uint32_t *bits)
{
    uint32_t sum;
    const uint32_t n = bsf_wire_eg_tally_sums(t, &sum);
    uint32_t a = t->n_len[0];                       /* A(k - 1) */
    uint32_t cost = 2u * (sum + t->n_below[0]) - n; /* order 0 */
    uint32_t best_cost = cost;
    uint32_t floor_bits = 2u * n; /* n (k + 1) for the next k */
    unsigned best = 0;
    unsigned k;
    for (k = 1; k <= BSF_WIRE_K_CTRL_MAX && floor_bits < best_cost; ++k) {
        /* cost(k) - cost(k - 1) = 2 (A(k - 1) + B(k) - B(k - 1)) - n */
        cost += 2u * (a + t->n_below[k]) - n;
        a += t->n_len[k];
        if (cost < best_cost) {
            best_cost = cost;
            best = k;
        }
        floor_bits += n;
    }
    *bits = best_cost;
    return best;
}

/*
 * COBS of a body of n bytes takes 1 + n + F bytes (without the 0x00
 * delimiter), F the number of full blocks (254 data bytes, code 0xFF):
 * bsf_cobs_full_blocks counts them (bsf_cobs.c). bsf_cobs_encode_in_place
 * turns the body buf[offset .. offset + n - 1], offset >= 1 + F, into its
 * code in buf[0 ..] and returns the code's length; with offset = 1 + F the
 * code ends where the body ended. The output never overtakes the input it
 * still has to read.
 */
size_t bsf_cobs_full_blocks(const uint8_t *body, size_t n);
size_t bsf_cobs_encode_in_place(uint8_t *buf, size_t offset, size_t n);

/*
 * A metadata source name: well-formed UTF-8 (RFC 3629: shortest form, no
 * surrogates, at most U+10FFFF) without control characters (C0, DEL, C1),
 * so that it prints safely. Returns 1 when s[0..len-1] is acceptable.
 */
static inline int bsf_wire_source_ok(const uint8_t *s, size_t len)
{
    size_t i = 0;
    while (i < len) {
        const uint8_t b = s[i];
        uint32_t cp;
        size_t n;
        size_t j;
        if (b < 0x80u) {
            if (b < 0x20u || b == 0x7Fu) {
                return 0;
            }
            ++i;
            continue;
        }
        if (b >= 0xC2u && b <= 0xDFu) {
            n = 1u;
            cp = b & 0x1Fu;
        } else if (b >= 0xE0u && b <= 0xEFu) {
            n = 2u;
            cp = b & 0x0Fu;
        } else if (b >= 0xF0u && b <= 0xF4u) {
            n = 3u;
            cp = b & 0x07u;
        } else {
            return 0; /* continuation byte, overlong lead C0/C1, or above U+10FFFF */
        }
        if (len - i <= n) {
            return 0;
        }
        for (j = 1u; j <= n; ++j) {
            if ((s[i + j] & 0xC0u) != 0x80u) {
                return 0;
            }
            cp = (cp << 6) | (s[i + j] & 0x3Fu);
        }
        if ((n == 2u && cp < 0x800u) || (n == 3u && cp < 0x10000u) || cp > 0x10FFFFu ||
            (cp >= 0xD800u && cp <= 0xDFFFu) || (cp >= 0x80u && cp <= 0x9Fu)) {
            return 0;
        }
        i += n + 1u;
    }
    return 1;
}

#endif /* BSF_WIRE_H */
