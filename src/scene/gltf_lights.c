/* glTF 2.0 KHR_lights_punctual (Khronos extension spec): point, spot and
 * directional lights defined in the root "extensions" and placed by the
 * nodes that reference them; a light shines down its node's local -Z.
 * Read from the glTF JSON directly (cJSON) because assimp drops the exact
 * fields; .glb files are located through their 12-byte header and first
 * (JSON) chunk per the glTF 2.0 binary container spec. Node world matrices
 * are T * R * S (or "matrix"), parent times child, column-major. */
#include "luxel/scene.h"
#include "core/internal.h"

#include "json_text.h"

#include <cjson/cJSON.h>
#include <errno.h>
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
    return lx_json_parse_text(file, text, size, root);
}

/* ---- typed values --------------------------------------------------------- */

/* Numbers: finite, also as a float. */
static bool number(const cJSON *item, float *out)
{
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble) ||
        !isfinite((float)item->valuedouble))
        return false;
    *out = (float)item->valuedouble;
    return true;
}

/* An array of exactly n finite numbers. */
static bool numbers(const cJSON *item, float *out, int n)
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != n)
        return false;
    int i = 0;
    for (const cJSON *e = item->child; e; e = e->next)
        if (!number(e, &out[i++]))
            return false;
    return true;
}

/* An integer index in [0, count). */
static bool index_in(const cJSON *item, size_t count, size_t *out)
{
    if (!cJSON_IsNumber(item))
        return false;
    double v = item->valuedouble;
    if (!(v >= 0.0) || v != floor(v) || v >= (double)count)
        return false;
    *out = (size_t)v;
    return true;
}

static const cJSON *get(const cJSON *obj, const char *key)
{
    return cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
}

/* The string at key, or NULL when absent or not a string. */
static const char *get_string(const cJSON *obj, const char *key)
{
    const cJSON *s = get(obj, key);
    return cJSON_IsString(s) && s->valuestring ? s->valuestring : NULL;
}

/* "node 3 ('Lamp')" for messages. */
static void label(char *buf, size_t size, const char *what, size_t index, const cJSON *obj)
{
    const char *name = get_string(obj, "name");
    if (name)
        snprintf(buf, size, "%s %zu ('%.60s')", what, index, name);
    else
        snprintf(buf, size, "%s %zu", what, index);
}

/* ---- light definitions ---------------------------------------------------- */

typedef struct def {
    lx_light light;   /* everything but name, position and direction */
    const char *name; /* the definition's own name or NULL; owned by cJSON */
} def;

