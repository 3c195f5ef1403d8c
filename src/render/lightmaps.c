/* The bake's manifest (docs/manifest.md) read back: pages, nodes with
 * their page, UV set and Unity-style scale/offset, units; every field
 * checked. Binding the manifest's nodes to a scene's by name. */
#include "render_internal.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MANIFEST_MAX ((size_t)64 << 20)

lx_lightmaps_load_desc lx_lightmaps_load_desc_defaults(const lx_lightmaps_load_desc *desc)
{
    lx_lightmaps_load_desc d = desc ? *desc : (lx_lightmaps_load_desc){0};
    return d;
}

void lx_lightmaps_free(lx_lightmaps *lm)
{
    if (!lm)
        return;
    for (uint32_t i = 0; i < lm->page_count; i++) {
        free(lm->pages[i].file);
        lx_image_free(&lm->pages[i].image);
        for (int c = 0; c < 4; c++) {
            free(lm->pages[i].sh_files[c]);
            lx_image_free(&lm->pages[i].sh[c]);
        }
        free(lm->pages[i].dir_file);
        lx_image_free(&lm->pages[i].dir);
    }
    for (uint32_t i = 0; i < lm->node_count; i++)
        free(lm->nodes[i].name);
    for (uint32_t i = 0; i < lm->unbaked_count; i++)
        free(lm->unbaked[i]);
    free(lm->unbaked);
    free(lm->pages);
    free(lm->nodes);
    free(lm->dir);
    free(lm->scene);
    free(lm->scene_with_uvs);
    free(lm->sky);
    memset(lm, 0, sizeof *lm);
}

/* An optional finite number; false (message set) when present but not one. */
static bool opt_number(const char *file, const cJSON *obj, const char *key, double lo, double hi,
                       double *out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it)
        return true;
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble) || it->valuedouble < lo ||
        it->valuedouble > hi) {
        lx_fail(LX_ERR_FORMAT, "%s: \"%s\" must be a number in [%g, %g]", file, key, lo, hi);
        return false;
    }
    *out = it->valuedouble;
    return true;
}

static bool is_int(const cJSON *it, double lo, double hi)
{
    return cJSON_IsNumber(it) && isfinite(it->valuedouble) && it->valuedouble >= lo &&
           it->valuedouble <= hi && floor(it->valuedouble) == it->valuedouble;
}

/* A file the manifest names, joined to its folder into *out; it must lie
 * in that folder or below unless any_path (lx_path_confine). */
static lx_status manifest_file(const char *file, const char *dir, const char *what,
                               const char *name, bool any_path, char **out)
{
    if (!(*out = lx_path_join(dir, name)))
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", file);
    return lx_path_confine(file, what, name, dir, *out, any_path);
}

