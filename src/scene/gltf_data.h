/* Private to src/scene: the binary side of glTF for the GLB writer -
 * a file's buffers (GLB binary chunk, data: URIs, external files),
 * accessors read into packed arrays, and the output's one binary buffer
 * with the views and accessors added to it. */
#ifndef LX_GLTF_DATA_H
#define LX_GLTF_DATA_H

#include "luxel/core.h"

#include <cjson/cJSON.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* glTF component types (glTF 2.0 spec, 3.6.2.2). */
#define LX_GL_BYTE 5120
#define LX_GL_UNSIGNED_BYTE 5121
#define LX_GL_SHORT 5122
#define LX_GL_UNSIGNED_SHORT 5123
#define LX_GL_UNSIGNED_INT 5125
#define LX_GL_FLOAT 5126
#define LX_GL_ARRAY_BUFFER 34962
#define LX_GL_ELEMENT_ARRAY_BUFFER 34963

/* Bytes of one component (0 for an unknown type). */
size_t lx_gl_component_size(int component_type);
/* Components of "SCALAR", "VEC2"... (0 for an unknown type). */
int lx_gl_type_components(const char *type);

/* A file's bytes: the JSON, the binary chunk of a GLB, and its folder. */
typedef struct lx_gltf_file {
    const char *path;
    cJSON *root;
    uint8_t *bytes; /* the whole file */
    size_t size;
    const uint8_t *bin; /* GLB binary chunk or NULL */
    size_t bin_size;
    char *folder;        /* for relative URIs ... */
    bool allow_any_path; /* ... which lie in it or below unless this is set */
    /* buffers by index, loaded by lx_gltf_file_buffers */
    uint8_t **buffers;
    size_t *buffer_sizes;
    bool *buffer_owned;
    size_t buffer_count;
} lx_gltf_file;

/* Reads path (.gltf or .glb) and parses its JSON. */
lx_status lx_gltf_file_open(const char *path, lx_gltf_file *f);
/* Replaces the file's bytes by glb (malloc'd, taken over whatever
 * happens), a GLB whose JSON is f->root as it is now: its binary chunk
 * becomes f->bin. Before lx_gltf_file_buffers. */
lx_status lx_gltf_file_adopt_glb(lx_gltf_file *f, uint8_t *glb, size_t size);
/* Loads every buffer (each must hold its byteLength bytes). */
lx_status lx_gltf_file_buffers(lx_gltf_file *f);
void lx_gltf_file_close(lx_gltf_file *f);

/* The bytes a URI names: a data: URI decoded, else a file relative to the
 * glTF's folder (percent-escapes decoded). what names the owner in
 * messages ("image 2"). *mime gets a data: URI's media type (malloc'd) or
 * NULL. */
lx_status lx_gltf_uri_read(const lx_gltf_file *f, const char *uri, const char *what,
                           uint8_t **out, size_t *size, char **mime);

/* An accessor's elements, packed (count * elem bytes), sparse values
 * applied. */
typedef struct lx_gltf_array {
    size_t count;
    int component_type;
    int components;
    bool normalized;
    size_t elem; /* bytes of one element */
    uint8_t *data;
    char type[8];
} lx_gltf_array;

lx_status lx_gltf_accessor_read(const lx_gltf_file *f, size_t index, lx_gltf_array *out);
void lx_gltf_array_free(lx_gltf_array *a);
/* Component c of element i as a number (normalized integers mapped to
 * [-1, 1] or [0, 1] when dequantize, raw integers otherwise). */
double lx_gltf_array_get(const lx_gltf_array *a, size_t i, int c, bool dequantize);

/* ---- output ----------------------------------------------------------- */

/* The output's binary chunk, grown as views are added. */
typedef struct lx_glb_bin {
    uint8_t *data;
    size_t size, capacity;
    bool failed; /* out of memory (reported by lx_glb_write) */
} lx_glb_bin;

/* Appends size bytes at an offset aligned to 8, returns the offset. */
size_t lx_glb_bin_append(lx_glb_bin *b, const void *bytes, size_t size);
/* A bufferView of buffer 0 over bytes appended now; stride 0 leaves
 * byteStride out, target 0 leaves target out. Returns its index. */
int lx_glb_add_view(cJSON *root, lx_glb_bin *b, const void *bytes, size_t size, size_t stride,
                    int target);
/* An accessor over a view; min/max (components values each) may be NULL. */
int lx_glb_add_accessor(cJSON *root, int view, int component_type, size_t count, const char *type,
                        bool normalized, const double *min, const double *max);
/* cJSON helpers that note a failed allocation in *bad. */
cJSON *lx_glb_array_of(cJSON *root, const char *key);
/* Writes root and b as a GLB at path, atomically (lx_out_*). */
lx_status lx_glb_write(const char *path, cJSON *root, lx_glb_bin *b);

/* "image/png", "image/jpeg"... from the first bytes, NULL when unknown. */
const char *lx_image_mime_sniff(const uint8_t *bytes, size_t size);

/* RFC 4648 base64 (also its URL alphabet; '=' padding optional) of the n
 * characters at s into *out (malloc) and *size: 1 when decoded, 0 when
 * malformed, -1 when out of memory. */
int lx_gltf_base64_decode(const char *s, size_t n, uint8_t **out, size_t *size);

#endif
