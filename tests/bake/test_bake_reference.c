/* The fast path (rasterized texel maps, Embree shadow rays) against the
 * per-texel lighting document's brute force (tests/common/reference.c: every texel searches every
 * triangle; every shadow ray tests every triangle of every node).
 *
 * Texel maps: every texel the reference covers must be covered by the fast
 * path with the same triangle (or, for a centre exactly on a shared edge,
 * another triangle that also contains it) and the same world position;
 * texels only the fast path covers (its pass 2) must be border texels: the
 * triangle overlaps the texel square (with an area: touching along a line
 * does not count) but no triangle contains its centre,
 * and the sample is the triangle's closest point to the centre.
 * Lighting: the reference lighting at each texel matches the baked value to
 * 1e-5 relative, hard shadows and unshadowed lights, several lights. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"
#include "reference.h"

#define EDGE_EPS 1e-4 /* shadow rays this close to an edge are skipped */
/* Baked (float) against the reference (double): relative to the texel's
 * value, or to GRAZING of the lights' unattenuated illuminance (the oracle's
 * scale: no N.L, no range falloff) where that is larger. Measured: 2.1e-6
 * (plane+box, at the fast path's samples and at the reference's), 1.7e-6
 * at most in the other scenes. */
#define LIGHT_TOL 6e-6
#define GRAZING 0.01

/* ---- scene building --------------------------------------------------------- */

static lx_scene *new_scene(const char *name)
{
    lx_scene *s;
    assert_int_equal(lx_scene_create(name, &s), LX_OK);
    lx_material mat = {.name = "white", .base_color = {1, 1, 1, 1}};
    assert_int_equal(lx_scene_add_material(s, &mat, NULL), LX_OK);
    return s;
}

static uint32_t add_mesh(lx_scene *s, lx_mesh *m)
{
    uint32_t idx;
    if (lx_scene_add_mesh(s, m, &idx) != LX_OK)
        fail_msg("add mesh: %s", lx_last_error());
    lx_test_mesh_free(m);
    return idx;
}

static uint32_t add_node(lx_scene *s, const char *name, lx_mat4 world, const uint32_t *meshes,
                         uint32_t count)
{
    uint32_t idx;
    if (lx_scene_add_node(s, name, &world, meshes, count, &idx) != LX_OK)
        fail_msg("add node: %s", lx_last_error());
    return idx;
}

static void add_light(lx_scene *s, lx_light l)
{
    if (lx_scene_add_light(s, &l) != LX_OK)
        fail_msg("add light: %s", lx_last_error());
}

static lx_light point(const char *name, lx_vec3 p, float cd, float range, lx_shadow_mode sh)
{
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "%s", name);
    l.position = p;
    l.intensity = cd;
    l.range = range;
    l.shadow = sh;
    return l;
}

static lx_light spot(const char *name, lx_vec3 p, lx_vec3 target, float cd, lx_shadow_mode sh)
{
    lx_light l = lx_light_defaults(LX_LIGHT_SPOT);
    snprintf(l.name, sizeof l.name, "%s", name);
    l.position = p;
    l.direction = lx_normalize(lx_sub(target, p));
    l.inner_angle = LX_DEG2RAD(20.0f);
    l.outer_angle = LX_DEG2RAD(40.0f);
    l.intensity = cd;
    l.shadow = sh;
    l.color = lx_v3(0.3f, 0.6f, 1.0f);
    return l;
}

static lx_light sun(const char *name, lx_vec3 dir, float lux, lx_shadow_mode sh)
{
    lx_light l = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    snprintf(l.name, sizeof l.name, "%s", name);
    l.direction = lx_normalize(dir);
    l.intensity = lux;
    l.shadow = sh;
    l.color = lx_v3(1.0f, 0.9f, 0.7f);
    return l;
}

static lx_vec4 axis_angle(lx_vec3 axis, float deg)
{
    axis = lx_normalize(axis);
    float h = LX_DEG2RAD(deg) / 2;
    return lx_v4(axis.x * sinf(h), axis.y * sinf(h), axis.z * sinf(h), cosf(h));
}

