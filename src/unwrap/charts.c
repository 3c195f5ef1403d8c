/* Chart segmentation, after the D-charts family (Julius, Kraevoy and
 * Sheffer, "D-Charts: Quasi-Developable Mesh Segmentation", 2005) as the
 * xatlas / thekla atlas lightmappers grow them. Coplanar neighbours are
 * first merged into planar regions (a wall of many triangles moves as one).
 * Then charts grow over regions by a greedy best-first search: a region
 * joins the chart it costs least to join, where the cost adds
 *  - the angle between its normal and the chart's (area-weighted) normal,
 *  - the seams it crosses (where the file splits vertices: more for hard
 *    edges, a little for texture seams),
 *  - roundness (how much it lengthens the chart's border for its area),
 *  - a reward for closing gaps (it shares more border with the chart than
 *    it adds).
 * No region joins beyond the angle limit or the cost limit; when no chart
 * can grow, the largest region left seeds a new one. */
#include "unwrap_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PLANAR_COS (1.0 - 1e-5) /* normals within 0.26 degrees are coplanar */
#define MAX_COST 2.0
#define DEVIATION_WEIGHT 2.0
#define ROUNDNESS_WEIGHT 0.01
#define STRAIGHTNESS_WEIGHT 6.0

/* ---- planar regions ------------------------------------------------------ */

