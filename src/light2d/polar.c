/* Polar shadow maps of 2D lights (seed 003, "2D lighting system tutorial
 * part 4": the casters around a light unwrapped into a column per ray and
 * each column reduced to its nearest occluder). On the CPU the unwrap and
 * the reduction are one step: every boundary caster pixel under the light's
 * reach is rasterised into the angular bins its square covers, keeping the
 * nearest distance per bin (only boundary pixels can be the first caster a
 * ray meets). A second pass keeps where the first caster run of each ray
 * ends, so casters can be lit on their face. Soft shadows: in a ray's hard
 * shadow the map is filtered along the angle (percentage-closer filtering)
 * over a window that grows with the distance behind the occluder, as a
 * light of radius `softness` predicts; before the occluder, each side of
 * the light is seen up to the horizon the occluders beside the ray make
 * (the tangent from the point to them in angle and inverse distance, the
 * way horizon maps bound a height field). Sparse tables of the window
 * minimum and maximum skip the filter wherever the window is wholly lit
 * or wholly shadowed. */
#include "l2_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define L2_FAR 1e30f
#define L2_PI 3.14159265358979323846

#ifdef L2_GATHER
#include <immintrin.h>
#endif
/* Filter taps beyond which a penumbra window is sampled, not summed. */
#define L2_MAX_TAPS 32

/* Pseudo-angle in [0, 8] of the direction (dx, dy) (not both zero), see
 * l2_polar; *u gets the slope on its face (dp/dangle = 1 + u^2). */
static inline float pseudo_angle(float dx, float dy, float *u)
{
    float ax = fabsf(dx), ay = fabsf(dy);
    if (ax >= ay) {
        if (ax == 0.0f) {
            *u = 0.0f;
            return 0.0f;
        }
        float t = dy / ax;
        *u = t;
        return dx > 0.0f ? 1.0f + t : 5.0f - t;
    }
    float t = dx / ay;
    *u = t;
    return dy > 0.0f ? 3.0f - t : 7.0f + t;
}

static inline int wrap(int i, int n)
{
    return i < 0 ? i + n : (i >= n ? i - n : i);
}

void l2_polar_free(l2_polar *pm)
{
    free(pm->occ);
    free(pm->ex);
    free(pm->inv_ux);
    free(pm->inv_uy);
    free(pm->lit);
    free(pm->occx);
    free(pm->hz);
    free(pm->theta);
    free(pm->exits);
    free(pm->qocc);
    free(pm->gap);
    free(pm->tmin);
    free(pm->tmax);
    memset(pm, 0, sizeof *pm);
}

/* The pseudo-angles [lo, hi] a square spans from its corners' p[4]; a
 * square that straddles p = 0 gets hi (and maybe lo) past 8. */
static void corner_span(const float p[4], float *lo_out, float *hi_out)
{
    float lo = p[0], hi = p[0];
    for (int k = 1; k < 4; k++) {
        lo = l2_min(lo, p[k]);
        hi = l2_max(hi, p[k]);
    }
    if (hi - lo > 4.0f) { /* the square straddles p = 0 */
        lo = 8.0f;
        hi = 0.0f;
        for (int k = 0; k < 4; k++) {
            float q = p[k] < 4.0f ? p[k] + 8.0f : p[k];
            lo = l2_min(lo, q);
            hi = l2_max(hi, q);
        }
    }
    *lo_out = lo;
    *hi_out = hi;
}

/* The bins [b0, b1] of a square from its corners' pseudo-angles p[4]
 * (the second half of square_bins). */
static void corner_bins(const l2_polar *pm, const float p[4], int *b0, int *b1)
{
    float lo, hi;
    corner_span(p, &lo, &hi);
    int n = pm->n;
    int a = (int)(lo * pm->bins_per_p), b = (int)(hi * pm->bins_per_p);
    if (a >= n) {
        a -= n;
        b -= n;
    }
    if (b > a + n - 1)
        b = a + n - 1;
    *b0 = a;
    *b1 = b;
}

/* The bins [b0, b1] (b1 may pass n: wrap) the square [ax,bx] x [ay,by]
 * (relative to the light, not containing it) covers. */
static void square_bins(const l2_polar *pm, float ax, float bx, float ay, float by, int *b0,
                        int *b1)
{
    float u;
    float p[4] = {pseudo_angle(ax, ay, &u), pseudo_angle(bx, ay, &u), pseudo_angle(ax, by, &u),
                  pseudo_angle(bx, by, &u)};
    corner_bins(pm, p, b0, b1);
}

/* Rows of n floats in each of the sparse tables tmin and tmax: the
 * levels, and at least the 8 open_gaps borrows tmax for as scratch (8
 * ints a ray) before the tables are built; a small light has fewer
 * levels (a radius-3 light overran tmax, found by fuzz_light2d_json). */
static uint64_t table_rows(uint64_t levels)
{
    return levels > 8 ? levels : 8;
}