/* remaps a mesh's lightmap UVs (uv[1]) into the rectangle [u0,u1]x[v0,v1] */
static void remap_uv1(lx_mesh *m, float u0, float v0, float u1, float v1)
{
    float lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        lo[0] = fminf(lo[0], m->uv[1][i].x), hi[0] = fmaxf(hi[0], m->uv[1][i].x);
        lo[1] = fminf(lo[1], m->uv[1][i].y), hi[1] = fmaxf(hi[1], m->uv[1][i].y);
    }
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        lx_vec2 t = m->uv[1][i];
        m->uv[1][i] = lx_v2(u0 + (u1 - u0) * (t.x - lo[0]) / (hi[0] - lo[0]),
                            v0 + (v1 - v0) * (t.y - lo[1]) / (hi[1] - lo[1]));
    }
}

/* ---- independent geometry for the border check -------------------------- */

/* Separating-axis gap between a 2D triangle and the square [x0,x0+1]x[y0,y0+1]
 * (texel units): > 0 separated, 0 touching, < 0 overlapping. */
static double tri_square_gap(const double t[3][2], double x0, double y0)
{
    const double sq[4][2] = {{x0, y0}, {x0 + 1, y0}, {x0 + 1, y0 + 1}, {x0, y0 + 1}};
    double axes[5][2] = {{1, 0}, {0, 1}};
    for (int e = 0; e < 3; e++) {
        const double *a = t[e], *b = t[(e + 1) % 3];
        double nx = b[1] - a[1], ny = a[0] - b[0], len = hypot(nx, ny);
        axes[2 + e][0] = nx / len, axes[2 + e][1] = ny / len;
    }
    double gap = -INFINITY;
    for (int k = 0; k < 5; k++) {
        double amin = INFINITY, amax = -INFINITY, bmin = INFINITY, bmax = -INFINITY;
        for (int i = 0; i < 3; i++) {
            double p = t[i][0] * axes[k][0] + t[i][1] * axes[k][1];
            amin = fmin(amin, p), amax = fmax(amax, p);
        }
        for (int i = 0; i < 4; i++) {
            double p = sq[i][0] * axes[k][0] + sq[i][1] * axes[k][1];
            bmin = fmin(bmin, p), bmax = fmax(bmax, p);
        }
        gap = fmax(gap, fmax(bmin - amax, amin - bmax));
    }
    return gap;
}

static double seg_dist(const double p[2], const double a[2], const double b[2])
{
    double dx = b[0] - a[0], dy = b[1] - a[1];
    double t = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return hypot(p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy));
}

/* Distance from p to triangle t (2D). */
static double tri_dist(const double t[3][2], const double p[2])
{
    double w[3];
    if (lx_ref_uv_barycentric(lx_v2((float)t[0][0], (float)t[0][1]),
                              lx_v2((float)t[1][0], (float)t[1][1]),
                              lx_v2((float)t[2][0], (float)t[2][1]), p[0], p[1], w) &&
        w[0] >= 0 && w[1] >= 0 && w[2] >= 0)
        return 0.0;
    return fmin(seg_dist(p, t[0], t[1]), fmin(seg_dist(p, t[1], t[2]), seg_dist(p, t[2], t[0])));
}

/* A triangle's lightmap UVs in texel units. */
static void uv_texels(const lx_mesh *m, uint32_t tri, int w, int h, double out[3][2])
{
    const lx_vec2 *uv = m->uv[lx_ref_uv_set(m)];
    for (int k = 0; k < 3; k++) {
        lx_vec2 t = uv[m->indices[3 * tri + k]];
        out[k][0] = (double)t.x * w;
        out[k][1] = (double)t.y * h;
    }
}

/* Barycentrics of world point p on a world triangle (Ericson 3.4, the
 * document's checkIntersectionInTri); *off = distance from the triangle's plane
 * point with those barycentrics. */
