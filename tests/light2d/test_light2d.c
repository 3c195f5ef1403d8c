/* Tests of 2D shadowed lights (src/light2d) against values computed here:
 * hard shadows of random caster images against an exact visibility found by
 * marching the segment from the light to each pixel centre (mismatches only
 * next to shadow edges), falloffs against their formulas, a light in a
 * closed ring lighting nothing outside it, mirror symmetry, soft shadows
 * (lit and shadowed regions as the hard shadow, penumbra widths as a light
 * of radius `softness` predicts by similar triangles), N.L over a normal
 * map, identical bytes on 1 and 2 threads, the static-light cache, and the
 * lights JSON's errors. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "luxel/light2d.h"

/* test_soft_against_disk's bounds on the mean difference from a light
 * disk, a small factor above the 0.0080 (lit side) and 0.0471 (shadow
 * side) measured (0.0186 and 0.0483 before each ray was sampled along its
 * middle line, issue 28) */
#define LIT_SIDE_TOL 0.02
#define SHADOW_SIDE_TOL 0.06

/* deterministic random numbers of the test's own */
static uint32_t rng_state = 12345u;
static uint32_t rnd(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return rng_state >> 8;
}
static float rndf(void)
{
    return (float)(rnd() & 0xffff) / 65536.0f;
}

/* An RGBA image with `rects` random opaque rectangles. */
static void random_casters(lx_image *img, int w, int h, int rects, uint32_t seed)
{
    rng_state = seed;
    assert_int_equal(lx_image_alloc(img, w, h, 4), LX_OK);
    for (int r = 0; r < rects; r++) {
        int x0 = (int)(rnd() % (unsigned)w), y0 = (int)(rnd() % (unsigned)h);
        int rw = 1 + (int)(rnd() % 12u), rh = 1 + (int)(rnd() % 12u);
        for (int y = y0; y < y0 + rh && y < h; y++)
            for (int x = x0; x < x0 + rw && x < w; x++)
                img->data[((size_t)y * w + x) * 4 + 3] = 1.0f;
    }
}

static bool caster_at(const lx_image *img, int x, int y)
{
    if (x < 0 || y < 0 || x >= img->width || y >= img->height)
        return false;
    return img->data[((size_t)y * img->width + x) * 4 + 3] >= 0.5f;
}

/* Exact visibility by marching the segment light -> (cx, cy) in steps of
 * 1/64 pixel. self_shadow: any caster on the way (the end's own included)
 * blocks; otherwise the first caster run met may contain the end. */
static bool reference_lit_at(const lx_image *img, float lx, float ly, double cx, double cy,
                             bool self_shadow)
{
    double len = hypot(cx - lx, cy - ly);
    int steps = (int)ceil(len * 64.0);
    bool in_run = false, left_run = false;
    for (int i = 0; i <= steps; i++) {
        double t = steps ? (double)i / steps : 1.0;
        int x = (int)floor(lx + t * (cx - lx)), y = (int)floor(ly + t * (cy - ly));
        bool c = caster_at(img, x, y);
        if (self_shadow) {
            if (c)
                return false;
            continue;
        }
        if (c && left_run)
            return false;
        if (c)
            in_run = true;
        else if (in_run)
            left_run = true;
    }
    return !left_run;
}

/* reference_lit_at the centre of pixel (px, py). */
static bool reference_lit(const lx_image *img, float lx, float ly, int px, int py,
                          bool self_shadow)
{
    return reference_lit_at(img, lx, ly, px + 0.5, py + 0.5, self_shadow);
}

/* Whether the segments to the centre of (px, py) turned about the light
 * by 17 angles evenly over [-delta, delta] all find the same: a polar map
 * of n rays samples each ray along its middle line, which passes up to
 * half a ray (delta = 4/n radians: a ray spans at most 8/n) to either side
 * of a pixel's own line, so where they differ (a shadow's edge, or a
 * sliver of light between two shadows) the pixel may go either way. */
