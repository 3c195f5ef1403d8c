/* Material preview (seed 002_26369eb9c57a642b.txt; Lengyel, FGED vol. 2
 * ch. 7): a height or normal map on a quad or sphere under one directional
 * light, shaded per pixel with Lambert diffuse (rho/pi) and Blinn-Phong
 * specular, the UV moved by the seed's ApplyParallaxOffset and the direct
 * light scaled by its ApplyHorizonMap. The maps it needs (normals from the
 * heights, the parallax map, the horizon layers) are made once up front. */
#include "normal_internal.h"

#include <math.h>
#include <string.h>

#define SH_PI 3.14159265358979323846

lx_shade_desc lx_shade_desc_defaults(const lx_shade_desc *desc)
{
    lx_shade_desc d;
    if (desc)
        d = *desc;
    else
        memset(&d, 0, sizeof d);
    if (d.strength == 0.0f)
        d.strength = LX_DEFAULT_HEIGHT_STRENGTH;
    if (d.light.x == 0.0f && d.light.y == 0.0f && d.light.z == 0.0f)
        d.light = lx_shade_light_dir(135.0f, 35.0f);
    if (d.light_color[0] == 0.0f && d.light_color[1] == 0.0f && d.light_color[2] == 0.0f)
        d.light_color[0] = d.light_color[1] = d.light_color[2] = 1.0f;
    if (d.illuminance == 0.0f)
        d.illuminance = (float)SH_PI;
    if (d.fov == 0.0f)
        d.fov = 40.0f;
    if (d.specular[0] == 0.0f && d.specular[1] == 0.0f && d.specular[2] == 0.0f)
        d.specular[0] = d.specular[1] = d.specular[2] = 0.04f;
    if (d.exponent == 0.0f)
        d.exponent = 64.0f;
    if (d.parallax_scale == 0.0f)
        d.parallax_scale = 1.0f;
    if (d.out_width == 0)
        d.out_width = 512;
    if (d.out_height == 0)
        d.out_height = 512;
    return d;
}

lx_vec3 lx_shade_light_dir(float az, float el)
{
    double a = (double)az * SH_PI / 180.0, e = (double)el * SH_PI / 180.0;
    return lx_v3((float)(cos(e) * cos(a)), (float)(cos(e) * sin(a)), (float)sin(e));
}

/* Bilinear fetch of the first n channels of img at uv (texel centres at
 * ((x + 1/2)/W, (y + 1/2)/H)), texels outside addressed by wrap. */
static void fetch(const lx_image *img, lx_wrap wrap, double u, double v, int n, float *o)
{
    int w = img->width, h = img->height, c = img->channels;
    double fx = u * w - 0.5, fy = v * h - 0.5;
    double x0f = floor(fx), y0f = floor(fy);
    double ax = fx - x0f, ay = fy - y0f;
    double px = wrap == LX_WRAP_MIRROR ? 2.0 * w : w, py = wrap == LX_WRAP_MIRROR ? 2.0 * h : h;
    if (wrap != LX_WRAP_CLAMP) {
        x0f -= floor(x0f / px) * px;
        y0f -= floor(y0f / py) * py;
    } else {
        x0f = x0f < -1.0 ? -1.0 : x0f > w ? w : x0f;
        y0f = y0f < -1.0 ? -1.0 : y0f > h ? h : y0f;
    }
    int x0 = (int)x0f, y0 = (int)y0f;
    int xa = lx_wrap_index(wrap, x0, w), xb = lx_wrap_index(wrap, x0 + 1, w);
    int ya = lx_wrap_index(wrap, y0, h), yb = lx_wrap_index(wrap, y0 + 1, h);
    const float *d = img->data;
    for (int k = 0; k < n; k++) {
#define AT(x, y) ((double)d[((size_t)(y) * (size_t)w + (size_t)(x)) * (size_t)c + (size_t)k])
        double top = AT(xa, ya) + ax * (AT(xb, ya) - AT(xa, ya));
        double bottom = AT(xa, yb) + ax * (AT(xb, yb) - AT(xa, yb));
#undef AT
        o[k] = (float)(top + ay * (bottom - top));
    }
}

typedef struct shade_job {
    const lx_shade_desc *d;
    const lx_image *normals, *parallax, *layer0, *layer1;
    lx_vec3 light;     /* unit, world */
    double dist;       /* camera distance */
    double radius;     /* sphere radius */
    float pscale[2];   /* parallax UV per unit value */
    lx_image *out;
} shade_job;

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void norm3(double *a)
{
    double l = sqrt(dot3(a, a));
    if (l > 0.0)
        for (int i = 0; i < 3; i++)
            a[i] /= l;
}

