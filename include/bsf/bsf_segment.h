/* SPDX-License-Identifier: MIT */
/*
 * bsf_segment.h - split a scan's points into segments (runs of beams that
 * belong to one surface), drop the short ones as wasted, and classify the
 * kept ones as auxiliary (a corner inside) or bleak (smooth).
 *
 * Two methods (docs/DESIGN.md, "Methods"):
 *  - SVED (default): a point joins the current segment when its distance to
 *    the segment's last point is at most r(rho) = a * exp(b * rho), rho the
 *    range of the new point. Invalid beams never break a segment by
 *    themselves: only the distance test does.
 *  - RPOS (baseline of the paper): consecutive VALID points q[i-1], q[i],
 *    q[i+1] stay together while the turn between q[i]-q[i-1] and q[i+1]-q[i]
 *    is at most alpha_max and the two spacings differ by at most a factor eta.
 *
 * Both keep segments of at least min_segment_points valid points; points of
 * shorter segments are wasted (paper section 5.3.1: fewer than five points).
 * Both make one pass over the beams, use no square root and no heap.
 */
#ifndef BSF_SEGMENT_H
#define BSF_SEGMENT_H

#include "bsf_common.h"
#include "bsf_feature.h"
#include "bsf_scan.h"

BSF_BEGIN_DECLS

/** One kept segment: a run of beams, both ends valid beams. */
typedef struct {
    uint16_t first;     /**< beam index of the first valid point (inclusive) */
    uint16_t last;      /**< beam index of the last valid point (inclusive) */
    uint16_t n_points;  /**< valid points in the segment (invalid beams inside are not counted) */
    uint8_t kind;       /**< a bsf_feature_kind_t, set by bsf_segment_classify (BLEAK before) */
    uint8_t n_interest; /**< inner interest points (see bsf_segment_classify), saturates at 255 */
} bsf_segment_t;

/** "No segment" in a label array (see bsf_segment_sved_labelled). */
#define BSF_SEG_NONE 0xFFFFu

/**
 * SVED parameters. The first three are the paper's rule; the last five
 * extend it and are all off in bsf_sved_params_paper():
 *  - lookback: besides the current segment, a point may join one of the
 *    `lookback` most recently extended open segments whose last point lies
 *    within the radius and at most max_gap_beams beams back (the nearest
 *    such last point wins). So a thin occluder (a chair leg, a door frame)
 *    in front of a wall leaves the wall one segment instead of splitting
 *    it; points inside a segment stay in beam order.
 *  - radius_max: the radius a * exp(b * rho) is capped at radius_max. The
 *    paper states a and b for ranges 0.5..30 m; beyond that the exponential
 *    explodes (3.3 m at 40 m, 13 m at 60 m) and chains sparse far points
 *    metres apart into one feature.
 *  - reject_mixed: a mixed pixel (a lone reading between a foreground and a
 *    background surface at a depth jump, see bsf_segment_sved_labelled)
 *    joins no segment, so it cannot bend or bridge either surface.
 *  - join_grazing: a wall seen at grazing incidence returns one point every
 *    half metre or more at 7 m, farther apart than the radius, yet on a line
 *    to millimetres; such steps join the current segment (on by default, off
 *    in the paper's rule: the corners of such walls are found,
 *    docs/GROUND_TRUTH.md).
 */
typedef struct {
    float a;                     /**< distance threshold at range 0, metres, finite, > 0 */
    float b;                     /**< growth of the threshold with range, 1/metre, finite, >= 0 */
    uint16_t min_segment_points; /**< shortest kept segment, points, 1..BSF_MAX_POINTS */
    uint16_t max_gap_beams;      /**< rejoin only segments whose last point is at most this
                                      many beams back, 1..BSF_MAX_POINTS (used when lookback > 0) */
    float radius_max;            /**< cap on the radius, metres; 0 = no cap (the paper), else
                                      finite and >= a */
    uint8_t lookback;     /**< older open segments a point may rejoin, 0..BSF_SVED_MAX_LOOKBACK;
                               0 = the paper's rule (the current segment only) */
    uint8_t reject_mixed; /**< 1: mixed pixels join no segment; 0: the paper */
    uint8_t join_grazing; /**< 1: a point also joins the current segment across a step wider
                               than the radius (at most radius_max, used when radius_max > 0)
                               where four consecutive returns through the step lie on one line,
                               a wall seen at grazing incidence (up to 80 deg), or where such a
                               wall starts at a corner (default); 2: also the first four
                               returns of a wall seen nearer edge-on, when they start at a
                               corner (or the last four, ending at one): the default of
                               lc-sved-pdm, whose corners end there; 0 (the paper): none */
} bsf_sved_params_t;

/** Largest lookback of bsf_sved_params_t. */
#define BSF_SVED_MAX_LOOKBACK 8u

/** RPOS parameters. */
typedef struct {
    float alpha_max;             /**< largest turn between successive steps, radians, (0, pi] */
    float eta;                   /**< largest ratio of successive spacings, 1..1e6 */
    uint16_t min_segment_points; /**< shortest kept segment, points, 1..BSF_MAX_POINTS */
} bsf_rpos_params_t;

