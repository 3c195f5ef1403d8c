/* The lights JSON's "materials" section (docs/lights-json.md, "Materials"):
 * per scene material, a height texture the baker self-shadows (Lengyel's
 * horizon map) and occludes texels with, its strength and which of the two
 * it drives. Read against the scene's material names; applied only once
 * the whole file is valid. */
#include "lights_json_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const material_keys[] = {"height", "strength", "horizon", "ao"};

/* One material's settings from the file (path NULL: the file names none). */
typedef struct pending_material {
    char *path;
    float strength;
    bool horizon, ao;
} pending_material;

static lx_status read_material_entry(lx_jf_ctx *c, const cJSON *obj, pending_material *p)
{
    if (!cJSON_IsObject(obj))
        return lx_jf_fail(c, LX_ERR_FORMAT, "must be an object with \"height\"");
    lx_status st = lx_jf_check_keys(c, obj, material_keys, LX_JF_COUNT(material_keys));
    if (st != LX_OK)
        return st;
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, "height");
    const char *rel = NULL;
    if (!it)
        return lx_jf_fail(c, LX_ERR_FORMAT, "missing 'height' (a height image file)");
    if ((st = lx_jf_string(c, it, "height", &rel)) != LX_OK)
        return st;
    if (!rel[0])
        return lx_jf_fail(c, LX_ERR_FORMAT, "height is an empty path");
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
    p->path = lx_jf_relative_path(c, rel);
    return p->path ? LX_OK : lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
}

/* "materials": {"<material name>": {"height", "strength", "horizon",
 * "ao"}}, into pending (one per scene material, every material of the
 * name given). A name no scene material has is an error. */
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
        if (st != LX_OK) {
            free(p.path);
            return st;
        }
        for (uint32_t m = 0; m < scene->material_count; m++) {
            if (!scene->materials[m].name || strcmp(scene->materials[m].name, name) != 0)
                continue;
            pending[m] = p;
            pending[m].path = lx_strdup(p.path);
            if (!pending[m].path) {
                free(p.path);
                return lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
            }
        }
        free(p.path);
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
        free(p->m[m].path);
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
        if (!pm->path)
            continue;
        lx_material *mat = &scene->materials[m];
        free(mat->height_map_path);
        mat->height_map_path = pm->path;
        mat->height_strength = pm->strength;
        mat->height_horizon = pm->horizon;
        mat->height_ao = pm->ao;
        pm->path = NULL;
    }
}
