/* The shape of a scene file's node graph, measured without recursion:
 * its depth (the longest chain of parents and children, instances
 * included), the nodes it expands to when every instance is copied (as
 * assimp does), and any cycle. The readers behind luxel's scene import
 * walk the hierarchy recursively, once per level, and copy an instanced
 * subtree once per reference, so a file must pass these bounds before it
 * is handed to them (import_checks.c). */
#include "core/internal.h"

#include "node_graph.h"

#include <stdlib.h>
#include <string.h>

void node_graph_free(node_graph *g)
{
    free(g->from);
    free(g->to);
    memset(g, 0, sizeof *g);
}

bool node_graph_add_edge(node_graph *g, uint32_t parent, uint32_t child)
{
    if (g->edges == g->capacity) {
        size_t cap = g->capacity ? g->capacity * 2 : 64;
        uint32_t *from = realloc(g->from, cap * sizeof *from);
        if (!from)
            return false;
        g->from = from;
        uint32_t *to = realloc(g->to, cap * sizeof *to);
        if (!to)
            return false;
        g->to = to;
        g->capacity = cap;
    }
    g->from[g->edges] = parent;
    g->to[g->edges] = child;
    g->edges++;
    return true;
}

/* States of the depth-first walk. */
enum { UNSEEN, OPEN, DONE };

lx_status node_graph_measure(const node_graph *g, node_graph_shape *shape)
{
    memset(shape, 0, sizeof *shape);
    shape->cycle_at = UINT32_MAX;
    size_t n = g->nodes;
    if (n == 0)
        return LX_OK;
    /* children of each node, grouped (counting sort of the edges) */
    size_t *first = calloc(n + 1, sizeof *first);
    uint32_t *child = malloc((g->edges ? g->edges : 1) * sizeof *child);
    uint32_t *depth = malloc(n * sizeof *depth);
    uint64_t *size = malloc(n * sizeof *size);
    uint8_t *state = calloc(n, 1);
    uint32_t *stack = malloc(n * sizeof *stack);
    size_t *next = malloc(n * sizeof *next);
    if (!first || !child || !depth || !size || !state || !stack || !next) {
        free(first), free(child), free(depth), free(size), free(state), free(stack), free(next);
        return LX_ERR_NOMEM;
    }
    for (size_t e = 0; e < g->edges; e++)
        first[g->from[e] + 1]++;
    for (size_t i = 0; i < n; i++)
        first[i + 1] += first[i];
    size_t *fill = next; /* borrowed before the walk needs it */
    memcpy(fill, first, n * sizeof *fill);
    for (size_t e = 0; e < g->edges; e++)
        child[fill[g->from[e]]++] = g->to[e];

    for (size_t root = 0; root < n && shape->cycle_at == UINT32_MAX; root++) {
        if (state[root] != UNSEEN)
            continue;
        size_t top = 0;
        stack[top++] = (uint32_t)root;
        state[root] = OPEN;
        next[root] = first[root];
        depth[root] = 1;
        size[root] = 1;
        while (top > 0) {
            uint32_t v = stack[top - 1];
            if (next[v] < first[v + 1]) {
                uint32_t c = child[next[v]++];
                if (state[c] == OPEN) {
                    shape->cycle_at = c;
                    break;
                }
                if (state[c] == UNSEEN) {
                    state[c] = OPEN;
                    next[c] = first[c];
                    depth[c] = 1;
                    size[c] = 1;
                    stack[top++] = c;
                    continue;
                }
                /* a finished subtree: measured already, reached again */
                if (depth[c] + 1 > depth[v])
                    depth[v] = depth[c] + 1;
                size[v] = size[v] + size[c] < NODE_GRAPH_SIZE_CAP ? size[v] + size[c]
                                                                  : NODE_GRAPH_SIZE_CAP;
                continue;
            }
            state[v] = DONE;
            top--;
            if (depth[v] > shape->depth) {
                shape->depth = depth[v];
                shape->deepest = v;
            }
            if (size[v] > shape->expanded) {
                shape->expanded = size[v];
                shape->largest = v;
            }
            if (top > 0) {
                uint32_t p = stack[top - 1];
                if (depth[v] + 1 > depth[p])
                    depth[p] = depth[v] + 1;
                size[p] = size[p] + size[v] < NODE_GRAPH_SIZE_CAP ? size[p] + size[v]
                                                                  : NODE_GRAPH_SIZE_CAP;
            }
        }
    }
    free(first), free(child), free(depth), free(size), free(state), free(stack), free(next);
    return LX_OK;
}
