/* MikkTSpace tangent frames per triangle corner: Morten S. Mikkelsen,
 * "Simulation of Wrinkled Surfaces Revisited" (MSc thesis, 2008), as the
 * reference implementation (mikktspace.c, used by Blender and required by
 * glTF 2.0 for files without tangents) documents its behaviour with its
 * default settings. Written here from that description:
 *  1. corners are welded into vertices when position, normal and UV are
 *     all equal;
 *  2. triangles with two equal corner positions are degenerate and left
 *     out until step 6;
 *  3. each triangle gets dP/du and dP/dv (unit, signed so that they follow
 *     +u and +v), their magnitudes, and its orientation (the sign of its
 *     UV area); triangles without a usable UV gradient start no group but
 *     may join any (taking its orientation);
 *  4. triangles sharing an edge (same two welded vertices, opposite
 *     direction) are neighbours; around each welded vertex, the fan of
 *     neighbouring triangles of one orientation is a group (a vertex is
 *     split between mirrored halves);
 *  5. a group's tangent is the angle-weighted sum of its triangles' dP/du
 *     projected into the plane of the vertex normal, normalized; the
 *     handedness is the group's orientation (triangles whose projected
 *     gradients point exactly opposite form their own subgroup, the
 *     reference's 180-degree threshold);
 *  6. degenerate triangles copy the frame of a good corner of the same
 *     welded vertex.
 * luxel's UVs have v growing downward (glTF), so the glTF handedness is
 * the negated reference sign (as three.js and the glTF sample models do).
 * Arithmetic is in float, as in the reference, so that orientation and
 * zero tests decide the same way. Where the reference leaves a zero
 * tangent (a group of triangles without UV gradient only), luxel writes a
 * unit vector perpendicular to the normal instead. */
#include "core/internal.h"
#include "luxel/maps.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TRI_DEGENERATE 1u
#define TRI_ANY 2u    /* no usable UV gradient: joins any group */
#define TRI_ORIENT 4u /* positive UV area (orientation preserving) */

typedef struct tri_info {
    lx_vec3 os, ot; /* unit dP/du, dP/dv (or zero) */
    float mag_s, mag_t;
    int32_t nb[3];    /* neighbour across edge i (corner i to i+1), -1 none */
    int32_t group[3]; /* group of corner i, -1 none */
    unsigned flags;
} tri_info;

typedef struct mctx {
    const lx_mesh *m;
    const lx_vec2 *uv;
    size_t nt;
    uint32_t *weld; /* per corner: the welded vertex (its first corner) */
    tri_info *tri;
    int32_t *group_vertex; /* per group: welded vertex */
    uint8_t *group_orient;
    size_t groups;
    int32_t *stack;
} mctx;

static bool nz(float x)
{
    return fabsf(x) > 1.17549435e-38f; /* FLT_MIN, the reference's NotZero */
}
static bool vnz(lx_vec3 v)
{
    return nz(v.x) || nz(v.y) || nz(v.z);
}
static lx_vec3 vnorm(lx_vec3 v)
{
    float len = sqrtf(v.x * v.x + v.y * v.y + v.z * v.z);
    return lx_scale(v, 1.0f / len);
}
static lx_vec3 project(lx_vec3 v, lx_vec3 n)
{
    lx_vec3 r = lx_sub(v, lx_scale(n, lx_dot(n, v)));
    return vnz(r) ? vnorm(r) : r;
}

static lx_vec3 pos_of(const mctx *c, size_t corner)
{
    return c->m->positions[c->m->indices[corner]];
}
static lx_vec3 nrm_of(const mctx *c, size_t corner)
{
    return c->m->normals[c->m->indices[corner]];
}
static lx_vec2 uv_of(const mctx *c, size_t corner)
{
    return c->uv[c->m->indices[corner]];
}

/* ---- 1. welding ----------------------------------------------------------- */

typedef struct keyed {
    float key[8]; /* position, normal, uv */
    uint32_t corner;
} keyed;

static int keyed_cmp(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    for (int i = 0; i < 8; i++)
        if (x->key[i] != y->key[i])
            return x->key[i] < y->key[i] ? -1 : 1;
    return x->corner < y->corner ? -1 : x->corner > y->corner;
}

