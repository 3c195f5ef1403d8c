/* Tests of the glTF camera reader (src/scene/gltf_cameras.c) through
 * lx_scene_load: files written here with two camera definitions placed by
 * nested TRS nodes and a "matrix" node, whose world eye, forward (local -Z)
 * and up (local +Y) are computed here from the quaternions with the
 * rotation formula v' = v + 2w (q x v) + 2 q x (q x v), in double,
 * independently of the library's matrices; extra fields and extensions
 * ignored; and bad cameras (yfov 0, above pi, out of float range, missing,
 * an orthographic xmag of 0, zero scale) left out with one warning each naming the file, the load
 * still succeeding; a node naming a camera the file lacks, an unknown type
 * or missing parameters fail the load with one line naming the file and
 * the node or camera. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "luxel/scene.h"

#define PI_D 3.14159265358979323846

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* one triangle, so the file has geometry */
static void add_triangle(lx_test_gltf *g)
{
    static const float pos[] = {0, 0, 0, 1, 0, 0, 0, 0, -1};
    lx_test_primitive p = {.vertex_count = 3, .position = pos, .material = -1};
    lx_test_gltf_node(g, "floor", lx_test_gltf_mesh(g, "tri", &p, 1), "");
}

/* ---- an independent rotation ------------------------------------------- */

typedef struct dvec {
    double x, y, z;
} dvec;

