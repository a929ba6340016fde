/* SPDX-License-Identifier: MIT */
/*
 * bsf_extract.h - the whole pipeline in one call: scan -> points -> corners
 * -> segments -> B-spline features, for each of the four methods (bsf's
 * default LC-SVED-PDM and the paper's three; docs/DESIGN.md, Methods).
 *
 *   static bsf_extractor_t ex;               // all working memory, no heap
 *   static bsf_result_t res;
 *   bsf_params_t p = bsf_params_default(BSF_METHOD_DEFAULT);
 *   if (bsf_extractor_init(&ex, &p) != BSF_OK) { ... }
 *   if (bsf_extract(&ex, &scan, &res) >= 0) { ... res.features ... }  // BSF_OK or BSF_OK_CUT
 *
 * Each stage is also callable on its own (bsf_scan.h, bsf_lc.h,
 * bsf_falko.h, bsf_bid.h, bsf_segment.h, bsf_fit.h).
 */
#ifndef BSF_EXTRACT_H
#define BSF_EXTRACT_H

#include "bsf_common.h"
#include "bsf_scan.h"
#include "bsf_feature.h"
#include "bsf_falko.h"
#include "bsf_lc.h"
#include "bsf_bid.h"
#include "bsf_segment.h"
#include "bsf_fit.h"

BSF_BEGIN_DECLS

/**
 * Extraction methods: the three of the paper's Table 1, and bsf's default.
 * FALKO-SVED-PDM is the paper's proposal with FALKOLib-identical keypoints
 * (the paper-faithful configuration). LC-SVED-PDM replaces FALKO by LC, bsf's
 * line-corner detector (bsf_lc.h), and holds each PDM vertex at LC's two-line
 * intersection: it finds the corners FALKO misses (FALKO's neighbourhood and
 * its per-scan relative score hide most corners beyond 3 m and lone corners)
 * and places them where the walls meet (docs/DESIGN.md, Why LC is the default;
 * docs/GROUND_TRUTH.md has the numbers). With SVED's reject_mixed on, LC
 * runs without the mixed pixels SVED finds off the line of a long run
 * (bsf_segment_sved_labelled; at most BSF_MAX_KEYPOINTS per scan), so that
 * none ends a corner's side off its wall.
 */
typedef enum {
    BSF_METHOD_FALKO_SVED_PDM = 0, /**< the paper's proposal: FALKO corners, SVED, PDM */
    BSF_METHOD_BID_SVED_PDM = 1,   /**< baseline: B-spline interest points (slow), SVED, PDM */
    BSF_METHOD_RPOS_LSBA = 2,   /**< baseline: RPOS segments, 4-point least squares, no corners */
    BSF_METHOD_LC_SVED_PDM = 3, /**< default: LC line corners, SVED, PDM with anchored vertices */
    BSF_METHOD_COUNT = 4
} bsf_method_t;

/** The method a user gets unless they choose: LC-SVED-PDM. */
#define BSF_METHOD_DEFAULT BSF_METHOD_LC_SVED_PDM

/**
 * A clock for the time metric: returns a free-running 32-bit tick count
 * (only differences are used, so it may wrap). NULL: no timing, no cost.
 * Ready-made hooks are in port/bsf_port_clock.h.
 */
typedef uint32_t (*bsf_clock_fn)(void *user);

