/* SPDX-License-Identifier: MIT */
#include "bsf_scene.h"

#include <math.h>
#include <string.h>

#define SCENE_PI 3.14159265358979323846
/* Rays start this far out so a sensor standing on a surface does not hit it. */
#define SCENE_T_MIN 1e-9
/* Endpoints closer than this are the same vertex (a corner). */
#define SCENE_JOIN_EPS 1e-9
/* Angles within this of pi are collinear joints, not corners. */
#define SCENE_COLLINEAR_EPS 1e-6
#define SCENE_FAR 1e300
/* Angle either side of a vertex at which its two walls must be seen, radians. */
#define SCENE_SIDE_EPS 1e-6

static int finite_d(double v)
{
    return v == v && fabs(v) <= 1.7976931348623157e308;
}

void bsf_scene_init(bsf_scene_t *scene)
{
    if (scene != NULL) {
        memset(scene, 0, sizeof *scene);
    }
}

int bsf_scene_add_segment(bsf_scene_t *scene, double x0, double y0, double x1, double y1)
{
    bsf_shape_t *s;
    if (scene == NULL || !finite_d(x0) || !finite_d(y0) || !finite_d(x1) || !finite_d(y1) ||
        (x0 == x1 && y0 == y1)) {
        return BSF_ERR_ARG;
    }
    if (scene->n_shapes >= BSF_SCENE_MAX_SHAPES) {
        return BSF_ERR_CAPACITY;
    }
    s = &scene->shape[scene->n_shapes];
    s->kind = BSF_SHAPE_SEGMENT;
    s->x0 = x0;
    s->y0 = y0;
    s->x1 = x1;
    s->y1 = y1;
    s->r = 0.0;
    return (int)scene->n_shapes++;
}

int bsf_scene_add_circle(bsf_scene_t *scene, double cx, double cy, double r)
{
    bsf_shape_t *s;
    if (scene == NULL || !finite_d(cx) || !finite_d(cy) || !finite_d(r) || !(r > 0.0)) {
        return BSF_ERR_ARG;
    }
    if (scene->n_shapes >= BSF_SCENE_MAX_SHAPES) {
        return BSF_ERR_CAPACITY;
    }
    s = &scene->shape[scene->n_shapes];
    s->kind = BSF_SHAPE_CIRCLE;
    s->x0 = cx;
    s->y0 = cy;
    s->x1 = cx;
    s->y1 = cy;
    s->r = r;
    return (int)scene->n_shapes++;
}

bsf_status_t bsf_scene_add_polyline(bsf_scene_t *scene, const double *xy, size_t n_vertices,
                                    int closed)
{
    size_t n_edges;
    size_t k;
    if (scene == NULL || xy == NULL || n_vertices < 2u || (closed && n_vertices < 3u)) {
        return BSF_ERR_ARG;
    }
    n_edges = closed ? n_vertices : n_vertices - 1u;
    for (k = 0; k < n_vertices; ++k) {
        if (!finite_d(xy[2u * k]) || !finite_d(xy[2u * k + 1u])) {
            return BSF_ERR_ARG;
        }
    }
    for (k = 0; k < n_edges; ++k) {
        const size_t a = k;
        const size_t b = (k + 1u) % n_vertices;
        if (xy[2u * a] == xy[2u * b] && xy[2u * a + 1u] == xy[2u * b + 1u]) {
            return BSF_ERR_ARG;
        }
    }
    if (n_edges > BSF_SCENE_MAX_SHAPES - scene->n_shapes) {
        return BSF_ERR_CAPACITY;
    }
    for (k = 0; k < n_edges; ++k) {
        const size_t a = k;
        const size_t b = (k + 1u) % n_vertices;
        /* Cannot fail: inputs and room were checked above. */
        (void)bsf_scene_add_segment(scene, xy[2u * a], xy[2u * a + 1u], xy[2u * b],
                                    xy[2u * b + 1u]);
    }
    return BSF_OK;
}

static bsf_status_t rect_corners(double x0, double y0, double x1, double y1, double xy[8])
{
    if (!(x0 != x1) || !(y0 != y1)) {
        return BSF_ERR_ARG;
    }
    xy[0] = x0;
    xy[1] = y0;
    xy[2] = x1;
    xy[3] = y0;
    xy[4] = x1;
    xy[5] = y1;
    xy[6] = x0;
    xy[7] = y1;
    return BSF_OK;
}

