/* Typed fields of a JSON object with errors that name the file, the place
 * and the field (json_fields.h). */
#include "json_fields.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

lx_status lx_jf_float(const lx_jf_ctx *c, const cJSON *item, const char *field, float *out)
{
    if (!cJSON_IsNumber(item))
        return lx_jf_fail(c, LX_ERR_FORMAT, "%s must be a number", field);
    double v = item->valuedouble;
    if (!isfinite(v) || !isfinite((float)v))
        return lx_jf_fail(c, LX_ERR_FORMAT, "%s is not a finite number", field);
    *out = (float)v;
    return LX_OK;
}

lx_status lx_jf_non_negative(const lx_jf_ctx *c, const cJSON *item, const char *field, float *out)
{
    lx_status st = lx_jf_float(c, item, field, out);
    if (st == LX_OK && *out < 0.0f)
        return lx_jf_fail(c, LX_ERR_INVALID, "%s %g is negative", field, *out);
    return st;
}

lx_status lx_jf_vec3(const lx_jf_ctx *c, const cJSON *item, const char *field, lx_vec3 *out)
{
    if (!cJSON_IsArray(item))
        return lx_jf_fail(c, LX_ERR_FORMAT, "%s must be an array of 3 numbers", field);
    int n = cJSON_GetArraySize(item);
    if (n != 3)
        return lx_jf_fail(c, LX_ERR_FORMAT, "%s must be an array of 3 numbers, not %d", field, n);
    float v[3];
    int i = 0;
    for (const cJSON *e = item->child; e; e = e->next, i++) {
        char name[48];
        snprintf(name, sizeof name, "%s[%d]", field, i);
        lx_status st = lx_jf_float(c, e, name, &v[i]);
        if (st != LX_OK)
            return st;
    }
    *out = lx_v3(v[0], v[1], v[2]);
    return LX_OK;
}

/* A direction-like vector of any non-zero length, normalized; *raw keeps
 * the values as given (for messages). */
lx_status lx_jf_unit_vec3(const lx_jf_ctx *c, const cJSON *item, const char *field, lx_vec3 *out,
                          lx_vec3 *raw)
{
    lx_vec3 d;
    lx_status st = lx_jf_vec3(c, item, field, &d);
    if (st != LX_OK)
        return st;
    /* The length in float can overflow even for finite components. */
    double len = sqrt((double)d.x * d.x + (double)d.y * d.y + (double)d.z * d.z);
    if (!(len > 1e-20))
        return lx_jf_fail(c, LX_ERR_INVALID, "%s [%g, %g, %g] has zero length", field, d.x, d.y,
                          d.z);
    *out = lx_v3((float)(d.x / len), (float)(d.y / len), (float)(d.z / len));
    if (raw)
        *raw = d;
    return LX_OK;
}

lx_status lx_jf_color(const lx_jf_ctx *c, const cJSON *item, const char *field, lx_vec3 *out)
{
    lx_status st = lx_jf_vec3(c, item, field, out);
    if (st == LX_OK && (out->x < 0.0f || out->y < 0.0f || out->z < 0.0f))
        return lx_jf_fail(c, LX_ERR_INVALID, "%s [%g, %g, %g] has a negative component", field,
                          out->x, out->y, out->z);
    return st;
}

lx_status lx_jf_string(const lx_jf_ctx *c, const cJSON *item, const char *field, const char **out)
{
    if (!cJSON_IsString(item) || !item->valuestring)
        return lx_jf_fail(c, LX_ERR_FORMAT, "%s must be a string", field);
    *out = item->valuestring;
    return LX_OK;
}

/* Maps a string to one of the names; fails listing the accepted ones. */
lx_status lx_jf_enum(const lx_jf_ctx *c, const cJSON *item, const char *field,
                     const char *const *names, int count, int *out)
{
    const char *s = NULL;
    lx_status st = lx_jf_string(c, item, field, &s);
    if (st != LX_OK)
        return st;
    for (int i = 0; i < count; i++)
        if (strcmp(s, names[i]) == 0) {
            *out = i;
            return LX_OK;
        }
    char list[128] = "";
    for (int i = 0; i < count; i++) {
        strncat(list, i ? ", " : "", sizeof list - strlen(list) - 1);
        strncat(list, names[i], sizeof list - strlen(list) - 1);
    }
    return lx_jf_fail(c, LX_ERR_FORMAT, "unknown %s '%.40s' (expected %s)", field, s, list);
}

/* Every key of obj must be in allowed, once. An object has at most as many
 * keys as allowed before this fails, so the duplicate scan stays short. */
lx_status lx_jf_check_keys(const lx_jf_ctx *c, const cJSON *obj, const char *const *allowed,
                           int count)
{
    for (const cJSON *e = obj->child; e; e = e->next) {
        const char *key = e->string ? e->string : "";
        bool known = false;
        for (int i = 0; i < count && !known; i++)
            known = strcmp(key, allowed[i]) == 0;
        if (!known)
            return lx_jf_fail(c, LX_ERR_FORMAT, "unknown key '%.40s'", key);
        for (const cJSON *p = obj->child; p != e; p = p->next)
            if (strcmp(p->string, key) == 0)
                return lx_jf_fail(c, LX_ERR_FORMAT, "key '%s' appears twice", key);
    }
    return LX_OK;
}

/* A path the file gives, relative to the file's folder (malloc'd). */
lx_status lx_jf_relative_path(const lx_jf_ctx *c, const char *field, const char *rel, char **out)
{
    *out = NULL;
    char *dir = lx_path_dirname(c->file);
    char *path = dir ? lx_path_join(dir, rel) : NULL;
    if (!path) {
        free(dir);
        return lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
    }
    char what[160];
    snprintf(what, sizeof what, "%s%s%s", c->where, c->where[0] ? ": " : "", field);
    lx_status st = lx_path_confine(c->file, what, rel, dir, path, c->allow_any_path);
    free(dir);
    if (st != LX_OK) {
        free(path);
        return st;
    }
    *out = path;
    return LX_OK;
}
