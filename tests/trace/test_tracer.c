/* lx_tracer (Embree) against the brute-force Moller-Trumbore of
 * tests/common/reference.c over every triangle of every node in world space:
 * random rays over several meshes placed by rotated, scaled, mirrored and
 * shared-mesh nodes; closest hit (node, mesh, triangle, t, u, v), occlusion,
 * nearest distance, batched and packet occlusion agree, except for rays passing
 * within 1e-4 (barycentric) of an edge or hitting at the very end of their
 * range, which are skipped. Moving a node and committing moves its hits. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"
#include "core/internal.h"
#include "reference.h"
#include "scenes.h"

#include <stdatomic.h>

#define RAYS 1000
#define EDGE_EPS 1e-4
/* Embree's hits against the double-precision reference: measured within
 * 2.6e-6 relative in t (2.1e-6 on the aimed rays) and 1.3e-5 in u, v */
#define T_TOL 8e-6
#define UV_TOL 4e-5

/* ---- a small deterministic generator (xorshift64*) -------------------------- */

static uint64_t rng_state;
static double rnd(void)
{
    rng_state ^= rng_state >> 12;
    rng_state ^= rng_state << 25;
    rng_state ^= rng_state >> 27;
    return (double)((rng_state * 2685821657736338717ull) >> 11) / 9007199254740992.0;
}
static float rnd_range(float lo, float hi)
{
    return lo + (hi - lo) * (float)rnd();
}

/* ---- the scene ------------------------------------------------------------------ */

static uint32_t add_mesh(lx_scene *s, lx_mesh *m)
{
    uint32_t idx;
    if (lx_scene_add_mesh(s, m, &idx) != LX_OK)
        fail_msg("add mesh: %s", lx_last_error());
    lx_test_mesh_free(m);
    return idx;
}

static lx_mesh soup(int count)
{
    lx_mesh m = {0};
    m.name = lx_strdup("soup");
    m.vertex_count = (uint32_t)(3 * count);
    m.triangle_count = (uint32_t)count;
    m.positions = malloc(sizeof(lx_vec3) * m.vertex_count);
    m.indices = malloc(sizeof(uint32_t) * m.vertex_count);
    for (int t = 0; t < count; t++) {
        lx_vec3 c = lx_v3(rnd_range(-1, 1), rnd_range(-1, 1), rnd_range(-1, 1));
        for (int k = 0; k < 3; k++) {
            m.positions[3 * t + k] = lx_add(
                c, lx_v3(rnd_range(-0.4f, 0.4f), rnd_range(-0.4f, 0.4f), rnd_range(-0.4f, 0.4f)));
            m.indices[3 * t + k] = (uint32_t)(3 * t + k);
        }
    }
    return m;
}

static lx_vec4 axis_angle(lx_vec3 axis, float deg)
{
    axis = lx_normalize(axis);
    float h = LX_DEG2RAD(deg) / 2;
    return lx_v4(axis.x * sinf(h), axis.y * sinf(h), axis.z * sinf(h), cosf(h));
}

/* nodes: 0 box (identity), 1 the same box turned and scaled, 2 a plane,
 * 3 the soup and a small plane together, 4 the box mirrored */