bsf_status_t bsf_scene_add_rect_room(bsf_scene_t *scene, double x0, double y0, double x1, double y1)
{
    double xy[8];
    const bsf_status_t st = rect_corners(x0, y0, x1, y1, xy);
    return st != BSF_OK ? st : bsf_scene_add_polyline(scene, xy, 4u, 1);
}

bsf_status_t bsf_scene_add_solid(bsf_scene_t *scene, const double *xy, size_t n_vertices)
{
    const size_t first = scene != NULL ? scene->n_shapes : 0u;
    size_t k;
    bsf_status_t st = bsf_scene_add_polyline(scene, xy, n_vertices, 1);
    if (st != BSF_OK) {
        return st;
    }
    ++scene->n_solids;
    for (k = first; k < scene->n_shapes; ++k) {
        scene->shape[k].solid = scene->n_solids;
    }
    return BSF_OK;
}

bsf_status_t bsf_scene_add_box(bsf_scene_t *scene, double x0, double y0, double x1, double y1)
{
    double xy[8];
    const bsf_status_t st = rect_corners(x0, y0, x1, y1, xy);
    return st != BSF_OK ? st : bsf_scene_add_solid(scene, xy, 4u);
}

/* Whether (x,y) is inside solid polygon `id`: the edges carrying that id
 * crossed an odd number of times by a ray towards +x. */
static int inside_solid(const bsf_scene_t *scene, int id, double x, double y)
{
    int inside = 0;
    size_t k;
    for (k = 0; k < scene->n_shapes; ++k) {
        const bsf_shape_t *s = &scene->shape[k];
        if (s->kind == BSF_SHAPE_SEGMENT && s->solid == id && ((s->y0 > y) != (s->y1 > y)) &&
            x < s->x0 + (y - s->y0) * (s->x1 - s->x0) / (s->y1 - s->y0)) {
            inside = !inside;
        }
    }
    return inside;
}

int bsf_scene_pose_blocked(const bsf_scene_t *scene, double x, double y, double clearance)
{
    size_t k;
    int shape = -1;
    if (scene == NULL || !finite_d(x) || !finite_d(y)) {
        return 0;
    }
    for (k = 0; k < scene->n_shapes; ++k) {
        const bsf_shape_t *s = &scene->shape[k];
        if (s->kind == BSF_SHAPE_CIRCLE) {
            const double dx = x - s->x0;
            const double dy = y - s->y0;
            if (sqrt(dx * dx + dy * dy) < s->r) {
                return (int)k;
            }
        } else if (s->solid > 0 && inside_solid(scene, s->solid, x, y)) {
            return (int)k;
        }
    }
    if (bsf_scene_distance_to_surface(scene, x, y, &shape) < clearance) {
        return shape;
    }
    return -1;
}

int bsf_scene_point_enclosed(const bsf_scene_t *scene, double x, double y, size_t n_rays)
{
    size_t k;
    if (scene == NULL || n_rays == 0u) {
        return 0;
    }
    for (k = 0; k < n_rays; ++k) {
        const double a = 2.0 * SCENE_PI * (double)k / (double)n_rays;
        if (bsf_scene_raycast(scene, x, y, a, NULL) < 0.0) {
            return 0;
        }
    }
    return 1;
}

bsf_status_t bsf_scene_add_corner(bsf_scene_t *scene, double vx, double vy, double heading_a,
                                  double len_a, double heading_b, double len_b)
{
    double xy[6];
    if (!finite_d(heading_a) || !finite_d(heading_b) || !(len_a > 0.0) || !(len_b > 0.0) ||
        !finite_d(len_a) || !finite_d(len_b)) {
        return BSF_ERR_ARG;
    }
    /* Walk from the end of wall a through the vertex to the end of wall b. */
    xy[0] = vx + len_a * cos(heading_a);
    xy[1] = vy + len_a * sin(heading_a);
    xy[2] = vx;
    xy[3] = vy;
    xy[4] = vx + len_b * cos(heading_b);
    xy[5] = vy + len_b * sin(heading_b);
    return bsf_scene_add_polyline(scene, xy, 3u, 0);
}

