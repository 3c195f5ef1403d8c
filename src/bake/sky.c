/* Sky light in the baker: the environment's irradiance at each
 * texel, either unshadowed from its order-2 spherical harmonics
 * (Ramamoorthi & Hanrahan 2001, ibl/sh.c) or with sky visibility, by rays
 * that escape the scene bringing the environment they see.
 *
 * With rays the environment is box-filtered to at most LX_SKY_LOOKUP_SIZE
 * texels a side and split in two, L = base + peak, where peak is the
 * texels brighter than LX_SKY_PEAK_RATIO times the mean luminance (a sun,
 * a window), taken whole, and base the rest:
 * - base by stratified cosine-weighted rays over the texel's hemisphere
 *   (Malley's method: points uniform on the unit disk lifted onto the
 *   hemisphere), E = pi / N sum base(w);
 * - peak by rays toward its texels, each chosen with probability
 *   proportional to its peak luminance times solid angle (the seed's "every
 *   texel a directional light", sampled by importance), jittered within the
 *   texel: E = P / M sum cos(w) over the rays that escape, P the peak's
 *   total, within the texel at Halton points (bases 2, 3) shifted per
 *   lightmap texel. A sun then casts clean shadows with a few dozen rays,
 *   where cosine rays alone would almost never find it. Taking the bright
 *   texels whole leaves the cosine rays none of the sun to find by chance:
 *   keeping the part below the threshold in the base (the mean itself
 *   raised by the sun) made a sun texel's base 1% of its light, found by
 *   one cosine ray in 200, and 1% noise in the test's sun-lit texels. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LX_SKY_LOOKUP_SIZE 64
#define LX_SKY_DEFAULT_SAMPLES 64u
#define LX_SKY_PEAK_RATIO 8.0
/* Brightest sky texel (nits, intensity applied) the baker takes: its SH
 * coefficients (up to 2 sqrt(pi) L), irradiance (pi L, plus ringing) and
 * peak estimates (at most 4 pi L / 0.0722 for a pure blue sun) then stay
 * well inside a float. */
#define LX_SKY_MAX_RADIANCE 1e36

/* Splits the lookup into base (kept in b->sky_lookup) and peak
 * (b->sky_peak), and builds the peak's sampling table. */
static lx_status split_peak(lx_baker *b)
{
    lx_cubemap *base = &b->sky_lookup;
    int n = base->size;
    size_t texels = (size_t)6 * n * n;
    double sum = 0.0;
    for (size_t i = 0; i < texels; i++) {
        int y = (int)(i / (size_t)n % (size_t)n), x = (int)(i % (size_t)n);
        sum += lx_luminance(base->data + 3 * i) * lx_cube_texel_solid_angle(n, x, y);
    }
    double threshold = LX_SKY_PEAK_RATIO * sum / (4.0 * LX_PI);
    double *cdf = malloc(sizeof(double) * (texels + 1));
    float *peak = calloc(texels * 3, sizeof(float));
    if (!cdf || !peak) {
        free(cdf);
        free(peak);
        return lx_fail(LX_ERR_NOMEM, "sky: out of memory");
    }
    cdf[0] = 0.0;
    for (size_t i = 0; i < texels; i++) {
        int y = (int)(i / (size_t)n % (size_t)n), x = (int)(i % (size_t)n);
        float *t = base->data + 3 * i;
        double lum = lx_luminance(t);
        double share = 0.0;
        if (lum > threshold) {
            /* the whole texel */
            for (int k = 0; k < 3; k++) {
                peak[3 * i + k] = t[k];
                t[k] = 0.0f;
            }
            share = lum * lx_cube_texel_solid_angle(n, x, y);
        }
        cdf[i + 1] = cdf[i] + share;
    }
    if (!(cdf[texels] > 0.0)) {
        free(cdf);
        free(peak);
        return LX_OK; /* nothing stands out: cosine rays suffice */
    }
    b->sky_peak = peak;
    b->sky_peak_cdf = cdf;
    return LX_OK;
}

