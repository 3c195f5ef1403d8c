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

struct lx_lj_nodes {
    lx_node_settings *entries; /* per entry of the section, in file order */
    char **unmatched;          /* patterns that matched no node (copies) */
    uint32_t entry_count, unmatched_count;
    uint32_t *first, *node_entries; /* per scene node: its entries, CSR */
    uint32_t node_count;
    char *scene_name, *file; /* for the warning */
};

void lx_lj_nodes_free(lx_lj_nodes *p)
{
    if (!p)
        return;
    for (uint32_t k = 0; k < p->unmatched_count; k++)
        free(p->unmatched[k]);
    free(p->unmatched);
    free(p->entries);
    free(p->first);
    free(p->node_entries);
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
    uint32_t count = 0;
    for (const cJSON *e = obj->child; e; e = e->next)
        count++;
    uint32_t nn = scene->node_count;
    lx_lj_nodes *p = calloc(1, sizeof *p);
    if (p) {
        p->entries = calloc((size_t)count + 1, sizeof *p->entries);
        p->unmatched = calloc((size_t)count + 1, sizeof *p->unmatched);
        p->first = calloc((size_t)nn + 1, sizeof *p->first);
        p->scene_name = lx_strdup(scene->path ? scene->path : "the scene");
        p->file = lx_strdup(c->file);
    }
    if (!p || !p->entries || !p->unmatched || !p->first || !p->scene_name || !p->file) {
        lx_lj_nodes_free(p);
        return lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
    }
    p->node_count = nn;
    p->entry_count = count;
    uint32_t k = 0;
    uint64_t pairs = 0;
    lx_status st = LX_OK;
    for (const cJSON *e = obj->child; e && st == LX_OK; e = e->next, k++) {
        const char *pattern = e->string ? e->string : "";
        snprintf(c->where, sizeof c->where, "nodes");
        for (const cJSON *q = obj->child; q != e; q = q->next)
            if (strcmp(q->string, pattern) == 0) {
                st = lx_jf_fail(c, LX_ERR_FORMAT, "'%.60s' appears twice", pattern);
                break;
            }
        if (st != LX_OK)
            break;
        if (!pattern[0]) {
            st = lx_jf_fail(c, LX_ERR_FORMAT, "an empty name matches no node");
            break;
        }
        snprintf(c->where, sizeof c->where, "nodes ('%.60s')", pattern);
        p->entries[k] = lx_node_settings_none();
        if ((st = read_entry(c, e, &p->entries[k])) != LX_OK)
            break;
        uint32_t hits = 0;
        for (uint32_t n = 0; n < nn; n++)
            if (matches(pattern, scene->nodes[n].name)) {
                p->first[n]++;
                hits++;
            }
        pairs += hits;
        if (!hits && !(p->unmatched[p->unmatched_count++] = lx_strdup(pattern)))
            st = lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
    }
    /* per node, the entries that match it, in file order */
    if (st == LX_OK) {
        p->node_entries = malloc(sizeof(uint32_t) * (size_t)(pairs + 1));
        if (!p->node_entries)
            st = lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
    }
    if (st == LX_OK) {
        uint32_t run = 0;
        for (uint32_t n = 0; n <= nn; n++) {
            uint32_t here = n < nn ? p->first[n] : 0;
            p->first[n] = run;
            run += here;
        }
        uint32_t *fill = calloc((size_t)nn + 1, sizeof *fill);
        if (!fill) {
            st = lx_jf_fail(c, LX_ERR_NOMEM, "out of memory");
        } else {
            k = 0;
            for (const cJSON *e = obj->child; e; e = e->next, k++)
                for (uint32_t n = 0; n < nn; n++)
                    if (matches(e->string, scene->nodes[n].name))
                        p->node_entries[p->first[n] + fill[n]++] = k;
            free(fill);
        }
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
        for (uint32_t i = p->first[n]; i < p->first[n + 1]; i++)
            lx_node_settings_apply(&p->entries[p->node_entries[i]], &scene->nodes[n].bake);
    if (p->unmatched_count) {
        char more[64] = "";
        if (p->unmatched_count > 1)
            snprintf(more, sizeof more, " (nor do %u more)", p->unmatched_count - 1);
        lx_log(LX_LOG_WARN, "%s: nodes: '%.60s' matches no node of %s%s", p->file, p->unmatched[0],
               p->scene_name, more);
    }
}