/* One pixel's radiance into rgb. */
static void shade_pixel(const shade_job *j, int px, int py, float *rgb)
{
    const lx_shade_desc *d = j->d;
    int W = d->out_width, H = d->out_height;
    double aspect = (double)W / (double)H;
    /* the point of the plane z = 0 under the pixel: the frame spans
     * [-aspect, aspect] x [-1, 1] there */
    double sx = (2.0 * (px + 0.5) / W - 1.0) * aspect, sy = 1.0 - 2.0 * (py + 0.5) / H;
    double cam[3] = {0.0, 0.0, j->dist};
    double p[3], t[3], b[3], n[3], u, v;
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (d->shape == LX_SHADE_QUAD) {
        p[0] = sx, p[1] = sy, p[2] = 0.0;
        t[0] = 1, t[1] = 0, t[2] = 0;
        b[0] = 0, b[1] = 1, b[2] = 0;
        n[0] = 0, n[1] = 0, n[2] = 1;
        u = (sx / aspect + 1.0) * 0.5;
        v = (1.0 - sy) * 0.5;
    } else {
        double dir[3] = {sx, sy, -j->dist};
        norm3(dir);
        /* |cam + s dir|^2 = r^2 */
        double bq = dot3(cam, dir), cq = dot3(cam, cam) - j->radius * j->radius;
        double disc = bq * bq - cq;
        if (disc < 0.0)
            return;
        double s = -bq - sqrt(disc);
        for (int i = 0; i < 3; i++)
            p[i] = cam[i] + s * dir[i], n[i] = p[i] / j->radius;
        norm3(n);
        double lon = atan2(n[0], n[2]);
        double lat = asin(n[1] < -1.0 ? -1.0 : n[1] > 1.0 ? 1.0 : n[1]);
        u = 0.5 + lon / (2.0 * SH_PI);
        v = 0.5 - lat / SH_PI;
        t[0] = cos(lon), t[1] = 0.0, t[2] = -sin(lon);
        /* bitangent = cross(n, t): toward the north pole */
        b[0] = n[1] * t[2] - n[2] * t[1];
        b[1] = n[2] * t[0] - n[0] * t[2];
        b[2] = n[0] * t[1] - n[1] * t[0];
    }
    double vw[3] = {cam[0] - p[0], cam[1] - p[1], cam[2] - p[2]};
    norm3(vw);
    double lw[3] = {j->light.x, j->light.y, j->light.z};
    double vt[3] = {dot3(vw, t), dot3(vw, b), dot3(vw, n)};
    double lt[3] = {dot3(lw, t), dot3(lw, b), dot3(lw, n)};
    if (j->parallax) {
        lx_vec2 uv = lx_parallax_offset(j->parallax, d->wrap, lx_v2((float)u, (float)v),
                                        lx_v3((float)vt[0], (float)vt[1], (float)vt[2]),
                                        j->pscale, 0);
        /* the moves only: a UV not moved stays exactly as it was */
        u += (double)(uv.x - (float)u);
        v += (double)(uv.y - (float)v);
    }
    float m[3];
    fetch(j->normals, d->wrap, u, v, 3, m);
    double nt[3] = {m[0], d->green_down ? -m[1] : m[1], m[2]};
    norm3(nt);
    float base[3] = {0.8f, 0.8f, 0.8f};
    if (d->base_color)
        fetch(d->base_color, d->wrap, u, v, 3, base);
    double ht[3] = {lt[0] + vt[0], lt[1] + vt[1], lt[2] + vt[2]};
    norm3(ht);
    double nl = dot3(nt, lt), nh = dot3(nt, ht);
    double diff = nl > 0.0 ? nl : 0.0;
    double spec = d->no_specular || nl <= 0.0 ? 0.0 : pow(nh > 0.0 ? nh : 0.0, d->exponent);
    double shadow = lt[2] > 0.0 ? 1.0 : 0.0;
    if (shadow > 0.0 && j->layer0) {
        float h0[4], h1[4];
        fetch(j->layer0, d->wrap, u, v, 4, h0);
        fetch(j->layer1, d->wrap, u, v, 4, h1);
        shadow = lx_horizon_light(h0, h1, lx_v3((float)lt[0], (float)lt[1], (float)lt[2]), 0.0f);
    }
    for (int c = 0; c < 3; c++) {
        double e = (double)d->light_color[c] * d->illuminance;
        double direct = (base[c] / SH_PI * diff + d->specular[c] * spec) * e * shadow;
        rgb[c] = (float)(direct + base[c] / SH_PI * d->ambient);
    }
}

static bool shade_rows(void *ctx, int y0, int y1, float *scratch)
{
    (void)scratch;
    const shade_job *j = ctx;
    int w = j->d->out_width;
    bool ok = true;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < w; x++) {
            float *o = j->out->data + ((size_t)y * (size_t)w + (size_t)x) * 3;
            shade_pixel(j, x, y, o);
            ok &= isfinite(o[0]) && isfinite(o[1]) && isfinite(o[2]);
        }
    return ok;
}

static bool finite3(const float *v)
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

