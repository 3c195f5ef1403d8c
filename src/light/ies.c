/* IES LM-63 photometric data files (ANSI/IESNA LM-63-1986, -1991, -1995 and
 * -2002, "Standard File Format for the Electronic Transfer of Photometric
 * Data"): the reader, bilinear interpolation of the candela table extended
 * by the file's horizontal symmetry, and the luminous flux integrated over
 * the sphere (midpoint rule, dOmega = sin(theta) dtheta dphi), as used by
 * Filament's photometric lights (R. Guy and M. Agopian, "Physically Based
 * Rendering in Filament").
 *
 * Layout read here: an optional "IESNA:LM-63-<year>" / "IESNA91" first line
 * (a 1986 file has none), keyword or label lines, "TILT=NONE|INCLUDE|file",
 * the tilt block when INCLUDE (geometry, count, angles, factors), then a
 * stream of numbers separated by blanks, commas or line breaks: lamps,
 * lumens per lamp, candela multiplier, vertical and horizontal counts,
 * photometric type, units, width, length, height, ballast factor, ballast-
 * lamp factor ("future use" since 1995), input watts, the vertical angles,
 * the horizontal angles and the candela values, one plane after another.
 *
 * Photometric types A and B are resampled onto a type C grid when loaded
 * (ies_types.c). */
#include "ies_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- the number stream --------------------------------------------------- */

typedef struct ies_reader {
    const char *p, *end;
    const char *name;
    int line;      /* line of p */
    int tok_line;  /* line of the last token read */
    char tok[64];  /* the last token, cut to fit */
    bool tok_long; /* the token did not fit */
} ies_reader;

static bool is_sep(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || c == ',' || c == '\n';
}

/* The next token, or false at the end of the text. */
static bool next_token(ies_reader *r)
{
    while (r->p < r->end && is_sep(*r->p)) {
        if (*r->p == '\n')
            r->line++;
        r->p++;
    }
    if (r->p >= r->end)
        return false;
    r->tok_line = r->line;
    size_t n = 0;
    r->tok_long = false;
    while (r->p < r->end && !is_sep(*r->p)) {
        if (n + 1 < sizeof r->tok)
            r->tok[n++] = *r->p;
        else
            r->tok_long = true;
        r->p++;
    }
    r->tok[n] = '\0';
    /* a NUL byte inside the token makes it a non-number */
    if (strlen(r->tok) != n)
        r->tok_long = true;
    return true;
}

/* Reads one finite number for `what`; at the end of the text, fails with
 * "expected <expected> <plural>, found <found>". */
static lx_status read_number(ies_reader *r, const char *what, double *out, long expected,
                             long found, const char *plural)
{
    if (!next_token(r)) {
        if (plural)
            return lx_fail(LX_ERR_FORMAT, "%s: line %d: expected %ld %s, found %ld (file ends)",
                           r->name, r->tok_line, expected, plural, found);
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: file ends before the %s", r->name, r->tok_line,
                       what);
    }
    char *endp;
    double v = strtod(r->tok, &endp);
    if (r->tok_long || endp == r->tok || *endp != '\0')
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: %s: '%.20s' is not a number", r->name,
                       r->tok_line, what, r->tok);
    if (!isfinite(v))
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: %s: '%.20s' is not a finite number", r->name,
                       r->tok_line, what, r->tok);
    *out = v;
    return LX_OK;
}

/* A whole number in [lo, hi]. */
static lx_status read_int(ies_reader *r, const char *what, long lo, long hi, int *out)
{
    double v;
    lx_status st = read_number(r, what, &v, 0, 0, NULL);
    if (st != LX_OK)
        return st;
    if (v != floor(v) || v < (double)lo || v > (double)hi)
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: %s is %s, must be a whole number in %ld..%ld",
                       r->name, r->tok_line, what, r->tok, lo, hi);
    *out = (int)v;
    return LX_OK;
}

/* n strictly increasing angles in [lo, hi]; note ends the range message. */
static lx_status read_angles(ies_reader *r, const char *what, int n, double lo, double hi,
                             const char *note, float *out)
{
    for (int i = 0; i < n; i++) {
        double v;
        lx_status st = read_number(r, what, &v, n, i, what);
        if (st != LX_OK)
            return st;
        if (v < lo || v > hi)
            return lx_fail(LX_ERR_FORMAT, "%s: line %d: %s %d is %s, outside %g..%g%s", r->name,
                           r->tok_line, what, i + 1, r->tok, lo, hi, note);
        if (i > 0 && !((float)v > out[i - 1]))
            return lx_fail(LX_ERR_FORMAT,
                           "%s: line %d: %s out of order: %s follows %g (angles must increase)",
                           r->name, r->tok_line, what, r->tok, (double)out[i - 1]);
        out[i] = (float)v;
    }
    return LX_OK;
}

