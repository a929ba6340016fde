/* SPDX-License-Identifier: MIT */
/*
 * bsf_map.h - a fused feature map on the robot and its reconstruction on the
 * receiver (docs/FORMAT.md section 11 is the normative wire format of the
 * map frames; docs/MAP.md explains the design).
 *
 * Robot: bsf_map_fuse() folds one scan's features (bsf_result_t, sensor
 * frame) into a map of world-frame clamped quadratic B-spline control-point
 * chains, given the laser's pose in the world. Repeated observations refine
 * the control points they cover, extend a feature at its ends, bridge two
 * features into one, and merge a corner seen again into the same map
 * vertex. bsf_map_encode() then writes one map-update frame with what
 * changed since the last frame: new features, appended spans, control
 * points that moved more than a tolerance from the value the receiver holds,
 * merges, removals, optional snapshots of old features (for late joiners
 * and lost frames) and an optional pose record.
 *
 * Receiver: bsf_map_rx_apply() applies the payload of a map frame (as
 * bsf_decoder_feed() delivers it, type BSF_FRAME_TYPE_MAP) to a receiver map.
 * The receiver's control points are exactly the quantised values the robot
 * sent, so its map equals the robot's "sent" copy value for value.
 *
 * Fixed memory: bsf_map_t and bsf_map_rx_t are caller-owned, sized by the
 * caps in bsf_config.h (BSF_MAP_*), no heap, bounded work per call. A map
 * vertex is stored once with its vertex flag; the accessors give it twice
 * (two consecutive flagged slots), like a scan's features, so that
 * bsf_bspline_eval() draws the same curve.
 */
#ifndef BSF_MAP_H
#define BSF_MAP_H

#include "bsf_common.h"
#include "bsf_feature.h"

BSF_BEGIN_DECLS

/* ---- Format constants ------------------------------------------------------ */

/** Smallest frame buffer bsf_map_encode() accepts, bytes. */
#define BSF_MAP_FRAME_MIN_SIZE 64u
/** Id of a robot feature whose new-feature record has not gone out yet
 *  (bsf_map_feature_ctrl, bsf_map_feature_q): ids are given at the first
 *  send, 0, 1, 2, ..., so a receiver knows every id below the largest it saw
 *  was sent. */
#define BSF_MAP_ID_UNSENT 0xFFFFFFFFu
/** Largest map-update frame on the wire (COBS body + delimiter), bytes;
 *  bsf_map_encode also keeps frames within BSF_FRAME_MAX_SIZE, what a stream
 *  decoder of the same caps holds. */
#define BSF_MAP_FRAME_MAX_SIZE 4096u

/* ---- Parameters ------------------------------------------------------------ */

/** Runtime parameters of a map (bsf_map_params_default gives the defaults). */
typedef struct {
    float match_dist;         /**< metres, (0, 1]: a scan curve sample within this distance
                                   of a map curve belongs to it (default 0.10); the
                                   largest gate when it depends on range (below) */
    float match_dist_near;    /**< metres, (0, 1]: the gate of a sample at the sensor; it
                                   grows by match_dist_per_m per metre of the sample's
                                   range, up to match_dist (default 0.03) */
    float match_dist_per_m;   /**< [0, 1]: that growth, metres per metre (default 0.01;
                                   0: a fixed gate) */
    float match_angle;        /**< radians, (0, pi/2]: largest direction difference for
                                   that (default 0.5) */
    float vertex_dist;        /**< metres, [0, match_dist]: a scan vertex this close to a map
                                   vertex merges into it (default 0.05) */
    float ctrl_spacing;       /**< metres, [0.02, 2]: spacing of control points appended to a
                                   map feature (default 0.25) */
    float send_tol;           /**< metres, [0, 1]: a control point is re-sent when its fused
                                   position is farther than this from the value the receiver
                                   holds (default 0.02) */
    float simplify_tol;       /**< metres, [0, 0.5]: before points are first sent, those
                                   within this of the chord of their kept neighbours are
                                   dropped (not vertices, not chain ends; 0: keep all;
                                   default 0.015) */
    float quant_step;         /**< metres, [BSF_QUANT_STEP_MIN, BSF_QUANT_STEP_MAX], rounded
                                   to 0.1 mm: the wire's unit of control points (default 0.005) */
    uint16_t weight_cap;      /**< 1..255: observation weight at which a control point's
                                   running mean stops growing (default 32) */
    uint32_t forget_after;    /**< fuse calls: a feature fully sent and not seen for this many
                                   calls may be forgotten when the caps fill (default 50) */
    uint16_t snapshot_budget; /**< bytes per frame for snapshot records of old features,
                                   round robin (0: no snapshots; default 0) */
    uint16_t frame_interval;  /**< 1..1000 fuse calls: bsf_map_encode sends map changes at most
                                   once per this many calls since its last map frame,
                                   so that changes share a frame's overhead (default 5;
                                   1: every call) */
} bsf_map_params_t;

