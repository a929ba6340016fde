/* SPDX-License-Identifier: MIT */
/* bench_fit: microseconds per spline fit and PDM iterations to converge on
 * typical synthetic segments (host tool, not a test).
 *
 * usage: bench_fit [repetitions]   (default 20000 per case)
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "bsf/bsf.h"

#define MAX_PTS 64
#define N_RUNS 9

typedef struct {
    const char *name;
    bsf_point_t pts[MAX_PTS];
    size_t n;
    uint16_t vertex[2];
    size_t n_vertex;
} bench_case_t;

static bsf_pdm_work_t work;
static uint64_t rng = 0x9E3779B97F4A7C15u;

static double uniform01(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 7;
    rng ^= rng << 17;
    return (double)(rng >> 11) * (1.0 / 9007199254740992.0);
}

static double gauss(void)
{
    double u1 = uniform01();
    double u2 = uniform01();
    if (u1 < 1e-300) {
        u1 = 1e-300;
    }
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void add_point(bench_case_t *c, double x, double y, double sigma)
{
    c->pts[c->n].x = (float)(x + sigma * gauss());
    c->pts[c->n].y = (float)(y + sigma * gauss());
    c->n++;
}

static void run_case(const bench_case_t *c, size_t reps)
{
    bsf_pdm_params_t p;
    bsf_point_t ctrl[BSF_MAX_CTRL_PER_FEATURE];
    bsf_point_t ctrl4[4];
    uint8_t is_vertex[BSF_MAX_CTRL_PER_FEATURE];
    bsf_pdm_info_t info;
    size_t n_ctrl = 0;
    float e = 0.0f;
    float e_lsba = 0.0f;
    double pdm_us[N_RUNS];
    double lsba_us[N_RUNS];
    size_t run;
    size_t r;
    volatile float sink = 0.0f;

    bsf_pdm_params_default(&p);
    for (run = 0; run < N_RUNS; ++run) {
        double t0 = now_s();
        for (r = 0; r < reps; ++r) {
            if (bsf_pdm_fit(c->pts, c->n, c->vertex, c->n_vertex, &p, &work, ctrl, is_vertex,
                            BSF_MAX_CTRL_PER_FEATURE, &n_ctrl, &e, &info) != BSF_OK) {
                fprintf(stderr, "%s: PDM fit failed\n", c->name);
                exit(1);
            }
            sink += ctrl[0].x;
        }
        pdm_us[run] = (now_s() - t0) * 1e6 / (double)reps;
        t0 = now_s();
        for (r = 0; r < reps; ++r) {
            if (bsf_lsba_fit(c->pts, c->n, ctrl4, &e_lsba) != BSF_OK) {
                fprintf(stderr, "%s: LSBA fit failed\n", c->name);
                exit(1);
            }
            sink += ctrl4[0].x;
        }
        lsba_us[run] = (now_s() - t0) * 1e6 / (double)reps;
    }
    qsort(pdm_us, N_RUNS, sizeof pdm_us[0], cmp_double);
    qsort(lsba_us, N_RUNS, sizeof lsba_us[0], cmp_double);
    printf("%-22s %3zu pts  PDM %6.2f us  it %2u  refine %u  ctrl %2zu  E %6.2f mm"
           "   | LSBA %5.2f us  E %6.2f mm\n",
           c->name, c->n, pdm_us[N_RUNS / 2], (unsigned)info.iterations, (unsigned)info.refinements,
           n_ctrl, 1e3 * (double)e, lsba_us[N_RUNS / 2], 1e3 * (double)e_lsba);
    (void)sink;
}

int main(int argc, char **argv)
{
    static bench_case_t cases[5];
    const size_t reps = argc > 1 ? (size_t)strtoul(argv[1], NULL, 10) : 20000u;
    size_t i;
    bench_case_t *c;

    if (reps == 0u) {
        fprintf(stderr, "usage: bench_fit [repetitions > 0]\n");
        return 2;
    }
    memset(cases, 0, sizeof cases);

    c = &cases[0];
    c->name = "wall 30 pts, 1 cm";
    for (i = 0; i < 30u; ++i) {
        add_point(c, 2.0 + 0.05 * (double)i, 1.0 + 0.02 * (double)i, 0.01);
    }
    c = &cases[1];
    c->name = "wall 30 pts, 5 mm";
    for (i = 0; i < 30u; ++i) {
        add_point(c, 2.0 + 0.05 * (double)i, 1.0 + 0.02 * (double)i, 0.005);
    }
    c = &cases[2];
    c->name = "L-corner 31 pts, 1 cm";
    for (i = 0; i < 15u; ++i) {
        add_point(c, 3.0, 1.0 - 0.06 * (double)(15u - i), 0.01);
    }
    c->vertex[0] = (uint16_t)c->n;
    c->n_vertex = 1u;
    for (i = 0; i <= 15u; ++i) {
        add_point(c, 3.0 - 0.06 * (double)i, 1.0, 0.01);
    }
    c = &cases[3];
    c->name = "arc r 1 m 90 deg, 1 cm";
    for (i = 0; i < 30u; ++i) {
        const double a = 1.5707963267948966 * (double)i / 29.0;
        add_point(c, 2.0 + cos(a), 0.5 + sin(a), 0.01);
    }
    c = &cases[4];
    c->name = "arc r 3 m 60 deg, 5 mm";
    for (i = 0; i < 40u; ++i) {
        const double a = 1.0471975511965976 * (double)i / 39.0;
        add_point(c, 3.0 * cos(a), 3.0 * sin(a), 0.005);
    }

    printf("bench_fit: median of %d runs x %zu fits, default PDM parameters "
           "(refinement on, target 15 mm)\n",
           N_RUNS, reps);
    for (i = 0; i < 5u; ++i) {
        run_case(&cases[i], reps);
    }
    printf("sizeof(bsf_pdm_work_t) = %zu bytes\n", sizeof(bsf_pdm_work_t));
    return 0;
}
