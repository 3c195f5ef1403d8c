/* A glTF file written again with lightmap UVs: the file's JSON and buffers
 * are read back, the primitives luxel unwrapped get vertices split where
 * the new UVs have seams (every attribute and morph target copied per new
 * vertex, triangles in the order the glTF 2.0 spec, 3.7.2.1, defines for
 * lists, strips and fans), and everything is written as one GLB (glTF 2.0
 * spec, 4.4) with every buffer and image in its binary chunk.
 * luxel's meshes come from assimp, whose vertices are joined and whose
 * triangles may start at another corner: each file triangle is matched to
 * luxel's triangle of the same rank by corner positions. */
#include "core/internal.h"
#include "gltf_data.h"
#include "gltf_json.h"
#include "gltf_write_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct job {
    size_t node, mesh, prim; /* glTF indices */
    const lx_scene_uvs *uvs;
} job;

#define EVERY_NODE SIZE_MAX /* a job for a mesh wherever it is placed */

static int job_cmp(const void *a, const void *b)
{
    const job *x = a, *y = b;
    if (x->node != y->node)
        return x->node < y->node ? -1 : 1;
    if (x->mesh != y->mesh)
        return x->mesh < y->mesh ? -1 : 1;
    return x->prim < y->prim ? -1 : x->prim > y->prim;
}

typedef struct wctx {
    const lx_scene *scene;
    lx_gltf_file *f;
    lx_glb_bin bin;
    const char *out;
} wctx;

static bool close_to(lx_vec3 a, lx_vec3 b)
{
    float s = 1.0f + fmaxf(fabsf(a.x), fmaxf(fabsf(a.y), fabsf(a.z)));
    float t = 1e-5f * s;
    return fabsf(a.x - b.x) <= t && fabsf(a.y - b.y) <= t && fabsf(a.z - b.z) <= t;
}

/* The accessor index at obj[key] (malformed: SIZE_MAX). */
static size_t accessor_at(const lx_gltf_file *f, const cJSON *obj, const char *key)
{
    size_t n = (size_t)cJSON_GetArraySize(lx_gltf_get(f->root, "accessors")), i;
    return lx_gltf_index(lx_gltf_get(obj, key), n, &i) ? i : SIZE_MAX;
}

