/* luxel/light.h - the physical light model: light types, units and their
 * conversions, distance and angular attenuation, illuminance at a point.
 *
 * CONVENTIONS  Positions in metres, directions are unit vectors pointing
 *   where the light shines (a light node's local -Z, as KHR_lights_punctual).
 *   Intensity inside an lx_light is always candela for point and spot
 *   lights and lux for directional lights; other units are converted when a
 *   light is made (lx_light_intensity_to_native). Angles in radians, spot
 *   angles measured from the axis. Colour is linear Rec.709 RGB.
 *   Evaluation follows Filament's physically based model (R. Guy and
 *   M. Agopian, "Physically Based Rendering in Filament"): inverse square
 *   law with the smooth window (1 - (d/r)^4)^2, the spot's smooth angular
 *   attenuation, N.L. The "classic" model of the per-texel lighting
 *   document luxel started from (its DynamicLight kernel) is
 *   ((1 - d/range) * |N.L|)^2 * colour * intensity, in the light's own units
 *   (a classic spot also takes the cone attenuation; a classic directional
 *   light gives (N.L)^2 * colour * intensity). Distances below 1 cm are
 *   taken as 1 cm in the inverse square law (Filament's 1e-4 m^2 floor).
 *   A spot with inner == outer is a hard-edged cone (as Blender exports).
 * ERRORS  lx_light_validate and the conversions return LX_ERR_INVALID
 *   naming the light ("light 'lamp': outer_angle 100 deg is above 90 deg");
 *   the IES reader LX_ERR_IO, LX_ERR_FORMAT, LX_ERR_UNSUPPORTED or
 *   LX_ERR_NOMEM naming the file and line. The message is lx_last_error().
 *   Evaluation functions do not fail: they take validated lights and finite
 *   inputs.
 * MEMORY  lx_light is plain data. An lx_ies_profile is reference counted:
 *   lx_ies_load / lx_ies_parse return it with one reference, lx_ies_retain
 *   adds one, lx_ies_free drops one and frees it with the last. A light
 *   borrows its profile.
 * THREADING  Every function is thread-safe: the model keeps no state of its
 *   own (errors go to the calling thread's lx_last_error). A profile is
 *   never changed after loading, so any number of threads may read it at
 *   once; lx_ies_retain and lx_ies_free count atomically.
 *
 * USAGE
 *   lx_light spot = lx_light_defaults(LX_LIGHT_SPOT); // at the origin, down -Y
 *   spot.position = lx_v3(0.0f, 3.0f, 0.0f);
 *   if (lx_light_intensity_to_native(&spot, 800.0f, LX_UNIT_LUMEN, LX_SPOT_POWER_PI,
 *                                    &spot.intensity) != LX_OK ||
 *       lx_light_validate(&spot) != LX_OK)
 *       return 1;
 *   lx_light_eval e; // a floor point 0.5 m off the axis, facing up
 *   if (lx_light_evaluate(&spot, lx_v3(0.5f, 0.0f, 0.0f), lx_v3(0.0f, 1.0f, 0.0f), &e))
 *       printf("%.1f lx from %.2f m\n", e.illuminance.y, e.distance);
 *   lx_ies_profile *lamp;
 *   if (lx_ies_load("lamp.ies", &lamp) != LX_OK) {
 *       fprintf(stderr, "%s\n", lx_last_error());
 *       return 1;
 *   }
 *   double beam, field;
 *   if (lx_ies_beam_field(lamp, 0.0f, &beam, &field) != LX_OK) {
 *       lx_ies_free(lamp);
 *       return 1;
 *   }
 *   printf("%.0f lm, beam %.1f deg, field %.1f deg\n", lx_ies_total_lumens(lamp), beam, field);
 *   spot.type = LX_LIGHT_POINT; // the lamp's own candela, borrowed
 *   spot.profile = lamp;
 *   spot.profile_scale = 1.0f;
 *   if (lx_light_evaluate(&spot, lx_v3(0.5f, 0.0f, 0.0f), lx_v3(0.0f, 1.0f, 0.0f), &e))
 *       printf("%.1f lx\n", e.illuminance.y);
 *   lx_ies_free(lamp);
 *   float tube = lx_tube_light_illuminance(lx_v3(0.0f, 2.5f, 0.0f), lx_v3(1.0f, 0.0f, 0.0f), 1.2f,
 *                                          0.02f, 2e4f, lx_v3(0.0f, 0.0f, 0.0f),
 *                                          lx_v3(0.0f, 1.0f, 0.0f));
 *   printf("a 1.2 m tube of 20000 nt, 2.5 m up: %.1f lx\n", tube);
 */
