/* The lights JSON's "materials" section (docs/lights-json.md, "Materials"):
 * per scene material, a height texture the baker self-shadows (Lengyel's
 * horizon map) and occludes texels with, or a normal map (a file, or the
 * material's own normal texture) to integrate heights from; its strength
 * and which of the two it drives. Read against the scene's material names; applied only once
 * the whole file is valid. */
#include "lights_json_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const material_keys[] = {"height", "normal", "green",
                                            "strength", "horizon", "ao"};

/* One material's settings from the file (active false: the file names
 * none). Heights come from path (a height image), or are integrated from
 * a normal map: normal_path, or the material's own normal texture when
 * from_normals and normal_path is NULL. */
typedef struct pending_material {
    bool active;
    char *path, *normal_path;
    bool from_normals, green_down;
    float strength;
    bool horizon, ao;
} pending_material;

static void pending_free(pending_material *p)
{
    free(p->path);
    free(p->normal_path);
    p->path = p->normal_path = NULL;
}

/* A non-empty path relative to the file, malloc'd into *out. */
static lx_status read_path(lx_jf_ctx *c, const cJSON *it, const char *field, char **out)
{
    const char *rel = NULL;
    lx_status st = lx_jf_string(c, it, field, &rel);
    if (st != LX_OK)
        return st;
    if (!rel[0])
        return lx_jf_fail(c, LX_ERR_FORMAT, "%s is an empty path", field);
    return lx_jf_relative_path(c, field, rel, out);
}

static lx_status read_material_entry(lx_jf_ctx *c, const cJSON *obj, pending_material *p)
{
    if (!cJSON_IsObject(obj))
        return lx_jf_fail(c, LX_ERR_FORMAT, "must be an object with \"height\" or \"normal\"");
    lx_status st = lx_jf_check_keys(c, obj, material_keys, LX_JF_COUNT(material_keys));
    if (st != LX_OK)
        return st;
    const cJSON *height = cJSON_GetObjectItemCaseSensitive(obj, "height");
    const cJSON *normal = cJSON_GetObjectItemCaseSensitive(obj, "normal");
    const cJSON *it;
    if (height && normal)
        return lx_jf_fail(c, LX_ERR_FORMAT,
                          "give 'height' (a height image) or 'normal' (a normal map), not both");
    if (height && (st = read_path(c, height, "height", &p->path)) != LX_OK)
        return st;
    if (normal && (st = read_path(c, normal, "normal", &p->normal_path)) != LX_OK)
        return st;
    p->from_normals = !height;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "green"))) {
        static const char *const greens[] = {"up", "down"};
        int e = 0;
        if (height)
            return lx_jf_fail(c, LX_ERR_FORMAT, "'green' is for normal maps, not 'height'");
        if ((st = lx_jf_enum(c, it, "green", greens, 2, &e)) != LX_OK)
            return st;
        p->green_down = e == 1;
    }
    p->strength = 0.0f;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "strength"))) {
        if ((st = lx_jf_float(c, it, "strength", &p->strength)) != LX_OK)
            return st;
        if (!(p->strength > 0.0f))
            return lx_jf_fail(c, LX_ERR_INVALID, "strength %g must be above 0", p->strength);
    }
    static const char *const flags[] = {"horizon", "ao"};
    bool *dst[] = {&p->horizon, &p->ao};
    for (int k = 0; k < 2; k++) {
        *dst[k] = true;
        if ((it = cJSON_GetObjectItemCaseSensitive(obj, flags[k]))) {
            if (!cJSON_IsBool(it))
                return lx_jf_fail(c, LX_ERR_FORMAT, "%s must be true or false", flags[k]);
            *dst[k] = cJSON_IsTrue(it);
        }
    }
    p->active = true;
    return LX_OK;
}

/* "materials": {"<material name>": {"height" or "normal", "green",
 * "strength", "horizon", "ao"}}, into pending (one per scene material,
 * every material of the name given). A name no scene material has is an
 * error, and so is an entry with neither "height" nor "normal" for a
 * material without a normal texture. */
