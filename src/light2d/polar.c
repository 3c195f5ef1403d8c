/* Polar shadow maps of 2D lights (seed 003, "2D lighting system tutorial
 * part 4": the casters around a light unwrapped into a column per ray and
 * each column reduced to its nearest occluder). On the CPU the unwrap and
 * the reduction are one step: every boundary caster pixel under the light's
 * reach is rasterised into the angular bins its square covers, keeping the
 * nearest distance per bin (only boundary pixels can be the first caster a
 * ray meets). A second pass keeps where the first caster run of each ray
 * ends, so casters can be lit on their face. Soft shadows filter the map
 * along the angle (percentage-closer filtering) over a window that grows
 * with the distance behind the occluder, as a light of radius `softness`
 * predicts; sparse tables of the window minimum and maximum skip the
 * filter wherever the window is wholly lit or wholly shadowed. */
#include "l2_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define L2_FAR 1e30f

/* AVX2 gathers for the sampled filter where the CPU has them (GCC or
 * clang on x86-64). */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(L2_NO_CLONES)
#define L2_GATHER 1
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
    free(pm->lit);
    free(pm->occx);
    free(pm->sel);
    free(pm->exits);
    free(pm->qocc);
    free(pm->gap);
    free(pm->tmin);
    free(pm->tmax);
    memset(pm, 0, sizeof *pm);
}

/* The bins [b0, b1] of a square from its corners' pseudo-angles p[4]
 * (the second half of square_bins). */
static void corner_bins(const l2_polar *pm, const float p[4], int *b0, int *b1)
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
        float *lit = realloc(pm->lit, (size_t)n * sizeof *lit);
        if (lit)
            pm->lit = lit;
        float *qocc = realloc(pm->qocc, (size_t)n * sizeof *qocc);
        if (qocc)
            pm->qocc = qocc;
        float *occx = realloc(pm->occx, (size_t)n * 3 * sizeof *occx);
        if (occx)
            pm->occx = occx;
        uint8_t *sel = realloc(pm->sel, (size_t)n);
        if (sel)
            pm->sel = sel;
        pm->sel_n = 0;
        if (!occ || !ex || !lit || !qocc || !occx || !sel)
            return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for a polar map of %d rays", n);
        pm->capacity = n;
    }
    size_t t = (size_t)n * levels;
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

/* The penumbra wedges' reach (l2_polar.lit). The occluder of ray j, at
 * inverse distance q_j = 1/occ[j], casts a penumbra over the points at
 * inverse distance q whose window s (q_j - q) x scale (in bins, scale =
 * (1 + u^2) n/8 the bins per radian at the point, u the pseudo-angle's
 * slope there) reaches ray j: with g the whole bins between rays b and j,
 * a point of ray b can be in it only when q < q_j - g / (s x scale). So
 * lit[b] = max_j (q_j - g c_b) bounds every wedge reaching ray b, c_b =
 * 1 / (s n/8 (1 + u_b^2)) with u_b^2 the largest over ray b's bin. c_b
 * lies in [c, 2c], c = 1 / (s n/4): four distance transforms with linear
 * cones of slopes c 2^(k/4), k = 0..3, one pass each way around the circle
 * (twice round, so that wedges wrap), and each ray takes the steepest
 * cone not steeper than its own c_b. */
static void penumbra_reach(l2_polar *pm, float s, float *q)
{
    int n = pm->n;
    const float *occ = pm->occ;
    float *lit = pm->lit;
    const uint8_t *sel = pm->sel;
    float step[4];
    for (int k = 0; k < 4; k++)
        step[k] = (float)(exp2(0.25 * k) / (s * 0.25 * (double)n));
    for (int i = 0; i < n; i++) {
        q[i] = occ[i] >= L2_FAR ? 0.0f : 1.0f / l2_max(occ[i], 1e-6f);
        lit[i] = q[i];
    }

    /* g: the best wedge of each slope arriving from the bins before i,
     * its gap counted */
    float g0 = 0.0f, g1 = 0.0f, g2 = 0.0f, g3 = 0.0f;
    for (int lap = 0; lap < 2; lap++)
        for (int i = 0; i < n; i++) {
            if (lap) {
                int k = sel[i];
                float v = k == 0 ? g0 : (k == 1 ? g1 : (k == 2 ? g2 : g3));
                lit[i] = l2_max(lit[i], v);
            }
            float qi = q[i];
            g0 = l2_max(qi, g0 - step[0]);
            g1 = l2_max(qi, g1 - step[1]);
            g2 = l2_max(qi, g2 - step[2]);
            g3 = l2_max(qi, g3 - step[3]);
        }
    g0 = g1 = g2 = g3 = 0.0f;
    for (int lap = 0; lap < 2; lap++)
        for (int i = n - 1; i >= 0; i--) {
            if (lap) {
                int k = sel[i];
                float v = k == 0 ? g0 : (k == 1 ? g1 : (k == 2 ? g2 : g3));
                lit[i] = l2_max(lit[i], v);
            }
            float qi = q[i];
            g0 = l2_max(qi, g0 - step[0]);
            g1 = l2_max(qi, g1 - step[1]);
            g2 = l2_max(qi, g2 - step[2]);
            g3 = l2_max(qi, g3 - step[3]);
        }
}

/* l2_polar.sel: per ray b, the steepest of the four cones of
 * penumbra_reach not steeper than c_b (it depends on n alone). */