#ifndef LUXEL_LIGHT_H
#define LUXEL_LIGHT_H

#include "luxel/core.h"
#include "luxel/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Lumens per watt used to convert radiometric input (photopic maximum). */
#define LX_LUMENS_PER_WATT 683.0f

typedef enum lx_light_type {
    LX_LIGHT_POINT = 0,
    LX_LIGHT_SPOT,
    LX_LIGHT_DIRECTIONAL,
    LX_LIGHT_SPHERE, /* area lights: intensity is luminance in nits */
    LX_LIGHT_DISK,
    LX_LIGHT_RECT,
    LX_LIGHT_TUBE /* a capsule along direction; radius 0: a linear light, intensity
                     in cd per metre across its axis */
} lx_light_type;

typedef enum lx_shadow_mode {
    LX_SHADOW_HARD = 0, /* one occlusion ray per texel and light */
    LX_SHADOW_NONE,     /* lit only: nothing blocks the light */
    LX_SHADOW_BLUR,     /* the per-texel document's blur from the nearest occluder */
    LX_SHADOW_SOFT      /* area lights: rays to `samples` points on the light */
} lx_shadow_mode;

typedef enum lx_falloff_model {
    LX_MODEL_PHYSICAL = 0, /* inverse square x smooth range window (lux) */
    LX_MODEL_CLASSIC       /* ((1 - d/range) |N.L|)^2 colour intensity */
} lx_falloff_model;

typedef enum lx_light_unit {
    LX_UNIT_DEFAULT = 0, /* cd for point/spot, lx for directional */
    LX_UNIT_CANDELA,
    LX_UNIT_LUMEN,
    LX_UNIT_WATT,
    LX_UNIT_LUX,
    LX_UNIT_NIT /* cd/m^2: area-light luminance */
} lx_light_unit;

/* How a spot light's luminous power becomes intensity. */
typedef enum lx_spot_conversion {
    LX_SPOT_POWER_PI = 0, /* I = P / pi: illuminance does not depend on the cone */
    LX_SPOT_POWER_CONE    /* I = P / (2 pi (1 - cos outer)): power stays in the cone */
} lx_spot_conversion;

#define LX_LIGHT_NAME_MAX 64

typedef struct lx_light {
    char name[LX_LIGHT_NAME_MAX];
    lx_light_type type;
    lx_vec3 position;  /* metres (point, spot) */
    lx_vec3 direction; /* unit, where the light shines (spot, directional) */
    lx_vec3 color;     /* linear RGB, typically max component 1 */
    float intensity;   /* candela (point, spot) or lux (directional) */
    float range;       /* metres; 0 = unlimited (physical), required > 0 for classic */
    float inner_angle; /* radians from the axis, 0 <= inner <= outer */
    float outer_angle; /* radians from the axis, 0 < outer <= pi/2 */
    lx_falloff_model model;
    lx_shadow_mode shadow;
    float blur_power;      /* blur shadows: exponent, default 1 */
    float blur_multiplier; /* blur shadows: scale, default 1 */
    lx_vec3 ambient;       /* lux added everywhere in range, falling off with range */
    bool dynamic;          /* re-evaluated by lx_baker_update instead of baked */
    /* area lights (sphere, disk, rect, tube); direction is the emitting side
     * (a tube's axis) */
    float radius;        /* metres: sphere, disk, tube (0: a linear tube) */
    float length;        /* metres: tube, between its cap centres */
    float width, height; /* metres: rect, width along cross(up, direction) */
    lx_vec3 up;          /* rect: fixes its rotation about direction */
    uint32_t samples;    /* soft shadows: points on the light per texel, 0 = the default
                            (lx_light_sample_count) */
    /* photometric profile (point and spot): candela toward a direction is
     * the profile's value times profile_scale; its 0 deg vertical angle
     * points along direction, its 0 deg horizontal plane toward up (and
     * 90 deg toward cross(direction, up)). Borrowed: whoever sets it keeps
     * the profile alive (lx_ies_retain) while the light is used. */
    const struct lx_ies_profile *profile;
    float profile_scale;
} lx_light;

#define LX_MAX_LIGHT_SAMPLES 1024u
/* Soft shadows: points on the light per texel when lx_light.samples is 0. */
#define LX_DEFAULT_LIGHT_SAMPLES 16u

