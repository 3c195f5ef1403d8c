/* Punctual light evaluation: Filament's physically based light model
 * (R. Guy and M. Agopian, "Physically Based Rendering in Filament",
 * "Physically based punctual lights": inverse square law with the smooth
 * range window (1 - (d/r)^4)^2, the spot's smooth angular attenuation,
 * N.L), and from the per-texel lighting document luxel started from: its
 * "classic" CSLight falloff ((1 - d/range) |N.L|)^2 * colour * intensity of
 * its DynamicLight kernel, its dynamic blur shadow factor and its ambient
 * wish list item (ambient that falls off with the light's reach and adds
 * across lights). */
#include "luxel/light.h"
#include "core/internal.h"
#include "light_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Filament clamps d^2 so a texel sitting on the light does not blow up. */
#define LX_MIN_DISTANCE_SQ 1e-4f
/* Filament's floor on cos(inner) - cos(outer): keeps the spot scale finite. */
#define LX_MIN_SPOT_COS_DELTA 1e-4f
/* Allowed deviation of a direction's length from 1. */
#define LX_DIRECTION_TOLERANCE 1e-3f
/* Angles read from files as float pi/2 land a hair above the float constant. */
#define LX_ANGLE_SLACK 1e-6f

lx_light lx_light_defaults(lx_light_type type)
{
    lx_light l;
    memset(&l, 0, sizeof l);
    l.type = type;
    l.position = lx_v3(0.0f, 0.0f, 0.0f);
    l.direction = lx_v3(0.0f, -1.0f, 0.0f);
    l.color = lx_v3(1.0f, 1.0f, 1.0f);
    l.intensity = 1.0f;
    l.range = 0.0f;
    l.inner_angle = 0.0f;
    l.outer_angle = LX_PI / 4.0f;
    l.model = LX_MODEL_PHYSICAL;
    l.shadow = LX_SHADOW_HARD;
    l.blur_power = 1.0f;
    l.blur_multiplier = 1.0f;
    l.ambient = lx_v3(0.0f, 0.0f, 0.0f);
    l.dynamic = false;
    /* area lights: 10 cm, facing down with up = +Z */
    l.radius = type == LX_LIGHT_SPHERE || type == LX_LIGHT_DISK ? 0.1f
               : type == LX_LIGHT_TUBE                          ? 0.02f
                                                                : 0.0f;
    l.length = type == LX_LIGHT_TUBE ? 1.0f : 0.0f;
    l.width = l.height = type == LX_LIGHT_RECT ? 0.1f : 0.0f;
    l.up = lx_v3(0.0f, 0.0f, 1.0f);
    l.samples = 0;
    return l;
}

uint32_t lx_light_sample_count(const lx_light *light)
{
    return light->samples ? light->samples : LX_DEFAULT_LIGHT_SAMPLES;
}

bool lx_light_is_area(const lx_light *light)
{
    return light->type == LX_LIGHT_SPHERE || light->type == LX_LIGHT_DISK ||
           light->type == LX_LIGHT_RECT || light->type == LX_LIGHT_TUBE;
}

/* The rect's axes: x along its width, y along its height, x cross y = the
 * emitting direction, so corners in (x, y) order are counter-clockwise
 * seen from the front. */
static void rect_axes(const lx_light *light, lx_vec3 *x, lx_vec3 *y)
{
    *x = lx_normalize(lx_cross(light->up, light->direction));
    *y = lx_cross(light->direction, *x);
}

void lx_rect_light_corners(const lx_light *light, lx_vec3 corners[4])
{
    lx_vec3 x, y;
    rect_axes(light, &x, &y);
    lx_vec3 hx = lx_scale(x, 0.5f * light->width), hy = lx_scale(y, 0.5f * light->height);
    corners[0] = lx_sub(lx_sub(light->position, hx), hy);
    corners[1] = lx_sub(lx_add(light->position, hx), hy);
    corners[2] = lx_add(lx_add(light->position, hx), hy);
    corners[3] = lx_add(lx_sub(light->position, hx), hy);
}

