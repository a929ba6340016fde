/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: the extractor (all four methods; the default,
 * LC-SVED-PDM, unless a flag picks another) fed arbitrary ranges, geometry,
 * parameters (LC's included) and a clock hook. Checks: bsf_extractor_init accepts
 * exactly the parameters bsf_params_check accepts, the status is one the API
 * documents, an error leaves an empty result, a success gives a finite,
 * consistent result within the caps whose valid-point count matches the
 * scan, the times are 0 without a clock and consistent with one, and the
 * frame (when the encoder can represent it) decodes to control points
 * within half a step.
 *
 * Input: byte 0 = flags (F_RPOS and F_BID pick the method: neither LC,
 * both FALKO), then geometry (2 bytes, or 16 with F_RAW_GEOM);
 * with F_PARAMS a count byte and that many edits of the method's defaults
 * (1 byte naming a field, 4 value bytes: a raw value when the field byte's
 * bit 7 is set, else a value near the default, so most edits stay in range
 * and reach the code behind the checks; field 36 sets a clock hook); with
 * F_OVER_CAP one byte picking a count of
 * BSF_MAX_POINTS + 1 - (0..3) beams, the ranges given repeated up to it;
 * then the ranges (uint16 millimetres, or raw float bits with F_RAW_RANGES).
 */
#include <string.h>

#include "fuzz_check.h"

enum {
    F_RPOS = 0x01,        /* method RPOS-LSBA (with F_BID: FALKO-SVED-PDM) */
    F_RAW_RANGES = 0x02,  /* ranges are raw float bits (else uint16 millimetres) */
    F_RAW_GEOM = 0x04,    /* geometry is raw float bits (else small codes) */
    F_PARAMS = 0x08,      /* parameter edits follow (any stage's) */
    F_OVER_CAP = 0x10,    /* a count at or just below/above BSF_MAX_POINTS */
    F_ENCODE = 0x20,      /* also encode and decode the result */
    F_FULL_CIRCLE = 0x40, /* the beams cover the whole circle (seam wrap paths) */
    F_BID = 0x80          /* method BID-SVED-PDM (with F_RPOS: FALKO-SVED-PDM) */
};

static uint32_t clock_now;
static uint32_t clock_step;
static unsigned clock_calls;

static uint32_t fake_clock(void *user)
{
    FUZZ_CHECK(user == &clock_now);
    ++clock_calls;
    clock_now += clock_step;
    return clock_now;
}

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

/* Every feature's curve evaluates to finite points and derivatives along
 * its length; the basis sums to 1; a NaN parameter is refused, outputs
 * untouched. */
static void check_curves(void)
{
    static const float ts[4] = {0.0f, 0.37f, 0.5f, 1.0f};
    size_t f, k;
    for (f = 0; f < res.n_features; ++f) {
        const bsf_feature_t *ft = &res.features[f];
        const bsf_point_t *c = &res.ctrl[ft->ctrl_first];
        bsf_point_t pt, d1, d2, keep;
        for (k = 0; k < 4u; ++k) {
            float u = -1.0f, basis[3], b1[3], b2[3];
            const size_t span = bsf_bspline_span(ft->n_ctrl, ts[k], &u);
            FUZZ_CHECK(span <= (size_t)ft->n_ctrl - 3u && u >= 0.0f && u <= 1.0f);
            bsf_bspline_basis(ft->n_ctrl, span, u, basis, b1, b2);
            FUZZ_CHECK(fabsf(basis[0] + basis[1] + basis[2] - 1.0f) <= 1e-5f);
            FUZZ_CHECK(bsf_bspline_eval(c, ft->n_ctrl, ts[k], &pt, &d1, &d2) == BSF_OK);
            FUZZ_CHECK(fuzz_finite(pt.x) && fuzz_finite(pt.y));
            FUZZ_CHECK(fuzz_finite(d1.x) && fuzz_finite(d1.y));
            FUZZ_CHECK(fuzz_finite(d2.x) && fuzz_finite(d2.y));
        }
        keep = pt;
        FUZZ_CHECK(bsf_bspline_eval(c, ft->n_ctrl, NAN, &pt, NULL, NULL) == BSF_ERR_ARG);
        FUZZ_CHECK(memcmp(&keep, &pt, sizeof pt) == 0);
    }
}

/* Stats times: all 0 without a clock; with one, the whole time covers every
 * stage (the fake clock cannot wrap: at most 5 calls of < 2^16 ticks). */
static void check_times(const bsf_params_t *p)
{
    size_t k;
    if (p->clock == NULL) {
        FUZZ_CHECK(res.stats.time_ns == 0u && clock_calls == 0u);
        for (k = 0; k < BSF_STAGE_COUNT; ++k) {
            FUZZ_CHECK(res.stats.stage_ns[k] == 0u);
        }
        return;
    }
    FUZZ_CHECK(clock_calls >= 2u);
    for (k = 0; k < BSF_STAGE_COUNT; ++k) {
        FUZZ_CHECK(res.stats.stage_ns[k] <= res.stats.time_ns);
    }
    if (clock_step == 0u) {
        FUZZ_CHECK(res.stats.time_ns == 0u);
    }
}

/* A value near a default: v's low byte scales it by 1/8 .. 32. */
static float near(float def, uint32_t v)
{
    return def * (0.125f + (float)(v & 0xFFu) / 8.0f);
}

/* Edit one parameter of p. field bit 7: v is the raw value (float bits or
 * integer); else a value near the default (floats) or a small integer. */
static void edit_param(bsf_params_t *p, uint32_t field, uint32_t v)
{
    const int raw = (field & 0x80u) != 0u;
    float fv;
    uint32_t iv = raw ? v : (v & 0xFFu);
    memcpy(&fv, &v, sizeof fv);
#define F(dst) (dst) = raw ? fv : near((dst), v)
    switch ((field & 0x7Fu) % 50u) {
    case 0: F(p->sved.a); break;
    case 1: F(p->sved.b); break;
    case 2: p->sved.min_segment_points = (uint16_t)iv; break;
    case 3: F(p->rpos.alpha_max); break;
    case 4: F(p->rpos.eta); break;
    case 5: p->rpos.min_segment_points = (uint16_t)iv; break;
    case 6: p->falko.min_score_th = raw ? (int)v : (int)(iv % 101u); break;
    case 7: F(p->falko.min_range); break;
    case 8: F(p->falko.max_range); break;
    case 9: p->falko.subbeam = (int)(iv & 1u); break;
    case 10: F(p->falko.nms_radius); break;
    case 11: F(p->falko.neigh_a); break;
    case 12: F(p->falko.neigh_b); break;
    case 13: p->falko.neigh_min_points = raw ? (int)v : (int)(iv % 8u); break;
    case 14: F(p->falko.b_ratio); break;
    case 15: p->falko.grid_sectors = raw ? (int)v : (int)(iv % 70u); break;
    case 16: p->falko.circular_sector_distance = (int)(iv & 1u); break;
    case 17: F(p->bid.neigh_a); break;
    case 18: F(p->bid.neigh_b); break;
    case 19: F(p->bid.t_th); break;
    case 20: F(p->bid.nms_radius); break;
    case 21: p->bid.min_side_points = (uint16_t)(raw ? v : iv % 8u); break;
    case 22: p->bid.max_iterations = (uint16_t)(raw ? v : iv % 40u); break;
    case 23: F(p->bid.rel_tol); break;
    case 24: F(p->pdm.precision_spacing); break;
    case 25: F(p->pdm.lambda_per_metre); break;
    case 26: F(p->pdm.rel_tol); break;
    case 27: F(p->pdm.target_rms); break;
    case 28: p->pdm.max_iterations = (uint16_t)(raw ? v : iv % 40u); break;
    case 29: p->pdm.refine_iterations = (uint16_t)(raw ? v : iv % 40u); break;
    case 30: p->pdm.max_ctrl = (uint16_t)(raw ? v : iv % 80u); break;
    case 31: p->pdm.footpoint_steps = (uint8_t)(raw ? v : iv % 10u); break;
    case 32: p->pdm.refine = (uint8_t)(iv & 1u); break;
    case 33: p->method = (bsf_method_t)(v % 5u); break;
    case 34:
        F(p->falko.neigh_b);
        F(p->bid.neigh_b);
        break;
    case 35:
        /* bins of 0 to 1.02 m (above 1 refused), or raw */
        p->fit_bin_length = raw ? fv : 0.004f * (float)(v & 0xFFu);
        break;
    case 36:
        /* a clock hook: v's low 16 bits are the ticks per call; clock_hz is
         * v itself when raw (0 must be refused), else 1 MHz */
        clock_step = v & 0xFFFFu;
        p->clock = fake_clock;
        p->clock_user = &clock_now;
        p->clock_hz = raw ? v : 1000000u;
        break;
    case 37: F(p->lc.jump_a); break;
    case 38: F(p->lc.jump_b); break;
    case 39: F(p->lc.split_min); break;
    case 40: F(p->lc.split_sigmas); break;
    case 41:
        /* in (0, pi/2): near the default, or raw */
        p->lc.min_turn = raw ? fv : 0.01f + 0.006f * (float)(v & 0xFFu);
        break;
    case 42: F(p->lc.curve_ratio); break;
    case 43: F(p->lc.floor); break;
    case 44: F(p->lc.max_side); break;
    case 45: F(p->lc.apex_slack); break;
    case 46: F(p->lc.min_side_len); break;
    case 47:
        /* the default is FLT_MAX (no limit): a limit in metres, or raw */
        p->lc.max_range = raw ? fv : 0.25f * (float)(v & 0xFFu);
        break;
    case 48: p->lc.min_side_points = (uint16_t)(raw ? v : iv % 70u); break;
    case 49: F(p->split_dist); break;
    default:
        F(p->sved.a);
        F(p->sved.b);
        break;
    }
#undef F
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    input_t in;
    bsf_params_t params;
    bsf_scan_t scan;
    bsf_status_t st;
    size_t count = 0u;
    size_t over_cap_count = 0u;
    size_t n_valid = 0u;
    size_t n_top = 0u;
    float top = 0.0f;
    size_t i;
    uint8_t flags;
    int extractor_ok;
    if (size == 0u) {
        return 0;
    }
    in.p = data;
    in.n = size;
    flags = (uint8_t)take_u32(&in, 1u);
    {
        static const bsf_method_t by_flags[4] = {BSF_METHOD_LC_SVED_PDM, BSF_METHOD_RPOS_LSBA,
                                                 BSF_METHOD_BID_SVED_PDM,
                                                 BSF_METHOD_FALKO_SVED_PDM};
        const unsigned pick = ((flags & F_RPOS) ? 1u : 0u) | ((flags & F_BID) ? 2u : 0u);
        params = bsf_params_default(by_flags[pick]);
    }
    clock_now = 0u;
    clock_step = 0u;
    clock_calls = 0u;
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
        size_t n_edits = take_u32(&in, 1u) & 0x1Fu;
        while (n_edits-- > 0u) {
            const uint32_t field = take_u32(&in, 1u);
            const uint32_t v = take_u32(&in, 4u);
            edit_param(&params, field, v);
        }
    }
    if (flags & F_OVER_CAP) {
        over_cap_count = BSF_MAX_POINTS + 1u - (take_u32(&in, 1u) & 3u);
    }
    memset(&ex, 0, sizeof ex);
    st = bsf_extractor_init(&ex, &params);
    FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_PARAM);
    FUZZ_CHECK((st == BSF_OK) == (bsf_params_check(&params) == BSF_OK));
    extractor_ok = st == BSF_OK;
    fuzz_check_status(st);
    {
        /* method names round-trip; unknown methods have none */
        const char *name = bsf_method_name(params.method);
        FUZZ_CHECK((name != NULL) == ((unsigned)params.method < (unsigned)BSF_METHOD_COUNT));
        FUZZ_CHECK(name == NULL || bsf_method_from_name(name) == params.method);
    }

    while (in.n > 0u && count < BSF_MAX_POINTS) {
        if (flags & F_RAW_RANGES) {
            ranges[count++] = take_raw_float(&in);
        } else {
            const uint32_t mm = take_u32(&in, 2u);
            ranges[count++] = (mm == 0xFFFFu) ? NAN : 0.001f * (float)mm;
        }
    }
    if (over_cap_count > 0u) {
        /* near the cap: the given ranges repeated (1 m if none) */
        const size_t given = count;
        for (i = count; i < over_cap_count; ++i) {
            ranges[i] = given > 0u ? ranges[i % given] : 1.0f;
        }
        count = over_cap_count;
    }
    scan.ranges = ranges;
    scan.count = count;
    if ((flags & F_FULL_CIRCLE) && count > 0u) {
        scan.angle_increment = 6.2831853f / (float)count;
    }

    memset(&res, 0x5A, sizeof res);
    st = bsf_extract(&ex, &scan, &res);
    fuzz_check_status(st);
    if (!extractor_ok) {
        FUZZ_CHECK(st == BSF_ERR_ARG || st == BSF_ERR_PARAM); /* never initialised */
        return 0;
    }
    if (st < 0) {
        FUZZ_CHECK(st == BSF_ERR_ARG || st == BSF_ERR_CAPACITY);
        check_error_result();
        return 0;
    }
    /* BSF_OK_CUT: a cap cut the output, and the stats say so (docs/DESIGN.md, Cut policy) */
    FUZZ_CHECK(st == BSF_OK || st == BSF_OK_CUT);
    FUZZ_CHECK((st == BSF_OK_CUT) == (res.stats.cut != 0u));
    check_times(&params);
    FUZZ_CHECK(count <= BSF_MAX_POINTS);
    fuzz_check_result(&res, 1);
    for (i = 0; i < count; ++i) {
        if (bsf_range_is_valid(ranges[i], scan.range_min, scan.range_max)) {
            ++n_valid;
            top = ranges[i] > top ? ranges[i] : top;
        }
    }
    for (i = 0; i < count; ++i) {
        n_top += (size_t)(bsf_range_is_valid(ranges[i], scan.range_min, scan.range_max) &&
                          ranges[i] == top);
    }
    /* No-return detection may invalidate every reading equal to the largest
     * valid one (runs of at least min_run of them), nothing else. */
    FUZZ_CHECK(res.stats.n_valid == n_valid ||
               (res.stats.n_valid == n_valid - n_top && n_top >= ex.params.no_return.min_run &&
                ex.params.no_return.min_run > 0u));
    FUZZ_CHECK(res.stats.n_keypoints <= BSF_MAX_KEYPOINTS);
    for (i = 0; i < res.n_features; ++i) {
        FUZZ_CHECK(res.features[i].last_beam < count);
    }
    check_curves();
    if (flags & F_ENCODE) {
        check_roundtrip();
    }
    return 0;
}