/* The number of points on the light a soft shadow uses: light->samples, or
 * LX_DEFAULT_LIGHT_SAMPLES when it is 0. Not clamped: lx_light_validate
 * rejects samples above LX_MAX_LIGHT_SAMPLES. */
uint32_t lx_light_sample_count(const lx_light *light);

/* True for the area light types (sphere, disk, rect, tube). */
bool lx_light_is_area(const lx_light *light);

/* A point on an area light's surface from two numbers in [0,1) (uniform
 * in area), with the surface normal there; for soft shadows. A linear tube
 * (radius 0) gives a point uniform along its segment and a zero normal. */
lx_vec3 lx_area_light_point(const lx_light *light, float u, float v, lx_vec3 *normal);

/* The area an area light shows along its axis (a tube: across it), in m^2:
 * candela = luminance * this. pi r^2 for a sphere or disk, W H for a rect,
 * 2 r length + pi r^2 for a tube (0 for a linear tube and other types). */
double lx_area_light_projected_area(const lx_light *light);

/* The rect's four corners, counter-clockwise seen from the emitting side. */
void lx_rect_light_corners(const lx_light *light, lx_vec3 corners[4]);

/* A light of the given type with every default filled in: white, intensity
 * 1, unlimited range, cone 0..pi/4, hard shadows, blur power/multiplier 1,
 * pointing down -Y. */
lx_light lx_light_defaults(lx_light_type type);

/* The largest values a light may hold (lx_light_validate). No real scene
 * comes near them (the sun gives 1.2e5 lx and its disc 1.6e9 nt, a
 * searchlight 1e9 cd; the Earth is 1.3e7 m across), and they keep every
 * float of a bake finite: intensity x colour at the 1 cm floor of the
 * inverse square law is at most 1e12 x 1e2 / 1e-4 = 1e18 lx, the largest
 * value a lightmap may hold, and squared distances and sizes (1e14 m^2)
 * are far from float's 3.4e38 while metres keep 1 m steps. */
#define LX_LIGHT_MAX_INTENSITY 1e12f /* of its native unit: cd, lx, nt (cd/m, linear tube);
                                        also each ambient component, lx */
#define LX_LIGHT_MAX_COLOR 1e2f      /* each linear RGB component */
#define LX_LIGHT_MAX_DISTANCE 1e7f   /* metres: position components, range, radius,
                                        length, width, height */

/* Checks every field (finite, in range, unit direction, within the
 * limits above); fails with LX_ERR_INVALID and "light 'name': <problem>". */
lx_status lx_light_validate(const lx_light *light);

/* Converts value in unit to the light's native unit (cd or lx) given its
 * type and cone. Fails with LX_ERR_INVALID when the unit does not fit the
 * type (lux for a point light, candela for a directional one). */
lx_status lx_light_intensity_to_native(const lx_light *light, float value, lx_light_unit unit,
                                       lx_spot_conversion spot_conversion, float *native);

/* Parses "cd", "lm", "W", "lx" (and long names); LX_UNIT_DEFAULT if unknown. */
lx_light_unit lx_light_unit_from_string(const char *s);
const char *lx_light_unit_symbol(lx_light_unit unit);
const char *lx_light_type_name(lx_light_type type);
const char *lx_shadow_mode_name(lx_shadow_mode mode);

/* Smooth distance window (1 - (d^2/r^2)^2)^2, 1 when range is 0. */
float lx_light_range_window(float distance_sq, float range);
/* Spot angular attenuation for cos of the angle to the axis. */
float lx_light_spot_attenuation(const lx_light *light, float cos_angle);

typedef struct lx_light_eval {
    lx_vec3 to_light;    /* unit vector from the point toward the light */
    float distance;      /* to the light, INFINITY for directional */
    lx_vec3 illuminance; /* unshadowed, N.L included: lux (physical model) */
    lx_vec3 ambient;     /* the light's ambient contribution at the point */
} lx_light_eval;

/* Evaluates light at point p with unit normal n. Returns false when the
 * light contributes nothing direct there (behind, out of range or cone);
 * ambient is filled in either case. */
bool lx_light_evaluate(const lx_light *light, lx_vec3 p, lx_vec3 n, lx_light_eval *out);

/* The blur shadow factor of the per-texel lighting document (its "dynamic
 * blurred shadows"): clamp((occluder_dist / light_dist)^power *
 * multiplier, 0, 1), where occluder_dist is measured from the texel. */
float lx_light_blur_visibility(const lx_light *light, float occluder_distance,
                               float light_distance);

/* ---- colour ------------------------------------------------------------- */

