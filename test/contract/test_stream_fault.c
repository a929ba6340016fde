/* SPDX-License-Identifier: MIT */
/* Fault injection: a long stream of frames through a channel that flips,
 * drops and inserts bytes. Every frame that arrived intact must be decoded,
 * and no frame that differs from what was sent may ever be delivered. */
#include <stdio.h>
#include <string.h>

#include "bsf/bsf.h"
#include "stream_fixtures.h"
#include "unity.h"

#ifdef __arm__
#define N_FRAMES 400u
#else
#define N_FRAMES 4000u
#endif

static bsf_result_t res;
static bsf_frame_t frame;
static bsf_decoder_t dec;
static uint8_t sent[BSF_FRAME_MAX_SIZE];
static uint8_t check[BSF_FRAME_MAX_SIZE];
static uint8_t chunk[64];
static uint8_t damaged[N_FRAMES + 1u];
static uint8_t decoded[N_FRAMES];

typedef struct {
    unsigned intact;
    unsigned delivered;
    unsigned false_accepts;
    unsigned intact_missed;
} tally_t;

void setUp(void)
{
    bsf_decoder_init(&dec);
    memset(damaged, 0, sizeof damaged);
    memset(decoded, 0, sizeof decoded);
}

void tearDown(void)
{
}

/* Frame i of the stream, rebuilt on demand from its index. */
static size_t encode_frame(uint32_t i, uint8_t *out)
{
    fx_rng_t rng;
    bsf_frame_info_t info;
    size_t n = 0;
    fx_rng_seed(&rng, 0x51ED270Bu ^ (i * 2654435761u));
    fx_random_result(&rng, 10u, &info, &res);
    info.seq = i;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_encode(&info, &res, out, BSF_FRAME_MAX_SIZE, &n));
    return n;
}

/* A delivered frame is genuine when re-encoding it gives back, byte for
 * byte, the frame that was sent under its sequence number (quantised
 * values re-quantise to themselves), and it was not delivered before. */
static void judge(tally_t *t)
{
    bsf_frame_info_t info;
    size_t n_sent;
    size_t n_back = 0;
    ++t->delivered;
    if (frame.seq >= N_FRAMES || decoded[frame.seq]) {
        ++t->false_accepts;
        return;
    }
    decoded[frame.seq] = 1u;
    n_sent = encode_frame(frame.seq, sent);
    bsf_frame_info_init(&info);
    info.seq = frame.seq;
    info.timestamp_ms = frame.timestamp_ms;
    info.has_pose = frame.has_pose;
    info.pose.x = frame.pose.x;
    info.pose.y = frame.pose.y;
    info.pose.theta = frame.pose.theta;
    info.quant_step = frame.quant_step;
    if (bsf_frame_encode(&info, &frame.result, check, sizeof check, &n_back) != BSF_OK ||
        n_back != n_sent || memcmp(check, sent, n_sent) != 0) {
        ++t->false_accepts;
    }
}

static void feed(const uint8_t *data, size_t len, tally_t *t)
{
    size_t off = 0;
    while (off < len) {
        size_t used = 0;
        const int r = bsf_decoder_feed(&dec, data + off, len - off, &used, &frame);
        TEST_ASSERT_TRUE(r == 0 || r == 1);
        off += used;
        if (r == 1) {
            judge(t);
        }
    }
}

/* Sends N_FRAMES frames through a channel that hits each byte with
 * probability rate_ppm / 1e6 by a flip, a drop or an insertion before it. */
static tally_t run_channel(uint32_t rate_ppm, uint32_t seed)
{
    static uint8_t frame_bytes[BSF_FRAME_MAX_SIZE];
    fx_rng_t ch;
    tally_t t;
    size_t fill = 0;
    size_t chunk_len;
    uint32_t i;
    const uint32_t threshold = rate_ppm * 4295u; /* ~ rate * 2^32 */

    memset(&t, 0, sizeof t);
    fx_rng_seed(&ch, seed);
    chunk_len = fx_rng_range(&ch, 1u, sizeof chunk);
    for (i = 0; i < N_FRAMES; ++i) {
        const size_t n = encode_frame(i, frame_bytes);
        size_t j;
        for (j = 0; j < n; ++j) {
            uint8_t out[2];
            size_t n_out = 0;
            size_t k;
            if (fx_rng_next(&ch) < threshold) {
                const uint32_t kind = fx_rng_range(&ch, 0u, 2u);
                damaged[i] = 1u;
                if (j == n - 1u) {
                    damaged[i + 1u] = 1u; /* a hit delimiter merges the next frame in */
                }
                if (kind == 0u) {
                    out[n_out++] = (uint8_t)(frame_bytes[j] ^ fx_rng_range(&ch, 1u, 255u));
                } else if (kind == 2u) {
                    out[n_out++] = (uint8_t)fx_rng_next(&ch);
                    out[n_out++] = frame_bytes[j];
                }
            } else {
                out[n_out++] = frame_bytes[j];
            }
            for (k = 0; k < n_out; ++k) {
                chunk[fill++] = out[k];
                if (fill == chunk_len) {
                    feed(chunk, fill, &t);
                    fill = 0;
                    chunk_len = fx_rng_range(&ch, 1u, sizeof chunk);
                }
            }
        }
    }
    chunk[fill++] = 0u; /* close whatever is still open */
    feed(chunk, fill, &t);
    for (i = 0; i < N_FRAMES; ++i) {
        if (!damaged[i]) {
            ++t.intact;
            if (!decoded[i]) {
                ++t.intact_missed;
            }
        }
    }
    return t;
}