/** Fill p with the defaults documented in bsf_map_params_t. p must not be NULL. */
void bsf_map_params_default(bsf_map_params_t *p);

/* ---- Robot map --------------------------------------------------------------- */

/** Counters of a map; they only grow until bsf_map_init(). */
typedef struct {
    uint32_t n_fused;          /**< scans fused */
    uint32_t n_obs;            /**< scan features fused */
    uint32_t n_new;            /**< map features created */
    uint32_t n_extended;       /**< extensions of a map feature at one end */
    uint32_t n_merged;         /**< two map features joined into one, or a never-sent copy
                                    of a map feature dropped */
    uint32_t n_refined;        /**< control point refinements (one per point per scan) */
    uint32_t n_vertex_merged;  /**< scan vertices merged into an existing map vertex */
    uint32_t n_vertex_made;    /**< map control points turned into a vertex by a scan vertex,
                                    or where a chain closes on itself at a corner */
    uint32_t n_forgotten;      /**< features dropped from RAM (the receiver keeps them) */
    uint32_t n_forgotten_ctrl; /**< their control points */
    uint32_t n_dropped_obs;    /**< scan features left out: caps full, nothing to forget */
    uint32_t n_transient;      /**< features seen in one scan only, never sent, dropped */
    uint32_t n_folds_cut;      /**< scan features whose end turned back in bearing (a hooked
                                    tail): that end cut, or the feature left out */
    uint32_t n_frames;         /**< frames written by bsf_map_encode */
    uint32_t map_bytes;        /**< bytes of those frames, pose records excluded */
    uint32_t pose_bytes;       /**< bytes of pose records (and of pose-only frames) */
    uint32_t n_records;        /**< update records written (pose records excluded) */
    uint32_t n_snapshots;      /**< snapshot records written */
    uint32_t n_moved_ctrl;     /**< control point moves sent */
    uint32_t record_bytes[6];  /**< payload bytes of the records by operation: new feature,
                                    append, move, merge, snapshot, pose (FORMAT.md section 11);
                                    the rest of map_bytes + pose_bytes is frame overhead */
} bsf_map_stats_t;

/** One control point of the robot's map (internal layout; read it through
 *  the accessors). */
typedef struct {
    float x, y;         /**< fused world position, metres */
    int32_t qx, qy;     /**< value the receiver holds, in quant steps (when sent) */
    uint16_t next;      /**< pool index of the next point of the chain, or 0xFFFF */
    uint16_t prev;      /**< pool index of the previous point, or 0xFFFF */
    uint8_t weight;     /**< observation weight, 1..weight_cap */
    uint8_t flags;      /**< vertex, sent */
    uint8_t corner_obs; /**< of a vertex: scan corners merged into it, 1..255 */
} bsf_map_ctrl_t;

/** One feature of the robot's map (internal layout). */
typedef struct {
    float min_x, min_y; /**< bounding box of the control points, metres */
    float max_x, max_y;
    uint32_t id;        /**< feature id on the wire, unique for the stream, given when its
                             new-feature record goes out (BSF_MAP_ID_UNSENT before) */
    uint32_t last_seen; /**< n_fused when last observed */
    uint16_t head;      /**< pool index of the first control point */
    uint16_t tail;      /**< pool index of the last control point */
    uint16_t n_ctrl;    /**< distinct control points (a vertex counts once) */
    uint8_t flags;      /**< sent, in a queued merge, made by this scan */
    uint8_t upd;        /**< update count mod 16, as the receiver holds it */
} bsf_map_feature_t;

/** Segments of map curves near one scan feature, searched by bsf_map_fuse. */
#define BSF_MAP_SEG_WINDOW 192

/** One span of a map curve as a chord between its knot points (internal). */
typedef struct {
    float ax, ay, bx, by; /**< chord between two points of the span (a curved span is cut in
                               several chords) */
    float u0, du;         /**< span parameter at a, and its increase to b */
    uint16_t feature;     /**< slot in features[] */
    uint16_t p[3];        /**< pool indices of the span's three control points */
    uint8_t ends;         /**< 1: the chain's first span, 2: its last span */
} bsf_map_seg_t;