static lx_status read_def(const char *file, const cJSON *obj, size_t index, def *out)
{
    char who[128];
    label(who, sizeof who, "KHR_lights_punctual light", index, obj);
    if (!cJSON_IsObject(obj))
        return failf(file, LX_ERR_FORMAT, "%s is not an object", who);
    const char *type = get_string(obj, "type");
    if (!type)
        return failf(file, LX_ERR_FORMAT, "%s: missing 'type'", who);
    lx_light_type t;
    if (strcmp(type, "point") == 0)
        t = LX_LIGHT_POINT;
    else if (strcmp(type, "spot") == 0)
        t = LX_LIGHT_SPOT;
    else if (strcmp(type, "directional") == 0)
        t = LX_LIGHT_DIRECTIONAL;
    else
        return failf(file, LX_ERR_FORMAT,
                     "%s: unknown type '%.40s' (expected point, spot or directional)", who, type);
    lx_light l = lx_light_defaults(t);
    const cJSON *it;
    float v[3];
    if ((it = get(obj, "color"))) {
        if (!numbers(it, v, 3))
            return failf(file, LX_ERR_FORMAT, "%s: color must be 3 finite numbers", who);
        if (v[0] < 0.0f || v[1] < 0.0f || v[2] < 0.0f)
            return failf(file, LX_ERR_INVALID, "%s: color has a negative component", who);
        l.color = lx_v3(v[0], v[1], v[2]);
    }
    if ((it = get(obj, "intensity"))) {
        if (!number(it, &l.intensity))
            return failf(file, LX_ERR_FORMAT, "%s: intensity must be a finite number", who);
        if (l.intensity < 0.0f)
            return failf(file, LX_ERR_INVALID, "%s: intensity %g is negative", who, l.intensity);
    }
    if ((it = get(obj, "range"))) {
        if (!number(it, &l.range))
            return failf(file, LX_ERR_FORMAT, "%s: range must be a finite number", who);
        if (!(l.range > 0.0f))
            return failf(file, LX_ERR_INVALID, "%s: range %g must be above 0", who, l.range);
    }
    if (t == LX_LIGHT_SPOT && (it = get(obj, "spot"))) {
        if (!cJSON_IsObject(it))
            return failf(file, LX_ERR_FORMAT, "%s: spot must be an object", who);
        const cJSON *a;
        if ((a = get(it, "innerConeAngle")) && !number(a, &l.inner_angle))
            return failf(file, LX_ERR_FORMAT, "%s: spot.innerConeAngle must be a finite number",
                         who);
        if ((a = get(it, "outerConeAngle")) && !number(a, &l.outer_angle))
            return failf(file, LX_ERR_FORMAT, "%s: spot.outerConeAngle must be a finite number",
                         who);
    }
    if (t == LX_LIGHT_SPOT) {
        /* pi/2 written in double rounds a hair above float pi/2. */
        if (l.outer_angle > 0.5f * LX_PI && l.outer_angle <= 0.5f * LX_PI + 1e-5f)
            l.outer_angle = 0.5f * LX_PI;
        if (l.inner_angle < 0.0f)
            return failf(file, LX_ERR_INVALID, "%s: spot.innerConeAngle %g is negative", who,
                         l.inner_angle);
        if (!(l.outer_angle > 0.0f) || l.outer_angle > 0.5f * LX_PI)
            return failf(file, LX_ERR_INVALID, "%s: spot.outerConeAngle %g is outside (0, pi/2]",
                         who, l.outer_angle);
        /* Equal angles (Blender's export) are fine: a hard-edged cone. */
        if (l.inner_angle > l.outer_angle)
            return failf(file, LX_ERR_INVALID,
                         "%s: spot.innerConeAngle %g is above spot.outerConeAngle %g", who,
                         l.inner_angle, l.outer_angle);
    }
    out->light = l;
    out->name = get_string(obj, "name");
    return LX_OK;
}

/* ---- node transforms ---------------------------------------------------- */

