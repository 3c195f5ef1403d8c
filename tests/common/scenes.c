/* Generated benchmark scenes, the bake's shadow rays regenerated, and the
 * machine report (see scenes.h). */
#define _POSIX_C_SOURCE 200809L
#include "scenes.h"
#include "core/internal.h"
#include "helpers.h"

#include <cjson/cJSON.h>
#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static const char *program = "bench";

double lx_bench_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

_Noreturn void lx_bench_die(const char *what)
{
    fprintf(stderr, "%s: %s: %s\n", program, what, lx_last_error());
    exit(1);
}

static void *xmalloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p) {
        fprintf(stderr, "%s: out of memory (%zu bytes)\n", program, size);
        exit(1);
    }
    return p;
}

/* ---- scenes -------------------------------------------------------------- */

static uint32_t rng_state = 12345u;

void lx_test_rand_seed(uint32_t seed)
{
    rng_state = seed;
}

float lx_test_rand(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) / 16777216.0f;
}

lx_mesh lx_test_spheres_mesh(const char *name, const lx_vec3 *centre, const float *radius,
                             int count, int slices, int stacks)
{
    lx_mesh m = {0};
    uint32_t vps = (uint32_t)(2 + slices * (stacks - 1));
    uint32_t tps = (uint32_t)(2 * slices * (stacks - 1));
    m.name = lx_strdup(name);
    if (!m.name)
        lx_bench_die("lx_strdup");
    m.vertex_count = vps * (uint32_t)count;
    m.triangle_count = tps * (uint32_t)count;
    m.positions = xmalloc(sizeof(lx_vec3) * m.vertex_count);
    m.normals = xmalloc(sizeof(lx_vec3) * m.vertex_count);
    m.indices = xmalloc(sizeof(uint32_t) * 3 * m.triangle_count);
    uint32_t *ix = m.indices;
    for (int s = 0; s < count; s++) {
        uint32_t base = vps * (uint32_t)s;
        lx_vec3 *p = m.positions + base, *n = m.normals + base;
        n[0] = lx_v3(0, 1, 0);
        for (int j = 1; j < stacks; j++) {
            float th = LX_PI * (float)j / (float)stacks;
            for (int i = 0; i < slices; i++) {
                float ph = 2.0f * LX_PI * (float)i / (float)slices;
                n[1 + (j - 1) * slices + i] =
                    lx_v3(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph));
            }
        }
        n[vps - 1] = lx_v3(0, -1, 0);
        for (uint32_t v = 0; v < vps; v++)
            p[v] = lx_madd(centre[s], n[v], radius[s]);
#define RING(j, i) (base + 1u + (uint32_t)((j)-1) * (uint32_t)slices + (uint32_t)((i) % slices))
        for (int i = 0; i < slices; i++) { /* top fan, outward winding */
            *ix++ = base;
            *ix++ = RING(1, i + 1);
            *ix++ = RING(1, i);
        }
        for (int j = 1; j < stacks - 1; j++)
            for (int i = 0; i < slices; i++) {
                uint32_t a = RING(j, i), b = RING(j, i + 1), c = RING(j + 1, i),
                         d = RING(j + 1, i + 1);
                *ix++ = a, *ix++ = b, *ix++ = c;
                *ix++ = b, *ix++ = d, *ix++ = c;
            }
        for (int i = 0; i < slices; i++) { /* bottom fan */
            *ix++ = base + vps - 1;
            *ix++ = RING(stacks - 1, i);
            *ix++ = RING(stacks - 1, i + 1);
        }
#undef RING
    }
    return m;
}

lx_light lx_test_point_light(int k, float size, float height, bool dynamic)
{
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "light%d", k);
    float sx = (k & 1) ? 0.27f : -0.23f, sz = (k & 2) ? 0.21f : -0.29f;
    l.position = lx_v3(sx * size, height * (1.0f + 0.1f * (float)k), sz * size);
    static const lx_vec3 colors[4] = {{1, 0.9f, 0.8f}, {0.8f, 0.9f, 1}, {1, 1, 1}, {1, 0.8f, 0.6f}};
    l.color = colors[k & 3];
    l.intensity = 40.0f * height * height; /* ~40 lux under each light */
    l.shadow = LX_SHADOW_HARD;
    l.dynamic = dynamic;
    return l;
}

