/* Real-world glTF and OBJ files (lx_scene_load): zero-area triangles
 * dropped and counted (refused in strict mode), KHR_mesh_quantization and
 * EXT_meshopt_compression files against the same mesh in plain floats
 * (the compressed files made here with meshoptimizer's encoders),
 * extensionsRequired, Git LFS pointers, OBJ paths with backslashes,
 * lx_mesh.source_mesh/source_primitive and lx_node.source_node on an
 * instanced multi-primitive file, KHR_materials_emissive_strength, and a
 * Collada file whose light is left out with a warning. Expected values
 * come from the inputs written here. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "luxel/scene.h"
#include "scene/gltf_json.h" /* lx_gltf_rewrite, to read what it decoded */

#include <math.h>
#include <meshoptimizer.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ---- warnings ------------------------------------------------------------- */

static void load_fails(const char *path, const lx_scene_load_desc *desc, lx_status want,
                       const char *needle1, const char *needle2)
{
    lx_scene *s = NULL;
    lx_status st = lx_scene_load(path, desc, &s);
    if (st == LX_OK)
        lx_scene_destroy(s);
    if (st != want)
        fail_msg("lx_scene_load(%s): status %d, want %d ('%s')", path, (int)st, (int)want,
                 st == LX_OK ? "" : lx_last_error());
    const char *msg = lx_last_error();
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    if (!strstr(msg, base))
        fail_msg("'%s' does not name '%s'", msg, base);
    if (needle1 && !strstr(msg, needle1))
        fail_msg("'%s' does not say '%s'", msg, needle1);
    if (needle2 && !strstr(msg, needle2))
        fail_msg("'%s' does not say '%s'", msg, needle2);
}

static void path_in(char *out, size_t size, const char *dir, const char *name)
{
    snprintf(out, size, "%s/%s", dir, name);
}

static void write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs(text, fp);
    assert_int_equal(fclose(fp), 0);
}

static const lx_node *node_named(const lx_scene *s, const char *name)
{
    return &s->nodes[lx_test_node_named(s, name)];
}

/* ---- zero-area triangles ----------------------------------------------------- */

static const float QUAD_POS[] = {0, 0, 0, 0, 0, 1, 1, 0, 1, 1, 0, 0, 2, 0, 2};
static const float QUAD_UV[] = {0, 0, 0, 1, 1, 1, 1, 0, 0.5f, 0.5f};

static void test_zero_area_counted(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_zero_area");
    /* vertex 4 at (2,0,2) lies on the diagonal x = z through 0 and 2, so
     * triangles (0,2,4) and (2,0,4) have zero area */
    static const uint32_t one[] = {0, 1, 2, 0, 2, 3, 0, 2, 4};
    static const uint32_t two[] = {0, 2, 4, 0, 1, 2, 2, 0, 4, 0, 2, 3};
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_primitive a = {.vertex_count = 5, .position = QUAD_POS, .uv0 = QUAD_UV,
                           .index_count = 9, .indices = one, .material = -1};
    lx_test_primitive b = a;
    b.index_count = 12;
    b.indices = two;
    lx_test_gltf_node(g, "first", lx_test_gltf_mesh(g, "sliver_a", &a, 1), "");
    lx_test_gltf_node(g, "second", lx_test_gltf_mesh(g, "sliver_b", &b, 1), "");
    char path[1024];
    path_in(path, sizeof path, dir, "slivers.gltf");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);

    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    assert_int_equal(book.warnings, 1);
    if (!strstr(book.text, "3 zero-area triangles left out (of 2 meshes)"))
        fail_msg("warning: %s", book.text);
    assert_int_equal(s->mesh_count, 2);
    uint32_t dropped = 0;
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        assert_int_equal(s->meshes[i].triangle_count, 2);
        dropped += s->meshes[i].dropped_triangles;
    }
    assert_int_equal(dropped, 3);
    lx_scene_destroy(s);
    lx_scene_load_desc strict = {.strict = true};
    load_fails(path, &strict, LX_ERR_FORMAT, "3 zero-area triangles", "sliver_a");
}

/* A triangle of zero area in UV space only is no load error. */
static void test_zero_uv_area_loads(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_zero_uv");
    static const float uv[] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 1, 0, 0, 0};
    static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_primitive p = {.vertex_count = 5, .position = QUAD_POS, .uv0 = uv, .index_count = 6,
                           .indices = idx, .material = -1};
    lx_test_gltf_node(g, "n", lx_test_gltf_mesh(g, "flat_uv", &p, 1), "");
    char path[1024];
    path_in(path, sizeof path, dir, "flat_uv.gltf");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene_load_desc strict = {.strict = true};
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, &strict, &book);
    assert_int_equal(s->meshes[0].triangle_count, 2);
    lx_scene_destroy(s);
}

/* ---- a mesh to quantize and compress ------------------------------------------ */

#define NV 6
#define NT 4
/* a folded strip in [-2.5, 2.5]^3 (for int16) and its copy in [0, 4]^3 (for
 * uint8), multiples of 1/8 so that the exponential filter keeps them */
static const float MESH_POS[NV * 3] = {-2.5f, 0, -2.5f,   -2.5f, 1.25f, 0.5f, 0,    0.5f,
                                       -2.5f, 0.125f, 2.5f, 0.75f, 2.5f, 0,   -2.5f, 2.5f,
                                       -1.5f, 2.375f};
