/* Texel map: lightmap texels mapped to world space. The per-texel lighting
 * article (the method this baker follows) searches every
 * triangle for every texel; here each triangle is rasterized in UV space
 * instead, O(texels + triangles). Pass 1 gives each texel whose centre lies
 * in a triangle that triangle's barycentric point; pass 2 gives texels a
 * triangle only partly covers (chart borders) the triangle's closest point
 * to the texel centre, so chart edges get real samples and do not go dark. */
#include "bake_internal.h"
#include "core/internal.h"

#include "luxel/maps.h"

#include <omp.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct raster_ctx {
    int width, height;
    int row0, row1;  /* the band of rows this rasterization writes, [row0, row1) */
    uint32_t *owner; /* per pixel: page-local triangle id, UINT32_MAX = none */
    float *b1, *b2;  /* barycentrics of vertices 1 and 2 */
    float *distance; /* 0 for centre coverage, else texel-space distance */
    uint8_t *strict; /* centre strictly inside the owner */
    uint32_t overlap;
    uint32_t *slot_overlap; /* overlapping texels counted by the later mesh */
    bool centres_only;      /* pass 1 alone (the supersampling points) */
} raster_ctx;

/* One mesh of one node on the page. */
typedef struct slot {
    const lx_mesh *mesh;
    uint32_t mesh_index;
    uint32_t node;
    uint32_t first_triangle; /* page-local id of the mesh's triangle 0 */
    const lx_vec2 *uv;
    double scale_offset[4]; /* the node's UVs into the page: uv * so.xy + so.zw */
} slot;

/* Barycentrics (w0, w1, w2) of point p in triangle abc, in double so edge
 * decisions do not depend on evaluation order. false if degenerate. */
static bool barycentric(const double a[2], const double b[2], const double c[2], double px,
                        double py, double w[3])
{
    double d = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if (d == 0.0)
        return false;
    w[1] = ((px - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (py - a[1])) / d;
    w[2] = ((b[0] - a[0]) * (py - a[1]) - (px - a[0]) * (b[1] - a[1])) / d;
    w[0] = 1.0 - w[1] - w[2];
    return true;
}

/* Closest point of triangle abc to p (Ericson, Real-Time Collision
 * Detection 5.1.5), as barycentrics. */
static void closest_on_triangle(const double a[2], const double b[2], const double c[2],
                                const double p[2], double w[3])
{
    double ab[2] = {b[0] - a[0], b[1] - a[1]}, ac[2] = {c[0] - a[0], c[1] - a[1]};
    double ap[2] = {p[0] - a[0], p[1] - a[1]};
    double d1 = ab[0] * ap[0] + ab[1] * ap[1], d2 = ac[0] * ap[0] + ac[1] * ap[1];
    if (d1 <= 0 && d2 <= 0) {
        w[0] = 1, w[1] = 0, w[2] = 0;
        return;
    }
    double bp[2] = {p[0] - b[0], p[1] - b[1]};
    double d3 = ab[0] * bp[0] + ab[1] * bp[1], d4 = ac[0] * bp[0] + ac[1] * bp[1];
    if (d3 >= 0 && d4 <= d3) {
        w[0] = 0, w[1] = 1, w[2] = 0;
        return;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        double v = d1 / (d1 - d3);
        w[0] = 1 - v, w[1] = v, w[2] = 0;
        return;
    }
    double cp[2] = {p[0] - c[0], p[1] - c[1]};
    double d5 = ab[0] * cp[0] + ab[1] * cp[1], d6 = ac[0] * cp[0] + ac[1] * cp[1];
    if (d6 >= 0 && d5 <= d6) {
        w[0] = 0, w[1] = 0, w[2] = 1;
        return;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        double t = d2 / (d2 - d6);
        w[0] = 1 - t, w[1] = 0, w[2] = t;
        return;
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w[0] = 0, w[1] = 1 - t, w[2] = t;
        return;
    }
    double denom = 1.0 / (va + vb + vc);
    w[1] = vb * denom;
    w[2] = vc * denom;
    w[0] = 1 - w[1] - w[2];
}

/* Does triangle abc overlap the axis-aligned square [x0,x0+1]x[y0,y0+1]
 * with a positive area? Separating axes: the square's two axes and the
 * triangle's edge normals; touching along an edge or at a corner is not
 * overlapping (a chart whose border runs along texel edges covers no extra
 * ring of texels). */
static bool triangle_overlaps_texel(const double *v[3], double x0, double y0)
{
    double minx = fmin(v[0][0], fmin(v[1][0], v[2][0]));
    double maxx = fmax(v[0][0], fmax(v[1][0], v[2][0]));
    double miny = fmin(v[0][1], fmin(v[1][1], v[2][1]));
    double maxy = fmax(v[0][1], fmax(v[1][1], v[2][1]));
    if (maxx <= x0 || minx >= x0 + 1 || maxy <= y0 || miny >= y0 + 1)
        return false;
    double corners[4][2] = {{x0, y0}, {x0 + 1, y0}, {x0, y0 + 1}, {x0 + 1, y0 + 1}};
    for (int e = 0; e < 3; e++) {
        const double *p = v[e], *q = v[(e + 1) % 3], *r = v[(e + 2) % 3];
        double nx = q[1] - p[1], ny = p[0] - q[0];
        double side = nx * (r[0] - p[0]) + ny * (r[1] - p[1]);
        bool all_out = true;
        for (int k = 0; k < 4 && all_out; k++) {
            double s = nx * (corners[k][0] - p[0]) + ny * (corners[k][1] - p[1]);
            all_out = side > 0 ? s <= 0 : s >= 0;
        }
        if (all_out)
            return false;
    }
    return true;
}

static void uv_to_texel(const raster_ctx *r, const slot *s, lx_vec2 uv, double out[2])
{
    out[0] = ((double)uv.x * s->scale_offset[0] + s->scale_offset[2]) * r->width;
    out[1] = ((double)uv.y * s->scale_offset[1] + s->scale_offset[3]) * r->height;
}

/* The texel rectangle a triangle may touch, grown by pad, within the
 * rows of the band; false when it lies wholly outside them. Clamped in double before converting, so
 * UVs far outside [0,1] neither overflow an int nor cost a long loop. */
static bool bbox(const double *v[3], int pad, const raster_ctx *r, int *x0, int *y0, int *x1,
                 int *y1)
{
    double minx = fmin(v[0][0], fmin(v[1][0], v[2][0])) - pad;
    double maxx = fmax(v[0][0], fmax(v[1][0], v[2][0])) + pad;
    double miny = fmin(v[0][1], fmin(v[1][1], v[2][1])) - pad;
    double maxy = fmax(v[0][1], fmax(v[1][1], v[2][1])) + pad;
    double w = r->width, lo = r->row0, hi = r->row1;
    if (!(maxx >= 0.0 && minx < w && maxy >= lo && miny < hi))
        return false;
    *x0 = (int)fmax(floor(minx), 0.0);
    *y0 = (int)fmax(floor(miny), lo);
    *x1 = (int)fmin(floor(maxx), w - 1.0);
    *y1 = (int)fmin(floor(maxy), hi - 1.0);
    return true;
}

static void raster_centres(raster_ctx *r, const double *v[3], uint32_t id, uint32_t slot_index)
{
    int x0, y0, x1, y1;
    if (!bbox(v, 0, r, &x0, &y0, &x1, &y1))
        return;
    const double strict_eps = 1e-6;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            double w[3];
            if (!barycentric(v[0], v[1], v[2], x + 0.5, y + 0.5, w))
                return;
            if (w[0] < 0 || w[1] < 0 || w[2] < 0)
                continue;
            size_t p = (size_t)y * r->width + x;
            bool strict = w[0] > strict_eps && w[1] > strict_eps && w[2] > strict_eps;
            if (r->owner[p] != UINT32_MAX) {
                /* an edge shared by neighbours is not an overlap */
                if (strict && r->strict[p]) {
                    r->overlap++;
                    r->slot_overlap[slot_index]++;
                }
                continue;
            }
            r->owner[p] = id;
            r->b1[p] = (float)w[1];
            r->b2[p] = (float)w[2];
            r->distance[p] = 0.0f;
            r->strict[p] = strict;
        }
}

