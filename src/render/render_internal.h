/* Private to src/render: the camera basis and node binding the renderer
 * shares between its files. */
#ifndef LX_RENDER_INTERNAL_H
#define LX_RENDER_INTERNAL_H

#include "luxel/render.h"
#include "core/internal.h"

typedef struct lx_camera_basis_t {
    lx_vec3 eye, fwd, right, up; /* orthonormal, right-handed */
    float tan_x, tan_y;          /* half-extent of the image plane at depth 1;
                                    orthographic: of the image, in metres */
    bool ortho;                  /* rays along fwd from the plane through eye */
} lx_camera_basis_t;

/* The basis of a checked camera (lx_camera_check) for a width x height image. */
void lx_camera_basis(const lx_camera *cam, int width, int height, lx_camera_basis_t *b);

/* lx_lightmaps_check, filling map[scene node] with the manifest node that
 * lights it (UINT32_MAX: none). map may be NULL. */
lx_status lx_lightmaps_bind(const lx_lightmaps *lm, const lx_scene *scene, uint32_t *map);

/* lx_render_view; quiet: no warnings through lx_log (lx_camera_auto's
 * small probe renders). */
lx_status lx_render_view_quiet(const lx_scene *scene, const lx_lightmaps *lm,
                               const lx_tracer *tracer, const lx_render_desc *desc, lx_image *out,
                               bool quiet);

#endif
