/* PNG/JPEG/TGA/Radiance HDR through stb_image and stb_image_write (the
 * implementations are compiled into Debian's libstb; the PNG writer's is
 * image_png.c's, with zlib as its deflate). 8-bit and 16-bit data use the
 * sRGB transfer function of IEC 61966-2-1:1999; alpha stays linear. */
#include "image_internal.h"

#include <zlib.h>

#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

/* ---- reading ------------------------------------------------------------- */

static lx_status stb_failure(const char *name)
{
    const char *why = stbi_failure_reason();
    if (!why)
        why = "unknown error";
    lx_status s = strcmp(why, "outofmem") == 0 ? LX_ERR_NOMEM : LX_ERR_FORMAT;
    return lx_fail(s, "%s: cannot decode: %s", name, why);
}

/* Offset just past the next '\n' (or the end), as stb's header reader
 * splits lines. */
static size_t next_line(const unsigned char *d, size_t size, size_t pos, bool *empty)
{
    size_t start = pos;
    while (pos < size && d[pos] != '\n')
        pos++;
    *empty = pos == start;
    return pos < size ? pos + 1 : pos;
}

/* Walks a Radiance file's pixel data the way stb_image 2.27 decodes it and
 * fails where stb would not: stb reads zeros past the end of the data
 * (a truncated file loads as black), and a zero-length run makes its RLE
 * loop spin forever. After this check stb never runs out of data. */
static lx_status check_hdr_data(const unsigned char *d, size_t size, int w, int h, const char *name)
{
    bool empty;
    size_t pos = next_line(d, size, 0, &empty); /* "#?RADIANCE" */
    do
        pos = next_line(d, size, pos, &empty);
    while (!empty && pos < size);
    pos = next_line(d, size, pos, &empty);   /* "-Y h +X w" */
    size_t flat = (size_t)w * (size_t)h * 4; /* w, h < 2^24 (stb's limit) */
    if (w < 8 || w >= 32768) {
        if (size - pos < flat)
            goto truncated;
        return LX_OK;
    }
    for (int y = 0; y < h; y++) {
        if (size - pos < 4)
            goto truncated;
        const unsigned char *p = d + pos;
        if (p[0] != 2 || p[1] != 2 || (p[2] & 0x80)) {
            /* not run-length encoded: stb reads the whole image flat from here */
            if (size - pos < flat)
                goto truncated;
            return LX_OK;
        }
        if ((p[2] << 8 | p[3]) != w)
            return lx_fail(LX_ERR_FORMAT,
                           "%s: scanline %d: run-length header gives width %d, "
                           "expected %d",
                           name, y, p[2] << 8 | p[3], w);
        pos += 4;
        for (int c = 0; c < 4; c++) {
            for (int x = 0; x < w;) {
                if (pos >= size)
                    goto truncated;
                int count = d[pos++];
                bool run = count > 128;
                if (run)
                    count -= 128;
                if (count == 0 || count > w - x)
                    return lx_fail(LX_ERR_FORMAT, "%s: scanline %d: bad run length %d", name, y,
                                   count);
                size_t bytes = run ? 1 : (size_t)count;
                if (size - pos < bytes)
                    goto truncated;
                pos += bytes;
                x += count;
            }
        }
    }
    return LX_OK;
truncated:
    return lx_fail(LX_ERR_FORMAT, "%s: truncated: pixel data ends at byte %zu", name, size);
}

/* The tables a JPEG has defined so far and the components of its frame. */
typedef struct jpeg_state {
    bool huffman[2][4], quant[4], frame, progressive, coded[4];
    int components, ids[4], quant_of[4];
} jpeg_state;

/* Checks one SOS header (at body) against what is defined: stb decodes
 * with whatever its uninitialised tables hold otherwise. */