static void raster_borders(raster_ctx *r, const double *v[3], uint32_t id)
{
    int x0, y0, x1, y1;
    if (!bbox(v, 1, r, &x0, &y0, &x1, &y1))
        return;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            size_t p = (size_t)y * r->width + x;
            if (r->owner[p] != UINT32_MAX && r->distance[p] == 0.0f)
                continue; /* centre already covered */
            if (!triangle_overlaps_texel(v, x, y))
                continue;
            double c[2] = {x + 0.5, y + 0.5}, w[3];
            closest_on_triangle(v[0], v[1], v[2], c, w);
            /* nudge the sample off the edge, into the triangle */
            const double nudge = 1e-3;
            for (int k = 0; k < 3; k++)
                w[k] = w[k] * (1 - nudge) + nudge / 3;
            double px = w[0] * v[0][0] + w[1] * v[1][0] + w[2] * v[2][0];
            double py = w[0] * v[0][1] + w[1] * v[1][1] + w[2] * v[2][1];
            float d = (float)hypot(px - c[0], py - c[1]);
            if (d <= 0.0f)
                d = 1e-9f;
            if (r->owner[p] != UINT32_MAX && r->distance[p] <= d)
                continue;
            r->owner[p] = id;
            r->b1[p] = (float)w[1];
            r->b2[p] = (float)w[2];
            r->distance[p] = d;
        }
}

/* Rows per band: the unit of parallel rasterization. */
#define RASTER_BAND 32

/* Both passes over every triangle, in parallel over bands of rows: each
 * band runs pass 1 then pass 2 over the triangles that reach it, in mesh
 * and triangle order, so every texel sees the same triangles in the same
 * order as one serial sweep would and the result is the same for any
 * thread count. Triangles are listed per band first (a counting sort in
 * triangle order), so a band skips the ones that miss it. */
static lx_status raster_bands(raster_ctx *r, const slot *slots, uint32_t slot_count,
                              const uint8_t *skip, uint32_t total_triangles,
                              const lx_bake_desc *desc, lx_texel_progress progress,
                              const char *what)
{
    int threads = desc->threads;
    _Atomic int bands_done = 0;
    _Atomic bool cancelled = false;
    int bands = (r->height + RASTER_BAND - 1) / RASTER_BAND;
    uint32_t *band_start = calloc((size_t)bands + 1, sizeof(uint32_t));
    uint32_t *band_fill = calloc((size_t)bands, sizeof(uint32_t));
    uint32_t *counts = calloc((size_t)bands * (slot_count + 1), sizeof(uint32_t));
    uint32_t *tri_slot = malloc(sizeof(uint32_t) * (total_triangles ? total_triangles : 1));
    int *tri_rows = malloc(2 * sizeof(int) * (total_triangles ? total_triangles : 1));
    lx_status st = LX_OK;
    if (!band_start || !band_fill || !counts || !tri_slot || !tri_rows) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
        goto done;
    }
    /* the bands each triangle's rows reach (its border pass grows it by 1) */
    uint64_t entries = 0;
    for (uint32_t s = 0; s < slot_count; s++) {
        const lx_mesh *m = slots[s].mesh;
        for (uint32_t t = 0; t < m->triangle_count; t++) {
            uint32_t id = slots[s].first_triangle + t;
            tri_slot[id] = s;
            tri_rows[2 * id] = 1; /* empty: row0 > row1 */
            tri_rows[2 * id + 1] = 0;
            if (skip[id])
                continue;
            const uint32_t *i = &m->indices[3 * t];
            double a[2], b[2], c[2];
            uv_to_texel(r, &slots[s], slots[s].uv[i[0]], a);
            uv_to_texel(r, &slots[s], slots[s].uv[i[1]], b);
            uv_to_texel(r, &slots[s], slots[s].uv[i[2]], c);
            const double *v[3] = {a, b, c};
            int x0, y0, x1, y1;
            if (!bbox(v, 1, r, &x0, &y0, &x1, &y1))
                continue;
            tri_rows[2 * id] = y0 / RASTER_BAND;
            tri_rows[2 * id + 1] = y1 / RASTER_BAND;
            for (int k = y0 / RASTER_BAND; k <= y1 / RASTER_BAND; k++)
                band_start[k + 1]++;
            entries += (uint64_t)(y1 / RASTER_BAND - y0 / RASTER_BAND + 1);
        }
    }
    if (entries > UINT32_MAX) {
        st = lx_fail(LX_ERR_NOMEM, "%s: too many triangle rows to rasterize", what);
        goto done;
    }
    for (int k = 0; k < bands; k++)
        band_start[k + 1] += band_start[k];
    uint32_t *list = malloc(sizeof(uint32_t) * (entries ? entries : 1));
    if (!list) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
        goto done;
    }
    for (uint32_t id = 0; id < total_triangles; id++)
        for (int k = tri_rows[2 * id]; k <= tri_rows[2 * id + 1]; k++)
            list[band_start[k] + band_fill[k]++] = id;

#pragma omp parallel for schedule(dynamic, 1) num_threads(lx_thread_count(threads))
    for (int k = 0; k < bands; k++) {
        if (atomic_load(&cancelled))
            continue;
        /* large maps take long enough to report and stop: the calling
         * thread reports (one thread at a time, never backwards) */
        if (desc->progress && omp_get_thread_num() == 0 &&
            !desc->progress(desc->progress_user,
                            progress.from + (progress.to - progress.from) *
                                                (float)atomic_load(&bands_done) / (float)bands))
            atomic_store(&cancelled, true);
        raster_ctx br = *r;
        br.row0 = k * RASTER_BAND;
        br.row1 = br.row0 + RASTER_BAND < r->height ? br.row0 + RASTER_BAND : r->height;
        br.overlap = 0;
        br.slot_overlap = counts + (size_t)k * (slot_count + 1);
        for (int pass = 0; pass < (r->centres_only ? 1 : 2); pass++)
            for (uint32_t e = band_start[k]; e < band_start[k + 1]; e++) {
                uint32_t id = list[e], s = tri_slot[id];
                const lx_mesh *m = slots[s].mesh;
                const uint32_t *i = &m->indices[3 * (id - slots[s].first_triangle)];
                double a[2], b[2], c[2];
                uv_to_texel(&br, &slots[s], slots[s].uv[i[0]], a);
                uv_to_texel(&br, &slots[s], slots[s].uv[i[1]], b);
                uv_to_texel(&br, &slots[s], slots[s].uv[i[2]], c);
                const double *v[3] = {a, b, c};
                if (pass == 0)
                    raster_centres(&br, v, id, s);
                else
                    raster_borders(&br, v, id);
            }
        br.slot_overlap[slot_count] = br.overlap;
        atomic_fetch_add(&bands_done, 1);
    }
    free(list);
    if (atomic_load(&cancelled)) {
        st = lx_fail(LX_ERR_CANCELLED, "bake cancelled");
        goto done;
    }
    /* overlap counts summed in band order */
    for (int k = 0; k < bands; k++) {
        const uint32_t *c = counts + (size_t)k * (slot_count + 1);
        for (uint32_t s = 0; s < slot_count; s++)
            r->slot_overlap[s] += c[s];
        r->overlap += c[slot_count];
    }
