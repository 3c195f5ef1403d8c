/* Portable Float Map reader and writer, after the format's definition by
 * Paul Debevec (https://www.pauldebevec.com/Research/HDR/PFM/): a text
 * header "PF" (RGB) or "Pf" (grey), width, height and a scale whose sign
 * gives the byte order (negative = little endian), then 32-bit floats, rows
 * from the bottom of the image to the top. */
#include "image_internal.h"

#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Reads the next whitespace-separated header field into tok. Fields are
 * short; the copy gives strtol a terminated string. */
static lx_status next_field(const unsigned char *d, size_t size, size_t *pos, char *tok,
                            size_t tok_size, const char *name, const char *what)
{
    size_t p = *pos;
    if (p >= size || !isspace(d[p]))
        return lx_fail(LX_ERR_FORMAT, "%s: header: expected whitespace before the %s", name, what);
    while (p < size && isspace(d[p]))
        p++;
    size_t n = 0;
    while (p < size && !isspace(d[p])) {
        if (n + 1 >= tok_size)
            return lx_fail(LX_ERR_FORMAT, "%s: header: %s is too long", name, what);
        tok[n++] = (char)d[p++];
    }
    tok[n] = '\0';
    if (n == 0)
        return lx_fail(LX_ERR_FORMAT, "%s: truncated: header ends before the %s", name, what);
    *pos = p;
    return LX_OK;
}

static lx_status parse_size(const char *tok, const char *name, const char *what, int *out)
{
    for (const char *c = tok; *c; c++)
        if (!isdigit((unsigned char)*c))
            return lx_fail(LX_ERR_FORMAT, "%s: header: %s \"%s\" is not a positive integer", name,
                           what, tok);
    errno = 0;
    long v = strtol(tok, NULL, 10);
    if (errno || v < 1 || v > INT_MAX)
        return lx_fail(LX_ERR_FORMAT, "%s: header: %s %s is out of range (1..%d)", name, what, tok,
                       INT_MAX);
    *out = (int)v;
    return LX_OK;
}

/* The scale's sign (-1 or +1; 0 when the field is not a non-zero number).
 * Parsed by hand: strtod follows the locale's decimal point, and only the
 * sign is used. */
static int scale_sign(const char *t)
{
    int sign = 1;
    if (*t == '+' || *t == '-')
        sign = *t++ == '-' ? -1 : 1;
    bool digits = false, nonzero = false;
    for (int part = 0; part < 2; part++) {
        while (isdigit((unsigned char)*t)) {
            digits = true;
            nonzero |= *t++ != '0';
        }
        if (part == 0 && *t == '.')
            t++;
        else
            break;
    }
    if (!digits)
        return 0;
    if (*t == 'e' || *t == 'E') {
        t++;
        if (*t == '+' || *t == '-')
            t++;
        if (!isdigit((unsigned char)*t))
            return 0;
        while (isdigit((unsigned char)*t))
            t++;
    }
    return *t == '\0' && nonzero ? sign : 0;
}

