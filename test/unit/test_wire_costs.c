/* SPDX-License-Identifier: MIT */
/* The encoder's one-pass costing of Exp-Golomb orders (src/bsf_wire.h):
 * the totals from the bit-length tallies equal the sum of every value's code
 * length at every order, so the orders chosen, and the frames, stay the same
 * as costing each value at each order. White-box. */
#include <string.h>

#include "bsf/bsf_stream.h"
#include "bsf_wire.h"
#include "unity.h"

void setUp(void)
{
}

void tearDown(void)
{
}

static uint32_t rng_state = 12345u;

static uint32_t next_random(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return rng_state;
}

/* One value below 2^25 with a random bit length, often a run of ones at the
 * top (where the carry of v + 2^k changes the code length). */
static uint64_t random_value(void)
{
    const unsigned len = next_random() % 26u;
    uint64_t v;
    if (len == 0u) {
        return 0u;
    }
    v = (uint64_t)(next_random() & ((1u << len) - 1u)) | ((uint64_t)1 << (len - 1u));
    if ((next_random() & 3u) == 0u) {
        const unsigned ones = 1u + next_random() % len;
        v |= (((uint64_t)1 << ones) - 1u) << (len - ones); /* leading run of ones */
    }
    return v;
}

static void test_tally_costs_equal_the_sum_of_code_lengths_at_every_order(void)
{
    unsigned trial;
    for (trial = 0; trial < 400u; ++trial) {
        bsf_wire_eg_tally_t t;
        uint32_t want[BSF_WIRE_K_CTRL_MAX + 1u];
        uint32_t got[BSF_WIRE_K_CTRL_MAX + 1u];
        const unsigned n = trial % 50u;
        unsigned i;
        unsigned k;
        memset(&t, 0, sizeof t);
        memset(want, 0, sizeof want);
        for (i = 0; i < n; ++i) {
            const uint64_t v = trial < 40u ? (uint64_t)(trial * 50u + i) : random_value();
            bsf_wire_eg_tally_add(&t, v);
            for (k = 0; k <= BSF_WIRE_K_CTRL_MAX; ++k) {
                want[k] += bsf_wire_eg_bits(v, k);
            }
        }
        bsf_wire_eg_tally_costs(&t, BSF_WIRE_K_CTRL_MAX, got);
        TEST_ASSERT_EQUAL_UINT32_ARRAY(want, got, BSF_WIRE_K_CTRL_MAX + 1u);
    }
}

/* The order search stops early (no order above k can beat n (k + 1) bits):
 * it still finds the first order with the fewest bits, and those bits. */
static void test_best_order_is_the_first_cheapest_of_all_orders(void)
{
    unsigned trial;
    for (trial = 0; trial < 400u; ++trial) {
        bsf_wire_eg_tally_t t;
        uint32_t cost[BSF_WIRE_K_CTRL_MAX + 1u];
        const unsigned n = trial % 60u;
        unsigned i;
        unsigned k;
        unsigned want = 0;
        uint32_t bits = 0;
        memset(&t, 0, sizeof t);
        for (i = 0; i < n; ++i) {
            /* small values too: many orders tie there */
            const uint64_t v = (trial & 1u) != 0u ? random_value() : (uint64_t)(next_random() % 9u);
            bsf_wire_eg_tally_add(&t, v);
        }
        bsf_wire_eg_tally_costs(&t, BSF_WIRE_K_CTRL_MAX, cost);
        for (k = 1; k <= BSF_WIRE_K_CTRL_MAX; ++k) {
            if (cost[k] < cost[want]) {
                want = k;
            }
        }
        TEST_ASSERT_EQUAL_UINT(want, bsf_wire_eg_tally_best(&t, &bits));
        TEST_ASSERT_EQUAL_UINT32(cost[want], bits);
    }
}

/* COBS in place (the encoder's direct path) gives bsf_cobs_encode's bytes,
 * ends where the body ended when it starts behind 1 + full blocks, and
 * writes nothing beyond: bodies with zeros, and with runs of 254 bytes and
 * more (full blocks), some ending exactly after one. */
