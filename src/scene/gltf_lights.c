/* glTF 2.0 KHR_lights_punctual (Khronos extension spec): point, spot and
 * directional lights defined in the root "extensions" and placed by the
 * nodes that reference them; a light shines down its node's local -Z.
 * Read from the glTF JSON directly (cJSON, through gltf_json.c) because
 * assimp drops the exact fields; nodes are placed by gltf_nodes.c. */
#include "luxel/scene.h"
#include "core/internal.h"

#include "gltf_json.h"
#include "json_text.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define failf(file, st, ...) lx_json_fail(st, file, NULL, __VA_ARGS__)

/* ---- light definitions ---------------------------------------------------- */

typedef struct def {
    lx_light light;   /* everything but name, position and direction */
    const char *name; /* the definition's own name or NULL; owned by cJSON */
} def;

static lx_status read_def(const char *file, const cJSON *obj, size_t index, def *out)
{
    char who[128];
    lx_gltf_label(who, sizeof who, "KHR_lights_punctual light", index, obj);
    if (!cJSON_IsObject(obj))
        return failf(file, LX_ERR_FORMAT, "%s is not an object", who);
    const char *type = lx_gltf_get_string(obj, "type");
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
    if ((it = lx_gltf_get(obj, "color"))) {
        if (!lx_gltf_numbers(it, v, 3))
            return failf(file, LX_ERR_FORMAT, "%s: color must be 3 finite numbers", who);
        if (v[0] < 0.0f || v[1] < 0.0f || v[2] < 0.0f)
            return failf(file, LX_ERR_INVALID, "%s: color has a negative component", who);
        l.color = lx_v3(v[0], v[1], v[2]);
    }
    if ((it = lx_gltf_get(obj, "intensity"))) {
        if (!lx_gltf_number(it, &l.intensity))
            return failf(file, LX_ERR_FORMAT, "%s: intensity must be a finite number", who);
        if (l.intensity < 0.0f)
            return failf(file, LX_ERR_INVALID, "%s: intensity %g is negative", who, l.intensity);
    }
    if ((it = lx_gltf_get(obj, "range"))) {
        if (!lx_gltf_number(it, &l.range))
            return failf(file, LX_ERR_FORMAT, "%s: range must be a finite number", who);
        if (!(l.range > 0.0f))
            return failf(file, LX_ERR_INVALID, "%s: range %g must be above 0", who, l.range);
    }
    if (t == LX_LIGHT_SPOT && (it = lx_gltf_get(obj, "spot"))) {
        if (!cJSON_IsObject(it))
            return failf(file, LX_ERR_FORMAT, "%s: spot must be an object", who);
        const cJSON *a;
        if ((a = lx_gltf_get(it, "innerConeAngle")) && !lx_gltf_number(a, &l.inner_angle))
            return failf(file, LX_ERR_FORMAT, "%s: spot.innerConeAngle must be a finite number",
                         who);
        if ((a = lx_gltf_get(it, "outerConeAngle")) && !lx_gltf_number(a, &l.outer_angle))
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
    out->name = lx_gltf_get_string(obj, "name");
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
    const cJSON *ext = lx_gltf_get(lx_gltf_get(node, "extensions"), "KHR_lights_punctual");
    if (!ext)
        return LX_OK;
    const cJSON *li = lx_gltf_get(ext, "light");
    if (!li)
        return failf(file, LX_ERR_FORMAT, "%s: KHR_lights_punctual without 'light'", who);
    if (!lx_gltf_index(li, def_count, index))
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
    lx_gltf_graph g = {0};
    lx_status st = lx_gltf_graph_build(file, root, &g);
    if (st == LX_OK)
        st = lx_gltf_graph_select(file, root, &g);
    size_t count = 0;
    char who[128];
    for (size_t i = 0; i < g.count && st == LX_OK; i++) {
        bool has;
        size_t li;
        lx_gltf_label(who, sizeof who, "node", i, g.nodes[i]);
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
        lx_gltf_label(who, sizeof who, "node", i, g.nodes[i]);
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
            base = lx_gltf_get_string(g.nodes[i], "name");
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
    lx_gltf_graph_free(&g);
    return st;
}

lx_status lx_gltf_lights_from_json(lx_scene *scene, const char *file, const cJSON *root)
{
    const cJSON *khr = lx_gltf_get(lx_gltf_get(root, "extensions"), "KHR_lights_punctual");
    if (!khr)
        return LX_OK; /* files without the extension have no lights */
    lx_status st = LX_OK;
    def *defs = NULL;
    size_t def_count = 0;
    const cJSON *list = lx_gltf_get(khr, "lights");
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
    free(defs);
    return st;
}

lx_status lx_gltf_lights_load_memory(lx_scene *scene, const void *bytes, size_t size,
                                     const char *name)
{
    if (!bytes)
        return lx_fail_null(__func__, "bytes");
    const char *file = name && name[0] ? name : "glTF";
    if (!scene)
        return failf(file, LX_ERR_INVALID, "no scene to add the lights to");
    if (!bytes && size > 0)
        return failf(file, LX_ERR_INVALID, "no bytes");
    cJSON *root;
    lx_status st = lx_gltf_json_read_memory(file, bytes, size, &root);
    if (st == LX_OK)
        st = lx_gltf_lights_from_json(scene, file, root);
    cJSON_Delete(root);
    return st;
}

lx_status lx_gltf_lights_load(lx_scene *scene, const char *path)
{
    if (!path)
        return lx_fail(LX_ERR_INVALID, "glTF lights: no path");
    if (!scene)
        return failf(path, LX_ERR_INVALID, "no scene to add the lights to");
    cJSON *root;
    lx_status st = lx_gltf_json_read(path, &root);
    if (st == LX_OK)
        st = lx_gltf_lights_from_json(scene, path, root);
    cJSON_Delete(root);
    return st;
}