/** A merge queued for the next frame (internal). */
typedef struct {
    uint32_t id_a, id_b;  /**< b is joined to the tail of a */
    uint16_t bridge;      /**< pool index of the first bridge point, or 0xFFFF */
    uint16_t n_bridge;    /**< bridge points between a's and b's points */
    uint8_t flags;        /**< a reversed, b reversed */
    uint8_t upd_a, upd_b; /**< update counts before the merge */
} bsf_map_op_t;

/** The robot's map. Fixed size (sizeof is the whole RAM cost); caller memory. */
typedef struct {
    bsf_map_params_t params;
    bsf_map_feature_t features[BSF_MAP_MAX_FEATURES];
    bsf_map_ctrl_t ctrl[BSF_MAP_MAX_CTRL];
    bsf_map_op_t ops[BSF_MAP_MAX_OPS];
    uint16_t n_ops;
    uint16_t n_features;                    /**< used slots of features[] (packed) */
    uint16_t free_ctrl;                     /**< head of the free list of ctrl[] */
    uint16_t n_free_ctrl;                   /**< points on that list */
    uint32_t next_id;                       /**< id of the next feature sent (ids: 0, 1, ... in
                                                 the order of their new-feature records) */
    uint32_t frame_seq;                     /**< sequence number of the next frame */
    uint32_t snapshot_next;                 /**< round-robin position of snapshots (feature id) */
    uint16_t snapshot_pos;                  /**< next point of a snapshot sent in parts */
    uint16_t snapshot_head;                 /**< head point of that feature at its first part */
    int32_t step_code;                      /**< quant_step in 0.1 mm */
    uint32_t last_frame_call;               /**< stats.n_fused at the last frame with map records */
    bsf_map_seg_t segs[BSF_MAP_SEG_WINDOW]; /**< work area of bsf_map_fuse */
    uint16_t n_segs;
    bsf_map_stats_t stats;
} bsf_map_t;

/**
 * Start an empty map with the given parameters (copied; NULL: defaults).
 * Returns BSF_OK, or a negative bsf_status_t on failure: BSF_ERR_ARG when map
 * is NULL, BSF_ERR_PARAM when a parameter is outside its documented range
 * or not finite. map is only written on success.
 */
BSF_NODISCARD bsf_status_t bsf_map_init(bsf_map_t *map, const bsf_map_params_t *params);

/**
 * Fuse one scan's features, given the laser's pose in the world frame.
 * Bounded work: at most BSF_MAX_SEGMENTS features, each compared with the map
 * features near it along a bounded window of control points. When the caps
 * are full, features sent and not seen for params.forget_after calls are
 * forgotten (stats.n_forgotten); if that is not enough, the scan feature is
 * left out (stats.n_dropped_obs). Returns the number of scan features fused
 * (>= 0), or a negative bsf_status_t on failure: BSF_ERR_ARG for NULL
 * pointers, a non-finite or out-of-range pose (|x|, |y| > BSF_POSE_XY_MAX,
 * |theta| > BSF_POSE_THETA_MAX), or a feature with non-finite control
 * points, points that could land farther than 8 km (or 0.9 * (2^23 - 1)
 * quant steps) from the world origin, n_ctrl < 3 or control points outside
 * scan->n_ctrl; BSF_ERR_CAPACITY when scan->n_features or n_ctrl exceed the
 * caps. On error the map is unchanged. A feature seen in one scan only and
 * never sent is dropped after 5 calls (stats.n_transient).
 */
BSF_NODISCARD int bsf_map_fuse(bsf_map_t *map, const bsf_result_t *scan, const bsf_pose_t *pose);

/**
 * Write one map-update frame (COBS(payload || CRC) || 0x00) with the changes
 * not yet sent, as many as fit in cap bytes (the rest wait for the next
 * frame), plus snapshot records within params.snapshot_budget and, when pose
 * is not NULL, a pose record. Map changes and snapshots go out only once
 * params.frame_interval fuse calls have passed since the last frame that
 * carried them (a pose record may go in any call). What is written counts as received: the
 * robot's copy of the receiver's values is updated. *out_len is 0 (and no
 * frame is written) when there is nothing to send. Returns BSF_OK, or a
 * negative bsf_status_t on failure: BSF_ERR_ARG for NULL map, buf or
 * out_len, or a non-finite or out-of-range pose; BSF_ERR_BUFFER when cap <
 * BSF_MAP_FRAME_MIN_SIZE.
 */
BSF_NODISCARD bsf_status_t bsf_map_encode(bsf_map_t *map, const bsf_pose_t *pose, uint8_t *buf,
                                          size_t cap, size_t *out_len);

/** 1 when bsf_map_encode() has map changes ready to send (not counting
 *  snapshots, a pose, new points still held back, or params.frame_interval),
 *  else 0 (also for NULL). */
