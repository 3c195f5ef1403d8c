/* The shape of a scene file's node graph (node_graph.c): depth, expanded
 * node count and cycles, measured without recursion. Private to scene. */
#ifndef LX_SCENE_NODE_GRAPH_H
#define LX_SCENE_NODE_GRAPH_H

#include "luxel/core.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The deepest hierarchy a scene file may have: levels of nodes from a root
 * to a leaf, instances followed. */
#define NODE_DEPTH_MAX 256
/* Expanded node counts saturate here (a DAG of instances can double at
 * every level). */
#define NODE_GRAPH_SIZE_CAP ((uint64_t)1 << 40)

/* Nodes 0..nodes-1 and parent -> child edges (children and instances). */
typedef struct node_graph {
    size_t nodes;
    size_t edges, capacity;
    uint32_t *from, *to;
} node_graph;

typedef struct node_graph_shape {
    uint32_t depth;    /* nodes on the longest parent-child chain */
    uint32_t deepest;  /* the node that chain starts at */
    uint64_t expanded; /* nodes the largest subtree expands to, instances
                          copied (saturates at NODE_GRAPH_SIZE_CAP) */
    uint32_t largest;  /* that subtree's root */
    uint32_t cycle_at; /* a node on a cycle, or UINT32_MAX */
} node_graph_shape;

/* Adds an edge; false when out of memory. */
bool node_graph_add_edge(node_graph *g, uint32_t parent, uint32_t child);
/* Measures g (every edge's ends below g->nodes). LX_ERR_NOMEM (no message)
 * when the walk cannot allocate. A cycle stops the walk: depth and
 * expanded then count only what was measured before it. */
lx_status node_graph_measure(const node_graph *g, node_graph_shape *shape);
void node_graph_free(node_graph *g);

#endif