done:
    free(band_start);
    free(band_fill);
    free(counts);
    free(tri_slot);
    free(tri_rows);
    return st;
}

/* A node's side at a fixed resolution: the resolution times its
 * lightmap scale (a multiple of 4 when scaled, 4..LX_MAX_LIGHTMAP_SIZE). */
static int scaled_resolution(const lx_node *node, const lx_bake_desc *desc)
{
    float scale = lx_node_lightmap_scale(&node->bake);
    if (scale == 1.0f)
        return desc->resolution;
    double r = ceil((double)desc->resolution * scale / 4.0) * 4.0;
    return r < 4.0 ? 4 : r > LX_MAX_LIGHTMAP_SIZE ? LX_MAX_LIGHTMAP_SIZE : (int)r;
}

/* Lightmap size for texel density: R^2 * uv_area = (T s)^2 * world_area,
 * s the node's lightmap scale. */
static int size_from_density(const lx_scene *scene, const lx_node *node, const slot *slots,
                             uint32_t slot_count, const lx_bake_desc *desc, bool warn)
{
    double world_area = 0, uv_area = 0;
    for (uint32_t s = 0; s < slot_count; s++) {
        const lx_mesh *m = slots[s].mesh;
        for (uint32_t t = 0; t < m->triangle_count; t++) {
            const uint32_t *i = &m->indices[3 * t];
            lx_vec3 a = lx_mat4_point(&node->world, m->positions[i[0]]);
            lx_vec3 b = lx_mat4_point(&node->world, m->positions[i[1]]);
            lx_vec3 c = lx_mat4_point(&node->world, m->positions[i[2]]);
            world_area += 0.5 * lx_length(lx_cross(lx_sub(b, a), lx_sub(c, a)));
            lx_vec2 ua = slots[s].uv[i[0]], ub = slots[s].uv[i[1]], uc = slots[s].uv[i[2]];
            uv_area += 0.5 * fabs((double)(ub.x - ua.x) * (uc.y - ua.y) -
                                  (double)(uc.x - ua.x) * (ub.y - ua.y));
        }
    }
    if (!(uv_area > 0))
        return 4;
    double r =
        desc->texel_density * lx_node_lightmap_scale(&node->bake) * sqrt(world_area / uv_area);
    /* compare in double: a huge (or infinite) size must cap, not wrap */
    if (!(r <= desc->max_resolution)) {
        if (warn)
            lx_log(LX_LOG_WARN,
                   "%s: node '%s': %.0f texels per side needed for %.3g texels/m; capped at %d",
                   scene->path, node->name, r,
                   desc->texel_density * lx_node_lightmap_scale(&node->bake), desc->max_resolution);
        return desc->max_resolution;
    }
    int size = (int)(ceil(r / 4.0) * 4.0);
    if (size > desc->max_resolution)
        size = desc->max_resolution;
    return size < 4 ? 4 : size;
}

/* The index of the mesh's UV set a slot reads. */
static int slot_uv_set(const slot *s)
{
    for (int k = 0; k < LX_MAX_UV_SETS; k++)
        if (s->uv == s->mesh->uv[k])
            return k;
    return 0;
}

static lx_status check_uv_triangles(const lx_scene *scene, const slot *s, const lx_node *node,
                                    const lx_bake_desc *desc, uint8_t *skip)
{
    int uv_set = slot_uv_set(s);
    uint32_t degenerate = 0, outside = 0;
    const lx_mesh *m = s->mesh;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *i = &m->indices[3 * t];
        lx_vec2 a = s->uv[i[0]], b = s->uv[i[1]], c = s->uv[i[2]];
        double e1x = b.x - a.x, e1y = b.y - a.y, e2x = c.x - a.x, e2y = c.y - a.y;
        double cross = e1x * e2y - e2x * e1y;
        double longest = fmax(e1x * e1x + e1y * e1y,
                              fmax(e2x * e2x + e2y * e2y, (c.x - b.x) * (double)(c.x - b.x) +
                                                              (c.y - b.y) * (double)(c.y - b.y)));
        skip[t] = 0;
        if (!(fabs(cross) > 1e-7 * longest) || longest == 0.0) {
            if (desc->strict)
                return lx_fail(LX_ERR_FORMAT, "%s: mesh '%s': triangle %u has zero area in TEXCOORD_%d",
                               scene->path, m->name, t, uv_set);
            skip[t] = 1;
            degenerate++;
            continue;
        }
        float lo = fminf(a.x, fminf(b.x, fminf(c.x, fminf(a.y, fminf(b.y, c.y)))));
        float hi = fmaxf(a.x, fmaxf(b.x, fmaxf(c.x, fmaxf(a.y, fmaxf(b.y, c.y)))));
        if (lo < 0.0f || hi > 1.0f)
            outside++;
    }
    if (degenerate)
        lx_log(LX_LOG_WARN, "%s: node '%s': mesh '%s': %u triangles with zero UV area skipped",
               scene->path, node->name, m->name, degenerate);
    if (outside)
        lx_log(LX_LOG_WARN,
               "%s: node '%s': mesh '%s': %u triangles reach outside the [0,1] lightmap; "
               "the parts outside get no texels",
               scene->path, node->name, m->name, outside);
    return LX_OK;
}

/* The slot holding page-local triangle id (slots ascend by first
 * triangle; an atlas page has many). */
static uint32_t slot_of(const slot *slots, uint32_t count, uint32_t id)
{
    uint32_t lo = 0, hi = count - 1;
    while (lo < hi) {
        uint32_t mid = (lo + hi + 1) / 2;
        if (slots[mid].first_triangle <= id)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}


/* Texel n's world-space position and normals under world (nm: its normal
 * matrix), as lx_texel_map_transform computes them (world_geometric: its
 * triangle's, made once a triangle), and its object space when the map
 * keeps it. */
static void place_texel(lx_lightmap *map, uint32_t n, const lx_mat4 *world, const lx_mat4 *nm,
                        lx_vec3 position, lx_vec3 normal, lx_vec3 geometric,
                        lx_vec3 world_geometric, lx_vec3 smooth)
{
    map->world_position[n] = lx_mat4_point(world, position);
    map->world_normal[n] = lx_normalize(lx_mat4_vector(nm, normal));
    map->world_geometric_normal[n] = world_geometric;
    if (map->world_smooth_normal)
        map->world_smooth_normal[n] = lx_normalize(lx_mat4_vector(nm, smooth));
    if (map->object_position) {
        map->object_position[n] = position;
        map->object_normal[n] = normal;
        map->object_geometric_normal[n] = geometric;
        if (map->object_smooth_normal)
            map->object_smooth_normal[n] = smooth;
    }
}

/* True when every mesh of the node with UVs has set `set`. */
static bool node_has_set(const lx_scene *scene, const lx_node *node, int set)
{
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        const lx_mesh *m = &scene->meshes[node->meshes[k]];
        if (m->uv[0] && !m->uv[set])
            return false;
    }
    return true;
}

