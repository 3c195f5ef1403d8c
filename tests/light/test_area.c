/* Tests of the area-light illuminance (src/light/area.c) against values
 * computed here independently: a midpoint quadrature in double of
 * L cos(t_p) cos(t_light) / d^2 over the light's surface (only surface
 * points above p's horizon and facing p count), published closed forms
 * (on-axis disk, parallel disk off axis, parallel rectangle seen from
 * below a corner: the form-factor catalogue's cases; a tube seen along its
 * axis is a sphere light), the far-field limit
 * I cos(t) / d^2, energy conservation (the illuminance integrated over a
 * sphere enclosing the light equals its power) and the luminance from power
 * conversions against the exitance pi L integrated over the light's area. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "luxel/light.h"

#define PI_D 3.14159265358979323846

/* ---- double vectors and the reference quadrature ------------------------- */

typedef struct v3d {
    double x, y, z;
} v3d;

static v3d d3(double x, double y, double z)
{
    v3d r = {x, y, z};
    return r;
}
static v3d of(lx_vec3 a)
{
    return d3(a.x, a.y, a.z);
}
static v3d add3(v3d a, v3d b)
{
    return d3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static v3d sub3(v3d a, v3d b)
{
    return d3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static v3d mul3(v3d a, double s)
{
    return d3(a.x * s, a.y * s, a.z * s);
}
static double dot3(v3d a, v3d b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static v3d cross3(v3d a, v3d b)
{
    return d3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static v3d unit3(v3d a)
{
    return mul3(a, 1.0 / sqrt(dot3(a, a)));
}
/* Two unit vectors completing the unit vector m to an orthonormal frame. */
static void frame3(v3d m, v3d *e1, v3d *e2)
{
    v3d a = fabs(m.x) < 0.6 ? d3(1, 0, 0) : d3(0, 1, 0);
    *e1 = unit3(cross3(m, a));
    *e2 = cross3(m, *e1);
}
static lx_vec3 tof(v3d a)
{
    return lx_v3((float)a.x, (float)a.y, (float)a.z);
}

/* One surface element: point q with emitting normal m and area da. */
static double element(v3d q, v3d m, double da, v3d p, v3d n)
{
    v3d s = sub3(q, p);
    double d2 = dot3(s, s), d = sqrt(d2);
    double cos_p = dot3(n, s) / d;
    double cos_l = -dot3(m, s) / d;
    if (cos_p <= 0.0 || cos_l <= 0.0)
        return 0.0;
    return cos_p * cos_l / d2 * da;
}

/* Sphere: midpoint grid over the cap visible from p, parametrized by the
 * angle b from the direction to p (0..acos(r/d)) and the azimuth. */
static double ref_sphere(v3d c, double r, double lum, v3d p, v3d n, int steps)
{
    n = unit3(n);
    v3d u = sub3(p, c);
    double d = sqrt(dot3(u, u));
    u = mul3(u, 1.0 / d);
    v3d e1, e2;
    frame3(u, &e1, &e2);
    double bmax = acos(r / d);
    double db = bmax / steps, dphi = 2.0 * PI_D / (2 * steps);
    double sum = 0.0;
    for (int i = 0; i < steps; i++) {
        double b = (i + 0.5) * db;
        double da = r * r * sin(b) * db * dphi;
        for (int j = 0; j < 2 * steps; j++) {
            double phi = (j + 0.5) * dphi;
            v3d m = add3(mul3(u, cos(b)),
                         add3(mul3(e1, sin(b) * cos(phi)), mul3(e2, sin(b) * sin(phi))));
            sum += element(add3(c, mul3(m, r)), m, da, p, n);
        }
    }
    return lum * sum;
}

/* Disk: midpoint grid in radius and azimuth. */
static double ref_disk(v3d c, v3d normal, double r, double lum, v3d p, v3d n, int steps)
{
    n = unit3(n);
    v3d m = unit3(normal), e1, e2;
    frame3(m, &e1, &e2);
    double dr = r / steps, dphi = 2.0 * PI_D / (2 * steps);
    double sum = 0.0;
    for (int i = 0; i < steps; i++) {
        double rho = (i + 0.5) * dr;
        for (int j = 0; j < 2 * steps; j++) {
            double phi = (j + 0.5) * dphi;
            v3d q = add3(c, add3(mul3(e1, rho * cos(phi)), mul3(e2, rho * sin(phi))));
            sum += element(q, m, rho * dr * dphi, p, n);
        }
    }
    return lum * sum;
}

/* Parallelogram c0 + u (c1 - c0) + v (c3 - c0): midpoint grid in u, v; the
 * emitting side is the one from which c0, c1, c2, c3 run counter-clockwise. */
static double ref_rect(const lx_vec3 corners[4], double lum, v3d p, v3d n, int steps)
{
    n = unit3(n);
    v3d c0 = of(corners[0]);
    v3d eu = sub3(of(corners[1]), c0), ev = sub3(of(corners[3]), c0);
    v3d area = cross3(eu, ev);
    double a = sqrt(dot3(area, area));
    v3d m = mul3(area, 1.0 / a);
    double du = 1.0 / steps, da = a * du * du;
    double sum = 0.0;
    for (int i = 0; i < steps; i++)
        for (int j = 0; j < steps; j++) {
            v3d q = add3(c0, add3(mul3(eu, (i + 0.5) * du), mul3(ev, (j + 0.5) * du)));
            sum += element(q, m, da, p, n);
        }
    return lum * sum;
}

/* ---- comparisons ---------------------------------------------------------- */

/* Largest relative error seen per shape, printed at the end. */
static double max_err[5][2];
static char max_what[5][2][96];
enum { BY_QUADRATURE, BY_OTHER }; /* kinds of reference */
enum { SPHERE, DISK, RECT, LINE, TUBE };
static const char *shape_names[] = {"sphere", "disk", "rect", "line", "tube"};

/* got within rel_tol of want, relative to want, or within abs_tol when the
 * expected value is (near) 0. */
static void check_kind(int shape, int kind, const char *what, double got, double want,
                       double rel_tol, double abs_tol)
{
    double err = fabs(got - want);
    if (want > abs_tol / rel_tol) {
        double rel = err / want;
        if (rel > max_err[shape][kind]) {
            max_err[shape][kind] = rel;
            snprintf(max_what[shape][kind], sizeof max_what[shape][kind], "%s", what);
        }
        if (!(rel <= rel_tol))
            fail_msg("%s %s: got %.9g, want %.9g (relative error %.3g > %g)", shape_names[shape],
                     what, got, want, rel, rel_tol);
    } else if (!(err <= abs_tol)) {
        fail_msg("%s %s: got %.9g, want %.9g (absolute error %.3g > %g)", shape_names[shape], what,
                 got, want, err, abs_tol);
    }
}

/* Against closed forms, limits and invariants. */
static void check(int shape, const char *what, double got, double want, double rel_tol,
                  double abs_tol)
{
    check_kind(shape, BY_OTHER, what, got, want, rel_tol, abs_tol);
}

/* Bounds against the quadratures at 400 steps (800 for the rect's square
 * grid), a small factor above the largest error measured (relative; the
 * absolute bound, a share of the luminance, for values near 0). The
 * quadratures' own error dominates: it falls fourfold with twice the steps. */
#define QUAD_STEPS 400
#define SPHERE_QUAD_TOL 2e-5 /* measured 4.9e-6 (scan 4) */
#define SPHERE_QUAD_ABS 5e-9 /* x L; measured 1.4e-9 */
#define DISK_QUAD_TOL 5e-5   /* measured 1.7e-5 (scan 24) */
#define DISK_QUAD_ABS 1e-7   /* x L; measured 2.7e-8 */
#define RECT_QUAD_TOL 2.5e-5 /* measured 7.2e-6 (scan 31) */
#define RECT_QUAD_ABS 3e-9   /* x L; measured 8e-10 */
#define TUBE_QUAD_TOL 1e-5   /* measured 2.8e-6 (off to the side, tilted) */
/* Results are floats: where the reference is exact, half an ulp (6e-8) is
 * the floor; these bounds sit a small factor above the errors measured,
 * 1e-8 to 6e-8. */
#define FLOAT_TOL 2e-7
/* The tube scan's quadrature runs at 200 steps: its largest error, 7.3e-5
 * of the scale the scan uses, falls fourfold with twice the steps (1.9e-5
 * at 400), so it is the quadrature's own. */
#define TUBE_SCAN_TOL 2e-4

/* Deterministic numbers in [0, 1) for the scans (a 64-bit LCG). */
static double rnd(uint64_t *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}
static v3d rnd_unit(uint64_t *s)
{
    for (;;) {
        v3d v = d3(2 * rnd(s) - 1, 2 * rnd(s) - 1, 2 * rnd(s) - 1);
        double l2 = dot3(v, v);
        if (l2 > 0.01 && l2 <= 1.0)
            return mul3(v, 1.0 / sqrt(l2));
    }
}

/* ---- sphere ------------------------------------------------------------- */

static void sphere_case(const char *what, lx_vec3 c, float r, float lum, lx_vec3 p, lx_vec3 n)
{
    double got = lx_sphere_light_illuminance(c, r, lum, p, n);
    double want = ref_sphere(of(c), r, lum, of(p), of(n), QUAD_STEPS);
    check_kind(SPHERE, BY_QUADRATURE, what, got, want, SPHERE_QUAD_TOL, SPHERE_QUAD_ABS * lum);
}

static void test_sphere_positions(void **state)
{
    (void)state;
    lx_vec3 c = lx_v3(0, 2, 0), up = lx_v3(0, 1, 0);
    float r = 0.5f, lum = 1000.0f;
    sphere_case("below", c, r, lum, lx_v3(0, 0, 0), up);
    sphere_case("off axis", c, r, lum, lx_v3(1.5f, 0, 0.7f), up);
    sphere_case("tilted normal", c, r, lum, lx_v3(0.3f, 0.5f, -0.2f),
                tof(unit3(d3(0.6, 1.0, -0.3))));
    sphere_case("grazing, above the horizon", c, r, lum, lx_v3(6, 1.4f, 0), up);
    sphere_case("grazing, partly below", c, r, lum, lx_v3(6, 1.9f, 0), up);
    sphere_case("centre below the horizon", c, r, lum, lx_v3(1, 2.2f, 0), up);
    sphere_case("centre above the horizon", c, r, lum, lx_v3(1, 1.8f, 0.5f), up);
    sphere_case("close, partly below", c, r, lum, lx_v3(0.7f, 2.0f, 0.1f),
                tof(unit3(d3(0.2, 1, 0))));
    sphere_case("facing away, partly below", c, r, lum, lx_v3(0.0f, 1.2f, 0.0f),
                tof(unit3(d3(1, -0.3, 0))));

    /* wholly below the horizon: exactly 0 */
    assert_true(lx_sphere_light_illuminance(c, r, lum, lx_v3(0, 3, 0), up) == 0.0f);
    assert_true(lx_sphere_light_illuminance(c, r, lum, lx_v3(2, 1, 0), lx_v3(1, 0, 0)) == 0.0f);

    /* closed form above the horizon: pi L sin^2(a) cos(t) */
    double d2 = 4.0 + 0.25; /* p = (0.5, 0, 0) */
    double cos_t = 2.0 / sqrt(d2);
    check(SPHERE, "closed form", lx_sphere_light_illuminance(c, r, lum, lx_v3(0.5f, 0, 0), up),
          PI_D * lum * 0.25 / d2 * cos_t, FLOAT_TOL, 0.0);

    /* on or inside the sphere: pi L, whatever the normal */
    check(SPHERE, "inside", lx_sphere_light_illuminance(c, r, lum, lx_v3(0.1f, 2.1f, 0), up),
          PI_D * lum, FLOAT_TOL, 0.0);
    check(SPHERE, "at the centre", lx_sphere_light_illuminance(c, r, lum, c, lx_v3(0, -1, 0)),
          PI_D * lum, FLOAT_TOL, 0.0);
    /* degenerate lights give 0 */
    assert_true(lx_sphere_light_illuminance(c, 0.0f, lum, lx_v3(0, 0, 0), up) == 0.0f);
    assert_true(lx_sphere_light_illuminance(c, r, 0.0f, lx_v3(0, 0, 0), up) == 0.0f);
}

/* Random positions and normals around the sphere, most of them with the
 * sphere crossing the horizon. */
static void test_sphere_scan(void **state)
{
    (void)state;
    uint64_t s = 1;
    lx_vec3 c = lx_v3(0.2f, 1.0f, -0.3f);
    float r = 0.4f, lum = 50.0f;
    int partial = 0;
    for (int k = 0; k < 40; k++) {
        v3d dir = rnd_unit(&s);
        double dist = r * (1.3 + 4.0 * rnd(&s));
        lx_vec3 p = tof(add3(of(c), mul3(dir, dist)));
        /* normals tilted so the horizon is near the centre */
        v3d n = unit3(add3(mul3(dir, -0.3 * (2 * rnd(&s) - 1)), rnd_unit(&s)));
        double h = dot3(sub3(of(c), of(p)), n);
        partial += fabs(h) < r;
        char what[64];
        snprintf(what, sizeof what, "scan %d", k);
        sphere_case(what, c, r, lum, p, tof(n));
    }
    print_message("%d of 40 cross the horizon\n", partial);
    assert_true(partial >= 10);
}

static void test_sphere_far_field(void **state)
{
    (void)state;
    float r = 0.05f, lum = 2000.0f;
    double d = 100.0; /* d / r = 2000: relative deviation (r/d)^2 = 2.5e-7 */
    v3d n = unit3(d3(0.5, 1.0, 0.0));
    double got = lx_sphere_light_illuminance(lx_v3(0, (float)d, 0), r, lum, lx_v3(0, 0, 0), tof(n));
    double intensity = lum * PI_D * r * r; /* I = L pi r^2 */
    /* exact for a sphere; measured 1.4e-8 */
    check(SPHERE, "far field", got, intensity * n.y / (d * d), FLOAT_TOL, 0.0);
}

/* ---- disk --------------------------------------------------------------- */

static void disk_case(const char *what, lx_vec3 c, lx_vec3 normal, float r, float lum, lx_vec3 p,
                      lx_vec3 n)
{
    double got = lx_disk_light_illuminance(c, normal, r, lum, p, n);
    double want = ref_disk(of(c), of(normal), r, lum, of(p), of(n), QUAD_STEPS);
    check_kind(DISK, BY_QUADRATURE, what, got, want, DISK_QUAD_TOL, DISK_QUAD_ABS * lum);
}

static void test_disk_positions(void **state)
{
    (void)state;
    lx_vec3 c = lx_v3(0, 2, 0), down = lx_v3(0, -1, 0), up = lx_v3(0, 1, 0);
    lx_vec3 tilted = tof(unit3(d3(0.3, -1.0, 0.2)));
    float r = 0.5f, lum = 1000.0f;
    disk_case("below", c, down, r, lum, lx_v3(0, 0, 0), up);
    disk_case("off axis", c, down, r, lum, lx_v3(1.5f, 0, 0.7f), up);
    disk_case("tilted disk", c, tilted, r, lum, lx_v3(0.4f, 0.3f, -0.6f), up);
    disk_case("tilted receiver", c, tilted, r, lum, lx_v3(-0.5f, 0.8f, 0.2f),
              tof(unit3(d3(-0.4, 1.0, 0.7))));
    disk_case("grazing receiver", c, down, r, lum, lx_v3(5, 1.8f, 0), up);
    disk_case("grazing emitter", c, down, r, lum, lx_v3(4, 1.9f, 0), lx_v3(-1, 0, 0));
    disk_case("partly below, vertical receiver", c, down, r, lum, lx_v3(0.2f, 1.0f, 0),
              lx_v3(1, 0, 0));
    disk_case("partly below, close", c, down, r, lum, lx_v3(-0.3f, 1.7f, 0.1f),
              tof(unit3(d3(-1, 0.4, 0.3))));
    disk_case("partly below, tilted disk", c, tilted, r, lum, lx_v3(0.6f, 1.2f, 0.1f),
              tof(unit3(d3(-1, 0.2, 0.1))));
    disk_case("near the rim", c, down, r, lum, lx_v3(0.45f, 1.7f, 0), up);

    /* wholly below the horizon, behind, and in the plane: exactly 0 */
    assert_true(lx_disk_light_illuminance(c, down, r, lum, lx_v3(2, 1, 0), lx_v3(1, 0, 0)) == 0.0f);
    assert_true(lx_disk_light_illuminance(c, down, r, lum, lx_v3(0, 3, 0), down) == 0.0f);
    assert_true(lx_disk_light_illuminance(c, down, r, lum, lx_v3(0.2f, 3, 0.1f), up) == 0.0f);
    assert_true(lx_disk_light_illuminance(c, down, r, lum, lx_v3(2, 2, 0), lx_v3(-1, 0, 0)) ==
                0.0f);

    /* closed forms (form-factor catalogue): on the axis at height h,
     * E = pi L r^2 / (r^2 + h^2); a receiver parallel to the disk at
     * height h and distance a from the axis,
     * E = pi L / 2 (1 - (h^2 + a^2 - r^2) / sqrt((h^2 + a^2 + r^2)^2 - 4 a^2 r^2)). */
    check(DISK, "on axis", lx_disk_light_illuminance(c, down, r, lum, lx_v3(0, 0, 0), up),
          PI_D * lum * 0.25 / (0.25 + 4.0), FLOAT_TOL, 0.0);
    double h = 2.0, a = 0.8f, rr = 0.5;
    double want = PI_D * lum / 2.0 *
                  (1.0 - (h * h + a * a - rr * rr) /
                             sqrt(pow(h * h + a * a + rr * rr, 2) - 4.0 * a * a * rr * rr));
    check(DISK, "parallel, off axis",
          lx_disk_light_illuminance(c, down, r, lum, lx_v3(0.8f, 0, 0), up), want, FLOAT_TOL, 0.0);
    h = 0.25, a = 0.3f;
    want = PI_D * lum / 2.0 *
           (1.0 - (h * h + a * a - rr * rr) /
                      sqrt(pow(h * h + a * a + rr * rr, 2) - 4.0 * a * a * rr * rr));
    check(DISK, "parallel, close",
          lx_disk_light_illuminance(c, down, r, lum, lx_v3(0, 1.75f, 0.3f), up), want, FLOAT_TOL,
          0.0);
}

static void test_disk_scan(void **state)
{
    (void)state;
    uint64_t s = 2;
    float r = 0.4f, lum = 50.0f;
    lx_vec3 c = lx_v3(0.2f, 1.0f, -0.3f);
    int partial = 0, tested = 0;
    while (tested < 40) {
        v3d normal = rnd_unit(&s);
        v3d dir = rnd_unit(&s);
        double dist = r * (0.8 + 4.0 * rnd(&s));
        v3d p = add3(of(c), mul3(dir, dist));
        double height = dot3(sub3(p, of(c)), normal);
        if (height < 0.25 * r)
            continue; /* behind the light, or too close to its plane for the grid */
        /* a horizon through or near the disk's centre */
        v3d t = rnd_unit(&s);
        t = unit3(sub3(t, mul3(dir, dot3(t, dir))));
        v3d n = unit3(add3(t, mul3(dir, (2 * rnd(&s) - 1) * r / dist)));
        double hc = dot3(sub3(of(c), p), n);
        double sin_tilt = sqrt(fmax(0.0, 1.0 - pow(dot3(n, normal), 2)));
        partial += fabs(hc) < r * sin_tilt;
        char what[64];
        snprintf(what, sizeof what, "scan %d", tested);
        disk_case(what, c, tof(normal), r, lum, tof(p), tof(n));
        tested++;
    }
    print_message("%d of 40 cross the horizon\n", partial);
    assert_true(partial >= 10);
}

static void test_disk_far_field(void **state)
{
    (void)state;
    float r = 0.05f, lum = 2000.0f;
    double d = 100.0;
    v3d normal = unit3(d3(0.3, -1.0, 0.1)), n = unit3(d3(0.5, 1.0, 0.0));
    double got = lx_disk_light_illuminance(lx_v3(0, (float)d, 0), tof(normal), r, lum,
                                           lx_v3(0, 0, 0), tof(n));
    /* a Lambertian disk's intensity is L A cos(t_light) */
    double intensity = lum * PI_D * r * r * -normal.y;
    /* off by about (r/d)^2 = 2.5e-7; measured 2.2e-7 */
    check(DISK, "far field", got, intensity * n.y / (d * d), 6e-7, 0.0);
}

/* The disk as a 4096-gon with the disk's area gives the same. */
static void test_disk_vs_polygon(void **state)
{
    (void)state;
    enum { N = 4096 };
    static lx_vec3 poly[N];
    v3d c = d3(0, 2, 0), m = unit3(d3(0.3, -1.0, 0.2)), e1, e2;
    frame3(m, &e1, &e2);
    /* counter-clockwise seen from the emitting side m: e1 -> e2 with
     * e1 x e2 = m */
    double r = 0.5 * sqrt(2.0 * PI_D / (N * sin(2.0 * PI_D / N)));
    for (int i = 0; i < N; i++) {
        double t = 2.0 * PI_D * i / N;
        poly[i] = tof(add3(c, add3(mul3(e1, r * cos(t)), mul3(e2, r * sin(t)))));
    }
    lx_vec3 ps[] = {lx_v3(0, 0, 0), lx_v3(0.6f, 1.2f, 0.1f), lx_v3(-0.3f, 1.7f, 0.1f)};
    lx_vec3 ns[] = {lx_v3(0, 1, 0), tof(unit3(d3(-1, 0.2, 0.1))), tof(unit3(d3(-1, 0.4, 0.3)))};
    for (int k = 0; k < 3; k++) {
        double disk = lx_disk_light_illuminance(tof(c), tof(m), 0.5f, 100.0f, ps[k], ns[k]);
        double poly_e = lx_polygon_light_illuminance(poly, N, 100.0f, ps[k], ns[k]);
        /* measured 0: the same floats */
        check(DISK, "4096-gon", disk, poly_e, FLOAT_TOL, 0.0);
    }
}

/* ---- rect / polygon ------------------------------------------------------------ */

/* A w x h rect centred at c with emitting normal m and "right" axis ex;
 * corners counter-clockwise seen from the emitting side. */
static void make_rect(lx_vec3 out[4], v3d c, v3d m, v3d ex, double w, double h)
{
    m = unit3(m);
    ex = unit3(sub3(ex, mul3(m, dot3(ex, m))));
    v3d ey = cross3(m, ex); /* ex x ey = m */
    out[0] = tof(add3(c, add3(mul3(ex, -w / 2), mul3(ey, -h / 2))));
    out[1] = tof(add3(c, add3(mul3(ex, w / 2), mul3(ey, -h / 2))));
    out[2] = tof(add3(c, add3(mul3(ex, w / 2), mul3(ey, h / 2))));
    out[3] = tof(add3(c, add3(mul3(ex, -w / 2), mul3(ey, h / 2))));
}

static void rect_case(const char *what, const lx_vec3 corners[4], float lum, lx_vec3 p, lx_vec3 n)
{
    double got = lx_rect_light_illuminance(corners, lum, p, n);
    double want = ref_rect(corners, lum, of(p), of(n), 2 * QUAD_STEPS);
    check_kind(RECT, BY_QUADRATURE, what, got, want, RECT_QUAD_TOL, RECT_QUAD_ABS * lum);
}

static void test_rect_positions(void **state)
{
    (void)state;
    lx_vec3 rc[4], tc[4], up = lx_v3(0, 1, 0), down = lx_v3(0, -1, 0);
    float lum = 1000.0f;
    make_rect(rc, d3(0, 2, 0), d3(0, -1, 0), d3(1, 0, 0), 1.0, 0.5);
    make_rect(tc, d3(0, 2, 0), d3(0.3, -1.0, 0.2), d3(1, 0.2, 0.4), 1.2, 0.4);
    rect_case("below", rc, lum, lx_v3(0, 0, 0), up);
    rect_case("off axis", rc, lum, lx_v3(1.5f, 0, 0.7f), up);
    rect_case("tilted rect", tc, lum, lx_v3(0.4f, 0.3f, -0.6f), up);
    rect_case("tilted receiver", tc, lum, lx_v3(-0.5f, 0.8f, 0.2f), tof(unit3(d3(-0.4, 1.0, 0.7))));
    rect_case("grazing receiver", rc, lum, lx_v3(5, 1.8f, 0), up);
    rect_case("grazing emitter", rc, lum, lx_v3(4, 1.9f, 0), lx_v3(-1, 0, 0));
    rect_case("partly below, vertical receiver", rc, lum, lx_v3(0.2f, 1.0f, 0), lx_v3(1, 0, 0));
    rect_case("partly below, close", rc, lum, lx_v3(-0.3f, 1.7f, 0.1f),
              tof(unit3(d3(-1, 0.4, 0.3))));
    rect_case("partly below, tilted rect", tc, lum, lx_v3(0.6f, 1.2f, 0.1f),
              tof(unit3(d3(-1, 0.2, 0.1))));
    rect_case("two corners below", rc, lum, lx_v3(0.1f, 1.5f, 0.05f), tof(unit3(d3(1, 0.3, 1))));

    /* wholly below, behind, in the plane: exactly 0 */
    assert_true(lx_rect_light_illuminance(rc, lum, lx_v3(2, 1, 0), lx_v3(1, 0, 0)) == 0.0f);
    assert_true(lx_rect_light_illuminance(rc, lum, lx_v3(0, 3, 0), down) == 0.0f);
    assert_true(lx_rect_light_illuminance(rc, lum, lx_v3(2, 2, 0), lx_v3(-1, 0, 0)) == 0.0f);
    /* the same corners clockwise: the light faces up, p below is behind */
    lx_vec3 cw[4] = {rc[3], rc[2], rc[1], rc[0]};
    assert_true(lx_rect_light_illuminance(cw, lum, lx_v3(0, 0, 0), up) == 0.0f);
    assert_true(lx_polygon_light_illuminance(rc, 2, lum, lx_v3(0, 0, 0), up) == 0.0f);
    assert_true(lx_polygon_light_illuminance(NULL, 4, lum, lx_v3(0, 0, 0), up) == 0.0f);

    /* closed form (form-factor catalogue): a receiver parallel to an a x b
     * rectangle at distance c, below one of its corners:
     * F = 1/(2 pi) (X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))),
     * X = a/c, Y = b/c; E = pi L F. Below the rect's centre: four of them. */
    double X = 0.5 / 2.0, Y = 0.25 / 2.0;
    double f = (X / sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) +
                Y / sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y))) /
               (2.0 * PI_D);
    check(RECT, "closed form, centre", lx_rect_light_illuminance(rc, lum, lx_v3(0, 0, 0), up),
          4.0 * PI_D * lum * f, FLOAT_TOL, 0.0);
    X = 1.0 / 1.5, Y = 0.5 / 1.5;
    f = (X / sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) +
         Y / sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y))) /
        (2.0 * PI_D);
    check(RECT, "closed form, corner",
          lx_rect_light_illuminance(rc, lum, lx_v3(-0.5f, 0.5f, -0.25f), up), PI_D * lum * f,
          FLOAT_TOL, 0.0);
}

