/* What assimp 5.2.5 cannot read in a glTF 2.0 file, made readable before
 * it sees the file: the extensionsRequired check, EXT_meshopt_compression
 * (Khronos extension spec: compressed bufferViews, decoded with
 * meshoptimizer's decoders and filters) and KHR_mesh_quantization
 * (normalized and integer accessors, which assimp copies byte for byte
 * into its float vectors: converted to float here as the glTF 2.0 spec's
 * 3.11 "Animations"/"Accessors" normalization rules say). The file is
 * rewritten in memory as a GLB: the JSON (changed in place, so every index
 * the importer matches stays the same) and a binary chunk that holds the
 * file's own binary chunk followed by the decoded and converted data. */
#include "gltf_data.h"
#include "gltf_json.h"
#include "core/internal.h"

#include "json_text.h"

#include <math.h>
#include <meshoptimizer.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define failf(file, st, ...) lx_json_fail(st, file, NULL, __VA_ARGS__)
#define BUFFER_MAX ((size_t)1 << 31)
#define LFS_MAGIC "version https://git-lfs.github.com/spec/v1"

/* ---- extensionsRequired -------------------------------------------------- */

static const char *const supported[] = {
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_texture_transform",
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "KHR_materials_pbrSpecularGlossiness", /* its diffuse colour: the albedo */
};

/* Extensions that only add image formats: a file requiring one loads, its
 * textures in that format left out. */
static const char *const texture_formats[] = {"KHR_texture_basisu", "EXT_texture_webp",
                                              "EXT_texture_avif"};

lx_status lx_gltf_check_required(const char *file, const cJSON *root)
{
    const cJSON *req = lx_gltf_get(root, "extensionsRequired");
    if (!req)
        return LX_OK;
    if (!cJSON_IsArray(req))
        return failf(file, LX_ERR_FORMAT, "extensionsRequired is not an array");
    for (const cJSON *e = req->child; e; e = e->next) {
        if (!cJSON_IsString(e) || !e->valuestring)
            return failf(file, LX_ERR_FORMAT, "extensionsRequired holds a non-string");
        bool known = false;
        for (size_t i = 0; i < sizeof supported / sizeof supported[0] && !known; i++)
            known = strcmp(e->valuestring, supported[i]) == 0;
        bool texture_only = false;
        for (size_t i = 0; i < sizeof texture_formats / sizeof texture_formats[0]; i++)
            texture_only |= strcmp(e->valuestring, texture_formats[i]) == 0;
        if (texture_only) {
            /* only textures need it: the geometry and lights are there */
            lx_log(LX_LOG_WARN,
                   "%s: requires %s, an image format luxel does not decode: textures only in "
                   "it are left out (their materials' factors are used)",
                   file, e->valuestring);
            continue;
        }
        if (!known)
            return failf(file, LX_ERR_UNSUPPORTED, "requires extension %.80s, which luxel does not read",
                         e->valuestring);
    }
    return LX_OK;
}

/* ---- Git LFS pointers ------------------------------------------------------ */

bool lx_lfs_pointer(const void *bytes, size_t size)
{
    size_t n = sizeof LFS_MAGIC - 1;
    return size >= n && memcmp(bytes, LFS_MAGIC, n) == 0;
}

bool lx_lfs_pointer_file(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return false;
    char head[64];
    size_t n = fread(head, 1, sizeof head, fp);
    fclose(fp);
    return lx_lfs_pointer(head, n);
}

/* A URI's path with %XX escapes decoded (the glTF spec's URIs are
 * RFC 3986), or NULL when malformed or out of memory. */
static char *uri_path(const char *uri)
{
    size_t n = strlen(uri);
    char *out = malloc(n + 1), *o = out;
    if (!out)
        return NULL;
    for (const char *p = uri; *p; p++) {
        if (*p == '%' && p[1] && p[2]) {
            char hex[3] = {p[1], p[2], 0}, *end;
            long v = strtol(hex, &end, 16);
            if (*end || v <= 0) {
                free(out);
                return NULL;
            }
            *o++ = (char)v;
            p += 2;
        } else {
            *o++ = *p;
        }
    }
    *o = '\0';
    return out;
}

static bool is_data_uri(const char *uri)
{
    return strncmp(uri, "data:", 5) == 0;
}

/* A base64 data: URI whose text is not base64, or a buffer's that holds
 * fewer bytes than its byteLength, is refused here: assimp's glTF reader
 * leaks what it allocated when it throws on one (found by fuzz_scene).
 * Other data: URIs are left to the readers. */
