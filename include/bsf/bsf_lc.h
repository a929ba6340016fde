/* SPDX-License-Identifier: MIT */
/*
 * bsf_lc.h - LC, the line-corner detector: bsf's own corner source, used by
 * the default method "lc-sved-pdm". It is not FALKO and does not try to
 * reproduce FALKOLib (FALKO stays available, keypoint-identical to FALKOLib,
 * in "falko-sved-pdm", the paper-faithful method).
 *
 * How it works, per run of points that SVED's distance rule keeps together:
 *  1. split the run where a point lies farther than a tolerance from the chord
 *     of its piece (Douglas-Peucker without recursion); the tolerance is
 *     split_sigmas times the run's noise, estimated from how far each point
 *     lies from the chord of its two neighbours, and at least split_min.
 *     Where the beams are denser than 5 cm at the point's range, the
 *     chord's direction comes from the points 5 cm of beams either side
 *     (the neighbours' chord would point anywhere at centimetre noise), and
 *     the tolerance is split_sigmas times the noise along the rays there
 *     when that is larger: a wall facing the sensor has many points with
 *     the whole range noise across it, which the run's average across its
 *     surfaces (lowered by walls seen obliquely) would split every few
 *     points;
 *  2. judge every split point with the two pieces beside it (each cut to
 *     max_side metres from the apex): fit a total-least-squares line to each
 *     side (the apex left out) and keep the split as a corner only when
 *     - each side has min_side_points points (one fewer where it runs to
 *       the end of its run) and reaches min_side_len (a side of more points
 *       may fall short of it by the square root of their ratio, to half),
 *     - the lines turn by at least min_turn,
 *     - their intersection lies near the apex (within twice the local beam
 *       spacing plus apex_slack), and
 *     - two lines explain the points much better than one smooth curve: the
 *       squared residual of the better of one line and one circle (fitted to
 *       both sides together) is above curve_ratio times that of the two
 *       lines, plus (count x floor^2). So round pillars, curved walls and
 *       noise on straight walls give no corner, whatever the beam spacing;
 *     - each side is straight: a circle does not explain it curve_ratio times
 *       better per degree of freedom (n - 2 for a line, n - 3 for a circle;
 *       a side of three points passes, since any circle fits three points);
 *     with corner_evidence, a split that fails the curve_ratio test is
 *     still a corner when the curve's squared residual exceeds the two
 *     lines' by as many noise variances as chance exceeds once in about
 *     270 000 judgements (25 with many points, more with few: the F
 *     distribution's tail with the noise variance estimated from the
 *     lines), and by at least one noise variance per point, also against
 *     the geometrically fitted circle; then neither side may show curvature
 *     at that level, be seen at more than 80 deg incidence, nor any two
 *     consecutive points step along the ray by more than such a surface
 *     allows (a depth jump, a mixed pixel). The ratio test asks the same
 *     factor whatever the number of points, so a shallow corner between
 *     long sides (a 35 deg turn between 1.3 m sides scores 5-25 at 1 cm
 *     noise) fails it by chance; this test grows with the noise instead;
 *     a rejected split merges its two pieces and the neighbours are judged
 *     again, unless its sides turn (by min_turn, and two lines beat one line
 *     curve_ratio times) and no smooth curve explains its points within the
 *     noise (the first bound of the evidence test above, whatever
 *     corner_evidence says): such a split is no corner, but it stays and ends
 *     its neighbours' sides, so a side never reaches across a shallow corner
 *     the tests could not confirm into the next wall (where its line's
 *     residual would grow and cost that neighbour its corner too);
 *     once the lines turn by min_turn, and before their other tests, a split
 *     where a side's line does not explain its points within the noise
 *     (2 (n - 2) + 6.25 noise variances) is judged as a crease, where a
 *     curved wall meets a wall or another curved wall: each side is its
 *     line, or its circle when that cuts the line's residual by 25 noise
 *     variances, has at least 10 points, spans at most 60 deg and fits
 *     within the noise itself; the split is a corner when the best circle
 *     over both sides leaves curve_ratio times the two pieces' squared
 *     residual (counted at no less than the noise) plus the floor, no depth
 *     jump lies in the window, and the pieces cross near the apex (as near
 *     as the lines must) at min_turn or more. The circles of one pillar, or
 *     of a wall of varying curvature, touch rather than cross, so these get
 *     no corner. Where a side is round, the two lines' intersection would
 *     lie off the crease even when they pass; a side of min_side_points - 1
 *     points (where it runs to the end of its run) gives no corner when the
 *     intersection lies past the apex's ray, away from it, by 3 noise
 *     standard deviations while the apex lies 3 of them nearer the other
 *     side's line than its own: the far wall's first return beyond its own
 *     corner, where a mixed pixel among the two points turned their line
 *     (where both sides are that short, the side before the apex is tested);
 *  3. report each corner at its apex beam, with the intersection of the two
 *     lines (of the crease's pieces) as its position (PDM starts the vertex
 *     there and keeps it there).
 * On a full-circle scan (bsf_points_full_circle) the pass starts at the first
 * beam where a run breaks anyway, so a run goes on through the seam between
 * the last and the first beam and a corner straight behind the sensor is
 * judged as one ahead is (a closed surface all round, with no break, is cut
 * at the seam).
 * Thresholds are absolute or relative to the estimated noise; none depends
 * on the other corners of the scan. Cost is linear in beams per split level.
 */
