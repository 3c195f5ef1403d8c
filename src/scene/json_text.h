/* Private to src/scene: JSON text to a cJSON tree, with errors that name
 * the file, line and column. */
#ifndef LX_JSON_TEXT_H
#define LX_JSON_TEXT_H

#include "luxel/core.h"

#include <cjson/cJSON.h>

/* Parses size bytes (not necessarily NUL-terminated; a UTF-8 byte-order
 * mark is skipped) into *root, which the caller frees with cJSON_Delete.
 * NUL bytes, trailing garbage and syntax errors fail with LX_ERR_FORMAT:
 * "<file>: line L, column C: malformed JSON near '...'". */
lx_status lx_json_parse_text(const char *file, const char *text, size_t size, cJSON **root);

#endif
