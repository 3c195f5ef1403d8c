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

void l2_shade_row(const lx_light2d *ctx, const l2_prep *p, int y, float *acc)
{
    const lx_light2d_light *l = &p->l;
    float dy = (float)y + 0.5f - l->y;
    float dy2 = dy * dy;
    float *cache = p->cache ? p->cache + (size_t)(y - p->y0) * (p->x1 - p->x0) * 3 : NULL;
    if (cache)
        memset(cache, 0, (size_t)(p->x1 - p->x0) * 3 * sizeof *cache);
    if (dy2 >= p->r2)
        return;
    float half = sqrtf(p->r2 - dy2);
    int xa = (int)fmaxf((float)p->x0, floorf(l->x - half - 0.5f));
    int xb = (int)fminf((float)p->x1, ceilf(l->x + half + 0.5f));
    const uint8_t *caster = ctx->caster + (size_t)y * ctx->width;
    const float *normals = ctx->normals ? ctx->normals + (size_t)y * ctx->width * 3 : NULL;
    bool shadow = l->shadow;
    float h = l->height, h2 = h * h;
    for (int x = xa; x < xb; x++) {
        float dx = (float)x + 0.5f - l->x;
        float d2 = dx * dx + dy2;
        if (d2 >= p->r2)
            continue;
        float f;
        float d = sqrtf(d2);
        if (l->falloff == LX_FALLOFF2D_SMOOTH) {
            float q = 1.0f - d2 * p->inv_r2;
            f = q * q;
        } else if (l->falloff == LX_FALLOFF2D_LINEAR) {
            f = 1.0f - d * p->inv_r;
        } else {
            f = 1.0f;
        }
        if (p->spot && d > 0.0f) {
            float c = (dx * p->dir_x + dy * p->dir_y) / d;
            if (c <= p->cos_outer)
                continue;
            if (c < p->cos_inner) {
                float t = (c - p->cos_outer) * p->inv_fade;
                f *= t * t * (3.0f - 2.0f * t);
            }
        }
        if (normals) {
            const float *nn = normals + 3 * x;
            float ndl = -dx * nn[0] - dy * nn[1] + h * nn[2];
            if (ndl <= 0.0f)
                continue;
            f *= ndl / sqrtf(d2 + h2);
        }
        if (shadow && d > 0.0f) {
            float v = l2_visibility(&p->polar, l, dx, dy, d, caster[x] != 0);
            if (v <= 0.0f)
                continue;
            f *= v;
        }
        float r = p->rgb.x * f, g = p->rgb.y * f, b = p->rgb.z * f;
        if (cache) {
            float *c = cache + 3 * (x - p->x0);
            c[0] = r;
            c[1] = g;
            c[2] = b;
        }
        acc[3 * x] += r;
        acc[3 * x + 1] += g;
        acc[3 * x + 2] += b;
    }
}

/* Adds a cached light's row. */
static void add_cached(const l2_prep *p, int y, float *acc)
{
    const float *c = p->cache + (size_t)(y - p->y0) * (p->x1 - p->x0) * 3;
    float *a = acc + 3 * p->x0;
    int n = (p->x1 - p->x0) * 3;
    for (int i = 0; i < n; i++)
        a[i] += c[i];
}

lx_status lx_light2d_render(lx_light2d *ctx, lx_vec3 ambient, const lx_image *albedo, float *out,
                            float *light_map)
{
    int w = ctx->width, hgt = ctx->height;
    if (albedo) {
        if (albedo->width != w || albedo->height != hgt)
            return lx_fail(LX_ERR_INVALID, "casters: %dx%d but albedo: %dx%d", w, hgt,
                           albedo->width, albedo->height);
        if (albedo->channels < 3)
            return lx_fail(LX_ERR_INVALID, "albedo: %d channel%s, not RGB", albedo->channels,
                           albedo->channels == 1 ? "" : "s");
    }
    if (!isfinite(ambient.x) || !isfinite(ambient.y) || !isfinite(ambient.z) ||
        ambient.x < 0.0f || ambient.y < 0.0f || ambient.z < 0.0f)
        return lx_fail(LX_ERR_INVALID, "ambient must be finite and >= 0");
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
    float *rows = malloc((size_t)threads * w * 3 * sizeof *rows);
    if (!rows)
        return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for %d rows", threads);
    int ach = albedo ? albedo->channels : 0;
#pragma omp parallel num_threads(threads)
    {
        int tid = 0;
#ifdef _OPENMP
        tid = omp_get_thread_num();
#endif
        float *acc = rows + (size_t)tid * w * 3;
#pragma omp for schedule(dynamic, 4)
        for (int y = 0; y < hgt; y++) {
            for (int x = 0; x < w; x++) {
                acc[3 * x] = ambient.x;
                acc[3 * x + 1] = ambient.y;
                acc[3 * x + 2] = ambient.z;
            }
            for (int i = 0; i < count; i++) {
                const l2_prep *p = &ctx->preps[i];
                if (y < p->y0 || y >= p->y1 || p->x1 <= p->x0)
                    continue;
                if (p->relight)
                    l2_shade_row(ctx, p, y, acc);
                else
                    add_cached(p, y, acc);
            }
            size_t row = (size_t)y * w * 3;
            if (light_map)
                memcpy(light_map + row, acc, (size_t)w * 3 * sizeof *acc);
            if (out) {
                float *o = out + row;
                if (albedo) {
                    const float *a = albedo->data + (size_t)y * w * ach;
                    for (int x = 0; x < w; x++)
                        for (int k = 0; k < 3; k++)
                            o[3 * x + k] = a[ach * x + k] * acc[3 * x + k];
                } else {
                    memcpy(o, acc, (size_t)w * 3 * sizeof *acc);
                }
            }
        }
    }
    free(rows);
    for (int i = 0; i < count; i++)
        if (ctx->preps[i].cache)
            ctx->preps[i].relight = false;
    ctx->relit = relit;
    return LX_OK;
}
