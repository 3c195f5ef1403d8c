/* Discrete Fourier transforms of any length, and the cosine transform
 * through them, for the Poisson solve in height_from_normals.c.
 *
 * The Fourier transform is the mixed-radix Cooley-Tukey recursion
 * (decimation in time; radices 4, 2, 3, 5, 7, 11, 13 with their
 * butterflies), and for a length with a larger prime factor Bluestein's
 * chirp z-transform (Bluestein 1970; Rabiner, Schafer and Rader 1969):
 * X_k = w_k sum_j (x_j w_j) conj(w_(k-j)), w_k = exp(-i pi k^2 / n), the
 * sum a circular convolution of length m >= 2n - 1 (a power of two) done
 * with two transforms. The cosine transform (DCT-II) is Makhoul's (IEEE
 * Trans. ASSP 28(1), 1980): the even-indexed samples then the odd ones
 * reversed, one complex transform of length n, a twist by
 * exp(-i pi k / (2n)); its inverse runs the same steps backward. */
#include "fft_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FFT_PI 3.14159265358979323846

static void cis_table(double *t, int n, double scale)
{
    for (int k = 0; k < n; k++) {
        t[2 * k] = cos(scale * k);
        t[2 * k + 1] = sin(scale * k);
    }
}

void lx_fft_plan_free(lx_fft_plan *p)
{
    if (!p)
        return;
    free(p->twiddle);
    free(p->dct);
    free(p->chirp);
    free(p->chirp_f);
    if (p->sub) {
        lx_fft_plan_free(p->sub);
        free(p->sub);
    }
    memset(p, 0, sizeof *p);
}

size_t lx_fft_scratch(const lx_fft_plan *p)
{
    /* the cosine transform's complex row, then the transform's own */
    size_t own = p->m ? 2 * (size_t)p->m + lx_fft_scratch(p->sub) : 2 * (size_t)p->n + 64;
    return 2 * (size_t)p->n + own;
}

lx_status lx_fft_plan_make(int n, lx_fft_plan *p)
{
    memset(p, 0, sizeof *p);
    if (n < 1)
        return lx_fail(LX_ERR_INVALID, "transform length %d must be at least 1", n);
    p->n = n;
    int rest = n;
    static const int radices[] = {4, 2, 3, 5, 7, 11, 13};
    for (int r = 0; r < 7; r++)
        while (rest % radices[r] == 0 && p->factor_count < 40) {
            p->factors[p->factor_count++] = radices[r];
            rest /= radices[r];
        }
    p->twiddle = malloc(sizeof(double) * 2 * (size_t)n);
    p->dct = malloc(sizeof(double) * 2 * (size_t)n);
    if (!p->twiddle || !p->dct)
        goto nomem;
    cis_table(p->twiddle, n, -2.0 * FFT_PI / n);
    cis_table(p->dct, n, -FFT_PI / (2.0 * n));
    if (rest == 1)
        return LX_OK;
    /* Bluestein: a power of two m >= 2n - 1 */
    p->factor_count = 0;
    int m = 1;
    while (m < 2 * n - 1)
        m *= 2;
    p->m = m;
    p->chirp = malloc(sizeof(double) * 2 * (size_t)n);
    p->chirp_f = calloc(2 * (size_t)m, sizeof(double));
    p->sub = calloc(1, sizeof *p->sub);
    if (!p->chirp || !p->chirp_f || !p->sub)
        goto nomem;
    for (int k = 0; k < n; k++) {
        /* k^2 mod 2n keeps the angle small and exact */
        long long q = ((long long)k * k) % (2LL * n);
        double a = -FFT_PI * (double)q / n;
        p->chirp[2 * k] = cos(a);
        p->chirp[2 * k + 1] = sin(a);
    }
    lx_status st = lx_fft_plan_make(m, p->sub);
    if (st != LX_OK) {
        free(p->sub);
        p->sub = NULL;
        lx_fft_plan_free(p);
        return st;
    }
    double *b = p->chirp_f;
    for (int j = 0; j < n; j++) {
        b[2 * j] = p->chirp[2 * j];
        b[2 * j + 1] = -p->chirp[2 * j + 1];
        if (j > 0) {
            b[2 * (m - j)] = b[2 * j];
            b[2 * (m - j) + 1] = b[2 * j + 1];
        }
    }
    double *scratch = malloc(sizeof(double) * lx_fft_scratch(p->sub));
    if (!scratch)
        goto nomem;
    lx_fft(p->sub, b, false, scratch);
    free(scratch);
    for (int j = 0; j < 2 * m; j++)
        b[j] /= m;
    return LX_OK;
nomem:
    lx_fft_plan_free(p);
    return lx_fail(LX_ERR_NOMEM, "out of memory for a transform of length %d", n);
}