/* A unit vector uniform on the sphere from u, v in [0,1). */
static lx_vec3 sphere_direction(float u, float v)
{
    float phi = 2.0f * LX_PI * v;
    float z = 1.0f - 2.0f * u, r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return lx_v3(r * cosf(phi), r * sinf(phi), z);
}

/* A tube's surface, uniform in area: u first picks the cylinder (its share
 * of the area, 2 pi r L / (2 pi r L + 4 pi r^2)) or a cap, then places the
 * point within it, so stratification in u carries over. */
static lx_vec3 tube_point(const lx_light *light, float u, float v, lx_vec3 *normal)
{
    lx_vec3 axis = light->direction;
    float half = 0.5f * light->length, r = light->radius;
    if (!(r > 0.0f)) {
        *normal = lx_v3(0.0f, 0.0f, 0.0f);
        return lx_madd(light->position, axis, (2.0f * u - 1.0f) * half);
    }
    float side = light->length / (light->length + 2.0f * r);
    if (u < side) {
        lx_vec3 t = lx_perpendicular(axis), b = lx_cross(axis, t);
        float phi = 2.0f * LX_PI * v;
        *normal = lx_add(lx_scale(t, cosf(phi)), lx_scale(b, sinf(phi)));
        lx_vec3 centre = lx_madd(light->position, axis, (2.0f * u / side - 1.0f) * half);
        return lx_madd(centre, *normal, r);
    }
    /* caps: the rest of u covers the whole sphere; each hemisphere sits on
     * the end it faces */
    lx_vec3 d = sphere_direction((u - side) / (1.0f - side), v);
    *normal = d;
    float end = lx_dot(d, axis) >= 0.0f ? half : -half;
    return lx_madd(lx_madd(light->position, axis, end), d, r);
}

lx_vec3 lx_area_light_point(const lx_light *light, float u, float v, lx_vec3 *normal)
{
    float phi = 2.0f * LX_PI * v;
    if (light->type == LX_LIGHT_SPHERE) {
        lx_vec3 d = sphere_direction(u, v);
        *normal = d;
        return lx_madd(light->position, d, light->radius);
    }
    if (light->type == LX_LIGHT_TUBE)
        return tube_point(light, u, v, normal);
    *normal = light->direction;
    if (light->type == LX_LIGHT_DISK) {
        lx_vec3 t = lx_perpendicular(light->direction), b = lx_cross(light->direction, t);
        float r = light->radius * sqrtf(u);
        return lx_madd(lx_madd(light->position, t, r * cosf(phi)), b, r * sinf(phi));
    }
    lx_vec3 x, y;
    rect_axes(light, &x, &y);
    return lx_madd(lx_madd(light->position, x, (u - 0.5f) * light->width), y,
                   (v - 0.5f) * light->height);
}

/* Candela toward the point (along -to_light) from the light's photometric
 * profile (Filament's photometric lights): the vertical angle from the
 * light's direction, the horizontal angle around it from up. */
static float profile_intensity(const lx_light *light, lx_vec3 to_light)
{
    lx_vec3 v = lx_neg(to_light), d = light->direction;
    float cos_v = lx_clampf(lx_dot(v, d), -1.0f, 1.0f);
    lx_vec3 h0 = lx_sub(light->up, lx_scale(d, lx_dot(light->up, d)));
    h0 = lx_length(h0) > 1e-6f ? lx_normalize(h0) : lx_perpendicular(d);
    lx_vec3 h90 = lx_cross(d, h0);
    float phi = LX_RAD2DEG(atan2f(lx_dot(v, h90), lx_dot(v, h0)));
    if (phi < 0.0f)
        phi += 360.0f;
    float cd = lx_ies_candela(light->profile, LX_RAD2DEG(acosf(cos_v)), phi);
    return cd * light->profile_scale;
}

/* Area lights: the exact unshadowed illuminance (area.c), with the range
 * window on the distance to the light's centre. */