/* The lightmap UV set of a node: the set luxel writes lightmap UVs to when
 * it is above TEXCOORD_1 (a set no material reads: luxel's own, from an
 * earlier unwrap) and every mesh with UVs has it, else TEXCOORD_1 when
 * every one has that, else TEXCOORD_0. */
int lx_bake_uv_set(const lx_scene *scene, uint32_t node_index, lx_uv_choice choice)
{
    if (choice == LX_UV_SET_0 || choice == LX_UV_SET_1)
        return choice == LX_UV_SET_1 ? 1 : 0;
    const lx_node *node = &scene->nodes[node_index];
    int own = lx_scene_lightmap_set(scene, node_index);
    if (own > 1 && node_has_set(scene, node, own))
        return own;
    return node_has_set(scene, node, 1) ? 1 : 0;
}

/* Appends the node's meshes that have UV set `uv_set` (a negative one:
 * the automatic choice, put in *uv_set) to slots, from triangle id
 * *first on. Returns how many. */
static uint32_t collect_slots(const lx_scene *scene, uint32_t node_index, const float so[4],
                              int *uv_set, slot *slots, uint32_t *first, bool warn)
{
    const lx_node *node = &scene->nodes[node_index];
    /* the automatic choice's TEXCOORD_0 fallback is warned about once per
     * bake, for every node (lx_bake_warn_texcoord0) */
    if (*uv_set < 0)
        *uv_set = lx_bake_uv_set(scene, node_index, LX_UV_SET_AUTO);
    uint32_t n = 0;
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        const lx_mesh *m = &scene->meshes[node->meshes[k]];
        const lx_vec2 *uv = m->uv[*uv_set];
        if (!uv) { /* one warning for them all: the baker's (warn_no_uvs) */
            if (warn)
                lx_log(LX_LOG_INFO,
                       "%s: node '%s': mesh '%s' has no UVs; it gets no lightmap "
                       "texels (it still casts shadows)",
                       scene->path, node->name, m->name);
            continue;
        }
        slot *sl = &slots[n++];
        *sl = (slot){m, node->meshes[k], node_index, *first, uv, {so[0], so[1], so[2], so[3]}};
        *first += m->triangle_count;
    }
    return n;
}

/* The page's seam samples (stitch.c), from its meshes' UV seams. */
static lx_status build_stitch(const slot *slots, uint32_t slot_count, lx_lightmap *map,
                              const char *what)
{
    lx_stitch_mesh *meshes = malloc(sizeof *meshes * (slot_count ? slot_count : 1));
    if (!meshes)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    for (uint32_t s = 0; s < slot_count; s++) {
        meshes[s].mesh = slots[s].mesh;
        meshes[s].uv_set = slot_uv_set(&slots[s]);
        memcpy(meshes[s].scale_offset, slots[s].scale_offset, sizeof meshes[s].scale_offset);
    }
    lx_status st = lx_seam_stitch_build(meshes, slot_count, map->info.width, map->info.height,
                                        what, &map->stitch);
    free(meshes);
    return st;
}

/* The surface at barycentrics (w0, w1, w2) of triangle t of a slot's
 * mesh, in object space: position, shading normal (normal map applied
 * when tangents is not NULL) and geometric normal. */
/* Triangle t's unit geometric normal (object space). */
static lx_vec3 triangle_normal(const lx_mesh *m, uint32_t t)
{
    const uint32_t *i = &m->indices[3 * t];
    lx_vec3 pa = m->positions[i[0]], pb = m->positions[i[1]], pc = m->positions[i[2]];
    return lx_normalize(lx_cross(lx_sub(pb, pa), lx_sub(pc, pa)));
}

/* surface_point with the triangle's normal given (geometric, from
 * triangle_normal): what changes from texel to texel. */
static void surface_at(const lx_scene *scene, const slot *sl, const lx_vec4 *tangents, uint32_t t,
                       float w0, float w1, float w2, const lx_vec3 *geometric, lx_vec3 *position,
                       lx_vec3 *normal, lx_vec3 *smooth)
{
    const lx_mesh *m = sl->mesh;
    const uint32_t *i = &m->indices[3 * t];
    lx_vec3 pa = m->positions[i[0]], pb = m->positions[i[1]], pc = m->positions[i[2]];
    *position = lx_add(lx_add(lx_scale(pa, w0), lx_scale(pb, w1)), lx_scale(pc, w2));
    lx_vec3 nrm = lx_add(lx_add(lx_scale(m->normals[i[0]], w0), lx_scale(m->normals[i[1]], w1)),
                         lx_scale(m->normals[i[2]], w2));
    nrm = lx_length(nrm) > 1e-12f ? lx_normalize(nrm) : *geometric;
    if (smooth)
        *smooth = nrm;
    if (tangents)
        lx_material_normal_at(lx_mesh_material(scene, m), m, tangents, i, w0, w1, w2, &nrm);
    *normal = nrm;
}

static void surface_point(const lx_scene *scene, const slot *sl, const lx_vec4 *tangents,
                          uint32_t t, float w0, float w1, float w2, lx_vec3 *position,
                          lx_vec3 *normal, lx_vec3 *geometric, lx_vec3 *smooth)
{
    *geometric = triangle_normal(sl->mesh, t);
    surface_at(scene, sl, tangents, t, w0, w1, w2, geometric, position, normal, smooth);
}

/* From point `position` of triangle t (barycentrics w0, w1, w2, object
 * space) to the smooth surface its vertex normals describe: the point
 * projected onto each vertex's tangent plane where it lies below it,
 * blended by the barycentrics (Hanika 2021); zero on a flat facet, where
 * it would point into the mesh, or where the shading normal faces away
 * from the facet's (normals against the winding). */
static lx_vec3 terminator_lift(const lx_mesh *m, uint32_t t, float w0, float w1, float w2,
                               lx_vec3 position, lx_vec3 normal, lx_vec3 geometric)
{
    const uint32_t *i = &m->indices[3 * t];
    const float w[3] = {w0, w1, w2};
    lx_vec3 lift = lx_v3(0.0f, 0.0f, 0.0f);
    for (int k = 0; k < 3; k++) {
        lx_vec3 n = m->normals[i[k]];
        float len = lx_length(n);
        if (!(len > 0.0f))
            continue;
        n = lx_scale(n, 1.0f / len);
        float below = lx_dot(lx_sub(position, m->positions[i[k]]), n);
        if (below < 0.0f)
            lift = lx_madd(lift, n, -w[k] * below);
    }
    if (!(lx_dot(lift, geometric) > 0.0f) || !(lx_dot(normal, geometric) > 0.0f))
        return lx_v3(0.0f, 0.0f, 0.0f);
    return lift;
}

/* The world step of one texel along x and along y on triangle t of a
 * slot (the inverse of its UV-to-texel map): zero for a triangle without
 * UV area. */