/* ---- the text header ------------------------------------------------------ */

static bool starts_with_ci(const char *s, const char *end, const char *prefix)
{
    for (; *prefix; prefix++, s++) {
        if (s >= end)
            return false;
        char c = *s, p = *prefix;
        if (c >= 'a' && c <= 'z')
            c = (char)(c - 'a' + 'A');
        if (c != p)
            return false;
    }
    return true;
}

static void trim(const char **b, const char **e)
{
    while (*b < *e && (**b == ' ' || **b == '\t' || **b == '\r'))
        (*b)++;
    while (*e > *b && ((*e)[-1] == ' ' || (*e)[-1] == '\t' || (*e)[-1] == '\r'))
        (*e)--;
}

static void copy_span(char *dst, size_t cap, const char *b, const char *e)
{
    size_t n = (size_t)(e - b);
    if (n >= cap)
        n = cap - 1;
    memcpy(dst, b, n);
    dst[n] = '\0';
    /* embedded NUL bytes just end the string early */
}

static lx_status add_keyword(lx_ies_profile *p, const char *name, int line, const char *b,
                             const char *e, int *cap)
{
    if (p->keyword_count >= IES_MAX_KEYWORDS)
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: more than %d lines before TILT=", name, line,
                       IES_MAX_KEYWORDS);
    if (p->keyword_count == *cap) {
        int ncap = *cap ? *cap * 2 : 16;
        ies_keyword *k = realloc(p->keywords, (size_t)ncap * sizeof *k);
        if (!k)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory for keywords", name);
        p->keywords = k;
        *cap = ncap;
    }
    ies_keyword *k = &p->keywords[p->keyword_count++];
    k->key[0] = '\0';
    if (b < e && *b == '[') {
        const char *close = memchr(b, ']', (size_t)(e - b));
        if (close) {
            copy_span(k->key, sizeof k->key, b + 1, close);
            b = close + 1;
            trim(&b, &e);
        }
    }
    copy_span(k->value, sizeof k->value, b, e);
    return LX_OK;
}

/* Reads the lines up to TILT=; leaves r after the TILT line. */
static lx_status read_header(lx_ies_profile *p, ies_reader *r, const char **tilt_b,
                             const char **tilt_e, int *tilt_line)
{
    int cap = 0;
    strcpy(p->version, "LM-63-1986");
    for (int line = 1; r->p < r->end; line++) {
        const char *b = r->p;
        const char *nl = memchr(b, '\n', (size_t)(r->end - b));
        const char *e = nl ? nl : r->end;
        r->p = nl ? nl + 1 : r->end;
        r->line = line + 1;
        trim(&b, &e);
        if (line == 1) {
            if (starts_with_ci(b, e, "IESNA:LM-63-") || starts_with_ci(b, e, "IES:LM-63-")) {
                const char *v = memchr(b, ':', (size_t)(e - b)) + 1;
                copy_span(p->version, sizeof p->version, v, e);
                continue;
            }
            if (starts_with_ci(b, e, "IESNA91")) {
                strcpy(p->version, "LM-63-1991");
                continue;
            }
        }
        if (starts_with_ci(b, e, "TILT")) {
            const char *eq = b + 4;
            while (eq < e && (*eq == ' ' || *eq == '\t'))
                eq++;
            if (eq < e && *eq == '=') {
                *tilt_b = eq + 1;
                *tilt_e = e;
                trim(tilt_b, tilt_e);
                *tilt_line = line;
                r->tok_line = line;
                return LX_OK;
            }
        }
        lx_status st = add_keyword(p, r->name, line, b, e, &cap);
        if (st != LX_OK)
            return st;
    }
    return lx_fail(LX_ERR_FORMAT, "%s: line %d: no TILT= line (not an IES LM-63 file?)", r->name,
                   r->line > 1 ? r->line - 1 : 1);
}

