/* The test oracle: the per-texel lighting document's brute-force lighting,
 * written independently of src/bake, src/trace and src/light so the fast
 * path (rasterized texel maps, Embree, the light model) can be checked
 * against it.
 *
 * - Texel map: for every texel, every triangle of the node's meshes is
 *   searched (mesh order, then triangle order) for the first whose UV
 *   triangle contains the texel centre ((x+0.5)/W, (y+0.5)/H) with
 *   barycentrics >= 0; the same barycentrics on the world triangle give the
 *   texel's position and interpolated normal (the document's UvToWorld kernel).
 *   Lightmap UVs are TEXCOORD_1 when the mesh has them, else TEXCOORD_0.
 *   Normal maps are not applied (the reference scenes have none).
 * - Rays: Moller-Trumbore in double precision against EVERY triangle of
 *   EVERY node in world space, both faces (the document's shadow loop).
 * - Lighting: for every light, the light model evaluated from its formulas
 *   in double (luxel/light.h: Filament's inverse square law with the
 *   smooth range window (1 - (d/r)^4)^2 and the 1e-4 m^2 floor, the spot's
 *   smooth cone t^2 or a hard cone when inner == outer, N.L; the classic
 *   ((1 - d/range) N.L)^2 I, (N.L)^2 I for a directional light; ambient
 *   times the range window, everywhere for a directional light; the blur
 *   shadow clamp((d_occluder / d_light)^power * multiplier, 0, 1), the
 *   scene's diagonal standing in for a directional light's distance), and,
 *   unless the light's shadow mode is NONE,
 *   a shadow ray toward the light whose origin is offset along the
 *   geometric normal (on the light's side) by
 *     bias = 1e-5 * scene bounding-box diagonal + 4e-6 * max|p| component,
 *   tmax = distance - 2 * bias (the rule of src/bake/direct.c, so results
 *   compare); plus the light's ambient and the scene ambient.
 *
 * Everything is slow and simple on purpose. Near-ties (a ray passing within
 * a relative edge_eps of a triangle edge, a texel centre on an edge) are
 * reported as ambiguous so tests can skip them instead of guessing.
 */
#ifndef LX_TEST_REFERENCE_H
#define LX_TEST_REFERENCE_H

#include "luxel/luxel.h"

/* A triangle in world space (double), with where it came from. */
typedef struct lx_ref_triangle {
    double p[3][3];
    uint32_t node, mesh, triangle;
} lx_ref_triangle;

/* Every triangle of every node of scene, transformed by the node's world
 * matrix, in node / mesh / triangle order. */
typedef struct lx_ref_scene {
    lx_ref_triangle *tris;
    uint32_t count;
    double lo[3], hi[3]; /* world bounds */
    float diagonal;      /* |hi - lo|, 1 when empty */
} lx_ref_scene;

void lx_ref_scene_build(const lx_scene *scene, lx_ref_scene *out);
void lx_ref_scene_free(lx_ref_scene *rs);

/* Moller-Trumbore (double, no culling). Fills t, u (weight of vertex 1),
 * v (weight of vertex 2) of the ray's intersection with the triangle's
 * plane and returns true when t is in [tmin, tmax] and u, v, 1-u-v >= 0.
 * *margin (may be NULL) is min(u, v, 1-u-v) of the plane hit (negative when
 * outside), or -INFINITY when the ray is parallel to the plane. */
bool lx_ref_intersect(const lx_ref_triangle *tri, const double o[3], const double d[3], double tmin,
                      double tmax, double *t, double *u, double *v, double *margin);

typedef struct lx_ref_hit {
    double t, u, v;
    uint32_t node, mesh, triangle;
} lx_ref_hit;

/* Nearest hit over all triangles of rs within [tmin, tmax]; false if none.
 * *ambiguous (may be NULL) is set when some triangle's plane is crossed
 * within [tmin, tmax] with a barycentric margin within +-edge_eps, when a
 * triangle is hit within 1e-6 (relative to max(1, |tmax|)) of tmin or tmax,
 * or when the two nearest hits are that close in t: the answer then
 * depends on rounding. */
bool lx_ref_closest(const lx_ref_scene *rs, lx_vec3 origin, lx_vec3 dir, double tmin, double tmax,
                    double edge_eps, lx_ref_hit *hit, bool *ambiguous);

/* Any hit within [tmin, tmax]; *ambiguous as for lx_ref_closest (but only
 * edge and range-end near misses count). */
