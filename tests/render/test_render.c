/* Camera views with lightmaps (lx_render_view) against values computed
 * here: a plane under a constant lightmap shows base colour x E / pi, and
 * the 8-bit file the sRGB code of Hable's curve of it (the formula written
 * out below); a cube baked under uniform ambient light through luxel's own
 * UVs is one colour wherever an independent ray-box test says a whole
 * pixel sees the cube - chart borders included (no seams); the default
 * framing keeps the 8 corners of the bounds inside the image (projected
 * here); 1 and 2 threads give the same bits; lightmaps of another scene,
 * a missing page and a cancelled render fail. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"

#define PI_D 3.14159265358979323846

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static char *join(const char *dir, const char *name)
{
    static char buf[4][1024];
    static int k;
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static void write_constant_page(const char *path, int w, int h, float r, float g, float b)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, w, h, 3), LX_OK);
    for (int i = 0; i < w * h; i++) {
        img.data[3 * i + 0] = r;
        img.data[3 * i + 1] = g;
        img.data[3 * i + 2] = b;
    }
    assert_int_equal(lx_image_write(path, &img, NULL), LX_OK);
    lx_image_free(&img);
}

/* ---- the camera, written out independently -------------------------------- */

typedef struct basis {
    double eye[3], f[3], r[3], u[3], tx, ty;
} basis;

static void norm3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] /= l;
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static basis make_basis(const lx_camera *c, int w, int h)
{
    basis b;
    double t[3] = {c->target.x, c->target.y, c->target.z}, up[3] = {c->up.x, c->up.y, c->up.z};
    b.eye[0] = c->eye.x, b.eye[1] = c->eye.y, b.eye[2] = c->eye.z;
    for (int k = 0; k < 3; k++)
        b.f[k] = t[k] - b.eye[k];
    norm3(b.f);
    cross3(b.f, up, b.r);
    norm3(b.r);
    cross3(b.r, b.f, b.u);
    b.ty = tan(0.5 * (c->fov > 0 ? c->fov : 50.0 * PI_D / 180.0));
    b.tx = b.ty * w / h;
    return b;
}

/* Image position of p (pixels from the top-left corner). */
static void project(const basis *b, const double p[3], int w, int h, double *x, double *y,
                    double *z)
{
    double d[3] = {p[0] - b->eye[0], p[1] - b->eye[1], p[2] - b->eye[2]};
    *z = d[0] * b->f[0] + d[1] * b->f[1] + d[2] * b->f[2];
    double dx = d[0] * b->r[0] + d[1] * b->r[1] + d[2] * b->r[2];
    double dy = d[0] * b->u[0] + d[1] * b->u[1] + d[2] * b->u[2];
    *x = 0.5 * w * (1.0 + dx / (*z * b->tx));
    *y = 0.5 * h * (1.0 - dy / (*z * b->ty));
}

/* Does the ray through image point (x, y) hit the box [lo, hi]? (slabs) */
static bool ray_hits_box(const basis *b, double x, double y, int w, int h, const double lo[3],
                         const double hi[3])
{
    double px = (2.0 * x / w - 1.0) * b->tx, py = (1.0 - 2.0 * y / h) * b->ty;
    double d[3];
    for (int k = 0; k < 3; k++)
        d[k] = b->f[k] + px * b->r[k] + py * b->u[k];
    double t0 = 0.0, t1 = INFINITY;
    for (int k = 0; k < 3; k++) {
        double a = (lo[k] - b->eye[k]) / d[k], c = (hi[k] - b->eye[k]) / d[k];
        if (a > c) {
            double s = a;
            a = c;
            c = s;
        }
        t0 = fmax(t0, a);
        t1 = fmin(t1, c);
    }
    return t0 <= t1;
}

/* ---- a plane under a constant lightmap ------------------------------------ */

