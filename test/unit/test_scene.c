/* SPDX-License-Identifier: MIT */
/* Synthetic scenes: exact ray hits, noise statistics, ground-truth corners. */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bench_scenes.h"
#include "bsf_scene.h"
#include "unity.h"

#define PI_D 3.14159265358979323846

/* Unity is built without double support: compare doubles here. */
#define ASSERT_NEAR_D(tol, expected, actual)                                                       \
    TEST_ASSERT_TRUE_MESSAGE(fabs((double)(actual) - (double)(expected)) <= (tol),                 \
                             #actual " differs from " #expected)

static bsf_scene_t scene;
static float ranges[BSF_MAX_POINTS];
static float clean[BSF_MAX_POINTS];
static int16_t hits[BSF_MAX_POINTS];
static bsf_points_t points;

void setUp(void)
{
    bsf_scene_init(&scene);
    memset(ranges, 0, sizeof ranges);
    memset(hits, 0x5A, sizeof hits);
}

void tearDown(void)
{
}

/* Four beams straight down, ahead, up and behind (sensor frame). */
static bsf_lidar_t cross_lidar(double x, double y, double theta)
{
    bsf_lidar_t l = bsf_lidar_default(x, y, theta, 4u, 1.0);
    l.angle_min = -0.5 * PI_D;
    l.angle_increment = 0.5 * PI_D;
    return l;
}

static void test_rays_hit_room_walls_at_exact_distances(void)
{
    const bsf_lidar_t l = cross_lidar(0.0, 0.0, 0.0);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_rect_room(&scene, -2.0, -3.0, 4.0, 5.0));
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)scene.n_shapes);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, NULL, ranges, hits, 4u));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.0f, ranges[0]);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 4.0f, ranges[1]);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 5.0f, ranges[2]);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 2.0f, ranges[3]);
    /* Walls in polyline order: bottom, right, top, left. */
    TEST_ASSERT_EQUAL_INT16(0, hits[0]);
    TEST_ASSERT_EQUAL_INT16(1, hits[1]);
    TEST_ASSERT_EQUAL_INT16(2, hits[2]);
    TEST_ASSERT_EQUAL_INT16(3, hits[3]);
}

static void test_sensor_pose_rotates_and_shifts_the_beams(void)
{
    /* At (1,1) facing +y: ahead is the top wall (4 m), "down" is the right wall. */
    const bsf_lidar_t l = cross_lidar(1.0, 1.0, 0.5 * PI_D);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_rect_room(&scene, -2.0, -3.0, 4.0, 5.0));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, NULL, ranges, hits, 4u));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.0f, ranges[0]);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 4.0f, ranges[1]);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.0f, ranges[2]);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 4.0f, ranges[3]);
    TEST_ASSERT_EQUAL_INT16(1, hits[0]);
    TEST_ASSERT_EQUAL_INT16(2, hits[1]);
}

static void test_circles_are_hit_from_outside_and_from_inside(void)
{
    const bsf_lidar_t l = cross_lidar(0.0, 0.0, 0.0);
    int pillar = bsf_scene_add_circle(&scene, 3.0, 0.0, 0.5);
    int hall = bsf_scene_add_circle(&scene, 1.0, 0.0, 3.0);
    TEST_ASSERT_EQUAL_INT(0, pillar);
    TEST_ASSERT_EQUAL_INT(1, hall);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, NULL, ranges, hits, 4u));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 2.5f, ranges[1]); /* pillar before the hall wall at 4 */
    TEST_ASSERT_EQUAL_INT16(0, hits[1]);
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 2.0f, ranges[3]); /* hall wall behind */
    TEST_ASSERT_EQUAL_INT16(1, hits[3]);
    /* Up: hall wall at sqrt(3^2 - 1^2). */
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 2.8284271f, ranges[2]);
}

