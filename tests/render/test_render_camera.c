/* Cameras of a scene file and the default camera (render/camera_auto.c):
 * - a closed room (a box whose faces look in) seen from the iso framing
 *   meets back faces first, so lx_camera_auto places the eye inside the
 *   room's bounds, looking along its longer horizontal axis; from there
 *   every pixel of a render sees a front face (coverage 1, worked out
 *   here: the eye is inside a closed box);
 * - a closed object (faces out) keeps the iso framing, bit for bit;
 * - a room with thick walls (faces in and out), black outside and lit
 *   inside as a bake leaves it, is entered when the lightmaps are given;
 * - lx_render_view's zeroed camera is lx_camera_auto's (same bytes);
 * - a render from a glTF file's camera equals, byte for byte, the render
 *   from the lx_camera written here from the node's matrix (entries 0 and
 *   +-1 and a translation, exact in float) and the yfov;
 * - an orthographic glTF camera sees a floor at the size its ymag says,
 *   and the same image from any height. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "luxel/render.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void write_page(const char *path, int w, int h)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, w, h, 3), LX_OK);
    /* a gradient, so a moved camera shows */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = 0; k < 3; k++)
                img.data[3 * (y * w + x) + k] = 50.0f + 10.0f * (float)x + 3.0f * (float)(y + k);
    assert_int_equal(lx_image_write(path, &img, NULL), LX_OK);
    lx_image_free(&img);
}

static lx_scene *box_scene(bool inward)
{
    lx_scene *s = lx_test_new_scene("box");
    lx_material mat = {.name = "white", .base_color = {0.8f, 0.8f, 0.8f, 1.0f},
                       .normal_scale = 1.0f};
    uint32_t mi;
    assert_int_equal(lx_scene_add_material(s, &mat, &mi), LX_OK);
    /* 6 m along X, 3 m tall, 4 m along Z */
    lx_mesh m = lx_test_box("room", lx_v3(-3, 0, -2), lx_v3(3, 3, 2), inward);
    m.material = mi;
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    return s;
}

static void test_closed_room_inside(void **state)
{
    (void)state;
    lx_scene *s = box_scene(true);
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    lx_camera cam;
    lx_camera_auto_info info;
    assert_int_equal(lx_camera_auto(s, NULL, tr, 0.0f, 16.0f / 9.0f, &cam, &info), LX_OK);
    /* from outside, the faces toward the eye look away from it */
    assert_true(info.outside_back > 0.5f);
    assert_true(info.moved);
    assert_true(info.inside);
    assert_true(cam.eye.x > -3 && cam.eye.x < 3 && cam.eye.y > 0 && cam.eye.y < 3 &&
                cam.eye.z > -2 && cam.eye.z < 2);
    lx_vec3 d = lx_sub(cam.target, cam.eye);
    assert_true(fabsf(d.y) < 1e-6f && fabsf(d.z) < 1e-6f && fabsf(d.x) > 0.5f);
    /* the inside view's probes all meet front faces */
    assert_true(info.score == 1.0f);
    assert_int_equal(lx_camera_check(&cam), LX_OK);
    lx_tracer_destroy(tr);
    lx_scene_destroy(s);
}

static void test_closed_object_outside(void **state)
{
    (void)state;
    lx_scene *s = box_scene(false);
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    lx_camera cam;
    lx_camera_auto_info info;
    float fov = 0.6f;
    assert_int_equal(lx_camera_auto(s, NULL, tr, fov, 2.0f, &cam, &info), LX_OK);
    assert_false(info.moved);
    assert_true(info.outside_back == 0.0f);
    assert_true(info.outside_hit > 0.0f);
    lx_camera iso = lx_camera_frame(lx_v3(-3, 0, -2), lx_v3(3, 3, 2), LX_VIEW_ISO, fov, 2.0f);
    assert_memory_equal(&cam, &iso, sizeof cam);
    lx_tracer_destroy(tr);
    lx_scene_destroy(s);
}

/* A room with thick walls: the inward box lit (its page a gradient), an
 * outward box 0.2 m larger around it black (its page zeros), as a bake of
 * a room lit from inside leaves them. Faces alone cannot tell it from a
 * plain box; the lightmaps can: with them the camera goes inside, without
 * them the iso view stays. */
/* A room (inward box) inside a box (outward), walls 0.2 m thick: DIR's
 * inner.exr (written by the caller) lights the room, outer.exr (black)
 * the outside; the manifest, the scene and its lightmaps. */
