/* SPDX-License-Identifier: MIT */
/*
 * bsf_stream_writer.h - internal: the byte machinery every frame encoder
 * shares, apart from what any frame means.
 *
 * - The bit writer: fields (u(n), Exp-Golomb, floats) written most
 *   significant bit first, or only counted (a costing run), into a buffer or
 *   a small chunk that the streaming path hands on.
 * - The frame job: a frame type supplies two functions (check and bound its
 *   input; its payload through a writer) and bsf_enc_job_encode or
 *   bsf_enc_job_encode_sink turns them into a frame: payload, CRC-32C, COBS
 *   and the 0x00 delimiter, written straight into a buffer that holds the
 *   bound or streamed to a counter, a buffer or a sink (bsf_stream_writer.c).
 *
 * A new frame type is a file of its own that fills a bsf_enc_job_t; it
 * touches neither this header nor the other frame types (docs/DESIGN.md,
 * Stream design; the wire rules are in docs/FORMAT.md).
 */
#ifndef BSF_STREAM_WRITER_H
#define BSF_STREAM_WRITER_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "bsf/bsf_stream.h"
#include "bsf_math.h"
#include "bsf_wire.h"

/* ---- Bit writer ---------------------------------------------------------- */

/* The hot paths inline their helpers so that the writer's state lives in
 * registers; the compact variant (BSF_CONFIG_COMPACT) leaves that to the
 * compiler. */
#if (defined(__GNUC__) || defined(__clang__)) && !BSF_CONFIG_COMPACT
#define ENC_INLINE static inline __attribute__((always_inline))
#else
#define ENC_INLINE static inline
#endif

#define CHUNK_BYTES 32u /* streaming path: payload bytes handed on at a time */

/*
 * The payload's bits, most significant first, gather in acc and leave as
 * whole big-endian 32-bit words. A run copies this into a local, so that it
 * stays in registers. In a costing run nothing is written: bits sums the
 * fields' lengths.
 */
#if UINTPTR_MAX > 0xFFFFFFFFu && !BSF_CONFIG_COMPACT
/* 64-bit hosts: a field that completes a word stays whole in acc, and the
 * word is the 32 bits above the field's rest (fewer shifts per word). */
#define ENC_ACC64 1
typedef uint64_t acc_t;
#else
typedef uint32_t acc_t;
#endif

struct bsf_cobs_out; /* the streaming output (bsf_stream_writer.c) */

typedef struct {
    uint8_t *p;    /* the next word goes here */
    uint8_t *end;  /* words must end at or before this */
    acc_t acc;     /* pending bits in the low 32 - room bits (higher bits: leftovers) */
    unsigned room; /* free bits in acc, 1..32 */
    uint32_t bits; /* costing run: payload bits so far */
#if BSF_CONFIG_COMPACT
    int costing; /* a costing run (see ENC_COSTING) */
#endif
} bits_t;

/* Where the words go. */
typedef struct {
    bits_t b;
    struct bsf_cobs_out *out; /* streaming path; NULL when writing straight into a buffer */
    uint8_t *end;             /* the end after a spill */
    int overflow;             /* direct writing reached its end (a planning bug: never written) */
    uint8_t chunk[CHUNK_BYTES];
} writer_t;

/* A writer for a costing run (only counting), or for writing to out
 * (streaming) or straight to start .. end. */
static inline void writer_init(writer_t *w, int costing, struct bsf_cobs_out *out, uint8_t *start,
                               uint8_t *end)
{
#if BSF_CONFIG_COMPACT
    w->b.costing = costing;
#else
    (void)costing;
#endif
    w->out = out;
    w->overflow = 0;
    w->b.acc = 0u;
    w->b.room = 32u;
    w->b.bits = 0u;
    if (start != NULL) {
        w->b.p = start;
        w->b.end = end;
    } else {
        w->b.p = w->chunk;
        w->b.end = w->chunk + CHUNK_BYTES;
    }
}

ENC_INLINE void store_be32(uint8_t *p, uint32_t v)
{
#if defined(__BYTE_ORDER__) && defined(__ORDER_BIG_ENDIAN__) &&                                    \
    __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
    memcpy(p, &v, 4u);
#elif defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) &&                               \
    __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__ && (defined(__GNUC__) || defined(__clang__))
    v = __builtin_bswap32(v);
    memcpy(p, &v, 4u);
#else
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
#endif
}

/* No room for a word at p: hand the chunk on (streaming), or stop writing
 * (direct). Returns where the next word goes; w->end is its end. */
uint8_t *bsf_writer_spill(writer_t *w, uint8_t *p);

ENC_INLINE void put_word(writer_t *w, bits_t *b, uint32_t word)
{
    if ((size_t)(b->end - b->p) < 4u) {
        b->p = bsf_writer_spill(w, b->p);
        b->end = w->end;
    }
    store_be32(b->p, word);
    b->p += 4;
}

