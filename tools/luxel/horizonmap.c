/* luxel horizonmap: horizon maps of a height image (lx_horizon_map, the
 * seed's ConstructHorizonMap) and the weight cube map their shading
 * function samples; and the options it shares with luxel aomap. */
#define _POSIX_C_SOURCE 200809L
#include "maps_cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Face size of DIR/horizon-weights.exr: the seed's 16. The weights are
 * linear in the azimuth within a face's texel, so a bilinear fetch of 16
 * texels a face is close to exact. */
#define WEIGHT_CUBE_SIZE 16

static const char *horizon_usage =
    "usage: luxel horizonmap HEIGHT -o DIR [options]\n"
    "\n"
    "Horizon maps of a height image (Lengyel, FGED vol. 2 sec. 7.8): for eight\n"
    "directions, every 45 degrees counter-clockwise from +x with y up the image,\n"
    "the sine of the horizon's elevation (averaged over each direction's angular\n"
    "bins) in DIR/horizon0.png (directions 0-3 in R, G, B, A) and\n"
    "DIR/horizon1.png (4-7), as linear codes (not sRGB); and\n"
    "DIR/horizon-weights.exr, the weight cube a shader samples with the\n"
    "tangent-space light direction: six %dx%d faces (+X -X +Y -Y +Z -Z) stacked\n"
    "top to bottom, float RGBA, positive weights for horizon0, negative (negated)\n"
    "for horizon1. HEIGHT: 8- or 16-bit PNG (grey or the first channel) or\n"
    "float EXR/PFM/HDR, values in [0, 1].\n"
    "\n"
    "options:\n"
    "  -o, --output DIR   output folder (made if missing)\n"
    "  --strength S       a height value v is S*v texels (default %g)\n"
    "  --angles N         angular bins, a power of two from 16 to 1024 (default 32)\n"
    "  --radius R         search radius in texels, 2..256 (default 16)\n"
    "  --wrap MODE        texels outside the image: repeat, clamp or mirror\n"
    "                     (default repeat, for tiling textures)\n"
    "  --bits 8|16        PNG bit depth (default 8)\n"
    "  --threads N        worker threads (default: all cores)\n"
    "  -q, --quiet        no progress bar, no summary\n"
    "  -v, --verbose      phase times\n"
    "  -h, --help         show this help\n";

enum { OPT_ANGLES = MAPS_OPT_OWN, OPT_RADIUS, OPT_POWER, OPT_COSINE };

int cli_horizon_args(const char *command, int argc, char **argv, cli_horizon_opts *o)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"strength", required_argument, NULL, MAPS_OPT_STRENGTH},
                                            {"angles", required_argument, NULL, OPT_ANGLES},
                                            {"radius", required_argument, NULL, OPT_RADIUS},
                                            {"wrap", required_argument, NULL, MAPS_OPT_WRAP},
                                            {"bits", required_argument, NULL, MAPS_OPT_BITS},
                                            {"power", required_argument, NULL, OPT_POWER},
                                            {"cosine", no_argument, NULL, OPT_COSINE},
                                            {"threads", required_argument, NULL, CLI_OPT_THREADS},
                                            {"quiet", no_argument, NULL, 'q'},
                                            {"verbose", no_argument, NULL, 'v'},
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    bool ao = strcmp(command, "aomap") == 0;
    memset(o, 0, sizeof *o);
    o->desc = lx_horizon_desc_defaults(NULL);
    o->bits = 8;
    maps_common m = {.output_is_folder = !ao};
    opterr = 0;
    optind = 1;
    int c;
    long n;
    double f;
    while ((c = getopt_long(argc, argv, ":o:qvh", options, NULL)) != -1) {
        switch (c) {
        case OPT_ANGLES:
            if (!cli_parse_int(optarg, 16, 1024, &n) || (n & (n - 1)) != 0)
                return cli_usage_error(command,
                                       "--angles must be a power of two from 16 to 1024, not '%s'",
                                       optarg);
            o->desc.angles = (int)n;
            break;
        case OPT_RADIUS:
            if (!cli_parse_int(optarg, 2, 256, &n))
                return cli_usage_error(command, "--radius must be texels in 2..256, not '%s'",
                                       optarg);
            o->desc.radius = (int)n;
            break;
        case OPT_POWER:
            if (!ao)
                return cli_usage_error(command, "unknown option '--power'");
            if (!cli_parse_float(optarg, 1e-3, 1e3, &f))
                return cli_usage_error(command, "--power must be a number in 0.001..1000, not '%s'",
                                       optarg);
            o->desc.ao_power = (float)f;
            break;
        case OPT_COSINE:
            if (!ao)
                return cli_usage_error(command, "unknown option '--cosine'");
            o->desc.ao_cosine = true;
            break;
        case 'h':
            return -1;
        default: {
            int rc = maps_common_option(command, c, argv, &m);
            if (rc != 0)
                return rc;
        }
        }
    }
    o->output = m.out.path;
    if (m.strength > 0.0f)
        o->desc.strength = m.strength;
    if (m.wrap_given)
        o->desc.wrap = m.wrap;
    if (m.out.bits)
        o->bits = m.out.bits;
    if (m.threads)
        o->desc.threads = m.threads;
    o->quiet = m.quiet;
    if (optind >= argc)
        return cli_usage_error(command, "no height image given");
    if (optind + 1 < argc)
        return cli_usage_error(command, "one height image at a time ('%s' is extra)",
                               argv[optind + 1]);
    o->input = argv[optind];
    if (!o->output)
        return cli_usage_error(command, "-o %s is required", ao ? "OUT" : "DIR");
    cli_set_quiet(o->quiet);
    return 0;
}

