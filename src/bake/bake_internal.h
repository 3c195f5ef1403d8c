/* Private to src/bake: the baker's texel maps and lighting passes. */
#ifndef LX_BAKE_INTERNAL_H
#define LX_BAKE_INTERNAL_H

#include "luxel/bake.h"
#include "luxel/maps.h"
#include "luxel/trace.h"

/* Texels are stored in tiles of TILE x TILE for coherent rays; a tile is
 * also the unit of parallel work, so results do not depend on threads. */
#define LX_TILE 8

/* One covered texel. Its position and normals are in the lightmap's
 * world_* arrays (and object_* for a node that can move), its base colour
 * in albedo. */
typedef struct lx_texel {
    uint32_t pixel;    /* y * width + x */
    uint32_t mesh;     /* scene mesh index */
    uint32_t triangle; /* in that mesh */
    uint32_t node;     /* scene node placing the mesh (a page holds several) */
} lx_texel;

/* A texel of a material with a height (horizon.c): its horizon layers and
 * AO sampled at its material UV, and the world tangent frame of the
 * surface under the height. flags 0: the texel bakes as without one. */
#define LX_TEXEL_HORIZON 1u
#define LX_TEXEL_AO 2u
typedef struct lx_texel_horizon {
    float h0[4], h1[4];
    float ao; /* 1 without an AO map */
    uint32_t flags;
    lx_vec3 t, b, n;
} lx_texel_horizon;

/* A scene material's horizon layers and AO map (empty when not asked). */
typedef struct lx_horizon_material {
    lx_image layer0, layer1, ao;
    bool horizon, use_ao, active;
} lx_horizon_material;

/* Seam stitching (stitch.c): the samples along a map's UV seams, made with
 * its texel map when desc.stitch_seams asks. */
typedef struct lx_seam_stitch lx_seam_stitch;

typedef struct lx_lightmap {
    lx_lightmap_info info;
    char *name;
    lx_texel *texels;     /* info.used_texels, grouped by tile */
    uint32_t *tile_start; /* tile_count + 1 offsets into texels */
    uint32_t tile_count;
    lx_vec3 *world_position; /* per texel, for the node's current transform */
    lx_vec3 *world_normal;   /* shading normal, normal map applied */
    lx_vec3 *world_geometric_normal;
    /* the same in object space, what survives the node moving; NULL while
     * the node sits at the identity it was built at (the world arrays are
     * then object space: a static bake keeps one copy) */
    lx_vec3 *object_position;
    lx_vec3 *object_normal;
    lx_vec3 *object_geometric_normal;
    lx_vec3 *albedo; /* per texel base colour (factor x texture); NULL unless
                        the bake is of radiance or has bounces */
    lx_vec3 *emission; /* per texel emitted radiance (nits, emissive scale
                          applied); NULL unless bounces > 0 and a material
                          of the map emits */
    lx_texel_horizon *horizon; /* per texel; NULL when no texel's material has a height */
    uint8_t *mask;   /* width * height */
    float *baked;    /* width * height * 3 */
    float *realtime; /* width * height * 3; NULL (reads as zero) until the
                        first update with dynamic lights */
    lx_seam_stitch *stitch; /* NULL: not asked, or no seams */
    /* Whether the texel map (texels, tiles, positions, normals, albedo,
     * emission, horizon, stitch) is in memory. A tiled baker
     * (bake_tiles.c) keeps only name, info, mask, baked and realtime of
     * the maps outside the tile it works on, and rebuilds the rest. */
    bool loaded;
    bool horizon_page; /* a node on it has a height (its texels may take records) */
} lx_lightmap;

/* How to build a lightmap again (a tiled baker): its page. */
typedef struct lx_tile_page {
    int width, height; /* 0: the node's own size */
    struct lx_page_node *nodes;
    uint32_t node_count;
} lx_tile_page;