static lx_scene *make_scene(void)
{
    rng_state = 0x9E3779B97F4A7C15ull;
    lx_scene *s;
    assert_int_equal(lx_scene_create("tracer", &s), LX_OK);
    lx_material mat = {.name = "m", .base_color = {1, 1, 1, 1}};
    assert_int_equal(lx_scene_add_material(s, &mat, NULL), LX_OK);
    lx_mesh box = lx_test_box("box", lx_v3(-0.5f, -0.5f, -0.5f), lx_v3(0.5f, 0.5f, 0.5f), false);
    lx_mesh plane = lx_test_plane("plane", 4.0f, 0.0f, 0.0f, 0.0f, 3);
    lx_mesh small = lx_test_plane("small", 0.7f, 0.2f, 0.1f, -0.1f, 2);
    lx_mesh sp = soup(24);
    uint32_t ib = add_mesh(s, &box), ip = add_mesh(s, &plane), is = add_mesh(s, &small),
             iu = add_mesh(s, &sp);
    lx_mat4 m0 = lx_mat4_translate(lx_v3(-1.2f, 0.8f, 0.3f));
    lx_mat4 m1 = lx_mat4_trs(lx_v3(1.0f, 1.1f, -0.8f), axis_angle(lx_v3(1, 1, 0.2f), 40.0f),
                             lx_v3(1.4f, 0.5f, 0.9f));
    lx_mat4 m2 = lx_mat4_trs(lx_v3(0.0f, -0.3f, 0.0f), axis_angle(lx_v3(0, 0, 1), 8.0f),
                             lx_v3(1.0f, 1.0f, 1.0f));
    lx_mat4 m3 = lx_mat4_trs(lx_v3(0.3f, 1.6f, 1.2f), axis_angle(lx_v3(0.2f, 1, 0), 25.0f),
                             lx_v3(0.8f, 0.8f, 0.8f));
    lx_mat4 m4 = lx_mat4_trs(lx_v3(-0.6f, 0.6f, -1.3f), axis_angle(lx_v3(0, 1, 0), 30.0f),
                             lx_v3(-0.9f, 0.7f, 1.2f));
    uint32_t pair[2] = {iu, is};
    assert_int_equal(lx_scene_add_node(s, "box", &m0, &ib, 1, NULL), LX_OK);
    assert_int_equal(lx_scene_add_node(s, "turned", &m1, &ib, 1, NULL), LX_OK);
    assert_int_equal(lx_scene_add_node(s, "floor", &m2, &ip, 1, NULL), LX_OK);
    assert_int_equal(lx_scene_add_node(s, "pair", &m3, pair, 2, NULL), LX_OK);
    assert_int_equal(lx_scene_add_node(s, "mirrored", &m4, &ib, 1, NULL), LX_OK);
    return s;
}

typedef struct ray_case {
    lx_ray ray;
    bool ambiguous;
    bool hit;
    lx_ref_hit ref;
} ray_case;

/* RAYS random rays inside the scene's bounds (grown by 1 m): random
 * directions of length 0.5..2, half with a finite range, some with tmin. */
static void make_rays(const lx_ref_scene *rs, ray_case *rc, uint64_t seed)
{
    rng_state = seed;
    for (int i = 0; i < RAYS; i++) {
        lx_vec3 o = lx_v3(rnd_range((float)rs->lo[0] - 1, (float)rs->hi[0] + 1),
                          rnd_range((float)rs->lo[1] - 1, (float)rs->hi[1] + 1),
                          rnd_range((float)rs->lo[2] - 1, (float)rs->hi[2] + 1));
        lx_vec3 d;
        if (i % 3 == 0) {
            do
                d = lx_v3(rnd_range(-1, 1), rnd_range(-1, 1), rnd_range(-1, 1));
            while (lx_length(d) > 1.0f || lx_length(d) < 0.1f);
        } else {
            /* aimed at a point near a random triangle (barycentrics in
             * -0.2..1.2: inside or just beside it) */
            const lx_ref_triangle *t = &rs->tris[(uint32_t)(rnd() * rs->count) % rs->count];
            double b1 = rnd() * 1.4 - 0.2, b2 = rnd() * 1.4 - 0.2, b0 = 1.0 - b1 - b2;
            lx_vec3 target = lx_v3((float)(b0 * t->p[0][0] + b1 * t->p[1][0] + b2 * t->p[2][0]),
                                   (float)(b0 * t->p[0][1] + b1 * t->p[1][1] + b2 * t->p[2][1]),
                                   (float)(b0 * t->p[0][2] + b1 * t->p[1][2] + b2 * t->p[2][2]));
            d = lx_sub(target, o);
            if (lx_length(d) < 1e-3f)
                d = lx_v3(0, -1, 0);
        }
        d = lx_scale(lx_normalize(d), rnd_range(0.5f, 2.0f));
        rc[i].ray.origin = o;
        rc[i].ray.dir = d;
        rc[i].ray.tmin = (i % 4 == 0) ? rnd_range(0.0f, 0.5f) : 0.0f;
        rc[i].ray.tmax = (i % 2 == 0) ? INFINITY : rnd_range(0.5f, 6.0f);
    }
}

