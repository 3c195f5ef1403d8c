/* One truth for where a node's lightmap UVs live. A floor whose material
 * reads an occlusion map through TEXCOORD_1 is baked by the CLI with
 * generated UVs (--unwrap always). Once, the .glb put them in TEXCOORD_2
 * while the manifest (and luxel render) named TEXCOORD_1 - the occlusion
 * set - and the scene rendered with blotches.
 *
 * Checked here against outside values, not luxel's own:
 * - the manifest names the set (TEXCOORD_2) and the scene_with_uvs file
 *   holds the generated UVs there, with TEXCOORD_1 still the file's own
 *   (every value one of the input's);
 * - the lightmap read at each floor vertex through the named set holds the
 *   point light's irradiance E = I h / d^3 (closed form, no bounces)
 *   within 5% (texels of 6 cm at the edges: the half-texel the bilinear
 *   read spans moves E by at most 3%); read through TEXCOORD_1, the
 *   occlusion set, it does not (the check can tell the sets apart);
 * - `luxel render` of the output succeeds;
 * - baking the written file again takes TEXCOORD_2 as the lightmap set
 *   (its manifest says so) without generating UVs.
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
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define GRID 4          /* quads per side */
#define SIDE 4.0f       /* metres */
#define HEIGHT 1.5      /* of the light above the floor */
#define INTENSITY 900.0 /* cd */
static const double LIGHT_X = 0.5, LIGHT_Z = -0.25;

static char dir[PATH_MAX];

/* Runs luxel with args (NULL-terminated); output to DIR/cli.log. */
static int run_luxel(const char *const *args)
{
    char log[PATH_MAX + 16];
    snprintf(log, sizeof log, "%s/cli.log", dir);
    int code = lx_test_run_luxel(args, log, log);
    if (code != 0) {
        char text[4096];
        lx_test_read_text(log, text, sizeof text);
        print_message("luxel said:\n%s\n", text);
    }
    return code;
}

static cJSON *read_json(const char *path)
{
    char *text = NULL;
    size_t size = 0;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        fail_msg("cannot open %s", path);
    fseek(fp, 0, SEEK_END);
    size = (size_t)ftell(fp);
    fseek(fp, 0, SEEK_SET);
    text = malloc(size + 1);
    assert_non_null(text);
    assert_int_equal(fread(text, 1, size, fp), size);
    text[size] = '\0';
    fclose(fp);
    cJSON *j = cJSON_Parse(text);
    free(text);
    if (!j)
        fail_msg("%s is not JSON", path);
    return j;
}

/* The node entry of the manifest in out/. */
static const cJSON *manifest_node(const cJSON *manifest, const char *name)
{
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItem(manifest, "nodes"))
    {
        const cJSON *n = cJSON_GetObjectItem(e, "node");
        if (cJSON_IsString(n) && strcmp(n->valuestring, name) == 0)
            return e;
    }
    fail_msg("the manifest has no node '%s'", name);
    return NULL;
}

/* The floor: GRID x GRID quads over SIDE metres at y = 0, facing +Y.
 * TEXCOORD_0 spans the unit square; TEXCOORD_1 (the occlusion map's) the
 * same squeezed into [0, 0.5]^2 and mirrored, so it is no lightmap set. */
