/* 2D lights: shading a frame (seed 003, "2D lighting system", the light
 * map pass): out = albedo x (ambient + sum of lights), each light touching
 * only the pixels within its radius, with its falloff, spot cone, shadow
 * visibility from its polar map (polar.c) and, over a normal map, N.L
 * towards the light lifted to its height. Rows are independent and every
 * row adds its lights in their order, so the bytes do not depend on the
 * thread count; static lights keep their contribution in a cache and add
 * the same floats again on later frames. */
#include "l2_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif
#ifdef L2_GATHER
#include <immintrin.h>
#endif

/* Pass 2a of a soft light (shade_span): each pixel's case, branch-free and
 * over restrict pointers so that it vectorizes with gathers from the map. */
L2_CLONES __attribute__((noinline))
static void classify(const float *restrict occ, const float *restrict ex,
                     const float *restrict lit,
                     const float *restrict gap, int nb, int n, bool face_ok, float s, float kcap,
                     float bpp, int dtop, const uint8_t *restrict caster,
                     const float *restrict da, const float *restrict ca,
                     const float *restrict ua, float *restrict fa, float *restrict dea,
                     float *restrict ka, uint8_t *restrict code)
{
    for (int i = 0; i < n; i++) {
        float d = da[i];
        int b = (int)ca[i];
        b = b >= nb ? b - nb : b;
        float o = occ[b];
        bool face = face_ok & (caster[i] != 0) & (d <= ex[b]);
        /* clamped on a face, d elsewhere; written as min/max of selected
         * bounds because a select of the two values leaves GCC a select
         * of masks it cannot vectorize */
        float de = l2_max(l2_min(d, face ? o - 0.5f : INFINITY), face ? 0.5f : -INFINITY);
        bool pen = !(de * lit[b] < 1.0f);
        bool reach = face | (d < o);
        float u2 = ua[i] * ua[i];
        /* the window of the far side of the ray's first caster run (where
         * it is known): a line to the light from behind a caster clears
         * its back before its front */
        float ob = face_ok ? l2_max(o, l2_min(ex[b], d)) : o;
        float k = s * (1.0f / l2_max(ob, 0.5f) - 1.0f / d) * (1.0f + u2) * bpp;
        k = l2_min(k, kcap);
        int lv = l2_depth_level(l2_max(d, L2_DEPTH0), dtop);
        bool closed = (k < 0.5f) | ((d >= L2_DEPTH0) & (k <= gap[lv * nb + b]));
        bool active = (fa[i] > 0.0f) & (d > 0.0f) & pen;
        bool dark = active & !reach & closed;
        fa[i] = dark ? 0.0f : fa[i];
        code[i] = (uint8_t)((active & !dark) ? (reach ? 1 : 2) : 0);
        dea[i] = de;
        ka[i] = k;
    }
}

#ifdef L2_GATHER
/* classify on AVX2 with its four gathers from the map written out (GCC
 * emulates them with scalar loads otherwise, most of classify's time): the
 * scalar loop's operations lane by lane, in its order, so the same bytes.
 * n is a multiple of 8. */
