/* MikkTSpace tangents (src/maps/mikktspace.c) against the reference
 * implementation: the npm package `mikktspace`, a WebAssembly build of it,
 * run by tests/maps/mikktspace_oracle.js (installed into BUILD/oracles by
 * scripts/install-test-oracles.sh; the comparisons are skipped when node or
 * the package is missing). Meshes: a UV sphere (seam and pole
 * triangles of zero area), a box with a chart per face, a surface whose
 * left half has mirrored UVs, and a grid with collapsed (zero-area) UV
 * triangles and degenerate triangles. The reference returns its sign for
 * UVs with v up; luxel's v grows downward (glTF), so luxel's w is the
 * reference's negated. Both methods are also checked for orthonormality
 * and for handedness against each triangle's own UV gradient, computed
 * here in double. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "helpers.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Angle tolerance against the reference, degrees: 4x the largest difference
 * measured on these meshes (4.8e-6, float rounding on the sphere). */
#define ORACLE_TOL_DEG 2e-5

static lx_mesh mesh_alloc(const char *name, uint32_t nv, uint32_t nt)
{
    lx_mesh m = {0};
    m.name = malloc(strlen(name) + 1);
    if (m.name)
        memcpy(m.name, name, strlen(name) + 1);
    m.vertex_count = nv;
    m.triangle_count = nt;
    m.positions = calloc(nv, sizeof(lx_vec3));
    m.normals = calloc(nv, sizeof(lx_vec3));
    m.uv[0] = calloc(nv, sizeof(lx_vec2));
    m.indices = calloc(3 * (size_t)nt, sizeof(uint32_t));
    m.source_mesh = m.source_primitive = -1;
    assert_true(m.name && m.positions && m.normals && m.uv[0] && m.indices);
    return m;
}

static void tri(lx_mesh *m, uint32_t t, uint32_t a, uint32_t b, uint32_t c)
{
    m->indices[3 * t] = a, m->indices[3 * t + 1] = b, m->indices[3 * t + 2] = c;
}

/* Latitude-longitude sphere: rings x seg quads, a seam column at u = 1,
 * pole rows whose quads have two corners at the pole (degenerate). */
static lx_mesh uv_sphere(int seg, int rings)
{
    lx_mesh m = mesh_alloc("sphere", (uint32_t)((seg + 1) * (rings + 1)),
                           (uint32_t)(2 * seg * rings));
    for (int i = 0; i <= rings; i++)
        for (int j = 0; j <= seg; j++) {
            double th = M_PI * i / rings, ph = 2 * M_PI * j / seg;
            double s = (i == 0 || i == rings) ? 0.0 : sin(th);
            lx_vec3 p = lx_v3((float)(s * cos(ph)), (float)cos(th), (float)(s * sin(ph)));
            uint32_t v = (uint32_t)(i * (seg + 1) + j);
            m.positions[v] = p;
            m.normals[v] = p;
            m.uv[0][v] = lx_v2((float)j / seg, (float)i / rings);
        }
    uint32_t t = 0;
    for (int i = 0; i < rings; i++)
        for (int j = 0; j < seg; j++) {
            uint32_t a = (uint32_t)(i * (seg + 1) + j), b = a + 1;
            uint32_t d = a + (uint32_t)(seg + 1), c = d + 1;
            tri(&m, t++, a, b, c);
            tri(&m, t++, a, c, d);
        }
    return m;
}

/* A height surface z = h(x, y) over [-1,1]^2 on an n x n grid. */
static double height(double x, double y)
{
    return 0.2 * sin(2 * x + 0.3) * cos(1.5 * y);
}

