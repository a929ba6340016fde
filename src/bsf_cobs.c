/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_stream.h"

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
