/* luxel/bake.h - per-texel lightmaps: every node that carries meshes gets a
 * lightmap over its lightmap UVs; texels are mapped to world space by
 * rasterizing the triangles in UV space, lit by the scene's lights with
 * hard, blurred or no shadows, plus ambient, and padded by dilation.
 * The baker is also the seed's real-time path: texel map and ray structures
 * are built once; dynamic lights are re-evaluated by lx_baker_update while
 * static lights stay baked, and lx_baker_apply combines the two.
 *
 * CONVENTIONS  Lightmap UVs are TEXCOORD_1 when a mesh has them, else
 *   TEXCOORD_0 (with a warning). Texel (x, y), row 0 at the top, has its
 *   centre at UV ((x+0.5)/W, (y+0.5)/H). Outputs are irradiance in lux
 *   (LX_QUANTITY_IRRADIANCE) or outgoing radiance of a Lambertian surface
 *   in nits: irradiance * base colour / pi (LX_QUANTITY_RADIANCE). Lights
 *   using the classic model add in their own units.
 * ERRORS  lx_baker_create names the mesh and the problem (zero-area UV
 *   triangles, no lightmap fits in memory, no node covering a single
 *   texel: LX_ERR_INVALID rather than black lightmaps). Overlapping UVs,
 *   meshes without UVs, UVs outside [0,1] and a node that covers no texel
 *   while others do are warnings through lx_log.
 * MEMORY  lx_baker_create copies what it needs from the scene (the scene
 *   may be destroyed afterwards). Info structs are borrowed until
 *   lx_baker_destroy.
 * THREADING  lx_baker_create, lx_dilate (on distinct images) and the
 *   *_desc_defaults are thread-safe; several bakers may run on different
 *   threads at once. One baker is used from one thread at a time (every
 *   lx_baker_* call on it, the read-only ones included, while another may
 *   change it); it runs OpenMP over texel tiles internally, at most
 *   desc.threads threads, and its results are bit-identical for any thread
 *   count. lx_dilate runs at most its desc's threads, bit-identical too.
 *   The long calls (lx_baker_create, _bake, _update, _apply, lx_dilate)
 *   report to their progress callback, which is called from one thread at
 *   a time, not always the caller's, and returning false cancels
 *   (LX_ERR_CANCELLED; what each call leaves is said at the call).
 *
 * USAGE
 *   lx_scene *scene;
 *   lx_baker *b;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK) return 1;
 *   lx_bake_desc d = lx_bake_desc_defaults(NULL);
 *   d.resolution = 64;
 *   d.padding = LX_PADDING_RECOMMENDED;
 *   lx_status st = lx_baker_create(scene, &d, &b);
 *   lx_scene_destroy(scene);                              // the baker keeps a copy
 *   if (st != LX_OK) return 1;
 *   lx_image img;
 *   if (lx_baker_bake(b) == LX_OK && lx_baker_apply_alloc(b, 0, &img) == LX_OK) {
 *       lx_image_write("room.exr", &img, NULL);           // irradiance in lux
 *       lx_image_free(&img);
 *   }
 *   lx_baker_destroy(b);
 */
#ifndef LUXEL_BAKE_H
#define LUXEL_BAKE_H

#include "luxel/core.h"
#include "luxel/ibl.h"
#include "luxel/light.h"
#include "luxel/math.h"
#include "luxel/scene.h"
#include "luxel/unwrap.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lx_baker lx_baker;

typedef enum lx_quantity {
    LX_QUANTITY_IRRADIANCE = 0, /* lux */
    LX_QUANTITY_RADIANCE        /* nits, irradiance * base colour / pi */
} lx_quantity;

/* Which UV set holds a node's lightmap UVs. */
typedef enum lx_uv_choice {
    LX_UV_SET_AUTO = 0, /* luxel's own lightmap set, else TEXCOORD_1, else TEXCOORD_0
                           (lx_bake_uv_set) */
    LX_UV_SET_0,        /* TEXCOORD_0 */
    LX_UV_SET_1         /* TEXCOORD_1 */
} lx_uv_choice;

/* The lightmap UV set of scene node `node` under `choice`: the set named,
 * or for LX_UV_SET_AUTO the set luxel writes lightmap UVs to
 * (lx_scene_lightmap_set) when that is above TEXCOORD_1 - a set no material
 * reads, so one luxel wrote - and every mesh of the node that has UVs has
 * it; else TEXCOORD_1 when every such mesh has it; else TEXCOORD_0.
 * Whether the meshes have it is the caller's to check. */
int lx_bake_uv_set(const lx_scene *scene, uint32_t node, lx_uv_choice choice);

