/* SPDX-License-Identifier: MIT */
/*
 * make_corpus - write the fuzzers' seed corpus (test/fuzz/corpus/) from the
 * project's own encoder and scenes: real frames of demo-office scans (raw,
 * as payloads, after garbage, inside an oversize frame, and for the direct
 * COBS / frame-decode / encoder modes), the same scans as extractor inputs
 * (each method, parameter edits, a clock, a 1081-beam raw-float scan), and
 * synthetic CARMEN logs (FLASER 180/181/360/361, a line longer than the
 * reader's first buffer, gzip whole and cut, a gzip line over the line cap).
 * Usage: make_corpus DIR   (DIR/stream, DIR/extract, DIR/carmen must exist)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef BSF_HAVE_ZLIB
#include <zlib.h>
#endif

#include "bsf/bsf.h"
#include "bsf_scene.h"

static bsf_extractor_t ex;
static bsf_result_t res;
static float ranges[BSF_MAX_POINTS];
static uint8_t wire[BSF_FRAME_MAX_SIZE];

static int write_file(const char *dir, const char *sub, const char *name, const void *p, size_t n)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s/%s", dir, sub, name);
    f = fopen(path, "wb");
    if (f == NULL || fwrite(p, 1, n, f) != n || fclose(f) != 0) {
        fprintf(stderr, "make_corpus: cannot write %s\n", path);
        return 1;
    }
    return 0;
}

/* One demo scan as extractor input: flags, 2-byte geometry code, uint16 mm ranges. */
static size_t extract_input(uint8_t *out, size_t n_beams, uint8_t flags)
{
    size_t i;
    size_t n = 0u;
    out[n++] = flags;
    /* angle_min -3.1 + 0.1 * 7 = -2.4 (about -3/4 pi), increment 0.0005 * (25 + 1) */
    out[n++] = (uint8_t)(7u | (25u << 6));
    out[n++] = (uint8_t)((25u >> 2) | 0x40u);
    for (i = 0; i < n_beams; ++i) {
        const float r = ranges[i];
        const unsigned mm = (r > 0.0f && r < 65.0f) ? (unsigned)(r * 1000.0f + 0.5f) : 0xFFFFu;
        out[n++] = (uint8_t)(mm & 0xFFu);
        out[n++] = (uint8_t)(mm >> 8);
    }
    return n;
}

/* Appends a 4-byte little-endian value. */
static size_t put4(uint8_t *out, size_t n, uint32_t v)
{
    out[n] = (uint8_t)v;
    out[n + 1u] = (uint8_t)(v >> 8);
    out[n + 2u] = (uint8_t)(v >> 16);
    out[n + 3u] = (uint8_t)(v >> 24);
    return n + 4u;
}

static uint32_t bits_of(float f)
{
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    return b;
}

/* A CARMEN FLASER line of n beams into text; returns its length. */
static size_t flaser_line(char *text, size_t cap, unsigned n, double t)
{
    size_t len = (size_t)snprintf(text, cap, "FLASER %u", n);
    unsigned i;
    for (i = 0; i < n; ++i) {
        len += (size_t)snprintf(text + len, cap - len, " %.2f", 2.0 + 0.01 * (double)(i % 300u));
    }
    len += (size_t)snprintf(text + len, cap - len, " 1 2 0.1 1 2 0.1 %.3f nohost %.3f\n", t, t);
    return len;
}