static lx_status check_jpeg_scan(jpeg_state *j, const unsigned char *d, size_t size, size_t body,
                                 const char *name)
{
    size_t ns = d[body], q = body + 1;
    if (q + 2 * ns + 3 > size)
        return LX_OK; /* stb reads zeros and fails the scan */
    int ss = d[q + 2 * ns], ah = d[q + 2 * ns + 2] >> 4;
    /* dc: a baseline scan or a progressive DC first pass, which reads the DC
     * Huffman table; ac: a pass that reads the AC table */
    bool dc = !j->progressive || (ss == 0 && ah == 0), ac = !j->progressive || ss > 0;
    for (size_t k = 0; k < ns; k++) {
        int id = d[q + 2 * k], td = d[q + 2 * k + 1] >> 4, ta = d[q + 2 * k + 1] & 15;
        for (int i = 0; i < j->components; i++) {
            if (j->ids[i] != id || td > 3 || ta > 3)
                continue;
            if ((dc && !j->huffman[0][td]) || (ac && !j->huffman[1][ta]))
                return lx_fail(LX_ERR_FORMAT,
                               "%s: corrupt JPEG: scan of component %d uses an undefined "
                               "Huffman table",
                               name, id);
            /* progressive: the DC first pass zeroes a component's blocks,
             * which every later pass refines */
            if (!dc && !j->coded[i])
                return lx_fail(LX_ERR_FORMAT,
                               "%s: corrupt JPEG: scan of component %d before its first DC scan",
                               name, id);
            if (j->quant_of[i] > 3 || !j->quant[j->quant_of[i]])
                return lx_fail(LX_ERR_FORMAT,
                               "%s: corrupt JPEG: component %d uses an undefined "
                               "quantization table",
                               name, id);
            if (dc)
                j->coded[i] = true;
        }
    }
    return LX_OK;
}

/* Walks a JPEG's markers the way stb_image 2.27 does and rejects what stb
 * mishandles (found by fuzz/fuzz_image.c):
 * - a Huffman table whose 16 code counts sum past 256: stb writes past it;
 * - a scan using a table never defined, a component no scan codes
 *   (baseline) or without a DC first pass (progressive): stb decodes with
 *   or returns uninitialised memory;
 * - a file smaller than its image can be (every 8x8 block costs at least one
 *   bit): stb "decodes" the missing data as zeros. */
static lx_status check_jpeg(const unsigned char *d, size_t size, const char *name)
{
    jpeg_state j = {.components = 0};
    size_t pos = 2; /* after SOI */
    while (pos < size) {
        if (d[pos] != 0xff) { /* stb skips padding between segments */
            pos++;
            continue;
        }
        while (pos < size && d[pos] == 0xff)
            pos++;
        if (pos + 2 >= size)
            break;
        int m = d[pos++];
        if (m == 0xd9) /* EOI: stb stops */
            break;
        if (m == 0x00 || m == 0x01 || (m >= 0xd0 && m <= 0xd7))
            continue; /* no length field */
        size_t len = (size_t)d[pos] << 8 | d[pos + 1], body = pos + 2, p = body;
        /* stb reads DHT and DQT tables while the declared length lasts,
         * even past it */
        for (long left = (long)len - 2; m == 0xc4 && left > 0 && p < size;) {
            int n = 0, tc = d[p] >> 4, th = d[p] & 15;
            if (tc > 1 || th > 3)
                break; /* stb rejects the table first */
            for (size_t i = p + 1; i < p + 17 && i < size; i++)
                n += d[i];
            if (n > 256)
                return lx_fail(LX_ERR_FORMAT,
                               "%s: corrupt JPEG: Huffman table at byte %zu has %d codes "
                               "(at most 256)",
                               name, p, n);
            j.huffman[tc][th] = true;
            p += 17 + (size_t)n;
            left -= 17 + n;
        }
        for (long left = (long)len - 2; m == 0xdb && left > 0 && p < size;) {
            int precision = d[p] >> 4, t = d[p] & 15;
            if (precision > 1 || t > 3)
                break;
            j.quant[t] = true;
            p += precision ? 129 : 65;
            left -= precision ? 129 : 65;
        }
        if ((m == 0xc0 || m == 0xc1 || m == 0xc2) && !j.frame && body + 6 <= size) {
            j.frame = true; /* stb reads the first frame header only */
            j.progressive = m == 0xc2;
            uint64_t h = (uint64_t)d[body + 1] << 8 | d[body + 2];
            uint64_t w = (uint64_t)d[body + 3] << 8 | d[body + 4];
            j.components = d[body + 5] < 4 ? d[body + 5] : 4;
            for (int i = 0; i < j.components; i++) {
                size_t c = body + 6 + 3 * (size_t)i;
                j.ids[i] = c < size ? d[c] : 0;
                j.quant_of[i] = c + 2 < size ? d[c + 2] : 0;
            }
            if (w * h > 512 * (uint64_t)size)
                return lx_fail(LX_ERR_FORMAT,
                               "%s: truncated: a %llux%llu JPEG needs more than %zu bytes", name,
                               (unsigned long long)w, (unsigned long long)h, size);
        }
        if (m == 0xda && j.frame && body < size) {
            lx_status s = check_jpeg_scan(&j, d, size, body, name);
            if (s != LX_OK)
                return s;
        }
        if (len < 2)
            break; /* stb fails here */
        pos += len;
        if (m == 0xda) {
            /* entropy-coded data runs to the next marker: 0xff followed by
             * neither a stuffed 0, fill, nor a restart marker */
            while (pos + 1 < size && !(d[pos] == 0xff && d[pos + 1] != 0x00 && d[pos + 1] != 0xff &&
                                       (d[pos + 1] < 0xd0 || d[pos + 1] > 0xd7)))
                pos++;
        }
    }
    for (int i = 0; i < j.components; i++)
        if (!j.coded[i])
            return lx_fail(LX_ERR_FORMAT, "%s: corrupt JPEG: component %d has no %sscan data", name,
                           j.ids[i], j.progressive ? "DC " : "");
    return LX_OK;
}

