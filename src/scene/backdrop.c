/* Backdrops: a game level often sits on a ground or terrain mesh that
 * runs kilometres past it (the town of a driving game on a 2 km plain).
 * Sized by the scene's area, the lightmaps then spend nearly every texel
 * on ground nobody walks on, the level gets a texel every metre or two,
 * and the default camera frames the plain with the level a speck in it.
 * A node that holds more than half of the lightmapped area, at least
 * LX_BACKDROP_MIN_AREA (below, a room's floor under one crate, the
 * density is the most anyway), and whose bounds span LX_BACKDROP_RATIO
 * times the rest's is marked a backdrop:
 * its lightmap scale (unless given) is lowered until it takes
 * LX_BACKDROP_SHARE of the texels, and the default camera frames the
 * rest. It still casts shadows, gets a lightmap and bounces light. */
#include "node_bake.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>

double lx_node_world_area(const lx_scene *scene, uint32_t n)
{
    if (!scene || n >= scene->node_count)
        return 0.0;
    const lx_node *node = &scene->nodes[n];
    double area = 0.0;
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        const lx_mesh *m = &scene->meshes[node->meshes[k]];
        for (uint32_t t = 0; t < m->triangle_count; t++) {
            const uint32_t *i = &m->indices[3 * t];
            lx_vec3 p = lx_mat4_point(&node->world, m->positions[i[0]]);
            lx_vec3 q = lx_mat4_point(&node->world, m->positions[i[1]]);
            lx_vec3 r = lx_mat4_point(&node->world, m->positions[i[2]]);
            area += 0.5 * lx_length(lx_cross(lx_sub(q, p), lx_sub(r, p)));
        }
    }
    return area;
}

static bool lightmapped(const lx_node *node)
{
    return !node->bake.sky && !node->bake.no_lightmap && node->mesh_count > 0;
}

/* The largest extent of [lo, hi]. */
static float span(lx_vec3 lo, lx_vec3 hi)
{
    lx_vec3 e = lx_sub(hi, lo);
    return fmaxf(e.x, fmaxf(e.y, e.z));
}

uint32_t lx_scene_mark_backdrops_except(lx_scene *s, const bool *decided)
{
    if (!s || s->node_count < 2)
        return 0;
    double total = 0.0, biggest = 0.0;
    uint32_t which = UINT32_MAX;
    for (uint32_t n = 0; n < s->node_count; n++) {
        if (!lightmapped(&s->nodes[n]))
            continue;
        double scale = lx_node_lightmap_scale(&s->nodes[n].bake);
        double a = lx_node_world_area(s, n) * scale * scale;
        total += a;
        if (a > biggest) {
            biggest = a;
            which = n;
        }
    }
    if (which == UINT32_MAX || !(biggest > 0.5 * total) || !(biggest >= LX_BACKDROP_MIN_AREA) ||
        (decided && decided[which]) || s->nodes[which].bake.lightmap_scale > 0.0f)
        return 0;
    /* the rest: every other lightmapped node */
    lx_vec3 lo = lx_v3(INFINITY, INFINITY, INFINITY), hi = lx_v3(-INFINITY, -INFINITY, -INFINITY);
    bool any = false;
    for (uint32_t n = 0; n < s->node_count; n++)
        if (n != which && lightmapped(&s->nodes[n]))
            any |= lx_node_grow_bounds(s, &s->nodes[n], &lo, &hi);
    lx_vec3 blo = lx_v3(INFINITY, INFINITY, INFINITY),
            bhi = lx_v3(-INFINITY, -INFINITY, -INFINITY);
    if (!any || !lx_node_grow_bounds(s, &s->nodes[which], &blo, &bhi))
        return 0;
    float rest = span(lo, hi), its = span(blo, bhi);
    if (!(rest > 0.0f) || !(its >= LX_BACKDROP_RATIO * rest))
        return 0;
    /* its texels go as scale^2 x area: LX_BACKDROP_SHARE of them */
    double others = total - biggest;
    double scale = sqrt(LX_BACKDROP_SHARE / (1.0 - LX_BACKDROP_SHARE) * others / biggest);
    scale = fmax(scale, 1.0 / LX_NODE_MAX_LIGHTMAP_SCALE);
    if (!(scale < 1.0))
        return 0;
    lx_node *node = &s->nodes[which];
    node->bake.backdrop = true;
    node->bake.lightmap_scale = (float)scale;
    lx_log(LX_LOG_WARN,
           "%s: node '%s' spans %.3g m around the rest's %.3g m and holds %.0f%% of the "
           "lightmapped area (a backdrop): its lightmap scale is %.2g, for %.0f%% of the texels, "
           "and the default camera frames the rest (luxel_lightmap_scale in its extras or "
           "\"lightmap_scale\" in the lights JSON's \"nodes\" sets it)",
           s->path ? s->path : "scene", node->name, (double)its, (double)rest,
           100.0 * biggest / total, scale, 100.0 * LX_BACKDROP_SHARE);
    return 1;
}

uint32_t lx_scene_mark_backdrops(lx_scene *scene)
{
    return lx_scene_mark_backdrops_except(scene, NULL);
}