/* lx_lightmap_info.uv_set of an atlas page whose nodes use different sets. */
#define LX_UV_SET_MIXED (-1)

/* Dilation around the charts: none (the library's default), or the texels
 * `luxel bake` uses unless told otherwise. */
#define LX_PADDING_NONE 0
#define LX_PADDING_RECOMMENDED 2
#define LX_MAX_LIGHTMAP_SIZE 16384

/* Sky light: every texel lit by an environment (radiance in nits, luxel's
 * IBL conventions, ibl.h). Unshadowed, the irradiance of its order-2
 * spherical harmonics at the texel's normal; with shadows, the mean of
 * cosine-weighted rays over the texel's hemisphere that escape the scene,
 * each bringing the environment it sees (pi / N sum L). lx_baker_create
 * rejects an environment with NaN, infinite or negative texels, or whose
 * brightest texel times intensity exceeds 1e36 nits. */
/* The face size a sky environment is worth loading at
 * (lx_env_load_desc.size): enough for its order-2 spherical harmonics,
 * and more than the 64 texels a side sky shadows look it up at. */
#define LX_SKY_ENVIRONMENT_SIZE 256

/* Global illumination: the bounces `luxel bake` makes unless told, the
 * most the baker takes, and the gather rays per texel. */
#define LX_BOUNCES_RECOMMENDED 2
#define LX_MAX_BOUNCES 64
#define LX_GI_SAMPLES_DEFAULT 128u
#define LX_MAX_GI_SAMPLES 65536u
/* Adaptive gathers (lx_bake_desc.gi_adaptive): the relative standard
 * error a tile's rounds aim at. */
#define LX_GI_ADAPTIVE_NOISE 0.025
/* The dynamic lights' one bounce (lx_baker_update): the gather rays per
 * texel a real-time user should start from, and the most taken. */
#define LX_DYNAMIC_BOUNCE_SAMPLES_RECOMMENDED 16u
#define LX_MAX_DYNAMIC_BOUNCE_SAMPLES 1024u

/* Texel supersampling (lx_bake_desc.supersample): at most this many
 * sample points a side, N x N a texel. */
#define LX_MAX_SUPERSAMPLE 16
/* Edge supersampling (lx_bake_desc.edge_supersample): the points a side
 * `luxel bake` gives the texels on a hard shadow's edge unless told. */
#define LX_EDGE_SUPERSAMPLE_RECOMMENDED 4

/* What a bake's denoising filters (`luxel bake --denoise off|indirect|all`). */
typedef enum lx_denoise_mode {
    LX_DENOISE_OFF = 0,  /* nothing: out = direct + indirect */
    LX_DENOISE_INDIRECT, /* the indirect part, direct added back: out = direct + F(indirect) */
    LX_DENOISE_ALL       /* the sum: out = F(direct + indirect) */
} lx_denoise_mode;

/* Directional lightmaps (`luxel bake --directional sh|dominant`), for
 * normal-mapped surfaces at run time; docs/directional.md. */
typedef enum lx_directional_mode {
    LX_DIRECTIONAL_OFF = 0, /* irradiance only */
    LX_DIRECTIONAL_SH,      /* L1 spherical harmonics per texel (lx_baker_sh) */
    LX_DIRECTIONAL_DOMINANT /* a dominant direction per texel (lx_baker_dominant) */
} lx_directional_mode;

typedef struct lx_sky_desc {
    const lx_cubemap *environment; /* NULL = no sky; read by lx_baker_create only */
    float intensity;               /* multiplier, 0 = 1 */
    bool shadows;                  /* rays through the scene: sky visibility */
    uint32_t samples;              /* rays per texel with shadows, 0 = 64 */
} lx_sky_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_sky_desc lx_sky_desc_defaults(const lx_sky_desc *desc);

/* How the bounces' gather rays are drawn (lx_bake_desc.gi_sampling). */
typedef enum lx_gi_sampling {
    LX_GI_SAMPLING_GUIDED = 0, /* the default: a quarter of each texel's rays
                                  cosine-weighted, teaching its 8 x 8 texel
                                  tile where the light comes from; the rest
                                  half cosine-weighted, half toward that
                                  light, weighed by multiple importance
                                  sampling: unbiased, and no longer exact
                                  under constant light. A bounce of fewer
                                  than 64 rays a texel is not guided (too
                                  few to learn from); directional data come
                                  from the cosine-weighted rays alone */
    LX_GI_SAMPLING_COSINE      /* every ray cosine-weighted, stratified */
} lx_gi_sampling;

/* Which face of a double-sided material's surface (glTF doubleSided) its
 * texels bake (lx_bake_desc.double_sided): a texel holds one value, and a
 * view draws it on both faces. */
