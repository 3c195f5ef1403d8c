/* Tests of the light model (src/light): closed forms of Filament's punctual
 * and directional lights and of the per-texel lighting document's classic
 * falloff,
 * computed here independently in double precision, unit conversions,
 * exposure, blur shadows, ambient and validation messages. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "helpers.h"

#define PI_D 3.14159265358979323846
/* The model works in float: where the reference is exact, a few half-ulps
 * (6e-8 relative) are the floor; the errors measured against these bounds
 * are 0 to 6.8e-8. Other bounds state their own measured error. */
#define FLOAT_TOL 2e-7

static void assert_fails(lx_status st, lx_status want, const char *needle)
{
    if (st != want)
        fail_msg("status %s, want %s (message: %s)", lx_status_name(st), lx_status_name(want),
                 lx_last_error());
    if (!strstr(lx_last_error(), needle))
        fail_msg("message '%s' does not contain '%s'", lx_last_error(), needle);
}

/* Filament's window written out: (1 - (d/r)^4)^2, clamped, 1 for r = 0. */
static double window_ref(double d, double r)
{
    if (r <= 0.0)
        return 1.0;
    double f = 1.0 - pow(d / r, 4.0);
    return f > 0.0 ? f * f : 0.0;
}

static lx_light named(lx_light_type type, const char *name)
{
    lx_light l = lx_light_defaults(type);
    strcpy(l.name, name);
    return l;
}

static void test_defaults(void **state)
{
    (void)state;
    lx_light l = lx_light_defaults(LX_LIGHT_SPOT);
    assert_int_equal(l.type, LX_LIGHT_SPOT);
    assert_true(l.color.x == 1.0f && l.color.y == 1.0f && l.color.z == 1.0f);
    assert_true(l.intensity == 1.0f && l.range == 0.0f);
    assert_true(l.inner_angle == 0.0f);
    lx_test_assert_rel(l.outer_angle, PI_D / 4.0, FLOAT_TOL);
    assert_int_equal(l.shadow, LX_SHADOW_HARD);
    assert_int_equal(l.model, LX_MODEL_PHYSICAL);
    assert_true(l.blur_power == 1.0f && l.blur_multiplier == 1.0f);
    assert_true(l.direction.y == -1.0f);
    assert_int_equal(lx_light_validate(&l), LX_OK);
    lx_light d = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    assert_int_equal(lx_light_validate(&d), LX_OK);
    /* soft-shadow samples: 0 stands for the default, 16 */
    lx_light a = lx_light_defaults(LX_LIGHT_RECT);
    assert_int_equal(a.samples, 0);
    assert_int_equal(LX_DEFAULT_LIGHT_SAMPLES, 16);
    assert_int_equal(lx_light_sample_count(&a), 16);
    a.samples = 5;
    assert_int_equal(lx_light_sample_count(&a), 5);
}

static void test_range_window(void **state)
{
    (void)state;
    assert_true(lx_light_range_window(0.0f, 4.0f) == 1.0f);
    assert_true(lx_light_range_window(16.0f, 4.0f) == 0.0f);
    lx_test_assert_rel(lx_light_range_window(4.0f, 4.0f), (1.0 - 1.0 / 16.0) * (1.0 - 1.0 / 16.0),
                       FLOAT_TOL);
    assert_true(lx_light_range_window(25.0f, 4.0f) == 0.0f);
    assert_true(lx_light_range_window(1e6f, 0.0f) == 1.0f);
    lx_test_assert_rel(lx_light_range_window(9.0f, 5.0f), window_ref(3.0, 5.0), FLOAT_TOL);
}

