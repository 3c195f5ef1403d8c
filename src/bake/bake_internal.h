/* Private to src/bake: the baker's texel maps and lighting passes. */
#ifndef LX_BAKE_INTERNAL_H
#define LX_BAKE_INTERNAL_H

#include "luxel/bake.h"
#include "luxel/maps.h"
#include "luxel/trace.h"

/* ---- directional data (directional.c) ----------------------------------
 * Per texel, the order-1 spherical harmonics of the incoming radiance
 * (nits), world space, luxel's SH basis (ibl.h): 4 RGB coefficients, L00,
 * L1-1 (y), L10 (z), L11 (x), 12 floats. */
#define LX_SH_FLOATS 12
#define LX_SH_Y0 0.282095f
#define LX_SH_Y1 0.488603f

typedef struct lx_sh4 {
    float c[LX_SH_FLOATS];
} lx_sh4;

/* Radiance e (a delta: e is the illuminance on a surface facing it) from
 * unit direction d. */
static inline void lx_sh4_add_delta(lx_sh4 *s, lx_vec3 e, lx_vec3 d)
{
    float y[4] = {LX_SH_Y0, LX_SH_Y1 * d.y, LX_SH_Y1 * d.z, LX_SH_Y1 * d.x};
    for (int k = 0; k < 4; k++) {
        s->c[3 * k] += e.x * y[k];
        s->c[3 * k + 1] += e.y * y[k];
        s->c[3 * k + 2] += e.z * y[k];
    }
}

/* An irradiance a that is the same for every normal (the ambient terms):
 * a uniform radiance a / pi over the sphere, L00 = 4 Y00 a. */
static inline void lx_sh4_add_uniform(lx_sh4 *s, lx_vec3 a)
{
    s->c[0] += 4.0f * LX_SH_Y0 * a.x;
    s->c[1] += 4.0f * LX_SH_Y0 * a.y;
    s->c[2] += 4.0f * LX_SH_Y0 * a.z;
}

/* A contribution e (irradiance at the texel's normal n, lux) of light
 * arriving from unit direction d: a delta of e / (n . d), n . d taken as
 * at least `floor` (a point-like light is only lit above the horizon,
 * floor 1e-3; an area light's centre may sit below it while part of the
 * light is above, floor 0.1 keeps its delta within 10 e). */
static inline void lx_sh4_add_lit_floor(lx_sh4 *s, lx_vec3 e, lx_vec3 n, lx_vec3 d, float floor)
{
    float c = lx_dot(n, d);
    c = c > floor ? c : floor;
    float k = 1.0f / c;
    float y[4] = {LX_SH_Y0, LX_SH_Y1 * d.y, LX_SH_Y1 * d.z, LX_SH_Y1 * d.x};
    for (int i = 0; i < 4; i++) {
        s->c[3 * i] += e.x * k * y[i];
        s->c[3 * i + 1] += e.y * k * y[i];
        s->c[3 * i + 2] += e.z * k * y[i];
    }
}

static inline void lx_sh4_add_lit(lx_sh4 *s, lx_vec3 e, lx_vec3 n, lx_vec3 d)
{
    lx_sh4_add_lit_floor(s, e, n, d, 1e-3f);
}

static inline void lx_sh4_scale(lx_sh4 *s, float k)
{
    for (int i = 0; i < LX_SH_FLOATS; i++)
        s->c[i] *= k;
}

/* What gather ray k (of sx x sy cells, lx_cosine_direction about the
 * unit normal n) in unit direction d adds, times its radiance / N, to the
 * estimate of int L Y dw over the hemisphere (directional.c): *w0 for
 * L00 / Y00 and *v for L1 / Y1. Not 1 / pdf = pi / c (c = d . n), whose
 * variance has no bound toward the horizon, but per elevation stratum
 * (u = 1 - c^2 in [i / sx, (i + 1) / sx)) the means over it: L00 the mean
 * of pi / c, L1 along n pi (the cosine estimator), L1 across n the mean of
 * pi s / c over the mean of s (s = sqrt(u), the sine). Bounded, exact for
 * a constant sky, unbiased for radiance that does not change with
 * elevation within a stratum. */
