/* Tests of lx_env_write (src/ibl/env_write.c) and of the threads, progress
 * and cancellation of the environment conversions and loading:
 * - every layout read back: faces, crosses and the KTX file's floats
 *   exactly (the KTX layout read here from the KTX 1.1 specification: a
 *   64-byte header, key/value data, per level imageSize and six faces of
 *   RGBA32F), the equirect of a constant exactly constant;
 * - the file names (stem, _m<L>, _<face>, extension), told to on_file
 *   before each file is made, and by lx_env_write_names without writing;
 * - a failure part-way (a NaN in a later level, the caller stopping,
 *   progress cancelling) leaves the folder as it was;
 * - KTX files are the same bytes on 1, 2 and 3 threads, with progress
 *   after each block of rows that never goes back, and image layouts
 *   report inside each file;
 * - bad stems, counts, layouts and formats, with their messages;
 * - resampling (equirect -> cube, cube -> equirect, cube -> cube, cross,
 *   downsampling) gives the same bytes for 1, 2 and 3 threads, reports
 *   progress up to 1 and leaves nothing when cancelled;
 * - memory checks: lx_prefilter_check and lx_env_write_check refuse what
 *   no machine holds, naming the GiB, before allocating. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cube_reference.h"
#include "helpers.h"
#include "core/internal.h"
#include "luxel/ibl.h"

static char *path_in(const char *dir, const char *file)
{
    static char buf[4][1300];
    static int next;
    char *p = buf[next++ % 4];
    snprintf(p, sizeof buf[0], "%s/%s", dir, file);
    return p;
}

static void fill_random(lx_cubemap *c, uint32_t seed)
{
    size_t n = 6 * (size_t)c->size * c->size * 3;
    for (size_t i = 0; i < n; i++)
        c->data[i] = lx_random(seed, (uint32_t)i, 0, 0) * 4.0f;
}

static void make_chain(lx_cubemap *levels, int size, int count, uint32_t seed)
{
    for (int l = 0; l < count; l++) {
        assert_int_equal(lx_cubemap_alloc(&levels[l], size >> l > 0 ? size >> l : 1), LX_OK);
        fill_random(&levels[l], seed + (uint32_t)l);
    }
}

static void free_chain(lx_cubemap *levels, int count)
{
    for (int l = 0; l < count; l++)
        lx_cubemap_free(&levels[l]);
}

static void assert_cubes_equal(const lx_cubemap *a, const lx_cubemap *b)
{
    assert_int_equal(a->size, b->size);
    assert_memory_equal(a->data, b->data, sizeof(float) * 18 * (size_t)a->size * a->size);
}

static void assert_error_mentions(const char *needle)
{
    if (!strstr(lx_last_error(), needle))
        fail_msg("error \"%s\" does not mention \"%s\"", lx_last_error(), needle);
}

/* The names on_file hears, in order. */
typedef struct heard {
    int count, stop_at;
    char name[64][80];
} heard;

static bool on_file(void *user, const char *name)
{
    heard *h = user;
    if (h->count == h->stop_at)
        return false;
    if (h->count < 64)
        snprintf(h->name[h->count], sizeof h->name[0], "%s", name);
    h->count++;
    return true;
}

static uint32_t rd32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* ---- layouts ------------------------------------------------------------ */

