/* Unshadowed illuminance from uniform Lambertian area lights in closed form,
 * and area-light luminance from luminous power.
 *
 * - Sphere: E = pi L sin^2(a) cos(t) while the sphere is above the horizon;
 *   partly below it, Snyder's exact formula (J. Snyder, "Area light sources
 *   for real-time graphics", Microsoft Research MSR-TR-96-11, 1996) as
 *   written in S. Lagarde and C. de Rousiers, "Moving Frostbite to
 *   Physically Based Rendering", SIGGRAPH 2014 course notes, section 4.7.2,
 *   listing "illuminanceSphereOrDisk".
 * - Polygon and rect: Lambert's formula for the form factor of a polygon
 *   (J. H. Lambert, Photometria, 1760; J. Arvo, "Applications of irradiance
 *   tensors to the simulation of non-Lambertian phenomena", SIGGRAPH 1995,
 *   eq. 2): E = L/2 sum_i angle(v_i, v_i+1) n_i . n over the edges, after
 *   Sutherland-Hodgman clipping of the polygon to the receiver's upper
 *   half-space so that lights crossing the horizon stay exact.
 * - Disk: the same contour integral (Stokes' theorem, the limit of
 *   Lambert's formula for a smooth boundary: E = L/2 closed-integral
 *   (R' x R) . n / |R|^2 dt) along the visible arc of the circle, done
 *   analytically: the integrand is (A + B cos t + C sin t) / (a + b cos t +
 *   c sin t), whose antiderivative is elementary; the chord cut by the
 *   horizon is one more Lambert edge.
 * - Line: the inverse-square, cosine-weighted integral of a Lambertian line
 *   element (intensity I sin(alpha)) along the segment, which has an
 *   elementary antiderivative; the horizon clips the segment at one point.
 * - Tube (capsule): the same contour integral along the capsule's
 *   silhouette seen from the receiver, exact in closed form. The capsule is
 *   the convex hull of the balls at its ends, so its silhouette is two
 *   cylinder rulings (straight Lambert edges) and two arcs of the circles
 *   where the cone from the receiver touches the balls (at a constant
 *   distance from it, so each arc's integral is elementary), clipped by the
 *   horizon as the disk is; seen from within the radius of the axis line,
 *   the near ball's cone holds the whole capsule and Snyder's sphere form
 *   is exact.
 * - Luminance from power: Filament's area-light conversions (R. Guy and
 *   M. Agopian, "Physically Based Rendering in Filament"; Frostbite 2014
 *   section 4.7.1), L = P / (pi A) with A the emitting area.
 * Everything is computed in double and returned as float. */
#include "luxel/light.h"
#include "core/internal.h"

#include <math.h>

/* pi in double: M_PI is not part of C11. */
#define LX_PI_D 3.14159265358979323846

typedef struct dvec3 {
    double x, y, z;
} dvec3;

