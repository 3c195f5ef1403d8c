/* A glTF 2.0 file's own JSON (cJSON): the whole of a .gltf, or the JSON
 * chunk of a .glb located through its 12-byte header per the glTF 2.0
 * binary container spec; typed reads shared by the readers of what assimp
 * drops (gltf_lights.c, gltf_textures.c); and each mesh primitive's mode,
 * material and the triangles it defines (glTF 2.0 spec, 3.7.2.1 Overview
 * of primitive modes), which the importer matches to assimp's meshes to
 * notice faces assimp dropped. */
#include "gltf_json.h"
#include "core/internal.h"

#include "json_text.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A .gltf is all JSON but may embed base64 buffers: allow big files. */
#define LX_GLTF_TEXT_MAX ((size_t)1 << 30)
#define LX_GLB_MAGIC 0x46546C67u      /* "glTF" little-endian */
#define LX_GLB_CHUNK_JSON 0x4E4F534Au /* "JSON" */
#define LX_GLB_HEADER 12u
#define LX_GLB_CHUNK_HEADER 8u

#define failf(file, st, ...) lx_json_fail(st, file, NULL, __VA_ARGS__)

/* ---- the container ------------------------------------------------------ */

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Checks a GLB's header and first chunk header (head holds the first
 * head_len bytes of a file of total bytes) and finds the JSON chunk. */
static lx_status glb_locate(const char *file, const uint8_t *head, size_t head_len, uint64_t total,
                            uint64_t *json_offset, uint32_t *json_size)
{
    if (total < LX_GLB_HEADER || head_len < LX_GLB_HEADER)
        return failf(file, LX_ERR_FORMAT, "truncated GLB: %llu bytes, the header needs 12",
                     (unsigned long long)total);
    if (le32(head) != LX_GLB_MAGIC)
        return failf(file, LX_ERR_FORMAT, "not a GLB file (bad magic)");
    uint32_t version = le32(head + 4), length = le32(head + 8);
    if (version != 2)
        return failf(file, LX_ERR_UNSUPPORTED, "GLB version %u (only version 2 is supported)",
                     version);
    if (length > total)
        return failf(file, LX_ERR_FORMAT,
                     "truncated GLB: the header says %u bytes, the file has %llu", length,
                     (unsigned long long)total);
    if (length < LX_GLB_HEADER + LX_GLB_CHUNK_HEADER || head_len < 20)
        return failf(file, LX_ERR_FORMAT, "truncated GLB: %u bytes leave no room for a chunk",
                     length);
    uint32_t chunk_len = le32(head + 12), chunk_type = le32(head + 16);
    if (chunk_type != LX_GLB_CHUNK_JSON)
        return failf(file, LX_ERR_FORMAT,
                     "GLB: the first chunk has type 0x%08X, not JSON (0x4E4F534A)", chunk_type);
    if (chunk_len > length - LX_GLB_HEADER - LX_GLB_CHUNK_HEADER)
        return failf(file, LX_ERR_FORMAT,
                     "truncated GLB: the JSON chunk of %u bytes runs past the end (%u bytes)",
                     chunk_len, length);
    *json_offset = LX_GLB_HEADER + LX_GLB_CHUNK_HEADER;
    *json_size = chunk_len;
    return LX_OK;
}

static lx_status parse_json(const char *file, const char *text, size_t size, cJSON **root)
{
    *root = NULL;
    const char *nul = memchr(text, '\0', size);
    if (nul)
        return failf(file, LX_ERR_FORMAT,
                     "neither glTF JSON (NUL byte at offset %zu) nor GLB (no 'glTF' magic)",
                     (size_t)(nul - text));
    lx_status st = lx_json_parse_text(file, text, size, root);
    if (st == LX_OK && !cJSON_IsObject(*root)) {
        cJSON_Delete(*root);
        *root = NULL;
        st = failf(file, LX_ERR_FORMAT, "the top level of the glTF JSON is not an object");
    }
    return st;
}