static lx_status parse_pages(const char *file, const char *dir, bool any_path, const cJSON *root,
                             lx_lightmaps *lm)
{
    char what[64];
    lx_status st;
    const cJSON *pages = cJSON_GetObjectItemCaseSensitive(root, "pages");
    if (!cJSON_IsArray(pages) || cJSON_GetArraySize(pages) == 0)
        return lx_fail(LX_ERR_FORMAT, "%s: \"pages\" must be a non-empty array", file);
    int n = cJSON_GetArraySize(pages);
    lm->pages = calloc((size_t)n, sizeof *lm->pages);
    if (!lm->pages)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", file);
    lm->page_count = (uint32_t)n;
    int i = 0;
    const cJSON *p;
    cJSON_ArrayForEach(p, pages)
    {
        const cJSON *f = cJSON_GetObjectItemCaseSensitive(p, "file");
        const cJSON *w = cJSON_GetObjectItemCaseSensitive(p, "width");
        const cJSON *h = cJSON_GetObjectItemCaseSensitive(p, "height");
        if (!cJSON_IsString(f) || !f->valuestring[0])
            return lx_fail(LX_ERR_FORMAT, "%s: pages[%d]: \"file\" must be a file name", file, i);
        if (!is_int(w, 1, LX_MAX_LIGHTMAP_SIZE) || !is_int(h, 1, LX_MAX_LIGHTMAP_SIZE))
            return lx_fail(LX_ERR_FORMAT,
                           "%s: pages[%d]: \"width\" and \"height\" must be integers in 1..%d",
                           file, i, LX_MAX_LIGHTMAP_SIZE);
        snprintf(what, sizeof what, "pages[%d]: file", i);
        if ((st = manifest_file(file, dir, what, f->valuestring, any_path, &lm->pages[i].file)) !=
            LX_OK)
            return st;
        lm->pages[i].width = (int)w->valuedouble;
        lm->pages[i].height = (int)h->valuedouble;
        const cJSON *sh = cJSON_GetObjectItemCaseSensitive(p, "sh");
        const cJSON *dir_file = cJSON_GetObjectItemCaseSensitive(p, "dir");
        if (lm->directional == LX_DIRECTIONAL_SH) {
            if (!cJSON_IsArray(sh) || cJSON_GetArraySize(sh) != 4)
                return lx_fail(LX_ERR_FORMAT, "%s: pages[%d]: \"sh\" must be 4 file names", file,
                               i);
            for (int c = 0; c < 4; c++) {
                const cJSON *it = cJSON_GetArrayItem(sh, c);
                if (!cJSON_IsString(it) || !it->valuestring[0])
                    return lx_fail(LX_ERR_FORMAT, "%s: pages[%d]: \"sh\" must be 4 file names",
                                   file, i);
                snprintf(what, sizeof what, "pages[%d]: sh[%d]", i, c);
                if ((st = manifest_file(file, dir, what, it->valuestring, any_path,
                                        &lm->pages[i].sh_files[c])) != LX_OK)
                    return st;
            }
        } else if (lm->directional == LX_DIRECTIONAL_DOMINANT) {
            if (!cJSON_IsString(dir_file) || !dir_file->valuestring[0])
                return lx_fail(LX_ERR_FORMAT, "%s: pages[%d]: \"dir\" must be a file name", file,
                               i);
            snprintf(what, sizeof what, "pages[%d]: dir", i);
            if ((st = manifest_file(file, dir, what, dir_file->valuestring, any_path,
                                    &lm->pages[i].dir_file)) != LX_OK)
                return st;
        }
        i++;
    }
    return LX_OK;
}

/* "nodes_without_lightmap": optional, an array of node names. */
static lx_status parse_unbaked(const char *file, const cJSON *root, lx_lightmaps *lm)
{
    const cJSON *list = cJSON_GetObjectItemCaseSensitive(root, "nodes_without_lightmap");
    if (!list)
        return LX_OK;
    if (!cJSON_IsArray(list))
        return lx_fail(LX_ERR_FORMAT, "%s: \"nodes_without_lightmap\" must be an array of names",
                       file);
    int n = cJSON_GetArraySize(list);
    lm->unbaked = calloc((size_t)n + 1, sizeof *lm->unbaked);
    if (!lm->unbaked)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", file);
    const cJSON *e;
    cJSON_ArrayForEach(e, list)
    {
        if (!cJSON_IsString(e))
            return lx_fail(LX_ERR_FORMAT, "%s: nodes_without_lightmap[%u] must be a node's name",
                           file, lm->unbaked_count);
        if (!(lm->unbaked[lm->unbaked_count] = lx_strdup(e->valuestring)))
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", file);
        lm->unbaked_count++;
    }
    return LX_OK;
}

static bool is_unbaked(const lx_lightmaps *lm, const char *name)
{
    for (uint32_t i = 0; i < lm->unbaked_count; i++)
        if (strcmp(lm->unbaked[i], name) == 0)
            return true;
    return false;
}

void lx_lightmaps_apply_settings(const lx_lightmaps *lm, lx_scene *scene)
{
    if (!lm || !scene)
        return;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        lx_node *node = &scene->nodes[n];
        if (!node->name)
            continue;
        if (is_unbaked(lm, node->name))
            node->bake.no_lightmap = true;
        for (uint32_t i = 0; i < lm->node_count; i++)
            if (strcmp(lm->nodes[i].name, node->name) == 0)
                node->bake.lightmap_scale = lm->nodes[i].lightmap_scale;
    }
}

