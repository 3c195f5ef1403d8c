/* Triangles whose corners lie on a line but were stored as floats (zdm2's
 * T-junction fillers: a vertex on a long edge, rounded off it by a few
 * units in the last place) are zero-area triangles: the loader leaves them
 * out, so they are neither unwrapped nor reported as zero-area UVs, while
 * every triangle it keeps, thin ones included, gets a positive UV area
 * (the baker's rule, |e1 x e2| > 1e-7 longest^2, on the page's float UVs).
 * The geometry is built here, so which triangles are collinear is known
 * by construction, not by the rule under test. Before (area against the
 * longest edge alone): 2 of the 12 fillers kept, both with zero UV area. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "uv_oracle.h"

#include "luxel/luxel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STEPS 24 /* points along the line, less one */

typedef struct geometry {
    float position[3 * 128];
    uint32_t index[3 * 128];
    int vertices, triangles;
    int collinear; /* triangles made of three points of the line */
} geometry;

static int vertex(geometry *g, double x, double y, double z)
{
    g->position[3 * g->vertices] = (float)x;
    g->position[3 * g->vertices + 1] = (float)y;
    g->position[3 * g->vertices + 2] = (float)z;
    return g->vertices++;
}

static void triangle(geometry *g, int a, int b, int c)
{
    g->index[3 * g->triangles] = (uint32_t)a;
    g->index[3 * g->triangles + 1] = (uint32_t)b;
    g->index[3 * g->triangles + 2] = (uint32_t)c;
    g->triangles++;
}

/* In the plane y = 0, 16-24 m from the origin (float spacing 1.9e-6 m):
 * points P_i on a line along dir, a strip of quads on one side, and on the
 * other side a triangle over every second pair of segments, its long edge
 * P_i P_i+2 meeting the strip through the filler (P_i+1, P_i, P_i+2), as a
 * level editor's T-junctions do. Two real thin triangles (0.2 mm and 1 mm
 * high), and a 300 m ground below, so that the page spans many metres. */
static void build(geometry *g)
{
    memset(g, 0, sizeof *g);
    const double dir[3] = {0.6, 0.0, 0.8}, across[3] = {0.8, 0.0, -0.6}, step = 0.37;
    const double o[3] = {16.1, 0.0, 16.3};
    int p[STEPS + 1], q[STEPS + 1];
    for (int i = 0; i <= STEPS; i++) {
        double s = step * i;
        p[i] = vertex(g, o[0] + s * dir[0], 0.0, o[2] + s * dir[2]);
        q[i] = vertex(g, o[0] + s * dir[0] + 0.5 * across[0], 0.0,
                      o[2] + s * dir[2] + 0.5 * across[2]);
    }
    for (int i = 0; i < STEPS; i++) { /* facing +Y */
        triangle(g, p[i], p[i + 1], q[i + 1]);
        triangle(g, p[i], q[i + 1], q[i]);
    }
    for (int i = 0; i + 2 <= STEPS; i += 2) {
        double s = step * (i + 1);
        int r = vertex(g, o[0] + s * dir[0] - 0.5 * across[0], 0.0,
                       o[2] + s * dir[2] - 0.5 * across[2]);
        triangle(g, p[i + 2], p[i], r);
        triangle(g, p[i + 1], p[i], p[i + 2]);
        g->collinear++;
    }
    const double heights[2] = {2e-4, 1e-3};
    for (int k = 0; k < 2; k++) {
        double s0[3] = {20.5 + k, 0.0, 25.1};
        int a = vertex(g, s0[0], 0.0, s0[2]);
        int b = vertex(g, s0[0] + 0.9 * dir[0], 0.0, s0[2] + 0.9 * dir[2]);
        int c = vertex(g, s0[0] + 0.45 * dir[0] + heights[k] * across[0], 0.0,
                       s0[2] + 0.45 * dir[2] + heights[k] * across[2]);
        triangle(g, a, b, c);
    }
    int f[4] = {vertex(g, 0, -5, 0), vertex(g, 0, -5, 300), vertex(g, 300, -5, 300),
                vertex(g, 300, -5, 0)};
    triangle(g, f[0], f[1], f[2]);
    triangle(g, f[0], f[2], f[3]);
}

