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

static lx_status validate(const lx_cubemap *src, lx_prefilter_desc *d)
{
    lx_status st = lx_ibl_check_cubemap(src, "prefilter: source cube map", true);
    if (st != LX_OK)
        return st;
    if (d->filter != LX_SPECULAR_GGX && d->filter != LX_SPECULAR_PHONG)
        return lx_fail(LX_ERR_INVALID, "prefilter: unknown filter %d", (int)d->filter);
    if (d->size == 0)
        d->size = src->size < 256 ? src->size : 256;
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
    if (d->samples < 1 || d->samples > 65536)
        return lx_fail(LX_ERR_INVALID, "prefilter: %d samples per texel is outside 1..65536",
                       d->samples);
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
    lx_status st = validate(src, &d);
    if (st != LX_OK)
        return st;
    int threads = lx_thread_count(d.threads);
    int mips = d.mips;

    lx_ibl_chain chain;
    if ((st = lx_ibl_chain_build(src, 1, threads, &chain)) != LX_OK)
        return st;
    lx_ibl_padded pads[LX_MAX_CUBE_MIPS + 1] = {{0}};
    lx_ggx_plan *ggx[LX_MAX_CUBE_MIPS] = {0};
    lx_conv_plan *conv[LX_MAX_CUBE_MIPS] = {0};
    bool sampled = false;
    const lx_cubemap *mirror = NULL;
    bool mirror_exact = false;
    double cost[LX_MAX_CUBE_MIPS];
    tile *tiles = NULL;
    int ntiles = 0;
    for (int l = 0; l < mips && st == LX_OK; l++) {
        int size = d.size >> l > 0 ? d.size >> l : 1;
        st = lx_cubemap_alloc(&levels[l], size);
        if (st != LX_OK)
            break;
        cost[l] = 1.0;
        if (d.filter == LX_SPECULAR_PHONG) {
            float e = d.phong_exponents ? d.phong_exponents[l] : lx_phong_level_exponent(l);
            lx_lobe lobe = lx_phong_lobe(e);
            st = lx_conv_plan_build(&chain, &lobe, size, HUGE_VAL, &conv[l]);
            if (st == LX_OK)
                cost[l] = lx_conv_plan_cost(conv[l]);
        } else if (l == 0) {
            mirror = mirror_source(&chain, size, &mirror_exact);
        } else {
            st = lx_ggx_level_build(&chain, lx_ggx_level_roughness(l, mips), d.samples, size,
                                    &conv[l], &ggx[l], &cost[l]);
            sampled = sampled || ggx[l];
        }
        int side = (size + LX_IBL_TILE - 1) / LX_IBL_TILE;
        ntiles += 6 * side * side;
    }
    /* importance samples read the chain's levels through a border */
    for (int i = 0; sampled && i < chain.count && st == LX_OK; i++)
        st = lx_ibl_pad(&chain.level[i], &pads[i]);
    if (st == LX_OK && !(tiles = malloc(sizeof(tile) * (size_t)ntiles)))
        st = lx_fail(LX_ERR_NOMEM, "out of memory");
    double total = 0.0;
    if (st == LX_OK) {
        int k = 0;
        for (int l = 0; l < mips; l++) {
            int size = levels[l].size, side = (size + LX_IBL_TILE - 1) / LX_IBL_TILE;
            for (int face = 0; face < 6; face++)
                for (int ty = 0; ty < side; ty++)
                    for (int tx = 0; tx < side; tx++) {
                        tile *t = &tiles[k++];
                        t->level = l, t->face = face;
                        t->x0 = tx * LX_IBL_TILE, t->y0 = ty * LX_IBL_TILE;
                        t->x1 = t->x0 + LX_IBL_TILE < size ? t->x0 + LX_IBL_TILE : size;
                        t->y1 = t->y0 + LX_IBL_TILE < size ? t->y0 + LX_IBL_TILE : size;
                    }
            total += cost[l] * 6.0 * size * size;
        }
    }

    if (st == LX_OK) {
        lx_ibl_progress prog;
        lx_ibl_progress_init(&prog, d.progress, d.progress_user, total, 0.0f, 1.0f);
        volatile int nomem = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
        for (int i = 0; i < ntiles; i++) {
            if (prog.cancelled || nomem)
                continue;
            const tile *t = &tiles[i];
            lx_cubemap *out = &levels[t->level];
            if (conv[t->level]) {
                if (!lx_conv_tile(conv[t->level], out, t->face, t->x0, t->y0, t->x1, t->y1))
                    nomem = 1;
            } else if (!ggx[t->level]) {
                mirror_tile(mirror, mirror_exact, out, t->face, t->x0, t->y0, t->x1, t->y1);
            } else {
                lx_ggx_tile(ggx[t->level], pads, out, t->face, t->x0, t->y0, t->x1, t->y1);
            }
            lx_ibl_progress_add(&prog, cost[t->level] * (t->x1 - t->x0) * (t->y1 - t->y0));
        }
        if (nomem)
            st = lx_fail(LX_ERR_NOMEM, "prefilter: out of memory");
        else if (!lx_ibl_progress_end(&prog))
            st = lx_fail(LX_ERR_CANCELLED, "prefilter cancelled");
    }

    free(tiles);
    for (int l = 0; l < mips; l++) {
        lx_ggx_plan_free(ggx[l]);
        lx_conv_plan_free(conv[l]);
    }
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
