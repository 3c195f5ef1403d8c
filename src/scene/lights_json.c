/* The luxel lights JSON (docs/lights-json.md): scene ambient plus a list of
 * lights in Filament's physical units or the classic model of the
 * per-texel lighting article, with its shadow modes and per-light ambient,
 * and area lights (sphere, disk, rect, tube; a point light with a radius
 * is a sphere, as in Filament). Parsed with cJSON; every key, type, length and
 * value is checked, and nothing changes in the scene unless the whole file
 * is valid. */
#include "json_fields.h"
#include "lights_json_internal.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LX_LIGHTS_JSON_MAX ((size_t)64 << 20)

/* ---- parsing the text -------------------------------------------------- */

/* Parses size bytes (not necessarily NUL-terminated) into *root. */
static lx_status parse_json(const char *file, const char *text, size_t size, cJSON **root)
{
    *root = NULL;
    if (size > LX_LIGHTS_JSON_MAX)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: %zu bytes is more than the 64 MiB a lights file may have", file, size);
    return lx_json_parse_text(file, text, size, root);
}

/* ---- lights by name: the file's own lights, then the scene's ----------- */

typedef struct name_table {
    int32_t *slots; /* >= 0: pending light; < 0: scene light -(i + 1); 0 entries unused */
    const char **names;
    size_t mask;
} name_table;

static uint32_t hash_name(const char *s)
{
    uint32_t h = 2166136261u; /* FNV-1a */
    for (; *s; s++)
        h = (h ^ (uint8_t)*s) * 16777619u;
    return h;
}

static lx_status table_init(name_table *t, size_t capacity)
{
    size_t n = 16;
    while (n < capacity * 2)
        n *= 2;
    t->slots = malloc(n * sizeof *t->slots);
    t->names = calloc(n, sizeof *t->names);
    t->mask = n - 1;
    if (!t->slots || !t->names)
        return LX_ERR_NOMEM;
    return LX_OK;
}

static void table_free(name_table *t)
{
    free(t->slots);
    free(t->names);
}

/* Sets name -> value (the name's storage must outlive the table). */
static void table_put(name_table *t, const char *name, int32_t value)
{
    size_t i = hash_name(name) & t->mask;
    while (t->names[i] && strcmp(t->names[i], name) != 0)
        i = (i + 1) & t->mask;
    t->names[i] = name;
    t->slots[i] = value;
}

static bool table_get(const name_table *t, const char *name, int32_t *value)
{
    size_t i = hash_name(name) & t->mask;
    for (; t->names[i]; i = (i + 1) & t->mask)
        if (strcmp(t->names[i], name) == 0) {
            *value = t->slots[i];
            return true;
        }
    return false;
}

/* ---- one light ---------------------------------------------------------- */

static const char *const light_keys[] = {"name",        "type",
                                         "position",    "direction",
                                         "color",       "intensity",
                                         "unit",        "spot_conversion",
                                         "range",       "inner_angle",
                                         "outer_angle", "shadow",
                                         "blur_power",  "blur_multiplier",
                                         "model",       "ambient",
                                         "dynamic",     "srgb",
                                         "temperature", "radius",
                                         "width",       "height",
                                         "up",          "samples",
                                         "ies",         "masked",
                                         "length",      "multiplier"};
/* Indexed by lx_light_type and lx_shadow_mode. */
static const char *const type_names[] = {"point", "spot", "directional", "sphere",
                                         "disk",  "rect", "tube"};
static const char *const shadow_names[] = {"hard", "none", "blur", "soft"};
static const char *const model_names[] = {"physical", "classic"};
static const char *const conversion_names[] = {"pi", "cone"};

/* Repeats the light module's "light 'key': problem" message as "file:
 * lights[i] ('key'): problem": where already names the light. */
static lx_status restate(const lx_jf_ctx *c, lx_status st, const lx_light *l)
{
    char label[LX_LIGHT_NAME_MAX + 24], msg[512];
    if (l->name[0])
        snprintf(label, sizeof label, "light '%s': ", l->name);
    else
        snprintf(label, sizeof label, "light (unnamed): ");
    const char *text = lx_last_error();
    size_t n = strlen(label);
    snprintf(msg, sizeof msg, "%s", strncmp(text, label, n) == 0 ? text + n : text);
    return lx_jf_fail(c, st, "%s", msg);
}

