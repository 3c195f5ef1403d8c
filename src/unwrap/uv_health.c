/* UV health: whether a UV set can serve as lightmap UVs. The range, the
 * zero-area triangles (the baker's rule: |e1 x e2| <= 1e-7 (longest edge)^2),
 * the triangles turned against their mesh's majority, and the covered texels
 * two triangles overlap at a resolution. Coverage is the baker's
 * conservative one (a triangle covers a texel it overlaps with a positive
 * area: separating axes); a covered texel counts as overlapped when two
 * triangles share more than LX_UV_OVERLAP_AREA of it (the texel square
 * clipped by both triangles, Sutherland-Hodgman), so triangles that merely
 * share an edge never count. Work is split in tiles of texels, each with
 * the triangles binned to it; counts are integers summed per tile, the same
 * for any thread count. */
#include "luxel/unwrap.h"

#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TILE 32
/* The share of a texel two triangles must both cover for an overlap: above
 * float rounding along a shared edge (2.4e-4 texel at 4096 texels a side),
 * far below any real fold. */
#define OVERLAP_AREA 1e-3

lx_uv_health_desc lx_uv_health_desc_defaults(const lx_uv_health_desc *desc)
{
    lx_uv_health_desc d = {0};
    if (desc)
        d = *desc;
    if (d.resolution <= 0)
        d.resolution = 256;
    if (d.max_resolution <= 0)
        d.max_resolution = 4096;
    if (!(d.max_overlap > 0.0f))
        d.max_overlap = 0.01f;
    if (!(d.min_coverage > 0.0f))
        d.min_coverage = 0.125f;
    return d;
}

const char *lx_uv_problem_name(lx_uv_problem problem)
{
    switch (problem) {
    case LX_UV_OK:
        return "usable";
    case LX_UV_MISSING:
        return "missing";
    case LX_UV_OUTSIDE:
        return "outside [0,1]";
    case LX_UV_ZERO_AREA:
        return "zero-area triangles";
    case LX_UV_OVERLAP:
        return "overlapping";
    case LX_UV_SPARSE:
        return "sparse";
    case LX_UV_SHARED:
        return "shared";
    }
    return "unknown";
}

/* One triangle in texel units, with its inward edge lines. */
typedef struct htri {
    double p[3][2];
    double n[3][2], c[3]; /* inside: n . x + c >= 0 */
    int x0, y0, x1, y1;   /* texel bounds, clamped to the grid */
} htri;

typedef struct hmesh {
    const lx_mesh *mesh;
    const lx_mat4 *world; /* NULL: object space */
} hmesh;

static bool degenerate_uv(lx_vec2 a, lx_vec2 b, lx_vec2 c, double *cross)
{
    double e1x = (double)b.x - a.x, e1y = (double)b.y - a.y;
    double e2x = (double)c.x - a.x, e2y = (double)c.y - a.y;
    double e3x = (double)c.x - b.x, e3y = (double)c.y - b.y;
    *cross = e1x * e2y - e2x * e1y;
    double longest = fmax(e1x * e1x + e1y * e1y, fmax(e2x * e2x + e2y * e2y, e3x * e3x + e3y * e3y));
    return !(fabs(*cross) > 1e-7 * longest) || longest == 0.0;
}

/* Does t overlap texel (x, y) with a positive area? */
static bool tri_overlaps_texel(const htri *t, int x, int y)
{
    double cx[4] = {x, x + 1.0, x, x + 1.0}, cy[4] = {y, y, y + 1.0, y + 1.0};
    for (int e = 0; e < 3; e++) {
        int in = 0;
        for (int k = 0; k < 4; k++)
            in += t->n[e][0] * cx[k] + t->n[e][1] * cy[k] + t->c[e] > 0.0;
        if (in == 0)
            return false;
    }
    /* the texel's own axes: the triangle's bounds against the square */
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], t->p[k][d]);
            hi[d] = fmax(hi[d], t->p[k][d]);
        }
    return hi[0] > x && lo[0] < x + 1.0 && hi[1] > y && lo[1] < y + 1.0;
}

