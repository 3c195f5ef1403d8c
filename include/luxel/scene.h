/* luxel/scene.h - triangle meshes, materials, nodes (instances) and lights:
 * import from glTF 2.0 and OBJ files, programmatic
 * construction, and the lights JSON that adds to or overrides a scene.
 *
 * CONVENTIONS  Right-handed, +Y up, metres. Mesh data is in object space;
 *   a node places one or more meshes with its world matrix. UV origin at the
 *   top-left of the image (glTF); OBJ's bottom-left V is flipped on import.
 *   uv[0] is TEXCOORD_0, uv[1] TEXCOORD_1. Tangents are xyz + w handedness:
 *   bitangent = cross(normal, tangent.xyz) * w (glTF).
 *   Lights are world-space lx_lights with native units (cd, lx). What
 *   assimp drops or changes is read from a glTF file's own JSON:
 *   KHR_lights_punctual's fields, KHR_texture_transform (lx_uv_transform)
 *   and its texCoord override.
 * ERRORS  Loaders fail with a message naming the file and the place:
 *   "room.glb: mesh 'floor': vertex 12: position is not finite".
 *   Problems that do not stop a load (a mesh with no UVs...) are reported
 *   through lx_log as warnings.
 * MEMORY  lx_scene_load / lx_scene_create allocate; lx_scene_destroy frees
 *   the scene and everything it points to. Pointers into a scene are
 *   borrowed until lx_scene_destroy.
 * THREADING  lx_scene_load, lx_gltf_lights_load and lx_triangle_degenerate
 *   are thread-safe. Loads on several threads run at once except while
 *   assimp reads a file (one file at a time: assimp keeps its last error in
 *   one process-wide string); a glTF file whose meshes cannot all be
 *   matched to the file's primitives is imported alone, with assimp's
 *   process-wide log attached. A program that calls assimp's C API itself
 *   must not import or attach log streams while lx_scene_load runs. A scene
 *   is read-only once built: reading one from several threads is safe, but
 *   the functions that change a scene (lx_scene_add_*,
 *   lx_scene_adopt_profile, lx_lights_json_apply*) must not run while
 *   another thread uses it.
 *
 * USAGE
 *   lx_scene *scene;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK) {
 *       fprintf(stderr, "%s\n", lx_last_error());
 *       return 1;
 *   }
 *   printf("%u nodes, %u lights\n", scene->node_count, scene->light_count);
 *   lx_scene_destroy(scene);
 */
#ifndef LUXEL_SCENE_H
#define LUXEL_SCENE_H

#include "luxel/core.h"
#include "luxel/light.h"
#include "luxel/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* UV sets a mesh keeps: TEXCOORD_0 to TEXCOORD_7, as assimp reads them
 * (three.js reads four: uv to uv3). */
#define LX_MAX_UV_SETS 8

typedef struct lx_mesh {
    char *name;
    uint32_t vertex_count;
    uint32_t triangle_count;
    lx_vec3 *positions;          /* vertex_count */
    lx_vec3 *normals;            /* vertex_count, unit length */
    lx_vec4 *tangents;           /* vertex_count or NULL */
    lx_vec2 *uv[LX_MAX_UV_SETS]; /* vertex_count each, or NULL */
    uint32_t *indices;           /* 3 * triangle_count */
    uint32_t material;           /* index into scene->materials */
    /* Where the mesh came from, so a writer can map it back to the file.
     * dropped_triangles: zero-area triangles the importer left out (they
     * are not in indices). source_mesh, source_primitive: the glTF mesh
     * and primitive index it is (assimp makes one mesh per primitive,
     * shared by every node that instances it), -1 when not glTF or not
     * matched to the file's primitives. lx_scene_add_mesh copies these as
     * given: set -1 when building meshes by hand. */
    uint32_t dropped_triangles;
    int32_t source_mesh, source_primitive;
} lx_mesh;

/* A texture's KHR_texture_transform (Khronos extension spec): the texture
 * is read at uv' = offset + R(rotation) * (scale * uv), R = [cos -sin;
 * sin cos] - the extension's matrix translation * rotation * scale, in
 * glTF's UV space (origin top-left, as every UV in luxel). A zeroed struct
 * (enabled false) is the identity. */
