/* luxel ies: what an IES LM-63 photometric file holds (header fields, total
 * lumens integrated over the sphere, peak candela, beam and field angles of
 * the main planes) and, with --plot, the polar candela curve of the C0-C180
 * and C90-C270 planes. Beam and field angle: the full angle between the two
 * directions of a plane where the intensity falls to 50% and 10% of that
 * plane's maximum (IES/CIE; lx_ies_beam_field). Type A and B files are shown
 * as the library converts them to type C (docs/ies.md): their C0-C180 plane
 * holds the vertical angles, C90-C270 the horizontal ones. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *ies_usage =
    "usage: luxel ies FILE [options]\n"
    "\n"
    "Prints the header of an IES LM-63 photometric file (1986, 1991, 1995 or\n"
    "2002), its total lumens (integrated over the sphere), peak candela and the\n"
    "beam and field angles (full angles at 50% and 10% of the maximum) of the\n"
    "C0-C180 and C90-C270 planes.\n"
    "\n"
    "options:\n"
    "  --plot OUT.png   draw the polar candela curve of the main planes\n"
    "                   (C0-C180 red, C90-C270 blue; rings at 25/50/75/100%\n"
    "                   of the peak; vertical angle 0 points down)\n"
    "  -h, --help       show this help\n";

/* Intensity at angle a (degrees, -180..180) in the plane through
 * horizontal angles h_pos (a >= 0) and h_pos + 180 (a < 0). */
static float plane_cd(const lx_ies_profile *p, float h_pos, double a)
{
    return a >= 0 ? lx_ies_candela(p, (float)a, h_pos) : lx_ies_candela(p, (float)-a, h_pos + 180);
}

/* ---- the polar plot ------------------------------------------------------ */

static void put(lx_image *img, int x, int y, lx_vec3 c)
{
    if (x < 0 || y < 0 || x >= img->width || y >= img->height)
        return;
    float *px = img->data + ((size_t)y * img->width + x) * 3;
    px[0] = c.x;
    px[1] = c.y;
    px[2] = c.z;
}

/* Bresenham's line, `thick` pixels square. */
static void line(lx_image *img, double x0, double y0, double x1, double y1, int thick, lx_vec3 c)
{
    int ax = (int)lround(x0), ay = (int)lround(y0), bx = (int)lround(x1), by = (int)lround(y1);
    int dx = abs(bx - ax), dy = -abs(by - ay);
    int sx = ax < bx ? 1 : -1, sy = ay < by ? 1 : -1;
    int err = dx + dy;
    for (;;) {
        for (int j = 0; j < thick; j++)
            for (int i = 0; i < thick; i++)
                put(img, ax + i - thick / 2, ay + j - thick / 2, c);
        if (ax == bx && ay == by)
            break;
        int e2 = 2 * err;
        if (e2 >= dy) {
            err += dy;
            ax += sx;
        }
        if (e2 <= dx) {
            err += dx;
            ay += sy;
        }
    }
}

static lx_status plot(const lx_ies_profile *p, const char *path)
{
    const int size = 512;
    const double cx = size / 2.0, cy = size / 2.0, radius = size * 0.45;
    lx_image img = {0};
    lx_status st = lx_image_alloc(&img, size, size, 3);
    if (st != LX_OK)
        return st;
    for (size_t i = 0; i < (size_t)size * size * 3; i++)
        img.data[i] = 1.0f;
    const lx_vec3 grey = lx_v3(0.45f, 0.45f, 0.45f), light_grey = lx_v3(0.75f, 0.75f, 0.75f);
    /* axes, then rings at 25/50/75/100% of the peak */
    line(&img, cx - radius, cy, cx + radius, cy, 1, light_grey);
    line(&img, cx, cy - radius, cx, cy + radius, 1, light_grey);
    for (int r = 1; r <= 4; r++) {
        double rr = radius * r / 4.0;
        for (int k = 0; k < 360; k++) {
            double a0 = k * (LX_PI / 180.0), a1 = (k + 1) * (LX_PI / 180.0);
            line(&img, cx + rr * cos(a0), cy + rr * sin(a0), cx + rr * cos(a1), cy + rr * sin(a1),
                 1, grey);
        }
    }
    float peak = lx_ies_peak_candela(p);
    const lx_vec3 colours[2] = {lx_v3(0.85f, 0.05f, 0.05f), lx_v3(0.05f, 0.2f, 0.9f)};
    const float planes[2] = {0.0f, 90.0f};
    for (int c = 0; c < 2 && peak > 0; c++) {
        double px = 0, py = 0;
        for (int k = 0; k <= 1440; k++) {
            double a = -180.0 + k * 0.25; /* signed angle from nadir, + toward h = plane */
            double r = radius * plane_cd(p, planes[c], a) / peak;
            double ar = a * (LX_PI / 180.0);
            double x = cx + r * sin(ar), y = cy + r * cos(ar); /* 0 points down */
            if (k > 0)
                line(&img, px, py, x, y, 2, colours[c]);
            px = x;
            py = y;
        }
    }
    st = lx_image_write(path, &img, NULL); /* PNG from the name, values as they are */
    lx_image_free(&img);
    return st;
}