static lx_mesh surface(const char *name, int n, lx_vec2 (*uvf)(double x, double y))
{
    lx_mesh m = mesh_alloc(name, (uint32_t)((n + 1) * (n + 1)), (uint32_t)(2 * n * n));
    for (int i = 0; i <= n; i++)
        for (int j = 0; j <= n; j++) {
            double x = -1 + 2.0 * j / n, y = -1 + 2.0 * i / n;
            double hx = 0.4 * cos(2 * x + 0.3) * cos(1.5 * y);
            double hy = -0.3 * sin(2 * x + 0.3) * sin(1.5 * y);
            double l = sqrt(hx * hx + hy * hy + 1);
            uint32_t v = (uint32_t)(i * (n + 1) + j);
            m.positions[v] = lx_v3((float)x, (float)y, (float)height(x, y));
            m.normals[v] = lx_v3((float)(-hx / l), (float)(-hy / l), (float)(1 / l));
            m.uv[0][v] = uvf(x, y);
        }
    uint32_t t = 0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            uint32_t a = (uint32_t)(i * (n + 1) + j), b = a + 1;
            uint32_t d = a + (uint32_t)(n + 1), c = d + 1;
            /* alternate diagonals so that fans differ around vertices */
            if ((i + j) % 2) {
                tri(&m, t++, a, b, c);
                tri(&m, t++, a, c, d);
            } else {
                tri(&m, t++, a, b, d);
                tri(&m, t++, b, c, d);
            }
        }
    return m;
}

/* u mirrored across x = 0 (the left half's UVs are the right half's
 * reflected), v down the surface, slightly curved */
static lx_vec2 uv_mirrored(double x, double y)
{
    return lx_v2((float)(fabs(x) + 0.1 * y * y), (float)(0.5 - 0.5 * y + 0.05 * x * x));
}

static lx_vec2 uv_plain(double x, double y)
{
    return lx_v2((float)(0.5 + 0.5 * x), (float)(0.5 - 0.5 * y));
}

/* The plain surface with a block of vertices collapsed to one UV (zero-area
 * UV triangles inside it), a column with the next column's u (UV area zero
 * between them), and two extra triangles: one repeating a corner, one a
 * sliver with three collinear positions. */
static lx_mesh degenerate_uvs(void)
{
    int n = 8;
    lx_mesh s = surface("degenerate", n, uv_plain);
    lx_mesh m = mesh_alloc("degenerate", s.vertex_count + 3, s.triangle_count + 2);
    memcpy(m.positions, s.positions, sizeof(lx_vec3) * s.vertex_count);
    memcpy(m.normals, s.normals, sizeof(lx_vec3) * s.vertex_count);
    memcpy(m.uv[0], s.uv[0], sizeof(lx_vec2) * s.vertex_count);
    memcpy(m.indices, s.indices, sizeof(uint32_t) * 3 * s.triangle_count);
    for (int i = 2; i <= 4; i++)
        for (int j = 2; j <= 4; j++)
            m.uv[0][i * (n + 1) + j] = lx_v2(0.3f, 0.3f);
    for (int i = 0; i <= n; i++)
        m.uv[0][i * (n + 1) + 7].x = m.uv[0][i * (n + 1) + 6].x;
    uint32_t nv = s.vertex_count;
    tri(&m, s.triangle_count, 0, 0, 1);
    m.positions[nv] = lx_v3(2, 0, 0), m.positions[nv + 1] = lx_v3(2.5f, 0, 0);
    m.positions[nv + 2] = lx_v3(3, 0, 0);
    for (uint32_t k = 0; k < 3; k++) {
        m.normals[nv + k] = lx_v3(0, 0, 1);
        m.uv[0][nv + k] = lx_v2(0.1f * (float)k, 0.2f * (float)(k % 2));
    }
    tri(&m, s.triangle_count + 1, nv, nv + 1, nv + 2);
    lx_test_mesh_free(&s);
    return m;
}

/* The box with normals averaged at its corners (smooth shading) as well. */
static lx_mesh smooth_box(void)
{
    lx_mesh m = lx_test_box("box", lx_v3(-1, -0.5f, -0.7f), lx_v3(1, 0.5f, 0.7f), false);
    for (uint32_t v = 0; v < m.vertex_count; v++)
        m.normals[v] = lx_normalize(m.positions[v]);
    return m;
}