static void test_point_inverse_square(void **state)
{
    (void)state;
    lx_light l = named(LX_LIGHT_POINT, "bulb");
    l.position = lx_v3(0.5f, 2.0f, -1.0f);
    l.intensity = 800.0f;
    l.range = 10.0f;
    l.color = lx_v3(1.0f, 0.5f, 0.25f);
    const float pts[][3] = {{0, 0, 0}, {1, 0, 0}, {3, 0, -2}, {-4, 0.5f, 3}, {0.5f, 1.0f, -1.0f}};
    const float nrm[][3] = {{0, 1, 0}, {0, 1, 0}, {0.6f, 0.8f, 0}, {0, 0.8f, -0.6f}, {0, 1, 0}};
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
        lx_vec3 p = lx_v3(pts[i][0], pts[i][1], pts[i][2]);
        lx_vec3 n = lx_v3(nrm[i][0], nrm[i][1], nrm[i][2]);
        double lx = 0.5 - p.x, ly = 2.0 - p.y, lz = -1.0 - p.z;
        double d = sqrt(lx * lx + ly * ly + lz * lz);
        double cos_t = (lx * n.x + ly * n.y + lz * n.z) / d;
        double e = 800.0 * cos_t / (d * d) * window_ref(d, 10.0);
        lx_light_eval ev;
        assert_true(lx_light_evaluate(&l, p, n, &ev));
        /* the window near its edge (d = 5.2 of 10): measured 5.0e-7 */
        lx_test_assert_rel(ev.illuminance.x, e, 1.5e-6);
        lx_test_assert_rel(ev.illuminance.y, 0.5 * e, 1.5e-6);
        lx_test_assert_rel(ev.illuminance.z, 0.25 * e, 1.5e-6);
        lx_test_assert_rel(ev.distance, d, FLOAT_TOL);
        lx_test_assert_rel(ev.to_light.y, ly / d, FLOAT_TOL);
    }
    /* Behind the surface and out of range: no direct light. */
    lx_light_eval ev;
    assert_false(lx_light_evaluate(&l, lx_v3(0, 0, 0), lx_v3(0, -1, 0), &ev));
    assert_true(ev.illuminance.x == 0.0f);
    assert_false(lx_light_evaluate(&l, lx_v3(0.5f, -9.0f, -1.0f), lx_v3(0, 1, 0), &ev));
    /* Unlimited range: the pure inverse square law. */
    l.range = 0.0f;
    assert_true(lx_light_evaluate(&l, lx_v3(0.5f, -98.0f, -1.0f), lx_v3(0, 1, 0), &ev));
    lx_test_assert_rel(ev.illuminance.x, 800.0 / (100.0 * 100.0), FLOAT_TOL);
    /* Closer than 1 cm the distance is taken as 1 cm (Filament's 1e-4 m^2
     * floor): 5 mm above the point, facing the light, 800 / 1e-4 lx. */
    assert_true(lx_light_evaluate(&l, lx_v3(0.5f, 1.995f, -1.0f), lx_v3(0, 1, 0), &ev));
    lx_test_assert_rel(ev.illuminance.x, 800.0 / 1e-4, FLOAT_TOL);
    /* and beyond 1 cm, the inverse square itself: 2 cm (from 1.98f as stored) */
    assert_true(lx_light_evaluate(&l, lx_v3(0.5f, 1.98f, -1.0f), lx_v3(0, 1, 0), &ev));
    double h = 2.0 - (double)1.98f;
    lx_test_assert_rel(ev.illuminance.x, 800.0 / (h * h), FLOAT_TOL);
}

/* A spot 3 m above the floor pointing down; the floor point at angle deg. */
static lx_light_eval spot_at(const lx_light *l, double deg, bool *lit)
{
    lx_vec3 p = lx_v3((float)(3.0 * tan(deg * PI_D / 180.0)), 0.0f, 0.0f);
    lx_light_eval ev;
    *lit = lx_light_evaluate(l, p, lx_v3(0, 1, 0), &ev);
    return ev;
}

static double spot_ref(double deg, double inner, double outer, double intensity)
{
    double c = cos(deg * PI_D / 180.0);
    double ci = cos(inner * PI_D / 180.0), co = cos(outer * PI_D / 180.0);
    double t = (c - co) / fmax(ci - co, 1e-4);
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    double d = 3.0 / c;
    return intensity * t * t * c / (d * d);
}