bsf_status_t bsf_scene_add_l_room(bsf_scene_t *scene, double x0, double y0, double w, double h,
                                  double notch_w, double notch_h)
{
    double xy[12];
    if (!(notch_w > 0.0) || !(notch_w < w) || !(notch_h > 0.0) || !(notch_h < h)) {
        return BSF_ERR_ARG;
    }
    xy[0] = x0;
    xy[1] = y0;
    xy[2] = x0 + w;
    xy[3] = y0;
    xy[4] = x0 + w;
    xy[5] = y0 + h - notch_h;
    xy[6] = x0 + w - notch_w; /* the reflex corner */
    xy[7] = y0 + h - notch_h;
    xy[8] = x0 + w - notch_w;
    xy[9] = y0 + h;
    xy[10] = x0;
    xy[11] = y0 + h;
    return bsf_scene_add_polyline(scene, xy, 6u, 1);
}

bsf_status_t bsf_scene_add_room_with_pillar(bsf_scene_t *scene, double x0, double y0, double x1,
                                            double y1, double pcx, double pcy, double pillar_r)
{
    bsf_status_t st;
    int idx;
    if (scene == NULL) {
        return BSF_ERR_ARG;
    }
    if (scene->n_shapes + 5u > BSF_SCENE_MAX_SHAPES) {
        return BSF_ERR_CAPACITY;
    }
    if (!finite_d(pcx) || !finite_d(pcy) || !finite_d(pillar_r) || !(pillar_r > 0.0)) {
        return BSF_ERR_ARG;
    }
    st = bsf_scene_add_rect_room(scene, x0, y0, x1, y1);
    if (st != BSF_OK) {
        return st;
    }
    idx = bsf_scene_add_circle(scene, pcx, pcy, pillar_r);
    return idx < 0 ? (bsf_status_t)idx : BSF_OK;
}

bsf_lidar_t bsf_lidar_default(double x, double y, double theta, size_t n_beams, double fov)
{
    bsf_lidar_t l;
    memset(&l, 0, sizeof l);
    if (n_beams < 2u) {
        return l;
    }
    l.pose.x = x;
    l.pose.y = y;
    l.pose.theta = theta;
    l.n_beams = n_beams;
    l.angle_min = -0.5 * fov;
    l.angle_increment = fov / (double)(n_beams - 1u);
    l.range_max = 30.0;
    l.noise_sigma = 0.0;
    l.no_return = (float)(l.range_max + 1.0);
    return l;
}

/* ---- random numbers ------------------------------------------------------- */

void bsf_scene_rng_seed(bsf_scene_rng_t *rng, uint64_t seed)
{
    /* splitmix64 scrambles the seed; xorshift needs a non-zero state. */
    uint64_t z = seed + 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    rng->state = z != 0u ? z : 0x2545F4914F6CDD1Dull;
    rng->spare = 0.0;
    rng->has_spare = 0;
}

uint64_t bsf_scene_rng_next(bsf_scene_rng_t *rng)
{
    uint64_t x = rng->state;
    x ^= x >> 12;
    x ^= x << 25;
    x ^= x >> 27;
    rng->state = x;
    return x * 0x2545F4914F6CDD1Dull;
}

double bsf_scene_rng_uniform(bsf_scene_rng_t *rng)
{
    /* 53 random bits, shifted by one so 0 never occurs (log(0) in Box-Muller). */
    const uint64_t bits = bsf_scene_rng_next(rng) >> 11;
    return ((double)bits + 1.0) * (1.0 / 9007199254740992.0);
}

double bsf_scene_rng_gauss(bsf_scene_rng_t *rng)
{
    double u1;
    double u2;
    double mag;
    if (rng->has_spare) {
        rng->has_spare = 0;
        return rng->spare;
    }
    u1 = bsf_scene_rng_uniform(rng);
    u2 = bsf_scene_rng_uniform(rng);
    mag = sqrt(-2.0 * log(u1));
    rng->spare = mag * sin(2.0 * SCENE_PI * u2);
    rng->has_spare = 1;
    return mag * cos(2.0 * SCENE_PI * u2);
}

/* ---- ray casting ---------------------------------------------------------- */

