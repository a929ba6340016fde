/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_extract.h"
#include "bsf_compact.h"
#include "bsf_grazing.h"
#include "bsf_lc_internal.h"
#include "bsf_math.h"
#include "bsf_segment_internal.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#define BSF_EXTRACTOR_READY 0x62736621u /* "bsf!" */
/* The default method's fit_bin_length is 0 (no bins, memset) unless a
 * benchmark build sets BSF_FIT_BIN_LENGTH_DEFAULT (bsf_params_check must
 * accept the defaults it returns). */
#if defined(BSF_FIT_BIN_LENGTH_DEFAULT) && !BSF_CONFIG_FIT_BINS
#error "BSF_FIT_BIN_LENGTH_DEFAULT needs BSF_CONFIG_FIT_BINS 1"
#endif
#ifndef BSF_SPLIT_DIST_DEFAULT
#define BSF_SPLIT_DIST_DEFAULT 0.25f
#endif

static const char *const method_names[BSF_METHOD_COUNT] = {
    "falko-sved-pdm",
    "bid-sved-pdm",
    "rpos-lsba",
    "lc-sved-pdm",
};

const char *bsf_method_name(bsf_method_t method)
{
    if ((unsigned)method >= (unsigned)BSF_METHOD_COUNT) {
        return NULL;
    }
    return method_names[method];
}

bsf_method_t bsf_method_from_name(const char *name)
{
    unsigned m;
    if (name == NULL) {
        return BSF_METHOD_COUNT;
    }
    for (m = 0; m < (unsigned)BSF_METHOD_COUNT; ++m) {
        if (strcmp(name, method_names[m]) == 0) {
            return (bsf_method_t)m;
        }
    }
    return BSF_METHOD_COUNT;
}

bsf_params_t bsf_params_default(bsf_method_t method)
{
    bsf_params_t p;
    memset(&p, 0, sizeof p);
    p.method = method;
    /* A method left out of the build (BSF_CONFIG_METHODS) keeps its
     * parameters zero: nothing reads them, and their defaults stay unlinked. */
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_FALKO
    p.falko = bsf_falko_params_default();
#endif
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_LC
    p.lc = bsf_lc_params_default();
#endif
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_BID
    p.bid = bsf_bid_params_default();
#endif
    p.sved = bsf_sved_params_default();
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_RPOS
    p.rpos = bsf_rpos_params_default();
#endif
    bsf_pdm_params_default(&p.pdm);
    /* (nothing to set when both are left out: bsf_params_check refuses them) */
    if (((BSF_CONFIG_METHODS) & (BSF_CONFIG_METHOD_FALKO | BSF_CONFIG_METHOD_BID)) != 0u &&
        (method == BSF_METHOD_FALKO_SVED_PDM || method == BSF_METHOD_BID_SVED_PDM)) {
        /* Keypoint detectors that miss most corners (docs/GROUND_TRUTH.md):
         * PDM's systematic-deviation test would spend control points rounding
         * the corners they miss, so these methods refine on RMS alone, at the
         * 25 mm that beats the paper's compactness with FALKO (TABLE1.md). */
        p.pdm.target_rms = 0.025f;
        p.pdm.bias_window = 0u;
    }
    if (method == BSF_METHOD_LC_SVED_PDM) {
        /* LC finds the corner where a wall seen nearly edge-on starts, so
         * its segments may take that wall's first returns (bsf_grazing.h);
         * a detector that leaves no vertex there would round it off. */
        p.sved.join_grazing = 2u;
#ifdef BSF_FIT_BIN_LENGTH_DEFAULT
        p.fit_bin_length = BSF_FIT_BIN_LENGTH_DEFAULT;
#endif
    }
    p.no_return = bsf_no_return_params_default();
    p.split_dist = BSF_SPLIT_DIST_DEFAULT;
    p.trim_tails = 1u;
    p.clock = NULL;
    p.clock_user = NULL;
    p.clock_hz = 0u;
    return p;
}

bsf_params_t bsf_params_paper(bsf_method_t method)
{
    bsf_params_t p = bsf_params_default(method);
    p.sved = bsf_sved_params_paper();
    p.no_return.min_run = 0u;
    p.split_dist = 0.0f;
    p.trim_tails = 0u;
#ifdef BSF_FIT_BIN_LENGTH_DEFAULT
    p.fit_bin_length = 0.0f;
#endif
    /* The first release's refinement target, so the paper-faithful rows of
     * bsf table1 are the numbers that release printed. */
    p.pdm.target_rms = 0.015f;
    p.pdm.bias_window = 0u;
    return p;
}

/* The no-return code finite and not negative, split_dist a length
 * (bsf_floats_in_range). */
static const bsf_float_range_t extract_float_ranges[] = {
    {FLT_MAX, (uint16_t)offsetof(bsf_params_t, no_return.code), 0u},
    {BSF_FIT_MAX_COORD, (uint16_t)offsetof(bsf_params_t, split_dist), 0u},
#if BSF_CONFIG_FIT_BINS /* else any value but 0 is BSF_ERR_UNSUPPORTED */
    {1.0f, (uint16_t)offsetof(bsf_params_t, fit_bin_length), 0u},
#endif
};

bsf_status_t bsf_params_check(const bsf_params_t *p)
{
    bsf_status_t st = BSF_OK;
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    if ((p->clock != NULL && p->clock_hz == 0u) ||
        !bsf_floats_in_range(p, extract_float_ranges,
                             sizeof extract_float_ranges / sizeof extract_float_ranges[0]) ||
        p->trim_tails > 1u) {
        return BSF_ERR_PARAM;
    }
    if (((unsigned)p->method < (unsigned)BSF_METHOD_COUNT &&
         ((BSF_CONFIG_METHODS) & (1u << (unsigned)p->method)) == 0u) ||
        (!(BSF_CONFIG_FIT_BINS) && p->fit_bin_length != 0.0f)) {
        return BSF_ERR_UNSUPPORTED; /* left out of this build (bsf_config.h) */
    }
    switch (p->method) {
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_FALKO
    case BSF_METHOD_FALKO_SVED_PDM: st = bsf_falko_params_check(&p->falko); break;
#endif
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_LC
    case BSF_METHOD_LC_SVED_PDM: st = bsf_lc_params_check(&p->lc); break;
#endif
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_BID
    case BSF_METHOD_BID_SVED_PDM: st = bsf_bid_params_check(&p->bid); break;
#endif
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_RPOS
    case BSF_METHOD_RPOS_LSBA: st = bsf_rpos_params_check(&p->rpos); break;
#endif
    default: return BSF_ERR_PARAM;
    }
    /* Every method but RPOS-LSBA segments with SVED and fits with PDM. */
    if (st == BSF_OK && p->method != BSF_METHOD_RPOS_LSBA) {
        st = bsf_sved_params_check(&p->sved);
        if (st == BSF_OK) {
            st = bsf_pdm_params_check(&p->pdm);
        }
    }
    /* A NULL inside a valid struct cannot happen, so any failure is a value. */
    return st == BSF_OK ? BSF_OK : BSF_ERR_PARAM;
}

bsf_status_t bsf_extractor_init(bsf_extractor_t *ex, const bsf_params_t *params)
{
    bsf_status_t st;
    if (ex == NULL || params == NULL) {
        return BSF_ERR_ARG;
    }
    ex->ready = 0u;
    st = bsf_params_check(params);
    if (st != BSF_OK) {
        return st;
    }
    ex->params = *params;
    ex->n_keypoints = 0u;
    ex->n_segments = 0u;
    ex->ready = BSF_EXTRACTOR_READY;
    return BSF_OK;
}

/* Whether the method in use is RPOS-LSBA: constant 0 when RPOS is compiled
 * out, so its segmenter and fitter are not linked. */
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_RPOS
#define USES_RPOS(ex) ((ex)->params.method == BSF_METHOD_RPOS_LSBA)
#else
#define USES_RPOS(ex) 0
#endif
/* Whether the method in use is LC-SVED-PDM: constant 1 when LC is the only
 * method compiled in (bsf_extractor_init refuses any other), so the other
 * methods' branches are not compiled. */
#if (BSF_CONFIG_METHODS) == BSF_CONFIG_METHOD_LC
#define USES_LC(ex) 1
#else
#define USES_LC(ex) ((ex)->params.method == BSF_METHOD_LC_SVED_PDM)
#endif

/* Tick difference to nanoseconds, saturating at 2^32 - 1 ns. */
static BSF_COMPACT_NOINLINE uint32_t ticks_to_ns(uint32_t ticks, uint32_t hz)
{
    const float ns = (float)ticks * (1.0e9f / (float)hz);
    if (!(ns < 4294967040.0f)) {
        return 0xFFFFFFFFu;
    }
    return (uint32_t)ns;
}

typedef struct {
    const bsf_params_t *p;
    uint32_t start;
    uint32_t last;
} stage_clock_t;

static void clock_start(stage_clock_t *c, const bsf_params_t *p)
{
    c->p = p;
    c->start = c->last = (p->clock != NULL) ? p->clock(p->clock_user) : 0u;
}

static void clock_stage(stage_clock_t *c, bsf_stats_t *stats, bsf_stage_t stage)
{
    uint32_t now;
    if (c->p->clock == NULL) {
        return;
    }
    now = c->p->clock(c->p->clock_user);
    stats->stage_ns[stage] = ticks_to_ns(now - c->last, c->p->clock_hz);
    stats->time_ns = ticks_to_ns(now - c->start, c->p->clock_hz);
    c->last = now;
}

