/* The binary side of glTF 2.0 for the GLB writer (glTF 2.0 spec: 3.6
 * Buffers, buffer views and accessors, including sparse accessors; 4.4
 * the GLB container; RFC 2397 data: URIs with RFC 4648 base64; RFC 3986
 * percent-encoding of relative URIs). */
#include "gltf_data.h"
#include "core/internal.h"
#include "gltf_json.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LX_GLTF_FILE_MAX ((size_t)1 << 31)

size_t lx_gl_component_size(int t)
{
    switch (t) {
    case LX_GL_BYTE:
    case LX_GL_UNSIGNED_BYTE:
        return 1;
    case LX_GL_SHORT:
    case LX_GL_UNSIGNED_SHORT:
        return 2;
    case LX_GL_UNSIGNED_INT:
    case LX_GL_FLOAT:
        return 4;
    default:
        return 0;
    }
}

int lx_gl_type_components(const char *type)
{
    static const struct {
        const char *name;
        int n;
    } types[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
                 {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
    for (size_t i = 0; type && i < sizeof types / sizeof types[0]; i++)
        if (strcmp(type, types[i].name) == 0)
            return types[i].n;
    return 0;
}

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* f->bin: the binary chunk of f->bytes when they are a GLB (its JSON
 * chunk checked by the read), else NULL. */
static lx_status find_bin(lx_gltf_file *f)
{
    f->bin = NULL;
    f->bin_size = 0;
    size_t size = f->size;
    if (size >= 12 && memcmp(f->bytes, "glTF", 4) == 0) {
        /* a BIN chunk may follow the JSON */
        uint64_t length = le32(f->bytes + 8);
        uint64_t pos = 20 + (uint64_t)le32(f->bytes + 12);
        pos = (pos + 3) & ~(uint64_t)3;
        if (length <= size && pos + 8 <= length) {
            uint64_t len = le32(f->bytes + pos);
            if (le32(f->bytes + pos + 4) == 0x004E4942u) { /* "BIN\0" */
                if (len > length - pos - 8)
                    return lx_fail(LX_ERR_FORMAT,
                                   "%s: truncated GLB: the binary chunk of %llu bytes runs past "
                                   "the end",
                                   f->path, (unsigned long long)len);
                f->bin = f->bytes + pos + 8;
                f->bin_size = (size_t)len;
            }
        }
    }
    return LX_OK;
}

lx_status lx_gltf_file_adopt_glb(lx_gltf_file *f, uint8_t *glb, size_t size)
{
    free(f->bytes);
    f->bytes = glb;
    f->size = size;
    return find_bin(f);
}

lx_status lx_gltf_file_open(const char *path, lx_gltf_file *f)
{
    memset(f, 0, sizeof *f);
    f->path = path;
    char *bytes;
    size_t size;
    lx_status st = lx_read_file(path, LX_GLTF_FILE_MAX, &bytes, &size);
    if (st != LX_OK)
        return st;
    f->bytes = (uint8_t *)bytes;
    f->size = size;
    st = lx_gltf_json_read_memory(path, bytes, size, &f->root);
    if (st != LX_OK)
        return st;
    if ((st = find_bin(f)) != LX_OK)
        return st;
    f->folder = lx_path_dirname(path);
    if (!f->folder)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    if (!lx_gltf_is_v2(f->root))
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: not glTF 2.0 (asset.version)", path);
    return LX_OK;
}

void lx_gltf_file_close(lx_gltf_file *f)
{
    for (size_t i = 0; i < f->buffer_count; i++)
        if (f->buffer_owned[i])
            free(f->buffers[i]);
    free(f->buffers);
    free(f->buffer_sizes);
    free(f->buffer_owned);
    cJSON_Delete(f->root);
    free(f->bytes);
    free(f->folder);
    memset(f, 0, sizeof *f);
}

static int b64_value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z')
        return c - 'A';
    if (c >= 'a' && c <= 'z')
        return c - 'a' + 26;
    if (c >= '0' && c <= '9')
        return c - '0' + 52;
    if (c == '+' || c == '-')
        return 62;
    if (c == '/' || c == '_')
        return 63;
    return -1;
}

int lx_gltf_base64_decode(const char *s, size_t n, uint8_t **out, size_t *size)
{
    while (n && (s[n - 1] == '=' || s[n - 1] == '\n' || s[n - 1] == '\r'))
        n--;
    uint8_t *d = malloc(n / 4 * 3 + 3);
    if (!d)
        return -1;
    size_t k = 0;
    uint32_t acc = 0;
    int bits = 0;
    for (size_t i = 0; i < n; i++) {
        int v = b64_value((unsigned char)s[i]);
        if (v < 0) {
            free(d);
            return 0;
        }
        acc = acc << 6 | (uint32_t)v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            d[k++] = (uint8_t)(acc >> bits);
        }
    }
    *out = d;
    *size = k;
    return 1;
}

