/* luxel/render.h - camera views of a scene with its baked lightmaps
 * applied: one primary ray per pixel sample (Embree, through lx_tracer),
 * each hit shaded as a Lambertian surface, base colour x irradiance / pi,
 * the irradiance looked up in the node's lightmap page through the bake's
 * manifest (docs/manifest.md). This is what `luxel render` draws.
 *
 * CONVENTIONS  World space, metres, +Y up (scene.h). A camera looks from
 *   eye toward target with a vertical field of view in radians; pixel (x,
 *   y), row 0 at the top, covers [x, x+1] x [y, y+1]. The rendered image is
 *   linear radiance in nits (cd/m^2): RGB, Rec.709 primaries; expose it
 *   with lx_exposure_from_ev100 and tone map it when writing (core.h).
 *   Lightmaps in lux are shaded as base colour x E / pi; lightmaps of
 *   outgoing radiance (quantity "radiance") are shown as they are; values
 *   are divided by the manifest's pre_exposure. Pages are read with
 *   clamp-to-edge addressing at the UVs the manifest says: page_uv = uv *
 *   scale_offset.xy + scale_offset.zw (Unity's lightmapScaleOffset).
 *   Back faces are culled unless desc.two_sided or the material is
 *   double-sided (glTF materials are single-sided by default); the base colour is the material's
 * factor times its texture read at its own UV set under KHR_texture_transform. ERRORS
 * lx_lightmaps_load names the manifest and the field or page that is wrong; lx_render_view fails
 * with LX_ERR_INVALID when the lightmaps belong to another scene (a node the scene lacks, a node
 * count or a mesh count that differs, a UV set a mesh lacks), LX_ERR_CANCELLED when the progress
 * callback says stop. MEMORY  lx_lightmaps_load fills a caller-owned struct; lx_lightmaps_free
 *   releases what it allocated. lx_render_view allocates out (free it with
 *   lx_image_free); nothing else outlives the call.
 * THREADING  Every function is thread-safe on distinct outputs.
 *   lx_render_view runs OpenMP over tiles of pixels, at most desc.threads
 *   threads, and gives the same bits for any thread count: each pixel's
 *   samples are stratified and jittered by a counter-based generator keyed
 *   by (seed, pixel, sample).
 *
 * USAGE
 *   lx_scene *scene;
 *   lx_lightmaps lm;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK) return 1;
 *   if (lx_lightmaps_load("lightmaps/room", NULL, &lm) == LX_OK) {
 *       lx_image img;
 *       lx_render_desc d = lx_render_desc_defaults(NULL); // 1280x720, lx_camera_auto
 *       if (lx_render_view(scene, &lm, NULL, &d, &img) == LX_OK) {
 *           lx_image_write_desc w = {.tonemap = LX_TONEMAP_ACES,
 *                                    .exposure = lx_exposure_from_ev100(lm.preview_ev100)};
 *           lx_image_write("view.png", &img, &w);
 *           lx_image_free(&img);
 *       }
 *       lx_lightmaps_free(&lm);
 *   }
 *   lx_scene_destroy(scene);
 */
#ifndef LUXEL_RENDER_H
#define LUXEL_RENDER_H

#include "luxel/bake.h"
#include "luxel/core.h"
#include "luxel/ibl.h"
#include "luxel/math.h"
#include "luxel/scene.h"
#include "luxel/trace.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- cameras --------------------------------------------------------- */

typedef struct lx_camera {
    lx_vec3 eye;    /* where the camera is */
    lx_vec3 target; /* the point at the centre of the image */
    lx_vec3 up;     /* roughly up in the image; zero = +Y (-Z looking straight
                       up or down) */
    float fov;      /* vertical field of view in radians, 0 = 50 degrees */
    float ortho_height; /* > 0: an orthographic camera whose image is this many
                           metres tall (rays parallel to the view, starting in
                           the plane through eye; fov unused); 0 = perspective */
} lx_camera;

#define LX_RENDER_DEFAULT_FOV_DEGREES 50.0f

/* Directions lx_camera_frame looks from. */
typedef enum lx_view {
    LX_VIEW_ISO = 0, /* from +X +Y +Z (above, front right), looking at the centre */
    LX_VIEW_FRONT,   /* from +Z toward -Z */
    LX_VIEW_BACK,    /* from -Z toward +Z */
    LX_VIEW_LEFT,    /* from -X toward +X */
    LX_VIEW_RIGHT,   /* from +X toward -X */
    LX_VIEW_TOP      /* from +Y down, -Z up in the image */
} lx_view;