static void test_rect_scan(void **state)
{
    (void)state;
    uint64_t s = 3;
    float lum = 50.0f;
    v3d c = d3(0.2, 1.0, -0.3);
    int partial = 0, tested = 0;
    while (tested < 40) {
        v3d normal = rnd_unit(&s);
        lx_vec3 corners[4];
        make_rect(corners, c, normal, rnd_unit(&s), 0.4 + 0.6 * rnd(&s), 0.2 + 0.6 * rnd(&s));
        v3d dir = rnd_unit(&s);
        v3d p = add3(c, mul3(dir, 0.4 + 1.6 * rnd(&s)));
        if (dot3(sub3(p, c), normal) < 0.1)
            continue; /* behind, or too close to the plane for the grid */
        v3d n = unit3(add3(mul3(dir, -0.3 * (2 * rnd(&s) - 1)), rnd_unit(&s)));
        int below = 0;
        for (int i = 0; i < 4; i++)
            below += dot3(sub3(of(corners[i]), p), n) < 0.0;
        partial += below > 0 && below < 4;
        char what[64];
        snprintf(what, sizeof what, "scan %d", tested);
        rect_case(what, corners, lum, tof(p), tof(n));
        tested++;
    }
    print_message("%d of 40 cross the horizon\n", partial);
    assert_true(partial >= 10);
}