static lx_status check_data_uri(const char *path, const char *what, size_t index, const char *uri,
                                const cJSON *buffer)
{
    const char *comma = strstr(uri, ";base64,");
    if (!comma)
        return LX_OK;
    uint8_t *bytes = NULL;
    size_t size = 0;
    int decoded = lx_gltf_base64_decode(comma + 8, strlen(comma + 8), &bytes, &size);
    free(bytes);
    if (decoded < 0)
        return failf(path, LX_ERR_NOMEM, "out of memory decoding %s %zu", what, index);
    if (decoded == 0)
        return failf(path, LX_ERR_FORMAT, "%s %zu: the data URI is not base64", what, index);
    double declared = buffer ? cJSON_GetNumberValue(lx_gltf_get(buffer, "byteLength")) : 0.0;
    if (buffer && declared > (double)size)
        return failf(path, LX_ERR_FORMAT, "buffer %zu: byteLength %.0f but %zu bytes of data",
                     index, declared, size);
    return LX_OK;
}

lx_status lx_gltf_check_files(const char *path, const cJSON *root, bool allow_any_path)
{
    static const char *const lists[] = {"buffers", "images"};
    char *folder = lx_path_dirname(path);
    if (!folder)
        return failf(path, LX_ERR_NOMEM, "out of memory");
    lx_status st = LX_OK;
    for (int l = 0; l < 2 && st == LX_OK; l++) {
        const cJSON *list = lx_gltf_get(root, lists[l]);
        size_t i = 0;
        for (const cJSON *b = cJSON_IsArray(list) ? list->child : NULL; b && st == LX_OK;
             b = b->next, i++) {
            const char *uri = lx_gltf_get_string(b, "uri");
            if (uri && is_data_uri(uri)) {
                st = check_data_uri(path, l ? "image" : "buffer", i, uri, l ? NULL : b);
                continue;
            }
            if (!uri)
                continue;
            char *rel = uri_path(uri), *full = rel ? lx_path_join(folder, rel) : NULL;
            char what[32];
            snprintf(what, sizeof what, "%s %zu", l ? "image" : "buffer", i);
            if (full)
                st = lx_path_confine(path, what, uri, folder, full, allow_any_path);
            if (st == LX_OK && full && lx_lfs_pointer_file(full))
                st = failf(path, LX_ERR_FORMAT,
                           "%s %zu ('%.200s') is a Git LFS pointer, not the file: run git lfs pull",
                           l ? "image" : "buffer", i, uri);
            free(rel);
            free(full);
        }
    }
    free(folder);
    return st;
}

/* ---- the rewrite ----------------------------------------------------------- */

typedef struct source_buffer {
    bool loaded;
    uint8_t *data; /* owned unless it is the GLB's binary chunk */
    size_t size;
    bool owned;
} source_buffer;

typedef struct rewrite {
    const char *file;
    char *folder;
    cJSON *root;
    const uint8_t *bin; /* the GLB's binary chunk, or NULL */
    size_t bin_size;
    source_buffer *buffers; /* the file's buffers by index */
    size_t buffer_count;
    const cJSON **views;
    size_t view_count;
    uint8_t *out; /* the new binary chunk */
    size_t out_size, out_cap;
    bool *rewritten_view; /* the view now lies in out */
    size_t added;         /* views added after the file's view_count */
} rewrite;

static lx_status decode_base64(const rewrite *r, size_t index, const char *text, source_buffer *b)
{
    int decoded = lx_gltf_base64_decode(text, strlen(text), &b->data, &b->size);
    if (decoded < 0)
        return failf(r->file, LX_ERR_NOMEM, "out of memory decoding buffer %zu", index);
    if (decoded == 0)
        return failf(r->file, LX_ERR_FORMAT, "buffer %zu: the data URI is not base64", index);
    b->owned = true;
    return LX_OK;
}

