/* Light probes (lx_baker_probes): the incident radiance at a point
 * projected onto order-2 real spherical harmonics by Monte Carlo
 * integration, L_lm = 4 pi / N sum L(w_k) Y_lm(w_k) over N directions,
 * equal-area rings that integrate order-2 harmonics exactly, randomly
 * rotated per probe (lx_sphere_direction; P.-P.
 * Sloan, "Stupid Spherical Harmonics (SH) Tricks", GDC 2008, for the
 * projection, and Ramamoorthi & Hanrahan 2001 for the irradiance engines
 * evaluate from it). A ray that hits a surface reads its exitant radiance
 * from the lightmaps, as the bake's final gather does (lx_hit_radiance),
 * so the probe holds the surfaces' direct and indirect light; the sky's
 * bright part and the lights are sampled toward them (deltas projected
 * directly: L_lm += E Y_lm(w_light)). Validity is the bake's texel test:
 * most rays hitting back faces. Every probe's rays come from (probe
 * index, sample), each probe is written by one thread, and sums are in
 * double in sample order, so any thread count gives the same bytes. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* lx_random seeds and dimensions apart from the texels' (whose seed is
 * the map index) */
#define PROBE_SEED 0x9f0be5u
#define PROBE_KEY 0x7000u
#define PEAK_KEY 0x7100u
#define AREA_KEY 0x7200u
/* probes per unit of parallel work */
#define PROBE_CHUNK 8

lx_probe_desc lx_probe_desc_defaults(const lx_probe_desc *desc)
{
    lx_probe_desc d;
    if (desc)
        d = *desc;
    else
        memset(&d, 0, sizeof d);
    if (d.samples == 0)
        d.samples = LX_PROBE_SAMPLES_DEFAULT;
    return d;
}

lx_status lx_probe_grid(lx_vec3 lo, lx_vec3 hi, int nx, int ny, int nz, lx_vec3 *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    if (nx < 1 || ny < 1 || nz < 1 || nx > LX_MAX_PROBE_GRID || ny > LX_MAX_PROBE_GRID ||
        nz > LX_MAX_PROBE_GRID)
        return lx_fail(LX_ERR_INVALID, "probe grid %dx%dx%d: each count must be 1..%d", nx, ny, nz,
                       LX_MAX_PROBE_GRID);
    if ((uint64_t)nx * (uint64_t)ny * (uint64_t)nz > LX_MAX_PROBES)
        return lx_fail(LX_ERR_INVALID, "probe grid %dx%dx%d: more than %u probes", nx, ny, nz,
                       LX_MAX_PROBES);
    if (!lx_vec3_finite(lo) || !lx_vec3_finite(hi) || lo.x > hi.x || lo.y > hi.y || lo.z > hi.z)
        return lx_fail(LX_ERR_INVALID, "probe grid: the box must be finite with lo <= hi");
    if (!out)
        return lx_fail(LX_ERR_INVALID, "probe grid: out must not be NULL");
    for (int k = 0; k < nz; k++)
        for (int j = 0; j < ny; j++)
            for (int i = 0; i < nx; i++) {
                float fx = ((float)i + 0.5f) / (float)nx, fy = ((float)j + 0.5f) / (float)ny;
                float fz = ((float)k + 0.5f) / (float)nz;
                out[((size_t)k * (size_t)ny + (size_t)j) * (size_t)nx + (size_t)i] =
                    lx_v3(lo.x + fx * (hi.x - lo.x), lo.y + fy * (hi.y - lo.y),
                          lo.z + fz * (hi.z - lo.z));
            }
    return LX_OK;
}

typedef struct probe_run {
    const lx_baker *b;
    const lx_radiance_source *sources;
    uint32_t sx, sy; /* the rays' strata */
} probe_run;

/* acc += w * Y(d), per channel. */
static void add_sh(double acc[9][3], lx_vec3 d, lx_vec3 w)
{
    float y[9];
    lx_sh9_basis(d, y);
    for (int j = 0; j < 9; j++) {
        acc[j][0] += (double)w.x * (double)y[j];
        acc[j][1] += (double)w.y * (double)y[j];
        acc[j][2] += (double)w.z * (double)y[j];
    }
}

