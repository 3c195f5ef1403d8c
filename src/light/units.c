/* Photometric units of Filament's physical light model (R. Guy and
 * M. Agopian, "Physically Based Rendering in Filament"): luminous
 * power (lm) to intensity (cd) for point lights I = P / 4pi and for spot
 * lights I = P / pi or I = P / (2pi (1 - cos outer)), watts through
 * 683 lm/W, lux for directional lights; exposure from EV100 (1 / (1.2 *
 * 2^EV100)) and EV100 from average luminance with K = 12.5; unit and enum
 * names. */
#include "luxel/light.h"
#include "core/internal.h"
#include "light_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* pi in double: M_PI is not part of C11. */
#define LX_PI_D 3.14159265358979323846

/* "light 'key'" or "light (unnamed)" for messages. */
static void light_label(const lx_light *light, char *buf, size_t size)
{
    const void *nul = memchr(light->name, '\0', sizeof light->name);
    int n = nul ? (int)((const char *)nul - light->name) : (int)sizeof light->name;
    if (n == 0)
        snprintf(buf, size, "light (unnamed)");
    else
        snprintf(buf, size, "light '%.*s'", n, light->name);
}

/* A linear tube (radius 0) carries candela per metre across its axis,
 * I_l: its intensity at alpha from the axis is I_l L sin(alpha), so its
 * power is I_l L pi^2 (the integral of sin(alpha) over the sphere). Candela
 * is the whole tube's intensity across the axis. */
static lx_status linear_to_native(const lx_light *light, const char *who, float value,
                                  lx_light_unit unit, float *native)
{
    if (unit == LX_UNIT_NIT)
        return lx_fail(LX_ERR_INVALID,
                       "%s: a linear tube (radius 0) has no area for nt; give cd, lm or W", who);
    if (unit == LX_UNIT_LUX)
        return lx_fail(LX_ERR_INVALID, "%s: tube lights take cd, lm or W, not lx", who);
    if (!(light->length > 0.0f) || !isfinite(light->length))
        return lx_fail(LX_ERR_INVALID, "%s: a linear tube needs its length first", who);
    double per_metre;
    if (unit == LX_UNIT_DEFAULT || unit == LX_UNIT_CANDELA) {
        per_metre = (double)value / light->length;
    } else {
        double lumens = unit == LX_UNIT_WATT ? (double)value * LX_LUMENS_PER_WATT : (double)value;
        per_metre = lumens / (LX_PI_D * LX_PI_D * light->length);
    }
    if (!(per_metre <= 3.4028234663852886e38))
        return lx_fail(LX_ERR_INVALID, "%s: intensity %g %s overflows as cd per metre", who, value,
                       lx_light_unit_symbol(unit));
    *native = (float)per_metre;
    return LX_OK;
}

double lx_area_light_projected_area(const lx_light *light)
{
    double r = light->radius;
    switch (light->type) {
    case LX_LIGHT_RECT:
        return (double)light->width * light->height;
    case LX_LIGHT_TUBE:
        return 2.0 * r * light->length + LX_PI_D * r * r;
    case LX_LIGHT_SPHERE:
    case LX_LIGHT_DISK:
        return LX_PI_D * r * r;
    default:
        return 0.0;
    }
}

/* Area lights carry luminance (nits): power goes through the emitting
 * area (Filament's and Frostbite's L = P / (pi A),
 * lx_area_light_luminance_from_power), candela
 * through the area seen along the axis. */
