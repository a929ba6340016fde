/* SPDX-License-Identifier: MIT */
/* Table 1 on Intel: FALKO-SVED-PDM with the shipped defaults must be no
 * worse than the paper on retrievability, compactness and accuracy at once.
 * N counts every reading below the log's declared maximum range (50 m for
 * Intel, which puts the 81.83 no-return code out); nothing else is filtered. */
#include <stdio.h>
#include <stdlib.h>

#include "bsf/bsf.h"
#include "carmen.h"
#include "shared_dir.h"
#include "unity.h"

static char log_path[2048];
static bsf_extractor_t ex;
static bsf_result_t res;
static float times[8192];

void setUp(void)
{
}

void tearDown(void)
{
}

static void run(bsf_method_t method, bsf_metrics_summary_t *s)
{
    carmen_reader_t *rd = carmen_open(log_path, stderr);
    carmen_scan_t rec;
    bsf_metrics_acc_t acc;
    bsf_params_t p = bsf_params_default(method);
    int r;
    TEST_ASSERT_NOT_NULL(rd);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extractor_init(&ex, &p));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_init(&acc, times, 8192u));
    while ((r = carmen_next(rd, &rec)) > 0) {
        bsf_scan_t sc;
        bsf_scan_counts_t c;
        sc.ranges = rec.ranges;
        sc.count = rec.count;
        sc.angle_min = rec.angle_min;
        sc.angle_increment = rec.angle_increment;
        sc.range_min = 0.0f;
        sc.range_max = carmen_valid_range_max(&rec);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_extract(&ex, &sc, &res));
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_counts(&res, &c));
        TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_add(&acc, &c));
    }
    TEST_ASSERT_EQUAL_INT(0, r);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)carmen_malformed_count(rd));
    carmen_close(rd);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_metrics_acc_summary(&acc, s));
}

static void test_falko_sved_pdm_on_intel_is_no_worse_than_table_1(void)
{
    bsf_metrics_summary_t s;
    run(BSF_METHOD_FALKO_SVED_PDM, &s);
    printf("intel falko-sved-pdm: %lu scans, retrievability %.2f %% (paper 86.4), compactness "
           "%.4f (paper 0.192), accuracy %.5f m (paper 0.0158)\n",
           (unsigned long)s.n_scans, 100.0 * (double)s.retrievability, (double)s.compactness,
           (double)s.accuracy);
    TEST_ASSERT_EQUAL_UINT32(2672u, s.n_scans);
    TEST_ASSERT_TRUE_MESSAGE(s.retrievability >= 0.864f, "retrievability below the paper's");
    TEST_ASSERT_TRUE_MESSAGE(s.compactness <= 0.192f, "compactness worse than the paper's");
    TEST_ASSERT_TRUE_MESSAGE(s.accuracy <= 0.0158f, "accuracy worse than the paper's");
}

int main(void)
{
    char shared_dir[2048];
    FILE *probe;
    bsf_test_shared_dir(shared_dir, sizeof shared_dir);
    snprintf(log_path, sizeof log_path, "%s/data/intel.log.gz", shared_dir);
    probe = fopen(log_path, "rb");
    if (probe == NULL) {
        printf("SKIPPED: Intel dataset not found (%s)\n", log_path);
        return 77;
    }
    fclose(probe);
    UNITY_BEGIN();
    RUN_TEST(test_falko_sved_pdm_on_intel_is_no_worse_than_table_1);
    return UNITY_END();
}