/* Keeps the part of polygon in (n points, at most 9) inside n . x + c >= 0. */
static int clip_line(const double (*in)[2], int n, const double nv[2], double c, double (*out)[2])
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *a = in[i], *b = in[(i + 1) % n];
        double da = nv[0] * a[0] + nv[1] * a[1] + c, db = nv[0] * b[0] + nv[1] * b[1] + c;
        if (da >= 0.0) {
            out[m][0] = a[0], out[m][1] = a[1];
            m++;
        }
        if ((da >= 0.0) != (db >= 0.0)) {
            double s = da / (da - db);
            out[m][0] = a[0] + s * (b[0] - a[0]);
            out[m][1] = a[1] + s * (b[1] - a[1]);
            m++;
        }
    }
    return m;
}

/* The texel square clipped by t: at most 7 corners. */
static int clip_tri(const double (*in)[2], int n, const htri *t, double (*out)[2])
{
    double tmp[12][2];
    n = clip_line(in, n, t->n[0], t->c[0], tmp);
    n = n ? clip_line((const double(*)[2])tmp, n, t->n[1], t->c[1], out) : 0;
    n = n ? clip_line((const double(*)[2])out, n, t->n[2], t->c[2], tmp) : 0;
    memcpy(out, tmp, sizeof(double) * 2 * (size_t)n);
    return n;
}

static double polygon_area(const double (*p)[2], int n)
{
    double a = 0.0;
    for (int i = 0; i < n; i++)
        a += p[i][0] * p[(i + 1) % n][1] - p[(i + 1) % n][0] * p[i][1];
    return fabs(0.5 * a);
}

static bool boxes_meet(const htri *a, const htri *b)
{
    return a->x0 <= b->x1 && b->x0 <= a->x1 && a->y0 <= b->y1 && b->y0 <= a->y1;
}

/* A growing array of uint32_t. */
typedef struct u32s {
    uint32_t *v;
    size_t n, cap;
} u32s;

static bool u32s_push(u32s *a, uint32_t x)
{
    if (a->n == a->cap) {
        size_t cap = a->cap ? 2 * a->cap : 256;
        uint32_t *v = realloc(a->v, sizeof *v * cap);
        if (!v)
            return false;
        a->v = v;
        a->cap = cap;
    }
    a->v[a->n++] = x;
    return true;
}

