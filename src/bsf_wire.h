/*
 * bsf_wire.h - internal: rules shared by the frame encoder and decoder
 * (docs/FORMAT.md sections "Integers" and "Control points").
 */
#ifndef BSF_WIRE_H
#define BSF_WIRE_H

#include <stdint.h>

/* Flag bits of payload byte 1. */
#define BSF_WIRE_FLAG_POSE 0x01u
#define BSF_WIRE_FLAGS_KNOWN 0x01u

/* Feature descriptor bits. */
#define BSF_WIRE_DESC_KIND 0x01u
#define BSF_WIRE_DESC_VERTICES 0x02u
#define BSF_WIRE_DESC_MISSING 0x04u
#define BSF_WIRE_DESC_SHIFT 3u

/* Wire codes and units. */
#define BSF_WIRE_STEP_CODE_MAX 10000u
#define BSF_WIRE_E_CURVE_CODE_MAX 10000000u
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
    int64_t q = num / den;
    if (num % den != 0 && num < 0) {
        --q;
    }
    return a + q;
}

#endif /* BSF_WIRE_H */
