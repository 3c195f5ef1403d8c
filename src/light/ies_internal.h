/* Private to src/light: the parsed IES profile shared by the LM-63 reader
 * (ies.c) and the type A/B conversion (ies_types.c). */
#ifndef LUXEL_LIGHT_IES_INTERNAL_H
#define LUXEL_LIGHT_IES_INTERNAL_H

#include "luxel/light.h"

#define IES_MAX_FILE_SIZE (16u << 20)
#define IES_MAX_ANGLES 100000
#define IES_MAX_VALUES 4194304 /* vertical x horizontal */
#define IES_MAX_KEYWORDS 10000
#define IES_KEY_MAX 64
#define IES_VALUE_MAX 256
#define IES_ANGLE_EPS 1e-4
#define IES_PI 3.14159265358979323846
#define IES_AB_MAX_STEP 1.0  /* degrees: coarsest type C grid made from an A/B file */
#define IES_AB_MIN_STEP 0.25 /* degrees: finest */

typedef struct ies_keyword {
    char key[IES_KEY_MAX];
    char value[IES_VALUE_MAX];
} ies_keyword;

struct lx_ies_profile {
    char version[32];
    ies_keyword *keywords;
    int keyword_count;
    bool tilt_included;
    int lamp_count;
    double lumens_per_lamp, multiplier, ballast_factor, ballast_lamp_factor, input_watts;
    int photometric_type, units;
    double width, length, height;
    int nv, nh;
    float *vert;  /* nv degrees, strictly increasing */
    float *horiz; /* nh degrees, strictly increasing */
    float *cd;    /* nh planes of nv values, scaled */
    lx_ies_symmetry symmetry;
    /* type A and B: the file's own angles (vert, horiz and cd then hold the
     * type C grid made from them); NULL for type C */
    float *file_vert, *file_horiz;
    int file_nv, file_nh;
    float peak;
    int refs; /* owners: lx_ies_retain adds one, lx_ies_free drops one */
};

/* |a - b| within IES_ANGLE_EPS degrees. */
bool ies_near(float a, double b);
/* Index i and weight t with a[i] <= x <= a[i+1] (n >= 2, a[0] <= x <= a[n-1]). */
void ies_bracket(const float *a, int n, float x, int *i, float *t);
/* Checks the type C angle ranges and sets p->symmetry; errors name the
 * vertical (vline) or horizontal (hline) angle line. */
lx_status ies_classify(lx_ies_profile *p, const char *name, int vline, int hline);
/* Resamples a type A or B table onto a type C grid (ies_types.c). */
lx_status ies_convert_ab(lx_ies_profile *p, const char *name, int vline, int hline);

static inline float ies_lerp(float a, float b, float t)
{
    return a + (b - a) * t;
}

#endif
