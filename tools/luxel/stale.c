/* Stale outputs: files an earlier bake left in the output folder that this
 * bake does not write (another scene's lightmaps, or nodes that are gone).
 * Only names the earlier run's manifest lists count, so a file luxel did
 * not write is never reported or removed. Also the CLI's JSON reading with
 * errors by line, a trailing comma named as such. */
#define _XOPEN_SOURCE 700
#include "cli.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Line of byte off (1-based). */
static size_t line_of(const char *text, size_t off)
{
    size_t line = 1;
    for (size_t i = 0; i < off; i++)
        line += text[i] == '\n';
    return line;
}

static bool json_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

/* The '}' or ']' right after a comma at q, when there is one: *comma is
 * the comma's offset. */
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

bool cli_json_trailing_comma(const char *text, size_t size, size_t error_at, size_t *line,
                             char *closer)
{
    if (error_at > size)
        return false;
    /* cJSON stops at the closer, or just past it */
    size_t q = error_at, comma;
    while (q < size && json_space(text[q]))
        q++;
    size_t b = error_at;
    while (b > 0 && json_space(text[b - 1]))
        b--;
    size_t at;
    if (q < size && closer_after_comma(text, q, &comma))
        at = q;
    else if (b > 0 && closer_after_comma(text, b - 1, &comma))
        at = b - 1;
    else
        return false;
    *line = line_of(text, comma);
    *closer = text[at];
    return true;
}

cJSON *cli_json_parse(const char *name, const char *text, size_t size, char *err, size_t err_size)
{
    const char *end = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(text, size, &end, 0);
    if (root) {
        /* nothing but white space after the value */
        size_t off = (size_t)(end - text);
        while (off < size && json_space(text[off]))
            off++;
        if (off == size)
            return root;
        cJSON_Delete(root);
        snprintf(err, err_size, "%s: line %zu: text after the JSON value", name,
                 line_of(text, off));
        return NULL;
    }
    size_t off = end && end >= text && end <= text + size ? (size_t)(end - text) : size;
    size_t line;
    char closer;
    if (cli_json_trailing_comma(text, size, off, &line, &closer))
        snprintf(err, err_size, "%s: line %zu: trailing comma before '%c'", name, line, closer);
    else if (off >= size)
        snprintf(err, err_size, "%s: line %zu: malformed JSON: unexpected end", name,
                 line_of(text, size));
    else
        snprintf(err, err_size, "%s: line %zu: malformed JSON", name, line_of(text, off));
    return NULL;
}

/* A name luxel may have written into the folder: a plain file name. */
static bool plain_name(const char *s)
{
    return s && s[0] && !strchr(s, '/') && strcmp(s, ".") != 0 && strcmp(s, "..") != 0 &&
           strcmp(s, "manifest.json") != 0;
}

static bool listed(const char *name, const char *const *names, uint32_t count)
{
    for (uint32_t i = 0; i < count; i++)
        if (strcmp(names[i], name) == 0)
            return true;
    return false;
}

static bool add(cli_stale *s, const char *name)
{
    if (listed(name, (const char *const *)s->names, s->count))
        return true;
    char **n = realloc(s->names, sizeof *n * (s->count + 1));
    if (!n)
        return false;
    s->names = n;
    if (!(s->names[s->count] = cli_strdup(name)))
        return false;
    s->count++;
    return true;
}

/* Whether two scene paths name the same file (the same text, or both
 * resolve to one file). */
static bool same_scene(const char *a, const char *b)
{
    if (strcmp(a, b) == 0)
        return true;
    char ra[PATH_MAX], rb[PATH_MAX];
    return realpath(a, ra) && realpath(b, rb) && strcmp(ra, rb) == 0;
}

char *cli_read_text(const char *path, size_t *size)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return NULL;
    char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n + 4096 > cap) {
            cap = cap ? cap * 2 : 8192;
            if (cap > ((size_t)64 << 20)) /* manifests and points files are small */
                break;
            char *b = realloc(buf, cap);
            if (!b)
                break;
            buf = b;
        }
        size_t got = fread(buf + n, 1, cap - n, fp);
        n += got;
        if (got == 0)
            break;
    }
    bool ok = !ferror(fp) && feof(fp);
    fclose(fp);
    if (!ok) {
        free(buf);
        return NULL;
    }
    *size = n;
    return buf;
}