/* The n (0..31) bits of v (v < 2^n). */
ENC_INLINE void put_bits(writer_t *w, bits_t *b, uint32_t v, unsigned n)
{
#ifdef ENC_ACC64
    b->acc = (b->acc << n) | v;
    if (n < b->room) {
        b->room -= n;
    } else {
        const unsigned rest = n - b->room; /* bits of v for the next word; room <= n <= 31 */
        put_word(w, b, (uint32_t)(b->acc >> rest));
        b->room = 32u - rest;
    }
#else
    if (n < b->room) {
        b->acc = (b->acc << n) | v;
        b->room -= n;
    } else {
        const unsigned rest = n - b->room; /* bits of v for the next word; room <= n <= 31 */
        put_word(w, b, (b->acc << b->room) | (v >> rest));
        b->acc = v; /* the bits of v above rest leave with the next word's shifts */
        b->room = 32u - rest;
    }
#endif
}

/* floor(log2(c)) for 1 <= c < 2^31 (x86 BSR). */
ENC_INLINE unsigned log2_nz(uint32_t c)
{
#if defined(__GNUC__) || defined(__clang__)
    return 31u ^ (unsigned)__builtin_clz(c);
#else
    return bsf_wire_bitlen31(c) - 1u;
#endif
}

/* Exp-Golomb code of order k (<= 25) of v < 2^30: v + 2^k in 2 b - 1 - k
 * bits, b its bit length (b - 1 - k leading zeros, then v + 2^k). */
ENC_INLINE void put_eg(writer_t *w, bits_t *b, uint32_t v, unsigned k)
{
    const uint32_t c = v + ((uint32_t)1 << k);
    const unsigned lg = log2_nz(c);
    const unsigned len = 2u * lg + 1u - k;
    if (len < 32u) {
        put_bits(w, b, c, len);
    } else {
        put_bits(w, b, 0u, lg - k);
        put_bits(w, b, c, lg + 1u);
    }
}

ENC_INLINE unsigned eg_len(uint32_t v, unsigned k)
{
    return 2u * log2_nz(v + ((uint32_t)1 << k)) + 1u - k;
}

/*
 * Whether a run only counts: the callers' costing argument, a constant once
 * the field functions are inlined into a run of either kind. The compact
 * variant keeps one copy of each field function instead, and takes the
 * kind from the bits (set by writer_init), so that they take four arguments,
 * all in registers; the costing argument is then left out.
 */
#if BSF_CONFIG_COMPACT
#define ENC_COSTING_PARAM
#define ENC_COSTING(b) ((b)->costing)
#define field_u(w, b, costing, v, n) field_u_(w, b, v, n)
#define field_eg(w, b, costing, v, k) field_eg_(w, b, v, k)
#define field_eg64(w, b, costing, v, k) field_eg64_(w, b, v, k)
#define field_float(w, b, costing, v) field_float_(w, b, v)
#define field_u64(w, b, costing, v, n) field_u64_(w, b, v, n)
#else
#define ENC_COSTING_PARAM int costing,
#define ENC_COSTING(b) costing
#define field_u(w, b, costing, v, n) field_u_(w, b, costing, v, n)
#define field_eg(w, b, costing, v, k) field_eg_(w, b, costing, v, k)
#define field_eg64(w, b, costing, v, k) field_eg64_(w, b, costing, v, k)
#define field_float(w, b, costing, v) field_float_(w, b, costing, v)
#define field_u64(w, b, costing, v, n) field_u64_(w, b, costing, v, n)
#endif

/* Fields, written or (costing) counted: u(n) with n <= 31. */
ENC_INLINE void field_u_(writer_t *w, bits_t *b, ENC_COSTING_PARAM uint32_t v, unsigned n)
{
    if (ENC_COSTING(b)) {
        b->bits += n;
    } else {
        put_bits(w, b, v, n);
    }
}

/* EGk of v < 2^30, k <= 25. */
ENC_INLINE void field_eg_(writer_t *w, bits_t *b, ENC_COSTING_PARAM uint32_t v, unsigned k)
{
    if (ENC_COSTING(b)) {
        b->bits += eg_len(v, k);
    } else {
        put_eg(w, b, v, k);
    }
}

/* Two EG fields, v0 (order k0) then v1 (order k1), each v < 2^30 and k <= 25:
 * one field when both codes fit in 31 bits together (feature fields). */
