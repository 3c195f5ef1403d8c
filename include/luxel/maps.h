/* luxel/maps.h - texture-space tools: tangent frames, height fields and
 * the maps made from them (normal, parallax, horizon, ambient occlusion).
 *
 * CONVENTIONS  UV origin at the top-left (glTF). A height field is a
 *   one-channel lx_image, row 0 at the top; a value v is a height of
 *   strength * v texels. Image x runs along columns, y up the image (toward
 *   row 0). Texels outside the image are addressed by an lx_wrap mode, at
 *   any size (not only powers of two). docs/maps.md has the pictures. Tangents are xyz + w
 *   handedness with bitangent = cross(normal, tangent.xyz) * w, the glTF
 *   convention: the tangent follows +u and the bitangent points toward -v
 *   (up in the image), matching normal maps whose green channel is "up".
 * ERRORS  LX_ERR_INVALID for missing inputs.
 * MEMORY  The caller owns every buffer.
 * THREADING  Every function is thread-safe (pure: it reads its inputs and
 *   writes only the caller's buffers).
 *
 * USAGE
 *   lx_scene *scene;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK) return 1;
 *   const lx_mesh *mesh = &scene->meshes[0];
 *   lx_vec4 *t = malloc(sizeof *t * mesh->vertex_count);
 *   if (t && lx_compute_tangents(mesh, 0, t) == LX_OK) {
 *       lx_vec3 m = lx_v3(0.6f, 0, 0.8f);   // a normal-map texel, tangent space
 *       lx_vec3 n = lx_tangent_to_world(m, mesh->normals[0], t[0]);
 *       printf("perturbed normal (%g, %g, %g)\n", n.x, n.y, n.z);
 *   }
 *   free(t);
 *   lx_scene_destroy(scene);
 */
#ifndef LUXEL_MAPS_H
#define LUXEL_MAPS_H

#include "luxel/core.h"
#include "luxel/math.h"
#include "luxel/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- height fields ------------------------------------------------------ */

/* How texel indices outside [0, n) are addressed. REPEAT tiles (i mod n);
 * CLAMP repeats the edge texel; MIRROR reflects with the edge texel
 * repeated (OpenGL's MIRRORED_REPEAT: -1 -> 0, n -> n - 1, period 2n). */
typedef enum lx_wrap { LX_WRAP_REPEAT = 0, LX_WRAP_CLAMP, LX_WRAP_MIRROR } lx_wrap;

/* i addressed into [0, n) by wrap, for any int i; n must be >= 1. */
int lx_wrap_index(lx_wrap wrap, int i, int n);
/* "repeat", "clamp" or "mirror"; NULL for another value. */
const char *lx_wrap_name(lx_wrap wrap);
/* The mode named name (as lx_wrap_name writes it); false when none. */
bool lx_wrap_parse(const char *name, lx_wrap *out);

/* Loads a height image into a one-channel lx_image (*out, freed with
 * lx_image_free): 8- and 16-bit PNG (and TGA, JPEG) as code / 255 or
 * code / 65535 with no sRGB decoding, grey or the first channel; float
 * formats (EXR, PFM, HDR) as stored. Fails with the file named for an
 * unreadable or zero-size image and for NaN or infinite heights. On
 * failure *out is zeroed. */
lx_status lx_height_load(const char *path, lx_image *out);

/* The height scale every tool uses when a desc leaves strength at 0: a
 * value v is a height of 24 v texels (the seed's example scale). */
#define LX_DEFAULT_HEIGHT_STRENGTH 24.0f

/* ---- normal maps -----------------------------------------------------------
 * Normals from a height field (Lengyel, FGED vol. 2 sec. 7.5): with h in
 * texels (strength * value), n is proportional to (-dh/dx, -dh/dy, 1), x
 * along the columns and y up the image (dh/dy = row above less row below),
 * as unit tangent-space vectors. Encoded for a texture as rgb = n/2 + 1/2.
 * Texel (x, y) of every map made here belongs to height texel (x, y): the
 * maps are the height's size, with no shift. */

