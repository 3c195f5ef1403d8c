/* Tone curves for 8-bit outputs (core.h): clamp, Hill's ACES fit and
 * Hable's filmic curve. */
#include "luxel/core.h"

#include <math.h>
#include <string.h>

/* Hill's fit: sRGB -> the ACES working space (with the reference rendering's
 * saturation folded in), the rational fit of RRT + ODT, then back. Each
 * row of both matrices sums to 1, so a grey input stays grey. */
static const float aces_in[3][3] = {
    {0.59719f, 0.35458f, 0.04823f},
    {0.07600f, 0.90834f, 0.01566f},
    {0.02840f, 0.13383f, 0.83777f},
};
static const float aces_out[3][3] = {
    {1.60475f, -0.53108f, -0.07367f},
    {-0.10208f, 1.10813f, -0.00605f},
    {-0.00327f, -0.07276f, 1.07602f},
};

static float aces_fit(float v)
{
    float a = v * (v + 0.0245786f) - 0.000090537f;
    float b = v * (0.983729f * v + 0.4329510f) + 0.238081f;
    return a / b;
}

static float hable(float x)
{
    const float A = 0.15f, B = 0.50f, C = 0.10f, D = 0.20f, E = 0.02f, F = 0.30f;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

#define FILMIC_WHITE 11.2f

static float unit(float v)
{
    return v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v; /* NaN passes through */
}

static float filmic(float v)
{
    return unit(hable(2.0f * (v > 0.0f ? v : 0.0f)) / hable(FILMIC_WHITE));
}

float lx_tonemap_grey(lx_tonemap curve, float v)
{
    switch (curve) {
    case LX_TONEMAP_ACES:
        /* the fit is negative just above 0: the output clamp cuts it */
        return unit(aces_fit(v > 0.0f ? v : 0.0f));
    case LX_TONEMAP_FILMIC:
        return filmic(v);
    case LX_TONEMAP_CLAMP:
    default:
        return unit(v);
    }
}

void lx_tonemap_rgb(lx_tonemap curve, float rgb[3])
{
    if (curve != LX_TONEMAP_ACES) {
        for (int k = 0; k < 3; k++)
            rgb[k] = lx_tonemap_grey(curve, rgb[k]);
        return;
    }
    float fitted[3];
    for (int r = 0; r < 3; r++) {
        float v = aces_in[r][0] * rgb[0] + aces_in[r][1] * rgb[1] + aces_in[r][2] * rgb[2];
        fitted[r] = aces_fit(v > 0.0f ? v : 0.0f);
    }
    for (int r = 0; r < 3; r++)
        rgb[r] = unit(aces_out[r][0] * fitted[0] + aces_out[r][1] * fitted[1] +
                      aces_out[r][2] * fitted[2]);
}

const char *lx_tonemap_name(lx_tonemap curve)
{
    switch (curve) {
    case LX_TONEMAP_CLAMP:
        return "clamp";
    case LX_TONEMAP_ACES:
        return "aces";
    case LX_TONEMAP_FILMIC:
        return "filmic";
    }
    return NULL;
}

bool lx_tonemap_parse(const char *name, lx_tonemap *out)
{
    for (int c = LX_TONEMAP_CLAMP; c <= LX_TONEMAP_FILMIC; c++)
        if (name && strcmp(name, lx_tonemap_name((lx_tonemap)c)) == 0) {
            *out = (lx_tonemap)c;
            return true;
        }
    return false;
}
