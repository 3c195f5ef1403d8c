/* The tests' own check of lightmap UVs (uv_oracle.h) and generated meshes. */
#include "uv_oracle.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

bool lx_uv_overlaps_texel(const double uv[3][2], int x, int y)
{
    double x0 = x, y0 = y, lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], uv[k][d]);
            hi[d] = fmax(hi[d], uv[k][d]);
        }
    if (hi[0] <= x0 || lo[0] >= x0 + 1 || hi[1] <= y0 || lo[1] >= y0 + 1)
        return false;
    double corner[4][2] = {{x0, y0}, {x0 + 1, y0}, {x0, y0 + 1}, {x0 + 1, y0 + 1}};
    for (int e = 0; e < 3; e++) {
        const double *p = uv[e], *q = uv[(e + 1) % 3], *r = uv[(e + 2) % 3];
        double nx = q[1] - p[1], ny = p[0] - q[0];
        double side = nx * (r[0] - p[0]) + ny * (r[1] - p[1]);
        int out = 0;
        for (int k = 0; k < 4; k++) {
            double s = nx * (corner[k][0] - p[0]) + ny * (corner[k][1] - p[1]);
            out += side > 0 ? s <= 0 : s >= 0;
        }
        if (out == 4)
            return false;
    }
    return true;
}

/* Keeps the part of polygon in (n points) where sign * (p[axis] - at) >= 0. */
static int clip(const double (*in)[2], int n, int axis, double at, double sign, double (*out)[2])
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *a = in[i], *b = in[(i + 1) % n];
        double da = sign * (a[axis] - at), db = sign * (b[axis] - at);
        if (da >= 0) {
            out[m][0] = a[0], out[m][1] = a[1];
            m++;
        }
        if ((da >= 0) != (db >= 0)) {
            double t = da / (da - db);
            out[m][0] = a[0] + t * (b[0] - a[0]);
            out[m][1] = a[1] + t * (b[1] - a[1]);
            m++;
        }
    }
    return m;
}

double lx_uv_texel_coverage(const double uv[3][2], int x, int y)
{
    double a[8][2], b[8][2];
    int n = 3;
    for (int k = 0; k < 3; k++)
        a[k][0] = uv[k][0], a[k][1] = uv[k][1];
    n = clip((const double(*)[2])a, n, 0, x, 1.0, b);
    n = clip((const double(*)[2])b, n, 0, x + 1.0, -1.0, a);
    n = clip((const double(*)[2])a, n, 1, y, 1.0, b);
    n = clip((const double(*)[2])b, n, 1, y + 1.0, -1.0, a);
    double area = 0.0;
    for (int i = 0; i < n; i++)
        area += a[i][0] * a[(i + 1) % n][1] - a[(i + 1) % n][0] * a[i][1];
    return fabs(0.5 * area);
}

/* Keeps the part of polygon `in` on the inner side of the line through a
 * and b, inner being the side where `inner` lies. */
static int clip_side(const double (*in)[2], int n, const double *a, const double *b,
                     const double *inner, double (*out)[2])
{
    double ex = b[0] - a[0], ey = b[1] - a[1];
    double ref = ex * (inner[1] - a[1]) - ey * (inner[0] - a[0]);
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *p = in[i], *q = in[(i + 1) % n];
        double dp = (ex * (p[1] - a[1]) - ey * (p[0] - a[0])) * (ref > 0 ? 1 : -1);
        double dq = (ex * (q[1] - a[1]) - ey * (q[0] - a[0])) * (ref > 0 ? 1 : -1);
        if (dp >= 0) {
            out[m][0] = p[0], out[m][1] = p[1];
            m++;
        }
        if ((dp >= 0) != (dq >= 0)) {
            double t = dp / (dp - dq);
            out[m][0] = p[0] + t * (q[0] - p[0]);
            out[m][1] = p[1] + t * (q[1] - p[1]);
            m++;
        }
    }
    return m;
}

static int clip_by_triangle(double (*poly)[2], int n, const double t[3][2])
{
    double tmp[16][2];
    for (int e = 0; e < 3 && n > 0; e++) {
        n = clip_side((const double(*)[2])poly, n, t[e], t[(e + 1) % 3], t[(e + 2) % 3], tmp);
        memcpy(poly, tmp, sizeof(double) * 2 * (size_t)n);
    }
    return n;
}

