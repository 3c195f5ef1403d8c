/* Dilation (lx_dilate) against its definition, computed here the plain way:
 * every pass reads copies of the previous pass's values and mask, visits
 * every texel of the image, and gives each empty one with filled
 * 8-neighbours their average, summed in float in the order dy = -1..1,
 * dx = -1..1. The library's frontier algorithm must match it bit for bit on
 * random masks, sizes, channel counts and pass counts, for any thread
 * count; cancelling and failing leave data and mask as they were; bad
 * arguments are rejected; lx_baker_apply pads with it and can be
 * cancelled. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the definition ------------------------------------------------------ */

static void dilate_by_definition(float *data, uint8_t *mask, int w, int h, int channels, int passes)
{
    size_t pixels = (size_t)w * h;
    float *old_data = malloc(sizeof(float) * pixels * channels);
    uint8_t *old_mask = malloc(pixels);
    assert_non_null(old_data);
    assert_non_null(old_mask);
    for (int pass = 0; pass < passes; pass++) {
        memcpy(old_data, data, sizeof(float) * pixels * channels);
        memcpy(old_mask, mask, pixels);
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t p = (size_t)y * w + x;
                if (old_mask[p])
                    continue;
                float sum[4] = {0, 0, 0, 0};
                int n = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int nx = x + dx, ny = y + dy;
                        if (nx < 0 || ny < 0 || nx >= w || ny >= h)
                            continue;
                        size_t q = (size_t)ny * w + nx;
                        if (!old_mask[q])
                            continue;
                        for (int c = 0; c < channels; c++)
                            sum[c] += old_data[q * channels + c];
                        n++;
                    }
                if (n == 0)
                    continue;
                for (int c = 0; c < channels; c++)
                    data[p * channels + c] = sum[c] / (float)n;
                mask[p] = 1;
            }
    }
    free(old_data);
    free(old_mask);
}

/* ---- random inputs ------------------------------------------------------- */

static uint64_t rng_state;