static lx_scene *thick_room(const char *dir, lx_lightmaps *lm)
{
    char path[4096];
    lx_image black;
    assert_int_equal(lx_image_alloc(&black, 16, 16, 3), LX_OK);
    memset(black.data, 0, sizeof(float) * 16 * 16 * 3);
    snprintf(path, sizeof path, "%s/outer.exr", dir);
    assert_int_equal(lx_image_write(path, &black, NULL), LX_OK);
    lx_image_free(&black);
    snprintf(path, sizeof path, "%s/manifest.json", dir);
    write_text(path, "{\"scene\":\"thick\",\"quantity\":\"irradiance\",\"unit\":\"lx\","
                     "\"pages\":[{\"file\":\"inner.exr\",\"width\":16,\"height\":16},"
                     "{\"file\":\"outer.exr\",\"width\":16,\"height\":16}],"
                     "\"nodes\":[{\"node\":\"inner\",\"meshes\":[\"inner\"],\"page\":0,"
                     "\"scale_offset\":[1,1,0,0],\"uv_set\":\"TEXCOORD_1\"},"
                     "{\"node\":\"outer\",\"meshes\":[\"outer\"],\"page\":1,"
                     "\"scale_offset\":[1,1,0,0],\"uv_set\":\"TEXCOORD_1\"}]}");
    lx_scene *s = lx_test_new_scene("thick");
    lx_material mat = {.name = "white", .base_color = {0.8f, 0.8f, 0.8f, 1.0f},
                       .normal_scale = 1.0f};
    uint32_t mi;
    assert_int_equal(lx_scene_add_material(s, &mat, &mi), LX_OK);
    lx_mesh in = lx_test_box("inner", lx_v3(-3, 0, -2), lx_v3(3, 3, 2), true);
    lx_mesh out = lx_test_box("outer", lx_v3(-3.2f, -0.2f, -2.2f), lx_v3(3.2f, 3.2f, 2.2f), false);
    in.material = out.material = mi;
    lx_test_add(s, &in);
    lx_test_add(s, &out);
    lx_test_mesh_free(&in);
    lx_test_mesh_free(&out);
    if (lx_lightmaps_load(dir, NULL, lm) != LX_OK)
        fail_msg("%s", lx_last_error());
    return s;
}