struct lx_baker {
    lx_bake_desc desc;
    lx_lightmap *maps;
    uint32_t map_count;
    uint32_t *node_map;            /* scene node -> map index or UINT32_MAX */
    float (*node_scale_offset)[4]; /* scene node -> its UVs into its map */
    uint32_t node_count;
    lx_mat4 *node_world;
    lx_light *lights;
    uint32_t light_count;
    lx_vec3 ambient;
    lx_tracer *tracer;
    bool tracer_dirty;
    float scene_diagonal;
    float bias; /* shadow ray origin offset, metres */
    /* sky light (sky.c) */
    bool has_sky, sky_shadows;
    uint32_t sky_samples;
    lx_sh9 sky_sh;         /* scaled by the sky's intensity */
    lx_cubemap sky_lookup; /* with shadows: the filtered, scaled environment
                              less its peak */
    float *sky_peak;       /* NULL, or the bright part per texel (RGB) */
    double *sky_peak_cdf;  /* cumulative luminance x solid angle of the peak */
    /* global illumination (gi.c), made when desc.bounces > 0: each node's
     * lightmap UV set, and each mesh's UVs (both sets), triangles and
     * emission, to find what a gather ray hit */
    int8_t *node_uv_set;
    uint32_t mesh_count;
    lx_vec2 **mesh_uv[LX_MAX_UV_SETS];
    uint32_t **mesh_indices;
    uint32_t *mesh_triangles;
    lx_vec3 *mesh_emission;
    uint64_t gi_invalid_texels; /* found by the last bake */
    /* during lx_baker_create only (for the baker's life when tiled): each
     * material's horizon layers and AO */
    lx_horizon_material *horizon_materials;
    uint32_t horizon_material_count;
    /* tiles (bake_tiles.c): consecutive groups of whole lightmaps whose
     * working set fits the memory limit; one tile when everything fits */
    uint32_t tile_count;
    uint32_t *tile_first_map; /* tile_count + 1 */
    uint32_t loaded_tile;     /* the tile in memory when tiled; UINT32_MAX none */
    bool tiled;               /* more than one tile: maps are rebuilt */
    lx_scene *tile_scene;     /* tiled: the copy texel maps are rebuilt from */
    lx_tile_page *pages;      /* tiled: per map, its page */
    uint64_t memory_limit;    /* the limit tiles were planned for */
};

/* Bytes a lightmap needs per texel at most: raster scratch, mask, baked and
 * real-time RGB, and a texel record with its world- and object-space
 * copies and its albedo. */
#define LX_BYTES_PER_TEXEL (4 * 4 + 2 + 2 * 12 + sizeof(lx_texel) + 2 * 3 * 12 + 12)

/* The size of node's own lightmap under desc (texel_map.c); 0 x 0 when
 * the node has no UVs. */
void lx_texel_map_size(const lx_scene *scene, uint32_t node, const lx_bake_desc *desc, int *width,
                       int *height);

/* A lightmap page: the nodes it holds and where their UVs land in it. */
typedef struct lx_page_node {
    uint32_t node;
    int uv_set;            /* -1: the automatic choice */
    float scale_offset[4]; /* page uv = uv * xy + zw */
} lx_page_node;

typedef struct lx_page_spec {
    const char *name;
    int width, height; /* 0: the node's own size (one node) */
    const lx_page_node *nodes;
    uint32_t node_count;
} lx_page_spec;

/* The share of a long operation's progress one step reports in: it goes
 * from `from` to `to`. */
typedef struct lx_texel_progress {
    float from, to;
} lx_texel_progress;

/* Builds the texel map of a page into map (texel_map.c), reporting its
 * rasterization to desc->progress within `progress` (and stopping with
 * LX_ERR_CANCELLED when it says so). Returns LX_OK with map->info.width
 * == 0 and a warning when no node of it has UVs to bake. */
lx_status lx_texel_map_build(const lx_scene *scene, const lx_page_spec *page,
                             const lx_bake_desc *desc, lx_texel_progress progress,
                             const lx_horizon_material *horizon, lx_lightmap *map);

