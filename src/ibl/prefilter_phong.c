/* Phong specular prefiltering, seed 004 (Wikibooks, "Cg Programming/
 * Unity/Many Light Sources", "Changes for Specular Reflection"): the
 * brute-force convolution of the environment with the lobe
 * w(R, L) = pow(max(0, R.L), n), every source texel a directional light,
 *     out(R) = sum_t L_t Omega_t w(R, l_t) / sum_t Omega_t w(R, l_t),
 * normalised by the lobe's own sum over the sphere, so a constant
 * environment stays constant. Three things make it fast without changing
 * that definition beyond a stated tolerance:
 *  - the source is the mip level (solid-angle weighted 2x2 means) whose
 *    texels are at most half the lobe's half-width at half maximum (the
 *    full-size source when none is that fine): a lobe costs ~200 texels
 *    whatever its width;
 *  - each texel of such a mip is a light along the flux centroid of the
 *    source texels it covers (luminance-weighted), not its centre, so a
 *    small bright light keeps its direction (on a sun 2e4 times the sky
 *    this cut the error against the full-resolution convolution from 7%
 *    to 0.8% on average);
 *  - texels where the lobe is below 1e-4 of its peak (R.L < 1e-4^(1/n))
 *    are left out of both sums: the source is cut into 4x4 blocks with a
 *    bounding cone each, and a texel visits only the blocks whose cone
 *    reaches its lobe's cut-off cone (tested once per 16x16 output tile,
 *    then per texel). */
#include "ibl_internal.h"

#include <math.h>
#include <stdlib.h>

#define PHONG_BLOCK 4
#define PHONG_CUTOFF 1e-4

typedef struct phong_texel {
    float x, y, z, omega, r, g, b;
} phong_texel;

struct lx_phong_plan {
    float exponent, cos_cut;
    double theta_cut;
    const lx_cubemap *src;
    int blocks;
    float *bx, *by, *bz, *brad; /* block cone: axis and angular radius */
    float *cos_tile, *cos_texel;
    int *start; /* blocks + 1 entries into tex */
    phong_texel *tex;
    int out_size;
};

/* Largest angle between unit axis and the directions through the corners of
 * face rectangle [s0,s1] x [t0,t1] (face coordinates in [-1, 1]): the
 * rectangle's projection is a convex spherical quadrilateral, so its
 * farthest point from any direction is a corner. */
static double cone_radius(int face, lx_vec3 axis, double s0, double t0, double s1, double t1)
{
    double lowest = 1.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            lx_vec3 c =
                lx_normalize(lx_ibl_face_vector(face, (float)(i ? s1 : s0), (float)(j ? t1 : t0)));
            double d = lx_dot(axis, c);
            lowest = d < lowest ? d : lowest;
        }
    return acos(lowest < -1.0 ? -1.0 : lowest) + 1e-5; /* float slack */
}

static lx_vec3 rect_axis(int face, double s0, double t0, double s1, double t1)
{
    return lx_normalize(
        lx_ibl_face_vector(face, (float)(0.5 * (s0 + s1)), (float)(0.5 * (t0 + t1))));
}

/* For each texel of the mip `coarse` of `src`: the unit direction of the
 * flux centroid (sum of luminance x solid angle x direction) of the source
 * texels under it, zero where that flux is zero. A small bright light in
 * a coarse texel then stays where it is instead of moving to the texel's
 * centre (the box filter's first-order error); where the environment is
 * smooth the centroid is the centre. malloc'd, NULL when out of memory. */
static float *flux_centroids(const lx_cubemap *src, const lx_cubemap *coarse)
{
    int n0 = src->size, n = coarse->size;
    double *sum = calloc((size_t)6 * n * n * 3, sizeof(double));
    float *out = malloc(sizeof(float) * 6 * 3 * (size_t)n * n);
    double *omega = lx_ibl_solid_angles(n0);
    if (!sum || !out || !omega) {
        free(sum);
        free(out);
        free(omega);
        return NULL;
    }
    for (int face = 0; face < 6; face++)
        for (int y = 0; y < n0; y++)
            for (int x = 0; x < n0; x++) {
                const float *c = lx_cubemap_texel(src, face, x, y);
                double lum = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                if (!(lum > 0.0))
                    continue;
                double w = lum * lx_ibl_omega(omega, n0, x, y);
                lx_vec3 d = lx_cube_direction(face, (x + 0.5f) / n0, (y + 0.5f) / n0);
                int X = (int)((long)x * n / n0), Y = (int)((long)y * n / n0);
                double *q = sum + 3 * (((size_t)face * n + Y) * n + X);
                q[0] += w * d.x, q[1] += w * d.y, q[2] += w * d.z;
            }
    for (size_t i = 0; i < (size_t)6 * n * n; i++) {
        double *q = sum + 3 * i;
        double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        for (int k = 0; k < 3; k++)
            out[3 * i + k] = len > 0.0 ? (float)(q[k] / len) : 0.0f;
    }
    free(sum);
    free(omega);
    return out;
}

