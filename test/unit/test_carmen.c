/* SPDX-License-Identifier: MIT */
/*
 * CARMEN log reader (tools/carmen.c): small logs written by the test, plain
 * and gzip-compressed, with every kind of line the datasets hold plus
 * malformed ones. Host only (files, zlib).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifdef BSF_HAVE_ZLIB
#include <zlib.h>
#endif

#include "carmen.h"
#include "unity.h"

#define PI_D 3.14159265358979323846

/* This Unity build has no double support: compare doubles here. */
#define EXPECT_DOUBLE(expected, actual)                                                            \
    TEST_ASSERT_TRUE_MESSAGE(fabs((expected) - (actual)) <= 1e-9 * (1.0 + fabs(expected)), #actual)

static char path_plain[256];
static char path_gz[256];
static char path_tmp[256];
static char big_line[80000];

void setUp(void)
{
}

void tearDown(void)
{
}

/* Line numbers below matter: the reports name them. */
static void build_log(char *buf, size_t cap)
{
    size_t len = 0;
    int i;
#define ADD(...) len += (size_t)snprintf(buf + len, cap - len, __VA_ARGS__)
    ADD("# message formats defined: PARAM ODOM FLASER\n"); /* 1 */
    ADD("\n");                                             /* 2 */
    ADD("PARAM robot_frontlaser_offset 0.0 nohost 0\n");   /* 3 */
    ADD("ODOM 0 0 0 0 0 0 0.000246 pippo 0.000246\n");     /* 4 */
    ADD("FLASER 180");                                     /* 5 */
    for (i = 0; i < 180; ++i) {
        ADD(" %d.%02d", 1 + i / 100, i % 100);
    }
    ADD(" 1.5 -2.25 0.5 1.25 -2.5 0.75 1000.125 pippo 1000.2\n");
    ADD("NEFF 42\n");                                                       /* 6 */
    ADD("ROBOTLASER1 0 -1.570796 3.141593 0.017453 50.000000 0.100000 0 5 " /* 7 */
        "3.36 3.34 81.83 4 2.85e-01 0 10.5 20.25 0.1 11.5 21.25 0.2 0 0 0.55 0.55 0 "
        "975001234.512345 nohost 12.5\n");
    ADD("FLASER 5 1 2 3\n");                                        /* 8: short */
    ADD("ROBOTLASER1 0 -1.57 3.14 0.0174 50 0.1 0 3 1.0 abc 2.0 0 " /* 9: bad range */
        "0 0 0 0 0 0 0 0 0 0 0 5.0 nohost 5.0\n");
    ADD("FLASER 9000 1 2 3\n");                          /* 10: count */
    ADD("ROBOTLASER1 0 -1.57 3.14 0 50 0.1 0 3 1 1 1 0 " /* 11: res 0 */
        "0 0 0 0 0 0 0 0 0 0 0 5.0 nohost 5.0\n");
    ADD("VERTEX2 0 0 0 0\n");                                    /* 12 */
    ADD("## EDGES\n");                                           /* 13 */
    ADD("FLASER 7 1 2 3 4 5 6 7 0 0 0 0 0 0 7.5 pippo 7.5\r\n"); /* 14: CRLF */
    ADD("FLASER 361");                                           /* 15 */
    for (i = 0; i < 361; ++i) {
        ADD(" 2");
    }
    ADD(" 0 0 0 0 0 0 8.5 pippo 8.5\n");
    ADD("%s\n", big_line);                                                  /* 16: long */
    ADD("ROBOTLASER1 0 -1.566433 3.141593 0.017453 81.9 0.1 0 2 5.5 6.5 0 " /* 17: no EOL */
        "1 2 3 4 5 6 0 0 0 0 0 9.25 nohost 9.25");
#undef ADD
    TEST_ASSERT_TRUE(len < cap - 1u);
}

static char log_text[200000];

static void make_big_line(void)
{
    /* A ROBOTLASER1 line of 5000 beams, far longer than the reader's first
     * buffer: beam i reads (i % 1000) / 100. */
    size_t len = 0;
    int i;
    len += (size_t)snprintf(big_line + len, sizeof big_line - len,
                            "ROBOTLASER1 0 -2.35619 4.71 0.000942 30 0.1 0 5000");
    for (i = 0; i < 5000; ++i) {
        len += (size_t)snprintf(big_line + len, sizeof big_line - len, " %d.%02d", (i % 1000) / 100,
                                (i % 1000) % 100);
    }
    len += (size_t)snprintf(big_line + len, sizeof big_line - len,
                            " 0 0 0 0 0 0 0 0 0 0 0 0 77.5 nohost 77.5");
    TEST_ASSERT_TRUE(len < sizeof big_line - 1u);
}

static void write_files(void)
{
    FILE *f;
#ifdef BSF_HAVE_ZLIB
    gzFile gz;
#else
    char cmd[600];
#endif
    int fd;
    const char *tmp = getenv("TMPDIR");
    if (tmp == NULL || tmp[0] == '\0') {
        tmp = "/tmp";
    }
    make_big_line();
    build_log(log_text, sizeof log_text);

    snprintf(path_plain, sizeof path_plain, "%s/bsf_carmen_XXXXXX", tmp);
    fd = mkstemp(path_plain);
    TEST_ASSERT_TRUE(fd >= 0);
    f = fdopen(fd, "w");
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)strlen(log_text),
                             (uint32_t)fwrite(log_text, 1, strlen(log_text), f));
    TEST_ASSERT_EQUAL_INT(0, fclose(f));

    snprintf(path_tmp, sizeof path_tmp, "%s/bsf_carmen_tmp_XXXXXX", tmp);
    fd = mkstemp(path_tmp);
    TEST_ASSERT_TRUE(fd >= 0);
    close(fd);

    snprintf(path_gz, sizeof path_gz, "%s/bsf_carmen_gz_XXXXXX", tmp);
    fd = mkstemp(path_gz);
    TEST_ASSERT_TRUE(fd >= 0);
    close(fd);
