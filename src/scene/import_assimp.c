/* Scene import through assimp's C API (glTF 2.0, OBJ, FBX, ...): meshes,
 * materials with their normal and base-colour textures, and the node
 * hierarchy flattened into world-space instances. From a glTF file's own
 * JSON (gltf_json.c) come what assimp drops or changes: KHR_lights_punctual
 * lights (gltf_lights.c), KHR_texture_transform and texCoord
 * (gltf_textures.c), and the triangle count of every primitive, so faces
 * assimp dropped for out-of-range indices are noticed without its log. */
#include "luxel/scene.h"
#include "core/internal.h"

#include "gltf_json.h"
#include "json_text.h"

#include <assimp/cimport.h>
#include <assimp/GltfMaterial.h>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <float.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#define LX_NAME_MAX 256

typedef struct import_ctx {
    const char *path;
    const struct aiScene *ai;
    lx_scene *scene;
    const lx_scene_load_desc *desc;
    uint32_t *mesh_map; /* assimp mesh -> lx mesh index, UINT32_MAX if skipped */
    char *folder;
    const cJSON *gltf; /* the file's glTF 2.0 JSON, or NULL */
} import_ctx;

/* assimp's C API keeps the last error in one process-wide string, which
 * every failed import assigns (aiImportFileExWithProperties), so imports
 * are serialized. Its glTF 1.0 importer reports faces it dropped for
 * out-of-range indices only through its log, also process-wide: for such
 * files the log is watched while the import runs. glTF 2.0 files are
 * checked against their JSON instead (check_dropped_faces) and no other
 * importer drops faces that way, so no other import attaches a log (which
 * would also make assimp format every message it logs). */
static pthread_mutex_t import_lock = PTHREAD_MUTEX_INITIALIZER;
static bool dropped_faces;

static void on_assimp_log(const char *message, char *user)
{
    (void)user;
    if (strstr(message, "out-of-range indices"))
        dropped_faces = true;
}

/* OBJ text numbers that assimp would silently read as 0 ("nan", "inf",
 * values beyond float range) are refused before import. */
