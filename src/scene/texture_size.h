/* The pixels a scene's textures keep on load for the density a bake will
 * read them at (texture_size.c). Private to scene. */
#ifndef LX_SCENE_TEXTURE_SIZE_H
#define LX_SCENE_TEXTURE_SIZE_H

#include "luxel/scene.h"

/* The three maps a material's textures fill, in this order. */
enum { LX_TEXTURE_NORMAL, LX_TEXTURE_BASE_COLOR, LX_TEXTURE_EMISSIVE, LX_TEXTURE_SLOTS };

/* keep[3 * k + slot] gets lx_image_load_desc.keep_pixels for map slot of
 * scene material k (0: as stored) by the rule at LX_TEXTURE_TEXELS_PER_TEXEL
 * in scene.h, from desc's densities and the scene's nodes, meshes and the
 * materials' UV sets and transforms (the maps need not be decoded). keep
 * holds 3 x material_count entries; all 0 when desc gives no density. */
lx_status lx_texture_keep_pixels(const lx_scene *scene, const lx_scene_load_desc *desc,
                                 uint64_t *keep);

#endif
