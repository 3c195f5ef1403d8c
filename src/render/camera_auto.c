/* The default camera of a scene with no camera of its own: the iso framing
 * of its bounds (camera.c; the nodes with a lightmap, sky domes and a
 * backdrop left out),
 * checked by what it sees. A grid of probe rays
 * through the view finds the first surface along each (both faces); with
 * the bake's lightmaps, a small render of the same view (one sample a
 * pixel on the same grid) tells which of those surfaces are lit. A probe
 * scores when its first surface is a front face and lit. When less than
 * half of what the iso view meets scores, the framings from the four
 * sides, then views from inside the bounds - raised, near one end of a
 * horizontal axis, looking along it - are scored too, and the first group
 * with a view of which at least half scores gives the one with the most
 * scoring probes (the first in that order unless a later one scores
 * clearly more): a closed room seen from
 * outside shows the back faces of walls that face in, or the unlit
 * outside of walls with two sides; a box open on one side is best seen
 * through that side. Before all that, a scene whose four inside views
 * each meet something on 90% of their probes is a closed room (walls
 * all round) and is shown from inside, by its best right inside view,
 * however lit its outside. */
#include "render_internal.h"
#include "scene/node_bake.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* probe rays per view: a grid over the image, PROBES_Y rows and as many
 * columns as keep the image's aspect (at most MAX_X) */
#define PROBES_Y 18
#define MAX_X 64
#define PROBES (MAX_X * PROBES_Y)
/* an inside eye's height in the bounds, from the bottom */
#define INSIDE_HEIGHT 0.55f
/* an inside eye's distance from the bounds' centre along its view axis,
 * as a fraction of the bounds' extent on that axis (0.35: 15% of the way
 * in from the wall behind it) */
#define INSIDE_BACK 0.35f
/* a view is right when at least this fraction of what it meets is lit
 * front faces */
#define GOOD 0.5f
/* the inside views of a closed room meet the scene on at least this
 * fraction of their probes each */
#define ENCLOSED 0.9f
/* iso, four side framings, four inside views */
#define VIEWS 9
/* lit: luminance above this fraction of the brightest view's median */
#define LIT_FRACTION 0.01
/* a later view of a group replaces an earlier one that is right only when
 * it scores this much more: views of a symmetric room score within noise
 * of each other, and the camera must not flip between two bakes of it */
#define CLEARLY_BETTER 0.05f

enum { MISS = 0, FRONT, BACK, BLOCKED };

typedef struct view_probe {
    lx_camera cam;
    int nx; /* columns */
    unsigned char kind[PROBES];
    float lum[PROBES]; /* rendered luminance, -1 where the render missed */
    double median;     /* of the covered pixels' luminance */
} view_probe;

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* Probes v->cam's view on a v->nx x PROBES_Y grid: first surfaces, and
 * with lm a 1-sample render of that size. Hits nearer than near count as
 * blocked (an eye against or inside something). */
static lx_status probe(const lx_scene *scene, const lx_lightmaps *lm, const lx_tracer *tracer,
                       float near, view_probe *v)
{
    lx_camera_basis_t b;
    int nx = v->nx;
    lx_camera_basis(&v->cam, nx, PROBES_Y, &b);
    for (int j = 0; j < PROBES_Y; j++)
        for (int i = 0; i < nx; i++) {
            float sx = (2.0f * ((float)i + 0.5f) / (float)nx - 1.0f) * b.tan_x;
            float sy = (1.0f - 2.0f * ((float)j + 0.5f) / PROBES_Y) * b.tan_y;
            lx_vec3 d = lx_normalize(
                lx_add(b.fwd, lx_add(lx_scale(b.right, sx), lx_scale(b.up, sy))));
            lx_ray r = {.origin = b.eye, .tmin = 0.0f, .dir = d, .tmax = INFINITY};
            lx_hit h;
            unsigned char *k = &v->kind[j * nx + i];
            if (!lx_tracer_closest_kind(tracer, &r, LX_RAY_FRAMING, &h))
                *k = MISS;
            else if (h.t < near)
                *k = BLOCKED;
            else
                *k = lx_dot(h.normal, d) > 0.0f ? BACK : FRONT;
        }
    v->median = 0.0;
    if (!lm)
        return LX_OK;
    float coverage[PROBES], sorted[PROBES];
    lx_render_desc d = {.width = nx, .height = PROBES_Y, .samples = 1, .camera = v->cam,
                        .coverage = coverage, .threads = 1};
    lx_image img;
    lx_status st = lx_render_view_quiet(scene, lm, tracer, &d, &img, true);
    if (st != LX_OK)
        return st;
    int n = 0;
    for (int p = 0; p < nx * PROBES_Y; p++) {
        v->lum[p] = coverage[p] > 0.0f ? lx_luminance(img.data + 3 * p) : -1.0f;
        if (v->lum[p] >= 0.0f)
            sorted[n++] = v->lum[p];
    }
    lx_image_free(&img);
    if (n) {
        qsort(sorted, (size_t)n, sizeof *sorted, cmp_float);
        v->median = sorted[n / 2];
    }
    return LX_OK;
}