static void texel_axes(const raster_ctx *r, const slot *sl, uint32_t t, const lx_mat4 *world,
                       lx_vec3 axes[2])
{
    const lx_mesh *m = sl->mesh;
    const uint32_t *i = &m->indices[3 * t];
    double a[2], b[2], c[2];
    uv_to_texel(r, sl, sl->uv[i[0]], a);
    uv_to_texel(r, sl, sl->uv[i[1]], b);
    uv_to_texel(r, sl, sl->uv[i[2]], c);
    double t1x = b[0] - a[0], t1y = b[1] - a[1], t2x = c[0] - a[0], t2y = c[1] - a[1];
    double det = t1x * t2y - t2x * t1y;
    axes[0] = axes[1] = lx_v3(0.0f, 0.0f, 0.0f);
    if (!(fabs(det) > 0.0) || !isfinite(det))
        return;
    lx_vec3 e1 = lx_sub(m->positions[i[1]], m->positions[i[0]]);
    lx_vec3 e2 = lx_sub(m->positions[i[2]], m->positions[i[0]]);
    /* [e1 e2] = [dP/dx dP/dy] [t1 t2] */
    lx_vec3 dx = lx_scale(lx_sub(lx_scale(e1, (float)t2y), lx_scale(e2, (float)t1y)),
                          (float)(1.0 / det));
    lx_vec3 dy = lx_scale(lx_sub(lx_scale(e2, (float)t1x), lx_scale(e1, (float)t2x)),
                          (float)(1.0 / det));
    axes[0] = lx_mat4_vector(world, dx);
    axes[1] = lx_mat4_vector(world, dy);
}

static int range_order(const void *a, const void *b)
{
    const lx_footprint_range *x = a, *y = b;
    if (x->node != y->node)
        return x->node < y->node ? -1 : 1;
    return x->mesh < y->mesh ? -1 : x->mesh > y->mesh;
}

/* The texel footprint of every triangle of the page (texel_axes), one
 * range of triangles per slot. */
static lx_status build_footprints(const lx_scene *scene, const raster_ctx *r, const slot *slots,
                                  uint32_t slot_count, uint32_t total_triangles, int threads,
                                  const char *what, lx_texel_footprints **out)
{
    lx_texel_footprints *f = calloc(1, sizeof *f);
    if (f) {
        f->axes = malloc(2 * sizeof(lx_vec3) * (total_triangles ? total_triangles : 1));
        f->ranges = malloc(sizeof(lx_footprint_range) * (slot_count ? slot_count : 1));
    }
    if (!f || !f->axes || !f->ranges) {
        lx_texel_footprints_free(f);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the texel footprints", what);
    }
    for (uint32_t s = 0; s < slot_count; s++)
        f->ranges[s] = (lx_footprint_range){slots[s].node, slots[s].mesh_index,
                                            slots[s].first_triangle};
    f->range_count = slot_count;
    qsort(f->ranges, slot_count, sizeof *f->ranges, range_order);
    int64_t count = total_triangles;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int64_t id = 0; id < count; id++) {
        uint32_t s = slot_of(slots, slot_count, (uint32_t)id);
        texel_axes(r, &slots[s], (uint32_t)id - slots[s].first_triangle,
                   &scene->nodes[slots[s].node].world, &f->axes[2 * id]);
    }
    *out = f;
    return LX_OK;
}

void lx_texel_footprints_free(lx_texel_footprints *f)
{
    if (!f)
        return;
    free(f->axes);
    free(f->ranges);
    free(f);
}

/* Texel supersampling: the page rasterized again, centres only, at N
 * times its resolution; sub-texel (x N + b, y N + a) is point s = a N + b
 * of texel (x, y), the centre of cell (b, a) of its N x N grid, so the
 * points are stratified over its footprint and each has the position
 * and normals of the triangle covering it. A point no triangle covers
 * keeps the texel's own sample and is marked uncovered. */
static lx_status build_subsamples(const lx_scene *scene, const lx_bake_desc *desc,
                                  const slot *slots, uint32_t slot_count, const uint8_t *skip,
                                  uint32_t total_triangles, lx_vec4 *const *tangents,
                                  const lx_mat4 *nms, const uint32_t *slot_node,
                                  lx_texel_progress progress, const char *what, lx_lightmap *map)
{
    int n = desc->supersample, w = map->info.width, h = map->info.height;
    uint32_t used = map->info.used_texels, count = (uint32_t)(n * n);
    size_t pixels = (size_t)w * n * (size_t)h * n, total = (size_t)count * used;
    raster_ctx r = {.width = w * n, .height = h * n, .row1 = h * n, .centres_only = true};
    unsigned char *block = malloc(17 * pixels);
    r.slot_overlap = calloc(slot_count, sizeof(uint32_t));
    size_t bytes = sizeof(lx_vec3) * (total ? total : 1);
    map->sub_position = malloc(bytes);
    map->sub_normal = malloc(bytes);
    map->sub_geometric_normal = malloc(bytes);
    map->sub_covered = malloc(total ? total : 1);
    bool object = map->object_position != NULL;
    if (object) {
        map->sub_object_position = malloc(bytes);
        map->sub_object_normal = malloc(bytes);
        map->sub_object_geometric_normal = malloc(bytes);
    }
    lx_status st = LX_OK;
    if (!block || !r.slot_overlap || !map->sub_position || !map->sub_normal ||
        !map->sub_geometric_normal || !map->sub_covered ||
        (object && (!map->sub_object_position || !map->sub_object_normal ||
                    !map->sub_object_geometric_normal))) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for %dx%d supersampling", what, n, n);
        goto done;
    }
    map->sub_count = count;
    r.owner = (uint32_t *)block;
    r.b1 = (float *)(block + 4 * pixels);
    r.b2 = (float *)(block + 8 * pixels);
    r.distance = (float *)(block + 12 * pixels);
    r.strict = block + 16 * pixels;
    memset(r.strict, 0, pixels);
    memset(r.owner, 0xFF, sizeof(uint32_t) * pixels);
    st = raster_bands(&r, slots, slot_count, skip, total_triangles, desc, progress, what);
    if (st != LX_OK)
        goto done;
    int64_t texels = used;
#pragma omp parallel for schedule(static) num_threads(lx_thread_count(desc->threads))
    for (int64_t k = 0; k < texels; k++) {
        uint32_t pixel = map->texels[k].pixel;
        size_t x = pixel % (uint32_t)w, y = pixel / (uint32_t)w;
        for (uint32_t s = 0; s < count; s++) {
            size_t q = (y * n + s / n) * (size_t)r.width + x * n + s % n;
            size_t at = (size_t)s * used + (size_t)k;
            uint32_t id = r.owner[q];
            if (id == UINT32_MAX) {
                map->sub_position[at] = map->world_position[k];
                map->sub_normal[at] = map->world_normal[k];
                map->sub_geometric_normal[at] = map->world_geometric_normal[k];
                if (object) {
                    map->sub_object_position[at] = map->object_position[k];
                    map->sub_object_normal[at] = map->object_normal[k];
                    map->sub_object_geometric_normal[at] = map->object_geometric_normal[k];
                }
                map->sub_covered[at] = 0;
                continue;
            }
            uint32_t sl = slot_of(slots, slot_count, id);
            float w1 = r.b1[q], w2 = r.b2[q];
            lx_vec3 position, normal, geometric;
            surface_point(scene, &slots[sl], tangents[sl], id - slots[sl].first_triangle,
                          1.0f - w1 - w2, w1, w2, &position, &normal, &geometric, NULL);
            const lx_mat4 *world = &scene->nodes[slots[sl].node].world;
            const lx_mat4 *nm = &nms[slot_node[sl]];
            map->sub_position[at] = lx_mat4_point(world, position);
            map->sub_normal[at] = lx_normalize(lx_mat4_vector(nm, normal));
            map->sub_geometric_normal[at] = lx_normalize(lx_mat4_vector(nm, geometric));
            if (object) {
                map->sub_object_position[at] = position;
                map->sub_object_normal[at] = normal;
                map->sub_object_geometric_normal[at] = geometric;
            }
            map->sub_covered[at] = 1;
        }
    }