static dvec cross(dvec a, dvec b)
{
    return (dvec){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

/* v rotated by the unit quaternion (qx, qy, qz, qw) */
static dvec qrot(const double q[4], dvec v)
{
    dvec u = {q[0], q[1], q[2]};
    dvec t = cross(u, v);
    dvec tt = cross(u, t);
    return (dvec){v.x + 2 * q[3] * t.x + 2 * tt.x, v.y + 2 * q[3] * t.y + 2 * tt.y,
                  v.z + 2 * q[3] * t.z + 2 * tt.z};
}

static dvec add(dvec a, dvec b)
{
    return (dvec){a.x + b.x, a.y + b.y, a.z + b.z};
}

/* float inputs, float outputs: a few ulps of the values (|v| <= 8) */
#define TOL 4e-6

static void expect_vec(lx_vec3 got, dvec want, const char *what)
{
    if (fabs(got.x - want.x) > TOL || fabs(got.y - want.y) > TOL || fabs(got.z - want.z) > TOL)
        fail_msg("%s: (%.7g, %.7g, %.7g), want (%.7g, %.7g, %.7g)", what, got.x, got.y, got.z,
                 want.x, want.y, want.z);
}

static const lx_scene_camera *camera_named(const lx_scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->camera_count; i++)
        if (strcmp(s->cameras[i].name, name) == 0)
            return &s->cameras[i];
    fail_msg("no camera '%s'", name);
    return NULL;
}

/* node "rig": T(1, 2, 3), R = 120 degrees about (1,1,1)/sqrt 3 (q = (1/2,
 *   1/2, 1/2, 1/2): x -> y -> z -> x), child "cam_main".
 * node "cam_main": T(0, 0, 2), R = 30 degrees about Y, camera 0 ("Main").
 * node "cam_side": matrix = 2 x (90 degrees about X) + T(-4, 1, 0), camera
 *   1 (unnamed: named after the node). R_x(90) maps y -> z, z -> -y.
 * node "again": camera 0 at the origin, unrotated: "Main_2". */
static void test_two_cameras(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_gltf_cameras");
    char path[4096];
    snprintf(path, sizeof path, "%s/cams.gltf", dir);
    double s30 = sin(PI_D / 12.0), c30 = cos(PI_D / 12.0); /* half of 30 degrees */
    char rot[200];
    snprintf(rot, sizeof rot,
             "\"translation\":[0,0,2],\"rotation\":[0,%.17g,0,%.17g],\"camera\":0", s30, c30);
    lx_test_gltf *g = lx_test_gltf_new();
    add_triangle(g);
    int main_node = lx_test_gltf_node_ex(g, "cam_main", -1, rot, false);
    char rig[200];
    snprintf(rig, sizeof rig,
             "\"translation\":[1,2,3],\"rotation\":[0.5,0.5,0.5,0.5],\"children\":[%d]",
             main_node);
    lx_test_gltf_node(g, "rig", -1, rig);
    lx_test_gltf_node(g, "cam_side", -1,
                      "\"matrix\":[2,0,0,0, 0,0,2,0, 0,-2,0,0, -4,1,0,1],\"camera\":1");
    lx_test_gltf_node(g, "again", -1, "\"camera\":0");
    lx_test_gltf_top(g, "\"cameras\":["
                        "{\"name\":\"Main\",\"type\":\"perspective\",\"perspective\":"
                        "{\"yfov\":0.7,\"aspectRatio\":1.5,\"znear\":0.1,\"zfar\":100,"
                        "\"extras\":{\"lens\":35}},\"extras\":{\"blender\":true},"
                        "\"extensions\":{\"EXT_unknown_camera\":{\"iso\":100}}},"
                        "{\"type\":\"perspective\",\"perspective\":{\"yfov\":1.0,\"znear\":0.05}}"
                        "]");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);

    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    assert_int_equal(book.warnings, 0);
    assert_int_equal(s->camera_count, 3);

    const double qrig[4] = {0.5, 0.5, 0.5, 0.5};
    const double qcam[4] = {0, s30, 0, c30};
    const lx_scene_camera *m = camera_named(s, "Main");
    assert_string_equal(m->node_name, "cam_main");
    assert_int_equal(m->source_camera, 0);
    assert_int_equal(m->type, LX_SCENE_CAMERA_PERSPECTIVE);
    assert_true(fabs(m->yfov - 0.7) < 1e-7);
    assert_true(fabs(m->aspect - 1.5) < 1e-7);
    assert_true(fabs(m->znear - 0.1) < 1e-7);
    assert_true(fabs(m->zfar - 100.0) < 1e-5);
    expect_vec(m->eye, add((dvec){1, 2, 3}, qrot(qrig, (dvec){0, 0, 2})), "Main eye");
    expect_vec(m->forward, qrot(qrig, qrot(qcam, (dvec){0, 0, -1})), "Main forward");
    expect_vec(m->up, qrot(qrig, qrot(qcam, (dvec){0, 1, 0})), "Main up");
    /* by hand: R_y(30)(0,0,-1) = (-sin 30, 0, -cos 30) = (-1/2, 0, -0.866); the rig
     * sends x -> y, y -> z, z -> x: (-0.866, -1/2, 0) */
    expect_vec(m->forward, (dvec){-cos(PI_D / 6), -0.5, 0}, "Main forward by hand");

    const lx_scene_camera *side = camera_named(s, "cam_side");
    assert_int_equal(side->source_camera, 1);
    assert_true(fabs(side->yfov - 1.0) < 1e-7);
    assert_true(side->aspect == 0.0f);
    assert_true(side->zfar == 0.0f);
    expect_vec(side->eye, (dvec){-4, 1, 0}, "side eye");
    expect_vec(side->forward, (dvec){0, 1, 0}, "side forward (unit despite scale 2)");
    expect_vec(side->up, (dvec){0, 0, 1}, "side up");

    const lx_scene_camera *again = camera_named(s, "Main_2");
    assert_string_equal(again->node_name, "again");
    expect_vec(again->eye, (dvec){0, 0, 0}, "again eye");
    expect_vec(again->forward, (dvec){0, 0, -1}, "again forward");
    /* glTF node order: rig's child cam_main is node 1, cam_side 3, again 4 */
    assert_string_equal(s->cameras[0].name, "Main");
    assert_string_equal(s->cameras[1].name, "cam_side");
    assert_string_equal(s->cameras[2].name, "Main_2");
    lx_scene_destroy(s);

    /* the same as a GLB */
    lx_test_gltf *g2 = lx_test_gltf_new();
    add_triangle(g2);
    lx_test_gltf_node(g2, "cam", -1, "\"translation\":[0,1,5],\"camera\":0");
    lx_test_gltf_top(g2, "\"cameras\":[{\"type\":\"perspective\",\"perspective\":"
                         "{\"yfov\":0.5,\"znear\":0.1}}]");
    snprintf(path, sizeof path, "%s/cam.glb", dir);
    lx_test_gltf_write_glb(g2, path);
    lx_test_gltf_free(g2);
    s = lx_test_load_logged(path, NULL, &book);
    assert_int_equal(s->camera_count, 1);
    assert_string_equal(s->cameras[0].name, "cam");
    expect_vec(s->cameras[0].eye, (dvec){0, 1, 5}, "glb eye");
    lx_scene_destroy(s);
}