static void image_layouts_read_back_exactly(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_write/layouts");
    lx_cubemap levels[3];
    make_chain(levels, 8, 3, 7);
    struct {
        lx_env_layout layout;
        const char *first; /* the name lx_env_load reads level 1 from */
    } cases[] = {{LX_ENV_FACES, "f_m1_px.pfm"},
                 {LX_ENV_CROSS, "c_m1.pfm"},
                 {LX_ENV_CROSS_VERTICAL, "v_m1.pfm"}};
    const char *stems[] = {"f", "c", "v"};
    for (int k = 0; k < 3; k++) {
        heard h = {.stop_at = -1};
        lx_env_write_desc d = {.layout = cases[k].layout,
                               .format = LX_IMAGE_PFM,
                               .threads = 2,
                               .on_file = on_file,
                               .on_file_user = &h};
        assert_int_equal(lx_env_write(dir, stems[k], levels, 3, &d), LX_OK);
        assert_int_equal(h.count, cases[k].layout == LX_ENV_FACES ? 18 : 3);
        lx_cubemap back;
        assert_int_equal(lx_env_load(path_in(dir, cases[k].first), NULL, &back), LX_OK);
        assert_cubes_equal(&back, &levels[1]);
        lx_cubemap_free(&back);
    }
    /* the names: faces level by level, face by face */
    assert_int_equal(lx_test_count_files(dir), 18 + 3 + 3);
    heard h = {.stop_at = -1};
    lx_env_write_desc d = {.format = LX_IMAGE_EXR, .on_file = on_file, .on_file_user = &h};
    assert_int_equal(lx_env_write(dir, "one", levels, 1, &d), LX_OK);
    const char *want[6] = {"one_px.exr", "one_nx.exr", "one_py.exr",
                           "one_ny.exr", "one_pz.exr", "one_nz.exr"};
    assert_int_equal(h.count, 6);
    for (int i = 0; i < 6; i++)
        assert_string_equal(h.name[i], want[i]);
    h.count = 0;
    d.mip_names = true;
    d.layout = LX_ENV_EQUIRECT;
    d.format = LX_IMAGE_HDR;
    assert_int_equal(lx_env_write(dir, "eq", levels, 1, &d), LX_OK);
    assert_int_equal(h.count, 1);
    assert_string_equal(h.name[0], "eq_m0.hdr");
    free_chain(levels, 3);
}

/* lx_env_write_names tells the names lx_env_write then writes, in its
 * order, for every layout, one level or several, with and without
 * mip_names; it creates nothing, refuses what lx_env_write refuses and
 * stops when the caller does. */
static void names_told_before_writing(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_write/names");
    lx_cubemap levels[3];
    make_chain(levels, 4, 3, 5);
    const lx_env_layout layouts[] = {LX_ENV_FACES, LX_ENV_CROSS, LX_ENV_CROSS_VERTICAL,
                                     LX_ENV_EQUIRECT, LX_ENV_KTX};
    int files = 0;
    for (int k = 0; k < 5; k++)
        for (int count = 1; count <= 3; count += 2)
            for (int mip_names = 0; mip_names < 2; mip_names++) {
                char stem[32];
                snprintf(stem, sizeof stem, "s%d_%d_%d", k, count, mip_names);
                heard told = {.stop_at = -1}, made = {.stop_at = -1};
                lx_env_write_desc d = {.layout = layouts[k],
                                       .format = LX_IMAGE_PFM,
                                       .mip_names = mip_names,
                                       .on_file = on_file,
                                       .on_file_user = &told};
                assert_int_equal(lx_env_write_names(stem, count, &d), LX_OK);
                assert_int_equal(lx_test_count_files(dir), files);
                d.on_file_user = &made;
                assert_int_equal(lx_env_write(dir, stem, levels, count, &d), LX_OK);
                assert_int_equal(told.count, made.count);
                for (int i = 0; i < told.count; i++)
                    assert_string_equal(told.name[i], made.name[i]);
                files += made.count;
                assert_int_equal(lx_test_count_files(dir), files);
            }
    /* the names of the cases read back above */
    heard h = {.stop_at = -1};
    lx_env_write_desc d = {.mip_names = true, .on_file = on_file, .on_file_user = &h};
    assert_int_equal(lx_env_write_names("specular", 2, &d), LX_OK);
    assert_int_equal(h.count, 12);
    assert_string_equal(h.name[0], "specular_m0_px.exr");
    assert_string_equal(h.name[11], "specular_m1_nz.exr");
    /* what lx_env_write refuses, and a caller that stops */
    assert_int_equal(lx_env_write_names("a/b", 1, &d), LX_ERR_INVALID);
    assert_error_mentions("without '/'");
    assert_int_equal(lx_env_write_names("x", LX_MAX_CUBE_MIPS + 1, &d), LX_ERR_INVALID);
    h = (heard){.stop_at = 2};
    assert_int_equal(lx_env_write_names("stop", 1, &d), LX_ERR_CANCELLED);
    assert_int_equal(h.count, 2);
    assert_int_equal(lx_env_write_names("quiet", 1, NULL), LX_OK);
    free_chain(levels, 3);
}