/**
 * SVED defaults (what the extractor uses unless told otherwise): the paper's
 * a = 0.2 m, b = 0.07 /m, min_segment_points = 5, plus lookback 4,
 * max_gap_beams 16, radius_max 1.0 m, reject_mixed 1 and join_grazing 1 (docs/TABLE1.md has
 * the measurements behind each value).
 */
bsf_sved_params_t bsf_sved_params_default(void);

/** The paper's SVED rule exactly: a = 0.2 m, b = 0.07 /m, min_segment_points
 *  = 5, lookback 0, radius_max 0 (none), reject_mixed 0, join_grazing 0. */
bsf_sved_params_t bsf_sved_params_paper(void);

/** RPOS defaults of the paper: alpha_max = pi/4, eta = 1.5, min_segment_points = 5. */
bsf_rpos_params_t bsf_rpos_params_default(void);

/**
 * Check SVED parameters against the ranges documented on bsf_sved_params_t.
 * @return BSF_OK; BSF_ERR_ARG when p is NULL; BSF_ERR_PARAM when a value is out
 *         of range (NaN included).
 */
BSF_NODISCARD bsf_status_t bsf_sved_params_check(const bsf_sved_params_t *p);

/**
 * Check RPOS parameters against the ranges documented on bsf_rpos_params_t.
 * @return BSF_OK; BSF_ERR_ARG when p is NULL; BSF_ERR_PARAM when a value is out
 *         of range (NaN included).
 */
BSF_NODISCARD bsf_status_t bsf_rpos_params_check(const bsf_rpos_params_t *p);

/**
 * SVED segmentation, the paper's rule whatever the extensions in params say
 * (they are checked, then ignored; bsf_segment_sved_labelled applies them).
 * Walks the beams in order; each valid point joins the
 * current segment when its distance to the segment's last point is at most
 * a * exp(b * rho) (rho: its range, metres), else it starts a new segment.
 * Segments with fewer than min_segment_points points are not output; their
 * points are counted as wasted. Kept segments come out in beam order, with
 * kind BSF_FEATURE_BLEAK and n_interest 0 (see bsf_segment_classify).
 *
 * @param pts     points of one scan (bsf_scan_to_points)
 * @param params  parameters; NULL means the defaults
 * @param out     kept segments (cap entries; may be NULL when cap is 0)
 * @param cap     length of out
 * @param n_out   number of kept segments written
 * @param n_wasted_points  valid points in dropped segments (may be NULL);
 *                always pts->n_valid minus the points of the kept segments
 * @return BSF_OK (an empty or all-invalid scan gives 0 segments, and a single
 *         valid point 0 segments and 1 wasted point with the defaults);
 *         BSF_ERR_ARG for a NULL pts or n_out, or out NULL with cap > 0;
 *         BSF_ERR_PARAM for bad params; BSF_ERR_CAPACITY when pts->count
 *         exceeds BSF_MAX_POINTS or more than cap segments are kept. On any
 *         error *n_out and *n_wasted_points are 0 and out is unspecified.
 */
BSF_NODISCARD bsf_status_t bsf_segment_sved(const bsf_points_t *pts,
                                            const bsf_sved_params_t *params, bsf_segment_t *out,
                                            size_t cap, size_t *n_out, size_t *n_wasted_points);