#ifdef BSF_HAVE_ZLIB
    gz = gzopen(path_gz, "wb9");
    TEST_ASSERT_NOT_NULL(gz);
    TEST_ASSERT_EQUAL_INT((int)strlen(log_text), gzwrite(gz, log_text, (unsigned)strlen(log_text)));
    TEST_ASSERT_EQUAL_INT(Z_OK, gzclose(gz));
#else
    /* the reader falls back to the system's gzip; so does this writer */
    snprintf(cmd, sizeof cmd, "gzip -9 -c '%s' > '%s'", path_plain, path_gz);
    TEST_ASSERT_EQUAL_INT(0, system(cmd));
#endif
}

/* Reads the whole log and checks every record and every report. */
static void check_log(const char *path)
{
    FILE *err = tmpfile();
    carmen_reader_t *rd;
    carmen_scan_t s;
    char report[4096];
    char expect[512];
    size_t n_rep;

    TEST_ASSERT_NOT_NULL(err);
    rd = carmen_open(path, err);
    TEST_ASSERT_NOT_NULL(rd);

    /* line 5: FLASER 180 */
    TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_INT(CARMEN_FLASER, s.type);
    TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)s.line);
    TEST_ASSERT_EQUAL_UINT32(180u, (uint32_t)s.count);
    TEST_ASSERT_EQUAL_FLOAT(1.00f, s.ranges[0]);
    TEST_ASSERT_EQUAL_FLOAT(2.79f, s.ranges[179]);
    TEST_ASSERT_EQUAL_FLOAT((float)(-PI_D / 2.0), s.angle_min);
    TEST_ASSERT_EQUAL_FLOAT((float)(PI_D / 180.0), s.angle_increment);
    TEST_ASSERT_EQUAL_FLOAT(80.0f, s.max_range);
    EXPECT_DOUBLE(1.5, s.laser_pose.x);
    EXPECT_DOUBLE(-2.25, s.laser_pose.y);
    EXPECT_DOUBLE(0.5, s.laser_pose.theta);
    EXPECT_DOUBLE(1.25, s.robot_pose.x);
    EXPECT_DOUBLE(-2.5, s.robot_pose.y);
    EXPECT_DOUBLE(0.75, s.robot_pose.theta);
    EXPECT_DOUBLE(1000.125, s.timestamp);

    /* line 7: ROBOTLASER1, geometry from the line, exponent notation */
    TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_INT(CARMEN_ROBOTLASER1, s.type);
    TEST_ASSERT_EQUAL_UINT32(7u, (uint32_t)s.line);
    TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)s.count);
    TEST_ASSERT_EQUAL_FLOAT(-1.570796f, s.angle_min);
    TEST_ASSERT_EQUAL_FLOAT(0.017453f, s.angle_increment);
    TEST_ASSERT_EQUAL_FLOAT(50.0f, s.max_range);
    TEST_ASSERT_EQUAL_FLOAT(3.36f, s.ranges[0]);
    TEST_ASSERT_EQUAL_FLOAT(81.83f, s.ranges[2]);
    TEST_ASSERT_EQUAL_FLOAT(4.0f, s.ranges[3]);
    TEST_ASSERT_EQUAL_FLOAT(0.285f, s.ranges[4]);
    EXPECT_DOUBLE(10.5, s.laser_pose.x);
    EXPECT_DOUBLE(20.25, s.laser_pose.y);
    EXPECT_DOUBLE(0.1, s.laser_pose.theta);
    EXPECT_DOUBLE(11.5, s.robot_pose.x);
    EXPECT_DOUBLE(21.25, s.robot_pose.y);
    EXPECT_DOUBLE(0.2, s.robot_pose.theta);
    EXPECT_DOUBLE(975001234.512345, s.timestamp);

    /* lines 8-11 are malformed, 12-13 skipped; line 14: 7 beams over 180 deg */
    TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_UINT32(14u, (uint32_t)s.line);
    TEST_ASSERT_EQUAL_UINT32(7u, (uint32_t)s.count);
    TEST_ASSERT_EQUAL_FLOAT((float)(PI_D / 6.0), s.angle_increment);
    TEST_ASSERT_EQUAL_FLOAT(7.0f, s.ranges[6]);
    EXPECT_DOUBLE(7.5, s.timestamp);
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)carmen_malformed_count(rd));

    /* line 15: 361 beams, half a degree */
    TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_UINT32(361u, (uint32_t)s.count);
    TEST_ASSERT_EQUAL_FLOAT((float)(PI_D / 360.0), s.angle_increment);
    TEST_ASSERT_EQUAL_FLOAT(2.0f, s.ranges[360]);

    /* line 16: 5000 beams on one long line */
    TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_UINT32(16u, (uint32_t)s.line);
    TEST_ASSERT_EQUAL_UINT32(5000u, (uint32_t)s.count);
    TEST_ASSERT_EQUAL_FLOAT(9.99f, s.ranges[999]);
    TEST_ASSERT_EQUAL_FLOAT(0.01f, s.ranges[4001]);
    TEST_ASSERT_EQUAL_FLOAT(-2.35619f, s.angle_min);
    EXPECT_DOUBLE(77.5, s.timestamp);

    /* line 17: beam count changed again, no newline at the end of the file */
    TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_UINT32(17u, (uint32_t)s.line);
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)s.count);
    TEST_ASSERT_EQUAL_FLOAT(6.5f, s.ranges[1]);
    TEST_ASSERT_EQUAL_FLOAT(81.9f, s.max_range);
    EXPECT_DOUBLE(9.25, s.timestamp);

    TEST_ASSERT_EQUAL_INT(0, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_INT(0, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)carmen_malformed_count(rd));
    carmen_close(rd);

    rewind(err);
    n_rep = fread(report, 1, sizeof report - 1u, err);
    report[n_rep] = '\0';
    fclose(err);
    snprintf(expect, sizeof expect, "%s:8: FLASER: missing or bad field", path);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(report, expect), report);
    snprintf(expect, sizeof expect, "%s:9: ROBOTLASER1: missing or bad field: range reading", path);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(report, expect), report);
    snprintf(expect, sizeof expect, "%s:10: FLASER: beam count 9000", path);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(report, expect), report);
    snprintf(expect, sizeof expect, "%s:11: ROBOTLASER1: angular resolution", path);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(report, expect), report);
}

