/* An independent check of lightmap UVs, written for the tests from the
 * definitions (it calls nothing of luxel's but the inline math): texels a
 * triangle covers (positive-area overlap with the texel's square), charts
 * found again from the UVs (triangles that share a UV point), overlaps
 * between charts, the padding between them, flipped triangles, and the
 * angle distortion of every triangle against its 3D shape. Also
 * generated meshes for the unwrapper's tests and benchmark. */
#ifndef LX_TEST_UV_ORACLE_H
#define LX_TEST_UV_ORACLE_H

#include "luxel/luxel.h"

/* One triangle on a page: its corners in space and in page UV. */
typedef struct lx_uv_triangle {
    double p[3][3];
    double uv[3][2];
} lx_uv_triangle;

typedef struct lx_uv_report {
    uint32_t charts;   /* groups of triangles joined by shared UV points */
    uint32_t flipped;  /* triangles with a negative or zero UV area */
    uint32_t outside;  /* triangles with a corner outside [0,1]^2 */
    uint64_t covered;  /* texels some triangle overlaps */
    uint64_t overlap;  /* texels two charts overlap */
    uint64_t crowded;  /* texels within `padding` rings of two charts */
    double area_uv;    /* summed UV area in texels */
    double area_3d;    /* summed surface area */
    double angle_mean; /* area-weighted mean |UV angle - 3D angle|, radians */
    double angle_max;  /* the largest, over triangles above 1 texel */
} lx_uv_report;

/* Checks n triangles on a width x height page; padding is the rings each
 * chart should own. */
void lx_uv_check(const lx_uv_triangle *tris, uint32_t n, int width, int height, int padding,
                 lx_uv_report *out);

/* Does triangle uv (texel units) overlap texel (x, y) with a positive
 * area? Separating axes, in double. */
bool lx_uv_overlaps_texel(const double uv[3][2], int x, int y);

/* The area of triangle uv (texel units) inside texel (x, y), 0..1: the
 * triangle clipped by the texel's four sides (Sutherland-Hodgman). */
double lx_uv_texel_coverage(const double uv[3][2], int x, int y);

/* Texels of a width x height grid (uv in texel units, n triangles, every
 * one with a nonzero area) some triangle overlaps with a positive area
 * (*covered), and those where two triangles share more than min_area
 * texels of area (returned): every texel against every pair of
 * triangles, the texel clipped by each triangle's three sides. */
uint64_t lx_uv_pair_overlaps(const double (*uv)[3][2], uint32_t n, int width, int height,
                             double min_area, uint64_t *covered);

/* Generated meshes (indexed, with normals; no UVs): a torus of radii R, r
 * with about `triangles` triangles; a closed cylinder (radius, height) with
 * caps; a bumpy height field of side `size`. */
lx_mesh lx_test_torus(const char *name, double R, double r, uint32_t triangles);
lx_mesh lx_test_cylinder(const char *name, double radius, double height, uint32_t triangles);
lx_mesh lx_test_terrain(const char *name, double size, uint32_t triangles);

#endif
