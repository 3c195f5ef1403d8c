/* The bounce-by-bounce brute-force reference (bounce_reference.h). */
#include "bounce_reference.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* A sender: a small piece of a triangle, with the receiver texel whose
 * radiance it carries. */
typedef struct sender {
    double p[3], ng[3];
    double v[3][3]; /* the piece's corners */
    double area;
    uint32_t node_slot; /* index into desc->nodes */
    int parent;         /* receiver texel of that node */
} sender;

static double d3dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The receiver texel of node map `map` that carries the radiance of the
 * surface at lightmap UV (u, v): the texel containing it when used, else
 * the nearest used texel within two texels (chart borders whose centres
 * fall outside the chart); -1 when none. */
static int parent_texel(const lx_ref_map *map, double u, double v)
{
    int W = map->width, H = map->height;
    int x0 = (int)floor(u * W), y0 = (int)floor(v * H);
    int best = -1;
    double best_d2 = INFINITY;
    for (int dy = -2; dy <= 2; dy++)
        for (int dx = -2; dx <= 2; dx++) {
            int x = x0 + dx, y = y0 + dy;
            if (x < 0 || y < 0 || x >= W || y >= H || !map->texels[y * W + x].used)
                continue;
            double cx = (x + 0.5) / W - u, cy = (y + 0.5) / H - v;
            double d2 = cx * cx * W * W + cy * cy * H * H;
            if (d2 < best_d2)
                best_d2 = d2, best = y * W + x;
        }
    return best;
}

/* Splits every triangle of `node` (reference triangle `tri`, mesh m with
 * its lightmap UVs uv) into n^2 similar triangles, n = sub times the
 * triangle's longest UV edge in texels (at least sub), each a sender at
 * its centroid with its exact world area. */
static void add_senders(const lx_ref_triangle *tri, const lx_vec2 *uv, const uint32_t *idx,
                        const lx_ref_map *map, int sub, uint32_t slot, sender **snd,
                        size_t *count, size_t *cap)
{
    double uvp[3][2];
    for (int v = 0; v < 3; v++)
        uvp[v][0] = uv[idx[v]].x, uvp[v][1] = uv[idx[v]].y;
    double longest = 0.0;
    for (int v = 0; v < 3; v++) {
        const double *a = uvp[v], *b = uvp[(v + 1) % 3];
        longest = fmax(longest, fmax(fabs(a[0] - b[0]) * map->width,
                                     fabs(a[1] - b[1]) * map->height));
    }
    int n = sub * (int)ceil(fmax(longest, 1.0));
    double e1[3], e2[3], c[3], ng[3];
    for (int i = 0; i < 3; i++) {
        e1[i] = tri->p[1][i] - tri->p[0][i];
        e2[i] = tri->p[2][i] - tri->p[0][i];
    }
    lx_ref_cross(e1, e2, c);
    double area = 0.5 * sqrt(d3dot(c, c)) / ((double)n * n);
    memcpy(ng, c, sizeof ng);
    lx_ref_normalize(ng);
    /* sub-triangles in barycentric steps of 1/n: (i, j) upright and
     * (i, j) inverted */
    for (int i = 0; i < n; i++)
        for (int j = 0; i + j < n; j++)
            for (int flip = 0; flip < 2; flip++) {
                if (flip && i + j + 1 >= n)
                    continue;
                /* centroid in barycentrics of vertices 1 and 2 */
                double b1 = flip ? (i + 2.0 / 3.0) / n : (i + 1.0 / 3.0) / n;
                double b2 = flip ? (j + 2.0 / 3.0) / n : (j + 1.0 / 3.0) / n;
                double b0 = 1.0 - b1 - b2;
                double u = b0 * uvp[0][0] + b1 * uvp[1][0] + b2 * uvp[2][0];
                double v = b0 * uvp[0][1] + b1 * uvp[1][1] + b2 * uvp[2][1];
                int parent = parent_texel(map, u, v);
                if (parent < 0)
                    continue;
                if (*count == *cap) {
                    *cap = *cap ? 2 * *cap : 1024;
                    *snd = realloc(*snd, *cap * sizeof **snd);
                }
                sender *s = &(*snd)[(*count)++];
                for (int k = 0; k < 3; k++)
                    s->p[k] = b0 * tri->p[0][k] + b1 * tri->p[1][k] + b2 * tri->p[2][k];
                /* corners: (i, j), (i+1, j), (i, j+1) steps, or for the
                 * inverted piece (i+1, j+1), (i, j+1), (i+1, j) */
                const int corner[2][3][2] = {{{0, 0}, {1, 0}, {0, 1}}, {{1, 1}, {0, 1}, {1, 0}}};
                for (int q = 0; q < 3; q++) {
                    double c1 = (double)(i + corner[flip][q][0]) / n;
                    double c2 = (double)(j + corner[flip][q][1]) / n;
                    double c0 = 1.0 - c1 - c2;
                    for (int k = 0; k < 3; k++)
                        s->v[q][k] = c0 * tri->p[0][k] + c1 * tri->p[1][k] + c2 * tri->p[2][k];
                }
                /* the side the texel map calls front (mirroring transforms
                 * flip the winding's normal) */
                lx_vec3 tn = map->texels[parent].geometric_normal;
                double sgn = tn.x * ng[0] + tn.y * ng[1] + tn.z * ng[2] < 0.0 ? -1.0 : 1.0;
                for (int k = 0; k < 3; k++)
                    s->ng[k] = sgn * ng[k];
                s->area = area;
                s->node_slot = slot;
                s->parent = parent;
            }
}