/* Lowest SH irradiance over a spread of normals (a Fibonacci sphere). */
static float sh_minimum(const lx_sh9 *sh)
{
    const int n = 2048;
    float lowest = INFINITY;
    for (int i = 0; i < n; i++) {
        float y = 1.0f - 2.0f * ((float)i + 0.5f) / (float)n;
        float r = sqrtf(fmaxf(0.0f, 1.0f - y * y));
        float phi = (float)i * 2.39996323f; /* the golden angle */
        float e[3];
        lx_sh_irradiance(sh, lx_v3(r * cosf(phi), y, r * sinf(phi)), e);
        for (int k = 0; k < 3; k++)
            lowest = fminf(lowest, e[k]);
    }
    return lowest;
}

lx_status lx_sky_prepare(lx_baker *b, const lx_sky_desc *sky)
{
    if (!sky->environment)
        return LX_OK;
    const lx_cubemap *env = sky->environment;
    if (!env->data || env->size < 1)
        return lx_fail(LX_ERR_INVALID, "sky: the environment cube map is empty");
    if (!(sky->intensity >= 0.0f) || !isfinite(sky->intensity))
        return lx_fail(LX_ERR_INVALID, "sky: intensity must be finite and >= 0");
    if (sky->samples > LX_MAX_SKY_SAMPLES)
        return lx_fail(LX_ERR_INVALID, "sky: samples %u is above %u", sky->samples,
                       LX_MAX_SKY_SAMPLES);
    float scale = sky->intensity > 0.0f ? sky->intensity : 1.0f;
    /* the baker's threads bound the sky's filters too */
    lx_ibl_desc run = {.threads = b->desc.threads};
    lx_status st = lx_sh_project(env, &run, &b->sky_sh);
    if (st != LX_OK) {
        lx_error_prefix("sky");
        return st;
    }
    /* finite now (the projection checked): negative radiance has no
     * meaning, and too bright a sky overflows once scaled */
    size_t values = (size_t)env->size * (size_t)env->size * 18, negative = 0;
    float brightest = 0.0f;
    for (size_t i = 0; i < values; i++) {
        negative += env->data[i] < 0.0f;
        brightest = fmaxf(brightest, env->data[i]);
    }
    if (negative)
        return lx_fail(LX_ERR_INVALID,
                       "sky: %zu environment values are negative; an environment needs "
                       "radiance >= 0",
                       negative);
    if (!((double)brightest * scale <= LX_SKY_MAX_RADIANCE))
        return lx_fail(LX_ERR_INVALID,
                       "sky: intensity %g times the brightest texel (%g nt) would overflow; "
                       "the sky may reach %g nt",
                       (double)scale, (double)brightest, LX_SKY_MAX_RADIANCE);
    for (int i = 0; i < 9; i++)
        for (int k = 0; k < 3; k++)
            b->sky_sh.c[i][k] *= scale;
    b->sky_samples = sky->samples ? sky->samples : LX_SKY_DEFAULT_SAMPLES;
    b->sky_shadows = sky->shadows;
    b->has_sky = true;
    if (!sky->shadows) {
        float lowest = sh_minimum(&b->sky_sh);
        if (lowest < 0.0f)
            lx_log(LX_LOG_WARN,
                   "sky: its spherical-harmonic irradiance dips to %g lx for some normals "
                   "(ringing around a small, bright source); those texels get 0. Sky shadows "
                   "sample the environment itself",
                   (double)lowest);
        return LX_OK;
    }
    /* the lookup for escaping rays: box-filtered to the size halving
     * reaches below LX_SKY_LOOKUP_SIZE (in one pass), scaled */
    int size = env->size;
    while (size > LX_SKY_LOOKUP_SIZE)
        size = size / 2 > 0 ? size / 2 : 1;
    lx_cubemap level;
    if ((st = lx_cubemap_downsample(env, size, &run, &level)) != LX_OK)
        return st;
    size_t n = (size_t)level.size * level.size * 18;
    for (size_t i = 0; i < n; i++)
        level.data[i] *= scale;
    b->sky_lookup = level;
    return split_peak(b);
}

