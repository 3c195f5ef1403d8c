/* Pinhole cameras: the view basis, projection of points, and framing a
 * box from a named direction (the distance solved per corner so every
 * corner lies inside the view frustum). */
#include "render_internal.h"

#include <math.h>
#include <string.h>

static const char *const view_names[] = {"iso", "front", "back", "left", "right", "top"};

const char *lx_view_name(lx_view view)
{
    return (unsigned)view < sizeof view_names / sizeof view_names[0] ? view_names[view] : NULL;
}

bool lx_view_parse(const char *name, lx_view *out)
{
    for (unsigned i = 0; i < sizeof view_names / sizeof view_names[0]; i++)
        if (name && strcmp(name, view_names[i]) == 0) {
            *out = (lx_view)i;
            return true;
        }
    return false;
}

static float camera_fov(const lx_camera *cam)
{
    return cam->fov > 0.0f ? cam->fov : LX_DEG2RAD(LX_RENDER_DEFAULT_FOV_DEGREES);
}

/* The up hint: the camera's, else +Y, else -Z when the view runs along Y. */
static lx_vec3 up_hint(lx_vec3 fwd, lx_vec3 up)
{
    if (up.x != 0.0f || up.y != 0.0f || up.z != 0.0f)
        return up;
    return fabsf(fwd.y) > 0.999f ? lx_v3(0, 0, -1) : lx_v3(0, 1, 0);
}

lx_status lx_camera_check(const lx_camera *cam)
{
    if (!cam)
        return lx_fail_null(__func__, "cam");
    if (!lx_vec3_finite(cam->eye) || !lx_vec3_finite(cam->target) || !lx_vec3_finite(cam->up) ||
        !isfinite(cam->fov) || !isfinite(cam->ortho_height))
        return lx_fail(LX_ERR_INVALID, "camera: eye, target, up and fov must be finite");
    if (cam->ortho_height < 0.0f)
        return lx_fail(LX_ERR_INVALID, "camera: ortho_height %g is negative",
                       (double)cam->ortho_height);
    float fov = camera_fov(cam);
    if (fov >= LX_PI)
        return lx_fail(LX_ERR_INVALID,
                       "camera: the field of view must be below 180 degrees, not %g",
                       (double)LX_RAD2DEG(fov));
    lx_vec3 d = lx_sub(cam->target, cam->eye);
    float len = lx_length(d);
    if (!(len > 0.0f) || !isfinite(len))
        return lx_fail(LX_ERR_INVALID, "camera: eye and target are the same point");
    lx_vec3 fwd = lx_scale(d, 1.0f / len);
    lx_vec3 up = up_hint(fwd, cam->up);
    lx_vec3 side = lx_cross(fwd, lx_normalize(up));
    if (!(lx_length(side) > 1e-4f))
        return lx_fail(LX_ERR_INVALID, "camera: up points along the view direction");
    return LX_OK;
}

void lx_camera_basis(const lx_camera *cam, int width, int height, lx_camera_basis_t *b)
{
    b->eye = cam->eye;
    b->fwd = lx_normalize(lx_sub(cam->target, cam->eye));
    b->right = lx_normalize(lx_cross(b->fwd, lx_normalize(up_hint(b->fwd, cam->up))));
    b->up = lx_cross(b->right, b->fwd);
    b->ortho = cam->ortho_height > 0.0f;
    b->tan_y = b->ortho ? 0.5f * cam->ortho_height : tanf(0.5f * camera_fov(cam));
    b->tan_x = b->tan_y * (float)width / (float)height;
}

bool lx_camera_project(const lx_camera *cam, int width, int height, lx_vec3 p, float *x, float *y)
{
    lx_camera_basis_t b;
    lx_camera_basis(cam, width, height, &b);
    lx_vec3 r = lx_sub(p, b.eye);
    float z = lx_dot(r, b.fwd);
    if (!(z > 0.0f))
        return false;
    if (b.ortho)
        z = 1.0f;
    *x = 0.5f * (float)width * (1.0f + lx_dot(r, b.right) / (z * b.tan_x));
    *y = 0.5f * (float)height * (1.0f - lx_dot(r, b.up) / (z * b.tan_y));
    return true;
}

lx_camera lx_camera_frame(lx_vec3 lo, lx_vec3 hi, lx_view view, float fov, float aspect)
{
    static const float dirs[][3] = {{1, 1, 1},  {0, 0, 1}, {0, 0, -1},
                                    {-1, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    lx_camera cam = {.fov = fov > 0.0f && fov < LX_PI ? fov
                                                      : LX_DEG2RAD(LX_RENDER_DEFAULT_FOV_DEGREES)};
    if (!(aspect > 0.0f) || !isfinite(aspect))
        aspect = 16.0f / 9.0f;
    unsigned v = (unsigned)view < 6 ? (unsigned)view : 0;
    lx_vec3 from = lx_normalize(lx_v3(dirs[v][0], dirs[v][1], dirs[v][2]));
    lx_vec3 c = lx_scale(lx_add(lo, hi), 0.5f);
    cam.target = c;
    /* the basis depends on the direction only: place the eye at unit
     * distance to get it, then solve the distance */
    cam.eye = lx_add(c, from);
    lx_camera_basis_t b;
    lx_camera_basis(&cam, 1, 1, &b);
    b.tan_x = b.tan_y * aspect;
    const float margin = 0.95f;
    float tx = b.tan_x * margin, ty = b.tan_y * margin;
    /* The eye sits at c + sx right + sy up - D fwd. Corner k (image-plane
     * offsets x, y and depth z from c) is inside when |x - sx| <= (z + D) tx
     * and |y - sy| <= (z + D) ty: per axis D >= max(a - s / t, b + s / t)
     * with a = max(x / t - z), b = max(-x / t - z), least at s = t (a - b) / 2
     * where D = (a + b) / 2. */
    double ax = -INFINITY, bx = -INFINITY, ay = -INFINITY, by = -INFINITY, zmin = INFINITY;
    for (int k = 0; k < 8; k++) {
        lx_vec3 p = lx_v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
        lx_vec3 r = lx_sub(p, c);
        double x = lx_dot(r, b.right), y = lx_dot(r, b.up), z = lx_dot(r, b.fwd);
        ax = fmax(ax, x / tx - z), bx = fmax(bx, -x / tx - z);
        ay = fmax(ay, y / ty - z), by = fmax(by, -y / ty - z);
        zmin = fmin(zmin, z);
    }
    double sx = tx * (ax - bx) / 2.0, sy = ty * (ay - by) / 2.0;
    double dist = fmax((ax + bx) / 2.0, (ay + by) / 2.0);
    float extent = lx_length(lx_sub(hi, lo));
    /* the eye stays in front of every corner */
    dist = fmax(dist, -zmin + 1e-3 * extent);
    if (!(extent > 0.0f))
        dist = 1.0, sx = 0.0, sy = 0.0;
    cam.target = lx_add(c, lx_add(lx_scale(b.right, (float)sx), lx_scale(b.up, (float)sy)));
    cam.eye = lx_sub(cam.target, lx_scale(b.fwd, (float)dist));
    cam.up = b.up;
    return cam;
}

lx_camera lx_camera_from_scene(const lx_scene_camera *sc)
{
    lx_camera cam = {.eye = sc->eye, .target = lx_add(sc->eye, sc->forward), .up = sc->up};
    if (sc->type == LX_SCENE_CAMERA_PERSPECTIVE)
        cam.fov = sc->yfov;
    else
        cam.ortho_height = 2.0f * fabsf(sc->ymag);
    return cam;
}