/* an orthographic camera is read and kept */
static void test_orthographic(void **state)
{
    (void)state;
    char path[4096];
    snprintf(path, sizeof path, "%s/ortho.gltf", lx_test_dir("test_gltf_cameras"));
    lx_test_gltf *g = lx_test_gltf_new();
    add_triangle(g);
    lx_test_gltf_node(g, "top", -1, "\"translation\":[0,10,0],\"camera\":0");
    lx_test_gltf_top(g, "\"cameras\":[{\"type\":\"orthographic\",\"orthographic\":"
                        "{\"xmag\":2,\"ymag\":1.5,\"znear\":0,\"zfar\":50}}]");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    assert_int_equal(book.warnings, 0);
    assert_int_equal(s->camera_count, 1);
    assert_int_equal(s->cameras[0].type, LX_SCENE_CAMERA_ORTHOGRAPHIC);
    assert_true(s->cameras[0].xmag == 2.0f && s->cameras[0].ymag == 1.5f);
    lx_scene_destroy(s);
}

/* One bad camera per file: the scene loads, the camera is left out, and
 * one warning names the file and the problem. */
static void expect_left_out(const char *name, const char *nodes_members, const char *cameras,
                            const char *needle)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", lx_test_dir("test_gltf_cameras"), name);
    lx_test_gltf *g = lx_test_gltf_new();
    add_triangle(g);
    lx_test_gltf_node(g, "bad_cam", -1, nodes_members);
    lx_test_gltf_node(g, "good_cam", -1, "\"translation\":[0,1,4],\"camera\":0");
    lx_test_gltf_top(g, cameras);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    if (book.warnings != 1 || !strstr(book.text, name) || !strstr(book.text, needle))
        fail_msg("%s: %d warnings '%s', want one naming the file and '%s'", name, book.warnings,
                 book.text, needle);
    assert_non_null(strchr(book.text, '\n'));
    assert_true(strchr(book.text, '\n')[1] == '\0'); /* one line */
    /* the good camera stays */
    assert_int_equal(s->camera_count, 1);
    assert_string_equal(s->cameras[0].node_name, "good_cam");
    lx_scene_destroy(s);
}

#define GOOD "{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.8,\"znear\":0.1}}"

/* a node naming a camera the file lacks, a camera of an unknown type or
 * without its parameters: the load fails naming the node or camera
 * (assimp refuses such files; luxel says which before it reads one) */
static void expect_load_fails(const char *name, const char *node_members, const char *cameras,
                              const char *needle)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", lx_test_dir("test_gltf_cameras"), name);
    lx_test_gltf *g = lx_test_gltf_new();
    add_triangle(g);
    lx_test_gltf_node(g, "bad_cam", -1, node_members);
    lx_test_gltf_top(g, cameras);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = NULL;
    assert_int_equal(lx_scene_load(path, NULL, &s), LX_ERR_FORMAT);
    assert_null(s);
    const char *msg = lx_last_error();
    if (!strstr(msg, name) || !strstr(msg, needle))
        fail_msg("'%s' does not name %s and say '%s'", msg, name, needle);
    assert_null(strchr(msg, '\n'));
}

static void test_missing_camera(void **state)
{
    (void)state;
    expect_load_fails("missing.gltf", "\"camera\":7", "\"cameras\":[" GOOD "]",
                      "node 1 ('bad_cam'): camera 7 is not in the file (1 camera)");
    expect_load_fails("type.gltf", "\"camera\":1",
                      "\"cameras\":[" GOOD ",{\"type\":\"fisheye\"}]",
                      "camera 1: type 'fisheye' is not perspective or orthographic");
    expect_load_fails("noparams.gltf", "\"camera\":0",
                      "\"cameras\":[{\"name\":\"P\",\"type\":\"perspective\"}]",
                      "camera 0 ('P'): no 'perspective' object");
}