lx_gltf_kind lx_gltf_sniff(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return LX_GLTF_NONE;
    unsigned char head[64];
    size_t n = fread(head, 1, sizeof head, fp);
    fclose(fp);
    if (n >= 4 && memcmp(head, "glTF", 4) == 0)
        return LX_GLTF_GLB;
    size_t i = n >= 3 && memcmp(head, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
    while (i < n && (head[i] == ' ' || head[i] == '\t' || head[i] == '\r' || head[i] == '\n'))
        i++;
    return i < n && head[i] == '{' ? LX_GLTF_TEXT : LX_GLTF_NONE;
}

lx_status lx_gltf_json_read_memory(const char *file, const void *bytes, size_t size, cJSON **root)
{
    *root = NULL;
    const uint8_t *b = bytes ? bytes : (const uint8_t *)"";
    if (size >= 4 && memcmp(b, "glTF", 4) == 0) {
        uint64_t off;
        uint32_t len;
        lx_status st = glb_locate(file, b, size, size, &off, &len);
        if (st != LX_OK)
            return st;
        return parse_json(file, (const char *)b + off, len, root);
    }
    return parse_json(file, (const char *)b, size, root);
}

lx_status lx_gltf_json_read(const char *path, cJSON **root)
{
    *root = NULL;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return failf(path, LX_ERR_IO, "cannot open: %s", strerror(errno));
    uint8_t head[20];
    size_t head_len = fread(head, 1, sizeof head, fp);
    if (head_len < 4 || memcmp(head, "glTF", 4) != 0) {
        /* A .gltf: all of it is JSON. */
        fclose(fp);
        char *text;
        size_t size;
        lx_status st = lx_read_file(path, LX_GLTF_TEXT_MAX, &text, &size);
        if (st != LX_OK)
            return st;
        st = parse_json(path, text, size, root);
        free(text);
        return st;
    }
    /* A .glb: read only the JSON chunk, not the binary buffers. */
    long total = -1;
    if (fseek(fp, 0, SEEK_END) == 0)
        total = ftell(fp);
    uint64_t off;
    uint32_t len;
    lx_status st = total < 0 ? failf(path, LX_ERR_IO, "cannot tell the file's size")
                             : glb_locate(path, head, head_len, (uint64_t)total, &off, &len);
    char *json = NULL;
    if (st == LX_OK && !(json = malloc(len ? len : 1)))
        st = failf(path, LX_ERR_NOMEM, "cannot allocate %u bytes for the JSON chunk", len);
    if (st == LX_OK && (fseek(fp, (long)off, SEEK_SET) != 0 || fread(json, 1, len, fp) != len))
        st = failf(path, LX_ERR_IO, "cannot read the JSON chunk");
    fclose(fp);
    if (st == LX_OK)
        st = parse_json(path, json, len, root);
    free(json);
    return st;
}

lx_status lx_glb_check_file(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return failf(path, LX_ERR_IO, "cannot open: %s", strerror(errno));
    uint8_t head[12];
    size_t got = fread(head, 1, sizeof head, fp);
    lx_status st = LX_OK;
    if (fseek(fp, 0, SEEK_END) != 0) {
        fclose(fp);
        return failf(path, LX_ERR_IO, "cannot seek");
    }
    long total = ftell(fp);
    if (got < sizeof head || total < (long)sizeof head) {
        fclose(fp);
        return failf(path, LX_ERR_FORMAT, "truncated GLB: %ld bytes, the header needs 12",
                     total < 0 ? 0L : total);
    }
    size_t lead = 0; /* white space before a web page's '<' */
    while (lead < sizeof head - 1 && (head[lead] == ' ' || head[lead] == '\n' || head[lead] == '\r' ||
                                      head[lead] == '\t'))
        lead++;
    if (le32(head) != LX_GLB_MAGIC && head[lead] == '<')
        st = failf(path, LX_ERR_FORMAT,
                   "not a GLB file: it starts with '<', as a web page does (a download that "
                   "saved the page, not the model?)");
    else if (le32(head) != LX_GLB_MAGIC)
        st = failf(path, LX_ERR_FORMAT, "not a GLB file (bad magic)");
    else if (le32(head + 4) != 2)
        st = failf(path, LX_ERR_UNSUPPORTED, "GLB version %u (only version 2 is supported)",
                   le32(head + 4));
    else if ((uint64_t)le32(head + 8) > (uint64_t)total)
        st = failf(path, LX_ERR_FORMAT, "truncated GLB: the header says %u bytes, the file has %ld",
                   le32(head + 8), total);
    /* walk the chunks: each length must fit in what the header declares */
    uint64_t length = le32(head + 8), pos = LX_GLB_HEADER;
    for (int chunk = 0; st == LX_OK && pos < length; chunk++) {
        uint8_t ch[LX_GLB_CHUNK_HEADER];
        if (length - pos < LX_GLB_CHUNK_HEADER || fseek(fp, (long)pos, SEEK_SET) != 0 ||
            fread(ch, 1, sizeof ch, fp) != sizeof ch) {
            st = failf(path, LX_ERR_FORMAT, "truncated GLB: chunk %d header is cut", chunk);
            break;
        }
        uint64_t len = le32(ch);
        if (len > length - pos - LX_GLB_CHUNK_HEADER) {
            st = failf(path, LX_ERR_FORMAT,
                       "truncated GLB: chunk %d of %llu bytes runs past the end (%llu bytes)",
                       chunk, (unsigned long long)len, (unsigned long long)length);
            break;
        }
        pos += LX_GLB_CHUNK_HEADER + len;
    }
    fclose(fp);
    return st;
}

bool lx_gltf_is_v2(const cJSON *root)
{
    const char *v = lx_gltf_get_string(lx_gltf_get(root, "asset"), "version");
    return v && v[0] == '2' && v[1] == '.';
}

/* ---- typed values --------------------------------------------------------- */

const cJSON *lx_gltf_get(const cJSON *obj, const char *key)
{
    return cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
}

const char *lx_gltf_get_string(const cJSON *obj, const char *key)
{
    const cJSON *s = lx_gltf_get(obj, key);
    return cJSON_IsString(s) && s->valuestring ? s->valuestring : NULL;
}

bool lx_gltf_number(const cJSON *item, float *out)
{
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) ||
        !isfinite((float)item->valuedouble))
        return false;
    *out = (float)item->valuedouble;
    return true;
}