/* stb_image reads zeros past the end of a TGA, so a cut file loads as
 * black and a 30-byte header can claim a 6403x28525 image that stb then
 * allocates and "decodes". The data must at least hold the pixels
 * (uncompressed) or one packet per 128 pixels (run-length encoded). The
 * header has passed plausible_tga() in image.c (18 bytes or more). */
static lx_status check_tga_size(const unsigned char *d, size_t size, const char *name)
{
    size_t w = d[12] | (size_t)d[13] << 8, h = d[14] | (size_t)d[15] << 8;
    size_t pixel_bytes = ((size_t)d[16] + 7) / 8;
    size_t map_bytes = d[1] ? (d[5] | (size_t)d[6] << 8) * (((size_t)d[7] + 7) / 8) : 0;
    size_t offset = 18 + (size_t)d[0] + map_bytes;
    size_t have = size > offset ? size - offset : 0;
    bool rle = d[2] >= 9;
    size_t need = rle ? (w * h + 127) / 128 * (1 + pixel_bytes) : w * h * pixel_bytes;
    if (have < need)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: truncated: %zux%zu %s needs %s%zu bytes of pixels, "
                       "found %zu",
                       name, w, h, rle ? "run-length TGA" : "TGA", rle ? "at least " : "", need,
                       have);
    return LX_OK;
}

/* ---- PNG: the DEFLATE stream stb inflates ----------------------------------
 * stb_image 2.27 maps the invalid distance codes 30 and 31 to distance 0 and
 * copies bytes it never wrote into the image (found by fuzzing; valgrind
 * shows the uninitialised reads). zlib inflates the stream first, into a
 * scratch buffer, and what zlib rejects never reaches stb. */

static bool inflate_check(const unsigned char *d, size_t size, bool zlib_header)
{
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    /* negative window bits: a raw stream without the zlib header */
    if (inflateInit2(&zs, zlib_header ? 15 : -15) != Z_OK)
        return false;
    unsigned char scratch[16384];
    int ret = Z_OK;
    size_t offset = 0;
    while (ret == Z_OK) {
        if (zs.avail_in == 0) {
            size_t chunk = size - offset < (size_t)1 << 30 ? size - offset : (size_t)1 << 30;
            if (chunk == 0)
                break; /* input ended before the stream did */
            zs.next_in = (unsigned char *)d + offset;
            zs.avail_in = (uInt)chunk;
            offset += chunk;
        }
        zs.next_out = scratch;
        zs.avail_out = sizeof scratch;
        ret = inflate(&zs, Z_NO_FLUSH);
    }
    inflateEnd(&zs);
    return ret == Z_STREAM_END;
}