/* The bytes of the file's buffer `index`. */
static lx_status buffer_bytes(rewrite *r, size_t index, const uint8_t **data, size_t *size)
{
    if (index >= r->buffer_count)
        return failf(r->file, LX_ERR_FORMAT, "buffer %zu does not exist (count %zu)", index,
                     r->buffer_count);
    source_buffer *b = &r->buffers[index];
    const cJSON *json = cJSON_GetArrayItem(lx_gltf_get(r->root, "buffers"), (int)index);
    if (!b->loaded) {
        const char *uri = lx_gltf_get_string(json, "uri");
        lx_status st = LX_OK;
        if (!uri && index == 0 && r->bin) {
            b->data = (uint8_t *)r->bin;
            b->size = r->bin_size;
        } else if (!uri) {
            return failf(r->file, LX_ERR_FORMAT,
                         "buffer %zu has no data (no uri: a fallback of EXT_meshopt_compression?) "
                         "but a bufferView reads it",
                         index);
        } else if (is_data_uri(uri)) {
            const char *comma = strstr(uri, ";base64,");
            if (!comma)
                return failf(r->file, LX_ERR_UNSUPPORTED, "buffer %zu: data URI is not base64",
                             index);
            st = decode_base64(r, index, comma + 8, b);
        } else {
            char *rel = uri_path(uri), *full = rel ? lx_path_join(r->folder, rel) : NULL;
            if (!full)
                st = failf(r->file, LX_ERR_FORMAT, "buffer %zu: malformed uri '%.200s'", index,
                           uri);
            else if (lx_lfs_pointer_file(full))
                st = failf(r->file, LX_ERR_FORMAT,
                           "buffer %zu ('%.200s') is a Git LFS pointer, not the file: run git lfs "
                           "pull",
                           index, uri);
            else {
                char *bytes = NULL;
                st = lx_read_file(full, BUFFER_MAX, &bytes, &b->size);
                b->data = (uint8_t *)bytes;
                b->owned = true;
            }
            free(rel);
            free(full);
        }
        if (st != LX_OK)
            return st;
        b->loaded = true;
    }
    double declared = cJSON_GetNumberValue(lx_gltf_get(json, "byteLength"));
    if (!(declared >= 0) || declared > (double)b->size)
        return failf(r->file, LX_ERR_FORMAT, "buffer %zu: byteLength %.0f but %zu bytes of data",
                     index, declared, b->size);
    *data = b->data;
    *size = (size_t)declared;
    return LX_OK;
}

/* A non-negative integer member (def when absent); false when malformed. */
static bool get_size(const cJSON *obj, const char *key, size_t def, size_t *out)
{
    const cJSON *it = lx_gltf_get(obj, key);
    if (!it) {
        *out = def;
        return true;
    }
    return lx_gltf_index(it, (size_t)1 << 53, out);
}

static void set_number(cJSON *obj, const char *key, double v)
{
    cJSON *n = cJSON_CreateNumber(v);
    bool kept = cJSON_HasObjectItem(obj, key) ? cJSON_ReplaceItemInObjectCaseSensitive(obj, key, n)
                                              : cJSON_AddItemToObject(obj, key, n);
    if (!kept)
        cJSON_Delete(n);
}

/* Appends size bytes (16-byte aligned) to the new binary chunk. */
static lx_status out_append(rewrite *r, const void *bytes, size_t size, size_t *offset)
{
    size_t start = (r->out_size + 15) / 16 * 16;
    if (start + size > r->out_cap) {
        size_t cap = (start + size) + (start + size) / 2 + 64;
        uint8_t *p = realloc(r->out, cap);
        if (!p)
            return failf(r->file, LX_ERR_NOMEM, "out of memory rewriting the buffers (%zu bytes)",
                         cap);
        r->out = p;
        r->out_cap = cap;
    }
    memset(r->out + r->out_size, 0, start - r->out_size);
    if (size)
        memcpy(r->out + start, bytes, size);
    r->out_size = start + size;
    *offset = start;
    return LX_OK;
}

/* The bytes of bufferView v as they are now (in the new chunk once
 * rewritten). */
static lx_status view_bytes(rewrite *r, size_t v, const uint8_t **data, size_t *size,
                            size_t *stride)
{
    const cJSON *view = r->views[v];
    size_t buffer, offset, length;
    if (!lx_gltf_index(lx_gltf_get(view, "buffer"), SIZE_MAX, &buffer) ||
        !get_size(view, "byteOffset", 0, &offset) || !get_size(view, "byteLength", 0, &length) ||
        !get_size(view, "byteStride", 0, stride))
        return failf(r->file, LX_ERR_FORMAT, "bufferView %zu: malformed buffer, byteOffset, "
                     "byteLength or byteStride", v);
    const uint8_t *base;
    size_t have;
    if (r->rewritten_view[v]) {
        base = r->out;
        have = r->out_size;
    } else {
        lx_status st = buffer_bytes(r, buffer, &base, &have);
        if (st != LX_OK)
            return st;
    }
    if (offset > have || length > have - offset)
        return failf(r->file, LX_ERR_FORMAT,
                     "bufferView %zu: bytes %zu..%zu run past its buffer (%zu bytes)", v, offset,
                     offset + length, have);
    *data = base + offset;
    *size = length;
    return LX_OK;
}

/* ---- EXT_meshopt_compression ----------------------------------------------- */