static void test_beams_without_surface_or_beyond_range_max_give_no_return(void)
{
    bsf_lidar_t l = cross_lidar(0.0, 0.0, 0.0);
    l.range_max = 4.5;
    l.no_return = 99.0f;
    /* One wall ahead at 3 m, one above at 5 m (beyond range_max), nothing else. */
    TEST_ASSERT_EQUAL_INT(0, bsf_scene_add_segment(&scene, 3.0, -1.0, 3.0, 1.0));
    TEST_ASSERT_EQUAL_INT(1, bsf_scene_add_segment(&scene, -1.0, 5.0, 1.0, 5.0));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, NULL, ranges, hits, 4u));
    TEST_ASSERT_FLOAT_WITHIN(1e-6f, 3.0f, ranges[1]);
    TEST_ASSERT_EQUAL_INT16(0, hits[1]);
    TEST_ASSERT_EQUAL_FLOAT(99.0f, ranges[0]);
    TEST_ASSERT_EQUAL_INT16(-1, hits[0]);
    TEST_ASSERT_EQUAL_FLOAT(99.0f, ranges[2]);
    TEST_ASSERT_EQUAL_INT16(-1, hits[2]);
}

static void test_noise_has_requested_sigma_and_zero_mean(void)
{
    const double sigma = 0.02;
    bsf_lidar_t l = bsf_lidar_default(0.0, 0.0, 0.0, 181u, PI_D * 0.5);
    bsf_scene_rng_t rng;
    double sum = 0.0;
    double sum2 = 0.0;
    double mean;
    double sd;
    size_t n = 0;
    int rep;
    size_t i;
    TEST_ASSERT_EQUAL_INT(0, bsf_scene_add_segment(&scene, 2.0, -10.0, 2.0, 10.0));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, NULL, clean, NULL, BSF_MAX_POINTS));
    l.noise_sigma = sigma;
    bsf_scene_rng_seed(&rng, 12345u);
    for (rep = 0; rep < 20; ++rep) {
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_scene_scan(&scene, &l, &rng, ranges, hits, BSF_MAX_POINTS));
        for (i = 0; i < l.n_beams; ++i) {
            const double e = (double)ranges[i] - (double)clean[i];
            TEST_ASSERT_EQUAL_INT16(0, hits[i]);
            sum += e;
            sum2 += e * e;
            ++n;
        }
    }
    mean = sum / (double)n;
    sd = sqrt(sum2 / (double)n - mean * mean);
    /* 3620 samples: the sigma estimate is within ~1.2 % (1 s.e.), the mean within 3.3e-4. */
    ASSERT_NEAR_D(0.1 * sigma, sigma, sd);
    ASSERT_NEAR_D(4.0 * sigma / sqrt((double)n), 0.0, mean);
}

static void test_same_seed_repeats_and_other_seed_differs(void)
{
    bsf_lidar_t l = bsf_lidar_default(0.0, 0.0, 0.0, 50u, 1.0);
    bsf_scene_rng_t a;
    bsf_scene_rng_t b;
    size_t i;
    size_t n_diff = 0;
    l.noise_sigma = 0.05;
    TEST_ASSERT_EQUAL_INT(0, bsf_scene_add_segment(&scene, 2.0, -10.0, 2.0, 10.0));
    bsf_scene_rng_seed(&a, 7u);
    bsf_scene_rng_seed(&b, 7u);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, &a, ranges, NULL, BSF_MAX_POINTS));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, &b, clean, NULL, BSF_MAX_POINTS));
    TEST_ASSERT_EQUAL_MEMORY(ranges, clean, l.n_beams * sizeof ranges[0]);
    bsf_scene_rng_seed(&b, 8u);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, &b, clean, NULL, BSF_MAX_POINTS));
    for (i = 0; i < l.n_beams; ++i) {
        n_diff += ranges[i] != clean[i] ? 1u : 0u;
    }
    TEST_ASSERT_GREATER_THAN_UINT32(45u, (uint32_t)n_diff);
}