static void world_bary(const lx_ref_triangle *t, lx_vec3 p, double w[3], double *off)
{
    double e1[3], e2[3], q[3];
    for (int c = 0; c < 3; c++) {
        e1[c] = t->p[1][c] - t->p[0][c];
        e2[c] = t->p[2][c] - t->p[0][c];
    }
    q[0] = p.x - t->p[0][0], q[1] = p.y - t->p[0][1], q[2] = p.z - t->p[0][2];
    double d00 = 0, d01 = 0, d11 = 0, d20 = 0, d21 = 0;
    for (int c = 0; c < 3; c++) {
        d00 += e1[c] * e1[c], d01 += e1[c] * e2[c], d11 += e2[c] * e2[c];
        d20 += q[c] * e1[c], d21 += q[c] * e2[c];
    }
    double den = d00 * d11 - d01 * d01;
    w[1] = (d11 * d20 - d01 * d21) / den;
    w[2] = (d00 * d21 - d01 * d20) / den;
    w[0] = 1 - w[1] - w[2];
    double r2 = 0;
    for (int c = 0; c < 3; c++) {
        double d = q[c] - w[1] * e1[c] - w[2] * e2[c];
        r2 += d * d;
    }
    *off = sqrt(r2);
}

static const lx_ref_triangle *find_tri(const lx_ref_scene *rs, uint32_t node, uint32_t mesh,
                                       uint32_t tri)
{
    for (uint32_t i = 0; i < rs->count; i++)
        if (rs->tris[i].node == node && rs->tris[i].mesh == mesh && rs->tris[i].triangle == tri)
            return &rs->tris[i];
    return NULL;
}

/* ---- the comparison ----------------------------------------------------------- */

typedef struct stats {
    int ref_texels, fast_only, shadowed, compared, skipped;
    double max_rel[2]; /* largest difference of a channel (see LIGHT_TOL): at
                        * the fast path's sample, at the reference's */
} stats;

static bool close_rel(double a, double b, double rel)
{
    return fabs(a - b) <= rel * fmax(fabs(a), fabs(b)) + 1e-30;
}