static float float_from_bytes(const unsigned char *b, bool little)
{
    uint32_t u =
        little ? (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24
               : (uint32_t)b[3] | (uint32_t)b[2] << 8 | (uint32_t)b[1] << 16 | (uint32_t)b[0] << 24;
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

lx_status lx_img_load_pfm(const unsigned char *data, size_t size, const char *name,
                          const lx_img_budget *budget, lx_image *out)
{
    memset(out, 0, sizeof *out);
    if (size < 2 || data[0] != 'P' || (data[1] != 'F' && data[1] != 'f'))
        return lx_fail(LX_ERR_FORMAT, "%s: not a PFM file (header must start with PF or Pf)", name);
    int channels = data[1] == 'F' ? 3 : 1;
    size_t pos = 2;
    char tok[64];
    int width, height;
    lx_status s = next_field(data, size, &pos, tok, sizeof tok, name, "width");
    if (s == LX_OK)
        s = parse_size(tok, name, "width", &width);
    if (s == LX_OK)
        s = next_field(data, size, &pos, tok, sizeof tok, name, "height");
    if (s == LX_OK)
        s = parse_size(tok, name, "height", &height);
    if (s == LX_OK)
        s = next_field(data, size, &pos, tok, sizeof tok, name, "scale");
    if (s != LX_OK)
        return s;
    int sign = scale_sign(tok);
    if (sign == 0)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: header: scale \"%s\" must be a non-zero number (its sign gives "
                       "the byte order)",
                       name, tok);
    /* Exactly one whitespace character separates the header from the
     * pixels, which may themselves start with bytes that look like spaces. */
    if (pos >= size || !isspace(data[pos]))
        return lx_fail(LX_ERR_FORMAT, "%s: truncated: no line break after the header", name);
    pos++;

    size_t need;
    if (!lx_size_mul((size_t)width, (size_t)height, (size_t)channels * 4, &need))
        return lx_fail(LX_ERR_FORMAT, "%s: header: %dx%d pixels overflow the address space", name,
                       width, height);
    size_t have = size - pos;
    /* a header ended by "\r\n" leaves exactly one byte too many */
    if (have == need + 1 && data[pos - 1] == '\r' && data[pos] == '\n') {
        pos++;
        have--;
    }
    /* Checked before allocating, so a short file cannot ask for memory its
     * header merely claims. */
    if (have < need)
        return lx_fail(LX_ERR_FORMAT, "%s: truncated: expected %zu bytes of pixels, found %zu",
                       name, need, have);
    if (have > need)
        lx_log(LX_LOG_WARN, "%s: %zu bytes after the pixels ignored", name, have - need);
    /* the pixels are read from the file's bytes: no buffer of the reader's */
    s = lx_img_check_size(budget, name, width, height, channels, 0, true);
    if (s != LX_OK)
        return s;

    s = lx_image_alloc(out, width, height, channels);
    if (s != LX_OK) {
        lx_error_prefix(name);
        return s;
    }
    bool little = sign < 0;
    size_t row_values = (size_t)width * (size_t)channels;
    const unsigned char *p = data + pos;
    for (int r = 0; r < height; r++) {
        float *row = out->data + (size_t)(height - 1 - r) * row_values;
        for (size_t i = 0; i < row_values; i++, p += 4)
            row[i] = float_from_bytes(p, little);
    }
    return LX_OK;
}

static void float_to_le(float f, unsigned char *b)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    b[0] = (unsigned char)u;
    b[1] = (unsigned char)(u >> 8);
    b[2] = (unsigned char)(u >> 16);
    b[3] = (unsigned char)(u >> 24);
}

lx_status lx_img_write_pfm(FILE *fp, const char *path, const lx_image *img, float exposure,
                           lx_img_progress *progress)
{
    /* PFM holds grey or RGB: grey+alpha keeps the grey, RGBA the colour. */
    int in_c = img->channels;
    int out_c = in_c <= 2 ? 1 : 3;
    size_t row_bytes = (size_t)img->width * (size_t)out_c * 4;
    unsigned char *row = malloc(row_bytes);
    if (!row)
        return lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, row_bytes);
    fprintf(fp, "%s\n%d %d\n-1.0\n", out_c == 3 ? "PF" : "Pf", img->width, img->height);
    lx_img_progress_phase(progress, 0.0f, 1.0f, (uint64_t)img->height);
    bool stopped = false;
    for (int y = img->height - 1; y >= 0 && !ferror(fp) && !stopped; y--) {
        const float *src = img->data + (size_t)y * (size_t)img->width * (size_t)in_c;
        unsigned char *b = row;
        for (int x = 0; x < img->width; x++, src += in_c)
            for (int c = 0; c < out_c; c++, b += 4)
                float_to_le(src[c] * exposure, b);
        fwrite(row, 1, row_bytes, fp);
        stopped = !lx_img_progress_add(progress, 1);
    }
    free(row);
    if (ferror(fp))
        return lx_fail(LX_ERR_IO, "%s: write failed", path);
    if (stopped)
        return lx_img_cancelled(path);
    return LX_OK;
}