static lx_status check_obj_numbers(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return lx_fail(LX_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    char line[4096];
    char object[128] = "";
    unsigned long number = 0;
    lx_status st = LX_OK;
    while (st == LX_OK && fgets(line, sizeof line, fp)) {
        number++;
        if ((line[0] == 'o' || line[0] == 'g') && (line[1] == ' ' || line[1] == '\t')) {
            snprintf(object, sizeof object, "%s", line + 2);
            object[strcspn(object, "\r\n")] = '\0';
            continue;
        }
        const char *kind = NULL;
        if (strncmp(line, "v ", 2) == 0 || strncmp(line, "v\t", 2) == 0)
            kind = "v";
        else if (strncmp(line, "vt", 2) == 0 && (line[2] == ' ' || line[2] == '\t'))
            kind = "vt";
        else if (strncmp(line, "vn", 2) == 0 && (line[2] == ' ' || line[2] == '\t'))
            kind = "vn";
        if (!kind)
            continue;
        const char *p = line + strlen(kind);
        for (;;) {
            while (*p == ' ' || *p == '\t')
                p++;
            if (!*p || *p == '\n' || *p == '\r' || *p == '#')
                break;
            char *end;
            double v = strtod(p, &end);
            if (end == p)
                break; /* not a number: assimp reports it */
            if (!isfinite(v) || fabs(v) > FLT_MAX) {
                int len = (int)(end - p) < 32 ? (int)(end - p) : 32;
                st = lx_fail(LX_ERR_FORMAT, "%s: line %lu%s%s%s: '%s' value '%.*s' is not finite",
                             path, number, object[0] ? ": object '" : "", object,
                             object[0] ? "'" : "", kind, len, p);
                break;
            }
            p = end;
        }
    }
    fclose(fp);
    return st;
}

static lx_mat4 mat4_from_ai(const struct aiMatrix4x4 *a)
{
    /* aiMatrix4x4 is row-major (a1..a4 the first row); lx_mat4 column-major */
    lx_mat4 m = {{a->a1, a->b1, a->c1, a->d1, a->a2, a->b2, a->c2, a->d2, a->a3, a->b3, a->c3,
                  a->d3, a->a4, a->b4, a->c4, a->d4}};
    return m;
}

static bool has_extension(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && strcasecmp(path + n - e, ext) == 0;
}

/* Loads a texture named by a material: "*N" is embedded in the file, other
 * paths are relative to the scene's folder. Failures are warnings: the
 * material then goes without the map. With skip_textures only the name is
 * kept. */
static void load_texture(import_ctx *c, const struct aiString *tex_path, bool raw, const char *what,
                         const char *material, lx_image *out, char **out_path)
{
    const char *p = tex_path->data;
    if (c->desc->skip_textures) {
        *out_path = p[0] == '*' ? lx_strdup(p) : lx_path_join(c->folder, p);
        return;
    }
    lx_image_load_desc ld = {.raw_8bit = raw, .channels = raw ? 3 : 4};
    lx_status st;
    char *full = NULL;
    if (p[0] == '*') {
        char *end = NULL;
        long idx = strtol(p + 1, &end, 10);
        if (!end || *end || idx < 0 || (unsigned long)idx >= c->ai->mNumTextures) {
            lx_log(LX_LOG_WARN, "%s: material '%s': %s texture '%s' does not exist; ignored",
                   c->path, material, what, p);
            return;
        }
        const struct aiTexture *t = c->ai->mTextures[idx];
        if (t->mHeight != 0) {
            lx_log(LX_LOG_WARN,
                   "%s: material '%s': uncompressed embedded %s texture is not supported; "
                   "ignored",
                   c->path, material, what);
            return;
        }
        char name[LX_NAME_MAX];
        snprintf(name, sizeof name, "%s: embedded texture %ld", c->path, idx);
        st = lx_image_load_memory(t->pcData, t->mWidth, name, &ld, out);
    } else {
        full = lx_path_join(c->folder, p);
        if (!full)
            return;
        st = lx_image_load(full, &ld, out);
    }
    if (st != LX_OK) {
        lx_log(LX_LOG_WARN, "%s: material '%s': %s texture not loaded (%s); ignored", c->path,
               material, what, lx_last_error());
        memset(out, 0, sizeof *out);
        free(full);
        return;
    }
    *out_path = full ? full : lx_strdup(p);
}

static lx_status import_materials(import_ctx *c)
{
    /* assimp's glTF 2.0 importer makes material i of glTF material i, and
     * one default material after them */
    const cJSON *gltf_materials = lx_gltf_get(c->gltf, "materials");
    unsigned gltf_count =
        cJSON_IsArray(gltf_materials) ? (unsigned)cJSON_GetArraySize(gltf_materials) : 0;
    bool by_json = c->gltf && c->ai->mNumMaterials == gltf_count + 1;
    if (c->gltf && gltf_count && !by_json)
        lx_log(LX_LOG_WARN,
               "%s: assimp made %u materials of the file's %u; texCoord and "
               "KHR_texture_transform are taken from assimp",
               c->path, c->ai->mNumMaterials, gltf_count);
    for (unsigned i = 0; i < c->ai->mNumMaterials; i++) {
        const struct aiMaterial *am = c->ai->mMaterials[i];
        lx_material m = {0};
        lx_gltf_texture_ref ref_base = {0}, ref_normal = {0};
        if (by_json && i < gltf_count) {
            lx_status st = lx_gltf_material_textures(c->path, c->gltf, i, &ref_base, &ref_normal);
            if (st != LX_OK)
                return st;
        }
        struct aiString name;
        char name_buf[LX_NAME_MAX];
        if (aiGetMaterialString(am, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS && name.length)
            snprintf(name_buf, sizeof name_buf, "%s", name.data);
        else
            snprintf(name_buf, sizeof name_buf, "material%u", i);
        m.name = name_buf;
        struct aiColor4D col;
        m.base_color = lx_v4(1, 1, 1, 1);
        if (aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &col) == aiReturn_SUCCESS ||
            aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &col) == aiReturn_SUCCESS)
            m.base_color = lx_v4(col.r, col.g, col.b, col.a);
        if (!(isfinite(m.base_color.x) && isfinite(m.base_color.y) && isfinite(m.base_color.z)) ||
            m.base_color.x < 0 || m.base_color.y < 0 || m.base_color.z < 0)
            return lx_fail(LX_ERR_FORMAT,
                           "%s: material '%s': base colour is not a finite "
                           "non-negative colour",
                           c->path, name_buf);
        struct aiString tex;
        unsigned uv = 0;
        if (aiGetMaterialTexture(am, aiTextureType_NORMALS, 0, &tex, NULL, &uv, NULL, NULL, NULL,
                                 NULL) == aiReturn_SUCCESS) {
            load_texture(c, &tex, true, "normal", name_buf, &m.normal_map, &m.normal_map_path);
            if (ref_normal.present) {
                uv = ref_normal.tex_coord;
                m.normal_transform = ref_normal.transform;
            }
            /* checked unsigned: a huge texCoord must not wrap to -1 */
            m.normal_uv_set = uv < LX_MAX_UV_SETS ? (int)uv : LX_MAX_UV_SETS;
            /* glTF normalTexture.scale scales the map's x and y */
            ai_real scale = 1;
            if (aiGetMaterialFloatArray(am, AI_MATKEY_GLTF_TEXTURE_SCALE(aiTextureType_NORMALS, 0),
                                        &scale, NULL) == aiReturn_SUCCESS &&
                isfinite(scale))
                m.normal_scale = scale;
        }
        uv = 0;
        if (aiGetMaterialTexture(am, aiTextureType_BASE_COLOR, 0, &tex, NULL, &uv, NULL, NULL, NULL,
                                 NULL) == aiReturn_SUCCESS ||
            aiGetMaterialTexture(am, aiTextureType_DIFFUSE, 0, &tex, NULL, &uv, NULL, NULL, NULL,
                                 NULL) == aiReturn_SUCCESS) {
            load_texture(c, &tex, false, "base colour", name_buf, &m.base_color_map,
                         &m.base_color_map_path);
            if (ref_base.present) {
                uv = ref_base.tex_coord;
                m.base_color_transform = ref_base.transform;
            }
            m.base_color_uv_set = uv < LX_MAX_UV_SETS ? (int)uv : LX_MAX_UV_SETS;
        }
        if (m.normal_uv_set >= LX_MAX_UV_SETS || m.base_color_uv_set >= LX_MAX_UV_SETS) {
            lx_log(LX_LOG_WARN,
                   "%s: material '%s': textures on UV sets above 1 are not "
                   "supported; ignored",
                   c->path, name_buf);
            if (m.normal_uv_set >= LX_MAX_UV_SETS) {
                lx_image_free(&m.normal_map);
                m.normal_uv_set = 0;
                m.normal_transform = (lx_uv_transform){0};
            }
            if (m.base_color_uv_set >= LX_MAX_UV_SETS) {
                lx_image_free(&m.base_color_map);
                m.base_color_uv_set = 0;
                m.base_color_transform = (lx_uv_transform){0};
            }
        }
        if (m.normal_scale == 0.0f)
            m.normal_scale = 1.0f;
        lx_status st = lx_scene_add_material(c->scene, &m, NULL);
        lx_image_free(&m.normal_map);
        lx_image_free(&m.base_color_map);
        free(m.normal_map_path);
        free(m.base_color_map_path);
        if (st != LX_OK)
            return st;
    }
    if (c->scene->material_count == 0) {
        lx_material m = {.name = "default", .base_color = {1, 1, 1, 1}, .normal_scale = 1};
        return lx_scene_add_material(c->scene, &m, NULL);
    }
    return LX_OK;
}