/* out (n complex) = the transform of in[0], in[s], ..., in[(n-1) s]
 * (complex, s in complex steps), n the product of factors[f...]; the
 * plan's twiddles are for N = p->n, so W_n^e = twiddle[e N / n]. */
static void transform(const lx_fft_plan *p, double *out, const double *in, size_t s, int f, int n,
                      double *tmp)
{
    int r = p->factors[f], m = n / r;
    if (m == 1) {
        for (int q = 0; q < r; q++) {
            out[2 * q] = in[2 * (size_t)q * s];
            out[2 * q + 1] = in[2 * (size_t)q * s + 1];
        }
    } else {
        for (int j = 0; j < r; j++)
            transform(p, out + 2 * (size_t)j * m, in + 2 * (size_t)j * s, s * (size_t)r, f + 1, m,
                      tmp);
    }
    size_t stride = (size_t)(p->n / n); /* twiddle step for W_n */
    const double *tw = p->twiddle;
    if (r == 2) {
        for (int k = 0; k < m; k++) {
            double *a = out + 2 * k, *b = out + 2 * (k + m);
            double wr = tw[2 * stride * k], wi = tw[2 * stride * k + 1];
            double br = b[0] * wr - b[1] * wi, bi = b[0] * wi + b[1] * wr;
            b[0] = a[0] - br;
            b[1] = a[1] - bi;
            a[0] += br;
            a[1] += bi;
        }
        return;
    }
    if (r == 4) {
        for (int k = 0; k < m; k++) {
            double y[4][2];
            for (int j = 0; j < 4; j++) {
                const double *x = out + 2 * (k + j * m);
                size_t e = stride * (size_t)j * (size_t)k;
                double wr = tw[2 * e], wi = tw[2 * e + 1];
                y[j][0] = x[0] * wr - x[1] * wi;
                y[j][1] = x[0] * wi + x[1] * wr;
            }
            double s0r = y[0][0] + y[2][0], s0i = y[0][1] + y[2][1];
            double d0r = y[0][0] - y[2][0], d0i = y[0][1] - y[2][1];
            double s1r = y[1][0] + y[3][0], s1i = y[1][1] + y[3][1];
            double d1r = y[1][0] - y[3][0], d1i = y[1][1] - y[3][1];
            /* W_4 = -i: X1 = d0 - i d1, X3 = d0 + i d1 */
            double *x0 = out + 2 * k, *x1 = out + 2 * (k + m), *x2 = out + 2 * (k + 2 * m),
                   *x3 = out + 2 * (k + 3 * m);
            x0[0] = s0r + s1r;
            x0[1] = s0i + s1i;
            x2[0] = s0r - s1r;
            x2[1] = s0i - s1i;
            x1[0] = d0r + d1i;
            x1[1] = d0i - d1r;
            x3[0] = d0r - d1i;
            x3[1] = d0i + d1r;
        }
        return;
    }
    /* any small radix: the r-point transform of the twiddled values */
    size_t rstride = (size_t)(p->n / r);
    for (int k = 0; k < m; k++) {
        for (int j = 0; j < r; j++) {
            const double *x = out + 2 * (k + j * m);
            size_t e = stride * (size_t)j * (size_t)k;
            double wr = tw[2 * e], wi = tw[2 * e + 1];
            tmp[2 * j] = x[0] * wr - x[1] * wi;
            tmp[2 * j + 1] = x[0] * wi + x[1] * wr;
        }
        for (int q = 0; q < r; q++) {
            double sr = 0.0, si = 0.0;
            for (int j = 0; j < r; j++) {
                size_t e = rstride * (size_t)((j * q) % r);
                double wr = tw[2 * e], wi = tw[2 * e + 1];
                sr += tmp[2 * j] * wr - tmp[2 * j + 1] * wi;
                si += tmp[2 * j] * wi + tmp[2 * j + 1] * wr;
            }
            out[2 * (k + q * m)] = sr;
            out[2 * (k + q * m) + 1] = si;
        }
    }
}

