/* SPDX-License-Identifier: MIT */
/*
 * stream_io.c - a bsf byte stream through the decoder (frames, counters,
 * sequence gaps), and the dataset metrics of a stream in bounded memory.
 */
#include "tool.h"

/* ---- decoding a stream ---------------------------------------------------- */

static bsf_decoder_t g_dec;
static bsf_frame_t g_frame;

/* read(2) what is there (a pipe or a serial device gives what has arrived
 * instead of waiting for a whole block), retried after a signal. */
static ssize_t read_some(int fd, uint8_t *buf, size_t cap)
{
    ssize_t n;
    do {
        n = read(fd, buf, cap);
    } while (n < 0 && errno == EINTR);
    return n;
}

/* The last 0x00 of p[0 .. n-1], or NULL. */
static const uint8_t *last_zero_in(const uint8_t *p, size_t n)
{
    while (n > 0u) {
        if (p[--n] == 0u) {
            return p + n;
        }
    }
    return NULL;
}

/* Bookkeeping of one delivered frame: sequence gaps (features and map frames
 * each have their own numbers; a metadata frame has none), counts, then the
 * callback. */
static int deliver(stream_summary_t *sum, frame_cb on_frame, void *ctx, size_t bytes)
{
    if (g_frame.type == BSF_FRAME_TYPE_METADATA) {
        ++sum->n_metadata;
        sum->metadata_bytes += bytes;
    } else if (g_frame.type == BSF_FRAME_TYPE_MAP) {
        /* map frames number themselves apart from features frames */
        if (sum->have_map_seq && g_frame.seq != sum->last_map_seq + 1u) {
            const uint32_t gap = g_frame.seq - sum->last_map_seq - 1u;
            if (gap < 0x80000000u) {
                sum->map_seq_gaps += gap;
            }
        }
        sum->have_map_seq = 1;
        sum->last_map_seq = g_frame.seq;
        sum->dropped_at_last_map = frames_dropped(&g_dec.stats);
        ++sum->n_map_frames;
        sum->map_frame_bytes += bytes;
    } else {
        if (sum->have_seq && g_frame.seq != sum->last_seq + 1u) {
            const uint32_t gap = g_frame.seq - sum->last_seq - 1u;
            if (gap < 0x80000000u) {
                sum->seq_gaps += gap;
            }
        }
        sum->have_seq = 1;
        sum->last_seq = g_frame.seq;
        ++sum->n_scans;
    }
    return on_frame != NULL ? on_frame(ctx, &g_frame, bytes) : 0;
}

int decode_stream(FILE *in, const char *name, frame_cb on_frame, void *ctx, stream_summary_t *sum)
{
    static uint8_t buf[65536];
    const int fd = fileno(in);
    /* Wire position just after the last 0x00 seen: where the next frame
     * starts, so that a frame's size is its own (garbage before it and
     * empty frames are not counted in it). */
    unsigned long long frame_start = 0;
    ssize_t got;

    memset(sum, 0, sizeof *sum);
    bsf_decoder_init(&g_dec);
    while ((got = read_some(fd, buf, sizeof buf)) > 0) {
        size_t off = 0;
        while (off < (size_t)got) {
            size_t used = 0;
            const int r = bsf_decoder_feed(&g_dec, buf + off, (size_t)got - off, &used, &g_frame);
            const uint8_t *last_zero;
            if (r < 0) {
                fail_msg("%s: decoder error (%s)", name, bsf_status_str((bsf_status_t)r));
                return -1;
            }
            if (r > 0) {
                /* the frame ends with the delimiter at buf[off + used - 1] */
                const unsigned long long end = sum->bytes_in + used;
                const uint8_t *z = last_zero_in(buf + off, used - 1u);
                const unsigned long long start =
                    z != NULL ? sum->bytes_in + (unsigned long long)(z - (buf + off)) + 1u
                              : frame_start;
                sum->bytes_in = end;
                frame_start = end;
                off += used;
                if (deliver(sum, on_frame, ctx, (size_t)(end - start)) != 0) {
                    return -1;
                }
                continue;
            }
            last_zero = last_zero_in(buf + off, used);
            if (last_zero != NULL) {
                frame_start = sum->bytes_in + (unsigned long long)(last_zero - (buf + off)) + 1u;
            }
            sum->bytes_in += used;
            off += used;
            if (used == 0u) {
                break;
            }
        }
    }
    if (got < 0) {
        fail_msg("%s: read error: %s", name, strerror(errno));
        return -1;
    }
    /* A stream that ends without a delimiter leaves a partial frame behind.
     * A frame complete but for its delimiter is intact: it is delivered
     * (and its sequence gap counted) like any other; else it is dropped. */
    {
        static const uint8_t zero = 0u;
        size_t used = 0;
        const int r = bsf_decoder_feed(&g_dec, &zero, 1u, &used, &g_frame);
        if (r > 0 && deliver(sum, on_frame, ctx, (size_t)(sum->bytes_in + 1u - frame_start)) != 0) {
            return -1;
        }
    }
    sum->stats = g_dec.stats;
    if (sum->bytes_in > 0u && sum->stats.frames_ok == 0u) {
        fail_msg("%s: no valid bsf frame in %llu bytes (%lu bytes skipped: bad crc %lu, malformed "
                 "%lu, unsupported version %lu, unknown type %lu, oversize %lu)",
                 name, sum->bytes_in, (unsigned long)sum->stats.bytes_skipped,
                 (unsigned long)sum->stats.bad_crc, (unsigned long)sum->stats.malformed,
                 (unsigned long)sum->stats.unsupported_version,
                 (unsigned long)sum->stats.unknown_type, (unsigned long)sum->stats.oversize);
        return -1;
    }
    return 0;
}