#define LX_MIN_TEMPERATURE 1000.0f /* kelvin: range of Krystek's approximation */
#define LX_MAX_TEMPERATURE 40000.0f

/* CIE 1931 xy chromaticity of a black body at kelvin (Planckian locus in
 * CIE 1960 UCS by Krystek's rational approximation). Fails with
 * LX_ERR_INVALID outside [LX_MIN_TEMPERATURE, LX_MAX_TEMPERATURE]. */
lx_status lx_temperature_to_xy(float kelvin, float *x, float *y);

/* Linear Rec.709/sRGB colour of a black body at kelvin (as Filament does): xy, to
 * XYZ at Y = 1, to linear sRGB with the standard matrix, normalized so the
 * largest channel is 1. Components below 0 (outside the sRGB gamut, below
 * about 1900 K) are set to 0. */
lx_status lx_temperature_to_rgb(float kelvin, lx_vec3 *rgb);

/* A colour given in sRGB (gamma-encoded, 0..1 per channel) as linear RGB. */
lx_vec3 lx_srgb_color_to_linear(lx_vec3 srgb);

/* ---- photometric profiles (IES LM-63) ----------------------------------- */

/* A luminaire's candela distribution read from an IES LM-63 file (1986,
 * 1991, 1995 and 2002 variants), in photometric type C: vertical angle 0 is
 * straight down the luminaire's axis (nadir), horizontal angles go around
 * it. Type A and B files are resampled to type C when read, their beam
 * axis on the nadir (docs/ies.md). Candela values already include the
 * candela multiplier and the ballast factors. */
typedef struct lx_ies_profile lx_ies_profile;

/* Reads an IES file; errors name the file and line. */
lx_status lx_ies_load(const char *path, lx_ies_profile **out);
/* Same from text in memory; name is used in messages. */
lx_status lx_ies_parse(const char *text, size_t size, const char *name, lx_ies_profile **out);
/* Drops one reference; the profile is freed with the last. */
void lx_ies_free(lx_ies_profile *profile);
/* Adds a reference (for a second owner, such as a baker); returns profile. */
lx_ies_profile *lx_ies_retain(const lx_ies_profile *profile);

/* Candela toward (vertical, horizontal) in degrees, interpolated between
 * the file's angles and extended by its horizontal symmetry. */
float lx_ies_candela(const lx_ies_profile *profile, float vertical_deg, float horizontal_deg);
/* Luminous flux in lumens: the candela distribution integrated numerically
 * over the sphere. */
double lx_ies_total_lumens(const lx_ies_profile *profile);
/* Largest candela value. */
float lx_ies_peak_candela(const lx_ies_profile *profile);

/* Spread of a plane (IES and CIE definitions): in the plane through the
 * horizontal angles h and h + 180 (0: the C0-C180 plane, 90: C90-C270), the
 * full angle in degrees between the two directions either side of the
 * plane's maximum intensity where the candela first falls below `fraction`
 * of that maximum: LX_IES_BEAM_FRACTION (50%) gives the beam angle,
 * LX_IES_FIELD_FRACTION (10%) the field angle. Exact for the profile as
 * lx_ies_candela interpolates it (within a plane, linear between the
 * vertical angles; dark past the last one, a step there), not sampled.
 * Where several directions share the maximum, the walk starts from the one
 * nearest the nadir. *angle_deg is -1 when the intensity never falls that
 * far on one side, or the plane is dark. Fails with LX_ERR_INVALID (and
 * leaves *angle_deg alone) for a NULL pointer, a horizontal angle that is
 * not finite or a fraction not strictly between 0 and 1. */
#define LX_IES_BEAM_FRACTION 0.5
#define LX_IES_FIELD_FRACTION 0.1
lx_status lx_ies_spread_angle(const lx_ies_profile *profile, float horizontal_deg, double fraction,
                              double *angle_deg);
/* The beam (50%) and field (10%) angles of one plane, as
 * lx_ies_spread_angle gives them. */
lx_status lx_ies_beam_field(const lx_ies_profile *profile, float horizontal_deg, double *beam_deg,
                            double *field_deg);
/* The largest candela of the plane through horizontal angles h and
 * h + 180 (both halves), as lx_ies_candela interpolates it: the maximum
 * lx_ies_spread_angle measures that plane's fractions from. A beam angle
 * describes the beam only in a plane that carries the profile's peak
 * (lx_ies_peak_candela); elsewhere it measures a side lobe. Fails with
 * LX_ERR_INVALID for a NULL pointer or a horizontal angle not finite. */