lx_scene *lx_test_spheres_scene(const char *name, float size, int ground_n, int grid, int slices,
                                int stacks, bool dynamic, lx_test_scene_info *info)
{
    lx_scene *scene;
    if (lx_scene_create(name, &scene) != LX_OK)
        lx_bench_die("lx_scene_create");
    lx_test_rand_seed(12345u);
    lx_mesh ground = lx_test_plane("ground", size, 0.0f, 0.0f, 0.0f, ground_n);
    lx_test_add(scene, &ground);
    memset(info, 0, sizeof *info);
    info->ground_triangles = ground.triangle_count;
    info->triangles = ground.triangle_count;
    info->nodes = 1;
    lx_test_mesh_free(&ground);

    float spacing = size / (float)grid;
    lx_vec3 *centre = xmalloc(sizeof(lx_vec3) * (size_t)grid);
    float *radius = xmalloc(sizeof(float) * (size_t)grid);
    for (int row = 0; row < grid; row++) {
        for (int i = 0; i < grid; i++) {
            float r = spacing * (0.18f + 0.14f * lx_test_rand());
            float x =
                -size / 2 + spacing * ((float)i + 0.5f) + spacing * 0.15f * (lx_test_rand() - 0.5f);
            float z = -size / 2 + spacing * ((float)row + 0.5f) +
                      spacing * 0.15f * (lx_test_rand() - 0.5f);
            float y = r + spacing * (0.1f + 0.9f * lx_test_rand());
            centre[i] = lx_v3(x, y, z);
            radius[i] = r;
        }
        char nm[32];
        snprintf(nm, sizeof nm, "spheres%d", row);
        lx_mesh m = lx_test_spheres_mesh(nm, centre, radius, grid, slices, stacks);
        lx_test_add(scene, &m);
        info->triangles += m.triangle_count;
        info->sphere_triangles += m.triangle_count;
        info->spheres += (uint32_t)grid;
        info->nodes++;
        lx_test_mesh_free(&m);
    }
    free(centre);
    free(radius);
    for (int k = 0; k < LX_BENCH_LIGHTS; k++) {
        lx_light l = lx_test_point_light(k, size, 0.2f * size, dynamic);
        if (lx_scene_add_light(scene, &l) != LX_OK)
            lx_bench_die("lx_scene_add_light");
    }
    return scene;
}

void lx_test_grid_lights(int n, float size, float height, lx_light *out)
{
    static const lx_vec3 colors[4] = {{1, 0.9f, 0.8f}, {0.8f, 0.9f, 1}, {1, 1, 1}, {1, 0.8f, 0.6f}};
    lx_test_rand_seed(777u);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int k = j * n + i;
            lx_light l = lx_light_defaults(LX_LIGHT_POINT);
            snprintf(l.name, sizeof l.name, "grid%d", k);
            float cell = size / (float)n;
            float x = -size / 2 + cell * ((float)i + 0.25f + 0.5f * lx_test_rand());
            float z = -size / 2 + cell * ((float)j + 0.25f + 0.5f * lx_test_rand());
            float y = height * (0.9f + 0.2f * lx_test_rand());
            l.position = lx_v3(x, y, z);
            l.color = colors[k & 3];
            l.intensity = 40.0f * y * y; /* ~40 lux straight below */
            l.shadow = LX_SHADOW_HARD;
            out[k] = l;
        }
}

/* ---- glTF writing ---------------------------------------------------------- */

typedef struct glb_bin {
    unsigned char *data;
    size_t len, cap;
} glb_bin;

static size_t bin_append(glb_bin *b, const void *src, size_t n)
{
    while (b->len % 4)
        b->len++; /* every view starts 4-aligned (zeros: the buffer is calloc'd) */
    size_t need = b->len + n;
    if (need > b->cap) {
        size_t cap = b->cap ? b->cap : 1 << 20;
        while (cap < need + 4)
            cap *= 2;
        unsigned char *d = realloc(b->data, cap);
        if (!d)
            lx_bench_die("realloc");
        memset(d + b->cap, 0, cap - b->cap);
        b->data = d;
        b->cap = cap;
    }
    size_t at = b->len;
    memcpy(b->data + at, src, n);
    b->len = need;
    return at;
}

