/* Private to src/scene: the two ways lx_scene_write_glb writes a scene. */
#ifndef LX_GLTF_WRITE_INTERNAL_H
#define LX_GLTF_WRITE_INTERNAL_H

#include "luxel/scene.h"

/* The scene's glTF file written again with the UVs (gltf_write.c). */
lx_status lx_gltf_write_with_uvs(const lx_scene *scene, const char *path,
                                 const lx_glb_write_desc *desc);

#endif
