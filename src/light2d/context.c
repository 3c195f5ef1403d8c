/* 2D lights: the context of a caster image (seed 003, "2D lighting system":
 * shadow casters unwrapped into a polar map per light). Casters are kept as
 * a byte mask plus tile lists of their boundary pixels, the only pixels a
 * ray can meet first; lights are validated and cached here, shaded in
 * shade.c from the polar maps of polar.c. */
#include "l2_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lx_light2d_light lx_light2d_light_defaults(lx_light2d_type type)
{
    lx_light2d_light l;
    memset(&l, 0, sizeof l);
    l.type = type;
    l.dir_x = 1.0f;
    l.arc = 60.0f;
    l.edge = LX_LIGHT2D_DEFAULT_EDGE;
    l.color = lx_v3(1.0f, 1.0f, 1.0f);
    l.intensity = 1.0f;
    l.falloff = LX_FALLOFF2D_SMOOTH;
    l.shadow = true;
    return l;
}

lx_status lx_light2d_light_validate(const lx_light2d_light *l)
{
    if (!l)
        return lx_fail_null(__func__, "light");
    if (l->type != LX_LIGHT2D_POINT && l->type != LX_LIGHT2D_SPOT)
        return lx_fail(LX_ERR_INVALID, "type %d is neither point nor spot", (int)l->type);
    if (l->falloff < LX_FALLOFF2D_SMOOTH || l->falloff > LX_FALLOFF2D_NONE)
        return lx_fail(LX_ERR_INVALID, "falloff %d is unknown", (int)l->falloff);
    const struct {
        const char *name;
        float v;
    } finite[] = {{"position", l->x},     {"position", l->y},         {"direction", l->dir_x},
                  {"direction", l->dir_y}, {"arc", l->arc},            {"edge", l->edge},
                  {"color", l->color.x},  {"color", l->color.y},      {"color", l->color.z},
                  {"intensity", l->intensity}, {"radius", l->radius}, {"softness", l->softness},
                  {"height", l->height}};
    for (size_t i = 0; i < sizeof finite / sizeof finite[0]; i++)
        if (!isfinite(finite[i].v))
            return lx_fail(LX_ERR_INVALID, "%s is not finite", finite[i].name);
    if (!(l->radius > 0.0f))
        return lx_fail(LX_ERR_INVALID, "radius %g must be > 0", l->radius);
    if (l->radius > 65536.0f)
        return lx_fail(LX_ERR_INVALID, "radius %g is more than 65536 pixels", l->radius);
    if (l->color.x < 0.0f || l->color.y < 0.0f || l->color.z < 0.0f)
        return lx_fail(LX_ERR_INVALID, "color has a negative component");
    if (l->intensity < 0.0f)
        return lx_fail(LX_ERR_INVALID, "intensity %g is negative", l->intensity);
    /* a bound far above any real light keeps every sum of lights finite
     * (an infinite colour times a zero falloff would be NaN) */
    float peak = l2_max(l->color.x, l2_max(l->color.y, l->color.z));
    if ((double)peak * l->intensity > LX_LIGHT2D_MAX_LIGHT)
        return lx_fail(LX_ERR_INVALID, "intensity %g x color %g is more than %g", l->intensity,
                       peak, LX_LIGHT2D_MAX_LIGHT);
    if (l->softness < 0.0f)
        return lx_fail(LX_ERR_INVALID, "softness %g is negative", l->softness);
    if (l->height < 0.0f)
        return lx_fail(LX_ERR_INVALID, "height %g is negative", l->height);
    if (fabsf(l->x) > 1e6f || fabsf(l->y) > 1e6f)
        return lx_fail(LX_ERR_INVALID, "position (%g, %g) is more than 1e6 pixels away", l->x,
                       l->y);
    if (l->type == LX_LIGHT2D_SPOT) {
        if (!(l->arc > 0.0f && l->arc <= 360.0f))
            return lx_fail(LX_ERR_INVALID, "arc %g must be in (0, 360]", l->arc);
        if (l->dir_x == 0.0f && l->dir_y == 0.0f)
            return lx_fail(LX_ERR_INVALID, "direction is zero");
        if (l->edge < 0.0f)
            return lx_fail(LX_ERR_INVALID, "edge %g is negative", l->edge);
    }
    return LX_OK;
}