typedef struct lx_uv_transform {
    bool enabled;   /* false: uv' = uv and the fields below are ignored */
    lx_vec2 offset; /* in UV units */
    float rotation; /* radians */
    lx_vec2 scale;
} lx_uv_transform;

/* uv' for uv under t (computed in double, rounded once). */
static inline lx_vec2 lx_uv_transform_apply(const lx_uv_transform *t, lx_vec2 uv)
{
    if (!t->enabled)
        return uv;
    double c = cos((double)t->rotation), s = sin((double)t->rotation);
    double su = (double)t->scale.x * uv.x, sv = (double)t->scale.y * uv.y;
    return lx_v2((float)(t->offset.x + c * su - s * sv), (float)(t->offset.y + s * su + c * sv));
}

/* Textures are sampled bilinearly with wrap-around (glTF's REPEAT) at the
 * texel's uv[*_uv_set] under *_transform. A normal map's tangent frame
 * belongs to the mesh's UV set (its tangents, else ones computed from
 * uv[normal_uv_set] as glTF asks), not to the transform: the transform
 * only moves where the map is read. */
typedef struct lx_material {
    char *name;
    lx_vec4 base_color;                   /* linear RGBA factor */
    lx_image base_color_map;              /* linear RGBA (sRGB-decoded), width 0 if none */
    int base_color_uv_set;                /* texCoord (or KHR_texture_transform's override) */
    char *base_color_map_path;            /* where it came from (for messages), or NULL */
    lx_uv_transform base_color_transform; /* KHR_texture_transform of the map */
    lx_image normal_map;                  /* raw tangent-space normals in [0,1], width 0 if none */
    float normal_scale;                   /* glTF normalTexture.scale, 1 by default */
    int normal_uv_set;                    /* UV set the normal map uses */
    char *normal_map_path;                /* where it came from (for messages), or NULL */
    lx_uv_transform normal_transform;     /* KHR_texture_transform of the map */
    lx_vec3 emissive; /* linear emitted radiance in nits: glTF emissiveFactor
                       * times KHR_materials_emissive_strength (OBJ's Ke);
                       * 0 = none. The baker's bounces gather it
                       * (lx_bake_desc.bounces, emissive_scale). */
    lx_image emissive_map;              /* linear RGBA (sRGB-decoded), width 0 if none;
                                           emission = emissive x its RGB */
    int emissive_uv_set;                /* texCoord (or KHR_texture_transform's) */
    char *emissive_map_path;            /* where it came from, or NULL */
    lx_uv_transform emissive_transform; /* KHR_texture_transform of the map */
    /* Bit k set: some texture of the material reads TEXCOORD_k - any
     * texture the file gives it (occlusion, metallic-roughness, extensions'
     * textures), not only those luxel samples. A lightmap set luxel writes
     * never takes such a set (lx_scene_lightmap_set). */
    uint32_t uv_sets_read;
    /* The lights JSON's "materials" entry (docs/lights-json.md): a height
     * texture the baker self-shadows (horizon) and occludes (ao) the
     * material's texels with, read at uv[normal_uv_set] under
     * normal_transform. NULL path = none. */
    char *height_map_path; /* resolved against the JSON's folder; loaded by the baker */
    float height_strength; /* texels of height per unit value; 0 = LX_DEFAULT_HEIGHT_STRENGTH
                            * (heights from normals: a multiplier, 0 = 1) */
    /* Or heights integrated from a normal map (lx_height_from_normals, wrap
     * repeat) when height_from_normals: the image at height_normal_path, or
     * this material's normal_map (its heights times normal_scale) when that
     * is NULL. height_map_path is then NULL. */
    bool height_from_normals;
    char *height_normal_path; /* resolved against the JSON's folder, or NULL */
    bool height_green_down;   /* that normal map's y points down the image (DirectX) */
    bool height_horizon;   /* direct light times the horizon factor */
    bool height_ao;        /* ambient and sky light times the AO map */
    /* KHR_materials_unlit: the file means it drawn as its base colour, not
     * lit (a sky dome, a backdrop). The bake still lights it; a node whose
     * every material is unlit and that encloses the scene is a sky dome
     * (lx_scene_mark_sky_domes). */
    bool unlit;
    /* glTF doubleSided (assimp's two-sided flag for other formats): both
     * faces are the surface. A view draws both (lx_render_view); a bake
     * holds one value a texel, of the face lx_bake_desc.double_sided
     * chooses, and neither face is the inside of a solid. */
    bool double_sided;
    /* Times each map was halved on load (lx_scene_load_desc's texture
     * density), 0 = as its file holds it. Heights integrated from the
     * normal map search a radius of that many fewer texels (the same
     * distance on the surface). */
    int base_color_map_halvings, normal_map_halvings, emissive_map_halvings;
} lx_material;