static bool evaluate_area(const lx_light *light, lx_vec3 p, lx_vec3 n, lx_light_eval *out)
{
    lx_vec3 to_light = lx_sub(light->position, p);
    float dist_sq = lx_dot(to_light, to_light);
    float dist = sqrtf(dist_sq);
    float window = lx_light_range_window(dist_sq, light->range);
    out->ambient = lx_scale(light->ambient, window);
    out->distance = dist;
    out->to_light = dist > 0.0f ? lx_scale(to_light, 1.0f / dist) : n;
    float e;
    if (light->type == LX_LIGHT_SPHERE) {
        e = lx_sphere_light_illuminance(light->position, light->radius, light->intensity, p, n);
    } else if (light->type == LX_LIGHT_DISK) {
        e = lx_disk_light_illuminance(light->position, light->direction, light->radius,
                                      light->intensity, p, n);
    } else if (light->type == LX_LIGHT_TUBE && light->radius > 0.0f) {
        e = lx_tube_light_illuminance(light->position, light->direction, light->length,
                                      light->radius, light->intensity, p, n);
    } else if (light->type == LX_LIGHT_TUBE) {
        /* linear: intensity is candela per metre across the axis */
        lx_vec3 half = lx_scale(light->direction, 0.5f * light->length);
        e = lx_line_light_illuminance(lx_sub(light->position, half), lx_add(light->position, half),
                                      light->intensity, p, n);
    } else {
        lx_vec3 corners[4];
        lx_rect_light_corners(light, corners);
        e = lx_rect_light_illuminance(corners, light->intensity, p, n);
    }
    e *= window;
    if (!(e > 0.0f))
        return false;
    out->illuminance = lx_scale(light->color, e);
    return true;
}

/* The light's name for messages; names are not guaranteed NUL-terminated
 * in a struct handed to us, so print at most the buffer. */
static int name_len(const lx_light *light)
{
    const void *nul = memchr(light->name, '\0', sizeof light->name);
    return nul ? (int)((const char *)nul - light->name) : (int)sizeof light->name;
}

static lx_status invalid(const lx_light *light, const char *what)
{
    int n = name_len(light);
    if (n == 0)
        return lx_fail(LX_ERR_INVALID, "light (unnamed): %s", what);
    return lx_fail(LX_ERR_INVALID, "light '%.*s': %s", n, light->name, what);
}

static lx_status check_vec(const lx_light *light, const char *field, lx_vec3 v, bool non_negative)
{
    char msg[160];
    if (!lx_vec3_finite(v)) {
        snprintf(msg, sizeof msg, "%s is not finite", field);
        return invalid(light, msg);
    }
    if (non_negative && (v.x < 0.0f || v.y < 0.0f || v.z < 0.0f)) {
        snprintf(msg, sizeof msg, "%s [%g, %g, %g] has a negative component", field, v.x, v.y, v.z);
        return invalid(light, msg);
    }
    return LX_OK;
}

/* A scalar that must be finite and >= 0. */
static lx_status check_non_negative(const lx_light *light, const char *field, float v)
{
    char msg[160];
    if (!isfinite(v)) {
        snprintf(msg, sizeof msg, "%s is not finite", field);
        return invalid(light, msg);
    }
    if (v < 0.0f) {
        snprintf(msg, sizeof msg, "%s %g is negative", field, v);
        return invalid(light, msg);
    }
    return LX_OK;
}

/* A value (already known finite) within [-limit, limit]. */
static lx_status check_limit(const lx_light *light, const char *field, float v, float limit,
                             const char *unit)
{
    char msg[200];
    if (fabsf(v) > limit) {
        snprintf(msg, sizeof msg, "%s %g %s is beyond %g %s (the largest luxel accepts)", field, v,
                 unit, limit, unit);
        return invalid(light, msg);
    }
    return LX_OK;
}

static lx_status check_vec_limit(const lx_light *light, const char *field, lx_vec3 v, float limit,
                                 const char *unit)
{
    char msg[200];
    if (fabsf(v.x) > limit || fabsf(v.y) > limit || fabsf(v.z) > limit) {
        snprintf(msg, sizeof msg, "%s [%g, %g, %g] has a component beyond %g%s%s (the largest luxel accepts)",
                 field, v.x, v.y, v.z, limit, unit[0] ? " " : "", unit);
        return invalid(light, msg);
    }
    return LX_OK;
}

