/* Atlas packing on texel bitmaps, as xatlas packs: each chart is
 * rasterized into the texels its triangles overlap, grown by the padding
 * (the rings it owns), and placed, upright or turned a quarter, where its
 * grown footprint meets no other one: the first hole inside the page's
 * used extent, else the place that grows the extent least (the square of
 * the larger side plus k times the area; xatlas's measure is k = 1).
 * Charts go largest first. The packing runs for k = 1, 4 and 1000 and
 * keeps the attempt covering the largest share of its pages among those
 * whose pages are near-square (at most 1.5 : 1), else the squarest. A node's charts
 * share one page: nodes are dealt to pages by area, and a node whose chart does not fit moves, all
 * its charts with it, to the next page. Footprints are kept as runs of texels per row, so charts
 * interlock and small ones fill the holes of rings. */
#include "unwrap_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define FILL_ESTIMATE 0.80  /* share of a page the dealing of nodes plans to use */
#define MANY_CHARTS 1024    /* above this, holes are sought from a cursor */
#define MAX_PAGE_ASPECT 1.5 /* a page's long side over its short side, when it can be */

/* ---- rasterizing --------------------------------------------------------- */

/* Marks in cover (w x h) the texels triangle p (texel units) overlaps with
 * a positive area, or with eps > 0 every texel within eps of it. A row
 * at a time: the triangle cut to the row's strip is a convex polygon, and
 * a texel of the row is touched when its x-range meets the polygon's. */
static void rasterize(uint8_t *cover, int w, int h, const double p[3][2], double eps)
{
    double ymin = fmin(p[0][1], fmin(p[1][1], p[2][1])),
           ymax = fmax(p[0][1], fmax(p[1][1], p[2][1]));
    int y0 = (int)fmax(floor(ymin - eps), 0.0), y1 = (int)fmin(ceil(ymax + eps) - 1.0, h - 1.0);
    for (int y = y0; y <= y1; y++) {
        double lo_y = y - eps, hi_y = y + 1.0 + eps;
        if (!(ymax > lo_y && ymin < hi_y) && eps == 0.0)
            continue;
        double lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < 3; k++) {
            const double *a = p[k], *b = p[(k + 1) % 3];
            if (a[1] >= lo_y && a[1] <= hi_y)
                lo = fmin(lo, a[0]), hi = fmax(hi, a[0]);
            double lines[2] = {lo_y, hi_y};
            for (int l = 0; l < 2; l++) {
                double ly = lines[l];
                if ((a[1] - ly) * (b[1] - ly) < 0.0) {
                    double x = a[0] + (ly - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                    lo = fmin(lo, x), hi = fmax(hi, x);
                }
            }
        }
        if (eps == 0.0 ? !(lo < hi) : !(lo <= hi))
            continue;
        int x0 = (int)fmax(floor(lo - eps), 0.0), x1 = (int)fmin(ceil(hi + eps) - 1.0, w - 1.0);
        if (x1 >= x0)
            memset(&cover[(size_t)y * w + x0], 1, (size_t)(x1 - x0 + 1));
    }
}

/* Footprints take every texel within this of a triangle, so that the
 * float page UVs the baker reads back (good to about 2.4e-4 texel in a
 * 4096 page) can never reach a texel the packer did not reserve. */
#define COVER_MARGIN 2e-3

/* An item in one orientation: covered texels and the padded footprint,
 * kept as runs of texels per row (so a ring's hole can hold other charts). */
typedef struct shape {
    int cw, ch;             /* covered grid (texels) */
    double dx, dy;          /* uv (0, 0) in the grid: the chart centred in it */
    int fw, fh;             /* footprint: cw + 2 pad, ch + 2 pad */
    uint32_t *row_first;    /* fh + 1 offsets into runs */
    int (*runs)[2];         /* first and last texel of each run */
    int widest, widest_row; /* the longest run and its row */
    int *row_width;         /* per footprint row: its longest run */
    uint8_t *cover;         /* cw x ch */
    uint32_t covered;
} shape;

static void shape_free(shape *s)
{
    free(s->row_width);
    free(s->row_first);
    free(s->runs);
    free(s->cover);
    memset(s, 0, sizeof *s);
}

