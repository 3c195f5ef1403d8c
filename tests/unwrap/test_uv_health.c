/* lx_uv_health_mesh / _node on generated meshes whose UVs are known:
 * counts against closed forms (a grid of cells aligned to the texels, a
 * fold onto a neighbour) and against the tests' brute-force oracle
 * (tests/common/uv_oracle.h: every texel against every pair of
 * triangles), the range and reasons of unusable sets, zero-area and
 * flipped triangles, the density sizing rule, and the same counts for any
 * thread count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"
#include "uv_oracle.h"

#include "luxel/unwrap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The oracle's and the library's threshold: two triangles overlap a texel
 * when they share more than a thousandth of it. */
#define MIN_AREA 1e-3

/* g x g unit quads in the plane y = 0, each two triangles with vertices of
 * their own (no sharing, so each can be given any UVs); `extra` more quads
 * placed beyond the grid. UV set 1: cell (i, j) of the unit square. */
static lx_mesh grid(uint32_t g, uint32_t extra)
{
    uint32_t quads = g * g + extra;
    lx_mesh m = {0};
    m.name = "grid";
    m.vertex_count = 6 * quads;
    m.triangle_count = 2 * quads;
    m.positions = calloc(m.vertex_count, sizeof(lx_vec3));
    m.normals = calloc(m.vertex_count, sizeof(lx_vec3));
    m.uv[1] = calloc(m.vertex_count, sizeof(lx_vec2));
    m.indices = calloc(3 * (size_t)m.triangle_count, sizeof(uint32_t));
    assert_true(m.positions && m.normals && m.uv[1] && m.indices);
    static const int corner[6][2] = {{0, 0}, {0, 1}, {1, 1}, {0, 0}, {1, 1}, {1, 0}};
    for (uint32_t q = 0; q < quads; q++) {
        uint32_t i = q < g * g ? q % g : q - g * g, j = q < g * g ? q / g : g + 1;
        for (int k = 0; k < 6; k++) {
            uint32_t v = 6 * q + (uint32_t)k;
            m.positions[v] = lx_v3((float)(i + corner[k][0]), 0.0f, (float)(j + corner[k][1]));
            m.normals[v] = lx_v3(0.0f, 1.0f, 0.0f);
            m.uv[1][v] = lx_v2((float)(q % (g * g) % g + corner[k][0]) / (float)g,
                               (float)(q % (g * g) / g + corner[k][1]) / (float)g);
            m.indices[v] = v;
        }
    }
    return m;
}

static void free_grid(lx_mesh *m)
{
    free(m->positions);
    free(m->normals);
    free(m->uv[1]);
    free(m->indices);
}

/* The oracle's counts for set 1 of m at res texels a side (zero-area
 * triangles left out, as the baker leaves them). */
static uint64_t oracle(const lx_mesh *m, int res, uint64_t *covered)
{
    double(*uv)[3][2] = malloc(sizeof *uv * m->triangle_count);
    assert_non_null(uv);
    uint32_t n = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        for (int k = 0; k < 3; k++) {
            lx_vec2 p = m->uv[1][m->indices[3 * t + k]];
            uv[n][k][0] = (double)p.x * res;
            uv[n][k][1] = (double)p.y * res;
        }
        double area = (uv[n][1][0] - uv[n][0][0]) * (uv[n][2][1] - uv[n][0][1]) -
                      (uv[n][2][0] - uv[n][0][0]) * (uv[n][1][1] - uv[n][0][1]);
        n += area != 0.0;
    }
    uint64_t o = lx_uv_pair_overlaps((const double(*)[3][2])uv, n, res, res, MIN_AREA, covered);
    free(uv);
    return o;
}

static lx_uv_health health(const lx_mesh *m, int res, int threads)
{
    lx_uv_health_desc d = {.resolution = res, .threads = threads};
    lx_uv_health h;
    assert_int_equal(lx_uv_health_mesh(m, 1, &d, &h), LX_OK);
    return h;
}