/* How a bake treats a node: what Unity's Cast Shadows, Receive GI,
 * Contribute GI and Scale In Lightmap, Bakery's per-object settings and
 * Godot's GI mode set. Zero is the default (the node casts shadows, gets
 * a lightmap, takes part in bounces, at the scene's texel density), so a
 * node lx_scene_add_node adds bakes as every node did before these
 * existed. lx_scene_load reads them from glTF node extras (luxel_*: see
 * docs/bake.md, "Per-node bake control") and marks sky domes; the lights
 * JSON's "nodes" section (lx_lights_json_apply) overrides both. */
typedef struct lx_node_bake {
    bool no_cast_shadows;  /* invisible to shadow rays: lights, sky, AO, emitters */
    bool no_lightmap;      /* no lightmap: needs no UVs, gets no texels, no page */
    bool no_contribute_gi; /* bounces pass through it: it reflects and emits
                              nothing into other texels, and does not make
                              texels that see its back faces invalid */
    float lightmap_scale;  /* texel-density multiplier of its lightmap (or, at a
                              fixed resolution, of its side), > 0; 0 = 1 */
    bool sky;              /* a sky dome (lx_scene_mark_sky_domes, or marked):
                              left out of lx_scene_bounds, the default camera,
                              the CLI's default texel density and camera rays.
                              The three no_* flags are what bakes it: marking
                              sets them, and settings given later change them */
    bool backdrop;         /* a ground or terrain running far past the rest
                              (lx_scene_mark_backdrops): baked as any node, at
                              the lowered lightmap_scale marking gave it; left
                              out of the default camera's framing */
} lx_node_bake;

/* lightmap_scale with its default applied. */
static inline float lx_node_lightmap_scale(const lx_node_bake *b)
{
    return b->lightmap_scale > 0.0f ? b->lightmap_scale : 1.0f;
}

typedef struct lx_node {
    char *name;       /* unique within the scene */
    lx_mat4 world;    /* object to world */
    uint32_t *meshes; /* indices into scene->meshes */
    uint32_t mesh_count;
    int32_t source_node; /* the glTF node index, -1 when not glTF, not matched
                          * or added with lx_scene_add_node */
    lx_node_bake bake;   /* zero (the default) from lx_scene_add_node */
} lx_node;

#define LX_MAX_SKY_SAMPLES 65536u

/* The sky a lights JSON asks for ("sky" key): the environment file is
 * named, not loaded (lx_env_load in ibl.h reads it). */
typedef struct lx_scene_sky {
    char *environment; /* path resolved against the JSON's folder; NULL = none */
    float intensity;   /* multiplier, default 1 */
    bool shadows;
    uint32_t samples; /* 1..LX_MAX_SKY_SAMPLES, 0 = the baker's default */
} lx_scene_sky;

/* A camera a scene file places (glTF "cameras" and the nodes that refer
 * to them). It looks down its node's local -Z with local +Y up (glTF
 * 2.0, 3.10); eye, forward and up are that frame in world space. */
typedef enum lx_scene_camera_type {
    LX_SCENE_CAMERA_PERSPECTIVE = 0,
    LX_SCENE_CAMERA_ORTHOGRAPHIC
} lx_scene_camera_type;

