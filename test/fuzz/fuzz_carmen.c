/* SPDX-License-Identifier: MIT */
/*
 * libFuzzer harness: the CARMEN log reader (tools/carmen) fed arbitrary
 * text or gzip data through a temporary file (the reader's real path), and
 * the tool's range policy (tools/carmen/carmen_bsf.c) on every record.
 *
 * Properties: every record has a beam count in 1..CARMEN_MAX_BEAMS, a finite
 * non-zero increment, a finite start angle and a growing line number; each
 * malformed line is reported exactly once as "FILE:LINE: ..." with a line
 * number in order, and a read error once more ("read error", then nothing
 * is returned); a plain input never yields more records than lines; the
 * scan the tool would build has a range_max in (0, 81.8] that makes the
 * no-return codes invalid (or exactly the --range-max given), and
 * bsf_scan_to_points accepts or cleanly refuses it. Memory: the reader's
 * line buffer never holds more than CARMEN_MAX_BUFFER bytes, whatever the
 * input (a gzip input inflates to far longer lines than that), and every
 * line over CARMEN_MAX_LINE is one of the malformed lines reported.
 *
 * Input starting with 0x1f (gzip data starts 1f 8b) is written to a file
 * named *.log.gz, so cut or corrupt gzip streams (and non-gzip data under a
 * .gz name) reach the reader's read-error paths; other input goes to a
 * plain *.log file.
 */
#define _GNU_SOURCE /* fopencookie; mkdtemp, unlink, rmdir, access */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "carmen.h"
#include "carmen_bsf.h"
#include "fuzz_check.h"

static char path_plain[300];
static char path_gz[300];
static bsf_points_t points;

static char dir_path[256];

/* A private directory holding in.log and in.log.gz. */
static void make_temp(void)
{
    const char *dir = getenv("TMPDIR");
    if (access("/dev/shm", W_OK) == 0) {
        dir = "/dev/shm"; /* no disk I/O per input */
    } else if (dir == NULL) {
        dir = "/tmp";
    }
    snprintf(dir_path, sizeof dir_path, "%s/bsf_fuzz_carmen_XXXXXX", dir);
    FUZZ_CHECK(mkdtemp(dir_path) != NULL);
    snprintf(path_plain, sizeof path_plain, "%s/in.log", dir_path);
    snprintf(path_gz, sizeof path_gz, "%s/in.log.gz", dir_path);
}

static void remove_temp(void)
{
    unlink(path_plain);
    unlink(path_gz);
    rmdir(dir_path);
}

/* The reader's reports, checked line by line as they are written (a gzip
 * input can inflate to millions of reported lines: nothing is kept but the
 * counts and the current line's start). Each line must be "PATH:N: ...",
 * N not decreasing, one per malformed line plus one per read error. */
typedef struct {
    const char *path;
    char head[512]; /* the line's first bytes: path, number and the message's start */
    size_t len;     /* bytes of the current line so far */
    unsigned long lines, read_errors, last;
} report_check_t;

static report_check_t reports;

static void check_report_line(report_check_t *c)
{
    const size_t plen = strlen(c->path);
    const size_t kept = c->len < sizeof c->head ? c->len : sizeof c->head - 1u;
    char *after;
    unsigned long n;
    c->head[kept] = '\0';
    FUZZ_CHECK(kept > plen + 2u && memcmp(c->head, c->path, plen) == 0 && c->head[plen] == ':');
    n = strtoul(c->head + plen + 1u, &after, 10);
    FUZZ_CHECK(after[0] == ':' && after[1] == ' ' && n >= 1u);
    if (strncmp(after + 2, "read error", 10) == 0) {
        ++c->read_errors;
        FUZZ_CHECK(n >= c->last);
    } else {
        ++c->lines;
        FUZZ_CHECK(n > c->last || (c->lines == 1u && n >= 1u));
        c->last = n;
    }
}

static ssize_t report_write(void *cookie, const char *buf, size_t size)
{
    report_check_t *c = cookie;
    size_t i;
    for (i = 0; i < size; ++i) {
        if (buf[i] == '\n') {
            check_report_line(c);
            c->len = 0u;
        } else {
            if (c->len < sizeof c->head - 1u) {
                c->head[c->len] = buf[i];
            }
            ++c->len;
        }
    }
    return (ssize_t)size;
}