/* Distance along the unit ray (ox,oy)+(dx,dy)t to shape s, or -1 when missed. */
static double ray_hit(const bsf_shape_t *s, double ox, double oy, double dx, double dy)
{
    if (s->kind == BSF_SHAPE_SEGMENT) {
        const double ex = s->x1 - s->x0;
        const double ey = s->y1 - s->y0;
        const double px = s->x0 - ox;
        const double py = s->y0 - oy;
        const double denom = dx * ey - dy * ex;
        double t;
        double u;
        if (denom == 0.0) {
            return -1.0; /* parallel: a grazing ray sees no wall */
        }
        t = (px * ey - py * ex) / denom;
        u = (px * dy - py * dx) / denom;
        if (t > SCENE_T_MIN && u >= 0.0 && u <= 1.0) {
            return t;
        }
        return -1.0;
    } else {
        const double fx = ox - s->x0;
        const double fy = oy - s->y0;
        const double b = fx * dx + fy * dy;
        const double c = fx * fx + fy * fy - s->r * s->r;
        const double disc = b * b - c;
        double q;
        if (disc < 0.0) {
            return -1.0;
        }
        q = sqrt(disc);
        if (-b - q > SCENE_T_MIN) {
            return -b - q;
        }
        if (-b + q > SCENE_T_MIN) {
            return -b + q; /* sensor inside the circle: its far side */
        }
        return -1.0;
    }
}

double bsf_scene_raycast(const bsf_scene_t *scene, double ox, double oy, double angle,
                         int *hit_shape)
{
    const double dx = cos(angle);
    const double dy = sin(angle);
    double best = -1.0;
    int best_shape = -1;
    size_t k;
    if (scene != NULL) {
        for (k = 0; k < scene->n_shapes; ++k) {
            const double t = ray_hit(&scene->shape[k], ox, oy, dx, dy);
            if (t > 0.0 && (best < 0.0 || t < best)) {
                best = t;
                best_shape = (int)k;
            }
        }
    }
    if (hit_shape != NULL) {
        *hit_shape = best_shape;
    }
    return best;
}

