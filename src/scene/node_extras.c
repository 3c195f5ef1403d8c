/* Per-node bake settings from glTF node extras: what Blender exports of an
 * object's custom properties ("Include > Custom Properties"). Booleans may
 * come as true/false or as the integers 0 and 1 (Blender's integer
 * properties, and its booleans before 3.0); the lightmap scale is a
 * number. Only a node's own extras count (not its parents'), the node
 * that carries the mesh in the file. */
#include "gltf_json.h"
#include "node_bake.h"
#include "core/internal.h"

#include "json_text.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define PREFIX "luxel_"

static const char *const bool_keys[] = {"luxel_cast_shadows", "luxel_lightmap",
                                        "luxel_contribute_gi", "luxel_sky"};

static bool read_bool(const cJSON *it, int8_t *out)
{
    if (cJSON_IsBool(it)) {
        *out = cJSON_IsTrue(it) ? 1 : 0;
        return true;
    }
    if (cJSON_IsNumber(it) && (it->valuedouble == 0.0 || it->valuedouble == 1.0)) {
        *out = it->valuedouble == 1.0 ? 1 : 0;
        return true;
    }
    return false;
}

/* The settings in one node's extras object. */
static lx_status read_extras(const char *file, const char *who, const cJSON *extras,
                             lx_node_settings *s, const char **unknown)
{
    char where[200];
    snprintf(where, sizeof where, "%s: extras", who);
    for (const cJSON *e = extras->child; e; e = e->next) {
        const char *key = e->string ? e->string : "";
        if (strncmp(key, PREFIX, strlen(PREFIX)) != 0)
            continue; /* other tools' properties */
        int k = 0;
        while (k < 4 && strcmp(key, bool_keys[k]) != 0)
            k++;
        if (k < 4) {
            int8_t *dst[] = {&s->cast_shadows, &s->lightmap, &s->contribute_gi, &s->sky};
            if (!read_bool(e, dst[k]))
                return lx_json_fail(LX_ERR_FORMAT, file, where,
                                    "%s must be true or false (or 1 or 0)", key);
        } else if (strcmp(key, "luxel_lightmap_scale") == 0) {
            double v = cJSON_IsNumber(e) ? e->valuedouble : NAN;
            if (!isfinite(v) || !(v >= 1.0 / LX_NODE_MAX_LIGHTMAP_SCALE) ||
                v > LX_NODE_MAX_LIGHTMAP_SCALE)
                return lx_json_fail(LX_ERR_FORMAT, file, where,
                                    "luxel_lightmap_scale must be a number from 1/%g to %g",
                                    (double)LX_NODE_MAX_LIGHTMAP_SCALE,
                                    (double)LX_NODE_MAX_LIGHTMAP_SCALE);
            s->lightmap_scale = (float)v;
        } else if (!*unknown) {
            *unknown = key;
        }
    }
    return LX_OK;
}

lx_status lx_gltf_node_extras_read(lx_scene *scene, const char *file, const cJSON *root,
                                   bool *sky_decided)
{
    const cJSON *nodes = lx_gltf_get(root, "nodes");
    size_t count = (size_t)cJSON_GetArraySize(nodes);
    if (!cJSON_IsArray(nodes) || count == 0)
        return LX_OK;
    const char *unknown = NULL;
    char unknown_who[160] = "";
    for (uint32_t n = 0; n < scene->node_count; n++) {
        lx_node *node = &scene->nodes[n];
        if (node->source_node < 0 || (size_t)node->source_node >= count)
            continue;
        const cJSON *jn = cJSON_GetArrayItem(nodes, node->source_node);
        const cJSON *extras = lx_gltf_get(jn, "extras");
        if (!cJSON_IsObject(extras))
            continue;
        char who[160];
        lx_gltf_label(who, sizeof who, "node", (size_t)node->source_node, jn);
        lx_node_settings s = lx_node_settings_none();
        const char *was = unknown;
        lx_status st = read_extras(file, who, extras, &s, &unknown);
        if (st != LX_OK)
            return st;
        if (!was && unknown)
            snprintf(unknown_who, sizeof unknown_who, "%s", who);
        lx_node_settings_apply(&s, &node->bake);
        if (sky_decided && s.sky >= 0)
            sky_decided[n] = true;
    }
    if (unknown)
        lx_log(LX_LOG_WARN,
               "%s: %s: extras: unknown key '%.60s' left alone (luxel reads luxel_cast_shadows, "
               "luxel_lightmap, luxel_contribute_gi, luxel_lightmap_scale and luxel_sky)",
               file, unknown_who, unknown);
    return LX_OK;
}
