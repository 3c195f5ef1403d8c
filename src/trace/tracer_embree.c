/* Ray queries through Intel Embree 3: every (node, mesh) pair is one
 * triangle geometry with world-space vertices in a single flat scene,
 * masked by the kinds of rays its node's bake settings let meet it.
 * A flat BVH traces 20-60% faster than instances here, and Embree 3.13's
 * coherent ray streams through instances were seen to hang. A node that
 * moves gets its vertices rewritten and the scene is rebuilt at the next
 * commit. */
#include "luxel/trace.h"
#include "core/internal.h"

#include <embree3/rtcore.h>
#include <pthread.h>
#include <stdatomic.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct geometry_ref {
    uint32_t node;
    uint32_t mesh;
    bool mirrored; /* the node's transform has a negative determinant */
} geometry_ref;

struct lx_tracer {
    RTCDevice device;
    RTCScene scene;
    RTCGeometry *geometries; /* one per (node, mesh) pair */
    geometry_ref *refs;
    uint32_t geometry_count;
    uint32_t *node_first_geometry; /* node -> first geometry, node_count + 1 */
    uint32_t node_count;
    lx_vec3 **mesh_positions; /* object-space copies, to re-place moved nodes */
    uint32_t *mesh_vertex_counts;
    uint32_t mesh_count;
};

/* Each geometry's Embree mask: a bit per kind of ray that meets it
 * (lx_ray_kind), from its node's bake settings; a ray's mask is its kind's
 * bit (every bit for LX_RAY_ANY). Embree tests (ray mask & geometry mask)
 * at each primitive it would hit, so nodes without flags cost nothing. */
enum {
    MASK_SHADOW = 1u,  /* casts shadows */
    MASK_GATHER = 2u,  /* takes part in bounces */
    MASK_CAMERA = 4u,  /* not a sky dome */
    MASK_FRAMING = 8u, /* has a lightmap and is not a sky dome */
    MASK_ANY = 16u     /* every geometry */
};

static unsigned geometry_mask(const lx_node_bake *b)
{
    unsigned m = MASK_ANY;
    m |= b->no_cast_shadows ? 0u : MASK_SHADOW;
    m |= b->no_contribute_gi ? 0u : MASK_GATHER;
    m |= b->sky ? 0u : MASK_CAMERA;
    m |= b->sky || b->no_lightmap ? 0u : MASK_FRAMING;
    return m;
}

static unsigned ray_mask(lx_ray_kind kind)
{
    switch (kind) {
    case LX_RAY_SHADOW:
        return MASK_SHADOW;
    case LX_RAY_GATHER:
        return MASK_GATHER;
    case LX_RAY_SURFACE:
        return MASK_SHADOW | MASK_GATHER;
    case LX_RAY_CAMERA:
        return MASK_CAMERA;
    case LX_RAY_FRAMING:
        return MASK_FRAMING;
    default:
        return 0xFFFFFFFFu;
    }
}

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

/* Writes positions placed by world into an Embree vertex buffer. */
static void place_vertices(float *dst, const lx_vec3 *src, uint32_t count, const lx_mat4 *world)
{
    for (uint32_t v = 0; v < count; v++) {
        lx_vec3 p = lx_mat4_point(world, src[v]);
        dst[3 * v + 0] = p.x;
        dst[3 * v + 1] = p.y;
        dst[3 * v + 2] = p.z;
    }
}

static RTCGeometry new_geometry(RTCDevice dev, const lx_mesh *m, const lx_mat4 *world,
                                unsigned mask)
{
    RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    /* Embree-allocated buffers carry the padding its SIMD loads need. */
    float *verts = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                           3 * sizeof(float), m->vertex_count);
    unsigned *idx = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                            3 * sizeof(unsigned), m->triangle_count);
    if (!verts || !idx) {
        rtcReleaseGeometry(geom);
        return NULL;
    }
    place_vertices(verts, m->positions, m->vertex_count, world);
    memcpy(idx, m->indices, sizeof(unsigned) * 3 * (size_t)m->triangle_count);
    rtcSetGeometryMask(geom, mask);
    rtcCommitGeometry(geom);
    return geom;
}