bsf_status_t bsf_scene_scan(const bsf_scene_t *scene, const bsf_lidar_t *lidar,
                            bsf_scene_rng_t *rng, float *ranges, int16_t *hit_shape, size_t cap)
{
    size_t i;
    if (scene == NULL || lidar == NULL || ranges == NULL) {
        return BSF_ERR_ARG;
    }
    if (!finite_d(lidar->angle_min) || !finite_d(lidar->angle_increment) ||
        lidar->angle_increment == 0.0 || !(lidar->range_max > 0.0) ||
        !finite_d(lidar->noise_sigma) || lidar->noise_sigma < 0.0 ||
        (lidar->noise_sigma > 0.0 && rng == NULL) || !finite_d(lidar->pose.x) ||
        !finite_d(lidar->pose.y) || !finite_d(lidar->pose.theta)) {
        return BSF_ERR_ARG;
    }
    if (lidar->n_beams == 0u || lidar->n_beams > cap || lidar->n_beams > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    for (i = 0; i < lidar->n_beams; ++i) {
        const double a = lidar->pose.theta + lidar->angle_min + (double)i * lidar->angle_increment;
        int shape = -1;
        double t = bsf_scene_raycast(scene, lidar->pose.x, lidar->pose.y, a, &shape);
        if (t < 0.0 || t > lidar->range_max) {
            ranges[i] = lidar->no_return;
            shape = -1;
        } else {
            if (lidar->noise_sigma > 0.0) {
                t += lidar->noise_sigma * bsf_scene_rng_gauss(rng);
                if (t < 0.0) {
                    t = 0.0;
                }
            }
            ranges[i] = (float)t;
        }
        if (hit_shape != NULL) {
            hit_shape[i] = (int16_t)shape;
        }
    }
    return BSF_OK;
}

bsf_scan_t bsf_scene_lidar_scan(const bsf_lidar_t *lidar, const float *ranges)
{
    bsf_scan_t s;
    memset(&s, 0, sizeof s);
    if (lidar == NULL) {
        return s;
    }
    s.ranges = ranges;
    s.count = lidar->n_beams;
    s.angle_min = (float)lidar->angle_min;
    s.angle_increment = (float)lidar->angle_increment;
    s.range_min = 0.0f;
    s.range_max = (float)lidar->range_max;
    return s;
}

/* ---- ground truth --------------------------------------------------------- */

void bsf_scene_sensor_to_world(const bsf_scene_pose_t *pose, double sx, double sy, double *wx,
                               double *wy)
{
    const double c = cos(pose->theta);
    const double s = sin(pose->theta);
    *wx = pose->x + c * sx - s * sy;
    *wy = pose->y + s * sx + c * sy;
}

void bsf_scene_world_to_sensor(const bsf_scene_pose_t *pose, double wx, double wy, double *sx,
                               double *sy)
{
    const double c = cos(pose->theta);
    const double s = sin(pose->theta);
    const double dx = wx - pose->x;
    const double dy = wy - pose->y;
    *sx = c * dx + s * dy;
    *sy = -s * dx + c * dy;
}

int bsf_scene_beam_of_bearing(const bsf_lidar_t *lidar, double bearing)
{
    int m;
    if (lidar == NULL || lidar->n_beams == 0u || lidar->angle_increment == 0.0 ||
        !finite_d(bearing)) {
        return -1;
    }
    /* The field of view may straddle +-pi: try the bearing one turn either way. */
    for (m = -2; m <= 2; ++m) {
        const double k =
            (bearing + (double)m * 2.0 * SCENE_PI - lidar->angle_min) / lidar->angle_increment;
        if (k >= -0.5 && k <= (double)lidar->n_beams - 0.5) {
            long idx = (long)floor(k + 0.5);
            if (idx > (long)lidar->n_beams - 1) {
                idx = (long)lidar->n_beams - 1;
            }
            if (idx < 0) {
                idx = 0;
            }
            return (int)idx;
        }
    }
    return -1;
}

static int same_point(double ax, double ay, double bx, double by)
{
    return fabs(ax - bx) <= SCENE_JOIN_EPS && fabs(ay - by) <= SCENE_JOIN_EPS;
}

/* Unit-free direction of the wall from its endpoint (vx,vy) into the wall. */
static void wall_direction(const bsf_shape_t *s, double vx, double vy, double *ux, double *uy)
{
    if (same_point(s->x0, s->y0, vx, vy)) {
        *ux = s->x1 - s->x0;
        *uy = s->y1 - s->y0;
    } else {
        *ux = s->x0 - s->x1;
        *uy = s->y0 - s->y1;
    }
}

/* Fills a corner record; returns 0 when the joint is collinear (no corner). */
static int make_corner(const bsf_scene_t *scene, const bsf_lidar_t *lidar, size_t a, size_t b,
                       double vx, double vy, bsf_scene_corner_t *c)
{
    double ax, ay, bx, by;
    double angle;
    double sx, sy;
    double t;
    int shape;
    wall_direction(&scene->shape[a], vx, vy, &ax, &ay);
    wall_direction(&scene->shape[b], vx, vy, &bx, &by);
    angle = atan2(fabs(ax * by - ay * bx), ax * bx + ay * by);
    if (angle > SCENE_PI - SCENE_COLLINEAR_EPS) {
        return 0;
    }
    bsf_scene_world_to_sensor(&lidar->pose, vx, vy, &sx, &sy);
    c->x = sx;
    c->y = sy;
    c->wx = vx;
    c->wy = vy;
    c->range = sqrt(sx * sx + sy * sy);
    c->bearing = atan2(sy, sx);
    c->angle = angle;
    c->beam = bsf_scene_beam_of_bearing(lidar, c->bearing);
    c->shape_a = (uint16_t)a;
    c->shape_b = (uint16_t)b;
    c->visible = 0;
    if (c->beam >= 0 && c->range <= lidar->range_max && c->range > 0.0) {
        const double dir = atan2(vy - lidar->pose.y, vx - lidar->pose.x);
        int left = -1;
        int right = -1;
        /* Occluded when a surface lies clearly before the vertex on its line
         * of sight. Seen as a corner only when rays just either side of the
         * vertex hit its two walls, one each: with one wall hidden behind
         * the vertex (or seen edge-on) it is a jump edge, not a corner. */
        t = bsf_scene_raycast(scene, lidar->pose.x, lidar->pose.y, dir, &shape);
        if (t < 0.0 || t >= c->range - 1e-6) {
            (void)bsf_scene_raycast(scene, lidar->pose.x, lidar->pose.y, dir + SCENE_SIDE_EPS,
                                    &left);
            (void)bsf_scene_raycast(scene, lidar->pose.x, lidar->pose.y, dir - SCENE_SIDE_EPS,
                                    &right);
            c->visible =
                ((left == (int)a && right == (int)b) || (left == (int)b && right == (int)a)) ? 1
                                                                                             : 0;
        }
    }
    return 1;
}

bsf_status_t bsf_scene_corners(const bsf_scene_t *scene, const bsf_lidar_t *lidar,
                               bsf_scene_corner_t *out, size_t cap, size_t *n_out)
{
    size_t a;
    size_t b;
    size_t n = 0;
    if (scene == NULL || lidar == NULL || n_out == NULL || (out == NULL && cap > 0u)) {
        return BSF_ERR_ARG;
    }
    for (a = 0; a < scene->n_shapes; ++a) {
        const bsf_shape_t *sa = &scene->shape[a];
        if (sa->kind != BSF_SHAPE_SEGMENT) {
            continue;
        }
        for (b = a + 1u; b < scene->n_shapes; ++b) {
            const bsf_shape_t *sb = &scene->shape[b];
            double vx;
            double vy;
            bsf_scene_corner_t c;
            int end;
            if (sb->kind != BSF_SHAPE_SEGMENT) {
                continue;
            }
            /* Each of a's two endpoints may touch one of b's. */
            for (end = 0; end < 2; ++end) {
                vx = end == 0 ? sa->x0 : sa->x1;
                vy = end == 0 ? sa->y0 : sa->y1;
                if (!same_point(vx, vy, sb->x0, sb->y0) && !same_point(vx, vy, sb->x1, sb->y1)) {
                    continue;
                }
                if (!make_corner(scene, lidar, a, b, vx, vy, &c)) {
                    continue;
                }
                if (n < cap) {
                    out[n] = c;
                }
                ++n;
            }
        }
    }
    *n_out = n;
    return n > cap ? BSF_ERR_CAPACITY : BSF_OK;
}

double bsf_scene_distance_to_surface(const bsf_scene_t *scene, double wx, double wy, int *shape)
{
    double best = SCENE_FAR;
    int best_shape = -1;
    size_t k;
    if (scene != NULL) {
        for (k = 0; k < scene->n_shapes; ++k) {
            const bsf_shape_t *s = &scene->shape[k];
            double d;
            if (s->kind == BSF_SHAPE_SEGMENT) {
                const double ex = s->x1 - s->x0;
                const double ey = s->y1 - s->y0;
                double u = ((wx - s->x0) * ex + (wy - s->y0) * ey) / (ex * ex + ey * ey);
                double px;
                double py;
                u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
                px = s->x0 + u * ex - wx;
                py = s->y0 + u * ey - wy;
                d = sqrt(px * px + py * py);
            } else {
                const double cx = wx - s->x0;
                const double cy = wy - s->y0;
                d = fabs(sqrt(cx * cx + cy * cy) - s->r);
            }
            if (d < best) {
                best = d;
                best_shape = (int)k;
            }
        }
    }
    if (shape != NULL) {
        *shape = best_shape;
    }
    return best;
}

void bsf_scene_demo_office(bsf_scene_t *sc)
{
    static const double outline[] = {0.0, 0.0, 14.0, 0.0,  14.0, 6.0,
                                     9.0, 6.0, 9.0,  10.0, 0.0,  10.0};
    bsf_scene_init(sc);
    (void)bsf_scene_add_polyline(sc, outline, 6u, 1);
    /* a partition wall with a doorway, a cabinet, a pillar */
    (void)bsf_scene_add_segment(sc, 5.0, 0.0, 5.0, 3.0);
    (void)bsf_scene_add_segment(sc, 5.0, 4.2, 5.0, 7.0);
    (void)bsf_scene_add_box(sc, 2.0, 7.5, 3.5, 8.3);
    (void)bsf_scene_add_circle(sc, 10.5, 3.0, 0.45);
}

void bsf_scene_demo_pose(long k, long n, double *x, double *y, double *theta)
{
    const double s = (double)k / (double)n;
    *x = 3.0 + 8.0 * (0.5 - 0.5 * cos(2.0 * SCENE_PI * s));
    *y = 3.6 + 1.2 * sin(2.0 * SCENE_PI * s);
    *theta = atan2(1.2 * 2.0 * SCENE_PI * cos(2.0 * SCENE_PI * s),
                   8.0 * SCENE_PI * sin(2.0 * SCENE_PI * s) + 1e-9);
}

/* ---- cluttered rooms ------------------------------------------------------ */

size_t bsf_scene_clutter_shapes(const bsf_scene_clutter_t *c)
{
    if (c == NULL) {
        return 0u;
    }
    return (c->n_teeth > 0u ? 4u * c->n_teeth + 2u : 4u) + c->n_posts + 4u * c->n_boxes;
}

/* One long wall at height y from x = -half_w to +half_w, with n_teeth teeth
 * standing `depth` towards y = 0; joints computed once so walls share them. */
static void add_toothed_wall(bsf_scene_t *scene, double half_w, double y, size_t n_teeth,
                             double depth)
{
    const double step = 2.0 * half_w / (double)(2u * n_teeth);
    const double inward = y > 0.0 ? -depth : depth;
    size_t k;
    for (k = 0; k < 2u * n_teeth; ++k) {
        const double xa = -half_w + step * (double)k;
        const double xb = (k + 1u == 2u * n_teeth) ? half_w : -half_w + step * (double)(k + 1u);
        const double ya = (k % 2u == 0u) ? y : y + inward;
        const double yb = (k % 2u == 0u) ? y + inward : y;
        (void)bsf_scene_add_segment(scene, xa, ya, xb, yb);
    }
}

/* A random object centre inside the room, `margin` from the walls and `clear`
 * from the origin (tries until one fits; the room is larger than both). */
static void clutter_place(const bsf_scene_clutter_t *c, double margin, bsf_scene_rng_t *rng,
                          double *x, double *y)
{
    int tries;
    for (tries = 0; tries < 1000; ++tries) {
        *x = (2.0 * bsf_scene_rng_uniform(rng) - 1.0) * (c->half_w - margin);
        *y = (2.0 * bsf_scene_rng_uniform(rng) - 1.0) * (c->half_h - margin);
        if (*x * *x + *y * *y >= c->clear * c->clear) {
            return;
        }
    }
    *x = c->half_w - margin; /* a corner of the room: certainly clear */
    *y = c->half_h - margin;
}

bsf_status_t bsf_scene_add_clutter_room(bsf_scene_t *scene, const bsf_scene_clutter_t *c,
                                        bsf_scene_rng_t *rng)
{
    const double wall_margin = 0.3 + 0.36; /* a box's half diagonal stays inside */
    double margin;
    size_t k;
    if (scene == NULL || c == NULL || rng == NULL || !finite_d(c->half_w) || !finite_d(c->half_h) ||
        !(c->half_w > 1.0) || !(c->half_h > 1.0) || !finite_d(c->clear) || !(c->clear >= 0.0) ||
        (c->n_teeth > 0u && !(c->tooth_depth > 0.0 && c->tooth_depth < 0.5 * c->half_h))) {
        return BSF_ERR_ARG;
    }
    if (bsf_scene_clutter_shapes(c) > BSF_SCENE_MAX_SHAPES - scene->n_shapes) {
        return BSF_ERR_CAPACITY;
    }
    margin = wall_margin + (c->n_teeth > 0u ? c->tooth_depth : 0.0);
    if (c->n_teeth == 0u) {
        (void)bsf_scene_add_rect_room(scene, -c->half_w, -c->half_h, c->half_w, c->half_h);
    } else {
        add_toothed_wall(scene, c->half_w, -c->half_h, c->n_teeth, c->tooth_depth);
        add_toothed_wall(scene, c->half_w, c->half_h, c->n_teeth, c->tooth_depth);
        (void)bsf_scene_add_segment(scene, c->half_w, -c->half_h, c->half_w, c->half_h);
        (void)bsf_scene_add_segment(scene, -c->half_w, c->half_h, -c->half_w, -c->half_h);
    }
    for (k = 0; k < c->n_posts; ++k) {
        double x;
        double y;
        const double r = 0.03 + 0.09 * bsf_scene_rng_uniform(rng);
        clutter_place(c, margin, rng, &x, &y);
        (void)bsf_scene_add_circle(scene, x, y, r);
    }
    for (k = 0; k < c->n_boxes; ++k) {
        double x;
        double y;
        const double half = 0.5 * (0.2 + 0.3 * bsf_scene_rng_uniform(rng));
        const double a = 2.0 * SCENE_PI * bsf_scene_rng_uniform(rng);
        const double ux = half * cos(a);
        const double uy = half * sin(a);
        double xy[8];
        clutter_place(c, margin, rng, &x, &y);
        xy[0] = x + ux - uy;
        xy[1] = y + uy + ux;
        xy[2] = x - ux - uy;
        xy[3] = y - uy + ux;
        xy[4] = x - ux + uy;
        xy[5] = y - uy - ux;
        xy[6] = x + ux + uy;
        xy[7] = y + uy - ux;
        (void)bsf_scene_add_solid(scene, xy, 4u);
    }
    return BSF_OK;
}

/* ---- ground-truth benchmark scenes ---------------------------------------- */

void bsf_scene_truth_angles(bsf_scene_t *sc)
{
    /* Counter-clockwise outline; (1.5, 4) and (5, 7.5) are reflex notches. */
    static const double outline[] = {0.0,  0.0, 10.0, 0.0, 10.0, 3.0, 12.0, 4.5,
                                     12.0, 9.0, 7.0,  9.0, 5.0,  7.5, 2.0,  9.0,
                                     0.0,  9.0, 0.0,  5.0, 1.5,  4.0, 0.0,  3.0};
    const double c = cos(SCENE_PI / 6.0);
    const double s = sin(SCENE_PI / 6.0);
    double box[8];
    static const double bx[4] = {-0.4, 0.4, 0.4, -0.4};
    static const double by[4] = {-0.25, -0.25, 0.25, 0.25};
    size_t k;
    bsf_scene_init(sc);
    (void)bsf_scene_add_polyline(sc, outline, 12u, 1);
    for (k = 0; k < 4u; ++k) {
        box[2u * k] = 6.0 + c * bx[k] - s * by[k];
        box[2u * k + 1u] = 4.3 + s * bx[k] + c * by[k];
    }
    (void)bsf_scene_add_solid(sc, box, 4u);
    (void)bsf_scene_add_segment(sc, 8.0, 7.6, 10.0, 8.2);
    (void)bsf_scene_add_circle(sc, 2.5, 7.2, 0.3);
    (void)bsf_scene_add_circle(sc, 9.0, 1.2, 0.025);
    (void)bsf_scene_add_circle(sc, 9.4, 1.2, 0.025);
    (void)bsf_scene_add_circle(sc, 9.0, 1.6, 0.025);
    (void)bsf_scene_add_circle(sc, 9.4, 1.6, 0.025);
}

void bsf_scene_truth_curved(bsf_scene_t *sc)
{
    bsf_scene_init(sc);
    (void)bsf_scene_add_circle(sc, 0.0, 0.0, 5.0);
    (void)bsf_scene_add_segment(sc, -6.0, -2.0, 3.5, -2.0);
    (void)bsf_scene_add_segment(sc, 3.5, -2.0, 3.5, 6.0);
    (void)bsf_scene_add_circle(sc, -4.5, 3.5, 1.5);
    (void)bsf_scene_add_circle(sc, -1.0, 3.0, 0.4);
    (void)bsf_scene_add_circle(sc, 1.5, 2.5, 0.2);
    (void)bsf_scene_add_box(sc, -3.0, -1.2, -2.4, -0.6);
}

void bsf_scene_truth_pose(int which, long k, long n, double *x, double *y, double *theta)
{
    const double s = n > 0 ? (double)k / (double)n : 0.0;
    const double a = 2.0 * SCENE_PI * s;
    double cx = 6.0;
    double cy = 4.5;
    double rx = 3.5;
    double ry = 2.0;
    double h;
    if (which == 0) {
        bsf_scene_demo_pose(k, n, x, y, theta);
        return;
    }
    if (which == 2) {
        cx = 0.0;
        cy = 0.8;
        rx = 2.0;
        ry = 1.2;
    }
    *x = cx + rx * cos(a);
    *y = cy + ry * sin(a);
    h = atan2(ry * cos(a), -rx * sin(a)) + 0.9 * sin(3.0 * a);
    *theta = atan2(sin(h), cos(h));
}

size_t bsf_scene_mixed_pixels(float *ranges, size_t n, float no_return, double jump, double prob,
                              bsf_scene_rng_t *rng)
{
    size_t i;
    size_t changed = 0;
    if (ranges == NULL || rng == NULL || n < 2u) {
        return 0u;
    }
    for (i = 0; i + 1u < n; ++i) {
        const double a = (double)ranges[i];
        const double b = (double)ranges[i + 1u];
        double w;
        if (ranges[i] == no_return || ranges[i + 1u] == no_return || fabs(a - b) <= jump) {
            continue;
        }
        if (bsf_scene_rng_uniform(rng) > prob) {
            continue;
        }
        w = bsf_scene_rng_uniform(rng);
        /* The spot straddles the edge: the far beam of the pair reads between. */
        if (a > b) {
            ranges[i] = (float)(b + w * (a - b));
        } else {
            ranges[i + 1u] = (float)(a + w * (b - a));
        }
        ++changed;
        ++i; /* the pair is used */
    }
    return changed;
}