__attribute__((target("avx2"))) static void
classify_avx2(const float *restrict occ, const float *restrict ex, const float *restrict lit,
              const float *restrict gap, int nb, int n, bool face_ok, float s, float kcap,
              float bpp, int dtop, const uint8_t *restrict caster, const float *restrict da,
              const float *restrict ca, const float *restrict ua, float *restrict fa,
              float *restrict dea, float *restrict ka, uint8_t *restrict code)
{
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f),
                 half = _mm256_set1_ps(0.5f), inf = _mm256_set1_ps(INFINITY),
                 ninf = _mm256_set1_ps(-INFINITY), depth0 = _mm256_set1_ps(L2_DEPTH0),
                 vs = _mm256_set1_ps(s), vcap = _mm256_set1_ps(kcap),
                 vbpp = _mm256_set1_ps(bpp);
    const __m256i vnb = _mm256_set1_epi32(nb), vnb1 = _mm256_set1_epi32(nb - 1),
                  i127 = _mm256_set1_epi32(127), mant = _mm256_set1_epi32(0x7fffff),
                  sqrt2 = _mm256_set1_epi32(0x3504f3 - 1), vtop = _mm256_set1_epi32(dtop),
                  i1 = _mm256_set1_epi32(1), i2 = _mm256_set1_epi32(2);
    const __m256 vface_ok = _mm256_castsi256_ps(_mm256_set1_epi32(face_ok ? -1 : 0));
    for (int i = 0; i < n; i += 8) {
        __m256 d = _mm256_loadu_ps(da + i);
        __m256i b = _mm256_cvttps_epi32(_mm256_loadu_ps(ca + i));
        b = _mm256_sub_epi32(b, _mm256_and_si256(_mm256_cmpgt_epi32(b, vnb1), vnb));
        __m256 o = _mm256_i32gather_ps(occ, b, 4);
        __m256 e = _mm256_i32gather_ps(ex, b, 4);
        __m256i cast = _mm256_cvtepu8_epi32(_mm_loadl_epi64((const __m128i *)(caster + i)));
        __m256 is_caster =
            _mm256_castsi256_ps(_mm256_cmpgt_epi32(cast, _mm256_setzero_si256()));
        __m256 face = _mm256_and_ps(_mm256_and_ps(vface_ok, is_caster),
                                    _mm256_cmp_ps(d, e, _CMP_LE_OQ));
        __m256 hi_b = _mm256_blendv_ps(inf, _mm256_sub_ps(o, half), face);
        __m256 lo_b = _mm256_blendv_ps(ninf, half, face);
        __m256 de = _mm256_max_ps(_mm256_min_ps(d, hi_b), lo_b);
        __m256 lt = _mm256_i32gather_ps(lit, b, 4);
        __m256 pen = _mm256_cmp_ps(_mm256_mul_ps(de, lt), one, _CMP_NLT_UQ);
        __m256 reach = _mm256_or_ps(face, _mm256_cmp_ps(d, o, _CMP_LT_OQ));
        __m256 u = _mm256_loadu_ps(ua + i);
        __m256 u2 = _mm256_mul_ps(u, u);
        __m256 ob = face_ok ? _mm256_max_ps(o, _mm256_min_ps(e, d)) : o;
        __m256 k = _mm256_sub_ps(_mm256_div_ps(one, _mm256_max_ps(ob, half)),
                                 _mm256_div_ps(one, d));
        k = _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(vs, k), _mm256_add_ps(one, u2)), vbpp);
        k = _mm256_min_ps(k, vcap);
        /* l2_depth_level of max(d, L2_DEPTH0) */
        __m256i bits = _mm256_castps_si256(_mm256_div_ps(_mm256_max_ps(d, depth0), depth0));
        __m256i ex2 = _mm256_sub_epi32(_mm256_srli_epi32(bits, 23), i127);
        __m256i lv = _mm256_sub_epi32(_mm256_add_epi32(ex2, ex2),
                                      _mm256_cmpgt_epi32(_mm256_and_si256(bits, mant), sqrt2));
        lv = _mm256_min_epi32(lv, vtop);
        __m256 g = _mm256_i32gather_ps(gap, _mm256_add_epi32(_mm256_mullo_epi32(lv, vnb), b), 4);
        __m256 closed = _mm256_or_ps(
            _mm256_cmp_ps(k, half, _CMP_LT_OQ),
            _mm256_and_ps(_mm256_cmp_ps(d, depth0, _CMP_GE_OQ), _mm256_cmp_ps(k, g, _CMP_LE_OQ)));
        __m256 f = _mm256_loadu_ps(fa + i);
        __m256 active = _mm256_and_ps(
            _mm256_and_ps(_mm256_cmp_ps(f, zero, _CMP_GT_OQ), _mm256_cmp_ps(d, zero, _CMP_GT_OQ)),
            pen);
        __m256 dark = _mm256_andnot_ps(reach, _mm256_and_ps(active, closed));
        _mm256_storeu_ps(fa + i, _mm256_andnot_ps(dark, f));
        /* code: 0, or 1 where reached, 2 where not, for active & !dark */
        __m256i shown = _mm256_castps_si256(_mm256_andnot_ps(dark, active));
        __m256i c = _mm256_and_si256(
            shown, _mm256_blendv_epi8(i2, i1, _mm256_castps_si256(reach)));
        __m128i c16 = _mm_packs_epi32(_mm256_castsi256_si128(c), _mm256_extracti128_si256(c, 1));
        _mm_storel_epi64((__m128i *)(code + i), _mm_packus_epi16(c16, c16));
        _mm256_storeu_ps(dea + i, de);
        _mm256_storeu_ps(ka + i, k);
    }
}
#endif