/* horizon.c: the horizon layers and AO of every material with a height
 * (one per scene material; *out NULL when none has one), loaded (or
 * integrated from a normal map) and made once, reporting to desc->progress
 * within share and stopping with LX_ERR_CANCELLED when it says so; a
 * warning for each mesh of such a material without its UV set; the per-texel data of a map (b1, b2: the raster's barycentrics
 * per pixel); a light's factor at a texel; whether a tile has any such
 * texel. */
lx_status lx_bake_horizon_load(const lx_scene *scene, const lx_bake_desc *desc,
                               lx_texel_progress share, lx_horizon_material **out);
/* Whether a mesh of node has a material with horizon maps (its texels
 * then take an lx_texel_horizon each). */
bool lx_bake_node_has_horizon(const lx_scene *scene, const lx_horizon_material *hm, uint32_t node);
void lx_bake_horizon_free(lx_horizon_material *hm, uint32_t count);
lx_status lx_bake_horizon_texels(const lx_scene *scene, const lx_horizon_material *hm,
                                 lx_lightmap *map, const float *b1, const float *b2, int threads);
float lx_texel_horizon_factor(const lx_texel_horizon *h, lx_vec3 to_light);
bool lx_tile_has_horizon(const lx_lightmap *map, uint32_t first, uint32_t count);
void lx_texel_map_free(lx_lightmap *map);
/* Makes the object-space copies a move needs (a map built at the
 * identity has none); LX_ERR_NOMEM when they do not fit. */
lx_status lx_texel_map_keep_object_space(lx_lightmap *map);
/* Recomputes the world positions and normals of node's texels from its
 * transform; the map has its object-space copies
 * (lx_texel_map_keep_object_space). */
void lx_texel_map_transform(lx_lightmap *map, uint32_t node, const lx_mat4 *world);

/* Adds the given lights (indices into baker->lights) into target
 * (width*height*3 floats per map), plus `ambient` at every texel
 * (direct.c). progress_base/progress_span place this pass in the whole
 * operation's progress. */
/* Shadow ray from texel position p with geometric normal ng toward e's
 * light (direct.c). */
lx_ray lx_shadow_ray(const lx_baker *b, lx_vec3 p, lx_vec3 ng, const lx_light_eval *e);

/* Stratified cosine-weighted directions (Malley's method), shared by the
 * sky's, the gathers' and AO's rays (sky.c): n rays as sx x sy cells
 * (sx = floor(sqrt n), at least 1), and ray k's direction about the unit
 * frame (t, bt, n), jittered by lx_random(map, pixel, k, key) and
 * (..., key + 1), so any thread count gives the same rays. */
void lx_cosine_strata(uint32_t count, uint32_t *sx, uint32_t *sy);
lx_vec3 lx_cosine_direction(lx_vec3 t, lx_vec3 bt, lx_vec3 n, uint32_t map, uint32_t pixel,
                            uint32_t k, uint32_t sx, uint32_t sy, uint32_t key);

/* Takes what the baker needs of a sky (SH, the lookup for rays); nothing
 * when sky->environment is NULL (sky.c). */
lx_status lx_sky_prepare(lx_baker *b, const lx_sky_desc *sky);
void lx_sky_free(lx_baker *b);
/* Adds the sky's irradiance to accum for count texels from first. */
void lx_sky_tile(const lx_baker *b, uint32_t map_index, const lx_lightmap *map, uint32_t first,
                 uint32_t count, lx_vec3 *accum);

/* A mesh of a page for stitch.c: its lightmap UV set and the scale and
 * offset that take it into the page. */
typedef struct lx_stitch_mesh {
    const lx_mesh *mesh;
    int uv_set;
    double scale_offset[4];
} lx_stitch_mesh;
/* The seam samples of a width x height page holding meshes; *out NULL
 * when there are no seams. what names the page in errors. */
lx_status lx_seam_stitch_build(const lx_stitch_mesh *meshes, uint32_t count, int width,
                               int height, const char *what, lx_seam_stitch **out);
/* Stitches data (the page's pixels, `channels` floats each) in place. */
lx_status lx_seam_stitch_apply(const lx_seam_stitch *s, float *data, int channels,
                               const char *what);