static inline void lx_sh_ray_weight(uint32_t k, uint32_t sx, lx_vec3 d, lx_vec3 n, float *w0,
                                    lx_vec3 *v)
{
    uint32_t i = k % sx;
    double a = (double)i / sx, b = (double)(i + 1) / sx;
    if (b > 1.0)
        b = 1.0;
    double ca = sqrt(1.0 - a), cb = sqrt(1.0 - b), sa = sqrt(a), sb = sqrt(b);
    *w0 = (float)(2.0 * LX_PI * sx * (ca - cb));
    /* int sqrt(u / (1 - u)) du = asin(sqrt u) - sqrt(u (1 - u)) */
    double fa = asin(sa) - sa * ca, fb = asin(sb) - sb * cb;
    double mean_s = 2.0 / 3.0 * (sb * sb * sb - sa * sa * sa) * sx;
    double wt = mean_s > 0.0 ? LX_PI * (fb - fa) * sx / mean_s : 0.0;
    float c = lx_dot(d, n);
    *v = lx_add(lx_scale(n, LX_PI), lx_scale(lx_sub(d, lx_scale(n, c)), (float)wt));
}

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

/* Texel footprints per triangle of a page: the triangles of the pair
 * (node, mesh) of ranges[k] start at ranges[k].first; triangle t's two
 * axes are axes[2 (first + t)] and the next. ranges sorted by (node,
 * mesh). */
typedef struct lx_footprint_range {
    uint32_t node, mesh, first;
} lx_footprint_range;

typedef struct lx_texel_footprints {
    lx_vec3 *axes;
    lx_footprint_range *ranges;
    uint32_t range_count;
} lx_texel_footprints;

void lx_texel_footprints_free(lx_texel_footprints *f);

/* The world step of one texel along x ([0]) and along y ([1]) at texel
 * t, from its triangle's footprint (zero for a triangle without UV
 * area). */
static inline const lx_vec3 *lx_texel_axes(const lx_texel_footprints *f, const lx_texel *t)
{
    uint32_t lo = 0, hi = f->range_count - 1;
    while (lo < hi) { /* the last range at or before (node, mesh) */
        uint32_t mid = (lo + hi + 1) / 2;
        const lx_footprint_range *r = &f->ranges[mid];
        if (r->node < t->node || (r->node == t->node && r->mesh <= t->mesh))
            lo = mid;
        else
            hi = mid - 1;
    }
    return &f->axes[2 * ((size_t)f->ranges[lo].first + t->triangle)];
}

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

/* An emissive mesh as placed by a node (emitters.c). */
typedef struct lx_emitter_instance {
    uint32_t node, mesh;
} lx_emitter_instance;

/* The dynamic lights' bounce (dyn_bounce.c): each texel's cached gather
 * hits and the per-update buffers. */
typedef struct lx_dyn_bounce lx_dyn_bounce;

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
    /* the interpolated vertex normal, before the normal map, on a map with
     * normal-mapped texels (else NULL; object space as above): the bounces
     * gather about it, so a normal map's detail at the texels' scale does
     * not mottle the indirect light */
    lx_vec3 *world_smooth_normal, *object_smooth_normal;
    lx_vec3 *albedo; /* per texel base colour (factor x texture); NULL unless
                        the bake is of radiance or has bounces */
    lx_vec3 *emission; /* per texel emitted radiance (nits, emissive scale
                          applied); NULL unless bounces > 0 and a material
                          of the map emits */
    lx_texel_horizon *horizon; /* per texel; NULL when no texel's material has a height */
    /* per texel: from the facet to the smooth surface its vertex normals
     * describe (lx_lift_shadow_ray), world space, and object space when
     * the object arrays are kept; NULL when no mesh here is smooth-shaded */
    lx_vec3 *lift, *object_lift;
    uint8_t *mask;   /* width * height */
    float *baked;    /* width * height * 3 */
    float *realtime; /* width * height * 3; NULL (reads as zero) until the
                        first update with dynamic lights */
    float *sh;       /* width * height * LX_SH_FLOATS: the baked light's L1
                        spherical harmonics (directional.c); NULL unless
                        desc.directional */
    lx_seam_stitch *stitch; /* NULL: not asked, or no seams */
    float *gi_variance; /* width * height: the variance of the bounces' estimate
                           of each texel's luminance (the gathers' sample
                           variance over their rays, summed over the
                           bounces), the denoiser's guide; after a bake
                           with bounces that denoises them, else NULL */
    float *sampled; /* width * height * 3: the part of baked's direct light
                       estimated by sampling (the shadowed sky, soft
                       shadows, emitters), denoised apart under
                       --denoise indirect (lx_bake_sampled_begin); made
                       and freed by each such bake, else NULL; resident */
    float *sampled_variance; /* width * height: the variance of sampled's
                                luminance estimate (its samples' spread),
                                the denoiser's guide; with sampled */
    uint8_t *gi_valid; /* width * height, after a bake with bounces in which
                          a texel lay inside geometry (else NULL): 0 at
                          those texels, left out of the denoiser; resident */
    /* Texel supersampling (desc.supersample = N > 1): sub_count = N^2
     * points a texel, point s of texel i at [s * used_texels + i] (so
     * the arrays from s * used_texels on read like world_position);
     * sub_covered 0 where no triangle covers point s (it then holds the
     * texel's own sample and is left out of the mean). Object-space
     * copies exactly when the texel's are kept. sub_count 0: none. */
    uint32_t sub_count;
    lx_vec3 *sub_position, *sub_normal, *sub_geometric_normal;
    lx_vec3 *sub_object_position, *sub_object_normal, *sub_object_geometric_normal;
    uint8_t *sub_covered;
    /* Until lx_bake_straddle has run (then NULL; kept for edge
     * supersampling, until a node moves): the world step of one texel
     * along x and along y on each triangle of the page (the same for all
     * its texels), read through lx_texel_axes. */
    lx_texel_footprints *footprints;
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

