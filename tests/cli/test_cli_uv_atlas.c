/* A texture atlas's UVs taken for lightmap UVs. Eight boxes (eight meshes)
 * share one atlas in TEXCOORD_0, each over one cell of a 4x2 grid of the
 * square (its six faces tile the cell), as objects of a game level share
 * a texture atlas. Baked with their own UVs (--unwrap never), every node's
 * lightmap is its whole square, and its triangles cover the cell: exactly
 * 1/8 of the page's texels, the closed form when the page's side is a
 * multiple of 4 (the cell's edges i/4 and j/2 fall on texel edges; the
 * baker rounds sides up to multiples of 4).
 *
 * `luxel bake` (--unwrap auto, the default) finds them pieces of a square
 * the eight share (lx_uv_share_nodes): one warning naming "shared 8",
 * every node's UVs generated, and the pages' covered texels at least three
 * times the 1/8 (measured: 69% of one page, 5.5 times; the bound 3/8 sits
 * 1.8x below it, the test prints both). Instances of
 * one box whose UVs fill the square are left as they are: no warning, the
 * file's UVs kept. `luxel info` lists the eight pieces, and no instance.
 *
 * The CLI is the `luxel` next to this test's executable. */
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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define BOXES 8

static char dir[PATH_MAX];

/* Runs luxel with args (NULL-terminated); stdout and stderr to DIR/log. */
static int run_luxel(const char *const *args, char *text, size_t size)
{
    char log[PATH_MAX + 16];
    snprintf(log, sizeof log, "%s/log", dir);
    int code = lx_test_run_luxel(args, log, log);
    lx_test_read_text(log, text, size);
    if (code != 0)
        print_message("luxel said:\n%s\n", text);
    return code;
}

static cJSON *read_manifest(const char *out)
{
    char path[PATH_MAX + 32], *text = malloc(1 << 20);
    assert_non_null(text);
    snprintf(path, sizeof path, "%s/manifest.json", out);
    lx_test_read_text(path, text, 1 << 20);
    cJSON *j = cJSON_Parse(text);
    free(text);
    if (!j)
        fail_msg("%s is not JSON", path);
    return j;
}

/* A 1 m box at (2k, 0, 0), its six faces tiling the rectangle r = (x0, y0,
 * x1, y1) of the UV square in a 3x2 grid (TEXCOORD_0), written as
 * primitive p from the arrays given (24 vertices, 36 indices). */
static void box(int k, const float r[4], float pos[72], float nrm[72], float uv[48],
                uint32_t idx[36], lx_test_primitive *p)
{
    lx_mesh m = lx_test_box("box", lx_v3(2.0f * k, 0, 0), lx_v3(2.0f * k + 1, 1, 1), false);
    const float xs[4] = {r[0], r[0] + (r[2] - r[0]) / 3.0f, r[0] + 2.0f * (r[2] - r[0]) / 3.0f,
                         r[2]};
    const float ys[3] = {r[1], 0.5f * (r[1] + r[3]), r[3]};
    static const int ci[4] = {0, 1, 1, 0}, cj[4] = {0, 0, 1, 1};
    for (int v = 0; v < 24; v++) {
        pos[3 * v] = m.positions[v].x, pos[3 * v + 1] = m.positions[v].y;
        pos[3 * v + 2] = m.positions[v].z;
        nrm[3 * v] = m.normals[v].x, nrm[3 * v + 1] = m.normals[v].y;
        nrm[3 * v + 2] = m.normals[v].z;
        int f = v / 4, c = v % 4;
        uv[2 * v] = xs[f % 3 + ci[c]];
        uv[2 * v + 1] = ys[f / 3 + cj[c]];
    }
    memcpy(idx, m.indices, sizeof(uint32_t) * 36);
    lx_test_mesh_free(&m);
    *p = (lx_test_primitive){.vertex_count = 24,
                             .position = pos,
                             .normal = nrm,
                             .uv0 = uv,
                             .index_count = 36,
                             .indices = idx,
                             .material = -1};
}

