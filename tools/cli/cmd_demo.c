/* SPDX-License-Identifier: MIT */
/*
 * cmd_demo.c - bsf demo: the built-in synthetic office, end to end.
 */
#include "tool.h"

static const char demo_help[] =
    "Usage: bsf demo [--scans N] [--method M] [--stream FILE] [--svg FILE]\n"
    "No files needed: a robot drives through a built-in synthetic office (walls,\n"
    "corners, a round pillar) with a noisy 361-beam LIDAR; bsf extracts every scan,\n"
    "encodes it into a stream (default demo.bsf), decodes the stream, prints the\n"
    "metrics and draws the map (default demo.svg) over the true walls.\n";

int cmd_demo(int argc, char **argv)
{
    static float ranges[BSF_MAX_POINTS];
    const char *stream_path = "demo.bsf", *svg_path = "demo.svg";
    bsf_method_t method = BSF_METHOD_DEFAULT;
    long n_scans = 60;
    bsf_scene_t scene;
    bsf_scene_rng_t rng;
    bsf_frame_info_t info;
    stream_summary_t sum;
    dataset_metrics_t dm;
    FILE *out;
    FILE *in;
    int rc;
    long k;
    int i, err = 0;
    for (i = 1; i < argc; ++i) {
        const char *v;
        if (is_help(argv[i])) {
            fputs(demo_help, stdout);
            return 0;
        } else if ((v = opt_value(argc, argv, &i, "--scans", &err)) != NULL) {
            if (parse_long(v, 1, 100000L, &n_scans) != 0) {
                return usage_error("--scans needs 1..100000, got '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--method", &err)) != NULL) {
            method = bsf_method_from_name(v);
            if (method == BSF_METHOD_COUNT) {
                return usage_error("unknown method '%s'", v);
            }
        } else if ((v = opt_value(argc, argv, &i, "--stream", &err)) != NULL) {
            stream_path = v;
        } else if ((v = opt_value(argc, argv, &i, "--svg", &err)) != NULL) {
            svg_path = v;
        } else if (err) {
            return err;
        } else {
            return usage_error("unknown argument '%s'", argv[i]);
        }
        if (err) {
            return err;
        }
    }
    bsf_scene_demo_office(&scene);
    bsf_scene_rng_seed(&rng, 2026u);
    if (init_extractor(method) != 0) {
        return EXIT_FAIL;
    }
    out = open_out(stream_path, 1);
    if (out == NULL) {
        return EXIT_FAIL;
    }
    bsf_frame_info_init(&info);
    for (k = 0; k < n_scans; ++k) {
        double x, y, th;
        bsf_lidar_t lid;
        bsf_scan_t sc;
        size_t len = 0;
        bsf_status_t st;
        bsf_scene_demo_pose(k, n_scans, &x, &y, &th);
        lid = bsf_lidar_default(x, y, th, 361u, 1.5 * M_PI);
        lid.noise_sigma = 0.01;
        lid.range_max = 20.0;
        lid.no_return = 81.83f;
        if (bsf_scene_scan(&scene, &lid, &rng, ranges, NULL, BSF_MAX_POINTS) != BSF_OK) {
            fail_msg("scene simulation failed");
            fclose(out);
            return EXIT_FAIL;
        }
        sc.ranges = ranges;
        sc.count = lid.n_beams;
        sc.angle_min = (float)lid.angle_min;
        sc.angle_increment = (float)lid.angle_increment;
        sc.range_min = 0.05f;
        sc.range_max = 30.0f;
        if (k == 0) {
            /* the stream says what produced it (FORMAT.md section 3.6) */
            bsf_metadata_t meta;
            size_t mlen = 0;
            fill_metadata(&meta, &sc, info.quant_step);
            if (bsf_metadata_encode(&meta, g_frame_buf, sizeof g_frame_buf, &mlen) != BSF_OK ||
                fwrite(g_frame_buf, 1, mlen, out) != mlen) {
                fail_msg("cannot write the metadata frame to %s", stream_path);
                fclose(out);
                return EXIT_FAIL;
            }
        }
        st = bsf_extract(&g_ex, &sc, &g_res);
        if (st >= 0) { /* BSF_OK, or BSF_OK_CUT: what fits the caps */
            info.seq = (uint32_t)k;
            info.timestamp_ms = (uint64_t)(100 * k);
            info.has_pose = 1u;
            info.pose.x = (float)x;
            info.pose.y = (float)y;
            info.pose.theta = (float)remainder(th, 2.0 * M_PI);
            st = bsf_frame_encode(&info, &g_res, g_frame_buf, sizeof g_frame_buf, &len);
        }
        if (st != BSF_OK) {
            fail_msg("scan %ld: %s", k, bsf_status_str(st));
            fclose(out);
            return EXIT_FAIL;
        }
        if (fwrite(g_frame_buf, 1, len, out) != len) {
            fail_msg("write error on %s", stream_path);
            fclose(out);
            return EXIT_FAIL;
        }
    }
    if (close_out(out, stream_path) != 0) {
        return EXIT_FAIL;
    }
    in = open_in(stream_path);
    if (in == NULL) {
        return EXIT_FAIL;
    }
    if (metrics_of_stream(in, stream_path, &dm, &sum) != 0) {
        close_in(in);
        return EXIT_FAIL;
    }
    printf("bsf demo: %ld synthetic scans (361 beams, 1 cm noise) with %s\n", n_scans,
           bsf_method_name(method));
    print_metrics(stdout, stream_path, &sum, &dm);
    rc = write_map_svg(svg_path, in, stream_path, 0, -1, NULL, &scene, NULL,
                       "bsf demo: synthetic office", 1600.0);
    close_in(in);
    if (rc != 0) {
        return EXIT_FAIL;
    }
    printf("map               %s\n", svg_path);
    if (sum.n_scans != (unsigned long)n_scans || frames_dropped(&sum.stats) != 0) {
        fail_msg("the stream did not round-trip: %lu of %ld frames decoded", sum.n_scans, n_scans);
        return EXIT_FAIL;
    }
    return 0;
}
