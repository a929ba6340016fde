/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: the CARMEN log reader (tools/carmen.c) fed arbitrary
 * text through a temporary file (the reader's real path: zlib reads plain
 * and gzip files alike). Every record it returns must have a beam count in
 * 1..CARMEN_MAX_BEAMS, a finite non-zero increment and a finite start angle,
 * and line numbers that grow; each record then goes through
 * bsf_scan_to_points as the tool does.
 */
#define _POSIX_C_SOURCE 200809L /* mkstemp, unlink, access */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "carmen.h"
#include "fuzz_check.h"

static char path[256];
static bsf_points_t points;

static void make_temp(void)
{
    const char *dir = getenv("TMPDIR");
    int fd;
    if (access("/dev/shm", W_OK) == 0) {
        dir = "/dev/shm"; /* no disk I/O per input */
    } else if (dir == NULL) {
        dir = "/tmp";
    }
    snprintf(path, sizeof path, "%s/bsf_fuzz_carmen_XXXXXX", dir);
    fd = mkstemp(path);
    FUZZ_CHECK(fd >= 0);
    close(fd);
}

static void remove_temp(void)
{
    unlink(path);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    FILE *f;
    carmen_reader_t *r;
    carmen_scan_t s;
    unsigned long last_line = 0u;
    size_t records = 0u;
    size_t newlines = 0u;
    size_t i;
    int rc;
    if (path[0] == '\0') {
        make_temp();
        atexit(remove_temp);
    }
    f = fopen(path, "wb");
    FUZZ_CHECK(f != NULL);
    FUZZ_CHECK(fwrite(data, 1, size, f) == size);
    FUZZ_CHECK(fclose(f) == 0);
    for (i = 0; i < size; ++i) {
        newlines += data[i] == '\n';
    }

    r = carmen_open(path, NULL);
    FUZZ_CHECK(r != NULL);
    while ((rc = carmen_next(r, &s)) == 1) {
        bsf_scan_t scan;
        bsf_status_t st;
        FUZZ_CHECK(s.type == CARMEN_FLASER || s.type == CARMEN_ROBOTLASER1);
        FUZZ_CHECK(s.ranges != NULL);
        FUZZ_CHECK(s.count >= 1u && s.count <= CARMEN_MAX_BEAMS);
        FUZZ_CHECK(isfinite(s.angle_min) && isfinite(s.angle_increment));
        FUZZ_CHECK(s.angle_increment != 0.0f);
        FUZZ_CHECK(s.line > last_line);
        last_line = s.line;
        ++records;
        scan.ranges = s.ranges;
        scan.count = s.count;
        scan.angle_min = s.angle_min;
        scan.angle_increment = s.angle_increment;
        scan.range_min = 0.0f;
        scan.range_max = s.max_range;
        st = bsf_scan_to_points(&scan, &points);
        FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_ARG || st == BSF_ERR_CAPACITY);
        if (st == BSF_OK) {
            FUZZ_CHECK(points.n_valid <= points.count && points.count == s.count);
        }
    }
    FUZZ_CHECK(rc == 0 || rc == -1);
    /* a gzip body can hold more lines than the raw input has newlines */
    FUZZ_CHECK(records <= newlines + 1u || (size >= 2u && data[0] == 0x1Fu && data[1] == 0x8Bu));
    carmen_close(r);
    return 0;
}