done:
    free(block);
    free(r.slot_overlap);
    return st;
}

lx_status lx_texel_map_build(const lx_scene *scene, const lx_page_spec *page,
                             const lx_bake_desc *desc, lx_texel_progress progress,
                             const lx_horizon_material *horizon, lx_lightmap *map)
{
    memset(map, 0, sizeof *map);
    map->info.node = page->node_count == 1 ? page->nodes[0].node : UINT32_MAX;
    map->name = lx_strdup(page->name);
    map->info.name = map->name;
    uint32_t mesh_slots = 0;
    for (uint32_t k = 0; k < page->node_count; k++)
        mesh_slots += scene->nodes[page->nodes[k].node].mesh_count;
    slot *slots = calloc(mesh_slots ? mesh_slots : 1, sizeof *slots);
    if (!slots || !map->name) {
        free(slots);
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    }
    uint32_t slot_count = 0, first = 0;
    int uv_set = -1;
    for (uint32_t k = 0; k < page->node_count; k++) {
        int set = page->nodes[k].uv_set;
        slot_count += collect_slots(scene, page->nodes[k].node, page->nodes[k].scale_offset, &set,
                                    slots + slot_count, &first, true);
        uv_set = k == 0 || set == uv_set ? set : LX_UV_SET_MIXED;
    }
    map->info.uv_set = uv_set;
    if (slot_count == 0) {
        free(slots);
        return LX_OK;
    }
    /* the node's own size when it has the page to itself and no size is
     * given */
    int w = page->width, h = page->height;
    if (w <= 0 || h <= 0) {
        const lx_node *node = &scene->nodes[page->nodes[0].node];
        w = h = desc->texel_density > 0
                    ? size_from_density(scene, node, slots, slot_count, desc, true)
                    : scaled_resolution(node, desc);
    }
    map->info.width = w;
    map->info.height = h;
    uint64_t pixels = (uint64_t)w * (uint64_t)h;
    char what[400];
    snprintf(what, sizeof what, "%s: lightmap '%s' (%dx%d)", scene->path, page->name, w, h);
    /* with a horizon record a texel when a node here has a height */
    bool horizon_texels = false;
    for (uint32_t k = 0; k < page->node_count && !horizon_texels; k++)
        horizon_texels = lx_bake_node_has_horizon(scene, horizon, page->nodes[k].node);
    /* supersampling N: the raster again at N^2 the pixels (17 bytes each,
     * freed after) and 2 x 3 vectors and a flag a point */
    uint64_t sub = desc->supersample > 1 ? (uint64_t)desc->supersample * desc->supersample : 0;
    lx_status st = lx_check_memory(
        pixels * (LX_BYTES_PER_TEXEL + (horizon_texels ? sizeof(lx_texel_horizon) : 0) +
                  2 * sizeof(lx_vec3) + sub * (17 + 6 * sizeof(lx_vec3) + 1)),
        what);
    if (st != LX_OK) {
        free(slots);
        return st;
    }

    raster_ctx r = {.width = w, .height = h, .row0 = 0, .row1 = h};
    /* The raster's buffers in one block (17 bytes a pixel) that becomes
     * the baked buffer (12) once the texels are gathered: fresh memory
     * costs a page fault per page, often more than the work done on it. */
    unsigned char *block = malloc(17 * (size_t)pixels);
    r.owner = (uint32_t *)block;
    r.b1 = (float *)(block + 4 * (size_t)pixels);
    r.b2 = (float *)(block + 8 * (size_t)pixels);
    r.distance = (float *)(block + 12 * (size_t)pixels);
    r.strict = block + 16 * (size_t)pixels;
    if (block)
        memset(r.strict, 0, pixels);
    uint32_t total_triangles = 0;
    for (uint32_t s = 0; s < slot_count; s++)
        total_triangles += slots[s].mesh->triangle_count;
    uint8_t *skip = malloc(total_triangles ? total_triangles : 1);
    r.slot_overlap = calloc(slot_count, sizeof(uint32_t));
    if (!block || !skip || !r.slot_overlap) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
        goto done;
    }
    memset(r.owner, 0xFF, sizeof(uint32_t) * pixels);
    for (uint32_t s = 0; s < slot_count && st == LX_OK; s++)
        st = check_uv_triangles(scene, &slots[s], &scene->nodes[slots[s].node], desc,
                                skip + slots[s].first_triangle);
    if (st != LX_OK)
        goto done;

    /* with supersampling its raster takes the later three quarters */
    lx_texel_progress main_progress = progress, sub_progress = progress;
    if (sub)
        main_progress.to = sub_progress.from = progress.from + 0.25f * (progress.to - progress.from);
    st = raster_bands(&r, slots, slot_count, skip, total_triangles, desc, main_progress, what);
    if (st != LX_OK)
        goto done;
    map->info.overlap_texels = r.overlap;
    for (uint32_t s = 0; s < slot_count; s++)
        if (r.slot_overlap[s])
            lx_log(LX_LOG_WARN,
                   "%s: mesh '%s' (node '%s'): %u texels are covered by overlapping lightmap UVs",
                   scene->path, slots[s].mesh->name, scene->nodes[slots[s].node].name,
                   r.slot_overlap[s]);

    /* gather covered texels tile by tile */
    uint32_t used = 0;
    int64_t pixel_count = (int64_t)pixels;