/* A non-square rect light's orientation (light.h: width along
 * cross(up, direction), height along up's part across direction): corners
 * built here from that rule against lx_rect_light_corners, and the light's
 * illuminance through lx_light_evaluate at points along each of its axes
 * against the quadrature of the rect built here. From 0.6 and 1.2 m along
 * its width a 1.6 x 0.4 rect gives 1.3 and 1.6 times what it gives from as
 * far along its height, so swapped axes would fail. */
static void test_rect_light_orientation(void **state)
{
    (void)state;
    const v3d dirs[2] = {d3(0, -1, 0), unit3(d3(0.3, -1.0, 0.2))};
    const v3d ups[2] = {d3(0, 0, 1), d3(0.2, 0.1, 1.0)};
    const double w = 1.6, h = 0.4, lum = 500.0;
    const v3d c = d3(0.1, 2.0, -0.3);
    for (int f = 0; f < 2; f++) {
        lx_light l = lx_light_defaults(LX_LIGHT_RECT);
        l.position = tof(c);
        l.direction = tof(dirs[f]);
        l.up = tof(unit3(ups[f]));
        l.width = (float)w;
        l.height = (float)h;
        l.intensity = (float)lum;
        assert_int_equal(lx_light_validate(&l), LX_OK);
        v3d d = of(l.direction), up = of(l.up);
        v3d ex = unit3(cross3(up, d));                     /* width */
        v3d ey = unit3(sub3(up, mul3(d, dot3(up, d))));    /* height */
        assert_true(dot3(cross3(ex, ey), d) > 1.0 - 1e-6); /* ex, ey, d right-handed */
        lx_vec3 want[4], got[4];
        const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
        for (int k = 0; k < 4; k++)
            want[k] = tof(add3(c, add3(mul3(ex, sx[k] * w / 2), mul3(ey, sy[k] * h / 2))));
        lx_rect_light_corners(&l, got);
        for (int k = 0; k < 4; k++) /* floats near 2 m: measured 1.2e-7 */
            assert_true(lx_length(lx_sub(got[k], want[k])) < 5e-7f);
        double along[2][2]; /* [axis][distance] */
        for (int axis = 0; axis < 2; axis++)
            for (int k = 0; k < 2; k++) {
                double off = k == 0 ? 0.6 : 1.2;
                v3d p = add3(add3(c, d), mul3(axis == 0 ? ex : ey, off)); /* 1 m in front */
                lx_vec3 n = tof(mul3(d, -1.0));
                lx_light_eval e;
                assert_true(lx_light_evaluate(&l, tof(p), n, &e));
                double ref = ref_rect(want, lum, p, of(n), 2 * QUAD_STEPS);
                char what[64];
                snprintf(what, sizeof what, "%s %g m along its %s", f ? "tilted" : "level", off,
                         axis == 0 ? "width" : "height");
                check_kind(RECT, BY_QUADRATURE, what, e.illuminance.x, ref, RECT_QUAD_TOL,
                           RECT_QUAD_ABS * lum);
                along[axis][k] = ref;
            }
        /* 1.3 and 1.6 times (level) */
        assert_true(along[0][0] > 1.2 * along[1][0]);
        assert_true(along[0][1] > 1.2 * along[1][1]);
    }
}

