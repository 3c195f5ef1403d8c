/* The split-sum DFG table: B. Karis, "Real Shading in Unreal Engine 4",
 * SIGGRAPH 2013 course notes (IntegrateBRDF): for GGX, the specular
 * reflectance under uniform white light is F0 * A + B with
 *     A = integral of (1 - Fc) f / F cos,  B = integral of Fc f / F cos,
 * Fc = (1 - V.H)^5 (Schlick), estimated by importance sampling the GGX
 * normal distribution (N-point Hammersley set, the same for every texel):
 * each sample weighs G (V.H) / ((N.H)(N.V)). G is Smith's height-correlated
 * masking-shadowing G2 = 1 / (1 + Lambda(v) + Lambda(l)) with
 * Lambda = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2 (E. Heitz, "Understanding
 * the Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 2014),
 * alpha = roughness^2 (perceptual roughness, as in glTF). Sums in double. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static double lambda_ggx(double cos_theta, double a2)
{
    double c2 = cos_theta * cos_theta;
    double t2 = (1.0 - c2) / c2;
    return 0.5 * (sqrt(1.0 + a2 * t2) - 1.0);
}

/* The half vectors of one roughness: Hammersley points mapped through the
 * GGX distribution. Only their x and z matter (V lies in the x-z plane). */
static void half_vectors(double a2, int samples, double *hx, double *hz)
{
    for (int i = 0; i < samples; i++) {
        float u, v;
        lx_ibl_hammersley((uint32_t)i, (uint32_t)samples, &u, &v);
        double c2 = (1.0 - u) / (1.0 + (a2 - 1.0) * u);
        hz[i] = sqrt(c2);
        hx[i] = sqrt(1.0 - c2) * cos(2.0 * 3.14159265358979323846 * v);
    }
}

static void dfg_texel(double nov, double a2, int samples, const double *hx, const double *hz,
                      float out[2])
{
    /* V in the plane x-z, N = +z */
    double vx = sqrt(1.0 - nov * nov), vz = nov;
    double lv = lambda_ggx(nov, a2);
    double sa = 0.0, sb = 0.0;
    for (int i = 0; i < samples; i++) {
        double vh = vx * hx[i] + vz * hz[i];
        double nl = 2.0 * vh * hz[i] - vz; /* (L = 2 (V.H) H - V).z */
        if (nl <= 0.0 || vh <= 0.0)
            continue;
        double g = 1.0 / (1.0 + lv + lambda_ggx(nl, a2));
        double gv = g * vh / (hz[i] * nov);
        double f1 = 1.0 - vh, f2 = f1 * f1, fc = f2 * f2 * f1;
        sa += (1.0 - fc) * gv;
        sb += fc * gv;
    }
    out[0] = (float)(sa / samples);
    out[1] = (float)(sb / samples);
}

lx_status lx_dfg_lut(int size, int samples, lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "DFG table: no output image (NULL)");
    memset(out, 0, sizeof *out);
    size = size ? size : 128;
    samples = samples ? samples : 1024;
    if (size < 1 || size > 4096)
        return lx_fail(LX_ERR_INVALID, "DFG table: size %d is outside 1..4096", size);
    if (samples < 1 || samples > 1 << 20)
        return lx_fail(LX_ERR_INVALID, "DFG table: %d samples per texel is outside 1..%d", samples,
                       1 << 20);
    lx_status st = lx_image_alloc(out, size, size, 2);
    if (st != LX_OK)
        return st;
    volatile int nomem = 0;
#pragma omp parallel num_threads(lx_thread_count(0))
    {
        double *h = malloc(sizeof(double) * 2 * (size_t)samples);
        if (!h)
            nomem = 1;
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < size; y++) {
            if (!h)
                continue;
            double r = (y + 0.5) / size, a2 = r * r * r * r;
            half_vectors(a2, samples, h, h + samples);
            for (int x = 0; x < size; x++)
                dfg_texel((x + 0.5) / size, a2, samples, h, h + samples,
                          out->data + 2 * ((size_t)y * size + x));
        }
        free(h);
    }
    if (nomem) {
        lx_image_free(out);
        return lx_fail(LX_ERR_NOMEM, "DFG table: out of memory");
    }
    return LX_OK;
}