/* Over BSF_MAX_KEYPOINTS the detector keeps what fits (bsf_falko_detect and
 * bsf_bid_detect the strongest, bsf_lc_detect the first in beam order) and
 * reports how many it found: keep those and count the rest as cut. Any other
 * error stands. */
static BSF_COMPACT_NOINLINE bsf_status_t keep_keypoints_that_fit(bsf_status_t st,
                                                                 bsf_extractor_t *ex,
                                                                 bsf_stats_t *stats)
{
    if (st == BSF_ERR_CAPACITY && ex->n_keypoints > (size_t)BSF_MAX_KEYPOINTS) {
        stats->cut |= BSF_CUT_KEYPOINTS;
        stats->n_cut_keypoints = (uint32_t)(ex->n_keypoints - (size_t)BSF_MAX_KEYPOINTS);
        ex->n_keypoints = BSF_MAX_KEYPOINTS;
        return BSF_OK;
    }
    return st;
}

/* Bytes of SVED's mixed-pixel marks at the start of ex->segments. */
#define MIXED_MARK_BYTES (((size_t)BSF_MAX_POINTS + 7u) / 8u)

/* SVED's mixed-pixel marks for this scan (bsf_sved_mixed_marks), found
 * once before LC and used by segmentation, or NULL when the method finds
 * none or they do not fit (caps with few segments: SVED then finds them
 * again). They live in ex->segments, unused until segmentation fills it. */
static uint8_t *mixed_marks(bsf_extractor_t *ex)
{
    if (!USES_LC(ex) || !ex->params.sved.reject_mixed ||
        sizeof ex->segments * 8u < (size_t)BSF_MAX_POINTS) {
        return NULL;
    }
    return (uint8_t *)(void *)ex->segments;
}

/* The grazing joins' verdicts for this scan (bsf_grazing_join's memo),
 * zeroed before LC and kept for segmentation: LC and SVED ask about many of
 * the same wide steps. After the mixed-pixel marks in ex->segments; NULL
 * with no marks, when they do not fit beside them (many beams, few
 * segments: each stage then asks alone), and in the compact build (over
 * 100 bytes of code). */
static uint8_t *grazing_memo(bsf_extractor_t *ex)
{
    if (BSF_CONFIG_COMPACT || mixed_marks(ex) == NULL ||
        sizeof ex->segments < MIXED_MARK_BYTES + BSF_GRAZING_MEMO_BYTES((size_t)BSF_MAX_POINTS)) {
        return NULL;
    }
    return (uint8_t *)(void *)ex->segments + MIXED_MARK_BYTES;
}

#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_LC
/* Beams ex->interest[0..n) valid (1) or not (0). */
static BSF_COMPACT_NOINLINE void set_valid(bsf_extractor_t *ex, size_t n, uint8_t valid)
{
    size_t k;
    for (k = 0; k < n; ++k) {
        ex->points.valid[ex->interest[k]] = valid;
    }
}

/* LC without the returns SVED's mixed-pixel rule will reject off the line
 * of a long run: such a return, taken into a corner's side, bends its line
 * off the wall and costs the corner. Those beams are invalid for the
 * detection only; ex->interest, filled after it, lists them meanwhile (the
 * first BSF_MAX_KEYPOINTS in beam order; LC sees any beyond). */
static bsf_status_t detect_lc(bsf_extractor_t *ex)
{
    size_t n = 0u;
    bsf_status_t st;
    uint8_t *memo = grazing_memo(ex);
    if (ex->params.sved.reject_mixed) {
        n = bsf_sved_mixed_marks(&ex->points, &ex->params.sved, mixed_marks(ex), ex->interest,
                                 BSF_MAX_KEYPOINTS);
    }
    if (memo != NULL) {
        memset(memo, 0, BSF_GRAZING_MEMO_BYTES(ex->points.count));
        /* LC's verdicts hold for SVED only for the same question (SVED's
         * cap and corner rule LC's; either asks none with join_grazing 0):
         * else LC keeps none and SVED asks alone. */
        if (ex->params.sved.join_grazing != ex->params.lc.join_grazing ||
            !(ex->params.sved.radius_max == BSF_GRAZING_LC_CAP)) {
            memo = NULL;
        }
    }
    set_valid(ex, n, 0u);
    st = bsf_lc_detect_memo(&ex->points, &ex->params.lc, &ex->scratch.lc, ex->keypoints,
                            BSF_MAX_KEYPOINTS, &ex->n_keypoints, memo);
    ex->noise2 = ex->scratch.lc.noise2; /* segmentation reuses the scratch */
    set_valid(ex, n, 1u);
    /* and only on the same valid beams: not those LC saw invalid */
    if (memo != NULL) {
        size_t k;
        for (k = 0; k < n; ++k) {
            bsf_grazing_memo_forget(memo, ex->interest[k], ex->points.count);
        }
    }
    return st;
}
#endif

static bsf_status_t detect_corners(bsf_extractor_t *ex, bsf_stats_t *stats)
{
    bsf_status_t st = BSF_OK;
    size_t i;
    ex->n_keypoints = 0u;
    switch (ex->params.method) {
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_FALKO
    case BSF_METHOD_FALKO_SVED_PDM:
        st = bsf_falko_detect(&ex->points, &ex->params.falko, &ex->scratch.falko, ex->keypoints,
                              BSF_MAX_KEYPOINTS, &ex->n_keypoints);
        break;
#endif
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_LC
    case BSF_METHOD_LC_SVED_PDM: st = detect_lc(ex); break;
#endif
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_BID
    case BSF_METHOD_BID_SVED_PDM:
        st = bsf_bid_detect(&ex->points, &ex->params.bid, &ex->scratch.bid, ex->keypoints,
                            BSF_MAX_KEYPOINTS, &ex->n_keypoints);
        break;
#endif
    default: break; /* RPOS-LSBA finds no corners */
    }
    st = keep_keypoints_that_fit(st, ex, stats);
    if (st != BSF_OK) {
        ex->n_keypoints = 0u;
        return st;
    }
    /* Detectors return keypoints ascending by beam; keep that as a checked
     * invariant, since classification relies on it. */
    for (i = 0; i < ex->n_keypoints; ++i) {
        ex->interest[i] = ex->keypoints[i].index;
        if (i > 0u && ex->interest[i] <= ex->interest[i - 1u]) {
            return BSF_ERR_ARG;
        }
    }
    return BSF_OK;
}

/* Segments of at least min_points points among all[0..n). */
static BSF_COMPACT_NOINLINE size_t count_segments_from(const bsf_segment_t *all, size_t n,
                                                       uint32_t min_points)
{
    size_t c = 0u;
    size_t i;
    for (i = 0; i < n; ++i) {
        c += ((uint32_t)all[i].n_points >= min_points) ? 1u : 0u;
    }
    return c;
}

/* Copy the kept segments all[0..n) into ex->segments. Over BSF_MAX_SEGMENTS,
 * the segments covering the most points win (ties: earlier in segmentation
 * order), they stay in segmentation order, and the rest are counted as cut. */
