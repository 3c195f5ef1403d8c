/* The 2D lights JSON (docs/light2d.md): {"ambient": [r, g, b], "lights":
 * [{"type", "position", "direction", "arc", "edge", "color" | "temperature",
 * "intensity", "radius", "falloff", "softness", "height", "shadow",
 * "self_shadow", "dynamic"}]}. Parsed with cJSON; every key, type and value
 * is checked and errors name the file, the light and the field. Colour
 * temperatures go through the light module's black-body colour. */
#include "luxel/light.h"
#include "luxel/light2d.h"
#include "core/internal.h"

#include <cjson/cJSON.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define L2_JSON_MAX ((size_t)16 << 20)

typedef struct jctx {
    const char *file;
    char where[48]; /* "lights[2]" or "" */
} jctx;

static lx_status jfail(const jctx *c, lx_status st, const char *fmt, ...) LX_PRINTF(3, 4);
static lx_status jfail(const jctx *c, lx_status st, const char *fmt, ...)
{
    char msg[384];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (c->where[0])
        return lx_fail(st, "%s: %s: %s", c->file, c->where, msg);
    return lx_fail(st, "%s: %s", c->file, msg);
}

static lx_status get_number(const jctx *c, const cJSON *it, const char *field, float *out)
{
    if (!cJSON_IsNumber(it))
        return jfail(c, LX_ERR_FORMAT, "%s must be a number", field);
    double v = it->valuedouble;
    if (!isfinite(v) || !isfinite((float)v))
        return jfail(c, LX_ERR_FORMAT, "%s is not a finite number", field);
    *out = (float)v;
    return LX_OK;
}

static lx_status get_vec(const jctx *c, const cJSON *it, const char *field, int n, float *out)
{
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != n)
        return jfail(c, LX_ERR_FORMAT, "%s must be an array of %d numbers", field, n);
    int k = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, it)
    {
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || !isfinite((float)e->valuedouble))
            return jfail(c, LX_ERR_FORMAT, "%s[%d] must be a finite number", field, k);
        out[k++] = (float)e->valuedouble;
    }
    return LX_OK;
}

static lx_status get_bool(const jctx *c, const cJSON *it, const char *field, bool *out)
{
    if (!cJSON_IsBool(it))
        return jfail(c, LX_ERR_FORMAT, "%s must be true or false", field);
    *out = cJSON_IsTrue(it);
    return LX_OK;
}

