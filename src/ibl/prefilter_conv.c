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
 *    each with a bounding cone; only the nodes whose cone reaches the
 *    lobe's cut-off cone r.l >= lobe->cos_cut are visited. Phong's lights
 *    past the cut-off are left out one by one; GGX's cut-off is a tiny
 *    fraction of the peak and is applied to whole nodes;
 *  - for lobes with long tails (GGX falls as the inverse fourth power of
 *    the angle, so a sun lights the whole hemisphere through it), a node
 *    whose nearest point is at least lobe->far times its angular radius
 *    away from r counts as one light: its flux centroid, its summed solid
 *    angle and its solid-angle weighted mean value, the opening-angle
 *    criterion of J. Barnes and P. Hut, "A hierarchical O(N log N)
 *    force-calculation algorithm", Nature 324 (1986). The lights still
 *    partition the sphere for every r; the error is the lobe's curvature
 *    across a far node, second order in radius / distance (the centroid
 *    takes the first order).
 * The walk down the tree is made once per group of 4x4 output texels with
 * the criteria widened by the group's angular radius, so every texel of
 * the group sees a partition at least as fine as its own walk would give;
 * the group's lights (far nodes and the texels of the opened leaves) are
 * copied into one flat list, and each texel sums over that list without
 * tests or branches, eight lanes at a time (about 2 ns a light where the
 * walk per texel took 5-10 ns a node). Lanes sum in float over chunks of
 * 64 lights, chunks in double, in one fixed order: the same result for
 * any thread count. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CONV_LEAF 4       /* a node of tier 1 is 4x4 texels... */
#define CONV_BLOCK 2      /* ...one of a tier above is 2x2 nodes of the tier below */
#define CONV_TOP 4        /* the top tier has at most this many nodes along a face */
#define CONV_MAX_TIERS 16 /* 4 x 2^15 > LX_MAX_CUBE_SIZE */
#define CONV_GROUP 4      /* output texels share a walk in groups of 4x4 */
#define CONV_LANES 8      /* a texel's sums run in 4 lanes... */
#define CONV_CHUNK 64     /* ...in float over 64 lights, then in double */
#define PI_D 3.14159265358979323846

typedef struct conv_light {
    float x, y, z, omega, r, g, b;
} conv_light;

/* A node's face rectangle in texels of the plan's mip. */
typedef struct conv_rect {
    int face, x0, y0, x1, y1;
} conv_rect;

/* Nodes of one tier of the tree. */
typedef struct conv_tier {
    int count;
    float *ax, *ay, *az; /* bounding cone axis */
    float *cos_cull;     /* group axis.axis below it: every light is past the cut-off */
    float *cos_far;      /* group axis.axis at most it: the node is one light for the group */
    int *first;          /* children [first[i], first[i + 1]) in the tier below */
    conv_light *light;   /* the node as one light (filled by lx_conv_plan_fill) */
    conv_rect *rect;     /* kept until the plan is filled */
} conv_tier;

