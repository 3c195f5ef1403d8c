/* luxel light2d: shadowed 2D lights over a caster image (lx_light2d,
 * docs/light2d.md), written as an image of albedo x light and, on request,
 * the light map alone. Outputs are staged and published together: a failed
 * run leaves no file. --frames N renders N frames through the per-frame API
 * as a game would and reports the frame rate. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <getopt.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char *light2d_usage =
    "usage: luxel light2d --casters C.png --lights L.json -o OUT [options]\n"
    "\n"
    "Lights a 2D scene: every light of L.json (point or spot, falloff, colour or\n"
    "temperature, soft shadows, height over normal maps) casts shadows from the\n"
    "caster pixels of C.png (alpha >= --threshold). The image written is\n"
    "albedo x (ambient + sum of lights). docs/light2d.md has the lights schema.\n"
    "\n"
    "options:\n"
    "  --casters FILE      the shadow casters (an image with alpha; with --mask\n"
    "                      a grey mask, casters where it is >= the threshold)\n"
    "  --lights FILE       the lights JSON (required)\n"
    "  -o, --output FILE   the lit image: .png (sRGB), .exr, .pfm or .hdr (linear)\n"
    "  --albedo FILE       the colours lit (default white), the casters' size;\n"
    "                      its alpha, when it has one, is the output's (PNG, EXR)\n"
    "  --normals FILE      tangent-space normal map, the casters' size\n"
    "  --green up|down     the normal map's green axis (default up)\n"
    "  --mask              casters from the first channel, not alpha\n"
    "  --threshold T       caster threshold in [0, 1] (default 0.5)\n"
    "  --light-map FILE    also write ambient + sum of lights (.exr, .pfm, .hdr, .png)\n"
    "  --threads N         worker threads (default: all cores)\n"
    "  --frames N          render N frames through the per-frame API (dynamic\n"
    "                      lights re-lit every frame) and print the frame rate\n"
    "  -q, --quiet         no summary\n"
    "  -h, --help          show this help\n";

enum {
    OPT_CASTERS = 256,
    OPT_LIGHTS,
    OPT_ALBEDO,
    OPT_NORMALS,
    OPT_GREEN,
    OPT_MASK,
    OPT_THRESHOLD,
    OPT_LIGHT_MAP,
    OPT_FRAMES
};

typedef struct l2_args {
    const char *casters, *lights, *output, *albedo, *normals, *light_map;
    bool green_down, mask, quiet;
    double threshold;
    int threads;
    long frames;
} l2_args;

static bool output_format_ok(const char *path)
{
    lx_image_format f = lx_image_format_from_path(path);
    return f == LX_IMAGE_PNG || f == LX_IMAGE_EXR || f == LX_IMAGE_PFM || f == LX_IMAGE_HDR;
}

static int parse_args(int argc, char **argv, l2_args *a)
{
    static const struct option options[] = {{"casters", required_argument, NULL, OPT_CASTERS},
                                            {"lights", required_argument, NULL, OPT_LIGHTS},
                                            {"output", required_argument, NULL, 'o'},
                                            {"albedo", required_argument, NULL, OPT_ALBEDO},
                                            {"normals", required_argument, NULL, OPT_NORMALS},
                                            {"green", required_argument, NULL, OPT_GREEN},
                                            {"mask", no_argument, NULL, OPT_MASK},
                                            {"threshold", required_argument, NULL, OPT_THRESHOLD},
                                            {"light-map", required_argument, NULL, OPT_LIGHT_MAP},
                                            {"threads", required_argument, NULL, CLI_OPT_THREADS},
                                            {"frames", required_argument, NULL, OPT_FRAMES},
                                            {"quiet", no_argument, NULL, 'q'},
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->threshold = 0.5;
    opterr = 0;
    optind = 1;
    int c;
    long n;
    while ((c = getopt_long(argc, argv, ":o:qh", options, NULL)) != -1) {
        switch (c) {
        case OPT_CASTERS:
            a->casters = optarg;
            break;
        case OPT_LIGHTS:
            a->lights = optarg;
            break;
        case 'o':
            a->output = optarg;
            break;
        case OPT_ALBEDO:
            a->albedo = optarg;
            break;
        case OPT_NORMALS:
            a->normals = optarg;
            break;
        case OPT_LIGHT_MAP:
            a->light_map = optarg;
            break;
        case OPT_GREEN:
            if (strcmp(optarg, "up") == 0)
                a->green_down = false;
            else if (strcmp(optarg, "down") == 0)
                a->green_down = true;
            else
                return cli_usage_error("light2d", "--green must be up or down, not '%s'", optarg);
            break;
        case OPT_MASK:
            a->mask = true;
            break;
        case OPT_THRESHOLD:
            if (!cli_parse_float(optarg, 0.0, 1.0, &a->threshold))
                return cli_usage_error("light2d", "--threshold must be in [0, 1], not '%s'",
                                       optarg);
            break;
        case OPT_FRAMES:
            if (!cli_parse_int(optarg, 1, 1000000, &n))
                return cli_usage_error("light2d", "--frames must be 1..1000000, not '%s'",
                                       optarg);
            a->frames = n;
            break;
        case 'h':
            fputs(light2d_usage, stdout);
            return -1;
        default: {
            int rc = cli_common_option("light2d", c, argv, &a->threads, &a->quiet);
            if (rc != 0)
                return rc;
        }
        }
    }
    if (optind < argc)
        return cli_usage_error("light2d", "unexpected argument '%s'", argv[optind]);
    if (!a->casters || !*a->casters)
        return cli_usage_error("light2d", "--casters is required");
    if (!a->lights || !*a->lights)
        return cli_usage_error("light2d", "--lights is required");
    if (!a->output || !*a->output)
        return cli_usage_error("light2d", "-o is required");
    if (!output_format_ok(a->output))
        return cli_usage_error("light2d", "-o must end in .png, .exr, .pfm or .hdr, not '%s'",
                               a->output);
    if (a->light_map && !output_format_ok(a->light_map))
        return cli_usage_error("light2d",
                               "--light-map must end in .png, .exr, .pfm or .hdr, not '%s'",
                               a->light_map);
    cli_set_quiet(a->quiet);
    return 0;
}

static bool load_image(const char *path, bool raw, lx_image *img)
{
    lx_image_load_desc d = {.raw_8bit = raw};
    if (lx_image_load(path, &d, img) != LX_OK) {
        cli_error("%s", lx_last_error());
        return false;
    }
    return true;
}

static bool same_size(const char *casters, const lx_image *c, const char *path,
                      const lx_image *img)
{
    if (img->width == c->width && img->height == c->height)
        return true;
    cli_error("%s: %dx%d, but the casters (%s) are %dx%d", path, img->width, img->height,
              casters, c->width, c->height);
    return false;
}

/* out (RGB) becomes RGBA with the alpha of albedo (RGBA, same size). */
static bool with_alpha(lx_image *out, const lx_image *albedo)
{
    lx_image rgba;
    if (lx_image_alloc(&rgba, out->width, out->height, 4) != LX_OK)
        return false;
    size_t n = (size_t)out->width * (size_t)out->height;
    for (size_t i = 0; i < n; i++) {
        memcpy(&rgba.data[4 * i], &out->data[3 * i], 3 * sizeof(float));
        rgba.data[4 * i + 3] = albedo->data[4 * i + 3];
    }
    lx_image_free(out);
    *out = rgba;
    return true;
}