lx_tracer_desc lx_tracer_desc_defaults(const lx_tracer_desc *desc)
{
    lx_tracer_desc d = {0};
    if (desc)
        d = *desc;
    return d; /* every field's zero is its default */
}

/* Embree's build progress, which its build threads may report at once,
 * turned into lx_progress_fn's contract: one call at a time (a thread that
 * finds another reporting goes on), never backwards. */
typedef struct build_progress {
    lx_progress_fn fn;
    void *user;
    pthread_mutex_t lock;
    double reported;
    _Atomic bool cancelled;
} build_progress;

static bool on_build_progress(void *ptr, double n)
{
    build_progress *p = ptr;
    if (atomic_load(&p->cancelled))
        return false;
    if (pthread_mutex_trylock(&p->lock) == 0) {
        if (n > p->reported)
            p->reported = n;
        if (!p->fn(p->user, (float)p->reported))
            atomic_store(&p->cancelled, true);
        pthread_mutex_unlock(&p->lock);
    }
    return !atomic_load(&p->cancelled);
}

lx_status lx_tracer_create(const lx_scene *scene, const lx_tracer_desc *in, lx_tracer **out)
{
    if (!scene)
        return lx_fail_null(__func__, "scene");
    if (!out)
        return lx_fail_null(__func__, "out");
    *out = NULL;
    embree_error[0] = '\0';
    lx_tracer_desc desc = lx_tracer_desc_defaults(in);
    int threads = desc.threads;
    if (threads < 0)
        return lx_fail(LX_ERR_INVALID, "tracer: thread count %d is negative", threads);
    lx_tracer *tr = calloc(1, sizeof *tr);
    if (!tr)
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a tracer");
    /* Embree builds the BVH on its own threads: hold them to the count */
    char config[32] = "";
    if (threads > 0)
        snprintf(config, sizeof config, "threads=%d", threads);
    tr->device = rtcNewDevice(threads > 0 ? config : NULL);
    if (!tr->device) {
        free(tr);
        return lx_fail(LX_ERR_UNSUPPORTED, "Embree: cannot create a device (error %d)",
                       (int)rtcGetDeviceError(NULL));
    }
    rtcSetDeviceErrorFunction(tr->device, on_embree_error, NULL);
    tr->node_count = scene->node_count;
    tr->mesh_count = scene->mesh_count;
    uint32_t count = 0;
    for (uint32_t n = 0; n < scene->node_count; n++)
        count += scene->nodes[n].mesh_count;
    tr->geometry_count = count;
    tr->geometries = calloc(count ? count : 1, sizeof(RTCGeometry));
    tr->refs = calloc(count ? count : 1, sizeof(geometry_ref));
    tr->node_first_geometry = calloc(scene->node_count + 1, sizeof(uint32_t));
    tr->mesh_positions = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof(lx_vec3 *));
    tr->mesh_vertex_counts = calloc(scene->mesh_count ? scene->mesh_count : 1, sizeof(uint32_t));
    if (!tr->geometries || !tr->refs || !tr->node_first_geometry || !tr->mesh_positions ||
        !tr->mesh_vertex_counts) {
        lx_tracer_destroy(tr);
        return lx_fail(LX_ERR_NOMEM, "out of memory creating a tracer");
    }
    tr->scene = rtcNewScene(tr->device);
    rtcSetSceneFlags(tr->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(tr->scene, RTC_BUILD_QUALITY_HIGH);

    uint32_t g = 0;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        const lx_node *node = &scene->nodes[n];
        tr->node_first_geometry[n] = g;
        for (uint32_t k = 0; k < node->mesh_count; k++) {
            uint32_t mi = node->meshes[k];
            const lx_mesh *m = &scene->meshes[mi];
            if (!tr->mesh_positions[mi]) {
                tr->mesh_positions[mi] = malloc(sizeof(lx_vec3) * m->vertex_count);
                if (!tr->mesh_positions[mi]) {
                    lx_tracer_destroy(tr);
                    return lx_fail(LX_ERR_NOMEM, "out of memory creating a tracer");
                }
                memcpy(tr->mesh_positions[mi], m->positions, sizeof(lx_vec3) * m->vertex_count);
                tr->mesh_vertex_counts[mi] = m->vertex_count;
            }
            RTCGeometry geom =
                new_geometry(tr->device, m, &node->world, geometry_mask(&node->bake));
            lx_status st = embree_status(scene->path);
            if (st != LX_OK || !geom) {
                if (geom)
                    rtcReleaseGeometry(geom);
                lx_tracer_destroy(tr);
                return st != LX_OK ? st
                                   : lx_fail(LX_ERR_NOMEM,
                                             "%s: out of memory for the rays of "
                                             "mesh '%s'",
                                             scene->path, m->name);
            }
            rtcAttachGeometryByID(tr->scene, geom, g);
            tr->geometries[g] = geom;
            tr->refs[g] = (geometry_ref){n, mi, lx_mat4_det3(&node->world) < 0.0f};
            g++;
        }
    }
    tr->node_first_geometry[scene->node_count] = g;
    build_progress monitor = {.fn = desc.progress, .user = desc.progress_user};
    pthread_mutex_init(&monitor.lock, NULL);
    if (desc.progress)
        rtcSetSceneProgressMonitorFunction(tr->scene, on_build_progress, &monitor);
    rtcCommitScene(tr->scene);
    /* later commits (moved nodes) report to nobody: the monitor is gone */
    rtcSetSceneProgressMonitorFunction(tr->scene, NULL, NULL);
    pthread_mutex_destroy(&monitor.lock);
    lx_status st = embree_status(scene->path);
    if (atomic_load(&monitor.cancelled))
        st =
            lx_fail(LX_ERR_CANCELLED, "%s: building the ray structures was cancelled", scene->path);
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
    for (uint32_t i = 0; i < tr->geometry_count; i++)
        if (tr->geometries && tr->geometries[i])
            rtcReleaseGeometry(tr->geometries[i]);
    if (tr->scene)
        rtcReleaseScene(tr->scene);
    for (uint32_t i = 0; i < tr->mesh_count; i++)
        if (tr->mesh_positions)
            free(tr->mesh_positions[i]);
    if (tr->device)
        rtcReleaseDevice(tr->device);
    free(tr->geometries);
    free(tr->refs);
    free(tr->node_first_geometry);
    free(tr->mesh_positions);
    free(tr->mesh_vertex_counts);
    free(tr);
}