struct lx_conv_plan {
    lx_lobe lobe;
    int level, n;                             /* the chain level it reads and its face size */
    const lx_cubemap *src;                    /* that level, once filled */
    int tiers;                                /* node tiers 1..tiers; the lights are tier 0 */
    float *lx, *ly, *lz, *lom, *lr, *lg, *lb; /* the lights (structure of arrays) */
    conv_tier tier[CONV_MAX_TIERS + 1];
    double cost;     /* list entries a texel sums */
    size_t most;     /* the longest group list met while measuring */
    size_t lights;   /* 6 n^2 */
    double group_ra; /* the widest group's angular radius */
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

/* The group of output texels [x0, x1) x [y0, y1) of a size m face: its
 * axis and angular radius. */
static lx_vec3 group_cone(int face, int m, int x0, int y0, int x1, int y1, double *radius)
{
    double s0 = 2.0 * x0 / m - 1, s1 = 2.0 * x1 / m - 1;
    double t0 = 2.0 * y0 / m - 1, t1 = 2.0 * y1 / m - 1;
    lx_vec3 axis = rect_axis(face, s0, t0, s1, t1);
    if (radius)
        *radius = cone_radius(face, axis, s0, t0, s1, t1);
    return axis;
}

/* The widest cone around a group of a size m face (the six are alike). */
static double widest_group(int m)
{
    double widest = 0.0;
    for (int y0 = 0; y0 < m; y0 += CONV_GROUP)
        for (int x0 = 0; x0 < m; x0 += CONV_GROUP) {
            double r;
            group_cone(LX_FACE_PZ, m, x0, y0, x0 + CONV_GROUP < m ? x0 + CONV_GROUP : m,
                       y0 + CONV_GROUP < m ? y0 + CONV_GROUP : m, &r);
            widest = r > widest ? r : widest;
        }
    return widest;
}

/* ---- the tree --------------------------------------------------------------- */

static void tier_free(conv_tier *t)
{
    free(t->ax);
    free(t->first);
    free(t->light);
    free(t->rect);
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
    t->ax = malloc(sizeof(float) * 5 * (size_t)count);
    t->first = malloc(sizeof(int) * ((size_t)count + 1));
    t->light = malloc(sizeof(conv_light) * (size_t)count);
    t->rect = malloc(sizeof(conv_rect) * (size_t)count);
    if (!t->ax || !t->first || !t->light || !t->rect)
        return false;
    t->ay = t->ax + count, t->az = t->ay + count;
    t->cos_cull = t->az + count, t->cos_far = t->cos_cull + count;
    return true;
}

/* The side of a node of tier t, in texels. */
static long tier_span(int t)
{
    long span = t > 0 ? CONV_LEAF : 1;
    for (int k = 2; k <= t; k++)
        span *= CONV_BLOCK;
    return span;
}

/* Tiers a tree over n x n texels a face has. */
static int tier_count(int n)
{
    int tiers = 1;
    while ((n + tier_span(tiers) - 1) / tier_span(tiers) > CONV_TOP && tiers < CONV_MAX_TIERS)
        tiers++;
    return tiers;
}

/* Bytes of the tree over n x n texels a face. */
static uint64_t tree_bytes(int n)
{
    uint64_t bytes = 0;
    for (int t = 1; t <= tier_count(n); t++) {
        uint64_t nb = (uint64_t)((n + tier_span(t) - 1) / tier_span(t));
        bytes += 6 * nb * nb *
                 (5 * sizeof(float) + sizeof(int) + sizeof(conv_light) + sizeof(conv_rect));
    }
    return bytes;
}

/* The tree over the n x n texels of each face: tier 1 of 4x4 texels, each
 * tier above of 2x2 nodes of the one below, up to the first with at most
 * CONV_TOP nodes along a face. Children are stored contiguously, in the
 * order of their parents; a tier 1 node's lights are its texels, row by
 * row. Returns false when out of memory. */
static bool build_tree(lx_conv_plan *p, int n)
{
    int tiers = tier_count(n);
    p->tiers = tiers;
    for (int t = 1; t <= tiers; t++) {
        long nb = (n + tier_span(t) - 1) / tier_span(t);
        if (!tier_alloc(&p->tier[t], (int)(6 * nb * nb)))
            return false;
    }
    /* the top tier: faces, rows, columns */
    long top = tier_span(tiers);
    int k = 0;
    for (int face = 0; face < 6; face++)
        for (long y = 0; y < n; y += top)
            for (long x = 0; x < n; x += top)
                p->tier[tiers].rect[k++] =
                    (conv_rect){face, (int)x, (int)y, (int)(x + top < n ? x + top : n),
                                (int)(y + top < n ? y + top : n)};
    /* each tier below: the children of the one above, in its order */
    for (int t = tiers; t >= 1; t--) {
        long sp = tier_span(t - 1);
        conv_tier *T = &p->tier[t];
        int m = 0;
        for (int i = 0; i < T->count; i++) {
            const conv_rect *R = &T->rect[i];
            T->first[i] = m;
            if (t == 1) {
                m += (R->x1 - R->x0) * (R->y1 - R->y0);
                continue;
            }
            for (long y = R->y0; y < R->y1; y += sp)
                for (long x = R->x0; x < R->x1; x += sp)
                    p->tier[t - 1].rect[m++] =
                        (conv_rect){R->face, (int)x, (int)y, (int)(x + sp < R->x1 ? x + sp : R->x1),
                                    (int)(y + sp < R->y1 ? y + sp : R->y1)};
        }
        T->first[T->count] = m;
    }
    return true;
}

/* ---- a group's list ----------------------------------------------------------- */

/* The lights one group of output texels sums: structure of arrays, padded
 * with lights of no weight to a whole number of chunks. */
typedef struct conv_list {
    size_t count, capacity;
    float *x, *y, *z, *om, *r, *g, *b;
} conv_list;

static void list_free(conv_list *l)
{
    free(l->x);
    memset(l, 0, sizeof *l);
}

static bool list_reserve(conv_list *l, size_t more)
{
    if (l->count + more <= l->capacity)
        return true;
    size_t cap = l->capacity ? l->capacity : 1024;
    while (cap < l->count + more)
        cap *= 2;
    float *x = malloc(sizeof(float) * 7 * cap);
    if (!x)
        return false;
    float *old[7] = {l->x, l->y, l->z, l->om, l->r, l->g, l->b};
    float **mine[7] = {&l->x, &l->y, &l->z, &l->om, &l->r, &l->g, &l->b};
    for (int k = 0; k < 7; k++) {
        if (l->count)
            memcpy(x + k * cap, old[k], sizeof(float) * l->count);
        *mine[k] = x + k * cap;
    }
    free(old[0]);
    l->capacity = cap;
    return true;
}

static void list_put(conv_list *l, const conv_light *t)
{
    size_t i = l->count++;
    l->x[i] = t->x, l->y[i] = t->y, l->z[i] = t->z, l->om[i] = t->omega;
    l->r[i] = t->r, l->g[i] = t->g, l->b[i] = t->b;
}

/* The walk for a group around axis a: visits the nodes whose cone reaches
 * the group's cut-off cone; a node far from every texel of the group is
 * one light (put, when not NULL, gets it), an opened leaf its texels.
 * Returns the list length; false in *ok when out of memory. */
static size_t group_walk(const lx_conv_plan *p, lx_vec3 a, conv_list *put, bool *ok)
{
    size_t count = 0;
    int sp = 0, cur[CONV_MAX_TIERS + 1], end[CONV_MAX_TIERS + 1];
    cur[0] = 0, end[0] = p->tier[p->tiers].count;
    while (sp >= 0) {
        if (cur[sp] == end[sp]) {
            sp--;
            continue;
        }
        int tier = p->tiers - sp, i = cur[sp]++;
        const conv_tier *T = &p->tier[tier];
        float d = a.x * T->ax[i] + a.y * T->ay[i] + a.z * T->az[i];
        if (d < T->cos_cull[i])
            continue;
        if (d <= T->cos_far[i]) {
            if (put) {
                if (!list_reserve(put, 1)) {
                    *ok = false;
                    return count;
                }
                list_put(put, &T->light[i]);
            }
            count++;
        } else if (tier == 1) {
            int k0 = T->first[i], k1 = T->first[i + 1];
            if (put) {
                if (!list_reserve(put, (size_t)(k1 - k0))) {
                    *ok = false;
                    return count;
                }
                size_t at = put->count;
                size_t len = (size_t)(k1 - k0) * sizeof(float);
                memcpy(put->x + at, p->lx + k0, len), memcpy(put->y + at, p->ly + k0, len);
                memcpy(put->z + at, p->lz + k0, len), memcpy(put->om + at, p->lom + k0, len);
                memcpy(put->r + at, p->lr + k0, len), memcpy(put->g + at, p->lg + k0, len);
                memcpy(put->b + at, p->lb + k0, len);
                put->count += (size_t)(k1 - k0);
            }
            count += (size_t)(k1 - k0);
        } else {
            sp++;
            cur[sp] = T->first[i], end[sp] = T->first[i + 1];
        }
    }
    return count;
}

/* ---- per texel ------------------------------------------------------------------- */

/* The sums at r over a GGX list: D(h) (n.l) with n.h^2 = (1 + d) / 2 up to
 * the constant alpha^2 / pi, 0 past the horizon (d + |d| = 2 max(d, 0)
 * exactly), 1 + n.h^2 (alpha^2 - 1) written without the cancellation near
 * d = 1. */
static void sum_ggx(const conv_list *l, float a, lx_vec3 r, double out[4])
{
    double tot[4] = {0, 0, 0, 0};
    for (size_t k0 = 0; k0 < l->count; k0 += CONV_CHUNK) {
        size_t k1 = k0 + CONV_CHUNK < l->count ? k0 + CONV_CHUNK : l->count;
        /* two sets of four lanes: r, g, b and the weight */
        lx_v4f s[2][4] = {{{0}}};
        for (size_t k = k0; k < k1; k += CONV_LANES)
            for (int h = 0; h < 2; h++) {
                size_t i = k + 4 * (size_t)h;
                lx_v4f d = r.x * lx_v4_load(l->x + i) + r.y * lx_v4_load(l->y + i) +
                           r.z * lx_v4_load(l->z + i);
                lx_v4f q = 0.5f * (1.0f - d) + 0.5f * (1.0f + d) * a; /* >= a > 0 */
                lx_v4f w = 0.5f * (d + lx_v4_abs(d)) / (q * q) * lx_v4_load(l->om + i);
                s[h][0] += w * lx_v4_load(l->r + i);
                s[h][1] += w * lx_v4_load(l->g + i);
                s[h][2] += w * lx_v4_load(l->b + i);
                s[h][3] += w;
            }
        for (int c = 0; c < 4; c++)
            for (int h = 0; h < 2; h++)
                for (int j = 0; j < 4; j++)
                    tot[c] += (double)s[h][c][j];
    }
    for (int c = 0; c < 4; c++)
        out[c] = tot[c];
}

/* The same for Phong's pow(r.l, n), lights past the cut-off left out. */
static void sum_phong(const conv_list *l, float e, float cut, lx_vec3 r, double out[4])
{
    double tot[4] = {0, 0, 0, 0};
    for (size_t k = 0; k < l->count; k++) {
        float d = r.x * l->x[k] + r.y * l->y[k] + r.z * l->z[k];
        if (d < cut)
            continue;
        double w = (double)(exp2f(e * log2f(d)) * l->om[k]);
        tot[0] += w * l->r[k];
        tot[1] += w * l->g[k];
        tot[2] += w * l->b[k];
        tot[3] += w;
    }
    for (int c = 0; c < 4; c++)
        out[c] = tot[c];
}

/* ---- the plan ---------------------------------------------------------------------- */

/* The coarsest chain level whose mean texel angle sqrt(4 pi / 6) / size is
 * at most half_width / texels. */
static int source_level(const int *sizes, int count, const lx_lobe *lobe)
{
    double need = lobe->texels * 1.4472025091165353 / lobe->half_width;
    int level = 0;
    while (level + 1 < count && sizes[level + 1] >= need)
        level++;
    return level;
}

lx_status lx_conv_plan_create(const int *chain_sizes, int chain_count, const lx_lobe *lobe,
                              int out_size, double max_cost, lx_conv_plan **out)
{
    *out = NULL;
    lx_conv_plan *p = calloc(1, sizeof *p);
    if (!p)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    p->lobe = *lobe;
    p->level = source_level(chain_sizes, chain_count, lobe);
    int n = p->n = chain_sizes[p->level];
    p->lights = (size_t)6 * n * n;
    if (!build_tree(p, n)) {
        lx_conv_plan_free(p);
        return lx_fail(LX_ERR_NOMEM, "out of memory for a convolution of a %d x %d source", n, n);
    }

    /* the nodes' cones and the group tests: the widest group's radius
     * widens both */
    double theta_cut = acos(lobe->cos_cut < -1.0f ? -1.0 : (double)lobe->cos_cut);
    double g = p->group_ra = widest_group(out_size);
    for (int t = 1; t <= p->tiers; t++) {
        conv_tier *T = &p->tier[t];
        for (int i = 0; i < T->count; i++) {
            const conv_rect *R = &T->rect[i];
            double s0 = 2.0 * R->x0 / n - 1, s1 = 2.0 * R->x1 / n - 1;
            double t0 = 2.0 * R->y0 / n - 1, t1 = 2.0 * R->y1 / n - 1;
            lx_vec3 axis = rect_axis(R->face, s0, t0, s1, t1);
            double rad = cone_radius(R->face, axis, s0, t0, s1, t1);
            T->ax[i] = axis.x, T->ay[i] = axis.y, T->az[i] = axis.z;
            T->cos_cull[i] = cos_of(rad + theta_cut + g);
            T->cos_far[i] = lobe->far > 0.0 ? cos_of(rad * (1.0 + lobe->far) + g) : -2.0f;
        }
    }

    /* the cost: the lights a texel sums, over probe groups spread over a
     * face (the six are alike); over budget, no plan */
    size_t entries = 0;
    int probes = 0, m = out_size;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++, probes++) {
            int x0 = (int)((i + 0.37) / 4 * m) / CONV_GROUP * CONV_GROUP;
            int y0 = (int)((j + 0.61) / 4 * m) / CONV_GROUP * CONV_GROUP;
            lx_vec3 a = group_cone(LX_FACE_PZ, m, x0, y0, x0 + CONV_GROUP < m ? x0 + CONV_GROUP : m,
                                   y0 + CONV_GROUP < m ? y0 + CONV_GROUP : m, NULL);
            size_t len = group_walk(p, a, NULL, NULL);
            entries += len;
            p->most = len > p->most ? len : p->most;
        }
    p->cost = (double)entries / probes;
    if (p->cost > max_cost) {
        lx_conv_plan_free(p);
        return LX_OK;
    }
    *out = p;
    return LX_OK;
}