static lx_status reserve(l2_polar *pm, int n, int levels, int depth_levels)
{
    size_t g = (size_t)n * depth_levels;
    if (g > (size_t)pm->gap_capacity) {
        float *a = realloc(pm->gap, g * sizeof *a);
        if (!a)
            return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for a polar map of %d rays", n);
        pm->gap = a;
        pm->gap_capacity = (int)g;
    }
    if (n > pm->capacity) {
        float *occ = realloc(pm->occ, (size_t)n * sizeof *occ);
        if (occ)
            pm->occ = occ;
        float *ex = realloc(pm->ex, (size_t)n * sizeof *ex);
        if (ex)
            pm->ex = ex;
        float *iux = realloc(pm->inv_ux, (size_t)n * sizeof *iux);
        if (iux)
            pm->inv_ux = iux;
        float *iuy = realloc(pm->inv_uy, (size_t)n * sizeof *iuy);
        if (iuy)
            pm->inv_uy = iuy;
        pm->ray_n = 0;
        float *lit = realloc(pm->lit, (size_t)n * sizeof *lit);
        if (lit)
            pm->lit = lit;
        float *qocc = realloc(pm->qocc, (size_t)n * sizeof *qocc);
        if (qocc)
            pm->qocc = qocc;
        float *occx = realloc(pm->occx, (size_t)n * 3 * sizeof *occx);
        if (occx)
            pm->occx = occx;
        float *th = realloc(pm->theta, ((size_t)n + 1) * sizeof *th);
        if (th)
            pm->theta = th;
        pm->theta_n = 0;
        float *hz = realloc(pm->hz, (size_t)n * 2 * L2_HZ * sizeof *hz);
        if (hz)
            pm->hz = hz;
        if (!occ || !ex || !iux || !iuy || !lit || !qocc || !occx || !th || !hz)
            return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for a polar map of %d rays", n);
        pm->capacity = n;
    }
    size_t t = (size_t)n * (size_t)table_rows((uint64_t)levels);
    if (t > (size_t)pm->table_capacity) {
        float *a = realloc(pm->tmin, t * sizeof *a);
        if (a)
            pm->tmin = a;
        float *b = realloc(pm->tmax, t * sizeof *b);
        if (b)
            pm->tmax = b;
        if (!a || !b)
            return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for a polar map of %d rays", n);
        pm->table_capacity = (int)t;
    }
    return LX_OK;
}

/* The sampled lines' directions, pm->inv_ux and inv_uy: ray b's line has
 * p = (b + 0.5) / bpp, on the face f = floor(p / 2) the direction (1, p -
 * 1), (3 - p, 1), (-1, 5 - p) or (p - 7, -1), normalised. With n a
 * multiple of 8 no line lies on an axis or a diagonal (p would be a whole
 * number). They depend on n alone. */
static void ray_dirs(l2_polar *pm)
{
    int n = pm->n;
    double bpp = (double)n / 8.0;
    for (int b = 0; b < n; b++) {
        double p = (b + 0.5) / bpp, x, y;
        int f = (int)floor(p * 0.5);
        if (f <= 0) {
            x = 1.0;
            y = p - 1.0;
        } else if (f == 1) {
            x = 3.0 - p;
            y = 1.0;
        } else if (f == 2) {
            x = -1.0;
            y = 5.0 - p;
        } else {
            x = p - 7.0;
            y = -1.0;
        }
        double len = sqrt(x * x + y * y);
        pm->inv_ux[b] = (float)(len / x);
        pm->inv_uy[b] = (float)(len / y);
    }
    pm->ray_n = n;
}

/* The ray boundaries' true angles, theta[b] for b in [0, n] (radians,
 * theta[n] = 2 pi): on the face centred at pseudo-angle 2f + 1 the angle is
 * f pi/2 + atan(p - 2f - 1). They depend on n alone. */
static void ray_angles(l2_polar *pm)
{
    int n = pm->n;
    double bpp = (double)n / 8.0;
    for (int b = 0; b <= n; b++) {
        double p = b / bpp;
        int f = (int)floor(p * 0.5);
        f = f > 3 ? 3 : f;
        pm->theta[b] = (float)(f * (L2_PI / 2.0) + atan(p - (2.0 * f + 1.0)));
    }
    pm->theta_n = n;
}

/* The lit side's horizons (l2_polar.hz and .lit). The line from a point
 * at angle a and inverse distance w towards the point of the light t x s
 * to its side (t in [0, 1], s the softness) runs, in the small-angle
 * limit, through the angles a + t s (w' - w) at inverse distances w' > w.
 * Counting everything at or beyond a ray's occluder as blocked (its
 * caster and its shadow), ray j at an angle g past the point (inverse
 * occluder distance q_j > w) blocks the t >= g / (s (q_j - w)). So the
 * side's light is visible for t below T = min_j g_j / (s (q_j - w)), and
 * T <= t exactly when w <= L_t = max_j (q_j - g_j / (t s)): a maximum over
 * the rays of that side, kept for the L2_HZ levels of r = 1/t of
 * hz_r. Per ray c, hz[c][k] holds L for a point at c's lower boundary
 * looking up (rays after c, once round) and hz[c][L2_HZ + k] for a point
 * at its upper boundary looking down; a point inside the ray adds its
 * angle from that boundary times r_k / s. Summed in double from the
 * absolute angles, stored relative to the ray (no cancellation). */
static const float hz_r[L2_HZ] = {1.0f, 1.5f, 2.0f, 3.0f, 4.0f, 6.0f, 8.0f, 16.0f};

static inline double dmax(double a, double b)
{
    return a > b ? a : b;
}

