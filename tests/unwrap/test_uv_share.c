/* lx_uv_share_nodes on scenes of boxes whose UVs are placed by the test:
 * each box's six faces fill a 3x2 grid over a rectangle of the UV square,
 * so a node's UV box is that rectangle and its share (box area over the
 * area of the box of all its set's boxes) is known in closed form.
 * - eight boxes side by side in one atlas (4x2 cells): each 1/8, shared;
 * - four in the quadrants: 1/4 each, shared, though each covers 1/4 of
 *   the square and lx_uv_health_node finds nothing wrong;
 * - pieces overlapping one another in the atlas: shared;
 * - every node a full square of its own (packing margins differing):
 *   not shared;
 * - instances of one mesh in a corner of the square: not shared (the
 *   node-level min_coverage is what judges them: sparse);
 * - a full-square node among pieces, sets judged apart, nodes that do not
 *   count (missing set, UVs outside the square, no meshes), the default
 *   set, max_share, and bad arguments. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include "luxel/unwrap.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Set `set` of m (a lx_test_box) laid over the rectangle r = (x0, y0, x1,
 * y1): face f fills cell (f % 3, f / 3) of a 3x2 grid, the grid's outer
 * lines exactly r's. */
static void place(lx_mesh *m, int set, const float r[4])
{
    if (!m->uv[set])
        m->uv[set] = malloc(sizeof(lx_vec2) * m->vertex_count);
    assert_non_null(m->uv[set]);
    const float xs[4] = {r[0], r[0] + (r[2] - r[0]) / 3.0f, r[0] + 2.0f * (r[2] - r[0]) / 3.0f,
                         r[2]};
    const float ys[3] = {r[1], 0.5f * (r[1] + r[3]), r[3]};
    /* lx_test_box's corner order in each face: (-1,-1) (1,-1) (1,1) (-1,1) */
    static const int ci[4] = {0, 1, 1, 0}, cj[4] = {0, 0, 1, 1};
    for (int f = 0; f < 6; f++)
        for (int k = 0; k < 4; k++)
            m->uv[set][4 * f + k] = lx_v2(xs[f % 3 + ci[k]], ys[f / 3 + cj[k]]);
}

/* A box mesh with set 0 over r0 and set 1 over r1 (NULL: no set 1). */
static uint32_t add_box(lx_scene *s, const float r0[4], const float r1[4])
{
    lx_mesh m = lx_test_box("box", lx_v3(0, 0, 0), lx_v3(1, 1, 1), false);
    place(&m, 0, r0);
    if (r1)
        place(&m, 1, r1);
    else {
        free(m.uv[1]);
        m.uv[1] = NULL;
    }
    uint32_t index;
    assert_int_equal(lx_scene_add_mesh(s, &m, &index), LX_OK);
    lx_test_mesh_free(&m);
    return index;
}

static void add_node(lx_scene *s, uint32_t mesh, float x)
{
    char name[32];
    snprintf(name, sizeof name, "node%u", s->node_count);
    lx_mat4 w = lx_mat4_translate(lx_v3(2.0f * x, 0, 0));
    assert_int_equal(lx_scene_add_node(s, name, &w, &mesh, 1, NULL), LX_OK);
}

/* Judges every node on set `set`; out holds scene->node_count entries. */
static void judge(const lx_scene *s, int set, const lx_uv_share_desc *d, lx_uv_share *out)
{
    int sets[64];
    assert_true(s->node_count <= 64);
    for (uint32_t n = 0; n < s->node_count; n++)
        sets[n] = set;
    assert_int_equal(lx_uv_share_nodes(s, sets, d, out), LX_OK);
}

/* The share's closed form: the areas are products of exact binary
 * fractions (quarters, halves), so float and double agree to the last bit;
 * others within a few ulps. */
#define EPS 1e-6