/* ---- area lights ---------------------------------------------------------- */

static bool is_area_type(lx_light_type t)
{
    return t == LX_LIGHT_SPHERE || t == LX_LIGHT_DISK || t == LX_LIGHT_RECT || t == LX_LIGHT_TUBE;
}

static bool has_radius(lx_light_type t)
{
    return t == LX_LIGHT_SPHERE || t == LX_LIGHT_DISK || t == LX_LIGHT_TUBE;
}

/* The unit a value without "unit" is in: candela, lux or nits; a tube's
 * depends on its radius (nits, or candela when linear), so it is left to
 * lx_light_intensity_to_native. */
static lx_light_unit native_unit(lx_light_type t)
{
    return t == LX_LIGHT_DIRECTIONAL ? LX_UNIT_LUX
           : t == LX_LIGHT_TUBE      ? LX_UNIT_DEFAULT
           : is_area_type(t)         ? LX_UNIT_NIT
                                     : LX_UNIT_CANDELA;
}

/* What an lx_light's intensity means: lux, candela, nits or, for a linear
 * tube, candela per metre. */
typedef enum { KIND_LUX, KIND_CANDELA, KIND_NIT, KIND_CANDELA_PER_METRE } intensity_kind;

static intensity_kind kind_of(const lx_light *l)
{
    if (l->type == LX_LIGHT_DIRECTIONAL)
        return KIND_LUX;
    if (l->type == LX_LIGHT_TUBE && !(l->radius > 0.0f))
        return KIND_CANDELA_PER_METRE;
    return is_area_type(l->type) ? KIND_NIT : KIND_CANDELA;
}

/* Changes l's type; the sizes the new type uses and the old one did not
 * (or does not share) come from the new type's defaults. */
static void change_type(lx_light *l, lx_light_type type)
{
    lx_light d = lx_light_defaults(type);
    if (!(has_radius(l->type) && has_radius(type)))
        l->radius = d.radius;
    if (type != LX_LIGHT_TUBE)
        l->length = 0.0f;
    else if (l->type != LX_LIGHT_TUBE)
        l->length = d.length;
    if (!(l->type == LX_LIGHT_RECT && type == LX_LIGHT_RECT)) {
        l->width = d.width;
        l->height = d.height;
        l->up = d.up;
    }
    l->type = type;
}

/* Unit vectors a and b are (anti)parallel, too close to fix a rect's
 * rotation. */
static bool parallel(lx_vec3 a, lx_vec3 b)
{
    return !(lx_length(lx_cross(a, b)) > 1e-4f);
}

/* A rect's up when the file gives none: +Y, or +Z for a rect facing
 * straight up or down. */
static lx_vec3 default_up(lx_vec3 direction)
{
    lx_vec3 y = lx_v3(0.0f, 1.0f, 0.0f);
    return parallel(y, direction) ? lx_v3(0.0f, 0.0f, 1.0f) : y;
}

/* The keys of area lights: radius (a point light given one becomes a
 * sphere), width, height, up, samples. new_shape: the light is new or
 * its type changed in this entry, so a rect gets the default up. */