static lx_status decode_meshopt(rewrite *r, size_t v, cJSON *view, const cJSON *ext)
{
    char who[64];
    snprintf(who, sizeof who, "bufferView %zu: EXT_meshopt_compression", v);
    size_t buffer, offset, length, stride, count, parent_length, parent_stride;
    const char *mode = lx_gltf_get_string(ext, "mode");
    const char *filter = lx_gltf_get_string(ext, "filter");
    if (!cJSON_IsObject(ext) || !lx_gltf_index(lx_gltf_get(ext, "buffer"), SIZE_MAX, &buffer) ||
        !get_size(ext, "byteOffset", 0, &offset) || !get_size(ext, "byteLength", SIZE_MAX, &length) ||
        length == SIZE_MAX || !get_size(ext, "byteStride", 0, &stride) ||
        !get_size(ext, "count", SIZE_MAX, &count) || count == SIZE_MAX || !mode ||
        !get_size(view, "byteLength", 0, &parent_length) ||
        !get_size(view, "byteStride", 0, &parent_stride))
        return lx_json_fail(LX_ERR_FORMAT, r->file, who,
                            "needs buffer, byteLength, byteStride, count and mode");
    if (!filter)
        filter = "NONE";
    bool attributes = strcmp(mode, "ATTRIBUTES") == 0, triangles = strcmp(mode, "TRIANGLES") == 0,
         indices = strcmp(mode, "INDICES") == 0;
    if (!attributes && !triangles && !indices)
        return lx_json_fail(LX_ERR_UNSUPPORTED, r->file, who, "unknown mode '%.40s'", mode);
    int f = strcmp(filter, "NONE") == 0          ? 0
            : strcmp(filter, "OCTAHEDRAL") == 0  ? 1
            : strcmp(filter, "QUATERNION") == 0  ? 2
            : strcmp(filter, "EXPONENTIAL") == 0 ? 3
                                                 : -1;
    if (f < 0)
        return lx_json_fail(LX_ERR_UNSUPPORTED, r->file, who, "unknown filter '%.40s'", filter);
    /* the spec's validity rules, which the decoders also assume */
    const char *bad = NULL;
    if (attributes && (stride == 0 || stride % 4 != 0 || stride > 256))
        bad = "ATTRIBUTES needs a byteStride that is a multiple of 4 up to 256";
    else if (!attributes && stride != 2 && stride != 4)
        bad = "TRIANGLES and INDICES need a byteStride of 2 or 4";
    else if (triangles && count % 3 != 0)
        bad = "TRIANGLES needs a count divisible by 3";
    else if (!attributes && f != 0)
        bad = "filters apply to ATTRIBUTES only";
    else if (f == 1 && stride != 4 && stride != 8)
        bad = "OCTAHEDRAL needs a byteStride of 4 or 8";
    else if (f == 2 && stride != 8)
        bad = "QUATERNION needs a byteStride of 8";
    else if (parent_stride && parent_stride != stride)
        bad = "byteStride differs from the bufferView's";
    if (bad)
        return lx_json_fail(LX_ERR_FORMAT, r->file, who, "%s", bad);
    size_t decoded;
    if (!lx_size_mul(count, stride, 1, &decoded) || decoded != parent_length)
        return lx_json_fail(LX_ERR_FORMAT, r->file, who,
                            "count %zu times byteStride %zu is not the bufferView's byteLength %zu",
                            count, stride, parent_length);
    const uint8_t *src;
    size_t src_size;
    lx_status st = buffer_bytes(r, buffer, &src, &src_size);
    if (st != LX_OK)
        return st;
    if (offset > src_size || length > src_size - offset)
        return lx_json_fail(LX_ERR_FORMAT, r->file, who,
                            "bytes %zu..%zu run past buffer %zu (%zu bytes)", offset,
                            offset + length, buffer, src_size);
    char what[96];
    snprintf(what, sizeof what, "decoding bufferView %zu", v);
    if ((st = lx_check_memory(decoded, what)) != LX_OK)
        return st;
    uint8_t *dst = malloc(decoded ? decoded : 1);
    if (!dst)
        return lx_json_fail(LX_ERR_NOMEM, r->file, who, "out of memory for %zu bytes", decoded);
    int rc = attributes  ? meshopt_decodeVertexBuffer(dst, count, stride, src + offset, length)
             : triangles ? meshopt_decodeIndexBuffer(dst, count, stride, src + offset, length)
                         : meshopt_decodeIndexSequence(dst, count, stride, src + offset, length);
    if (rc != 0) {
        free(dst);
        return lx_json_fail(LX_ERR_FORMAT, r->file, who, "the %s data does not decode (%d)", mode,
                            rc);
    }
    if (f == 1)
        meshopt_decodeFilterOct(dst, count, stride);
    else if (f == 2)
        meshopt_decodeFilterQuat(dst, count, stride);
    else if (f == 3)
        meshopt_decodeFilterExp(dst, count, stride);
    size_t at;
    st = out_append(r, dst, decoded, &at);
    free(dst);
    if (st != LX_OK)
        return st;
    set_number(view, "buffer", 0);
    set_number(view, "byteOffset", (double)at);
    r->rewritten_view[v] = true;
    cJSON *exts = cJSON_GetObjectItemCaseSensitive(view, "extensions");
    cJSON_DeleteItemFromObjectCaseSensitive(exts, "EXT_meshopt_compression");
    if (!exts->child)
        cJSON_DeleteItemFromObjectCaseSensitive(view, "extensions");
    return LX_OK;
}