static lx_status read_tilt(ies_reader *r)
{
    int geometry = 0, count = 0; /* set whenever read_int succeeds */
    lx_status st = read_int(r, "lamp-to-luminaire geometry", 1, 3, &geometry);
    if (st == LX_OK)
        st = read_int(r, "number of tilt angles", 1, IES_MAX_ANGLES, &count);
    if (st != LX_OK)
        return st;
    float *angles = malloc((size_t)count * sizeof *angles);
    if (!angles)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for %d tilt angles", r->name, count);
    st = read_angles(r, "tilt angles", count, 0.0, 180.0, "", angles);
    free(angles);
    for (int i = 0; st == LX_OK && i < count; i++) {
        double f;
        st = read_number(r, "tilt multiplying factor", &f, count, i, "tilt multiplying factors");
        if (st == LX_OK && f < 0)
            st = lx_fail(LX_ERR_FORMAT, "%s: line %d: tilt multiplying factor %s is negative",
                         r->name, r->tok_line, r->tok);
    }
    return st;
}

/* ---- symmetry ------------------------------------------------------------- */

bool ies_near(float a, double b)
{
    return fabs((double)a - b) <= IES_ANGLE_EPS;
}

lx_status ies_classify(lx_ies_profile *p, const char *name, int vline, int hline)
{
    double v0 = p->vert[0], v1 = p->vert[p->nv - 1];
    if (p->nv < 2 || !((ies_near(p->vert[0], 0) || ies_near(p->vert[0], 90)) &&
                       (ies_near(p->vert[p->nv - 1], 90) || ies_near(p->vert[p->nv - 1], 180))))
        return lx_fail(LX_ERR_FORMAT,
                       "%s: line %d: vertical angles %g..%g are not 0-90, 90-180 or 0-180", name,
                       vline, v0, v1);
    double h0 = p->horiz[0], h1 = p->horiz[p->nh - 1];
    if (p->nh == 1 && ies_near(p->horiz[0], 0))
        p->symmetry = LX_IES_ROTATIONAL;
    else if (p->nh > 1 && ies_near(p->horiz[0], 0) && ies_near(p->horiz[p->nh - 1], 90))
        p->symmetry = LX_IES_QUADRANT;
    else if (p->nh > 1 && ies_near(p->horiz[0], 0) && ies_near(p->horiz[p->nh - 1], 180))
        p->symmetry = LX_IES_BILATERAL;
    else if (p->nh > 1 && ies_near(p->horiz[0], 90) && ies_near(p->horiz[p->nh - 1], 270))
        p->symmetry = LX_IES_BILATERAL_90;
    else if (p->nh > 1 && ies_near(p->horiz[0], 0) && h1 > 180 && h1 <= 360 + IES_ANGLE_EPS)
        p->symmetry = LX_IES_FULL;
    else
        return lx_fail(LX_ERR_FORMAT,
                       "%s: line %d: horizontal angles %g..%g match no symmetry (0, 0-90, 0-180, "
                       "90-270 or 0-360)",
                       name, hline, h0, h1);
    return LX_OK;
}

/* ---- parsing -------------------------------------------------------------- */