/** Runtime parameters; start from bsf_params_default(method). */
typedef struct {
    bsf_method_t method;
    bsf_falko_params_t falko; /**< used by FALKO-SVED-PDM */
    bsf_lc_params_t lc;       /**< used by LC-SVED-PDM */
    bsf_bid_params_t bid;     /**< used by BID-SVED-PDM */
    /** Used by the three SVED methods. With LC-SVED-PDM and sved.reject_mixed
     *  on, the extractor also gives a wall back the returns an occluder cut
     *  off: a run of 2 to sved.min_segment_points - 1 returns that SVED
     *  wasted just past a segment's end, beyond one or more returns in front
     *  of the segment's line (a leg, a post), joins the segment when all of
     *  it lies on the line of the segment's last 5-8 returns (straight within
     *  the scan's noise) within 4 standard errors. The run must start within
     *  sved.radius_max of the end (so radius_max 0, no cap in SVED, turns
     *  this off) and end within sved.max_gap_beams beams; it needs the
     *  mixed-pixel marks, which share the segments' storage and are kept
     *  only when that array (BSF_MAX_SEGMENTS of bsf_segment_t) holds a
     *  bit per beam, as with every default cap. */
    bsf_sved_params_t sved;
    bsf_rpos_params_t rpos;           /**< used by RPOS-LSBA */
    bsf_pdm_params_t pdm;             /**< used by the three PDM methods */
    bsf_no_return_params_t no_return; /**< no-return codes, every method (bsf_scan.h) */
    /** Cut policy of the three PDM methods (docs/DESIGN.md, "Cut policy"): a
     *  feature with a point farther than this from its curve is split just
     *  after its farthest point, and each side (at least 3 points) is fitted
     *  on its own, at most 7 splits deep; no point leaves
     *  the features. Metres, >= 0; 0 turns it off (bsf_params_paper).
     *  Default 0.25. */
    float split_dist;
    /** LC-SVED-PDM: 1 (default) leaves a segment's end return out of its
     *  feature when the straight run of 8 returns beside it misses it, on
     *  the sensor's side, by more than split_sigmas standard errors (the
     *  run's own scatter) and lc.split_min, turning by lc.min_turn or more:
     *  a single return on the next wall past a concave corner seen at
     *  grazing incidence, or on an occluder. A curve bent to reach it swings
     *  through free space. Segments of at least 7 returns (the run is then
     *  shorter, down to 5, and the noise at least the scan's); where LC has
     *  a corner within the run, the returns between the end and the corner
     *  (a corner 6-9 returns in; 4-5 for a floating end). An end whose
     *  neighbouring beam past it reads nearer the sensor (a floating return
     *  at a depth jump, likely a mixed pixel) is judged from a run of 3 or
     *  4 returns. The return counts as wasted in Γ.
     *  A segment of 5 to 8 returns without a corner (one of 7 or 8 through
     *  its views of 5 or 6 returns that leave 1-3 out at one end) whose last
     *  two returns at one end lie off the line of the others, on diverging
     *  lines turning by lc.min_turn or more, after a step more than twice
     *  the step before it or with their own step under half of it, gets a
     *  vertex where the two lines cross between the two beams, near the
     *  returns (no return is left out).
     *  0 keeps every return (bsf_params_paper). */
    uint8_t trim_tails;
    /** The three PDM methods: a bound on the fit's work per scan, for
     *  firmware that must keep up with a dense LIDAR in its worst scan
     *  (docs/PERFORMANCE.md, "A bound on the fit's work"). The scan spends
     *  about this many footpoint passes per point it fits, on average, on
     *  refinement near the target: each fit may use the passes still left
     *  per point still to fit (bsf_pdm_params_t.max_passes, at least one;
     *  what a fit leaves unused goes to the later ones). A fragment still
     *  more than twice pdm.target_rms from its points grows past it. A fit
     *  stopped early keeps fewer control points and a larger E_curve;
     *  stats.n_fit_visits counts the work. With fit_bin_length, a binned
     *  fit's passes visit bins but its share is per return, so what it
     *  leaves goes to the fits after it (the scan's total still holds).
     *  0 (default): no bound. */
    uint8_t fit_passes;
    /** The three PDM methods: on dense scans, PDM may fit the means of bins
     *  of consecutive returns instead of the returns themselves, for speed
     *  (docs/PERFORMANCE.md, "Fitting bin means"). Between two pinned
     *  returns of a fit (its first and last, and each vertex, which stay
     *  single), the returns are cut into equal bins of k, k the most returns
     *  whose share of the run's chord is at most this length, and at most a
     *  128th of the run (so runs under 256 returns never bin: a bin must not
     *  take room the curve needs to bend). E_curve and the cut policy's
     *  farthest point are over the returns, each return's distance taken
     *  along the curve's normal at its bin's footpoint; stats.n_fit_visits
     *  counts bin visits. PDM's refinement tests (target_rms, the windowed
     *  mean of bias_window bins) see bin means: their noise share shrinks and
     *  each window spans k times more wall, so refinement stops earlier
     *  (measured: 3 cm bins make the 3200-beam office's fit 7x cheaper, with
     *  curve p99 worse by 0.02 to 0.9 cm on most of the ground-truth
     *  benchmark's 1081- and 3200-beam rows). Metres, 0..1; 0 (the default
     *  for every method): every return is fitted. A build with
     *  BSF_CONFIG_FIT_BINS 0 (bsf_config.h) refuses a non-zero value with
     *  BSF_ERR_UNSUPPORTED. */
    float fit_bin_length;
    bsf_clock_fn clock; /**< optional, see bsf_clock_fn */
    void *clock_user;   /**< passed to clock */
    uint32_t clock_hz;  /**< ticks per second of clock (> 0 when clock is set) */
} bsf_params_t;