static void reference_answers(const lx_ref_scene *rs, ray_case *rc)
{
    for (int i = 0; i < RAYS; i++)
        rc[i].hit = lx_ref_closest(rs, rc[i].ray.origin, rc[i].ray.dir, rc[i].ray.tmin,
                                   rc[i].ray.tmax, EDGE_EPS, &rc[i].ref, &rc[i].ambiguous);
}

/* Compares every unambiguous ray's closest hit, occlusion and distance. */
static void compare_single(const lx_tracer *tr, const ray_case *rc, const char *what)
{
    int hits = 0, misses = 0, skipped = 0;
    for (int i = 0; i < RAYS; i++) {
        if (rc[i].ambiguous) {
            skipped++;
            continue;
        }
        const lx_ray *r = &rc[i].ray;
        lx_hit h;
        bool got = lx_tracer_closest(tr, r, &h);
        if (got != rc[i].hit)
            fail_msg("%s: ray %d (o %g %g %g, d %g %g %g, t %g..%g): tracer %s, reference %s", what,
                     i, r->origin.x, r->origin.y, r->origin.z, r->dir.x, r->dir.y, r->dir.z,
                     r->tmin, r->tmax, got ? "hit" : "miss", rc[i].hit ? "hit" : "miss");
        assert_int_equal(lx_tracer_occluded(tr, r), rc[i].hit);
        float nd = lx_tracer_nearest_distance(tr, r);
        if (!got) {
            misses++;
            assert_true(isinf(nd));
            continue;
        }
        hits++;
        const lx_ref_hit *w = &rc[i].ref;
        if (h.node != w->node || h.mesh != w->mesh || h.triangle != w->triangle)
            fail_msg("%s: ray %d hits node %u mesh %u triangle %u, reference %u %u %u", what, i,
                     h.node, h.mesh, h.triangle, w->node, w->mesh, w->triangle);
        if (!(fabs(h.t - w->t) <= T_TOL * fabs(w->t)))
            fail_msg("%s: ray %d t %.9g, reference %.9g", what, i, h.t, w->t);
        assert_true(fabs(h.u - w->u) <= UV_TOL);
        assert_true(fabs(h.v - w->v) <= UV_TOL);
        assert_true(fabs(nd - w->t) <= T_TOL * fabs(w->t));
    }
    print_message("%s: %d hits, %d misses, %d rays skipped near edges\n", what, hits, misses,
                  skipped);
    assert_true(hits > RAYS / 5);
    assert_true(misses > RAYS / 10);
    assert_true(skipped < RAYS / 20);
}

/* Garbage on the stack below the caller, as a real caller leaves it. */
__attribute__((noinline)) static void dirty_stack(void)
{
    volatile unsigned char junk[64 * 1024];
    for (size_t i = 0; i < sizeof junk; i++)
        junk[i] = 0xFF;
}

