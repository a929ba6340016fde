/* SPDX-License-Identifier: MIT */
/*
 * bsf_scene.h - synthetic 2D LIDAR scenes for tests, demos and benchmarks.
 *
 * A scene is a set of line segments and full circles in a world frame
 * (metres). A virtual LIDAR at a pose ray-casts into it, adds Gaussian range
 * noise from its own seedable generator, and reports which surface each beam
 * hit. Ground truth: the true corners (where two segments share an
 * endpoint) in the sensor frame with their nearest beam, and the distance of
 * any world point to the nearest surface.
 *
 * Portable C99: no heap, no I/O, only <math.h>, <string.h>, <stdint.h> and
 * <stddef.h>, so it also runs inside unit tests on the emulated Cortex-M4F.
 * Geometry is computed in double (exact hits, robust at grazing angles);
 * ranges come out as float, as a driver delivers them.
 *
 * Not part of the library: nothing in src/ may include this header.
 */
#ifndef BSF_SCENE_H
#define BSF_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "bsf/bsf_common.h"
#include "bsf/bsf_scan.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Largest number of shapes (segments and circles) in one scene. */
#ifndef BSF_SCENE_MAX_SHAPES
#define BSF_SCENE_MAX_SHAPES 64
#endif

/** Kind of a scene shape. */
typedef enum {
    BSF_SHAPE_SEGMENT = 0, /**< line segment from (x0,y0) to (x1,y1) */
    BSF_SHAPE_CIRCLE = 1   /**< full circle, centre (x0,y0), radius r */
} bsf_shape_kind_t;

/** One surface of a scene, world frame, metres. */
typedef struct {
    int kind;      /**< a bsf_shape_kind_t */
    double x0, y0; /**< segment start, or circle centre */
    double x1, y1; /**< segment end (unused for a circle) */
    double r;      /**< circle radius (unused for a segment) */
    int solid;     /**< segment: 0 for a wall, k > 0 for an edge of the k-th solid
                        polygon (bsf_scene_add_solid); circles are always solid */
} bsf_shape_t;

/** A scene: up to BSF_SCENE_MAX_SHAPES surfaces. Fixed size, caller-owned. */
typedef struct {
    bsf_shape_t shape[BSF_SCENE_MAX_SHAPES];
    size_t n_shapes;
    int n_solids; /**< solid polygons added so far (bsf_scene_add_solid) */
} bsf_scene_t;

/** A pose in the world frame: position in metres, heading in radians (CCW). */
typedef struct {
    double x;
    double y;
    double theta;
} bsf_scene_pose_t;

/**
 * A virtual LIDAR. Beam i points at pose.theta + angle_min + i*angle_increment
 * in the world. A beam whose nearest surface is farther than range_max (or
 * which hits nothing) returns `no_return`.
 */
typedef struct {
    bsf_scene_pose_t pose;  /**< sensor pose in the world */
    size_t n_beams;         /**< number of beams, 1..BSF_MAX_POINTS */
    double angle_min;       /**< angle of beam 0 in the sensor frame, radians */
    double angle_increment; /**< angle between beams, radians, non-zero */
    double range_max;       /**< farthest surface that still returns, metres (> 0) */
    double noise_sigma;     /**< standard deviation of Gaussian range noise, metres (>= 0) */
    float no_return;        /**< value written for a beam without return */
} bsf_lidar_t;

/** Deterministic pseudo-random generator (xorshift64*) with a Gaussian cache. */
typedef struct {
    uint64_t state;
    double spare; /**< second Box-Muller value, used when has_spare */
    int has_spare;
} bsf_scene_rng_t;

/** A true corner: two segments of the scene sharing an endpoint. */
typedef struct {
    double x, y;      /**< vertex in the sensor frame, metres */
    double wx, wy;    /**< vertex in the world frame, metres */
    double range;     /**< distance from the sensor, metres */
    double bearing;   /**< direction in the sensor frame, radians, in [-pi, pi] */
    double angle;     /**< angle between the two walls at the vertex, radians, (0, pi) */
    int beam;         /**< nearest beam index, -1 when outside the field of view */
    int visible;      /**< 1 when in the field of view, within range_max, not occluded,
                           and both walls are seen next to the vertex (else a jump edge) */
    uint16_t shape_a; /**< index of the first segment */
    uint16_t shape_b; /**< index of the second segment */
} bsf_scene_corner_t;

