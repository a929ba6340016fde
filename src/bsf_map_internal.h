/* SPDX-License-Identifier: MIT */
/*
 * bsf_map_internal.h - internal: what the map's fusion (bsf_map.c) and its
 * update frames (bsf_map_frame.c) share; docs/FORMAT.md section 11.
 */
#ifndef BSF_MAP_INTERNAL_H
#define BSF_MAP_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "bsf/bsf_map.h"
#include "bsf/bsf_stream.h"

#define BSF_MAP_NONE 0xFFFFu

/* bsf_map_ctrl_t.flags */
#define BSF_MAP_CF_VERTEX 1u   /* a vertex (multiplicity 2) */
#define BSF_MAP_CF_SENT 2u     /* qx, qy hold what the receiver has */
#define BSF_MAP_CF_SENT_VTX 4u /* the receiver's vertex flag of the point */

/* bsf_map_feature_t.flags */
#define BSF_MAP_FF_SENT 1u  /* its new-feature record went out */
#define BSF_MAP_FF_OP 2u    /* part of a queued merge */
#define BSF_MAP_FF_FRESH 4u /* made by the scan being fused */

/* bsf_map_op_t.flags */
#define BSF_MAP_OP_REV_A 1u
#define BSF_MAP_OP_REV_B 2u

/* Record operations (low 3 bits of a record's tag byte). */
#define BSF_MAP_REC_NEW 0u
#define BSF_MAP_REC_APPEND 1u
#define BSF_MAP_REC_MOVE 2u
#define BSF_MAP_REC_MERGE 3u
#define BSF_MAP_REC_SNAPSHOT 4u
#define BSF_MAP_REC_POSE 5u
#define BSF_MAP_REC_OPS 6u /* operations with their own byte count in the stats */
/* The robot's next feature id: every id it has given is below it. Sent with
 * the snapshots (its bytes counted with them), once per round. */
#define BSF_MAP_REC_ID_LIMIT 6u

/* Tag: bits 0-2 operation, bits 3-6 the feature's update count mod 16,
 * bit 7 the end of an append (1: head) or the reversal of a merge's first
 * feature; 0 for the other operations. */
#define BSF_MAP_TAG_UPD_SHIFT 3u
#define BSF_MAP_TAG_HIGH 0x80u

/* Largest |quantised coordinate| (as for features frames) and the largest
 * point count of one record. */
#define BSF_MAP_Q_MAX 8388607L
#define BSF_MAP_REC_MAX_POINTS 65535u

/* Quantised value of a coordinate, metres -> steps, half up. */
static inline int32_t bsf_map_quant(float v, float inv_step)
{
    return (int32_t)floorf(v * inv_step + 0.5f);
}

/* Slot of the robot feature with this id, or BSF_MAP_NONE. */
uint16_t bsf_map_slot_of_id(const bsf_map_t *m, uint32_t id);

/* 1 when a sent point differs from what the receiver holds: farther than
 * send_tol, or another vertex flag. */
static inline int bsf_map_ctrl_moved(const bsf_map_ctrl_t *c, float step, float tol2)
{
    const float ex = c->x - (float)c->qx * step;
    const float ey = c->y - (float)c->qy * step;
    return ex * ex + ey * ey > tol2 ||
           ((c->flags & BSF_MAP_CF_VERTEX) != 0u) != ((c->flags & BSF_MAP_CF_SENT_VTX) != 0u);
}

/* 1 when the feature is sent whole and no point is farther than send_tol
 * from its sent value: nothing of it waits for a frame. */
int bsf_map_chain_clean(const bsf_map_t *m, const bsf_map_feature_t *f);

/* Before points go out for the first time: of the n points that follow
 * `anchor` (along next, or prev when dir is 1), drop those strictly inside
 * the run that are unsent, not vertices, and within params.simplify_tol of
 * the chord between the points kept on either side (the last of the n is
 * kept). A straight wall then costs its ends, not a point every
 * ctrl_spacing. Returns how many of the n remain. */
uint32_t bsf_map_simplify(bsf_map_t *m, bsf_map_feature_t *f, uint16_t anchor, int dir, uint32_t n);

/* Syntax of a map payload (no receiver state): every record well formed,
 * nothing left over. Sets *seq. Returns BSF_OK or BSF_ERR_FORMAT. */
bsf_status_t bsf_map_frame_check(const uint8_t *payload, size_t len, uint32_t *seq);

/* The stream decoder's entry for a map frame: checks the payload and fills
 * out (when not NULL) as bsf_frame_t documents for map frames. */
bsf_status_t bsf_map_frame_parse(const uint8_t *payload, size_t len, bsf_frame_t *out);

#endif /* BSF_MAP_INTERNAL_H */
