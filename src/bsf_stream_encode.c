/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_stream.h"

#include <math.h>
#include <string.h>

#include "bsf_math.h"
#include "bsf_wire.h"

#if defined(__SSE2__) && defined(__x86_64__) && !defined(__OPTIMIZE_SIZE__) &&                     \
    !defined(BSF_ENC_PORTABLE)
#include <emmintrin.h>
#endif

/*
 * How a features frame is made (two runs over the result, docs/PERFORMANCE.md):
 *
 * 1. Planning: validates the whole input, sums the bits of every field but
 *    the control point values, quantises each control point once into a
 *    per-frame table of wire values (zigzag value and class) and tallies
 *    those per class, from which each class's shortest Exp-Golomb order and
 *    the payload's exact size follow.
 * 2. Writing: when the caller's buffer holds the size bound, a bit writer
 *    that stores whole 32-bit words writes the payload straight into it,
 *    behind room for COBS's extra bytes, taking the values from the table
 *    (a feature beyond the table is quantised again); then CRC-32C over the
 *    payload and COBS in place.
 *
 * Sinks, metadata frames and buffers smaller than the bound take the
 * streaming path: the same bit writer fills a small chunk whose bytes go
 * through CRC and COBS to a counter, the buffer or the sink.
 */

/* ---- Streaming output: COBS blocks to a counter, a buffer or a sink ---- */

typedef struct {
    uint8_t *buf;    /* buffer mode, else NULL */
    size_t cap;      /* size of buf */
    size_t pos;      /* bytes of the frame produced so far */
    size_t code_pos; /* buffer mode: where the current block's code byte goes */
    uint8_t code;    /* 1 + data bytes in the current block */
    uint32_t crc;    /* CRC-32C of the payload so far */
    bsf_encoder_t *work;
    bsf_sink_fn sink; /* sink mode: a block is collected in work->block, its code byte first */
    void *ctx;
    int failed; /* the sink refused bytes */
} stream_t;

static void emit(stream_t *s, const uint8_t *data, size_t len)
{
    if (!s->failed) {
        if (s->sink(s->ctx, data, len) != 0) {
            s->failed = 1;
        } else {
            s->pos += len;
        }
    }
}

static void block_start(stream_t *s)
{
    s->code = 1u;
    if (s->sink == NULL) {
        s->code_pos = s->pos++;
    }
}

static void block_end(stream_t *s)
{
    if (s->sink != NULL) {
        s->work->block[0] = s->code;
        emit(s, s->work->block, s->code);
    } else if (s->buf != NULL && s->code_pos < s->cap) {
        s->buf[s->code_pos] = s->code;
    }
}

static void stream_init(stream_t *s)
{
    memset(s, 0, sizeof *s);
    block_start(s);
}

/* One body byte (payload or CRC) through COBS. */
static void stream_byte(stream_t *s, uint8_t b)
{
    if (b == 0u) {
        block_end(s);
        block_start(s);
        return;
    }
    if (s->sink != NULL) {
        s->work->block[s->code] = b;
    } else {
        if (s->buf != NULL && s->pos < s->cap) {
            s->buf[s->pos] = b;
        }
        ++s->pos;
    }
    if (++s->code == 0xFFu) {
        block_end(s);
        block_start(s);
    }
}

static void stream_payload(stream_t *s, const uint8_t *data, size_t len)
{
    size_t i;
    s->crc = bsf_crc32c(s->crc, data, len);
    for (i = 0; i < len; ++i) {
        stream_byte(s, data[i]);
    }
}

/* The CRC (not itself checksummed), the last block and the 0x00. */
static void stream_finish(stream_t *s)
{
    unsigned i;
    const uint32_t crc = s->crc;
    for (i = 0; i < 4u; ++i) {
        stream_byte(s, (uint8_t)(crc >> (8u * i)));
    }
    if (s->sink != NULL) {
        s->work->block[0] = s->code;
        s->work->block[s->code] = 0u;
        emit(s, s->work->block, (size_t)s->code + 1u);
    } else {
        block_end(s);
        if (s->buf != NULL && s->pos < s->cap) {
            s->buf[s->pos] = 0u;
        }
        ++s->pos;
    }
}

/* ---- Bit writer ---------------------------------------------------------- */

/* The hot paths inline their helpers so that the writer's state lives in
 * registers; a size-optimised build (-Os) leaves that to the compiler. */
#if (defined(__GNUC__) || defined(__clang__)) && !defined(__OPTIMIZE_SIZE__)
#define ENC_INLINE static inline __attribute__((always_inline))
#else
#define ENC_INLINE static inline
#endif

#if defined(__GNUC__) || defined(__clang__)
#define ENC_NOINLINE static __attribute__((noinline))
#else
#define ENC_NOINLINE static
#endif

#define CHUNK_BYTES 32u /* streaming path: payload bytes handed on at a time */

/*
 * The payload's bits, most significant first, gather in acc and leave as
 * whole big-endian 32-bit words. A run copies this into a local, so that it
 * stays in registers. In a costing run nothing is written: bits sums the
 * fields' lengths.
 */
#if UINTPTR_MAX > 0xFFFFFFFFu && !defined(__OPTIMIZE_SIZE__)
/* 64-bit hosts: a field that completes a word stays whole in acc, and the
 * word is the 32 bits above the field's rest (fewer shifts per word). */
#define ENC_ACC64 1
typedef uint64_t acc_t;
#else
typedef uint32_t acc_t;
#endif

typedef struct {
    uint8_t *p;    /* the next word goes here */
    uint8_t *end;  /* words must end at or before this */
    acc_t acc;     /* pending bits in the low 32 - room bits (higher bits: leftovers) */
    unsigned room; /* free bits in acc, 1..32 */
    uint32_t bits; /* costing run: payload bits so far */
} bits_t;

/* Where the words go. */
typedef struct {
    bits_t b;
    stream_t *out; /* streaming path; NULL when writing straight into a buffer */
    uint8_t *end;  /* the end after a spill */
    int overflow;  /* direct writing reached its end (a planning bug: never written) */
    uint8_t chunk[CHUNK_BYTES];
} writer_t;