/** Empty the scene. Does nothing when scene is NULL. */
void bsf_scene_init(bsf_scene_t *scene);

/**
 * Add a line segment (world frame, metres).
 * @return its shape index (>= 0); BSF_ERR_ARG when scene is NULL, a coordinate
 *         is not finite or the segment has zero length; BSF_ERR_CAPACITY when
 *         the scene is full.
 */
int bsf_scene_add_segment(bsf_scene_t *scene, double x0, double y0, double x1, double y1);

/**
 * Add a full circle (world frame, metres).
 * @return its shape index (>= 0); BSF_ERR_ARG when scene is NULL, a value is not
 *         finite or r <= 0; BSF_ERR_CAPACITY when the scene is full.
 */
int bsf_scene_add_circle(bsf_scene_t *scene, double cx, double cy, double r);

/**
 * Add a polyline through n_vertices points xy[2k], xy[2k+1] (metres); closed
 * joins the last vertex back to the first. Consecutive vertices share exact
 * endpoints, so every joint is a ground-truth corner (unless collinear).
 * @return BSF_OK; BSF_ERR_ARG for NULL, n_vertices < 2 (< 3 when closed) or a
 *         zero-length edge; BSF_ERR_CAPACITY when the edges do not fit (the
 *         scene is then left unchanged).
 */
bsf_status_t bsf_scene_add_polyline(bsf_scene_t *scene, const double *xy, size_t n_vertices,
                                    int closed);

/**
 * Add a solid obstacle: the closed polygon through n_vertices points, as
 * bsf_scene_add_polyline with closed = 1, whose inside no sensor may stand in
 * (bsf_scene_pose_blocked). Ray-casting treats its edges as walls.
 * @return as bsf_scene_add_polyline.
 */
bsf_status_t bsf_scene_add_solid(bsf_scene_t *scene, const double *xy, size_t n_vertices);

/**
 * A solid box with corners (x0,y0) and (x1,y1) (a cabinet, a crate): the
 * edges of bsf_scene_add_rect_room, added as bsf_scene_add_solid.
 * @return as bsf_scene_add_solid (BSF_ERR_ARG when degenerate).
 */
bsf_status_t bsf_scene_add_box(bsf_scene_t *scene, double x0, double y0, double x1, double y1);

/**
 * Whether a sensor may stand at world point (x,y): not inside a circle or a
 * solid polygon, and at least `clearance` metres from every surface.
 * @return -1 when the pose is free; otherwise the index of the first shape it
 *         is inside of or too close to (any edge of the solid polygon it is
 *         in). A NULL scene or a non-finite point gives 0.
 */
int bsf_scene_pose_blocked(const bsf_scene_t *scene, double x, double y, double clearance);

/**
 * Whether the world point (x,y) is enclosed: a ray in each of n_rays
 * directions evenly spread over the full circle hits a surface (so the point
 * is inside a room rather than outside it). @return 1 or 0 (0 for NULL or
 * n_rays == 0).
 */
int bsf_scene_point_enclosed(const bsf_scene_t *scene, double x, double y, size_t n_rays);

/**
 * Rectangular room with corners (x0,y0) and (x1,y1): four walls, four 90 degree
 * corners. @return as bsf_scene_add_polyline (BSF_ERR_ARG when degenerate).
 */
bsf_status_t bsf_scene_add_rect_room(bsf_scene_t *scene, double x0, double y0, double x1,
                                     double y1);

/**
 * Two walls meeting at the vertex (vx,vy): one of length len_a in direction
 * heading_a, one of length len_b in direction heading_b (radians, world).
 * With headings differing by pi/2 this is the classic 90 degree corner.
 * @return as bsf_scene_add_polyline.
 */
bsf_status_t bsf_scene_add_corner(bsf_scene_t *scene, double vx, double vy, double heading_a,
                                  double len_a, double heading_b, double len_b);

/**
 * L-shaped room: the rectangle (x0,y0)-(x0+w,y0+h) with the rectangle of size
 * notch_w x notch_h cut from its (x0+w, y0+h) corner. Six walls, five convex
 * corners and one reflex corner at (x0+w-notch_w, y0+h-notch_h).
 * @return as bsf_scene_add_polyline; BSF_ERR_ARG unless 0 < notch_w < w and
 *         0 < notch_h < h.
 */
bsf_status_t bsf_scene_add_l_room(bsf_scene_t *scene, double x0, double y0, double w, double h,
                                  double notch_w, double notch_h);