static lx_scene *plane_scene(lx_vec4 base)
{
    lx_scene *s = lx_test_new_scene("plane");
    lx_material mat = {.name = "paint", .base_color = base, .normal_scale = 1.0f};
    uint32_t mi;
    assert_int_equal(lx_scene_add_material(s, &mat, &mi), LX_OK);
    lx_mesh m = lx_test_plane("floor", 2.0f, 0.0f, 0.0f, 0.0f, 2);
    m.material = mi;
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    return s;
}

static const char *plane_manifest =
    "{\"scene\":\"plane\",\"quantity\":\"irradiance\",\"unit\":\"lx\",\"preview_ev100\":7,"
    "\"pre_exposure\":%g,\"pages\":[{\"file\":\"floor.exr\",\"width\":8,\"height\":8}],"
    "\"nodes\":[{\"node\":\"floor\",\"meshes\":[\"floor\"],\"page\":0,"
    "\"scale_offset\":[1,1,0,0],\"uv_set\":\"TEXCOORD_1\",\"uvs\":\"own\"}]}";

static double hable(double x)
{
    const double A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

static double srgb_code(double linear)
{
    double c = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
    return floor(c * 255.0 + 0.5);
}

static void test_plane_constant(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_plane");
    const double E[3] = {300.0, 200.0, 100.0}, base[3] = {0.8, 0.5, 0.25}, pre = 2.0;
    /* pre-exposed values: the renderer divides the factor out */
    write_constant_page(join(dir, "floor.exr"), 8, 8, (float)(E[0] * pre), (float)(E[1] * pre),
                        (float)(E[2] * pre));
    char text[1024];
    snprintf(text, sizeof text, plane_manifest, pre);
    write_text(join(dir, "manifest.json"), text);
    lx_scene *s = plane_scene(lx_v4(0.8f, 0.5f, 0.25f, 1.0f));
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    for (int filter = 0; filter < 2; filter++) {
        lx_render_desc d = lx_render_desc_defaults(NULL);
        d.width = 64, d.height = 36;
        d.filter = (lx_lightmap_filter)filter;
        d.camera = (lx_camera){
            .eye = {0, 2, 0}, .target = {0, 0, 0}, .up = {0, 0, -1}, .fov = 40.0f * LX_PI / 180.0f};
        lx_image img;
        assert_int_equal(lx_render_view(s, &lm, NULL, &d, &img), LX_OK);
        assert_int_equal(img.channels, 3);
        /* the middle 24x24 pixels see the plane (|x|, |z| < 0.6 m) */
        for (int y = 6; y < 30; y++)
            for (int x = 20; x < 44; x++)
                for (int k = 0; k < 3; k++) {
                    double want = base[k] * E[k] / PI_D;
                    /* float products and the 2x2 / 4x4 weights: 1.4e-7 measured */
                    assert_true(fabs(img.data[(y * 64 + x) * 3 + k] - want) < 6e-7 * want);
                }
        if (filter == 0) {
            /* the 8-bit file: exposure, Hable's curve, sRGB */
            const double ev = 7.0, exposure = 1.0 / (1.2 * pow(2.0, ev));
            lx_image_write_desc w = {.tonemap = LX_TONEMAP_FILMIC, .exposure = (float)exposure};
            const char *png = join(dir, "view.png");
            assert_int_equal(lx_image_write(png, &img, &w), LX_OK);
            lx_image back;
            lx_image_load_desc ld = {.raw_8bit = true, .channels = 3};
            assert_int_equal(lx_image_load(png, &ld, &back), LX_OK);
            for (int k = 0; k < 3; k++) {
                double v = base[k] * E[k] / PI_D * exposure;
                double want = srgb_code(hable(2.0 * v) / hable(11.2));
                double got = floor(back.data[(18 * 64 + 32) * 3 + k] * 255.0 + 0.5);
                assert_true(fabs(got - want) <= 1.0);
            }
            lx_image_free(&back);
        }
        lx_image_free(&img);
    }
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

/* Back faces are culled unless the material is double-sided (glTF
 * doubleSided): from under the plane, a single-sided one is not there
 * (the background, black) and a double-sided one shows its lightmap. */
static void test_double_sided_drawn(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_double_sided");
    const double E = 300.0, base = 0.5;
    write_constant_page(join(dir, "floor.exr"), 8, 8, (float)E, (float)E, (float)E);
    char text[1024];
    snprintf(text, sizeof text, plane_manifest, 1.0);
    write_text(join(dir, "manifest.json"), text);
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    for (int two = 0; two < 2; two++) {
        lx_scene *s = plane_scene(lx_v4((float)base, (float)base, (float)base, 1.0f));
        s->materials[s->meshes[0].material].double_sided = two;
        lx_render_desc d = lx_render_desc_defaults(NULL);
        d.width = 64, d.height = 36;
        d.camera = (lx_camera){.eye = {0, -2, 0},
                               .target = {0, 0, 0},
                               .up = {0, 0, -1},
                               .fov = 40.0f * LX_PI / 180.0f};
        lx_image img;
        assert_int_equal(lx_render_view(s, &lm, NULL, &d, &img), LX_OK);
        double want = two ? base * E / PI_D : 0.0;
        for (int y = 6; y < 30; y++)
            for (int x = 20; x < 44; x++)
                for (int k = 0; k < 3; k++)
                    assert_true(fabs(img.data[(y * 64 + x) * 3 + k] - want) <= 6e-7 * want);
        lx_image_free(&img);
        lx_scene_destroy(s);
    }
    lx_lightmaps_free(&lm);
}

/* An 8-bit page (bake --format png) holds E / pi at the preview exposure:
 * the render takes it back to lux. */
static void test_png_page(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_png");
    const double E = 150.0, ev = 6.3, exposure = 1.0 / (1.2 * pow(2.0, ev));
    lx_image page;
    assert_int_equal(lx_image_alloc(&page, 8, 8, 3), LX_OK);
    for (int i = 0; i < 8 * 8 * 3; i++)
        page.data[i] = (float)E;
    lx_image_write_desc w = {.exposure = (float)(exposure / PI_D)};
    assert_int_equal(lx_image_write(join(dir, "floor.png"), &page, &w), LX_OK);
    lx_image_free(&page);
    char text[1024];
    snprintf(text, sizeof text,
             "{\"scene\":\"plane\",\"format\":\"png\",\"preview_ev100\":%g,"
             "\"pages\":[{\"file\":\"floor.png\",\"width\":8,\"height\":8}],"
             "\"nodes\":[{\"node\":\"floor\",\"meshes\":[\"floor\"],\"page\":0,"
             "\"scale_offset\":[1,1,0,0],\"uv_set\":\"TEXCOORD_1\"}]}",
             ev);
    write_text(join(dir, "manifest.json"), text);
    lx_scene *s = plane_scene(lx_v4(0.5f, 0.5f, 0.5f, 1.0f));
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    lx_render_desc d = {.width = 16, .height = 16, .samples = 1};
    d.camera = (lx_camera){
        .eye = {0, 2, 0}, .target = {0, 0, 0}, .up = {0, 0, -1}, .fov = 20.0f * LX_PI / 180.0f};
    lx_image img;
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &img), LX_OK);
    double want = 0.5 * E / PI_D;
    /* the stored value E / pi x exposure = 0.50 is within half an sRGB
     * code step of 0.50: 0.7% at most */
    for (int k = 0; k < 16 * 16 * 3; k++)
        assert_true(fabs(img.data[k] - want) < 0.007 * want);
    lx_image_free(&img);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

/* Radiance pages (--quantity radiance) already hold E x albedo / pi: shown
 * as stored, not multiplied by the base colour again. */
static void test_radiance_page(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_radiance");
    write_constant_page(join(dir, "floor.exr"), 8, 8, 12.0f, 6.0f, 3.0f);
    char text[1024];
    snprintf(text, sizeof text, plane_manifest, 1.0);
    char *q = strstr(text, "\"irradiance\"");
    assert_non_null(q);
    memcpy(q, "\"radiance\"  ", 12); /* same length: "irradiance" in quotes */
    write_text(join(dir, "manifest.json"), text);
    lx_scene *s = plane_scene(lx_v4(0.5f, 0.25f, 0.125f, 1.0f));
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    assert_int_equal(lm.quantity, LX_QUANTITY_RADIANCE);
    lx_render_desc d = {.width = 8, .height = 8, .samples = 2};
    d.camera = (lx_camera){
        .eye = {0, 2, 0}, .target = {0, 0, 0}, .up = {0, 0, -1}, .fov = 20.0f * LX_PI / 180.0f};
    lx_image img;
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &img), LX_OK);
    const float want[3] = {12.0f, 6.0f, 3.0f};
    /* bilinear weights of equal texels: exact to a few ulps */
    for (int k = 0; k < 8 * 8 * 3; k++)
        assert_true(fabsf(img.data[k] - want[k % 3]) < 4e-6f * want[k % 3]);
    lx_image_free(&img);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

