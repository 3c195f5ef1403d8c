/* Order-2 spherical harmonics for irradiance: R. Ramamoorthi and
 * P. Hanrahan, "An Efficient Representation for Irradiance Environment
 * Maps", SIGGRAPH 2001. Projection (their equation 10) as a sum over cube
 * texels weighted by their exact solid angles, in double; irradiance by
 * their equation 13 with the constants c1..c5. The basis is the paper's,
 * with x, y, z luxel's axes (+Y up): the irradiance formula holds in any
 * orthonormal frame, only the names of the coefficients follow the axes. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

const float lx_sh_irradiance_constants[5] = {0.429043f, 0.511664f, 0.743125f, 0.886227f, 0.247708f};

void lx_sh9_basis(lx_vec3 d, float y[9])
{
    y[0] = 0.282095f;
    y[1] = 0.488603f * d.y;
    y[2] = 0.488603f * d.z;
    y[3] = 0.488603f * d.x;
    y[4] = 1.092548f * d.x * d.y;
    y[5] = 1.092548f * d.y * d.z;
    y[6] = 0.315392f * (3.0f * d.z * d.z - 1.0f);
    y[7] = 1.092548f * d.x * d.z;
    y[8] = 0.546274f * (d.x * d.x - d.y * d.y);
}

/* How each face's direction (x, y, z) is made of its local coordinates
 * (a, b, c) = (1, sc, tc) / sqrt(1 + sc^2 + tc^2): world axis i =
 * sign * local[perm], read off the face table (lx_ibl_face_axes: exactly
 * one of the major, right and down axes has a component along i). */
static void face_perm_sign(int face, int perm[3], double sign[3])
{
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            if (lx_ibl_face_axes[face][k][i] != 0.0f) {
                perm[i] = k;
                sign[i] = lx_ibl_face_axes[face][k][i];
            }
}

/* Local monomials: 1, a, b, c, aa, bb, cc, ab, ac, bc. */
enum { M1, MA, MB, MC, MAA, MBB, MCC, MAB, MAC, MBC, MONOMIALS };

static int mono2(int i, int j)
{
    static const int table[3][3] = {{MAA, MAB, MAC}, {MAB, MBB, MBC}, {MAC, MBC, MCC}};
    return table[i][j];
}

/* One row y of all six faces: the radiance-weighted local monomial sums,
 * out[face][monomial][channel]. Along a row tc is fixed, so with
 * q_k(x) = Omega {1, r, r sc, r^2, r^2 sc, r^2 sc^2} (r = a) six sums per
 * channel give all ten monomials. Each sum is split into two lanes (even
 * and odd x) added at the end: a fixed order the compiler can vectorise. */
static void project_row(const lx_cubemap *c, const double *omega, int y, double *q, double *lin,
                        double out[6][MONOMIALS][3])
{
    int n = c->size;
    double tc = 2.0 * (y + 0.5) / n - 1.0;
    double *q0 = q, *q1 = q + n, *q2 = q + 2 * n, *q3 = q + 3 * n, *q4 = q + 4 * n, *q5 = q + 5 * n;
    for (int x = 0; x < n; x++) {
        double sc = 2.0 * (x + 0.5) / n - 1.0;
        double r2 = 1.0 / (1.0 + sc * sc + tc * tc), r = sqrt(r2);
        double w = lx_ibl_omega(omega, n, x, y);
        q0[x] = w, q1[x] = w * r, q2[x] = w * r * sc;
        q3[x] = w * r2, q4[x] = w * r2 * sc, q5[x] = w * r2 * sc * sc;
    }
    for (int face = 0; face < 6; face++) {
        const float *p = lx_cubemap_texel(c, face, 0, y);
        for (int x = 0; x < n; x++)
            for (int ch = 0; ch < 3; ch++)
                lin[ch * n + x] = p[3 * x + ch];
        double acc[6][3][2] = {{{0}}};
        int x = 0;
        for (; x + 1 < n; x += 2)
            for (int ch = 0; ch < 3; ch++) {
                const double *l = lin + ch * n + x;
                for (int lane = 0; lane < 2; lane++) {
                    acc[0][ch][lane] += q0[x + lane] * l[lane];
                    acc[1][ch][lane] += q1[x + lane] * l[lane];
                    acc[2][ch][lane] += q2[x + lane] * l[lane];
                    acc[3][ch][lane] += q3[x + lane] * l[lane];
                    acc[4][ch][lane] += q4[x + lane] * l[lane];
                    acc[5][ch][lane] += q5[x + lane] * l[lane];
                }
            }
        for (; x < n; x++)
            for (int ch = 0; ch < 3; ch++) {
                double l = lin[ch * n + x];
                acc[0][ch][0] += q0[x] * l, acc[1][ch][0] += q1[x] * l;
                acc[2][ch][0] += q2[x] * l, acc[3][ch][0] += q3[x] * l;
                acc[4][ch][0] += q4[x] * l, acc[5][ch][0] += q5[x] * l;
            }
        for (int ch = 0; ch < 3; ch++) {
            double P[6];
            for (int k = 0; k < 6; k++)
                P[k] = acc[k][ch][0] + acc[k][ch][1];
            double *m = &out[face][0][ch];
            m[3 * M1] = P[0], m[3 * MA] = P[1], m[3 * MB] = P[2], m[3 * MC] = tc * P[1];
            m[3 * MAA] = P[3], m[3 * MBB] = P[5], m[3 * MCC] = tc * tc * P[3];
            m[3 * MAB] = P[4], m[3 * MAC] = tc * P[3], m[3 * MBC] = tc * P[4];
        }
    }
}

