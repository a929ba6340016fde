/* SPDX-License-Identifier: MIT */
/*
 * bsf_stream_decode.c - frame decoding apart from what a frame holds:
 * bsf_frame_decode checks a body's CRC-32C, reads its version and type byte
 * and hands the payload to that type's parser (the table below: a new frame
 * type joins by one entry, its parser declared in bsf_frame_parsers.h);
 * bsf_decoder_feed undoes COBS byte by byte, finds the 0x00 delimiters and
 * counts what it could not deliver.
 */
#include "bsf/bsf_stream.h"

#include <string.h>

#include "bsf_frame_parsers.h"
#include "bsf_wire.h"

/* The frame types this decoder reads, from the format version each
 * appeared in (up to BSF_FORMAT_VERSION). */
static const struct {
    uint8_t type;
    uint8_t min_version;
    bsf_frame_parse_fn parse;
} frame_types[] = {
    {BSF_FRAME_TYPE_FEATURES, BSF_FORMAT_VERSION_MIN, bsf_features_parse},
    {BSF_FRAME_TYPE_METADATA, 2u, bsf_metadata_parse},
    {BSF_FRAME_TYPE_MAP, 2u, bsf_map_parse},
};

/*
 * Parse a payload whose CRC has been checked. With out == NULL it only
 * validates; with out it writes, and then cannot fail (same bytes).
 */
static bsf_status_t parse_payload(const uint8_t *p, size_t len, bsf_frame_t *out)
{
    unsigned version;
    unsigned type;
    size_t i;
    reader_t r;

    if (len < 1u) {
        return BSF_ERR_FORMAT;
    }
    version = (unsigned)p[0] >> 4;
    type = p[0] & 0x0Fu;
    if (version < BSF_FORMAT_VERSION_MIN || version > BSF_FORMAT_VERSION) {
        return BSF_ERR_VERSION;
    }
    r.p = p + 1;
    r.len = len - 1u;
    r.bit_pos = 0;
    for (i = 0; i < sizeof frame_types / sizeof frame_types[0]; ++i) {
        if (frame_types[i].type == type && version >= frame_types[i].min_version) {
            return frame_types[i].parse(&r, version, out);
        }
    }
    return BSF_ERR_VERSION; /* a type this version does not have */
}

/* Version, type and fields of a body whose CRC has been checked. */
static bsf_status_t decode_checked(const uint8_t *body, size_t len, bsf_frame_t *out)
{
    const size_t payload_len = len - BSF_FRAME_CRC_SIZE;
    bsf_status_t st = parse_payload(body, payload_len, NULL);
    if (st == BSF_OK) {
        st = parse_payload(body, payload_len, out);
    }
    if (st == BSF_OK) {
        out->payload = body;
        out->payload_len = payload_len;
    }
    return st;
}

bsf_status_t bsf_frame_decode(const uint8_t *body, size_t len, bsf_frame_t *out)
{
    if (body == NULL || out == NULL) {
        return BSF_ERR_ARG;
    }
    if (len <= BSF_FRAME_CRC_SIZE || bsf_crc32c(0u, body, len) != BSF_WIRE_CRC_RESIDUE) {
        return BSF_ERR_CRC;
    }
    return decode_checked(body, len, out);
}

static void frame_reset(bsf_decoder_t *dec)
{
    dec->len = 0u;
    dec->raw_len = 0u;
    dec->crc = 0u;
    dec->block_left = 0u;
    dec->block_code = 0u;
    dec->overflow = 0u;
}

void bsf_decoder_init(bsf_decoder_t *dec)
{
    if (dec != NULL) {
        frame_reset(dec);
        dec->meta_n_beams = 0u;
        memset(&dec->stats, 0, sizeof dec->stats);
    }
}

static void append(bsf_decoder_t *dec, uint8_t b)
{
    if (dec->len >= sizeof dec->body) {
        dec->overflow = 1u;
        return;
    }
    dec->body[dec->len++] = b;
    dec->crc = bsf_crc32c(dec->crc, &b, 1u);
}

/* The beam count of the last metadata frame, for a features frame that
 * does not carry its own, when it is consistent with the frame. */
static void fill_n_beams(bsf_result_t *res, uint32_t n_beams)
{
    uint32_t i;
    if (n_beams == 0u || res->stats.n_valid > n_beams) {
        return;
    }
    for (i = 0; i < res->n_features; ++i) {
        if (res->features[i].last_beam >= n_beams) {
            return;
        }
    }
    res->stats.n_beams = n_beams;
}

/* A delimiter arrived: deliver the frame or count why not. */
static int end_frame(bsf_decoder_t *dec, bsf_frame_t *out)
{
    bsf_decoder_stats_t *st = &dec->stats;
    int delivered = 0;

    if (dec->overflow) {
        ++st->oversize;
    } else if (dec->block_left != 0u) {
        ++st->malformed; /* the frame ends inside a COBS block: bytes were lost */
    } else if (dec->len <= BSF_FRAME_CRC_SIZE || dec->crc != BSF_WIRE_CRC_RESIDUE) {
        ++st->bad_crc;
    } else {
        const bsf_status_t s = decode_checked(dec->body, dec->len, out);
        if (s == BSF_OK) {
            ++st->frames_ok;
            delivered = out->type;
            if (out->type == BSF_FRAME_TYPE_METADATA) {
                ++st->metadata;
                dec->meta_n_beams = out->metadata.n_beams;
            } else if (out->result.stats.n_beams == 0u) {
                fill_n_beams(&out->result, dec->meta_n_beams);
            }
        } else if (s == BSF_ERR_VERSION) {
            const unsigned version = (unsigned)(dec->body[0] >> 4);
            if (version < BSF_FORMAT_VERSION_MIN || version > BSF_FORMAT_VERSION) {
                ++st->unsupported_version;
            } else {
                ++st->unknown_type;
            }
        } else {
            ++st->malformed;
        }
    }
    if (!delivered) {
        st->bytes_skipped += (uint32_t)dec->raw_len;
    }
    frame_reset(dec);
    return delivered;
}

int bsf_decoder_feed(bsf_decoder_t *dec, const uint8_t *data, size_t len, size_t *consumed,
                     bsf_frame_t *out)
{
    size_t i;

    if (dec == NULL || consumed == NULL || out == NULL || (data == NULL && len > 0u)) {
        return BSF_ERR_ARG;
    }
    for (i = 0; i < len; ++i) {
        const uint8_t b = data[i];
        if (b == 0u) {
            if (dec->raw_len != 0u) {
                const int type = end_frame(dec, out);
                if (type != 0) {
                    *consumed = i + 1u;
                    return type;
                }
            }
            continue;
        }
        ++dec->raw_len;
        if (dec->overflow) {
            continue;
        }
        if (dec->block_left == 0u) {
            /* A code byte: the previous short block stood for a zero. */
            if (dec->block_code != 0u && dec->block_code != 0xFFu) {
                append(dec, 0u);
            }
            dec->block_code = b;
            dec->block_left = (uint8_t)(b - 1u);
        } else {
            append(dec, b);
            --dec->block_left;
        }
    }
    *consumed = len;
    return 0;
}
