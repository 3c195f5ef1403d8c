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
 * horizon: 1024 samples of D were 1-2% off at N.V < 0.1, as many visible
 * normals are within 0.05% everywhere. The samples are the N-point
 * Hammersley set mapped as Heitz does (a disk point, squeezed toward the
 * view), the same for every texel; sums in double. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The Hammersley points as Heitz's disk points: (r cos phi, r sin phi,
 * sqrt(1 - t1^2)) per sample. */
typedef struct dfg_job {
    int size, samples;
    const double *t1, *t2, *root;
    float *out;
} dfg_job;

static double lambda_ggx(double cos2, double a2)
{
    return 0.5 * (sqrt(1.0 + a2 * (1.0 - cos2) / cos2) - 1.0);
}

static bool dfg_row(void *ctx, int y)
{
    const dfg_job *j = ctx;
    int size = j->size, samples = j->samples;
    double r = (y + 0.5) / size, a = r * r, a2 = a * a;
    for (int x = 0; x < size; x++) {
        double nov = (x + 0.5) / size;
        /* V in the x-z plane, N = +z; the view stretched into the
         * hemisphere configuration (alpha = 1) */
        double vx = sqrt(1.0 - nov * nov), vz = nov;
        double hl = sqrt(a2 * vx * vx + vz * vz);
        double hx = a * vx / hl, hz = vz / hl; /* T1 = +y, T2 = (-hz, 0, hx) */
        double s = 0.5 * (1.0 + hz);
        double lv = lambda_ggx(vz * vz, a2);
        double sa = 0.0, sb = 0.0;
        for (int i = 0; i < samples; i++) {
            double t1 = j->t1[i];
            double t2 = (1.0 - s) * j->root[i] + s * j->t2[i];
            double nz = sqrt(fmax(0.0, 1.0 - t1 * t1 - t2 * t2));
            /* the normal in the stretched configuration, back to alpha */
            double mx = a * (nz * hx - t2 * hz), my = a * t1, mz = fmax(0.0, t2 * hx + nz * hz);
            double ml = sqrt(mx * mx + my * my + mz * mz);
            double vh = (vx * mx + vz * mz) / ml;
            double lz = 2.0 * vh * mz / ml - vz; /* (L = 2 (V.H) H - V).z */
            if (!(lz > 0.0) || !(vh > 0.0))
                continue;
            double w = (1.0 + lv) / (1.0 + lv + lambda_ggx(lz * lz, a2)); /* G2 / G1(V) */
            double f1 = 1.0 - vh, f2 = f1 * f1, fc = f2 * f2 * f1;
            sa += (1.0 - fc) * w;
            sb += fc * w;
        }
        float *o = j->out + 2 * ((size_t)y * size + x);
        o[0] = (float)(sa / samples);
        o[1] = (float)(sb / samples);
    }
    return true;
}

lx_status lx_dfg_lut(int size, int samples, const lx_ibl_desc *in, lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "DFG table: no output image (NULL)");
    memset(out, 0, sizeof *out);
    lx_ibl_desc desc = lx_ibl_desc_defaults(in);
    size = size ? size : 128;
    samples = samples ? samples : 1024;
    if (size < 1 || size > 4096)
        return lx_fail(LX_ERR_INVALID, "DFG table: size %d is outside 1..4096", size);
    if (samples < 1 || samples > 1 << 20)
        return lx_fail(LX_ERR_INVALID, "DFG table: %d samples per texel is outside 1..%d", samples,
                       1 << 20);
    lx_status st = lx_ibl_check_threads(desc.threads);
    if (st != LX_OK)
        return st;
    if ((st = lx_image_alloc(out, size, size, 2)) != LX_OK)
        return st;
    double *pts = malloc(sizeof(double) * 3 * (size_t)samples);
    if (!pts) {
        lx_image_free(out);
        return lx_fail(LX_ERR_NOMEM, "DFG table: out of memory");
    }
    dfg_job job = {size, samples, pts, pts + samples, pts + 2 * (size_t)samples, out->data};
    for (int i = 0; i < samples; i++) {
        float u, v;
        lx_ibl_hammersley((uint32_t)i, (uint32_t)samples, &u, &v);
        double r = sqrt((double)u), phi = 2.0 * 3.14159265358979323846 * v;
        pts[i] = r * cos(phi);
        pts[samples + i] = r * sin(phi);
        pts[2 * (size_t)samples + i] = sqrt(fmax(0.0, 1.0 - pts[i] * pts[i]));
    }
    lx_ibl_run run = lx_ibl_run_make(desc.threads, desc.progress, desc.progress_user);
    st = lx_ibl_for(&run, size, NULL, dfg_row, &job, "DFG table");
    free(pts);
    if (st != LX_OK)
        lx_image_free(out);
    return st;
}
