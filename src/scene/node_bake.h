/* Private to src/scene: per-node bake settings (lx_node_bake) as glTF
 * node extras and the lights JSON's "nodes" section give them, and the
 * sky domes lx_scene_load marks. */
#ifndef LX_NODE_BAKE_H
#define LX_NODE_BAKE_H

#include "luxel/scene.h"

#include <cjson/cJSON.h>
#include <stdbool.h>

/* Settings given for a node by one source: each bool -1 when not given,
 * else 0 or 1; lightmap_scale 0 when not given. */
typedef struct lx_node_settings {
    int8_t cast_shadows, lightmap, contribute_gi, sky;
    float lightmap_scale;
} lx_node_settings;

/* Settings that give nothing. */
static inline lx_node_settings lx_node_settings_none(void)
{
    return (lx_node_settings){-1, -1, -1, -1, 0.0f};
}

/* World bounds of one node's vertices grown into [*lo, *hi]; false (and
 * the bounds unchanged) when it has none (scene.c). */
bool lx_node_grow_bounds(const lx_scene *s, const lx_node *node, lx_vec3 *lo, lx_vec3 *hi);

/* The most a lightmap_scale may be (and 1 / it the least). */
#define LX_NODE_MAX_LIGHTMAP_SCALE 1024.0f

/* Applies s to b: "sky" first (true marks a sky dome and turns its three
 * flags off, false unmarks it and turns them back on), then the other
 * fields given. */
void lx_node_settings_apply(const lx_node_settings *s, lx_node_bake *b);

/* The luxel_* extras of the glTF nodes the scene's nodes came from
 * (lx_node.source_node; docs/bake.md): applied to each node's bake, and
 * sky_decided[n] set where luxel_sky was given. A value of the wrong type
 * fails (LX_ERR_FORMAT) naming the file, the node and the key; an unknown
 * luxel_* key is one warning for the file. */
lx_status lx_gltf_node_extras_read(lx_scene *scene, const char *file, const cJSON *root,
                                   bool *sky_decided);

/* lx_scene_mark_sky_domes leaving out the nodes whose decided[n] is true
 * (decided may be NULL). */
uint32_t lx_scene_mark_sky_domes_except(lx_scene *scene, const bool *decided);
/* lx_scene_mark_backdrops, the same way. */
uint32_t lx_scene_mark_backdrops_except(lx_scene *scene, const bool *decided);

#endif