FILE *open_seekable(const char *path)
{
    static uint8_t buf[65536];
    FILE *in = open_in(path);
    FILE *tmp;
    ssize_t got;
    if (in == NULL || lseek(fileno(in), 0, SEEK_CUR) >= 0) {
        return in;
    }
    /* A pipe: spool it to an unnamed temporary file (memory stays bounded). */
    tmp = tmpfile();
    if (tmp == NULL) {
        fail_msg("cannot create a temporary file for %s: %s", path, strerror(errno));
        return NULL;
    }
    while ((got = read_some(fileno(in), buf, sizeof buf)) > 0) {
        if (write(fileno(tmp), buf, (size_t)got) != got) {
            fail_msg("cannot spool %s to a temporary file: %s", path, strerror(errno));
            fclose(tmp);
            return NULL;
        }
    }
    if (got < 0) {
        fail_msg("%s: read error: %s", path, strerror(errno));
        fclose(tmp);
        return NULL;
    }
    if (lseek(fileno(tmp), 0, SEEK_SET) != 0) {
        fail_msg("cannot rewind the temporary file: %s", strerror(errno));
        fclose(tmp);
        return NULL;
    }
    return tmp;
}

int rewind_input(FILE *in, const char *name)
{
    if (lseek(fileno(in), 0, SEEK_SET) != 0) {
        fail_msg("%s: cannot read it again: %s", name, strerror(errno));
        return -1;
    }
    return 0;
}

void close_in(FILE *in)
{
    if (in != NULL && in != stdin) {
        fclose(in);
    }
}

unsigned long frames_dropped(const bsf_decoder_stats_t *s)
{
    return (unsigned long)s->bad_crc + s->malformed + s->unsupported_version + s->oversize;
}