/* A constant environment's equirect is that constant: each pixel a mean of
 * samples that are all the constant. */
static void equirect_of_a_constant(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_write/equirect");
    lx_cubemap c = lx_test_constant_env(4, 0.75f);
    lx_env_write_desc d = {.layout = LX_ENV_EQUIRECT, .format = LX_IMAGE_PFM};
    assert_int_equal(lx_env_write(dir, "sky", &c, 1, &d), LX_OK);
    lx_image img;
    assert_int_equal(lx_image_load(path_in(dir, "sky.pfm"), NULL, &img), LX_OK);
    assert_int_equal(img.width, 16);
    assert_int_equal(img.height, 8);
    for (int i = 0; i < 16 * 8 * img.channels; i++)
        assert_true(img.data[i] == 0.75f);
    lx_image_free(&img);
    lx_cubemap_free(&c);
}

/* The KTX file's levels hold the cube maps' values as RGBA32F, A = 1. */
static void ktx_holds_the_levels(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_write/ktx");
    lx_cubemap levels[4];
    make_chain(levels, 8, 4, 11);
    heard h = {.stop_at = -1};
    lx_env_write_desc d = {.layout = LX_ENV_KTX, .on_file = on_file, .on_file_user = &h};
    assert_int_equal(lx_env_write(dir, "spec", levels, 4, &d), LX_OK);
    assert_int_equal(h.count, 1);
    assert_string_equal(h.name[0], "spec.ktx");
    char *bytes;
    size_t size;
    assert_int_equal(lx_read_file(path_in(dir, "spec.ktx"), 1 << 24, &bytes, &size), LX_OK);
    const unsigned char *u = (const unsigned char *)bytes;
    assert_int_equal(rd32(u + 12 + 4 * 11), 4); /* numberOfMipmapLevels */
    assert_int_equal(rd32(u + 12 + 4 * 10), 6); /* numberOfFaces */
    size_t pos = 64 + rd32(u + 60);
    for (int l = 0; l < 4; l++) {
        int n = levels[l].size;
        assert_int_equal(rd32(u + pos), (uint32_t)(n * n * 16));
        pos += 4;
        for (int f = 0; f < 6; f++)
            for (int y = 0; y < n; y++)
                for (int x = 0; x < n; x++, pos += 16) {
                    float v[4];
                    memcpy(v, u + pos, 16);
                    const float *t = lx_test_cube_texel(&levels[l], f, x, y);
                    assert_true(v[0] == t[0] && v[1] == t[1] && v[2] == t[2] && v[3] == 1.0f);
                }
    }
    assert_int_equal(pos, size);
    free(bytes);
    free_chain(levels, 4);
}

/* ---- failures leave nothing ------------------------------------------------ */