lx_status light_check_sizes(const lx_light *light)
{
    lx_status st;
    const char *names[4] = {"radius", "length", "width", "height"};
    const float sizes[4] = {light->radius, light->length, light->width, light->height};
    for (int k = 0; k < 4; k++)
        if (isfinite(sizes[k]) &&
            (st = check_limit(light, names[k], sizes[k], LX_LIGHT_MAX_DISTANCE, "m")) != LX_OK)
            return st;
    return LX_OK;
}

/* The unit intensity is held in for this light (for messages). */
static const char *native_unit(const lx_light *light)
{
    if (light->type == LX_LIGHT_DIRECTIONAL)
        return "lx";
    if (light->type == LX_LIGHT_TUBE && !(light->radius > 0.0f))
        return "cd/m";
    return lx_light_is_area(light) ? "nt" : "cd";
}

/* Values finite but absurd (LX_LIGHT_MAX_*, light.h says why): refused
 * here, before a bake turns them into infinities. */
static lx_status check_limits(const lx_light *light)
{
    lx_status st;
    if ((st = check_vec_limit(light, "position", light->position, LX_LIGHT_MAX_DISTANCE, "m")) !=
            LX_OK ||
        (st = check_limit(light, "intensity", light->intensity, LX_LIGHT_MAX_INTENSITY,
                          native_unit(light))) != LX_OK ||
        (st = check_vec_limit(light, "color", light->color, LX_LIGHT_MAX_COLOR, "")) != LX_OK ||
        (st = check_vec_limit(light, "ambient", light->ambient, LX_LIGHT_MAX_INTENSITY, "lx")) !=
            LX_OK ||
        (st = check_limit(light, "range", light->range, LX_LIGHT_MAX_DISTANCE, "m")) != LX_OK)
        return st;
    return light_check_sizes(light);
}

/* The area-light fields: sizes, the rect's up vector, soft shadows. */
static lx_status validate_area(const lx_light *light)
{
    char msg[200];
    if (light->samples > LX_MAX_LIGHT_SAMPLES) {
        snprintf(msg, sizeof msg, "samples %u is above %u", light->samples, LX_MAX_LIGHT_SAMPLES);
        return invalid(light, msg);
    }
    if (!lx_light_is_area(light)) {
        if (light->shadow == LX_SHADOW_SOFT)
            return invalid(light, "soft shadows need an area light (sphere, disk, rect or tube)");
        return LX_OK;
    }
    if (light->model == LX_MODEL_CLASSIC)
        return invalid(light, "area lights use the physical model");
    if (light->type == LX_LIGHT_RECT) {
        if (!(light->width > 0.0f && isfinite(light->width)) ||
            !(light->height > 0.0f && isfinite(light->height)))
            return invalid(light, "a rect light needs a finite width and height above 0");
        lx_vec3 side = lx_cross(light->up, light->direction);
        if (!lx_vec3_finite(light->up) || !(lx_length(side) > 1e-6f))
            return invalid(light, "a rect light's up must be finite and not along its direction");
    } else if (light->type == LX_LIGHT_TUBE) {
        if (!(light->radius >= 0.0f && isfinite(light->radius)))
            return invalid(light, "a tube light needs a finite radius of 0 or more");
        if (!(light->length >= 0.0f && isfinite(light->length)))
            return invalid(light, "a tube light needs a finite length of 0 or more");
        if (!(light->radius > 0.0f) && !(light->length > 0.0f))
            return invalid(light, "a linear tube light (radius 0) needs a length above 0");
    } else if (!(light->radius > 0.0f && isfinite(light->radius))) {
        return invalid(light, "a sphere or disk light needs a finite radius above 0");
    }
    return LX_OK;
}