/* One bufferView and accessor over n bytes of src; returns the accessor. */
static int glb_accessor(cJSON *views, cJSON *accessors, glb_bin *b, const void *src, size_t bytes,
                        uint32_t count, int component, const char *type, int target)
{
    size_t at = bin_append(b, src, bytes);
    cJSON *v = cJSON_CreateObject();
    cJSON_AddNumberToObject(v, "buffer", 0);
    cJSON_AddNumberToObject(v, "byteOffset", (double)at);
    cJSON_AddNumberToObject(v, "byteLength", (double)bytes);
    cJSON_AddNumberToObject(v, "target", target);
    cJSON_AddItemToArray(views, v);
    cJSON *a = cJSON_CreateObject();
    cJSON_AddNumberToObject(a, "bufferView", cJSON_GetArraySize(views) - 1);
    cJSON_AddNumberToObject(a, "componentType", component);
    cJSON_AddNumberToObject(a, "count", count);
    cJSON_AddStringToObject(a, "type", type);
    cJSON_AddItemToArray(accessors, a);
    return cJSON_GetArraySize(accessors) - 1;
}

static void put_le32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8), p[2] = (unsigned char)(v >> 16),
    p[3] = (unsigned char)(v >> 24);
}

void lx_test_write_glb(const lx_scene *scene, const char *path)
{
    enum { FLOAT = 5126, UINT = 5125, ARRAY = 34962, ELEMENTS = 34963 };
    cJSON *root = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    cJSON_AddStringToObject(asset, "generator", "luxel tests/common/scenes.c");
    cJSON_AddNumberToObject(root, "scene", 0);
    cJSON *scenes = cJSON_AddArrayToObject(root, "scenes");
    cJSON *sc = cJSON_CreateObject();
    cJSON *roots = cJSON_AddArrayToObject(sc, "nodes");
    cJSON_AddItemToArray(scenes, sc);
    cJSON *nodes = cJSON_AddArrayToObject(root, "nodes");
    cJSON *meshes = cJSON_AddArrayToObject(root, "meshes");
    cJSON *accessors = cJSON_AddArrayToObject(root, "accessors");
    cJSON *views = cJSON_AddArrayToObject(root, "bufferViews");
    glb_bin bin = {0};
    for (uint32_t n = 0; n < scene->node_count; n++) {
        const lx_node *node = &scene->nodes[n];
        cJSON *mesh = cJSON_CreateObject();
        cJSON_AddStringToObject(mesh, "name", node->name);
        cJSON *prims = cJSON_AddArrayToObject(mesh, "primitives");
        for (uint32_t k = 0; k < node->mesh_count; k++) {
            const lx_mesh *m = &scene->meshes[node->meshes[k]];
            cJSON *prim = cJSON_CreateObject();
            cJSON *attr = cJSON_AddObjectToObject(prim, "attributes");
            int pos = glb_accessor(views, accessors, &bin, m->positions,
                                   sizeof(lx_vec3) * m->vertex_count, m->vertex_count, FLOAT,
                                   "VEC3", ARRAY);
            lx_vec3 lo = m->positions[0], hi = lo; /* POSITION needs its bounds */
            for (uint32_t v = 1; v < m->vertex_count; v++) {
                lo = lx_v3(fminf(lo.x, m->positions[v].x), fminf(lo.y, m->positions[v].y),
                           fminf(lo.z, m->positions[v].z));
                hi = lx_v3(fmaxf(hi.x, m->positions[v].x), fmaxf(hi.y, m->positions[v].y),
                           fmaxf(hi.z, m->positions[v].z));
            }
            cJSON *acc = cJSON_GetArrayItem(accessors, pos);
            cJSON_AddItemToObject(acc, "min",
                                  cJSON_CreateFloatArray((float[]){lo.x, lo.y, lo.z}, 3));
            cJSON_AddItemToObject(acc, "max",
                                  cJSON_CreateFloatArray((float[]){hi.x, hi.y, hi.z}, 3));
            cJSON_AddNumberToObject(attr, "POSITION", pos);
            if (m->normals)
                cJSON_AddNumberToObject(attr, "NORMAL",
                                        glb_accessor(views, accessors, &bin, m->normals,
                                                     sizeof(lx_vec3) * m->vertex_count,
                                                     m->vertex_count, FLOAT, "VEC3", ARRAY));
            for (int u = 0; u < LX_MAX_UV_SETS; u++)
                if (m->uv[u])
                    cJSON_AddNumberToObject(attr, u ? "TEXCOORD_1" : "TEXCOORD_0",
                                            glb_accessor(views, accessors, &bin, m->uv[u],
                                                         sizeof(lx_vec2) * m->vertex_count,
                                                         m->vertex_count, FLOAT, "VEC2", ARRAY));
            cJSON_AddNumberToObject(prim, "indices",
                                    glb_accessor(views, accessors, &bin, m->indices,
                                                 sizeof(uint32_t) * 3 * m->triangle_count,
                                                 3 * m->triangle_count, UINT, "SCALAR", ELEMENTS));
            cJSON_AddItemToArray(prims, prim);
        }
        cJSON_AddItemToArray(meshes, mesh);
        cJSON *nd = cJSON_CreateObject();
        cJSON_AddStringToObject(nd, "name", node->name);
        cJSON_AddNumberToObject(nd, "mesh", n);
        cJSON_AddItemToArray(nodes, nd);
        cJSON_AddItemToArray(roots, cJSON_CreateNumber(n));
    }
    while (bin.len % 4)
        bin.len++;
    cJSON *buffers = cJSON_AddArrayToObject(root, "buffers");
    cJSON *buf = cJSON_CreateObject();
    cJSON_AddNumberToObject(buf, "byteLength", (double)bin.len);
    cJSON_AddItemToArray(buffers, buf);
    char *json = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    if (!json)
        lx_bench_die("cJSON_PrintUnformatted");
    size_t jlen = strlen(json), jpad = (jlen + 3) & ~(size_t)3;
    unsigned char head[20];
    memcpy(head, "glTF", 4);
    put_le32(head + 4, 2);
    put_le32(head + 8, (uint32_t)(12 + 8 + jpad + 8 + bin.len));
    put_le32(head + 12, (uint32_t)jpad);
    memcpy(head + 16, "JSON", 4);
    unsigned char bin_head[8];
    put_le32(bin_head, (uint32_t)bin.len);
    memcpy(bin_head + 4, "BIN\0", 4);
    FILE *f = fopen(path, "wb");
    bool ok = f && fwrite(head, 1, 20, f) == 20 && fwrite(json, 1, jlen, f) == jlen &&
              fwrite("   ", 1, jpad - jlen, f) == jpad - jlen && fwrite(bin_head, 1, 8, f) == 8 &&
              fwrite(bin.data, 1, bin.len, f) == bin.len;
    ok = f && fclose(f) == 0 && ok;
    free(json);
    free(bin.data);
    if (!ok) {
        fprintf(stderr, "%s: cannot write %s\n", program, path);
        exit(1);
    }
}

