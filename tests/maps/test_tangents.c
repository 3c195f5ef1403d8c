/* Tangent frames (src/maps/tangents.c) on planes with known UV layouts. The
 * expected frame follows from the layout alone: the tangent is the world
 * direction in which u grows (dP/du, made perpendicular to the normal), and
 * the handedness w makes cross(n, t) * w point toward decreasing v (glTF
 * normal maps: +Y is "up" in the image, and luxel's v grows downward). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"

/* UV layouts as functions of the plane's own (s, t) in [0,1]^2, where
 * lx_test_plane puts s along +x and t along +z. */
typedef lx_vec2 (*layout_fn)(float s, float t);

static lx_vec2 standard(float s, float t)
{
    return lx_v2(s, t);
}
static lx_vec2 mirror_u(float s, float t)
{
    return lx_v2(1 - s, t);
}
static lx_vec2 mirror_v(float s, float t)
{
    return lx_v2(s, 1 - t);
}
/* a quarter turn: u along +z, v along -x */
static lx_vec2 quarter(float s, float t)
{
    return lx_v2(t, 1 - s);
}
/* shear: u = (s + t/2)/2, v = t, so x = 4u - v - 1, z = 2v - 1:
 * dP/du = (4, 0, 0), dP/dv = (-1, 0, 2) */
static lx_vec2 shear(float s, float t)
{
    return lx_v2(0.5f * (s + 0.5f * t), t);
}

static lx_mesh plane_with(layout_fn f, int set)
{
    lx_mesh m = lx_test_plane("plane", 2.0f, 0.0f, 0.0f, 0.0f, 3);
    for (uint32_t v = 0; v < m.vertex_count; v++) {
        lx_vec3 p = m.positions[v];
        float s = (p.x + 1.0f) / 2.0f, t = (p.z + 1.0f) / 2.0f;
        m.uv[set][v] = f(s, t);
        m.uv[1 - set][v] = lx_v2(0.3f * t, 0.9f - 0.2f * s); /* something else */
    }
    return m;
}

static void assert_vec(lx_vec3 got, lx_vec3 want, float tol, const char *what)
{
    if (!(fabsf(got.x - want.x) <= tol && fabsf(got.y - want.y) <= tol &&
          fabsf(got.z - want.z) <= tol))
        fail_msg("%s: got (%g, %g, %g), want (%g, %g, %g)", what, got.x, got.y, got.z, want.x,
                 want.y, want.z);
}

static lx_vec3 xyz(lx_vec4 t)
{
    return lx_v3(t.x, t.y, t.z);
}

/* Every vertex: tangent == t_want, w == w_want, and the frame's
 * bitangent points toward decreasing v (-dP/dv). */
static void check_frames(const lx_mesh *m, int set, lx_vec3 t_want, float w_want,
                         lx_vec3 minus_dpdv)
{
    lx_vec4 *t = malloc(sizeof *t * m->vertex_count);
    assert_int_equal(lx_compute_tangents(m, set, t), LX_OK);
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        lx_vec3 n = m->normals[v];
        /* unit vectors: measured within one float ulp (1.2e-7) of the
         * expected ones, bounds 3e-7; N.T within 3e-8 of 0, bound 1e-7 */
        assert_vec(xyz(t[v]), t_want, 3e-7f, "tangent");
        assert_true(fabsf(lx_dot(xyz(t[v]), n)) < 1e-7f);
        assert_true(t[v].w == w_want);
        lx_vec3 b = lx_scale(lx_cross(n, xyz(t[v])), t[v].w);
        assert_true(lx_dot(b, lx_normalize(minus_dpdv)) > 0.0f);
        /* tangent space -> world: z is the normal, x the tangent, y the
         * bitangent (toward -v) */
        assert_vec(lx_tangent_to_world(lx_v3(0, 0, 1), n, t[v]), n, 3e-7f, "m = +z");
        assert_vec(lx_tangent_to_world(lx_v3(1, 0, 0), n, t[v]), t_want, 3e-7f, "m = +x");
        assert_vec(lx_tangent_to_world(lx_v3(0, 1, 0), n, t[v]), b, 3e-7f, "m = +y");
        lx_vec3 diag = lx_normalize(lx_add(lx_add(t_want, b), lx_scale(n, 2.0f)));
        assert_vec(lx_tangent_to_world(lx_v3(0.5f, 0.5f, 1.0f), n, t[v]), diag, 3e-7f,
                   "m not unit");
    }
    free(t);
}

