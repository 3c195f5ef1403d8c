/* A light tree over the emissive triangles (Conty Estevez and Kulla,
 * "Importance Sampling of Many Lights with Adaptive Tree Splitting",
 * HPG 2018; the bounds as Pharr, Jakob and Humphreys describe them in
 * Physically Based Rendering, 4th ed., 12.6): picks a triangle for a
 * receiving point with probability close to its share of the point's
 * irradiance, so a texel beside one bulb of a string of a hundred spends
 * its samples on that bulb rather than on the string's power.
 *
 * Each node bounds its triangles: a box, their summed power (emission
 * luminance x area) and a cone holding their front normals. Its
 * importance for a point p with normal n is
 *     power x cos(theta') x cos(theta_i') / d^2,
 * d the distance from p to the box's centre (at least the box's radius),
 * theta' the smallest angle between the cone and the direction to p, and
 * theta_i' the smallest between n and the directions into the box (both
 * widened by the angle the box's bounding sphere subtends at p; zero past
 * 90 degrees). The bounds are conservative: a node of zero importance
 * cannot light p, so sampling stays unbiased. A pick walks down from the
 * root choosing a child by the two importances, the one uniform number
 * rescaled at each step (stratified samples stay stratified), and returns
 * the product of the choices' probabilities.
 *
 * The tree splits at the median centroid along the widest axis of the
 * centroids' box (ties by triangle index): the same tree for the same
 * scene, on any thread count. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI_D 3.14159265358979323846
#define HALF_PI (0.5 * PI_D)

typedef struct tree_node {
    double lo[3], hi[3];
    double axis[3];  /* the normals' cone: its axis ... */
    double cos_half; /* ... and the cosine of its half angle (-1: every way) */
    double power;
    uint32_t child;    /* internal: the first child (the second follows it) */
    uint32_t triangle; /* a leaf: the triangle, else UINT32_MAX */
} tree_node;

struct lx_emitter_tree {
    tree_node *nodes;
    uint32_t count;
};

typedef struct build_item {
    uint32_t triangle;
    double centroid[3];
} build_item;

typedef struct build_state {
    const lx_emitter_bounds *tri;
    build_item *items;
    tree_node *nodes;
    uint32_t count;
} build_state;

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double clamp_unit(double x)
{
    return x < -1.0 ? -1.0 : x > 1.0 ? 1.0 : x;
}

/* The smallest cone holding cones a and b, into a. */
static void cone_union(double *axis, double *cos_half, const double *b_axis, double b_cos)
{
    if (*cos_half <= -1.0)
        return;
    if (b_cos <= -1.0) {
        *cos_half = -1.0;
        return;
    }
    double ta = acos(clamp_unit(*cos_half)), tb = acos(clamp_unit(b_cos));
    double td = acos(clamp_unit(dot3(axis, b_axis)));
    if (td + tb <= ta)
        return; /* b inside a */
    if (td + ta <= tb) {
        memcpy(axis, b_axis, 3 * sizeof(double));
        *cos_half = b_cos;
        return;
    }
    double t = 0.5 * (ta + td + tb);
    if (t >= PI_D) {
        *cos_half = -1.0;
        return;
    }
    /* turn a's axis towards b's by t - ta */
    double along = dot3(axis, b_axis), perp[3];
    for (int k = 0; k < 3; k++)
        perp[k] = b_axis[k] - along * axis[k];
    double len = sqrt(dot3(perp, perp));
    if (!(len > 1e-12)) {
        *cos_half = -1.0; /* opposite axes */
        return;
    }
    double turn = t - ta, c = cos(turn), s = sin(turn);
    for (int k = 0; k < 3; k++)
        axis[k] = c * axis[k] + s * perp[k] / len;
    double norm = sqrt(dot3(axis, axis));
    for (int k = 0; k < 3; k++)
        axis[k] /= norm;
    *cos_half = cos(t);
}

