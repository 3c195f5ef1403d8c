/* glTF 2.0 node hierarchy (spec 3.5): children checked (in range, one
 * parent each, no cycles), world matrices T * R * S (or "matrix"), parent
 * times child, column-major, computed from the roots down without
 * recursion; and the nodes of the default scene. Shared by the readers of
 * what nodes place (KHR_lights_punctual lights, cameras). */
#include "core/internal.h"

#include "gltf_json.h"
#include "json_text.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>

#define failf(file, st, ...) lx_json_fail(st, file, NULL, __VA_ARGS__)

/* ---- node transforms ---------------------------------------------------- */

static lx_status local_matrix(const char *file, const cJSON *node, const char *who, lx_mat4 *m)
{
    const cJSON *it;
    if ((it = lx_gltf_get(node, "matrix"))) {
        if (!lx_gltf_numbers(it, m->m, 16))
            return failf(file, LX_ERR_FORMAT, "%s: matrix must be 16 finite numbers", who);
        return LX_OK;
    }
    float t[3] = {0, 0, 0}, r[4] = {0, 0, 0, 1}, s[3] = {1, 1, 1};
    if ((it = lx_gltf_get(node, "translation")) && !lx_gltf_numbers(it, t, 3))
        return failf(file, LX_ERR_FORMAT, "%s: translation must be 3 finite numbers", who);
    if ((it = lx_gltf_get(node, "rotation")) && !lx_gltf_numbers(it, r, 4))
        return failf(file, LX_ERR_FORMAT, "%s: rotation must be 4 finite numbers", who);
    if ((it = lx_gltf_get(node, "scale")) && !lx_gltf_numbers(it, s, 3))
        return failf(file, LX_ERR_FORMAT, "%s: scale must be 3 finite numbers", who);
    /* Exporters write quaternions rounded; renormalize so R stays a rotation. */
    double qn =
        sqrt((double)r[0] * r[0] + (double)r[1] * r[1] + (double)r[2] * r[2] + (double)r[3] * r[3]);
    if (!(qn > 1e-12))
        return failf(file, LX_ERR_FORMAT, "%s: rotation quaternion has zero length", who);
    lx_vec4 q =
        lx_v4((float)(r[0] / qn), (float)(r[1] / qn), (float)(r[2] / qn), (float)(r[3] / qn));
    *m = lx_mat4_trs(lx_v3(t[0], t[1], t[2]), q, lx_v3(s[0], s[1], s[2]));
    return LX_OK;
}


void lx_gltf_graph_free(lx_gltf_graph *g)
{
    free(g->nodes);
    free(g->parent);
    free(g->world);
    free(g->included);
    free(g->order);
}

/* Checks children (in range, one parent each, no cycles) and computes every
 * node's world matrix from the roots down, without recursion. */