static void test_rect_far_field(void **state)
{
    (void)state;
    lx_vec3 rc[4];
    double d = 100.0, w = 0.1, h = 0.05;
    v3d m = unit3(d3(0.3, -1.0, 0.1)), n = unit3(d3(0.5, 1.0, 0.0));
    make_rect(rc, d3(0, d, 0), m, d3(1, 0, 0), w, h);
    double got = lx_rect_light_illuminance(rc, 2000.0f, lx_v3(0, 0, 0), tof(n));
    double intensity = 2000.0 * w * h * -m.y; /* L A cos(t_light) */
    /* off by about (w/d)^2 / 4; measured 1.8e-7 */
    check(RECT, "far field", got, intensity * n.y / (d * d), 6e-7, 0.0);
}

/* An L-shaped (concave) polygon clipped by the horizon gives the sum of the
 * two rects it is made of. */
static void test_concave_polygon(void **state)
{
    (void)state;
    /* in the plane y = 2, emitting down: counter-clockwise seen from below */
    lx_vec3 ell[6] = {lx_v3(0, 2, 0),       lx_v3(1, 2, 0),    lx_v3(1, 2, 0.5f),
                      lx_v3(0.5f, 2, 0.5f), lx_v3(0.5f, 2, 1), lx_v3(0, 2, 1)};
    lx_vec3 a[4] = {lx_v3(0, 2, 0), lx_v3(1, 2, 0), lx_v3(1, 2, 0.5f), lx_v3(0, 2, 0.5f)};
    lx_vec3 b[4] = {lx_v3(0, 2, 0.5f), lx_v3(0.5f, 2, 0.5f), lx_v3(0.5f, 2, 1), lx_v3(0, 2, 1)};
    lx_vec3 ps[] = {lx_v3(0.3f, 1, 0.3f), lx_v3(0.7f, 1.5f, 0.8f), lx_v3(0.4f, 1.8f, 0.6f)};
    lx_vec3 ns[] = {lx_v3(0, 1, 0), tof(unit3(d3(1, 0.2, 1))), tof(unit3(d3(-1, 0.1, 0.4)))};
    for (int k = 0; k < 3; k++) {
        double whole = lx_polygon_light_illuminance(ell, 6, 100.0f, ps[k], ns[k]);
        double parts = lx_rect_light_illuminance(a, 100.0f, ps[k], ns[k]) +
                       lx_rect_light_illuminance(b, 100.0f, ps[k], ns[k]);
        /* measured 8.8e-8 relative (and 7e-9 absolute on the 0.08 lx point) */
        check(RECT, "L shape", whole, parts, 3e-7, 3e-8);
        assert_true(whole > 0.0);
    }
}