bool lx_gltf_numbers(const cJSON *item, float *out, int n)
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != n)
        return false;
    int i = 0;
    for (const cJSON *e = item->child; e; e = e->next)
        if (!lx_gltf_number(e, &out[i++]))
            return false;
    return true;
}

bool lx_gltf_index(const cJSON *item, size_t count, size_t *out)
{
    if (!cJSON_IsNumber(item))
        return false;
    double v = item->valuedouble;
    if (!(v >= 0.0) || v != floor(v) || v >= (double)count)
        return false;
    *out = (size_t)v;
    return true;
}

uint32_t lx_gltf_texcoords_read(const cJSON *j)
{
    uint32_t sets = 0;
    for (const cJSON *c = j ? j->child : NULL; c; c = c->next) {
        if (c->string && strcmp(c->string, "texCoord") == 0 && cJSON_IsNumber(c) &&
            c->valuedouble >= 0 && c->valuedouble < 32 && c->valuedouble == (int)c->valuedouble)
            sets |= 1u << (int)c->valuedouble;
        if (cJSON_IsObject(c) || cJSON_IsArray(c))
            sets |= lx_gltf_texcoords_read(c);
    }
    return sets;
}

void lx_gltf_label(char *buf, size_t size, const char *what, size_t index, const cJSON *obj)
{
    const char *name = lx_gltf_get_string(obj, "name");
    if (name)
        snprintf(buf, size, "%s %zu ('%.60s')", what, index, name);
    else
        snprintf(buf, size, "%s %zu", what, index);
}

/* ---- primitives ------------------------------------------------------------ */

/* The count of accessor `ref` (an index into the n accessors), or false. */
static bool accessor_count(const cJSON *const *accessors, size_t n, const cJSON *ref,
                           uint64_t *count)
{
    size_t i;
    if (!lx_gltf_index(ref, n, &i))
        return false;
    const cJSON *c = lx_gltf_get(accessors[i], "count");
    if (!cJSON_IsNumber(c) || !(c->valuedouble >= 0.0) || c->valuedouble != floor(c->valuedouble) ||
        c->valuedouble > 4294967295.0)
        return false;
    *count = (uint64_t)c->valuedouble;
    return true;
}