/* uv of vertex v of item it, turned or not. */
static void item_uv(const uw_item *it, uint32_t v, bool turned, double out[2])
{
    double u = it->uv[2 * v], w = it->uv[2 * v + 1];
    out[0] = turned ? it->height - w : u;
    out[1] = turned ? u : w;
}

static bool make_shape(const uw_item *it, bool turned, int pad, shape *s)
{
    memset(s, 0, sizeof *s);
    double w = turned ? it->height : it->width, h = turned ? it->width : it->height;
    /* the fewest texels that hold the chart with COVER_MARGIN on each side,
     * the chart centred in them: no border lies on a texel edge, where the
     * page's float UVs could tip it either way */
    double margin = it->solid ? 0.0 : COVER_MARGIN;
    s->cw = (int)fmax(ceil(w + 2.0 * margin), 1.0);
    s->ch = (int)fmax(ceil(h + 2.0 * margin), 1.0);
    s->dx = 0.5 * (s->cw - w);
    s->dy = 0.5 * (s->ch - h);
    s->fw = s->cw + 2 * pad;
    s->fh = s->ch + 2 * pad;
    size_t fsize = (size_t)s->fw * s->fh;
    s->cover = calloc((size_t)s->cw * s->ch, 1);
    s->row_first = malloc(sizeof(uint32_t) * ((size_t)s->fh + 1));
    uint8_t *wide = calloc(fsize, 1), *grown = calloc(fsize, 1);
    if (!s->cover || !s->row_first || !wide || !grown) {
        free(wide);
        free(grown);
        shape_free(s);
        return false;
    }
    uint8_t *strict = it->solid ? NULL : calloc((size_t)s->cw * s->ch, 1);
    if (it->solid) {
        memset(s->cover, 1, (size_t)s->cw * s->ch);
        s->covered = (uint32_t)((size_t)s->cw * s->ch);
    } else if (!strict) {
        free(wide);
        free(grown);
        shape_free(s);
        return false;
    } else {
        for (uint32_t t = 0; t < it->triangle_count; t++) {
            double p[3][2];
            for (int k = 0; k < 3; k++) {
                item_uv(it, it->corners[3 * t + k], turned, p[k]);
                p[k][0] += s->dx;
                p[k][1] += s->dy;
            }
            rasterize(s->cover, s->cw, s->ch, p, COVER_MARGIN);
            rasterize(strict, s->cw, s->ch, p, 0.0);
        }
        for (size_t i = 0; i < (size_t)s->cw * s->ch; i++)
            s->covered += strict[i];
        free(strict);
    }
    /* the footprint: covered texels grown by pad in every direction (a
     * square: the 8-neighbour rings the baker's dilation fills), rows
     * first, then columns */
    for (int y = 0; y < s->ch; y++)
        for (int x = 0; x < s->cw; x++)
            if (s->cover[(size_t)y * s->cw + x])
                memset(&wide[(size_t)(y + pad) * s->fw + x], 1, (size_t)(2 * pad + 1));
    for (int y = 0; y < s->fh; y++)
        for (int x = 0; x < s->fw; x++)
            if (wide[(size_t)y * s->fw + x])
                for (int k = y - pad; k <= y + pad; k++)
                    if (k >= 0 && k < s->fh)
                        grown[(size_t)k * s->fw + x] = 1;
    free(wide);
    uint32_t runs = 0;
    for (int pass = 0; pass < 2; pass++) {
        runs = 0;
        for (int y = 0; y < s->fh; y++) {
            if (pass == 1)
                s->row_first[y] = runs;
            const uint8_t *row = &grown[(size_t)y * s->fw];
            for (int x = 0; x < s->fw;) {
                if (!row[x]) {
                    x++;
                    continue;
                }
                int end = x;
                while (end + 1 < s->fw && row[end + 1])
                    end++;
                if (pass == 1)
                    s->runs[runs][0] = x, s->runs[runs][1] = end;
                runs++;
                x = end + 1;
            }
        }
        if (pass == 0 && !(s->runs = malloc(sizeof *s->runs * (runs ? runs : 1)))) {
            free(grown);
            shape_free(s);
            return false;
        }
    }
    s->row_first[s->fh] = runs;
    free(grown);
    s->widest = 0;
    s->row_width = calloc((size_t)s->fh, sizeof(int));
    if (!s->row_width) {
        shape_free(s);
        return false;
    }
    for (int y = 0; y < s->fh; y++)
        for (uint32_t k = s->row_first[y]; k < s->row_first[y + 1]; k++) {
            int run = s->runs[k][1] - s->runs[k][0] + 1;
            s->row_width[y] = run > s->row_width[y] ? run : s->row_width[y];
            if (run > s->widest)
                s->widest = run, s->widest_row = y;
        }
    return true;
}