lx_light2d_desc lx_light2d_desc_defaults(const lx_light2d_desc *desc)
{
    lx_light2d_desc d;
    if (desc)
        d = *desc;
    else
        memset(&d, 0, sizeof d);
    if (d.threshold == 0.0f)
        d.threshold = 0.5f;
    return d;
}

int l2_ray_count(const lx_light2d *ctx, float radius)
{
    if (ctx->polar_resolution > 0)
        return ctx->polar_resolution;
    /* a ray of pseudo-angle width 8/n spans at most 8/n radians (at the
     * middle of a face), so rays are under 0.9 pixel apart at the radius */
    double n = ceil(8.0 * (double)radius / 0.9);
    if (n < 64.0)
        n = 64.0;
    if (n > (1 << 20))
        n = 1 << 20;
    return ((int)n + 7) & ~7;
}

int lx_light2d_rays(const lx_light2d *ctx, const lx_light2d_light *light)
{
    return l2_ray_count(ctx, light->radius);
}

int lx_light2d_relit_count(const lx_light2d *ctx)
{
    return ctx->relit;
}

/* Caster bits of the rectangle from img. */
static void read_casters(lx_light2d *ctx, const lx_image *img, int x0, int y0, int x1, int y1)
{
    int ch = img->channels;
    int k = ctx->mask ? 0 : ch - 1;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            float a = img->data[((size_t)y * img->width + x) * ch + k];
            ctx->caster[(size_t)y * ctx->width + x] = a >= ctx->threshold ? 1 : 0;
        }
}

static bool is_caster(const lx_light2d *ctx, int x, int y)
{
    if (x < 0 || y < 0 || x >= ctx->width || y >= ctx->height)
        return false;
    return ctx->caster[(size_t)y * ctx->width + x] != 0;
}

lx_status l2_build_edges(lx_light2d *ctx)
{
    int tx = ctx->tiles_x, ty = ctx->tiles_y;
    size_t tiles = (size_t)tx * ty;
    uint32_t *count = calloc(tiles + 1, sizeof *count);
    if (!count)
        return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for the caster tiles");
    size_t total = 0;
    for (int y = 0; y < ctx->height; y++)
        for (int x = 0; x < ctx->width; x++) {
            if (!is_caster(ctx, x, y))
                continue;
            if (!is_caster(ctx, x - 1, y) || !is_caster(ctx, x + 1, y) ||
                !is_caster(ctx, x, y - 1) || !is_caster(ctx, x, y + 1)) {
                count[(size_t)(y / L2_TILE) * tx + x / L2_TILE]++;
                total++;
            }
        }
    l2_edge *edges = malloc((total ? total : 1) * sizeof *edges);
    if (!edges) {
        free(count);
        return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for %zu caster edges", total);
    }
    uint32_t run = 0;
    for (size_t t = 0; t < tiles; t++) {
        uint32_t c = count[t];
        count[t] = run;
        run += c;
    }
    count[tiles] = run;
    uint32_t *fill = malloc(tiles * sizeof *fill + 1);
    if (!fill) {
        free(count);
        free(edges);
        return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for the caster tiles");
    }
    memcpy(fill, count, tiles * sizeof *fill);
    /* tile by tile, rows inside a tile in order: the lists do not depend on
     * anything but the casters */
    for (int y = 0; y < ctx->height; y++)
        for (int x = 0; x < ctx->width; x++) {
            if (!is_caster(ctx, x, y))
                continue;
            uint8_t f = 0;
            f |= is_caster(ctx, x - 1, y) ? 0 : L2_FREE_LEFT;
            f |= is_caster(ctx, x + 1, y) ? 0 : L2_FREE_RIGHT;
            f |= is_caster(ctx, x, y - 1) ? 0 : L2_FREE_UP;
            f |= is_caster(ctx, x, y + 1) ? 0 : L2_FREE_DOWN;
            if (!f)
                continue;
            size_t t = (size_t)(y / L2_TILE) * tx + x / L2_TILE;
            edges[fill[t]++] = (l2_edge){(uint16_t)x, (uint16_t)y, f};
        }
    free(fill);
    memset(ctx->block_caster, 0, (size_t)ctx->blocks_x * ctx->blocks_y);
    for (int y = 0; y < ctx->height; y++)
        for (int x = 0; x < ctx->width; x++)
            if (ctx->caster[(size_t)y * ctx->width + x])
                ctx->block_caster[(size_t)(y / L2_BLOCK) * ctx->blocks_x + x / L2_BLOCK] = 1;
    free(ctx->tile_start);
    free(ctx->edges);
    ctx->tile_start = count;
    ctx->edges = edges;
    return LX_OK;
}

