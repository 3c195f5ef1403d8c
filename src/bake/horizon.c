/* Horizon self-shadowing and ambient occlusion of texels from a height
 * texture per material (Lengyel, FGED vol. 2 sec. 7.8: the horizon map and
 * its shading function ApplyHorizonMap, and the ambient factor): each
 * material the lights JSON gives a height (or a normal map to integrate
 * heights from, lx_height_from_normals) gets its horizon layers and AO
 * map made once (lx_horizon_map, wrap repeat); each of its texels keeps the
 * layers and AO sampled bilinearly at its material UV and its tangent
 * frame, and direct.c scales a light's direct term by lx_horizon_light of
 * the light's direction in that frame, and ambient and sky by the AO. */
#include "bake_internal.h"
#include "core/internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void lx_bake_horizon_free(lx_horizon_material *hm, uint32_t count)
{
    for (uint32_t m = 0; hm && m < count; m++) {
        lx_image_free(&hm[m].layer0);
        lx_image_free(&hm[m].layer1);
        lx_image_free(&hm[m].ao);
    }
    free(hm);
}

static bool has_height(const lx_material *mat)
{
    return (mat->height_map_path || mat->height_from_normals) &&
           (mat->height_horizon || mat->height_ao);
}

/* Progress of one material's steps within the bake's share for them. */
typedef struct horizon_progress {
    const lx_bake_desc *desc;
    float from, to;
} horizon_progress;

static bool material_progress(void *user, float f)
{
    const horizon_progress *p = user;
    return p->desc->progress(p->desc->progress_user, p->from + (p->to - p->from) * f);
}

/* The heights of mat integrated from its normal map (the named file, or
 * its own normal texture), in texels times *strength_out's factor. */
static lx_status heights_from_normals(const lx_material *mat, const lx_bake_desc *desc,
                                      horizon_progress *hp, lx_image *height, float *scale,
                                      int *radius)
{
    lx_image normals;
    lx_status st;
    *scale = mat->height_strength > 0.0f ? mat->height_strength : 1.0f;
    if (mat->height_normal_path) {
        lx_image img;
        lx_image_load_desc ld = {.raw_8bit = true};
        st = lx_image_load(mat->height_normal_path, &ld, &img);
        if (st == LX_OK) {
            st = lx_normal_decode(&img, mat->height_normal_path, &normals);
            lx_image_free(&img);
        }
    } else {
        /* the glTF normal texture, whose slopes normal_scale multiplies */
        const char *name = mat->normal_map_path ? mat->normal_map_path : "normal texture";
        st = lx_normal_decode(&mat->normal_map, name, &normals);
        *scale *= mat->normal_scale > 0.0f ? mat->normal_scale : 1.0f;
        /* a map halved on load (lx_scene_load_desc's texture density):
         * its heights keep their slopes (in texels of the map as kept),
         * and the horizon is searched over the same distance on the
         * surface, so over fewer of its texels */
        if (mat->normal_map_halvings > 0) {
            lx_horizon_desc given = lx_horizon_desc_defaults(NULL);
            int h = mat->normal_map_halvings < 30 ? mat->normal_map_halvings : 30;
            *radius = given.radius >> h > 2 ? given.radius >> h : 2;
        }
    }
    if (st != LX_OK)
        return st;
    lx_height_from_normals_desc d = {.wrap = LX_WRAP_REPEAT,
                                     .green_down = mat->height_green_down,
                                     .threads = desc->threads,
                                     .progress = desc->progress ? material_progress : NULL,
                                     .progress_user = hp};
    st = lx_height_from_normals(&normals, &d, height);
    lx_image_free(&normals);
    return st;
}