static lx_status read_area(const lx_jf_ctx *c, const cJSON *obj, bool new_shape, lx_light *l)
{
    lx_status st;
    const cJSON *it;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "radius"))) {
        float r;
        if ((st = lx_jf_non_negative(c, it, "radius", &r)) != LX_OK)
            return st;
        if (l->type == LX_LIGHT_POINT && r > 0.0f) {
            change_type(l, LX_LIGHT_SPHERE); /* a point light is a sphere of radius 0 */
            new_shape = true;
        }
        if (l->type != LX_LIGHT_POINT && !has_radius(l->type))
            return lx_jf_fail(c, LX_ERR_INVALID,
                              "radius is for sphere, disk, tube and point lights, not a %s light",
                              lx_light_type_name(l->type));
        if (has_radius(l->type) && l->type != LX_LIGHT_TUBE && !(r > 0.0f))
            return lx_jf_fail(c, LX_ERR_INVALID, "radius %g must be above 0 for a %s light", r,
                              lx_light_type_name(l->type));
        if (has_radius(l->type))
            l->radius = r;
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "length"))) {
        if (l->type != LX_LIGHT_TUBE)
            return lx_jf_fail(c, LX_ERR_INVALID, "length is for tube lights, not a %s light",
                              lx_light_type_name(l->type));
        if ((st = lx_jf_non_negative(c, it, "length", &l->length)) != LX_OK)
            return st;
    }
    if (l->type == LX_LIGHT_TUBE && !(l->radius > 0.0f) && !(l->length > 0.0f))
        return lx_jf_fail(c, LX_ERR_INVALID,
                          "a tube with radius 0 (a linear light) needs a length above 0");
    static const char *const sizes[] = {"width", "height"};
    for (int i = 0; i < 2; i++) {
        if (!(it = cJSON_GetObjectItemCaseSensitive(obj, sizes[i])))
            continue;
        if (l->type != LX_LIGHT_RECT)
            return lx_jf_fail(c, LX_ERR_INVALID, "%s is for rect lights, not a %s light", sizes[i],
                              lx_light_type_name(l->type));
        float v;
        if ((st = lx_jf_float(c, it, sizes[i], &v)) != LX_OK)
            return st;
        if (!(v > 0.0f))
            return lx_jf_fail(c, LX_ERR_INVALID, "%s %g must be above 0", sizes[i], v);
        *(i == 0 ? &l->width : &l->height) = v;
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "up"))) {
        /* a rect's rotation, or the 0 deg plane of a point or spot's profile */
        bool profiled = cJSON_GetObjectItemCaseSensitive(obj, "ies") || l->profile;
        if (l->type != LX_LIGHT_RECT &&
            !(profiled && (l->type == LX_LIGHT_POINT || l->type == LX_LIGHT_SPOT)))
            return lx_jf_fail(
                c, LX_ERR_INVALID,
                "up is for rect lights and lights with an ies profile, not a %s light",
                lx_light_type_name(l->type));
        lx_vec3 up, raw;
        if ((st = lx_jf_unit_vec3(c, it, "up", &up, &raw)) != LX_OK)
            return st;
        if (parallel(up, l->direction))
            return lx_jf_fail(c, LX_ERR_INVALID,
                              "up [%g, %g, %g] is parallel to direction [%g, %g, %g]", raw.x, raw.y,
                              raw.z, l->direction.x, l->direction.y, l->direction.z);
        l->up = up;
    } else if (l->type == LX_LIGHT_RECT && (new_shape || parallel(l->up, l->direction))) {
        /* An override that turns the rect toward its old up picks the
         * default again rather than failing. */
        l->up = default_up(l->direction);
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "samples"))) {
        if (!is_area_type(l->type))
            return lx_jf_fail(
                c, LX_ERR_INVALID,
                "samples is for area lights (sphere, disk, rect, tube), not a %s light",
                lx_light_type_name(l->type));
        if (!cJSON_IsNumber(it))
            return lx_jf_fail(c, LX_ERR_FORMAT, "samples must be a whole number");
        double v = it->valuedouble;
        if (!isfinite(v) || v != floor(v))
            return lx_jf_fail(c, LX_ERR_FORMAT, "samples %g is not a whole number", v);
        if (v < 1.0 || v > (double)LX_MAX_LIGHT_SAMPLES)
            return lx_jf_fail(c, LX_ERR_INVALID, "samples %g is outside 1..%u", v,
                              LX_MAX_LIGHT_SAMPLES);
        l->samples = (uint32_t)v;
    }
    return LX_OK;
}

/* The intensity of a light whose type changed between punctual (cd), area
 * (nt) and linear (cd/m) without a new "intensity": the same candela along
 * the axis (a tube: across it), through the area the light shows there
 * (lx_area_light_projected_area) or along a linear tube's length. */
static lx_status carry_intensity(const lx_jf_ctx *c, const lx_light *before, lx_light *l)
{
    intensity_kind from = kind_of(before), to = kind_of(l);
    if (from == to || from == KIND_LUX || to == KIND_LUX)
        return LX_OK;
    double cd = before->intensity;
    if (from == KIND_NIT)
        cd *= lx_area_light_projected_area(before);
    else if (from == KIND_CANDELA_PER_METRE)
        cd *= before->length;
    if (!((float)cd <= 3.4028234663852886e38f))
        return lx_jf_fail(c, LX_ERR_INVALID, "intensity %g overflows as candela",
                          before->intensity);
    if (to == KIND_CANDELA) {
        l->intensity = (float)cd;
        return LX_OK;
    }
    lx_status st = lx_light_intensity_to_native(l, (float)cd, LX_UNIT_CANDELA, LX_SPOT_POWER_PI,
                                                &l->intensity);
    return st == LX_OK ? LX_OK : restate(c, st, l);
}

