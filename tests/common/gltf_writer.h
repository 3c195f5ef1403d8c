/* A small glTF 2.0 writer for tests: meshes of float32 attributes and
 * uint32 indices in one buffer embedded as a base64 data: URI, nodes,
 * materials and textures given as JSON text, and 8-bit PNG images written
 * from bytes (stb_image_write). Test inputs are made by this code, never
 * checked in. Failures end the test (cmocka's fail_msg). */
#ifndef LX_TEST_GLTF_WRITER_H
#define LX_TEST_GLTF_WRITER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct lx_test_gltf lx_test_gltf;

/* One triangle-list primitive. Arrays hold vertex_count entries of 3
 * (position, normal), 4 (tangent) or 2 (uv0, uv1) floats; NULL leaves the
 * attribute out. index_count 0 writes a non-indexed primitive. */
typedef struct lx_test_primitive {
    int vertex_count;
    const float *position;
    const float *normal;
    const float *tangent;
    const float *uv0, *uv1;
    int index_count;
    const uint32_t *indices;
    int material; /* -1: none */
    bool points;  /* mode 0 (POINTS) instead of 4 (TRIANGLES) */
} lx_test_primitive;

lx_test_gltf *lx_test_gltf_new(void);
void lx_test_gltf_free(lx_test_gltf *g);

/* A mesh of count primitives; returns its index. */
int lx_test_gltf_mesh(lx_test_gltf *g, const char *name, const lx_test_primitive *prims, int count);
/* A root node carrying mesh (< 0: none); members is more JSON inside the
 * node's object ("" for none), e.g. "\"translation\":[0,1,0]". */
int lx_test_gltf_node(lx_test_gltf *g, const char *name, int mesh, const char *members);
/* A node named name (NULL: no name) carrying mesh (< 0: none), listed in
 * the scene's nodes when root (else a child, through "children" in another
 * node's members, or a node no scene lists); returns its index. */
int lx_test_gltf_node_ex(lx_test_gltf *g, const char *name, int mesh, const char *members,
                         bool root);
/* Replaces the "scene" and "scenes" members written by default ("scene":0
 * and one scene of the root nodes) by members, e.g.
 * "\"scene\":1,\"scenes\":[{\"nodes\":[0]},{\"nodes\":[1,2]}]". */
void lx_test_gltf_scenes(lx_test_gltf *g, const char *members);
/* More top-level members, e.g. "\"skins\":[{\"joints\":[2]}]". */
void lx_test_gltf_top(lx_test_gltf *g, const char *members);
/* A material from the full text of its JSON object; returns its index. */
int lx_test_gltf_material(lx_test_gltf *g, const char *json);
/* An image at uri (relative to the .gltf) and a texture of it; returns the
 * texture's index. */
int lx_test_gltf_texture(lx_test_gltf *g, const char *uri);
/* Lists an extension in extensionsUsed. */
void lx_test_gltf_use_extension(lx_test_gltf *g, const char *name);
/* Lists an extension in extensionsRequired (and extensionsUsed). */
void lx_test_gltf_require_extension(lx_test_gltf *g, const char *name);

/* Raw pieces, for layouts the primitive writer does not make (quantized
 * or compressed data). Bytes appended to buffer 0 (4-byte aligned);
 * returns their offset. */
size_t lx_test_gltf_bytes(lx_test_gltf *g, const void *bytes, size_t size);
/* A bufferView over bytes appended to buffer 0, with byteStride when
 * stride > 0; returns its index. */
int lx_test_gltf_view(lx_test_gltf *g, const void *bytes, size_t size, int stride);
/* A bufferView, accessor or mesh from the full text of its JSON object;
 * returns its index. */
int lx_test_gltf_view_json(lx_test_gltf *g, const char *json);
int lx_test_gltf_accessor_json(lx_test_gltf *g, const char *json);
int lx_test_gltf_mesh_json(lx_test_gltf *g, const char *json);
/* A buffer after buffer 0 from the full text of its JSON object; returns
 * its index. */
int lx_test_gltf_buffer_json(lx_test_gltf *g, const char *json);

/* Writes the .gltf (buffer 0 as a base64 data: URI). */
void lx_test_gltf_write(const lx_test_gltf *g, const char *path);
/* Writes a .glb: the same JSON with buffer 0 as the binary chunk. */
void lx_test_gltf_write_glb(const lx_test_gltf *g, const char *path);

struct lx_test_quad;
/* Mesh `name` (returned) of quad q (texture_oracle.h): POSITION, NORMAL,
 * TEXCOORD_0 and _1 from q, TANGENT when tangent (4 floats for each of
 * the 4 corners) is not NULL, material mat. */
int lx_test_gltf_quad_mesh(lx_test_gltf *g, const char *name, const struct lx_test_quad *q,
                           int mat, const float *tangent);

/* A .gltf of quad q (texture_oracle.h) as one node "quad" with mesh
 * "quad": POSITION, NORMAL, TEXCOORD_0 and _1 from q, TANGENT when tangent
 * (4 floats for each of the 4 corners) is not NULL, one material given as
 * JSON text using textures 0..texture_count-1 of the images at uris. */
void lx_test_write_quad_gltf(const char *path, const struct lx_test_quad *q, const char *material,
                             const char *const *uris, int texture_count, const float *tangent);

/* An 8-bit PNG of w x h pixels with channels (1..4) bytes each, row 0 at
 * the top. */
void lx_test_write_png(const char *path, int w, int h, int channels, const uint8_t *pixels);

#endif