#if !BSF_CONFIG_COMPACT
ENC_INLINE void field_eg2(writer_t *w, bits_t *b, int costing, uint32_t v0, unsigned k0,
                          uint32_t v1, unsigned k1)
{
    const uint32_t c0 = v0 + ((uint32_t)1 << k0);
    const uint32_t c1 = v1 + ((uint32_t)1 << k1);
    const unsigned len0 = 2u * log2_nz(c0) + 1u - k0;
    const unsigned len1 = 2u * log2_nz(c1) + 1u - k1;
    if (costing) {
        b->bits += len0 + len1;
    } else if (len0 + len1 < 32u) {
        put_bits(w, b, (c0 << len1) | c1, len0 + len1);
    } else {
        put_eg(w, b, v0, k0);
        put_eg(w, b, v1, k1);
    }
}
#else
/* compact: the two fields one after the other (a macro: no function of its own) */
#define field_eg2(w, b, costing, v0, k0, v1, k1)                                                   \
    do {                                                                                           \
        field_eg(w, b, costing, v0, k0);                                                           \
        field_eg(w, b, costing, v1, k1);                                                           \
    } while (0)
#endif

/* The n low bits of x (n <= 64), 16 at a time, the highest first. */
static inline void put_bits_wide(writer_t *w, bits_t *b, uint64_t x, unsigned n)
{
    while (n > 0u) {
        const unsigned take = n > 16u ? 16u : n;
        n -= take;
        put_bits(w, b, (uint32_t)(x >> n) & ((1u << take) - 1u), take);
    }
}

/* u(n) of v < 2^n for n <= 64: the n low bits of v, 16 at a time. */
ENC_INLINE void field_u64_(writer_t *w, bits_t *b, ENC_COSTING_PARAM uint64_t v, unsigned n)
{
    if (ENC_COSTING(b)) {
        b->bits += n;
    } else {
        put_bits_wide(w, b, v, n);
    }
}

/* EGk of any v with v >> k < 2^63 (k <= 63): the rare wide fields. State
 * in and out by value, so that the caller's stays in registers. */
static inline bits_t put_eg_wide(writer_t *w, bits_t b, ENC_COSTING_PARAM uint64_t v, unsigned k)
{
    const uint64_t u = (v >> k) + 1u;
    const unsigned n = bsf_wire_bitlen(u);
    if (ENC_COSTING(&b)) {
        b.bits += 2u * n - 1u + k;
        return b;
    }
    put_bits_wide(w, &b, 0u, n - 1u); /* the n - 1 zeros */
    put_bits_wide(w, &b, u, n);       /* u, then the k low bits of v */
    put_bits_wide(w, &b, v, k);
    return b;
}

/* EGk of v: the narrow fields as field_eg; the compact variant writes them
 * too through put_eg_wide, which gives the same bits (v + 2^k is u followed
 * by the k low bits of v) in one code path. */
ENC_INLINE void field_eg64_(writer_t *w, bits_t *b, ENC_COSTING_PARAM uint64_t v, unsigned k)
{
#if BSF_CONFIG_COMPACT
    *b = put_eg_wide(w, *b, v, k);
#else
    if (v < ((uint64_t)1 << 30) && k <= 25u) {
        field_eg(w, b, costing, (uint32_t)v, k);
    } else {
        *b = put_eg_wide(w, *b, costing, v, k);
    }
#endif
}

ENC_INLINE void field_float_(writer_t *w, bits_t *b, ENC_COSTING_PARAM float v)
{
    /* the 32 bits, 16 at a time */
    field_u64(w, b, costing, bsf_float_bits(v), 32u);
}

static inline int is_finite_f(float v)
{
    return bsf_finite_bits(v);
}

/* ---- Frame job ----------------------------------------------------------- */

typedef struct bsf_enc_job bsf_enc_job_t;

/*
 * One frame to encode, as its type sees it. A frame type embeds this as the
 * first member of its own job and fills plan and payload; a firmware that
 * encodes only one type links no other type's code.
 */
struct bsf_enc_job {
    /* Checks the input and sets max_bits to a bound of the payload's bits
     * (or their exact number); anything else it learns stays in the type's
     * job. Returns BSF_OK or the error for the caller. */
    bsf_status_t (*plan)(bsf_enc_job_t *job);
    /* The payload through w, written or (costing) only counted, after plan
     * accepted the input. */
    void (*payload)(writer_t *w, int costing, bsf_enc_job_t *job);
    uint32_t max_bits;
};

/* The exact payload bits: a costing run of job->payload. */
uint32_t bsf_enc_job_bits(bsf_enc_job_t *job);

/* Plans the frame, then writes it to buf (cap bytes; NULL: only its length
 * in *out_len). BSF_ERR_BUFFER when it does not fit. */
bsf_status_t bsf_enc_job_encode(bsf_enc_job_t *job, uint8_t *buf, size_t cap, size_t *out_len);

/* Plans the frame, then hands it to sink in COBS blocks (through work). */
bsf_status_t bsf_enc_job_encode_sink(bsf_enc_job_t *job, bsf_encoder_t *work, bsf_sink_fn sink,
                                     void *ctx, size_t *written);

#endif /* BSF_STREAM_WRITER_H */
