/* IES photometric types A and B turned into type C (part of the LM-63
 * reader, ies.c).
 *
 * Photometric types A and B (floodlights, automotive lamps) are resampled
 * onto a type C grid when loaded, with the angle relations of the CIE
 * B-beta / A-alpha systems (CIE 121-1996; EN 13032-1) that Radiance's
 * source.cal and the EULUMDAT converters use for type B: the A/B beam axis
 * (0, 0) is the type C nadir, vertical angles tilt toward C0 and horizontal
 * angles toward C90. With x, y, z the direction's components along C0, C90
 * and the nadir, type B reads sin H = y, tan V = x / z (polar axis C90-C270)
 * and type A sin V = x, tan H = y / z (polar axis C0-C180). */
#include "ies_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>

/* An A/B file's first and last angles on one axis: at least two angles
 * with the beam axis (0) among them; starting at 0 means the other side is
 * the mirror image. */
static lx_status check_ab_axis(const char *name, int line, const char *what, const float *a, int n,
                               char type)
{
    if (n < 2)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: line %d: photometric type %c needs at least 2 %s (found %d)", name,
                       line, type, what, n);
    if (!(a[0] <= IES_ANGLE_EPS && a[n - 1] >= -IES_ANGLE_EPS))
        return lx_fail(LX_ERR_FORMAT,
                       "%s: line %d: %s %g..%g do not reach the beam axis: photometric type %c "
                       "angles run from -90 (or 0 when symmetric) to 90",
                       name, line, what, (double)a[0], (double)a[n - 1], type);
    return LX_OK;
}

/* deg in [a[0], a[n-1]] (snapped when within rounding), or false. */
static bool in_range(const float *a, int n, double *deg)
{
    if (*deg < a[0]) {
        if (*deg < a[0] - 1e-6)
            return false;
        *deg = a[0];
    } else if (*deg > a[n - 1]) {
        if (*deg > a[n - 1] + 1e-6)
            return false;
        *deg = a[n - 1];
    }
    return true;
}

/* Bilinear candela of the file's own A/B table at vertical v, horizontal h
 * (degrees); an axis starting at 0 is mirrored; 0 outside the measured
 * angles. */
static float ab_candela(const lx_ies_profile *p, double v, double h)
{
    if (ies_near(p->vert[0], 0))
        v = fabs(v);
    if (ies_near(p->horiz[0], 0))
        h = fabs(h);
    if (!in_range(p->vert, p->nv, &v) || !in_range(p->horiz, p->nh, &h))
        return 0.0f;
    int i, j;
    float tv, th;
    ies_bracket(p->vert, p->nv, (float)v, &i, &tv);
    ies_bracket(p->horiz, p->nh, (float)h, &j, &th);
    const float *a = p->cd + (size_t)j * (size_t)p->nv;
    const float *b = a + p->nv;
    return ies_lerp(ies_lerp(a[i], a[i + 1], tv), ies_lerp(b[i], b[i + 1], tv), th);
}

static double finest_step(const float *a, int n, double step)
{
    for (int i = 1; i < n; i++)
        if (a[i] - a[i - 1] < step)
            step = a[i] - a[i - 1];
    return step;
}

/* Resamples the file's A/B table (in p->vert, p->horiz, p->cd) onto a type
 * C grid: vertical 0..90 (an A/B file measures only the half space around
 * its beam axis), horizontal over the range its symmetry needs, both at the
 * file's finest angle step held to 0.25..1 degree. Each grid direction is
 * turned into the file's angles (see the top of this file) and looked up
 * bilinearly. The file's angles are kept for lx_ies_get_info. */
lx_status ies_convert_ab(lx_ies_profile *p, const char *name, int vline, int hline)
{
    char type = p->photometric_type == 2 ? 'B' : 'A';
    lx_status st = check_ab_axis(name, vline, "vertical angles", p->vert, p->nv, type);
    if (st == LX_OK)
        st = check_ab_axis(name, hline, "horizontal angles", p->horiz, p->nh, type);
    if (st != LX_OK)
        return st;
    /* a mirrored horizontal axis is y -> -y (the C0-C180 plane), a mirrored
     * vertical axis x -> -x (the C90-C270 plane), in both types */
    bool vsym = ies_near(p->vert[0], 0), hsym = ies_near(p->horiz[0], 0);
    double c0 = 0.0, c1 = 360.0;
    if (vsym && hsym)
        c1 = 90.0;
    else if (hsym)
        c1 = 180.0;
    else if (vsym) {
        c0 = 90.0;
        c1 = 270.0;
    }
    double fine = finest_step(p->horiz, p->nh, finest_step(p->vert, p->nv, IES_AB_MAX_STEP));
    double step = IES_AB_MAX_STEP;
    while (step > fine && step > IES_AB_MIN_STEP)
        step *= 0.5;
    int nv = (int)lround(90.0 / step) + 1;
    int nh = (int)lround((c1 - c0) / step) + 1;
    float *vert = malloc((size_t)nv * sizeof *vert);
    float *horiz = malloc((size_t)nh * sizeof *horiz);
    float *cd = malloc((size_t)nv * (size_t)nh * sizeof *cd);
    if (!vert || !horiz || !cd) {
        free(vert);
        free(horiz);
        free(cd);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the type C grid of a type %c file",
                       name, type);
    }
    const double rad = IES_PI / 180.0;
    for (int i = 0; i < nv; i++)
        vert[i] = (float)(i * step);
    for (int j = 0; j < nh; j++) {
        horiz[j] = (float)(c0 + j * step);
        double sc = sin(horiz[j] * rad), cc = cos(horiz[j] * rad);
        for (int i = 0; i < nv; i++) {
            double sg = sin(vert[i] * rad);
            double x = sg * cc, y = sg * sc, z = cos(vert[i] * rad);
            double v, h;
            /* on the file's polar axis every plane angle names the same
             * direction: take plane 0 there rather than rounding noise */
            if (type == 'B') {
                h = asin(y < -1.0 ? -1.0 : (y > 1.0 ? 1.0 : y)) / rad;
                v = fabs(x) < 1e-9 && fabs(z) < 1e-9 ? 0.0 : atan2(x, z) / rad;
            } else {
                v = asin(x < -1.0 ? -1.0 : (x > 1.0 ? 1.0 : x)) / rad;
                h = fabs(y) < 1e-9 && fabs(z) < 1e-9 ? 0.0 : atan2(y, z) / rad;
            }
            cd[(size_t)j * (size_t)nv + (size_t)i] = ab_candela(p, v, h);
        }
    }
    p->file_vert = p->vert;
    p->file_horiz = p->horiz;
    p->file_nv = p->nv;
    p->file_nh = p->nh;
    free(p->cd);
    p->vert = vert;
    p->horiz = horiz;
    p->cd = cd;
    p->nv = nv;
    p->nh = nh;
    return ies_classify(p, name, vline, hline);
}