uint64_t lx_uv_pair_overlaps(const double (*uv)[3][2], uint32_t n, int width, int height,
                             double min_area, uint64_t *covered)
{
    uint64_t overlapped = 0;
    *covered = 0;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            bool cov = false, both = false;
            for (uint32_t i = 0; i < n; i++) {
                cov = cov || lx_uv_overlaps_texel(uv[i], x, y);
                for (uint32_t j = i + 1; j < n && !both; j++) {
                    double poly[16][2] = {{x, y}, {x + 1, y}, {x + 1, y + 1}, {x, y + 1}};
                    int m = clip_by_triangle(poly, 4, uv[i]);
                    m = clip_by_triangle(poly, m, uv[j]);
                    double area = 0.0;
                    for (int k = 0; k < m; k++)
                        area += poly[k][0] * poly[(k + 1) % m][1] - poly[(k + 1) % m][0] * poly[k][1];
                    both = fabs(0.5 * area) > min_area;
                }
            }
            *covered += cov;
            overlapped += both;
        }
    return overlapped;
}

typedef struct corner_key {
    double u, v;
    uint32_t tri;
} corner_key;

static int cmp_corner(const void *pa, const void *pb)
{
    const corner_key *a = pa, *b = pb;
    if (a->u != b->u)
        return a->u < b->u ? -1 : 1;
    if (a->v != b->v)
        return a->v < b->v ? -1 : 1;
    return a->tri < b->tri ? -1 : a->tri > b->tri;
}

static uint32_t root(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x)
        x = parent[x] = parent[parent[x]];
    return x;
}

static double angle_at(const double *a, const double *b, const double *c, int dims)
{
    double u[3] = {0, 0, 0}, v[3] = {0, 0, 0}, uu = 0, vv = 0, uv = 0;
    for (int d = 0; d < dims; d++) {
        u[d] = b[d] - a[d];
        v[d] = c[d] - a[d];
        uu += u[d] * u[d];
        vv += v[d] * v[d];
        uv += u[d] * v[d];
    }
    double cs = uv / sqrt(uu * vv);
    return acos(fmax(-1.0, fmin(1.0, cs)));
}