/* A new accessor holding the elements src_of[0..count) of accessor ai. */
static lx_status remap_accessor(wctx *c, size_t ai, const uint32_t *src_of, size_t count,
                                bool want_bounds, int *out)
{
    lx_gltf_array a;
    lx_status st = lx_gltf_accessor_read(c->f, ai, &a);
    if (st != LX_OK)
        return st;
    for (size_t v = 0; v < count; v++)
        if (src_of[v] >= a.count) {
            lx_gltf_array_free(&a);
            return lx_fail(LX_ERR_FORMAT, "%s: accessor %zu has %zu elements, vertex %u needs more",
                           c->f->path, ai, a.count, src_of[v]);
        }
    /* vertex attributes start on 4-byte boundaries (glTF 2.0, 3.6.2.4) */
    size_t stride = (a.elem + 3) & ~(size_t)3;
    uint8_t *d = calloc(count ? count : 1, stride);
    if (!d) {
        lx_gltf_array_free(&a);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
    }
    for (size_t v = 0; v < count; v++)
        memcpy(d + v * stride, a.data + (size_t)src_of[v] * a.elem, a.elem);
    const cJSON *orig = cJSON_GetArrayItem(lx_gltf_get(c->f->root, "accessors"), (int)ai);
    bool bounds = want_bounds || (lx_gltf_get(orig, "min") && lx_gltf_get(orig, "max"));
    double lo[16], hi[16];
    for (int k = 0; k < a.components; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
    for (size_t v = 0; bounds && v < count; v++)
        for (int k = 0; k < a.components; k++) {
            double x = lx_gltf_array_get(&a, src_of[v], k, false);
            lo[k] = fmin(lo[k], x);
            hi[k] = fmax(hi[k], x);
        }
    bounds = bounds && count > 0;
    int view = lx_glb_add_view(c->f->root, &c->bin, d, count * stride,
                               stride != a.elem ? stride : 0, LX_GL_ARRAY_BUFFER);
    free(d);
    *out = lx_glb_add_accessor(c->f->root, view, a.component_type, count, a.type, a.normalized,
                               bounds ? lo : NULL, bounds ? hi : NULL);
    lx_gltf_array_free(&a);
    if (*out < 0 || c->bin.failed)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
    return LX_OK;
}

/* True when name is skip or one of e's attributes (NULL: none). */
static bool skipped(const char *name, const char *skip, const lx_scene_uvs *e)
{
    if (!name)
        return false;
    if (skip && strcmp(name, skip) == 0)
        return true;
    for (uint32_t k = 0; e && k < e->attribute_count; k++)
        if (strcmp(e->attributes[k].name, name) == 0)
            return true;
    return false;
}

/* Every attribute of obj (a primitive's "attributes" or a morph target)
 * replaced by its copy per new vertex; those skipped() are left out. */
static lx_status remap_attributes(wctx *c, cJSON *obj, const uint32_t *src_of, size_t count,
                                  const char *skip, const lx_scene_uvs *e, const char *where)
{
    cJSON *next;
    for (cJSON *a = obj ? obj->child : NULL; a; a = next) {
        next = a->next;
        if (skipped(a->string, skip, e)) {
            cJSON_DeleteItemFromObjectCaseSensitive(obj, a->string);
            continue;
        }
        size_t ai = accessor_at(c->f, obj, a->string);
        if (ai == SIZE_MAX)
            return lx_fail(LX_ERR_FORMAT, "%s: %s: attribute %s is not an accessor index",
                           c->f->path, where, a->string);
        int idx;
        lx_status st = remap_accessor(c, ai, src_of, count, strcmp(a->string, "POSITION") == 0,
                                      &idx);
        if (st != LX_OK)
            return st;
        cJSON_SetNumberValue(a, idx);
    }
    return LX_OK;
}

/* The corners (file vertex indices) of every triangle of a primitive. */
static lx_status primitive_corners(wctx *c, const cJSON *prim, size_t vertex_count,
                                   const char *where, uint32_t **out, size_t *tri_count)
{
    *out = NULL;
    *tri_count = 0;
    const cJSON *mode_j = lx_gltf_get(prim, "mode");
    int mode = mode_j ? (cJSON_IsNumber(mode_j) ? mode_j->valueint : -1) : 4;
    if (mode < 4 || mode > 6)
        return lx_fail(LX_ERR_FORMAT, "%s: %s: mode %d is not a triangle mode", c->f->path, where,
                       mode);
    lx_gltf_array ix = {0};
    size_t n = vertex_count;
    if (lx_gltf_get(prim, "indices")) {
        size_t ai = accessor_at(c->f, prim, "indices");
        if (ai == SIZE_MAX)
            return lx_fail(LX_ERR_FORMAT, "%s: %s: indices is not an accessor index", c->f->path,
                           where);
        lx_status st = lx_gltf_accessor_read(c->f, ai, &ix);
        if (st != LX_OK)
            return st;
        if (ix.components != 1 || ix.component_type == LX_GL_FLOAT ||
            ix.component_type == LX_GL_BYTE || ix.component_type == LX_GL_SHORT) {
            lx_gltf_array_free(&ix);
            return lx_fail(LX_ERR_FORMAT, "%s: %s: indices are not unsigned scalars", c->f->path,
                           where);
        }
        n = ix.count;
    }
    size_t tris = mode == 4 ? n / 3 : n >= 3 ? n - 2 : 0;
    uint32_t *corner = malloc(sizeof(uint32_t) * 3 * (tris ? tris : 1));
    if (!corner) {
        lx_gltf_array_free(&ix);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
    }
    for (size_t t = 0; t < tris; t++) {
        size_t k[3];
        if (mode == 4) {
            k[0] = 3 * t, k[1] = 3 * t + 1, k[2] = 3 * t + 2;
        } else if (mode == 5) { /* strip: every other triangle turned */
            k[0] = t, k[1] = t + 1 + t % 2, k[2] = t + 2 - t % 2;
        } else { /* fan */
            k[0] = t + 1, k[1] = t + 2, k[2] = 0;
        }
        for (int q = 0; q < 3; q++) {
            double v = ix.data ? lx_gltf_array_get(&ix, k[q], 0, false) : (double)k[q];
            if (!(v < (double)vertex_count)) {
                lx_gltf_array_free(&ix);
                free(corner);
                return lx_fail(LX_ERR_FORMAT, "%s: %s: index %.0f out of range (count %zu)",
                               c->f->path, where, v, vertex_count);
            }
            corner[3 * t + q] = (uint32_t)v;
        }
    }
    lx_gltf_array_free(&ix);
    *out = corner;
    *tri_count = tris;
    return LX_OK;
}

#define DROPPED UINT32_MAX

/* The entry's attributes over the new vertices (vertex v is entry vertex
 * key_of[v]; DROPPED ones, corners of zero-area triangles, get zeros and,
 * for TANGENT, a unit +x). */
static lx_status add_attributes(wctx *c, cJSON *attrs, const lx_scene_uvs *e,
                                const uint32_t *key_of, size_t nv, bool has_normal,
                                const char *where)
{
    static const char *const types[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    for (uint32_t k = 0; k < e->attribute_count; k++) {
        const lx_vertex_attribute *at = &e->attributes[k];
        bool tangent = strcmp(at->name, "TANGENT") == 0;
        if (tangent && !has_normal) {
            lx_log(LX_LOG_WARN, "%s: %s has no NORMAL: TANGENT left out (glTF ignores it)",
                   c->f->path, where);
            continue;
        }
        size_t comps = (size_t)at->components;
        float *d = calloc(nv ? nv * comps : 1, sizeof(float));
        if (!d)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
        for (size_t v = 0; v < nv; v++) {
            if (key_of[v] == DROPPED) {
                if (tangent)
                    d[v * comps] = d[v * comps + 3] = 1.0f;
                continue;
            }
            memcpy(d + v * comps, at->data + (size_t)key_of[v] * comps, sizeof(float) * comps);
        }
        int view = lx_glb_add_view(c->f->root, &c->bin, d, sizeof(float) * comps * nv, 0,
                                   LX_GL_ARRAY_BUFFER);
        free(d);
        int acc = lx_glb_add_accessor(c->f->root, view, LX_GL_FLOAT, nv, types[comps], false,
                                      NULL, NULL);
        if (acc < 0 || c->bin.failed)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
        cJSON_AddNumberToObject(attrs, at->name, acc);
    }
    return LX_OK;
}

static lx_status rebuild_primitive(wctx *c, cJSON *prim, const job *jb, const char *where)
{
    const lx_scene_uvs *e = jb->uvs;
    const lx_mesh *m = &c->scene->meshes[e->mesh];
    cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    if (lx_gltf_get(lx_gltf_get(prim, "extensions"), "KHR_draco_mesh_compression"))
        return lx_fail(LX_ERR_UNSUPPORTED,
                       "%s: %s: compressed geometry (KHR_draco_mesh_compression) cannot be "
                       "written again",
                       c->f->path, where);
    size_t pa = accessor_at(c->f, attrs, "POSITION");
    if (pa == SIZE_MAX)
        return lx_fail(LX_ERR_FORMAT, "%s: %s: no POSITION accessor", c->f->path, where);
    lx_gltf_array pos;
    lx_status st = lx_gltf_accessor_read(c->f, pa, &pos);
    if (st != LX_OK)
        return st;
    uint32_t *corner = NULL, *uvid = NULL, *head = NULL, *next = NULL, *src_of = NULL;
    uint32_t *key_of = NULL, *new_index = NULL;
    lx_vec2 *uv = NULL;
    size_t tris = 0, nv = 0;
    if (pos.components != 3) {
        st = lx_fail(LX_ERR_FORMAT, "%s: %s: POSITION is not VEC3", c->f->path, where);
        goto done;
    }
    st = primitive_corners(c, prim, pos.count, where, &corner, &tris);
    if (st != LX_OK)
        goto done;
    size_t cap = 3 * (tris ? tris : 1);
    uvid = malloc(sizeof(uint32_t) * cap);
    head = malloc(sizeof(uint32_t) * (pos.count ? pos.count : 1));
    next = malloc(sizeof(uint32_t) * cap);
    src_of = malloc(sizeof(uint32_t) * cap);
    key_of = malloc(sizeof(uint32_t) * cap);
    new_index = malloc(sizeof(uint32_t) * cap);
    uv = malloc(sizeof(lx_vec2) * cap);
    if (!uvid || !head || !next || !src_of || !key_of || !new_index || !uv) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
        goto done;
    }
    /* file triangle t against luxel's triangle j, in order: assimp keeps
     * the order but may start a triangle at another corner, and drops
     * zero-area ones when asked to */
    static const int perm[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                   {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
    size_t j = 0;
    for (size_t t = 0; t < tris; t++) {
        lx_vec3 g[3];
        for (int q = 0; q < 3; q++) {
            uint32_t v = corner[3 * t + q];
            g[q] = lx_v3((float)lx_gltf_array_get(&pos, v, 0, true),
                         (float)lx_gltf_array_get(&pos, v, 1, true),
                         (float)lx_gltf_array_get(&pos, v, 2, true));
        }
        bool matched = false;
        if (j < m->triangle_count) {
            lx_vec3 l[3];
            for (int q = 0; q < 3; q++)
                l[q] = m->positions[m->indices[3 * j + q]];
            for (int p = 0; p < 6 && !matched; p++) {
                matched = close_to(g[0], l[perm[p][0]]) && close_to(g[1], l[perm[p][1]]) &&
                          close_to(g[2], l[perm[p][2]]);
                for (int q = 0; matched && q < 3; q++)
                    uvid[3 * t + q] = e->indices[3 * j + perm[p][q]];
            }
        }
        if (matched) {
            j++;
            continue;
        }
        if (lx_triangle_degenerate(g[0], g[1], g[2]) || !lx_vec3_finite(g[0]) ||
            !lx_vec3_finite(g[1]) || !lx_vec3_finite(g[2])) {
            uvid[3 * t] = uvid[3 * t + 1] = uvid[3 * t + 2] = DROPPED;
            continue;
        }
        st = lx_fail(LX_ERR_UNSUPPORTED,
                     "%s: %s: triangle %zu does not match luxel's mesh '%s' (triangle %zu)",
                     c->f->path, where, t, m->name, j);
        goto done;
    }
    if (j != m->triangle_count) {
        st = lx_fail(LX_ERR_UNSUPPORTED, "%s: %s: %zu triangles match luxel's mesh '%s' of %u",
                     c->f->path, where, j, m->name, m->triangle_count);
        goto done;
    }
    /* one new vertex per (file vertex, UV vertex) pair */
    for (size_t v = 0; v < pos.count; v++)
        head[v] = UINT32_MAX;
    for (int pass = 0; pass < 2; pass++)
        for (size_t k = 0; k < 3 * tris; k++) {
            uint32_t gv = corner[k], key = uvid[k];
            if ((key == DROPPED) != (pass == 1))
                continue;
            uint32_t found = UINT32_MAX;
            if (key == DROPPED && head[gv] != UINT32_MAX)
                found = head[gv]; /* a zero-area triangle: any copy serves */
            for (uint32_t w = head[gv]; found == UINT32_MAX && w != UINT32_MAX; w = next[w])
                if (key_of[w] == key)
                    found = w;
            if (found == UINT32_MAX) {
                found = (uint32_t)nv++;
                key_of[found] = key;
                src_of[found] = gv;
                uv[found] = key == DROPPED || !e->uv ? lx_v2(0.0f, 0.0f) : e->uv[key];
                next[found] = head[gv];
                head[gv] = found;
            }
            new_index[k] = found;
        }
    /* the lightmap set: the node's, one for all its primitives (the set
     * the manifest names) */
    char set[32] = "";
    int lightmap_set = e->uv ? lx_scene_lightmap_set(c->scene, e->node) : 0;
    if (lightmap_set < 0) {
        st = lx_fail(LX_ERR_UNSUPPORTED,
                     "%s: %s: its materials read textures through every UV set from 1 to %d: "
                     "no set is left for the lightmap",
                     c->f->path, where, LX_MAX_UV_SETS - 1);
        goto done;
    }
    if (e->uv)
        snprintf(set, sizeof set, "TEXCOORD_%d", lightmap_set);
    bool has_normal = lx_gltf_get(attrs, "NORMAL") != NULL;
    st = remap_attributes(c, attrs, src_of, nv, set[0] ? set : NULL, e, where);
    cJSON *targets = cJSON_GetObjectItemCaseSensitive(prim, "targets");
    for (cJSON *tg = cJSON_IsArray(targets) ? targets->child : NULL; st == LX_OK && tg;
         tg = tg->next)
        st = remap_attributes(c, tg, src_of, nv, NULL, NULL, where);
    if (st != LX_OK)
        goto done;
    int view, acc;
    if (e->uv) {
        view = lx_glb_add_view(c->f->root, &c->bin, uv, sizeof(lx_vec2) * nv, 0,
                               LX_GL_ARRAY_BUFFER);
        acc = lx_glb_add_accessor(c->f->root, view, LX_GL_FLOAT, nv, "VEC2", false, NULL, NULL);
        /* sets are numbered from 0 without gaps (glTF, and readers such as
         * assimp): the lightmap UVs fill any missing set below theirs */
        for (int k = 0; k < lightmap_set; k++) {
            char below[32];
            snprintf(below, sizeof below, "TEXCOORD_%d", k);
            if (!lx_gltf_get(attrs, below))
                cJSON_AddNumberToObject(attrs, below, acc);
        }
        cJSON_AddNumberToObject(attrs, set, acc);
    }
    st = add_attributes(c, attrs, e, key_of, nv, has_normal, where);
    if (st != LX_OK)
        goto done;
    /* indices: 16 bits when they fit below the restart value */
    bool small = nv < 65535;
    size_t isz = small ? 2 : 4;
    uint8_t *ib = malloc(isz * 3 * (tris ? tris : 1));
    if (!ib) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
        goto done;
    }
    for (size_t k = 0; k < 3 * tris; k++) {
        if (small) {
            uint16_t x = (uint16_t)new_index[k];
            memcpy(ib + 2 * k, &x, 2);
        } else {
            memcpy(ib + 4 * k, &new_index[k], 4);
        }
    }
    view = lx_glb_add_view(c->f->root, &c->bin, ib, isz * 3 * tris, 0,
                           LX_GL_ELEMENT_ARRAY_BUFFER);
    free(ib);
    acc = lx_glb_add_accessor(c->f->root, view,
                              small ? LX_GL_UNSIGNED_SHORT : LX_GL_UNSIGNED_INT, 3 * tris,
                              "SCALAR", false, NULL, NULL);
    cJSON_DeleteItemFromObjectCaseSensitive(prim, "indices");
    cJSON_AddNumberToObject(prim, "indices", acc);
    cJSON_DeleteItemFromObjectCaseSensitive(prim, "mode"); /* TRIANGLES */
    if (c->bin.failed || acc < 0)
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
done:
    lx_gltf_array_free(&pos);
    free(corner);
    free(uvid);
    free(head);
    free(next);
    free(src_of);
    free(key_of);
    free(new_index);
    free(uv);
    return st;
}

/* Every image with a uri moves into the binary chunk. One that cannot be
 * read or is no image format glTF carries keeps its uri, with a warning:
 * the import went without it (a warning too), and the scene's other
 * outputs need not fail for it. */
static lx_status embed_images(wctx *c)
{
    cJSON *images = cJSON_GetObjectItemCaseSensitive(c->f->root, "images");
    size_t i = 0;
    for (cJSON *im = cJSON_IsArray(images) ? images->child : NULL; im; im = im->next, i++) {
        const char *uri = lx_gltf_get_string(im, "uri");
        if (!uri)
            continue;
        char what[64];
        snprintf(what, sizeof what, "image %zu", i);
        uint8_t *bytes;
        size_t size;
        char *mime = NULL;
        lx_status st = lx_gltf_uri_read(c->f, uri, what, &bytes, &size, &mime);
        if (st == LX_ERR_NOMEM)
            return st;
        if (st != LX_OK) {
            lx_log(LX_LOG_WARN, "%s; the .glb written refers to it by its uri", lx_last_error());
            continue;
        }
        const char *given = lx_gltf_get_string(im, "mimeType");
        const char *sniffed = lx_image_mime_sniff(bytes, size);
        const char *type = given ? given : sniffed ? sniffed : mime;
        if (!type) {
            free(bytes);
            free(mime);
            lx_log(LX_LOG_WARN,
                   "%s: %s ('%s'): not a PNG, JPEG, WebP or KTX2 image; the .glb written "
                   "refers to it by its uri",
                   c->f->path, what, uri);
            continue;
        }
        char type_copy[64];
        snprintf(type_copy, sizeof type_copy, "%s", type);
        int view = lx_glb_add_view(c->f->root, &c->bin, bytes, size, 0, 0);
        free(bytes);
        free(mime);
        cJSON_DeleteItemFromObjectCaseSensitive(im, "uri");
        cJSON_DeleteItemFromObjectCaseSensitive(im, "mimeType");
        cJSON_AddNumberToObject(im, "bufferView", view);
        cJSON_AddStringToObject(im, "mimeType", type_copy);
        if (c->bin.failed)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
    }
    return LX_OK;
}

static bool required(const cJSON *root, const char *ext)
{
    const cJSON *list = lx_gltf_get(root, "extensionsRequired");
    for (const cJSON *e = cJSON_IsArray(list) ? list->child : NULL; e; e = e->next)
        if (cJSON_IsString(e) && strcmp(e->valuestring, ext) == 0)
            return true;
    return false;
}

/* The glTF node, mesh and primitive of every entry, checked. */
static lx_status make_jobs(wctx *c, const lx_glb_write_desc *d, job *jobs)
{
    const lx_scene *s = c->scene;
    const cJSON *nodes = lx_gltf_get(c->f->root, "nodes");
    const cJSON *meshes = lx_gltf_get(c->f->root, "meshes");
    size_t nn = (size_t)cJSON_GetArraySize(nodes), nm = (size_t)cJSON_GetArraySize(meshes);
    for (uint32_t k = 0; k < d->uv_count; k++) {
        const lx_scene_uvs *e = &d->uvs[k];
        const lx_mesh *m = &s->meshes[e->mesh];
        if (e->node == LX_SCENE_EVERY_NODE) {
            if (m->source_mesh < 0 || m->source_primitive < 0 || (size_t)m->source_mesh >= nm ||
                m->source_primitive >=
                    cJSON_GetArraySize(lx_gltf_get(cJSON_GetArrayItem(meshes, m->source_mesh),
                                                   "primitives")))
                return lx_fail(LX_ERR_UNSUPPORTED,
                               "%s: mesh '%s': luxel could not tell which primitive of the file "
                               "it came from",
                               c->f->path, m->name);
            jobs[k] = (job){EVERY_NODE, (size_t)m->source_mesh, (size_t)m->source_primitive, e};
            continue;
        }
        const lx_node *n = &s->nodes[e->node];
        if (n->source_node < 0 || m->source_mesh < 0 || m->source_primitive < 0 ||
            (size_t)n->source_node >= nn || (size_t)m->source_mesh >= nm)
            return lx_fail(LX_ERR_UNSUPPORTED,
                           "%s: node '%s', mesh '%s': luxel could not tell which primitive of the "
                           "file it came from",
                           c->f->path, n->name, m->name);
        size_t gm;
        const cJSON *gn = cJSON_GetArrayItem(nodes, n->source_node);
        const cJSON *prims = lx_gltf_get(cJSON_GetArrayItem(meshes, m->source_mesh), "primitives");
        if (!lx_gltf_index(lx_gltf_get(gn, "mesh"), nm, &gm) || gm != (size_t)m->source_mesh ||
            m->source_primitive >= cJSON_GetArraySize(prims))
            return lx_fail(LX_ERR_INVALID, "%s: node '%s' does not place mesh '%s' in the file",
                           c->f->path, n->name, m->name);
        jobs[k] = (job){(size_t)n->source_node, gm, (size_t)m->source_primitive, e};
    }
    qsort(jobs, d->uv_count, sizeof *jobs, job_cmp);
    for (uint32_t k = 1; k < d->uv_count; k++)
        if (jobs[k].node == jobs[k - 1].node && jobs[k].mesh == jobs[k - 1].mesh &&
            jobs[k].prim == jobs[k - 1].prim)
            return lx_fail(LX_ERR_INVALID, "%s: two sets of UVs for node %zu, primitive %zu",
                           c->f->path, jobs[k].node, jobs[k].prim);
    return LX_OK;
}

static lx_status write_from_file(wctx *c, const lx_glb_write_desc *d)
{
    lx_gltf_file *f = c->f;
    if (required(f->root, "KHR_draco_mesh_compression"))
        return lx_fail(LX_ERR_UNSUPPORTED,
                       "%s: compressed geometry (KHR_draco_mesh_compression) cannot be written "
                       "again",
                       f->path);
    /* EXT_meshopt_compression's views are decoded (the file's JSON changed
     * in place, its indices kept) and written as plain data: the
     * extension's own buffer references would not survive the buffers
     * merged below, and its fallback buffer has no bytes */
    uint8_t *glb = NULL;
    size_t glb_size = 0;
    lx_status st = lx_gltf_decode_meshopt(f->path, f->root, &glb, &glb_size);
    if (st == LX_OK && glb)
        st = lx_gltf_file_adopt_glb(f, glb, glb_size);
    else
        free(glb);
    if (st != LX_OK)
        return st;
    st = lx_gltf_file_buffers(f);
    if (st != LX_OK)
        return st;
    bool *acc_before = NULL, *view_before = NULL;
    size_t nacc_before = 0, nview_before = 0;
    st = lx_gltf_used(f->root, &acc_before, &nacc_before, &view_before, &nview_before);
    if (st != LX_OK)
        return st;
    /* the old buffers, one after the other, become the start of the new one */
    size_t *base = malloc(sizeof(size_t) * (f->buffer_count ? f->buffer_count : 1));
    job *jobs = malloc(sizeof(job) * (d->uv_count ? d->uv_count : 1));
    cJSON *pristine = NULL;
    size_t *users = NULL, *job_users = NULL;
    bool *claimed = NULL;
    if (!base || !jobs) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
        goto done;
    }
    for (size_t i = 0; i < f->buffer_count; i++)
        base[i] = lx_glb_bin_append(&c->bin, f->buffers[i], f->buffer_sizes[i]);
    cJSON *views = cJSON_GetObjectItemCaseSensitive(f->root, "bufferViews");
    int old_views = cJSON_IsArray(views) ? cJSON_GetArraySize(views) : 0;
    st = make_jobs(c, d, jobs);
    if (st != LX_OK)
        goto done;
    cJSON *nodes = cJSON_GetObjectItemCaseSensitive(f->root, "nodes");
    cJSON *meshes = cJSON_GetObjectItemCaseSensitive(f->root, "meshes");
    size_t nm = (size_t)cJSON_GetArraySize(meshes);
    pristine = cJSON_Duplicate(meshes, true);
    users = calloc(nm ? nm : 1, sizeof *users);
    job_users = calloc(nm ? nm : 1, sizeof *job_users);
    claimed = calloc(nm ? nm : 1, sizeof *claimed);
    if ((meshes && !pristine) || !users || !job_users || !claimed) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
        goto done;
    }
    size_t gm;
    for (const cJSON *n = cJSON_IsArray(nodes) ? nodes->child : NULL; n; n = n->next)
        if (lx_gltf_index(lx_gltf_get(n, "mesh"), nm, &gm))
            users[gm]++;
    for (uint32_t k = 0; k < d->uv_count; k++)
        if (jobs[k].node != EVERY_NODE && (k == 0 || jobs[k].node != jobs[k - 1].node))
            job_users[jobs[k].mesh]++;
    for (uint32_t k = 0; k < d->uv_count && st == LX_OK;) {
        uint32_t end = k;
        while (end < d->uv_count && jobs[end].node == jobs[k].node &&
               (jobs[k].node != EVERY_NODE || jobs[end].mesh == jobs[k].mesh))
            end++;
        size_t mesh = jobs[k].mesh;
        cJSON *target;
        if (jobs[k].node == EVERY_NODE) {
            target = cJSON_GetArrayItem(meshes, (int)mesh); /* in place, for every node */
        } else if (!claimed[mesh] && users[mesh] == job_users[mesh]) {
            claimed[mesh] = true; /* the first of the nodes that all get UVs */
            target = cJSON_GetArrayItem(meshes, (int)mesh);
        } else {
            /* an instance: a mesh of its own, from the file's */
            target = cJSON_Duplicate(cJSON_GetArrayItem(pristine, (int)mesh), true);
            if (!target) {
                st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->out);
                break;
            }
            cJSON_AddItemToArray(meshes, target);
            cJSON *node = cJSON_GetArrayItem(nodes, (int)jobs[k].node);
            cJSON_SetNumberValue(cJSON_GetObjectItemCaseSensitive(node, "mesh"),
                                 cJSON_GetArraySize(meshes) - 1);
        }
        cJSON *prims = cJSON_GetObjectItemCaseSensitive(target, "primitives");
        for (; k < end && st == LX_OK; k++) {
            char where[96];
            snprintf(where, sizeof where, "mesh %zu, primitive %zu", mesh, jobs[k].prim);
            st = rebuild_primitive(c, cJSON_GetArrayItem(prims, (int)jobs[k].prim), &jobs[k],
                                   where);
        }
        k = end;
    }
    if (st == LX_OK)
        st = embed_images(c);
    if (st != LX_OK)
        goto done;
    /* the file's views now lie in buffer 0 at their buffer's base */
    int i = 0;
    for (cJSON *v = views ? views->child : NULL; v && i < old_views; v = v->next, i++) {
        size_t b = 0, off = 0;
        const cJSON *bj = lx_gltf_get(v, "buffer"), *oj = lx_gltf_get(v, "byteOffset");
        if (!lx_gltf_index(bj, f->buffer_count, &b)) {
            st = lx_fail(LX_ERR_FORMAT, "%s: bufferView %d: buffer is not a valid index",
                         f->path, i);
            goto done;
        }
        if (cJSON_IsNumber(oj) && oj->valuedouble > 0)
            off = (size_t)oj->valuedouble;
        cJSON_SetNumberValue((cJSON *)bj, 0);
        cJSON_DeleteItemFromObjectCaseSensitive(v, "byteOffset");
        if (base[b] + off)
            cJSON_AddNumberToObject(v, "byteOffset", (double)(base[b] + off));
    }
    st = lx_gltf_drop_unused(f->root, acc_before, nacc_before, view_before, nview_before);
    if (st == LX_OK)
        st = lx_glb_write(c->out, f->root, &c->bin);
done:
    free(acc_before);
    free(view_before);
    cJSON_Delete(pristine);
    free(users);
    free(job_users);
    free(claimed);
    free(base);
    free(jobs);
    return st;
}

lx_status lx_gltf_write_with_uvs(const lx_scene *scene, const char *path,
                                 const lx_glb_write_desc *d)
{
    lx_gltf_file f;
    wctx c = {.scene = scene, .f = &f, .out = path};
    lx_status st = lx_gltf_file_open(scene->path, &f);
    f.allow_any_path = scene->allow_any_path;
    if (st == LX_OK)
        st = write_from_file(&c, d);
    lx_gltf_file_close(&f);
    free(c.bin.data);
    return st;
}
