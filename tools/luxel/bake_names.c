/* The names of luxel bake's files (bake_names.h), planned before the bake
 * so that no two outputs share a name and no node's file takes one of
 * luxel's own; and the earlier bake's files this one does not replace. */
#define _POSIX_C_SOURCE 200809L
#include "bake_names.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* A file stem from a node name: path separators and control characters
 * become '_', and no leading dot (hidden files, and luxel's own staging
 * folders, start with one). */
static void sanitized_stem(const char *name, char *out, size_t size)
{
    size_t n = 0;
    for (const char *s = name; *s && n + 1 < size; s++) {
        unsigned char ch = (unsigned char)*s;
        out[n++] = (ch < 32 || ch == '/' || ch == '\\' || ch == ':' || ch == '*' || ch == '?' ||
                    ch == '"' || ch == '<' || ch == '>' || ch == '|')
                       ? '_'
                       : (char)ch;
    }
    out[n] = '\0';
    if (n == 0 || out[0] == '.')
        out[0] = '_';
    if (n == 0)
        out[1] = '\0';
}

int bake_directional_names(const bake_args *a, const char *stem, char out[DIR_FILES][300])
{
    if (a->desc.directional == LX_DIRECTIONAL_DOMINANT) {
        snprintf(out[0], 300, "%s_dir.png", stem);
        return 1;
    }
    if (a->desc.directional != LX_DIRECTIONAL_SH)
        return 0;
    for (int c = 0; c < 4; c++)
        snprintf(out[c], 300, "%s_sh%d.%s", stem, c, lx_image_format_extension(a->format));
    return 4;
}

/* The files a lightmap with this stem is written as; returns how many. */
static int stem_files(const bake_args *a, const char *stem, char out[STEM_FILES][300])
{
    int n = 0;
    snprintf(out[n++], 300, "%s.%s", stem, lx_image_format_extension(a->format));
    if (a->format != LX_IMAGE_PNG)
        snprintf(out[n++], 300, "%s.png", stem);
    if (a->ao)
        snprintf(out[n++], 300, "%s_ao.png", stem);
    char dn[DIR_FILES][300];
    int k = bake_directional_names(a, stem, dn);
    for (int j = 0; j < k; j++)
        memcpy(out[n++], dn[j], 300);
    return n;
}

static uint32_t name_hash(const char *s)
{
    uint32_t h = 2166136261u; /* FNV-1a over the lower-cased bytes */
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        h = (h ^ (uint32_t)(c >= 'A' && c <= 'Z' ? c + 32 : c)) * 16777619u;
    }
    return h;
}

static bool name_taken(const output_names *on, const char *name)
{
    for (uint32_t i = name_hash(name) & (on->slot_count - 1); on->slots[i];
         i = (i + 1) & (on->slot_count - 1))
        if (strcasecmp(on->names[on->slots[i] - 1], name) == 0)
            return true;
    return false;
}

/* Adds a name not taken yet; false when out of memory. The set is made
 * for `capacity` names (output_names_init) and holds at most that many. */
static bool name_add(output_names *on, const char *name)
{
    char *copy = cli_strdup(name);
    if (!copy)
        return false;
    uint32_t i = name_hash(name) & (on->slot_count - 1);
    while (on->slots[i])
        i = (i + 1) & (on->slot_count - 1);
    on->names[on->count] = copy;
    on->slots[i] = ++on->count;
    return true;
}

static bool output_names_init(output_names *on, uint32_t capacity)
{
    memset(on, 0, sizeof *on);
    on->slot_count = 16;
    while (on->slot_count < 2 * (uint64_t)capacity && on->slot_count < (1u << 31))
        on->slot_count *= 2;
    if (on->slot_count < 2 * (uint64_t)capacity)
        return false;
    on->names = calloc(capacity ? capacity : 1, sizeof *on->names);
    on->slots = calloc(on->slot_count, sizeof *on->slots);
    return on->names && on->slots;
}