/* Stages one image in the folder of `path` and publishes it. */
typedef struct l2_out {
    cli_stage st;
    char *dir, *name;
    bool begun;
} l2_out;

static bool out_begin(l2_out *o, const char *path)
{
    memset(o, 0, sizeof *o);
    char *a = cli_strdup(path), *b = cli_strdup(path);
    if (!a || !b) {
        free(a);
        free(b);
        cli_error("out of memory");
        return false;
    }
    o->dir = cli_strdup(dirname(a));
    o->name = cli_strdup(basename(b));
    free(a);
    free(b);
    if (!o->dir || !o->name) {
        cli_error("out of memory");
        return false;
    }
    if (!cli_stage_begin(&o->st, o->dir))
        return false;
    o->begun = true;
    return cli_stage_check(&o->st, o->name);
}

static void out_end(l2_out *o)
{
    if (o->begun)
        cli_stage_clear(&o->st);
    free(o->dir);
    free(o->name);
}

static int run(const l2_args *a)
{
    int status = EXIT_FAILED;
    lx_image casters = {0}, albedo = {0}, normals = {0}, out = {0}, lm = {0};
    lx_light2d_scene scene = {0};
    lx_light2d *ctx = NULL;
    l2_out o1, o2;
    memset(&o1, 0, sizeof o1);
    memset(&o2, 0, sizeof o2);
    if (!load_image(a->casters, false, &casters))
        goto done;
    if (!a->mask && casters.channels != 2 && casters.channels != 4) {
        cli_error("%s: the image has no alpha channel (use --mask for a grey mask)", a->casters);
        goto done;
    }
    if (a->albedo && (!load_image(a->albedo, false, &albedo) ||
                      !same_size(a->casters, &casters, a->albedo, &albedo)))
        goto done;
    if (a->albedo && albedo.channels < 3) {
        cli_error("%s: %d channel%s, the albedo must be RGB", a->albedo, albedo.channels,
                  albedo.channels == 1 ? "" : "s");
        goto done;
    }
    if (a->normals && (!load_image(a->normals, true, &normals) ||
                       !same_size(a->casters, &casters, a->normals, &normals)))
        goto done;
    if (a->normals && normals.channels < 3) {
        cli_error("%s: %d channel%s, a normal map must be RGB", a->normals, normals.channels,
                  normals.channels == 1 ? "" : "s");
        goto done;
    }
    if (lx_light2d_scene_load(a->lights, &scene) != LX_OK) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    if (!out_begin(&o1, a->output) || (a->light_map && !out_begin(&o2, a->light_map)))
        goto done;
    lx_light2d_desc desc = {.threshold = (float)a->threshold, .mask = a->mask,
                            .threads = a->threads};
    if (a->threshold == 0.0)
        desc.threshold = 1e-30f; /* every pixel with any alpha */
    if (lx_light2d_create(&casters, &desc, &ctx) != LX_OK ||
        (a->normals && lx_light2d_set_normals(ctx, &normals, a->green_down) != LX_OK)) {
        cli_error("%s: %s", a->casters, lx_last_error());
        goto done;
    }
    if (lx_image_alloc(&out, casters.width, casters.height, 3) != LX_OK ||
        (a->light_map && lx_image_alloc(&lm, casters.width, casters.height, 3) != LX_OK)) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    long frames = a->frames > 0 ? a->frames : 1;
    double t0 = cli_now();
    for (long f = 0; f < frames; f++) {
        if (lx_light2d_set_lights(ctx, scene.lights, scene.count) != LX_OK) {
            cli_error("%s: %s", a->lights, lx_last_error());
            goto done;
        }
        if (lx_light2d_render(ctx, scene.ambient, a->albedo ? &albedo : NULL, out.data,
                              a->light_map ? lm.data : NULL) != LX_OK) {
            cli_error("%s", lx_last_error());
            goto done;
        }
        if (cli_interrupted()) {
            cli_report_interrupt(true);
            goto done;
        }
    }
    double seconds = cli_now() - t0;
    /* the albedo's alpha carries over: transparent pixels stay transparent
     * (PNG and EXR hold it; PFM and HDR cannot, and say so) */
    if (a->albedo && albedo.channels == 4) {
        const char *dot = strrchr(a->output, '.');
        bool holds_alpha = dot && (strcasecmp(dot, ".png") == 0 || strcasecmp(dot, ".exr") == 0);
        if (!holds_alpha) {
            lx_log(LX_LOG_WARN, "%s: %s holds no alpha: the albedo's (%s) is left out", a->output,
                   dot ? dot + 1 : "the format", a->albedo);
        } else if (!with_alpha(&out, &albedo)) {
            cli_error("%s: out of memory", a->output);
            goto done;
        }
    }
    lx_image_write_desc wd = {.threads = a->threads};
    if (!cli_stage_image(&o1.st, o1.name, &out, &wd) ||
        (a->light_map && !cli_stage_image(&o2.st, o2.name, &lm, &wd)))
        goto done;
    if (!cli_stage_publish(&o1.st) || (a->light_map && !cli_stage_publish(&o2.st)))
        goto done;
    if (a->frames > 0)
        printf("light2d: %ld frames in %.3f s (%.1f frames/s)\n", frames, seconds,
               seconds > 0.0 ? frames / seconds : 0.0);
    if (!a->quiet)
        fprintf(stderr, "luxel: lit %dx%d with %d light%s in %.2f s\n", casters.width,
                casters.height, scene.count, scene.count == 1 ? "" : "s", cli_elapsed());
    status = EXIT_OK;
done:
    out_end(&o2);
    out_end(&o1);
    lx_light2d_destroy(ctx);
    lx_light2d_scene_free(&scene);
    lx_image_free(&casters);
    lx_image_free(&albedo);
    lx_image_free(&normals);
    lx_image_free(&out);
    lx_image_free(&lm);
    return status;
}

int cmd_light2d(int argc, char **argv)
{
    l2_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    return run(&a);
}