static void compare_batch(const lx_tracer *tr, const ray_case *rc, bool coherent, bool dirty)
{
    /* in chunks of 64 (a bake tile's texels), plus odd sizes */
    lx_ray rays[RAYS];
    uint8_t occ[RAYS];
    for (int i = 0; i < RAYS; i++)
        rays[i] = rc[i].ray;
    const int sizes[] = {64, 1, 2, 7, 38, 64, 100, 17};
    int at = 0, k = 0;
    while (at < RAYS) {
        int n = sizes[k++ % 8];
        if (n > RAYS - at)
            n = RAYS - at;
        if (dirty)
            dirty_stack();
        lx_tracer_occluded_batch(tr, rays + at, (uint32_t)n, coherent, occ + at);
        at += n;
    }
    for (int i = 0; i < RAYS; i++)
        if (!rc[i].ambiguous && occ[i] != rc[i].hit)
            fail_msg("batch (coherent %d) ray %d: occluded %d, reference %d", coherent, i, occ[i],
                     rc[i].hit);
}

/* Puts ray r in lane j of packet pk. */
static void packet_set(lx_ray_packet *pk, int j, const lx_ray *r)
{
    pk->origin_x[j] = r->origin.x, pk->origin_y[j] = r->origin.y, pk->origin_z[j] = r->origin.z;
    pk->dir_x[j] = r->dir.x, pk->dir_y[j] = r->dir.y, pk->dir_z[j] = r->dir.z;
    pk->tmin[j] = r->tmin, pk->tmax[j] = r->tmax;
}

/* lx_tracer_occluded_packet over every ray, in three passes that put each
 * ray in a different lane beside different rays, with random lanes left
 * out: an active lane answers as the brute-force reference (ambiguous rays
 * skipped) and, every ray included, the same in every pass and as
 * lx_tracer_occluded; an inactive lane answers 0 and keeps its tmax. */
static void compare_packets(const lx_tracer *tr, const ray_case *rc)
{
    static int answer[RAYS];
    for (int i = 0; i < RAYS; i++)
        answer[i] = -1;
    rng_state = 777;
    for (int pass = 0; pass < 3; pass++) {
        int stride = pass == 0 ? 1 : pass == 1 ? 7 : 13; /* coprime with RAYS */
        for (int base = 0; base < RAYS; base += LX_RAY_PACKET) {
            lx_ray_packet pk;
            int which[LX_RAY_PACKET];
            uint32_t active = 0;
            for (int j = 0; j < LX_RAY_PACKET; j++) {
                which[j] = ((base + j) * stride + pass) % RAYS;
                packet_set(&pk, j, &rc[which[j]].ray);
                /* pass 0 traces every ray; later passes leave out a third */
                bool on = base + j < RAYS && (pass == 0 || rnd() < 0.67);
                active |= (uint32_t)on << j;
            }
            float tmax_before[LX_RAY_PACKET];
            memcpy(tmax_before, pk.tmax, sizeof tmax_before);
            dirty_stack();
            uint32_t blocked = lx_tracer_occluded_packet(tr, &pk, active);
            assert_int_equal(blocked & ~active, 0);
            for (int j = 0; j < LX_RAY_PACKET; j++) {
                const ray_case *c = &rc[which[j]];
                if (!((active >> j) & 1u)) {
                    assert_true(pk.tmax[j] == tmax_before[j] || isnan(tmax_before[j]));
                    continue;
                }
                int got = (int)((blocked >> j) & 1u);
                if (!c->ambiguous && got != c->hit)
                    fail_msg("packet pass %d lane %d ray %d: occluded %d, reference %d", pass, j,
                             which[j], got, c->hit);
                if (answer[which[j]] >= 0 && answer[which[j]] != got)
                    fail_msg("ray %d: lane %d of pass %d answers %d, an earlier lane %d", which[j],
                             j, pass, got, answer[which[j]]);
                answer[which[j]] = got;
            }
        }
    }
    for (int i = 0; i < RAYS; i++)
        if (answer[i] != (int)lx_tracer_occluded(tr, &rc[i].ray))
            fail_msg("ray %d: packet answers %d, lx_tracer_occluded %d", i, answer[i], !answer[i]);
    /* nothing active: nothing traced, nothing blocked */
    lx_ray_packet pk;
    for (int j = 0; j < LX_RAY_PACKET; j++)
        packet_set(&pk, j, &rc[j].ray);
    assert_int_equal(lx_tracer_occluded_packet(tr, &pk, 0), 0);
}

