/* lx_scene_write_glb: scenes written with the unwrapper's lightmap UVs and
 * read back through assimp (lx_scene_load), an independent reader. The
 * round trip must keep every triangle, in order, at the same world
 * positions, with TEXCOORD_1 equal to the unwrapper's UVs at each corner;
 * materials and node names stay, and the JSON the writer does not own
 * (extras, KHR_lights_punctual, other extensions) is equal as JSON values.
 * The Khronos glTF-Validator (npm, a test oracle installed by
 * scripts/install-test-oracles.sh) must report no error on the outputs;
 * those tests are skipped where it is not installed. Inputs are written
 * by tests/common/gltf_writer.c or as OBJ text here; the
 * EXT_meshopt_compression input (gltfpack's layout: the primitives'
 * attributes and indices sharing compressed views, octahedral int8
 * normals, a fallback buffer without data) is encoded here with
 * meshoptimizer's encoders. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <meshoptimizer.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static bool exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

/* A box as one primitive's arrays (floats for the test writer). */
typedef struct prim_data {
    float *pos, *nrm, *uv0;
    uint32_t *idx;
    int nv, ni;
} prim_data;

static prim_data box_data(lx_vec3 lo, lx_vec3 hi)
{
    lx_mesh m = lx_test_box("b", lo, hi, false);
    prim_data p = {.nv = (int)m.vertex_count, .ni = 3 * (int)m.triangle_count};
    p.pos = malloc(sizeof(float) * 3 * m.vertex_count);
    p.nrm = malloc(sizeof(float) * 3 * m.vertex_count);
    p.uv0 = malloc(sizeof(float) * 2 * m.vertex_count);
    p.idx = malloc(sizeof(uint32_t) * (size_t)p.ni);
    assert_true(p.pos && p.nrm && p.uv0 && p.idx);
    memcpy(p.pos, m.positions, sizeof(float) * 3 * m.vertex_count);
    memcpy(p.nrm, m.normals, sizeof(float) * 3 * m.vertex_count);
    memcpy(p.uv0, m.uv[0], sizeof(float) * 2 * m.vertex_count);
    memcpy(p.idx, m.indices, sizeof(uint32_t) * (size_t)p.ni);
    lx_test_mesh_free(&m);
    return p;
}

static void prim_free(prim_data *p)
{
    free(p->pos);
    free(p->nrm);
    free(p->uv0);
    free(p->idx);
}

static lx_test_primitive prim_of(const prim_data *p, int material)
{
    return (lx_test_primitive){.vertex_count = p->nv,
                               .position = p->pos,
                               .normal = p->nrm,
                               .uv0 = p->uv0,
                               .index_count = p->ni,
                               .indices = p->idx,
                               .material = material};
}

/* Loads in_path, unwraps it at 16 texels per metre and writes out_path. */
static void unwrap_and_write(const char *in_path, const char *out_path, lx_scene **scene,
                             lx_unwrap **unwrap)
{
    assert_int_equal(lx_scene_load(in_path, NULL, scene), LX_OK);
    lx_unwrap_desc d = lx_unwrap_desc_defaults(NULL);
    d.texel_density = 16.0f;
    d.padding = LX_UNWRAP_PADDING_RECOMMENDED;
    d.threads = 2;
    assert_int_equal(lx_unwrap_scene(*scene, &d, unwrap), LX_OK);
    lx_scene_uvs *uvs = calloc((*unwrap)->mesh_count, sizeof *uvs);
    assert_non_null(uvs);
    for (uint32_t k = 0; k < (*unwrap)->mesh_count; k++) {
        const lx_unwrap_mesh *m = &(*unwrap)->meshes[k];
        uvs[k] = (lx_scene_uvs){.node = m->node,
                                .mesh = m->mesh,
                                .vertex_count = m->vertex_count,
                                .vertex_source = m->vertex_source,
                                .uv = m->uv,
                                .indices = m->indices};
    }
    lx_glb_write_desc wd = {.uvs = uvs, .uv_count = (*unwrap)->mesh_count};
    lx_status st = lx_scene_write_glb(*scene, out_path, &wd);
    if (st != LX_OK)
        fail_msg("%s", lx_last_error());
    free(uvs);
}

static void assert_close3(lx_vec3 a, lx_vec3 b)
{
    /* world positions go through the same float matrix products */
    for (int k = 0; k < 3; k++) {
        float x = (&a.x)[k], y = (&b.x)[k];
        if (!(fabsf(x - y) <= 1e-6f * fmaxf(1.0f, fabsf(y))))
            fail_msg("position component %d: %.9g, want %.9g", k, x, y);
    }
}

/* Every unwrapped (node, mesh) of s against the written scene read back:
 * the node of the same name places, in the same slot, a mesh with the
 * same triangles in order, the same world positions, the unwrapper's UVs
 * in TEXCOORD_1 and the same material. Returns the vertices read back. */
