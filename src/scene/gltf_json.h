/* Private to src/scene: a glTF file's own JSON, for what assimp drops or
 * changes (KHR_lights_punctual, KHR_texture_transform, the primitives'
 * index counts), and typed reads from it. */
#ifndef LX_GLTF_JSON_H
#define LX_GLTF_JSON_H

#include "luxel/scene.h"

#include <cjson/cJSON.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* What the start of a file looks like: a GLB container ("glTF" magic),
 * JSON text (a '{' after white space and an optional UTF-8 byte-order
 * mark), or anything else. */
typedef enum lx_gltf_kind { LX_GLTF_NONE = 0, LX_GLTF_GLB, LX_GLTF_TEXT } lx_gltf_kind;
lx_gltf_kind lx_gltf_sniff(const char *path);

/* The JSON of a .gltf (the whole file) or .glb (its JSON chunk, located
 * through the 12-byte header; the binary chunk is not read). *root is
 * freed by the caller with cJSON_Delete. */
lx_status lx_gltf_json_read(const char *path, cJSON **root);
/* Same from bytes in memory; file names them in messages. */
lx_status lx_gltf_json_read_memory(const char *file, const void *bytes, size_t size, cJSON **root);

/* True when asset.version is "2.x". */
bool lx_gltf_is_v2(const cJSON *root);

/* ---- typed values -------------------------------------------------------- */

/* obj[key] when obj is an object, else NULL. */
const cJSON *lx_gltf_get(const cJSON *obj, const char *key);
/* The string at key, or NULL when absent or not a string. */
const char *lx_gltf_get_string(const cJSON *obj, const char *key);
/* A finite number that is also finite as a float. */
bool lx_gltf_number(const cJSON *item, float *out);
/* An array of exactly n such numbers. */
bool lx_gltf_numbers(const cJSON *item, float *out, int n);
/* An integer index in [0, count). */
bool lx_gltf_index(const cJSON *item, size_t count, size_t *out);
/* The UV sets the textures of a material object read, bit k for
 * TEXCOORD_k (k < 32): every "texCoord" in it, core textures', extensions'
 * and KHR_texture_transform's alike. */
uint32_t lx_gltf_texcoords_read(const cJSON *material);
/* "node 3 ('Lamp')" for messages. */
void lx_gltf_label(char *buf, size_t size, const char *what, size_t index, const cJSON *obj);

/* ---- the node hierarchy (gltf_nodes.c) ---------------------------------- */

typedef struct lx_gltf_graph {
    size_t count;
    const cJSON **nodes; /* count */
    int64_t *parent;     /* -1 for roots */
    lx_mat4 *world;
    bool *included; /* in the scene being loaded (lx_gltf_graph_select) */
    size_t *order;  /* nodes parents first; reached entries */
    size_t reached;
} lx_gltf_graph;

/* Checks "nodes" and their children and computes every world matrix;
 * fails naming the node (a malformed transform, a cycle...). Free g with
 * lx_gltf_graph_free, also after a failure. */
lx_status lx_gltf_graph_build(const char *file, const cJSON *root, lx_gltf_graph *g);
/* Marks the nodes of the default scene ("scene", else scenes[0]), or every
 * node when the file has no scenes. */
lx_status lx_gltf_graph_select(const char *file, const cJSON *root, lx_gltf_graph *g);
void lx_gltf_graph_free(lx_gltf_graph *g);

/* ---- readers -------------------------------------------------------------- */

/* KHR_lights_punctual from a parsed glTF (gltf_lights.c). */
lx_status lx_gltf_lights_from_json(lx_scene *scene, const char *file, const cJSON *root);

/* glTF cameras placed by the default scene's nodes (gltf_cameras.c); bad
 * ones are left out with a warning, never failing the load. */
lx_status lx_gltf_cameras_from_json(lx_scene *scene, const char *file, const cJSON *root);
/* Fails (LX_ERR_FORMAT, naming the camera or node) when a camera is not
 * an object with a known type and its parameters object, or a node's
 * "camera" is not an index into "cameras": assimp refuses such files with
 * a message that names neither, so this is checked before it reads one. */
lx_status lx_gltf_check_cameras(const char *file, const cJSON *root);

/* What the JSON says about one texture of a material (gltf_textures.c). */
typedef struct lx_gltf_texture_ref {
    bool present;              /* the material names this texture */
    uint32_t tex_coord;        /* texCoord, or KHR_texture_transform's override */
    lx_uv_transform transform; /* KHR_texture_transform, enabled when given */
} lx_gltf_texture_ref;

