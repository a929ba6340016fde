/* SPDX-License-Identifier: MIT */
/* bid_calibrate: N_q of BID at synthetic corners, straight walls and circles,
 * used to choose the default threshold t_th (host tool, not a test).
 *
 * usage: bid_calibrate [beams over 180 degrees (181)] [range noise sigma, m (0.01)]
 *
 * For each scene it prints the smallest N_q near each true corner (within
 * 2 beams), or the smallest N_q anywhere for corner-free scenes.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"

#define PI 3.14159265358979323846

static bsf_points_t points;
static bsf_bid_work_t work;
static float ranges[BSF_MAX_POINTS];

static int scan_scene(const bsf_scene_t *scene, bsf_lidar_t *lidar, uint64_t seed)
{
    bsf_scene_rng_t rng;
    bsf_scan_t scan;
    bsf_bid_params_t p = bsf_bid_params_default();
    bsf_keypoint_t kp[BSF_MAX_KEYPOINTS];
    size_t n_kp = 0;
    bsf_scene_rng_seed(&rng, seed);
    if (bsf_scene_scan(scene, lidar, &rng, ranges, NULL, BSF_MAX_POINTS) != BSF_OK) {
        return -1;
    }
    scan = bsf_scene_lidar_scan(lidar, ranges);
    if (bsf_scan_to_points(&scan, &points) != BSF_OK) {
        return -1;
    }
    if (bsf_bid_detect(&points, &p, &work, kp, BSF_MAX_KEYPOINTS, &n_kp) != BSF_OK) {
        return -1;
    }
    return (int)n_kp;
}

static float min_score(size_t lo, size_t hi)
{
    float m = 1e30f;
    size_t i;
    for (i = lo; i <= hi && i < points.count; ++i) {
        m = work.score[i] < m ? work.score[i] : m;
    }
    return m;
}

int main(int argc, char **argv)
{
    const size_t n_beams = argc > 1 ? (size_t)atoi(argv[1]) : 181u;
    const double sigma = argc > 2 ? atof(argv[2]) : 0.01;
    const double angles[] = {PI / 2.0, PI / 3.0};
    const double dists[] = {2.0, 4.0, 6.0};
    const double turns[] = {-0.3, 0.0, 0.3};
    float worst_corner[2] = {0.0f, 0.0f};
    float best_wall = 1e30f;
    float best_circle = 1e30f;
    size_t a;
    size_t d;
    size_t t;
    uint64_t seed = 1u;

    for (a = 0; a < 2u; ++a) {
        for (d = 0; d < 3u; ++d) {
            for (t = 0; t < 3u; ++t) {
                int convex;
                for (convex = 0; convex < 2; ++convex) {
                    bsf_scene_t scene;
                    bsf_lidar_t lidar = bsf_lidar_default(0.0, 0.0, 0.0, n_beams, PI);
                    bsf_scene_corner_t c[4];
                    size_t n_c = 0;
                    const double vx = dists[d] * cos(turns[t]);
                    const double vy = dists[d] * sin(turns[t]);
                    const double to_sensor = atan2(-vy, -vx);
                    const double mid = convex ? to_sensor + PI : to_sensor;
                    const double half =
                        convex ? (PI - angles[a]) / 2.0 + angles[a] / 2.0 : angles[a] / 2.0;
                    int n_kp;
                    float s;
                    lidar.noise_sigma = sigma;
                    bsf_scene_init(&scene);
                    if (convex) {
                        /* A convex corner seen from outside: walls leave the
                         * vertex away from the sensor, both faces visible. */
                        (void)bsf_scene_add_corner(&scene, vx, vy, mid + angles[a] / 2.0, 1.5,
                                                   mid - angles[a] / 2.0, 1.5);
                    } else {
                        (void)bsf_scene_add_corner(&scene, vx, vy, mid + half, 1.5, mid - half,
                                                   1.5);
                    }
                    n_kp = scan_scene(&scene, &lidar, seed++);
                    if (bsf_scene_corners(&scene, &lidar, c, 4u, &n_c) != BSF_OK || n_c < 1u ||
                        c[0].beam < 2 || !c[0].visible) {
                        continue;
                    }
                    s = min_score((size_t)c[0].beam - 2u, (size_t)c[0].beam + 2u);
                    printf("corner %3.0f deg %s d %.0f turn %+.1f: min N_q %.3f, keypoints %d\n",
                           angles[a] * 180.0 / PI, convex ? "convex " : "concave", dists[d],
                           turns[t], (double)s, n_kp);
                    worst_corner[a] = s > worst_corner[a] ? s : worst_corner[a];
                }
            }
        }
    }
    for (d = 0; d < 3u; ++d) {
        for (t = 0; t < 3u; ++t) {
            bsf_scene_t scene;
            bsf_lidar_t lidar = bsf_lidar_default(0.0, 0.0, 0.0, n_beams, PI);
            const double ang = turns[t] * 2.0;
            const double cx = dists[d];
            int n_kp;
            float s;
            lidar.noise_sigma = sigma;
            bsf_scene_init(&scene);
            (void)bsf_scene_add_segment(&scene, cx - 4.0 * sin(ang), -4.0 * cos(ang),
                                        cx + 4.0 * sin(ang), 4.0 * cos(ang));
            n_kp = scan_scene(&scene, &lidar, seed++);
            s = min_score(0u, points.count - 1u);
            printf("wall d %.0f tilt %+.1f: min N_q %.3f, keypoints %d\n", dists[d], ang, (double)s,
                   n_kp);
            best_wall = s < best_wall ? s : best_wall;
        }
    }
    {
        const double radii[] = {0.5, 1.0, 2.0};
        for (d = 0; d < 3u; ++d) {
            bsf_scene_t scene;
            bsf_lidar_t lidar = bsf_lidar_default(0.0, 0.0, 0.0, n_beams, PI);
            int n_kp;
            float s;
            lidar.noise_sigma = sigma;
            bsf_scene_init(&scene);
            (void)bsf_scene_add_circle(&scene, 2.0 + 2.0 * radii[d], 0.3, radii[d]);
            n_kp = scan_scene(&scene, &lidar, seed++);
            s = min_score(0u, points.count - 1u);
            printf("circle r %.1f: min N_q %.3f, keypoints %d\n", radii[d], (double)s, n_kp);
            best_circle = s < best_circle ? s : best_circle;
        }
    }
    printf("largest corner minimum: 90 deg %.3f, 60 deg %.3f; smallest wall %.3f, circle %.3f\n",
           (double)worst_corner[0], (double)worst_corner[1], (double)best_wall,
           (double)best_circle);
    return 0;
}
