/* Whether a flattened chart overlaps itself: two of its triangles sharing
 * a positive area in UV. Pairs are found through a uniform grid of about
 * one triangle a cell (each pair tested once, in the cell holding the
 * lower corner of their boxes' intersection) and tested by separating
 * axes, the six edge normals of the two triangles (Ericson, Real-Time
 * Collision Detection 4.4 and 5.2.1); touching along an edge or at a
 * vertex is not overlapping.
 *
 * Why, beside flatten.c's border check: a border that pinches, passing
 * twice through one vertex, can fold two fans over each other without
 * any two border segments crossing (the segments that meet there share
 * the vertex and are not compared). The Japanese garden has such
 * charts: coplanar faces that overlap in space by 2 cm, joined to the
 * rest at two vertices, 14 texels covered twice; truck_town's ground 132. */
#include "unwrap_internal.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#define MAX_CELLS_A_SIDE 1024

/* Does an edge of triangle a have all of b on its outer side (or on it)? */
static bool separated_by_edge_of(const double *a[3], const double *b[3])
{
    for (int e = 0; e < 3; e++) {
        const double *p = a[e], *q = a[(e + 1) % 3], *r = a[(e + 2) % 3];
        double nx = q[1] - p[1], ny = p[0] - q[0];
        double inner = nx * (r[0] - p[0]) + ny * (r[1] - p[1]);
        bool all_out = true;
        for (int k = 0; k < 3 && all_out; k++) {
            double s = nx * (b[k][0] - p[0]) + ny * (b[k][1] - p[1]);
            all_out = inner > 0.0 ? s <= 0.0 : s >= 0.0;
        }
        if (all_out)
            return true;
    }
    return false;
}

static void corners_of(const uw_chart *c, uint32_t i, const double *v[3])
{
    for (int k = 0; k < 3; k++)
        v[k] = &c->uv[2 * c->corners[3 * i + k]];
}

static void box_of(const uw_chart *c, uint32_t i, double box[4])
{
    const double *v[3];
    corners_of(c, i, v);
    box[0] = fmin(v[0][0], fmin(v[1][0], v[2][0]));
    box[1] = fmin(v[0][1], fmin(v[1][1], v[2][1]));
    box[2] = fmax(v[0][0], fmax(v[1][0], v[2][0]));
    box[3] = fmax(v[0][1], fmax(v[1][1], v[2][1]));
}

typedef struct overlap_grid {
    double lo[2], scale[2];
    uint32_t nx, ny;
} overlap_grid;

static uint32_t cell_x(const overlap_grid *g, double x)
{
    return (uint32_t)fmin(fmax((x - g->lo[0]) * g->scale[0], 0.0), g->nx - 1.0);
}

static uint32_t cell_y(const overlap_grid *g, double y)
{
    return (uint32_t)fmin(fmax((y - g->lo[1]) * g->scale[1], 0.0), g->ny - 1.0);
}

/* Tests the pairs binned in one cell; each pair only in the cell of the
 * lower corner of its boxes' intersection. */
static bool cell_overlaps(const uw_chart *c, const overlap_grid *g, const uint32_t *list,
                          uint32_t count, uint32_t x, uint32_t y)
{
    for (uint32_t i = 0; i < count; i++)
        for (uint32_t j = i + 1; j < count; j++) {
            double a[4], b[4];
            box_of(c, list[i], a);
            box_of(c, list[j], b);
            if (a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1])
                continue;
            if (cell_x(g, fmax(a[0], b[0])) != x || cell_y(g, fmax(a[1], b[1])) != y)
                continue;
            const double *p[3], *q[3];
            corners_of(c, list[i], p);
            corners_of(c, list[j], q);
            if (!separated_by_edge_of(p, q) && !separated_by_edge_of(q, p))
                return true;
        }
    return false;
}

int uw_chart_overlaps(const uw_chart *c)
{
    uint32_t n = c->triangle_count;
    if (n < 2)
        return 0;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, sides = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        double box[4];
        box_of(c, i, box);
        lo[0] = fmin(lo[0], box[0]), lo[1] = fmin(lo[1], box[1]);
        hi[0] = fmax(hi[0], box[2]), hi[1] = fmax(hi[1], box[3]);
        sides += fmax(box[2] - box[0], box[3] - box[1]);
    }
    /* cells the size of a triangle, at most about n of them */
    double ext0 = hi[0] - lo[0], ext1 = hi[1] - lo[1];
    double cell = fmax(sides / n, sqrt(ext0 * ext1 / n));
    if (!(cell > 0.0) || !isfinite(cell))
        return 1; /* no extent: everything on a point or a line */
    overlap_grid g = {{lo[0], lo[1]}, {0.0, 0.0}, 1, 1};
    g.nx = (uint32_t)fmin(fmax(ceil(ext0 / cell), 1.0), MAX_CELLS_A_SIDE);
    g.ny = (uint32_t)fmin(fmax(ceil(ext1 / cell), 1.0), MAX_CELLS_A_SIDE);
    g.scale[0] = g.nx / fmax(ext0, 1e-300);
    g.scale[1] = g.ny / fmax(ext1, 1e-300);
    size_t cells = (size_t)g.nx * g.ny;
    uint32_t *start = calloc(cells + 1, sizeof(uint32_t));
    if (!start)
        return -1;
    /* count, then fill the cells each triangle's box covers */
    size_t refs = 0;
    for (uint32_t i = 0; i < n; i++) {
        double box[4];
        box_of(c, i, box);
        for (uint32_t y = cell_y(&g, box[1]); y <= cell_y(&g, box[3]); y++)
            for (uint32_t x = cell_x(&g, box[0]); x <= cell_x(&g, box[2]); x++) {
                start[(size_t)y * g.nx + x + 1]++;
                refs++;
            }
    }
    for (size_t k = 0; k < cells; k++)
        start[k + 1] += start[k];
    if (refs > UINT32_MAX) { /* boxes over most cells: cut the chart rather than count */
        free(start);
        return 1;
    }
    uint32_t *items = malloc(sizeof(uint32_t) * (refs ? refs : 1));
    uint32_t *fill = malloc(sizeof(uint32_t) * cells);
    if (!items || !fill) {
        free(start);
        free(items);
        free(fill);
        return -1;
    }
    for (size_t k = 0; k < cells; k++)
        fill[k] = start[k];
    for (uint32_t i = 0; i < n; i++) {
        double box[4];
        box_of(c, i, box);
        for (uint32_t y = cell_y(&g, box[1]); y <= cell_y(&g, box[3]); y++)
            for (uint32_t x = cell_x(&g, box[0]); x <= cell_x(&g, box[2]); x++)
                items[fill[(size_t)y * g.nx + x]++] = i;
    }
    int overlaps = 0;
    for (uint32_t y = 0; y < g.ny && !overlaps; y++)
        for (uint32_t x = 0; x < g.nx && !overlaps; x++) {
            size_t k = (size_t)y * g.nx + x;
            overlaps = cell_overlaps(c, &g, items + start[k], start[k + 1] - start[k], x, y);
        }
    free(start);
    free(items);
    free(fill);
    return overlaps;
}
