/* Camera views with lightmaps applied: a primary ray per stratified,
 * jittered pixel sample (box filter over the pixel), the hit shaded as a
 * Lambertian surface lit by its lightmap, E * albedo / pi. Lightmaps are
 * read bilinearly or with the cubic B-spline (the smooth 4x4 kernel of
 * "bicubic lightmap sampling" in engines; weights as in Mitchell &
 * Netravali's B = 1, C = 0 family member). */
#include "render_internal.h"
#include "luxel/maps.h"

#include <math.h>
#include <omp.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#define TILE 16
#define MAX_SIDE 16384
#define MAX_SAMPLES 4096
/* back faces a ray may pass through before it gives up (drawn as a miss) */
#define MAX_CULLED 64

lx_render_desc lx_render_desc_defaults(const lx_render_desc *desc)
{
    lx_render_desc d = desc ? *desc : (lx_render_desc){0};
    if (d.width == 0 && d.height == 0) {
        d.width = 1280;
        d.height = 720;
    }
    if (d.samples == 0)
        d.samples = 4;
    if (d.sky_intensity == 0.0f)
        d.sky_intensity = 1.0f;
    return d;
}

/* ---- lightmap lookups ------------------------------------------------------ */

static const float *texel(const lx_image *img, int x, int y)
{
    x = x < 0 ? 0 : (x >= img->width ? img->width - 1 : x);
    y = y < 0 ? 0 : (y >= img->height ? img->height - 1 : y);
    return img->data + ((size_t)y * (size_t)img->width + (size_t)x) * 3;
}

/* Page coordinates of uv: texel centres at half-integers, clamped to
 * something an int holds (clamp-to-edge does the rest). */
static void page_coords(const lx_image *img, float u, float v, float *x, float *y)
{
    *x = lx_clampf(u * (float)img->width - 0.5f, -4.0f, (float)img->width + 4.0f);
    *y = lx_clampf(v * (float)img->height - 0.5f, -4.0f, (float)img->height + 4.0f);
    if (!isfinite(*x))
        *x = 0.0f;
    if (!isfinite(*y))
        *y = 0.0f;
}

static void sample_bilinear(const lx_image *img, float u, float v, float out[3])
{
    float x, y;
    page_coords(img, u, v, &x, &y);
    float fx = floorf(x), fy = floorf(y), tx = x - fx, ty = y - fy;
    int x0 = (int)fx, y0 = (int)fy;
    const float *a = texel(img, x0, y0), *b = texel(img, x0 + 1, y0);
    const float *c = texel(img, x0, y0 + 1), *d = texel(img, x0 + 1, y0 + 1);
    for (int k = 0; k < 3; k++) {
        float top = a[k] + (b[k] - a[k]) * tx, bottom = c[k] + (d[k] - c[k]) * tx;
        out[k] = top + (bottom - top) * ty;
    }
}

/* Uniform cubic B-spline weights for the taps at -1, 0, 1, 2 around t. */
static void bspline(float t, float w[4])
{
    float s = 1.0f - t, t2 = t * t, t3 = t2 * t;
    w[0] = s * s * s / 6.0f;
    w[1] = (3.0f * t3 - 6.0f * t2 + 4.0f) / 6.0f;
    w[2] = (-3.0f * t3 + 3.0f * t2 + 3.0f * t + 1.0f) / 6.0f;
    w[3] = t3 / 6.0f;
}

static void sample_bicubic(const lx_image *img, float u, float v, float out[3])
{
    float x, y;
    page_coords(img, u, v, &x, &y);
    float fx = floorf(x), fy = floorf(y), wx[4], wy[4];
    bspline(x - fx, wx);
    bspline(y - fy, wy);
    int x0 = (int)fx - 1, y0 = (int)fy - 1;
    float acc[3] = {0, 0, 0};
    for (int j = 0; j < 4; j++) {
        float row[3] = {0, 0, 0};
        for (int i = 0; i < 4; i++) {
            const float *t = texel(img, x0 + i, y0 + j);
            for (int k = 0; k < 3; k++)
                row[k] += wx[i] * t[k];
        }
        for (int k = 0; k < 3; k++)
            acc[k] += wy[j] * row[k];
    }
    for (int k = 0; k < 3; k++)
        out[k] = acc[k] > 0.0f ? acc[k] : 0.0f;
}

