/* SPDX-License-Identifier: MIT */
/*
 * bsf_cobs.c - byte machinery: Consistent Overhead Byte Stuffing, the
 * framing of every frame (docs/FORMAT.md). The public one-shot coder
 * (bsf_cobs_encode, bsf_cobs_decode) and, for the frame writer, the count
 * of full blocks and the in-place encoder (bsf_wire.h).
 */
#include "bsf/bsf_stream.h"

#include <string.h>

#include "bsf_wire.h"

bsf_status_t bsf_cobs_encode(const uint8_t *in, size_t len, uint8_t *out, size_t cap,
                             size_t *out_len)
{
    size_t i;
    size_t pos = 1;      /* next data byte goes here */
    size_t code_pos = 0; /* where the current block's code byte goes */
    uint8_t code = 1;    /* 1 + data bytes in the current block */
    size_t need = 1;

    if ((in == NULL && len > 0) || out == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    /* Exact size first, so that nothing is written when it does not fit. */
    for (i = 0; i < len; ++i) {
        if (in[i] == 0u) {
            ++need;
            code = 1;
        } else {
            ++need;
            if (++code == 0xFFu) {
                ++need;
                code = 1;
            }
        }
    }
    *out_len = need;
    if (need > cap) {
        return BSF_ERR_BUFFER;
    }
    code = 1;
    for (i = 0; i < len; ++i) {
        if (in[i] == 0u) {
            out[code_pos] = code;
            code_pos = pos++;
            code = 1;
        } else {
            out[pos++] = in[i];
            if (++code == 0xFFu) {
                out[code_pos] = code;
                code_pos = pos++;
                code = 1;
            }
        }
    }
    out[code_pos] = code;
    return BSF_OK;
}

/* Non-zero bytes at s before the first zero, at most limit: a machine word
 * at a time (a word has a zero byte when subtracting 1 from every byte
 * borrows into a byte whose top bit was clear), then byte by byte. */
static size_t nonzero_run(const uint8_t *s, size_t limit)
{
    const size_t ones = (size_t)-1 / 0xFFu; /* 0x01 in every byte */
    const size_t highs = ones * 0x80u;
    size_t i = 0;
    while (limit - i >= sizeof(size_t)) {
        size_t word;
        memcpy(&word, s + i, sizeof word);
        if (((word - ones) & ~word & highs) != 0u) {
            break;
        }
        i += sizeof(size_t);
    }
    while (i < limit && s[i] != 0u) {
        ++i;
    }
    return i;
}

size_t bsf_cobs_full_blocks(const uint8_t *body, size_t n)
{
    size_t full = 0;
    size_t i = 0;
    for (;;) {
        const size_t left = n - i;
        const size_t run = nonzero_run(body + i, left < 254u ? left : 254u);
        i += run;
        if (run == 254u) {
            ++full;
        } else if (i == n) {
            return full;
        } else {
            ++i; /* the zero */
        }
    }
}

#if (defined(__GNUC__) || defined(__clang__)) && !BSF_CONFIG_COMPACT
/* A body of fewer than 254 bytes right behind its first code byte: no block
 * is full and no byte moves, so each zero byte becomes the distance to the
 * next zero (or to the end), and buf[0] the distance to the first. Zero
 * bytes are found a 64-bit word at a time: (w & 0x7F..) + 0x7F.. sets the
 * top bit of every byte whose low 7 bits are not all 0, which with w's own
 * top bits leaves exactly the zero bytes' top bits clear (no false hits). */
static size_t cobs_short_in_place(uint8_t *buf, size_t n)
{
    const uint64_t low7 = 0x7F7F7F7F7F7F7F7Full;
    uint8_t *code_at = buf;
    const uint8_t *const words_end = buf + 1 + (n & ~(size_t)7u);
    uint8_t *at = buf + 1;
    size_t i;
    for (; at != words_end; at += 8) {
        uint64_t w;
        uint64_t zeros;
        memcpy(&w, at, sizeof w);
        zeros = ~(((w & low7) + low7) | w | low7);
        while (zeros != 0u) {
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) &&                                 \
    __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
            const unsigned byte = (unsigned)__builtin_ctzll(zeros) / 8u;
#else
            const unsigned byte = (unsigned)__builtin_clzll(zeros) / 8u;
#endif
            uint8_t *const zero = at + byte;
            *code_at = (uint8_t)(zero - code_at);
            code_at = zero;
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) &&                                 \
    __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
            zeros &= zeros - 1u; /* the first byte is the lowest */
#else
            zeros &= ~((uint64_t)0x80u << (8u * (7u - byte))); /* the first byte is the highest */
#endif
        }
    }
    for (i = (size_t)(at - buf); i <= n; ++i) {
        if (buf[i] == 0u) {
            *code_at = (uint8_t)(buf + i - code_at);
            code_at = buf + i;
        }
    }
    *code_at = (uint8_t)(buf + n + 1u - code_at);
    return n + 1u;
}
#endif

/* Blocks as in bsf_cobs_encode; a block's data moves only when an earlier
 * block of 254 bytes inserted a code byte (bodies of 254 bytes or more). */
size_t bsf_cobs_encode_in_place(uint8_t *buf, size_t offset, size_t n)
{
    const uint8_t *src = buf + offset;
    const uint8_t *const src_end = src + n;
    uint8_t *code_at = buf;
    uint8_t *out = buf + 1;
#if (defined(__GNUC__) || defined(__clang__)) && !BSF_CONFIG_COMPACT
    if (offset == 1u && n < 254u) {
        return cobs_short_in_place(buf, n);
    }
#endif
    for (;;) {
        const size_t left = (size_t)(src_end - src);
        const size_t run = nonzero_run(src, left < 254u ? left : 254u);
        if (out != src) {
            memmove(out, src, run);
        }
        out += run;
        src += run;
        *code_at = (uint8_t)(run + 1u);
        if (run < 254u) {
            if (src == src_end) {
                break;
            }
            ++src; /* the zero: the next block's code byte takes its place */
        }
        code_at = out++;
    }
    return (size_t)(out - buf);
}

bsf_status_t bsf_cobs_decode(const uint8_t *in, size_t len, uint8_t *out, size_t cap,
                             size_t *out_len)
{
    size_t i = 0;
    size_t pos = 0;

    if ((in == NULL && len > 0) || out == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    while (i < len) {
        const uint8_t code = in[i++];
        uint8_t k;
        if (code == 0u || (size_t)(code - 1u) > len - i) {
            return BSF_ERR_FORMAT;
        }
        for (k = 1; k < code; ++k) {
            if (in[i] == 0u) {
                return BSF_ERR_FORMAT;
            }
            if (pos >= cap) {
                return BSF_ERR_BUFFER;
            }
            out[pos++] = in[i++];
        }
        /* A short block stands for its data plus one zero, except at the
         * very end, where that zero is the implicit one COBS appends. */
        if (code != 0xFFu && i < len) {
            if (pos >= cap) {
                return BSF_ERR_BUFFER;
            }
            out[pos++] = 0u;
        }
    }
    *out_len = pos;
    return BSF_OK;
}