static void test_spot(void **state)
{
    (void)state;
    lx_light l = named(LX_LIGHT_SPOT, "spot");
    l.position = lx_v3(0, 3, 0);
    l.direction = lx_v3(0, -1, 0);
    l.inner_angle = LX_DEG2RAD(20.0f);
    l.outer_angle = LX_DEG2RAD(30.0f);
    l.intensity = 1200.0f;
    assert_int_equal(lx_light_validate(&l), LX_OK);
    const double angles[] = {0.0, 10.0, 19.0, 22.0, 25.0, 28.0, 29.5};
    for (size_t i = 0; i < sizeof angles / sizeof angles[0]; i++) {
        bool lit;
        lx_light_eval ev = spot_at(&l, angles[i], &lit);
        assert_true(lit);
        /* the ramp from float cosines: measured 1.1e-5 (at 29.5 deg) */
        lx_test_assert_rel(ev.illuminance.x, spot_ref(angles[i], 20, 30, 1200), 4e-5);
    }
    /* Inside the inner cone the spot factor is exactly 1. */
    bool lit;
    lx_light_eval ev = spot_at(&l, 10.0, &lit);
    double c = cos(10.0 * PI_D / 180.0);
    lx_test_assert_rel(ev.illuminance.x, 1200.0 * c * c * c / 9.0, 5e-7); /* measured 1.3e-7 */
    spot_at(&l, 31.0, &lit);
    assert_false(lit);
    spot_at(&l, 60.0, &lit);
    assert_false(lit);
    /* The attenuation function itself, penumbra midpoint. */
    double ci = cos(20 * PI_D / 180), co = cos(30 * PI_D / 180);
    double t = ((ci + co) / 2 - co) / (ci - co);
    lx_test_assert_rel(lx_light_spot_attenuation(&l, (float)((ci + co) / 2)), t * t,
                       1.5e-5); /* float cosines: measured 3.8e-6 */
    /* Point lights have no cone. */
    lx_light p = lx_light_defaults(LX_LIGHT_POINT);
    assert_true(lx_light_spot_attenuation(&p, -1.0f) == 1.0f);
}

static void test_spot_hard_edge(void **state)
{
    (void)state;
    /* Blender writes innerConeAngle == outerConeAngle: a hard-edged cone. */
    lx_light l = named(LX_LIGHT_SPOT, "blender");
    l.position = lx_v3(0, 3, 0);
    l.inner_angle = l.outer_angle = LX_DEG2RAD(30.0f);
    l.intensity = 100.0f;
    assert_int_equal(lx_light_validate(&l), LX_OK);
    bool lit;
    lx_light_eval ev = spot_at(&l, 29.8, &lit);
    assert_true(lit);
    double c = cos(29.8 * PI_D / 180.0);
    lx_test_assert_rel(ev.illuminance.x, 100.0 * c * c * c / 9.0, FLOAT_TOL);
    ev = spot_at(&l, 0.0, &lit);
    assert_true(lit);
    lx_test_assert_rel(ev.illuminance.x, 100.0 / 9.0, FLOAT_TOL);
    spot_at(&l, 30.2, &lit);
    assert_false(lit);
    assert_true(lx_light_spot_attenuation(&l, cosf(LX_DEG2RAD(29.9f))) == 1.0f);
    assert_true(lx_light_spot_attenuation(&l, cosf(LX_DEG2RAD(30.1f))) == 0.0f);
    /* Zero-width cone at 0 deg inner: still valid. */
    l.inner_angle = 0.0f;
    l.outer_angle = LX_DEG2RAD(1.0f);
    assert_int_equal(lx_light_validate(&l), LX_OK);
}