/* ---- line and tube -------------------------------------------------------- */

/* Line: midpoint steps along a..b of I sin(alpha) cos(t_p) / d^2, with
 * sin(alpha) from the angle between the segment and the element's
 * direction to p (a brute-force sum, not the closed form). */
static double ref_line(v3d a, v3d b, double per_metre, v3d p, v3d n, int steps)
{
    n = unit3(n);
    v3d seg = sub3(b, a);
    double len = sqrt(dot3(seg, seg));
    v3d w = mul3(seg, 1.0 / len);
    double dl = len / steps, sum = 0.0;
    for (int i = 0; i < steps; i++) {
        v3d s = sub3(add3(a, mul3(seg, (i + 0.5) / steps)), p);
        double d2 = dot3(s, s), d = sqrt(d2);
        double cos_p = dot3(n, s) / d;
        v3d c = cross3(w, s);
        double sin_a = sqrt(dot3(c, c)) / d;
        if (cos_p > 0.0)
            sum += per_metre * sin_a * cos_p / d2 * dl;
    }
    return sum;
}

/* Tube: the capsule's surface, a midpoint grid over the cylinder (length x
 * azimuth) and over each hemispherical cap (polar angle from the axis x
 * azimuth), every element Lambertian. */
static double ref_tube(v3d c, v3d axis, double len, double r, double lum, v3d p, v3d n, int steps)
{
    n = unit3(n);
    v3d w = unit3(axis), e1, e2;
    frame3(w, &e1, &e2);
    double dphi = 2.0 * PI_D / (2 * steps), sum = 0.0;
    double dl = len / steps;
    for (int i = 0; i < steps; i++) {
        v3d on_axis = add3(c, mul3(w, -0.5 * len + (i + 0.5) * dl));
        for (int j = 0; j < 2 * steps; j++) {
            double phi = (j + 0.5) * dphi;
            v3d m = add3(mul3(e1, cos(phi)), mul3(e2, sin(phi)));
            sum += element(add3(on_axis, mul3(m, r)), m, r * dl * dphi, p, n);
        }
    }
    double dt = 0.5 * PI_D / steps;
    for (int end = -1; end <= 1; end += 2) {
        v3d cap = add3(c, mul3(w, 0.5 * len * end));
        for (int i = 0; i < steps; i++) {
            double t = (i + 0.5) * dt;
            for (int j = 0; j < 2 * steps; j++) {
                double phi = (j + 0.5) * dphi;
                v3d m = add3(mul3(w, end * cos(t)),
                             add3(mul3(e1, sin(t) * cos(phi)), mul3(e2, sin(t) * sin(phi))));
                sum += element(add3(cap, mul3(m, r)), m, r * r * sin(t) * dt * dphi, p, n);
            }
        }
    }
    return lum * sum;
}