L2_CLONES static void horizons(l2_polar *pm, float s)
{
    int n = pm->n;
    const float *qo = pm->qocc, *th = pm->theta;
    const double two_pi = 2.0 * L2_PI;
    double inv[L2_HZ], run[L2_HZ];
    for (int k = 0; k < L2_HZ; k++) {
        inv[k] = (double)hz_r[k] / (double)s;
        pm->hz_inv[k] = (float)inv[k];
    }
    /* looking up: the rays after c (c + 1 .. n - 1 as they are, then 0 ..
     * c - 1 a turn later) */
    for (int k = 0; k < L2_HZ; k++)
        run[k] = -INFINITY;
    for (int j = 0; j < n; j++) /* the wrapped part, a prefix maximum */
        for (int k = 0; k < L2_HZ; k++) {
            float *h = pm->hz + (size_t)j * 2 * L2_HZ;
            h[k] = (float)run[k]; /* rays 0 .. j - 1 a turn later */
            run[k] = dmax(run[k], qo[j] - (th[j] + two_pi) * inv[k]);
        }
    for (int k = 0; k < L2_HZ; k++)
        run[k] = -INFINITY;
    for (int c = n - 1; c >= 0; c--) {
        float *h = pm->hz + (size_t)c * 2 * L2_HZ;
        for (int k = 0; k < L2_HZ; k++) {
            double m = dmax(run[k], (double)h[k]) + th[c] * inv[k];
            run[k] = dmax(run[k], qo[c] - th[c] * inv[k]);
            h[k] = (float)m;
        }
    }
    /* looking down: rays c - 1 .. 0, then n - 1 .. c + 1 a turn earlier,
     * from the upper boundaries theta[j + 1] */
    for (int k = 0; k < L2_HZ; k++)
        run[k] = -INFINITY;
    for (int j = n - 1; j >= 0; j--)
        for (int k = 0; k < L2_HZ; k++) {
            float *h = pm->hz + (size_t)j * 2 * L2_HZ + L2_HZ;
            h[k] = (float)run[k];
            run[k] = dmax(run[k], qo[j] + (th[j + 1] - two_pi) * inv[k]);
        }
    for (int k = 0; k < L2_HZ; k++)
        run[k] = -INFINITY;
    for (int c = 0; c < n; c++) {
        float *h = pm->hz + (size_t)c * 2 * L2_HZ + L2_HZ;
        for (int k = 0; k < L2_HZ; k++) {
            double m = dmax(run[k], (double)h[k]) - th[c + 1] * inv[k];
            run[k] = dmax(run[k], qo[c] + th[c + 1] * inv[k]);
            h[k] = (float)m;
        }
    }
    /* lit[c]: no point of ray c farther than 1 / lit[c] sees any of the
     * light blocked (L_1 at the far boundary of each side), nor lies
     * behind c's own occluder */
    for (int c = 0; c < n; c++) {
        const float *h = pm->hz + (size_t)c * 2 * L2_HZ;
        float wid = (th[c + 1] - th[c]) * pm->hz_inv[0];
        float own = pm->occ[c] >= L2_FAR ? 0.0f : 1.0f / l2_max(pm->occ[c], 1e-6f);
        pm->lit[c] = l2_max(own, l2_max(h[0], h[L2_HZ]) + wid);
    }
}

/* gap[lv] for every depth level: per ray, the whole bins between it and
 * the nearest ray whose occluder is at the level's distance or beyond
 * (65535 when none): a 1D distance transform around the circle, the
 * bins since the last open ray counted once round each way (twice round,
 * so that the count wraps; whole numbers, exact). Eight levels at a time
 * on vector lanes; fw (8 n ints) keeps the forward counts. */
typedef float l2_v8f __attribute__((vector_size(32)));
typedef int32_t l2_v8i __attribute__((vector_size(32)));
L2_CLONES static void open_gaps(l2_polar *pm, int32_t *fw)
{
    int n = pm->n;
    const float *occ = pm->occ;
    for (int l0 = 0; l0 < pm->depth_levels; l0 += 8) {
        /* the levels' distances, as l2_depth_level counts: 2^(lv/2) exactly
         * for even lv, the float just at or above 2^(lv/2) sqrt(2) for odd;
         * lanes past the last level never open */
        l2_v8f thr;
        for (int j = 0; j < 8; j++) {
            int lv = l0 + j;
            union {
                uint32_t u;
                float f;
            } t = {(uint32_t)((lv >> 1) + 127) << 23 | ((lv & 1) ? 0x3504f3u : 0u)};
            thr[j] = lv < pm->depth_levels ? t.f * L2_DEPTH0 : INFINITY;
        }
        const l2_v8i one = {1, 1, 1, 1, 1, 1, 1, 1};
        l2_v8i run = one * (1 << 22);
        for (int lap = 0; lap < 2; lap++)
            for (int i = 0; i < n; i++) {
                l2_v8f o = {occ[i], occ[i], occ[i], occ[i], occ[i], occ[i], occ[i], occ[i]};
                l2_v8i open = o >= thr;
                run = (run + one) & ~open;
                if (lap)
                    memcpy(fw + (size_t)i * 8, &run, sizeof run);
            }
        run = one * (1 << 22);
        int top = pm->depth_levels - l0 < 8 ? pm->depth_levels - l0 : 8;
        for (int lap = 0; lap < 2; lap++)
            for (int i = n - 1; i >= 0; i--) {
                l2_v8f o = {occ[i], occ[i], occ[i], occ[i], occ[i], occ[i], occ[i], occ[i]};
                l2_v8i open = o >= thr;
                run = (run + one) & ~open;
                if (!lap)
                    continue;
                l2_v8i f;
                memcpy(&f, fw + (size_t)i * 8, sizeof f);
                l2_v8i lt = f < run;
                l2_v8i m = (f & lt) | (run & ~lt);
                /* the nearer of the two, less the bin itself */
                m = m - one;
                l2_v8i neg = m < 0 * one;
                m = m & ~neg;
                l2_v8i big = m > one * 65535;
                m = (m & ~big) | ((one * 65535) & big);
                for (int j = 0; j < top; j++)
                    pm->gap[(size_t)(l0 + j) * n + i] = (float)m[j];
            }
    }
}

