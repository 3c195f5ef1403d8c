/* luxel ies: what an IES LM-63 photometric file holds (header fields, total
 * lumens integrated over the sphere, peak candela, beam and field angles of
 * the planes that carry the peak) and, with --plot, a labelled polar
 * candela plot. Beam and field angle: the full angle between the two
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
    "planes that carry the peak: C0-C180 and C90-C270 when their maximum is\n"
    "within 1% of it, else the plane through the peak.\n"
    "\n"
    "options:\n"
    "  --plot OUT.png   draw the polar candela curve of those planes (C0-C180\n"
    "                   red, C90-C270 blue, the peak's plane green), rings\n"
    "                   labelled in candela, angles from the nadir (down)\n"
    "  -h, --help       show this help\n";

/* Intensity at angle a (degrees, -180..180) in the plane through
 * horizontal angles h_pos (a >= 0) and h_pos + 180 (a < 0). */
static float plane_cd(const lx_ies_profile *p, float h_pos, double a)
{
    return a >= 0 ? lx_ies_candela(p, (float)a, h_pos) : lx_ies_candela(p, (float)-a, h_pos + 180);
}

/* ---- the polar plot ------------------------------------------------------ */

#define PLOT_W 600
#define PLOT_H 660

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

/* A 5x7 bitmap font of the characters the plot writes (rows top down, bit
 * 4 the left column); '^' is the degree sign. Others draw as a box. */
static const struct {
    char c;
    unsigned char rows[7];
} glyphs[] = {
    {'0', {0x0e, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0e}},
    {'1', {0x04, 0x0c, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'2', {0x0e, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1f}},
    {'3', {0x1e, 0x01, 0x01, 0x0e, 0x01, 0x01, 0x1e}},
    {'4', {0x02, 0x06, 0x0a, 0x12, 0x1f, 0x02, 0x02}},
    {'5', {0x1f, 0x10, 0x1e, 0x01, 0x01, 0x11, 0x0e}},
    {'6', {0x06, 0x08, 0x10, 0x1e, 0x11, 0x11, 0x0e}},
    {'7', {0x1f, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0e, 0x11, 0x11, 0x0e, 0x11, 0x11, 0x0e}},
    {'9', {0x0e, 0x11, 0x11, 0x0f, 0x01, 0x02, 0x0c}},
    {'C', {0x0e, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0e}},
    {'a', {0x00, 0x00, 0x0e, 0x01, 0x0f, 0x11, 0x0f}},
    {'c', {0x00, 0x00, 0x0e, 0x10, 0x10, 0x11, 0x0e}},
    {'d', {0x01, 0x01, 0x0d, 0x13, 0x11, 0x11, 0x0f}},
    {'e', {0x00, 0x00, 0x0e, 0x11, 0x1f, 0x10, 0x0e}},
    {'f', {0x06, 0x09, 0x08, 0x1c, 0x08, 0x08, 0x08}},
    {'g', {0x00, 0x0f, 0x11, 0x11, 0x0f, 0x01, 0x0e}},
    {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'i', {0x04, 0x00, 0x0c, 0x04, 0x04, 0x04, 0x0e}},
    {'k', {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}},
    {'l', {0x0c, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0e}},
    {'m', {0x00, 0x00, 0x1a, 0x15, 0x15, 0x11, 0x11}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'o', {0x00, 0x00, 0x0e, 0x11, 0x11, 0x11, 0x0e}},
    {'p', {0x00, 0x00, 0x1e, 0x11, 0x1e, 0x10, 0x10}},
    {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0f, 0x10, 0x0e, 0x01, 0x1e}},
    {'t', {0x08, 0x08, 0x1c, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0d}},
    {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0a, 0x04}},
    {'x', {0x00, 0x00, 0x11, 0x0a, 0x04, 0x0a, 0x11}},
    {'-', {0x00, 0x00, 0x00, 0x1f, 0x00, 0x00, 0x00}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0c, 0x0c}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {':', {0x00, 0x0c, 0x0c, 0x00, 0x0c, 0x0c, 0x00}},
    {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'^', {0x0c, 0x12, 0x12, 0x0c, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1f, 0x04, 0x04, 0x00}},
    {'=', {0x00, 0x00, 0x1f, 0x00, 0x1f, 0x00, 0x00}},
    {',', {0x00, 0x00, 0x00, 0x00, 0x0c, 0x04, 0x08}},
};