static void test_plain_log_gives_every_laser_record_and_reports_bad_lines(void)
{
    check_log(path_plain);
}

static void test_gzip_log_reads_the_same(void)
{
    check_log(path_gz);
}

static void test_missing_file_gives_null(void)
{
    TEST_ASSERT_NULL(carmen_open("/nonexistent/dir/no.log", stderr));
    TEST_ASSERT_NULL(carmen_open(NULL, stderr));
    carmen_close(NULL);
}

static void test_silent_reader_still_counts_bad_lines(void)
{
    carmen_reader_t *rd = carmen_open(path_plain, NULL);
    carmen_scan_t s;
    int n = 0;
    TEST_ASSERT_NOT_NULL(rd);
    while (carmen_next(rd, &s) == 1) {
        ++n;
    }
    TEST_ASSERT_EQUAL_INT(6, n);
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)carmen_malformed_count(rd));
    carmen_close(rd);
}

/* ---- damaged files ---------------------------------------------------------- */

static void write_bytes(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n, (uint32_t)fwrite(data, 1, n, f));
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
}

static size_t read_all(const char *path, unsigned char *buf, size_t cap)
{
    size_t n;
    FILE *f = fopen(path, "rb");
    TEST_ASSERT_NOT_NULL(f);
    n = fread(buf, 1, cap, f);
    TEST_ASSERT_TRUE(n < cap);
    fclose(f);
    return n;
}