int bsf_map_pending(const bsf_map_t *map);

/** Number of features in the robot's RAM; features are indexed 0 .. count - 1
 *  (indices change when features are merged or forgotten; ids do not). */
size_t bsf_map_feature_count(const bsf_map_t *map);

/**
 * Control points of robot map feature `index`, vertices given twice (two
 * consecutive flagged slots). sent = 0: fused positions; sent = 1: the values
 * the receiver holds (quantised; points not yet sent are left out). ctrl and
 * is_vertex (either may be NULL) take up to cap entries; *id (may be NULL)
 * receives the feature's id (BSF_MAP_ID_UNSENT before it is sent). Returns the number of stored
 * control points (may exceed cap: then only cap were written), or a negative bsf_status_t on
 * failure: BSF_ERR_ARG for NULL map or index out of range.
 */
BSF_NODISCARD int bsf_map_feature_ctrl(const bsf_map_t *map, size_t index, int sent,
                                       bsf_point_t *ctrl, uint8_t *is_vertex, size_t cap,
                                       uint32_t *id);

/* ---- Receiver ------------------------------------------------------------------ */

/** Receiver counters; they only grow until bsf_map_rx_init(). */
typedef struct {
    uint32_t frames;          /**< map frames applied */
    uint32_t frames_missed;   /**< gaps in the frame sequence numbers */
    uint32_t records;         /**< records applied */
    uint32_t records_skipped; /**< records not applicable: stale or unknown feature, or a
                                   feature over the receiver's caps */
    uint32_t snapshots;       /**< snapshot records applied */
    uint32_t poses;           /**< pose records received */
} bsf_map_rx_stats_t;

/** One control point of the receiver (internal layout). */
typedef struct {
    int32_t qx, qy; /**< quantised position (quant steps of the stream) */
    uint16_t next;  /**< index of the next point, or 0xFFFF */
    uint16_t prev;  /**< index of the previous point, or 0xFFFF */
    uint8_t vertex; /**< 1: a vertex (multiplicity 2) */
} bsf_map_rx_ctrl_t;

/** One receiver feature slot (internal layout), indexed by feature id. */
typedef struct {
    uint16_t head, tail; /**< point indices, 0xFFFF when empty */
    uint16_t n_ctrl;     /**< distinct points */
    uint8_t state;       /**< absent, present, stale, removed, snapshot arriving */
    uint8_t upd;         /**< update count mod 16 */
    uint32_t lost_at;    /**< bsf_map_rx_t.lost when the feature was last confirmed (or its
                              snapshot started) */
} bsf_map_rx_feature_t;

/** The receiver's map: every feature the robot ever sent, by id. */
typedef struct {
    bsf_map_rx_feature_t features[BSF_MAP_RX_MAX_FEATURES];
    bsf_map_rx_ctrl_t ctrl[BSF_MAP_RX_MAX_CTRL];
    uint16_t free_ctrl; /**< head of the free list */
    uint32_t n_free_ctrl;
    uint32_t id_limit;  /**< one past the largest id seen */
    uint32_t next_seq;  /**< expected frame sequence number */
    uint32_t lost;      /**< map frames lost so far, each gap counted up to 16 (more
                             cannot be told apart by the 4-bit update counts) */
    uint8_t seen_frame; /**< 1 once a frame was applied */
    uint8_t loss_noted; /**< 1: the link dropped a frame since the last map frame */
    uint8_t ids_known;  /**< 1: no feature id at or above id_limit can have been missed */
    uint8_t over_cap;   /**< 1: a record named an id at or above BSF_MAP_RX_MAX_FEATURES */
    float quant_step;   /**< metres, from the last frame */
    uint8_t has_pose;   /**< 1 once a pose record arrived */
    bsf_pose_t pose;    /**< last pose received */
    bsf_map_rx_stats_t stats;
} bsf_map_rx_t;

/** Empty receiver map, zero counters. rx must not be NULL. */
void bsf_map_rx_init(bsf_map_rx_t *rx);

/**
 * Apply the payload of one map frame (bsf_frame_t.payload / payload_len as
 * delivered by bsf_decoder_feed, or the body of bsf_frame_decode without its
 * CRC). The whole payload is checked first; a malformed one changes nothing.
 * A record for a feature the receiver does not hold in the state the record
 * expects (a frame before it was lost) is skipped and the feature marked
 * stale until a snapshot of it arrives; a gap in the frame sequence numbers
 * leaves every feature unconfirmed (bsf_map_rx_feature_state). Returns the number of records
 * skipped (>= 0), or a negative bsf_status_t on failure: BSF_ERR_ARG for NULL
 * pointers, BSF_ERR_VERSION when it is not a map frame, BSF_ERR_FORMAT when
 * malformed.
 */