/**
 * Rectangular room (x0,y0)-(x1,y1) with a round pillar of radius pillar_r at
 * (pcx,pcy). @return as bsf_scene_add_rect_room and bsf_scene_add_circle.
 */
bsf_status_t bsf_scene_add_room_with_pillar(bsf_scene_t *scene, double x0, double y0, double x1,
                                            double y1, double pcx, double pcy, double pillar_r);

/**
 * A LIDAR with sensible defaults at pose (x, y, theta): n_beams beams over
 * [-fov/2, +fov/2] (increment fov/(n_beams-1)), range_max 30 m, no noise,
 * no_return = range_max + 1. Returns an all-zero lidar when n_beams < 2.
 */
bsf_lidar_t bsf_lidar_default(double x, double y, double theta, size_t n_beams, double fov);

/** Seed the generator; every seed (0 included) gives a distinct, valid stream. */
void bsf_scene_rng_seed(bsf_scene_rng_t *rng, uint64_t seed);

/** Next uniform 64-bit value of the generator. */
uint64_t bsf_scene_rng_next(bsf_scene_rng_t *rng);

/** Uniform double in (0, 1]. */
double bsf_scene_rng_uniform(bsf_scene_rng_t *rng);

/** Standard normal sample (mean 0, standard deviation 1), Box-Muller. */
double bsf_scene_rng_gauss(bsf_scene_rng_t *rng);

/**
 * Cast one ray from world point (ox,oy) in world direction `angle`.
 * @return distance to the nearest surface, metres, or a negative value when
 *         nothing is hit; *hit_shape (may be NULL) gets the shape index or -1.
 */
double bsf_scene_raycast(const bsf_scene_t *scene, double ox, double oy, double angle,
                         int *hit_shape);

/**
 * Simulate one scan. ranges[i] gets the true distance plus N(0, sigma) noise
 * (clamped at 0), or lidar->no_return when beam i hits nothing within
 * range_max; hit_shape[i] (hit_shape may be NULL) gets the surface index or -1.
 * rng may be NULL only when noise_sigma is 0.
 * @return BSF_OK; BSF_ERR_ARG for NULL scene/lidar/ranges, a non-finite or
 *         zero increment, range_max <= 0, a negative or non-finite sigma, or a
 *         missing rng with noise; BSF_ERR_CAPACITY when n_beams is 0, larger
 *         than cap (the length of ranges and hit_shape) or than BSF_MAX_POINTS.
 */
bsf_status_t bsf_scene_scan(const bsf_scene_t *scene, const bsf_lidar_t *lidar,
                            bsf_scene_rng_t *rng, float *ranges, int16_t *hit_shape, size_t cap);

/**
 * Describe a simulated scan to the library: ranges, count and geometry from
 * the lidar, range_min 0, range_max = lidar->range_max (a noisy hit just past
 * range_max is then invalid, as with a real sensor).
 */
bsf_scan_t bsf_scene_lidar_scan(const bsf_lidar_t *lidar, const float *ranges);

/**
 * The true corners of the scene seen from the lidar: every pair of segments
 * sharing an endpoint (within 1e-9 m) that is not collinear, in the order the
 * segments were added. Corners outside the field of view are reported with
 * beam -1 and visible 0.
 * @return BSF_OK; BSF_ERR_ARG for NULL arguments; BSF_ERR_CAPACITY when more
 *         than cap corners exist (*n_out then holds how many exist).
 */
bsf_status_t bsf_scene_corners(const bsf_scene_t *scene, const bsf_lidar_t *lidar,
                               bsf_scene_corner_t *out, size_t cap, size_t *n_out);

/**
 * Nearest beam index for a sensor-frame bearing (radians), -1 when the bearing
 * lies more than half an increment outside the field of view.
 */
int bsf_scene_beam_of_bearing(const bsf_lidar_t *lidar, double bearing);

/**
 * Distance (metres) from world point (wx,wy) to the nearest surface; a large
 * value (1e300) for an empty scene or NULL. *shape (may be NULL) gets the index
 * of that surface or -1.
 */
double bsf_scene_distance_to_surface(const bsf_scene_t *scene, double wx, double wy, int *shape);

/** Sensor frame (sx,sy) to world frame, for a sensor at pose. */
void bsf_scene_sensor_to_world(const bsf_scene_pose_t *pose, double sx, double sy, double *wx,
                               double *wy);

