/* lx_prefilter: the specular mip chain of an environment, one level per
 * roughness (GGX, prefilter_ggx.c: a direct convolution, or importance
 * sampling where that costs less) or Phong exponent (prefilter_phong.c),
 * the direct convolutions by prefilter_conv.c. Builds the source's
 * solid-angle weighted mip chain and every level's plan once, then fills
 * every tile of every level in one OpenMP loop; each texel is computed
 * alone from read-only inputs, so the output is the same for any thread
 * count. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

float lx_ggx_level_roughness(int level, int count)
{
    if (count <= 1 || level <= 0)
        return 0.0f;
    if (level >= count - 1)
        return 1.0f;
    return (float)level / (float)(count - 1);
}

float lx_phong_level_exponent(int level)
{
    if (level <= 0)
        return 2048.0f;
    if (level >= 6)
        return 1.0f;
    return 2048.0f / (float)(1 << (2 * level));
}

lx_prefilter_desc lx_prefilter_desc_defaults(const lx_prefilter_desc *desc)
{
    lx_prefilter_desc d = {0};
    if (desc)
        d = *desc;
    /* size and mips depend on the source: lx_prefilter fills them */
    if (d.samples == 0)
        d.samples = 256;
    return d;
}

int lx_prefilter_size(int source_size, const lx_prefilter_desc *desc)
{
    if (desc && desc->size)
        return desc->size;
    return source_size < LX_PREFILTER_DEFAULT_SIZE ? source_size : LX_PREFILTER_DEFAULT_SIZE;
}

/* Checks desc against a source of face size source_size and fills size
 * and mips. */
static lx_status validate(int source_size, lx_prefilter_desc *d)
{
    if (source_size < 1 || source_size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "prefilter: source face size %d is outside 1..%d",
                       source_size, LX_MAX_CUBE_SIZE);
    if (d->filter != LX_SPECULAR_GGX && d->filter != LX_SPECULAR_PHONG)
        return lx_fail(LX_ERR_INVALID, "prefilter: unknown filter %d", (int)d->filter);
    d->size = lx_prefilter_size(source_size, d);
    if (d->size < 1 || d->size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "prefilter: face size %d is outside 1..%d", d->size,
                       LX_MAX_CUBE_SIZE);
    int most = lx_cube_mip_count(d->size);
    if (d->mips == 0)
        d->mips = most;
    if (d->mips < 1 || d->mips > most)
        return lx_fail(LX_ERR_INVALID,
                       "prefilter: %d mip levels asked; a %d x %d face has 1..%d (down to 1x1)",
                       d->mips, d->size, d->size, most);
    if (d->samples < 1 || d->samples > LX_PREFILTER_MAX_SAMPLES)
        return lx_fail(LX_ERR_INVALID, "prefilter: %d samples per texel is outside 1..%d",
                       d->samples, LX_PREFILTER_MAX_SAMPLES);
    if (d->filter == LX_SPECULAR_PHONG && d->phong_exponents)
        for (int i = 0; i < d->mips; i++) {
            float e = d->phong_exponents[i];
            if (!(e > 0.0f) || !(e <= 1e6f))
                return lx_fail(LX_ERR_INVALID,
                               "prefilter: Phong exponent %g of level %d is outside (0, 1e6]",
                               (double)e, i);
        }
    return lx_ibl_check_threads(d->threads);
}

static int level_size(const lx_prefilter_desc *d, int l)
{
    return d->size >> l > 0 ? d->size >> l : 1;
}

/* What one call computes: the source's chain sizes and each level's plan
 * (made from the sizes alone, before any texel is read). */
typedef struct plan {
    int sizes[LX_MAX_CUBE_MIPS + 1], chain_count;
    lx_ggx_plan *ggx[LX_MAX_CUBE_MIPS];
    lx_conv_plan *conv[LX_MAX_CUBE_MIPS];
    double cost[LX_MAX_CUBE_MIPS];
    bool sampled; /* some level samples the padded chain */
} plan;

