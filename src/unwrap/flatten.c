/* Flattening a chart. Planar charts are projected onto their plane
 * (isometric). A curved chart keeps its projection when that serves
 * (xatlas's rule: nothing turned over or crossing, L2 stretch at most 1.1,
 * no triangle's above 1.25); otherwise it takes least-squares conformal
 * maps (Levy,
 * Petitjean, Ray and Maillot, "Least Squares Conformal Maps for Automatic
 * Texture Atlas Generation", SIGGRAPH 2002): the piecewise-linear map whose
 * gradients come closest to the Cauchy-Riemann equations, in the least-
 * squares sense weighted by area, with two vertices pinned. The normal
 * equations are solved by CHOLMOD's sparse Cholesky factorization
 * (SuiteSparse). The result is scaled to the chart's area and checked: a
 * triangle turned over, a border that crosses itself, two triangles
 * overlapping (chart_overlap.c) or an L2 stretch (Sander, Snyder, Gortler
 * and Hoppe, "Texture Mapping Progressive Meshes", 2001) above the limit
 * sends the chart back to be cut. Last, the chart is turned so that its
 * bounding box is smallest (rotating calipers over its convex hull) and
 * wider than tall. */
#include "unwrap_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <suitesparse/cholmod.h>

#define PLANAR_COS (1.0 - 1e-6)

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

