/* SPDX-License-Identifier: MIT */
/*
 * FALKO on synthetic scans ray-cast in the test (walls and a pillar), the
 * shared beam NMS (white-box), and the refused or degenerate calls.
 * Runs on the host and on the emulated Cortex-M4F.
 */
#include <math.h>
#include <string.h>

#include "bsf/bsf.h"
#include "bsf_nms.h"
#include "unity.h"

#define NO_RETURN 81.83f
#define DEG (3.14159265358979f / 180.0f)

static float ranges[BSF_MAX_POINTS + 1];
static bsf_points_t points;
static bsf_falko_work_t work;
static bsf_keypoint_t kps[BSF_MAX_KEYPOINTS];
static float nms_score[BSF_MAX_POINTS];
static uint16_t nms_peak[BSF_MAX_POINTS];

typedef struct {
    float x1, y1, x2, y2;
} wall_t;

typedef struct {
    float cx, cy, radius;
} pillar_t;

void setUp(void)
{
    memset(&points, 0, sizeof points);
    memset(kps, 0, sizeof kps);
}

void tearDown(void)
{
}

/* Distance along the unit ray (dx, dy) from the origin to the nearest wall
 * or pillar, or NO_RETURN. */
static float cast_ray(float dx, float dy, const wall_t *walls, size_t n_walls,
                      const pillar_t *pillars, size_t n_pillars)
{
    float best = NO_RETURN;
    size_t k;
    for (k = 0; k < n_walls; ++k) {
        const wall_t *w = &walls[k];
        const float ex = w->x2 - w->x1;
        const float ey = w->y2 - w->y1;
        const float den = dx * ey - dy * ex;
        float t, u;
        if (fabsf(den) < 1e-9f) {
            continue;
        }
        /* origin + t d = w1 + u e */
        t = (w->x1 * ey - w->y1 * ex) / den;
        u = (w->x1 * dy - w->y1 * dx) / den;
        if (t > 0.0f && u >= 0.0f && u <= 1.0f && t < best) {
            best = t;
        }
    }
    for (k = 0; k < n_pillars; ++k) {
        const pillar_t *p = &pillars[k];
        const float b = dx * p->cx + dy * p->cy;
        const float c = p->cx * p->cx + p->cy * p->cy - p->radius * p->radius;
        const float disc = b * b - c;
        if (disc >= 0.0f) {
            const float t = b - sqrtf(disc);
            if (t > 0.0f && t < best) {
                best = t;
            }
        }
    }
    return best;
}

static bsf_scan_t cast_scan(size_t count, float angle_min, float inc, const wall_t *walls,
                            size_t n_walls, const pillar_t *pillars, size_t n_pillars)
{
    bsf_scan_t s;
    size_t i;
    for (i = 0; i < count; ++i) {
        const float a = angle_min + (float)i * inc;
        ranges[i] = cast_ray(cosf(a), sinf(a), walls, n_walls, pillars, n_pillars);
    }
    s.ranges = ranges;
    s.count = count;
    s.angle_min = angle_min;
    s.angle_increment = inc;
    s.range_min = 0.0f;
    s.range_max = 81.0f;
    return s;
}

/* 180 beams, -90 .. +89 deg, 1 deg: beam 90 looks straight ahead. */
static bsf_scan_t cast_180(const wall_t *walls, size_t n_walls, const pillar_t *pillars,
                           size_t n_pillars)
{
    return cast_scan(180u, -90.0f * DEG, 1.0f * DEG, walls, n_walls, pillars, n_pillars);
}

static size_t detect_default(const bsf_scan_t *s)
{
    const bsf_falko_params_t p = bsf_falko_params_default();
    size_t n = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(s, &points));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_detect(&points, &p, &work, kps, BSF_MAX_KEYPOINTS, &n));
    return n;
}

/* A room corner (90 deg, concave) 2 m straight ahead: walls x + y = 2 and
 * x - y = 2 meet at (2, 0), the point of beam 90. */
static const wall_t corner_walls[] = {{2.0f, 0.0f, -3.0f, 5.0f}, {2.0f, 0.0f, -3.0f, -5.0f}};

static void test_right_angle_corner_at_2m_found_within_one_beam(void)
{
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    const size_t n = detect_default(&s);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_INT_WITHIN(1, 90, kps[0].index);
}