#pragma omp parallel for schedule(static) reduction(+ : used) num_threads(lx_thread_count(desc->threads))
    for (int64_t p = 0; p < pixel_count; p++)
        used += r.owner[p] != UINT32_MAX;
    int tiles_x = (w + LX_TILE - 1) / LX_TILE, tiles_y = (h + LX_TILE - 1) / LX_TILE;
    map->tile_count = (uint32_t)tiles_x * (uint32_t)tiles_y;
    map->texels = malloc(sizeof(lx_texel) * (used ? used : 1));
    map->tile_start = malloc(sizeof(uint32_t) * (map->tile_count + 1));
    map->mask = calloc(pixels, 1);
    /* map->realtime: made by the first update with dynamic lights (baker.c) */
    map->world_position = malloc(sizeof(lx_vec3) * (used ? used : 1));
    map->world_normal = malloc(sizeof(lx_vec3) * (used ? used : 1));
    map->world_geometric_normal = malloc(sizeof(lx_vec3) * (used ? used : 1));
    bool want_albedo = desc->quantity == LX_QUANTITY_RADIANCE || lx_bake_keeps_surfaces(desc);
    if (want_albedo)
        map->albedo = malloc(sizeof(lx_vec3) * (used ? used : 1));
    /* emission per texel, when a material here emits: for the gather, and
     * for the emitters' direct light when its emission has a texture */
    bool emits = false;
    for (uint32_t s = 0; s < slot_count; s++) {
        const lx_material *mat = lx_mesh_material(scene, slots[s].mesh);
        lx_vec3 e = lx_material_emission(mat, desc->emissive_scale);
        bool textured = mat && mat->emissive_map.width > 0;
        emits |= (e.x > 0.0f || e.y > 0.0f || e.z > 0.0f) &&
                 (lx_bake_keeps_surfaces(desc) || textured);
    }
    if (emits)
        map->emission = malloc(sizeof(lx_vec3) * (used ? used : 1));
    if (!map->texels || !map->tile_start || !map->mask || !map->world_position ||
        !map->world_normal || !map->world_geometric_normal || (want_albedo && !map->albedo) ||
        (emits && !map->emission)) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
        goto done;
    }
    /* tangents for normal-mapped meshes: from the file, else computed */
    lx_vec4 **tangents = calloc(slot_count, sizeof(lx_vec4 *));
    bool *own_tangents = calloc(slot_count, sizeof(bool));
    if (!tangents || !own_tangents) {
        free(tangents);
        free(own_tangents);
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
        goto done;
    }
    for (uint32_t s = 0; s < slot_count && st == LX_OK; s++) {
        const lx_mesh *m = slots[s].mesh;
        const lx_material *mat = lx_mesh_material(scene, m);
        /* a directional bake leaves normal maps to run time (its
         * directional data brings them in at full resolution) */
        if (mat->normal_map.width <= 0 || !m->uv[mat->normal_uv_set] ||
            desc->directional != LX_DIRECTIONAL_OFF)
            continue;
        if (m->tangents) {
            tangents[s] = m->tangents;
            continue;
        }
        tangents[s] = malloc(sizeof(lx_vec4) * m->vertex_count);
        own_tangents[s] = true;
        st = tangents[s] ? lx_compute_tangents(m, mat->normal_uv_set, tangents[s])
                         : lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    }
    /* world space as lx_texel_map_transform computes it; object space kept
     * only for a page with a node away from the identity (the world arrays
     * are object space otherwise, up to the rounding of a renormalization) */
    lx_mat4 *nms = malloc(sizeof(lx_mat4) * page->node_count);
    uint32_t *slot_node = malloc(sizeof(uint32_t) * slot_count); /* index into page->nodes */
    if (!nms || !slot_node)
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    bool identity = true;
    lx_mat4 id = lx_mat4_identity();
    for (uint32_t k = 0; k < page->node_count && st == LX_OK; k++) {
        const lx_mat4 *world = &scene->nodes[page->nodes[k].node].world;
        if (!lx_mat4_normal_matrix(world, &nms[k]))
            nms[k] = *world;
        for (int e = 0; e < 16; e++)
            identity &= world->m[e] == id.m[e];
    }
    for (uint32_t s = 0, k = 0; s < slot_count && st == LX_OK; s++) {
        while (page->nodes[k].node != slots[s].node)
            k++;
        slot_node[s] = k;
    }
    /* the vertex normals the bounces gather about, where normal maps apply */
    bool mapped = false;
    for (uint32_t s = 0; s < slot_count; s++)
        mapped |= tangents[s] != NULL;
    if (mapped && st == LX_OK) {
        map->world_smooth_normal = malloc(sizeof(lx_vec3) * (used ? used : 1));
        map->object_smooth_normal = identity ? NULL : malloc(sizeof(lx_vec3) * (used ? used : 1));
        if (!map->world_smooth_normal || (!identity && !map->object_smooth_normal))
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    }
    if (!identity && st == LX_OK) {
        map->object_position = malloc(sizeof(lx_vec3) * (used ? used : 1));
        map->object_normal = malloc(sizeof(lx_vec3) * (used ? used : 1));
        map->object_geometric_normal = malloc(sizeof(lx_vec3) * (used ? used : 1));
        if (!map->object_position || !map->object_normal || !map->object_geometric_normal)
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    }
    /* the shadow terminator's lift, where a mesh is smooth-shaded */
    bool smooth = false;
    for (uint32_t sl = 0; sl < slot_count && !smooth; sl++)
        smooth = lx_mesh_is_smooth(slots[sl].mesh);
    if (smooth && st == LX_OK) {
        map->lift = malloc(sizeof(lx_vec3) * (used ? used : 1));
        if (map->object_position)
            map->object_lift = malloc(sizeof(lx_vec3) * (used ? used : 1));
        if (!map->lift || (map->object_position && !map->object_lift))
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    }
    /* texels in tile order: count each tile's, place the tiles, then fill
     * them in parallel (every texel's slot is known, so any thread count
     * writes the same arrays) */
    int threads = lx_thread_count(desc->threads);
    int tile_count = (int)map->tile_count;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int tile = 0; tile < tile_count; tile++) {
        int ty = tile / tiles_x, tx = tile % tiles_x;
        uint32_t c = 0;
        for (int y = ty * LX_TILE; y < (ty + 1) * LX_TILE && y < h; y++)
            for (int x = tx * LX_TILE; x < (tx + 1) * LX_TILE && x < w; x++)
                c += r.owner[(size_t)y * w + x] != UINT32_MAX;
        map->tile_start[tile + 1] = c;
    }
    map->tile_start[0] = 0;
    for (int tile = 0; tile < tile_count; tile++)
        map->tile_start[tile + 1] += map->tile_start[tile];
    uint32_t n = map->tile_start[tile_count];
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
    for (int tile = 0; tile < tile_count; tile++) {
        if (st != LX_OK)
            continue;
        int ty = tile / tiles_x, tx = tile % tiles_x;
        uint32_t k = map->tile_start[tile];
        /* what is the same across a triangle, made once per run of it */
        uint32_t cached = UINT32_MAX, s = 0;
        lx_vec3 geometric = {0}, world_geometric = {0};
        for (int y = ty * LX_TILE; y < (ty + 1) * LX_TILE && y < h; y++)
            for (int x = tx * LX_TILE; x < (tx + 1) * LX_TILE && x < w; x++) {
                size_t p = (size_t)y * w + x;
                if (r.owner[p] == UINT32_MAX)
                    continue;
                if (r.owner[p] != cached) {
                    cached = r.owner[p];
                    s = slot_of(slots, slot_count, cached);
                    geometric = triangle_normal(slots[s].mesh, cached - slots[s].first_triangle);
                    world_geometric =
                        lx_normalize(lx_mat4_vector(&nms[slot_node[s]], geometric));
                }
                const lx_mesh *m = slots[s].mesh;
                uint32_t t = r.owner[p] - slots[s].first_triangle;
                const uint32_t *i = &m->indices[3 * t];
                float w1 = r.b1[p], w2 = r.b2[p], w0 = 1.0f - w1 - w2;
                lx_texel *tx_ = &map->texels[k];
                tx_->pixel = (uint32_t)p;
                tx_->mesh = slots[s].mesh_index;
                tx_->triangle = t;
                tx_->node = slots[s].node;
                lx_vec3 position, nrm, vertex_normal;
                surface_at(scene, &slots[s], tangents[s], t, w0, w1, w2, &geometric, &position,
                           &nrm, &vertex_normal);
                const lx_material *mat = lx_mesh_material(scene, m);
                if (map->albedo)
                    map->albedo[k] = lx_material_albedo_at(mat, m, i, w0, w1, w2);
                if (map->emission)
                    map->emission[k] =
                        lx_material_emission_at(mat, m, i, w0, w1, w2, desc->emissive_scale);
                if (map->lift) {
                    lx_vec3 lift = terminator_lift(m, t, w0, w1, w2, position, nrm, geometric);
                    map->lift[k] = lx_mat4_vector(&scene->nodes[slots[s].node].world, lift);
                    if (map->object_lift)
                        map->object_lift[k] = lift;
                }
                place_texel(map, k++, &scene->nodes[slots[s].node].world, &nms[slot_node[s]],
                            position, nrm, geometric, world_geometric, vertex_normal);
                map->mask[p] = 1;
            }
    }
    map->info.used_texels = n;
    if (st == LX_OK)
        st = build_footprints(scene, &r, slots, slot_count, total_triangles, threads, what,
                              &map->footprints);
    if (st == LX_OK && sub)
        st = build_subsamples(scene, desc, slots, slot_count, skip, total_triangles, tangents, nms,
                              slot_node, sub_progress, what, map);
    if (st == LX_OK)
        st = lx_bake_horizon_texels(scene, horizon, map, r.b1, r.b2, desc->threads);
    if (st == LX_OK && desc->stitch_seams)
        st = build_stitch(slots, slot_count, map, what);
    for (uint32_t s = 0; s < slot_count; s++)
        if (own_tangents[s])
            free(tangents[s]);
    free(tangents);
    free(own_tangents);
    free(nms);
    free(slot_node);
    if (st == LX_OK) {
        /* the raster is done with: its block is the (zeroed) baked buffer */
        map->baked = (float *)block;
        memset(map->baked, 0, sizeof(float) * 3 * (size_t)pixels);
        block = NULL;
    }
