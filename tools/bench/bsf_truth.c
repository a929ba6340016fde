/* SPDX-License-Identifier: MIT */
#include "bsf_truth.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define TRUTH_MAX_CORNERS 256
#define TRUTH_MAX_CREASES 256

int bsf_truth_verbose = 0;

void bsf_truth_acc_init(bsf_truth_acc_t *acc)
{
    memset(acc, 0, sizeof *acc);
}

static void hist_add(bsf_truth_hist_t *h, double d)
{
    long bin = (long)(d / BSF_TRUTH_BIN);
    if (bin < 0) {
        bin = 0;
    }
    if (bin > BSF_TRUTH_NBINS) {
        bin = BSF_TRUTH_NBINS;
    }
    h->hist[bin]++;
    h->sum_sq += d * d;
    if (d > h->max) {
        h->max = d;
    }
    h->n++;
}

double bsf_truth_quantile(const bsf_truth_hist_t *h, double q)
{
    uint64_t want;
    uint64_t seen = 0;
    long b;
    if (h->n == 0u) {
        return 0.0;
    }
    want = (uint64_t)ceil(q * (double)h->n);
    if (want < 1u) {
        want = 1u;
    }
    for (b = 0; b <= BSF_TRUTH_NBINS; ++b) {
        seen += h->hist[b];
        if (seen >= want) {
            return b == BSF_TRUTH_NBINS ? h->max : (double)(b + 1) * BSF_TRUTH_BIN;
        }
    }
    return h->max;
}

/* Where a straight wall meets a circle, two circles cross, or a wall ends on
 * another (world frame): real creases of the geometry that the corner list
 * does not hold. */
static size_t creases(const bsf_scene_t *sc, double *xy, size_t cap)
{
    size_t n = 0;
    size_t a;
    size_t b;
    /* T-junctions: a wall's end on the inside of another wall. */
    for (a = 0; a < sc->n_shapes; ++a) {
        const bsf_shape_t *s = &sc->shape[a];
        int end;
        if (s->kind != BSF_SHAPE_SEGMENT) {
            continue;
        }
        for (end = 0; end < 2; ++end) {
            const double ex = end == 0 ? s->x0 : s->x1;
            const double ey = end == 0 ? s->y0 : s->y1;
            for (b = 0; b < sc->n_shapes; ++b) {
                const bsf_shape_t *o = &sc->shape[b];
                double dx, dy, t, px, py;
                if (b == a || o->kind != BSF_SHAPE_SEGMENT) {
                    continue;
                }
                dx = o->x1 - o->x0;
                dy = o->y1 - o->y0;
                t = ((ex - o->x0) * dx + (ey - o->y0) * dy) / (dx * dx + dy * dy);
                px = o->x0 + t * dx - ex;
                py = o->y0 + t * dy - ey;
                if (t > 1e-9 && t < 1.0 - 1e-9 && px * px + py * py < 1e-12 && n < cap) {
                    xy[2u * n] = ex;
                    xy[2u * n + 1u] = ey;
                    ++n;
                }
            }
        }
    }
    for (a = 0; a < sc->n_shapes; ++a) {
        const bsf_shape_t *s = &sc->shape[a];
        if (s->kind != BSF_SHAPE_SEGMENT) {
            continue;
        }
        for (b = 0; b < sc->n_shapes; ++b) {
            const bsf_shape_t *c = &sc->shape[b];
            const double dx = s->x1 - s->x0;
            const double dy = s->y1 - s->y0;
            const double fx = s->x0 - c->x0;
            const double fy = s->y0 - c->y0;
            double qa, qb, qc, disc;
            int k;
            if (c->kind != BSF_SHAPE_CIRCLE) {
                continue;
            }
            qa = dx * dx + dy * dy;
            qb = 2.0 * (fx * dx + fy * dy);
            qc = fx * fx + fy * fy - c->r * c->r;
            disc = qb * qb - 4.0 * qa * qc;
            if (disc < 0.0) {
                continue;
            }
            for (k = -1; k <= 1; k += 2) {
                const double t = (-qb + (double)k * sqrt(disc)) / (2.0 * qa);
                if (t >= 0.0 && t <= 1.0 && n < cap) {
                    xy[2u * n] = s->x0 + t * dx;
                    xy[2u * n + 1u] = s->y0 + t * dy;
                    ++n;
                }
            }
        }
    }
    /* Where two circles cross (a bulge on a round wall). */
    for (a = 0; a < sc->n_shapes; ++a) {
        const bsf_shape_t *s = &sc->shape[a];
        if (s->kind != BSF_SHAPE_CIRCLE) {
            continue;
        }
        for (b = a + 1u; b < sc->n_shapes; ++b) {
            const bsf_shape_t *c = &sc->shape[b];
            const double dx = c->x0 - s->x0;
            const double dy = c->y0 - s->y0;
            const double d = sqrt(dx * dx + dy * dy);
            double along, h2;
            int k;
            if (c->kind != BSF_SHAPE_CIRCLE || !(d > 0.0)) {
                continue;
            }
            along = (s->r * s->r - c->r * c->r + d * d) / (2.0 * d);
            h2 = s->r * s->r - along * along;
            if (h2 < 0.0) {
                continue;
            }
            for (k = -1; k <= 1; k += 2) {
                if (n < cap) {
                    const double h = (double)k * sqrt(h2);
                    xy[2u * n] = s->x0 + (along * dx - h * dy) / d;
                    xy[2u * n + 1u] = s->y0 + (along * dy + h * dx) / d;
                    ++n;
                }
            }
        }
    }
    return n;
}