/* Whether nothing blocks p from d within distance (INFINITY: a direction). */
static bool visible(const lx_baker *b, const lx_light *light, lx_vec3 p, lx_vec3 d, float distance)
{
    if (light->shadow == LX_SHADOW_NONE)
        return true;
    float bias = b->bias + 4e-6f * lx_max_abs_component(p);
    lx_ray ray = {.origin = p, .dir = d, .tmin = 0.0f, .tmax = INFINITY};
    if (isfinite(distance))
        ray.tmax = fmaxf(distance - 2.0f * bias, 0.0f);
    return !lx_tracer_occluded(b->tracer, &ray);
}

/* The whole surface area lx_area_light_point samples uniformly. */
static double area_of(const lx_light *l)
{
    double r = l->radius;
    switch (l->type) {
    case LX_LIGHT_SPHERE:
        return 4.0 * LX_PI * r * r;
    case LX_LIGHT_DISK:
        return LX_PI * r * r;
    case LX_LIGHT_RECT:
        return (double)l->width * (double)l->height;
    case LX_LIGHT_TUBE:
        return 2.0 * LX_PI * r * l->length + 4.0 * LX_PI * r * r;
    default:
        return 0.0;
    }
}

/* An area light seen from p: points uniform over its surface, each
 * bringing luminance x cos at the light / d^2 x area / S toward it (a
 * linear tube: candela per metre x sin to the axis / d^2 x length / S). */
static void area_light_sh(const lx_baker *b, const lx_light *light, uint32_t li, uint32_t probe,
                          lx_vec3 p, double acc[9][3])
{
    uint32_t want = lx_light_sample_count(light);
    if (want < LX_PROBE_AREA_SAMPLES_MIN)
        want = LX_PROBE_AREA_SAMPLES_MIN;
    uint32_t sx, sy;
    lx_cosine_strata(want, &sx, &sy);
    uint32_t cells = sx * sy;
    lx_vec3 to_centre = lx_sub(light->position, p);
    float window = lx_light_range_window(lx_dot(to_centre, to_centre), light->range);
    if (!(window > 0.0f))
        return;
    bool linear = light->type == LX_LIGHT_TUBE && !(light->radius > 0.0f);
    double size = linear ? (double)light->length : area_of(light);
    lx_vec3 radiance = lx_scale(light->color, light->intensity * window);
    double sum[9][3];
    memset(sum, 0, sizeof sum);
    uint32_t key = AREA_KEY + 4u * li;
    for (uint32_t k = 0; k < cells; k++) {
        float u = ((float)(k % sx) + lx_random(PROBE_SEED, probe, k, key)) / (float)sx;
        float v = ((float)(k / sx) + lx_random(PROBE_SEED, probe, k, key + 1)) / (float)sy;
        lx_vec3 nq;
        lx_vec3 q = lx_area_light_point(light, u, v, &nq);
        lx_vec3 w = lx_sub(q, p);
        float d2 = lx_dot(w, w);
        if (!(d2 > 0.0f))
            continue;
        float dist = sqrtf(d2);
        lx_vec3 d = lx_scale(w, 1.0f / dist);
        float g;
        if (linear) {
            g = lx_length(lx_cross(light->direction, d));
        } else {
            g = -lx_dot(nq, d);
            if (!(g > 0.0f))
                continue; /* the point faces away */
        }
        if (!visible(b, light, p, d, dist))
            continue;
        add_sh(sum, d, lx_scale(radiance, g / d2));
    }
    double scale = size / (double)cells;
    for (int j = 0; j < 9; j++)
        for (int c = 0; c < 3; c++)
            acc[j][c] += sum[j][c] * scale;
}