/* Covered and overlapped texels of tris on a w x h grid. */
static lx_status rasterize(const htri *tris, uint32_t count, int w, int h,
                           const lx_uv_health_desc *d, uint64_t *covered, uint64_t *overlapped)
{
    *covered = *overlapped = 0;
    int tx = (w + TILE - 1) / TILE, ty = (h + TILE - 1) / TILE;
    size_t tiles = (size_t)tx * (size_t)ty;
    size_t *start = calloc(tiles + 1, sizeof *start);
    uint64_t *tile_cov = calloc(tiles, sizeof *tile_cov);
    uint64_t *tile_ovl = calloc(tiles, sizeof *tile_ovl);
    if (!start || !tile_cov || !tile_ovl) {
        free(start);
        free(tile_cov);
        free(tile_ovl);
        return lx_fail(LX_ERR_NOMEM, "UV health: out of memory for %d x %d texels", w, h);
    }
    /* bin the triangles to the tiles their bounds reach, in triangle order */
    double work = 0.0; /* texel tests to come */
    for (uint32_t t = 0; t < count; t++) {
        if (tris[t].x0 > tris[t].x1 || tris[t].y0 > tris[t].y1)
            continue;
        work += (double)(tris[t].x1 - tris[t].x0 + 1) * (tris[t].y1 - tris[t].y0 + 1);
        for (int j = tris[t].y0 / TILE; j <= tris[t].y1 / TILE; j++)
            for (int i = tris[t].x0 / TILE; i <= tris[t].x1 / TILE; i++)
                start[(size_t)j * tx + i + 1]++;
    }
    for (size_t k = 0; k < tiles; k++)
        start[k + 1] += start[k];
    uint32_t *bins = malloc(sizeof *bins * (start[tiles] ? start[tiles] : 1));
    size_t *fill = malloc(sizeof *fill * (tiles ? tiles : 1));
    if (!bins || !fill) {
        free(bins);
        free(fill);
        free(start);
        free(tile_cov);
        free(tile_ovl);
        return lx_fail(LX_ERR_NOMEM, "UV health: out of memory binning %u triangles", count);
    }
    memcpy(fill, start, sizeof *fill * tiles);
    for (uint32_t t = 0; t < count; t++) {
        if (tris[t].x0 > tris[t].x1 || tris[t].y0 > tris[t].y1)
            continue;
        for (int j = tris[t].y0 / TILE; j <= tris[t].y1 / TILE; j++)
            for (int i = tris[t].x0 / TILE; i <= tris[t].x1 / TILE; i++)
                bins[fill[(size_t)j * tx + i]++] = t;
    }
    free(fill);

    int failed = 0, cancelled = 0;
    long long tile_count = (long long)tiles, done = 0;
    /* below a few milliseconds of work, waking threads costs more than it
     * saves (a scene of many small nodes calls this once a node) */
#pragma omp parallel num_threads(lx_thread_count(d->threads)) if (work > 1048576.0)
    {
        /* per texel of the tile: the triangles covering it (CSR) */
        uint32_t first[TILE * TILE + 1];
        u32s list = {0};
        u32s at = {0}; /* (texel, triangle) pairs in triangle order */
#pragma omp for schedule(dynamic, 1)
        for (long long k = 0; k < tile_count; k++) {
            int stop_a, stop_b;
#pragma omp atomic read
            stop_a = failed;
#pragma omp atomic read
            stop_b = cancelled;
            if (stop_a || stop_b)
                continue;
            int ox = (int)(k % tx) * TILE, oy = (int)(k / tx) * TILE;
            at.n = 0;
            bool ok = true;
            for (size_t b = start[k]; b < start[k + 1] && ok; b++) {
                const htri *t = &tris[bins[b]];
                int x0 = t->x0 > ox ? t->x0 : ox, x1 = t->x1 < ox + TILE - 1 ? t->x1 : ox + TILE - 1;
                int y0 = t->y0 > oy ? t->y0 : oy, y1 = t->y1 < oy + TILE - 1 ? t->y1 : oy + TILE - 1;
                for (int y = y0; y <= y1 && ok; y++)
                    for (int x = x0; x <= x1 && ok; x++)
                        if (tri_overlaps_texel(t, x, y))
                            ok = u32s_push(&at, (uint32_t)((y - oy) * TILE + (x - ox))) &&
                                 u32s_push(&at, bins[b]);
            }
            if (ok && list.cap < at.n / 2 + 1) {
                uint32_t *v = realloc(list.v, sizeof *v * (at.n / 2 + 1));
                ok = v != NULL;
                if (v) {
                    list.v = v;
                    list.cap = at.n / 2 + 1;
                }
            }
            if (!ok) {
#pragma omp atomic write
                failed = 1;
                continue;
            }
            memset(first, 0, sizeof first);
            for (size_t i = 0; i < at.n; i += 2)
                first[at.v[i] + 1]++;
            for (int i = 0; i < TILE * TILE; i++)
                first[i + 1] += first[i];
            uint32_t pos[TILE * TILE];
            memcpy(pos, first, sizeof pos);
            for (size_t i = 0; i < at.n; i += 2)
                list.v[pos[at.v[i]]++] = at.v[i + 1];
            uint64_t cov = 0, ovl = 0;
            for (int i = 0; i < TILE * TILE; i++) {
                uint32_t a = first[i], e = first[i + 1];
                if (a == e)
                    continue;
                cov++;
                double x = ox + i % TILE, y = oy + i / TILE;
                const double square[4][2] = {{x, y}, {x + 1, y}, {x + 1, y + 1}, {x, y + 1}};
                bool hit = false;
                for (uint32_t p = a; p < e && !hit; p++) {
                    const htri *A = &tris[list.v[p]];
                    double inA[12][2];
                    int na = clip_tri(square, 4, A, inA);
                    if (na < 3 || polygon_area((const double(*)[2])inA, na) <= OVERLAP_AREA)
                        continue;
                    for (uint32_t q = p + 1; q < e && !hit; q++) {
                        const htri *B = &tris[list.v[q]];
                        if (!boxes_meet(A, B))
                            continue;
                        double both[12][2];
                        int nb = clip_tri((const double(*)[2])inA, na, B, both);
                        hit = nb >= 3 && polygon_area((const double(*)[2])both, nb) > OVERLAP_AREA;
                    }
                }
                ovl += hit;
            }
            tile_cov[k] = cov;
            tile_ovl[k] = ovl;
            long long now;
#pragma omp atomic capture
            now = ++done;
            /* one thread reports; the others never wait for it */
            if (d->progress && omp_get_thread_num() == 0 &&
                !d->progress(d->progress_user, (float)now / (float)tile_count)) {
#pragma omp atomic write
                cancelled = 1;
            }
        }
        free(list.v);
        free(at.v);
    }
    for (size_t k = 0; k < tiles; k++) {
        *covered += tile_cov[k];
        *overlapped += tile_ovl[k];
    }
    free(bins);
    free(start);
    free(tile_cov);
    free(tile_ovl);
    if (cancelled)
        return lx_fail(LX_ERR_CANCELLED, "UV health cancelled");
    return failed ? lx_fail(LX_ERR_NOMEM, "UV health: out of memory for %d x %d texels", w, h)
                  : LX_OK;
}