/* As reserve() below takes them: per ray the occluders, exits, lit
 * flags, their quantized copy (4 floats), the sampled line's direction
 * (2), three occluder coordinates,
 * an angle and 2 L2_HZ horizons; the min/max tables of `levels` levels
 * and the gaps of `depth_levels`. */
uint64_t l2_polar_bytes(const lx_light2d *ctx, const lx_light2d_light *l)
{
    uint64_t n = (uint64_t)l2_ray_count(ctx, l->radius);
    uint64_t levels = 0;
    while (((uint64_t)1 << levels) <= n)
        levels++;
    uint64_t depth_levels =
        l->softness > 0.0f ? (uint64_t)l2_depth_level(l->radius + 2.0f, 1 << 10) + 1 : 0;
    uint64_t floats =
        n * (4 + 2 + 3 + 1 + 2 * L2_HZ) + 1 + n * table_rows(levels) * 2 + n * depth_levels;
    return floats * sizeof(float);
}

/* The rays [i0, i1] (no wrap) whose sampled lines cross the square
 * [ax, bx] x [ay, by] (relative to the light, which lies outside it):
 * occ[i] becomes at most the distance along line i to where it enters the
 * square, the larger of its distances to the near x and near y sides
 * (slabs). A loop without branches, so that it vectorizes. */
static void enter_run(float *restrict occ, const float *restrict iux, const float *restrict iuy,
                      int i0, int i1, float ax, float bx, float ay, float by)
{
    for (int i = i0; i <= i1; i++) {
        float tx = l2_min(ax * iux[i], bx * iux[i]);
        float ty = l2_min(ay * iuy[i], by * iuy[i]);
        occ[i] = l2_min(occ[i], l2_max(tx, ty));
    }
}

/* The rays [i0, i1] (no wrap) whose sampled lines cross the boundary
 * pixel whose square starts at (ax, ay) (relative to the light, side 1):
 * where line i leaves it, through the x side when its far x slab ends
 * first, else the y side; when that side is free (free: L2_FREE_*) and the
 * point lies at or beyond the ray's occluder, ex[i] becomes at most its
 * distance. */
static void leave_run(const float *restrict occ, float *restrict ex, const float *restrict iux,
                      const float *restrict iuy, int i0, int i1, float ax, float ay,
                      uint8_t free_sides)
{
    float bx = ax + 1.0f, by = ay + 1.0f;
    bool right = free_sides & L2_FREE_RIGHT, left = free_sides & L2_FREE_LEFT;
    bool down = free_sides & L2_FREE_DOWN, up = free_sides & L2_FREE_UP;
    for (int i = i0; i <= i1; i++) {
        float tx = l2_max(ax * iux[i], bx * iux[i]);
        float ty = l2_max(ay * iuy[i], by * iuy[i]);
        bool xs = tx <= ty;
        float t = xs ? tx : ty;
        bool open = xs ? (iux[i] > 0.0f ? right : left) : (iuy[i] > 0.0f ? down : up);
        if (open && t >= occ[i] && t < ex[i])
            ex[i] = t;
    }
}