double lx_conv_plan_cost(const lx_conv_plan *p)
{
    return p->cost;
}

uint64_t lx_conv_plan_bytes(const lx_conv_plan *p)
{
    /* the lights, and while filling the flux vectors and solid angles */
    return 7 * sizeof(float) * (uint64_t)p->lights + 24 * (uint64_t)p->lights +
           8ull * (uint64_t)(p->n + 1) * (uint64_t)(p->n + 1) + tree_bytes(p->n) / 4;
}

int lx_conv_plan_level(const lx_conv_plan *p)
{
    return p->level;
}

/* The flux vectors of one row of a coarse level, gathered from level 0
 * (luminance x solid angle x direction of each source texel under a
 * coarse texel) or, when the sizes nest, from a finer level's. */
typedef struct flux_job {
    const lx_cubemap *src; /* level 0 */
    const double *omega;   /* its solid angles */
    const double *finer;   /* or a finer level's flux vectors, */
    int finer_size;        /* of this face size */
    int size;
    double *out;
} flux_job;

static bool flux_row(void *ctx, int row)
{
    const flux_job *j = ctx;
    int n = j->size, face = row / n, Y = row % n;
    double *q = j->out + 3 * ((size_t)row * n);
    memset(q, 0, sizeof(double) * 3 * (size_t)n);
    if (j->finer) {
        int k = j->finer_size / n;
        for (int y = Y * k; y < (Y + 1) * k; y++)
            for (int x = 0; x < j->finer_size; x++) {
                const double *f =
                    j->finer + 3 * (((size_t)face * j->finer_size + y) * j->finer_size + x);
                double *o = q + 3 * (size_t)(x / k);
                o[0] += f[0], o[1] += f[1], o[2] += f[2];
            }
        return true;
    }
    /* source texel x lies under coarse texel floor(x n / n0) */
    int n0 = j->src->size;
    int y0 = (int)(((long)Y * n0 + n - 1) / n), y1 = (int)(((long)(Y + 1) * n0 + n - 1) / n);
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < n0; x++) {
            const float *c = lx_cubemap_texel(j->src, face, x, y);
            double lum = lx_luminance(c);
            if (!(lum > 0.0))
                continue;
            double w = lum * lx_ibl_omega(j->omega, n0, x, y);
            lx_vec3 d = lx_cube_direction(face, (x + 0.5f) / n0, (y + 0.5f) / n0);
            double *o = q + 3 * (size_t)((long)x * n / n0);
            o[0] += w * d.x, o[1] += w * d.y, o[2] += w * d.z;
        }
    return true;
}