typedef struct lx_scene_camera {
    char *name;      /* the glTF camera's name, else its node's, else "camera<N>";
                        unique within the scene (repeats get "_2", "_3"...) */
    char *node_name; /* the node that places it, or NULL when unnamed */
    int32_t source_camera, source_node; /* glTF indices, -1 when not glTF */
    lx_scene_camera_type type;
    lx_vec3 eye;     /* world position */
    lx_vec3 forward; /* unit world direction of local -Z */
    lx_vec3 up;      /* unit, orthogonal to forward: local +Y made so */
    float yfov;      /* perspective: vertical field of view, radians, in (0, pi) */
    float aspect;    /* width / height the file states, 0 = none (a renderer
                        uses its image's) */
    float znear, zfar; /* metres; zfar 0 = infinite */
    float xmag, ymag;  /* orthographic: half width and height, metres */
} lx_scene_camera;

typedef struct lx_scene {
    char *path; /* file the scene came from, or a given name */
    lx_mesh *meshes;
    uint32_t mesh_count;
    lx_material *materials;
    uint32_t material_count;
    lx_node *nodes; /* only nodes that carry meshes */
    uint32_t node_count;
    lx_light *lights;
    uint32_t light_count;
    lx_vec3 ambient;           /* constant scene ambient (lux) */
    lx_scene_sky sky;          /* from the lights JSON; loading it is the caller's */
    lx_ies_profile **profiles; /* photometric profiles the lights point to */
    uint32_t profile_count;
    lx_scene_camera *cameras; /* the file's cameras, in glTF node order */
    uint32_t camera_count;
    bool allow_any_path; /* files named by the scene's lights JSON (IES
                            profiles) may lie outside its folder; set by
                            lx_scene_load from its desc */
} lx_scene;

/* The largest texture a scene load decodes, in pixels (8192 x 8192, the
 * largest most engines and GPUs take): a larger one is refused from its
 * header, before decoding, with a warning naming its size, and its
 * material goes without the map, as for any texture that does not load. */
#define LX_SCENE_TEXTURE_MAX_PIXELS ((uint64_t)8192 * 8192)

/* Textures at the resolution a bake reads them (lx_scene_load_desc's
 * texture_density): each texture is halved on load (lx_image_load_desc's
 * keep_pixels, an area average) while every node reading it keeps at
 * least LX_TEXTURE_TEXELS_PER_TEXEL texture texels across each of its
 * lightmap texels - over the node's triangles that read it, texture
 * pixels x UV area (under the texture's transform; repeats count) >=
 * LX_TEXTURE_TEXELS_PER_TEXEL^2 x density^2 x world area - and while it
 * keeps LX_TEXTURE_MIN_PIXELS pixels (256 x 256): a texture of at most
 * 512 x 512 pixels is decoded as it always was. A texture whose readers'
 * UVs have no area is kept whole; one no node reads keeps the minimum. */
#define LX_TEXTURE_TEXELS_PER_TEXEL 2
#define LX_TEXTURE_MIN_PIXELS ((uint64_t)256 * 256)

/* The lightmap texel density (texels per metre) a bake will give node of
 * scene, whose geometry and nodes are loaded; 0 when its textures are
 * read at no particular density (it then keeps its textures whole). */
typedef float (*lx_texture_density_fn)(void *user, const lx_scene *scene, uint32_t node);

typedef struct lx_scene_load_desc {
    bool strict;        /* fail (LX_ERR_FORMAT) on zero-area triangles instead
                           of dropping them with one warning */
    bool skip_textures; /* name textures (the *_map_path fields) without
                           decoding them: the maps stay empty (luxel info) */
    bool allow_any_path; /* read files the scene names (buffers, textures,
                            material libraries) wherever they are; by
                            default only files in the scene file's folder
                            or below it are read, others fail the load */
    float texture_density; /* > 0: the lightmap texels per metre the scene
                              will be baked at; textures are decoded no
                              finer than that needs (LX_TEXTURE_TEXELS_PER_TEXEL);
                              0 = every texture as its file holds it */
    lx_texture_density_fn texture_density_fn; /* or the density of each node,
                              called once per node after the geometry is
                              loaded and before any texture is decoded;
                              overrides texture_density; may be NULL */
    void *texture_density_user; /* passed to texture_density_fn */
} lx_scene_load_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_scene_load_desc lx_scene_load_desc_defaults(const lx_scene_load_desc *desc);

