/* A small glTF 2.0 writer for tests (see gltf_writer.h): the layout follows
 * the glTF 2.0 specification (accessors over bufferViews of one buffer,
 * POSITION with min/max, componentType 5126 float and 5125 uint32). */
#include "gltf_writer.h"
#include "texture_oracle.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image_write.h>

typedef struct text {
    char *s;
    size_t len, cap;
} text;

struct lx_test_gltf {
    unsigned char *bin;
    size_t bin_size, bin_cap;
    text accessors, views, meshes, nodes, roots, materials, textures, images, used, scenes, top,
        required, buffers;
    int accessor_count, view_count, mesh_count, node_count, material_count, texture_count,
        used_count, root_count, required_count, buffer_count;
};

static void add(text *t, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    va_list ap2;
    va_copy(ap2, ap);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    assert_true(n >= 0);
    if (t->len + (size_t)n + 1 > t->cap) {
        size_t cap = (t->cap ? t->cap * 2 : 256) + (size_t)n;
        char *s = realloc(t->s, cap);
        assert_non_null(s);
        t->s = s;
        t->cap = cap;
    }
    vsnprintf(t->s + t->len, t->cap - t->len, fmt, ap2);
    va_end(ap2);
    t->len += (size_t)n;
}

static const char *str(const text *t)
{
    return t->s ? t->s : "";
}

lx_test_gltf *lx_test_gltf_new(void)
{
    lx_test_gltf *g = calloc(1, sizeof *g);
    assert_non_null(g);
    return g;
}

void lx_test_gltf_free(lx_test_gltf *g)
{
    if (!g)
        return;
    text *all[] = {&g->accessors, &g->views,  &g->meshes, &g->nodes,  &g->roots, &g->materials,
                   &g->textures,  &g->images, &g->used,   &g->scenes, &g->top, &g->required,
                   &g->buffers};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        free(all[i]->s);
    free(g->bin);
    free(g);
}

size_t lx_test_gltf_bytes(lx_test_gltf *g, const void *bytes, size_t size)
{
    size_t start = (g->bin_size + 3) / 4 * 4;
    if (start + size > g->bin_cap) {
        size_t cap = (start + size) * 2;
        unsigned char *b = realloc(g->bin, cap);
        assert_non_null(b);
        g->bin = b;
        g->bin_cap = cap;
    }
    memset(g->bin + g->bin_size, 0, start - g->bin_size);
    memcpy(g->bin + start, bytes, size);
    g->bin_size = start + size;
    return start;
}

int lx_test_gltf_view(lx_test_gltf *g, const void *bytes, size_t size, int stride)
{
    size_t start = lx_test_gltf_bytes(g, bytes, size);
    add(&g->views, "%s{\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu", g->view_count ? "," : "",
        start, size);
    if (stride > 0)
        add(&g->views, ",\"byteStride\":%d", stride);
    add(&g->views, "}");
    return g->view_count++;
}

int lx_test_gltf_view_json(lx_test_gltf *g, const char *json)
{
    add(&g->views, "%s%s", g->view_count ? "," : "", json);
    return g->view_count++;
}

int lx_test_gltf_accessor_json(lx_test_gltf *g, const char *json)
{
    add(&g->accessors, "%s%s", g->accessor_count ? "," : "", json);
    return g->accessor_count++;
}

int lx_test_gltf_mesh_json(lx_test_gltf *g, const char *json)
{
    add(&g->meshes, "%s%s", g->mesh_count ? "," : "", json);
    return g->mesh_count++;
}

int lx_test_gltf_buffer_json(lx_test_gltf *g, const char *json)
{
    add(&g->buffers, ",%s", json);
    return ++g->buffer_count;
}

void lx_test_gltf_require_extension(lx_test_gltf *g, const char *name)
{
    lx_test_gltf_use_extension(g, name);
    add(&g->required, "%s\"%s\"", g->required_count++ ? "," : "", name);
}

/* Appends bytes as a bufferView (4-byte aligned); returns its index. */
static int view(lx_test_gltf *g, const void *bytes, size_t size)
{
    return lx_test_gltf_view(g, bytes, size, 0);
}