uint32_t lx_seam_stitch_samples(const lx_seam_stitch *s);
void lx_seam_stitch_free(lx_seam_stitch *s);
/* gi.c: copies what finding a gather ray's hit needs (when desc.bounces
 * > 0); frees it; adds desc.bounces of indirect light into the baked
 * buffers, within [progress_base, progress_base + progress_span]. */
lx_status lx_gi_prepare(lx_baker *b, const lx_scene *scene);
void lx_gi_free(lx_baker *b);
lx_status lx_bake_indirect(lx_baker *b, float progress_base, float progress_span);
/* A material's emitted radiance in nits times scale, without texture. */
lx_vec3 lx_material_emission(const lx_material *mat, float scale);

/* bake_denoise.c: a copy of every map's baked buffer before the bounces
 * when desc.denoise is INDIRECT with bounces (else NULL, *st LX_OK);
 * its release; the denoising of every map within the given progress. */
float **lx_bake_denoise_keep(const lx_baker *b, lx_status *st);
void lx_bake_denoise_free(const lx_baker *b, float **direct);
lx_status lx_bake_denoise(lx_baker *b, float **direct, float progress_base, float progress_span);

lx_status lx_bake_lights(lx_baker *baker, const uint32_t *lights, uint32_t light_count,
                         lx_vec3 ambient, bool to_realtime, float progress_base,
                         float progress_span);

/* ---- memory and tiles (bake_tiles.c) ----------------------------------------
 * The one list of the bake's per-texel buffers (bytes per lightmap pixel:
 * the covered texels are bounded by the pixels), split into what stays in
 * memory for the whole bake (resident) and what a tile of lightmaps needs
 * while it is worked on. A new per-texel buffer is a line in that list. */
typedef struct lx_bake_texel_bytes {
    uint32_t resident; /* per pixel of every lightmap, for the whole bake */
    uint32_t tile;     /* per pixel of the lightmaps of the tile worked on */
} lx_bake_texel_bytes;
/* The bytes per pixel of a lightmap under desc: horizon when a node on it
 * has a height, dynamic when the scene has dynamic lights, tiled for a
 * bake in several tiles (its baked buffers stay resident). */
lx_bake_texel_bytes lx_bake_texel_bytes_of(const lx_bake_desc *desc, bool horizon, bool dynamic,
                                           bool tiled);
/* What the scene copy, the BVH and the gathers' mesh copies take. */
uint64_t lx_bake_scene_bytes(const lx_scene *scene, bool copy);
/* Makes sure the texel map of `map` is in memory: in a tiled baker, the
 * tile in memory is let go and map's tile rebuilt. */
lx_status lx_bake_tile_need(lx_baker *b, uint32_t map);
/* Lets go of a map's texel map, keeping what stays resident. */
void lx_bake_map_unload(lx_lightmap *map);
/* The progress share of tile t within [from, to] (by pixels). */
void lx_bake_tile_share(const lx_baker *b, uint32_t t, float from, float to, float *tfrom,
                        float *tto);
/* A lightmap lx_baker_create will build: its page, name and size. */
typedef struct lx_tile_candidate {
    char *name;
    lx_tile_page page;
    bool horizon;
    uint64_t pixels;
} lx_tile_candidate;
/* Decides whether the candidates fit the memory limit together or are
 * baked in tiles (b->tiled, b->memory_limit), and fails with one line
 * when even the resident part and the largest lightmap's working set do
 * not fit. */
lx_status lx_bake_plan_memory(lx_baker *b, const lx_scene *scene, const lx_tile_candidate *c,
                              uint32_t count, bool dynamic);
/* Groups the maps into tiles under b->memory_limit (after the maps are
 * built): resident bytes are counted for every map, tile bytes per tile. */
lx_status lx_bake_plan_tiles(lx_baker *b, const lx_scene *scene, bool dynamic);
/* A copy of the scene's meshes, materials and nodes (what texel maps are
 * built from), for a tiled baker. */
lx_status lx_bake_scene_copy(const lx_scene *scene, lx_scene **out);
/* The progress callback's answer at fraction f (true: go on). */
bool lx_bake_report(const lx_baker *b, float f);

#endif