static void test_corner_orientation_points_back_into_the_room(void)
{
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)detect_default(&s));
    /* Both wings run back toward the sensor: the mean direction is -x. */
    TEST_ASSERT_FLOAT_WITHIN(0.1f, -1.0f, cosf(kps[0].orientation));
}

static void test_corner_subbeam_point_lands_on_the_true_corner(void)
{
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)detect_default(&s));
    TEST_ASSERT_FLOAT_WITHIN(0.01f, 2.0f, kps[0].point.x);
    TEST_ASSERT_FLOAT_WITHIN(0.01f, 0.0f, kps[0].point.y);
    /* r = 0.1 exp(0.07 * 2) */
    TEST_ASSERT_FLOAT_WITHIN(1e-4f, 0.11503f, kps[0].radius);
    TEST_ASSERT_TRUE(kps[0].score >= 0.0f);
}

static void test_corner_off_axis_found_within_one_beam(void)
{
    /* The same corner turned to 30 deg: beam 120. */
    const float c = cosf(30.0f * DEG), sn = sinf(30.0f * DEG);
    wall_t w[2];
    size_t k, n;
    bsf_scan_t s;
    for (k = 0; k < 2; ++k) {
        const float x1 = corner_walls[k].x1, y1 = corner_walls[k].y1;
        const float x2 = corner_walls[k].x2, y2 = corner_walls[k].y2;
        w[k].x1 = c * x1 - sn * y1;
        w[k].y1 = sn * x1 + c * y1;
        w[k].x2 = c * x2 - sn * y2;
        w[k].y2 = sn * x2 + c * y2;
    }
    s = cast_180(w, 2, NULL, 0);
    n = detect_default(&s);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_INT_WITHIN(1, 120, kps[0].index);
}

static void test_corner_with_one_neighbour_per_side_is_rejected_until_radius_grows(void)
{
    /* At 3 m the beams on the 45 deg walls are 0.074 m apart, r is 0.123 m:
     * one neighbour per side, fewer than neigh_min_points = 2. */
    bsf_falko_params_t p = bsf_falko_params_default();
    wall_t w[2];
    size_t k, n = 9;
    bsf_scan_t s;
    for (k = 0; k < 2; ++k) {
        w[k].x1 = 1.5f * corner_walls[k].x1;
        w[k].y1 = 1.5f * corner_walls[k].y1;
        w[k].x2 = 1.5f * corner_walls[k].x2;
        w[k].y2 = 1.5f * corner_walls[k].y2;
    }
    s = cast_180(w, 2, NULL, 0);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
    p.neigh_a = 0.2f; /* r = 0.25 m: three neighbours per side */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_detect(&points, &p, &work, kps, 4, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_INT_WITHIN(1, 90, kps[0].index);
}

static void test_straight_wall_yields_no_keypoint(void)
{
    const wall_t wall[] = {{2.0f, -40.0f, 2.0f, 40.0f}};
    const bsf_scan_t s = cast_180(wall, 1, NULL, 0);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
    TEST_ASSERT_TRUE(points.n_valid > 150u);
}

static void test_oblique_straight_wall_yields_no_keypoint(void)
{
    const wall_t wall[] = {{-1.0f, -3.0f, 5.0f, 3.0f}};
    const bsf_scan_t s = cast_180(wall, 1, NULL, 0);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
}

static void test_circle_around_sensor_yields_no_keypoint(void)
{
    /* Inside a circle of radius 3 m centred on the sensor: every range is 3. */
    bsf_scan_t s = cast_180(NULL, 0, NULL, 0);
    size_t i;
    for (i = 0; i < 180u; ++i) {
        ranges[i] = 3.0f;
    }
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
    TEST_ASSERT_EQUAL_UINT32(180u, (uint32_t)points.n_valid);
}

static void test_pillar_yields_no_keypoint(void)
{
    const pillar_t pillar[] = {{3.0f, 0.5f, 1.0f}};
    const bsf_scan_t s = cast_180(NULL, 0, pillar, 1);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
    TEST_ASSERT_TRUE(points.n_valid > 20u);
}

static void test_empty_all_invalid_and_single_beam_scans_give_no_keypoint(void)
{
    bsf_scan_t s = cast_180(NULL, 0, NULL, 0); /* all NO_RETURN */
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)points.n_valid);
    ranges[50] = 2.0f;
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)points.n_valid);
    s.count = 0;
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
    s.count = 1;
    ranges[0] = 2.0f;
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)detect_default(&s));
}

