/* Ray queries through Intel Embree 3: one BVH per mesh, one instance per
 * (node, mesh) pair in a dynamic top-level scene, so moving a node only
 * refits the small top level. */
#include "luxel/trace.h"

#include <embree3/rtcore.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct instance_ref {
    uint32_t node;
    uint32_t mesh;
} instance_ref;

struct lx_tracer {
    RTCDevice device;
    RTCScene top;
    RTCScene *mesh_scenes;  /* one per scene mesh (NULL when unused) */
    uint32_t mesh_count;
    RTCGeometry *instances; /* one per (node, mesh) pair */
    instance_ref *refs;
    uint32_t instance_count;
    uint32_t *node_first_instance; /* node -> first instance, node_count + 1 */
    uint32_t node_count;
};

/* Embree reports errors through a callback; keep the first for the message. */
static _Thread_local char embree_error[256];

static void on_embree_error(void *user, enum RTCError code, const char *str)
{
    if (!embree_error[0])
        snprintf(embree_error, sizeof embree_error, "Embree error %d: %s", (int)code,
                 str ? str : "");
}

static lx_status embree_status(const char *what)
{
    if (!embree_error[0])
        return LX_OK;
    lx_status s = lx_fail(LX_ERR_INVALID, "%s: %s", what, embree_error);
    embree_error[0] = '\0';
    return s;
}

static RTCScene build_mesh_scene(RTCDevice dev, const lx_mesh *m)
{
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    /* Embree-allocated buffers carry the padding its SIMD loads need. */
    float *verts = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                           3 * sizeof(float), m->vertex_count);
    unsigned *idx = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                            3 * sizeof(unsigned), m->triangle_count);
    if (!verts || !idx) {
        rtcReleaseGeometry(geom);
        rtcReleaseScene(scene);
        return NULL;
    }
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        verts[3 * v + 0] = m->positions[v].x;
        verts[3 * v + 1] = m->positions[v].y;
        verts[3 * v + 2] = m->positions[v].z;
    }
    memcpy(idx, m->indices, sizeof(unsigned) * 3 * (size_t)m->triangle_count);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene, geom, 0);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    return scene;
}

lx_status lx_tracer_create(const lx_scene *scene, lx_tracer **out)
{
    *out = NULL;
    embree_error[0] = '\0';
    lx_tracer *tr = calloc(1, sizeof *tr);
    if (!tr)
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a tracer");
    tr->device = rtcNewDevice(NULL);
    if (!tr->device) {
        free(tr);
        return lx_fail(LX_ERR_UNSUPPORTED, "Embree: cannot create a device (error %d)",
                       (int)rtcGetDeviceError(NULL));
    }
    rtcSetDeviceErrorFunction(tr->device, on_embree_error, NULL);
    tr->mesh_count = scene->mesh_count;
    tr->node_count = scene->node_count;
    uint32_t inst = 0;
    for (uint32_t n = 0; n < scene->node_count; n++)
        inst += scene->nodes[n].mesh_count;
    tr->instance_count = inst;
    tr->mesh_scenes = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof(RTCScene));
    tr->instances = calloc(inst ? inst : 1, sizeof(RTCGeometry));
    tr->refs = calloc(inst ? inst : 1, sizeof(instance_ref));
    tr->node_first_instance = calloc(scene->node_count + 1, sizeof(uint32_t));
    if (!tr->mesh_scenes || !tr->instances || !tr->refs || !tr->node_first_instance) {
        lx_tracer_destroy(tr);
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a tracer");
    }
    tr->top = rtcNewScene(tr->device);
    rtcSetSceneFlags(tr->top, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(tr->top, RTC_BUILD_QUALITY_LOW);

    inst = 0;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        const lx_node *node = &scene->nodes[n];
        tr->node_first_instance[n] = inst;
        for (uint32_t k = 0; k < node->mesh_count; k++) {
            uint32_t mi = node->meshes[k];
            if (!tr->mesh_scenes[mi]) {
                tr->mesh_scenes[mi] = build_mesh_scene(tr->device, &scene->meshes[mi]);
                lx_status st = embree_status(scene->path);
                if (st != LX_OK || !tr->mesh_scenes[mi]) {
                    lx_tracer_destroy(tr);
                    return st != LX_OK ? st
                                       : lx_fail(LX_ERR_NOMEM, "%s: cannot build the BVH of "
                                                 "mesh '%s'", scene->path,
                                                 scene->meshes[mi].name);
                }
            }
            RTCGeometry g = rtcNewGeometry(tr->device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(g, tr->mesh_scenes[mi]);
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, node->world.m);
            rtcCommitGeometry(g);
            rtcAttachGeometryByID(tr->top, g, inst);
            tr->instances[inst] = g;
            tr->refs[inst] = (instance_ref){n, mi};
            inst++;
        }
    }
    tr->node_first_instance[scene->node_count] = inst;
    rtcCommitScene(tr->top);
    lx_status st = embree_status(scene->path);
    if (st != LX_OK) {
        lx_tracer_destroy(tr);
        return st;
    }
    *out = tr;
    return LX_OK;
}