static void plan_free(plan *p)
{
    for (int l = 0; l < LX_MAX_CUBE_MIPS; l++) {
        lx_ggx_plan_free(p->ggx[l]);
        lx_conv_plan_free(p->conv[l]);
        p->ggx[l] = NULL;
        p->conv[l] = NULL;
    }
}

/* The plans of every level of d for a source of face size n, and a check
 * that the call's whole peak fits in memory: the source, its mip chain,
 * padded copies of the chain (when a level samples it), the convolutions'
 * lights and the levels. */
static lx_status make_plan(int n, const lx_prefilter_desc *d, plan *p)
{
    memset(p, 0, sizeof *p);
    p->chain_count = lx_ibl_chain_sizes(n, 1, p->sizes);
    uint64_t source = lx_ibl_cube_bytes(n), chain = lx_ibl_chain_bytes(n, 1), levels = 0;
    for (int l = 0; l < d->mips; l++)
        levels += lx_ibl_cube_bytes(level_size(d, l));
    char what[400], a[32], b[32], c[32], e[32], f[32];
    lx_format_bytes(source, a, sizeof a);
    lx_format_bytes(chain, b, sizeof b);
    lx_format_bytes(levels, f, sizeof f);
    snprintf(what, sizeof what,
             "prefilter: a %d x %d source (%s) with its mips (%s) into %d levels of %d x %d and "
             "down (%s)",
             n, n, a, b, d->mips, d->size, d->size, f);
    /* the source, its chain and the levels, before anything is made */
    lx_status st = lx_check_memory(source + chain + levels, what);
    for (int l = 0; l < d->mips && st == LX_OK; l++) {
        int size = level_size(d, l);
        p->cost[l] = 1.0;
        if (d->filter == LX_SPECULAR_PHONG) {
            float n_l = d->phong_exponents ? d->phong_exponents[l] : lx_phong_level_exponent(l);
            lx_lobe lobe = lx_phong_lobe(n_l);
            st = lx_conv_plan_create(p->sizes, p->chain_count, &lobe, size, HUGE_VAL, &p->conv[l]);
            if (st == LX_OK)
                p->cost[l] = lx_conv_plan_cost(p->conv[l]);
        } else if (l > 0) {
            st = lx_ggx_level_plan(p->sizes, p->chain_count, lx_ggx_level_roughness(l, d->mips),
                                   d->samples, size, &p->conv[l], &p->ggx[l], &p->cost[l]);
            p->sampled = p->sampled || p->ggx[l];
        }
    }
    if (st != LX_OK) {
        plan_free(p);
        return st;
    }
    uint64_t pads = 0, lights = 0;
    for (int i = 0; p->sampled && i < p->chain_count; i++)
        pads += lx_ibl_padded_bytes(p->sizes[i]);
    for (int l = 0; l < d->mips; l++)
        if (p->conv[l])
            lights += lx_conv_plan_bytes(p->conv[l]);
    lx_format_bytes(pads, c, sizeof c);
    lx_format_bytes(lights, e, sizeof e);
    snprintf(what, sizeof what,
             "prefilter: a %d x %d source (%s) with its mips (%s), padded copies (%s) and "
             "convolution work (%s) into %d levels of %d x %d and down (%s)",
             n, n, a, b, c, e, d->mips, d->size, d->size, f);
    st = lx_check_memory(source + chain + pads + lights + levels, what);
    if (st != LX_OK)
        plan_free(p);
    return st;
}

lx_status lx_prefilter_check(int source_size, const lx_prefilter_desc *desc)
{
    lx_prefilter_desc d = lx_prefilter_desc_defaults(desc);
    lx_status st = validate(source_size, &d);
    if (st != LX_OK)
        return st;
    plan p;
    st = make_plan(source_size, &d, &p);
    plan_free(&p);
    return st;
}

/* Level 0 of GGX (roughness 0): the source at the level's size, from the
 * mip of that size when there is one, else bilinear from the smallest mip
 * at least that size. */
