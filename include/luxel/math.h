/* luxel/math.h - small vector and matrix types shared by every module.
 *
 * CONVENTIONS  Right-handed, +Y up, metres. lx_mat4 is column-major like
 *   glTF: m[col*4 + row]; points transform as M * (x, y, z, 1).
 * ERRORS / MEMORY  None: plain values, header-only inline functions.
 * THREADING  Every function is thread-safe (pure, inline).
 *
 * USAGE
 *   lx_vec3 a = lx_v3(0, 0, 0), b = lx_v3(1, 0, 0), c = lx_v3(0, 0, -1);
 *   lx_vec3 n = lx_normalize(lx_cross(lx_sub(b, a), lx_sub(c, a)));   // (0, 1, 0)
 *   lx_mat4 m = lx_mat4_translate(lx_v3(0, 2, 0));
 *   lx_vec3 p = lx_mat4_point(&m, a);
 *   printf("normal (%g, %g, %g), moved %g m\n", n.x, n.y, n.z, lx_length(lx_sub(p, a)));
 */
#ifndef LUXEL_MATH_H
#define LUXEL_MATH_H

#include <math.h>
#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LX_PI 3.14159265358979323846f
#define LX_DEG2RAD(d) ((d) * (LX_PI / 180.0f))
#define LX_RAD2DEG(r) ((r) * (180.0f / LX_PI))

typedef struct lx_vec2 {
    float x, y;
} lx_vec2;
typedef struct lx_vec3 {
    float x, y, z;
} lx_vec3;
typedef struct lx_vec4 {
    float x, y, z, w;
} lx_vec4;
typedef struct lx_mat4 {
    float m[16];
} lx_mat4;

static inline lx_vec2 lx_v2(float x, float y)
{
    lx_vec2 r = {x, y};
    return r;
}
static inline lx_vec3 lx_v3(float x, float y, float z)
{
    lx_vec3 r = {x, y, z};
    return r;
}
static inline lx_vec4 lx_v4(float x, float y, float z, float w)
{
    lx_vec4 r = {x, y, z, w};
    return r;
}