static bool reference_clear(const lx_image *img, float lx, float ly, int px, int py,
                            bool self_shadow, double delta)
{
    double dx = px + 0.5 - lx, dy = py + 0.5 - ly;
    bool first = reference_lit(img, lx, ly, px, py, self_shadow);
    for (int k = -8; k <= 8; k++) {
        double c = cos(k * delta / 8.0), s = sin(k * delta / 8.0);
        if (reference_lit_at(img, lx, ly, lx + dx * c - dy * s, ly + dx * s + dy * c,
                             self_shadow) != first)
            return false;
    }
    return true;
}

/* Light map of one light over casters, ambient 0. */
static float *render_one(const lx_image *casters, const lx_light2d_light *l, int threads,
                         const lx_image *normals)
{
    lx_light2d_desc d = {.threads = threads};
    lx_light2d *ctx = NULL;
    assert_int_equal(lx_light2d_create(casters, &d, &ctx), LX_OK);
    if (normals)
        assert_int_equal(lx_light2d_set_normals(ctx, normals, false), LX_OK);
    assert_int_equal(lx_light2d_set_lights(ctx, l, 1), LX_OK);
    float *lm = malloc((size_t)casters->width * casters->height * 3 * sizeof *lm);
    assert_non_null(lm);
    assert_int_equal(lx_light2d_render(ctx, lx_v3(0, 0, 0), NULL, NULL, lm), LX_OK);
    lx_light2d_destroy(ctx);
    return lm;
}

/* Counts pixels whose lit state differs from the reference, and those of
 * them farther than 2 pixels from any reference shadow edge whose
 * reference is the same within half a ray of the map (reference_clear,
 * n rays). */
static void compare_hard(const lx_image *img, const lx_light2d_light *l, int n, const float *lm,
                         int *mismatches, int *far_mismatches, int *lit_count)
{
    int w = img->width, h = img->height;
    unsigned char *ref = malloc((size_t)w * h);
    unsigned char *inside = malloc((size_t)w * h);
    assert_non_null(ref);
    assert_non_null(inside);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double dx = x + 0.5 - l->x, dy = y + 0.5 - l->y;
            inside[y * w + x] = hypot(dx, dy) < l->radius - 1.5;
            ref[y * w + x] = reference_lit(img, l->x, l->y, x, y, l->self_shadow);
        }
    *mismatches = *far_mismatches = *lit_count = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            if (!inside[y * w + x])
                continue;
            bool lit = lm[3 * ((size_t)y * w + x)] > 0.0f;
            *lit_count += ref[y * w + x];
            if (lit == (bool)ref[y * w + x])
                continue;
            (*mismatches)++;
            bool near_edge = false;
            for (int j = -2; j <= 2 && !near_edge; j++)
                for (int i = -2; i <= 2; i++) {
                    int xx = x + i, yy = y + j;
                    /* a shadow line starts at every caster corner: a
                     * caster this close has one within 2 px, even when
                     * it falls between pixel centres */
                    if (xx >= 0 && yy >= 0 && xx < w && yy < h &&
                        (ref[yy * w + xx] != ref[y * w + x] || caster_at(img, xx, yy))) {
                        near_edge = true;
                        break;
                    }
                }
            if (!near_edge && reference_clear(img, l->x, l->y, x, y, l->self_shadow, 4.0 / n)) {
                if (*far_mismatches < 6)
                    print_message("  far mismatch at %d,%d: reference %d\n", x, y,
                                  ref[y * w + x]);
                (*far_mismatches)++;
            }
        }
    free(ref);
    free(inside);
}

