/* Writes a small 2D scene for `luxel light2d` into a folder: casters.png
 * (sprites with alpha: crates, round pillars, a wall with a doorway),
 * albedo.png (a tiled floor under the sprites), normals.png (bevelled
 * crates, domed pillars, a flat floor with grooves between tiles; green up)
 * and lights.json (a warm torch, a cool spot, a soft lantern, a dim fill).
 *
 * usage: gen_light2d DIR [WIDTH HEIGHT]   (default 480 270) */
#include "luxel/core.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct px {
    float a, r, g, b;    /* caster alpha, albedo */
    float nx, ny, nz;    /* normal, tangent space (y up) */
} px;

static void crate(px *im, int w, int h, int x0, int y0, int s)
{
    for (int y = y0; y < y0 + s && y < h; y++)
        for (int x = x0; x < x0 + s && x < w; x++) {
            if (x < 0 || y < 0)
                continue;
            px *p = &im[y * w + x];
            p->a = 1.0f;
            bool plank = ((y - y0) / 4) % 2 == 0;
            p->r = plank ? 0.55f : 0.45f;
            p->g = plank ? 0.36f : 0.30f;
            p->b = 0.18f;
            int bevel = 3;
            float nx = 0.0f, ny = 0.0f;
            if (x - x0 < bevel)
                nx = -0.6f;
            else if (x0 + s - 1 - x < bevel)
                nx = 0.6f;
            if (y - y0 < bevel)
                ny = 0.6f; /* the top edge faces up the image */
            else if (y0 + s - 1 - y < bevel)
                ny = -0.6f;
            float len = sqrtf(nx * nx + ny * ny + 1.0f);
            p->nx = nx / len;
            p->ny = ny / len;
            p->nz = 1.0f / len;
        }
}

static void pillar(px *im, int w, int h, float cx, float cy, float r)
{
    for (int y = (int)(cy - r) - 1; y <= (int)(cy + r) + 1; y++)
        for (int x = (int)(cx - r) - 1; x <= (int)(cx + r) + 1; x++) {
            if (x < 0 || y < 0 || x >= w || y >= h)
                continue;
            float dx = (x + 0.5f - cx) / r, dy = (y + 0.5f - cy) / r;
            float q = dx * dx + dy * dy;
            if (q > 1.0f)
                continue;
            px *p = &im[y * w + x];
            p->a = 1.0f;
            p->r = 0.62f;
            p->g = 0.62f;
            p->b = 0.66f;
            p->nx = dx;
            p->ny = -dy;
            p->nz = sqrtf(fmaxf(0.0f, 1.0f - q));
        }
}

static void wall(px *im, int w, int h, int x0, int y0, int x1, int y1)
{
    for (int y = y0; y < y1 && y < h; y++)
        for (int x = x0; x < x1 && x < w; x++) {
            px *p = &im[y * w + x];
            p->a = 1.0f;
            bool mortar = (y % 6 == 0) || ((x + (y / 6) * 5) % 12 == 0);
            p->r = mortar ? 0.35f : 0.60f;
            p->g = mortar ? 0.33f : 0.28f;
            p->b = mortar ? 0.30f : 0.22f;
            p->nx = 0.0f;
            p->ny = 0.0f;
            p->nz = 1.0f;
        }
}