/** Defaults for a method: what a user gets (segmentation extensions on,
 *  see bsf_sved_params_default, and no-return detection on). PDM takes
 *  bsf_pdm_params_default (30 mm target plus the systematic-deviation test)
 *  except FALKO-SVED-PDM and BID-SVED-PDM, which refine on RMS alone to
 *  25 mm (bias_window 0): their keypoints miss most corners, which the test
 *  would round with control points. LC-SVED-PDM segments with
 *  join_grazing 2 (bsf_sved_params_t): LC puts the vertex where a wall seen
 *  nearly edge-on starts at a corner.
 *  An unknown method gives the FALKO-SVED-PDM defaults with that method
 *  stored, which bsf_extractor_init then refuses. In a build without some
 *  methods (BSF_CONFIG_METHODS), their own parameter structs (falko, bid,
 *  lc, rpos) are left zero: those methods are refused, and a caller that
 *  uses a detector directly takes its defaults from its own
 *  bsf_*_params_default. */
bsf_params_t bsf_params_default(bsf_method_t method);

/** The paper-faithful configuration of a method: as bsf_params_default but
 *  with the paper's SVED rule (bsf_sved_params_paper), no no-return
 *  detection beyond range_max, and PDM's refinement on RMS alone with the
 *  first release's 15 mm target (the paper states none; bias_window 0).
 *  `bsf table1 --paper` uses it. */
bsf_params_t bsf_params_paper(bsf_method_t method);

/** Check every parameter the method uses. @return BSF_OK, BSF_ERR_ARG for
 *  NULL, BSF_ERR_PARAM for an unknown method or a value out of range,
 *  BSF_ERR_UNSUPPORTED for a method left out of this build
 *  (BSF_CONFIG_METHODS, bsf_config.h) or a non-zero fit_bin_length in a
 *  build without the fit on bin means (BSF_CONFIG_FIT_BINS). */
BSF_NODISCARD bsf_status_t bsf_params_check(const bsf_params_t *params);

/**
 * All working memory of the pipeline, owned by the caller. Statically
 * allocatable; its size follows from the caps in bsf_config.h (see the
 * README's table). Fields are private: use the functions.
 */
typedef struct {
    bsf_params_t params;
    /* The scalars before the arrays: Thumb-2 loads a field within 4 KB of a
     * pointer (1 KB for a float) in one instruction, one farther away takes
     * an address computation first (docs/PERFORMANCE.md, section 3); the
     * small arrays next, then the stages' scratch, the points (14 KB)
     * last. */
    size_t n_keypoints;
    size_t n_segments;
    float noise2;   /**< the scan's noise variance by LC (bsf_lc_work_t), for the tail rule */
    uint32_t ready; /**< set by a successful init */
    bsf_segment_t segments[BSF_MAX_SEGMENTS];
    bsf_keypoint_t keypoints[BSF_MAX_KEYPOINTS];
    uint16_t interest[BSF_MAX_KEYPOINTS]; /**< keypoint beam indices, ascending */
    /** Stage scratch. The corner stage runs before segmentation, and
     *  segmentation before fitting, so their working memory overlaps: the
     *  corner detectors' work, or the per-beam segment labels (written by
     *  segmentation, read by fitting, valid after bsf_extract until the next
     *  call) beside either every kept segment before the cap or the fitting
     *  stage's work. */
    union {
        bsf_falko_work_t falko;
        bsf_lc_work_t lc;
        bsf_bid_work_t bid;
        struct {
            /** per beam: first beam of its segment, or BSF_SEG_NONE */
            uint16_t label[BSF_MAX_POINTS];
            union {
                bsf_segment_t all[BSF_MAX_POINTS]; /**< every kept segment, before the cap */
                struct {
                    uint16_t vertex_pos[BSF_MAX_KEYPOINTS];       /**< vertices, in seg_points */
                    bsf_point_t vertex_anchor[BSF_MAX_KEYPOINTS]; /**< their anchors (LC) */
                    bsf_point_t seg_points[BSF_MAX_POINTS];       /**< the segment's valid points */
                    bsf_pdm_work_t pdm;
                    bsf_pdm_params_t pdm_params; /**< the fit's: params.pdm, max_passes set */
                    bsf_pdm_info_t pdm_info;     /**< the fit's outcome */
                    uint32_t passes_left; /**< point visits the scan may still spend (fit_passes) */
                    uint32_t points_left; /**< points of the segments still to fit */
                    uint16_t bin_pos[BSF_PDM_MAX_VERTICES]; /**< vertices' bins (fit_bin_length) */
                    uint16_t bin_worst_at; /**< a binned fit's farthest return, or 0xFFFF */
                    float bin_worst;       /**< its squared distance from the curve */
                } fit;
            } use;
        } seg;
    } scratch;
    bsf_points_t points;
} bsf_extractor_t;

