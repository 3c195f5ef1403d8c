/* The material preview (lx_shade) against the seed's formulas evaluated
 * here in double: on a flat height the normal is +z, so every pixel is
 * base/pi (E sat(l.z) + ambient) + spec E sat(h.z)^a [l.z > 0] with the
 * view from the camera geometry (quad: the plane z = 0 under the pixel,
 * camera at (0, 0, 1/tan(fov/2)); sphere centre: normal +z too). Horizon
 * shadows and parallax change nothing on a flat field; a step of H texels
 * shadows a texel d texels before it when the light's elevation is below
 * the closed-form horizon (and never above atan(H/d)). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"
#include "luxel/maps.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

static void light_of(double az, double el, double l[3])
{
    az *= PI / 180, el *= PI / 180;
    l[0] = cos(el) * cos(az), l[1] = cos(el) * sin(az), l[2] = sin(el);
}

/* The expected colour channel c of quad pixel (i, j) with normal +z. */
static double flat_quad(const lx_shade_desc *d, int i, int j, int c, double base)
{
    int W = d->out_width, H = d->out_height;
    double aspect = (double)W / H, D = 1 / tan(d->fov * PI / 360);
    double sx = (2.0 * (i + 0.5) / W - 1) * aspect, sy = 1 - 2.0 * (j + 0.5) / H;
    double v[3] = {-sx, -sy, D}, lv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] /= lv;
    double l[3] = {d->light.x, d->light.y, d->light.z};
    double hh[3] = {l[0] + v[0], l[1] + v[1], l[2] + v[2]};
    double hz = hh[2] / sqrt(hh[0] * hh[0] + hh[1] * hh[1] + hh[2] * hh[2]);
    double E = d->light_color[c] * d->illuminance;
    double nl = l[2] > 0 ? l[2] : 0;
    double spec = l[2] > 0 && !d->no_specular ? pow(hz, d->exponent) : 0;
    return base / PI * (E * nl + d->ambient) + d->specular[c] * E * spec;
}

static lx_image flat(int w, int h, float value)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, w, h, 1), LX_OK);
    for (int i = 0; i < w * h; i++)
        img.data[i] = value;
    return img;
}

static lx_shade_desc flat_desc(const lx_image *hf, int size)
{
    double l[3];
    light_of(30, 50, l);
    lx_shade_desc d = {.height = hf,
                       .light = lx_v3((float)l[0], (float)l[1], (float)l[2]),
                       .light_color = {1.0f, 0.5f, 0.25f},
                       .illuminance = 2.0f,
                       .ambient = 0.3f,
                       .fov = 40.0f,
                       .specular = {0.1f, 0.2f, 0.3f},
                       .exponent = 20.0f,
                       .out_width = size,
                       .out_height = size,
                       .threads = 2};
    return d;
}

static void flat_quad_and_sphere(void **state)
{
    (void)state;
    lx_image hf = flat(32, 32, 0.5f), img;
    lx_shade_desc d = flat_desc(&hf, 33);
    assert_int_equal(lx_shade(&d, &img), LX_OK);
    assert_int_equal(img.channels, 3);
    int pix[][2] = {{16, 16}, {0, 0}, {32, 5}, {7, 30}};
    for (size_t p = 0; p < sizeof pix / sizeof pix[0]; p++)
        for (int c = 0; c < 3; c++) {
            double want = flat_quad(&d, pix[p][0], pix[p][1], c, 0.8);
            double got = img.data[(pix[p][1] * 33 + pix[p][0]) * 3 + c];
            assert_float_equal(got, want, 2e-6 * want + 1e-7);
        }
    lx_image_free(&img);
    /* the sphere's centre pixel: normal +z, view +z, as the quad's centre */
    d.shape = LX_SHADE_SPHERE;
    assert_int_equal(lx_shade(&d, &img), LX_OK);
    for (int c = 0; c < 3; c++)
        assert_float_equal(img.data[(16 * 33 + 16) * 3 + c], flat_quad(&d, 16, 16, c, 0.8),
                           1e-5);
    /* corners are off the sphere: black */
    assert_true(img.data[0] == 0.0f && img.data[1] == 0.0f && img.data[2] == 0.0f);
    lx_image_free(&img);
    lx_image_free(&hf);
}

/* Horizon and parallax on or off: the same bytes on a flat field (height 0
 * for parallax, so the base colour's checker is not moved). */
static void flat_on_off(void **state)
{
    (void)state;
    lx_image hf = flat(24, 20, 0.0f), base;
    assert_int_equal(lx_image_alloc(&base, 24, 20, 3), LX_OK);
    for (int i = 0; i < 24 * 20 * 3; i++)
        base.data[i] = ((i / 3) % 24 / 4 + (i / 3) / 24 / 4) % 2 ? 0.9f : 0.2f;
    for (int shape = 0; shape < 2; shape++) {
        lx_shade_desc d = flat_desc(&hf, 41);
        d.shape = (lx_shade_shape)shape;
        d.base_color = &base;
        lx_image all, nohz, nopx;
        assert_int_equal(lx_shade(&d, &all), LX_OK);
        d.no_horizon = true;
        assert_int_equal(lx_shade(&d, &nohz), LX_OK);
        d.no_horizon = false;
        d.no_parallax = true;
        assert_int_equal(lx_shade(&d, &nopx), LX_OK);
        size_t n = (size_t)41 * 41 * 3;
        assert_memory_equal(all.data, nohz.data, n * sizeof(float));
        assert_memory_equal(all.data, nopx.data, n * sizeof(float));
        /* threads do not change the result */
        lx_image one;
        d.threads = 1;
        assert_int_equal(lx_shade(&d, &one), LX_OK);
        assert_memory_equal(one.data, nopx.data, n * sizeof(float));
        lx_image_free(&one);
        lx_image_free(&all);
        lx_image_free(&nohz);
        lx_image_free(&nopx);
    }
    lx_image_free(&base);
    lx_image_free(&hf);
}