static int float_accessor(lx_test_gltf *g, const float *data, int count, int comps, bool minmax)
{
    static const char *types[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    int v = view(g, data, sizeof(float) * (size_t)count * (size_t)comps);
    add(&g->accessors, "%s{\"bufferView\":%d,\"componentType\":5126,\"count\":%d,\"type\":\"%s\"",
        g->accessor_count ? "," : "", v, count, types[comps]);
    if (minmax) {
        add(&g->accessors, ",\"min\":[");
        for (int c = 0; c < comps; c++) {
            float lo = INFINITY;
            for (int i = 0; i < count; i++)
                lo = fminf(lo, data[i * comps + c]);
            add(&g->accessors, "%s%.9g", c ? "," : "", lo);
        }
        add(&g->accessors, "],\"max\":[");
        for (int c = 0; c < comps; c++) {
            float hi = -INFINITY;
            for (int i = 0; i < count; i++)
                hi = fmaxf(hi, data[i * comps + c]);
            add(&g->accessors, "%s%.9g", c ? "," : "", hi);
        }
        add(&g->accessors, "]");
    }
    add(&g->accessors, "}");
    return g->accessor_count++;
}

int lx_test_gltf_mesh(lx_test_gltf *g, const char *name, const lx_test_primitive *prims, int count)
{
    add(&g->meshes, "%s{\"name\":\"%s\",\"primitives\":[", g->mesh_count ? "," : "", name);
    for (int p = 0; p < count; p++) {
        const lx_test_primitive *pr = &prims[p];
        int nv = pr->vertex_count;
        add(&g->meshes, "%s{\"attributes\":{\"POSITION\":%d", p ? "," : "",
            float_accessor(g, pr->position, nv, 3, true));
        if (pr->normal)
            add(&g->meshes, ",\"NORMAL\":%d", float_accessor(g, pr->normal, nv, 3, false));
        if (pr->tangent)
            add(&g->meshes, ",\"TANGENT\":%d", float_accessor(g, pr->tangent, nv, 4, false));
        if (pr->uv0)
            add(&g->meshes, ",\"TEXCOORD_0\":%d", float_accessor(g, pr->uv0, nv, 2, false));
        if (pr->uv1)
            add(&g->meshes, ",\"TEXCOORD_1\":%d", float_accessor(g, pr->uv1, nv, 2, false));
        add(&g->meshes, "}");
        if (pr->index_count > 0) {
            int v = view(g, pr->indices, sizeof(uint32_t) * (size_t)pr->index_count);
            add(&g->accessors,
                "%s{\"bufferView\":%d,\"componentType\":5125,\"count\":%d,\"type\":\"SCALAR\"}",
                g->accessor_count ? "," : "", v, pr->index_count);
            add(&g->meshes, ",\"indices\":%d", g->accessor_count++);
        }
        if (pr->material >= 0)
            add(&g->meshes, ",\"material\":%d", pr->material);
        add(&g->meshes, ",\"mode\":%d}", pr->points ? 0 : 4);
    }
    add(&g->meshes, "]}");
    return g->mesh_count++;
}

int lx_test_gltf_node_ex(lx_test_gltf *g, const char *name, int mesh, const char *members,
                         bool root)
{
    const char *sep = "";
    add(&g->nodes, "%s{", g->node_count ? "," : "");
    if (name) {
        add(&g->nodes, "\"name\":\"%s\"", name);
        sep = ",";
    }
    if (mesh >= 0) {
        add(&g->nodes, "%s\"mesh\":%d", sep, mesh);
        sep = ",";
    }
    if (members && members[0])
        add(&g->nodes, "%s%s", sep, members);
    add(&g->nodes, "}");
    if (root)
        add(&g->roots, "%s%d", g->root_count++ ? "," : "", g->node_count);
    return g->node_count++;
}

int lx_test_gltf_node(lx_test_gltf *g, const char *name, int mesh, const char *members)
{
    return lx_test_gltf_node_ex(g, name, mesh, members, true);
}

void lx_test_gltf_scenes(lx_test_gltf *g, const char *members)
{
    g->scenes.len = 0;
    add(&g->scenes, "%s", members);
}

void lx_test_gltf_top(lx_test_gltf *g, const char *members)
{
    add(&g->top, ",%s", members);
}

int lx_test_gltf_material(lx_test_gltf *g, const char *json)
{
    add(&g->materials, "%s%s", g->material_count ? "," : "", json);
    return g->material_count++;
}

int lx_test_gltf_texture(lx_test_gltf *g, const char *uri)
{
    add(&g->images, "%s{\"uri\":\"%s\"}", g->texture_count ? "," : "", uri);
    add(&g->textures, "%s{\"source\":%d}", g->texture_count ? "," : "", g->texture_count);
    return g->texture_count++;
}

void lx_test_gltf_use_extension(lx_test_gltf *g, const char *name)
{
    add(&g->used, "%s\"%s\"", g->used_count++ ? "," : "", name);
}

static void base64(text *out, const unsigned char *in, size_t n)
{
    static const char tab[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16;
        if (i + 1 < n)
            v |= (uint32_t)in[i + 1] << 8;
        if (i + 2 < n)
            v |= in[i + 2];
        char q[5] = {tab[(v >> 18) & 63], tab[(v >> 12) & 63], i + 1 < n ? tab[(v >> 6) & 63] : '=',
                     i + 2 < n ? tab[v & 63] : '=', 0};
        add(out, "%s", q);
    }
}

/* The JSON of the file; buffer 0 as a data: URI unless glb. */
static void json_text(const lx_test_gltf *g, text *j, bool glb)
{
    add(j, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"luxel tests\"}");
    if (g->used_count)
        add(j, ",\"extensionsUsed\":[%s]", str(&g->used));
    if (g->required_count)
        add(j, ",\"extensionsRequired\":[%s]", str(&g->required));
    if (g->scenes.len)
        add(j, ",%s", str(&g->scenes));
    else
        add(j, ",\"scene\":0,\"scenes\":[{\"nodes\":[%s]}]", str(&g->roots));
    add(j, ",\"nodes\":[%s]%s", str(&g->nodes), str(&g->top));
    add(j, ",\"meshes\":[%s],\"accessors\":[%s],\"bufferViews\":[%s]", str(&g->meshes),
        str(&g->accessors), str(&g->views));
    if (g->material_count)
        add(j, ",\"materials\":[%s]", str(&g->materials));
    if (g->texture_count)
        add(j, ",\"textures\":[%s],\"images\":[%s]", str(&g->textures), str(&g->images));
    add(j, ",\"buffers\":[{\"byteLength\":%zu", g->bin_size);
    if (!glb) {
        add(j, ",\"uri\":\"data:application/octet-stream;base64,");
        base64(j, g->bin, g->bin_size);
        add(j, "\"");
    }
    add(j, "}%s]}", str(&g->buffers));
}

static void write_bytes(const char *path, const void *bytes, size_t size)
{
    FILE *fp = fopen(path, "wb");
    if (!fp)
        fail_msg("cannot write %s", path);
    assert_int_equal(fwrite(bytes, 1, size, fp), size);
    assert_int_equal(fclose(fp), 0);
}

void lx_test_gltf_write(const lx_test_gltf *g, const char *path)
{
    text j = {0};
    json_text(g, &j, false);
    write_bytes(path, j.s, j.len);
    free(j.s);
}

static void le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (unsigned char)(v >> (8 * i));
}

