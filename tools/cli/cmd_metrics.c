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
    in = open_in(in_path);
    if (in == NULL) {
        return EXIT_FAIL;
    }
    rc = metrics_of_stream(in, in_path, &d, &sum);
    close_in(in);
    if (rc != 0) {
        return EXIT_FAIL;
    }
    print_metrics(stdout, in_path, &sum, &d);
    return close_out(stdout, "stdout") == 0 ? 0 : EXIT_FAIL;
}