#define FONT_SCALE 2
#define FONT_ADVANCE (6 * FONT_SCALE)
#define FONT_HEIGHT (7 * FONT_SCALE)

static void text(lx_image *img, int x, int y, const char *s, lx_vec3 c)
{
    for (; *s; s++, x += FONT_ADVANCE) {
        if (*s == ' ')
            continue;
        static const unsigned char box[7] = {0x1f, 0x11, 0x11, 0x11, 0x11, 0x11, 0x1f};
        const unsigned char *rows = box;
        for (size_t g = 0; g < sizeof glyphs / sizeof glyphs[0]; g++)
            if (glyphs[g].c == *s)
                rows = glyphs[g].rows;
        for (int r = 0; r < 7; r++)
            for (int k = 0; k < 5; k++)
                if (rows[r] & (0x10 >> k))
                    for (int j = 0; j < FONT_SCALE; j++)
                        for (int i = 0; i < FONT_SCALE; i++)
                            put(img, x + k * FONT_SCALE + i, y + r * FONT_SCALE + j, c);
    }
}

static int text_width(const char *s)
{
    return (int)strlen(s) * FONT_ADVANCE - FONT_SCALE;
}

/* Text centred on (x, y). */
static void text_centred(lx_image *img, double x, double y, const char *s, lx_vec3 c)
{
    text(img, (int)lround(x - text_width(s) / 2.0), (int)lround(y - FONT_HEIGHT / 2.0), s, c);
}

/* The scale: rings at multiples of a round step (1, 2, 2.5 or 5 x 10^k)
 * whose last ring, 3 to 5 steps out, holds the peak. */
static double ring_step(double peak, int *rings)
{
    double e = pow(10.0, floor(log10(peak)));
    static const double steps[] = {0.5, 1.0, 2.0, 2.5, 5.0, 10.0};
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        double step = steps[i] * e / 2.0;
        int n = (int)ceil(peak / step - 1e-9);
        if (n <= 5) {
            *rings = n < 1 ? 1 : n;
            return step;
        }
    }
    *rings = 5;
    return peak / 5.0;
}

/* The planes a plot draws: C0-C180, C90-C270 and, when neither carries
 * the peak, the one that does. */
typedef struct plot_plane {
    float h;
    lx_vec3 colour;
} plot_plane;