static void test_directional(void **state)
{
    (void)state;
    lx_light l = named(LX_LIGHT_DIRECTIONAL, "sun");
    double dx = 0.3, dy = -1.0, dz = 0.2, len = sqrt(dx * dx + dy * dy + dz * dz);
    l.direction = lx_v3((float)(dx / len), (float)(dy / len), (float)(dz / len));
    l.intensity = 100000.0f;
    l.color = lx_v3(1.0f, 0.9f, 0.8f);
    lx_light_eval ev;
    assert_true(lx_light_evaluate(&l, lx_v3(100, -5, 3), lx_v3(0, 1, 0), &ev));
    double cos_t = -dy / len;
    lx_test_assert_rel(ev.illuminance.x, 100000.0 * cos_t, FLOAT_TOL);
    lx_test_assert_rel(ev.illuminance.y, 90000.0 * cos_t, FLOAT_TOL);
    assert_true(isinf(ev.distance));
    lx_test_assert_rel(ev.to_light.x, -dx / len, FLOAT_TOL);
    lx_test_assert_rel(ev.to_light.y, -dy / len, FLOAT_TOL);
    /* A wall facing +X gets cos = -dx/len < 0: dark. */
    assert_false(lx_light_evaluate(&l, lx_v3(0, 0, 0), lx_v3(1, 0, 0), &ev));
    assert_true(lx_light_evaluate(&l, lx_v3(0, 0, 0), lx_v3(-1, 0, 0), &ev));
    lx_test_assert_rel(ev.illuminance.x, 100000.0 * dx / len, FLOAT_TOL);
}

static void test_classic(void **state)
{
    (void)state;
    lx_light l = named(LX_LIGHT_POINT, "classic");
    l.model = LX_MODEL_CLASSIC;
    l.position = lx_v3(2, 1, 0);
    l.range = 5.0f;
    l.intensity = 1.5f;
    l.color = lx_v3(1.0f, 0.5f, 0.0f);
    assert_int_equal(lx_light_validate(&l), LX_OK);
    const float pts[][3] = {{2, 0, 1}, {0, 0, 0}, {4, -2, 1}, {2, 0.9f, 0}};
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++) {
        /* The document: val = (1 - dist/range) * |dot(lightVec, normal)|,
         * lit = val * val * color * intensity, when facing and in range. */
        double lx = 2.0 - pts[i][0], ly = 1.0 - pts[i][1], lz = 0.0 - pts[i][2];
        double d = sqrt(lx * lx + ly * ly + lz * lz);
        double dot = fabs(ly / d);
        double val = (1.0 - d / 5.0) * dot;
        lx_light_eval ev;
        assert_true(
            lx_light_evaluate(&l, lx_v3(pts[i][0], pts[i][1], pts[i][2]), lx_v3(0, 1, 0), &ev));
        /* (1 - d / range) from a float distance: measured 2.2e-7 */
        lx_test_assert_rel(ev.illuminance.x, val * val * 1.5, 8e-7);
        lx_test_assert_rel(ev.illuminance.y, val * val * 0.75, 8e-7);
        assert_true(ev.illuminance.z == 0.0f);
    }
    lx_light_eval ev;
    assert_false(lx_light_evaluate(&l, lx_v3(2, -4.5f, 0), lx_v3(0, 1, 0), &ev)); /* d > range */
    assert_false(lx_light_evaluate(&l, lx_v3(2, 0, 0), lx_v3(0, -1, 0), &ev));    /* behind */
    assert_true(ev.illuminance.x == 0.0f);
}