/* Bilinear lookup of an image of `channels` floats a texel (clamp to
 * edge), for the directional data (signed: no clamping at 0). */
static void sample_bilinear_n(const lx_image *img, float u, float v, int channels, float *out)
{
    float x, y;
    page_coords(img, u, v, &x, &y);
    float fx = floorf(x), fy = floorf(y), tx = x - fx, ty = y - fy;
    int x0 = (int)fx, y0 = (int)fy;
    for (int k = 0; k < channels; k++)
        out[k] = 0.0f;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            int xx = x0 + i, yy = y0 + j;
            xx = xx < 0 ? 0 : (xx >= img->width ? img->width - 1 : xx);
            yy = yy < 0 ? 0 : (yy >= img->height ? img->height - 1 : yy);
            const float *t = img->data + ((size_t)yy * (size_t)img->width + (size_t)xx) * channels;
            float w = (i ? tx : 1.0f - tx) * (j ? ty : 1.0f - ty);
            for (int k = 0; k < channels; k++)
                out[k] += w * t[k];
        }
}

/* ---- shading --------------------------------------------------------------- */

typedef struct render_ctx {
    const lx_scene *scene;
    const lx_lightmaps *lm;
    const lx_tracer *tracer;
    const uint32_t *node_map; /* scene node -> manifest node */
    const lx_render_desc *d;
    lx_camera_basis_t cam;
    float *det_sign; /* per scene node: the sign of its world matrix's determinant */
    lx_vec3 background;
    float inv_pre_exposure;
    /* directional lightmaps: per mesh its normal map's tangents (NULL: no
     * normal map), per node its normal matrix */
    lx_vec4 **tangents;
    lx_mat4 *normal_matrix;
} render_ctx;

/* The factor by which a normal map changes the lightmap's irradiance at
 * a hit (lx_render_view's contract): per channel, from the page's
 * directional data at page UV (u, v). 1 without a normal map or data. */
static lx_vec3 directional_factor(const render_ctx *c, const lx_lightmap_page *page,
                                  const lx_node *node, uint32_t node_index, const lx_mesh *m,
                                  uint32_t mesh_index, const uint32_t *i, float w0, float w1,
                                  float w2, float u, float v)
{
    lx_vec3 one = lx_v3(1.0f, 1.0f, 1.0f);
    const lx_vec4 *tg = c->tangents ? c->tangents[mesh_index] : NULL;
    if (!tg || !m->normals)
        return one;
    const lx_material *mat = lx_mesh_material(c->scene, m);
    lx_vec3 n = lx_add(lx_add(lx_scale(m->normals[i[0]], w0), lx_scale(m->normals[i[1]], w1)),
                       lx_scale(m->normals[i[2]], w2));
    if (!(lx_length(n) > 1e-12f))
        return one;
    n = lx_normalize(n);
    lx_vec3 np = n;
    lx_material_normal_at(mat, m, tg, i, w0, w1, w2, &np);
    const lx_mat4 *nm = &c->normal_matrix[node_index];
    (void)node;
    n = lx_normalize(lx_mat4_vector(nm, n));
    np = lx_normalize(lx_mat4_vector(nm, np));
    if (!lx_vec3_finite(n) || !lx_vec3_finite(np))
        return one;
    if (c->lm->directional == LX_DIRECTIONAL_DOMINANT) {
        if (page->dir.width <= 0)
            return one;
        float d[4];
        sample_bilinear_n(&page->dir, u, v, 4, d);
        lx_vec3 dir = lx_v3(2.0f * d[0] - 1.0f, 2.0f * d[1] - 1.0f, 2.0f * d[2] - 1.0f);
        /* Unity's DecodeDirectionalLightmap */
        float f = (0.5f * lx_dot(np, dir) + 0.5f) / fmaxf(1e-4f, d[3]);
        return lx_v3(f, f, f);
    }
    if (page->sh[0].width <= 0)
        return one;
    float e[4][3];
    for (int k = 0; k < 4; k++)
        sample_bilinear_n(&page->sh[k], u, v, 3, e[k]);
    float out[3];
    for (int ch = 0; ch < 3; ch++) {
        /* E1 along y, z, x in sh[1..3] */
        lx_vec3 e1 = lx_v3(e[3][ch], e[1][ch], e[2][ch]);
        float base = e[0][ch] + lx_dot(e1, n), bent = e[0][ch] + lx_dot(e1, np);
        out[ch] = base > 1e-6f * e[0][ch] && base > 0.0f ? fmaxf(bent, 0.0f) / base : 1.0f;
    }
    return lx_v3(out[0], out[1], out[2]);
}

