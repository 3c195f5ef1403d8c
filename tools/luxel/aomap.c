/* luxel aomap: the ambient-occlusion map of a height image (lx_horizon_map's
 * ambient factor, the seed's ambientMap with the mean it means). */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <stdio.h>
#include <string.h>

static const char *ao_usage =
    "usage: luxel aomap HEIGHT -o OUT [options]\n"
    "\n"
    "Ambient-occlusion map of a height image (Lengyel, FGED vol. 2 sec. 7.8):\n"
    "per texel, the mean over the angular bins of the cosine of the horizon's\n"
    "elevation, raised to --power; with --cosine the mean of its square, the\n"
    "cosine-weighted visible fraction of the sky. 1 is open, 0 fully occluded.\n"
    "OUT: .png (grey, linear codes, not sRGB), .exr or .pfm (float). HEIGHT:\n"
    "8- or 16-bit PNG (grey or the first channel) or float EXR/PFM/HDR.\n"
    "\n"
    "options:\n"
    "  -o, --output OUT   output image\n"
    "  --strength S       a height value v is S*v texels (default %g)\n"
    "  --power P          exponent of the ambient factor (default 1)\n"
    "  --cosine           cosine-weighted visible fraction (mean of cos^2)\n"
    "  --angles N         angular bins, a power of two from 16 to 1024 (default 32)\n"
    "  --radius R         search radius in texels, 2..256 (default 16)\n"
    "  --wrap MODE        texels outside the image: repeat, clamp or mirror\n"
    "                     (default repeat, for tiling textures)\n"
    "  --bits 8|16        PNG bit depth (default 8; .exr and .pfm are float)\n"
    "  --threads N        worker threads (default: all cores)\n"
    "  -q, --quiet        no progress bar, no summary\n"
    "  -v, --verbose      phase times\n"
    "  -h, --help         show this help\n";

int cmd_aomap(int argc, char **argv)
{
    cli_horizon_opts o;
    int rc = cli_horizon_args("aomap", argc, argv, &o);
    if (rc < 0) {
        printf(ao_usage, (double)LX_DEFAULT_HEIGHT_STRENGTH);
        return EXIT_OK;
    }
    if (rc != 0)
        return rc;
    lx_image_format format = lx_image_format_from_path(o.output);
    if (format != LX_IMAGE_PNG && format != LX_IMAGE_EXR && format != LX_IMAGE_PFM)
        return cli_usage_error("aomap", "%s: the output must end in .png, .exr or .pfm", o.output);
    lx_image hf, ao = {0};
    if (cli_horizon_load(&o, &hf) != EXIT_OK)
        return EXIT_FAILED;
    int status = cli_horizon_run(&o, &hf, NULL, NULL, &ao);
    lx_image_free(&hf);
    if (status != EXIT_OK)
        return status;
    /* lx_image_write is atomic: a temporary file renamed when complete */
    cli_progress progress;
    cli_progress_init(&progress, "write", o.quiet);
    lx_image_write_desc wd = {.linear = true,
                              .bits = format == LX_IMAGE_PNG ? o.bits : 0,
                              .threads = o.desc.threads,
                              .progress = cli_progress_update,
                              .progress_user = &progress};
    lx_status st = lx_image_write(o.output, &ao, &wd);
    cli_progress_finish(&progress);
    if (st != LX_OK) {
        if (st == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s", lx_last_error());
        lx_image_free(&ao);
        return EXIT_FAILED;
    }
    if (!o.quiet) {
        double mean = 0.0;
        size_t n = (size_t)ao.width * (size_t)ao.height;
        for (size_t i = 0; i < n; i++)
            mean += ao.data[i];
        lx_horizon_desc d = lx_horizon_desc_defaults(&o.desc);
        fprintf(stderr,
                "luxel: AO map %dx%d, %d bins, radius %d, strength %g, power %g%s, mean %.3f, "
                "in %.2f s\n",
                ao.width, ao.height, d.angles, d.radius, (double)d.strength, (double)d.ao_power,
                d.ao_cosine ? ", cosine-weighted" : "", n ? mean / (double)n : 0.0, cli_elapsed());
        printf("%s\n", o.output);
    }
    lx_image_free(&ao);
    return EXIT_OK;
}
