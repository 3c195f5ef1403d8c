/* The demo scenes (examples/gen_scenes.c: room.glb and retro.glb, their
 * own lights) baked twice at one texel density: on their own lightmap UVs
 * and on luxel's (every node unwrapped, packed in atlas pages, as `luxel
 * bake --unwrap always` does). The same world points, on a fine grid over
 * every triangle, are looked up through both UV sets (bilinear, the maps
 * padded): the area-weighted mean irradiance over the scene must agree
 * within 1% per channel, since the light is the same and only where its
 * texels sit differs (measured: luxel's UVs 0.28% below on the room, 0.35%
 * on retro, alike in every channel).
 *
 * gen_scenes is the one next to this test's executable (CMake puts both in
 * bin/); it shares no code with luxel. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

static char scenes[PATH_MAX];

static int setup(void **state)
{
    (void)state;
    char gen[PATH_MAX + 16];
    lx_test_sibling("gen_scenes", gen, sizeof gen);
    snprintf(scenes, sizeof scenes, "%s", lx_test_dir("test_unwrap_light"));
    char *argv[] = {gen, scenes, NULL};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    pid_t pid;
    assert_int_equal(posix_spawn(&pid, gen, &fa, NULL, argv, environ), 0);
    posix_spawn_file_actions_destroy(&fa);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    return 0;
}

/* Bilinear lookup of img at uv (texel centres at (x + 0.5) / W), clamped
 * at the border. */
static void lookup(const lx_image *img, double u, double v, double out[3])
{
    double x = u * img->width - 0.5, y = v * img->height - 0.5;
    int x0 = (int)floor(x), y0 = (int)floor(y);
    double fx = x - x0, fy = y - y0;
    for (int c = 0; c < 3; c++)
        out[c] = 0.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            int xi = x0 + i, yj = y0 + j;
            xi = xi < 0 ? 0 : xi >= img->width ? img->width - 1 : xi;
            yj = yj < 0 ? 0 : yj >= img->height ? img->height - 1 : yj;
            double w = (i ? fx : 1.0 - fx) * (j ? fy : 1.0 - fy);
            for (int c = 0; c < 3; c++)
                out[c] += w * img->data[((size_t)yj * img->width + xi) * img->channels + c];
        }
}

typedef struct bake {
    lx_scene *scene;
    lx_baker *baker;
    lx_unwrap *unwrap;
    lx_image *maps;
    uint32_t map_count;
} bake;

static void bake_scene(const char *path, float density, bool unwrap, bake *out)
{
    memset(out, 0, sizeof *out);
    if (lx_scene_load(path, NULL, &out->scene) != LX_OK)
        fail_msg("%s", lx_last_error());
    lx_bake_desc d = {.texel_density = density, .padding = LX_PADDING_RECOMMENDED};
    if (unwrap) {
        lx_unwrap_desc ud = {.texel_density = density, .padding = LX_PADDING_RECOMMENDED};
        if (lx_unwrap_scene(out->scene, &ud, &out->unwrap) != LX_OK ||
            lx_unwrap_apply(out->scene, out->unwrap) != LX_OK)
            fail_msg("%s", lx_last_error());
        d.atlas = out->unwrap;
    }
    if (lx_baker_create(out->scene, &d, &out->baker) != LX_OK)
        fail_msg("%s", lx_last_error());
    assert_int_equal(lx_baker_bake(out->baker), LX_OK);
    assert_int_equal(lx_baker_update(out->baker), LX_OK);
    out->map_count = lx_baker_lightmap_count(out->baker);
    out->maps = calloc(out->map_count, sizeof *out->maps);
    assert_non_null(out->maps);
    for (uint32_t m = 0; m < out->map_count; m++)
        assert_int_equal(lx_baker_apply_alloc(out->baker, m, &out->maps[m]), LX_OK);
}

static void free_bake(bake *b)
{
    for (uint32_t m = 0; m < b->map_count; m++)
        lx_image_free(&b->maps[m]);
    free(b->maps);
    lx_baker_destroy(b->baker);
    lx_unwrap_destroy(b->unwrap);
    lx_scene_destroy(b->scene);
}

/* The irradiance of b at barycentric (w1, w2) of triangle t of mesh k of
 * node n, through that node's lightmap UVs. */