/* The beam of the return on shape `wall` nearest corner c (lidar->n_beams
 * when the wall has none); *dmin receives its distance. */
static size_t nearest_wall_return(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                                  const float *ranges, const int16_t *hit_shape, int wall,
                                  double *dmin)
{
    size_t start = lidar->n_beams;
    size_t i;
    *dmin = 1e300;
    for (i = 0; i < lidar->n_beams; ++i) {
        if (hit_shape[i] == wall) {
            const double a = lidar->angle_min + (double)i * lidar->angle_increment;
            const double d =
                hypot((double)ranges[i] * cos(a) - c->x, (double)ranges[i] * sin(a) - c->y);
            if (d < *dmin) {
                *dmin = d;
                start = i;
            }
        }
    }
    return start;
}

/* The scan's beams close a full circle. */
static int full_ring(const bsf_lidar_t *lidar)
{
    return fabs(fabs(lidar->angle_increment) * (double)lidar->n_beams - 6.283185307179586) <=
           fabs(lidar->angle_increment);
}

/* *b one beam further in direction dir (-1 or +1), through the seam of a
 * ring; 0 at the end of a scan that is not one. */
static int step_beam(size_t *b, int dir, size_t n, int ring)
{
    if (dir < 0) {
        if (*b == 0u && !ring) {
            return 0;
        }
        *b = *b == 0u ? n - 1u : *b - 1u;
    } else {
        if (*b + 1u == n && !ring) {
            return 0;
        }
        *b = *b + 1u == n ? 0u : *b + 1u;
    }
    return 1;
}

/* Each wall of corner c seen over some length (see bsf_truth.h). */
static int walls_seen(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar, const float *ranges,
                      const int16_t *hit_shape)
{
    int side;
    for (side = 0; side < 2; ++side) {
        const int wall = side == 0 ? c->shape_a : c->shape_b;
        int hits = 0;
        double dmin = 1e300;
        double dmax = 0.0;
        double d_sorted[64];
        size_t i;
        for (i = 0; i < lidar->n_beams; ++i) {
            double a;
            double px;
            double py;
            double d;
            if (hit_shape[i] != wall) {
                continue;
            }
            a = lidar->angle_min + (double)i * lidar->angle_increment;
            px = (double)ranges[i] * cos(a);
            py = (double)ranges[i] * sin(a);
            d = hypot(px - c->x, py - c->y);
            if (d <= BSF_TRUTH_WALL_LEN) {
                if (hits < 64) {
                    d_sorted[hits] = d;
                }
                ++hits;
                dmin = d < dmin ? d : dmin;
                dmax = d > dmax ? d : dmax;
            }
        }
        if (hits < BSF_TRUTH_MIN_HITS || dmax - dmin < BSF_TRUTH_MIN_SPREAD) {
            return 0;
        }
        {
            /* The first BSF_TRUTH_MIN_HITS hits from the vertex must sample
             * the wall as a surface: gaps of at most BSF_TRUTH_MAX_GAP. */
            const int m = hits < 64 ? hits : 64;
            int u;
            int v;
            double prev = 0.0;
            for (u = 1; u < m; ++u) {
                const double key = d_sorted[u];
                for (v = u - 1; v >= 0 && d_sorted[v] > key; --v) {
                    d_sorted[v + 1] = d_sorted[v];
                }
                d_sorted[v + 1] = key;
            }
            for (u = 0; u < BSF_TRUTH_MIN_HITS; ++u) {
                if (d_sorted[u] - prev > BSF_TRUTH_MAX_GAP) {
                    return 0;
                }
                prev = d_sorted[u];
            }
        }
    }
    return 1;
}

