/* SPDX-License-Identifier: MIT */
/*
 * Fault injection on the map stream: the map-update frames of a synthetic
 * drive (the demo office, three loops, then a quiet tail in which snapshots
 * go round) through a channel that flips bits (1e-4 .. 1e-2 per byte),
 * inserts or deletes bytes, replaces bursts, or goes silent for 1 .. 6 whole
 * frames, and to a receiver that joins late. A lossless receiver fed the same frames is the
 * reference (it holds the robot's sent copy, checked). Judged at the end, feature by feature: the
 * damaged receiver holds exactly the reference's points, or flags the feature (stale output of
 * bsf_map_rx_feature_ctrl: unconfirmed, stale or missing); a feature that differs without the flag
 * must not exist, whether the receiver counted a loss or not. A feature flagged but equal is a
 * false alarm (counted, kept low by confirmation through update counts). Every frame the decoder
 * delivers must be one the robot sent, byte for byte (damaged frames accepted: must be 0), and
 * every frame the channel did not touch must be delivered.
 */
#include <stdio.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "demo_scan.h"
#include "unity.h"

#define N_LOOP 90
#define N_DRIVE (3 * N_LOOP)
#define N_TAIL 400
#define MAX_FRAMES (N_DRIVE + N_TAIL + 1) /* + the robot's next frame */
#define STREAM_CAP (MAX_FRAMES * 600)
#define MAX_Q 4096

static bsf_extractor_t ex;
static bsf_result_t res;
static bsf_map_t map;
static bsf_map_rx_t ref;
static bsf_map_rx_t rx;
static bsf_decoder_t dec;
static bsf_frame_t frame;
static bsf_scene_t scene;
static uint8_t stream[STREAM_CAP];
static size_t frame_start[MAX_FRAMES + 1];
static uint32_t frame_seq[MAX_FRAMES];
static size_t n_frames;
static size_t stream_len;
static uint8_t channel[2 * STREAM_CAP];
static uint8_t damaged[MAX_FRAMES + 1];
static uint8_t delivered[MAX_FRAMES];
static int32_t q_a[2 * MAX_Q];
static int32_t q_b[2 * MAX_Q];
static uint8_t v_a[MAX_Q];
static uint8_t v_b[MAX_Q];

typedef struct {
    unsigned frames_untouched; /* frames the channel did not touch (nor their delimiter) */
    unsigned frames_recovered; /* of those, delivered */
    unsigned frames_delivered;
    unsigned damaged_accepted; /* delivered but not a frame the robot sent: must be 0 */
    unsigned features;         /* features the reference holds */
    unsigned intact;           /* equal to the reference, never flagged */
    unsigned repaired;         /* equal, after being flagged stale on the way */
    unsigned reported;         /* flagged at the end (bsf_map_rx_feature_ctrl's stale), of which: */
    unsigned unconfirmed;      /*   frames lost since it was last confirmed */
    unsigned stale;            /*   a record of it skipped, or its snapshot arriving */
    unsigned missing;          /*   sent, never received: the receiver holds none of it */
    unsigned ghost;            /*   the robot merged it away, the receiver still holds it */
    unsigned false_alarm;      /*   equal to the reference all the same */
    unsigned unflagged;        /* different and not flagged after a counted loss: must be 0 */
    unsigned wrong;            /* different, not flagged, no loss counted: must be 0 */
} tally_t;

static int first_seen;     /* the damaged receiver got a frame */
static uint32_t first_seq; /* the sequence number of its first */
static uint64_t rng_state;

static uint32_t rng_next(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (uint32_t)(rng_state >> 11);
}

static uint32_t rng_below(uint32_t n)
{
    return rng_next() % n;
}

void setUp(void)
{
}

void tearDown(void)
{
}

/* The sequence number of a map payload (a uvar after the type byte). */
static uint32_t payload_seq(const uint8_t *p, size_t len)
{
    uint32_t v = 0u;
    size_t i;
    for (i = 1u; i < len && i < 6u; ++i) {
        v |= (uint32_t)(p[i] & 0x7Fu) << (7u * (i - 1u));
        if (!(p[i] & 0x80u)) {
            break;
        }
    }
    return v;
}