static void set_reason(lx_uv_health *h, lx_uv_problem problem)
{
    h->problem = problem;
    h->usable = problem == LX_UV_OK;
    switch (problem) {
    case LX_UV_OK:
        h->reason[0] = '\0';
        break;
    case LX_UV_MISSING:
        snprintf(h->reason, sizeof h->reason, "no TEXCOORD_%d", h->uv_set);
        break;
    case LX_UV_OUTSIDE:
        snprintf(h->reason, sizeof h->reason, "outside [0,1] (u %.4g..%.4g, v %.4g..%.4g)",
                 (double)h->min.x, (double)h->max.x, (double)h->min.y, (double)h->max.y);
        break;
    case LX_UV_ZERO_AREA:
        snprintf(h->reason, sizeof h->reason, "%u zero-area triangle%s", h->zero_area_triangles,
                 h->zero_area_triangles == 1 ? "" : "s");
        break;
    case LX_UV_OVERLAP:
        snprintf(h->reason, sizeof h->reason, "overlaps on %.3g%% of its texels",
                 100.0 * h->overlap_share);
        break;
    case LX_UV_SPARSE:
        snprintf(h->reason, sizeof h->reason,
                 "covers %.3g%% of the UV square (a texture atlas's part?)", 100.0 * h->uv_area);
        break;
    case LX_UV_SHARED: /* lx_uv_share_nodes's, never set here */
        snprintf(h->reason, sizeof h->reason, "a piece of a UV square other nodes share");
        break;
    }
}