static void test_ambient(void **state)
{
    (void)state;
    lx_light red = named(LX_LIGHT_POINT, "red");
    red.position = lx_v3(0, 0, 0);
    red.range = 5.0f;
    red.ambient = lx_v3(0.1f, 0, 0);
    lx_light blue = named(LX_LIGHT_POINT, "blue");
    blue.position = lx_v3(1, 0, 0);
    blue.range = 6.0f;
    blue.ambient = lx_v3(0, 0, 0.2f);
    lx_vec3 p = lx_v3(0, 2.5f, 0);
    lx_light_eval a, b;
    lx_light_evaluate(&red, p, lx_v3(0, -1, 0), &a); /* facing away: ambient all the same */
    lx_light_evaluate(&blue, p, lx_v3(0, 1, 0), &b);
    lx_test_assert_rel(a.ambient.x, 0.1 * window_ref(2.5, 5.0), FLOAT_TOL);
    double db = sqrt(1.0 + 6.25);
    lx_test_assert_rel(b.ambient.z, 0.2 * window_ref(db, 6.0), FLOAT_TOL);
    lx_vec3 sum = lx_add(a.ambient, b.ambient); /* red + blue = purple */
    assert_true(sum.x > 0.0f && sum.z > 0.0f && sum.y == 0.0f);
    /* Out of reach: no ambient. */
    lx_light_evaluate(&red, lx_v3(0, 7, 0), lx_v3(0, 1, 0), &a);
    assert_true(a.ambient.x == 0.0f);
    /* Unlimited range and directional lights: ambient everywhere. */
    red.range = 0.0f;
    lx_light_evaluate(&red, lx_v3(0, 700, 0), lx_v3(0, 1, 0), &a);
    lx_test_assert_rel(a.ambient.x, 0.1, FLOAT_TOL);
    lx_light sun = named(LX_LIGHT_DIRECTIONAL, "sun");
    sun.ambient = lx_v3(0.3f, 0.2f, 0.1f);
    lx_light_evaluate(&sun, p, lx_v3(0, -1, 0), &a);
    lx_test_assert_rel(a.ambient.y, 0.2, FLOAT_TOL);
}

static void test_blur(void **state)
{
    (void)state;
    lx_light l = named(LX_LIGHT_POINT, "b");
    l.shadow = LX_SHADOW_BLUR;
    lx_test_assert_rel(lx_light_blur_visibility(&l, 1.0f, 4.0f), 0.25, FLOAT_TOL);
    l.blur_power = 2.0f;
    lx_test_assert_rel(lx_light_blur_visibility(&l, 1.0f, 4.0f), 1.0 / 16.0, FLOAT_TOL);
    l.blur_multiplier = 3.0f;
    lx_test_assert_rel(lx_light_blur_visibility(&l, 1.0f, 4.0f), 3.0 / 16.0, FLOAT_TOL);
    l.blur_multiplier = 100.0f;
    assert_true(lx_light_blur_visibility(&l, 1.0f, 4.0f) == 1.0f);
    assert_true(lx_light_blur_visibility(&l, 0.0f, 4.0f) == 0.0f);
    assert_true(lx_light_blur_visibility(&l, 1.0f, 0.0f) == 0.0f);
}