static uint32_t find(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/* A region's border: edges toward other regions or the mesh border. */
typedef struct border_edge {
    uint32_t region; /* across the edge, UW_NONE at the mesh border */
    float seam;
    double length;
} border_edge;

typedef struct regions {
    uint32_t count;
    uint32_t *of_triangle;    /* per triangle, UW_NONE when degenerate */
    uint32_t *first_triangle; /* count + 1 offsets into triangles */
    uint32_t *triangles;
    uint32_t *first_border; /* count + 1 offsets into border */
    border_edge *border;
    double *area;
    double (*normal)[3];
} regions;

static void regions_free(regions *r)
{
    free(r->of_triangle);
    free(r->first_triangle);
    free(r->triangles);
    free(r->first_border);
    free(r->border);
    free(r->area);
    free(r->normal);
    memset(r, 0, sizeof *r);
}

static lx_status build_regions(const uw_mesh *m, regions *r)
{
    memset(r, 0, sizeof *r);
    uint32_t nt = m->triangle_count;
    uint32_t *parent = malloc(sizeof(uint32_t) * (nt ? nt : 1));
    r->of_triangle = malloc(sizeof(uint32_t) * (nt ? nt : 1));
    if (!parent || !r->of_triangle) {
        free(parent);
        regions_free(r);
        return lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
    }
    for (uint32_t t = 0; t < nt; t++)
        parent[t] = t;
    for (uint32_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t u = m->adjacent[3 * t + k];
            if (u == UW_NONE || u < t)
                continue;
            const double *a = m->normal[t], *b = m->normal[u];
            if (a[0] * b[0] + a[1] * b[1] + a[2] * b[2] < PLANAR_COS)
                continue;
            uint32_t ra = find(parent, t), rb = find(parent, u);
            if (ra != rb) /* the smaller index is the root: the same for any order */
                parent[ra > rb ? ra : rb] = ra > rb ? rb : ra;
        }
    /* number the regions in order of their first triangle: a root's
     * number is kept in of_triangle[root] until its members read it */
    uint32_t count = 0;
    for (uint32_t t = 0; t < nt; t++)
        r->of_triangle[t] = UW_NONE;
    for (uint32_t t = 0; t < nt; t++) {
        if (m->degenerate[t])
            continue;
        uint32_t root = find(parent, t);
        if (r->of_triangle[root] == UW_NONE)
            r->of_triangle[root] = count++;
        r->of_triangle[t] = r->of_triangle[root];
    }
    free(parent);
    r->count = count;
    r->first_triangle = calloc((size_t)count + 1, sizeof(uint32_t));
    r->triangles = malloc(sizeof(uint32_t) * (nt ? nt : 1));
    r->first_border = calloc((size_t)count + 1, sizeof(uint32_t));
    r->area = calloc(count ? count : 1, sizeof(double));
    r->normal = calloc(count ? count : 1, sizeof *r->normal);
    if (!r->first_triangle || !r->triangles || !r->first_border || !r->area || !r->normal) {
        regions_free(r);
        return lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
    }
    size_t borders = 0;
    for (uint32_t t = 0; t < nt; t++) {
        uint32_t g = r->of_triangle[t];
        if (g == UW_NONE)
            continue;
        r->first_triangle[g + 1]++;
        r->area[g] += m->area[t];
        for (int c = 0; c < 3; c++)
            r->normal[g][c] += m->normal[t][c] * m->area[t];
        for (int k = 0; k < 3; k++) {
            uint32_t u = m->adjacent[3 * t + k];
            if (u == UW_NONE || r->of_triangle[u] != g) {
                r->first_border[g + 1]++;
                borders++;
            }
        }
    }
    for (uint32_t g = 0; g < count; g++) {
        r->first_triangle[g + 1] += r->first_triangle[g];
        r->first_border[g + 1] += r->first_border[g];
        double len = sqrt(r->normal[g][0] * r->normal[g][0] + r->normal[g][1] * r->normal[g][1] +
                          r->normal[g][2] * r->normal[g][2]);
        for (int c = 0; c < 3; c++)
            r->normal[g][c] = len > 0.0 ? r->normal[g][c] / len : 0.0;
    }
    r->border = malloc(sizeof(border_edge) * (borders ? borders : 1));
    uint32_t *fill_t = malloc(sizeof(uint32_t) * (count ? count : 1));
    uint32_t *fill_b = malloc(sizeof(uint32_t) * (count ? count : 1));
    if (!r->border || !fill_t || !fill_b) {
        free(fill_t);
        free(fill_b);
        regions_free(r);
        return lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
    }
    memcpy(fill_t, r->first_triangle, sizeof(uint32_t) * count);
    memcpy(fill_b, r->first_border, sizeof(uint32_t) * count);
    for (uint32_t t = 0; t < nt; t++) {
        uint32_t g = r->of_triangle[t];
        if (g == UW_NONE)
            continue;
        r->triangles[fill_t[g]++] = t;
        for (int k = 0; k < 3; k++) {
            uint32_t u = m->adjacent[3 * t + k];
            if (u != UW_NONE && r->of_triangle[u] == g)
                continue;
            border_edge *e = &r->border[fill_b[g]++];
            e->region = u == UW_NONE ? UW_NONE : r->of_triangle[u];
            e->seam = u == UW_NONE ? 0.0f : m->seam[3 * t + k];
            e->length = m->edge_length[3 * t + k];
        }
    }
    free(fill_t);
    free(fill_b);
    return LX_OK;
}

/* ---- the candidate heap ------------------------------------------------- */

typedef struct candidate {
    double cost;
    uint32_t region, chart, version;
} candidate;

typedef struct heap {
    candidate *items;
    size_t count, capacity;
} heap;

static bool before(const candidate *a, const candidate *b)
{
    if (a->cost != b->cost)
        return a->cost < b->cost;
    if (a->region != b->region)
        return a->region < b->region;
    return a->chart < b->chart;
}

static bool heap_push(heap *h, candidate c)
{
    if (h->count == h->capacity) {
        size_t cap = h->capacity ? 2 * h->capacity : 256;
        candidate *p = realloc(h->items, sizeof *p * cap);
        if (!p)
            return false;
        h->items = p;
        h->capacity = cap;
    }
    size_t i = h->count++;
    while (i > 0) {
        size_t up = (i - 1) / 2;
        if (!before(&c, &h->items[up]))
            break;
        h->items[i] = h->items[up];
        i = up;
    }
    h->items[i] = c;
    return true;
}

static candidate heap_pop(heap *h)
{
    candidate top = h->items[0], last = h->items[--h->count];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, best = i;
        const candidate *bv = &last;
        if (l < h->count && before(&h->items[l], bv))
            best = l, bv = &h->items[l];
        if (r < h->count && before(&h->items[r], bv))
            best = r;
        if (best == i)
            break;
        h->items[i] = h->items[best];
        i = best;
    }
    if (h->count > 0)
        h->items[i] = last;
    return top;
}

/* ---- growing ------------------------------------------------------------ */

typedef struct chart_state {
    double normal_sum[3];
    double area, border;
    uint32_t version;
} chart_state;