/* ---- tests ------------------------------------------------------------------------- */

static void test_random_rays(void **state)
{
    (void)state;
    lx_scene *s = make_scene();
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    lx_ref_scene rs;
    lx_ref_scene_build(s, &rs);
    static ray_case rc[RAYS];
    make_rays(&rs, rc, 12345);
    reference_answers(&rs, rc);
    compare_single(tr, rc, "random rays");
    compare_batch(tr, rc, false, false);
    /* rays aimed at triangle centroids: every node and mesh gets hits */
    int seen[5] = {0};
    for (uint32_t i = 0; i < rs.count; i += 3) {
        const lx_ref_triangle *t = &rs.tris[i];
        lx_vec3 c = lx_v3((float)((t->p[0][0] + t->p[1][0] + t->p[2][0]) / 3),
                          (float)((t->p[0][1] + t->p[1][1] + t->p[2][1]) / 3),
                          (float)((t->p[0][2] + t->p[1][2] + t->p[2][2]) / 3));
        lx_vec3 o = lx_v3(c.x + 0.3f, c.y + 5.0f, c.z - 0.2f);
        lx_vec3 d = lx_sub(c, o);
        lx_ref_hit w;
        bool amb;
        bool hit = lx_ref_closest(&rs, o, d, 0.0, 2.0, EDGE_EPS, &w, &amb);
        if (amb)
            continue;
        lx_hit h;
        lx_ray r = {o, 0.0f, d, 2.0f};
        assert_int_equal(lx_tracer_closest(tr, &r, &h), hit);
        assert_true(hit); /* at least the aimed-at triangle */
        assert_int_equal(h.node, w.node);
        assert_int_equal(h.mesh, w.mesh);
        assert_int_equal(h.triangle, w.triangle);
        assert_true(fabs(h.t - w.t) <= T_TOL * w.t);
        seen[h.node]++;
    }
    for (int n = 0; n < 5; n++)
        assert_true(seen[n] > 0);
    lx_ref_scene_free(&rs);
    lx_tracer_destroy(tr);
    lx_scene_destroy(s);
}

