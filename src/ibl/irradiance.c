/* Brute-force diffuse irradiance after Wikibooks' "Cg Programming/
 * Unity/Many Light Sources", computeFilteredCubemap: every texel of the
 * source cube map is a directional light and the irradiance of a normal is
 * the sum of them all, weighted by the cosine. Differences from the seed,
 * all toward the exact integral E(n) = sum over texels of
 * L * integral over the texel of max(0, n.w) dw:
 *  - each texel is weighted by its exact solid angle (the seed uses none);
 *  - a texel wholly above the horizon of n contributes L (n . Phi), where
 *    Phi = integral of w dw over the texel is its irradiance vector, exact
 *    from Lambert's formula for a spherical polygon, 1/2 sum_e theta_e u_e
 *    (J. Arvo, "Applications of Irradiance Tensors...", SIGGRAPH 1995);
 *  - a texel the horizon cuts is split into k x k sub-texels, each a
 *    directional light at its centre with its exact solid angle (k brings
 *    the split grid to 128 per face side, at most 32).
 * A constant environment L then gives pi L to ~2e-5 from a 32^2 source.
 * The source is first downsampled (solid-angle weighted 2x2) to at most
 * source_size per side, so a 512^2 input stays practical. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct lights {
    int count, sub;           /* texels, sub-texels per texel (k * k) */
    int padded;               /* count to a multiple of 4, lights of nothing after it */
    float *cx, *cy, *cz;      /* centre direction */
    float *px, *py, *pz;      /* irradiance vector Phi */
    float *horizon;           /* sin of the texel's angular radius */
    float *r, *g, *b;         /* radiance */
    float *sx, *sy, *sz, *sw; /* sub-texel directions and solid angles, sub per texel */
} lights;

static void lights_free(lights *l)
{
    free(l->cx);
    free(l->sx);
    memset(l, 0, sizeof *l);
}

static lx_vec3 unit_corner(int face, int n, double x, double y)
{
    return lx_normalize(
        lx_ibl_face_vector(face, (float)(2.0 * x / n - 1.0), (float)(2.0 * y / n - 1.0)));
}

/* Phi of face texel (x, y): Lambert's formula over its four edges. */
static void irradiance_vector(int face, int n, int x, int y, lx_vec3 centre, double phi[3])
{
    double v[4][3];
    const int cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};
    for (int k = 0; k < 4; k++) {
        /* corner directions in double: the edges of small texels are short */
        double sc = 2.0 * (x + cx[k]) / n - 1.0, tc = 2.0 * (y + cy[k]) / n - 1.0;
        double a[3];
        lx_ibl_face_vector_d(face, sc, tc, a);
        double len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        for (int c = 0; c < 3; c++)
            v[k][c] = a[c] / len;
    }
    phi[0] = phi[1] = phi[2] = 0.0;
    for (int e = 0; e < 4; e++) {
        const double *a = v[e], *b = v[(e + 1) & 3];
        double w[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                       a[0] * b[1] - a[1] * b[0]};
        double s = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        double theta = atan2(s, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
        for (int c = 0; c < 3; c++)
            phi[c] += 0.5 * theta * w[c] / s;
    }
    /* the corner order's orientation decides the sign: Phi points outward */
    if (phi[0] * centre.x + phi[1] * centre.y + phi[2] * centre.z < 0.0)
        for (int c = 0; c < 3; c++)
            phi[c] = -phi[c];
}

