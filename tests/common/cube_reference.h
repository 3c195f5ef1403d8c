/* ibl.h's cube map conventions written out again for the tests, so that
 * the inputs and expected values of the IBL and sky tests do not come from
 * the code under test: the face table (OpenGL's, ibl.h: face coordinates
 * sc, tc in [-1, 1] to a direction), texel centres, texel solid angles by a
 * midpoint rule of dA / (1 + a^2 + b^2)^(3/2), and environments built from
 * a function of the direction at every texel centre. */
#ifndef LX_TEST_CUBE_REFERENCE_H
#define LX_TEST_CUBE_REFERENCE_H

#include "luxel/ibl.h"

/* The direction through face coordinates sc, tc of face (0..5 = +X -X +Y
 * -Y +Z -Z), not normalised: the point on the cube of half-size 1. */
void lx_test_face_vec(int face, double sc, double tc, double v[3]);

/* The same direction, normalised. */
void lx_test_face_dir(int face, double sc, double tc, double d[3]);

/* The unit direction through the centre of texel (x, y), row 0 at the top,
 * of a size x size face. */
void lx_test_texel_dir(int face, int size, int x, int y, double d[3]);

/* The solid angle of texel (x, y) of a size x size face by an m x m
 * midpoint rule. */
double lx_test_texel_omega(int size, int x, int y, int m);

/* The 3 floats of texel (x, y) of face `face`, from lx_cubemap's documented
 * layout written out here (faces in lx_cube_face order, each size x size
 * texels, rows top to bottom, 3 floats a texel), not from
 * lx_cubemap_texel. */
float *lx_test_cube_texel(const lx_cubemap *c, int face, int x, int y);

/* The exact solid angle of texel (x, y) of a size x size face: the
 * rectangle [a0, a1] x [b0, b1] of the face at distance 1 subtends
 * S(a1, b1) - S(a0, b1) - S(a1, b0) + S(a0, b0) with
 * S(a, b) = atan2(a b, sqrt(a^2 + b^2 + 1)). */
double lx_test_texel_solid_angle(int size, int x, int y);

/* Radiance (3 channels) at unit direction (x, y, z). */
typedef void (*lx_test_env_fn)(double x, double y, double z, float out[3]);

/* A cube map whose every texel holds fn at its centre's direction; fails
 * the test when it cannot be allocated. Free with lx_cubemap_free. Its
 * memory comes from lx_cubemap_alloc (so that lx_cubemap_free releases
 * it), the only library call here; every value in it is written here. */
lx_cubemap lx_test_make_env(int size, lx_test_env_fn fn);

/* A progress callback's record for the IBL tests: how many calls, the
 * last fraction, whether the fractions never fell; the callback returns
 * false (cancel) at call number stop_after. */
typedef struct lx_test_progress {
    int calls, stop_after;
    float last;
    bool monotone;
} lx_test_progress;

/* A record that never cancels, or that cancels at call stop_after. */
lx_test_progress lx_test_progress_make(int stop_after);
/* An lx_progress_fn; user is an lx_test_progress. */
bool lx_test_progress_fn(void *user, float fraction);

/* A cube map holding value in every channel of every texel. */
lx_cubemap lx_test_constant_env(int size, float value);

#endif