/* The health of the meshes together (one lightmap UV space). */
static lx_status health_of(const hmesh *meshes, uint32_t mesh_count, int uv_set,
                           const lx_uv_health_desc *in, bool sized_by_density, lx_uv_health *out)
{
    lx_uv_health_desc d = lx_uv_health_desc_defaults(in);
    memset(out, 0, sizeof *out);
    out->uv_set = uv_set;
    if (uv_set < 0 || uv_set >= LX_MAX_UV_SETS)
        return lx_fail(LX_ERR_INVALID, "UV set %d is outside 0..%d", uv_set, LX_MAX_UV_SETS - 1);
    if (d.resolution > LX_UNWRAP_MAX_ATLAS_SIZE || d.max_resolution > LX_UNWRAP_MAX_ATLAS_SIZE ||
        d.threads < 0 || !(d.texel_density >= 0.0f) || !isfinite(d.texel_density) ||
        !(d.max_overlap <= 1.0f))
        return lx_fail(LX_ERR_INVALID, "UV health: bad options (resolution %d, max resolution "
                                       "%d, threads %d, density %g, max overlap %g)",
                       d.resolution, d.max_resolution, d.threads, (double)d.texel_density,
                       (double)d.max_overlap);
    out->min = lx_v2(INFINITY, INFINITY);
    out->max = lx_v2(-INFINITY, -INFINITY);
    out->present = true;
    uint64_t total = 0;
    for (uint32_t k = 0; k < mesh_count; k++) {
        out->present &= meshes[k].mesh->uv[uv_set] != NULL;
        total += meshes[k].mesh->triangle_count;
    }
    if (!out->present) {
        out->min = out->max = lx_v2(0.0f, 0.0f);
        set_reason(out, LX_UV_MISSING);
        return LX_OK;
    }
    if (total > UINT32_MAX)
        return lx_fail(LX_ERR_INVALID, "UV health: %llu triangles is too many",
                       (unsigned long long)total);
    out->triangles = (uint32_t)total;
    double *cross = malloc(sizeof *cross * (total ? total : 1));
    uint8_t *zero = malloc(total ? total : 1);
    if (!cross || !zero) {
        free(cross);
        free(zero);
        return lx_fail(LX_ERR_NOMEM, "UV health: out of memory for %llu triangles",
                       (unsigned long long)total);
    }
    /* range, zero-area and turned triangles, areas */
    uint32_t base = 0;
    for (uint32_t k = 0; k < mesh_count; k++) {
        const lx_mesh *m = meshes[k].mesh;
        const lx_vec2 *uv = m->uv[uv_set];
        uint32_t pos = 0, neg = 0;
        for (uint32_t t = 0; t < m->triangle_count; t++) {
            const uint32_t *i = &m->indices[3 * t];
            lx_vec2 a = uv[i[0]], b = uv[i[1]], c = uv[i[2]];
            for (int v = 0; v < 3; v++) {
                lx_vec2 p = uv[i[v]];
                out->min.x = fminf(out->min.x, p.x);
                out->min.y = fminf(out->min.y, p.y);
                out->max.x = fmaxf(out->max.x, p.x);
                out->max.y = fmaxf(out->max.y, p.y);
            }
            double cr;
            zero[base + t] = degenerate_uv(a, b, c, &cr);
            cross[base + t] = cr;
            out->uv_area += 0.5 * fabs(cr);
            if (zero[base + t])
                out->zero_area_triangles++;
            else if (cr > 0.0)
                pos++;
            else
                neg++;
            lx_vec3 p0 = m->positions[i[0]], p1 = m->positions[i[1]], p2 = m->positions[i[2]];
            if (meshes[k].world) {
                p0 = lx_mat4_point(meshes[k].world, p0);
                p1 = lx_mat4_point(meshes[k].world, p1);
                p2 = lx_mat4_point(meshes[k].world, p2);
            }
            out->world_area += 0.5 * lx_length(lx_cross(lx_sub(p1, p0), lx_sub(p2, p0)));
        }
        out->flipped_triangles += pos >= neg ? neg : pos;
        base += m->triangle_count;
    }
    if (total == 0)
        out->min = out->max = lx_v2(0.0f, 0.0f);
    /* the bitmap's side: the baker's for the density, else the resolution */
    int res = d.resolution;
    if (sized_by_density && d.texel_density > 0.0f) {
        double r = out->uv_area > 0.0 ? d.texel_density * sqrt(out->world_area / out->uv_area)
                                      : 4.0;
        if (!(r <= d.max_resolution))
            res = d.max_resolution;
        else {
            res = (int)(ceil(r / 4.0) * 4.0);
            res = res > d.max_resolution ? d.max_resolution : res < 4 ? 4 : res;
        }
    }
    out->resolution = res;
    htri *tris = malloc(sizeof *tris * (total ? total : 1));
    if (!tris) {
        free(cross);
        free(zero);
        return lx_fail(LX_ERR_NOMEM, "UV health: out of memory for %llu triangles",
                       (unsigned long long)total);
    }
    uint32_t n = 0;
    base = 0;
    for (uint32_t k = 0; k < mesh_count; k++) {
        const lx_mesh *m = meshes[k].mesh;
        const lx_vec2 *uv = m->uv[uv_set];
        for (uint32_t t = 0; t < m->triangle_count; t++) {
            if (zero[base + t])
                continue; /* the baker skips them too */
            htri *h = &tris[n++];
            double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
            for (int v = 0; v < 3; v++) {
                lx_vec2 p = uv[m->indices[3 * t + v]];
                h->p[v][0] = (double)p.x * res;
                h->p[v][1] = (double)p.y * res;
                for (int e = 0; e < 2; e++) {
                    lo[e] = fmin(lo[e], h->p[v][e]);
                    hi[e] = fmax(hi[e], h->p[v][e]);
                }
            }
            double s = cross[base + t] > 0.0 ? 1.0 : -1.0;
            for (int e = 0; e < 3; e++) {
                const double *p = h->p[e], *q = h->p[(e + 1) % 3];
                /* left of p->q is inside for a counter-clockwise (s > 0) one */
                h->n[e][0] = -s * (q[1] - p[1]);
                h->n[e][1] = s * (q[0] - p[0]);
                h->c[e] = -(h->n[e][0] * p[0] + h->n[e][1] * p[1]);
            }
            /* texels the bounds reach, clamped in double (far-off UVs
             * neither overflow nor loop long) */
            h->x0 = (int)fmax(floor(lo[0]), 0.0);
            h->y0 = (int)fmax(floor(lo[1]), 0.0);
            h->x1 = (int)fmin(ceil(hi[0]) - 1.0, res - 1.0);
            h->y1 = (int)fmin(ceil(hi[1]) - 1.0, res - 1.0);
            if (!(lo[0] < res) || !(lo[1] < res) || !(hi[0] > 0.0) || !(hi[1] > 0.0))
                h->x0 = 1, h->x1 = 0; /* wholly off the grid */
        }
        base += m->triangle_count;
    }
    free(cross);
    free(zero);
    lx_status st = rasterize(tris, n, res, res, &d, &out->covered_texels,
                             &out->overlap_texels);
    free(tris);
    if (st != LX_OK)
        return st;
    out->overlap_share =
        out->covered_texels ? (double)out->overlap_texels / (double)out->covered_texels : 0.0;
    bool outside = total && (out->min.x < 0.0f || out->min.y < 0.0f || out->max.x > 1.0f ||
                             out->max.y > 1.0f);
    set_reason(out, outside                             ? LX_UV_OUTSIDE
                    : out->zero_area_triangles          ? LX_UV_ZERO_AREA
                    : out->overlap_share > d.max_overlap ? LX_UV_OVERLAP
                    : total && out->uv_area < d.min_coverage ? LX_UV_SPARSE
                                                         : LX_UV_OK);
    return LX_OK;
}

