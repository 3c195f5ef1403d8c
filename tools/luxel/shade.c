/* luxel shade: a material preview (lx_shade) of a height or normal map,
 * optionally with a base colour, on a quad or a sphere under one
 * directional light, written as an sRGB PNG (exposure and tone curve) or
 * a linear float image. */
#define _POSIX_C_SOURCE 200809L
#include "maps_cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *shade_usage =
    "usage: luxel shade (--height H | --normal N) [--base-color C] -o OUT [options]\n"
    "\n"
    "Renders a material preview: the height map H (or the tangent-space normal\n"
    "map N) on a quad filling the frame or on a sphere, lit by one directional\n"
    "light with Lambert diffuse and Blinn-Phong specular (seed 002), the texture\n"
    "coordinates moved by parallax offset and the light shadowed by the\n"
    "heights' horizon map (both need --height). C is an sRGB colour image\n"
    "(default grey 0.8). OUT is an sRGB PNG (exposed and tone mapped) or a\n"
    "linear .exr/.pfm. docs/maps.md has the conventions.\n"
    "\n"
    "options:\n"
    "  --height H           height image (as normalmap reads it)\n"
    "  --normal N           normal map (rgb = n/2 + 1/2) instead\n"
    "  --base-color C       base colour image\n"
    "  -o, --output OUT     the picture (.png, .exr or .pfm)\n"
    "  --shape S            quad (default) or sphere\n"
    "  --light AZ,EL        light azimuth (from +x, counter-clockwise) and\n"
    "                       elevation in degrees (default 135,35)\n"
    "  --strength S         texels of height per unit value (default %g)\n"
    "  --size WxH           picture size (default 512x512)\n"
    "  --exposure EV        png: exposure in stops (default 0)\n"
    "  --tonemap T          png: filmic (default), aces or clamp\n"
    "  --ambient A          ambient illuminance (default 0)\n"
    "  --no-parallax        no parallax offset\n"
    "  --no-horizon         no horizon shadows\n"
    "  --no-specular        no specular term\n"
    "  --green G            normal map's green: up (default) or down\n"
    "  --wrap W             texels beyond the edges: repeat (default), clamp, mirror\n"
    "  --threads N          worker threads (default: all cores)\n"
    "  -v, --verbose        the time of each phase\n"
    "  -q, --quiet          no progress bar or summary\n"
    "  -h, --help           show this help\n";

enum {
    OPT_HEIGHT = MAPS_OPT_OWN,
    OPT_NORMAL,
    OPT_BASE,
    OPT_SHAPE,
    OPT_LIGHT,
    OPT_SIZE,
    OPT_EXPOSURE,
    OPT_TONEMAP,
    OPT_AMBIENT,
    OPT_NO_PARALLAX,
    OPT_NO_HORIZON,
    OPT_NO_SPECULAR
};

typedef struct shade_args {
    const char *height, *normal, *base;
    maps_output out;
    lx_shade_desc desc;
    float exposure;
    lx_tonemap tonemap;
    bool quiet;
} shade_args;