/* Adds the light's contribution to the pixels [xs, xe) of row y into acc
 * (the row's width*3 floats), and to its cache row when it is a static
 * light being re-lit (the caller cleared that row); scratch holds 8
 * arrays of l2_scratch_stride(width) floats. */
L2_CLONES
static void shade_span(const lx_light2d *ctx, const l2_prep *p, int y, int xs, int xe,
                       float *acc, float *scratch, bool shadows)
{
    const lx_light2d_light *l = &p->l;
    float dy = (float)y + 0.5f - l->y;
    float dy2 = dy * dy;
    float *cache = p->cache ? p->cache + (size_t)(y - p->y0) * (p->x1 - p->x0) * 3 : NULL;
    if (dy2 >= p->r2)
        return;
    float half = sqrtf(p->r2 - dy2);
    int xa = (int)l2_max((float)xs, floorf(l->x - half - 0.5f));
    int xb = (int)l2_min((float)xe, ceilf(l->x + half + 0.5f));
    int n = xb - xa;
    if (n <= 0)
        return;
    /* the vector passes run over whole vectors (L2_PAD) */
    int n8 = (n + 7) & ~7;
    size_t ws = l2_scratch_stride(ctx->width);
    /* pass 1, branch-free so that it vectorizes: distance, falloff and the
     * continuous polar bin of every pixel of the span */
    float *fa = scratch, *da = scratch + ws, *ca = scratch + 2 * ws, *ua = scratch + 3 * ws;
    float lx = l->x, r2 = p->r2, inv_r = p->inv_r, inv_r2 = p->inv_r2;
    float bpp = p->polar.bins_per_p;
    int kind = (int)l->falloff;
    for (int i = 0; i < n8; i++) {
        float dx = (float)(xa + i) + 0.5f - lx;
        float d2 = dx * dx + dy2;
        float d = sqrtf(d2);
        float q = 1.0f - d2 * inv_r2;
        float f = kind == 0 ? q * q : (kind == 1 ? 1.0f - d * inv_r : 1.0f);
        fa[i] = d2 < r2 ? f : 0.0f;
        da[i] = d;
        float ax = fabsf(dx), ay = fabsf(dy);
        bool big = ax >= ay;
        float m = big ? ax : ay;
        float num = big ? dy : dx;
        float t = num / l2_max(m, 1e-30f);
        float pa = big ? (dx > 0.0f ? 1.0f + t : 5.0f - t) : (dy > 0.0f ? 3.0f - t : 7.0f + t);
        ca[i] = pa * bpp;
        ua[i] = t;
    }
    if (p->spot) {
        float cx = p->dir_x, cy = p->dir_y, co = p->cos_outer, ci = p->cos_inner, k = p->inv_fade;
        for (int i = 0; i < n8; i++) {
            float dx = (float)(xa + i) + 0.5f - lx;
            float d = da[i];
            float c = d > 0.0f ? (dx * cx + dy * cy) / d : 1.0f;
            float t = l2_min(l2_max((c - co) * k, 0.0f), 1.0f);
            float s = c >= ci ? 1.0f : (c <= co ? 0.0f : t * t * (3.0f - 2.0f * t));
            fa[i] *= s;
        }
    }
    if (ctx->normals) {
        size_t plane = (size_t)ctx->width * ctx->height;
        const float *nx = ctx->normals + (size_t)y * ctx->width + xa, *ny = nx + plane,
                    *nz = nx + 2 * plane;
        float h = l->height, h2 = h * h;
        for (int i = 0; i < n8; i++) {
            float dx = (float)(xa + i) + 0.5f - lx;
            float ndl = -dx * nx[i] - dy * ny[i] + h * nz[i];
            float len = sqrtf(da[i] * da[i] + h2);
            float v = ndl / l2_max(len, 1e-30f);
            fa[i] *= ndl > 0.0f ? v : 0.0f;
        }
    }
    /* pass 2: shadows from the polar map */
    if (!shadows) {
        /* the block test found every pixel lit */
    } else if (l->shadow && l->softness <= 0.0f) {
        const uint8_t *caster = ctx->caster + (size_t)y * ctx->width + xa;
        const l2_polar *pm = &p->polar;
        int nb = pm->n;
        bool face_ok = !l->self_shadow;
        for (int i = 0; i < n; i++) {
            float d = da[i];
            int b = (int)ca[i];
            b = b >= nb ? b - nb : b;
            bool face = face_ok & (caster[i] != 0) & (d <= pm->ex[b]);
            bool keep = (d < pm->occ[b]) | face | (d <= 0.0f);
            fa[i] = keep ? fa[i] : 0.0f;
        }
    } else if (l->shadow) {
        /* 2a, branch-free so that it vectorizes (gathers from the map):
         * each pixel's case. Fully lit pixels (in no occluder's penumbra)
         * keep their light, fully shadowed ones (in the hard shadow, with
         * no open ray in the penumbra window) drop it; the others are
         * listed for 2b: those their ray reaches (or lit on their face)
         * for the nearest occluder's penumbra, those in the hard shadow
         * for their own occluder's filter (window ka). */
        const uint8_t *caster = ctx->caster + (size_t)y * ctx->width + xa;
        const l2_polar *pm = &p->polar;
        int nb = pm->n;
        bool face_ok = !l->self_shadow;
        float kcap = 0.5f * (float)nb - 1.0f, s = l->softness;
        int dtop = pm->depth_levels - 1;
        float *dea = scratch + 4 * ws, *ka = scratch + 5 * ws;
        uint8_t *code = (uint8_t *)(scratch + 6 * ws); /* 4 ws bytes */
#ifdef L2_GATHER
        if (l2_gather_ok())
            classify_avx2(pm->occ, pm->ex, pm->lit, pm->gap, nb, n8, face_ok, s, kcap, bpp,
                          dtop, caster, da, ca, ua, fa, dea, ka, code);
        else
#endif
            classify(pm->occ, pm->ex, pm->lit, pm->gap, nb, n8, face_ok, s, kcap, bpp, dtop,
                     caster, da, ca, ua, fa, dea, ka, code);
        /* 2b: the penumbrae (of the span's pixels alone), skipping eight
         * pixels at a time where none is listed */
        for (int i = n; i < n8; i++)
            code[i] = 0;
        l2_penumbrae(pm, n8, code, ca, dea, da, ka, fa);
    }
    /* the row's three planes of light (and the cache row's) */
    float cr = p->rgb.x, cg = p->rgb.y, cb = p->rgb.z;
    int w = ctx->width;
    if (cache) {
        int cw = p->x1 - p->x0;
        float *c = cache + (xa - p->x0);
        for (int i = 0; i < n; i++) {
            c[i] = cr * fa[i];
            c[cw + i] = cg * fa[i];
            c[2 * cw + i] = cb * fa[i];
        }
    }
    float *ar = acc + xa, *ag = ar + w, *ab = ar + 2 * w;
    for (int i = 0; i < n; i++) {
        ar[i] += cr * fa[i];
        ag[i] += cg * fa[i];
        ab[i] += cb * fa[i];
    }
}

