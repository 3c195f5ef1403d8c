/* The lights JSON's "nodes" section (docs/lights-json.md, "Nodes"): per
 * node, by its name or a glob pattern over the names (fnmatch: *, ?,
 * [...]), whether it casts shadows, gets a lightmap, takes part in
 * bounces, is a sky dome, and its lightmap scale. Entries apply in the
 * file's order, a later one overriding an earlier one's keys; a pattern
 * that matches no node is a warning. Applied only once the whole file is
 * valid, over what the scene file's extras said. */
#include "lights_json_internal.h"
#include "node_bake.h"

#include <fnmatch.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const node_keys[] = {"cast_shadows", "lightmap", "contribute_gi",
                                        "lightmap_scale", "sky"};

static lx_status read_entry(lx_jf_ctx *c, const cJSON *obj, lx_node_settings *s)
{
    if (!cJSON_IsObject(obj))
        return lx_jf_fail(c, LX_ERR_FORMAT,
                          "must be an object of cast_shadows, lightmap, contribute_gi, "
                          "lightmap_scale or sky");
    lx_status st = lx_jf_check_keys(c, obj, node_keys, LX_JF_COUNT(node_keys));
    if (st != LX_OK)
        return st;
    int8_t *flags[] = {&s->cast_shadows, &s->lightmap, &s->contribute_gi, NULL, &s->sky};
    for (int k = 0; k < LX_JF_COUNT(node_keys); k++) {
        const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, node_keys[k]);
        if (!it || !flags[k])
            continue;
        if (!cJSON_IsBool(it))
            return lx_jf_fail(c, LX_ERR_FORMAT, "%s must be true or false", node_keys[k]);
        *flags[k] = cJSON_IsTrue(it) ? 1 : 0;
    }
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, "lightmap_scale");
    if (it) {
        float v;
        if ((st = lx_jf_float(c, it, "lightmap_scale", &v)) != LX_OK)
            return st;
        if (!(v >= 1.0f / LX_NODE_MAX_LIGHTMAP_SCALE) || v > LX_NODE_MAX_LIGHTMAP_SCALE)
            return lx_jf_fail(c, LX_ERR_INVALID, "lightmap_scale %g is outside 1/%g..%g", (double)v,
                              (double)LX_NODE_MAX_LIGHTMAP_SCALE,
                              (double)LX_NODE_MAX_LIGHTMAP_SCALE);
        s->lightmap_scale = v;
    }
    return LX_OK;
}

static bool matches(const char *pattern, const char *name)
{
    return strcmp(pattern, name) == 0 || fnmatch(pattern, name, 0) == 0;
}

/* Entries a section may have (each is checked against the ones before it
 * for repeats), and entries times nodes matched: a 64 MiB file of
 * patterns over a large level would otherwise run for hours. */
#define MAX_ENTRIES 4096u
#define MAX_MATCHES 100000000ull

struct lx_lj_nodes {
    lx_node_bake *bake; /* per scene node: its settings once the file applies */
    uint32_t node_count;
    char **unmatched; /* patterns that matched no node (copies) */
    uint32_t unmatched_count;
    char *scene_name, *file; /* for the warning */
};

void lx_lj_nodes_free(lx_lj_nodes *p)
{
    if (!p)
        return;
    for (uint32_t k = 0; k < p->unmatched_count; k++)
        free(p->unmatched[k]);
    free(p->unmatched);
    free(p->bake);
    free(p->scene_name);
    free(p->file);
    free(p);
}

lx_status lx_lj_nodes_read(lx_jf_ctx *c, const cJSON *obj, const lx_scene *scene, lx_lj_nodes **out)
{
    *out = NULL;
    snprintf(c->where, sizeof c->where, "nodes");
    if (!cJSON_IsObject(obj))
        return lx_jf_fail(c, LX_ERR_FORMAT, "must be an object of node names or patterns");
    uint64_t count = 0;
    for (const cJSON *e = obj->child; e; e = e->next)
        count++;
    uint32_t nn = scene->node_count;
    if (count > MAX_ENTRIES)
        return lx_jf_fail(c, LX_ERR_INVALID, "%llu entries are more than the %u allowed",
                          (unsigned long long)count, MAX_ENTRIES);
    if (count * (nn ? nn : 1) > MAX_MATCHES)
        return lx_jf_fail(c, LX_ERR_INVALID,
                          "%llu entries over %u nodes are more than the %llu matches allowed",
                          (unsigned long long)count, nn, MAX_MATCHES);
    lx_lj_nodes *p = calloc(1, sizeof *p);
    if (p) {
        p->bake = calloc((size_t)nn + 1, sizeof *p->bake);
        p->unmatched = calloc((size_t)count + 1, sizeof *p->unmatched);
        p->scene_name = lx_strdup(scene->path ? scene->path : "the scene");
        p->file = lx_strdup(c->file);
    }
    if (!p || !p->bake || !p->unmatched || !p->scene_name || !p->file) {
        lx_lj_nodes_free(p);
        return lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
    }
    p->node_count = nn;
    for (uint32_t n = 0; n < nn; n++)
        p->bake[n] = scene->nodes[n].bake;
    /* entries in file order, each over the nodes it matches */
    lx_status st = LX_OK;
    for (const cJSON *e = obj->child; e && st == LX_OK; e = e->next) {
        const char *pattern = e->string ? e->string : "";
        snprintf(c->where, sizeof c->where, "nodes");
        for (const cJSON *q = obj->child; q != e && st == LX_OK; q = q->next)
            if (strcmp(q->string, pattern) == 0)
                st = lx_jf_fail(c, LX_ERR_FORMAT, "'%.60s' appears twice", pattern);
        if (st != LX_OK)
            break;
        if (!pattern[0]) {
            st = lx_jf_fail(c, LX_ERR_FORMAT, "an empty name matches no node");
            break;
        }
        snprintf(c->where, sizeof c->where, "nodes ('%.60s')", pattern);
        lx_node_settings settings = lx_node_settings_none();
        if ((st = read_entry(c, e, &settings)) != LX_OK)
            break;
        bool hit = false;
        for (uint32_t n = 0; n < nn; n++)
            if (matches(pattern, scene->nodes[n].name)) {
                lx_node_settings_apply(&settings, &p->bake[n]);
                hit = true;
            }
        if (!hit && !(p->unmatched[p->unmatched_count++] = lx_strdup(pattern)))
            st = lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
    }
    if (st != LX_OK) {
        lx_lj_nodes_free(p);
        return st;
    }
    *out = p;
    return LX_OK;
}

void lx_lj_nodes_apply(const lx_lj_nodes *p, lx_scene *scene)
{
    if (!p)
        return;
    for (uint32_t n = 0; n < p->node_count && n < scene->node_count; n++)
        scene->nodes[n].bake = p->bake[n];
    if (p->unmatched_count) {
        char more[64] = "";
        if (p->unmatched_count > 1)
            snprintf(more, sizeof more, " (nor do %u more)", p->unmatched_count - 1);
        lx_log(LX_LOG_WARN, "%s: nodes: '%.60s' matches no node of %s%s", p->file, p->unmatched[0],
               p->scene_name, more);
    }
}