static void test_corner_reports_right_angle_and_the_beam_where_walls_change(void)
{
    /* 90 degree corner 2 m ahead, slightly left, walls going away from the sensor. */
    const bsf_lidar_t l = bsf_lidar_default(0.0, 0.0, 0.0, 181u, PI_D);
    bsf_scene_corner_t c[4];
    size_t n = 0;
    int k;
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_scene_add_corner(&scene, 2.0, 0.3, 0.75 * PI_D, 3.0, -0.75 * PI_D, 3.0));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(&scene, &l, c, 4u, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    ASSERT_NEAR_D(1e-9, 0.5 * PI_D, c[0].angle);
    ASSERT_NEAR_D(1e-9, 2.0, c[0].x);
    ASSERT_NEAR_D(1e-9, 0.3, c[0].y);
    TEST_ASSERT_EQUAL_INT(1, c[0].visible);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, NULL, ranges, hits, BSF_MAX_POINTS));
    k = c[0].beam;
    TEST_ASSERT_TRUE(k > 0 && k < 180);
    /* The nearest beam is within half a step of the vertex, and the walls
     * change between its neighbours. */
    ASSERT_NEAR_D(0.5 * l.angle_increment + 1e-12, c[0].bearing,
                  l.angle_min + (double)k * l.angle_increment);
    TEST_ASSERT_NOT_EQUAL(hits[k - 1], hits[k + 1]);
    TEST_ASSERT_TRUE(hits[k - 1] >= 0 && hits[k + 1] >= 0);
    /* The vertex is the farthest point of a concave corner seen from inside. */
    TEST_ASSERT_TRUE(ranges[k] >= ranges[k - 3] && ranges[k] >= ranges[k + 3]);
}

static void test_room_corners_are_found_and_occlusion_is_reported(void)
{
    bsf_lidar_t l = bsf_lidar_default(0.0, 0.0, 0.0, 720u, 1.0);
    bsf_scene_corner_t c[8];
    size_t n = 0;
    size_t i;
    l.angle_min = -PI_D;
    l.angle_increment = 2.0 * PI_D / 720.0;
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_scene_add_room_with_pillar(&scene, -5.0, -5.0, 5.0, 5.0, 2.5, 2.5, 0.5));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(&scene, &l, c, 8u, &n));
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)n);
    for (i = 0; i < n; ++i) {
        const int behind_pillar = c[i].wx > 0.0 && c[i].wy > 0.0;
        ASSERT_NEAR_D(1e-9, 0.5 * PI_D, c[i].angle);
        ASSERT_NEAR_D(1e-9, sqrt(50.0), c[i].range);
        TEST_ASSERT_TRUE(c[i].beam >= 0);
        TEST_ASSERT_EQUAL_INT(behind_pillar ? 0 : 1, c[i].visible);
    }
    /* Capacity: too small an output is an error that still reports the count. */
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_scene_corners(&scene, &l, c, 3u, &n));
    TEST_ASSERT_EQUAL_UINT32(4u, (uint32_t)n);
}

static void test_l_room_has_six_corners_and_corner_outside_fov_has_no_beam(void)
{
    /* Sensor looks +x with a 90 degree field of view. */
    const bsf_lidar_t l = bsf_lidar_default(0.5, 0.5, 0.0, 91u, 0.5 * PI_D);
    bsf_scene_corner_t c[8];
    size_t n = 0;
    size_t i;
    size_t n_in_fov = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_l_room(&scene, 0.0, 0.0, 6.0, 4.0, 3.0, 2.0));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(&scene, &l, c, 8u, &n));
    TEST_ASSERT_EQUAL_UINT32(6u, (uint32_t)n);
    for (i = 0; i < n; ++i) {
        const double b = atan2(c[i].wy - 0.5, c[i].wx - 0.5);
        const int in_fov = fabs(b) <= 0.25 * PI_D + 0.5 * l.angle_increment;
        TEST_ASSERT_EQUAL_INT(in_fov ? 1 : 0, c[i].beam >= 0 ? 1 : 0);
        n_in_fov += in_fov ? 1u : 0u;
        if (!in_fov) {
            TEST_ASSERT_EQUAL_INT(0, c[i].visible);
        }
    }
    /* (6,0), (6,2) and the reflex corner (3,2) lie within +-45 degrees. */
    TEST_ASSERT_EQUAL_UINT32(3u, (uint32_t)n_in_fov);
}