static lx_status read_materials(lx_jf_ctx *c, const cJSON *obj, const lx_scene *scene,
                                pending_material *pending)
{
    snprintf(c->where, sizeof c->where, "materials");
    if (!cJSON_IsObject(obj))
        return lx_jf_fail(c, LX_ERR_FORMAT, "must be an object of material names");
    for (const cJSON *e = obj->child; e; e = e->next) {
        const char *name = e->string ? e->string : "";
        snprintf(c->where, sizeof c->where, "materials");
        for (const cJSON *p = obj->child; p != e; p = p->next)
            if (strcmp(p->string, name) == 0)
                return lx_jf_fail(c, LX_ERR_FORMAT, "material '%.40s' appears twice", name);
        bool found = false;
        for (uint32_t m = 0; m < scene->material_count && !found; m++)
            found = scene->materials[m].name && strcmp(scene->materials[m].name, name) == 0;
        if (!found)
            return lx_jf_fail(c, LX_ERR_INVALID,
                              "unknown material '%.40s' (%s has none of that name)", name,
                              scene->path ? scene->path : "the scene");
        snprintf(c->where, sizeof c->where, "materials ('%.40s')", name);
        pending_material p = {0};
        lx_status st = read_material_entry(c, e, &p);
        for (uint32_t m = 0; m < scene->material_count && st == LX_OK; m++) {
            const lx_material *mat = &scene->materials[m];
            if (!mat->name || strcmp(mat->name, name) != 0)
                continue;
            if (p.from_normals && !p.normal_path && mat->normal_map.width <= 0) {
                st = lx_jf_fail(c, LX_ERR_FORMAT,
                                "missing 'height' (a height image) or 'normal' (a normal map): "
                                "the material has no normal texture to integrate heights from");
                break;
            }
            pending[m] = p;
            pending[m].path = p.path ? lx_strdup(p.path) : NULL;
            pending[m].normal_path = p.normal_path ? lx_strdup(p.normal_path) : NULL;
            if ((p.path && !pending[m].path) || (p.normal_path && !pending[m].normal_path))
                st = lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
        }
        pending_free(&p);
        if (st != LX_OK)
            return st;
    }
    return LX_OK;
}

struct lx_lj_materials {
    pending_material *m; /* one per scene material */
    uint32_t count;
};

void lx_lj_materials_free(lx_lj_materials *p)
{
    for (uint32_t m = 0; p && m < p->count; m++)
        pending_free(&p->m[m]);
    if (p)
        free(p->m);
    free(p);
}

lx_status lx_lj_materials_read(lx_jf_ctx *c, const cJSON *obj, const lx_scene *scene,
                               lx_lj_materials **out)
{
    *out = NULL;
    lx_lj_materials *p = calloc(1, sizeof *p);
    if (p)
        p->m = calloc(scene->material_count + 1, sizeof *p->m);
    if (!p || !p->m) {
        free(p);
        return lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
    }
    p->count = scene->material_count;
    lx_status st = read_materials(c, obj, scene, p->m);
    if (st != LX_OK) {
        lx_lj_materials_free(p);
        return st;
    }
    *out = p;
    return LX_OK;
}

void lx_lj_materials_apply(lx_lj_materials *p, lx_scene *scene)
{
    for (uint32_t m = 0; p && m < p->count && m < scene->material_count; m++) {
        pending_material *pm = &p->m[m];
        if (!pm->active)
            continue;
        lx_material *mat = &scene->materials[m];
        free(mat->height_map_path);
        free(mat->height_normal_path);
        mat->height_map_path = pm->path;
        mat->height_normal_path = pm->normal_path;
        mat->height_from_normals = pm->from_normals;
        mat->height_green_down = pm->green_down;
        mat->height_strength = pm->strength;
        mat->height_horizon = pm->horizon;
        mat->height_ao = pm->ao;
        pm->path = pm->normal_path = NULL;
    }
}
