/* Independent texture arithmetic for tests (see texture_oracle.h). */
#include "texture_oracle.h"

#include <math.h>
#include <stddef.h>

double lx_test_srgb_decode(int code)
{
    double c = code / 255.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

double lx_test_srgb_encode(double v)
{
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static int wrap(long i, int n)
{
    long r = i % n;
    return (int)(r < 0 ? r + n : r);
}

void lx_test_bilinear(const double *texels, int w, int h, int channels, double u, double v,
                      double *out)
{
    double x = u * w - 0.5, y = v * h - 0.5;
    double fx = floor(x), fy = floor(y);
    double tx = x - fx, ty = y - fy;
    int c0 = wrap((long)fx, w), c1 = wrap((long)fx + 1, w);
    int r0 = wrap((long)fy, h), r1 = wrap((long)fy + 1, h);
    for (int c = 0; c < channels; c++) {
        double a = texels[((size_t)r0 * w + c0) * channels + c];
        double b = texels[((size_t)r0 * w + c1) * channels + c];
        double d = texels[((size_t)r1 * w + c0) * channels + c];
        double e = texels[((size_t)r1 * w + c1) * channels + c];
        out[c] = (1 - ty) * ((1 - tx) * a + tx * b) + ty * ((1 - tx) * d + tx * e);
    }
}

/* 3x3 matrices column-major as GLSL's mat3(...) constructor fills them. */
static void mat3_mul(const double a[9], const double b[9], double out[9])
{
    for (int col = 0; col < 3; col++)
        for (int row = 0; row < 3; row++) {
            double s = 0;
            for (int k = 0; k < 3; k++)
                s += a[k * 3 + row] * b[col * 3 + k];
            out[col * 3 + row] = s;
        }
}

void lx_test_texture_transform(const double offset[2], double rotation, const double scale[2],
                               double u, double v, double out[2])
{
    /* the spec's GLSL: mat3(1,0,0, 0,1,0, Offset.x,Offset.y,1),
     * mat3(cos,sin,0, -sin,cos,0, 0,0,1), mat3(Scale.x,0,0, 0,Scale.y,0, 0,0,1) */
    const double tr[9] = {1, 0, 0, 0, 1, 0, offset[0], offset[1], 1};
    const double c = cos(rotation), s = sin(rotation);
    const double rot[9] = {c, s, 0, -s, c, 0, 0, 0, 1};
    const double sc[9] = {scale[0], 0, 0, 0, scale[1], 0, 0, 0, 1};
    double tmp[9], m[9];
    mat3_mul(tr, rot, tmp);
    mat3_mul(tmp, sc, m);
    const double in[3] = {u, v, 1};
    for (int row = 0; row < 2; row++)
        out[row] = m[0 * 3 + row] * in[0] + m[1 * 3 + row] * in[1] + m[2 * 3 + row] * in[2];
}

void lx_test_quad_point(const lx_test_quad *q, double s, double t, double p[3])
{
    for (int k = 0; k < 3; k++)
        p[k] = q->o[k] + s * q->e1[k] + t * q->e2[k];
}

void lx_test_quad_uv(const lx_test_quad *q, int set, double s, double t, double uv[2])
{
    for (int k = 0; k < 2; k++)
        uv[k] = q->uv[set][0][k] + s * q->uv[set][1][k] + t * q->uv[set][2][k];
}

bool lx_test_quad_st(const lx_test_quad *q, int set, double u, double v, double *s, double *t)
{
    const double(*m)[2] = q->uv[set];
    double det = m[1][0] * m[2][1] - m[2][0] * m[1][1];
    if (det == 0)
        return false;
    double du = u - m[0][0], dv = v - m[0][1];
    *s = (du * m[2][1] - m[2][0] * dv) / det;
    *t = (m[1][0] * dv - du * m[1][1]) / det;
    return true;
}

void lx_test_quad_arrays(const lx_test_quad *q, float pos[12], float nrm[12], float uv0[8],
                         float uv1[8], uint32_t idx[6])
{
    static const double corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    double n[3] = {q->e1[1] * q->e2[2] - q->e1[2] * q->e2[1],
                   q->e1[2] * q->e2[0] - q->e1[0] * q->e2[2],
                   q->e1[0] * q->e2[1] - q->e1[1] * q->e2[0]};
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int i = 0; i < 4; i++) {
        double p[3], uv[2];
        lx_test_quad_point(q, corner[i][0], corner[i][1], p);
        for (int k = 0; k < 3; k++) {
            pos[3 * i + k] = (float)p[k];
            nrm[3 * i + k] = (float)(n[k] / len);
        }
        lx_test_quad_uv(q, 0, corner[i][0], corner[i][1], uv);
        uv0[2 * i] = (float)uv[0];
        uv0[2 * i + 1] = (float)uv[1];
        lx_test_quad_uv(q, 1, corner[i][0], corner[i][1], uv);
        uv1[2 * i] = (float)uv[0];
        uv1[2 * i + 1] = (float)uv[1];
    }
    /* e1 x e2 = n: (0,0) -> (1,0) -> (1,1) is counter-clockwise around n */
    const uint32_t tri[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; k++)
        idx[k] = tri[k];
}

void lx_test_gradient_normal_map(int w, int blue0, int blue_step, uint8_t *px, double *raw)
{
    for (int y = 0; y < w; y++)
        for (int x = 0; x < w; x++) {
            const int v[3] = {40 + 24 * x, 60 + 20 * y, blue0 + blue_step * (x + y)};
            for (int c = 0; c < 3; c++) {
                px[(y * w + x) * 3 + c] = (uint8_t)v[c];
                raw[(y * w + x) * 3 + c] = v[c] / 255.0;
            }
        }
}