/* The cost for region g to join chart c, or INFINITY when it may not. */
static double join_cost(const regions *r, const uint32_t *chart_of, uint32_t g, uint32_t c,
                        const chart_state *s, double max_angle_cos)
{
    double len = sqrt(s->normal_sum[0] * s->normal_sum[0] + s->normal_sum[1] * s->normal_sum[1] +
                      s->normal_sum[2] * s->normal_sum[2]);
    if (!(len > 0.0))
        return INFINITY;
    const double *n = r->normal[g];
    double cosine =
        (n[0] * s->normal_sum[0] + n[1] * s->normal_sum[1] + n[2] * s->normal_sum[2]) / len;
    if (cosine < max_angle_cos)
        return INFINITY;
    double l_in = 0.0, l_out = 0.0, seam = 0.0;
    for (uint32_t e = r->first_border[g]; e < r->first_border[g + 1]; e++) {
        const border_edge *b = &r->border[e];
        if (b->region != UW_NONE && chart_of[b->region] == c) {
            l_in += b->length;
            seam += b->length * b->seam;
        } else {
            l_out += b->length;
        }
    }
    if (!(l_in > 0.0))
        return INFINITY; /* not a neighbour (a stale entry) */
    double new_area = s->area + r->area[g], new_border = s->border + l_out - l_in;
    double cost = DEVIATION_WEIGHT * (1.0 - cosine) + seam / l_in;
    if (new_border > 0.0 && s->area > 0.0) {
        double old_round = s->border * s->border / s->area;
        double new_round = new_border * new_border / new_area;
        cost += ROUNDNESS_WEIGHT * (1.0 - old_round / new_round);
    }
    cost += STRAIGHTNESS_WEIGHT * fmin((l_out - l_in) / (l_out + l_in), 0.0);
    return cost <= MAX_COST ? cost : INFINITY;
}

static double region_border(const regions *r, uint32_t g)
{
    double sum = 0.0;
    for (uint32_t e = r->first_border[g]; e < r->first_border[g + 1]; e++)
        sum += r->border[e].length;
    return sum;
}

typedef struct sized {
    double area;
    uint32_t index;
} sized;

static int larger_first(const void *pa, const void *pb)
{
    const sized *a = pa, *b = pb;
    if (a->area != b->area)
        return a->area > b->area ? -1 : 1;
    return a->index < b->index ? -1 : a->index > b->index;
}

/* Region indices by area, largest first (ties by index). */
static bool sort_by_area(uint32_t *order, uint32_t n, const double *area)
{
    sized *tmp = malloc(sizeof *tmp * (n ? n : 1));
    if (!tmp)
        return false;
    for (uint32_t i = 0; i < n; i++)
        tmp[i] = (sized){area[i], i};
    qsort(tmp, n, sizeof *tmp, larger_first);
    for (uint32_t i = 0; i < n; i++)
        order[i] = tmp[i].index;
    free(tmp);
    return true;
}

static lx_status push_neighbours(heap *h, const regions *r, const uint32_t *chart_of, uint32_t g,
                                 uint32_t c, const chart_state *s, double max_angle_cos)
{
    for (uint32_t e = r->first_border[g]; e < r->first_border[g + 1]; e++) {
        uint32_t q = r->border[e].region;
        if (q == UW_NONE || chart_of[q] != UW_NONE)
            continue;
        double cost = join_cost(r, chart_of, q, c, s, max_angle_cos);
        if (isinf(cost))
            continue;
        candidate cand = {cost, q, c, s->version};
        if (!heap_push(h, cand))
            return lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
    }
    return LX_OK;
}

static void join(const regions *r, uint32_t *chart_of, uint32_t g, uint32_t c, chart_state *s)
{
    double l_in = 0.0, l_out = 0.0;
    for (uint32_t e = r->first_border[g]; e < r->first_border[g + 1]; e++) {
        const border_edge *b = &r->border[e];
        if (b->region != UW_NONE && chart_of[b->region] == c)
            l_in += b->length;
        else
            l_out += b->length;
    }
    chart_of[g] = c;
    for (int k = 0; k < 3; k++)
        s->normal_sum[k] += r->normal[g][k] * r->area[g];
    s->area += r->area[g];
    s->border += l_out - l_in;
    s->version++;
}