/* bsf_points_t documents an invalid beam as the point (0, 0), but points
 * filled by hand may leave anything there: the detector must ignore it. Each
 * beam near the corner in turn is made invalid, once at (0, 0) and once
 * holding a stale point (the corner's, or a wall point beside it) that the
 * end searches would take for a neighbour; the keypoints must be the same. */
static void test_invalid_beam_coordinates_never_change_keypoints(void)
{
    static bsf_points_t clean;
    static bsf_keypoint_t ref[BSF_MAX_KEYPOINTS];
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    const bsf_falko_params_t p = bsf_falko_params_default();
    size_t j, k, n_ref, n;
    size_t n_found = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &clean));
    for (j = 80u; j <= 100u; ++j) {
        const bsf_point_t stale[3] = {clean.pt[90], clean.pt[86], clean.pt[94]};
        points = clean;
        points.valid[j] = 0u;
        points.pt[j].x = 0.0f;
        points.pt[j].y = 0.0f;
        points.range[j] = 0.0f;
        points.n_valid = clean.n_valid - 1u;
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_falko_detect(&points, &p, &work, ref, BSF_MAX_KEYPOINTS, &n_ref));
        for (k = 0; k < 3u; ++k) {
            points.pt[j] = stale[k];
            TEST_ASSERT_EQUAL_INT(BSF_OK,
                                  bsf_falko_detect(&points, &p, &work, kps, BSF_MAX_KEYPOINTS, &n));
            TEST_ASSERT_EQUAL_UINT32((uint32_t)n_ref, (uint32_t)n);
            if (n > 0u) {
                TEST_ASSERT_EQUAL_MEMORY(ref, kps, n * sizeof kps[0]);
            }
        }
        n_found += (n_ref > 0u) ? 1u : 0u;
    }
    /* Not vacuous: the corner survives most single invalid beams. */
    TEST_ASSERT_GREATER_THAN_UINT32(15u, (uint32_t)n_found);
}

/* A valid beam whose point is not finite (a caller's own bsf_points_t) is
 * never a neighbour nor a keypoint, and the end searches, which stop at the
 * apex itself, still stop there. Windows here span about 40 beams (the
 * four-beam walks on x86); the corner beam's own neighbours are poisoned too. */
static void test_non_finite_points_of_valid_beams_are_never_neighbours(void)
{
    static bsf_points_t clean;
    static const size_t poisoned[] = {100u, 300u, 480u, 520u, 700u, 900u};
    const bsf_scan_t s = cast_scan(1001u, -45.0f * DEG, 0.09f * DEG, corner_walls, 2, NULL, 0);
    const bsf_falko_params_t p = bsf_falko_params_default();
    int variant;
    size_t k, n;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &clean));
    for (variant = 0; variant < 4; ++variant) {
        const float bad = (variant == 0) ? NAN : (variant == 1) ? INFINITY : -INFINITY;
        points = clean;
        for (k = 0; k < sizeof poisoned / sizeof poisoned[0]; ++k) {
            TEST_ASSERT_EQUAL_UINT8(1u, points.valid[poisoned[k]]);
            if (variant == 3) {
                points.pt[poisoned[k]].y = NAN;
            } else {
                points.pt[poisoned[k]].x = bad;
            }
        }
        TEST_ASSERT_EQUAL_INT(BSF_OK,
                              bsf_falko_detect(&points, &p, &work, kps, BSF_MAX_KEYPOINTS, &n));
        TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
        TEST_ASSERT_INT_WITHIN(2, 500, kps[0].index);
        TEST_ASSERT_TRUE(isfinite(kps[0].point.x) && isfinite(kps[0].point.y));
        TEST_ASSERT_TRUE(isfinite(kps[0].orientation));
    }
}

static void test_nan_ranges_are_skipped_not_propagated(void)
{
    bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    size_t k, n;
    for (k = 0; k < 180u; k += 7u) {
        if (k < 85u || k > 95u) {
            ranges[k] = NAN;
        }
    }
    n = detect_default(&s);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_INT_WITHIN(1, 90, kps[0].index);
    TEST_ASSERT_TRUE(kps[0].point.x == kps[0].point.x);
    TEST_ASSERT_TRUE(kps[0].orientation == kps[0].orientation);
}

