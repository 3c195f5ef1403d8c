/* lx_image_write's progress and cancel (core.h): in every format the
 * callback hears fractions in [0, 1] that never go back, one call at a
 * time, several times during the encoding and 1.0 last; returning false
 * ends the call with LX_ERR_CANCELLED naming the file, the callback is
 * not called again, and neither the file nor a temporary one is left (a
 * file already at the path stays as it was). The files are the same
 * bytes for 1, 2 and 3 threads, with or without a callback. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"
#include "luxel/core.h"

/* Enough rows for many EXR chunks (16 scanlines each with ZIP), PNG
 * strips (128 KiB of filtered rows) and HDR strips (32 rows). */
#define W 640
#define H 480

typedef struct recorder {
    int calls;
    float fraction[4096];
    _Atomic int inside; /* calls under way: must never pass 1 */
    int overlaps;
    float stop_from; /* return false at the first fraction >= this; > 1: never */
    int after_stop;  /* calls after returning false */
    bool stopped;
} recorder;

static bool record(void *user, float fraction)
{
    recorder *r = user;
    if (atomic_fetch_add(&r->inside, 1) != 0)
        r->overlaps++;
    if (r->stopped)
        r->after_stop++;
    if (r->calls < (int)(sizeof r->fraction / sizeof r->fraction[0]))
        r->fraction[r->calls] = fraction;
    r->calls++;
    bool go = fraction < r->stop_from;
    r->stopped = r->stopped || !go;
    atomic_fetch_sub(&r->inside, 1);
    return go;
}

/* A smooth image with some texture, values in (0, 1] (exposed into every
 * format's range), alpha when channels is 4. */
static lx_image test_image(int channels)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, W, H, channels), LX_OK);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < channels; c++) {
                uint32_t h = (uint32_t)(x * 73856093u) ^ (uint32_t)(y * 19349663u) ^ (uint32_t)c;
                float noise = (float)(h % 1000u) / 100000.0f;
                img.data[((size_t)y * W + x) * channels + c] =
                    0.05f + 0.9f * (float)(x + y * (c + 1)) / (float)(W + H * 4) + noise;
            }
    return img;
}

static unsigned char *read_all(const char *path, size_t *size)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    unsigned char *buf = malloc((size_t)n + 1);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)n, fp), (size_t)n);
    fclose(fp);
    *size = (size_t)n;
    return buf;
}

typedef struct format_case {
    const char *name; /* file name */
    int channels;
    bool half;
    int min_reports; /* reports during the encoding, besides the last 1.0 */
} format_case;

static const format_case cases[] = {
    {"f32.exr", 3, false, 10}, /* a report a scanline at most every 0.1% */
    {"f16.exr", 4, true, 10},  /* 30 chunks encoded, then written */
    {"img.png", 3, false, 8},  /* rows coded, then 8 deflate strips */
    {"img.hdr", 3, false, 10}, /* 15 strips of 32 rows */
    {"img.pfm", 1, false, 10}, /* a report a row at most every 0.1% */
    {"img.jpg", 3, false, 2},  /* the codes, then the encoder's end */
    {"img.tga", 4, false, 2},
};
#define CASES (int)(sizeof cases / sizeof cases[0])

