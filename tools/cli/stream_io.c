/* SPDX-License-Identifier: MIT */
/*
 * stream_io.c - a bsf byte stream through the decoder (frames, counters,
 * sequence gaps), and the dataset metrics of decoded frames.
 */
#include "tool.h"

/* ---- decoded stream in memory ------------------------------------------------ */

void frame_list_free(frame_list_t *l)
{
    free(l->frames);
    free(l->frame_bytes);
    memset(l, 0, sizeof *l);
}

static bsf_decoder_t g_dec;
static bsf_frame_t g_frame;

int decode_stream(FILE *in, const char *name, frame_cb on_frame, void *ctx,
                  bsf_decoder_stats_t *stats_out, unsigned long *seq_gaps)
{
    static uint8_t buf[65536];
    size_t got;
    size_t frame_start_bytes = 0;
    size_t total = 0;
    int have_seq = 0;
    uint32_t last_seq = 0;

    bsf_decoder_init(&g_dec);
    *seq_gaps = 0;
    while ((got = fread(buf, 1, sizeof buf, in)) > 0) {
        size_t off = 0;
        while (off < got) {
            size_t used = 0;
            const int r = bsf_decoder_feed(&g_dec, buf + off, got - off, &used, &g_frame);
            if (r < 0) {
                fail_msg("%s: decoder error (%s)", name, bsf_status_str((bsf_status_t)r));
                return -1;
            }
            off += used;
            total += used;
            if (r == 1) {
                const size_t bytes = total - frame_start_bytes;
                frame_start_bytes = total;
                if (have_seq && g_frame.seq != last_seq + 1u) {
                    const uint32_t gap = g_frame.seq - last_seq - 1u;
                    if (gap < 0x80000000u) {
                        *seq_gaps += gap;
                    }
                }
                have_seq = 1;
                last_seq = g_frame.seq;
                if (on_frame != NULL && on_frame(ctx, &g_frame, bytes) != 0) {
                    return -1;
                }
            }
            if (used == 0 && r == 0) {
                break;
            }
        }
    }
    if (ferror(in)) {
        fail_msg("%s: read error", name);
        return -1;
    }
    /* A stream that ends without a delimiter leaves a partial frame behind:
     * it is counted as dropped, never used. */
    {
        static const uint8_t zero = 0u;
        size_t used = 0;
        const int r = bsf_decoder_feed(&g_dec, &zero, 1u, &used, &g_frame);
        if (r == 1 && on_frame != NULL) {
            /* a frame complete but for its delimiter is intact: use it */
            if (on_frame(ctx, &g_frame, total + 1u - frame_start_bytes) != 0) {
                return -1;
            }
        }
    }
    *stats_out = g_dec.stats;
    return 0;
}

static int store_frame(void *ctx, const bsf_frame_t *f, size_t bytes)
{
    frame_list_t *l = (frame_list_t *)ctx;
    if (l->n == l->cap) {
        const size_t cap = l->cap ? 2u * l->cap : 256u;
        bsf_frame_t *nf = (bsf_frame_t *)realloc(l->frames, cap * sizeof *nf);
        size_t *nb;
        if (nf == NULL) {
            fail_msg("out of memory after %zu frames", l->n);
            return -1;
        }
        l->frames = nf;
        nb = (size_t *)realloc(l->frame_bytes, cap * sizeof *nb);
        if (nb == NULL) {
            fail_msg("out of memory after %zu frames", l->n);
            return -1;
        }
        l->frame_bytes = nb;
        l->cap = cap;
    }
    l->frames[l->n] = *f;
    l->frame_bytes[l->n] = bytes;
    l->n++;
    return 0;
}

int load_frames(const char *path, frame_list_t *l)
{
    FILE *in = open_in(path);
    int rc;
    memset(l, 0, sizeof *l);
    if (in == NULL) {
        return -1;
    }
    rc = decode_stream(in, path, store_frame, l, &l->stats, &l->seq_gaps);
    if (in != stdin) {
        fclose(in);
    }
    return rc;
}

unsigned long frames_dropped(const bsf_decoder_stats_t *s)
{
    return (unsigned long)s->bad_crc + s->malformed + s->unsupported_version + s->oversize;
}

/* ---- metrics ------------------------------------------------------------------ */

/* A result's metric counts; the library's own definition (time from the
 * result's stats: for a decoded frame, the extraction time it carries). */
bsf_scan_counts_t counts_of_result(const bsf_result_t *r)
{
    bsf_scan_counts_t c;
    if (bsf_metrics_counts(r, &c) != BSF_OK) {
        memset(&c, 0, sizeof c);
    }
    return c;
}

static int cmp_size(const void *a, const void *b)
{
    const size_t x = *(const size_t *)a;
    const size_t y = *(const size_t *)b;
    return (x > y) - (x < y);
}

size_t nearest_rank_size(size_t *v, size_t n, double p)
{
    size_t rank;
    if (n == 0) {
        return 0;
    }
    qsort(v, n, sizeof *v, cmp_size);
    rank = (size_t)ceil(p * (double)n);
    if (rank < 1) {
        rank = 1;
    }
    if (rank > n) {
        rank = n;
    }
    return v[rank - 1];
}

int metrics_of_frames(const frame_list_t *l, dataset_metrics_t *out)
{
    bsf_metrics_acc_t acc;
    float *times = (float *)malloc((l->n ? l->n : 1u) * sizeof(float));
    size_t *bytes = (size_t *)malloc((l->n ? l->n : 1u) * sizeof(size_t));
    size_t i;
    double sum_bytes = 0.0;
    int rc = 0;

    if (times == NULL || bytes == NULL || bsf_metrics_acc_init(&acc, times, l->n) != BSF_OK) {
        free(times);
        free(bytes);
        fail_msg("out of memory");
        return -1;
    }
    for (i = 0; i < l->n && rc == 0; ++i) {
        const bsf_frame_t *f = &l->frames[i];
        const bsf_scan_counts_t c = counts_of_result(&f->result);
        if (bsf_metrics_acc_add(&acc, &c) != BSF_OK) {
            fail_msg("frame seq %lu has inconsistent counts", (unsigned long)f->seq);
            rc = -1;
        }
        bytes[i] = l->frame_bytes[i];
        sum_bytes += (double)l->frame_bytes[i];
    }
    if (rc == 0 && bsf_metrics_acc_summary(&acc, &out->m) != BSF_OK) {
        rc = -1;
    }
    out->bytes_mean = l->n ? sum_bytes / (double)l->n : 0.0;
    out->bytes_median = nearest_rank_size(bytes, l->n, 0.5);
    out->bytes_p95 = nearest_rank_size(bytes, l->n, 0.95);
    free(times);
    free(bytes);
    return rc;
}