static int hex_value(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

lx_status lx_gltf_uri_read(const lx_gltf_file *f, const char *uri, const char *what,
                           uint8_t **out, size_t *size, char **mime)
{
    *out = NULL;
    *size = 0;
    if (mime)
        *mime = NULL;
    if (strncmp(uri, "data:", 5) == 0) {
        const char *comma = strchr(uri, ',');
        if (!comma)
            return lx_fail(LX_ERR_FORMAT, "%s: %s: data: URI without a ','", f->path, what);
        size_t head = (size_t)(comma - uri);
        if (head < 12 || strncmp(comma - 7, ";base64", 7) != 0)
            return lx_fail(LX_ERR_UNSUPPORTED, "%s: %s: data: URI is not base64", f->path, what);
        if (lx_gltf_base64_decode(comma + 1, strlen(comma + 1), out, size) != 1)
            return lx_fail(LX_ERR_FORMAT, "%s: %s: data: URI holds malformed base64", f->path,
                           what);
        if (mime) {
            const char *semi = memchr(uri + 5, ';', head - 5);
            size_t len = (size_t)((semi ? semi : comma) - (uri + 5));
            *mime = malloc(len + 1);
            if (*mime) {
                memcpy(*mime, uri + 5, len);
                (*mime)[len] = '\0';
            }
        }
        return LX_OK;
    }
    if (strstr(uri, "://"))
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: %s: URI '%s' is not a relative file path", f->path,
                       what, uri);
    size_t n = strlen(uri);
    char *name = malloc(n + 1);
    if (!name)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", f->path);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        int hi, lo;
        if (uri[i] == '%' && i + 2 < n && (hi = hex_value(uri[i + 1])) >= 0 &&
            (lo = hex_value(uri[i + 2])) >= 0) {
            name[k++] = (char)(hi * 16 + lo);
            i += 2;
        } else {
            name[k++] = uri[i];
        }
    }
    name[k] = '\0';
    char *path = lx_path_join(f->folder, name);
    free(name);
    if (!path)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", f->path);
    /* checked at lx_scene_load too; the file may have changed since */
    lx_status st = lx_path_confine(f->path, what, uri, f->folder, path, f->allow_any_path);
    if (st != LX_OK) {
        free(path);
        return st;
    }
    char *bytes;
    st = lx_read_file(path, LX_GLTF_FILE_MAX, &bytes, size);
    if (st != LX_OK) {
        st = lx_fail(st, "%s: %s: cannot read '%s'", f->path, what, path);
        free(path);
        return st;
    }
    free(path);
    *out = (uint8_t *)bytes;
    return LX_OK;
}