lx_status lx_conv_flux(const lx_ibl_chain *chain, int level, const double *finer, int finer_level,
                       const lx_ibl_run *run, double **out)
{
    int n = chain->level[level].size, n0 = chain->level[0].size;
    flux_job j = {.src = &chain->level[0], .size = n};
    if (finer && chain->level[finer_level].size % n == 0 &&
        n0 % chain->level[finer_level].size == 0) {
        j.finer = finer;
        j.finer_size = chain->level[finer_level].size;
    }
    *out = NULL;
    j.out = malloc(sizeof(double) * 18 * (size_t)n * n);
    double *omega = j.finer ? NULL : lx_ibl_solid_angles(n0);
    if (!j.out || (!j.finer && !omega)) {
        free(j.out);
        free(omega);
        return lx_fail(LX_ERR_NOMEM, "out of memory for the flux of a %d x %d mip", n, n);
    }
    j.omega = omega;
    lx_status st = lx_ibl_for(run, 6 * n, NULL, flux_row, &j, "prefilter");
    free(omega);
    if (st != LX_OK) {
        free(j.out);
        return st;
    }
    *out = j.out;
    return LX_OK;
}

lx_status lx_conv_plan_fill(lx_conv_plan *p, const lx_ibl_chain *chain, const double *flux)
{
    const lx_cubemap *s = p->src = &chain->level[p->level];
    int n = s->size;
    size_t lights = p->lights;
    double *omega = lx_ibl_solid_angles(n);
    /* per node of the tier being built: flux vector, solid angle, solid
     * angle x value */
    double *acc = malloc(sizeof(double) * 7 * (size_t)p->tier[1].count);
    if ((p->lx = malloc(sizeof(float) * 7 * lights))) {
        p->ly = p->lx + lights, p->lz = p->ly + lights, p->lom = p->lz + lights;
        p->lr = p->lom + lights, p->lg = p->lr + lights, p->lb = p->lg + lights;
    }
    if (!omega || !acc || !p->lx) {
        free(omega);
        free(acc);
        return lx_fail(LX_ERR_NOMEM, "out of memory for a convolution of a %d x %d source", n, n);
    }
    /* the lights, each tier 1 node's texels row by row, and their sums */
    conv_tier *T1 = &p->tier[1];
    for (int i = 0; i < T1->count; i++) {
        const conv_rect *R = &T1->rect[i];
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
                    double lum = lx_luminance(c);
                    double w = lum > 0.0 ? lum * om : 0.0;
                    a[0] += w * d.x, a[1] += w * d.y, a[2] += w * d.z;
                }
                a[3] += om, a[4] += om * c[0], a[5] += om * c[1], a[6] += om * c[2];
                p->lx[k] = d.x, p->ly[k] = d.y, p->lz[k] = d.z, p->lom[k] = (float)om;
                p->lr[k] = c[0], p->lg[k] = c[1], p->lb[k] = c[2];
            }
    }
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
        free(T->rect);
        T->rect = NULL;
    }
    free(acc);
    return LX_OK;
}