static void progress_is_monotonic(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_image_write_progress");
    for (int i = 0; i < CASES; i++) {
        const format_case *fc = &cases[i];
        lx_image img = test_image(fc->channels);
        for (int threads = 1; threads <= 3; threads++) {
            char path[600];
            snprintf(path, sizeof path, "%s/t%d_%s", dir, threads, fc->name);
            static recorder r;
            memset(&r, 0, sizeof r);
            r.stop_from = 2.0f;
            lx_image_write_desc wd = {
                .half = fc->half, .threads = threads, .progress = record, .progress_user = &r};
            if (lx_image_write(path, &img, &wd) != LX_OK)
                fail_msg("%s: %s", path, lx_last_error());
            if (r.calls < fc->min_reports + 1)
                fail_msg("%s, %d threads: %d reports, want at least %d", fc->name, threads, r.calls,
                         fc->min_reports + 1);
            assert_int_equal(r.overlaps, 0);
            for (int k = 0; k < r.calls && k < 4096; k++) {
                assert_true(r.fraction[k] >= 0.0f && r.fraction[k] <= 1.0f);
                if (k > 0 && r.fraction[k] < r.fraction[k - 1])
                    fail_msg("%s, %d threads: report %d is %g after %g", fc->name, threads, k,
                             (double)r.fraction[k], (double)r.fraction[k - 1]);
            }
            assert_true(r.fraction[r.calls - 1] == 1.0f);
            /* reports come during the encoding, not only at its end */
            assert_true(r.fraction[r.calls / 2] < 1.0f);
        }
        lx_image_free(&img);
    }
}

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_image_write_bytes");
    for (int i = 0; i < CASES; i++) {
        const format_case *fc = &cases[i];
        lx_image img = test_image(fc->channels);
        unsigned char *first = NULL;
        size_t first_size = 0;
        for (int run = 0; run < 4; run++) {
            /* 1, 2 and 3 threads with a callback, 2 without */
            int threads = run < 3 ? run + 1 : 2;
            char path[600];
            snprintf(path, sizeof path, "%s/r%d_%s", dir, run, fc->name);
            static recorder r;
            memset(&r, 0, sizeof r);
            r.stop_from = 2.0f;
            lx_image_write_desc wd = {.half = fc->half,
                                      .threads = threads,
                                      .progress = run < 3 ? record : NULL,
                                      .progress_user = &r};
            assert_int_equal(lx_image_write(path, &img, &wd), LX_OK);
            size_t size;
            unsigned char *bytes = read_all(path, &size);
            if (!first) {
                first = bytes;
                first_size = size;
                continue;
            }
            if (size != first_size || memcmp(bytes, first, size) != 0)
                fail_msg("%s: %d threads wrote other bytes than 1 thread", fc->name, threads);
            free(bytes);
        }
        free(first);
        lx_image_free(&img);
    }
}

/* A file already at the path before a cancelled write. */
static void write_marker(const char *path)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs("old contents", fp);
    assert_int_equal(fclose(fp), 0);
}

static void cancel_leaves_no_file(void **state)
{
    (void)state;
    for (int i = 0; i < CASES; i++) {
        const format_case *fc = &cases[i];
        lx_image img = test_image(fc->channels);
        /* stop at the first report, half-way, and at the last, 1.0 */
        for (int when = 0; when < 3; when++)
            for (int threads = 1; threads <= 3; threads += 2) {
                char tag[64];
                snprintf(tag, sizeof tag, "test_image_write_cancel_%d", i);
                const char *dir = lx_test_dir(tag);
                char path[600];
                snprintf(path, sizeof path, "%s/%s", dir, fc->name);
                static recorder r;
                float stop_from = when == 0 ? 0.0f : when == 1 ? 0.5f : 1.0f;
                memset(&r, 0, sizeof r);
                r.stop_from = stop_from;
                lx_image_write_desc wd = {
                    .half = fc->half, .threads = threads, .progress = record, .progress_user = &r};
                lx_status st = lx_image_write(path, &img, &wd);
                if (st != LX_ERR_CANCELLED)
                    fail_msg("%s, stopped at fraction %g: status %d", fc->name, (double)stop_from,
                             (int)st);
                assert_non_null(strstr(lx_last_error(), path));
                assert_non_null(strstr(lx_last_error(), "writing cancelled"));
                assert_int_equal(r.after_stop, 0);
                assert_int_equal(lx_test_count_files(dir), 0);
                /* over an older file: that file stays */
                write_marker(path);
                memset(&r, 0, sizeof r);
                r.stop_from = stop_from;
                assert_int_equal(lx_image_write(path, &img, &wd), LX_ERR_CANCELLED);
                assert_int_equal(lx_test_count_files(dir), 1);
                size_t size;
                unsigned char *old = read_all(path, &size);
                assert_int_equal(size, strlen("old contents"));
                assert_memory_equal(old, "old contents", size);
                free(old);
            }
        lx_image_free(&img);
    }
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(progress_is_monotonic),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(cancel_leaves_no_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