static lx_status parse_nodes(const char *file, const cJSON *root, lx_lightmaps *lm)
{
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    if (!cJSON_IsArray(nodes))
        return lx_fail(LX_ERR_FORMAT, "%s: \"nodes\" must be an array", file);
    int n = cJSON_GetArraySize(nodes);
    if (n == 0)
        return lx_fail(LX_ERR_FORMAT, "%s: \"nodes\" is empty: no node has a lightmap", file);
    lm->nodes = calloc((size_t)n, sizeof *lm->nodes);
    if (!lm->nodes)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", file);
    int i = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, nodes)
    {
        lx_lightmap_node *ln = &lm->nodes[i];
        const cJSON *name = cJSON_GetObjectItemCaseSensitive(e, "node");
        const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(e, "meshes");
        const cJSON *page = cJSON_GetObjectItemCaseSensitive(e, "page");
        const cJSON *so = cJSON_GetObjectItemCaseSensitive(e, "scale_offset");
        const cJSON *set = cJSON_GetObjectItemCaseSensitive(e, "uv_set");
        const cJSON *uvs = cJSON_GetObjectItemCaseSensitive(e, "uvs");
        const cJSON *scale = cJSON_GetObjectItemCaseSensitive(e, "lightmap_scale");
        if (!cJSON_IsString(name))
            return lx_fail(LX_ERR_FORMAT, "%s: nodes[%d]: \"node\" must be the node's name", file,
                           i);
        for (int k = 0; k < i; k++)
            if (strcmp(lm->nodes[k].name, name->valuestring) == 0)
                return lx_fail(LX_ERR_FORMAT, "%s: nodes[%d]: node '%s' is listed twice", file, i,
                               name->valuestring);
        if (!(ln->name = lx_strdup(name->valuestring)))
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", file);
        lm->node_count = (uint32_t)i + 1;
        if (!cJSON_IsArray(meshes))
            return lx_fail(LX_ERR_FORMAT, "%s: nodes[%d] ('%s'): \"meshes\" must be an array", file,
                           i, ln->name);
        ln->mesh_count = (uint32_t)cJSON_GetArraySize(meshes);
        if (!is_int(page, 0, (double)lm->page_count - 1))
            return lx_fail(LX_ERR_FORMAT, "%s: nodes[%d] ('%s'): \"page\" must index pages (%u)",
                           file, i, ln->name, lm->page_count);
        ln->page = (uint32_t)page->valuedouble;
        ln->lightmap_scale = 1.0f;
        if (scale) {
            double v = cJSON_IsNumber(scale) ? scale->valuedouble : NAN;
            if (!(v > 0.0) || !isfinite((float)v))
                return lx_fail(LX_ERR_FORMAT,
                               "%s: nodes[%d] ('%s'): \"lightmap_scale\" must be a number above 0",
                               file, i, ln->name);
            ln->lightmap_scale = (float)v;
        }
        if (!cJSON_IsArray(so) || cJSON_GetArraySize(so) != 4)
            return lx_fail(LX_ERR_FORMAT,
                           "%s: nodes[%d] ('%s'): \"scale_offset\" must be 4 numbers", file, i,
                           ln->name);
        for (int k = 0; k < 4; k++) {
            const cJSON *v = cJSON_GetArrayItem(so, k);
            if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble) || !isfinite((float)v->valuedouble))
                return lx_fail(LX_ERR_FORMAT,
                               "%s: nodes[%d] ('%s'): \"scale_offset\" must be 4 finite numbers",
                               file, i, ln->name);
            ln->scale_offset[k] = (float)v->valuedouble;
        }
        int set_index = -1;
        char tail;
        if (!cJSON_IsString(set) ||
            sscanf(set->valuestring, "TEXCOORD_%d%c", &set_index, &tail) != 1 ||
            set_index < 0 || set_index >= LX_MAX_UV_SETS ||
            strncmp(set->valuestring, "TEXCOORD_", 9) != 0 ||
            !(set->valuestring[9] >= '0' && set->valuestring[9] <= '9'))
            return lx_fail(LX_ERR_FORMAT,
                           "%s: nodes[%d] ('%s'): \"uv_set\" must be TEXCOORD_0 to TEXCOORD_%d",
                           file, i, ln->name, LX_MAX_UV_SETS - 1);
        ln->uv_set = set_index;
        if (uvs && !(cJSON_IsString(uvs) && (strcmp(uvs->valuestring, "own") == 0 ||
                                             strcmp(uvs->valuestring, "generated") == 0)))
            return lx_fail(LX_ERR_FORMAT, "%s: nodes[%d] ('%s'): \"uvs\" must be own or generated",
                           file, i, ln->name);
        ln->generated = uvs && strcmp(uvs->valuestring, "generated") == 0;
        i++;
    }
    return LX_OK;
}