lx_status l2_polar_build(const lx_light2d *ctx, l2_prep *p)
{
    const lx_light2d_light *l = &p->l;
    l2_polar *pm = &p->polar;
    int n = l2_ray_count(ctx, l->radius);
    bool soft = l->softness > 0.0f;
    int levels = 0;
    while ((1 << levels) <= n)
        levels++;
    /* depth levels up to the farthest shaded distance, the radius */
    int depth_levels = soft ? l2_depth_level(l->radius + 2.0f, 1 << 10) + 1 : 0;
    lx_status st = reserve(pm, n, levels, depth_levels);
    if (st != LX_OK)
        return st;
    pm->n = n;
    pm->levels = levels;
    pm->depth_levels = depth_levels;
    pm->bins_per_p = (float)n / 8.0f;
    float *occ = pm->occ, *ex = pm->ex;
    for (int b = 0; b < n; b++) {
        occ[b] = L2_FAR;
        ex[b] = L2_FAR;
    }
    float lx = l->x, ly = l->y, r = l->radius, r2 = r * r;
    int tx0 = (int)fmax(0.0, floor((l->x - r - 1.0) / L2_TILE));
    int ty0 = (int)fmax(0.0, floor((l->y - r - 1.0) / L2_TILE));
    int tx1 = (int)fmin(ctx->tiles_x - 1, floor((l->x + r + 1.0) / L2_TILE));
    int ty1 = (int)fmin(ctx->tiles_y - 1, floor((l->y + r + 1.0) / L2_TILE));
    bool face = !l->self_shadow;
    if (pm->ray_n != n)
        ray_dirs(pm);
    const float *iux = pm->inv_ux, *iuy = pm->inv_uy;
    float bpp = pm->bins_per_p;
    /* the boundary pixels, listed with their rays for the second pass
     * (where rays leave their caster run; at most every pixel of the
     * tiles) */
    size_t most = 0;
    if (face)
        for (int ty = ty0; ty <= ty1; ty++)
            for (int tx = tx0; tx <= tx1; tx++) {
                size_t t = (size_t)ty * ctx->tiles_x + tx;
                most += ctx->tile_start[t + 1] - ctx->tile_start[t];
            }
    if (most > pm->exit_capacity) {
        l2_exit *a = realloc(pm->exits, most * sizeof *a);
        if (!a)
            return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for a polar map of %d rays", n);
        pm->exits = a;
        pm->exit_capacity = most;
    }
    size_t exits = 0;
    for (int ty = ty0; ty <= ty1; ty++)
        for (int tx = tx0; tx <= tx1; tx++) {
            size_t t = (size_t)ty * ctx->tiles_x + tx;
            for (uint32_t e = ctx->tile_start[t]; e < ctx->tile_start[t + 1]; e++) {
                const l2_edge *ed = &ctx->edges[e];
                float ax = (float)ed->x - lx, bx = ax + 1.0f;
                float ay = (float)ed->y - ly, by = ay + 1.0f;
                float nx = ax > 0.0f ? ax : (bx < 0.0f ? -bx : 0.0f);
                float ny = ay > 0.0f ? ay : (by < 0.0f ? -by : 0.0f);
                float dn2 = nx * nx + ny * ny;
                if (dn2 >= r2)
                    continue;
                bool inside = nx == 0.0f && ny == 0.0f;
                /* the rays whose sampled line crosses the square: those
                 * whose middle p lies in the square's span */
                int c0 = 0, c1 = n - 1;
                if (!inside) {
                    float u, pc[4] = {pseudo_angle(ax, ay, &u), pseudo_angle(bx, ay, &u),
                                      pseudo_angle(ax, by, &u), pseudo_angle(bx, by, &u)};
                    float lo, hi;
                    corner_span(pc, &lo, &hi);
                    c0 = (int)ceilf(lo * bpp - 0.5f);
                    c1 = (int)floorf(hi * bpp - 0.5f);
                    if (c0 >= n) {
                        c0 -= n;
                        c1 -= n;
                    }
                    c1 = c1 < c0 + n - 1 ? c1 : c0 + n - 1;
                }
                bool sampled = c0 <= c1;
                if (inside) {
                    for (int i = 0; i < n; i++)
                        occ[i] = 0.0f;
                } else if (sampled) {
                    /* each line's distance to where it enters the square */
                    int e0 = c1 < n ? c1 : n - 1;
                    enter_run(occ, iux, iuy, c0, e0, ax, bx, ay, by);
                    if (c1 >= n)
                        enter_run(occ, iux, iuy, 0, c1 - n, ax, bx, ay, by);
                } else {
                    /* a square between two sampled lines (only where rays
                     * are farther apart than a pixel: a fixed
                     * polar_resolution) still blocks the rays it touches,
                     * from its nearest point, so no caster falls between
                     * rays */
                    square_bins(pm, ax, bx, ay, by, &c0, &c1);
                    float dn = sqrtf(dn2);
                    for (int b = c0; b <= c1; b++) {
                        int i = b >= n ? b - n : b;
                        occ[i] = l2_min(occ[i], dn);
                    }
                }
                if (!face)
                    continue;
                l2_exit *ev = &pm->exits[exits];
                *ev = (l2_exit){c0, c1, ax, ay, 0.0f, ed->free, sampled || inside};
                if (!ev->sampled) {
                    /* such a square ends the runs of all its rays at its
                     * far corner where it has a free side away from the
                     * light */
                    float cx = ax + 0.5f, cy = ay + 0.5f;
                    bool exit = ((ed->free & L2_FREE_RIGHT) && cx > 0.0f) ||
                                ((ed->free & L2_FREE_LEFT) && cx < 0.0f) ||
                                ((ed->free & L2_FREE_DOWN) && cy > 0.0f) ||
                                ((ed->free & L2_FREE_UP) && cy < 0.0f);
                    if (!exit)
                        continue;
                    float fx = l2_max(ax * ax, bx * bx), fy = l2_max(ay * ay, by * by);
                    ev->df = sqrtf(fx + fy);
                }
                exits++;
            }
        }
    /* where the first caster run of each ray ends: the nearest point at or
     * beyond the ray's occluder where its line leaves a boundary pixel
     * through a free side */
    for (size_t x = 0; x < exits; x++) {
        const l2_exit *ev = &pm->exits[x];
        if (ev->sampled) {
            int e0 = ev->b1 < n ? ev->b1 : n - 1;
            leave_run(occ, ex, iux, iuy, ev->b0, e0, ev->ax, ev->ay, ev->free);
            if (ev->b1 >= n)
                leave_run(occ, ex, iux, iuy, 0, ev->b1 - n, ev->ax, ev->ay, ev->free);
            continue;
        }
        float df = ev->df;
        for (int b = ev->b0; b <= ev->b1; b++) {
            int i = b >= n ? b - n : b;
            if (df >= occ[i] && df < ex[i])
                ex[i] = df;
        }
    }
    /* a light inside a caster pixel that is not on a boundary */
    int ix = (int)floorf(lx), iy = (int)floorf(ly);
    if (ix >= 0 && iy >= 0 && ix < ctx->width && iy < ctx->height &&
        ctx->caster[(size_t)iy * ctx->width + ix])
        for (int b = 0; b < n; b++)
            occ[b] = 0.0f;
    if (soft) {
        if (pm->theta_n != n)
            ray_angles(pm);
        for (int i = 0; i < n; i++)
            pm->qocc[i] = 1.0f / l2_max(occ[i], 0.5f);
        horizons(pm, l->softness);
        /* scratch: the sparse table (table_rows x n >= 8 n floats) */
        open_gaps(pm, (int32_t *)pm->tmax);
    }
    for (int rep = 0; rep < 3; rep++)
        memcpy(pm->occx + (size_t)rep * n, occ, (size_t)n * sizeof *occ);
    memcpy(pm->tmin, occ, (size_t)n * sizeof *occ);
    memcpy(pm->tmax, occ, (size_t)n * sizeof *occ);
    for (int k = 1; k < levels; k++) {
        const float *a = pm->tmin + (size_t)(k - 1) * n, *b = pm->tmax + (size_t)(k - 1) * n;
        float *c = pm->tmin + (size_t)k * n, *d = pm->tmax + (size_t)k * n;
        int h = 1 << (k - 1), m = n - h > 0 ? n - h : 0;
        /* without wrapping (so that it vectorizes), then the wrapped tail */
        for (int i = 0; i < m; i++) {
            c[i] = l2_min(a[i], a[i + h]);
            d[i] = l2_max(b[i], b[i + h]);
        }
        for (int i = m; i < n; i++) {
            int j = (i + h) % n;
            c[i] = l2_min(a[i], a[j]);
            d[i] = l2_max(b[i], b[j]);
        }
    }
    return LX_OK;
}