lx_status lx_light2d_create(const lx_image *casters, const lx_light2d_desc *desc,
                            lx_light2d **out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    *out = NULL;
    lx_light2d_desc d = lx_light2d_desc_defaults(desc);
    if (!casters || !casters->data || casters->width <= 0 || casters->height <= 0)
        return lx_fail(LX_ERR_INVALID, "casters: no image");
    if (casters->width > 65535 || casters->height > 65535)
        return lx_fail(LX_ERR_UNSUPPORTED, "casters: %dx%d is more than 65535 pixels a side",
                       casters->width, casters->height);
    if (!d.mask && casters->channels != 2 && casters->channels != 4)
        return lx_fail(LX_ERR_INVALID,
                       "casters: the image has no alpha channel (%d channel%s; a grey mask "
                       "needs the mask option)",
                       casters->channels, casters->channels == 1 ? "" : "s");
    if (!isfinite(d.threshold) || d.threshold < 0.0f || d.threshold > 1.0f)
        return lx_fail(LX_ERR_INVALID, "threshold %g must be in [0, 1]", d.threshold);
    if (d.polar_resolution < 0 || d.polar_resolution > (1 << 20))
        return lx_fail(LX_ERR_INVALID, "polar resolution %d must be in 0..%d",
                       d.polar_resolution, 1 << 20);
    lx_light2d *ctx = calloc(1, sizeof *ctx);
    if (!ctx)
        return lx_fail(LX_ERR_NOMEM, "light2d: out of memory");
    ctx->width = casters->width;
    ctx->height = casters->height;
    ctx->channels = casters->channels;
    ctx->mask = d.mask;
    ctx->threshold = d.threshold;
    ctx->threads = d.threads;
    ctx->polar_resolution = d.polar_resolution > 0 ? (d.polar_resolution + 7) & ~7 : 0;
    ctx->tiles_x = (ctx->width + L2_TILE - 1) / L2_TILE;
    ctx->tiles_y = (ctx->height + L2_TILE - 1) / L2_TILE;
    ctx->blocks_x = (ctx->width + L2_BLOCK - 1) / L2_BLOCK;
    ctx->blocks_y = (ctx->height + L2_BLOCK - 1) / L2_BLOCK;
    ctx->caster = calloc((size_t)ctx->width * ctx->height + L2_PAD, 1);
    ctx->block_caster = malloc((size_t)ctx->blocks_x * ctx->blocks_y);
    if (!ctx->caster || !ctx->block_caster) {
        free(ctx->caster);
        free(ctx->block_caster);
        free(ctx);
        return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for a %dx%d caster mask",
                       casters->width, casters->height);
    }
    read_casters(ctx, casters, 0, 0, ctx->width, ctx->height);
    lx_status st = l2_build_edges(ctx);
    if (st != LX_OK) {
        lx_light2d_destroy(ctx);
        return st;
    }
    *out = ctx;
    return LX_OK;
}

static void invalidate_all(lx_light2d *ctx)
{
    for (int i = 0; i < ctx->count; i++)
        ctx->preps[i].relight = true;
}

void lx_light2d_destroy(lx_light2d *ctx)
{
    if (!ctx)
        return;
    for (int i = 0; i < ctx->prep_capacity; i++) {
        free(ctx->preps[i].cache);
        l2_polar_free(&ctx->preps[i].polar);
    }
    free(ctx->preps);
    free(ctx->caster);
    free(ctx->block_caster);
    free(ctx->tile_start);
    free(ctx->edges);
    free(ctx->normals);
    free(ctx->work);
    free(ctx);
}

