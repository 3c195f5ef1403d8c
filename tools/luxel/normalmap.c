/* luxel normalmap: a tangent-space normal map from a height image
 * (lx_normal_map), or two normal maps blended (lx_normal_blend_image),
 * written as one image of the input's size, texel for texel. */
#define _POSIX_C_SOURCE 200809L
#include "maps_cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *normalmap_usage =
    "usage: luxel normalmap HEIGHT -o OUT [options]\n"
    "       luxel normalmap --blend BASE DETAIL -o OUT [--method M] [options]\n"
    "\n"
    "Makes a tangent-space normal map from HEIGHT: a grey 8- or 16-bit PNG\n"
    "(values code/255 or code/65535; the first channel of a colour image) or\n"
    "a float image (EXR, PFM, HDR) as stored. A value v is a height of S v\n"
    "texels; x runs along the columns, y up the image, and the normal is\n"
    "normalize(-S dh/dx, -S dh/dy, 1), stored as rgb = n/2 + 1/2 (PNG codes\n"
    "rounded to nearest, no sRGB). OUT has HEIGHT's size and its pixel (x, y)\n"
    "is the normal of height texel (x, y). docs/maps.md has the conventions.\n"
    "\n"
    "With --blend, adds the detail normal map DETAIL to BASE (both encoded as\n"
    "above, same size, same green convention, which OUT keeps).\n"
    "\n"
    "options:\n"
    "  -o, --output OUT     the normal map (.png, .exr or .pfm)\n"
    "  --strength S         texels of height per unit value (default %g)\n"
    "  --invert             HEIGHT is a depth map: larger values lie deeper\n"
    "  --filter F           slopes: central (default; the seed's differences),\n"
    "                       sobel or scharr (smoothed across; same slope on a ramp)\n"
    "  --wrap W             texels beyond the edges: repeat (default; tiles),\n"
    "                       clamp or mirror\n"
    "  --green G            up (default; OpenGL, glTF) or down (DirectX)\n"
    "  --bits N             png bits per channel: 8 (default) or 16\n"
    "  --format F           png, exr or pfm (default: from OUT's name)\n"
    "  --blend              blend BASE and DETAIL instead\n"
    "  --method M           blend: rnm (default; reoriented normal mapping),\n"
    "                       udn or whiteout (Barre-Brisebois and Hill 2012)\n"
    "  --threads N          worker threads (default: all cores)\n"
    "  -v, --verbose        the time of each phase\n"
    "  -q, --quiet          no progress bar or summary\n"
    "  -h, --help           show this help\n";

enum { OPT_BLEND = MAPS_OPT_OWN, OPT_METHOD, OPT_INVERT };

typedef struct normalmap_args {
    const char *inputs[2];
    int input_count;
    maps_output out;
    lx_normalmap_desc desc;
    bool blend, quiet;
    bool invert;               /* HEIGHT is a depth map: higher values lie deeper */
    const char *height_option; /* --strength, --filter, --wrap or --invert given */
    bool method_given;
    lx_normal_blend_method method;
} normalmap_args;

static int parse_args(int argc, char **argv, normalmap_args *a)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"strength", required_argument, NULL, MAPS_OPT_STRENGTH},
                                            {"filter", required_argument, NULL, MAPS_OPT_FILTER},
                                            {"wrap", required_argument, NULL, MAPS_OPT_WRAP},
                                            {"green", required_argument, NULL, MAPS_OPT_GREEN},
                                            {"bits", required_argument, NULL, MAPS_OPT_BITS},
                                            {"format", required_argument, NULL, MAPS_OPT_FORMAT},
                                            {"blend", no_argument, NULL, OPT_BLEND},
                                            {"method", required_argument, NULL, OPT_METHOD},
                                            {"invert", no_argument, NULL, OPT_INVERT},
                                            {"threads", required_argument, NULL, CLI_OPT_THREADS},
                                            {"quiet", no_argument, NULL, 'q'},
                                            {"verbose", no_argument, NULL, 'v'},
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    maps_common m = {0};
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":o:qvh", options, NULL)) != -1) {
        switch (c) {
        case OPT_BLEND:
            a->blend = true;
            break;
        case OPT_INVERT:
            a->invert = true;
            break;
        case OPT_METHOD:
            if (!lx_normal_blend_parse(optarg, &a->method))
                return cli_usage_error("normalmap", "--method must be rnm, udn or whiteout, not '%s'",
                                       optarg);
            a->method_given = true;
            break;
        case 'h': {
            lx_normalmap_desc d = lx_normalmap_desc_defaults(NULL);
            printf(normalmap_usage, (double)d.strength);
            return -1;
        }
        default: {
            int rc = maps_common_option("normalmap", c, argv, &m);
            if (rc != 0)
                return rc;
        }
        }
    }
    a->out = m.out;
    a->desc.strength = m.strength;
    a->desc.filter = m.filter;
    a->desc.wrap = m.wrap;
    a->desc.green_down = m.green_down;
    a->desc.threads = m.threads;
    a->quiet = m.quiet;
    a->height_option = m.height_option ? m.height_option : a->invert ? "--invert" : NULL;
    int want = a->blend ? 2 : 1;
    a->input_count = argc - optind;
    if (a->input_count < want)
        return cli_usage_error("normalmap", a->blend ? "--blend needs BASE and DETAIL"
                                                     : "no height image given");
    if (a->input_count > want)
        return cli_usage_error("normalmap", "'%s' is extra", argv[optind + want]);
    for (int i = 0; i < want; i++)
        a->inputs[i] = argv[optind + i];
    if (a->blend && a->height_option)
        return cli_usage_error("normalmap", "%s is for heights, not --blend", a->height_option);
    if (!a->blend && a->method_given)
        return cli_usage_error("normalmap", "--method is for --blend");
    return maps_output_resolve("normalmap", &a->out);
}

