/* A material's values at a point of a mesh (maps.h, "MATERIALS AT A
 * POINT"): the one reading of a glTF material's textures, shared by the
 * baker (texel centres) and the renderer (ray hits). */
#include "luxel/maps.h"

const lx_material *lx_mesh_material(const lx_scene *scene, const lx_mesh *m)
{
    static const lx_material white = {
        .name = "default", .base_color = {1, 1, 1, 1}, .normal_scale = 1.0f};
    return m->material < scene->material_count ? &scene->materials[m->material] : &white;
}

lx_vec3 lx_material_emission(const lx_material *mat, float scale)
{
    return lx_scale(mat->emissive, scale);
}

/* A UV set's coordinates at the point, moved by a texture's transform. */
static lx_vec2 uv_at(const lx_vec2 *uv, const lx_uv_transform *transform, const uint32_t *i,
                     float w0, float w1, float w2)
{
    float u = uv[i[0]].x * w0 + uv[i[1]].x * w1 + uv[i[2]].x * w2;
    float v = uv[i[0]].y * w0 + uv[i[1]].y * w1 + uv[i[2]].y * w2;
    return lx_uv_transform_apply(transform, lx_v2(u, v));
}

/* The mesh's UV set `set`, or NULL when it has none. */
static const lx_vec2 *uv_set(const lx_mesh *m, int set)
{
    return set >= 0 && set < LX_MAX_UV_SETS ? m->uv[set] : NULL;
}

lx_vec3 lx_material_albedo_at(const lx_material *mat, const lx_mesh *m, const uint32_t *i, float w0,
                              float w1, float w2)
{
    lx_vec3 a = lx_v3(mat->base_color.x, mat->base_color.y, mat->base_color.z);
    const lx_vec2 *uv = uv_set(m, mat->base_color_uv_set);
    if (mat->base_color_map.width > 0 && uv) {
        lx_vec2 at = uv_at(uv, &mat->base_color_transform, i, w0, w1, w2);
        float c[4] = {1, 1, 1, 1};
        lx_image_sample_bilinear(&mat->base_color_map, at.x, at.y, c);
        a = lx_mul(a, lx_v3(c[0], c[1], c[2]));
    }
    return a;
}

lx_vec3 lx_material_emission_at(const lx_material *mat, const lx_mesh *m, const uint32_t *i,
                                float w0, float w1, float w2, float scale)
{
    lx_vec3 e = lx_material_emission(mat, scale);
    const lx_vec2 *uv = uv_set(m, mat->emissive_uv_set);
    if (mat->emissive_map.width > 0 && uv && (e.x > 0.0f || e.y > 0.0f || e.z > 0.0f)) {
        lx_vec2 at = uv_at(uv, &mat->emissive_transform, i, w0, w1, w2);
        float c[4] = {1, 1, 1, 1};
        lx_image_sample_bilinear(&mat->emissive_map, at.x, at.y, c);
        e = lx_mul(e, lx_v3(c[0], c[1], c[2]));
    }
    return e;
}

void lx_material_normal_at(const lx_material *mat, const lx_mesh *m, const lx_vec4 *tangents,
                           const uint32_t *i, float w0, float w1, float w2, lx_vec3 *normal)
{
    const lx_vec2 *uv = uv_set(m, mat->normal_uv_set);
    if (!uv)
        return;
    /* KHR_texture_transform moves where the map is read; the tangent frame
     * stays the UV set's own (scene.h) */
    lx_vec2 at = uv_at(uv, &mat->normal_transform, i, w0, w1, w2);
    float c[4] = {0.5f, 0.5f, 1.0f, 1.0f};
    lx_image_sample_bilinear(&mat->normal_map, at.x, at.y, c);
    lx_vec3 t = lx_v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        float wk = k == 0 ? w0 : (k == 1 ? w1 : w2);
        t = lx_madd(t, lx_v3(tangents[i[k]].x, tangents[i[k]].y, tangents[i[k]].z), wk);
    }
    lx_vec3 mn = lx_v3((2.0f * c[0] - 1.0f) * mat->normal_scale,
                       (2.0f * c[1] - 1.0f) * mat->normal_scale, 2.0f * c[2] - 1.0f);
    *normal = lx_tangent_to_world(mn, *normal, lx_v4(t.x, t.y, t.z, tangents[i[0]].w));
}