static lx_status plot(const lx_ies_profile *p, const plot_plane *planes, int plane_count,
                      const char *path)
{
    const double cx = PLOT_W / 2.0, cy = 60 + PLOT_W / 2.0, radius = PLOT_W * 0.38;
    lx_image img = {0};
    lx_status st = lx_image_alloc(&img, PLOT_W, PLOT_H, 3);
    if (st != LX_OK)
        return st;
    for (size_t i = 0; i < (size_t)PLOT_W * PLOT_H * 3; i++)
        img.data[i] = 1.0f;
    const lx_vec3 black = lx_v3(0.0f, 0.0f, 0.0f), grey = lx_v3(0.45f, 0.45f, 0.45f),
                  light_grey = lx_v3(0.8f, 0.8f, 0.8f);
    float peak = lx_ies_peak_candela(p);
    int rings = 4;
    double step = peak > 0 ? ring_step(peak, &rings) : 1.0;
    double outer = step * rings; /* candela at the outer ring */
    /* spokes every 30 degrees, labelled outside the outer ring */
    for (int d = 0; d < 360; d += 30) {
        double ar = d * (LX_PI / 180.0);
        line(&img, cx, cy, cx + radius * sin(ar), cy + radius * cos(ar), 1, light_grey);
        int shown = d <= 180 ? d : 360 - d;
        char label[16];
        snprintf(label, sizeof label, "%d^", shown);
        double lr = radius + 26.0;
        text_centred(&img, cx + lr * sin(ar), cy + lr * cos(ar), label, grey);
    }
    /* rings with their candela on the upward axis */
    for (int r = 1; r <= rings; r++) {
        double rr = radius * r / rings;
        for (int k = 0; k < 360; k++) {
            double a0 = k * (LX_PI / 180.0), a1 = (k + 1) * (LX_PI / 180.0);
            line(&img, cx + rr * cos(a0), cy + rr * sin(a0), cx + rr * cos(a1), cy + rr * sin(a1),
                 1, grey);
        }
        char label[48];
        snprintf(label, sizeof label, "%s%s", cli_num(step * r), r == rings ? " cd" : "");
        text(&img, (int)cx + 5, (int)lround(cy - rr) + 3, label, black);
    }
    for (int c = 0; c < plane_count && peak > 0; c++) {
        double px = 0, py = 0;
        for (int k = 0; k <= 1440; k++) {
            double a = -180.0 + k * 0.25; /* signed angle from nadir, + toward h = plane */
            double r = radius * plane_cd(p, planes[c].h, a) / outer;
            double ar = a * (LX_PI / 180.0);
            double x = cx + r * sin(ar), y = cy + r * cos(ar); /* 0 points down */
            if (k > 0)
                line(&img, px, py, x, y, 2, planes[c].colour);
            px = x;
            py = y;
        }
    }
    /* the legend: each plane's colour and name, the peak */
    char label[64];
    for (int c = 0; c < plane_count; c++) {
        int y = 12 + c * (FONT_HEIGHT + 6);
        line(&img, 12, y + FONT_HEIGHT / 2, 40, y + FONT_HEIGHT / 2, 3, planes[c].colour);
        float h1 = planes[c].h + 180.0f;
        snprintf(label, sizeof label, "C%s-C%s", cli_num_digits(planes[c].h, 4),
                 cli_num_digits(h1, 4));
        text(&img, 48, y, label, black);
    }
    snprintf(label, sizeof label, "peak %s cd", cli_num_digits(peak, 5));
    text(&img, PLOT_W - 12 - text_width(label), 12, label, black);
    /* which half of the circle is which side of the planes */
    int y = PLOT_H - FONT_HEIGHT - 12;
    char right[64] = "right:", left[64] = "left:";
    for (int c = 0; c < plane_count; c++) {
        size_t nr = strlen(right), nl = strlen(left);
        snprintf(right + nr, sizeof right - nr, " C%s", cli_num_digits(planes[c].h, 4));
        snprintf(left + nl, sizeof left - nl, " C%s", cli_num_digits(planes[c].h + 180.0f, 4));
    }
    text(&img, 12, y, left, black);
    text(&img, PLOT_W - 12 - text_width(right), y, right, black);
    text_centred(&img, cx, y + FONT_HEIGHT / 2.0, "0^ = nadir", black);
    st = lx_image_write(path, &img, NULL); /* PNG from the name, values as they are */
    lx_image_free(&img);
    return st;
}

/* ---- the command ---------------------------------------------------------- */

static void print_angles(const char *what, int n, const float *a)
{
    printf("%s: %d (%s..%s deg)\n", what, n, cli_num(a[0]), cli_num(a[n - 1]));
}

static void print_spread(const char *what, const char *plane, double angle, int percent)
{
    if (angle < 0)
        printf("%s angle %s: none (never falls to %d%%)\n", what, plane, percent);
    else
        printf("%s angle %s: %s deg\n", what, plane, cli_num_digits(angle, 4));
}

/* A plane carries the peak when its maximum is the profile's within 1%:
 * measured planes meet at the nadir only to the goniometer's precision,
 * and a type A/B file's planes are resampled. A plane that measures a
 * side lobe is far below (a road light's C90-C270: 40%). */