static void compare_map(const lx_scene *scene, const lx_ref_scene *rs, const lx_baker *b,
                        uint32_t map, stats *st)
{
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, map);
    const lx_node *node = &scene->nodes[info->node];
    const int w = info->width, h = info->height;
    /* positions: measured within 4.7e-8 of the scene's diagonal (float
     * rounding of the transforms), bound 2e-7 */
    const double pos_tol = 2e-7 * rs->diagonal;
    lx_ref_map ref;
    lx_ref_texel_map(scene, info->node, w, h, &ref);
    const uint8_t *mask = lx_baker_mask(b, map);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    /* the same lights with shadows off: to count texels some shadow darkens */
    lx_light *open = malloc(sizeof(lx_light) * (scene->light_count + 1));
    for (uint32_t l = 0; l < scene->light_count; l++) {
        open[l] = scene->lights[l];
        open[l].shadow = LX_SHADOW_NONE;
    }
    uint32_t used = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const lx_ref_texel *rt = &ref.texels[y * w + x];
            lx_texel_sample s;
            bool fast = lx_baker_texel(b, map, x, y, &s);
            assert_int_equal(fast, mask[y * w + x] != 0);
            used += fast;
            if (rt->used) {
                st->ref_texels++;
                if (!fast)
                    fail_msg("node '%s' texel (%d, %d): the reference covers it (mesh %u "
                             "triangle %u), the fast path does not",
                             node->name, x, y, rt->mesh, rt->triangle);
                if (rt->margin > 1e-6) {
                    if (s.mesh != rt->mesh || s.triangle != rt->triangle)
                        fail_msg("node '%s' texel (%d, %d): triangle %u/%u, reference %u/%u",
                                 node->name, x, y, s.mesh, s.triangle, rt->mesh, rt->triangle);
                } else {
                    /* centre on a shared edge: either neighbour is right */
                    double t[3][2], bw[3];
                    uv_texels(&scene->meshes[s.mesh], s.triangle, w, h, t);
                    lx_ref_uv_barycentric(lx_v2((float)t[0][0], (float)t[0][1]),
                                          lx_v2((float)t[1][0], (float)t[1][1]),
                                          lx_v2((float)t[2][0], (float)t[2][1]), x + 0.5, y + 0.5,
                                          bw);
                    if (fmin(bw[0], fmin(bw[1], bw[2])) < -1e-6)
                        fail_msg("node '%s' texel (%d, %d): triangle %u/%u does not contain "
                                 "the centre",
                                 node->name, x, y, s.mesh, s.triangle);
                }
                double d = lx_length(lx_sub(s.position, rt->position));
                if (!(d <= pos_tol))
                    fail_msg("node '%s' texel (%d, %d): position (%g %g %g), reference "
                             "(%g %g %g)",
                             node->name, x, y, s.position.x, s.position.y, s.position.z,
                             rt->position.x, rt->position.y, rt->position.z);
                /* measured: one float ulp below 1 at most; bound two */
                assert_true(lx_dot(s.normal, rt->normal) > 1.0f - 2e-7f);
                assert_true(fabsf(lx_dot(s.geometric_normal, rt->geometric_normal)) > 1.0f - 2e-7f);
            } else if (fast) {
                /* pass 2: a border texel the triangle overlaps without its centre */
                st->fast_only++;
                const lx_mesh *m = &scene->meshes[s.mesh];
                bool in_node = false;
                for (uint32_t k = 0; k < node->mesh_count; k++)
                    in_node = in_node || node->meshes[k] == s.mesh;
                assert_true(in_node);
                assert_true(s.triangle < m->triangle_count);
                double t[3][2];
                uv_texels(m, s.triangle, w, h, t);
                /* a positive area in common: touching along a line is not
                 * overlapping */
                double gap = tri_square_gap(t, x, y);
                if (!(gap < -1e-9))
                    fail_msg("node '%s' texel (%d, %d): border texel of triangle %u/%u which "
                             "does not overlap its square with an area (gap %g texels)",
                             node->name, x, y, s.mesh, s.triangle, gap);
                /* the sample lies on that triangle ... */
                const lx_ref_triangle *wt = find_tri(rs, info->node, s.mesh, s.triangle);
                assert_non_null(wt);
                double bw[3], off;
                world_bary(wt, s.position, bw, &off);
                assert_true(off <= pos_tol);
                /* measured: never outside; float rounding allowed */
                assert_true(fmin(bw[0], fmin(bw[1], bw[2])) >= -1e-7);
                /* ... at (nearly: nudged 0.1% toward the centroid) its closest
                 * point to the centre, and no other triangle of the node
                 * overlapping the texel is closer (measured: within 4.9e-4
                 * of the triangle's diameter) */
                double c[2] = {x + 0.5, y + 0.5};
                double uvp[2] = {bw[0] * t[0][0] + bw[1] * t[1][0] + bw[2] * t[2][0],
                                 bw[0] * t[0][1] + bw[1] * t[1][1] + bw[2] * t[2][1]};
                double d_lib = hypot(uvp[0] - c[0], uvp[1] - c[1]);
                double d_min = INFINITY, diam = 0;
                for (uint32_t k = 0; k < node->mesh_count; k++) {
                    const lx_mesh *mk = &scene->meshes[node->meshes[k]];
                    if (lx_ref_uv_set(mk) < 0)
                        continue;
                    for (uint32_t tr = 0; tr < mk->triangle_count; tr++) {
                        double tt[3][2];
                        uv_texels(mk, tr, w, h, tt);
                        if (tri_square_gap(tt, x, y) > -1e-9)
                            continue;
                        d_min = fmin(d_min, tri_dist(tt, c));
                    }
                }
                for (int k = 0; k < 3; k++)
                    diam =
                        fmax(diam, hypot(t[k][0] - t[(k + 1) % 3][0], t[k][1] - t[(k + 1) % 3][1]));
                if (!(fabs(d_lib - d_min) <= 2e-3 * diam + 1e-4))
                    fail_msg("node '%s' border texel (%d, %d): sample %g texels from the "
                             "centre, closest triangle %g",
                             node->name, x, y, d_lib, d_min);
                assert_true(d_lib <= sqrt(0.5) + 2e-3 * diam + 1e-4);
            }

            if (!fast)
                continue;
            /* lighting: the reference at the fast path's own sample, and at
             * the reference's sample, against the baked value */
            const float *px = &img.data[3 * (y * w + x)];
            for (int pass = 0; pass < 2; pass++) {
                if (pass == 1 && !rt->used)
                    break;
                lx_vec3 p = pass == 0 ? s.position : rt->position;
                lx_vec3 n = pass == 0 ? s.normal : rt->normal;
                lx_vec3 ng = pass == 0 ? s.geometric_normal : rt->geometric_normal;
                bool amb = false;
                lx_vec3 scale;
                lx_vec3 want = lx_ref_shade_scale(rs, scene->lights, scene->light_count,
                                                  scene->ambient, p, n, ng, EDGE_EPS, &amb, &scale);
                if (amb) {
                    st->skipped++;
                    continue;
                }
                st->compared++;
                const float wv[3] = {want.x, want.y, want.z};
                const float sc[3] = {scale.x, scale.y, scale.z};
                for (int k = 0; k < 3; k++) {
                    /* relative, but to no less than GRAZING of what the
                     * lights bring before N.L and the falloff: their float
                     * rounding is absolute */
                    double size = fmax(fmax(fabs(px[k]), fabs(wv[k])), GRAZING * sc[k]);
                    double err = size > 0.0 ? fabs(px[k] - wv[k]) / size : 0.0;
                    st->max_rel[pass] = fmax(st->max_rel[pass], err);
                    if (!(err <= LIGHT_TOL))
                        fail_msg("node '%s' texel (%d, %d) channel %d (%s sample at %g %g "
                                 "%g, normal %g %g %g): baked %.9g, reference %.9g "
                                 "(difference %.3g of %.6g)",
                                 node->name, x, y, k, pass == 0 ? "fast" : "reference", p.x, p.y,
                                 p.z, n.x, n.y, n.z, px[k], wv[k], err, size);
                }
                if (pass == 0) {
                    lx_vec3 unshadowed = lx_ref_shade(rs, open, scene->light_count, scene->ambient,
                                                      p, n, ng, EDGE_EPS, NULL);
                    if (!close_rel(unshadowed.x + unshadowed.y + unshadowed.z,
                                   want.x + want.y + want.z, 1e-4))
                        st->shadowed++;
                }
            }
        }
    assert_int_equal(used, info->used_texels);
    free(open);
    lx_image_free(&img);
    lx_ref_map_free(&ref);
}