static void run_and_check(uint32_t rate_ppm, const char *label, uint32_t seed)
{
    const tally_t t = run_channel(rate_ppm, seed);
    printf("fault rate %s: frames sent %u, intact %u, decoded %u, false accepts %u; "
           "bad crc %u, malformed %u, unsupported %u, unknown type %u, oversize %u, "
           "bytes skipped %u\n",
           label, (unsigned)N_FRAMES, t.intact, t.delivered, t.false_accepts,
           (unsigned)dec.stats.bad_crc, (unsigned)dec.stats.malformed,
           (unsigned)dec.stats.unsupported_version, (unsigned)dec.stats.unknown_type,
           (unsigned)dec.stats.oversize, (unsigned)dec.stats.bytes_skipped);
    TEST_ASSERT_EQUAL_UINT32(0u, t.false_accepts);
    TEST_ASSERT_EQUAL_UINT32(0u, t.intact_missed);
    TEST_ASSERT_EQUAL_UINT32(t.delivered, dec.stats.frames_ok);
    TEST_ASSERT_TRUE(t.delivered >= t.intact);
    TEST_ASSERT_TRUE(t.intact < N_FRAMES); /* the channel did hit something */
}

static void test_rate_1e4_every_intact_frame_decoded_none_false(void)
{
    run_and_check(100u, "1e-4", 1u);
}

static void test_rate_1e3_every_intact_frame_decoded_none_false(void)
{
    run_and_check(1000u, "1e-3", 2u);
}

static void test_rate_3e3_every_intact_frame_decoded_none_false(void)
{
    run_and_check(3000u, "3e-3", 3u);
}

static void test_rate_1e2_every_intact_frame_decoded_none_false(void)
{
    run_and_check(10000u, "1e-2", 4u);
}

/* Damage that the CRC cannot see (it is recomputed): the parser must reject
 * it or deliver a frame the encoder can represent again, never crash. */
static void test_crc_valid_mutations_are_rejected_or_consistent(void)
{
    static uint8_t body[BSF_FRAME_BODY_MAX_SIZE];
    static bsf_frame_t again;
    fx_rng_t rng;
    uint32_t i;
    unsigned accepted = 0;
    unsigned rejected = 0;
    fx_rng_seed(&rng, 77u);
    for (i = 0; i < N_FRAMES; ++i) {
        const size_t n = encode_frame(i, sent);
        size_t len = 0;
        size_t n_back = 0;
        uint32_t crc;
        uint32_t k;
        const uint32_t hits = fx_rng_range(&rng, 1u, 3u);
        bsf_frame_info_t info;
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_decode(sent, n - 1u, body, sizeof body, &len));
        len -= 4u;
        for (k = 0; k < hits; ++k) {
            const uint32_t what = fx_rng_range(&rng, 0u, 9u);
            if (what == 0u && len > 1u) {
                --len; /* cut the last byte */
            } else if (what == 1u && len + 5u < sizeof body) {
                body[len++] = (uint8_t)fx_rng_next(&rng); /* add one */
            } else {
                body[fx_rng_range(&rng, 0u, (uint32_t)len - 1u)] = (uint8_t)fx_rng_next(&rng);
            }
        }
        crc = bsf_crc32c(0u, body, len);
        for (k = 0; k < 4u; ++k) {
            body[len + k] = (uint8_t)(crc >> (8u * k));
        }
        if (bsf_frame_decode(body, len + 4u, &frame) != BSF_OK) {
            ++rejected;
            continue;
        }
        ++accepted;
        bsf_frame_info_init(&info);
        info.seq = frame.seq;
        info.timestamp_ms = frame.timestamp_ms;
        info.has_pose = frame.has_pose;
        info.pose.x = frame.pose.x;
        info.pose.y = frame.pose.y;
        info.pose.theta = frame.pose.theta;
        info.quant_step = frame.quant_step;
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_frame_encode(&info, &frame.result, check, sizeof check, &n_back));
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_decode(check, n_back - 1u, body, sizeof body, &len));
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_frame_decode(body, len, &again));
        TEST_ASSERT_EQUAL_UINT16(frame.result.n_features, again.result.n_features);
        TEST_ASSERT_EQUAL_UINT16(frame.result.n_ctrl, again.result.n_ctrl);
        TEST_ASSERT_EQUAL_UINT32(frame.result.stats.n_valid, again.result.stats.n_valid);
    }
    printf("crc-valid mutations: %u rejected, %u accepted as consistent frames\n", rejected,
           accepted);
    TEST_ASSERT_TRUE(rejected > 0u);
}

static void test_clean_channel_delivers_every_frame(void)
{
    const tally_t t = run_channel(0u, 5u);
    TEST_ASSERT_EQUAL_UINT32(N_FRAMES, t.intact);
    TEST_ASSERT_EQUAL_UINT32(N_FRAMES, t.delivered);
    TEST_ASSERT_EQUAL_UINT32(0u, dec.stats.bytes_skipped);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_clean_channel_delivers_every_frame);
    RUN_TEST(test_crc_valid_mutations_are_rejected_or_consistent);
    RUN_TEST(test_rate_1e4_every_intact_frame_decoded_none_false);
    RUN_TEST(test_rate_1e3_every_intact_frame_decoded_none_false);
    RUN_TEST(test_rate_3e3_every_intact_frame_decoded_none_false);
    RUN_TEST(test_rate_1e2_every_intact_frame_decoded_none_false);
    return UNITY_END();
}