static void test_null_arguments_are_refused(void)
{
    const bsf_falko_params_t p = bsf_falko_params_default();
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    size_t n = 99;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(NULL, &p, &work, kps, 4, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(&points, NULL, &work, kps, 4, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(&points, &p, NULL, kps, 4, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(&points, &p, &work, NULL, 4, &n));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(&points, &p, &work, kps, 4, NULL));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_params_check(NULL));
}

static void test_bad_geometry_and_oversized_scan_are_refused(void)
{
    const bsf_falko_params_t p = bsf_falko_params_default();
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    size_t n = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    points.angle_increment = 0.0f;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(&points, &p, &work, kps, 4, &n));
    points.angle_increment = NAN;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_ARG, bsf_falko_detect(&points, &p, &work, kps, 4, &n));
    points.angle_increment = 1.0f * DEG;
    points.count = BSF_MAX_POINTS + 1u;
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_falko_detect(&points, &p, &work, kps, 4, &n));
}

static void test_bad_parameters_are_refused(void)
{
    const bsf_falko_params_t d = bsf_falko_params_default();
    bsf_falko_params_t p;
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    size_t n = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_params_check(&d));
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
#define EXPECT_BAD(field, value)                                                                   \
    do {                                                                                           \
        p = d;                                                                                     \
        p.field = (value);                                                                         \
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ERR_PARAM, bsf_falko_params_check(&p), #field);          \
        TEST_ASSERT_EQUAL_INT_MESSAGE(BSF_ERR_PARAM,                                               \
                                      bsf_falko_detect(&points, &p, &work, kps, 4, &n), #field);   \
    } while (0)
    EXPECT_BAD(min_score_th, -1);
    EXPECT_BAD(min_score_th, 101);
    EXPECT_BAD(min_range, -0.5f);
    EXPECT_BAD(max_range, 0.0f);
    EXPECT_BAD(max_range, NAN);
    EXPECT_BAD(nms_radius, -0.1f);
    EXPECT_BAD(neigh_a, 0.0f);
    EXPECT_BAD(neigh_a, INFINITY);
    EXPECT_BAD(neigh_b, -0.07f);
    EXPECT_BAD(neigh_min_points, 0);
    EXPECT_BAD(b_ratio, 0.0f);
    EXPECT_BAD(grid_sectors, 1);
    EXPECT_BAD(grid_sectors, 65);
#undef EXPECT_BAD
}

static void test_defaults_are_falkolib_defaults(void)
{
    const bsf_falko_params_t p = bsf_falko_params_default();
    TEST_ASSERT_EQUAL_INT(50, p.min_score_th);
    TEST_ASSERT_EQUAL_FLOAT(0.0f, p.min_range);
    TEST_ASSERT_EQUAL_FLOAT(30.0f, p.max_range);
    TEST_ASSERT_EQUAL_INT(1, p.subbeam);
    TEST_ASSERT_EQUAL_FLOAT(0.1f, p.nms_radius);
    TEST_ASSERT_EQUAL_FLOAT(0.1f, p.neigh_a);
    TEST_ASSERT_EQUAL_FLOAT(0.07f, p.neigh_b);
    TEST_ASSERT_EQUAL_INT(2, p.neigh_min_points);
    TEST_ASSERT_EQUAL_FLOAT(2.5f, p.b_ratio);
    TEST_ASSERT_EQUAL_INT(16, p.grid_sectors);
    TEST_ASSERT_EQUAL_INT(0, p.circular_sector_distance);
}

static void test_max_range_excludes_far_corner(void)
{
    bsf_falko_params_t p = bsf_falko_params_default();
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    size_t n = 9;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    p.max_range = 1.9f; /* the corner is at 2 m */
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_detect(&points, &p, &work, kps, 4, &n));
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)n);
}

static void test_without_subbeam_point_is_the_beam_point(void)
{
    bsf_falko_params_t p = bsf_falko_params_default();
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    size_t n = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    p.subbeam = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_detect(&points, &p, &work, kps, 4, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_EQUAL_FLOAT(points.pt[kps[0].index].x, kps[0].point.x);
    TEST_ASSERT_EQUAL_FLOAT(points.pt[kps[0].index].y, kps[0].point.y);
}

static void test_paper_circular_distance_also_finds_the_corner(void)
{
    bsf_falko_params_t p = bsf_falko_params_default();
    const bsf_scan_t s = cast_180(corner_walls, 2, NULL, 0);
    size_t n = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    p.circular_sector_distance = 1;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_falko_detect(&points, &p, &work, kps, 4, &n));
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_INT_WITHIN(1, 90, kps[0].index);
}