bool cli_stale_find(const char *dir, const char *scene, const char *const *outputs,
                    uint32_t output_count, cli_stale *out)
{
    memset(out, 0, sizeof *out);
    char *path = cli_path_join(dir, "manifest.json");
    if (!path) {
        cli_error("out of memory");
        return false;
    }
    struct stat sb;
    if (stat(path, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        free(path);
        return true; /* no earlier bake here */
    }
    size_t size = 0;
    char *text = cli_read_text(path, &size);
    if (!text) {
        lx_log(LX_LOG_WARN,
               "%s: cannot read the earlier bake's manifest (%s): stale files "
               "not checked",
               path, strerror(errno));
        free(path);
        return true;
    }
    char err[512];
    cJSON *root = cli_json_parse(path, text, size, err, sizeof err);
    free(text);
    if (!root) {
        lx_log(LX_LOG_WARN, "%s: stale files not checked", err);
        free(path);
        return true;
    }
    free(path);
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(root, "scene");
    if (cJSON_IsString(sc) && !same_scene(sc->valuestring, scene))
        out->other_scene = cli_strdup(sc->valuestring);
    bool ok = true;
    const char *lists[2] = {"pages", "lightmaps"}; /* lightmaps: before atlas pages */
    for (int l = 0; l < 2; l++) {
        const cJSON *arr = cJSON_GetObjectItemCaseSensitive(root, lists[l]);
        const cJSON *e;
        cJSON_ArrayForEach(e, arr)
        {
            /* a page's files: the map, its preview, AO and directional maps */
            const char *keys[4] = {"file", "preview", "ao", "dir"};
            for (int k = 0; k < 4; k++) {
                const cJSON *f = cJSON_GetObjectItemCaseSensitive(e, keys[k]);
                if (cJSON_IsString(f) && plain_name(f->valuestring) &&
                    !listed(f->valuestring, outputs, output_count))
                    ok = ok && add(out, f->valuestring);
            }
            const cJSON *f;
            cJSON_ArrayForEach(f, cJSON_GetObjectItemCaseSensitive(e, "sh"))
            {
                if (cJSON_IsString(f) && plain_name(f->valuestring) &&
                    !listed(f->valuestring, outputs, output_count))
                    ok = ok && add(out, f->valuestring);
            }
        }
    }
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(root, "earlier_files"))
    {
        if (cJSON_IsString(e) && plain_name(e->valuestring) &&
            !listed(e->valuestring, outputs, output_count))
            ok = ok && add(out, e->valuestring);
    }
    /* the scene with UVs, and the render of --render */
    const char *top[2] = {"scene_with_uvs", "render"};
    for (int k = 0; k < 2; k++) {
        const cJSON *f = cJSON_GetObjectItemCaseSensitive(root, top[k]);
        if (cJSON_IsString(f) && plain_name(f->valuestring) &&
            !listed(f->valuestring, outputs, output_count))
            ok = ok && add(out, f->valuestring);
    }
    cJSON_Delete(root);
    if (!ok) {
        cli_error("out of memory");
        cli_stale_free(out);
        return false;
    }
    /* only what is still there */
    uint32_t kept = 0;
    for (uint32_t i = 0; i < out->count; i++) {
        char *p = cli_path_join(dir, out->names[i]);
        bool there = p && lstat(p, &sb) == 0 && S_ISREG(sb.st_mode);
        free(p);
        if (there)
            out->names[kept++] = out->names[i];
        else
            free(out->names[i]);
    }
    out->count = kept;
    return true;
}

void cli_stale_warn(const cli_stale *s, const char *dir, bool clean)
{
    if (!s->count)
        return;
    char list[400] = "";
    size_t len = 0;
    uint32_t shown = 0;
    for (uint32_t i = 0; i < s->count; i++) {
        size_t need = strlen(s->names[i]) + 2;
        if (len + need + 16 >= sizeof list)
            break;
        len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "", s->names[i]);
        shown++;
    }
    if (shown < s->count)
        snprintf(list + len, sizeof list - len, ", and %u more", s->count - shown);
    char from[300] = "";
    if (s->other_scene)
        snprintf(from, sizeof from, " of an earlier bake of %s", s->other_scene);
    else
        snprintf(from, sizeof from, " of an earlier bake");
    if (clean)
        lx_log(LX_LOG_INFO, "%s: removing %u %s%s that this bake does not write (%s)", dir,
               s->count, cli_plural(s->count, "file", "files"), from, list);
    else
        lx_log(LX_LOG_WARN,
               "%s holds %u %s%s that this bake does not write (%s); --clean "
               "removes them",
               dir, s->count, cli_plural(s->count, "file", "files"), from, list);
}

bool cli_stale_remove(const cli_stale *s, const char *dir)
{
    bool ok = true;
    for (uint32_t i = 0; i < s->count; i++) {
        char *p = cli_path_join(dir, s->names[i]);
        struct stat sb;
        /* a file, as when found; a folder or link put there since is left */
        if (p && lstat(p, &sb) == 0 && S_ISREG(sb.st_mode) && unlink(p) != 0) {
            cli_error("%s: cannot remove: %s", p, strerror(errno));
            ok = false;
        }
        free(p);
    }
    return ok;
}

void cli_stale_free(cli_stale *s)
{
    for (uint32_t i = 0; i < s->count; i++)
        free(s->names[i]);
    free(s->names);
    free(s->other_scene);
    memset(s, 0, sizeof *s);
}
