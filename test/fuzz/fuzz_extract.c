/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: the extractor fed arbitrary ranges, geometry and some
 * parameters. Checks: the status is one the API documents, an error leaves
 * an empty result, a success gives a finite, consistent result within the
 * caps whose valid-point count matches the scan, and whose frame (when the
 * encoder can represent it) decodes to control points within half a step.
 *
 * Input: byte 0 = flags, then geometry, optional parameters, then ranges.
 */
#include <string.h>

#include "fuzz_check.h"

enum {
    F_RPOS = 0x01,       /* method RPOS-LSBA instead of FALKO-SVED-PDM */
    F_RAW_RANGES = 0x02, /* ranges are raw float bits (else uint16 millimetres) */
    F_RAW_GEOM = 0x04,   /* geometry is raw float bits (else small codes) */
    F_PARAMS = 0x08,     /* segmentation and FALKO parameters follow */
    F_OVER_CAP = 0x10,   /* claim one beam more than BSF_MAX_POINTS */
    F_ENCODE = 0x20      /* also encode and decode the result */
};

static bsf_extractor_t ex;
static bsf_result_t res;
static float ranges[BSF_MAX_POINTS + 1];
static uint8_t wire[BSF_FRAME_MAX_SIZE];
static bsf_decoder_t dec;
static bsf_frame_t frame;

typedef struct {
    const uint8_t *p;
    size_t n;
} input_t;

static uint32_t take_u32(input_t *in, size_t bytes)
{
    uint32_t v = 0u;
    size_t i;
    for (i = 0; i < bytes; ++i) {
        v |= (uint32_t)(in->n > 0u ? *in->p : 0u) << (8u * i);
        if (in->n > 0u) {
            in->p++;
            in->n--;
        }
    }
    return v;
}

