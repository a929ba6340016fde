/* SPDX-License-Identifier: MIT */
/*
 * bsf_host_caps.h - the caps of every host build of bsf: the tool `bsf`
 * (bsf_big, with its benchmarks and tests) and the Python extension
 * (tools/python/setup.py reads this file). One set, so that any frame one of
 * them writes the other reads, and a scan one accepts the other accepts.
 *
 * Used as the library's BSF_CONFIG_HEADER (include/bsf/bsf_config.h); a cap
 * already defined on the command line wins. Room for full-circle LIDARs of
 * up to 4096 beams and 1081-beam scanners in clutter: keypoints, segments
 * and control points per scan about 4x the library's 1081-beam defaults.
 * The cap per feature keeps its default (32, PDM's default max_ctrl), so a
 * scan that fits the default caps gives the same features as the firmware
 * build. Plain decimal numbers only (bsf_abi.h puts them in symbol names).
 */
#ifndef BSF_HOST_CAPS_H
#define BSF_HOST_CAPS_H

#ifndef BSF_MAX_POINTS
#define BSF_MAX_POINTS 4096
#endif
#ifndef BSF_MAX_KEYPOINTS
#define BSF_MAX_KEYPOINTS 256
#endif
#ifndef BSF_MAX_SEGMENTS
#define BSF_MAX_SEGMENTS 512
#endif
#ifndef BSF_MAX_CTRL_POINTS
#define BSF_MAX_CTRL_POINTS 2048
#endif

#endif /* BSF_HOST_CAPS_H */
