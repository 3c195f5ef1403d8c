/* The scene container: meshes, materials, nodes and lights, their
 * validation and programmatic construction. */
#include "luxel/scene.h"
#include "core/internal.h"
#include "node_bake.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A scene with the capacities of its growing arrays, which users never see:
 * lx_scene_create hands out &store->scene. */
typedef struct scene_store {
    lx_scene scene;
    uint32_t mesh_capacity, material_capacity, node_capacity, light_capacity, profile_capacity;
    uint32_t camera_capacity;
} scene_store;

static scene_store *store_of(lx_scene *s)
{
    return (scene_store *)((char *)s - offsetof(scene_store, scene));
}

/* Grows *array (of elem bytes, *capacity entries) to hold count + 1. */
static lx_status grow(void **array, uint32_t *capacity, uint32_t count, size_t elem,
                      const char *what)
{
    if (count < *capacity)
        return LX_OK;
    if (count >= UINT32_MAX / 2)
        return lx_fail(LX_ERR_NOMEM, "too many %s (%u)", what, count);
    uint32_t cap = *capacity ? *capacity * 2 : 8;
    void *p = realloc(*array, (size_t)cap * elem);
    if (!p)
        return lx_fail(LX_ERR_NOMEM, "out of memory adding %s", what);
    memset((char *)p + (size_t)*capacity * elem, 0, (size_t)(cap - *capacity) * elem);
    *array = p;
    *capacity = cap;
    return LX_OK;
}

lx_status lx_scene_create(const char *name, lx_scene **out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    *out = NULL;
    scene_store *store = calloc(1, sizeof *store);
    if (!store || !(store->scene.path = lx_strdup(name ? name : "scene"))) {
        free(store);
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a scene");
    }
    *out = &store->scene;
    return LX_OK;
}

static void mesh_free(lx_mesh *m)
{
    free(m->name);
    free(m->positions);
    free(m->normals);
    free(m->tangents);
    for (int i = 0; i < LX_MAX_UV_SETS; i++)
        free(m->uv[i]);
    free(m->indices);
}

static void material_free(lx_material *m)
{
    free(m->name);
    free(m->normal_map_path);
    free(m->base_color_map_path);
    free(m->height_map_path);
    free(m->height_normal_path);
    lx_image_free(&m->normal_map);
    lx_image_free(&m->base_color_map);
    free(m->emissive_map_path);
    lx_image_free(&m->emissive_map);
}

void lx_scene_destroy(lx_scene *s)
{
    if (!s)
        return;
    for (uint32_t i = 0; i < s->mesh_count; i++)
        mesh_free(&s->meshes[i]);
    for (uint32_t i = 0; i < s->material_count; i++)
        material_free(&s->materials[i]);
    for (uint32_t i = 0; i < s->node_count; i++) {
        free(s->nodes[i].name);
        free(s->nodes[i].meshes);
    }
    free(s->meshes);
    free(s->materials);
    free(s->nodes);
    for (uint32_t i = 0; i < s->profile_count; i++)
        lx_ies_free(s->profiles[i]);
    free(s->profiles);
    free(s->lights);
    for (uint32_t i = 0; i < s->camera_count; i++) {
        free(s->cameras[i].name);
        free(s->cameras[i].node_name);
    }
    free(s->cameras);
    free(s->sky.environment);
    free(s->path);
    free(store_of(s));
}

static void *dup_array(const void *src, size_t count, size_t elem)
{
    if (!src)
        return NULL;
    void *p = malloc(count * elem);
    if (p)
        memcpy(p, src, count * elem);
    return p;
}

/* Area-weighted vertex normals from the faces. */
static void compute_normals(lx_mesh *m)
{
    memset(m->normals, 0, sizeof(lx_vec3) * m->vertex_count);
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *idx = &m->indices[3 * t];
        lx_vec3 a = m->positions[idx[0]], b = m->positions[idx[1]], c = m->positions[idx[2]];
        lx_vec3 n = lx_cross(lx_sub(b, a), lx_sub(c, a));
        for (int k = 0; k < 3; k++)
            m->normals[idx[k]] = lx_add(m->normals[idx[k]], n);
    }
    for (uint32_t v = 0; v < m->vertex_count; v++)
        m->normals[v] = lx_normalize(m->normals[v]);
}

/* Renormalizes the file's normals; a zero one takes the face normals around
 * its vertex, the others are kept (hard edges stay hard). */