typedef enum lx_double_sided {
    LX_DOUBLE_SIDED_AUTO = 0, /* the default: the front (the winding's), unless
                                 no viewer can be in front of it - per
                                 triangle, when its front is closed in within
                                 a metre (at most a tenth of 32 camera rays
                                 reach open space) and its back is open (a
                                 quarter or more): then the back, normals
                                 turned over (a pond's water or a stepping
                                 stone modelled facing down, an inside-out
                                 mesh) */
    LX_DOUBLE_SIDED_FRONT     /* always the front (Unity's and Bakery's
                                 lightmappers) */
} lx_double_sided;

typedef struct lx_bake_desc {
    int resolution;      /* texels per side for every lightmap, 0 = 256 */
    float texel_density; /* texels per metre; > 0 sizes each lightmap from its
                            world and UV areas, rounded to a multiple of 4 */
    int max_resolution;  /* cap for texel_density sizes, 0 = 4096 */
    lx_quantity quantity;
    int padding;            /* texels of dilation around the charts, 0..64; 0 = none
                               (the one field whose zero is a value, not a default;
                               luxel bake uses LX_PADDING_RECOMMENDED) */
    bool stitch_seams;      /* make texels across UV seams agree (lx_baker_apply,
                               after the padding): where a surface crosses from
                               one chart to another, bilinear lookups on both
                               sides then read the same light, and no line shows.
                               Off by default (texels near seams then hold their
                               own texel's light exactly); luxel bake turns it on */
    int threads;            /* 0 = all cores */
    bool strict;            /* zero-UV-area triangles fail the bake instead of
                               being left out with one warning per mesh */
    float shadow_bias;      /* ray origin offset in metres, 0 = scale-aware auto */
    lx_uv_choice uv_set;    /* the lightmap UV set of every node (without an atlas) */
    const lx_unwrap *atlas; /* NULL: a lightmap per node; else one per page of
                               this layout (lx_unwrap_scene, applied to the
                               scene with lx_unwrap_apply), each node's UVs
                               placed by its scale_offset; borrowed by
                               lx_baker_create only */
    lx_sky_desc sky;        /* baked with the static lights */
    /* Indirect diffuse light (global illumination, see "GLOBAL
     * ILLUMINATION" above lx_baker_bake). */
    int bounces;           /* 0..LX_MAX_BOUNCES; 0 = direct light only (the
                              library's default, like padding's zero a value;
                              luxel bake uses LX_BOUNCES_RECOMMENDED) */
    uint32_t gi_samples;   /* gather rays per texel of the first bounce (half,
                              at least 16, of the later ones: they carry
                              albedo times less light and read the smoother
                              light of the one before), and the emitters'
                              shadow rays (at most 256), 1..
                              LX_MAX_GI_SAMPLES, 0 = LX_GI_SAMPLES_DEFAULT */
    lx_gi_sampling gi_sampling; /* GUIDED (the default) or COSINE;
                              `luxel bake --gi-sampling` */
    lx_double_sided double_sided; /* AUTO (the default) or FRONT; `luxel bake
                              --double-sided`. Either way the bounces, the
                              light probes and the samples moved out of
                              geometry take both faces of a double-sided
                              material for its surface, never for the
                              inside of a solid */
    bool gi_adaptive;      /* gather in rounds of gi_samples / 4 rays (at
                              least 4): after the first, each 8 x 8 texel
                              tile takes as many rounds (2 to 16, up to
                              4 x gi_samples rays) as its texels' mean
                              relative variance a ray asks for a standard
                              error of LX_GI_ADAPTIVE_NOISE (of a texel's
                              light, or of a tenth of the bounce's mean for
                              dark texels): the rays go where the noise is.
                              One count a tile, not a texel: a texel judged
                              by its own rays stops early when they missed
                              the bright part, and leaves a dark blotch.
                              false (the default): gi_samples rays for
                              every texel; `luxel bake --gi-adaptive` */
    float emissive_scale;  /* multiplies the emissive materials' radiance
                              (nits); 0 = 1 */
    lx_denoise_mode denoise; /* edge-aware denoising of the baked buffers at the
                              end of lx_baker_bake (denoise.h): OFF (the
                              library's default), INDIRECT (the bounces' part
                              only; nothing without bounces) or ALL; luxel bake
                              uses INDIRECT */
    uint32_t dynamic_bounce_samples; /* the dynamic lights' one bounce in
                              lx_baker_update: cached gather rays per texel,
                              0..LX_MAX_DYNAMIC_BOUNCE_SAMPLES; 0 = none (the
                              library's default, like bounces' zero a value:
                              the update then stays direct light only, as
                              before); LX_DYNAMIC_BOUNCE_SAMPLES_RECOMMENDED
                              (16) for real time. Independent of bounces. */
    bool probes;           /* keep what lx_baker_probes reads of the surfaces
                              (each texel's albedo and emission, the meshes'
                              UVs: 12-24 bytes a texel), kept anyway with
                              bounces > 0 */
    lx_directional_mode directional; /* OFF (default), SH or DOMINANT: the baked
                              light's directions kept per texel (48 bytes a
                              texel more); either mode allows both
                              lx_baker_sh and lx_baker_dominant. Texels are
                              then baked with the interpolated vertex normal:
                              normal maps are left to run time */
    int supersample;       /* 1..LX_MAX_SUPERSAMPLE, 0 = 1: each texel's direct
                              light (lights, ambient, sky) is the mean over the
                              N x N stratified points of its footprint that a
                              triangle covers (thin features, hard shadow
                              edges); gathers, AO and the dynamic lights'
                              real-time buffers keep the texel's one point. Costs N^2 times the direct pass and about
                              40 N^2 bytes a texel more (72 N^2 for a map of a
                              node away from the identity) */
    int edge_supersample;  /* 0..LX_MAX_SUPERSAMPLE; 0 or 1 = off (the
                              library's default); N: a texel whose hard
                              shadows differ from a neighbour's (a shadow's
                              edge crosses it: some point or spot light or
                              the sun reaches one and not the other) gets
                              its direct light again as the mean over N x N
                              points of its footprint, as supersample does
                              for every texel (Bakery's antialiasing): smooth
                              shadow edges for a few texels' cost. Points
                              the texel's centre cannot see along its
                              surface (under a wall) are left out. Ignored
                              with supersample > 1; luxel bake uses
                              LX_EDGE_SUPERSAMPLE_RECOMMENDED. Only the
                              lights whose shadows differ around the texel
                              are shaded again. 20 bytes a texel while the
                              direct light is baked */
    /* Memory and scale (see "MEMORY AND TILES" above lx_baker_tile_count). */
    uint64_t memory_limit;  /* bytes the bake may take; 0 (or more than the
                               machine has) = what the machine has: its
                               physical memory, control group and rlimits */
    uint32_t caller_bytes_per_texel; /* bytes the caller holds per lightmap
                               pixel while the baker lives (luxel bake: the
                               applied RGB float images it keeps until it
                               writes them, 12, and AO's 4): counted as
                               resident in the limit; 0 = none */
    lx_progress_fn progress;
    void *progress_user;
} lx_bake_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in,
 * the sky's included (lx_sky_desc_defaults). */