static const lx_cubemap *mirror_source(const lx_ibl_chain *chain, int size, bool *exact)
{
    int pick = 0;
    for (int i = 0; i < chain->count; i++)
        if (chain->level[i].size >= size)
            pick = i;
    *exact = chain->level[pick].size == size;
    return &chain->level[pick];
}

static void mirror_tile(const lx_cubemap *from, bool exact, lx_cubemap *out, int face, int x0,
                        int y0, int x1, int y1)
{
    int m = out->size;
    for (int y = y0; y < y1; y++) {
        if (exact) {
            memcpy(lx_cubemap_texel(out, face, x0, y), lx_cubemap_texel(from, face, x0, y),
                   sizeof(float) * 3 * (size_t)(x1 - x0));
            continue;
        }
        for (int x = x0; x < x1; x++)
            lx_ibl_sample(from, lx_cube_direction(face, (x + 0.5f) / m, (y + 0.5f) / m),
                          lx_cubemap_texel(out, face, x, y));
    }
}

typedef struct tile {
    int level, face, x0, y0, x1, y1;
} tile;

/* The state the parallel steps share. */
typedef struct job {
    plan *p;
    lx_ibl_chain *chain;
    lx_ibl_padded *pads;
    lx_cubemap *levels;
    const tile *tiles;
    const lx_cubemap *mirror;
    bool mirror_exact;
    int conv_levels[LX_MAX_CUBE_MIPS];
    double *flux[LX_MAX_CUBE_MIPS + 1]; /* per chain level the convolutions read */
} job;

static bool fill_item(void *ctx, int i)
{
    job *j = ctx;
    lx_conv_plan *c = j->p->conv[j->conv_levels[i]];
    return lx_conv_plan_fill(c, j->chain, j->flux[lx_conv_plan_level(c)]) == LX_OK;
}

static bool pad_item(void *ctx, int i)
{
    job *j = ctx;
    return lx_ibl_pad(&j->chain->level[i], &j->pads[i]) == LX_OK;
}

static bool tile_item(void *ctx, int i)
{
    const job *j = ctx;
    const tile *t = &j->tiles[i];
    lx_cubemap *out = &j->levels[t->level];
    if (j->p->conv[t->level])
        return lx_conv_tile(j->p->conv[t->level], out, t->face, t->x0, t->y0, t->x1, t->y1);
    if (j->p->ggx[t->level])
        lx_ggx_tile(j->p->ggx[t->level], j->pads, out, t->face, t->x0, t->y0, t->x1, t->y1);
    else
        mirror_tile(j->mirror, j->mirror_exact, out, t->face, t->x0, t->y0, t->x1, t->y1);
    return true;
}

static void free_levels(lx_cubemap *levels, int count)
{
    for (int i = 0; i < count; i++)
        lx_cubemap_free(&levels[i]);
}

