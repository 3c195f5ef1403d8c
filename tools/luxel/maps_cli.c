/* The output side shared by the texture-space map commands: one image
 * named by -o, its format from --format or the name, its bit depth from
 * --bits, written through a staging folder (stage.c) so a failed or
 * interrupted run leaves nothing. */
#define _POSIX_C_SOURCE 200809L
#include "maps_cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool maps_parse_format(const char *s, lx_image_format *out)
{
    lx_image_format f;
    if (!cli_parse_format(s, &f) || f == LX_IMAGE_HDR)
        return false;
    *out = f;
    return true;
}

bool maps_parse_bits(const char *s, int *out)
{
    if (strcmp(s, "8") == 0 || strcmp(s, "16") == 0) {
        *out = atoi(s);
        return true;
    }
    return false;
}

int maps_common_option(const char *command, int c, char **argv, maps_common *m)
{
    double f;
    switch (c) {
    case 'o':
        if (!*optarg)
            return cli_usage_error(command, "-o needs a %s name",
                                   m->output_is_folder ? "folder" : "file");
        m->out.path = optarg;
        return 0;
    case MAPS_OPT_STRENGTH:
        if (!cli_parse_float(optarg, 1e-6, 1e6, &f))
            return cli_usage_error(command, "--strength must be a number in 1e-6..1e6, not '%s'",
                                   optarg);
        m->strength = (float)f;
        m->height_option = "--strength";
        return 0;
    case MAPS_OPT_FILTER:
        if (!lx_normal_filter_parse(optarg, &m->filter))
            return cli_usage_error(command, "--filter must be central, sobel or scharr, not '%s'",
                                   optarg);
        m->filter_given = true;
        m->height_option = "--filter";
        return 0;
    case MAPS_OPT_WRAP:
        if (!lx_wrap_parse(optarg, &m->wrap))
            return cli_usage_error(command, "--wrap must be repeat, clamp or mirror, not '%s'",
                                   optarg);
        m->wrap_given = true;
        m->height_option = "--wrap";
        return 0;
    case MAPS_OPT_GREEN:
        if (strcmp(optarg, "up") == 0)
            m->green_down = false;
        else if (strcmp(optarg, "down") == 0)
            m->green_down = true;
        else
            return cli_usage_error(command, "--green must be up or down, not '%s'", optarg);
        return 0;
    case MAPS_OPT_BITS:
        if (!maps_parse_bits(optarg, &m->out.bits))
            return cli_usage_error(command, "--bits must be 8 or 16, not '%s'", optarg);
        return 0;
    case MAPS_OPT_FORMAT:
        if (!maps_parse_format(optarg, &m->out.format))
            return cli_usage_error(command, "--format must be png, exr or pfm, not '%s'", optarg);
        m->out.format_given = true;
        return 0;
    default:
        return cli_common_option(command, c, argv, &m->threads, &m->quiet);
    }
}

/* The file name part of a path ("" when it ends with '/'). */
static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

int maps_output_resolve(const char *command, maps_output *o)
{
    if (!o->path)
        return cli_usage_error(command, "no output given (-o OUT)");
    const char *base = base_name(o->path);
    if (!base[0] || strcmp(base, ".") == 0 || strcmp(base, "..") == 0)
        return cli_usage_error(command, "-o needs a file name, not the folder '%s'", o->path);
    lx_image_format named = lx_image_format_from_path(o->path);
    bool known = named == LX_IMAGE_PNG || named == LX_IMAGE_EXR || named == LX_IMAGE_PFM;
    if (o->format_given) {
        if (named != LX_IMAGE_AUTO && named != o->format)
            return cli_usage_error(command, "--format %s does not match the name '%s'",
                                   lx_image_format_extension(o->format), o->path);
    } else if (known) {
        o->format = named;
    } else if (named != LX_IMAGE_AUTO) {
        return cli_usage_error(command, "cannot write %s: use .png, .exr or .pfm",
                               lx_image_format_extension(named));
    } else {
        return cli_usage_error(command,
                               "cannot tell the format of '%s': name it .png, .exr or .pfm, or "
                               "give --format",
                               o->path);
    }
    if (o->bits && o->format != LX_IMAGE_PNG)
        return cli_usage_error(command, "--bits is for png; %s stores 32-bit floats",
                               lx_image_format_extension(o->format));
    if (!o->bits)
        o->bits = 8;
    return 0;
}

/* The folder part of a path ("." when none) into a malloc'd string. */
static char *dir_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return cli_strdup(".");
    if (slash == path)
        return cli_strdup("/");
    char *d = malloc((size_t)(slash - path) + 1);
    if (d) {
        memcpy(d, path, (size_t)(slash - path));
        d[slash - path] = '\0';
    }
    return d;
}

const char *maps_output_name(const maps_output *o)
{
    return base_name(o->path);
}

bool maps_output_begin(const maps_output *o, cli_stage *st)
{
    memset(st, 0, sizeof *st);
    char *dir = dir_name(o->path);
    if (!dir) {
        cli_error("out of memory");
        return false;
    }
    bool ok = cli_stage_begin(st, dir) && cli_stage_check(st, base_name(o->path));
    free(dir);
    if (!ok)
        cli_stage_clear(st);
    return ok;
}

bool maps_output_write(const maps_output *o, cli_stage *st, const lx_image *img, int threads,
                       bool quiet)
{
    if (o->format == LX_IMAGE_PNG) {
        size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
        for (size_t i = 0; i < n; i++)
            if (!(img->data[i] >= 0.0f && img->data[i] <= 1.0f)) {
                size_t p = i / (size_t)img->channels;
                cli_error("%s: value %g at pixel (%zu, %zu) is outside [0,1], which png cannot "
                          "store; write .exr or .pfm",
                          o->path, (double)img->data[i], p % (size_t)img->width,
                          p / (size_t)img->width);
                return false;
            }
    }
    cli_progress progress;
    cli_progress_init(&progress, "write", quiet);
    lx_image_write_desc wd = {.format = o->format,
                              .linear = true,
                              .bits = o->format == LX_IMAGE_PNG ? o->bits : 0,
                              .threads = threads,
                              .progress = cli_progress_update,
                              .progress_user = &progress};
    bool ok = cli_stage_image(st, base_name(o->path), img, &wd);
    cli_progress_finish(&progress);
    return ok && cli_stage_publish(st);
}

const char *maps_size(const lx_image *img)
{
    static _Thread_local char buf[4][32];
    static _Thread_local int next;
    char *b = buf[next++ & 3];
    snprintf(b, sizeof buf[0], "%dx%d", img->width, img->height);
    return b;
}
