/* SPDX-License-Identifier: MIT */
/*
 * bsf_metadata_encode.c - the metadata frame's encoder (bsf_metadata_init,
 * bsf_metadata_encode, bsf_metadata_encode_sink; docs/FORMAT.md, "Metadata
 * frame"): its checks and its payload's fields. The bytes (bit writer, CRC,
 * COBS) are bsf_stream_writer.h's.
 */
#include "bsf/bsf_stream.h"

#include <string.h>

#include "bsf_math.h"
#include "bsf_stream_writer.h"
#include "bsf_wire.h"

void bsf_metadata_init(bsf_metadata_t *m)
{
    if (m != NULL) {
        memset(m, 0, sizeof *m);
        m->lib_version_major = (uint16_t)BSF_VERSION_MAJOR;
        m->lib_version_minor = (uint16_t)BSF_VERSION_MINOR;
        m->lib_version_patch = (uint16_t)BSF_VERSION_PATCH;
        m->quant_step = BSF_QUANT_STEP_DEFAULT;
#define META_CAP_INIT(field, cap, k) m->field = (uint32_t)(cap);
        BSF_WIRE_META_CAPS(META_CAP_INIT)
#undef META_CAP_INIT
    }
}

static int cap_ok(uint32_t v)
{
    return v >= 1u && v <= BSF_WIRE_META_U16_MAX;
}

/* Every cap the frame carries within 1..65535. */
static int caps_ok(const bsf_metadata_t *m)
{
#define META_CAP_OK(field, cap, k) cap_ok(m->field) &&
    return BSF_WIRE_META_CAPS(META_CAP_OK) 1;
#undef META_CAP_OK
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
    if (!is_finite_f(m->target_rms) || !(m->target_rms >= 0.0f) || !caps_ok(m) ||
        m->n_beams > BSF_WIRE_META_U16_MAX || !is_finite_f(m->angle_min) ||
        !is_finite_f(m->angle_increment) || !is_finite_f(m->range_min) ||
        !is_finite_f(m->range_max) || !(m->range_min >= 0.0f) || !(m->range_max >= m->range_min) ||
        m->has_time_origin > 1u ||
        (m->has_time_origin != 0u && (m->time_origin_us > BSF_METADATA_TIME_ORIGIN_MAX ||
                                      m->time_origin_us < -BSF_METADATA_TIME_ORIGIN_MAX)) ||
        m->source_len > BSF_METADATA_SOURCE_MAX ||
        !bsf_wire_source_ok((const uint8_t *)m->source, m->source_len)) {
        return BSF_ERR_ARG;
    }
    return BSF_OK;
}

static void metadata_payload(writer_t *w, int costing, const bsf_metadata_t *m, uint32_t step_code)
{
    (void)costing; /* unused in the compact variant (ENC_COSTING) */
    bits_t *b = &w->b;
    unsigned i;
    field_u(w, b, costing, (BSF_FORMAT_VERSION << 4) | BSF_FRAME_TYPE_METADATA, 8u);
    field_eg(w, b, costing, m->lib_version_major, BSF_WIRE_K_LIB_VERSION);
    field_eg(w, b, costing, m->lib_version_minor, BSF_WIRE_K_LIB_VERSION);
    field_eg(w, b, costing, m->lib_version_patch, BSF_WIRE_K_LIB_VERSION);
    field_eg(w, b, costing, m->method, BSF_WIRE_K_METHOD);
    field_float(w, b, costing, m->target_rms);
    field_eg(w, b, costing, step_code, BSF_WIRE_K_STEP);
#define META_CAP_FIELD(field, cap, k) field_eg(w, b, costing, m->field, k);
    BSF_WIRE_META_CAPS(META_CAP_FIELD)
#undef META_CAP_FIELD
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

/* ---- The metadata frame as a job of bsf_stream_writer.h ----------------- */

typedef struct {
    bsf_enc_job_t job; /* first: the writer's view */
    const bsf_metadata_t *meta;
    uint32_t step_code;
} metadata_job_t;

static void metadata_job_payload(writer_t *w, int costing, bsf_enc_job_t *job)
{
    const metadata_job_t *mj = (const metadata_job_t *)job;
    metadata_payload(w, costing, mj->meta, mj->step_code);
}

static bsf_status_t metadata_job_plan(bsf_enc_job_t *job)
{
    metadata_job_t *mj = (metadata_job_t *)job;
    const bsf_status_t st = check_metadata(mj->meta, &mj->step_code);
    if (st == BSF_OK) {
        job->max_bits = bsf_enc_job_bits(job); /* exact */
    }
    return st;
}

static void metadata_job_init(metadata_job_t *mj, const bsf_metadata_t *m)
{
    memset(mj, 0, sizeof *mj);
    mj->meta = m;
    mj->job.plan = metadata_job_plan;
    mj->job.payload = metadata_job_payload;
}

bsf_status_t bsf_metadata_encode(const bsf_metadata_t *m, uint8_t *buf, size_t cap, size_t *out_len)
{
    metadata_job_t mj;
    if (m == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    metadata_job_init(&mj, m);
    return bsf_enc_job_encode(&mj.job, buf, cap, out_len);
}

bsf_status_t bsf_metadata_encode_sink(bsf_encoder_t *work, const bsf_metadata_t *m,
                                      bsf_sink_fn sink, void *ctx, size_t *written)
{
    metadata_job_t mj;
    if (written != NULL) {
        *written = 0u;
    }
    if (work == NULL || m == NULL || sink == NULL) {
        return BSF_ERR_ARG;
    }
    metadata_job_init(&mj, m);
    return bsf_enc_job_encode_sink(&mj.job, work, sink, ctx, written);
}