/* "iso", "front", ... ; NULL for another value. */
const char *lx_view_name(lx_view view);
/* The view named name; false when none. */
bool lx_view_parse(const char *name, lx_view *out);

/* A camera that looks at the box [lo, hi] from `view`, at the centre of
 * the box, as close as it can while all 8 corners stay inside the image
 * (with a 5% margin). fov: vertical, radians (0 = 50 degrees); aspect:
 * width / height (0 = 16/9). */
lx_camera lx_camera_frame(lx_vec3 lo, lx_vec3 hi, lx_view view, float fov, float aspect);

/* Where world point p lands in an image of width x height (pixel units,
 * (0, 0) the top-left corner of the image) seen by cam; false when p is
 * behind the camera. */
bool lx_camera_project(const lx_camera *cam, int width, int height, lx_vec3 p, float *x, float *y);

/* LX_OK when the camera can make an image: finite, eye != target, up not
 * along the view, fov in (0, pi), ortho_height >= 0. The message names
 * the problem. */
lx_status lx_camera_check(const lx_camera *cam);

/* The view of a camera the scene file placed (scene.h, lx_scene_camera):
 * eye, target eye + forward, its up and its yfov. The file's aspectRatio
 * is not used: the image's width / height is (as glTF asks of a renderer
 * whose viewport differs). An orthographic camera gives its frame with fov
 * 0 (the default); an orthographic one ortho_height 2 x |ymag| (its xmag
 * is not used either: the image's aspect sets the width). */
lx_camera lx_camera_from_scene(const lx_scene_camera *camera);

/* ---- lightmaps of a bake (manifest.json) ------------------------------ */

typedef struct lx_lightmap_page {
    char *file; /* path of the page (the manifest's folder joined) */
    int width, height;
    lx_image image; /* linear RGB as stored (width 0 when not loaded) */
    /* directional data (docs/directional.md), NULL / width 0 when none:
     * "sh": sh[0] E0 = pi Y00 L00 and sh[1..3] E1 = 2 pi / 3 Y1 L1 for
     * L1-1 (y), L10 (z), L11 (x), all in the page's units (normalized files
     * are decoded to these); the irradiance of unit normal n is E0 + E1y
     * n.y + E1z n.z + E1x n.x. "dir": Unity's RGBA dominant direction. */
    char *sh_files[4];
    lx_image sh[4];
    char *dir_file;
    lx_image dir;
} lx_lightmap_page;

typedef struct lx_lightmap_node {
    char *name;            /* scene node name */
    uint32_t mesh_count;   /* meshes the manifest lists for it */
    uint32_t page;         /* index into pages */
    int uv_set;            /* n = TEXCOORD_n, below LX_MAX_UV_SETS */
    bool generated;        /* luxel made the UVs ("uvs": "generated") */
    float scale_offset[4]; /* node UV -> page UV */
    float lightmap_scale;  /* the node's lightmap scale in the bake (lx_node.bake;
                              1 when absent) */
} lx_lightmap_node;

typedef struct lx_lightmaps {
    char *dir;            /* the folder given */
    char *scene;          /* the manifest's "scene", as the bake was given it */
    char *scene_with_uvs; /* the scene with generated UVs, joined to dir; NULL when none */
    lx_quantity quantity; /* irradiance (lux) or radiance (nits) */
    float pre_exposure;   /* factor the stored values carry (1 without --pre-expose) */
    float preview_ev100;  /* the previews' exposure (0 when absent) */
    float texel_density;  /* texels per metre, 0 when absent */
    int padding;          /* texel rings each chart owns (-1 when absent) */
    int atlas_size;       /* largest page side asked for (0 when absent) */
    char *sky;            /* the sky environment as the bake was given it, or NULL */
    lx_directional_mode directional; /* the manifest's "directional" mode (OFF
                                        when absent) */
    bool sh_normalized;   /* the sh files hold L1 / (sqrt 3 L00) as codes
                             (decoded to E1 when loaded) */
    float sky_intensity;  /* its multiplier (1 when absent) */
    float emissive_scale; /* the bake's --emissive-scale (1 when absent): the
                             render draws emissive materials' radiance
                             times it */
    lx_lightmap_page *pages;
    uint32_t page_count;
    lx_lightmap_node *nodes;
    uint32_t node_count;
    char **unbaked; /* "nodes_without_lightmap": the nodes the bake gave
                       none by their settings (lx_node.bake.no_lightmap,
                       sky domes), by name */
    uint32_t unbaked_count;
} lx_lightmaps;