/* gzip-compress src into dst (a .gz file), as the reader's build would. */
static void gzip_file(const char *src, const char *dst)
{
#ifdef BSF_HAVE_ZLIB
    static unsigned char text[4096];
    const size_t n = read_all(src, text, sizeof text);
    gzFile gz = gzopen(dst, "wb9");
    TEST_ASSERT_NOT_NULL(gz);
    TEST_ASSERT_EQUAL_INT((int)n, gzwrite(gz, text, (unsigned)n));
    TEST_ASSERT_EQUAL_INT(Z_OK, gzclose(gz));
#else
    char cmd[600];
    snprintf(cmd, sizeof cmd, "gzip -9 -n -c '%s' > '%s'", src, dst);
    TEST_ASSERT_EQUAL_INT(0, system(cmd));
#endif
}

/* Lines 1-9; the damaged ones must be reported, the others read with their
 * own line numbers (a NUL must not glue line 3 to line 2). */
static const char damaged_log[] =
    "FLASER 3 1 2 3 0 0 0 0 0 0 1.0 h 1.0\n"     /* 1 */
    "FLASER 3 1 2\0 3 0 0 0 0 0 0 2.0 h 2.0\n"   /* 2: NUL at column 13 */
    "FLASER 3 1 2 3 0 0 0 0 0 0 3.0 h 3.0\n"     /* 3 */
    "FLASER 3 1 2 3 0 0 0\001 0 0 0 4.0 h 4.0\n" /* 4: SOH at column 21 */
    "ODOM 0 0 0 0 0 0 5.0 \033[2J 5.0\n"         /* 5: ESC at column 22 */
    "FLASER 3 1\r2 3 0 0 0 0 0 0 6.0 h 6.0\n"    /* 6: CR at column 11 */
    "FLASER 3 1 2 3 0 0 0 0 0 0 7.0 h 7.0\r\n"   /* 7: final CR is fine */
    "FLASER 3 1 2 3 0 0 0 0 0 0 8.0 h 8.0\177\n" /* 8: DEL at column 37 */
    "\0\0\0\n"                                   /* 9: NULs only */
    "FLASER 3 1 2 3 0 0 0 0 0 0 10.0 h 10.0\n";  /* 10 */

