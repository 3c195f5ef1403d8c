/* Generated benchmark scenes and the helpers the bench/ programs share:
 *
 * - lx_test_spheres_scene: a lightmapped ground square under a grid of
 *   floating UV spheres (occluders without UVs) and 4 point lights with hard
 *   shadows; sizes are picked by the caller (~100k triangles for the full
 *   bake, ~10k for the real-time update). Deterministic: its own LCG,
 *   reseeded on every call.
 * - lx_bench_rays: the shadow rays a bake of lightmap 0 casts, regenerated
 *   through the public API (lx_baker_texel, lx_light_evaluate and
 *   src/bake/direct.c's origin/tmax rule) and grouped in the bake's 8x8
 *   tiles, light by light, so raw tracer throughput can be measured on
 *   exactly the same work; lx_bench_trace runs them through an lx_tracer.
 * - lx_bench_flat_*: the same rays straight through Embree on one flat BVH
 *   (rtcOccluded1, rtcOccluded1M, 4-, 8- and 16-wide packets).
 * - lx_test_write_glb / lx_test_write_lights_json: a scene as a .glb and
 *   its lights as a lights JSON, for running the CLI on it.
 * - the machine report: CPU model, load average, clock, SI-prefixed rates.
 *
 * Errors end the process with a message (these are benchmark tools). */
#ifndef LX_TEST_SCENES_H
#define LX_TEST_SCENES_H

#include "luxel/luxel.h"

#include <embree3/rtcore.h>

#define LX_BENCH_TILE 8   /* LX_TILE in src/bake/bake_internal.h */
#define LX_BENCH_LIGHTS 4 /* lights in every lx_test_spheres_scene */

/* ---- scenes -------------------------------------------------------------- */

/* The scenes' LCG: next value in [0, 1), and reseeding. */
float lx_test_rand(void);
void lx_test_rand_seed(uint32_t seed);

/* count UV spheres (slices x stacks, pole fans, outward winding, no
 * degenerate triangles) in one mesh with normals and no UVs. */
lx_mesh lx_test_spheres_mesh(const char *name, const lx_vec3 *centre, const float *radius,
                             int count, int slices, int stacks);

/* Point light k (0..3) of a scene of side `size`, `height` above the
 * ground, ~40 lux straight below it, hard shadows. */
lx_light lx_test_point_light(int k, float size, float height, bool dynamic);

typedef struct lx_test_scene_info {
    uint32_t triangles, ground_triangles, spheres, sphere_triangles, nodes;
} lx_test_scene_info;

/* A ground square of side size (2 * ground_n^2 triangles, TEXCOORD_1 over
 * [0,1]^2: node 0, the one lightmapped node) under grid x grid spheres
 * (one node per row of spheres) and LX_BENCH_LIGHTS point lights at 0.2 x
 * size above it (dynamic or not). */
lx_scene *lx_test_spheres_scene(const char *name, float size, int ground_n, int grid, int slices,
                                int stacks, bool dynamic, lx_test_scene_info *info);

/* n x n point lights (hard shadows, no range: every texel facing up sees
 * every one) on a jittered grid `height` above a ground of side size, each
 * giving ~40 lux straight below it. out holds n * n lights. */
void lx_test_grid_lights(int n, float size, float height, lx_light *out);

/* Writes scene's nodes and meshes (positions, normals, TEXCOORD_0/1 when
 * present, 32-bit indices, identity transforms) as a binary glTF 2.0 file;
 * lights are left out (give them in a lights JSON). Ends the process on
 * failure. */
void lx_test_write_glb(const lx_scene *scene, const char *path);

/* Writes point lights as a lights JSON (docs/lights-json.md): name,
 * position, colour, intensity in cd, shadow mode; floats printed so they
 * read back exactly. Ends the process on failure. */
void lx_test_write_lights_json(const lx_light *lights, uint32_t count, const char *path);