lx_bake_desc lx_bake_desc_defaults(const lx_bake_desc *desc);

typedef struct lx_lightmap_info {
    uint32_t node;    /* scene node index; UINT32_MAX for an atlas page of
                         several nodes */
    const char *name; /* node name, or "lightmap-<k>" for atlas page k */
    int width, height;
    int uv_set;              /* n = TEXCOORD_n, or LX_UV_SET_MIXED */
    uint32_t used_texels;    /* texels covered by triangles */
    uint32_t overlap_texels; /* texels claimed by two triangles' interiors */
} lx_lightmap_info;

/* Builds the texel maps of every node with UVs and the ray structures.
 * A texel sample that lies inside geometry (a floor texel whose centre is
 * under a wall standing on the floor) moves along its surface to the
 * visible side, within its texel, when its own surface continues there
 * outside every solid (docs/ARCHITECTURE.md, the texel map); it then
 * bakes like its visible part instead of dark. lx_baker_texel reports
 * the moved position.
 * Lights are copied from scene->lights, ambient from scene->ambient.
 * desc->progress, when set, hears the texel maps (the first 90%) and the
 * BVH build (the rest) and may stop either (LX_ERR_CANCELLED, *out stays
 * NULL). */
lx_status lx_baker_create(const lx_scene *scene, const lx_bake_desc *desc, lx_baker **out);
void lx_baker_destroy(lx_baker *baker);

/* MEMORY AND TILES  lx_baker_create adds up what the bake takes (the
 * scene, its BVH, and per lightmap pixel the buffers listed in
 * docs/bake.md: 260 bytes a pixel with luxel bake's defaults). When
 * that exceeds desc.memory_limit (default: what the machine has) the
 * lightmaps are baked in tiles: runs of whole lightmaps whose texel maps
 * and working buffers fit beside what stays for the whole bake (each
 * map's mask and baked light, the bounces' sources: 38 bytes a pixel
 * with bounces, 50 denoising their part, plus caller_bytes_per_texel,
 * and a copy of the scene).
 * Each pass (direct light, validity, each bounce, denoising, update,
 * apply, AO, metering, lx_baker_texel) builds a tile's texel maps again
 * from that copy, works on it and lets it go, so the light is exactly the
 * untiled bake's (same bytes) at the cost of rebuilding texel maps. When
 * even the resident part and the largest lightmap's working set do not
 * fit, lx_baker_create fails with LX_ERR_NOMEM and one line naming the
 * memory needed and available; a single lightmap is never split. Moving
 * a node (lx_baker_set_node_transform) in a tiled baker moves it in the
 * copy: texel maps are then built where it stands. */