static const uint32_t MESH_IDX[NT * 3] = {0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 3, 5};
static const float MESH_UV[NV * 2] = {0, 0, 0, 0.5f, 0.3f, 0.1f, 0.4f, 0.9f, 1, 0, 0.9f, 1};

static void mesh_normals(float *n)
{
    /* unit normals of some spread, not the faces' (a file may say anything) */
    for (int v = 0; v < NV; v++) {
        double x = sin(0.7 * v + 0.3), y = 0.8 + 0.1 * v, z = cos(1.3 * v);
        double len = sqrt(x * x + y * y + z * z);
        n[3 * v] = (float)(x / len);
        n[3 * v + 1] = (float)(y / len);
        n[3 * v + 2] = (float)(z / len);
    }
}

/* World position of corner k of triangle t of the first mesh of node. */
static lx_vec3 corner(const lx_scene *s, const lx_node *node, uint32_t t, int k)
{
    const lx_mesh *m = &s->meshes[node->meshes[0]];
    assert_true(t < m->triangle_count);
    return lx_mat4_point(&node->world, m->positions[m->indices[3 * t + (uint32_t)k]]);
}

static const lx_mesh *mesh_of(const lx_scene *s, const char *node)
{
    return &s->meshes[node_named(s, node)->meshes[0]];
}