lx_status lx_prefilter(const lx_cubemap *src, const lx_prefilter_desc *in,
                       lx_cubemap levels[LX_MAX_CUBE_MIPS], int *count)
{
    if (!levels || !count)
        return lx_fail(LX_ERR_INVALID, "prefilter: no output levels or count (NULL)");
    *count = 0;
    memset(levels, 0, sizeof(lx_cubemap) * LX_MAX_CUBE_MIPS);
    lx_prefilter_desc d = lx_prefilter_desc_defaults(in);
    lx_status st = lx_ibl_check_cubemap(src, "prefilter: source cube map", true);
    if (st == LX_OK)
        st = validate(src->size, &d);
    if (st != LX_OK)
        return st;
    char name[96];
    snprintf(name, sizeof name, "prefilter: %d x %d specular faces from a %d x %d source", d.size,
             d.size, src->size, src->size);
    lx_ibl_warn_upsampling(name, d.size, src->size);
    plan p;
    if ((st = make_plan(src->size, &d, &p)) != LX_OK)
        return st;
    int mips = d.mips;
    lx_ibl_run run = lx_ibl_run_make(d.threads, d.progress, d.progress_user);

    lx_ibl_chain chain;
    lx_ibl_padded pads[LX_MAX_CUBE_MIPS + 1] = {{0}};
    tile *tiles = NULL;
    job j = {.p = &p, .chain = &chain, .pads = pads, .levels = levels};
    lx_ibl_run part = lx_ibl_run_part(&run, 0.0, 0.04);
    st = lx_ibl_chain_build(src, 1, &part, &chain);
    if (st != LX_OK) {
        plan_free(&p);
        return st;
    }
    /* the flux vectors of the chain levels the convolutions read, each
     * from the next finer one where the sizes nest; then the lights and
     * the padded chain, level by level */
    int nconv = 0;
    bool used[LX_MAX_CUBE_MIPS + 1] = {false};
    for (int l = 0; l < mips; l++)
        if (p.conv[l]) {
            j.conv_levels[nconv++] = l;
            used[lx_conv_plan_level(p.conv[l])] = true;
        }
    int nused = 0, done = 0;
    for (int i = 1; i < chain.count; i++)
        nused += used[i];
    for (int i = 1, finer = 0; i < chain.count && st == LX_OK; i++)
        if (used[i]) {
            part =
                lx_ibl_run_part(&run, 0.04 + 0.02 * done / nused, 0.04 + 0.02 * (done + 1) / nused);
            st = lx_conv_flux(&chain, i, finer ? j.flux[finer] : NULL, finer, &part, &j.flux[i]);
            finer = i, done++;
        }
    part = lx_ibl_run_part(&run, 0.06, 0.08);
    if (st == LX_OK)
        st = lx_ibl_for(&part, nconv, NULL, fill_item, &j, "prefilter");
    part = lx_ibl_run_part(&run, 0.08, 0.1);
    if (st == LX_OK && p.sampled)
        st = lx_ibl_for(&part, chain.count, NULL, pad_item, &j, "prefilter");
    int ntiles = 0;
    for (int l = 0; l < mips && st == LX_OK; l++) {
        int size = level_size(&d, l), side = (size + LX_IBL_TILE - 1) / LX_IBL_TILE;
        st = lx_cubemap_alloc(&levels[l], size);
        ntiles += 6 * side * side;
    }
    if (st == LX_OK)
        j.mirror = mirror_source(&chain, levels[0].size, &j.mirror_exact);
    double *cost = NULL;
    if (st == LX_OK && (!(tiles = malloc(sizeof(tile) * (size_t)ntiles)) ||
                        !(cost = malloc(sizeof(double) * (size_t)ntiles))))
        st = lx_fail(LX_ERR_NOMEM, "prefilter: out of memory");
    if (st == LX_OK) {
        /* every tile of every level in one loop, each weighed by its cost */
        int k = 0;
        for (int l = 0; l < mips; l++) {
            int size = levels[l].size, side = (size + LX_IBL_TILE - 1) / LX_IBL_TILE;
            for (int face = 0; face < 6; face++)
                for (int ty = 0; ty < side; ty++)
                    for (int tx = 0; tx < side; tx++, k++) {
                        tile *t = &tiles[k];
                        t->level = l, t->face = face;
                        t->x0 = tx * LX_IBL_TILE, t->y0 = ty * LX_IBL_TILE;
                        t->x1 = t->x0 + LX_IBL_TILE < size ? t->x0 + LX_IBL_TILE : size;
                        t->y1 = t->y0 + LX_IBL_TILE < size ? t->y0 + LX_IBL_TILE : size;
                        cost[k] = p.cost[l] * (t->x1 - t->x0) * (t->y1 - t->y0);
                    }
        }
        j.tiles = tiles;
        part = lx_ibl_run_part(&run, 0.1, 1.0);
        st = lx_ibl_for(&part, ntiles, cost, tile_item, &j, "prefilter");
    }
    free(tiles);
    free(cost);
    for (int i = 0; i <= LX_MAX_CUBE_MIPS; i++)
        free(j.flux[i]);
    plan_free(&p);
    for (int i = 0; i < chain.count; i++)
        lx_ibl_padded_free(&pads[i]);
    lx_ibl_chain_free(&chain);
    if (st != LX_OK) {
        free_levels(levels, mips);
        return st;
    }
    *count = mips;
    return LX_OK;
}