/* The IHDR chunk's size, bit depth and colour type (PNG specification,
 * table 11.1), named in the message where stb would only say "unknown
 * image type". A file too short for IHDR is stb's to report. */
static lx_status check_png_header(const unsigned char *d, size_t size, const char *name)
{
    if (size < 8 + 8 + 13 || memcmp(d + 12, "IHDR", 4) != 0)
        return LX_OK;
    uint32_t w = (uint32_t)d[16] << 24 | (uint32_t)d[17] << 16 | (uint32_t)d[18] << 8 | d[19];
    uint32_t h = (uint32_t)d[20] << 24 | (uint32_t)d[21] << 16 | (uint32_t)d[22] << 8 | d[23];
    int depth = d[24], type = d[25];
    if (w == 0 || h == 0)
        return lx_fail(LX_ERR_FORMAT, "%s: the image has no pixels (%ux%u)", name, w, h);
    /* the depths each colour type allows, as bits 1, 2, 4, 8, 16 */
    int allowed;
    switch (type) {
    case 0: allowed = 1 | 2 | 4 | 8 | 16; break;
    case 3: allowed = 1 | 2 | 4 | 8; break;
    case 2: case 4: case 6: allowed = 8 | 16; break;
    default:
        return lx_fail(LX_ERR_FORMAT, "%s: unknown PNG colour type %d", name, type);
    }
    bool power = depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16;
    if (!power || !(allowed & depth))
        return lx_fail(LX_ERR_UNSUPPORTED,
                       "%s: unsupported bit depth %d for PNG colour type %d", name, depth, type);
    return LX_OK;
}

/* Gathers the IDAT chunks (the one zlib stream stb inflates) and checks it.
 * A "CgBI" chunk (Apple's PNG variant) means a raw stream without the
 * 2-byte zlib header, as stb reads it. */
static lx_status check_png_data(const unsigned char *d, size_t size, const char *name)
{
    unsigned char *stream = malloc(size);
    if (!stream)
        return lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", name, size);
    size_t n = 0;
    bool header = true;
    for (size_t pos = 8; size - pos >= 12;) {
        size_t len =
            (size_t)d[pos] << 24 | (size_t)d[pos + 1] << 16 | (size_t)d[pos + 2] << 8 | d[pos + 3];
        const unsigned char *type = d + pos + 4;
        if (len > size - pos - 12 || memcmp(type, "IEND", 4) == 0)
            break;
        if (memcmp(type, "CgBI", 4) == 0)
            header = false;
        if (memcmp(type, "IDAT", 4) == 0) {
            memcpy(stream + n, d + pos + 8, len);
            n += len;
        }
        pos += 12 + len;
    }
    /* no data or a malformed zlib header is stb's own error */
    bool stb_fails = n == 0 || (header && (n < 2 || (stream[0] * 256 + stream[1]) % 31 != 0 ||
                                           (stream[1] & 32) || (stream[0] & 15) != 8));
    bool ok = stb_fails || inflate_check(stream, n, header);
    free(stream);
    if (!ok)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: corrupt PNG: the compressed image data is invalid or truncated", name);
    return LX_OK;
}

static bool is_alpha(int c, int channels)
{
    return (channels == 2 || channels == 4) && c == channels - 1;
}

/* stb's decoded samples a row at a time as the floats a load returns:
 * HDR as they are, 16-bit and 8-bit samples mapped to [0,1] and
 * sRGB-decoded but for alpha and raw data. */
typedef struct stb_rows {
    const void *pixels;
    int width, channels;
    bool hdr, wide;
    bool linear[4]; /* channel c taken without the sRGB decoding */
    float to_linear[256], to_unit[256];
} stb_rows;

static void stb_row(void *ctx, int y, float *row)
{
    const stb_rows *r = ctx;
    int c = r->channels;
    size_t n = (size_t)r->width * (size_t)c, at = (size_t)y * n;
    if (r->hdr) {
        memcpy(row, (const float *)r->pixels + at, n * sizeof(float));
    } else if (r->wide) {
        const stbi_us *p = (const stbi_us *)r->pixels + at;
        for (size_t i = 0; i < n; i++) {
            float v = (float)p[i] / 65535.0f;
            row[i] = r->linear[i % (size_t)c] ? v : lx_srgb_to_linear(v);
        }
    } else {
        const stbi_uc *p = (const stbi_uc *)r->pixels + at;
        for (size_t i = 0; i < n; i++)
            row[i] = r->linear[i % (size_t)c] ? r->to_unit[p[i]] : r->to_linear[p[i]];
    }
}