/* Imports a scene file through assimp: glTF 2.0 (.gltf, .glb), OBJ (.obj),
 * and Collada (.dae), FBX (.fbx), PLY and STL, plus the
 * KHR_lights_punctual lights of glTF files (other formats' lights are not
 * read: one warning when a file has some; the lights JSON adds them).
 * Other names fail with LX_ERR_UNSUPPORTED. desc may be NULL.
 * glTF cameras placed by the default scene's nodes become scene->cameras
 * (perspective and orthographic; world transforms of the nodes). A camera
 * that cannot be used - a yfov that is not a finite angle in (0, pi) or
 * missing, an orthographic xmag or ymag of 0, a node transform with no -Z
 * or +Y axis (zero scale) - is left out with one warning through lx_log
 * naming the file and the camera or node, and does not fail the load; a
 * camera of an unknown type or without its parameters object and a node
 * naming a camera the file lacks fail it (LX_ERR_FORMAT, naming the
 * camera or node: assimp refuses such files). Camera fields luxel does
 * not read (extras, extensions) are ignored.
 * glTF extensions: KHR_mesh_quantization, EXT_meshopt_compression (decoded
 * by luxel before assimp reads the file), KHR_texture_transform,
 * KHR_materials_emissive_strength, KHR_materials_unlit,
 * KHR_materials_pbrSpecularGlossiness (diffuseFactor x diffuseTexture is
 * the base colour, preferred to a pbrMetallicRoughness fallback beside
 * it) and KHR_lights_punctual are read; nodes' luxel_* extras set their bake
 * settings (lx_node.bake; a bad value fails the load naming the node and
 * the key) and sky domes are marked (lx_scene_mark_sky_domes); a file
 * whose extensionsRequired names any other fails with LX_ERR_UNSUPPORTED
 * naming it. A scene, buffer or texture that is a Git LFS pointer is named
 * as one. Triangles of zero area in space are dropped with one warning per
 * load that counts them (lx_mesh.dropped_triangles), or fail the load with
 * desc->strict; non-finite values and out-of-range indices fail it with a
 * message naming the mesh. A glTF
 * material whose KHR_texture_transform cannot be told (assimp's material
 * matches none of the file's through the scene's meshes, and the file's
 * materials of its name state different transforms) fails the load with
 * LX_ERR_UNSUPPORTED naming the material rather than take a wrong one.
 * Textures are decoded after the geometry, one at a time, into the
 * scene's materials, at the size desc's texture density leaves them
 * (LX_TEXTURE_TEXELS_PER_TEXEL); memory while one loads: its file, its
 * decoded 8-bit (16-bit, float for HDR) samples and its float image as
 * kept. A texture that cannot be read or is larger than
 * LX_SCENE_TEXTURE_MAX_PIXELS is a warning and its material goes
 * without it. */
lx_status lx_scene_load(const char *path, const lx_scene_load_desc *desc, lx_scene **out);

/* An empty scene named name (used in messages). */
lx_status lx_scene_create(const char *name, lx_scene **out);
void lx_scene_destroy(lx_scene *scene);

/* Adds a copy of mesh (all arrays are copied; normals computed from faces
 * when NULL). Returns its index in *index (may be NULL). Validates it. */
lx_status lx_scene_add_mesh(lx_scene *scene, const lx_mesh *mesh, uint32_t *index);
/* Adds a copy of material (normal map image copied). */
lx_status lx_scene_add_material(lx_scene *scene, const lx_material *material, uint32_t *index);
/* Adds a node placing meshes with world; name must be unique. */
lx_status lx_scene_add_node(lx_scene *scene, const char *name, const lx_mat4 *world,
                            const uint32_t *meshes, uint32_t mesh_count, uint32_t *index);
/* The scene takes over one reference to profile (freed with the scene), so
 * its lights may point to it. */
lx_status lx_scene_adopt_profile(lx_scene *scene, lx_ies_profile *profile);
/* Adds a copy of light after validating it; a light whose name matches an
 * existing light's replaces it. */
lx_status lx_scene_add_light(lx_scene *scene, const lx_light *light);

/* Adds a copy of camera (names copied) after checking it: finite, forward
 * and up unit and orthogonal (within 1e-3), a perspective yfov in (0, pi),
 * an orthographic xmag and ymag not 0. A NULL or empty name becomes
 * "camera<N>"; a name already taken fails (LX_ERR_INVALID). */
