/* Beam and field angles of a photometric profile's planes: the full angle,
 * in the plane through horizontal angles h and h + 180, between the two
 * directions either side of the plane's maximum where the intensity falls
 * to a fraction of that maximum, 50% for the beam angle and 10% for the
 * field angle (IES LM-75 / the IES Lighting Handbook's beam and field
 * spread; CIE 121's half-peak divergence is the same 50% angle).
 *
 * Within a plane the profile's candela is linear in the vertical angle
 * between the grid's vertical angles (lx_ies_candela interpolates
 * bilinearly and the horizontal weight is fixed along a plane), so the
 * plane is a closed chain of linear segments in the signed angle a
 * (a >= 0: vertical angle a toward h; a < 0: vertical angle -a toward
 * h + 180), dark outside the grid's vertical range. The crossings are
 * solved on those segments, exactly, not sampled. */
#include "ies_internal.h"
#include "core/internal.h"

#include <math.h>

/* The k-th knot of one half-plane's vertical angles 0, vert..., 180
 * (without 0 or 180 where the grid starts or ends there, to the reader's
 * 1e-4 degrees), and their count. */
typedef struct plane_knots {
    const lx_ies_profile *p;
    int head; /* 1 when the grid starts at 90: a dark knot at 0 first */
    int count;
} plane_knots;

static plane_knots knots_of(const lx_ies_profile *p)
{
    plane_knots k = {p, p->vert[0] > IES_ANGLE_EPS ? 1 : 0, 0};
    k.count = k.head + p->nv + (p->vert[p->nv - 1] < 180.0 - IES_ANGLE_EPS ? 1 : 0);
    return k;
}

static float knot(const plane_knots *k, int j)
{
    if (j < k->head)
        return 0.0f;
    j -= k->head;
    return j < k->p->nv ? k->p->vert[j] : 180.0f;
}

/* Segment s of the chain in increasing a, s in [0, 2 (count - 1)): the
 * half-plane toward h + 180 from a = -180 up to 0, then the one toward h.
 * Values at its ends as limits from inside it (0 outside the grid's range,
 * so the range's ends are steps). */
typedef struct segment {
    double a0, a1, f0, f1;
} segment;

static segment segment_at(const plane_knots *k, float h, int s)
{
    int half = k->count - 1;
    bool positive = s >= half;
    int j = positive ? s - half : half - 1 - s; /* knots j, j + 1 of the half-plane */
    float v0 = knot(k, j), v1 = knot(k, j + 1);
    float hh = positive ? h : h + 180.0f;
    bool lit = v0 >= k->p->vert[0] && v1 <= k->p->vert[k->p->nv - 1];
    double c0 = lit ? lx_ies_candela(k->p, v0, hh) : 0.0;
    double c1 = lit ? lx_ies_candela(k->p, v1, hh) : 0.0;
    segment g;
    if (positive)
        g = (segment){v0, v1, c0, c1};
    else
        g = (segment){-(double)v1, -(double)v0, c1, c0};
    return g;
}

/* Distance along the plane from the maximum at a_max to where the chain
 * first falls below `threshold` walking in direction dir (+1: increasing
 * a), starting in segment s (which holds a_max at its left end when dir is
 * +1, at its right end when dir is -1); -1 if it never does. */
static double walk(const plane_knots *k, float h, int s, double a_max, int dir, double threshold)
{
    int n = 2 * (k->count - 1);
    double wrap = 0.0; /* 360 once the walk passes a = +-180 */
    for (int step = 0; step < n; step++) {
        int idx = ((s + dir * step) % n + n) % n;
        if (step > 0 && idx == (dir > 0 ? 0 : n - 1))
            wrap = 360.0;
        segment g = segment_at(k, h, idx);
        double near = dir > 0 ? g.f0 : g.f1, far = dir > 0 ? g.f1 : g.f0;
        double a_near = dir > 0 ? g.a0 : g.a1;
        double a;
        if (near < threshold) {
            a = a_near; /* a step down at the segment's start */
        } else if (far < threshold) {
            a = a_near + dir * (near - threshold) / (near - far) * (g.a1 - g.a0);
        } else {
            continue;
        }
        return dir * (a - a_max) + wrap;
    }
    return -1.0;
}