void lx_uv_check(const lx_uv_triangle *tris, uint32_t n, int width, int height, int padding,
                 lx_uv_report *out)
{
    memset(out, 0, sizeof *out);
    /* charts: triangles sharing a UV point */
    uint32_t *parent = malloc(sizeof(uint32_t) * (n ? n : 1));
    corner_key *keys = malloc(sizeof(corner_key) * 3 * (size_t)(n ? n : 1));
    for (uint32_t t = 0; t < n; t++) {
        parent[t] = t;
        for (int k = 0; k < 3; k++)
            keys[3 * t + k] = (corner_key){tris[t].uv[k][0], tris[t].uv[k][1], t};
    }
    qsort(keys, 3 * (size_t)n, sizeof *keys, cmp_corner);
    for (size_t i = 1; i < 3 * (size_t)n; i++)
        if (keys[i].u == keys[i - 1].u && keys[i].v == keys[i - 1].v) {
            uint32_t a = root(parent, keys[i].tri), b = root(parent, keys[i - 1].tri);
            if (a != b)
                parent[a > b ? a : b] = a > b ? b : a;
        }
    free(keys);
    uint32_t *chart = malloc(sizeof(uint32_t) * (n ? n : 1));
    for (uint32_t t = 0; t < n; t++) {
        chart[t] = root(parent, t);
        out->charts += chart[t] == t;
    }
    free(parent);
    /* texel owners: -1 none, a chart, or -2 for two charts */
    size_t texels = (size_t)width * height;
    int64_t *owner = malloc(sizeof(int64_t) * texels);
    for (size_t i = 0; i < texels; i++)
        owner[i] = -1;
    double weight = 0.0;
    for (uint32_t t = 0; t < n; t++) {
        const lx_uv_triangle *tr = &tris[t];
        double px[3][2];
        bool outside = false;
        for (int k = 0; k < 3; k++) {
            outside = outside || tr->uv[k][0] < 0 || tr->uv[k][0] > 1 || tr->uv[k][1] < 0 ||
                      tr->uv[k][1] > 1;
            px[k][0] = tr->uv[k][0] * width;
            px[k][1] = tr->uv[k][1] * height;
        }
        out->outside += outside;
        double area = 0.5 * ((px[1][0] - px[0][0]) * (px[2][1] - px[0][1]) -
                             (px[2][0] - px[0][0]) * (px[1][1] - px[0][1]));
        double e1[3], e2[3], cr[3];
        for (int d = 0; d < 3; d++) {
            e1[d] = tr->p[1][d] - tr->p[0][d];
            e2[d] = tr->p[2][d] - tr->p[0][d];
        }
        cr[0] = e1[1] * e2[2] - e1[2] * e2[1];
        cr[1] = e1[2] * e2[0] - e1[0] * e2[2];
        cr[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double area3 = 0.5 * sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
        out->area_uv += area;
        out->area_3d += area3;
        if (!(area > 0.0)) {
            out->flipped++;
            continue;
        }
        double err = 0.0;
        for (int k = 0; k < 3; k++) {
            double a3 = angle_at(tr->p[k], tr->p[(k + 1) % 3], tr->p[(k + 2) % 3], 3);
            double a2 = angle_at(px[k], px[(k + 1) % 3], px[(k + 2) % 3], 2);
            err += fabs(a2 - a3) / 3.0;
            if (area > 1.0)
                out->angle_max = fmax(out->angle_max, fabs(a2 - a3));
        }
        out->angle_mean += err * area3;
        weight += area3;
        int x0 = (int)fmax(floor(fmin(px[0][0], fmin(px[1][0], px[2][0]))), 0.0);
        int x1 = (int)fmin(floor(fmax(px[0][0], fmax(px[1][0], px[2][0]))), width - 1.0);
        int y0 = (int)fmax(floor(fmin(px[0][1], fmin(px[1][1], px[2][1]))), 0.0);
        int y1 = (int)fmin(floor(fmax(px[0][1], fmax(px[1][1], px[2][1]))), height - 1.0);
        for (int y = y0; y <= y1; y++)
            for (int x = x0; x <= x1; x++) {
                if (!lx_uv_overlaps_texel(px, x, y))
                    continue;
                int64_t *o = &owner[(size_t)y * width + x];
                if (*o == -1)
                    *o = chart[t];
                else if (*o >= 0 && *o != (int64_t)chart[t])
                    *o = -2;
            }
    }
    out->angle_mean = weight > 0.0 ? out->angle_mean / weight : 0.0;
    /* padding: every covered texel claims the square of side 2 padding + 1
     * around it for its chart */
    int64_t *claim = malloc(sizeof(int64_t) * texels);
    for (size_t i = 0; i < texels; i++)
        claim[i] = -1;
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            int64_t o = owner[(size_t)y * width + x];
            if (o == -1)
                continue;
            out->covered++;
            out->overlap += o == -2;
            for (int dy = -padding; dy <= padding; dy++)
                for (int dx = -padding; dx <= padding; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= width || qy >= height)
                        continue;
                    int64_t *c = &claim[(size_t)qy * width + qx];
                    if (*c == -1)
                        *c = o;
                    else if (*c != o && *c != -2)
                        *c = -2;
                }
        }
    for (size_t i = 0; i < texels; i++)
        out->crowded += claim[i] == -2;
    free(claim);
    free(owner);
    free(chart);
}

/* ---- generated meshes ----------------------------------------------------- */

static lx_mesh alloc_mesh(const char *name, uint32_t vertices, uint32_t triangles)
{
    lx_mesh m = {0};
    m.name = (char *)name;
    m.vertex_count = vertices;
    m.triangle_count = triangles;
    m.positions = calloc(vertices, sizeof(lx_vec3));
    m.indices = calloc(3 * (size_t)triangles, sizeof(uint32_t));
    return m;
}

