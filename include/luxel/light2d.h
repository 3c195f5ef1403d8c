/* luxel/light2d.h - shadow-casting 2D lights over images, for 2D games: point
 * and spot lights, hard or soft shadows from a caster image, normal-mapped
 * sprites, cached static lights and a per-frame API (docs/light2d.md).
 *
 * CONVENTIONS  Positions in pixels, origin at the image's top-left corner,
 *   +y down; pixel (i, j) is centred at (i + 0.5, j + 0.5). A pixel is a
 *   caster when its alpha (or, with desc.mask, its first channel) is at
 *   least desc.threshold. A spot's direction is a vector in those
 *   coordinates, its arc the full opening angle in degrees. Light values
 *   are linear RGB. Normal maps are tangent-space, raw [0,1] codes, green
 *   up unless told otherwise.
 * ERRORS  Functions returning lx_status set lx_last_error(): "lights[2]:
 *   radius -1 must be > 0", "casters: 64x64 but normals: 32x32".
 * MEMORY  lx_light2d_create allocates the context; lx_light2d_destroy frees
 *   it. Images passed in are copied: the caller keeps ownership. Output
 *   buffers are the caller's.
 * THREADING  A context is used by one thread at a time; lx_light2d_render
 *   uses up to desc.threads OpenMP threads and gives the same bytes for any
 *   count.
 *
 * USAGE
 *   lx_image casters;
 *   lx_image_alloc(&casters, 64, 64, 4);
 *   lx_light2d *ctx = NULL;
 *   lx_light2d_create(&casters, NULL, &ctx);
 *   lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
 *   l.x = 32.0f; l.y = 32.0f; l.radius = 30.0f;
 *   float *out = calloc(64 * 64 * 3, sizeof(float));
 *   if (lx_light2d_set_lights(ctx, &l, 1) == LX_OK)
 *       lx_light2d_render(ctx, lx_v3(0.1f, 0.1f, 0.1f), NULL, out, NULL);
 *   free(out);
 *   lx_light2d_destroy(ctx);
 *   lx_image_free(&casters);
 */
#ifndef LUXEL_LIGHT2D_H
#define LUXEL_LIGHT2D_H

#include "luxel/core.h"
#include "luxel/math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum lx_light2d_type { LX_LIGHT2D_POINT = 0, LX_LIGHT2D_SPOT } lx_light2d_type;

/* Falloff within the radius R at distance d: smooth (1 - (d/R)^2)^2,
 * linear 1 - d/R, none 1. Zero beyond R in every case. */
typedef enum lx_light2d_falloff {
    LX_FALLOFF2D_SMOOTH = 0,
    LX_FALLOFF2D_LINEAR,
    LX_FALLOFF2D_NONE
} lx_light2d_falloff;

/* The largest colour x intensity of a light and the largest ambient: far
 * above any real light, they keep every sum of lights finite. */
#define LX_LIGHT2D_MAX_LIGHT 1e30

/* Spot edge fade when none is given: the last 5 degrees of the arc. */
#define LX_LIGHT2D_DEFAULT_EDGE 5.0f

typedef struct lx_light2d_light {
    lx_light2d_type type;
    float x, y;             /* position in pixels (may lie outside the image) */
    float dir_x, dir_y;     /* spot: where it shines, any non-zero length */
    float arc;              /* spot: full opening angle, degrees in (0, 360] */
    float edge;             /* spot: degrees of fade inside the arc's edge
                               (0 = a hard edge) */
    lx_vec3 color;          /* linear RGB, >= 0 */
    float intensity;        /* multiplies color, >= 0 */
    float radius;           /* reach in pixels, > 0 */
    lx_light2d_falloff falloff;
    float softness;         /* the light's own radius in pixels: penumbrae
                               widen with the distance behind the occluder
                               (0 = hard shadows) */
    float height;           /* pixels above the image plane: with normals,
                               lighting is N.L with L towards (x, y, height) */
    bool shadow;            /* casters block this light */
    bool self_shadow;       /* casters shadow their own face too (default:
                               the first caster run a ray meets is lit) */
    bool dynamic;           /* re-lit every frame; static lights are cached */
} lx_light2d_light;