/* The triangles of one (node, mesh) pair of double-sided meshes, from
 * first in lx_baker.side_flip (sides.c). */
typedef struct lx_side_range {
    uint32_t node, mesh;
    size_t first;
} lx_side_range;

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
    /* emitters (emitters.c): each emissive mesh's object-space positions
     * (NULL for the others), whether a texture modulates its emission, and
     * every node's emissive meshes */
    lx_vec3 **mesh_positions;
    uint8_t *mesh_emission_textured;
    lx_emitter_instance *emitters;
    uint32_t emitter_count;
    uint64_t gi_invalid_texels; /* found by the last bake */
    /* the dynamic lights' bounce (dyn_bounce.c); NULL until the first
     * update that needs it */
    lx_dyn_bounce *dyn;
    bool dyn_stale; /* a node moved: the cached hits are rebuilt */
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
    /* double-sided materials (sides.c): per scene mesh, whether both faces
     * are the surface; per triangle of the double-sided meshes of nodes
     * with a lightmap, sorted by (node, mesh), whether it bakes its back */
    uint8_t *mesh_double_sided;
    uint32_t double_sided_mesh_count;
    lx_side_range *side_ranges;
    uint32_t side_range_count;
    uint8_t *side_flip;
    bool sides_decided; /* lx_bake_sides has run: rebuilt maps turn too */
};

/* sides.c: decides which face of each double-sided triangle its texels
 * bake (once the maps and the tracer exist), and turns over the normals
 * of a map's texels that bake the back (every map loaded then, and every
 * map a tiled baker builds again). */
lx_status lx_bake_sides(lx_baker *b, const lx_scene *scene);
void lx_bake_sides_apply(const lx_baker *b, lx_lightmap *map);
void lx_bake_sides_free(lx_baker *b);
/* Whether triangle t of (node, mesh) bakes its back face. */
bool lx_bake_side_flipped(const lx_baker *b, uint32_t node, uint32_t mesh, uint32_t t);

/* Whether a ray along dir that hit h met the face a lightmap holds the
 * light of: a front face, or of a double-sided material the face its
 * texels bake (the back where lx_bake_sides turned them). The other face
 * of a double-sided surface brings nothing - its light is not baked -
 * but is no solid's inside either (lx_bake_hit_inside). False for a
 * grazing hit. */
static inline bool lx_bake_hit_surface(const lx_baker *b, lx_vec3 dir, const lx_hit *h)
{
    float c = lx_dot(dir, h->normal);
    if (!(h->mesh < b->double_sided_mesh_count && b->mesh_double_sided[h->mesh]))
        return c < 0.0f;
    return lx_bake_side_flipped(b, h->node, h->mesh, h->triangle) ? c > 0.0f : c < 0.0f;
}

/* Whether it met the back face of a single-sided material: the inside of
 * a solid. */
static inline bool lx_bake_hit_inside(const lx_baker *b, lx_vec3 dir, const lx_hit *h)
{
    return lx_dot(dir, h->normal) > 0.0f &&
           !(h->mesh < b->double_sided_mesh_count && b->mesh_double_sided[h->mesh]);
}

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