/* the fraction of probes on a lit front face; *of_hits: the fraction of
 * the probes that meet something */
static float score(const view_probe *v, bool use_light, double lit, float *of_hits)
{
    int n = 0, hits = 0, count = v->nx * PROBES_Y;
    for (int p = 0; p < count; p++) {
        n += v->kind[p] == FRONT && (!use_light || v->lum[p] > lit);
        hits += v->kind[p] != MISS;
    }
    *of_hits = hits ? (float)n / (float)hits : 0.0f;
    return (float)n / (float)count;
}

/* The bounds the default camera frames: the nodes that get a lightmap
 * and are neither sky domes nor a backdrop (what a bake lights, without
 * the plain around it), else the scene's. */
static bool framed_bounds(const lx_scene *scene, lx_vec3 *lo, lx_vec3 *hi)
{
    bool any = false;
    lx_vec3 a = lx_v3(INFINITY, INFINITY, INFINITY), b = lx_v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t n = 0; n < scene->node_count; n++) {
        const lx_node *node = &scene->nodes[n];
        if (node->bake.sky || node->bake.no_lightmap || node->bake.backdrop)
            continue;
        any |= lx_node_grow_bounds(scene, node, &a, &b);
    }
    if (!any)
        return lx_scene_bounds(scene, lo, hi);
    *lo = a;
    *hi = b;
    return true;
}

/* Walls all round: every inside view (v[5..8]) meets the scene on nearly
 * every probe (a window or a door lets a little through). A bake of a
 * closed room is for its inside, however lit the outside of its walls (a
 * sun on the roof): the best right inside view, into *out and info;
 * false when the scene is open or no inside view is right. */
static bool closed_room_view(const view_probe *v, int count, bool use_light, double lit,
                             char names[][48], lx_camera *out, lx_camera_auto_info *info)
{
    for (int k = 5; k < VIEWS; k++) {
        int met = 0;
        for (int p = 0; p < count; p++)
            met += v[k].kind[p] != MISS;
        if ((float)met < ENCLOSED * (float)count)
            return false;
    }
    int room = 0;
    float room_score = 0.0f, good;
    for (int k = 5; k < VIEWS; k++) {
        float s = score(&v[k], use_light, lit, &good);
        if (good >= GOOD && s > room_score + (room ? CLEARLY_BETTER : 0.0f)) {
            room = k;
            room_score = s;
        }
    }
    if (!room)
        return false;
    *out = v[room].cam;
    info->moved = info->inside = info->enclosed = true;
    info->score = room_score;
    snprintf(info->placement, sizeof info->placement, "%s", names[room]);
    return true;
}

