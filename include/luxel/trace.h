/* luxel/trace.h - ray queries over a scene: occlusion and closest hit
 * through Intel Embree 3, over one flat world-space BVH of every node's
 * meshes. A node can move; the BVH is rebuilt at the next commit.
 *
 * CONVENTIONS  World space, metres. A ray covers origin + t*dir for t in
 *   [tmin, tmax]; dir need not be unit length (t is then in units of |dir|).
 *   Both faces of every triangle block rays.
 * ERRORS  lx_tracer_create fails with LX_ERR_NOMEM or LX_ERR_INVALID (an
 *   Embree error, named). Queries cannot fail.
 * MEMORY  The tracer copies the geometry it needs; the scene may be freed
 *   after lx_tracer_create. lx_tracer_destroy releases everything.
 * THREADING  lx_tracer_create* is thread-safe. Queries (lx_tracer_occluded*,
 *   lx_tracer_closest, lx_tracer_nearest_distance) may run on many threads
 *   at once on one tracer; lx_tracer_set_node_transform and
 *   lx_tracer_commit must not overlap queries or each other.
 *
 * USAGE
 *   lx_scene *scene;
 *   lx_tracer *tr;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK) return 1;
 *   if (lx_tracer_create(scene, &tr) != LX_OK) { lx_scene_destroy(scene); return 1; }
 *   lx_ray r = {.origin = lx_v3(0, 1, 0), .dir = lx_v3(0, -1, 0), .tmin = 0, .tmax = 100};
 *   lx_hit hit;
 *   if (lx_tracer_closest(tr, &r, &hit)) printf("floor %g m below\n", hit.t);
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
} lx_hit;

/* Builds the ray structures for every node of scene. */
lx_status lx_tracer_create(const lx_scene *scene, lx_tracer **out);
/* The same with Embree's own build threads held to `threads` (0 = all
 * cores), for callers that bound their thread count. */
lx_status lx_tracer_create_threads(const lx_scene *scene, int threads, lx_tracer **out);
void lx_tracer_destroy(lx_tracer *tracer);

/* Moves a node; takes effect at the next lx_tracer_commit. */
lx_status lx_tracer_set_node_transform(lx_tracer *tracer, uint32_t node, const lx_mat4 *world);
/* Rebuilds the BVH after nodes moved (about a millisecond per 10k
 * triangles). */
lx_status lx_tracer_commit(lx_tracer *tracer);

/* True when anything blocks the ray within [tmin, tmax]. */
bool lx_tracer_occluded(const lx_tracer *tracer, const lx_ray *ray);

/* Occlusion for count rays in one call; coherent hints that neighbouring
 * rays are similar (texels of one tile toward one light). occluded[i] is
 * 1 when ray i is blocked. */
void lx_tracer_occluded_batch(const lx_tracer *tracer, const lx_ray *rays, uint32_t count,
                              bool coherent, uint8_t *occluded);

/* Nearest hit within [tmin, tmax]; false when none. */
bool lx_tracer_closest(const lx_tracer *tracer, const lx_ray *ray, lx_hit *hit);

/* Nearest hit from the origin, t only; INFINITY when none. Cheaper than
 * lx_tracer_closest when only the distance matters. */
float lx_tracer_nearest_distance(const lx_tracer *tracer, const lx_ray *ray);

#ifdef __cplusplus
}
#endif
#endif