lx_status lx_gltf_file_buffers(lx_gltf_file *f)
{
    const cJSON *buffers = lx_gltf_get(f->root, "buffers");
    size_t n = cJSON_IsArray(buffers) ? (size_t)cJSON_GetArraySize(buffers) : 0;
    f->buffers = calloc(n ? n : 1, sizeof *f->buffers);
    f->buffer_sizes = calloc(n ? n : 1, sizeof *f->buffer_sizes);
    f->buffer_owned = calloc(n ? n : 1, sizeof *f->buffer_owned);
    if (!f->buffers || !f->buffer_sizes || !f->buffer_owned)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", f->path);
    f->buffer_count = n;
    size_t i = 0;
    for (const cJSON *b = buffers ? buffers->child : NULL; b; b = b->next, i++) {
        char what[64];
        snprintf(what, sizeof what, "buffer %zu", i);
        float len_f;
        const cJSON *len = lx_gltf_get(b, "byteLength");
        if (!lx_gltf_number(len, &len_f) || len->valuedouble < 1 ||
            len->valuedouble != floor(len->valuedouble) || len->valuedouble > 9e15)
            return lx_fail(LX_ERR_FORMAT, "%s: %s: byteLength is not a positive integer", f->path,
                           what);
        size_t want = (size_t)len->valuedouble;
        const char *uri = lx_gltf_get_string(b, "uri");
        uint8_t *data = NULL;
        size_t size = 0;
        if (!uri) {
            if (i != 0 || !f->bin)
                return lx_fail(LX_ERR_UNSUPPORTED,
                               "%s: %s has no uri and is not a GLB's binary chunk", f->path,
                               what);
            data = (uint8_t *)f->bin;
            size = f->bin_size;
        } else {
            lx_status st = lx_gltf_uri_read(f, uri, what, &data, &size, NULL);
            if (st != LX_OK)
                return st;
            f->buffer_owned[i] = true;
        }
        f->buffers[i] = data;
        f->buffer_sizes[i] = size;
        if (size < want)
            return lx_fail(LX_ERR_FORMAT, "%s: %s: byteLength is %zu but the data has %zu bytes",
                           f->path, what, want, size);
        f->buffer_sizes[i] = want;
    }
    return LX_OK;
}

/* A non-negative integer member (absent: dflt). */
static bool get_size(const cJSON *obj, const char *key, size_t dflt, size_t *out)
{
    const cJSON *v = lx_gltf_get(obj, key);
    if (!v) {
        *out = dflt;
        return true;
    }
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0) || v->valuedouble > 9e15 ||
        v->valuedouble != floor(v->valuedouble))
        return false;
    *out = (size_t)v->valuedouble;
    return true;
}

/* The bytes of bufferView vi: *base and its length, its stride (0: none). */
static lx_status view_bytes(const lx_gltf_file *f, size_t vi, const uint8_t **base, size_t *len,
                            size_t *stride)
{
    const cJSON *views = lx_gltf_get(f->root, "bufferViews");
    const cJSON *v = cJSON_GetArrayItem(views, (int)vi);
    size_t buf, off, n;
    if (!cJSON_IsObject(v) || !get_size(v, "buffer", SIZE_MAX, &buf) ||
        buf >= f->buffer_count || !get_size(v, "byteOffset", 0, &off) ||
        !get_size(v, "byteLength", SIZE_MAX, &n) || n == SIZE_MAX ||
        !get_size(v, "byteStride", 0, stride))
        return lx_fail(LX_ERR_FORMAT, "%s: bufferView %zu is malformed", f->path, vi);
    if (off > f->buffer_sizes[buf] || n > f->buffer_sizes[buf] - off)
        return lx_fail(LX_ERR_FORMAT, "%s: bufferView %zu runs past its buffer", f->path, vi);
    *base = f->buffers[buf] + off;
    *len = n;
    return LX_OK;
}

void lx_gltf_array_free(lx_gltf_array *a)
{
    free(a->data);
    memset(a, 0, sizeof *a);
}