/* The base-colour texture and normalTexture of glTF material `index`,
 * whose JSON object is material (both zeroed when it is not an object):
 * pbrMetallicRoughness's baseColorTexture, or with spec_gloss
 * KHR_materials_pbrSpecularGlossiness's diffuseTexture (the material's
 * albedo then, its metallic-roughness part a fallback for readers without
 * the extension). Malformed extension fields fail naming the file, the
 * material and the field. */
lx_status lx_gltf_material_textures(const char *file, const cJSON *material, size_t index,
                                    bool spec_gloss, lx_gltf_texture_ref *base_color,
                                    lx_gltf_texture_ref *normal);

/* The emissiveTexture of glTF material `index` (zeroed when none). */
lx_status lx_gltf_material_emissive_texture(const char *file, const cJSON *material, size_t index,
                                            lx_gltf_texture_ref *emissive);

/* emissiveFactor times KHR_materials_emissive_strength of glTF material
 * `index` (zero when it states none). */
lx_status lx_gltf_material_emissive(const char *file, const cJSON *material, size_t index,
                                    lx_vec3 *out);

/* The primitives of the file's meshes as the JSON states them, flat in
 * file order: mesh 0's primitives, then mesh 1's, ... (what matches them
 * to assimp's meshes is the node hierarchy: import_assimp.c). */
#define LX_GLTF_NO_MATERIAL (-1)  /* the primitive names no material */
#define LX_GLTF_BAD_MATERIAL (-2) /* "material" is not a valid index */
typedef struct lx_gltf_primitives {
    size_t mesh_count; /* entries of "meshes" */
    size_t *first;     /* mesh_count + 1 entries: mesh m holds first[m]..first[m+1]-1 */
    size_t count;      /* primitives in all */
    /* per primitive: */
    uint32_t *mesh;      /* its mesh */
    uint64_t *triangles; /* triangles of a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN
                          * primitive (glTF 2.0 spec, 3.7.2.1), UINT64_MAX when that
                          * cannot be told (other modes, missing or malformed
                          * accessors: assimp reports those itself) */
    int64_t *material;   /* material index, LX_GLTF_NO_MATERIAL or LX_GLTF_BAD_MATERIAL */
    int8_t *mode;        /* 0..6, or -1 when "mode" is not one of them */
} lx_gltf_primitives;

/* Reads every mesh's primitives (a mesh that is not an object or has no
 * "primitives" array has none). Free with lx_gltf_primitives_free, also
 * after a failure (which leaves *out empty). */
lx_status lx_gltf_primitives_read(const char *file, const cJSON *root, lx_gltf_primitives *out);
void lx_gltf_primitives_free(lx_gltf_primitives *p);

/* ---- what assimp cannot read (gltf_rewrite.c) ---------------------------- */

/* Fails with LX_ERR_UNSUPPORTED naming the first extension in
 * extensionsRequired that luxel does not read; one that only adds an image
 * format (KHR_texture_basisu, EXT_texture_webp, EXT_texture_avif) is a
 * warning: the file loads without those textures. */
lx_status lx_gltf_check_required(const char *file, const cJSON *root);
/* Whether bytes (or the start of the file at path) are a Git LFS pointer. */
bool lx_lfs_pointer(const void *bytes, size_t size);
bool lx_lfs_pointer_file(const char *path);
/* Fails naming the first buffer or image file (uri) that lies outside the
 * file's folder (unless allow_any_path; lx_path_confine) or is a Git LFS
 * pointer, and the first base64 data: URI that is not base64 or, for a
 * buffer, holds fewer bytes than its byteLength. */
lx_status lx_gltf_check_files(const char *path, const cJSON *root, bool allow_any_path);
/* When the file uses EXT_meshopt_compression or quantized vertex
 * attributes (KHR_mesh_quantization), decodes them: root is changed in
 * place (the same nodes, meshes, accessors and materials; new buffers and
 * bufferViews) and *glb receives the whole file as a GLB (malloc'd) for
 * assimp. Otherwise *glb is NULL and root unchanged. */
lx_status lx_gltf_rewrite(const char *path, cJSON *root, uint8_t **glb, size_t *glb_size);
/* The same for EXT_meshopt_compression alone (quantized attributes stay as
 * they are, KHR_mesh_quantization listed as before): what a file written
 * again with lightmap UVs starts from. */
lx_status lx_gltf_decode_meshopt(const char *path, cJSON *root, uint8_t **glb, size_t *glb_size);
/* Every accessor within its bufferView and every bufferView within its
 * buffer, by the JSON's numbers (gltf_ranges.c); the error names the
 * accessor or view and how many bytes it overruns. */
lx_status lx_gltf_check_ranges(const char *path, const cJSON *root);

#endif