static lx_status parse_light(const jctx *c, const cJSON *obj, lx_light2d_light *out)
{
    if (!cJSON_IsObject(obj))
        return jfail(c, LX_ERR_FORMAT, "a light must be an object");
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(obj, "type");
    lx_light2d_type t = LX_LIGHT2D_POINT;
    if (type) {
        if (!cJSON_IsString(type))
            return jfail(c, LX_ERR_FORMAT, "type must be \"point\" or \"spot\"");
        if (strcmp(type->valuestring, "point") == 0)
            t = LX_LIGHT2D_POINT;
        else if (strcmp(type->valuestring, "spot") == 0)
            t = LX_LIGHT2D_SPOT;
        else
            return jfail(c, LX_ERR_FORMAT, "unknown type '%.40s' (expected point or spot)",
                         type->valuestring);
    }
    lx_light2d_light l = lx_light2d_light_defaults(t);
    bool has_position = false, has_radius = false, has_color = false, has_temperature = false;
    bool has_direction = false, has_arc = false;
    const cJSON *it;
    lx_status st = LX_OK;
    cJSON_ArrayForEach(it, obj)
    {
        const char *k = it->string;
        float v[3];
        if (strcmp(k, "type") == 0) {
            continue;
        } else if (strcmp(k, "position") == 0) {
            if ((st = get_vec(c, it, k, 2, v)) != LX_OK)
                return st;
            l.x = v[0];
            l.y = v[1];
            has_position = true;
        } else if (strcmp(k, "direction") == 0) {
            if ((st = get_vec(c, it, k, 2, v)) != LX_OK)
                return st;
            if (v[0] == 0.0f && v[1] == 0.0f)
                return jfail(c, LX_ERR_INVALID, "direction is zero");
            l.dir_x = v[0];
            l.dir_y = v[1];
            has_direction = true;
        } else if (strcmp(k, "arc") == 0) {
            if ((st = get_number(c, it, k, &l.arc)) != LX_OK)
                return st;
            if (!(l.arc > 0.0f && l.arc <= 360.0f))
                return jfail(c, LX_ERR_INVALID, "arc %g must be in (0, 360]", l.arc);
            has_arc = true;
        } else if (strcmp(k, "edge") == 0) {
            if ((st = get_number(c, it, k, &l.edge)) != LX_OK)
                return st;
            if (l.edge < 0.0f)
                return jfail(c, LX_ERR_INVALID, "edge %g is negative", l.edge);
        } else if (strcmp(k, "color") == 0) {
            if ((st = get_vec(c, it, k, 3, v)) != LX_OK)
                return st;
            if (v[0] < 0.0f || v[1] < 0.0f || v[2] < 0.0f)
                return jfail(c, LX_ERR_INVALID, "color has a negative component");
            l.color = lx_v3(v[0], v[1], v[2]);
            has_color = true;
        } else if (strcmp(k, "temperature") == 0) {
            float kelvin;
            if ((st = get_number(c, it, k, &kelvin)) != LX_OK)
                return st;
            if (lx_temperature_to_rgb(kelvin, &l.color) != LX_OK)
                return jfail(c, LX_ERR_INVALID, "temperature %g K is outside %g..%g K", kelvin,
                             LX_MIN_TEMPERATURE, LX_MAX_TEMPERATURE);
            has_temperature = true;
        } else if (strcmp(k, "intensity") == 0) {
            if ((st = get_number(c, it, k, &l.intensity)) != LX_OK)
                return st;
            if (l.intensity < 0.0f)
                return jfail(c, LX_ERR_INVALID, "intensity %g is negative", l.intensity);
        } else if (strcmp(k, "radius") == 0) {
            if ((st = get_number(c, it, k, &l.radius)) != LX_OK)
                return st;
            if (!(l.radius > 0.0f))
                return jfail(c, LX_ERR_INVALID, "radius %g must be > 0", l.radius);
            has_radius = true;
        } else if (strcmp(k, "falloff") == 0) {
            if (!cJSON_IsString(it))
                return jfail(c, LX_ERR_FORMAT, "falloff must be \"smooth\", \"linear\" or \"none\"");
            if (strcmp(it->valuestring, "smooth") == 0)
                l.falloff = LX_FALLOFF2D_SMOOTH;
            else if (strcmp(it->valuestring, "linear") == 0)
                l.falloff = LX_FALLOFF2D_LINEAR;
            else if (strcmp(it->valuestring, "none") == 0)
                l.falloff = LX_FALLOFF2D_NONE;
            else
                return jfail(c, LX_ERR_FORMAT,
                             "unknown falloff '%.40s' (expected smooth, linear or none)",
                             it->valuestring);
        } else if (strcmp(k, "softness") == 0) {
            if ((st = get_number(c, it, k, &l.softness)) != LX_OK)
                return st;
            if (l.softness < 0.0f)
                return jfail(c, LX_ERR_INVALID, "softness %g is negative", l.softness);
        } else if (strcmp(k, "height") == 0) {
            if ((st = get_number(c, it, k, &l.height)) != LX_OK)
                return st;
            if (l.height < 0.0f)
                return jfail(c, LX_ERR_INVALID, "height %g is negative", l.height);
        } else if (strcmp(k, "shadow") == 0) {
            if ((st = get_bool(c, it, k, &l.shadow)) != LX_OK)
                return st;
        } else if (strcmp(k, "self_shadow") == 0) {
            if ((st = get_bool(c, it, k, &l.self_shadow)) != LX_OK)
                return st;
        } else if (strcmp(k, "dynamic") == 0) {
            if ((st = get_bool(c, it, k, &l.dynamic)) != LX_OK)
                return st;
        } else {
            return jfail(c, LX_ERR_FORMAT, "unknown key '%.40s'", k);
        }
    }
    if (!has_position)
        return jfail(c, LX_ERR_FORMAT, "position is missing");
    if (!has_radius)
        return jfail(c, LX_ERR_FORMAT, "radius is missing");
    if (has_color && has_temperature)
        return jfail(c, LX_ERR_FORMAT, "color and temperature are both given (one of them)");
    if (t == LX_LIGHT2D_POINT && (has_direction || has_arc))
        return jfail(c, LX_ERR_FORMAT, "%s is for spot lights, this is a point light",
                     has_direction ? "direction" : "arc");
    if (t == LX_LIGHT2D_SPOT && !has_direction)
        return jfail(c, LX_ERR_FORMAT, "direction is missing (a spot light needs one)");
    if (lx_light2d_light_validate(&l) != LX_OK) {
        char msg[256];
        snprintf(msg, sizeof msg, "%s", lx_last_error());
        return jfail(c, LX_ERR_INVALID, "%s", msg);
    }
    *out = l;
    return LX_OK;
}