lx_status lx_gltf_accessor_read(const lx_gltf_file *f, size_t index, lx_gltf_array *out)
{
    memset(out, 0, sizeof *out);
    const cJSON *acc = cJSON_GetArrayItem(lx_gltf_get(f->root, "accessors"), (int)index);
    const char *type = lx_gltf_get_string(acc, "type");
    const cJSON *ct = lx_gltf_get(acc, "componentType");
    size_t count, off, view = SIZE_MAX;
    if (!cJSON_IsObject(acc) || !type || !cJSON_IsNumber(ct) ||
        !get_size(acc, "count", SIZE_MAX, &count) || count == SIZE_MAX ||
        !get_size(acc, "byteOffset", 0, &off) || !get_size(acc, "bufferView", SIZE_MAX, &view))
        return lx_fail(LX_ERR_FORMAT, "%s: accessor %zu is malformed", f->path, index);
    out->component_type = ct->valueint;
    out->components = lx_gl_type_components(type);
    size_t cs = lx_gl_component_size(out->component_type);
    if (!cs || !out->components)
        return lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: unknown type %s or componentType %d",
                       f->path, index, type, out->component_type);
    if (out->components > 4 && cs < 4)
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: accessor %zu: matrices of %zu-byte components",
                       f->path, index, cs);
    snprintf(out->type, sizeof out->type, "%s", type);
    out->normalized = cJSON_IsTrue(lx_gltf_get(acc, "normalized"));
    out->elem = cs * (size_t)out->components;
    out->count = count;
    size_t total;
    if (!lx_size_mul(count, out->elem, 1, &total) || total > LX_GLTF_FILE_MAX)
        return lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: count %zu is too large", f->path, index,
                       count);
    out->data = calloc(total ? total : 1, 1);
    if (!out->data)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory reading accessor %zu", f->path, index);
    if (view != SIZE_MAX) {
        const uint8_t *base;
        size_t len, stride;
        lx_status st = view_bytes(f, view, &base, &len, &stride);
        if (st != LX_OK) {
            lx_gltf_array_free(out);
            return st;
        }
        if (!stride)
            stride = out->elem;
        if (count && (off > len || (count - 1) > (len - off) / stride ||
                      (count - 1) * stride + out->elem > len - off)) {
            lx_gltf_array_free(out);
            return lx_fail(LX_ERR_FORMAT, "%s: accessor %zu runs past bufferView %zu", f->path,
                           index, view);
        }
        for (size_t i = 0; i < count; i++)
            memcpy(out->data + i * out->elem, base + off + i * stride, out->elem);
    }
    const cJSON *sparse = lx_gltf_get(acc, "sparse");
    if (sparse) {
        const cJSON *si = lx_gltf_get(sparse, "indices"), *sv = lx_gltf_get(sparse, "values");
        size_t n, iv, io, vv, vo;
        const cJSON *ict = lx_gltf_get(si, "componentType");
        lx_status st = LX_OK;
        if (!get_size(sparse, "count", SIZE_MAX, &n) || n == SIZE_MAX || n > count ||
            !get_size(si, "bufferView", SIZE_MAX, &iv) || !get_size(si, "byteOffset", 0, &io) ||
            !get_size(sv, "bufferView", SIZE_MAX, &vv) || !get_size(sv, "byteOffset", 0, &vo) ||
            !cJSON_IsNumber(ict))
            st = lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: malformed sparse", f->path, index);
        const uint8_t *ib = NULL, *vb = NULL;
        size_t il, vl, stride;
        size_t ics = st == LX_OK ? lx_gl_component_size(ict->valueint) : 0;
        if (st == LX_OK && (ics < 1 || ict->valueint == LX_GL_FLOAT))
            st = lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: sparse indices type", f->path, index);
        if (st == LX_OK)
            st = view_bytes(f, iv, &ib, &il, &stride);
        if (st == LX_OK)
            st = view_bytes(f, vv, &vb, &vl, &stride);
        if (st == LX_OK && (io > il || n > (il - io) / ics || vo > vl || n > (vl - vo) / out->elem))
            st = lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: sparse data runs past its view",
                         f->path, index);
        for (size_t k = 0; st == LX_OK && k < n; k++) {
            const uint8_t *p = ib + io + k * ics;
            size_t at = ics == 1 ? p[0] : ics == 2 ? (size_t)(p[0] | p[1] << 8) : le32(p);
            if (at >= count) {
                st = lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: sparse index %zu out of range",
                             f->path, index, at);
                break;
            }
            memcpy(out->data + at * out->elem, vb + vo + k * out->elem, out->elem);
        }
        if (st != LX_OK) {
            lx_gltf_array_free(out);
            return st;
        }
    }
    return LX_OK;
}