static int write(const char *dir, const char *name, int w, int h, int ch, const float *data)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    lx_image img = {w, h, ch, (float *)data};
    lx_image_write_desc d = {.linear = strcmp(name, "normals.png") == 0 ||
                                       strcmp(name, "casters.png") == 0};
    if (lx_image_write(path, &img, &d) != LX_OK) {
        fprintf(stderr, "gen_light2d: %s\n", lx_last_error());
        return 1;
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 2 && argc != 4) {
        fprintf(stderr, "usage: gen_light2d DIR [WIDTH HEIGHT]\n");
        return 2;
    }
    int w = 480, h = 270;
    if (argc == 4) {
        w = atoi(argv[2]);
        h = atoi(argv[3]);
        if (w < 64 || h < 64 || w > 8192 || h > 8192) {
            fprintf(stderr, "gen_light2d: the size must be 64..8192 a side\n");
            return 2;
        }
    }
    mkdir(argv[1], 0777);
    px *im = calloc((size_t)w * h, sizeof *im);
    if (!im)
        return 1;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            px *p = &im[y * w + x];
            bool groove = x % 24 == 0 || y % 24 == 0;
            bool dark = ((x / 24) + (y / 24)) % 2 == 0;
            p->r = groove ? 0.25f : (dark ? 0.50f : 0.58f);
            p->g = groove ? 0.25f : (dark ? 0.50f : 0.56f);
            p->b = groove ? 0.25f : (dark ? 0.48f : 0.52f);
            p->nx = x % 24 == 1 ? 0.5f : (x % 24 == 23 ? -0.5f : 0.0f);
            p->ny = y % 24 == 1 ? -0.5f : (y % 24 == 23 ? 0.5f : 0.0f);
            p->nz = 1.0f;
            float len = sqrtf(p->nx * p->nx + p->ny * p->ny + 1.0f);
            p->nx /= len;
            p->ny /= len;
            p->nz /= len;
        }
    /* scale the layout with the size */
    float sx = w / 480.0f, sy = h / 270.0f, s = fminf(sx, sy);
    wall(im, w, h, (int)(300 * sx), 0, (int)(310 * sx), (int)(110 * sy));
    wall(im, w, h, (int)(300 * sx), (int)(150 * sy), (int)(310 * sx), h);
    crate(im, w, h, (int)(120 * sx), (int)(60 * sy), (int)(22 * s));
    crate(im, w, h, (int)(200 * sx), (int)(170 * sy), (int)(26 * s));
    crate(im, w, h, (int)(60 * sx), (int)(190 * sy), (int)(18 * s));
    crate(im, w, h, (int)(380 * sx), (int)(200 * sy), (int)(24 * s));
    pillar(im, w, h, 180 * sx, 110 * sy, 9 * s);
    pillar(im, w, h, 90 * sx, 120 * sy, 7 * s);
    pillar(im, w, h, 400 * sx, 80 * sy, 10 * s);
    float *casters = malloc((size_t)w * h * 4 * sizeof *casters);
    float *albedo = malloc((size_t)w * h * 3 * sizeof *albedo);
    float *normals = malloc((size_t)w * h * 3 * sizeof *normals);
    if (!casters || !albedo || !normals)
        return 1;
    for (int i = 0; i < w * h; i++) {
        casters[4 * i] = casters[4 * i + 1] = casters[4 * i + 2] = im[i].a;
        casters[4 * i + 3] = im[i].a;
        albedo[3 * i] = im[i].r;
        albedo[3 * i + 1] = im[i].g;
        albedo[3 * i + 2] = im[i].b;
        normals[3 * i] = 0.5f + 0.5f * im[i].nx;
        normals[3 * i + 1] = 0.5f + 0.5f * im[i].ny;
        normals[3 * i + 2] = 0.5f + 0.5f * im[i].nz;
    }
    int rc = write(argv[1], "casters.png", w, h, 4, casters) ||
             write(argv[1], "albedo.png", w, h, 3, albedo) ||
             write(argv[1], "normals.png", w, h, 3, normals);
    char path[1024];
    snprintf(path, sizeof path, "%s/lights.json", argv[1]);
    FILE *f = fopen(path, "w");
    if (!f)
        return 1;
    fprintf(f,
            "{\n  \"ambient\": [0.03, 0.03, 0.05],\n  \"lights\": [\n"
            "    {\"type\": \"point\", \"position\": [%g, %g], \"temperature\": 2200, "
            "\"intensity\": 2.2, \"radius\": %g, \"softness\": %g, \"height\": %g},\n"
            "    {\"type\": \"spot\", \"position\": [%g, %g], \"direction\": [-1, 0.25], "
            "\"arc\": 50, \"color\": [0.45, 0.6, 1.0], \"intensity\": 2.0, \"radius\": %g, "
            "\"softness\": %g, \"height\": %g, \"falloff\": \"linear\"},\n"
            "    {\"type\": \"point\", \"position\": [%g, %g], \"temperature\": 4000, "
            "\"intensity\": 1.4, \"radius\": %g, \"softness\": %g, \"height\": %g, "
            "\"dynamic\": true},\n"
            "    {\"type\": \"point\", \"position\": [%g, %g], \"color\": [0.5, 1.0, 0.6], "
            "\"intensity\": 0.5, \"radius\": %g, \"shadow\": false, \"height\": %g}\n"
            "  ]\n}\n",
            150 * sx, 130 * sy, 170 * s, 3 * s, 30 * s, 460 * sx, 120 * sy, 300 * s, 5 * s,
            40 * s, 260 * sx, 90 * sy, 120 * s, 6 * s, 25 * s, 60 * sx, 240 * sy, 90 * s, 20 * s);
    fclose(f);
    free(im);
    free(casters);
    free(albedo);
    free(normals);
    return rc;
}
