/* GGX specular prefiltering for the split-sum approximation: B. Karis,
 * "Real Shading in Unreal Engine 4", SIGGRAPH 2013 course notes
 * (PrefilterEnvMap: GGX importance sampling with N = V = R, samples
 * weighted by N.L), with filtered importance sampling from M. Colbert and
 * J. Krivanek, "GPU-Based Importance Sampling", GPU Gems 3 ch. 20: each
 * sample reads the source mip level whose texels match the solid angle the
 * sample stands for, lod = 0.5 log2(Omega_s / Omega_p) + 1, with
 * Omega_s = 1 / (N pdf) and Omega_p = 4 pi / (6 size^2) of the source, so
 * a bright small light is spread over the sample's share of the lobe
 * instead of sparkling. The one-level bias (Filament's cmgen uses the
 * same, K = 4) makes neighbouring samples' footprints overlap: without it
 * a sun 2e4 times the sky leaves the 256-sample pattern as blotches in the
 * mid-roughness levels; with it, smooth environments come out ~2x blurrier
 * than the exact convolution (mean 0.3-1.3%, worst 1-6% on the tests'
 * sky, against 0.1-0.3% and 0.4-1.6% without). Samples are the N-point
 * Hammersley set, the same for every texel (deterministic, and the filter
 * varies smoothly from texel to texel, turned by Karis' tangent frame);
 * reads are trilinear between two levels of the solid-angle weighted mip
 * chain and bilinear across face edges (the taps lx_cubemap_sample takes),
 * so the levels have no seams. */
#include "ibl_internal.h"

#include <math.h>
#include <stdlib.h>

typedef struct ggx_sample {
    float x, y, z; /* L in the frame of N (z along N) */
    float weight;  /* N.L */
    int level;     /* lower mip level to read */
    float frac;    /* blend toward level + 1 */
} ggx_sample;

struct lx_ggx_plan {
    int count;
    double weight_sum;
    ggx_sample *s;
};

lx_status lx_ggx_plan_build(const lx_ibl_chain *chain, float roughness, int samples,
                            lx_ggx_plan **out)
{
    *out = NULL;
    lx_ggx_plan *p = calloc(1, sizeof *p);
    ggx_sample *s = malloc(sizeof(ggx_sample) * (size_t)samples);
    if (!p || !s) {
        free(p);
        free(s);
        return lx_fail(LX_ERR_NOMEM, "out of memory for %d GGX samples", samples);
    }
    p->s = s;
    double a = (double)roughness * roughness, a2 = a * a;
    int size0 = chain->level[0].size;
    double omega_p = 4.0 * 3.14159265358979323846 / (6.0 * size0 * size0);
    int top = chain->count - 1;
    for (int i = 0; i < samples; i++) {
        float u, v;
        lx_ibl_hammersley((uint32_t)i, (uint32_t)samples, &u, &v);
        /* GGX half-vector: cos^2 theta_h = (1 - u) / (1 + (a^2 - 1) u) */
        double c2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u);
        double ch = sqrt(c2), sh = sqrt(1.0 - c2);
        double phi = 2.0 * 3.14159265358979323846 * v;
        /* L = 2 (V.H) H - V with V = N = (0, 0, 1) */
        double lz = 2.0 * c2 - 1.0;
        if (!(lz > 0.0))
            continue;
        ggx_sample *o = &s[p->count++];
        o->x = (float)(2.0 * ch * sh * cos(phi));
        o->y = (float)(2.0 * ch * sh * sin(phi));
        o->z = (float)lz;
        o->weight = (float)lz;
        p->weight_sum += o->weight;
        /* pdf of L: D(h) (N.H) / (4 V.H) = D / 4 when N = V */
        double dd = (a2 - 1.0) * c2 + 1.0;
        double pdf = a2 / (3.14159265358979323846 * dd * dd) / 4.0;
        double omega_s = 1.0 / ((double)samples * pdf);
        double lod = 0.5 * log2(omega_s / omega_p) + 1.0;
        lod = lod < 0.0 ? 0.0 : lod > top ? top : lod;
        o->level = (int)lod;
        o->frac = (float)(lod - o->level);
        if (o->level >= top)
            o->level = top, o->frac = 0.0f;
    }
    if (p->count == 0) {
        /* too few samples to land one above the horizon: the mirror ray */
        s[0] = (ggx_sample){0.0f, 0.0f, 1.0f, 1.0f, 0, 0.0f};
        p->count = 1;
        p->weight_sum = 1.0;
    }
    *out = p;
    return LX_OK;
}

double lx_ggx_plan_cost(const lx_ggx_plan *p)
{
    return (double)p->count + 1.0;
}

void lx_ggx_plan_free(lx_ggx_plan *p)
{
    if (!p)
        return;
    free(p->s);
    free(p);
}

void lx_ggx_tile(const lx_ggx_plan *p, const lx_ibl_padded *pads, lx_cubemap *out, int face, int x0,
                 int y0, int x1, int y1)
{
    int m = out->size;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            lx_vec3 n = lx_cube_direction(face, (x + 0.5f) / m, (y + 0.5f) / m);
            lx_vec3 t, b;
            lx_ibl_frame(n, &t, &b);
            double sum[3] = {0, 0, 0};
            for (int i = 0; i < p->count; i++) {
                const ggx_sample *s = &p->s[i];
                lx_vec3 d = lx_v3(t.x * s->x + b.x * s->y + n.x * s->z,
                                  t.y * s->x + b.y * s->y + n.y * s->z,
                                  t.z * s->x + b.z * s->y + n.z * s->z);
                int f;
                float u, v, c[3];
                lx_ibl_face_st(d, &f, &u, &v);
                lx_ibl_padded_bilinear(&pads[s->level], f, u, v, c);
                if (s->frac > 0.0f) {
                    float c1[3];
                    lx_ibl_padded_bilinear(&pads[s->level + 1], f, u, v, c1);
                    for (int k = 0; k < 3; k++)
                        c[k] += (c1[k] - c[k]) * s->frac;
                }
                for (int k = 0; k < 3; k++)
                    sum[k] += (double)(s->weight * c[k]);
            }
            float *o = lx_cubemap_texel(out, face, x, y);
            for (int k = 0; k < 3; k++)
                o[k] = (float)(sum[k] / p->weight_sum);
        }
}