static lx_status parse(lx_ies_profile *p, ies_reader *r)
{
    const char *tb = NULL, *te = NULL; /* set whenever read_header succeeds */
    int tilt_line = 0;
    lx_status st = read_header(p, r, &tb, &te, &tilt_line);
    if (st != LX_OK)
        return st;
    if (te - tb == 4 && starts_with_ci(tb, te, "NONE")) {
        p->tilt_included = false;
    } else if (te - tb == 7 && starts_with_ci(tb, te, "INCLUDE")) {
        p->tilt_included = true;
        if ((st = read_tilt(r)) != LX_OK)
            return st;
    } else if (te == tb) {
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: TILT= needs NONE, INCLUDE or a file name",
                       r->name, tilt_line);
    } else {
        char file[80];
        copy_span(file, sizeof file, tb, te);
        return lx_fail(LX_ERR_UNSUPPORTED,
                       "%s: line %d: TILT=%s: tilt data in a separate file is not supported "
                       "(use TILT=NONE or TILT=INCLUDE)",
                       r->name, tilt_line, file);
    }

    double d;
    if ((st = read_int(r, "number of lamps", 1, 100000, &p->lamp_count)) != LX_OK)
        return st;
    if ((st = read_number(r, "lumens per lamp", &p->lumens_per_lamp, 0, 0, NULL)) != LX_OK)
        return st;
    if (p->lumens_per_lamp < 0 && p->lumens_per_lamp != -1.0)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: line %d: lumens per lamp is %s (must be >= 0, or -1 for absolute "
                       "photometry)",
                       r->name, r->tok_line, r->tok);
    if ((st = read_number(r, "candela multiplier", &p->multiplier, 0, 0, NULL)) != LX_OK)
        return st;
    if (p->multiplier < 0)
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: candela multiplier %s is negative", r->name,
                       r->tok_line, r->tok);
    if ((st = read_int(r, "number of vertical angles", 1, IES_MAX_ANGLES, &p->nv)) != LX_OK)
        return st;
    if ((st = read_int(r, "number of horizontal angles", 1, IES_MAX_ANGLES, &p->nh)) != LX_OK)
        return st;
    uint64_t total = (uint64_t)p->nv * (uint64_t)p->nh;
    if (total > IES_MAX_VALUES)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: line %d: %d vertical x %d horizontal angles is %llu candela values, "
                       "more than the %d allowed",
                       r->name, r->tok_line, p->nv, p->nh, (unsigned long long)total,
                       IES_MAX_VALUES);
    if ((st = read_int(r, "photometric type", 1, 3, &p->photometric_type)) != LX_OK)
        return st;
    if ((st = read_int(r, "units type", 1, 2, &p->units)) != LX_OK)
        return st;
    if ((st = read_number(r, "width", &p->width, 0, 0, NULL)) != LX_OK ||
        (st = read_number(r, "length", &p->length, 0, 0, NULL)) != LX_OK ||
        (st = read_number(r, "height", &p->height, 0, 0, NULL)) != LX_OK)
        return st;
    if ((st = read_number(r, "ballast factor", &p->ballast_factor, 0, 0, NULL)) != LX_OK)
        return st;
    if (p->ballast_factor < 0)
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: ballast factor %s is negative", r->name,
                       r->tok_line, r->tok);
    if ((st = read_number(r, "ballast-lamp photometric factor", &p->ballast_lamp_factor, 0, 0,
                          NULL)) != LX_OK)
        return st;
    if (p->ballast_lamp_factor < 0)
        return lx_fail(LX_ERR_FORMAT, "%s: line %d: ballast-lamp photometric factor %s is negative",
                       r->name, r->tok_line, r->tok);
    if ((st = read_number(r, "input watts", &d, 0, 0, NULL)) != LX_OK)
        return st;
    p->input_watts = d;

    p->vert = malloc((size_t)p->nv * sizeof *p->vert);
    p->horiz = malloc((size_t)p->nh * sizeof *p->horiz);
    p->cd = malloc((size_t)total * sizeof *p->cd);
    if (!p->vert || !p->horiz || !p->cd)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for %llu candela values", r->name,
                       (unsigned long long)total);
    /* type C: vertical 0..180 from the nadir, horizontal 0..360 around it;
     * types A and B: both -90..90 from the beam axis */
    bool type_c = p->photometric_type == 1;
    const char *note =
        type_c ? ""
               : (p->photometric_type == 2 ? " for photometric type B" : " for photometric type A");
    if ((st = read_angles(r, "vertical angles", p->nv, type_c ? 0.0 : -90.0, type_c ? 180.0 : 90.0,
                          note, p->vert)) != LX_OK)
        return st;
    int vline = r->tok_line;
    if ((st = read_angles(r, "horizontal angles", p->nh, type_c ? 0.0 : -90.0,
                          type_c ? 360.0 : 90.0, note, p->horiz)) != LX_OK)
        return st;
    int hline = r->tok_line;
    double scale = p->multiplier * p->ballast_factor * p->ballast_lamp_factor;
    p->peak = 0.0f;
    for (uint64_t i = 0; i < total; i++) {
        double c;
        if ((st = read_number(r, "candela value", &c, (long)total, (long)i, "candela values")) !=
            LX_OK)
            return st;
        if (c < 0)
            return lx_fail(LX_ERR_FORMAT, "%s: line %d: candela value %s is negative", r->name,
                           r->tok_line, r->tok);
        double v = c * scale;
        if (!(v <= 3.0e38))
            return lx_fail(LX_ERR_FORMAT, "%s: line %d: candela value %s x %g is too large",
                           r->name, r->tok_line, r->tok, scale);
        p->cd[i] = (float)v;
        if (p->cd[i] > p->peak)
            p->peak = p->cd[i];
    }
    if (next_token(r))
        return lx_fail(LX_ERR_FORMAT,
                       "%s: line %d: unexpected '%.20s' after the %llu candela values", r->name,
                       r->tok_line, r->tok, (unsigned long long)total);
    if (!type_c)
        return ies_convert_ab(p, r->name, vline, hline);
    return ies_classify(p, r->name, vline, hline);
}