static dvec3 dv(double x, double y, double z)
{
    dvec3 r = {x, y, z};
    return r;
}
/* a - b of float vectors, exact in double. */
static dvec3 dsub(lx_vec3 a, lx_vec3 b)
{
    return dv((double)a.x - b.x, (double)a.y - b.y, (double)a.z - b.z);
}
static dvec3 dfrom(lx_vec3 a)
{
    return dv(a.x, a.y, a.z);
}
static double ddot(dvec3 a, dvec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static dvec3 dcross(dvec3 a, dvec3 b)
{
    return dv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static dvec3 dmadd(dvec3 a, dvec3 b, double s)
{
    return dv(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static dvec3 dscale(dvec3 a, double s)
{
    return dv(a.x * s, a.y * s, a.z * s);
}
/* a / |a|, or the zero vector when a is zero. */
static dvec3 dnormalize(dvec3 a)
{
    double len = sqrt(ddot(a, a));
    return len > 0.0 ? dscale(a, 1.0 / len) : dv(0.0, 0.0, 0.0);
}

/* ---- sphere --------------------------------------------------------------- */

/* The sphere's illuminance over L (so a projected solid angle) for w the
 * vector from p to the centre and nn the unit normal. */
static double sphere_form(dvec3 w, double r, dvec3 nn)
{
    double d2 = ddot(w, w), r2 = r * r;
    if (d2 <= r2)
        return LX_PI_D;
    double d = sqrt(d2);
    double cos_t = ddot(w, nn) / d;
    cos_t = cos_t < -1.0 ? -1.0 : (cos_t > 1.0 ? 1.0 : cos_t);
    double sin2a = r2 / d2;
    if (cos_t * cos_t >= sin2a) {
        /* wholly above (cos_t > sin a) or wholly below the horizon */
        return cos_t > 0.0 ? LX_PI_D * sin2a * cos_t : 0.0;
    }
    /* Snyder 1996 / Frostbite 2014 listing: x = cot a, y = -x cot t */
    double sin_t = sqrt(1.0 - cos_t * cos_t);
    double x = sqrt(d2 - r2) / r;
    double y = -x * cos_t / sin_t;
    y = y < -1.0 ? -1.0 : (y > 1.0 ? 1.0 : y);
    double s = sin_t * sqrt(1.0 - y * y);
    double e = (cos_t * acos(y) - x * s) * sin2a + atan(s / x);
    return e > 0.0 ? e : 0.0;
}

float lx_sphere_light_illuminance(lx_vec3 centre, float radius, float luminance, lx_vec3 p,
                                  lx_vec3 n)
{
    if (!(radius > 0.0f) || !(luminance > 0.0f))
        return 0.0f;
    dvec3 w = dsub(centre, p);
    if (ddot(w, w) <= (double)radius * radius)
        return (float)(LX_PI_D * luminance);
    dvec3 nn = dnormalize(dfrom(n));
    if (ddot(nn, nn) == 0.0)
        return 0.0f;
    return (float)(luminance * sphere_form(w, radius, nn));
}

/* ---- polygon -------------------------------------------------------------- */

/* Lambert's term of the edge a -> b seen from the origin: the angle between
 * a and b times the cosine between n and the normal of the plane through
 * the origin and the edge, oriented b x a (counter-clockwise polygons seen
 * from their emitting side then give positive sums). */
static double lambert_edge(dvec3 a, dvec3 b, dvec3 n)
{
    dvec3 c = dcross(b, a);
    double s = sqrt(ddot(c, c));
    if (!(s > 0.0))
        return 0.0; /* a zero-length edge (or one through the origin, excluded by the caller) */
    return atan2(s, ddot(a, b)) * ddot(c, n) / s;
}

/* Running sum of Lambert terms over the vertices a clipper emits. */
typedef struct edge_sum {
    dvec3 first, prev;
    int count;
    double sum;
    dvec3 n;
} edge_sum;

static void emit(edge_sum *es, dvec3 v)
{
    if (es->count == 0)
        es->first = v;
    else
        es->sum += lambert_edge(es->prev, v, es->n);
    es->prev = v;
    es->count++;
}

float lx_polygon_light_illuminance(const lx_vec3 *vertices, int count, float luminance, lx_vec3 p,
                                   lx_vec3 n)
{
    if (!vertices || count < 3 || !(luminance > 0.0f))
        return 0.0f;
    dvec3 nn = dnormalize(dfrom(n));
    if (ddot(nn, nn) == 0.0)
        return 0.0f;

    /* One-sidedness: the Newell normal of a polygon counter-clockwise seen
     * from its emitting side points to that side. Vertices relative to p. */
    dvec3 newell = dv(0.0, 0.0, 0.0), centroid = dv(0.0, 0.0, 0.0);
    for (int i = 0; i < count; i++) {
        dvec3 a = dsub(vertices[i], p);
        dvec3 b = dsub(vertices[i + 1 < count ? i + 1 : 0], p);
        newell = dmadd(newell, dcross(a, b), 1.0);
        centroid = dmadd(centroid, a, 1.0);
    }
    if (ddot(centroid, newell) >= 0.0)
        return 0.0f; /* p behind the light or in its plane */

    /* Sutherland-Hodgman against the half-space h = v . n >= 0, streamed
     * into the edge sum: no storage, any vertex count. */
    edge_sum es = {.count = 0, .sum = 0.0, .n = nn};
    for (int i = 0; i < count; i++) {
        dvec3 a = dsub(vertices[i], p);
        dvec3 b = dsub(vertices[i + 1 < count ? i + 1 : 0], p);
        double ha = ddot(a, nn), hb = ddot(b, nn);
        if (ha >= 0.0)
            emit(&es, a);
        if ((ha >= 0.0) != (hb >= 0.0))
            emit(&es, dmadd(a, dv(b.x - a.x, b.y - a.y, b.z - a.z), ha / (ha - hb)));
    }
    if (es.count < 3)
        return 0.0f; /* wholly below the horizon (or touching it) */
    es.sum += lambert_edge(es.prev, es.first, nn);
    double e = 0.5 * luminance * es.sum;
    return e > 0.0 ? (float)e : 0.0f;
}

float lx_rect_light_illuminance(const lx_vec3 corners[4], float luminance, lx_vec3 p, lx_vec3 n)
{
    return lx_polygon_light_illuminance(corners, 4, luminance, p, n);
}

/* ---- disk ----------------------------------------------------------------- */

/* The integral over t in [t0, t1] of (A + B cos t + C sin t) / (a + b cos t
 * + c sin t), for a > sqrt(b^2 + c^2) (the receiver is off the rim).
 * With b cos t + c sin t = rho cos s (s = t - phi) the numerator becomes
 * A + P cos s + Q sin s, and
 *   int ds / (a + rho cos s)     = (s + 2 T(s)) / k,  k = sqrt(a^2 - rho^2),
 *   T(s) = atan2((m - 1) sin s, (1 + m) + (1 - m) cos s),
 *          m = sqrt((a - rho) / (a + rho)),
 * which is 2/k atan(m tan(s/2)) unwrapped (the atan2's second argument is
 * >= 2m > 0, so T is continuous for every s);
 *   int cos s ds / (a + rho cos s) = (s - a int ds / (a + rho cos s)) / rho,
 *   int sin s ds / (a + rho cos s) = -ln(a + rho cos s) / rho,
 * both rearranged below so that nothing cancels when rho is small. */
static double arc_integral(double A, double B, double C, double a, double b, double c, double t0,
                           double t1)
{
    double rho = sqrt(b * b + c * c);
    if (rho <= 1e-12 * a) /* the denominator is constant to 1e-12 */
        return (A * (t1 - t0) + B * (sin(t1) - sin(t0)) - C * (cos(t1) - cos(t0))) / a;
    double phi = atan2(c, b);
    double P = B * cos(phi) + C * sin(phi);
    double Q = C * cos(phi) - B * sin(phi);
    double s0 = t0 - phi, s1 = t1 - phi;
    double sp = sqrt(a + rho), sm = sqrt(a - rho);
    double k = sp * sm;
    double m1 = -2.0 * rho / ((sm + sp) * sp); /* m - 1 without cancellation */
    double T0 = atan2(m1 * sin(s0), 2.0 + m1 - m1 * cos(s0));
    double T1 = atan2(m1 * sin(s1), 2.0 + m1 - m1 * cos(s1));
    double ds = s1 - s0, dT = T1 - T0;
    double i_one = (ds + 2.0 * dT) / k;
    /* (ds - a i_one) / rho = -ds rho / (k (a + k)) - 2 a dT / (k rho) */
    double i_cos = -ds * rho / (k * (a + k)) - 2.0 * a * dT / (k * rho);
    double i_sin = -log1p(rho * (cos(s1) - cos(s0)) / (a + rho * cos(s0))) / rho;
    return A * i_one + P * i_cos + Q * i_sin;
}

float lx_disk_light_illuminance(lx_vec3 centre, lx_vec3 normal, float radius, float luminance,
                                lx_vec3 p, lx_vec3 n)
{
    if (!(radius > 0.0f) || !(luminance > 0.0f))
        return 0.0f;
    dvec3 N = dnormalize(dfrom(normal));
    dvec3 nn = dnormalize(dfrom(n));
    if (ddot(N, N) == 0.0 || ddot(nn, nn) == 0.0)
        return 0.0f;
    dvec3 w = dsub(centre, p); /* from p to the centre */
    if (ddot(w, N) >= 0.0)
        return 0.0f; /* p behind the disk or in its plane */

    /* Frame with e1 x e2 = N: t increasing runs counter-clockwise seen from
     * the emitting side. The circle is R(t) = w + r (cos t e1 + sin t e2). */
    dvec3 e1 = fabs(N.x) < 0.9 ? dv(1.0, 0.0, 0.0) : dv(0.0, 1.0, 0.0);
    e1 = dnormalize(dcross(N, e1));
    dvec3 e2 = dcross(N, e1);
    double r = radius;

    /* Height above the horizon: h(t) = h0 + r (s1 cos t + s2 sin t). */
    double h0 = ddot(w, nn);
    double s1 = ddot(e1, nn), s2 = ddot(e2, nn);
    double sigma = sqrt(s1 * s1 + s2 * s2);
    double t0, t1;
    bool clipped = false;
    if (h0 - r * sigma >= 0.0) {
        t0 = 0.0;
        t1 = 2.0 * LX_PI_D;
    } else if (h0 + r * sigma <= 0.0) {
        return 0.0f;
    } else {
        /* visible where cos(t - psi) > -h0 / (r sigma) = cos(beta) */
        double psi = atan2(s2, s1);
        double cb = -h0 / (r * sigma);
        double beta = acos(cb < -1.0 ? -1.0 : (cb > 1.0 ? 1.0 : cb));
        t0 = psi - beta;
        t1 = psi + beta;
        clipped = true;
    }

    /* (R' x R) . n = A + B cos t + C sin t, |R|^2 = a + b cos t + c sin t */
    double A = -r * r * ddot(N, nn);
    double B = r * ddot(dcross(e2, w), nn);
    double C = -r * ddot(dcross(e1, w), nn);
    double a = ddot(w, w) + r * r;
    double b = 2.0 * r * ddot(w, e1);
    double c = 2.0 * r * ddot(w, e2);
    double sum = arc_integral(A, B, C, a, b, c, t0, t1);
    if (clipped) {
        /* the chord along the horizon, from the arc's end back to its start */
        dvec3 x1 = dmadd(dmadd(w, e1, r * cos(t1)), e2, r * sin(t1));
        dvec3 x0 = dmadd(dmadd(w, e1, r * cos(t0)), e2, r * sin(t0));
        sum += lambert_edge(x1, x0, nn);
    }
    double e = 0.5 * luminance * sum;
    return e > 0.0 ? (float)e : 0.0f;
}

/* ---- line and tube ---------------------------------------------------------- */

/* Along the line q(s) = p + D_perp + s w (s measured from the foot of the
 * perpendicular from p, h = |D_perp|), an element of intensity I sin(alpha)
 * gives I sin(alpha) cos(theta_n) / d^2 = I h (A + B s) / (s^2 + h^2)^2
 * with A = n . D_perp and B = n . w (sin(alpha) = h / d, and A + B s is the
 * element's height above the receiver's plane). The antiderivative of that
 * over I, times h. */
static double line_integral(double A, double B, double h, double s)
{
    double q = s * s + h * h;
    return A * (s / (2.0 * h * q) + atan(s / h) / (2.0 * h * h)) - h * B / (2.0 * q);
}

float lx_line_light_illuminance(lx_vec3 a, lx_vec3 b, float intensity_per_metre, lx_vec3 p,
                                lx_vec3 n)
{
    if (!(intensity_per_metre > 0.0f))
        return 0.0f;
    dvec3 seg = dsub(b, a);
    double len = sqrt(ddot(seg, seg));
    dvec3 nn = dnormalize(dfrom(n));
    if (!(len > 0.0) || ddot(nn, nn) == 0.0)
        return 0.0f;
    dvec3 w = dscale(seg, 1.0 / len);
    dvec3 D = dsub(a, p);
    double along = ddot(w, D); /* s of the segment's start */
    dvec3 perp = dmadd(D, w, -along);
    double h = sqrt(ddot(perp, perp));
    /* on the line itself every element is seen edge-on */
    if (!(h > 1e-9 * (len + sqrt(ddot(D, D)))))
        return 0.0f;
    double A = ddot(nn, perp), B = ddot(nn, w);
    /* the part above the horizon: A + B s > 0 for s in [s0, s1] */
    double s0 = along, s1 = along + len;
    if (B > 0.0) {
        s0 = fmax(s0, -A / B);
    } else if (B < 0.0) {
        s1 = fmin(s1, -A / B);
    } else if (!(A > 0.0)) {
        return 0.0f;
    }
    if (!(s1 > s0))
        return 0.0f;
    double e = line_integral(A, B, h, s1) - line_integral(A, B, h, s0);
    return e > 0.0 ? (float)(intensity_per_metre * e) : 0.0f;
}

/* The capsule: its silhouette seen from p, clipped by p's horizon, is a
 * closed contour, and the illuminance is Lambert's contour integral along it
 * (the disk's Stokes form). A capsule is the convex hull of the two balls at
 * its ends, so the cone of directions toward it is the convex hull of the
 * balls' two cones. While p is farther than r from the axis line (h > r),
 * two planes through p touch the cylinder along its rulings, both balls on
 * the same side, and the silhouette is
 *   ruling 1 (end a -> end b), the outer arc of b's tangent circle,
 *   ruling 2 (b -> a), the outer arc of a's tangent circle,
 * counter-clockwise seen from p; each ruling is a straight edge (Lambert's
 * term, exact), each arc an arc of the circle where the cone from p touches
 * the ball, which is at the same distance from p all along, so its integral
 * is elementary. While h <= r one ball's cone holds the other's and the
 * capsule shows as that ball (the sphere's exact form). The horizon cuts the
 * convex silhouette in at most two points; the part below is dropped and a
 * chord along the horizon closes the contour, as for the disk. */

/* One piece of the contour. A segment from q0 to q1, or an arc of the
 * circle centre + rho (cos t e1 + sin t e2), t from t0 to t1, of a ball of
 * angular radius alpha (sin_a = r / D) seen in direction dir, e1 x e2 = -dir. */
typedef struct tube_piece {
    bool arc;
    dvec3 q0, q1;
    dvec3 centre, e1, e2, dir;
    double rho, t0, t1, sin_a, cos_a;
    double cos_g, sin_g; /* arcs: cos and sin of t1 = -t0 */
} tube_piece;

/* The arc's point at t, from cos t and sin t. */
static dvec3 arc_point(const tube_piece *pc, double cos_t, double sin_t)
{
    return dmadd(dmadd(pc->centre, pc->e1, pc->rho * cos_t), pc->e2, pc->rho * sin_t);
}

/* The contour integral (R' x R) . n / |R|^2 over the arc's t in [u0, u1]:
 * with |R|^2 = D^2 - r^2 constant it is
 * sin^2 a (dir . n) du + sin a cos a ((e2 . n) dcos - (e1 . n) dsin). */
static double arc_term(const tube_piece *pc, dvec3 nn, double du, double dsin, double dcos)
{
    return pc->sin_a * pc->sin_a * ddot(pc->dir, nn) * du +
           pc->sin_a * pc->cos_a * (ddot(pc->e2, nn) * dcos - ddot(pc->e1, nn) * dsin);
}

/* Where the arc is above the horizon: up to two intervals of [t0, t1] in
 * order; returns how many. Height over D cos a: cos a (dir . n) + sin a
 * (e1 . n cos t + e2 . n sin t). */
static int arc_visible(const tube_piece *pc, dvec3 nn, double lo[2], double hi[2])
{
    double s1 = ddot(pc->e1, nn), s2 = ddot(pc->e2, nn);
    double sigma = sqrt(s1 * s1 + s2 * s2);
    double h0 = pc->cos_a * ddot(pc->dir, nn), amp = pc->sin_a * sigma;
    if (h0 >= amp) {
        lo[0] = pc->t0, hi[0] = pc->t1;
        return 1;
    }
    if (h0 <= -amp)
        return 0;
    /* visible where cos(t - psi) >= -h0 / amp, |t - psi| <= beta (mod 2 pi) */
    double psi = atan2(s2, s1), beta = acos(-h0 / amp);
    double base = psi - beta; /* moved into (t0 - 2 pi, t0] */
    base -= 2.0 * LX_PI_D * ceil((base - pc->t0) / (2.0 * LX_PI_D));
    int count = 0;
    for (int j = 0; j < 2; j++) {
        double a = base + 2.0 * LX_PI_D * j, b = a + 2.0 * beta;
        a = a > pc->t0 ? a : pc->t0;
        b = b < pc->t1 ? b : pc->t1;
        if (b > a) {
            lo[count] = a, hi[count] = b;
            count++;
        }
    }
    return count;
}

/* A visible part of piece `piece`: its parameter range (t for an arc, 0..1
 * along a ruling) and whether its ends are the piece's own ends. */
typedef struct tube_part {
    int piece;
    bool whole_start, whole_end;
    double u0, u1;
} tube_part;

/* The contour's point at parameter u of piece pc; exact at an arc's ends. */
static dvec3 part_point(const tube_piece *pc, double u)
{
    if (!pc->arc)
        return dmadd(pc->q0, dmadd(pc->q1, pc->q0, -1.0), u);
    if (u == pc->t1)
        return arc_point(pc, pc->cos_g, pc->sin_g);
    if (u == pc->t0)
        return arc_point(pc, pc->cos_g, -pc->sin_g);
    return arc_point(pc, cos(u), sin(u));
}

static double capsule_form(dvec3 a, dvec3 w, double len, double r, dvec3 nn)
{
    /* closest point of the segment a + s w, s in [0, len], to p (the origin) */
    double aw = ddot(a, w);
    double s_close = -aw < 0.0 ? 0.0 : (-aw > len ? len : -aw);
    dvec3 close = dmadd(a, w, s_close);
    if (ddot(close, close) <= r * r)
        return LX_PI_D;            /* on or inside the capsule */
    dvec3 perp = dmadd(a, w, -aw); /* from p to the axis line, perpendicular to it */
    double h = sqrt(ddot(perp, perp));
    dvec3 b = dmadd(a, w, len);
    if (!(h > r) || !(len > 0.0)) {
        /* one ball's cone holds the whole capsule: the nearer end */
        return sphere_form(ddot(a, a) <= ddot(b, b) ? a : b, r, nn);
    }
    double bw = aw + len;
    dvec3 u = dscale(perp, 1.0 / h), e = dcross(u, w);
    double rt = sqrt((h - r) * (h + r)); /* h sqrt(1 - r^2 / h^2) */
    /* the tangent planes' normals nu = -(r/h) u +- (rt/h) e; the rulings
     * are at a + r nu .. b + r nu */
    dvec3 off1 = dmadd(dscale(u, -r * r / h), e, r * rt / h);
    dvec3 off2 = dmadd(dscale(u, -r * r / h), e, -r * rt / h);

    tube_piece pcs[4];
    pcs[0] = (tube_piece){.arc = false, .q0 = dmadd(a, off1, 1.0), .q1 = dmadd(b, off1, 1.0)};
    pcs[2] = (tube_piece){.arc = false, .q0 = dmadd(b, off2, 1.0), .q1 = dmadd(a, off2, 1.0)};
    for (int k = 0; k < 2; k++) {
        /* pcs[1]: b's arc, pcs[3]: a's. In the plane of w and u (a mirror
         * plane of the whole picture) the direction away from the other
         * ball, perpendicular to dir: e1 = (h w - bw u) / D at b and
         * (aw u - h w) / D at a; then e2 = -dir x e1 = -e at b, +e at a. */
        dvec3 c = k == 0 ? b : a;
        double cw = k == 0 ? bw : aw, sign = k == 0 ? 1.0 : -1.0;
        double d = sqrt(ddot(c, c));
        tube_piece *pc = &pcs[k == 0 ? 1 : 3];
        pc->arc = true;
        pc->dir = dscale(c, 1.0 / d);
        pc->sin_a = r / d;
        pc->cos_a = sqrt((d - r) * (d + r)) / d;
        pc->centre = dscale(pc->dir, d * pc->cos_a * pc->cos_a);
        pc->rho = d * pc->sin_a * pc->cos_a;
        pc->e1 = dscale(dmadd(dscale(w, h), u, -cw), sign / d);
        pc->e2 = dscale(e, -sign);
        /* the tangent points sit at +-gamma from e1: (x, y) in (e1, e2) is
         * (sign r^2 cw / (h d), -+ r rt / h), so gamma = atan2(rt d, sign r cw) */
        double gx = sign * r * cw, gy = rt * d, gl = sqrt(gx * gx + gy * gy);
        double gamma = atan2(gy, gx);
        pc->t0 = -gamma;
        pc->t1 = gamma;
        pc->cos_g = gx / gl;
        pc->sin_g = gy / gl;
    }

    /* the parts above the horizon, in contour order */
    tube_part parts[8];
    int count = 0;
    double sum = 0.0;
    for (int i = 0; i < 4; i++) {
        const tube_piece *pc = &pcs[i];
        if (pc->arc) {
            double lo[2], hi[2];
            int m = arc_visible(pc, nn, lo, hi);
            for (int j = 0; j < m; j++) {
                bool ws = lo[j] == pc->t0, we = hi[j] == pc->t1;
                if (ws && we) /* the whole arc, -gamma .. gamma */
                    sum += arc_term(pc, nn, hi[j] - lo[j], 2.0 * pc->sin_g, 0.0);
                else
                    sum += arc_term(pc, nn, hi[j] - lo[j], sin(hi[j]) - sin(lo[j]),
                                    cos(hi[j]) - cos(lo[j]));
                parts[count++] = (tube_part){i, ws, we, lo[j], hi[j]};
            }
        } else {
            double h0 = ddot(pc->q0, nn), h1 = ddot(pc->q1, nn);
            if (h0 < 0.0 && h1 < 0.0)
                continue;
            double u0 = h0 < 0.0 ? h0 / (h0 - h1) : 0.0, u1 = h1 < 0.0 ? h0 / (h0 - h1) : 1.0;
            sum += lambert_edge(u0 > 0.0 ? part_point(pc, u0) : pc->q0,
                                u1 < 1.0 ? part_point(pc, u1) : pc->q1, nn);
            parts[count++] = (tube_part){i, !(h0 < 0.0), !(h1 < 0.0), u0, u1};
        }
    }
    if (count == 0)
        return 0.0;
    /* close each gap (a stretch below the horizon) with the horizon's chord */
    for (int k = 0; k < count; k++) {
        const tube_part *x = &parts[k], *y = &parts[(k + 1) % count];
        bool joined = x->whole_end && y->whole_start && y->piece == (x->piece + 1) % 4;
        if (!joined)
            sum += lambert_edge(part_point(&pcs[x->piece], x->u1),
                                part_point(&pcs[y->piece], y->u0), nn);
    }
    double form = 0.5 * sum;
    return form > 0.0 ? form : 0.0;
}

float lx_tube_light_illuminance(lx_vec3 centre, lx_vec3 axis, float length, float radius,
                                float luminance, lx_vec3 p, lx_vec3 n)
{
    if (!(radius > 0.0f) || !(luminance > 0.0f) || !(length >= 0.0f))
        return 0.0f;
    dvec3 w = dnormalize(dfrom(axis));
    dvec3 nn = dnormalize(dfrom(n));
    if (ddot(w, w) == 0.0) {
        if (!(length > 0.0f))
            w = dv(1.0, 0.0, 0.0); /* a sphere has no axis to need */
        else
            return 0.0f;
    }
    dvec3 a = dmadd(dsub(centre, p), w, -0.5 * (double)length); /* end a, from p */
    if (ddot(nn, nn) == 0.0) {
        /* only a point on or inside the tube gets light without a normal */
        double form = capsule_form(a, w, length, radius, dv(0.0, 0.0, 0.0));
        return form >= LX_PI_D ? (float)(LX_PI_D * luminance) : 0.0f;
    }
    return (float)(luminance * capsule_form(a, w, length, radius, nn));
}

/* ---- luminance from power --------------------------------------------------- */

static lx_status check_size(const char *shape, const char *what, float v, bool zero_ok)
{
    if (!isfinite(v))
        return lx_fail(LX_ERR_INVALID, "%s light: %s is not finite", shape, what);
    if (v < 0.0f || (!zero_ok && v == 0.0f))
        return lx_fail(LX_ERR_INVALID, "%s light: %s %g is not above 0", shape, what, v);
    return LX_OK;
}

lx_status lx_area_light_luminance_from_power(lx_area_shape shape, float power_lm, float radius,
                                             float length, float width, float height,
                                             float *luminance)
{
    static const char *names[] = {"sphere", "disk", "rect", "tube"};
    if (!luminance)
        return lx_fail(LX_ERR_INVALID, "area light: NULL luminance pointer");
    if ((unsigned)shape > (unsigned)LX_AREA_TUBE)
        return lx_fail(LX_ERR_INVALID, "area light: shape %d is not an area-light shape",
                       (int)shape);
    const char *name = names[shape];
    if (!isfinite(power_lm))
        return lx_fail(LX_ERR_INVALID, "%s light: power is not finite", name);
    if (power_lm < 0.0f)
        return lx_fail(LX_ERR_INVALID, "%s light: power %g lm is negative", name, power_lm);

    lx_status st = LX_OK;
    double area = 0.0; /* emitting area in m^2 */
    double r = radius;
    switch (shape) {
    case LX_AREA_SPHERE:
        st = check_size(name, "radius", radius, false);
        area = 4.0 * LX_PI_D * r * r;
        break;
    case LX_AREA_DISK:
        st = check_size(name, "radius", radius, false);
        area = LX_PI_D * r * r;
        break;
    case LX_AREA_RECT:
        if ((st = check_size(name, "width", width, false)) == LX_OK)
            st = check_size(name, "height", height, false);
        area = (double)width * height;
        break;
    case LX_AREA_TUBE:
        if (isfinite(radius) && radius == 0.0f)
            return lx_fail(LX_ERR_INVALID,
                           "tube light: radius 0 (a linear tube) has no finite luminance");
        if ((st = check_size(name, "radius", radius, false)) == LX_OK)
            st = check_size(name, "length", length, true);
        area = 2.0 * LX_PI_D * r * length + 4.0 * LX_PI_D * r * r;
        break;
    }
    if (st != LX_OK)
        return st;
    double l = (double)power_lm / (LX_PI_D * area);
    if (!(l <= 3.4028234663852886e38))
        return lx_fail(LX_ERR_INVALID, "%s light: luminance %g nt from %g lm overflows a float",
                       name, l, power_lm);
    *luminance = (float)l;
    return LX_OK;
}