static inline lx_vec3 lx_add(lx_vec3 a, lx_vec3 b)
{
    return lx_v3(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline lx_vec3 lx_sub(lx_vec3 a, lx_vec3 b)
{
    return lx_v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline lx_vec3 lx_mul(lx_vec3 a, lx_vec3 b)
{
    return lx_v3(a.x * b.x, a.y * b.y, a.z * b.z);
}
static inline lx_vec3 lx_scale(lx_vec3 a, float s)
{
    return lx_v3(a.x * s, a.y * s, a.z * s);
}
static inline lx_vec3 lx_neg(lx_vec3 a)
{
    return lx_v3(-a.x, -a.y, -a.z);
}
static inline float lx_dot(lx_vec3 a, lx_vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static inline lx_vec3 lx_cross(lx_vec3 a, lx_vec3 b)
{
    return lx_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float lx_length(lx_vec3 a)
{
    return sqrtf(lx_dot(a, a));
}
static inline lx_vec3 lx_normalize(lx_vec3 a)
{
    float len = lx_length(a);
    return len > 0.0f ? lx_scale(a, 1.0f / len) : a;
}
/* a + b*s */
static inline lx_vec3 lx_madd(lx_vec3 a, lx_vec3 b, float s)
{
    return lx_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
static inline float lx_max_component(lx_vec3 a)
{
    float m = a.x > a.y ? a.x : a.y;
    return m > a.z ? m : a.z;
}
static inline float lx_max_abs_component(lx_vec3 a)
{
    float x = fabsf(a.x), y = fabsf(a.y), z = fabsf(a.z);
    float m = x > y ? x : y;
    return m > z ? m : z;
}
static inline bool lx_vec3_finite(lx_vec3 a)
{
    return isfinite(a.x) && isfinite(a.y) && isfinite(a.z);
}
static inline float lx_clampf(float x, float lo, float hi)
{
    return x < lo ? lo : (x > hi ? hi : x);
}
static inline float lx_saturate(float x)
{
    return lx_clampf(x, 0.0f, 1.0f);
}

/* Luminance (Y) of linear Rec.709/sRGB primaries, ITU-R BT.709's weights;
 * in double, for the sums that accumulate it. */
static inline double lx_luminance(const float rgb[3])
{
    return 0.2126 * (double)rgb[0] + 0.7152 * (double)rgb[1] + 0.0722 * (double)rgb[2];
}

/* lx_luminance of a vector's three components as R, G, B. */
static inline double lx_luminance3(lx_vec3 v)
{
    return 0.2126 * (double)v.x + 0.7152 * (double)v.y + 0.0722 * (double)v.z;
}

/* Any unit vector perpendicular to n (n must be unit length). */
static inline lx_vec3 lx_perpendicular(lx_vec3 n)
{
    lx_vec3 a = fabsf(n.x) < 0.9f ? lx_v3(1, 0, 0) : lx_v3(0, 1, 0);
    return lx_normalize(lx_cross(n, a));
}

static inline lx_mat4 lx_mat4_identity(void)
{
    lx_mat4 r = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}};
    return r;
}
static inline lx_mat4 lx_mat4_mul(const lx_mat4 *a, const lx_mat4 *b)
{
    lx_mat4 r;
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            float s = 0.0f;
            for (int k = 0; k < 4; k++)
                s += a->m[k * 4 + row] * b->m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}
static inline lx_mat4 lx_mat4_translate(lx_vec3 t)
{
    lx_mat4 r = lx_mat4_identity();
    r.m[12] = t.x;
    r.m[13] = t.y;
    r.m[14] = t.z;
    return r;
}
/* Rotation by a unit quaternion (x, y, z, w), as glTF stores them. */
static inline lx_mat4 lx_mat4_from_quat(lx_vec4 q)
{
    float x = q.x, y = q.y, z = q.z, w = q.w;
    lx_mat4 r = lx_mat4_identity();
    r.m[0] = 1 - 2 * (y * y + z * z);
    r.m[1] = 2 * (x * y + z * w);
    r.m[2] = 2 * (x * z - y * w);
    r.m[4] = 2 * (x * y - z * w);
    r.m[5] = 1 - 2 * (x * x + z * z);
    r.m[6] = 2 * (y * z + x * w);
    r.m[8] = 2 * (x * z + y * w);
    r.m[9] = 2 * (y * z - x * w);
    r.m[10] = 1 - 2 * (x * x + y * y);
    return r;
}
/* T * R * S, glTF's node transform order. */
static inline lx_mat4 lx_mat4_trs(lx_vec3 t, lx_vec4 q, lx_vec3 s)
{
    lx_mat4 r = lx_mat4_from_quat(q);
    for (int row = 0; row < 3; row++) {
        r.m[0 + row] *= s.x;
        r.m[4 + row] *= s.y;
        r.m[8 + row] *= s.z;
    }
    r.m[12] = t.x;
    r.m[13] = t.y;
    r.m[14] = t.z;
    return r;
}
static inline lx_vec3 lx_mat4_point(const lx_mat4 *m, lx_vec3 p)
{
    return lx_v3(m->m[0] * p.x + m->m[4] * p.y + m->m[8] * p.z + m->m[12],
                 m->m[1] * p.x + m->m[5] * p.y + m->m[9] * p.z + m->m[13],
                 m->m[2] * p.x + m->m[6] * p.y + m->m[10] * p.z + m->m[14]);
}
static inline lx_vec3 lx_mat4_vector(const lx_mat4 *m, lx_vec3 v)
{
    return lx_v3(m->m[0] * v.x + m->m[4] * v.y + m->m[8] * v.z,
                 m->m[1] * v.x + m->m[5] * v.y + m->m[9] * v.z,
                 m->m[2] * v.x + m->m[6] * v.y + m->m[10] * v.z);
}
/* Determinant of the upper 3x3 part. */
static inline float lx_mat4_det3(const lx_mat4 *m)
{
    const float *a = m->m;
    return a[0] * (a[5] * a[10] - a[9] * a[6]) - a[4] * (a[1] * a[10] - a[9] * a[2]) +
           a[8] * (a[1] * a[6] - a[5] * a[2]);
}
/* Normal matrix: the inverse transpose of the upper 3x3, up to a positive
 * scale, as an lx_mat4 with no translation; false when the matrix is
 * singular. Transform normals with lx_mat4_vector and renormalize. */
static inline bool lx_mat4_normal_matrix(const lx_mat4 *m, lx_mat4 *out)
{
    float a[11];
    for (int i = 0; i < 11; i++)
        a[i] = m->m[i];
    float det = lx_mat4_det3(m);
    if (!isfinite(det) || !(fabsf(det) > 1e-30f)) {
        /* a very large or small scale: rescale to a largest element of 1,
         * which keeps the direction of every normal */
        float s = 0.0f;
        for (int i = 0; i < 11; i++)
            s = fmaxf(s, fabsf(a[i]));
        if (!(s > 0.0f) || !isfinite(s))
            return false;
        lx_mat4 scaled = lx_mat4_identity();
        for (int i = 0; i < 11; i++)
            scaled.m[i] = a[i] = a[i] / s;
        det = lx_mat4_det3(&scaled);
        if (!(fabsf(det) > 1e-30f))
            return false;
    }
    float inv = 1.0f / det;
    /* cofactor matrix / det = inverse transpose */
    lx_mat4 r = lx_mat4_identity();
    r.m[0] = (a[5] * a[10] - a[6] * a[9]) * inv;
    r.m[1] = (a[6] * a[8] - a[4] * a[10]) * inv;
    r.m[2] = (a[4] * a[9] - a[5] * a[8]) * inv;
    r.m[4] = (a[2] * a[9] - a[1] * a[10]) * inv;
    r.m[5] = (a[0] * a[10] - a[2] * a[8]) * inv;
    r.m[6] = (a[1] * a[8] - a[0] * a[9]) * inv;
    r.m[8] = (a[1] * a[6] - a[2] * a[5]) * inv;
    r.m[9] = (a[2] * a[4] - a[0] * a[6]) * inv;
    r.m[10] = (a[0] * a[5] - a[1] * a[4]) * inv;
    *out = r;
    return true;
}
static inline bool lx_mat4_finite(const lx_mat4 *m)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m->m[i]))
            return false;
    return true;
}

#ifdef __cplusplus
}
#endif
#endif