/* A step of H = 4 texels at x = 40 (heights 0 before it, 1 from it on,
 * strength 4), lit from +x at elevation e: texel 40 - d is fully lit when
 * sin e >= sin atan(H / d) (no texel can rise higher), and dark when
 * sin e is 1/8 (the shading function's ramp) below the horizon its
 * direction's bins see at worst: atan(H / (d / cos 22.5 deg + 1.5)). */
static void step_shadow(void **state)
{
    (void)state;
    int W = 64, Hh = 8;
    double Hwall = 4.0;
    lx_image hf = flat(W, Hh, 0.0f);
    for (int y = 0; y < Hh; y++)
        for (int x = 40; x < W; x++)
            hf.data[y * W + x] = 1.0f;
    int lit = 0, dark = 0;
    double els[] = {3, 8, 12, 18, 25, 35, 50, 65};
    for (size_t k = 0; k < sizeof els / sizeof els[0]; k++) {
        double l[3];
        light_of(0, els[k], l);
        lx_shade_desc d = {.height = &hf,
                           .strength = (float)Hwall,
                           .wrap = LX_WRAP_CLAMP,
                           .light = lx_v3((float)l[0], (float)l[1], (float)l[2]),
                           .illuminance = 1.0f,
                           .fov = 30.0f,
                           .no_specular = true,
                           .no_parallax = true, /* the wide frame's views move UVs far */
                           .out_width = W,
                           .out_height = Hh,
                           .threads = 2};
        d = lx_shade_desc_defaults(&d);
        lx_image img;
        assert_int_equal(lx_shade(&d, &img), LX_OK);
        double se = sin(els[k] * PI / 180);
        for (int dd = 2; dd <= 12; dd++) {
            int x = 40 - dd, y = Hh / 2;
            double got = img.data[(y * W + x) * 3];
            double full = flat_quad(&d, x, y, 0, 0.8);
            double top = sin(atan(Hwall / dd));
            double low = sin(atan(Hwall / (dd / cos(22.5 * PI / 180) + 1.5))) - 0.125;
            if (se >= top) {
                assert_float_equal(got, full, 1e-5);
                lit++;
            } else if (se < low) {
                assert_float_equal(got, 0.0, 1e-7);
                dark++;
            } else {
                assert_true(got >= -1e-7 && got <= full + 1e-5);
            }
        }
        /* on top of the step, nothing rises: lit */
        assert_float_equal(img.data[((Hh / 2) * W + 50) * 3], flat_quad(&d, 50, Hh / 2, 0, 0.8),
                           1e-5);
        lx_image_free(&img);
    }
    assert_true(lit > 10 && dark > 10);
    lx_image_free(&hf);
}

/* Normals given (y up, or y flipped with green_down) shade as the normals
 * the heights give, bit for bit, with parallax and horizon off. */
static void normals_input(void **state)
{
    (void)state;
    lx_image hf = flat(16, 12, 0.0f), nm, a, b;
    for (int i = 0; i < 16 * 12; i++)
        hf.data[i] = (float)((i * 37 % 11) / 10.0);
    lx_normalmap_desc nd = {.strength = 5.0f, .wrap = LX_WRAP_MIRROR};
    assert_int_equal(lx_normal_map(&hf, &nd, &nm), LX_OK);
    lx_shade_desc d = flat_desc(&hf, 29);
    d.strength = 5.0f;
    d.wrap = LX_WRAP_MIRROR;
    d.no_parallax = d.no_horizon = true;
    d.shape = LX_SHADE_SPHERE;
    assert_int_equal(lx_shade(&d, &a), LX_OK);
    d.height = NULL;
    d.normals = &nm;
    assert_int_equal(lx_shade(&d, &b), LX_OK);
    assert_memory_equal(a.data, b.data, sizeof(float) * 29 * 29 * 3);
    lx_image_free(&b);
    for (int i = 0; i < 16 * 12; i++)
        nm.data[i * 3 + 1] = -nm.data[i * 3 + 1];
    d.green_down = true;
    assert_int_equal(lx_shade(&d, &b), LX_OK);
    assert_memory_equal(a.data, b.data, sizeof(float) * 29 * 29 * 3);
    lx_image_free(&a);
    lx_image_free(&b);
    lx_image_free(&nm);
    lx_image_free(&hf);
}

static void bad_inputs(void **state)
{
    (void)state;
    lx_image img, hf = flat(4, 4, 0.0f), rgb;
    lx_shade_desc d = {0};
    assert_int_equal(lx_shade(&d, &img), LX_ERR_INVALID);
    assert_null(img.data);
    assert_int_equal(lx_image_alloc(&rgb, 4, 4, 3), LX_OK);
    memset(rgb.data, 0, sizeof(float) * 48);
    d.height = &rgb;
    assert_int_equal(lx_shade(&d, &img), LX_ERR_INVALID);
    d.height = &hf;
    d.fov = 200.0f;
    assert_int_equal(lx_shade(&d, &img), LX_ERR_INVALID);
    d.fov = 0.0f;
    d.light = lx_v3(NAN, 0, 1);
    assert_int_equal(lx_shade(&d, &img), LX_ERR_INVALID);
    lx_image_free(&rgb);
    lx_image_free(&hf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(flat_quad_and_sphere),
        cmocka_unit_test(flat_on_off),
        cmocka_unit_test(step_shadow),
        cmocka_unit_test(normals_input),
        cmocka_unit_test(bad_inputs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