/* Extra seeds for the modes added with the coverage work (see each harness). */
static int extra_seeds(const char *dir, const uint8_t *frame, size_t frame_len, bsf_scene_t *scene,
                       bsf_scene_rng_t *rng)
{
    static uint8_t out[8u * BSF_MAX_POINTS + 64u];
    static uint8_t tmp[2u * BSF_MAX_POINTS + 16u];
    static char text[80000];
    int err = 0;
    size_t n, i, len;
    bsf_lidar_t lid;

    /* stream: garbage, then a frame (mode 0x00) */
    n = 0u;
    out[n++] = 7u;
    for (i = 0; i < 40u; ++i) {
        out[n++] = (uint8_t)(0x5Bu * i + 1u);
    }
    memcpy(out + n, frame, frame_len);
    err |= write_file(dir, "stream", "garbage_frame.bin", out, n + frame_len);
    /* stream: oversize (mode 0x40), 4 * 32 extra bytes of frame data */
    out[0] = 0x40u | 3u;
    out[1] = 4u;
    memcpy(out + 2, frame, frame_len - 1u);
    err |= write_file(dir, "stream", "oversize.bin", out, frame_len + 1u);
    /* stream direct (0xC0): COBS bytes, a body with its CRC fixed, encoder edits */
    out[0] = 0xC0u;
    out[1] = 0u; /* sel % 4 = 0: bsf_cobs_decode; sel / 4 = 0: tight cap */
    memcpy(out + 2, frame, frame_len - 1u);
    err |= write_file(dir, "stream", "direct_cobs.bin", out, frame_len + 1u);
    out[1] = 4u; /* sel % 4 = 0: bsf_cobs_decode, sel / 4 = 1: large cap */
    err |= write_file(dir, "stream", "direct_cobs_large.bin", out, frame_len + 1u);
    {
        size_t blen = 0u;
        out[1] = 5u; /* sel % 4 = 1: bsf_frame_decode, sel / 4 = 1: CRC fixed */
        if (bsf_cobs_decode(frame, frame_len - 1u, out + 2, sizeof out - 2u, &blen) != BSF_OK) {
            return 1;
        }
        err |= write_file(dir, "stream", "direct_decode.bin", out, blen - 4u + 2u);
    }
    out[1] = 2u + 4u * 40u; /* sel % 4 = 2: encoder; sel / 4 = 40: sink limit 320 bytes */
    err |= write_file(dir, "stream", "direct_encode.bin", out, 2u);
    n = 2u;
    out[n++] = 0x00u; /* pose_x raw */
    n = put4(out, n, bits_of(123.456f));
    out[n++] = 0x03u; /* quant_step */
    n = put4(out, n, bits_of(0.001f));
    out[n++] = 0x14u; /* ctrl[1].x */
    n = put4(out, n, bits_of(-7.25f));
    out[n++] = 0x0Fu; /* timestamp, has_pose, n_valid, time_ns */
    n = put4(out, n, 0x12345u);
    err |= write_file(dir, "stream", "direct_encode_edits.bin", out, n);
    n = 0u;
    out[n++] = 0xC0u;
    out[n++] = 3u + 4u * 60u; /* sel % 4 = 3: metadata encoder; sink limit 120 bytes */
    out[n++] = 5u;            /* n_beams 361 */
    n = put4(out, n, 361u);
    out[n++] = 6u; /* angle_min */
    n = put4(out, n, bits_of(-2.4f));
    out[n++] = 7u; /* angle_increment */
    n = put4(out, n, bits_of(0.013f));
    out[n++] = 9u; /* range_max */
    n = put4(out, n, bits_of(30.0f));
    out[n++] = 12u; /* source "log1" */
    memcpy(out + n, "log1", 4u);
    n += 4u;
    err |= write_file(dir, "stream", "direct_metadata.bin", out, n);

    /* extract: a 1081-beam scan, raw floats, at the cap (F_RAW_RANGES |
     * F_OVER_CAP | F_ENCODE), and the BID method, parameter edits, a clock */
    lid = bsf_lidar_default(1.0, 1.0, 0.3, 1081u, 4.86);
    lid.angle_min = -2.4;
    lid.angle_increment = 0.0045;
    lid.noise_sigma = 0.01;
    lid.range_max = 20.0;
    lid.no_return = 81.83f;
    if (bsf_scene_scan(scene, &lid, rng, ranges, NULL, BSF_MAX_POINTS) != BSF_OK) {
        return 1;
    }
    n = 0u;
    out[n++] = 0x32u;
    out[n++] = (uint8_t)(7u | (8u << 6)); /* angle_min -2.4, increment 0.0045 */
    out[n++] = (uint8_t)((8u >> 2) | 0x40u);
    out[n++] = 1u; /* BSF_MAX_POINTS + 1 - 1 beams */
    for (i = 0; i < 1081u && i < BSF_MAX_POINTS; ++i) {
        n = put4(out, n, bits_of(ranges[i]));
    }
    err |= write_file(dir, "extract", "cap_raw.bin", out, n);
    len = extract_input(out, 361u, 0xA0u); /* BID + encode, the 361 first beams */
    err |= write_file(dir, "extract", "bid.bin", out, len);
    n = 0u;
    out[n++] = 0x28u; /* F_PARAMS | F_ENCODE */
    out[n++] = (uint8_t)(7u | (25u << 6));
    out[n++] = (uint8_t)((25u >> 2) | 0x40u);
    out[n++] = 4u;  /* four edits near the defaults */
    out[n++] = 24u; /* pdm.precision_spacing x 1.125 */
    n = put4(out, n, 8u);
    out[n++] = 30u; /* pdm.max_ctrl 20 */
    n = put4(out, n, 20u);
    out[n++] = 11u; /* falko.neigh_a x 1.625 */
    n = put4(out, n, 12u);
    out[n++] = 16u; /* falko.circular_sector_distance 1 */
    n = put4(out, n, 1u);
    len = extract_input(tmp, 361u, 0x28u);
    memcpy(out + n, tmp + 3, len - 3u); /* the ranges after flags and geometry */
    err |= write_file(dir, "extract", "params.bin", out, n + len - 3u);
    n = 0u;
    out[n++] = 0x28u; /* F_PARAMS | F_ENCODE: one edit, the clock hook */
    out[n++] = (uint8_t)(7u | (25u << 6));
    out[n++] = (uint8_t)((25u >> 2) | 0x40u);
    out[n++] = 1u;
    out[n++] = 36u; /* 1000 ticks per call at 1 MHz */
    n = put4(out, n, 1000u);
    len = extract_input(tmp, 361u, 0x28u);
    memcpy(out + n, tmp + 3, len - 3u);
    err |= write_file(dir, "extract", "clock.bin", out, n + len - 3u);

    n = 0u;
    out[n++] = 0x28u; /* F_PARAMS | F_ENCODE, the default method (LC): four LC edits */
    out[n++] = (uint8_t)(7u | (25u << 6));
    out[n++] = (uint8_t)((25u >> 2) | 0x40u);
    out[n++] = 4u;
    out[n++] = 39u; /* lc.split_min x 0.625 */
    n = put4(out, n, 4u);
    out[n++] = 42u; /* lc.curve_ratio x 0.375 */
    n = put4(out, n, 2u);
    out[n++] = 47u; /* lc.max_range 8 m */
    n = put4(out, n, 32u);
    out[n++] = 48u; /* lc.min_side_points 2 */
    n = put4(out, n, 2u);
    len = extract_input(tmp, 361u, 0x28u);
    memcpy(out + n, tmp + 3, len - 3u);
    err |= write_file(dir, "extract", "lc_params.bin", out, n + len - 3u);

    /* extract: 1081 beams of 6-beam blocks alternating 2 m and 6 m (the
     * harness repeats one period up to the cap): more segments, keypoints
     * and control points than the caps hold, so the cut paths run */
    {
        static const uint8_t methods[4] = {0xB1u, 0x31u, 0xB0u, 0x30u}; /* FALKO, RPOS, BID, LC */
        static const char *const names[4] = {"cut_falko.bin", "cut_rpos.bin", "cut_bid.bin",
                                             "cut_lc.bin"};
        size_t m;
        for (m = 0; m < 4u; ++m) {
            n = 0u;
            out[n++] = methods[m];
            out[n++] = (uint8_t)(7u | (8u << 6)); /* angle_min -2.4, increment 0.0045 */
            out[n++] = (uint8_t)((8u >> 2) | 0x40u);
            out[n++] = 1u; /* BSF_MAX_POINTS beams */
            for (i = 0; i < 12u; ++i) {
                const unsigned mm = i < 6u ? 2000u : 6000u;
                out[n++] = (uint8_t)(mm & 0xFFu);
                out[n++] = (uint8_t)(mm >> 8);
            }
            err |= write_file(dir, "extract", names[m], out, n);
        }
    }

    /* carmen: FLASER 180/181/360/361, a long line, gzip whole and cut */
    {
        static const unsigned counts[4] = {180u, 181u, 360u, 361u};
        char name[64];
        for (i = 0; i < 4u; ++i) {
            len = flaser_line(text, sizeof text, counts[i], 10.0 + (double)i);
            snprintf(name, sizeof name, "flaser_%u.txt", counts[i]);
            err |= write_file(dir, "carmen", name, text, len);
        }
        len =
            (size_t)snprintf(text, sizeof text, "ROBOTLASER1 0 -2.35 4.71 0.000942 30 0.1 0 5000");
        for (i = 0; i < 5000u; ++i) {
            len += (size_t)snprintf(text + len, sizeof text - len, " %u.%02u", (unsigned)(i % 9u),
                                    (unsigned)(i % 100u));
        }
        len += (size_t)snprintf(text + len, sizeof text - len,
                                " 0 0 0 0 0 0 0 0 0 0 0 0 7.5 nohost 7.5\n");
        err |= write_file(dir, "carmen", "long_line.txt", text, len);
    }
#ifdef BSF_HAVE_ZLIB
    {
        static uint8_t gz[8192];
        z_stream zs;
        len = flaser_line(text, sizeof text, 180u, 1.0);
        len += flaser_line(text + len, sizeof text - len, 181u, 2.0);
        memset(&zs, 0, sizeof zs);
        if (deflateInit2(&zs, 9, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
            return 1;
        }
        zs.next_in = (Bytef *)text;
        zs.avail_in = (uInt)len;
        zs.next_out = gz;
        zs.avail_out = (uInt)sizeof gz;
        if (deflate(&zs, Z_FINISH) != Z_STREAM_END) {
            return 1;
        }
        n = sizeof gz - zs.avail_out;
        deflateEnd(&zs);
        err |= write_file(dir, "carmen", "two_scans_gzip.seed", gz, n);
        err |= write_file(dir, "carmen", "two_scans_gzip_cut.seed", gz, n / 2u);

        /* a scan, then a line of 2 MiB (over the reader's line cap) in a few
         * KiB of gzip, then a scan */
        len = flaser_line(text, sizeof text, 180u, 1.0);
        memset(&zs, 0, sizeof zs);
        if (deflateInit2(&zs, 9, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
            return 1;
        }
        zs.next_out = gz;
        zs.avail_out = (uInt)sizeof gz;
        zs.next_in = (Bytef *)text;
        zs.avail_in = (uInt)len;
        if (deflate(&zs, Z_NO_FLUSH) != Z_OK) {
            return 1;
        }
        memset(text, 'a', 65536u);
        for (i = 0; i < 32u; ++i) {
            zs.next_in = (Bytef *)text;
            zs.avail_in = 65536u;
            if (deflate(&zs, Z_NO_FLUSH) != Z_OK) {
                return 1;
            }
        }
        text[0] = '\n';
        len = 1u + flaser_line(text + 1, sizeof text - 1u, 181u, 2.0);
        zs.next_in = (Bytef *)text;
        zs.avail_in = (uInt)len;
        if (deflate(&zs, Z_FINISH) != Z_STREAM_END) {
            return 1;
        }
        n = sizeof gz - zs.avail_out;
        deflateEnd(&zs);
        err |= write_file(dir, "carmen", "overlong_line_gzip.seed", gz, n);
    }
#endif
    return err;
}

int main(int argc, char **argv)
{
    static uint8_t buf[2u * BSF_MAX_POINTS + 16u];
    static const char *const carmen[] = {
        "# synthetic log\nFLASER 5 1.0 1.1 1.2 1.3 1.4 0.5 0.2 0.1 0.5 0.2 0.1 12.5 host 12.5\n",
        "ROBOTLASER1 0 -1.5708 3.1416 0.7854 30.0 0.01 0 5 2.0 2.1 nan 2.3 81.83 0 0.1 0.2 0.3 "
        "0.0 0.1 0.2 0.0 0.0 0.5 0.5 0.2 100.0 host 100.0\n",
        "ODOM 1 2 3 0 0 0 1.0 host 1.0\nFLASER 3 1 2 3 0 0 0 0 0 0 2.0 host 2.0\r\n"
        "FLASER x 1 2\nPARAM robot_length 0.5\n\nFLASER 181",
        "ROBOTLASER1 0 0 3.14 0 30 0.01 0 2 1 1 3 9 9 9 0 0 0 0 0 0 0 0 0 0 0 0 1 h 1\n"
        "ROBOTLASER1 0 1e300 3.14 1e-50 30 0.01 0 2 1 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1 h 1\n",
    };
    const char *dir;
    bsf_params_t p = bsf_params_default(BSF_METHOD_FALKO_SVED_PDM);
    bsf_scene_t scene;
    bsf_scene_rng_t rng;
    bsf_frame_info_t info;
    size_t k;
    size_t all_len = 0u;
    size_t frame0_len = 0u;
    static uint8_t all[4u * BSF_FRAME_MAX_SIZE];
    int err = 0;
    if (argc != 2) {
        fprintf(stderr, "usage: make_corpus DIR\n");
        return 2;
    }
    dir = argv[1];
    if (bsf_extractor_init(&ex, &p) != BSF_OK) {
        return 1;
    }
    bsf_scene_demo_office(&scene);
    bsf_scene_rng_seed(&rng, 7u);
    bsf_frame_info_init(&info);
    for (k = 0; k < 3u; ++k) {
        double x, y, th;
        bsf_lidar_t lid;
        bsf_scan_t sc;
        size_t len = 0u;
        size_t n;
        char name[64];
        bsf_scene_demo_pose((long)(k * 7u), 60, &x, &y, &th);
        lid = bsf_lidar_default(x, y, th, 361u, 1.5 * 3.14159265358979);
        lid.angle_min = -2.4;
        lid.angle_increment = 0.0005 * 26.0;
        lid.noise_sigma = 0.01;
        lid.range_max = 20.0;
        lid.no_return = 81.83f;
        if (bsf_scene_scan(&scene, &lid, &rng, ranges, NULL, BSF_MAX_POINTS) != BSF_OK) {
            return 1;
        }
        sc = bsf_scene_lidar_scan(&lid, ranges);
        sc.range_min = 0.05f;
        sc.range_max = 30.0f;
        if (bsf_extract(&ex, &sc, &res) < 0) {
            return 1;
        }
        if (k == 2u && res.stats.n_valid > res.stats.n_in_features) {
            /* a scan cut by a cap: the header extension's counters */
            res.stats.cut = BSF_CUT_SEGMENTS;
            res.stats.n_cut_segments = 1u;
            res.stats.n_cut_points = res.stats.n_valid - res.stats.n_in_features;
        }
        info.seq = (uint32_t)k;
        info.timestamp_ms = 100u * k;
        /* frame 1 carries its own geometry (header extension) */
        info.has_geometry = (uint8_t)(k == 1u);
        info.angle_min = sc.angle_min;
        info.angle_increment = sc.angle_increment;
        if (k == 1u && res.stats.n_beams == 0u) {
            res.stats.n_beams = (uint32_t)sc.count;
        }
        info.has_pose = (uint8_t)(k != 1u);
        info.pose.x = (float)x;
        info.pose.y = (float)y;
        info.pose.theta = (float)th;
        if (bsf_frame_encode(&info, &res, wire, sizeof wire, &len) != BSF_OK) {
            return 1;
        }
        /* stream input: chunk-size byte, then the frame */
        buf[0] = (uint8_t)(k * 13u);
        memcpy(buf + 1, wire, len);
        snprintf(name, sizeof name, "frame_%u.bin", (unsigned)k);
        err |= write_file(dir, "stream", name, buf, len + 1u);
        {
            /* payload mode: the COBS-decoded frame without its CRC */
            size_t blen = 0u;
            buf[0] = (uint8_t)(0x80u | (k * 5u));
            if (bsf_cobs_decode(wire, len - 1u, buf + 1, sizeof buf - 1u, &blen) != BSF_OK) {
                return 1;
            }
            snprintf(name, sizeof name, "payload_%u.bin", (unsigned)k);
            err |= write_file(dir, "stream", name, buf, blen - 4u + 1u);
        }
        memcpy(all + all_len, wire, len);
        all_len += len;
        if (k == 0u) {
            frame0_len = len;
        }
        n = extract_input(buf, lid.n_beams, (uint8_t)(k == 2u ? 0x21u : 0x20u));
        snprintf(name, sizeof name, "scan_%u.bin", (unsigned)k);
        err |= write_file(dir, "extract", name, buf, n);
    }
    /* before the metadata frame goes in front: the seeds use the first frame */
    err |= extra_seeds(dir, all, frame0_len, &scene, &rng);
    {
        /* a metadata frame, raw and as a payload */
        bsf_metadata_t meta;
        size_t len = 0u;
        size_t blen = 0u;
        bsf_metadata_init(&meta);
        meta.target_rms = 0.015f;
        meta.n_beams = 361u;
        meta.angle_min = -2.4f;
        meta.angle_increment = 0.013f;
        meta.range_min = 0.05f;
        meta.range_max = 30.0f;
        meta.has_time_origin = 1u;
        meta.time_origin_us = 1066286502361000LL;
        memcpy(meta.source, "demo.log\xC3\xA9", 10u);
        meta.source_len = 10u;
        if (bsf_metadata_encode(&meta, wire, sizeof wire, &len) != BSF_OK) {
            return 1;
        }
        buf[0] = 7u;
        memcpy(buf + 1, wire, len);
        err |= write_file(dir, "stream", "metadata.bin", buf, len + 1u);
        buf[0] = 0x80u;
        if (bsf_cobs_decode(wire, len - 1u, buf + 1, sizeof buf - 1u, &blen) != BSF_OK) {
            return 1;
        }
        err |= write_file(dir, "stream", "metadata_payload.bin", buf, blen - 4u + 1u);
        /* the stream as bsf extract writes it: metadata, then frames */
        memmove(all + len, all, all_len < sizeof all - len ? all_len : sizeof all - len);
        memcpy(all, wire, len);
        all_len = all_len + len < sizeof all ? all_len + len : sizeof all;
    }
    buf[0] = 63u;
    memcpy(buf + 1, all, all_len < sizeof buf - 1u ? all_len : sizeof buf - 1u);
    err |= write_file(dir, "stream", "three_frames.bin", buf,
                      (all_len < sizeof buf - 1u ? all_len : sizeof buf - 1u) + 1u);
    for (k = 0; k < sizeof carmen / sizeof carmen[0]; ++k) {
        char name[64];
        snprintf(name, sizeof name, "log_%u.txt", (unsigned)k);
        err |= write_file(dir, "carmen", name, carmen[k], strlen(carmen[k]));
    }
    return err;
}
