/* ibl.h's cube map conventions written out again for the tests (see
 * cube_reference.h). */
#include "cube_reference.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>

void lx_test_face_vec(int face, double sc, double tc, double v[3])
{
    switch (face) {
    case 0:
        v[0] = 1, v[1] = -tc, v[2] = -sc;
        break;
    case 1:
        v[0] = -1, v[1] = -tc, v[2] = sc;
        break;
    case 2:
        v[0] = sc, v[1] = 1, v[2] = tc;
        break;
    case 3:
        v[0] = sc, v[1] = -1, v[2] = -tc;
        break;
    case 4:
        v[0] = sc, v[1] = -tc, v[2] = 1;
        break;
    default:
        v[0] = -sc, v[1] = -tc, v[2] = -1;
        break;
    }
}

void lx_test_face_dir(int face, double sc, double tc, double d[3])
{
    lx_test_face_vec(face, sc, tc, d);
    double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int k = 0; k < 3; k++)
        d[k] /= n;
}

void lx_test_texel_dir(int face, int size, int x, int y, double d[3])
{
    lx_test_face_dir(face, 2.0 * (x + 0.5) / size - 1.0, 2.0 * (y + 0.5) / size - 1.0, d);
}

double lx_test_texel_omega(int size, int x, int y, int m)
{
    double h = 2.0 / size / m, sum = 0.0;
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            double a = -1.0 + 2.0 * x / size + (i + 0.5) * h;
            double b = -1.0 + 2.0 * y / size + (j + 0.5) * h;
            sum += 1.0 / pow(1.0 + a * a + b * b, 1.5);
        }
    return sum * h * h;
}

float *lx_test_cube_texel(const lx_cubemap *c, int face, int x, int y)
{
    size_t n = (size_t)c->size;
    return c->data + 3 * ((size_t)face * n * n + (size_t)y * n + (size_t)x);
}

static double corner_solid_angle(double a, double b)
{
    return atan2(a * b, sqrt(a * a + b * b + 1.0));
}

double lx_test_texel_solid_angle(int size, int x, int y)
{
    double a0 = 2.0 * x / size - 1.0, a1 = 2.0 * (x + 1) / size - 1.0;
    double b0 = 2.0 * y / size - 1.0, b1 = 2.0 * (y + 1) / size - 1.0;
    return corner_solid_angle(a1, b1) - corner_solid_angle(a0, b1) - corner_solid_angle(a1, b0) +
           corner_solid_angle(a0, b0);
}

lx_cubemap lx_test_make_env(int size, lx_test_env_fn fn)
{
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, size), LX_OK);
    assert_int_equal(c.size, size);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < size; y++)
            for (int x = 0; x < size; x++) {
                double d[3];
                lx_test_texel_dir(f, size, x, y, d);
                fn(d[0], d[1], d[2], lx_test_cube_texel(&c, f, x, y));
            }
    return c;
}

lx_cubemap lx_test_constant_env(int size, float value)
{
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, size), LX_OK);
    assert_int_equal(c.size, size);
    for (size_t i = 0; i < (size_t)6 * size * size * 3; i++)
        c.data[i] = value;
    return c;
}

lx_test_progress lx_test_progress_make(int stop_after)
{
    lx_test_progress p = {0, stop_after > 0 ? stop_after : 1 << 30, 0.0f, true};
    return p;
}

bool lx_test_progress_fn(void *user, float fraction)
{
    lx_test_progress *p = user;
    p->monotone = p->monotone && fraction >= p->last;
    p->last = fraction;
    return ++p->calls < p->stop_after;
}