static BSF_COMPACT_NOINLINE void
keep_segments_that_fit(bsf_extractor_t *ex, const bsf_segment_t *all, size_t n, bsf_stats_t *stats)
{
    const size_t cap = BSF_MAX_SEGMENTS;
    uint32_t lo = 0u; /* at least cap segments have lo points or more */
    uint32_t hi = 0xFFFFu;
    size_t n_above;
    size_t i;
    ex->n_segments = 0u;
    if (n <= cap) {
        memcpy(ex->segments, all, n * sizeof *all);
        ex->n_segments = n;
        return;
    }
    while (lo < hi) {
        const uint32_t mid = (lo + hi + 1u) / 2u;
        if (count_segments_from(all, n, mid) >= cap) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    n_above = count_segments_from(all, n, lo + 1u);
    for (i = 0; i < n; ++i) {
        const uint32_t np = all[i].n_points;
        if (np > lo || (np == lo && n_above < cap)) {
            n_above += (np == lo) ? 1u : 0u;
            ex->segments[ex->n_segments++] = all[i];
        } else {
            stats->n_cut_segments++;
            stats->n_cut_points += np;
        }
    }
    stats->cut |= BSF_CUT_SEGMENTS;
}

#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_LC
/* Returns of a segment's end that judge a short run past it
 * (join_occluded_run): a line with a noise estimate of its own. */
#define JOIN_END_RUN 8u
/* Fewest of them: a noise estimate with two degrees of freedom at least. */
#define JOIN_MIN_END_RUN 5u

static float sq_dist(const bsf_point_t *a, const bsf_point_t *b);

#if !BSF_CONFIG_COMPACT
/* Of the `block` returns in no segment just before position k past beam
 * end (direction dir), valid, a run of 2 to min_segment_points - 1 not
 * marked mixed (marks) ends there, at position 2 or later, and starts
 * within radius_max of beam end (join_occluded_run's first test). */
static int run_within_radius(const bsf_extractor_t *ex, const uint8_t *marks, size_t end,
                             ptrdiff_t dir, size_t k, size_t block)
{
    size_t q;
    for (q = k - 1u; q + block >= k && q > 1u && q + ex->params.sved.min_segment_points > k; --q) {
        const size_t b = (size_t)((ptrdiff_t)end + dir * (ptrdiff_t)q);
        if ((marks[b / 8u] >> (b % 8u)) & 1u) {
            return 0;
        }
        if (q + 2u <= k && sq_dist(&ex->points.pt[b], &ex->points.pt[end]) <=
                               ex->params.sved.radius_max * ex->params.sved.radius_max) {
            return 1;
        }
    }
    return 0;
}
#endif

/* A wall seen past an occluder: segment s goes on along the line of its
 * last 5 to JOIN_END_RUN returns at end `end` (dir -1: its first beam, +1:
 * its last), that run straight within the scan's noise (noise2 from LC; a
 * corner or a curve is not); past that end lie one or more returns in
 * front of that line (a chair leg, a post, a person), then 2 to
 * min_segment_points - 1 returns SVED wasted (no segment, no mixed-pixel
 * mark) that all lie on the line, within split_sigmas standard errors of a
 * return one step past the run, the first within radius_max of s's end,
 * and nothing else on the line after them. SVED's radius, which bounds a
 * step from the last return only, cannot join them across the occluder's
 * width; their line can. A gap with no return in front (a doorway, an
 * opening, a wall seen nearly edge-on) is left as it is. They join s:
 * labels, first or last, count. */
static BSF_COMPACT_NOINLINE void join_occluded_run(bsf_extractor_t *ex, bsf_segment_t *s,
                                                   ptrdiff_t dir, const uint8_t *marks)
{
    const bsf_points_t *pts = &ex->points;
    uint16_t *label = ex->scratch.seg.label;
    const size_t first = s->first;
    const size_t end = dir > 0 ? s->last : first;
    bsf_point_t w[JOIN_END_RUN + 1u];
    bsf_side_line_t l;
    float bound2;
    size_t b = end;
    size_t j;
    size_t k;
    size_t at = 0u; /* the run's first position past the end, 0: none yet */
#if !BSF_CONFIG_COMPACT
    /* Speed only, first, cheaply (most ends have none; the compact build
     * goes on to the line at every end): a candidate run past the end,
     * 2 to min_segment_points - 1 wasted, unmarked returns (positions q ..
     * k - 1, q > 1: one other return at least before them) before a
     * return of a segment, an invalid one or max_gap_beams, all valid (an
     * invalid beam has no segment), the first within radius_max of the end.
     * at counts the valid returns in no segment before position k. */
    j = dir > 0 ? pts->count - 1u - end : end;
    j = j < (size_t)ex->params.sved.max_gap_beams ? j : (size_t)ex->params.sved.max_gap_beams;
    b = end;
    for (k = 1u;; ++k) {
        /* the next four beams all in segments (no label BSF_SEG_NONE among
         * them) reset the count, as one by one below; most ends have a
         * long segment beside them */
        while (at < 2u && k + 3u <= j) {
            uint64_t v;
            memcpy(&v, &label[dir > 0 ? b + 1u : b - 4u], sizeof v);
            v = ~v; /* a zero lane: a beam in no segment */
            if (((v - 0x0001000100010001u) & ~v & 0x8000800080008000u) != 0u) {
                break;
            }
            k += 4u;
            b = (size_t)((ptrdiff_t)b + 4 * dir);
            at = 0u;
        }
        if (k <= j) {
            b = (size_t)((ptrdiff_t)b + dir);
            if (label[b] == (uint16_t)BSF_SEG_NONE && pts->valid[b]) {
                ++at;
                continue;
            }
        }
        if (at >= 2u && run_within_radius(ex, marks, end, dir, k, at)) {
            break;
        }
        if (k > j || label[b] == (uint16_t)BSF_SEG_NONE) {
            return; /* the window's end, or an invalid beam */
        }
        at = 0u;
    }
    at = 0u;
    b = end;
#endif
    /* s's returns from that end inwards (beams first .. last) */
    for (l.n = 1; l.n <= (int)JOIN_END_RUN && b - first <= (size_t)s->last - first;
         b = (size_t)((ptrdiff_t)b - dir)) {
        if (label[b] == first) {
            w[l.n++] = pts->pt[b];
        }
    }
    w[0] = pts->pt[end];
    bsf_side_fit(w, &l);
    if (l.n <= (int)JOIN_MIN_END_RUN || !(l.var <= 4.0f * ex->noise2)) {
        return; /* too short to judge, or not straight within the noise */
    }
    if (l.var < ex->noise2) {
        l.var = ex->noise2;
    }
    bound2 = ex->params.lc.split_sigmas * ex->params.lc.split_sigmas * l.var * l.reach_i;
    /* Returns in front of the line (positions 1 .. at - 1 past the end),
     * then the run (at .. k - 1) up to a return of a segment, an invalid
     * one or max_gap_beams (wasted returns off the line after it spoil
     * it). */
    for (k = 1u; k <= (size_t)ex->params.sved.max_gap_beams; ++k) {
        float d;
        int none;
        j = (size_t)((ptrdiff_t)end + dir * (ptrdiff_t)k);
        if (j >= pts->count || !pts->valid[j]) {
            break;
        }
        d = bsf_side_distance(&l, &pts->pt[j]);
        none = label[j] == (uint16_t)BSF_SEG_NONE;
        if (none && !((marks[j / 8u] >> (j % 8u)) & 1u) && d * d <= bound2) {
            at = at > 0u ? at : k;
            continue;
        }
        /* the sensor's side of the line: -(nx cx + ny cy) > 0 */
        if (at > 0u || !(d * -(l.nx * l.cx + l.ny * l.cy) > 0.0f && d * d > bound2)) {
            at = none ? 0u : at; /* or behind the line, or on another surface */
            break;
        }
    }
    /* k - at returns in the run */
    if (at < 2u || k < at + 2u || k - at >= (size_t)ex->params.sved.min_segment_points ||
        !(sq_dist(&pts->pt[(size_t)((ptrdiff_t)end + dir * (ptrdiff_t)at)], &pts->pt[end]) <=
          ex->params.sved.radius_max * ex->params.sved.radius_max)) {
        return;
    }
    /* The run's beams j .. j + k - at - 1 join s, whose label is its
     * first beam (the run's lowest, when it joins before s). */
    j = dir > 0 ? end + at : end + 1u - k;
    if (j < first) {
        s->first = (uint16_t)j;
    } else {
        s->last = (uint16_t)(j + (k - at) - 1u);
    }
    s->n_points = (uint16_t)(s->n_points + (k - at));
    for (b = s->first; b <= s->last; ++b) {
        if (b - j < k - at || label[b] == first) {
            label[b] = s->first;
        }
    }
}

/* join_occluded_run at each segment's first end, then its last, in the
 * order of all[0..n); not through the seam of a full-circle scan. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline)) /* its frame (a line's points) stays off the fit's deepest call chain */
#endif
static void
join_occluded_runs(bsf_extractor_t *ex, bsf_segment_t *all, size_t n)
{
    const uint8_t *marks = mixed_marks(ex);
    size_t i;
    for (i = 0u; marks != NULL && i < 2u * n; ++i) {
        if (all[i / 2u].first <= all[i / 2u].last) {
            join_occluded_run(ex, &all[i / 2u], (ptrdiff_t)(i % 2u) * 2 - 1, marks);
        }
    }
}
#endif

static bsf_status_t segment(bsf_extractor_t *ex, bsf_stats_t *stats)
{
    /* Every kept segment fits the scratch (one per valid point at most), so
     * the cap can choose among all of them. */
    bsf_segment_t *all = ex->scratch.seg.use.all;
    size_t n_all = 0u;
    bsf_status_t st;
    ex->n_segments = 0u;
    if (USES_RPOS(ex)) {
        size_t k;
        size_t b;
        st = bsf_segment_rpos(&ex->points, &ex->params.rpos, all, BSF_MAX_POINTS, &n_all, NULL);
        /* RPOS segments are runs of valid beams: label them so that fitting
         * gathers every method's segments alike. */
        for (b = 0; b < ex->points.count; ++b) {
            ex->scratch.seg.label[b] = (uint16_t)BSF_SEG_NONE;
        }
        for (k = 0; st == BSF_OK && k < n_all; ++k) {
            for (b = all[k].first; b <= all[k].last; ++b) {
                if (ex->points.valid[b]) {
                    ex->scratch.seg.label[b] = all[k].first;
                }
            }
        }
    } else {
        st = bsf_segment_sved_marked(&ex->points, &ex->params.sved, all, BSF_MAX_POINTS,
                                     ex->scratch.seg.label, mixed_marks(ex), grazing_memo(ex),
                                     &n_all);
    }
    if (st != BSF_OK) {
        return st;
    }
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_LC
    join_occluded_runs(ex, all, n_all);
#endif
    keep_segments_that_fit(ex, all, n_all, stats);
    if (USES_RPOS(ex)) {
        return BSF_OK;
    }
    return bsf_segment_classify_labelled(ex->segments, ex->n_segments, &ex->points,
                                         ex->scratch.seg.label, ex->interest, ex->n_keypoints);
}

#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_LC
/* Points of the straight run beside a segment end that judge it (tail_end),
 * at most: enough for a noise estimate of its own with six degrees of
 * freedom. */
#define TAIL_RUN 8u
/* The shortest run: a segment of fewer than TAIL_MIN_RUN + 2 returns
 * (the run, the end judged, the other end left out of the run) is judged
 * only at a floating end (floating_end) or for a two-return corner (the
 * apex mode of tail_end). */
#define TAIL_MIN_RUN 5u
/* The shortest run beside a floating return (floating_end), and beside a
 * two-return end of a segment too short for TAIL_MIN_RUN (a segment of 5
 * returns). */
#define TAIL_FLOAT_RUN 3u

static float sq_dist(const bsf_point_t *a, const bsf_point_t *b)
{
    return (a->x - b->x) * (a->x - b->x) + (a->y - b->y) * (a->y - b->y);
}

/* Is the end return p[0] of a segment a tail: a return on another surface,
 * nearer the sensor, that the straight run p[(gap + 1) step], ...
 * p[(gap + run) step] (step +1 or -1) does not explain? At a concave corner
 * seen at grazing incidence the next wall often gives a single return
 * before the corner, which no corner test can confirm, and a curve bent to
 * reach it swings through free space (half a metre past a corridor's end
 * wall on the ground-truth scenes). It is one when the run's line (total
 * least squares, SVED's side line) misses p[0] by more than split_sigmas
 * standard errors of a new return gap + 1 steps past the run (the noise
 * variance: the run's scatter per degree of freedom, at least the scan's
 * noise2 from LC, and the line's own error there) and at least split_min,
 * on the sensor's side, with a turn of at least min_turn. Only the sensor's
 * side: a convex surface's last returns (a pillar's silhouette) bend away
 * from the sensor and still lie on it. The scan's noise keeps a short run,
 * whose own scatter over a few degrees of freedom is often far below the
 * noise by chance, from taking real returns for tails. With gap 1 the run
 * is a vertex's side (the vertex two returns from the end) and the return
 * p[step] between must lie on its line (within the same bound one step past
 * it, or split_min): LC's vertex then sits one return before the corner and
 * only p[0] is on the next surface. With apex (gap 1) it asks instead
 * whether p[step] and p[0] are a second surface: both off the run's line
 * (p[step] by the bound above), on either side, their line turning away
 * from it by min_turn or more and crossing it (the corner, written to apex)
 * between the beams of p[2 step] and p[step], and the step from p[2 step]
 * to p[step] at least twice the run's spacing, or the step from p[step] to
 * p[0] at most half of it (a run at grazing incidence, the second surface
 * seen square-on). A smooth surface (a pillar's silhouette) bends by
 * degrees and keeps its spacing; a second surface starts where the returns
 * jump or their spacing changes at once. With apex and a run longer than
 * TAIL_MIN_RUN (blend mode) it asks whether p[step] is a blend of two
 * ranges and p[0] a return of a nearer surface: p[step] off the run's line
 * by the bound above, p[0] turning from it by min_turn, nearer the sensor
 * than p[step] along p[step]'s beam and off the line further on the same
 * side, the sensor's, by split_sigmas noise deviations (no line error:
 * both share it) and split_min, and their line crossing the run's line
 * anywhere but near and between the beams of p[2 step] and p[step], where
 * two returns of a second wall at a concave corner meet it (no spacing
 * test; apex is scratch). */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline)) /* its frame stays off the fit's deepest call chain */