static uint32_t check_round_trip(const lx_scene *s, const lx_unwrap *u, const char *out_path)
{
    lx_scene *r;
    lx_status st = lx_scene_load(out_path, NULL, &r);
    if (st != LX_OK)
        fail_msg("%s", lx_last_error());
    assert_int_equal(r->node_count, s->node_count);
    assert_int_equal(r->light_count, s->light_count);
    uint32_t vertices = 0;
    for (uint32_t k = 0; k < u->mesh_count; k++) {
        const lx_unwrap_mesh *um = &u->meshes[k];
        const lx_node *n = &s->nodes[um->node];
        const lx_node *rn = &r->nodes[lx_test_node_named(r, n->name)];
        uint32_t slot = 0;
        while (slot < n->mesh_count && n->meshes[slot] != um->mesh)
            slot++;
        assert_true(slot < n->mesh_count);
        assert_int_equal(rn->mesh_count, n->mesh_count);
        const lx_mesh *m = &s->meshes[um->mesh], *rm = &r->meshes[rn->meshes[slot]];
        assert_int_equal(rm->triangle_count, m->triangle_count);
        assert_non_null(rm->uv[1]);
        assert_string_equal(r->materials[rm->material].name, s->materials[m->material].name);
        vertices += rm->vertex_count;
        for (uint32_t c = 0; c < 3 * m->triangle_count; c++) {
            /* the same triangle; assimp may start a strip's triangle at
             * another corner (same winding): the corner read back */
            uint32_t t = c / 3, rot = 0, rc = c;
            for (; rot < 3; rot++) {
                bool all = true;
                for (uint32_t q = 0; q < 3; q++) {
                    lx_vec3 w = m->positions[m->indices[3 * t + q]];
                    lx_vec3 g = rm->positions[rm->indices[3 * t + (q + rot) % 3]];
                    all = all && w.x == g.x && w.y == g.y && w.z == g.z;
                }
                if (all)
                    break;
            }
            if (rot < 3)
                rc = 3 * t + (c % 3 + rot) % 3;
            lx_vec3 want = lx_mat4_point(&n->world, m->positions[m->indices[c]]);
            lx_vec3 got = lx_mat4_point(&rn->world, rm->positions[rm->indices[rc]]);
            assert_close3(got, want);
            /* assimp turns V over and back (1 - (1 - v)): two float roundings
             * of values in [0, 1], at most 2^-24 each */
            lx_vec2 uv = rm->uv[1][rm->indices[rc]], w = um->uv[um->indices[c]];
            if (!(fabsf(uv.x - w.x) <= 0x1p-23f && fabsf(uv.y - w.y) <= 0x1p-23f))
                fail_msg("mesh '%s' corner %u: TEXCOORD_1 (%.9g, %.9g), the unwrapper's (%.9g, "
                         "%.9g)",
                         m->name, c, uv.x, uv.y, w.x, w.y);
            if (m->uv[0]) {
                lx_vec2 a = rm->uv[0][rm->indices[rc]], b = m->uv[0][m->indices[c]];
                assert_true(a.x == b.x && a.y == b.y);
            }
        }
    }
    lx_scene_destroy(r);
    return vertices;
}

/* The JSON chunk of a .glb, parsed. */
static cJSON *glb_json(const char *path)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    unsigned char head[20];
    assert_int_equal(fread(head, 1, 20, fp), 20);
    assert_memory_equal(head, "glTF", 4);
    uint32_t len = (uint32_t)head[12] | (uint32_t)head[13] << 8 | (uint32_t)head[14] << 16 |
                   (uint32_t)head[15] << 24;
    char *text = malloc(len + 1);
    assert_non_null(text);
    assert_int_equal(fread(text, 1, len, fp), len);
    text[len] = '\0';
    fclose(fp);
    cJSON *j = cJSON_Parse(text);
    free(text);
    assert_non_null(j);
    return j;
}

static cJSON *text_json(const char *path)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    static char buf[1 << 20];
    size_t n = fread(buf, 1, sizeof buf - 1, fp);
    fclose(fp);
    buf[n] = '\0';
    cJSON *j = cJSON_Parse(buf);
    assert_non_null(j);
    return j;
}

/* Runs the glTF-Validator on path: true when it reports no error, skips
 * the test when it is not installed. */
static void validate(const char *path)
{
    const char *tmp = getenv("LX_TEST_TMP");
    char oracles[1024], script[1024], cmd[4096];
    snprintf(oracles, sizeof oracles, "%s/../oracles", tmp ? tmp : "build/test-tmp");
    /* the wrapper sits in tests/common beside this file's folder */
    snprintf(script, sizeof script, "%s", __FILE__);
    char *slash = strrchr(script, '/');
    assert_non_null(slash);
    *slash = '\0';
    slash = strrchr(script, '/');
    assert_non_null(slash);
    snprintf(slash, sizeof script - (size_t)(slash - script), "/common/gltf_validate.js");
    if (system("command -v node >/dev/null 2>&1") != 0) {
        print_message("node is not installed\n");
        skip();
    }
    snprintf(cmd, sizeof cmd, "node '%s' '%s' '%s'", script, oracles, path);
    int rc = system(cmd);
    int code = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
    if (code == 77) {
        print_message("gltf-validator is not installed (scripts/install-test-oracles.sh)\n");
        skip();
    }
    if (code != 0)
        fail_msg("glTF-Validator reports errors in %s", path);
}

/* ---- inputs --------------------------------------------------------------- */

/* Two primitives of one mesh (two materials), under a parent node with a
 * transform; extras on nodes, materials and the root; a light. */
