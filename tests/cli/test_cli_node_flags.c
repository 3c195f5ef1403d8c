/* luxel bake with per-node bake control and a sky dome, on generated
 * glTF files, checked against outside values:
 * - a 40 m floor and a crate under a 2 km KHR_materials_unlit dome, a sun
 *   from the lights JSON: one warning, naming the dome; the dome has no
 *   lightmap (no file, no manifest entry); the sun reaches the floor:
 *   E = E_sun cos(theta) (closed form) on all of it but the crate's
 *   shadow; the texel density is the rule's for the floor and crate alone
 *   (2^20 texels over their area, docs/bake.md); the default camera frames
 *   the room (lx_camera_frame of its bounds, iso) and `luxel render` draws
 *   no black dome;
 * - a lights JSON "nodes" entry by glob turns two boxes' lightmaps off: the
 *   bake succeeds without them (the manifest's nodes_without_lightmap
 *   names them, and `luxel render` binds the lightmaps to the scene file);
 *   `luxel info` lists the settings, extras included;
 * - bad input: a wrong type in "nodes" and a scene whose every lightmap is
 *   off fail with one line, exit status 1, and no output folder. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"

#include <cjson/cJSON.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char dir[PATH_MAX];

/* Runs luxel with args (NULL-terminated); stdout and stderr to log. */
static int run_luxel(const char *const *args, const char *log)
{
    return lx_test_run_luxel(args, log, log);
}

static cJSON *read_json(const char *path)
{
    char text[1 << 16];
    lx_test_read_text(path, text, sizeof text);
    cJSON *j = cJSON_Parse(text);
    if (!j)
        fail_msg("%s is not JSON", path);
    return j;
}

static const cJSON *manifest_node(const cJSON *manifest, const char *name)
{
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItem(manifest, "nodes"))
    {
        const cJSON *n = cJSON_GetObjectItem(e, "node");
        if (cJSON_IsString(n) && strcmp(n->valuestring, name) == 0)
            return e;
    }
    return NULL;
}

static int count_substr(const char *text, const char *what)
{
    int n = 0;
    for (const char *p = strstr(text, what); p; p = strstr(p + 1, what))
        n++;
    return n;
}

static bool exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* A quad at y = 0 over [-h, h]^2 facing +Y, UVs (both sets) over [0, 1]:
 * u along +x, v along +z. */