/* straddle.c: moves every texel sample of the maps in memory that lies
 * inside geometry (a floor texel half under a wall standing on it) to the
 * visible side and leaves such supersampling points out; frees their
 * footprints unless edge supersampling is to use them. Reports within [progress_base, + progress_span] when
 * report (LX_ERR_CANCELLED when told to stop). */
lx_status lx_bake_straddle(lx_baker *b, float progress_base, float progress_span, bool report);
/* Whether any texel of tile [first, first + count) of map (with its
 * footprints) could straddle: false when its texels lie in one plane and
 * every triangle within reach of their rays (a sphere around them, wide
 * enough for the texels' and their footprint points' rays) lies in that
 * plane too (the tile's own surface): then no ray along the surface from
 * a texel to a point of its footprint meets anything. */
bool lx_bake_tile_may_straddle(const lx_baker *b, const lx_lightmap *map, uint32_t first,
                               uint32_t count);

/* Adds the given lights (indices into baker->lights) into target
 * (width*height*3 floats per map), plus `ambient` at every texel
 * (direct.c). progress_base/progress_span place this pass in the whole
 * operation's progress. */
/* Shadow ray from texel position p with geometric normal ng toward e's
 * light (direct.c). */
lx_ray lx_shadow_ray(const lx_baker *b, lx_vec3 p, lx_vec3 ng, const lx_light_eval *e);
/* The shadow terminator (Hanika, "Hacking the Shadow Terminator", Ray
 * Tracing Gems II, 2021): a ray leaving a smooth-shaded facet below its
 * plane (the shading normal lit, the facet turned away) starts from the
 * smooth surface the vertex normals describe, the texel's lift above the
 * facet (texel_map.c), not from inside the mesh. Lift NULL: none. */
static inline lx_ray lx_lift_shadow_ray(lx_ray r, lx_vec3 ng, const lx_vec3 *lift, uint32_t texel)
{
    if (lift && lx_dot(ng, r.dir) < 0.0f)
        r.origin = lx_add(r.origin, lift[texel]);
    return r;
}

/* Stratified cosine-weighted directions (Malley's method), shared by the
 * sky's, the gathers' and AO's rays (sky.c): n rays as sx x sy cells
 * (sx = floor(sqrt n), at least 1), and ray k's direction about the unit
 * frame (t, bt, n), jittered by lx_random(map, pixel, k, key) and
 * (..., key + 1), so any thread count gives the same rays. */
void lx_cosine_strata(uint32_t count, uint32_t *sx, uint32_t *sy);
lx_vec3 lx_cosine_direction(lx_vec3 t, lx_vec3 bt, lx_vec3 n, uint32_t map, uint32_t pixel,
                            uint32_t k, uint32_t sx, uint32_t sy, uint32_t key);

/* Directions over the whole sphere for the light probes' rays (sky.c):
 * sx x sy of them (lx_cosine_strata's split), sx equal-area rings of sy
 * equally spaced azimuths, the rings' heights set so that the set
 * integrates every spherical harmonic of order <= 2 exactly (its mean of
 * z^2 is 1/3, odd moments and azimuthal terms vanish: a constant
 * environment projects onto L00 alone, to rounding), turned by a uniformly
 * random rotation m per probe (lx_sphere_rotation: lx_random(seed, index,
 * 0, key..key + 2)), so each direction is uniform on the sphere. */
void lx_sphere_rotation(uint32_t seed, uint32_t index, uint32_t key, float m[9]);
lx_vec3 lx_sphere_direction(const float m[9], uint32_t k, uint32_t sx, uint32_t sy);
/* The sky radiance an escaping ray in direction d brings (nits): with sky
 * shadows the filtered environment less its bright peak, else nothing
 * (the unshadowed sky is its SH). */
lx_vec3 lx_sky_radiance(const lx_baker *b, lx_vec3 d);
/* The sky's bright peak (when it has one) seen from p, projected onto
 * lx_sh9_basis and added to acc (radiance SH): count rays toward peak
 * texels chosen by importance, as the texels' sky rays, each that escapes
 * adding total x chroma x Y(d) / count; seeded by (seed, index, k, key..
 * key + 3). */
void lx_sky_peak_sh(const lx_baker *b, lx_vec3 p, uint32_t seed, uint32_t index, uint32_t count,
                    uint32_t key, double acc[9][3]);