static void repair_normals(lx_mesh *m)
{
    bool any_zero = false;
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        float len = lx_length(m->normals[v]);
        if (len > 1e-12f)
            m->normals[v] = lx_scale(m->normals[v], 1.0f / len);
        else
            any_zero = true;
    }
    if (!any_zero)
        return;
    lx_vec3 *kept = malloc(sizeof(lx_vec3) * m->vertex_count);
    if (!kept)
        return; /* zero normals then fall back to geometric ones in the bake */
    memcpy(kept, m->normals, sizeof(lx_vec3) * m->vertex_count);
    compute_normals(m);
    for (uint32_t v = 0; v < m->vertex_count; v++)
        if (lx_length(kept[v]) > 0.0f)
            m->normals[v] = kept[v];
    free(kept);
}

/* Heights up to this many units in the last place of a triangle's largest
 * coordinate are the rounding of points on a line: zdm2's T-junction
 * fillers (a vertex on the long edge, rounded off it) are 0.25 to 14.3
 * ulps high, its next thinnest triangles 25.6 and more. */
#define ROUNDING_ULPS 16.0

/* Whether triangle abc's height (twice its area over its longest edge) is
 * within ROUNDING_ULPS of its coordinates' float spacing: three points on
 * a line stored as floats, whose area and normal are rounding noise (a
 * float page UV cannot hold them either: zdm2's became zero-area). */
static bool height_is_rounding(lx_vec3 a, lx_vec3 b, lx_vec3 c)
{
    double p[3][3] = {{a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}};
    double e1[3], e2[3], e3[3], big = 0.0;
    for (int k = 0; k < 3; k++) {
        e1[k] = p[1][k] - p[0][k];
        e2[k] = p[2][k] - p[0][k];
        e3[k] = p[2][k] - p[1][k];
        big = fmax(big, fmax(fabs(p[0][k]), fmax(fabs(p[1][k]), fabs(p[2][k]))));
    }
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                   e1[0] * e2[1] - e1[1] * e2[0]};
    double longest = fmax(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2],
                          fmax(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2],
                               e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2]));
    double ulp = (double)nextafterf((float)big, INFINITY) - (float)big;
    double cross = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return cross <= ROUNDING_ULPS * ulp * sqrt(longest);
}

/* A triangle is degenerate in space when its area is negligible next to
 * its edges, or its height is the rounding of its float coordinates: its
 * geometric normal cannot be trusted. */
bool lx_triangle_degenerate(lx_vec3 a, lx_vec3 b, lx_vec3 c)
{
    lx_vec3 e1 = lx_sub(b, a), e2 = lx_sub(c, a), e3 = lx_sub(c, b);
    float cross_len = lx_length(lx_cross(e1, e2));
    float longest = fmaxf(lx_dot(e1, e1), fmaxf(lx_dot(e2, e2), lx_dot(e3, e3)));
    return !(cross_len > 1e-6f * longest) || longest == 0.0f || height_is_rounding(a, b, c);
}

static lx_status validate_mesh(const lx_scene *s, const lx_mesh *m, const char *name)
{
    if (m->vertex_count == 0 || m->triangle_count == 0 || !m->positions || !m->indices)
        return lx_fail(LX_ERR_INVALID, "%s: mesh '%s': no triangles", s->path, name);
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        if (!lx_vec3_finite(m->positions[v]))
            return lx_fail(LX_ERR_FORMAT, "%s: mesh '%s': vertex %u: position is not finite",
                           s->path, name, v);
        if (m->normals && !lx_vec3_finite(m->normals[v]))
            return lx_fail(LX_ERR_FORMAT, "%s: mesh '%s': vertex %u: normal is not finite", s->path,
                           name, v);
        for (int k = 0; k < LX_MAX_UV_SETS; k++)
            if (m->uv[k] && !(isfinite(m->uv[k][v].x) && isfinite(m->uv[k][v].y)))
                return lx_fail(LX_ERR_FORMAT, "%s: mesh '%s': vertex %u: TEXCOORD_%d is not finite",
                               s->path, name, v, k);
        if (m->tangents) {
            lx_vec4 t = m->tangents[v];
            if (!(isfinite(t.x) && isfinite(t.y) && isfinite(t.z) && isfinite(t.w)))
                return lx_fail(LX_ERR_FORMAT, "%s: mesh '%s': vertex %u: tangent is not finite",
                               s->path, name, v);
        }
    }
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *idx = &m->indices[3 * t];
        for (int k = 0; k < 3; k++)
            if (idx[k] >= m->vertex_count)
                return lx_fail(LX_ERR_FORMAT,
                               "%s: mesh '%s': triangle %u: index %u out of range (count %u)",
                               s->path, name, t, idx[k], m->vertex_count);
        if (lx_triangle_degenerate(m->positions[idx[0]], m->positions[idx[1]],
                                   m->positions[idx[2]]))
            return lx_fail(LX_ERR_FORMAT, "%s: mesh '%s': triangle %u has zero area", s->path, name,
                           t);
    }
    if (m->material >= s->material_count && s->material_count > 0)
        return lx_fail(LX_ERR_INVALID, "%s: mesh '%s': material %u out of range (count %u)",
                       s->path, name, m->material, s->material_count);
    return LX_OK;
}