/* An emissive material draws its own radiance on top of what it reflects:
 * L = base / pi x E + emission x the bake's emissive_scale (manifest
 * "indirect"), nits, as any glTF viewer draws emissiveFactor. */
static void test_emissive_plane(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_emissive");
    const double E = 40.0, base = 0.5, emit[3] = {2.0, 1.0, 0.5}, scale = 30.0;
    write_constant_page(join(dir, "floor.exr"), 8, 8, (float)E, (float)E, (float)E);
    char text[1024];
    snprintf(text, sizeof text, plane_manifest, 1.0);
    /* the bake's emissive scale, in the manifest's "indirect" */
    char *tail = strrchr(text, '}');
    assert_non_null(tail);
    snprintf(tail, sizeof text - (size_t)(tail - text),
             ",\"indirect\":{\"bounces\":2,\"gi_samples\":16,\"emissive_scale\":%g}}", scale);
    write_text(join(dir, "manifest.json"), text);
    lx_scene *s = lx_test_new_scene("plane");
    lx_material mat = {.name = "panel",
                       .base_color = {(float)base, (float)base, (float)base, 1.0f},
                       .emissive = {(float)emit[0], (float)emit[1], (float)emit[2]},
                       .normal_scale = 1.0f};
    uint32_t mi;
    assert_int_equal(lx_scene_add_material(s, &mat, &mi), LX_OK);
    lx_mesh m = lx_test_plane("floor", 2.0f, 0.0f, 0.0f, 0.0f, 2);
    m.material = mi;
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    assert_true(fabs(lm.emissive_scale - scale) < 1e-6 * scale);
    lx_render_desc d = {.width = 8, .height = 8, .samples = 2};
    d.camera = (lx_camera){
        .eye = {0, 2, 0}, .target = {0, 0, 0}, .up = {0, 0, -1}, .fov = 20.0f * LX_PI / 180.0f};
    lx_image img;
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &img), LX_OK);
    for (int k = 0; k < 8 * 8 * 3; k++) {
        double want = base * E / PI_D + emit[k % 3] * scale;
        /* float sums of equal texels: a few ulps */
        assert_true(fabs(img.data[k] - want) < 4e-6 * want);
    }
    lx_image_free(&img);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