static void test_line_positions(void **state)
{
    (void)state;
    lx_vec3 a = lx_v3(-0.6f, 2.0f, 0.1f), b = lx_v3(0.6f, 2.2f, -0.1f);
    struct {
        const char *what;
        lx_vec3 p, n;
    } cases[] = {
        {"below the middle, facing up", {0, 0, 0}, {0, 1, 0}},
        {"off to the side, tilted", {1.5f, 0.5f, 0.7f}, {-0.3f, 1, 0.1f}},
        {"beyond an end", {2.0f, 2.1f, -0.2f}, {-1, 0, 0}},
        {"horizon cuts the segment", {0, 1.9f, 0.5f}, {1, 0.2f, 0}},
        {"horizon cuts it the other way", {0.2f, 2.4f, 0.3f}, {-1, -0.3f, 0.2f}},
        {"close to the segment", {0.1f, 2.1f, 0.05f}, {0, 0, 1}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double got = lx_line_light_illuminance(a, b, 50.0f, cases[k].p, cases[k].n);
        double want = ref_line(of(a), of(b), 50.0, of(cases[k].p), of(cases[k].n), 200000);
        /* 200000 steps: measured 2.7e-8 (beyond an end) */
        check_kind(LINE, BY_QUADRATURE, cases[k].what, got, want, 1e-7, 1e-8);
        assert_true(want > 0.0);
    }
    /* wholly below the horizon, and on the segment's own line: nothing */
    assert_true(lx_line_light_illuminance(a, b, 50.0f, lx_v3(0, 0, 0), lx_v3(0, -1, 0)) == 0.0f);
    lx_vec3 beyond = lx_add(b, lx_scale(lx_sub(b, a), 0.5f));
    assert_true(lx_line_light_illuminance(a, b, 50.0f, beyond, lx_v3(0, 1, 0)) == 0.0f);
    /* far away the segment is a point of its intensity across it times
     * its length: I L cos(t) / d^2 */
    lx_vec3 far = lx_v3(0.0f, 2.1f + 400.0f, 0.0f), n = lx_v3(0, -1, 0);
    double len = lx_length(lx_sub(b, a));
    double sin_a = lx_length(lx_cross(lx_normalize(lx_sub(b, a)), lx_v3(0, 1, 0)));
    check(LINE, "far field", lx_line_light_illuminance(a, b, 50.0f, far, n),
          50.0 * len * sin_a / (400.0 * 400.0), 5e-6, 0.0); /* measured 1.5e-6 */
}

static void test_tube_positions(void **state)
{
    (void)state;
    lx_vec3 c = lx_v3(0.0f, 2.0f, 0.0f), axis = lx_v3(1.0f, 0.0f, 0.0f);
    float len = 1.2f, r = 0.04f, lum = 1000.0f;
    /* every point at least 5 radii from the tube's axis or caps */
    struct {
        const char *what;
        lx_vec3 p, n;
    } cases[] = {
        {"5 radii below the middle", {0, 2.0f - 0.2f, 0}, {0, 1, 0}},
        {"1.5 m below", {0.3f, 0.5f, 0}, {0, 1, 0}},
        {"off to the side, tilted", {1.5f, 0.5f, 0.7f}, {-0.3f, 1, 0.1f}},
        {"beyond an end, on the axis", {1.2f, 2.0f, 0}, {-1, 0, 0}},
        {"beyond an end, off the axis", {1.0f, 1.5f, 0.3f}, {-0.5f, 1, 0}},
        {"a wall beside it", {0.2f, 2.0f, 0.5f}, {0, 0, -1}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double got = lx_tube_light_illuminance(c, axis, len, r, lum, cases[k].p, cases[k].n);
        double want = ref_tube(of(c), of(axis), len, r, lum, of(cases[k].p), of(cases[k].n), 400);
        check_kind(TUBE, BY_QUADRATURE, cases[k].what, got, want, TUBE_QUAD_TOL, 1e-8 * lum);
        assert_true(want > 0.0);
    }
    /* length 0: exactly a sphere light */
    lx_vec3 p = lx_v3(0.3f, 1.0f, 0.2f), n = lx_normalize(lx_v3(0.1f, 1.0f, 0.3f));
    check(TUBE, "length 0 is a sphere", lx_tube_light_illuminance(c, axis, 0.0f, 0.3f, lum, p, n),
          lx_sphere_light_illuminance(c, 0.3f, lum, p, n), FLOAT_TOL, 0.0);
    /* horizon through the tube's axis: the upper half of the tube, a grazing
     * sliver (1% of what the point gets facing the tube); the quadrature
     * resolves the cut less well, measured 1.1e-5 */
    lx_vec3 level = lx_v3(0.0f, 2.0f, 1.0f), up = lx_v3(0.0f, 1.0f, 0.0f);
    double sliver = ref_tube(of(c), of(axis), len, r, lum, of(level), of(up), 400);
    check_kind(TUBE, BY_QUADRATURE, "horizon through the tube",
               lx_tube_light_illuminance(c, axis, len, r, lum, level, up), sliver, 4e-5, 0.0);
    /* end-on, just off the axis line: the near cap hides most of the side */
    lx_vec3 end_on = lx_v3(1.005f, 2.046f, 0.0f), toward = lx_v3(-1.0f, 0.0f, 0.0f);
    check_kind(TUBE, BY_QUADRATURE, "nearly end-on",
               lx_tube_light_illuminance(c, axis, len, r, lum, end_on, toward),
               ref_tube(of(c), of(axis), len, r, lum, of(end_on), of(toward), 400), TUBE_QUAD_TOL,
               0.0);
    /* on the axis line beyond an end (the near cap's cone holds the whole
     * tube: a sphere light) and just inside the radius off it */
    lx_vec3 on_axis = lx_v3(0.9f, 2.0f, 0.0f), inside_r = lx_v3(0.9f, 2.0f + 0.99f * r, 0.0f);
    check(TUBE, "on the axis: the near cap",
          lx_tube_light_illuminance(c, axis, len, r, lum, on_axis, toward),
          lx_sphere_light_illuminance(lx_v3(0.6f, 2.0f, 0.0f), r, lum, on_axis, toward), FLOAT_TOL,
          0.0);
    check_kind(TUBE, BY_QUADRATURE, "beyond an end, 0.99 r off the axis",
               lx_tube_light_illuminance(c, axis, len, r, lum, inside_r, toward),
               ref_tube(of(c), of(axis), len, r, lum, of(inside_r), of(toward), 400), TUBE_QUAD_TOL,
               0.0);
    /* on or inside the capsule: pi L */
    check(TUBE, "inside",
          lx_tube_light_illuminance(c, axis, len, r, lum, lx_v3(0.6f, 2.01f, 0), up), PI_D * lum,
          FLOAT_TOL, 0.0);
}

/* 400 points around a tilted tube, a quarter each: anywhere around it, beyond
 * an end near its axis (seen end-on, the axis within 2.5 radii: the near
 * cap's cone holds the capsule up to 1 radius, the rulings show beyond),
 * beside it, and 1-4 m away; half the normals random, half with the horizon
 * through the tube. Against the surface quadrature at 200 steps. */
/* Distance from p to the segment of length len along axis centred on c. */
static double segment_distance(v3d p, v3d c, v3d axis, double len)
{
    double t = dot3(sub3(p, c), axis);
    t = t < -0.5 * len ? -0.5 * len : (t > 0.5 * len ? 0.5 * len : t);
    v3d d = sub3(p, add3(c, mul3(axis, t)));
    return sqrt(dot3(d, d));
}

static void test_tube_scan(void **state)
{
    (void)state;
    uint64_t s = 5;
    v3d c = d3(0.1, 1.5, -0.2), axis = unit3(d3(0.3, 0.2, 1.0)), e1, e2;
    frame3(axis, &e1, &e2);
    double len = 0.8, r = 0.06, lum = 100.0;
    int crossing = 0, lit = 0;
    for (int k = 0; k < 400; k++) {
        double along, radial;
        v3d around = unit3(add3(mul3(e1, 2 * rnd(&s) - 1), mul3(e2, 2 * rnd(&s) - 1)));
        v3d p;
        switch (k % 4) {
        case 0: /* anywhere, 0.5 to 20 radii off the surface */
            do
                p = add3(add3(c, mul3(axis, len * (1.2 * rnd(&s) - 0.6))),
                         mul3(rnd_unit(&s), r * (1.5 + 19.5 * rnd(&s))));
            while (segment_distance(p, c, axis, len) < 1.5 * r);
            break;
        case 1: /* beyond an end, near the axis line */
            along = (0.5 * len + r * (1.5 + 7.5 * rnd(&s))) * (rnd(&s) < 0.5 ? -1 : 1);
            radial = 2.5 * r * rnd(&s);
            p = add3(add3(c, mul3(axis, along)), mul3(around, radial));
            break;
        case 2: /* beside the cylinder */
            along = len * (rnd(&s) - 0.5);
            radial = r * (1.5 + 10.5 * rnd(&s));
            p = add3(add3(c, mul3(axis, along)), mul3(around, radial));
            break;
        default: /* far */
            p = add3(c, mul3(rnd_unit(&s), 1.0 + 3.0 * rnd(&s)));
            break;
        }
        v3d n;
        if (k % 8 < 4) {
            n = rnd_unit(&s);
        } else {
            /* the horizon through a point of the axis, tilted by up to 1.5 radii */
            v3d q = add3(c, mul3(axis, len * (rnd(&s) - 0.5)));
            v3d to = sub3(q, p);
            double d = sqrt(dot3(to, to));
            to = mul3(to, 1.0 / d);
            v3d t = rnd_unit(&s);
            t = unit3(sub3(t, mul3(to, dot3(t, to))));
            n = unit3(add3(t, mul3(to, 1.5 * r / d * (2 * rnd(&s) - 1))));
        }
        /* heights of the capsule's lowest and highest points over the horizon */
        double h0 = dot3(sub3(add3(c, mul3(axis, -0.5 * len)), p), n);
        double h1 = dot3(sub3(add3(c, mul3(axis, 0.5 * len)), p), n);
        crossing += fmin(h0, h1) - r < 0.0 && fmax(h0, h1) + r > 0.0;
        double got = lx_tube_light_illuminance(tof(c), tof(axis), (float)len, (float)r, (float)lum,
                                               tof(p), tof(n));
        double want = ref_tube(c, axis, len, r, lum, p, n, 200);
        lit += want > 0.0;
        /* the quadrature's error is a share of the whole tube's light, not
         * of a grazing sliver's: measured against 5% of I(alpha) / d^2 at
         * least */
        v3d to_c = sub3(c, p);
        double d2 = dot3(to_c, to_c), cos_a = dot3(to_c, axis) / sqrt(d2);
        double far = lum * (2 * r * len * sqrt(fmax(0.0, 1 - cos_a * cos_a)) + PI_D * r * r) / d2;
        double scale = fmax(want, 0.05 * fmin(far, PI_D * lum));
        double err = fabs(got - want) / scale;
        if (err > max_err[TUBE][BY_QUADRATURE]) {
            max_err[TUBE][BY_QUADRATURE] = err;
            snprintf(max_what[TUBE][BY_QUADRATURE], sizeof max_what[TUBE][BY_QUADRATURE], "scan %d",
                     k);
        }
        if (!(err <= TUBE_SCAN_TOL))
            fail_msg("tube scan %d: got %.9g, want %.9g (error %.3g of %.6g > %g)", k, got, want,
                     err, scale, TUBE_SCAN_TOL);
    }
    print_message("%d of 400 lit, %d with the horizon through the tube\n", lit, crossing);
    assert_true(crossing >= 150);
    assert_true(lit >= 250);
}

/* Points from lx_area_light_point lie on the tube's surface with outward
 * normals, uniform in area: the share on the cylinder is its share of the
 * area. A linear tube's points lie on its segment. */
static void test_tube_surface_points(void **state)
{
    (void)state;
    lx_light l = lx_light_defaults(LX_LIGHT_TUBE);
    l.position = lx_v3(1.0f, 2.0f, 3.0f);
    l.direction = lx_normalize(lx_v3(1.0f, 0.5f, 0.0f));
    l.length = 0.8f;
    l.radius = 0.1f;
    int n = 64, on_side = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            lx_vec3 m;
            lx_vec3 q = lx_area_light_point(&l, (i + 0.5f) / n, (j + 0.5f) / n, &m);
            lx_vec3 rel = lx_sub(q, l.position);
            float t = lx_dot(rel, l.direction);
            float tc = fmaxf(-0.4f, fminf(0.4f, t));
            lx_vec3 nearest = lx_madd(l.position, l.direction, tc);
            /* float positions near 3 m: measured 1.7e-7 (radius), 1.2e-7 */
            assert_true(fabsf(lx_length(lx_sub(q, nearest)) - 0.1f) < 5e-7f);
            assert_true(lx_length(lx_sub(lx_madd(nearest, m, 0.1f), q)) < 5e-7f);
            /* on the cylinder |m . axis| is float rounding (1e-7); a cap's
             * point nearest its rim on this grid is at 0.04 */
            on_side += fabsf(t) < 0.4f - 1e-5f && fabsf(lx_dot(m, l.direction)) < 1e-5f;
        }
    /* the cylinder's share of the area picks the columns of u below it */
    double side_share = 2.0 * PI_D * 0.1 * 0.8 / (2.0 * PI_D * 0.1 * 0.8 + 4.0 * PI_D * 0.01);
    int columns = 0;
    for (int i = 0; i < n; i++)
        columns += (i + 0.5) / n < side_share;
    assert_int_equal(on_side, columns * n);
    l.radius = 0.0f;
    lx_vec3 m;
    lx_vec3 q = lx_area_light_point(&l, 0.25f, 0.7f, &m);
    assert_true(lx_length(lx_sub(q, lx_madd(l.position, l.direction, -0.2f))) < 5e-7f); /* 0 */
    assert_true(lx_dot(m, m) == 0.0f);
}

/* Unit conversions of tubes through lx_light_intensity_to_native, against
 * the power of their intensity distribution L (2 r len sin(a) + pi r^2)
 * (cd per metre I sin(a) when linear) integrated over the sphere here. */
static double tube_power(double lum, double r, double len)
{
    int steps = 4000;
    double dt = PI_D / steps, sum = 0.0;
    for (int i = 0; i < steps; i++) {
        double a = (i + 0.5) * dt;
        sum += lum * (2.0 * r * len * sin(a) + PI_D * r * r) * sin(a) * dt * 2.0 * PI_D;
    }
    return sum;
}

static void test_tube_units(void **state)
{
    (void)state;
    lx_light l = lx_light_defaults(LX_LIGHT_TUBE);
    l.length = 1.2f;
    l.radius = 0.02f;
    float native;
    assert_int_equal(
        lx_light_intensity_to_native(&l, 3000.0f, LX_UNIT_LUMEN, LX_SPOT_POWER_PI, &native), LX_OK);
    /* 4000-step sums of the power: measured 5e-9 to 6e-8 */
    check(TUBE, "lm to nt", tube_power(native, 0.02, 1.2), 3000.0, FLOAT_TOL, 0.0);
    assert_int_equal(
        lx_light_intensity_to_native(&l, 10.0f, LX_UNIT_WATT, LX_SPOT_POWER_PI, &native), LX_OK);
    check(TUBE, "W to nt", tube_power(native, 0.02, 1.2), 6830.0, FLOAT_TOL, 0.0);
    /* candela: the intensity across the axis, L (2 r len + pi r^2) */
    assert_int_equal(
        lx_light_intensity_to_native(&l, 500.0f, LX_UNIT_CANDELA, LX_SPOT_POWER_PI, &native),
        LX_OK);
    check(TUBE, "cd to nt", native * (2.0 * 0.02 * 1.2 + PI_D * 0.0004), 500.0, FLOAT_TOL, 0.0);
    assert_int_equal(lx_light_intensity_to_native(&l, 7.0f, LX_UNIT_NIT, LX_SPOT_POWER_PI, &native),
                     LX_OK);
    assert_true(native == 7.0f);

    /* linear: candela per metre across the axis */
    l.radius = 0.0f;
    assert_int_equal(
        lx_light_intensity_to_native(&l, 3000.0f, LX_UNIT_LUMEN, LX_SPOT_POWER_PI, &native), LX_OK);
    double per_metre_power = 0.0;
    for (int i = 0; i < 4000; i++) {
        double a = (i + 0.5) * PI_D / 4000;
        per_metre_power += sin(a) * sin(a) * (PI_D / 4000) * 2.0 * PI_D;
    }
    check(LINE, "lm to cd/m", native * 1.2 * per_metre_power, 3000.0, FLOAT_TOL, 0.0);
    assert_int_equal(
        lx_light_intensity_to_native(&l, 600.0f, LX_UNIT_CANDELA, LX_SPOT_POWER_PI, &native),
        LX_OK);
    check(LINE, "cd to cd/m", native, 500.0, FLOAT_TOL, 0.0);
    native = -7.0f;
    assert_int_equal(lx_light_intensity_to_native(&l, 5.0f, LX_UNIT_NIT, LX_SPOT_POWER_PI, &native),
                     LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "linear tube (radius 0) has no area for nt"));
    assert_true(native == -7.0f);
    /* validation: a linear tube needs a length; sizes are finite */
    l.length = 0.0f;
    assert_int_equal(lx_light_validate(&l), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "needs a length above 0"));
    l.length = 1.0f;
    l.radius = NAN;
    assert_int_equal(lx_light_validate(&l), LX_ERR_INVALID);
    l.radius = 0.01f;
    l.length = -1.0f;
    assert_int_equal(lx_light_validate(&l), LX_ERR_INVALID);
    l.length = 1.0f;
    assert_int_equal(lx_light_validate(&l), LX_OK);
}