/* Radiance seen along ray r (dir unit length); *hit tells whether it
 * met the scene. */
static lx_vec3 shade(const render_ctx *c, lx_ray r, bool *hit)
{
    *hit = true;
    const lx_scene *scene = c->scene;
    for (int pass = 0; pass < MAX_CULLED; pass++) {
        lx_hit h;
        if (!lx_tracer_closest_kind(c->tracer, &r, LX_RAY_CAMERA, &h))
            break;
        if (h.node >= scene->node_count || h.mesh >= scene->mesh_count)
            break;
        const lx_node *node = &scene->nodes[h.node];
        const lx_mesh *m = &scene->meshes[h.mesh];
        if (h.triangle >= m->triangle_count)
            break;
        const uint32_t *i = &m->indices[3 * (size_t)h.triangle];
        /* glTF culls back faces unless the material is doubleSided */
        if (!c->d->two_sided && !lx_mesh_material(scene, m)->double_sided) {
            lx_vec3 p0 = lx_mat4_point(&node->world, m->positions[i[0]]);
            lx_vec3 p1 = lx_mat4_point(&node->world, m->positions[i[1]]);
            lx_vec3 p2 = lx_mat4_point(&node->world, m->positions[i[2]]);
            lx_vec3 n = lx_cross(lx_sub(p1, p0), lx_sub(p2, p0));
            /* a mirroring transform turns counter-clockwise faces around (glTF) */
            if (lx_dot(n, r.dir) * c->det_sign[h.node] > 0.0f) {
                float next = h.t * (1.0f + 1e-6f) + 1e-6f;
                if (!(next > r.tmin) || !(next < r.tmax))
                    break;
                r.tmin = next;
                continue;
            }
        }
        float w1 = h.u, w2 = h.v, w0 = 1.0f - w1 - w2;
        uint32_t ln_index = c->node_map[h.node];
        if (ln_index == UINT32_MAX)
            return lx_v3(0, 0, 0);
        const lx_lightmap_node *ln = &c->lm->nodes[ln_index];
        const lx_vec2 *uv = m->uv[ln->uv_set];
        float u = uv[i[0]].x * w0 + uv[i[1]].x * w1 + uv[i[2]].x * w2;
        float v = uv[i[0]].y * w0 + uv[i[1]].y * w1 + uv[i[2]].y * w2;
        u = u * ln->scale_offset[0] + ln->scale_offset[2];
        v = v * ln->scale_offset[1] + ln->scale_offset[3];
        const lx_image *page = &c->lm->pages[ln->page].image;
        float e[3];
        if (c->d->filter == LX_LIGHTMAP_BICUBIC)
            sample_bicubic(page, u, v, e);
        else
            sample_bilinear(page, u, v, e);
        lx_vec3 value = lx_scale(lx_v3(e[0], e[1], e[2]), c->inv_pre_exposure);
        if (c->tangents)
            value = lx_mul(value, directional_factor(c, &c->lm->pages[ln->page], node, h.node, m,
                                                     h.mesh, i, w0, w1, w2, u, v));
        /* what the surface emits (nits, as the bake scaled it) is not in
         * the lightmap: an emitter's lightmap holds the light it receives */
        const lx_material *mat = lx_mesh_material(scene, m);
        lx_vec3 emitted = lx_material_emission_at(mat, m, i, w0, w1, w2, c->lm->emissive_scale);
        if (c->lm->quantity == LX_QUANTITY_RADIANCE)
            return lx_add(value, emitted);
        return lx_add(lx_scale(lx_mul(value, lx_material_albedo_at(mat, m, i, w0, w1, w2)),
                               1.0f / LX_PI),
                      emitted);
    }
    *hit = false;
    if (c->d->sky) {
        float s[3];
        lx_cubemap_sample(c->d->sky, r.dir, s);
        return lx_scale(lx_v3(s[0], s[1], s[2]), c->d->sky_intensity);
    }
    return c->background;
}