static lx_status import_mesh(import_ctx *c, unsigned i)
{
    const struct aiMesh *am = c->ai->mMeshes[i];
    char name[LX_NAME_MAX];
    if (am->mName.length)
        snprintf(name, sizeof name, "%s", am->mName.data);
    else
        snprintf(name, sizeof name, "mesh%u", i);
    c->mesh_map[i] = UINT32_MAX;
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || am->mNumFaces == 0) {
        lx_log(LX_LOG_WARN, "%s: mesh '%s' has no triangles (points or lines); skipped", c->path,
               name);
        return LX_OK;
    }
    uint32_t nv = am->mNumVertices;
    lx_mesh m = {0};
    m.name = name;
    m.vertex_count = nv;
    m.material = am->mMaterialIndex < c->scene->material_count ? am->mMaterialIndex : 0;
    lx_status st = LX_OK;
    m.positions = malloc(sizeof(lx_vec3) * (nv ? nv : 1));
    m.indices = malloc(sizeof(uint32_t) * 3 * (size_t)am->mNumFaces);
    if (!m.positions || !m.indices) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory reading mesh '%s'", c->path, name);
        goto done;
    }
    for (uint32_t v = 0; v < nv; v++)
        m.positions[v] = lx_v3(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    if (am->mNormals) {
        m.normals = malloc(sizeof(lx_vec3) * nv);
        if (!m.normals) {
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
            goto done;
        }
        for (uint32_t v = 0; v < nv; v++)
            m.normals[v] = lx_v3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
    }
    for (int k = 0; k < LX_MAX_UV_SETS; k++) {
        if (!am->mTextureCoords[k])
            continue;
        m.uv[k] = malloc(sizeof(lx_vec2) * nv);
        if (!m.uv[k]) {
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
            goto done;
        }
        /* aiProcess_FlipUVs already put the origin at the top-left */
        for (uint32_t v = 0; v < nv; v++)
            m.uv[k][v] = lx_v2(am->mTextureCoords[k][v].x, am->mTextureCoords[k][v].y);
    }
    if (am->mTangents && am->mBitangents && am->mNormals) {
        m.tangents = malloc(sizeof(lx_vec4) * nv);
        if (!m.tangents) {
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
            goto done;
        }
        for (uint32_t v = 0; v < nv; v++) {
            lx_vec3 t = lx_v3(am->mTangents[v].x, am->mTangents[v].y, am->mTangents[v].z);
            lx_vec3 b = lx_v3(am->mBitangents[v].x, am->mBitangents[v].y, am->mBitangents[v].z);
            float w = lx_dot(lx_cross(m.normals[v], t), b) < 0.0f ? -1.0f : 1.0f;
            m.tangents[v] = lx_v4(t.x, t.y, t.z, w);
        }
    }
    uint32_t tri = 0, skipped = 0, not_tri = 0;
    for (unsigned f = 0; f < am->mNumFaces; f++) {
        const struct aiFace *face = &am->mFaces[f];
        if (face->mNumIndices != 3) {
            not_tri++;
            continue;
        }
        uint32_t *dst = &m.indices[3 * tri];
        for (int k = 0; k < 3; k++) {
            dst[k] = face->mIndices[k];
            if (dst[k] >= nv) {
                st = lx_fail(LX_ERR_FORMAT,
                             "%s: mesh '%s': face %u: index %u out of range "
                             "(count %u)",
                             c->path, name, f, dst[k], nv);
                goto done;
            }
        }
        if (!lx_vec3_finite(m.positions[dst[0]]) || !lx_vec3_finite(m.positions[dst[1]]) ||
            !lx_vec3_finite(m.positions[dst[2]])) {
            st = lx_fail(LX_ERR_FORMAT, "%s: mesh '%s': face %u: position is not finite", c->path,
                         name, f);
            goto done;
        }
        if (lx_triangle_degenerate(m.positions[dst[0]], m.positions[dst[1]], m.positions[dst[2]])) {
            if (!c->desc->skip_degenerate) {
                st = lx_fail(LX_ERR_FORMAT,
                             "%s: mesh '%s': triangle %u has zero area "
                             "(--skip-degenerate drops such triangles)",
                             c->path, name, f);
                goto done;
            }
            skipped++;
            continue;
        }
        tri++;
    }
    if (skipped)
        lx_log(LX_LOG_WARN, "%s: mesh '%s': %u zero-area triangles skipped", c->path, name,
               skipped);
    if (not_tri)
        lx_log(LX_LOG_WARN, "%s: mesh '%s': %u point/line primitives skipped", c->path, name,
               not_tri);
    if (tri == 0) {
        lx_log(LX_LOG_WARN, "%s: mesh '%s' has no usable triangles; skipped", c->path, name);
        goto done;
    }
    m.triangle_count = tri;
    st = lx_scene_add_mesh(c->scene, &m, &c->mesh_map[i]);
done:
    free(m.positions);
    free(m.normals);
    free(m.tangents);
    free(m.indices);
    for (int k = 0; k < LX_MAX_UV_SETS; k++)
        free(m.uv[k]);
    return st;
}