/* The tiles the baker works in: 1 when every lightmap fits at once. */
uint32_t lx_baker_tile_count(const lx_baker *baker);

uint32_t lx_baker_lightmap_count(const lx_baker *baker);
/* Borrowed until lx_baker_destroy. */
const lx_lightmap_info *lx_baker_lightmap_info(const lx_baker *baker, uint32_t map);
/* The lightmap holding scene node `node` and the scale and offset that
 * take the node's lightmap UVs into it (Unity's lightmapScaleOffset: uv *
 * xy + zw; (1, 1, 0, 0) for a lightmap of its own). false when the node
 * has none (no UVs, no meshes). */
bool lx_baker_node_lightmap(const lx_baker *baker, uint32_t node, uint32_t *map,
                            float scale_offset[4]);

/* width*height bytes, 1 where a texel is covered. Borrowed. */
const uint8_t *lx_baker_mask(const lx_baker *baker, uint32_t map);

/* Bakes the static (non-dynamic) lights, ambient and sky, then
 * desc.bounces of indirect diffuse light. LX_ERR_CANCELLED when the
 * progress callback asks to stop (the baked buffers are then zero).
 *
 * GLOBAL ILLUMINATION  Direct light is the lights, the ambient and the sky
 * seen directly; indirect light is everything reflected at least once, or
 * emitted by a surface (an emissive material). Each bounce k gathers, at
 * every valid texel, desc.gi_samples stratified cosine-weighted rays
 * (seeded by map, texel and sample: bit-identical for any thread count);
 * a ray that hits the front of a lightmapped surface brings that
 * surface's bounce k-1 exitant radiance, base colour / pi x irradiance,
 * read bilinearly over the valid texels of its lightmap; E_k = pi / N x
 * sum. A ray that escapes brings nothing (the sky it sees is direct
 * light, already baked), a back face nothing (of a double-sided
 * material: the face its texels do not bake). Surfaces without a
 * lightmap (no UVs) reflect nothing.
 * EMITTERS  An emissive surface (emissiveFactor x emissiveTexture x
 * KHR_materials_emissive_strength x desc.emissive_scale, nits, from its
 * front face) is direct light at any bounce count: its triangles are
 * importance-sampled (luminance x area) with shadow rays,
 * min(gi_samples, 256) a texel, and their exact unshadowed irradiance
 * (Lambert's polygon formula) is the control variate while the scene has
 * at most 64 emissive triangles, so only penumbrae are noisy; the
 * gathers do not count emission again. With N bounces emitted light is
 * then reflected up to N times, as the lights' is (emitters.c).
 * A texel whose rays mostly hit back faces of single-sided materials is
 * inside geometry: it is
 * invalid, takes no part in the bounces, and gets the average of its
 * valid neighbours. The result is direct + E_1 + ... + E_bounces, in the
 * same units; emission itself is not in the lightmaps (the material
 * draws it). Dynamic lights get one bounce in lx_baker_update when
 * desc.dynamic_bounce_samples > 0 (see there). Memory while baking:
 * about 50 bytes a texel (albedo, validity, the sources and two
 * irradiance buffers), plus 12 per texel of an emissive material; with
 * desc.directional 48 more a texel, kept (the SH), and 48 during the
 * bounces. */
lx_status lx_baker_bake(lx_baker *baker);

/* Light access: index as in scene->lights. Changing a static light takes
 * effect at the next lx_baker_bake, a dynamic one at the next update.
 * Turning a static light dynamic counts it twice (baked and real-time)
 * until the next lx_baker_bake. */
uint32_t lx_baker_light_count(const lx_baker *baker);
const lx_light *lx_baker_light(const lx_baker *baker, uint32_t light);
lx_status lx_baker_set_light(lx_baker *baker, uint32_t light, const lx_light *value);

/* Moves a node (the seed's "moving meshes"): its texels and the ray
 * structures follow at the next update. Baked light on it is not rebaked. */
lx_status lx_baker_set_node_transform(lx_baker *baker, uint32_t node, const lx_mat4 *world);