/* Takes what the baker needs of a sky (SH, the lookup for rays); nothing
 * when sky->environment is NULL (sky.c). */
lx_status lx_sky_prepare(lx_baker *b, const lx_sky_desc *sky);
void lx_sky_free(lx_baker *b);
/* Adds the sky's irradiance to accum for count texels from first, its
 * directional data to sh (NULL: none), and the variance of its
 * luminance's estimate to variance (NULL: not asked; 0 unshadowed). */
void lx_sky_tile(const lx_baker *b, uint32_t map_index, const lx_lightmap *map, uint32_t first,
                 uint32_t count, lx_vec3 *accum, lx_sh4 *sh, float *variance);

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
/* gi.c: copies what finding a gather ray's hit needs (when the baker
 * keeps surfaces; emitters_only: only the emissive meshes, for the
 * emitters' direct light without bounces); frees it; adds desc.bounces of indirect light into the baked
 * buffers, within [progress_base, progress_base + progress_span]. */
lx_status lx_gi_prepare(lx_baker *b, const lx_scene *scene, bool emitters_only);
void lx_gi_free(lx_baker *b);
lx_status lx_bake_indirect(lx_baker *b, float progress_base, float progress_span);
/* A texel's gather frame (gi.c): the ray origin (lifted off the surface
 * along the geometric normal, as lx_shadow_ray does), its normals and the
 * tangents of the shading normal. */
typedef struct lx_gather_frame {
    lx_vec3 origin, n, ng, t, bt;
    uint32_t map, pixel;
} lx_gather_frame;
lx_gather_frame lx_gather_frame_of(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                                   uint32_t i);
/* Gather ray k of a frame: stratified cosine-weighted direction in cell k
 * of sx x sy about the shading normal, jittered by key; false when it
 * points below the geometric surface (it counts as dark). */
bool lx_gather_ray(const lx_gather_frame *f, uint32_t k, uint32_t sx, uint32_t sy, uint32_t key,
                   lx_ray *ray);
/* The gather rays a texel of bounce `bounce` (1 = the first) casts when
 * the bake asks for `samples`. */
uint32_t lx_gi_bounce_samples(uint32_t samples, int bounce);
/* Guided gathers (gi_guide.c): a histogram over the sphere of directions
 * (LX_GUIDE_SIDE^2 cells of the octahedral map) of where a tile's light
 * came from, and its alias table. */
#define LX_GUIDE_SIDE 32
#define LX_GUIDE_BINS (LX_GUIDE_SIDE * LX_GUIDE_SIDE)
typedef struct lx_gi_guide {
    float cell[LX_GUIDE_BINS];
    float prob[LX_GUIDE_BINS];  /* each cell's probability */
    float keep[LX_GUIDE_BINS];  /* the alias table: a cell drawn is kept */
    uint16_t alias[LX_GUIDE_BINS]; /* with probability keep, else its alias */
    bool ready; /* built and not empty */
} lx_gi_guide;
void lx_gi_guide_clear(lx_gi_guide *g);
/* value (a ray's luminance over its pdf) into dir's cell */
void lx_gi_guide_add(lx_gi_guide *g, lx_vec3 dir, float value);
/* Smooths the cells and makes the alias table; false (and not ready) when
 * empty. */
bool lx_gi_guide_build(lx_gi_guide *g);
/* A direction drawn from the guide with uniform numbers u (the cell), u1,
 * u2 (within it); its solid-angle pdf is lx_gi_guide_pdf. */
lx_vec3 lx_gi_guide_sample(const lx_gi_guide *g, float u, float u1, float u2);
float lx_gi_guide_pdf(const lx_gi_guide *g, lx_vec3 dir);
/* Where a point (barycentrics u, v of a triangle of mesh under node) lands
 * in its lightmap: the map and continuous texel coordinates (texel centres
 * at integers, clamped to [-1, w] x [-1, h]); false when the surface has
 * no lightmap. */
bool lx_gi_hit_texel(const lx_baker *b, uint32_t node, uint32_t mesh, uint32_t triangle, float u,
                     float v, uint32_t *map_index, float *fx, float *fy);
/* data (3 floats a pixel) at (fx, fy) of map: bilinear over the texels
 * `valid` (per pixel) marks, else the average of the valid texels of the
 * nearest ring (up to 3); zero when none. */