static lx_status lights_build(const lx_cubemap *s, lights *l)
{
    memset(l, 0, sizeof *l);
    int n = s->size;
    int k = n >= 128 ? 1 : 128 / n;
    k = k > 32 ? 32 : k;
    size_t count = (size_t)6 * n * n, sub = (size_t)k * k, padded = (count + 3) / 4 * 4;
    l->count = (int)count;
    l->padded = (int)padded;
    l->sub = (int)sub;
    l->cx = calloc(padded * 10, sizeof(float));
    l->sx = malloc(sizeof(float) * count * sub * 4);
    double *omega = lx_ibl_solid_angles(n * k);
    if (!l->cx || !l->sx || !omega) {
        free(omega);
        lights_free(l);
        return lx_fail(LX_ERR_NOMEM, "out of memory for %zu source texels", count);
    }
    l->cy = l->cx + padded, l->cz = l->cy + padded;
    l->px = l->cz + padded, l->py = l->px + padded, l->pz = l->py + padded;
    l->horizon = l->pz + padded;
    l->r = l->horizon + padded, l->g = l->r + padded, l->b = l->g + padded;
    l->sy = l->sx + count * sub, l->sz = l->sy + count * sub, l->sw = l->sz + count * sub;
    for (int face = 0; face < 6; face++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                size_t t = ((size_t)face * n + y) * n + x;
                lx_vec3 c = unit_corner(face, n, x + 0.5, y + 0.5);
                double phi[3];
                irradiance_vector(face, n, x, y, c, phi);
                float lowest = 1.0f; /* cos of the angular radius */
                for (int j = 0; j < 2; j++)
                    for (int i = 0; i < 2; i++) {
                        float cc = lx_dot(c, unit_corner(face, n, x + i, y + j));
                        lowest = cc < lowest ? cc : lowest;
                    }
                lowest = lx_clampf(lowest, -1.0f, 1.0f);
                const float *p = lx_cubemap_texel(s, face, x, y);
                l->cx[t] = c.x, l->cy[t] = c.y, l->cz[t] = c.z;
                l->px[t] = (float)phi[0], l->py[t] = (float)phi[1], l->pz[t] = (float)phi[2];
                /* sin(radius), rounded up a little so float error cannot
                 * call a cut texel whole */
                l->horizon[t] = sqrtf(1.0f - lowest * lowest) * 1.0001f + 1e-6f;
                l->r[t] = p[0], l->g[t] = p[1], l->b[t] = p[2];
                for (int j = 0; j < k; j++)
                    for (int i = 0; i < k; i++) {
                        size_t u = t * sub + (size_t)j * k + i;
                        int X = x * k + i, Y = y * k + j;
                        lx_vec3 d = unit_corner(face, n * k, X + 0.5, Y + 0.5);
                        l->sx[u] = d.x, l->sy[u] = d.y, l->sz[u] = d.z;
                        l->sw[u] = (float)lx_ibl_omega(omega, n * k, X, Y);
                    }
            }
    free(omega);
    return LX_OK;
}

/* The irradiance at unit normal nrm: the texels wholly above its horizon
 * four at a time (lx_v4f lanes summed in float over 64 texels, then in
 * double), and those the horizon cuts (cut: room for every texel's index)
 * one by one, from their sub-texels. */
static void irradiance_at(const lights *l, lx_vec3 nrm, int *cut, float out[3])
{
    double e[3] = {0, 0, 0};
    int ncut = 0;
    for (int t0 = 0; t0 < l->padded; t0 += 64) {
        int t1 = t0 + 64 < l->padded ? t0 + 64 : l->padded;
        lx_v4f sum[3] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}};
        for (int t = t0; t < t1; t += 4) {
            lx_v4f c = nrm.x * lx_v4_load(l->cx + t) + nrm.y * lx_v4_load(l->cy + t) +
                       nrm.z * lx_v4_load(l->cz + t);
            lx_v4f h = lx_v4_load(l->horizon + t);
            lx_v4i whole = c >= h, part = (c > -h) & ~whole;
            lx_v4f w = nrm.x * lx_v4_load(l->px + t) + nrm.y * lx_v4_load(l->py + t) +
                       nrm.z * lx_v4_load(l->pz + t);
            lx_v4f zero = {0, 0, 0, 0};
            w = lx_v4_select(whole, w, zero);
            sum[0] += w * lx_v4_load(l->r + t);
            sum[1] += w * lx_v4_load(l->g + t);
            sum[2] += w * lx_v4_load(l->b + t);
            if (part[0] | part[1] | part[2] | part[3])
                for (int k = 0; k < 4; k++)
                    if (part[k])
                        cut[ncut++] = t + k;
        }
        for (int k = 0; k < 3; k++)
            e[k] += ((double)sum[k][0] + sum[k][1]) + ((double)sum[k][2] + sum[k][3]);
    }
    for (int i = 0; i < ncut; i++) {
        int t = cut[i];
        double w = 0.0;
        size_t u0 = (size_t)t * l->sub;
        int s = 0;
        if (l->sub % 4 == 0) {
            /* the sub-texels four at a time, max(cos, 0) x solid angle */
            lx_v4f sum = {0, 0, 0, 0};
            for (; s < l->sub; s += 4) {
                size_t u = u0 + s;
                lx_v4f cs = nrm.x * lx_v4_load(l->sx + u) + nrm.y * lx_v4_load(l->sy + u) +
                            nrm.z * lx_v4_load(l->sz + u);
                sum += lx_v4_pos(cs) * lx_v4_load(l->sw + u);
            }
            w = ((double)sum[0] + sum[1]) + ((double)sum[2] + sum[3]);
        }
        for (; s < l->sub; s++) {
            size_t u = u0 + s;
            float cs = nrm.x * l->sx[u] + nrm.y * l->sy[u] + nrm.z * l->sz[u];
            if (cs > 0.0f)
                w += (double)(cs * l->sw[u]);
        }
        e[0] += w * l->r[t];
        e[1] += w * l->g[t];
        e[2] += w * l->b[t];
    }
    for (int k = 0; k < 3; k++)
        out[k] = (float)e[k];
}