lx_status lx_gltf_graph_build(const char *file, const cJSON *root, lx_gltf_graph *g)
{
    const cJSON *nodes = lx_gltf_get(root, "nodes");
    if (nodes && !cJSON_IsArray(nodes))
        return failf(file, LX_ERR_FORMAT, "'nodes' must be an array");
    size_t n = 0;
    for (const cJSON *e = nodes ? nodes->child : NULL; e; e = e->next)
        n++;
    g->count = n;
    size_t alloc = n ? n : 1;
    g->nodes = malloc(alloc * sizeof *g->nodes);
    g->parent = malloc(alloc * sizeof *g->parent);
    g->world = malloc(alloc * sizeof *g->world);
    g->included = calloc(alloc, sizeof *g->included);
    g->order = malloc(alloc * sizeof *g->order);
    size_t *stack = malloc(alloc * sizeof *stack);
    bool *seen = calloc(alloc, sizeof *seen);
    if (!g->nodes || !g->parent || !g->world || !g->included || !g->order || !stack || !seen) {
        free(stack);
        free(seen);
        return failf(file, LX_ERR_NOMEM, "out of memory for %zu nodes", n);
    }
    size_t i = 0;
    for (const cJSON *e = nodes ? nodes->child : NULL; e; e = e->next, i++) {
        g->nodes[i] = e;
        g->parent[i] = -1;
    }
    lx_status st = LX_OK;
    char who[128];
    for (i = 0; i < n && st == LX_OK; i++) {
        lx_gltf_label(who, sizeof who, "node", i, g->nodes[i]);
        if (!cJSON_IsObject(g->nodes[i])) {
            st = failf(file, LX_ERR_FORMAT, "%s is not an object", who);
            break;
        }
        const cJSON *children = lx_gltf_get(g->nodes[i], "children");
        if (!children)
            continue;
        if (!cJSON_IsArray(children)) {
            st = failf(file, LX_ERR_FORMAT, "%s: children must be an array", who);
            break;
        }
        for (const cJSON *c = children->child; c && st == LX_OK; c = c->next) {
            size_t k;
            if (!lx_gltf_index(c, n, &k))
                st = failf(file, LX_ERR_FORMAT, "%s: child %g is not a node index (%zu nodes)", who,
                           cJSON_IsNumber(c) ? c->valuedouble : -1.0, n);
            else if (k == i)
                st = failf(file, LX_ERR_FORMAT, "%s is its own child (a cycle)", who);
            else if (g->parent[k] >= 0)
                st = failf(file, LX_ERR_FORMAT, "node %zu is a child of both node %lld and %s", k,
                           (long long)g->parent[k], who);
            else
                g->parent[k] = (int64_t)i;
        }
    }
    /* One parent each: a cycle is a loop of nodes no root reaches. */
    size_t top = 0;
    for (i = 0; i < n && st == LX_OK; i++)
        if (g->parent[i] < 0)
            stack[top++] = i;
    while (top > 0 && st == LX_OK) {
        size_t k = stack[--top];
        g->order[g->reached++] = k;
        seen[k] = true;
        lx_gltf_label(who, sizeof who, "node", k, g->nodes[k]);
        lx_mat4 local;
        if ((st = local_matrix(file, g->nodes[k], who, &local)) != LX_OK)
            break;
        g->world[k] = g->parent[k] < 0 ? local : lx_mat4_mul(&g->world[g->parent[k]], &local);
        if (!lx_mat4_finite(&g->world[k]))
            st = failf(file, LX_ERR_FORMAT, "%s: world transform is not finite", who);
        const cJSON *children = lx_gltf_get(g->nodes[k], "children");
        for (const cJSON *c = children ? children->child : NULL; c; c = c->next)
            stack[top++] = (size_t)c->valuedouble; /* checked above */
    }
    for (i = 0; i < n && st == LX_OK; i++)
        if (!seen[i]) {
            /* Unreached nodes are on or below a loop of parents: n steps up
             * from one surely land on the loop. */
            size_t k = i;
            for (size_t steps = 0; steps < n; steps++)
                k = (size_t)g->parent[k];
            st = failf(file, LX_ERR_FORMAT, "the node hierarchy has a cycle through node %zu", k);
        }
    free(stack);
    free(seen);
    return st;
}

/* Marks the nodes of the default scene ("scene", else scenes[0]), or every
 * node when the file has no scenes. */
lx_status lx_gltf_graph_select(const char *file, const cJSON *root, lx_gltf_graph *g)
{
    const cJSON *scenes = lx_gltf_get(root, "scenes");
    if (scenes && !cJSON_IsArray(scenes))
        return failf(file, LX_ERR_FORMAT, "'scenes' must be an array");
    size_t scene_count = (size_t)(scenes ? cJSON_GetArraySize(scenes) : 0);
    const cJSON *which = lx_gltf_get(root, "scene");
    if (scene_count == 0) {
        if (which)
            return failf(file, LX_ERR_FORMAT, "'scene' is given but there are no scenes");
        for (size_t i = 0; i < g->count; i++)
            g->included[i] = true;
        return LX_OK;
    }
    size_t s = 0;
    if (which && !lx_gltf_index(which, scene_count, &s))
        return failf(file, LX_ERR_FORMAT, "'scene' is not a scene index (%zu scenes)", scene_count);
    const cJSON *sc = cJSON_GetArrayItem(scenes, (int)s);
    if (!cJSON_IsObject(sc))
        return failf(file, LX_ERR_FORMAT, "scene %zu is not an object", s);
    const cJSON *roots = lx_gltf_get(sc, "nodes");
    if (roots && !cJSON_IsArray(roots))
        return failf(file, LX_ERR_FORMAT, "scene %zu: nodes must be an array", s);
    bool *marked = calloc(g->count ? g->count : 1, sizeof *marked);
    if (!marked)
        return failf(file, LX_ERR_NOMEM, "out of memory for %zu nodes", g->count);
    for (const cJSON *r = roots ? roots->child : NULL; r; r = r->next) {
        size_t k;
        if (!lx_gltf_index(r, g->count, &k)) {
            free(marked);
            return failf(file, LX_ERR_FORMAT, "scene %zu: node %g is not a node index (%zu nodes)",
                         s, cJSON_IsNumber(r) ? r->valuedouble : -1.0, g->count);
        }
        marked[k] = true;
    }
    /* A node is in the scene when it or an ancestor is a listed root;
     * order has parents before children. */
    for (size_t i = 0; i < g->reached; i++) {
        size_t k = g->order[i];
        g->included[k] = marked[k] || (g->parent[k] >= 0 && g->included[g->parent[k]]);
    }
    free(marked);
    return LX_OK;
}