lx_status lx_scene_add_mesh(lx_scene *s, const lx_mesh *src, uint32_t *index)
{
    if (!s)
        return lx_fail_null(__func__, "scene");
    if (!src)
        return lx_fail_null(__func__, "mesh");
    char fallback[32];
    snprintf(fallback, sizeof fallback, "mesh%u", s->mesh_count);
    const char *name = src->name && src->name[0] ? src->name : fallback;
    lx_status st = validate_mesh(s, src, name);
    if (st != LX_OK)
        return st;
    st = grow((void **)&s->meshes, &store_of(s)->mesh_capacity, s->mesh_count, sizeof(lx_mesh),
              "meshes");
    if (st != LX_OK)
        return st;
    lx_mesh m = *src;
    size_t nv = src->vertex_count;
    size_t ni;
    if (!lx_size_mul(src->triangle_count, 3, 1, &ni))
        return lx_fail(LX_ERR_NOMEM, "%s: mesh '%s' is too large", s->path, name);
    m.name = lx_strdup(name);
    m.positions = dup_array(src->positions, nv, sizeof(lx_vec3));
    m.normals =
        src->normals ? dup_array(src->normals, nv, sizeof(lx_vec3)) : malloc(nv * sizeof(lx_vec3));
    m.tangents = dup_array(src->tangents, nv, sizeof(lx_vec4));
    for (int k = 0; k < LX_MAX_UV_SETS; k++)
        m.uv[k] = dup_array(src->uv[k], nv, sizeof(lx_vec2));
    m.indices = dup_array(src->indices, ni, sizeof(uint32_t));
    bool ok = m.name && m.positions && m.normals && m.indices && (!src->tangents || m.tangents);
    for (int k = 0; k < LX_MAX_UV_SETS; k++)
        ok = ok && (!src->uv[k] || m.uv[k]);
    if (!ok) {
        mesh_free(&m);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory copying mesh '%s'", s->path, name);
    }
    if (!src->normals)
        compute_normals(&m);
    else
        repair_normals(&m);
    if (index)
        *index = s->mesh_count;
    s->meshes[s->mesh_count++] = m;
    return LX_OK;
}

lx_status lx_scene_add_material(lx_scene *s, const lx_material *src, uint32_t *index)
{
    if (!s)
        return lx_fail_null(__func__, "scene");
    if (!src)
        return lx_fail_null(__func__, "material");
    lx_status st = grow((void **)&s->materials, &store_of(s)->material_capacity, s->material_count,
                        sizeof(lx_material), "materials");
    if (st != LX_OK)
        return st;
    lx_material m = *src;
    char fallback[32];
    snprintf(fallback, sizeof fallback, "material%u", s->material_count);
    m.name = lx_strdup(src->name && src->name[0] ? src->name : fallback);
    m.normal_map_path = src->normal_map_path ? lx_strdup(src->normal_map_path) : NULL;
    m.base_color_map_path = src->base_color_map_path ? lx_strdup(src->base_color_map_path) : NULL;
    m.height_map_path = src->height_map_path ? lx_strdup(src->height_map_path) : NULL;
    m.height_normal_path = src->height_normal_path ? lx_strdup(src->height_normal_path) : NULL;
    memset(&m.normal_map, 0, sizeof m.normal_map);
    m.emissive_map_path = src->emissive_map_path ? lx_strdup(src->emissive_map_path) : NULL;
    memset(&m.base_color_map, 0, sizeof m.base_color_map);
    memset(&m.emissive_map, 0, sizeof m.emissive_map);
    const lx_image *maps[3] = {&src->normal_map, &src->base_color_map, &src->emissive_map};
    lx_image *dst[3] = {&m.normal_map, &m.base_color_map, &m.emissive_map};
    for (int i = 0; i < 3; i++) {
        if (maps[i]->width <= 0)
            continue;
        if (lx_image_alloc(dst[i], maps[i]->width, maps[i]->height, maps[i]->channels) != LX_OK) {
            material_free(&m);
            return LX_ERR_NOMEM;
        }
        memcpy(dst[i]->data, maps[i]->data,
               sizeof(float) * (size_t)maps[i]->width * maps[i]->height * maps[i]->channels);
    }
    if (m.normal_scale == 0.0f)
        m.normal_scale = 1.0f;
    /* the sets of the maps luxel samples are read too */
    const int sets[3] = {src->normal_uv_set, src->base_color_uv_set, src->emissive_uv_set};
    for (int i = 0; i < 3; i++)
        if (maps[i]->width > 0 && sets[i] >= 0 && sets[i] < 32)
            m.uv_sets_read |= 1u << sets[i];
    if (index)
        *index = s->material_count;
    s->materials[s->material_count++] = m;
    return LX_OK;
}