void lx_test_write_lights_json(const lx_light *lights, uint32_t count, const char *path)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *list = cJSON_AddArrayToObject(root, "lights");
    for (uint32_t i = 0; i < count; i++) {
        const lx_light *l = &lights[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", l->name);
        cJSON_AddStringToObject(o, "type", "point");
        cJSON_AddItemToObject(
            o, "position",
            cJSON_CreateFloatArray((float[]){l->position.x, l->position.y, l->position.z}, 3));
        cJSON_AddItemToObject(
            o, "color", cJSON_CreateFloatArray((float[]){l->color.x, l->color.y, l->color.z}, 3));
        cJSON_AddNumberToObject(o, "intensity", l->intensity);
        cJSON_AddStringToObject(o, "unit", "cd");
        if (l->range > 0.0f)
            cJSON_AddNumberToObject(o, "range", l->range);
        cJSON_AddStringToObject(o, "shadow",
                                l->shadow == LX_SHADOW_NONE   ? "none"
                                : l->shadow == LX_SHADOW_BLUR ? "blur"
                                                              : "hard");
        cJSON_AddBoolToObject(o, "dynamic", l->dynamic);
        cJSON_AddItemToArray(list, o);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    FILE *f = text ? fopen(path, "w") : NULL;
    bool ok = f && fputs(text, f) >= 0;
    ok = f && fclose(f) == 0 && ok;
    free(text);
    if (!ok) {
        fprintf(stderr, "%s: cannot write %s\n", program, path);
        exit(1);
    }
}

/* ---- the bake's shadow rays ---------------------------------------------- */

lx_ray lx_bench_shadow_ray(float base_bias, lx_vec3 p, lx_vec3 ng, const lx_light_eval *e)
{
    lx_vec3 side = lx_dot(ng, e->to_light) >= 0.0f ? ng : lx_neg(ng);
    float bias = base_bias + 4e-6f * lx_max_abs_component(p);
    lx_ray r;
    r.origin = lx_madd(p, side, bias);
    r.dir = e->to_light;
    r.tmin = 0.0f;
    r.tmax = isfinite(e->distance) ? e->distance - 2.0f * bias : INFINITY;
    if (r.tmax < 0.0f)
        r.tmax = 0.0f;
    return r;
}

/* The scale-aware bias lx_baker_create picks (1e-5 x scene diagonal). */
static float auto_bias(const lx_scene *scene)
{
    lx_vec3 lo, hi;
    float diag = lx_scene_bounds(scene, &lo, &hi) ? lx_length(lx_sub(hi, lo)) : 1.0f;
    if (!(diag > 0.0f))
        diag = 1.0f;
    return 1e-5f * diag;
}

void lx_bench_rays_build(const lx_baker *b, const lx_scene *scene, lx_bench_rays *rs)
{
    enum { TILE = LX_BENCH_TILE };
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, 0);
    const uint8_t *mask = lx_baker_mask(b, 0);
    int w = info->width, h = info->height;
    int tx_n = (w + TILE - 1) / TILE, ty_n = (h + TILE - 1) / TILE;
    uint32_t L = lx_baker_light_count(b);
    memset(rs, 0, sizeof *rs);
    rs->tiles = tx_n * ty_n;
    rs->lights = (int)L;
    rs->bias = auto_bias(scene);
    size_t cap = (size_t)info->used_texels * L + 1;
    rs->rays = xmalloc(sizeof(lx_ray) * cap);
    rs->illuminance = xmalloc(sizeof(lx_vec3) * cap);
    rs->pixel = xmalloc(sizeof(uint32_t) * cap);
    rs->batch = xmalloc(sizeof(uint32_t) * ((size_t)rs->tiles * L + 1));
    rs->texel = xmalloc(sizeof(lx_texel_sample) * ((size_t)info->used_texels + 1));
    rs->tile_texel = xmalloc(sizeof(uint32_t) * ((size_t)rs->tiles + 1));
    uint64_t n = 0;
    uint32_t used = 0;
    lx_texel_sample ts[TILE * TILE];
    uint32_t px[TILE * TILE];
    for (int ty = 0; ty < ty_n; ty++)
        for (int tx = 0; tx < tx_n; tx++) {
            int cnt = 0;
            for (int y = ty * TILE; y < (ty + 1) * TILE && y < h; y++)
                for (int x = tx * TILE; x < (tx + 1) * TILE && x < w; x++)
                    if (mask[(size_t)y * w + x] && lx_baker_texel(b, 0, x, y, &ts[cnt]))
                        px[cnt++] = (uint32_t)(y * w + x);
            int tile = ty * tx_n + tx;
            rs->tile_texel[tile] = used;
            memcpy(rs->texel + used, ts, sizeof(lx_texel_sample) * (size_t)cnt);
            used += (uint32_t)cnt;
            for (uint32_t l = 0; l < L; l++) {
                rs->batch[(size_t)tile * L + l] = (uint32_t)n;
                const lx_light *light = lx_baker_light(b, l);
                for (int k = 0; k < cnt; k++) {
                    lx_light_eval e;
                    rs->samples++;
                    if (!lx_light_evaluate(light, ts[k].position, ts[k].normal, &e)) {
                        rs->behind++;
                        continue;
                    }
                    rs->rays[n] =
                        lx_bench_shadow_ray(rs->bias, ts[k].position, ts[k].geometric_normal, &e);
                    rs->illuminance[n] = e.illuminance;
                    rs->pixel[n] = px[k];
                    n++;
                }
            }
        }
    rs->batch[(size_t)rs->tiles * L] = (uint32_t)n;
    rs->tile_texel[rs->tiles] = used;
    rs->count = n;
}

