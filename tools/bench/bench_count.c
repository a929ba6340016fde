/* SPDX-License-Identifier: MIT */
/*
 * bench_count - a fixed workload for exact instruction counts under
 * callgrind (tools/scripts/perf_table.py runs it): every scan is prepared
 * first, then each is extracted once, without a clock hook, so the inclusive
 * cost of bsf_extract, of its stages' functions and of bsf_frame_encode is
 * theirs alone, and per-call dumps (--dump-after) hold one scan each.
 *
 *   bench_count intel LOG [--method NAME] [--encode] [--max-scans N]
 *   bench_count scaling --beams N [--method NAME]     (bench_scenes.h, 20 poses)
 *   bench_count adversarial --kind pillar|clutter|long-wall [--method NAME]
 *   bench_count office --beams N [--fov360] [--method NAME]   (demo office, 8 poses)
 *   any mode: --fit-passes K (bsf_params_t.fit_passes; default 0, no bound),
 *             --fit-bin-length M (bsf_params_t.fit_bin_length; default the method's)
 *
 * Prints what it ran (scans, frames, features) on one line; exit 1 on any
 * failure (a scan that does not extract, a pose that is not free).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_scenes.h"
#include "bsf/bsf.h"
#include "bsf_scene.h"
#include "carmen.h"

#define BENCH_PI 3.14159265358979323846

static bsf_extractor_t g_ex;
static bsf_result_t g_res;
static uint8_t g_frame[BSF_FRAME_MAX_SIZE];

typedef struct {
    bsf_scan_t *scans;
    float **ranges;
    size_t n;
    size_t cap;
} scan_list_t;

static void *xmalloc(size_t n)
{
    void *p = malloc(n != 0u ? n : 1u);
    if (p == NULL) {
        fprintf(stderr, "bench_count: out of memory\n");
        exit(1);
    }
    return p;
}

/* Room for one more scan of `beams` beams; returns its ranges. */
static float *list_add(scan_list_t *l, size_t beams)
{
    if (l->n == l->cap) {
        l->cap = l->cap ? 2u * l->cap : 64u;
        l->scans = realloc(l->scans, l->cap * sizeof *l->scans);
        l->ranges = realloc(l->ranges, l->cap * sizeof *l->ranges);
        if (l->scans == NULL || l->ranges == NULL) {
            fprintf(stderr, "bench_count: out of memory\n");
            exit(1);
        }
    }
    l->ranges[l->n] = xmalloc(beams * sizeof(float));
    return l->ranges[l->n];
}

static int load_intel(const char *path, size_t max_scans, scan_list_t *l)
{
    carmen_reader_t *rd = carmen_open(path, stderr);
    carmen_scan_t rec;
    if (rd == NULL) {
        return 1;
    }
    while ((max_scans == 0u || l->n < max_scans) && carmen_next(rd, &rec) == 1) {
        float *r;
        bsf_scan_t *s;
        if (rec.count > BSF_MAX_POINTS) {
            continue;
        }
        r = list_add(l, rec.count);
        memcpy(r, rec.ranges, rec.count * sizeof(float));
        s = &l->scans[l->n++];
        s->ranges = r;
        s->count = rec.count;
        s->angle_min = rec.angle_min;
        s->angle_increment = rec.angle_increment;
        s->range_min = 0.0f;
        s->range_max = carmen_valid_range_max(&rec);
    }
    carmen_close(rd);
    return l->n > 0u ? 0 : 1;
}