/* Sparse-wall rule (see bsf_truth.h): from the hit on each wall nearest the
 * vertex, the run of consecutive beams on that wall (through the seam of a
 * full-circle scan) holds at least BSF_TRUTH_MIN_HITS returns and reaches at
 * least BSF_TRUTH_SPARSE_REACH from the vertex. */
static int walls_seen_sparse(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                             const float *ranges, const int16_t *hit_shape)
{
    const size_t n = lidar->n_beams;
    const int ring = full_ring(lidar);
    int side;
    for (side = 0; side < 2; ++side) {
        const int wall = side == 0 ? c->shape_a : c->shape_b;
        double reach;
        const size_t start = nearest_wall_return(c, lidar, ranges, hit_shape, wall, &reach);
        int dir;
        int run = 1;
        if (start == n) {
            return 0;
        }
        for (dir = -1; dir <= 1; dir += 2) {
            size_t b = start;
            size_t steps;
            for (steps = 1; steps < n && step_beam(&b, dir, n, ring); ++steps) {
                double a;
                double d;
                if (hit_shape[b] != wall || b == start) {
                    break;
                }
                a = lidar->angle_min + (double)b * lidar->angle_increment;
                d = hypot((double)ranges[b] * cos(a) - c->x, (double)ranges[b] * sin(a) - c->y);
                reach = d > reach ? d : reach;
                ++run;
            }
        }
        if (run < BSF_TRUTH_MIN_HITS || reach < BSF_TRUTH_SPARSE_REACH) {
            return 0;
        }
    }
    return 1;
}

/* For a missed corner (--verbose): each wall's returns from the one nearest
 * the vertex outwards (up to 7): beam, range, the feature holding it (999:
 * none), and the step to the next return with the sine of its angle to
 * that return's ray (below 0.17 the wall is seen more than 80 deg off its
 * normal). */
static void print_corner_walls(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                               const float *ranges, const int16_t *hit_shape,
                               const bsf_result_t *res)
{
    const size_t n = lidar->n_beams;
    int side;
    for (side = 0; side < 2; ++side) {
        const int wall = side == 0 ? c->shape_a : c->shape_b;
        double dmin;
        const size_t start = nearest_wall_return(c, lidar, ranges, hit_shape, wall, &dmin);
        size_t i, b;
        int dir, best_dir = 0;
        if (start == n) {
            printf("   wall %d: no hits\n", wall);
            continue;
        }
        for (dir = -1; dir <= 1; dir += 2) {
            size_t bb = (start + n + (size_t)dir) % n;
            if (hit_shape[bb] == wall) {
                best_dir = dir;
            }
        }
        printf("   wall %d, nearest return %.3f m from the vertex", wall, dmin);
        b = start;
        for (i = 0; i < 7 && hit_shape[b] == wall; ++i) {
            const double a = lidar->angle_min + (double)b * lidar->angle_increment;
            const double px = (double)ranges[b] * cos(a), py = (double)ranges[b] * sin(a);
            const size_t nb = (b + n + (size_t)best_dir) % n;
            const double a2 = lidar->angle_min + (double)nb * lidar->angle_increment;
            const double qx = (double)ranges[nb] * cos(a2), qy = (double)ranges[nb] * sin(a2);
            const double st = hypot(qx - px, qy - py);
            const double sn = fabs((qx - px) * qy - (qy - py) * qx) / (st * hypot(qx, qy));
            size_t f, feat = 999;
            for (f = 0; f < res->n_features; ++f) {
                const bsf_feature_t *ft = &res->features[f];
                const int in = ft->first_beam <= ft->last_beam
                                   ? (b >= ft->first_beam && b <= ft->last_beam)
                                   : (b >= ft->first_beam || b <= ft->last_beam);
                if (in) {
                    feat = f;
                }
            }
            printf(" | b%lu r%.2f f%lu", (unsigned long)b, (double)ranges[b], (unsigned long)feat);
            if (best_dir != 0 && hit_shape[nb] == wall) {
                printf(" st%.2f sin%.2f", st, sn);
            }
            if (best_dir == 0) {
                break;
            }
            b = nb;
        }
        printf("\n");
    }
}

/* A convex corner: the sensor (origin of the sensor frame) stands outside
 * the wedge between the corner's two walls. */