/* A node name unique in the scene: the node's own, else "node<N>", with
 * "_2", "_3"... appended on collisions. */
static void unique_node_name(const lx_scene *s, const char *base, char *out, size_t size)
{
    snprintf(out, size, "%s", base);
    for (int n = 2;; n++) {
        bool taken = false;
        for (uint32_t i = 0; i < s->node_count && !taken; i++)
            taken = strcmp(s->nodes[i].name, out) == 0;
        if (!taken)
            return;
        snprintf(out, size, "%s_%d", base, n);
    }
}

static lx_status import_node(import_ctx *c, const struct aiNode *node, const lx_mat4 *parent,
                             int depth, uint32_t *counter)
{
    if (depth > 256)
        return lx_fail(LX_ERR_FORMAT, "%s: node hierarchy deeper than 256 levels", c->path);
    lx_mat4 local = mat4_from_ai(&node->mTransformation);
    lx_mat4 world = lx_mat4_mul(parent, &local);
    (*counter)++;
    if (node->mNumMeshes) {
        uint32_t *meshes = malloc(sizeof(uint32_t) * node->mNumMeshes);
        if (!meshes)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
        uint32_t n = 0;
        for (unsigned k = 0; k < node->mNumMeshes; k++) {
            unsigned mi = node->mMeshes[k];
            if (mi >= c->ai->mNumMeshes) {
                free(meshes);
                return lx_fail(LX_ERR_FORMAT, "%s: node '%s': mesh %u out of range (count %u)",
                               c->path, node->mName.data, mi, c->ai->mNumMeshes);
            }
            if (c->mesh_map[mi] != UINT32_MAX)
                meshes[n++] = c->mesh_map[mi];
        }
        lx_status st = LX_OK;
        if (n && lx_mat4_finite(&world) && !(fabsf(lx_mat4_det3(&world)) > 1e-20f)) {
            /* exporters hide objects with a zero scale: nothing to bake */
            lx_log(LX_LOG_WARN, "%s: node '%s' has a zero scale; skipped", c->path,
                   node->mName.data);
            n = 0;
        }
        if (n) {
            char base[LX_NAME_MAX], name[LX_NAME_MAX + 16];
            if (node->mName.length)
                snprintf(base, sizeof base, "%s", node->mName.data);
            else
                snprintf(base, sizeof base, "node%u", *counter - 1);
            unique_node_name(c->scene, base, name, sizeof name);
            st = lx_scene_add_node(c->scene, name, &world, meshes, n, NULL);
        }
        free(meshes);
        if (st != LX_OK)
            return st;
    }
    for (unsigned k = 0; k < node->mNumChildren; k++) {
        lx_status st = import_node(c, node->mChildren[k], &world, depth + 1, counter);
        if (st != LX_OK)
            return st;
    }
    return LX_OK;
}