bool lx_conv_tile(const lx_conv_plan *p, lx_cubemap *out, int face, int x0, int y0, int x1, int y1)
{
    int m = out->size;
    conv_list list = {0};
    bool ok = list_reserve(&list, p->most + CONV_CHUNK);
    for (int gy = y0; ok && gy < y1; gy += CONV_GROUP)
        for (int gx = x0; ok && gx < x1; gx += CONV_GROUP) {
            int ex = gx + CONV_GROUP < x1 ? gx + CONV_GROUP : x1;
            int ey = gy + CONV_GROUP < y1 ? gy + CONV_GROUP : y1;
            list.count = 0;
            group_walk(p, group_cone(face, m, gx, gy, ex, ey, NULL), &list, &ok);
            /* pad to whole lanes with lights of no weight */
            while (ok && list.count % CONV_LANES) {
                static const conv_light none = {0, 0, 1, 0, 0, 0, 0};
                if ((ok = list_reserve(&list, 1)))
                    list_put(&list, &none);
            }
            for (int y = gy; ok && y < ey; y++)
                for (int x = gx; x < ex; x++) {
                    lx_vec3 r = lx_cube_direction(face, (x + 0.5f) / m, (y + 0.5f) / m);
                    double s[4];
                    if (p->lobe.kind == LX_LOBE_GGX)
                        sum_ggx(&list, p->lobe.param, r, s);
                    else
                        sum_phong(&list, p->lobe.param, p->lobe.cos_cut, r, s);
                    float *o = lx_cubemap_texel(out, face, x, y);
                    if (s[3] > 0.0) {
                        for (int k = 0; k < 3; k++)
                            o[k] = (float)(s[k] / s[3]);
                    } else {
                        /* a lobe narrower than the source's texels */
                        lx_ibl_sample(p->src, r, o);
                    }
                }
        }
    list_free(&list);
    return ok;
}
