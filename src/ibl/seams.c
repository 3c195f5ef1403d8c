/* Cube map seam fixing after the seed "Cg Programming/Unity/Many Light
 * Sources" (Wikibooks): texels along a cube edge take the mean of
 * themselves and their neighbour across the edge, and the three texels
 * that meet at a cube corner take their common mean, so an engine that
 * filters each face on its own sees no seam.
 *
 * The seed lists the twelve edges and eight corners in tables; here the
 * neighbour across an edge is the texel lx_cubemap_sample takes there
 * (lx_ibl_texel_across), which pairs the same texels. One change from the
 * seed: its edge loop also averages the corner texels pairwise before the
 * corner pass overwrites them; here corner texels are only averaged with
 * the other two corner texels, from their original values. Edge and
 * corner texels form disjoint sets and each pair (each triple) is visited
 * once, from its lowest face, so the fix works in place. */
#include "ibl_internal.h"

void lx_cubemap_fix_seams(lx_cubemap *c)
{
    if (!c || !c->data || c->size < 1)
        return;
    int n = c->size, max = n - 1;
    if (n == 1) {
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
    /* the four edges of each face: texel (x, y) along it and the step out */
    for (int f = 0; f < 6; f++)
        for (int e = 0; e < 4; e++)
            for (int i = 1; i < max; i++) {
                int x = e == 0 ? i : e == 1 ? max : e == 2 ? i : 0;
                int y = e == 0 ? 0 : e == 1 ? i : e == 2 ? max : i;
                int dx = e == 1 ? 1 : e == 3 ? -1 : 0, dy = e == 0 ? -1 : e == 2 ? 1 : 0;
                int g, gx, gy;
                lx_ibl_texel_across(n, f, x + dx, y + dy, &g, &gx, &gy);
                if (g < f)
                    continue; /* done from face g */
                float *a = lx_cubemap_texel(c, f, x, y), *b = lx_cubemap_texel(c, g, gx, gy);
                for (int k = 0; k < 3; k++) {
                    float m = 0.5f * (a[k] + b[k]);
                    a[k] = m;
                    b[k] = m;
                }
            }
    /* the corners: each face's four, with the two across its two edges */
    for (int f = 0; f < 6; f++)
        for (int corner = 0; corner < 4; corner++) {
            int x = corner & 1 ? max : 0, y = corner & 2 ? max : 0;
            int g[3] = {f}, gx[3] = {x}, gy[3] = {y};
            lx_ibl_texel_across(n, f, x ? n : -1, y, &g[1], &gx[1], &gy[1]);
            lx_ibl_texel_across(n, f, x, y ? n : -1, &g[2], &gx[2], &gy[2]);
            if (g[1] < f || g[2] < f)
                continue; /* done from a lower face */
            float *p[3];
            for (int j = 0; j < 3; j++)
                p[j] = lx_cubemap_texel(c, g[j], gx[j], gy[j]);
            for (int k = 0; k < 3; k++) {
                float m = (p[0][k] + p[1][k] + p[2][k]) / 3.0f;
                p[0][k] = p[1][k] = p[2][k] = m;
            }
        }
}