/* Faces assimp's glTF 2.0 importer dropped: it makes one mesh per
 * primitive, in file order, and leaves out every triangle with a vertex
 * index past the primitive's vertices (it says so only in its log). A
 * triangle primitive that comes out with fewer faces than its accessor's
 * count defines fails the load. */
static lx_status check_dropped_faces(const import_ctx *c)
{
    uint64_t *want;
    uint32_t *mesh_of;
    size_t n;
    lx_status st = lx_gltf_primitive_triangles(c->path, c->gltf, &want, &mesh_of, &n);
    if (st != LX_OK)
        return st;
    /* a count assimp does not match is a file it read some other way (it
     * fails such files itself): nothing to compare */
    if (n == c->ai->mNumMeshes) {
        const cJSON *meshes = lx_gltf_get(c->gltf, "meshes");
        size_t first = 0; /* entry of the current mesh's primitive 0 */
        for (size_t k = 0; k < n && st == LX_OK; k++) {
            if (k > 0 && mesh_of[k] != mesh_of[k - 1])
                first = k;
            const struct aiMesh *am = c->ai->mMeshes[k];
            if (want[k] == UINT64_MAX || !(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) ||
                (uint64_t)am->mNumFaces >= want[k])
                continue;
            char who[128];
            lx_gltf_label(who, sizeof who, "mesh", mesh_of[k],
                          cJSON_GetArrayItem(meshes, (int)mesh_of[k]));
            st = lx_fail(LX_ERR_FORMAT,
                         "%s: %s: primitive %zu: %llu of %llu triangles have vertex indices out "
                         "of range",
                         c->path, who, k - first, (unsigned long long)(want[k] - am->mNumFaces),
                         (unsigned long long)want[k]);
        }
    }
    free(want);
    free(mesh_of);
    return st;
}

