/* SPDX-License-Identifier: MIT */
/*
 * bsf_common.h - status codes and basic types shared by every bsf module.
 */
#ifndef BSF_COMMON_H
#define BSF_COMMON_H

#include <stddef.h>
#include <stdint.h>

#include "bsf_config.h"
#include "bsf_abi.h"
#include "bsf_version.h"

BSF_BEGIN_DECLS

/** Results that must not be ignored (a status that carries an error). */
#if defined(__GNUC__) || defined(__clang__)
#define BSF_NODISCARD __attribute__((warn_unused_result))
#else
#define BSF_NODISCARD
#endif

/**
 * Status of a bsf call: BSF_OK (0) on success, a negative value on error.
 * Functions that return a count return it as a non-negative value.
 * bsf_extract alone may also return BSF_OK_CUT (1): success, but a
 * compile-time cap cut the output (see bsf_stats_t.cut). Test `st < 0` for
 * failure; `st != BSF_OK` also catches a cut scan.
 */
typedef enum {
    BSF_OK = 0,
    BSF_OK_CUT = 1,   /**< output valid, but the features that did not fit a cap were left out */
    BSF_ERR_ARG = -1, /**< NULL pointer or an argument outside its domain */
    BSF_ERR_CAPACITY = -2,    /**< input or output larger than a compile-time cap */
    BSF_ERR_PARAM = -3,       /**< runtime parameter out of its documented range */
    BSF_ERR_NUMERIC = -4,     /**< a solve failed (matrix not positive definite after one retry) */
    BSF_ERR_DEGENERATE = -5,  /**< too few or coincident points for the requested fit */
    BSF_ERR_BUFFER = -6,      /**< caller's output buffer too small */
    BSF_ERR_FORMAT = -7,      /**< malformed frame or field */
    BSF_ERR_CRC = -8,         /**< frame check sequence mismatch */
    BSF_ERR_VERSION = -9,     /**< unsupported frame version or type */
    BSF_ERR_UNSUPPORTED = -10 /**< method or feature compiled out of this build (bsf_config.h) */
} bsf_status_t;

/** A point in the sensor (or world) plane, metres. */
typedef struct {
    float x;
    float y;
} bsf_point_t;

/**
 * A planar pose: where a frame (the laser, the robot) sits in a parent frame
 * (the world, the map). A point p given in the child frame is at
 * (x + cos(theta) p.x - sin(theta) p.y, y + sin(theta) p.x + cos(theta) p.y)
 * in the parent frame. Metres and radians, counter-clockwise.
 */
typedef struct {
    float x;     /**< metres */
    float y;     /**< metres */
    float theta; /**< radians, counter-clockwise from the parent's x axis */
} bsf_pose_t;

/**
 * An interest point (corner) found by a corner detector (LC, FALKO or BID).
 * The beam index is what segmentation and fitting use; the other fields
 * describe the keypoint for users who want it as a landmark (LC: the two
 * walls' intersection).
 */
typedef struct {
    uint16_t index;    /**< beam index of the keypoint */
    bsf_point_t point; /**< position, sensor frame, metres (sub-beam refined when enabled) */
    float orientation; /**< FALKO orientation; LC: the corner's bisector; radians (0 for BID) */
    float radius;      /**< neighbourhood radius used (LC: the longer side), metres */
    /** FALKO: raw integer score (lower = more corner-like); BID: N_q; LC: the
     *  curve-to-lines residual ratio (higher = sharper) */
    float score;
} bsf_keypoint_t;

/** Short English name of a status code ("ok", "bad argument", ...); never NULL. */
const char *bsf_status_str(bsf_status_t status);

BSF_END_DECLS

#endif /* BSF_COMMON_H */
