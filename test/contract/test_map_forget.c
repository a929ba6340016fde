/* SPDX-License-Identifier: MIT */
/*
 * test_map_forget.c - the map's caps filling up (built against a copy of the
 * library with small map caps): the robot forgets features it has sent and
 * not seen for a while, keeps running, and the receiver keeps everything,
 * untouched, with the robot's sent copy exact for what the robot holds.
 */
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "demo_scan.h"
#include "unity.h"

#if BSF_MAP_MAX_CTRL > 512
#error "test_map_forget needs a library built with small map caps"
#endif

static bsf_extractor_t ex;
static bsf_result_t res;
static bsf_map_t map;
static bsf_map_rx_t rx;
static bsf_decoder_t dec;
static bsf_frame_t frame;
static bsf_scene_t scene;
static uint8_t buf[BSF_MAP_FRAME_MAX_SIZE];
static int32_t q_a[2 * 1024];
static int32_t q_b[2 * 1024];
static uint8_t v_a[1024];
static uint8_t v_b[1024];

#define N_SCANS 90
#define MAX_IDS 512

/* What the receiver held for each id when the robot forgot it. */
static int32_t kept_q[MAX_IDS][2 * 64];
static int kept_n[MAX_IDS];

void setUp(void)
{
}

void tearDown(void)
{
}

static void deliver(const uint8_t *data, size_t len)
{
    size_t off = 0;
    while (off < len) {
        size_t used = 0;
        const int t = bsf_decoder_feed(&dec, data + off, len - off, &used, &frame);
        TEST_ASSERT_TRUE(t >= 0);
        off += used;
        if (t == (int)BSF_FRAME_TYPE_MAP) {
            TEST_ASSERT_EQUAL_INT(0, bsf_map_rx_apply(&rx, frame.payload, frame.payload_len));
        }
    }
}

static int robot_has(uint32_t id)
{
    size_t i;
    for (i = 0; i < bsf_map_feature_count(&map); ++i) {
        uint32_t fid = 0;
        TEST_ASSERT_TRUE(bsf_map_feature_q(&map, i, NULL, NULL, 0u, &fid) >= 0);
        if (fid == id) {
            return 1;
        }
    }
    return 0;
}

static void test_map_forgets_sent_features_and_receiver_keeps_them(void)
{
    bsf_map_params_t p;
    long k;
    uint32_t id;
    uint32_t n_kept = 0;
    bsf_map_params_default(&p);
    p.forget_after = 10u;
    p.frame_interval = 1u;
    bsf_scene_demo_office(&scene);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_map_init(&map, &p));
    bsf_map_rx_init(&rx);
    bsf_decoder_init(&dec);
    memset(kept_n, 0, sizeof kept_n);
    for (k = 0; k < 3 * N_SCANS; ++k) {
        bsf_pose_t pose;
        size_t len = 0;
        size_t i;
        demo_scan_extract(&scene, k % N_SCANS, N_SCANS, 100u + (uint64_t)k, &ex, &res, &pose);
        TEST_ASSERT_TRUE(bsf_map_fuse(&map, &res, &pose) >= 0);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_map_encode(&map, NULL, buf, sizeof buf, &len));
        deliver(buf, len);
        /* the robot's RAM stays within its caps, its sent copy exact */
        TEST_ASSERT_TRUE(bsf_map_feature_count(&map) <= BSF_MAP_MAX_FEATURES);
        for (i = 0; i < bsf_map_feature_count(&map); ++i) {
            uint32_t fid = 0;
            const int n = bsf_map_feature_q(&map, i, q_a, v_a, 1024u, &fid);
            TEST_ASSERT_TRUE(n >= 0 && n <= 1024);
            TEST_ASSERT_EQUAL_INT(n, bsf_map_rx_feature_q(&rx, fid, q_b, v_b, 1024u));
            if (n > 0) {
                TEST_ASSERT_EQUAL_MEMORY(q_a, q_b, (size_t)n * 2u * sizeof q_a[0]);
                TEST_ASSERT_EQUAL_MEMORY(v_a, v_b, (size_t)n);
            }
        }
        /* remember what the receiver holds of each feature the robot forgot */
        for (id = 0; id < bsf_map_rx_id_limit(&rx) && id < MAX_IDS; ++id) {
            if (kept_n[id] == 0 && !robot_has(id)) {
                const int n = bsf_map_rx_feature_q(&rx, id, kept_q[id], NULL, 64u);
                TEST_ASSERT_TRUE(n >= 0);
                kept_n[id] = n > 64 ? -1 : (n == 0 ? -2 : n);
            }
        }
    }
    TEST_ASSERT_TRUE(map.stats.n_forgotten > 0u);
    TEST_ASSERT_TRUE(map.stats.n_forgotten_ctrl > 0u);
    /* forgotten features stay at the receiver exactly as they were */
    for (id = 0; id < bsf_map_rx_id_limit(&rx) && id < MAX_IDS; ++id) {
        if (kept_n[id] > 0) {
            const int n = bsf_map_rx_feature_q(&rx, id, q_b, NULL, 1024u);
            TEST_ASSERT_EQUAL_INT(kept_n[id], n);
            TEST_ASSERT_EQUAL_MEMORY(kept_q[id], q_b, (size_t)n * 2u * sizeof q_b[0]);
            ++n_kept;
        }
    }
    TEST_ASSERT_TRUE(n_kept > 0u);
    TEST_ASSERT_EQUAL_UINT32(0u, rx.stats.records_skipped);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_map_forgets_sent_features_and_receiver_keeps_them);
    return UNITY_END();
}