static void test_bad_cameras(void **state)
{
    (void)state;
    expect_left_out("yfov0.gltf", "\"camera\":1",
                    "\"cameras\":[" GOOD ",{\"type\":\"perspective\",\"perspective\":"
                    "{\"yfov\":0,\"znear\":0.1}}]",
                    "yfov 0 is not an angle");
    expect_left_out("yfov4.gltf", "\"camera\":1",
                    "\"cameras\":[" GOOD ",{\"type\":\"perspective\",\"perspective\":"
                    "{\"yfov\":4,\"znear\":0.1}}]",
                    "yfov 4 is not an angle");
    expect_left_out("yfovhuge.gltf", "\"camera\":1",
                    "\"cameras\":[" GOOD ",{\"type\":\"perspective\",\"perspective\":"
                    "{\"yfov\":1e39,\"znear\":0.1}}]",
                    "is not an angle");
    expect_left_out("noyfov.gltf", "\"camera\":1",
                    "\"cameras\":[" GOOD ",{\"type\":\"perspective\",\"perspective\":"
                    "{\"znear\":0.1}}]",
                    "no yfov");
    expect_left_out("ortho0.gltf", "\"camera\":1",
                    "\"cameras\":[" GOOD ",{\"type\":\"orthographic\",\"orthographic\":"
                    "{\"xmag\":0,\"ymag\":1,\"znear\":0,\"zfar\":5}}]",
                    "xmag and ymag must be finite numbers other than 0");
    expect_left_out("zeroscale.gltf", "\"scale\":[0,0,0],\"camera\":0", "\"cameras\":[" GOOD "]",
                    "zero scale");
    expect_left_out("flat.gltf", "\"scale\":[1,0,1],\"camera\":0", "\"cameras\":[" GOOD "]",
                    "zero scale");
}

/* lx_scene_add_camera: copies, names the unnamed, refuses bad frames,
 * angles and taken names with a message naming the scene */
static void test_add_camera(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("built");
    lx_scene_camera c = {.eye = {1, 2, 3}, .forward = {0, 0, -1}, .up = {0, 1, 0},
                         .yfov = 0.9f, .source_camera = -1, .source_node = -1};
    assert_int_equal(lx_scene_add_camera(s, &c), LX_OK);
    assert_string_equal(s->cameras[0].name, "camera0");
    assert_null(s->cameras[0].node_name);
    char name[] = "Hall";
    c.name = name;
    assert_int_equal(lx_scene_add_camera(s, &c), LX_OK);
    name[0] = 'X'; /* copied */
    assert_string_equal(s->cameras[1].name, "Hall");
    c.name = "Hall";
    assert_int_equal(lx_scene_add_camera(s, &c), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "'Hall' is taken"));
    c.name = "bad";
    c.yfov = 0.0f;
    assert_int_equal(lx_scene_add_camera(s, &c), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "built: camera 'bad': yfov 0"));
    c.yfov = 0.9f;
    c.up = lx_v3(0, 0, -1); /* along forward */
    assert_int_equal(lx_scene_add_camera(s, &c), LX_ERR_INVALID);
    c.up = lx_v3(0, 1, 0);
    c.eye.x = NAN;
    assert_int_equal(lx_scene_add_camera(s, &c), LX_ERR_INVALID);
    c.eye.x = 0.0f;
    c.type = LX_SCENE_CAMERA_ORTHOGRAPHIC; /* xmag, ymag 0 */
    assert_int_equal(lx_scene_add_camera(s, &c), LX_ERR_INVALID);
    assert_int_equal(s->camera_count, 2);
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_cameras),
        cmocka_unit_test(test_orthographic),
        cmocka_unit_test(test_bad_cameras),
        cmocka_unit_test(test_missing_camera),
        cmocka_unit_test(test_add_camera),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
