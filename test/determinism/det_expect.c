/* SPDX-License-Identifier: MIT */
/*
 * det_expect - run the determinism workload on the host and write its
 * results as a C header (the reference the cross builds' test_determinism
 * compares against): hashes, counts, the host's simulated ranges as bit
 * patterns (so the target runs the library on exactly the host's input),
 * and, when a log is given and readable, a sample of its scans as bit
 * patterns with the host's hashes for them.
 * Usage: det_expect OUT.h [LOG]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "carmen.h"
#include "det_core.h"

/** Scans taken from the log (every DET_LOG_STRIDE-th), at most. */
#define DET_LOG_SCANS 40u
#define DET_LOG_STRIDE 67u

static float all_ranges[DET_SCANS * DET_BEAMS];
static det_log_scan_t log_scans[DET_LOG_SCANS];
static uint32_t log_range_bits[DET_LOG_SCANS * CARMEN_MAX_BEAMS];

static uint32_t bits_of(float f)
{
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    return b;
}

/* Reads every DET_LOG_STRIDE-th scan of the log as the tool would give it
 * to the library. Returns the number of scans read (0 if none). */
static size_t read_log(const char *path, size_t *n_ranges)
{
    carmen_reader_t *rd = carmen_open(path, stderr);
    carmen_scan_t rec;
    size_t n = 0u, index = 0u;
    double t0 = 0.0;
    *n_ranges = 0u;
    if (rd == NULL) {
        return 0u;
    }
    while (n < DET_LOG_SCANS && carmen_next(rd, &rec) == 1) {
        size_t i;
        det_log_scan_t *s = &log_scans[n];
        if (index++ % DET_LOG_STRIDE != 0u || rec.count > BSF_MAX_POINTS) {
            continue;
        }
        if (n == 0u) {
            t0 = rec.timestamp;
        }
        s->count = (uint32_t)rec.count;
        s->angle_min = bits_of(rec.angle_min);
        s->angle_increment = bits_of(rec.angle_increment);
        s->range_max = bits_of(carmen_valid_range_max(&rec));
        s->pose_x = bits_of((float)rec.laser_pose.x);
        s->pose_y = bits_of((float)rec.laser_pose.y);
        s->pose_theta =
            bits_of((float)remainder(rec.laser_pose.theta, 2.0 * 3.14159265358979323846));
        s->timestamp_ms =
            rec.timestamp > t0 ? (uint32_t)llround((rec.timestamp - t0) * 1000.0) : 0u;
        for (i = 0; i < rec.count; ++i) {
            log_range_bits[*n_ranges + i] = bits_of(rec.ranges[i]);
        }
        *n_ranges += rec.count;
        ++n;
    }
    carmen_close(rd);
    return n;
}

static void write_u32_array(FILE *f, const char *name, const uint32_t *v, size_t n)
{
    size_t i;
    fprintf(f, "static const uint32_t %s[%lu] = {", name, (unsigned long)(n > 0u ? n : 1u));
    for (i = 0; i < n; ++i) {
        const char *sep = (i == 0u) ? "\n    " : ((i % 6u == 0u) ? ",\n    " : ", ");
        fprintf(f, "%s0x%08lxu", sep, (unsigned long)v[i]);
    }
    fprintf(f, "%s};\n", n > 0u ? "" : "0u");
}

/* The map workload's results as NAME_* macros. */
static void write_map(FILE *f, const char *name, const det_map_summary_t *m)
{
    fprintf(f, "#define %s_STREAM_HASH 0x%08lxu\n", name, (unsigned long)m->stream_hash);
    fprintf(f, "#define %s_STREAM_BYTES %luu\n", name, (unsigned long)m->stream_bytes);
    fprintf(f, "#define %s_FRAMES %luu\n", name, (unsigned long)m->frames);
    fprintf(f, "#define %s_ALIGN_HASH 0x%08lxu\n", name, (unsigned long)m->align_hash);
    fprintf(f, "#define %s_ACCEPTED %luu\n", name, (unsigned long)m->n_accepted);
    fprintf(f, "#define %s_RX_HASH 0x%08lxu\n", name, (unsigned long)m->rx_hash);
    fprintf(f, "#define %s_RX_POINTS %luu\n", name, (unsigned long)m->rx_points);
}