lx_status lx_tracer_set_node_transform(lx_tracer *tr, uint32_t node, const lx_mat4 *world)
{
    if (!tr)
        return lx_fail_null(__func__, "tracer");
    if (!world)
        return lx_fail_null(__func__, "world");
    if (node >= tr->node_count)
        return lx_fail(LX_ERR_INVALID, "node %u out of range (count %u)", node, tr->node_count);
    if (!lx_mat4_finite(world) || !(fabsf(lx_mat4_det3(world)) > 1e-20f))
        return lx_fail(LX_ERR_INVALID, "node %u: transform is not finite or is singular", node);
    for (uint32_t i = tr->node_first_geometry[node]; i < tr->node_first_geometry[node + 1]; i++) {
        uint32_t mi = tr->refs[i].mesh;
        float *verts = rtcGetGeometryBufferData(tr->geometries[i], RTC_BUFFER_TYPE_VERTEX, 0);
        place_vertices(verts, tr->mesh_positions[mi], tr->mesh_vertex_counts[mi], world);
        rtcUpdateGeometryBuffer(tr->geometries[i], RTC_BUFFER_TYPE_VERTEX, 0);
        rtcCommitGeometry(tr->geometries[i]);
        tr->refs[i].mirrored = lx_mat4_det3(world) < 0.0f;
    }
    return LX_OK;
}

lx_status lx_tracer_commit(lx_tracer *tr)
{
    if (!tr)
        return lx_fail_null(__func__, "tracer");
    rtcCommitScene(tr->scene);
    return embree_status("tracer");
}

static void to_rtc_ray(const lx_ray *r, unsigned mask, struct RTCRay *out)
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
    out->mask = mask;
    out->id = 0;
    out->flags = 0;
}

