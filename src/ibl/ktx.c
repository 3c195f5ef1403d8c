/* KTX 1.1 cube map writer, after the Khronos "KTX File Format Specification"
 * version 1.1 (https://registry.khronos.org/KTX/specs/1.0/ktxspec.v1.html):
 * the 12-byte identifier, endianness 0x04030201, glType HALF_FLOAT or FLOAT,
 * glFormat and glBaseInternalFormat RGBA, glInternalFormat RGBA16F or
 * RGBA32F, six faces, one key/value pair (KTXwriter), then per mip level
 * imageSize (the bytes of one face, as the spec has it for non-array cube
 * maps) and the faces +X, -X, +Y, -Y, +Z, -Z, each padded to 4 bytes. Rows
 * are written first to last: row 0 is face coordinate t = 0 as OpenGL
 * uploads it. Everything is little-endian.
 *
 * Half floats round to nearest, ties to even (IEEE 754-2008 binary16),
 * subnormals included; values above the largest half (65504) are rejected
 * rather than clamped. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GL_HALF_FLOAT 0x140B
#define GL_FLOAT 0x1406
#define GL_RGBA 0x1908
#define GL_RGBA16F 0x881A
#define GL_RGBA32F 0x8814

static const unsigned char ktx_identifier[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31,
                                                 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};

static void put_u32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

static lx_status check_levels(const char *path, const lx_cubemap *levels, int count, bool half)
{
    if (!levels || count < 1 || count > LX_MAX_CUBE_MIPS)
        return lx_fail(LX_ERR_INVALID, "%s: %d mip levels (expected 1..%d)", path, count,
                       LX_MAX_CUBE_MIPS);
    int size0 = levels[0].size;
    if (size0 < 1 || size0 > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "%s: cube size %d is outside 1..%d", path, size0,
                       LX_MAX_CUBE_SIZE);
    if (count > lx_cube_mip_count(size0))
        return lx_fail(LX_ERR_INVALID, "%s: %d mip levels, but a cube of size %d has only %d", path,
                       count, size0, lx_cube_mip_count(size0));
    for (int l = 0; l < count; l++) {
        int want = size0 >> l > 0 ? size0 >> l : 1;
        if (!levels[l].data || levels[l].size != want)
            return lx_fail(LX_ERR_INVALID, "%s: mip level %d is %d texels wide, expected %d", path,
                           l, levels[l].data ? levels[l].size : 0, want);
        const lx_cubemap *c = &levels[l];
        size_t n = 6 * (size_t)c->size * (size_t)c->size * 3;
        for (size_t i = 0; i < n; i++) {
            float v = c->data[i];
            const char *problem = NULL;
            if (!isfinite(v))
                problem = isnan(v) ? "is NaN" : "is infinite";
            else if (half && fabsf(v) > LX_HALF_MAX)
                problem = "is outside the half-float range (|v| <= 65504); write RGBA32F instead";
            if (problem) {
                size_t texel = i / 3, per_face = (size_t)c->size * (size_t)c->size;
                size_t r = texel % per_face;
                char value[40] = "";
                if (isfinite(v))
                    snprintf(value, sizeof value, " %g", (double)v);
                return lx_fail(LX_ERR_INVALID,
                               "%s: mip level %d face %s texel (%zu, %zu): value%s %s", path, l,
                               lx_cube_face_name((int)(texel / per_face)), r % (size_t)c->size,
                               r / (size_t)c->size, value, problem);
            }
        }
    }
    return LX_OK;
}

lx_status lx_ktx_write_cubemap(const char *path, const lx_cubemap *levels, int count, bool half)
{
    lx_ibl_run run = lx_ibl_run_make(0, NULL, NULL);
    return lx_ibl_ktx_write(path, levels, count, half, &run);
}

/* Face rows [y0, y0 + rows) as RGBA texels (A = 1) in the file's type. */
static void convert_rows(const lx_cubemap *c, int face, int y0, int rows, bool half,
                         unsigned char *out, int threads)
{
    size_t texel_bytes = half ? 8 : 16;
    size_t row_bytes = (size_t)c->size * texel_bytes;
    /* a block of a few thousand texels is not worth a thread */
#pragma omp parallel for schedule(static) num_threads(threads) if ((size_t)rows * c->size > 16384)
    for (int r = 0; r < rows; r++) {
        const float *src = lx_cubemap_texel(c, face, 0, y0 + r);
        unsigned char *p = out + (size_t)r * row_bytes;
        for (int x = 0; x < c->size; x++) {
            float rgba[4] = {src[3 * x], src[3 * x + 1], src[3 * x + 2], 1.0f};
            for (int k = 0; k < 4; k++) {
                if (half) {
                    uint16_t h = lx_float_to_half(rgba[k]);
                    *p++ = (unsigned char)h;
                    *p++ = (unsigned char)(h >> 8);
                } else {
                    uint32_t bits;
                    memcpy(&bits, &rgba[k], sizeof bits);
                    put_u32(p, bits);
                    p += 4;
                }
            }
        }
    }
}

