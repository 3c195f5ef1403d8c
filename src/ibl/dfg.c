/* The split-sum DFG table: B. Karis, "Real Shading in Unreal Engine 4",
 * SIGGRAPH 2013 course notes (IntegrateBRDF): for GGX, the specular
 * reflectance under uniform white light is F0 * A + B with
 *     A = integral of (1 - Fc) f cos,  B = integral of Fc f cos,
 * f = D G2 / (4 (N.V)(N.L)), Fc = (1 - V.H)^5 (Schlick). G2 is Smith's
 * height-correlated masking-shadowing 1 / (1 + Lambda(v) + Lambda(l)) with
 * Lambda = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2 (E. Heitz,
 * "Understanding the Masking-Shadowing Function in Microfacet-Based
 * BRDFs", JCGT 2014), alpha = roughness^2 (perceptual roughness, as in
 * glTF).
 *
 * The integrals are estimated by sampling the distribution of visible
 * normals (E. Heitz, "Sampling the GGX Distribution of Visible Normals",
 * JCGT 2018): with H drawn from D_V(H) = G1(V) (V.H)+ D(H) / (N.V) and L
 * its mirror of V, f cos / pdf(L) = G2 / G1(V), a weight in [0, 1] that
 * stays smooth at grazing views, where sampling D alone (Karis) weighs
 * samples by G (V.H) / ((N.H)(N.V)) and loses most of them below the
 * horizon. The samples are the points ((i + 1/2) / N, frac(i / phi)) of
 * the golden-ratio (Fibonacci) lattice of the unit square, mapped as
 * Heitz does (a disk point, squeezed toward the view), the same for every
 * texel; lanes sum in float, texels in double. Against a fine quadrature
 * over the hemisphere of light directions, 1024 such samples are within
 * 2e-4 of A and 3e-4 of B everywhere, N.V -> 0 included, where 1024
 * Hammersley samples of D (Karis) were 1-3% off in A, and Hammersley
 * points for the visible normals 4e-4 off in B. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The Hammersley points as Heitz's disk points: (r cos phi, r sin phi,
 * sqrt(1 - t1^2)) per sample. */
typedef struct dfg_job {
    int size, samples, padded;
    const float *t1, *t2, *root;
    float *out;
} dfg_job;

/* Four samples at a time (lx_v4f, in float): each lane sums 16 samples,
 * then the lanes go into double, in a fixed order. */
#define CHUNK 64
typedef lx_v4f v4f;

/* The view's constants: V = (vx, 0, vz), its stretched direction
 * (hx, 0, hz) (alpha = 1: T1 = +y, T2 = (-hz, 0, hx)), Heitz's s, and
 * 1 + Lambda(v) and 1/2 + Lambda(v). */
typedef struct dfg_view {
    float a, a2, vx, vz, hx, hz, s, g1, g0;
} dfg_view;

/* The weights of samples i..i+3: (1 - Fc) and Fc times G2 / G1(V), the
 * estimator's f cos / pdf, added to sa, sb. G2 / G1 = (1 + Lv) / (1 + Lv +
 * Ll) with Ll = (sqrt(lz^2 + a2 (1 - lz^2)) / lz - 1) / 2, written times
 * lz+ = max(lz, 0): below the horizon (lz <= 0, which V.H <= 0 implies)
 * the weight is 0 with no test, so the lanes vectorise (|lz| < N.V < 1
 * keeps 1 - lz^2 > 0 and the denominator positive). */
static inline void dfg_quad(const dfg_job *j, int i, const dfg_view *v, v4f *sa, v4f *sb)
{
    v4f t1 = lx_v4_load(j->t1 + i);
    v4f t2 = (1.0f - v->s) * lx_v4_load(j->root + i) + v->s * lx_v4_load(j->t2 + i);
    v4f nz = lx_v4_sqrt(lx_v4_pos(1.0f - t1 * t1 - t2 * t2));
    /* the normal in the stretched configuration, back to alpha */
    v4f mx = v->a * (nz * v->hx - t2 * v->hz), my = v->a * t1;
    v4f mz = lx_v4_pos(t2 * v->hx + nz * v->hz);
    v4f inv = 1.0f / lx_v4_sqrt(mx * mx + my * my + mz * mz);
    v4f vh = (v->vx * mx + v->vz * mz) * inv;
    v4f lz = 2.0f * vh * mz * inv - v->vz, lp = lx_v4_pos(lz);
    v4f root = lx_v4_sqrt(lp * lp + v->a2 * (1.0f - lz * lz));
    v4f w = v->g1 * lp / (v->g0 * lp + 0.5f * root);
    v4f f1 = 1.0f - vh, f2 = f1 * f1, fc = f2 * f2 * f1;
    *sa += (1.0f - fc) * w;
    *sb += fc * w;
}

