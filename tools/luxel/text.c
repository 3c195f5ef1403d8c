/* Numbers and counts as people write them, for every line the CLI prints
 * to humans: "1000 texels/m", "0.25", "1 lightmap", "2 lightmaps", and 0
 * for the float noise around zero (-5.96e-08). */
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Rotating buffers: several numbers in one printf. */
#define NUM_SLOTS 16
#define NUM_SIZE 48

const char *cli_num_digits(double v, int digits)
{
    static _Thread_local char slots[NUM_SLOTS][NUM_SIZE];
    static _Thread_local unsigned next;
    char *buf = slots[next++ % NUM_SLOTS];
    if (digits < 1)
        digits = 1;
    if (digits > 15)
        digits = 15;
    if (isnan(v))
        return strcpy(buf, "nan");
    if (isinf(v))
        return strcpy(buf, v < 0 ? "-inf" : "inf");
    double a = fabs(v);
    if (a < CLI_NUM_ZERO)
        return strcpy(buf, "0");
    if (a >= 1e-4 && a < 1e15) {
        /* fixed notation: the integer part whole, the decimals the
         * significant digits leave, trailing zeros cut */
        int whole = a >= 1.0 ? (int)floor(log10(a)) + 1 : 0;
        int decimals = digits - whole;
        if (a < 1.0)
            decimals = digits - (int)floor(log10(a)) - 1;
        if (decimals < 0)
            decimals = 0;
        snprintf(buf, NUM_SIZE, "%.*f", decimals, v);
        if (strchr(buf, '.')) {
            size_t n = strlen(buf);
            while (buf[n - 1] == '0')
                buf[--n] = '\0';
            if (buf[n - 1] == '.')
                buf[--n] = '\0';
        }
        if (strcmp(buf, "-0") == 0)
            strcpy(buf, "0");
        return buf;
    }
    snprintf(buf, NUM_SIZE, "%.*g", digits, v);
    return buf;
}

const char *cli_num(double v)
{
    return cli_num_digits(v, 6);
}

const char *cli_plural(uint64_t n, const char *one, const char *many)
{
    return n == 1 ? one : many;
}