/* The slope estimate. CENTRAL is the seed's (h[x+1] - h[x-1]) / 2; SOBEL
 * and SCHARR smooth across the derivative with weights 1-2-1 and 3-10-3
 * and are normalised (by 8 and 32) so a linear ramp gets the same slope
 * from all three. */
typedef enum lx_normal_filter {
    LX_NORMAL_CENTRAL = 0,
    LX_NORMAL_SOBEL,
    LX_NORMAL_SCHARR
} lx_normal_filter;

/* "central", "sobel" or "scharr"; NULL for another value. */
const char *lx_normal_filter_name(lx_normal_filter filter);
/* The filter named name; false when none. */
bool lx_normal_filter_parse(const char *name, lx_normal_filter *out);

typedef struct lx_normalmap_desc {
    float strength;          /* texels of height per unit value; 0 = LX_DEFAULT_HEIGHT_STRENGTH */
    lx_normal_filter filter; /* slope estimate (CENTRAL) */
    lx_wrap wrap;            /* addressing outside the image (REPEAT) */
    bool green_down;         /* y down the image (DirectX); default up (OpenGL, glTF) */
    int threads;             /* 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_normalmap_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_normalmap_desc lx_normalmap_desc_defaults(const lx_normalmap_desc *desc);

/* Unit tangent-space normals of a one-channel height field: *out is
 * allocated here (3 channels, height's size; free with lx_image_free) and
 * zeroed on failure. The result does not depend on desc->threads.
 * Fails (LX_ERR_INVALID) for a strength that is not finite and > 0 and
 * for a height that is not one channel. */
lx_status lx_normal_map(const lx_image *height, const lx_normalmap_desc *desc, lx_image *out);

/* Unit normals (3 or more channels; only the first three are read) to
 * texture values rgb = n/2 + 1/2 in [0,1], 3 channels, into *out
 * (allocated here). Written as 8- or 16-bit PNG with linear codes
 * (lx_image_write_desc.linear) each channel is round((n + 1)/2 * max). */
lx_status lx_normal_encode(const lx_image *normals, lx_image *out);

/* Texture values (3 or 4 channels; alpha ignored) to unit normals
 * 2 rgb - 1 normalized, 3 channels, into *out (allocated here). Fails with
 * LX_ERR_FORMAT naming name and the pixel for a value that is not a
 * direction (zero length) or not finite, and for fewer than 3 channels. */
lx_status lx_normal_decode(const lx_image *encoded, const char *name, lx_image *out);

/* ---- heights from normal maps -----------------------------------------------
 * The inverse of lx_normal_map: heights whose slopes best fit a normal
 * map's, g = (-n.x / n.z, -n.y / n.z) texels of height per texel (x along
 * the columns, y up the image; normals with z below 1/16 count as
 * z = 1/16). Least squares over every step between neighbouring texels
 * (the step's height change against the mean of its two texels' slopes),
 * solved exactly (the Poisson equation, by fast Fourier or cosine
 * transforms at any size). Heights are defined up to a constant: the
 * lowest is 0. docs/maps.md has the details and the accuracy. */

typedef struct lx_height_from_normals_desc {
    lx_wrap wrap;            /* REPEAT (default): the map tiles, steps wrap
                                around the edges; CLAMP and MIRROR: no steps
                                across the edges (Neumann boundaries) */
    bool green_down;         /* y down the image (DirectX); default up (OpenGL, glTF) */
    int threads;             /* 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_height_from_normals_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_height_from_normals_desc
lx_height_from_normals_desc_defaults(const lx_height_from_normals_desc *desc);

/* Heights in texels (strength 1: lx_normal_map with strength 1 and the
 * same wrap gives back the normals, up to the fit's error) of unit
 * tangent-space normals (lx_normal_decode; 3 or more channels, the first
 * three read; any non-zero length is normalized) into *out (one channel,
 * the normals' size, allocated here; zeroed on failure). The lowest height
 * is 0. The result does not depend on desc->threads. Fails with
 * LX_ERR_INVALID naming the texel of a normal that is not finite or has
 * zero length, LX_ERR_NOMEM (saying how much) when the work does not fit:
 * 28 bytes a texel with REPEAT, 20 otherwise, and LX_ERR_CANCELLED. */
lx_status lx_height_from_normals(const lx_image *normals, const lx_height_from_normals_desc *desc,
                                 lx_image *out);

/* How a detail normal map perturbs a base one (Barre-Brisebois and Hill,
 * "Blending in Detail", 2012). RNM (reoriented normal mapping) rotates
 * the detail by the rotation taking +z to the base normal:
 * t = b + (0,0,1), u = d * (-1,-1,1), r = t (t.u) / t.z - u. UDN:
 * normalize(b.x + d.x, b.y + d.y, b.z). WHITEOUT: normalize(b.x + d.x,
 * b.y + d.y, b.z d.z). */
typedef enum lx_normal_blend_method {
    LX_BLEND_RNM = 0,
    LX_BLEND_UDN,
    LX_BLEND_WHITEOUT
} lx_normal_blend_method;

/* "rnm", "udn" or "whiteout"; NULL for another value. */
const char *lx_normal_blend_name(lx_normal_blend_method method);
/* The method named name; false when none. */
bool lx_normal_blend_parse(const char *name, lx_normal_blend_method *out);

/* The blend of unit tangent-space normals base and detail, unit length.
 * RNM of a base pointing straight down (z = -1, no rotation defined)
 * returns detail; a UDN or Whiteout sum of zero length (opposite slopes
 * on bases lying in the plane) is (0, 0, 1). */
lx_vec3 lx_normal_blend(lx_normal_blend_method method, lx_vec3 base, lx_vec3 detail);

/* Per texel blend of two unit-normal images of the same size (3 or more
 * channels; the first three read) into *out (3 channels, allocated here).
 * threads: 0 = all cores; the result does not depend on it. Fails with
 * LX_ERR_INVALID when the sizes differ. */
lx_status lx_normal_blend_image(lx_normal_blend_method method, const lx_image *base,
                                const lx_image *detail, int threads, lx_image *out);

/* ---- parallax maps ----------------------------------------------------------
 * The seed's parallax map (FGED vol. 2 sec. 7.7): per texel n.z * v, v the
 * height value as stored (in [0,1] for PNG heights) and n.z the z of the
 * texel's normal (lx_normal_map with the same desc; its green_down is not
 * used). A renderer offsets texture coordinates toward the viewer by
 * scale * n.z * v, iterated (lx_parallax_offset). */

/* One channel, height's size, into *out (allocated here; zeroed on
 * failure). Fails as lx_normal_map does. */
lx_status lx_parallax_map(const lx_image *height, const lx_normalmap_desc *desc, lx_image *out);

/* The seed's iteration count. */
#define LX_PARALLAX_ITERATIONS 4

/* The seed's ApplyParallaxOffset: `iterations` times (0 = 4, the seed's)
 * uv += p(uv) * (view.x * scale[0], -view.y * scale[1]), p sampled
 * bilinearly from channel 0 of parallax (texel centres at
 * ((x + 0.5)/W, (y + 0.5)/H), texels outside addressed by wrap). uv has the
 * top-left origin (v down), view is the unit tangent-space direction
 * toward the viewer (x right, y up the image, z out): its y is negated
 * for v. scale is the UV offset per unit of parallax value, per
 * iteration: the moves add up, so on a smooth surface the offset is about
 * `iterations` times one move. For the physical (offset-limited) depth
 * of heights of S texels per unit value, scale = (S/W, S/H) / iterations. */
lx_vec2 lx_parallax_offset(const lx_image *parallax, lx_wrap wrap, lx_vec2 uv, lx_vec3 view,
                           const float scale[2], int iterations);

/* ---- horizon and ambient-occlusion maps ---------------------------------
 * Lengyel's horizon maps (FGED vol. 2 sec. 7.8): for each texel, the
 * largest tangent of the elevation toward higher texels within a radius,
 * in `angles` bins around the texel; eight directions (every 45 degrees
 * from +x, counter-clockwise as seen with y up the image) stored as the
 * sine of the horizon elevation averaged over each direction's bins, in
 * two RGBA layers. The ambient factor is the mean over the bins of the
 * cosine of the elevation (or of its square with ao_cosine), raised to
 * ao_power. Bin m is the direction 2 pi m / angles; a texel at distance r
 * (0 < r < radius) counts for the bins within atan(sqrt(1/2) / r) of its
 * azimuth; direction k averages the angles/8 + 1 bins within 22.5 degrees
 * of k * 45 degrees, ends included. docs/maps.md has the details. */

typedef struct lx_horizon_desc {
    float strength;          /* texels of height per unit value; 0 = LX_DEFAULT_HEIGHT_STRENGTH */
    int angles;              /* angular bins, a power of two in 16..1024; 0 = 32 */
    int radius;              /* search radius in texels, 2..256 (texels nearer
                                than it count); 0 = 16 */
    lx_wrap wrap;            /* addressing outside the image (REPEAT) */
    float ao_power;          /* exponent of the ambient factor; 0 = 1 */
    bool ao_cosine;          /* ambient factor = cosine-weighted visible fraction */
    int threads;             /* 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_horizon_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_horizon_desc lx_horizon_desc_defaults(const lx_horizon_desc *desc);

/* Horizon layers (two 4-channel images the size of height: layer0 holds
 * directions 0..3, layer1 4..7) and the ambient map (one channel); any of
 * the three outputs may be NULL. height must have one channel and finite
 * values; a desc value out of its range fails with LX_ERR_INVALID naming
 * it. The result is the same for any desc->threads. Outputs are allocated
 * here and freed with lx_image_free; on failure (and when the progress
 * callback cancels: LX_ERR_CANCELLED) they are zeroed. */
lx_status lx_horizon_map(const lx_image *height, const lx_horizon_desc *desc, lx_image *layer0,
                         lx_image *layer1, lx_image *ao);

/* The four signed channel weights for tangent-space direction dir (the
 * seed's weight cube map evaluated exactly): positive weights apply to
 * layer0, negative ones (negated) to layer1. */
void lx_horizon_weights(lx_vec3 dir, float w[4]);

/* The weight cube map the shading function samples in a shader: six faces
 * of size x size RGBA texels (+x, -x, +y, -y, +z, -z, as in cube maps),
 * stacked in one image size wide and 6 size high. */
lx_status lx_horizon_weight_cube(int size, lx_image *out);

/* Light factor in [0,1] of a texel with horizon layers h0, h1 (4 values
 * each) for the unit tangent-space light direction l (ApplyHorizonMap):
 * saturate((l.z - sin(horizon)) * hardness + 1); hardness 0 = 8. */
float lx_horizon_light(const float h0[4], const float h1[4], lx_vec3 l, float hardness);

/* ---- tangent frames --------------------------------------------------------
 * Tangents are xyz + w handedness (glTF TANGENT). MikkTSpace frames belong
 * to triangle corners: one vertex may need several (at UV seams, mirrored
 * halves, hard edges), so the corner functions write 3 * triangle_count
 * entries, out[3 * t + k] for corner k of triangle t. */

/* How tangents are computed. MIKKTSPACE (default): Mikkelsen's method,
 * agreeing with the reference implementation glTF names for files without
 * tangents. LENGYEL: per-vertex sums of triangle gradients (the seed). */
typedef enum lx_tangent_method { LX_TANGENTS_MIKKTSPACE = 0, LX_TANGENTS_LENGYEL } lx_tangent_method;

/* "mikktspace" or "lengyel"; NULL for another value. */
const char *lx_tangent_method_name(lx_tangent_method method);
/* The method named name; false when none. */
bool lx_tangent_method_parse(const char *name, lx_tangent_method *out);

/* MikkTSpace tangents per triangle corner from positions, normals and
 * uv[uv_set] (Mikkelsen 2008, with the reference implementation's default
 * settings: corners welded on equal position, normal and UV; groups split
 * by handedness; angle-weighted; degenerate triangles take a neighbouring
 * corner's frame). The handedness is for glTF's v-down UVs (the reference's
 * sign negated). Every xyz is unit length and perpendicular to the corner's
 * normal; where the reference would give a zero tangent (no UV gradient
 * anywhere around a vertex) it is any unit vector perpendicular to the
 * normal. out must hold 3 * mesh->triangle_count entries. Fails with
 * LX_ERR_INVALID when the mesh has no normals or no such UV set. */
lx_status lx_compute_tangents_mikktspace(const lx_mesh *mesh, int uv_set, lx_vec4 *out);

/* Tangents per triangle corner by method: MIKKTSPACE as above, LENGYEL the
 * per-vertex tangent of lx_compute_tangents at each corner. out must hold
 * 3 * mesh->triangle_count entries. */
lx_status lx_compute_corner_tangents(const lx_mesh *mesh, lx_tangent_method method, int uv_set,
                                     lx_vec4 *out);

/* ---- material preview --------------------------------------------------
 * A height or normal map (and a base colour) lit on a quad or a sphere by
 * one directional light (seed 002: Lambert diffuse rho/pi and Blinn-Phong
 * specular, ApplyParallaxOffset, ApplyHorizonMap). World axes: x right,
 * y up, z toward the camera, a perspective camera on +z looking at the
 * origin. The quad is the plane z = 0 filling the frame (texture tiled once
 * across it; its tangent frame is the world's, so a tangent-space light is
 * the world light); the sphere of radius sin(fov/2) D (D the camera
 * distance) just fills the frame's height, u = 1/2 + longitude / 2 pi
 * (longitude 0 facing the camera), v = 1/2 - latitude / pi, the tangent
 * along +u and the bitangent toward the north pole. Per pixel:
 *   L = base/pi (E sat(n.l) + ambient)
 *     + specular E sat(n.h)^exponent [n.l > 0]   (h = normalize(l + v))
 * the direct part times lx_horizon_light(l) with horizon shadows, and 0
 * where the light is below the geometric surface. E = colour * illuminance. */

typedef enum lx_shade_shape { LX_SHADE_QUAD = 0, LX_SHADE_SPHERE } lx_shade_shape;

typedef struct lx_shade_desc {
    const lx_image *height;  /* one channel; or NULL with normals */
    const lx_image *normals; /* unit tangent-space normals (lx_normal_decode),
                                used instead of heights when given */
    const lx_image *base_color; /* linear RGB (3 or 4 channels); NULL = grey 0.8 */
    float strength;          /* texels of height per unit value; 0 = LX_DEFAULT_HEIGHT_STRENGTH */
    lx_wrap wrap;            /* addressing outside the textures (REPEAT) */
    bool green_down;         /* normals have y down the image (DirectX) */
    lx_shade_shape shape;    /* QUAD */
    lx_vec3 light;           /* world direction toward the light; zero =
                                lx_shade_light_dir(135, 35) */
    float light_color[3];    /* all zero = white */
    float illuminance;       /* E multiplier; 0 = pi (white Lambert face-on = 1) */
    float ambient;           /* ambient illuminance (0) */
    float fov;               /* vertical field of view in degrees; 0 = 40 */
    float specular[3];       /* Blinn-Phong colour; all zero = 0.04 grey */
    float exponent;          /* Blinn-Phong power; 0 = 64 */
    bool no_specular;        /* no specular term */
    bool no_parallax;        /* no parallax offset (off anyway without heights) */
    float parallax_scale;    /* multiplier on the physical depth: a scale of
                                (S/W, S/H) / LX_PARALLAX_ITERATIONS; 0 = 1 */
    bool no_horizon;         /* no horizon shadows (off anyway without heights) */
    lx_horizon_desc horizon; /* the horizon map's settings (strength and
                                wrap are taken from this desc) */
    int out_width, out_height; /* output size in pixels; 0 = 512 */
    int threads;             /* 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_shade_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_shade_desc lx_shade_desc_defaults(const lx_shade_desc *desc);

/* The unit world direction toward a light at azimuth az (degrees,
 * counter-clockwise from +x in the quad's plane) and elevation el (degrees
 * above that plane). */
lx_vec3 lx_shade_light_dir(float az, float el);

/* Renders the preview into *out (3 channels linear RGB, allocated here;
 * zeroed on failure). The result does not depend on desc->threads. Fails
 * (LX_ERR_INVALID) without a height or normals, for a height that is not
 * one channel, normals with fewer than 3 channels, a base colour with
 * fewer than 3, a light that is not finite or zero after defaults, and
 * values out of range. */
lx_status lx_shade(const lx_shade_desc *desc, lx_image *out);

/* Per-vertex tangents from positions, normals and uv[uv_set] (Lengyel's
 * method, FGED vol. 2 ch. 7: per-triangle tangent/bitangent summed over
 * vertices, Gram-Schmidt against the normal, handedness in w). Vertices
 * whose triangles have no usable UV gradient get any tangent perpendicular
 * to the normal. out must hold mesh->vertex_count entries. */
lx_status lx_compute_tangents(const lx_mesh *mesh, int uv_set, lx_vec4 *out);

/* Tangent-space vector m (x right, y up, z out) to the frame of normal n
 * and tangent t (w = handedness); normalized. */
lx_vec3 lx_tangent_to_world(lx_vec3 m, lx_vec3 n, lx_vec4 t);

/* ---- materials at a point ---------------------------------------------------
 * A glTF material's values at a point of a mesh (barycentrics w0, w1, w2
 * of the triangle with vertex indices i[3]): each texture read bilinearly
 * at the point's UVs moved by its KHR_texture_transform. The baker reads
 * texel centres and luxel render its ray hits through these, so both see
 * a material alike. */

/* The mesh's material; a mesh without one (or a scene built without
 * materials) reads as white, non-emissive and unmapped. */
const lx_material *lx_mesh_material(const lx_scene *scene, const lx_mesh *m);

/* A material's emitted radiance in nits times scale, without texture. */
lx_vec3 lx_material_emission(const lx_material *mat, float scale);

/* Base colour factor x base-colour texture (linear RGB). */
lx_vec3 lx_material_albedo_at(const lx_material *mat, const lx_mesh *m, const uint32_t *i,
                              float w0, float w1, float w2);

/* lx_material_emission times the emissive texture's RGB. */
lx_vec3 lx_material_emission_at(const lx_material *mat, const lx_mesh *m, const uint32_t *i,
                                float w0, float w1, float w2, float scale);

/* *normal (object space, unit) bent by the material's normal map through
 * the vertex tangents (xyz, w = handedness, of the map's UV set, e.g.
 * from lx_compute_tangents); unchanged without that UV set. The caller
 * checks that the material has a normal map. */
void lx_material_normal_at(const lx_material *mat, const lx_mesh *m, const lx_vec4 *tangents,
                           const uint32_t *i, float w0, float w1, float w2, lx_vec3 *normal);

#ifdef __cplusplus
}
#endif
#endif
