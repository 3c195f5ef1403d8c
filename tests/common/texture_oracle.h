/* Independent texture arithmetic for tests, in double and from the
 * published definitions, never from luxel's own functions: the sRGB
 * transfer function (IEC 61966-2-1), bilinear filtering with glTF's REPEAT
 * wrap and texel centres at (x + 0.5) / W, KHR_texture_transform's matrix
 * (translation * rotation * scale, as the extension spec writes it), and
 * planar quads whose positions and UV sets are affine in (s, t). */
#ifndef LX_TEST_TEXTURE_ORACLE_H
#define LX_TEST_TEXTURE_ORACLE_H

#include <stdbool.h>
#include <stdint.h>

/* Linear value of an 8-bit sRGB code. */
double lx_test_srgb_decode(int code);
/* sRGB-encoded value of a linear one in [0, 1] (clamped). */
double lx_test_srgb_encode(double linear);

/* A bilinear REPEAT sample at (u, v) of w x h texels of `channels` doubles
 * each (row 0 at the top). */
void lx_test_bilinear(const double *texels, int w, int h, int channels, double u, double v,
                      double *out);

/* A w x w normal-map gradient (so a flipped V or swapped channels fail):
 * texel (x, y) holds the 8-bit codes (40 + 24 x, 60 + 20 y, blue0 +
 * blue_step (x + y)), px as bytes and raw as code / 255. */
void lx_test_gradient_normal_map(int w, int blue0, int blue_step, uint8_t *px, double *raw);

/* uv' = M (u, v, 1) with M = translation(offset) * rotation(rotation) *
 * scale(scale), the 3x3 matrices of the KHR_texture_transform spec
 * multiplied out as written. */
void lx_test_texture_transform(const double offset[2], double rotation, const double scale[2],
                               double u, double v, double out[2]);

/* A planar quad P(s, t) = o + s e1 + t e2 over s, t in [0, 1] with up to
 * two UV sets, each affine: uv = a + s b + t c (uv[k] = {a, b, c}). */
typedef struct lx_test_quad {
    double o[3], e1[3], e2[3];
    double uv[2][3][2];
} lx_test_quad;

void lx_test_quad_point(const lx_test_quad *q, double s, double t, double p[3]);
void lx_test_quad_uv(const lx_test_quad *q, int set, double s, double t, double uv[2]);
/* (s, t) where UV set `set` takes (u, v); false if the set is degenerate. */
bool lx_test_quad_st(const lx_test_quad *q, int set, double u, double v, double *s, double *t);
/* The quad as two triangles for a glTF file: corners (s, t) = (0,0),
 * (1,0), (1,1), (0,1), normals n = normalize(e1 x e2), indices wound
 * counter-clockwise around n. */
void lx_test_quad_arrays(const lx_test_quad *q, float pos[12], float nrm[12], float uv0[8],
                         float uv1[8], uint32_t idx[6]);

#endif