static void writer_init(writer_t *w, stream_t *out, uint8_t *start, uint8_t *end)
{
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
static uint8_t *writer_spill(writer_t *w, uint8_t *p)
{
    if (w->out != NULL) {
        stream_payload(w->out, w->chunk, (size_t)(p - w->chunk));
    } else {
        w->overflow = 1;
    }
    w->end = w->chunk + CHUNK_BYTES;
    return w->chunk;
}

ENC_INLINE void put_word(writer_t *w, bits_t *b, uint32_t word)
{
    if ((size_t)(b->end - b->p) < 4u) {
        b->p = writer_spill(w, b->p);
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

/* Fields, written or (costing) counted: u(n) with n <= 31. */
ENC_INLINE void field_u(writer_t *w, bits_t *b, int costing, uint32_t v, unsigned n)
{
    if (costing) {
        b->bits += n;
    } else {
        put_bits(w, b, v, n);
    }
}

/* EGk of v < 2^30, k <= 25. */
ENC_INLINE void field_eg(writer_t *w, bits_t *b, int costing, uint32_t v, unsigned k)
{
    if (costing) {
        b->bits += eg_len(v, k);
    } else {
        put_eg(w, b, v, k);
    }
}

/* Two EG fields, v0 (order k0) then v1 (order k1), each v < 2^30 and k <= 25:
 * one field when both codes fit in 31 bits together (feature fields). */
#if !defined(__OPTIMIZE_SIZE__)
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
/* -Os: the two fields one after the other (a macro: no function of its own) */
#define field_eg2(w, b, costing, v0, k0, v1, k1)                                                   \
    do {                                                                                           \
        field_eg(w, b, costing, v0, k0);                                                           \
        field_eg(w, b, costing, v1, k1);                                                           \
    } while (0)
#endif

/* EGk of any v with v >> k < 2^63 (k <= 63), 16 bits at a time: the rare
 * wide fields. State in and out by value, so that the caller's stays in
 * registers. */
static bits_t put_eg_wide(writer_t *w, bits_t b, int costing, uint64_t v, unsigned k)
{
    const uint64_t u = (v >> k) + 1u;
    const unsigned n = bsf_wire_bitlen(u);
    unsigned i;
    if (costing) {
        b.bits += 2u * n - 1u + k;
        return b;
    }
    for (i = 1u; i < n; ++i) {
        put_bits(w, &b, 0u, 1u); /* the n - 1 zeros */
    }
    for (i = n; i > 0u;) { /* u, then the k low bits of v: 16 bits at a time */
        const unsigned take = i > 16u ? 16u : i;
        i -= take;
        put_bits(w, &b, (uint32_t)(u >> i) & ((1u << take) - 1u), take);
    }
    for (i = k; i > 0u;) {
        const unsigned take = i > 16u ? 16u : i;
        i -= take;
        put_bits(w, &b, (uint32_t)(v >> i) & ((1u << take) - 1u), take);
    }
    return b;
}

ENC_INLINE void field_eg64(writer_t *w, bits_t *b, int costing, uint64_t v, unsigned k)
{
    if (v < ((uint64_t)1 << 30) && k <= 25u) {
        field_eg(w, b, costing, (uint32_t)v, k);
    } else {
        *b = put_eg_wide(w, *b, costing, v, k);
    }
}

ENC_INLINE void field_float(writer_t *w, bits_t *b, int costing, float v)
{
    const uint32_t u = bsf_float_bits(v);
    field_u(w, b, costing, u >> 16, 16u);
    field_u(w, b, costing, u & 0xFFFFu, 16u);
}

#if !defined(__OPTIMIZE_SIZE__) /* the direct writer only (job_direct) */
/* Bits written so far. */
static size_t writer_bits(const writer_t *w, const uint8_t *start)
{
    return (size_t)(w->b.p - start) * 8u + (32u - w->b.room);
}

/* Pads the payload to whole bytes and pushes out its last, partial word
 * (its unused bytes are overwritten by what follows). */
static void writer_flush(writer_t *w)
{
    if (w->b.room < 32u) {
        put_word(w, &w->b, (uint32_t)(w->b.acc << w->b.room));
    }
}
#endif

/* Streaming path: the payload's last bytes, then CRC, last block and 0x00. */
static void writer_end_stream(writer_t *w)
{
    size_t n;
    if (w->b.room < 32u) {
        const unsigned tail = (32u - w->b.room + 7u) / 8u; /* bytes of the partial word */
        put_word(w, &w->b, (uint32_t)(w->b.acc << w->b.room));
        n = (size_t)(w->b.p - w->chunk) - (4u - tail);
    } else {
        n = (size_t)(w->b.p - w->chunk);
    }
    stream_payload(w->out, w->chunk, n);
    stream_finish(w->out);
}

/* ---- Quantisation and checks ------------------------------------------- */

static int is_finite_f(float v)
{
    return bsf_finite_bits(v);
}

#if defined(__SSE2__) && defined(__x86_64__) && !defined(__OPTIMIZE_SIZE__) &&                     \
    !defined(BSF_ENC_PORTABLE)
/* Both coordinates at once with the same IEEE single operations as
 * quantise (divide, add, truncate, compare), so the same q and verdict. */
ENC_INLINE int quantise_point(bsf_point_t p, float step, int32_t q[2])
{
    const __m128 r =
        _mm_add_ps(_mm_div_ps(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(const void *)&p)),
                              _mm_set1_ps(step)),
                   _mm_set1_ps(0.5f));
    const __m128 in_range = _mm_cmplt_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), r),
                                         _mm_set1_ps((float)BSF_QUANT_MAX_STEPS + 1.0f));
    const __m128i t = _mm_cvttps_epi32(r);
    /* floor: one lower where the truncation rounded up (a negative r with a fraction) */
    const __m128i fl = _mm_add_epi32(t, _mm_castps_si128(_mm_cmpgt_ps(_mm_cvtepi32_ps(t), r)));
    const __m128i above_min =
        _mm_cmpgt_epi32(fl, _mm_set1_epi32(-(int32_t)BSF_QUANT_MAX_STEPS - 1));
    q[0] = _mm_cvtsi128_si32(fl);
    q[1] = _mm_cvtsi128_si32(_mm_shuffle_epi32(fl, 1));
    return (_mm_movemask_ps(_mm_and_ps(in_range, _mm_castsi128_ps(above_min))) & 3) == 3;
}
#else
/* Nearest multiple of step, in steps: floor(v / step + 0.5); 0 when v is
 * not finite or too far. |floor(r)| <= BSF_QUANT_MAX_STEPS = 2^23 - 1 is
 * -(2^23 - 1) <= r < 2^23, where the floor is a truncation toward zero,
 * one lower for a negative r with a fraction. */
ENC_INLINE int quantise(float v, float step, int32_t *q)
{
    const float r = v / step + 0.5f;
    int32_t t;
    if (!(fabsf(r) < (float)BSF_QUANT_MAX_STEPS + 1.0f)) {
        *q = 0;
        return 0; /* NaN included */
    }
    t = (int32_t)r;
    *q = (float)t > r ? t - 1 : t;
    return *q >= -BSF_QUANT_MAX_STEPS; /* -2^23 < r < -(2^23 - 1) floors to -2^23 */
}