static lx_status parse_manifest(const char *file, const char *dir, bool any_path, const cJSON *root,
                                lx_lightmaps *lm)
{
    if (!cJSON_IsObject(root))
        return lx_fail(LX_ERR_FORMAT, "%s: not a JSON object", file);
    const cJSON *scene = cJSON_GetObjectItemCaseSensitive(root, "scene");
    if (cJSON_IsString(scene) && !(lm->scene = lx_strdup(scene->valuestring)))
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", file);
    const cJSON *swu = cJSON_GetObjectItemCaseSensitive(root, "scene_with_uvs");
    if (swu && !cJSON_IsNull(swu)) {
        if (!cJSON_IsString(swu) || !swu->valuestring[0])
            return lx_fail(LX_ERR_FORMAT, "%s: \"scene_with_uvs\" must be a file name", file);
        lx_status st = manifest_file(file, dir, "scene_with_uvs", swu->valuestring, any_path,
                                     &lm->scene_with_uvs);
        if (st != LX_OK)
            return st;
    }
    const cJSON *q = cJSON_GetObjectItemCaseSensitive(root, "quantity");
    if (!q || (cJSON_IsString(q) && strcmp(q->valuestring, "irradiance") == 0))
        lm->quantity = LX_QUANTITY_IRRADIANCE;
    else if (cJSON_IsString(q) && strcmp(q->valuestring, "radiance") == 0)
        lm->quantity = LX_QUANTITY_RADIANCE;
    else
        return lx_fail(LX_ERR_FORMAT, "%s: \"quantity\" must be irradiance or radiance", file);
    double v = 1.0;
    if (!opt_number(file, root, "pre_exposure", 1e-30, 1e30, &v))
        return LX_ERR_FORMAT;
    lm->pre_exposure = (float)v;
    v = 0.0;
    if (!opt_number(file, root, "preview_ev100", -64, 64, &v))
        return LX_ERR_FORMAT;
    lm->preview_ev100 = (float)v;
    v = 0.0;
    if (!opt_number(file, root, "texel_density", 0, 1e9, &v))
        return LX_ERR_FORMAT;
    lm->texel_density = (float)v;
    v = -1.0;
    if (!opt_number(file, root, "padding", 0, LX_UNWRAP_MAX_PADDING, &v))
        return LX_ERR_FORMAT;
    lm->padding = (int)v;
    v = 0.0;
    if (!opt_number(file, root, "atlas_size", 0, LX_UNWRAP_MAX_ATLAS_SIZE, &v))
        return LX_ERR_FORMAT;
    lm->atlas_size = (int)v;
    lm->sky_intensity = 1.0f;
    const cJSON *sky = cJSON_GetObjectItemCaseSensitive(root, "sky");
    if (cJSON_IsObject(sky)) {
        const cJSON *env = cJSON_GetObjectItemCaseSensitive(sky, "environment");
        if (cJSON_IsString(env) && env->valuestring[0] && !(lm->sky = lx_strdup(env->valuestring)))
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", file);
        v = 1.0;
        if (!opt_number(file, sky, "intensity", 0, 1e30, &v))
            return LX_ERR_FORMAT;
        lm->sky_intensity = (float)v;
    }
    lm->emissive_scale = 1.0f;
    const cJSON *indirect = cJSON_GetObjectItemCaseSensitive(root, "indirect");
    if (cJSON_IsObject(indirect)) {
        v = 1.0;
        if (!opt_number(file, indirect, "emissive_scale", 1e-30, 1e30, &v))
            return LX_ERR_FORMAT;
        lm->emissive_scale = (float)v;
    }
    const cJSON *dj = cJSON_GetObjectItemCaseSensitive(root, "directional");
    if (dj && !cJSON_IsNull(dj)) {
        const cJSON *mode = cJSON_GetObjectItemCaseSensitive(dj, "mode");
        const cJSON *enc = cJSON_GetObjectItemCaseSensitive(dj, "encoding");
        if (cJSON_IsString(mode) && strcmp(mode->valuestring, "sh") == 0)
            lm->directional = LX_DIRECTIONAL_SH;
        else if (cJSON_IsString(mode) && strcmp(mode->valuestring, "dominant") == 0)
            lm->directional = LX_DIRECTIONAL_DOMINANT;
        else
            return lx_fail(LX_ERR_FORMAT, "%s: \"directional\": \"mode\" must be sh or dominant",
                           file);
        if (lm->directional == LX_DIRECTIONAL_SH) {
            if (cJSON_IsString(enc) && strcmp(enc->valuestring, "normalized") == 0)
                lm->sh_normalized = true;
            else if (!(cJSON_IsString(enc) && strcmp(enc->valuestring, "irradiance") == 0))
                return lx_fail(LX_ERR_FORMAT,
                               "%s: \"directional\": \"encoding\" must be irradiance or "
                               "normalized",
                               file);
        }
    }
    lx_status st = parse_pages(file, dir, any_path, root, lm);
    if (st == LX_OK)
        st = parse_nodes(file, root, lm);
    if (st == LX_OK)
        st = parse_unbaked(file, root, lm);
    return st;
}

