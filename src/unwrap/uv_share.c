/* Shared UV squares: whether a node's lightmap UV set is a piece of one
 * square that other nodes' meshes share (objects sharing a texture atlas),
 * judged across the scene. Each node's UV box (the bounding box of its
 * triangles' UVs) against the span of its set (the bounding box of every
 * counted node's box of that set): a box at most max_share of the span is
 * a piece. One pass over each mesh's triangles for its box (instances read
 * a mesh once), then the boxes sorted per set to count the different ones.
 * No published method: the measure is luxel's own (docs/ARCHITECTURE.md,
 * "UV health"). */
#include "luxel/unwrap.h"

#include "core/internal.h"
#include "unwrap_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lx_uv_share_desc lx_uv_share_desc_defaults(const lx_uv_share_desc *desc)
{
    lx_uv_share_desc d = {0};
    if (desc)
        d = *desc;
    if (!(d.max_share > 0.0f))
        d.max_share = 0.5f;
    return d;
}

/* The box of one mesh's triangles in one set (false: no triangles). */
static bool mesh_box(const lx_mesh *m, int set, float box[4])
{
    const lx_vec2 *uv = m->uv[set];
    box[0] = box[1] = INFINITY;
    box[2] = box[3] = -INFINITY;
    for (size_t i = 0; i < 3 * (size_t)m->triangle_count; i++) {
        lx_vec2 p = uv[m->indices[i]];
        box[0] = fminf(box[0], p.x);
        box[1] = fminf(box[1], p.y);
        box[2] = fmaxf(box[2], p.x);
        box[3] = fmaxf(box[3], p.y);
    }
    return m->triangle_count > 0;
}

typedef struct cached_box {
    int set; /* -1: not read yet */
    bool any;
    float box[4];
} cached_box;

/* A counted node's box, sortable by (set, box). */
typedef struct node_box {
    int set;
    float box[4];
} node_box;

static int cmp_box(const void *pa, const void *pb)
{
    const node_box *a = pa, *b = pb;
    if (a->set != b->set)
        return a->set < b->set ? -1 : 1;
    for (int k = 0; k < 4; k++)
        if (a->box[k] != b->box[k])
            return a->box[k] < b->box[k] ? -1 : 1;
    return 0;
}

static double box_area(const float b[4])
{
    return ((double)b[2] - b[0]) * ((double)b[3] - b[1]);
}

lx_status lx_uv_share_nodes(const lx_scene *scene, const int *uv_sets, const lx_uv_share_desc *desc,
                            lx_uv_share *out)
{
    if (!scene)
        return lx_fail_null(__func__, "scene");
    if (!out)
        return lx_fail_null(__func__, "out");
    lx_uv_share_desc d = lx_uv_share_desc_defaults(desc);
    if (!(d.max_share <= 1.0f))
        return lx_fail(LX_ERR_INVALID, "UV share: max_share %g is outside (0, 1]",
                       (double)d.max_share);
    uint32_t nn = scene->node_count;
    for (uint32_t n = 0; n < nn; n++) {
        int set = uv_sets ? uv_sets[n] : uw_auto_uv_set(scene, n);
        if (set < 0 || set >= LX_MAX_UV_SETS)
            return lx_fail(LX_ERR_INVALID, "%s: node '%s': UV set %d is outside 0..%d", scene->path,
                           scene->nodes[n].name, set, LX_MAX_UV_SETS - 1);
    }
    cached_box *cache = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof *cache);
    node_box *sorted = malloc(sizeof *sorted * (nn ? nn : 1));
    if (!cache || !sorted) {
        free(cache);
        free(sorted);
        return lx_fail(LX_ERR_NOMEM, "UV share: out of memory for %u nodes", nn);
    }
    for (uint32_t m = 0; m < scene->mesh_count; m++)
        cache[m].set = -1;

    /* each node's box, and the spans of the sets */
    float span[LX_MAX_UV_SETS][4];
    uint32_t users[LX_MAX_UV_SETS] = {0};
    for (int s = 0; s < LX_MAX_UV_SETS; s++) {
        span[s][0] = span[s][1] = INFINITY;
        span[s][2] = span[s][3] = -INFINITY;
    }
    uint32_t counted = 0;
    for (uint32_t n = 0; n < nn; n++) {
        const lx_node *node = &scene->nodes[n];
        lx_uv_share *o = &out[n];
        memset(o, 0, sizeof *o);
        o->uv_set = uv_sets ? uv_sets[n] : uw_auto_uv_set(scene, n);
        float box[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
        bool ok = node->mesh_count > 0 && !node->bake.no_lightmap, any = false;
        for (uint32_t k = 0; k < node->mesh_count && ok; k++) {
            uint32_t mi = node->meshes[k];
            const lx_mesh *m = &scene->meshes[mi];
            if (!m->uv[o->uv_set]) {
                ok = false;
                break;
            }
            cached_box c = cache[mi];
            if (c.set != o->uv_set) {
                c.set = o->uv_set;
                c.any = mesh_box(m, o->uv_set, c.box);
                /* a mesh placed with two sets keeps the first one's box */
                if (cache[mi].set < 0)
                    cache[mi] = c;
            }
            if (!c.any)
                continue;
            any = true;
            box[0] = fminf(box[0], c.box[0]);
            box[1] = fminf(box[1], c.box[1]);
            box[2] = fmaxf(box[2], c.box[2]);
            box[3] = fmaxf(box[3], c.box[3]);
        }
        o->counted =
            ok && any && box[0] >= 0.0f && box[1] >= 0.0f && box[2] <= 1.0f && box[3] <= 1.0f;
        o->share = 1.0;
        if (!o->counted)
            continue;
        o->min = lx_v2(box[0], box[1]);
        o->max = lx_v2(box[2], box[3]);
        float *sp = span[o->uv_set];
        sp[0] = fminf(sp[0], box[0]);
        sp[1] = fminf(sp[1], box[1]);
        sp[2] = fmaxf(sp[2], box[2]);
        sp[3] = fmaxf(sp[3], box[3]);
        users[o->uv_set]++;
        sorted[counted].set = o->uv_set;
        memcpy(sorted[counted].box, box, sizeof box);
        counted++;
    }
    free(cache);

    /* different boxes per set: equal ones sort next to each other */
    uint32_t boxes[LX_MAX_UV_SETS] = {0};
    qsort(sorted, counted, sizeof *sorted, cmp_box);
    for (uint32_t i = 0; i < counted; i++)
        boxes[sorted[i].set] += i == 0 || cmp_box(&sorted[i - 1], &sorted[i]) != 0;
    free(sorted);

    for (uint32_t n = 0; n < nn; n++) {
        lx_uv_share *o = &out[n];
        if (!o->counted)
            continue;
        const float *sp = span[o->uv_set];
        const float mine[4] = {o->min.x, o->min.y, o->max.x, o->max.y};
        o->span_min = lx_v2(sp[0], sp[1]);
        o->span_max = lx_v2(sp[2], sp[3]);
        o->users = users[o->uv_set];
        o->boxes = boxes[o->uv_set];
        double whole = box_area(sp);
        o->share = whole > 0.0 ? box_area(mine) / whole : 1.0;
        o->shared = o->share <= d.max_share;
        if (o->shared)
            snprintf(o->reason, sizeof o->reason,
                     "is a piece of a UV square %u nodes share (its UV box %.3g%% of theirs; a "
                     "texture atlas?)",
                     o->users, 100.0 * o->share);
    }
    return LX_OK;
}