/* The static lights and the ambient at p. */
static void lights_sh(const lx_baker *b, uint32_t probe, lx_vec3 p, double acc[9][3])
{
    lx_vec3 ambient = b->ambient;
    for (uint32_t li = 0; li < b->light_count; li++) {
        const lx_light *light = &b->lights[li];
        if (light->dynamic)
            continue;
        lx_light_eval e;
        /* toward the light first (and its ambient, filled either way),
         * then at normal incidence: E with N.L = 1 */
        lx_light_evaluate(light, p, lx_v3(0.0f, 1.0f, 0.0f), &e);
        ambient = lx_add(ambient, e.ambient);
        if (lx_light_is_area(light)) {
            area_light_sh(b, light, li, probe, p, acc);
            continue;
        }
        if (!(e.distance > 0.0f))
            continue; /* the probe sits on the light */
        lx_vec3 to_light = e.to_light;
        if (!lx_light_evaluate(light, p, to_light, &e))
            continue;
        if (!visible(b, light, p, to_light, e.distance))
            continue;
        add_sh(acc, to_light, e.illuminance);
    }
    /* a constant radiance ambient / pi over the sphere: L_00 = 4 pi x
     * ambient / pi x Y_00 = 2 ambient / sqrt(pi) */
    double c00 = 2.0 / sqrt(LX_PI);
    acc[0][0] += c00 * ambient.x;
    acc[0][1] += c00 * ambient.y;
    acc[0][2] += c00 * ambient.z;
}

static void probe_one(const probe_run *run, uint32_t index, lx_vec3 p, lx_probe *out)
{
    const lx_baker *b = run->b;
    uint32_t cells = run->sx * run->sy, back = 0;
    double sum[9][3];
    memset(sum, 0, sizeof sum);
    memset(out, 0, sizeof *out);
    float rot[9];
    lx_sphere_rotation(PROBE_SEED, index, PROBE_KEY, rot);
    for (uint32_t k = 0; k < cells; k++) {
        lx_vec3 d = lx_sphere_direction(rot, k, run->sx, run->sy);
        lx_ray ray = {.origin = p, .dir = d, .tmin = 0.0f, .tmax = INFINITY};
        lx_hit h;
        lx_vec3 l;
        if (lx_tracer_closest_kind(b->tracer, &ray, LX_RAY_GATHER, &h)) {
            if (lx_bake_hit_inside(b, d, &h)) {
                back++;
                continue;
            }
            /* the face of a double-sided surface whose light is not baked */
            if (!lx_bake_hit_surface(b, d, &h))
                continue;
            l = lx_hit_radiance(b, run->sources, true, &h);
        } else {
            l = lx_sky_radiance(b, d);
        }
        add_sh(sum, d, l);
    }
    out->back_face_share = (float)back / (float)cells;
    if (2 * back > cells)
        return; /* inside geometry */
    double scale = 4.0 * LX_PI / (double)cells;
    for (int j = 0; j < 9; j++)
        for (int c = 0; c < 3; c++)
            sum[j][c] *= scale;
    /* the sky: its peak toward it (half as many rays as the sphere's, as
     * the texels' sky), or unshadowed, whole */
    lx_sky_peak_sh(b, p, PROBE_SEED, index, (cells + 1) / 2, PEAK_KEY, sum);
    if (b->has_sky && !b->sky_shadows)
        for (int j = 0; j < 9; j++)
            for (int c = 0; c < 3; c++)
                sum[j][c] += b->sky_sh.c[j][c];
    lights_sh(b, index, p, sum);
    for (int j = 0; j < 9; j++)
        for (int c = 0; c < 3; c++)
            out->sh.c[j][c] = (float)sum[j][c];
    out->valid = true;
}

/* Each map's exitant radiance as the probes' rays see it: albedo / pi x
 * the baked irradiance + emission, at covered texels. */
static lx_status make_sources(const lx_baker *b, lx_radiance_source *src, float **bufs)
{
    uint64_t bytes = 0;
    for (uint32_t m = 0; m < b->map_count; m++)
        bytes += (uint64_t)b->maps[m].info.width * (uint64_t)b->maps[m].info.height * 12u;
    lx_status st = lx_check_memory(bytes, "the light probes' surface radiance");
    if (st != LX_OK)
        return st;
    for (uint32_t m = 0; m < b->map_count; m++) {
        /* a tiled baker builds each tile's texels again, in order */
        if ((st = lx_bake_tile_need((lx_baker *)b, m)) != LX_OK)
            return st;
        const lx_lightmap *map = &b->maps[m];
        size_t pixels = (size_t)map->info.width * (size_t)map->info.height;
        bufs[m] = calloc(pixels * 3 + 1, sizeof(float));
        if (!bufs[m])
            return lx_fail(LX_ERR_NOMEM, "lightmap '%s': out of memory for the light probes",
                           map->name);
        for (uint32_t i = 0; i < map->info.used_texels; i++) {
            size_t p = map->texels[i].pixel;
            lx_vec3 e = lx_v3(map->baked[3 * p], map->baked[3 * p + 1], map->baked[3 * p + 2]);
            lx_vec3 l = lx_scale(lx_mul(map->albedo[i], e), 1.0f / LX_PI);
            if (map->emission)
                l = lx_add(l, map->emission[i]);
            bufs[m][3 * p] = l.x;
            bufs[m][3 * p + 1] = l.y;
            bufs[m][3 * p + 2] = l.z;
        }
        src[m].valid = map->mask;
        src[m].source = bufs[m];
    }
    return LX_OK;
}

