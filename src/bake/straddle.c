/* Texels that straddle a wall: a texel at a chart border, or any texel
 * whose footprint runs under another surface (a floor texel whose centre
 * lies just under a wall standing on the floor), has its sample point
 * inside geometry, where every shadow ray is blocked and every gather ray
 * sees back faces: it bakes dark, the dark line production lightmappers'
 * users know at wall-floor junctions. The fix follows Bakery's
 * "adjust samples" and lightmapper.h's notes on hidden texels: rays are
 * cast from the sample along the surface, in the eight directions of the
 * texel's footprint (its two axes and their diagonals, from the UV to
 * world map of its triangle), lifted off the surface by the shadow bias;
 * when the first thing one of them hits within the texel's half-diagonal
 * is a back face, the sample sits inside that geometry and moves, along
 * the surface, to just past the nearest such hit where its own surface
 * continues outside every solid (acceptable()): the visible side of the
 * wall, still within the texel's footprint. A supersampling point whose
 * first hit along one of the footprint's four axis directions, within the
 * texel's whole diagonal, is a back face lies under the wall: it is left
 * out of the texel's mean (the part of the texel nobody can see). Rays
 * depend on the texel alone, so any thread count moves the same samples.
 *
 * Limitation: single-sided geometry seen from behind looks like the
 * inside of a solid; a sample within half a texel of the back of a
 * single-sided wall moves through it. Both faces of a double-sided
 * material are surface (lx_bake_hit_inside): no sample moves through one. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>

/* The unit direction of v along the surface of normal n; false when v
 * has no part along it. */
static bool along_surface(lx_vec3 v, lx_vec3 n, lx_vec3 *out)
{
    lx_vec3 d = lx_sub(v, lx_scale(n, lx_dot(v, n)));
    float len = lx_length(d);
    if (!(len > 0.0f) || !isfinite(len))
        return false;
    *out = lx_scale(d, 1.0f / len);
    return true;
}

/* The first hit of a ray from p (lifted by lift along ng) in direction d
 * within reach: 1 front face, -1 back face (its distance in *t), 0 none. */
static int first_hit(const lx_baker *b, lx_vec3 p, lx_vec3 ng, float lift, lx_vec3 d, float reach,
                     float *t)
{
    lx_ray ray = {.origin = lx_madd(p, ng, lift), .dir = d, .tmin = 0.0f, .tmax = reach};
    lx_hit hit;
    if (!lx_tracer_closest_kind(b->tracer, &ray, LX_RAY_SURFACE, &hit))
        return 0;
    *t = hit.t;
    /* both faces of a double-sided material are surface, no solid's inside */
    return lx_bake_hit_inside(b, d, &hit) ? -1 : 1;
}

/* v through the inverse of m's upper 3x3 (Cramer's rule, in double);
 * false when m is singular. */
static bool inverse_vector(const lx_mat4 *m, lx_vec3 v, lx_vec3 *out)
{
    /* columns of the 3x3 */
    double a[3] = {m->m[0], m->m[1], m->m[2]}, b[3] = {m->m[4], m->m[5], m->m[6]},
           c[3] = {m->m[8], m->m[9], m->m[10]}, r[3] = {v.x, v.y, v.z};
#define DET3(x, y, z)                                                                             \
    ((x)[0] * ((y)[1] * (z)[2] - (y)[2] * (z)[1]) - (y)[0] * ((x)[1] * (z)[2] - (x)[2] * (z)[1]) + \
     (z)[0] * ((x)[1] * (y)[2] - (x)[2] * (y)[1]))
    double det = DET3(a, b, c);
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return false;
    *out = lx_v3((float)(DET3(r, b, c) / det), (float)(DET3(a, r, c) / det),
                 (float)(DET3(a, b, r) / det));
#undef DET3
    return true;
}