void lx_bench_rays_free(lx_bench_rays *rs)
{
    free(rs->rays);
    free(rs->illuminance);
    free(rs->pixel);
    free(rs->batch);
    free(rs->texel);
    free(rs->tile_texel);
    memset(rs, 0, sizeof *rs);
}

double lx_bench_trace(const lx_tracer *tr, const lx_bench_rays *rs, lx_bench_trace_mode mode,
                      int threads, uint8_t *occluded)
{
    const int L = rs->lights;
    double t0 = lx_bench_now();
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int tile = 0; tile < rs->tiles; tile++)
        for (int l = 0; l < L; l++) {
            uint32_t s = rs->batch[(size_t)tile * L + l], e = rs->batch[(size_t)tile * L + l + 1];
            if (mode == LX_BENCH_SINGLE)
                for (uint32_t j = s; j < e; j++)
                    occluded[j] = lx_tracer_occluded(tr, &rs->rays[j]);
            else if (e > s)
                lx_tracer_occluded_batch(tr, rs->rays + s, e - s, mode == LX_BENCH_BATCH,
                                         occluded + s);
        }
    return lx_bench_now() - t0;
}

/* ---- raw Embree on a flat BVH --------------------------------------------- */

/* One Embree scene holding every triangle in world space (what a user of
 * raw Embree would build for a static bake), same flags as the tracer. */