static void cone_select(l2_polar *pm)
{
    int n = pm->n;
    double bpp = (double)n / 8.0;
    for (int i = 0; i < n; i++) {
        /* the bin's pseudo-angles [p0, p1] and the face centre (odd) of p0 */
        double p0 = i / bpp, p1 = (i + 1) / bpp;
        double cen = 2.0 * floor(p0 * 0.5) + 1.0;
        double u2 = 1.0;
        if (p1 <= cen + 1.0) {
            double a = p0 - cen, b = p1 - cen;
            u2 = a * a > b * b ? a * a : b * b;
        }
        /* margins for the rounding of the pixels' pseudo-angles and
         * windows */
        double ratio = 2.0 / (1.0 + u2 + 1e-4) * (1.0 - 1e-4);
        int k = 0;
        while (k < 3 && exp2(0.25 * (k + 1)) <= ratio)
            k++;
        pm->sel[i] = (uint8_t)k;
    }
    pm->sel_n = n;
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
    /* the boundary pixels where a ray leaves its caster run, listed with
     * their bins for the second pass (at most every pixel of the tiles) */
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
                int b0 = 0, b1 = n - 1;
                if (!inside)
                    square_bins(pm, ax, bx, ay, by, &b0, &b1);
                float dn = sqrtf(dn2);
                for (int b = b0; b <= b1; b++) {
                    int i = b >= n ? b - n : b;
                    if (dn < occ[i])
                        occ[i] = dn;
                }
                if (face) {
                    float cx = ax + 0.5f, cy = ay + 0.5f;
                    bool exit = ((ed->free & L2_FREE_RIGHT) && cx > 0.0f) ||
                                ((ed->free & L2_FREE_LEFT) && cx < 0.0f) ||
                                ((ed->free & L2_FREE_DOWN) && cy > 0.0f) ||
                                ((ed->free & L2_FREE_UP) && cy < 0.0f) || inside;
                    if (exit) {
                        float fx = l2_max(ax * ax, bx * bx), fy = l2_max(ay * ay, by * by);
                        pm->exits[exits++] = (l2_exit){b0, b1, sqrtf(fx + fy)};
                    }
                }
            }
        }
    /* where the first caster run of each ray ends: the nearest far corner
     * of an exit pixel at or beyond the ray's occluder */
    for (size_t x = 0; x < exits; x++) {
        const l2_exit *ev = &pm->exits[x];
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
        if (pm->sel_n != n)
            cone_select(pm);
        /* scratch: the sparse table, built below */
        penumbra_reach(pm, l->softness, pm->tmin);
        for (int i = 0; i < n; i++)
            pm->qocc[i] = 1.0f / l2_max(occ[i], 0.5f);
        /* scratch: the sparse table (levels x n >= 8 n floats) */
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

static inline bool l2_gather_ok(void)
{
    return __builtin_cpu_supports("avx2");
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
        float lit = 0.0f;
        for (int b = b0; b <= b1; b++) {
            float w = l2_min(hi, (float)(b + 1)) - l2_max(lo, (float)b);
            lit += occ[b] >= d ? w : 0.0f;
        }
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

/* Soft visibility at distance d on the ray at continuous bin c: the
 * nearest occluder o in a search window (the window an occluder at d/8
 * would need), then the filter over the half-angle softness (d - o) /
 * (d o), the angle a light of radius softness subtends behind o, with o
 * the nearest occluder inside that window. */
static inline float soft_visibility(const l2_polar *pm, float s, float c, float u2, float d)
{
    float scale = (1.0f + u2) * pm->bins_per_p; /* bins per radian */
    float cap = 0.5f * (float)pm->n - 1.0f;
    float ks = l2_min(7.0f * s / d * scale, cap);
    int b0 = floor_clone(c - ks), b1 = floor_clone(c + ks);
    float m = range_query(pm, pm->tmin, b0, b1, false);
    if (m >= d)
        return 1.0f;
    /* the nearest occluder's window shrinks as farther occluders are
     * found nearest inside it: iterate to (close to) the fixed point, where
     * the window is that of the nearest occluder inside it */
    float k = 0.0f;
    for (int it = 0; it < 4; it++) {
        float o = l2_max(m, 0.5f);
        k = l2_min(s * (d - o) / (d * o) * scale, cap);
        if (k < 0.5f)
            break;
        float m2 = range_query(pm, pm->tmin, floor_clone(c - k), floor_clone(c + k), false);
        if (m2 >= d)
            return 1.0f;
        if (m2 == m)
            break;
        m = m2;
    }
    if (k < 0.5f)
        return pm->occx[pm->n + floor_clone(c)] >= d ? 1.0f : 0.0f;
    /* the point's own ray reaches past it (d is before its occluder, or
     * on its lit face) and lies in the window (k >= 0.5) */
    return filter(pm, c, k, d, true);
}

L2_CLONES
void l2_penumbrae(const l2_polar *pm, float s, int n8, const uint8_t *code, const float *ca,
                  const float *ua, const float *dea, const float *da, const float *ka, float *fa)
{
    for (int i0 = 0; i0 < n8; i0 += 8) {
        uint64_t word;
        memcpy(&word, code + i0, sizeof word);
        if (!word)
            continue;
        for (int i = i0; i < i0 + 8; i++) {
            if (code[i] == 1)
                fa[i] *= soft_visibility(pm, s, ca[i], ua[i] * ua[i], dea[i]);
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