static void test_thick_walls(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_camera_thick");
    char path[4096];
    snprintf(path, sizeof path, "%s/inner.exr", dir);
    write_page(path, 16, 16);
    lx_lightmaps lm;
    lx_scene *s = thick_room(dir, &lm);
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    lx_camera cam;
    lx_camera_auto_info info;
    assert_int_equal(lx_camera_auto(s, &lm, tr, 0.0f, 16.0f / 9.0f, &cam, &info), LX_OK);
    assert_true(info.outside_back == 0.0f);
    assert_true(info.outside_unlit == 1.0f); /* all it meets is the black outside */
    assert_true(info.moved && info.inside);
    assert_true(cam.eye.x > -3 && cam.eye.x < 3 && cam.eye.y > 0 && cam.eye.y < 3 &&
                cam.eye.z > -2 && cam.eye.z < 2);
    assert_true(info.enclosed);
    /* without lightmaps the outside's front faces would do, but a room
     * with walls all round is shown from inside all the same */
    assert_int_equal(lx_camera_auto(s, NULL, tr, 0.0f, 16.0f / 9.0f, &cam, &info), LX_OK);
    assert_true(info.moved && info.inside && info.enclosed);
    lx_tracer_destroy(tr);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

/* The thick-walled room lit evenly but for a dark 2x2 patch on the wall
 * at +X (face 0's chart) or at -X (face 1's): the inside views along +X and
 * -X then score a little apart, one way or the other. The camera must not
 * follow such noise: both bakes get the same view, the first inside view
 * (along +X). */
static lx_camera thick_room_with_patch(int face, lx_camera_auto_info *info)
{
    char dir_name[64];
    snprintf(dir_name, sizeof dir_name, "render_camera_patch%d", face);
    const char *dir = lx_test_dir(dir_name);
    char path[4096];
    lx_image page;
    assert_int_equal(lx_image_alloc(&page, 16, 16, 3), LX_OK);
    for (int i = 0; i < 16 * 16 * 3; i++)
        page.data[i] = 100.0f;
    /* face f's chart: columns (f % 3) * 16/3 .. , rows (f / 3) * 8 .. */
    int x0 = (face % 3) * 16 / 3 + 2, y0 = (face / 3) * 8 + 3;
    for (int y = y0; y < y0 + 2; y++)
        for (int x = x0; x < x0 + 2; x++)
            for (int k = 0; k < 3; k++)
                page.data[3 * (y * 16 + x) + k] = 0.0f;
    snprintf(path, sizeof path, "%s/inner.exr", dir);
    assert_int_equal(lx_image_write(path, &page, NULL), LX_OK);
    lx_image_free(&page);
    lx_lightmaps lm;
    lx_scene *s = thick_room(dir, &lm);
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    lx_camera cam;
    assert_int_equal(lx_camera_auto(s, &lm, tr, 0.0f, 16.0f / 9.0f, &cam, info), LX_OK);
    lx_tracer_destroy(tr);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
    return cam;
}

static void test_no_flip_on_noise(void **state)
{
    (void)state;
    lx_camera_auto_info a, b;
    lx_camera ca = thick_room_with_patch(0, &a), cb = thick_room_with_patch(1, &b);
    print_message("patch at +X: %s (score %.4f); at -X: %s (score %.4f)\n", a.placement,
                  (double)a.score, b.placement, (double)b.score);
    assert_true(a.inside && b.inside);
    assert_true(a.score != b.score); /* the patches do change the scores */
    assert_string_equal(a.placement, b.placement);
    assert_string_equal(a.placement, "inside, looking along +X");
    assert_memory_equal(&ca, &cb, sizeof ca);
}

static const char *room_manifest =
    "{\"scene\":\"box\",\"quantity\":\"irradiance\",\"unit\":\"lx\",\"preview_ev100\":7,"
    "\"pages\":[{\"file\":\"room.exr\",\"width\":16,\"height\":16}],"
    "\"nodes\":[{\"node\":\"room\",\"meshes\":[\"room\"],\"page\":0,"
    "\"scale_offset\":[1,1,0,0],\"uv_set\":\"TEXCOORD_1\"}]}";

static void test_default_render_is_auto(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_camera_room");
    char path[4096];
    snprintf(path, sizeof path, "%s/room.exr", dir);
    write_page(path, 16, 16);
    snprintf(path, sizeof path, "%s/manifest.json", dir);
    write_text(path, room_manifest);
    lx_scene *s = box_scene(true);
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    float coverage[48 * 27];
    lx_render_desc d = {.width = 48, .height = 27, .samples = 2, .coverage = coverage};
    lx_image a, b;
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &a), LX_OK);
    /* inside a closed box every ray meets a wall facing it */
    for (int i = 0; i < 48 * 27; i++)
        assert_true(coverage[i] == 1.0f);
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    assert_int_equal(lx_camera_auto(s, &lm, tr, 0.0f, 48.0f / 27.0f, &d.camera, NULL), LX_OK);
    d.coverage = NULL;
    assert_int_equal(lx_render_view(s, &lm, tr, &d, &b), LX_OK);
    assert_memory_equal(a.data, b.data, sizeof(float) * 48 * 27 * 3);
    lx_image_free(&a);
    lx_image_free(&b);
    lx_tracer_destroy(tr);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

/* A 4 m floor at y = 0 with TEXCOORD_1 over the unit square, lit by an
 * 8 x 8 page, and one camera node (`node_json`: its matrix and camera
 * reference; `cameras_json`: the file's cameras), written to a fresh
 * folder `name`, loaded into *scene and *lm. */
static void floor_with_camera(const char *name, const char *node_json, const char *cameras_json,
                              lx_scene **scene, lx_lightmaps *lm)
{
    const char *dir = lx_test_dir(name);
    static const float pos[] = {-2, 0, -2, -2, 0, 2, 2, 0, 2, 2, 0, -2};
    static const float nrm[] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    static const float uv[] = {0, 0, 0, 1, 1, 1, 1, 0};
    static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
    lx_test_primitive p = {.vertex_count = 4, .position = pos, .normal = nrm, .uv0 = uv,
                           .uv1 = uv, .index_count = 6, .indices = idx, .material = -1};
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_node(g, "floor", lx_test_gltf_mesh(g, "floor", &p, 1), "");
    lx_test_gltf_node(g, "rig", -1, node_json);
    lx_test_gltf_top(g, cameras_json);
    char path[4096];
    snprintf(path, sizeof path, "%s/floor.gltf", dir);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    if (lx_scene_load(path, NULL, scene) != LX_OK)
        fail_msg("%s", lx_last_error());
    assert_int_equal((*scene)->camera_count, 1);
    snprintf(path, sizeof path, "%s/floor.exr", dir);
    write_page(path, 8, 8);
    snprintf(path, sizeof path, "%s/manifest.json", dir);
    write_text(path, "{\"scene\":\"floor.gltf\",\"quantity\":\"irradiance\",\"unit\":\"lx\","
                     "\"pages\":[{\"file\":\"floor.exr\",\"width\":8,\"height\":8}],"
                     "\"nodes\":[{\"node\":\"floor\",\"meshes\":[\"floor\"],\"page\":0,"
                     "\"scale_offset\":[1,1,0,0],\"uv_set\":\"TEXCOORD_1\"}]}");
    if (lx_lightmaps_load(dir, NULL, lm) != LX_OK)
        fail_msg("%s", lx_last_error());
}