static void hard_case(lx_light2d_type type, bool self_shadow, uint32_t seed)
{
    lx_image img;
    random_casters(&img, 128, 96, 25, seed);
    lx_light2d_light l = lx_light2d_light_defaults(type);
    l.x = 50.3f + 20.0f * rndf();
    l.y = 40.7f + 10.0f * rndf();
    /* keep the light off casters */
    for (int y = (int)l.y - 2; y <= (int)l.y + 2; y++)
        for (int x = (int)l.x - 2; x <= (int)l.x + 2; x++)
            img.data[((size_t)y * img.width + x) * 4 + 3] = 0.0f;
    l.radius = 90.0f;
    l.falloff = LX_FALLOFF2D_NONE;
    l.self_shadow = self_shadow;
    if (type == LX_LIGHT2D_SPOT) {
        l.dir_x = 1.0f;
        l.dir_y = 0.6f;
        l.arc = 360.0f; /* the cone is tested elsewhere: here, the shadows */
    }
    float *lm = render_one(&img, &l, 2, NULL);
    int mis, far, lit;
    lx_light2d *ctx = NULL;
    assert_int_equal(lx_light2d_create(&img, NULL, &ctx), LX_OK);
    int n = lx_light2d_rays(ctx, &l);
    lx_light2d_destroy(ctx);
    compare_hard(&img, &l, n, lm, &mis, &far, &lit);
    print_message("hard shadows (seed %u, self_shadow %d): %d lit, %d mismatches, %d away "
                  "from edges\n",
                  seed, self_shadow, lit, mis, far);
    assert_true(lit > 500);
    assert_int_equal(far, 0);
    assert_true(mis < lit / 8);
    free(lm);
    lx_image_free(&img);
}

static void test_hard_shadows(void **state)
{
    (void)state;
    for (uint32_t s = 1; s <= 3; s++) {
        hard_case(LX_LIGHT2D_POINT, true, s);
        hard_case(LX_LIGHT2D_POINT, false, s + 10);
        hard_case(LX_LIGHT2D_SPOT, true, s + 20);
    }
}

static void test_falloffs(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 64, 64, 4), LX_OK);
    lx_light2d_falloff kinds[3] = {LX_FALLOFF2D_SMOOTH, LX_FALLOFF2D_LINEAR, LX_FALLOFF2D_NONE};
    for (int k = 0; k < 3; k++) {
        lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
        l.x = 30.3f;
        l.y = 33.8f;
        l.radius = 25.0f;
        l.falloff = kinds[k];
        l.color = lx_v3(1.0f, 0.5f, 0.25f);
        l.intensity = 2.0f;
        float *lm = render_one(&img, &l, 1, NULL);
        double worst = 0.0;
        for (int y = 0; y < 64; y++)
            for (int x = 0; x < 64; x++) {
                double d = hypot(x + 0.5 - l.x, y + 0.5 - l.y), q = d / l.radius, f;
                if (q >= 1.0)
                    f = 0.0;
                else if (k == 0)
                    f = (1.0 - q * q) * (1.0 - q * q);
                else if (k == 1)
                    f = 1.0 - q;
                else
                    f = 1.0;
                const float *v = lm + 3 * (y * 64 + x);
                worst = fmax(worst, fabs(v[0] - 2.0 * f));
                worst = fmax(worst, fabs(v[1] - 1.0 * f));
                worst = fmax(worst, fabs(v[2] - 0.5 * f));
            }
        assert_true(worst < 1e-5);
        free(lm);
    }
    /* a spot: nothing outside the arc, full inside it less the edge */
    lx_light2d_light s = lx_light2d_light_defaults(LX_LIGHT2D_SPOT);
    s.x = 32.0f;
    s.y = 32.0f;
    s.radius = 30.0f;
    s.falloff = LX_FALLOFF2D_NONE;
    s.dir_x = 0.0f;
    s.dir_y = 1.0f;
    s.arc = 90.0f;
    s.edge = 10.0f;
    float *lm = render_one(&img, &s, 1, NULL);
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            double dx = x + 0.5 - s.x, dy = y + 0.5 - s.y;
            double d = hypot(dx, dy);
            if (d >= s.radius || d == 0.0)
                continue;
            double ang = acos(dy / d) * 180.0 / 3.14159265358979323846;
            float v = lm[3 * (y * 64 + x)];
            if (ang > 45.0 + 1e-3)
                assert_true(v == 0.0f);
            else if (ang < 35.0 - 1e-3)
                assert_true(fabsf(v - 1.0f) < 1e-6f);
            else
                assert_true(v >= 0.0f && v <= 1.0f);
        }
    free(lm);
    lx_image_free(&img);
}

