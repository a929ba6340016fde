/* SPDX-License-Identifier: MIT */
#include "bench_scenes.h"

#include <math.h>

#define BENCH_PI 3.14159265358979323846

const size_t bench_scale_beams[BENCH_SCALE_SIZES] = {180, 250, 500, 1000, 2000, 4000};

bsf_status_t bench_scaling_scene(bsf_scene_t *scene)
{
    bsf_scene_init(scene);
    if (bsf_scene_add_l_room(scene, -4.0, -3.0, 12.0, 8.0, 5.0, 3.0) != BSF_OK ||
        bsf_scene_add_circle(scene, 2.0, 0.5, 0.35) < 0 ||
        bsf_scene_add_circle(scene, 5.0, -1.5, 0.5) < 0 ||
        bsf_scene_add_corner(scene, -1.0, 3.0, 0.0, 1.5, -1.5707963, 1.0) != BSF_OK) {
        return BSF_ERR_CAPACITY;
    }
    return BSF_OK;
}

/* A diagonal walk through the room, passing between the pillars. (The walk
 * of earlier releases, y = -1.0 + 0.1 i, put poses 13 and 14 inside the
 * pillar at (2.0, 0.5).) */
bsf_scene_pose_t bench_scaling_pose(size_t i)
{
    bsf_scene_pose_t p;
    p.x = -2.0 + 0.3 * (double)i;
    p.y = -1.8 + 0.1 * (double)i;
    p.theta = 0.3 * (double)i;
    return p;
}

/* Both rooms of the demo office, the doorway, near the cabinet and past the
 * pillar; headings spread so that every wall is seen. */
bsf_scene_pose_t bench_office_pose(size_t i)
{
    static const double xyt[BENCH_OFFICE_POSES][3] = {
        {2.5, 2.0, 0.3}, {3.5, 5.5, 1.2},  {1.2, 9.0, -0.8}, {5.0, 3.6, 0.0},
        {7.0, 2.0, 2.0}, {8.0, 8.5, -1.5}, {11.5, 4.5, 3.0}, {12.8, 1.0, 1.9},
    };
    bsf_scene_pose_t p;
    const size_t k = i % BENCH_OFFICE_POSES;
    p.x = xyt[k][0];
    p.y = xyt[k][1];
    p.theta = xyt[k][2];
    return p;
}

int bench_poses_check(const bsf_scene_t *scene, const bsf_scene_pose_t *poses, size_t n,
                      double clearance, int *shape)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        const int s = bsf_scene_pose_blocked(scene, poses[i].x, poses[i].y, clearance);
        if (s >= 0 || !bsf_scene_point_enclosed(scene, poses[i].x, poses[i].y, 360u)) {
            if (shape != NULL) {
                *shape = s;
            }
            return (int)i;
        }
    }
    if (shape != NULL) {
        *shape = -1;
    }
    return -1;
}

const char *bench_adv_name(int kind)
{
    switch (kind) {
    case BENCH_ADV_PILLAR: return "pillar";
    case BENCH_ADV_CLUTTER: return "clutter";
    case BENCH_ADV_LONG_WALL: return "long-wall";
    default: return NULL;
    }
}

size_t bench_adv_beams(int kind)
{
    return kind == BENCH_ADV_LONG_WALL ? 4000u : 1000u;
}

