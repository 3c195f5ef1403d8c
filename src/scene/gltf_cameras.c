/* glTF 2.0 cameras (spec 3.10): "perspective" (yfov, aspectRatio, znear,
 * zfar) and "orthographic" (xmag, ymag, znear, zfar) definitions in the
 * root "cameras", placed by the nodes whose "camera" names one. A camera
 * looks down its node's local -Z with local +Y up. Read from the JSON
 * directly (cJSON, through gltf_json.c): assimp keeps cameras but not the
 * node they belong to in a form luxel's other readers share. A camera luxel
 * cannot use is left out with one warning, never failing the load: cameras
 * are for views, and a scene with a broken one still bakes. */
#include "luxel/scene.h"
#include "core/internal.h"

#include "gltf_json.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A definition as read: ok false when it is left out (warned once). */
typedef struct cam_def {
    bool ok;
    lx_scene_camera cam; /* type and projection fields */
    const char *name;    /* owned by cJSON, or NULL */
} cam_def;

/* An optional finite number >= lo (or > lo when strict); 0 when absent or
 * malformed (luxel reads these fields for callers and never needs them). */
static float optional(const cJSON *obj, const char *key, float lo, bool strict)
{
    float v;
    const cJSON *it = lx_gltf_get(obj, key);
    if (!it || !lx_gltf_number(it, &v) || (strict ? !(v > lo) : !(v >= lo)))
        return 0.0f;
    return v;
}

static void read_def(const char *file, const cJSON *obj, size_t index, cam_def *out)
{
    char who[128];
    lx_gltf_label(who, sizeof who, "camera", index, obj);
    memset(out, 0, sizeof *out);
    if (!cJSON_IsObject(obj)) {
        lx_log(LX_LOG_WARN, "%s: %s is not an object: left out", file, who);
        return;
    }
    out->name = lx_gltf_get_string(obj, "name");
    const char *type = lx_gltf_get_string(obj, "type");
    lx_scene_camera *c = &out->cam;
    if (type && strcmp(type, "perspective") == 0) {
        const cJSON *p = lx_gltf_get(obj, "perspective");
        const cJSON *yf = lx_gltf_get(p, "yfov");
        float yfov;
        if (!cJSON_IsObject(p)) {
            lx_log(LX_LOG_WARN, "%s: %s: no 'perspective' object: left out", file, who);
            return;
        }
        if (!yf) {
            lx_log(LX_LOG_WARN, "%s: %s: no yfov: left out", file, who);
            return;
        }
        if (!lx_gltf_number(yf, &yfov) || !(yfov > 0.0f) || !(yfov < LX_PI)) {
            if (cJSON_IsNumber(yf))
                lx_log(LX_LOG_WARN,
                       "%s: %s: yfov %g is not an angle in (0, pi) radians: left out", file, who,
                       yf->valuedouble);
            else
                lx_log(LX_LOG_WARN, "%s: %s: yfov is not a number: left out", file, who);
            return;
        }
        c->type = LX_SCENE_CAMERA_PERSPECTIVE;
        c->yfov = yfov;
        c->aspect = optional(p, "aspectRatio", 0.0f, true);
        c->znear = optional(p, "znear", 0.0f, true);
        c->zfar = optional(p, "zfar", c->znear, true);
    } else if (type && strcmp(type, "orthographic") == 0) {
        const cJSON *o = lx_gltf_get(obj, "orthographic");
        float xmag = 0.0f, ymag = 0.0f;
        if (!cJSON_IsObject(o) || !lx_gltf_number(lx_gltf_get(o, "xmag"), &xmag) ||
            !lx_gltf_number(lx_gltf_get(o, "ymag"), &ymag) || xmag == 0.0f || ymag == 0.0f) {
            lx_log(LX_LOG_WARN,
                   "%s: %s: orthographic xmag and ymag must be finite numbers other than 0: "
                   "left out",
                   file, who);
            return;
        }
        c->type = LX_SCENE_CAMERA_ORTHOGRAPHIC;
        c->xmag = xmag;
        c->ymag = ymag;
        c->znear = optional(o, "znear", 0.0f, false);
        c->zfar = optional(o, "zfar", c->znear, true);
    } else {
        lx_log(LX_LOG_WARN, "%s: %s: type %s%.40s%s is not perspective or orthographic: left out",
               file, who, type ? "'" : "", type ? type : "missing", type ? "'" : "");
        return;
    }
    out->ok = true;
}