lx_status lx_bake_horizon_load(const lx_scene *scene, const lx_bake_desc *desc,
                               lx_texel_progress share, lx_horizon_material **out)
{
    *out = NULL;
    uint32_t count = 0;
    for (uint32_t m = 0; m < scene->material_count; m++)
        count += has_height(&scene->materials[m]);
    if (!count)
        return LX_OK;
    lx_horizon_material *hm = calloc(scene->material_count, sizeof *hm);
    if (!hm)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for height maps", scene->path);
    lx_status st = LX_OK;
    uint32_t done = 0;
    for (uint32_t m = 0; m < scene->material_count && st == LX_OK; m++) {
        const lx_material *mat = &scene->materials[m];
        if (!has_height(mat))
            continue;
        /* this material's part of the share: integrating (when from a
         * normal map) and the horizon map, half each */
        float from = share.from + (share.to - share.from) * (float)done / (float)count;
        float to = share.from + (share.to - share.from) * (float)(done + 1) / (float)count;
        float mid = mat->height_from_normals ? 0.5f * (from + to) : from;
        horizon_progress hp = {desc, from, mid};
        lx_image height;
        float strength = mat->height_strength;
        int radius = 0; /* the default */
        if (mat->height_from_normals)
            st = heights_from_normals(mat, desc, &hp, &height, &strength, &radius);
        else
            st = lx_height_load(mat->height_map_path, &height);
        if (st == LX_OK) {
            hp.from = mid;
            hp.to = to;
            lx_horizon_desc d = {.strength = strength,
                                 .radius = radius,
                                 .wrap = LX_WRAP_REPEAT,
                                 .threads = desc->threads,
                                 .progress = desc->progress ? material_progress : NULL,
                                 .progress_user = &hp};
            st = lx_horizon_map(&height, &d, mat->height_horizon ? &hm[m].layer0 : NULL,
                                mat->height_horizon ? &hm[m].layer1 : NULL,
                                mat->height_ao ? &hm[m].ao : NULL);
            lx_image_free(&height);
        }
        if (st == LX_ERR_CANCELLED) {
            lx_fail(LX_ERR_CANCELLED, "bake cancelled");
            break;
        }
        if (st != LX_OK) {
            char where[300];
            snprintf(where, sizeof where, "%s: material '%s'", scene->path,
                     mat->name ? mat->name : "");
            lx_error_prefix(where);
            break;
        }
        hm[m].horizon = mat->height_horizon;
        hm[m].use_ao = mat->height_ao;
        hm[m].active = true;
        done++;
    }
    /* a mesh of such a material without the UV set its height is read at
     * bakes without it: say so once per mesh */
    for (uint32_t i = 0; i < scene->mesh_count && st == LX_OK; i++) {
        const lx_mesh *mesh = &scene->meshes[i];
        if (mesh->material >= scene->material_count || !hm[mesh->material].active)
            continue;
        const lx_material *mat = &scene->materials[mesh->material];
        if (mat->normal_uv_set < 0 || mat->normal_uv_set >= LX_MAX_UV_SETS ||
            !mesh->uv[mat->normal_uv_set])
            lx_log(LX_LOG_WARN,
                   "%s: mesh '%s' has no UV set %d for material '%s''s height: no horizon "
                   "shadows or AO on it",
                   scene->path, mesh->name ? mesh->name : "", mat->normal_uv_set,
                   mat->name ? mat->name : "");
    }
    if (st != LX_OK) {
        lx_bake_horizon_free(hm, scene->material_count);
        return st;
    }
    *out = hm;
    return LX_OK;
}

bool lx_bake_node_has_horizon(const lx_scene *scene, const lx_horizon_material *hm, uint32_t node)
{
    if (!hm)
        return false;
    const lx_node *n = &scene->nodes[node];
    for (uint32_t k = 0; k < n->mesh_count; k++) {
        const lx_mesh *m = &scene->meshes[n->meshes[k]];
        if (m->material < scene->material_count && hm[m->material].active)
            return true;
    }
    return false;
}

/* The material a texel's mesh uses, when it has horizon maps and the mesh
 * the UVs they are read at. */
static const lx_horizon_material *texel_material(const lx_scene *scene,
                                                 const lx_horizon_material *hm, const lx_mesh *m)
{
    if (m->material >= scene->material_count || !hm[m->material].active)
        return NULL;
    const lx_material *mat = &scene->materials[m->material];
    return m->uv[mat->normal_uv_set] ? &hm[m->material] : NULL;
}