static void write_scene(const char *path)
{
    enum { N = (GRID + 1) * (GRID + 1) };
    float pos[3 * N], nrm[3 * N], uv0[2 * N], uv1[2 * N];
    uint32_t idx[6 * GRID * GRID];
    for (int j = 0; j <= GRID; j++)
        for (int i = 0; i <= GRID; i++) {
            int v = j * (GRID + 1) + i;
            float u = (float)i / GRID, w = (float)j / GRID;
            pos[3 * v] = -SIDE / 2 + SIDE * u;
            pos[3 * v + 1] = 0;
            pos[3 * v + 2] = -SIDE / 2 + SIDE * w;
            nrm[3 * v] = 0, nrm[3 * v + 1] = 1, nrm[3 * v + 2] = 0;
            uv0[2 * v] = u, uv0[2 * v + 1] = w;
            uv1[2 * v] = 0.5f * (1 - u), uv1[2 * v + 1] = 0.5f * w;
        }
    int k = 0;
    for (int j = 0; j < GRID; j++)
        for (int i = 0; i < GRID; i++) {
            uint32_t a = (uint32_t)(j * (GRID + 1) + i), b = a + 1, c = a + GRID + 1, d = c + 1;
            /* counter-clockwise seen from +Y */
            uint32_t t[6] = {a, c, b, b, c, d};
            memcpy(&idx[k], t, sizeof t);
            k += 6;
        }
    char png[PATH_MAX + 8];
    snprintf(png, sizeof png, "%s/ao.png", dir);
    uint8_t grey[4 * 3];
    memset(grey, 200, sizeof grey);
    lx_test_write_png(png, 2, 2, 3, grey);
    lx_test_gltf *g = lx_test_gltf_new();
    int tex = lx_test_gltf_texture(g, "ao.png");
    char mat[256];
    snprintf(mat, sizeof mat,
             "{\"name\":\"concrete\",\"occlusionTexture\":{\"index\":%d,\"texCoord\":1},"
             "\"pbrMetallicRoughness\":{\"metallicFactor\":0}}",
             tex);
    int m = lx_test_gltf_material(g, mat);
    lx_test_primitive p = {.vertex_count = N,
                           .position = pos,
                           .normal = nrm,
                           .uv0 = uv0,
                           .uv1 = uv1,
                           .index_count = 6 * GRID * GRID,
                           .indices = idx,
                           .material = m};
    lx_test_gltf_node(g, "floor", lx_test_gltf_mesh(g, "floor", &p, 1), "");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static double bilinear(const lx_image *img, double u, double v)
{
    double x = u * img->width - 0.5, y = v * img->height - 0.5;
    int x0 = (int)floor(x), y0 = (int)floor(y);
    double fx = x - x0, fy = y - y0, sum = 0;
    for (int dy = 0; dy < 2; dy++)
        for (int dx = 0; dx < 2; dx++) {
            int px = x0 + dx, py = y0 + dy;
            px = px < 0 ? 0 : px >= img->width ? img->width - 1 : px;
            py = py < 0 ? 0 : py >= img->height ? img->height - 1 : py;
            /* luminance-free: the light is white, read channel 0 */
            double t = img->data[((size_t)py * img->width + px) * img->channels];
            sum += t * (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy);
        }
    return sum;
}

/* The largest relative error of the lightmap read at every floor vertex
 * through UV set `set` (scale_offset applied) against E = I h / d^3. */
static double worst_error(const lx_scene *s, const lx_image *page, const float so[4], int set)
{
    double worst = 0;
    for (uint32_t k = 0; k < s->nodes[0].mesh_count; k++) {
        const lx_mesh *m = &s->meshes[s->nodes[0].meshes[k]];
        assert_non_null(m->uv[set]);
        for (uint32_t v = 0; v < m->vertex_count; v++) {
            double dx = m->positions[v].x - LIGHT_X, dz = m->positions[v].z - LIGHT_Z;
            double d = sqrt(dx * dx + dz * dz + HEIGHT * HEIGHT);
            double want = INTENSITY * HEIGHT / (d * d * d);
            double u = m->uv[set][v].x * so[0] + so[2], w = m->uv[set][v].y * so[1] + so[3];
            double got = bilinear(page, u, w);
            double err = fabs(got - want) / want;
            worst = err > worst ? err : worst;
        }
    }
    return worst;
}

static void floor_set(const char *out, int want_set, const char *want_uvs, const char *scene_file)
{
    char path[PATH_MAX * 2];
    snprintf(path, sizeof path, "%s/manifest.json", out);
    cJSON *manifest = read_json(path);
    const cJSON *e = manifest_node(manifest, "floor");
    char want_name[16];
    snprintf(want_name, sizeof want_name, "TEXCOORD_%d", want_set);
    assert_string_equal(cJSON_GetObjectItem(e, "uv_set")->valuestring, want_name);
    assert_string_equal(cJSON_GetObjectItem(e, "uvs")->valuestring, want_uvs);
    float so[4];
    for (int i = 0; i < 4; i++)
        so[i] = (float)cJSON_GetArrayItem(cJSON_GetObjectItem(e, "scale_offset"), i)->valuedouble;
    int page_index = cJSON_GetObjectItem(e, "page")->valueint;
    const cJSON *page = cJSON_GetArrayItem(cJSON_GetObjectItem(manifest, "pages"), page_index);
    snprintf(path, sizeof path, "%s/%s", out, cJSON_GetObjectItem(page, "file")->valuestring);
    lx_image img;
    if (lx_image_load(path, NULL, &img) != LX_OK)
        fail_msg("%s", lx_last_error());
    /* the scene that holds the UVs: scene_with_uvs, else the input */
    const cJSON *with = cJSON_GetObjectItem(manifest, "scene_with_uvs");
    if (cJSON_IsString(with))
        snprintf(path, sizeof path, "%s/%s", out, with->valuestring);
    else
        snprintf(path, sizeof path, "%s", scene_file);
    lx_scene *s;
    if (lx_scene_load(path, NULL, &s) != LX_OK)
        fail_msg("%s", lx_last_error());
    assert_int_equal(s->node_count, 1);
    double through_named = worst_error(s, &img, so, want_set);
    double through_occlusion = worst_error(s, &img, so, 1);
    print_message("%s: worst error through %s %.4f, through TEXCOORD_1 %.4f\n", out, want_name,
                  through_named, through_occlusion);
    assert_true(through_named < 0.05);
    assert_true(through_occlusion > 0.2);
    lx_scene_destroy(s);
    lx_image_free(&img);
    cJSON_Delete(manifest);
}

static void generated_uvs_where_the_manifest_says(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_uv_sets"));
    char scene[PATH_MAX + 16], lights[PATH_MAX + 16], out[PATH_MAX + 16];
    snprintf(scene, sizeof scene, "%s/floor.gltf", dir);
    snprintf(lights, sizeof lights, "%s/lights.json", dir);
    snprintf(out, sizeof out, "%s/out", dir);
    write_scene(scene);
    FILE *fp = fopen(lights, "w");
    assert_non_null(fp);
    fprintf(fp,
            "{\"lights\": [{\"type\": \"point\", \"position\": [%g, %g, %g], \"intensity\": %g,"
            " \"unit\": \"cd\"}]}",
            LIGHT_X, HEIGHT, LIGHT_Z, INTENSITY);
    fclose(fp);
    const char *bake[] = {"bake",    scene,      "--lights", lights, "--unwrap", "always",
                          "--bounces", "0",      "--texel-density", "16", "--denoise", "off",
                          "-q",      "-o",       out,        NULL};
    assert_int_equal(run_luxel(bake), 0);
    floor_set(out, 2, "generated", scene);

    /* the written file keeps the occlusion map's set as it was */
    char glb[PATH_MAX * 2];
    cJSON *manifest;
    {
        char path[PATH_MAX * 2];
        snprintf(path, sizeof path, "%s/manifest.json", out);
        manifest = read_json(path);
        snprintf(glb, sizeof glb, "%s/%s", out,
                 cJSON_GetObjectItem(manifest, "scene_with_uvs")->valuestring);
        cJSON_Delete(manifest);
    }
    lx_scene *in, *written;
    assert_int_equal(lx_scene_load(scene, NULL, &in), LX_OK);
    assert_int_equal(lx_scene_load(glb, NULL, &written), LX_OK);
    const lx_mesh *a = &in->meshes[0];
    for (uint32_t k = 0; k < written->nodes[0].mesh_count; k++) {
        const lx_mesh *b = &written->meshes[written->nodes[0].meshes[k]];
        for (uint32_t v = 0; v < b->vertex_count; v++) {
            bool found = false;
            for (uint32_t w = 0; w < a->vertex_count && !found; w++)
                found = a->uv[1][w].x == b->uv[1][v].x && a->uv[1][w].y == b->uv[1][v].y;
            if (!found)
                fail_msg("written vertex %u: TEXCOORD_1 (%g, %g) is not one of the input's", v,
                         b->uv[1][v].x, b->uv[1][v].y);
        }
    }
    assert_int_equal(written->materials[written->meshes[0].material].uv_sets_read & 2u, 2u);
    lx_scene_destroy(in);
    lx_scene_destroy(written);

    char view[PATH_MAX + 16];
    snprintf(view, sizeof view, "%s/view.png", dir);
    const char *render[] = {"render", scene, "--lightmaps", out, "-q", "-o", view, NULL};
    assert_int_equal(run_luxel(render), 0);

    /* baked again from the written file: its own set, no new UVs */
    char again[PATH_MAX + 16];
    snprintf(again, sizeof again, "%s/again", dir);
    const char *rebake[] = {"bake",      glb,  "--lights", lights, "--bounces", "0",
                            "--denoise", "off", "--texel-density", "16", "-q", "-o", again, NULL};
    assert_int_equal(run_luxel(rebake), 0);
    floor_set(again, 2, "own", glb);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(generated_uvs_where_the_manifest_says),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
