/* SPDX-License-Identifier: MIT */
/* The encoder's one-pass costing of Exp-Golomb orders (src/bsf_wire.h):
 * the totals from the bit-length tallies equal the sum of every value's code
 * length at every order, so the orders chosen, and the frames, stay the same
 * as costing each value at each order. White-box. */
#include <string.h>

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
    RUN_TEST(test_prediction_is_the_floor_division_at_every_size);
    RUN_TEST(test_bit_length_is_one_plus_floor_log2);
    return UNITY_END();
}
