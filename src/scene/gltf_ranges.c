/* Byte ranges of a glTF file's accessors and bufferViews checked against
 * what holds them (glTF 2.0 spec, 3.6.2.4 and 3.6.1: an accessor lies
 * within its bufferView, a bufferView within its buffer), from the JSON
 * alone, before assimp reads the file (it leaks memory on overruns). */
#include "core/internal.h"
#include "gltf_data.h"
#include "gltf_json.h"
#include "json_text.h"

#include <math.h>
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

lx_status lx_gltf_check_ranges(const char *path, const cJSON *root)
{
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