static bool dfg_row(void *ctx, int y)
{
    const dfg_job *j = ctx;
    int size = j->size, samples = j->samples;
    double r = (y + 0.5) / size, a = r * r, a2 = a * a;
    for (int x = 0; x < size; x++) {
        double nov = (x + 0.5) / size;
        double vx = sqrt(1.0 - nov * nov), vz = nov;
        double hl = sqrt(a2 * vx * vx + vz * vz);
        double hx = a * vx / hl, hz = vz / hl;
        double lv = 0.5 * (sqrt(1.0 + a2 * (1.0 - vz * vz) / (vz * vz)) - 1.0);
        dfg_view v = {(float)a,
                      (float)a2,
                      (float)vx,
                      (float)vz,
                      (float)hx,
                      (float)hz,
                      (float)(0.5 * (1.0 + hz)),
                      (float)(1.0 + lv),
                      (float)(0.5 + lv)};
        double A = 0.0, B = 0.0;
        for (int c = 0; c < j->padded; c += CHUNK) {
            int end = c + CHUNK < j->padded ? c + CHUNK : j->padded;
            v4f sa = {0, 0, 0, 0}, sb = {0, 0, 0, 0};
            for (int i = c; i < end; i += 4)
                dfg_quad(j, i, &v, &sa, &sb);
            A += ((double)sa[0] + sa[1]) + ((double)sa[2] + sa[3]);
            B += ((double)sb[0] + sb[1]) + ((double)sb[2] + sb[3]);
        }
        float *o = j->out + 2 * ((size_t)y * size + x);
        o[0] = (float)(A / samples);
        o[1] = (float)(B / samples);
    }
    return true;
}

lx_status lx_dfg_lut(int size, int samples, const lx_ibl_desc *in, lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "DFG table: no output image (NULL)");
    memset(out, 0, sizeof *out);
    lx_ibl_desc desc = lx_ibl_desc_defaults(in);
    size = size ? size : LX_DFG_DEFAULT_SIZE;
    samples = samples ? samples : LX_DFG_DEFAULT_SAMPLES;
    if (size < 1 || size > LX_DFG_MAX_SIZE)
        return lx_fail(LX_ERR_INVALID, "DFG table: size %d is outside 1..%d", size,
                       LX_DFG_MAX_SIZE);
    if (samples < 1 || samples > LX_DFG_MAX_SAMPLES)
        return lx_fail(LX_ERR_INVALID, "DFG table: %d samples per texel is outside 1..%d", samples,
                       LX_DFG_MAX_SAMPLES);
    lx_status st = lx_ibl_check_threads(desc.threads);
    if (st != LX_OK)
        return st;
    if ((st = lx_image_alloc(out, size, size, 2)) != LX_OK)
        return st;
    /* padded with points of no weight: t1 = 0 and t2 = root = 1 give
     * V.H = 0, a mirror on the horizon */
    int padded = (samples + 3) / 4 * 4;
    float *pts = malloc(sizeof(float) * 3 * (size_t)padded);
    if (!pts) {
        lx_image_free(out);
        return lx_fail(LX_ERR_NOMEM, "DFG table: out of memory");
    }
    dfg_job job = {size, samples, padded, pts, pts + padded, pts + 2 * (size_t)padded, out->data};
    for (int i = 0; i < padded; i++) {
        double t1 = 0.0, t2 = 1.0, root = 1.0;
        if (i < samples) {
            /* the golden-ratio lattice: ((i + 1/2) / N, frac(i / phi)) */
            double u = (i + 0.5) / samples, v = fmod(i * 0.61803398874989484820, 1.0);
            double r = sqrt(u), phi = 2.0 * 3.14159265358979323846 * v;
            t1 = r * cos(phi), t2 = r * sin(phi);
            double q = 1.0 - t1 * t1;
            root = sqrt(q > 0.0 ? q : 0.0);
        }
        pts[i] = (float)t1, pts[padded + i] = (float)t2;
        pts[2 * (size_t)padded + i] = (float)root;
    }
    lx_ibl_run run = lx_ibl_run_make(desc.threads, desc.progress, desc.progress_user);
    st = lx_ibl_for(&run, size, NULL, dfg_row, &job, "DFG table");
    free(pts);
    if (st != LX_OK)
        lx_image_free(out);
    return st;
}