/* Minimum (or maximum) of occ over bins [lo, hi], hi - lo < n. */
static inline float range_query(const l2_polar *pm, const float *table, int lo, int hi, bool max)
{
    int n = pm->n;
    int len = hi - lo + 1;
    int k = 31 - __builtin_clz((unsigned)len);
    const float *t = table + (size_t)k * n;
    /* windows are under n rays and centred in [0, n]: one wrap at most,
     * and most windows need none */
    int a = lo, b = hi - (1 << k) + 1;
    if (lo < 0 || hi >= n) {
        a = wrap(a, n);
        b = wrap(b, n);
    }
    return max ? l2_max(t[a], t[b]) : l2_min(t[a], t[b]);
}

#ifdef L2_GATHER
/* The sampled filter's taps with AVX2 gathers, 8 at a time: the same
 * floats (i x step, then + base; truncated) and the same comparisons as
 * the scalar loop, so the same count. */
__attribute__((target("avx2"))) static int taps_gather(const float *occx, float base, float step,
                                                       float d)
{
    const __m256 lane = _mm256_setr_ps(0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f);
    const __m256 vb = _mm256_set1_ps(base), vs = _mm256_set1_ps(step), vd = _mm256_set1_ps(d);
    int lit = 0;
    for (int i = 0; i < L2_MAX_TAPS; i += 8) {
        __m256 t = _mm256_add_ps(_mm256_set1_ps((float)i), lane);
        __m256i idx = _mm256_cvttps_epi32(_mm256_add_ps(vb, _mm256_mul_ps(t, vs)));
        __m256 o = _mm256_i32gather_ps(occx, idx, 4);
        lit += __builtin_popcount((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(o, vd, _CMP_GE_OQ)));
    }
    return lit;
}
#endif

/* floor(x) for |x| < 2^31 in the clones of the filter and the search:
 * one rounding instruction where the clone's target has SSE4.1 (a call
 * to floorf in the default clone); the same value as l2_floor. */
static inline int floor_clone(float x)
{
    return (int)__builtin_floorf(x);
}

/* Fraction of the window [c - k, c + k] (in bins) whose rays reach past
 * d; reaches: the caller expects a ray of the window (its own) to reach
 * past d, so the shortcut for windows where none does (which gives the
 * same 0 as the taps would) is not worth its range query. */
static inline float filter(const l2_polar *pm, float c, float k, float d, bool reaches)
{
    int n = pm->n;
    float lo = c - k, hi = c + k;
    int b0 = floor_clone(lo), b1 = floor_clone(hi);
    /* (no ray of the window reaches past d: no light; the callers' windows
     * always hold a ray that does not, so the filter never gives 1 from
     * the window's minimum alone) */
    if (!reaches && range_query(pm, pm->tmax, b0, b1, true) < d)
        return 0.0f;
    const float *occ = pm->occx + n; /* b in [-n, 2n) */
    if (b1 - b0 + 1 <= L2_MAX_TAPS) {
        /* the whole rays inside counted (a loop that vectorizes), the two
         * end rays by the part of them in the window */
        if (b0 == b1)
            return occ[b0] >= d ? 1.0f : 0.0f;
        int inside = 0;
        for (int b = b0 + 1; b < b1; b++)
            inside += occ[b] >= d;
        float lit = (float)inside + (occ[b0] >= d ? (float)(b0 + 1) - lo : 0.0f) +
                    (occ[b1] >= d ? hi - (float)b1 : 0.0f);
        return lit / (hi - lo);
    }
    /* taps at the centres of L2_MAX_TAPS equal parts */
    /* from the start of occx (lo + n > 0: c >= 0, k < n/2), where
     * truncation floors */
    float step = (hi - lo) / L2_MAX_TAPS;
    float base = lo + 0.5f * step + (float)n;
#ifdef L2_GATHER
    if (l2_gather_ok())
        return (float)taps_gather(pm->occx, base, step, d) / L2_MAX_TAPS;
#endif
    int lit = 0;
    for (int i = 0; i < L2_MAX_TAPS; i++)
        lit += pm->occx[(int)(base + (float)i * step)] >= d;
    return (float)lit / L2_MAX_TAPS;
}

