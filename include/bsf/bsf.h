/* SPDX-License-Identifier: MIT */
/*
 * bsf.h - umbrella header of the bsf library: include this one.
 *
 * bsf turns a 2D LIDAR scan into quadratic B-spline map features in fixed,
 * caller-owned memory (no heap, no VLAs, no recursion).
 */
#ifndef BSF_H
#define BSF_H

#include "bsf_config.h"
#include "bsf_version.h"
#include "bsf_common.h"
#include "bsf_scan.h"
#include "bsf_feature.h"
#include "bsf_metrics.h"
#include "bsf_segment.h"
#include "bsf_falko.h"
#include "bsf_lc.h"
#include "bsf_bspline.h"
#include "bsf_fit.h"
#include "bsf_bid.h"
#include "bsf_extract.h"
#include "bsf_stream.h"
#include "bsf_map.h"
#include "bsf_align.h"

#endif /* BSF_H */
