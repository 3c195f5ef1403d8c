/* The horizon map's shading side: Lengyel's GenerateHorizonCube and
 * ApplyHorizonMap (FGED vol. 2 sec. 7.8, eq. 7.58; seed
 * 002_26369eb9c57a642b.txt).
 *
 * A tangent-space light direction l at azimuth phi (counter-clockwise from
 * +x, y up the image) lies between two of the horizon map's eight
 * directions, k = floor(phi / 45 deg) and k + 1; its horizon sine is
 * interpolated linearly between theirs, with weights 1 - f and f (f the
 * fraction of the way from k to k + 1). Directions 0..3 are layer 0's
 * channels R, G, B, A and 4..7 layer 1's, so the two weights always fall
 * in different channels and one signed RGBA value holds both: positive
 * for layer 0, negative for layer 1. The cube map stores that value for
 * every direction so a shader gets it with one fetch; the seed's is 16 x 16
 * per face, here any size, texel centres at (2 (i + 1/2) / size - 1). */
#include "luxel/maps.h"
#include "core/internal.h"

#include <math.h>

#define HZ_PI 3.14159265358979323846
#include <string.h>

void lx_horizon_weights(lx_vec3 dir, float w[4])
{
    w[0] = w[1] = w[2] = w[3] = 0.0f;
    double t = atan2((double)dir.y, (double)dir.x) / (HZ_PI / 4.0); /* (-4, 4] */
    if (t < 0.0)
        t += 8.0;
    int k = (int)floor(t);
    double f = t - (double)k;
    k &= 7;
    int k1 = (k + 1) & 7;
    w[k & 3] = (float)((k < 4 ? 1.0 : -1.0) * (1.0 - f));
    w[k1 & 3] = (float)((k1 < 4 ? 1.0 : -1.0) * f);
}

/* The direction through texel centre (x, y) in [-1, 1]^2 of a face, in the
 * OpenGL cube map convention (y down the face). */
static lx_vec3 face_dir(int face, float x, float y)
{
    switch (face) {
    case 0: return lx_v3(1.0f, -y, -x);
    case 1: return lx_v3(-1.0f, -y, x);
    case 2: return lx_v3(x, 1.0f, y);
    case 3: return lx_v3(x, -1.0f, -y);
    case 4: return lx_v3(x, -y, 1.0f);
    default: return lx_v3(-x, -y, -1.0f);
    }
}

lx_status lx_horizon_weight_cube(int size, lx_image *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    if (size < 1 || size > 4096)
        return lx_fail(LX_ERR_INVALID, "horizon weight cube: size %d is not from 1 to 4096", size);
    lx_status st = lx_image_alloc(out, size, 6 * size, 4);
    if (st != LX_OK)
        return st;
    for (int face = 0; face < 6; face++)
        for (int j = 0; j < size; j++)
            for (int i = 0; i < size; i++) {
                float x = 2.0f * ((float)i + 0.5f) / (float)size - 1.0f;
                float y = 2.0f * ((float)j + 0.5f) / (float)size - 1.0f;
                float *px = out->data + (((size_t)face * (size_t)size + (size_t)j) * (size_t)size +
                                         (size_t)i) * 4;
                lx_horizon_weights(face_dir(face, x, y), px);
            }
    return LX_OK;
}

float lx_horizon_light(const float h0[4], const float h1[4], lx_vec3 l, float hardness)
{
    if (!(hardness > 0.0f))
        hardness = 8.0f;
    float w[4];
    lx_horizon_weights(l, w);
    float s = 0.0f;
    for (int c = 0; c < 4; c++)
        s += w[c] > 0.0f ? w[c] * h0[c] : -w[c] * h1[c];
    float f = (l.z - s) * hardness + 1.0f;
    return f < 0.0f ? 0.0f : f > 1.0f ? 1.0f : f;
}