int lx_scene_lightmap_set(const lx_scene *s, uint32_t n)
{
    if (!s || n >= s->node_count)
        return -1;
    uint32_t read = 0;
    const lx_node *node = &s->nodes[n];
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        uint32_t mat = s->meshes[node->meshes[k]].material;
        if (mat < s->material_count)
            read |= s->materials[mat].uv_sets_read;
    }
    for (int set = 1; set < LX_MAX_UV_SETS; set++)
        if (!(read & (1u << set)))
            return set;
    return -1;
}

lx_status lx_scene_add_node(lx_scene *s, const char *name, const lx_mat4 *world,
                            const uint32_t *meshes, uint32_t mesh_count, uint32_t *index)
{
    if (!s)
        return lx_fail_null(__func__, "scene");
    if (!world)
        return lx_fail_null(__func__, "world");
    if (mesh_count > 0 && !meshes)
        return lx_fail(LX_ERR_INVALID, "%s: meshes is NULL with mesh_count %u", __func__,
                       mesh_count);
    if (!name || !name[0])
        return lx_fail(LX_ERR_INVALID, "%s: a node needs a name", s->path);
    for (uint32_t i = 0; i < s->node_count; i++)
        if (strcmp(s->nodes[i].name, name) == 0)
            return lx_fail(LX_ERR_INVALID, "%s: node name '%s' is used twice", s->path, name);
    if (!lx_mat4_finite(world))
        return lx_fail(LX_ERR_FORMAT, "%s: node '%s': transform is not finite", s->path, name);
    if (!(fabsf(lx_mat4_det3(world)) > 1e-20f))
        return lx_fail(LX_ERR_FORMAT, "%s: node '%s': transform is singular (zero scale)", s->path,
                       name);
    for (uint32_t i = 0; i < mesh_count; i++)
        if (meshes[i] >= s->mesh_count)
            return lx_fail(LX_ERR_INVALID, "%s: node '%s': mesh %u out of range (count %u)",
                           s->path, name, meshes[i], s->mesh_count);
    lx_status st = grow((void **)&s->nodes, &store_of(s)->node_capacity, s->node_count,
                        sizeof(lx_node), "nodes");
    if (st != LX_OK)
        return st;
    lx_node n = {0};
    n.name = lx_strdup(name);
    n.world = *world;
    n.source_node = -1;
    n.mesh_count = mesh_count;
    n.source_node = -1;
    n.meshes = mesh_count ? dup_array(meshes, mesh_count, sizeof(uint32_t)) : NULL;
    if (!n.name || (mesh_count && !n.meshes)) {
        free(n.name);
        free(n.meshes);
        return lx_fail(LX_ERR_NOMEM, "out of memory adding node '%s'", name);
    }
    if (index)
        *index = s->node_count;
    s->nodes[s->node_count++] = n;
    return LX_OK;
}

lx_status lx_scene_add_light(lx_scene *s, const lx_light *light)
{
    if (!s)
        return lx_fail_null(__func__, "scene");
    lx_status st = lx_light_validate(light);
    if (st != LX_OK) {
        lx_error_prefix(s->path);
        return st;
    }
    if (light->name[0])
        for (uint32_t i = 0; i < s->light_count; i++)
            if (strcmp(s->lights[i].name, light->name) == 0) {
                s->lights[i] = *light;
                return LX_OK;
            }
    st = grow((void **)&s->lights, &store_of(s)->light_capacity, s->light_count, sizeof(lx_light),
              "lights");
    if (st != LX_OK)
        return st;
    s->lights[s->light_count++] = *light;
    return LX_OK;
}