/* the floor with camera 0 ("Cam", yfov 0.75) at node "rig": matrix with
 * columns x -> (0,0,1),
 * y -> (0,1,0), z -> (-1,0,0) (90 degrees about Y: local -Z looks along
 * +X) and translation (-3, 1.5, 0.25); so eye (-3, 1.5, 0.25), forward
 * (1, 0, 0), up (0, 1, 0), all exact */
static void test_gltf_camera_render(void **state)
{
    (void)state;
    lx_scene *s;
    lx_lightmaps lm;
    floor_with_camera("render_camera_gltf",
                      "\"matrix\":[0,0,1,0, 0,1,0,0, -1,0,0,0, -3,1.5,0.25,1],\"camera\":0",
                      "\"cameras\":[{\"name\":\"Cam\",\"type\":\"perspective\","
                      "\"perspective\":{\"yfov\":0.75,\"aspectRatio\":1.0,\"znear\":0.1}}]",
                      &s, &lm);
    float coverage[40 * 30];
    lx_render_desc d = {.width = 40, .height = 30, .samples = 2, .coverage = coverage};
    d.camera = lx_camera_from_scene(&s->cameras[0]);
    lx_image a, b;
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &a), LX_OK);
    /* the lower half looks down at the floor, the upper half over it */
    assert_true(coverage[29 * 40 + 20] == 1.0f);
    assert_true(coverage[0 * 40 + 20] == 0.0f);
    d.coverage = NULL;
    d.camera = (lx_camera){.eye = {-3.0f, 1.5f, 0.25f},
                           .target = {-2.0f, 1.5f, 0.25f},
                           .up = {0, 1, 0},
                           .fov = 0.75f};
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &b), LX_OK);
    assert_memory_equal(a.data, b.data, sizeof(float) * 40 * 30 * 3);
    lx_image_free(&a);
    lx_image_free(&b);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

/* An orthographic camera (ortho_height 8 m, square 32 x 32 image) straight
 * above the 4 m floor: the floor covers exactly the middle 16 x 16 pixels
 * (4 m of 8), and the image does not change with the height of the eye
 * (parallel rays), to float rounding of where the rays start. */
static void test_orthographic_render(void **state)
{
    (void)state;
    /* 90 degrees about X: local -Z looks down -Y, local +Y is -Z */
    lx_scene *s;
    lx_lightmaps lm;
    floor_with_camera("render_camera_ortho",
                      "\"matrix\":[1,0,0,0, 0,0,-1,0, 0,1,0,0, 0,2,0,1],\"camera\":0",
                      "\"cameras\":[{\"type\":\"orthographic\",\"orthographic\":"
                      "{\"xmag\":4,\"ymag\":4,\"znear\":0,\"zfar\":10}}]",
                      &s, &lm);
    float coverage[32 * 32];
    lx_render_desc d = {.width = 32, .height = 32, .samples = 4, .coverage = coverage};
    d.camera = lx_camera_from_scene(&s->cameras[0]);
    assert_true(d.camera.ortho_height == 8.0f); /* 2 x ymag */
    lx_image a, b;
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &a), LX_OK);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            bool in = x >= 8 && x < 24 && y >= 8 && y < 24;
            if (coverage[y * 32 + x] != (in ? 1.0f : 0.0f))
                fail_msg("pixel (%d, %d): coverage %g", x, y, coverage[y * 32 + x]);
        }
    d.coverage = NULL;
    d.camera = (lx_camera){.eye = {0, 5, 0}, .target = {0, 4, 0}, .up = {0, 0, -1},
                           .ortho_height = 8.0f};
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &b), LX_OK);
    /* the same points seen: the same values (measured: identical bytes;
     * a few ulps allowed for the barycentrics of rays that start apart) */
    for (int i = 0; i < 32 * 32 * 3; i++)
        assert_true(fabsf(a.data[i] - b.data[i]) <= 4.0f * FLT_EPSILON * fabsf(a.data[i]));
    lx_image_free(&a);
    lx_image_free(&b);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_room_inside),
        cmocka_unit_test(test_closed_object_outside),
        cmocka_unit_test(test_thick_walls),
        cmocka_unit_test(test_no_flip_on_noise),
        cmocka_unit_test(test_default_render_is_auto),
        cmocka_unit_test(test_gltf_camera_render),
        cmocka_unit_test(test_orthographic_render),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
