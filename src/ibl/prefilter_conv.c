/* Direct convolution of an environment with a lobe w(r.l) that depends on
 * the angle between the output direction r and the light direction l
 * alone, shared by the Phong (prefilter_phong.c) and GGX
 * (prefilter_ggx.c) levels of lx_prefilter: the brute-force definition,
 * every source texel a directional light,
 *     out(r) = sum_t L_t Omega_t w(r.l_t) / sum_t Omega_t w(r.l_t),
 * normalised by the lobe's own sum, so a constant environment stays
 * constant. Four things make it fast without changing that definition
 * beyond a stated tolerance:
 *  - the source is the mip level (solid-angle weighted 2x2 means) whose
 *    mean texel angle sqrt(4 pi / 6) / size is at most the lobe's
 *    half-width at half maximum over lobe->texels (the full-size source
 *    when none is that fine);
 *  - each texel of such a mip is a light along the flux centroid of the
 *    source texels it covers (luminance x solid angle weighted), not its
 *    centre, so a small bright light keeps its direction (on a sun 2e4
 *    times the sky this cut the Phong error against the full-resolution
 *    convolution from 7% to 0.8% on average);
 *  - the mip's texels are grouped into a tree of nodes (4x4 texels, then
 *    2x2 nodes of the tier below, up to at most 4x4 nodes along a face),
 *    each with a bounding cone; a texel visits only the nodes whose cone
 *    reaches its lobe's cut-off cone r.l >= lobe->cos_cut (the top tier
 *    tested once per 16x16 output tile, then down the tree per texel).
 *    Phong's lights past the cut-off are left out one by one; GGX's cut-off
 *    is a tiny fraction of the peak and is applied to whole nodes;
 *  - for lobes with long tails (GGX falls as the inverse fourth power of
 *    the angle, so a sun lights the whole hemisphere through it), a node
 *    whose nearest point is at least lobe->far times its angular radius
 *    away from r counts as one light: its flux centroid, its summed solid
 *    angle and its solid-angle weighted mean value, the opening-angle
 *    criterion of J. Barnes and P. Hut, "A hierarchical O(N log N)
 *    force-calculation algorithm", Nature 324 (1986). The lights still
 *    partition the sphere for every r; the error is the lobe's curvature
 *    across a far node, second order in radius / distance (the centroid
 *    takes the first order), and a texel costs a few hundred nodes and
 *    lights per tier of the tree, whatever the lobe's width and tail
 *    (1000-1600 on a 256^2 source's sharpest GGX levels, against ~50000
 *    texels in their hemisphere).
 * Each texel's sums run over the tree in one fixed order, in double. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>

#define CONV_LEAF 4       /* a node of tier 1 is 4x4 texels... */
#define CONV_BLOCK 2      /* ...one of a tier above is 2x2 nodes of the tier below */
#define CONV_TOP 4        /* the top tier has at most this many nodes along a face */
#define CONV_MAX_TIERS 16 /* 4 x 2^15 > LX_MAX_CUBE_SIZE */
#define PI_D 3.14159265358979323846

typedef struct conv_light {
    float x, y, z, omega, r, g, b;
} conv_light;

/* Nodes of one tier of the tree. */
typedef struct conv_tier {
    int count;
    float *ax, *ay, *az; /* bounding cone axis */
    float *cos_cull;     /* r.axis below it: every light of the node is past the cut-off */
    float *cos_far;      /* r.axis at most it: the node is one light */
    float *cos_tile;     /* tile axis.axis below it: past the cut-off for the whole tile */
    int *first;          /* children [first[i], first[i + 1]) in the tier below */
    conv_light *light;   /* the node as one light */
} conv_tier;

struct lx_conv_plan {
    lx_lobe lobe;
    const lx_cubemap *src;
    int level;                                /* of the chain */
    int tiers;                                /* node tiers 1..tiers; the lights are tier 0 */
    float *lx, *ly, *lz, *lom, *lr, *lg, *lb; /* the lights (structure of arrays) */
    conv_tier tier[CONV_MAX_TIERS + 1];
    double cost;
};