/* Frames the decoder refused so far. */
static uint32_t decoder_dropped(void)
{
    const bsf_decoder_stats_t *d = &dec.stats;
    return d->bad_crc + d->malformed + d->oversize + d->unsupported_version + d->unknown_type;
}

/* Feed bytes to the decoder into rx; judge every delivered frame. */
static void feed(bsf_map_rx_t *to, const uint8_t *data, size_t len, tally_t *t)
{
    size_t off = 0u;
    while (off < len) {
        size_t used = 0u;
        const uint32_t dropped = decoder_dropped();
        const int got = bsf_decoder_feed(&dec, data + off, len - off, &used, &frame);
        TEST_ASSERT_TRUE(got >= 0);
        off += used;
        if (decoder_dropped() != dropped) {
            bsf_map_rx_note_loss(to); /* it may have been a map frame */
        }
        if (got == (int)BSF_FRAME_TYPE_MAP) {
            const uint32_t seq = payload_seq(frame.payload, frame.payload_len);
            size_t k = n_frames;
            size_t j;
            for (j = 0; j < n_frames; ++j) {
                if (frame_seq[j] == seq) {
                    k = j;
                    break;
                }
            }
            if (t != NULL) {
                ++t->frames_delivered;
            }
            /* genuine: the payload the robot sent under this sequence
             * number, byte for byte, delivered once */
            if (k == n_frames || delivered[k]) {
                if (t != NULL) {
                    ++t->damaged_accepted;
                }
                continue;
            }
            {
                static bsf_decoder_t d2;
                static bsf_frame_t f2;
                size_t used2 = 0u;
                bsf_decoder_init(&d2);
                TEST_ASSERT_EQUAL_INT((int)BSF_FRAME_TYPE_MAP,
                                      bsf_decoder_feed(&d2, stream + frame_start[k],
                                                       frame_start[k + 1u] - frame_start[k], &used2,
                                                       &f2));
                if (f2.payload_len != frame.payload_len ||
                    memcmp(f2.payload, frame.payload, f2.payload_len) != 0) {
                    if (t != NULL) {
                        ++t->damaged_accepted;
                    }
                    continue;
                }
            }
            delivered[k] = 1u;
            if (!first_seen) {
                first_seen = 1;
                first_seq = seq;
            }
            TEST_ASSERT_TRUE(bsf_map_rx_apply(to, frame.payload, frame.payload_len) >= 0);
        }
    }
}

/* The robot's drive with the given snapshot budget: every frame into
 * stream[], frame boundaries kept; the reference receiver fed all of it. */
static uint16_t stream_budget = 0xFFFFu;

