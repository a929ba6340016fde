/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_metrics.h"

#include <math.h>
#include <string.h>

enum { M_GAMMA = 0, M_ETA = 1, M_ACC = 2, M_TIME = 3 };

static int finite_nonneg(float v)
{
    return v == v && v >= 0.0f && v <= 3.402823466e38f;
}

bsf_status_t bsf_metrics_counts(const bsf_result_t *r, bsf_scan_counts_t *out)
{
    bsf_scan_counts_t c;
    size_t i;
    if (r == NULL || out == NULL) {
        return BSF_ERR_ARG;
    }
    memset(&c, 0, sizeof c);
    c.n_valid = r->stats.n_valid;
    c.n_features = r->n_features;
    for (i = 0; i < r->n_features; ++i) {
        c.n_in_features += r->features[i].n_points;
        c.n_ctrl += r->features[i].n_ctrl;
        c.sum_e_curve += r->features[i].e_curve;
    }
    c.time_s = r->stats.time_ns > 0u ? (float)r->stats.time_ns * 1e-9f : -1.0f;
    c.cut = r->stats.cut;
    c.n_cut_keypoints = r->stats.n_cut_keypoints;
    c.n_cut_segments = r->stats.n_cut_segments;
    c.n_cut_points = r->stats.n_cut_points;
    *out = c;
    return BSF_OK;
}

bsf_status_t bsf_metrics_scan(const bsf_scan_counts_t *c, bsf_scan_metrics_t *out)
{
    bsf_scan_metrics_t m;

    if (c == NULL || out == NULL || c->n_in_features > c->n_valid ||
        c->n_cut_points > c->n_valid - c->n_in_features || !finite_nonneg(c->sum_e_curve) ||
        c->time_s != c->time_s ||
        (c->n_features == 0u && (c->n_in_features != 0u || c->n_ctrl != 0u))) {
        return BSF_ERR_ARG;
    }
    memset(&m, 0, sizeof m);
    if (c->n_valid > 0u) {
        m.retrievability = (float)c->n_in_features / (float)c->n_valid;
        m.has_retrievability = 1u;
    }
    if (c->n_in_features > 0u) {
        m.compactness = (float)c->n_ctrl / (float)c->n_in_features;
        m.has_compactness = 1u;
    }
    if (c->n_features > 0u) {
        m.accuracy = c->sum_e_curve / (float)c->n_features;
        m.has_accuracy = 1u;
    }
    if (c->time_s >= 0.0f && c->time_s <= 3.402823466e38f) {
        m.time_s = c->time_s;
        m.has_time = 1u;
    }
    *out = m;
    return BSF_OK;
}

bsf_status_t bsf_metrics_acc_init(bsf_metrics_acc_t *acc, float *time_samples, size_t time_cap)
{
    if (acc == NULL || (time_samples == NULL && time_cap > 0u)) {
        return BSF_ERR_ARG;
    }
    memset(acc, 0, sizeof *acc);
    acc->time_samples = time_samples;
    acc->time_cap = time_cap;
    return BSF_OK;
}

static void kahan_add(bsf_metrics_acc_t *acc, int k, float v)
{
    const float y = v - acc->comp[k];
    const float t = acc->sum[k] + y;
    acc->comp[k] = (t - acc->sum[k]) - y;
    acc->sum[k] = t;
    acc->n[k]++;
}