lx_status lx_light2d_set_normals(lx_light2d *ctx, const lx_image *normals, bool green_down)
{
    if (!ctx)
        return lx_fail_null(__func__, "ctx");
    if (!normals) {
        free(ctx->normals);
        ctx->normals = NULL;
        invalidate_all(ctx);
        return LX_OK;
    }
    if (normals->width != ctx->width || normals->height != ctx->height)
        return lx_fail(LX_ERR_INVALID, "casters: %dx%d but normals: %dx%d", ctx->width,
                       ctx->height, normals->width, normals->height);
    if (normals->channels < 3)
        return lx_fail(LX_ERR_INVALID, "normals: %d channel%s, not RGB", normals->channels,
                       normals->channels == 1 ? "" : "s");
    size_t count = (size_t)ctx->width * ctx->height;
    float *n = calloc(count * 3 + L2_PAD, sizeof *n);
    if (!n)
        return lx_fail(LX_ERR_NOMEM, "normals: out of memory");
    int ch = normals->channels;
    for (size_t i = 0; i < count; i++) {
        const float *c = normals->data + i * ch;
        /* tangent space: +x right, +y up the image (green up), +z out of
         * it; pixel space has +y down */
        float x = 2.0f * c[0] - 1.0f;
        float y = 2.0f * c[1] - 1.0f;
        float z = 2.0f * c[2] - 1.0f;
        if (!green_down)
            y = -y;
        float len = sqrtf(x * x + y * y + z * z);
        if (!(len > 1e-6f)) {
            x = 0.0f;
            y = 0.0f;
            z = 1.0f;
            len = 1.0f;
        }
        n[i] = x / len;
        n[count + i] = y / len;
        n[2 * count + i] = z / len;
    }
    free(ctx->normals);
    ctx->normals = n;
    invalidate_all(ctx);
    return LX_OK;
}

/* The pixels under a light's reach, clipped to the image (may be empty). */
static void light_box(const lx_light2d *ctx, const lx_light2d_light *l, int *x0, int *y0,
                      int *x1, int *y1)
{
    double r = l->radius;
    double a = floor(l->x - r), b = ceil(l->x + r) + 1.0;
    double c = floor(l->y - r), d = ceil(l->y + r) + 1.0;
    *x0 = (int)fmax(0.0, fmin(a, ctx->width));
    *x1 = (int)fmax(0.0, fmin(b, ctx->width));
    *y0 = (int)fmax(0.0, fmin(c, ctx->height));
    *y1 = (int)fmax(0.0, fmin(d, ctx->height));
}

lx_status lx_light2d_update_casters(lx_light2d *ctx, const lx_image *casters, int x, int y,
                                    int w, int h)
{
    if (!ctx)
        return lx_fail_null(__func__, "ctx");
    if (!casters || casters->width != ctx->width || casters->height != ctx->height)
        return lx_fail(LX_ERR_INVALID, "casters: the update is not %dx%d", ctx->width,
                       ctx->height);
    if (casters->channels != ctx->channels)
        return lx_fail(LX_ERR_INVALID, "casters: the update has %d channels, not %d",
                       casters->channels, ctx->channels);
    if (w <= 0 || h <= 0 || x < 0 || y < 0 || x > ctx->width - w || y > ctx->height - h)
        return lx_fail(LX_ERR_INVALID, "casters: rectangle %d,%d %dx%d is outside the %dx%d image",
                       x, y, w, h, ctx->width, ctx->height);
    read_casters(ctx, casters, x, y, x + w, y + h);
    lx_status st = l2_build_edges(ctx);
    if (st != LX_OK)
        return st;
    /* a light is touched when its reach (the square it lights and casts
     * from) meets the rectangle grown by the pixel whose boundary status
     * may have changed */
    for (int i = 0; i < ctx->count; i++) {
        const lx_light2d_light *l = &ctx->preps[i].l;
        double r = l->radius + 2.0;
        if (l->x + r >= x - 1 && l->x - r <= x + w + 1 && l->y + r >= y - 1 &&
            l->y - r <= y + h + 1)
            ctx->preps[i].relight = true;
    }
    return LX_OK;
}

/* Field by field: padding bytes may differ between equal lights. */
static bool same_light(const lx_light2d_light *a, const lx_light2d_light *b)
{
    return a->type == b->type && a->x == b->x && a->y == b->y && a->dir_x == b->dir_x &&
           a->dir_y == b->dir_y && a->arc == b->arc && a->edge == b->edge &&
           a->color.x == b->color.x && a->color.y == b->color.y && a->color.z == b->color.z &&
           a->intensity == b->intensity && a->radius == b->radius && a->falloff == b->falloff &&
           a->softness == b->softness && a->height == b->height && a->shadow == b->shadow &&
           a->self_shadow == b->self_shadow && a->dynamic == b->dynamic;
}