/* Re-evaluates the dynamic lights into the real-time buffers. Reports to
 * desc.progress like lx_baker_bake (leave it NULL for per-frame use).
 * With desc.dynamic_bounce_samples = N > 0 the dynamic lights also get one
 * diffuse bounce through the lightmaps: the first update that needs it
 * (and the first after lx_baker_set_node_transform) traces and caches N
 * stratified cosine-weighted gather rays per texel and the texels'
 * validity, as lx_baker_bake's bounces do; every update then reads
 * albedo / pi x the dynamic direct light at the cached hits (bilinear over
 * valid texels) and adds pi / N x their sum - no rays. The bounce is that
 * of lx_baker_bake with bounces = 1 for the same light, with N samples'
 * noise (N rounded up to whole strata, sx x sy). Cost: 12 x N + 1 bytes
 * per texel and 13 per lightmap pixel while the baker lives (193 and 13
 * at N = 16); per update about N bilinear reads per texel
 * (bench_realtime; docs/ARCHITECTURE.md, "The dynamic lights' bounce").
 * Bit-identical for any thread count. */
lx_status lx_baker_update(lx_baker *baker);

/* baked + real-time for one lightmap, in the desc's quantity, padded by
 * desc.padding passes of lx_dilate. out must be a 3-channel image of the
 * lightmap's size. Reports the dilation to desc.progress (0 to 1 for this
 * map) and stops when told (LX_ERR_CANCELLED); on any failure out's
 * pixels are zeroed. */
lx_status lx_baker_apply(const lx_baker *baker, uint32_t map, lx_image *out);
/* Same into a newly allocated image (free with lx_image_free). */
lx_status lx_baker_apply_alloc(const lx_baker *baker, uint32_t map, lx_image *out);
/* The seed's apply: saturated 8-bit RGBA (exposure multiplier, then clamp;
 * sRGB-encoded when srgb). out must hold width*height*4 bytes. */
lx_status lx_baker_apply_rgba8(const lx_baker *baker, uint32_t map, float exposure, bool srgb,
                               uint8_t *out);

typedef struct lx_texel_sample {
    lx_vec3 position; /* world, on the triangle */
    lx_vec3 normal;   /* world shading normal (normal map applied) */
    lx_vec3 geometric_normal;
    uint32_t mesh;     /* scene mesh index */
    uint32_t triangle; /* triangle in that mesh */
    uint32_t node;     /* scene node that places the mesh */
} lx_texel_sample;

/* The world-space sample of texel (x, y); false when it is not covered. */
bool lx_baker_texel(const lx_baker *baker, uint32_t map, int x, int y, lx_texel_sample *out);

/* The EV100 that exposes the mean luminance of every covered texel of
 * every lightmap (baked + real-time, in the desc's quantity; irradiance
 * metered as a white Lambertian surface, E / pi) to middle grey
 * (lx_ev100_from_luminance). *lit gets false, and *ev100 0, when that mean
 * is 0: every lightmap is black. */
void lx_baker_meter_ev100(const lx_baker *baker, float *ev100, bool *lit);

/* ---- directional lightmaps ---------------------------------------------------
 * With desc.directional set, lx_baker_bake keeps per texel the order-1
 * spherical harmonics of the baked (static) light's incoming radiance, in
 * nits, world space, in luxel's SH basis (ibl.h): L00 (Y00 = 0.282095),
 * L1-1 (0.488603 y), L10 (0.488603 z), L11 (0.488603 x); L_lm = int
 * L(w) Y_lm(w) dw. Lights, ambient and sky seen directly and the bounces
 * all count, each as the irradiance holds it: a light as a delta from its
 * direction at the texel (area lights from their centre), the ambient
 * terms as a uniform radiance over the sphere, an unshadowed sky as its
 * own L0 and L1, sky and gather rays over the texel's hemisphere. The
 * irradiance for a unit normal n is (Ramamoorthi & Hanrahan's cosine
 * lobe) E(n) = pi Y00 L00 + 2 pi / 3 (L1-1 Y1-1(n) + L10 Y10(n) + L11
 * Y11(n)). Real-time (dynamic) lights are not in it. Denoising filters
 * the coefficients with the guides' weights alone (docs/directional.md). */

/* The 4 coefficient images of lightmap `map` (RGB each, the lightmap's
 * size, allocated here: free each with lx_image_free): out[0] L00, out[1]
 * L1-1 (y), out[2] L10 (z), out[3] L11 (x), padded and stitched like
 * lx_baker_apply, 0 outside the charts. LX_ERR_INVALID when the baker was
 * made without desc.directional or map is out of range; out zeroed on
 * failure. */
lx_status lx_baker_sh(const lx_baker *baker, uint32_t map, lx_image out[4]);

