/* SPDX-License-Identifier: MIT */
/*
 * det_core.h - the host/target determinism workload: the demo office's scans
 * (tools/bsf_scene, double precision) extracted with two methods and encoded
 * into frames; FNV-1a hashes of the ranges and of every frame byte.
 */
#ifndef BSF_DET_CORE_H
#define BSF_DET_CORE_H

#include <stddef.h>
#include <stdint.h>

#include "bsf/bsf.h"

/** Scans of the demo loop used (every 60 / DET_SCANS-th pose of `bsf demo`). */
#define DET_SCANS 6u
/** Beams per scan, as in `bsf demo`. */
#define DET_BEAMS 361u
/** Methods run on each scan: FALKO-SVED-PDM and RPOS-LSBA. */
#define DET_METHODS 2u

typedef struct {
    uint32_t ranges_hash;  /**< FNV-1a of the float bits of every simulated range */
    uint32_t stream_hash;  /**< FNV-1a of every encoded frame byte, in order */
    uint32_t stream_bytes; /**< total frame bytes */
    uint32_t n_features;   /**< features over all frames */
    uint32_t n_ctrl;       /**< control points over all frames */
} det_summary_t;

/** FNV-1a, 32 bit, continued from h (start with DET_FNV_INIT). */
#define DET_FNV_INIT 2166136261u
uint32_t det_fnv1a(uint32_t h, const uint8_t *p, size_t n);

/** Simulate scan k (0..DET_SCANS-1) of the demo loop into ranges[DET_BEAMS]. */
bsf_status_t det_simulate(unsigned k, float *ranges, bsf_scan_t *scan);

/**
 * Run the workload. ranges_in: DET_SCANS * DET_BEAMS ranges to use instead
 * of simulating (NULL: simulate here). frame_cb (may be NULL) sees each
 * frame's bytes.
 * @return BSF_OK or the first failing status.
 */
bsf_status_t det_run(const float *ranges_in, det_summary_t *out,
                     void (*frame_cb)(void *ctx, const uint8_t *frame, size_t len), void *ctx);

#endif /* BSF_DET_CORE_H */