lx_status lx_ibl_ktx_write(const char *path, const lx_cubemap *levels, int count, bool half,
                           const lx_ibl_run *run)
{
    if (!path)
        return lx_fail(LX_ERR_INVALID, "lx_ktx_write_cubemap: path is NULL");
    lx_status st = check_levels(path, levels, count, half);
    if (st != LX_OK)
        return st;
    int size0 = levels[0].size;
    size_t texel_bytes = half ? 8 : 16;
    size_t face_bytes0 = (size_t)size0 * (size_t)size0 * texel_bytes;
    if (face_bytes0 > 0xffffffffu)
        return lx_fail(LX_ERR_INVALID, "%s: a %d face is too large for KTX's 32-bit imageSize",
                       path, size0);
    /* rows are converted in blocks of about KTX_BLOCK texels on the run's
     * threads and written in order; progress after each block */
    enum { KTX_BLOCK = 1 << 18 };
    size_t block_texels = (size_t)size0 > KTX_BLOCK ? (size_t)size0 : KTX_BLOCK;
    unsigned char *row = malloc(block_texels * texel_bytes);
    if (!row)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);

    /* key/value data: one pair, padded to 4 bytes */
    static const char kv_key[] = "KTXwriter";
    char kv_value[32];
    snprintf(kv_value, sizeof kv_value, "luxel %s", lx_version());
    uint32_t kv_size = (uint32_t)(sizeof kv_key + strlen(kv_value) + 1);
    uint32_t kv_pad = 3 - ((kv_size + 3) % 4);
    uint32_t kv_total = 4 + kv_size + kv_pad;

    unsigned char header[64];
    memcpy(header, ktx_identifier, 12);
    const uint32_t fields[13] = {0x04030201u,
                                 half ? GL_HALF_FLOAT : GL_FLOAT,
                                 half ? 2u : 4u, /* glTypeSize */
                                 GL_RGBA,
                                 half ? GL_RGBA16F : GL_RGBA32F,
                                 GL_RGBA,
                                 (uint32_t)size0,
                                 (uint32_t)size0,
                                 0, /* pixelDepth */
                                 0, /* numberOfArrayElements */
                                 6, /* numberOfFaces */
                                 (uint32_t)count,
                                 kv_total};
    for (int i = 0; i < 13; i++)
        put_u32(header + 12 + 4 * i, fields[i]);

    lx_out_file f;
    st = lx_out_open(&f, path);
    if (st != LX_OK) {
        free(row);
        return st;
    }
    FILE *fp = f.fp;
    bool ok = fwrite(header, 1, 64, fp) == 64;
    unsigned char kv[4 + 64 + 3] = {0};
    put_u32(kv, kv_size);
    memcpy(kv + 4, kv_key, sizeof kv_key);
    memcpy(kv + 4 + sizeof kv_key, kv_value, strlen(kv_value) + 1);
    ok = ok && fwrite(kv, 1, kv_total, fp) == kv_total;
    /* progress by faces written, each weighed by its texels */
    double total = 0.0, done = 0.0;
    for (int l = 0; l < count; l++)
        total += 6.0 * levels[l].size * levels[l].size;
    bool cancelled = false;
    for (int l = 0; l < count && ok && !cancelled; l++) {
        const lx_cubemap *c = &levels[l];
        size_t face_bytes = (size_t)c->size * (size_t)c->size * texel_bytes;
        unsigned char size_field[4];
        put_u32(size_field, (uint32_t)face_bytes);
        ok = fwrite(size_field, 1, 4, fp) == 4;
        /* face_bytes is a multiple of 8: no cube or mip padding is needed */
        int block_rows = (int)(block_texels / (size_t)c->size);
        for (int face = 0; face < 6 && ok && !cancelled; face++)
            for (int y = 0; y < c->size && ok && !cancelled; y += block_rows) {
                int rows = c->size - y < block_rows ? c->size - y : block_rows;
                convert_rows(c, face, y, rows, half, row, run->threads);
                size_t n = (size_t)rows * (size_t)c->size * texel_bytes;
                ok = fwrite(row, 1, n, fp) == n;
                done += (double)rows * c->size;
                if (run->progress && ok)
                    cancelled =
                        !run->progress(run->user, run->base + run->span * (float)(done / total));
            }
    }
    free(row);
    if (cancelled) {
        lx_out_abort(&f);
        return lx_fail(LX_ERR_CANCELLED, "%s: writing cancelled", path);
    }
    if (!ok) {
        int err = errno;
        lx_out_abort(&f);
        return lx_fail(LX_ERR_IO, "%s: write failed: %s", path, strerror(err));
    }
    return lx_out_commit(&f);
}
