/* Private to src/scene: typed fields of a JSON object (numbers, vectors,
 * colours, strings, enums, the allowed keys) read with cJSON, each error
 * naming the file, the place in it and the field: "lights.json:
 * lights[2] ('key'): intensity must be a number". Shared by the lights
 * JSON's parts (lights_json.c, lights_json_materials.c). */
#ifndef LX_JSON_FIELDS_H
#define LX_JSON_FIELDS_H

#include "luxel/scene.h"
#include "core/internal.h"

#include "json_text.h"

#include <cjson/cJSON.h>

/* Where a reader is: the file and the place in it, for messages. */
typedef struct lx_jf_ctx {
    const char *file;          /* name used in messages */
    char where[128];           /* "lights[2] ('key')" or "" at the root */
    lx_ies_profile **profiles; /* loaded by this file: the scene adopts them */
    uint32_t profile_count;
    bool allow_any_path; /* files named may lie outside the file's folder */
} lx_jf_ctx;

/* lx_fail with "<file>: <where>: " in front. */
#define lx_jf_fail(c, st, ...) lx_json_fail(st, (c)->file, (c)->where, __VA_ARGS__)

#define LX_JF_COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

/* A finite number (as float). */
lx_status lx_jf_float(const lx_jf_ctx *c, const cJSON *item, const char *field, float *out);
/* A finite number >= 0. */
lx_status lx_jf_non_negative(const lx_jf_ctx *c, const cJSON *item, const char *field, float *out);
/* An array of 3 finite numbers. */
lx_status lx_jf_vec3(const lx_jf_ctx *c, const cJSON *item, const char *field, lx_vec3 *out);
/* A direction-like vector of any non-zero length, normalized; *raw (may be
 * NULL) keeps the values as given (for messages). */
lx_status lx_jf_unit_vec3(const lx_jf_ctx *c, const cJSON *item, const char *field, lx_vec3 *out,
                          lx_vec3 *raw);
/* An array of 3 finite numbers none of which is negative. */
lx_status lx_jf_color(const lx_jf_ctx *c, const cJSON *item, const char *field, lx_vec3 *out);
/* A string (borrowed from item). */
lx_status lx_jf_string(const lx_jf_ctx *c, const cJSON *item, const char *field, const char **out);
/* A string among names, as its index; fails listing the accepted ones. */
lx_status lx_jf_enum(const lx_jf_ctx *c, const cJSON *item, const char *field,
                     const char *const *names, int count, int *out);
/* Every key of obj is in allowed, once. */
lx_status lx_jf_check_keys(const lx_jf_ctx *c, const cJSON *obj, const char *const *allowed,
                           int count);
/* A path the file gives in field, relative to the file's folder, into
 * *out (malloc'd); it must lie in that folder or below unless
 * c->allow_any_path (lx_path_confine). */
lx_status lx_jf_relative_path(const lx_jf_ctx *c, const char *field, const char *rel, char **out);

#endif