static void failures_leave_nothing(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_write/failures");
    lx_cubemap levels[3];
    make_chain(levels, 4, 3, 3);
    /* a NaN in level 2, after 12 faces are written */
    lx_test_cube_texel(&levels[2], LX_FACE_NY, 0, 0)[1] = NAN;
    lx_env_write_desc d = {.format = LX_IMAGE_EXR};
    assert_int_equal(lx_env_write(dir, "bad", levels, 3, &d), LX_ERR_INVALID);
    assert_error_mentions("bad_m2_ny.exr: pixel (0, 0) channel 1 is NaN");
    assert_int_equal(lx_test_count_files(dir), 0);
    d.layout = LX_ENV_KTX;
    assert_int_equal(lx_env_write(dir, "bad", levels, 3, &d), LX_ERR_INVALID);
    assert_error_mentions("mip level 2 face ny texel (0, 0)");
    assert_int_equal(lx_test_count_files(dir), 0);
    lx_test_cube_texel(&levels[2], LX_FACE_NY, 0, 0)[1] = 1.0f;

    /* the caller stops before the fourth file */
    heard h = {.stop_at = 3};
    d = (lx_env_write_desc){.format = LX_IMAGE_PFM, .on_file = on_file, .on_file_user = &h};
    assert_int_equal(lx_env_write(dir, "stop", levels, 3, &d), LX_ERR_CANCELLED);
    assert_error_mentions("stop_m0_ny.pfm: writing cancelled");
    assert_int_equal(lx_test_count_files(dir), 0);

    /* progress cancels at its second report (in the first file) */
    lx_test_progress p = lx_test_progress_make(2);
    d = (lx_env_write_desc){
        .format = LX_IMAGE_PFM, .progress = lx_test_progress_fn, .progress_user = &p};
    assert_int_equal(lx_env_write(dir, "cancel", levels, 3, &d), LX_ERR_CANCELLED);
    assert_int_equal(lx_test_count_files(dir), 0);
    /* and runs to 1 when let be */
    p = lx_test_progress_make(0);
    assert_int_equal(lx_env_write(dir, "all", levels, 3, &d), LX_OK);
    assert_true(p.monotone && p.calls >= 3);
    assert_float_equal(p.last, 1.0f, 1e-6f);
    assert_int_equal(lx_test_count_files(dir), 18);
    free_chain(levels, 3);
}

/* KTX on 1, 2 and 3 threads: the same bytes, progress during the file
 * (after each block of rows: here each face of each level) that never
 * goes back and ends at 1; cancelled half-way, no file. Image layouts
 * report inside each file too. */
static void write_threads_progress_cancel(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_write/threads");
    lx_cubemap levels[9];
    make_chain(levels, 256, 9, 5);
    char *first = NULL;
    size_t first_size = 0;
    for (int threads = 1; threads <= 3; threads++) {
        for (int half = 0; half < 2; half++) {
            char stem[32];
            snprintf(stem, sizeof stem, "t%d_%d", threads, half);
            lx_test_progress p = lx_test_progress_make(0);
            lx_env_write_desc d = {.layout = LX_ENV_KTX,
                                   .half = half,
                                   .threads = threads,
                                   .progress = lx_test_progress_fn,
                                   .progress_user = &p};
            assert_int_equal(lx_env_write(dir, stem, levels, 9, &d), LX_OK);
            assert_true(p.monotone);
            assert_true(p.calls >= 6 * 9);
            assert_float_equal(p.last, 1.0f, 1e-6f);
            if (half)
                continue;
            char name[40];
            snprintf(name, sizeof name, "%s.ktx", stem);
            char *bytes;
            size_t size;
            assert_int_equal(lx_read_file(path_in(dir, name), 1 << 26, &bytes, &size), LX_OK);
            if (!first) {
                first = bytes;
                first_size = size;
                continue;
            }
            assert_int_equal(size, first_size);
            assert_memory_equal(bytes, first, size);
            free(bytes);
        }
    }
    free(first);
    const char *cancel_dir = lx_test_dir("ibl_env_write/threads_cancel");
    lx_test_progress p = lx_test_progress_make(27);
    lx_env_write_desc d = {
        .layout = LX_ENV_KTX, .threads = 2, .progress = lx_test_progress_fn, .progress_user = &p};
    assert_int_equal(lx_env_write(cancel_dir, "stop", levels, 9, &d), LX_ERR_CANCELLED);
    assert_int_equal(p.calls, 27);
    assert_int_equal(lx_test_count_files(cancel_dir), 0);

    /* six EXR faces of 256 x 256: reports inside each file */
    p = lx_test_progress_make(0);
    d = (lx_env_write_desc){
        .format = LX_IMAGE_EXR, .threads = 2, .progress = lx_test_progress_fn, .progress_user = &p};
    assert_int_equal(lx_env_write(cancel_dir, "faces", levels, 1, &d), LX_OK);
    assert_true(p.monotone);
    assert_true(p.calls > 6 * 10);
    assert_float_equal(p.last, 1.0f, 1e-6f);
    free_chain(levels, 9);
}

