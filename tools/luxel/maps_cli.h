/* Shared pieces of the texture-space map commands (normalmap, parallaxmap,
 * shade; private to tools/luxel): the -o/--format/--bits output of one
 * image, staged as bake stages its files. */
#ifndef LUXEL_MAPS_CLI_H
#define LUXEL_MAPS_CLI_H

#include "cli.h"

int cmd_normalmap(int argc, char **argv);
int cmd_heightmap(int argc, char **argv);
int cmd_parallaxmap(int argc, char **argv);
int cmd_shade(int argc, char **argv);

/* One output image: -o OUT, --format png|exr|pfm (default from OUT's
 * extension), --bits 8|16 (PNG only; default 8). */
typedef struct maps_output {
    const char *path;
    lx_image_format format; /* resolved by maps_output_resolve */
    int bits;               /* 0 until given */
    bool format_given;
} maps_output;

/* getopt_long codes of the options the map commands share (a command's
 * own codes start at MAPS_OPT_OWN; --threads is CLI_OPT_THREADS). */
enum {
    MAPS_OPT_STRENGTH = 256,
    MAPS_OPT_FILTER,
    MAPS_OPT_WRAP,
    MAPS_OPT_GREEN,
    MAPS_OPT_BITS,
    MAPS_OPT_FORMAT,
    MAPS_OPT_OWN
};

/* What the shared options set; each stays zero until its option is given
 * (copy the given ones into the command's desc after parsing). */
typedef struct maps_common {
    bool output_is_folder;    /* set before parsing: -o names a folder */
    maps_output out;          /* -o, --format, --bits */
    float strength;           /* --strength; 0 = not given */
    lx_normal_filter filter;  /* --filter */
    lx_wrap wrap;             /* --wrap */
    bool filter_given, wrap_given;
    bool green_down;          /* --green down */
    const char *height_option; /* the last of --strength, --filter, --wrap given */
    int threads;              /* --threads; 0 = not given */
    bool quiet;
} maps_common;

/* Handles option c of `command` when it is a shared one, or the common
 * tail (cli_common_option): 0 when handled, else EXIT_USAGE with the
 * error printed (a bad value, a missing value, an unknown option). Call
 * it from the default case of the command's switch. */
int maps_common_option(const char *command, int c, char **argv, maps_common *m);

/* --format's value: png, exr or pfm. */
bool maps_parse_format(const char *s, lx_image_format *out);
/* --bits' value: 8 or 16. */
bool maps_parse_bits(const char *s, int *out);

/* Checks the output options of `command` once parsed: OUT given and naming
 * a file, a format from --format or OUT's extension (png, exr, pfm), the
 * two agreeing, --bits only with PNG. Returns 0, or EXIT_USAGE with the
 * error printed. */
int maps_output_resolve(const char *command, maps_output *o);

/* Stages OUT's folder (created when missing) and checks OUT can be
 * replaced, before the work; false with the error printed. */
bool maps_output_begin(const maps_output *o, cli_stage *st);
/* OUT's file name (past its last '/'), the name it is staged under. */
const char *maps_output_name(const maps_output *o);

/* Writes img as OUT (linear codes in PNG: data, not colour) through the
 * stage and moves it into place; false with the error printed (nothing
 * is left behind). For PNG, values outside [0,1] are an error naming the
 * first one (they would be clamped). */
bool maps_output_write(const maps_output *o, cli_stage *st, const lx_image *img, int threads,
                       bool quiet);

/* The width x height of an image as "WxH" in a rotating buffer. */
const char *maps_size(const lx_image *img);

#endif