static stats compare_scene(const lx_scene *scene, int resolution)
{
    lx_bake_desc d = {.resolution = resolution, .padding = LX_PADDING_NONE};
    lx_baker *b;
    if (lx_baker_create(scene, &d, &b) != LX_OK)
        fail_msg("baker: %s", lx_last_error());
    assert_int_equal(lx_baker_bake(b), LX_OK);
    lx_ref_scene rs;
    lx_ref_scene_build(scene, &rs);
    stats st = {0};
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++)
        compare_map(scene, &rs, b, m, &st);
    print_message("%s: %d reference texels, %d border-only, %d lit compared, "
                  "%d skipped near edges, %d shadowed, largest difference %.3g at the fast "
                  "path's samples, %.3g at the reference's\n",
                  scene->path, st.ref_texels, st.fast_only, st.compared, st.skipped, st.shadowed,
                  st.max_rel[0], st.max_rel[1]);
    assert_true(st.skipped * 50 <= st.compared); /* at most 2% near-ties */
    lx_ref_scene_free(&rs);
    lx_baker_destroy(b);
    return st;
}

/* ---- scenes -------------------------------------------------------------------- */

static void test_plane_box_occluder(void **state)
{
    (void)state;
    lx_scene *s = new_scene("plane+box");
    lx_mat4 id = lx_mat4_identity();
    lx_mesh ground = lx_test_plane("ground", 6.0f, 0.0f, 0.0f, 0.0f, 6);
    uint32_t g = add_mesh(s, &ground);
    add_node(s, "ground", id, &g, 1);
    lx_mesh box = lx_test_box("box", lx_v3(-0.5f, 0.6f, -0.3f), lx_v3(0.5f, 1.4f, 0.7f), false);
    uint32_t bx = add_mesh(s, &box);
    add_node(s, "box", id, &bx, 1);
    add_light(s, point("bulb", lx_v3(0.3f, 3.0f, 0.2f), 80.0f, 0.0f, LX_SHADOW_HARD));
    add_light(s, spot("spot", lx_v3(-2.0f, 2.5f, 1.5f), lx_v3(0.5f, 0.0f, -0.5f), 200.0f,
                      LX_SHADOW_HARD));
    s->ambient = lx_v3(0.01f, 0.02f, 0.03f);
    stats st = compare_scene(s, 64);
    assert_true(st.ref_texels > 4000);
    assert_true(st.fast_only > 50); /* the box's charts have borders */
    assert_true(st.shadowed > 200);
    lx_scene_destroy(s);
}