static void make_stream(uint16_t budget)
{
    bsf_map_params_t p;
    long k;
    if (stream_budget == budget) {
        return;
    }
    stream_budget = budget;
    n_frames = 0u;
    stream_len = 0u;
    bsf_scene_demo_office(&scene);
    bsf_map_params_default(&p);
    p.frame_interval = 1u;
    p.snapshot_budget = budget;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_map_init(&map, &p));
    for (k = 0; k < N_DRIVE + N_TAIL; ++k) {
        bsf_pose_t pose = {1.0f, 1.0f, 0.0f};
        size_t len = 0u;
        if (k < N_DRIVE) {
            demo_scan_extract(&scene, k % N_LOOP, N_LOOP, 77u + (uint64_t)k, &ex, &res, &pose);
        } else {
            res.n_features = 0u; /* the robot stands still: snapshots go round */
            res.n_ctrl = 0u;
        }
        TEST_ASSERT_TRUE(bsf_map_fuse(&map, &res, &pose) >= 0);
        TEST_ASSERT_TRUE(stream_len + BSF_MAP_FRAME_MAX_SIZE <= STREAM_CAP);
        TEST_ASSERT_EQUAL_INT(
            BSF_OK, bsf_map_encode(&map, NULL, stream + stream_len, BSF_MAP_FRAME_MAX_SIZE, &len));
        if (len > 0u) {
            TEST_ASSERT_TRUE(n_frames < MAX_FRAMES);
            frame_start[n_frames] = stream_len;
            frame_seq[n_frames] = map.frame_seq - 1u;
            ++n_frames;
            stream_len += len;
        }
    }
    {
        /* The robot's next frame (its pose, nothing else changed): a receiver
         * learns of lost frames only from a later one, so a run whose last
         * frames go silent is judged once the link is back. */
        const bsf_pose_t pose = {1.0f, 1.0f, 0.0f};
        size_t len = 0u;
        TEST_ASSERT_EQUAL_INT(
            BSF_OK, bsf_map_encode(&map, &pose, stream + stream_len, BSF_MAP_FRAME_MAX_SIZE, &len));
        TEST_ASSERT_TRUE(len > 0u && n_frames < MAX_FRAMES);
        frame_start[n_frames] = stream_len;
        frame_seq[n_frames] = map.frame_seq - 1u;
        ++n_frames;
        stream_len += len;
    }
    frame_start[n_frames] = stream_len;
    bsf_map_rx_init(&ref);
    bsf_decoder_init(&dec);
    memset(delivered, 0, sizeof delivered);
    for (k = 0; k < (long)n_frames; ++k) {
        /* a frame advances a feature's update count by at most 4: what lets
         * a receiver confirm a feature by its count after a short loss */
        static uint8_t upd_before[BSF_MAP_RX_MAX_FEATURES];
        static uint8_t held_before[BSF_MAP_RX_MAX_FEATURES];
        const uint32_t limit = bsf_map_rx_id_limit(&ref);
        uint32_t id;
        for (id = 0; id < limit; ++id) {
            upd_before[id] = ref.features[id].upd;
            held_before[id] = bsf_map_rx_feature_state(&ref, id) == BSF_MAP_RX_CONFIRMED;
        }
        feed(&ref, stream + frame_start[k], frame_start[k + 1] - frame_start[k], NULL);
        for (id = 0; id < limit; ++id) {
            if (held_before[id] && bsf_map_rx_feature_state(&ref, id) == BSF_MAP_RX_CONFIRMED) {
                TEST_ASSERT_TRUE((((unsigned)ref.features[id].upd - upd_before[id]) & 15u) <= 4u);
            }
        }
    }
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n_frames, ref.stats.frames);
    printf("map stream, snapshot budget %u: %zu frames, %zu bytes, %u features in the robot's "
           "RAM; lossless receiver: %u records skipped\n",
           (unsigned)budget, n_frames, stream_len, (unsigned)bsf_map_feature_count(&map),
           (unsigned)ref.stats.records_skipped);
    /* a receiver that lost nothing applies everything (a snapshot of a
     * feature it can vouch for leaves it whole) */
    TEST_ASSERT_EQUAL_UINT32(0u, ref.stats.records_skipped);
    /* the reference holds the robot's sent copy of every feature in its RAM,
     * never flagged */
    for (k = 0; k < (long)bsf_map_feature_count(&map); ++k) {
        uint32_t id = 0u;
        uint8_t stale = 1u;
        const int n = bsf_map_feature_q(&map, (size_t)k, q_a, v_a, MAX_Q, &id);
        TEST_ASSERT_TRUE(n >= 0 && n <= MAX_Q);
        TEST_ASSERT_TRUE(bsf_map_rx_feature_ctrl(&ref, id, NULL, NULL, 0u, &stale) >= 0);
        TEST_ASSERT_EQUAL_UINT8(0u, stale);
        TEST_ASSERT_EQUAL_INT(n, bsf_map_rx_feature_q(&ref, id, q_b, v_b, MAX_Q));
        TEST_ASSERT_EQUAL_MEMORY(q_a, q_b, (size_t)n * 2u * sizeof q_a[0]);
        TEST_ASSERT_EQUAL_MEMORY(v_a, v_b, (size_t)n);
    }
}

/* The receiver knows it lost frames: a gap in the sequence numbers, a first
 * frame other than the stream's first, or a damaged frame dropped. */
static int loss_counted(void)
{
    const bsf_decoder_stats_t *d = &dec.stats;
    return rx.stats.frames_missed > 0u || (first_seen && first_seq != 0u) ||
           d->bad_crc + d->malformed + d->oversize + d->unsupported_version + d->unknown_type > 0u;
}