static void expect_write_error(const char *folder, const char *stem, const lx_cubemap *levels,
                               int count, const lx_env_write_desc *d, lx_status want,
                               const char *needle)
{
    lx_status st = lx_env_write(folder, stem, levels, count, d);
    if (st != want)
        fail_msg("status %s, want %s (%s)", lx_status_name(st), lx_status_name(want),
                 lx_last_error());
    assert_error_mentions(needle);
}

static void bad_input(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_write/bad");
    lx_cubemap levels[2];
    make_chain(levels, 4, 2, 5);
    lx_env_write_desc d = {0};
    expect_write_error(dir, "a/b", levels, 1, &d, LX_ERR_INVALID, "without '/'");
    expect_write_error(dir, "", levels, 1, &d, LX_ERR_INVALID, "the stem ''");
    expect_write_error(dir, NULL, levels, 1, &d, LX_ERR_INVALID, "(NULL)");
    expect_write_error(NULL, "x", levels, 1, &d, LX_ERR_INVALID, "no folder");
    expect_write_error(dir, "x", levels, 0, &d, LX_ERR_INVALID, "0 levels");
    expect_write_error(dir, "x", levels, LX_MAX_CUBE_MIPS + 1, &d, LX_ERR_INVALID, "16 levels");
    expect_write_error(dir, "x", NULL, 1, &d, LX_ERR_INVALID, "no levels");
    d.layout = (lx_env_layout)99;
    expect_write_error(dir, "x", levels, 1, &d, LX_ERR_INVALID, "unknown output layout 99");
    d = (lx_env_write_desc){.format = LX_IMAGE_PNG, .half = true};
    expect_write_error(dir, "x", levels, 1, &d, LX_ERR_INVALID, "not png images");
    d = (lx_env_write_desc){.format = (lx_image_format)42};
    expect_write_error(dir, "x", levels, 1, &d, LX_ERR_INVALID, "unknown image format 42");
    d = (lx_env_write_desc){.threads = -1};
    expect_write_error(dir, "x", levels, 1, &d, LX_ERR_INVALID, "thread count -1");
    /* KTX levels must halve */
    d = (lx_env_write_desc){.layout = LX_ENV_KTX};
    lx_cubemap wrong[2] = {levels[0], levels[0]};
    expect_write_error(dir, "x", wrong, 2, &d, LX_ERR_INVALID, "mip level 1 is 4 texels wide");
    lx_cubemap empty = {0, NULL};
    expect_write_error(dir, "x", &empty, 1, &d, LX_ERR_INVALID, "x: level 0");
    /* a folder that is not there: the writer's message names the path */
    d = (lx_env_write_desc){.format = LX_IMAGE_PFM};
    expect_write_error(path_in(dir, "missing"), "x", levels, 1, &d, LX_ERR_IO, "missing/x_px.pfm");
    assert_int_equal(lx_test_count_files(dir), 0);

    /* the loads and conversions refuse a negative thread count, leaving
     * their outputs empty */
    lx_ibl_desc bad = {.threads = -2};
    lx_image img, eq;
    lx_cubemap c = {.size = 99};
    assert_int_equal(lx_image_alloc(&eq, 16, 8, 3), LX_OK);
    assert_int_equal(lx_cubemap_from_equirect(&eq, 4, &bad, &c), LX_ERR_INVALID);
    assert_error_mentions("thread count -2");
    assert_null(c.data);
    img.data = (float *)&img;
    assert_int_equal(lx_cubemap_to_equirect(&levels[0], 16, &bad, &img), LX_ERR_INVALID);
    assert_error_mentions("thread count -2");
    assert_null(img.data);
    img.data = (float *)&img;
    assert_int_equal(lx_cubemap_to_cross(&levels[0], false, &bad, &img), LX_ERR_INVALID);
    assert_null(img.data);
    lx_image cross;
    assert_int_equal(lx_image_alloc(&cross, 16, 12, 3), LX_OK);
    assert_int_equal(lx_cubemap_from_cross(&cross, &bad, &c), LX_ERR_INVALID);
    assert_error_mentions("thread count -2");
    assert_null(c.data);
    lx_env_load_desc ld = {.threads = -2};
    assert_int_equal(lx_env_from_image(&eq, "sky.hdr", &ld, &c), LX_ERR_INVALID);
    assert_error_mentions("sky.hdr: thread count -2");
    assert_null(c.data);
    assert_int_equal(lx_env_load(path_in(dir, "none.hdr"), &ld, &c), LX_ERR_INVALID);
    assert_error_mentions("none.hdr: thread count -2");
    assert_null(c.data);
    lx_image_free(&cross);
    lx_image_free(&eq);
    assert_int_equal(lx_test_count_files(dir), 0);
    free_chain(levels, 2);
}