lx_status lx_img_load_stb(const unsigned char *data, size_t size, const char *name, bool is_tga,
                          bool raw_8bit, const lx_img_budget *budget, lx_image *out)
{
    memset(out, 0, sizeof *out);
    if (size > INT_MAX)
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: %zu bytes is more than stb_image reads (2 GiB)",
                       name, size);
    int len = (int)size;
    lx_status s = LX_OK;
    bool png = size >= 8 && memcmp(data, "\x89PNG\r\n\x1a\n", 8) == 0;
    if (size >= 3 && data[0] == 0xff && data[1] == 0xd8 && data[2] == 0xff)
        s = check_jpeg(data, size, name);
    else if (png)
        s = check_png_header(data, size, name);
    else if (is_tga)
        s = check_tga_size(data, size, name);
    if (s != LX_OK)
        return s;

    /* stbi_loadf would also accept 8-bit files and apply its own gamma and
     * scale; luxel decodes those itself, so loadf is only for real HDR. */
    bool hdr = stbi_is_hdr_from_memory(data, len) != 0;
    bool wide = !hdr && stbi_is_16_bit_from_memory(data, len) != 0;

    /* Size up front, from the header, so a file claiming a huge image
     * fails with luxel's message before stb allocates. stb holds its
     * decoded samples and, while decoding, about as much again (a PNG's
     * inflated rows, a JPEG's component planes). */
    int w, h, comp;
    if (!stbi_info_from_memory(data, len, &w, &h, &comp))
        return stb_failure(name);
    double sample = hdr ? sizeof(float) : wide ? 2 : 1;
    double decoder = 2.0 * (double)w * (double)h * (comp > 0 ? comp : 4) * sample;
    s = lx_img_check_size(budget, name, w, h, comp > 0 ? comp : 4,
                          decoder >= 1.8e19 ? UINT64_MAX : (uint64_t)decoder, false);
    if (s != LX_OK)
        return s;
    /* inflating a PNG's whole stream: once its size is known to fit */
    if (png && (s = check_png_data(data, size, name)) != LX_OK)
        return s;
    if (hdr) {
        s = check_hdr_data(data, size, w, h, name);
        if (s != LX_OK)
            return s;
    }
    void *pixels;
    if (hdr)
        pixels = stbi_loadf_from_memory(data, len, &w, &h, &comp, 0);
    else if (wide)
        pixels = stbi_load_16_from_memory(data, len, &w, &h, &comp, 0);
    else
        pixels = stbi_load_from_memory(data, len, &w, &h, &comp, 0);
    if (!pixels)
        return stb_failure(name);

    /* the float image at the size kept: the decoded samples are converted
     * (and averaged, when reduced) straight into it, then let go */
    int kw, kh;
    lx_img_reduced_size(w, h, budget->keep_pixels, &kw, &kh, budget->halvings);
    s = lx_image_alloc(out, kw, kh, comp);
    if (s != LX_OK) {
        stbi_image_free(pixels);
        lx_error_prefix(name);
        return s;
    }
    stb_rows rows = {.pixels = pixels, .width = w, .channels = comp, .hdr = hdr, .wide = wide};
    for (int k = 0; k < 256; k++) {
        rows.to_unit[k] = (float)k / 255.0f;
        rows.to_linear[k] = raw_8bit ? rows.to_unit[k] : lx_srgb_to_linear(rows.to_unit[k]);
    }
    for (int c = 0; c < comp; c++)
        rows.linear[c] = raw_8bit || is_alpha(c, comp);
    if (kw == w && kh == h) {
        for (int y = 0; y < h; y++)
            stb_row(&rows, y, out->data + (size_t)y * (size_t)w * (size_t)comp);
    } else {
        s = lx_img_reduce(w, h, comp, stb_row, &rows, out);
        if (s != LX_OK) {
            lx_image_free(out);
            lx_error_prefix(name);
        }
    }
    stbi_image_free(pixels);
    return s;
}