static void test_reflex_corner_with_a_hidden_wall_is_a_jump_edge_not_a_visible_corner(void)
{
    /* L-room notch vertex (3,2): its walls run right along y=2 and up along x=3. */
    bsf_lidar_t l = bsf_lidar_default(1.0, 1.0, 0.0, 720u, 1.0);
    bsf_scene_corner_t c[8];
    size_t n = 0;
    size_t i;
    int reflex = -1;
    l.angle_min = -PI_D;
    l.angle_increment = 2.0 * PI_D / 720.0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_l_room(&scene, 0.0, 0.0, 6.0, 4.0, 3.0, 2.0));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(&scene, &l, c, 8u, &n));
    for (i = 0; i < n; ++i) {
        if (fabs(c[i].wx - 3.0) < 1e-9 && fabs(c[i].wy - 2.0) < 1e-9) {
            reflex = (int)i;
        }
    }
    TEST_ASSERT_TRUE(reflex >= 0);
    /* From (1,1) both walls are seen next to the vertex. */
    TEST_ASSERT_EQUAL_INT(1, c[reflex].visible);
    /* From (1,3) the wall along y=2 hides behind the vertex. */
    l.pose.y = 3.0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(&scene, &l, c, 8u, &n));
    TEST_ASSERT_TRUE(c[reflex].beam >= 0);
    TEST_ASSERT_EQUAL_INT(0, c[reflex].visible);
}

static void test_scan_points_lie_on_the_surfaces_in_the_world(void)
{
    bsf_lidar_t l = bsf_lidar_default(1.0, -0.5, 0.7, 361u, 1.5 * PI_D);
    bsf_scan_t s;
    size_t i;
    TEST_ASSERT_EQUAL_INT(
        BSF_OK, bsf_scene_add_room_with_pillar(&scene, -4.0, -3.0, 6.0, 5.0, 3.0, 1.0, 0.4));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, NULL, ranges, hits, BSF_MAX_POINTS));
    s = bsf_scene_lidar_scan(&l, ranges);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_UINT32(361u, (uint32_t)points.n_valid);
    for (i = 0; i < points.count; ++i) {
        double wx;
        double wy;
        int shape = -1;
        bsf_scene_sensor_to_world(&l.pose, (double)points.pt[i].x, (double)points.pt[i].y, &wx,
                                  &wy);
        ASSERT_NEAR_D(1e-5, 0.0, bsf_scene_distance_to_surface(&scene, wx, wy, &shape));
        TEST_ASSERT_EQUAL_INT(hits[i], shape);
    }
}

static void test_distance_to_surface_and_frame_transforms(void)
{
    const bsf_scene_pose_t pose = {1.0, 2.0, 0.5 * PI_D};
    double sx;
    double sy;
    double wx;
    double wy;
    int shape = -2;
    ASSERT_NEAR_D(1e-12, 1e300, bsf_scene_distance_to_surface(&scene, 0.0, 0.0, &shape));
    TEST_ASSERT_EQUAL_INT(-1, shape);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_rect_room(&scene, -2.0, -3.0, 4.0, 5.0));
    TEST_ASSERT_EQUAL_INT(4, bsf_scene_add_circle(&scene, 0.0, 1.0, 0.25));
    ASSERT_NEAR_D(1e-12, 0.75, bsf_scene_distance_to_surface(&scene, 0.0, 0.0, &shape));
    TEST_ASSERT_EQUAL_INT(4, shape);
    /* Beyond a segment's end the distance is to the endpoint. */
    ASSERT_NEAR_D(1e-12, 5.0, bsf_scene_distance_to_surface(&scene, 7.0, 9.0, &shape));
    bsf_scene_sensor_to_world(&pose, 1.0, 0.0, &wx, &wy);
    ASSERT_NEAR_D(1e-12, 1.0, wx);
    ASSERT_NEAR_D(1e-12, 3.0, wy);
    bsf_scene_world_to_sensor(&pose, wx, wy, &sx, &sy);
    ASSERT_NEAR_D(1e-12, 1.0, sx);
    ASSERT_NEAR_D(1e-12, 0.0, sy);
}

