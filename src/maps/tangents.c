/* Per-vertex tangent frames from UV gradients: Lengyel, "Foundations of Game
 * Engine Development" vol. 2 ch. 7: each triangle's tangent and
 * bitangent are summed at its vertices, the tangent is made orthogonal to
 * the normal and the bitangent's side is kept as a handedness sign. */
#include "luxel/maps.h"
#include "core/internal.h"

#include <stdlib.h>
#include <string.h>

lx_status lx_compute_tangents(const lx_mesh *mesh, int uv_set, lx_vec4 *out)
{
    if (!mesh)
        return lx_fail_null(__func__, "mesh");
    if (!out)
        return lx_fail_null(__func__, "out");
    if (uv_set < 0 || uv_set >= LX_MAX_UV_SETS || !mesh->uv[uv_set])
        return lx_fail(LX_ERR_INVALID, "mesh '%s': no TEXCOORD_%d for tangents",
                       mesh->name ? mesh->name : "?", uv_set);
    uint32_t nv = mesh->vertex_count;
    lx_vec3 *acc = calloc((size_t)nv * 2, sizeof(lx_vec3));
    if (!acc)
        return lx_fail(LX_ERR_NOMEM, "mesh '%s': out of memory for tangents", mesh->name);
    lx_vec3 *tan = acc, *bitan = acc + nv;
    const lx_vec2 *uv = mesh->uv[uv_set];
    for (uint32_t t = 0; t < mesh->triangle_count; t++) {
        const uint32_t *idx = &mesh->indices[3 * t];
        lx_vec3 p0 = mesh->positions[idx[0]];
        lx_vec3 e1 = lx_sub(mesh->positions[idx[1]], p0);
        lx_vec3 e2 = lx_sub(mesh->positions[idx[2]], p0);
        float x1 = uv[idx[1]].x - uv[idx[0]].x, x2 = uv[idx[2]].x - uv[idx[0]].x;
        float y1 = uv[idx[1]].y - uv[idx[0]].y, y2 = uv[idx[2]].y - uv[idx[0]].y;
        float det = x1 * y2 - x2 * y1;
        if (!(fabsf(det) > 1e-20f))
            continue; /* no UV gradient: this triangle says nothing */
        float r = 1.0f / det;
        lx_vec3 dpdu = lx_scale(lx_sub(lx_scale(e1, y2), lx_scale(e2, y1)), r);
        lx_vec3 dpdv = lx_scale(lx_sub(lx_scale(e2, x1), lx_scale(e1, x2)), r);
        for (int k = 0; k < 3; k++) {
            tan[idx[k]] = lx_add(tan[idx[k]], dpdu);
            bitan[idx[k]] = lx_add(bitan[idx[k]], dpdv);
        }
    }
    for (uint32_t v = 0; v < nv; v++) {
        lx_vec3 n = mesh->normals[v];
        lx_vec3 t = lx_sub(tan[v], lx_scale(n, lx_dot(n, tan[v])));
        float len = lx_length(t);
        t = len > 1e-20f ? lx_scale(t, 1.0f / len) : lx_perpendicular(n);
        /* v grows downward in luxel's UVs, so "up" in the image is -dP/dv */
        float w = lx_dot(lx_cross(n, t), bitan[v]) > 0.0f ? -1.0f : 1.0f;
        out[v] = lx_v4(t.x, t.y, t.z, w);
    }
    free(acc);
    return LX_OK;
}

const char *lx_tangent_method_name(lx_tangent_method method)
{
    switch (method) {
    case LX_TANGENTS_MIKKTSPACE:
        return "mikktspace";
    case LX_TANGENTS_LENGYEL:
        return "lengyel";
    }
    return NULL;
}

bool lx_tangent_method_parse(const char *name, lx_tangent_method *out)
{
    for (int m = LX_TANGENTS_MIKKTSPACE; name && m <= LX_TANGENTS_LENGYEL; m++)
        if (strcmp(name, lx_tangent_method_name((lx_tangent_method)m)) == 0) {
            *out = (lx_tangent_method)m;
            return true;
        }
    return false;
}

lx_status lx_compute_corner_tangents(const lx_mesh *mesh, lx_tangent_method method, int uv_set,
                                     lx_vec4 *out)
{
    if (method == LX_TANGENTS_MIKKTSPACE)
        return lx_compute_tangents_mikktspace(mesh, uv_set, out);
    if (method != LX_TANGENTS_LENGYEL)
        return lx_fail(LX_ERR_INVALID, "lx_compute_corner_tangents: unknown method %d", method);
    if (!mesh->normals)
        return lx_fail(LX_ERR_INVALID, "mesh '%s': no normals for tangents",
                       mesh->name ? mesh->name : "?");
    lx_vec4 *per_vertex = malloc(sizeof(lx_vec4) * (mesh->vertex_count ? mesh->vertex_count : 1));
    if (!per_vertex)
        return lx_fail(LX_ERR_NOMEM, "mesh '%s': out of memory for tangents",
                       mesh->name ? mesh->name : "?");
    lx_status st = lx_compute_tangents(mesh, uv_set, per_vertex);
    for (size_t k = 0; st == LX_OK && k < 3 * (size_t)mesh->triangle_count; k++)
        out[k] = per_vertex[mesh->indices[k]];
    free(per_vertex);
    return st;
}

lx_vec3 lx_tangent_to_world(lx_vec3 m, lx_vec3 n, lx_vec4 t)
{
    lx_vec3 tt = lx_v3(t.x, t.y, t.z);
    tt = lx_normalize(lx_sub(tt, lx_scale(n, lx_dot(n, tt))));
    lx_vec3 b = lx_scale(lx_cross(n, tt), t.w);
    lx_vec3 r = lx_add(lx_add(lx_scale(tt, m.x), lx_scale(b, m.y)), lx_scale(n, m.z));
    float len = lx_length(r);
    return len > 1e-20f ? lx_scale(r, 1.0f / len) : n;
}