lx_vec3 lx_gi_lookup(const lx_lightmap *map, const uint8_t *valid, const float *data, float fx,
                     float fy);
/* The validity test: true when most of texel i's rays hit back faces. */
bool lx_gi_texel_inside(const lx_baker *b, uint32_t map_index, uint32_t i);
/* Gives the invalid texels (per texel flags) of buf (`channels` floats a
 * pixel, at most LX_SH_FLOATS) the average of their valid (per pixel
 * flags) or already filled neighbours, ring by ring. */
lx_status lx_gi_fill_invalid(const lx_lightmap *map, const uint8_t *valid, const uint8_t *invalid,
                             float *buf, int channels);
/* emitter_tree.c: a light tree over emissive triangles, each given by
 * its bounds (box, front normal, power = emission luminance x area > 0).
 * A pick for a receiving point (normal n) and one uniform number u walks
 * down by the children's importance; it gives the triangle, its
 * probability and u rescaled into the picked share (false: nothing in
 * the tree can light the point). lx_emitter_tree_probability is the
 * probability a pick gives a triangle (every path searched; for tests). */
typedef struct lx_emitter_bounds {
    lx_vec3 lo, hi, normal;
    double power;
} lx_emitter_bounds;
typedef struct lx_emitter_tree lx_emitter_tree;
lx_status lx_emitter_tree_build(const lx_emitter_bounds *tri, uint32_t count,
                                lx_emitter_tree **out);
void lx_emitter_tree_destroy(lx_emitter_tree *tree);
bool lx_emitter_tree_pick(const lx_emitter_tree *tree, lx_vec3 point, lx_vec3 normal, float u,
                          uint32_t *triangle, double *probability, float *u_rest);
double lx_emitter_tree_probability(const lx_emitter_tree *tree, lx_vec3 point, lx_vec3 normal,
                                   uint32_t triangle);
/* emitters.c: next-event estimation of the emissive triangles' light
 * (direct light, at any bounce count, when an emitter exists). The set of
 * emissive triangles is made once (NULL when nothing emits; a tiled
 * baker builds every map again to read textured emission), then each
 * tile's texels get their light added into the baked buffers of the maps
 * in memory, within [progress_base, progress_base + progress_span]. */
typedef struct lx_emitter_set lx_emitter_set;
lx_status lx_emitter_set_create(lx_baker *b, lx_emitter_set **out);
void lx_emitter_set_destroy(const lx_baker *b, lx_emitter_set *set);
lx_status lx_bake_emitters(lx_baker *b, const lx_emitter_set *set, float progress_base,
                           float progress_span);
/* dyn_bounce.c: one bounce of the real-time buffers' light (the dynamic
 * lights' direct light) added into them; its cache's release. */
lx_status lx_dyn_bounce_update(lx_baker *b);
void lx_dyn_bounce_free(lx_baker *b);
/* The exitant radiance of every lightmap's surface, what a ray that hits
 * it sees: per pixel a validity byte and RGB radiance (nits). */
typedef struct lx_radiance_source {
    const uint8_t *valid; /* width * height: 1 where source may be read */
    const float *source;  /* width * height * 3 */
} lx_radiance_source;
/* The exitant radiance a front-face hit h sees (gi.c): the hit surface's
 * source texels (sources[map], one per baker map), bilinear over the valid
 * ones (or the valid texels of the nearest ring around the hit's texel);
 * a surface without a lightmap reflects nothing and emits its material's
 * emission when `emission` is set. Needs lx_gi_prepare's mesh data. Used
 * by the gathers (gi.c) and the light probes (probes.c). */
lx_vec3 lx_hit_radiance(const lx_baker *b, const lx_radiance_source *sources, bool emission,
                        const lx_hit *h);
/* Whether a baker made with desc keeps what lx_hit_radiance reads: each
 * texel's albedo and emission and the meshes' UVs (bounces, the dynamic
 * lights' bounce, or probes). */
static inline bool lx_bake_keeps_surfaces(const lx_bake_desc *desc)
{
    return desc->bounces > 0 || desc->dynamic_bounce_samples > 0 || desc->probes;
}

/* The points a side edge supersampling gives a shadow edge's texels
 * (desc.edge_supersample), 0 when it is off. */
static inline int lx_bake_edge_supersample(const lx_bake_desc *desc)
{
    return desc->edge_supersample > 1 && desc->supersample <= 1 ? desc->edge_supersample : 0;
}

