/* SPDX-License-Identifier: MIT */
/*
 * bsf_grazing.h - internal: whether two neighbouring beams lie on one wall
 * seen at grazing incidence, where their returns are farther apart than any
 * radius test on the distance alone allows.
 *
 * Why: a wall seen nearly edge-on gets one return every half metre or more
 * at 7 m, farther apart than SVED's radius, yet those returns lie on a line
 * to a few millimetres (range noise moves a point along the wall, hardly
 * off it). A depth jump gives no such line: a mixed pixel halfway across
 * one lies on the chord of its two neighbours, but the surfaces either
 * side do not go on along it. So a wide step is taken as a continuing
 * surface when four consecutive returns through it are collinear with
 * similar steps; or, where a corner turns onto such a wall, when four
 * returns beyond the step are and the return before it lies just behind
 * the first of them on their line (a corner lies within one beam step of
 * the wall's line).
 */
#ifndef BSF_GRAZING_H
#define BSF_GRAZING_H

#include <stddef.h>
#include <stdint.h>

#include "bsf/bsf_config.h"
#include "bsf/bsf_scan.h"

/* Largest distance of the middle return from the chord of its neighbours,
 * metres: several times what 1-3 cm of range noise moves a grazing return
 * off its wall, far below the offset of an edge across a depth jump. */
#define BSF_GRAZING_LINE_TOL 0.03f
/* Largest ratio of two successive steps along one line (on a plane the step
 * grows with 1 / cos^2 of the incidence: about 1.4 per beam at 85 deg). */
#define BSF_GRAZING_STEP_RATIO 2.0f
/* Smallest sine of the angle between a wide step and the ray (incidence at
 * most 80 deg): nearer edge-on, a door or recess in the wall hides between
 * two returns that still line up, and the feature would close it. */
#define BSF_GRAZING_MIN_SIN 0.17f

/* Points pt[i0], pt[i1], pt[i2] in that order on a line: the middle one
 * between the two, within BSF_GRAZING_LINE_TOL of their chord, the two steps
 * within the ratio. (Indices, not points: every caller's points are in one
 * array, and three indices are fewer instructions to pass than six floats.) */
int bsf_grazing_triple(const bsf_point_t *pt, size_t i0, size_t i1, size_t i2);

/* The last valid beam, the one before beam 0 on the ring of a full-circle
 * scan (where SVED's and LC's passes look for their start), or pts->count
 * when no beam is valid. */
static inline size_t bsf_last_valid_beam(const bsf_points_t *pts)
{
    size_t i;
    for (i = pts->count; i > 0u; --i) {
        if (pts->valid[i - 1u]) {
            return i - 1u;
        }
    }
    return pts->count;
}

#if !BSF_CONFIG_COMPACT
/* Speed only, for SVED's and LC's ring_start: from beam i on, the valid
 * beams before beam end within sqrt(r2) of the valid beam before them
 * (*prev the first) join in a loop, the last point in registers. Returns
 * the first beam that does not join (or end), with *prev the last that
 * did: each caller's own test then judges that beam as before. */
static inline size_t bsf_join_near_beams(const bsf_points_t *pts, size_t i, size_t end, float r2,
                                         size_t *prev)
{
    const uint8_t *valid = pts->valid;
    const bsf_point_t *pt = pts->pt;
    bsf_point_t at = pt[*prev];
    while (i < end) {
        if (valid[i]) {
            const float dx = pt[i].x - at.x;
            const float dy = pt[i].y - at.y;
            if (!(dx * dx + dy * dy <= r2)) {
                break;
            }
            at = pt[i];
            *prev = i;
        }
        ++i;
    }
    return i;
}
#endif

#if BSF_CONFIG_SIMD && defined(__SSE2__)
#include <emmintrin.h>
#include <string.h>

/* Are beams b..b + 3 all valid, each within sqrt(r2) of the beam before it
 * (b - 1 .. b + 2)? Speed only: LC's run walk and SVED's one open segment
 * take four such beams at once, with the same squared distances as their
 * beam-by-beam tests. Needs 1 <= b and b + 4 <= pts->count. */
static inline int bsf_four_steps_within(const bsf_points_t *pts, size_t b, float r2)
{
    uint32_t valid4;
    memcpy(&valid4, &pts->valid[b], sizeof valid4);
    /* a zero byte: an invalid beam */
    if (((valid4 - 0x01010101u) & ~valid4 & 0x80808080u) != 0u) {
        return 0;
    }
    {
        const float *q = &pts->pt[b].x;
        /* pairs (b - 1, b), (b, b + 1) and (b + 1, b + 2), (b + 2, b + 3) */
        const __m128 d1 = _mm_sub_ps(_mm_loadu_ps(q - 2), _mm_loadu_ps(q));
        const __m128 d2 = _mm_sub_ps(_mm_loadu_ps(q + 2), _mm_loadu_ps(q + 4));
        const __m128 s1 = _mm_mul_ps(d1, d1);
        const __m128 s2 = _mm_mul_ps(d2, d2);
        const __m128 t1 = _mm_add_ps(s1, _mm_shuffle_ps(s1, s1, _MM_SHUFFLE(2, 3, 0, 1)));
        const __m128 t2 = _mm_add_ps(s2, _mm_shuffle_ps(s2, s2, _MM_SHUFFLE(2, 3, 0, 1)));
        return _mm_movemask_ps(_mm_cmple_ps(_mm_shuffle_ps(t1, t2, _MM_SHUFFLE(2, 0, 2, 0)),
                                            _mm_set1_ps(r2))) == 15;
    }
}
#endif

/* Largest step LC's runs join this way, metres: SVED's default radius cap,
 * so runs and segments go on across the same steps. */
#define BSF_GRAZING_LC_CAP 1.0f

/* Beams a and a + 1 (both valid, no wrap) continue one grazing wall, their
 * step at most cap metres (see the top of this file). One collinear triple
 * is not enough: a mixed pixel halfway across a depth jump lies on the
 * chord of its neighbours too, but the surfaces either side do not go on
 * along that line, so four consecutive returns must be collinear. Nearer
 * edge-on than BSF_GRAZING_MIN_SIN, only with at_corners and only the
 * first four returns of a wall that starts at a corner (or the last four
 * of one that ends at one), the step onto that corner included: that
 * corner is visible (three returns on a line fix the wall), and four
 * returns from it leave no room for a long wall to close a door.
 * memo (NULL: none) keeps each step's verdict once computed, 2 bits per
 * step a (0: not asked yet, 1: no, 2: yes), BSF_GRAZING_MEMO_BYTES(count)
 * bytes zeroed by the caller, who keeps pts (points and valid flags), cap
 * and at_corners the same while it is in use. Why: LC and SVED ask about
 * many of the same wide steps, and on a step seen edge-on the corner runs
 * cost hundreds of instructions. The compact build ignores memo (its code
 * would not fit the firmware's budget). */
int bsf_grazing_join(const bsf_points_t *pts, size_t a, float cap, int at_corners, uint8_t *memo);

/* Bytes of bsf_grazing_join's memo for n beams. */
#define BSF_GRAZING_MEMO_BYTES(n) (((n) + 3u) / 4u)

/* Forget the memo's verdicts that depend on beam m (those of the steps
 * whose tests read it: m - 6 .. m + 5), as when beam m's valid flag
 * changes; count is pts->count. */
void bsf_grazing_memo_forget(uint8_t *memo, size_t m, size_t count);

#endif