static void eight_side_by_side(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("atlas");
    for (int k = 0; k < 8; k++) {
        float i = (float)(k % 4), j = (float)(k / 4);
        const float r[4] = {i / 4, j / 2, (i + 1) / 4, (j + 1) / 2};
        add_node(s, add_box(s, r, NULL), (float)k);
    }
    lx_uv_share out[8];
    judge(s, 0, NULL, out);
    for (int k = 0; k < 8; k++) {
        float i = (float)(k % 4), j = (float)(k / 4);
        assert_true(out[k].counted);
        assert_int_equal(out[k].uv_set, 0);
        assert_float_equal(out[k].min.x, i / 4, 0);
        assert_float_equal(out[k].min.y, j / 2, 0);
        assert_float_equal(out[k].max.x, (i + 1) / 4, 0);
        assert_float_equal(out[k].max.y, (j + 1) / 2, 0);
        assert_float_equal(out[k].span_min.x, 0, 0);
        assert_float_equal(out[k].span_min.y, 0, 0);
        assert_float_equal(out[k].span_max.x, 1, 0);
        assert_float_equal(out[k].span_max.y, 1, 0);
        assert_int_equal(out[k].users, 8);
        assert_int_equal(out[k].boxes, 8);
        /* (1/4 x 1/2) / 1 */
        assert_float_equal(out[k].share, 0.125, 0);
        assert_true(out[k].shared);
        if (!strstr(out[k].reason, "a UV square 8 nodes share (its UV box 12.5% of theirs"))
            fail_msg("reason '%s'", out[k].reason);
    }
    lx_scene_destroy(s);
}

/* Quadrants: each box covers 1/4 of the square (its faces tile the
 * quadrant), above min_coverage's 1/8, and has no overlap, so the node on
 * its own is usable; across the nodes it is a quarter of the square four
 * share. */
static void quadrants_usable_alone_shared_together(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("quadrants");
    for (int k = 0; k < 4; k++) {
        float i = (float)(k % 2), j = (float)(k / 2);
        const float r[4] = {i / 2, j / 2, (i + 1) / 2, (j + 1) / 2};
        add_node(s, add_box(s, r, NULL), (float)k);
    }
    lx_uv_share out[4];
    judge(s, 0, NULL, out);
    for (uint32_t k = 0; k < 4; k++) {
        lx_uv_health h;
        assert_int_equal(lx_uv_health_node(s, k, 0, NULL, &h), LX_OK);
        assert_float_equal(h.uv_area, 0.25, EPS);
        assert_true(h.usable);
        assert_float_equal(out[k].share, 0.25, 0);
        assert_true(out[k].shared);
    }
    /* a max_share under 1/4 lets them be */
    lx_uv_share_desc d = {.max_share = 0.2f};
    judge(s, 0, &d, out);
    for (int k = 0; k < 4; k++) {
        assert_float_equal(out[k].share, 0.25, 0);
        assert_false(out[k].shared);
        assert_string_equal(out[k].reason, "");
    }
    lx_scene_destroy(s);
}

/* Pieces on top of one another, as atlas objects reusing texture regions
 * are: box k over [k/16, k/16 + 1/4] x [0, 1/4], k = 0..7. The span is
 * [0, 11/16] x [0, 1/4]: share (1/16) / (11/64) = 4/11. */
static void overlapping_pieces(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("overlapping");
    for (int k = 0; k < 8; k++) {
        const float r[4] = {(float)k / 16, 0, (float)k / 16 + 0.25f, 0.25f};
        add_node(s, add_box(s, r, NULL), (float)k);
    }
    lx_uv_share out[8];
    judge(s, 0, NULL, out);
    for (int k = 0; k < 8; k++) {
        assert_float_equal(out[k].span_max.x, 11.0 / 16, 0);
        assert_float_equal(out[k].span_max.y, 0.25, 0);
        assert_float_equal(out[k].share, 4.0 / 11, EPS);
        assert_true(out[k].shared);
        assert_int_equal(out[k].boxes, 8);
    }
    lx_scene_destroy(s);
}

/* Lightmap sets of their own: eight meshes, each over the square less a
 * packing margin of k/200 on every side (a packer's margins differ). Span
 * [0,1]^2, share (1 - k/100)^2 >= 0.8649: none shared. */
