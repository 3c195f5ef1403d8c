/* GGX specular prefiltering for the split-sum approximation: B. Karis,
 * "Real Shading in Unreal Engine 4", SIGGRAPH 2013 course notes
 * (PrefilterEnvMap: N = V = R, light weighted by N.L). A level is what
 * Karis' estimator converges to, the convolution of the environment with
 *     w(l) = D(h) (n.l),  h = normalize(n + l),  alpha = roughness^2,
 * normalised by its own sum, computed one of two ways:
 *  - directly (prefilter_conv.c with lx_ggx_lobe): on the source mip whose
 *    texels are at most 1/3 of the lobe's half-width at half maximum, each
 *    texel a light at its flux centroid, nodes of texels at least 3 of
 *    their radii away (from every texel of a group of 4x4) taken as one
 *    light (GGX's tail falls as the inverse fourth power of the angle, so
 *    a sun lights the whole hemisphere through it), nothing past where D
 *    falls below 1e-8 of its peak. On bench_ibl's sky with a 2e4-nit sun
 *    every level of a 256^2 source is within 0.04-0.21% of the
 *    brute-force convolution on average (0.8% at worst), where importance
 *    sampling with 256 samples was 2-9% off (30-85% at worst, the sun seen
 *    through the samples' pattern), and it takes less time;
 *  - by importance sampling, where the direct convolution would cost more
 *    than desc.samples samples per texel (one sample takes as long as ~24
 *    lights of a group's list; the convolution's count is measured on its
 *    tree before its lights are made; with 256 samples no level of a
 *    chain up to 2048^2 is sampled, whose sharpest levels sum ~2000
 *    lights a texel):
 *    desc.samples Hammersley directions of the GGX distribution, with
 *    filtered importance sampling from M. Colbert and J. Krivanek,
 *    "GPU-Based Importance Sampling", GPU Gems 3 ch. 20: each sample reads
 *    the source mip level whose texels match the solid angle the sample
 *    stands for, lod = 0.5 log2(Omega_s / Omega_p) + 1, with
 *    Omega_s = 1 / (N pdf) and Omega_p = 4 pi / (6 size^2) of the source,
 *    so a bright small light is spread over the sample's share of the lobe
 *    instead of sparkling. The one-level bias (Filament's cmgen uses the
 *    same, K = 4) makes neighbouring samples' footprints overlap: without
 *    it a sun 2e4 times the sky leaves the 256-sample pattern as blotches
 *    in the mid-roughness levels; with it, smooth environments come out ~2x
 *    blurrier than the exact convolution (mean 0.3-1.3%, worst 1-6% on the
 *    tests' sky, against 0.1-0.3% and 0.4-1.6% without). Samples are the
 *    N-point Hammersley set, the same for every texel (deterministic, and
 *    the filter varies smoothly from texel to texel, turned by Karis'
 *    tangent frame); reads are trilinear between two levels of the
 *    solid-angle weighted mip chain and bilinear across face edges (the
 *    taps lx_cubemap_sample takes), so the levels have no seams. */
#include "ibl_internal.h"
#include "core/internal.h"

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

lx_status lx_ggx_plan_build(const int *chain_sizes, int chain_count, float roughness, int samples,
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
    int size0 = chain_sizes[0];
    double omega_p = 4.0 * 3.14159265358979323846 / (6.0 * size0 * size0);
    int top = chain_count - 1;
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

/* ---- direct convolution ----------------------------------------------------- */

/* The lobe's cut-off: where D falls below this fraction of its peak. The
 * tail beyond holds about sqrt(GGX_CUTOFF) of the lobe's weight. */
#define GGX_CUTOFF 1e-8
/* The source mip's mean texel angle is at most the lobe's half-width at
 * half maximum over this. */
#define GGX_TEXELS 3.0
/* Far field: a node of texels at least this many times its radius away is
 * one light. */
#define GGX_FAR 3.0
/* Lights a convolution sums in the time of one importance sample
 * (measured 23-26 on levels 1-4 of a 256^2 chain: ~1.1 ns a light, list
 * building included, against ~26 ns a sample). */
#define GGX_CONV_PER_SAMPLE 24.0

/* The lobe D(h) (n.l) / D(n) at angle theta between n = r and l. */
static double ggx_falloff(double a2, double theta)
{
    double c = cos(theta), q = 0.5 * (1.0 - c) + 0.5 * (1.0 + c) * a2;
    return c * a2 * a2 / (q * q);
}

lx_lobe lx_ggx_lobe(float roughness)
{
    double a2 = pow((double)roughness, 4.0);
    lx_lobe l = {.kind = LX_LOBE_GGX, .param = (float)a2, .texels = GGX_TEXELS, .far = GGX_FAR};
    /* D / D_peak = (a2 / q)^2 with q = 1 + n.h^2 (a2 - 1), n.h^2 = (1 + c) / 2:
     * the cut-off cosine solves q = a2 / sqrt(GGX_CUTOFF); past the horizon
     * (c <= 0) the lobe's n.l ends it */
    double k = a2 / sqrt(GGX_CUTOFF);
    double c = k >= 1.0 ? -1.0 : (1.0 + a2 - 2.0 * k) / (1.0 - a2);
    l.cos_cut = (float)(c > 0.0 ? c : 0.0);
    /* the half-width by bisection: the lobe falls monotonically to 0 at
     * theta = pi / 2 */
    double lo = 0.0, hi = 0.5 * 3.14159265358979323846;
    for (int i = 0; i < 60; i++) {
        double mid = 0.5 * (lo + hi);
        if (ggx_falloff(a2, mid) > 0.5)
            lo = mid;
        else
            hi = mid;
    }
    l.half_width = 0.5 * (lo + hi);
    return l;
}

lx_status lx_ggx_level_plan(const int *chain_sizes, int chain_count, float roughness, int samples,
                            int out_size, lx_conv_plan **conv, lx_ggx_plan **is, double *cost)
{
    *conv = NULL, *is = NULL;
    lx_lobe lobe = lx_ggx_lobe(roughness);
    lx_status st = lx_conv_plan_create(chain_sizes, chain_count, &lobe, out_size,
                                       GGX_CONV_PER_SAMPLE * samples, conv);
    if (st != LX_OK || *conv) {
        *cost = *conv ? lx_conv_plan_cost(*conv) / GGX_CONV_PER_SAMPLE : 0.0;
        return st;
    }
    st = lx_ggx_plan_build(chain_sizes, chain_count, roughness, samples, is);
    *cost = st == LX_OK ? lx_ggx_plan_cost(*is) : 0.0;
    return st;
}