bsf_status_t bsf_metrics_acc_add(bsf_metrics_acc_t *acc, const bsf_scan_counts_t *counts)
{
    bsf_scan_metrics_t m;
    bsf_status_t st;

    if (acc == NULL) {
        return BSF_ERR_ARG;
    }
    st = bsf_metrics_scan(counts, &m);
    if (st != BSF_OK) {
        return st;
    }
    if (m.has_time && acc->time_samples != NULL) {
        if (acc->time_count >= acc->time_cap) {
            return BSF_ERR_CAPACITY;
        }
        acc->time_samples[acc->time_count++] = m.time_s;
    }
    if (m.has_retrievability) {
        kahan_add(acc, M_GAMMA, m.retrievability);
    }
    if (m.has_compactness) {
        kahan_add(acc, M_ETA, m.compactness);
    }
    if (m.has_accuracy) {
        kahan_add(acc, M_ACC, m.accuracy);
    }
    if (m.has_time) {
        kahan_add(acc, M_TIME, m.time_s);
    }
    acc->n_scans++;
    acc->sum_features += counts->n_features;
    acc->sum_ctrl += counts->n_ctrl;
    acc->sum_points += counts->n_in_features;
    acc->sum_valid += counts->n_valid;
    acc->n_cut_scans += (counts->cut != 0u) ? 1u : 0u;
    acc->sum_cut_keypoints += counts->n_cut_keypoints;
    acc->sum_cut_segments += counts->n_cut_segments;
    acc->sum_cut_points += counts->n_cut_points;
    return BSF_OK;
}

/* Heapsort, ascending: in place, no recursion, O(n log n) worst case. */
static void sift_down(float *v, size_t root, size_t n)
{
    for (;;) {
        size_t child = 2u * root + 1u;
        float t;
        if (child >= n) {
            return;
        }
        if (child + 1u < n && v[child + 1u] > v[child]) {
            ++child;
        }
        if (!(v[child] > v[root])) {
            return;
        }
        t = v[root];
        v[root] = v[child];
        v[child] = t;
        root = child;
    }
}

static void sort_floats(float *v, size_t n)
{
    size_t i;
    for (i = n / 2u; i-- > 0u;) {
        sift_down(v, i, n);
    }
    for (i = n; i-- > 1u;) {
        const float t = v[0];
        v[0] = v[i];
        v[i] = t;
        sift_down(v, 0u, i);
    }
}

static size_t nearest_rank(size_t n, float p)
{
    /* ceil(p*n) as a 1-based rank, clamped to [1, n]; returned 0-based. */
    float r = ceilf(p * (float)n);
    size_t rank = (r < 1.0f) ? 1u : (size_t)r;
    if (rank > n) {
        rank = n;
    }
    return rank - 1u;
}

bsf_status_t bsf_metrics_acc_summary(bsf_metrics_acc_t *acc, bsf_metrics_summary_t *out)
{
    bsf_metrics_summary_t s;
    float *means[4];
    int k;

    if (acc == NULL || out == NULL) {
        return BSF_ERR_ARG;
    }
    memset(&s, 0, sizeof s);
    means[M_GAMMA] = &s.retrievability;
    means[M_ETA] = &s.compactness;
    means[M_ACC] = &s.accuracy;
    means[M_TIME] = &s.time_mean_s;
    for (k = 0; k < 4; ++k) {
        if (acc->n[k] > 0u) {
            *means[k] = acc->sum[k] / (float)acc->n[k];
        }
    }
    s.n_retrievability = acc->n[M_GAMMA];
    s.n_compactness = acc->n[M_ETA];
    s.n_accuracy = acc->n[M_ACC];
    s.n_time = acc->n[M_TIME];
    s.n_scans = acc->n_scans;
    if (acc->n_scans > 0u) {
        s.features_per_scan = (float)acc->sum_features / (float)acc->n_scans;
        s.ctrl_per_scan = (float)acc->sum_ctrl / (float)acc->n_scans;
    }
    s.n_cut_scans = acc->n_cut_scans;
    s.cut_keypoints = acc->sum_cut_keypoints;
    s.cut_segments = acc->sum_cut_segments;
    s.cut_points = acc->sum_cut_points;
    if (acc->time_samples != NULL && acc->time_count > 0u) {
        sort_floats(acc->time_samples, acc->time_count);
        s.time_median_s = acc->time_samples[nearest_rank(acc->time_count, 0.5f)];
        s.time_p99_s = acc->time_samples[nearest_rank(acc->time_count, 0.99f)];
    }
    *out = s;
    return BSF_OK;
}