static void prepare(const lx_light2d *ctx, l2_prep *p)
{
    const lx_light2d_light *l = &p->l;
    light_box(ctx, l, &p->x0, &p->y0, &p->x1, &p->y1);
    p->r2 = l->radius * l->radius;
    p->inv_r = 1.0f / l->radius;
    p->inv_r2 = 1.0f / p->r2;
    p->rgb = lx_v3(l->color.x * l->intensity, l->color.y * l->intensity,
                   l->color.z * l->intensity);
    p->spot = l->type == LX_LIGHT2D_SPOT && l->arc < 360.0f;
    if (p->spot) {
        double len = hypot(l->dir_x, l->dir_y);
        p->dir_x = (float)(l->dir_x / len);
        p->dir_y = (float)(l->dir_y / len);
        double half = 0.5 * l->arc * 3.14159265358979323846 / 180.0;
        double inner = half - l->edge * 3.14159265358979323846 / 180.0;
        if (inner < 0.0)
            inner = 0.0;
        p->cos_outer = (float)cos(half);
        p->cos_inner = (float)cos(inner);
        p->inv_fade = p->cos_inner > p->cos_outer ? 1.0f / (p->cos_inner - p->cos_outer) : 0.0f;
    }
}

lx_status lx_light2d_set_lights(lx_light2d *ctx, const lx_light2d_light *lights, int count)
{
    if (!ctx)
        return lx_fail_null(__func__, "ctx");
    if (count < 0 || (count > 0 && !lights))
        return lx_fail(LX_ERR_INVALID, "light2d: %d lights and no array", count);
    for (int i = 0; i < count; i++) {
        lx_status st = lx_light2d_light_validate(&lights[i]);
        if (st != LX_OK) {
            char where[32];
            snprintf(where, sizeof where, "lights[%d]", i);
            lx_error_prefix(where);
            return st;
        }
    }
    /* What the lights will hold, counted before any of it is taken: a
     * static light caches its lit box (3 floats a pixel), a shadowed one
     * keeps its polar map. (The lights already held and unchanged are
     * counted too: an upper bound.) */
    uint64_t bytes = (uint64_t)count * sizeof(l2_prep);
    for (int i = 0; i < count; i++) {
        l2_prep probe = {.l = lights[i]};
        prepare(ctx, &probe);
        if (!probe.l.dynamic && probe.x1 > probe.x0 && probe.y1 > probe.y0)
            bytes += (uint64_t)(probe.x1 - probe.x0) * (uint64_t)(probe.y1 - probe.y0) * 3 *
                     sizeof(float);
        if (probe.l.shadow && probe.x1 > probe.x0 && probe.y1 > probe.y0)
            bytes += l2_polar_bytes(ctx, &probe.l);
    }
    char what[96];
    snprintf(what, sizeof what, "light2d: the caches and shadow maps of %d lights", count);
    lx_status enough = lx_check_memory(bytes, what);
    if (enough != LX_OK)
        return enough;
    if (count > ctx->prep_capacity) {
        l2_prep *p = realloc(ctx->preps, (size_t)count * sizeof *p);
        if (!p)
            return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for %d lights", count);
        memset(p + ctx->prep_capacity, 0, (size_t)(count - ctx->prep_capacity) * sizeof *p);
        ctx->preps = p;
        ctx->prep_capacity = count;
    }
    for (int i = 0; i < count; i++) {
        l2_prep *p = &ctx->preps[i];
        bool same = i < ctx->count && !lights[i].dynamic && !p->l.dynamic && p->cache &&
                    same_light(&p->l, &lights[i]);
        if (same)
            continue;
        p->l = lights[i];
        prepare(ctx, p);
        free(p->cache);
        p->cache = NULL;
        p->relight = true;
        if (!p->l.dynamic && p->x1 > p->x0 && p->y1 > p->y0) {
            size_t n = (size_t)(p->x1 - p->x0) * (size_t)(p->y1 - p->y0) * 3;
            p->cache = malloc(n * sizeof(float));
            if (!p->cache) {
                ctx->count = i;
                return lx_fail(LX_ERR_NOMEM, "light2d: out of memory for a light's cache");
            }
        }
    }
    ctx->count = count;
    return LX_OK;
}