static void write_multi(const char *path)
{
    prim_data a = box_data(lx_v3(0, 0, 0), lx_v3(1, 1, 1));
    prim_data b = box_data(lx_v3(2, 0, 0), lx_v3(3, 2, 1));
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_material(g, "{\"name\":\"red\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
                             "[0.8,0.1,0.1,1]},\"extras\":{\"tag\":\"r\",\"n\":[1,2.5]}}");
    lx_test_gltf_material(g, "{\"name\":\"blue\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
                             "[0.1,0.1,0.8,1]}}");
    lx_test_primitive prims[2] = {prim_of(&a, 0), prim_of(&b, 1)};
    lx_test_gltf_mesh(g, "parts", prims, 2);
    lx_test_gltf_node_ex(g, "parent", -1,
                         "\"children\":[1,2],\"translation\":[0,1,0],\"rotation\":[0,0.38268343,0,"
                         "0.92387953],\"extras\":{\"id\":7}",
                         true);
    lx_test_gltf_node_ex(g, "child", 0, "\"scale\":[2,2,2],\"extras\":{\"k\":{\"deep\":[true,null]}}",
                         false);
    lx_test_gltf_node_ex(g, "lamp", -1,
                         "\"translation\":[1,3,1],\"extensions\":{\"KHR_lights_punctual\":"
                         "{\"light\":0}}",
                         false);
    lx_test_gltf_use_extension(g, "KHR_lights_punctual");
    lx_test_gltf_top(g, "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[{\"name\":\"bulb\","
                        "\"type\":\"point\",\"intensity\":20,\"color\":[1,0.9,0.8],\"range\":9}]}},"
                        "\"extras\":{\"author\":\"test\",\"v\":1.25}");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    prim_free(&a);
    prim_free(&b);
}

/* One mesh placed by three nodes. */
static void write_instanced(const char *path)
{
    prim_data a = box_data(lx_v3(-0.5f, 0, -0.5f), lx_v3(0.5f, 1, 0.5f));
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_material(g, "{\"name\":\"grey\"}");
    lx_test_primitive p = prim_of(&a, 0);
    lx_test_gltf_mesh(g, "crate", &p, 1);
    lx_test_gltf_node(g, "crate1", 0, "\"translation\":[0,0,0]");
    lx_test_gltf_node(g, "crate2", 0, "\"translation\":[3,0,0]");
    lx_test_gltf_node(g, "crate3", 0, "\"translation\":[0,0,3],\"scale\":[2,1,1]");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    prim_free(&a);
}

/* ---- tests ---------------------------------------------------------------- */

static void test_multi_primitive_round_trip(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_multi");
    char in[512], out[512];
    snprintf(in, sizeof in, "%s/multi.gltf", dir);
    snprintf(out, sizeof out, "%s/multi_uv.glb", dir);
    write_multi(in);
    lx_scene *s;
    lx_unwrap *u;
    unwrap_and_write(in, out, &s, &u);
    assert_int_equal(u->mesh_count, 2);
    uint32_t vertices = check_round_trip(s, u, out);
    /* a box's six faces cannot lie in one chart: seams split vertices */
    assert_true(vertices > 0);
    /* the JSON the writer does not own is unchanged */
    cJSON *a = text_json(in), *b = glb_json(out);
    assert_true(cJSON_Compare(cJSON_GetObjectItem(a, "extras"), cJSON_GetObjectItem(b, "extras"),
                              true));
    assert_true(cJSON_Compare(cJSON_GetObjectItem(a, "extensions"),
                              cJSON_GetObjectItem(b, "extensions"), true));
    assert_true(cJSON_Compare(cJSON_GetObjectItem(a, "materials"),
                              cJSON_GetObjectItem(b, "materials"), true));
    cJSON *na = cJSON_GetObjectItem(a, "nodes"), *nb = cJSON_GetObjectItem(b, "nodes");
    assert_int_equal(cJSON_GetArraySize(na), cJSON_GetArraySize(nb));
    /* one node per mesh user: nodes are unchanged, mesh index included */
    assert_true(cJSON_Compare(na, nb, true));
    /* the primitives' TEXCOORD_1 is new, TEXCOORD_0 kept */
    cJSON *prim = cJSON_GetArrayItem(
        cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(b, "meshes"), 0), "primitives"),
        1);
    cJSON *attrs = cJSON_GetObjectItem(prim, "attributes");
    assert_non_null(cJSON_GetObjectItem(attrs, "TEXCOORD_0"));
    assert_non_null(cJSON_GetObjectItem(attrs, "TEXCOORD_1"));
    assert_int_equal(cJSON_GetObjectItem(prim, "material")->valueint, 1);
    cJSON_Delete(a);
    cJSON_Delete(b);
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
}

static void test_instances_get_meshes_of_their_own(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_inst");
    char in[512], out[512];
    snprintf(in, sizeof in, "%s/inst.gltf", dir);
    snprintf(out, sizeof out, "%s/inst_uv.glb", dir);
    write_instanced(in);
    lx_scene *s;
    lx_unwrap *u;
    unwrap_and_write(in, out, &s, &u);
    assert_int_equal(u->mesh_count, 3);
    check_round_trip(s, u, out);
    cJSON *b = glb_json(out);
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(b, "meshes")), 3);
    cJSON *nodes = cJSON_GetObjectItem(b, "nodes");
    bool seen[3] = {false, false, false};
    for (int i = 0; i < 3; i++) {
        int m = cJSON_GetObjectItem(cJSON_GetArrayItem(nodes, i), "mesh")->valueint;
        assert_true(m >= 0 && m < 3 && !seen[m]);
        seen[m] = true;
    }
    cJSON_Delete(b);
    /* each instance has a region of its own: no sample point of a fine
     * grid over the page lies inside triangles of two instances */
    enum { G = 512 };
    uint8_t *owner = calloc((size_t)G * G, 1);
    assert_non_null(owner);
    for (uint32_t k = 0; k < 3; k++) {
        const lx_unwrap_mesh *um = &u->meshes[k];
        assert_int_equal(u->nodes[um->node].page, u->nodes[u->meshes[0].node].page);
        for (uint32_t t = 0; t < s->meshes[um->mesh].triangle_count; t++) {
            lx_vec2 a = um->uv[um->indices[3 * t]], bb = um->uv[um->indices[3 * t + 1]],
                    c = um->uv[um->indices[3 * t + 2]];
            double area =
                (double)(bb.x - a.x) * (c.y - a.y) - (double)(bb.y - a.y) * (c.x - a.x);
            for (int y = 0; y < G; y++)
                for (int x = 0; x < G; x++) {
                    double px = (x + 0.5) / G, py = (y + 0.5) / G;
                    double w0 = (bb.x - px) * (c.y - py) - (bb.y - py) * (c.x - px);
                    double w1 = (c.x - px) * (a.y - py) - (c.y - py) * (a.x - px);
                    double w2 = (a.x - px) * (bb.y - py) - (a.y - py) * (bb.x - px);
                    bool inside = area > 0 ? (w0 > 0 && w1 > 0 && w2 > 0)
                                           : (w0 < 0 && w1 < 0 && w2 < 0);
                    if (!inside)
                        continue;
                    uint8_t *o = &owner[(size_t)y * G + (size_t)x];
                    assert_true(*o == 0 || *o == k + 1);
                    *o = (uint8_t)(k + 1);
                }
        }
    }
    free(owner);
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
}