static lx_status local_matrix(const char *file, const cJSON *node, const char *who, lx_mat4 *m)
{
    const cJSON *it;
    if ((it = get(node, "matrix"))) {
        if (!numbers(it, m->m, 16))
            return failf(file, LX_ERR_FORMAT, "%s: matrix must be 16 finite numbers", who);
        return LX_OK;
    }
    float t[3] = {0, 0, 0}, r[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if ((it = get(node, "translation")) && !numbers(it, t, 3))
        return failf(file, LX_ERR_FORMAT, "%s: translation must be 3 finite numbers", who);
    if ((it = get(node, "rotation")) && !numbers(it, r, 4))
        return failf(file, LX_ERR_FORMAT, "%s: rotation must be 4 finite numbers", who);
    if ((it = get(node, "scale")) && !numbers(it, s, 3))
        return failf(file, LX_ERR_FORMAT, "%s: scale must be 3 finite numbers", who);
    /* Exporters write quaternions rounded; renormalize so R stays a rotation. */
    double qn =
        sqrt((double)r[0] * r[0] + (double)r[1] * r[1] + (double)r[2] * r[2] + (double)r[3] * r[3]);
    if (!(qn > 1e-12))
        return failf(file, LX_ERR_FORMAT, "%s: rotation quaternion has zero length", who);
    lx_vec4 q =
        lx_v4((float)(r[0] / qn), (float)(r[1] / qn), (float)(r[2] / qn), (float)(r[3] / qn));
    *m = lx_mat4_trs(lx_v3(t[0], t[1], t[2]), q, lx_v3(s[0], s[1], s[2]));
    return LX_OK;
}

typedef struct graph {
    size_t count;
    const cJSON **nodes; /* count */
    int64_t *parent;     /* -1 for roots */
    lx_mat4 *world;
    bool *included; /* in the scene being loaded */
    size_t *order;  /* nodes parents first; reached entries */
    size_t reached;
} graph;

static void graph_free(graph *g)
{
    free(g->nodes);
    free(g->parent);
    free(g->world);
    free(g->included);
    free(g->order);
}

/* Checks children (in range, one parent each, no cycles) and computes every
 * node's world matrix from the roots down, without recursion. */
static lx_status build_graph(const char *file, const cJSON *root, graph *g)
{
    const cJSON *nodes = get(root, "nodes");
    if (nodes && !cJSON_IsArray(nodes))
        return failf(file, LX_ERR_FORMAT, "'nodes' must be an array");
    size_t n = 0;
    for (const cJSON *e = nodes ? nodes->child : NULL; e; e = e->next)
        n++;
    g->count = n;
    size_t alloc = n ? n : 1;
    g->nodes = malloc(alloc * sizeof *g->nodes);
    g->parent = malloc(alloc * sizeof *g->parent);
    g->world = malloc(alloc * sizeof *g->world);
    g->included = calloc(alloc, sizeof *g->included);
    g->order = malloc(alloc * sizeof *g->order);
    size_t *stack = malloc(alloc * sizeof *stack);
    bool *seen = calloc(alloc, sizeof *seen);
    if (!g->nodes || !g->parent || !g->world || !g->included || !g->order || !stack || !seen) {
        free(stack);
        free(seen);
        return failf(file, LX_ERR_NOMEM, "out of memory for %zu nodes", n);
    }
    size_t i = 0;
    for (const cJSON *e = nodes ? nodes->child : NULL; e; e = e->next, i++) {
        g->nodes[i] = e;
        g->parent[i] = -1;
    }
    lx_status st = LX_OK;
    char who[128];
    for (i = 0; i < n && st == LX_OK; i++) {
        label(who, sizeof who, "node", i, g->nodes[i]);
        if (!cJSON_IsObject(g->nodes[i])) {
            st = failf(file, LX_ERR_FORMAT, "%s is not an object", who);
            break;
        }
        const cJSON *children = get(g->nodes[i], "children");
        if (!children)
            continue;
        if (!cJSON_IsArray(children)) {
            st = failf(file, LX_ERR_FORMAT, "%s: children must be an array", who);
            break;
        }
        for (const cJSON *c = children->child; c && st == LX_OK; c = c->next) {
            size_t k;
            if (!index_in(c, n, &k))
                st = failf(file, LX_ERR_FORMAT, "%s: child %g is not a node index (%zu nodes)", who,
                           cJSON_IsNumber(c) ? c->valuedouble : -1.0, n);
            else if (k == i)
                st = failf(file, LX_ERR_FORMAT, "%s is its own child (a cycle)", who);
            else if (g->parent[k] >= 0)
                st = failf(file, LX_ERR_FORMAT, "node %zu is a child of both node %lld and %s", k,
                           (long long)g->parent[k], who);
            else
                g->parent[k] = (int64_t)i;
        }
    }
    /* One parent each: a cycle is a loop of nodes no root reaches. */
    size_t top = 0;
    for (i = 0; i < n && st == LX_OK; i++)
        if (g->parent[i] < 0)
            stack[top++] = i;
    while (top > 0 && st == LX_OK) {
        size_t k = stack[--top];
        g->order[g->reached++] = k;
        seen[k] = true;
        label(who, sizeof who, "node", k, g->nodes[k]);
        lx_mat4 local;
        if ((st = local_matrix(file, g->nodes[k], who, &local)) != LX_OK)
            break;
        g->world[k] = g->parent[k] < 0 ? local : lx_mat4_mul(&g->world[g->parent[k]], &local);
        if (!lx_mat4_finite(&g->world[k]))
            st = failf(file, LX_ERR_FORMAT, "%s: world transform is not finite", who);
        const cJSON *children = get(g->nodes[k], "children");
        for (const cJSON *c = children ? children->child : NULL; c; c = c->next)
            stack[top++] = (size_t)c->valuedouble; /* checked above */
    }
    for (i = 0; i < n && st == LX_OK; i++)
        if (!seen[i]) {
            /* Unreached nodes are on or below a loop of parents: n steps up
             * from one surely land on the loop. */
            size_t k = i;
            for (size_t steps = 0; steps < n; steps++)
                k = (size_t)g->parent[k];
            st = failf(file, LX_ERR_FORMAT, "the node hierarchy has a cycle through node %zu", k);
        }
    free(stack);
    free(seen);
    return st;
}

/* Marks the nodes of the default scene ("scene", else scenes[0]), or every
 * node when the file has no scenes. */
static lx_status select_scene(const char *file, const cJSON *root, graph *g)
{
    const cJSON *scenes = get(root, "scenes");
    if (scenes && !cJSON_IsArray(scenes))
        return failf(file, LX_ERR_FORMAT, "'scenes' must be an array");
    size_t scene_count = (size_t)(scenes ? cJSON_GetArraySize(scenes) : 0);
    const cJSON *which = get(root, "scene");
    if (scene_count == 0) {
        if (which)
            return failf(file, LX_ERR_FORMAT, "'scene' is given but there are no scenes");
        for (size_t i = 0; i < g->count; i++)
            g->included[i] = true;
        return LX_OK;
    }
    size_t s = 0;
    if (which && !index_in(which, scene_count, &s))
        return failf(file, LX_ERR_FORMAT, "'scene' is not a scene index (%zu scenes)", scene_count);
    const cJSON *sc = cJSON_GetArrayItem(scenes, (int)s);
    if (!cJSON_IsObject(sc))
        return failf(file, LX_ERR_FORMAT, "scene %zu is not an object", s);
    const cJSON *roots = get(sc, "nodes");
    if (roots && !cJSON_IsArray(roots))
        return failf(file, LX_ERR_FORMAT, "scene %zu: nodes must be an array", s);
    bool *marked = calloc(g->count ? g->count : 1, sizeof *marked);
    if (!marked)
        return failf(file, LX_ERR_NOMEM, "out of memory for %zu nodes", g->count);
    for (const cJSON *r = roots ? roots->child : NULL; r; r = r->next) {
        size_t k;
        if (!index_in(r, g->count, &k)) {
            free(marked);
            return failf(file, LX_ERR_FORMAT, "scene %zu: node %g is not a node index (%zu nodes)",
                         s, cJSON_IsNumber(r) ? r->valuedouble : -1.0, g->count);
        }
        marked[k] = true;
    }
    /* A node is in the scene when it or an ancestor is a listed root;
     * order has parents before children. */
    for (size_t i = 0; i < g->reached; i++) {
        size_t k = g->order[i];
        g->included[k] = marked[k] || (g->parent[k] >= 0 && g->included[g->parent[k]]);
    }
    free(marked);
    return LX_OK;
}

/* ---- unique names ------------------------------------------------------- */

/* A small open-addressing map from owned strings to sizes. */
typedef struct strmap {
    char **keys;
    size_t *values;
    size_t mask;
} strmap;

static bool strmap_init(strmap *m, size_t capacity)
{
    size_t n = 16;
    while (n < capacity * 2)
        n *= 2;
    m->keys = calloc(n, sizeof *m->keys);
    m->values = calloc(n, sizeof *m->values);
    m->mask = n - 1;
    return m->keys && m->values;
}

static void strmap_free(strmap *m)
{
    if (m->keys)
        for (size_t i = 0; i <= m->mask; i++)
            free(m->keys[i]);
    free(m->keys);
    free(m->values);
}

static size_t strmap_slot(const strmap *m, const char *key)
{
    uint32_t h = 2166136261u; /* FNV-1a */
    for (const char *p = key; *p; p++)
        h = (h ^ (uint8_t)*p) * 16777619u;
    size_t i = h & m->mask;
    while (m->keys[i] && strcmp(m->keys[i], key) != 0)
        i = (i + 1) & m->mask;
    return i;
}

static bool strmap_get(const strmap *m, const char *key, size_t *value)
{
    size_t i = strmap_slot(m, key);
    if (!m->keys[i])
        return false;
    if (value)
        *value = m->values[i];
    return true;
}

static bool strmap_put(strmap *m, const char *key, size_t value)
{
    size_t i = strmap_slot(m, key);
    if (!m->keys[i] && !(m->keys[i] = lx_strdup(key)))
        return false;
    m->values[i] = value;
    return true;
}

/* Copies at most max bytes of src into dst without splitting a UTF-8
 * sequence; true when it had to cut. */
static bool copy_truncated(char *dst, const char *src, size_t max)
{
    size_t n = strlen(src);
    bool cut = n > max;
    if (cut) {
        n = max;
        while (n > 0 && ((uint8_t)src[n] & 0xC0) == 0x80)
            n--;
    }
    memcpy(dst, src, n);
    dst[n] = '\0';
    return cut;
}

/* Gives out the base name, or base_2, base_3... when taken. next remembers
 * where each base's suffixes stopped so many copies stay linear. */
static lx_status unique_name(const char *file, const char *base_in, strmap *used, strmap *next,
                             char out[LX_LIGHT_NAME_MAX])
{
    char base[LX_LIGHT_NAME_MAX];
    if (copy_truncated(base, base_in, LX_LIGHT_NAME_MAX - 1))
        lx_log(LX_LOG_WARN, "%s: light name '%s...' cut to %d bytes", file, base,
               LX_LIGHT_NAME_MAX - 1);
    if (!strmap_get(used, base, NULL)) {
        memcpy(out, base, sizeof base);
    } else {
        size_t k = 2;
        strmap_get(next, base, &k);
        for (;; k++) {
            char suffix[24];
            int len = snprintf(suffix, sizeof suffix, "_%zu", k);
            copy_truncated(out, base, LX_LIGHT_NAME_MAX - 1 - (size_t)len);
            strcat(out, suffix);
            if (!strmap_get(used, out, NULL))
                break;
        }
        if (!strmap_put(next, base, k + 1))
            return failf(file, LX_ERR_NOMEM, "out of memory naming lights");
    }
    if (!strmap_put(used, out, 0))
        return failf(file, LX_ERR_NOMEM, "out of memory naming lights");
    return LX_OK;
}

/* ---- the file ------------------------------------------------------------- */

/* The light index a node references, or false when it has none. */
static lx_status node_light(const char *file, const cJSON *node, const char *who, size_t def_count,
                            bool *has, size_t *index)
{
    *has = false;
    const cJSON *ext = get(get(node, "extensions"), "KHR_lights_punctual");
    if (!ext)
        return LX_OK;
    const cJSON *li = get(ext, "light");
    if (!li)
        return failf(file, LX_ERR_FORMAT, "%s: KHR_lights_punctual without 'light'", who);
    if (!index_in(li, def_count, index))
        return failf(file, LX_ERR_FORMAT, "%s: light %g is out of range (%zu lights)", who,
                     cJSON_IsNumber(li) ? li->valuedouble : -1.0, def_count);
    *has = true;
    return LX_OK;
}

/* Places one light instance by its node's world matrix. */
static lx_status place(const char *file, const lx_mat4 *world, const char *who, lx_light *l)
{
    l->position = lx_mat4_point(world, lx_v3(0.0f, 0.0f, 0.0f));
    lx_vec3 d = lx_mat4_vector(world, lx_v3(0.0f, 0.0f, -1.0f));
    double len = sqrt((double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z);
    if (len > 1e-20 && isfinite(len))
        l->direction = lx_v3((float)(d.x / len), (float)(d.y / len), (float)(d.z / len));
    else if (l->type != LX_LIGHT_POINT)
        return failf(file, LX_ERR_FORMAT, "%s: its transform has no -Z axis to shine along", who);
    if (!lx_vec3_finite(l->position))
        return failf(file, LX_ERR_FORMAT, "%s: light position is not finite", who);
    return LX_OK;
}

static lx_status load_lights(lx_scene *scene, const char *file, const cJSON *root, const def *defs,
                             size_t def_count)
{
    graph g = {0};
    lx_status st = build_graph(file, root, &g);
    if (st == LX_OK)
        st = select_scene(file, root, &g);
    size_t count = 0;
    char who[128];
    for (size_t i = 0; i < g.count && st == LX_OK; i++) {
        bool has;
        size_t li;
        label(who, sizeof who, "node", i, g.nodes[i]);
        if (g.included[i] &&
            (st = node_light(file, g.nodes[i], who, def_count, &has, &li)) == LX_OK && has)
            count++;
    }
    lx_light *lights = NULL;
    strmap used = {0}, next = {0};
    if (st == LX_OK && count > 0) {
        lights = malloc(count * sizeof *lights);
        if (!lights || !strmap_init(&used, count) || !strmap_init(&next, count))
            st = failf(file, LX_ERR_NOMEM, "out of memory for %zu lights", count);
    }
    size_t n = 0;
    for (size_t i = 0; i < g.count && st == LX_OK && n < count; i++) {
        bool has;
        size_t li;
        label(who, sizeof who, "node", i, g.nodes[i]);
        if (!g.included[i] || node_light(file, g.nodes[i], who, def_count, &has, &li) != LX_OK ||
            !has)
            continue;
        lx_light *l = &lights[n];
        *l = defs[li].light;
        /* The light's own name, else its node's, else light<index>. */
        char fallback[32];
        snprintf(fallback, sizeof fallback, "light%zu", li);
        const char *base = defs[li].name;
        if (!base || !base[0])
            base = get_string(g.nodes[i], "name");
        if (!base || !base[0])
            base = fallback;
        if ((st = unique_name(file, base, &used, &next, l->name)) != LX_OK)
            break;
        if ((st = place(file, &g.world[i], who, l)) != LX_OK)
            break;
        if ((st = lx_light_validate(l)) != LX_OK) {
            lx_error_prefix(who);
            lx_error_prefix(file);
            break;
        }
        n++;
    }
    /* Nothing reaches the scene unless every light was good. */
    for (size_t i = 0; i < n && st == LX_OK; i++)
        st = lx_scene_add_light(scene, &lights[i]);
    free(lights);
    strmap_free(&used);
    strmap_free(&next);
    graph_free(&g);
    return st;
}

static lx_status load_json(lx_scene *scene, const char *file, const char *text, size_t size)
{
    cJSON *root;
    lx_status st = parse_json(file, text, size, &root);
    if (st != LX_OK)
        return st;
    def *defs = NULL;
    size_t def_count = 0;
    const cJSON *khr = get(get(root, "extensions"), "KHR_lights_punctual");
    if (!cJSON_IsObject(root)) {
        st = failf(file, LX_ERR_FORMAT, "the top level of the glTF JSON is not an object");
    } else if (khr) {
        /* Files without the extension have no lights: nothing to do. */
        const cJSON *list = get(khr, "lights");
        if (!cJSON_IsObject(khr) || (list && !cJSON_IsArray(list)))
            st = failf(file, LX_ERR_FORMAT, "KHR_lights_punctual: 'lights' must be an array");
        for (const cJSON *e = list ? list->child : NULL; e; e = e->next)
            def_count++;
        if (st == LX_OK && def_count > 0 && !(defs = malloc(def_count * sizeof *defs)))
            st = failf(file, LX_ERR_NOMEM, "out of memory for %zu lights", def_count);
        size_t i = 0;
        for (const cJSON *e = list ? list->child : NULL; e && st == LX_OK; e = e->next, i++)
            st = read_def(file, e, i, &defs[i]);
        if (st == LX_OK)
            st = load_lights(scene, file, root, defs, def_count);
    }
    free(defs);
    cJSON_Delete(root);
    return st;
}

lx_status lx_gltf_lights_load_memory(lx_scene *scene, const void *bytes, size_t size,
                                     const char *name)
{
    const char *file = name && name[0] ? name : "glTF";
    if (!scene)
        return failf(file, LX_ERR_INVALID, "no scene to add the lights to");
    if (!bytes && size > 0)
        return failf(file, LX_ERR_INVALID, "no bytes");
    const uint8_t *b = bytes ? bytes : (const uint8_t *)"";
    if (size >= 4 && memcmp(b, "glTF", 4) == 0) {
        uint64_t off;
        uint32_t len;
        lx_status st = glb_locate(file, b, size, size, &off, &len);
        if (st != LX_OK)
            return st;
        return load_json(scene, file, (const char *)b + off, len);
    }
    return load_json(scene, file, (const char *)b, size);
}

lx_status lx_gltf_lights_load(lx_scene *scene, const char *path)
{
    if (!path)
        return lx_fail(LX_ERR_INVALID, "glTF lights: no path");
    if (!scene)
        return failf(path, LX_ERR_INVALID, "no scene to add the lights to");
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
        st = load_json(scene, path, text, size);
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
        st = load_json(scene, path, json, len);
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
    if (le32(head) != LX_GLB_MAGIC)
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
