/* SPDX-License-Identifier: MIT */
/*
 * bsf_metadata_decode.c - the metadata frame's parser (docs/FORMAT.md,
 * "Metadata frame"), called by bsf_stream_decode.c for frames of type
 * BSF_FRAME_TYPE_METADATA; the bit reader is bsf_stream_reader.h's.
 */
#include <string.h>

#include "bsf_frame_parsers.h"

static int get_cap(reader_t *r, unsigned k, uint32_t *v)
{
    return get_u32(r, k, BSF_WIRE_META_U16_MAX, v) && *v >= 1u;
}

/* Every cap the frame carries, in wire order. */
static int get_caps(reader_t *r, bsf_metadata_t *m)
{
#define META_CAP_GET(field, cap, k) get_cap(r, k, &m->field) &&
    return BSF_WIRE_META_CAPS(META_CAP_GET) 1;
#undef META_CAP_GET
}

/* Metadata payload after byte 0 (see metadata_payload in the encoder). */
static bsf_status_t parse_metadata(reader_t *r, bsf_metadata_t *out)
{
    bsf_metadata_t m;
    uint32_t v[3];
    uint32_t method;
    uint32_t step_code;
    uint32_t has_origin;
    uint32_t source_len;
    uint32_t i;
    int64_t origin = 0;

    memset(&m, 0, sizeof m);
    for (i = 0; i < 3u; ++i) {
        if (!get_u32(r, BSF_WIRE_K_LIB_VERSION, BSF_WIRE_META_U16_MAX, &v[i])) {
            return BSF_ERR_FORMAT;
        }
    }
    if (!get_u32(r, BSF_WIRE_K_METHOD, BSF_WIRE_METHOD_MAX, &method) ||
        !get_float(r, &m.target_rms) || !(m.target_rms >= 0.0f) ||
        !get_u32(r, BSF_WIRE_K_STEP, BSF_WIRE_STEP_CODE_MAX, &step_code) || step_code == 0u ||
        !get_caps(r, &m) ||
        !get_u32(r, BSF_WIRE_K_META_N_BEAMS, BSF_WIRE_META_U16_MAX, &m.n_beams) ||
        !get_float(r, &m.angle_min) || !get_float(r, &m.angle_increment) ||
        !get_float(r, &m.range_min) || !get_float(r, &m.range_max) || !(m.range_min >= 0.0f) ||
        !(m.range_max >= m.range_min) || !get_bits(r, 1u, &has_origin)) {
        return BSF_ERR_FORMAT;
    }
    if (has_origin != 0u &&
        !get_signed(r, BSF_WIRE_K_TIME_ORIGIN, BSF_METADATA_TIME_ORIGIN_MAX, &origin)) {
        return BSF_ERR_FORMAT;
    }
    if (!get_u32(r, BSF_WIRE_K_SOURCE_LEN, BSF_METADATA_SOURCE_MAX, &source_len)) {
        return BSF_ERR_FORMAT;
    }
    for (i = 0; i < source_len; ++i) {
        uint32_t c;
        if (!get_bits(r, 8u, &c)) {
            return BSF_ERR_FORMAT;
        }
        m.source[i] = (char)c;
    }
    if (!bsf_wire_source_ok((const uint8_t *)m.source, source_len) || !padding_ok(r)) {
        return BSF_ERR_FORMAT;
    }
    if (out != NULL) {
        m.lib_version_major = (uint16_t)v[0];
        m.lib_version_minor = (uint16_t)v[1];
        m.lib_version_patch = (uint16_t)v[2];
        m.method = (uint8_t)method;
        m.quant_step = (float)step_code * BSF_QUANT_STEP_UNIT;
        m.has_time_origin = (uint8_t)has_origin;
        m.time_origin_us = origin;
        m.source_len = (uint8_t)source_len;
        m.source[source_len] = '\0';
        *out = m;
    }
    return BSF_OK;
}

bsf_status_t bsf_metadata_parse(reader_t *r, unsigned version, bsf_frame_t *out)
{
    const bsf_status_t st = parse_metadata(r, out != NULL ? &out->metadata : NULL);
    if (st == BSF_OK && out != NULL) {
        bsf_result_t *res = &out->result;
        out->version = (uint8_t)version;
        out->type = (uint8_t)BSF_FRAME_TYPE_METADATA;
        out->seq = 0u;
        out->timestamp_ms = 0u;
        out->has_pose = 0u;
        out->pose.x = 0.0f;
        out->pose.y = 0.0f;
        out->pose.theta = 0.0f;
        out->quant_step = out->metadata.quant_step;
        out->time_us = 0u;
        out->has_geometry = 0u;
        out->angle_min = 0.0f;
        out->angle_increment = 0.0f;
        res->n_features = 0u;
        res->n_ctrl = 0u;
        memset(&res->stats, 0, sizeof res->stats);
    }
    return st;
}