/* The camera frame of world: false when it has no -Z or no +Y apart from
 * it (a zero or degenerate scale). */
static bool frame(const lx_mat4 *world, lx_scene_camera *c)
{
    lx_vec3 f = lx_mat4_vector(world, lx_v3(0.0f, 0.0f, -1.0f));
    lx_vec3 u = lx_mat4_vector(world, lx_v3(0.0f, 1.0f, 0.0f));
    double fl = sqrt((double)f.x * f.x + (double)f.y * f.y + (double)f.z * f.z);
    double ul = sqrt((double)u.x * u.x + (double)u.y * u.y + (double)u.z * u.z);
    if (!(fl > 1e-20) || !(ul > 1e-20) || !isfinite(fl) || !isfinite(ul))
        return false;
    double fd[3] = {f.x / fl, f.y / fl, f.z / fl};
    double ud[3] = {u.x / ul, u.y / ul, u.z / ul};
    double k = fd[0] * ud[0] + fd[1] * ud[1] + fd[2] * ud[2];
    for (int i = 0; i < 3; i++)
        ud[i] -= k * fd[i];
    double l = sqrt(ud[0] * ud[0] + ud[1] * ud[1] + ud[2] * ud[2]);
    if (!(l > 1e-6))
        return false;
    c->eye = lx_mat4_point(world, lx_v3(0.0f, 0.0f, 0.0f));
    c->forward = lx_v3((float)fd[0], (float)fd[1], (float)fd[2]);
    c->up = lx_v3((float)(ud[0] / l), (float)(ud[1] / l), (float)(ud[2] / l));
    return lx_vec3_finite(c->eye);
}

/* base, or base_2, base_3... : the first name no scene camera has. */
static bool taken(const lx_scene *scene, const char *name)
{
    for (uint32_t i = 0; i < scene->camera_count; i++)
        if (strcmp(scene->cameras[i].name, name) == 0)
            return true;
    return false;
}

static lx_status add(lx_scene *scene, lx_scene_camera *c, const char *base)
{
    char name[256];
    snprintf(name, sizeof name, "%s", base);
    for (unsigned k = 2; taken(scene, name); k++)
        snprintf(name, sizeof name, "%.200s_%u", base, k);
    c->name = name;
    lx_status st = lx_scene_add_camera(scene, c);
    if (st == LX_ERR_NOMEM)
        return st;
    if (st != LX_OK) /* a value a float could not hold after the transform */
        lx_log(LX_LOG_WARN, "%s: left out", lx_last_error());
    return LX_OK;
}

lx_status lx_gltf_check_cameras(const char *file, const cJSON *root)
{
    const cJSON *list = lx_gltf_get(root, "cameras");
    const cJSON *nodes = lx_gltf_get(root, "nodes");
    size_t count = (size_t)(cJSON_IsArray(list) ? cJSON_GetArraySize(list) : 0), k = 0;
    char who[128];
    for (const cJSON *c = count ? list->child : NULL; c; c = c->next, k++) {
        lx_gltf_label(who, sizeof who, "camera", k, c);
        const char *type = lx_gltf_get_string(c, "type");
        if (!cJSON_IsObject(c))
            return lx_fail(LX_ERR_FORMAT, "%s: %s is not an object", file, who);
        if (!type || (strcmp(type, "perspective") != 0 && strcmp(type, "orthographic") != 0))
            return lx_fail(LX_ERR_FORMAT,
                           "%s: %s: type %s%.40s%s is not perspective or orthographic", file, who,
                           type ? "'" : "", type ? type : "missing", type ? "'" : "");
        if (!cJSON_IsObject(lx_gltf_get(c, type)))
            return lx_fail(LX_ERR_FORMAT, "%s: %s: no '%s' object", file, who, type);
    }
    k = 0;
    for (const cJSON *n = cJSON_IsArray(nodes) ? nodes->child : NULL; n; n = n->next, k++) {
        const cJSON *ref = lx_gltf_get(n, "camera");
        size_t ci;
        if (!ref || lx_gltf_index(ref, count, &ci))
            continue;
        lx_gltf_label(who, sizeof who, "node", k, n);
        if (cJSON_IsNumber(ref))
            return lx_fail(LX_ERR_FORMAT, "%s: %s: camera %g is not in the file (%zu %s)", file,
                           who, ref->valuedouble, count, count == 1 ? "camera" : "cameras");
        return lx_fail(LX_ERR_FORMAT, "%s: %s: 'camera' is not a camera index", file, who);
    }
    return LX_OK;
}

