/* The emitters' light tree (emitter_tree.c) against its invariants, on
 * random triangles seen from random points:
 * - a pick's probabilities over all triangles and the share of picks
 *   that end in a branch nothing of which can light the point sum to one;
 * - the bounds are conservative: a triangle that sends light to the point
 *   (some of it in front of the point's hemisphere, the point in front of
 *   it) has a probability above zero, else sampling would be biased;
 * - the picks are what the probabilities say: over a fine grid of the
 *   uniform number, each triangle's share of picks is its probability,
 *   and the probability a pick returns is the triangle's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bake/bake_internal.h"
#include "helpers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define TRIANGLES 200
#define POINTS 60
#define GRID 200000

static uint64_t state_bits = 0x9E3779B97F4A7C15ull;

static double uniform(void)
{
    state_bits = state_bits * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(state_bits >> 11) * (1.0 / 9007199254740992.0);
}

static lx_vec3 unit_vector(void)
{
    double z = 2.0 * uniform() - 1.0, phi = 6.283185307179586 * uniform();
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    return lx_v3((float)(r * cos(phi)), (float)(r * sin(phi)), (float)z);
}

typedef struct triangle {
    lx_vec3 v[3], n;
} triangle;

/* Small triangles scattered in a 4 m cube, facing every way; 1 in 4
 * clustered around a string along x (many small emitters together). */
static void make_triangles(triangle *tri, lx_emitter_bounds *bounds)
{
    for (int i = 0; i < TRIANGLES; i++) {
        lx_vec3 c = i % 4 ? lx_v3((float)(4.0 * uniform() - 2.0), (float)(4.0 * uniform() - 2.0),
                                  (float)(4.0 * uniform() - 2.0))
                          : lx_v3((float)(-2.0 + 0.08 * i / 4), 1.0f, 0.0f);
        lx_vec3 a = unit_vector(), b = lx_normalize(lx_cross(a, unit_vector()));
        double size = 0.02 + 0.2 * uniform();
        tri[i].v[0] = lx_madd(c, a, (float)size);
        tri[i].v[1] = lx_madd(c, b, (float)size);
        tri[i].v[2] = lx_madd(c, lx_add(a, b), (float)-size);
        lx_vec3 cr = lx_cross(lx_sub(tri[i].v[1], tri[i].v[0]), lx_sub(tri[i].v[2], tri[i].v[0]));
        tri[i].n = lx_normalize(cr);
        lx_emitter_bounds *bd = &bounds[i];
        bd->lo = bd->hi = tri[i].v[0];
        for (int k = 1; k < 3; k++) {
            bd->lo = lx_v3(fminf(bd->lo.x, tri[i].v[k].x), fminf(bd->lo.y, tri[i].v[k].y),
                           fminf(bd->lo.z, tri[i].v[k].z));
            bd->hi = lx_v3(fmaxf(bd->hi.x, tri[i].v[k].x), fmaxf(bd->hi.y, tri[i].v[k].y),
                           fmaxf(bd->hi.z, tri[i].v[k].z));
        }
        bd->normal = tri[i].n;
        bd->power = 0.5 * lx_length(cr) * (0.1 + 10.0 * uniform());
    }
}

/* Whether triangle t sends light to p (normal n): some point of it in
 * front of p's hemisphere and p in front of it, tested on a fine grid of
 * the triangle's points. */
static bool lights(const triangle *t, lx_vec3 p, lx_vec3 n)
{
    for (int i = 0; i <= 20; i++)
        for (int j = 0; i + j <= 20; j++) {
            float a = (float)i / 20.0f, b = (float)j / 20.0f;
            lx_vec3 x = lx_add(t->v[0], lx_add(lx_scale(lx_sub(t->v[1], t->v[0]), a),
                                               lx_scale(lx_sub(t->v[2], t->v[0]), b)));
            lx_vec3 d = lx_sub(x, p);
            if (lx_dot(n, d) > 1e-4f && -lx_dot(t->n, d) > 1e-4f)
                return true;
        }
    return false;
}