/* 8-bit pages hold what the bake's previews show: the quantity times
 * the preview exposure (irradiance as E / pi), sRGB-encoded; scale is
 * what takes the decoded values back to the manifest's units. */
static float eight_bit_scale(const lx_lightmaps *lm)
{
    float e = lx_exposure_from_ev100(lm->preview_ev100);
    return lm->quantity == LX_QUANTITY_RADIANCE ? 1.0f / e : LX_PI / e;
}

static lx_status load_page(const char *manifest, uint32_t i, lx_lightmap_page *p, float scale8)
{
    lx_image_load_desc ld = {.channels = 3};
    lx_status st = lx_image_load(p->file, &ld, &p->image);
    if (st != LX_OK) {
        lx_error_prefix(manifest);
        return st;
    }
    if (p->image.width != p->width || p->image.height != p->height)
        return lx_fail(LX_ERR_FORMAT, "%s: page %u: %s is %dx%d, the manifest says %dx%d", manifest,
                       i, p->file, p->image.width, p->image.height, p->width, p->height);
    size_t n = (size_t)p->width * (size_t)p->height * 3;
    lx_image_format f = lx_image_format_from_path(p->file);
    if (f == LX_IMAGE_PNG || f == LX_IMAGE_JPG || f == LX_IMAGE_TGA)
        for (size_t k = 0; k < n; k++)
            p->image.data[k] *= scale8;
    for (size_t k = 0; k < n; k++)
        if (!(p->image.data[k] >= 0.0f))
            return lx_fail(LX_ERR_FORMAT, "%s: page %u: %s: texel (%zu, %zu) is negative", manifest,
                           i, p->file, (k / 3) % (size_t)p->width, (k / 3) / (size_t)p->width);
    return LX_OK;
}

/* One directional image of page i: its size checked, finite values
 * (raw codes for 8-bit files unless scale8 > 0, then scaled as a page). */
static lx_status load_extra(const char *manifest, uint32_t i, const lx_lightmap_page *p,
                            const char *path, int channels, float scale8, lx_image *out)
{
    lx_image_load_desc ld = {.channels = channels, .raw_8bit = !(scale8 > 0.0f)};
    lx_status st = lx_image_load(path, &ld, out);
    if (st != LX_OK) {
        lx_error_prefix(manifest);
        return st;
    }
    if (out->width != p->width || out->height != p->height)
        return lx_fail(LX_ERR_FORMAT, "%s: page %u: %s is %dx%d, the manifest says %dx%d", manifest,
                       i, path, out->width, out->height, p->width, p->height);
    lx_image_format f = lx_image_format_from_path(path);
    size_t n = (size_t)p->width * (size_t)p->height * (size_t)channels;
    if (scale8 > 0.0f && (f == LX_IMAGE_PNG || f == LX_IMAGE_JPG || f == LX_IMAGE_TGA))
        for (size_t k = 0; k < n; k++)
            out->data[k] *= scale8;
    return LX_OK;
}