static lx_status area_to_native(const lx_light *light, const char *who, float value,
                                lx_light_unit unit, float *native)
{
    if (light->type == LX_LIGHT_TUBE && !(light->radius > 0.0f))
        return linear_to_native(light, who, value, unit, native);
    if (unit == LX_UNIT_DEFAULT || unit == LX_UNIT_NIT) {
        *native = value;
        return LX_OK;
    }
    if (unit == LX_UNIT_LUX)
        return lx_fail(LX_ERR_INVALID, "%s: %s lights take nt, cd, lm or W, not lx", who,
                       lx_light_type_name(light->type));
    lx_area_shape shape = light->type == LX_LIGHT_SPHERE ? LX_AREA_SPHERE
                          : light->type == LX_LIGHT_DISK ? LX_AREA_DISK
                          : light->type == LX_LIGHT_TUBE ? LX_AREA_TUBE
                                                         : LX_AREA_RECT;
    if (unit == LX_UNIT_CANDELA) {
        double projected = lx_area_light_projected_area(light);
        if (!(projected > 0.0) || !isfinite(projected))
            return lx_fail(LX_ERR_INVALID, "%s: candela needs the light's size first", who);
        *native = (float)(value / projected);
        return LX_OK;
    }
    float lumens = unit == LX_UNIT_WATT ? value * LX_LUMENS_PER_WATT : value;
    lx_status st = lx_area_light_luminance_from_power(shape, lumens, light->radius, light->length,
                                                      light->width, light->height, native);
    if (st != LX_OK)
        lx_error_prefix(who);
    return st;
}

lx_status lx_light_intensity_to_native(const lx_light *light, float value, lx_light_unit unit,
                                       lx_spot_conversion spot_conversion, float *native)
{
    if (!light || !native)
        return lx_fail(LX_ERR_INVALID, "light: NULL pointer");
    char who[LX_LIGHT_NAME_MAX + 16];
    light_label(light, who, sizeof who);
    if (!isfinite(value))
        return lx_fail(LX_ERR_INVALID, "%s: intensity is not finite", who);
    if (value < 0.0f)
        return lx_fail(LX_ERR_INVALID, "%s: intensity %g is negative", who, value);
    if ((unsigned)unit > (unsigned)LX_UNIT_NIT)
        return lx_fail(LX_ERR_INVALID, "%s: unit %d is not a light unit", who, (int)unit);

    if (light->type == LX_LIGHT_DIRECTIONAL) {
        if (unit != LX_UNIT_DEFAULT && unit != LX_UNIT_LUX)
            return lx_fail(LX_ERR_INVALID, "%s: directional lights take lux, not %s", who,
                           lx_light_unit_symbol(unit));
        *native = value;
        return LX_OK;
    }
    if (lx_light_is_area(light)) {
        lx_status st = light_check_sizes(light);
        return st != LX_OK ? st : area_to_native(light, who, value, unit, native);
    }
    if (light->type != LX_LIGHT_POINT && light->type != LX_LIGHT_SPOT)
        return lx_fail(LX_ERR_INVALID, "%s: type %d is not a light type", who, (int)light->type);
    if (unit == LX_UNIT_NIT)
        return lx_fail(LX_ERR_INVALID, "%s: %s lights take cd, lm or W, not nt", who,
                       lx_light_type_name(light->type));
    if (unit == LX_UNIT_LUX)
        return lx_fail(LX_ERR_INVALID, "%s: %s lights take cd, lm or W, not lx", who,
                       lx_light_type_name(light->type));
    if (unit == LX_UNIT_DEFAULT || unit == LX_UNIT_CANDELA) {
        *native = value;
        return LX_OK;
    }

    double lumens = unit == LX_UNIT_WATT ? (double)value * LX_LUMENS_PER_WATT : (double)value;
    double candela;
    if (light->type == LX_LIGHT_POINT) {
        candela = lumens / (4.0 * LX_PI_D);
    } else if (spot_conversion == LX_SPOT_POWER_CONE) {
        /* Solid angle of the outer cone: the power stays inside it, so a
         * narrower cone gets brighter. */
        double outer = light->outer_angle;
        if (!(outer > 0.0) || !(outer <= LX_PI_D))
            return lx_fail(LX_ERR_INVALID,
                           "%s: outer_angle %g deg cannot convert lumens over the cone", who,
                           outer * 180.0 / LX_PI_D);
        candela = lumens / (2.0 * LX_PI_D * (1.0 - cos(outer)));
    } else if (spot_conversion == LX_SPOT_POWER_PI) {
        /* Filament's default: the cone does not change the illuminance. */
        candela = lumens / LX_PI_D;
    } else {
        return lx_fail(LX_ERR_INVALID, "%s: spot conversion %d is unknown", who,
                       (int)spot_conversion);
    }
    float result = (float)candela;
    if (!isfinite(result))
        return lx_fail(LX_ERR_INVALID, "%s: intensity %g %s overflows as candela", who, value,
                       lx_light_unit_symbol(unit));
    *native = result;
    return LX_OK;
}