ENC_INLINE int quantise_point(bsf_point_t p, float step, int32_t q[2])
{
    const int ok_x = quantise(p.x, step, &q[0]);
    const int ok_y = quantise(p.y, step, &q[1]);
    return ok_x && ok_y;
}
#endif

/* ---- Control point values ------------------------------------------------ */

/* A value in the per-frame table: zigzag code (below 2^26) | class << 30. */
#define VALUE_CLASS_SHIFT 30u
#define VALUE_MASK 0x3FFFFFFFu

/* Table entries: per feature a head (distinct points, vertex mask in two
 * words) and its values; those of a typical frame (about 75 on Intel, 130 on
 * MIT and Freiburg) at 4 bytes each, and room for one more feature (at most
 * 2 values per stored control point) behind them, where the planning run
 * puts those of features beyond the table and the writing runs make them
 * again. */
#define VALUE_HEAD 3u
#define VALUE_KEEP 144u
#define VALUE_TABLE (VALUE_KEEP + VALUE_HEAD + 2u * BSF_MAX_CTRL_PER_FEATURE)

ENC_INLINE uint32_t zigzag32(int32_t v)
{
    const uint32_t twice = (uint32_t)v << 1;
    return v < 0 ? ~twice : twice; /* -2v - 1 for v < 0 */
}

/* One value of class cls: stored, and tallied in the planning run. */
ENC_INLINE uint32_t add_value(uint32_t *out, uint32_t cnt, bsf_wire_eg_tally_t *tally, unsigned cls,
                              int32_t v)
{
    const uint32_t z = zigzag32(v);
    if (tally != NULL) {
        bsf_wire_eg_tally_add32(&tally[cls], z);
    }
    out[cnt] = z | ((uint32_t)cls << VALUE_CLASS_SHIFT);
    return cnt + 1u;
}

/* bsf_wire_predict in 32 bits: quantised coordinates within 2^23 - 1 make
 * |b - a| <= 2^24 - 2, and k <= BSF_MAX_CTRL_PER_FEATURE - 2 <= 62 (bsf_stream.h
 * caps it at 64), so (b - a)(2s - 1) + k stays below 2^24 * 123 + 62 < 2^31. */
ENC_INLINE int32_t predict32(int32_t a, int32_t b, uint32_t s, uint32_t k)
{
    const int32_t den = 2 * (int32_t)k;
    const int32_t num = (b - a) * (2 * (int32_t)s - 1) + (int32_t)k;
    int32_t q;
    if (k == 1u) {
        /* the usual case, a fragment with one precision point: floor(num / 2)
         * as a shift of num + 2^31, which is not negative */
        return a + ((int32_t)(((uint32_t)num ^ 0x80000000u) >> 1) - 0x40000000);
    }
    q = num / den;
    return a + (num - q * den < 0 ? q - 1 : q); /* floor */
}

/* A flagged slot s needs a flagged partner s + 1 that quantises to q. */
static int vertex_partner_ok(const bsf_point_t *p, const uint8_t *vtx, size_t s, size_t n,
                             float step, const int32_t q[2])
{
    int32_t q2[2];
    if (s + 1u >= n || vtx[s + 1u] == 0u) {
        return 0;
    }
    if (memcmp(&p[s], &p[s + 1u], sizeof p[s]) == 0) {
        return 1; /* the usual copy: the same bits quantise alike */
    }
    return quantise_point(p[s + 1u], step, q2) && q2[0] == q[0] && q2[1] == q[1];
}

/*
 * The values of one feature's n control points in wire order (FORMAT.md
 * section 3.3): the first distinct point as a delta from prev (the last
 * anchor of the previous feature, updated here), then per fragment the next
 * anchor (vertex or last point) as a delta from the previous anchor, then
 * the fragment's precision points as residuals from their predicted places
 * on the chord. Stores them in out (room for 2 n), tallies them when tally
 * is given (the planning run), and returns their number (2 per distinct
 * point), or 0 when a point cannot be represented or a flagged slot has no
 * equal partner; *mask gets the vertex mask in wire order: one bit per
 * distinct point, point 0 the highest of the m (FORMAT.md section 3.2).
 */
ENC_INLINE uint32_t feature_values(const bsf_point_t *p, const uint8_t *vtx, size_t n, float step,
                                   int32_t prev[2], uint32_t *out, bsf_wire_eg_tally_t *tally,
                                   uint64_t *mask)
{
    size_t s_a = 0;
    size_t c_a;
    uint32_t cnt = 0;
    int32_t q_a[2];

    *mask = 0u;

    if (!quantise_point(p[0], step, q_a)) {
        return 0u;
    }
    c_a = 1u;
    if (vtx[0] != 0u) {
        if (!vertex_partner_ok(p, vtx, 0u, n, step, q_a)) {
            return 0u;
        }
        *mask = 1u;
        c_a = 2u;
    }
    cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_FIRST, q_a[0] - prev[0]);
    cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_FIRST, q_a[1] - prev[1]);
    while (s_a + c_a < n) {
        const size_t t = s_a + c_a;
        size_t s_b = t;
        size_t i;
        int32_t q_b[2];
        uint32_t k;
        while (s_b < n - 1u && vtx[s_b] == 0u) {
            ++s_b;
        }
        k = (uint32_t)(s_b - t);
        if (!quantise_point(p[s_b], step, q_b)) {
            return 0u;
        }
        *mask <<= k + 1u; /* k + 1 <= 63: the k precision points and anchor b */
        c_a = 1u;
        if (vtx[s_b] != 0u) {
            if (!vertex_partner_ok(p, vtx, s_b, n, step, q_b)) {
                return 0u;
            }
            *mask |= 1u; /* anchor b: the mask's lowest bit for now */
            c_a = 2u;
        }
        cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_ANCHOR, q_b[0] - q_a[0]);
        cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_ANCHOR, q_b[1] - q_a[1]);
        for (i = t; i < s_b; ++i) {
            const uint32_t s = (uint32_t)(i - t) + 1u;
            int32_t q[2];
            if (!quantise_point(p[i], step, q)) {
                return 0u;
            }
            cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_PREC,
                            q[0] - predict32(q_a[0], q_b[0], s, k));
            cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_PREC,
                            q[1] - predict32(q_a[1], q_b[1], s, k));
        }
        s_a = s_b;
        q_a[0] = q_b[0];
        q_a[1] = q_b[1];
    }
    prev[0] = q_a[0];
    prev[1] = q_a[1];
    return cnt;
}

/* Per class at its order k: 2^k, and 1 - k (modulo 2^32) for the code's
 * length 2 floor(log2(v + 2^k)) + 1 - k. */