static int corner_convex(const bsf_scene_t *scene, const bsf_scene_corner_t *c,
                         const bsf_lidar_t *lidar)
{
    double dir[2][2];
    double sx;
    double sy;
    double cab;
    double cas;
    double csb;
    int side;
    for (side = 0; side < 2; ++side) {
        const bsf_shape_t *w = &scene->shape[side == 0 ? c->shape_a : c->shape_b];
        const double d0 = hypot(w->x0 - c->wx, w->y0 - c->wy);
        const double d1 = hypot(w->x1 - c->wx, w->y1 - c->wy);
        dir[side][0] = d0 > d1 ? w->x0 - c->wx : w->x1 - c->wx;
        dir[side][1] = d0 > d1 ? w->y0 - c->wy : w->y1 - c->wy;
    }
    sx = lidar->pose.x - c->wx;
    sy = lidar->pose.y - c->wy;
    cab = dir[0][0] * dir[1][1] - dir[0][1] * dir[1][0];
    cas = dir[0][0] * sy - dir[0][1] * sx;
    csb = sx * dir[1][1] - sy * dir[1][0];
    return !(cas * cab > 0.0 && csb * cab > 0.0);
}

int bsf_truth_corner_seen(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                          const float *ranges, const int16_t *hit_shape)
{
    return c->visible && c->range <= BSF_TRUTH_RANGE_MAX && walls_seen(c, lidar, ranges, hit_shape);
}

int bsf_truth_corner_seen_sparse(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                                 const float *ranges, const int16_t *hit_shape)
{
    return c->visible && c->range <= BSF_TRUTH_RANGE_MAX &&
           walls_seen_sparse(c, lidar, ranges, hit_shape);
}

size_t bsf_truth_returns_on_shapes(int16_t *on_shape, const int16_t *hit_shape, const float *clean,
                                   const float *delivered, const float *unmixed, size_t n,
                                   double tol)
{
    size_t relabelled = 0;
    size_t i;
    for (i = 0; i < n; ++i) {
        /* A blend lies between two surfaces, on neither, unless it happens
         * to land within the noise of its own wall. */
        const int blend = delivered[i] != unmixed[i] &&
                          fabs((double)delivered[i] - (double)clean[i]) > tol && hit_shape[i] >= 0;
        on_shape[i] = blend ? (int16_t)-1 : hit_shape[i];
        relabelled += (size_t)blend;
    }
    return relabelled;
}