static void test_obj_scene_round_trip(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_obj");
    char in[512], mtl[512], png[512], out[512];
    snprintf(in, sizeof in, "%s/two.obj", dir);
    snprintf(mtl, sizeof mtl, "%s/two.mtl", dir);
    snprintf(png, sizeof png, "%s/checker.png", dir);
    snprintf(out, sizeof out, "%s/two_uv.glb", dir);
    uint8_t px[4 * 4 * 3];
    for (int i = 0; i < 16; i++)
        px[3 * i] = px[3 * i + 1] = px[3 * i + 2] = (uint8_t)((i + i / 4) % 2 ? 255 : 30);
    lx_test_write_png(png, 4, 4, 3, px);
    FILE *fp = fopen(mtl, "w");
    assert_non_null(fp);
    fputs("newmtl paint\nKd 0.5 0.25 0.125\nmap_Kd checker.png\nnewmtl plain\nKd 0.2 0.7 0.2\n",
          fp);
    fclose(fp);
    fp = fopen(in, "w");
    assert_non_null(fp);
    /* a unit cube (object "cube") and a quad (object "floor") */
    fputs("mtllib two.mtl\no cube\nusemtl paint\n"
          "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
          "f 1/1 4/4 3/3 2/2\nf 5/1 6/2 7/3 8/4\nf 1/1 2/2 6/3 5/4\nf 4/1 8/4 7/3 3/2\n"
          "f 1/1 5/2 8/3 4/4\nf 2/1 3/2 7/3 6/4\n"
          "o floor\nusemtl plain\nv -2 -0.5 -2\nv 3 -0.5 -2\nv 3 -0.5 3\nv -2 -0.5 3\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 9/5 12/8 11/7 10/6\n",
          fp);
    fclose(fp);
    lx_scene *s;
    lx_unwrap *u;
    unwrap_and_write(in, out, &s, &u);
    check_round_trip(s, u, out);
    lx_scene *r;
    assert_int_equal(lx_scene_load(out, NULL, &r), LX_OK);
    /* materials by name, their base colour factor and texture kept */
    uint32_t found = 0;
    for (uint32_t i = 0; i < s->material_count; i++)
        for (uint32_t j = 0; j < r->material_count; j++)
            if (strcmp(s->materials[i].name, r->materials[j].name) == 0) {
                found++;
                lx_vec4 a = s->materials[i].base_color, b = r->materials[j].base_color;
                assert_true(fabsf(a.x - b.x) < 1e-6f && fabsf(a.y - b.y) < 1e-6f &&
                            fabsf(a.z - b.z) < 1e-6f && fabsf(a.w - b.w) < 1e-6f);
                assert_int_equal(r->materials[j].base_color_map.width,
                                 s->materials[i].base_color_map.width);
            }
    assert_true(found >= 2);
    lx_scene_destroy(r);
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
}

/* A node whose material reads TEXCOORD_1 (an occlusion map) keeps that
 * set: the node's lightmap goes to TEXCOORD_2, one set for all its
 * primitives (the manifest names one per node), and every primitive keeps
 * its own TEXCOORD_1. Read back, TEXCOORD_2 is where a later bake looks. */