lx_status lx_baker_probes(lx_baker *b, const lx_vec3 *points, uint32_t count,
                          const lx_probe_desc *desc, lx_probe *out)
{
    if (!b || (count && (!points || !out)))
        return lx_fail(LX_ERR_INVALID, "lx_baker_probes: baker, points and out must not be NULL");
    if (count)
        memset(out, 0, sizeof(lx_probe) * count);
    if (!lx_bake_keeps_surfaces(&b->desc))
        return lx_fail(LX_ERR_INVALID,
                       "light probes: the baker was made without desc.probes (or bounces), so it "
                       "kept no surface colours to read");
    lx_probe_desc d = lx_probe_desc_defaults(desc);
    if (d.samples > LX_MAX_PROBE_SAMPLES)
        return lx_fail(LX_ERR_INVALID, "light probes: %u samples, at most %u", d.samples,
                       LX_MAX_PROBE_SAMPLES);
    if (d.threads < 0 || d.threads > 1024)
        return lx_fail(LX_ERR_INVALID, "light probes: thread count %d is outside 0..1024",
                       d.threads);
    if (count > LX_MAX_PROBES)
        return lx_fail(LX_ERR_INVALID, "light probes: %u probes, at most %u", count, LX_MAX_PROBES);
    for (uint32_t i = 0; i < count; i++)
        if (!lx_vec3_finite(points[i]))
            return lx_fail(LX_ERR_INVALID, "light probes: point %u is not finite", i);
    if (count == 0)
        return LX_OK;
    if (b->tracer_dirty) {
        lx_status st = lx_tracer_commit(b->tracer);
        if (st != LX_OK)
            return st;
        b->tracer_dirty = false;
    }
    lx_radiance_source *src = calloc(b->map_count + 1, sizeof *src);
    float **bufs = calloc(b->map_count + 1, sizeof *bufs);
    lx_status st = src && bufs ? make_sources(b, src, bufs)
                               : lx_fail(LX_ERR_NOMEM, "out of memory for the light probes");
    probe_run run = {.b = b, .sources = src};
    lx_cosine_strata(d.samples, &run.sx, &run.sy);
    int threads = lx_thread_count(d.threads ? d.threads : b->desc.threads);
    int chunks = (int)((count + PROBE_CHUNK - 1) / PROBE_CHUNK);
    volatile int cancelled = 0;
    int done = 0;
    if (st == LX_OK) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
        for (int c = 0; c < chunks; c++) {
            if (cancelled)
                continue;
            uint32_t first = (uint32_t)c * PROBE_CHUNK;
            uint32_t last = first + PROBE_CHUNK < count ? first + PROBE_CHUNK : count;
            for (uint32_t i = first; i < last; i++)
                probe_one(&run, i, points[i], &out[i]);
            if (d.progress) {
                int now;
#pragma omp atomic capture
                now = ++done;
                if (omp_get_thread_num() == 0 &&
                    !d.progress(d.progress_user, (float)now / (float)chunks))
                    cancelled = 1;
            }
        }
        if (!cancelled && d.progress && !d.progress(d.progress_user, 1.0f))
            cancelled = 1;
        if (cancelled) {
            if (count)
                memset(out, 0, sizeof(lx_probe) * count);
            st = lx_fail(LX_ERR_CANCELLED, "light probes cancelled");
        }
    }
    for (uint32_t m = 0; bufs && m < b->map_count; m++)
        free(bufs[m]);
    free(bufs);
    free(src);
    return st;
}