int bsf_truth_add(bsf_truth_acc_t *acc, const bsf_scene_t *scene, const bsf_lidar_t *lidar,
                  const float *ranges, const int16_t *hit_shape, const bsf_result_t *res,
                  size_t bytes, double time_ns)
{
    static bsf_scene_corner_t corners[TRUTH_MAX_CORNERS];
    double crease_xy[2 * TRUTH_MAX_CREASES];
    size_t n_corners = 0;
    size_t n_creases;
    size_t f;
    size_t k;
    size_t j;

    if (bsf_scene_corners(scene, lidar, corners, TRUTH_MAX_CORNERS, &n_corners) != BSF_OK) {
        return -1;
    }
    n_creases = creases(scene, crease_xy, TRUTH_MAX_CREASES);
    for (k = 0; k < n_creases; ++k) {
        double sx;
        double sy;
        bsf_scene_world_to_sensor(&lidar->pose, crease_xy[2u * k], crease_xy[2u * k + 1u], &sx,
                                  &sy);
        crease_xy[2u * k] = sx;
        crease_xy[2u * k + 1u] = sy;
    }

    /* Recall and position error. */
    for (k = 0; k < n_corners; ++k) {
        const bsf_scene_corner_t *c = &corners[k];
        int band;
        int dense;
        double best = 1e300;
        if (!c->visible || c->range > BSF_TRUTH_RANGE_MAX) {
            continue;
        }
        dense = walls_seen(c, lidar, ranges, hit_shape);
        if (!dense && !walls_seen_sparse(c, lidar, ranges, hit_shape)) {
            continue;
        }
        band = c->range < 3.0 ? 0 : (c->range < 6.0 ? 1 : 2);
        for (j = 0; j < res->n_ctrl; ++j) {
            if (res->ctrl_is_vertex[j]) {
                const double d =
                    hypot((double)res->ctrl[j].x - c->x, (double)res->ctrl[j].y - c->y);
                best = d < best ? d : best;
            }
        }
        if (walls_seen_sparse(c, lidar, ranges, hit_shape)) {
            const double deg = c->angle * 57.29577951308232;
            const double off_seam = fabs(c->bearing - lidar->angle_min);
            const int ring = fabs(fabs(lidar->angle_increment) * (double)lidar->n_beams -
                                  6.283185307179586) <= fabs(lidar->angle_increment);
            const int hit = best <= BSF_TRUTH_MATCH;
            acc->visible_sparse[band]++;
            if (hit) {
                acc->found_sparse[band]++;
                hist_add(&acc->vertex_err_sparse, best);
            } else if (bsf_truth_verbose && !dense) {
                printf("missed sparse-wall corner at world (%.3f, %.3f), range %.2f m, beam %d, "
                       "angle %.0f deg, nearest vertex %.3f m\n",
                       c->wx, c->wy, c->range, c->beam, c->angle * 57.29577951, best);
                print_corner_walls(c, lidar, ranges, hit_shape, res);
            }
            if (deg >= BSF_TRUTH_OBTUSE_MIN && deg <= BSF_TRUTH_OBTUSE_MAX) {
                if (corner_convex(scene, c, lidar)) {
                    acc->obtuse_visible++;
                    acc->obtuse_found += (uint64_t)hit;
                } else {
                    acc->obtuse_concave_visible++;
                    acc->obtuse_concave_found += (uint64_t)hit;
                }
            }
            if (ring) {
                /* beam 0 is the seam; its distance in angle, either way round */
                const double seam = fmin(fmod(off_seam, 6.283185307179586),
                                         6.283185307179586 - fmod(off_seam, 6.283185307179586));
                if (seam * 57.29577951308232 <= BSF_TRUTH_SEAM_DEG) {
                    acc->behind_visible++;
                    acc->behind_found += (uint64_t)hit;
                } else if (seam * 57.29577951308232 >= 180.0 - BSF_TRUTH_SEAM_DEG) {
                    acc->ahead_visible++;
                    acc->ahead_found += (uint64_t)hit;
                }
            }
        }
        if (!dense) {
            continue;
        }
        acc->visible[band]++;
        if (best <= BSF_TRUTH_MATCH) {
            acc->found[band]++;
            hist_add(&acc->vertex_err, best);
        } else if (bsf_truth_verbose) {
            printf("missed corner at world (%.3f, %.3f), range %.2f m, beam %d, angle %.0f deg, "
                   "nearest vertex %.3f m\n",
                   c->wx, c->wy, c->range, c->beam, c->angle * 57.29577951, best);
        }
    }

    /* Precision, and the curves against the true surfaces. */
    for (f = 0; f < res->n_features; ++f) {
        const bsf_feature_t *ft = &res->features[f];
        const bsf_point_t *ctrl = &res->ctrl[ft->ctrl_first];
        const size_t n_samples = (size_t)BSF_TRUTH_SAMPLES_PER_SPAN * (ft->n_ctrl - 2u);
        double worst = 0.0;
        for (j = 0; j < ft->n_ctrl; ++j) {
            const size_t g = ft->ctrl_first + j;
            double best = 1e300;
            int crease = 0;
            if (!res->ctrl_is_vertex[g] || (j > 0u && res->ctrl_is_vertex[g - 1u])) {
                continue; /* not a vertex, or its second copy */
            }
            for (k = 0; k < n_corners; ++k) {
                const double d = hypot((double)res->ctrl[g].x - corners[k].x,
                                       (double)res->ctrl[g].y - corners[k].y);
                best = d < best ? d : best;
            }
            for (k = 0; k < n_creases; ++k) {
                if (hypot((double)res->ctrl[g].x - crease_xy[2u * k],
                          (double)res->ctrl[g].y - crease_xy[2u * k + 1u]) <= BSF_TRUTH_MATCH) {
                    crease = 1;
                }
            }
            if (best > BSF_TRUTH_MATCH && crease) {
                acc->vertices_creases++;
                continue;
            }
            acc->vertices++;
            if (best <= BSF_TRUTH_MATCH) {
                acc->vertices_correct++;
            } else if (bsf_truth_verbose) {
                double wx;
                double wy;
                int shape = -1;
                double d;
                bsf_scene_sensor_to_world(&lidar->pose, (double)res->ctrl[g].x,
                                          (double)res->ctrl[g].y, &wx, &wy);
                d = bsf_scene_distance_to_surface(scene, wx, wy, &shape);
                printf("false vertex at world (%.3f, %.3f), range %.2f m, %.3f m from shape %d, "
                       "%.3f m from the nearest corner\n",
                       wx, wy, hypot((double)res->ctrl[g].x, (double)res->ctrl[g].y), d, shape,
                       best);
            }
            ++j; /* skip the second copy */
        }
        for (j = 0; j <= n_samples; ++j) {
            bsf_point_t p;
            double wx;
            double wy;
            double d;
            if (bsf_bspline_eval(ctrl, ft->n_ctrl, (float)((double)j / (double)n_samples), &p, NULL,
                                 NULL) != BSF_OK) {
                continue;
            }
            bsf_scene_sensor_to_world(&lidar->pose, (double)p.x, (double)p.y, &wx, &wy);
            d = bsf_scene_distance_to_surface(scene, wx, wy, NULL);
            hist_add(&acc->curve, d);
            worst = d > worst ? d : worst;
            if (bsf_truth_verbose && d > 0.03) {
                const size_t span = j / BSF_TRUTH_SAMPLES_PER_SPAN;
                const size_t ns = ft->n_ctrl - 2u;
                const int end = span == 0u || span + 1u >= ns;
                int near_v = 0;
                size_t q;
                for (q = span; q < span + 3u && q < ft->n_ctrl; ++q) {
                    near_v |= res->ctrl_is_vertex[ft->ctrl_first + q];
                }
                printf("far sample %.3f m at t %.3f: %s, feature %u ctrl, %u points, beams %u-%u\n",
                       d, (double)j / (double)n_samples,
                       end ? "end span" : (near_v ? "vertex span" : "inner span"), ft->n_ctrl,
                       ft->n_points, ft->first_beam, ft->last_beam);
            }
        }
        acc->features++;
        if (worst > BSF_TRUTH_STRAY && bsf_truth_verbose) {
            size_t nv = 0;
            double wx, wy, wx1, wy1;
            for (j = 0; j < ft->n_ctrl; ++j) {
                nv += res->ctrl_is_vertex[ft->ctrl_first + j];
            }
            bsf_scene_sensor_to_world(&lidar->pose, (double)ctrl[0].x, (double)ctrl[0].y, &wx, &wy);
            bsf_scene_sensor_to_world(&lidar->pose, (double)ctrl[ft->n_ctrl - 1u].x,
                                      (double)ctrl[ft->n_ctrl - 1u].y, &wx1, &wy1);
            printf("stray feature: max %.3f m, beams %u-%u, %u points, %u ctrl (%lu vertex slots), "
                   "E %.4f, world (%.2f,%.2f)-(%.2f,%.2f)\n",
                   worst, ft->first_beam, ft->last_beam, ft->n_points, ft->n_ctrl,
                   (unsigned long)nv, (double)ft->e_curve, wx, wy, wx1, wy1);
        }
        if (worst > BSF_TRUTH_STRAY) {
            acc->features_stray++;
        }
    }
    acc->scans++;
    acc->n_valid += res->stats.n_valid;
    acc->n_in_features += res->stats.n_in_features;
    acc->n_ctrl += res->stats.n_ctrl;
    acc->bytes += bytes;
    acc->time_ns += time_ns;
    return 0;
}