/* Largest angle between unit axis and the directions through the corners of
 * face rectangle [s0,s1] x [t0,t1] (face coordinates in [-1, 1]): the
 * rectangle's projection is a convex spherical quadrilateral, so its
 * farthest point from any direction is a corner. */
static double cone_radius(int face, lx_vec3 axis, double s0, double t0, double s1, double t1)
{
    double lowest = 1.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            lx_vec3 c =
                lx_normalize(lx_ibl_face_vector(face, (float)(i ? s1 : s0), (float)(j ? t1 : t0)));
            double d = lx_dot(axis, c);
            lowest = d < lowest ? d : lowest;
        }
    return acos(lowest < -1.0 ? -1.0 : lowest) + 1e-5; /* float slack */
}

static lx_vec3 rect_axis(int face, double s0, double t0, double s1, double t1)
{
    return lx_normalize(
        lx_ibl_face_vector(face, (float)(0.5 * (s0 + s1)), (float)(0.5 * (t0 + t1))));
}

static float cos_of(double angle)
{
    return (float)cos(angle < PI_D ? angle : PI_D);
}

/* For each texel of the mip `coarse` of `src`: the sum of luminance x
 * solid angle x direction over the source texels under it (its flux
 * vector; the centroid is its direction). malloc'd, NULL when out of
 * memory. */
static double *flux_vectors(const lx_cubemap *src, const lx_cubemap *coarse)
{
    int n0 = src->size, n = coarse->size;
    double *sum = calloc((size_t)6 * n * n * 3, sizeof(double));
    double *omega = lx_ibl_solid_angles(n0);
    if (!sum || !omega) {
        free(sum);
        free(omega);
        return NULL;
    }
    for (int face = 0; face < 6; face++)
        for (int y = 0; y < n0; y++)
            for (int x = 0; x < n0; x++) {
                const float *c = lx_cubemap_texel(src, face, x, y);
                double lum = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                if (!(lum > 0.0))
                    continue;
                double w = lum * lx_ibl_omega(omega, n0, x, y);
                lx_vec3 d = lx_cube_direction(face, (x + 0.5f) / n0, (y + 0.5f) / n0);
                int X = (int)((long)x * n / n0), Y = (int)((long)y * n / n0);
                double *q = sum + 3 * (((size_t)face * n + Y) * n + X);
                q[0] += w * d.x, q[1] += w * d.y, q[2] += w * d.z;
            }
    free(omega);
    return sum;
}

static void tier_free(conv_tier *t)
{
    free(t->ax);
    free(t->first);
    free(t->light);
}

void lx_conv_plan_free(lx_conv_plan *p)
{
    if (!p)
        return;
    free(p->lx);
    for (int t = 1; t <= p->tiers; t++)
        tier_free(&p->tier[t]);
    free(p);
}

static bool tier_alloc(conv_tier *t, int count)
{
    t->count = count;
    t->ax = malloc(sizeof(float) * 6 * (size_t)count);
    t->first = malloc(sizeof(int) * ((size_t)count + 1));
    t->light = malloc(sizeof(conv_light) * (size_t)count);
    if (!t->ax || !t->first || !t->light)
        return false;
    t->ay = t->ax + count, t->az = t->ay + count;
    t->cos_cull = t->az + count, t->cos_far = t->cos_cull + count;
    t->cos_tile = t->cos_far + count;
    return true;
}

/* A node's face rectangle in texels of the plan's mip. */
typedef struct conv_rect {
    int face, x0, y0, x1, y1;
} conv_rect;

/* ---- per texel ---------------------------------------------------------- */

typedef struct conv_sum {
    double num[3], den;
} conv_sum;

static inline void add_light(const conv_light *t, double w, conv_sum *s)
{
    s->num[0] += w * t->r;
    s->num[1] += w * t->g;
    s->num[2] += w * t->b;
    s->den += w;
}