bsf_status_t bench_adv_scan(int kind, size_t k, float *ranges, size_t cap, bsf_scan_t *scan)
{
    static bsf_scene_t scene; /* large with BSF_SCENE_MAX_SHAPES 1024: not on the stack */
    bsf_scene_rng_t rng;
    bsf_lidar_t l;
    const size_t beams = bench_adv_beams(kind);
    size_t i;
    bsf_status_t st;

    if (bench_adv_name(kind) == NULL || k >= BENCH_ADV_SCANS || ranges == NULL || scan == NULL) {
        return BSF_ERR_ARG;
    }
    if (beams > cap || beams > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    bsf_scene_rng_seed(&rng, 1500u + 10u * (unsigned)kind + (unsigned)k);
    bsf_scene_init(&scene);
    if (kind == BENCH_ADV_PILLAR) {
        /* The sensor faces the pillar's centre from 2, 5, 10 or 20 cm off its
         * surface: the pillar fills up to ~120 degrees of the view. */
        static const double gap[BENCH_ADV_SCANS] = {0.02, 0.05, 0.10, 0.20};
        const double r = 0.3;
        const double a = 0.7 * (double)k;
        const double sx = 4.0 - (r + gap[k]) * cos(a);
        const double sy = 3.0 - (r + gap[k]) * sin(a);
        if (bsf_scene_add_room_with_pillar(&scene, 0.0, 0.0, 8.0, 6.0, 4.0, 3.0, r) != BSF_OK) {
            return BSF_ERR_CAPACITY;
        }
        if (bsf_scene_pose_blocked(&scene, sx, sy, 0.0) >= 0 ||
            !bsf_scene_point_enclosed(&scene, sx, sy, 360u)) {
            return BSF_ERR_DEGENERATE;
        }
        l = bsf_lidar_default(sx, sy, a, beams, 1.5 * BENCH_PI);
    } else if (kind == BENCH_ADV_CLUTTER) {
        /* No surface at all: ranges drawn independently per beam. */
        l = bsf_lidar_default(0.0, 0.0, 0.0, beams, 1.5 * BENCH_PI);
        for (i = 0; i < beams; ++i) {
            ranges[i] = (float)(0.3 + 7.7 * bsf_scene_rng_uniform(&rng));
        }
        *scan = bsf_scene_lidar_scan(&l, ranges);
        return BSF_OK;
    } else {
        /* A 1 km wall in front of the sensor, 0.5 to 4 m away. */
        static const double dist[BENCH_ADV_SCANS] = {0.5, 1.0, 2.0, 4.0};
        if (bsf_scene_add_segment(&scene, -500.0, dist[k], 500.0, dist[k]) < 0) {
            return BSF_ERR_CAPACITY;
        }
        l = bsf_lidar_default(0.0, 0.0, 0.5 * BENCH_PI, beams, BENCH_PI);
    }
    l.noise_sigma = 0.01;
    st = bsf_scene_scan(&scene, &l, &rng, ranges, NULL, cap);
    if (st != BSF_OK) {
        return st;
    }
    *scan = bsf_scene_lidar_scan(&l, ranges);
    return BSF_OK;
}

bsf_status_t bench_truth_corridor(bsf_scene_t *scene)
{
    /* One closed outline: the bottom wall left to right, then the top wall
     * right to left, each with six recesses. */
    double xy[2 * 52];
    size_t n = 0;
    int r;
    const double len = 24.0;
    const double half = 1.0;
    const double depth = 0.5;
    const double door = 1.2;
    xy[2u * n] = 0.0;
    xy[2u * n++ + 1u] = -half;
    for (r = 0; r < 6; ++r) {
        const double x0 = 1.5 + 3.5 * (double)r;
        xy[2u * n] = x0;
        xy[2u * n++ + 1u] = -half;
        xy[2u * n] = x0;
        xy[2u * n++ + 1u] = -half - depth;
        xy[2u * n] = x0 + door;
        xy[2u * n++ + 1u] = -half - depth;
        xy[2u * n] = x0 + door;
        xy[2u * n++ + 1u] = -half;
    }
    xy[2u * n] = len;
    xy[2u * n++ + 1u] = -half;
    xy[2u * n] = len;
    xy[2u * n++ + 1u] = half;
    for (r = 5; r >= 0; --r) {
        const double x0 = 3.2 + 3.5 * (double)r;
        xy[2u * n] = x0 + door;
        xy[2u * n++ + 1u] = half;
        xy[2u * n] = x0 + door;
        xy[2u * n++ + 1u] = half + depth;
        xy[2u * n] = x0;
        xy[2u * n++ + 1u] = half + depth;
        xy[2u * n] = x0;
        xy[2u * n++ + 1u] = half;
    }
    xy[2u * n] = 0.0;
    xy[2u * n++ + 1u] = half;
    bsf_scene_init(scene);
    return bsf_scene_add_polyline(scene, xy, n, 1) == BSF_OK ? BSF_OK : BSF_ERR_CAPACITY;
}

bsf_scene_pose_t bench_truth_corridor_pose(long k, long n)
{
    bsf_scene_pose_t p;
    const double s = n > 0 ? (double)k / (double)n : 0.0;
    const int back = s >= 0.5;
    const double u = back ? 2.0 * (s - 0.5) : 2.0 * s;
    p.x = back ? 22.0 - 20.0 * u : 2.0 + 20.0 * u;
    p.y = 0.3 * sin(7.0 * BENCH_PI * u);
    p.theta = (back ? BENCH_PI : 0.0) + 0.4 * sin(5.0 * BENCH_PI * u);
    p.theta = atan2(sin(p.theta), cos(p.theta));
    return p;
}

bsf_status_t bench_truth_clutter(bsf_scene_t *scene)
{
    bsf_scene_clutter_t c;
    bsf_scene_rng_t rng;
    c.half_w = 5.0;
    c.half_h = 3.5;
    c.n_teeth = 4;
    c.tooth_depth = 0.4;
    c.n_posts = 6;
    c.n_boxes = 5;
    c.clear = 1.5;
    bsf_scene_rng_seed(&rng, 2718u);
    bsf_scene_init(scene);
    return bsf_scene_add_clutter_room(scene, &c, &rng);
}

bsf_scene_pose_t bench_truth_clutter_pose(long k, long n)
{
    bsf_scene_pose_t p;
    const double a = n > 0 ? 2.0 * BENCH_PI * (double)k / (double)n : 0.0;
    p.x = 0.8 * cos(a);
    p.y = 0.8 * sin(a);
    p.theta = atan2(sin(1.5 * a), cos(1.5 * a));
    return p;
}