/* Per mesh the tangents of its normal map (the mesh's, else MikkTSpace's
 * from the map's UV set; NULL without a normal map), per node its normal
 * matrix. */
static lx_status prepare_directional(const lx_scene *scene, lx_vec4 ***tangents, bool **own,
                                     lx_mat4 **normal_matrix)
{
    uint32_t nm = scene->mesh_count, nn = scene->node_count;
    *tangents = calloc(nm + 1, sizeof **tangents);
    *own = calloc(nm + 1, sizeof **own);
    *normal_matrix = malloc((nn + 1) * sizeof **normal_matrix);
    if (!*tangents || !*own || !*normal_matrix)
        return lx_fail(LX_ERR_NOMEM, "render: out of memory");
    for (uint32_t n = 0; n < nn; n++)
        if (!lx_mat4_normal_matrix(&scene->nodes[n].world, &(*normal_matrix)[n]))
            (*normal_matrix)[n] = lx_mat4_identity();
    for (uint32_t k = 0; k < nm; k++) {
        const lx_mesh *m = &scene->meshes[k];
        if (m->material >= scene->material_count)
            continue;
        const lx_material *mat = &scene->materials[m->material];
        if (mat->normal_map.width <= 0 || mat->normal_uv_set < 0 ||
            mat->normal_uv_set >= LX_MAX_UV_SETS || !m->uv[mat->normal_uv_set] || !m->normals)
            continue;
        if (m->tangents) {
            (*tangents)[k] = m->tangents;
            continue;
        }
        lx_vec4 *t = malloc(sizeof(lx_vec4) * (m->vertex_count + 1));
        if (!t)
            return lx_fail(LX_ERR_NOMEM, "render: out of memory for tangents");
        (*tangents)[k] = t;
        (*own)[k] = true;
        lx_status st = lx_compute_tangents(m, mat->normal_uv_set, t);
        if (st != LX_OK)
            return st;
    }
    return LX_OK;
}

static void free_directional(const lx_scene *scene, lx_vec4 **tangents, bool *own,
                             lx_mat4 *normal_matrix)
{
    for (uint32_t k = 0; tangents && own && k < scene->mesh_count; k++)
        if (own[k])
            free(tangents[k]);
    free(tangents);
    free(own);
    free(normal_matrix);
}

static void render_tile(const render_ctx *c, int tile, int tiles_x, lx_image *out)
{
    const lx_render_desc *d = c->d;
    int x0 = (tile % tiles_x) * TILE, y0 = (tile / tiles_x) * TILE;
    int x1 = x0 + TILE < d->width ? x0 + TILE : d->width;
    int y1 = y0 + TILE < d->height ? y0 + TILE : d->height;
    /* strata: the most square sx x sy grid with sx * sy = samples */
    int sx = (int)floorf(sqrtf((float)d->samples));
    while (d->samples % sx)
        sx--;
    int sy = d->samples / sx;
    float inv_w = 1.0f / (float)d->width, inv_h = 1.0f / (float)d->height;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            uint32_t pixel = (uint32_t)y * (uint32_t)d->width + (uint32_t)x;
            double acc[3] = {0, 0, 0};
            int hits = 0;
            for (int s = 0; s < d->samples; s++) {
                float jx =
                    ((float)(s % sx) + lx_random(d->seed, pixel, (uint32_t)s, 0)) / (float)sx;
                float jy =
                    ((float)(s / sx) + lx_random(d->seed, pixel, (uint32_t)s, 1)) / (float)sy;
                float px = (2.0f * ((float)x + jx) * inv_w - 1.0f) * c->cam.tan_x;
                float py = (1.0f - 2.0f * ((float)y + jy) * inv_h) * c->cam.tan_y;
                lx_vec3 off = lx_add(lx_scale(c->cam.right, px), lx_scale(c->cam.up, py));
                lx_ray r = {.origin = c->cam.eye, .tmin = 0.0f, .tmax = INFINITY};
                if (c->cam.ortho) {
                    r.origin = lx_add(c->cam.eye, off);
                    r.dir = c->cam.fwd;
                } else {
                    r.dir = lx_normalize(lx_add(c->cam.fwd, off));
                }
                bool hit;
                lx_vec3 L = shade(c, r, &hit);
                hits += hit;
                acc[0] += L.x, acc[1] += L.y, acc[2] += L.z;
            }
            float *o = out->data + (size_t)pixel * 3;
            for (int k = 0; k < 3; k++)
                o[k] = (float)(acc[k] / (double)d->samples);
            if (d->coverage)
                d->coverage[pixel] = (float)hits / (float)d->samples;
        }
}