static void test_bad_input_is_refused_with_an_error(void)
{
    bsf_lidar_t l = bsf_lidar_default(0.0, 0.0, 0.0, 10u, 1.0);
    bsf_scene_rng_t rng;
    const double xy[4] = {0.0, 0.0, 0.0, 0.0};
    size_t n = 0;
    int k;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_add_segment(NULL, 0.0, 0.0, 1.0, 0.0));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_add_segment(&scene, 0.0, 0.0, 0.0, 0.0));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_add_segment(&scene, (double)NAN, 0.0, 1.0, 0.0));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_add_circle(&scene, 0.0, 0.0, 0.0));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_add_polyline(&scene, xy, 2u, 0));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_add_l_room(&scene, 0.0, 0.0, 2.0, 2.0, 2.0, 1.0));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)scene.n_shapes);
    for (k = 0; k < BSF_SCENE_MAX_SHAPES; ++k) {
        TEST_ASSERT_EQUAL_INT(k, bsf_scene_add_circle(&scene, (double)k, 0.0, 0.1));
    }
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_scene_add_segment(&scene, 0.0, 0.0, 1.0, 0.0));
    bsf_scene_init(&scene);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_scan(NULL, &l, NULL, ranges, hits, 10u));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_scan(&scene, &l, NULL, NULL, hits, 10u));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_scene_scan(&scene, &l, NULL, ranges, hits, 9u));
    l.noise_sigma = 0.1;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_scan(&scene, &l, NULL, ranges, hits, 10u));
    bsf_scene_rng_seed(&rng, 1u);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_scan(&scene, &l, &rng, ranges, hits, 10u));
    l.angle_increment = 0.0;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_scan(&scene, &l, &rng, ranges, hits, 10u));
    l.angle_increment = 0.1;
    l.n_beams = BSF_MAX_POINTS + 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY,
                          bsf_scene_scan(&scene, &l, &rng, ranges, hits, BSF_MAX_POINTS + 1u));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_scene_corners(&scene, &l, NULL, 0u, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_corners(&scene, &l, NULL, 0u, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
}

/* A sensor pose is checked against every shape: inside a pillar, inside a
 * solid box, too close to a wall, outside the room are all refused. */
static void test_pose_check_finds_poses_inside_obstacles(void)
{
    static const double crate[] = {3.0, 1.0, 4.0, 1.0, 4.0, 2.0, 3.0, 2.0};
    int pillar;
    bsf_scene_init(&scene);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_rect_room(&scene, 0.0, 0.0, 8.0, 5.0));
    pillar = bsf_scene_add_circle(&scene, 6.0, 3.0, 0.4);
    TEST_ASSERT_EQUAL_INT(4, pillar);
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_solid(&scene, crate, 4u));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scene_add_box(&scene, 1.0, 3.5, 1.6, 4.2));
    TEST_ASSERT_EQUAL_INT(2, scene.n_solids);
    TEST_ASSERT_EQUAL_INT(0, scene.shape[0].solid);
    TEST_ASSERT_EQUAL_INT(1, scene.shape[5].solid);
    TEST_ASSERT_EQUAL_INT(2, scene.shape[9].solid);
    /* free: open floor; the room itself is a wall, not a solid */
    TEST_ASSERT_EQUAL_INT(-1, bsf_scene_pose_blocked(&scene, 2.0, 2.5, 0.3));
    TEST_ASSERT_EQUAL_INT(-1, bsf_scene_pose_blocked(&scene, 6.0, 2.2, 0.3));
    /* inside the pillar, and just outside it but closer than the clearance */
    TEST_ASSERT_EQUAL_INT(pillar, bsf_scene_pose_blocked(&scene, 6.1, 3.1, 0.3));
    TEST_ASSERT_EQUAL_INT(pillar, bsf_scene_pose_blocked(&scene, 6.0, 2.45, 0.3));
    TEST_ASSERT_EQUAL_INT(-1, bsf_scene_pose_blocked(&scene, 6.0, 2.45, 0.1));
    /* inside the crate and the box, even with clearance 0 */
    TEST_ASSERT_TRUE(scene.shape[bsf_scene_pose_blocked(&scene, 3.5, 1.5, 0.0)].solid == 1);
    TEST_ASSERT_TRUE(scene.shape[bsf_scene_pose_blocked(&scene, 1.3, 3.8, 0.0)].solid == 2);
    /* against a wall */
    TEST_ASSERT_EQUAL_INT(0, bsf_scene_pose_blocked(&scene, 2.0, 0.1, 0.3));
    TEST_ASSERT_EQUAL_INT(0, bsf_scene_pose_blocked(NULL, 2.0, 2.5, 0.3));
    /* enclosed inside the room, not outside it */
    TEST_ASSERT_EQUAL_INT(1, bsf_scene_point_enclosed(&scene, 2.0, 2.5, 360u));
    TEST_ASSERT_EQUAL_INT(0, bsf_scene_point_enclosed(&scene, -1.0, 2.5, 360u));
    TEST_ASSERT_EQUAL_INT(0, bsf_scene_point_enclosed(&scene, 2.0, 2.5, 0u));
}

