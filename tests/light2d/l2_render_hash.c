/* Renders a fixed set of 2D light scenes and prints a hash of each light
 * map's bytes, one line a scene. Built twice (CMakeLists.txt): against the
 * library as shipped (vector clones and AVX2 gathers where the CPU has
 * them) and against src/light2d built with -DL2_NO_CLONES (portable scalar
 * loops); test_portable_bytes.sh checks that the two print the same lines,
 * the promise that the bytes do not depend on the CPU. */
#include "luxel/light2d.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint32_t state = 777u;
static uint32_t rnd(void)
{
    state = state * 1664525u + 1013904223u;
    return state >> 8;
}

/* FNV-1a over the bytes */
static uint64_t hash_bytes(const void *p, size_t n)
{
    const unsigned char *b = p;
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

int main(void)
{
    const int w = 301, h = 203;
    lx_image casters = {0}, normals = {0};
    if (lx_image_alloc(&casters, w, h, 4) != LX_OK || lx_image_alloc(&normals, w, h, 3) != LX_OK)
        return 1;
    /* rectangles and discs, thin ones included; normals bumped over discs */
    for (int i = 0; i < w * h; i++) {
        normals.data[3 * i] = 0.5f;
        normals.data[3 * i + 1] = 0.5f;
        normals.data[3 * i + 2] = 1.0f;
    }
    for (int k = 0; k < 60; k++) {
        int cx = (int)(rnd() % w), cy = (int)(rnd() % h), s = 1 + (int)(rnd() % 9);
        bool disc = rnd() % 2;
        for (int y = cy - s; y <= cy + s; y++)
            for (int x = cx - (disc ? s : 1); x <= cx + s; x++) {
                if (x < 0 || y < 0 || x >= w || y >= h)
                    continue;
                float dx = (float)(x - cx) / s, dy = (float)(y - cy) / s;
                if (disc && dx * dx + dy * dy > 1.0f)
                    continue;
                casters.data[((size_t)y * w + x) * 4 + 3] = 1.0f;
                if (disc) {
                    normals.data[3 * ((size_t)y * w + x)] = 0.5f + 0.5f * dx;
                    normals.data[3 * ((size_t)y * w + x) + 1] = 0.5f - 0.5f * dy;
                }
            }
    }
    float *lm = malloc((size_t)w * h * 3 * sizeof *lm);
    if (!lm)
        return 1;
    /* softness 0 (hard), small and wide; point and spot; faces lit or
     * self-shadowed; with and without the normal map; a light off the image */
    const float softness[] = {0.0f, 2.0f, 6.0f, 20.0f};
    for (int scene = 0; scene < 16; scene++) {
        lx_light2d_light l[3];
        for (int i = 0; i < 3; i++) {
            l[i] = lx_light2d_light_defaults(i == 1 && scene % 2 ? LX_LIGHT2D_SPOT
                                                                 : LX_LIGHT2D_POINT);
            l[i].x = (float)(rnd() % (w + 60)) - 30.0f + 0.37f * i;
            l[i].y = (float)(rnd() % (h + 60)) - 30.0f + 0.21f * i;
            l[i].radius = 40.0f + (float)(rnd() % 200);
            l[i].softness = softness[(scene + i) % 4];
            l[i].self_shadow = scene % 4 == 3;
            l[i].falloff = (lx_light2d_falloff)(scene % 3);
            l[i].height = 30.0f;
            l[i].dir_x = 1.0f;
            l[i].dir_y = 0.3f * i;
            l[i].arc = 70.0f;
        }
        lx_light2d_desc d = {.threads = 2};
        lx_light2d *ctx = NULL;
        if (lx_light2d_create(&casters, &d, &ctx) != LX_OK ||
            (scene % 2 == 0 && lx_light2d_set_normals(ctx, &normals, false) != LX_OK) ||
            lx_light2d_set_lights(ctx, l, 3) != LX_OK ||
            lx_light2d_render(ctx, lx_v3(0.0f, 0.0f, 0.0f), NULL, NULL, lm) != LX_OK) {
            fprintf(stderr, "l2_render_hash: scene %d: %s\n", scene, lx_last_error());
            return 1;
        }
        lx_light2d_destroy(ctx);
        printf("scene %2d: %016llx\n", scene,
               (unsigned long long)hash_bytes(lm, (size_t)w * h * 3 * sizeof *lm));
    }
    free(lm);
    lx_image_free(&casters);
    lx_image_free(&normals);
    return 0;
}