bool lx_tracer_occluded(const lx_tracer *tr, const lx_ray *ray)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRay r;
    to_rtc_ray(ray, MASK_SHADOW, &r);
    rtcOccluded1(tr->scene, &ctx, &r);
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
            to_rtc_ray(&rays[base + i], MASK_SHADOW, &buf[i]);
        rtcOccluded1M(tr->scene, &ctx, buf, n, sizeof(struct RTCRay));
        for (uint32_t i = 0; i < n; i++)
            occluded[base + i] = buf[i].tfar < 0.0f;
    }
}

/* lx_ray_packet is Embree's RTCRay16, field for field, so a packet goes to
 * rtcOccluded16 as it is. */
_Static_assert(sizeof(lx_ray_packet) == sizeof(struct RTCRay16), "packet layout");
_Static_assert(offsetof(lx_ray_packet, tmin) == offsetof(struct RTCRay16, tnear), "tnear");
_Static_assert(offsetof(lx_ray_packet, dir_x) == offsetof(struct RTCRay16, dir_x), "dir_x");
_Static_assert(offsetof(lx_ray_packet, internal_time) == offsetof(struct RTCRay16, time), "time");
_Static_assert(offsetof(lx_ray_packet, tmax) == offsetof(struct RTCRay16, tfar), "tfar");
_Static_assert(offsetof(lx_ray_packet, internal) == offsetof(struct RTCRay16, mask), "mask");
_Static_assert(offsetof(struct RTCRay16, id) == offsetof(struct RTCRay16, mask) + 64, "id");
_Static_assert(offsetof(struct RTCRay16, flags) == offsetof(struct RTCRay16, mask) + 128, "flags");

uint32_t lx_tracer_occluded_packet(const lx_tracer *tr, lx_ray_packet *packet, uint32_t active)
{
    active &= (1u << LX_RAY_PACKET) - 1u;
    if (!active)
        return 0;
    /* the lanes' valid words, four at a time from the mask's nibbles */
    static const int32_t nibble[16][4] = {
        {0, 0, 0, 0},   {-1, 0, 0, 0},   {0, -1, 0, 0},   {-1, -1, 0, 0},
        {0, 0, -1, 0},  {-1, 0, -1, 0},  {0, -1, -1, 0},  {-1, -1, -1, 0},
        {0, 0, 0, -1},  {-1, 0, 0, -1},  {0, -1, 0, -1},  {-1, -1, 0, -1},
        {0, 0, -1, -1}, {-1, 0, -1, -1}, {0, -1, -1, -1}, {-1, -1, -1, -1}};
    _Alignas(64) int32_t valid[LX_RAY_PACKET]; /* Embree loads it as one vector */
    for (int i = 0; i < LX_RAY_PACKET; i += 4)
        memcpy(valid + i, nibble[(active >> i) & 15u], sizeof nibble[0]);
    /* written through the packet's own type, read back after the call */
    memset(packet->internal_time, 0, sizeof packet->internal_time);
    for (int i = 0; i < LX_RAY_PACKET; i++)
        packet->internal[0][i] = MASK_SHADOW;                      /* mask: shadow casters */
    memset(packet->internal[1], 0, sizeof packet->internal[1]);    /* id */
    memset(packet->internal[2], 0, sizeof packet->internal[2]);    /* flags */
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcOccluded16((const int *)valid, tr->scene, &ctx, (struct RTCRay16 *)(void *)packet);
    uint32_t blocked = 0;
#if defined(__SSE2__)
    /* whole-vector loads of what Embree just stored as vectors: scalar
     * loads of its lanes would stall on store forwarding */
    for (int i = 0; i < LX_RAY_PACKET; i += 4) {
        __m128 t = _mm_load_ps(packet->tmax + i);
        blocked |= (uint32_t)_mm_movemask_ps(_mm_cmplt_ps(t, _mm_setzero_ps())) << i;
    }
#else
    for (int i = 0; i < LX_RAY_PACKET; i++)
        blocked |= (uint32_t)(packet->tmax[i] < 0.0f) << i;
#endif
    return blocked & active;
}