#define PEAK_PLANE_TOLERANCE 0.01

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
        default: {
            int rc = cli_common_option("ies", c, argv, NULL, NULL);
            if (rc != 0)
                return rc;
        }
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
        printf("lumens per lamp: %s\n", cli_num(in.lumens_per_lamp));
    printf("candela multiplier: %s\n", cli_num(in.multiplier));
    printf("ballast factor: %s\n", cli_num(in.ballast_factor));
    printf("ballast-lamp photometric factor: %s\n", cli_num(in.ballast_lamp_factor));
    printf("input watts: %s\n", cli_num(in.input_watts));
    printf("photometric type: %s\n", types[in.photometric_type & 3]);
    printf("units: %s\n", in.units == 1 ? "feet" : "metres");
    printf("luminous opening: width %s, length %s, height %s %s\n", cli_num(in.width),
           cli_num(in.length), cli_num(in.height),
           in.units == 1 ? "ft" : "m");
    print_angles("vertical angles", in.vertical_count, in.vertical_angles);
    print_angles("horizontal angles", in.horizontal_count, in.horizontal_angles);
    /* a type A or B file is converted to type C on loading: its symmetry is
     * the converted distribution's */
    printf("symmetry: %s%s\n", lx_ies_symmetry_name(in.symmetry),
           in.photometric_type == 1 ? "" : " (after conversion to type C)");
    printf("total lumens: %s lm (integrated)\n", cli_num(lx_ies_total_lumens(p)));
    printf("peak candela: %s cd\n", cli_num(lx_ies_peak_candela(p)));
    /* beam and field angles describe the beam only in a plane that
     * carries the peak: C0-C180 and C90-C270 when they do, else the plane
     * through the peak (in another plane the figure measures a side lobe:
     * a wall washer's C90-C270 "beam" can be 300 degrees) */
    float peak_h = 0.0f;
    plot_plane planes[3] = {{0.0f, lx_v3(0.85f, 0.05f, 0.05f)},
                            {90.0f, lx_v3(0.05f, 0.2f, 0.9f)}};
    int plane_count = 2;
    bool carries[3] = {false, false, true};
    lx_ies_peak_plane(p, &peak_h);
    float top = 0.0f; /* the distribution's largest value (resampled A/B: <= peak) */
    lx_ies_plane_peak(p, peak_h, &top);
    for (int k = 0; k < 2; k++) {
        float m = 0.0f;
        lx_ies_plane_peak(p, planes[k].h, &m);
        carries[k] = top > 0.0f && m >= top * (1.0f - (float)PEAK_PLANE_TOLERANCE);
        if (!carries[k] && top > 0.0f)
            printf("plane C%s-C%s: maximum %s cd, %s%% of the peak: no beam or field angle\n",
                   cli_num(planes[k].h), cli_num(planes[k].h + 180.0f), cli_num_digits(m, 5),
                   cli_num_digits(100.0 * m / top, 2));
    }
    if (top > 0.0f && !carries[0] && !carries[1]) {
        planes[2] = (plot_plane){peak_h, lx_v3(0.1f, 0.6f, 0.1f)};
        plane_count = 3;
    }
    for (int k = 0; k < plane_count; k++) {
        if (!carries[k])
            continue;
        double beam, field;
        if (lx_ies_beam_field(p, planes[k].h, &beam, &field) != LX_OK) {
            cli_error("%s", lx_last_error());
            lx_ies_free(p);
            return EXIT_FAILED;
        }
        char name[64];
        snprintf(name, sizeof name, "C%s-C%s", cli_num_digits(planes[k].h, 4),
                 cli_num_digits(planes[k].h + 180.0f, 4));
        print_spread("beam", name, beam, 50);
        print_spread("field", name, field, 10);
    }
    int rc = EXIT_OK;
    if (plot_path) {
        /* one file, written under a temporary name and renamed */
        if (plot(p, planes, plane_count, plot_path) != LX_OK) {
            cli_error("%s", lx_last_error());
            rc = EXIT_FAILED;
        }
    }
    lx_ies_free(p);
    return rc;
}
