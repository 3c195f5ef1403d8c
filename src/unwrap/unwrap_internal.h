/* Private to src/unwrap: the mesh as the unwrapper sees it (welded
 * topology, face normals), charts, flattening and packing. */
#ifndef LX_UNWRAP_INTERNAL_H
#define LX_UNWRAP_INTERNAL_H

#include "luxel/unwrap.h"

#include <stdbool.h>
#include <stdint.h>

#define UW_NONE UINT32_MAX

/* One mesh under one node's linear map (rotation, scale; no translation),
 * with its faces welded by position. Edge k of triangle t runs from corner
 * k to corner (k + 1) % 3. */
typedef struct uw_mesh {
    uint32_t vertex_count, triangle_count;
    const uint32_t *indices; /* the scene mesh's, borrowed */
    double (*position)[3];   /* per vertex, metres, under the linear map */
    uint32_t *weld;          /* per vertex: the first vertex at its position */
    uint32_t *adjacent;      /* 3 per triangle: the triangle across edge k, or
                                UW_NONE (border, non-manifold or flipped) */
    float *seam;             /* 3 per triangle: the cost of crossing edge k,
                                0 where the file's vertices are shared */
    double (*normal)[3];     /* per triangle, unit (zero when degenerate) */
    double *area;            /* per triangle, m^2 */
    double *edge_length;     /* 3 per triangle */
    uint8_t *degenerate;     /* per triangle: zero area, left out of charts */
    uint32_t degenerate_count;
} uw_mesh;

/* The lightmap set of node n lx_bake_uv_set chooses by itself (bake.h sits
 * above this module): luxel's own set above 1 on every mesh, else
 * TEXCOORD_1 on every mesh, else TEXCOORD_0. */
int uw_auto_uv_set(const lx_scene *scene, uint32_t n);

/* Builds m from mesh under the 3x3 linear part `linear` (row-major) of a
 * node's transform. The mesh arrays are borrowed. */
lx_status uw_mesh_build(const lx_mesh *mesh, const double linear[9], uw_mesh *m);
void uw_mesh_free(uw_mesh *m);

/* A chart: triangles of one mesh, and once flattened their UVs. */
typedef struct uw_chart {
    uint32_t *triangles; /* mesh triangle indices, ascending */
    uint32_t triangle_count;
    /* flattening (flatten.c) */
    uint32_t vertex_count;
    uint32_t *vertices;   /* chart vertex -> welded mesh vertex, ascending */
    uint32_t *corners;    /* 3 per chart triangle: chart vertex */
    double *uv;           /* 2 per chart vertex, metres, min corner at (0, 0),
                             turned so its bounding box is smallest and wide */
    double width, height; /* bounding box of uv */
    double area;          /* surface area, m^2 */
    double stretch;       /* L2 stretch of the flattening (1 = isometric) */
} uw_chart;

void uw_chart_free(uw_chart *c);

/* Where mesh triangle t is in c->triangles, or UW_NONE. */
uint32_t uw_chart_find(const uw_chart *c, uint32_t t);

/* Grows charts over m's non-degenerate faces: planar regions first, then
 * regions join the chart they cost least to join (normal deviation, seams
 * crossed, shape), no face turning more than max_angle_cos away from its
 * chart's normal. *charts is malloc'd; the charts partition every
 * non-degenerate triangle. */
lx_status uw_grow_charts(const uw_mesh *m, double max_angle_cos, uw_chart **charts,
                         uint32_t *count);

/* Cuts chart c in two (grown from its two most distant faces);
 * false when it has a single triangle. */
bool uw_split_chart(const uw_mesh *m, const uw_chart *c, uw_chart *a, uw_chart *b);

/* Flattens c: projection when planar, else least-squares conformal maps,
 * scaled to keep its area, turned to its smallest bounding box. false
 * when the result folds, overlaps itself or stretches beyond max_stretch
 * (c then has no UVs), or LX_ERR_NOMEM through *status. */
bool uw_flatten(const uw_mesh *m, uw_chart *c, double max_stretch, lx_status *status);

/* Whether two triangles of flattened chart c (its uv) overlap with a
 * positive area: 1, 0, or -1 out of memory (chart_overlap.c). */
int uw_chart_overlaps(const uw_chart *c);

/* ---- packing (pack.c) ---------------------------------------------------- */

/* A thing to place: a chart's triangles in texels (or a kept node's square),
 * rasterized into covered texels and grown by the padding. */
typedef struct uw_item {
    uint32_t node; /* scene node: a node's items share a page */
    uint32_t triangle_count;
    const double *uv;        /* 2 per vertex, texels, min corner at (0, 0) */
    const uint32_t *corners; /* 3 per triangle */
    double width, height;    /* extent of uv */
    bool solid;              /* a kept node's square: every texel of it is taken */
    /* results */
    uint32_t page;
    int x, y;         /* the page texel at the corner of its covered grid */
    double dx, dy;    /* where uv (0, 0) sits in that grid: the chart is
                         centred in the texels it spans */
    bool turned;      /* placed turned a quarter: (u, v) -> (height - v, u) */
    uint32_t covered; /* covered texels */
} uw_item;

typedef struct uw_pack_desc {
    int padding;
    int atlas_size;
    bool page_per_node; /* no two nodes share a page */
    int threads;
    lx_progress_fn progress;
    void *progress_user;
    float progress_from, progress_to;
} uw_pack_desc;

/* Places items (their node fields group them) into pages of at most
 * atlas_size; fills each item's page, x + dx, y + dy (the page texel of
 * its uv (0, 0)), turned and covered, and the pages' sizes (cropped to multiples
 * of 4) and counts. LX_ERR_UNSUPPORTED with *too_big set to the node when
 * one node's charts cannot share one page. */
lx_status uw_pack(uw_item *items, uint32_t item_count, const uw_pack_desc *desc,
                  lx_unwrap_page **pages, uint32_t *page_count, uint32_t *too_big);

#endif