static void check_damaged(const char *path)
{
    static const unsigned long good_lines[] = {1u, 3u, 7u, 10u};
    static const char *const reports[] = {
        ":2: control byte 0x00 at column 13", ":4: control byte 0x01 at column 21",
        ":5: control byte 0x1b at column 22", ":6: control byte 0x0d at column 11",
        ":8: control byte 0x7f at column 37", ":9: control byte 0x00 at column 1"};
    FILE *err = tmpfile();
    carmen_reader_t *rd;
    carmen_scan_t s;
    char report[4096];
    char expect[512];
    size_t i, n_rep;
    TEST_ASSERT_NOT_NULL(err);
    rd = carmen_open(path, err);
    TEST_ASSERT_NOT_NULL(rd);
    for (i = 0; i < sizeof good_lines / sizeof good_lines[0]; ++i) {
        TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
        TEST_ASSERT_EQUAL_UINT32((uint32_t)good_lines[i], (uint32_t)s.line);
        EXPECT_DOUBLE((double)good_lines[i], s.timestamp);
        TEST_ASSERT_EQUAL_UINT32(3u, (uint32_t)s.count);
    }
    TEST_ASSERT_EQUAL_INT(0, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_UINT32(6u, (uint32_t)carmen_malformed_count(rd));
    carmen_close(rd);
    rewind(err);
    n_rep = fread(report, 1, sizeof report - 1u, err);
    report[n_rep] = '\0';
    fclose(err);
    for (i = 0; i < sizeof reports / sizeof reports[0]; ++i) {
        snprintf(expect, sizeof expect, "%s%s\n", path, reports[i]);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(report, expect), report);
    }
}

static void test_control_bytes_make_a_reported_malformed_line(void)
{
    char gz[300];
    write_bytes(path_tmp, damaged_log, sizeof damaged_log - 1u);
    check_damaged(path_tmp);
    snprintf(gz, sizeof gz, "%s.gz", path_tmp);
    gzip_file(path_tmp, gz);
    check_damaged(gz);
    remove(gz);
}

/* Newlines in what a gzip decompressor makes of the first n bytes of gz. */
static unsigned long newlines_in_prefix(const unsigned char *gz, size_t n)
{
    unsigned long lines = 0;
    static unsigned char out[8192];
#ifdef BSF_HAVE_ZLIB
    z_stream zs;
    int rc;
    size_t i;
    memset(&zs, 0, sizeof zs);
    TEST_ASSERT_EQUAL_INT(Z_OK, inflateInit2(&zs, 16 + MAX_WBITS));
    zs.next_in = (unsigned char *)(uintptr_t)gz;
    zs.avail_in = (uInt)n;
    do {
        zs.next_out = out;
        zs.avail_out = (uInt)sizeof out;
        rc = inflate(&zs, Z_NO_FLUSH);
        for (i = 0; i < sizeof out - zs.avail_out; ++i) {
            lines += out[i] == '\n';
        }
    } while (rc == Z_OK && zs.avail_out == 0u);
    inflateEnd(&zs);
#else
    char cmd[600];
    FILE *p;
    size_t got, i;
    write_bytes(path_tmp, gz, n);
    snprintf(cmd, sizeof cmd, "gzip -dc < '%s' 2>/dev/null", path_tmp);
    p = popen(cmd, "r");
    TEST_ASSERT_NOT_NULL(p);
    while ((got = fread(out, 1, sizeof out, p)) > 0u) {
        for (i = 0; i < got; ++i) {
            lines += out[i] == '\n';
        }
    }
    (void)pclose(p);
#endif
    return lines;
}

