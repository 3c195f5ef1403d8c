/* luxel/maps.h - texture-space tools: tangent frames.
 *
 * CONVENTIONS  UV origin at the top-left (glTF). Tangents are xyz + w
 *   handedness with bitangent = cross(normal, tangent.xyz) * w, the glTF
 *   convention: the tangent follows +u and the bitangent points toward -v
 *   (up in the image), matching normal maps whose green channel is "up".
 * ERRORS  LX_ERR_INVALID for missing inputs.
 * MEMORY  The caller owns every buffer.
 * THREADING  Every function is thread-safe (pure: it reads its inputs and
 *   writes only the caller's buffers).
 *
 * USAGE
 *   lx_scene *scene;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK) return 1;
 *   const lx_mesh *mesh = &scene->meshes[0];
 *   lx_vec4 *t = malloc(sizeof *t * mesh->vertex_count);
 *   if (t && lx_compute_tangents(mesh, 0, t) == LX_OK) {
 *       lx_vec3 m = lx_v3(0.6f, 0, 0.8f);   // a normal-map texel, tangent space
 *       lx_vec3 n = lx_tangent_to_world(m, mesh->normals[0], t[0]);
 *       printf("perturbed normal (%g, %g, %g)\n", n.x, n.y, n.z);
 *   }
 *   free(t);
 *   lx_scene_destroy(scene);
 */
#ifndef LUXEL_MAPS_H
#define LUXEL_MAPS_H

#include "luxel/core.h"
#include "luxel/math.h"
#include "luxel/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Per-vertex tangents from positions, normals and uv[uv_set] (Lengyel's
 * method, FGED vol. 2 ch. 7: per-triangle tangent/bitangent summed over
 * vertices, Gram-Schmidt against the normal, handedness in w). Vertices
 * whose triangles have no usable UV gradient get any tangent perpendicular
 * to the normal. out must hold mesh->vertex_count entries. */
lx_status lx_compute_tangents(const lx_mesh *mesh, int uv_set, lx_vec4 *out);

/* Tangent-space vector m (x right, y up, z out) to the frame of normal n
 * and tangent t (w = handedness); normalized. */
lx_vec3 lx_tangent_to_world(lx_vec3 m, lx_vec3 n, lx_vec4 t);

#ifdef __cplusplus
}
#endif
#endif