static void clean_grid_is_usable(void **state)
{
    (void)state;
    lx_mesh m = grid(4, 0);
    lx_uv_health h = health(&m, 64, 0);
    assert_true(h.present && h.usable);
    assert_int_equal(h.problem, LX_UV_OK);
    assert_string_equal(h.reason, "");
    /* the cells tile the unit square: every texel, none twice */
    assert_int_equal(h.covered_texels, 64 * 64);
    assert_int_equal(h.overlap_texels, 0);
    assert_int_equal(h.flipped_triangles, 0);
    assert_int_equal(h.zero_area_triangles, 0);
    assert_int_equal(h.triangles, 32);
    assert_true(h.min.x == 0.0f && h.min.y == 0.0f && h.max.x == 1.0f && h.max.y == 1.0f);
    lx_test_assert_rel(h.uv_area, 1.0, 1e-6);
    lx_test_assert_rel(h.world_area, 16.0, 1e-6);
    free_grid(&m);
}

static void one_tile_off_is_outside(void **state)
{
    (void)state;
    lx_mesh m = grid(4, 0);
    for (uint32_t v = 0; v < m.vertex_count; v++)
        m.uv[1][v].x += 1.0f;
    lx_uv_health h = health(&m, 64, 0);
    assert_false(h.usable);
    assert_int_equal(h.problem, LX_UV_OUTSIDE);
    assert_true(h.min.x == 1.0f && h.max.x == 2.0f && h.min.y == 0.0f && h.max.y == 1.0f);
    assert_non_null(strstr(h.reason, "outside [0,1]"));
    assert_non_null(strstr(h.reason, "u 1..2"));
    /* nothing lands on the lightmap */
    assert_int_equal(h.covered_texels, 0);
    uint64_t covered;
    assert_int_equal(oracle(&m, 64, &covered), 0);
    assert_int_equal(covered, 0);
    free_grid(&m);
}

/* 16 cells plus 4 quads laid again over the first row of cells: at 64
 * texels the cells are 16 texels, so exactly a quarter of the texels are
 * overlapped; at 50 they are 12.5 texels and the overlapped rows are
 * 0..12, 13 of 50. */
static void tiled_overlap_share(void **state)
{
    (void)state;
    lx_mesh m = grid(4, 4);
    lx_uv_health h = health(&m, 64, 0);
    assert_int_equal(h.covered_texels, 64 * 64);
    assert_int_equal(h.overlap_texels, 64 * 16);
    assert_true(h.overlap_share == 0.25);
    assert_false(h.usable);
    assert_int_equal(h.problem, LX_UV_OVERLAP);
    assert_string_equal(h.reason, "overlaps on 25% of its texels");
    uint64_t covered, o = oracle(&m, 64, &covered);
    assert_int_equal(h.overlap_texels, o);
    assert_int_equal(h.covered_texels, covered);

    h = health(&m, 50, 0);
    assert_int_equal(h.covered_texels, 50 * 50);
    assert_int_equal(h.overlap_texels, 13 * 50);
    lx_test_assert_rel(h.overlap_share, 13.0 / 50.0, 1e-12);
    o = oracle(&m, 50, &covered);
    assert_int_equal(h.overlap_texels, o);
    assert_int_equal(h.covered_texels, covered);

    /* a threshold above the share accepts it */
    lx_uv_health_desc d = {.resolution = 64, .max_overlap = 0.3f};
    assert_int_equal(lx_uv_health_mesh(&m, 1, &d, &h), LX_OK);
    assert_true(h.usable);
    free_grid(&m);
}

/* A quad's second triangle folded over its diagonal onto the first: one
 * flipped triangle; of the cell's s x s texels (s = 16) the s(s+1)/2 the
 * first triangle covers (the diagonal ones by half) are overlapped and the
 * s(s-1)/2 only the second covered are lost. */