static void test_move_node_and_commit(void **state)
{
    (void)state;
    lx_scene *s = make_scene();
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);

    /* a ray straight down onto the identity box's top (node 0, top at 1.3) */
    lx_ray down = {lx_v3(-1.1f, 4.0f, 0.35f), 0.0f, lx_v3(0, -1, 0), INFINITY};
    lx_hit h;
    assert_true(lx_tracer_closest(tr, &down, &h));
    assert_int_equal(h.node, 0);
    assert_true(fabsf(h.t - 2.7f) <= T_TOL * 2.7); /* measured exact */
    /* the outward box's top faces up: the ray meets its front */
    assert_true(fabsf(h.normal.x) < 1e-6f && fabsf(h.normal.y - 1.0f) < 1e-6f &&
                fabsf(h.normal.z) < 1e-6f);
    /* from inside the box the top is a back face: the same normal */
    lx_ray up = {lx_v3(-1.1f, 0.9f, 0.35f), 0.0f, lx_v3(0, 1, 0), INFINITY};
    assert_true(lx_tracer_closest(tr, &up, &h));
    assert_int_equal(h.node, 0);
    assert_true(lx_dot(up.dir, h.normal) > 0.99f);
    /* mirrored in x (a negative determinant): glTF turns the winding
     * over, so the top still faces up */
    lx_mat4 mirror = s->nodes[0].world;
    for (int r = 0; r < 3; r++)
        mirror.m[r] = -mirror.m[r]; /* column 0: x flipped */
    assert_int_equal(lx_tracer_set_node_transform(tr, 0, &mirror), LX_OK);
    assert_int_equal(lx_tracer_commit(tr), LX_OK);
    assert_true(lx_tracer_closest(tr, &down, &h)); /* the box is centred on its node */
    assert_int_equal(h.node, 0);
    assert_true(h.normal.y > 0.99f);
    assert_int_equal(lx_tracer_set_node_transform(tr, 0, &s->nodes[0].world), LX_OK);
    assert_int_equal(lx_tracer_commit(tr), LX_OK);

    /* move the box: 2 m along +x and 0.5 m down, with a turn */
    lx_mat4 moved =
        lx_mat4_trs(lx_v3(0.8f, 0.3f, 0.3f), axis_angle(lx_v3(0, 1, 0), 45.0f), lx_v3(1, 1, 1));
    assert_int_equal(lx_tracer_set_node_transform(tr, 0, &moved), LX_OK);
    assert_int_equal(lx_tracer_commit(tr), LX_OK);
    /* the old spot: the box is gone; the ray goes on to the floor (node 2) */
    assert_true(lx_tracer_closest(tr, &down, &h));
    assert_true(h.node != 0);
    /* the new spot: top of the moved box at y = 0.8 */
    lx_ray down2 = {lx_v3(0.85f, 4.0f, 0.32f), 0.0f, lx_v3(0, -1, 0), INFINITY};
    assert_true(lx_tracer_closest(tr, &down2, &h));
    assert_int_equal(h.node, 0);
    assert_true(fabsf(h.t - 3.2f) <= T_TOL * 3.2); /* measured exact */

    /* the whole random comparison on the moved scene */
    s->nodes[0].world = moved;
    lx_mat4 m3 = lx_mat4_trs(lx_v3(-0.5f, 0.4f, 0.9f), axis_angle(lx_v3(1, 0, 0), -60.0f),
                             lx_v3(1.2f, 0.6f, 1.2f));
    assert_int_equal(lx_tracer_set_node_transform(tr, 3, &m3), LX_OK);
    assert_int_equal(lx_tracer_commit(tr), LX_OK);
    s->nodes[3].world = m3;
    lx_ref_scene rs;
    lx_ref_scene_build(s, &rs);
    static ray_case rc[RAYS];
    make_rays(&rs, rc, 777);
    reference_answers(&rs, rc);
    compare_single(tr, rc, "after moving nodes 0 and 3");

    /* bad nodes and transforms are refused */
    lx_mat4 id = lx_mat4_identity();
    assert_int_equal(lx_tracer_set_node_transform(tr, 5, &id), LX_ERR_INVALID);
    lx_mat4 flat = id;
    flat.m[10] = 0.0f;
    assert_int_equal(lx_tracer_set_node_transform(tr, 1, &flat), LX_ERR_INVALID);
    lx_mat4 inf = id;
    inf.m[13] = INFINITY;
    assert_int_equal(lx_tracer_set_node_transform(tr, 1, &inf), LX_ERR_INVALID);
    lx_ref_scene_free(&rs);
    lx_tracer_destroy(tr);
    lx_scene_destroy(s);
}

/* The baker calls the batch with coherent = true for a tile's shadow rays.
 * With a dirty stack (as the baker leaves it) this must still answer, and
 * answer the same as the reference. */