void note_trailing_loss(bsf_map_rx_t *rx, const stream_summary_t *sum)
{
    if (sum->n_map_frames > 0u && frames_dropped(&sum->stats) != sum->dropped_at_last_map) {
        bsf_map_rx_note_loss(rx);
    }
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

/* Largest extraction time a frame carries, microseconds (FORMAT.md). */
#define TOOL_TIME_US_MAX 4294967u

/*
 * Exact quantiles in bounded memory: the wire carries extraction times as
 * whole microseconds (0 .. 4 294 967) and frame sizes are at most
 * BSF_FRAME_MAX_SIZE bytes, so a counting histogram over each holds every
 * sample whatever the stream's length. The time histogram is 17 MB of
 * address space, of which only the pages of times that occur are touched.
 */
typedef struct {
    bsf_metrics_acc_t acc;
    uint32_t *time_hist; /* TOOL_TIME_US_MAX + 1 counters */
    uint32_t bytes_hist[BSF_FRAME_MAX_SIZE + 2u];
    unsigned long long n_time;
    double sum_time_s;
    unsigned long long n_bytes;
    unsigned long long sum_bytes;
    unsigned long n_cut_scans;
    unsigned long long cut_keypoints, cut_segments, cut_points;
    int failed;
} metrics_stream_t;

static metrics_stream_t g_ms;

/* The value of nearest rank ceil(p_num / p_den * n) in a histogram. */
static size_t hist_rank(const uint32_t *hist, size_t n_bins, unsigned long long n,
                        unsigned long long p_num, unsigned long long p_den)
{
    unsigned long long rank = (p_num * n + p_den - 1u) / p_den;
    unsigned long long seen = 0;
    size_t i;
    if (rank < 1u) {
        rank = 1u;
    }
    for (i = 0; i < n_bins; ++i) {
        seen += hist[i];
        if (seen >= rank) {
            return i;
        }
    }
    return n_bins - 1u;
}

static float time_s_of_us(size_t us)
{
    bsf_result_t *r = &g_res; /* shared scratch: only its stats are read */
    memset(&r->stats, 0, sizeof r->stats);
    r->n_features = 0u;
    r->n_ctrl = 0u;
    r->stats.time_ns = (uint32_t)us * 1000u;
    return counts_of_result(r).time_s;
}

static int metrics_frame(void *ctx, const bsf_frame_t *f, size_t bytes)
{
    metrics_stream_t *ms = (metrics_stream_t *)ctx;
    bsf_scan_counts_t c;
    if (f->type != BSF_FRAME_TYPE_FEATURES) {
        return 0;
    }
    c = counts_of_result(&f->result);
    if (c.time_s >= 0.0f) {
        ++ms->time_hist[f->time_us <= TOOL_TIME_US_MAX ? f->time_us : TOOL_TIME_US_MAX];
        ++ms->n_time;
        ms->sum_time_s += (double)c.time_s;
    }
    c.time_s = -1.0f; /* time quantiles come from the histogram */
    if (bsf_metrics_acc_add(&ms->acc, &c) != BSF_OK) {
        fail_msg("frame seq %lu has inconsistent counts", (unsigned long)f->seq);
        return -1;
    }
    ++ms->bytes_hist[bytes <= BSF_FRAME_MAX_SIZE ? bytes : BSF_FRAME_MAX_SIZE + 1u];
    ++ms->n_bytes;
    ms->sum_bytes += bytes;
    if (f->result.stats.cut != 0u) {
        ++ms->n_cut_scans;
        ms->cut_keypoints += f->result.stats.n_cut_keypoints;
        ms->cut_segments += f->result.stats.n_cut_segments;
        ms->cut_points += f->result.stats.n_cut_points;
    }
    return 0;
}

int metrics_of_stream(FILE *in, const char *name, dataset_metrics_t *out, stream_summary_t *sum)
{
    metrics_stream_t *ms = &g_ms;
    int rc;
    memset(ms, 0, sizeof *ms);
    memset(out, 0, sizeof *out);
    ms->time_hist = (uint32_t *)calloc((size_t)TOOL_TIME_US_MAX + 1u, sizeof(uint32_t));
    if (ms->time_hist == NULL || bsf_metrics_acc_init(&ms->acc, NULL, 0u) != BSF_OK) {
        free(ms->time_hist);
        fail_msg("out of memory");
        return -1;
    }
    rc = decode_stream(in, name, metrics_frame, ms, sum);
    if (rc == 0 && bsf_metrics_acc_summary(&ms->acc, &out->m) != BSF_OK) {
        fail_msg("%s: metrics cannot be summarised", name);
        rc = -1;
    }
    if (rc == 0) {
        out->m.n_time = (uint32_t)ms->n_time;
        if (ms->n_time > 0u) {
            out->m.time_mean_s = (float)(ms->sum_time_s / (double)ms->n_time);
            out->m.time_median_s = time_s_of_us(
                hist_rank(ms->time_hist, (size_t)TOOL_TIME_US_MAX + 1u, ms->n_time, 1u, 2u));
            out->m.time_p99_s = time_s_of_us(
                hist_rank(ms->time_hist, (size_t)TOOL_TIME_US_MAX + 1u, ms->n_time, 99u, 100u));
        }
        if (ms->n_bytes > 0u) {
            out->bytes_median =
                hist_rank(ms->bytes_hist, BSF_FRAME_MAX_SIZE + 2u, ms->n_bytes, 1u, 2u);
            out->bytes_p95 =
                hist_rank(ms->bytes_hist, BSF_FRAME_MAX_SIZE + 2u, ms->n_bytes, 95u, 100u);
            out->bytes_mean = (double)ms->sum_bytes / (double)ms->n_bytes;
        }
        out->n_cut_scans = ms->n_cut_scans;
        out->cut_keypoints = ms->cut_keypoints;
        out->cut_segments = ms->cut_segments;
        out->cut_points = ms->cut_points;
    }
    free(ms->time_hist);
    ms->time_hist = NULL;
    return rc;
}