static void test_material_uv1_kept(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_uv1");
    char in[512], out[512], png[512];
    snprintf(in, sizeof in, "%s/uv1.gltf", dir);
    snprintf(out, sizeof out, "%s/uv1_out.glb", dir);
    snprintf(png, sizeof png, "%s/t.png", dir);
    uint8_t px[12] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    lx_test_write_png(png, 2, 2, 3, px);
    prim_data a = box_data(lx_v3(0, 0, 0), lx_v3(1, 1, 1));
    prim_data b = box_data(lx_v3(2, 0, 0), lx_v3(3, 1, 1));
    lx_test_gltf *g = lx_test_gltf_new();
    int tex = lx_test_gltf_texture(g, "t.png");
    char json[256];
    snprintf(json, sizeof json,
             "{\"name\":\"ao\",\"occlusionTexture\":{\"index\":%d,\"texCoord\":1}}", tex);
    lx_test_gltf_material(g, json);
    lx_test_gltf_material(g, "{\"name\":\"plain\"}");
    lx_test_primitive p[2] = {prim_of(&a, 0), prim_of(&b, 1)};
    p[0].uv1 = a.uv0;
    p[1].uv1 = b.uv0;
    lx_test_gltf_mesh(g, "m", p, 2);
    lx_test_gltf_node(g, "n", 0, "");
    lx_test_gltf_write(g, in);
    lx_test_gltf_free(g);
    lx_scene *s;
    lx_unwrap *u;
    unwrap_and_write(in, out, &s, &u);
    cJSON *j = glb_json(out);
    cJSON *prims =
        cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(j, "meshes"), 0), "primitives");
    cJSON *a0 = cJSON_GetObjectItem(cJSON_GetArrayItem(prims, 0), "attributes");
    cJSON *a1 = cJSON_GetObjectItem(cJSON_GetArrayItem(prims, 1), "attributes");
    assert_non_null(cJSON_GetObjectItem(a0, "TEXCOORD_2"));
    assert_non_null(cJSON_GetObjectItem(a1, "TEXCOORD_2"));
    assert_int_equal(lx_scene_lightmap_set(s, 0), 2);
    /* the image is embedded: no uri left */
    cJSON *img = cJSON_GetArrayItem(cJSON_GetObjectItem(j, "images"), 0);
    assert_null(cJSON_GetObjectItem(img, "uri"));
    assert_string_equal(cJSON_GetObjectItem(img, "mimeType")->valuestring, "image/png");
    cJSON_Delete(j);
    /* read back: both primitives keep their TEXCOORD_1 (every value one
     * of the input's, not page UVs), the lightmap set is 2 and a bake
     * takes it */
    lx_scene *r;
    assert_int_equal(lx_scene_load(out, NULL, &r), LX_OK);
    assert_int_equal(r->node_count, 1);
    assert_int_equal(lx_scene_lightmap_set(r, 0), 2);
    assert_int_equal(lx_bake_uv_set(r, 0, LX_UV_SET_AUTO), 2);
    for (uint32_t k = 0; k < r->nodes[0].mesh_count; k++) {
        const lx_mesh *m = &r->meshes[r->nodes[0].meshes[k]];
        assert_non_null(m->uv[1]);
        assert_non_null(m->uv[2]);
        const lx_mesh *in_mesh = &s->meshes[k];
        bool page_uvs_differ = false;
        for (uint32_t v = 0; v < m->vertex_count; v++) {
            bool found = false;
            for (uint32_t w = 0; w < in_mesh->vertex_count && !found; w++)
                found = in_mesh->uv[1][w].x == m->uv[1][v].x &&
                        in_mesh->uv[1][w].y == m->uv[1][v].y;
            assert_true(found);
            page_uvs_differ |= m->uv[2][v].x != m->uv[1][v].x;
        }
        assert_true(page_uvs_differ);
    }
    lx_unwrap_destroy(u);
    lx_scene_destroy(r);
    lx_scene_destroy(s);
    prim_free(&a);
    prim_free(&b);
}

static int image_warnings;
static void count_image_warnings(void *user, lx_log_level level, const char *msg)
{
    (void)user;
    if (level == LX_LOG_WARN && strstr(msg, "image 0") && strstr(msg, "gone.png"))
        image_warnings++;
}

/* A texture file that is not there: the import goes without it and the
 * write does too (before, the write failed - after a whole bake), the
 * image keeping its uri, each with a warning naming it. */
static void test_missing_image(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_missing_image");
    char in[512], out[512];
    snprintf(in, sizeof in, "%s/in.gltf", dir);
    snprintf(out, sizeof out, "%s/out.glb", dir);
    prim_data a = box_data(lx_v3(0, 0, 0), lx_v3(1, 1, 1));
    lx_test_gltf *g = lx_test_gltf_new();
    int tex = lx_test_gltf_texture(g, "gone.png");
    char json[256];
    snprintf(json, sizeof json,
             "{\"name\":\"m\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":%d}}}",
             tex);
    lx_test_gltf_material(g, json);
    lx_test_primitive p = prim_of(&a, 0);
    lx_test_gltf_mesh(g, "m", &p, 1);
    lx_test_gltf_node(g, "n", 0, "");
    lx_test_gltf_write(g, in);
    lx_test_gltf_free(g);
    image_warnings = 0;
    lx_set_log_callback(count_image_warnings, NULL);
    lx_scene *s;
    lx_unwrap *u;
    unwrap_and_write(in, out, &s, &u);
    lx_set_log_callback(NULL, NULL);
    assert_int_equal(image_warnings, 1); /* the write's; the import names the material */
    cJSON *j = glb_json(out);
    cJSON *img = cJSON_GetArrayItem(cJSON_GetObjectItem(j, "images"), 0);
    assert_string_equal(cJSON_GetObjectItem(img, "uri")->valuestring, "gone.png");
    assert_null(cJSON_GetObjectItem(img, "bufferView"));
    cJSON_Delete(j);
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
    prim_free(&a);
}

static void test_validator_accepts_outputs(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_valid");
    char in[512], out[512];
    void (*writers[2])(const char *) = {write_multi, write_instanced};
    for (int i = 0; i < 2; i++) {
        snprintf(in, sizeof in, "%s/in%d.gltf", dir, i);
        snprintf(out, sizeof out, "%s/out%d.glb", dir, i);
        writers[i](in);
        lx_scene *s;
        lx_unwrap *u;
        unwrap_and_write(in, out, &s, &u);
        lx_unwrap_destroy(u);
        lx_scene_destroy(s);
        validate(out);
    }
    /* the outputs of the other tests */
    const char *others[] = {"gltfw_obj/two_uv.glb", "gltfw_uv1/uv1_out.glb"};
    const char *tmp = getenv("LX_TEST_TMP");
    for (int i = 0; i < 2; i++) {
        snprintf(out, sizeof out, "%s/%s", tmp ? tmp : "/tmp", others[i]);
        if (exists(out))
            validate(out);
    }
}