static double ratio(uint64_t a, uint64_t b)
{
    return b > 0u ? (double)a / (double)b : 0.0;
}

void bsf_truth_summary(const bsf_truth_acc_t *acc, bsf_truth_summary_t *s)
{
    uint64_t vis = 0;
    uint64_t found = 0;
    int b;
    memset(s, 0, sizeof *s);
    for (b = 0; b < BSF_TRUTH_BANDS; ++b) {
        vis += acc->visible[b];
        found += acc->found[b];
        s->recall_band[b] = ratio(acc->found[b], acc->visible[b]);
    }
    s->visible = vis;
    s->recall = ratio(found, vis);
    vis = 0;
    found = 0;
    for (b = 0; b < BSF_TRUTH_BANDS; ++b) {
        vis += acc->visible_sparse[b];
        found += acc->found_sparse[b];
        s->recall_sparse_band[b] = ratio(acc->found_sparse[b], acc->visible_sparse[b]);
    }
    s->visible_sparse = vis;
    s->recall_sparse = ratio(found, vis);
    s->verr_sparse_median = bsf_truth_quantile(&acc->vertex_err_sparse, 0.5);
    s->verr_sparse_p90 = bsf_truth_quantile(&acc->vertex_err_sparse, 0.9);
    s->oracle_found_median = bsf_truth_quantile(&acc->oracle_err_found, 0.5);
    s->oracle_found_p90 = bsf_truth_quantile(&acc->oracle_err_found, 0.9);
    s->oracle_all_median = bsf_truth_quantile(&acc->oracle_err_all, 0.5);
    s->oracle_all_p90 = bsf_truth_quantile(&acc->oracle_err_all, 0.9);
    s->obtuse_visible = acc->obtuse_visible;
    s->recall_obtuse = ratio(acc->obtuse_found, acc->obtuse_visible);
    s->obtuse_concave_visible = acc->obtuse_concave_visible;
    s->recall_obtuse_concave = ratio(acc->obtuse_concave_found, acc->obtuse_concave_visible);
    s->behind_visible = acc->behind_visible;
    s->recall_behind = ratio(acc->behind_found, acc->behind_visible);
    s->ahead_visible = acc->ahead_visible;
    s->recall_ahead = ratio(acc->ahead_found, acc->ahead_visible);
    s->precision = acc->vertices > 0u ? ratio(acc->vertices_correct, acc->vertices) : 1.0;
    s->verr_median = bsf_truth_quantile(&acc->vertex_err, 0.5);
    s->verr_p90 = bsf_truth_quantile(&acc->vertex_err, 0.9);
    s->verr_max = acc->vertex_err.max;
    s->curve_rms = acc->curve.n > 0u ? sqrt(acc->curve.sum_sq / (double)acc->curve.n) : 0.0;
    s->curve_p99 = bsf_truth_quantile(&acc->curve, 0.99);
    s->curve_max = acc->curve.max;
    s->stray_share = ratio(acc->features_stray, acc->features);
    s->gamma = ratio(acc->n_in_features, acc->n_valid);
    s->eta = ratio(acc->n_ctrl, acc->n_in_features);
    s->bytes_per_scan = acc->scans > 0u ? (double)acc->bytes / (double)acc->scans : 0.0;
    s->us_per_scan = acc->scans > 0u ? acc->time_ns / 1000.0 / (double)acc->scans : 0.0;
}

