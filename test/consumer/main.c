/* SPDX-License-Identifier: MIT */
/* Converts a three-beam scan with the installed library; exit 0 when the
 * library answers as documented. */
#include <bsf/bsf.h>

static bsf_points_t points;

int main(void)
{
    static const float ranges[3] = {1.0f, -1.0f, 2.0f};
    bsf_scan_t scan = {ranges, 3u, 0.0f, 0.01f, 0.1f, 10.0f};
    if (bsf_scan_to_points(&scan, &points) != BSF_OK) {
        return 1;
    }
    return points.n_valid == 2u ? 0 : 2;
}