/* Feature by feature, the damaged receiver against the reference. */
static void judge_features(tally_t *t, const uint8_t *was_stale)
{
    uint32_t id;
    const uint32_t lim = bsf_map_rx_id_limit(&ref) > bsf_map_rx_id_limit(&rx)
                             ? bsf_map_rx_id_limit(&ref)
                             : bsf_map_rx_id_limit(&rx);
    for (id = 0; id < lim; ++id) {
        uint8_t stale_ref = 0u;
        uint8_t stale = 0u;
        const int n = bsf_map_rx_feature_q(&ref, id, q_a, v_a, MAX_Q);
        const int m = bsf_map_rx_feature_q(&rx, id, q_b, v_b, MAX_Q);
        int same;
        TEST_ASSERT_TRUE(n >= 0 && n <= MAX_Q && m >= 0 && m <= MAX_Q);
        TEST_ASSERT_TRUE(bsf_map_rx_feature_ctrl(&ref, id, NULL, NULL, 0u, &stale_ref) >= 0);
        TEST_ASSERT_TRUE(bsf_map_rx_feature_ctrl(&rx, id, NULL, NULL, 0u, &stale) >= 0);
        TEST_ASSERT_EQUAL_UINT8(0u, stale_ref); /* it lost nothing */
        same = n == m && memcmp(q_a, q_b, (size_t)n * 2u * sizeof q_a[0]) == 0 &&
               memcmp(v_a, v_b, (size_t)n) == 0;
        if (n == 0 && m == 0) {
            continue; /* neither holds it (merged away, never sent) */
        }
        ++t->features;
        if (stale) {
            const int st = bsf_map_rx_feature_state(&rx, id);
            ++t->reported;
            t->unconfirmed += st == BSF_MAP_RX_UNCONFIRMED;
            t->stale += st == BSF_MAP_RX_STALE;
            t->missing += st == BSF_MAP_RX_MISSING;
            t->ghost += n == 0;
            t->false_alarm += same ? 1u : 0u;
            TEST_ASSERT_TRUE(st >= BSF_MAP_RX_UNCONFIRMED && st <= BSF_MAP_RX_MISSING);
            TEST_ASSERT_TRUE(st != BSF_MAP_RX_MISSING || m == 0);
        } else if (!same && loss_counted()) {
            ++t->unflagged;
            printf("  feature %u: reference %d points, receiver %d, not flagged after a loss\n",
                   (unsigned)id, n, m);
        } else if (!same) {
            ++t->wrong;
            printf("  feature %u: reference %d points, receiver %d, not flagged\n", (unsigned)id, n,
                   m);
        } else if (was_stale[id]) {
            ++t->repaired;
        } else {
            ++t->intact;
        }
    }
}

static uint8_t was_stale[BSF_MAP_RX_MAX_FEATURES];

static void note_stale(void)
{
    uint32_t id;
    for (id = 0; id < bsf_map_rx_id_limit(&rx); ++id) {
        uint8_t st = 0u;
        TEST_ASSERT_TRUE(bsf_map_rx_feature_ctrl(&rx, id, NULL, NULL, 0u, &st) >= 0);
        was_stale[id] |= st;
    }
}

enum { FLIPS, INSERTS, DELETES, BURSTS, LATE_JOIN, SILENCES };
static const char *const model_name[] = {"bit flips", "insertions", "deletions",
                                         "bursts",    "late join",  "silences"};

/* One run through the channel: rate is per byte (bit flips: per bit of a
 * byte hit), or the number of bursts, or the frame the late receiver joins
 * at. The stream goes out frame by frame; the receiver is judged at the end. */