lx_status lx_bake_horizon_texels(const lx_scene *scene, const lx_horizon_material *hm,
                                 lx_lightmap *map, const float *b1, const float *b2, int threads)
{
    uint32_t n = map->info.used_texels;
    if (!hm || n == 0)
        return LX_OK;
    /* the meshes of this map that need a frame, with their tangents */
    lx_vec4 **tangents = calloc(scene->mesh_count + 1, sizeof *tangents);
    bool *own = calloc(scene->mesh_count + 1, sizeof *own);
    lx_status st = tangents && own ? LX_OK : lx_fail(LX_ERR_NOMEM, "%s: out of memory", map->name);
    bool any = false;
    for (uint32_t k = 0; k < n && st == LX_OK; k++) {
        uint32_t mi = map->texels[k].mesh;
        const lx_mesh *m = &scene->meshes[mi];
        if (tangents[mi] || !texel_material(scene, hm, m))
            continue;
        any = true;
        if (m->tangents) {
            tangents[mi] = m->tangents;
            continue;
        }
        tangents[mi] = malloc(sizeof(lx_vec4) * (m->vertex_count ? m->vertex_count : 1));
        own[mi] = true;
        st = tangents[mi] ? lx_compute_tangents(m, scene->materials[m->material].normal_uv_set,
                                                tangents[mi])
                          : lx_fail(LX_ERR_NOMEM, "%s: out of memory", map->name);
    }
    if (st == LX_OK && any) {
        map->horizon = calloc(n, sizeof *map->horizon);
        if (!map->horizon)
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for horizon texels", map->name);
    }
    if (st == LX_OK && any) {
#pragma omp parallel for schedule(static) num_threads(lx_thread_count(threads))
        for (int64_t kk = 0; kk < (int64_t)n; kk++) {
            uint32_t k = (uint32_t)kk;
            const lx_texel *tx = &map->texels[k];
            const lx_mesh *m = &scene->meshes[tx->mesh];
            const lx_horizon_material *h = texel_material(scene, hm, m);
            lx_texel_horizon *out = &map->horizon[k];
            if (!h)
                continue;
            const lx_material *mat = &scene->materials[m->material];
            const uint32_t *i = &m->indices[3 * tx->triangle];
            float w1 = b1[tx->pixel], w2 = b2[tx->pixel], w0 = 1.0f - w1 - w2;
            const lx_vec2 *uv = m->uv[mat->normal_uv_set];
            float u = uv[i[0]].x * w0 + uv[i[1]].x * w1 + uv[i[2]].x * w2;
            float v = uv[i[0]].y * w0 + uv[i[1]].y * w1 + uv[i[2]].y * w2;
            lx_vec2 at = lx_uv_transform_apply(&mat->normal_transform, lx_v2(u, v));
            out->ao = 1.0f;
            if (h->horizon) {
                lx_image_sample_bilinear(&h->layer0, at.x, at.y, out->h0);
                lx_image_sample_bilinear(&h->layer1, at.x, at.y, out->h1);
                out->flags |= LX_TEXEL_HORIZON;
            }
            if (h->use_ao) {
                lx_image_sample_bilinear(&h->ao, at.x, at.y, &out->ao);
                out->flags |= LX_TEXEL_AO;
            }
            /* the frame of the surface the height sits on: the
             * interpolated normal (not the normal-mapped one) and the
             * tangent made perpendicular to it */
            lx_vec3 pa = m->positions[i[0]], pb = m->positions[i[1]], pc = m->positions[i[2]];
            lx_vec3 geometric = lx_normalize(lx_cross(lx_sub(pb, pa), lx_sub(pc, pa)));
            lx_vec3 nrm = lx_add(lx_add(lx_scale(m->normals[i[0]], w0), lx_scale(m->normals[i[1]], w1)),
                                 lx_scale(m->normals[i[2]], w2));
            nrm = lx_length(nrm) > 1e-12f ? lx_normalize(nrm) : geometric;
            const lx_vec4 *tg = tangents[tx->mesh];
            lx_vec3 t = lx_v3(0, 0, 0);
            for (int c = 0; c < 3; c++) {
                float wc = c == 0 ? w0 : (c == 1 ? w1 : w2);
                t = lx_madd(t, lx_v3(tg[i[c]].x, tg[i[c]].y, tg[i[c]].z), wc);
            }
            const lx_mat4 *world = &scene->nodes[tx->node].world;
            lx_mat4 nm;
            if (!lx_mat4_normal_matrix(world, &nm))
                nm = *world;
            lx_vec3 wn = lx_normalize(lx_mat4_vector(&nm, nrm));
            lx_vec3 wt = lx_mat4_vector(world, t);
            wt = lx_sub(wt, lx_scale(wn, lx_dot(wn, wt)));
            if (!(lx_length(wt) > 1e-12f)) {
                /* no usable tangent: any perpendicular one */
                lx_vec3 a = fabsf(wn.x) < 0.9f ? lx_v3(1, 0, 0) : lx_v3(0, 1, 0);
                wt = lx_cross(a, wn);
            }
            wt = lx_normalize(wt);
            float hand = tg[i[0]].w < 0.0f ? -1.0f : 1.0f;
            out->t = wt;
            out->b = lx_scale(lx_cross(wn, wt), hand);
            out->n = wn;
        }
    }
    for (uint32_t mi = 0; tangents && mi < scene->mesh_count; mi++)
        if (own && own[mi])
            free(tangents[mi]);
    free(tangents);
    free(own);
    return st;
}

float lx_texel_horizon_factor(const lx_texel_horizon *h, lx_vec3 to_light)
{
    if (!(h->flags & LX_TEXEL_HORIZON))
        return 1.0f;
    lx_vec3 l = lx_v3(lx_dot(to_light, h->t), lx_dot(to_light, h->b), lx_dot(to_light, h->n));
    return lx_horizon_light(h->h0, h->h1, l, 0.0f);
}

bool lx_tile_has_horizon(const lx_lightmap *map, uint32_t first, uint32_t count)
{
    if (!map->horizon)
        return false;
    for (uint32_t k = 0; k < count; k++)
        if (map->horizon[first + k].flags)
            return true;
    return false;
}