static void folded_triangle(void **state)
{
    (void)state;
    lx_mesh m = grid(4, 0);
    /* quad 5 (cell (1, 1)): triangles (00, 01, 11) and (00, 11, 10); the
     * corner 10 goes to 01, the mirror image across the diagonal */
    uint32_t v = 6 * 5 + 5;
    m.uv[1][v] = m.uv[1][6 * 5 + 1];
    lx_uv_health h = health(&m, 64, 0);
    assert_int_equal(h.flipped_triangles, 1);
    assert_int_equal(h.zero_area_triangles, 0);
    assert_int_equal(h.overlap_texels, 16 * 17 / 2);
    assert_int_equal(h.covered_texels, 64 * 64 - 16 * 15 / 2);
    uint64_t covered, o = oracle(&m, 64, &covered);
    assert_int_equal(h.overlap_texels, o);
    assert_int_equal(h.covered_texels, covered);
    /* 136 of 3976 texels: above 1% */
    assert_int_equal(h.problem, LX_UV_OVERLAP);

    /* the same triangle turned in place (its corners' UVs swapped) covers
     * what it covered: flipped, nothing overlapped, usable */
    lx_mesh n = grid(4, 0);
    lx_vec2 t = n.uv[1][6 * 5 + 4];
    n.uv[1][6 * 5 + 4] = n.uv[1][6 * 5 + 5];
    n.uv[1][6 * 5 + 5] = t;
    h = health(&n, 64, 0);
    assert_int_equal(h.flipped_triangles, 1);
    assert_int_equal(h.overlap_texels, 0);
    assert_int_equal(h.covered_texels, 64 * 64);
    assert_true(h.usable);
    /* turning every triangle but one makes that one the flipped one */
    for (uint32_t q = 0; q < 16; q++)
        for (int k = 0; k < 2; k++) {
            lx_vec2 *uv = &n.uv[1][6 * q + 3 * (uint32_t)k];
            lx_vec2 s = uv[1];
            uv[1] = uv[2];
            uv[2] = s;
        }
    h = health(&n, 64, 0);
    assert_int_equal(h.flipped_triangles, 1);
    free_grid(&m);
    free_grid(&n);
}

static void zero_area_triangle(void **state)
{
    (void)state;
    lx_mesh m = grid(4, 0);
    /* triangle 2 (quad 1's first): its third corner onto the line of the
     * other two */
    lx_vec2 a = m.uv[1][6], b = m.uv[1][7];
    m.uv[1][8] = lx_v2(a.x, (a.y + b.y) * 0.5f);
    lx_uv_health h = health(&m, 64, 0);
    assert_int_equal(h.zero_area_triangles, 1);
    assert_int_equal(h.flipped_triangles, 0);
    assert_false(h.usable);
    assert_int_equal(h.problem, LX_UV_ZERO_AREA);
    assert_string_equal(h.reason, "1 zero-area triangle");
    /* the rest still cover their texels; the collapsed one's half cell is
     * lost except the texels its neighbour touches on the diagonal */
    uint64_t covered, o = oracle(&m, 64, &covered);
    assert_int_equal(h.overlap_texels, o);
    assert_int_equal(h.covered_texels, covered);
    assert_int_equal(h.covered_texels, 64 * 64 - 16 * 15 / 2);
    free_grid(&m);
}

static void missing_set(void **state)
{
    (void)state;
    lx_mesh m = grid(2, 0);
    lx_uv_health h;
    assert_int_equal(lx_uv_health_mesh(&m, 0, NULL, &h), LX_OK);
    assert_false(h.present);
    assert_false(h.usable);
    assert_int_equal(h.problem, LX_UV_MISSING);
    assert_string_equal(h.reason, "no TEXCOORD_0");
    assert_int_equal(lx_uv_health_mesh(&m, LX_MAX_UV_SETS, NULL, &h), LX_ERR_INVALID);
    lx_uv_health_desc bad = {.threads = -1};
    assert_int_equal(lx_uv_health_mesh(&m, 1, &bad, &h), LX_ERR_INVALID);
    free_grid(&m);
}

/* UVs in a corner of the square, as a texture atlas gives each object: a
 * 4x4 grid squeezed into [0, 0.115]^2 covers 0.115^2 = 1.3% of the
 * square (closed form) and is not usable; squeezed to 0.36 (13%) it is, at
 * the default min_coverage of 1/8, and a min_coverage of 0.2 refuses it. */