/* ---- resampling: threads, progress, cancel ---------------------------------- */

static void smooth(double x, double y, double z, float out[3])
{
    out[0] = (float)(1.0 + 0.5 * x + 0.25 * y * z);
    out[1] = (float)(2.0 + y);
    out[2] = (float)(1.5 + 0.5 * z * x);
}

/* Runs one conversion per thread count 1..3 and compares the bytes; then
 * with progress to 1, then cancelled. */
typedef lx_status (*convert_fn)(const void *in, const lx_ibl_desc *d, void *out);
typedef size_t (*bytes_fn)(const void *out, const float **data);

static size_t cube_bytes(const void *out, const float **data)
{
    const lx_cubemap *c = out;
    *data = c->data;
    return c->data ? sizeof(float) * 18 * (size_t)c->size * c->size : 0;
}

static size_t image_bytes(const void *out, const float **data)
{
    const lx_image *img = out;
    *data = img->data;
    return img->data ? sizeof(float) * (size_t)img->width * img->height * img->channels : 0;
}

static void check_run(const char *what, convert_fn fn, const void *in, bytes_fn bytes,
                      void (*release)(void *), void *out0, void *out1)
{
    lx_ibl_desc d = {.threads = 1};
    assert_int_equal(fn(in, &d, out0), LX_OK);
    const float *a, *b;
    size_t n = bytes(out0, &a);
    assert_true(n > 0);
    for (int t = 2; t <= 3; t++) {
        d.threads = t;
        assert_int_equal(fn(in, &d, out1), LX_OK);
        assert_int_equal(bytes(out1, &b), n);
        if (memcmp(a, b, n) != 0)
            fail_msg("%s: %d threads give other bytes than 1", what, t);
        release(out1);
    }
    lx_test_progress p = lx_test_progress_make(0);
    d = (lx_ibl_desc){.threads = 2, .progress = lx_test_progress_fn, .progress_user = &p};
    assert_int_equal(fn(in, &d, out1), LX_OK);
    if (!(p.calls >= 2 && p.monotone && p.last == 1.0f))
        fail_msg("%s: %d progress calls, last %g, monotone %d", what, p.calls, p.last, p.monotone);
    release(out1);
    p = lx_test_progress_make(2);
    assert_int_equal(fn(in, &d, out1), LX_ERR_CANCELLED);
    assert_error_mentions("cancelled");
    assert_int_equal(bytes(out1, &b), 0);
    release(out0);
}

static void release_cube(void *c)
{
    lx_cubemap_free(c);
}

static void release_image(void *img)
{
    lx_image_free(img);
}

static lx_status from_equirect(const void *in, const lx_ibl_desc *d, void *out)
{
    return lx_cubemap_from_equirect(in, 24, d, out);
}

static lx_status to_equirect(const void *in, const lx_ibl_desc *d, void *out)
{
    return lx_cubemap_to_equirect(in, 64, d, out);
}

static lx_status to_cross(const void *in, const lx_ibl_desc *d, void *out)
{
    return lx_cubemap_to_cross(in, true, d, out);
}

static lx_status from_cross(const void *in, const lx_ibl_desc *d, void *out)
{
    return lx_cubemap_from_cross(in, d, out);
}

static lx_status downsample(const void *in, const lx_ibl_desc *d, void *out)
{
    return lx_cubemap_downsample(in, 5, d, out);
}

typedef struct load_args {
    const char *path;
    int size;
} load_args;