static void irradiance_at(const bake *b, uint32_t n, uint32_t k, uint32_t t, double w1, double w2,
                          double out[3])
{
    uint32_t map;
    float so[4];
    assert_true(lx_baker_node_lightmap(b->baker, n, &map, so));
    const lx_mesh *m = &b->scene->meshes[b->scene->nodes[n].meshes[k]];
    int set = b->unwrap ? 1 : lx_bake_uv_set(b->scene, n, LX_UV_SET_AUTO);
    const lx_vec2 *uv = m->uv[set];
    assert_non_null(uv);
    const uint32_t *i = &m->indices[3 * t];
    double w0 = 1.0 - w1 - w2;
    double u = w0 * uv[i[0]].x + w1 * uv[i[1]].x + w2 * uv[i[2]].x;
    double v = w0 * uv[i[0]].y + w1 * uv[i[1]].y + w2 * uv[i[2]].y;
    lookup(&b->maps[map], u * so[0] + so[2], v * so[1] + so[3], out);
}

/* Area-weighted means over every triangle of both bakes, at the centroids
 * of a grid of k x k equal sub-triangles per triangle (k from its size:
 * about `per_metre` points a metre). */
static void compare(const char *file, float density, double per_metre)
{
    char path[PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/%s", scenes, file);
    bake own, gen;
    bake_scene(path, density, false, &own);
    bake_scene(path, density, true, &gen);
    assert_int_equal(own.scene->node_count, gen.scene->node_count);
    double sum_own[3] = {0, 0, 0}, sum_gen[3] = {0, 0, 0}, area_sum = 0.0;
    for (uint32_t n = 0; n < own.scene->node_count; n++) {
        const lx_node *node = &own.scene->nodes[n];
        assert_int_equal(node->mesh_count, gen.scene->nodes[n].mesh_count);
        for (uint32_t k = 0; k < node->mesh_count; k++) {
            const lx_mesh *m = &own.scene->meshes[node->meshes[k]];
            assert_int_equal(m->triangle_count,
                             gen.scene->meshes[gen.scene->nodes[n].meshes[k]].triangle_count);
            for (uint32_t t = 0; t < m->triangle_count; t++) {
                const uint32_t *i = &m->indices[3 * t];
                lx_vec3 a = lx_mat4_point(&node->world, m->positions[i[0]]);
                lx_vec3 b = lx_mat4_point(&node->world, m->positions[i[1]]);
                lx_vec3 c = lx_mat4_point(&node->world, m->positions[i[2]]);
                double area = 0.5 * lx_length(lx_cross(lx_sub(b, a), lx_sub(c, a)));
                double edge = fmax(lx_length(lx_sub(b, a)),
                                   fmax(lx_length(lx_sub(c, a)), lx_length(lx_sub(c, b))));
                int g = (int)fmin(64.0, fmax(1.0, ceil(edge * per_metre)));
                double w = area / ((double)g * g);
                for (int p = 0; p < g; p++)
                    for (int q = 0; q + p < g; q++)
                        for (int down = 0; down < 2; down++) {
                            if (down && p + q > g - 2)
                                continue;
                            double s = down ? 2.0 / 3.0 : 1.0 / 3.0;
                            double w1 = (p + s) / g, w2 = (q + s) / g;
                            double e_own[3], e_gen[3];
                            irradiance_at(&own, n, k, t, w1, w2, e_own);
                            irradiance_at(&gen, n, k, t, w1, w2, e_gen);
                            for (int ch = 0; ch < 3; ch++) {
                                sum_own[ch] += w * e_own[ch];
                                sum_gen[ch] += w * e_gen[ch];
                            }
                            area_sum += w;
                        }
            }
        }
    }
    for (int ch = 0; ch < 3; ch++) {
        double mo = sum_own[ch] / area_sum, mg = sum_gen[ch] / area_sum;
        if (getenv("LX_TEST_VERBOSE"))
            printf("%s channel %d: own UVs %.6g lx, luxel's %.6g lx (%+.3f%%)\n", file, ch, mo, mg,
                   100.0 * (mg / mo - 1.0));
        assert_true(mo > 0.0);
        lx_test_assert_rel(mg, mo, 0.01);
    }
    free_bake(&own);
    free_bake(&gen);
}

static void room_same_light(void **state)
{
    (void)state;
    compare("room.glb", 32.0f, 16.0);
}

static void retro_same_light(void **state)
{
    (void)state;
    compare("retro.glb", 8.0f, 4.0);
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(room_same_light),
        cmocka_unit_test(retro_same_light),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