bool lx_ref_occluded(const lx_ref_scene *rs, lx_vec3 origin, lx_vec3 dir, double tmin, double tmax,
                     double edge_eps, bool *ambiguous);

/* One texel of the reference texel map. */
typedef struct lx_ref_texel {
    bool used;
    uint32_t mesh;            /* scene mesh index */
    uint32_t triangle;        /* in that mesh */
    double bary[3];           /* weights of the triangle's vertices 0, 1, 2 */
    double margin;            /* min(bary): how far inside the centre is */
    lx_vec3 position;         /* world */
    lx_vec3 normal;           /* world, interpolated vertex normals, unit */
    lx_vec3 geometric_normal; /* world, unit (normal matrix x object face normal) */
} lx_ref_texel;

typedef struct lx_ref_map {
    uint32_t node;
    int width, height;
    lx_ref_texel *texels; /* width * height, row 0 at the top */
} lx_ref_map;

/* The document's every-texel-times-every-triangle UV -> world map of node. */
void lx_ref_texel_map(const lx_scene *scene, uint32_t node, int width, int height, lx_ref_map *out);
void lx_ref_map_free(lx_ref_map *map);

/* The UV set a mesh's lightmap uses (1 when TEXCOORD_1 exists, else 0;
 * -1 when it has none). */
int lx_ref_uv_set(const lx_mesh *mesh);

/* Barycentrics (w0, w1, w2) of (px, py) in UV triangle abc (double);
 * false when the UV triangle is degenerate. */
bool lx_ref_uv_barycentric(lx_vec2 a, lx_vec2 b, lx_vec2 c, double px, double py, double w[3]);

/* True for the lights the oracle evaluates: point, spot and directional
 * lights without a photometric profile. */
bool lx_ref_light_supported(const lx_light *light);

/* Light arriving at a surface point: sum over lights of ambient + shadowed
 * direct light (see the header comment), plus `ambient`. Every light must
 * be one lx_ref_light_supported accepts (the process aborts naming it
 * otherwise). n is the shading
 * normal, ng the geometric normal (either sign). *ambiguous (may be NULL)
 * is set when a shadow ray was ambiguous in the sense of lx_ref_occluded
 * with edge_eps. */
lx_vec3 lx_ref_shade(const lx_ref_scene *rs, const lx_light *lights, uint32_t light_count,
                     lx_vec3 ambient, lx_vec3 p, lx_vec3 n, lx_vec3 ng, double edge_eps,
                     bool *ambiguous);

/* lx_ref_shade, and in *scale (may be NULL) the sum over lights of what
 * reaches p without N.L and without the distance falloff (physical:
 * I spot / max(d^2, 1e-4), classic: I spot, directional: I; times colour)
 * plus the ambients: the size of the terms whose float rounding the baked
 * value carries, for comparisons at grazing light or a range's edge. */
lx_vec3 lx_ref_shade_scale(const lx_ref_scene *rs, const lx_light *lights, uint32_t light_count,
                           lx_vec3 ambient, lx_vec3 p, lx_vec3 n, lx_vec3 ng, double edge_eps,
                           bool *ambiguous, lx_vec3 *scale);

/* Shadow-ray bias for point p in rs (the rule of src/bake/direct.c). */
float lx_ref_bias(const lx_ref_scene *rs, lx_vec3 p);

/* Illuminance at a point from a Lambertian rectangle of luminance L in a
 * plane parallel to the receiving surface, at height h > 0 above it along
 * the receiver's normal: the rectangle spans [a0, a1] x [b0, b1] in that
 * plane's coordinates, measured from the point's foot (the point moved h
 * along its normal). E = pi L F, F by superposition of the form-factor
 * catalogue's corner case (a receiver parallel to an a x b rectangle at
 * distance c, below one of its corners:
 *   F = 1/(2 pi) (X/sqrt(1+X^2) atan(Y/sqrt(1+X^2))
 *                 + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))),  X = a/c, Y = b/c,
 * odd in X and in Y, so the four corners add with signs wherever the foot
 * is). In double; not Lambert's edge sum, which src/light/area.c uses. */
double lx_ref_rect_parallel_illuminance(double a0, double a1, double b0, double b1, double h,
                                        double luminance);

/* Double-precision vector helpers the oracle uses, for tests that need
 * the same arithmetic outside the library. */
double lx_ref_dot(const double a[3], const double b[3]);
void lx_ref_cross(const double a[3], const double b[3], double r[3]);
void lx_ref_normalize(double a[3]); /* leaves a zero vector as it is */

#endif
