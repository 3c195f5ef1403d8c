/* Private to src/scene: the parts of the lights JSON reader
 * (docs/lights-json.md) that live in their own files. */
#ifndef LX_LIGHTS_JSON_INTERNAL_H
#define LX_LIGHTS_JSON_INTERNAL_H

#include "json_fields.h"

/* The "materials" section read but not yet applied: one entry per scene
 * material (lights_json_materials.c). */
typedef struct lx_lj_materials lx_lj_materials;

/* Reads "materials" (obj) against scene's material names into *out
 * (NULL on failure); nothing in the scene changes. */
lx_status lx_lj_materials_read(lx_jf_ctx *c, const cJSON *obj, const lx_scene *scene,
                               lx_lj_materials **out);
/* Gives the read settings to the scene's materials (the whole file is
 * valid by then); p keeps nothing the scene now owns. */
void lx_lj_materials_apply(lx_lj_materials *p, lx_scene *scene);
/* Frees p (NULL is fine). */
void lx_lj_materials_free(lx_lj_materials *p);

/* The "nodes" section read but not yet applied: settings per scene node
 * (lights_json_nodes.c). */
typedef struct lx_lj_nodes lx_lj_nodes;

/* Reads "nodes" (obj: node names or glob patterns to settings) against
 * scene's node names into *out (NULL on failure); nothing in the scene
 * changes. */
lx_status lx_lj_nodes_read(lx_jf_ctx *c, const cJSON *obj, const lx_scene *scene,
                           lx_lj_nodes **out);
/* Gives the read settings to the scene's nodes, and warns once for the
 * patterns that matched no node. */
void lx_lj_nodes_apply(const lx_lj_nodes *p, lx_scene *scene);
void lx_lj_nodes_free(lx_lj_nodes *p);

#endif