lx_status lx_shade(const lx_shade_desc *desc, lx_image *out)
{
    if (!desc)
        return lx_fail_null(__func__, "desc");
    if (!out)
        return lx_fail(LX_ERR_INVALID, "shade: out must not be NULL");
    memset(out, 0, sizeof *out);
    lx_shade_desc d = lx_shade_desc_defaults(desc);
    const lx_image *hf = d.height;
    if (!hf && !d.normals)
        return lx_fail(LX_ERR_INVALID, "shade: a height or a normal image is needed");
    if (hf && (!hf->data || hf->channels != 1 || hf->width < 1 || hf->height < 1))
        return lx_fail(LX_ERR_INVALID, "shade: the height must be one channel with pixels");
    if (d.normals && (!d.normals->data || d.normals->channels < 3 || d.normals->width < 1))
        return lx_fail(LX_ERR_INVALID, "shade: the normals need 3 channels and pixels");
    if (d.base_color && (!d.base_color->data || d.base_color->channels < 3 ||
                         d.base_color->width < 1 || d.base_color->height < 1))
        return lx_fail(LX_ERR_INVALID, "shade: the base colour needs 3 channels and pixels");
    if (d.shape != LX_SHADE_QUAD && d.shape != LX_SHADE_SPHERE)
        return lx_fail(LX_ERR_INVALID, "shade: unknown shape %d", (int)d.shape);
    double ll = sqrt((double)d.light.x * d.light.x + (double)d.light.y * d.light.y +
                     (double)d.light.z * d.light.z);
    if (!(ll > 0.0) || !isfinite(ll))
        return lx_fail(LX_ERR_INVALID, "shade: the light direction is zero or not finite");
    if (!finite3(d.light_color) || !finite3(d.specular) || !isfinite(d.illuminance) ||
        !isfinite(d.ambient) || d.light_color[0] < 0 || d.light_color[1] < 0 ||
        d.light_color[2] < 0 || d.specular[0] < 0 || d.specular[1] < 0 || d.specular[2] < 0 ||
        d.illuminance < 0 || d.ambient < 0)
        return lx_fail(LX_ERR_INVALID, "shade: light, specular and ambient must be finite and >= 0");
    if (!(d.fov > 0.0f && d.fov < 170.0f))
        return lx_fail(LX_ERR_INVALID, "shade: fov %g is not in (0, 170) degrees", (double)d.fov);
    if (!(d.exponent > 0.0f && d.exponent < 1e6f) || !(d.strength > 0.0f) ||
        !isfinite(d.strength) || !isfinite(d.parallax_scale))
        return lx_fail(LX_ERR_INVALID, "shade: exponent, strength or parallax scale out of range");
    if (d.out_width < 1 || d.out_height < 1 || d.out_width > 16384 || d.out_height > 16384)
        return lx_fail(LX_ERR_INVALID, "shade: size %dx%d is not from 1 to 16384", d.out_width,
                       d.out_height);

    lx_image normals = {0}, parallax = {0}, layer0 = {0}, layer1 = {0};
    lx_status s = LX_OK;
    lx_normalmap_desc nd = {.strength = d.strength, .wrap = d.wrap, .threads = d.threads};
    if (!d.normals)
        s = lx_normal_map(hf, &nd, &normals);
    if (s == LX_OK && hf && !d.no_parallax)
        s = lx_parallax_map(hf, &nd, &parallax);
    if (s == LX_OK && hf && !d.no_horizon) {
        lx_horizon_desc hd = d.horizon;
        hd.strength = d.strength;
        hd.wrap = d.wrap;
        hd.threads = d.threads;
        hd.progress = NULL;
        s = lx_horizon_map(hf, &hd, &layer0, &layer1, NULL);
    }
    if (s == LX_OK)
        s = lx_image_alloc(out, d.out_width, d.out_height, 3);
    if (s == LX_OK) {
        shade_job job = {.d = &d,
                         .normals = d.normals ? d.normals : &normals,
                         .parallax = parallax.data ? &parallax : NULL,
                         .layer0 = layer0.data ? &layer0 : NULL,
                         .layer1 = layer1.data ? &layer1 : NULL,
                         .light = lx_v3((float)(d.light.x / ll), (float)(d.light.y / ll),
                                        (float)(d.light.z / ll)),
                         .out = out};
        job.dist = 1.0 / tan((double)d.fov * SH_PI / 360.0);
        job.radius = job.dist * sin((double)d.fov * SH_PI / 360.0);
        if (hf) {
            /* each of the iterations moves about the whole offset again */
            float depth = d.parallax_scale * d.strength / (float)LX_PARALLAX_ITERATIONS;
            job.pscale[0] = depth / (float)hf->width;
            job.pscale[1] = depth / (float)hf->height;
        }
        bool bad = false;
        s = lx_nm_run_rows(d.out_height, 1, d.threads, d.progress, d.progress_user, shade_rows,
                           &job, "shade", &bad);
        if (s == LX_ERR_INVALID && bad)
            s = lx_fail(LX_ERR_INVALID, "shade: a pixel came out not finite (a value in the "
                                        "inputs is NaN or too large)");
    }
    lx_image_free(&normals);
    lx_image_free(&parallax);
    lx_image_free(&layer0);
    lx_image_free(&layer1);
    if (s != LX_OK)
        lx_image_free(out);
    return s;
}