static void write_scene(const geometry *g, const char *path)
{
    lx_test_gltf *gl = lx_test_gltf_new();
    lx_test_primitive prim = {.vertex_count = g->vertices,
                              .position = g->position,
                              .index_count = 3 * g->triangles,
                              .indices = g->index,
                              .material = -1};
    int mesh = lx_test_gltf_mesh(gl, "level", &prim, 1);
    lx_test_gltf_node(gl, "level", mesh, "");
    lx_test_gltf_write_glb(gl, path);
    lx_test_gltf_free(gl);
}

/* Twice the signed area of a triangle's page UVs in texels and its
 * longest edge squared, in double from the float UVs (the baker's terms). */
static bool positive_uv_area(const lx_vec2 uv[3], int width, int height)
{
    double a[3][2];
    for (int k = 0; k < 3; k++)
        a[k][0] = (double)uv[k].x * width, a[k][1] = (double)uv[k].y * height;
    double e1x = a[1][0] - a[0][0], e1y = a[1][1] - a[0][1];
    double e2x = a[2][0] - a[0][0], e2y = a[2][1] - a[0][1];
    double e3x = a[2][0] - a[1][0], e3y = a[2][1] - a[1][1];
    double cross = e1x * e2y - e2x * e1y;
    double longest =
        fmax(e1x * e1x + e1y * e1y, fmax(e2x * e2x + e2y * e2y, e3x * e3x + e3y * e3y));
    return fabs(cross) > 1e-7 * longest && longest > 0.0;
}

static void fillers_are_left_out_and_the_rest_gets_uv_area(void **state)
{
    (void)state;
    geometry g;
    build(&g);
    /* the fillers are collinear to float rounding: a few ulps high */
    assert_int_equal(g.collinear, STEPS / 2);
    char path[512];
    snprintf(path, sizeof path, "%s/slivers.glb", lx_test_dir("slivers"));
    write_scene(&g, path);
    lx_test_logbook book;
    lx_scene *scene = lx_test_load_logged(path, NULL, &book);
    assert_int_equal(scene->mesh_count, 1);
    /* every filler left out (one warning counts them), nothing else */
    assert_int_equal(scene->meshes[0].triangle_count, (uint32_t)(g.triangles - g.collinear));
    char want[64];
    snprintf(want, sizeof want, "%d zero-area triangles left out", g.collinear);
    assert_non_null(strstr(book.text, want));

    /* 1 texel/m: a page of about 300 m, whose float UVs are 1.8e-5 m apart
     * at its far side, ten times the fillers' height */
    lx_unwrap_desc d = lx_unwrap_desc_defaults(NULL);
    d.texel_density = 1.0f;
    d.padding = LX_UNWRAP_PADDING_RECOMMENDED;
    lx_unwrap *u;
    assert_int_equal(lx_unwrap_scene(scene, &d, &u), LX_OK);
    assert_int_equal(u->stats.degenerate_triangles, 0);
    assert_int_equal(u->mesh_count, 1);
    const lx_unwrap_mesh *um = &u->meshes[0];
    const lx_unwrap_page *pg = &u->pages[u->nodes[um->node].page];
    uint32_t zero = 0;
    for (uint32_t t = 0; t < scene->meshes[0].triangle_count; t++) {
        lx_vec2 uv[3];
        for (int k = 0; k < 3; k++)
            uv[k] = um->uv[um->indices[3 * t + k]];
        zero += !positive_uv_area(uv, pg->width, pg->height);
    }
    assert_int_equal(zero, 0);
    lx_unwrap_destroy(u);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fillers_are_left_out_and_the_rest_gets_uv_area),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
