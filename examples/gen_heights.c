/* gen_heights: height fields for the texture-space tools' examples and
 * docs pictures, written as 16-bit grey PNGs by luxel's own writer:
 *   DIR/bumps.png    round bumps, a cone and a square plateau on flat ground
 *   DIR/bricks.png   a tileable brick wall (rows offset by half a brick),
 *                    bevelled bricks and recessed mortar
 *   DIR/ripples.png  fine tileable ripples, a detail map
 * Usage: gen_heights DIR [SIZE] (default 192; bricks tile at any size). */
#include "luxel/luxel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double smooth(double e0, double e1, double x)
{
    double t = (x - e0) / (e1 - e0);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return t * t * (3 - 2 * t);
}

static double bumps(double u, double v)
{
    double h = 0.1;
    static const double b[][3] = {{0.25, 0.28, 0.13}, {0.72, 0.3, 0.09}, {0.3, 0.75, 0.07}};
    for (int i = 0; i < 3; i++) {
        double d = hypot(u - b[i][0], v - b[i][1]) / b[i][2];
        if (d < 1)
            h = fmax(h, 0.1 + 0.6 * sqrt(1 - d * d));
    }
    double c = hypot(u - 0.72, v - 0.74);
    if (c < 0.16)
        h = fmax(h, 0.1 + 0.8 * (1 - c / 0.16));
    if (fabs(u - 0.5) < 0.06 && fabs(v - 0.52) < 0.06)
        h = fmax(h, 0.45);
    return h;
}

static double bricks(double u, double v)
{
    int rows = 6, cols = 3;
    double y = v * rows, row = floor(y);
    double x = u * cols + (fmod(row, 2) != 0 ? 0.5 : 0);
    double fx = x - floor(x), fy = y - row;
    /* distance to the nearest mortar line, in brick heights */
    double dx = fmin(fx, 1 - fx) * rows / cols * 2, dy = fmin(fy, 1 - fy);
    double d = fmin(dx, dy);
    double brick = 0.35 + 0.5 * smooth(0.04, 0.14, d);
    /* a little texture on each brick, periodic in u and v */
    brick += 0.03 * sin(2 * M_PI * 12 * u) * sin(2 * M_PI * 18 * v);
    return brick;
}

static double ripples(double u, double v)
{
    return 0.5 + 0.25 * sin(2 * M_PI * (9 * u + 4 * v)) * sin(2 * M_PI * (3 * u - 11 * v)) +
           0.15 * sin(2 * M_PI * 23 * u) * cos(2 * M_PI * 17 * v);
}

static int write(const char *dir, const char *name, int n, double (*f)(double, double))
{
    lx_image img;
    if (lx_image_alloc(&img, n, n, 1) != LX_OK)
        return 1;
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++)
            img.data[(size_t)y * n + x] = (float)f((x + 0.5) / n, (y + 0.5) / n);
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    lx_image_write_desc d = {.linear = true, .bits = 16};
    lx_status s = lx_image_write(path, &img, &d);
    lx_image_free(&img);
    if (s != LX_OK) {
        fprintf(stderr, "gen_heights: %s\n", lx_last_error());
        return 1;
    }
    printf("%s\n", path);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: gen_heights DIR [SIZE]\n");
        return 2;
    }
    int n = argc == 3 ? atoi(argv[2]) : 192;
    if (n < 8 || n > 8192) {
        fprintf(stderr, "gen_heights: SIZE must be in 8..8192\n");
        return 2;
    }
    return write(argv[1], "bumps.png", n, bumps) | write(argv[1], "bricks.png", n, bricks) |
           write(argv[1], "ripples.png", n, ripples);
}