/* "ies" (a path relative to this file), "masked" and "multiplier":
 * Filament's photometric lights. A masked profile keeps its shape and takes
 * the light's intensity as its average (lumens / 4 pi); an unmasked one
 * keeps its own candela times the multiplier (a multiplier on a masked
 * profile is an error, not ignored). Runs after the intensity is known. */
static lx_status read_profile(lx_jf_ctx *c, const cJSON *obj, lx_light *l)
{
    lx_status st;
    const cJSON *ies = cJSON_GetObjectItemCaseSensitive(obj, "ies");
    const cJSON *masked_item = cJSON_GetObjectItemCaseSensitive(obj, "masked");
    const cJSON *mult_item = cJSON_GetObjectItemCaseSensitive(obj, "multiplier");
    if (!ies) {
        if ((masked_item || mult_item) && !l->profile)
            return lx_jf_fail(c, LX_ERR_FORMAT, "'masked' and 'multiplier' need an 'ies' profile");
        if (!masked_item && !mult_item)
            return LX_OK;
    }
    if (l->type != LX_LIGHT_POINT && l->type != LX_LIGHT_SPOT)
        return lx_jf_fail(c, LX_ERR_INVALID,
                          "ies profiles go on point and spot lights, not a %s light",
                          lx_light_type_name(l->type));
    if (ies) {
        const char *rel = NULL;
        if ((st = lx_jf_string(c, ies, "ies", &rel)) != LX_OK)
            return st;
        char *path = NULL;
        if ((st = lx_jf_relative_path(c, "ies", rel, &path)) != LX_OK)
            return st;
        lx_ies_profile *profile = NULL;
        st = lx_ies_load(path, &profile);
        free(path);
        if (st != LX_OK) {
            char where[300];
            snprintf(where, sizeof where, "%s: %s: ies", c->file, c->where);
            lx_error_prefix(where);
            return st;
        }
        lx_ies_profile **list =
            realloc(c->profiles, sizeof(lx_ies_profile *) * (c->profile_count + 1));
        if (!list) {
            lx_ies_free(profile);
            return lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
        }
        c->profiles = list;
        c->profiles[c->profile_count++] = profile;
        l->profile = profile;
    }
    bool masked = false;
    if (masked_item) {
        if (!cJSON_IsBool(masked_item))
            return lx_jf_fail(c, LX_ERR_FORMAT, "masked must be true or false");
        masked = cJSON_IsTrue(masked_item);
    }
    if (masked && mult_item)
        return lx_jf_fail(
            c, LX_ERR_FORMAT,
            "'multiplier' scales an unmasked profile; a masked one takes its scale from "
            "'intensity'");
    if (masked) {
        double lumens = lx_ies_total_lumens(l->profile);
        if (!(lumens > 0.0))
            return lx_jf_fail(c, LX_ERR_INVALID,
                              "a masked ies profile needs some light (it has 0 lm)");
        l->profile_scale = (float)(l->intensity / (lumens / (4.0 * 3.14159265358979323846)));
    } else {
        float multiplier = 1.0f;
        if (mult_item &&
            (st = lx_jf_non_negative(c, mult_item, "multiplier", &multiplier)) != LX_OK)
            return st;
        l->profile_scale = multiplier;
    }
    return LX_OK;
}

/* Fills out from obj; a light named like one in names (earlier in the file
 * or already in the scene) starts from that light. */
