/* Phong specular prefiltering after Wikibooks' "Cg Programming/
 * Unity/Many Light Sources", "Changes for Specular Reflection": the
 * brute-force convolution of the environment with the lobe
 * w(R, L) = pow(max(0, R.L), n), every source texel a directional light,
 *     out(R) = sum_t L_t Omega_t w(R, l_t) / sum_t Omega_t w(R, l_t),
 * normalised by the lobe's own sum over the sphere, so a constant
 * environment stays constant. Computed by prefilter_conv.c's direct
 * convolution with this lobe:
 *  - on the mip level whose texels are at most half the lobe's half-width
 *    at half maximum (the full-size source when none is that fine), each
 *    texel a light at the flux centroid of what it covers: a lobe costs
 *    ~200 texels whatever its width;
 *  - leaving out texels where the lobe is below 1e-4 of its peak
 *    (R.L < 1e-4^(1/n)). The lobe falls like exp(-n theta^2 / 2), so what
 *    is left out weighs about 1e-4 of the lobe, and a node of texels is
 *    never taken as one light (no far field: the lobe's relative
 *    curvature grows away from its axis). */
#include "ibl_internal.h"

#include <math.h>

#define PHONG_CUTOFF 1e-4

lx_lobe lx_phong_lobe(float exponent)
{
    lx_lobe l = {.kind = LX_LOBE_PHONG, .param = exponent, .texels = 2.0, .far = 0.0};
    l.cos_cut = (float)exp(log(PHONG_CUTOFF) / exponent);
    l.half_width = acos(exp(log(0.5) / exponent));
    return l;
}