/* ---- KHR_mesh_quantization -------------------------------------------------- */

static int type_components(const char *type)
{
    static const char *const names[] = {"SCALAR", "VEC2", "VEC3", "VEC4"};
    for (int i = 0; i < 4; i++)
        if (type && strcmp(type, names[i]) == 0)
            return i + 1;
    return 0;
}

/* One component as float: normalized integers as the glTF 2.0 spec maps
 * them (signed: max(c / (2^(b-1) - 1), -1); unsigned: c / (2^b - 1)). */
static float component(const uint8_t *p, int type, bool normalized)
{
    switch (type) {
    case 5120: {
        int8_t c = (int8_t)p[0];
        return normalized ? fmaxf((float)c / 127.0f, -1.0f) : (float)c;
    }
    case 5121:
        return normalized ? (float)p[0] / 255.0f : (float)p[0];
    case 5122: {
        int16_t c = (int16_t)(uint16_t)(p[0] | p[1] << 8);
        return normalized ? fmaxf((float)c / 32767.0f, -1.0f) : (float)c;
    }
    case 5123: {
        uint16_t c = (uint16_t)(p[0] | p[1] << 8);
        return normalized ? (float)c / 65535.0f : (float)c;
    }
    default: {
        float x;
        memcpy(&x, p, 4);
        return x;
    }
    }
}

static lx_status convert_accessor(rewrite *r, size_t a, cJSON *acc)
{
    char who[48];
    snprintf(who, sizeof who, "accessor %zu", a);
    if (!cJSON_IsObject(acc))
        return lx_json_fail(LX_ERR_FORMAT, r->file, who, "is not an object");
    int type = (int)cJSON_GetNumberValue(lx_gltf_get(acc, "componentType"));
    int comps = type_components(lx_gltf_get_string(acc, "type"));
    size_t count, offset, view;
    int csize = type == 5120 || type == 5121 ? 1 : type == 5122 || type == 5123 ? 2 : 0;
    if (!csize || !comps || !get_size(acc, "count", SIZE_MAX, &count) || count == SIZE_MAX ||
        count > UINT32_MAX || !get_size(acc, "byteOffset", 0, &offset))
        return lx_json_fail(LX_ERR_FORMAT, r->file, who,
                            "a quantized vertex attribute needs componentType 5120..5123, a type "
                            "and a count");
    if (lx_gltf_get(acc, "sparse"))
        return lx_json_fail(LX_ERR_UNSUPPORTED, r->file, who,
                            "sparse quantized attributes are not read");
    bool normalized = cJSON_IsTrue(lx_gltf_get(acc, "normalized"));
    size_t elem = (size_t)csize * (size_t)comps, floats;
    if (!lx_size_mul(count, (size_t)comps, sizeof(float), &floats))
        return lx_json_fail(LX_ERR_FORMAT, r->file, who, "count %zu is too large", count);
    char what[64];
    snprintf(what, sizeof what, "converting accessor %zu", a);
    lx_status st = lx_check_memory(floats, what);
    if (st != LX_OK)
        return st;
    float *out = calloc(floats ? floats : 1, 1);
    if (!out)
        return lx_json_fail(LX_ERR_NOMEM, r->file, who, "out of memory");
    const cJSON *vref = lx_gltf_get(acc, "bufferView");
    if (vref) { /* no bufferView: all zeros */
        const uint8_t *data;
        size_t size, stride;
        if (!lx_gltf_index(vref, r->view_count, &view))
            st = lx_json_fail(LX_ERR_FORMAT, r->file, who, "bufferView is not a valid index");
        else
            st = view_bytes(r, view, &data, &size, &stride);
        if (st == LX_OK) {
            if (!stride)
                stride = elem;
            if (count && (offset > size || elem > size - offset ||
                          (count - 1) > (size - offset - elem) / stride))
                st = lx_json_fail(LX_ERR_FORMAT, r->file, who,
                                  "%zu elements of %zu bytes (stride %zu) from byte %zu run past "
                                  "bufferView %zu (%zu bytes)",
                                  count, elem, stride, offset, view, size);
            for (size_t i = 0; st == LX_OK && i < count; i++)
                for (int k = 0; k < comps; k++)
                    out[i * comps + k] =
                        component(data + offset + i * stride + (size_t)k * csize, type, normalized);
        }
    }
    size_t at = 0;
    if (st == LX_OK)
        st = out_append(r, out, floats, &at);
    if (st != LX_OK) {
        free(out);
        return st;
    }
    /* a new bufferView, tightly packed, in the new chunk */
    cJSON *views = cJSON_GetObjectItemCaseSensitive(r->root, "bufferViews");
    if (!cJSON_IsArray(views)) {
        /* accessors without views (all zeros): the list starts here */
        cJSON_DeleteItemFromObjectCaseSensitive(r->root, "bufferViews");
        views = cJSON_AddArrayToObject(r->root, "bufferViews");
    }
    cJSON *nv = cJSON_CreateObject();
    cJSON_AddNumberToObject(nv, "buffer", 0);
    cJSON_AddNumberToObject(nv, "byteOffset", (double)at);
    cJSON_AddNumberToObject(nv, "byteLength", (double)floats);
    if (!views || !cJSON_AddItemToArray(views, nv)) {
        cJSON_Delete(nv);
        free(out);
        return lx_json_fail(LX_ERR_NOMEM, r->file, who, "out of memory");
    }
    set_number(acc, "bufferView", (double)(r->view_count + r->added++));
    set_number(acc, "byteOffset", 0);
    set_number(acc, "componentType", 5126);
    cJSON_DeleteItemFromObjectCaseSensitive(acc, "normalized");
    /* bounds as floats: min/max of the values (POSITION needs them) */
    cJSON_DeleteItemFromObjectCaseSensitive(acc, "min");
    cJSON_DeleteItemFromObjectCaseSensitive(acc, "max");
    if (count) {
        cJSON *lo = cJSON_AddArrayToObject(acc, "min"), *hi = cJSON_AddArrayToObject(acc, "max");
        for (int k = 0; k < comps; k++) {
            float a0 = out[k], b0 = out[k];
            for (size_t i = 1; i < count; i++) {
                a0 = fminf(a0, out[i * comps + k]);
                b0 = fmaxf(b0, out[i * comps + k]);
            }
            cJSON_AddItemToArray(lo, cJSON_CreateNumber(a0));
            cJSON_AddItemToArray(hi, cJSON_CreateNumber(b0));
        }
    }
    free(out);
    return LX_OK;
}