static void test_ring(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 100, 100, 4), LX_OK);
    for (int y = 0; y < 100; y++)
        for (int x = 0; x < 100; x++) {
            double d = hypot(x + 0.5 - 50.0, y + 0.5 - 50.0);
            if (d >= 20.0 && d <= 23.0)
                img.data[(y * 100 + x) * 4 + 3] = 1.0f;
        }
    for (int soft = 0; soft < 2; soft++) {
        lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
        l.x = 44.0f;
        l.y = 53.0f;
        l.radius = 80.0f;
        l.softness = soft ? 4.0f : 0.0f;
        float *lm = render_one(&img, &l, 2, NULL);
        int lit_inside = 0;
        for (int y = 0; y < 100; y++)
            for (int x = 0; x < 100; x++) {
                double d = hypot(x + 0.5 - 50.0, y + 0.5 - 50.0);
                float v = lm[3 * (y * 100 + x)];
                if (d > 23.8)
                    assert_true(v == 0.0f);
                if (d < 19.0 && v > 0.0f)
                    lit_inside++;
            }
        assert_true(lit_inside > 1000);
        free(lm);
    }
    lx_image_free(&img);
}

/* A soft light of radius 3 px (a few dozen rays, fewer than 8 levels of
 * its tables: their scratch overran the table, seen under ASan) lights
 * its disc and nothing past its radius. */
static void test_small_soft_light(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 24, 24, 4), LX_OK);
    img.data[(12 * 24 + 12) * 4 + 3] = 1.0f; /* one caster pixel beside it */
    lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
    l.x = 8.0f;
    l.y = 12.0f;
    l.radius = 3.0f;
    l.softness = 41.0f;
    float *lm = render_one(&img, &l, 1, NULL);
    for (int y = 0; y < 24; y++)
        for (int x = 0; x < 24; x++) {
            float v = lm[3 * (y * 24 + x)];
            assert_true(isfinite(v) && v >= 0.0f);
            if (hypot(x + 0.5 - 8.0, y + 0.5 - 12.0) > 4.0)
                assert_true(v == 0.0f);
        }
    assert_true(lm[3 * (12 * 24 + 8)] > 0.0f);
    free(lm);
    lx_image_free(&img);
}

static void test_mirror(void **state)
{
    (void)state;
    lx_image a, b;
    random_casters(&a, 96, 80, 30, 77);
    assert_int_equal(lx_image_alloc(&b, 96, 80, 4), LX_OK);
    for (int y = 0; y < 80; y++)
        for (int x = 0; x < 96; x++)
            b.data[(y * 96 + (95 - x)) * 4 + 3] = a.data[(y * 96 + x) * 4 + 3];
    lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
    l.x = 40.25f;
    l.y = 37.5f;
    l.radius = 70.0f;
    for (int yy = 35; yy < 40; yy++)
        for (int xx = 38; xx < 43; xx++) {
            a.data[(yy * 96 + xx) * 4 + 3] = 0.0f;
            b.data[(yy * 96 + 95 - xx) * 4 + 3] = 0.0f;
        }
    lx_light2d_light m = l;
    m.x = 96.0f - l.x;
    float *la = render_one(&a, &l, 1, NULL), *lb = render_one(&b, &m, 1, NULL);
    int differ = 0, lit = 0;
    for (int y = 0; y < 80; y++)
        for (int x = 0; x < 96; x++) {
            float va = la[3 * (y * 96 + x)], vb = lb[3 * (y * 96 + 95 - x)];
            lit += va > 0.0f;
            if ((va > 0.0f) != (vb > 0.0f))
                differ++;
            else if (va > 0.0f)
                assert_true(fabsf(va - vb) < 1e-5f);
        }
    print_message("mirror: %d lit, %d differ\n", lit, differ);
    assert_true(differ <= lit / 100);
    free(la);
    free(lb);
    lx_image_free(&a);
    lx_image_free(&b);
}