#endif
static int
tail_end(const bsf_point_t *p, ptrdiff_t step, size_t gap, size_t run, float noise2,
         const bsf_lc_params_t *lc, bsf_point_t *apex)
{
    bsf_point_t w[TAIL_RUN + 1u];
    bsf_side_line_t l;
    float bound2;
    float d;
    float d1;
    float sx;
    float sy;
    float s;
    size_t k;
    sx = p[0].x - p[step].x;
    sy = p[0].y - p[step].y;
    /* blend mode, first (cheap, most ends fail it): p[0] nearer the sensor
     * than p[step] along p[step]'s beam */
    if (apex != NULL && run > TAIL_MIN_RUN && !(sx * p[step].x + sy * p[step].y < 0.0f)) {
        return 0;
    }
    for (k = 0; k <= run; ++k) {
        w[k] = p[(ptrdiff_t)(k + gap) * step];
    }
    l.n = (int)run + 1;
    bsf_side_fit(w, &l);
    if (l.var < noise2) {
        l.var = noise2;
    }
    bound2 = lc->split_sigmas * lc->split_sigmas * l.var;
    d = l.d_near;
    d1 = d;
    if (gap > 0u) {
        if ((d * d > bound2 * l.reach_nr && d * d > lc->split_min * lc->split_min) ==
            (apex == NULL)) {
            return 0; /* p[step] off the side too (a second side of two returns), or on it */
        }
        d = bsf_side_distance(&l, &p[0]);
        l.reach_nr = l.reach_i;
    }
    s = bsf_sinf(lc->min_turn);
    /* The turn: p[0] off the line by its own return, or off p[step]'s
     * offset (two returns) by min_turn or more. */
    d1 = apex != NULL ? d - d1 : d;
    if (!(d1 * d1 > s * s * (sx * sx + sy * sy))) {
        return 0;
    }
    if (apex != NULL) {
        int between;
        d = d - d1; /* p[step]'s offset */
        if (!(d * d1 > 0.0f &&
              (run > TAIL_MIN_RUN ||
               sq_dist(&p[2 * step], &p[step]) > 4.0f * sq_dist(&p[2 * step], &p[3 * step]) ||
               4.0f * sq_dist(&p[step], &p[0]) < sq_dist(&p[2 * step], &p[3 * step])))) {
            return 0;
        }
        d /= d1;
        apex->x = p[step].x - d * sx;
        apex->y = p[step].y - d * sy;
        /* Between the two beams, on the sensor's side (not in the
         * opposite wedge behind it), and near: lines that barely turn
         * (a small min_turn) cross far away, or not at all (NaN). */
        between = (p[2 * step].x * apex->y - p[2 * step].y * apex->x) *
                          (apex->x * p[step].y - apex->y * p[step].x) >
                      0.0f &&
                  apex->x * p[step].x + apex->y * p[step].y > 0.0f &&
                  sq_dist(apex, &p[step]) <= 4.0f * sq_dist(&p[2 * step], &p[step]);
        if (between || run <= TAIL_MIN_RUN) {
            return between && run <= TAIL_MIN_RUN;
        }
        d = d1; /* blend mode: p[0] judged by its offset from p[step]'s */
        l.reach_nr = 1.0f;
    }
    /* The sensor (the origin) lies on the side of the line where
     * -(nx cx + ny cy) is positive. */
    return d * (l.nx * l.cx + l.ny * l.cy) < 0.0f && d * d > bound2 * l.reach_nr &&
           d * d > lc->split_min * lc->split_min;
}

/* Does the beam past segment end b (dir -1 before it, +1 after it) read a
 * valid range nearer the sensor than b? Then b lies in range between the
 * surface its segment follows and the nearer surface seen past it: at a
 * depth jump, where a mixed pixel (a beam that reads a blend of the two
 * ranges and floats in free space) lies. A real end return of a far
 * surface, beside the surface that hides the rest, lies on its line, which
 * tail_end checks. It does not look across the seam of a full-circle scan
 * (measured: no segment ends there at a depth jump). */
static int floating_end(const bsf_points_t *pts, size_t b, int dir)
{
    const size_t o = b + (size_t)(ptrdiff_t)dir;
    return o < pts->count && pts->valid[o] && pts->range[o] < pts->range[b];
}

/* The first and last of the n gathered points to fit (LC with trim_tails): a
 * tail (tail_end, judged by the run of up to TAIL_RUN returns beside it that
 * leaves the other end out; the blend mode's run, one return further in,
 * reaches the other end on a segment of 9 or 10 returns) is left off. With
 * an LC corner within that run the run is the corner's side: the returns
 * between the end and the corner, its apex left out; with the corner two
 * returns from the end, up to TAIL_RUN returns from the vertex, not past the
 * next one nor to the other end. A run of TAIL_FLOAT_RUN to TAIL_MIN_RUN - 1
 * returns judges only a floating end (floating_end): a far surface seen over
 * a few returns through a gap, whose end beam blends with the surface in
 * front. A segment too short for TAIL_MIN_RUN and without a corner gets one,
 * a vertex at its third return from that end anchored at the crossing, when
 * its last two returns at one end are a second surface (tail_end with an
 * apex, judged by the other returns): its one quadratic span cannot turn
 * there and would swing off both surfaces, and leaving the two returns out
 * would waste a third of the segment. A segment of 6 to 8 returns without a
 * corner is judged the same way through views of 5 or 6 returns that leave 1
 * to 3 returns out at one end (shortest view first): a corner between a wall
 * seen at grazing incidence (3-4 returns half a metre apart) and the next
 * wall (3-4 returns a tenth of that apart), the two returns of one wall
 * nearest the corner judged against the other wall's line; the shortest run
 * that passes puts the vertex between the last sparse and the first dense
 * return. Before the tail test, an end with no corner within 6 returns asks
 * whether its second return is a blend (a mixed pixel) and the end a return
 * of a nearer surface (tail_end's blend mode, judged by the tail rule's run
 * one return further in, at least 6 returns): a side wall at grazing
 * incidence or an occluder whose last return SVED joined through the blend.
 * Both leave: a curve bent to reach them swings through free space. Returns
 * the segment's vertex count (vertex_pos and vertex_anchor, as
 * gather_segment wrote them, or that one vertex). */
