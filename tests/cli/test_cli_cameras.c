/* `luxel render` and `luxel info` with a glTF file's cameras, end to end:
 * a closed room (a 6 x 3 x 4 m box whose faces look in, lit by a point
 * light) with two cameras, written here, baked by the CLI, then
 * - the default render uses camera 0 and says so on stderr;
 * - --gltf-camera 0, --gltf-camera Main (its name) and --gltf-camera
 *   main_cam (its node's name) give the same bytes, and those equal the
 *   render from --camera with the eye, target and up worked out here from
 *   the node's matrix (entries 0 and +-1, exact) and --fov 40, the file's
 *   yfov being written as the float luxel makes of 40 degrees;
 * - --gltf-camera 1 equals --camera of camera 1's pose; --fov replaces
 *   the file's yfov;
 * - a bad index or name fails with status 2, one error line that counts
 *   and names the cameras, and no image; --gltf-camera with --view too;
 * - luxel info lists both cameras;
 * - the same room without cameras is rendered from inside (the iso view
 *   from outside meets the walls' back faces), saying why.
 * The CLI is the `luxel` next to this test's executable. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char dir[PATH_MAX];
static char out_log[PATH_MAX + 16], err_log[PATH_MAX + 16];
static char cams_gltf[PATH_MAX + 32], plain_gltf[PATH_MAX + 32];
static char cams_maps[PATH_MAX + 32], plain_maps[PATH_MAX + 32];

/* Runs luxel with args (NULL-terminated); stdout and stderr go to
 * DIR/out.log and DIR/err.log. Returns the exit status. */
static int run(const char *const *args)
{
    return lx_test_run_luxel(args, out_log, err_log);
}

static char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    static char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    if (size)
        *size = n;
    char *copy = malloc(n + 1);
    assert_non_null(copy);
    memcpy(copy, buf, n + 1);
    return copy;
}

static void expect_in(const char *path, const char *needle)
{
    char *text = slurp(path, NULL);
    assert_non_null(text);
    if (!strstr(text, needle))
        fail_msg("%s does not say '%s':\n%s", path, needle, text);
    free(text);
}

static void expect_same_file(const char *a, const char *b)
{
    size_t na, nb;
    char *x = slurp(a, &na), *y = slurp(b, &nb);
    if (!x || !y)
        fail_msg("%s or %s is missing", a, b);
    if (na != nb || memcmp(x, y, na) != 0)
        fail_msg("%s and %s differ", a, b);
    free(x);
    free(y);
}

