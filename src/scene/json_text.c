/* JSON text to a cJSON tree for the scene module's readers (lights JSON,
 * glTF), reporting syntax errors by line and column. */
#include "json_text.h"
#include "core/internal.h"

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool json_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

/* Whether text[q] is a '}' or ']' right after a comma (white space
 * between); *comma gets the comma's offset. */
static bool closer_after_comma(const char *text, size_t q, size_t *comma)
{
    if (text[q] != '}' && text[q] != ']')
        return false;
    size_t p = q;
    while (p > 0 && json_space(text[p - 1]))
        p--;
    if (p == 0 || text[p - 1] != ',')
        return false;
    *comma = p - 1;
    return true;
}

/* Reports a cJSON syntax error at pos with its line and column. */
static lx_status syntax_error(const char *file, const char *text, size_t size, const char *pos)
{
    size_t off = pos && pos >= text && pos <= text + size ? (size_t)(pos - text) : 0;
    size_t line = 1, col = 1;
    for (size_t i = 0; i < off; i++) {
        if (text[i] == '\n') {
            line++;
            col = 1;
        } else {
            col++;
        }
    }
    /* a trailing comma: cJSON stops at the '}' or ']' after it, or just
     * past it; named at the comma's line */
    size_t q = off, b = off, comma = 0;
    while (q < size && json_space(text[q]))
        q++;
    while (b > 0 && json_space(text[b - 1]))
        b--;
    size_t at = SIZE_MAX;
    if (q < size && closer_after_comma(text, q, &comma))
        at = q;
    else if (b > 0 && closer_after_comma(text, b - 1, &comma))
        at = b - 1;
    if (at != SIZE_MAX) {
        size_t comma_line = 1;
        for (size_t i = 0; i < comma; i++)
            comma_line += text[i] == '\n';
        return lx_fail(LX_ERR_FORMAT, "%s: line %zu: trailing comma before '%c'", file, comma_line,
                       text[at]);
    }
    if (off >= size)
        return lx_fail(LX_ERR_FORMAT, "%s: line %zu, column %zu: malformed JSON: unexpected end",
                       file, line, col);
    char near[24];
    size_t n = 0;
    for (size_t i = off; i < size && n < 16 && text[i] != '\n'; i++)
        near[n++] = (text[i] >= 0x20 && text[i] < 0x7f) ? text[i] : '?';
    near[n] = '\0';
    return lx_fail(LX_ERR_FORMAT, "%s: line %zu, column %zu: malformed JSON near '%s'", file, line,
                   col, near);
}

lx_status lx_json_parse_text(const char *file, const char *text, size_t size, cJSON **root)
{
    *root = NULL;
    const char *nul = memchr(text, '\0', size);
    if (nul)
        return lx_fail(LX_ERR_FORMAT, "%s: byte %zu is a NUL byte, not JSON text", file,
                       (size_t)(nul - text));
    /* A copy with a terminator: cJSON then also rejects trailing garbage. */
    char *buf = malloc(size + 1);
    if (!buf)
        return lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", file, size + 1);
    memcpy(buf, text, size);
    buf[size] = '\0';
    size_t skip = size >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0; /* UTF-8 BOM */
    const char *end = NULL;
    *root = cJSON_ParseWithLengthOpts(buf + skip, size - skip + 1, &end, 1);
    lx_status st = LX_OK;
    if (!*root)
        st = syntax_error(file, buf, size, end);
    free(buf);
    return st;
}

lx_status lx_json_fail(lx_status status, const char *file, const char *where, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (where && where[0])
        return lx_fail(status, "%s: %s: %s", file, where, msg);
    return lx_fail(status, "%s: %s", file, msg);
}
