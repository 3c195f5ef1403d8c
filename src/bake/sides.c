/* Which face of a double-sided surface a lightmap holds. A glTF material
 * with doubleSided is lit and drawn on both faces (glTF 2.0 spec, 3.9.5:
 * the back face's normal reversed), but a texel holds one value. Unity's
 * progressive lightmapper and Bakery bake the front face (the winding's)
 * only: their "double-sided GI" and "backface GI" settings change how
 * other texels' rays see the back, not what a texel holds; three.js draws
 * that one lightmap on both faces. A surface modelled facing away from
 * where it is seen - a pond's water or a stepping stone whose faces point
 * down, an inside-out closed mesh - then bakes its hidden face, black
 * where a viewer sees it lit.
 *
 * luxel bakes the front unless no viewer can be in front of it. Per
 * triangle of a double-sided material placed by a node with a lightmap,
 * SIDE_POINTS points (the centroid and three toward the corners) each cast
 * SIDE_RAYS stratified cosine-weighted camera rays from each face; a ray
 * reaches open space when it escapes the scene, or meets a front face
 * farther than SIDE_REACH (1 m): a back face is the inside of a solid
 * at any distance, a surface nearer than that closes the face in (a
 * pond's water 20 cm above its bed, a lily pad lying on the water). When
 * at most a tenth of the front's rays reach open space and at least a
 * quarter of the back's do, the triangle's texels bake its back: their
 * normals (shading and geometric, their object-space copies, their
 * supersampling points) are turned over, as glTF turns them for the back
 * face, and their terminator lift is dropped. A room of single-plane
 * walls facing in keeps its fronts (the room is open space); a floor
 * whose front is covered by furniture at arm's length while nothing is
 * under the floor turns over (an unseen patch either way). The rays
 * depend on the triangle alone: any thread count decides the same. */
#include "bake_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#define SIDE_KEY 0x7100u
#define SIDE_POINTS 4u
#define SIDE_RAYS 8u /* a point and face: 4 x 2 strata */
#define SIDE_FRONT_OPEN_MAX (SIDE_POINTS * SIDE_RAYS / 10u)
#define SIDE_BACK_OPEN_MIN (SIDE_POINTS * SIDE_RAYS / 4u)
/* metres within which a front face closes a face in */
#define SIDE_REACH 1.0f

static int range_cmp(const void *a, const void *b)
{
    const lx_side_range *x = a, *y = b;
    if (x->node != y->node)
        return x->node < y->node ? -1 : 1;
    return x->mesh < y->mesh ? -1 : x->mesh > y->mesh;
}

/* What a ray from p along unit d meets: ESCAPED (nothing), FAR (a front
 * face beyond SIDE_REACH), or CLOSED (a front face within it, or a back
 * face: the inside of a solid). */
enum { CLOSED, FAR, ESCAPED };
static int ray_meets(const lx_baker *b, lx_vec3 p, lx_vec3 d)
{
    lx_ray ray = {.origin = p, .dir = d, .tmin = 0.0f, .tmax = INFINITY};
    lx_hit h;
    if (!lx_tracer_closest_kind(b->tracer, &ray, LX_RAY_CAMERA, &h))
        return ESCAPED;
    return lx_dot(d, h.normal) < 0.0f && h.t > SIDE_REACH ? FAR : CLOSED;
}

/* The luminance of the direct light a face at p with unit normal n
 * receives: the static lights (their shadows by one ray each) and the
 * sky's unshadowed irradiance times the share of the face's rays that
 * escaped (its sky visibility). */
static double direct_light(const lx_baker *b, lx_vec3 p, lx_vec3 n, float sky_share)
{
    double sum = 0.0;
    for (uint32_t l = 0; l < b->light_count; l++) {
        const lx_light *light = &b->lights[l];
        lx_light_eval e;
        if (light->dynamic || !lx_light_evaluate(light, p, n, &e))
            continue;
        if (light->shadow != LX_SHADOW_NONE) {
            lx_ray ray = {.origin = p, .dir = e.to_light, .tmin = 0.0f, .tmax = e.distance};
            if (lx_tracer_occluded(b->tracer, &ray))
                continue;
        }
        const float rgb[3] = {e.illuminance.x, e.illuminance.y, e.illuminance.z};
        sum += lx_luminance(rgb);
    }
    if (b->has_sky) {
        float irr[3];
        lx_sh_irradiance(&b->sky_sh, n, irr);
        double v = lx_luminance(irr);
        sum += v > 0.0 ? v * sky_share : 0.0;
    }
    return sum;
}

/* Whether triangle t of mesh m placed by node n (key: its index among the
 * decided triangles) bakes its back face. */