typedef struct lx_lightmaps_load_desc {
    bool skip_images;    /* read the manifest only: pages keep width 0 images */
    bool allow_any_path; /* read files the manifest names wherever they are;
                            by default only files in its folder or below it
                            are read, others fail the load */
} lx_lightmaps_load_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_lightmaps_load_desc lx_lightmaps_load_desc_defaults(const lx_lightmaps_load_desc *desc);

/* Reads dir/manifest.json and the pages it lists (EXR, HDR, PFM or PNG,
 * lx_image_load; 8-bit pages hold the previews' exposed values, E / pi
 * for irradiance, and are scaled back by the manifest's preview_ev100 -
 * to within their 8 bits and the clipping at 1), checking that each page has the size the manifest
 * says and finite, non-negative values, that node pages and UV sets exist and scale_offsets are
 * finite. desc may be NULL. On failure *out is zeroed and the message names the file:
 * "dir/manifest.json: nodes[2]: page 7 out of range (3 pages)". */
lx_status lx_lightmaps_load(const char *dir, const lx_lightmaps_load_desc *desc, lx_lightmaps *out);
void lx_lightmaps_free(lx_lightmaps *lm);

/* LX_OK when lm fits scene: every manifest node is a scene node with as
 * many meshes, each with the UV set named; and the scene nodes the
 * manifest leaves out have no UVs in any set (they could not be baked),
 * or no lightmap by their settings (bake.no_lightmap, or named in
 * lm->unbaked). Else LX_ERR_INVALID: "lightmaps/room/manifest.json: node
 * 'floor' is not in scene.glb: the lightmaps of another scene?". */
lx_status lx_lightmaps_check(const lx_lightmaps *lm, const lx_scene *scene);

/* Gives the scene's nodes the bake settings the bake had where lm records
 * them (settings from a lights JSON the scene file does not carry):
 * bake.no_lightmap for the nodes lm->unbaked names, so the default camera
 * leaves them out as the bake did, and each lightmap node's
 * lightmap_scale, so UVs made again pack as the bake's did. Names the
 * scene lacks are left alone. */
void lx_lightmaps_apply_settings(const lx_lightmaps *lm, lx_scene *scene);

/* ---- the default camera ---------------------------------------------- */

/* What lx_camera_auto saw and chose. */
typedef struct lx_camera_auto_info {
    float outside_hit;   /* fraction of the iso view's probes that meet the scene */
    float outside_back;  /* of those, the fraction whose first surface is a back face */
    float outside_unlit; /* ... and the fraction on a front face that is not lit */
    float outside_score; /* fraction of the iso view's probes on a lit front face */
    bool moved;          /* another view was taken */
    bool inside;         /* ... from inside the bounds (else a side's framing) */
    bool enclosed;       /* ... because the scene is a closed room: its inside
                            views meet walls all round */
    float score;         /* the taken view's fraction of probes on a lit front face */
    char placement[48];  /* "iso", "front", "back", "left", "right" or
                            "inside, looking along +X" (-X, +Z, -Z) */
} lx_camera_auto_info;