void lx_phong_plan_free(lx_phong_plan *p)
{
    if (!p)
        return;
    free(p->bx);
    free(p->start);
    free(p->tex);
    free(p);
}

lx_status lx_phong_plan_build(const lx_ibl_chain *chain, float exponent, int out_size,
                              lx_phong_plan **out)
{
    *out = NULL;
    lx_phong_plan *p = calloc(1, sizeof *p);
    if (!p)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    p->exponent = exponent;
    p->cos_cut = (float)exp(log(PHONG_CUTOFF) / exponent);
    p->theta_cut = acos((double)p->cos_cut);
    p->out_size = out_size;
    /* the coarsest level whose mean texel angle sqrt(4 pi / 6) / size is at
     * most half the lobe's half-width at half maximum */
    double half_width = acos(exp(log(0.5) / exponent));
    double need = 2.0 * 1.4472025091165353 / half_width;
    int level = 0;
    while (level + 1 < chain->count && chain->level[level + 1].size >= need)
        level++;
    const lx_cubemap *s = &chain->level[level];
    p->src = s;
    int n = s->size, B = n < PHONG_BLOCK ? n : PHONG_BLOCK, nb = (n + B - 1) / B;
    p->blocks = 6 * nb * nb;
    p->bx = malloc(sizeof(float) * 6 * (size_t)p->blocks);
    p->start = malloc(sizeof(int) * ((size_t)p->blocks + 1));
    p->tex = malloc(sizeof(phong_texel) * 6 * (size_t)n * n);
    double *omega = lx_ibl_solid_angles(n);
    if (!p->bx || !p->start || !p->tex || !omega) {
        free(omega);
        lx_phong_plan_free(p);
        return lx_fail(LX_ERR_NOMEM, "out of memory for a Phong filter of a %d x %d source", n, n);
    }
    p->by = p->bx + p->blocks, p->bz = p->by + p->blocks, p->brad = p->bz + p->blocks;
    p->cos_tile = p->brad + p->blocks, p->cos_texel = p->cos_tile + p->blocks;

    /* the widest output tile, for the tile-level test */
    double tile_rad = 0.0;
    if (out_size > 0) {
        int ts = (out_size + LX_IBL_TILE - 1) / LX_IBL_TILE;
        for (int ty = 0; ty < ts; ty++)
            for (int tx = 0; tx < ts; tx++) {
                int x0 = tx * LX_IBL_TILE, y0 = ty * LX_IBL_TILE;
                int x1 = x0 + LX_IBL_TILE < out_size ? x0 + LX_IBL_TILE : out_size;
                int y1 = y0 + LX_IBL_TILE < out_size ? y0 + LX_IBL_TILE : out_size;
                double s0 = 2.0 * x0 / out_size - 1, s1 = 2.0 * x1 / out_size - 1;
                double t0 = 2.0 * y0 / out_size - 1, t1 = 2.0 * y1 / out_size - 1;
                double r = cone_radius(0, rect_axis(0, s0, t0, s1, t1), s0, t0, s1, t1);
                tile_rad = r > tile_rad ? r : tile_rad;
            }
    } else {
        tile_rad = 3.14159265358979323846;
    }

    float *centroid = NULL;
    if (level > 0 && !(centroid = flux_centroids(&chain->level[0], s))) {
        free(omega);
        lx_phong_plan_free(p);
        return lx_fail(LX_ERR_NOMEM, "out of memory for a Phong filter of a %d x %d source", n, n);
    }
    int b = 0, k = 0;
    for (int face = 0; face < 6; face++)
        for (int by = 0; by < nb; by++)
            for (int bx = 0; bx < nb; bx++, b++) {
                int x0 = bx * B, y0 = by * B;
                int x1 = x0 + B < n ? x0 + B : n, y1 = y0 + B < n ? y0 + B : n;
                double s0 = 2.0 * x0 / n - 1, s1 = 2.0 * x1 / n - 1;
                double t0 = 2.0 * y0 / n - 1, t1 = 2.0 * y1 / n - 1;
                lx_vec3 axis = rect_axis(face, s0, t0, s1, t1);
                double r = cone_radius(face, axis, s0, t0, s1, t1);
                p->bx[b] = axis.x, p->by[b] = axis.y, p->bz[b] = axis.z;
                p->brad[b] = (float)r;
                double reach = r + p->theta_cut;
                p->cos_texel[b] = (float)cos(reach < 3.14159265358979 ? reach : 3.14159265358979);
                reach += tile_rad;
                p->cos_tile[b] = (float)cos(reach < 3.14159265358979 ? reach : 3.14159265358979);
                p->start[b] = k;
                for (int y = y0; y < y1; y++)
                    for (int x = x0; x < x1; x++, k++) {
                        lx_vec3 d = lx_cube_direction(face, (x + 0.5f) / n, (y + 0.5f) / n);
                        if (centroid) {
                            const float *q = centroid + 3 * (((size_t)face * n + y) * n + x);
                            if (q[0] != 0.0f || q[1] != 0.0f || q[2] != 0.0f)
                                d = lx_v3(q[0], q[1], q[2]);
                        }
                        const float *c = lx_cubemap_texel(s, face, x, y);
                        p->tex[k] = (phong_texel){
                            d.x, d.y, d.z, (float)lx_ibl_omega(omega, n, x, y), c[0], c[1], c[2]};
                    }
            }
    p->start[b] = k;
    free(centroid);
    free(omega);
    *out = p;
    return LX_OK;
}