lx_status lx_ies_plane_peak(const lx_ies_profile *profile, float horizontal_deg, float *candela);
/* The horizontal angle in [0, 180) of a plane that carries the peak: the
 * first of the profile's horizontal angles (increasing) toward which some
 * vertical angle reaches the largest candela of the distribution as
 * lx_ies_candela interpolates it (a type A or B file's resampled grid may
 * stay a little below the file's own lx_ies_peak_candela), folded into
 * [0, 180) (the plane through h is the plane through h + 180). 0 for a
 * dark profile.
 * Fails with LX_ERR_INVALID for a NULL pointer. */
lx_status lx_ies_peak_plane(const lx_ies_profile *profile, float *horizontal_deg);

/* Horizontal symmetry of a profile, from its first and last horizontal
 * angles: 0 only; 0-90; 0-180; 90-270; 0 to more than 180 (full, the
 * last plane wrapping to 0/360). */
typedef enum lx_ies_symmetry {
    LX_IES_ROTATIONAL = 0, /* one plane: the same in every direction around the axis */
    LX_IES_QUADRANT,       /* 0-90, mirrored into the other quadrants */
    LX_IES_BILATERAL,      /* 0-180, mirrored about the 0-180 plane */
    LX_IES_BILATERAL_90,   /* 90-270, mirrored about the 90-270 plane */
    LX_IES_FULL            /* 0-360 */
} lx_ies_symmetry;

/* The header of an IES file, as read. Scale factors are the file's own
 * (the profile's candela values already include them). */
typedef struct lx_ies_info {
    const char *version; /* "LM-63-2002", "LM-63-1995", "LM-63-1991" or "LM-63-1986" */
    int keyword_count;   /* lines before TILT=, see lx_ies_keyword */
    bool tilt_included;  /* TILT=INCLUDE (the tilt data is read and checked, not applied) */
    int lamp_count;
    double lumens_per_lamp; /* -1 for absolute photometry */
    double multiplier;      /* candela multiplier */
    double ballast_factor;
    double ballast_lamp_factor; /* 1995+: "future use", normally 1 */
    double input_watts;
    int photometric_type; /* 1 = C, 2 = B, 3 = A */
    int units;            /* 1 = feet, 2 = metres (width, length, height) */
    double width, length, height;
    int vertical_count, horizontal_count;
    const float *vertical_angles;   /* degrees, increasing; borrowed until lx_ies_free */
    const float *horizontal_angles; /* degrees, increasing; borrowed until lx_ies_free */
    lx_ies_symmetry symmetry;       /* types A and B: of the converted type C distribution */
} lx_ies_info;

/* Fills out with the profile's header; pointers are borrowed until
 * lx_ies_free. */
void lx_ies_get_info(const lx_ies_profile *profile, lx_ies_info *out);
/* The index-th line before TILT= (0 <= index < keyword_count): key is the
 * keyword without brackets ("TEST", "MANUFAC"), or "" for a 1986 label
 * line; value the rest of the line, trimmed. Borrowed until lx_ies_free;
 * NULL when index is out of range. */
const char *lx_ies_keyword(const lx_ies_profile *profile, int index, const char **value);
/* "rotational", "quadrant", "bilateral 0-180", "bilateral 90-270", "full". */
const char *lx_ies_symmetry_name(lx_ies_symmetry symmetry);

/* ---- area lights ----------------------------------------------------------- */

/* Unshadowed illuminance in lux at a point p with normal n from a uniform
 * Lambertian area light of luminance L (nits), exact for lights partly
 * below p's horizon (the plane through p with normal n): only the part of
 * the light above that plane counts. Nothing occludes the light but its own
 * body. Inputs must be finite (lights are validated when they are made);
 * normals need not be exactly unit length (they are normalized here, a zero
 * normal gives 0). A radius or luminance that is not above 0 gives 0. */

/* A sphere of the given radius around centre: pi L sin^2(a) cos(t) while
 * the sphere is wholly above the horizon (sin a = r/d, t the angle between
 * n and the direction to the centre), Snyder's exact formula while it is
 * partly below, 0 when it is wholly below. A point on or inside the sphere
 * sees light over its whole hemisphere: the result is then pi L. */
float lx_sphere_light_illuminance(lx_vec3 centre, float radius, float luminance, lx_vec3 p,
                                  lx_vec3 n);

/* A one-sided disk emitting toward normal (its emitting side): 0 for points
 * behind it or in its plane. Exact in closed form for any orientation and
 * for disks partly below the horizon (Stokes' contour integral along the
 * circle, integrated analytically). */