/* A square room 4 m x 4 m around the sensor, 1081 beams over 270 deg: the
 * corners at -45 and +45 deg are beams 360 and 720. */
static const wall_t room[] = {{2.0f, -2.0f, 2.0f, 2.0f},
                              {2.0f, 2.0f, -2.0f, 2.0f},
                              {-2.0f, 2.0f, -2.0f, -2.0f},
                              {-2.0f, -2.0f, 2.0f, -2.0f}};

static void test_scan_at_capacity_finds_room_corners(void)
{
    const bsf_scan_t s = cast_scan(BSF_MAX_POINTS, -135.0f * DEG,
                                   270.0f * DEG / (float)(BSF_MAX_POINTS - 1), room, 4, NULL, 0);
    const size_t n = detect_default(&s);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)BSF_MAX_POINTS, (uint32_t)points.n_valid);
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)n);
    TEST_ASSERT_INT_WITHIN(1, (BSF_MAX_POINTS - 1) / 3, kps[0].index);
    TEST_ASSERT_INT_WITHIN(1, 2 * (BSF_MAX_POINTS - 1) / 3, kps[1].index);
}

static void test_too_small_output_reports_capacity_and_total(void)
{
    const bsf_falko_params_t p = bsf_falko_params_default();
    const bsf_scan_t s = cast_scan(BSF_MAX_POINTS, -135.0f * DEG,
                                   270.0f * DEG / (float)(BSF_MAX_POINTS - 1), room, 4, NULL, 0);
    size_t n = 0;
    TEST_ASSERT_EQUAL_INT(BSF_OK, bsf_scan_to_points(&s, &points));
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_falko_detect(&points, &p, &work, kps, 1, &n));
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)n);
    TEST_ASSERT_INT_WITHIN(1, (BSF_MAX_POINTS - 1) / 3, kps[0].index);
    TEST_ASSERT_EQUAL_INT(BSF_ERR_CAPACITY, bsf_falko_detect(&points, &p, &work, NULL, 0, &n));
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)n);
}

static void test_clockwise_scan_finds_the_same_corner(void)
{
    /* Beam i at +89 - i deg: the corner straight ahead is beam 89. */
    const bsf_scan_t s = cast_scan(180u, 89.0f * DEG, -1.0f * DEG, corner_walls, 2, NULL, 0);
    const size_t n = detect_default(&s);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_INT_WITHIN(1, 89, kps[0].index);
}

/* ---- shared NMS (white-box) ---------------------------------------------- */

/* n beams at 10 m, 1 deg apart: with radius 0.1 m every window is 0. */
static void far_points(size_t n)
{
    size_t i;
    points.count = n;
    points.n_valid = n;
    points.angle_min = 0.0f;
    points.angle_increment = 1.0f * DEG;
    for (i = 0; i < n; ++i) {
        points.range[i] = 10.0f;
        points.valid[i] = 1u;
        points.pt[i].x = 10.0f * cosf((float)i * DEG);
        points.pt[i].y = 10.0f * sinf((float)i * DEG);
        nms_score[i] = 0.0f;
    }
}

static void test_nms_windows_follow_range(void)
{
    far_points(10);
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bsf_nms_half_window(&points, 3, 0.1f));
    points.range[3] = 1.0f; /* asin(0.1) / 1 deg = 5.74 */
    TEST_ASSERT_EQUAL_UINT32(5u, (uint32_t)bsf_nms_half_window(&points, 3, 0.1f));
    points.range[3] = 0.05f; /* radius >= range: asin(0.8) / 1 deg = 53.1 */
    TEST_ASSERT_EQUAL_UINT32(53u, (uint32_t)bsf_nms_half_window(&points, 3, 0.1f));
    points.valid[3] = 0u; /* invalid: far away */
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)bsf_nms_half_window(&points, 3, 0.1f));
}

static void test_nms_plateau_collapses_to_middle(void)
{
    size_t n;
    far_points(9);
    nms_score[2] = 5.0f;
    nms_score[3] = 5.0f;
    nms_score[4] = 5.0f;
    nms_score[7] = 3.0f;
    n = bsf_nms_beams(&points, nms_score, BSF_NMS_HIGHER_IS_BETTER, 1.0f, 0.1f, nms_peak);
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT16(3u, nms_peak[0]);
    TEST_ASSERT_EQUAL_UINT16(7u, nms_peak[1]);
}