RTCScene lx_bench_flat_scene(RTCDevice dev, const lx_scene *scene)
{
    RTCScene s = rtcNewScene(dev);
    rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
    uint32_t nv = 0, nt = 0;
    for (uint32_t n = 0; n < scene->node_count; n++)
        for (uint32_t k = 0; k < scene->nodes[n].mesh_count; k++) {
            const lx_mesh *m = &scene->meshes[scene->nodes[n].meshes[k]];
            nv += m->vertex_count;
            nt += m->triangle_count;
        }
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       3 * sizeof(float), nv);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), nt);
    uint32_t vb = 0, tb = 0;
    for (uint32_t n = 0; n < scene->node_count; n++)
        for (uint32_t k = 0; k < scene->nodes[n].mesh_count; k++) {
            const lx_mesh *m = &scene->meshes[scene->nodes[n].meshes[k]];
            for (uint32_t i = 0; i < m->vertex_count; i++) {
                lx_vec3 p = lx_mat4_point(&scene->nodes[n].world, m->positions[i]);
                v[3 * (vb + i)] = p.x, v[3 * (vb + i) + 1] = p.y, v[3 * (vb + i) + 2] = p.z;
            }
            for (uint32_t i = 0; i < 3 * m->triangle_count; i++)
                ix[3 * tb + i] = vb + m->indices[i];
            vb += m->vertex_count;
            tb += m->triangle_count;
        }
    rtcCommitGeometry(g);
    rtcAttachGeometry(s, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(s);
    return s;
}

static void to_rtc(const lx_ray *r, struct RTCRay *o)
{
    o->org_x = r->origin.x, o->org_y = r->origin.y, o->org_z = r->origin.z;
    o->dir_x = r->dir.x, o->dir_y = r->dir.y, o->dir_z = r->dir.z;
    o->tnear = r->tmin, o->tfar = r->tmax, o->time = 0.0f;
    o->mask = 0xFFFFFFFFu, o->id = 0, o->flags = 0;
}

/* Every ray once straight through Embree (rtcOccluded1 or coherent
 * rtcOccluded1M), same tiles and schedule; returns seconds. */