/* The directional data of page i (lm->directional), decoded to E0, E1. */
static lx_status load_directional(const char *manifest, const lx_lightmaps *lm, uint32_t i,
                                  lx_lightmap_page *p, float scale8)
{
    lx_status st = LX_OK;
    if (lm->directional == LX_DIRECTIONAL_DOMINANT)
        return load_extra(manifest, i, p, p->dir_file, 4, 0.0f, &p->dir);
    if (lm->directional != LX_DIRECTIONAL_SH)
        return LX_OK;
    for (int c = 0; c < 4 && st == LX_OK; c++)
        st = load_extra(manifest, i, p, p->sh_files[c], 3,
                        c == 0 || !lm->sh_normalized ? scale8 : 0.0f, &p->sh[c]);
    if (st != LX_OK)
        return st;
    size_t n = (size_t)p->width * (size_t)p->height * 3;
    for (size_t k = 0; k < n; k++) {
        float e0 = p->sh[0].data[k];
        if (!(e0 >= 0.0f))
            return lx_fail(LX_ERR_FORMAT, "%s: page %u: %s: texel (%zu, %zu) is negative",
                           manifest, i, p->sh_files[0], (k / 3) % (size_t)p->width,
                           (k / 3) / (size_t)p->width);
        /* codes r / 2 + 1/2, r = L1 / (sqrt 3 L00): E1 = 2 E0 r */
        for (int c = 1; c < 4 && lm->sh_normalized; c++)
            p->sh[c].data[k] = 2.0f * e0 * (2.0f * p->sh[c].data[k] - 1.0f);
    }
    return LX_OK;
}

lx_status lx_lightmaps_load(const char *dir, const lx_lightmaps_load_desc *desc, lx_lightmaps *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    if (!dir)
        return lx_fail_null(__func__, "dir");
    memset(out, 0, sizeof *out);
    lx_lightmaps_load_desc d = lx_lightmaps_load_desc_defaults(desc);
    if (!dir || !dir[0])
        return lx_fail(LX_ERR_INVALID, "lightmaps: no folder given");
    char *file = lx_path_join(dir, "manifest.json");
    if (!file)
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    char *text = NULL;
    size_t size = 0;
    lx_status st = lx_read_file(file, MANIFEST_MAX, &text, &size);
    if (st != LX_OK) {
        free(file);
        return st;
    }
    cJSON *root = cJSON_ParseWithLength(text, size);
    free(text);
    if (!root) {
        st = lx_fail(LX_ERR_FORMAT, "%s: not valid JSON", file);
        free(file);
        return st;
    }
    lx_lightmaps lm = {0};
    if (!(lm.dir = lx_strdup(dir)))
        st = lx_fail(LX_ERR_NOMEM, "out of memory");
    else
        st = parse_manifest(file, dir, d.allow_any_path, root, &lm);
    cJSON_Delete(root);
    for (uint32_t i = 0; st == LX_OK && !d.skip_images && i < lm.page_count; i++)
    {
        st = load_page(file, i, &lm.pages[i], eight_bit_scale(&lm));
        if (st == LX_OK)
            st = load_directional(file, &lm, i, &lm.pages[i], eight_bit_scale(&lm));
    }
    free(file);
    if (st != LX_OK) {
        lx_lightmaps_free(&lm);
        return st;
    }
    *out = lm;
    return LX_OK;
}

/* ---- binding to a scene -------------------------------------------------- */

static const char *scene_name(const lx_scene *scene)
{
    return scene->path ? scene->path : "the scene";
}

static int cmp_names(const void *a, const void *b)
{
    const char *const *x = a, *const *y = b;
    return strcmp(*x, *y);
}