static tally_t run(int model, double rate, uint64_t seed)
{
    tally_t t;
    size_t k;
    size_t silent_left = 0u; /* SILENCES: frames still to lose */
    memset(&t, 0, sizeof t);
    rng_state = seed * 0x9E3779B97F4A7C15ull + 1u;
    memset(damaged, 0, sizeof damaged);
    memset(delivered, 0, sizeof delivered);
    memset(was_stale, 0, sizeof was_stale);
    first_seen = 0;
    bsf_map_rx_init(&rx);
    bsf_decoder_init(&dec);
    for (k = 0; k < n_frames; ++k) {
        const uint8_t *f = stream + frame_start[k];
        const size_t n = frame_start[k + 1u] - frame_start[k];
        size_t out = 0u;
        size_t j;
        if (model == SILENCES) {
            /* the link goes silent for `rate` whole frames, from a frame in
             * 8: losses of 1 .. 3 frames end in count confirmations, 4 or
             * more must not; the last frame always arrives (the link is back) */
            if (silent_left == 0u && rng_below(8u) == 0u) {
                silent_left = (size_t)rate;
            }
            if (silent_left > 0u && k + 1u < n_frames) {
                --silent_left;
                damaged[k] = 1u;
                continue;
            }
            memcpy(channel, f, n);
            out = n;
        } else if (model == LATE_JOIN) {
            if (k < (size_t)rate) {
                damaged[k] = 1u; /* never heard */
                continue;
            }
            memcpy(channel, f, n);
            out = n;
        } else if (model == BURSTS) {
            /* rate bursts over the stream: each frame hit with probability
             * rate / n_frames; a burst of 2..64 random bytes replaces as many */
            memcpy(channel, f, n);
            out = n;
            if (rng_below(1000000u) < (uint32_t)(rate * 1e6 / (double)n_frames)) {
                const size_t at = rng_below((uint32_t)n);
                size_t len = 2u + rng_below(63u);
                if (at + len > n) {
                    len = n - at;
                }
                for (j = 0; j < len; ++j) {
                    channel[at + j] = (uint8_t)rng_next();
                }
                damaged[k] = 1u;
                if (at + len == n) {
                    damaged[k + 1u] = 1u; /* its delimiter: the next frame merges in */
                }
            }
        } else {
            const uint32_t per_million = (uint32_t)(rate * 1e6);
            for (j = 0; j < n; ++j) {
                if (rng_below(1000000u) >= per_million) {
                    channel[out++] = f[j];
                    continue;
                }
                damaged[k] = 1u;
                if (j == n - 1u) {
                    damaged[k + 1u] = 1u;
                }
                if (model == FLIPS) {
                    channel[out++] = (uint8_t)(f[j] ^ (1u << rng_below(8u)));
                } else if (model == INSERTS) {
                    channel[out++] = (uint8_t)rng_next();
                    channel[out++] = f[j];
                } /* DELETES: the byte is dropped */
            }
        }
        feed(&rx, channel, out, &t);
        note_stale();
    }
    if (dec.raw_len > 0u) {
        /* the link went quiet inside a frame: what a receiver's timeout says */
        bsf_map_rx_note_loss(&rx);
    }
    for (k = 0; k < n_frames; ++k) {
        if (!damaged[k]) {
            ++t.frames_untouched;
            t.frames_recovered += delivered[k];
        }
    }
    judge_features(&t, was_stale);
    printf(
        "budget %-3u %-10s %-6g seed %-4u: frames %zu, untouched %u, recovered %u, delivered "
        "%u, damaged "
        "accepted %u; features %u: intact %u, repaired %u, reported %u (unconfirmed %u, stale %u, "
        "missing %u; ghosts %u, false alarms %u), unflagged %u, wrong %u\n",
        (unsigned)stream_budget, model_name[model], rate, (unsigned)seed, n_frames,
        t.frames_untouched, t.frames_recovered, t.frames_delivered, t.damaged_accepted, t.features,
        t.intact, t.repaired, t.reported, t.unconfirmed, t.stale, t.missing, t.ghost, t.false_alarm,
        t.unflagged, t.wrong);
    return t;
}

static tally_t total;

static void add(const tally_t *t)
{
    total.frames_untouched += t->frames_untouched;
    total.frames_recovered += t->frames_recovered;
    total.frames_delivered += t->frames_delivered;
    total.damaged_accepted += t->damaged_accepted;
    total.features += t->features;
    total.intact += t->intact;
    total.repaired += t->repaired;
    total.reported += t->reported;
    total.unconfirmed += t->unconfirmed;
    total.stale += t->stale;
    total.missing += t->missing;
    total.ghost += t->ghost;
    total.false_alarm += t->false_alarm;
    total.unflagged += t->unflagged;
    total.wrong += t->wrong;
}