double bsf_truth_oracle_reach = 0.0;
FILE *bsf_truth_oracle_log = NULL;
const char *bsf_truth_oracle_key = "";
const bsf_keypoint_t *bsf_truth_oracle_keypoints = NULL;
size_t bsf_truth_oracle_n_keypoints = 0;

/* Sums of one side's points for its total-least-squares line. */
typedef struct {
    double n, sx, sy, sxx, sxy, syy;
} oracle_sums_t;

/* The line through the sums' points: unit normal (nx, ny) and offset d,
 * nx x + ny y = d. 0, or -1 with fewer than 2 points. */
static int oracle_line(const oracle_sums_t *s, double *nx, double *ny, double *d)
{
    double mx, my, cxx, cxy, cyy, theta;
    if (s->n < 2.0) {
        return -1;
    }
    mx = s->sx / s->n;
    my = s->sy / s->n;
    cxx = s->sxx / s->n - mx * mx;
    cxy = s->sxy / s->n - mx * my;
    cyy = s->syy / s->n - my * my;
    /* direction of largest spread; the normal is across it */
    theta = 0.5 * atan2(2.0 * cxy, cxx - cyy);
    *nx = -sin(theta);
    *ny = cos(theta);
    *d = *nx * mx + *ny * my;
    return 0;
}

/* Beam b of a wall's run into the oracle's sums. Returns 1 when the beam
 * lies beyond reach (the walk stops: along a straight wall, the beams after
 * it are farther still), else 0. */
static int oracle_take(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar, const float *clean,
                       const float *measured, double reach, size_t b, oracle_sums_t *s, double *len)
{
    const double a = lidar->angle_min + (double)b * lidar->angle_increment;
    const double d = hypot((double)clean[b] * cos(a) - c->x, (double)clean[b] * sin(a) - c->y);
    double px, py;
    if (reach > 0.0 && d > reach) {
        return 1;
    }
    px = (double)measured[b] * cos(a);
    py = (double)measured[b] * sin(a);
    s->n += 1.0;
    s->sx += px;
    s->sy += py;
    s->sxx += px * px;
    s->sxy += px * py;
    s->syy += py * py;
    *len = d > *len ? d : *len;
    return 0;
}

