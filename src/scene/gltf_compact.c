/* Accessors and bufferViews a glTF rewrite left unused are dropped and the
 * remaining ones renumbered (glTF 2.0 spec, 3.6: every reference is an
 * index into the top-level arrays). The references followed are those of
 * the core spec - primitive attributes, indices and morph targets, skins'
 * inverseBindMatrices, animation samplers' input and output, accessors'
 * bufferView and sparse views, images' bufferView - and
 * EXT_mesh_gpu_instancing's attributes. A file that uses an extension not
 * known here to leave accessors and views alone is not compacted. */
#include "core/internal.h"
#include "gltf_json.h"
#include "gltf_write_internal.h"

#include <stdlib.h>
#include <string.h>

typedef void (*ref_fn)(cJSON *ref, bool accessor, void *user);

static void each_number(cJSON *obj, bool accessor, ref_fn fn, void *user)
{
    for (cJSON *c = cJSON_IsObject(obj) ? obj->child : NULL; c; c = c->next)
        if (cJSON_IsNumber(c))
            fn(c, accessor, user);
}

static void ref(cJSON *obj, const char *key, bool accessor, ref_fn fn, void *user)
{
    cJSON *r = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (cJSON_IsNumber(r))
        fn(r, accessor, user);
}

#define EACH(item, parent, key)                                                                    \
    for (cJSON *item = cJSON_IsArray(cJSON_GetObjectItemCaseSensitive(parent, key))                \
                           ? cJSON_GetObjectItemCaseSensitive(parent, key)->child                  \
                           : NULL;                                                                 \
         item; item = item->next)

static void walk(cJSON *root, ref_fn fn, void *user)
{
    EACH(mesh, root, "meshes")
    EACH(prim, mesh, "primitives")
    {
        each_number(cJSON_GetObjectItemCaseSensitive(prim, "attributes"), true, fn, user);
        ref(prim, "indices", true, fn, user);
        EACH(target, prim, "targets")
        each_number(target, true, fn, user);
    }
    EACH(skin, root, "skins")
    ref(skin, "inverseBindMatrices", true, fn, user);
    EACH(anim, root, "animations")
    EACH(sampler, anim, "samplers")
    {
        ref(sampler, "input", true, fn, user);
        ref(sampler, "output", true, fn, user);
    }
    EACH(node, root, "nodes")
    {
        cJSON *inst = cJSON_GetObjectItemCaseSensitive(
            cJSON_GetObjectItemCaseSensitive(node, "extensions"), "EXT_mesh_gpu_instancing");
        each_number(cJSON_GetObjectItemCaseSensitive(inst, "attributes"), true, fn, user);
    }
    EACH(acc, root, "accessors")
    {
        ref(acc, "bufferView", false, fn, user);
        cJSON *sparse = cJSON_GetObjectItemCaseSensitive(acc, "sparse");
        ref(cJSON_GetObjectItemCaseSensitive(sparse, "indices"), "bufferView", false, fn, user);
        ref(cJSON_GetObjectItemCaseSensitive(sparse, "values"), "bufferView", false, fn, user);
    }
    EACH(image, root, "images")
    ref(image, "bufferView", false, fn, user);
}

typedef struct marks {
    bool *acc, *view;
    size_t nacc, nview;
} marks;

static void mark(cJSON *r, bool accessor, void *user)
{
    marks *m = user;
    double v = r->valuedouble;
    if (accessor && v >= 0 && v < (double)m->nacc)
        m->acc[(size_t)v] = true;
    if (!accessor && v >= 0 && v < (double)m->nview)
        m->view[(size_t)v] = true;
}

typedef struct remap {
    const int *acc, *view;
    size_t nacc, nview;
} remap;

static void renumber(cJSON *r, bool accessor, void *user)
{
    remap *m = user;
    double v = r->valuedouble;
    if (accessor && v >= 0 && v < (double)m->nacc)
        cJSON_SetNumberValue(r, m->acc[(size_t)v]);
    if (!accessor && v >= 0 && v < (double)m->nview)
        cJSON_SetNumberValue(r, m->view[(size_t)v]);
}

/* Extensions known not to refer to accessors or bufferViews (or whose
 * references walk() follows). */