static int parse_args(int argc, char **argv, shade_args *a)
{
    static const struct option options[] = {{"height", required_argument, NULL, OPT_HEIGHT},
                                            {"normal", required_argument, NULL, OPT_NORMAL},
                                            {"base-color", required_argument, NULL, OPT_BASE},
                                            {"output", required_argument, NULL, 'o'},
                                            {"shape", required_argument, NULL, OPT_SHAPE},
                                            {"light", required_argument, NULL, OPT_LIGHT},
                                            {"strength", required_argument, NULL, MAPS_OPT_STRENGTH},
                                            {"size", required_argument, NULL, OPT_SIZE},
                                            {"exposure", required_argument, NULL, OPT_EXPOSURE},
                                            {"tonemap", required_argument, NULL, OPT_TONEMAP},
                                            {"ambient", required_argument, NULL, OPT_AMBIENT},
                                            {"no-parallax", no_argument, NULL, OPT_NO_PARALLAX},
                                            {"no-horizon", no_argument, NULL, OPT_NO_HORIZON},
                                            {"no-specular", no_argument, NULL, OPT_NO_SPECULAR},
                                            {"green", required_argument, NULL, MAPS_OPT_GREEN},
                                            {"wrap", required_argument, NULL, MAPS_OPT_WRAP},
                                            {"threads", required_argument, NULL, CLI_OPT_THREADS},
                                            {"quiet", no_argument, NULL, 'q'},
                                            {"verbose", no_argument, NULL, 'v'},
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->tonemap = LX_TONEMAP_FILMIC;
    maps_common m = {0};
    opterr = 0;
    optind = 1;
    int c;
    double f;
    while ((c = getopt_long(argc, argv, ":o:qvh", options, NULL)) != -1) {
        switch (c) {
        case OPT_HEIGHT: a->height = optarg; break;
        case OPT_NORMAL: a->normal = optarg; break;
        case OPT_BASE: a->base = optarg; break;
        case OPT_SHAPE:
            if (strcmp(optarg, "quad") == 0)
                a->desc.shape = LX_SHADE_QUAD;
            else if (strcmp(optarg, "sphere") == 0)
                a->desc.shape = LX_SHADE_SPHERE;
            else
                return cli_usage_error("shade", "--shape must be quad or sphere, not '%s'", optarg);
            break;
        case OPT_LIGHT: {
            double az, el;
            char tail;
            if (sscanf(optarg, "%lf,%lf%c", &az, &el, &tail) != 2 || !isfinite(az) ||
                !isfinite(el) || el < -90.0 || el > 90.0)
                return cli_usage_error("shade",
                                       "--light must be AZ,EL in degrees (EL in -90..90), not '%s'",
                                       optarg);
            a->desc.light = lx_shade_light_dir((float)az, (float)el);
            break;
        }
        case OPT_SIZE: {
            int w, h;
            char tail;
            if (sscanf(optarg, "%dx%d%c", &w, &h, &tail) != 2 || w < 1 || h < 1 || w > 16384 ||
                h > 16384)
                return cli_usage_error("shade", "--size must be WxH from 1 to 16384, not '%s'",
                                       optarg);
            a->desc.out_width = w;
            a->desc.out_height = h;
            break;
        }
        case OPT_EXPOSURE:
            if (!cli_parse_float(optarg, -30, 30, &f))
                return cli_usage_error("shade", "--exposure must be stops in -30..30, not '%s'",
                                       optarg);
            a->exposure = (float)exp2(f);
            break;
        case OPT_TONEMAP:
            if (!lx_tonemap_parse(optarg, &a->tonemap))
                return cli_usage_error("shade", "--tonemap must be filmic, aces or clamp, not '%s'",
                                       optarg);
            break;
        case OPT_AMBIENT:
            if (!cli_parse_float(optarg, 0, 1e6, &f))
                return cli_usage_error("shade", "--ambient must be a number in 0..1e6, not '%s'",
                                       optarg);
            a->desc.ambient = (float)f;
            break;
        case OPT_NO_PARALLAX: a->desc.no_parallax = true; break;
        case OPT_NO_HORIZON: a->desc.no_horizon = true; break;
        case OPT_NO_SPECULAR: a->desc.no_specular = true; break;
        case 'h':
            printf(shade_usage, (double)LX_DEFAULT_HEIGHT_STRENGTH);
            return -1;
        default: {
            int rc = maps_common_option("shade", c, argv, &m);
            if (rc != 0)
                return rc;
        }
        }
    }
    a->out = m.out;
    a->desc.strength = m.strength;
    a->desc.green_down = m.green_down;
    a->desc.wrap = m.wrap;
    a->desc.threads = m.threads;
    a->quiet = m.quiet;
    if (optind < argc)
        return cli_usage_error("shade", "'%s' is extra", argv[optind]);
    if (!a->height == !a->normal)
        return cli_usage_error("shade", a->height ? "give --height or --normal, not both"
                                                  : "no input given (--height H or --normal N)");
    return maps_output_resolve("shade", &a->out);
}

/* The inputs loaded; false with the error printed. */
static bool load_inputs(const shade_args *a, lx_image *height, lx_image *normals, lx_image *base)
{
    lx_status s;
    if (a->height) {
        s = lx_height_load(a->height, height);
    } else {
        lx_image img;
        lx_image_load_desc ld = {.raw_8bit = true};
        s = lx_image_load(a->normal, &ld, &img);
        if (s == LX_OK) {
            s = lx_normal_decode(&img, a->normal, normals);
            lx_image_free(&img);
        }
    }
    if (s == LX_OK && a->base) {
        s = lx_image_load(a->base, NULL, base);
        if (s == LX_OK && base->channels < 3) {
            cli_error("%s: %d channel(s); a base colour needs 3 or 4 (RGB)", a->base,
                      base->channels);
            return false;
        }
    }
    if (s != LX_OK)
        cli_error("%s", lx_last_error());
    return s == LX_OK;
}

int cmd_shade(int argc, char **argv)
{
    shade_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    cli_stage st;
    if (!maps_output_begin(&a.out, &st))
        return EXIT_FAILED;
    lx_image height = {0}, normals = {0}, base = {0}, img = {0};
    bool ok = load_inputs(&a, &height, &normals, &base);
    if (ok) {
        cli_phase("load");
        a.desc.height = a.height ? &height : NULL;
        a.desc.normals = a.normal ? &normals : NULL;
        a.desc.base_color = a.base ? &base : NULL;
        cli_progress progress;
        cli_progress_init(&progress, "shade", a.quiet);
        a.desc.progress = cli_progress_update;
        a.desc.progress_user = &progress;
        lx_status s = lx_shade(&a.desc, &img);
        cli_progress_finish(&progress);
        if (s == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else if (s != LX_OK)
            cli_error("%s: %s", a.height ? a.height : a.normal, lx_last_error());
        ok = s == LX_OK;
    }
    if (ok) {
        cli_phase("shade");
        cli_progress progress;
        cli_progress_init(&progress, "write", a.quiet);
        lx_image_write_desc wd = {.format = a.out.format,
                                  .exposure = a.exposure,
                                  .tonemap = a.tonemap,
                                  .bits = a.out.format == LX_IMAGE_PNG ? a.out.bits : 0,
                                  .threads = a.desc.threads,
                                  .progress = cli_progress_update,
                                  .progress_user = &progress};
        const char *slash = strrchr(a.out.path, '/');
        ok = cli_stage_image(&st, slash ? slash + 1 : a.out.path, &img, &wd);
        cli_progress_finish(&progress);
        ok = ok && cli_stage_publish(&st);
        cli_phase("write");
    }
    cli_stage_clear(&st);
    if (ok && !a.quiet) {
        fprintf(stderr, "luxel: shaded %s %s in %.2f s\n",
                a.desc.shape == LX_SHADE_SPHERE ? "sphere" : "quad", maps_size(&img),
                cli_elapsed());
        printf("%s\n", a.out.path);
    }
    lx_image_free(&height);
    lx_image_free(&normals);
    lx_image_free(&base);
    lx_image_free(&img);
    return ok ? EXIT_OK : EXIT_FAILED;
}