static double flat_run(bool stream, RTCScene flat, const lx_bench_rays *rs, int threads,
                       uint8_t *occluded)
{
    const int L = rs->lights;
    double t0 = lx_bench_now();
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int tile = 0; tile < rs->tiles; tile++) {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        if (stream)
            ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        struct RTCRay buf[LX_BENCH_TILE * LX_BENCH_TILE];
        for (int l = 0; l < L; l++) {
            uint32_t s = rs->batch[(size_t)tile * L + l], e = rs->batch[(size_t)tile * L + l + 1];
            uint32_t n = e - s;
            const lx_ray *r = rs->rays + s;
            uint8_t *o = occluded + s;
            if (!stream) {
                for (uint32_t j = 0; j < n; j++) {
                    to_rtc(&r[j], &buf[0]);
                    rtcOccluded1(flat, &ctx, &buf[0]);
                    o[j] = buf[0].tfar < 0.0f;
                }
            } else if (n) {
                for (uint32_t j = 0; j < n; j++)
                    to_rtc(&r[j], &buf[j]);
                rtcOccluded1M(flat, &ctx, buf, n, sizeof(struct RTCRay));
                for (uint32_t j = 0; j < n; j++)
                    o[j] = buf[j].tfar < 0.0f;
            }
        }
    }
    return lx_bench_now() - t0;
}

/* Every ray once through Embree's packet calls rtcOccluded4/8/16 (width
 * w), the rays of one tile toward one light in packets of w with a valid
 * mask on the last; same tiles, schedule and threads as flat_run. */
#define PACKET_RUN(W)                                                                              \
    static double packet_run##W(RTCScene flat, const lx_bench_rays *rs, int threads,               \
                                uint8_t *occluded)                                                 \
    {                                                                                              \
        const int L = rs->lights;                                                                  \
        double t0 = lx_bench_now();                                                                \
        _Pragma("omp parallel for schedule(dynamic, 4) num_threads(threads)") for (int tile = 0;   \
                                                                                   tile <          \
                                                                                   rs->tiles;      \
                                                                                   tile++)         \
        {                                                                                          \
            struct RTCIntersectContext ctx;                                                        \
            rtcInitIntersectContext(&ctx);                                                         \
            ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;                                       \
            struct RTCRay##W pk;                                                                   \
            int valid[W];                                                                          \
            for (int l = 0; l < L; l++) {                                                          \
                uint32_t s = rs->batch[(size_t)tile * L + l];                                      \
                uint32_t e = rs->batch[(size_t)tile * L + l + 1];                                  \
                for (uint32_t b = s; b < e; b += W) {                                              \
                    for (int j = 0; j < W; j++) {                                                  \
                        const lx_ray *r = &rs->rays[b + j < e ? b + j : s];                        \
                        valid[j] = b + j < e ? -1 : 0;                                             \
                        pk.org_x[j] = r->origin.x, pk.org_y[j] = r->origin.y;                      \
                        pk.org_z[j] = r->origin.z, pk.tnear[j] = r->tmin;                          \
                        pk.dir_x[j] = r->dir.x, pk.dir_y[j] = r->dir.y, pk.dir_z[j] = r->dir.z;    \
                        pk.time[j] = 0.0f, pk.tfar[j] = r->tmax, pk.mask[j] = 0xFFFFFFFFu;         \
                        pk.id[j] = 0, pk.flags[j] = 0;                                             \
                    }                                                                              \
                    rtcOccluded##W(valid, flat, &ctx, &pk);                                        \
                    for (int j = 0; j < W && b + j < e; j++)                                       \
                        occluded[b + j] = pk.tfar[j] < 0.0f;                                       \
                }                                                                                  \
            }                                                                                      \
        }                                                                                          \
        return lx_bench_now() - t0;                                                                \
    }
PACKET_RUN(4)
PACKET_RUN(8)
PACKET_RUN(16)