/* Whether texel i's sample may move to `to`: its own surface (the same
 * node's mesh) is under it, and none of the footprint's rays from there
 * meets a back face first, however far (it is inside no other solid;
 * seen from behind, single-sided geometry counts as a solid, so moves
 * stay conservative). A texel sandwiched between two solids, or one whose way out
 * leaves its own surface (a face buried in a wall up to its edge), stays
 * where it is: the bounces' validity test finds it inside and leaves it
 * out. */
static bool acceptable(const lx_baker *b, const lx_lightmap *map, uint32_t i, lx_vec3 to,
                       lx_vec3 ng, float lift, const lx_vec3 *dirs, uint32_t nd)
{
    lx_ray down = {.origin = lx_madd(to, ng, lift), .dir = lx_neg(ng), .tmin = 0.0f,
                   .tmax = 2.0f * lift};
    lx_hit hit;
    if (!lx_tracer_closest(b->tracer, &down, &hit) || hit.node != map->texels[i].node ||
        hit.mesh != map->texels[i].mesh)
        return false;
    for (uint32_t k = 0; k < nd; k++) {
        float t;
        if (first_hit(b, to, ng, lift, dirs[k], b->scene_diagonal, &t) < 0)
            return false;
    }
    return true;
}

/* One texel: moves its sample when it is inside geometry and marks its
 * hidden supersampling points; returns whether it moved. */
static bool straddle_texel(const lx_baker *b, lx_lightmap *map, uint32_t i)
{
    const lx_vec3 *axes = lx_texel_axes(map->footprints, &map->texels[i]);
    lx_vec3 ax = axes[0], ay = axes[1];
    float half = 0.5f * fmaxf(lx_length(lx_add(ax, ay)), lx_length(lx_sub(ax, ay)));
    if (!(half > 0.0f) || !isfinite(half))
        return false;
    lx_vec3 p = map->world_position[i], ng = map->world_geometric_normal[i];
    float lift = b->bias + 4e-6f * lx_max_abs_component(p);
    const lx_vec3 step[8] = {ax,
                             lx_neg(ax),
                             ay,
                             lx_neg(ay),
                             lx_add(ax, ay),
                             lx_neg(lx_add(ax, ay)),
                             lx_sub(ax, ay),
                             lx_neg(lx_sub(ax, ay))};
    lx_vec3 dirs[8];
    uint32_t nd = 0;
    for (int k = 0; k < 8; k++)
        if (along_surface(step[k], ng, &dirs[nd]))
            nd++;
    /* the sample: the back faces within the half-diagonal, nearest
     * first; any hit within the diagonal says geometry is near (then the
     * points look) */
    float dist[8];
    uint32_t order[8], exits = 0;
    bool near = false;
    for (uint32_t k = 0; k < nd; k++) {
        float t;
        int h = first_hit(b, p, ng, lift, dirs[k], 2.0f * half, &t);
        near |= h != 0;
        if (h < 0 && t <= half) {
            uint32_t j = exits++;
            for (; j > 0 && dist[j - 1] > t; j--) {
                dist[j] = dist[j - 1];
                order[j] = order[j - 1];
            }
            dist[j] = t;
            order[j] = k;
        }
    }
    bool moved = false;
    for (uint32_t e = 0; e < exits && !moved; e++) {
        lx_vec3 offset = lx_scale(dirs[order[e]], dist[e] + 2.0f * lift);
        lx_vec3 to = lx_add(p, offset);
        if (!acceptable(b, map, i, to, ng, lift, dirs, nd))
            continue;
        map->world_position[i] = to;
        if (map->object_position) {
            lx_vec3 local;
            if (inverse_vector(&b->node_world[map->texels[i].node], offset, &local))
                map->object_position[i] = lx_add(map->object_position[i], local);
        }
        moved = true;
    }
    if (!near || map->sub_count == 0)
        return moved;
    size_t used = map->info.used_texels;
    for (uint32_t s = 0; s < map->sub_count; s++) {
        size_t at = s * used + i;
        if (!map->sub_covered[at])
            continue;
        lx_vec3 q = map->sub_position[at], qg = map->sub_geometric_normal[at];
        float qlift = b->bias + 4e-6f * lx_max_abs_component(q);
        for (int k = 0; k < 4; k++) {
            lx_vec3 d;
            float t;
            if (along_surface(step[k], qg, &d) &&
                first_hit(b, q, qg, qlift, d, 2.0f * half, &t) < 0) {
                map->sub_covered[at] = 0;
                break;
            }
        }
    }
    return moved;
}

