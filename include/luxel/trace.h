/* luxel/trace.h - ray queries over a scene: occlusion and closest hit
 * through Intel Embree 3, over one flat world-space BVH of every node's
 * meshes. A node can move; the BVH is rebuilt at the next commit.
 *
 * CONVENTIONS  World space, metres. A ray covers origin + t*dir for t in
 *   [tmin, tmax]; dir need not be unit length (t is then in units of |dir|).
 *   Both faces of every triangle block rays. Which nodes a ray meets
 *   depends on its kind (lx_ray_kind) and the nodes' bake settings, read
 *   at lx_tracer_create.
 * ERRORS  lx_tracer_create fails with LX_ERR_NOMEM or LX_ERR_INVALID (an
 *   Embree error, named). Queries cannot fail.
 * MEMORY  The tracer copies the geometry it needs; the scene may be freed
 *   after lx_tracer_create. lx_tracer_destroy releases everything.
 * THREADING  lx_tracer_create is thread-safe. Queries (lx_tracer_occluded*,
 *   lx_tracer_closest, lx_tracer_nearest_distance) may run on many threads
 *   at once on one tracer, each thread with its own lx_ray_packet;
 *   lx_tracer_set_node_transform and lx_tracer_commit must not overlap
 *   queries or each other.
 *
 * USAGE
 *   lx_scene *scene;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK)
 *       return 1;
 *   lx_tracer *tr;
 *   if (lx_tracer_create(scene, NULL, &tr) != LX_OK) {
 *       lx_scene_destroy(scene);
 *       return 1;
 *   }
 *   lx_ray r = {.origin = {0, 1, 0}, .dir = {0, -1, 0}, .tmin = 0, .tmax = 10};
 *   bool blocked = lx_tracer_occluded(tr, &r); // the room's floor is below
 *   lx_ray_packet pk;                          // 16 coherent rays at once
 *   for (int i = 0; i < LX_RAY_PACKET; i++) {
 *       pk.origin_x[i] = -0.75f + 0.1f * (float)i, pk.origin_y[i] = 1, pk.origin_z[i] = 0;
 *       pk.dir_x[i] = 0, pk.dir_y[i] = -1, pk.dir_z[i] = 0;
 *       pk.tmin[i] = 0, pk.tmax[i] = 10;
 *   }
 *   uint32_t hit = lx_tracer_occluded_packet(tr, &pk, 0xFFFFu);
 *   int n = 0;
 *   for (int i = 0; i < LX_RAY_PACKET; i++)
 *       n += (hit >> i) & 1u;
 *   printf("down: %s; packet: %d of 16 blocked\n", blocked ? "blocked" : "free", n);
 *   lx_tracer_destroy(tr);
 *   lx_scene_destroy(scene);
 */
#ifndef LUXEL_TRACE_H
#define LUXEL_TRACE_H

#include "luxel/core.h"
#include "luxel/math.h"
#include "luxel/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lx_tracer lx_tracer;

typedef struct lx_ray {
    lx_vec3 origin;
    float tmin;
    lx_vec3 dir;
    float tmax;
} lx_ray;

typedef struct lx_hit {
    float t;           /* distance along the ray in units of |dir| */
    uint32_t node;     /* scene node index */
    uint32_t mesh;     /* scene mesh index */
    uint32_t triangle; /* triangle index in the mesh */
    float u, v;        /* barycentrics of vertices 1 and 2 */
    lx_vec3 normal;    /* unit world geometric normal of the triangle, by its
                          winding: (p1 - p0) x (p2 - p0), negated under a
                          node transform that mirrors (as glTF); a ray with
                          dot(dir, normal) > 0 hit its back face */
} lx_hit;

/* Kinds of rays: which nodes a ray meets, by their bake settings
 * (lx_node.bake, scene.h). The occlusion queries (lx_tracer_occluded*) and
 * lx_tracer_nearest_distance are shadow rays; lx_tracer_closest meets
 * every node; lx_tracer_closest_kind takes the kind. */
typedef enum lx_ray_kind {
    LX_RAY_ANY = 0, /* every node */
    LX_RAY_SHADOW,  /* nodes that cast shadows (bake.no_cast_shadows false):
                       the visibility of lights, the sky, AO and emitters */
    LX_RAY_GATHER,  /* nodes that take part in bounces (no_contribute_gi false) */
    LX_RAY_SURFACE, /* nodes that cast shadows or take part in bounces: what
                       light meets (samples moved out of geometry) */
    LX_RAY_CAMERA,  /* every node but sky domes (bake.sky): what a view shows */
    LX_RAY_FRAMING  /* nodes that get a lightmap and are not sky domes: what
                       the default camera frames */
} lx_ray_kind;