static const char *in_dir(const char *name)
{
    static char buf[8][PATH_MAX + 64];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void render_ok(const char *image, const char *const *extra)
{
    const char *args[32] = {"render", cams_gltf, "--lightmaps", cams_maps, "-o", in_dir(image),
                            "--size", "64x36", "--samples", "2", "--exposure", "8"};
    int n = 12;
    for (; *extra; extra++)
        args[n++] = *extra;
    args[n] = NULL;
    int rc = run(args);
    if (rc != 0) {
        char *err = slurp(err_log, NULL);
        fail_msg("luxel render -o %s: status %d: %s", image, rc, err ? err : "");
    }
}

/* the room as a glTF (with cameras when cameras is not NULL) */
static void write_room(const char *path, const char *cameras_top, const char *const *camera_nodes,
                       int camera_node_count)
{
    lx_mesh m = lx_test_box("room", lx_v3(-3, 0, -2), lx_v3(3, 3, 2), true);
    lx_test_primitive p = {.vertex_count = (int)m.vertex_count,
                           .position = &m.positions[0].x,
                           .normal = &m.normals[0].x,
                           .uv0 = &m.uv[0][0].x,
                           .uv1 = &m.uv[1][0].x,
                           .index_count = (int)(3 * m.triangle_count),
                           .indices = m.indices,
                           .material = 0};
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_material(g, "{\"name\":\"white\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
                             "[0.8,0.8,0.8,1],\"metallicFactor\":0}}");
    lx_test_gltf_node(g, "room", lx_test_gltf_mesh(g, "room", &p, 1), "");
    for (int i = 0; i < camera_node_count; i += 2)
        lx_test_gltf_node(g, camera_nodes[i], -1, camera_nodes[i + 1]);
    if (cameras_top)
        lx_test_gltf_top(g, cameras_top);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_test_mesh_free(&m);
}

static void bake(const char *scene, const char *out)
{
    const char *lights = in_dir("lights.json");
    FILE *f = fopen(lights, "w");
    assert_non_null(f);
    fputs("{\"lights\": [{\"type\": \"point\", \"position\": [0.5, 2.5, 0.3], \"intensity\": 200,"
          " \"unit\": \"cd\"}]}",
          f);
    assert_int_equal(fclose(f), 0);
    const char *args[] = {"bake", scene, "--lights", lights, "--resolution", "32", "--bounces",
                          "0", "-q", "-o", out, NULL};
    int rc = run(args);
    if (rc != 0) {
        char *err = slurp(err_log, NULL);
        fail_msg("luxel bake %s: status %d: %s", scene, rc, err ? err : "");
    }
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_cameras"));
    snprintf(out_log, sizeof out_log, "%s/out.log", dir);
    snprintf(err_log, sizeof err_log, "%s/err.log", dir);
    snprintf(cams_gltf, sizeof cams_gltf, "%s/cams.gltf", dir);
    snprintf(plain_gltf, sizeof plain_gltf, "%s/plain.gltf", dir);
    snprintf(cams_maps, sizeof cams_maps, "%s/cams-maps", dir);
    snprintf(plain_maps, sizeof plain_maps, "%s/plain-maps", dir);

    /* yfov: the float luxel makes of --fov 40, printed so it reads back the same */
    char top[512];
    float fov = LX_DEG2RAD((float)40.0);
    snprintf(top, sizeof top,
             "\"cameras\":[{\"name\":\"Main\",\"type\":\"perspective\",\"perspective\":"
             "{\"yfov\":%.9g,\"aspectRatio\":1.333,\"znear\":0.1,\"zfar\":100}},"
             "{\"name\":\"Side\",\"type\":\"perspective\",\"perspective\":"
             "{\"yfov\":%.9g,\"znear\":0.1}}]",
             (double)fov, (double)fov);
    /* main_cam: 90 degrees about Y (local -Z looks along +X) at
     * (-2.5, 1.5, 0.25); side_cam: unrotated (looks along -Z) at (0.5, 1.25, 1.5) */
    const char *nodes[] = {
        "main_cam", "\"matrix\":[0,0,1,0, 0,1,0,0, -1,0,0,0, -2.5,1.5,0.25,1],\"camera\":0",
        "side_cam", "\"translation\":[0.5,1.25,1.5],\"camera\":1"};
    write_room(cams_gltf, top, nodes, 4);
    write_room(plain_gltf, NULL, NULL, 0);
    bake(cams_gltf, cams_maps);
    bake(plain_gltf, plain_maps);
    return 0;
}

static void default_is_first_camera(void **state)
{
    (void)state;
    const char *none[] = {NULL};
    render_ok("default.png", none);
    expect_in(err_log, "camera 0 'Main' (node 'main_cam')");
    const char *by_index[] = {"--gltf-camera", "0", NULL};
    render_ok("index0.png", by_index);
    const char *by_name[] = {"--gltf-camera", "Main", NULL};
    render_ok("name.png", by_name);
    const char *by_node[] = {"--gltf-camera", "main_cam", NULL};
    render_ok("node.png", by_node);
    /* eye (-2.5, 1.5, 0.25), forward +X, up +Y */
    const char *manual[] = {"--camera", "-2.5,1.5,0.25,-1.5,1.5,0.25,0,1,0", "--fov", "40", NULL};
    render_ok("manual0.png", manual);
    expect_same_file(in_dir("default.png"), in_dir("index0.png"));
    expect_same_file(in_dir("default.png"), in_dir("name.png"));
    expect_same_file(in_dir("default.png"), in_dir("node.png"));
    expect_same_file(in_dir("default.png"), in_dir("manual0.png"));
}

/* --fov replaces the camera's yfov */
static void fov_override(void **state)
{
    (void)state;
    const char *with_fov[] = {"--gltf-camera", "Main", "--fov", "65", NULL};
    render_ok("fov65.png", with_fov);
    expect_in(err_log, "--fov field of view 65 degrees");
    const char *manual[] = {"--camera", "-2.5,1.5,0.25,-1.5,1.5,0.25,0,1,0", "--fov", "65", NULL};
    render_ok("manual65.png", manual);
    expect_same_file(in_dir("fov65.png"), in_dir("manual65.png"));
}

static void second_camera(void **state)
{
    (void)state;
    const char *by_index[] = {"--gltf-camera", "1", NULL};
    render_ok("index1.png", by_index);
    expect_in(err_log, "camera 1 'Side'");
    const char *by_name[] = {"--gltf-camera", "Side", NULL};
    render_ok("side.png", by_name);
    const char *manual[] = {"--camera", "0.5,1.25,1.5,0.5,1.25,0.5,0,1,0", "--fov", "40", NULL};
    render_ok("manual1.png", manual);
    expect_same_file(in_dir("index1.png"), in_dir("side.png"));
    expect_same_file(in_dir("index1.png"), in_dir("manual1.png"));
    /* not the first camera's view */
    size_t na, nb;
    char *a = slurp(in_dir("index1.png"), &na), *b = slurp(in_dir("index0.png"), &nb);
    assert_true(na != nb || memcmp(a, b, na) != 0);
    free(a);
    free(b);
}

/* status 2, exactly one line on stderr holding every needle, no image */
static void expect_usage_error(const char *const *extra, const char *const *needles)
{
    const char *image = in_dir("bad.png");
    unlink(image);
    const char *args[32] = {"render", cams_gltf, "--lightmaps", cams_maps, "-o", image,
                            "--size", "32x18"};
    int n = 8;
    for (; *extra; extra++)
        args[n++] = *extra;
    args[n] = NULL;
    int rc = run(args);
    char *err = slurp(err_log, NULL);
    assert_non_null(err);
    if (rc != 2)
        fail_msg("status %d, want 2: %s", rc, err);
    char *nl = strchr(err, '\n');
    if (strncmp(err, "luxel: error: ", 14) != 0 || !nl || nl[1] != '\0')
        fail_msg("want one error line, got:\n%s", err);
    for (; *needles; needles++)
        if (!strstr(err, *needles))
            fail_msg("'%s' does not say '%s'", err, *needles);
    free(err);
    assert_int_equal(access(image, F_OK), -1);
}

static void bad_selection(void **state)
{
    (void)state;
    const char *index[] = {"--gltf-camera", "2", NULL};
    const char *want[] = {"cams.gltf", "--gltf-camera 2", "2 cameras", "0 'Main'", "1 'Side'",
                          NULL};
    expect_usage_error(index, want);
    const char *name[] = {"--gltf-camera", "Nope", NULL};
    const char *want_name[] = {"no such camera", "Nope", "2 cameras", "0 'Main'", NULL};
    expect_usage_error(name, want_name);
    const char *with_view[] = {"--gltf-camera", "0", "--view", "iso", NULL};
    const char *want_view[] = {"--view and --gltf-camera", NULL};
    expect_usage_error(with_view, want_view);
    const char *with_camera[] = {"--gltf-camera", "0", "--camera", "0,1,0,1,1,0", NULL};
    const char *want_camera[] = {"--camera and --gltf-camera", NULL};
    expect_usage_error(with_camera, want_camera);
}

static void info_lists_cameras(void **state)
{
    (void)state;
    const char *args[] = {"info", cams_gltf, NULL};
    assert_int_equal(run(args), 0);
    expect_in(out_log, "cameras: 2");
    expect_in(out_log, "Main");
    expect_in(out_log, "yfov 40 deg");
    expect_in(out_log, "node 'main_cam'");
    expect_in(out_log, "Side");
    expect_in(out_log, "at (0.5, 1.25, 1.5)");
}

static void no_camera_goes_inside(void **state)
{
    (void)state;
    const char *image = in_dir("plain.png");
    const char *args[] = {"render", plain_gltf, "--lightmaps", plain_maps, "-o", image,
                          "--size", "64x36", "--samples", "2", NULL};
    int rc = run(args);
    char *err = slurp(err_log, NULL);
    if (rc != 0)
        fail_msg("status %d: %s", rc, err ? err : "");
    free(err);
    /* a closed room: shown from inside, and the CLI says why */
    expect_in(err_log, "is a closed room (walls all round)");
    expect_in(err_log, "inside, looking along");
    assert_int_equal(access(image, F_OK), 0);
    /* --view iso keeps the outside framing, and says nothing of it */
    const char *iso[] = {"render", plain_gltf, "--lightmaps", plain_maps, "-o", in_dir("iso.png"),
                         "--size", "64x36", "--samples", "2", "--view", "iso", NULL};
    assert_int_equal(run(iso), 0);
    err = slurp(err_log, NULL);
    assert_null(strstr(err, "back faces"));
    assert_null(strstr(err, "closed room"));
    free(err);
    /* a camera asked of a file without any: status 2, one line */
    const char *none[] = {"render", plain_gltf, "--lightmaps", plain_maps, "-o",
                          in_dir("none.png"), "--gltf-camera", "0", NULL};
    assert_int_equal(run(none), 2);
    err = slurp(err_log, NULL);
    if (!strstr(err, "plain.gltf: --gltf-camera 0: the scene has no cameras") ||
        strchr(err, '\n')[1] != '\0')
        fail_msg("'%s'", err);
    free(err);
    assert_int_equal(access(in_dir("none.png"), F_OK), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(default_is_first_camera), cmocka_unit_test(fov_override),
        cmocka_unit_test(second_camera),
        cmocka_unit_test(bad_selection),           cmocka_unit_test(info_lists_cameras),
        cmocka_unit_test(no_camera_goes_inside),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