static void test_transformed_nodes(void **state)
{
    (void)state;
    lx_scene *s = new_scene("transformed");
    lx_mat4 id = lx_mat4_identity();
    lx_mesh ground = lx_test_plane("ground", 6.0f, 0.0f, 0.5f, -0.5f, 4);
    uint32_t g = add_mesh(s, &ground);
    add_node(s, "ground", id, &g, 1);
    lx_mesh box = lx_test_box("box", lx_v3(-0.5f, -0.5f, -0.5f), lx_v3(0.5f, 0.5f, 0.5f), false);
    uint32_t bx = add_mesh(s, &box);
    /* rotated, non-uniformly scaled, translated */
    lx_mat4 trs = lx_mat4_trs(lx_v3(0.4f, 1.2f, -0.3f), axis_angle(lx_v3(1, 2, 0.5f), 35.0f),
                              lx_v3(1.3f, 0.6f, 0.9f));
    add_node(s, "turned", trs, &bx, 1);
    /* the same mesh mirrored (negative determinant) */
    lx_mat4 mir = lx_mat4_trs(lx_v3(-1.5f, 0.9f, 1.0f), axis_angle(lx_v3(0, 1, 0), -20.0f),
                              lx_v3(-0.8f, 0.7f, 1.1f));
    add_node(s, "mirrored", mir, &bx, 1);
    add_light(s, sun("sun", lx_v3(0.4f, -1.0f, 0.3f), 3.0f, LX_SHADOW_HARD));
    add_light(s, point("lamp", lx_v3(-0.5f, 2.5f, -1.0f), 40.0f, 8.0f, LX_SHADOW_NONE));
    add_light(s, point("low", lx_v3(2.0f, 0.8f, 1.5f), 25.0f, 0.0f, LX_SHADOW_HARD));
    stats st = compare_scene(s, 64);
    assert_true(st.shadowed > 100);
    lx_scene_destroy(s);
}

