/* Private to src/core: the per-format image readers and writers behind
 * lx_image_load_memory and lx_image_write (image.c). */
#ifndef LX_CORE_IMAGE_INTERNAL_H
#define LX_CORE_IMAGE_INTERNAL_H

#include "internal.h"

#include <stdio.h>

#if defined(__GNUC__)
#define LX_IMG_HIDDEN __attribute__((visibility("hidden")))
#else
#define LX_IMG_HIDDEN
#endif

/* Readers. name is used in messages only; data holds size bytes; is_tga
 * says the stb reader got a TGA (which has no signature). Each fills
 * *out with the values as stored (no channel conversion, no NaN check) and
 * leaves it zeroed on failure. */
LX_IMG_HIDDEN lx_status lx_img_load_stb(const unsigned char *data, size_t size, const char *name,
                                        bool is_tga, bool raw_8bit, lx_image *out);
LX_IMG_HIDDEN lx_status lx_img_load_pfm(const unsigned char *data, size_t size, const char *name,
                                        lx_image *out);
LX_IMG_HIDDEN lx_status lx_img_load_exr(const unsigned char *data, size_t size, const char *name,
                                        lx_image *out);

/* Writers to an open temporary file. The caller has checked img (1..4
 * channels, finite values, exposed values in the format's range) and
 * commits or aborts the file. exposure is the multiplier (never 0);
 * threads bounds the encoding threads (0 = all cores). */
LX_IMG_HIDDEN lx_status lx_img_write_stb(FILE *fp, const char *path, const lx_image *img,
                                         lx_image_format format, float exposure, int threads);
LX_IMG_HIDDEN lx_status lx_img_write_pfm(FILE *fp, const char *path, const lx_image *img,
                                         float exposure);
LX_IMG_HIDDEN lx_status lx_img_write_exr(FILE *fp, const char *path, const lx_image *img,
                                         float exposure, bool half, int threads);

/* A PNG file of 8-bit pixels (channels 1..4, rows top to bottom) in memory
 * from malloc, *out_len bytes; NULL when out of memory. Deflates on up to
 * `threads` threads (0 = all cores); the bytes do not depend on it
 * (image_png.c). */
LX_IMG_HIDDEN unsigned char *lx_img_png_encode(const unsigned char *pixels, int width, int height,
                                               int channels, int threads, int *out_len);

/* The bound below which stb's RGBE encoder keeps its exponent byte in
 * range (2^127). */
#define LX_RGBE_LIMIT 0x1p127f

#endif
