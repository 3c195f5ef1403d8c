/* lx_scene_write_glb: a scene with lightmap UVs as a GLB (glTF 2.0 spec,
 * 4.4 GLB file format). glTF scenes go back through their own file
 * (gltf_write.c); any other scene is written from luxel's data here: one
 * node per scene node with its world matrix, one mesh per node whose
 * primitives are the node's meshes, materials with their base colour
 * factor and embedded PNG/JPEG textures. */
#include "core/internal.h"
#include "gltf_data.h"
#include "gltf_json.h"
#include "gltf_write_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

lx_glb_write_desc lx_glb_write_desc_defaults(const lx_glb_write_desc *desc)
{
    lx_glb_write_desc d = {0};
    if (desc)
        d = *desc;
    return d; /* no field has a default other than zero */
}

static lx_status check_uvs(const lx_scene *s, const char *path, const lx_glb_write_desc *d)
{
    if (d->uv_count && !d->uvs)
        return lx_fail(LX_ERR_INVALID, "%s: %u UV entries given as NULL", path, d->uv_count);
    for (uint32_t k = 0; k < d->uv_count; k++) {
        const lx_scene_uvs *e = &d->uvs[k];
        if ((e->node >= s->node_count && e->node != LX_SCENE_EVERY_NODE) ||
            e->mesh >= s->mesh_count)
            return lx_fail(LX_ERR_INVALID,
                           "%s: UV entry %u: node %u or mesh %u out of range (%u nodes, %u "
                           "meshes)",
                           path, k, e->node, e->mesh, s->node_count, s->mesh_count);
        const lx_mesh *m = &s->meshes[e->mesh];
        if (e->vertex_count && !e->vertex_source)
            return lx_fail(LX_ERR_INVALID, "%s: UV entry %u has no vertices", path, k);
        if (e->attribute_count && !e->attributes)
            return lx_fail(LX_ERR_INVALID, "%s: UV entry %u: %u attributes given as NULL", path,
                           k, e->attribute_count);
        for (uint32_t a = 0; a < e->attribute_count; a++) {
            const lx_vertex_attribute *at = &e->attributes[a];
            if (!at->name || !*at->name || at->components < 1 || at->components > 4 ||
                (e->vertex_count && !at->data))
                return lx_fail(LX_ERR_INVALID, "%s: UV entry %u: attribute %u is malformed", path,
                               k, a);
            for (size_t i = 0; i < (size_t)at->components * e->vertex_count; i++)
                if (!isfinite(at->data[i]))
                    return lx_fail(LX_ERR_INVALID, "%s: UV entry %u: %s of vertex %zu is not finite",
                                   path, k, at->name, i / (size_t)at->components);
        }
        if (m->triangle_count && !e->indices)
            return lx_fail(LX_ERR_INVALID, "%s: UV entry %u has no indices", path, k);
        for (uint32_t v = 0; v < e->vertex_count; v++) {
            if (e->vertex_source[v] >= m->vertex_count)
                return lx_fail(LX_ERR_INVALID,
                               "%s: UV entry %u: vertex %u copies vertex %u of mesh '%s' (count "
                               "%u)",
                               path, k, v, e->vertex_source[v], m->name, m->vertex_count);
            if (e->uv && (!isfinite(e->uv[v].x) || !isfinite(e->uv[v].y)))
                return lx_fail(LX_ERR_INVALID, "%s: UV entry %u: vertex %u: UV is not finite",
                               path, k, v);
        }
        for (size_t i = 0; i < 3 * (size_t)m->triangle_count; i++)
            if (e->indices[i] >= e->vertex_count)
                return lx_fail(LX_ERR_INVALID, "%s: UV entry %u: index %u out of range (count %u)",
                               path, k, e->indices[i], e->vertex_count);
    }
    return LX_OK;
}

/* ---- a scene without a glTF file ------------------------------------------ */

typedef struct bctx {
    cJSON *root;
    lx_glb_bin bin;
    const char *out;
} bctx;

/* A float attribute of n elements of comps floats gathered through src
 * (NULL: identity). */
