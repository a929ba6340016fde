/* SPDX-License-Identifier: MIT */
/*
 * bsf_scan.h - the scan model: ranges plus geometry in, points plus a
 * validity mask out.
 */
#ifndef BSF_SCAN_H
#define BSF_SCAN_H

#include "bsf_common.h"

BSF_BEGIN_DECLS

/**
 * One 2D LIDAR scan as the driver delivers it. Beam i points at
 * angle_min + i * angle_increment (radians, counter-clockwise, 0 ahead).
 * Give the increment itself; never derive it from a field of view.
 * The library only reads `ranges`; the caller owns it.
 */
typedef struct {
    const float *ranges;   /**< count readings, metres */
    size_t count;          /**< number of beams, 1..BSF_MAX_POINTS */
    float angle_min;       /**< angle of beam 0, radians */
    float angle_increment; /**< angle between beams, radians, finite and non-zero */
    float range_min;       /**< smallest valid reading, metres (>= 0) */
    float range_max;       /**< readings >= range_max are invalid: set it below no-return codes */
} bsf_scan_t;

/**
 * A scan converted to Cartesian points in the sensor frame. Invalid beams
 * keep their index (beam indices stay meaningful) with valid[i] == 0,
 * point (0,0) and range 0; they are never used as points.
 */
typedef struct {
    bsf_point_t pt[BSF_MAX_POINTS]; /**< beam i's point, metres */
    float range[BSF_MAX_POINTS];    /**< beam i's range, metres (0 when invalid) */
    uint8_t valid[BSF_MAX_POINTS];  /**< 1 when beam i is a valid reading */
    size_t count;                   /**< number of beams (index space) */
    size_t n_valid;                 /**< N: number of valid readings */
    float angle_min;                /**< copied from the scan */
    float angle_increment;          /**< copied from the scan */
} bsf_points_t;

/**
 * Is one reading valid? True when r is finite and range_min <= r < range_max.
 * NaN, +-inf, negative and zero readings are never valid (zero only passes
 * when range_min is 0, so it is rejected explicitly).
 */
int bsf_range_is_valid(float r, float range_min, float range_max);

/**
 * Convert a scan to points.
 *
 * @return BSF_OK; BSF_ERR_ARG when scan, scan->ranges (with count > 0) or out
 *         is NULL, or the geometry is not finite, or angle_increment is 0, or
 *         range_min < 0, or range_max <= range_min; BSF_ERR_CAPACITY when
 *         count > BSF_MAX_POINTS. On error `out` is left untouched.
 *         A scan with count == 0 or with no valid reading is not an error:
 *         it gives n_valid == 0.
 */
BSF_NODISCARD bsf_status_t bsf_scan_to_points(const bsf_scan_t *scan, bsf_points_t *out);

/**
 * Do the beams cover the whole circle? True when |angle_increment| * count
 * is within one |angle_increment| of 2 pi: the first and the last beam are
 * then neighbours, and the segmentation and FALKO treat the beams as a ring.
 */
int bsf_points_full_circle(const bsf_points_t *pts);

/** Parameters of bsf_points_reject_no_return. */
typedef struct {
    /** A reading exactly equal to this (after float conversion) is a
     *  no-return code, metres; 0 = none given. For a sensor whose driver
     *  codes "no return" as a fixed value (for example 50.0 or 81.91) but
     *  does not declare it as its maximum range. */
    float code;
    /** Auto-detection: the scan's largest reading is a no-return code when
     *  at least this many consecutive beams hold it bit for bit and the
     *  valid beams beside that run (at least one) read more than 10 % less.
     *  0 = off. Default 5, the shortest kept segment of
     *  the default SVED: a shorter run of far readings cannot make a
     *  feature of its own, and being 10 % away from its neighbours it joins
     *  none of theirs (the radius is capped at 1 m). A genuine surface
     *  rarely does this: a corner's peak is one beam, and a surface seen
     *  head-on near the scan's maximum changes by centimetres beside its
     *  run. A scan of nothing but equal readings (a round room from its
     *  centre, or nothing but sky) is left alone. Measured on the four paper logs (their codes lie
     * above the declared maximum, so every reading this rule takes is a genuine one): 0 readings
     * taken; 117 with runs of 3 and no 10 % condition, 23 with runs of 3, 4 with runs of 4. */
    uint16_t min_run;
} bsf_no_return_params_t;