/** World frame (wx,wy) to the sensor frame of a sensor at pose. */
void bsf_scene_world_to_sensor(const bsf_scene_pose_t *pose, double wx, double wy, double *sx,
                               double *sy);

/**
 * The demo scene of `bsf demo` (also used by the fuzz corpus and the
 * host/target determinism check): a 14 m x 10 m L-shaped office with a
 * partition wall and doorway, a cabinet and a round pillar.
 */
void bsf_scene_demo_office(bsf_scene_t *scene);

/**
 * The demo's sensor pose for scan k of n (a loop through both rooms and the
 * doorway): world position in metres and heading in radians, in (-pi, pi].
 */
void bsf_scene_demo_pose(long k, long n, double *x, double *y, double *theta);

/**
 * A cluttered room for cap tests and cap sizing: a rectangle centred on the
 * origin whose two long walls (top and bottom) may carry zig-zag shelving
 * (each tooth two edges, each joint a corner), plus round posts (chair and
 * table legs) and square boxes at random places, sizes and headings.
 */
typedef struct {
    double half_w;      /**< half the room's width (x), metres, > 1 */
    double half_h;      /**< half the room's height (y), metres, > 1 */
    size_t n_teeth;     /**< zig-zag teeth along each long wall (0: straight walls) */
    double tooth_depth; /**< how far a tooth stands into the room, metres (> 0 when n_teeth > 0) */
    size_t n_posts;     /**< round posts, radius 0.03..0.12 m */
    size_t n_boxes;     /**< square boxes, side 0.2..0.5 m */
    double clear;       /**< no object centre within this distance of the origin, metres */
} bsf_scene_clutter_t;

/** Shapes a cluttered room takes in a scene: 4 * n_teeth + 2 walls (4 when
 *  straight), one per post, four per box. */
size_t bsf_scene_clutter_shapes(const bsf_scene_clutter_t *c);

/**
 * Add a cluttered room (see bsf_scene_clutter_t). Objects are drawn from rng
 * uniformly over the room, at least 0.3 m inside the walls and `clear` from
 * the origin (where the sensor stands); they may overlap one another.
 * Compile the scene with a larger BSF_SCENE_MAX_SHAPES for dense clutter.
 * @return BSF_OK; BSF_ERR_ARG for NULL, a room half size <= 1 m, a tooth depth
 *         that is not in (0, half_h / 2) with teeth, or a negative clear;
 *         BSF_ERR_CAPACITY when the shapes do not fit (scene left unchanged).
 */
bsf_status_t bsf_scene_add_clutter_room(bsf_scene_t *scene, const bsf_scene_clutter_t *c,
                                        bsf_scene_rng_t *rng);

/* ---- ground-truth benchmark scenes (bench_truth, test_truth) ------------- */

/**
 * An office with corners of many angles: a 12 m x 11 m outline with 90, 117,
 * 127, 143 and 153 degree convex corners and two reflex (concave) notches, a
 * free-standing box turned by 30 degrees, a slanted partition, a round pillar
 * and four chair legs (2.5 cm circles) as clutter.
 */
void bsf_scene_truth_angles(bsf_scene_t *scene);

/**
 * A room with curved walls: the sensor stands inside a 5 m circle (a concave
 * curved wall) cut by two straight walls meeting at a 90 degree corner, with a
 * convex bulge (a 1.5 m circle pushing into the room), two round pillars and
 * a square box.
 */
void bsf_scene_truth_curved(bsf_scene_t *scene);

/**
 * Sensor pose k of n on a loop through the free space of a benchmark scene:
 * which = 0 the demo office (as bsf_scene_demo_pose), 1 bsf_scene_truth_angles,
 * 2 bsf_scene_truth_curved. Heading along the loop, turned by a slow wobble so
 * that a narrow field of view sees every side. Unknown `which` gives pose 0.
 */
void bsf_scene_truth_pose(int which, long k, long n, double *x, double *y, double *theta);

/**
 * Mixed pixels: where neighbouring beams i, i+1 differ by more than `jump`
 * metres (both returns), with probability `prob` the nearer-to-the-edge beam
 * of the pair gets a range blended between the two (uniform weight), as a
 * real scanner's spot straddling a depth edge does. Returns the number of
 * beams changed. Beams equal to no_return are left alone.
 */
size_t bsf_scene_mixed_pixels(float *ranges, size_t n, float no_return, double jump, double prob,
                              bsf_scene_rng_t *rng);

#ifdef __cplusplus
}
#endif

#endif /* BSF_SCENE_H */