lx_status lx_scene_add_camera(lx_scene *scene, const lx_scene_camera *camera);

/* True when triangle abc has negligible area next to its edges, or a
 * height (twice its area over its longest edge) of at most 16 units in the
 * last place of its largest coordinate: three points on a line, rounded
 * to floats (its normal cannot be trusted). */
bool lx_triangle_degenerate(lx_vec3 a, lx_vec3 b, lx_vec3 c);

/* World-space bounds of every node's meshes but sky domes (bake.sky),
 * or of every node's when all are sky domes. false when empty. */
bool lx_scene_bounds(const lx_scene *scene, lx_vec3 *lo, lx_vec3 *hi);

/* Sky domes: a node whose every material is unlit (lx_material.unlit,
 * KHR_materials_unlit) and whose world bounds contain the bounds of every
 * node that is neither unlit nor already a sky, with a diagonal at least
 * LX_SKY_DOME_RATIO times theirs. Each such node gets bake.sky and the
 * three no_* flags (it casts no shadows, gets no lightmap and takes no part
 * in bounces), and one warning through lx_log names it (the first, and how
 * many more). lx_scene_load calls this after reading node extras, leaving
 * alone a node whose extras say luxel_sky. Returns the nodes marked. */
#define LX_SKY_DOME_RATIO 4.0f
uint32_t lx_scene_mark_sky_domes(lx_scene *scene);

/* Marks a backdrop: the lightmapped node (not a sky, with a lightmap)
 * holding more than half of the lightmapped world area (each node's area
 * times its lightmap_scale squared) and at least LX_BACKDROP_MIN_AREA m^2
 * (what luxel bake's default budget of 2^20 texels covers at 10 texels a
 * metre; below, a room's floor under one crate, the density is the most
 * it gives anyway), whose bounds' largest extent is at
 * least LX_BACKDROP_RATIO times that of the other lightmapped nodes
 * together, and whose lightmap_scale is not set: it gets bake.backdrop
 * and the lightmap_scale that leaves it LX_BACKDROP_SHARE of the texels
 * at any density (at least 1 / 1024), and one warning through lx_log
 * names it. lx_scene_load calls this after the sky domes, leaving alone a
 * node whose extras set its lightmap scale. Returns the nodes marked (0
 * or 1). */
#define LX_BACKDROP_RATIO 8.0f
#define LX_BACKDROP_MIN_AREA 10000.0
#define LX_BACKDROP_SHARE 0.1
uint32_t lx_scene_mark_backdrops(lx_scene *scene);

/* The world-space surface area of node n's triangles, in square metres;
 * 0 for a node out of range. */
double lx_node_world_area(const lx_scene *scene, uint32_t node);

/* Reads a lights JSON file (docs/lights-json.md) and applies it: its
 * "ambient" sets scene->ambient, each light is added or overrides the scene
 * light of the same name (an override starts from that light and changes
 * only the keys given), its "nodes" entries (by name or glob) change the
 * matching nodes' bake settings (lx_node.bake; a pattern matching no node
 * is one warning through lx_log). All or nothing: on failure, naming the
 * file and the field, the scene is unchanged. */
lx_status lx_lights_json_apply(lx_scene *scene, const char *path);
/* Same from text already in memory; name is used in messages. */
lx_status lx_lights_json_apply_text(lx_scene *scene, const char *text, size_t size,
                                    const char *name);

/* Reads the KHR_lights_punctual lights of a .gltf or .glb file (of its
 * default scene, else the first, else every parentless node) and adds them,
 * placed by their nodes' world transforms. A light is named after the glTF
 * light, else its node, else "light<N>"; repeated names get "_2", "_3"...
 * Files without the extension add nothing. */
lx_status lx_gltf_lights_load(lx_scene *scene, const char *path);
lx_status lx_gltf_lights_load_memory(lx_scene *scene, const void *bytes, size_t size,
                                     const char *name);

/* ---- writing a scene with lightmap UVs (glTF binary) ---------------------- */

/* A per-vertex attribute a writer adds (or replaces, when the primitive
 * has one of that name): components floats per vertex. */
