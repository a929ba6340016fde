/* SPDX-License-Identifier: MIT */
/*
 * fuzz_input.h - the fuzzer's bytes read as little-endian values, for the map
 * harnesses; past the end every byte reads as 0, so any input is a whole one.
 */
#ifndef BSF_FUZZ_INPUT_H
#define BSF_FUZZ_INPUT_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

typedef struct {
    const uint8_t *p;
    size_t n;
} input_t;

static inline uint8_t take1(input_t *in)
{
    uint8_t v = 0u;
    if (in->n > 0u) {
        v = in->p[0];
        ++in->p;
        --in->n;
    }
    return v;
}

static inline uint16_t take2(input_t *in)
{
    const uint16_t lo = take1(in);
    return (uint16_t)(lo | ((uint16_t)take1(in) << 8));
}

/* A float from raw bits: NaN, infinities and subnormals included. */
static inline float take_raw(input_t *in)
{
    uint32_t bits = take2(in);
    float f;
    bits |= (uint32_t)take2(in) << 16;
    memcpy(&f, &bits, sizeof f);
    return f;
}

#endif