static void picks_follow_the_probabilities(void **state)
{
    (void)state;
    static triangle tri[TRIANGLES];
    static lx_emitter_bounds bounds[TRIANGLES];
    make_triangles(tri, bounds);
    lx_emitter_tree *tree;
    assert_int_equal(lx_emitter_tree_build(bounds, TRIANGLES, &tree), LX_OK);
    double worst_sum = 0.0, worst_share = 0.0, worst_returned = 0.0, lost = 0.0;
    int lit_pairs = 0, unlit_points = 0;
    static uint32_t picks[TRIANGLES];
    for (int k = 0; k < POINTS; k++) {
        lx_vec3 p = lx_v3((float)(5.0 * uniform() - 2.5), (float)(5.0 * uniform() - 2.5),
                          (float)(5.0 * uniform() - 2.5));
        lx_vec3 n = unit_vector();
        double prob[TRIANGLES], sum = 0.0;
        for (int i = 0; i < TRIANGLES; i++) {
            prob[i] = lx_emitter_tree_probability(tree, p, n, (uint32_t)i);
            sum += prob[i];
            if (lights(&tri[i], p, n)) {
                lit_pairs++;
                assert_true(prob[i] > 0.0); /* conservative */
            }
        }
        unlit_points += sum == 0.0; /* nothing lights it (checked above) */
        for (int i = 0; i < TRIANGLES; i++)
            picks[i] = 0;
        uint32_t failed = 0;
        for (int g = 0; g < GRID; g++) {
            uint32_t t;
            double pr;
            float rest;
            if (!lx_emitter_tree_pick(tree, p, n, (float)((g + 0.5) / GRID), &t, &pr, &rest)) {
                failed++;
                continue;
            }
            assert_true(t < TRIANGLES);
            assert_true(rest >= 0.0f && rest < 1.0f);
            worst_returned = fmax(worst_returned, fabs(pr - prob[t]) / prob[t]);
            picks[t]++;
        }
        for (int i = 0; i < TRIANGLES; i++)
            worst_share = fmax(worst_share, fabs((double)picks[i] / GRID - prob[i]));
        /* a branch whose children both have no importance here ends the
         * pick (its share is lost, the estimate unbiased: only triangles
         * that cannot light p are below it) */
        worst_sum = fmax(worst_sum, fabs(sum + (double)failed / GRID - 1.0));
        lost = fmax(lost, (double)failed / GRID);
    }
    printf("light tree, %d triangles, %d points (%d lit by none): %d lit pairs; probabilities "
           "and lost picks sum to 1 within %.3g (lost at most %.3g), picks' shares within %.3g "
           "of the probabilities, returned probability within %.3g\n",
           TRIANGLES, POINTS, unlit_points, lit_pairs, worst_sum, lost, worst_share,
           worst_returned);
    /* the grid's share of lost picks: 2 / GRID a dead branch */
    assert_true(worst_sum < 1e-4);
    assert_true(unlit_points < POINTS / 2);
    /* a share of a grid of GRID numbers is off by at most a cell per
     * interval end: 2 / GRID (float rounding of u adds less) */
    assert_true(worst_share <= 2.0 / GRID + 1e-7);
    /* the pick's product against the search's: 0 in Debug builds; the
     * Release (LTO) build differs by up to 2.8e-5 relative on texels near
     * a node's cut-off angle (cos of an angle near 90 degrees amplifies
     * rounding), cause not pinned down: bound 1e-4 */
    assert_true(worst_returned < 1e-4);
    lx_emitter_tree_destroy(tree);
}

/* One triangle: the root is its leaf; it lights what is in front of it. */
static void one_triangle(void **state)
{
    (void)state;
    lx_emitter_bounds b = {.lo = lx_v3(0, 1, 0), .hi = lx_v3(1, 1, 1),
                           .normal = lx_v3(0, -1, 0), .power = 2.0};
    lx_emitter_tree *tree;
    assert_int_equal(lx_emitter_tree_build(&b, 1, &tree), LX_OK);
    uint32_t t = 7;
    double pr = 0.0;
    float rest = -1.0f;
    assert_true(lx_emitter_tree_pick(tree, lx_v3(0.5f, 0, 0.5f), lx_v3(0, 1, 0), 0.25f, &t, &pr,
                                     &rest));
    assert_int_equal(t, 0);
    assert_true(pr == 1.0 && rest == 0.25f);
    /* above it (behind its front) nothing */
    assert_false(lx_emitter_tree_pick(tree, lx_v3(0.5f, 3, 0.5f), lx_v3(0, 1, 0), 0.25f, &t, &pr,
                                      &rest));
    lx_emitter_tree_destroy(tree);
    assert_int_equal(lx_emitter_tree_build(&b, 0, &tree), LX_OK);
    assert_null(tree);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(picks_follow_the_probabilities),
        cmocka_unit_test(one_triangle),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