static BSF_COMPACT_NOINLINE size_t trim_tails(bsf_extractor_t *ex, const bsf_segment_t *s, size_t n,
                                              size_t n_vertex, size_t *lo, size_t *hi)
{
    uint16_t *pos = ex->scratch.seg.use.fit.vertex_pos;
    const bsf_point_t *pts = ex->scratch.seg.use.fit.seg_points;
    const size_t run = n - 2u < TAIL_RUN ? n - 2u : TAIL_RUN;
    /* Too short for the tail rule's run (in a view of 5 or 6 returns, leaving
     * t returns out): a two-return end is a corner. */
    bsf_point_t *apex =
        n < TAIL_MIN_RUN + 4u && n_vertex == 0u ? ex->scratch.seg.use.fit.vertex_anchor : NULL;
    size_t t = n - TAIL_MIN_RUN;
    int e;
    if (!USES_LC(ex) || !ex->params.trim_tails || n < TAIL_FLOAT_RUN + 2u) {
        return n_vertex;
    }
    for (; apex != NULL && t + TAIL_MIN_RUN + 1u >= n && t < n; --t) {
        for (e = 0; e < 2; ++e) {
            if (tail_end(e ? &pts[n - 1u - t] : &pts[t], e ? -1 : 1, 1u, n - t - 2u, ex->noise2,
                         &ex->params.lc, apex)) {
                pos[0] = (uint16_t)(e ? n - 3u - t : t + 2u);
                return 1u;
            }
        }
    }
    for (e = 0; e < 2; ++e) {
        /* Distances from this end to its nearest vertex (n: none) and to
         * the next one (n - 2 when there is no second vertex). */
        size_t d1 = n;
        size_t d2 = n - 2u;
        size_t side;
        size_t k;
        const bsf_point_t *q = e ? &pts[n - 1u] : pts;
        bsf_point_t a;
        if (n_vertex > 0u) {
            d1 = e ? n - 1u - pos[n_vertex - 1u] : pos[0];
        }
        if (n_vertex > 1u) {
            d2 = e ? n - 1u - pos[n_vertex - 2u] : pos[1];
        }
        side = d1 == 2u ? d2 - 1u : (d1 <= run + 1u ? d1 - 1u : run);
        /* k 2: the blend and the end leave; k 1: the end (a tail) */
        for (k = 2u; k > 0u; --k) {
            if ((k == 2u ? d1 != 2u && side > TAIL_MIN_RUN
                         : side >= TAIL_MIN_RUN ||
                               (side >= TAIL_FLOAT_RUN &&
                                floating_end(&ex->points, e ? s->last : s->first, e ? 1 : -1))) &&
                tail_end(q, e ? -1 : 1, d1 == 2u || k == 2u, side < run ? side : run, ex->noise2,
                         &ex->params.lc, k == 2u ? &a : NULL)) {
                break;
            }
        }
        if (e) {
            *hi = n - 1u - k;
        } else {
            *lo = k;
        }
    }
    return n_vertex;
}
#endif

/* Gather a segment's valid points into ex->scratch.seg.use.fit.seg_points and the positions of
 * its vertices into ex->scratch.seg.use.fit.vertex_pos: interest beams inside the segment that
 * are not among its first two or last two points (the rule of
 * bsf_segment_classify). Returns the number of points. */

static BSF_COMPACT_INLINE size_t gather_segment(bsf_extractor_t *ex, const bsf_segment_t *s,
                                                size_t *n_vertex)
{
    /* Locals: the point stores below could change *s and ex's counts as
     * far as the compiler knows, which then reloads them at every beam
     * (the arrays' addresses too, but as locals they cost x86 registers). */
    const size_t first = s->first;
    const size_t last = s->last;
    const size_t count = ex->points.count;
    const size_t n_keypoints = ex->n_keypoints;
    size_t n = 0u;
    size_t nv = 0u;
    size_t k = 0u;
    size_t b;
    size_t i;

    while (k < n_keypoints && ex->interest[k] < first) {
        ++k;
    }
    /* The segment's beams are those labelled with its first beam; a
     * wrapping segment (first > last) runs on through beam 0. */
    for (b = first;; b = (b + 1u < count) ? b + 1u : 0u) {
        if (b == 0u && first > 0u) {
            k = 0u; /* wrapped through the seam */
        }
#if !BSF_CONFIG_COMPACT
        {
            /* Speed only, the same points: the beams before the next
             * interest beam, the last beam and the seam need no keypoint
             * or end test (k skips the interest beams before b early, as
             * the test below would on the next beam of the segment). */
            const uint16_t *label = ex->scratch.seg.label;
            const bsf_point_t *pt = ex->points.pt;
            bsf_point_t *out = ex->scratch.seg.use.fit.seg_points;
            const uint16_t want = (uint16_t)first;
            size_t end = b <= last ? last : count - 1u;
            while (k < n_keypoints && ex->interest[k] < b) {
                ++k;
            }
            if (k < n_keypoints && ex->interest[k] < end) {
                end = ex->interest[k];
            }
            for (; b < end; ++b) {
                if (label[b] == want) {
                    out[n++] = pt[b];
                }
            }
        }
#endif
        if (ex->scratch.seg.label[b] != first) {
            if (b == last) {
                break;
            }
            continue;
        }
        while (k < n_keypoints && ex->interest[k] < b) {
            ++k; /* an interest beam on an invalid reading is no vertex */
        }
        if (k < n_keypoints && ex->interest[k] == b) {
            ex->scratch.seg.use.fit.vertex_anchor[nv] = ex->keypoints[k].point;
            ex->scratch.seg.use.fit.vertex_pos[nv++] = (uint16_t)n;
            ++k;
        }
        ex->scratch.seg.use.fit.seg_points[n++] = ex->points.pt[b];
        if (b == last) {
            break;
        }
    }
    *n_vertex = 0u;
    for (i = 0; i < nv; ++i) {
        if (ex->scratch.seg.use.fit.vertex_pos[i] >= 2u &&
            (size_t)ex->scratch.seg.use.fit.vertex_pos[i] + 3u <= n) {
            ex->scratch.seg.use.fit.vertex_anchor[*n_vertex] =
                ex->scratch.seg.use.fit.vertex_anchor[i];
            ex->scratch.seg.use.fit.vertex_pos[(*n_vertex)++] =
                ex->scratch.seg.use.fit.vertex_pos[i];
        }
    }
    return n;
}

/* Pieces of one segment waiting to be fitted by the cut policy: each split
 * pushes two, the left one fitted first, so the stack holds at most one
 * piece per level of splitting and this bounds the depth. */
#define SPLIT_STACK 8u
/* Fewest points of a piece: a quadratic's three control points, so a piece
 * always fits and no point leaves the features. */
#define SPLIT_MIN_POINTS 3u

/* Beam of the k-th valid point of segment s (as gather_segment visits them). */
static uint16_t beam_of_point(const bsf_extractor_t *ex, const bsf_segment_t *s, size_t k)
{
    size_t b;
    for (b = s->first;; b = (b + 1u < ex->points.count) ? b + 1u : 0u) {
        if (ex->scratch.seg.label[b] == s->first) {
            if (k == 0u) {
                return (uint16_t)b;
            }
            --k;
        }
        if (b == s->last) {
            return (uint16_t)b;
        }
    }
}

/* The point at parameter t (PDM's, 0..1) of the quadratic B-spline with
 * control points ctrl[0..m), with what its derivative needs: the span's
 * local u, its end factors k0 (1 on the first span, else 1/2) and k2 (1 on
 * the last), and the differences a = ctrl[s] - ctrl[s+1], b = ctrl[s+2] -
 * ctrl[s+1] (the span's basis in closed form, docs/DESIGN.md, appendix). */
typedef struct {
    float x, y, u, k0, k2, ax, ay, bx, by;
} span_point_t;

/* Inlined in the speed builds too: out of line, its result went through the
 * stack at every bin of bin_walk and every point of farthest_point. */
#if !BSF_CONFIG_COMPACT && (defined(__GNUC__) || defined(__clang__))
#define SPAN_POINT_INLINE inline __attribute__((always_inline))
#else
#define SPAN_POINT_INLINE BSF_COMPACT_INLINE
#endif
static SPAN_POINT_INLINE void span_point(const bsf_point_t *ctrl, size_t m, float t,
                                         span_point_t *c)
{
    const size_t last = m - 3u;
    const float x = t * (float)(m - 2u);
    size_t s = x > 0.0f ? (size_t)x : 0u;
    float b0, b2;
    s = s > last ? last : s;
    c->u = x - (float)s;
    c->k0 = s == 0u ? 1.0f : 0.5f;
    c->k2 = s == last ? 1.0f : 0.5f;
    b0 = c->k0 * (1.0f - c->u) * (1.0f - c->u);
    b2 = c->k2 * c->u * c->u;
    c->ax = ctrl[s].x - ctrl[s + 1u].x;
    c->ay = ctrl[s].y - ctrl[s + 1u].y;
    c->bx = ctrl[s + 2u].x - ctrl[s + 1u].x;
    c->by = ctrl[s + 2u].y - ctrl[s + 1u].y;
    c->x = ctrl[s + 1u].x + b0 * c->ax + b2 * c->bx;
    c->y = ctrl[s + 1u].y + b0 * c->ay + b2 * c->by;
}