/* ---- EXT_meshopt_compression -------------------------------------------------- */

/* A compressed bufferView (EXT_meshopt_compression, Khronos extension
 * spec) of count elements of stride bytes: the encoded bytes in buffer 0,
 * the view itself in fallback buffer 1 at *fallback. */
static int meshopt_view(lx_test_gltf *g, const void *data, size_t count, size_t stride,
                        bool triangles, const char *filter, size_t *fallback)
{
    size_t cap = triangles ? meshopt_encodeIndexBufferBound(count, 1u << 16)
                           : meshopt_encodeVertexBufferBound(count, stride);
    unsigned char *enc = malloc(cap);
    assert_non_null(enc);
    size_t n;
    if (triangles) {
        unsigned int *idx = malloc(sizeof(unsigned int) * count);
        assert_non_null(idx);
        for (size_t i = 0; i < count; i++)
            idx[i] = ((const uint16_t *)data)[i];
        n = meshopt_encodeIndexBuffer(enc, cap, idx, count);
        free(idx);
    } else {
        n = meshopt_encodeVertexBuffer(enc, cap, data, count, stride);
    }
    assert_true(n > 0);
    size_t at = lx_test_gltf_bytes(g, enc, n);
    free(enc);
    char json[512], member[64] = "";
    if (!triangles)
        snprintf(member, sizeof member, ",\"byteStride\":%zu,\"target\":34962", stride);
    else
        snprintf(member, sizeof member, ",\"target\":34963");
    snprintf(json, sizeof json,
             "{\"buffer\":1,\"byteOffset\":%zu,\"byteLength\":%zu%s,\"extensions\":{"
             "\"EXT_meshopt_compression\":{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,"
             "\"byteStride\":%zu,\"count\":%zu,\"mode\":\"%s\",\"filter\":\"%s\"}}}",
             *fallback, count * stride, member, at, n, stride, count,
             triangles ? "TRIANGLES" : "ATTRIBUTES", filter);
    *fallback += (count * stride + 15) / 16 * 16;
    return lx_test_gltf_view_json(g, json);
}

/* Two boxes without UVs as a gltfpack -cc file would hold them: both
 * primitives' positions in one compressed view, their normals (int8,
 * octahedral filter, KHR_mesh_quantization) in another, their indices
 * (uint16) in one TRIANGLES view, the accessors at offsets into them;
 * nodes "a" (moved) and "b". */