/* ---- the bake's shadow rays ---------------------------------------------- */

/* Rays grouped [tile][light][ray] exactly as the bake batches them. */
typedef struct lx_bench_rays {
    lx_ray *rays;
    lx_vec3 *illuminance; /* per ray, unshadowed */
    uint32_t *pixel;      /* per ray */
    uint32_t *batch;      /* tiles * lights + 1 offsets into rays */
    int tiles, lights;
    uint64_t samples;       /* used texels x lights */
    uint64_t count;         /* rays */
    uint64_t behind;        /* samples with no direct light (no ray) */
    lx_texel_sample *texel; /* used texels, tile by tile */
    uint32_t *tile_texel;   /* tiles + 1 offsets into texel */
    float bias;             /* the baker's automatic base bias */
} lx_bench_rays;

/* src/bake/direct.c's shadow ray for a sample at p (geometric normal ng). */
lx_ray lx_bench_shadow_ray(float base_bias, lx_vec3 p, lx_vec3 ng, const lx_light_eval *e);

/* The rays of lightmap 0 with the baker's current lights. */
void lx_bench_rays_build(const lx_baker *baker, const lx_scene *scene, lx_bench_rays *out);
void lx_bench_rays_free(lx_bench_rays *rs);

typedef enum lx_bench_trace_mode {
    LX_BENCH_SINGLE,          /* lx_tracer_occluded, one ray per call */
    LX_BENCH_BATCH,           /* lx_tracer_occluded_batch, coherent */
    LX_BENCH_BATCH_INCOHERENT /* lx_tracer_occluded_batch, incoherent */
} lx_bench_trace_mode;

/* Traces every ray once over the bake's tiles and OpenMP schedule; fills
 * occluded[ray] and returns the seconds taken. */
double lx_bench_trace(const lx_tracer *tracer, const lx_bench_rays *rs, lx_bench_trace_mode mode,
                      int threads, uint8_t *occluded);

/* ---- raw Embree on a flat BVH (what a user of raw Embree would build) ---- */

/* One Embree scene holding every triangle in world space, the tracer's
 * flags (robust, high build quality). */
RTCScene lx_bench_flat_scene(RTCDevice dev, const lx_scene *scene);

typedef enum lx_bench_flat_mode {
    LX_FLAT_1,       /* rtcOccluded1, one ray per call */
    LX_FLAT_1M,      /* rtcOccluded1M, coherent, a tile's rays toward a light */
    LX_FLAT_PACKET4, /* rtcOccluded4/8/16 on those rays in order, valid masks */
    LX_FLAT_PACKET8,
    LX_FLAT_PACKET16,
    LX_FLAT_PACKET16_BLOCKS, /* rtcOccluded16 on 4x4 blocks of full tiles */
    LX_FLAT_MODES
} lx_bench_flat_mode;

extern const char *const lx_bench_flat_names[LX_FLAT_MODES];

/* Traces every ray once over the bake's tiles and OpenMP schedule on
 * `threads`; fills occluded[ray] and returns the seconds taken. */
double lx_bench_flat_trace(lx_bench_flat_mode mode, RTCScene flat, const lx_bench_rays *rs,
                           int threads, uint8_t *occluded);

/* ---- report -------------------------------------------------------------- */

double lx_bench_now(void); /* monotonic seconds */

/* "program: what: lx_last_error()" on stderr, exit status 1. */
_Noreturn void lx_bench_die(const char *what);

/* Prints "program  machine: CPU, N logical CPUs, T threads, Embree x.y.z"
 * and the load average; later messages are prefixed with program. */
void lx_bench_header(const char *program, int threads);

/* The 1-minute load average from /proc/loadavg ("?" when unknown). */
const char *lx_bench_load(char *buf, size_t size);

/* v with an SI prefix: "12.30 M". buf holds >= 32 chars. */
const char *lx_bench_si(double v, char *buf);

#endif