static lx_status read_light(lx_jf_ctx *c, const cJSON *obj, const name_table *names,
                            const lx_light *pending, const lx_scene *scene, lx_light *out)
{
    lx_status st;
    const cJSON *name_item = cJSON_GetObjectItemCaseSensitive(obj, "name");
    const char *name = "";
    if (name_item) {
        if ((st = lx_jf_string(c, name_item, "name", &name)) != LX_OK)
            return st;
        if (strlen(name) >= LX_LIGHT_NAME_MAX)
            return lx_jf_fail(c, LX_ERR_INVALID, "name '%.20s...' is longer than %d bytes", name,
                              LX_LIGHT_NAME_MAX - 1);
        size_t len = strlen(c->where);
        snprintf(c->where + len, sizeof c->where - len, " ('%s')", name);
    }
    const cJSON *type_item = cJSON_GetObjectItemCaseSensitive(obj, "type");
    if ((st = lx_jf_check_keys(c, obj, light_keys, LX_JF_COUNT(light_keys))) != LX_OK)
        return st;

    /* An override by name starts from the existing light: only the keys
     * the file gives change. */
    int32_t found = 0;
    bool is_override = name[0] && table_get(names, name, &found);
    int type = 0;
    if (type_item && (st = lx_jf_enum(c, type_item, "type", type_names, LX_JF_COUNT(type_names),
                                      &type)) != LX_OK)
        return st;
    lx_light l;
    bool new_shape = !is_override; /* a rect then gets the default up */
    if (is_override) {
        l = found >= 0 ? pending[found] : scene->lights[-(found + 1)];
    } else {
        if (!type_item)
            return lx_jf_fail(
                c, LX_ERR_FORMAT,
                "missing 'type' (point, spot, directional, sphere, disk, rect or tube)");
        l = lx_light_defaults((lx_light_type)type);
        memcpy(l.name, name, strlen(name) + 1);
    }
    /* The light as it was (or a new light's defaults), for an intensity
     * that has to follow a change between candela and nits. */
    const lx_light before = l;
    if (is_override && type_item && l.type != (lx_light_type)type) {
        change_type(&l, (lx_light_type)type);
        new_shape = true;
    }
    /* The type as written decides the default unit: a point light given a
     * radius becomes a sphere below but still counts in candela. */
    const lx_light_type written_type = l.type;

    const cJSON *it;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "position"))) {
        if ((st = lx_jf_vec3(c, it, "position", &l.position)) != LX_OK)
            return st;
    } else if (!is_override && l.type != LX_LIGHT_DIRECTIONAL) {
        return lx_jf_fail(c, LX_ERR_FORMAT, "missing 'position' for a %s light",
                          lx_light_type_name(l.type));
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "direction"))) {
        if ((st = lx_jf_unit_vec3(c, it, "direction", &l.direction, NULL)) != LX_OK)
            return st;
    } else if (!is_override && l.type != LX_LIGHT_POINT && l.type != LX_LIGHT_SPHERE) {
        return lx_jf_fail(c, LX_ERR_FORMAT, "missing 'direction' for a %s light",
                          lx_light_type_name(l.type));
    }
    /* one way to give the colour: linear RGB, sRGB-encoded, or kelvin */
    const cJSON *color_items[3] = {cJSON_GetObjectItemCaseSensitive(obj, "color"),
                                   cJSON_GetObjectItemCaseSensitive(obj, "srgb"),
                                   cJSON_GetObjectItemCaseSensitive(obj, "temperature")};
    if (!!color_items[0] + !!color_items[1] + !!color_items[2] > 1)
        return lx_jf_fail(c, LX_ERR_FORMAT,
                          "give one of 'color', 'srgb' and 'temperature', not several");
    if (color_items[0] && (st = lx_jf_color(c, color_items[0], "color", &l.color)) != LX_OK)
        return st;
    if (color_items[1]) {
        lx_vec3 srgb;
        if ((st = lx_jf_color(c, color_items[1], "srgb", &srgb)) != LX_OK)
            return st;
        if (srgb.x > 1.0f || srgb.y > 1.0f || srgb.z > 1.0f)
            return lx_jf_fail(c, LX_ERR_INVALID, "srgb [%g, %g, %g] has a component above 1",
                              srgb.x, srgb.y, srgb.z);
        l.color = lx_srgb_color_to_linear(srgb);
    }
    if (color_items[2]) {
        float kelvin;
        if ((st = lx_jf_float(c, color_items[2], "temperature", &kelvin)) != LX_OK)
            return st;
        if (lx_temperature_to_rgb(kelvin, &l.color) != LX_OK)
            return lx_jf_fail(c, LX_ERR_INVALID, "temperature %g K is outside %g..%g K",
                              (double)kelvin, (double)LX_MIN_TEMPERATURE,
                              (double)LX_MAX_TEMPERATURE);
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "ambient")) &&
        (st = lx_jf_color(c, it, "ambient", &l.ambient)) != LX_OK)
        return st;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "range")) &&
        (st = lx_jf_non_negative(c, it, "range", &l.range)) != LX_OK)
        return st;
    float deg;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "inner_angle"))) {
        if ((st = lx_jf_non_negative(c, it, "inner_angle", &deg)) != LX_OK)
            return st;
        l.inner_angle = LX_DEG2RAD(deg);
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "outer_angle"))) {
        if ((st = lx_jf_non_negative(c, it, "outer_angle", &deg)) != LX_OK)
            return st;
        l.outer_angle = LX_DEG2RAD(deg);
    }
    int e = 0;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "shadow"))) {
        if ((st = lx_jf_enum(c, it, "shadow", shadow_names, LX_JF_COUNT(shadow_names), &e)) !=
            LX_OK)
            return st;
        l.shadow = (lx_shadow_mode)e;
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "model"))) {
        if ((st = lx_jf_enum(c, it, "model", model_names, LX_JF_COUNT(model_names), &e)) != LX_OK)
            return st;
        l.model = (lx_falloff_model)e;
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "blur_power")) &&
        (st = lx_jf_non_negative(c, it, "blur_power", &l.blur_power)) != LX_OK)
        return st;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "blur_multiplier")) &&
        (st = lx_jf_non_negative(c, it, "blur_multiplier", &l.blur_multiplier)) != LX_OK)
        return st;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "dynamic"))) {
        if (!cJSON_IsBool(it))
            return lx_jf_fail(c, LX_ERR_FORMAT, "dynamic must be true or false");
        l.dynamic = cJSON_IsTrue(it);
    }

    /* Sizes before units: they need them (and a radius can make a point
     * light a sphere). */
    if ((st = read_area(c, obj, new_shape, &l)) != LX_OK)
        return st;
    bool area = is_area_type(l.type);
    if (l.shadow == LX_SHADOW_SOFT && !area)
        return lx_jf_fail(c, LX_ERR_INVALID,
                          "shadow 'soft' needs an area light (sphere, disk, rect, tube, or a point "
                          "light with a radius), not a %s light",
                          lx_light_type_name(l.type));

    /* Units last: lumens over a spot's cone need the final outer angle, an
     * area light's lumens or candela its final size. */
    lx_spot_conversion conv = LX_SPOT_POWER_PI;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "spot_conversion"))) {
        if ((st = lx_jf_enum(c, it, "spot_conversion", conversion_names,
                             LX_JF_COUNT(conversion_names), &e)) != LX_OK)
            return st;
        conv = (lx_spot_conversion)e;
    }
    lx_light_unit unit = LX_UNIT_DEFAULT;
    const cJSON *unit_item = cJSON_GetObjectItemCaseSensitive(obj, "unit");
    if (unit_item) {
        const char *s = NULL;
        if ((st = lx_jf_string(c, unit_item, "unit", &s)) != LX_OK)
            return st;
        unit = lx_light_unit_from_string(s);
        if (unit == LX_UNIT_DEFAULT)
            return lx_jf_fail(c, LX_ERR_FORMAT,
                              "unknown unit '%.40s' (expected cd, lm, W, lx or nt)", s);
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "intensity"))) {
        float value;
        if ((st = lx_jf_non_negative(c, it, "intensity", &value)) != LX_OK)
            return st;
        if ((unit == LX_UNIT_LUX || (unit == LX_UNIT_NIT && !area)) &&
            l.type != LX_LIGHT_DIRECTIONAL)
            return lx_jf_fail(c, LX_ERR_INVALID, "unit: %s lights take %s, not %s",
                              lx_light_type_name(l.type), area ? "nt, cd, lm or W" : "cd, lm or W",
                              lx_light_unit_symbol(unit));
        if (unit != LX_UNIT_DEFAULT && unit != LX_UNIT_LUX && l.type == LX_LIGHT_DIRECTIONAL)
            return lx_jf_fail(c, LX_ERR_INVALID, "unit: directional lights take lux, not %s",
                              lx_light_unit_symbol(unit));
        if (unit == LX_UNIT_DEFAULT)
            unit = native_unit(written_type);
        if ((st = lx_light_intensity_to_native(&l, value, unit, conv, &l.intensity)) != LX_OK)
            return restate(c, st, &l);
    } else if (unit_item) {
        return lx_jf_fail(c, LX_ERR_FORMAT, "'unit' is given without 'intensity'");
    } else if ((st = carry_intensity(c, &before, &l)) != LX_OK) {
        return st;
    }

    if ((st = read_profile(c, obj, &l)) != LX_OK)
        return st;
    if ((st = lx_light_validate(&l)) != LX_OK)
        return restate(c, st, &l);
    *out = l;
    return LX_OK;
}