/* The atlas: box k over cell (k % 4, k / 4) of a 4x2 grid, its own mesh. */
static void write_atlas(const char *path)
{
    lx_test_gltf *g = lx_test_gltf_new();
    for (int k = 0; k < BOXES; k++) {
        float i = (float)(k % 4), j = (float)(k / 4);
        const float r[4] = {i / 4, j / 2, (i + 1) / 4, (j + 1) / 2};
        float pos[72], nrm[72], uv[48];
        uint32_t idx[36];
        lx_test_primitive p;
        box(k, r, pos, nrm, uv, idx, &p);
        char name[16];
        snprintf(name, sizeof name, "box%d", k);
        lx_test_gltf_node(g, name, lx_test_gltf_mesh(g, name, &p, 1), "");
    }
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

/* Instances: one box mesh over the whole square, placed by BOXES nodes. */
static void write_instances(const char *path)
{
    lx_test_gltf *g = lx_test_gltf_new();
    const float r[4] = {0, 0, 1, 1};
    float pos[72], nrm[72], uv[48];
    uint32_t idx[36];
    lx_test_primitive p;
    box(0, r, pos, nrm, uv, idx, &p);
    int mesh = lx_test_gltf_mesh(g, "box", &p, 1);
    for (int k = 0; k < BOXES; k++) {
        char name[16], at[64];
        snprintf(name, sizeof name, "copy%d", k);
        snprintf(at, sizeof at, "\"translation\":[%d,0,0]", 2 * k);
        lx_test_gltf_node(g, name, mesh, at);
    }
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void write_lights(const char *path)
{
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fprintf(fp, "{\"lights\": [{\"type\": \"point\", \"position\": [7.5, 4, 3], "
                "\"intensity\": 500, \"unit\": \"cd\"}]}");
    fclose(fp);
}

/* Lines of text containing what. */
static int lines_with(const char *text, const char *what)
{
    int n = 0;
    for (const char *line = text; line && *line;) {
        const char *end = strchr(line, '\n');
        size_t len = end ? (size_t)(end - line) : strlen(line);
        char buf[4096];
        snprintf(buf, sizeof buf, "%.*s", (int)(len < sizeof buf ? len : sizeof buf - 1), line);
        n += strstr(buf, what) != NULL;
        line = end ? end + 1 : NULL;
    }
    return n;
}

/* Covered texels over page texels, all pages; each node's "uvs" is want. */
static double usage(const char *out, const char *want_uvs, bool cells)
{
    cJSON *m = read_manifest(out);
    double used = 0, all = 0;
    const cJSON *page;
    cJSON_ArrayForEach(page, cJSON_GetObjectItem(m, "pages"))
    {
        int w = cJSON_GetObjectItem(page, "width")->valueint;
        int h = cJSON_GetObjectItem(page, "height")->valueint;
        double u = cJSON_GetObjectItem(page, "used_texels")->valuedouble;
        if (cells) {
            /* a page of its own for one cell: exactly 1/8 of it */
            assert_int_equal(w % 4, 0);
            assert_int_equal(h % 2, 0);
            assert_float_equal(u, (double)w * h / 8, 0);
        }
        used += u;
        all += (double)w * h;
    }
    int nodes = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItem(m, "nodes"))
    {
        assert_string_equal(cJSON_GetObjectItem(e, "uvs")->valuestring, want_uvs);
        nodes++;
    }
    assert_int_equal(nodes, BOXES);
    cJSON_Delete(m);
    return used / all;
}

#define UNWRAP_WARNING "no usable TEXCOORD lightmap UVs"

static void atlas_pieces_unwrapped(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_uv_atlas"));
    char scene[PATH_MAX + 16], lights[PATH_MAX + 16], never[PATH_MAX + 16], aut[PATH_MAX + 16];
    snprintf(scene, sizeof scene, "%s/atlas.gltf", dir);
    snprintf(lights, sizeof lights, "%s/lights.json", dir);
    snprintf(never, sizeof never, "%s/never", dir);
    snprintf(aut, sizeof aut, "%s/auto", dir);
    write_atlas(scene);
    write_lights(lights);
    static char text[1 << 16];

    const char *keep[] = {"bake",      scene, "--lights",        lights, "--bounces", "0",
                          "--denoise", "off", "--texel-density", "16",   "--unwrap",  "never",
                          "-o",        never, NULL};
    assert_int_equal(run_luxel(keep, text, sizeof text), 0);
    assert_int_equal(lines_with(text, UNWRAP_WARNING), 0);
    double kept = usage(never, "own", true);

    const char *bake[] = {"bake",      scene, "--lights",        lights, "--bounces", "0",
                          "--denoise", "off", "--texel-density", "16",   "-o",        aut,
                          NULL};
    assert_int_equal(run_luxel(bake, text, sizeof text), 0);
    assert_int_equal(lines_with(text, UNWRAP_WARNING), 1);
    if (lines_with(text, "8 of 8 nodes have " UNWRAP_WARNING " (shared 8)") != 1)
        fail_msg("luxel said:\n%s", text);
    double made = usage(aut, "generated", false);
    const char *info[] = {"info", scene, NULL};
    assert_int_equal(run_luxel(info, text, sizeof text), 0);
    assert_int_equal(lines_with(text, "UV squares shared: 8 nodes' lightmap UVs are pieces"), 1);
    assert_int_equal(lines_with(text, "a UV square 8 nodes share (its UV box 12.5% of theirs"), 8);
    print_message("covered texels: %.4f of the pages with the atlas's UVs, %.4f unwrapped\n", kept,
                  made);
    assert_float_equal(kept, 0.125, 0);
    assert_true(made >= 3 * kept);
}

static void instances_kept(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_uv_atlas_instances"));
    char scene[PATH_MAX + 16], lights[PATH_MAX + 16], out[PATH_MAX + 16];
    snprintf(scene, sizeof scene, "%s/copies.gltf", dir);
    snprintf(lights, sizeof lights, "%s/lights.json", dir);
    snprintf(out, sizeof out, "%s/out", dir);
    write_instances(scene);
    write_lights(lights);
    static char text[1 << 16];
    const char *bake[] = {"bake",      scene, "--lights",        lights, "--bounces", "0",
                          "--denoise", "off", "--texel-density", "16",   "-o",        out,
                          NULL};
    assert_int_equal(run_luxel(bake, text, sizeof text), 0);
    assert_int_equal(lines_with(text, UNWRAP_WARNING), 0);
    usage(out, "own", false);
    const char *info[] = {"info", scene, NULL};
    assert_int_equal(run_luxel(info, text, sizeof text), 0);
    assert_int_equal(lines_with(text, "UV squares shared"), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(atlas_pieces_unwrapped),
        cmocka_unit_test(instances_kept),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