void lx_sky_free(lx_baker *b)
{
    lx_cubemap_free(&b->sky_lookup);
    free(b->sky_peak);
    free(b->sky_peak_cdf);
    b->sky_peak = NULL;
    b->sky_peak_cdf = NULL;
    b->has_sky = false;
}

/* The texel of a cube map face-major texel index. */
static void texel_of(int n, size_t i, int *face, int *x, int *y)
{
    size_t per_face = (size_t)n * (size_t)n;
    *face = (int)(i / per_face);
    *y = (int)(i % per_face / (size_t)n);
    *x = (int)(i % (size_t)n);
}

/* The texel index a direction falls in (nearest: the lookup is already
 * filtered, and the base must match the texels the peak was cut from). */
static size_t texel_index(int n, lx_vec3 d)
{
    int face, x, y;
    lx_cube_texel_at(d, n, &face, &x, &y);
    return ((size_t)face * (size_t)n + (size_t)y) * (size_t)n + (size_t)x;
}

/* The first texel whose cumulative share exceeds u * total. */
static size_t pick_texel(const double *cdf, size_t count, double u)
{
    double target = u * cdf[count];
    size_t lo = 0, hi = count - 1;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (cdf[mid + 1] <= target)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* The radical inverse of k in a base: its digits mirrored about the point. */
static float radical_inverse(uint32_t k, uint32_t base)
{
    double inv = 1.0 / base, f = inv, r = 0.0;
    for (; k; k /= base, f *= inv)
        r += (double)(k % base) * f;
    return (float)r;
}

/* v + offset, wrapped into [0, 1) (a Cranley-Patterson rotation). */
static float shifted(float v, float offset)
{
    float r = v + offset;
    r = r >= 1.0f ? r - 1.0f : r;
    return r < 1.0f ? r : 0.99999994f;
}

void lx_cosine_strata(uint32_t count, uint32_t *sx, uint32_t *sy)
{
    uint32_t x = (uint32_t)sqrtf((float)count);
    x = x ? x : 1u;
    *sx = x;
    *sy = (count + x - 1) / x;
}

lx_vec3 lx_cosine_direction(lx_vec3 t, lx_vec3 bt, lx_vec3 n, uint32_t map, uint32_t pixel,
                            uint32_t k, uint32_t sx, uint32_t sy, uint32_t key)
{
    float u = ((float)(k % sx) + lx_random(map, pixel, k, key)) / (float)sx;
    float v = ((float)(k / sx) + lx_random(map, pixel, k, key + 1)) / (float)sy;
    float r = sqrtf(u), phi = 2.0f * LX_PI * v;
    return lx_add(lx_add(lx_scale(t, r * cosf(phi)), lx_scale(bt, r * sinf(phi))),
                  lx_scale(n, sqrtf(fmaxf(0.0f, 1.0f - u))));
}

/* Casts m rays (directions in rays[], weights per channel in w[]) and adds
 * the weights of those that escape to sum; with shs, also w x (Y00 shw,
 * Y1 shv) to shs (4 x RGB). */
static void cast(const lx_baker *b, lx_ray *rays, const lx_vec3 *w, uint32_t m, double sum[3],
                 double *squares, const float *shw, const lx_vec3 *shv, double *shs)
{
    uint8_t occluded[64];
    lx_tracer_occluded_batch(b->tracer, rays, m, false, occluded);
    for (uint32_t j = 0; j < m; j++)
        if (!occluded[j]) {
            sum[0] += w[j].x;
            sum[1] += w[j].y;
            sum[2] += w[j].z;
            double lum = lx_luminance3(w[j]);
            *squares += lum * lum;
            if (!shs)
                continue;
            lx_vec3 v = shv[j];
            double y[4] = {LX_SH_Y0 * shw[j], LX_SH_Y1 * v.y, LX_SH_Y1 * v.z, LX_SH_Y1 * v.x};
            for (int k = 0; k < 4; k++) {
                double f = y[k];
                shs[3 * k] += w[j].x * f;
                shs[3 * k + 1] += w[j].y * f;
                shs[3 * k + 2] += w[j].z * f;
            }
        }
}

/* The variance of a mean of n samples whose values (luminance) sum to
 * sum with squares summing to squares, times scale^2 (the estimate is
 * scale x the sum). Stratification makes the real variance smaller. */
static double mean_variance(double sum, double squares, uint32_t n, double scale)
{
    if (n < 2)
        return 0.0;
    double spread = (squares - sum * sum / (double)n) / (double)(n - 1);
    return spread > 0.0 ? scale * scale * (double)n * spread : 0.0;
}

/* Sky visibility of one texel (see the top of this file). Samples are
 * stratified and jittered by map, texel and sample, so any thread count
 * gives the same rays; directions below the geometric surface are blocked
 * by it. *variance: the estimate's (its luminance's). */
static lx_vec3 sky_visible(const lx_baker *b, uint32_t map_index, const lx_lightmap *map,
                           uint32_t texel, lx_sh4 *sh, double *variance)
{
    const lx_cubemap *lookup = &b->sky_lookup;
    int n = lookup->size;
    lx_vec3 p = map->world_position[texel], nrm = map->world_normal[texel];
    lx_vec3 ng = map->world_geometric_normal[texel];
    lx_vec3 t = lx_perpendicular(nrm), bt = lx_cross(nrm, t);
    uint32_t pixel = map->texels[texel].pixel;
    const uint32_t key = 0x5eedu; /* dimensions apart from the lights' */
    enum { BATCH = 64 };
    lx_ray rays[BATCH];
    lx_vec3 w[BATCH];
    float shw[BATCH];
    lx_vec3 shv[BATCH];
    double shs_base[LX_SH_FLOATS] = {0}, shs_peak[LX_SH_FLOATS] = {0};
    lx_vec3 result = lx_v3(0.0f, 0.0f, 0.0f);

    /* base: stratified cosine-weighted directions, pi / N sum base(w) */
    uint32_t want = b->sky_samples, sx, sy;
    lx_cosine_strata(want, &sx, &sy);
    uint32_t cells = sx * sy;
    double sum[3] = {0.0, 0.0, 0.0}, squares = 0.0;
    uint32_t m = 0;
    for (uint32_t k = 0; k < cells; k++) {
        lx_vec3 d = lx_cosine_direction(t, bt, nrm, map_index, pixel, k, sx, sy, key);
        if (!(lx_dot(d, ng) > 0.0f))
            continue;
        const float *l = lookup->data + 3 * texel_index(n, d);
        lx_light_eval e = {.to_light = d, .distance = INFINITY};
        rays[m] = lx_shadow_ray(b, p, ng, &e);
        /* the SH estimate's weight over pi (the irradiance's), see
         * directional.c */
        lx_sh_ray_weight(k, sx, d, nrm, &shw[m], &shv[m]);
        shw[m] /= LX_PI;
        shv[m] = lx_scale(shv[m], 1.0f / LX_PI);
        w[m++] = lx_v3(l[0], l[1], l[2]);
        if (m == BATCH) {
            cast(b, rays, w, m, sum, &squares, shw, shv, sh ? shs_base : NULL);
            m = 0;
        }
    }
    if (m)
        cast(b, rays, w, m, sum, &squares, shw, shv, sh ? shs_base : NULL);
    double scale = LX_PI / (double)cells;
    if (sh)
        for (int c = 0; c < LX_SH_FLOATS; c++)
            sh->c[c] += (float)(shs_base[c] * scale);
    result = lx_v3((float)(sum[0] * scale), (float)(sum[1] * scale), (float)(sum[2] * scale));
    *variance = mean_variance(lx_luminance3(result) / scale, squares, cells, scale);
    if (!b->sky_peak)
        return result;
    /* the peak's rays: pdf luminance x solid angle / P, so L Y / pdf is
     * the ray's weight / cos x P / M x Y */

    /* peak: texels by importance, P / M sum chroma cos over escaping rays */
    size_t texels = (size_t)6 * n * n;
    uint32_t peaks = (want + 1) / 2;
    double total = b->sky_peak_cdf[texels];
    float ox = lx_random(map_index, pixel, 0, key + 3),
          oy = lx_random(map_index, pixel, 0, key + 4);
    sum[0] = sum[1] = sum[2] = squares = 0.0;
    m = 0;
    for (uint32_t k = 0; k < peaks; k++) {
        double u = ((double)k + lx_random(map_index, pixel, k, key + 2)) / (double)peaks;
        size_t i = pick_texel(b->sky_peak_cdf, texels, u);
        int face, x, y;
        texel_of(n, i, &face, &x, &y);
        /* within the texel: the Halton point k (bases 2 and 3: any run of
         * consecutive k, all a texel gets, is spread evenly over it),
         * shifted by the texel's own random offset */
        float s = ((float)x + shifted(radical_inverse(k, 2), ox)) / (float)n;
        float tt = ((float)y + shifted(radical_inverse(k, 3), oy)) / (float)n;
        lx_vec3 d = lx_cube_direction(face, s, tt);
        float cos_n = lx_dot(d, nrm);
        if (!(cos_n > 0.0f) || !(lx_dot(d, ng) > 0.0f))
            continue;
        const float *l = b->sky_peak + 3 * i;
        float chroma = (float)(cos_n / lx_luminance(l));
        lx_light_eval e = {.to_light = d, .distance = INFINITY};
        rays[m] = lx_shadow_ray(b, p, ng, &e);
        shw[m] = 1.0f / cos_n;
        shv[m] = lx_scale(d, shw[m]);
        w[m++] = lx_v3(l[0] * chroma, l[1] * chroma, l[2] * chroma);
        if (m == BATCH) {
            cast(b, rays, w, m, sum, &squares, shw, shv, sh ? shs_peak : NULL);
            m = 0;
        }
    }
    if (m)
        cast(b, rays, w, m, sum, &squares, shw, shv, sh ? shs_peak : NULL);
    scale = total / (double)peaks;
    if (sh)
        for (int c = 0; c < LX_SH_FLOATS; c++)
            sh->c[c] += (float)(shs_peak[c] * scale);
    lx_vec3 peak = lx_v3((float)(sum[0] * scale), (float)(sum[1] * scale), (float)(sum[2] * scale));
    *variance += mean_variance(lx_luminance3(peak) / scale, squares, peaks, scale);
    return lx_add(result, peak);
}

void lx_sky_tile(const lx_baker *b, uint32_t map_index, const lx_lightmap *map, uint32_t first,
                 uint32_t count, lx_vec3 *accum, lx_sh4 *sh, float *variance)
{
    for (uint32_t k = 0; k < count; k++) {
        uint32_t i = first + k;
        lx_vec3 e;
        if (b->sky_shadows) {
            double v = 0.0;
            e = sky_visible(b, map_index, map, i, sh ? &sh[k] : NULL, &v);
            if (variance)
                variance[k] += (float)v;
        } else {
            /* unshadowed: nothing blocks any direction, so the texel's
             * directional data is the sky's own L0 and L1 */
            for (int c = 0; sh && c < 4; c++)
                for (int ch = 0; ch < 3; ch++)
                    sh[k].c[3 * c + ch] += b->sky_sh.c[c][ch];
            float irr[3];
            lx_sh_irradiance(&b->sky_sh, map->world_normal[i], irr);
            e = lx_v3(fmaxf(irr[0], 0.0f), fmaxf(irr[1], 0.0f), fmaxf(irr[2], 0.0f));
        }
        accum[k] = lx_add(accum[k], e);
    }
}

void lx_sphere_rotation(uint32_t seed, uint32_t index, uint32_t key, float m[9])
{
    /* a uniformly random unit quaternion (Shoemake, "Uniform random
     * rotations", Graphics Gems III) */
    double u1 = lx_random(seed, index, 0, key), u2 = lx_random(seed, index, 0, key + 1);
    double u3 = lx_random(seed, index, 0, key + 2);
    double a = sqrt(1.0 - u1), b = sqrt(u1), t2 = 2.0 * LX_PI * u2, t3 = 2.0 * LX_PI * u3;
    double w = a * sin(t2), x = a * cos(t2), y = b * sin(t3), z = b * cos(t3);
    double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
                   2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                   2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
    for (int i = 0; i < 9; i++)
        m[i] = (float)r[i];
}

lx_vec3 lx_sphere_direction(const float m[9], uint32_t k, uint32_t sx, uint32_t sy)
{
    /* ring i = k % sx of sx equal-area bands (z uniform: Archimedes'
     * hat-box theorem), at its middle height scaled so that the rings'
     * mean z^2 is 1/3, the sphere's (the middles' is (1 - 1/sx^2) / 3);
     * sy azimuths equally spaced around it, each ring turned by a golden
     * fraction of a step */
    uint32_t i = k % sx, j = k / sx;
    double scale = sx > 1 ? 1.0 / sqrt(1.0 - 1.0 / ((double)sx * (double)sx)) : 0.0;
    double z = (1.0 - (2.0 * i + 1.0) / (double)sx) * scale;
    double turn = fmod((double)i * 0.6180339887498949, 1.0);
    double phi = 2.0 * LX_PI * (((double)j + turn) / (double)sy);
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    double d[3] = {r * cos(phi), r * sin(phi), z};
    return lx_v3((float)(m[0] * d[0] + m[1] * d[1] + m[2] * d[2]),
                 (float)(m[3] * d[0] + m[4] * d[1] + m[5] * d[2]),
                 (float)(m[6] * d[0] + m[7] * d[1] + m[8] * d[2]));
}

lx_vec3 lx_sky_radiance(const lx_baker *b, lx_vec3 d)
{
    if (!b->has_sky || !b->sky_shadows)
        return lx_v3(0.0f, 0.0f, 0.0f);
    const float *l = b->sky_lookup.data + 3 * texel_index(b->sky_lookup.size, d);
    return lx_v3(l[0], l[1], l[2]);
}

void lx_sky_peak_sh(const lx_baker *b, lx_vec3 p, uint32_t seed, uint32_t index, uint32_t count,
                    uint32_t key, double acc[9][3])
{
    if (!b->has_sky || !b->sky_shadows || !b->sky_peak || count == 0)
        return;
    int n = b->sky_lookup.size;
    size_t texels = (size_t)6 * n * n;
    double total = b->sky_peak_cdf[texels];
    float ox = lx_random(seed, index, 0, key + 2), oy = lx_random(seed, index, 0, key + 3);
    double scale = total / (double)count;
    for (uint32_t k = 0; k < count; k++) {
        double u = ((double)k + lx_random(seed, index, k, key)) / (double)count;
        size_t i = pick_texel(b->sky_peak_cdf, texels, u);
        int face, x, y;
        texel_of(n, i, &face, &x, &y);
        float s = ((float)x + shifted(radical_inverse(k, 2), ox)) / (float)n;
        float tt = ((float)y + shifted(radical_inverse(k, 3), oy)) / (float)n;
        lx_vec3 d = lx_cube_direction(face, s, tt);
        lx_ray ray = {.origin = p, .dir = d, .tmin = 0.0f, .tmax = INFINITY};
        if (lx_tracer_occluded(b->tracer, &ray))
            continue;
        /* the texel's radiance over its pdf (luminance x solid angle /
         * total, per solid angle): total x chroma */
        const float *l = b->sky_peak + 3 * i;
        double w = scale / lx_luminance(l);
        float y9[9];
        lx_sh9_basis(d, y9);
        for (int j = 0; j < 9; j++)
            for (int c = 0; c < 3; c++)
                acc[j][c] += w * (double)l[c] * (double)y9[j];
    }
}