static void write_float_file(const char *path)
{
    float nrm[NV * 3], pos8[NV * 3];
    mesh_normals(nrm);
    for (int i = 0; i < NV * 3; i++)
        pos8[i] = (MESH_POS[i] + 2.5f) * 0.75f; /* into [0, 3.75], multiples of 3/32 */
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_primitive p = {.vertex_count = NV, .position = MESH_POS, .normal = nrm,
                           .uv0 = MESH_UV, .index_count = NT * 3, .indices = MESH_IDX,
                           .material = -1};
    lx_test_gltf_node(g, "n16", lx_test_gltf_mesh(g, "m16", &p, 1), "");
    p.position = pos8;
    lx_test_gltf_node(g, "n8", lx_test_gltf_mesh(g, "m8", &p, 1), "");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

/* ---- KHR_mesh_quantization ------------------------------------------------------ */

static void test_quantized(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_quantized");
    char fpath[1024], qpath[1024];
    path_in(fpath, sizeof fpath, dir, "float.gltf");
    path_in(qpath, sizeof qpath, dir, "quantized.gltf");
    write_float_file(fpath);

    const float s16 = 2.5f, s8 = 4.0f;
    float nrm[NV * 3];
    mesh_normals(nrm);
    int16_t p16[NV * 4] = {0};
    uint8_t p8[NV * 4] = {0};
    int8_t n8[NV * 4] = {0};
    uint16_t uv16[NV * 2], idx16[NT * 3];
    for (int v = 0; v < NV; v++)
        for (int c = 0; c < 3; c++) {
            float p = MESH_POS[3 * v + c];
            p16[4 * v + c] = (int16_t)lrintf(p / s16 * 32767.0f);
            p8[4 * v + c] = (uint8_t)lrintf((p + 2.5f) * 0.75f / s8 * 255.0f);
            n8[4 * v + c] = (int8_t)lrintf(nrm[3 * v + c] * 127.0f);
        }
    for (int i = 0; i < NV * 2; i++)
        uv16[i] = (uint16_t)lrintf(MESH_UV[i] * 65535.0f);
    for (int i = 0; i < NT * 3; i++)
        idx16[i] = (uint16_t)MESH_IDX[i];
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_require_extension(g, "KHR_mesh_quantization");
    char json[512];
    int vp16 = lx_test_gltf_view(g, p16, sizeof p16, 8);
    int vp8 = lx_test_gltf_view(g, p8, sizeof p8, 4);
    int vn = lx_test_gltf_view(g, n8, sizeof n8, 4);
    int vuv = lx_test_gltf_view(g, uv16, sizeof uv16, 0);
    int vi = lx_test_gltf_view(g, idx16, sizeof idx16, 0);
    snprintf(json, sizeof json,
             "{\"bufferView\":%d,\"componentType\":5122,\"normalized\":true,\"count\":%d,"
             "\"type\":\"VEC3\",\"min\":[-32767,-32767,-32767],\"max\":[32767,32767,32767]}",
             vp16, NV);
    int ap16 = lx_test_gltf_accessor_json(g, json);
    snprintf(json, sizeof json,
             "{\"bufferView\":%d,\"componentType\":5121,\"normalized\":true,\"count\":%d,"
             "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[255,255,255]}",
             vp8, NV);
    int ap8 = lx_test_gltf_accessor_json(g, json);
    snprintf(json, sizeof json,
             "{\"bufferView\":%d,\"componentType\":5120,\"normalized\":true,\"count\":%d,"
             "\"type\":\"VEC3\"}",
             vn, NV);
    int an = lx_test_gltf_accessor_json(g, json);
    snprintf(json, sizeof json,
             "{\"bufferView\":%d,\"componentType\":5123,\"normalized\":true,\"count\":%d,"
             "\"type\":\"VEC2\"}",
             vuv, NV);
    int auv = lx_test_gltf_accessor_json(g, json);
    snprintf(json, sizeof json,
             "{\"bufferView\":%d,\"componentType\":5123,\"count\":%d,\"type\":\"SCALAR\"}", vi,
             NT * 3);
    int ai = lx_test_gltf_accessor_json(g, json);
    /* vertex colours as normalized bytes (core glTF): read, not used */
    uint8_t rgba[NV * 4];
    for (int i = 0; i < NV * 4; i++)
        rgba[i] = (uint8_t)(40 * i);
    snprintf(json, sizeof json,
             "{\"bufferView\":%d,\"componentType\":5121,\"normalized\":true,\"count\":%d,"
             "\"type\":\"VEC4\"}",
             lx_test_gltf_view(g, rgba, sizeof rgba, 4), NV);
    int acol = lx_test_gltf_accessor_json(g, json);
    for (int k = 0; k < 2; k++) {
        snprintf(json, sizeof json,
                 "{\"name\":\"%s\",\"primitives\":[{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,"
                 "\"TEXCOORD_0\":%d,\"COLOR_0\":%d},\"indices\":%d}]}",
                 k ? "m8" : "m16", k ? ap8 : ap16, an, auv, acol, ai);
        int mesh = lx_test_gltf_mesh_json(g, json);
        snprintf(json, sizeof json, "\"scale\":[%g,%g,%g]", k ? s8 : s16, k ? s8 : s16,
                 k ? s8 : s16);
        lx_test_gltf_node(g, k ? "n8" : "n16", mesh, json);
    }
    lx_test_gltf_write(g, qpath);
    lx_test_gltf_free(g);

    lx_scene *f = NULL, *q = NULL;
    assert_int_equal(lx_scene_load(fpath, NULL, &f), LX_OK);
    if (lx_scene_load(qpath, NULL, &q) != LX_OK)
        fail_msg("%s", lx_last_error());
    const char *names[] = {"n16", "n8"};
    const float step[] = {s16 / 32767.0f, s8 / 255.0f};
    for (int k = 0; k < 2; k++) {
        const lx_node *nf = node_named(f, names[k]), *nq = node_named(q, names[k]);
        const lx_mesh *mf = mesh_of(f, names[k]), *mq = mesh_of(q, names[k]);
        assert_int_equal(mq->triangle_count, NT);
        for (uint32_t t = 0; t < NT; t++)
            for (int c = 0; c < 3; c++) {
                lx_vec3 a = corner(f, nf, t, c), b = corner(q, nq, t, c);
                /* half a step of rounding, plus float error */
                assert_true(fabsf(a.x - b.x) <= 0.51f * step[k] + 1e-6f);
                assert_true(fabsf(a.y - b.y) <= 0.51f * step[k] + 1e-6f);
                assert_true(fabsf(a.z - b.z) <= 0.51f * step[k] + 1e-6f);
                uint32_t vf = mf->indices[3 * t + c], vq = mq->indices[3 * t + c];
                /* int8 normals: 1/254 per component before renormalizing */
                assert_true(lx_length(lx_sub(mf->normals[vf], mq->normals[vq])) < 0.02f);
                assert_true(fabsf(mf->uv[0][vf].x - mq->uv[0][vq].x) <= 0.51f / 65535.0f + 1e-7f);
                assert_true(fabsf(mf->uv[0][vf].y - mq->uv[0][vq].y) <= 0.51f / 65535.0f + 1e-7f);
            }
    }
    lx_scene_destroy(f);
    lx_scene_destroy(q);
}

/* Found by fuzz_scene: a quantized accessor with no bufferView (all
 * zeros) in a file whose "bufferViews" is not a list. The load ends with a
 * message or a scene, and leaks nothing (make check-asan). */
static void test_quantized_without_views(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_quantized_noviews");
    char path[1024];
    path_in(path, sizeof path, dir, "noviews.gltf");
    write_text(path, "{\"asset\":{\"version\":\"2.0\"},\"extensionsRequired\":["
                     "\"KHR_mesh_quantization\"],\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
                     "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{"
                     "\"POSITION\":0}}]}],\"accessors\":[{\"componentType\":5122,"
                     "\"normalized\":true,\"count\":3,\"type\":\"VEC3\"}],\"bufferViews\":7,"
                     "\"buffers\":[]}");
    lx_scene *s = NULL;
    if (lx_scene_load(path, NULL, &s) == LX_OK)
        lx_scene_destroy(s);
    else
        assert_non_null(strstr(lx_last_error(), "noviews.gltf"));
}

/* ---- EXT_meshopt_compression ------------------------------------------------------ */

/* A bufferView of count elements of stride bytes compressed into buffer 0,
 * its fallback (uncompressed) range in buffer 1 at *fallback. */
static int meshopt_view(lx_test_gltf *g, const void *data, size_t count, size_t stride,
                        const char *mode, const char *filter, bool parent_stride,
                        size_t *fallback)
{
    size_t cap = strcmp(mode, "ATTRIBUTES") == 0
                     ? meshopt_encodeVertexBufferBound(count, stride)
                     : strcmp(mode, "TRIANGLES") == 0 ? meshopt_encodeIndexBufferBound(count, 1u << 16)
                                                      : meshopt_encodeIndexSequenceBound(count, 1u << 16);
    unsigned char *enc = malloc(cap);
    assert_non_null(enc);
    unsigned int idx[64];
    if (strcmp(mode, "ATTRIBUTES") != 0) {
        assert_true(count <= 64);
        for (size_t i = 0; i < count; i++)
            idx[i] = stride == 2 ? ((const uint16_t *)data)[i] : ((const uint32_t *)data)[i];
    }
    size_t n = strcmp(mode, "ATTRIBUTES") == 0 ? meshopt_encodeVertexBuffer(enc, cap, data, count, stride)
               : strcmp(mode, "TRIANGLES") == 0 ? meshopt_encodeIndexBuffer(enc, cap, idx, count)
                                                : meshopt_encodeIndexSequence(enc, cap, idx, count);
    assert_true(n > 0);
    size_t at = lx_test_gltf_bytes(g, enc, n);
    free(enc);
    char json[512], stride_member[32] = "";
    if (parent_stride)
        snprintf(stride_member, sizeof stride_member, ",\"byteStride\":%zu", stride);
    snprintf(json, sizeof json,
             "{\"buffer\":1,\"byteOffset\":%zu,\"byteLength\":%zu%s,\"extensions\":{"
             "\"EXT_meshopt_compression\":{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,"
             "\"byteStride\":%zu,\"count\":%zu,\"mode\":\"%s\",\"filter\":\"%s\"}}}",
             *fallback, count * stride, stride_member, at, n, stride, count, mode, filter);
    *fallback += (count * stride + 15) / 16 * 16;
    return lx_test_gltf_view_json(g, json);
}

static void write_meshopt_file(const char *path, bool glb)
{
    float nrm[NV * 3], nrm4[NV * 4];
    mesh_normals(nrm);
    for (int v = 0; v < NV; v++) {
        memcpy(&nrm4[4 * v], &nrm[3 * v], 3 * sizeof(float));
        nrm4[4 * v + 3] = 1.0f;
    }
    float pos8[NV * 3];
    for (int i = 0; i < NV * 3; i++)
        pos8[i] = (MESH_POS[i] + 2.5f) * 0.75f;
    int16_t oct[NV * 4];
    meshopt_encodeFilterOct(oct, NV, 8, 16, nrm4);
    uint32_t exp_pos[NV * 3];
    meshopt_encodeFilterExp(exp_pos, NV, 12, 24, pos8);
    uint16_t idx16[NT * 3];
    for (int i = 0; i < NT * 3; i++)
        idx16[i] = (uint16_t)MESH_IDX[i];

    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_require_extension(g, "EXT_meshopt_compression");
    lx_test_gltf_require_extension(g, "KHR_mesh_quantization");
    size_t fb = 0;
    /* mesh m16: plain ATTRIBUTES, TRIANGLES indices (uint32) */
    int vpos = meshopt_view(g, MESH_POS, NV, 12, "ATTRIBUTES", "NONE", true, &fb);
    int vnrm = meshopt_view(g, nrm, NV, 12, "ATTRIBUTES", "NONE", true, &fb);
    int vuv = meshopt_view(g, MESH_UV, NV, 8, "ATTRIBUTES", "NONE", true, &fb);
    int vidx = meshopt_view(g, MESH_IDX, NT * 3, 4, "TRIANGLES", "NONE", false, &fb);
    /* mesh m8: EXPONENTIAL positions, OCTAHEDRAL int16 normals, INDICES (uint16) */
    int vpos8 = meshopt_view(g, exp_pos, NV, 12, "ATTRIBUTES", "EXPONENTIAL", true, &fb);
    int voct = meshopt_view(g, oct, NV, 8, "ATTRIBUTES", "OCTAHEDRAL", true, &fb);
    int vidx16 = meshopt_view(g, idx16, NT * 3, 2, "INDICES", "NONE", false, &fb);
    char json[512];
    snprintf(json, sizeof json,
             "{\"byteLength\":%zu,\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}",
             fb);
    lx_test_gltf_buffer_json(g, json);
    const struct {
        int view, type, count;
        const char *kind, *extra;
    } acc[] = {
        {vpos, 5126, NV, "VEC3", ",\"min\":[-2.5,0,-2.5],\"max\":[2.5,2.5,2.5]"},
        {vnrm, 5126, NV, "VEC3", ""},
        {vuv, 5126, NV, "VEC2", ""},
        {vidx, 5125, NT * 3, "SCALAR", ""},
        {vpos8, 5126, NV, "VEC3", ",\"min\":[0,0,0],\"max\":[3.75,3.75,3.75]"},
        {voct, 5122, NV, "VEC3", ",\"normalized\":true"},
        {vidx16, 5123, NT * 3, "SCALAR", ""},
    };
    int a[7];
    for (int i = 0; i < 7; i++) {
        snprintf(json, sizeof json,
                 "{\"bufferView\":%d,\"componentType\":%d,\"count\":%d,\"type\":\"%s\"%s}",
                 acc[i].view, acc[i].type, acc[i].count, acc[i].kind, acc[i].extra);
        a[i] = lx_test_gltf_accessor_json(g, json);
    }
    snprintf(json, sizeof json,
             "{\"name\":\"m16\",\"primitives\":[{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,"
             "\"TEXCOORD_0\":%d},\"indices\":%d}]}",
             a[0], a[1], a[2], a[3]);
    lx_test_gltf_node(g, "n16", lx_test_gltf_mesh_json(g, json), "");
    snprintf(json, sizeof json,
             "{\"name\":\"m8\",\"primitives\":[{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,"
             "\"TEXCOORD_0\":%d},\"indices\":%d}]}",
             a[4], a[5], a[2], a[6]);
    lx_test_gltf_node(g, "n8", lx_test_gltf_mesh_json(g, json), "");
    if (glb)
        lx_test_gltf_write_glb(g, path);
    else
        lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void test_meshopt(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_meshopt");
    char fpath[1024], paths[2][1024];
    path_in(fpath, sizeof fpath, dir, "float.gltf");
    path_in(paths[0], sizeof paths[0], dir, "meshopt.glb");
    path_in(paths[1], sizeof paths[1], dir, "meshopt.gltf");
    write_float_file(fpath);
    write_meshopt_file(paths[0], true);
    write_meshopt_file(paths[1], false);
    lx_scene *f = NULL;
    assert_int_equal(lx_scene_load(fpath, NULL, &f), LX_OK);
    for (int file = 0; file < 2; file++) {
        lx_scene *m = NULL;
        if (lx_scene_load(paths[file], NULL, &m) != LX_OK)
            fail_msg("%s", lx_last_error());
        const char *names[] = {"n16", "n8"};
        for (int k = 0; k < 2; k++) {
            const lx_mesh *mf = mesh_of(f, names[k]), *mm = mesh_of(m, names[k]);
            assert_int_equal(mm->triangle_count, mf->triangle_count);
            for (uint32_t i = 0; i < 3 * mf->triangle_count; i++) {
                uint32_t vf = mf->indices[i], vm = mm->indices[i];
                /* lossless codecs and the exponential filter on multiples
                 * of 1/8: the same bits */
                assert_memory_equal(&mf->positions[vf], &mm->positions[vm], sizeof(lx_vec3));
                assert_memory_equal(&mf->uv[0][vf], &mm->uv[0][vm], sizeof(lx_vec2));
                float tol = k == 0 ? 0.0f : 2e-4f; /* 16-bit octahedral */
                assert_true(lx_length(lx_sub(mf->normals[vf], mm->normals[vm])) <= tol);
            }
        }
        lx_scene_destroy(m);
    }
    lx_scene_destroy(f);
}

/* The QUATERNION filter (no mesh attribute uses it: animations and
 * instances do) and EXPONENTIAL on two components, read back from the
 * GLB lx_gltf_rewrite makes against the values encoded. */
static void test_meshopt_filters(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_meshopt_filters");
    enum { N = 16 };
    float quat[N * 4], vec2[N * 2];
    for (int i = 0; i < N; i++) {
        double a = 0.37 * i, len;
        double q[4] = {sin(a) * 0.6, cos(a * 1.3) * 0.5, 0.3 + 0.05 * i, cos(a)};
        len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        for (int k = 0; k < 4; k++)
            quat[4 * i + k] = (float)(q[k] / len);
        vec2[2 * i] = (float)(1000.0 * sin(a));
        vec2[2 * i + 1] = (float)(0.001 * cos(a));
    }
    int16_t qenc[N * 4];
    meshopt_encodeFilterQuat(qenc, N, 8, 16, quat);
    uint32_t eenc[N * 2];
    meshopt_encodeFilterExp(eenc, N, 8, 20, vec2);
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_require_extension(g, "EXT_meshopt_compression");
    size_t fb = 0;
    int vq = meshopt_view(g, qenc, N, 8, "ATTRIBUTES", "QUATERNION", true, &fb);
    int ve = meshopt_view(g, eenc, N, 8, "ATTRIBUTES", "EXPONENTIAL", true, &fb);
    char json[256];
    snprintf(json, sizeof json,
             "{\"byteLength\":%zu,\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}",
             fb);
    lx_test_gltf_buffer_json(g, json);
    char path[1024];
    path_in(path, sizeof path, dir, "filters.glb");
    lx_test_gltf_write_glb(g, path);
    lx_test_gltf_free(g);

    cJSON *root = NULL;
    assert_int_equal(lx_gltf_json_read(path, &root), LX_OK);
    uint8_t *glb = NULL;
    size_t size = 0;
    if (lx_gltf_rewrite(path, root, &glb, &size) != LX_OK)
        fail_msg("%s", lx_last_error());
    assert_non_null(glb);
    /* the GLB's binary chunk follows the JSON chunk */
    uint32_t jlen = (uint32_t)glb[12] | (uint32_t)glb[13] << 8 | (uint32_t)glb[14] << 16 |
                    (uint32_t)glb[15] << 24;
    const uint8_t *bin = glb + 20 + jlen + 8;
    const cJSON *views = cJSON_GetObjectItem(root, "bufferViews");
    const cJSON *v = cJSON_GetArrayItem(views, vq), *w = cJSON_GetArrayItem(views, ve);
    assert_int_equal((int)cJSON_GetNumberValue(cJSON_GetObjectItem(v, "buffer")), 0);
    assert_null(cJSON_GetObjectItem(v, "extensions"));
    const uint8_t *qd = bin + (size_t)cJSON_GetNumberValue(cJSON_GetObjectItem(v, "byteOffset"));
    const uint8_t *ed = bin + (size_t)cJSON_GetNumberValue(cJSON_GetObjectItem(w, "byteOffset"));
    for (int i = 0; i < N; i++) {
        int16_t c[4];
        memcpy(c, qd + 8 * i, 8);
        /* a quaternion and its negation are the same rotation */
        double dot = 0;
        for (int k = 0; k < 4; k++)
            dot += c[k] / 32767.0 * quat[4 * i + k];
        assert_true(fabs(fabs(dot) - 1.0) < 1e-4);
        float e[2];
        memcpy(e, ed + 8 * i, 8);
        for (int k = 0; k < 2; k++) {
            /* the spec's decoding: 2^E * M, E the top byte and M the
             * low 24 bits, both signed */
            uint32_t word = eenc[2 * i + k];
            int32_t m = (int32_t)(word << 8) >> 8;
            int exponent = (int8_t)(word >> 24);
            float want = (float)ldexp((double)m, exponent);
            if (e[k] != want)
                fail_msg("element %d.%d: %.9g, the word says %.9g", i, k, e[k], want);
        }
    }
    const cJSON *req = cJSON_GetObjectItem(root, "extensionsRequired");
    assert_int_equal(cJSON_GetArraySize(req), 0);
    free(glb);
    cJSON_Delete(root);
}

/* ---- extensionsRequired ------------------------------------------------------------ */

static void write_quad(const char *path, const char *required, const char *material)
{
    static const uint32_t idx[] = {0, 1, 2, 0, 2, 3};
    lx_test_gltf *g = lx_test_gltf_new();
    if (required)
        lx_test_gltf_require_extension(g, required);
    int mat = material ? lx_test_gltf_material(g, material) : -1;
    lx_test_primitive p = {.vertex_count = 4, .position = QUAD_POS, .uv0 = QUAD_UV,
                           .index_count = 6, .indices = idx, .material = mat};
    lx_test_gltf_node(g, "quad", lx_test_gltf_mesh(g, "quad", &p, 1), "");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

/* Warnings naming an extension, counted by count_warnings. */
static int warnings_naming;
static const char *warning_needle;
static void count_warnings(void *user, lx_log_level level, const char *msg)
{
    (void)user;
    if (level == LX_LOG_WARN && strstr(msg, warning_needle))
        warnings_naming++;
}

static void test_required_extensions(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_required");
    char path[1024];
    path_in(path, sizeof path, dir, "draco.gltf");
    write_quad(path, "KHR_draco_mesh_compression", NULL);
    load_fails(path, NULL, LX_ERR_UNSUPPORTED, "requires extension KHR_draco_mesh_compression",
               "does not read");
    const char *fine[] = {"KHR_texture_transform", "KHR_materials_emissive_strength",
                          "KHR_lights_punctual", "KHR_mesh_quantization"};
    for (int i = 0; i < 4; i++) {
        path_in(path, sizeof path, dir, "fine.gltf");
        write_quad(path, fine[i], NULL);
        lx_scene *s = NULL;
        if (lx_scene_load(path, NULL, &s) != LX_OK)
            fail_msg("%s: %s", fine[i], lx_last_error());
        lx_scene_destroy(s);
    }
    /* extensions that only add an image format: the file loads, one
     * warning names the extension, the material keeps its factor */
    const char *images[] = {"KHR_texture_basisu", "EXT_texture_webp", "EXT_texture_avif"};
    for (int i = 0; i < 3; i++) {
        path_in(path, sizeof path, dir, "image_format.gltf");
        write_quad(path, images[i],
                   "{\"name\":\"red\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,0,0,1]}}");
        warnings_naming = 0;
        warning_needle = images[i];
        lx_set_log_callback(count_warnings, NULL);
        lx_scene *s = NULL;
        lx_status st = lx_scene_load(path, NULL, &s);
        lx_set_log_callback(NULL, NULL);
        if (st != LX_OK)
            fail_msg("%s: %s", images[i], lx_last_error());
        assert_int_equal(warnings_naming, 1);
        const lx_material *red = &s->materials[s->meshes[0].material];
        assert_true(red->base_color.x == 1.0f && red->base_color.y == 0.0f);
        lx_scene_destroy(s);
    }
}

static void test_emissive_strength(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_emissive");
    char path[1024];
    path_in(path, sizeof path, dir, "glow.gltf");
    write_quad(path, "KHR_materials_emissive_strength",
               "{\"name\":\"glow\",\"emissiveFactor\":[1,0.5,0.25],\"extensions\":{"
               "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4}}}");
    lx_scene *s = NULL;
    assert_int_equal(lx_scene_load(path, NULL, &s), LX_OK);
    const lx_material *m = &s->materials[s->meshes[0].material];
    lx_test_assert_vec3(m->emissive, 4.0, 2.0, 1.0);
    lx_scene_destroy(s);
}

/* ---- Git LFS pointers ---------------------------------------------------------------- */

static const char *LFS = "version https://git-lfs.github.com/spec/v1\n"
                         "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\n"
                         "size 12345\n";

static void test_lfs_pointers(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_lfs");
    char path[1024];
    path_in(path, sizeof path, dir, "scene.glb");
    write_text(path, LFS);
    load_fails(path, NULL, LX_ERR_FORMAT, "is a Git LFS pointer, not the file", "git lfs pull");
    /* a web page saved under the model's name */
    path_in(path, sizeof path, dir, "page.glb");
    write_text(path, "\n\n<!DOCTYPE html>\n<html><body>Not found</body></html>\n");
    load_fails(path, NULL, LX_ERR_FORMAT, "not a GLB file", "web page");

    /* a .gltf whose buffer file is a pointer */
    char bin[1024];
    path_in(bin, sizeof bin, dir, "mesh.bin");
    write_text(bin, LFS);
    path_in(path, sizeof path, dir, "external.gltf");
    write_text(path, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
                     "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":{"
                     "\"POSITION\":0}}]}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,"
                     "\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}],"
                     "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
                     "\"buffers\":[{\"byteLength\":36,\"uri\":\"mesh.bin\"}]}");
    load_fails(path, NULL, LX_ERR_FORMAT, "buffer 0 ('mesh.bin') is a Git LFS pointer",
               "git lfs pull");

    /* an OBJ texture that is a pointer: the scene loads, the warning says so */
    char tex[1024];
    path_in(tex, sizeof tex, dir, "wood.png");
    write_text(tex, LFS);
    path_in(path, sizeof path, dir, "lfs.mtl");
    write_text(path, "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n");
    path_in(path, sizeof path, dir, "lfs.obj");
    write_text(path, "mtllib lfs.mtl\no tri\nv 0 0 0\nv 1 0 0\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 0 1\n"
                     "usemtl wood\nf 1/1 2/2 3/3\n");
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    if (!strstr(book.text, "wood.png is a Git LFS pointer, not the file: run git lfs pull"))
        fail_msg("warnings: %s", book.text);
    lx_scene_destroy(s);
}

/* ---- OBJ written on Windows ------------------------------------------------------------- */

static void test_backslash_obj(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_backslash");
    char sub[1024], path[1024];
    path_in(sub, sizeof sub, dir, "materials");
    mkdir(sub, 0755);
    path_in(sub, sizeof sub, dir, "textures");
    mkdir(sub, 0755);
    static const uint8_t pixels[2 * 2 * 3] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    path_in(path, sizeof path, dir, "textures/wood.png");
    lx_test_write_png(path, 2, 2, 3, pixels);
    path_in(path, sizeof path, dir, "materials/wood.mtl");
    write_text(path, "newmtl wood\r\nKd 0.5 0.25 0.125\r\nmap_Kd textures\\wood.png\r\n");
    path_in(path, sizeof path, dir, "windows.obj");
    write_text(path, "mtllib materials\\wood.mtl\r\no tri\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 0 -1\r\n"
                     "vt 0 0\r\nvt 1 0\r\nvt 0 1\r\nusemtl wood\r\nf 1/1 2/2 3/3\r\n");
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    assert_int_equal(book.warnings, 0);
    const lx_material *m = &s->materials[s->meshes[0].material];
    assert_string_equal(m->name, "wood");
    lx_test_assert_vec3(lx_v3(m->base_color.x, m->base_color.y, m->base_color.z), 0.5, 0.25,
                        0.125);
    assert_int_equal(m->base_color_map.width, 2);
    lx_scene_destroy(s);
}

/* ---- where meshes and nodes came from -------------------------------------------------- */

static void test_source_mapping(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_source");
    /* primitive p of glTF mesh m is a triangle at x = 10 m + p, so the
     * mapping can be read off the positions */
    static const uint32_t idx[] = {0, 1, 2};
    float pos[4][9];
    for (int k = 0; k < 4; k++) {
        int m = k < 2 ? 1 : k - 2 == 0 ? 0 : 2, p = k < 2 ? k : 0;
        /* mesh 0: one primitive (k 2), mesh 1: two (k 0, 1), mesh 2: one (k 3) */
        float x = 10.0f * (float)m + (float)p;
        float tri[9] = {x, 0, 0, x + 1, 0, 0, x, 0, -1};
        memcpy(pos[k], tri, sizeof tri);
    }
    lx_test_gltf *g = lx_test_gltf_new();
    int mat0 = lx_test_gltf_material(g, "{\"name\":\"red\"}");
    int mat1 = lx_test_gltf_material(g, "{\"name\":\"blue\"}");
    lx_test_primitive single = {.vertex_count = 3, .position = pos[2], .index_count = 3,
                                .indices = idx, .material = mat0};
    lx_test_primitive two[2] = {
        {.vertex_count = 3, .position = pos[0], .index_count = 3, .indices = idx, .material = mat0},
        {.vertex_count = 3, .position = pos[1], .index_count = 3, .indices = idx, .material = mat1}};
    lx_test_primitive last = single;
    last.position = pos[3];
    assert_int_equal(lx_test_gltf_mesh(g, "single", &single, 1), 0);
    assert_int_equal(lx_test_gltf_mesh(g, "pair", two, 2), 1);
    assert_int_equal(lx_test_gltf_mesh(g, "last", &last, 1), 2);
    /* nodes: 0 "holder" (no mesh, children 1 and 2), 1 "pair_a" (mesh 1),
     * 2 "single_a" (mesh 0), 3 "pair_b" (mesh 1 again), 4 unnamed (mesh 2),
     * 5 "single_b" (mesh 0 again, child of 4) */
    lx_test_gltf_node_ex(g, "holder", -1, "\"children\":[1,2]", true);
    lx_test_gltf_node_ex(g, "pair_a", 1, "\"translation\":[0,1,0]", false);
    lx_test_gltf_node_ex(g, "single_a", 0, "", false);
    lx_test_gltf_node_ex(g, "pair_b", 1, "\"translation\":[0,2,0]", true);
    lx_test_gltf_node_ex(g, NULL, 2, "\"children\":[5]", true);
    lx_test_gltf_node_ex(g, "single_b", 0, "\"translation\":[0,3,0]", false);
    char path[1024];
    path_in(path, sizeof path, dir, "instanced.gltf");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);

    lx_scene *s = NULL;
    if (lx_scene_load(path, NULL, &s) != LX_OK)
        fail_msg("%s", lx_last_error());
    assert_int_equal(s->node_count, 5);
    int seen = 0;
    for (uint32_t n = 0; n < s->node_count; n++) {
        const lx_node *node = &s->nodes[n];
        int want_node = strcmp(node->name, "pair_a") == 0     ? 1
                        : strcmp(node->name, "single_a") == 0 ? 2
                        : strcmp(node->name, "pair_b") == 0   ? 3
                        : strcmp(node->name, "single_b") == 0 ? 5
                                                              : 4;
        assert_int_equal(node->source_node, want_node);
        int want_mesh = want_node == 1 || want_node == 3 ? 1 : want_node == 4 ? 2 : 0;
        assert_int_equal(node->mesh_count, want_mesh == 1 ? 2 : 1);
        for (uint32_t k = 0; k < node->mesh_count; k++) {
            const lx_mesh *m = &s->meshes[node->meshes[k]];
            assert_int_equal(m->source_mesh, want_mesh);
            /* the position tells which primitive it really is */
            float x = m->positions[0].x;
            for (uint32_t v = 1; v < m->vertex_count; v++)
                x = fminf(x, m->positions[v].x);
            assert_float_equal(x, 10.0f * (float)m->source_mesh + (float)m->source_primitive, 0);
            assert_int_equal(m->dropped_triangles, 0);
            seen++;
        }
    }
    assert_int_equal(seen, 7);
    lx_scene_destroy(s);

    /* not glTF: -1 everywhere */
    path_in(path, sizeof path, dir, "tri.obj");
    write_text(path, "o tri\nv 0 0 0\nv 1 0 0\nv 0 0 -1\nf 1 2 3\n");
    assert_int_equal(lx_scene_load(path, NULL, &s), LX_OK);
    assert_int_equal(s->meshes[0].source_mesh, -1);
    assert_int_equal(s->meshes[0].source_primitive, -1);
    assert_int_equal(s->nodes[0].source_node, -1);
    lx_scene_destroy(s);
}

/* ---- other formats' lights --------------------------------------------------------------- */

static void test_collada_lights_warned(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_collada");
    char path[1024];
    path_in(path, sizeof path, dir, "lamp.dae");
    write_text(
        path,
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
        "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
        "<asset><unit name=\"meter\" meter=\"1\"/><up_axis>Y_UP</up_axis></asset>\n"
        "<library_lights><light id=\"lamp\" name=\"lamp\"><technique_common><point>"
        "<color>1 1 1</color></point></technique_common></light></library_lights>\n"
        "<library_geometries><geometry id=\"tri\" name=\"tri\"><mesh>\n"
        "<source id=\"tri-pos\"><float_array id=\"tri-pos-array\" count=\"9\">0 0 0 1 0 0 0 0 -1"
        "</float_array><technique_common><accessor source=\"#tri-pos-array\" count=\"3\" "
        "stride=\"3\"><param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
        "<param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
        "<vertices id=\"tri-vtx\"><input semantic=\"POSITION\" source=\"#tri-pos\"/></vertices>\n"
        "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#tri-vtx\" offset=\"0\"/>"
        "<p>0 1 2</p></triangles>\n"
        "</mesh></geometry></library_geometries>\n"
        "<library_visual_scenes><visual_scene id=\"scene\">"
        "<node id=\"tri_node\" name=\"tri_node\"><instance_geometry url=\"#tri\"/></node>"
        "<node id=\"lamp_node\" name=\"lamp_node\"><translate>0 2 0</translate>"
        "<instance_light url=\"#lamp\"/></node></visual_scene></library_visual_scenes>\n"
        "<scene><instance_visual_scene url=\"#scene\"/></scene>\n</COLLADA>\n");
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    assert_int_equal(s->light_count, 0);
    assert_true(s->node_count >= 1);
    assert_int_equal(book.warnings, 1);
    if (!strstr(book.text, "lights left out") || !strstr(book.text, "--lights"))
        fail_msg("warnings: %s", book.text);
    lx_scene_destroy(s);
}

/* Two triangles with the same positions, normals and TEXCOORD_0 along
 * their shared edge but their own TEXCOORD_1 (two lightmap charts, as
 * luxel unwrap writes them): the load keeps every corner's TEXCOORD_1. */
static void test_lightmap_set_not_joined(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_ext_charts");
    static const float pos[] = {0, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 1};
    static const float nrm[] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    static const float uv0[] = {0, 0, 0, 1, 1, 0, 1, 0, 0, 1, 1, 1};
    static const float uv1[] = {0.125f, 0.125f, 0.125f, 0.375f, 0.375f, 0.125f,
                                0.625f, 0.625f, 0.625f, 0.875f, 0.875f, 0.875f};
    static const uint32_t idx[] = {0, 1, 2, 3, 4, 5};
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_primitive p = {.vertex_count = 6, .position = pos, .normal = nrm, .uv0 = uv0,
                           .uv1 = uv1, .index_count = 6, .indices = idx, .material = -1};
    lx_test_gltf_node(g, "n", lx_test_gltf_mesh(g, "charts", &p, 1), "");
    char path[1024];
    path_in(path, sizeof path, dir, "two_charts.gltf");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    const lx_mesh *m = &s->meshes[0];
    assert_int_equal(m->triangle_count, 2);
    assert_non_null(m->uv[1]);
    for (uint32_t c = 0; c < 6; c++) {
        lx_vec2 got = m->uv[1][m->indices[c]];
        assert_true(fabsf(got.x - uv1[2 * c]) < 1e-6f && fabsf(got.y - uv1[2 * c + 1]) < 1e-6f);
    }
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_zero_area_counted),    cmocka_unit_test(test_zero_uv_area_loads),
        cmocka_unit_test(test_quantized),            cmocka_unit_test(test_meshopt),
        cmocka_unit_test(test_meshopt_filters),   cmocka_unit_test(test_quantized_without_views),
        cmocka_unit_test(test_required_extensions),  cmocka_unit_test(test_emissive_strength),
        cmocka_unit_test(test_lfs_pointers),         cmocka_unit_test(test_backslash_obj),
        cmocka_unit_test(test_source_mapping),       cmocka_unit_test(test_collada_lights_warned),
        cmocka_unit_test(test_lightmap_set_not_joined),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