/* "line L, column C" of the byte at `at`. */
static void position_of(const char *text, size_t at, size_t *line, size_t *col)
{
    *line = 1;
    *col = 1;
    for (size_t i = 0; i < at; i++) {
        if (text[i] == '\n') {
            (*line)++;
            *col = 1;
        } else {
            (*col)++;
        }
    }
}

lx_status lx_light2d_scene_parse(const char *name, const char *text, size_t size,
                                 lx_light2d_scene *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    jctx c = {.file = name ? name : "lights"};
    if (!text)
        return jfail(&c, LX_ERR_INVALID, "no text");
    if (size > L2_JSON_MAX)
        return jfail(&c, LX_ERR_FORMAT, "%zu bytes is more than the 16 MiB a lights file may have",
                     size);
    if (memchr(text, '\0', size))
        return jfail(&c, LX_ERR_FORMAT, "a NUL byte in the text, not JSON");
    char *buf = malloc(size + 1);
    if (!buf)
        return jfail(&c, LX_ERR_NOMEM, "out of memory");
    memcpy(buf, text, size);
    buf[size] = '\0';
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(buf, size + 1, &end, 1);
    if (!root) {
        size_t at = end && end >= buf && end <= buf + size ? (size_t)(end - buf) : size;
        size_t line, col;
        position_of(buf, at, &line, &col);
        bool truncated = at >= size || buf[at] == '\0';
        free(buf);
        if (truncated)
            return jfail(&c, LX_ERR_FORMAT, "line %zu: the JSON ends early (truncated?)", line);
        return jfail(&c, LX_ERR_FORMAT, "line %zu, column %zu: malformed JSON", line, col);
    }
    free(buf);
    lx_status st = LX_OK;
    if (!cJSON_IsObject(root)) {
        st = jfail(&c, LX_ERR_FORMAT, "the top level must be an object");
        goto done;
    }
    const cJSON *it;
    const cJSON *lights = NULL;
    cJSON_ArrayForEach(it, root)
    {
        if (strcmp(it->string, "ambient") == 0) {
            float v[3];
            if ((st = get_vec(&c, it, "ambient", 3, v)) != LX_OK)
                goto done;
            if (v[0] < 0.0f || v[1] < 0.0f || v[2] < 0.0f) {
                st = jfail(&c, LX_ERR_INVALID, "ambient has a negative component");
                goto done;
            }
            if (v[0] > LX_LIGHT2D_MAX_LIGHT || v[1] > LX_LIGHT2D_MAX_LIGHT ||
                v[2] > LX_LIGHT2D_MAX_LIGHT) {
                st = jfail(&c, LX_ERR_INVALID, "ambient is more than %g", LX_LIGHT2D_MAX_LIGHT);
                goto done;
            }
            out->ambient = lx_v3(v[0], v[1], v[2]);
        } else if (strcmp(it->string, "lights") == 0) {
            if (!cJSON_IsArray(it)) {
                st = jfail(&c, LX_ERR_FORMAT, "lights must be an array");
                goto done;
            }
            lights = it;
        } else {
            st = jfail(&c, LX_ERR_FORMAT, "unknown key '%.40s' (expected ambient or lights)",
                       it->string);
            goto done;
        }
    }
    if (!lights) {
        st = jfail(&c, LX_ERR_FORMAT, "lights is missing");
        goto done;
    }
    int n = cJSON_GetArraySize(lights);
    if (n > 0) {
        out->lights = calloc((size_t)n, sizeof *out->lights);
        if (!out->lights) {
            st = jfail(&c, LX_ERR_NOMEM, "out of memory for %d lights", n);
            goto done;
        }
    }
    int i = 0;
    cJSON_ArrayForEach(it, lights)
    {
        snprintf(c.where, sizeof c.where, "lights[%d]", i);
        if ((st = parse_light(&c, it, &out->lights[i])) != LX_OK)
            goto done;
        i++;
    }
    out->count = n;
done:
    cJSON_Delete(root);
    if (st != LX_OK)
        lx_light2d_scene_free(out);
    return st;
}

lx_status lx_light2d_scene_load(const char *path, lx_light2d_scene *out)
{
    if (!path)
        return lx_fail_null(__func__, "path");
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    char *text = NULL;
    size_t size = 0;
    lx_status st = lx_read_file(path, L2_JSON_MAX, &text, &size);
    if (st != LX_OK)
        return st;
    st = lx_light2d_scene_parse(path, text, size, out);
    free(text);
    return st;
}

void lx_light2d_scene_free(lx_light2d_scene *scene)
{
    if (!scene)
        return;
    free(scene->lights);
    memset(scene, 0, sizeof *scene);
}
