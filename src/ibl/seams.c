/* Cube map seam fixing after the seed "Cg Programming/Unity/Many Light
 * Sources" (Wikibooks; /work/shared/seeds/004): texels along a cube edge
 * take the mean of themselves and their neighbour across the edge, and the
 * three texels that meet at a cube corner take their common mean, so an
 * engine that filters each face on its own sees no seam.
 *
 * The seed's tables are used as published (its getDirection() is the face
 * table of luxel/ibl.h with i = x, j = y), with one change: the seed's edge
 * loop also averages the corner texels pairwise before the corner pass
 * overwrites them; here corner texels are only averaged with the other two
 * corner texels, from their original values. Edge and corner texels form
 * disjoint sets, so the fix works in place and in any order. */
#include "luxel/ibl.h"

/* A coordinate along an edge as a function of the edge index i. */
enum { C0, CMAX, CI, CMAX_I };

static const unsigned char edges[12][6] = {
    /* face a, x, y   face b, x, y  (the seed's setFaceAverage calls) */
    {LX_FACE_PX, CI, C0, LX_FACE_PY, CMAX, CMAX_I},
    {LX_FACE_PX, C0, CI, LX_FACE_PZ, CMAX, CI},
    {LX_FACE_PX, CI, CMAX, LX_FACE_NY, CMAX, CI},
    {LX_FACE_PX, CMAX, CI, LX_FACE_NZ, C0, CI},
    {LX_FACE_NX, CI, C0, LX_FACE_PY, C0, CI},
    {LX_FACE_NX, C0, CI, LX_FACE_NZ, CMAX, CI},
    {LX_FACE_NX, CI, CMAX, LX_FACE_NY, C0, CMAX_I},
    {LX_FACE_NX, CMAX, CI, LX_FACE_PZ, C0, CI},
    {LX_FACE_PY, CI, C0, LX_FACE_NZ, CMAX_I, C0},
    {LX_FACE_PY, CI, CMAX, LX_FACE_PZ, CI, C0},
    {LX_FACE_NY, CI, C0, LX_FACE_PZ, CI, CMAX},
    {LX_FACE_NY, CI, CMAX, LX_FACE_NZ, CMAX_I, CMAX},
};

static const unsigned char corners[8][9] = {
    /* three (face, x, y) with 0 = first and 1 = last texel (setCornerAverage) */
    {LX_FACE_PX, 0, 0, LX_FACE_PY, 1, 1, LX_FACE_PZ, 1, 0},
    {LX_FACE_PX, 1, 0, LX_FACE_PY, 1, 0, LX_FACE_NZ, 0, 0},
    {LX_FACE_PX, 0, 1, LX_FACE_NY, 1, 0, LX_FACE_PZ, 1, 1},
    {LX_FACE_PX, 1, 1, LX_FACE_NY, 1, 1, LX_FACE_NZ, 0, 1},
    {LX_FACE_NX, 0, 0, LX_FACE_PY, 0, 0, LX_FACE_NZ, 1, 0},
    {LX_FACE_NX, 1, 0, LX_FACE_PY, 0, 1, LX_FACE_PZ, 0, 0},
    {LX_FACE_NX, 0, 1, LX_FACE_NY, 0, 1, LX_FACE_NZ, 1, 1},
    {LX_FACE_NX, 1, 1, LX_FACE_NY, 0, 0, LX_FACE_PZ, 0, 1},
};

static int coord(int code, int i, int max)
{
    switch (code) {
    case C0:
        return 0;
    case CMAX:
        return max;
    case CI:
        return i;
    default:
        return max - i;
    }
}

void lx_cubemap_fix_seams(lx_cubemap *c)
{
    if (!c || !c->data || c->size < 1)
        return;
    int max = c->size - 1;
    if (c->size == 1) {
        /* every face touches the other four: all six must agree */
        float mean[3] = {0, 0, 0};
        for (int f = 0; f < 6; f++)
            for (int k = 0; k < 3; k++)
                mean[k] += lx_cubemap_texel(c, f, 0, 0)[k];
        for (int f = 0; f < 6; f++)
            for (int k = 0; k < 3; k++)
                lx_cubemap_texel(c, f, 0, 0)[k] = mean[k] / 6.0f;
        return;
    }
    for (int e = 0; e < 12; e++) {
        const unsigned char *t = edges[e];
        for (int i = 1; i < max; i++) {
            float *a = lx_cubemap_texel(c, t[0], coord(t[1], i, max), coord(t[2], i, max));
            float *b = lx_cubemap_texel(c, t[3], coord(t[4], i, max), coord(t[5], i, max));
            for (int k = 0; k < 3; k++) {
                float m = 0.5f * (a[k] + b[k]);
                a[k] = m;
                b[k] = m;
            }
        }
    }
    for (int n = 0; n < 8; n++) {
        const unsigned char *t = corners[n];
        float *p[3];
        for (int j = 0; j < 3; j++)
            p[j] = lx_cubemap_texel(c, t[3 * j], t[3 * j + 1] * max, t[3 * j + 2] * max);
        for (int k = 0; k < 3; k++) {
            float m = (p[0][k] + p[1][k] + p[2][k]) / 3.0f;
            p[0][k] = p[1][k] = p[2][k] = m;
        }
    }
}