static void write_meshopt(const char *path)
{
    prim_data p[2] = {box_data(lx_v3(0, 0, 0), lx_v3(1, 1, 1)),
                      box_data(lx_v3(2, 0, 0), lx_v3(3, 2, 1))};
    int nv = p[0].nv + p[1].nv, ni = p[0].ni + p[1].ni;
    float *pos = malloc(sizeof(float) * 3 * (size_t)nv),
          *nrm4 = malloc(sizeof(float) * 4 * (size_t)nv);
    int8_t *oct = malloc(4 * (size_t)nv);
    uint16_t *idx = malloc(sizeof(uint16_t) * (size_t)ni);
    assert_true(pos && nrm4 && oct && idx);
    for (int k = 0, v0 = 0, i0 = 0; k < 2; v0 += p[k].nv, i0 += p[k].ni, k++) {
        memcpy(pos + 3 * v0, p[k].pos, sizeof(float) * 3 * (size_t)p[k].nv);
        for (int v = 0; v < p[k].nv; v++) {
            memcpy(nrm4 + 4 * (v0 + v), p[k].nrm + 3 * v, sizeof(float) * 3);
            nrm4[4 * (v0 + v) + 3] = 0.0f;
        }
        for (int i = 0; i < p[k].ni; i++)
            idx[i0 + i] = (uint16_t)p[k].idx[i]; /* each primitive's own vertices */
    }
    meshopt_encodeFilterOct(oct, (size_t)nv, 4, 8, nrm4);
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_require_extension(g, "EXT_meshopt_compression");
    lx_test_gltf_require_extension(g, "KHR_mesh_quantization");
    size_t fb = 0;
    int vpos = meshopt_view(g, pos, (size_t)nv, 12, false, "NONE", &fb);
    int vnrm = meshopt_view(g, oct, (size_t)nv, 4, false, "OCTAHEDRAL", &fb);
    int vidx = meshopt_view(g, idx, (size_t)ni, 2, true, "NONE", &fb);
    char json[512];
    snprintf(
        json, sizeof json,
        "{\"byteLength\":%zu,\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}",
        fb);
    lx_test_gltf_buffer_json(g, json);
    for (int k = 0, v0 = 0, i0 = 0; k < 2; v0 += p[k].nv, i0 += p[k].ni, k++) {
        lx_vec3 lo = k ? lx_v3(2, 0, 0) : lx_v3(0, 0, 0), hi = k ? lx_v3(3, 2, 1) : lx_v3(1, 1, 1);
        snprintf(json, sizeof json,
                 "{\"bufferView\":%d,\"byteOffset\":%d,\"componentType\":5126,\"count\":%d,"
                 "\"type\":\"VEC3\",\"min\":[%g,%g,%g],\"max\":[%g,%g,%g]}",
                 vpos, 12 * v0, p[k].nv, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
        int apos = lx_test_gltf_accessor_json(g, json);
        snprintf(json, sizeof json,
                 "{\"bufferView\":%d,\"byteOffset\":%d,\"componentType\":5120,\"normalized\":"
                 "true,\"count\":%d,\"type\":\"VEC3\"}",
                 vnrm, 4 * v0, p[k].nv);
        int anrm = lx_test_gltf_accessor_json(g, json);
        snprintf(json, sizeof json,
                 "{\"bufferView\":%d,\"byteOffset\":%d,\"componentType\":5123,\"count\":%d,"
                 "\"type\":\"SCALAR\"}",
                 vidx, 2 * i0, p[k].ni);
        int aidx = lx_test_gltf_accessor_json(g, json);
        snprintf(json, sizeof json,
                 "{\"name\":\"box%d\",\"primitives\":[{\"attributes\":{\"POSITION\":%d,"
                 "\"NORMAL\":%d},\"indices\":%d}]}",
                 k, apos, anrm, aidx);
        lx_test_gltf_node(g, k ? "b" : "a", lx_test_gltf_mesh_json(g, json),
                          k ? "" : "\"translation\":[0,0.5,-2]");
    }
    lx_test_gltf_write_glb(g, path);
    lx_test_gltf_free(g);
    free(pos);
    free(nrm4);
    free(oct);
    free(idx);
    prim_free(&p[0]);
    prim_free(&p[1]);
}

/* True when the JSON array root[key] holds the string s. */
static bool lists(const cJSON *root, const char *key, const char *s)
{
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(root, key);
    for (const cJSON *e = cJSON_IsArray(list) ? list->child : NULL; e; e = e->next)
        if (cJSON_IsString(e) && strcmp(e->valuestring, s) == 0)
            return true;
    return false;
}

/* A meshopt-compressed file is written with its views decoded: the
 * unwrapper's UVs read back at every corner, the positions too, no view
 * left compressed (the extension gone from the lists; an empty
 * extensionsRequired would be invalid), the quantized normals kept as
 * they were, and the glTF-Validator finds no error. */
static void test_meshopt_round_trip(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_meshopt");
    char in[512], out[512];
    snprintf(in, sizeof in, "%s/packed.glb", dir);
    snprintf(out, sizeof out, "%s/out.glb", dir);
    write_meshopt(in);
    lx_scene *s;
    lx_unwrap *u;
    unwrap_and_write(in, out, &s, &u);
    assert_int_equal(u->mesh_count, 2);
    check_round_trip(s, u, out);
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
    cJSON *j = glb_json(out);
    assert_false(lists(j, "extensionsUsed", "EXT_meshopt_compression"));
    assert_false(lists(j, "extensionsRequired", "EXT_meshopt_compression"));
    assert_true(lists(j, "extensionsRequired", "KHR_mesh_quantization"));
    const cJSON *views = cJSON_GetObjectItemCaseSensitive(j, "bufferViews");
    for (const cJSON *v = views ? views->child : NULL; v; v = v->next)
        assert_null(cJSON_GetObjectItemCaseSensitive(v, "extensions"));
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(j, "buffers")), 1);
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(j, "meshes");
    const cJSON *accessors = cJSON_GetObjectItemCaseSensitive(j, "accessors");
    for (const cJSON *m = meshes ? meshes->child : NULL; m; m = m->next) {
        const cJSON *prim =
            cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(m, "primitives"), 0);
        const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
        const cJSON *a = cJSON_GetArrayItem(
            accessors, cJSON_GetObjectItemCaseSensitive(attrs, "NORMAL")->valueint);
        assert_int_equal(cJSON_GetObjectItemCaseSensitive(a, "componentType")->valueint, 5120);
        assert_true(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(a, "normalized")));
        assert_non_null(cJSON_GetObjectItemCaseSensitive(attrs, "TEXCOORD_1"));
    }
    cJSON_Delete(j);
    validate(out);
}

/* Triangle strips and fans (glTF 2.0 spec, 3.7.2.1) come out as lists of
 * the same triangles in the same order and winding. */