/* A bar from x = 0 to 100, y = 60..64 under a light at (100, 20): the
 * shadow edge is the vertical line x = 100. A light of radius s gives a
 * penumbra 2 s (d - o) / o wide at distance d behind an occluder at o. */
static void test_soft(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 200, 200, 4), LX_OK);
    for (int y = 60; y < 64; y++)
        for (int x = 0; x < 100; x++)
            img.data[(y * 200 + x) * 4 + 3] = 1.0f;
    lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
    l.x = 100.0f;
    l.y = 20.0f;
    l.radius = 400.0f;
    l.falloff = LX_FALLOFF2D_NONE;
    float *hard = render_one(&img, &l, 2, NULL);
    l.softness = 8.0f;
    float *soft = render_one(&img, &l, 2, NULL);
    double prev = 0.0;
    int rows[3] = {100, 140, 190};
    for (int r = 0; r < 3; r++) {
        int y = rows[r];
        double d = y + 0.5 - l.y, o = 40.0;
        double predicted = 2.0 * l.softness * (d - o) / o;
        /* the width of the 5%..95% ramp, 0.9 of the full penumbra */
        int inside = 0;
        for (int x = 0; x < 200; x++) {
            float v = soft[3 * (y * 200 + x)];
            if (v > 0.05f && v < 0.95f)
                inside++;
            double dist = fabs(x + 0.5 - 100.0);
            if (dist > 0.5 * predicted + 2.0)
                assert_true(v == hard[3 * (y * 200 + x)]);
        }
        print_message("row %d: penumbra %d px, predicted %.1f (5..95%%: %.1f)\n", y, inside,
                      predicted, 0.9 * predicted);
        assert_true(fabs(inside - 0.9 * predicted) <= 0.2 * predicted + 2.0);
        assert_true(inside > prev);
        prev = inside;
    }
    free(hard);
    free(soft);
    lx_image_free(&img);
}

/* The share of a light disk of radius s at (lx, ly) that the point (px,
 * py) sees, by brute force: m directions evenly spread over the angle the
 * disk subtends, each segment to the disk marched through the caster
 * mask in steps of 1/4 pixel. */
static double disk_visibility(const lx_image *img, double px, double py, double lx, double ly,
                              double s, int m)
{
    double dx = lx - px, dy = ly - py, d = hypot(dx, dy);
    double half = asin(s / d), mid = atan2(dy, dx);
    int seen = 0;
    for (int j = 0; j < m; j++) {
        double a = mid + half * (-1.0 + (2.0 * j + 1.0) / m);
        double ux = cos(a), uy = sin(a), off = a - mid;
        /* to where the direction enters the disk */
        double len = d * cos(off) - sqrt(fmax(0.0, s * s - d * d * sin(off) * sin(off)));
        bool open = true;
        for (double t = 0.25; t < len && open; t += 0.25)
            open = !caster_at(img, (int)floor(px + t * ux), (int)floor(py + t * uy));
        seen += open;
    }
    return (double)seen / m;
}

/* Soft shadows against the light disk itself: over random casters, the
 * mean difference from the brute-force disk visibility of every pixel
 * (casters and those within the light's diameter of it aside), apart for
 * those the light's centre sees (the lit side) and those in its hard
 * shadow: the penumbrae's error, spread over the pixels of that side. The
 * model (docs/light2d.md) is exact for one caster's straight edge; where
 * casters at several depths or round ones shape a penumbra it is not. */
