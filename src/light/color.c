/* Light colours: colour temperature to linear sRGB as Filament does (R. Guy
 * and M. Agopian, "Physically Based Rendering in Filament"): the Planckian locus in CIE 1960 UCS by
 * Krystek's rational approximation (M. Krystek, "An algorithm to calculate correlated colour
 * temperature", Color Research & Application 10, 1985), CIE 1960 uv to
 * CIE 1931 xy, to XYZ at Y = 1, to linear sRGB with the IEC 61966-2-1
 * matrix, normalized to a largest channel of 1. */
#include "luxel/light.h"
#include "core/internal.h"

lx_status lx_temperature_to_xy(float kelvin, float *x, float *y)
{
    if (!x)
        return lx_fail_null(__func__, "x");
    if (!y)
        return lx_fail_null(__func__, "y");
    if (!(kelvin >= LX_MIN_TEMPERATURE && kelvin <= LX_MAX_TEMPERATURE))
        return lx_fail(LX_ERR_INVALID, "colour temperature %g K is outside %g..%g K",
                       (double)kelvin, (double)LX_MIN_TEMPERATURE, (double)LX_MAX_TEMPERATURE);
    double t = kelvin, t2 = t * t;
    double u = (0.860117757 + 1.54118254e-4 * t + 1.28641212e-7 * t2) /
               (1.0 + 8.42420235e-4 * t + 7.08145163e-7 * t2);
    double v = (0.317398726 + 4.22806245e-5 * t + 4.20481691e-8 * t2) /
               (1.0 - 2.89741816e-5 * t + 1.61456053e-7 * t2);
    double d = 2.0 * u - 8.0 * v + 4.0;
    *x = (float)(3.0 * u / d);
    *y = (float)(2.0 * v / d);
    return LX_OK;
}

lx_status lx_temperature_to_rgb(float kelvin, lx_vec3 *rgb)
{
    if (!rgb)
        return lx_fail_null(__func__, "rgb");
    float xf, yf;
    lx_status st = lx_temperature_to_xy(kelvin, &xf, &yf);
    if (st != LX_OK)
        return st;
    double x = xf, y = yf;
    double X = x / y, Y = 1.0, Z = (1.0 - x - y) / y;
    double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
    double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
    double b = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
    /* below ~1900 K blue leaves the sRGB gamut: the nearest displayable hue */
    r = r > 0.0 ? r : 0.0;
    g = g > 0.0 ? g : 0.0;
    b = b > 0.0 ? b : 0.0;
    double m = r > g ? (r > b ? r : b) : (g > b ? g : b);
    *rgb = lx_v3((float)(r / m), (float)(g / m), (float)(b / m));
    return LX_OK;
}

lx_vec3 lx_srgb_color_to_linear(lx_vec3 c)
{
    return lx_v3(lx_srgb_to_linear(c.x), lx_srgb_to_linear(c.y), lx_srgb_to_linear(c.z));
}