/* ---- writing ------------------------------------------------------------- */

/* Errors show in ferror(fp), which lx_out_commit checks. */
static void write_to_file(void *context, void *data, int size)
{
    fwrite(data, 1, (size_t)size, (FILE *)context);
}

/* 8-bit sRGB encoding by an exact search instead of a pow per value:
 * code k is the nearest to linear v from threshold[k - 1] on (the linear
 * value of the sRGB midpoint between codes k - 1 and k), so v's code is
 * the count of thresholds <= v. Each threshold is kept as the smallest
 * float at or above its double value (a float compares with it exactly as
 * with the double), and a table over the float's top 19 bits (sign,
 * exponent and 10 mantissa bits: buckets 0.1% wide, narrower than the gap
 * between any two thresholds) gives the count at the bottom of v's
 * bucket, at most one step short of the answer. */
#define SRGB8_SHIFT 13
#define SRGB8_FIRST (0x39000000u >> SRGB8_SHIFT) /* below threshold[0] */
#define SRGB8_LAST (0x3f800000u >> SRGB8_SHIFT)  /* 1.0f */
typedef struct srgb8_encoder {
    float threshold[256]; /* [255]: above every float, a sentinel */
    uint8_t start[SRGB8_LAST - SRGB8_FIRST + 1];
} srgb8_encoder;

static void srgb8_init(srgb8_encoder *enc)
{
    for (int k = 1; k <= 255; k++) {
        double c = ((double)k - 0.5) / 255.0;
        double t = c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
        float f = (float)t;
        if ((double)f < t)
            f = nextafterf(f, INFINITY);
        enc->threshold[k - 1] = f;
    }
    enc->threshold[255] = INFINITY;
    int k = 0;
    for (uint32_t b = SRGB8_FIRST; b <= SRGB8_LAST; b++) {
        uint32_t lo = b << SRGB8_SHIFT;
        float v;
        memcpy(&v, &lo, sizeof v);
        while (k < 255 && v >= enc->threshold[k])
            k++;
        enc->start[b - SRGB8_FIRST] = (uint8_t)k;
    }
}

static unsigned char encode_srgb8(const srgb8_encoder *enc, float v)
{
    if (!(v >= enc->threshold[0]))
        return 0; /* NaN, negative, or below code 1 */
    if (v >= 1.0f)
        return 255;
    uint32_t bits;
    memcpy(&bits, &v, sizeof bits);
    int k = enc->start[(bits >> SRGB8_SHIFT) - SRGB8_FIRST];
    k += v >= enc->threshold[k];   /* one threshold at most in a bucket */
    while (v >= enc->threshold[k]) /* (never taken; kept exact regardless) */
        k++;
    return (unsigned char)k;
}

static unsigned char encode_unorm8(float v)
{
    v = v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
    return (unsigned char)(v * 255.0f + 0.5f);
}

/* Progress of the 8-bit writers: the sRGB codes, then the encoder. PNG:
 * stb's row filters (no reports) and the deflate strips, then the file's
 * bytes in one write; JPEG and TGA: stb's encoder, which cannot report,
 * then its end. Shares as measured on an 8192 x 8192 RGB image on one
 * and two threads (codes 20-25%, filters 11-16%, deflate 40-50%, the
 * write 12-15%). */
#define LX_8BIT_CODES 0.25f
#define LX_PNG_DEFLATE_FROM 0.4f
#define LX_PNG_DEFLATE_TO 0.87f

static lx_status write_8bit(FILE *fp, const char *path, const lx_image *img, lx_image_format format,
                            float exposure, lx_tonemap tonemap, bool linear, int threads,
                            lx_img_progress *progress)
{
    int c = img->channels;
    /* stb_image_write sizes its buffers with int arithmetic */
    if ((int64_t)img->height * ((int64_t)img->width * c + 1) > INT_MAX / 2)
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: %dx%d is too large for the %s writer", path,
                       img->width, img->height, lx_image_format_extension(format));
    size_t n = (size_t)img->width * (size_t)img->height * (size_t)c;
    unsigned char *bytes = malloc(n);
    if (!bytes)
        return lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, n);
    srgb8_encoder enc;
    srgb8_init(&enc);
    int colour = c == 2 || c == 4 ? c - 1 : c; /* channels before alpha */
    lx_img_progress_phase(progress, 0.0f, LX_8BIT_CODES, (uint64_t)img->height);
    /* rows in parallel: each value's code depends on that value alone */
