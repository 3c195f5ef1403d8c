/* The bounce-by-bounce brute-force reference for indirect light: every
 * texel against every texel with explicit visibility, written on the
 * test oracle of reference.h and nothing of src/bake or src/trace.
 *
 * Receivers are the used texels of the reference texel maps
 * (lx_ref_texel_map) of the given nodes at their centres. Senders are the
 * nodes' triangles cut into n^2 similar pieces (n = `sub` times the
 * triangle's longest UV edge in texels), each at its centroid with its
 * exact world area, so the senders tile the surfaces exactly; a piece
 * carries the radiance of the receiver texel its UV lies in (or the
 * nearest used one within two texels, for chart borders). A sender whose
 * centroid is in front of the receiver and faces it adds its radiance
 * times its exact polygon-to-point transfer (Lambert's contour integral,
 * so a piece next to the receiver is not treated as a point)
 * to the receiver's irradiance when the segment between the centroid
 * and the receiver is unoccluded (lx_ref_occluded, both ends moved off their surfaces by
 * lx_ref_bias along the geometric normals). With G the gather above:
 *     R_0 = emitted radiance,
 *     R_k+1 = albedo / pi (G[R_k] + (k == 0 ? direct irradiance : 0)),
 * and G[R_k] is the irradiance of light that left its last surface after
 * k reflections (k = 0: straight from emitters).
 *
 * The error left is the radiance being constant over each receiver
 * texel and visibility decided at piece centroids. Slow on purpose:
 * O(receivers x senders x triangles).
 */
#ifndef LX_TEST_BOUNCE_REFERENCE_H
#define LX_TEST_BOUNCE_REFERENCE_H

#include "reference.h"

/* The albedo (and emitted radiance, nits) of a texel; user is the
 * caller's. */
typedef void (*lx_bref_material_fn)(void *user, uint32_t node, const lx_ref_texel *texel,
                                    lx_vec3 *albedo, lx_vec3 *emitted);

typedef struct lx_bref_desc {
    const lx_scene *scene;
    const uint32_t *nodes; /* node_count nodes, each with lightmap UVs */
    uint32_t node_count;
    int width, height;     /* every node's map size */
    int sub;               /* senders per receiver side (>= 1) */
    int bounces;           /* >= 1 */
    lx_bref_material_fn material;
    void *user;
    /* direct[i][t]: node i's texel t direct irradiance (lux), NULL = none
     * (light then comes from emitters only) */
    const lx_vec3 *const *direct;
} lx_bref_desc;

typedef struct lx_bref_result {
    uint32_t node_count;
    int width, height, bounces;
    lx_ref_map *maps;   /* node_count receiver maps */
    /* irradiance[i][k * texels + t] = G[R_k] at node i's texel t, for
     * k = 0..bounces (bounces + 1 layers; texels = width * height) */
    lx_vec3 **irradiance;
} lx_bref_result;

void lx_bref_run(const lx_bref_desc *desc, lx_bref_result *out);
void lx_bref_free(lx_bref_result *r);

/* The indirect irradiance of `bounces` bounces at node i's texel t: the sum
 * of G[R_k] over k = 1..bounces (bounces <= r->bounces). */
lx_vec3 lx_bref_indirect(const lx_bref_result *r, uint32_t node, int texel, int bounces);

#endif