static void test_soft_against_disk(void **state)
{
    (void)state;
    lx_image img;
    random_casters(&img, 160, 160, 40, 777u);
    const float pos[3][2] = {{80.5f, 80.5f}, {30.25f, 120.75f}, {140.5f, 20.5f}};
    const float soft[2] = {3.0f, 8.0f};
    double err[2] = {0.0, 0.0};
    int count[2] = {0, 0};
    for (int c = 0; c < 6; c++) {
        lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
        l.x = pos[c % 3][0];
        l.y = pos[c % 3][1];
        l.radius = 200.0f;
        l.falloff = LX_FALLOFF2D_NONE;
        l.softness = soft[c / 3];
        /* the light's disk clear of casters */
        for (int y = (int)(l.y - l.softness) - 1; y <= (int)(l.y + l.softness) + 1; y++)
            for (int x = (int)(l.x - l.softness) - 1; x <= (int)(l.x + l.softness) + 1; x++)
                if (x >= 0 && y >= 0 && x < 160 && y < 160)
                    img.data[((size_t)y * 160 + x) * 4 + 3] = 0.0f;
        float *lm = render_one(&img, &l, 2, NULL);
        for (int y = 0; y < 160; y += 2)
            for (int x = 0; x < 160; x += 2) {
                double d = hypot(x + 0.5 - l.x, y + 0.5 - l.y);
                if (caster_at(&img, x, y) || d < 2.0 * l.softness + 2.0)
                    continue;
                double ref = disk_visibility(&img, x + 0.5, y + 0.5, l.x, l.y, l.softness, 48);
                double v = lm[3 * (y * 160 + x)];
                int side = reference_lit(&img, l.x, l.y, x, y, false) ? 0 : 1;
                err[side] += fabs(v - ref);
                count[side]++;
            }
        free(lm);
    }
    err[0] /= count[0];
    err[1] /= count[1];
    print_message("against the disk: lit side %.4f (%d px), shadow side %.4f (%d px)\n",
                  err[0], count[0], err[1], count[1]);
    assert_true(count[0] > 300 && count[1] > 300);
    assert_true(err[0] < LIT_SIDE_TOL);
    assert_true(err[1] < SHADOW_SIDE_TOL);
    lx_image_free(&img);
}

static void test_normals(void **state)
{
    (void)state;
    lx_image img, nm;
    assert_int_equal(lx_image_alloc(&img, 48, 40, 4), LX_OK);
    assert_int_equal(lx_image_alloc(&nm, 48, 40, 3), LX_OK);
    rng_state = 99;
    for (int i = 0; i < 48 * 40; i++) {
        nm.data[3 * i] = rndf();
        nm.data[3 * i + 1] = rndf();
        nm.data[3 * i + 2] = 0.5f + 0.5f * rndf();
    }
    lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
    l.x = 20.0f;
    l.y = 22.0f;
    l.radius = 40.0f;
    l.height = 12.0f;
    l.falloff = LX_FALLOFF2D_LINEAR;
    float *lm = render_one(&img, &l, 1, &nm);
    double worst = 0.0;
    for (int y = 0; y < 40; y++)
        for (int x = 0; x < 48; x++) {
            const float *c = nm.data + 3 * (y * 48 + x);
            double n[3] = {2.0 * c[0] - 1.0, -(2.0 * c[1] - 1.0), 2.0 * c[2] - 1.0};
            double nl = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            double L[3] = {l.x - (x + 0.5), l.y - (y + 0.5), l.height};
            double ll = sqrt(L[0] * L[0] + L[1] * L[1] + L[2] * L[2]);
            double ndl = (n[0] * L[0] + n[1] * L[1] + n[2] * L[2]) / (nl * ll);
            double d = hypot(L[0], L[1]);
            double f = d < l.radius ? 1.0 - d / l.radius : 0.0;
            double want = f * fmax(ndl, 0.0);
            worst = fmax(worst, fabs(lm[3 * (y * 48 + x)] - want));
        }
    assert_true(worst < 2e-5);
    free(lm);
    lx_image_free(&img);
    lx_image_free(&nm);
}