/* Irradiance per unit radiance at p (unit normal n) from the triangle
 * v[3], wholly in front of p: Lambert's contour integral
 * 1/2 |sum over edges of gamma_i n . unit(a_i x a_i+1)|, a_i = v_i - p,
 * gamma_i the angle between a_i and a_i+1. Exact at any distance, so
 * pieces next to the receiver (a corner) are not points. */
static double polygon_irradiance(const double v[3][3], const double p[3], const double n[3])
{
    double a[3][3];
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < 3; k++)
            a[i][k] = v[i][k] - p[k];
        lx_ref_normalize(a[i]);
    }
    double sum = 0.0;
    for (int i = 0; i < 3; i++) {
        const double *x = a[i], *y = a[(i + 1) % 3];
        double c[3];
        lx_ref_cross(x, y, c);
        double len = sqrt(d3dot(c, c));
        if (!(len > 0.0))
            continue;
        double gamma = atan2(len, d3dot(x, y));
        sum += gamma * d3dot(n, c) / len;
    }
    return 0.5 * fabs(sum);
}

static void to_d(lx_vec3 v, double r[3])
{
    r[0] = v.x, r[1] = v.y, r[2] = v.z;
}

void lx_bref_run(const lx_bref_desc *d, lx_bref_result *out)
{
    memset(out, 0, sizeof *out);
    int W = d->width, H = d->height, S = d->sub > 0 ? d->sub : 1;
    size_t texels = (size_t)W * H;
    lx_ref_scene rs;
    lx_ref_scene_build(d->scene, &rs);
    out->node_count = d->node_count;
    out->width = W, out->height = H, out->bounces = d->bounces;
    out->maps = calloc(d->node_count, sizeof *out->maps);
    out->irradiance = calloc(d->node_count, sizeof *out->irradiance);
    lx_vec3 **albedo = calloc(d->node_count, sizeof *albedo);
    lx_vec3 **radiance = calloc(d->node_count, sizeof *radiance); /* R_k of each texel */
    size_t nsend = 0, cap = 0;
    sender *snd = NULL;
    for (uint32_t i = 0; i < d->node_count; i++) {
        uint32_t node = d->nodes[i];
        lx_ref_texel_map(d->scene, node, W, H, &out->maps[i]);
        out->irradiance[i] = calloc(texels * (size_t)(d->bounces + 1), sizeof(lx_vec3));
        albedo[i] = calloc(texels, sizeof(lx_vec3));
        radiance[i] = calloc(texels, sizeof(lx_vec3));
        for (size_t t = 0; t < texels; t++) {
            const lx_ref_texel *tx = &out->maps[i].texels[t];
            if (!tx->used)
                continue;
            lx_vec3 emitted = {0, 0, 0};
            d->material(d->user, node, tx, &albedo[i][t], &emitted);
            radiance[i][t] = emitted;
        }
        for (uint32_t k = 0; k < rs.count; k++) {
            const lx_ref_triangle *tri = &rs.tris[k];
            if (tri->node != node)
                continue;
            const lx_mesh *m = &d->scene->meshes[tri->mesh];
            int set = lx_ref_uv_set(m);
            if (set < 0)
                continue;
            add_senders(tri, m->uv[set], &m->indices[3 * tri->triangle], &out->maps[i], S, i,
                        &snd, &nsend, &cap);
        }
    }

    for (int k = 0; k <= d->bounces; k++) {
        /* gather G[R_k] at every receiver */
        for (uint32_t i = 0; i < d->node_count; i++)
            for (size_t t = 0; t < texels; t++) {
                const lx_ref_texel *rx = &out->maps[i].texels[t];
                if (!rx->used)
                    continue;
                double p[3], ng[3], e[3] = {0, 0, 0};
                to_d(rx->position, p);
                to_d(rx->geometric_normal, ng);
                float rb = lx_ref_bias(&rs, rx->position);
                for (size_t j = 0; j < nsend; j++) {
                    const sender *s = &snd[j];
                    lx_vec3 L = radiance[s->node_slot][s->parent];
                    if (L.x == 0.0f && L.y == 0.0f && L.z == 0.0f)
                        continue;
                    double dv[3] = {s->p[0] - p[0], s->p[1] - p[1], s->p[2] - p[2]};
                    double r2 = d3dot(dv, dv);
                    if (!(r2 > 0.0))
                        continue;
                    double r = sqrt(r2);
                    double ci = d3dot(ng, dv) / r, cj = -d3dot(s->ng, dv) / r;
                    if (ci <= 0.0 || cj <= 0.0)
                        continue;
                    /* both ends off their surfaces, toward each other */
                    lx_vec3 from = {(float)(p[0] + rb * ng[0]), (float)(p[1] + rb * ng[1]),
                                    (float)(p[2] + rb * ng[2])};
                    float sb = lx_ref_bias(&rs, (lx_vec3){(float)s->p[0], (float)s->p[1],
                                                          (float)s->p[2]});
                    double to[3] = {s->p[0] + sb * s->ng[0], s->p[1] + sb * s->ng[1],
                                    s->p[2] + sb * s->ng[2]};
                    double seg[3] = {to[0] - from.x, to[1] - from.y, to[2] - from.z};
                    double len = sqrt(d3dot(seg, seg));
                    if (!(len > 0.0))
                        continue;
                    lx_vec3 dir = {(float)(seg[0] / len), (float)(seg[1] / len),
                                   (float)(seg[2] / len)};
                    if (lx_ref_occluded(&rs, from, dir, 0.0, len, 0.0, NULL))
                        continue;
                    double w = polygon_irradiance(s->v, p, ng);
                    e[0] += L.x * w, e[1] += L.y * w, e[2] += L.z * w;
                }
                out->irradiance[i][(size_t)k * texels + t] =
                    (lx_vec3){(float)e[0], (float)e[1], (float)e[2]};
            }
        /* R_k+1 = albedo / pi (G[R_k] + direct at k = 0) */
        for (uint32_t i = 0; i < d->node_count; i++)
            for (size_t t = 0; t < texels; t++) {
                lx_vec3 g = out->irradiance[i][(size_t)k * texels + t];
                if (k == 0 && d->direct && d->direct[i]) {
                    g.x += d->direct[i][t].x;
                    g.y += d->direct[i][t].y;
                    g.z += d->direct[i][t].z;
                }
                lx_vec3 a = albedo[i][t];
                radiance[i][t] = (lx_vec3){(float)(a.x * g.x / LX_PI), (float)(a.y * g.y / LX_PI),
                                           (float)(a.z * g.z / LX_PI)};
            }
    }
    for (uint32_t i = 0; i < d->node_count; i++) {
        free(albedo[i]);
        free(radiance[i]);
    }
    free(albedo);
    free(radiance);
    free(snd);
    lx_ref_scene_free(&rs);
}

void lx_bref_free(lx_bref_result *r)
{
    for (uint32_t i = 0; i < r->node_count; i++) {
        lx_ref_map_free(&r->maps[i]);
        free(r->irradiance[i]);
    }
    free(r->maps);
    free(r->irradiance);
    memset(r, 0, sizeof *r);
}

lx_vec3 lx_bref_indirect(const lx_bref_result *r, uint32_t node, int texel, int bounces)
{
    size_t texels = (size_t)r->width * r->height;
    lx_vec3 s = {0, 0, 0};
    for (int k = 1; k <= bounces && k <= r->bounces; k++) {
        lx_vec3 g = r->irradiance[node][(size_t)k * texels + (size_t)texel];
        s.x += g.x, s.y += g.y, s.z += g.z;
    }
    return s;
}
