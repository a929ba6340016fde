/* SPDX-License-Identifier: MIT */
/*
 * bsf_stream_writer.c - the byte machinery of the frame encoders: the
 * streaming output (payload bytes through CRC-32C and COBS to a counter, a
 * buffer or a sink), the bit writer's spill of a full chunk, and the frame
 * job that plans a frame and writes it (bsf_stream_writer.h). Nothing here
 * knows what a frame holds; the frame types live in bsf_features_encode.c
 * and bsf_metadata_encode.c.
 */
#include "bsf_stream_writer.h"
#include "bsf_compact.h"

/* ---- Streaming output: COBS blocks to a counter, a buffer or a sink ---- */

typedef struct bsf_cobs_out {
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

static BSF_COMPACT_NOINLINE void emit(stream_t *s, const uint8_t *data, size_t len)
{
    if (!s->failed) {
        if (s->sink(s->ctx, data, len) != 0) {
            s->failed = 1;
        } else {
            s->pos += len;
        }
    }
}

static BSF_COMPACT_INLINE void block_start(stream_t *s)
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

static BSF_COMPACT_NOINLINE void stream_init(stream_t *s)
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

#if !BSF_CONFIG_COMPACT /* the direct writer only (job_direct) */
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

/* ---- Bit writer: the rare paths ------------------------------------------ */

uint8_t *bsf_writer_spill(writer_t *w, uint8_t *p)
{
    if (w->out != NULL) {
        stream_payload(w->out, w->chunk, (size_t)(p - w->chunk));
    } else {
        w->overflow = 1;
    }
    w->end = w->chunk + CHUNK_BYTES;
    return w->chunk;
}

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

/* ---- Frame job: plan, then write to a buffer or a sink ------------------ */

/* The exact payload bits: a costing run (a call of its own, so that its
 * writer is not on the planning run's stack). */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
uint32_t
bsf_enc_job_bits(bsf_enc_job_t *job)
{
    writer_t w;
    writer_init(&w, 1, NULL, NULL, NULL);
    job->payload(&w, 1, job);
    return w.b.bits;
}

/* Checks the input and bounds the payload's size (and chooses the orders). */
static bsf_status_t job_plan(bsf_enc_job_t *job)
{
    job->max_bits = 0u;
    return job->plan(job);
}

static void job_stream(bsf_enc_job_t *job, stream_t *s)
{
    writer_t w;
    writer_init(&w, 0, s, NULL, NULL);
    job->payload(&w, 0, job);
    writer_end_stream(&w);
}

#if !BSF_CONFIG_COMPACT
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
static bsf_status_t job_direct(bsf_enc_job_t *job, uint8_t *buf, size_t *out_len)
{
    const size_t max_payload = ((size_t)job->max_bits + 7u) / 8u;
    uint8_t *const start = buf + 1;
    writer_t w;
    size_t payload;
    size_t body;
    uint32_t crc;
    size_t full = 0;
    size_t len;
    unsigned i;
    /* the last word may reach 3 bytes beyond the payload, into the CRC's place */
    writer_init(&w, 0, NULL, start, start + max_payload + BSF_FRAME_CRC_SIZE);
    job->payload(&w, 0, job);
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

bsf_status_t bsf_enc_job_encode(bsf_enc_job_t *job, uint8_t *buf, size_t cap, size_t *out_len)
{
    const bsf_status_t st = job_plan(job);
    size_t body;
    stream_t s;
    if (st != BSF_OK) {
        *out_len = 0u;
        return st;
    }
#if !BSF_CONFIG_COMPACT
    /* The direct writer is for speed only: the compact variant leaves it
     * out and always streams, which gives the same frame. */
    if (buf != NULL && cap >= frame_bound(((size_t)job->max_bits + 7u) / 8u + BSF_FRAME_CRC_SIZE)) {
        return job_direct(job, buf, out_len);
    }
#endif
    body = ((size_t)bsf_enc_job_bits(job) + 7u) / 8u + BSF_FRAME_CRC_SIZE;
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

bsf_status_t bsf_enc_job_encode_sink(bsf_enc_job_t *job, bsf_encoder_t *work, bsf_sink_fn sink,
                                     void *ctx, size_t *written)
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