static void report(lx_status s)
{
    if (s == LX_ERR_CANCELLED)
        cli_report_interrupt(false);
    else
        cli_error("%s", lx_last_error());
}

/* The normal map of a height image, encoded; *out zeroed on failure. */
static bool from_height(normalmap_args *a, lx_image *encoded)
{
    lx_image height, normals;
    lx_status s = lx_height_load(a->inputs[0], &height);
    if (s != LX_OK) {
        cli_error("%s", lx_last_error());
        return false;
    }
    cli_phase("load");
    /* a depth map: the heights are its values negated */
    for (size_t i = 0; a->invert && i < (size_t)height.width * (size_t)height.height; i++)
        height.data[i * (size_t)height.channels] = -height.data[i * (size_t)height.channels];
    cli_progress progress;
    cli_progress_init(&progress, "normalmap", a->quiet);
    a->desc.progress = cli_progress_update;
    a->desc.progress_user = &progress;
    s = lx_normal_map(&height, &a->desc, &normals);
    cli_progress_finish(&progress);
    lx_image_free(&height);
    if (s != LX_OK) {
        if (s != LX_ERR_CANCELLED)
            cli_error("%s: %s", a->inputs[0], lx_last_error());
        else
            report(s);
        return false;
    }
    s = lx_normal_encode(&normals, encoded);
    lx_image_free(&normals);
    if (s != LX_OK)
        report(s);
    return s == LX_OK;
}

/* An encoded normal map read as unit normals. */
static bool load_normals(const char *path, lx_image *out)
{
    lx_image img;
    lx_image_load_desc ld = {.raw_8bit = true};
    lx_status s = lx_image_load(path, &ld, &img);
    if (s == LX_OK) {
        /* names the file for an image with no pixels or too few channels */
        s = lx_normal_decode(&img, path, out);
        lx_image_free(&img);
    }
    if (s != LX_OK)
        cli_error("%s", lx_last_error());
    return s == LX_OK;
}

static bool blended(normalmap_args *a, lx_image *encoded)
{
    lx_image base, detail, r;
    if (!load_normals(a->inputs[0], &base))
        return false;
    if (!load_normals(a->inputs[1], &detail)) {
        lx_image_free(&base);
        return false;
    }
    bool ok = false;
    if (base.width != detail.width || base.height != detail.height) {
        cli_error("%s: %s, but the base %s is %s: sizes must match", a->inputs[1],
                  maps_size(&detail), a->inputs[0], maps_size(&base));
    } else {
        cli_phase("load");
        lx_status s = lx_normal_blend_image(a->method, &base, &detail, a->desc.threads, &r);
        if (s == LX_OK) {
            s = lx_normal_encode(&r, encoded);
            lx_image_free(&r);
        }
        if (s != LX_OK)
            report(s);
        ok = s == LX_OK;
    }
    lx_image_free(&base);
    lx_image_free(&detail);
    return ok;
}

int cmd_normalmap(int argc, char **argv)
{
    normalmap_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    cli_stage st;
    if (!maps_output_begin(&a.out, &st))
        return EXIT_FAILED;
    lx_image encoded = {0};
    bool ok = a.blend ? blended(&a, &encoded) : from_height(&a, &encoded);
    if (ok) {
        cli_phase(a.blend ? "blend" : "normal map");
        ok = maps_output_write(&a.out, &st, &encoded, a.desc.threads, a.quiet);
        cli_phase("write");
    }
    cli_stage_clear(&st);
    if (ok && !a.quiet) {
        lx_normalmap_desc d = lx_normalmap_desc_defaults(&a.desc);
        const char *bits = a.out.format == LX_IMAGE_PNG ? (a.out.bits == 16 ? ", 16-bit" : ", 8-bit")
                                                        : "";
        if (a.blend)
            fprintf(stderr, "luxel: blended normal map %s (%s%s) in %.2f s\n",
                    maps_size(&encoded), lx_normal_blend_name(a.method), bits, cli_elapsed());
        else
            fprintf(stderr,
                    "luxel: normal map %s (%s, strength %s, %s, green %s%s) in %.2f s\n",
                    maps_size(&encoded), lx_normal_filter_name(d.filter), cli_num(d.strength),
                    lx_wrap_name(d.wrap), d.green_down ? "down" : "up", bits, cli_elapsed());
        printf("%s\n", a.out.path);
    }
    lx_image_free(&encoded);
    return ok ? EXIT_OK : EXIT_FAILED;
}