#ifndef BSF_LC_H
#define BSF_LC_H

#include "bsf_common.h"
#include "bsf_scan.h"

BSF_BEGIN_DECLS

/** LC parameters; start from bsf_lc_params_default(). */
typedef struct {
    float jump_a;       /**< runs break where consecutive points are farther apart than
                             jump_a * exp(jump_b * range), metres (0.2, SVED's) */
    float jump_b;       /**< see jump_a, 1/metres (0.07) */
    float split_min;    /**< smallest split tolerance, metres (0.02) */
    float split_sigmas; /**< split tolerance in estimated noise sigmas (4) */
    float min_turn;     /**< smallest change of direction at a corner, radians (0.15) */
    float curve_ratio;  /**< two lines must beat the best smooth curve by this factor (10) */
    float floor;        /**< residual floor per point, metres (0.003) */
    float max_side;     /**< length of each side used for the line fits, metres (1.5) */
    float apex_slack;   /**< extra distance allowed from apex to intersection, metres (0.05) */
    float min_side_len; /**< length each side must reach from the apex, metres (0.15); a
                             side of more than min_side_points points may fall short of it
                             by the square root of their ratio, to half at four times as
                             many (its direction is as well determined) */
    float max_range;    /**< no corner at an apex farther than this, metres (FLT_MAX: no
                             limit; the side tests already need min_side_points points
                             within max_side of the apex, which the beam spacing decides) */
    uint16_t min_side_points; /**< points needed on each side, apex excluded, >= 2 (3); one
                                   fewer where a side reaches the end of its run */
    uint8_t join_grazing;     /**< 1: a run goes on across a step wider than the jump radius
                                   (at most 1 m) where four consecutive returns through it
                                   lie on one line, a wall seen at grazing incidence (up to
                                   80 deg), or where such a wall starts at a corner; 2
                                   (default): also the first four returns of a wall seen
                                   nearer edge-on, when they start at a corner (or the last
                                   four, ending at one); 0: it does not */
    uint8_t corner_evidence;  /**< 1: a split the curve_ratio test rejects is still a corner
                                   when the best smooth curve misses the points by far more
                                   than the noise explains (a likelihood-ratio test, see
                                   above; default); 0: curve_ratio alone */
} bsf_lc_params_t;

/** The defaults listed beside each field of bsf_lc_params_t. */
bsf_lc_params_t bsf_lc_params_default(void);