void lx_test_gltf_write_glb(const lx_test_gltf *g, const char *path)
{
    text j = {0};
    json_text(g, &j, true);
    size_t jpad = (j.len + 3) / 4 * 4, bpad = (g->bin_size + 3) / 4 * 4;
    size_t total = 12 + 8 + jpad + 8 + bpad;
    unsigned char *out = calloc(1, total);
    assert_non_null(out);
    memcpy(out, "glTF", 4);
    le32(out + 4, 2);
    le32(out + 8, (uint32_t)total);
    le32(out + 12, (uint32_t)jpad);
    memcpy(out + 16, "JSON", 4);
    memcpy(out + 20, j.s, j.len);
    memset(out + 20 + j.len, ' ', jpad - j.len);
    le32(out + 20 + jpad, (uint32_t)bpad);
    memcpy(out + 24 + jpad, "BIN\0", 4);
    if (g->bin_size)
        memcpy(out + 28 + jpad, g->bin, g->bin_size);
    write_bytes(path, out, total);
    free(out);
    free(j.s);
}

void lx_test_write_png(const char *path, int w, int h, int channels, const uint8_t *pixels)
{
    if (!stbi_write_png(path, w, h, channels, pixels, w * channels))
        fail_msg("cannot write %s", path);
}

int lx_test_gltf_quad_mesh(lx_test_gltf *g, const char *name, const lx_test_quad *q, int mat,
                           const float *tangent)
{
    float pos[12], nrm[12], uv0[8], uv1[8];
    uint32_t idx[6];
    lx_test_quad_arrays(q, pos, nrm, uv0, uv1, idx);
    lx_test_primitive p = {.vertex_count = 4,
                           .position = pos,
                           .normal = nrm,
                           .tangent = tangent,
                           .uv0 = uv0,
                           .uv1 = uv1,
                           .index_count = 6,
                           .indices = idx,
                           .material = mat};
    return lx_test_gltf_mesh(g, name, &p, 1);
}

void lx_test_write_quad_gltf(const char *path, const lx_test_quad *q, const char *material,
                             const char *const *uris, int texture_count, const float *tangent)
{
    lx_test_gltf *g = lx_test_gltf_new();
    for (int i = 0; i < texture_count; i++)
        lx_test_gltf_texture(g, uris[i]);
    lx_test_gltf_use_extension(g, "KHR_texture_transform");
    int mat = lx_test_gltf_material(g, material);
    lx_test_gltf_node(g, "quad", lx_test_gltf_quad_mesh(g, "quad", q, mat, tangent), "");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}