static uint32_t find_vertex(const uint32_t *sorted, uint32_t n, uint32_t v)
{
    uint32_t lo = 0, hi = n;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (sorted[mid] < v)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* chart vertices (welded ids, ascending) and each corner's chart vertex */
static bool chart_vertices(const uw_mesh *m, uw_chart *c)
{
    size_t nc = 3 * (size_t)c->triangle_count;
    uint32_t *ids = malloc(sizeof(uint32_t) * nc);
    c->corners = malloc(sizeof(uint32_t) * nc);
    if (!ids || !c->corners) {
        free(ids);
        return false;
    }
    for (uint32_t i = 0; i < c->triangle_count; i++)
        for (int k = 0; k < 3; k++)
            ids[3 * i + k] = m->weld[m->indices[3 * c->triangles[i] + k]];
    memcpy(c->corners, ids, sizeof(uint32_t) * nc);
    qsort(ids, nc, sizeof(uint32_t), cmp_u32);
    uint32_t n = 0;
    for (size_t i = 0; i < nc; i++)
        if (n == 0 || ids[n - 1] != ids[i])
            ids[n++] = ids[i];
    /* never a zero size: realloc(p, 0) may free p and return NULL */
    uint32_t *shrunk = realloc(ids, sizeof(uint32_t) * (n ? n : 1));
    if (!shrunk) {
        free(ids);
        return false;
    }
    c->vertices = shrunk;
    c->vertex_count = n;
    for (size_t i = 0; i < nc; i++)
        c->corners[i] = find_vertex(c->vertices, n, c->corners[i]);
    return true;
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize3(double v[3])
{
    double len = sqrt(dot3(v, v));
    if (len > 0.0)
        for (int k = 0; k < 3; k++)
            v[k] /= len;
}

/* Projection onto the plane of normal n. */
static void project(const uw_mesh *m, const uw_chart *c, const double n[3], double *uv)
{
    double e1[3], e2[3];
    /* any direction across n: the axis least aligned with it */
    double axis[3] = {0, 0, 0};
    int k = fabs(n[0]) <= fabs(n[1]) && fabs(n[0]) <= fabs(n[2]) ? 0
            : fabs(n[1]) <= fabs(n[2])                           ? 1
                                                                 : 2;
    axis[k] = 1.0;
    cross3(n, axis, e1);
    normalize3(e1);
    cross3(n, e1, e2);
    for (uint32_t v = 0; v < c->vertex_count; v++) {
        const double *p = m->position[c->vertices[v]];
        uv[2 * v] = dot3(p, e1);
        uv[2 * v + 1] = dot3(p, e2);
    }
}

/* ---- least-squares conformal maps ------------------------------------------ */

/* The normal equations' matrix: symmetric, of 2x2 blocks [[c, s], [-s, c]]
 * per pair of vertices sharing a triangle (c the cotangent weight, s the
 * area term), in compressed rows. */
typedef struct lscm_matrix {
    uint32_t n;
    uint32_t *row; /* n + 1 */
    uint32_t *col; /* row[n] */
    double *c, *s; /* row[n] */
} lscm_matrix;

static void lscm_free(lscm_matrix *a)
{
    free(a->row);
    free(a->col);
    free(a->c);
    free(a->s);
}

typedef struct pair_entry {
    uint64_t key; /* (i << 32) | j */
    double c, s;
} pair_entry;

static int cmp_pair(const void *pa, const void *pb)
{
    const pair_entry *a = pa, *b = pb;
    return a->key < b->key ? -1 : a->key > b->key;
}

static bool lscm_build(const uw_mesh *m, const uw_chart *c, lscm_matrix *a)
{
    memset(a, 0, sizeof *a);
    size_t ne = 9 * (size_t)c->triangle_count;
    pair_entry *e = malloc(sizeof *e * ne);
    if (!e)
        return false;
    for (uint32_t i = 0; i < c->triangle_count; i++) {
        const uint32_t *idx = &m->indices[3 * c->triangles[i]];
        const double *p0 = m->position[idx[0]], *p1 = m->position[idx[1]],
                     *p2 = m->position[idx[2]];
        /* the triangle in its own plane: q0 = 0, q1 on +x */
        double d1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        double d2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        double x[3] = {d1[0], d1[1], d1[2]}, y[3], nrm[3];
        normalize3(x);
        cross3(d1, d2, nrm);
        normalize3(nrm);
        cross3(nrm, x, y);
        double q[3][2] = {{0.0, 0.0}, {dot3(d1, x), 0.0}, {dot3(d2, x), dot3(d2, y)}};
        double twice_area = q[1][0] * q[2][1];
        double area = 0.5 * twice_area;
        /* gradient of vertex k's hat function: the opposite edge turned a
         * quarter, over twice the area */
        double g[3][2];
        for (int k = 0; k < 3; k++) {
            const double *from = q[(k + 1) % 3], *to = q[(k + 2) % 3];
            g[k][0] = -(to[1] - from[1]) / twice_area;
            g[k][1] = (to[0] - from[0]) / twice_area;
        }
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++) {
                pair_entry *pe = &e[9 * (size_t)i + 3 * r + k];
                uint64_t vi = c->corners[3 * i + r], vj = c->corners[3 * i + k];
                pe->key = (vi << 32) | vj;
                pe->c = area * (g[r][0] * g[k][0] + g[r][1] * g[k][1]);
                pe->s = area * (g[r][1] * g[k][0] - g[r][0] * g[k][1]);
            }
    }
    qsort(e, ne, sizeof *e, cmp_pair);
    uint32_t n = c->vertex_count;
    a->n = n;
    a->row = calloc((size_t)n + 1, sizeof(uint32_t));
    a->col = malloc(sizeof(uint32_t) * ne);
    a->c = malloc(sizeof(double) * ne);
    a->s = malloc(sizeof(double) * ne);
    if (!a->row || !a->col || !a->c || !a->s) {
        free(e);
        lscm_free(a);
        return false;
    }
    uint32_t nnz = 0;
    for (size_t k = 0; k < ne;) {
        size_t j = k;
        double cs = 0.0, ss = 0.0;
        while (j < ne && e[j].key == e[k].key) {
            cs += e[j].c;
            ss += e[j].s;
            j++;
        }
        uint32_t ri = (uint32_t)(e[k].key >> 32);
        a->col[nnz] = (uint32_t)e[k].key;
        a->c[nnz] = cs;
        a->s[nnz] = ss;
        a->row[ri + 1]++;
        nnz++;
        k = j;
    }
    for (uint32_t i = 0; i < n; i++)
        a->row[i + 1] += a->row[i];
    free(e);
    return true;
}

/* Minimizes the conformal energy with vertices p0 and p1 held at their
 * uv. With z = u + iv per vertex the block [[c, s], [-s, c]] is the
 * complex number c - is, and the matrix is Hermitian positive definite:
 * the free unknowns solve H_ff z = -H_fp z_p, by CHOLMOD's sparse Cholesky
 * factorization (SuiteSparse) in complex arithmetic, half the size of the
 * real system. uv receives the result; false when the factorization fails
 * (the chart is then cut) or memory runs out (*nomem). */
static bool lscm_solve(const lscm_matrix *a, uint32_t p0, uint32_t p1, double *uv, bool *nomem)
{
    *nomem = false;
    uint32_t n = a->n;
    uint32_t *free_index = malloc(sizeof(uint32_t) * n);
    if (!free_index) {
        *nomem = true;
        return false;
    }
    uint32_t nf = 0;
    for (uint32_t i = 0; i < n; i++)
        free_index[i] = i == p0 || i == p1 ? UW_NONE : nf++;
    cholmod_common cc;
    cholmod_start(&cc);
    cc.print = 0; /* luxel reports, CHOLMOD stays quiet */
    cc.error_handler = NULL;
    cc.supernodal = CHOLMOD_SIMPLICIAL; /* no BLAS: no threads of its own */
    cholmod_triplet *t =
        cholmod_allocate_triplet(nf, nf, a->row[n], -1 /* lower triangle */, CHOLMOD_COMPLEX, &cc);
    cholmod_dense *b = cholmod_zeros(nf, 1, CHOLMOD_COMPLEX, &cc);
    cholmod_sparse *m = NULL;
    cholmod_factor *l = NULL;
    cholmod_dense *x = NULL;
    bool ok = t && b;
    if (ok) {
        int *ti = t->i, *tj = t->j;
        double *tx = t->x, *bx = b->x;
        size_t nz = 0;
        for (uint32_t i = 0; i < n; i++) {
            uint32_t fi = free_index[i];
            if (fi == UW_NONE)
                continue;
            for (uint32_t k = a->row[i]; k < a->row[i + 1]; k++) {
                uint32_t j = a->col[k], fj = free_index[j];
                double c = a->c[k], sv = a->s[k];
                if (fj == UW_NONE) {
                    /* a pinned neighbour moves to the right-hand side */
                    double xu = uv[2 * j], xv = uv[2 * j + 1];
                    bx[2 * fi] -= c * xu + sv * xv;
                    bx[2 * fi + 1] -= -sv * xu + c * xv;
                } else if (fi >= fj) {
                    ti[nz] = (int)fi;
                    tj[nz] = (int)fj;
                    tx[2 * nz] = c;
                    tx[2 * nz + 1] = -sv;
                    nz++;
                }
            }
        }
        t->nnz = nz;
        m = cholmod_triplet_to_sparse(t, nz, &cc);
        ok = m != NULL;
    }
    if (ok) {
        l = cholmod_analyze(m, &cc);
        ok = l && cholmod_factorize(m, l, &cc) && cc.status == CHOLMOD_OK;
    }
    if (ok) {
        x = cholmod_solve(CHOLMOD_A, l, b, &cc);
        ok = x != NULL;
    }
    if (ok) {
        const double *xx = x->x;
        for (uint32_t i = 0; i < n; i++)
            if (free_index[i] != UW_NONE) {
                uv[2 * i] = xx[2 * free_index[i]];
                uv[2 * i + 1] = xx[2 * free_index[i] + 1];
            }
    }
    *nomem = !ok && cc.status == CHOLMOD_OUT_OF_MEMORY;
    cholmod_free_dense(&x, &cc);
    cholmod_free_factor(&l, &cc);
    cholmod_free_sparse(&m, &cc);
    cholmod_free_dense(&b, &cc);
    cholmod_free_triplet(&t, &cc);
    cholmod_finish(&cc);
    free(free_index);
    return ok;
}

/* ---- checks -------------------------------------------------------------- */

static double signed_area(const double *uv, const uint32_t *tri)
{
    const double *a = &uv[2 * tri[0]], *b = &uv[2 * tri[1]], *c = &uv[2 * tri[2]];
    return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
}

/* The L2 stretch of the chart: sqrt of the area-weighted mean over its
 * triangles of (1/s1^2 + 1/s2^2) / 2, s1 and s2 the singular values of
 * the map from the surface to the plane (those of the inverse map, plane
 * to surface, are 1/s). 1 for an isometry once areas are equal. */
static double l2_stretch(const uw_mesh *m, const uw_chart *c, double *worst)
{
    double sum = 0.0, area = 0.0;
    if (worst)
        *worst = 0.0;
    for (uint32_t i = 0; i < c->triangle_count; i++) {
        const uint32_t *idx = &m->indices[3 * c->triangles[i]];
        const uint32_t *cv = &c->corners[3 * i];
        const double *p0 = m->position[idx[0]], *p1 = m->position[idx[1]],
                     *p2 = m->position[idx[2]];
        double d1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        double d2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        /* surface gradients of u and v (Sander et al.): S_s = dq/ds etc.
         * computed as the map from uv to the surface */
        const double *u0 = &c->uv[2 * cv[0]], *u1 = &c->uv[2 * cv[1]], *u2 = &c->uv[2 * cv[2]];
        double s1 = u1[0] - u0[0], t1 = u1[1] - u0[1], s2 = u2[0] - u0[0], t2 = u2[1] - u0[1];
        double det = s1 * t2 - s2 * t1;
        if (!(det > 0.0))
            return INFINITY;
        double ss[3], st[3]; /* dp/ds and dp/dt */
        for (int k = 0; k < 3; k++) {
            ss[k] = (d1[k] * t2 - d2[k] * t1) / det;
            st[k] = (d2[k] * s1 - d1[k] * s2) / det;
        }
        double a = dot3(ss, ss), cc = dot3(st, st);
        if (worst) {
            /* the larger singular value of [ss st]: the most a unit of uv
             * stretches to on the surface */
            double b = dot3(ss, st), half = 0.5 * (a + cc), dif = 0.5 * (a - cc);
            *worst = fmax(*worst, sqrt(half + sqrt(dif * dif + b * b)));
        }
        double w = m->area[c->triangles[i]];
        sum += w * 0.5 * (a + cc);
        area += w;
    }
    return area > 0.0 ? sqrt(sum / area) : 1.0;
}

static double orient(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

static bool on_segment(const double *a, const double *b, const double *p)
{
    return fmin(a[0], b[0]) <= p[0] && p[0] <= fmax(a[0], b[0]) && fmin(a[1], b[1]) <= p[1] &&
           p[1] <= fmax(a[1], b[1]);
}

static bool segments_touch(const double *a, const double *b, const double *c, const double *d)
{
    double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
        return true;
    return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
           (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
}

typedef struct segment {
    uint32_t a, b; /* chart vertices */
} segment;

typedef struct grid {
    double lo[2], scale[2];
    uint32_t nx, ny;
} grid;

/* The cells [x0, x1] x [y0, y1] segment s's box covers. */
static void cells_of(const grid *g, const double *uv, segment s, uint32_t r[4])
{
    const double *pa = &uv[2 * s.a], *pb = &uv[2 * s.b];
    r[0] = (uint32_t)fmin((fmin(pa[0], pb[0]) - g->lo[0]) * g->scale[0], g->nx - 1);
    r[1] = (uint32_t)fmin((fmax(pa[0], pb[0]) - g->lo[0]) * g->scale[0], g->nx - 1);
    r[2] = (uint32_t)fmin((fmin(pa[1], pb[1]) - g->lo[1]) * g->scale[1], g->ny - 1);
    r[3] = (uint32_t)fmin((fmax(pa[1], pb[1]) - g->lo[1]) * g->scale[1], g->ny - 1);
}

/* Does the chart's border cross or touch itself (other than at shared
 * vertices)? Border edges are binned in a uniform grid. */
static int border_crosses(const uw_mesh *m, const uw_chart *c)
{
    size_t cap = 3 * (size_t)c->triangle_count, n = 0;
    segment *seg = malloc(sizeof *seg * cap);
    if (!seg)
        return -1;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, total = 0.0;
    for (uint32_t i = 0; i < c->triangle_count; i++) {
        uint32_t t = c->triangles[i];
        for (int k = 0; k < 3; k++) {
            uint32_t u = m->adjacent[3 * t + k];
            if (u != UW_NONE && uw_chart_find(c, u) != UW_NONE)
                continue;
            segment s = {c->corners[3 * i + k], c->corners[3 * i + (k + 1) % 3]};
            seg[n++] = s;
            const double *pa = &c->uv[2 * s.a], *pb = &c->uv[2 * s.b];
            for (int d = 0; d < 2; d++) {
                lo[d] = fmin(lo[d], fmin(pa[d], pb[d]));
                hi[d] = fmax(hi[d], fmax(pa[d], pb[d]));
            }
            total += hypot(pb[0] - pa[0], pb[1] - pa[1]);
        }
    }
    if (n < 4) {
        free(seg);
        return 0;
    }
    /* about one segment a cell */
    double cell = total / (double)n;
    double ext0 = hi[0] - lo[0], ext1 = hi[1] - lo[1];
    if (!(cell > 0.0)) {
        free(seg);
        return 1;
    }
    uint32_t gx = (uint32_t)fmin(fmax(ext0 / cell, 1.0), 1024.0);
    uint32_t gy = (uint32_t)fmin(fmax(ext1 / cell, 1.0), 1024.0);
    double sx = gx / fmax(ext0, 1e-300), sy = gy / fmax(ext1, 1e-300);
    /* count, then fill the cells */
    uint32_t *start = calloc((size_t)gx * gy + 1, sizeof(uint32_t));
    if (!start) {
        free(seg);
        return -1;
    }
    size_t refs = 0;
    grid g = {{lo[0], lo[1]}, {sx, sy}, gx, gy};
    for (size_t i = 0; i < n; i++) {
        uint32_t r[4];
        cells_of(&g, c->uv, seg[i], r);
        for (uint32_t y = r[2]; y <= r[3]; y++)
            for (uint32_t x = r[0]; x <= r[1]; x++) {
                start[(size_t)y * gx + x + 1]++;
                refs++;
            }
    }
    for (size_t i = 0; i < (size_t)gx * gy; i++)
        start[i + 1] += start[i];
    uint32_t *items = malloc(sizeof(uint32_t) * (refs ? refs : 1));
    uint32_t *fill = malloc(sizeof(uint32_t) * (size_t)gx * gy);
    if (!items || !fill) {
        free(seg);
        free(start);
        free(items);
        free(fill);
        return -1;
    }
    memcpy(fill, start, sizeof(uint32_t) * (size_t)gx * gy);
    for (size_t i = 0; i < n; i++) {
        uint32_t r[4];
        cells_of(&g, c->uv, seg[i], r);
        for (uint32_t y = r[2]; y <= r[3]; y++)
            for (uint32_t x = r[0]; x <= r[1]; x++)
                items[fill[(size_t)y * gx + x]++] = (uint32_t)i;
    }
    int crosses = 0;
    for (size_t cidx = 0; cidx < (size_t)gx * gy && !crosses; cidx++)
        for (uint32_t i = start[cidx]; i < start[cidx + 1] && !crosses; i++)
            for (uint32_t j = i + 1; j < start[cidx + 1] && !crosses; j++) {
                segment s = seg[items[i]], t = seg[items[j]];
                if (s.a == t.a || s.a == t.b || s.b == t.a || s.b == t.b)
                    continue;
                crosses = segments_touch(&c->uv[2 * s.a], &c->uv[2 * s.b], &c->uv[2 * t.a],
                                         &c->uv[2 * t.b]);
            }
    free(seg);
    free(start);
    free(items);
    free(fill);
    return crosses;
}

/* Does the flattened chart fold onto itself: its border crossing or
 * touching itself, or two triangles overlapping (a border pinched at a
 * vertex folds without crossing)? 1, 0, or -1 out of memory. */
static int folds(const uw_mesh *m, const uw_chart *c)
{
    int crosses = border_crosses(m, c);
    return crosses ? crosses : uw_chart_overlaps(c);
}

/* ---- the smallest bounding box ------------------------------------------- */

static int cmp_point(const void *pa, const void *pb)
{
    const double *a = pa, *b = pb;
    if (a[0] != b[0])
        return a[0] < b[0] ? -1 : 1;
    return a[1] < b[1] ? -1 : a[1] > b[1];
}

/* Turns the chart so that its bounding box has the least area (an edge
 * of the convex hull lies along it), wider than tall, min corner at 0. */
static bool fit_box(uw_chart *c)
{
    uint32_t n = c->vertex_count;
    double *pts = malloc(sizeof(double) * 2 * n);
    double *hull = malloc(sizeof(double) * 2 * (2 * (size_t)n + 1));
    if (!pts || !hull) {
        free(pts);
        free(hull);
        return false;
    }
    memcpy(pts, c->uv, sizeof(double) * 2 * n);
    qsort(pts, n, 2 * sizeof(double), cmp_point);
    /* Andrew's monotone chain */
    size_t h = 0;
    for (uint32_t i = 0; i < n; i++) {
        while (h >= 2 && orient(&hull[2 * (h - 2)], &hull[2 * (h - 1)], &pts[2 * i]) <= 0)
            h--;
        hull[2 * h] = pts[2 * i], hull[2 * h + 1] = pts[2 * i + 1], h++;
    }
    for (size_t i = n - 1, lower = h + 1; i-- > 0;) {
        while (h >= lower && orient(&hull[2 * (h - 2)], &hull[2 * (h - 1)], &pts[2 * i]) <= 0)
            h--;
        hull[2 * h] = pts[2 * i], hull[2 * h + 1] = pts[2 * i + 1], h++;
    }
    if (h > 1)
        h--; /* the last point repeats the first */
    double best_area = INFINITY, best_cos = 1.0, best_sin = 0.0;
    for (size_t e = 0; e < h; e++) {
        const double *a = &hull[2 * e], *b = &hull[2 * ((e + 1) % h)];
        double dx = b[0] - a[0], dy = b[1] - a[1], len = hypot(dx, dy);
        if (!(len > 0.0))
            continue;
        double cs = dx / len, sn = dy / len;
        double lo0 = INFINITY, hi0 = -INFINITY, lo1 = INFINITY, hi1 = -INFINITY;
        for (size_t i = 0; i < h; i++) {
            double x = hull[2 * i], y = hull[2 * i + 1];
            double u = cs * x + sn * y, v = -sn * x + cs * y;
            lo0 = fmin(lo0, u), hi0 = fmax(hi0, u);
            lo1 = fmin(lo1, v), hi1 = fmax(hi1, v);
        }
        double area = (hi0 - lo0) * (hi1 - lo1);
        if (area < best_area * (1.0 - 1e-9)) {
            best_area = area;
            best_cos = cs;
            best_sin = sn;
        }
    }
    free(pts);
    free(hull);
    /* rotate by -angle of the chosen edge */
    double lo0 = INFINITY, hi0 = -INFINITY, lo1 = INFINITY, hi1 = -INFINITY;
    for (uint32_t i = 0; i < n; i++) {
        double x = c->uv[2 * i], y = c->uv[2 * i + 1];
        double u = best_cos * x + best_sin * y, v = -best_sin * x + best_cos * y;
        c->uv[2 * i] = u, c->uv[2 * i + 1] = v;
        lo0 = fmin(lo0, u), hi0 = fmax(hi0, u);
        lo1 = fmin(lo1, v), hi1 = fmax(hi1, v);
    }
    double w = hi0 - lo0, ht = hi1 - lo1;
    bool turn = ht > w;
    for (uint32_t i = 0; i < n; i++) {
        double u = c->uv[2 * i] - lo0, v = c->uv[2 * i + 1] - lo1;
        /* a quarter turn keeps the orientation: (u, v) -> (v, w - u) */
        c->uv[2 * i] = turn ? v : u;
        c->uv[2 * i + 1] = turn ? w - u : v;
    }
    c->width = turn ? ht : w;
    c->height = turn ? w : ht;
    return true;
}

/* ---- flattening ---------------------------------------------------------- */

#define ORTHO_STRETCH 1.1 /* xatlas's limits for keeping a projection */
#define ORTHO_WORST 1.25

/* Every triangle the right way up, then the uv scaled to the chart's
 * surface area; false when a triangle is not. */
static bool scale_to_area(uw_chart *c)
{
    double uv_area = 0.0;
    for (uint32_t i = 0; i < c->triangle_count; i++) {
        double a = signed_area(c->uv, &c->corners[3 * i]);
        if (!(a > 0.0) || !isfinite(a))
            return false;
        uv_area += a;
    }
    double scale = sqrt(c->area / uv_area);
    if (!isfinite(scale) || !(scale > 0.0))
        return false;
    for (uint32_t v = 0; v < 2 * c->vertex_count; v++)
        c->uv[v] *= scale;
    return true;
}

/* Whether c's projection (in c->uv) serves as its flattening: 1 (uv
 * scaled, c->stretch set), 0, or -1 out of memory. */
static int projection_serves(const uw_mesh *m, uw_chart *c, double max_stretch)
{
    if (!scale_to_area(c))
        return 0;
    double worst;
    double stretch = l2_stretch(m, c, &worst);
    if (!(stretch <= ORTHO_STRETCH && stretch <= max_stretch && worst <= ORTHO_WORST))
        return 0;
    int crosses = folds(m, c);
    if (crosses)
        return crosses < 0 ? -1 : 0;
    c->stretch = stretch;
    return 1;
}

bool uw_flatten(const uw_mesh *m, uw_chart *c, double max_stretch, lx_status *status)
{
    *status = LX_OK;
    if (!chart_vertices(m, c)) {
        *status = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
        return false;
    }
    c->uv = malloc(sizeof(double) * 2 * c->vertex_count);
    if (!c->uv) {
        *status = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
        return false;
    }
    double normal[3] = {0, 0, 0};
    c->area = 0.0;
    for (uint32_t i = 0; i < c->triangle_count; i++) {
        uint32_t t = c->triangles[i];
        for (int k = 0; k < 3; k++)
            normal[k] += m->normal[t][k] * m->area[t];
        c->area += m->area[t];
    }
    normalize3(normal);
    bool planar = true;
    for (uint32_t i = 0; i < c->triangle_count && planar; i++)
        planar = dot3(m->normal[c->triangles[i]], normal) >= PLANAR_COS;
    project(m, c, normal, c->uv);
    /* A curved chart keeps its projection when that serves (xatlas's
     * rule): nothing turned over or crossing, L2 stretch at most
     * ORTHO_STRETCH and no triangle stretched beyond ORTHO_WORST. It fills
     * its box as the surface does and needs no solve. */
    int ortho = planar ? 1 : projection_serves(m, c, max_stretch);
    if (ortho < 0) {
        *status = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
        return false;
    }
    if (!ortho) {
        project(m, c, normal, c->uv);
        /* pins: two vertices far apart (farthest from the first vertex,
         * then farthest from that one), held where the projection puts
         * them; they fix the similarity the conformal map is free in */
        uint32_t p0 = 0, p1 = 0;
        double best = -1.0;
        for (int round = 0; round < 2; round++) {
            const double *from = m->position[c->vertices[round == 0 ? 0 : p0]];
            best = -1.0;
            uint32_t far = 0;
            for (uint32_t v = 0; v < c->vertex_count; v++) {
                const double *p = m->position[c->vertices[v]];
                double d = (p[0] - from[0]) * (p[0] - from[0]) +
                           (p[1] - from[1]) * (p[1] - from[1]) +
                           (p[2] - from[2]) * (p[2] - from[2]);
                if (d > best)
                    best = d, far = v;
            }
            if (round == 0)
                p0 = far;
            else
                p1 = far;
        }
        lscm_matrix a;
        if (p0 == p1 || !lscm_build(m, c, &a)) {
            if (p0 != p1)
                *status = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
            return false;
        }
        bool nomem;
        bool solved = lscm_solve(&a, p0, p1, c->uv, &nomem);
        lscm_free(&a);
        if (!solved) {
            if (nomem)
                *status = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
            return false;
        }
    }
    if (planar || !ortho) {
        if (!scale_to_area(c))
            return false;
        c->stretch = planar ? 1.0 : l2_stretch(m, c, NULL);
        if (!(c->stretch <= max_stretch))
            return false;
        int crosses = folds(m, c);
        if (crosses < 0) {
            *status = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
            return false;
        }
        if (crosses)
            return false;
    }
    if (!fit_box(c)) {
        *status = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
        return false;
    }
    return true;
}