lx_status uw_grow_charts(const uw_mesh *m, double max_angle_cos, uw_chart **charts_out,
                         uint32_t *count_out)
{
    *charts_out = NULL;
    *count_out = 0;
    regions r;
    lx_status st = build_regions(m, &r);
    if (st != LX_OK)
        return st;
    uint32_t n = r.count;
    uint32_t *chart_of = malloc(sizeof(uint32_t) * (n ? n : 1));
    uint32_t *order = malloc(sizeof(uint32_t) * (n ? n : 1));
    chart_state *state = NULL;
    uint32_t chart_count = 0, state_capacity = 0;
    heap h = {0};
    if (!chart_of || !order) {
        st = lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
        goto done;
    }
    memset(chart_of, 0xff, sizeof(uint32_t) * n);
    if (!sort_by_area(order, n, r.area)) {
        st = lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
        goto done;
    }
    uint32_t next_seed = 0;
    for (;;) {
        if (h.count == 0) {
            while (next_seed < n && chart_of[order[next_seed]] != UW_NONE)
                next_seed++;
            if (next_seed == n)
                break;
            uint32_t g = order[next_seed];
            if (chart_count == state_capacity) {
                uint32_t cap = state_capacity ? 2 * state_capacity : 64;
                chart_state *p = realloc(state, sizeof *p * cap);
                if (!p) {
                    st = lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
                    goto done;
                }
                state = p;
                state_capacity = cap;
            }
            uint32_t c = chart_count++;
            chart_state *s = &state[c];
            memset(s, 0, sizeof *s);
            chart_of[g] = c;
            for (int k = 0; k < 3; k++)
                s->normal_sum[k] = r.normal[g][k] * r.area[g];
            s->area = r.area[g];
            s->border = region_border(&r, g);
            st = push_neighbours(&h, &r, chart_of, g, c, s, max_angle_cos);
            if (st != LX_OK)
                goto done;
            continue;
        }
        candidate e = heap_pop(&h);
        if (chart_of[e.region] != UW_NONE)
            continue;
        chart_state *s = &state[e.chart];
        if (e.version != s->version) {
            /* the chart grew since: cost it again, and let a cheaper
             * candidate go first */
            double cost = join_cost(&r, chart_of, e.region, e.chart, s, max_angle_cos);
            if (isinf(cost))
                continue;
            if (h.count > 0 && cost > h.items[0].cost) {
                candidate again = {cost, e.region, e.chart, s->version};
                if (!heap_push(&h, again)) {
                    st = lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
                    goto done;
                }
                continue;
            }
        }
        join(&r, chart_of, e.region, e.chart, s);
        st = push_neighbours(&h, &r, chart_of, e.region, e.chart, s, max_angle_cos);
        if (st != LX_OK)
            goto done;
    }
    /* charts from regions: triangles ascending */
    uw_chart *charts = calloc(chart_count ? chart_count : 1, sizeof *charts);
    uint32_t *sizes = calloc(chart_count ? chart_count : 1, sizeof(uint32_t));
    if (!charts || !sizes) {
        free(charts);
        free(sizes);
        st = lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
        goto done;
    }
    for (uint32_t t = 0; t < m->triangle_count; t++)
        if (r.of_triangle[t] != UW_NONE)
            sizes[chart_of[r.of_triangle[t]]]++;
    bool ok = true;
    for (uint32_t c = 0; c < chart_count && ok; c++)
        ok = (charts[c].triangles = malloc(sizeof(uint32_t) * sizes[c])) != NULL;
    if (ok)
        for (uint32_t t = 0; t < m->triangle_count; t++)
            if (r.of_triangle[t] != UW_NONE) {
                uw_chart *c = &charts[chart_of[r.of_triangle[t]]];
                c->triangles[c->triangle_count++] = t;
            }
    free(sizes);
    if (!ok) {
        for (uint32_t c = 0; c < chart_count; c++)
            uw_chart_free(&charts[c]);
        free(charts);
        st = lx_fail(LX_ERR_NOMEM, "out of memory growing charts");
        goto done;
    }
    *charts_out = charts;
    *count_out = chart_count;
done:
    free(h.items);
    free(state);
    free(order);
    free(chart_of);
    regions_free(&r);
    return st;
}

void uw_chart_free(uw_chart *c)
{
    free(c->triangles);
    free(c->vertices);
    free(c->corners);
    free(c->uv);
    memset(c, 0, sizeof *c);
}

/* ---- cutting a chart in two ---------------------------------------------- */

static void centroid(const uw_mesh *m, uint32_t t, double out[3])
{
    const uint32_t *idx = &m->indices[3 * t];
    for (int k = 0; k < 3; k++)
        out[k] = (m->position[idx[0]][k] + m->position[idx[1]][k] + m->position[idx[2]][k]) / 3.0;
}