/* ---- the oracle ------------------------------------------------------------ */

static char script_dir[1024];

static const char *oracle_script(void)
{
    snprintf(script_dir, sizeof script_dir, "%s", __FILE__);
    char *slash = strrchr(script_dir, '/');
    assert_non_null(slash);
    snprintf(slash, sizeof script_dir - (size_t)(slash - script_dir), "/mikktspace_oracle.js");
    return script_dir;
}

/* The reference's tangents for every corner of m (uv set 0) into out;
 * skips the test when the oracle cannot run. */
static void oracle(const lx_mesh *m, lx_vec4 *out)
{
    if (system("command -v node >/dev/null 2>&1") != 0) {
        print_message("node is not installed\n");
        skip();
    }
    const char *tmp = getenv("LX_TEST_TMP");
    char oracles[1024], in[1100], res[1100], cmd[4400];
    snprintf(oracles, sizeof oracles, "%s/../oracles", tmp ? tmp : "build/test-tmp");
    const char *dir = lx_test_dir("mikktspace");
    snprintf(in, sizeof in, "%s/%s.in", dir, m->name);
    snprintf(res, sizeof res, "%s/%s.out", dir, m->name);
    FILE *f = fopen(in, "wb");
    assert_non_null(f);
    for (size_t k = 0; k < 3 * (size_t)m->triangle_count; k++) {
        uint32_t v = m->indices[k];
        float d[8] = {m->positions[v].x, m->positions[v].y, m->positions[v].z, m->normals[v].x,
                      m->normals[v].y,   m->normals[v].z,   m->uv[0][v].x,    m->uv[0][v].y};
        assert_int_equal(fwrite(d, sizeof d, 1, f), 1);
    }
    assert_int_equal(fclose(f), 0);
    snprintf(cmd, sizeof cmd, "node '%s' '%s' '%s' '%s'", oracle_script(), oracles, in, res);
    int rc = system(cmd);
    int code = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    if (code == 77) {
        print_message("mikktspace is not installed (scripts/install-test-oracles.sh)\n");
        skip();
    }
    assert_int_equal(code, 0);
    f = fopen(res, "rb");
    assert_non_null(f);
    size_t n = 3 * (size_t)m->triangle_count;
    assert_int_equal(fread(out, sizeof(lx_vec4), n, f), n);
    fclose(f);
}

static void compare_with_oracle(lx_mesh *m)
{
    size_t n = 3 * (size_t)m->triangle_count;
    lx_vec4 *got = malloc(sizeof(lx_vec4) * n), *want = malloc(sizeof(lx_vec4) * n);
    assert_true(got && want);
    assert_int_equal(lx_compute_tangents_mikktspace(m, 0, got), LX_OK);
    oracle(m, want);
    double worst = 0, sum = 0;
    size_t compared = 0, zero = 0, flipped = 0, initial = 0;
    for (size_t k = 0; k < n; k++) {
        double wl = sqrt((double)want[k].x * want[k].x + (double)want[k].y * want[k].y +
                         (double)want[k].z * want[k].z);
        if (!(wl > 1e-6)) {
            zero++; /* the reference's zero tangent: luxel writes a perpendicular */
            continue;
        }
        if (want[k].x == 1.0f && want[k].y == 0.0f && want[k].z == 0.0f) {
            /* the reference's initial frame, for corners no group reached
             * (triangles without a UV gradient): luxel makes it
             * perpendicular to the normal */
            lx_vec3 nk = m->normals[m->indices[k]];
            lx_vec3 p = lx_normalize(lx_sub(lx_v3(1, 0, 0), lx_scale(nk, nk.x)));
            want[k] = lx_v4(p.x, p.y, p.z, want[k].w);
            wl = 1;
            initial++;
        }
        /* atan2 of |cross| and dot: acos loses precision near 0 degrees */
        double gx = got[k].x, gy = got[k].y, gz = got[k].z;
        double wx = want[k].x / wl, wy = want[k].y / wl, wz = want[k].z / wl;
        double cx = gy * wz - gz * wy, cy = gz * wx - gx * wz, cz = gx * wy - gy * wx;
        double deg = atan2(sqrt(cx * cx + cy * cy + cz * cz), gx * wx + gy * wy + gz * wz) *
                     180 / M_PI;
        if (deg > worst)
            worst = deg;
        sum += deg;
        compared++;
        if (got[k].w != -want[k].w)
            flipped++;
    }
    print_message("%s: %zu corners, %zu compared: largest angle %.2e deg, mean %.2e deg, "
                  "%zu handedness differences, %zu zero reference tangents, %zu +x tangents\n",
                  m->name, n, compared, worst, compared ? sum / (double)compared : 0.0, flipped,
                  zero, initial);
    assert_true(compared > 0);
    assert_true(worst <= ORACLE_TOL_DEG);
    assert_int_equal(flipped, 0);
    free(got);
    free(want);
}