/* ASCII case-insensitive equality ("W", "w", "Lumen"). */
static bool same_word(const char *a, const char *b)
{
    for (; *a && *b; a++, b++) {
        char ca = (*a >= 'A' && *a <= 'Z') ? (char)(*a - 'A' + 'a') : *a;
        char cb = (*b >= 'A' && *b <= 'Z') ? (char)(*b - 'A' + 'a') : *b;
        if (ca != cb)
            return false;
    }
    return *a == *b;
}

lx_light_unit lx_light_unit_from_string(const char *s)
{
    static const struct {
        const char *word;
        lx_light_unit unit;
    } words[] = {
        {"cd", LX_UNIT_CANDELA}, {"candela", LX_UNIT_CANDELA}, {"candelas", LX_UNIT_CANDELA},
        {"lm", LX_UNIT_LUMEN},   {"lumen", LX_UNIT_LUMEN},     {"lumens", LX_UNIT_LUMEN},
        {"W", LX_UNIT_WATT},     {"watt", LX_UNIT_WATT},       {"watts", LX_UNIT_WATT},
        {"lx", LX_UNIT_LUX},     {"lux", LX_UNIT_LUX},         {"nt", LX_UNIT_NIT},
        {"nit", LX_UNIT_NIT},    {"nits", LX_UNIT_NIT},
    };
    if (!s)
        return LX_UNIT_DEFAULT;
    for (size_t i = 0; i < sizeof words / sizeof words[0]; i++)
        if (same_word(s, words[i].word))
            return words[i].unit;
    return LX_UNIT_DEFAULT;
}

const char *lx_light_unit_symbol(lx_light_unit unit)
{
    switch (unit) {
    case LX_UNIT_DEFAULT:
        return "default";
    case LX_UNIT_CANDELA:
        return "cd";
    case LX_UNIT_LUMEN:
        return "lm";
    case LX_UNIT_WATT:
        return "W";
    case LX_UNIT_LUX:
        return "lx";
    case LX_UNIT_NIT:
        return "nt";
    }
    return "unknown";
}

const char *lx_light_type_name(lx_light_type type)
{
    switch (type) {
    case LX_LIGHT_POINT:
        return "point";
    case LX_LIGHT_SPOT:
        return "spot";
    case LX_LIGHT_DIRECTIONAL:
        return "directional";
    case LX_LIGHT_SPHERE:
        return "sphere";
    case LX_LIGHT_DISK:
        return "disk";
    case LX_LIGHT_RECT:
        return "rect";
    case LX_LIGHT_TUBE:
        return "tube";
    }
    return "unknown";
}

const char *lx_shadow_mode_name(lx_shadow_mode mode)
{
    switch (mode) {
    case LX_SHADOW_HARD:
        return "hard";
    case LX_SHADOW_NONE:
        return "none";
    case LX_SHADOW_BLUR:
        return "blur";
    case LX_SHADOW_SOFT:
        return "soft";
    }
    return "unknown";
}

float lx_exposure_from_ev100(float ev100)
{
    return (float)(1.0 / (1.2 * exp2((double)ev100)));
}

float lx_ev100_from_luminance(double average_luminance)
{
    if (!(average_luminance > 0.0) || !isfinite(average_luminance))
        return 0.0f;
    return (float)log2(average_luminance * 100.0 / 12.5);
}

lx_status lx_ev100_from_camera(float aperture, float shutter_seconds, float iso, float *ev100)
{
    if (!ev100)
        return lx_fail_null(__func__, "ev100");
    if (!(aperture > 0.0f && isfinite(aperture)) ||
        !(shutter_seconds > 0.0f && isfinite(shutter_seconds)) || !(iso > 0.0f && isfinite(iso)))
        return lx_fail(LX_ERR_INVALID,
                       "camera settings f/%g, %g s, ISO %g: each must be a finite number above 0",
                       (double)aperture, (double)shutter_seconds, (double)iso);
    double n = aperture;
    *ev100 = (float)log2(n * n / shutter_seconds * 100.0 / iso);
    return LX_OK;
}