done:
    free(block);
    free(r.slot_overlap);
    free(skip);
    free(slots);
    return st;
}

void lx_texel_map_size(const lx_scene *scene, uint32_t node_index, const lx_bake_desc *desc,
                       int *width, int *height)
{
    const lx_node *node = &scene->nodes[node_index];
    *width = *height = 0;
    slot *slots = calloc(node->mesh_count ? node->mesh_count : 1, sizeof *slots);
    if (!slots)
        return;
    int uv_set = desc->uv_set - 1; /* LX_UV_SET_AUTO (0) -> -1 */
    uint32_t first = 0;
    const float identity[4] = {1.0f, 1.0f, 0.0f, 0.0f};
    uint32_t n = collect_slots(scene, node_index, identity, &uv_set, slots, &first, false);
    if (n)
        *width = *height = desc->texel_density > 0
                               ? size_from_density(scene, node, slots, n, desc, false)
                               : scaled_resolution(node, desc);
    free(slots);
}

lx_status lx_texel_map_keep_object_space(lx_lightmap *map)
{
    if (map->object_position)
        return LX_OK;
    size_t bytes = sizeof(lx_vec3) * (map->info.used_texels ? map->info.used_texels : 1);
    lx_vec3 *p = malloc(bytes), *n = malloc(bytes), *g = malloc(bytes);
    if (!p || !n || !g) {
        free(p);
        free(n);
        free(g);
        return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for its object space",
                       map->name);
    }
    /* built at the identity: the world arrays are the object space */
    memcpy(p, map->world_position, bytes);
    memcpy(n, map->world_normal, bytes);
    memcpy(g, map->world_geometric_normal, bytes);
    map->object_position = p;
    map->object_normal = n;
    map->object_geometric_normal = g;
    if (map->lift) {
        if (!(map->object_lift = malloc(bytes)))
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for its object space",
                           map->name);
        memcpy(map->object_lift, map->lift, bytes);
    }
    if (map->world_smooth_normal) {
        if (!(map->object_smooth_normal = malloc(bytes)))
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for its object space",
                           map->name);
        memcpy(map->object_smooth_normal, map->world_smooth_normal, bytes);
    }
    if (map->sub_count) {
        size_t sub = sizeof(lx_vec3) * map->sub_count * (size_t)map->info.used_texels;
        lx_vec3 *sp = malloc(sub ? sub : 1), *sn = malloc(sub ? sub : 1),
                *sg = malloc(sub ? sub : 1);
        if (!sp || !sn || !sg) {
            free(sp);
            free(sn);
            free(sg);
            return lx_fail(LX_ERR_NOMEM,
                           "lightmap '%s': out of memory for its supersampling's object space",
                           map->name);
        }
        memcpy(sp, map->sub_position, sub);
        memcpy(sn, map->sub_normal, sub);
        memcpy(sg, map->sub_geometric_normal, sub);
        map->sub_object_position = sp;
        map->sub_object_normal = sn;
        map->sub_object_geometric_normal = sg;
    }
    return LX_OK;
}

void lx_texel_map_transform(lx_lightmap *map, uint32_t node, const lx_mat4 *world)
{
    /* the footprints were the old transform's: edge supersampling stops */
    lx_texel_footprints_free(map->footprints);
    map->footprints = NULL;
    lx_mat4 nm;
    if (!lx_mat4_normal_matrix(world, &nm))
        nm = *world;
    for (uint32_t i = 0; i < map->info.used_texels; i++) {
        if (map->texels[i].node != node)
            continue;
        map->world_position[i] = lx_mat4_point(world, map->object_position[i]);
        map->world_normal[i] = lx_normalize(lx_mat4_vector(&nm, map->object_normal[i]));
        map->world_geometric_normal[i] =
            lx_normalize(lx_mat4_vector(&nm, map->object_geometric_normal[i]));
        if (map->lift)
            map->lift[i] = lx_mat4_vector(world, map->object_lift[i]);
        if (map->world_smooth_normal)
            map->world_smooth_normal[i] =
                lx_normalize(lx_mat4_vector(&nm, map->object_smooth_normal[i]));
        for (uint32_t s = 0; s < map->sub_count; s++) {
            size_t at = (size_t)s * map->info.used_texels + i;
            map->sub_position[at] = lx_mat4_point(world, map->sub_object_position[at]);
            map->sub_normal[at] = lx_normalize(lx_mat4_vector(&nm, map->sub_object_normal[at]));
            map->sub_geometric_normal[at] =
                lx_normalize(lx_mat4_vector(&nm, map->sub_object_geometric_normal[at]));
        }
    }
}

void lx_texel_map_free(lx_lightmap *map)
{
    free(map->name);
    free(map->texels);
    free(map->tile_start);
    free(map->world_position);
    free(map->horizon);
    free(map->world_normal);
    free(map->world_geometric_normal);
    free(map->object_position);
    free(map->object_normal);
    free(map->object_geometric_normal);
    free(map->world_smooth_normal);
    free(map->object_smooth_normal);
    free(map->lift);
    free(map->object_lift);
    free(map->albedo);
    free(map->emission);
    free(map->mask);
    free(map->baked);
    free(map->realtime);
    free(map->sh);
    free(map->gi_valid);
    free(map->gi_variance);
    free(map->sampled);
    free(map->sampled_variance);
    lx_seam_stitch_free(map->stitch);
    free(map->sub_position);
    free(map->sub_normal);
    free(map->sub_geometric_normal);
    free(map->sub_object_position);
    free(map->sub_object_normal);
    free(map->sub_object_geometric_normal);
    free(map->sub_covered);
    lx_texel_footprints_free(map->footprints);
    memset(map, 0, sizeof *map);
}