/* The lobe at cosine d, unnormalised: Phong's pow(d, n), 0 past the
 * cut-off; GGX's D(h) (n.l) with n.h^2 = (1 + d) / 2 up to the constant
 * alpha^2 / pi, 0 past the horizon, 1 + n.h^2 (alpha^2 - 1) written
 * without the cancellation near d = 1 (the same arithmetic as
 * visit_lights). */
static inline float lobe_value(const lx_lobe *l, float d)
{
    if (l->kind == LX_LOBE_PHONG)
        return d < l->cos_cut ? 0.0f : exp2f(l->param * log2f(d));
    float q = 0.5f * (1.0f - d) + 0.5f * (1.0f + d) * l->param;
    return 0.5f * (d + fabsf(d)) / (q * q);
}

/* Lights [k0, k1) of the mip (one node of tier 1), summed in order. */
static inline void visit_lights(const lx_conv_plan *p, int k0, int k1, lx_vec3 r, conv_sum *s)
{
    const float cut = p->lobe.cos_cut, a = p->lobe.param;
    const float *restrict x = p->lx + k0, *restrict y = p->ly + k0, *restrict z = p->lz + k0;
    const float *restrict om = p->lom + k0;
    const float *lr = p->lr + k0, *lg = p->lg + k0, *lb = p->lb + k0;
    double n0 = 0.0, n1 = 0.0, n2 = 0.0, den = 0.0;
    int n = k1 - k0;
    if (p->lobe.kind == LX_LOBE_PHONG) {
        /* most lights of a narrow lobe's nodes are past the cut-off */
        for (int k = 0; k < n; k++) {
            float d = r.x * x[k] + r.y * y[k] + r.z * z[k];
            if (d < cut)
                continue;
            double v = (double)(exp2f(a * log2f(d)) * om[k]);
            n0 += v * lr[k];
            n1 += v * lg[k];
            n2 += v * lb[k];
            den += v;
        }
    } else {
        /* the weights first, without comparisons (which may trap on NaN,
         * so the compiler would not vectorise them): d + |d| = 2 max(d, 0)
         * exactly. The cut-off is left to the nodes: a node entirely past
         * it is skipped, every light of a visited one counts. */
        float w[CONV_LEAF * CONV_LEAF];
        for (int k = 0; k < n; k++) {
            float d = r.x * x[k] + r.y * y[k] + r.z * z[k];
            float q = 0.5f * (1.0f - d) + 0.5f * (1.0f + d) * a; /* >= a > 0 */
            w[k] = 0.5f * (d + fabsf(d)) / (q * q) * om[k];
        }
        for (int k = 0; k < n; k++) {
            double v = w[k];
            n0 += v * lr[k];
            n1 += v * lg[k];
            n2 += v * lb[k];
            den += v;
        }
    }
    s->num[0] += n0;
    s->num[1] += n1;
    s->num[2] += n2;
    s->den += den;
}

/* A depth-first walk down the tree from top nodes [first, end): level sp
 * of the stack walks tier p->tiers - sp; the sums of a walk stay in
 * registers where a recursion would keep them in memory. */
typedef struct conv_walk {
    int sp, cur[CONV_MAX_TIERS + 1], end[CONV_MAX_TIERS + 1];
} conv_walk;

static inline void walk_start(conv_walk *w, int first, int end)
{
    w->sp = 0, w->cur[0] = first, w->end[0] = end;
}

/* The next node (tier *t, index *i) in tree order; false at the end. */
static inline bool walk_next(const lx_conv_plan *p, conv_walk *w, int *t, int *i)
{
    while (w->sp >= 0 && w->cur[w->sp] == w->end[w->sp])
        w->sp--;
    if (w->sp < 0)
        return false;
    *t = p->tiers - w->sp;
    *i = w->cur[w->sp]++;
    return true;
}

/* Walks node i of tier T's children next. */
static inline void walk_down(conv_walk *w, const conv_tier *T, int i)
{
    w->sp++;
    w->cur[w->sp] = T->first[i], w->end[w->sp] = T->first[i + 1];
}