static int ray_cast_poses(const bsf_scene_t *scene, const bsf_scene_pose_t *poses, size_t n,
                          size_t beams, int fov360, scan_list_t *l)
{
    bsf_scene_rng_t rng;
    size_t i;
    int shape;
    const int bad = bench_poses_check(scene, poses, n, BENCH_POSE_CLEARANCE, &shape);
    if (bad >= 0) {
        fprintf(stderr, "bench_count: pose %d (%.2f, %.2f) is not in free space (shape %d)\n", bad,
                poses[bad].x, poses[bad].y, shape);
        return 1;
    }
    if (beams < 8u || beams > BSF_MAX_POINTS) {
        fprintf(stderr, "bench_count: --beams must be in [8, %d]\n", BSF_MAX_POINTS);
        return 1;
    }
    bsf_scene_rng_seed(&rng, 2022u + beams);
    for (i = 0; i < n; ++i) {
        float *r = list_add(l, beams);
        bsf_lidar_t lid = bsf_lidar_default(poses[i].x, poses[i].y, poses[i].theta, beams,
                                            fov360 ? 2.0 * BENCH_PI : 1.5 * BENCH_PI);
        if (fov360) {
            lid.angle_min = -BENCH_PI;
            lid.angle_increment = 2.0 * BENCH_PI / (double)beams;
        }
        lid.noise_sigma = 0.01;
        if (bsf_scene_scan(scene, &lid, &rng, r, NULL, beams) != BSF_OK) {
            fprintf(stderr, "bench_count: ray-cast failed\n");
            return 1;
        }
        l->scans[l->n++] = bsf_scene_lidar_scan(&lid, r);
    }
    return 0;
}

static void usage(void)
{
    fprintf(stderr,
            "usage: bench_count intel LOG [--method NAME] [--encode] [--max-scans N]\n"
            "       bench_count scaling --beams N [--method NAME]\n"
            "       bench_count adversarial --kind pillar|clutter|long-wall [--method "
            "NAME]\n"
            "       bench_count office --beams N [--fov360] [--method NAME]\n"
            "       any mode: --fit-passes K (0..255, default 0: no bound), --fit-bin-length M\n");
}