/* The share of one side of the light that a point sees (horizons):
 * L_k = h[k] + off x inv[k] falls with k; T lies between the r = 1/t of
 * the last level at or above w and the first below it, interpolated
 * linearly in r (exact where one ray sets both levels: L is then linear in
 * r), or extrapolated past the last level. */
static inline float side_visible(const float *h, const float *inv, float off, float w)
{
    float L[L2_HZ];
    int m = 0;
    for (int k = 0; k < L2_HZ; k++) {
        L[k] = h[k] + off * inv[k];
        m += L[k] >= w;
    }
    if (m == 0)
        return 1.0f;
    int a = m < L2_HZ ? m - 1 : L2_HZ - 2, b = a + 1;
    float den = L[a] - L[b];
    if (!(den > 0.0f))
        return m < L2_HZ ? 1.0f / hz_r[b] : 0.0f;
    float r = hz_r[a] + (L[a] - w) / den * (hz_r[b] - hz_r[a]);
    return l2_min(1.0f / l2_max(r, 1.0f), 1.0f);
}

/* Soft visibility of a point its own ray reaches (lit side) at continuous
 * bin c and distance d: the mean of both sides' visible shares. */
static inline float reached_visibility(const l2_polar *pm, float c, float d)
{
    int n = pm->n;
    int b = floor_clone(c);
    float f = c - (float)b;
    b = b >= n ? b - n : (b < 0 ? b + n : b);
    float wid = pm->theta[b + 1] - pm->theta[b];
    float w = 1.0f / d;
    const float *h = pm->hz + (size_t)b * 2 * L2_HZ;
    float up = side_visible(h, pm->hz_inv, f * wid, w);
    float down = side_visible(h + L2_HZ, pm->hz_inv, (1.0f - f) * wid, w);
    return 0.5f * (up + down);
}

L2_CLONES
void l2_penumbrae(const l2_polar *pm, int n8, const uint8_t *code, const float *ca,
                  const float *dea, const float *da, const float *ka, float *fa)
{
    for (int i0 = 0; i0 < n8; i0 += 8) {
        uint64_t word;
        memcpy(&word, code + i0, sizeof word);
        if (!word)
            continue;
        for (int i = i0; i < i0 + 8; i++) {
            if (code[i] == 1)
                fa[i] *= reached_visibility(pm, ca[i], dea[i]);
            else if (code[i] == 2)
                fa[i] *= filter(pm, ca[i], ka[i], da[i], false);
        }
    }
}


/* Loops of the block tests over a run of rays [i0, i1] without an early
 * exit, so that they vectorize (the same comparisons, order free). */
L2_CLONES static bool any_at_least(const float *restrict v, int i0, int i1, float x)
{
    int any = 0;
    for (int i = i0; i <= i1; i++)
        any |= v[i] >= x;
    return any != 0;
}

L2_CLONES static float run_max(const float *restrict v, int i0, int i1, float m)
{
    for (int i = i0; i <= i1; i++)
        m = l2_max(m, v[i]);
    return m;
}

/* Whether some ray of [i0, i1] has an open ray within its penumbra window
 * at the block (block_dark). */
L2_CLONES static bool any_window_open(const float *restrict qocc, const float *restrict g, int i0,
                                      int i1, float s, float inv, float sc, float bpp, float kcap)
{
    int any = 0;
    for (int i = i0; i <= i1; i++) {
        float k = s * (qocc[i] - inv) * sc * bpp;
        k = l2_min(k, kcap);
        any |= (k >= 0.5f) & (k > g[i]);
    }
    return any != 0;
}

/* Whether the light leaves every pixel of the block dark (as shading
 * them would), given the block's geometry: its pixel centres' nearest and
 * farthest distance, rays [b0, b1] (one more each side) and the corners'
 * pseudo-angles pa and slopes u. */