/* ---- page bitmaps ----------------------------------------------------------- */

typedef struct page {
    int size;           /* side of the search area: atlas_size + 2 pad */
    int words;          /* 64-bit words a row */
    uint64_t *bits;     /* size rows */
    int *rightmost;     /* per row: its last taken texel, -1 when none */
    int cursor;         /* holes are sought from this row on (see find_place) */
    int cursor_class;   /* the size class the cursor belongs to */
    double area_weight; /* of the extent's area in the growth measure */
    int *inner;         /* per row: its longest free run left of rightmost */
    int used_w, used_h; /* extent of the placed footprints */
    uint32_t *nodes;    /* nodes dealt to the page */
    uint32_t node_count, node_capacity;
    double planned; /* their footprint area */
} page;

/* First set bit of row y in [from, to], or -1. */
static int first_set(const page *p, int y, int from, int to)
{
    const uint64_t *row = &p->bits[(size_t)y * p->words];
    int w = from >> 6;
    uint64_t word = row[w] & (~0ull << (from & 63));
    for (;;) {
        if (word) {
            int x = (w << 6) + __builtin_ctzll(word);
            return x <= to ? x : -1;
        }
        if (++w > (to >> 6))
            return -1;
        word = row[w];
    }
}

/* First clear bit of row y from `from` on (p->size when none). */
static int first_clear(const page *p, int y, int from)
{
    const uint64_t *row = &p->bits[(size_t)y * p->words];
    int w = from >> 6;
    uint64_t word = ~row[w] & (~0ull << (from & 63));
    while (!word) {
        if (++w >= p->words)
            return p->size;
        word = ~row[w];
    }
    int x = (w << 6) + __builtin_ctzll(word);
    return x < p->size ? x : p->size;
}

static void set_span(page *p, int y, int from, int to, bool on)
{
    uint64_t *row = &p->bits[(size_t)y * p->words];
    for (int x = from; x <= to;) {
        int w = x >> 6, b = x & 63;
        int n = 64 - b < to - x + 1 ? 64 - b : to - x + 1;
        uint64_t mask = (n == 64 ? ~0ull : ((1ull << n) - 1)) << b;
        row[w] = on ? row[w] | mask : row[w] & ~mask;
        x += n;
    }
}

/* Row y's last taken texel and longest hole before it. */
static void row_update(page *p, int y)
{
    const uint64_t *row = &p->bits[(size_t)y * p->words];
    int last = -1;
    for (int w = p->words - 1; w >= 0; w--)
        if (row[w]) {
            last = (w << 6) + 63 - __builtin_clzll(row[w]);
            break;
        }
    p->rightmost[y] = last;
    int best = 0;
    for (int x = last > 0 ? first_clear(p, y, 0) : last + 1; x < last;) {
        int end = first_set(p, y, x, last);
        best = end - x > best ? end - x : best;
        x = first_clear(p, y, end);
    }
    p->inner[y] = best;
}

/* The longest free run of row y within the used width. */
static int free_within(const page *p, int y)
{
    int trail = p->used_w - p->rightmost[y] - 1;
    return trail > p->inner[y] ? trail : p->inner[y];
}

/* Leftmost x in [0, limit] at which shape s fits with its top at row y;
 * -1 when none. Rows are checked round from the one that last blocked
 * (the likeliest to block again) until every row passes at one x. */