/* The sums at r over the tree below the top nodes cand[0..nc), in tree
 * order (the same for every run). */
static void convolve(const lx_conv_plan *p, const int *cand, int nc, lx_vec3 r, conv_sum *out)
{
    conv_sum s = {{0, 0, 0}, 0.0};
    conv_walk w;
    for (int c = 0; c < nc; c++) {
        walk_start(&w, cand[c], cand[c] + 1);
        int tier, i;
        while (walk_next(p, &w, &tier, &i)) {
            const conv_tier *T = &p->tier[tier];
            float d = r.x * T->ax[i] + r.y * T->ay[i] + r.z * T->az[i];
            if (d < T->cos_cull[i])
                continue;
            if (d <= T->cos_far[i]) {
                const conv_light *t = &T->light[i];
                float e = r.x * t->x + r.y * t->y + r.z * t->z;
                add_light(t, (double)(lobe_value(&p->lobe, e) * t->omega), &s);
            } else if (tier == 1) {
                visit_lights(p, T->first[i], T->first[i + 1], r, &s);
            } else {
                walk_down(&w, T, i);
            }
        }
    }
    *out = s;
}

/* convolve without the sums: how many nodes and lights a texel at r
 * tests, from every top node. */
static long count_visits(const lx_conv_plan *p, lx_vec3 r)
{
    long n = 0;
    conv_walk w;
    walk_start(&w, 0, p->tier[p->tiers].count);
    int tier, i;
    while (walk_next(p, &w, &tier, &i)) {
        const conv_tier *T = &p->tier[tier];
        float d = r.x * T->ax[i] + r.y * T->ay[i] + r.z * T->az[i];
        n++;
        if (d < T->cos_cull[i] || d <= T->cos_far[i])
            continue;
        if (tier == 1)
            n += T->first[i + 1] - T->first[i];
        else
            walk_down(&w, T, i);
    }
    return n;
}

/* ---- the plan ------------------------------------------------------------ */

/* The side of a node of tier t, in texels. */
static long tier_span(int t)
{
    long span = t > 0 ? CONV_LEAF : 1;
    for (int k = 2; k <= t; k++)
        span *= CONV_BLOCK;
    return span;
}

/* The tree over the n x n texels of each face: tier 1 of 4x4 texels, each
 * tier above of 2x2 nodes of the one below, up to the first with at most
 * CONV_TOP nodes along a face; rects[t] gets the rectangles of tier t's
 * nodes. Children are stored contiguously, in the order of their parents;
 * a tier 1 node's lights are its texels, row by row. Returns false when out
 * of memory. */
static bool build_tree(lx_conv_plan *p, int n, conv_rect **rects)
{
    int tiers = 1;
    while ((n + tier_span(tiers) - 1) / tier_span(tiers) > CONV_TOP && tiers < CONV_MAX_TIERS)
        tiers++;
    p->tiers = tiers;
    for (int t = 1; t <= tiers; t++) {
        long nb = (n + tier_span(t) - 1) / tier_span(t);
        if (!tier_alloc(&p->tier[t], (int)(6 * nb * nb)) ||
            !(rects[t] = malloc(sizeof(conv_rect) * 6 * (size_t)nb * (size_t)nb)))
            return false;
    }
    /* the top tier: faces, rows, columns */
    long top = tier_span(tiers);
    int k = 0;
    for (int face = 0; face < 6; face++)
        for (long y = 0; y < n; y += top)
            for (long x = 0; x < n; x += top)
                rects[tiers][k++] =
                    (conv_rect){face, (int)x, (int)y, (int)(x + top < n ? x + top : n),
                                (int)(y + top < n ? y + top : n)};
    /* each tier below: the children of the one above, in its order */
    for (int t = tiers; t >= 1; t--) {
        long sp = tier_span(t - 1);
        conv_tier *T = &p->tier[t];
        int m = 0;
        for (int i = 0; i < T->count; i++) {
            const conv_rect *R = &rects[t][i];
            T->first[i] = m;
            if (t == 1) {
                m += (R->x1 - R->x0) * (R->y1 - R->y0);
                continue;
            }
            for (long y = R->y0; y < R->y1; y += sp)
                for (long x = R->x0; x < R->x1; x += sp)
                    rects[t - 1][m++] =
                        (conv_rect){R->face, (int)x, (int)y, (int)(x + sp < R->x1 ? x + sp : R->x1),
                                    (int)(y + sp < R->y1 ? y + sp : R->y1)};
        }
        T->first[T->count] = m;
    }
    return true;
}