/* The default camera of a scene that brings none. Starts from
 * lx_camera_frame(..., LX_VIEW_ISO, ...) of the bounds of the nodes that
 * get a lightmap and are not sky domes (lx_node.bake; the scene's bounds
 * when there are none; a backdrop left out too) and probes it with a
 * grid of 18 rows of rays (as many columns as the aspect asks, at most
 * 64) through tracer (made from scene; the probes are LX_RAY_FRAMING
 * rays, which pass through the nodes left out): a probe scores when the first
 * surface it meets, either face, is a front face that is lit - lit judged
 * with lm by a 1-sample render of the same grid (luminance above 1% of
 * the brightest probed view's median); lm NULL, or every view black:
 * front faces only. The framings from the front, back, left and right
 * (lx_camera_frame), then four views from inside the bounds (eye at 55%
 * of the height, 15% in from one end of a horizontal axis, looking along
 * it; the longer axis first) are probed the same way (a hit nearer than 2%
 * of the bounds' diagonal scores nothing) when less than half of the
 * probes that meet the scene score in the iso view. Of the side framings
 * in which at least half of what the probes meet scores, the one with the
 * most scoring probes is taken; when there is none, of the inside views
 * so; when there is none either, the iso view stays: a closed room seen from
 * outside shows the back faces of walls that face in, or the unlit
 * outside of walls with two sides; a box open on one side is seen
 * through it. First of all, when each of the four inside views meets the
 * scene on at least 90% of its probes (walls all round: a closed room),
 * the best of them in which half of what they meet scores is taken,
 * whatever the iso view shows (info->enclosed). Deterministic: the same scene and lightmaps give the same
 * camera. tracer NULL: the iso framing unchecked. fov radians (0 = 50
 * degrees), aspect width / height (0 = 16/9). info may be NULL.
 * LX_ERR_INVALID for an empty scene; lx_render_view's errors for lm. */
lx_status lx_camera_auto(const lx_scene *scene, const lx_lightmaps *lm, const lx_tracer *tracer,
                         float fov, float aspect, lx_camera *out, lx_camera_auto_info *info);

/* ---- rendering -------------------------------------------------------- */

typedef enum lx_lightmap_filter {
    LX_LIGHTMAP_BILINEAR = 0, /* 2x2 texels */
    LX_LIGHTMAP_BICUBIC       /* 4x4 texels, cubic B-spline (smooth, never negative) */
} lx_lightmap_filter;

typedef struct lx_render_desc {
    int width, height;         /* pixels, 0 = 1280 x 720 */
    lx_camera camera;          /* eye == target (zeroed): lx_camera_auto (the iso
                                  framing of the scene's bounds, or a view
                                  from inside when that sees back faces), at
                                  camera.fov */
    int samples;               /* per pixel, 1..4096, 0 = 4 */
    lx_lightmap_filter filter; /* lightmap lookups */
    bool two_sided;            /* false: back faces of single-sided materials
                                  are culled (rays go through) */
    lx_vec3 background;        /* radiance (nits) of rays that miss (default black;
                                  coverage lets a caller compose its own) */
    const lx_cubemap *sky;     /* when set, rays that miss see it (radiance, nits) */
    float sky_intensity;       /* multiplier on sky, 0 = 1 */
    uint32_t seed;             /* sample pattern */
    float *coverage;           /* NULL, or width*height floats (the caller's) that
                                  get the fraction of each pixel's samples that
                                  hit the scene (for metering, masks) */
    int threads;               /* 0 = all cores */
    lx_progress_fn progress;   /* fraction of tiles done; false cancels */
    void *progress_user;
} lx_render_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in;
 * the camera stays zeroed (framed at render time). */
lx_render_desc lx_render_desc_defaults(const lx_render_desc *desc);

/* Renders scene with lightmaps lm into out (3 channels, linear radiance in
 * nits, allocated here). With directional lightmaps (lm->directional), a
 * surface whose material has a normal map is lit for its normal-mapped
 * normal n' (MikkTSpace tangents, or the mesh's): the lightmap's E times
 * f(n') / f(n), n the interpolated vertex normal, f the L1 irradiance E0 +
 * E1 . n (sh; f(n') clamped at 0, and no change where f(n) is not above
 * 0) or Unity's half-Lambert (n' . d) / 2 + 1/2 over the stored rebalancing
 * (dominant); other surfaces, or lightmaps without directional data, as
 * before. tracer may be NULL (one is built and destroyed
 * here), else it must have been made from scene. Checks lm against the
 * scene first (lx_lightmaps_check), and lm must have its images loaded.
 * Scene nodes without a lightmap are drawn black; sky domes
 * (lx_node.bake.sky) are not drawn (camera rays pass through them). On failure out is
 * zeroed. desc may be NULL. */
lx_status lx_render_view(const lx_scene *scene, const lx_lightmaps *lm, const lx_tracer *tracer,
                         const lx_render_desc *desc, lx_image *out);

#ifdef __cplusplus
}
#endif
#endif