static void test_threads_and_cache(void **state)
{
    (void)state;
    lx_image img;
    random_casters(&img, 160, 120, 60, 5);
    lx_light2d_light ls[4];
    for (int i = 0; i < 4; i++) {
        ls[i] = lx_light2d_light_defaults(i == 3 ? LX_LIGHT2D_SPOT : LX_LIGHT2D_POINT);
        ls[i].x = 20.0f + 40.0f * i;
        ls[i].y = 30.0f + 15.0f * i;
        ls[i].radius = 50.0f + 10.0f * i;
        ls[i].softness = (float)i;
        ls[i].dynamic = i % 2 == 0;
        ls[i].dir_y = 1.0f;
    }
    float *out[2];
    for (int t = 0; t < 2; t++) {
        lx_light2d_desc d = {.threads = t + 1};
        lx_light2d *ctx = NULL;
        assert_int_equal(lx_light2d_create(&img, &d, &ctx), LX_OK);
        assert_int_equal(lx_light2d_set_lights(ctx, ls, 4), LX_OK);
        out[t] = malloc(160 * 120 * 3 * sizeof(float));
        float *again = malloc(160 * 120 * 3 * sizeof(float));
        assert_int_equal(lx_light2d_render(ctx, lx_v3(0.1f, 0.1f, 0.1f), NULL, out[t], NULL),
                         LX_OK);
        assert_int_equal(lx_light2d_relit_count(ctx), 4);
        /* the static lights come from the cache, with the same bytes */
        assert_int_equal(lx_light2d_set_lights(ctx, ls, 4), LX_OK);
        assert_int_equal(lx_light2d_render(ctx, lx_v3(0.1f, 0.1f, 0.1f), NULL, again, NULL),
                         LX_OK);
        assert_int_equal(lx_light2d_relit_count(ctx), 2);
        assert_memory_equal(out[t], again, 160 * 120 * 3 * sizeof(float));
        /* a caster change under light 1 only (light 3 reaches x >= 70) */
        assert_int_equal(lx_light2d_update_casters(ctx, &img, 0, 0, 8, 8), LX_OK);
        assert_int_equal(lx_light2d_render(ctx, lx_v3(0.1f, 0.1f, 0.1f), NULL, again, NULL),
                         LX_OK);
        assert_int_equal(lx_light2d_relit_count(ctx), 3);
        assert_memory_equal(out[t], again, 160 * 120 * 3 * sizeof(float));
        free(again);
        lx_light2d_destroy(ctx);
    }
    assert_memory_equal(out[0], out[1], 160 * 120 * 3 * sizeof(float));
    free(out[0]);
    free(out[1]);
    lx_image_free(&img);
}

static void expect_json_error(const char *text, const char *needle)
{
    lx_light2d_scene s;
    lx_status st = lx_light2d_scene_parse("l.json", text, strlen(text), &s);
    if (st == LX_OK || !strstr(lx_last_error(), needle))
        fail_msg("'%s': got '%s', wanted '%s'", text, lx_last_error(), needle);
}