lx_status lx_gltf_cameras_from_json(lx_scene *scene, const char *file, const cJSON *root)
{
    const cJSON *list = lx_gltf_get(root, "cameras");
    const cJSON *nodes = lx_gltf_get(root, "nodes");
    bool referenced = false;
    for (const cJSON *n = cJSON_IsArray(nodes) ? nodes->child : NULL; n && !referenced;
         n = n->next)
        referenced = lx_gltf_get(n, "camera") != NULL;
    if (!list && !referenced)
        return LX_OK;
    if (list && !cJSON_IsArray(list)) {
        lx_log(LX_LOG_WARN, "%s: 'cameras' is not an array: cameras left out", file);
        return LX_OK;
    }
    size_t count = 0;
    for (const cJSON *e = list ? list->child : NULL; e; e = e->next)
        count++;
    cam_def *defs = calloc(count ? count : 1, sizeof *defs);
    if (!defs)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for %zu cameras", file, count);
    size_t i = 0;
    for (const cJSON *e = list ? list->child : NULL; e; e = e->next, i++)
        read_def(file, e, i, &defs[i]);
    lx_gltf_graph g = {0};
    lx_status st = lx_gltf_graph_build(file, root, &g);
    if (st == LX_OK)
        st = lx_gltf_graph_select(file, root, &g);
    if (st == LX_ERR_NOMEM) {
        lx_gltf_graph_free(&g);
        free(defs);
        return st;
    }
    if (st != LX_OK) {
        lx_log(LX_LOG_WARN, "%s: cameras left out", lx_last_error());
        lx_gltf_graph_free(&g);
        free(defs);
        return LX_OK;
    }
    char who[128];
    for (size_t k = 0; k < g.count && st == LX_OK; k++) {
        const cJSON *ref = lx_gltf_get(g.nodes[k], "camera");
        if (!ref || !g.included[k])
            continue;
        lx_gltf_label(who, sizeof who, "node", k, g.nodes[k]);
        size_t ci;
        if (!lx_gltf_index(ref, count, &ci)) {
            if (cJSON_IsNumber(ref))
                lx_log(LX_LOG_WARN, "%s: %s: camera %g is not in the file (%zu %s): left out",
                       file, who, ref->valuedouble, count, count == 1 ? "camera" : "cameras");
            else
                lx_log(LX_LOG_WARN, "%s: %s: 'camera' is not an index: left out", file, who);
            continue;
        }
        if (!defs[ci].ok)
            continue; /* warned once, with its definition */
        lx_scene_camera c = defs[ci].cam;
        if (!frame(&g.world[k], &c)) {
            lx_log(LX_LOG_WARN,
                   "%s: %s: its transform has a zero scale (no -Z or +Y axis to look along): "
                   "camera %zu left out",
                   file, who, ci);
            continue;
        }
        const char *node_name = lx_gltf_get_string(g.nodes[k], "name");
        c.node_name = node_name && node_name[0] ? (char *)node_name : NULL;
        c.source_camera = (int32_t)ci;
        c.source_node = (int32_t)k;
        char fallback[32];
        snprintf(fallback, sizeof fallback, "camera%zu", ci);
        const char *base = defs[ci].name && defs[ci].name[0] ? defs[ci].name
                           : c.node_name                     ? c.node_name
                                                             : fallback;
        st = add(scene, &c, base);
    }
    lx_gltf_graph_free(&g);
    free(defs);
    return st;
}
