/* The texture references of a glTF 2.0 material as the file states them
 * (baseColorTexture, or KHR_materials_pbrSpecularGlossiness's
 * diffuseTexture: Khronos extension spec, archived): texCoord and
 * KHR_texture_transform (Khronos extension spec: offset,
 * rotation, scale and a texCoord that overrides the textureInfo's). Read
 * from the JSON because assimp 5.2.5 keeps neither faithfully: it drops the
 * texCoord override, and its AI_MATKEY_UVTRANSFORM holds a translation
 * re-expressed for its own bottom-left, centre-rotated UV convention, which
 * aiProcess_FlipUVs then changes again (an offset of (0.1, 0.2) with
 * rotation 0.3 and scale (2, 3) comes out as a translation of
 * (0.440, 1.824)). */
#include "gltf_json.h"
#include "core/internal.h"

#include "json_text.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* A texCoord: a non-negative integer (the caller refuses sets above 1). */
static bool tex_coord(const cJSON *item, uint32_t *out)
{
    if (!cJSON_IsNumber(item))
        return false;
    double v = item->valuedouble;
    if (!(v >= 0.0) || v != floor(v) || v > 4294967295.0)
        return false;
    *out = (uint32_t)v;
    return true;
}

static lx_status read_ref(const char *file, const char *who, const cJSON *info,
                          lx_gltf_texture_ref *out)
{
    memset(out, 0, sizeof *out);
    if (!info)
        return LX_OK;
    if (!cJSON_IsObject(info))
        return lx_json_fail(LX_ERR_FORMAT, file, who, "must be an object");
    out->present = true;
    const cJSON *it = lx_gltf_get(info, "texCoord");
    if (it && !tex_coord(it, &out->tex_coord))
        return lx_json_fail(LX_ERR_FORMAT, file, who, "texCoord must be an integer >= 0");
    const cJSON *tt = lx_gltf_get(lx_gltf_get(info, "extensions"), "KHR_texture_transform");
    if (!tt)
        return LX_OK;
    char where[200];
    snprintf(where, sizeof where, "%s: KHR_texture_transform", who);
    if (!cJSON_IsObject(tt))
        return lx_json_fail(LX_ERR_FORMAT, file, where, "must be an object");
    lx_uv_transform t = {.enabled = true, .scale = {1.0f, 1.0f}};
    float v[2];
    if ((it = lx_gltf_get(tt, "offset"))) {
        if (!lx_gltf_numbers(it, v, 2))
            return lx_json_fail(LX_ERR_FORMAT, file, where, "offset must be 2 finite numbers");
        t.offset = lx_v2(v[0], v[1]);
    }
    if ((it = lx_gltf_get(tt, "rotation")) && !lx_gltf_number(it, &t.rotation))
        return lx_json_fail(LX_ERR_FORMAT, file, where, "rotation must be a finite number");
    if ((it = lx_gltf_get(tt, "scale"))) {
        if (!lx_gltf_numbers(it, v, 2))
            return lx_json_fail(LX_ERR_FORMAT, file, where, "scale must be 2 finite numbers");
        t.scale = lx_v2(v[0], v[1]);
    }
    if ((it = lx_gltf_get(tt, "texCoord")) && !tex_coord(it, &out->tex_coord))
        return lx_json_fail(LX_ERR_FORMAT, file, where, "texCoord must be an integer >= 0");
    out->transform = t;
    return LX_OK;
}

lx_status lx_gltf_material_textures(const char *file, const cJSON *m, size_t index, bool spec_gloss,
                                    lx_gltf_texture_ref *base_color, lx_gltf_texture_ref *normal)
{
    memset(base_color, 0, sizeof *base_color);
    memset(normal, 0, sizeof *normal);
    if (!cJSON_IsObject(m))
        return LX_OK;
    char who[160], where[200];
    lx_gltf_label(who, sizeof who, "material", index, m);
    const cJSON *base;
    if (spec_gloss) {
        snprintf(where, sizeof where, "%s: KHR_materials_pbrSpecularGlossiness: diffuseTexture",
                 who);
        base = lx_gltf_get(
            lx_gltf_get(lx_gltf_get(m, "extensions"), "KHR_materials_pbrSpecularGlossiness"),
            "diffuseTexture");
    } else {
        snprintf(where, sizeof where, "%s: baseColorTexture", who);
        base = lx_gltf_get(lx_gltf_get(m, "pbrMetallicRoughness"), "baseColorTexture");
    }
    lx_status st = read_ref(file, where, base, base_color);
    if (st != LX_OK)
        return st;
    snprintf(where, sizeof where, "%s: normalTexture", who);
    return read_ref(file, where, lx_gltf_get(m, "normalTexture"), normal);
}

lx_status lx_gltf_material_emissive_texture(const char *file, const cJSON *m, size_t index,
                                            lx_gltf_texture_ref *emissive)
{
    memset(emissive, 0, sizeof *emissive);
    if (!cJSON_IsObject(m))
        return LX_OK;
    char who[160], where[200];
    lx_gltf_label(who, sizeof who, "material", index, m);
    snprintf(where, sizeof where, "%s: emissiveTexture", who);
    return read_ref(file, where, lx_gltf_get(m, "emissiveTexture"), emissive);
}

lx_status lx_gltf_material_emissive(const char *file, const cJSON *m, size_t index, lx_vec3 *out)
{
    *out = lx_v3(0, 0, 0);
    if (!cJSON_IsObject(m))
        return LX_OK;
    char who[160];
    lx_gltf_label(who, sizeof who, "material", index, m);
    float f[3] = {0, 0, 0}, strength = 1.0f;
    const cJSON *it = lx_gltf_get(m, "emissiveFactor");
    if (it && (!lx_gltf_numbers(it, f, 3) || f[0] < 0 || f[1] < 0 || f[2] < 0))
        return lx_json_fail(LX_ERR_FORMAT, file, who,
                            "emissiveFactor must be 3 finite numbers >= 0");
    const cJSON *ext =
        lx_gltf_get(lx_gltf_get(m, "extensions"), "KHR_materials_emissive_strength");
    if (ext) {
        it = lx_gltf_get(ext, "emissiveStrength");
        if (!cJSON_IsObject(ext) || (it && (!lx_gltf_number(it, &strength) || strength < 0)))
            return lx_json_fail(LX_ERR_FORMAT, file, who,
                                "KHR_materials_emissive_strength: emissiveStrength must be a "
                                "finite number >= 0");
    }
    *out = lx_v3(f[0] * strength, f[1] * strength, f[2] * strength);
    if (!lx_vec3_finite(*out))
        return lx_json_fail(LX_ERR_FORMAT, file, who,
                            "emissiveFactor times emissiveStrength overflows a float");
    return LX_OK;
}