int main(int argc, char **argv)
{
    det_summary_t s;
    det_summary_t ls;
    det_map_summary_t ms;
    det_map_summary_t lms;
    bsf_status_t st = BSF_OK;
    FILE *f;
    unsigned k;
    size_t i, n_log = 0u, n_log_ranges = 0u;
    static uint32_t bits[DET_SCANS * DET_BEAMS];
    if (argc != 2 && argc != 3) {
        fprintf(stderr, "usage: det_expect OUT.h [LOG]\n");
        return 2;
    }
    for (k = 0; k < DET_SCANS && st == BSF_OK; ++k) {
        bsf_scan_t scan;
        st = det_simulate(k, all_ranges + (size_t)k * DET_BEAMS, &scan);
    }
    if (st == BSF_OK) {
        st = det_run(NULL, &s, NULL, NULL);
    }
    if (st == BSF_OK) {
        st = det_run_map(NULL, &ms);
    }
    memset(&ls, 0, sizeof ls);
    memset(&lms, 0, sizeof lms);
    if (st == BSF_OK && argc == 3) {
        n_log = read_log(argv[2], &n_log_ranges);
        if (n_log > 0u) {
            st = det_run_log(log_scans, n_log, log_range_bits, &ls);
            if (st == BSF_OK) {
                st = det_run_map_log(log_scans, n_log, log_range_bits, &lms);
            }
        } else {
            printf("det_expect: %s not readable: no log scans in the reference\n", argv[2]);
        }
    }
    if (st != BSF_OK) {
        fprintf(stderr, "det_expect: %s\n", bsf_status_str(st));
        return 1;
    }
    f = fopen(argv[1], "w");
    if (f == NULL) {
        perror(argv[1]);
        return 1;
    }
    fprintf(f, "/* Generated by det_expect on the build host: do not edit. */\n");
    fprintf(f, "#define DET_EXPECT_RANGES_HASH 0x%08lxu\n", (unsigned long)s.ranges_hash);
    fprintf(f, "#define DET_EXPECT_STREAM_HASH 0x%08lxu\n", (unsigned long)s.stream_hash);
    fprintf(f, "#define DET_EXPECT_DECODED_HASH 0x%08lxu\n", (unsigned long)s.decoded_hash);
    fprintf(f, "#define DET_EXPECT_STREAM_BYTES %luu\n", (unsigned long)s.stream_bytes);
    fprintf(f, "#define DET_EXPECT_FEATURES %luu\n", (unsigned long)s.n_features);
    fprintf(f, "#define DET_EXPECT_CTRL %luu\n", (unsigned long)s.n_ctrl);
    write_map(f, "DET_EXPECT_MAP", &ms);
    write_map(f, "DET_EXPECT_LOG_MAP", &lms);
    for (i = 0; i < (size_t)DET_SCANS * DET_BEAMS; ++i) {
        bits[i] = bits_of(all_ranges[i]);
    }
    write_u32_array(f, "det_host_range_bits", bits, (size_t)DET_SCANS * DET_BEAMS);

    fprintf(f, "#define DET_LOG_SCANS_USED %luu\n", (unsigned long)n_log);
    fprintf(f, "#define DET_EXPECT_LOG_RANGES_HASH 0x%08lxu\n", (unsigned long)ls.ranges_hash);
    fprintf(f, "#define DET_EXPECT_LOG_STREAM_HASH 0x%08lxu\n", (unsigned long)ls.stream_hash);
    fprintf(f, "#define DET_EXPECT_LOG_DECODED_HASH 0x%08lxu\n", (unsigned long)ls.decoded_hash);
    fprintf(f, "#define DET_EXPECT_LOG_STREAM_BYTES %luu\n", (unsigned long)ls.stream_bytes);
    fprintf(f, "#define DET_EXPECT_LOG_FEATURES %luu\n", (unsigned long)ls.n_features);
    fprintf(f, "static const det_log_scan_t det_log_scans[%lu] = {\n",
            (unsigned long)(n_log > 0u ? n_log : 1u));
    for (i = 0; i < n_log; ++i) {
        const det_log_scan_t *q = &log_scans[i];
        fprintf(
            f, "    {%luu, 0x%08lxu, 0x%08lxu, 0x%08lxu, 0x%08lxu, 0x%08lxu, 0x%08lxu, %luu},\n",
            (unsigned long)q->count, (unsigned long)q->angle_min, (unsigned long)q->angle_increment,
            (unsigned long)q->range_max, (unsigned long)q->pose_x, (unsigned long)q->pose_y,
            (unsigned long)q->pose_theta, (unsigned long)q->timestamp_ms);
    }
    fprintf(f, "%s};\n", n_log > 0u ? "" : "    {0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u}\n");
    write_u32_array(f, "det_log_range_bits", log_range_bits, n_log_ranges);
    printf("det_expect: demo: ranges 0x%08lx, stream 0x%08lx, decoded 0x%08lx, %lu bytes, %lu "
           "features, %lu control points; log: %lu scans, stream 0x%08lx, %lu bytes\n",
           (unsigned long)s.ranges_hash, (unsigned long)s.stream_hash,
           (unsigned long)s.decoded_hash, (unsigned long)s.stream_bytes,
           (unsigned long)s.n_features, (unsigned long)s.n_ctrl, (unsigned long)n_log,
           (unsigned long)ls.stream_hash, (unsigned long)ls.stream_bytes);
    printf("det_expect: map (demo): %lu frames, %lu bytes, stream 0x%08lx, %lu alignments "
           "accepted, receiver %lu points 0x%08lx; map (log): %lu frames, %lu bytes, stream "
           "0x%08lx, %lu accepted\n",
           (unsigned long)ms.frames, (unsigned long)ms.stream_bytes, (unsigned long)ms.stream_hash,
           (unsigned long)ms.n_accepted, (unsigned long)ms.rx_points, (unsigned long)ms.rx_hash,
           (unsigned long)lms.frames, (unsigned long)lms.stream_bytes,
           (unsigned long)lms.stream_hash, (unsigned long)lms.n_accepted);
    return fclose(f) == 0 ? 0 : 1;
}