static lx_status load(const void *in, const lx_ibl_desc *d, void *out)
{
    const load_args *a = in;
    lx_env_load_desc ld = {.size = a->size,
                           .threads = d->threads,
                           .progress = d->progress,
                           .progress_user = d->progress_user};
    return lx_env_load(a->path, &ld, out);
}

static void conversions_threads_progress_cancel(void **state)
{
    (void)state;
    lx_cubemap c = lx_test_make_env(16, smooth), c0, c1;
    lx_image eq, i0, i1;
    assert_int_equal(lx_cubemap_to_equirect(&c, 64, NULL, &eq), LX_OK);
    check_run("equirect -> cube", from_equirect, &eq, cube_bytes, release_cube, &c0, &c1);
    check_run("cube -> equirect", to_equirect, &c, image_bytes, release_image, &i0, &i1);
    check_run("cube -> vertical cross", to_cross, &c, image_bytes, release_image, &i0, &i1);
    lx_image cross;
    assert_int_equal(lx_cubemap_to_cross(&c, false, NULL, &cross), LX_OK);
    check_run("cross -> cube", from_cross, &cross, cube_bytes, release_cube, &c0, &c1);
    check_run("downsample 16 -> 5", downsample, &c, cube_bytes, release_cube, &c0, &c1);
    /* loading: an equirect file resampled, a cross file resampled */
    const char *dir = lx_test_dir("ibl_env_write/load");
    lx_image_write_desc wd = {.format = LX_IMAGE_PFM};
    assert_int_equal(lx_image_write(path_in(dir, "eq.pfm"), &eq, &wd), LX_OK);
    assert_int_equal(lx_image_write(path_in(dir, "cross.pfm"), &cross, &wd), LX_OK);
    load_args a = {path_in(dir, "eq.pfm"), 20};
    check_run("load an equirect", load, &a, cube_bytes, release_cube, &c0, &c1);
    a = (load_args){path_in(dir, "cross.pfm"), 10};
    check_run("load a cross at another size", load, &a, cube_bytes, release_cube, &c0, &c1);
    lx_image_free(&cross);
    lx_image_free(&eq);
    lx_cubemap_free(&c);
}

/* One pass to any smaller size equals halving twice when sizes divide, up
 * to rounding, and keeps the flux; bad sizes are refused. */
static void downsample_to_a_size(void **state)
{
    (void)state;
    lx_cubemap c = lx_test_make_env(16, smooth), half, quarter, direct;
    assert_int_equal(lx_cubemap_downsample(&c, 0, NULL, &half), LX_OK);
    assert_int_equal(half.size, 8);
    assert_int_equal(lx_cubemap_downsample(&half, 0, NULL, &quarter), LX_OK);
    assert_int_equal(lx_cubemap_downsample(&c, 4, NULL, &direct), LX_OK);
    /* measured: within 1.1e-7 relative (float rounding), bound 3e-7 */
    for (size_t i = 0; i < (size_t)18 * 4 * 4; i++)
        assert_float_equal(direct.data[i], quarter.data[i], 3e-7f * fabsf(quarter.data[i]));
    lx_cubemap_free(&half);
    lx_cubemap_free(&quarter);
    lx_cubemap_free(&direct);
    lx_cubemap out;
    assert_int_equal(lx_cubemap_downsample(&c, 17, NULL, &out), LX_ERR_INVALID);
    assert_error_mentions("face size 17 is outside 1..16");
    assert_null(out.data);
    assert_int_equal(lx_cubemap_downsample(&c, -1, NULL, &out), LX_ERR_INVALID);
    lx_ibl_desc d = {.threads = -5};
    assert_int_equal(lx_cubemap_downsample(&c, 4, &d, &out), LX_ERR_INVALID);
    assert_error_mentions("thread count -5");
    lx_cubemap_free(&c);
}

/* Upsampling more than 4x is said in a warning naming the memory. */
static char g_warning[512];
static void keep_warning(void *user, lx_log_level level, const char *msg)
{
    (void)user;
    if (level == LX_LOG_WARN)
        snprintf(g_warning, sizeof g_warning, "%s", msg);
}

