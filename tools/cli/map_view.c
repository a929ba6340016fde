/* SPDX-License-Identifier: MIT */
/*
 * map_view.c - the receiver's map of a map stream, for bsf map, listen and
 * metrics: the library's receiver (bsf_map_rx_apply) fed frame by frame, the
 * path of the pose records, and what each frame changed, found by comparing
 * every feature before and after (so the tool needs no knowledge of the
 * record layout).
 */
#include "tool.h"

/* Largest number of distinct points of one receiver feature. */
#define VIEW_MAX_POINTS BSF_MAP_RX_MAX_CTRL

int map_view_init(map_view_t *v, int track)
{
    memset(v, 0, sizeof *v);
    v->rx = (bsf_map_rx_t *)malloc(sizeof *v->rx);
    if (track) {
        v->n_ctrl = (uint32_t *)calloc(BSF_MAP_RX_MAX_FEATURES, sizeof(uint32_t));
        v->hash = (uint32_t *)calloc(BSF_MAP_RX_MAX_FEATURES, sizeof(uint32_t));
    }
    if (v->rx == NULL || (track && (v->n_ctrl == NULL || v->hash == NULL))) {
        map_view_free(v);
        fail_msg("out of memory");
        return -1;
    }
    bsf_map_rx_init(v->rx);
    v->track = track;
    return 0;
}

void map_view_free(map_view_t *v)
{
    free(v->rx);
    free(v->n_ctrl);
    free(v->hash);
    free(v->path);
    memset(v, 0, sizeof *v);
}

/* Points and hash of receiver feature id (FNV-1a over the quantised values
 * and vertex flags): the number of distinct points, 0 when absent. */
static uint32_t feature_state(const bsf_map_rx_t *rx, uint32_t id, uint32_t *hash)
{
    static int32_t q[2u * VIEW_MAX_POINTS];
    static uint8_t vtx[VIEW_MAX_POINTS];
    const int n = bsf_map_rx_feature_q(rx, id, q, vtx, VIEW_MAX_POINTS);
    uint32_t h = 2166136261u;
    int k;
    if (n <= 0) {
        *hash = 0u;
        return 0u;
    }
    for (k = 0; k < n && k < (int)VIEW_MAX_POINTS; ++k) {
        const uint32_t words[3] = {(uint32_t)q[2 * k], (uint32_t)q[2 * k + 1], vtx[k]};
        int w;
        for (w = 0; w < 3; ++w) {
            h = (h ^ (words[w] & 0xFFFFu)) * 16777619u;
            h = (h ^ (words[w] >> 16)) * 16777619u;
        }
    }
    *hash = h;
    return (uint32_t)n;
}

static int path_push(map_view_t *v, const bsf_pose_t *p)
{
    if (v->n_path == v->cap_path) {
        const size_t nc = v->cap_path ? 2u * v->cap_path : 1024u;
        double *q = (double *)realloc(v->path, 3u * nc * sizeof(double));
        if (q == NULL) {
            fail_msg("out of memory");
            return -1;
        }
        v->path = q;
        v->cap_path = nc;
    }
    v->path[3u * v->n_path] = (double)p->x;
    v->path[3u * v->n_path + 1u] = (double)p->y;
    v->path[3u * v->n_path + 2u] = (double)p->theta;
    ++v->n_path;
    return 0;
}

static unsigned varint_len(uint32_t v)
{
    unsigned n = 1;
    while (v >= 0x80u) {
        v >>= 7;
        ++n;
    }
    return n;
}

static uint32_t zigzag(long v)
{
    return v < 0 ? (uint32_t)(-2L * v - 1L) : (uint32_t)(2L * v);
}

/* Bytes of a pose record on the wire (before COBS): a tag byte, then x and
 * y in millimetres (zigzag varints) and theta in 65536ths of a turn (a
 * varint), as docs/FORMAT.md lays it out; recomputed from the decoded pose,
 * which holds exactly those integers. */
static unsigned pose_record_bytes(const bsf_pose_t *p)
{
    const long x = lround((double)p->x * 1000.0), y = lround((double)p->y * 1000.0);
    long th = lround((double)p->theta * (65536.0 / (2.0 * M_PI))) % 65536L;
    th = th < 0 ? th + 65536L : th;
    return 1u + varint_len(zigzag(x)) + varint_len(zigzag(y)) + varint_len((uint32_t)th);
}

int map_view_apply(map_view_t *v, const bsf_frame_t *f, size_t bytes, map_change_t *chg)
{
    const bsf_map_rx_stats_t before = v->rx->stats;
    const uint32_t limit_before = bsf_map_rx_id_limit(v->rx);
    int r;
    if (chg != NULL) {
        memset(chg, 0, sizeof *chg);
    }
    r = bsf_map_rx_apply(v->rx, f->payload, f->payload_len);
    if (r < 0) {
        ++v->frames_bad;
        fail_msg("map frame %lu refused by the receiver: %s", (unsigned long)f->seq,
                 bsf_status_str((bsf_status_t)r));
        return -1;
    }
    ++v->frames;
    v->bytes += bytes;
    if (v->rx->stats.poses != before.poses && v->rx->has_pose) {
        if (path_push(v, &v->rx->pose) != 0) {
            return -1;
        }
        /* the receiver counts a pose record among its records */
        if (v->rx->stats.records - before.records == v->rx->stats.poses - before.poses &&
            v->rx->stats.records_skipped == before.records_skipped) {
            ++v->pose_only_frames;
            v->pose_only_bytes += bytes;
        } else {
            v->pose_record_bytes += pose_record_bytes(&v->rx->pose);
        }
    }
    if (v->track) {
        const uint32_t limit = bsf_map_rx_id_limit(v->rx);
        unsigned long gone = 0, changed = 0, present = 0;
        map_change_t c;
        uint32_t id;
        memset(&c, 0, sizeof c);
        for (id = 0; id < limit && id < BSF_MAP_RX_MAX_FEATURES; ++id) {
            uint32_t h;
            const uint32_t n = feature_state(v->rx, id, &h);
            const uint32_t n0 = id < limit_before ? v->n_ctrl[id] : 0u;
            if (n0 == 0u && n > 0u) {
                ++c.created;
            } else if (n0 > 0u && n == 0u) {
                ++gone;
            } else if (n > n0) {
                ++c.extended;
                ++changed;
            } else if (n > 0u && (n != n0 || h != v->hash[id])) {
                ++c.moved;
                ++changed;
            }
            v->n_ctrl[id] = n;
            v->hash[id] = h;
            present += n > 0u ? 1u : 0u;
        }
        v->n_features = present;
        /* a merge empties one feature and grows or moves the one it joins */
        c.merged = changed > 0u ? gone : 0u;
        c.removed = changed > 0u ? 0u : gone;
        c.skipped = (unsigned long)(v->rx->stats.records_skipped - before.records_skipped);
        c.snapshots = (unsigned long)(v->rx->stats.snapshots - before.snapshots);
        c.poses = (unsigned long)(v->rx->stats.poses - before.poses);
        if (chg != NULL) {
            *chg = c;
        }
    }
    return 0;
}