double lx_gltf_array_get(const lx_gltf_array *a, size_t i, int c, bool dequantize)
{
    size_t cs = lx_gl_component_size(a->component_type);
    const uint8_t *p = a->data + i * a->elem + (size_t)c * cs;
    double v;
    switch (a->component_type) {
    case LX_GL_BYTE:
        v = (int8_t)p[0];
        return dequantize && a->normalized ? fmax(v / 127.0, -1.0) : v;
    case LX_GL_UNSIGNED_BYTE:
        v = p[0];
        return dequantize && a->normalized ? v / 255.0 : v;
    case LX_GL_SHORT:
        v = (int16_t)(uint16_t)(p[0] | p[1] << 8);
        return dequantize && a->normalized ? fmax(v / 32767.0, -1.0) : v;
    case LX_GL_UNSIGNED_SHORT:
        v = (uint16_t)(p[0] | p[1] << 8);
        return dequantize && a->normalized ? v / 65535.0 : v;
    case LX_GL_UNSIGNED_INT:
        return le32(p);
    default: {
        float x;
        memcpy(&x, p, 4);
        return x;
    }
    }
}

/* ---- output ----------------------------------------------------------- */

size_t lx_glb_bin_append(lx_glb_bin *b, const void *bytes, size_t size)
{
    size_t at = (b->size + 7) & ~(size_t)7;
    if (b->failed || at + size < at)
        goto bad;
    if (at + size > b->capacity) {
        size_t cap = b->capacity ? b->capacity : 1 << 16;
        while (cap < at + size)
            cap *= 2;
        uint8_t *grown = realloc(b->data, cap);
        if (!grown)
            goto bad;
        b->data = grown;
        b->capacity = cap;
    }
    memset(b->data + b->size, 0, at - b->size);
    if (size)
        memcpy(b->data + at, bytes, size);
    b->size = at + size;
    return at;
bad:
    b->failed = true;
    return 0;
}

cJSON *lx_glb_array_of(cJSON *root, const char *key)
{
    cJSON *a = cJSON_GetObjectItemCaseSensitive(root, key);
    if (!cJSON_IsArray(a)) {
        cJSON_DeleteItemFromObjectCaseSensitive(root, key);
        a = cJSON_AddArrayToObject(root, key);
    }
    return a;
}

int lx_glb_add_view(cJSON *root, lx_glb_bin *b, const void *bytes, size_t size, size_t stride,
                    int target)
{
    cJSON *views = lx_glb_array_of(root, "bufferViews");
    size_t at = lx_glb_bin_append(b, bytes, size);
    cJSON *v = cJSON_CreateObject();
    if (!views || !v) {
        b->failed = true;
        cJSON_Delete(v);
        return 0;
    }
    cJSON_AddNumberToObject(v, "buffer", 0);
    if (at)
        cJSON_AddNumberToObject(v, "byteOffset", (double)at);
    cJSON_AddNumberToObject(v, "byteLength", (double)size);
    if (stride)
        cJSON_AddNumberToObject(v, "byteStride", (double)stride);
    if (target)
        cJSON_AddNumberToObject(v, "target", target);
    cJSON_AddItemToArray(views, v);
    return cJSON_GetArraySize(views) - 1;
}