static void test_multi_mesh_node(void **state)
{
    (void)state;
    lx_scene *s = new_scene("multi-mesh");
    lx_mat4 id = lx_mat4_identity();
    lx_mesh ground = lx_test_plane("ground", 5.0f, 0.0f, 0.0f, 0.0f, 5);
    uint32_t g = add_mesh(s, &ground);
    add_node(s, "ground", id, &g, 1);
    /* one node, two meshes: a raised plate in the left of the lightmap and
     * a box in the right whose charts overlap the plate's UVs a little
     * (first mesh wins where both cover a centre). TEXCOORD_0 differs from
     * TEXCOORD_1 so using the wrong set shows. */
    lx_mesh plate = lx_test_plane("plate", 1.5f, 1.0f, -0.6f, 0.2f, 3);
    remap_uv1(&plate, 0.05f, 0.1f, 0.47f, 0.9f);
    lx_mesh box = lx_test_box("crate", lx_v3(0.5f, 0.3f, -0.9f), lx_v3(1.2f, 0.9f, -0.2f), false);
    remap_uv1(&box, 0.44f, 0.05f, 0.95f, 0.95f);
    uint32_t pair[2] = {add_mesh(s, &plate), add_mesh(s, &box)};
    add_node(s, "pair", lx_mat4_translate(lx_v3(0.1f, 0.2f, 0.0f)), pair, 2);
    /* a mesh with TEXCOORD_0 only */
    lx_mesh only0 = lx_test_plane("only0", 1.0f, 0.5f, 1.5f, 1.5f, 2);
    free(only0.uv[1]);
    only0.uv[1] = NULL;
    for (uint32_t v = 0; v < only0.vertex_count; v++)
        only0.uv[0][v] = lx_v2(0.2f + 0.6f * only0.uv[0][v].x, 0.1f + 0.7f * only0.uv[0][v].y);
    uint32_t o = add_mesh(s, &only0);
    add_node(s, "only0", id, &o, 1);
    add_light(s, point("bulb", lx_v3(0.0f, 3.0f, 0.5f), 60.0f, 0.0f, LX_SHADOW_HARD));
    add_light(s, sun("sun", lx_v3(-0.3f, -1.0f, 0.6f), 2.0f, LX_SHADOW_NONE));
    lx_light amb = point("glow", lx_v3(1.0f, 0.65f, 1.0f), 5.0f, 3.0f, LX_SHADOW_HARD);
    amb.ambient = lx_v3(0.2f, 0.0f, 0.1f);
    add_light(s, amb);
    stats st = compare_scene(s, 64);
    assert_true(st.shadowed > 100);
    lx_scene_destroy(s);
}

static void test_blur_shadows(void **state)
{
    (void)state;
    lx_scene *s = new_scene("blur");
    lx_mat4 id = lx_mat4_identity();
    lx_mesh ground = lx_test_plane("ground", 4.0f, 0.0f, 0.0f, 0.0f, 4);
    uint32_t g = add_mesh(s, &ground);
    add_node(s, "ground", id, &g, 1);
    lx_mesh plate = lx_test_plane("plate", 1.0f, 0.8f, 0.2f, 0.1f, 1);
    uint32_t p = add_mesh(s, &plate);
    add_node(s, "plate", id, &p, 1);
    lx_light l = point("soft", lx_v3(-0.2f, 2.5f, 0.0f), 50.0f, 0.0f, LX_SHADOW_BLUR);
    l.blur_power = 0.7f;
    l.blur_multiplier = 1.5f;
    add_light(s, l);
    add_light(s, point("hard", lx_v3(1.0f, 2.0f, 1.0f), 30.0f, 0.0f, LX_SHADOW_HARD));
    stats st = compare_scene(s, 48);
    assert_true(st.shadowed > 50);
    lx_scene_destroy(s);
}

/* The rest of the light model: the classic falloff on a point, a spot and
 * a directional light; ranges shorter than the scene (the classic point's
 * 3 m ends on the ground about 2.2 m out, the physical point's window at
 * 2.5 m); ambient that fades with the range; a hard-edged spot (inner ==
 * outer); a blurred directional light (the scene's diagonal for its
 * distance). */