/**
 * SVED with every extension of bsf_sved_params_t, and a per-beam label.
 * With lookback 0, radius_max 0 and reject_mixed 0 the segments are those of
 * the paper's rule (bsf_segment_sved). With lookback > 0 a segment's beam
 * run [first, last] may contain beams of other segments (an occluder in
 * front of a wall), so its members are the beams labelled with its first
 * beam.
 *
 * Mixed pixel: valid beam i whose neighbours i-2..i+2 are valid, whose range
 * lies strictly between those of beams i-1 and i+1, which jump by
 * J = |rho(i+1) - rho(i-1)| > the radius at rho(i), and either
 *  - the range steps i-2 -> i-1 and i+1 -> i+2 are both below J / 4 (two
 *    flat surfaces on either side, unlike a wall seen at a grazing angle
 *    whose steps grow smoothly), and beam i is more than J / 8 from both
 *    neighbours in range; or
 *  - it lies on neither surface, however near one of them in range: on
 *    the side nearer to beam i in range, at least 8 consecutive returns (up
 *    to 10) step within the radius at rho(i), the nearest lies on the total
 *    least-squares line of the others, and beam i lies off that line,
 *    towards the other surface, by more than 4 standard deviations of its
 *    extrapolated distance (the noise taken from the line's residual, at
 *    least 3 mm), while the nearest return does not lie off it on the same
 *    side by a quarter of that (the run turning there); and beam i lies
 *    beyond the radius from its neighbour on the other side and does not go
 *    on along a line through that neighbour and the next one (where the
 *    other side's first range step is within the radius: and the one after,
 *    both collinear; where it is wider, a wall seen at grazing incidence or
 *    lone returns, the first line suffices). A return at a surface's real
 *    end lies on that surface's line and stays; so does a return beside a
 *    run too short or bent to judge (a small object, a corner next to beam
 *    i), and the first return of a grazing wall. A single return of a third
 *    surface beyond a corner, between the two in range and off both, looks
 *    the same as a mixed pixel and goes too; or
 *  - it lies beside a thin occluder: its nearer neighbour (beyond the
 *    radius of beam i) and at most one more return beyond it (a leg, a
 *    post) are nearer than beam i, the next return past them is farther and
 *    beyond the radius of the occluder's last, and the surface behind is
 *    seen on both sides (2 or 3 consecutive returns within the radius on
 *    beam i's side and past the occluder). Beam i lies off the total
 *    least-squares line of those returns, on the occluder's side, by more
 *    than 5 standard deviations of its distance (the noise from the line's
 *    residual, at least 3 mm) and by more than 1/8 of the occluder's own
 *    distance from that line. The surface's own return beside the occluder
 *    lies on the line and stays.
 *    bsf_extract's LC (the default method) does not see the returns the
 *    second and third routes reject either (the first route has no noise
 *    scale: at 3 cm noise it takes real returns at small depth steps too).
 *
 * Full-circle scans (bsf_points_full_circle): the pass starts after the
 * widest step between cyclically consecutive valid points, so a surface
 * crossing the seam between the last and the first beam is one segment; it
 * is reported with first > last (beams first..count-1 then 0..last).
 *
 * @param label  pts->count entries (may be NULL): the first beam of the kept
 *               segment beam i belongs to, or BSF_SEG_NONE (invalid, wasted,
 *               mixed pixel)
 * Other parameters, outputs and return codes as bsf_segment_sved, except
 * that segments come out ordered by first beam (a wrapping one last).
 */
BSF_NODISCARD bsf_status_t bsf_segment_sved_labelled(const bsf_points_t *pts,
                                                     const bsf_sved_params_t *params,
                                                     bsf_segment_t *out, size_t cap,
                                                     uint16_t *label, size_t *n_out,
                                                     size_t *n_wasted_points);

/**
 * RPOS segmentation over consecutive VALID points: invalid beams are
 * skipped, so across a gap the spacing is the distance between the valid
 * points on either side (a gap of one beam on a wall doubles the spacing and
 * therefore breaks by the eta test; SVED is the method that bridges gaps).
 * A segment's first two
 * points always go together; each further point q[i+1] joins while, at the
 * segment's last point q[i], the turn |alpha_i| between q[i]-q[i-1] and
 * q[i+1]-q[i] is <= alpha_max and max(p_i, p_(i+1)) <= eta * min(p_i, p_(i+1))
 * with p_i = |q[i] - q[i-1]|. Otherwise the segment ends at q[i] and a new
 * one starts at q[i+1]: a corner point stays with the segment before it, and
 * an isolated outlier drags its next neighbour into a two-point (wasted)
 * segment, as in the paper. Output, waste rule, parameters and return codes
 * as bsf_segment_sved.
 */
BSF_NODISCARD bsf_status_t bsf_segment_rpos(const bsf_points_t *pts,
                                            const bsf_rpos_params_t *params, bsf_segment_t *out,
                                            size_t cap, size_t *n_out, size_t *n_wasted_points);

/**
 * Classify segments against interest points (corner beam indices).
 * A segment is BSF_FEATURE_AUXILIARY when at least one interest beam is a
 * valid beam of the segment other than its first two or last two valid
 * points; otherwise BSF_FEATURE_BLEAK. n_interest gets the number of such
 * inner interest points (saturating at 255). Segments may come in any order.
 *
 * @param segs            segments to update (n entries; may be NULL when n is 0)
 * @param pts             the points the segments were made from
 * @param interest_beams  beam indices, strictly ascending (may be NULL when
 *                        n_interest is 0); indices outside the scan are never inside a segment
 * @return BSF_OK; BSF_ERR_ARG for NULL pointers (as above), interest beams not
 *         strictly ascending, or a segment with first > last or last >=
 *         pts->count; BSF_ERR_CAPACITY when pts->count exceeds BSF_MAX_POINTS.
 *         On error no segment is changed.
 */
BSF_NODISCARD bsf_status_t bsf_segment_classify(bsf_segment_t *segs, size_t n,
                                                const bsf_points_t *pts,
                                                const uint16_t *interest_beams, size_t n_interest);

/**
 * bsf_segment_classify for segments from bsf_segment_sved_labelled: a
 * segment's points are the beams labelled with its first beam, and a
 * segment may wrap (first > last). label NULL means every valid beam of the
 * run belongs to the segment (then it equals bsf_segment_classify, plus
 * wrapping). Return codes as bsf_segment_classify (first > last is allowed).
 */
BSF_NODISCARD bsf_status_t bsf_segment_classify_labelled(bsf_segment_t *segs, size_t n,
                                                         const bsf_points_t *pts,
                                                         const uint16_t *label,
                                                         const uint16_t *interest_beams,
                                                         size_t n_interest);

BSF_END_DECLS

#endif /* BSF_SEGMENT_H */
