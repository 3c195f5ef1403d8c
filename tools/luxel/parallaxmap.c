/* luxel parallaxmap: the seed's parallax map n.z h of a height image
 * (lx_parallax_map), one grey image of the input's size. */
#define _POSIX_C_SOURCE 200809L
#include "maps_cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *parallaxmap_usage =
    "usage: luxel parallaxmap HEIGHT -o OUT [options]\n"
    "\n"
    "Makes the parallax map of HEIGHT (read as `luxel normalmap` reads it):\n"
    "per texel n.z v, v the height value and n.z the z of the texel's normal\n"
    "at strength S. A shader offsets texture coordinates toward the viewer\n"
    "by scale * n.z v per step (the seed's ApplyParallaxOffset); for heights\n"
    "of S texels, scale = S / (texture width) in u and S / height in v.\n"
    "OUT is grey, HEIGHT's size, texel for texel; PNG codes are linear.\n"
    "\n"
    "options:\n"
    "  -o, --output OUT     the parallax map (.png, .exr or .pfm)\n"
    "  --strength S         texels of height per unit value (default %g)\n"
    "  --filter F           slopes for n.z: central (default), sobel or scharr\n"
    "  --wrap W             texels beyond the edges: repeat (default), clamp or\n"
    "                       mirror\n"
    "  --bits N             png bits: 8 (default) or 16\n"
    "  --format F           png, exr or pfm (default: from OUT's name)\n"
    "  --threads N          worker threads (default: all cores)\n"
    "  -v, --verbose        the time of each phase\n"
    "  -q, --quiet          no progress bar or summary\n"
    "  -h, --help           show this help\n";

typedef struct parallax_args {
    const char *input;
    maps_output out;
    lx_normalmap_desc desc;
    bool quiet;
} parallax_args;

static int parse_args(int argc, char **argv, parallax_args *a)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"strength", required_argument, NULL, MAPS_OPT_STRENGTH},
                                            {"filter", required_argument, NULL, MAPS_OPT_FILTER},
                                            {"wrap", required_argument, NULL, MAPS_OPT_WRAP},
                                            {"bits", required_argument, NULL, MAPS_OPT_BITS},
                                            {"format", required_argument, NULL, MAPS_OPT_FORMAT},
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
        if (c == 'h') {
            lx_normalmap_desc d = lx_normalmap_desc_defaults(NULL);
            printf(parallaxmap_usage, (double)d.strength);
            return -1;
        }
        int rc = maps_common_option("parallaxmap", c, argv, &m);
        if (rc != 0)
            return rc;
    }
    a->out = m.out;
    a->desc.strength = m.strength;
    a->desc.filter = m.filter;
    a->desc.wrap = m.wrap;
    a->desc.threads = m.threads;
    a->quiet = m.quiet;
    if (optind >= argc)
        return cli_usage_error("parallaxmap", "no height image given");
    if (optind + 1 < argc)
        return cli_usage_error("parallaxmap", "'%s' is extra", argv[optind + 1]);
    a->input = argv[optind];
    return maps_output_resolve("parallaxmap", &a->out);
}

int cmd_parallaxmap(int argc, char **argv)
{
    parallax_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    cli_stage st;
    if (!maps_output_begin(&a.out, &st))
        return EXIT_FAILED;
    lx_image height, map = {0};
    lx_status s = lx_height_load(a.input, &height);
    bool ok = s == LX_OK;
    if (!ok)
        cli_error("%s", lx_last_error());
    if (ok) {
        cli_phase("load");
        cli_progress progress;
        cli_progress_init(&progress, "parallaxmap", a.quiet);
        a.desc.progress = cli_progress_update;
        a.desc.progress_user = &progress;
        s = lx_parallax_map(&height, &a.desc, &map);
        cli_progress_finish(&progress);
        lx_image_free(&height);
        ok = s == LX_OK;
        if (s == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else if (!ok)
            cli_error("%s: %s", a.input, lx_last_error());
    }
    if (ok) {
        ok = maps_output_write(&a.out, &st, &map, a.desc.threads, a.quiet);
        cli_phase("write");
    }
    cli_stage_clear(&st);
    if (ok && !a.quiet) {
        lx_normalmap_desc d = lx_normalmap_desc_defaults(&a.desc);
        fprintf(stderr, "luxel: parallax map %s (strength %s, %s%s) in %.2f s\n",
                maps_size(&map), cli_num(d.strength), lx_wrap_name(d.wrap),
                a.out.format == LX_IMAGE_PNG ? (a.out.bits == 16 ? ", 16-bit" : ", 8-bit") : "",
                cli_elapsed());
        printf("%s\n", a.out.path);
    }
    lx_image_free(&map);
    return ok ? EXIT_OK : EXIT_FAILED;
}