lx_status lx_camera_auto(const lx_scene *scene, const lx_lightmaps *lm, const lx_tracer *tracer,
                         float fov, float aspect, lx_camera *out, lx_camera_auto_info *info)
{
    if (!scene)
        return lx_fail_null(__func__, "scene");
    if (!out)
        return lx_fail_null(__func__, "out");
    lx_camera_auto_info local;
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    lx_vec3 lo, hi;
    if (!framed_bounds(scene, &lo, &hi))
        return lx_fail(LX_ERR_INVALID, "%s: the scene is empty: nothing to frame",
                       scene->path ? scene->path : "render");
    if (!(fov > 0.0f && fov < LX_PI))
        fov = LX_DEG2RAD(LX_RENDER_DEFAULT_FOV_DEGREES);
    if (!(aspect > 0.0f) || !isfinite(aspect))
        aspect = 16.0f / 9.0f;
    *out = lx_camera_frame(lo, hi, LX_VIEW_ISO, fov, aspect);
    snprintf(info->placement, sizeof info->placement, "iso");
    lx_vec3 e = lx_sub(hi, lo);
    float diag = lx_length(e);
    if (!tracer || !(diag > 0.0f) || !isfinite(diag))
        return LX_OK;
    float near = 0.02f * diag;

    /* view 0: iso; 1..4: framed from the front, back, left and right;
     * 5..8: inside, along the longer horizontal axis first */
    view_probe *v = calloc(VIEWS, sizeof *v);
    if (!v)
        return lx_fail(LX_ERR_NOMEM, "render: out of memory probing the default view");
    char names[VIEWS][48];
    int nx = (int)lrintf((float)PROBES_Y * aspect);
    nx = nx < 2 ? 2 : nx > MAX_X ? MAX_X : nx;
    for (int k = 0; k < VIEWS; k++)
        v[k].nx = nx;
    v[0].cam = *out;
    static const lx_view sides[4] = {LX_VIEW_FRONT, LX_VIEW_BACK, LX_VIEW_LEFT, LX_VIEW_RIGHT};
    for (int k = 0; k < 4; k++) {
        v[k + 1].cam = lx_camera_frame(lo, hi, sides[k], fov, aspect);
        snprintf(names[k + 1], sizeof names[k + 1], "%s", lx_view_name(sides[k]));
    }
    lx_vec3 c = lx_scale(lx_add(lo, hi), 0.5f);
    int axes[2] = {e.x >= e.z ? 0 : 2, e.x >= e.z ? 2 : 0};
    for (int k = 0; k < 4; k++) {
        int axis = axes[k / 2];
        float sign = k % 2 == 0 ? 1.0f : -1.0f;
        lx_vec3 dir = axis == 0 ? lx_v3(sign, 0.0f, 0.0f) : lx_v3(0.0f, 0.0f, sign);
        float extent = axis == 0 ? e.x : e.z;
        lx_vec3 eye = lx_sub(c, lx_scale(dir, INSIDE_BACK * extent));
        eye.y = lo.y + INSIDE_HEIGHT * e.y;
        v[k + 5].cam =
            (lx_camera){.eye = eye, .target = lx_add(eye, dir), .up = lx_v3(0, 1, 0), .fov = fov};
        snprintf(names[k + 5], sizeof names[k + 5], "inside, looking along %c%c",
                 sign > 0.0f ? '+' : '-', axis == 0 ? 'X' : 'Z');
    }
    lx_status st = LX_OK;
    double brightest = 0.0;
    for (int k = 0; k < VIEWS && st == LX_OK; k++) {
        st = probe(scene, lm, tracer, near, &v[k]);
        brightest = fmax(brightest, v[k].median);
    }
    if (st != LX_OK) {
        free(v);
        return st;
    }
    /* without light to judge by (no lightmaps, or all black), faces only */
    bool use_light = lm && brightest > 0.0;
    double lit = LIT_FRACTION * brightest;
    int hits = 0, back = 0, unlit = 0, count = nx * PROBES_Y;
    for (int p = 0; p < count; p++) {
        hits += v[0].kind[p] != MISS;
        back += v[0].kind[p] == BACK;
        unlit += v[0].kind[p] == FRONT && use_light && !(v[0].lum[p] > lit);
    }
    info->outside_hit = (float)hits / (float)count;
    info->outside_back = hits ? (float)back / (float)hits : 0.0f;
    info->outside_unlit = hits ? (float)unlit / (float)hits : 0.0f;
    float good;
    info->outside_score = info->score = score(&v[0], use_light, lit, &good);
    float iso_good = good;
    if (hits > 0 && closed_room_view(v, count, use_light, lit, names, out, info)) {
        free(v);
        return LX_OK;
    }
    if (hits == 0 || iso_good >= GOOD) {
        free(v);
        return LX_OK;
    }
    /* the iso view shows mostly the wrong side: the side framing that
     * shows the most of the right side (the whole scene stays in view),
     * else the best inside view; each must be right itself */
    for (int group = 0; group < 2 && !info->moved; group++) {
        int best = 0;
        float best_score = info->outside_score;
        for (int k = 1 + 4 * group; k < 5 + 4 * group; k++) {
            float s = score(&v[k], use_light, lit, &good);
            if (good >= GOOD && s > best_score + (best ? CLEARLY_BETTER : 0.0f)) {
                best = k;
                best_score = s;
            }
        }
        if (best != 0) {
            *out = v[best].cam;
            info->moved = true;
            info->inside = group == 1;
            info->score = best_score;
            snprintf(info->placement, sizeof info->placement, "%s", names[best]);
        }
    }
    free(v);
    return LX_OK;
}