static void corner_of_the_square(void **state)
{
    (void)state;
    for (int c = 0; c < 3; c++) {
        static const float side[3] = {0.115f, 0.36f, 0.36f};
        static const float min_coverage[3] = {0.0f, 0.0f, 0.2f};
        lx_mesh m = grid(4, 0);
        for (uint32_t v = 0; v < m.vertex_count; v++)
            m.uv[1][v] = lx_v2(m.uv[1][v].x * side[c], m.uv[1][v].y * side[c]);
        lx_uv_health_desc d = {.min_coverage = min_coverage[c]};
        lx_uv_health h;
        assert_int_equal(lx_uv_health_mesh(&m, 1, &d, &h), LX_OK);
        assert_float_equal(h.uv_area, (double)side[c] * side[c], 1e-6);
        bool usable = c == 1;
        assert_int_equal(h.usable, usable);
        if (!usable) {
            assert_int_equal(h.problem, LX_UV_SPARSE);
            if (!strstr(h.reason, "% of the UV square"))
                fail_msg("reason '%s'", h.reason);
        }
        free_grid(&m);
    }
}

/* Two nodes: the node's meshes share one lightmap, so two clean meshes on
 * the same cells overlap as a node; the density sizes the bitmap as the
 * baker does (side^2 * uv_area = density^2 * world_area). */
static void node_level(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("health");
    lx_mesh m = grid(4, 0);
    uint32_t mesh[2];
    assert_int_equal(lx_scene_add_mesh(scene, &m, &mesh[0]), LX_OK);
    assert_int_equal(lx_scene_add_mesh(scene, &m, &mesh[1]), LX_OK);
    lx_mat4 scale = lx_mat4_identity();
    scale.m[0] = scale.m[5] = scale.m[10] = 2.0f;
    assert_int_equal(lx_scene_add_node(scene, "one", &scale, mesh, 1, NULL), LX_OK);
    lx_mat4 id = lx_mat4_identity();
    assert_int_equal(lx_scene_add_node(scene, "two", &id, mesh, 2, NULL), LX_OK);
    lx_uv_health_desc d = {.texel_density = 10.0f};
    lx_uv_health h;
    assert_int_equal(lx_uv_health_node(scene, 0, 1, &d, &h), LX_OK);
    /* 64 m^2 on the unit square at 10 texels/m: 80 a side */
    lx_test_assert_rel(h.world_area, 64.0, 1e-6);
    assert_int_equal(h.resolution, 80);
    assert_true(h.usable);
    assert_int_equal(h.covered_texels, 80 * 80);
    assert_int_equal(lx_uv_health_node(scene, 1, 1, &d, &h), LX_OK);
    /* 32 m^2 on the square counted twice: 10 sqrt(16) = 40 */
    assert_int_equal(h.resolution, 40);
    assert_int_equal(h.overlap_texels, 40 * 40);
    assert_false(h.usable);
    assert_int_equal(lx_uv_health_node(scene, 2, 1, &d, &h), LX_ERR_INVALID);
    lx_scene_destroy(scene);
    free_grid(&m);
}

/* Counts are integers summed per tile: any thread count gives them (above
 * about a million texel tests the tiles run on several threads: 1201). */
static void threads_agree(void **state)
{
    (void)state;
    lx_mesh m = grid(8, 8);
    m.uv[1][6 * 9 + 5] = m.uv[1][6 * 9 + 1];
    static const int sizes[] = {37, 301, 1201};
    for (int r = 0; r < 3; r++) {
        int res = sizes[r];
        lx_uv_health a = health(&m, res, 1), b = health(&m, res, 2), c = health(&m, res, 3);
        assert_int_equal(a.covered_texels, b.covered_texels);
        assert_int_equal(a.covered_texels, c.covered_texels);
        assert_int_equal(a.overlap_texels, b.overlap_texels);
        assert_int_equal(a.overlap_texels, c.overlap_texels);
        if (res < 100) {
            uint64_t covered, o = oracle(&m, res, &covered);
            assert_int_equal(a.overlap_texels, o);
            assert_int_equal(a.covered_texels, covered);
        }
    }
    free_grid(&m);
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(clean_grid_is_usable), cmocka_unit_test(one_tile_off_is_outside),
        cmocka_unit_test(tiled_overlap_share),  cmocka_unit_test(folded_triangle),
        cmocka_unit_test(zero_area_triangle),   cmocka_unit_test(missing_set),
        cmocka_unit_test(corner_of_the_square),
        cmocka_unit_test(node_level),           cmocka_unit_test(threads_agree),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