int lx_glb_add_accessor(cJSON *root, int view, int component_type, size_t count, const char *type,
                        bool normalized, const double *min, const double *max)
{
    cJSON *accs = lx_glb_array_of(root, "accessors");
    cJSON *a = cJSON_CreateObject();
    if (!accs || !a) {
        cJSON_Delete(a);
        return -1;
    }
    cJSON_AddNumberToObject(a, "bufferView", view);
    cJSON_AddNumberToObject(a, "componentType", component_type);
    if (normalized)
        cJSON_AddBoolToObject(a, "normalized", true);
    cJSON_AddNumberToObject(a, "count", (double)count);
    cJSON_AddStringToObject(a, "type", type);
    int n = lx_gl_type_components(type);
    if (min && max) {
        cJSON_AddItemToObject(a, "min", cJSON_CreateDoubleArray(min, n));
        cJSON_AddItemToObject(a, "max", cJSON_CreateDoubleArray(max, n));
    }
    cJSON_AddItemToArray(accs, a);
    return cJSON_GetArraySize(accs) - 1;
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

lx_status lx_glb_write(const char *path, cJSON *root, lx_glb_bin *b)
{
    if (b->failed)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory building the binary buffer", path);
    /* one buffer: the binary chunk (GLB 4.4.3.3), padded to 4 bytes */
    cJSON_DeleteItemFromObjectCaseSensitive(root, "buffers");
    size_t bin_len = (b->size + 3) & ~(size_t)3;
    if (b->size) {
        cJSON *buffers = cJSON_AddArrayToObject(root, "buffers");
        cJSON *buf = cJSON_CreateObject();
        if (!buffers || !buf)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
        cJSON_AddNumberToObject(buf, "byteLength", (double)b->size);
        cJSON_AddItemToArray(buffers, buf);
    }
    char *json = cJSON_PrintUnformatted(root);
    if (!json)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory printing the JSON", path);
    size_t json_len = strlen(json), json_pad = (json_len + 3) & ~(size_t)3;
    uint64_t total = 12 + 8 + (uint64_t)json_pad + (b->size ? 8 + (uint64_t)bin_len : 0);
    if (total > 0xFFFFFFFFu) {
        free(json);
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: %llu bytes do not fit a GLB (4 GiB at most)",
                       path, (unsigned long long)total);
    }
    lx_out_file out;
    lx_status st = lx_out_open(&out, path);
    if (st != LX_OK) {
        free(json);
        return st;
    }
    FILE *fp = out.fp;
    uint8_t head[20];
    memcpy(head, "glTF", 4);
    put32(head + 4, 2);
    put32(head + 8, (uint32_t)total);
    put32(head + 12, (uint32_t)json_pad);
    put32(head + 16, 0x4E4F534Au); /* "JSON" */
    bool ok = fwrite(head, 1, 20, fp) == 20 && fwrite(json, 1, json_len, fp) == json_len;
    for (size_t i = json_len; ok && i < json_pad; i++)
        ok = fputc(' ', fp) != EOF;
    if (ok && b->size) {
        put32(head, (uint32_t)bin_len);
        put32(head + 4, 0x004E4942u); /* "BIN\0" */
        ok = fwrite(head, 1, 8, fp) == 8 && fwrite(b->data, 1, b->size, fp) == b->size;
        for (size_t i = b->size; ok && i < bin_len; i++)
            ok = fputc(0, fp) != EOF;
    }
    free(json);
    if (!ok) {
        int err = errno;
        lx_out_abort(&out);
        return lx_fail(LX_ERR_IO, "%s: cannot write: %s", path, strerror(err));
    }
    return lx_out_commit(&out);
}

const char *lx_image_mime_sniff(const uint8_t *p, size_t n)
{
    if (n >= 8 && memcmp(p, "\x89PNG\r\n\x1a\n", 8) == 0)
        return "image/png";
    if (n >= 3 && p[0] == 0xFF && p[1] == 0xD8 && p[2] == 0xFF)
        return "image/jpeg";
    if (n >= 12 && memcmp(p, "RIFF", 4) == 0 && memcmp(p + 8, "WEBP", 4) == 0)
        return "image/webp";
    if (n >= 12 && memcmp(p, "\xABKTX 20\xBB\r\n\x1a\n", 12) == 0)
        return "image/ktx2";
    return NULL;
}