int bsf_truth_oracle_vertex(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                            const float *clean, const int16_t *hit_shape, const float *measured,
                            double reach, double *x, double *y, int n_side[2], double len_side[2])
{
    const size_t n = lidar->n_beams;
    const int ring = full_ring(lidar);
    double nx[2], ny[2], dd[2], det;
    int side;
    for (side = 0; side < 2; ++side) {
        const int wall = side == 0 ? c->shape_a : c->shape_b;
        oracle_sums_t s = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        double dmin;
        double len = 0.0;
        const size_t start = nearest_wall_return(c, lidar, clean, hit_shape, wall, &dmin);
        int dir;
        if (start == n) {
            return -1;
        }
        if (oracle_take(c, lidar, clean, measured, reach, start, &s, &len) == 0) {
            /* the run either way from the start beam, as the sparse-wall rule walks it */
            for (dir = -1; dir <= 1; dir += 2) {
                size_t b = start;
                size_t steps;
                for (steps = 1; steps < n && step_beam(&b, dir, n, ring); ++steps) {
                    if (hit_shape[b] != wall || b == start ||
                        oracle_take(c, lidar, clean, measured, reach, b, &s, &len) != 0) {
                        break;
                    }
                }
            }
        }
        if (n_side != NULL) {
            n_side[side] = (int)s.n;
        }
        if (len_side != NULL) {
            len_side[side] = len;
        }
        if (oracle_line(&s, &nx[side], &ny[side], &dd[side]) != 0) {
            return -1;
        }
    }
    det = nx[0] * ny[1] - ny[0] * nx[1];
    if (!(fabs(det) > 1e-12)) {
        return -1;
    }
    *x = (dd[0] * ny[1] - ny[0] * dd[1]) / det;
    *y = (nx[0] * dd[1] - dd[0] * nx[1]) / det;
    return 0;
}

int bsf_truth_add_oracle(bsf_truth_acc_t *acc, const bsf_scene_t *scene, const bsf_lidar_t *lidar,
                         const float *clean, const int16_t *hit_shape, const float *measured,
                         const bsf_result_t *res)
{
    static bsf_scene_corner_t corners[TRUTH_MAX_CORNERS];
    size_t n_corners = 0;
    size_t k;
    size_t j;
    if (bsf_scene_corners(scene, lidar, corners, TRUTH_MAX_CORNERS, &n_corners) != BSF_OK) {
        return -1;
    }
    for (k = 0; k < n_corners; ++k) {
        const bsf_scene_corner_t *c = &corners[k];
        double best = 1e300;
        double bx = 0.0;
        double by = 0.0;
        double ox;
        double oy;
        double err;
        int n_side[2] = {0, 0};
        double len_side[2] = {0.0, 0.0};
        if (!c->visible || c->range > BSF_TRUTH_RANGE_MAX ||
            !walls_seen_sparse(c, lidar, clean, hit_shape)) {
            continue;
        }
        for (j = 0; j < res->n_ctrl; ++j) {
            if (res->ctrl_is_vertex[j]) {
                const double d =
                    hypot((double)res->ctrl[j].x - c->x, (double)res->ctrl[j].y - c->y);
                if (d < best) {
                    best = d;
                    bx = (double)res->ctrl[j].x;
                    by = (double)res->ctrl[j].y;
                }
            }
        }
        if (bsf_truth_oracle_vertex(c, lidar, clean, hit_shape, measured, bsf_truth_oracle_reach,
                                    &ox, &oy, n_side, len_side) != 0) {
            acc->oracle_undefined++;
            continue;
        }
        err = hypot(ox - c->x, oy - c->y);
        hist_add(&acc->oracle_err_all, err);
        if (best <= BSF_TRUTH_MATCH) {
            hist_add(&acc->oracle_err_found, err);
        }
        if (bsf_truth_oracle_log != NULL) {
            double kp_err = bsf_truth_oracle_keypoints != NULL ? 1e300 : -1.0;
            for (j = 0; bsf_truth_oracle_keypoints != NULL && j < bsf_truth_oracle_n_keypoints;
                 ++j) {
                const double d = hypot((double)bsf_truth_oracle_keypoints[j].point.x - c->x,
                                       (double)bsf_truth_oracle_keypoints[j].point.y - c->y);
                kp_err = d < kp_err ? d : kp_err;
            }
            fprintf(bsf_truth_oracle_log,
                    "%s %d %.5f %.5f %.5f %.1f %d %.3f %d %d %.3f %.3f %d %.5f %lu %.3f %.3f\n",
                    bsf_truth_oracle_key, best <= BSF_TRUTH_MATCH,
                    best <= BSF_TRUTH_MATCH ? best : -1.0, err,
                    best <= BSF_TRUTH_MATCH ? hypot(bx - ox, by - oy) : -1.0,
                    c->angle * 57.29577951308232, corner_convex(scene, c, lidar), c->range,
                    n_side[0], n_side[1], len_side[0], len_side[1],
                    walls_seen(c, lidar, clean, hit_shape), kp_err,
                    (unsigned long)(acc->scans > 0u ? acc->scans - 1u : 0u), c->wx, c->wy);
        }
    }
    return 0;
}