static void test_coherent_batch(void **state)
{
    (void)state;
    lx_scene *s = make_scene();
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    lx_ref_scene rs;
    lx_ref_scene_build(s, &rs);
    static ray_case rc[RAYS];
    make_rays(&rs, rc, 4242);
    reference_answers(&rs, rc);
    compare_batch(tr, rc, false, true);
    compare_batch(tr, rc, true, false);
    compare_batch(tr, rc, true, true);
    compare_packets(tr, rc);
    lx_ref_scene_free(&rs);
    lx_tracer_destroy(tr);
    lx_scene_destroy(s);

    /* shadow rays as a bake makes them: a tile of texels on a plane (one
     * node) toward a light above it; nothing blocks them */
    assert_int_equal(lx_scene_create("shadow rays", &s), LX_OK);
    lx_mesh plane = lx_test_plane("ground", 4.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add(s, &plane);
    lx_test_mesh_free(&plane);
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    /* two rays of such a tile, exactly */
    lx_ray two[2] = {{{0x1.cp-3f, 0x1.04dbcep-14f, -0x1.68p+0f},
                      0.0f,
                      {-0x1.c7f5a8p-8f, 0x1.daf54p-1f, 0x1.7e5758p-2f},
                      0x1.58f0dep+1f},
                     {{0x1.8p-4f, 0x1.03cf5ep-14f, -0x1.58p+0f},
                      0.0f,
                      {0x1.45777ap-5f, 0x1.dea0a4p-1f, 0x1.695d2p-2f},
                      0x1.564bd8p+1f}};
    uint8_t occ[64] = {1, 1};
    dirty_stack();
    lx_tracer_occluded_batch(tr, two, 2, true, occ);
    assert_int_equal(occ[0], 0);
    assert_int_equal(occ[1], 0);
    /* and whole tiles of them */
    const lx_vec3 light = lx_v3(0.2f, 2.5f, -0.4f);
    for (int tile = 0; tile < 64; tile++) {
        lx_ray rays[64];
        for (int k = 0; k < 64; k++) {
            int x = (tile % 8) * 8 + k % 8, y = (tile / 8) * 8 + k / 8;
            lx_vec3 p =
                lx_v3(-2.0f + 4.0f * (x + 0.5f) / 64, 1e-4f, -2.0f + 4.0f * (y + 0.5f) / 64);
            lx_vec3 d = lx_sub(light, p);
            float len = lx_length(d);
            rays[k] = (lx_ray){p, 0.0f, lx_scale(d, 1.0f / len), len - 2e-4f};
        }
        memset(occ, 1, sizeof occ);
        dirty_stack();
        lx_tracer_occluded_batch(tr, rays, 1 + (uint32_t)tile % 64, true, occ);
        for (int k = 0; k <= tile % 64; k++)
            assert_int_equal(occ[k], 0);
        /* the same tile as four packets of 4x4 texels */
        for (int q = 0; q < 4; q++) {
            lx_ray_packet pk;
            for (int j = 0; j < LX_RAY_PACKET; j++)
                packet_set(&pk, j, &rays[(q / 2 * 4 + j / 4) * 8 + q % 2 * 4 + j % 4]);
            assert_int_equal(lx_tracer_occluded_packet(tr, &pk, 0xFFFFu), 0);
        }
    }
    lx_tracer_destroy(tr);
    lx_scene_destroy(s);
}

/* The BVH build reports progress through lx_tracer_desc: from one thread
 * at a time (Embree's build threads may report at once), in [0, 1], never
 * backwards; returning false cancels the build with nothing made. */
typedef struct build_log {
    int calls;
    float last;
    bool backwards, out_of_range;
    _Atomic int inside, overlaps;
    int cancel_at; /* stop at this call, 0 = never */
} build_log;

static bool on_build(void *user, float fraction)
{
    build_log *log = user;
    if (atomic_fetch_add(&log->inside, 1) != 0)
        atomic_fetch_add(&log->overlaps, 1);
    log->calls++;
    log->backwards = log->backwards || fraction < log->last;
    log->out_of_range = log->out_of_range || !(fraction >= 0.0f && fraction <= 1.0f);
    log->last = fraction;
    bool go_on = log->cancel_at == 0 || log->calls < log->cancel_at;
    atomic_fetch_sub(&log->inside, 1);
    return go_on;
}

static void test_build_progress_and_cancel(void **state)
{
    (void)state;
    lx_test_scene_info info;
    /* about 100k triangles: a build Embree reports on */
    lx_scene *scene = lx_test_spheres_scene("progress", 40.0f, 32, 21, 16, 8, false, &info);
    build_log log = {0};
    lx_tracer_desc d = {.threads = 2, .progress = on_build, .progress_user = &log};
    lx_tracer *tr = NULL;
    assert_int_equal(lx_tracer_create(scene, &d, &tr), LX_OK);
    assert_non_null(tr);
    assert_true(log.calls > 0);
    assert_false(log.backwards);
    assert_false(log.out_of_range);
    assert_int_equal(atomic_load(&log.overlaps), 0);
    lx_tracer_destroy(tr);

    build_log stop = {.cancel_at = 1};
    d.progress_user = &stop;
    tr = (lx_tracer *)&stop; /* must be reset */
    assert_int_equal(lx_tracer_create(scene, &d, &tr), LX_ERR_CANCELLED);
    assert_null(tr);
    assert_non_null(strstr(lx_last_error(), "cancelled"));
    lx_scene_destroy(scene);
}

/* lx_tracer_off_plane_near: a 4 m floor (8 x 8 quads, y = 0) and a cube
 * [1, 1.5] x [0.2, 0.7] x [1, 1.5] above it. Spheres that reach only the
 * floor find nothing off its plane; one whose box reaches the cube's
 * does; any other plane finds the floor off it. */
static void test_off_plane_near(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("plane");
    lx_mesh floor = lx_test_plane("floor", 4.0f, 0.0f, 0.0f, 0.0f, 8);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    lx_mesh cube = lx_test_box("cube", lx_v3(1.0f, 0.2f, 1.0f), lx_v3(1.5f, 0.7f, 1.5f), false);
    lx_test_add(scene, &cube);
    lx_test_mesh_free(&cube);
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(scene, NULL, &tr), LX_OK);
    lx_vec3 up = lx_v3(0.0f, 1.0f, 0.0f);
    /* the floor alone: in its plane, at every size up to the cube */
    assert_false(lx_tracer_off_plane_near(tr, lx_v3(-1.0f, 0.0f, -1.0f), 0.5f, up, 0.0f, 1e-5f));
    assert_false(lx_tracer_off_plane_near(tr, lx_v3(0.0f, 0.0f, 0.0f), 0.95f, up, 0.0f, 1e-5f));
    /* the cube's box is 0.2 above the floor, from x, z = 1: the sphere at
     * (1.2, 0, 1.2) reaches it from radius 0.2 */
    assert_false(lx_tracer_off_plane_near(tr, lx_v3(1.2f, 0.0f, 1.2f), 0.19f, up, 0.0f, 1e-5f));
    assert_true(lx_tracer_off_plane_near(tr, lx_v3(1.2f, 0.0f, 1.2f), 0.21f, up, 0.0f, 1e-5f));
    /* a plane 1 cm above the floor: the floor leaves it, beyond the
     * tolerance only */
    assert_true(lx_tracer_off_plane_near(tr, lx_v3(-1.0f, 0.01f, -1.0f), 0.1f, up, 0.01f, 1e-3f));
    assert_false(lx_tracer_off_plane_near(tr, lx_v3(-1.0f, 0.01f, -1.0f), 0.1f, up, 0.01f, 0.02f));
    /* a wall's plane (x = -1) through the floor */
    assert_true(lx_tracer_off_plane_near(tr, lx_v3(-1.0f, 0.0f, -1.0f), 0.1f,
                                         lx_v3(1.0f, 0.0f, 0.0f), -1.0f, 1e-5f));
    lx_tracer_destroy(tr);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_off_plane_near),
        cmocka_unit_test(test_build_progress_and_cancel), cmocka_unit_test(test_random_rays),
        cmocka_unit_test(test_move_node_and_commit),
        cmocka_unit_test(test_coherent_batch), /* last: a hang ends the program */
    };
    lx_test_watchdog(30);
    return cmocka_run_group_tests(tests, NULL, NULL);
}