typedef struct project_job {
    const lx_cubemap *c;
    const double *omega;
    double *partial; /* per row: [6][MONOMIALS][3] */
} project_job;

#define ROW_SUMS ((size_t)6 * MONOMIALS * 3)

static bool project_item(void *ctx, int y)
{
    const project_job *j = ctx;
    double *scratch = malloc(sizeof(double) * 9 * (size_t)j->c->size);
    if (!scratch)
        return false;
    project_row(j->c, j->omega, y, scratch, scratch + 6 * (size_t)j->c->size,
                (double(*)[MONOMIALS][3])(j->partial + ROW_SUMS * (size_t)y));
    free(scratch);
    return true;
}

lx_status lx_sh_project(const lx_cubemap *c, const lx_ibl_desc *in, lx_sh9 *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "SH projection: no output (NULL)");
    memset(out, 0, sizeof *out);
    lx_ibl_desc desc = lx_ibl_desc_defaults(in);
    /* no separate scan for NaN: a bad texel makes the sums non-finite */
    lx_status st = lx_ibl_check_cubemap(c, "SH projection: cube map", false);
    if (st == LX_OK)
        st = lx_ibl_check_threads(desc.threads);
    if (st != LX_OK)
        return st;
    int n = c->size;
    double *omega = lx_ibl_solid_angles(n);
    double *partial = malloc(sizeof(double) * ROW_SUMS * (size_t)n);
    if (!omega || !partial) {
        free(omega);
        free(partial);
        return lx_fail(LX_ERR_NOMEM, "out of memory projecting a %d x %d cube map", n, n);
    }
    /* one partial sum per row index, added up in row order afterwards:
     * the same result for any number of threads */
    project_job job = {c, omega, partial};
    lx_ibl_run run = lx_ibl_run_make(desc.threads, desc.progress, desc.progress_user);
    st = lx_ibl_for(&run, n, NULL, project_item, &job, "SH projection");
    if (st != LX_OK) {
        free(partial);
        free(omega);
        return st;
    }
    double local[6][MONOMIALS][3] = {{{0}}};
    for (int y = 0; y < n; y++)
        for (size_t k = 0; k < ROW_SUMS; k++)
            (&local[0][0][0])[k] += partial[ROW_SUMS * (size_t)y + k];
    free(partial);
    free(omega);

    /* world monomial sums, then the coefficients */
    double sum[9][3] = {{0}};
    for (int face = 0; face < 6; face++) {
        int pm[3] = {0, 0, 0};
        double sg[3] = {0, 0, 0};
        face_perm_sign(face, pm, sg);
        for (int ch = 0; ch < 3; ch++) {
            double w1 = local[face][M1][ch];
            double w[3], ww[3][3];
            for (int i = 0; i < 3; i++) {
                w[i] = sg[i] * local[face][MA + pm[i]][ch];
                for (int j = 0; j < 3; j++)
                    ww[i][j] = sg[i] * sg[j] * local[face][mono2(pm[i], pm[j])][ch];
            }
            /* x = 0, y = 1, z = 2 */
            sum[0][ch] += 0.282095 * w1;
            sum[1][ch] += 0.488603 * w[1];
            sum[2][ch] += 0.488603 * w[2];
            sum[3][ch] += 0.488603 * w[0];
            sum[4][ch] += 1.092548 * ww[0][1];
            sum[5][ch] += 1.092548 * ww[1][2];
            sum[6][ch] += 0.315392 * (3.0 * ww[2][2] - w1);
            sum[7][ch] += 1.092548 * ww[0][2];
            sum[8][ch] += 0.546274 * (ww[0][0] - ww[1][1]);
        }
    }
    for (int k = 0; k < 9; k++)
        for (int ch = 0; ch < 3; ch++) {
            if (!isfinite(sum[k][ch]) || fabs(sum[k][ch]) > 3.0e38) {
                memset(out, 0, sizeof *out);
                st = lx_ibl_check_cubemap(c, "SH projection: cube map", true);
                return st != LX_OK ? st
                                   : lx_fail(LX_ERR_INVALID,
                                             "SH projection: coefficients overflow a float");
            }
            out->c[k][ch] = (float)sum[k][ch];
        }
    return LX_OK;
}

