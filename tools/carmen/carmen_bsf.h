/* SPDX-License-Identifier: MIT */
/*
 * carmen_bsf.h - CARMEN records as bsf scans: the host tool's range policy,
 * in the CARMEN reader's library so that the tests and fuzz_carmen check
 * exactly what the tool gives the extractor.
 */
#ifndef BSF_TOOLS_CARMEN_BSF_H
#define BSF_TOOLS_CARMEN_BSF_H

#include "bsf/bsf.h"
#include "carmen.h"

/** range_max of a record: opt when > 0, else the log's declared maximum below no-return codes. */
float scan_range_max(const carmen_scan_t *s, double opt);

/** A CARMEN record as a bsf scan (ranges point into the record). */
bsf_scan_t scan_of_record(const carmen_scan_t *s, double range_max_opt);

#endif /* BSF_TOOLS_CARMEN_BSF_H */
