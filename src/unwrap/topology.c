/* The unwrapper's view of a mesh: vertices welded by position (a file
 * splits vertices along hard edges and texture seams; charts may cross
 * those), triangles joined across their manifold edges, and the cost of
 * crossing each edge where the file's vertices are split. */
#include "unwrap_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- welding ----------------------------------------------------------- */

static uint32_t float_bits(float f)
{
    if (f == 0.0f)
        f = 0.0f; /* -0 and +0 are the same place */
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static uint32_t hash_position(lx_vec3 p)
{
    return lx_hash4(0x5eed, float_bits(p.x), float_bits(p.y), float_bits(p.z));
}

static bool same_position(lx_vec3 a, lx_vec3 b)
{
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

/* weld[v] = the first vertex with v's position (open addressing). */
static lx_status weld_vertices(const lx_mesh *mesh, uint32_t *weld)
{
    uint32_t n = mesh->vertex_count, size = 16;
    while (size < 2 * n)
        size *= 2;
    uint32_t *table = malloc(sizeof(uint32_t) * size);
    if (!table)
        return lx_fail(LX_ERR_NOMEM, "out of memory welding mesh '%s'", mesh->name);
    memset(table, 0xff, sizeof(uint32_t) * size);
    for (uint32_t v = 0; v < n; v++) {
        uint32_t h = hash_position(mesh->positions[v]) & (size - 1);
        for (;;) {
            uint32_t w = table[h];
            if (w == UW_NONE) {
                table[h] = v;
                weld[v] = v;
                break;
            }
            if (same_position(mesh->positions[w], mesh->positions[v])) {
                weld[v] = w;
                break;
            }
            h = (h + 1) & (size - 1);
        }
    }
    free(table);
    return LX_OK;
}

/* ---- edges ------------------------------------------------------------- */

typedef struct edge_rec {
    uint64_t key;    /* welded (lo << 32) | hi */
    uint32_t corner; /* 3 * triangle + k */
} edge_rec;

/* LSD radix sort by key, 16 bits a pass; stable, so equal keys stay in
 * corner order. */
static lx_status sort_edges(edge_rec *recs, size_t n)
{
    edge_rec *tmp = malloc(sizeof *tmp * (n ? n : 1));
    uint32_t *count = malloc(sizeof(uint32_t) * 65536);
    if (!tmp || !count) {
        free(tmp);
        free(count);
        return lx_fail(LX_ERR_NOMEM, "out of memory sorting edges");
    }
    edge_rec *src = recs, *dst = tmp;
    for (int pass = 0; pass < 4; pass++) {
        int shift = 16 * pass;
        memset(count, 0, sizeof(uint32_t) * 65536);
        for (size_t i = 0; i < n; i++)
            count[(src[i].key >> shift) & 0xffff]++;
        uint32_t sum = 0;
        for (int b = 0; b < 65536; b++) {
            uint32_t c = count[b];
            count[b] = sum;
            sum += c;
        }
        for (size_t i = 0; i < n; i++)
            dst[count[(src[i].key >> shift) & 0xffff]++] = src[i];
        edge_rec *t = src;
        src = dst;
        dst = t;
    }
    /* four passes: the sorted data is back in recs */
    free(tmp);
    free(count);
    return LX_OK;
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* What crossing the edge between corners ca (triangle t's edge k) and cb
 * costs: nothing where the file shares the vertices; else a texture seam
 * (0.5), more the more the file's normals turn across it (a hard edge). */
static float seam_cost(const lx_mesh *mesh, uint32_t ca, uint32_t cb)
{
    const uint32_t *idx = mesh->indices;
    uint32_t ta = ca / 3, ka = ca % 3, tb = cb / 3, kb = cb % 3;
    uint32_t a0 = idx[3 * ta + ka], a1 = idx[3 * ta + (ka + 1) % 3];
    uint32_t b0 = idx[3 * tb + kb], b1 = idx[3 * tb + (kb + 1) % 3];
    if (a0 == b1 && a1 == b0)
        return 0.0f;
    double d = 1.0;
    if (mesh->normals) {
        lx_vec3 n0 = mesh->normals[a0], n1 = mesh->normals[a1];
        lx_vec3 m0 = mesh->normals[b1], m1 = mesh->normals[b0];
        double d0 = fmin(fmax(lx_dot(n0, m0), 0.0), 1.0);
        double d1 = fmin(fmax(lx_dot(n1, m1), 0.0), 1.0);
        d = 0.5 * (d0 + d1);
    }
    return (float)(4.0 * (1.0 - d) + 0.5);
}

lx_status uw_mesh_build(const lx_mesh *mesh, const double linear[9], uw_mesh *m)
{
    memset(m, 0, sizeof *m);
    uint32_t nv = mesh->vertex_count, nt = mesh->triangle_count;
    m->vertex_count = nv;
    m->triangle_count = nt;
    m->indices = mesh->indices;
    m->position = malloc(sizeof *m->position * nv);
    m->weld = malloc(sizeof(uint32_t) * nv);
    m->adjacent = malloc(sizeof(uint32_t) * 3 * (size_t)nt);
    m->seam = calloc(3 * (size_t)nt, sizeof(float));
    m->normal = malloc(sizeof *m->normal * nt);
    m->area = malloc(sizeof(double) * nt);
    m->edge_length = malloc(sizeof(double) * 3 * (size_t)nt);
    m->degenerate = calloc(nt, 1);
    edge_rec *recs = malloc(sizeof *recs * 3 * (size_t)nt);
    if (!m->position || !m->weld || !m->adjacent || !m->seam || !m->normal || !m->area ||
        !m->edge_length || !m->degenerate || !recs) {
        free(recs);
        uw_mesh_free(m);
        return lx_fail(LX_ERR_NOMEM, "out of memory unwrapping mesh '%s'", mesh->name);
    }
    for (uint32_t v = 0; v < nv; v++) {
        lx_vec3 p = mesh->positions[v];
        for (int r = 0; r < 3; r++)
            m->position[v][r] =
                linear[3 * r] * p.x + linear[3 * r + 1] * p.y + linear[3 * r + 2] * p.z;
    }
    lx_status st = weld_vertices(mesh, m->weld);
    if (st != LX_OK) {
        free(recs);
        uw_mesh_free(m);
        return st;
    }
    for (uint32_t t = 0; t < nt; t++) {
        const uint32_t *idx = &mesh->indices[3 * t];
        const double *a = m->position[idx[0]], *b = m->position[idx[1]], *c = m->position[idx[2]];
        double e1[3], e2[3], n[3], longest = 0.0;
        for (int r = 0; r < 3; r++) {
            e1[r] = b[r] - a[r];
            e2[r] = c[r] - a[r];
        }
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        for (int k = 0; k < 3; k++) {
            const double *p = m->position[idx[k]], *q = m->position[idx[(k + 1) % 3]];
            double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
            double len2 = dot3(d, d);
            m->edge_length[3 * t + k] = sqrt(len2);
            longest = fmax(longest, len2);
        }
        double cross = sqrt(dot3(n, n));
        /* the scene's rule (lx_triangle_degenerate): area negligible next
         * to the longest edge; welded corners are degenerate too */
        bool degenerate = !(cross > 1e-6 * longest) || m->weld[idx[0]] == m->weld[idx[1]] ||
                          m->weld[idx[1]] == m->weld[idx[2]] || m->weld[idx[0]] == m->weld[idx[2]];
        m->degenerate[t] = degenerate;
        m->degenerate_count += degenerate;
        m->area[t] = degenerate ? 0.0 : 0.5 * cross;
        for (int r = 0; r < 3; r++)
            m->normal[t][r] = degenerate ? 0.0 : n[r] / cross;
    }
    /* half-edges keyed by their welded ends; exactly two with opposite
     * directions make a manifold edge, anything else is a border */
    size_t nrec = 0;
    for (uint32_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            m->adjacent[3 * t + k] = UW_NONE;
            if (m->degenerate[t])
                continue;
            uint32_t a = m->weld[mesh->indices[3 * t + k]];
            uint32_t b = m->weld[mesh->indices[3 * t + (k + 1) % 3]];
            uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
            recs[nrec].key = (lo << 32) | hi;
            recs[nrec].corner = 3 * t + (uint32_t)k;
            nrec++;
        }
    st = sort_edges(recs, nrec);
    if (st != LX_OK) {
        free(recs);
        uw_mesh_free(m);
        return st;
    }
    for (size_t i = 0; i < nrec;) {
        size_t j = i + 1;
        while (j < nrec && recs[j].key == recs[i].key)
            j++;
        if (j - i == 2) {
            uint32_t ca = recs[i].corner, cb = recs[i + 1].corner;
            uint32_t a_from = m->weld[mesh->indices[ca]];
            uint32_t b_from = m->weld[mesh->indices[cb]];
            if (a_from != b_from) { /* opposite directions: consistently oriented */
                m->adjacent[ca] = cb / 3;
                m->adjacent[cb] = ca / 3;
                float cost = seam_cost(mesh, ca, cb);
                m->seam[ca] = cost;
                m->seam[cb] = cost;
            }
        }
        i = j;
    }
    free(recs);
    return LX_OK;
}

void uw_mesh_free(uw_mesh *m)
{
    free(m->position);
    free(m->weld);
    free(m->adjacent);
    free(m->seam);
    free(m->normal);
    free(m->area);
    free(m->edge_length);
    free(m->degenerate);
    memset(m, 0, sizeof *m);
}