/* The point of pts[0..n) farthest from its footpoint on the curve ctrl[0..m)
 * (PDM's parameters t), as its squared distance; *at receives its index. */
static float farthest_point(const bsf_point_t *pts, size_t n, const float *t,
                            const bsf_point_t *ctrl, size_t m, size_t *at)
{
    float worst = 0.0f;
    size_t i;
    *at = 0u;
    for (i = 0; i < n; ++i) {
        span_point_t c;
        float dx, dy, d2;
        span_point(ctrl, m, t[i], &c);
        dx = c.x - pts[i].x;
        dy = c.y - pts[i].y;
        d2 = dx * dx + dy * dy;
        if (d2 > worst) {
            worst = d2;
            *at = i;
        }
    }
    return worst;
}

#if BSF_CONFIG_FIT_BINS
/* Fewest bins of a run between two pinned points: refinement may add one
 * precision point per 4 points, so bins of a short run (or of one seen from
 * close by) must not take the curve's room to bend (measured: with a floor of
 * 64 bins, a 361-return segment wrapping the sensor kept 4 control points). */
#define FIT_BIN_MIN_BINS 128u
/* Walk the bins of points pts[0..n) of a fit (bsf_params_t.fit_bin_length):
 * the first and last point and each vertex pos[0..nv) alone, each run
 * between two of them cut into equal bins of at most about `len` along the
 * run (its length summed over about 32 strides, so a curved run's bins are
 * not stretched by a short chord; noise only lengthens the sum, making bins
 * smaller). With ctrl NULL, bin means are written
 * over pts[0..) (bin j starts at or after point j, so in place) and the
 * vertices' bin indices to bin_pos; otherwise pts holds the points again and
 * each point's squared distance from the curve ctrl[0..m) is measured at its
 * bin's footpoint (t, one per bin): along the curve's normal for a bin of
 * several points, whole for a single point (as PDM measures it). Returns the
 * number of bins, or the sum of squared distances in *sum. */
static BSF_COMPACT_NOINLINE size_t bin_walk(bsf_extractor_t *ex, bsf_point_t *pts, size_t n,
                                            const uint16_t *pos, size_t nv, const bsf_point_t *ctrl,
                                            size_t m, float *sum)
{
    const float len = ex->params.fit_bin_length;
    const float *t = ex->scratch.seg.use.fit.pdm.t;
    size_t j = 0u;
    size_t v = 0u;
    size_t prev = 0u;
    size_t lo = 0u;
    size_t hi = 1u;
    size_t q = 0u;
    size_t runs = 0u; /* bins of the current run still to walk, after this one */
    size_t run_m = 0u;
    size_t worst_at = 0u;
    float worst = -1.0f;
    float total = 0.0f;
    for (;;) {
        float mx = 0.0f;
        float my = 0.0f;
        size_t i;
        if (ctrl == NULL) {
            for (i = lo; i < hi; ++i) {
                mx += pts[i].x;
                my += pts[i].y;
            }
            pts[j].x = mx / (float)(hi - lo);
            pts[j].y = my / (float)(hi - lo);
        } else {
            /* The bin's footpoint and the curve's derivative in u there. */
            span_point_t c;
            float cx, cy, tx, ty, inv;
            span_point(ctrl, m, t[j], &c);
            cx = c.x;
            cy = c.y;
            tx = c.k2 * c.u * c.bx - c.k0 * (1.0f - c.u) * c.ax;
            ty = c.k2 * c.u * c.by - c.k0 * (1.0f - c.u) * c.ay;
            inv = tx * tx + ty * ty;
            inv = hi - lo > 1u && inv > 0.0f ? 1.0f / inv : 0.0f;
            for (i = lo; i < hi; ++i) {
                const float dx = pts[i].x - cx;
                const float dy = pts[i].y - cy;
                const float along = tx * dx + ty * dy;
                float d2 = dx * dx + dy * dy - along * along * inv;
                d2 = d2 > 0.0f ? d2 : 0.0f;
                total += d2;
                if (d2 > worst) {
                    worst = d2;
                    worst_at = i;
                }
            }
        }
        ++j;
        if (hi == n) {
            ex->scratch.seg.use.fit.bin_worst = worst;
            ex->scratch.seg.use.fit.bin_worst_at = (uint16_t)worst_at;
            *sum = total;
            return j;
        }
        if (runs == 0u && lo == prev) {
            /* Past a pinned point: cut the run up to the next one. */
            const size_t next = v < nv ? pos[v] : n - 1u;
            size_t k = 1u;
            run_m = next - prev - 1u;
            if (run_m >= FIT_BIN_MIN_BINS) {
                /* Read before this run's first bin overwrites anything of it. */
                const size_t stride = run_m / 32u;
                const float most = len * (float)(run_m - 1u);
                float along = 0.0f;
                size_t at = prev + 1u;
                while (at < next - 1u) {
                    const size_t to = at + stride < next - 1u ? at + stride : next - 1u;
                    const float dx = pts[to].x - pts[at].x;
                    const float dy = pts[to].y - pts[at].y;
                    along += sqrtf(dx * dx + dy * dy);
                    at = to;
                }
                k = most >= along * (float)run_m ? run_m : (size_t)(most / along);
                k = k < run_m / FIT_BIN_MIN_BINS ? k : run_m / FIT_BIN_MIN_BINS;
                k = k > 1u ? k : 1u;
            }
            runs = run_m > 0u ? (run_m + k - 1u) / k : 0u;
            q = 0u;
        }
        if (runs > 0u) {
            /* The run's next bin: points prev+1 .. next-1 in `runs` near-equal parts. */
            const size_t of = q + runs;
            lo = prev + 1u + run_m * q / of;
            hi = prev + 1u + run_m * (q + 1u) / of;
            ++q;
            --runs;
            continue;
        }
        /* The next pinned point. */
        prev = v < nv ? pos[v] : n - 1u;
        if (ctrl == NULL && v < nv) {
            ex->scratch.seg.use.fit.bin_pos[v] = (uint16_t)j;
        }
        ++v;
        lo = prev;
        hi = prev + 1u;
    }
}

/* After a fit of points a..a+n-1 of segment s on bin means: the points
 * gathered again (as gather_segment does), and when the fit succeeded (ctrl,
 * m control points) their E_curve, returned; the farthest one is left for
 * split_point (bin_walk). */
#if !BSF_CONFIG_COMPACT && (defined(__GNUC__) || defined(__clang__))
__attribute__((noinline)) /* inlined, it slowed fit_segment's gather loop by 40 % */
#endif
static float
fit_returns_again(bsf_extractor_t *ex, const bsf_segment_t *s, size_t a, size_t n,
                  const uint16_t *pos, size_t nv, const bsf_point_t *ctrl, size_t m)
{
    bsf_point_t *pts = &ex->scratch.seg.use.fit.seg_points[a];
    size_t beam;
    size_t k = 0u;
    float sum;
#if !BSF_CONFIG_COMPACT
    {
        /* Speed only, the same points: the points before a counted in a
         * loop of their own, the arrays in locals (the point stores made
         * the compiler reload them at every beam). */
        const uint16_t *label = ex->scratch.seg.label;
        const bsf_point_t *pt = ex->points.pt;
        const uint16_t want = s->first;
        const size_t count = ex->points.count;
        const size_t stop = a + n;
        beam = s->first;
        while (k < a) { /* the points before a: counted only */
            k += label[beam] == want ? 1u : 0u;
            if (++beam == count) {
                beam = 0u;
            }
        }
        while (k < stop) {
            if (label[beam] == want) {
                pts[k - a] = pt[beam];
                ++k;
            }
            if (++beam == count) {
                beam = 0u;
            }
        }
    }
#else
    for (beam = s->first; k < a + n; beam = beam + 1u < ex->points.count ? beam + 1u : 0u) {
        if (ex->scratch.seg.label[beam] == s->first) {
            if (k >= a) {
                pts[k - a] = ex->points.pt[beam];
            }
            ++k;
        }
    }
#endif
    if (ctrl == NULL) {
        return 0.0f;
    }
    (void)bin_walk(ex, pts, n, pos, nv, ctrl, m, &sum);
    return sqrtf(sum / (float)n);
}

#endif /* BSF_CONFIG_FIT_BINS */

/* Where the cut policy splits points a..b of a segment (docs/DESIGN.md, "Cut
 * policy"), or 0 when the fit in res->ctrl[res->n_ctrl..] stands: when some
 * point lies more than split_dist from the curve, just after that point,
 * moved inwards so each side keeps SPLIT_MIN_POINTS points. A fit that used
 * every control point it may have stands: its worst point is at an end the
 * cap left off, and cutting there only chips the end off. The RMS bounds the
 * largest distance (max^2 <= n rms^2), so most fits need no search. */