/** Defaults: code 0 (none), min_run 5. */
bsf_no_return_params_t bsf_no_return_params_default(void);

/**
 * Invalidate no-return codes in pts (after bsf_scan_to_points): every valid
 * reading equal to p->code, and, when p->min_run > 0, every reading equal to
 * the scan's largest valid reading if a run of min_run or more consecutive
 * beams holds exactly that value and stands more than 10 % above its valid
 * neighbours, of which it has at least one (see bsf_no_return_params_t). Invalidated beams get
 * valid 0, point (0,0), range 0 and leave n_valid.
 * @param n_rejected  readings invalidated (may be NULL)
 * @return BSF_OK; BSF_ERR_ARG for NULL pts or p; BSF_ERR_PARAM for a code
 *         that is negative or not finite.
 */
BSF_NODISCARD bsf_status_t bsf_points_reject_no_return(bsf_points_t *pts,
                                                       const bsf_no_return_params_t *p,
                                                       size_t *n_rejected);

/** Candidate values bsf_no_return_learn keeps count of. */
#define BSF_NO_RETURN_CANDIDATES 4u
/** Scans of evidence after which bsf_no_return_learn takes a value as a code. */
#define BSF_NO_RETURN_LEARN_SCANS 20u
/** Every this many scans bsf_no_return_learn halves all evidence. */
#define BSF_NO_RETURN_AGE_SCANS 64u

/**
 * State of bsf_no_return_learn across the scans of one sensor. Caller-owned,
 * fixed size; start it with bsf_no_return_learner_init. Fields are private.
 */
typedef struct {
    float value[BSF_NO_RETURN_CANDIDATES];    /**< candidate codes (0: empty slot) */
    uint32_t count[BSF_NO_RETURN_CANDIDATES]; /**< scans of evidence for each */
    uint16_t beam[BSF_NO_RETURN_CANDIDATES];  /**< where each was last seen isolated */
    uint32_t n_scans;                         /**< scans since evidence was last halved */
    float code;                               /**< the learned code; 0 until one is found */
} bsf_no_return_learner_t;

/** Start (or restart) a learner: no candidates, no code. Does nothing for NULL. */
void bsf_no_return_learner_init(bsf_no_return_learner_t *l);

/**
 * Learn a no-return code that is not in runs (a driver writing "no return" as
 * a fixed value, for example 50.0, on lone beams as well as in runs) from a
 * stream of scans: a scan is evidence for its largest valid reading when some
 * run of beams holding exactly that value (one beam is enough) reads more than
 * 10 % above its valid neighbours on both sides, as in
 * bsf_points_reject_no_return, and it stands on other beams than the last
 * time (a sensor standing still sees a far surface through a gap on the
 * same beam scan after scan). Evidence is halved every
 * BSF_NO_RETURN_AGE_SCANS scans, and a value becomes the code once it has
 * BSF_NO_RETURN_LEARN_SCANS scans of evidence: it must recur in about one scan
 * in six or more (a code written in half the scans is found within about 40),
 * and a genuine surface far away does not repeat bit for bit as an isolated
 * maximum that often while the sensor moves. BSF_NO_RETURN_CANDIDATES values
 * are counted at once; a new one takes the slot of the least evidence. Once found, the
 * code stays. Put it in bsf_no_return_params_t.code (and re-initialise the
 * extractor) to drop it from later scans.
 * @param code_out  the learned code after this scan, 0 when none (may be NULL)
 * @return BSF_OK; BSF_ERR_ARG for NULL l or scan, or ranges NULL with count > 0;
 *         BSF_ERR_CAPACITY when count exceeds BSF_MAX_POINTS.
 */
BSF_NODISCARD bsf_status_t bsf_no_return_learn(bsf_no_return_learner_t *l, const bsf_scan_t *scan,
                                               float *code_out);

BSF_END_DECLS

#endif /* BSF_SCAN_H */