lx_mesh lx_test_torus(const char *name, double R, double r, uint32_t triangles)
{
    /* a x b quads around the ring and the tube, a = 2b */
    uint32_t b = (uint32_t)fmax(3.0, floor(sqrt(triangles / 4.0))), a = 2 * b;
    lx_mesh m = alloc_mesh(name, a * b, 2 * a * b);
    for (uint32_t i = 0; i < a; i++)
        for (uint32_t j = 0; j < b; j++) {
            double th = 2.0 * LX_PI * i / a, ph = 2.0 * LX_PI * j / b;
            m.positions[i * b + j] =
                lx_v3((float)((R + r * cos(ph)) * cos(th)), (float)(r * sin(ph)),
                      (float)((R + r * cos(ph)) * sin(th)));
        }
    uint32_t t = 0;
    for (uint32_t i = 0; i < a; i++)
        for (uint32_t j = 0; j < b; j++) {
            uint32_t p = i * b + j, q = ((i + 1) % a) * b + j;
            uint32_t p1 = i * b + (j + 1) % b, q1 = ((i + 1) % a) * b + (j + 1) % b;
            uint32_t quad[6] = {p, p1, q1, p, q1, q};
            memcpy(&m.indices[3 * t], quad, sizeof quad);
            t += 2;
        }
    return m;
}

lx_mesh lx_test_cylinder(const char *name, double radius, double height, uint32_t triangles)
{
    /* a side of s x h quads and two caps of s triangles, each cap with
     * its own vertices (a hard edge, as files have) */
    /* s^2 / 2 side triangles (h = s / 4 rows) and 2 s in the caps */
    uint32_t s = (uint32_t)fmax(3.0, floor(sqrt(2.0 * triangles))), h = (uint32_t)fmax(1, s / 4);
    uint32_t side_v = s * (h + 1), cap_v = s + 1;
    lx_mesh m = alloc_mesh(name, side_v + 2 * cap_v, 2 * s * h + 2 * s);
    for (uint32_t j = 0; j <= h; j++)
        for (uint32_t i = 0; i < s; i++) {
            double th = 2.0 * LX_PI * i / s;
            m.positions[j * s + i] = lx_v3((float)(radius * cos(th)), (float)(height * j / h),
                                           (float)(radius * sin(th)));
        }
    uint32_t t = 0;
    for (uint32_t j = 0; j < h; j++)
        for (uint32_t i = 0; i < s; i++) {
            uint32_t p = j * s + i, q = j * s + (i + 1) % s, p1 = p + s, q1 = q + s;
            uint32_t quad[6] = {p, p1, q1, p, q1, q};
            memcpy(&m.indices[3 * t], quad, sizeof quad);
            t += 2;
        }
    for (int cap = 0; cap < 2; cap++) {
        uint32_t base = side_v + (uint32_t)cap * cap_v;
        float y = cap ? (float)height : 0.0f;
        m.positions[base] = lx_v3(0.0f, y, 0.0f);
        for (uint32_t i = 0; i < s; i++) {
            double th = 2.0 * LX_PI * i / s;
            m.positions[base + 1 + i] =
                lx_v3((float)(radius * cos(th)), y, (float)(radius * sin(th)));
        }
        for (uint32_t i = 0; i < s; i++) {
            uint32_t u = base + 1 + i, w = base + 1 + (i + 1) % s;
            uint32_t tri[3] = {base, cap ? w : u, cap ? u : w}; /* outward */
            memcpy(&m.indices[3 * t], tri, sizeof tri);
            t++;
        }
    }
    return m;
}

lx_mesh lx_test_terrain(const char *name, double size, uint32_t triangles)
{
    uint32_t g = (uint32_t)fmax(2.0, floor(sqrt(triangles / 2.0)));
    lx_mesh m = alloc_mesh(name, (g + 1) * (g + 1), 2 * g * g);
    for (uint32_t j = 0; j <= g; j++)
        for (uint32_t i = 0; i <= g; i++) {
            double x = size * i / g, z = size * j / g;
            double y = 0.03 * size * sin(2.3 * x / size * 10.0) * cos(1.7 * z / size * 10.0);
            m.positions[j * (g + 1) + i] = lx_v3((float)x, (float)y, (float)z);
        }
    uint32_t t = 0;
    for (uint32_t j = 0; j < g; j++)
        for (uint32_t i = 0; i < g; i++) {
            uint32_t p = j * (g + 1) + i, q = p + 1, p1 = p + g + 1, q1 = p1 + 1;
            uint32_t quad[6] = {p, p1, q1, p, q1, q};
            memcpy(&m.indices[3 * t], quad, sizeof quad);
            t += 2;
        }
    return m;
}