static BSF_COMPACT_INLINE size_t split_point(const bsf_extractor_t *ex, size_t a, size_t b,
                                             size_t n_ctrl, float e_curve, const bsf_result_t *res)
{
    const float bound = ex->params.split_dist;
    const size_t n = b + 1u - a;
    size_t at;
    if (!(bound > 0.0f) || n < 2u * SPLIT_MIN_POINTS || n_ctrl >= (size_t)ex->params.pdm.max_ctrl ||
        e_curve * e_curve * (float)n <= bound * bound) {
        return 0u;
    }
#if BSF_CONFIG_FIT_BINS
    at = ex->scratch.seg.use.fit.bin_worst_at;
    if ((at != 0xFFFFu ? ex->scratch.seg.use.fit.bin_worst
                       : farthest_point(&ex->scratch.seg.use.fit.seg_points[a], n,
                                        ex->scratch.seg.use.fit.pdm.t, &res->ctrl[res->n_ctrl],
                                        n_ctrl, &at)) <= bound * bound) {
        return 0u;
    }
#else
    if (farthest_point(&ex->scratch.seg.use.fit.seg_points[a], n, ex->scratch.seg.use.fit.pdm.t,
                       &res->ctrl[res->n_ctrl], n_ctrl, &at) <= bound * bound) {
        return 0u;
    }
#endif
    at = at < SPLIT_MIN_POINTS - 1u ? SPLIT_MIN_POINTS - 1u : at;
    at = at > n - SPLIT_MIN_POINTS - 1u ? n - SPLIT_MIN_POINTS - 1u : at;
    return a + at + 1u;
}

/* PDM fit of points a..b of the gathered segment with its vertices inside
 * them (from 2 to count - 3 points in, as gather_segment keeps them), into
 * res->ctrl[res->n_ctrl..] without appending a feature. The vertex
 * positions, ascending, are shifted to the piece in place and back, so no
 * copy is made. *n_vertex_out receives the vertices used. */
static bsf_status_t fit_points(bsf_extractor_t *ex, const bsf_segment_t *s, size_t a, size_t b,
                               size_t n_vertex, bsf_result_t *res, size_t *n_ctrl, float *e_curve,
                               size_t *n_vertex_out)
{
    bsf_point_t *pts = &ex->scratch.seg.use.fit.seg_points[a];
    size_t nb;
    uint16_t *pos = ex->scratch.seg.use.fit.vertex_pos;
    /* LC's keypoint is the walls' intersection: the vertex stays there. */
    const int anchored = USES_LC(ex);
    const size_t n = b + 1u - a;
    /* This fit's parameters and outcome live in the scratch, not on the
     * stack of the deepest call chain. */
    bsf_pdm_params_t *pdm = &ex->scratch.seg.use.fit.pdm_params;
    bsf_pdm_info_t *info = &ex->scratch.seg.use.fit.pdm_info;
    size_t v0 = 0u;
    size_t v1;
    size_t i;
    bsf_status_t st;
    while (v0 < n_vertex && pos[v0] < a + 2u) {
        ++v0;
    }
    for (v1 = v0; v1 < n_vertex && (size_t)pos[v1] + 3u <= b + 1u;) {
        ++v1;
    }
    *n_vertex_out = v1 - v0;
    if (v1 - v0 > (size_t)BSF_PDM_MAX_VERTICES) {
        return BSF_ERR_CAPACITY; /* more corners than one feature can hold */
    }
    for (i = v0; i < v1; ++i) {
        pos[i] = (uint16_t)(pos[i] - a);
    }
    nb = n;
#if BSF_CONFIG_FIT_BINS
    if (ex->params.fit_bin_length > 0.0f && n >= 2u * FIT_BIN_MIN_BINS) {
        float sum;
        nb = bin_walk(ex, pts, n, &pos[v0], v1 - v0, NULL, 0u, &sum);
    }
    ex->scratch.seg.use.fit.bin_worst_at = 0xFFFFu; /* split_point: farthest_point's */
#endif
    *pdm = ex->params.pdm;
    if (ex->params.fit_passes != 0u) {
        /* The passes left per point left (fit_passes), at least one: the
         * first solve runs anyway. */
        const uint32_t share =
            ex->scratch.seg.use.fit.passes_left / (ex->scratch.seg.use.fit.points_left > n
                                                       ? ex->scratch.seg.use.fit.points_left
                                                       : (uint32_t)n);
        pdm->max_passes = (uint16_t)(share > 0xFFFFu ? 0xFFFFu : (share > 0u ? share : 1u));
    }
    info->iterations = 0u;
    st = bsf_pdm_fit_anchored(pts, nb, nb < n ? ex->scratch.seg.use.fit.bin_pos : &pos[v0],
                              anchored ? &ex->scratch.seg.use.fit.vertex_anchor[v0] : NULL, v1 - v0,
                              pdm, &ex->scratch.seg.use.fit.pdm, &res->ctrl[res->n_ctrl],
                              &res->ctrl_is_vertex[res->n_ctrl],
                              (size_t)BSF_MAX_CTRL_POINTS - res->n_ctrl, n_ctrl, e_curve, info);
    {
        /* What this fit spent, failed or not, counts against the scan. */
        const uint32_t spent = info->iterations * (uint32_t)nb;
        uint32_t *left = &ex->scratch.seg.use.fit.passes_left;
        *left = spent < *left ? *left - spent : 0u;
        res->stats.n_fit_visits += spent;
    }
#if BSF_CONFIG_FIT_BINS
    if (nb < n) {
        const float e = fit_returns_again(ex, s, a, n, &pos[v0], v1 - v0,
                                          st == BSF_OK ? &res->ctrl[res->n_ctrl] : NULL, *n_ctrl);
        if (st == BSF_OK) {
            *e_curve = e;
        }
    }
#else
    (void)s;
#endif
    for (i = v0; i < v1; ++i) {
        pos[i] = (uint16_t)(pos[i] + a);
    }
    return st;
}

/* Append the feature whose control points were just fitted at res->n_ctrl. */
static void append_feature(bsf_result_t *res, uint16_t first_beam, uint16_t last_beam,
                           uint16_t n_points, uint8_t kind, size_t n_ctrl, float e_curve)
{
    bsf_feature_t *f = &res->features[res->n_features++];
    f->first_beam = first_beam;
    f->last_beam = last_beam;
    f->n_points = n_points;
    f->ctrl_first = res->n_ctrl;
    f->n_ctrl = (uint8_t)n_ctrl;
    f->kind = kind;
    f->e_curve = e_curve;
    res->n_ctrl = (uint16_t)(res->n_ctrl + n_ctrl);
    res->stats.n_in_features += n_points;
    res->stats.n_ctrl += (uint32_t)n_ctrl;
}

/* Fit a segment of n gathered points as features: whole, or split by the
 * cut policy (split_point) into pieces that each fit, left to right. A piece
 * that fails undoes the pieces appended before it; the segment is then
 * fitted whole, unsplit, or its status returned when the whole fit fails or
 * the result has no room (BSF_ERR_BUFFER). */
static BSF_COMPACT_INLINE bsf_status_t fit_pieces(bsf_extractor_t *ex, const bsf_segment_t *s,
                                                  size_t n, size_t n_vertex, bsf_result_t *res)
{
    size_t lo0 = 0u;
    size_t hi0 = n - 1u;
    uint16_t lo[SPLIT_STACK];
    uint16_t hi[SPLIT_STACK];
    const uint16_t features0 = res->n_features;
    const uint16_t ctrl0 = res->n_ctrl;
    const uint32_t in0 = res->stats.n_in_features;
    const uint32_t nctrl0 = res->stats.n_ctrl;
    int may_split = 1;
    size_t depth = 1u;
#if (BSF_CONFIG_METHODS) & BSF_CONFIG_METHOD_LC
    n_vertex = trim_tails(ex, s, n, n_vertex, &lo0, &hi0);
#endif
    lo[0] = (uint16_t)lo0;
    hi[0] = (uint16_t)hi0;
    while (depth > 0u) {
        const size_t a = lo[depth - 1u];
        const size_t b = hi[depth - 1u];
        size_t n_ctrl = 0u;
        size_t nv = 0u;
        float e_curve = 0.0f;
        size_t cut = 0u;
        bsf_status_t st = BSF_ERR_BUFFER;
        --depth;
        if (res->n_features < BSF_MAX_SEGMENTS && (size_t)BSF_MAX_CTRL_POINTS - res->n_ctrl >= 3u) {
            st = fit_points(ex, s, a, b, n_vertex, res, &n_ctrl, &e_curve, &nv);
        }
        if (st != BSF_OK) {
            res->n_features = features0;
            res->n_ctrl = ctrl0;
            res->stats.n_in_features = in0;
            res->stats.n_ctrl = nctrl0;
            if (st == BSF_ERR_BUFFER || (a == lo0 && b == hi0)) {
                return st;
            }
            may_split = 0; /* start again: the whole segment, unsplit */
            depth = 1u;
            lo[0] = (uint16_t)lo0;
            hi[0] = (uint16_t)hi0;
            continue;
        }
        if (may_split && depth + 2u <= SPLIT_STACK) {
            cut = split_point(ex, a, b, n_ctrl, e_curve, res);
        }
        if (cut != 0u) {
            lo[depth] = (uint16_t)cut; /* right piece, fitted after the left */
            hi[depth++] = (uint16_t)b;
            lo[depth] = (uint16_t)a;
            hi[depth++] = (uint16_t)(cut - 1u);
        } else {
            /* A feature (the whole segment less its tails, or a piece) is
             * auxiliary when its fit holds a vertex: a tail left off can
             * take the segment's vertex with it, and a two-return end of a
             * short segment can give it one (trim_tails). The segment's
             * last beam is known: no walk through it (the first is
             * beam_of_point's first step anyway). */
            append_feature(res, beam_of_point(ex, s, a),
                           b + 1u == n ? s->last : beam_of_point(ex, s, b), (uint16_t)(b + 1u - a),
                           (uint8_t)(nv > 0u ? BSF_FEATURE_AUXILIARY : BSF_FEATURE_BLEAK), n_ctrl,
                           e_curve);
        }
    }
    return BSF_OK;
}