/**
 * Validate params and prepare ex (copies params; no other work).
 * @return BSF_OK; BSF_ERR_ARG for NULL; BSF_ERR_PARAM for bad params;
 *         BSF_ERR_UNSUPPORTED for a method left out of this build
 *         (BSF_CONFIG_METHODS). On error ex is marked not ready, and
 *         bsf_extract refuses it.
 */
BSF_NODISCARD bsf_status_t bsf_extractor_init(bsf_extractor_t *ex, const bsf_params_t *params);

/**
 * Extract one scan's features into *result (overwritten whole).
 * A segment whose fit fails numerically is dropped and counted in
 * result->stats.n_unfitted (its points are wasted), never output with NaN.
 *
 * Caps past the input (bsf_config.h) degrade gracefully and visibly: what
 * fits is kept, BSF_OK_CUT is returned and result->stats says what was cut.
 *  - More keypoints than BSF_MAX_KEYPOINTS: LC keeps the first ones in beam
 *    order (it has no strength to rank by); FALKO and BID keep the
 *    strongest (FALKO: highest strength; BID: lowest N_q; ties to the lower
 *    beam). A dropped keypoint loses a vertex, not points. stats.n_keypoints
 *    counts the kept ones, stats.n_cut_keypoints the others
 *    (BSF_CUT_KEYPOINTS; docs/DESIGN.md, Cut policy).
 *  - More kept segments than BSF_MAX_SEGMENTS: the segments covering the most
 *    points are kept (ties: the earlier in beam order), in beam order
 *    (BSF_CUT_SEGMENTS).
 *  - Control points beyond BSF_MAX_CTRL_POINTS: the segments are fitted
 *    again from the one covering the most points down (ties: beam order);
 *    a segment whose feature does not fit the room left is cut, a smaller
 *    one after it may still fit. Features then come out sorted by first
 *    beam (one wrapping through a full-circle seam last), with their
 *    control points laid out in that order (BSF_CUT_CTRL).
 * A cut segment counts in stats.n_cut_segments and its points in
 * stats.n_cut_points: they are part of N but of no feature, so they are
 * wasted in retrievability. A cut result never exceeds any cap, so it always
 * encodes within BSF_FRAME_MAX_SIZE. The cut path costs up to a second fit
 * of the scan (control-point cut) and a few passes over the segments.
 *
 * @return BSF_OK; BSF_OK_CUT (> 0) as above; BSF_ERR_ARG for NULL or an
 *         extractor not initialised, or a scan refused by bsf_scan_to_points;
 *         BSF_ERR_CAPACITY when the scan has more than BSF_MAX_POINTS beams
 *         (input is never truncated) or FALKO's raw score overflows. On error
 *         result holds no features (n_features 0) and zero stats.
 */
BSF_NODISCARD bsf_status_t bsf_extract(bsf_extractor_t *ex, const bsf_scan_t *scan,
                                       bsf_result_t *result);

/** Name of a method as the tool spells it ("falko-sved-pdm", ...), or NULL. */
const char *bsf_method_name(bsf_method_t method);

/** Method from its name; returns BSF_METHOD_COUNT for an unknown name. */
bsf_method_t bsf_method_from_name(const char *name);

BSF_END_DECLS

#endif /* BSF_EXTRACT_H */
