/* SPDX-License-Identifier: MIT */
/* CARMEN records as bsf scans (moved from tools/cli/log_scan.c). */
#include "carmen_bsf.h"

float scan_range_max(const carmen_scan_t *s, double opt)
{
    return opt > 0.0 ? (float)opt : carmen_valid_range_max(s);
}

bsf_scan_t scan_of_record(const carmen_scan_t *s, double range_max_opt)
{
    bsf_scan_t sc;
    sc.ranges = s->ranges;
    sc.count = s->count;
    sc.angle_min = s->angle_min;
    sc.angle_increment = s->angle_increment;
    sc.range_min = 0.0f;
    sc.range_max = scan_range_max(s, range_max_opt);
    return sc;
}