static int leftmost_fit(const page *p, const shape *s, int y, int limit)
{
    int x = 0, r = s->widest_row, passed = 0;
    while (passed < s->fh) {
        bool moved = false;
        for (uint32_t k = s->row_first[r]; k < s->row_first[r + 1]; k++) {
            int lo = s->runs[k][0], hi = s->runs[k][1];
            int blocked = first_set(p, y + r, x + lo, x + hi);
            if (blocked < 0)
                continue;
            x = first_clear(p, y + r, blocked) - lo;
            if (x > limit)
                return -1;
            moved = true;
            break;
        }
        passed = moved ? 0 : passed + 1;
        if (!moved)
            r = r + 1 < s->fh ? r + 1 : 0;
    }
    return x;
}

static void stamp(page *p, const shape *s, int x, int y, bool on)
{
    for (int r = 0; r < s->fh; r++) {
        for (uint32_t k = s->row_first[r]; k < s->row_first[r + 1]; k++)
            set_span(p, y + r, x + s->runs[k][0], x + s->runs[k][1], on);
        row_update(p, y + r);
    }
}

typedef struct placement {
    int x, y;
    int turned;
    double metric;
} placement;

/* Where the shape sits at row y if every row of it starts right of the
 * row's last taken texel (the page's right skyline); -1 past the limit. */
static int past_skyline(const page *p, const shape *s, int y, int limit)
{
    int x = 0;
    for (int r = 0; r < s->fh; r++) {
        if (s->row_first[r] == s->row_first[r + 1])
            continue;
        int need = p->rightmost[y + r] + 1 - s->runs[s->row_first[r]][0];
        x = need > x ? need : x;
    }
    return x <= limit ? x : -1;
}

static void consider(const page *p, const shape *s, int o, int x, int y, placement *best)
{
    int w = p->used_w > x + s->fw ? p->used_w : x + s->fw;
    int h = p->used_h > y + s->fh ? p->used_h : y + s->fh;
    int side = w > h ? w : h;
    double metric = (double)side * side + p->area_weight * w * h;
    if (metric < best->metric)
        *best = (placement){x, y, o, metric};
}

/* The best place for the item (shapes sh[0] upright, sh[1] turned) on p.
 * First a hole inside the used extent (no growth: the first one found,
 * top to bottom, wins); else the place that grows the extent least, among
 * those right of the skyline on every row and those at the bottom. */
static bool find_place(page *p, const shape sh[2], bool many, placement *best)
{
    best->metric = INFINITY;
    /* with many charts, those of one size class take the holes top to
     * bottom: the next starts where the last found one (a hole above it
     * was too small for a chart of its size, and about as small for this
     * one); a new class starts from the top. As xatlas's brute-force
     * packer keeps a start position per size bucket, this keeps thousands
     * of small charts from each searching the whole page, for about a
     * point of efficiency. */
    double area = (double)sh[0].fw * sh[0].fh;
    int size_class = many ? (int)floor(16.0 * log2(area)) : INT32_MIN;
    if (size_class != p->cursor_class || !many) {
        p->cursor_class = size_class;
        p->cursor = 0;
    }
    for (int y = p->cursor; y < p->used_h; y++)
        for (int o = 0; o < 2; o++) {
            const shape *s = &sh[o];
            int limit = p->used_w - s->fw;
            if (limit < 0 || y + s->fh > p->used_h || free_within(p, y + s->widest_row) < s->widest)
                continue;
            /* every row needs a hole as wide as its run somewhere */
            bool maybe = true;
            for (int r = 0; r < s->fh && maybe; r++)
                maybe = free_within(p, y + r) >= s->row_width[r];
            if (!maybe)
                continue;
            int x = leftmost_fit(p, s, y, limit);
            if (x >= 0) {
                consider(p, s, o, x, y, best);
                p->cursor = y;
                return true;
            }
        }
    for (int y = 0; y <= p->used_h; y++)
        for (int o = 0; o < 2; o++) {
            const shape *s = &sh[o];
            int limit = p->size - s->fw;
            if (limit < 0 || y + s->fh > p->size)
                continue;
            int x = past_skyline(p, s, y, limit);
            if (x >= 0)
                consider(p, s, o, x, y, best);
            if (y + s->fh > p->used_h && (x = leftmost_fit(p, s, y, limit)) >= 0)
                consider(p, s, o, x, y, best);
        }
    return best->metric < INFINITY;
}

/* ---- dealing nodes to pages -------------------------------------------------- */