void lx_tracer_destroy(lx_tracer *tr)
{
    if (!tr)
        return;
    for (uint32_t i = 0; i < tr->instance_count; i++)
        if (tr->instances && tr->instances[i])
            rtcReleaseGeometry(tr->instances[i]);
    if (tr->top)
        rtcReleaseScene(tr->top);
    for (uint32_t i = 0; i < tr->mesh_count; i++)
        if (tr->mesh_scenes && tr->mesh_scenes[i])
            rtcReleaseScene(tr->mesh_scenes[i]);
    if (tr->device)
        rtcReleaseDevice(tr->device);
    free(tr->mesh_scenes);
    free(tr->instances);
    free(tr->refs);
    free(tr->node_first_instance);
    free(tr);
}

lx_status lx_tracer_set_node_transform(lx_tracer *tr, uint32_t node, const lx_mat4 *world)
{
    if (node >= tr->node_count)
        return lx_fail(LX_ERR_INVALID, "node %u out of range (count %u)", node, tr->node_count);
    if (!lx_mat4_finite(world) || !(fabsf(lx_mat4_det3(world)) > 1e-20f))
        return lx_fail(LX_ERR_INVALID, "node %u: transform is not finite or is singular", node);
    for (uint32_t i = tr->node_first_instance[node]; i < tr->node_first_instance[node + 1]; i++) {
        rtcSetGeometryTransform(tr->instances[i], 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, world->m);
        rtcCommitGeometry(tr->instances[i]);
    }
    return LX_OK;
}

lx_status lx_tracer_commit(lx_tracer *tr)
{
    rtcCommitScene(tr->top);
    return embree_status("tracer");
}

static void to_rtc_ray(const lx_ray *r, struct RTCRay *out)
{
    out->org_x = r->origin.x;
    out->org_y = r->origin.y;
    out->org_z = r->origin.z;
    out->tnear = r->tmin;
    out->dir_x = r->dir.x;
    out->dir_y = r->dir.y;
    out->dir_z = r->dir.z;
    out->time = 0.0f;
    out->tfar = r->tmax;
    out->mask = 0xFFFFFFFFu;
    out->id = 0;
    out->flags = 0;
}

bool lx_tracer_occluded(const lx_tracer *tr, const lx_ray *ray)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRay r;
    to_rtc_ray(ray, &r);
    rtcOccluded1(tr->top, &ctx, &r);
    return r.tfar < 0.0f;
}

void lx_tracer_occluded_batch(const lx_tracer *tr, const lx_ray *rays, uint32_t count,
                              bool coherent, uint8_t *occluded)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    if (coherent)
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    enum { CHUNK = 64 };
    struct RTCRay buf[CHUNK];
    for (uint32_t base = 0; base < count; base += CHUNK) {
        uint32_t n = count - base < CHUNK ? count - base : CHUNK;
        for (uint32_t i = 0; i < n; i++)
            to_rtc_ray(&rays[base + i], &buf[i]);
        rtcOccluded1M(tr->top, &ctx, buf, n, sizeof(struct RTCRay));
        for (uint32_t i = 0; i < n; i++)
            occluded[base + i] = buf[i].tfar < 0.0f;
    }
}

bool lx_tracer_closest(const lx_tracer *tr, const lx_ray *ray, lx_hit *hit)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    to_rtc_ray(ray, &rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(tr->top, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return false;
    uint32_t inst = rh.hit.instID[0];
    if (hit) {
        hit->t = rh.ray.tfar;
        hit->node = inst < tr->instance_count ? tr->refs[inst].node : UINT32_MAX;
        hit->mesh = inst < tr->instance_count ? tr->refs[inst].mesh : UINT32_MAX;
        hit->triangle = rh.hit.primID;
        hit->u = rh.hit.u;
        hit->v = rh.hit.v;
    }
    return true;
}

float lx_tracer_nearest_distance(const lx_tracer *tr, const lx_ray *ray)
{
    lx_hit h;
    return lx_tracer_closest(tr, ray, &h) ? h.t : INFINITY;
}