static bool turns_over(const lx_baker *b, const lx_scene *scene, uint32_t n, const lx_mesh *m,
                       uint32_t t, uint32_t key)
{
    const lx_mat4 *w = &scene->nodes[n].world;
    const uint32_t *i = &m->indices[3 * (size_t)t];
    lx_vec3 p[3] = {lx_mat4_point(w, m->positions[i[0]]), lx_mat4_point(w, m->positions[i[1]]),
                    lx_mat4_point(w, m->positions[i[2]])};
    lx_vec3 ng = lx_cross(lx_sub(p[1], p[0]), lx_sub(p[2], p[0]));
    float len = lx_length(ng);
    if (!(len > 0.0f) || !isfinite(len))
        return false;
    /* the winding's front; a mirroring transform turns it around (glTF) */
    ng = lx_scale(ng, (lx_mat4_det3(w) < 0.0f ? -1.0f : 1.0f) / len);
    static const float bary[SIDE_POINTS][3] = {{1.0f / 3.0f, 1.0f / 3.0f, 1.0f / 3.0f},
                                               {2.0f / 3.0f, 1.0f / 6.0f, 1.0f / 6.0f},
                                               {1.0f / 6.0f, 2.0f / 3.0f, 1.0f / 6.0f},
                                               {1.0f / 6.0f, 1.0f / 6.0f, 2.0f / 3.0f}};
    uint32_t open[2] = {0, 0}, escaped[2] = {0, 0}, point_escaped[2][SIDE_POINTS];
    lx_vec3 origin[2][SIDE_POINTS];
    for (uint32_t face = 0; face < 2; face++) {
        lx_vec3 n_face = face ? lx_neg(ng) : ng;
        lx_vec3 tan = lx_normalize(lx_perpendicular(n_face)), bt = lx_cross(n_face, tan);
        for (uint32_t q = 0; q < SIDE_POINTS; q++) {
            lx_vec3 o = lx_add(lx_add(lx_scale(p[0], bary[q][0]), lx_scale(p[1], bary[q][1])),
                               lx_scale(p[2], bary[q][2]));
            o = lx_madd(o, n_face, b->bias + 4e-6f * lx_max_abs_component(o));
            origin[face][q] = o;
            point_escaped[face][q] = 0;
            for (uint32_t k = 0; k < SIDE_RAYS; k++) {
                lx_vec3 d =
                    lx_cosine_direction(tan, bt, n_face, key, 2 * q + face, k, 4, 2, SIDE_KEY);
                int r = ray_meets(b, o, d);
                open[face] += r != CLOSED;
                point_escaped[face][q] += r == ESCAPED;
            }
            escaped[face] += point_escaped[face][q];
        }
    }
    const uint32_t all = SIDE_POINTS * SIDE_RAYS;
    /* the front closed in, the back open: no viewer can be in front */
    if (open[0] <= all / 10)
        return open[1] >= all / 4;
    /* a room's inside (its rays meet its walls) keeps its front */
    if (escaped[0] < all / 4 || escaped[1] < all / 4)
        return false;
    /* both faces look into the open world (a ground plane over nothing, a
     * sign, a leaf): the one the light reaches, by a margin */
    double light[2] = {0.0, 0.0};
    for (uint32_t face = 0; face < 2; face++)
        for (uint32_t q = 0; q < SIDE_POINTS; q++)
            light[face] += direct_light(b, origin[face][q], face ? lx_neg(ng) : ng,
                                        (float)point_escaped[face][q] / (float)SIDE_RAYS);
    return light[1] > 2.0 * light[0];
}

