/* Dilation (padding): each pass gives every empty texel next to filled ones
 * the average of its filled 8-neighbours, growing charts by one ring, so
 * bilinear filtering and mip levels near chart borders do not fetch black. */
#include "luxel/bake.h"

#include <stdlib.h>
#include <string.h>

void lx_dilate(float *data, uint8_t *mask, int width, int height, int channels, int passes)
{
    if (passes <= 0 || width <= 0 || height <= 0 || channels < 1 || channels > 4)
        return;
    size_t pixels = (size_t)width * height;
    uint8_t *next = malloc(pixels);
    if (!next)
        return; /* padding is cosmetic; a failed pass leaves texels as they are */
    for (int pass = 0; pass < passes; pass++) {
        memcpy(next, mask, pixels);
        bool changed = false;
        for (int y = 0; y < height; y++)
            for (int x = 0; x < width; x++) {
                size_t p = (size_t)y * width + x;
                if (mask[p])
                    continue;
                float sum[4] = {0, 0, 0, 0};
                int n = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int nx = x + dx, ny = y + dy;
                        if (nx < 0 || ny < 0 || nx >= width || ny >= height)
                            continue;
                        size_t q = (size_t)ny * width + nx;
                        if (!mask[q])
                            continue;
                        for (int c = 0; c < channels; c++)
                            sum[c] += data[q * channels + c];
                        n++;
                    }
                if (n == 0)
                    continue;
                for (int c = 0; c < channels; c++)
                    data[p * channels + c] = sum[c] / (float)n;
                next[p] = 1;
                changed = true;
            }
        memcpy(mask, next, pixels);
        if (!changed)
            break;
    }
    free(next);
}