static double distance2(const double a[3], const double b[3])
{
    double d0 = a[0] - b[0], d1 = a[1] - b[1], d2 = a[2] - b[2];
    return d0 * d0 + d1 * d1 + d2 * d2;
}

uint32_t uw_chart_find(const uw_chart *c, uint32_t t)
{
    uint32_t lo = 0, hi = c->triangle_count;
    while (lo < hi) {
        uint32_t mid = (lo + hi) / 2;
        if (c->triangles[mid] < t)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < c->triangle_count && c->triangles[lo] == t ? lo : UW_NONE;
}

bool uw_split_chart(const uw_mesh *m, const uw_chart *c, uw_chart *a, uw_chart *b)
{
    memset(a, 0, sizeof *a);
    memset(b, 0, sizeof *b);
    uint32_t n = c->triangle_count;
    if (n < 2)
        return false;
    double(*cen)[3] = malloc(sizeof *cen * n);
    double *dist = malloc(sizeof(double) * n);
    uint32_t *label = malloc(sizeof(uint32_t) * n);
    heap queue = {0};
    if (!cen || !dist || !label) {
        free(cen);
        free(dist);
        free(label);
        return false;
    }
    double mid[3] = {0, 0, 0}, total = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        centroid(m, c->triangles[i], cen[i]);
        double w = m->area[c->triangles[i]];
        for (int k = 0; k < 3; k++)
            mid[k] += cen[i][k] * w;
        total += w;
    }
    for (int k = 0; k < 3; k++)
        mid[k] = total > 0.0 ? mid[k] / total : cen[0][k];
    /* the two seeds: farthest from the middle, then farthest from that */
    uint32_t seed[2] = {0, 0};
    double best = -1.0;
    for (uint32_t i = 0; i < n; i++) {
        double d = distance2(cen[i], mid);
        if (d > best)
            best = d, seed[0] = i;
    }
    best = -1.0;
    for (uint32_t i = 0; i < n; i++) {
        double d = distance2(cen[i], cen[seed[0]]);
        if (d > best && i != seed[0])
            best = d, seed[1] = i;
    }
    /* two fronts grown by distance along the faces (Dijkstra over
     * neighbouring triangles' centroids): each triangle to the nearer */
    for (uint32_t i = 0; i < n; i++) {
        dist[i] = INFINITY;
        label[i] = UW_NONE;
    }
    bool ok = true;
    for (int s = 0; s < 2 && ok; s++) {
        dist[seed[s]] = 0.0;
        ok = heap_push(&queue, (candidate){0.0, seed[s], (uint32_t)s, 0});
    }
    while (ok && queue.count > 0) {
        candidate f = heap_pop(&queue); /* cost: distance; region: triangle; chart: label */
        if (label[f.region] != UW_NONE)
            continue;
        label[f.region] = f.chart;
        uint32_t t = c->triangles[f.region];
        for (int k = 0; k < 3 && ok; k++) {
            uint32_t u = m->adjacent[3 * t + k];
            uint32_t j = u == UW_NONE ? UW_NONE : uw_chart_find(c, u);
            if (j == UW_NONE || label[j] != UW_NONE)
                continue;
            double d = f.cost + sqrt(distance2(cen[f.region], cen[j]));
            if (d < dist[j]) {
                dist[j] = d;
                ok = heap_push(&queue, (candidate){d, j, f.chart, 0});
            }
        }
    }
    uint32_t na = 0, nb = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (label[i] == UW_NONE) /* cut off from both seeds: with the first */
            label[i] = 0;
        if (label[i] == 0)
            na++;
        else
            nb++;
    }
    ok = ok && na > 0 && nb > 0;
    if (ok) {
        a->triangles = malloc(sizeof(uint32_t) * na);
        b->triangles = malloc(sizeof(uint32_t) * nb);
        ok = a->triangles && b->triangles;
    }
    if (ok)
        for (uint32_t i = 0; i < n; i++) {
            uw_chart *dst = label[i] == 0 ? a : b;
            dst->triangles[dst->triangle_count++] = c->triangles[i];
        }
    if (!ok) {
        uw_chart_free(a);
        uw_chart_free(b);
    }
    free(cen);
    free(dist);
    free(label);
    free(queue.items);
    return ok;
}