typedef struct packer {
    uw_item *items;
    uint32_t item_count;
    shape (*shapes)[2];
    uint32_t *order;     /* items, largest first */
    uint32_t *node_page; /* per node id (dense), UW_NONE = not dealt */
    uint32_t node_count;
    page *pages;
    uint32_t page_count;
    int pad, size;
    double area_weight; /* the growth measure of this attempt */
} packer;

static page *add_page(packer *k)
{
    page *pg = realloc(k->pages, sizeof *pg * (k->page_count + 1));
    if (!pg)
        return NULL;
    k->pages = pg;
    page *p = &pg[k->page_count];
    memset(p, 0, sizeof *p);
    p->size = k->size;
    p->words = (k->size + 63) / 64;
    p->bits = calloc((size_t)p->words * p->size, sizeof(uint64_t));
    p->cursor_class = INT32_MIN;
    p->area_weight = k->area_weight;
    p->rightmost = malloc(sizeof(int) * p->size);
    p->inner = calloc((size_t)p->size, sizeof(int));
    if (!p->bits || !p->rightmost || !p->inner) {
        free(p->bits);
        free(p->rightmost);
        free(p->inner);
        return NULL;
    }
    for (int y = 0; y < p->size; y++)
        p->rightmost[y] = -1;
    k->page_count++;
    return p;
}

static bool page_add_node(page *p, uint32_t node, double area)
{
    if (p->node_count == p->node_capacity) {
        uint32_t cap = p->node_capacity ? 2 * p->node_capacity : 8;
        uint32_t *n = realloc(p->nodes, sizeof(uint32_t) * cap);
        if (!n)
            return false;
        p->nodes = n;
        p->node_capacity = cap;
    }
    p->nodes[p->node_count++] = node;
    p->planned += area;
    return true;
}

static int cmp_items(const uint32_t *pa, const uint32_t *pb, const packer *k)
{
    uint32_t a = *pa, b = *pb;
    const shape *sa = &k->shapes[a][0], *sb = &k->shapes[b][0];
    double aa = (double)sa->fw * sa->fh, ab = (double)sb->fw * sb->fh;
    if (aa != ab)
        return aa > ab ? -1 : 1;
    if (sa->fh != sb->fh)
        return sa->fh > sb->fh ? -1 : 1;
    return a < b ? -1 : a > b;
}

/* Items largest footprint first (ties: taller, then index). */
static void sort_items(uint32_t *order, uint32_t n, const packer *k)
{
    /* merge sort, stable and O(n log n) */
    uint32_t *tmp = malloc(sizeof(uint32_t) * (n ? n : 1));
    if (!tmp) { /* fall back to insertion sort */
        for (uint32_t i = 1; i < n; i++)
            for (uint32_t j = i; j > 0 && cmp_items(&order[j], &order[j - 1], k) < 0; j--) {
                uint32_t t = order[j];
                order[j] = order[j - 1];
                order[j - 1] = t;
            }
        return;
    }
    for (uint32_t width = 1; width < n; width *= 2) {
        for (uint32_t lo = 0; lo < n; lo += 2 * width) {
            uint32_t mid = lo + width < n ? lo + width : n;
            uint32_t hi = lo + 2 * width < n ? lo + 2 * width : n;
            uint32_t i = lo, j = mid, o = lo;
            while (i < mid && j < hi)
                tmp[o++] = cmp_items(&order[j], &order[i], k) < 0 ? order[j++] : order[i++];
            while (i < mid)
                tmp[o++] = order[i++];
            while (j < hi)
                tmp[o++] = order[j++];
        }
        memcpy(order, tmp, sizeof(uint32_t) * n);
    }
    free(tmp);
}

static void page_extent(packer *k, page *p, uint32_t pi)
{
    p->used_w = p->used_h = 0;
    for (uint32_t i = 0; i < k->item_count; i++) {
        const uw_item *it = &k->items[i];
        if (it->page != pi)
            continue;
        const shape *s = &k->shapes[i][it->turned];
        p->used_w = it->x + s->fw > p->used_w ? it->x + s->fw : p->used_w;
        p->used_h = it->y + s->fh > p->used_h ? it->y + s->fh : p->used_h;
    }
}

/* One attempt: deals the nodes to fresh pages and places every item,
 * largest first, with the growth measure k->area_weight. */