/* A light of `type` with every default: white, intensity 1, smooth
 * falloff, shadow on, spot arc 60 towards +x with the default edge, radius
 * 0 (which the caller must set). */
lx_light2d_light lx_light2d_light_defaults(lx_light2d_type type);

/* LX_OK or LX_ERR_INVALID naming the field ("radius 0 must be > 0", "arc
 * 400 must be in (0, 360]", "direction is zero", non-finite values, colour
 * x intensity above LX_LIGHT2D_MAX_LIGHT). */
lx_status lx_light2d_light_validate(const lx_light2d_light *light);

typedef struct lx_light2d_desc {
    float threshold;      /* a caster has alpha >= threshold; 0 = 0.5 */
    bool mask;            /* casters from the first channel (a grey mask)
                             instead of alpha */
    int threads;          /* 0 = all cores */
    int polar_resolution; /* rays per light; 0 = chosen so that rays are
                             under a pixel apart at the light's radius */
} lx_light2d_desc;

lx_light2d_desc lx_light2d_desc_defaults(const lx_light2d_desc *desc);

typedef struct lx_light2d lx_light2d;

/* A context for the caster image (copied). Without desc.mask the image
 * needs an alpha channel (2 or 4 channels): LX_ERR_INVALID otherwise.
 * desc may be NULL. */
lx_status lx_light2d_create(const lx_image *casters, const lx_light2d_desc *desc,
                            lx_light2d **out);
void lx_light2d_destroy(lx_light2d *ctx);

/* Tangent-space normals (raw [0,1] codes, 3 or 4 channels, the casters'
 * size) for N.L lighting; green_down for maps whose green points down the
 * image (DirectX). NULL removes them. Invalidates every cached light. */
lx_status lx_light2d_set_normals(lx_light2d *ctx, const lx_image *normals, bool green_down);

/* Replaces the caster pixels of the rectangle [x, x+w) x [y, y+h) with
 * those of `casters` (an image of the context's size, read only inside the
 * rectangle, with the channels the context was made with). Only cached
 * lights whose reach touches the rectangle are re-lit. */
lx_status lx_light2d_update_casters(lx_light2d *ctx, const lx_image *casters, int x, int y,
                                    int w, int h);

/* The lights of the next frames (copied; validated). A static light equal
 * to the static light at the same index of the previous call keeps its
 * cached lighting; moved or changed lights are re-lit. */
lx_status lx_light2d_set_lights(lx_light2d *ctx, const lx_light2d_light *lights, int count);

/* Renders a frame; ambient components must be in [0,
 * LX_LIGHT2D_MAX_LIGHT]. out (may be NULL) gets width*height*3 floats,
 * albedo x (ambient + sum of lights), albedo from `albedo` (the casters'
 * size, RGB or RGBA, linear; NULL = white). light_map (may be NULL) gets
 * width*height*3 floats of ambient + sum of lights. At least one of out
 * and light_map must be given (LX_ERR_INVALID otherwise). */
lx_status lx_light2d_render(lx_light2d *ctx, lx_vec3 ambient, const lx_image *albedo, float *out,
                            float *light_map);

/* The number of rays of a light's polar map (the chosen or given
 * resolution). */
int lx_light2d_rays(const lx_light2d *ctx, const lx_light2d_light *light);

/* Lights whose lighting was computed (not taken from the cache) by the
 * last lx_light2d_render. */
int lx_light2d_relit_count(const lx_light2d *ctx);

/* ---- lights files (docs/light2d.md) --------------------------------------- */

typedef struct lx_light2d_scene {
    lx_vec3 ambient;
    lx_light2d_light *lights; /* count entries, malloc'd */
    int count;
} lx_light2d_scene;

/* Reads a lights JSON file: {"ambient": [r,g,b], "lights": [...]}. Unknown
 * keys, wrong types and bad values fail naming the file and field:
 * "l.json: lights[1]: radius 0 must be > 0". */
lx_status lx_light2d_scene_load(const char *path, lx_light2d_scene *out);
/* The same from text; name is used in messages. */
lx_status lx_light2d_scene_parse(const char *name, const char *text, size_t size,
                                 lx_light2d_scene *out);
void lx_light2d_scene_free(lx_light2d_scene *scene);

#ifdef __cplusplus
}
#endif
#endif