static bool weld(mctx *c)
{
    size_t nc = 3 * c->nt;
    keyed *order = malloc(sizeof(keyed) * (nc ? nc : 1));
    if (!order)
        return false;
    for (size_t k = 0; k < nc; k++) {
        lx_vec3 p = pos_of(c, k), n = nrm_of(c, k);
        lx_vec2 t = uv_of(c, k);
        const float v[8] = {p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y};
        for (int i = 0; i < 8; i++)
            order[k].key[i] = v[i] + 0.0f; /* -0 and +0 are equal, as == says */
        order[k].corner = (uint32_t)k;
    }
    qsort(order, nc, sizeof *order, keyed_cmp);
    for (size_t i = 0; i < nc;) {
        size_t j = i + 1;
        while (j < nc && memcmp(order[i].key, order[j].key, sizeof order[i].key) == 0)
            j++;
        for (size_t q = i; q < j; q++)
            c->weld[order[q].corner] = order[i].corner; /* the smallest corner of the run */
        i = j;
    }
    free(order);
    return true;
}

/* ---- 3. per-triangle gradients -------------------------------------------- */

static bool veq(lx_vec3 a, lx_vec3 b)
{
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

static void init_triangle(mctx *c, size_t f)
{
    tri_info *t = &c->tri[f];
    for (int i = 0; i < 3; i++)
        t->nb[i] = t->group[i] = -1;
    t->flags = TRI_ANY;
    lx_vec3 p1 = pos_of(c, 3 * f), p2 = pos_of(c, 3 * f + 1), p3 = pos_of(c, 3 * f + 2);
    if (veq(p1, p2) || veq(p1, p3) || veq(p2, p3)) {
        t->flags |= TRI_DEGENERATE;
        return;
    }
    lx_vec2 t1 = uv_of(c, 3 * f), t2 = uv_of(c, 3 * f + 1), t3 = uv_of(c, 3 * f + 2);
    float t21x = t2.x - t1.x, t21y = t2.y - t1.y, t31x = t3.x - t1.x, t31y = t3.y - t1.y;
    lx_vec3 d1 = lx_sub(p2, p1), d2 = lx_sub(p3, p1);
    float area2 = t21x * t31y - t21y * t31x;
    lx_vec3 os = lx_sub(lx_scale(d1, t31y), lx_scale(d2, t21y));
    lx_vec3 ot = lx_add(lx_scale(d1, -t31x), lx_scale(d2, t21x));
    if (area2 > 0.0f)
        t->flags |= TRI_ORIENT;
    if (nz(area2)) {
        float abs_area = fabsf(area2);
        float len_s = sqrtf(lx_dot(os, os)), len_t = sqrtf(lx_dot(ot, ot));
        float s = (t->flags & TRI_ORIENT) ? 1.0f : -1.0f;
        if (nz(len_s))
            os = lx_scale(os, s / len_s);
        if (nz(len_t))
            ot = lx_scale(ot, s / len_t);
        t->mag_s = len_s / abs_area;
        t->mag_t = len_t / abs_area;
        if (nz(t->mag_s) && nz(t->mag_t))
            t->flags &= ~TRI_ANY;
    }
    t->os = os;
    t->ot = ot;
}

/* ---- 4. neighbours and groups --------------------------------------------- */

typedef struct edge {
    uint32_t lo, hi; /* welded vertices, sorted */
    uint32_t f;
    uint8_t i;
} edge;

static int edge_cmp(const void *a, const void *b)
{
    const edge *x = a, *y = b;
    if (x->lo != y->lo)
        return x->lo < y->lo ? -1 : 1;
    if (x->hi != y->hi)
        return x->hi < y->hi ? -1 : 1;
    if (x->f != y->f)
        return x->f < y->f ? -1 : 1;
    return x->i < y->i ? -1 : x->i > y->i;
}

static bool neighbours(mctx *c)
{
    size_t ne = 0;
    edge *e = malloc(sizeof(edge) * 3 * (c->nt ? c->nt : 1));
    if (!e)
        return false;
    for (size_t f = 0; f < c->nt; f++) {
        if (c->tri[f].flags & TRI_DEGENERATE)
            continue;
        for (int i = 0; i < 3; i++) {
            uint32_t a = c->weld[3 * f + i], b = c->weld[3 * f + (i + 1) % 3];
            e[ne++] = (edge){a < b ? a : b, a < b ? b : a, (uint32_t)f, (uint8_t)i};
        }
    }
    qsort(e, ne, sizeof *e, edge_cmp);
    for (size_t i = 0; i < ne; i++) {
        tri_info *ta = &c->tri[e[i].f];
        if (ta->nb[e[i].i] != -1)
            continue;
        uint32_t a0 = c->weld[3 * e[i].f + e[i].i], a1 = c->weld[3 * e[i].f + (e[i].i + 1) % 3];
        /* the first later edge over the same vertices, run the other way */
        for (size_t j = i + 1; j < ne && e[j].lo == e[i].lo && e[j].hi == e[i].hi; j++) {
            tri_info *tb = &c->tri[e[j].f];
            uint32_t b0 = c->weld[3 * e[j].f + e[j].i];
            uint32_t b1 = c->weld[3 * e[j].f + (e[j].i + 1) % 3];
            if (b0 == a1 && b1 == a0 && tb->nb[e[j].i] == -1) {
                ta->nb[e[i].i] = (int32_t)e[j].f;
                tb->nb[e[j].i] = (int32_t)e[i].f;
                break;
            }
        }
    }
    free(e);
    return true;
}

/* The corner of triangle f at welded vertex v, or -1. */
static int corner_at(const mctx *c, size_t f, uint32_t v)
{
    for (int i = 0; i < 3; i++)
        if (c->weld[3 * f + i] == v)
            return i;
    return -1;
}

/* The fan of group g grown from triangle f across neighbours (the
 * reference's recursion, with an explicit stack). */
static void grow(mctx *c, int32_t g, int32_t start)
{
    size_t top = 0;
    c->stack[top++] = start;
    while (top) {
        int32_t f = c->stack[--top];
        tri_info *t = &c->tri[f];
        int i = corner_at(c, (size_t)f, (uint32_t)c->group_vertex[g]);
        if (i < 0 || t->group[i] != -1)
            continue; /* already this group's, or another's */
        if ((t->flags & TRI_ANY) && t->group[0] == -1 && t->group[1] == -1 &&
            t->group[2] == -1) {
            t->flags &= ~TRI_ORIENT; /* free to take the group's orientation */
            if (c->group_orient[g])
                t->flags |= TRI_ORIENT;
        }
        if (((t->flags & TRI_ORIENT) != 0) != (c->group_orient[g] != 0))
            continue;
        t->group[i] = g;
        /* right first on the stack, so that left is visited first */
        int32_t left = t->nb[i > 0 ? i - 1 : 2], right = t->nb[i];
        if (right >= 0)
            c->stack[top++] = right;
        if (left >= 0)
            c->stack[top++] = left;
    }
}

static void build_groups(mctx *c)
{
    for (size_t f = 0; f < c->nt; f++) {
        tri_info *t = &c->tri[f];
        if (t->flags & (TRI_DEGENERATE | TRI_ANY))
            continue; /* only triangles with a gradient start groups */
        for (int i = 0; i < 3; i++) {
            if (t->group[i] != -1)
                continue;
            int32_t g = (int32_t)c->groups++;
            c->group_vertex[g] = (int32_t)c->weld[3 * f + i];
            c->group_orient[g] = (t->flags & TRI_ORIENT) != 0;
            t->group[i] = g;
            int32_t left = t->nb[i > 0 ? i - 1 : 2], right = t->nb[i];
            if (left >= 0)
                grow(c, g, left);
            if (right >= 0)
                grow(c, g, right);
        }
    }
}

/* The reference's frame for corners it never reaches: +x with a negative
 * sign (glTF w = +1), here made perpendicular to the normal. */
static lx_vec4 initial_frame(lx_vec3 n)
{
    lx_vec3 t = lx_sub(lx_v3(1.0f, 0.0f, 0.0f), lx_scale(n, n.x));
    t = lx_length(t) > 1e-6f ? vnorm(t) : lx_perpendicular(n);
    return lx_v4(t.x, t.y, t.z, 1.0f);
}

/* ---- 5. a group's frame ----------------------------------------------------- */

/* Angle-weighted dP/du over triangles members[0..n) at welded vertex v. */
static lx_vec3 eval_frame(const mctx *c, const int32_t *members, size_t n, uint32_t v)
{
    lx_vec3 sum = lx_v3(0.0f, 0.0f, 0.0f);
    for (size_t k = 0; k < n; k++) {
        size_t f = (size_t)members[k];
        const tri_info *t = &c->tri[f];
        if (t->flags & TRI_ANY)
            continue;
        int i = corner_at(c, f, v);
        lx_vec3 nrm = nrm_of(c, 3 * f + (size_t)i);
        lx_vec3 os = project(t->os, nrm);
        lx_vec3 p0 = pos_of(c, 3 * f + (size_t)(i > 0 ? i - 1 : 2));
        lx_vec3 p1 = pos_of(c, 3 * f + (size_t)i);
        lx_vec3 p2 = pos_of(c, 3 * f + (size_t)(i < 2 ? i + 1 : 0));
        lx_vec3 v1 = project(lx_sub(p0, p1), nrm), v2 = project(lx_sub(p2, p1), nrm);
        float cosine = lx_dot(v1, v2);
        cosine = cosine > 1.0f ? 1.0f : cosine < -1.0f ? -1.0f : cosine;
        float angle = acosf(cosine);
        sum = lx_add(sum, lx_scale(os, angle));
    }
    return vnz(sum) ? vnorm(sum) : sum;
}

static bool frames(mctx *c, lx_vec4 *out)
{
    /* members of each group, in triangle order */
    size_t nc = 3 * c->nt;
    size_t *start = calloc(c->groups + 1, sizeof(size_t));
    int32_t *member = malloc(sizeof(int32_t) * (nc ? nc : 1));
    int32_t *sub = malloc(sizeof(int32_t) * (nc ? nc : 1));
    if (!start || !member || !sub) {
        free(start);
        free(member);
        free(sub);
        return false;
    }
    for (size_t f = 0; f < c->nt; f++)
        for (int i = 0; i < 3; i++)
            if (c->tri[f].group[i] >= 0)
                start[c->tri[f].group[i] + 1]++;
    for (size_t g = 0; g < c->groups; g++)
        start[g + 1] += start[g];
    size_t *fill = c->groups ? malloc(sizeof(size_t) * c->groups) : NULL;
    if (c->groups && !fill) {
        free(start);
        free(member);
        free(sub);
        return false;
    }
    if (fill)
        memcpy(fill, start, sizeof(size_t) * c->groups);
    for (size_t f = 0; f < c->nt; f++)
        for (int i = 0; i < 3; i++)
            if (c->tri[f].group[i] >= 0)
                member[fill[c->tri[f].group[i]]++] = (int32_t)f;
    free(fill);
    for (size_t f = 0; f < c->nt; f++) {
        const tri_info *t = &c->tri[f];
        for (int i = 0; i < 3 && !(t->flags & TRI_DEGENERATE); i++) {
            int32_t g = t->group[i];
            if (g < 0) { /* a corner no group reached: the reference's initial frame */
                out[3 * f + (size_t)i] = initial_frame(nrm_of(c, 3 * f + (size_t)i));
                continue;
            }
            uint32_t v = (uint32_t)c->group_vertex[g];
            lx_vec3 nrm = nrm_of(c, 3 * f + (size_t)i);
            lx_vec3 os = project(t->os, nrm), ot = project(t->ot, nrm);
            /* the subgroup of f: every member whose projected gradients are
             * not exactly opposite to f's, and every member free to join */
            size_t ns = 0;
            for (size_t k = start[g]; k < start[g + 1]; k++) {
                const tri_info *u = &c->tri[member[k]];
                bool any = ((t->flags | u->flags) & TRI_ANY) != 0;
                lx_vec3 nrm2 = nrm_of(c, 3 * (size_t)member[k] + (size_t)corner_at(
                                                                 c, (size_t)member[k], v));
                bool close = lx_dot(os, project(u->os, nrm2)) > -1.0f &&
                             lx_dot(ot, project(u->ot, nrm2)) > -1.0f;
                if (any || (size_t)member[k] == f || close)
                    sub[ns++] = member[k];
            }
            lx_vec3 tan = eval_frame(c, sub, ns, v);
            if (!(vnz(tan) && isfinite(tan.x) && isfinite(tan.y) && isfinite(tan.z)))
                tan = lx_perpendicular(nrm);
            /* the reference's sign is +1 for a positive UV area with v up;
             * luxel's v grows downward */
            out[3 * f + (size_t)i] = lx_v4(tan.x, tan.y, tan.z, c->group_orient[g] ? -1.0f : 1.0f);
        }
    }
    free(start);
    free(member);
    free(sub);
    return true;
}

/* ---- 6. degenerate triangles ------------------------------------------------ */

static void degenerates(const mctx *c, lx_vec4 *out)
{
    size_t nc = 3 * c->nt;
    /* first good corner of each welded vertex, by corner order */
    uint32_t *first = malloc(sizeof(uint32_t) * (nc ? nc : 1));
    if (first) {
        for (size_t k = 0; k < nc; k++)
            first[k] = UINT32_MAX;
        for (size_t k = nc; k-- > 0;)
            if (!(c->tri[k / 3].flags & TRI_DEGENERATE))
                first[c->weld[k]] = (uint32_t)k;
    }
    for (size_t f = 0; f < c->nt; f++) {
        if (!(c->tri[f].flags & TRI_DEGENERATE))
            continue;
        for (int i = 0; i < 3; i++) {
            size_t k = 3 * f + (size_t)i;
            uint32_t g = first ? first[c->weld[k]] : UINT32_MAX;
            if (g != UINT32_MAX) {
                out[k] = out[g];
            } else {
                out[k] = initial_frame(nrm_of(c, k));
            }
        }
    }
    free(first);
}

lx_status lx_compute_tangents_mikktspace(const lx_mesh *mesh, int uv_set, lx_vec4 *out)
{
    const char *name = mesh && mesh->name ? mesh->name : "?";
    if (!mesh || !out)
        return lx_fail(LX_ERR_INVALID, "lx_compute_tangents_mikktspace: no mesh or no output");
    if (uv_set < 0 || uv_set >= LX_MAX_UV_SETS || !mesh->uv[uv_set])
        return lx_fail(LX_ERR_INVALID, "mesh '%s': no TEXCOORD_%d for tangents", name, uv_set);
    if (!mesh->normals)
        return lx_fail(LX_ERR_INVALID, "mesh '%s': no normals for tangents", name);
    if (mesh->triangle_count > (UINT32_MAX - 3) / 3)
        return lx_fail(LX_ERR_INVALID, "mesh '%s': %u triangles are too many for tangents", name,
                       mesh->triangle_count);
    for (size_t k = 0; k < 3 * (size_t)mesh->triangle_count; k++)
        if (mesh->indices[k] >= mesh->vertex_count)
            return lx_fail(LX_ERR_INVALID, "mesh '%s': index %u out of range (count %u)", name,
                           mesh->indices[k], mesh->vertex_count);
    mctx c = {.m = mesh, .uv = mesh->uv[uv_set], .nt = mesh->triangle_count};
    size_t nc = c.nt > 0 ? 3 * (size_t)c.nt : 1;
    c.weld = malloc(sizeof(uint32_t) * nc);
    c.tri = malloc(sizeof(tri_info) * (c.nt ? c.nt : 1));
    c.group_vertex = malloc(sizeof(int32_t) * nc);
    c.group_orient = malloc(nc);
    c.stack = malloc(sizeof(int32_t) * 2 * nc + sizeof(int32_t));
    lx_status st = LX_OK;
    if (!c.weld || !c.tri || !c.group_vertex || !c.group_orient || !c.stack || !weld(&c)) {
        st = lx_fail(LX_ERR_NOMEM, "mesh '%s': out of memory for tangents", name);
        goto done;
    }
    for (size_t f = 0; f < c.nt; f++)
        init_triangle(&c, f);
    if (!neighbours(&c)) {
        st = lx_fail(LX_ERR_NOMEM, "mesh '%s': out of memory for tangents", name);
        goto done;
    }
    build_groups(&c);
    if (!frames(&c, out)) {
        st = lx_fail(LX_ERR_NOMEM, "mesh '%s': out of memory for tangents", name);
        goto done;
    }
    degenerates(&c, out);
done:
    free(c.weld);
    free(c.tri);
    free(c.group_vertex);
    free(c.group_orient);
    free(c.stack);
    return st;
}
