/* Normal blending against Barre-Brisebois and Hill, "Blending in Detail"
 * (2012), written here as the article gives them, on texture values in
 * [0,1] (its shader code), in double:
 *   RNM:      t = tex_b * ( 2, 2, 2) + (-1, -1,  0)
 *             u = tex_d * (-2,-2, 2) + ( 1,  1, -1)
 *             r = t * dot(t, u) / t.z - u
 *   UDN:      n1 = 2 tex_b - 1, n2 = 2 tex_d - 1,
 *             r = normalize(n1.xy + n2.xy, n1.z)
 *   Whiteout: r = normalize(n1.xy + n2.xy, n1.z * n2.z)
 * and invariants of RNM: a flat detail leaves the base, a flat base gives
 * the detail, and the detail's angle from +z is kept as the angle from the
 * base (a rotation). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"
#include "luxel/maps.h"

#include <math.h>
#include <string.h>

static void article(lx_normal_blend_method m, const double tb[3], const double td[3], double r[3])
{
    if (m == LX_BLEND_RNM) {
        double t[3] = {tb[0] * 2 - 1, tb[1] * 2 - 1, tb[2] * 2};
        double u[3] = {td[0] * -2 + 1, td[1] * -2 + 1, td[2] * 2 - 1};
        double dot = t[0] * u[0] + t[1] * u[1] + t[2] * u[2];
        for (int k = 0; k < 3; k++)
            r[k] = t[k] * dot / t[2] - u[k];
    } else {
        double n1[3], n2[3];
        for (int k = 0; k < 3; k++) {
            n1[k] = 2 * tb[k] - 1;
            n2[k] = 2 * td[k] - 1;
        }
        r[0] = n1[0] + n2[0];
        r[1] = n1[1] + n2[1];
        r[2] = m == LX_BLEND_UDN ? n1[2] : n1[2] * n2[2];
    }
    double len = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int k = 0; k < 3; k++)
        r[k] /= len;
}

/* A unit vector in the upper hemisphere from two numbers in [0,1). */
static lx_vec3 hemisphere(double a, double b)
{
    double z = 0.05 + 0.95 * a, phi = 2 * 3.14159265358979 * b, s = sqrt(1 - z * z);
    return lx_v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)z);
}

static double worst; /* the largest difference checked */

static void check(lx_vec3 got, const double want[3], double tol)
{
    for (int k = 0; k < 3; k++)
        worst = fmax(worst, fabs((k == 0 ? got.x : k == 1 ? got.y : got.z) - want[k]));
    if (fabs(got.x - want[0]) > tol || fabs(got.y - want[1]) > tol || fabs(got.z - want[2]) > tol)
        fail_msg("(%g, %g, %g), want (%g, %g, %g)", got.x, got.y, got.z, want[0], want[1],
                 want[2]);
}

/* Random unit pairs: each method equals the article's formula on the
 * texture values n/2 + 1/2 of the same vectors (float rounding: measured
 * 3e-8). */
static void published_formulas(void **state)
{
    (void)state;
    uint32_t s = 7;
    for (int i = 0; i < 2000; i++) {
        double q[4];
        for (int k = 0; k < 4; k++) {
            s = s * 1664525u + 1013904223u;
            q[k] = (s >> 8) / 16777216.0;
        }
        lx_vec3 b = hemisphere(q[0], q[1]), d = hemisphere(q[2], q[3]);
        double tb[3] = {b.x / 2.0 + 0.5, b.y / 2.0 + 0.5, b.z / 2.0 + 0.5};
        double td[3] = {d.x / 2.0 + 0.5, d.y / 2.0 + 0.5, d.z / 2.0 + 0.5};
        for (int m = 0; m < 3; m++) {
            double want[3];
            article((lx_normal_blend_method)m, tb, td, want);
            check(lx_normal_blend((lx_normal_blend_method)m, b, d), want, 2e-7);
        }
    }
    print_message("largest difference from the article's formulas: %.2g\n", worst);
}

static double dot3(lx_vec3 a, lx_vec3 b)
{
    return (double)a.x * b.x + (double)a.y * b.y + (double)a.z * b.z;
}

static void rnm_is_a_rotation(void **state)
{
    (void)state;
    lx_vec3 up = lx_v3(0, 0, 1);
    for (int i = 0; i < 50; i++) {
        lx_vec3 b = hemisphere(i / 50.0, i * 0.618), d = hemisphere(0.3 + i / 80.0, i * 0.377);
        lx_vec3 r = lx_normal_blend(LX_BLEND_RNM, b, d);
        assert_float_equal(dot3(r, r), 1.0, 1e-6);
        /* angle(base, result) = angle(+z, detail) */
        assert_float_equal(dot3(b, r), d.z, 1e-6);
        double fb[3] = {b.x, b.y, b.z}, fd[3] = {d.x, d.y, d.z};
        check(lx_normal_blend(LX_BLEND_RNM, b, up), fb, 1e-6);
        check(lx_normal_blend(LX_BLEND_RNM, up, d), fd, 1e-6);
    }
}

static void names(void **state)
{
    (void)state;
    lx_normal_blend_method m;
    assert_true(lx_normal_blend_parse("whiteout", &m));
    assert_int_equal(m, LX_BLEND_WHITEOUT);
    assert_string_equal(lx_normal_blend_name(LX_BLEND_RNM), "rnm");
    assert_false(lx_normal_blend_parse("linear", &m));
}

/* The image version blends texel by texel and refuses different sizes. */
static void images(void **state)
{
    (void)state;
    lx_image b, d, out;
    assert_int_equal(lx_image_alloc(&b, 5, 3, 3), LX_OK);
    assert_int_equal(lx_image_alloc(&d, 5, 3, 4), LX_OK);
    for (int i = 0; i < 15; i++) {
        lx_vec3 vb = hemisphere(i / 15.0, i * 0.31), vd = hemisphere(1 - i / 16.0, i * 0.77);
        memcpy(b.data + 3 * i, &vb, sizeof vb);
        d.data[4 * i] = vd.x, d.data[4 * i + 1] = vd.y, d.data[4 * i + 2] = vd.z;
        d.data[4 * i + 3] = 0.25f;
    }
    for (int m = 0; m < 3; m++) {
        assert_int_equal(lx_normal_blend_image((lx_normal_blend_method)m, &b, &d, 2, &out),
                         LX_OK);
        assert_int_equal(out.channels, 3);
        for (int i = 0; i < 15; i++) {
            lx_vec3 want = lx_normal_blend(
                (lx_normal_blend_method)m, lx_v3(b.data[3 * i], b.data[3 * i + 1], b.data[3 * i + 2]),
                lx_v3(d.data[4 * i], d.data[4 * i + 1], d.data[4 * i + 2]));
            assert_memory_equal(out.data + 3 * i, &want, sizeof want);
        }
        lx_image_free(&out);
    }
    lx_image small;
    assert_int_equal(lx_image_alloc(&small, 4, 3, 3), LX_OK);
    assert_int_equal(lx_normal_blend_image(LX_BLEND_RNM, &b, &small, 0, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "5x3"));
    assert_null(out.data);
    lx_image_free(&small);
    lx_image_free(&b);
    lx_image_free(&d);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(published_formulas),
        cmocka_unit_test(rnm_is_a_rotation),
        cmocka_unit_test(names),
        cmocka_unit_test(images),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