typedef struct lx_vertex_attribute {
    const char *name; /* glTF attribute name: "TANGENT", "TEXCOORD_2"... */
    int components;   /* 1..4 (SCALAR, VEC2, VEC3, VEC4) */
    const float *data; /* components * the entry's vertex_count, finite */
} lx_vertex_attribute;

/* node of an entry that applies to a mesh wherever it is placed: the
 * mesh is changed in place instead of copied per node. */
#define LX_SCENE_EVERY_NODE UINT32_MAX

/* New vertices for one mesh as one node places it (or as every node does,
 * node = LX_SCENE_EVERY_NODE): each a copy of mesh vertex vertex_source[v]
 * (all its attributes), with the lightmap UV uv[v] when uv is not NULL
 * and the extra attributes, and the mesh's triangles over them in the
 * same order (lx_unwrap_mesh in unwrap.h has the first fields). */
typedef struct lx_scene_uvs {
    uint32_t node, mesh; /* scene indices; the node places the mesh */
    uint32_t vertex_count;
    const uint32_t *vertex_source; /* vertex_count */
    const lx_vec2 *uv;             /* vertex_count, top-left origin; NULL: no lightmap set */
    const uint32_t *indices;       /* 3 * the mesh's triangle_count */
    const lx_vertex_attribute *attributes; /* attribute_count, per new vertex */
    uint32_t attribute_count;
} lx_scene_uvs;

typedef struct lx_glb_write_desc {
    const lx_scene_uvs *uvs; /* uv_count entries, at most one per (node, mesh) */
    uint32_t uv_count;
} lx_glb_write_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_glb_write_desc lx_glb_write_desc_defaults(const lx_glb_write_desc *desc);

/* Writes scene as a .glb at path (atomically: a temporary file renamed
 * when complete) with the UVs desc gives as the lightmap set.
 * A scene loaded from glTF is written from its file, read again:
 * everything stays as it was (materials, nodes, animations, skins,
 * extensions, extras) except that each primitive with new UVs gets every
 * vertex attribute and morph target rebuilt per new vertex, new indices
 * (mode TRIANGLES, triangles in the file's order) and the UVs as
 * TEXCOORD_n, n = lx_scene_lightmap_set of the node (replacing a set of
 * that name, which no material of the node reads). A primitive lacking a
 * set below n gets the UVs there too (sets are numbered from 0 without
 * gaps). A mesh that several nodes place with new UVs is copied for
 * every node after the first. An entry's attributes are added to its
 * primitive, replacing those of the same name (a TANGENT is left out, with
 * a warning through lx_log, where the file's primitive has no NORMAL).
 * All buffers become the GLB's binary chunk and images are embedded in it;
 * accessors and bufferViews the rewrite left unused are dropped (unless
 * the file uses an extension luxel does not know, which might refer to
 * them).
 * Other scenes (OBJ, built ones) are written from luxel's data: one node
 * per scene node (its world matrix), one primitive per mesh with POSITION,
 * NORMAL, TANGENT, TEXCOORD_0 and the lightmap TEXCOORD_1 (and the
 * entries' attributes), materials with
 * their base colour factor and PNG/JPEG textures embedded.
 * EXT_meshopt_compression views are written decoded, without the
 * extension (quantized attributes stay as they are).
 * Fails (nothing written) with LX_ERR_INVALID when an entry names a node
 * or mesh the scene does not pair, LX_ERR_UNSUPPORTED for Draco-compressed
 * glTF or a mesh luxel could not match to the file's primitives,
 * LX_ERR_IO / LX_ERR_FORMAT naming the file and the part. */
lx_status lx_scene_write_glb(const lx_scene *scene, const char *path, const lx_glb_write_desc *desc);

/* The UV set that holds the lightmap UVs luxel makes for node n (written
 * by lx_scene_write_glb, named by the bake's manifest, read back by
 * lx_bake_uv_set and luxel render): TEXCOORD_1, or when a material of one
 * of the node's meshes reads a texture through it (lx_material.uv_sets_read)
 * the lowest set above it that none reads. -1 when every set below
 * LX_MAX_UV_SETS is read. */
int lx_scene_lightmap_set(const lx_scene *scene, uint32_t node);

#ifdef __cplusplus
}
#endif
#endif
