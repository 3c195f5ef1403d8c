/* Writes the inputs the headers' USAGE examples read: the sky as Radiance
 * HDR (from gen_scenes' PFM) and a small IES LM-63-2002 file of a
 * rotationally symmetric lamp.
 * usage: make_usage_inputs SKY.pfm SKY.hdr LAMP.ies */
#include "luxel/luxel.h"

#include <stdio.h>

static const char lamp_ies[] = "IESNA:LM-63-2002\n"
                               "[TEST] luxel USAGE examples\n"
                               "[MANUFAC] luxel\n"
                               "TILT=NONE\n"
                               "1 -1 1 5 1 1 2 0 0 0\n"
                               "1 1 60\n"
                               "0 22.5 45 67.5 90\n"
                               "0\n"
                               "800 740 566 306 0\n";

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: make_usage_inputs SKY.pfm SKY.hdr LAMP.ies\n");
        return 2;
    }
    lx_image sky;
    if (lx_image_load(argv[1], NULL, &sky) != LX_OK ||
        lx_image_write(argv[2], &sky, NULL) != LX_OK) {
        fprintf(stderr, "make_usage_inputs: %s\n", lx_last_error());
        lx_image_free(&sky);
        return 1;
    }
    lx_image_free(&sky);
    FILE *fp = fopen(argv[3], "w");
    if (!fp || fputs(lamp_ies, fp) < 0 || fclose(fp) != 0) {
        fprintf(stderr, "make_usage_inputs: cannot write %s\n", argv[3]);
        return 1;
    }
    return 0;
}