/** @return BSF_OK; BSF_ERR_ARG for NULL; BSF_ERR_PARAM when a value is not
 *  finite or out of range (jump_a, split_min, max_side, curve_ratio, max_range > 0;
 *  jump_b, floor, apex_slack, min_side_len >= 0; split_sigmas >= 0; min_turn in (0, pi/2);
 *  min_side_points in 2..64; join_grazing 0..2; corner_evidence 0 or 1). */
BSF_NODISCARD bsf_status_t bsf_lc_params_check(const bsf_lc_params_t *p);

/** Points of a run per summary block of bsf_lc_work_t. */
#define BSF_LC_BLOCK 16

/** Summary of BSF_LC_BLOCK consecutive points of a run (bsf_lc_detect's
 *  internal bookkeeping on long runs): their bounding box and coordinate
 *  sums relative to its lower corner. */
typedef struct {
    float x0, y0, x1, y1; /**< bounding box, sensor frame, metres */
    float sx, sy;         /**< sums of the coordinates minus (x0, y0) */
    float sxx, sxy, syy;  /**< sums of their products */
    float ext2;           /**< squared diagonal of the box (slightly enlarged) */
} bsf_lc_block_t;

/** Scratch memory of bsf_lc_detect (about 24 bytes per beam; in the
 *  extractor it shares its space with the larger BID scratch). */
typedef struct {
    /** after bsf_lc_detect (BSF_OK or BSF_ERR_CAPACITY): the scan's noise
     *  variance (m^2), the squares of the runs' noise estimates that set
     *  their split tolerance (the noise across the surfaces, or the range
     *  noise where the beams are dense) averaged over their points; 0 when
     *  no run was long enough to judge */
    float noise2;
    /* Arrays in the order that measured smallest on the M4F (the byte
     * array and the run first; docs/PERFORMANCE.md, section 3). */
    uint8_t is_brk[BSF_MAX_POINTS];     /**< at each split's position in run, its last
                                             verdict (1 corner, 2 boundary) */
    uint16_t run[BSF_MAX_POINTS];       /**< beam index of each valid point of the current run */
    uint16_t judged_lo[BSF_MAX_POINTS]; /**< per split: neighbours of its last corner or
                                             boundary verdict */
    uint16_t judged_hi[BSF_MAX_POINTS];
    uint16_t brk[BSF_MAX_POINTS];     /**< split points, positions in run, ascending */
    uint16_t stack_a[BSF_MAX_POINTS]; /**< pending pieces of the split */
    uint16_t stack_b[BSF_MAX_POINTS];
    bsf_point_t rel[BSF_MAX_POINTS]; /**< run points relative to the apex being judged */
    /** summaries of the current run's points, block k holding positions
     *  k * BSF_LC_BLOCK on (long runs only) */
    bsf_lc_block_t block[(BSF_MAX_POINTS + BSF_LC_BLOCK - 1) / BSF_LC_BLOCK];
} bsf_lc_work_t;

/**
 * Detect corners. Keypoints come out ascending by beam index, with point =
 * the two-line intersection (sensor frame), orientation = the direction of
 * the corner's bisector (radians), radius = the longer side used (metres) and
 * score = the curve-to-lines residual ratio (curve to pieces for a crease;
 * higher = sharper evidence).
 * @return BSF_OK; BSF_ERR_ARG for NULL pointers (out may be NULL when out_cap
 *         is 0); BSF_ERR_PARAM for bad parameters; BSF_ERR_CAPACITY when
 *         pts->count > BSF_MAX_POINTS or more than out_cap corners were found
 *         (out holds the first out_cap, counted from where the pass starts on a
 *         full-circle scan, in beam order; *n_out the total).
 */
BSF_NODISCARD bsf_status_t bsf_lc_detect(const bsf_points_t *pts, const bsf_lc_params_t *p,
                                         bsf_lc_work_t *work, bsf_keypoint_t *out, size_t out_cap,
                                         size_t *n_out);

BSF_END_DECLS

#endif /* BSF_LC_H */