/* ---- a cube baked under uniform light, through generated UVs -------------- */

#define AMBIENT 50.0f
#define GREY 0.7f

static lx_scene *cube_scene(void)
{
    lx_scene *s = lx_test_new_scene("cube");
    lx_material mat = {.name = "grey", .base_color = {GREY, GREY, GREY, 1}, .normal_scale = 1.0f};
    uint32_t mi;
    assert_int_equal(lx_scene_add_material(s, &mat, &mi), LX_OK);
    lx_mesh m = lx_test_box("cube", lx_v3(-0.5f, 0.0f, -0.5f), lx_v3(0.5f, 1.0f, 0.5f), false);
    m.material = mi;
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    s->ambient = lx_v3(AMBIENT, AMBIENT, AMBIENT);
    return s;
}

/* Unwraps the cube, bakes it with dilation and writes pages + manifest
 * into dir, as luxel bake does. The scene gets the page UVs. */
static void bake_cube(lx_scene *s, const char *dir)
{
    lx_unwrap_desc ud = lx_unwrap_desc_defaults(NULL);
    ud.texel_density = 32.0f;
    ud.padding = LX_UNWRAP_PADDING_RECOMMENDED;
    lx_unwrap *u;
    assert_int_equal(lx_unwrap_scene(s, &ud, &u), LX_OK);
    assert_int_equal(lx_unwrap_apply(s, u), LX_OK);
    lx_bake_desc bd = lx_bake_desc_defaults(NULL);
    bd.atlas = u;
    bd.padding = LX_PADDING_RECOMMENDED;
    lx_baker *b;
    assert_int_equal(lx_baker_create(s, &bd, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    char text[4096];
    int n = snprintf(text, sizeof text,
                     "{\"scene\":\"cube\",\"quantity\":\"irradiance\","
                     "\"preview_ev100\":5,\"pages\":[");
    for (uint32_t p = 0; p < lx_baker_lightmap_count(b); p++) {
        lx_image img;
        assert_int_equal(lx_baker_apply_alloc(b, p, &img), LX_OK);
        char name[64];
        snprintf(name, sizeof name, "lightmap-%u.exr", p);
        assert_int_equal(lx_image_write(join(dir, name), &img, NULL), LX_OK);
        n += snprintf(text + n, sizeof text - (size_t)n,
                      "%s{\"file\":\"%s\",\"width\":%d,"
                      "\"height\":%d}",
                      p ? "," : "", name, img.width, img.height);
        lx_image_free(&img);
    }
    assert_int_equal(s->node_count, 1);
    n += snprintf(text + n, sizeof text - (size_t)n,
                  "],\"nodes\":[{\"node\":\"%s\",\"meshes\":[\"x\"],\"page\":%u,"
                  "\"scale_offset\":[1,1,0,0],\"uv_set\":\"TEXCOORD_1\",\"uvs\":\"generated\"}]}",
                  s->nodes[0].name, u->nodes[0].page);
    write_text(join(dir, "manifest.json"), text);
    lx_baker_destroy(b);
    lx_unwrap_destroy(u);
}

static void test_cube_no_seams(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_cube");
    lx_scene *s = cube_scene();
    bake_cube(s, dir);
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    const int W = 320, H = 180;
    const double lo[3] = {-0.5, 0.0, -0.5}, hi[3] = {0.5, 1.0, 0.5};
    const double want = GREY * AMBIENT / PI_D;
    for (int filter = 0; filter < 2; filter++)
        for (int view = LX_VIEW_ISO; view <= LX_VIEW_TOP; view++) {
            lx_render_desc d = lx_render_desc_defaults(NULL);
            d.width = W, d.height = H;
            d.filter = (lx_lightmap_filter)filter;
            d.camera = lx_camera_frame(lx_v3(-0.5f, 0.0f, -0.5f), lx_v3(0.5f, 1.0f, 0.5f),
                                       (lx_view)view, 0.0f, (float)W / H);
            lx_image img;
            assert_int_equal(lx_render_view(s, &lm, NULL, &d, &img), LX_OK);
            basis b = make_basis(&d.camera, W, H);
            int inside = 0;
            double worst = 0.0;
            for (int y = 0; y < H; y++)
                for (int x = 0; x < W; x++) {
                    /* the cube's outline is convex: 4 corners in, whole pixel in */
                    bool all = true;
                    for (int c = 0; c < 4 && all; c++)
                        all = ray_hits_box(&b, x + (c & 1), y + (c >> 1), W, H, lo, hi);
                    if (!all)
                        continue;
                    inside++;
                    for (int k = 0; k < 3; k++)
                        worst = fmax(worst, fabs(img.data[(y * W + x) * 3 + k] - want) / want);
                }
            /* a seam (black or another chart's texels) is off by tens of
             * percent (the bicubic lookup without the padding: 14%); float
             * rounding in the bake and the lookups measured 2.4e-7 */
            assert_true(inside > 2000);
            if (worst > 1e-6)
                fail_msg("view %d filter %d: a pixel on the cube is off by %g", view, filter,
                         worst);
            lx_image_free(&img);
        }
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

/* ---- framing ----------------------------------------------------------------- */

static void test_framing(void **state)
{
    (void)state;
    const float boxes[][6] = {{-1, 0, -1, 1, 2, 1},
                              {0, 0, 0, 10, 0.1f, 4},
                              {-50, -3, 7, -20, 30, 9},
                              {2, 2, 2, 2.001f, 2.001f, 2.001f},
                              {-0.2f, 0, -5, 0.2f, 0.3f, 5}};
    const int sizes[][2] = {{1280, 720}, {400, 800}, {100, 100}};
    const float fovs[] = {0.0f, 20.0f, 90.0f};
    for (size_t bi = 0; bi < sizeof boxes / sizeof boxes[0]; bi++)
        for (int view = LX_VIEW_ISO; view <= LX_VIEW_TOP; view++)
            for (int si = 0; si < 3; si++)
                for (int fi = 0; fi < 3; fi++) {
                    const float *bx = boxes[bi];
                    int W = sizes[si][0], H = sizes[si][1];
                    lx_camera c =
                        lx_camera_frame(lx_v3(bx[0], bx[1], bx[2]), lx_v3(bx[3], bx[4], bx[5]),
                                        (lx_view)view, fovs[fi] * LX_PI / 180.0f, (float)W / H);
                    assert_int_equal(lx_camera_check(&c), LX_OK);
                    basis b = make_basis(&c, W, H);
                    double margin = INFINITY;
                    double far = 0.0, extent = sqrt((bx[3] - bx[0]) * (bx[3] - bx[0]) +
                                                    (bx[4] - bx[1]) * (bx[4] - bx[1]) +
                                                    (bx[5] - bx[2]) * (bx[5] - bx[2]));
                    for (int k = 0; k < 6; k++)
                        far = fmax(far, fabs(bx[k]));
                    double tol = 1e-5 + 4e-7 * far / extent;
                    for (int k = 0; k < 8; k++) {
                        double p[3] = {k & 1 ? bx[3] : bx[0], k & 2 ? bx[4] : bx[1],
                                       k & 4 ? bx[5] : bx[2]};
                        double x, y, z;
                        project(&b, p, W, H, &x, &y, &z);
                        assert_true(z > 0.0);
                        assert_true(x >= 0.0 && x <= W && y >= 0.0 && y <= H);
                        margin =
                            fmin(margin, fmin(fmin(x / W, 1.0 - x / W), fmin(y / H, 1.0 - y / H)));
                        /* the library's projection agrees with this one */
                        float lxp, lyp;
                        assert_true(lx_camera_project(
                            &c, W, H, lx_v3((float)p[0], (float)p[1], (float)p[2]), &lxp, &lyp));
                        assert_true(fabs(lxp - x) < 1e-3 * W && fabs(lyp - y) < 1e-3 * H);
                    }
                    /* tight: the eye is as close as the corners allow, so
                     * on the binding axis a corner sits on the 5% border
                     * (2.5% of the image a side); float rounding measured
                     * 3e-6, and 1.7e-4 on the 1 mm box 3.5 m out, whose
                     * corners floats place to 2e-7 of their distance */
                    if (fabs(margin - 0.025) > tol)
                        fail_msg("box %zu view %d: nearest corner %g from the edge", bi, view,
                                 margin);
                }
}

/* ---- determinism, bad input, cancellation ------------------------------------ */

static void test_threads_identical(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_threads");
    lx_scene *s = cube_scene();
    bake_cube(s, dir);
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    lx_image img[2];
    for (int t = 0; t < 2; t++) {
        lx_render_desc d = lx_render_desc_defaults(NULL);
        d.width = 200, d.height = 120;
        d.samples = 3;
        d.threads = t + 1;
        assert_int_equal(lx_render_view(s, &lm, NULL, &d, &img[t]), LX_OK);
    }
    assert_memory_equal(img[0].data, img[1].data, sizeof(float) * 200 * 120 * 3);
    lx_image_free(&img[0]);
    lx_image_free(&img[1]);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(s);
}

static void test_other_scene(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_other");
    write_constant_page(join(dir, "floor.exr"), 8, 8, 1, 1, 1);
    char text[1024];
    snprintf(text, sizeof text, plane_manifest, 1.0);
    write_text(join(dir, "manifest.json"), text);
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    /* the cube's node is not the plane's */
    lx_scene *s = cube_scene();
    lx_image img;
    assert_int_equal(lx_render_view(s, &lm, NULL, NULL, &img), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "another scene"));
    assert_null(img.data);
    lx_scene_destroy(s);
    /* a scene with one more lit node than the manifest lists */
    s = plane_scene(lx_v4(1, 1, 1, 1));
    lx_mesh m = lx_test_plane("floor2", 1.0f, 1.0f, 0.0f, 0.0f, 1);
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    assert_int_equal(lx_lightmaps_check(&lm, s), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "floor2"));
    lx_scene_destroy(s);
    lx_lightmaps_free(&lm);

    /* a page that is not there, and one of the wrong size */
    remove(join(dir, "floor.exr"));
    assert_int_not_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    assert_non_null(strstr(lx_last_error(), "floor.exr"));
    write_constant_page(join(dir, "floor.exr"), 4, 8, 1, 1, 1);
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "4x8"));
    /* no manifest */
    assert_int_equal(lx_lightmaps_load(lx_test_dir("render_none"), NULL, &lm), LX_ERR_IO);
    assert_non_null(strstr(lx_last_error(), "manifest.json"));
}