static lx_status place_all(packer *k, uw_item *items, uint32_t item_count,
                           const uw_pack_desc *desc, const double *node_area, uint32_t *too_big,
                           float from, float to)
{
    lx_status st = LX_OK;
    for (uint32_t i = 0; i < item_count; i++)
        items[i].page = UW_NONE;
    /* deal nodes to pages by area, largest node first */
    uint32_t *nodes = malloc(sizeof(uint32_t) * (k->node_count ? k->node_count : 1));
    if (!nodes) {
        st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
        return st;
    }
    uint32_t nn = 0;
    for (uint32_t n = 0; n < k->node_count; n++) {
        k->node_page[n] = UW_NONE;
        if (node_area[n] > 0.0)
            nodes[nn++] = n;
    }
    for (uint32_t i = 1; i < nn; i++) /* insertion sort: node counts are small */
        for (uint32_t j = i;
             j > 0 && (node_area[nodes[j]] > node_area[nodes[j - 1]] ||
                       (node_area[nodes[j]] == node_area[nodes[j - 1]] && nodes[j] < nodes[j - 1]));
             j--) {
            uint32_t t = nodes[j];
            nodes[j] = nodes[j - 1];
            nodes[j - 1] = t;
        }
    double capacity = FILL_ESTIMATE * (double)k->size * k->size;
    for (uint32_t i = 0; i < nn; i++) {
        uint32_t n = nodes[i], p = 0;
        while (p < k->page_count && (desc->page_per_node || (k->pages[p].planned > 0.0 &&
                                                            k->pages[p].planned + node_area[n] >
                                                                capacity)))
            p++;
        if (p == k->page_count && !add_page(k)) {
            free(nodes);
            st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
            return st;
        }
        if (!page_add_node(&k->pages[p], n, node_area[n])) {
            free(nodes);
            st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
            return st;
        }
        k->node_page[n] = p;
    }
    free(nodes);
    /* pack page by page; a node that does not fit moves on */
    uint32_t placed = 0;
    for (uint32_t pi = 0; pi < k->page_count; pi++) {
        for (uint32_t oi = 0; oi < item_count; oi++) {
            uint32_t i = k->order[oi];
            uw_item *it = &items[i];
            if (k->node_page[it->node] != pi || it->page != UW_NONE)
                continue;
            page *p = &k->pages[pi];
            placement best;
            if (find_place(p, k->shapes[i], item_count > MANY_CHARTS, &best)) {
                it->page = pi;
                it->x = best.x;
                it->y = best.y;
                it->dx = k->shapes[i][best.turned].dx;
                it->dy = k->shapes[i][best.turned].dy;
                it->turned = best.turned;
                stamp(p, &k->shapes[i][best.turned], best.x, best.y, true);
                const shape *s = &k->shapes[i][best.turned];
                p->used_w = best.x + s->fw > p->used_w ? best.x + s->fw : p->used_w;
                p->used_h = best.y + s->fh > p->used_h ? best.y + s->fh : p->used_h;
                placed++;
            } else {
                /* the node moves to the next page with all its items */
                uint32_t node = it->node;
                bool alone = true;
                for (uint32_t j = 0; j < p->node_count; j++)
                    alone = alone && p->nodes[j] == node;
                if (alone) {
                    *too_big = node;
                    st = lx_fail(LX_ERR_UNSUPPORTED, "node %u: its charts do not fit in one page",
                                 node);
                    return st;
                }
                for (uint32_t j = 0; j < item_count; j++)
                    if (items[j].node == node && items[j].page == pi) {
                        stamp(p, &k->shapes[j][items[j].turned], items[j].x, items[j].y, false);
                        items[j].page = UW_NONE;
                        placed--;
                    }
                page_extent(k, p, pi);
                p->cursor = 0;
                if (pi + 1 == k->page_count && !add_page(k)) {
                    st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
                    return st;
                }
                p = &k->pages[pi];
                if (!page_add_node(&k->pages[pi + 1], node, node_area[node])) {
                    st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
                    return st;
                }
                k->node_page[node] = pi + 1;
            }
            if (desc->progress && (placed & 63) == 0) {
                float f = from + (to - from) * (float)placed / (float)(item_count ? item_count : 1);
                if (!desc->progress(desc->progress_user, f)) {
                    st = lx_fail(LX_ERR_CANCELLED, "cancelled");
                    return st;
                }
            }
        }
    }
    return st;
}