int main(int argc, char **argv)
{
    static bsf_scene_t scene;
    scan_list_t list = {NULL, NULL, 0u, 0u};
    bsf_method_t method = BSF_METHOD_DEFAULT;
    const char *mode;
    const char *log = NULL;
    long beams = 0;
    long max_scans = 0;
    long fit_passes = 0;
    double fit_bin_length = -1.0; /* < 0: the method's default */
    int encode = 0, fov360 = 0, kind = -1, a;
    size_t i;
    unsigned long features = 0, frames = 0, bytes = 0;
    bsf_params_t p;

    if (argc < 2) {
        usage();
        return 2;
    }
    mode = argv[1];
    for (a = 2; a < argc; ++a) {
        if (strcmp(argv[a], "--method") == 0 && a + 1 < argc) {
            method = bsf_method_from_name(argv[++a]);
            if (method == BSF_METHOD_COUNT) {
                fprintf(stderr, "bench_count: unknown method %s\n", argv[a]);
                return 2;
            }
        } else if (strcmp(argv[a], "--encode") == 0) {
            encode = 1;
        } else if (strcmp(argv[a], "--fov360") == 0) {
            fov360 = 1;
        } else if (strcmp(argv[a], "--beams") == 0 && a + 1 < argc) {
            beams = atol(argv[++a]);
        } else if (strcmp(argv[a], "--max-scans") == 0 && a + 1 < argc) {
            max_scans = atol(argv[++a]);
        } else if (strcmp(argv[a], "--fit-passes") == 0 && a + 1 < argc) {
            fit_passes = atol(argv[++a]);
        } else if (strcmp(argv[a], "--fit-bin-length") == 0 && a + 1 < argc) {
            char *end = NULL;
            fit_bin_length = strtod(argv[++a], &end);
            if (end == argv[a] || *end != '\0' || !(fit_bin_length >= 0.0)) {
                fit_bin_length = 2.0; /* refused below, with the usage */
            }
        } else if (strcmp(argv[a], "--kind") == 0 && a + 1 < argc) {
            ++a;
            for (kind = 0; kind < BENCH_ADV_COUNT; ++kind) {
                if (strcmp(argv[a], bench_adv_name(kind)) == 0) {
                    break;
                }
            }
            if (kind == BENCH_ADV_COUNT) {
                fprintf(stderr, "bench_count: unknown kind %s\n", argv[a]);
                return 2;
            }
        } else if (argv[a][0] != '-' && log == NULL) {
            log = argv[a];
        } else {
            usage();
            return 2;
        }
    }
    if (max_scans < 0 || beams < 0 || fit_passes < 0 || fit_passes > 255 || fit_bin_length > 1.0) {
        usage();
        return 2;
    }

    if (strcmp(mode, "intel") == 0 && log != NULL) {
        if (load_intel(log, (size_t)max_scans, &list) != 0) {
            fprintf(stderr, "bench_count: no scan read from %s\n", log);
            return 1;
        }
    } else if (strcmp(mode, "scaling") == 0 && beams > 0) {
        bsf_scene_pose_t poses[BENCH_SCALE_POSES];
        for (i = 0; i < BENCH_SCALE_POSES; ++i) {
            poses[i] = bench_scaling_pose(i);
        }
        if (bench_scaling_scene(&scene) != BSF_OK ||
            ray_cast_poses(&scene, poses, BENCH_SCALE_POSES, (size_t)beams, 0, &list) != 0) {
            return 1;
        }
    } else if (strcmp(mode, "office") == 0 && beams > 0) {
        bsf_scene_pose_t poses[BENCH_OFFICE_POSES];
        for (i = 0; i < BENCH_OFFICE_POSES; ++i) {
            poses[i] = bench_office_pose(i);
        }
        bsf_scene_demo_office(&scene);
        if (ray_cast_poses(&scene, poses, BENCH_OFFICE_POSES, (size_t)beams, fov360, &list) != 0) {
            return 1;
        }
    } else if (strcmp(mode, "adversarial") == 0 && kind >= 0) {
        size_t k;
        for (k = 0; k < BENCH_ADV_SCANS; ++k) {
            float *r = list_add(&list, bench_adv_beams(kind));
            if (bench_adv_scan(kind, k, r, bench_adv_beams(kind), &list.scans[list.n]) != BSF_OK) {
                fprintf(stderr, "bench_count: adversarial %s scan %zu failed\n",
                        bench_adv_name(kind), k);
                return 1;
            }
            ++list.n;
        }
    } else {
        usage();
        return 2;
    }

    p = bsf_params_default(method);
    p.fit_passes = (uint8_t)fit_passes;
    if (fit_bin_length >= 0.0) {
        p.fit_bin_length = (float)fit_bin_length;
    }
    if (bsf_extractor_init(&g_ex, &p) != BSF_OK) {
        fprintf(stderr, "bench_count: %s is not available in this build\n",
                bsf_method_name(method));
        return 1;
    }
    for (i = 0; i < list.n; ++i) {
        const bsf_status_t st = bsf_extract(&g_ex, &list.scans[i], &g_res);
        if (st < 0) {
            fprintf(stderr, "bench_count: scan %zu: %s\n", i, bsf_status_str(st));
            return 1;
        }
        features += g_res.n_features;
        if (encode) {
            bsf_frame_info_t info;
            size_t len = 0u;
            bsf_frame_info_init(&info);
            info.seq = (uint32_t)i;
            if (bsf_frame_encode(&info, &g_res, g_frame, sizeof g_frame, &len) != BSF_OK) {
                fprintf(stderr, "bench_count: scan %zu: frame not encoded\n", i);
                return 1;
            }
            ++frames;
            bytes += (unsigned long)len;
        }
    }
    printf("bench_count: %s %s: scans %zu frames %lu features %lu bytes %lu\n", mode,
           bsf_method_name(method), list.n, frames, features, bytes);
    for (i = 0; i < list.n; ++i) {
        free(list.ranges[i]);
    }
    free(list.ranges);
    free(list.scans);
    return 0;
}
