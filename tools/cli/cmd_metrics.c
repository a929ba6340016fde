/* SPDX-License-Identifier: MIT */
/*
 * cmd_metrics.c - bsf metrics: the paper's metrics of a stream.
 */
#include "tool.h"

static const char metrics_help[] =
    "Usage: bsf metrics IN\n"
    "The paper's metrics computed from a bsf stream alone ('-' for stdin):\n"
    "retrievability, compactness, accuracy, extraction time (mean, median, p99),\n"
    "features and control points per scan, bytes per scan (median, p95), metadata\n"
    "frames, scans cut by a cap, frames dropped, intact frames of a type this build\n"
    "does not know. Memory does not grow with the stream (medians are exact:\n"
    "counting histograms over the wire's integer units).\n"
    "A map stream (bsf extract --map) also gets its map's bytes: map frames, of which\n"
    "pose-only frames, the metadata and anything else, and the map the receiver\n"
    "rebuilds (features, control points, stale features, missing ids).\n"
    "Exits 1 when a non-empty input holds no valid frame.\n";

void print_metrics(FILE *f, const char *name, const stream_summary_t *s, const dataset_metrics_t *d)
{
    fprintf(f, "stream            %s\n", name);
    fprintf(f, "scans             %lu\n", (unsigned long)d->m.n_scans);
    fprintf(f, "retrievability    %.2f %%\n", 100.0 * (double)d->m.retrievability);
    fprintf(f, "compactness       %.4f\n", (double)d->m.compactness);
    fprintf(f, "accuracy          %.5f m\n", (double)d->m.accuracy);
    fprintf(f, "time              mean %.1f us, median %.1f us, p99 %.1f us\n",
            1e6 * (double)d->m.time_mean_s, 1e6 * (double)d->m.time_median_s,
            1e6 * (double)d->m.time_p99_s);
    fprintf(f, "features/scan     %.2f\n", (double)d->m.features_per_scan);
    fprintf(f, "ctrl points/scan  %.2f\n", (double)d->m.ctrl_per_scan);
    fprintf(f, "bytes/scan        median %zu, p95 %zu, mean %.1f\n", d->bytes_median, d->bytes_p95,
            d->bytes_mean);
    fprintf(f, "metadata frames   %lu (%llu bytes, %.2f per scan)\n", s->n_metadata,
            s->metadata_bytes,
            d->m.n_scans ? (double)s->metadata_bytes / (double)d->m.n_scans : 0.0);
    fprintf(f,
            "cut by a cap      %lu scans (dropped: %llu keypoints, %llu segments, %llu points)\n",
            d->n_cut_scans, d->cut_keypoints, d->cut_segments, d->cut_points);
    fprintf(f,
            "frames dropped    %lu (bad crc %lu, malformed %lu, unsupported %lu, oversize %lu), "
            "missing by sequence %lu\n",
            frames_dropped(&s->stats), (unsigned long)s->stats.bad_crc,
            (unsigned long)s->stats.malformed, (unsigned long)s->stats.unsupported_version,
            (unsigned long)s->stats.oversize, s->seq_gaps);
    /* intact frames of a type this build does not know (a newer sender's):
     * not damage, but not in any figure above either */
    fprintf(f, "unknown type      %lu frames (skipped)\n", (unsigned long)s->stats.unknown_type);
}

/* The map section: a second pass through the receiver. */
typedef struct {
    map_view_t view;
    int failed;
} metrics_map_ctx_t;

static int metrics_map_frame(void *vctx, const bsf_frame_t *f, size_t bytes)
{
    metrics_map_ctx_t *c = (metrics_map_ctx_t *)vctx;
    if (f->type == BSF_FRAME_TYPE_MAP && map_view_apply(&c->view, f, bytes, NULL) != 0) {
        c->failed = 1;
    }
    return 0;
}

static int print_map_metrics(FILE *in, const char *name, const stream_summary_t *s)
{
    static metrics_map_ctx_t c;
    stream_summary_t s2;
    const unsigned long long other = s->bytes_in - s->map_frame_bytes - s->metadata_bytes;
    unsigned long features = 0, ctrl = 0, stale = 0, missing = 0;
    uint32_t id;
    memset(&c, 0, sizeof c);
    if (map_view_init(&c.view, 0) != 0) {
        return -1;
    }
    if (rewind_input(in, name) != 0 || decode_stream(in, name, metrics_map_frame, &c, &s2) != 0) {
        map_view_free(&c.view);
        return -1;
    }
    note_trailing_loss(c.view.rx, &s2);
    for (id = 0; id < bsf_map_rx_id_limit(c.view.rx); ++id) {
        uint8_t st = 0;
        const int n = bsf_map_rx_feature_ctrl(c.view.rx, id, NULL, NULL, 0u, &st);
        if (n > 0) {
            ++features;
            ctrl += (unsigned long)n;
            stale += st;
        } else if (bsf_map_rx_feature_state(c.view.rx, id) == BSF_MAP_RX_MISSING) {
            ++missing;
        }
    }
    {
        const unsigned long long pose = c.view.pose_only_bytes + c.view.pose_record_bytes;
        printf("map frames        %lu, %llu bytes: map %llu, pose %llu (%lu pose records; %lu "
               "pose-only frames)\n",
               s->n_map_frames, s->map_frame_bytes, s->map_frame_bytes - pose, pose,
               (unsigned long)c.view.rx->stats.poses, c.view.pose_only_frames);
    }
    printf("other bytes       %llu metadata, %llu per-scan frames and unframed bytes\n",
           s->metadata_bytes, other);
    printf("map               %lu features, %lu control points (vertices twice), %lu stale, "
           "%lu missing; %lu map frames missing by sequence, %lu records skipped, %lu frames "
           "refused\n",
           features, ctrl, stale, missing, s->map_seq_gaps,
           (unsigned long)c.view.rx->stats.records_skipped, c.failed ? c.view.frames_bad : 0ul);
    map_view_free(&c.view);
    return 0;
}

int cmd_metrics(int argc, char **argv)
{
    const char *in_path = NULL;
    stream_summary_t sum;
    dataset_metrics_t d;
    FILE *in;
    int i, rc;
    for (i = 1; i < argc; ++i) {
        if (is_help(argv[i])) {
            fputs(metrics_help, stdout);
            return 0;
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            return usage_error("unknown option '%s'", argv[i]);
        } else if (in_path == NULL) {
            in_path = argv[i];
        } else {
            return usage_error("metrics takes one input, got '%s' too", argv[i]);
        }
    }
    if (in_path == NULL) {
        return usage_error("metrics needs an input stream (or '-')");
    }
    in = open_seekable(in_path);
    if (in == NULL) {
        return EXIT_FAIL;
    }
    rc = metrics_of_stream(in, in_path, &d, &sum);
    if (rc != 0) {
        close_in(in);
        return EXIT_FAIL;
    }
    print_metrics(stdout, in_path, &sum, &d);
    if (sum.n_map_frames > 0u && print_map_metrics(in, in_path, &sum) != 0) {
        close_in(in);
        return EXIT_FAIL;
    }
    close_in(in);
    return close_out(stdout, "stdout") == 0 ? 0 : EXIT_FAIL;
}