static int floor_mesh(lx_test_gltf *g, float h, int mat)
{
    static float pos[12], nrm[12], uv[8];
    const float c[4][2] = {{-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
    for (int v = 0; v < 4; v++) {
        pos[3 * v] = c[v][0] * h, pos[3 * v + 1] = 0, pos[3 * v + 2] = c[v][1] * h;
        nrm[3 * v] = 0, nrm[3 * v + 1] = 1, nrm[3 * v + 2] = 0;
        uv[2 * v] = 0.5f * (c[v][0] + 1), uv[2 * v + 1] = 0.5f * (c[v][1] + 1);
    }
    static const uint32_t idx[6] = {0, 2, 1, 1, 2, 3}; /* counter-clockwise from +Y */
    lx_test_primitive p = {.vertex_count = 4,
                           .position = pos,
                           .normal = nrm,
                           .uv0 = uv,
                           .uv1 = uv,
                           .index_count = 6,
                           .indices = idx,
                           .material = mat};
    return lx_test_gltf_mesh(g, "floor", &p, 1);
}

/* An axis-aligned box with both UV sets. */
static int box_mesh(lx_test_gltf *g, const char *name, lx_vec3 lo, lx_vec3 hi, bool inward, int mat)
{
    lx_mesh m = lx_test_box(name, lo, hi, inward);
    lx_test_primitive p = {.vertex_count = (int)m.vertex_count,
                           .position = &m.positions[0].x,
                           .normal = &m.normals[0].x,
                           .uv0 = &m.uv[0][0].x,
                           .uv1 = &m.uv[0][0].x,
                           .index_count = 3 * (int)m.triangle_count,
                           .indices = m.indices,
                           .material = mat};
    int mesh = lx_test_gltf_mesh(g, name, &p, 1);
    lx_test_mesh_free(&m);
    return mesh;
}

#define HALF 20.0f   /* the floor's half side */
#define DOME 2000.0f /* the dome's side */
#define SUN 100000.0 /* lux */
static const double SUN_DIR[3] = {0.3, -1.0, 0.2};

static void write_domed(const char *path)
{
    lx_test_gltf *g = lx_test_gltf_new();
    int lit = lx_test_gltf_material(g, "{\"name\":\"concrete\"}");
    int sky =
        lx_test_gltf_material(g, "{\"name\":\"sky\",\"extensions\":{\"KHR_materials_unlit\":{}},"
                                 "\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.4,0.6,1,1]}}");
    lx_test_gltf_use_extension(g, "KHR_materials_unlit");
    lx_test_gltf_node(g, "Floor", floor_mesh(g, HALF, lit), "");
    lx_test_gltf_node(g, "Crate", box_mesh(g, "crate", lx_v3(5, 0, 5), lx_v3(6, 1, 6), false, lit),
                      "");
    float h = 0.5f * DOME;
    lx_test_gltf_node(g, "SkyDome",
                      box_mesh(g, "dome", lx_v3(-h, -h, -h), lx_v3(h, h, h), true, sky), "");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

/* The CLI's default density for world area `area` (docs/bake.md): 2^20
 * texels over it, held to 4..40, two significant digits. */
static double density_rule(double area)
{
    double d = sqrt(1048576.0 / area);
    d = d > 40.0 ? 40.0 : d < 4.0 ? 4.0 : d;
    double scale = pow(10.0, floor(log10(d)) - 1.0);
    return floor(d / scale + 0.5) * scale;
}

static void sky_dome(void **state)
{
    (void)state;
    char scene[PATH_MAX + 32], lights[PATH_MAX + 32], out[PATH_MAX + 32], log[PATH_MAX + 32];
    snprintf(scene, sizeof scene, "%s/pool.gltf", dir);
    snprintf(lights, sizeof lights, "%s/sun.json", dir);
    snprintf(out, sizeof out, "%s/domed", dir);
    snprintf(log, sizeof log, "%s/domed.log", dir);
    write_domed(scene);
    FILE *fp = fopen(lights, "w");
    assert_non_null(fp);
    fprintf(fp,
            "{\"lights\": [{\"name\": \"sun\", \"type\": \"directional\", \"direction\": [%g, %g, "
            "%g], \"intensity\": %g, \"unit\": \"lx\"}]}",
            SUN_DIR[0], SUN_DIR[1], SUN_DIR[2], SUN);
    fclose(fp);
    const char *bake[] = {"bake",      scene, "--lights", lights, "--bounces", "0",
                          "--denoise", "off", "-o",       out,    NULL};
    int code = run_luxel(bake, log);
    char text[8192];
    lx_test_read_text(log, text, sizeof text);
    print_message("luxel bake said:\n%s", text);
    assert_int_equal(code, 0);
    /* one warning, and it names the dome */
    assert_int_equal(count_substr(text, "warning:"), 1);
    assert_non_null(strstr(text, "node 'SkyDome' is an unlit mesh enclosing the scene (a sky "
                                 "dome): it casts no shadows and gets no lightmap"));

    char path[PATH_MAX * 2];
    snprintf(path, sizeof path, "%s/manifest.json", out);
    cJSON *manifest = read_json(path);
    assert_null(manifest_node(manifest, "SkyDome"));
    snprintf(path, sizeof path, "%s/SkyDome.exr", out);
    assert_false(exists(path));
    /* the density of the floor and crate alone: 40^2 m^2 + 6 m^2 */
    double want_density = density_rule(4.0 * HALF * HALF + 6.0);
    double density = cJSON_GetObjectItem(manifest, "texel_density")->valuedouble;
    print_message("texel density %g, the rule on the room alone %g\n", density, want_density);
    assert_true(fabs(density - want_density) < 1e-6 * want_density);

    /* the sun on the floor: E cos(theta) at every texel but the crate's
     * shadow's (a float product: within 1e-6) */
    const cJSON *e = manifest_node(manifest, "Floor");
    assert_non_null(e);
    const cJSON *page = cJSON_GetArrayItem(cJSON_GetObjectItem(manifest, "pages"),
                                           cJSON_GetObjectItem(e, "page")->valueint);
    snprintf(path, sizeof path, "%s/%s", out, cJSON_GetObjectItem(page, "file")->valuestring);
    lx_image img;
    if (lx_image_load(path, NULL, &img) != LX_OK)
        fail_msg("%s", lx_last_error());
    double len = sqrt(SUN_DIR[0] * SUN_DIR[0] + SUN_DIR[1] * SUN_DIR[1] + SUN_DIR[2] * SUN_DIR[2]);
    double want = SUN * (-SUN_DIR[1] / len);
    size_t pixels = (size_t)img.width * img.height, right = 0;
    for (size_t p = 0; p < pixels; p++)
        right += fabs(img.data[p * img.channels] - want) <= 1e-6 * want;
    print_message("%zu of %zu floor texels at E cos = %g lx\n", right, pixels, want);
    /* the crate's shadow: about 1 + 1.2 m^2 of 1600 m^2; bound 1% */
    assert_true(right >= 0.99 * pixels);
    lx_image_free(&img);
    cJSON_Delete(manifest);

    /* the default camera frames the room, from outside it, inside the dome */
    lx_scene *s;
    assert_int_equal(lx_scene_load(scene, NULL, &s), LX_OK);
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    lx_camera cam;
    lx_camera_auto_info info;
    assert_int_equal(lx_camera_auto(s, NULL, tr, 0.0f, 0.0f, &cam, &info), LX_OK);
    lx_camera room = lx_camera_frame(lx_v3(-HALF, 0, -HALF), lx_v3(HALF, 1, HALF), LX_VIEW_ISO,
                                     LX_DEG2RAD(LX_RENDER_DEFAULT_FOV_DEGREES), 16.0f / 9.0f);
    print_message("camera at (%g, %g, %g) (%s), the room's iso framing (%g, %g, %g)\n", cam.eye.x,
                  cam.eye.y, cam.eye.z, info.placement, room.eye.x, room.eye.y, room.eye.z);
    assert_false(info.moved);
    lx_test_assert_vec3(cam.eye, room.eye.x, room.eye.y, room.eye.z);
    lx_test_assert_vec3(cam.target, room.target.x, room.target.y, room.target.z);
    lx_tracer_destroy(tr);
    lx_scene_destroy(s);

    /* luxel render: the dome is not drawn (no "drawn black" warning) */
    char view[PATH_MAX + 32];
    snprintf(view, sizeof view, "%s/view.png", dir);
    const char *render[] = {"render", scene, "--lightmaps", out, "-o", view, NULL};
    assert_int_equal(run_luxel(render, log), 0);
    lx_test_read_text(log, text, sizeof text);
    assert_null(strstr(text, "drawn black"));
}

/* A floor, two boxes and a crate whose extras say it casts no shadow. */
static void write_boxes(const char *path)
{
    lx_test_gltf *g = lx_test_gltf_new();
    int lit = lx_test_gltf_material(g, "{\"name\":\"concrete\"}");
    lx_test_gltf_node(g, "Floor", floor_mesh(g, 2.0f, lit), "");
    lx_test_gltf_node(g, "Box_1", box_mesh(g, "b1", lx_v3(-1, 0, -1), lx_v3(0, 1, 0), false, lit),
                      "");
    lx_test_gltf_node(g, "Box_2",
                      box_mesh(g, "b2", lx_v3(0.5f, 0, 0.5f), lx_v3(1, 1, 1), false, lit), "");
    lx_test_gltf_node(g, "Glass",
                      box_mesh(g, "glass", lx_v3(1, 0, -1), lx_v3(1.5f, 0.5f, -0.5f), false, lit),
                      "\"extras\":{\"luxel_cast_shadows\":false,\"luxel_lightmap_scale\":2}");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void lights_json_nodes(void **state)
{
    (void)state;
    char scene[PATH_MAX + 32], lights[PATH_MAX + 32], out[PATH_MAX + 32], log[PATH_MAX + 32];
    snprintf(scene, sizeof scene, "%s/boxes.gltf", dir);
    snprintf(lights, sizeof lights, "%s/boxes.json", dir);
    snprintf(out, sizeof out, "%s/boxes", dir);
    snprintf(log, sizeof log, "%s/boxes.log", dir);
    write_boxes(scene);
    FILE *fp = fopen(lights, "w");
    assert_non_null(fp);
    fprintf(fp, "{\"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"intensity\": 100,"
                " \"unit\": \"cd\"}],\n \"nodes\": {\"Box_*\": {\"lightmap\": false}}}");
    fclose(fp);
    const char *bake[] = {"bake",      scene, "--lights", lights, "--bounces", "0",
                          "--denoise", "off", "-o",       out,    NULL};
    assert_int_equal(run_luxel(bake, log), 0);
    char path[PATH_MAX * 2];
    snprintf(path, sizeof path, "%s/manifest.json", out);
    cJSON *manifest = read_json(path);
    const cJSON *unbaked = cJSON_GetObjectItem(manifest, "nodes_without_lightmap");
    assert_int_equal(cJSON_GetArraySize(unbaked), 2);
    assert_string_equal(cJSON_GetArrayItem(unbaked, 0)->valuestring, "Box_1");
    assert_string_equal(cJSON_GetArrayItem(unbaked, 1)->valuestring, "Box_2");
    assert_null(manifest_node(manifest, "Box_1"));
    assert_null(manifest_node(manifest, "Box_2"));
    assert_non_null(manifest_node(manifest, "Floor"));
    assert_non_null(manifest_node(manifest, "Glass"));
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(manifest, "nodes")), 2);
    cJSON_Delete(manifest);
    snprintf(path, sizeof path, "%s/Box_1.exr", out);
    assert_false(exists(path));
    /* the manifest names the boxes, so `luxel render` of the scene file
     * (which does not say their lightmaps are off) binds its lightmaps */
    char view[PATH_MAX + 32];
    snprintf(view, sizeof view, "%s/boxes.png", dir);
    const char *render[] = {"render", scene, "--lightmaps", out, "-o", view, NULL};
    assert_int_equal(run_luxel(render, log), 0);

    /* luxel info lists the settings: the extras', and the lights file's */
    char info_out[PATH_MAX + 32], text[8192];
    snprintf(info_out, sizeof info_out, "%s/info.txt", dir);
    const char *info[] = {"info", scene, "--lights", lights, NULL};
    assert_int_equal(run_luxel(info, info_out), 0);
    lx_test_read_text(info_out, text, sizeof text);
    print_message("%s", text);
    const char *glass = strstr(text, "  Glass ");
    assert_non_null(glass);
    const char *end = strchr(glass, '\n');
    assert_non_null(strstr(glass, "no shadows  lightmap scale 2"));
    assert_true(strstr(glass, "no shadows") < end);
    const char *box = strstr(text, "  Box_1 ");
    assert_non_null(box);
    assert_true(strstr(box, "no lightmap") < strchr(box, '\n'));
}

static void bad_input(void **state)
{
    (void)state;
    char scene[PATH_MAX + 32], lights[PATH_MAX + 32], out[PATH_MAX + 32], log[PATH_MAX + 32];
    snprintf(scene, sizeof scene, "%s/bad.gltf", dir);
    snprintf(lights, sizeof lights, "%s/bad.json", dir);
    snprintf(out, sizeof out, "%s/bad", dir);
    snprintf(log, sizeof log, "%s/bad.log", dir);
    write_boxes(scene);
    static const struct {
        const char *json, *message;
    } cases[] = {
        {"{\"ambient\": [1, 1, 1], \"nodes\": {\"Box_*\": {\"lightmap\": \"no\"}}}",
         "nodes ('Box_*'): lightmap must be true or false"},
        {"{\"ambient\": [1, 1, 1], \"nodes\": {\"Box_*\": {\"lightmap_scale\": -1}}}",
         "nodes ('Box_*'): lightmap_scale -1 is outside 1/1024..1024"},
        {"{\"ambient\": [1, 1, 1], \"nodes\": {\"Box_1\": {\"shadows\": false}}}",
         "nodes ('Box_1'): unknown key 'shadows'"},
        {"{\"ambient\": [1, 1, 1], \"nodes\": {\"*\": {\"lightmap\": false}}}", NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        FILE *fp = fopen(lights, "w");
        assert_non_null(fp);
        fputs(cases[i].json, fp);
        fclose(fp);
        const char *bake[] = {"bake", scene, "--lights", lights, "--bounces", "0", "-o", out, NULL};
        assert_int_equal(run_luxel(bake, log), 1);
        char text[4096], want[PATH_MAX * 2];
        lx_test_read_text(log, text, sizeof text);
        if (cases[i].message)
            snprintf(want, sizeof want, "luxel: error: %s: %s\n", lights, cases[i].message);
        else
            snprintf(want, sizeof want,
                     "luxel: error: %s: every node has its lightmap turned off (luxel_lightmap "
                     "extras, \"lightmap\": false in the lights JSON's \"nodes\", or sky domes): "
                     "nothing to bake\n",
                     scene);
        assert_string_equal(text, want);
        assert_false(exists(out));
    }
}

int main(void)
{
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_node_flags"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sky_dome),
        cmocka_unit_test(lights_json_nodes),
        cmocka_unit_test(bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
