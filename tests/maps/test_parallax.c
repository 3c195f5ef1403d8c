/* Parallax maps and offsets against their formulas (FGED vol. 2 sec.
 * 7.7): the map is n.z h with n.z = 1 / sqrt(1 + S^2 |grad h|^2) (a plane
 * gives it in closed form; a flat field gives h itself), and the offset
 * iterates uv += p(uv) (v.x s_u, -v.y s_v) with p bilinear between texel
 * centres, computed here independently in double: a constant map moves uv
 * by N p, a ramp follows the recurrence u <- u + k (a + b u), the wrap
 * modes address texels beyond the edges. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"
#include "luxel/maps.h"

#include <math.h>
#include <string.h>

static void plane_map(void **state)
{
    (void)state;
    int W = 16, H = 11;
    double a = 1.0 / 50, b = 1.0 / 70, S = 12;
    lx_image h, p;
    assert_int_equal(lx_image_alloc(&h, W, H, 1), LX_OK);
    for (int r = 0; r < H; r++)
        for (int x = 0; x < W; x++)
            h.data[r * W + x] = (float)(0.2 + a * x + b * (H - 1 - r));
    lx_normalmap_desc d = {.strength = (float)S, .wrap = LX_WRAP_CLAMP};
    assert_int_equal(lx_parallax_map(&h, &d, &p), LX_OK);
    assert_int_equal(p.channels, 1);
    assert_int_equal(p.width, W);
    assert_int_equal(p.height, H);
    double nz = 1 / sqrt(1 + S * S * (a * a + b * b));
    for (int r = 1; r < H - 1; r++)
        for (int x = 1; x < W - 1; x++)
            assert_float_equal(p.data[r * W + x], nz * h.data[r * W + x], 2e-7);
    lx_image_free(&p);
    /* a flat field: p = h exactly */
    for (int i = 0; i < W * H; i++)
        h.data[i] = 0.625f;
    assert_int_equal(lx_parallax_map(&h, NULL, &p), LX_OK);
    for (int i = 0; i < W * H; i++)
        assert_true(p.data[i] == 0.625f);
    lx_image_free(&p);
    lx_image_free(&h);
}

static void constant_offset(void **state)
{
    (void)state;
    lx_image p;
    assert_int_equal(lx_image_alloc(&p, 7, 5, 1), LX_OK);
    for (int i = 0; i < 35; i++)
        p.data[i] = 0.5f;
    float scale[2] = {0.1f, 0.2f};
    lx_vec3 v = lx_v3(0.6f, 0.48f, 0.64f);
    for (int it = 0; it <= 6; it++) {
        int n = it ? it : 4; /* 0 = the seed's 4 */
        lx_vec2 uv = lx_parallax_offset(&p, LX_WRAP_REPEAT, lx_v2(0.3f, 0.4f), v, scale, it);
        assert_float_equal(uv.x, 0.3 + n * 0.5 * 0.6 * 0.1, 1e-6);
        assert_float_equal(uv.y, 0.4 - n * 0.5 * 0.48 * 0.2, 1e-6);
    }
    lx_image_free(&p);
}

/* p(texel x) = a + b x along a row: between texel centres the bilinear
 * sample is a + b (u W - 0.5); iterating u <- u + k p(u) (k = v.x s_u)
 * from inside the image stays inside for these numbers. */
static void ramp_recurrence(void **state)
{
    (void)state;
    int W = 40, H = 3;
    double a = 0.1, b = 0.02;
    lx_image p;
    assert_int_equal(lx_image_alloc(&p, W, H, 1), LX_OK);
    for (int r = 0; r < H; r++)
        for (int x = 0; x < W; x++)
            p.data[r * W + x] = (float)(a + b * x);
    float scale[2] = {0.05f, 0.05f};
    lx_vec3 v = lx_v3(0.8f, 0.0f, 0.6f);
    double k = 0.8 * 0.05;
    for (int iters = 1; iters <= 8; iters++) {
        double u = 0.2;
        for (int i = 0; i < iters; i++)
            u += k * (a + b * (u * W - 0.5));
        lx_vec2 uv = lx_parallax_offset(&p, LX_WRAP_CLAMP, lx_v2(0.2f, 0.5f), v, scale, iters);
        assert_float_equal(uv.x, u, 2e-6);
        assert_float_equal(uv.y, 0.5, 1e-7);
    }
    lx_image_free(&p);
}

/* One step from u between the last texel centre and the edge: repeat
 * blends the last and first texels, clamp holds the last, mirror blends
 * the last with itself (the edge texel repeated). */
static void wrap_at_the_edge(void **state)
{
    (void)state;
    int W = 4;
    lx_image p;
    assert_int_equal(lx_image_alloc(&p, W, 1, 1), LX_OK);
    float row[4] = {0.8f, 0.1f, 0.2f, 0.4f};
    memcpy(p.data, row, sizeof row);
    float scale[2] = {1.0f, 1.0f};
    lx_vec3 v = lx_v3(1, 0, 0);
    double u = (W - 0.5 + 0.25) / W; /* a quarter past the last centre */
    double want[3];
    want[LX_WRAP_REPEAT] = u + (0.75 * 0.4 + 0.25 * 0.8);
    want[LX_WRAP_CLAMP] = u + 0.4;
    want[LX_WRAP_MIRROR] = u + 0.4;
    for (int w = 0; w < 3; w++) {
        lx_vec2 uv = lx_parallax_offset(&p, (lx_wrap)w, lx_v2((float)u, 0.5f), v, scale, 1);
        assert_float_equal(uv.x, want[w], 1e-6);
    }
    /* far outside the image, repeat is periodic in u */
    lx_vec2 a = lx_parallax_offset(&p, LX_WRAP_REPEAT, lx_v2(0.3f, 0.5f), v, scale, 1);
    lx_vec2 b = lx_parallax_offset(&p, LX_WRAP_REPEAT, lx_v2(-6.7f, 0.5f), v, scale, 1);
    assert_float_equal(a.x - 0.3, b.x + 6.7, 1e-5);
    lx_image_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(plane_map),
        cmocka_unit_test(constant_offset),
        cmocka_unit_test(ramp_recurrence),
        cmocka_unit_test(wrap_at_the_edge),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