/* Unity's directional lightmap of `map` (RGBA, allocated here): rgb = d /
 * 2 + 1/2, d the luminance-weighted mean direction the light comes from
 * (|d| <= 1 is its directionality: 1 for a single light, 0 for light from
 * every side equally), a = the half-Lambert of the texel's normal n,
 * (n . d) / 2 + 1/2 (Unity's rebalancing coefficient). A shader draws
 * lightmap x ((n' . d) / 2 + 1/2) / a for the normal-mapped n'. Padded
 * like lx_baker_apply; fails as lx_baker_sh. */
lx_status lx_baker_dominant(const lx_baker *baker, uint32_t map, lx_image *out);

/* ---- ambient occlusion lightmaps --------------------------------------------
 * The share of a texel's cosine-weighted hemisphere that is open within
 * `distance` metres, as Bakery, Unity and Unreal bake it: 1 in the open, 0
 * fully enclosed. Stratified cosine-weighted rays from the texel (seeded
 * by map, texel and sample: the same bytes for any thread count); a ray
 * that meets any surface, either face, within the distance is occluded,
 * and so is a direction below the texel's geometric surface. Under a
 * large parallel ceiling at height h < distance the exact value is
 * (h / distance)^2. */
#define LX_AO_DISTANCE_DEFAULT 1.0f /* metres, Unity's default */
#define LX_AO_SAMPLES_DEFAULT 256u
#define LX_MAX_AO_SAMPLES 65536u

