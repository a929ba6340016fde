/* SPDX-License-Identifier: MIT */
/*
 * demo_scan.h - a scan of the demo office's loop, extracted: the input of the
 * map and alignment tests (compile demo_scan.c with the test, beside
 * tools/scene/bsf_scene.c or bsf_scene).
 */
#ifndef BSF_TEST_DEMO_SCAN_H
#define BSF_TEST_DEMO_SCAN_H

#include <stdint.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"

/* Scan k of an n-pose loop through scene (bsf_scene_demo_pose): 361 beams
 * over 270 degrees with 1 cm of range noise drawn from seed, extracted with
 * the default method by ex into res; the scan's true pose in *pose. Fails the
 * running Unity test on any error. */
void demo_scan_extract(const bsf_scene_t *scene, long k, long n, uint64_t seed, bsf_extractor_t *ex,
                       bsf_result_t *res, bsf_pose_t *pose);

#endif