/* The pages of an attempt: cropped sizes, items renumbered. */
static lx_status crop_pages(packer *k, uw_item *items, uint32_t item_count,
                            lx_unwrap_page **pages_out, uint32_t *page_count_out)
{
    lx_status st = LX_OK;
    /* crop: the outer padding goes (nothing outside a page is sampled) */
    lx_unwrap_page *out = calloc(k->page_count ? k->page_count : 1, sizeof *out);
    if (!out) {
        st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
        return st;
    }
    uint32_t used_pages = 0;
    uint32_t *renumber = malloc(sizeof(uint32_t) * (k->page_count ? k->page_count : 1));
    if (!renumber) {
        free(out);
        st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
        return st;
    }
    for (uint32_t pi = 0; pi < k->page_count; pi++) {
        const page *p = &k->pages[pi];
        renumber[pi] = UW_NONE;
        if (p->used_w == 0)
            continue;
        int w = p->used_w - 2 * k->pad, h = p->used_h - 2 * k->pad;
        w = w < 1 ? 1 : w;
        h = h < 1 ? 1 : h;
        out[used_pages].width = (w + 3) / 4 * 4;
        out[used_pages].height = (h + 3) / 4 * 4;
        renumber[pi] = used_pages++;
    }
    for (uint32_t i = 0; i < item_count; i++) {
        uw_item *it = &items[i];
        it->page = renumber[it->page];
        out[it->page].covered_texels += it->covered;
        out[it->page].chart_count++;
        /* page texel of uv (0, 0): the footprint's corner, less the
         * cropped outer padding, plus the item's own padding */
        it->covered = k->shapes[i][it->turned].covered;
    }
    free(renumber);
    *pages_out = out;
    *page_count_out = used_pages;
    return LX_OK;
}

static void pages_free(packer *k)
{
    for (uint32_t p = 0; p < k->page_count; p++) {
        free(k->pages[p].bits);
        free(k->pages[p].rightmost);
        free(k->pages[p].inner);
        free(k->pages[p].nodes);
    }
    free(k->pages);
    k->pages = NULL;
    k->page_count = 0;
}

/* The most elongated page's long side over its short side. */
static double pages_aspect(const lx_unwrap_page *pages, uint32_t count)
{
    double worst = 1.0;
    for (uint32_t p = 0; p < count; p++) {
        double w = pages[p].width, h = pages[p].height;
        worst = fmax(worst, fmax(w, h) / fmin(w, h));
    }
    return worst;
}

/* Whether an attempt (share of its pages covered, page aspect) beats the
 * best so far: pages within MAX_PAGE_ASPECT first (users of xatlas and
 * Blender's Lightmap Pack expect a near-square page; area-first growth
 * laid zdm2 out as 2808 x 772 for 0.3 points of coverage), then the
 * larger share; among elongated ones the squarer. Ties keep the earlier. */
static bool better_attempt(double share, double aspect, double best_share, double best_aspect)
{
    bool square = aspect <= MAX_PAGE_ASPECT, best_square = best_aspect <= MAX_PAGE_ASPECT;
    if (square != best_square)
        return square;
    return square ? share > best_share : aspect < best_aspect;
}