lx_status lx_uv_health_mesh(const lx_mesh *mesh, int uv_set, const lx_uv_health_desc *desc,
                            lx_uv_health *out)
{
    if (!mesh)
        return lx_fail_null(__func__, "mesh");
    if (!out)
        return lx_fail_null(__func__, "out");
    hmesh m = {mesh, NULL};
    return health_of(&m, 1, uv_set, desc, false, out);
}

lx_status lx_uv_health_node(const lx_scene *scene, uint32_t node, int uv_set,
                            const lx_uv_health_desc *desc, lx_uv_health *out)
{
    if (!scene)
        return lx_fail_null(__func__, "scene");
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    if (node >= scene->node_count)
        return lx_fail(LX_ERR_INVALID, "%s: node %u out of range (count %u)", scene->path, node,
                       scene->node_count);
    const lx_node *n = &scene->nodes[node];
    hmesh *meshes = malloc(sizeof *meshes * (n->mesh_count ? n->mesh_count : 1));
    if (!meshes)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    for (uint32_t k = 0; k < n->mesh_count; k++)
        meshes[k] = (hmesh){&scene->meshes[n->meshes[k]], &n->world};
    lx_status st = health_of(meshes, n->mesh_count, uv_set, desc, true, out);
    free(meshes);
    return st;
}