static bool stop_early(void *user, float fraction)
{
    (void)fraction;
    int *calls = user;
    return ++*calls < 2;
}

static void test_cancel(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("render_cancel");
    write_constant_page(join(dir, "floor.exr"), 8, 8, 1, 1, 1);
    char text[1024];
    snprintf(text, sizeof text, plane_manifest, 1.0);
    write_text(join(dir, "manifest.json"), text);
    lx_lightmaps lm;
    assert_int_equal(lx_lightmaps_load(dir, NULL, &lm), LX_OK);
    lx_scene *s = plane_scene(lx_v4(1, 1, 1, 1));
    int calls = 0;
    lx_render_desc d = {
        .width = 256, .height = 256, .progress = stop_early, .progress_user = &calls};
    lx_image img;
    assert_int_equal(lx_render_view(s, &lm, NULL, &d, &img), LX_ERR_CANCELLED);
    assert_null(img.data);
    /* a camera with eye == target cannot make an image */
    lx_camera bad = {.eye = {1, 1, 1}, .target = {1, 1, 1}, .up = {0, 1, 0}};
    assert_int_equal(lx_camera_check(&bad), LX_ERR_INVALID);
    lx_scene_destroy(s);
    lx_lightmaps_free(&lm);
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane_constant),
        cmocka_unit_test(test_png_page),
        cmocka_unit_test(test_radiance_page),
        cmocka_unit_test(test_emissive_plane),
        cmocka_unit_test(test_cube_no_seams),
        cmocka_unit_test(test_framing),
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_other_scene),
        cmocka_unit_test(test_cancel),
        cmocka_unit_test(test_double_sided_drawn),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