lx_status uw_pack(uw_item *items, uint32_t item_count, const uw_pack_desc *desc,
                  lx_unwrap_page **pages_out, uint32_t *page_count_out, uint32_t *too_big)
{
    *too_big = UW_NONE;
    *pages_out = NULL;
    *page_count_out = 0;
    packer k = {0};
    k.items = items;
    k.item_count = item_count;
    k.pad = desc->padding;
    k.size = desc->atlas_size + 2 * desc->padding;
    lx_status st = LX_OK;
    k.shapes = calloc(item_count ? item_count : 1, sizeof *k.shapes);
    k.order = malloc(sizeof(uint32_t) * (item_count ? item_count : 1));
    uint32_t node_count = 0;
    for (uint32_t i = 0; i < item_count; i++)
        node_count = items[i].node + 1 > node_count ? items[i].node + 1 : node_count;
    k.node_count = node_count;
    k.node_page = malloc(sizeof(uint32_t) * (node_count ? node_count : 1));
    double *node_area = calloc(node_count ? node_count : 1, sizeof(double));
    if (!k.shapes || !k.order || !k.node_page || !node_area) {
        st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
        goto done;
    }
    int failed = 0;
    int threads = lx_thread_count(desc->threads);
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads) reduction(| : failed)
    for (uint32_t i = 0; i < item_count; i++) {
        bool ok = make_shape(&items[i], false, k.pad, &k.shapes[i][0]) &&
                  make_shape(&items[i], true, k.pad, &k.shapes[i][1]);
        failed |= !ok;
    }
    if (failed) {
        st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
        goto done;
    }
    for (uint32_t i = 0; i < item_count; i++) {
        const shape *s = &k.shapes[i][0], *t = &k.shapes[i][1];
        if (!(s->fw <= k.size && s->fh <= k.size) && !(t->fw <= k.size && t->fh <= k.size)) {
            /* too big either way up: the caller scales the node down */
            *too_big = items[i].node;
            st = lx_fail(LX_ERR_UNSUPPORTED,
                         "node %u: a chart of %dx%d texels is larger than a page", items[i].node,
                         s->cw, s->ch);
            goto done;
        }
        node_area[items[i].node] += (double)s->fw * s->fh;
        items[i].page = UW_NONE;
        items[i].covered = s->covered;
        k.order[i] = i;
    }
    sort_items(k.order, item_count, &k);
    /* Attempts with growth measures from square-first to area-first; the
     * near-square one covering the largest share of its pages wins (ties:
     * the earlier; better_attempt). Each is deterministic, so the result
     * is too. */
    static const double weights[] = {1.0, 4.0, 1000.0};
    const int attempts = (int)(sizeof weights / sizeof weights[0]);
    uw_item *best_items = NULL;
    lx_unwrap_page *best_pages = NULL;
    uint32_t best_count = 0;
    double best_share = -1.0, best_aspect = INFINITY;
    for (int a = 0; a < attempts && st == LX_OK; a++) {
        pages_free(&k);
        k.area_weight = weights[a];
        float span = (desc->progress_to - desc->progress_from) / (float)attempts;
        float from = desc->progress_from + span * (float)a;
        st = place_all(&k, items, item_count, desc, node_area, too_big, from, from + span);
        lx_unwrap_page *pages = NULL;
        uint32_t count = 0;
        if (st == LX_OK)
            st = crop_pages(&k, items, item_count, &pages, &count);
        if (st != LX_OK) {
            /* a node too big for a page under one measure may fit under
             * another; with nothing placed yet it is refused */
            if (st == LX_ERR_UNSUPPORTED && best_pages && a + 1 < attempts) {
                st = LX_OK;
                *too_big = UW_NONE;
            }
            continue;
        }
        double covered = 0.0, texels = 0.0;
        for (uint32_t p = 0; p < count; p++) {
            covered += pages[p].covered_texels;
            texels += (double)pages[p].width * pages[p].height;
        }
        double share = texels > 0.0 ? covered / texels : 0.0;
        double aspect = pages_aspect(pages, count);
        if (better_attempt(share, aspect, best_share, best_aspect)) {
            if (!best_items)
                best_items = malloc(sizeof *best_items * (item_count ? item_count : 1));
            if (!best_items) {
                free(pages);
                st = lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
                break;
            }
            memcpy(best_items, items, sizeof *items * item_count);
            free(best_pages);
            best_pages = pages;
            best_count = count;
            best_share = share;
            best_aspect = aspect;
        } else {
            free(pages);
        }
    }
    if (st == LX_OK && best_pages) {
        memcpy(items, best_items, sizeof *items * item_count);
        *pages_out = best_pages;
        *page_count_out = best_count;
        *too_big = UW_NONE;
    } else {
        free(best_pages);
    }
    free(best_items);
done:
    if (k.shapes)
        for (uint32_t i = 0; i < item_count; i++) {
            shape_free(&k.shapes[i][0]);
            shape_free(&k.shapes[i][1]);
        }
    free(k.shapes);
    free(k.order);
    free(k.node_page);
    free(node_area);
    pages_free(&k);
    return st;
}