/* Marks the quantized (integer componentType) accessors of one attributes
 * object: POSITION, NORMAL, TANGENT, TEXCOORD_n and COLOR_n. */
static size_t mark_attributes(const cJSON *attrs, const cJSON *const *accessors, size_t n,
                              bool *mark)
{
    static const char *const names[] = {"POSITION", "NORMAL", "TANGENT"};
    size_t found = 0;
    for (const cJSON *at = cJSON_IsObject(attrs) ? attrs->child : NULL; at; at = at->next) {
        bool wanted = strncmp(at->string, "TEXCOORD_", 9) == 0 || strncmp(at->string, "COLOR_", 6) == 0;
        for (int k = 0; k < 3 && !wanted; k++)
            wanted = strcmp(at->string, names[k]) == 0;
        size_t a;
        if (!wanted || !lx_gltf_index(at, n, &a) || mark[a])
            continue;
        const cJSON *ct = lx_gltf_get(accessors[a], "componentType");
        if (cJSON_IsNumber(ct) && ct->valuedouble != 5126) {
            mark[a] = true;
            found++;
        }
    }
    return found;
}

/* Marks the quantized accessors primitives and their morph targets use
 * (assimp reads all of them). */
static size_t find_quantized(const cJSON *root, const cJSON *const *accessors, size_t n,
                             bool *mark)
{
    size_t found = 0;
    const cJSON *meshes = lx_gltf_get(root, "meshes");
    for (const cJSON *m = cJSON_IsArray(meshes) ? meshes->child : NULL; m; m = m->next) {
        const cJSON *prims = lx_gltf_get(m, "primitives");
        for (const cJSON *p = cJSON_IsArray(prims) ? prims->child : NULL; p; p = p->next) {
            found += mark_attributes(lx_gltf_get(p, "attributes"), accessors, n, mark);
            const cJSON *targets = lx_gltf_get(p, "targets");
            for (const cJSON *t = cJSON_IsArray(targets) ? targets->child : NULL; t; t = t->next)
                found += mark_attributes(t, accessors, n, mark);
        }
    }
    return found;
}

/* ---- the GLB out -------------------------------------------------------------- */

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

/* New buffers: 0 is the new chunk (the file's own chunk at its start);
 * buffers with a uri that a bufferView still reads follow. */