static bool known_extension(const char *name)
{
    static const char *const known[] = {
        "KHR_lights_punctual",  "KHR_texture_transform",  "KHR_mesh_quantization",
        "KHR_texture_basisu",   "EXT_texture_webp",       "EXT_texture_avif",
        "KHR_materials_variants", "EXT_mesh_gpu_instancing", "KHR_xmp_json_ld",
        "EXT_lights_image_based"};
    if (strncmp(name, "KHR_materials_", 14) == 0)
        return true;
    for (size_t i = 0; i < sizeof known / sizeof *known; i++)
        if (strcmp(name, known[i]) == 0)
            return true;
    return false;
}

lx_status lx_gltf_used(cJSON *root, bool **acc, size_t *nacc, bool **view, size_t *nview)
{
    marks m = {NULL, NULL, (size_t)cJSON_GetArraySize(lx_gltf_get(root, "accessors")),
               (size_t)cJSON_GetArraySize(lx_gltf_get(root, "bufferViews"))};
    m.acc = calloc(m.nacc + 1, sizeof(bool));
    m.view = calloc(m.nview + 1, sizeof(bool));
    if (!m.acc || !m.view) {
        free(m.acc);
        free(m.view);
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    }
    walk(root, mark, &m);
    *acc = m.acc, *nacc = m.nacc, *view = m.view, *nview = m.nview;
    return LX_OK;
}

lx_status lx_gltf_drop_unused(cJSON *root, const bool *acc_before, size_t nacc_before,
                              const bool *view_before, size_t nview_before)
{
    const cJSON *used_ext = lx_gltf_get(root, "extensionsUsed");
    for (const cJSON *e = cJSON_IsArray(used_ext) ? used_ext->child : NULL; e; e = e->next)
        if (!cJSON_IsString(e) || !known_extension(e->valuestring))
            return LX_OK; /* it might refer to what looks unused */
    bool *acc, *view;
    size_t nacc, nview;
    lx_status st = lx_gltf_used(root, &acc, &nacc, &view, &nview);
    if (st != LX_OK)
        return st;
    int *amap = malloc(sizeof(int) * (nacc + 1)), *vmap = malloc(sizeof(int) * (nview + 1));
    if (!amap || !vmap) {
        free(amap), free(vmap), free(acc), free(view);
        return lx_fail(LX_ERR_NOMEM, "out of memory");
    }
    /* drop what was used before and is not now; the rest keeps its order */
    cJSON *accs = cJSON_GetObjectItemCaseSensitive(root, "accessors");
    int next = 0;
    for (size_t i = 0; i < nacc; i++)
        amap[i] = (i < nacc_before && acc_before[i] && !acc[i]) ? -1 : next++;
    /* views used only by dropped accessors go too */
    marks after = {acc, view, nacc, nview};
    memset(view, 0, nview);
    for (size_t i = 0; i < nacc; i++)
        acc[i] = amap[i] >= 0;
    {
        /* recount view uses over the accessors that stay and the images */
        size_t i = 0;
        EACH(a, root, "accessors")
        {
            if (amap[i++] >= 0) {
                ref(a, "bufferView", false, mark, &after);
                cJSON *sparse = cJSON_GetObjectItemCaseSensitive(a, "sparse");
                ref(cJSON_GetObjectItemCaseSensitive(sparse, "indices"), "bufferView", false, mark,
                    &after);
                ref(cJSON_GetObjectItemCaseSensitive(sparse, "values"), "bufferView", false, mark,
                    &after);
            }
        }
        EACH(image, root, "images")
        ref(image, "bufferView", false, mark, &after);
    }
    next = 0;
    for (size_t i = 0; i < nview; i++)
        vmap[i] = (i < nview_before && view_before[i] && !view[i]) ? -1 : next++;
    remap r = {amap, vmap, nacc, nview};
    walk(root, renumber, &r);
    for (size_t i = nacc; i-- > 0;)
        if (amap[i] < 0)
            cJSON_DeleteItemFromArray(accs, (int)i);
    cJSON *views = cJSON_GetObjectItemCaseSensitive(root, "bufferViews");
    for (size_t i = nview; i-- > 0;)
        if (vmap[i] < 0)
            cJSON_DeleteItemFromArray(views, (int)i);
    free(amap), free(vmap), free(acc), free(view);
    return LX_OK;
}