/* bake_denoise.c: the maps' sampled buffers (zeroed) when desc.denoise
 * is INDIRECT and the bake has a term estimated by sampling (the sky with
 * shadows, a static light with soft shadows, an emitter): the direct pass
 * fills them and the denoiser filters that part apart, with its own
 * variance, so the exact lights stay sharp; false (nothing made) when
 * there is none. Their release. */
lx_status lx_bake_sampled_begin(lx_baker *b, bool *made);
void lx_bake_sampled_end(lx_baker *b);
/* A copy of every map's exact direct light (the baked buffer less its
 * sampled part) when desc.denoise is INDIRECT with bounces (else NULL,
 * *st LX_OK); its release; the denoising of every map within the given
 * progress. */
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
/* What the scene asks of a bake beyond its desc (lx_bake_scene_needs). */
enum {
    LX_SCENE_NEEDS_DYNAMIC = 1u << 0,          /* a dynamic light */
    LX_SCENE_NEEDS_EMISSIVE_TEXTURE = 1u << 1, /* an emissive material with a texture */
    LX_SCENE_NEEDS_EMISSION = 1u << 2,         /* an emissive material */
    LX_SCENE_NEEDS_LIFT = 1u << 3,             /* a smooth-shaded mesh (lx_mesh_is_smooth) */
    LX_SCENE_NEEDS_SMOOTH_NORMAL = 1u << 4,    /* a material with a normal map */
};
/* Whether a mesh's vertex normals leave some triangle's plane (smooth
 * shading, where the shadow terminator needs lifted rays). */
bool lx_mesh_is_smooth(const lx_mesh *mesh);
uint32_t lx_bake_scene_needs(const lx_scene *scene);
/* The bytes per pixel of a lightmap under desc: horizon when a node on it
 * has a height; needs from lx_bake_scene_needs. The same buffers whether
 * the bake is tiled or not; tiled, a tile's are let go. */
lx_bake_texel_bytes lx_bake_texel_bytes_of(const lx_bake_desc *desc, bool horizon,
                                           uint32_t scene_needs);
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
                              uint32_t count, uint32_t scene_needs);
/* Groups the maps into tiles under b->memory_limit (after the maps are
 * built): resident bytes are counted for every map, tile bytes per tile. */
lx_status lx_bake_plan_tiles(lx_baker *b, const lx_scene *scene, uint32_t scene_needs);
/* A copy of the scene's meshes, materials and nodes (what texel maps are
 * built from), for a tiled baker. */
lx_status lx_bake_scene_copy(const lx_scene *scene, lx_scene **out);
/* The progress callback's answer at fraction f (true: go on). */
bool lx_bake_report(const lx_baker *b, float f);

/* One parallel loop over the texel tiles of every map in memory (every
 * map unless the baker is tiled), as each pass walks them: a global tile
 * index per iteration, progress counted in texels plus one per tile (so
 * empty tiles count), reported by thread 0 every `every` tiles within
 * [base, base + span]; cancelled once the callback says stop.
 *
 *     lx_tile_walk w;
 *     if ((st = lx_tile_walk_begin(b, base, span, 1, &w)) != LX_OK) return st;
 *     #pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
 *     for (int g = 0; g < w.tiles; g++) {
 *         if (w.cancelled) continue;
 *         uint32_t m, first, count;
 *         lx_tile_walk_at(&w, g, &m, &first, &count);
 *         ...texels first .. first + count - 1 of map m...
 *         lx_tile_walk_done(&w, g, count);
 *     }
 *     return lx_tile_walk_end(&w); (LX_ERR_CANCELLED when cancelled) */
typedef struct lx_tile_walk {
    const lx_baker *b;
    uint32_t *map_first_tile; /* map_count + 1 */
    int tiles;
    int every;
    bool quiet; /* no progress reports (nor cancel) */
    uint64_t total_work, done_work;
    float base, span;
    volatile int cancelled;
} lx_tile_walk;
lx_status lx_tile_walk_begin(const lx_baker *b, float base, float span, int every,
                             lx_tile_walk *w);
void lx_tile_walk_at(const lx_tile_walk *w, int global, uint32_t *map, uint32_t *first,
                     uint32_t *count);
void lx_tile_walk_done(lx_tile_walk *w, int global, uint32_t count);
lx_status lx_tile_walk_end(lx_tile_walk *w);

#endif