/* ---- the file ----------------------------------------------------------- */

static const char *const root_keys[] = {"ambient", "lights", "sky", "materials", "nodes"};
static const char *const sky_keys[] = {"environment", "intensity", "shadows", "samples"};

/* "sky": {"environment": path relative to the file, "intensity",
 * "shadows", "samples"}; the environment is named here, loaded by whoever
 * bakes. */
static lx_status read_sky(lx_jf_ctx *c, const cJSON *obj, lx_scene_sky *sky)
{
    snprintf(c->where, sizeof c->where, "sky");
    if (!cJSON_IsObject(obj))
        return lx_jf_fail(c, LX_ERR_FORMAT, "must be an object with \"environment\"");
    lx_status st = lx_jf_check_keys(c, obj, sky_keys, LX_JF_COUNT(sky_keys));
    if (st != LX_OK)
        return st;
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, "environment");
    const char *rel = NULL;
    if (!it)
        return lx_jf_fail(c, LX_ERR_FORMAT, "missing 'environment' (an image file)");
    if ((st = lx_jf_string(c, it, "environment", &rel)) != LX_OK)
        return st;
    if (!rel[0])
        return lx_jf_fail(c, LX_ERR_FORMAT, "environment is an empty path");
    sky->intensity = 1.0f;
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "intensity"))) {
        if ((st = lx_jf_non_negative(c, it, "intensity", &sky->intensity)) != LX_OK)
            return st;
        if (!(sky->intensity > 0.0f))
            return lx_jf_fail(c, LX_ERR_INVALID,
                              "intensity must be above 0 (leave \"sky\" out for none)");
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "shadows"))) {
        if (!cJSON_IsBool(it))
            return lx_jf_fail(c, LX_ERR_FORMAT, "shadows must be true or false");
        sky->shadows = cJSON_IsTrue(it);
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(obj, "samples"))) {
        double v = cJSON_IsNumber(it) ? it->valuedouble : NAN;
        if (!isfinite(v) || v != floor(v))
            return lx_jf_fail(c, LX_ERR_FORMAT, "samples must be a whole number");
        if (v < 1.0 || v > (double)LX_MAX_SKY_SAMPLES)
            return lx_jf_fail(c, LX_ERR_INVALID, "samples %g is outside 1..%u", v,
                              LX_MAX_SKY_SAMPLES);
        sky->samples = (uint32_t)v;
    }
    return lx_jf_relative_path(c, "environment", rel, &sky->environment);
}