/* The widest cone around an output tile's axis holding the tile. */
static double widest_tile(int out_size)
{
    if (out_size <= 0)
        return PI_D;
    double widest = 0.0;
    int ts = (out_size + LX_IBL_TILE - 1) / LX_IBL_TILE;
    for (int ty = 0; ty < ts; ty++)
        for (int tx = 0; tx < ts; tx++) {
            int x0 = tx * LX_IBL_TILE, y0 = ty * LX_IBL_TILE;
            int x1 = x0 + LX_IBL_TILE < out_size ? x0 + LX_IBL_TILE : out_size;
            int y1 = y0 + LX_IBL_TILE < out_size ? y0 + LX_IBL_TILE : out_size;
            double s0 = 2.0 * x0 / out_size - 1, s1 = 2.0 * x1 / out_size - 1;
            double t0 = 2.0 * y0 / out_size - 1, t1 = 2.0 * y1 / out_size - 1;
            double r = cone_radius(0, rect_axis(0, s0, t0, s1, t1), s0, t0, s1, t1);
            widest = r > widest ? r : widest;
        }
    return widest;
}

static int source_level(const lx_ibl_chain *chain, const lx_lobe *lobe)
{
    /* the coarsest level whose mean texel angle sqrt(4 pi / 6) / size is at
     * most half_width / texels */
    double need = lobe->texels * 1.4472025091165353 / lobe->half_width;
    int level = 0;
    while (level + 1 < chain->count && chain->level[level + 1].size >= need)
        level++;
    return level;
}

static void free_rects(conv_rect **rects)
{
    for (int t = 0; t <= CONV_MAX_TIERS; t++) {
        free(rects[t]);
        rects[t] = NULL;
    }
}

/* The lights (tier 0) and the nodes as single lights, from the source mip
 * s (level `level` of chain). Returns false when out of memory. */