#pragma omp parallel for schedule(static) num_threads(lx_thread_count(threads))
    for (int y = 0; y < img->height; y++) {
        if (lx_img_progress_stopped(progress))
            continue;
        size_t first = (size_t)y * (size_t)img->width;
        for (size_t p = first; p < first + (size_t)img->width; p++) {
            const float *v = img->data + p * (size_t)c;
            unsigned char *b = bytes + p * (size_t)c;
            if (colour == 3) {
                float rgb[3] = {v[0] * exposure, v[1] * exposure, v[2] * exposure};
                lx_tonemap_rgb(tonemap, rgb);
                for (int k = 0; k < 3; k++)
                    b[k] = linear ? encode_unorm8(rgb[k]) : encode_srgb8(&enc, rgb[k]);
            } else {
                float g = lx_tonemap_grey(tonemap, v[0] * exposure);
                b[0] = linear ? encode_unorm8(g) : encode_srgb8(&enc, g);
            }
            if (colour < c)
                b[colour] = encode_unorm8(v[colour]);
        }
        lx_img_progress_add(progress, 1);
    }
    if (lx_img_progress_stopped(progress)) {
        free(bytes);
        return lx_img_cancelled(path);
    }
    if (format == LX_IMAGE_PNG) {
        int len = 0;
        lx_img_progress_phase(progress, LX_PNG_DEFLATE_FROM,
                              LX_PNG_DEFLATE_TO - LX_PNG_DEFLATE_FROM, 1);
        unsigned char *png =
            lx_img_png_encode(bytes, img->width, img->height, c, threads, progress, &len);
        free(bytes);
        if (!png && lx_img_progress_stopped(progress))
            return lx_img_cancelled(path);
        if (!png)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory encoding png", path);
        fwrite(png, 1, (size_t)len, fp);
        free(png);
        return LX_OK;
    }
    int ok;
    switch (format) {
    case LX_IMAGE_JPG:
        ok = stbi_write_jpg_to_func(write_to_file, fp, img->width, img->height, c, bytes, 95);
        break;
    default:
        ok = stbi_write_tga_to_func(write_to_file, fp, img->width, img->height, c, bytes);
        break;
    }
    free(bytes);
    if (!ok)
        return lx_fail(LX_ERR_IO, "%s: cannot encode %s", path, lx_image_format_extension(format));
    return LX_OK;
}

/* Radiance HDR in strips of rows: stb encodes each strip (its own small
 * file, whose header is dropped) into memory on several threads, and the
 * strips are written in order after the one header of the whole image.
 * A scanline's run-length code depends on that scanline alone, so the
 * file is the same bytes on any thread count and as one stb call would
 * write it, but for the header. */
#define LX_HDR_STRIP 32

typedef struct hdr_strip {
    unsigned char *data;
    size_t size, capacity;
    bool failed;
    size_t negative;
} hdr_strip;

static void append_to_strip(void *context, void *data, int size)
{
    hdr_strip *s = context;
    if (s->failed || size <= 0)
        return;
    if (s->size + (size_t)size > s->capacity) {
        size_t cap = s->capacity ? 2 * s->capacity : 4096;
        while (cap < s->size + (size_t)size)
            cap *= 2;
        unsigned char *grown = realloc(s->data, cap);
        if (!grown) {
            s->failed = true;
            return;
        }
        s->data = grown;
        s->capacity = cap;
    }
    memcpy(s->data + s->size, data, (size_t)size);
    s->size += (size_t)size;
}

/* Where the scanlines of stb's output start: after the "-Y h +X w" line
 * that ends every Radiance header. */