lx_status lx_ies_spread_angle(const lx_ies_profile *profile, float horizontal_deg, double fraction,
                              double *angle_deg)
{
    if (!profile || !angle_deg)
        return lx_fail(LX_ERR_INVALID, "ies spread: NULL %s", profile ? "angle_deg" : "profile");
    if (!isfinite(horizontal_deg))
        return lx_fail(LX_ERR_INVALID, "ies spread: horizontal angle is not finite");
    if (!(fraction > 0.0 && fraction < 1.0))
        return lx_fail(LX_ERR_INVALID, "ies spread: fraction %g is not between 0 and 1", fraction);
    plane_knots k = knots_of(profile);
    int n = 2 * (k.count - 1);
    /* the maximum sits at a segment's end; among equal ones the nearest the
     * nadir (then the first in a) */
    double best = 0.0, a_max = 0.0;
    int s_max = -1, end_max = 0;
    for (int s = 0; s < n; s++) {
        segment g = segment_at(&k, horizontal_deg, s);
        for (int e = 0; e < 2; e++) {
            double f = e ? g.f1 : g.f0, a = e ? g.a1 : g.a0;
            if (f > best || (f == best && s_max >= 0 && fabs(a) < fabs(a_max))) {
                best = f;
                a_max = a;
                s_max = s;
                end_max = e;
            }
        }
    }
    *angle_deg = -1.0;
    if (!(best > 0.0))
        return LX_OK; /* a dark plane */
    double threshold = fraction * best;
    /* walk each way from the maximum: from its segment when the maximum is
     * that segment's near end, else from the neighbour past it */
    int right = end_max == 0 ? s_max : (s_max + 1) % n;
    int left = end_max == 1 ? s_max : (s_max - 1 + n) % n;
    double a_right = a_max, a_left = a_max;
    if (end_max == 1 && right == 0)
        a_right -= 360.0; /* the neighbour past +180 starts at -180 */
    if (end_max == 0 && left == n - 1)
        a_left += 360.0;
    double up = walk(&k, horizontal_deg, right, a_right, +1, threshold);
    double down = walk(&k, horizontal_deg, left, a_left, -1, threshold);
    if (up < 0.0 || down < 0.0)
        return LX_OK; /* never falls that far on one side */
    *angle_deg = up + down;
    return LX_OK;
}

lx_status lx_ies_beam_field(const lx_ies_profile *profile, float horizontal_deg, double *beam_deg,
                            double *field_deg)
{
    if (!beam_deg || !field_deg)
        return lx_fail(LX_ERR_INVALID, "ies spread: NULL %s", beam_deg ? "field_deg" : "beam_deg");
    lx_status st = lx_ies_spread_angle(profile, horizontal_deg, LX_IES_BEAM_FRACTION, beam_deg);
    if (st == LX_OK)
        st = lx_ies_spread_angle(profile, horizontal_deg, LX_IES_FIELD_FRACTION, field_deg);
    return st;
}

lx_status lx_ies_plane_peak(const lx_ies_profile *profile, float horizontal_deg, float *candela)
{
    if (!profile || !candela)
        return lx_fail(LX_ERR_INVALID, "ies plane peak: NULL %s", profile ? "candela" : "profile");
    if (!isfinite(horizontal_deg))
        return lx_fail(LX_ERR_INVALID, "ies plane peak: horizontal angle is not finite");
    /* the chain is linear between its knots: its maximum is at one */
    plane_knots k = knots_of(profile);
    double best = 0.0;
    for (int s = 0; s < 2 * (k.count - 1); s++) {
        segment g = segment_at(&k, horizontal_deg, s);
        best = fmax(best, fmax(g.f0, g.f1));
    }
    *candela = (float)best;
    return LX_OK;
}

lx_status lx_ies_peak_plane(const lx_ies_profile *profile, float *horizontal_deg)
{
    if (!profile || !horizontal_deg)
        return lx_fail(LX_ERR_INVALID, "ies peak plane: NULL %s",
                       profile ? "horizontal_deg" : "profile");
    /* bilinear interpolation peaks at a grid point: the first horizontal
     * angle whose column holds the grid's largest value (a type A/B file's
     * resampled grid may stay below the file's own peak), folded into one
     * plane */
    const lx_ies_profile *p = profile;
    float h = 0.0f, best = 0.0f;
    for (int j = 0; j < p->nh; j++) {
        const float *col = p->cd + (size_t)j * p->nv;
        for (int i = 0; i < p->nv; i++)
            if (col[i] > best) {
                best = col[i];
                h = p->horiz[j];
            }
    }
    h = fmodf(h, 180.0f);
    *horizontal_deg = h < 0.0f ? h + 180.0f : h;
    return LX_OK;
}