/* A row's three planes as RGB triples (restrict: it vectorizes). */
L2_CLONES static void interleave(float *restrict o, const float *restrict r,
                                 const float *restrict g, const float *restrict b, int w)
{
    for (int x = 0; x < w; x++) {
        o[3 * x] = r[x];
        o[3 * x + 1] = g[x];
        o[3 * x + 2] = b[x];
    }
}

/* Adds a cached light's row. */
static void add_cached(const lx_light2d *ctx, const l2_prep *p, int y, float *acc)
{
    int cw = p->x1 - p->x0, w = ctx->width;
    const float *c = p->cache + (size_t)(y - p->y0) * cw * 3;
    for (int k = 0; k < 3; k++) {
        float *a = acc + (size_t)k * w + p->x0;
        const float *ck = c + (size_t)k * cw;
        for (int i = 0; i < cw; i++)
            a[i] += ck[i];
    }
}

/* Adds light p to the rows [y0, y1) of a band (acc: the band's rows,
 * width*3 floats each, from row y0): the blocks the light leaves dark are
 * skipped, the rest shaded in runs of neighbouring blocks. runs holds
 * 3*(blocks_x+1) ints. */
static void shade_band(const lx_light2d *ctx, const l2_prep *p, int y0, int y1, float *acc,
                       float *scratch, int *runs)
{
    int w = ctx->width;
    int ya = y0 > p->y0 ? y0 : p->y0, yb = y1 < p->y1 ? y1 : p->y1;
    if (ya >= yb || p->x1 <= p->x0)
        return;
    if (!p->relight) {
        for (int y = ya; y < yb; y++)
            add_cached(ctx, p, y, acc + (size_t)(y - y0) * w * 3);
        return;
    }
    if (p->cache)
        for (int y = ya; y < yb; y++)
            memset(p->cache + (size_t)(y - p->y0) * (p->x1 - p->x0) * 3, 0,
                   (size_t)(p->x1 - p->x0) * 3 * sizeof(float));
    /* the band's blocks under the light: dark ones dropped, the others
     * merged into runs of the same kind (wholly lit, needing no shadow
     * pass, or not); runs[3 r + 2]: the kind */
    int by = y0 / L2_BLOCK, count = 0;
    int bx0 = p->x0 / L2_BLOCK, bx1 = (p->x1 - 1) / L2_BLOCK;
    for (int bx = bx0; bx <= bx1; bx++) {
        int xs = bx * L2_BLOCK, xe = xs + L2_BLOCK < w ? xs + L2_BLOCK : w;
        xs = xs > p->x0 ? xs : p->x0;
        xe = xe < p->x1 ? xe : p->x1;
        bool caster = ctx->block_caster[(size_t)by * ctx->blocks_x + bx] != 0;
        int bk = l2_block_kind(p, xs, ya, xe, yb, caster);
        if (bk == L2_BLOCK_DARK)
            continue;
        int kind = bk == L2_BLOCK_LIT ? 0 : 1;
        if (count > 0 && runs[3 * count - 2] == xs && runs[3 * count - 1] == kind)
            runs[3 * count - 2] = xe;
        else {
            runs[3 * count] = xs;
            runs[3 * count + 1] = xe;
            runs[3 * count + 2] = kind;
            count++;
        }
    }
    for (int y = ya; y < yb; y++)
        for (int r = 0; r < count; r++)
            shade_span(ctx, p, y, runs[3 * r], runs[3 * r + 1], acc + (size_t)(y - y0) * w * 3,
                       scratch, runs[3 * r + 2] != 0);
}