static void test_conversions(void **state)
{
    (void)state;
    lx_light p = named(LX_LIGHT_POINT, "p");
    float v;
    assert_int_equal(lx_light_intensity_to_native(&p, 1000, LX_UNIT_LUMEN, 0, &v), LX_OK);
    lx_test_assert_rel(v, 1000.0 / (4.0 * PI_D), FLOAT_TOL);
    assert_int_equal(lx_light_intensity_to_native(&p, 10, LX_UNIT_WATT, 0, &v), LX_OK);
    lx_test_assert_rel(v, 6830.0 / (4.0 * PI_D), FLOAT_TOL); /* 10 W = 6830 lm */
    assert_int_equal(lx_light_intensity_to_native(&p, 42, LX_UNIT_CANDELA, 0, &v), LX_OK);
    assert_true(v == 42.0f);
    assert_int_equal(lx_light_intensity_to_native(&p, 42, LX_UNIT_DEFAULT, 0, &v), LX_OK);
    assert_true(v == 42.0f);
    assert_fails(lx_light_intensity_to_native(&p, 1, LX_UNIT_LUX, 0, &v), LX_ERR_INVALID,
                 "light 'p': point lights take cd, lm or W, not lx");

    lx_light s = named(LX_LIGHT_SPOT, "s");
    s.outer_angle = LX_DEG2RAD(30.0f);
    assert_int_equal(lx_light_intensity_to_native(&s, 1000, LX_UNIT_LUMEN, LX_SPOT_POWER_PI, &v),
                     LX_OK);
    lx_test_assert_rel(v, 1000.0 / PI_D, FLOAT_TOL);
    assert_int_equal(lx_light_intensity_to_native(&s, 1000, LX_UNIT_LUMEN, LX_SPOT_POWER_CONE, &v),
                     LX_OK);
    lx_test_assert_rel(v, 1000.0 / (2.0 * PI_D * (1.0 - cos(30.0 * PI_D / 180.0))), FLOAT_TOL);
    assert_int_equal(lx_light_intensity_to_native(&s, 2, LX_UNIT_WATT, LX_SPOT_POWER_CONE, &v),
                     LX_OK);
    lx_test_assert_rel(v, 1366.0 / (2.0 * PI_D * (1.0 - cos(30.0 * PI_D / 180.0))), FLOAT_TOL);

    lx_light d = named(LX_LIGHT_DIRECTIONAL, "sun");
    assert_int_equal(lx_light_intensity_to_native(&d, 1e5f, LX_UNIT_LUX, 0, &v), LX_OK);
    assert_true(v == 1e5f);
    const lx_light_unit bad[] = {LX_UNIT_WATT, LX_UNIT_LUMEN, LX_UNIT_CANDELA};
    for (int i = 0; i < 3; i++)
        assert_fails(lx_light_intensity_to_native(&d, 1, bad[i], 0, &v), LX_ERR_INVALID,
                     "directional lights take lux");
    assert_fails(lx_light_intensity_to_native(&p, -1, LX_UNIT_LUMEN, 0, &v), LX_ERR_INVALID,
                 "negative");
    assert_fails(lx_light_intensity_to_native(&p, NAN, LX_UNIT_LUMEN, 0, &v), LX_ERR_INVALID,
                 "not finite");
}

