/* libFuzzer harness for the 2D lights JSON (src/light2d/scene_json.c,
 * lx_light2d_scene_parse): every input must end in LX_OK or a clean error,
 * never a crash, leak, hang or undefined behaviour. A file that parses must
 * hold only lights lx_light2d_light_validate accepts and a finite,
 * non-negative ambient; those lights are then rendered over a small caster
 * image (radii capped so that each run stays fast), which drives the
 * shading and the polar maps with whatever values the reader lets through.
 *
 *   make fuzz   (or: ./fuzz_light2d_json corpus/ fuzz/corpus/light2d_json/) */
#include "luxel/light2d.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#define FZ_SIZE 24
#define FZ_MAX_LIGHTS 8

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* One context for every run: a ring of casters with a gap, and a caster
 * pixel on the border. */
static lx_light2d *context(void)
{
    static lx_light2d *ctx;
    if (ctx)
        return ctx;
    lx_image img;
    if (lx_image_alloc(&img, FZ_SIZE, FZ_SIZE, 4) != LX_OK)
        __builtin_trap();
    for (int y = 0; y < FZ_SIZE; y++)
        for (int x = 0; x < FZ_SIZE; x++) {
            float dx = x + 0.5f - 12.0f, dy = y + 0.5f - 12.0f;
            float d2 = dx * dx + dy * dy;
            if ((d2 > 36.0f && d2 < 64.0f && x != 12) || (x == 0 && y == 0))
                img.data[(y * FZ_SIZE + x) * 4 + 3] = 1.0f;
        }
    lx_light2d_desc d = {.threads = 1};
    if (lx_light2d_create(&img, &d, &ctx) != LX_OK)
        __builtin_trap();
    lx_image_free(&img);
    return ctx;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lx_light2d_scene s;
    if (lx_light2d_scene_parse("fuzz.json", (const char *)data, size, &s) != LX_OK) {
        /* a failed parse leaves an empty scene */
        if (s.lights || s.count)
            __builtin_trap();
        return 0;
    }
    if (s.count < 0 || (s.count > 0 && !s.lights))
        __builtin_trap();
    lx_vec3 a = s.ambient;
    if (!(a.x >= 0.0f && a.x <= LX_LIGHT2D_MAX_LIGHT) ||
        !(a.y >= 0.0f && a.y <= LX_LIGHT2D_MAX_LIGHT) ||
        !(a.z >= 0.0f && a.z <= LX_LIGHT2D_MAX_LIGHT))
        __builtin_trap(); /* the reader let a bad ambient through */
    for (int i = 0; i < s.count; i++)
        if (lx_light2d_light_validate(&s.lights[i]) != LX_OK)
            __builtin_trap(); /* the reader let an invalid light through */
    int n = s.count < FZ_MAX_LIGHTS ? s.count : FZ_MAX_LIGHTS;
    for (int i = 0; i < n; i++) {
        /* a radius of up to 65536 is valid but costs a million rays */
        if (s.lights[i].radius > 40.0f)
            s.lights[i].radius = 40.0f;
    }
    lx_light2d *ctx = context();
    static float out[FZ_SIZE * FZ_SIZE * 3];
    if (lx_light2d_set_lights(ctx, s.lights, n) != LX_OK ||
        lx_light2d_render(ctx, a, NULL, out, NULL) != LX_OK)
        __builtin_trap(); /* valid lights must render */
    for (int i = 0; i < FZ_SIZE * FZ_SIZE * 3; i++)
        if (!(out[i] >= 0.0f) || isinf(out[i]))
            __builtin_trap(); /* light is finite and never negative */
    lx_light2d_scene_free(&s);
    return 0;
}
