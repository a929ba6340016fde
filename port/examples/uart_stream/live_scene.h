/* SPDX-License-Identifier: MIT */
/*
 * live_scene.h - the scans the uart_stream example sends: a robot driving
 * through the built-in synthetic office (tools/scene/bsf_scene.h), each scan
 * extracted and ready to encode. Portable C (no heap, no I/O), compiled for
 * the Cortex-M4F firmware and for the host program that writes the bytes the
 * firmware must send, so a test can compare the two byte for byte.
 */
#ifndef LIVE_SCENE_H
#define LIVE_SCENE_H

#include "bsf/bsf.h"
#include "bsf/bsf_stream.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Scans in one run (one lap of the office); a build may override it. */
#ifndef LIVE_SCENE_SCANS
#define LIVE_SCENE_SCANS 60
#endif

/** Beams per scan (270 degrees field of view, like `bsf demo`). */
#define LIVE_SCENE_BEAMS 361u

/** Milliseconds between scans (the frames' time stamps step by this). */
#define LIVE_SCENE_PERIOD_MS 100u

/**
 * Start a run: build the office and seed the noise. Returns BSF_OK or the
 * extractor's initialisation error. Not reentrant (one run at a time: its
 * buffers are static).
 */
bsf_status_t live_scene_start(void);

/**
 * Simulate and extract scan k (call with k = 0, 1, 2, ... in order: the
 * noise generator runs on from scan to scan), and fill info with its
 * sequence number k, its time stamp k * LIVE_SCENE_PERIOD_MS and the true
 * sensor pose. No extraction time is measured, so the frames are the same
 * bytes on every platform. Returns BSF_OK or the simulation/extraction error.
 */
bsf_status_t live_scene_scan(uint32_t k, bsf_frame_info_t *info, const bsf_result_t **result);

/** A metadata frame goes before scan 0 and before every LIVE_SCENE_META_EVERY-th
 *  scan, so a receiver that joins the link late learns what it hears. */
#define LIVE_SCENE_META_EVERY 20u

/**
 * What the run sends (after live_scene_start()): library version and caps,
 * method and PDM target, the LIDAR's geometry and range limits, the default
 * quantisation step, source "uart_stream: demo office", no time origin.
 */
void live_scene_metadata(bsf_metadata_t *m);

/**
 * The whole run through sink, exactly as the firmware sends it: a lone 0x00
 * (so a receiver that heard line noise drops it rather than the first
 * frame), then for each scan k a metadata frame when k is a multiple of
 * LIVE_SCENE_META_EVERY, and the scan's features frame. The firmware and the
 * host program that writes the expected bytes both call this, so the two
 * cannot drift apart. Stops at the first error.
 *
 * @param failed_scan  receives the scan index at which an error occurred
 *                     (LIVE_SCENE_SCANS when none); may be NULL.
 * @return BSF_OK, or the first error of start, extraction or encoding
 *         (BSF_ERR_BUFFER when sink refused bytes).
 */
bsf_status_t live_scene_send(bsf_sink_fn sink, void *ctx, uint32_t *failed_scan);

#ifdef __cplusplus
}
#endif

#endif /* LIVE_SCENE_H */
