/* Private to src/maps: discrete Fourier and cosine transforms of any
 * length (fft.c), for the Poisson solve of heights from normals
 * (height_from_normals.c). Complex values are interleaved doubles
 * (re, im). */
#ifndef LX_MAPS_FFT_INTERNAL_H
#define LX_MAPS_FFT_INTERNAL_H

#include "luxel/core.h"

#include <stdbool.h>
#include <stddef.h>

/* A transform length's precomputed tables. */
typedef struct lx_fft_plan {
    int n;
    int factor_count;
    int factors[40]; /* radices, in the order they are taken */
    double *twiddle; /* n complex: exp(-2 pi i k / n) */
    double *dct;     /* n complex: exp(-i pi k / (2 n)), for the cosine transform */
    /* Bluestein's chirp z-transform when n has a prime factor above the
     * direct radices: a power-of-two plan of length m >= 2n - 1 */
    int m;
    double *chirp;   /* n complex: exp(-i pi k^2 / n) */
    double *chirp_f; /* m complex: the transform of the conjugate chirp, / m */
    struct lx_fft_plan *sub;
} lx_fft_plan;

/* Makes the tables for length n >= 1; LX_ERR_NOMEM when they do not fit. */
lx_status lx_fft_plan_make(int n, lx_fft_plan *p);
void lx_fft_plan_free(lx_fft_plan *p);

/* Doubles of scratch one transform of the plan's length needs. */
size_t lx_fft_scratch(const lx_fft_plan *p);

/* In place: X_k = sum_j x_j exp(-+2 pi i j k / n) (minus sign forward,
 * plus inverse; unscaled, so forward then inverse multiplies by n). */
void lx_fft(const lx_fft_plan *p, double *data, bool inverse, double *scratch);

/* The cosine transform (DCT-II) of n reals, in place:
 * X_k = sum_j x_j cos(pi k (2 j + 1) / (2 n)); and its exact inverse
 * (lx_idct(lx_dct(x)) == x up to rounding). Makhoul's method through one
 * complex transform of length n. */
void lx_dct(const lx_fft_plan *p, double *data, double *scratch);
void lx_idct(const lx_fft_plan *p, double *data, double *scratch);

#endif