static void test_cobs_in_place_equals_cobs_encode(void)
{
    static uint8_t body[800];
    static uint8_t want[900];
    static uint8_t buf[900];
    unsigned trial;
    for (trial = 0; trial < 600u; ++trial) {
        const size_t n =
            trial < 8u ? 254u * (1u + trial % 3u) - (trial / 3u) % 2u : 1u + next_random() % 700u;
        const uint32_t zero_every = trial % 4u == 0u ? 0u : 1u + next_random() % 300u;
        size_t i;
        size_t want_len = 0;
        size_t full;
        size_t len;
        for (i = 0; i < n; ++i) {
            body[i] = (uint8_t)(1u + next_random() % 255u);
            if (zero_every != 0u && next_random() % zero_every == 0u) {
                body[i] = 0u;
            }
        }
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_cobs_encode(body, n, want, sizeof want, &want_len));
        full = bsf_cobs_full_blocks(body, n);
        TEST_ASSERT_EQUAL_size_t(want_len, 1u + n + full);
        memset(buf, 0xA5, sizeof buf);
        memcpy(buf + 1u + full, body, n);
        len = bsf_cobs_encode_in_place(buf, 1u + full, n);
        TEST_ASSERT_EQUAL_size_t(want_len, len);
        TEST_ASSERT_EQUAL_UINT8_ARRAY(want, buf, len);
        for (i = len; i < sizeof buf; ++i) {
            TEST_ASSERT_EQUAL_HEX8(0xA5, buf[i]);
        }
    }
}

/* The prediction's 32-bit fast path gives the 64-bit floor division's
 * result, on both sides of the switch between them. */
static int64_t predict_reference(int64_t a, int64_t b, uint32_t s, uint32_t k)
{
    const int64_t den = 2 * (int64_t)k;
    const int64_t num = (b - a) * (2 * (int64_t)s - 1) + (int64_t)k;
    int64_t q = num / den;
    if (num % den != 0 && num < 0) {
        --q;
    }
    return a + q;
}

static void test_prediction_is_the_floor_division_at_every_size(void)
{
    unsigned trial;
    for (trial = 0; trial < 20000u; ++trial) {
        const unsigned shift = trial % 31u; /* keeps (b - a) * (2s - 1) far from overflow */
        const int64_t a = (int64_t)(int32_t)next_random() >> (trial % 31u);
        const int64_t d = (int64_t)(int32_t)next_random() * ((int64_t)1 << shift) / 4096;
        const uint32_t k = 1u + next_random() % 64u;
        const uint32_t s = 1u + next_random() % k;
        const int64_t want = predict_reference(a, a + d, s, k);
        TEST_ASSERT_TRUE(want == bsf_wire_predict(a, a + d, s, k));
    }
    TEST_ASSERT_TRUE(predict_reference(0, -1, 1, 1) == bsf_wire_predict(0, -1, 1, 1));
    TEST_ASSERT_TRUE(predict_reference(0, INT32_MAX, 1, 1) == bsf_wire_predict(0, INT32_MAX, 1, 1));
    TEST_ASSERT_TRUE(predict_reference(0, -(int64_t)INT32_MAX - 5, 3, 2) ==
                     bsf_wire_predict(0, -(int64_t)INT32_MAX - 5, 3, 2));
}

static void test_bit_length_is_one_plus_floor_log2(void)
{
    unsigned b;
    TEST_ASSERT_EQUAL_UINT(0u, bsf_wire_bitlen(0u));
    for (b = 0; b < 64u; ++b) {
        const uint64_t p = (uint64_t)1 << b;
        TEST_ASSERT_EQUAL_UINT(b + 1u, bsf_wire_bitlen(p));
        TEST_ASSERT_EQUAL_UINT(b + 1u, bsf_wire_bitlen(p | (p - 1u)));
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_tally_costs_equal_the_sum_of_code_lengths_at_every_order);
    RUN_TEST(test_best_order_is_the_first_cheapest_of_all_orders);
    RUN_TEST(test_cobs_in_place_equals_cobs_encode);
    RUN_TEST(test_prediction_is_the_floor_division_at_every_size);
    RUN_TEST(test_bit_length_is_one_plus_floor_log2);
    return UNITY_END();
}