typedef struct lx_ao_desc {
    float distance;          /* metres, > 0; 0 = LX_AO_DISTANCE_DEFAULT */
    uint32_t samples;        /* rays per texel, 1..LX_MAX_AO_SAMPLES; 0 = default */
    int threads;             /* 0 = the baker's desc.threads */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_ao_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_ao_desc lx_ao_desc_defaults(const lx_ao_desc *desc);

/* The ambient occlusion of lightmap `map` into *out (one channel, the
 * lightmap's size, allocated here; free with lx_image_free): AO at
 * covered texels, padded like lx_baker_apply (the baker's desc.padding
 * passes of lx_dilate), 0 elsewhere. Reads the scene as the baker holds it
 * (nodes where they were last placed). Fails with LX_ERR_INVALID for a
 * distance that is not finite and > 0 or samples out of range,
 * LX_ERR_CANCELLED when the progress callback says so; *out is zeroed on
 * failure. */
lx_status lx_baker_ao(lx_baker *baker, uint32_t map, const lx_ao_desc *desc, lx_image *out);

/* ---- light probes ------------------------------------------------------------
 * Irradiance probes for dynamic objects, as engines place them (Unity's
 * light probes, Godot's LightmapGI probes): at each point, the incident
 * radiance over the whole sphere projected onto order-2 (L2) real
 * spherical harmonics, 9 RGB coefficients in ibl.h's lx_sh9 (the basis and
 * order of lx_sh9_basis, luxel's axes, +Y up).
 *
 * CONVENTION  The coefficients are RADIANCE coefficients (nits), L_lm =
 *   integral of L(w) Y_lm(w) dw, NOT convolved with the cosine lobe. An
 *   engine gets the irradiance (lux) at unit normal n by Ramamoorthi and
 *   Hanrahan's equation 13 (lx_sh_irradiance):
 *     E(n) = sum_lm A_l L_lm Y_lm(n),  A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4
 *   and a diffuse surface of albedo a shows a / pi x E(n) (nits). A
 *   constant environment of radiance L has L_00 = 2 sqrt(pi) L and
 *   E = pi L for every normal.
 * WHAT A PROBE HOLDS  Everything the probe sees, as the bake left it:
 *   - desc.samples rays over the sphere: equal-area rings of equally
 *     spaced directions that integrate every order-2 harmonic exactly (a
 *     constant environment gives L_00 alone, to rounding), turned by a
 *     random rotation per probe (seeded by the probe's index: the same
 *     bytes for any thread count, each ray uniform on the sphere); a ray
 *     that hits the front of a lightmapped surface brings its exitant
 *     radiance, albedo / pi x the baked irradiance (direct + every bounce,
 *     denoised as baked) + its emission, read as the gathers of the bake
 *     read it; a surface without a lightmap brings its material's emission;
 *   - a ray that escapes brings the sky it sees (with sky shadows; the
 *     sky's bright part, a sun, by rays toward it chosen by importance);
 *     an unshadowed sky is added whole from its SH, as the bake adds it to
 *     every texel;
 *   - the static lights seen from the probe: a point, spot or directional
 *     light is a delta, its illuminance at normal incidence E (lux, the
 *     light model's, range and cone included) times Y_lm toward it, times
 *     its visibility by one shadow ray (every shadow mode but NONE is hard
 *     at a probe); an area light by points on its surface (its soft-shadow
 *     samples, at least LX_PROBE_AREA_SAMPLES_MIN), each bringing
 *     luminance x cos / d^2 x its area share when not blocked;
 *     classic-model lights by the same delta with their formula's N.L
 *     taken as 1;
 *   - the scene's and the lights' ambient (lux, for any normal): a
 *     constant radiance ambient / pi.
 *   Dynamic lights are not in the probes (engines light dynamic objects
 *   with them directly).
 * VALIDITY  A probe whose rays mostly hit back faces (of single-sided
 * materials) sits inside geometry
 *   (the test of the bake's texel validity): valid = false, coefficients
 *   zero. */
#define LX_PROBE_SAMPLES_DEFAULT 256u
#define LX_MAX_PROBE_SAMPLES 65536u
#define LX_PROBE_AREA_SAMPLES_MIN 256u

typedef struct lx_probe_desc {
    uint32_t samples;        /* rays per probe, 1..LX_MAX_PROBE_SAMPLES; 0 =
                                LX_PROBE_SAMPLES_DEFAULT; rounded up to
                                sx rings of sy, sx = floor(sqrt(samples)),
                                sy = ceil(samples / sx) */
    int threads;             /* 0 = the baker's desc.threads */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_probe_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_probe_desc lx_probe_desc_defaults(const lx_probe_desc *desc);

typedef struct lx_probe {
    lx_sh9 sh;              /* radiance SH (nits), zero when not valid */
    bool valid;             /* false: inside geometry */
    float back_face_share;  /* the share of its rays that hit back faces */
} lx_probe;

/* The light probes at count points (world, metres) into out[count], after
 * lx_baker_bake (before it, surfaces are black). The baker must keep its
 * surfaces (desc.probes or bounces > 0), else LX_ERR_INVALID. Fails with
 * LX_ERR_INVALID for a point that is not finite or samples out of range,
 * LX_ERR_CANCELLED when the progress callback says so (out is then
 * zeroed). Reads the scene as the baker holds it (nodes where they were
 * last placed). Bit-identical for any thread count. Memory while it
 * runs: 12 bytes a lightmap pixel (the surfaces' exitant radiance). */
lx_status lx_baker_probes(lx_baker *baker, const lx_vec3 *points, uint32_t count,
                          const lx_probe_desc *desc, lx_probe *out);

/* The nx * ny * nz probe positions of a grid over the box [lo, hi]: the
 * centres of its cells, lo + (i + 0.5) / nx (hi - lo) along x (so no probe
 * sits on the box's faces, where a room's walls are), x fastest, then y,
 * then z: out[(k * ny + j) * nx + i]. Each count 1..LX_MAX_PROBE_GRID and
 * at most LX_MAX_PROBES probes in all, lo <= hi finite, else
 * LX_ERR_INVALID. out must hold nx * ny * nz points. */
#define LX_MAX_PROBE_GRID 1024
#define LX_MAX_PROBES (1u << 24)
lx_status lx_probe_grid(lx_vec3 lo, lx_vec3 hi, int nx, int ny, int nz, lx_vec3 *out);

/* Threads and progress of lx_dilate. desc may be NULL (all cores, no
 * progress). */
typedef struct lx_dilate_desc {
    int threads;             /* at most this many threads, 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_dilate_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_dilate_desc lx_dilate_desc_defaults(const lx_dilate_desc *desc);

/* Fills unused texels (mask 0) from used neighbours, one ring per pass, so
 * bilinear sampling and mips do not bleed black: each pass gives every
 * empty texel with a filled 8-neighbour the average of those neighbours
 * as the previous pass left them (summed in float, rows dy = -1..1, then
 * dx = -1..1), and marks it 1 in mask. Stops early when nothing grows.
 * Bit-identical for any thread count; the time follows the texels filled
 * (plus one scan of the mask), not passes x image.
 * data holds width*height*channels floats, mask width*height bytes
 * (nonzero = filled); channels 1..4, passes >= 0 (0 does nothing), at most
 * 2^32 - 1 texels, else LX_ERR_INVALID. Scratch memory is a byte a texel
 * plus the frontiers (and a copy of the empty texels it fills whose value
 * was not zero). desc->progress hears the passes; on LX_ERR_CANCELLED or
 * LX_ERR_NOMEM data and mask are left as they were. */
lx_status lx_dilate(float *data, uint8_t *mask, int width, int height, int channels, int passes,
                    const lx_dilate_desc *desc);

#ifdef __cplusplus
}
#endif
#endif