static void test_strips_and_fans(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_strip");
    char in[512], out[512];
    snprintf(in, sizeof in, "%s/strip.gltf", dir);
    snprintf(out, sizeof out, "%s/strip_uv.glb", dir);
    enum { NS = 12, NF = 10 };
    float sp[3 * NS], sn[3 * NS], fp[3 * NF], fn[3 * NF];
    for (int i = 0; i < NS; i++) { /* a zigzag along x on the floor */
        sp[3 * i] = 0.5f * (float)(i / 2), sp[3 * i + 1] = 0.0f, sp[3 * i + 2] = (float)(i % 2);
        sn[3 * i] = 0.0f, sn[3 * i + 1] = 1.0f, sn[3 * i + 2] = 0.0f;
    }
    fp[0] = 5.0f, fp[1] = 0.0f, fp[2] = 0.0f; /* a fan: centre, then the rim (+Y up) */
    for (int i = 1; i < NF; i++) {
        double a = -2.0 * 3.14159265358979 * (i - 1) / 12.0;
        fp[3 * i] = 5.0f + (float)cos(a), fp[3 * i + 1] = 0.0f, fp[3 * i + 2] = (float)sin(a);
    }
    for (int i = 0; i < NF; i++)
        fn[3 * i] = 0.0f, fn[3 * i + 1] = 1.0f, fn[3 * i + 2] = 0.0f;
    lx_test_primitive p[2] = {
        {.vertex_count = NS, .position = sp, .normal = sn, .material = -1},
        {.vertex_count = NF, .position = fp, .normal = fn, .material = -1}};
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_mesh(g, "sf", p, 2);
    lx_test_gltf_node(g, "sf", 0, "");
    lx_test_gltf_write(g, in);
    lx_test_gltf_free(g);
    /* the test writer writes lists: make the first a strip, the second a fan */
    FILE *f = fopen(in, "rb");
    assert_non_null(f);
    static char text[1 << 16];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    char *m1 = strstr(text, "\"mode\":4");
    assert_non_null(m1);
    m1[7] = '5';
    char *m2 = strstr(m1, "\"mode\":4");
    assert_non_null(m2);
    m2[7] = '6';
    f = fopen(in, "wb");
    assert_non_null(f);
    fwrite(text, 1, n, f);
    fclose(f);
    lx_scene *s;
    lx_unwrap *u;
    unwrap_and_write(in, out, &s, &u);
    assert_int_equal(u->mesh_count, 2);
    check_round_trip(s, u, out);
    /* the triangles by the spec's rule, against what was written */
    lx_scene *r;
    assert_int_equal(lx_scene_load(out, NULL, &r), LX_OK);
    const lx_node *rn = &r->nodes[0];
    const lx_mesh *rs = &r->meshes[rn->meshes[0]], *rf = &r->meshes[rn->meshes[1]];
    assert_int_equal(rs->triangle_count, NS - 2);
    assert_int_equal(rf->triangle_count, NF - 2);
    for (int t = 0; t < NS - 2; t++) {
        int k[3] = {t, t + 1 + t % 2, t + 2 - t % 2};
        for (int q = 0; q < 3; q++)
            lx_test_assert_vec3(rs->positions[rs->indices[3 * t + q]], sp[3 * k[q]],
                                sp[3 * k[q] + 1], sp[3 * k[q] + 2]);
    }
    for (int t = 0; t < NF - 2; t++) {
        int k[3] = {t + 1, t + 2, 0};
        for (int q = 0; q < 3; q++)
            lx_test_assert_vec3(rf->positions[rf->indices[3 * t + q]], fp[3 * k[q]],
                                fp[3 * k[q] + 1], fp[3 * k[q] + 2]);
    }
    lx_scene_destroy(r);
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
    validate(out);
}

static void test_bad_inputs(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltfw_bad");
    char in[512], out[512];
    snprintf(in, sizeof in, "%s/inst.gltf", dir);
    snprintf(out, sizeof out, "%s/out.glb", dir);
    write_instanced(in);
    lx_scene *s;
    assert_int_equal(lx_scene_load(in, NULL, &s), LX_OK);
    lx_unwrap *u;
    assert_int_equal(lx_unwrap_scene(s, NULL, &u), LX_OK);
    const lx_unwrap_mesh *m = &u->meshes[0];
    lx_scene_uvs e = {.node = m->node,
                      .mesh = m->mesh,
                      .vertex_count = m->vertex_count,
                      .vertex_source = m->vertex_source,
                      .uv = m->uv,
                      .indices = m->indices};
    lx_glb_write_desc d = {.uvs = &e, .uv_count = 1};
    /* a node the scene does not have */
    e.node = 99;
    assert_int_equal(lx_scene_write_glb(s, out, &d), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "node 99"));
    assert_false(exists(out));
    e.node = m->node;
    /* an index past the new vertices */
    uint32_t *bad = malloc(sizeof(uint32_t) * 3 * s->meshes[m->mesh].triangle_count);
    memcpy(bad, m->indices, sizeof(uint32_t) * 3 * s->meshes[m->mesh].triangle_count);
    bad[4] = m->vertex_count;
    e.indices = bad;
    assert_int_equal(lx_scene_write_glb(s, out, &d), LX_ERR_INVALID);
    assert_false(exists(out));
    e.indices = m->indices;
    free(bad);
    /* the file changed since it was loaded: its triangles no longer match */
    prim_data other = box_data(lx_v3(5, 5, 5), lx_v3(6, 7, 8));
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_primitive p = prim_of(&other, -1);
    lx_test_gltf_mesh(g, "crate", &p, 1);
    lx_test_gltf_node(g, "crate1", 0, "");
    lx_test_gltf_node(g, "crate2", 0, "");
    lx_test_gltf_node(g, "crate3", 0, "");
    lx_test_gltf_write(g, in);
    lx_test_gltf_free(g);
    prim_free(&other);
    assert_int_equal(lx_scene_write_glb(s, out, &d), LX_ERR_UNSUPPORTED);
    assert_non_null(strstr(lx_last_error(), "does not match"));
    assert_false(exists(out));
    /* the file is gone */
    assert_int_equal(unlink(in), 0);
    assert_int_equal(lx_scene_write_glb(s, out, &d), LX_ERR_IO);
    assert_false(exists(out));
    /* a folder that does not exist */
    write_instanced(in);
    snprintf(out, sizeof out, "%s/no/such/out.glb", dir);
    assert_int_equal(lx_scene_write_glb(s, out, &d), LX_ERR_IO);
    assert_non_null(strstr(lx_last_error(), out));
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_multi_primitive_round_trip),
        cmocka_unit_test(test_instances_get_meshes_of_their_own),
        cmocka_unit_test(test_obj_scene_round_trip),
        cmocka_unit_test(test_material_uv1_kept),
        cmocka_unit_test(test_missing_image),
        cmocka_unit_test(test_validator_accepts_outputs),
        cmocka_unit_test(test_strips_and_fans),
        cmocka_unit_test(test_meshopt_round_trip),
        cmocka_unit_test(test_bad_inputs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