static lx_status check_sh(const lx_sh9 *sh)
{
    if (!sh)
        return lx_fail(LX_ERR_INVALID, "SH irradiance: no coefficients (NULL)");
    for (int k = 0; k < 9; k++)
        for (int ch = 0; ch < 3; ch++)
            if (!isfinite(sh->c[k][ch]))
                return lx_fail(LX_ERR_INVALID, "SH irradiance: coefficient %d channel %d is %g", k,
                               ch, (double)sh->c[k][ch]);
    return LX_OK;
}

void lx_sh_irradiance(const lx_sh9 *sh, lx_vec3 n, float out[3])
{
    const double c1 = 0.429043, c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708;
    double x = n.x, y = n.y, z = n.z;
    for (int ch = 0; ch < 3; ch++) {
        double L00 = sh->c[0][ch], L1m1 = sh->c[1][ch], L10 = sh->c[2][ch], L11 = sh->c[3][ch];
        double L2m2 = sh->c[4][ch], L2m1 = sh->c[5][ch], L20 = sh->c[6][ch];
        double L21 = sh->c[7][ch], L22 = sh->c[8][ch];
        /* equation 13 */
        double e = c1 * L22 * (x * x - y * y) + c3 * L20 * z * z + c4 * L00 - c5 * L20 +
                   2.0 * c1 * (L2m2 * x * y + L21 * x * z + L2m1 * y * z) +
                   2.0 * c2 * (L11 * x + L1m1 * y + L10 * z);
        out[ch] = (float)e;
    }
}

typedef struct cube_job {
    const lx_sh9 *sh;
    lx_cubemap *out;
    long *negative; /* per row */
    float *lowest;  /* per row */
} cube_job;

static bool cube_row(void *ctx, int r)
{
    const cube_job *j = ctx;
    int size = j->out->size, face = r / size, y = r % size;
    long negative = 0;
    float lowest = 0.0f;
    for (int x = 0; x < size; x++) {
        lx_vec3 d = lx_cube_direction(face, (x + 0.5f) / size, (y + 0.5f) / size);
        float *o = lx_cubemap_texel(j->out, face, x, y);
        lx_sh_irradiance(j->sh, d, o);
        for (int k = 0; k < 3; k++) {
            negative += o[k] < 0.0f;
            lowest = o[k] < lowest ? o[k] : lowest;
        }
    }
    j->negative[r] = negative;
    j->lowest[r] = lowest;
    return true;
}

lx_status lx_sh_irradiance_cube(const lx_sh9 *sh, int size, const lx_ibl_desc *in, lx_cubemap *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "SH irradiance: no output cube map (NULL)");
    memset(out, 0, sizeof *out);
    lx_ibl_desc desc = lx_ibl_desc_defaults(in);
    lx_status st = check_sh(sh);
    if (st == LX_OK)
        st = lx_ibl_check_threads(desc.threads);
    if (st != LX_OK)
        return st;
    size = size ? size : LX_IRRADIANCE_DEFAULT_SIZE;
    if (size < 1 || size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "SH irradiance: face size %d is outside 1..%d", size,
                       LX_MAX_CUBE_SIZE);
    if ((st = lx_cubemap_alloc(out, size)) != LX_OK)
        return st;
    int rows = 6 * size;
    cube_job job = {sh, out, malloc(sizeof(long) * (size_t)rows),
                    malloc(sizeof(float) * (size_t)rows)};
    if (!job.negative || !job.lowest)
        st = lx_fail(LX_ERR_NOMEM, "SH irradiance: out of memory");
    lx_ibl_run run = lx_ibl_run_make(desc.threads, desc.progress, desc.progress_user);
    if (st == LX_OK)
        st = lx_ibl_for(&run, rows, NULL, cube_row, &job, "SH irradiance");
    long negative = 0;
    float lowest = 0.0f;
    for (int r = 0; st == LX_OK && r < rows; r++) {
        negative += job.negative[r];
        lowest = job.lowest[r] < lowest ? job.lowest[r] : lowest;
    }
    free(job.negative);
    free(job.lowest);
    if (st != LX_OK) {
        lx_cubemap_free(out);
        return st;
    }
    if (negative)
        lx_log(LX_LOG_WARN,
               "SH irradiance: %ld texel channels are negative (lowest %g lux): order-2 SH "
               "ringing around a strong, small light; left as computed",
               negative, (double)lowest);
    return LX_OK;
}