static void forward(const lx_fft_plan *p, double *data, double *scratch)
{
    int n = p->n;
    if (n == 1)
        return;
    if (!p->m) {
        memcpy(scratch, data, sizeof(double) * 2 * (size_t)n);
        transform(p, data, scratch, 1, 0, n, scratch + 2 * (size_t)n);
        return;
    }
    int m = p->m;
    double *a = scratch, *rest = scratch + 2 * (size_t)m;
    const double *w = p->chirp;
    for (int j = 0; j < n; j++) {
        a[2 * j] = data[2 * j] * w[2 * j] - data[2 * j + 1] * w[2 * j + 1];
        a[2 * j + 1] = data[2 * j] * w[2 * j + 1] + data[2 * j + 1] * w[2 * j];
    }
    memset(a + 2 * (size_t)n, 0, sizeof(double) * 2 * (size_t)(m - n));
    lx_fft(p->sub, a, false, rest);
    const double *b = p->chirp_f;
    for (int j = 0; j < m; j++) {
        double re = a[2 * j] * b[2 * j] - a[2 * j + 1] * b[2 * j + 1];
        double im = a[2 * j] * b[2 * j + 1] + a[2 * j + 1] * b[2 * j];
        a[2 * j] = re;
        a[2 * j + 1] = im;
    }
    lx_fft(p->sub, a, true, rest);
    for (int k = 0; k < n; k++) {
        data[2 * k] = a[2 * k] * w[2 * k] - a[2 * k + 1] * w[2 * k + 1];
        data[2 * k + 1] = a[2 * k] * w[2 * k + 1] + a[2 * k + 1] * w[2 * k];
    }
}

void lx_fft(const lx_fft_plan *p, double *data, bool inverse, double *scratch)
{
    size_t n = (size_t)p->n;
    if (inverse)
        for (size_t k = 0; k < n; k++)
            data[2 * k + 1] = -data[2 * k + 1];
    forward(p, data, scratch);
    if (inverse)
        for (size_t k = 0; k < n; k++)
            data[2 * k + 1] = -data[2 * k + 1];
}

void lx_dct(const lx_fft_plan *p, double *data, double *scratch)
{
    int n = p->n;
    double *v = scratch;
    for (int j = 0; j < (n + 1) / 2; j++) {
        v[2 * j] = data[2 * j];
        v[2 * j + 1] = 0.0;
    }
    for (int j = 0; j < n / 2; j++) {
        v[2 * (n - 1 - j)] = data[2 * j + 1];
        v[2 * (n - 1 - j) + 1] = 0.0;
    }
    lx_fft(p, v, false, scratch + 2 * (size_t)n);
    for (int k = 0; k < n; k++)
        data[k] = p->dct[2 * k] * v[2 * k] - p->dct[2 * k + 1] * v[2 * k + 1];
}

void lx_idct(const lx_fft_plan *p, double *data, double *scratch)
{
    int n = p->n;
    double *v = scratch;
    for (int k = 0; k < n; k++) {
        /* V_k = exp(i pi k / 2n) (X_k - i X_(n-k)), X_n = 0 */
        double c = p->dct[2 * k], s = -p->dct[2 * k + 1];
        double xk = data[k], xr = k > 0 ? data[n - k] : 0.0;
        v[2 * k] = c * xk + s * xr;
        v[2 * k + 1] = s * xk - c * xr;
    }
    lx_fft(p, v, true, scratch + 2 * (size_t)n);
    double inv = 1.0 / n;
    for (int j = 0; j < (n + 1) / 2; j++)
        data[2 * j] = v[2 * j] * inv;
    for (int j = 0; j < n / 2; j++)
        data[2 * j + 1] = v[2 * (n - 1 - j)] * inv;
}
