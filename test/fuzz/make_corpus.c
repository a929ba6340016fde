/* SPDX-License-Identifier: MIT */
/*
 * make_corpus - write the fuzzers' seed corpus (test/fuzz/corpus/) from the
 * project's own encoder and scenes: real frames of demo-office scans, the
 * same scans as extractor inputs, and a few synthetic CARMEN log lines.
 * Usage: make_corpus DIR   (DIR/stream, DIR/extract, DIR/carmen must exist)
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

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
        info.pose_x = (float)x;
        info.pose_y = (float)y;
        info.pose_theta = (float)th;
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
        n = extract_input(buf, lid.n_beams, (uint8_t)(k == 2u ? 0x21u : 0x20u));
        snprintf(name, sizeof name, "scan_%u.bin", (unsigned)k);
        err |= write_file(dir, "extract", name, buf, n);
    }
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