static lx_status check_desc(const lx_render_desc *d)
{
    if (d->width < 1 || d->height < 1 || d->width > MAX_SIDE || d->height > MAX_SIDE)
        return lx_fail(LX_ERR_INVALID,
                       "render: the image size must be 1..%d pixels a side, not %dx%d", MAX_SIDE,
                       d->width, d->height);
    if (d->samples < 1 || d->samples > MAX_SAMPLES)
        return lx_fail(LX_ERR_INVALID, "render: samples must be 1..%d, not %d", MAX_SAMPLES,
                       d->samples);
    if ((unsigned)d->filter > LX_LIGHTMAP_BICUBIC)
        return lx_fail(LX_ERR_INVALID, "render: unknown lightmap filter %d", (int)d->filter);
    if (!lx_vec3_finite(d->background) || d->background.x < 0 || d->background.y < 0 ||
        d->background.z < 0)
        return lx_fail(LX_ERR_INVALID, "render: the background must be finite and >= 0");
    if (!isfinite(d->sky_intensity) || d->sky_intensity < 0)
        return lx_fail(LX_ERR_INVALID, "render: the sky intensity must be finite and >= 0");
    if (d->sky && (d->sky->size < 1 || !d->sky->data))
        return lx_fail(LX_ERR_INVALID, "render: the sky cube map is empty");
    return LX_OK;
}

lx_status lx_render_view(const lx_scene *scene, const lx_lightmaps *lm, const lx_tracer *tracer,
                         const lx_render_desc *desc, lx_image *out)
{
    if (!lm)
        return lx_fail_null(__func__, "lm");
    if (!out)
        return lx_fail_null(__func__, "out");
    if (!scene)
        return lx_fail_null(__func__, "scene");
    return lx_render_view_quiet(scene, lm, tracer, desc, out, false);
}