lx_status lx_ies_parse(const char *text, size_t size, const char *name, lx_ies_profile **out)
{
    if (!text)
        return lx_fail_null(__func__, "text");
    if (!out)
        return lx_fail(LX_ERR_INVALID, "lx_ies_parse: out is NULL");
    *out = NULL;
    if (!name)
        name = "<ies>";
    if (!text && size)
        return lx_fail(LX_ERR_INVALID, "%s: no text", name);
    if (size > IES_MAX_FILE_SIZE)
        return lx_fail(LX_ERR_FORMAT, "%s: %zu bytes, more than the %u allowed for an IES file",
                       name, size, IES_MAX_FILE_SIZE);
    lx_ies_profile *p = calloc(1, sizeof *p);
    if (p)
        p->refs = 1;
    if (!p)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", name);
    ies_reader r = {.p = text, .end = text + size, .name = name, .line = 1, .tok_line = 1};
    lx_status st = parse(p, &r);
    if (st != LX_OK) {
        lx_ies_free(p);
        return st;
    }
    *out = p;
    return LX_OK;
}

lx_status lx_ies_load(const char *path, lx_ies_profile **out)
{
    if (!out || !path)
        return lx_fail(LX_ERR_INVALID, "lx_ies_load: path or out is NULL");
    *out = NULL;
    char *text;
    size_t size;
    lx_status st = lx_read_file(path, IES_MAX_FILE_SIZE, &text, &size);
    if (st != LX_OK)
        return st;
    st = lx_ies_parse(text, size, path, out);
    free(text);
    return st;
}

lx_ies_profile *lx_ies_retain(const lx_ies_profile *profile)
{
    lx_ies_profile *p = (lx_ies_profile *)profile;
    if (p)
        __atomic_add_fetch(&p->refs, 1, __ATOMIC_RELAXED);
    return p;
}

void lx_ies_free(lx_ies_profile *p)
{
    if (!p)
        return;
    if (__atomic_sub_fetch(&p->refs, 1, __ATOMIC_ACQ_REL) > 0)
        return;
    free(p->keywords);
    free(p->vert);
    free(p->horiz);
    free(p->cd);
    free(p->file_vert);
    free(p->file_horiz);
    free(p);
}

/* ---- evaluation ----------------------------------------------------------- */

/* Index i and weight t with a[i] <= x <= a[i+1] (n >= 2, a[0] <= x <= a[n-1]). */
void ies_bracket(const float *a, int n, float x, int *i, float *t)
{
    int lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (a[mid] <= x)
            lo = mid;
        else
            hi = mid;
    }
    *i = lo;
    float span = a[lo + 1] - a[lo];
    float w = (x - a[lo]) / span;
    *t = w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
}

/* The two planes and weight for horizontal angle h in [0, 360). */
static void horizontal_weights(const lx_ies_profile *p, float h, int *h0, int *h1, float *t)
{
    switch (p->symmetry) {
    case LX_IES_ROTATIONAL:
        *h0 = *h1 = 0;
        *t = 0.0f;
        return;
    case LX_IES_QUADRANT:
        if (h > 180.0f)
            h = 360.0f - h;
        if (h > 90.0f)
            h = 180.0f - h;
        break;
    case LX_IES_BILATERAL:
        if (h > 180.0f)
            h = 360.0f - h;
        break;
    case LX_IES_BILATERAL_90:
        if (h < 90.0f)
            h = 180.0f - h;
        else if (h > 270.0f)
            h = 540.0f - h;
        break;
    case LX_IES_FULL: {
        float last = p->horiz[p->nh - 1];
        if (h > last) { /* between the last plane and 360 = the first plane */
            *h0 = p->nh - 1;
            *h1 = 0;
            *t = (h - last) / (360.0f - last);
            return;
        }
        break;
    }
    }
    float lo = p->horiz[0], hi = p->horiz[p->nh - 1];
    h = h < lo ? lo : (h > hi ? hi : h);
    int i;
    ies_bracket(p->horiz, p->nh, h, &i, t);
    *h0 = i;
    *h1 = i + 1;
}