int cli_horizon_load(const cli_horizon_opts *o, lx_image *hf)
{
    if (lx_height_load(o->input, hf) != LX_OK) {
        cli_error("%s", lx_last_error());
        return EXIT_FAILED;
    }
    cli_phase("load");
    return EXIT_OK;
}

int cli_horizon_run(const cli_horizon_opts *o, const lx_image *hf, lx_image *l0, lx_image *l1,
                    lx_image *ao)
{
    cli_progress progress;
    cli_progress_init(&progress, ao && !l0 ? "aomap" : "horizonmap", o->quiet);
    lx_horizon_desc d = o->desc;
    d.progress = cli_progress_update;
    d.progress_user = &progress;
    lx_status st = lx_horizon_map(hf, &d, l0, l1, ao);
    cli_progress_finish(&progress);
    if (st != LX_OK) {
        if (st == LX_ERR_CANCELLED)
            cli_report_interrupt(true);
        else
            cli_error("%s: %s", o->input, lx_last_error());
        return EXIT_FAILED;
    }
    return EXIT_OK;
}

int cmd_horizonmap(int argc, char **argv)
{
    cli_horizon_opts o;
    int rc = cli_horizon_args("horizonmap", argc, argv, &o);
    if (rc < 0) {
        printf(horizon_usage, WEIGHT_CUBE_SIZE, WEIGHT_CUBE_SIZE,
               (double)LX_DEFAULT_HEIGHT_STRENGTH);
        return EXIT_OK;
    }
    if (rc != 0)
        return rc;
    static const char *const names[] = {"horizon0.png", "horizon1.png", "horizon-weights.exr"};
    /* a bad height image is reported before any folder is made */
    lx_image hf;
    if (cli_horizon_load(&o, &hf) != EXIT_OK)
        return EXIT_FAILED;
    cli_stage st;
    /* the three files are read together: one run at a time into a folder */
    if (!cli_stage_begin_set(&st, o.output, false)) {
        lx_image_free(&hf);
        return EXIT_FAILED;
    }
    int status = EXIT_FAILED;
    lx_image img[3] = {{0}};
    for (int k = 0; k < 3; k++)
        if (!cli_stage_check(&st, names[k]))
            goto done;
    if (cli_horizon_run(&o, &hf, &img[0], &img[1], NULL) != EXIT_OK)
        goto done;
    if (lx_horizon_weight_cube(WEIGHT_CUBE_SIZE, &img[2]) != LX_OK) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    lx_image_write_desc wd = {.linear = true, .bits = o.bits, .threads = o.desc.threads};
    for (int k = 0; k < 3; k++)
        if (!cli_stage_image(&st, names[k], &img[k], &wd))
            goto done;
    if (!cli_stage_publish(&st))
        goto done;
    cli_phase("write");
    status = EXIT_OK;
    if (!o.quiet) {
        lx_horizon_desc d = lx_horizon_desc_defaults(&o.desc);
        fprintf(stderr,
                "luxel: horizon map %dx%d, %d bins, radius %d, strength %g, wrap %s, in %.2f s\n",
                img[0].width, img[0].height, d.angles, d.radius, (double)d.strength,
                lx_wrap_name(d.wrap), cli_elapsed());
        for (int k = 0; k < 3; k++) {
            char *p = cli_path_join(o.output, names[k]);
            printf("%s\n", p ? p : names[k]);
            free(p);
        }
    }
done:
    lx_image_free(&hf);
    for (int k = 0; k < 3; k++)
        lx_image_free(&img[k]);
    cli_stage_clear(&st);
    return status;
}