BSF_NODISCARD int bsf_map_rx_apply(bsf_map_rx_t *rx, const uint8_t *payload, size_t len);

/**
 * Tell the receiver that the link dropped a frame (the stream decoder counted
 * a bad CRC, a malformed, oversized or unknown frame): it may have been a map
 * frame, so every feature is unconfirmed until the next map frame's sequence
 * number tells how many map frames were lost (none: the flags clear). Nothing
 * for NULL.
 */
void bsf_map_rx_note_loss(bsf_map_rx_t *rx);

/** What the receiver can say of one feature id (bsf_map_rx_feature_state). */
typedef enum {
    BSF_MAP_RX_NONE = 0,        /**< holds nothing and misses nothing: never sent, merged away */
    BSF_MAP_RX_CONFIRMED = 1,   /**< equal to the robot's sent copy as far as the stream can
                                     tell: no frame lost since it was last confirmed */
    BSF_MAP_RX_UNCONFIRMED = 2, /**< map frames were lost since it was last confirmed: it may
                                     have missed records (or been merged away on the robot) */
    BSF_MAP_RX_STALE = 3,       /**< a record of it could not apply, or its snapshot is still
                                     arriving in parts: it differs from the robot's */
    BSF_MAP_RX_MISSING = 4      /**< sent by the robot (or it may have been: ids past the
                                     largest seen after a loss) but never received: no points */
} bsf_map_rx_state_t;

/**
 * State of receiver feature `id` (a bsf_map_rx_state_t, >= 0). After a loss
 * every feature held is unconfirmed; a complete snapshot confirms it, and so
 * does a record that applies when at most 3 map frames were lost since the
 * feature was last confirmed (a frame advances a feature's 4-bit update
 * count by at most 4, docs/FORMAT.md section 11.3). Ids are given in send
 * order, so an id below bsf_map_rx_id_limit() never received is missing; so
 * is any id at or above it after a loss, until a new-feature record or an
 * id-limit record (sent with each snapshot round) shows which ids exist.
 * Returns BSF_ERR_ARG for NULL rx.
 */
BSF_NODISCARD int bsf_map_rx_feature_state(const bsf_map_rx_t *rx, uint32_t id);

/** One past the largest feature id the receiver has seen (ids are 0 .. this - 1;
 *  some of them may be absent, merged away or removed). 0 for NULL. */
uint32_t bsf_map_rx_id_limit(const bsf_map_rx_t *rx);

/**
 * Control points of receiver feature `id`, in metres (quantised values times
 * the stream's step), vertices given twice (two consecutive flagged slots);
 * ctrl and is_vertex (either may be NULL) take up to cap entries; *stale (may
 * be NULL) is 1 when the receiver cannot vouch for the feature: its state
 * (bsf_map_rx_feature_state) is unconfirmed, stale or missing (a missing
 * feature holds no points but is reported). Returns the number of stored control points (may
 * exceed cap), 0 when the id holds no feature (never sent, merged into
 * another, removed, or missed), or a negative bsf_status_t on failure:
 * BSF_ERR_ARG for NULL rx.
 */
BSF_NODISCARD int bsf_map_rx_feature_ctrl(const bsf_map_rx_t *rx, uint32_t id, bsf_point_t *ctrl,
                                          uint8_t *is_vertex, size_t cap, uint8_t *stale);

/**
 * Quantised control points (quant steps) of receiver feature `id`, each
 * point once, with its vertex flag: q takes 2 values (x, y) per point, up to
 * cap points. For exact comparison with the robot's sent copy. Returns the
 * number of distinct points, 0 when the id holds no feature, or a negative
 * bsf_status_t on failure: BSF_ERR_ARG for NULL rx.
 */
BSF_NODISCARD int bsf_map_rx_feature_q(const bsf_map_rx_t *rx, uint32_t id, int32_t *q,
                                       uint8_t *is_vertex, size_t cap);

/**
 * Quantised control points (quant steps) of robot feature `index` as sent,
 * in the same form as bsf_map_rx_feature_q(), and its id in *id (may be
 * NULL; BSF_MAP_ID_UNSENT before it is sent). Returns the number of distinct points, or a negative
 * bsf_status_t on failure: BSF_ERR_ARG for NULL map or index out of range.
 */
BSF_NODISCARD int bsf_map_feature_q(const bsf_map_t *map, size_t index, int32_t *q,
                                    uint8_t *is_vertex, size_t cap, uint32_t *id);

BSF_END_DECLS

#endif /* BSF_MAP_H */