lx_status lx_bake_sides(lx_baker *b, const lx_scene *scene)
{
    b->mesh_double_sided = calloc(scene->mesh_count + 1, 1);
    b->double_sided_mesh_count = scene->mesh_count;
    if (!b->mesh_double_sided)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for double-sided materials", scene->path);
    bool any = false;
    for (uint32_t m = 0; m < scene->mesh_count; m++) {
        b->mesh_double_sided[m] = lx_mesh_material(scene, &scene->meshes[m])->double_sided;
        any |= b->mesh_double_sided[m] != 0;
    }
    b->sides_decided = true;
    if (!any || b->desc.double_sided == LX_DOUBLE_SIDED_FRONT)
        return LX_OK;
    /* the (node, mesh) pairs to decide: double-sided meshes of nodes with
     * a lightmap */
    uint32_t count = 0;
    size_t triangles = 0;
    for (int pass = 0; pass < 2; pass++) {
        count = 0;
        triangles = 0;
        for (uint32_t n = 0; n < scene->node_count; n++) {
            const lx_node *node = &scene->nodes[n];
            if (node->bake.no_lightmap || b->node_map[n] == UINT32_MAX)
                continue;
            for (uint32_t k = 0; k < node->mesh_count; k++) {
                uint32_t mi = node->meshes[k];
                if (mi >= scene->mesh_count || !b->mesh_double_sided[mi])
                    continue;
                if (pass)
                    b->side_ranges[count] = (lx_side_range){n, mi, triangles};
                count++;
                triangles += scene->meshes[mi].triangle_count;
            }
        }
        if (!pass) {
            if (count == 0)
                return LX_OK;
            b->side_ranges = malloc(sizeof(lx_side_range) * count);
            b->side_flip = calloc(triangles + 1, 1);
            if (!b->side_ranges || !b->side_flip)
                return lx_fail(LX_ERR_NOMEM,
                               "%s: out of memory deciding the faces of %zu double-sided "
                               "triangles",
                               scene->path, triangles);
        }
    }
    b->side_range_count = count;
    qsort(b->side_ranges, count, sizeof *b->side_ranges, range_cmp);
    uint64_t turned = 0;
    for (uint32_t r = 0; r < count; r++) {
        const lx_side_range *range = &b->side_ranges[r];
        const lx_mesh *m = &scene->meshes[range->mesh];
        int64_t nt = m->triangle_count;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : turned)                           \
    num_threads(lx_thread_count(b->desc.threads))
        for (int64_t t = 0; t < nt; t++) {
            size_t at = range->first + (size_t)t;
            if (turns_over(b, scene, range->node, m, (uint32_t)t, (uint32_t)at)) {
                b->side_flip[at] = 1;
                turned++;
            }
        }
    }
    if (turned)
        lx_log(LX_LOG_INFO,
               "%s: %llu of %zu double-sided triangles bake their back face (their front "
               "closed in, or unlit where both faces look into the open)",
               scene->path, (unsigned long long)turned, triangles);
    return LX_OK;
}

bool lx_bake_side_flipped(const lx_baker *b, uint32_t node, uint32_t mesh, uint32_t t)
{
    if (!b->side_range_count)
        return false;
    lx_side_range key = {node, mesh, 0};
    const lx_side_range *r =
        bsearch(&key, b->side_ranges, b->side_range_count, sizeof key, range_cmp);
    return r && b->side_flip[r->first + t];
}

void lx_bake_sides_apply(const lx_baker *b, lx_lightmap *map)
{
    if (!b->side_range_count || !map->loaded || !map->texels)
        return;
    uint32_t used = map->info.used_texels;
    for (uint32_t i = 0; i < used; i++) {
        const lx_texel *tx = &map->texels[i];
        if (!lx_bake_side_flipped(b, tx->node, tx->mesh, tx->triangle))
            continue;
        lx_vec3 before = map->world_geometric_normal[i];
        map->world_normal[i] = lx_neg(map->world_normal[i]);
        map->world_geometric_normal[i] = lx_neg(before);
        if (map->object_normal) {
            map->object_normal[i] = lx_neg(map->object_normal[i]);
            map->object_geometric_normal[i] = lx_neg(map->object_geometric_normal[i]);
        }
        /* the lift reaches the smooth surface on the front's side */
        if (map->lift)
            map->lift[i] = lx_v3(0.0f, 0.0f, 0.0f);
        if (map->object_lift)
            map->object_lift[i] = lx_v3(0.0f, 0.0f, 0.0f);
        if (map->horizon) {
            map->horizon[i].n = lx_neg(map->horizon[i].n);
            map->horizon[i].b = lx_neg(map->horizon[i].b);
        }
        /* the texel's points bake the texel's face (a point on a
         * neighbouring triangle facing the same way turns with it) */
        for (uint32_t s = 0; s < map->sub_count; s++) {
            size_t at = (size_t)s * used + i;
            if (!(lx_dot(map->sub_geometric_normal[at], before) > 0.0f))
                continue;
            map->sub_normal[at] = lx_neg(map->sub_normal[at]);
            map->sub_geometric_normal[at] = lx_neg(map->sub_geometric_normal[at]);
            if (map->sub_object_normal) {
                map->sub_object_normal[at] = lx_neg(map->sub_object_normal[at]);
                map->sub_object_geometric_normal[at] = lx_neg(map->sub_object_geometric_normal[at]);
            }
        }
    }
}

void lx_bake_sides_free(lx_baker *b)
{
    free(b->mesh_double_sided);
    free(b->side_ranges);
    free(b->side_flip);
    b->mesh_double_sided = NULL;
    b->side_ranges = NULL;
    b->side_flip = NULL;
    b->side_range_count = 0;
}