/* Every prefix of a gzip log is a read error naming the file and the last
 * complete line, never a shorter log; the records delivered before the
 * error all lie before the cut. */
static void test_every_cut_of_a_gzip_log_is_a_read_error(void)
{
    static const char text[] = "# a small log\n"
                               "FLASER 3 1 2 3 0 0 0 0 0 0 1.0 h 1.0\n"
                               "ODOM 0 0 0 0 0 0 2.0 h 2.0\n"
                               "FLASER 3 1.5 2.5 3.5 0 0 0 0 0 0 3.0 h 3.0\n"
                               "FLASER 3 4 5 6 0 0 0 0 0 0 4.0 h 4.0\n";
    static unsigned char gz[4096];
    char gz_path[300];
    char cut_path[300];
    char report[2048];
    char expect[600];
    size_t size, cut;
    snprintf(gz_path, sizeof gz_path, "%s_whole.log.gz", path_tmp);
    snprintf(cut_path, sizeof cut_path, "%s_cut.log.gz", path_tmp);
    write_bytes(path_tmp, text, sizeof text - 1u);
    gzip_file(path_tmp, gz_path);
    size = read_all(gz_path, gz, sizeof gz);
    TEST_ASSERT_TRUE(size > 20u);
    for (cut = 0; cut <= size; ++cut) {
        FILE *err = tmpfile();
        carmen_reader_t *rd;
        carmen_scan_t s;
        unsigned long last_line = 0;
        const unsigned long complete = newlines_in_prefix(gz, cut);
        size_t n_rep;
        int rc;
        TEST_ASSERT_NOT_NULL(err);
        write_bytes(cut_path, gz, cut);
        rd = carmen_open(cut_path, err);
        TEST_ASSERT_NOT_NULL(rd);
        while ((rc = carmen_next(rd, &s)) == 1) {
            last_line = s.line;
        }
        carmen_close(rd);
        rewind(err);
        n_rep = fread(report, 1, sizeof report - 1u, err);
        report[n_rep] = '\0';
        fclose(err);
        if (cut == size) {
            TEST_ASSERT_EQUAL_INT_MESSAGE(0, rc, report);
            TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)last_line);
            TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n_rep);
            continue;
        }
        snprintf(expect, sizeof expect, "%s:%lu: read error: ", cut_path, complete + 1u);
        TEST_ASSERT_EQUAL_INT_MESSAGE(-1, rc, expect);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(report, expect), report);
        snprintf(expect, sizeof expect, "the last complete line is %lu\n", complete);
        TEST_ASSERT_NOT_NULL_MESSAGE(strstr(report, expect), report);
        TEST_ASSERT_TRUE(last_line <= complete);
    }
    remove(gz_path);
    remove(cut_path);
}

static void test_plain_file_named_gz_is_refused(void)
{
    static const char text[] = "FLASER 3 1 2 3 0 0 0 0 0 0 1.0 h 1.0\n";
    char named[300];
    carmen_reader_t *rd;
    carmen_scan_t s;
    snprintf(named, sizeof named, "%s_plain.log.gz", path_tmp);
    write_bytes(named, text, sizeof text - 1u);
    rd = carmen_open(named, NULL);
    TEST_ASSERT_NOT_NULL(rd);
    TEST_ASSERT_EQUAL_INT(-1, carmen_next(rd, &s));
    carmen_close(rd);
    remove(named);
}

/* ---- overlong lines ----------------------------------------------------------- */

/* Writes n copies of byte c. */
static void write_run(FILE *f, int c, size_t n)
{
    static char chunk[65536];
    memset(chunk, c, sizeof chunk);
    while (n > 0u) {
        const size_t k = n < sizeof chunk ? n : sizeof chunk;
        TEST_ASSERT_EQUAL_UINT32((uint32_t)k, (uint32_t)fwrite(chunk, 1, k, f));
        n -= k;
    }
}

