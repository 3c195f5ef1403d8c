/* luxel heightmap: heights integrated from a tangent-space normal map
 * (lx_height_from_normals), written as one image of the input's size:
 * texels of height in float formats, normalized to [0,1] in PNG with the
 * strength that maps them back printed. */
#define _POSIX_C_SOURCE 200809L
#include "maps_cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *heightmap_usage =
    "usage: luxel heightmap NORMALS -o OUT [options]\n"
    "\n"
    "Integrates the heights of a tangent-space normal map NORMALS (rgb =\n"
    "n/2 + 1/2; PNG codes read linearly, or a float image): the heights whose\n"
    "slopes (-n.x/n.z, -n.y/n.z) best fit the map's in least squares, the\n"
    "inverse of `luxel normalmap`. x runs along the columns, y up the image\n"
    "(--green down flips it). Heights are defined up to a constant: the\n"
    "lowest is 0. docs/maps.md has the method and its accuracy.\n"
    "\n"
    "OUT (.exr or .pfm) holds heights in texels (strength 1). A PNG holds\n"
    "them divided by the highest, S, in [0,1]: `strength S` is printed on\n"
    "stdout (also with --quiet), and `luxel normalmap OUT --strength S`\n"
    "(same --wrap) gives the normals back.\n"
    "\n"
    "options:\n"
    "  -o, --output OUT     the height image (.png, .exr or .pfm)\n"
    "  --wrap W             repeat (default: the map tiles; its steps wrap\n"
    "                       around the edges), clamp or mirror (no steps\n"
    "                       across the edges)\n"
    "  --green G            up (default; OpenGL, glTF) or down (DirectX)\n"
    "  --bits N             png bits per channel: 8 or 16 (default 16)\n"
    "  --format F           png, exr or pfm (default: from OUT's name)\n"
    "  --threads N          worker threads (default: all cores)\n"
    "  -v, --verbose        the time of each phase\n"
    "  -q, --quiet          no progress bar or summary\n"
    "  -h, --help           show this help\n";

typedef struct heightmap_args {
    const char *input;
    maps_output out;
    lx_height_from_normals_desc desc;
    bool quiet;
} heightmap_args;

static int parse_args(int argc, char **argv, heightmap_args *a)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"wrap", required_argument, NULL, MAPS_OPT_WRAP},
                                            {"green", required_argument, NULL, MAPS_OPT_GREEN},
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
            fputs(heightmap_usage, stdout);
            return -1;
        }
        int rc = maps_common_option("heightmap", c, argv, &m);
        if (rc != 0)
            return rc;
    }
    a->out = m.out;
    a->desc.wrap = m.wrap;
    a->desc.green_down = m.green_down;
    a->desc.threads = m.threads;
    a->quiet = m.quiet;
    if (argc - optind < 1)
        return cli_usage_error("heightmap", "no normal map given");
    if (argc - optind > 1)
        return cli_usage_error("heightmap", "'%s' is extra", argv[optind + 1]);
    a->input = argv[optind];
    /* heights want more than 8 bits: 16 unless asked */
    bool bits_given = a->out.bits != 0;
    int rc = maps_output_resolve("heightmap", &a->out);
    if (rc == 0 && !bits_given && a->out.format == LX_IMAGE_PNG)
        a->out.bits = 16;
    return rc;
}

/* The normal map's heights in texels; false with the error printed. */
static bool integrate(heightmap_args *a, lx_image *heights)
{
    lx_image img, normals;
    lx_image_load_desc ld = {.raw_8bit = true};
    lx_status s = lx_image_load(a->input, &ld, &img);
    if (s == LX_OK) {
        /* names the file for an image with no pixels, too few channels or
         * a texel that is no direction */
        s = lx_normal_decode(&img, a->input, &normals);
        lx_image_free(&img);
    }
    if (s != LX_OK) {
        cli_error("%s", lx_last_error());
        return false;
    }
    cli_phase("load");
    cli_progress progress;
    cli_progress_init(&progress, "heightmap", a->quiet);
    a->desc.progress = cli_progress_update;
    a->desc.progress_user = &progress;
    s = lx_height_from_normals(&normals, &a->desc, heights);
    cli_progress_finish(&progress);
    lx_image_free(&normals);
    if (s == LX_ERR_CANCELLED)
        cli_report_interrupt(false);
    else if (s != LX_OK)
        cli_error("%s: %s", a->input, lx_last_error());
    return s == LX_OK;
}

int cmd_heightmap(int argc, char **argv)
{
    heightmap_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    cli_stage st;
    if (!maps_output_begin(&a.out, &st))
        return EXIT_FAILED;
    lx_image heights = {0};
    bool ok = integrate(&a, &heights);
    double strength = 1.0;
    if (ok && a.out.format == LX_IMAGE_PNG) {
        /* [0,1] for PNG: divided by the highest (the lowest is 0) */
        size_t count = (size_t)heights.width * (size_t)heights.height;
        float hi = 0.0f;
        for (size_t i = 0; i < count; i++)
            hi = heights.data[i] > hi ? heights.data[i] : hi;
        if (hi > 1e-6f) {
            strength = hi;
            for (size_t i = 0; i < count; i++) {
                float v = heights.data[i] / hi;
                heights.data[i] = v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
            }
        }
    }
    if (ok) {
        cli_phase("heights");
        ok = maps_output_write(&a.out, &st, &heights, a.desc.threads, a.quiet);
        cli_phase("write");
    }
    cli_stage_clear(&st);
    if (ok) {
        if (!a.quiet) {
            const char *bits = a.out.format == LX_IMAGE_PNG
                                   ? (a.out.bits == 16 ? ", 16-bit" : ", 8-bit")
                                   : "";
            fprintf(stderr,
                    "luxel: height map %s (%s, green %s%s) in %.2f s; strength %s texels a "
                    "unit value\n",
                    maps_size(&heights), lx_wrap_name(a.desc.wrap),
                    a.desc.green_down ? "down" : "up", bits, cli_elapsed(),
                    cli_num_digits(strength, 9));
            printf("%s\n", a.out.path);
        }
        printf("strength %.9g\n", strength);
    }
    lx_image_free(&heights);
    return ok ? EXIT_OK : EXIT_FAILED;
}