void bake_output_names_free(output_names *on)
{
    for (uint32_t i = 0; on->names && i < on->count; i++)
        free(on->names[i]);
    free(on->names);
    free(on->slots);
    memset(on, 0, sizeof *on);
}

/* The names luxel gives its own outputs, which no lightmap may take
 * (view.png whether or not --render is given, so that a node's files do
 * not change names with it). */
static const char *const own_outputs[] = {"manifest.json", "view.png"};

bool bake_plan_outputs(const bake_args *a, const lx_scene *scene, const lx_baker *baker, bool atlas,
                       const char *uvs_name, uint32_t maps, char **stems, output_names *on)
{
    uint64_t capacity = (uint64_t)maps * STEM_FILES + 3;
    if (capacity > UINT32_MAX / 4 || !output_names_init(on, (uint32_t)capacity)) {
        cli_error("out of memory");
        return false;
    }
    bool ok = true;
    for (size_t i = 0; i < sizeof own_outputs / sizeof *own_outputs && ok; i++)
        ok = name_add(on, own_outputs[i]);
    if (ok && uvs_name[0])
        ok = name_add(on, uvs_name);
    char renamed[400] = "";
    uint32_t renamed_count = 0, unlisted = 0;
    for (uint32_t m = 0; m < maps && ok; m++) {
        const lx_lightmap_info *info = lx_baker_lightmap_info(baker, m);
        bool of_node = !atlas && info->node != UINT32_MAX;
        const char *base = of_node ? scene->nodes[info->node].name : info->name;
        char clean[200], stem[256], files[STEM_FILES][300];
        sanitized_stem(base, clean, sizeof clean);
        snprintf(stem, sizeof stem, "%s", clean);
        for (uint32_t k = 2;; k++) {
            int n = stem_files(a, stem, files);
            bool clash = false;
            for (int j = 0; j < n && !clash; j++)
                clash = name_taken(on, files[j]);
            if (!clash) {
                for (int j = 0; j < n && ok; j++)
                    ok = name_add(on, files[j]);
                break;
            }
            snprintf(stem, sizeof stem, "%s_%u", clean, k);
        }
        ok = ok && (stems[m] = cli_strdup(stem)) != NULL;
        if (ok && strcmp(stem, clean) != 0) {
            renamed_count++;
            size_t len = strlen(renamed);
            if (unlisted == 0 && len + strlen(base) + strlen(stem) + 40 < sizeof renamed)
                snprintf(renamed + len, sizeof renamed - len, "%s'%s' as %s.*", len ? ", " : "",
                         base, stem);
            else
                unlisted++;
        }
    }
    if (!ok) {
        cli_error("out of memory");
        return false;
    }
    if (renamed_count) {
        size_t len = strlen(renamed);
        if (unlisted)
            snprintf(renamed + len, sizeof renamed - len, " and %u more", unlisted);
        lx_log(LX_LOG_WARN,
               "%s: %u %s would share file names with other outputs or with luxel's own "
               "(manifest.json, view.png, the %s of each lightmap): %s; manifest.json names "
               "each node's files",
               a->scene, renamed_count, cli_plural(renamed_count, "lightmap", "lightmaps"),
               "_ao, _sh0.._sh3 and _dir maps", renamed);
    }
    return true;
}

bool bake_find_stale(const bake_args *a, const output_names *on, cli_stale *out)
{
    const char **written = calloc(on->count ? on->count : 1, sizeof *written);
    if (!written) {
        cli_error("out of memory");
        return false;
    }
    uint32_t n = 0;
    for (uint32_t i = 0; i < on->count; i++)
        if (a->render || strcmp(on->names[i], "view.png") != 0)
            written[n++] = on->names[i];
    bool ok = cli_stale_find(a->output, a->scene, written, n, out);
    free(written);
    return ok;
}
