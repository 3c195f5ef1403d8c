/* Sky domes: a game level's sky is often a mesh around it (a sphere or
 * dome kilometres across with an unlit material, KHR_materials_unlit).
 * Baked as geometry it is a wall: it blocks the sun, takes most of the
 * atlas, and the default camera lands inside it. A node whose materials
 * are all unlit and whose bounds enclose the rest of the scene, with room
 * to spare (LX_SKY_DOME_RATIO), is marked a sky: no shadows, no lightmap,
 * no part in bounces. The rest is every node that is not unlit (unlit
 * signs inside a level do not enclose it, and nested domes - a sky and a
 * cloud layer - enclose it each). */
#include "node_bake.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

void lx_node_settings_apply(const lx_node_settings *s, lx_node_bake *b)
{
    if (s->sky >= 0) {
        b->sky = s->sky == 1;
        b->no_cast_shadows = b->no_lightmap = b->no_contribute_gi = b->sky;
    }
    if (s->cast_shadows >= 0)
        b->no_cast_shadows = s->cast_shadows == 0;
    if (s->lightmap >= 0)
        b->no_lightmap = s->lightmap == 0;
    if (s->contribute_gi >= 0)
        b->no_contribute_gi = s->contribute_gi == 0;
    if (s->lightmap_scale > 0.0f)
        b->lightmap_scale = s->lightmap_scale;
}

static bool node_unlit(const lx_scene *s, const lx_node *node)
{
    if (node->mesh_count == 0)
        return false;
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        uint32_t m = s->meshes[node->meshes[k]].material;
        if (m >= s->material_count || !s->materials[m].unlit)
            return false;
    }
    return true;
}

/* World bounds of one node; false when it has no vertices. */
static bool node_bounds(const lx_scene *s, const lx_node *node, lx_vec3 *lo, lx_vec3 *hi)
{
    *lo = lx_v3(INFINITY, INFINITY, INFINITY);
    *hi = lx_v3(-INFINITY, -INFINITY, -INFINITY);
    return lx_node_grow_bounds(s, node, lo, hi);
}

uint32_t lx_scene_mark_sky_domes_except(lx_scene *s, const bool *decided)
{
    if (!s || s->node_count < 2)
        return 0;
    /* the rest: every node that is neither unlit nor a sky already */
    lx_vec3 lo = lx_v3(INFINITY, INFINITY, INFINITY), hi = lx_v3(-INFINITY, -INFINITY, -INFINITY);
    bool any = false;
    for (uint32_t n = 0; n < s->node_count; n++) {
        const lx_node *node = &s->nodes[n];
        lx_vec3 a, b;
        if (node->bake.sky || node_unlit(s, node) || !node_bounds(s, node, &a, &b))
            continue;
        lo = lx_v3(fminf(lo.x, a.x), fminf(lo.y, a.y), fminf(lo.z, a.z));
        hi = lx_v3(fmaxf(hi.x, b.x), fmaxf(hi.y, b.y), fmaxf(hi.z, b.z));
        any = true;
    }
    if (!any)
        return 0;
    float rest = lx_length(lx_sub(hi, lo));
    uint32_t marked = 0, first = 0;
    for (uint32_t n = 0; n < s->node_count; n++) {
        lx_node *node = &s->nodes[n];
        lx_vec3 a, b;
        if ((decided && decided[n]) || node->bake.sky || !node_unlit(s, node) ||
            !node_bounds(s, node, &a, &b))
            continue;
        bool encloses =
            a.x <= lo.x && a.y <= lo.y && a.z <= lo.z && b.x >= hi.x && b.y >= hi.y && b.z >= hi.z;
        if (!encloses || !(lx_length(lx_sub(b, a)) >= LX_SKY_DOME_RATIO * rest))
            continue;
        lx_node_settings sky = lx_node_settings_none();
        sky.sky = 1;
        lx_node_settings_apply(&sky, &node->bake);
        if (marked++ == 0)
            first = n;
    }
    if (marked) {
        char more[64] = "";
        if (marked > 1)
            snprintf(more, sizeof more, " (and %u more such nodes)", marked - 1);
        lx_log(LX_LOG_WARN,
               "%s: node '%s' is an unlit mesh enclosing the scene (a sky dome)%s: it casts no "
               "shadows and gets no lightmap (\"sky\": false in the lights JSON's \"nodes\" "
               "bakes it)",
               s->path ? s->path : "scene", s->nodes[first].name, more);
    }
    return marked;
}

uint32_t lx_scene_mark_sky_domes(lx_scene *scene)
{
    return lx_scene_mark_sky_domes_except(scene, NULL);
}