static float candela_at(const lx_ies_profile *p, float v, int h0, int h1, float th)
{
    if (v < p->vert[0] || v > p->vert[p->nv - 1])
        return 0.0f;
    int i;
    float tv;
    ies_bracket(p->vert, p->nv, v, &i, &tv);
    const float *a = p->cd + (size_t)h0 * (size_t)p->nv;
    const float *b = p->cd + (size_t)h1 * (size_t)p->nv;
    float ca = ies_lerp(a[i], a[i + 1], tv);
    float cb = ies_lerp(b[i], b[i + 1], tv);
    return ies_lerp(ca, cb, th);
}

float lx_ies_candela(const lx_ies_profile *p, float vertical_deg, float horizontal_deg)
{
    if (!p || !isfinite(vertical_deg) || !isfinite(horizontal_deg))
        return 0.0f;
    float v = fmodf(vertical_deg, 360.0f);
    float h = horizontal_deg;
    if (v < 0.0f)
        v += 360.0f;
    if (v > 180.0f) { /* past the zenith: the opposite half-plane */
        v = 360.0f - v;
        h += 180.0f;
    }
    h = fmodf(h, 360.0f);
    if (h < 0.0f)
        h += 360.0f;
    if (h >= 360.0f)
        h = 0.0f;
    int h0, h1;
    float th;
    horizontal_weights(p, h, &h0, &h1, &th);
    return candela_at(p, v, h0, h1, th);
}

double lx_ies_total_lumens(const lx_ies_profile *p)
{
    if (!p)
        return 0.0;
    /* midpoint rule on 0.1 x 0.5 degree cells; planes and the 90 degree
     * vertical boundary fall on cell edges */
    const int nt = 1800;
    const int np = p->symmetry == LX_IES_ROTATIONAL ? 1 : 720;
    const double dt = IES_PI / nt, dp = 2.0 * IES_PI / np;
    double sum = 0.0;
    for (int j = 0; j < np; j++) {
        float h = (float)((j + 0.5) * 360.0 / np);
        int h0, h1;
        float th;
        horizontal_weights(p, h, &h0, &h1, &th);
        double column = 0.0;
        for (int i = 0; i < nt; i++) {
            double theta = (i + 0.5) * dt;
            column +=
                (double)candela_at(p, (float)(theta * (180.0 / IES_PI)), h0, h1, th) * sin(theta);
        }
        sum += column;
    }
    return sum * dt * dp;
}

float lx_ies_peak_candela(const lx_ies_profile *p)
{
    return p ? p->peak : 0.0f;
}

/* ---- header access --------------------------------------------------------- */

void lx_ies_get_info(const lx_ies_profile *p, lx_ies_info *out)
{
    memset(out, 0, sizeof *out);
    if (!p)
        return;
    out->version = p->version;
    out->keyword_count = p->keyword_count;
    out->tilt_included = p->tilt_included;
    out->lamp_count = p->lamp_count;
    out->lumens_per_lamp = p->lumens_per_lamp;
    out->multiplier = p->multiplier;
    out->ballast_factor = p->ballast_factor;
    out->ballast_lamp_factor = p->ballast_lamp_factor;
    out->input_watts = p->input_watts;
    out->photometric_type = p->photometric_type;
    out->units = p->units;
    out->width = p->width;
    out->length = p->length;
    out->height = p->height;
    out->vertical_count = p->file_vert ? p->file_nv : p->nv;
    out->horizontal_count = p->file_vert ? p->file_nh : p->nh;
    out->vertical_angles = p->file_vert ? p->file_vert : p->vert;
    out->horizontal_angles = p->file_vert ? p->file_horiz : p->horiz;
    out->symmetry = p->symmetry;
}

const char *lx_ies_keyword(const lx_ies_profile *p, int index, const char **value)
{
    if (!p || index < 0 || index >= p->keyword_count)
        return NULL;
    if (value)
        *value = p->keywords[index].value;
    return p->keywords[index].key;
}

const char *lx_ies_symmetry_name(lx_ies_symmetry s)
{
    switch (s) {
    case LX_IES_ROTATIONAL:
        return "rotational";
    case LX_IES_QUADRANT:
        return "quadrant";
    case LX_IES_BILATERAL:
        return "bilateral 0-180";
    case LX_IES_BILATERAL_90:
        return "bilateral 90-270";
    case LX_IES_FULL:
        return "full";
    }
    return "unknown";
}