static size_t hdr_pixels_start(const hdr_strip *s)
{
    for (size_t i = 0; i + 3 < s->size; i++)
        if ((i == 0 || s->data[i - 1] == '\n') && memcmp(s->data + i, "-Y ", 3) == 0) {
            const unsigned char *nl = memchr(s->data + i, '\n', s->size - i);
            return nl ? (size_t)(nl - s->data) + 1 : s->size;
        }
    return s->size;
}

/* Encodes rows [y0, y0 + rows) into s; values exposed, negatives (RGBE
 * has no sign: stb would cast a negative mantissa to unsigned char)
 * written as 0 and counted. */
static void encode_hdr_strip(const lx_image *img, float exposure, int y0, int rows, hdr_strip *s)
{
    int c = img->channels;
    size_t n = (size_t)img->width * (size_t)rows * (size_t)c;
    float *values = malloc(n * sizeof(float));
    if (!values) {
        s->failed = true;
        return;
    }
    const float *src = img->data + (size_t)y0 * (size_t)img->width * (size_t)c;
    for (size_t i = 0; i < n; i++) {
        float v = is_alpha((int)(i % (size_t)c), c) ? src[i] : src[i] * exposure;
        if (v < 0.0f) {
            v = 0.0f;
            s->negative++;
        }
        values[i] = v;
    }
    if (!stbi_write_hdr_to_func(append_to_strip, s, img->width, rows, c, values))
        s->failed = true;
    free(values);
}

static lx_status write_hdr(FILE *fp, const char *path, const lx_image *img, float exposure,
                           int threads, lx_img_progress *progress)
{
    int c = img->channels;
    /* stb_image_write indexes a strip's values with int arithmetic */
    if ((int64_t)LX_HDR_STRIP * img->width * c > INT_MAX)
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: %d pixels a row is too wide for the hdr writer",
                       path, img->width);
    int n_threads = lx_thread_count(threads);
    int strips = (img->height + LX_HDR_STRIP - 1) / LX_HDR_STRIP;
    int batch = n_threads < strips ? n_threads : strips;
    hdr_strip *s = calloc((size_t)batch, sizeof *s);
    if (!s)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    fprintf(fp, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n", img->height, img->width);
    lx_img_progress_phase(progress, 0.0f, 1.0f, (uint64_t)img->height);
    lx_status st = LX_OK;
    size_t negative = 0;
    for (int first = 0; first < strips && st == LX_OK; first += batch) {
        int count = strips - first < batch ? strips - first : batch;
#pragma omp parallel for schedule(static, 1) num_threads(count)
        for (int k = 0; k < count; k++) {
            int y0 = (first + k) * LX_HDR_STRIP;
            int rows = img->height - y0 < LX_HDR_STRIP ? img->height - y0 : LX_HDR_STRIP;
            s[k].size = 0;
            s[k].failed = false;
            s[k].negative = 0;
            encode_hdr_strip(img, exposure, y0, rows, &s[k]);
        }
        for (int k = 0; k < count && st == LX_OK; k++) {
            if (s[k].failed) {
                st = lx_fail(LX_ERR_NOMEM, "%s: out of memory encoding hdr", path);
                break;
            }
            size_t at = hdr_pixels_start(&s[k]);
            fwrite(s[k].data + at, 1, s[k].size - at, fp);
            negative += s[k].negative;
            int y0 = (first + k) * LX_HDR_STRIP;
            int rows = img->height - y0 < LX_HDR_STRIP ? img->height - y0 : LX_HDR_STRIP;
            if (!lx_img_progress_add(progress, (uint64_t)rows))
                st = lx_img_cancelled(path);
        }
    }
    for (int k = 0; k < batch; k++)
        free(s[k].data);
    free(s);
    if (st == LX_OK && negative)
        lx_log(LX_LOG_WARN, "%s: %zu negative values written as 0 (Radiance HDR has no sign)", path,
               negative);
    return st;
}

lx_status lx_img_write_stb(FILE *fp, const char *path, const lx_image *img, lx_image_format format,
                           float exposure, lx_tonemap tonemap, bool linear, int threads,
                           lx_img_progress *progress)
{
    if (format == LX_IMAGE_HDR)
        return write_hdr(fp, path, img, exposure, threads, progress);
    return write_8bit(fp, path, img, format, exposure, tonemap, linear, threads, progress);
}