static void test_sphere(void **state)
{
    (void)state;
    lx_mesh m = uv_sphere(24, 12);
    compare_with_oracle(&m);
    lx_test_mesh_free(&m);
}

static void test_box(void **state)
{
    (void)state;
    lx_mesh m = lx_test_box("box_flat", lx_v3(-1, -0.5f, -0.7f), lx_v3(1, 0.5f, 0.7f), false);
    compare_with_oracle(&m);
    lx_test_mesh_free(&m);
    m = smooth_box();
    compare_with_oracle(&m);
    lx_test_mesh_free(&m);
}

static void test_mirrored(void **state)
{
    (void)state;
    lx_mesh m = surface("mirrored", 12, uv_mirrored);
    compare_with_oracle(&m);
    lx_test_mesh_free(&m);
}

static void test_degenerate(void **state)
{
    (void)state;
    lx_mesh m = degenerate_uvs();
    compare_with_oracle(&m);
    lx_test_mesh_free(&m);
}

/* ---- invariants, both methods ------------------------------------------------ */

/* Every corner's frame is orthonormal, w is +-1, and on each triangle with
 * a UV gradient the tangent follows +u and cross(n, t) * w points toward
 * -v (up the image). skip_mirror_line: corners at x = 0 are not checked
 * (Lengyel's per-vertex sums average both halves there). */
static void check_frames(const lx_mesh *m, lx_tangent_method method, bool skip_mirror_line)
{
    size_t n = 3 * (size_t)m->triangle_count, checked = 0;
    lx_vec4 *t = malloc(sizeof(lx_vec4) * n);
    assert_non_null(t);
    assert_int_equal(lx_compute_corner_tangents(m, method, 0, t), LX_OK);
    for (size_t k = 0; k < n; k++) {
        lx_vec3 nrm = m->normals[m->indices[k]], tt = lx_v3(t[k].x, t[k].y, t[k].z);
        assert_true(fabsf(lx_length(tt) - 1.0f) < 1e-5f);
        assert_true(fabsf(lx_dot(tt, nrm)) < 1e-5f);
        assert_true(t[k].w == 1.0f || t[k].w == -1.0f);
        /* the triangle's own gradients, in double */
        const uint32_t *ix = &m->indices[3 * (k / 3)];
        double e1[3], e2[3];
        const float *p0 = &m->positions[ix[0]].x, *p1 = &m->positions[ix[1]].x,
                    *p2 = &m->positions[ix[2]].x;
        for (int c = 0; c < 3; c++)
            e1[c] = (double)p1[c] - p0[c], e2[c] = (double)p2[c] - p0[c];
        lx_vec2 u0 = m->uv[0][ix[0]], u1 = m->uv[0][ix[1]], u2 = m->uv[0][ix[2]];
        double s1 = (double)u1.x - u0.x, s2 = (double)u2.x - u0.x;
        double q1 = (double)u1.y - u0.y, q2 = (double)u2.y - u0.y;
        double det = s1 * q2 - s2 * q1;
        double ax = e1[1] * e2[2] - e1[2] * e2[1], ay = e1[2] * e2[0] - e1[0] * e2[2],
               az = e1[0] * e2[1] - e1[1] * e2[0];
        if (fabs(det) < 1e-9 || ax * ax + ay * ay + az * az < 1e-18)
            continue; /* no UV gradient, or no area in space */
        if (skip_mirror_line && m->positions[m->indices[k]].x == 0.0f)
            continue;
        double dpdu[3], dpdv[3];
        for (int c = 0; c < 3; c++) {
            dpdu[c] = (q2 * e1[c] - q1 * e2[c]) / det;
            dpdv[c] = (s1 * e2[c] - s2 * e1[c]) / det;
        }
        lx_vec3 b = lx_scale(lx_cross(nrm, tt), t[k].w);
        double tu = tt.x * dpdu[0] + tt.y * dpdu[1] + tt.z * dpdu[2];
        double bv = b.x * dpdv[0] + b.y * dpdv[1] + b.z * dpdv[2];
        assert_true(tu > 0);
        assert_true(bv < 0);
        checked++;
    }
    assert_true(checked > n / 2);
    free(t);
}