static void upsampling_warns(void **state)
{
    (void)state;
    lx_image eq;
    assert_int_equal(lx_image_alloc(&eq, 16, 8, 3), LX_OK); /* 4 x 4 faces of detail */
    lx_set_log_callback(keep_warning, NULL);
    lx_cubemap c;
    g_warning[0] = '\0';
    assert_int_equal(lx_cubemap_from_equirect(&eq, 16, NULL, &c), LX_OK); /* 4x: no warning */
    assert_string_equal(g_warning, "");
    lx_cubemap_free(&c);
    lx_env_load_desc ld = {.size = 40};
    assert_int_equal(lx_env_from_image(&eq, "small.hdr", &ld, &c), LX_OK);
    lx_set_log_callback(NULL, NULL);
    if (!strstr(g_warning, "small.hdr: 40 x 40 faces from a 16 x 8 equirect upsample it 10x") ||
        !strstr(g_warning, "MiB cube map"))
        fail_msg("warning '%s'", g_warning);
    lx_cubemap_free(&c);
    lx_image_free(&eq);
}

/* ---- memory ---------------------------------------------------------------- */

static void memory_refused_before_allocating(void **state)
{
    (void)state;
    /* 15 Phong lobes of exponent 1e6 each read the whole 16384^2 source as
     * their lights: 15 x 45 GiB besides the 18 GiB source, more than any
     * machine holds */
    float exponents[LX_MAX_CUBE_MIPS];
    for (int i = 0; i < LX_MAX_CUBE_MIPS; i++)
        exponents[i] = 1e6f;
    lx_prefilter_desc pd = {.filter = LX_SPECULAR_PHONG,
                            .size = 16384,
                            .mips = LX_MAX_CUBE_MIPS,
                            .phong_exponents = exponents};
    assert_int_equal(lx_prefilter_check(16384, &pd), LX_ERR_NOMEM);
    assert_error_mentions("prefilter: a 16384 x 16384 source (18.0 GiB)");
    assert_error_mentions("GiB of memory, "); /* the bound: the machine, a limit */
    /* what fits is accepted, and bad descs get lx_prefilter's messages */
    assert_int_equal(lx_prefilter_check(64, NULL), LX_OK);
    pd = (lx_prefilter_desc){.mips = 9};
    assert_int_equal(lx_prefilter_check(64, &pd), LX_ERR_INVALID);
    assert_error_mentions("9 mip levels asked; a 64 x 64 face has 1..7");
    assert_int_equal(lx_prefilter_check(0, NULL), LX_ERR_INVALID);
    assert_error_mentions("source face size 0");

    /* a 16384 cross: the levels (24 GiB), the cross image and its encoded
     * copy (2 x 36 GiB); refused where less memory is available */
    lx_env_write_desc wd = {.layout = LX_ENV_CROSS};
    uint64_t need = 96ull << 30;
    lx_status st = lx_env_write_check(16384, 15, &wd);
    if (lx_memory_available(NULL) < need) {
        assert_int_equal(st, LX_ERR_NOMEM);
        assert_error_mentions("writing 15 levels of 16384 x 16384 faces as a cross needs");
    } else {
        assert_int_equal(st, LX_OK);
    }
    assert_int_equal(lx_env_write_check(64, 7, NULL), LX_OK);
    assert_int_equal(lx_env_write_check(0, 1, NULL), LX_ERR_INVALID);
    assert_error_mentions("face size 0");
}

int main(void)
{
    lx_test_watchdog(120);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(image_layouts_read_back_exactly),
        cmocka_unit_test(names_told_before_writing),
        cmocka_unit_test(equirect_of_a_constant),
        cmocka_unit_test(ktx_holds_the_levels),
        cmocka_unit_test(failures_leave_nothing),
        cmocka_unit_test(write_threads_progress_cancel),
        cmocka_unit_test(bad_input),
        cmocka_unit_test(conversions_threads_progress_cancel),
        cmocka_unit_test(downsample_to_a_size),
        cmocka_unit_test(upsampling_warns),
        cmocka_unit_test(memory_refused_before_allocating),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
