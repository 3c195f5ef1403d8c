/* Private to src/scene: JSON text to a cJSON tree, with errors that name
 * the file, line and column. */
#ifndef LX_JSON_TEXT_H
#define LX_JSON_TEXT_H

#include "luxel/core.h"
#include "core/internal.h"

#include <cjson/cJSON.h>

/* Parses size bytes (not necessarily NUL-terminated; a UTF-8 byte-order
 * mark is skipped) into *root, which the caller frees with cJSON_Delete.
 * NUL bytes, trailing garbage and syntax errors fail with LX_ERR_FORMAT:
 * "<file>: line L, column C: malformed JSON near '...'". */
lx_status lx_json_parse_text(const char *file, const char *text, size_t size, cJSON **root);

/* lx_fail with "<file>: " and, when where is not empty, "<where>: " in
 * front of the formatted message. */
lx_status lx_json_fail(lx_status status, const char *file, const char *where, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

/* Checks a .glb file's container before anything parses it: the 12-byte
 * header (magic, version 2, a length that fits the file) and every chunk's
 * length, so no reader allocates what a forged header claims. */
lx_status lx_glb_check_file(const char *path);

#endif