static lx_status remap_buffers(rewrite *r)
{
    size_t n = r->buffer_count;
    long *map = malloc((n ? n : 1) * sizeof *map);
    bool *used = calloc(n ? n : 1, 1);
    if (!map || !used) {
        free(map);
        free(used);
        return failf(r->file, LX_ERR_NOMEM, "out of memory");
    }
    for (size_t v = 0; v < r->view_count; v++) {
        size_t b;
        if (!r->rewritten_view[v] && lx_gltf_index(lx_gltf_get(r->views[v], "buffer"), n, &b))
            used[b] = true;
    }
    cJSON *old = cJSON_DetachItemFromObjectCaseSensitive(r->root, "buffers");
    cJSON *list = cJSON_CreateArray();
    cJSON *chunk = cJSON_CreateObject();
    cJSON_AddItemToArray(list, chunk);
    long next = 1;
    lx_status st = LX_OK;
    for (size_t i = 0; i < n; i++) {
        cJSON *b = cJSON_GetArrayItem(old, (int)i);
        const char *uri = lx_gltf_get_string(b, "uri");
        map[i] = -1;
        if (!used[i])
            continue;
        if (!uri && i == 0 && r->bin)
            map[i] = 0;
        else if (uri) {
            map[i] = next++;
            cJSON_AddItemToArray(list, cJSON_Duplicate(b, true));
        } else {
            st = failf(r->file, LX_ERR_FORMAT, "buffer %zu has no data (no uri) but a bufferView "
                       "reads it", i);
        }
    }
    cJSON_AddNumberToObject(chunk, "byteLength", (double)r->out_size);
    cJSON_AddItemToObject(r->root, "buffers", list);
    cJSON_Delete(old);
    for (size_t v = 0; st == LX_OK && v < r->view_count; v++) {
        size_t b;
        if (!r->rewritten_view[v] && lx_gltf_index(lx_gltf_get(r->views[v], "buffer"), n, &b))
            set_number((cJSON *)r->views[v], "buffer", (double)map[b]);
    }
    free(map);
    free(used);
    return st;
}

static lx_status write_glb(rewrite *r, uint8_t **glb, size_t *glb_size)
{
    char *json = cJSON_PrintUnformatted(r->root);
    if (!json)
        return failf(r->file, LX_ERR_NOMEM, "out of memory writing the rewritten JSON");
    size_t jn = strlen(json), jpad = (jn + 3) / 4 * 4, bpad = (r->out_size + 3) / 4 * 4;
    size_t total = 12 + 8 + jpad + 8 + bpad;
    if (total > UINT32_MAX) {
        free(json);
        return failf(r->file, LX_ERR_UNSUPPORTED, "the decoded file would exceed 4 GiB");
    }
    uint8_t *g = malloc(total);
    if (!g) {
        free(json);
        return failf(r->file, LX_ERR_NOMEM, "out of memory for %zu bytes", total);
    }
    memcpy(g, "glTF", 4);
    put32(g + 4, 2);
    put32(g + 8, (uint32_t)total);
    put32(g + 12, (uint32_t)jpad);
    memcpy(g + 16, "JSON", 4);
    memcpy(g + 20, json, jn);
    memset(g + 20 + jn, ' ', jpad - jn);
    uint8_t *b = g + 20 + jpad;
    put32(b, (uint32_t)bpad);
    memcpy(b + 4, "BIN\0", 4);
    if (r->out_size)
        memcpy(b + 8, r->out, r->out_size);
    memset(b + 8 + r->out_size, 0, bpad - r->out_size);
    free(json);
    *glb = g;
    *glb_size = total;
    return LX_OK;
}

/* The GLB's binary chunk (the second chunk, when it is "BIN\0"). */
static void find_bin(const uint8_t *file, size_t size, const uint8_t **bin, size_t *bin_size)
{
    *bin = NULL;
    *bin_size = 0;
    if (size < 20 || memcmp(file, "glTF", 4) != 0)
        return;
    uint64_t json_len = file[12] | (uint32_t)file[13] << 8 | (uint32_t)file[14] << 16 |
                        (uint32_t)file[15] << 24;
    uint64_t at = 20 + json_len;
    if (at + 8 > size)
        return;
    uint64_t len = file[at] | (uint32_t)file[at + 1] << 8 | (uint32_t)file[at + 2] << 16 |
                   (uint32_t)file[at + 3] << 24;
    if (memcmp(file + at + 4, "BIN\0", 4) != 0 || len > size - at - 8)
        return;
    *bin = file + at + 8;
    *bin_size = (size_t)len;
}

/* The rewrite; quantized: KHR_mesh_quantization's accessors converted to
 * floats too (for assimp), else left as they are (for a file written
 * again). */