void lx_gltf_primitives_free(lx_gltf_primitives *p)
{
    free(p->first);
    free(p->mesh);
    free(p->triangles);
    free(p->material);
    free(p->mode);
    memset(p, 0, sizeof *p);
}

static const cJSON *mesh_primitives(const cJSON *mesh)
{
    const cJSON *prims = lx_gltf_get(mesh, "primitives");
    return cJSON_IsArray(prims) ? prims : NULL;
}

lx_status lx_gltf_primitives_read(const char *file, const cJSON *root, lx_gltf_primitives *out)
{
    memset(out, 0, sizeof *out);
    const cJSON *meshes = lx_gltf_get(root, "meshes");
    const cJSON *acc_list = lx_gltf_get(root, "accessors");
    const cJSON *mat_list = lx_gltf_get(root, "materials");
    size_t nm = 0, n = 0;
    for (const cJSON *m = cJSON_IsArray(meshes) ? meshes->child : NULL; m; m = m->next, nm++) {
        const cJSON *prims = mesh_primitives(m);
        n += prims ? (size_t)cJSON_GetArraySize(prims) : 0;
    }
    size_t n_materials = cJSON_IsArray(mat_list) ? (size_t)cJSON_GetArraySize(mat_list) : 0;
    /* the accessors by index: cJSON's own lookup walks the list */
    size_t na = 0;
    for (const cJSON *a = cJSON_IsArray(acc_list) ? acc_list->child : NULL; a; a = a->next)
        na++;
    size_t slots = n ? n : 1;
    out->first = malloc((nm + 1) * sizeof *out->first);
    out->mesh = malloc(slots * sizeof *out->mesh);
    out->triangles = malloc(slots * sizeof *out->triangles);
    out->material = malloc(slots * sizeof *out->material);
    out->mode = malloc(slots * sizeof *out->mode);
    const cJSON **accessors = malloc((na ? na : 1) * sizeof *accessors);
    if (!out->first || !out->mesh || !out->triangles || !out->material || !out->mode ||
        !accessors) {
        free(accessors);
        lx_gltf_primitives_free(out);
        return failf(file, LX_ERR_NOMEM, "out of memory for %zu primitives", n);
    }
    na = 0;
    for (const cJSON *a = cJSON_IsArray(acc_list) ? acc_list->child : NULL; a; a = a->next)
        accessors[na++] = a;
    size_t k = 0;
    uint32_t mi = 0;
    for (const cJSON *m = cJSON_IsArray(meshes) ? meshes->child : NULL; m; m = m->next, mi++) {
        out->first[mi] = k;
        const cJSON *prims = mesh_primitives(m);
        for (const cJSON *p = prims ? prims->child : NULL; p; p = p->next, k++) {
            out->mesh[k] = mi;
            out->triangles[k] = UINT64_MAX;
            const cJSON *mat = lx_gltf_get(p, "material");
            size_t mat_index;
            if (!mat)
                out->material[k] = LX_GLTF_NO_MATERIAL;
            else if (lx_gltf_index(mat, n_materials, &mat_index))
                out->material[k] = (int64_t)mat_index;
            else
                out->material[k] = LX_GLTF_BAD_MATERIAL;
            const cJSON *mode = lx_gltf_get(p, "mode");
            size_t md = 4; /* TRIANGLES when "mode" is left out */
            if (mode && !lx_gltf_index(mode, 7, &md)) {
                out->mode[k] = -1;
                continue;
            }
            out->mode[k] = (int8_t)md;
            uint64_t c;
            const cJSON *indices = lx_gltf_get(p, "indices");
            const cJSON *ref =
                indices ? indices : lx_gltf_get(lx_gltf_get(p, "attributes"), "POSITION");
            if (!accessor_count(accessors, na, ref, &c))
                continue;
            if (md == 4) /* TRIANGLES: a trailing partial triangle is no triangle */
                out->triangles[k] = c / 3;
            else if ((md == 5 || md == 6) && c >= 3) /* TRIANGLE_STRIP, TRIANGLE_FAN */
                out->triangles[k] = c - 2;
        }
    }
    out->first[nm] = k;
    out->mesh_count = nm;
    out->count = n;
    free(accessors);
    return LX_OK;
}