lx_status lx_scene_add_camera(lx_scene *s, const lx_scene_camera *camera)
{
    if (!s)
        return lx_fail_null(__func__, "scene");
    if (!camera)
        return lx_fail_null(__func__, "camera");
    const lx_scene_camera *c = camera;
    const char *who = c->name && c->name[0] ? c->name : "(unnamed)";
    if (!lx_vec3_finite(c->eye) || !lx_vec3_finite(c->forward) || !lx_vec3_finite(c->up) ||
        !isfinite(c->yfov) || !isfinite(c->aspect) || !isfinite(c->znear) ||
        !isfinite(c->zfar) || !isfinite(c->xmag) || !isfinite(c->ymag))
        return lx_fail(LX_ERR_INVALID, "%s: camera '%s': a value is not finite", s->path, who);
    if (fabsf(lx_length(c->forward) - 1.0f) > 1e-3f || fabsf(lx_length(c->up) - 1.0f) > 1e-3f ||
        fabsf(lx_dot(c->forward, c->up)) > 1e-3f)
        return lx_fail(LX_ERR_INVALID,
                       "%s: camera '%s': forward and up must be unit and orthogonal", s->path, who);
    if (c->type == LX_SCENE_CAMERA_PERSPECTIVE && !(c->yfov > 0.0f && c->yfov < LX_PI))
        return lx_fail(LX_ERR_INVALID, "%s: camera '%s': yfov %g is not in (0, pi)", s->path, who,
                       (double)c->yfov);
    if (c->type == LX_SCENE_CAMERA_ORTHOGRAPHIC && (c->xmag == 0.0f || c->ymag == 0.0f))
        return lx_fail(LX_ERR_INVALID, "%s: camera '%s': xmag and ymag must not be 0", s->path,
                       who);
    if (c->type != LX_SCENE_CAMERA_PERSPECTIVE && c->type != LX_SCENE_CAMERA_ORTHOGRAPHIC)
        return lx_fail(LX_ERR_INVALID, "%s: camera '%s': unknown type %d", s->path, who,
                       (int)c->type);
    char fallback[32];
    snprintf(fallback, sizeof fallback, "camera%u", s->camera_count);
    const char *name = c->name && c->name[0] ? c->name : fallback;
    for (uint32_t i = 0; i < s->camera_count; i++)
        if (strcmp(s->cameras[i].name, name) == 0)
            return lx_fail(LX_ERR_INVALID, "%s: camera name '%s' is taken", s->path, name);
    lx_status st = grow((void **)&s->cameras, &store_of(s)->camera_capacity, s->camera_count,
                        sizeof(lx_scene_camera), "cameras");
    if (st != LX_OK)
        return st;
    lx_scene_camera copy = *c;
    copy.name = lx_strdup(name);
    copy.node_name = c->node_name ? lx_strdup(c->node_name) : NULL;
    if (!copy.name || (c->node_name && !copy.node_name)) {
        free(copy.name);
        free(copy.node_name);
        return lx_fail(LX_ERR_NOMEM, "out of memory adding a camera");
    }
    s->cameras[s->camera_count++] = copy;
    return LX_OK;
}

lx_status lx_scene_adopt_profile(lx_scene *s, lx_ies_profile *profile)
{
    if (!s)
        return lx_fail_null(__func__, "scene");
    lx_status st = grow((void **)&s->profiles, &store_of(s)->profile_capacity, s->profile_count,
                        sizeof(lx_ies_profile *), "photometric profiles");
    if (st != LX_OK)
        return st;
    s->profiles[s->profile_count++] = profile;
    return LX_OK;
}

bool lx_scene_bounds(const lx_scene *s, lx_vec3 *lo, lx_vec3 *hi)
{
    bool any = false, all_sky = true;
    for (uint32_t n = 0; n < s->node_count && all_sky; n++)
        all_sky = s->nodes[n].bake.sky;
    lx_vec3 a = lx_v3(INFINITY, INFINITY, INFINITY), b = lx_v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t n = 0; n < s->node_count; n++) {
        const lx_node *node = &s->nodes[n];
        if (node->bake.sky && !all_sky)
            continue; /* a sky dome is not what the scene spans */
        any |= lx_node_grow_bounds(s, node, &a, &b);
    }
    *lo = a;
    *hi = b;
    return any;
}

bool lx_node_grow_bounds(const lx_scene *s, const lx_node *node, lx_vec3 *lo, lx_vec3 *hi)
{
    bool any = false;
    lx_vec3 a = *lo, b = *hi;
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        const lx_mesh *m = &s->meshes[node->meshes[k]];
        for (uint32_t v = 0; v < m->vertex_count; v++) {
            lx_vec3 p = lx_mat4_point(&node->world, m->positions[v]);
            a = lx_v3(fminf(a.x, p.x), fminf(a.y, p.y), fminf(a.z, p.z));
            b = lx_v3(fmaxf(b.x, p.x), fmaxf(b.y, p.y), fmaxf(b.z, p.z));
            any = true;
        }
    }
    *lo = a;
    *hi = b;
    return any;
}