lx_status lx_light_validate(const lx_light *light)
{
    char msg[200];
    lx_status st;
    if (!light)
        return lx_fail(LX_ERR_INVALID, "light: NULL pointer");
    if (!memchr(light->name, '\0', sizeof light->name))
        return invalid(light, "name is not NUL-terminated within LX_LIGHT_NAME_MAX bytes");
    if ((unsigned)light->type > (unsigned)LX_LIGHT_TUBE) {
        snprintf(msg, sizeof msg, "type %d is not a light type", (int)light->type);
        return invalid(light, msg);
    }
    if ((unsigned)light->model > (unsigned)LX_MODEL_CLASSIC) {
        snprintf(msg, sizeof msg, "model %d is not a falloff model", (int)light->model);
        return invalid(light, msg);
    }
    if ((unsigned)light->shadow > (unsigned)LX_SHADOW_SOFT) {
        snprintf(msg, sizeof msg, "shadow %d is not a shadow mode", (int)light->shadow);
        return invalid(light, msg);
    }
    if ((st = check_vec(light, "position", light->position, false)) != LX_OK)
        return st;
    if ((st = check_vec(light, "direction", light->direction, false)) != LX_OK)
        return st;
    if (light->type != LX_LIGHT_POINT) {
        float len = lx_length(light->direction);
        if (fabsf(len - 1.0f) > LX_DIRECTION_TOLERANCE) {
            snprintf(msg, sizeof msg, "direction [%g, %g, %g] is not unit length (length %g)",
                     light->direction.x, light->direction.y, light->direction.z, len);
            return invalid(light, msg);
        }
    }
    if ((st = check_vec(light, "color", light->color, true)) != LX_OK)
        return st;
    if ((st = check_non_negative(light, "intensity", light->intensity)) != LX_OK)
        return st;
    if ((st = check_non_negative(light, "range", light->range)) != LX_OK)
        return st;
    if (light->model == LX_MODEL_CLASSIC && light->type != LX_LIGHT_DIRECTIONAL &&
        !(light->range > 0.0f))
        return invalid(light, "the classic model needs a range above 0");
    if (!isfinite(light->inner_angle))
        return invalid(light, "inner_angle is not finite");
    if (!isfinite(light->outer_angle))
        return invalid(light, "outer_angle is not finite");
    if (light->type == LX_LIGHT_SPOT) {
        float inner_deg = LX_RAD2DEG(light->inner_angle);
        float outer_deg = LX_RAD2DEG(light->outer_angle);
        if (light->inner_angle < 0.0f) {
            snprintf(msg, sizeof msg, "inner_angle %g deg is negative", inner_deg);
            return invalid(light, msg);
        }
        if (!(light->outer_angle > 0.0f)) {
            snprintf(msg, sizeof msg, "outer_angle %g deg must be above 0", outer_deg);
            return invalid(light, msg);
        }
        if (light->outer_angle > 0.5f * LX_PI + LX_ANGLE_SLACK) {
            snprintf(msg, sizeof msg, "outer_angle %g deg is above 90 deg", outer_deg);
            return invalid(light, msg);
        }
        if (light->inner_angle > light->outer_angle) {
            snprintf(msg, sizeof msg, "inner_angle %g deg is above outer_angle %g deg", inner_deg,
                     outer_deg);
            return invalid(light, msg);
        }
    }
    if ((st = check_non_negative(light, "blur_power", light->blur_power)) != LX_OK)
        return st;
    if ((st = check_non_negative(light, "blur_multiplier", light->blur_multiplier)) != LX_OK)
        return st;
    if ((st = check_vec(light, "ambient", light->ambient, true)) != LX_OK)
        return st;
    if (light->profile) {
        if (light->type != LX_LIGHT_POINT && light->type != LX_LIGHT_SPOT)
            return invalid(light, "photometric profiles go on point and spot lights");
        if (!(light->profile_scale >= 0.0f) || !isfinite(light->profile_scale))
            return invalid(light, "profile_scale must be finite and >= 0");
    }
    if ((st = check_limits(light)) != LX_OK)
        return st;
    return validate_area(light);
}

float lx_light_range_window(float distance_sq, float range)
{
    if (!(range > 0.0f))
        return 1.0f;
    float factor = distance_sq / (range * range);
    float smooth = 1.0f - factor * factor;
    if (!(smooth > 0.0f))
        return 0.0f;
    return smooth * smooth;
}

