/* Private to src/scene: the two ways lx_scene_write_glb writes a scene. */
#ifndef LX_GLTF_WRITE_INTERNAL_H
#define LX_GLTF_WRITE_INTERNAL_H

#include "luxel/scene.h"

#include <cjson/cJSON.h>

/* The scene's glTF file written again with the UVs (gltf_write.c). */
lx_status lx_gltf_write_with_uvs(const lx_scene *scene, const char *path,
                                 const lx_glb_write_desc *desc);

/* Which accessors and bufferViews root refers to (gltf_compact.c): *acc
 * (nacc entries) and *view (nview), malloc'd. */
lx_status lx_gltf_used(cJSON *root, bool **acc, size_t *nacc, bool **view, size_t *nview);
/* Drops the accessors and bufferViews that were used before (the marks
 * lx_gltf_used gave then) and are not now, renumbering the references;
 * nothing when the file uses an extension that might refer to them. */
lx_status lx_gltf_drop_unused(cJSON *root, const bool *acc_before, size_t nacc_before,
                              const bool *view_before, size_t nview_before);

#endif