/* ---- energy and power ------------------------------------------------------------ */

typedef enum { E_SPHERE, E_DISK, E_RECT, E_TUBE, E_LINE } energy_shape;

/* The illuminance integrated over a sphere of radius big_r around the
 * origin with inward normals: the light's whole power. */
static double enclosed_power(energy_shape shape, float lum, const lx_vec3 *rect, int steps,
                             double big_r)
{
    double dt = PI_D / steps, dphi = 2.0 * PI_D / (2 * steps);
    double sum = 0.0;
    for (int i = 0; i < steps; i++) {
        double t = (i + 0.5) * dt;
        double da = big_r * big_r * sin(t) * dt * dphi;
        for (int j = 0; j < 2 * steps; j++) {
            double phi = (j + 0.5) * dphi;
            v3d u = d3(sin(t) * cos(phi), cos(t), sin(t) * sin(phi));
            lx_vec3 p = tof(mul3(u, big_r)), n = tof(mul3(u, -1.0));
            double e = 0.0;
            if (shape == E_SPHERE)
                e = lx_sphere_light_illuminance(lx_v3(0.1f, 0, 0), 0.3f, lum, p, n);
            else if (shape == E_DISK)
                e = lx_disk_light_illuminance(lx_v3(0.1f, 0, 0), tof(unit3(d3(0.2, -1, 0.3))), 0.4f,
                                              lum, p, n);
            else if (shape == E_TUBE)
                e = lx_tube_light_illuminance(lx_v3(0.1f, 0, 0), tof(unit3(d3(0.2, -1, 0.3))), 0.8f,
                                              0.05f, lum, p, n);
            else if (shape == E_LINE)
                e = lx_line_light_illuminance(lx_v3(-0.3f, 0.1f, 0), lx_v3(0.4f, -0.2f, 0.1f), lum,
                                              p, n);
            else
                e = lx_rect_light_illuminance(rect, lum, p, n);
            sum += e * da;
        }
    }
    return sum;
}

static void test_energy_conservation(void **state)
{
    (void)state;
    float power = 1000.0f, lum;
    assert_int_equal(lx_area_light_luminance_from_power(LX_AREA_SPHERE, power, 0.3f, 0, 0, 0, &lum),
                     LX_OK);
    /* the midpoint rule over the enclosing sphere at 300 steps; measured
     * 4.6e-6 (sphere), 7.8e-6 (disk, rect), 3.0e-6 (tube), 5.2e-6 (line) */
    check(SPHERE, "enclosed power", enclosed_power(E_SPHERE, lum, NULL, 300, 1.0), power, 2e-5,
          0.0);
    assert_int_equal(lx_area_light_luminance_from_power(LX_AREA_DISK, power, 0.4f, 0, 0, 0, &lum),
                     LX_OK);
    check(DISK, "enclosed power", enclosed_power(E_DISK, lum, NULL, 300, 1.0), power, 3e-5, 0.0);
    lx_vec3 rc[4];
    make_rect(rc, d3(0.1, 0, 0), d3(0.2, -1, 0.3), d3(1, 0, 0), 0.8, 0.5);
    assert_int_equal(
        lx_area_light_luminance_from_power(LX_AREA_RECT, power, 0, 0, 0.8f, 0.5f, &lum), LX_OK);
    check(RECT, "enclosed power", enclosed_power(E_RECT, lum, rc, 300, 1.0), power, 3e-5, 0.0);
    assert_int_equal(
        lx_area_light_luminance_from_power(LX_AREA_TUBE, power, 0.05f, 0.8f, 0, 0, &lum), LX_OK);
    /* the sphere of radius 1 passes 0.2 m from the tube's end; measured
     * 3.0e-6 there, 2.3e-6 at 20 m */
    check(TUBE, "enclosed power", enclosed_power(E_TUBE, lum, NULL, 300, 1.0), power, 1e-5, 0.0);
    check(TUBE, "enclosed power at 20 m", enclosed_power(E_TUBE, lum, NULL, 300, 20.0), power, 1e-5,
          0.0);
    /* a line of I candela per metre across it emits I pi^2 lumens per metre */
    double line_len = sqrt(0.7 * 0.7 + 0.3 * 0.3 + 0.1 * 0.1);
    check(LINE, "enclosed power", enclosed_power(E_LINE, 10.0f, NULL, 300, 1.0),
          10.0 * PI_D * PI_D * line_len, 2e-5, 0.0);
}