static int float_attribute(bctx *c, const float *data, int comps, const uint32_t *src, size_t n,
                           bool bounds)
{
    float *d = malloc(sizeof(float) * (size_t)comps * (n ? n : 1));
    if (!d) {
        c->bin.failed = true;
        return -1;
    }
    double lo[4] = {INFINITY, INFINITY, INFINITY, INFINITY}, hi[4] = {-INFINITY, -INFINITY,
                                                                      -INFINITY, -INFINITY};
    for (size_t v = 0; v < n; v++) {
        size_t from = src ? src[v] : v;
        for (int k = 0; k < comps; k++) {
            float x = data[from * (size_t)comps + (size_t)k];
            d[v * (size_t)comps + (size_t)k] = x;
            lo[k] = fmin(lo[k], x);
            hi[k] = fmax(hi[k], x);
        }
    }
    static const char *const types[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
    int view = lx_glb_add_view(c->root, &c->bin, d, sizeof(float) * (size_t)comps * n, 0,
                               LX_GL_ARRAY_BUFFER);
    free(d);
    return lx_glb_add_accessor(c->root, view, LX_GL_FLOAT, n, types[comps], false,
                               bounds && n ? lo : NULL, bounds && n ? hi : NULL);
}

/* True when entry e brings an attribute called name. */
static bool replaced(const lx_scene_uvs *e, const char *name)
{
    for (uint32_t k = 0; e && k < e->attribute_count; k++)
        if (strcmp(e->attributes[k].name, name) == 0)
            return true;
    return false;
}

static cJSON *primitive(bctx *c, const lx_mesh *m, const lx_scene_uvs *e, int lightmap_set)
{
    size_t nv = e ? e->vertex_count : m->vertex_count;
    const uint32_t *src = e ? e->vertex_source : NULL;
    const uint32_t *indices = e ? e->indices : m->indices;
    cJSON *p = cJSON_CreateObject();
    cJSON *a = cJSON_AddObjectToObject(p, "attributes");
    if (!a) {
        cJSON_Delete(p);
        return NULL;
    }
    cJSON_AddNumberToObject(a, "POSITION",
                            float_attribute(c, &m->positions[0].x, 3, src, nv, true));
    if (m->normals && !replaced(e, "NORMAL"))
        cJSON_AddNumberToObject(a, "NORMAL",
                                float_attribute(c, &m->normals[0].x, 3, src, nv, false));
    if (m->tangents && !replaced(e, "TANGENT"))
        cJSON_AddNumberToObject(a, "TANGENT",
                                float_attribute(c, &m->tangents[0].x, 4, src, nv, false));
    /* every UV set the mesh has, the entry's lightmap UVs as set
     * lightmap_set and its TEXCOORD_n attributes over the mesh's */
    int uv[LX_MAX_UV_SETS];
    int top = -1;
    for (int k = 0; k < LX_MAX_UV_SETS; k++) {
        char name[16];
        snprintf(name, sizeof name, "TEXCOORD_%d", k);
        uv[k] = -1;
        if (e && e->uv && k == lightmap_set)
            uv[k] = float_attribute(c, &e->uv[0].x, 2, NULL, nv, false);
        else if (!replaced(e, name) && m->uv[k])
            uv[k] = float_attribute(c, &m->uv[k][0].x, 2, src, nv, false);
        if (uv[k] >= 0)
            top = k;
    }
    for (uint32_t k = 0; e && k < e->attribute_count; k++) {
        const lx_vertex_attribute *at = &e->attributes[k];
        int set = -1;
        if (sscanf(at->name, "TEXCOORD_%d", &set) == 1 && set >= 0 && set < LX_MAX_UV_SETS &&
            !(e->uv && set == lightmap_set)) {
            uv[set] = float_attribute(c, at->data, at->components, NULL, nv, false);
            top = set > top ? set : top;
        } else if (set < 0) {
            cJSON_AddNumberToObject(a, at->name,
                                    float_attribute(c, at->data, at->components, NULL, nv, false));
        }
    }
    /* sets are numbered from 0 without gaps: the lightmap set (else the
     * first set there is) stands in for a missing one */
    int stand_in = e && e->uv && lightmap_set >= 0 ? uv[lightmap_set] : -1;
    for (int k = 0; stand_in < 0 && k <= top; k++)
        stand_in = uv[k];
    for (int k = 0; k <= top; k++) {
        char name[16];
        snprintf(name, sizeof name, "TEXCOORD_%d", k);
        cJSON_AddNumberToObject(a, name, uv[k] >= 0 ? uv[k] : stand_in);
    }
    size_t ni = 3 * (size_t)m->triangle_count;
    bool small = nv < 65535;
    uint8_t *ib = malloc((small ? 2 : 4) * (ni ? ni : 1));
    if (!ib) {
        cJSON_Delete(p);
        return NULL;
    }
    for (size_t i = 0; i < ni; i++) {
        if (small) {
            uint16_t x = (uint16_t)indices[i];
            memcpy(ib + 2 * i, &x, 2);
        } else {
            memcpy(ib + 4 * i, &indices[i], 4);
        }
    }
    int view = lx_glb_add_view(c->root, &c->bin, ib, (small ? 2 : 4) * ni, 0,
                               LX_GL_ELEMENT_ARRAY_BUFFER);
    free(ib);
    cJSON_AddNumberToObject(p, "indices",
                            lx_glb_add_accessor(c->root, view,
                                                small ? LX_GL_UNSIGNED_SHORT : LX_GL_UNSIGNED_INT,
                                                ni, "SCALAR", false, NULL, NULL));
    cJSON_AddNumberToObject(p, "material", m->material);
    return p;
}

/* A texture of the image file at path, embedded; -1 (with a warning) when
 * it is not PNG or JPEG, the formats glTF carries. */
static int texture(bctx *c, const char *path, const char *material)
{
    char *bytes;
    size_t size;
    if (lx_read_file(path, (size_t)1 << 30, &bytes, &size) != LX_OK) {
        lx_log(LX_LOG_WARN, "%s: material '%s': cannot read texture '%s'; left out", c->out,
               material, path);
        return -1;
    }
    const char *mime = lx_image_mime_sniff((const uint8_t *)bytes, size);
    if (!mime || (strcmp(mime, "image/png") != 0 && strcmp(mime, "image/jpeg") != 0)) {
        free(bytes);
        lx_log(LX_LOG_WARN,
               "%s: material '%s': texture '%s' is not PNG or JPEG (glTF carries no other); "
               "left out",
               c->out, material, path);
        return -1;
    }
    int view = lx_glb_add_view(c->root, &c->bin, bytes, size, 0, 0);
    free(bytes);
    cJSON *images = lx_glb_array_of(c->root, "images");
    cJSON *textures = lx_glb_array_of(c->root, "textures");
    cJSON *im = cJSON_CreateObject(), *tx = cJSON_CreateObject();
    if (!images || !textures || !im || !tx) {
        cJSON_Delete(im);
        cJSON_Delete(tx);
        c->bin.failed = true;
        return -1;
    }
    cJSON_AddNumberToObject(im, "bufferView", view);
    cJSON_AddStringToObject(im, "mimeType", mime);
    cJSON_AddItemToArray(images, im);
    cJSON_AddNumberToObject(tx, "source", cJSON_GetArraySize(images) - 1);
    cJSON_AddItemToArray(textures, tx);
    return cJSON_GetArraySize(textures) - 1;
}

static void material(bctx *c, const lx_material *m, cJSON *list)
{
    cJSON *j = cJSON_CreateObject();
    cJSON_AddStringToObject(j, "name", m->name);
    cJSON *pbr = cJSON_AddObjectToObject(j, "pbrMetallicRoughness");
    const float f[4] = {m->base_color.x, m->base_color.y, m->base_color.z, m->base_color.w};
    cJSON_AddItemToObject(pbr, "baseColorFactor", cJSON_CreateFloatArray(f, 4));
    /* luxel's materials are diffuse: no metal */
    cJSON_AddNumberToObject(pbr, "metallicFactor", 0);
    if (m->double_sided)
        cJSON_AddTrueToObject(j, "doubleSided");
    if (m->base_color_map_path) {
        int t = texture(c, m->base_color_map_path, m->name);
        if (t >= 0) {
            cJSON *ti = cJSON_AddObjectToObject(pbr, "baseColorTexture");
            cJSON_AddNumberToObject(ti, "index", t);
            if (m->base_color_uv_set)
                cJSON_AddNumberToObject(ti, "texCoord", m->base_color_uv_set);
        }
    }
    if (m->normal_map_path) {
        int t = texture(c, m->normal_map_path, m->name);
        if (t >= 0) {
            cJSON *ti = cJSON_AddObjectToObject(j, "normalTexture");
            cJSON_AddNumberToObject(ti, "index", t);
            if (m->normal_uv_set)
                cJSON_AddNumberToObject(ti, "texCoord", m->normal_uv_set);
            if (m->normal_scale != 1.0f)
                cJSON_AddNumberToObject(ti, "scale", m->normal_scale);
        }
    }
    cJSON_AddItemToArray(list, j);
}

static bool identity(const lx_mat4 *m)
{
    for (int i = 0; i < 16; i++)
        if (m->m[i] != (i % 5 == 0 ? 1.0f : 0.0f))
            return false;
    return true;
}

static lx_status write_built(const lx_scene *s, const char *path, const lx_glb_write_desc *d)
{
    /* a node given lightmap UVs needs a set for them */
    for (uint32_t k = 0; k < d->uv_count; k++)
        for (uint32_t n = 0; d->uvs[k].uv && n < s->node_count; n++) {
            const lx_node *node = &s->nodes[n];
            bool placed = d->uvs[k].node == n;
            for (uint32_t q = 0; !placed && d->uvs[k].node == LX_SCENE_EVERY_NODE &&
                                 q < node->mesh_count;
                 q++)
                placed = node->meshes[q] == d->uvs[k].mesh;
            if (placed && lx_scene_lightmap_set(s, n) < 0)
                return lx_fail(LX_ERR_UNSUPPORTED,
                               "%s: node '%s': its materials read textures through every UV "
                               "set from 1 to %d: no set is left for the lightmap",
                               path, node->name, LX_MAX_UV_SETS - 1);
        }
    bctx c = {.root = cJSON_CreateObject(), .out = path};
    if (!c.root)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    cJSON *asset = cJSON_AddObjectToObject(c.root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    cJSON_AddStringToObject(asset, "generator", "luxel " LX_VERSION);
    cJSON_AddNumberToObject(c.root, "scene", 0);
    cJSON *scene = cJSON_CreateObject();
    cJSON_AddItemToArray(cJSON_AddArrayToObject(c.root, "scenes"), scene);
    cJSON *roots = cJSON_AddArrayToObject(scene, "nodes");
    cJSON *nodes = cJSON_AddArrayToObject(c.root, "nodes");
    cJSON *meshes = cJSON_AddArrayToObject(c.root, "meshes");
    cJSON *mats = cJSON_AddArrayToObject(c.root, "materials");
    for (uint32_t i = 0; mats && i < s->material_count; i++)
        material(&c, &s->materials[i], mats);
    for (uint32_t n = 0; nodes && meshes && n < s->node_count; n++) {
        const lx_node *node = &s->nodes[n];
        cJSON *mesh = cJSON_CreateObject();
        cJSON_AddStringToObject(mesh, "name", node->name);
        cJSON *prims = cJSON_AddArrayToObject(mesh, "primitives");
        /* a node with new UVs: its entries (the meshes it placed when
         * unwrapped), else its meshes as they are */
        bool has = false;
        int set = lx_scene_lightmap_set(s, n);
        for (uint32_t k = 0; k < d->uv_count; k++)
            if (d->uvs[k].node == n) {
                has = true;
                cJSON_AddItemToArray(prims,
                                     primitive(&c, &s->meshes[d->uvs[k].mesh], &d->uvs[k], set));
            }
        for (uint32_t k = 0; !has && k < node->mesh_count; k++) {
            /* an entry for the mesh wherever it is placed, else as it is */
            const lx_scene_uvs *every = NULL;
            for (uint32_t q = 0; q < d->uv_count && !every; q++)
                if (d->uvs[q].node == LX_SCENE_EVERY_NODE && d->uvs[q].mesh == node->meshes[k])
                    every = &d->uvs[q];
            cJSON_AddItemToArray(prims, primitive(&c, &s->meshes[node->meshes[k]], every, set));
        }
        cJSON_AddItemToArray(meshes, mesh);
        cJSON *j = cJSON_CreateObject();
        cJSON_AddStringToObject(j, "name", node->name);
        cJSON_AddNumberToObject(j, "mesh", cJSON_GetArraySize(meshes) - 1);
        if (!identity(&node->world))
            cJSON_AddItemToObject(j, "matrix", cJSON_CreateFloatArray(node->world.m, 16));
        cJSON_AddItemToArray(nodes, j);
        cJSON_AddItemToArray(roots, cJSON_CreateNumber(n));
    }
    lx_status st = LX_OK;
    if (!asset || !roots || !nodes || !meshes || !mats || c.bin.failed)
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    if (st == LX_OK)
        st = lx_glb_write(path, c.root, &c.bin);
    cJSON_Delete(c.root);
    free(c.bin.data);
    return st;
}

lx_status lx_scene_write_glb(const lx_scene *scene, const char *path, const lx_glb_write_desc *in)
{
    lx_glb_write_desc d = lx_glb_write_desc_defaults(in);
    if (!scene || !path)
        return lx_fail(LX_ERR_INVALID, "lx_scene_write_glb: no scene or no path");
    lx_status st = check_uvs(scene, path, &d);
    if (st != LX_OK)
        return st;
    /* a glTF scene (by name or by content) goes back through its file */
    const char *dot = scene->path ? strrchr(scene->path, '.') : NULL;
    bool gltf_name = dot && (strcasecmp(dot, ".gltf") == 0 || strcasecmp(dot, ".glb") == 0);
    if (scene->path && (gltf_name || lx_gltf_sniff(scene->path) != LX_GLTF_NONE))
        return lx_gltf_write_with_uvs(scene, path, &d);
    return write_built(scene, path, &d);
}