static lx_status rewrite_file(const char *path, cJSON *root, bool quantized_too, uint8_t **glb,
                              size_t *glb_size)
{
    *glb = NULL;
    *glb_size = 0;
    lx_status range = lx_gltf_check_ranges(path, root);
    if (range != LX_OK)
        return range;
    cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "bufferViews");
    cJSON *accessors = cJSON_GetObjectItemCaseSensitive(root, "accessors");
    rewrite r = {.file = path, .root = root};
    bool meshopt = false;
    for (const cJSON *v = cJSON_IsArray(views) ? views->child : NULL; v; v = v->next, r.view_count++)
        meshopt |= lx_gltf_get(lx_gltf_get(v, "extensions"), "EXT_meshopt_compression") != NULL;
    size_t n_acc = 0;
    for (const cJSON *a = cJSON_IsArray(accessors) ? accessors->child : NULL; a; a = a->next)
        n_acc++;
    const cJSON **acc = malloc((n_acc ? n_acc : 1) * sizeof *acc);
    bool *quantized = calloc(n_acc ? n_acc : 1, 1);
    if (!acc || !quantized) {
        free(acc);
        free(quantized);
        return failf(path, LX_ERR_NOMEM, "out of memory");
    }
    n_acc = 0;
    for (const cJSON *a = cJSON_IsArray(accessors) ? accessors->child : NULL; a; a = a->next)
        acc[n_acc++] = a;
    size_t n_quantized = quantized_too ? find_quantized(root, acc, n_acc, quantized) : 0;
    if (!meshopt && !n_quantized) {
        free(acc);
        free(quantized);
        return LX_OK;
    }
    lx_status st = LX_OK;
    char *file = NULL;
    size_t file_size = 0;
    const cJSON *buffers = lx_gltf_get(root, "buffers");
    for (const cJSON *b = cJSON_IsArray(buffers) ? buffers->child : NULL; b; b = b->next)
        r.buffer_count++;
    r.folder = lx_path_dirname(path);
    r.buffers = calloc(r.buffer_count ? r.buffer_count : 1, sizeof *r.buffers);
    r.views = malloc((r.view_count ? r.view_count : 1) * sizeof *r.views);
    r.rewritten_view = calloc(r.view_count + 1, 1);
    if (!r.folder || !r.buffers || !r.views || !r.rewritten_view)
        st = failf(path, LX_ERR_NOMEM, "out of memory");
    if (st == LX_OK && lx_gltf_sniff(path) == LX_GLTF_GLB) {
        st = lx_read_file(path, BUFFER_MAX, &file, &file_size);
        if (st == LX_OK)
            find_bin((const uint8_t *)file, file_size, &r.bin, &r.bin_size);
    }
    size_t i = 0;
    for (const cJSON *v = cJSON_IsArray(views) ? views->child : NULL; st == LX_OK && v; v = v->next)
        r.views[i++] = v;
    /* the file's own chunk first, so the views into it keep their offsets */
    size_t at;
    if (st == LX_OK && r.bin)
        st = out_append(&r, r.bin, r.bin_size, &at);
    for (size_t v = 0; st == LX_OK && v < r.view_count; v++) {
        const cJSON *ext =
            lx_gltf_get(lx_gltf_get(r.views[v], "extensions"), "EXT_meshopt_compression");
        if (ext)
            st = decode_meshopt(&r, v, (cJSON *)r.views[v], ext);
    }
    for (size_t a = 0; st == LX_OK && a < n_acc; a++) {
        if (!quantized[a])
            continue;
        st = convert_accessor(&r, a, (cJSON *)acc[a]);
    }
    if (st == LX_OK)
        st = remap_buffers(&r);
    if (st == LX_OK) {
        /* nothing left for a reader to decode */
        static const char *const lists[] = {"extensionsUsed", "extensionsRequired"};
        for (int l = 0; l < 2; l++) {
            cJSON *list = cJSON_GetObjectItemCaseSensitive(root, lists[l]);
            int k = 0;
            for (cJSON *e = cJSON_IsArray(list) ? list->child : NULL; e; k++) {
                cJSON *next = e->next;
                if (cJSON_IsString(e) &&
                    (strcmp(e->valuestring, "EXT_meshopt_compression") == 0 ||
                     (quantized_too && strcmp(e->valuestring, "KHR_mesh_quantization") == 0))) {
                    cJSON_DeleteItemFromArray(list, k);
                    k--;
                }
                e = next;
            }
            /* an empty list is invalid glTF (the validator's EMPTY_ENTITY) */
            if (cJSON_IsArray(list) && !list->child)
                cJSON_DeleteItemFromObjectCaseSensitive(root, lists[l]);
        }
        st = write_glb(&r, glb, glb_size);
    }
    for (size_t b = 0; b < r.buffer_count && r.buffers; b++)
        if (r.buffers[b].owned)
            free(r.buffers[b].data);
    free(r.buffers);
    free(r.views);
    free(r.rewritten_view);
    free(r.folder);
    free(r.out);
    free(file);
    free(acc);
    free(quantized);
    return st;
}

lx_status lx_gltf_rewrite(const char *path, cJSON *root, uint8_t **glb, size_t *glb_size)
{
    return rewrite_file(path, root, true, glb, glb_size);
}

lx_status lx_gltf_decode_meshopt(const char *path, cJSON *root, uint8_t **glb, size_t *glb_size)
{
    return rewrite_file(path, root, false, glb, glb_size);
}