/* The demo office's cabinet is a solid box: scans are unchanged by that
 * (the same edges in the same order), but no pose may stand inside it. */
static void test_demo_office_cabinet_is_solid(void)
{
    bsf_scene_demo_office(&scene);
    TEST_ASSERT_EQUAL_INT(1, scene.n_solids);
    TEST_ASSERT_TRUE(bsf_scene_pose_blocked(&scene, 2.75, 7.9, 0.0) >= 0);
    TEST_ASSERT_EQUAL_INT(-1, bsf_scene_pose_blocked(&scene, 2.75, 6.9, 0.3));
    TEST_ASSERT_TRUE(bsf_scene_pose_blocked(&scene, 10.5, 3.0, 0.0) >= 0); /* the pillar */
}

/* The benchmark scenes (tools/bench/bench_scenes.h): every pose free, while
 * the scaling walk of earlier releases stood inside a pillar twice. */
static void test_benchmark_poses_are_free_and_the_old_walk_was_not(void)
{
    bsf_scene_pose_t poses[BENCH_SCALE_POSES];
    size_t i;
    int shape = 0;
    int n_old_blocked = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bench_scaling_scene(&scene));
    for (i = 0; i < BENCH_SCALE_POSES; ++i) {
        poses[i] = bench_scaling_pose(i);
        /* the walk of the first releases: y = -1.0 + 0.1 i */
        if (bsf_scene_pose_blocked(&scene, poses[i].x, -1.0 + 0.1 * (double)i, 0.0) >= 0) {
            ++n_old_blocked;
        }
    }
    TEST_ASSERT_EQUAL_INT(2, n_old_blocked);
    TEST_ASSERT_EQUAL_INT(
        -1, bench_poses_check(&scene, poses, BENCH_SCALE_POSES, BENCH_POSE_CLEARANCE, &shape));
    TEST_ASSERT_EQUAL_INT(-1, shape);
    bsf_scene_demo_office(&scene);
    for (i = 0; i < BENCH_OFFICE_POSES; ++i) {
        poses[i] = bench_office_pose(i);
    }
    TEST_ASSERT_EQUAL_INT(
        -1, bench_poses_check(&scene, poses, BENCH_OFFICE_POSES, BENCH_POSE_CLEARANCE, &shape));
    /* a pose in the cabinet, and one outside the building, are caught */
    poses[3].x = 2.75;
    poses[3].y = 7.9;
    TEST_ASSERT_EQUAL_INT(3, bench_poses_check(&scene, poses, BENCH_OFFICE_POSES, 0.0, &shape));
    TEST_ASSERT_TRUE(shape >= 0 && scene.shape[shape].solid == 1);
    poses[3].x = 12.0;
    poses[3].y = 8.0; /* in the notch cut from the L, outside the walls */
    TEST_ASSERT_EQUAL_INT(3, bench_poses_check(&scene, poses, BENCH_OFFICE_POSES, 0.0, &shape));
    TEST_ASSERT_EQUAL_INT(-1, shape);
}