static bool build_lights(lx_conv_plan *p, const lx_ibl_chain *chain, conv_rect **rects)
{
    const lx_cubemap *s = p->src;
    int n = s->size;
    size_t lights = (size_t)6 * n * n;
    double *omega = lx_ibl_solid_angles(n);
    double *flux = p->level > 0 ? flux_vectors(&chain->level[0], s) : NULL;
    /* per node of the tier being built: flux vector, solid angle, solid
     * angle x value */
    double *acc = malloc(sizeof(double) * 7 * (size_t)p->tier[1].count);
    if ((p->lx = malloc(sizeof(float) * 7 * lights))) {
        p->ly = p->lx + lights, p->lz = p->ly + lights, p->lom = p->lz + lights;
        p->lr = p->lom + lights, p->lg = p->lr + lights, p->lb = p->lg + lights;
    }
    if (!omega || (!flux && p->level > 0) || !acc || !p->lx) {
        free(omega);
        free(flux);
        free(acc);
        return false;
    }
    /* the lights, each tier 1 node's texels row by row, and their sums */
    conv_tier *T1 = &p->tier[1];
    for (int i = 0; i < T1->count; i++) {
        const conv_rect *R = &rects[1][i];
        double *a = acc + 7 * (size_t)i;
        for (int j = 0; j < 7; j++)
            a[j] = 0.0;
        int k = T1->first[i], face = R->face;
        for (int y = R->y0; y < R->y1; y++)
            for (int x = R->x0; x < R->x1; x++, k++) {
                lx_vec3 d = lx_cube_direction(face, (x + 0.5f) / n, (y + 0.5f) / n);
                double om = lx_ibl_omega(omega, n, x, y);
                const float *c = lx_cubemap_texel(s, face, x, y);
                if (flux) {
                    const double *q = flux + 3 * (((size_t)face * n + y) * n + x);
                    double len = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
                    if (len > 0.0)
                        d = lx_v3((float)(q[0] / len), (float)(q[1] / len), (float)(q[2] / len));
                    a[0] += q[0], a[1] += q[1], a[2] += q[2];
                } else {
                    double lum = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                    double w = lum > 0.0 ? lum * om : 0.0;
                    a[0] += w * d.x, a[1] += w * d.y, a[2] += w * d.z;
                }
                a[3] += om, a[4] += om * c[0], a[5] += om * c[1], a[6] += om * c[2];
                p->lx[k] = d.x, p->ly[k] = d.y, p->lz[k] = d.z, p->lom[k] = (float)om;
                p->lr[k] = c[0], p->lg[k] = c[1], p->lb[k] = c[2];
            }
    }
    free(flux);
    free(omega);
    /* the nodes, tier by tier from the bottom: tier 1 from its lights, each
     * tier above from its children. A node's sums overwrite the slot of
     * its index in acc: every node has a child, so node i's children start
     * at or after i and the slots below i are no one's children any more. */
    for (int t = 1; t <= p->tiers; t++) {
        conv_tier *T = &p->tier[t];
        for (int i = 0; i < T->count; i++) {
            double sum[7];
            if (t == 1) {
                for (int j = 0; j < 7; j++)
                    sum[j] = acc[7 * (size_t)i + j];
            } else {
                for (int j = 0; j < 7; j++)
                    sum[j] = 0.0;
                for (int c = T->first[i]; c < T->first[i + 1]; c++)
                    for (int j = 0; j < 7; j++)
                        sum[j] += acc[7 * (size_t)c + j];
                for (int j = 0; j < 7; j++)
                    acc[7 * (size_t)i + j] = sum[j];
            }
            double len = sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
            lx_vec3 d = len > 0.0 ? lx_v3((float)(sum[0] / len), (float)(sum[1] / len),
                                          (float)(sum[2] / len))
                                  : lx_v3(T->ax[i], T->ay[i], T->az[i]);
            T->light[i] = (conv_light){d.x,
                                       d.y,
                                       d.z,
                                       (float)sum[3],
                                       (float)(sum[4] / sum[3]),
                                       (float)(sum[5] / sum[3]),
                                       (float)(sum[6] / sum[3])};
        }
    }
    free(acc);
    return true;
}

lx_status lx_conv_plan_build(const lx_ibl_chain *chain, const lx_lobe *lobe, int out_size,
                             double max_cost, lx_conv_plan **out)
{
    *out = NULL;
    lx_conv_plan *p = calloc(1, sizeof *p);
    if (!p)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    p->lobe = *lobe;
    p->level = source_level(chain, lobe);
    p->src = &chain->level[p->level];
    int n = p->src->size;
    conv_rect *rects[CONV_MAX_TIERS + 1] = {0};
    if (!build_tree(p, n, rects)) {
        free_rects(rects);
        lx_conv_plan_free(p);
        return lx_fail(LX_ERR_NOMEM, "out of memory for a convolution of a %d x %d source", n, n);
    }

    /* the nodes' cones and tests */
    double theta_cut = acos(lobe->cos_cut < -1.0f ? -1.0 : (double)lobe->cos_cut);
    double tile_rad = widest_tile(out_size);
    for (int t = 1; t <= p->tiers; t++) {
        conv_tier *T = &p->tier[t];
        for (int i = 0; i < T->count; i++) {
            const conv_rect *R = &rects[t][i];
            double s0 = 2.0 * R->x0 / n - 1, s1 = 2.0 * R->x1 / n - 1;
            double t0 = 2.0 * R->y0 / n - 1, t1 = 2.0 * R->y1 / n - 1;
            lx_vec3 axis = rect_axis(R->face, s0, t0, s1, t1);
            double rad = cone_radius(R->face, axis, s0, t0, s1, t1);
            T->ax[i] = axis.x, T->ay[i] = axis.y, T->az[i] = axis.z;
            T->cos_cull[i] = cos_of(rad + theta_cut);
            T->cos_far[i] = lobe->far > 0.0 ? cos_of(rad * (1.0 + lobe->far)) : -2.0f;
            T->cos_tile[i] = cos_of(rad + theta_cut + tile_rad);
        }
    }

    /* the cost: nodes and lights a texel tests, over probe directions
     * spread over a face (the six are alike); over budget, no plan */
    long visits = 0;
    int probes = 0;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++, probes++)
            visits +=
                count_visits(p, lx_cube_direction(LX_FACE_PZ, (i + 0.37f) / 4, (j + 0.61f) / 4));
    p->cost = (double)visits / probes;
    if (p->cost > max_cost) {
        free_rects(rects);
        lx_conv_plan_free(p);
        return LX_OK;
    }

    bool ok = build_lights(p, chain, rects);
    free_rects(rects);
    if (!ok) {
        lx_conv_plan_free(p);
        return lx_fail(LX_ERR_NOMEM, "out of memory for a convolution of a %d x %d source", n, n);
    }
    *out = p;
    return LX_OK;
}