static void carmen_close_and_check(carmen_reader_t *r, FILE *err, int rc)
{
    const unsigned long malformed = carmen_malformed_count(r);
    FUZZ_CHECK(carmen_overlong_count(r) <= malformed);
    FUZZ_CHECK(carmen_buffer_bytes(r) <= CARMEN_MAX_BUFFER);
    carmen_close(r);
    FUZZ_CHECK(fclose(err) == 0);
    FUZZ_CHECK(reports.len == 0u); /* every report ends with its newline */
    FUZZ_CHECK(reports.lines == malformed);
    FUZZ_CHECK(reports.read_errors == (rc < 0 ? 1u : 0u));
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    FILE *f;
    FILE *err;
    carmen_reader_t *r;
    carmen_scan_t s;
    unsigned long last_line = 0u;
    size_t records = 0u;
    size_t newlines = 0u;
    size_t i;
    int rc;
    const int is_gzip = size >= 2u && data[0] == 0x1Fu && data[1] == 0x8Bu;
    /* a first byte of 0x1f goes to the .gz name even without the rest of
     * the magic: "not gzip data" */
    const int gz_name = size >= 1u && data[0] == 0x1Fu;
    const char *path;
    if (path_plain[0] == '\0') {
        make_temp();
        atexit(remove_temp);
    }
    path = gz_name ? path_gz : path_plain;
    f = fopen(path, "wb");
    FUZZ_CHECK(f != NULL);
    FUZZ_CHECK(fwrite(data, 1, size, f) == size);
    FUZZ_CHECK(fclose(f) == 0);
    for (i = 0; i < size; ++i) {
        newlines += data[i] == '\n';
    }

    memset(&reports, 0, sizeof reports);
    reports.path = path;
    {
        static const cookie_io_functions_t io = {NULL, report_write, NULL, NULL};
        err = fopencookie(&reports, "w", io);
    }
    FUZZ_CHECK(err != NULL);
    r = carmen_open(path, err);
    FUZZ_CHECK(r != NULL);
    while ((rc = carmen_next(r, &s)) == 1) {
        bsf_scan_t scan;
        bsf_status_t st;
        double opt;
        FUZZ_CHECK(s.type == CARMEN_FLASER || s.type == CARMEN_ROBOTLASER1);
        FUZZ_CHECK(s.ranges != NULL);
        FUZZ_CHECK(s.count >= 1u && s.count <= CARMEN_MAX_BEAMS);
        FUZZ_CHECK(isfinite(s.angle_min) && isfinite(s.angle_increment));
        FUZZ_CHECK(s.angle_increment != 0.0f);
        FUZZ_CHECK(s.line > last_line);
        FUZZ_CHECK(carmen_buffer_bytes(r) <= CARMEN_MAX_BUFFER);
        last_line = s.line;
        ++records;

        /* the tool's default policy: the log's maximum, below no-return codes */
        scan = scan_of_record(&s, 0.0);
        FUZZ_CHECK(scan.ranges == s.ranges && scan.count == s.count);
        FUZZ_CHECK(scan.range_min == 0.0f);
        FUZZ_CHECK(scan.range_max > 0.0f && scan.range_max <= CARMEN_NO_RETURN_FLOOR);
        FUZZ_CHECK(!bsf_range_is_valid(81.83f, scan.range_min, scan.range_max));
        FUZZ_CHECK(!bsf_range_is_valid(81.91f, scan.range_min, scan.range_max));
        if (s.max_range > 0.0f && s.max_range < CARMEN_NO_RETURN_FLOOR) {
            FUZZ_CHECK(scan.range_max == s.max_range);
        }
        st = bsf_scan_to_points(&scan, &points);
        fuzz_check_status(st);
        FUZZ_CHECK(st == BSF_OK || st == BSF_ERR_ARG || st == BSF_ERR_CAPACITY);
        FUZZ_CHECK((st == BSF_ERR_CAPACITY) == (s.count > BSF_MAX_POINTS) || st == BSF_ERR_ARG);
        if (st == BSF_OK) {
            FUZZ_CHECK(points.n_valid <= points.count && points.count == s.count);
        }
        /* --range-max M (the tool accepts 1e-3..1e4) replaces it exactly */
        opt = 1e-3 + fmod(fabs(isfinite(s.timestamp) ? s.timestamp : 1.0), 1e4);
        FUZZ_CHECK(scan_range_max(&s, opt) == (float)opt);
    }
    FUZZ_CHECK(rc == 0 || rc == -1);
    /* a gzip body can hold more lines than the raw input has newlines */
    FUZZ_CHECK(records <= newlines + 1u || is_gzip);
    carmen_close_and_check(r, err, rc);
    return 0;
}