static void full_squares_of_their_own(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("own squares");
    for (int k = 0; k < 8; k++) {
        float m = (float)k / 200;
        const float r[4] = {m, m, 1 - m, 1 - m};
        add_node(s, add_box(s, r, NULL), (float)k);
    }
    lx_uv_share out[8];
    judge(s, 0, NULL, out);
    for (int k = 0; k < 8; k++) {
        double side = 1.0 - k / 100.0;
        assert_true(out[k].counted);
        assert_float_equal(out[k].share, side * side, EPS);
        assert_false(out[k].shared);
        assert_int_equal(out[k].boxes, 8);
    }
    lx_scene_destroy(s);
}

/* Eight nodes placing one mesh whose UVs sit in [0.6,0.7] x [0.2,0.3]:
 * one box, share 1, none shared - while each covers 1% of the square,
 * which lx_uv_health_node calls sparse. */
static void instances_of_one_mesh(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("instances");
    const float r[4] = {0.6f, 0.2f, 0.7f, 0.3f};
    uint32_t mesh = add_box(s, r, NULL);
    for (int k = 0; k < 8; k++)
        add_node(s, mesh, (float)k);
    lx_uv_share out[8];
    judge(s, 0, NULL, out);
    for (uint32_t k = 0; k < 8; k++) {
        assert_true(out[k].counted);
        assert_int_equal(out[k].users, 8);
        assert_int_equal(out[k].boxes, 1);
        assert_float_equal(out[k].share, 1.0, 0);
        assert_false(out[k].shared);
        lx_uv_health h;
        assert_int_equal(lx_uv_health_node(s, k, 0, NULL, &h), LX_OK);
        assert_float_equal(h.uv_area, 0.01, EPS);
        assert_int_equal(h.problem, LX_UV_SPARSE);
    }
    lx_scene_destroy(s);
}

/* One node over the whole square among four pieces of [0, 1/2]^2 (its
 * quarters): the pieces are 1/16 of the span, the whole square 1. */
static void full_square_among_pieces(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("mixed");
    const float whole[4] = {0, 0, 1, 1};
    add_node(s, add_box(s, whole, NULL), 0);
    for (int k = 0; k < 4; k++) {
        float i = (float)(k % 2), j = (float)(k / 2);
        const float r[4] = {i / 4, j / 4, (i + 1) / 4, (j + 1) / 4};
        add_node(s, add_box(s, r, NULL), (float)k + 1);
    }
    lx_uv_share out[5];
    judge(s, 0, NULL, out);
    assert_float_equal(out[0].share, 1.0, 0);
    assert_false(out[0].shared);
    for (int k = 1; k < 5; k++) {
        assert_float_equal(out[k].share, 1.0 / 16, 0);
        assert_true(out[k].shared);
        assert_int_equal(out[k].users, 5);
    }
    lx_scene_destroy(s);
}

/* Each set is a square of its own: pieces in TEXCOORD_0 and full squares
 * in TEXCOORD_1 on the same meshes. Judged on set 1 (given, or chosen as
 * lx_bake_uv_set does when every mesh has it: uv_sets NULL) none is
 * shared; on set 0 all are. A node judged on set 1 and one on set 0 do not
 * share a span. */
static void sets_apart(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("sets");
    const float whole[4] = {0, 0, 1, 1};
    for (int k = 0; k < 4; k++) {
        float i = (float)(k % 2), j = (float)(k / 2);
        const float r[4] = {i / 2, j / 2, (i + 1) / 2, (j + 1) / 2};
        add_node(s, add_box(s, r, whole), (float)k);
    }
    lx_uv_share out[4];
    judge(s, 1, NULL, out);
    for (int k = 0; k < 4; k++)
        assert_false(out[k].shared);
    assert_int_equal(lx_uv_share_nodes(s, NULL, NULL, out), LX_OK);
    for (int k = 0; k < 4; k++) {
        assert_int_equal(out[k].uv_set, 1);
        assert_false(out[k].shared);
    }
    judge(s, 0, NULL, out);
    for (int k = 0; k < 4; k++)
        assert_true(out[k].shared);
    /* node 0 alone on set 0, the others on set 1: its own span */
    int sets[4] = {0, 1, 1, 1};
    assert_int_equal(lx_uv_share_nodes(s, sets, NULL, out), LX_OK);
    assert_int_equal(out[0].users, 1);
    assert_float_equal(out[0].share, 1.0, 0);
    assert_false(out[0].shared);
    assert_int_equal(out[1].users, 3);
    assert_int_equal(out[1].boxes, 1);
    lx_scene_destroy(s);
}