/* rtcOccluded16 on 4x4 blocks of full 8x8 tiles (the others as rows) */
static double packet_run16q(RTCScene flat, const lx_bench_rays *rs, int threads, uint8_t *occluded)
{
    const int L = rs->lights;
    double t0 = lx_bench_now();
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
    for (int tile = 0; tile < rs->tiles; tile++) {
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
        struct RTCRay16 pk;
        int valid[16];
        for (int l = 0; l < L; l++) {
            uint32_t s = rs->batch[(size_t)tile * L + l];
            uint32_t e = rs->batch[(size_t)tile * L + l + 1];
            bool full = e - s == 64;
            for (uint32_t b = 0; b < e - s; b += 16) {
                uint32_t idx[16];
                for (int j = 0; j < 16; j++) {
                    uint32_t q = b / 16;
                    idx[j] = full ? ((q / 2) * 4 + j / 4) * 8 + (q % 2) * 4 + j % 4 : b + j;
                    valid[j] = idx[j] < e - s ? -1 : 0;
                    const lx_ray *r = &rs->rays[s + (idx[j] < e - s ? idx[j] : 0)];
                    pk.org_x[j] = r->origin.x, pk.org_y[j] = r->origin.y;
                    pk.org_z[j] = r->origin.z, pk.tnear[j] = r->tmin;
                    pk.dir_x[j] = r->dir.x, pk.dir_y[j] = r->dir.y, pk.dir_z[j] = r->dir.z;
                    pk.time[j] = 0.0f, pk.tfar[j] = r->tmax, pk.mask[j] = 0xFFFFFFFFu;
                    pk.id[j] = 0, pk.flags[j] = 0;
                }
                rtcOccluded16(valid, flat, &ctx, &pk);
                for (int j = 0; j < 16; j++)
                    if (valid[j])
                        occluded[s + idx[j]] = pk.tfar[j] < 0.0f;
            }
        }
    }
    return lx_bench_now() - t0;
}

double lx_bench_flat_trace(lx_bench_flat_mode mode, RTCScene flat, const lx_bench_rays *rs,
                           int threads, uint8_t *occluded)
{
    switch (mode) {
    case LX_FLAT_1:
        return flat_run(false, flat, rs, threads, occluded);
    case LX_FLAT_1M:
        return flat_run(true, flat, rs, threads, occluded);
    case LX_FLAT_PACKET4:
        return packet_run4(flat, rs, threads, occluded);
    case LX_FLAT_PACKET8:
        return packet_run8(flat, rs, threads, occluded);
    case LX_FLAT_PACKET16:
        return packet_run16(flat, rs, threads, occluded);
    default:
        return packet_run16q(flat, rs, threads, occluded);
    }
}

const char *const lx_bench_flat_names[LX_FLAT_MODES] = {
    "Embree flat BVH, rtcOccluded1",  "Embree flat BVH, rtcOccluded1M coh.",
    "Embree flat BVH, rtcOccluded4",  "Embree flat BVH, rtcOccluded8",
    "Embree flat BVH, rtcOccluded16", "Embree flat BVH, rtcOccluded16 4x4"};

/* ---- report -------------------------------------------------------------- */

static void cpu_model(char *out, size_t size)
{
    snprintf(out, size, "unknown CPU");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f)
        return;
    char line[512];
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "model name", 10)) {
            char *c = strchr(line, ':');
            if (c) {
                c++;
                while (*c == ' ' || *c == '\t')
                    c++;
                c[strcspn(c, "\n")] = '\0';
                snprintf(out, size, "%s", c);
            }
            break;
        }
    fclose(f);
}

const char *lx_bench_load(char *buf, size_t size)
{
    snprintf(buf, size, "?");
    FILE *f = fopen("/proc/loadavg", "r");
    if (!f)
        return buf;
    double l1;
    if (fscanf(f, "%lf", &l1) == 1)
        snprintf(buf, size, "%.2f", l1);
    fclose(f);
    return buf;
}

void lx_bench_header(const char *prog, int threads)
{
    program = prog;
    char cpu[256], load[32];
    cpu_model(cpu, sizeof cpu);
    printf("%s  machine: %s, %ld logical CPUs, %d threads, Embree %s\n", prog, cpu,
           sysconf(_SC_NPROCESSORS_ONLN), threads, RTC_VERSION_STRING);
    printf("load average (1 min) at start: %s (other processes share these cores)\n",
           lx_bench_load(load, sizeof load));
}

const char *lx_bench_si(double v, char *buf)
{
    if (v >= 1e9)
        snprintf(buf, 32, "%.2f G", v / 1e9);
    else if (v >= 1e6)
        snprintf(buf, 32, "%.2f M", v / 1e6);
    else if (v >= 1e3)
        snprintf(buf, 32, "%.2f k", v / 1e3);
    else
        snprintf(buf, 32, "%.2f ", v);
    return buf;
}