typedef struct lx_tracer_desc {
    int threads;             /* Embree's BVH-build threads, 0 = all cores */
    lx_progress_fn progress; /* hears the BVH build (fraction built); may be NULL;
                                returning false cancels it (LX_ERR_CANCELLED) */
    void *progress_user;
} lx_tracer_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_tracer_desc lx_tracer_desc_defaults(const lx_tracer_desc *desc);

/* Builds the ray structures for every node of scene. desc may be NULL. On
 * failure or cancellation *out stays NULL. */
lx_status lx_tracer_create(const lx_scene *scene, const lx_tracer_desc *desc, lx_tracer **out);
void lx_tracer_destroy(lx_tracer *tracer);

/* Moves a node; takes effect at the next lx_tracer_commit. */
lx_status lx_tracer_set_node_transform(lx_tracer *tracer, uint32_t node, const lx_mat4 *world);
/* Rebuilds the BVH after nodes moved (about a millisecond per 10k
 * triangles). */
lx_status lx_tracer_commit(lx_tracer *tracer);

/* True when a node that casts shadows blocks the ray within [tmin, tmax]
 * (every node does unless its bake.no_cast_shadows). The batch and packet
 * queries below are shadow rays too. */
bool lx_tracer_occluded(const lx_tracer *tracer, const lx_ray *ray);

/* Occlusion for count rays in one call; coherent hints that neighbouring
 * rays are similar (texels of one tile toward one light). occluded[i] is
 * 1 when ray i is blocked. */
void lx_tracer_occluded_batch(const lx_tracer *tracer, const lx_ray *rays, uint32_t count,
                              bool coherent, uint8_t *occluded);

/* Rays in one lx_tracer_occluded_packet call. */
#define LX_RAY_PACKET 16

#if defined(__cplusplus)
#define LX_ALIGN64 alignas(64)
#else
#define LX_ALIGN64 _Alignas(64)
#endif

/* LX_RAY_PACKET rays as structure of arrays (lane i of each field is ray
 * i), laid out as the tracer hands them to Embree, without a copy. Fill
 * origin, dir, tmin and tmax of the lanes you use; the rest is the
 * tracer's. 64-byte aligned: declare it, or allocate it with
 * aligned_alloc(64, ...). */
typedef struct lx_ray_packet {
    LX_ALIGN64 float origin_x[LX_RAY_PACKET];
    float origin_y[LX_RAY_PACKET];
    float origin_z[LX_RAY_PACKET];
    float tmin[LX_RAY_PACKET];
    float dir_x[LX_RAY_PACKET];
    float dir_y[LX_RAY_PACKET];
    float dir_z[LX_RAY_PACKET];
    float internal_time[LX_RAY_PACKET];  /* set by the tracer */
    float tmax[LX_RAY_PACKET];           /* a blocked lane's comes back negative */
    uint32_t internal[3][LX_RAY_PACKET]; /* set by the tracer */
} lx_ray_packet;

/* Occlusion of the lanes of packet whose bit is set in `active` (bit i =
 * lane i), traced together as one SIMD packet (Embree's rtcOccluded16; on
 * CPUs without 16-wide vectors Embree splits it). Returns the bits of the
 * active lanes that are blocked. Fastest for coherent rays: neighbouring
 * texels toward one light, where it traces 1.5-2.5x the rays per second of
 * lx_tracer_occluded_batch (bench_bake). The same ray gives the same answer
 * in any lane and any packet. */
uint32_t lx_tracer_occluded_packet(const lx_tracer *tracer, lx_ray_packet *packet, uint32_t active);

/* Nearest hit within [tmin, tmax] on any node; false when none. */
bool lx_tracer_closest(const lx_tracer *tracer, const lx_ray *ray, lx_hit *hit);
/* The same on the nodes a ray of `kind` meets. */
bool lx_tracer_closest_kind(const lx_tracer *tracer, const lx_ray *ray, lx_ray_kind kind,
                            lx_hit *hit);

/* Nearest hit from the origin on a node that casts shadows (the distance
 * to the occluder blurred shadows use), t only; INFINITY when none. */
float lx_tracer_nearest_distance(const lx_tracer *tracer, const lx_ray *ray);

/* Whether a triangle near the sphere (centre, radius) leaves the plane
 * n . x = d by more than tolerance: a conservative proximity test (a
 * triangle counts when its bounding box meets the sphere's), so false
 * means every triangle within radius of centre lies in the plane. Every
 * node counts, whatever its bake settings. */
bool lx_tracer_off_plane_near(const lx_tracer *tracer, lx_vec3 centre, float radius, lx_vec3 n,
                              float d, float tolerance);

#ifdef __cplusplus
}
#endif
#endif