typedef struct irr_job {
    const lights *l;
    lx_cubemap *out;
    int tiles_side;
} irr_job;

static bool irr_tile(void *ctx, int tile)
{
    const irr_job *j = ctx;
    int *cut = malloc(sizeof(int) * (size_t)j->l->padded);
    if (!cut)
        return false;
    int size = j->out->size, ts = j->tiles_side;
    int face = tile / (ts * ts), rest = tile % (ts * ts);
    int x0 = (rest % ts) * LX_IBL_TILE, y0 = (rest / ts) * LX_IBL_TILE;
    int x1 = x0 + LX_IBL_TILE < size ? x0 + LX_IBL_TILE : size;
    int y1 = y0 + LX_IBL_TILE < size ? y0 + LX_IBL_TILE : size;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            lx_vec3 nrm = lx_cube_direction(face, (x + 0.5f) / size, (y + 0.5f) / size);
            irradiance_at(j->l, nrm, cut, lx_cubemap_texel(j->out, face, x, y));
        }
    free(cut);
    return true;
}

lx_status lx_irradiance_brute(const lx_cubemap *src, int size, int source_size,
                              const lx_ibl_desc *in, lx_cubemap *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "irradiance: no output cube map (NULL)");
    memset(out, 0, sizeof *out);
    lx_ibl_desc desc = lx_ibl_desc_defaults(in);
    size = size ? size : LX_IRRADIANCE_DEFAULT_SIZE;
    source_size = source_size ? source_size : LX_IRRADIANCE_DEFAULT_SIZE;
    if (size < 1 || size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "irradiance: face size %d is outside 1..%d", size,
                       LX_MAX_CUBE_SIZE);
    if (source_size < 1 || source_size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "irradiance: source size %d is outside 1..%d", source_size,
                       LX_MAX_CUBE_SIZE);
    lx_status st = lx_ibl_check_threads(desc.threads);
    if (st != LX_OK)
        return st;
    if ((st = lx_ibl_check_cubemap(src, "irradiance: source cube map", true)) != LX_OK)
        return st;
    lx_ibl_run run = lx_ibl_run_make(desc.threads, desc.progress, desc.progress_user);

    /* the source, halved until it fits source_size, in one pass; then the
     * lights (10 floats a texel, 4 per sub-texel) and the output */
    int n = lx_ibl_halved_size(src->size, source_size);
    int k = n >= 128 ? 1 : 128 / n;
    k = k > 32 ? 32 : k;
    uint64_t need = (n < src->size ? lx_ibl_cube_bytes(n) : 0) +
                    (uint64_t)6 * n * n * (40 + 16 * (uint64_t)k * k) +
                    8ull * (uint64_t)(n * k + 1) * (n * k + 1) / 4 + lx_ibl_cube_bytes(size);
    char what[160];
    snprintf(what, sizeof what, "irradiance of a %d x %d cube map from a %d x %d source", size,
             size, n, n);
    if ((st = lx_check_memory(need, what)) != LX_OK)
        return st;
    lx_cubemap small = *src;
    bool owned = false;
    if (n < src->size) {
        lx_ibl_run part = lx_ibl_run_part(&run, 0.0, 0.1);
        if ((st = lx_ibl_downsample(src, n, &part, &small)) != LX_OK)
            return st;
        owned = true;
    }
    lights l;
    st = lights_build(&small, &l);
    if (owned)
        lx_cubemap_free(&small);
    if (st != LX_OK)
        return st;
    if ((st = lx_cubemap_alloc(out, size)) != LX_OK) {
        lights_free(&l);
        return st;
    }
    int tiles_side = (size + LX_IBL_TILE - 1) / LX_IBL_TILE;
    irr_job job = {&l, out, tiles_side};
    lx_ibl_run part = lx_ibl_run_part(&run, owned ? 0.1 : 0.0, 1.0);
    st = lx_ibl_for(&part, 6 * tiles_side * tiles_side, NULL, irr_tile, &job, "irradiance");
    lights_free(&l);
    if (st != LX_OK)
        lx_cubemap_free(out);
    return st;
}