lx_status lx_lightmaps_bind(const lx_lightmaps *lm, const lx_scene *scene, uint32_t *map)
{
    const char *m = lm->dir ? lm->dir : "lightmaps";
    uint32_t with_meshes = 0;
    for (uint32_t n = 0; n < scene->node_count; n++)
        with_meshes += scene->nodes[n].mesh_count > 0;
    if (lm->node_count > with_meshes)
        return lx_fail(
            LX_ERR_INVALID,
            "%s/manifest.json lists %u nodes, %s has %u: the lightmaps of another scene?", m,
            lm->node_count, scene_name(scene), with_meshes);
    /* manifest nodes sorted by name, each name followed by its index */
    struct entry {
        const char *name;
        uint32_t index;
    } *sorted = malloc((lm->node_count ? lm->node_count : 1) * sizeof *sorted);
    uint8_t *used = calloc(lm->node_count ? lm->node_count : 1, 1);
    if (!sorted || !used) {
        free(sorted);
        free(used);
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    }
    for (uint32_t i = 0; i < lm->node_count; i++)
        sorted[i] = (struct entry){lm->nodes[i].name, i};
    qsort(sorted, lm->node_count, sizeof *sorted, cmp_names);
    lx_status st = LX_OK;
    for (uint32_t n = 0; n < scene->node_count && st == LX_OK; n++) {
        const lx_node *node = &scene->nodes[n];
        const char *key = node->name ? node->name : "";
        struct entry *e = bsearch(&key, sorted, lm->node_count, sizeof *sorted, cmp_names);
        if (map)
            map[n] = e ? e->index : UINT32_MAX;
        if (!e) {
            /* a node the bake could not map (some mesh lacks a UV set),
             * or gave no lightmap by its settings */
            bool could_skip =
                node->mesh_count == 0 || node->bake.no_lightmap || is_unbaked(lm, key);
            for (uint32_t k = 0; k < node->mesh_count; k++) {
                const lx_mesh *mesh = &scene->meshes[node->meshes[k]];
                could_skip |= !mesh->uv[0] || !mesh->uv[1];
            }
            if (!could_skip)
                st = lx_fail(LX_ERR_INVALID,
                             "%s/manifest.json has no lightmap for node '%s' of %s (%u nodes "
                             "listed, the scene has %u): the lightmaps of another scene?",
                             m, key, scene_name(scene), lm->node_count, with_meshes);
            continue;
        }
        used[e->index] = 1;
        const lx_lightmap_node *ln = &lm->nodes[e->index];
        if (ln->mesh_count != node->mesh_count) {
            st = lx_fail(LX_ERR_INVALID,
                         "%s/manifest.json: node '%s' has %u meshes, in %s %u: the lightmaps of "
                         "another scene?",
                         m, key, ln->mesh_count, scene_name(scene), node->mesh_count);
            continue;
        }
        for (uint32_t k = 0; k < node->mesh_count && st == LX_OK; k++) {
            const lx_mesh *mesh = &scene->meshes[node->meshes[k]];
            if (!mesh->uv[ln->uv_set])
                st = lx_fail(LX_ERR_INVALID,
                             "%s/manifest.json: node '%s': mesh '%s' of %s has no TEXCOORD_%d%s", m,
                             key, mesh->name ? mesh->name : "?", scene_name(scene), ln->uv_set,
                             ln->generated ? " (luxel made them: use the scene_with_uvs file)"
                                           : ": the lightmaps of another scene?");
        }
    }
    for (uint32_t i = 0; i < lm->node_count && st == LX_OK; i++)
        if (!used[i])
            st =
                lx_fail(LX_ERR_INVALID,
                        "%s/manifest.json: node '%s' is not in %s: the lightmaps of another scene?",
                        m, lm->nodes[i].name, scene_name(scene));
    free(sorted);
    free(used);
    return st;
}

lx_status lx_lightmaps_check(const lx_lightmaps *lm, const lx_scene *scene)
{
    if (!lm)
        return lx_fail_null(__func__, "lm");
    if (!scene)
        return lx_fail_null(__func__, "scene");
    return lx_lightmaps_bind(lm, scene, NULL);
}
