/* Byte ranges of a glTF file's accessors and bufferViews checked against
 * what holds them (glTF 2.0 spec, 3.6.2.4 and 3.6.1: an accessor lies
 * within its bufferView, a bufferView within its buffer), from the JSON
 * alone, before assimp reads the file (it leaks memory on overruns).
 * An accessor without a bufferView (zeros, plus its sparse values,
 * 3.6.2.3) is not bounded by any bytes of the file: its count is checked
 * against the sparse data and the memory assimp would take for it. */
#include "core/internal.h"
#include "gltf_data.h"
#include "gltf_json.h"
#include "json_text.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* obj[key] as a non-negative integer (absent: def); false when malformed. */
static bool size_at(const cJSON *obj, const char *key, double def, double *out)
{
    const cJSON *v = lx_gltf_get(obj, key);
    *out = def;
    if (!v)
        return true;
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0) || v->valuedouble != floor(v->valuedouble))
        return false;
    *out = v->valuedouble;
    return true;
}

/* Bytes of one element (matrix columns padded to 4 bytes); 0 if unknown. */
static double element_size(const char *type, int component_type)
{
    double cs = (double)lx_gl_component_size(component_type);
    int n = type ? lx_gl_type_components(type) : 0;
    if (!cs || !n)
        return 0;
    if (strncmp(type, "MAT", 3) == 0) {
        int cols = n == 4 ? 2 : n == 9 ? 3 : 4;
        double col = cols * cs;
        return cols * (ceil(col / 4) * 4);
    }
    return n * cs;
}

/* What assimp's glTF 2.0 reader holds per byte of an accessor it fills
 * itself (no bufferView): the zero-filled data, its sparse copy and the
 * aiMesh arrays made from it. Measured: 30M VEC3 floats (360 MB of data)
 * took 2.1 GB, about 6 bytes per byte. */
#define ASSIMP_BYTES_PER_ACCESSOR_BYTE 6.0

/* One sparse block (3.6.2.3): 1 <= sparse count <= count, its indices and
 * values inside their bufferViews. */
static lx_status check_sparse(const char *path, size_t i, const cJSON *sparse, double count,
                              double elem, const cJSON *views, size_t nv)
{
    double n;
    if (!size_at(sparse, "count", 0, &n) || n < 1)
        return lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: sparse count must be at least 1", path,
                       i);
    if (n > count)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: accessor %zu: sparse count %.0f is more than the accessor's count %.0f",
                       path, i, n, count);
    const char *part[2] = {"indices", "values"};
    for (int k = 0; k < 2; k++) {
        const cJSON *block = lx_gltf_get(sparse, part[k]);
        size_t vi;
        double off, vlen, ct, size = elem;
        if (!lx_gltf_index(lx_gltf_get(block, "bufferView"), nv, &vi))
            return lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: sparse %s need a valid bufferView",
                           path, i, part[k]);
        const cJSON *view = cJSON_GetArrayItem(views, (int)vi);
        if (k == 0 && (!size_at(block, "componentType", 0, &ct) ||
                       !(size = (double)lx_gl_component_size((int)ct))))
            return lx_fail(LX_ERR_FORMAT, "%s: accessor %zu: sparse indices need a componentType",
                           path, i);
        if (!size_at(block, "byteOffset", 0, &off) || !size_at(view, "byteLength", 0, &vlen))
            continue; /* malformed: the importer names it */
        double end = off + n * size;
        if (end > vlen)
            return lx_fail(LX_ERR_FORMAT,
                           "%s: accessor %zu: sparse %s: %.0f bytes past the end of bufferView %zu",
                           path, i, part[k], end - vlen, vi);
    }
    return LX_OK;
}

/* Accessors without a bufferView: the memory assimp would fill for them,
 * all together, checked before it does. */