typedef struct {
    uint32_t one[BSF_WIRE_N_CLASSES];
    uint32_t adj[BSF_WIRE_N_CLASSES];
} orders_t;

/* One value's code at its class's order, from its c = v + 2^k and lg = floor(log2(c)). */
ENC_INLINE void put_value_code(writer_t *w, bits_t *b, uint32_t c, unsigned lg, unsigned len)
{
    if (len < 32u) {
        put_bits(w, b, c, len);
    } else {
        put_bits(w, b, 0u, len - lg - 1u);
        put_bits(w, b, c, lg + 1u);
    }
}

/* The values' codes at the frame's orders: the hot loop of the writing run. */
#if !defined(__OPTIMIZE_SIZE__)
/* Values come in pairs of one class (x, then y of a point): the two codes
 * go out as one field when they fit in 31 bits together (the usual case),
 * which saves a class lookup and a field per point. */
ENC_INLINE void put_values(writer_t *w, bits_t *b, int costing, const uint32_t *values, uint32_t n,
                           const orders_t *ord)
{
    uint32_t i;
    for (i = 0; i < n; i += 2u) {
        const uint32_t v0 = values[i];
        const unsigned cls = v0 >> VALUE_CLASS_SHIFT;
        const uint32_t one = ord->one[cls];
        const uint32_t adj = ord->adj[cls];
        const uint32_t c0 = (v0 & VALUE_MASK) + one;
        const uint32_t c1 = (values[i + 1u] & VALUE_MASK) + one;
        const unsigned lg0 = log2_nz(c0);
        const unsigned lg1 = log2_nz(c1);
        const unsigned len0 = 2u * lg0 + adj;
        const unsigned len1 = 2u * lg1 + adj;
        if (costing) {
            b->bits += len0 + len1;
        } else if (len0 + len1 < 32u) {
            /* c0 has lg0 + 1 <= len0 bits: the zero run and c0, then c1's */
            put_bits(w, b, (c0 << len1) | c1, len0 + len1);
        } else {
            put_value_code(w, b, c0, lg0, len0);
            put_value_code(w, b, c1, lg1, len1);
        }
    }
}
#else
ENC_INLINE void put_values(writer_t *w, bits_t *b, int costing, const uint32_t *values, uint32_t n,
                           const orders_t *ord)
{
    uint32_t i;
    for (i = 0; i < n; ++i) {
        const uint32_t v = values[i];
        const unsigned cls = v >> VALUE_CLASS_SHIFT;
        const uint32_t c = (v & VALUE_MASK) + ord->one[cls];
        const unsigned lg = log2_nz(c);
        const unsigned len = 2u * lg + ord->adj[cls];
        if (costing) {
            b->bits += len;
        } else {
            put_value_code(w, b, c, lg, len);
        }
    }
}
#endif

/* ---- Features frame ------------------------------------------------------ */

/* Beams minus one of a feature's run: last - first, or through the seam of
 * a full-circle scan of n_beams beams when first > last. */
static uint32_t feature_span(const bsf_feature_t *f, uint32_t n_beams)
{
    if (f->first_beam > f->last_beam) {
        return n_beams - f->first_beam + f->last_beam;
    }
    return (uint32_t)(f->last_beam - f->first_beam);
}

/* A feature's own fields (not its points) within the result and the caps. */
static int feature_ok(const bsf_feature_t *f, uint32_t n_beams, size_t n_ctrl)
{
    const size_t n = f->n_ctrl;
    const uint32_t beam_limit = n_beams != 0u ? n_beams : (uint32_t)BSF_MAX_POINTS;
    return !(f->kind > 1u || n < 3u || n > (size_t)BSF_MAX_CTRL_PER_FEATURE ||
             (size_t)f->ctrl_first + n > n_ctrl || f->first_beam >= beam_limit ||
             f->last_beam >= beam_limit || (f->first_beam > f->last_beam && n_beams == 0u) ||
             f->n_points > feature_span(f, n_beams) + 1u ||
             !(f->e_curve >= 0.0f && f->e_curve <= BSF_E_CURVE_MAX));
}

static bsf_status_t check_info(const bsf_frame_info_t *info, uint32_t *step_code)
{
    float code;
    if (!is_finite_f(info->quant_step)) {
        return BSF_ERR_ARG;
    }
    code = bsf_floorf(info->quant_step / BSF_QUANT_STEP_UNIT + 0.5f);
    if (!(code >= 1.0f && code <= (float)BSF_WIRE_STEP_CODE_MAX)) {
        return BSF_ERR_ARG;
    }
    *step_code = (uint32_t)code;
    if (info->has_pose > 1u || info->has_geometry > 1u ||
        (info->has_geometry != 0u &&
         (!is_finite_f(info->angle_min) || !is_finite_f(info->angle_increment)))) {
        return BSF_ERR_ARG;
    }
    if (info->has_pose != 0u &&
        (!(fabsf(info->pose.x) <= BSF_POSE_XY_MAX) || !(fabsf(info->pose.y) <= BSF_POSE_XY_MAX) ||
         !(fabsf(info->pose.theta) <= BSF_POSE_THETA_MAX))) {
        return BSF_ERR_ARG;
    }
    return BSF_OK;
}

/* The scan statistics that travel in the header's extension (FORMAT.md
 * section 3.1): the beam count must stay within the caps, the cut counters
 * go with a non-zero cut and stay within the scan. */
static bsf_status_t check_stats(const bsf_stats_t *st)
{
    const uint32_t cut_bits = BSF_CUT_KEYPOINTS | BSF_CUT_SEGMENTS | BSF_CUT_CTRL;
    if (st->n_valid > (uint32_t)BSF_MAX_POINTS || st->n_beams > (uint32_t)BSF_MAX_POINTS ||
        (st->n_beams != 0u && st->n_valid > st->n_beams) || (st->cut & ~cut_bits) != 0u) {
        return BSF_ERR_ARG;
    }
    if (st->cut == 0u) {
        return (st->n_cut_keypoints | st->n_cut_segments | st->n_cut_points) == 0u ? BSF_OK
                                                                                   : BSF_ERR_ARG;
    }
    if (st->n_cut_keypoints > (uint32_t)BSF_MAX_POINTS ||
        st->n_cut_segments > (uint32_t)BSF_MAX_POINTS || st->n_cut_points > st->n_valid) {
        return BSF_ERR_ARG;
    }
    return BSF_OK;
}

static int32_t round_to_int(float v)
{
    return (int32_t)bsf_floorf(v + 0.5f);
}

/* Header bits at most, and per feature bits at most outside the control
 * point values (FORMAT.md section 7). */
