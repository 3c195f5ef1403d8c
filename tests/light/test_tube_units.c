/* Units of linear tube lights (radius 0, intensity in cd per metre
 * across the axis; src/light/units.c):
 * - lux is no unit for a tube, linear or not (it was taken as lumens);
 * - watts and lumens go through the power of a Lambertian line,
 *   P = pi^2 I L (the integral of I L sin(alpha) over the sphere), checked
 *   by the illuminance at the middle of the tube facing it, worked out
 *   here: E = I (a / (a^2 + h^2) + atan(a / h) / h) for a half-length a at
 *   distance h (the integral of I h^2 / (s^2 + h^2)^2 over the segment). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "helpers.h"

#define PI_D 3.14159265358979323846

static lx_light linear_tube(float length)
{
    lx_light l = lx_light_defaults(LX_LIGHT_TUBE);
    strcpy(l.name, "strip");
    l.radius = 0.0f;
    l.length = length;
    l.position = lx_v3(0.0f, 2.0f, 0.0f);
    l.direction = lx_v3(1.0f, 0.0f, 0.0f);
    return l;
}

static void lux_is_not_a_tube_unit(void **state)
{
    (void)state;
    float native = -1.0f;
    lx_light l = linear_tube(1.0f);
    lx_status st = lx_light_intensity_to_native(&l, 100.0f, LX_UNIT_LUX, LX_SPOT_POWER_PI, &native);
    if (st != LX_ERR_INVALID)
        fail_msg("a linear tube took 100 lx (status %s, %g cd/m)", lx_status_name(st),
                 (double)native);
    assert_non_null(strstr(lx_last_error(), "lx"));
    assert_non_null(strstr(lx_last_error(), "strip"));
    /* and a capsule, as before */
    l.radius = 0.02f;
    assert_int_equal(
        lx_light_intensity_to_native(&l, 100.0f, LX_UNIT_LUX, LX_SPOT_POWER_PI, &native),
        LX_ERR_INVALID);
}

static void power_of_a_linear_tube(void **state)
{
    (void)state;
    const double length = 4.0, h = 0.5, a = 0.5 * length;
    lx_light l = linear_tube((float)length);
    /* 10 W at 683 lm/W */
    assert_int_equal(
        lx_light_intensity_to_native(&l, 10.0f, LX_UNIT_WATT, LX_SPOT_POWER_PI, &l.intensity),
        LX_OK);
    double per_metre = 10.0 * 683.0 / (PI_D * PI_D * length);
    lx_test_assert_rel(l.intensity, per_metre, 2e-7); /* a float: measured 3.8e-9 */
    assert_int_equal(lx_light_validate(&l), LX_OK);
    /* below the middle of the tube, facing it */
    lx_light_eval e;
    lx_vec3 p = lx_v3(0.0f, 2.0f - (float)h, 0.0f);
    assert_true(lx_light_evaluate(&l, p, lx_v3(0.0f, 1.0f, 0.0f), &e));
    double want = per_metre * (a / (a * a + h * h) + atan(a / h) / h);
    lx_test_assert_rel(e.illuminance.x, want, 2e-7); /* a float: measured 3.0e-8 */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(lux_is_not_a_tube_unit),
        cmocka_unit_test(power_of_a_linear_tube),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
