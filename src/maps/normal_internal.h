/* Private to src/maps: the slope estimate the normal and parallax maps
 * share (normalmap.c) and their parallel loop over bands of rows. */
#ifndef LX_MAPS_NORMAL_INTERNAL_H
#define LX_MAPS_NORMAL_INTERNAL_H

#include "luxel/maps.h"
#include "core/internal.h"

/* Checks height (one channel, at least one texel, data) and the filled
 * desc (strength finite and > 0, known filter and wrap, threads >= 0);
 * what names the caller in messages. */
lx_status lx_nm_check(const lx_image *height, const lx_normalmap_desc *d, const char *what);

/* Slopes of row y of height in value units per texel, from filter with
 * texels outside addressed by wrap: dx along +x, dy up the image (row
 * above less row below). dx and dy hold height->width floats each. */
void lx_nm_slopes_row(const lx_image *height, lx_normal_filter filter, lx_wrap wrap, int y,
                      float *dx, float *dy);

/* Work on rows [y0, y1) with scratch of `scratch` floats (per thread);
 * returns false when the rows hold a value that is not finite (the caller
 * then finds and names it). */
typedef bool (*lx_nm_rows_fn)(void *ctx, int y0, int y1, float *scratch);

/* Runs fn over the rows of an image height rows tall, in bands on up to
 * `threads` threads (0 = all cores), with progress (may be NULL) heard
 * after each band. LX_ERR_CANCELLED ("<what> cancelled") when progress
 * says stop, LX_ERR_NOMEM when the scratch cannot be had, LX_ERR_INVALID
 * with *bad set when fn returned false; the bands' results do not depend
 * on the thread count. */
lx_status lx_nm_run_rows(int height, size_t scratch, int threads, lx_progress_fn progress,
                         void *user, lx_nm_rows_fn fn, void *ctx, const char *what, bool *bad);

#endif