static int by_centroid(const build_item *x, const build_item *y, int axis)
{
    if (x->centroid[axis] != y->centroid[axis])
        return x->centroid[axis] < y->centroid[axis] ? -1 : 1;
    return x->triangle < y->triangle ? -1 : x->triangle > y->triangle;
}
static int by_x(const void *a, const void *b) { return by_centroid(a, b, 0); }
static int by_y(const void *a, const void *b) { return by_centroid(a, b, 1); }
static int by_z(const void *a, const void *b) { return by_centroid(a, b, 2); }

/* Bounds of items [first, first + n) into node k; children below it. */
static void build_node(build_state *s, uint32_t k, uint32_t first, uint32_t n)
{
    tree_node *node = &s->nodes[k];
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int a = 0; a < 3; a++)
        node->lo[a] = INFINITY, node->hi[a] = -INFINITY;
    node->power = 0.0;
    node->cos_half = 2.0; /* empty: the first triangle's cone replaces it */
    for (uint32_t i = first; i < first + n; i++) {
        const lx_emitter_bounds *t = &s->tri[s->items[i].triangle];
        const float *lo = &t->lo.x, *hi = &t->hi.x, *ax = &t->normal.x;
        double axis[3] = {ax[0], ax[1], ax[2]};
        for (int a = 0; a < 3; a++) {
            node->lo[a] = fmin(node->lo[a], lo[a]);
            node->hi[a] = fmax(node->hi[a], hi[a]);
            clo[a] = fmin(clo[a], s->items[i].centroid[a]);
            chi[a] = fmax(chi[a], s->items[i].centroid[a]);
        }
        node->power += t->power;
        if (node->cos_half > 1.0) {
            memcpy(node->axis, axis, sizeof axis);
            node->cos_half = 1.0;
        } else {
            cone_union(node->axis, &node->cos_half, axis, 1.0);
        }
    }
    if (n == 1) {
        node->triangle = s->items[first].triangle;
        node->child = 0;
        return;
    }
    node->triangle = UINT32_MAX;
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[axis] - clo[axis])
            axis = a;
    int (*const order[3])(const void *, const void *) = {by_x, by_y, by_z};
    qsort(s->items + first, n, sizeof(build_item), order[axis]);
    uint32_t left = n / 2;
    node->child = s->count;
    s->count += 2;
    build_node(s, node->child, first, left);
    build_node(s, s->nodes[k].child + 1, first + left, n - left);
}

lx_status lx_emitter_tree_build(const lx_emitter_bounds *tri, uint32_t count,
                                lx_emitter_tree **out)
{
    *out = NULL;
    if (count == 0)
        return LX_OK;
    lx_emitter_tree *tree = calloc(1, sizeof *tree);
    build_state s = {.tri = tri, .count = 1};
    s.items = malloc(sizeof(build_item) * count);
    s.nodes = malloc(sizeof(tree_node) * (2 * (size_t)count));
    if (!tree || !s.items || !s.nodes) {
        free(tree);
        free(s.items);
        free(s.nodes);
        return lx_fail(LX_ERR_NOMEM, "out of memory for the emitters' tree");
    }
    for (uint32_t i = 0; i < count; i++) {
        s.items[i].triangle = i;
        s.items[i].centroid[0] = 0.5 * ((double)tri[i].lo.x + tri[i].hi.x);
        s.items[i].centroid[1] = 0.5 * ((double)tri[i].lo.y + tri[i].hi.y);
        s.items[i].centroid[2] = 0.5 * ((double)tri[i].lo.z + tri[i].hi.z);
    }
    build_node(&s, 0, 0, count);
    free(s.items);
    tree->nodes = s.nodes;
    tree->count = s.count;
    *out = tree;
    return LX_OK;
}

void lx_emitter_tree_destroy(lx_emitter_tree *tree)
{
    if (!tree)
        return;
    free(tree->nodes);
    free(tree);
}