/* Fit one segment and append its feature (or the pieces the cut policy
 * splits it into) to the result. Returns BSF_OK, BSF_ERR_BUFFER when the
 * feature table or the control-point pool has no room left for it, or
 * another error when the fit itself fails (then nothing is appended). */
static bsf_status_t fit_segment(bsf_extractor_t *ex, const bsf_segment_t *s, bsf_result_t *res)
{
    size_t n_vertex = 0u;
    size_t n;
    float e_curve = 0.0f;
    bsf_status_t st;
    const size_t room = (size_t)BSF_MAX_CTRL_POINTS - res->n_ctrl;

    /* No fit when no feature could fit: a feature has at least 3 control
     * points (4 from LSBA). */
    if (res->n_features >= BSF_MAX_SEGMENTS || room < (USES_RPOS(ex) ? 4u : 3u)) {
        return BSF_ERR_BUFFER;
    }
    n = gather_segment(ex, s, &n_vertex);
    if (n == 0u) {
        return BSF_ERR_DEGENERATE; /* as PDM and LSBA say for too few points */
    }
    if (!USES_RPOS(ex)) {
        st = fit_pieces(ex, s, n, n_vertex, res);
        /* fit_features summed the same counts: no wrap. */
        ex->scratch.seg.use.fit.points_left -= s->n_points;
        return st;
    }
    st = bsf_lsba_fit(ex->scratch.seg.use.fit.seg_points, n, &res->ctrl[res->n_ctrl], &e_curve);
    if (st != BSF_OK) {
        return st;
    }
    memset(&res->ctrl_is_vertex[res->n_ctrl], 0, 4u);
    append_feature(res, s->first, s->last, s->n_points, s->kind, 4u, e_curve);
    return BSF_OK;
}

/* Index of the segment that comes next when going from most points to
 * fewest, ties in segment order, after segment `prev` (n_segments to start);
 * n_segments when there is none left. */
static size_t next_largest_segment(const bsf_extractor_t *ex, size_t prev)
{
    const uint32_t prev_n = prev < ex->n_segments ? ex->segments[prev].n_points : 0x10000u;
    size_t best = ex->n_segments;
    size_t i;
    for (i = 0; i < ex->n_segments; ++i) {
        const uint32_t np = ex->segments[i].n_points;
        const int after_prev = np < prev_n || (np == prev_n && i > prev && prev < ex->n_segments);
        if (after_prev && (best == ex->n_segments || np > ex->segments[best].n_points)) {
            best = i;
        }
    }
    return best;
}

/* Reverse v[a..b) and the vertex flags with it. */
static void reverse_ctrl(bsf_result_t *res, size_t a, size_t b)
{
    while (a + 1u < b) {
        const bsf_point_t p = res->ctrl[a];
        const uint8_t v = res->ctrl_is_vertex[a];
        --b;
        res->ctrl[a] = res->ctrl[b];
        res->ctrl_is_vertex[a] = res->ctrl_is_vertex[b];
        res->ctrl[b] = p;
        res->ctrl_is_vertex[b] = v;
        ++a;
    }
}

/* Beam order of features: by first beam, one wrapping through the seam of a
 * full-circle scan (first_beam > last_beam) last, as segmentation emits them. */
static BSF_COMPACT_NOINLINE uint32_t beam_order_key(const bsf_feature_t *f)
{
    return (f->first_beam > f->last_beam ? 0x10000u : 0u) + f->first_beam;
}

/* Sort the features into beam order and lay their control points out in
 * that order, as a result fitted in beam order has them. In place. */
static void put_features_in_beam_order(bsf_result_t *res)
{
    size_t i;
    size_t at = 0u;
    for (i = 1; i < res->n_features; ++i) {
        const bsf_feature_t f = res->features[i];
        size_t j = i;
        while (j > 0u && beam_order_key(&res->features[j - 1u]) > beam_order_key(&f)) {
            res->features[j] = res->features[j - 1u];
            --j;
        }
        res->features[j] = f;
    }
    for (i = 0; i < res->n_features; ++i) {
        bsf_feature_t *f = &res->features[i];
        const size_t from = f->ctrl_first;
        const size_t n = f->n_ctrl;
        size_t k;
        if (from != at) {
            /* Rotate [at, from + n) so the block moves to `at`; the blocks in
             * [at, from) (all of later features) move up by n. */
            reverse_ctrl(res, at, from);
            reverse_ctrl(res, from, from + n);
            reverse_ctrl(res, at, from + n);
            for (k = i + 1u; k < res->n_features; ++k) {
                if (res->features[k].ctrl_first < from) {
                    res->features[k].ctrl_first = (uint16_t)(res->features[k].ctrl_first + n);
                }
            }
            f->ctrl_first = (uint16_t)at;
        }
        at += n;
    }
}

/* Fit every segment in segment order. When the control points or the
 * feature table run out, start again, fitting the segments that cover the
 * most points first, so what is left out is the small stuff: a segment that
 * does not fit then is cut; smaller ones may still fit after it. */
static void fit_features(bsf_extractor_t *ex, bsf_result_t *res)
{
    uint32_t points = 0u;
    size_t si;
    int largest_first = 0;
    for (si = 0; si < ex->n_segments; ++si) {
        points += ex->segments[si].n_points;
    }
    ex->scratch.seg.use.fit.points_left = points;
    ex->scratch.seg.use.fit.passes_left = (uint32_t)ex->params.fit_passes * points;
    for (si = 0; si < ex->n_segments; si = largest_first ? next_largest_segment(ex, si) : si + 1u) {
        const bsf_segment_t *s = &ex->segments[si];
        const bsf_status_t st = fit_segment(ex, s, res);
        if (st == BSF_ERR_BUFFER && !largest_first) {
            /* Start again; the passes the first attempt spent stay spent. */
            largest_first = 1;
            ex->scratch.seg.use.fit.points_left = points;
            res->n_features = 0u;
            res->n_ctrl = 0u;
            res->stats.n_in_features = 0u;
            res->stats.n_ctrl = 0u;
            res->stats.n_unfitted = 0u;
            si = ex->n_segments;
        } else if (st == BSF_ERR_BUFFER) {
            res->stats.cut |=
                (res->n_features >= BSF_MAX_SEGMENTS) ? BSF_CUT_SEGMENTS : BSF_CUT_CTRL;
            res->stats.n_cut_segments++;
            res->stats.n_cut_points += s->n_points;
        } else if (st != BSF_OK) {
            /* Not fitted: its points count as wasted (docs/DESIGN.md, "PDM and
             * refinement"). */
            res->stats.n_unfitted++;
        }
    }
    /* Back into beam order when the fit went largest first, or when a split
     * segment's later pieces start past a segment that lies inside its run
     * (an occluder, SVED's look-back) or past the seam of a full-circle
     * scan (features already in beam order stay as they are). */
    for (si = 1; si < res->n_features; ++si) {
        if (beam_order_key(&res->features[si]) <= beam_order_key(&res->features[si - 1u])) {
            put_features_in_beam_order(res);
            break;
        }
    }
    res->stats.n_features = res->n_features;
}

static void clear_result(bsf_result_t *res)
{
    res->n_features = 0u;
    res->n_ctrl = 0u;
    memset(&res->stats, 0, sizeof res->stats);
}

bsf_status_t bsf_extract(bsf_extractor_t *ex, const bsf_scan_t *scan, bsf_result_t *res)
{
    stage_clock_t clk;
    bsf_status_t st;

    if (ex == NULL || scan == NULL || res == NULL) {
        return BSF_ERR_ARG;
    }
    clear_result(res);
    if (ex->ready != BSF_EXTRACTOR_READY) {
        return BSF_ERR_ARG;
    }
    clock_start(&clk, &ex->params);

    st = bsf_scan_to_points(scan, &ex->points);
    if (st != BSF_OK) {
        return st;
    }
    st = bsf_points_reject_no_return(&ex->points, &ex->params.no_return, NULL);
    if (st != BSF_OK) {
        return st;
    }
    res->stats.n_beams = (uint32_t)ex->points.count;
    res->stats.n_valid = (uint32_t)ex->points.n_valid;
    clock_stage(&clk, &res->stats, BSF_STAGE_POINTS);

    st = detect_corners(ex, &res->stats);
    if (st == BSF_OK) {
        res->stats.n_keypoints = (uint32_t)ex->n_keypoints;
        clock_stage(&clk, &res->stats, BSF_STAGE_CORNERS);
        st = segment(ex, &res->stats);
    }
    if (st != BSF_OK) {
        clear_result(res);
        return st;
    }
    clock_stage(&clk, &res->stats, BSF_STAGE_SEGMENTS);
    fit_features(ex, res);
    clock_stage(&clk, &res->stats, BSF_STAGE_FIT);
    return res->stats.cut != 0u ? BSF_OK_CUT : BSF_OK;
}