/* Lines 1 and 5 are scans; 2 (3 MiB) and 6 (1.5 MiB, no newline, the end)
 * are longer than the cap; 3 is a comment of exactly the cap, 4 a scan line
 * one byte over it. Memory never exceeds the cap, whatever the line. */
static void test_overlong_lines_are_reported_and_skipped_in_bounded_memory(void)
{
    static const char scan[] = "FLASER 3 1 2 3 0 0 0 0 0 0 %d.0 h %d.0\n";
    char path[300];
    char report[4096];
    FILE *f, *err;
    carmen_reader_t *rd;
    carmen_scan_t s;
    size_t n_rep;
    snprintf(path, sizeof path, "%s_long.log", path_tmp);
    f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    fprintf(f, scan, 1, 1);
    write_run(f, 'a', 3u << 20);
    fputc('\n', f);
    fputc('#', f);
    write_run(f, 'c', CARMEN_MAX_LINE - 1u);
    fputc('\n', f);
    fputs("FLASER 3 1 2 3 0 0 0 0 0 0 4.0 h 4.0 ", f);
    write_run(f, ' ', CARMEN_MAX_LINE);
    fputc('\n', f);
    fprintf(f, scan, 5, 5);
    write_run(f, 'b', 3u << 19);
    TEST_ASSERT_EQUAL_INT(0, fclose(f));

    err = tmpfile();
    TEST_ASSERT_NOT_NULL(err);
    rd = carmen_open(path, err);
    TEST_ASSERT_NOT_NULL(rd);
    TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)s.line);
    TEST_ASSERT_EQUAL_INT(1, carmen_next(rd, &s));
    TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)s.line);
    EXPECT_DOUBLE(5.0, s.timestamp);
    TEST_ASSERT_TRUE(carmen_buffer_bytes(rd) <= CARMEN_MAX_BUFFER);
    TEST_ASSERT_EQUAL_INT(0, carmen_next(rd, &s));
    TEST_ASSERT_TRUE(carmen_buffer_bytes(rd) <= CARMEN_MAX_BUFFER);
    TEST_ASSERT_EQUAL_UINT32(3u, (uint32_t)carmen_overlong_count(rd));
    TEST_ASSERT_EQUAL_UINT32(3u, (uint32_t)carmen_malformed_count(rd));
    carmen_close(rd);
    rewind(err);
    n_rep = fread(report, 1, sizeof report - 1u, err);
    report[n_rep] = '\0';
    fclose(err);
    {
        static const int lines[] = {2, 4, 6};
        char expect[400];
        size_t i;
        for (i = 0; i < 3u; ++i) {
            snprintf(expect, sizeof expect, "%s:%d: line longer than 1048576 bytes", path,
                     lines[i]);
            TEST_ASSERT_NOT_NULL_MESSAGE(strstr(report, expect), report);
        }
        TEST_ASSERT_NULL_MESSAGE(strstr(report, ":3:"), report);
    }
    remove(path);
}

int main(void)
{
    int rc;
    UNITY_BEGIN();
    write_files();
    RUN_TEST(test_plain_log_gives_every_laser_record_and_reports_bad_lines);
    RUN_TEST(test_gzip_log_reads_the_same);
    RUN_TEST(test_missing_file_gives_null);
    RUN_TEST(test_silent_reader_still_counts_bad_lines);
    RUN_TEST(test_control_bytes_make_a_reported_malformed_line);
    RUN_TEST(test_every_cut_of_a_gzip_log_is_a_read_error);
    RUN_TEST(test_plain_file_named_gz_is_refused);
    RUN_TEST(test_overlong_lines_are_reported_and_skipped_in_bounded_memory);
    rc = UNITY_END();
    remove(path_plain);
    remove(path_gz);
    remove(path_tmp);
    return rc;
}