static lx_status check_unbacked(const char *path, const cJSON *root)
{
    const cJSON *views = lx_gltf_get(root, "bufferViews");
    size_t nv = (size_t)cJSON_GetArraySize(views);
    const cJSON *accessors = lx_gltf_get(root, "accessors");
    double total = 0, largest = 0, elements = 0;
    size_t i = 0, largest_at = 0;
    for (const cJSON *a = cJSON_IsArray(accessors) ? accessors->child : NULL; a; a = a->next, i++) {
        double count, ct;
        if (!size_at(a, "count", 0, &count) || !size_at(a, "componentType", 0, &ct))
            continue; /* malformed: the importer names it */
        double elem = element_size(lx_gltf_get_string(a, "type"), (int)ct);
        const cJSON *sparse = lx_gltf_get(a, "sparse");
        if (sparse && elem) {
            lx_status st = check_sparse(path, i, sparse, count, elem, views, nv);
            if (st != LX_OK)
                return st;
        }
        if (lx_gltf_get(a, "bufferView") || !elem)
            continue;
        double bytes = count * elem * ASSIMP_BYTES_PER_ACCESSOR_BYTE;
        total += bytes;
        if (bytes > largest) {
            largest = bytes;
            largest_at = i;
            elements = count;
        }
    }
    if (total <= 0)
        return LX_OK;
    char what[160];
    snprintf(what, sizeof what,
             "reading its accessors without a bufferView (accessor %zu: %.0f elements)",
             largest_at, elements);
    lx_status st = lx_check_memory(total >= 1.8e19 ? UINT64_MAX : (uint64_t)total, what);
    if (st != LX_OK)
        lx_error_prefix(path);
    return st;
}

lx_status lx_gltf_check_ranges(const char *path, const cJSON *root)
{
    lx_status unbacked = check_unbacked(path, root);
    if (unbacked != LX_OK)
        return unbacked;
    const cJSON *buffers = lx_gltf_get(root, "buffers");
    const cJSON *views = lx_gltf_get(root, "bufferViews");
    size_t nb = (size_t)cJSON_GetArraySize(buffers), nv = (size_t)cJSON_GetArraySize(views);
    size_t i = 0;
    for (const cJSON *v = cJSON_IsArray(views) ? views->child : NULL; v; v = v->next, i++) {
        size_t b;
        double off, len, blen;
        if (!lx_gltf_index(lx_gltf_get(v, "buffer"), nb, &b) || !size_at(v, "byteOffset", 0, &off) ||
            !size_at(v, "byteLength", 0, &len) ||
            !size_at(cJSON_GetArrayItem(buffers, (int)b), "byteLength", 0, &blen))
            continue; /* malformed: the importer names it */
        if (off + len > blen)
            return lx_fail(LX_ERR_FORMAT, "%s: bufferView %zu: %.0f bytes past the end of buffer %zu",
                           path, i, off + len - blen, b);
    }
    i = 0;
    const cJSON *accessors = lx_gltf_get(root, "accessors");
    for (const cJSON *a = cJSON_IsArray(accessors) ? accessors->child : NULL; a; a = a->next, i++) {
        size_t vi;
        double off, count, vlen, stride, ct;
        if (!lx_gltf_get(a, "bufferView") ||
            !lx_gltf_index(lx_gltf_get(a, "bufferView"), nv, &vi))
            continue;
        const cJSON *view = cJSON_GetArrayItem(views, (int)vi);
        if (!size_at(a, "byteOffset", 0, &off) || !size_at(a, "count", 0, &count) ||
            !size_at(a, "componentType", 0, &ct) || !size_at(view, "byteLength", 0, &vlen))
            continue;
        double elem = element_size(lx_gltf_get_string(a, "type"), (int)ct);
        if (!elem || count == 0 || !size_at(view, "byteStride", elem, &stride))
            continue;
        double end = off + (count - 1) * stride + elem;
        if (end > vlen)
            return lx_fail(LX_ERR_FORMAT,
                           "%s: accessor %zu: %.0f bytes past the end of bufferView %zu", path, i,
                           end - vlen, vi);
    }
    return LX_OK;
}