static uint64_t next_random(void)
{
    /* splitmix64 */
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static float random_unit(void)
{
    return (float)(next_random() >> 40) / (float)(1u << 24);
}

typedef struct image {
    int w, h, channels;
    float *data;
    uint8_t *mask;
} image;

/* A mask of a few random rectangles and scattered texels (with `density`
 * of texels set), values 1 or other nonzero bytes; values in filled texels
 * spread over many magnitudes, and in empty texels zero or garbage. */
static image random_image(int w, int h, int channels, float density, bool garbage)
{
    image im = {w, h, channels, malloc(sizeof(float) * (size_t)w * h * channels),
                malloc((size_t)w * h)};
    assert_non_null(im.data);
    assert_non_null(im.mask);
    memset(im.mask, 0, (size_t)w * h);
    int rects = (int)(next_random() % 4);
    for (int r = 0; r < rects; r++) {
        int x0 = (int)(next_random() % (uint64_t)w), y0 = (int)(next_random() % (uint64_t)h);
        int x1 = x0 + (int)(next_random() % (uint64_t)(w / 3 + 1));
        int y1 = y0 + (int)(next_random() % (uint64_t)(h / 3 + 1));
        for (int y = y0; y <= y1 && y < h; y++)
            for (int x = x0; x <= x1 && x < w; x++)
                im.mask[(size_t)y * w + x] = 1;
    }
    for (size_t p = 0; p < (size_t)w * h; p++) {
        if (random_unit() < density)
            im.mask[p] = next_random() % 5 == 0 ? (uint8_t)(2 + next_random() % 254) : 1;
        for (int c = 0; c < channels; c++) {
            float v = random_unit() * powf(10.0f, (float)(next_random() % 9) - 4.0f);
            im.data[p * channels + c] = im.mask[p] || garbage ? v : 0.0f;
        }
    }
    return im;
}

static image copy_image(const image *src)
{
    size_t pixels = (size_t)src->w * src->h;
    image im = {src->w, src->h, src->channels, malloc(sizeof(float) * pixels * src->channels),
                malloc(pixels)};
    assert_non_null(im.data);
    assert_non_null(im.mask);
    memcpy(im.data, src->data, sizeof(float) * pixels * src->channels);
    memcpy(im.mask, src->mask, pixels);
    return im;
}

static void free_image(image *im)
{
    free(im->data);
    free(im->mask);
}

/* Bitwise equality of values and masks. */
static void assert_same(const image *a, const image *b, const char *what)
{
    size_t pixels = (size_t)a->w * a->h;
    for (size_t p = 0; p < pixels; p++) {
        if (a->mask[p] != b->mask[p] || memcmp(&a->data[p * a->channels], &b->data[p * a->channels],
                                               sizeof(float) * a->channels) != 0) {
            print_error("%s: %dx%d, %d channels: texel (%zu, %zu) differs: mask %d / %d, first "
                        "value %a / %a\n",
                        what, a->w, a->h, a->channels, p % (size_t)a->w, p / (size_t)a->w,
                        a->mask[p], b->mask[p], a->data[p * a->channels], b->data[p * a->channels]);
            fail();
        }
    }
}

/* lx_dilate with threads 1, 2 and 3 against the definition. */
static void check_case(const image *input, int passes)
{
    image want = copy_image(input);
    dilate_by_definition(want.data, want.mask, want.w, want.h, want.channels, passes);
    for (int threads = 1; threads <= 3; threads++) {
        image got = copy_image(input);
        lx_dilate_desc desc = {.threads = threads};
        assert_int_equal(lx_dilate(got.data, got.mask, got.w, got.h, got.channels, passes, &desc),
                         LX_OK);
        char what[64];
        snprintf(what, sizeof what, "%d passes, %d threads", passes, threads);
        assert_same(&got, &want, what);
        free_image(&got);
    }
    free_image(&want);
}

/* ---- tests --------------------------------------------------------------- */

/* Small random images: every size from 1 to 20 a side in turn (most not
 * multiples of 8, thin rows and columns included), 1 to 4 channels, sparse
 * to dense masks, one pass to more than the image needs. */
static void small_random_images_match_the_definition(void **state)
{
    (void)state;
    rng_state = 1;
    static const float densities[] = {0.0f, 0.01f, 0.05f, 0.3f, 0.9f};
    static const int passes[] = {1, 2, 3, 5, 30};
    for (int i = 0; i < 400; i++) {
        int w = 1 + i % 20, h = 1 + (i * 7) % 19;
        image im = random_image(w, h, 1 + i % 4, densities[i % 5], i % 3 == 0);
        check_case(&im, passes[(i / 5) % 5]);
        free_image(&im);
    }
}

/* Larger images, grown for many passes until they fill (or nearly fill)
 * the image; the last two have frontiers of tens of thousands of texels,
 * which run on several threads. */
static void large_images_match_over_many_passes(void **state)
{
    (void)state;
    rng_state = 2;
    static const struct {
        int w, h, channels, passes;
        float density;
        bool garbage;
    } cases[] = {
        {515, 389, 3, 64, 0.0005f, false}, {301, 257, 1, 150, 0.0001f, true},
        {1000, 203, 4, 20, 0.01f, true},   {257, 1021, 2, 40, 0.002f, false},
        {1024, 1024, 3, 9, 0.02f, true},   {700, 900, 2, 30, 0.001f, false},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        image im = random_image(cases[i].w, cases[i].h, cases[i].channels, cases[i].density,
                                cases[i].garbage);
        check_case(&im, cases[i].passes);
        free_image(&im);
    }
}

/* No texel filled, or none empty: nothing changes, LX_OK. */
static void nothing_to_grow(void **state)
{
    (void)state;
    float data[12] = {0};
    uint8_t none[12] = {0}, all[12];
    memset(all, 1, sizeof all);
    assert_int_equal(lx_dilate(data, none, 4, 3, 1, 5, NULL), LX_OK);
    for (int i = 0; i < 12; i++)
        assert_int_equal(none[i], 0);
    assert_int_equal(lx_dilate(data, all, 4, 3, 1, 5, NULL), LX_OK);
    assert_int_equal(lx_dilate(data, none, 4, 3, 1, 0, NULL), LX_OK);
}

typedef struct progress_log {
    int calls;
    int stop_at; /* the call that returns false (1 = the first); 0 = never */
    float fractions[512];
} progress_log;

static bool record_progress(void *user, float fraction)
{
    progress_log *log = user;
    if (log->calls < 512)
        log->fractions[log->calls] = fraction;
    log->calls++;
    return log->calls != log->stop_at;
}

/* Progress runs from above 0 to exactly 1, never backwards, once a pass
 * (here until the image is full, before the passes asked for). */
static void progress_reports_each_pass(void **state)
{
    (void)state;
    rng_state = 3;
    image im = random_image(64, 48, 3, 0.0f, false);
    memset(im.mask, 0, 64 * 48);
    im.mask[20 * 64 + 30] = 1;
    progress_log log = {0};
    lx_dilate_desc desc = {.threads = 2, .progress = record_progress, .progress_user = &log};
    assert_int_equal(lx_dilate(im.data, im.mask, 64, 48, 3, 100, &desc), LX_OK);
    /* the last texels, in column 63, are 33 rings from (30, 20) */
    assert_int_equal(log.calls, 33);
    for (int i = 0; i < log.calls; i++) {
        assert_true(log.fractions[i] > 0.0f && log.fractions[i] <= 1.0f);
        if (i > 0)
            assert_true(log.fractions[i] >= log.fractions[i - 1]);
    }
    assert_true(log.fractions[log.calls - 1] == 1.0f);
    free_image(&im);
}

/* Cancelling at any pass returns LX_ERR_CANCELLED and leaves data (garbage
 * in empty texels included) and mask exactly as they were. */
static void cancel_leaves_everything_as_it_was(void **state)
{
    (void)state;
    rng_state = 4;
    /* charts near one corner: 64 passes do not reach the far one */
    image input = random_image(300, 200, 3, 0.0f, true);
    memset(input.mask, 0, 300 * 200);
    for (int i = 0; i < 40; i++)
        input.mask[(size_t)(10 + i % 7) * 300 + 20 + (i * 13) % 50] = 1;
    static const int stop_at[] = {1, 2, 7, 40};
    for (int threads = 1; threads <= 3; threads++)
        for (size_t i = 0; i < sizeof stop_at / sizeof stop_at[0]; i++) {
            image im = copy_image(&input);
            progress_log log = {.stop_at = stop_at[i]};
            lx_dilate_desc desc = {
                .threads = threads, .progress = record_progress, .progress_user = &log};
            assert_int_equal(lx_dilate(im.data, im.mask, im.w, im.h, 3, 64, &desc),
                             LX_ERR_CANCELLED);
            assert_int_equal(log.calls, stop_at[i]);
            assert_non_null(strstr(lx_last_error(), "cancelled"));
            assert_same(&im, &input, "after cancelling");
            free_image(&im);
        }
    /* cancelled at the one report of a run with nothing to grow */
    image full = copy_image(&input);
    memset(full.mask, 1, (size_t)full.w * full.h);
    progress_log log = {.stop_at = 1};
    lx_dilate_desc desc = {.progress = record_progress, .progress_user = &log};
    assert_int_equal(lx_dilate(full.data, full.mask, full.w, full.h, 3, 4, &desc),
                     LX_ERR_CANCELLED);
    free_image(&full);
    free_image(&input);
}

static void expect_invalid(lx_status st, const char *needle)
{
    assert_int_equal(st, LX_ERR_INVALID);
    if (!strstr(lx_last_error(), needle)) {
        print_error("message '%s' does not say '%s'\n", lx_last_error(), needle);
        fail();
    }
}

/* Bad arguments fail with LX_ERR_INVALID and a message, touching nothing. */
static void bad_arguments_are_rejected(void **state)
{
    (void)state;
    float data[2 * 4] = {1, 2, 3, 4, 5, 6, 7, 8};
    uint8_t mask[2] = {1, 0};
    lx_dilate_desc bad_threads = {.threads = -1}, many_threads = {.threads = 5000};
    expect_invalid(lx_dilate(NULL, mask, 2, 1, 4, 1, NULL), "data");
    expect_invalid(lx_dilate(data, NULL, 2, 1, 4, 1, NULL), "mask");
    expect_invalid(lx_dilate(data, mask, 0, 1, 4, 1, NULL), "0 x 1");
    expect_invalid(lx_dilate(data, mask, 2, -3, 4, 1, NULL), "2 x -3");
    expect_invalid(lx_dilate(data, mask, 65536, 65537, 1, 1, NULL), "65536 x 65537");
    expect_invalid(lx_dilate(data, mask, 2, 1, 0, 1, NULL), "0 channels");
    expect_invalid(lx_dilate(data, mask, 2, 1, 5, 1, NULL), "5 channels");
    expect_invalid(lx_dilate(data, mask, 2, 1, 8, 1, NULL), "8 channels");
    expect_invalid(lx_dilate(data, mask, 2, 1, 4, -1, NULL), "-1 passes");
    expect_invalid(lx_dilate(data, mask, 2, 1, 4, 1, &bad_threads), "thread count -1");
    expect_invalid(lx_dilate(data, mask, 2, 1, 4, 1, &many_threads), "thread count 5000");
    assert_int_equal(mask[0], 1);
    assert_int_equal(mask[1], 0);
    for (int i = 0; i < 8; i++)
        assert_true(data[i] == (float)(i + 1));
}

/* ---- lx_baker_apply ------------------------------------------------------ */

/* A 1 m plane lit from above whose lightmap UVs cover only the middle of
 * the map, so padding has room to grow. */
static lx_scene *small_chart_scene(void)
{
    lx_scene *scene;
    assert_int_equal(lx_scene_create("dilate", &scene), LX_OK);
    lx_material mat = {.name = "white", .base_color = {1, 1, 1, 1}};
    assert_int_equal(lx_scene_add_material(scene, &mat, NULL), LX_OK);
    lx_mesh plane = lx_test_plane("plane", 1.0f, 0.0f, 0.0f, 0.0f, 4);
    for (uint32_t v = 0; v < plane.vertex_count; v++) {
        plane.uv[1][v].x = 0.3f + 0.4f * plane.uv[1][v].x;
        plane.uv[1][v].y = 0.25f + 0.4f * plane.uv[1][v].y;
    }
    uint32_t mesh;
    assert_int_equal(lx_scene_add_mesh(scene, &plane, &mesh), LX_OK);
    lx_test_mesh_free(&plane);
    lx_mat4 world = lx_mat4_identity();
    assert_int_equal(lx_scene_add_node(scene, "plane", &world, &mesh, 1, NULL), LX_OK);
    lx_light point = lx_light_defaults(LX_LIGHT_POINT);
    point.position = lx_v3(0.2f, 1.0f, 0.1f);
    point.intensity = 100.0f;
    point.shadow = LX_SHADOW_NONE;
    assert_int_equal(lx_scene_add_light(scene, &point), LX_OK);
    return scene;
}

static bool stop_when_asked(void *user, float fraction)
{
    (void)fraction;
    progress_log *log = user;
    log->calls++;
    return log->stop_at == 0 || log->calls < log->stop_at;
}

/* The padded apply is the unpadded one dilated by lx_dilate; cancelling it
 * (during the padding, or at the end of an unpadded apply) returns
 * LX_ERR_CANCELLED with the image zeroed. */
static void baker_apply_pads_and_cancels(void **state)
{
    (void)state;
    lx_scene *scene = small_chart_scene();
    progress_log log = {0};
    lx_bake_desc desc = {.resolution = 61,
                         .padding = 12,
                         .threads = 2,
                         .progress = stop_when_asked,
                         .progress_user = &log};
    lx_baker *padded, *plain;
    assert_int_equal(lx_baker_create(scene, &desc, &padded), LX_OK);
    desc.padding = LX_PADDING_NONE;
    assert_int_equal(lx_baker_create(scene, &desc, &plain), LX_OK);
    assert_int_equal(lx_baker_bake(padded), LX_OK);
    assert_int_equal(lx_baker_bake(plain), LX_OK);

    lx_image want, got;
    assert_int_equal(lx_baker_apply_alloc(plain, 0, &want), LX_OK);
    uint8_t mask[61 * 61];
    memcpy(mask, lx_baker_mask(plain, 0), sizeof mask);
    int used = 0;
    for (int p = 0; p < 61 * 61; p++)
        used += mask[p] != 0;
    assert_true(used > 200 && used < 61 * 61 / 2);
    assert_int_equal(lx_dilate(want.data, mask, 61, 61, 3, 12, NULL), LX_OK);
    log.calls = 0;
    assert_int_equal(lx_baker_apply_alloc(padded, 0, &got), LX_OK);
    assert_true(log.calls >= 12); /* one report a pass at least */
    assert_memory_equal(got.data, want.data, sizeof(float) * 61 * 61 * 3);

    /* cancelled at the third pass: zeroed */
    log.calls = 0;
    log.stop_at = 3;
    assert_int_equal(lx_baker_apply(padded, 0, &got), LX_ERR_CANCELLED);
    assert_int_equal(log.calls, 3);
    for (int i = 0; i < 61 * 61 * 3; i++)
        assert_true(got.data[i] == 0.0f);
    /* an unpadded apply reports once, at the end, and stops there too */
    log.calls = 0;
    log.stop_at = 1;
    assert_int_equal(lx_baker_apply(plain, 0, &want), LX_ERR_CANCELLED);
    for (int i = 0; i < 61 * 61 * 3; i++)
        assert_true(want.data[i] == 0.0f);
    lx_image freed;
    log.calls = 0;
    assert_int_equal(lx_baker_apply_alloc(padded, 0, &freed), LX_ERR_CANCELLED);
    assert_null(freed.data);

    lx_image_free(&want);
    lx_image_free(&got);
    lx_baker_destroy(padded);
    lx_baker_destroy(plain);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(small_random_images_match_the_definition),
        cmocka_unit_test(large_images_match_over_many_passes),
        cmocka_unit_test(nothing_to_grow),
        cmocka_unit_test(progress_reports_each_pass),
        cmocka_unit_test(cancel_leaves_everything_as_it_was),
        cmocka_unit_test(bad_arguments_are_rejected),
        cmocka_unit_test(baker_apply_pads_and_cancels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