static float take_raw_float(input_t *in)
{
    const uint32_t bits = take_u32(in, 4u);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static void check_error_result(void)
{
    static const bsf_stats_t zero;
    FUZZ_CHECK(res.n_features == 0u && res.n_ctrl == 0u);
    FUZZ_CHECK(memcmp(&res.stats, &zero, sizeof zero) == 0);
}

static void check_roundtrip(void)
{
    bsf_frame_info_t info;
    size_t len = 0u;
    size_t used = 0u;
    size_t k;
    bsf_status_t st;
    bsf_frame_info_init(&info);
    st = bsf_frame_encode(&info, &res, wire, sizeof wire, &len);
    if (st != BSF_OK) {
        /* only values the format cannot carry may be refused */
        int unrepresentable = 0;
        FUZZ_CHECK(st == BSF_ERR_ARG);
        for (k = 0; k < res.n_ctrl; ++k) {
            if (fabsf(res.ctrl[k].x) / info.quant_step > 8388000.0f ||
                fabsf(res.ctrl[k].y) / info.quant_step > 8388000.0f) {
                unrepresentable = 1;
            }
        }
        for (k = 0; k < res.n_features; ++k) {
            if (res.features[k].e_curve > BSF_E_CURVE_MAX * 0.999f) {
                unrepresentable = 1;
            }
        }
        FUZZ_CHECK(unrepresentable);
        return;
    }
    bsf_decoder_init(&dec);
    FUZZ_CHECK(bsf_decoder_feed(&dec, wire, len, &used, &frame) == 1 && used == len);
    FUZZ_CHECK(frame.result.n_features == res.n_features);
    FUZZ_CHECK(frame.result.n_ctrl == res.n_ctrl);
    for (k = 0; k < res.n_ctrl; ++k) {
        const float tol = 0.5001f * frame.quant_step + 1e-6f * fabsf(res.ctrl[k].x) +
                          1e-6f * fabsf(res.ctrl[k].y);
        FUZZ_CHECK(fabsf(frame.result.ctrl[k].x - res.ctrl[k].x) <= tol);
        FUZZ_CHECK(fabsf(frame.result.ctrl[k].y - res.ctrl[k].y) <= tol);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    input_t in;
    bsf_params_t params;
    bsf_scan_t scan;
    bsf_status_t st;
    size_t count = 0u;
    size_t n_valid = 0u;
    size_t i;
    uint8_t flags;
    if (size == 0u) {
        return 0;
    }
    in.p = data;
    in.n = size;
    flags = (uint8_t)take_u32(&in, 1u);
    params =
        bsf_params_default((flags & F_RPOS) ? BSF_METHOD_RPOS_LSBA : BSF_METHOD_FALKO_SVED_PDM);
    if (flags & F_RAW_GEOM) {
        scan.angle_min = take_raw_float(&in);
        scan.angle_increment = take_raw_float(&in);
        scan.range_min = take_raw_float(&in);
        scan.range_max = take_raw_float(&in);
    } else {
        const uint32_t g = take_u32(&in, 2u);
        scan.angle_min = -3.1f + 0.1f * (float)(g & 0x3Fu);
        scan.angle_increment = 0.0005f * (float)((g >> 6) & 0x3Fu) + 0.0005f;
        if (g & 0x8000u) {
            scan.angle_increment = -scan.angle_increment;
        }
        scan.range_min = 0.05f;
        scan.range_max = (g & 0x4000u) ? 30.0f : 81.0f;
    }
    if (flags & F_PARAMS) {
        params.sved.a = take_raw_float(&in);
        params.sved.b = take_raw_float(&in);
        params.sved.min_segment_points = (uint16_t)take_u32(&in, 2u);
        params.rpos.min_segment_points = params.sved.min_segment_points;
        params.rpos.alpha_max = take_raw_float(&in);
        params.falko.neigh_a = take_raw_float(&in);
        params.falko.nms_radius = take_raw_float(&in);
    }
    st = bsf_extractor_init(&ex, &params);
    FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_PARAM);
    FUZZ_CHECK((st == BSF_OK) == (bsf_params_check(&params) == BSF_OK));

    while (in.n > 0u && count < BSF_MAX_POINTS) {
        if (flags & F_RAW_RANGES) {
            ranges[count++] = take_raw_float(&in);
        } else {
            const uint32_t mm = take_u32(&in, 2u);
            ranges[count++] = (mm == 0xFFFFu) ? NAN : 0.001f * (float)mm;
        }
    }
    if (flags & F_OVER_CAP) {
        for (i = count; i <= BSF_MAX_POINTS; ++i) {
            ranges[i] = 1.0f;
        }
        count = BSF_MAX_POINTS + 1u;
    }
    scan.ranges = ranges;
    scan.count = count;

    memset(&res, 0x5A, sizeof res);
    st = bsf_extract(&ex, &scan, &res);
    if (st < 0) {
        FUZZ_CHECK(st == BSF_ERR_ARG || st == BSF_ERR_CAPACITY);
        check_error_result();
        return 0;
    }
    /* BSF_OK_CUT: a cap cut the output, and the stats say so (issue 18) */
    FUZZ_CHECK(st == BSF_OK || st == BSF_OK_CUT);
    FUZZ_CHECK((st == BSF_OK_CUT) == (res.stats.cut != 0u));
    FUZZ_CHECK(count <= BSF_MAX_POINTS);
    fuzz_check_result(&res, 1);
    for (i = 0; i < count; ++i) {
        n_valid += (size_t)bsf_range_is_valid(ranges[i], scan.range_min, scan.range_max);
    }
    FUZZ_CHECK(res.stats.n_valid == n_valid);
    FUZZ_CHECK(res.stats.n_keypoints <= BSF_MAX_KEYPOINTS);
    for (i = 0; i < res.n_features; ++i) {
        FUZZ_CHECK(res.features[i].last_beam < count);
    }
    if (flags & F_ENCODE) {
        check_roundtrip();
    }
    return 0;
}