static void test_nms_threshold_is_strict(void)
{
    size_t n;
    far_points(5);
    nms_score[1] = 2.0f;
    nms_score[3] = 3.0f;
    n = bsf_nms_beams(&points, nms_score, BSF_NMS_HIGHER_IS_BETTER, 2.0f, 0.1f, nms_peak);
    TEST_ASSERT_EQUAL_UINT32(1u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT16(3u, nms_peak[0]);
}

static void test_nms_suppresses_weaker_beam_inside_window(void)
{
    size_t i, n;
    far_points(20);
    for (i = 0; i < 20u; ++i) {
        points.range[i] = 1.0f; /* window 5 */
    }
    nms_score[8] = 4.0f;
    nms_score[10] = 6.0f;
    nms_score[18] = 5.0f;
    n = bsf_nms_beams(&points, nms_score, BSF_NMS_HIGHER_IS_BETTER, 0.0f, 0.1f, nms_peak);
    TEST_ASSERT_EQUAL_UINT32(2u, (uint32_t)n);
    TEST_ASSERT_EQUAL_UINT16(10u, nms_peak[0]);
    TEST_ASSERT_EQUAL_UINT16(18u, nms_peak[1]);
}

static void test_nms_lower_is_better_mirrors_higher_is_better(void)
{
    static uint16_t peak_hi[BSF_MAX_POINTS];
    size_t i, n_hi, n_lo;
    far_points(40);
    for (i = 0; i < 40u; ++i) {
        points.range[i] = 0.5f + 0.1f * (float)(i % 7u);
        nms_score[i] = (float)((i * 37u) % 11u);
    }
    n_hi = bsf_nms_beams(&points, nms_score, BSF_NMS_HIGHER_IS_BETTER, 2.0f, 0.1f, peak_hi);
    for (i = 0; i < 40u; ++i) {
        nms_score[i] = -nms_score[i];
    }
    n_lo = bsf_nms_beams(&points, nms_score, BSF_NMS_LOWER_IS_BETTER, -2.0f, 0.1f, nms_peak);
    TEST_ASSERT_TRUE(n_hi > 0u);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)n_hi, (uint32_t)n_lo);
    TEST_ASSERT_EQUAL_UINT16_ARRAY(peak_hi, nms_peak, n_hi);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_right_angle_corner_at_2m_found_within_one_beam);
    RUN_TEST(test_corner_orientation_points_back_into_the_room);
    RUN_TEST(test_corner_subbeam_point_lands_on_the_true_corner);
    RUN_TEST(test_corner_off_axis_found_within_one_beam);
    RUN_TEST(test_corner_with_one_neighbour_per_side_is_rejected_until_radius_grows);
    RUN_TEST(test_straight_wall_yields_no_keypoint);
    RUN_TEST(test_oblique_straight_wall_yields_no_keypoint);
    RUN_TEST(test_circle_around_sensor_yields_no_keypoint);
    RUN_TEST(test_pillar_yields_no_keypoint);
    RUN_TEST(test_empty_all_invalid_and_single_beam_scans_give_no_keypoint);
    RUN_TEST(test_invalid_beam_coordinates_never_change_keypoints);
    RUN_TEST(test_non_finite_points_of_valid_beams_are_never_neighbours);
    RUN_TEST(test_nan_ranges_are_skipped_not_propagated);
    RUN_TEST(test_null_arguments_are_refused);
    RUN_TEST(test_bad_geometry_and_oversized_scan_are_refused);
    RUN_TEST(test_bad_parameters_are_refused);
    RUN_TEST(test_defaults_are_falkolib_defaults);
    RUN_TEST(test_max_range_excludes_far_corner);
    RUN_TEST(test_without_subbeam_point_is_the_beam_point);
    RUN_TEST(test_paper_circular_distance_also_finds_the_corner);
    RUN_TEST(test_scan_at_capacity_finds_room_corners);
    RUN_TEST(test_too_small_output_reports_capacity_and_total);
    RUN_TEST(test_clockwise_scan_finds_the_same_corner);
    RUN_TEST(test_nms_windows_follow_range);
    RUN_TEST(test_nms_plateau_collapses_to_middle);
    RUN_TEST(test_nms_threshold_is_strict);
    RUN_TEST(test_nms_suppresses_weaker_beam_inside_window);
    RUN_TEST(test_nms_lower_is_better_mirrors_higher_is_better);
    return UNITY_END();
}