/* Adversarial scans: built when they fit the caps, refused when not. */
static void test_adversarial_scans_are_built_or_refused(void)
{
    static float adv[4000];
    bsf_scan_t scan;
    size_t k;
    for (k = 0; k < BENCH_ADV_SCANS; ++k) {
        TEST_ASSERT_EQUAL_INT(BSF_OK, bench_adv_scan(BENCH_ADV_PILLAR, k, adv, 4000u, &scan));
        TEST_ASSERT_EQUAL_UINT32(1000u, (uint32_t)scan.count);
        TEST_ASSERT_EQUAL_INT(BSF_OK, bench_adv_scan(BENCH_ADV_CLUTTER, k, adv, 4000u, &scan));
    }
    TEST_ASSERT_EQUAL_INT(BSF_MAX_POINTS >= 4000 ? BSF_OK : BSF_ERR_CAPACITY,
                          bench_adv_scan(BENCH_ADV_LONG_WALL, 0u, adv, 4000u, &scan));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bench_adv_scan(BENCH_ADV_PILLAR, 0u, adv, 999u, &scan));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bench_adv_scan(BENCH_ADV_COUNT, 0u, adv, 4000u, &scan));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG,
                          bench_adv_scan(BENCH_ADV_PILLAR, BENCH_ADV_SCANS, adv, 4000u, &scan));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_rays_hit_room_walls_at_exact_distances);
    RUN_TEST(test_sensor_pose_rotates_and_shifts_the_beams);
    RUN_TEST(test_circles_are_hit_from_outside_and_from_inside);
    RUN_TEST(test_beams_without_surface_or_beyond_range_max_give_no_return);
    RUN_TEST(test_noise_has_requested_sigma_and_zero_mean);
    RUN_TEST(test_same_seed_repeats_and_other_seed_differs);
    RUN_TEST(test_corner_reports_right_angle_and_the_beam_where_walls_change);
    RUN_TEST(test_room_corners_are_found_and_occlusion_is_reported);
    RUN_TEST(test_l_room_has_six_corners_and_corner_outside_fov_has_no_beam);
    RUN_TEST(test_reflex_corner_with_a_hidden_wall_is_a_jump_edge_not_a_visible_corner);
    RUN_TEST(test_scan_points_lie_on_the_surfaces_in_the_world);
    RUN_TEST(test_distance_to_surface_and_frame_transforms);
    RUN_TEST(test_bad_input_is_refused_with_an_error);
    RUN_TEST(test_pose_check_finds_poses_inside_obstacles);
    RUN_TEST(test_demo_office_cabinet_is_solid);
    RUN_TEST(test_benchmark_poses_are_free_and_the_old_walk_was_not);
    RUN_TEST(test_adversarial_scans_are_built_or_refused);
    return UNITY_END();
}