static void test_unit_names(void **state)
{
    (void)state;
    const struct {
        const char *s;
        lx_light_unit u;
    } cases[] = {{"cd", LX_UNIT_CANDELA},  {"candela", LX_UNIT_CANDELA}, {"lm", LX_UNIT_LUMEN},
                 {"lumen", LX_UNIT_LUMEN}, {"W", LX_UNIT_WATT},          {"watt", LX_UNIT_WATT},
                 {"lx", LX_UNIT_LUX},      {"lux", LX_UNIT_LUX},         {"kW", LX_UNIT_DEFAULT},
                 {"", LX_UNIT_DEFAULT},    {"lumenx", LX_UNIT_DEFAULT}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        assert_int_equal(lx_light_unit_from_string(cases[i].s), cases[i].u);
    assert_int_equal(lx_light_unit_from_string(NULL), LX_UNIT_DEFAULT);
    assert_string_equal(lx_light_unit_symbol(LX_UNIT_CANDELA), "cd");
    assert_string_equal(lx_light_unit_symbol(LX_UNIT_LUMEN), "lm");
    assert_string_equal(lx_light_unit_symbol(LX_UNIT_WATT), "W");
    assert_string_equal(lx_light_unit_symbol(LX_UNIT_LUX), "lx");
    assert_string_equal(lx_light_type_name(LX_LIGHT_POINT), "point");
    assert_string_equal(lx_light_type_name(LX_LIGHT_SPOT), "spot");
    assert_string_equal(lx_light_type_name(LX_LIGHT_DIRECTIONAL), "directional");
    assert_string_equal(lx_shadow_mode_name(LX_SHADOW_NONE), "none");
    assert_string_equal(lx_shadow_mode_name(LX_SHADOW_HARD), "hard");
    assert_string_equal(lx_shadow_mode_name(LX_SHADOW_BLUR), "blur");
}

static void test_exposure(void **state)
{
    (void)state;
    lx_test_assert_rel(lx_exposure_from_ev100(0.0f), 1.0 / 1.2, FLOAT_TOL);
    lx_test_assert_rel(lx_exposure_from_ev100(1.0f), 1.0 / 2.4, FLOAT_TOL);
    lx_test_assert_rel(lx_exposure_from_ev100(15.0f), 1.0 / (1.2 * 32768.0), FLOAT_TOL);
    /* EV100 = log2(L * 100 / 12.5): 0.125 nits -> 0 (measured exactly 0),
     * 12.5 nits -> log2(100). */
    assert_true(fabsf(lx_ev100_from_luminance(0.125)) < 1e-7f);
    lx_test_assert_rel(lx_ev100_from_luminance(12.5), log2(100.0), FLOAT_TOL);
    lx_test_assert_rel(lx_ev100_from_luminance(0.25), 1.0, FLOAT_TOL);
    assert_true(lx_ev100_from_luminance(0.0) == 0.0f);
    assert_true(lx_ev100_from_luminance(-3.0) == 0.0f);
}

static void test_validation(void **state)
{
    (void)state;
    lx_light l = named(LX_LIGHT_SPOT, "key");
    l.inner_angle = LX_DEG2RAD(40.0f);
    l.outer_angle = LX_DEG2RAD(30.0f);
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID,
                 "light 'key': inner_angle 40 deg is above outer_angle 30 deg");
    l = named(LX_LIGHT_SPOT, "key");
    l.outer_angle = LX_DEG2RAD(100.0f);
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "outer_angle 100 deg is above 90 deg");
    l.outer_angle = 0.0f;
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "outer_angle 0 deg must be above 0");
    l = named(LX_LIGHT_SPOT, "key");
    l.outer_angle = LX_PI / 2.0f; /* the limit itself is allowed */
    assert_int_equal(lx_light_validate(&l), LX_OK);
    l.direction = lx_v3(0, -2, 0);
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "direction [0, -2, 0] is not unit length");
    l.direction = lx_v3(0, -1.0005f, 0); /* inside the 1e-3 tolerance */
    assert_int_equal(lx_light_validate(&l), LX_OK);

    l = named(LX_LIGHT_POINT, "key");
    l.intensity = -1.0f;
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "light 'key': intensity -1 is negative");
    l = named(LX_LIGHT_POINT, "key");
    l.position.y = NAN;
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "position is not finite");
    l = named(LX_LIGHT_POINT, "key");
    l.range = -2.0f;
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "range -2 is negative");
    l = named(LX_LIGHT_POINT, "key");
    l.model = LX_MODEL_CLASSIC;
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "classic model needs a range");
    l = named(LX_LIGHT_POINT, "key");
    l.blur_power = -1.0f;
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "blur_power -1 is negative");
    l = named(LX_LIGHT_POINT, "key");
    l.blur_multiplier = INFINITY;
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "blur_multiplier is not finite");
    l = named(LX_LIGHT_POINT, "key");
    l.ambient = lx_v3(0.1f, -0.1f, 0.0f);
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "ambient");
    l = named(LX_LIGHT_POINT, "key");
    l.color = lx_v3(1.0f, INFINITY, 0.0f);
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "color is not finite");
    l = named(LX_LIGHT_DIRECTIONAL, "sun");
    l.direction = lx_v3(0, 0, 0);
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "light 'sun': direction");
    l = lx_light_defaults(LX_LIGHT_POINT);
    l.type = (lx_light_type)7;
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "light (unnamed): type 7");
    l = lx_light_defaults(LX_LIGHT_POINT);
    memset(l.name, 'x', sizeof l.name);
    assert_fails(lx_light_validate(&l), LX_ERR_INVALID, "not NUL-terminated");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_range_window),
        cmocka_unit_test(test_point_inverse_square),
        cmocka_unit_test(test_spot),
        cmocka_unit_test(test_spot_hard_edge),
        cmocka_unit_test(test_directional),
        cmocka_unit_test(test_classic),
        cmocka_unit_test(test_ambient),
        cmocka_unit_test(test_blur),
        cmocka_unit_test(test_conversions),
        cmocka_unit_test(test_unit_names),
        cmocka_unit_test(test_exposure),
        cmocka_unit_test(test_validation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