/* Nodes that do not count widen no span: one whose meshes lack the set,
 * one reaching outside the square (tiled UVs over [0, 2]^2), one without
 * meshes. The two pieces left, [0, 1/4]^2 and [1/4, 1/2] x [0, 1/4], span
 * [0, 1/2] x [0, 1/4]: share 1/2, shared at the default (at most 1/2). */
static void nodes_that_do_not_count(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("uncounted");
    const float a[4] = {0, 0, 0.25f, 0.25f}, b[4] = {0.25f, 0, 0.5f, 0.25f};
    const float tiled[4] = {0, 0, 2, 2}, whole[4] = {0, 0, 1, 1};
    add_node(s, add_box(s, a, whole), 0);
    add_node(s, add_box(s, b, whole), 1);
    add_node(s, add_box(s, tiled, whole), 2);
    uint32_t no_set1 = add_box(s, whole, NULL);
    add_node(s, no_set1, 3);
    lx_mat4 id = lx_mat4_identity();
    assert_int_equal(lx_scene_add_node(s, "empty", &id, NULL, 0, NULL), LX_OK);
    int sets[5] = {0, 0, 0, 1, 0};
    lx_uv_share out[5];
    assert_int_equal(lx_uv_share_nodes(s, sets, NULL, out), LX_OK);
    for (int k = 2; k < 5; k++) {
        assert_false(out[k].counted);
        assert_false(out[k].shared);
    }
    for (int k = 0; k < 2; k++) {
        assert_true(out[k].counted);
        assert_int_equal(out[k].users, 2);
        assert_float_equal(out[k].span_max.x, 0.5, 0);
        assert_float_equal(out[k].span_max.y, 0.25, 0);
        assert_float_equal(out[k].share, 0.5, 0);
        assert_true(out[k].shared);
    }
    lx_scene_destroy(s);
}

static void bad_arguments(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("bad");
    const float whole[4] = {0, 0, 1, 1};
    add_node(s, add_box(s, whole, NULL), 0);
    lx_uv_share out[1];
    assert_int_equal(lx_uv_share_nodes(NULL, NULL, NULL, out), LX_ERR_INVALID);
    assert_int_equal(lx_uv_share_nodes(s, NULL, NULL, NULL), LX_ERR_INVALID);
    int set = LX_MAX_UV_SETS;
    assert_int_equal(lx_uv_share_nodes(s, &set, NULL, out), LX_ERR_INVALID);
    if (!strstr(lx_last_error(), "node0") || !strstr(lx_last_error(), "UV set 8"))
        fail_msg("message '%s'", lx_last_error());
    set = -1;
    assert_int_equal(lx_uv_share_nodes(s, &set, NULL, out), LX_ERR_INVALID);
    lx_uv_share_desc d = {.max_share = 1.5f};
    set = 0;
    assert_int_equal(lx_uv_share_nodes(s, &set, &d, out), LX_ERR_INVALID);
    assert_float_equal(lx_uv_share_desc_defaults(NULL).max_share, 0.5, 0);
    assert_string_equal(lx_uv_problem_name(LX_UV_SHARED), "shared");
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(eight_side_by_side),
        cmocka_unit_test(quadrants_usable_alone_shared_together),
        cmocka_unit_test(overlapping_pieces),
        cmocka_unit_test(full_squares_of_their_own),
        cmocka_unit_test(instances_of_one_mesh),
        cmocka_unit_test(full_square_among_pieces),
        cmocka_unit_test(sets_apart),
        cmocka_unit_test(nodes_that_do_not_count),
        cmocka_unit_test(bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