float lx_light_spot_attenuation(const lx_light *light, float cos_angle)
{
    if (light->type != LX_LIGHT_SPOT)
        return 1.0f;
    float cos_outer = cosf(light->outer_angle);
    float cos_inner = cosf(light->inner_angle);
    /* inner == outer (Blender's glTF export) means a hard-edged cone; the
     * smooth ramp below would otherwise still be 1e-4 wide in cosine. */
    if (!(light->inner_angle < light->outer_angle))
        return cos_angle >= cos_outer ? 1.0f : 0.0f;
    float delta = cos_inner - cos_outer;
    float scale = 1.0f / (delta > LX_MIN_SPOT_COS_DELTA ? delta : LX_MIN_SPOT_COS_DELTA);
    float offset = -cos_outer * scale;
    float t = lx_saturate(cos_angle * scale + offset);
    return t * t;
}

static bool evaluate_directional(const lx_light *light, lx_vec3 n, lx_light_eval *out)
{
    out->to_light = lx_neg(light->direction);
    out->distance = INFINITY;
    out->ambient = light->ambient;
    float ndotl = lx_dot(n, out->to_light);
    if (!(ndotl > 0.0f))
        return false;
    float e;
    if (light->model == LX_MODEL_CLASSIC)
        e = ndotl * ndotl * light->intensity; /* no distance term at infinity */
    else
        e = light->intensity * ndotl;
    out->illuminance = lx_scale(light->color, e);
    return e > 0.0f;
}

bool lx_light_evaluate(const lx_light *light, lx_vec3 p, lx_vec3 n, lx_light_eval *out)
{
    if (!light || !out)
        return false;
    out->illuminance = lx_v3(0.0f, 0.0f, 0.0f);
    if (light->type == LX_LIGHT_DIRECTIONAL)
        return evaluate_directional(light, n, out);
    if (lx_light_is_area(light))
        return evaluate_area(light, p, n, out);

    lx_vec3 to_light = lx_sub(light->position, p);
    float dist_sq = lx_dot(to_light, to_light);
    float dist = sqrtf(dist_sq);
    /* The document wants ambient to reach only as far as the light does: the
     * same window as the direct light, so several lights' ambients blend. */
    out->ambient = lx_scale(light->ambient, lx_light_range_window(dist_sq, light->range));
    out->distance = dist;
    if (!(dist > 0.0f)) {
        out->to_light = n; /* no direction from a point onto itself */
        return false;
    }
    out->to_light = lx_scale(to_light, 1.0f / dist);
    float ndotl = lx_dot(n, out->to_light);
    if (!(ndotl > 0.0f))
        return false;
    float spot = lx_light_spot_attenuation(light, -lx_dot(light->direction, out->to_light));
    if (!(spot > 0.0f))
        return false;

    float intensity = light->profile ? profile_intensity(light, out->to_light) : light->intensity;
    float e;
    if (light->model == LX_MODEL_CLASSIC) {
        if (!(dist < light->range))
            return false;
        float v = (1.0f - dist / light->range) * ndotl;
        e = v * v * intensity * spot;
    } else {
        float window = lx_light_range_window(dist_sq, light->range);
        float d2 = dist_sq > LX_MIN_DISTANCE_SQ ? dist_sq : LX_MIN_DISTANCE_SQ;
        e = intensity * window * spot * ndotl / d2;
    }
    if (!(e > 0.0f))
        return false;
    out->illuminance = lx_scale(light->color, e);
    return true;
}

float lx_light_blur_visibility(const lx_light *light, float occluder_distance, float light_distance)
{
    /* An occluder with no measurable ray to compare against: fully shadowed. */
    if (!(light_distance > 0.0f) || !(occluder_distance >= 0.0f))
        return 0.0f;
    float ratio = occluder_distance / light_distance;
    float v = powf(ratio, light->blur_power) * light->blur_multiplier;
    if (!(v > 0.0f))
        return 0.0f;
    return v < 1.0f ? v : 1.0f;
}