double lx_conv_plan_cost(const lx_conv_plan *p)
{
    return p->cost;
}

/* The nodes of tier `tier` (1 or the top) that reach the cut-off cone of
 * some texel of the output tile around axis, in tree order; returns their
 * count. */
static int tile_nodes(const lx_conv_plan *p, int tier, lx_vec3 axis, int *out)
{
    int n = 0, t, i;
    conv_walk w;
    walk_start(&w, 0, p->tier[p->tiers].count);
    while (walk_next(p, &w, &t, &i)) {
        const conv_tier *T = &p->tier[t];
        if (axis.x * T->ax[i] + axis.y * T->ay[i] + axis.z * T->az[i] < T->cos_tile[i])
            continue;
        if (t == tier)
            out[n++] = i;
        else
            walk_down(&w, T, i);
    }
    return n;
}

bool lx_conv_tile(const lx_conv_plan *p, lx_cubemap *out, int face, int x0, int y0, int x1, int y1)
{
    int m = out->size;
    /* without a far field every light is weighed alone: the tile's list of
     * leaves, each tested per texel (as a walk down the tree would, in the
     * same order, without the walk); with one, each texel walks the tree
     * from the top nodes the tile reaches */
    bool flat = !(p->lobe.far > 0.0);
    int tier = flat ? 1 : p->tiers;
    int *cand = malloc(sizeof(int) * (size_t)p->tier[tier].count);
    if (!cand)
        return false;
    double s0 = 2.0 * x0 / m - 1, s1 = 2.0 * x1 / m - 1;
    double t0 = 2.0 * y0 / m - 1, t1 = 2.0 * y1 / m - 1;
    int nc = tile_nodes(p, tier, rect_axis(face, s0, t0, s1, t1), cand);
    const conv_tier *T = &p->tier[tier];
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            lx_vec3 r = lx_cube_direction(face, (x + 0.5f) / m, (y + 0.5f) / m);
            conv_sum s = {{0, 0, 0}, 0.0};
            if (flat) {
                for (int c = 0; c < nc; c++) {
                    int b = cand[c];
                    if (r.x * T->ax[b] + r.y * T->ay[b] + r.z * T->az[b] >= T->cos_cull[b])
                        visit_lights(p, T->first[b], T->first[b + 1], r, &s);
                }
            } else {
                convolve(p, cand, nc, r, &s);
            }
            float *o = lx_cubemap_texel(out, face, x, y);
            if (s.den > 0.0) {
                for (int k = 0; k < 3; k++)
                    o[k] = (float)(s.num[k] / s.den);
            } else {
                /* a lobe narrower than the source's texels */
                lx_ibl_sample(p->src, r, o);
            }
        }
    free(cand);
    return true;
}
