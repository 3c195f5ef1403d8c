/* UV seams (lx_uv_seams): manifold edges of the welded mesh whose two
 * triangles give their shared ends different UVs. */
#include "unwrap_internal.h"
#include "core/internal.h"

#include <stdlib.h>
#include <string.h>

static bool same_uv(lx_vec2 a, lx_vec2 b)
{
    return a.x == b.x && a.y == b.y;
}

lx_status lx_uv_seams(const lx_mesh *mesh, int uv_set, lx_uv_seam **out, uint32_t *count)
{
    if (!mesh)
        return lx_fail_null(__func__, "mesh");
    if (!out)
        return lx_fail_null(__func__, "out");
    if (!count)
        return lx_fail_null(__func__, "count");
    *out = NULL;
    *count = 0;
    if (uv_set < 0 || uv_set >= LX_MAX_UV_SETS || !mesh->uv[uv_set])
        return lx_fail(LX_ERR_INVALID, "mesh '%s' has no TEXCOORD_%d", mesh->name, uv_set);
    const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    uw_mesh m;
    lx_status st = uw_mesh_build(mesh, identity, &m);
    if (st != LX_OK)
        return st;
    const lx_vec2 *uv = mesh->uv[uv_set];
    const uint32_t *idx = mesh->indices;
    uint32_t n = 0, cap = 0;
    lx_uv_seam *seams = NULL;
    for (uint32_t t = 0; t < m.triangle_count; t++) {
        if (m.degenerate[t])
            continue;
        for (int k = 0; k < 3; k++) {
            uint32_t o = m.adjacent[3 * t + k];
            if (o == UW_NONE || o < t || m.degenerate[o])
                continue; /* a border, or listed from the other side */
            uint32_t a0 = idx[3 * t + k], a1 = idx[3 * t + (k + 1) % 3];
            /* the other triangle's corners at the same two places */
            uint32_t b0 = UW_NONE, b1 = UW_NONE;
            for (int j = 0; j < 3; j++) {
                uint32_t v = idx[3 * o + j];
                if (m.weld[v] == m.weld[a0])
                    b0 = v;
                else if (m.weld[v] == m.weld[a1])
                    b1 = v;
            }
            if (b0 == UW_NONE || b1 == UW_NONE)
                continue;
            if (same_uv(uv[a0], uv[b0]) && same_uv(uv[a1], uv[b1]))
                continue;
            if (n == cap) {
                cap = cap ? 2 * cap : 64;
                lx_uv_seam *grown = realloc(seams, sizeof *seams * cap);
                if (!grown) {
                    free(seams);
                    uw_mesh_free(&m);
                    return lx_fail(LX_ERR_NOMEM, "out of memory listing the seams of mesh '%s'",
                                   mesh->name);
                }
                seams = grown;
            }
            seams[n++] = (lx_uv_seam){.a = {uv[a0], uv[a1]},
                                      .b = {uv[b0], uv[b1]},
                                      .triangle_a = t,
                                      .triangle_b = o};
        }
    }
    uw_mesh_free(&m);
    *out = seams;
    *count = n;
    return LX_OK;
}