static lx_status apply_root(lx_scene *scene, const cJSON *root, const char *file)
{
    lx_jf_ctx c = {.file = file, .where = "", .allow_any_path = scene->allow_any_path};
    if (!cJSON_IsObject(root))
        return lx_jf_fail(&c, LX_ERR_FORMAT, "the top level must be an object with \"lights\"");
    lx_status st = lx_jf_check_keys(&c, root, root_keys, LX_JF_COUNT(root_keys));
    if (st != LX_OK)
        return st;
    const cJSON *amb = cJSON_GetObjectItemCaseSensitive(root, "ambient");
    lx_vec3 ambient = scene->ambient;
    if (amb && (st = lx_jf_color(&c, amb, "ambient", &ambient)) != LX_OK)
        return st;
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(root, "lights");
    size_t count = 0;
    if (list) {
        if (!cJSON_IsArray(list))
            return lx_jf_fail(&c, LX_ERR_FORMAT, "lights must be an array of objects");
        for (const cJSON *e = list->child; e; e = e->next)
            count++;
    }
    if (count > INT32_MAX / 4)
        return lx_jf_fail(&c, LX_ERR_INVALID, "%zu lights are too many", count);
    /* the sky last before the lights: from here on every exit frees it */
    const cJSON *sky_item = cJSON_GetObjectItemCaseSensitive(root, "sky");
    lx_scene_sky sky = {0};
    if (sky_item && (st = read_sky(&c, sky_item, &sky)) != LX_OK) {
        free(sky.environment);
        return st;
    }
    const cJSON *mat_item = cJSON_GetObjectItemCaseSensitive(root, "materials");
    lx_lj_materials *mats = NULL;
    if (mat_item && (st = lx_lj_materials_read(&c, mat_item, scene, &mats)) != LX_OK) {
        free(sky.environment);
        return st;
    }
    const cJSON *node_item = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    lx_lj_nodes *nodes = NULL;
    if (node_item && (st = lx_lj_nodes_read(&c, node_item, scene, &nodes)) != LX_OK) {
        free(sky.environment);
        lx_lj_materials_free(mats);
        return st;
    }
    c.where[0] = '\0';
    lx_light *pending = malloc((count ? count : 1) * sizeof *pending);
    name_table names = {0};
    if (!pending || table_init(&names, count + scene->light_count) != LX_OK) {
        free(pending);
        table_free(&names);
        free(sky.environment);
        lx_lj_materials_free(mats);
        lx_lj_nodes_free(nodes);
        return lx_jf_fail(&c, LX_ERR_NOMEM, "out of memory for %zu lights", count);
    }
    for (uint32_t i = 0; i < scene->light_count; i++)
        if (scene->lights[i].name[0])
            table_put(&names, scene->lights[i].name, -(int32_t)i - 1);

    size_t i = 0;
    for (const cJSON *e = list ? list->child : NULL; e && st == LX_OK; e = e->next, i++) {
        snprintf(c.where, sizeof c.where, "lights[%zu]", i);
        if (!cJSON_IsObject(e))
            st = lx_jf_fail(&c, LX_ERR_FORMAT, "must be an object");
        else
            st = read_light(&c, e, &names, pending, scene, &pending[i]);
        if (st == LX_OK && pending[i].name[0])
            table_put(&names, pending[i].name, (int32_t)i);
    }
    table_free(&names);
    /* profiles belong to the scene once the file is valid, else go */
    for (uint32_t k = 0; k < c.profile_count; k++)
        if (st != LX_OK || lx_scene_adopt_profile(scene, c.profiles[k]) != LX_OK)
            lx_ies_free(c.profiles[k]);
    free(c.profiles);
    if (st == LX_OK) {
        /* The whole file is valid: only now does the scene change. */
        scene->ambient = ambient;
        if (sky_item) {
            free(scene->sky.environment);
            scene->sky = sky;
            sky.environment = NULL;
        }
        lx_lj_materials_apply(mats, scene);
        lx_lj_nodes_apply(nodes, scene);
        for (i = 0; i < count && st == LX_OK; i++)
            if ((st = lx_scene_add_light(scene, &pending[i])) != LX_OK) {
                char where[160];
                snprintf(where, sizeof where, "%s: lights[%zu]", file, i);
                lx_error_prefix(where);
            }
    }
    free(pending);
    free(sky.environment);
    lx_lj_materials_free(mats);
    lx_lj_nodes_free(nodes);
    return st;
}

lx_status lx_lights_json_apply_text(lx_scene *scene, const char *text, size_t size,
                                    const char *name)
{
    if (!text)
        return lx_fail_null(__func__, "text");
    const char *file = name && name[0] ? name : "lights.json";
    if (!scene)
        return lx_fail(LX_ERR_INVALID, "%s: no scene to apply the lights to", file);
    if (!text && size > 0)
        return lx_fail(LX_ERR_INVALID, "%s: no text", file);
    cJSON *root;
    lx_status st = parse_json(file, text ? text : "", size, &root);
    if (st != LX_OK)
        return st;
    st = apply_root(scene, root, file);
    cJSON_Delete(root);
    return st;
}

lx_status lx_lights_json_apply(lx_scene *scene, const char *path)
{
    if (!scene)
        return lx_fail_null(__func__, "scene");
    if (!path)
        return lx_fail(LX_ERR_INVALID, "lights JSON: no path");
    char *text;
    size_t size;
    lx_status st = lx_read_file(path, LX_LIGHTS_JSON_MAX, &text, &size);
    if (st != LX_OK)
        return st;
    st = lx_lights_json_apply_text(scene, text, size, path);
    free(text);
    return st;
}