static void test_json(void **state)
{
    (void)state;
    const char *good = "{\"ambient\": [0.1, 0.1, 0.2], \"lights\": [{\"type\": \"spot\", "
                       "\"position\": [10, 20], \"direction\": [0, 1], \"arc\": 45, "
                       "\"temperature\": 3000, \"intensity\": 2, \"radius\": 50, \"falloff\": "
                       "\"linear\", \"softness\": 3, \"height\": 10, \"shadow\": true, "
                       "\"dynamic\": true, \"self_shadow\": false, \"edge\": 0}]}";
    lx_light2d_scene s;
    assert_int_equal(lx_light2d_scene_parse("l.json", good, strlen(good), &s), LX_OK);
    assert_int_equal(s.count, 1);
    assert_true(s.lights[0].type == LX_LIGHT2D_SPOT);
    assert_true(s.lights[0].color.x == 1.0f && s.lights[0].color.z < 0.5f); /* warm */
    assert_true(s.lights[0].falloff == LX_FALLOFF2D_LINEAR && s.lights[0].dynamic);
    lx_light2d_scene_free(&s);
    expect_json_error("{\"lights\": [{\"position\": [1, 2], \"radius\": 5, \"colour\": 1}]}",
                      "lights[0]: unknown key 'colour'");
    expect_json_error("{\"lights\": [{\"position\": [1, 2], \"radius\": 0}]}",
                      "lights[0]: radius 0 must be > 0");
    expect_json_error("{\"lights\": [{\"position\": [1, 2], \"radius\": -3}]}", "radius -3");
    expect_json_error("{\"lights\": [{\"type\": \"spot\", \"position\": [1, 2], \"radius\": 5, "
                      "\"direction\": [1, 0], \"arc\": 400}]}",
                      "arc 400 must be in (0, 360]");
    expect_json_error("{\"lights\": [{\"type\": \"spot\", \"position\": [1, 2], \"radius\": 5, "
                      "\"direction\": [0, 0]}]}",
                      "direction is zero");
    expect_json_error("{\"lights\": [{\"position\": [1, 2], \"radius\": 5", "truncated");
    expect_json_error("{\"ambient\": [1, 2], \"lights\": []}", "ambient must be an array of 3");
    expect_json_error("{\"lights\": [{\"radius\": 5}]}", "position is missing");
    expect_json_error("{\"light\": []}", "unknown key 'light'");
    /* colour x intensity would overflow a sum of lights (found by
     * fuzz_light2d_json: infinite light, NaN where the falloff is 0) */
    expect_json_error("{\"lights\": [{\"position\": [1, 2], \"radius\": 5, \"color\": [1e38, "
                      "1, 1], \"intensity\": 1e38}]}",
                      "lights[0]: intensity 1e+38 x color 1e+38 is more than 1e+30");
    expect_json_error("{\"ambient\": [3e38, 0, 0], \"lights\": []}", "ambient is more than");
}

static void test_bad_input(void **state)
{
    (void)state;
    lx_image rgb;
    assert_int_equal(lx_image_alloc(&rgb, 8, 8, 3), LX_OK);
    lx_light2d *ctx = NULL;
    assert_int_equal(lx_light2d_create(&rgb, NULL, &ctx), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "no alpha channel"));
    lx_light2d_desc d = {.mask = true};
    assert_int_equal(lx_light2d_create(&rgb, &d, &ctx), LX_OK);
    lx_image small;
    assert_int_equal(lx_image_alloc(&small, 4, 8, 3), LX_OK);
    assert_int_equal(lx_light2d_set_normals(ctx, &small, false), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "8x8 but normals: 4x8"));
    float out[8 * 8 * 3];
    assert_int_equal(lx_light2d_render(ctx, lx_v3(0, 0, 0), &small, out, NULL), LX_ERR_INVALID);
    lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
    assert_int_equal(lx_light2d_set_lights(ctx, &l, 1), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "lights[0]: radius 0 must be > 0"));
    /* a light outside the image still casts shadows into it */
    l.radius = 20.0f;
    l.x = -5.0f;
    assert_int_equal(lx_light2d_set_lights(ctx, &l, 1), LX_OK);
    assert_int_equal(lx_light2d_render(ctx, lx_v3(0, 0, 0), NULL, out, NULL), LX_OK);
    assert_true(out[0] > 0.0f);
    lx_light2d_destroy(ctx);
    lx_image_free(&rgb);
    lx_image_free(&small);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hard_shadows), cmocka_unit_test(test_falloffs),
        cmocka_unit_test(test_ring),         cmocka_unit_test(test_small_soft_light),
        cmocka_unit_test(test_mirror),
        cmocka_unit_test(test_soft),         cmocka_unit_test(test_soft_against_disk),
        cmocka_unit_test(test_normals),
        cmocka_unit_test(test_threads_and_cache), cmocka_unit_test(test_json),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