lx_status lx_render_view_quiet(const lx_scene *scene, const lx_lightmaps *lm,
                               const lx_tracer *tracer, const lx_render_desc *desc, lx_image *out,
                               bool quiet)
{
    memset(out, 0, sizeof *out);
    lx_render_desc d = lx_render_desc_defaults(desc);
    lx_status st = check_desc(&d);
    if (st != LX_OK)
        return st;
    for (uint32_t p = 0; p < lm->page_count; p++)
        if (lm->pages[p].image.width != lm->pages[p].width ||
            lm->pages[p].image.height != lm->pages[p].height || lm->pages[p].image.channels != 3)
            return lx_fail(LX_ERR_INVALID, "render: page %u (%s) is not loaded as 3 channels", p,
                           lm->pages[p].file);
    if (lm->pre_exposure <= 0.0f || !isfinite(lm->pre_exposure))
        return lx_fail(LX_ERR_INVALID, "render: pre_exposure must be above 0");
    for (uint32_t n = 0; n < lm->node_count; n++)
        if (lm->nodes[n].page >= lm->page_count || lm->nodes[n].uv_set < 0 ||
            lm->nodes[n].uv_set >= LX_MAX_UV_SETS)
            return lx_fail(LX_ERR_INVALID,
                           "render: lightmap node '%s': page or UV set out of range",
                           lm->nodes[n].name);
    bool frame = d.camera.eye.x == d.camera.target.x && d.camera.eye.y == d.camera.target.y &&
                 d.camera.eye.z == d.camera.target.z;
    if (frame) {
        lx_vec3 lo, hi;
        if (!lx_scene_bounds(scene, &lo, &hi))
            return lx_fail(LX_ERR_INVALID, "%s: the scene is empty: nothing to frame",
                           scene->path ? scene->path : "render");
    } else if ((st = lx_camera_check(&d.camera)) != LX_OK) {
        return st;
    }

    uint32_t nn = scene->node_count;
    uint32_t *map = malloc((nn ? nn : 1) * sizeof *map);
    float *det_sign = malloc((nn ? nn : 1) * sizeof *det_sign);
    if (!map || !det_sign) {
        free(map);
        free(det_sign);
        return lx_fail(LX_ERR_NOMEM, "render: out of memory");
    }
    st = lx_lightmaps_bind(lm, scene, map);
    uint32_t unlit = 0;
    for (uint32_t n = 0; n < nn; n++) {
        det_sign[n] = lx_mat4_det3(&scene->nodes[n].world) < 0.0f ? -1.0f : 1.0f;
        unlit += map[n] == UINT32_MAX && scene->nodes[n].mesh_count > 0 &&
                 !scene->nodes[n].bake.sky; /* not drawn */
    }
    if (st == LX_OK && unlit && !quiet)
        lx_log(LX_LOG_WARN, "%s: %u nodes have no lightmap and are drawn black",
               scene->path ? scene->path : "render", unlit);
    lx_tracer *own = NULL;
    if (st == LX_OK && !tracer) {
        lx_tracer_desc td = {.threads = d.threads};
        if ((st = lx_tracer_create(scene, &td, &own)) == LX_OK)
            tracer = own;
    }
    /* the default camera is probed through the tracer */
    if (st == LX_OK && frame) {
        st = lx_camera_auto(scene, lm, tracer, d.camera.fov, (float)d.width / (float)d.height,
                            &d.camera, NULL);
        if (st == LX_OK)
            st = lx_camera_check(&d.camera);
    }
    if (st == LX_OK)
        st = lx_image_alloc(out, d.width, d.height, 3);
    if (st != LX_OK) {
        free(map);
        free(det_sign);
        lx_tracer_destroy(own);
        return st;
    }

    /* directional lightmaps: the tangents of normal-mapped meshes */
    lx_vec4 **tangents = NULL;
    bool *own_tangents = NULL;
    lx_mat4 *normal_matrix = NULL;
    if (lm->directional != LX_DIRECTIONAL_OFF)
        st = prepare_directional(scene, &tangents, &own_tangents, &normal_matrix);
    if (st != LX_OK) {
        free_directional(scene, tangents, own_tangents, normal_matrix);
        free(map);
        free(det_sign);
        lx_tracer_destroy(own);
        lx_image_free(out);
        return st;
    }

    render_ctx c = {.scene = scene,
                    .lm = lm,
                    .tracer = tracer,
                    .node_map = map,
                    .d = &d,
                    .det_sign = det_sign,
                    .inv_pre_exposure = 1.0f / lm->pre_exposure,
                    .tangents = tangents,
                    .normal_matrix = normal_matrix};
    lx_camera_basis(&d.camera, d.width, d.height, &c.cam);
    c.background = d.background;

    int tiles_x = (d.width + TILE - 1) / TILE, tiles_y = (d.height + TILE - 1) / TILE;
    int tiles = tiles_x * tiles_y;
    atomic_int done = 0;
    atomic_bool cancel = false;
#pragma omp parallel for schedule(dynamic, 1) num_threads(lx_thread_count(d.threads))
    for (int t = 0; t < tiles; t++) {
        if (atomic_load_explicit(&cancel, memory_order_relaxed))
            continue;
        render_tile(&c, t, tiles_x, out);
        int k = atomic_fetch_add(&done, 1) + 1;
        /* only the first thread reports: calls never overlap */
        if (d.progress && omp_get_thread_num() == 0 &&
            !d.progress(d.progress_user, (float)k / (float)tiles))
            atomic_store(&cancel, true);
    }
    if (!atomic_load(&cancel) && d.progress && !d.progress(d.progress_user, 1.0f))
        atomic_store(&cancel, true);
    free(map);
    free(det_sign);
    lx_tracer_destroy(own);
    free_directional(scene, tangents, own_tangents, normal_matrix);
    if (atomic_load(&cancel)) {
        lx_image_free(out);
        return lx_fail(LX_ERR_CANCELLED, "render: cancelled");
    }
    return LX_OK;
}