static void test_standard_layout(void **state)
{
    (void)state;
    for (int set = 0; set < 2; set++) {
        lx_mesh m = plane_with(standard, set);
        /* u along +x; v along +z, so -v is -z = cross(+y, +x): w = +1 */
        check_frames(&m, set, lx_v3(1, 0, 0), 1.0f, lx_v3(0, 0, -1));
        lx_test_mesh_free(&m);
    }
}

static void test_mirrored_uvs_flip_w(void **state)
{
    (void)state;
    lx_mesh m = plane_with(mirror_u, 0);
    /* u grows toward -x; v still along +z: b = cross(+y, -x) w = +z w = -z */
    check_frames(&m, 0, lx_v3(-1, 0, 0), -1.0f, lx_v3(0, 0, -1));
    lx_test_mesh_free(&m);
    m = plane_with(mirror_v, 0);
    /* u along +x, v grows toward -z: -v is +z = cross(+y, +x) * -1 */
    check_frames(&m, 0, lx_v3(1, 0, 0), -1.0f, lx_v3(0, 0, 1));
    lx_test_mesh_free(&m);
}

static void test_rotated_layout_keeps_w(void **state)
{
    (void)state;
    lx_mesh m = plane_with(quarter, 0);
    /* u along +z, v along -x: -v is +x = cross(+y, +z): w = +1 */
    check_frames(&m, 0, lx_v3(0, 0, 1), 1.0f, lx_v3(1, 0, 0));
    lx_test_mesh_free(&m);
}

static void test_sheared_layout_follows_dpdu(void **state)
{
    (void)state;
    lx_mesh m = plane_with(shear, 0);
    /* dP/du is along +x exactly; dP/dv = (-1, 0, 2) is not perpendicular
     * to it: the bitangent only has to be on the -v side */
    check_frames(&m, 0, lx_v3(1, 0, 0), 1.0f, lx_v3(1, 0, -2));
    lx_test_mesh_free(&m);
}

static void test_rotated_plane(void **state)
{
    (void)state;
    lx_mesh m = plane_with(standard, 0);
    /* rotate positions and normals: the frame rotates with them */
    lx_vec3 axis = lx_normalize(lx_v3(0.3f, 1.0f, -0.7f));
    float a = LX_DEG2RAD(70.0f);
    lx_mat4 r = lx_mat4_from_quat(
        lx_v4(axis.x * sinf(a / 2), axis.y * sinf(a / 2), axis.z * sinf(a / 2), cosf(a / 2)));
    for (uint32_t v = 0; v < m.vertex_count; v++) {
        m.positions[v] = lx_mat4_point(&r, m.positions[v]);
        m.normals[v] = lx_normalize(lx_mat4_vector(&r, m.normals[v]));
    }
    check_frames(&m, 0, lx_normalize(lx_mat4_vector(&r, lx_v3(1, 0, 0))), 1.0f,
                 lx_mat4_vector(&r, lx_v3(0, 0, -1)));
    lx_test_mesh_free(&m);
}

static void test_missing_uvs_fail(void **state)
{
    (void)state;
    lx_mesh m = plane_with(standard, 0);
    lx_vec4 *t = malloc(sizeof *t * m.vertex_count);
    free(m.uv[1]);
    m.uv[1] = NULL;
    assert_int_equal(lx_compute_tangents(&m, 1, t), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "TEXCOORD_1"));
    assert_int_equal(lx_compute_tangents(&m, 2, t), LX_ERR_INVALID);
    assert_int_equal(lx_compute_tangents(&m, -1, t), LX_ERR_INVALID);
    free(t);
    lx_test_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_standard_layout),
        cmocka_unit_test(test_mirrored_uvs_flip_w),
        cmocka_unit_test(test_rotated_layout_keeps_w),
        cmocka_unit_test(test_sheared_layout_follows_dpdu),
        cmocka_unit_test(test_rotated_plane),
        cmocka_unit_test(test_missing_uvs_fail),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
