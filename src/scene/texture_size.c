/* How finely a scene's textures are decoded (scene.h, "Textures at the
 * resolution a bake reads them"). Textures are read at lightmap texels:
 * a texel samples its material's maps once, at its centre, bilinearly.
 * A texture finer than a few of its pixels across each texel that reads
 * it adds nothing a box-filtered copy does not give (the mean over the
 * texel's footprint is what the texel stands for), and costs 16 bytes a
 * pixel as floats. So per node reading a map, over the triangles of its
 * meshes that read it: the lightmap texels, density^2 x world area, and
 * the texture's UV area under its transform (repeats count, as each
 * repeat is read again); the map keeps LX_TEXTURE_TEXELS_PER_TEXEL^2
 * texture pixels per texel on the node that needs the most, and never
 * fewer than LX_TEXTURE_MIN_PIXELS. Sums are over whole nodes: a part of
 * a node whose UVs stretch the texture n times more than the node's mean
 * gets n times fewer texture pixels per texel there. */
#include "texture_size.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The UV set and transform map slot of mat is read through. */
static void slot_of(const lx_material *mat, int slot, int *set, const lx_uv_transform **t)
{
    switch (slot) {
    case LX_TEXTURE_NORMAL:
        *set = mat->normal_uv_set;
        *t = &mat->normal_transform;
        break;
    case LX_TEXTURE_BASE_COLOR:
        *set = mat->base_color_uv_set;
        *t = &mat->base_color_transform;
        break;
    default:
        *set = mat->emissive_uv_set;
        *t = &mat->emissive_transform;
        break;
    }
}

/* A transform's factor on UV areas: |scale.x scale.y| (rotation and offset
 * keep areas); 1 when it is not enabled (the identity). */
static double transform_area(const lx_uv_transform *t)
{
    return t->enabled ? fabs((double)t->scale.x * (double)t->scale.y) : 1.0;
}

lx_status lx_texture_keep_pixels(const lx_scene *scene, const lx_scene_load_desc *desc,
                                 uint64_t *keep)
{
    size_t slots = (size_t)scene->material_count * LX_TEXTURE_SLOTS;
    memset(keep, 0, sizeof *keep * slots);
    if (!desc->texture_density_fn && !(desc->texture_density > 0.0f))
        return LX_OK;
    /* the pixels each slot needs, the largest over the nodes reading it;
     * infinity where a node reads it through UVs of no area */
    double *need = calloc(slots ? slots : 1, sizeof *need);
    if (!need)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory sizing textures", scene->path);
    const double k2 = (double)LX_TEXTURE_TEXELS_PER_TEXEL * LX_TEXTURE_TEXELS_PER_TEXEL;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        const lx_node *node = &scene->nodes[n];
        float d = desc->texture_density_fn
                      ? desc->texture_density_fn(desc->texture_density_user, scene, n)
                      : desc->texture_density;
        if (!(d > 0.0f) || !isfinite(d))
            continue;
        for (uint32_t j = 0; j < node->mesh_count; j++) {
            const lx_mesh *m = &scene->meshes[node->meshes[j]];
            if (m->material >= scene->material_count)
                continue;
            const lx_material *mat = &scene->materials[m->material];
            /* world area, and UV area of every set (each read once) */
            double world = 0.0, uv_area[LX_MAX_UV_SETS] = {0};
            for (uint32_t t = 0; t < m->triangle_count; t++) {
                const uint32_t *i = &m->indices[3 * (size_t)t];
                lx_vec3 p = lx_mat4_point(&node->world, m->positions[i[0]]);
                lx_vec3 q = lx_mat4_point(&node->world, m->positions[i[1]]);
                lx_vec3 r = lx_mat4_point(&node->world, m->positions[i[2]]);
                world += 0.5 * (double)lx_length(lx_cross(lx_sub(q, p), lx_sub(r, p)));
                for (int s = 0; s < LX_MAX_UV_SETS; s++) {
                    const lx_vec2 *uv = m->uv[s];
                    if (!uv)
                        continue;
                    double ax = (double)uv[i[1]].x - uv[i[0]].x, ay = (double)uv[i[1]].y - uv[i[0]].y;
                    double bx = (double)uv[i[2]].x - uv[i[0]].x, by = (double)uv[i[2]].y - uv[i[0]].y;
                    uv_area[s] += 0.5 * fabs(ax * by - ay * bx);
                }
            }
            if (!(world > 0.0))
                continue;
            for (int slot = 0; slot < LX_TEXTURE_SLOTS; slot++) {
                int set;
                const lx_uv_transform *t;
                slot_of(mat, slot, &set, &t);
                if (set < 0 || set >= LX_MAX_UV_SETS || !m->uv[set])
                    continue; /* the mesh does not read this map */
                double area = uv_area[set] * transform_area(t);
                double pixels = area > 0.0 ? k2 * (double)d * (double)d * world / area : INFINITY;
                double *to = &need[(size_t)m->material * LX_TEXTURE_SLOTS + (size_t)slot];
                *to = pixels > *to ? pixels : *to;
            }
        }
    }
    for (size_t i = 0; i < slots; i++) {
        double p = need[i] > (double)LX_TEXTURE_MIN_PIXELS ? ceil(need[i])
                                                            : (double)LX_TEXTURE_MIN_PIXELS;
        keep[i] = p >= 1.8e19 ? 0 : (uint64_t)p; /* 0: as stored */
    }
    free(need);
    return LX_OK;
}
