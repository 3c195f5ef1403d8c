/* Guided gathers: where a tile's light comes from, learned from its first
 * round of cosine-weighted rays and sampled by the rounds after it.
 *
 * A gather's noise comes from the few directions that bring most of the
 * light (the pool of a spot on the floor, a sunlit wall seen from the
 * shade); cosine-weighted rays find them by chance. The guide is a
 * histogram over the sphere of directions in world space, in cells of
 * the octahedral map (no trigonometry to find or draw a cell; a cell's
 * solid angle is its area over (|x| + |y| + |z|)^3, the map's Jacobian),
 * filled with the luminance the first round's
 * rays brought over the estimator's pdf (so a cell holds an estimate of
 * the integral of L cos over it, summed over the tile's texels), smoothed
 * by one [1 2 1] pass each way and turned into an alias table. The later rounds
 * draw half their rays from it and half cosine-weighted and weigh each by
 * the balance heuristic (Veach's multi-sample MIS), so a wrong guide can
 * at most about double a texel's variance, never bias it: this is the
 * spirit of "practical path guiding" (Mueller et al. 2017) for one bounce,
 * with a tile of 8 x 8 texels as the spatial cell. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <string.h>

/* The octahedral map of a unit direction to [0, 1)^2 (the lower half
 * folded over the upper's corners) and back; area-preserving folds, so a
 * solid angle dw is dA (|x| + |y| + |z|)^3 x 4 with dA in [0, 1)^2. */
static void octahedral_of(lx_vec3 d, float *s, float *t)
{
    float l1 = fabsf(d.x) + fabsf(d.y) + fabsf(d.z);
    float x = d.x / l1, y = d.y / l1;
    if (d.z < 0.0f) {
        float fx = (1.0f - fabsf(y)) * (x >= 0.0f ? 1.0f : -1.0f);
        float fy = (1.0f - fabsf(x)) * (y >= 0.0f ? 1.0f : -1.0f);
        x = fx, y = fy;
    }
    *s = 0.5f * x + 0.5f;
    *t = 0.5f * y + 0.5f;
}

static lx_vec3 direction_of(float s, float t)
{
    float x = 2.0f * s - 1.0f, y = 2.0f * t - 1.0f;
    float z = 1.0f - fabsf(x) - fabsf(y);
    if (z < 0.0f) {
        float fx = (1.0f - fabsf(y)) * (x >= 0.0f ? 1.0f : -1.0f);
        float fy = (1.0f - fabsf(x)) * (y >= 0.0f ? 1.0f : -1.0f);
        x = fx, y = fy;
    }
    return lx_normalize(lx_v3(x, y, z));
}

static uint32_t cell_of(lx_vec3 d)
{
    float s, t;
    octahedral_of(d, &s, &t);
    int ix = (int)(s * (float)LX_GUIDE_SIDE), iy = (int)(t * (float)LX_GUIDE_SIDE);
    ix = ix < 0 ? 0 : ix >= LX_GUIDE_SIDE ? LX_GUIDE_SIDE - 1 : ix;
    iy = iy < 0 ? 0 : iy >= LX_GUIDE_SIDE ? LX_GUIDE_SIDE - 1 : iy;
    return (uint32_t)(iy * LX_GUIDE_SIDE + ix);
}

void lx_gi_guide_clear(lx_gi_guide *g)
{
    memset(g->cell, 0, sizeof g->cell);
    g->ready = false;
}

void lx_gi_guide_add(lx_gi_guide *g, lx_vec3 dir, float value)
{
    if (value > 0.0f && isfinite(value))
        g->cell[cell_of(dir)] += value;
}

bool lx_gi_guide_build(lx_gi_guide *g)
{
    /* smooth by [1 2 1] each way (edges clamped): a cell's light also
     * lights its neighbours' directions more often than not, and a first
     * round leaves gaps */
    enum { N = LX_GUIDE_SIDE };
    float tmp[LX_GUIDE_BINS];
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            const float *row = g->cell + y * N;
            int l = x > 0 ? x - 1 : x, r = x + 1 < N ? x + 1 : x;
            tmp[y * N + x] = 0.25f * row[l] + 0.5f * row[x] + 0.25f * row[r];
        }
    double total = 0.0;
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            int lo = y > 0 ? y - 1 : y, hi = y + 1 < N ? y + 1 : y;
            float v = 0.25f * tmp[lo * N + x] + 0.5f * tmp[y * N + x] + 0.25f * tmp[hi * N + x];
            g->cell[y * N + x] = v;
            total += v;
        }
    g->ready = total > 0.0 && isfinite(total);
    if (!g->ready)
        return false;
    /* the cells' probabilities and Vose's alias table: a cell is drawn in
     * constant time, without a search through cold memory */
    uint16_t small[LX_GUIDE_BINS], large[LX_GUIDE_BINS];
    float scaled[LX_GUIDE_BINS];
    int ns = 0, nl = 0;
    for (int c = 0; c < LX_GUIDE_BINS; c++) {
        g->prob[c] = (float)(g->cell[c] / total);
        scaled[c] = (float)(g->cell[c] / total * LX_GUIDE_BINS);
        if (scaled[c] < 1.0f)
            small[ns++] = (uint16_t)c;
        else
            large[nl++] = (uint16_t)c;
    }
    while (ns && nl) {
        uint16_t s = small[--ns], l = large[nl - 1];
        g->keep[s] = scaled[s];
        g->alias[s] = l;
        scaled[l] -= 1.0f - scaled[s];
        if (scaled[l] < 1.0f) {
            nl--;
            small[ns++] = l;
        }
    }
    /* what is left is 1 up to rounding */
    while (nl) {
        uint16_t l = large[--nl];
        g->keep[l] = 1.0f;
        g->alias[l] = l;
    }
    while (ns) {
        uint16_t s = small[--ns];
        g->keep[s] = 1.0f;
        g->alias[s] = s;
    }
    return true;
}

lx_vec3 lx_gi_guide_sample(const lx_gi_guide *g, float u, float u1, float u2)
{
    float x = u * (float)LX_GUIDE_BINS;
    int c = (int)x;
    c = c < 0 ? 0 : c >= LX_GUIDE_BINS ? LX_GUIDE_BINS - 1 : c;
    if (!(x - (float)c < g->keep[c]))
        c = g->alias[c];
    int ix = c % LX_GUIDE_SIDE, iy = c / LX_GUIDE_SIDE;
    return direction_of(((float)ix + u1) / (float)LX_GUIDE_SIDE,
                        ((float)iy + u2) / (float)LX_GUIDE_SIDE);
}

float lx_gi_guide_pdf(const lx_gi_guide *g, lx_vec3 dir)
{
    uint32_t c = cell_of(dir);
    float l1 = fabsf(dir.x) + fabsf(dir.y) + fabsf(dir.z);
    /* the cell's probability over its area in [0, 1)^2, by dA / dw */
    return g->prob[c] * (float)LX_GUIDE_BINS / (4.0f * l1 * l1 * l1);
}