/* Most tiles of open floors and walls, at one point query each instead
 * of eight rays a texel (bake_internal.h). */
bool lx_bake_tile_may_straddle(const lx_baker *b, const lx_lightmap *map, uint32_t first,
                               uint32_t count)
{
    lx_vec3 n = map->world_geometric_normal[first], lo = map->world_position[first], hi = lo;
    float d = lx_dot(n, map->world_position[first]), reach = 0.0f, tolerance = INFINITY;
    for (uint32_t i = first; i < first + count; i++) {
        lx_vec3 p = map->world_position[i];
        float lift = b->bias + 4e-6f * lx_max_abs_component(p);
        tolerance = fminf(tolerance, 0.5f * lift);
        if (lx_dot(map->world_geometric_normal[i], n) < 0.99999f)
            return true;
        const lx_vec3 *axes = lx_texel_axes(map->footprints, &map->texels[i]);
        lx_vec3 ax = axes[0], ay = axes[1];
        float half = 0.5f * fmaxf(lx_length(lx_add(ax, ay)), lx_length(lx_sub(ax, ay)));
        if (!isfinite(half))
            return true;
        reach = fmaxf(reach, 3.0f * half + 2.0f * lift);
        lo = lx_v3(fminf(lo.x, p.x), fminf(lo.y, p.y), fminf(lo.z, p.z));
        hi = lx_v3(fmaxf(hi.x, p.x), fmaxf(hi.y, p.y), fmaxf(hi.z, p.z));
    }
    for (uint32_t i = first; i < first + count; i++)
        if (fabsf(lx_dot(n, map->world_position[i]) - d) > tolerance)
            return true;
    lx_vec3 centre = lx_scale(lx_add(lo, hi), 0.5f);
    float radius = 0.5f * lx_length(lx_sub(hi, lo)) + reach;
    return lx_tracer_off_plane_near(b->tracer, centre, radius, n, d, tolerance);
}

lx_status lx_bake_straddle(lx_baker *b, float progress_base, float progress_span, bool report)
{
    if (b->tracer_dirty) {
        lx_status st = lx_tracer_commit(b->tracer);
        if (st != LX_OK)
            return st;
        b->tracer_dirty = false;
    }
    lx_tile_walk w;
    lx_status st = lx_tile_walk_begin(b, progress_base, progress_span, 1, &w);
    if (st != LX_OK)
        return st;
    if (!report)
        w.quiet = true;
    int64_t moved = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : moved)                             \
    num_threads(lx_thread_count(b->desc.threads))
    for (int global = 0; global < w.tiles; global++) {
        if (w.cancelled)
            continue;
        uint32_t m, first, count;
        lx_tile_walk_at(&w, global, &m, &first, &count);
        lx_lightmap *map = &b->maps[m];
        bool may = count && map->footprints && lx_bake_tile_may_straddle(b, map, first, count);
        for (uint32_t i = first; may && i < first + count; i++)
            moved += straddle_texel(b, map, i);
        lx_tile_walk_done(&w, global, count);
    }
    if ((st = lx_tile_walk_end(&w)) != LX_OK)
        return st;
    if (moved)
        lx_log(LX_LOG_INFO, "%lld texel samples moved out of geometry", (long long)moved);
    /* edge supersampling places its points by the footprints too */
    for (uint32_t m = 0; m < b->map_count && !lx_bake_edge_supersample(&b->desc); m++) {
        lx_texel_footprints_free(b->maps[m].footprints);
        b->maps[m].footprints = NULL;
    }
    return LX_OK;
}