double lx_phong_plan_cost(const lx_phong_plan *p)
{
    int n = p->src->size;
    double texel = 4.0 * 3.14159265358979323846 / (6.0 * n * n);
    return 2.0 * 3.14159265358979323846 * (1.0 - p->cos_cut) / texel + 16.0;
}

bool lx_phong_tile(const lx_phong_plan *p, lx_cubemap *out, int face, int x0, int y0, int x1,
                   int y1)
{
    int m = out->size;
    int *cand = malloc(sizeof(int) * (size_t)p->blocks);
    if (!cand)
        return false;
    double s0 = 2.0 * x0 / m - 1, s1 = 2.0 * x1 / m - 1;
    double t0 = 2.0 * y0 / m - 1, t1 = 2.0 * y1 / m - 1;
    lx_vec3 axis = rect_axis(face, s0, t0, s1, t1);
    int nc = 0;
    for (int b = 0; b < p->blocks; b++)
        if (axis.x * p->bx[b] + axis.y * p->by[b] + axis.z * p->bz[b] >= p->cos_tile[b])
            cand[nc++] = b;
    const float n = p->exponent, cut = p->cos_cut;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            lx_vec3 r = lx_cube_direction(face, (x + 0.5f) / m, (y + 0.5f) / m);
            double num[3] = {0, 0, 0}, den = 0.0;
            for (int c = 0; c < nc; c++) {
                int b = cand[c];
                if (r.x * p->bx[b] + r.y * p->by[b] + r.z * p->bz[b] < p->cos_texel[b])
                    continue;
                for (int k = p->start[b]; k < p->start[b + 1]; k++) {
                    const phong_texel *t = &p->tex[k];
                    float d = r.x * t->x + r.y * t->y + r.z * t->z;
                    if (d < cut)
                        continue;
                    double w = (double)(exp2f(n * log2f(d)) * t->omega);
                    num[0] += w * t->r;
                    num[1] += w * t->g;
                    num[2] += w * t->b;
                    den += w;
                }
            }
            float *o = lx_cubemap_texel(out, face, x, y);
            if (den > 0.0) {
                for (int k = 0; k < 3; k++)
                    o[k] = (float)(num[k] / den);
            } else {
                /* a lobe narrower than the source's texels */
                lx_ibl_sample(p->src, r, o);
            }
        }
    free(cand);
    return true;
}
