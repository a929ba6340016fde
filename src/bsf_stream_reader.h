/* SPDX-License-Identifier: MIT */
/*
 * bsf_stream_reader.h - internal: the byte machinery every frame decoder
 * shares: a bit reader over a payload whose CRC has been checked, reading
 * fields (u(n), Exp-Golomb, zigzag, floats) most significant bit first with
 * every value bounded, and the type of a frame parser, which
 * bsf_stream_decode.c dispatches to by frame type (the parsers are listed in
 * bsf_frame_parsers.h; docs/DESIGN.md, Stream design; docs/FORMAT.md for
 * the fields).
 */
#ifndef BSF_STREAM_READER_H
#define BSF_STREAM_READER_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "bsf/bsf_stream.h"
#include "bsf_wire.h"

/* Bit reader over the payload after byte 0, most significant bit first. */
typedef struct {
    const uint8_t *p;
    size_t len;     /* bytes */
    size_t bit_pos; /* bits consumed */
} reader_t;

static inline int get_bit(reader_t *r, uint32_t *bit)
{
    if (r->bit_pos >= 8u * r->len) {
        return 0;
    }
    *bit = (uint32_t)(r->p[r->bit_pos >> 3] >> (7u - (r->bit_pos & 7u))) & 1u;
    ++r->bit_pos;
    return 1;
}

/* n (<= 32) bits as an unsigned number. */
static inline int get_bits(reader_t *r, unsigned n, uint32_t *v)
{
    uint32_t value = 0;
    unsigned i;
    for (i = 0; i < n; ++i) {
        uint32_t bit;
        if (!get_bit(r, &bit)) {
            return 0;
        }
        value = (value << 1) | bit;
    }
    *v = value;
    return 1;
}

/*
 * An Exp-Golomb code of order k (k <= 25) whose value is at most max
 * (max >> k < 2^63). The run of leading zeros is cut off as soon as it is
 * too long for max, so the work per code is bounded.
 */
static inline int get_eg(reader_t *r, unsigned k, uint64_t max, uint64_t *v)
{
    const unsigned max_zeros = bsf_wire_bitlen((max >> k) + 1u) - 1u;
    unsigned zeros = 0;
    uint64_t u = 1u;
    uint64_t value;
    uint32_t bit;
    unsigned i;

    for (;;) {
        if (!get_bit(r, &bit)) {
            return 0;
        }
        if (bit != 0u) {
            break;
        }
        if (++zeros > max_zeros) {
            return 0;
        }
    }
    for (i = 0; i < zeros; ++i) {
        if (!get_bit(r, &bit)) {
            return 0;
        }
        u = (u << 1) | bit;
    }
    if (u - 1u > (max >> k)) {
        return 0;
    }
    value = u - 1u;
    for (i = 0; i < k; ++i) {
        if (!get_bit(r, &bit)) {
            return 0;
        }
        value = (value << 1) | bit;
    }
    if (value > max) {
        return 0;
    }
    *v = value;
    return 1;
}

static inline int get_u32(reader_t *r, unsigned k, uint32_t max, uint32_t *v)
{
    uint64_t u;
    if (!get_eg(r, k, max, &u)) {
        return 0;
    }
    *v = (uint32_t)u;
    return 1;
}

/* A zigzag Exp-Golomb code whose magnitude is at most max_abs. */
static inline int get_signed(reader_t *r, unsigned k, int64_t max_abs, int64_t *v)
{
    uint64_t u;
    if (!get_eg(r, k, 2u * (uint64_t)max_abs, &u)) {
        return 0;
    }
    *v = bsf_wire_unzigzag(u);
    return 1;
}

/* A float sent as its IEEE-754 binary32 bit pattern; 0 when not finite. */
static inline int get_float(reader_t *r, float *v)
{
    uint32_t hi;
    uint32_t lo;
    uint32_t u;
    if (!get_bits(r, 16u, &hi) || !get_bits(r, 16u, &lo)) {
        return 0;
    }
    u = (hi << 16) | lo;
    if ((u & 0x7F800000u) == 0x7F800000u) {
        return 0; /* infinity or NaN */
    }
    memcpy(v, &u, sizeof *v);
    return 1;
}

/* Only zero padding up to the end of the last byte may follow. */
static inline int padding_ok(reader_t *r)
{
    uint32_t pad;
    return 8u * r->len - r->bit_pos < 8u &&
           get_bits(r, (unsigned)(8u * r->len - r->bit_pos), &pad) && pad == 0u;
}

/*
 * A frame type's parser: the payload after byte 0 of a frame of this type
 * and format version, whose CRC has been checked. With out == NULL it only
 * validates; with out it fills every field of *out (the frame's header
 * fields too), and then cannot fail (same bytes). Returns BSF_OK,
 * BSF_ERR_FORMAT or BSF_ERR_CAPACITY.
 */
typedef bsf_status_t (*bsf_frame_parse_fn)(reader_t *r, unsigned version, bsf_frame_t *out);

#endif /* BSF_STREAM_READER_H */
