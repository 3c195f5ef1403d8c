/* The default camera of a scene with no camera of its own: the iso framing
 * of its bounds (camera.c), checked by what it sees first. A grid of probe
 * rays through the view finds the first surface along each; when more of
 * them meet back faces than front faces (a closed room seen from outside:
 * its walls face in), the view shows the wrong side of the scene and other
 * views are tried - inside the bounds, raised, looking along each
 * horizontal axis from near one end, and the framings from the four sides
 * and the top - and the one that sees the most front faces is taken. */
#include "render_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* probe rays per view: a grid over the image */
#define PROBES_X 32
#define PROBES_Y 18
/* an inside eye's height in the bounds, from the bottom */
#define INSIDE_HEIGHT 0.55f
/* an inside eye's distance from the bounds' centre along its view axis,
 * as a fraction of the bounds' extent on that axis (0.35: 15% of the way
 * in from the wall behind it) */
#define INSIDE_BACK 0.35f

typedef struct probe_count {
    int front, back, blocked, miss;
} probe_count;

/* Probes cam's view (fov as given, aspect width / height). Hits nearer than
 * near count as blocked (an eye against or inside something). */
static probe_count probe(const lx_tracer *tracer, const lx_camera *cam, float aspect, float near)
{
    probe_count n = {0};
    lx_camera_basis_t b;
    lx_camera_basis(cam, 1, 1, &b);
    b.tan_x = b.tan_y * aspect;
    for (int j = 0; j < PROBES_Y; j++)
        for (int i = 0; i < PROBES_X; i++) {
            float sx = (2.0f * ((float)i + 0.5f) / PROBES_X - 1.0f) * b.tan_x;
            float sy = (1.0f - 2.0f * ((float)j + 0.5f) / PROBES_Y) * b.tan_y;
            lx_vec3 d = lx_normalize(
                lx_add(b.fwd, lx_add(lx_scale(b.right, sx), lx_scale(b.up, sy))));
            lx_ray r = {.origin = b.eye, .tmin = 0.0f, .dir = d, .tmax = INFINITY};
            lx_hit h;
            if (!lx_tracer_closest(tracer, &r, &h))
                n.miss++;
            else if (h.t < near)
                n.blocked++;
            else if (lx_dot(h.normal, d) > 0.0f)
                n.back++;
            else
                n.front++;
        }
    return n;
}

static float score(probe_count n)
{
    return (float)n.front / (float)(PROBES_X * PROBES_Y);
}

lx_status lx_camera_auto(const lx_scene *scene, const lx_tracer *tracer, float fov, float aspect,
                         lx_camera *out, lx_camera_auto_info *info)
{
    lx_camera_auto_info local;
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    lx_vec3 lo, hi;
    if (!lx_scene_bounds(scene, &lo, &hi))
        return lx_fail(LX_ERR_INVALID, "%s: the scene is empty: nothing to frame",
                       scene->path ? scene->path : "render");
    if (!(fov > 0.0f && fov < LX_PI))
        fov = LX_DEG2RAD(LX_RENDER_DEFAULT_FOV_DEGREES);
    if (!(aspect > 0.0f) || !isfinite(aspect))
        aspect = 16.0f / 9.0f;
    lx_camera iso = lx_camera_frame(lo, hi, LX_VIEW_ISO, fov, aspect);
    *out = iso;
    snprintf(info->placement, sizeof info->placement, "iso");
    if (!tracer)
        return LX_OK;
    lx_vec3 e = lx_sub(hi, lo);
    float diag = lx_length(e);
    if (!(diag > 0.0f) || !isfinite(diag))
        return LX_OK;
    float near = 0.02f * diag;
    probe_count first = probe(tracer, &iso, aspect, near);
    int hits = first.front + first.back + first.blocked;
    info->outside_hit = (float)hits / (float)(PROBES_X * PROBES_Y);
    info->outside_back = hits ? (float)first.back / (float)hits : 0.0f;
    info->score = score(first);
    if (first.back <= first.front)
        return LX_OK;

    /* other views, best first on ties: inside along the longer horizontal
     * axis, then the shorter, then outside framings */
    lx_vec3 c = lx_scale(lx_add(lo, hi), 0.5f);
    int axes[2] = {e.x >= e.z ? 0 : 2, e.x >= e.z ? 2 : 0};
    float best = info->score;
    for (int k = 0; k < 4; k++) {
        int axis = axes[k / 2];
        float sign = k % 2 == 0 ? 1.0f : -1.0f;
        lx_vec3 dir = axis == 0 ? lx_v3(sign, 0.0f, 0.0f) : lx_v3(0.0f, 0.0f, sign);
        float extent = axis == 0 ? e.x : e.z;
        lx_vec3 eye = lx_sub(c, lx_scale(dir, INSIDE_BACK * extent));
        eye.y = lo.y + INSIDE_HEIGHT * e.y;
        lx_camera cam = {.eye = eye, .target = lx_add(eye, dir), .up = lx_v3(0, 1, 0), .fov = fov};
        float s = score(probe(tracer, &cam, aspect, near));
        if (s > best) {
            best = s;
            *out = cam;
            info->inside = true;
            snprintf(info->placement, sizeof info->placement, "inside, looking along %c%c",
                     sign > 0.0f ? '+' : '-', axis == 0 ? 'X' : 'Z');
        }
    }
    static const lx_view sides[] = {LX_VIEW_FRONT, LX_VIEW_BACK, LX_VIEW_LEFT, LX_VIEW_RIGHT,
                                    LX_VIEW_TOP};
    for (size_t k = 0; k < sizeof sides / sizeof sides[0]; k++) {
        lx_camera cam = lx_camera_frame(lo, hi, sides[k], fov, aspect);
        float s = score(probe(tracer, &cam, aspect, near));
        if (s > best) {
            best = s;
            *out = cam;
            info->inside = false;
            snprintf(info->placement, sizeof info->placement, "%s", lx_view_name(sides[k]));
        }
    }
    info->moved = best > info->score;
    info->score = best;
    return LX_OK;
}