/* Exitance of a Lambertian surface: L cos(t) integrated over the
 * hemisphere, by a midpoint grid. */
static double exitance(double lum)
{
    int steps = 2000;
    double dt = 0.5 * PI_D / steps, sum = 0.0;
    for (int i = 0; i < steps; i++) {
        double t = (i + 0.5) * dt;
        sum += lum * cos(t) * sin(t) * dt * 2.0 * PI_D;
    }
    return sum;
}

/* Surface area of a sphere of radius r by a midpoint grid. */
static double sphere_area(double r)
{
    int steps = 2000;
    double dt = PI_D / steps, sum = 0.0;
    for (int i = 0; i < steps; i++)
        sum += r * r * sin((i + 0.5) * dt) * dt * 2.0 * PI_D;
    return sum;
}

static void test_power_conversions(void **state)
{
    (void)state;
    double m = exitance(1.0); /* pi */
    float lum = 0.0f, power = 1200.0f;
    /* sphere: P = M * 4 pi r^2 */
    assert_int_equal(
        lx_area_light_luminance_from_power(LX_AREA_SPHERE, power, 0.25f, 0, 0, 0, &lum), LX_OK);
    /* exitance and areas by 2000-step midpoint sums: measured 6e-8 to 1.9e-7 */
    check(SPHERE, "exitance x area", lum * m * sphere_area(0.25), power, 5e-7, 0.0);
    check(SPHERE, "P / (4 pi^2 r^2)", lum, power / (4.0 * PI_D * PI_D * 0.0625), FLOAT_TOL, 0.0);
    /* disk: one side, pi r^2 (area by a polar midpoint grid) */
    assert_int_equal(lx_area_light_luminance_from_power(LX_AREA_DISK, power, 0.25f, 0, 0, 0, &lum),
                     LX_OK);
    double disk_area = 0.0;
    for (int i = 0; i < 1000; i++)
        disk_area += (i + 0.5) * (0.25 / 1000) * (0.25 / 1000) * 2.0 * PI_D;
    check(DISK, "exitance x area", lum * m * disk_area, power, 5e-7, 0.0);
    check(DISK, "P / (pi^2 r^2)", lum, power / (PI_D * PI_D * 0.0625), FLOAT_TOL, 0.0);
    /* rect: W H */
    assert_int_equal(
        lx_area_light_luminance_from_power(LX_AREA_RECT, power, 0, 0, 2.0f, 0.5f, &lum), LX_OK);
    check(RECT, "exitance x area", lum * m * 1.0, power, 5e-7, 0.0);
    check(RECT, "P / (pi W H)", lum, power / PI_D, FLOAT_TOL, 0.0);
    /* tube: cylinder side 2 pi r l plus two hemispherical caps 4 pi r^2 */
    assert_int_equal(
        lx_area_light_luminance_from_power(LX_AREA_TUBE, power, 0.02f, 1.2f, 0, 0, &lum), LX_OK);
    double tube_area = 2.0 * PI_D * 0.02 * 1.2 + sphere_area(0.02);
    check(TUBE, "exitance x area", lum * m * tube_area, power, 5e-7, 0.0);
    check(TUBE, "P / (pi A)", lum, power / (PI_D * (2.0 * PI_D * 0.02 * 1.2 + 4.0 * PI_D * 0.0004)),
          FLOAT_TOL, 0.0);
    /* a tube of length 0 is a sphere */
    float lum_sphere;
    assert_int_equal(lx_area_light_luminance_from_power(LX_AREA_TUBE, power, 0.1f, 0, 0, 0, &lum),
                     LX_OK);
    assert_int_equal(
        lx_area_light_luminance_from_power(LX_AREA_SPHERE, power, 0.1f, 0, 0, 0, &lum_sphere),
        LX_OK);
    check(TUBE, "length 0 is a sphere's luminance", lum, lum_sphere, FLOAT_TOL, 0.0);
    /* zero power is zero luminance */
    assert_int_equal(lx_area_light_luminance_from_power(LX_AREA_DISK, 0.0f, 0.1f, 0, 0, 0, &lum),
                     LX_OK);
    assert_true(lum == 0.0f);
}

static void expect_invalid(lx_status st, const char *needle, const float *lum)
{
    if (st != LX_ERR_INVALID)
        fail_msg("status %s, want LX_ERR_INVALID", lx_status_name(st));
    if (!strstr(lx_last_error(), needle))
        fail_msg("message '%s' does not contain '%s'", lx_last_error(), needle);
    assert_true(*lum == -7.0f); /* untouched */
}

static void test_power_bad_input(void **state)
{
    (void)state;
    float lum = -7.0f;
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_SPHERE, 100, -1.0f, 0, 0, 0, &lum),
                   "sphere light: radius -1 is not above 0", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_SPHERE, 100, 0.0f, 0, 0, 0, &lum),
                   "sphere light: radius 0 is not above 0", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_DISK, 100, NAN, 0, 0, 0, &lum),
                   "disk light: radius is not finite", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_RECT, 100, 0, 0, 0.0f, 1, &lum),
                   "rect light: width 0 is not above 0", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_RECT, 100, 0, 0, 1, -2.0f, &lum),
                   "rect light: height -2 is not above 0", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_RECT, 100, 0, 0, 1, INFINITY, &lum),
                   "rect light: height is not finite", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_TUBE, 100, 0.0f, 1, 0, 0, &lum),
                   "tube light: radius 0 (a linear tube)", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_TUBE, 100, 0.1f, -1, 0, 0, &lum),
                   "tube light: length -1 is not above 0", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_DISK, -5, 0.1f, 0, 0, 0, &lum),
                   "disk light: power -5 lm is negative", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_DISK, NAN, 0.1f, 0, 0, 0, &lum),
                   "disk light: power is not finite", &lum);
    expect_invalid(lx_area_light_luminance_from_power((lx_area_shape)9, 100, 0.1f, 0, 0, 0, &lum),
                   "shape 9 is not an area-light shape", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_SPHERE, 3e38f, 1e-20f, 0, 0, 0, &lum),
                   "overflows a float", &lum);
    expect_invalid(lx_area_light_luminance_from_power(LX_AREA_SPHERE, 100, 1, 0, 0, 0, NULL),
                   "NULL", &lum);
}

static int print_errors(void **state)
{
    (void)state;
    for (int i = 0; i < 5; i++)
        print_message("%s: largest relative error against the quadrature %.3g (%s), against "
                      "closed forms, limits and invariants %.3g (%s)\n",
                      shape_names[i], max_err[i][0], max_what[i][0], max_err[i][1], max_what[i][1]);
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_positions),    cmocka_unit_test(test_sphere_scan),
        cmocka_unit_test(test_sphere_far_field),    cmocka_unit_test(test_disk_positions),
        cmocka_unit_test(test_disk_scan),           cmocka_unit_test(test_disk_far_field),
        cmocka_unit_test(test_disk_vs_polygon),     cmocka_unit_test(test_rect_positions),
        cmocka_unit_test(test_rect_scan),           cmocka_unit_test(test_rect_light_orientation),
        cmocka_unit_test(test_rect_far_field),      cmocka_unit_test(test_concave_polygon),
        cmocka_unit_test(test_energy_conservation), cmocka_unit_test(test_power_conversions),
        cmocka_unit_test(test_power_bad_input),     cmocka_unit_test(test_line_positions),
        cmocka_unit_test(test_tube_positions),      cmocka_unit_test(test_tube_scan),
        cmocka_unit_test(test_tube_surface_points), cmocka_unit_test(test_tube_units),
    };
    return cmocka_run_group_tests(tests, NULL, print_errors);
}