/* True when assimp's glTF 2.0 importer read the file (it names itself in
 * the scene's metadata), so its meshes and materials follow the JSON's. */
static bool read_by_gltf2(const struct aiScene *ai)
{
    const struct aiMetadata *md = ai->mMetaData;
    for (unsigned i = 0; md && i < md->mNumProperties; i++)
        if (strcmp(md->mKeys[i].data, "SourceAsset_Format") == 0 &&
            md->mValues[i].mType == AI_AISTRING && md->mValues[i].mData)
            return strncmp(((const struct aiString *)md->mValues[i].mData)->data, "glTF2", 5) == 0;
    return false;
}

lx_scene_load_desc lx_scene_load_desc_defaults(const lx_scene_load_desc *desc)
{
    lx_scene_load_desc d = {0};
    if (desc)
        d = *desc;
    return d; /* every field's zero is its default */
}

lx_status lx_scene_load(const char *path, const lx_scene_load_desc *in, lx_scene **out)
{
    *out = NULL;
    lx_scene_load_desc defaults = lx_scene_load_desc_defaults(in);
    const lx_scene_load_desc *desc = &defaults;
    struct stat st_buf;
    if (stat(path, &st_buf) != 0)
        return lx_fail(LX_ERR_IO, "%s: cannot open: no such file", path);
    if (!S_ISREG(st_buf.st_mode))
        return lx_fail(LX_ERR_IO, "%s: not a regular file", path);
    FILE *probe = fopen(path, "rb");
    if (!probe)
        return lx_fail(LX_ERR_IO, "%s: cannot open: permission denied or unreadable", path);
    fclose(probe);
    /* assimp picks a reader by the name and, failing that, by sniffing the
     * bytes, and some of its readers overrun buffers on malformed input
     * (OpenGEX on 20 bytes of "vertexarray (attrib)"): it only gets the
     * formats luxel supports, each checked below before assimp reads it */
    if (!has_extension(path, ".gltf") && !has_extension(path, ".glb") &&
        !has_extension(path, ".obj"))
        return lx_fail(LX_ERR_UNSUPPORTED,
                       "%s: not a scene luxel reads (it reads .gltf, .glb and .obj files)", path);

    if (has_extension(path, ".obj")) {
        lx_status st = check_obj_numbers(path);
        if (st != LX_OK)
            return st;
    }
    /* glTF by content, not by name: assimp recognises it either way */
    lx_gltf_kind kind = lx_gltf_sniff(path);
    if (kind == LX_GLTF_GLB || has_extension(path, ".glb")) {
        lx_status st = lx_glb_check_file(path);
        if (st != LX_OK)
            return st;
    }
    /* a .gltf that is not JSON would be handed to whichever assimp reader
     * claims its bytes (its OpenGEX reader overruns a buffer on 20 bytes
     * of "vertexarray (attrib)") */
    if (kind == LX_GLTF_NONE && has_extension(path, ".gltf"))
        return lx_fail(LX_ERR_FORMAT, "%s: not glTF: the file is not JSON text", path);
    cJSON *gltf = NULL;
    if (kind != LX_GLTF_NONE) {
        lx_status st = lx_gltf_json_read(path, &gltf);
        if (st != LX_OK)
            return st;
    }
    bool gltf2 = gltf && lx_gltf_is_v2(gltf);
    /* only assimp's glTF 1.0 reader needs its log watched */
    bool watch_log = gltf && !gltf2;
    struct aiPropertyStore *props = aiCreatePropertyStore();
    /* Smooth normals where a file has none, but keep hard edges hard. */
    aiSetImportPropertyFloat(props, AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, 60.0f);
    unsigned flags = aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_FlipUVs |
                     aiProcess_GenSmoothNormals | aiProcess_JoinIdenticalVertices |
                     aiProcess_ValidateDataStructure;
    struct aiLogStream log = {on_assimp_log, NULL};
    pthread_mutex_lock(&import_lock);
    dropped_faces = false;
    if (watch_log)
        aiAttachLogStream(&log);
    const struct aiScene *ai = aiImportFileExWithProperties(path, flags, NULL, props);
    if (watch_log)
        aiDetachLogStream(&log);
    bool dropped = dropped_faces;
    char why[512];
    snprintf(why, sizeof why, "%s", ai ? "" : aiGetErrorString());
    pthread_mutex_unlock(&import_lock);
    aiReleasePropertyStore(props);
    if (!ai) {
        cJSON_Delete(gltf);
        return lx_fail(LX_ERR_FORMAT, "%s: cannot import: %s", path,
                       why[0] ? why : "unknown format or corrupt file");
    }
    if (dropped) {
        aiReleaseImport(ai);
        cJSON_Delete(gltf);
        return lx_fail(LX_ERR_FORMAT, "%s: some faces have indices out of range", path);
    }
    /* assimp flags a scene without meshes incomplete; lights alone are fine */
    if (!ai->mRootNode) {
        aiReleaseImport(ai);
        cJSON_Delete(gltf);
        return lx_fail(LX_ERR_FORMAT, "%s: cannot import: the file has no scene", path);
    }
    import_ctx c = {
        .path = path, .ai = ai, .desc = desc, .gltf = gltf2 && read_by_gltf2(ai) ? gltf : NULL};
    lx_status st = lx_scene_create(path, &c.scene);
    if (st != LX_OK) {
        aiReleaseImport(ai);
        cJSON_Delete(gltf);
        return st;
    }
    c.folder = lx_path_dirname(path);
    c.mesh_map = malloc(sizeof(uint32_t) * (ai->mNumMeshes ? ai->mNumMeshes : 1));
    if (!c.folder || !c.mesh_map)
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    if (st == LX_OK && c.gltf)
        st = check_dropped_faces(&c);
    if (st == LX_OK)
        st = import_materials(&c);
    for (unsigned i = 0; st == LX_OK && i < ai->mNumMeshes; i++)
        st = import_mesh(&c, i);
    if (st == LX_OK) {
        lx_mat4 root = lx_mat4_identity();
        uint32_t counter = 0;
        st = import_node(&c, ai->mRootNode, &root, 0, &counter);
    }
    if (st == LX_OK && gltf)
        st = lx_gltf_lights_from_json(c.scene, path, gltf);
    aiReleaseImport(ai);
    cJSON_Delete(gltf);
    free(c.mesh_map);
    free(c.folder);
    if (st != LX_OK) {
        lx_scene_destroy(c.scene);
        return st;
    }
    *out = c.scene;
    return LX_OK;
}