float lx_disk_light_illuminance(lx_vec3 centre, lx_vec3 normal, float radius, float luminance,
                                lx_vec3 p, lx_vec3 n);

/* A one-sided planar polygon of count >= 3 vertices, counter-clockwise seen
 * from its emitting side: Lambert's exact form factor after clipping the
 * polygon to p's upper half-space. 0 for points behind it (side taken from
 * the polygon's Newell normal and its vertex centroid) or in its plane, for
 * count < 3 or vertices NULL. The polygon must be simple (convex or not) and
 * planar; vertices are read, not kept. */
float lx_polygon_light_illuminance(const lx_vec3 *vertices, int count, float luminance, lx_vec3 p,
                                   lx_vec3 n);

/* A one-sided rectangle (any planar quadrilateral) given by its 4 corners,
 * counter-clockwise seen from its emitting side: the polygon form factor. */
float lx_rect_light_illuminance(const lx_vec3 corners[4], float luminance, lx_vec3 p, lx_vec3 n);

/* A linear light: the segment a..b, every metre of it a Lambertian line
 * element of intensity_per_metre candela across the segment (and
 * intensity_per_metre sin(alpha) at an angle alpha from it). Exact in
 * closed form, over the part of the segment above p's horizon; 0 for points
 * on the segment's line. */
float lx_line_light_illuminance(lx_vec3 a, lx_vec3 b, float intensity_per_metre, lx_vec3 p,
                                lx_vec3 n);

/* A tube: a cylinder of radius and length along axis (normalized here),
 * centred on centre, with hemispherical caps, of luminance L (its intensity
 * toward a direction at alpha from the axis is L (2 r length sin(alpha) +
 * pi r^2)). Exact in closed form, for lights partly below the horizon too:
 * Lambert's contour integral along the capsule's silhouette (two cylinder
 * rulings and an arc of each cap's outline, or the near cap's whole outline
 * seen from within a radius of the axis line), clipped by p's horizon.
 * Against a quadrature of the capsule's surface (tests/light/test_area.c)
 * it agrees to the quadrature's own error (3e-6 at 400 steps) beside the
 * tube, beyond its ends, end-on and with the horizon through the tube. On
 * or inside the capsule: pi L. Length 0 is a sphere light. No quadrature:
 * a handful of square roots and arc tangents a call. */
float lx_tube_light_illuminance(lx_vec3 centre, lx_vec3 axis, float length, float radius,
                                float luminance, lx_vec3 p, lx_vec3 n);

typedef enum lx_area_shape {
    LX_AREA_SPHERE = 0, /* radius */
    LX_AREA_DISK,       /* radius; emits from one side */
    LX_AREA_RECT,       /* width x height; emits from one side */
    LX_AREA_TUBE        /* a cylinder of radius and length with hemispherical caps */
} lx_area_shape;

/* Luminance (nits) of an area light emitting power_lm lumens from its whole
 * surface (Lambertian, exitance pi L): sphere L = P / (4 pi^2 r^2), disk
 * P / (pi^2 r^2), rect P / (pi W H), tube P / (pi (2 pi r length + 4 pi
 * r^2)). Only the sizes of the shape are read: radius (sphere, disk, tube),
 * length (tube), width and height (rect). Fails with LX_ERR_INVALID when
 * power_lm is negative or not finite, when a size it reads is not finite
 * or not above 0 (a tube's length may be 0: it is then a sphere; a linear
 * tube, radius 0, has no finite luminance), when the shape is unknown, or
 * when the luminance overflows a float. *luminance is written only on
 * success. */
lx_status lx_area_light_luminance_from_power(lx_area_shape shape, float power_lm, float radius,
                                             float length, float width, float height,
                                             float *luminance);

/* ---- exposure ------------------------------------------------------------ */

/* Photometric exposure multiplier for an EV100: 1 / (1.2 * 2^ev100). */
float lx_exposure_from_ev100(float ev100);
/* EV100 that maps an average luminance (nits) to middle grey (K = 12.5). */
float lx_ev100_from_luminance(double average_luminance);
/* EV100 of camera settings: log2(N^2 / t * 100 / S) for f-number N,
 * shutter time t in seconds and ISO sensitivity S. Fails with
 * LX_ERR_INVALID unless all three are finite and > 0. */
lx_status lx_ev100_from_camera(float aperture, float shutter_seconds, float iso, float *ev100);

#ifdef __cplusplus
}
#endif
#endif