/* A node's importance for point p, normal n (see the top). */
static double importance(const tree_node *node, const double *p, const double *n)
{
    double c[3], d[3], r2 = 0.0;
    for (int a = 0; a < 3; a++) {
        c[a] = 0.5 * (node->lo[a] + node->hi[a]);
        double h = 0.5 * (node->hi[a] - node->lo[a]);
        r2 += h * h;
        d[a] = p[a] - c[a];
    }
    double d2 = dot3(d, d);
    if (d2 <= r2)
        return node->power / fmax(r2, 1e-30); /* p within the bounds: no angle bounds */
    double dist = sqrt(d2), theta_b = asin(sqrt(r2 / d2));
    double w[3] = {d[0] / dist, d[1] / dist, d[2] / dist}; /* the centre towards p */
    /* the emitters' side */
    double theta_o = node->cos_half <= -1.0 ? PI_D : acos(clamp_unit(node->cos_half));
    double theta_w = acos(clamp_unit(dot3(node->axis, w)));
    double theta_e = fmax(0.0, theta_w - theta_o - theta_b);
    if (theta_e >= HALF_PI)
        return 0.0;
    /* the receiver's side */
    double theta_i = acos(clamp_unit(-dot3(n, w)));
    double theta_r = fmax(0.0, theta_i - theta_b);
    if (theta_r >= HALF_PI)
        return 0.0;
    return node->power * cos(theta_e) * cos(theta_r) / d2;
}

/* The shares of a node's two children for p, n (false when neither can
 * light it). One function for the pick and the probability, kept out of
 * line: the compiler then evaluates both the same way, so a pick's
 * probability is the exact product lx_emitter_tree_probability gives. */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static bool child_shares(const lx_emitter_tree *tree, const tree_node *node, const double *p,
                         const double *n, double *pa, double *pb)
{
    double ia = importance(&tree->nodes[node->child], p, n);
    double ib = importance(&tree->nodes[node->child + 1], p, n);
    double sum = ia + ib;
    if (!(sum > 0.0) || !isfinite(sum))
        return false;
    /* each as its importance over the sum (not 1 - the other: that
     * cancels when one side is tiny) */
    *pa = ia / sum;
    *pb = ib / sum;
    return true;
}

bool lx_emitter_tree_pick(const lx_emitter_tree *tree, lx_vec3 point, lx_vec3 normal, float u,
                          uint32_t *triangle, double *probability, float *u_rest)
{
    double p[3] = {point.x, point.y, point.z}, n[3] = {normal.x, normal.y, normal.z};
    const tree_node *node = &tree->nodes[0];
    double prob = 1.0, x = u;
    if (!(importance(node, p, n) > 0.0))
        return false;
    while (node->triangle == UINT32_MAX) {
        const tree_node *a = &tree->nodes[node->child], *b = a + 1;
        double pa, pb;
        if (!child_shares(tree, node, p, n, &pa, &pb))
            return false;
        if (x < pa) {
            x = x / pa;
            prob *= pa;
            node = a;
        } else {
            x = (x - pa) / (1.0 - pa);
            prob *= pb;
            node = b;
        }
        x = fmin(fmax(x, 0.0), 0x1.fffffep-1);
    }
    *triangle = node->triangle;
    *probability = prob;
    *u_rest = (float)x;
    return prob > 0.0;
}

double lx_emitter_tree_probability(const lx_emitter_tree *tree, lx_vec3 point, lx_vec3 normal,
                                   uint32_t triangle)
{
    /* every path down, until the leaf (for the tests: O(count)) */
    double p[3] = {point.x, point.y, point.z}, n[3] = {normal.x, normal.y, normal.z};
    uint32_t stack[64];
    double prob[64];
    int top = 0;
    stack[top] = 0, prob[top++] = 1.0;
    while (top > 0) {
        top--;
        const tree_node *node = &tree->nodes[stack[top]];
        double pr = prob[top];
        if (node->triangle != UINT32_MAX) {
            if (node->triangle == triangle)
                return pr;
            continue;
        }
        double pa, pb;
        if (!child_shares(tree, node, p, n, &pa, &pb) || top + 2 > 64)
            continue;
        stack[top] = node->child, prob[top++] = pr * pa;
        stack[top] = node->child + 1, prob[top++] = pr * pb;
    }
    return 0.0;
}