#define HEADER_MAX_BITS 619u
#define FEATURE_MAX_BITS 211u

/* What the planning run learns for the writing runs. */
typedef struct {
    uint32_t step_code;
    float step;
    int has_beams;
    int has_ext;
    uint32_t n_cached;      /* leading features whose values are all in the table */
    int32_t prev_resume[2]; /* the last anchor before feature n_cached */
    uint32_t max_bits;      /* payload bits at most (exact for a metadata frame) */
    uint8_t k_ctrl[BSF_WIRE_N_CLASSES];
} plan_t;

/* The checks that come before any feature. */
static bsf_status_t check_frame(const bsf_frame_info_t *info, const bsf_result_t *res, plan_t *pl)
{
    bsf_status_t st;
    if (res->n_features > (uint32_t)BSF_MAX_SEGMENTS ||
        res->n_ctrl > (uint32_t)BSF_MAX_CTRL_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    st = check_info(info, &pl->step_code);
    if (st != BSF_OK) {
        return st;
    }
    st = check_stats(&res->stats);
    if (st != BSF_OK) {
        return st;
    }
    if (info->has_geometry != 0u && res->stats.n_beams == 0u) {
        return BSF_ERR_ARG;
    }
    pl->step = (float)pl->step_code * BSF_QUANT_STEP_UNIT;
    pl->has_beams = info->has_geometry != 0u; /* or a feature wraps: plan_frame */
    return BSF_OK;
}

/*
 * Planning run: checks everything, quantises the control points into the
 * value table (while it has room) and tallies them per class, takes each
 * class's shortest order (ties to the smaller one; never longer than order
 * 25, which bounds every value by 26 bits, BSF_FRAME_CTRL_MAX_BITS), and
 * bounds the payload's size: the values' exact bits plus the most the
 * header and feature fields can take.
 */
static bsf_status_t plan_frame(const bsf_frame_info_t *info, const bsf_result_t *res,
                               uint32_t *table, plan_t *pl)
{
    bsf_wire_eg_tally_t tally[BSF_WIRE_N_CLASSES];
    const float step = pl->step;
    /* locals, not loads through res and pl, which the table's stores may alias */
    const uint32_t n_features = res->n_features;
    const uint32_t n_beams = res->stats.n_beams;
    const size_t n_ctrl = res->n_ctrl;
    uint32_t n_cached = 0;
    int32_t prev[2] = {0, 0};
    uint32_t used = 0; /* table entries of the leading features */
    uint32_t sum_points = 0;
    uint32_t i;
    unsigned cls;

    memset(tally, 0, sizeof tally);
    for (i = 0; i < n_features; ++i) {
        const bsf_feature_t *f = &res->features[i];
        uint32_t *head = table + used;
        uint32_t n_values;
        uint64_t mask;
        if (!feature_ok(f, n_beams, n_ctrl)) {
            return BSF_ERR_ARG;
        }
        if (n_cached == i) {
            pl->prev_resume[0] = prev[0];
            pl->prev_resume[1] = prev[1];
        }
        /* behind the kept entries: a head and at most 2 n_ctrl values, VALUE_TABLE has room */
        n_values = feature_values(&res->ctrl[f->ctrl_first], &res->ctrl_is_vertex[f->ctrl_first],
                                  f->n_ctrl, step, prev, head + VALUE_HEAD, tally, &mask);
        if (n_values == 0u) {
            return BSF_ERR_ARG;
        }
        if (n_cached == i && used + VALUE_HEAD + n_values <= VALUE_KEEP) {
            head[0] = n_values / 2u;
            head[1] = (uint32_t)mask;
            head[2] = (uint32_t)(mask >> 32);
            used += VALUE_HEAD + n_values;
            n_cached = i + 1u;
        }
        sum_points += f->n_points;
        if (f->first_beam > f->last_beam) {
            pl->has_beams = 1;
        }
    }
    pl->n_cached = n_cached;
    pl->has_ext = pl->has_beams || res->stats.cut != 0u;
    if (sum_points > res->stats.n_valid ||
        res->stats.n_cut_points > res->stats.n_valid - sum_points) {
        return BSF_ERR_ARG;
    }
    pl->max_bits = HEADER_MAX_BITS + FEATURE_MAX_BITS * n_features;
    for (cls = 0; cls < BSF_WIRE_N_CLASSES; ++cls) {
        uint32_t bits;
        pl->k_ctrl[cls] = (uint8_t)bsf_wire_eg_tally_best(&tally[cls], &bits);
        pl->max_bits += bits;
    }
    (void)info;
    return BSF_OK;
}

/*
 * The features payload through w, written or (costing) counted, after the
 * planning run: the values of the leading features come from the table,
 * the others are made again into it.
 */
ENC_INLINE void frame_payload_run(writer_t *w, int costing, plan_t *pl,
                                  const bsf_frame_info_t *info, const bsf_result_t *res,
                                  uint32_t *table)
{
    bits_t b = w->b;
    uint8_t k_ctrl[BSF_WIRE_N_CLASSES];
    orders_t ord;
    uint32_t prev_last_beam_plus1 = 0; /* the "previous last_beam" of the first feature is -1 */
    uint32_t used = 0;
    int32_t prev[2];
    uint32_t i;

    memcpy(k_ctrl, pl->k_ctrl, sizeof k_ctrl);
    for (i = 0; i < BSF_WIRE_N_CLASSES; ++i) {
        ord.one[i] = (uint32_t)1 << k_ctrl[i];
        ord.adj[i] = 1u - k_ctrl[i];
    }
    prev[0] = pl->prev_resume[0];
    prev[1] = pl->prev_resume[1];
    field_u(w, &b, costing, (BSF_FORMAT_VERSION << 4) | BSF_FRAME_TYPE_FEATURES, 8u);
    field_u(w, &b, costing, info->has_pose != 0u ? 1u : 0u, 1u);
    field_u(w, &b, costing, pl->has_ext ? 1u : 0u, 1u);
    field_eg64(w, &b, costing, info->seq, BSF_WIRE_K_SEQ);
    field_eg64(w, &b, costing, info->timestamp_ms, BSF_WIRE_K_TIMESTAMP);
    if (info->has_pose != 0u) {
        const uint32_t theta =
            (uint32_t)round_to_int(info->pose.theta * BSF_WIRE_THETA_PER_RAD) & 0xFFFFu;
        field_eg64(w, &b, costing, bsf_wire_zigzag(round_to_int(info->pose.x * 1000.0f)),
                   BSF_WIRE_K_POSE);
        field_eg64(w, &b, costing, bsf_wire_zigzag(round_to_int(info->pose.y * 1000.0f)),
                   BSF_WIRE_K_POSE);
        field_u(w, &b, costing, theta, 16u);
    }
    field_eg(w, &b, costing, pl->step_code, BSF_WIRE_K_STEP);
    field_eg(w, &b, costing, res->stats.n_valid, BSF_WIRE_K_N);
    /* round(time_ns / 1000) in 32 bits (a 64-bit division is a library call on Cortex-M) */
    field_eg(w, &b, costing,
             res->stats.time_ns / 1000u + (res->stats.time_ns % 1000u + 500u) / 1000u,
             BSF_WIRE_K_TIME_US);
    field_eg(w, &b, costing, res->n_features, BSF_WIRE_K_FEATURES);
    for (i = 0; i < BSF_WIRE_N_CLASSES; ++i) {
        field_u(w, &b, costing, k_ctrl[i], BSF_WIRE_K_CTRL_BITS);
    }
    if (pl->has_ext) {
        field_u(w, &b, costing, pl->has_beams ? 1u : 0u, 1u);
        field_u(w, &b, costing, info->has_geometry != 0u ? 1u : 0u, 1u);
        field_u(w, &b, costing, res->stats.cut, BSF_WIRE_CUT_BITS);
        if (pl->has_beams) {
            field_eg(w, &b, costing, res->stats.n_beams, BSF_WIRE_K_N_BEAMS);
        }
        if (info->has_geometry != 0u) {
            field_float(w, &b, costing, info->angle_min);
            field_float(w, &b, costing, info->angle_increment);
        }
        if (res->stats.cut != 0u) {
            field_eg(w, &b, costing, res->stats.n_cut_keypoints, BSF_WIRE_K_CUT_KEYPOINTS);
            field_eg(w, &b, costing, res->stats.n_cut_segments, BSF_WIRE_K_CUT_SEGMENTS);
            field_eg(w, &b, costing, res->stats.n_cut_points, BSF_WIRE_K_CUT_POINTS);
        }
    }

    for (i = 0; i < res->n_features; ++i) {
        const bsf_feature_t *f = &res->features[i];
        const uint8_t *vtx = &res->ctrl_is_vertex[f->ctrl_first];
        const uint32_t span = feature_span(f, res->stats.n_beams);
        uint64_t mask;
        uint32_t n_unique;
        const uint32_t *values = table;
        if (i < pl->n_cached) {
            n_unique = table[used];
            mask = table[used + 1u] | ((uint64_t)table[used + 2u] << 32);
            values = table + used + VALUE_HEAD;
            used += VALUE_HEAD + 2u * n_unique;
        } else {
            /* beyond the table: the same values again, into it */
            n_unique = feature_values(&res->ctrl[f->ctrl_first], vtx, f->n_ctrl, pl->step, prev,
                                      table, NULL, &mask) /
                       2u;
        }
#if !defined(__OPTIMIZE_SIZE__)
#if BSF_WIRE_K_M != 1u
#error "the fused kind / m / mask-flag field below assumes m - 2 in EG1"
#endif
        {
            /* kind, m - 2 (EG1: the code is m in 2 floor(log2 m) bits) and the
             * mask flag as one field of at most 14 bits */
            const unsigned m_len = 2u * log2_nz(n_unique);
            field_u(w, &b, costing,
                    ((uint32_t)f->kind << (m_len + 1u)) | (n_unique << 1) | (mask != 0u ? 1u : 0u),
                    m_len + 2u);
        }
#else
        field_u(w, &b, costing, f->kind, 1u);
        field_eg(w, &b, costing, n_unique - 2u, BSF_WIRE_K_M);
        field_u(w, &b, costing, mask != 0u ? 1u : 0u, 1u);
#endif
        if (mask != 0u) {
            uint32_t j = n_unique; /* bits left, the highest first */
            do {
                const unsigned take = j > 16u ? 16u : j;
                j -= take;
                field_u(w, &b, costing, (uint32_t)(mask >> j) & ((1u << take) - 1u), take);
            } while (j > 0u);
        }
        field_eg2(w, &b, costing, zigzag32((int32_t)f->first_beam - (int32_t)prev_last_beam_plus1),
                  BSF_WIRE_K_GAP, span, BSF_WIRE_K_SPAN);
        /* E_curve rounded half up: the planning run checked 0 <= e_curve <=
         * BSF_E_CURVE_MAX, so the conversion's truncation is the floor */
        field_eg2(w, &b, costing, span + 1u - f->n_points, BSF_WIRE_K_MISSING,
                  (uint32_t)(f->e_curve * BSF_WIRE_E_CURVE_PER_M + 0.5f), BSF_WIRE_K_E_CURVE);
        put_values(w, &b, costing, values, 2u * n_unique, &ord);
        prev_last_beam_plus1 = (uint32_t)f->last_beam + 1u;
    }
    if (pl->n_cached < res->n_features) {
        /* values made again overwrote the table: a further run makes all again */
        pl->n_cached = 0u;
        pl->prev_resume[0] = 0;
        pl->prev_resume[1] = 0;
    }
    w->b = b;
}

/* ---- Metadata frame ------------------------------------------------------ */

void bsf_metadata_init(bsf_metadata_t *m)
{
    if (m != NULL) {
        memset(m, 0, sizeof *m);
        m->lib_version_major = (uint16_t)BSF_VERSION_MAJOR;
        m->lib_version_minor = (uint16_t)BSF_VERSION_MINOR;
        m->lib_version_patch = (uint16_t)BSF_VERSION_PATCH;
        m->quant_step = BSF_QUANT_STEP_DEFAULT;
        m->max_points = (uint32_t)BSF_MAX_POINTS;
        m->max_keypoints = (uint32_t)BSF_MAX_KEYPOINTS;
        m->max_segments = (uint32_t)BSF_MAX_SEGMENTS;
        m->max_ctrl_per_feature = (uint32_t)BSF_MAX_CTRL_PER_FEATURE;
        m->max_ctrl_points = (uint32_t)BSF_MAX_CTRL_POINTS;
    }
}

static int cap_ok(uint32_t v)
{
    return v >= 1u && v <= BSF_WIRE_META_U16_MAX;
}

static bsf_status_t check_metadata(const bsf_metadata_t *m, uint32_t *step_code)
{
    float code;
    if (!is_finite_f(m->quant_step)) {
        return BSF_ERR_ARG;
    }
    code = bsf_floorf(m->quant_step / BSF_QUANT_STEP_UNIT + 0.5f);
    if (!(code >= 1.0f && code <= (float)BSF_WIRE_STEP_CODE_MAX)) {
        return BSF_ERR_ARG;
    }
    *step_code = (uint32_t)code;
    if (!is_finite_f(m->target_rms) || !(m->target_rms >= 0.0f) || !cap_ok(m->max_points) ||
        !cap_ok(m->max_keypoints) || !cap_ok(m->max_segments) || !cap_ok(m->max_ctrl_per_feature) ||
        !cap_ok(m->max_ctrl_points) || m->n_beams > BSF_WIRE_META_U16_MAX ||
        !is_finite_f(m->angle_min) || !is_finite_f(m->angle_increment) ||
        !is_finite_f(m->range_min) || !is_finite_f(m->range_max) || !(m->range_min >= 0.0f) ||
        !(m->range_max >= m->range_min) || m->has_time_origin > 1u ||
        (m->has_time_origin != 0u && (m->time_origin_us > BSF_METADATA_TIME_ORIGIN_MAX ||
                                      m->time_origin_us < -BSF_METADATA_TIME_ORIGIN_MAX)) ||
        m->source_len > BSF_METADATA_SOURCE_MAX ||
        !bsf_wire_source_ok((const uint8_t *)m->source, m->source_len)) {
        return BSF_ERR_ARG;
    }
    return BSF_OK;
}

/* The two runs as functions of their own, each compiled for its mode. */
static void frame_payload_write(writer_t *w, plan_t *pl, const bsf_frame_info_t *info,
                                const bsf_result_t *res, uint32_t *table)
{
    frame_payload_run(w, 0, pl, info, res, table);
}

static void frame_payload_cost(writer_t *w, plan_t *pl, const bsf_frame_info_t *info,
                               const bsf_result_t *res, uint32_t *table)
{
    frame_payload_run(w, 1, pl, info, res, table);
}

/* The metadata payload through w (FORMAT.md section 3.6); m was checked. */
static void metadata_payload(writer_t *w, int costing, const bsf_metadata_t *m, uint32_t step_code)
{
    bits_t *b = &w->b;
    unsigned i;
    field_u(w, b, costing, (BSF_FORMAT_VERSION << 4) | BSF_FRAME_TYPE_METADATA, 8u);
    field_eg(w, b, costing, m->lib_version_major, BSF_WIRE_K_LIB_VERSION);
    field_eg(w, b, costing, m->lib_version_minor, BSF_WIRE_K_LIB_VERSION);
    field_eg(w, b, costing, m->lib_version_patch, BSF_WIRE_K_LIB_VERSION);
    field_eg(w, b, costing, m->method, BSF_WIRE_K_METHOD);
    field_float(w, b, costing, m->target_rms);
    field_eg(w, b, costing, step_code, BSF_WIRE_K_STEP);
    field_eg(w, b, costing, m->max_points, BSF_WIRE_K_CAP_POINTS);
    field_eg(w, b, costing, m->max_keypoints, BSF_WIRE_K_CAP_KEYPOINTS);
    field_eg(w, b, costing, m->max_segments, BSF_WIRE_K_CAP_SEGMENTS);
    field_eg(w, b, costing, m->max_ctrl_per_feature, BSF_WIRE_K_CAP_CTRL_PER_FEATURE);
    field_eg(w, b, costing, m->max_ctrl_points, BSF_WIRE_K_CAP_CTRL_POINTS);
    field_eg(w, b, costing, m->n_beams, BSF_WIRE_K_META_N_BEAMS);
    field_float(w, b, costing, m->angle_min);
    field_float(w, b, costing, m->angle_increment);
    field_float(w, b, costing, m->range_min);
    field_float(w, b, costing, m->range_max);
    field_u(w, b, costing, m->has_time_origin != 0u ? 1u : 0u, 1u);
    if (m->has_time_origin != 0u) {
        field_eg64(w, b, costing, bsf_wire_zigzag(m->time_origin_us), BSF_WIRE_K_TIME_ORIGIN);
    }
    field_eg(w, b, costing, m->source_len, BSF_WIRE_K_SOURCE_LEN);
    for (i = 0; i < m->source_len; ++i) {
        field_u(w, b, costing, (uint8_t)m->source[i], 8u);
    }
}

/* ---- Both frame types: plan, then write to a buffer or a sink ------------ */

typedef struct job job_t;

/* What differs between the frame types, as functions that the job calls:
 * a firmware that encodes only features frames links no metadata code. */
typedef bsf_status_t (*job_plan_fn)(job_t *job);
typedef void (*job_payload_fn)(writer_t *w, int costing, job_t *job);

struct job {
    const bsf_frame_info_t *info; /* features frame: info and res */
    const bsf_result_t *res;
    const bsf_metadata_t *meta; /* or a metadata frame */
    uint32_t *table;            /* features frame: VALUE_TABLE entries */
    job_plan_fn plan_fn;        /* checks the input, bounds the payload (and chooses the orders) */
    job_payload_fn payload_fn;  /* the payload through w, written or counted */
    plan_t plan;
};

/* The payload through w, written or counted (the plan checked the input). */
static void job_payload(writer_t *w, int costing, job_t *job)
{
    job->payload_fn(w, costing, job);
}

static void frame_job_payload(writer_t *w, int costing, job_t *job)
{
    if (costing) {
        frame_payload_cost(w, &job->plan, job->info, job->res, job->table);
    } else {
        frame_payload_write(w, &job->plan, job->info, job->res, job->table);
    }
}

static void metadata_job_payload(writer_t *w, int costing, job_t *job)
{
    metadata_payload(w, costing, job->meta, job->plan.step_code);
}

/* The exact payload bits: a costing run (a call of its own, so that its
 * writer is not on the planning run's stack). */
ENC_NOINLINE uint32_t job_bits(job_t *job)
{
    writer_t w;
    writer_init(&w, NULL, NULL, NULL);
    job_payload(&w, 1, job);
    return w.b.bits;
}

static bsf_status_t frame_job_plan(job_t *job)
{
    const bsf_status_t st = check_frame(job->info, job->res, &job->plan);
    return st != BSF_OK ? st : plan_frame(job->info, job->res, job->table, &job->plan);
}

static bsf_status_t metadata_job_plan(job_t *job)
{
    const bsf_status_t st = check_metadata(job->meta, &job->plan.step_code);
    if (st == BSF_OK) {
        job->plan.max_bits = job_bits(job); /* exact */
    }
    return st;
}

/* Checks the input and bounds the payload's size (and chooses the orders). */
static bsf_status_t job_plan(job_t *job)
{
    memset(&job->plan, 0, sizeof job->plan);
    return job->plan_fn(job);
}

static void job_stream(job_t *job, stream_t *s)
{
    writer_t w;
    writer_init(&w, s, NULL, NULL);
    job_payload(&w, 0, job);
    writer_end_stream(&w);
}

#if !defined(__OPTIMIZE_SIZE__)
/* COBS bound of a body of n bytes, with the delimiter. */
static size_t frame_bound(size_t body)
{
    return body + body / 254u + 2u;
}

/*
 * The frame straight into buf, which holds the frame_bound of max_bits: the
 * payload goes to buf + 1 (behind the first code byte) and gets its CRC; a
 * body with full COBS blocks moves up by their number (a code byte each),
 * and COBS turns it into its code in place. Nothing is written beyond the
 * frame.
 */
static bsf_status_t job_direct(job_t *job, uint8_t *buf, size_t *out_len)
{
    const size_t max_payload = ((size_t)job->plan.max_bits + 7u) / 8u;
    uint8_t *const start = buf + 1;
    writer_t w;
    size_t payload;
    size_t body;
    uint32_t crc;
    size_t full = 0;
    size_t len;
    unsigned i;
    /* the last word may reach 3 bytes beyond the payload, into the CRC's place */
    writer_init(&w, NULL, start, start + max_payload + BSF_FRAME_CRC_SIZE);
    job_payload(&w, 0, job);
    payload = (writer_bits(&w, start) + 7u) / 8u;
    writer_flush(&w);
    if (w.overflow || payload > max_payload) {
        *out_len = 0u;
        return BSF_ERR_BUFFER; /* beyond the planned bound: never happens */
    }
    crc = bsf_crc32c(0u, start, payload);
    for (i = 0; i < 4u; ++i) {
        start[payload + i] = (uint8_t)(crc >> (8u * i));
    }
    body = payload + BSF_FRAME_CRC_SIZE;
    if (body >= 254u) {
        full = bsf_cobs_full_blocks(start, body);
        if (full > 0u) {
            memmove(start + full, start, body);
        }
    }
    len = bsf_cobs_encode_in_place(buf, 1u + full, body);
    buf[len] = 0u;
    *out_len = len + 1u;
    return BSF_OK;
}
#endif

static bsf_status_t job_encode(job_t *job, uint8_t *buf, size_t cap, size_t *out_len)
{
    const bsf_status_t st = job_plan(job);
    size_t body;
    stream_t s;
    if (st != BSF_OK) {
        *out_len = 0u;
        return st;
    }
#if !defined(__OPTIMIZE_SIZE__)
    /* The direct writer is for speed only: a size-optimised build (-Os)
     * leaves it out and always streams, which gives the same frame. */
    if (buf != NULL &&
        cap >= frame_bound(((size_t)job->plan.max_bits + 7u) / 8u + BSF_FRAME_CRC_SIZE)) {
        return job_direct(job, buf, out_len);
    }
#endif
    body = ((size_t)job_bits(job) + 7u) / 8u + BSF_FRAME_CRC_SIZE;
    if (body < 254u) {
        *out_len = body + 2u; /* exact: no block reaches 254 bytes */
    } else {
        stream_init(&s); /* count */
        job_stream(job, &s);
        *out_len = s.pos;
    }
    if (buf == NULL) {
        return BSF_OK;
    }
    if (*out_len > cap) {
        return BSF_ERR_BUFFER;
    }
    stream_init(&s);
    s.buf = buf;
    s.cap = cap;
    job_stream(job, &s);
    *out_len = s.pos;
    return BSF_OK;
}

static bsf_status_t job_encode_sink(job_t *job, bsf_encoder_t *work, bsf_sink_fn sink, void *ctx,
                                    size_t *written)
{
    stream_t s;
    const bsf_status_t st = job_plan(job);
    if (st != BSF_OK) {
        return st;
    }
    memset(&s, 0, sizeof s);
    s.work = work;
    s.sink = sink;
    s.ctx = ctx;
    block_start(&s);
    job_stream(job, &s);
    if (written != NULL) {
        *written = s.pos;
    }
    return s.failed ? BSF_ERR_BUFFER : BSF_OK;
}

void bsf_frame_info_init(bsf_frame_info_t *info)
{
    if (info != NULL) {
        info->seq = 0u;
        info->timestamp_ms = 0u;
        info->has_pose = 0u;
        info->pose.x = 0.0f;
        info->pose.y = 0.0f;
        info->pose.theta = 0.0f;
        info->quant_step = BSF_QUANT_STEP_DEFAULT;
        info->has_geometry = 0u;
        info->angle_min = 0.0f;
        info->angle_increment = 0.0f;
    }
}

/* A features-frame job over result, quantising into table. */
static void frame_job_init(job_t *job, const bsf_frame_info_t *info, const bsf_result_t *result,
                           uint32_t *table)
{
    memset(job, 0, sizeof *job);
    job->info = info;
    job->res = result;
    job->table = table;
    job->plan_fn = frame_job_plan;
    job->payload_fn = frame_job_payload;
}

bsf_status_t bsf_frame_encode(const bsf_frame_info_t *info, const bsf_result_t *result,
                              uint8_t *buf, size_t cap, size_t *out_len)
{
    uint32_t table[VALUE_TABLE];
    job_t job;
    if (info == NULL || result == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    frame_job_init(&job, info, result, table);
    return job_encode(&job, buf, cap, out_len);
}

bsf_status_t bsf_frame_encode_sink(bsf_encoder_t *work, const bsf_frame_info_t *info,
                                   const bsf_result_t *result, bsf_sink_fn sink, void *ctx,
                                   size_t *written)
{
    uint32_t table[VALUE_TABLE];
    job_t job;
    if (written != NULL) {
        *written = 0u;
    }
    if (work == NULL || info == NULL || result == NULL || sink == NULL) {
        return BSF_ERR_ARG;
    }
    frame_job_init(&job, info, result, table);
    return job_encode_sink(&job, work, sink, ctx, written);
}

bsf_status_t bsf_metadata_encode(const bsf_metadata_t *m, uint8_t *buf, size_t cap, size_t *out_len)
{
    job_t job;
    if (m == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    memset(&job, 0, sizeof job);
    job.meta = m;
    job.plan_fn = metadata_job_plan;
    job.payload_fn = metadata_job_payload;
    return job_encode(&job, buf, cap, out_len);
}

bsf_status_t bsf_metadata_encode_sink(bsf_encoder_t *work, const bsf_metadata_t *m,
                                      bsf_sink_fn sink, void *ctx, size_t *written)
{
    job_t job;
    if (written != NULL) {
        *written = 0u;
    }
    if (work == NULL || m == NULL || sink == NULL) {
        return BSF_ERR_ARG;
    }
    memset(&job, 0, sizeof job);
    job.meta = m;
    job.plan_fn = metadata_job_plan;
    job.payload_fn = metadata_job_payload;
    return job_encode_sink(&job, work, sink, ctx, written);
}