static void check(const tally_t *t)
{
    TEST_ASSERT_EQUAL_UINT(0u, t->damaged_accepted);
    TEST_ASSERT_EQUAL_UINT(0u, t->wrong);
    TEST_ASSERT_EQUAL_UINT(0u, t->unflagged);
    TEST_ASSERT_EQUAL_UINT(t->frames_untouched, t->frames_recovered);
    TEST_ASSERT_EQUAL_UINT(t->reported,
                           t->unconfirmed + t->stale + t->missing); /* every flag has a reason */
    add(t);
}

static void channel_runs(uint16_t budget)
{
    static const double rates[] = {1e-4, 3e-4, 1e-3, 3e-3, 1e-2};
    int model;
    size_t r;
    uint64_t seed;
    make_stream(budget);
    for (model = FLIPS; model <= DELETES; ++model) {
        for (r = 0; r < sizeof rates / sizeof rates[0]; ++r) {
            for (seed = 1u; seed <= 2u; ++seed) {
                const tally_t t = run(model, rates[r], seed + 10u * r + 100u * (uint64_t)model);
                check(&t);
            }
        }
    }
    for (seed = 1u; seed <= 4u; ++seed) {
        const tally_t t = run(BURSTS, 4.0 * (double)seed, 500u + seed);
        check(&t);
    }
    for (r = 1u; r <= 6u; ++r) {
        for (seed = 1u; seed <= 2u; ++seed) {
            const tally_t t = run(SILENCES, (double)r, 600u + 10u * r + seed);
            check(&t);
        }
    }
}

/* The default: no snapshots. What damage hits is reported, never repaired. */
static void test_map_fault_channel_no_snapshots(void)
{
    channel_runs(0u);
}

/* Snapshots of 40 bytes per frame repair what damage hit. */
static void test_map_fault_channel_snapshots(void)
{
    channel_runs(40u);
}

/* A receiver that joins late: everything before its first frame is missing;
 * without snapshots the features it never got are reported, with them they
 * come back. */
static void test_map_fault_late_join(void)
{
    static const double joins[] = {0.05, 0.3, 0.6};
    size_t j;
    make_stream(0u);
    for (j = 0; j < sizeof joins / sizeof joins[0]; ++j) {
        const tally_t t = run(LATE_JOIN, (double)(size_t)(joins[j] * (double)n_frames), 900u + j);
        check(&t);
        TEST_ASSERT_TRUE(t.frames_delivered > 0u);
    }
    make_stream(40u);
    for (j = 0; j < sizeof joins / sizeof joins[0]; ++j) {
        const tally_t t = run(LATE_JOIN, (double)(size_t)(joins[j] * (double)n_frames), 950u + j);
        check(&t);
        /* snapshots bring back every feature the robot holds */
        TEST_ASSERT_TRUE(t.features > 0u && t.repaired + t.intact > 0u);
        TEST_ASSERT_EQUAL_UINT(0u, t.missing);
    }
}

static void test_map_fault_totals(void)
{
    printf("TOTAL: frames untouched %u, recovered %u, delivered %u, damaged accepted %u; "
           "features %u: intact %u, repaired %u, reported %u (unconfirmed %u, stale %u, missing "
           "%u; ghosts %u, false alarms %u), unflagged %u, wrong %u\n",
           total.frames_untouched, total.frames_recovered, total.frames_delivered,
           total.damaged_accepted, total.features, total.intact, total.repaired, total.reported,
           total.unconfirmed, total.stale, total.missing, total.ghost, total.false_alarm,
           total.unflagged, total.wrong);
    TEST_ASSERT_TRUE(total.frames_recovered > 0u);
    TEST_ASSERT_TRUE(total.repaired > 0u); /* the resync design was exercised */
    TEST_ASSERT_EQUAL_UINT(0u, total.damaged_accepted);
    TEST_ASSERT_EQUAL_UINT(0u, total.wrong);
    TEST_ASSERT_EQUAL_UINT(0u, total.unflagged);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_map_fault_channel_no_snapshots);
    RUN_TEST(test_map_fault_channel_snapshots);
    RUN_TEST(test_map_fault_late_join);
    RUN_TEST(test_map_fault_totals);
    return UNITY_END();
}