static bool block_dark(const l2_prep *p, bool has_caster, float dmin, float dmax, int b0, int b1,
                       const float pa[4], const float u[4])
{
    const lx_light2d_light *l = &p->l;
    const l2_polar *pm = &p->polar;
    int n = pm->n;
    /* caster pixels lit on their face: only where a ray's first caster
     * run reaches the block */
    bool faces = has_caster && !l->self_shadow;
    /* every ray blocked before the nearest pixel (with a margin for the
     * rounding of d x 1/occ) */
    float before = dmin * (1.0f - 1e-5f);
    if (range_query(pm, pm->tmax, b0, b1, true) >= before)
        return false;
    /* the bins [b0, b1] as up to two runs without wrapping */
    int r0[2], r1[2], runs = 1;
    r0[0] = wrap(b0, n);
    r1[0] = r0[0] + (b1 - b0);
    if (r1[0] >= n) {
        r0[1] = 0;
        r1[1] = r1[0] - n;
        r1[0] = n - 1;
        runs = 2;
    }
    if (faces)
        for (int r = 0; r < runs; r++)
            if (any_at_least(pm->ex, r0[r], r1[r], before))
                return false;
    if (l->softness <= 0.0f)
        return true;
    /* and, as shade.c tests each pixel, no open ray in the penumbra window
     * of its ray's occluder: k = s (1/max(o, 0.5) - 1/d) (1 + u^2) n/8 is
     * at most its value at dmax and the largest u^2 of the block (at a
     * corner, or 1 across a face's edge), and the rays open at d are open
     * at the level of dmin */
    if (dmin < L2_DEPTH0)
        return false;
    float u2max = 0.0f, plo = 8.0f, phi = 0.0f;
    for (int c = 0; c < 4; c++) {
        u2max = l2_max(u2max, u[c] * u[c]);
        plo = l2_min(plo, pa[c]);
        phi = l2_max(phi, pa[c]);
    }
    /* a face's edge (|u| = 1) at p = 0, 2, 4, 6 between the corners */
    if (phi - plo > 4.0f || (int)(plo * 0.5f) != (int)(phi * 0.5f))
        u2max = 1.0f;
    float sc = 1.0f + u2max * (1.0f + 1e-5f), inv = 1.0f / dmax;
    float kcap = 0.5f * (float)n - 1.0f;
    const float *g = pm->gap + (size_t)l2_depth_level(dmin, pm->depth_levels - 1) * n;
    for (int r = 0; r < runs; r++)
        if (any_window_open(pm->qocc, g, r0[r], r1[r], l->softness, inv, sc, pm->bins_per_p, kcap))
            return false;
    return true;
}

/* Whether the light's shadows leave every pixel of the block its full
 * light, given the block's geometry (fx, fy: the largest squares of its
 * pixel centres' offsets; rays [b0, b1] as for block_dark). */
static bool block_lit(const l2_prep *p, bool has_caster, float fx, float fy, int b0, int b1)
{
    const lx_light2d_light *l = &p->l;
    const l2_polar *pm = &p->polar;
    int n = pm->n;
    if (has_caster && !l->self_shadow)
        return false;
    /* no pixel is farther (squares and sums round monotonically); a margin
     * for the rounding of the products with it */
    float dmax = sqrtf(fx + fy) * (1.0f + 1e-5f);
    /* every pixel before its ray's occluder */
    if (range_query(pm, pm->tmin, b0, b1, false) <= dmax)
        return false;
    if (l->softness <= 0.0f)
        return true;
    /* and in no occluder's penumbra wedge (shade.c: d x lit[b] < 1) */
    int a = wrap(b0, n), e = a + (b1 - b0);
    float most = run_max(pm->lit, a, e < n ? e : n - 1, 0.0f);
    if (e >= n)
        most = run_max(pm->lit, 0, e - n, most);
    return dmax * most < 1.0f;
}

int l2_block_kind(const l2_prep *p, int x0, int y0, int x1, int y1, bool has_caster)
{
    const lx_light2d_light *l = &p->l;
    const l2_polar *pm = &p->polar;
    int n = pm->n;
    /* the pixel centres, relative to the light, as shade.c computes them */
    float ax = (float)x0 + 0.5f - l->x, bx = (float)(x1 - 1) + 0.5f - l->x;
    float ay = (float)y0 + 0.5f - l->y, by = (float)(y1 - 1) + 0.5f - l->y;
    float nx = ax > 0.0f ? ax : (bx < 0.0f ? bx : 0.0f);
    float ny = ay > 0.0f ? ay : (by < 0.0f ? by : 0.0f);
    /* squares and sums round monotonically: no pixel is nearer */
    float dmin2 = nx * nx + ny * ny;
    if (dmin2 >= p->r2)
        return L2_BLOCK_DARK; /* out of reach: no falloff */
    if (!l->shadow || dmin2 < 4.0f)
        return L2_BLOCK_MIXED;
    float fx = l2_max(ax * ax, bx * bx), fy = l2_max(ay * ay, by * by);
    float dmin = sqrtf(dmin2), dmax = sqrtf(fx + fy);
    /* the corners' pseudo-angles, and the rays of the pixels, one more
     * each side for rounding */
    float pa[4], u[4];
    float cx[4] = {ax, bx, ax, bx}, cy[4] = {ay, ay, by, by};
    for (int c = 0; c < 4; c++)
        pa[c] = pseudo_angle(cx[c], cy[c], &u[c]);
    int b0, b1;
    corner_bins(pm, pa, &b0, &b1);
    b0--;
    b1++;
    if (b1 - b0 + 1 >= n)
        return L2_BLOCK_MIXED;
    if (block_dark(p, has_caster, dmin, dmax, b0, b1, pa, u))
        return L2_BLOCK_DARK;
    return block_lit(p, has_caster, fx, fy, b0, b1) ? L2_BLOCK_LIT : L2_BLOCK_MIXED;
}