static void test_classic_and_ranges(void **state)
{
    (void)state;
    lx_scene *s = new_scene("classic and ranges");
    lx_mat4 id = lx_mat4_identity();
    lx_mesh ground = lx_test_plane("ground", 6.0f, 0.0f, 0.0f, 0.0f, 6);
    uint32_t g = add_mesh(s, &ground);
    add_node(s, "ground", id, &g, 1);
    lx_mesh box = lx_test_box("box", lx_v3(-0.4f, 0.0f, -0.4f), lx_v3(0.4f, 0.9f, 0.4f), false);
    uint32_t bx = add_mesh(s, &box);
    add_node(s, "box", id, &bx, 1);

    lx_light cp = point("classic point", lx_v3(0.6f, 2.0f, 0.5f), 3.0f, 3.0f, LX_SHADOW_HARD);
    cp.model = LX_MODEL_CLASSIC;
    cp.color = lx_v3(1.0f, 0.8f, 0.6f);
    add_light(s, cp);
    lx_light cs = spot("classic spot", lx_v3(-1.8f, 2.2f, -1.2f), lx_v3(0.3f, 0.0f, 0.2f), 4.0f,
                       LX_SHADOW_BLUR);
    cs.model = LX_MODEL_CLASSIC;
    cs.range = 5.0f;
    add_light(s, cs);
    lx_light cd = sun("classic sun", lx_v3(0.3f, -1.0f, 0.5f), 0.5f, LX_SHADOW_HARD);
    cd.model = LX_MODEL_CLASSIC;
    add_light(s, cd);
    lx_light win = point("windowed", lx_v3(-1.0f, 1.2f, 1.5f), 6.0f, 2.5f, LX_SHADOW_NONE);
    win.ambient = lx_v3(0.05f, 0.02f, 0.0f);
    add_light(s, win);
    lx_light hard = spot("hard cone", lx_v3(1.5f, 2.5f, -1.5f), lx_v3(1.0f, 0.0f, -0.5f), 40.0f,
                         LX_SHADOW_HARD);
    hard.inner_angle = hard.outer_angle = LX_DEG2RAD(25.0f);
    add_light(s, hard);
    lx_light haze = sun("blurred sun", lx_v3(-0.5f, -1.0f, -0.2f), 1.5f, LX_SHADOW_BLUR);
    haze.blur_power = 1.3f;
    haze.blur_multiplier = 4.0f;
    add_light(s, haze);
    s->ambient = lx_v3(0.01f, 0.01f, 0.02f);
    stats st = compare_scene(s, 64);
    assert_true(st.shadowed > 300);
    lx_scene_destroy(s);
}

/* A chart whose borders fall exactly on texel boundaries: the UV square
 * [0.25, 0.75]^2 at 32 texels spans texels 8..23 exactly. The texels just
 * outside (columns and rows 7 and 24) only touch the chart along a line or
 * at a corner, with no area in common: the chart does not cover them. The
 * reference covers 8..23 by their centres, and nothing else overlaps. */
static void test_touching_texels_not_covered(void **state)
{
    (void)state;
    lx_scene *s = new_scene("aligned chart");
    lx_mat4 id = lx_mat4_identity();
    lx_mesh m = lx_test_plane("chart", 2.0f, 0.0f, 0.0f, 0.0f, 2);
    for (uint32_t v = 0; v < m.vertex_count; v++)
        for (int k = 0; k < 2; k++)
            m.uv[k][v] = lx_v2(0.25f + 0.5f * m.uv[k][v].x, 0.25f + 0.5f * m.uv[k][v].y);
    uint32_t mi = add_mesh(s, &m);
    add_node(s, "chart", id, &mi, 1);
    lx_bake_desc d = {.resolution = 32, .padding = LX_PADDING_NONE};
    lx_baker *b;
    assert_int_equal(lx_baker_create(s, &d, &b), LX_OK);
    const uint8_t *mask = lx_baker_mask(b, 0);
    lx_ref_map ref;
    lx_ref_texel_map(s, 0, 32, 32, &ref);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            int want = x >= 8 && x <= 23 && y >= 8 && y <= 23;
            assert_int_equal(ref.texels[y * 32 + x].used, want);
            if (mask[y * 32 + x] != want)
                fail_msg("texel (%d, %d): mask %d, want %d (used_texels %u, want 256)", x, y,
                         mask[y * 32 + x], want, lx_baker_lightmap_info(b, 0)->used_texels);
        }
    assert_int_equal(lx_baker_lightmap_info(b, 0)->used_texels, 256);
    lx_ref_map_free(&ref);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane_box_occluder),
        cmocka_unit_test(test_transformed_nodes),
        cmocka_unit_test(test_multi_mesh_node),
        cmocka_unit_test(test_blur_shadows),
        cmocka_unit_test(test_classic_and_ranges),
        cmocka_unit_test(test_touching_texels_not_covered),
    };
    lx_test_watchdog(60);
    return cmocka_run_group_tests(tests, NULL, NULL);
}