/* ---- the command ---------------------------------------------------------- */

static void print_angles(const char *what, int n, const float *a)
{
    printf("%s: %d (%g..%g deg)\n", what, n, a[0], a[n - 1]);
}

static void print_spread(const char *what, const char *plane, double angle, int percent)
{
    if (angle < 0)
        printf("%s angle %s: none (never falls to %d%%)\n", what, plane, percent);
    else
        printf("%s angle %s: %.1f deg\n", what, plane, angle);
}

int cmd_ies(int argc, char **argv)
{
    static const struct option options[] = {{"plot", required_argument, NULL, 'p'},
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    const char *plot_path = NULL;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":h", options, NULL)) != -1) {
        switch (c) {
        case 'p':
            plot_path = optarg;
            break;
        case 'h':
            fputs(ies_usage, stdout);
            return EXIT_OK;
        case ':':
            return cli_usage_error("ies", "option '%s' needs a value", argv[optind - 1]);
        default:
            return cli_usage_error("ies", "unknown option '%s'", argv[optind - 1]);
        }
    }
    if (optind >= argc)
        return cli_usage_error("ies", "no IES file given");
    if (optind + 1 < argc)
        return cli_usage_error("ies", "one file at a time ('%s' is extra)", argv[optind + 1]);
    if (plot_path && !*plot_path)
        return cli_usage_error("ies", "--plot needs a file name");
    const char *path = argv[optind];
    lx_ies_profile *p;
    if (lx_ies_load(path, &p) != LX_OK) {
        cli_error("%s", lx_last_error());
        return EXIT_FAILED;
    }
    lx_ies_info in;
    lx_ies_get_info(p, &in);
    static const char *types[] = {"?", "C", "B", "A"};
    printf("file: %s\n", path);
    printf("version: %s\n", in.version);
    for (int i = 0; i < in.keyword_count; i++) {
        const char *value;
        const char *key = lx_ies_keyword(p, i, &value);
        if (key[0])
            printf("keyword: [%s] %s\n", key, value);
        else
            printf("label: %s\n", value);
    }
    printf("tilt: %s\n", in.tilt_included ? "included (read, not applied)" : "none");
    printf("lamps: %d\n", in.lamp_count);
    if (in.lumens_per_lamp < 0)
        printf("lumens per lamp: -1 (absolute photometry)\n");
    else
        printf("lumens per lamp: %g\n", in.lumens_per_lamp);
    printf("candela multiplier: %g\n", in.multiplier);
    printf("ballast factor: %g\n", in.ballast_factor);
    printf("ballast-lamp photometric factor: %g\n", in.ballast_lamp_factor);
    printf("input watts: %g\n", in.input_watts);
    printf("photometric type: %s\n", types[in.photometric_type & 3]);
    printf("units: %s\n", in.units == 1 ? "feet" : "metres");
    printf("luminous opening: width %g, length %g, height %g %s\n", in.width, in.length, in.height,
           in.units == 1 ? "ft" : "m");
    print_angles("vertical angles", in.vertical_count, in.vertical_angles);
    print_angles("horizontal angles", in.horizontal_count, in.horizontal_angles);
    /* a type A or B file is converted to type C on loading: its symmetry is
     * the converted distribution's */
    printf("symmetry: %s%s\n", lx_ies_symmetry_name(in.symmetry),
           in.photometric_type == 1 ? "" : " (after conversion to type C)");
    printf("total lumens: %.6g lm (integrated)\n", lx_ies_total_lumens(p));
    printf("peak candela: %.6g cd\n", lx_ies_peak_candela(p));
    const char *planes[2] = {"C0-C180", "C90-C270"};
    for (int k = 0; k < 2; k++) {
        double beam, field;
        if (lx_ies_beam_field(p, k ? 90.0f : 0.0f, &beam, &field) != LX_OK) {
            cli_error("%s", lx_last_error());
            lx_ies_free(p);
            return EXIT_FAILED;
        }
        print_spread("beam", planes[k], beam, 50);
        print_spread("field", planes[k], field, 10);
    }
    int rc = EXIT_OK;
    if (plot_path) {
        /* one file, written under a temporary name and renamed */
        if (plot(p, plot_path) != LX_OK) {
            cli_error("%s", lx_last_error());
            rc = EXIT_FAILED;
        }
    }
    lx_ies_free(p);
    return rc;
}