bool lx_tracer_closest(const lx_tracer *tr, const lx_ray *ray, lx_hit *hit)
{
    return lx_tracer_closest_kind(tr, ray, LX_RAY_ANY, hit);
}

bool lx_tracer_closest_kind(const lx_tracer *tr, const lx_ray *ray, lx_ray_kind kind, lx_hit *hit)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    to_rtc_ray(ray, ray_mask(kind), &rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(tr->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return false;
    uint32_t g = rh.hit.geomID;
    if (hit) {
        hit->t = rh.ray.tfar;
        hit->node = g < tr->geometry_count ? tr->refs[g].node : UINT32_MAX;
        hit->mesh = g < tr->geometry_count ? tr->refs[g].mesh : UINT32_MAX;
        hit->triangle = rh.hit.primID;
        hit->u = rh.hit.u;
        hit->v = rh.hit.v;
        /* Embree's Ng: (p1 - p0) x (p2 - p0) in the world-space vertices
         * it traced (counter-clockwise = front, its manual); a mirroring
         * transform turns the winding over (glTF) */
        lx_vec3 n = lx_v3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
        float len = lx_length(n);
        bool mirrored = g < tr->geometry_count && tr->refs[g].mirrored;
        hit->normal = len > 0.0f ? lx_scale(n, (mirrored ? -1.0f : 1.0f) / len)
                                 : lx_v3(0.0f, 0.0f, 0.0f);
    }
    return true;
}

typedef struct plane_query {
    const lx_tracer *tr;
    float n[3], d, tolerance;
    float lo[3], hi[3]; /* the sphere's box */
    bool found;
} plane_query;

/* Embree's point query calls this for each triangle whose bounds meet the
 * query's: a triangle whose box meets the sphere's box and whose vertices
 * leave the plane ends the search. */
static bool off_plane_candidate(struct RTCPointQueryFunctionArguments *args)
{
    plane_query *q = args->userPtr;
    if (q->found || args->geomID >= q->tr->geometry_count)
        return false;
    RTCGeometry g = q->tr->geometries[args->geomID];
    const float *v = rtcGetGeometryBufferData(g, RTC_BUFFER_TYPE_VERTEX, 0);
    const unsigned *idx = rtcGetGeometryBufferData(g, RTC_BUFFER_TYPE_INDEX, 0);
    const unsigned *t = idx + 3 * (size_t)args->primID;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    bool off = false;
    for (int k = 0; k < 3; k++) {
        const float *p = v + 3 * (size_t)t[k];
        for (int a = 0; a < 3; a++) {
            lo[a] = p[a] < lo[a] ? p[a] : lo[a];
            hi[a] = p[a] > hi[a] ? p[a] : hi[a];
        }
        float h = q->n[0] * p[0] + q->n[1] * p[1] + q->n[2] * p[2] - q->d;
        off |= !(h <= q->tolerance && h >= -q->tolerance);
    }
    for (int a = 0; a < 3; a++)
        if (hi[a] < q->lo[a] || lo[a] > q->hi[a])
            return false;
    if (!off)
        return false;
    q->found = true;
    args->query->radius = 0.0f; /* nothing more to look for */
    return true;
}

bool lx_tracer_off_plane_near(const lx_tracer *tr, lx_vec3 centre, float radius, lx_vec3 n,
                              float d, float tolerance)
{
    plane_query q = {.tr = tr, .n = {n.x, n.y, n.z}, .d = d, .tolerance = tolerance};
    const float c[3] = {centre.x, centre.y, centre.z};
    for (int a = 0; a < 3; a++)
        q.lo[a] = c[a] - radius, q.hi[a] = c[a] + radius;
    struct RTCPointQuery query = {.x = centre.x, .y = centre.y, .z = centre.z, .radius = radius};
    struct RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(tr->scene, &query, &context, off_plane_candidate, &q);
    return q.found;
}

float lx_tracer_nearest_distance(const lx_tracer *tr, const lx_ray *ray)
{
    lx_hit h;
    return lx_tracer_closest_kind(tr, ray, LX_RAY_SHADOW, &h) ? h.t : INFINITY;
}