lx_status lx_light2d_render(lx_light2d *ctx, lx_vec3 ambient, const lx_image *albedo, float *out,
                            float *light_map)
{
    if (!ctx)
        return lx_fail_null(__func__, "ctx");
    /* a frame with nowhere to go is a caller's mistake, not a no-op */
    if (!out && !light_map)
        return lx_fail(LX_ERR_INVALID, "%s: out and light_map are both NULL", __func__);
    int w = ctx->width, hgt = ctx->height;
    if (albedo) {
        if (albedo->width != w || albedo->height != hgt)
            return lx_fail(LX_ERR_INVALID, "casters: %dx%d but albedo: %dx%d", w, hgt,
                           albedo->width, albedo->height);
        if (albedo->channels < 3)
            return lx_fail(LX_ERR_INVALID, "albedo: %d channel%s, not RGB", albedo->channels,
                           albedo->channels == 1 ? "" : "s");
    }
    if (!(ambient.x >= 0.0f && ambient.x <= LX_LIGHT2D_MAX_LIGHT) ||
        !(ambient.y >= 0.0f && ambient.y <= LX_LIGHT2D_MAX_LIGHT) ||
        !(ambient.z >= 0.0f && ambient.z <= LX_LIGHT2D_MAX_LIGHT))
        return lx_fail(LX_ERR_INVALID, "ambient must be in [0, %g]", LX_LIGHT2D_MAX_LIGHT);
    int threads = lx_thread_count(ctx->threads);
    /* polar maps of the lights computed this frame */
    int count = ctx->count;
    int relit = 0;
    lx_status st = LX_OK;
    for (int i = 0; i < count; i++) {
        l2_prep *p = &ctx->preps[i];
        if (p->l.dynamic || !p->cache)
            p->relight = true;
        if (p->relight)
            relit++;
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int i = 0; i < count; i++) {
        l2_prep *p = &ctx->preps[i];
        if (!p->relight || !p->l.shadow || p->x1 <= p->x0 || p->y1 <= p->y0)
            continue;
        lx_status s = l2_polar_build(ctx, p);
        if (s != LX_OK) {
#pragma omp critical(lx_light2d_status)
            st = s;
        }
    }
    if (st != LX_OK)
        return st;
    /* per thread: a band of accumulated rows, eight rows of scratch and the
     * runs of a band */
    size_t band = (size_t)L2_BLOCK * w * 3, per = band + l2_scratch_stride(w) * 8;
    size_t nruns = 3 * ((size_t)ctx->blocks_x + 1);
    /* kept from frame to frame (a fresh block of this size would be new
     * pages, faulted in and cleared every frame) */
    size_t need = (size_t)threads * (per * sizeof(float) + nruns * sizeof(int));
    if (need > ctx->work_size) {
        float *a = malloc(need);
        if (!a)
            return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for %d bands", threads);
        free(ctx->work);
        ctx->work = a;
        ctx->work_size = need;
    }
    float *rows = ctx->work;
    int *all_runs = (int *)(rows + (size_t)threads * per);
    int ach = albedo ? albedo->channels : 0;
    int bands = (hgt + L2_BLOCK - 1) / L2_BLOCK;
#pragma omp parallel num_threads(threads)
    {
        int tid = 0;
#ifdef _OPENMP
        tid = omp_get_thread_num();
#endif
        float *acc = rows + (size_t)tid * per;
        float *scratch = acc + band;
        int *runs = all_runs + (size_t)tid * nruns;
#pragma omp for schedule(dynamic, 1)
        for (int bi = 0; bi < bands; bi++) {
            int y0 = bi * L2_BLOCK, y1 = y0 + L2_BLOCK < hgt ? y0 + L2_BLOCK : hgt;
            /* each row as three planes: r, g, b */
            for (int y = y0; y < y1; y++) {
                float *r = acc + (size_t)(y - y0) * w * 3;
                for (int x = 0; x < w; x++) {
                    r[x] = ambient.x;
                    r[w + x] = ambient.y;
                    r[2 * w + x] = ambient.z;
                }
            }
            /* every pixel adds its lights in their order */
            for (int i = 0; i < count; i++)
                shade_band(ctx, &ctx->preps[i], y0, y1, acc, scratch, runs);
            for (int y = y0; y < y1; y++) {
                const float *r = acc + (size_t)(y - y0) * w * 3, *g = r + w, *b = g + w;
                size_t row = (size_t)y * w * 3;
                if (light_map)
                    interleave(light_map + row, r, g, b, w);
                if (out) {
                    float *o = out + row;
                    if (albedo) {
                        const float *a = albedo->data + (size_t)y * w * ach;
                        for (int x = 0; x < w; x++) {
                            o[3 * x] = a[ach * x] * r[x];
                            o[3 * x + 1] = a[ach * x + 1] * g[x];
                            o[3 * x + 2] = a[ach * x + 2] * b[x];
                        }
                    } else
                        interleave(o, r, g, b, w);
                }
            }
        }
    }
    for (int i = 0; i < count; i++)
        if (ctx->preps[i].cache)
            ctx->preps[i].relight = false;
    ctx->relit = relit;
    return LX_OK;
}