static void test_frames_mirrored(void **state)
{
    (void)state;
    lx_mesh m = surface("mirrored", 12, uv_mirrored);
    check_frames(&m, LX_TANGENTS_MIKKTSPACE, false);
    check_frames(&m, LX_TANGENTS_LENGYEL, true);
    /* the two halves really are of opposite handedness */
    lx_vec4 *t = malloc(sizeof(lx_vec4) * 3 * m.triangle_count);
    assert_non_null(t);
    assert_int_equal(lx_compute_tangents_mikktspace(&m, 0, t), LX_OK);
    int left = 0, right = 0, nl = 0, nr = 0;
    for (size_t k = 0; k < 3 * (size_t)m.triangle_count; k++) {
        float x = m.positions[m.indices[k]].x;
        if (x < 0)
            left += t[k].w > 0 ? 1 : -1, nl++;
        else if (x > 0)
            right += t[k].w > 0 ? 1 : -1, nr++;
    }
    /* one sign per half, opposite */
    assert_int_equal(abs(left), nl);
    assert_int_equal(abs(right), nr);
    assert_true(left * right < 0);
    free(t);
    lx_test_mesh_free(&m);
}

static void test_frames_sphere_and_box(void **state)
{
    (void)state;
    lx_mesh m = uv_sphere(16, 8);
    check_frames(&m, LX_TANGENTS_MIKKTSPACE, false);
    check_frames(&m, LX_TANGENTS_LENGYEL, false);
    lx_test_mesh_free(&m);
    m = lx_test_box("box", lx_v3(0, 0, 0), lx_v3(1, 2, 3), false);
    check_frames(&m, LX_TANGENTS_MIKKTSPACE, false);
    check_frames(&m, LX_TANGENTS_LENGYEL, false);
    lx_test_mesh_free(&m);
}

static void test_bad_input(void **state)
{
    (void)state;
    lx_mesh m = uv_sphere(4, 3);
    lx_vec4 t[3 * 24];
    assert_int_equal(lx_compute_tangents_mikktspace(&m, 1, t), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "TEXCOORD_1"));
    m.indices[5] = 999;
    assert_int_equal(lx_compute_tangents_mikktspace(&m, 0, t), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "999"));
    lx_tangent_method meth;
    assert_true(lx_tangent_method_parse("lengyel", &meth) && meth == LX_TANGENTS_LENGYEL);
    assert_false(lx_tangent_method_parse("mikk", &meth));
    lx_test_mesh_free(&m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_box),
        cmocka_unit_test(test_mirrored),
        cmocka_unit_test(test_degenerate),
        cmocka_unit_test(test_frames_mirrored),
        cmocka_unit_test(test_frames_sphere_and_box),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
