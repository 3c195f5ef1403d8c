/*
 * gen_scenes.c - example scene generator: writes two binary glTF 2.0 (.glb)
 * scenes for trying out and testing luxel's lightmap baker, and a clear-sky
 * environment for its image-based lighting.
 *
 * Usage: gen_scenes OUTDIR
 *   writes OUTDIR/room.glb, OUTDIR/retro.glb and OUTDIR/sky.pfm, creating
 *   OUTDIR if needed. Each file is written to a temporary file in OUTDIR and
 *   renamed when complete.
 *
 * Standalone on purpose (libc + libm only, no libluxel) so the test inputs
 * come from code that shares nothing with the code under test.
 *
 * Conventions: glTF's right-handed, +Y up, metres; UV origin top-left.
 * Every primitive has POSITION, NORMAL (flat: vertices are duplicated per
 * face), TEXCOORD_0 (0..1 per face, for materials), TEXCOORD_1 (lightmap UVs)
 * and uint16 indices (uint32 if a primitive ever needs more than 65535
 * vertices). Faces are quads split into two counter-clockwise triangles seen
 * from the side the normal points to. Materials are pbrMetallicRoughness with
 * a linear baseColorFactor, metallic 0, roughness 1. Lights use
 * KHR_lights_punctual and point down their node's local -Z.
 *
 * Lightmap UVs: each node carries one mesh and each mesh gets one lightmap.
 * Every planar quad face is one chart, charts of a mesh never overlap, keep
 * the face's aspect ratio, share one texel density per mesh, and are packed
 * by a shelf packer with >= 4 texels of gutter at 64x64 (>= 4/64 in UV)
 * between charts and from the border.
 *
 * Scene 1, room.glb - a Cornell-box-like room, 4 m wide (x -2..2), 3 m tall
 * (y 0..3), 4 m deep (z -2..2), open on the +z side, normals facing in.
 *   node "room"       mesh "room": floor, ceiling, back wall (white 0.8),
 *                     left wall x=-2 (red 0.63,0.065,0.05), right wall x=+2
 *                     (green 0.14,0.45,0.09); one primitive per material,
 *                     five charts in one lightmap.
 *   node "tall_box"   1.2 x 1.8 x 1.2 m white box, 6 faces, at (-0.7,0,-0.6),
 *                     turned +18 degrees about Y.
 *   node "short_box"  0.9 m white cube, 6 faces, at (0.8,0,0.7), turned -17
 *                     degrees about Y.
 *   "ceiling_lamp"    point light, colour (1,0.95,0.85), 150 cd, range 12 m,
 *                     at (0,2.7,0).
 *   "spot"            spot light, white, 400 cd, range 15 m, cone 0.35/0.6
 *                     rad, at (1.5,2.8,1.5) aimed at the tall box's top
 *                     (-0.7,1.8,-0.6).
 *
 * Scene 2, retro.glb - a courtyard meant to be baked at a low density
 * (~4-8 texels per metre) for a chunky retro look.
 *   node "ground"     24 x 24 m plane at y=0 (grey 0.6) as a 4x4 grid of
 *                     quads sharing one chart.
 *   "pillar_0".."pillar_3"  1 x 4 x 1 m stone pillars (no bottom face) at
 *                     (-5,-5), (5,-5), (-5,5), (5,5) in x,z.
 *   node "wall"       8 x 1.5 x 0.5 m sandstone wall (no bottom face)
 *                     centred at the origin, running along x.
 *   node "stair"      6 sandstone steps (0.25 m rise, 0.35 m run, 1.2 m
 *                     wide) climbing in +z onto the wall's top from its -z
 *                     side, at x=2.
 *   node "gate"       stone arch at z=8: two 0.6 x 3 m posts and a
 *                     4.2 x 0.6 x 0.6 m lintel, opening 3 m wide.
 *   "sun"             directional light, colour (1,0.9,0.75), 10000 lux,
 *                     40 degrees above the horizon.
 *   "torch_a", "torch_b"  point lights, colour (1,0.6,0.25), 60 cd, range
 *                     8 m, 2.5 m up beside pillars 3 and 0.
 *
 * sky.pfm - a clear day as a 1024 x 512 equirectangular PFM (radiance in
 * nits, linear Rec.709; luxel's convention: +Y up, the centre column looks
 * down -Z, docs/ibl.md). A deliberately simple model, not a measured sky:
 *   sky       L = Lz (1.6 - 0.6 sin e) at elevation e, a blue tint of
 *             luminance 1, Lz = 15000 / (1.2 pi) nits so the sky alone gives
 *             15000 lux on a horizontal surface (the integral of
 *             (1.6 - 0.6 mu) mu over the upper hemisphere is 1.2 pi);
 *   sun       a disk of 1.5 degrees radius (wider than the real 0.27 so it
 *             spans a few pixels) where the retro scene's sun is, 40 degrees
 *             up, of luminance 80000 / (pi sin^2 1.5 deg):
 *             80000 lux at normal incidence, a warm white;
 *   ground    below the horizon, a Lambertian ground of albedo 0.2 under the
 *             sun and sky: 0.2 (80000 sin 40 deg + 15000) / pi nits.
 * Each pixel averages 4 x 4 sub-pixel samples, so the sun's edge is
 * antialiased.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define PI 3.14159265358979323846

/* Lightmap gutter: 4 texels at the 64x64 reference resolution. Packing uses
 * a hair more so the minimum survives rounding the UVs to float. */
#define LM_REF_RES 64.0
#define LM_GUTTER_TEXELS 4.0
#define LM_GUTTER ((LM_GUTTER_TEXELS + 0.05) / LM_REF_RES)

enum {
    MAX_NAME = 32,
    MAX_FACES = 64,
    MAX_PRIMS = 4,
    MAX_MESHES = 16,
    MAX_NODES = 24,
    MAX_LIGHTS = 8,
    MAX_MATERIALS = 8,
    MAX_ACCESSORS = MAX_MESHES * MAX_PRIMS * 5,
};

/* Box faces, for add_box's mask. */
enum {
    BOX_PX = 1,
    BOX_NX = 2,
    BOX_PY = 4,
    BOX_NY = 8,
    BOX_PZ = 16,
    BOX_NZ = 32,
    BOX_ALL = 63,
    BOX_NO_BOTTOM = BOX_ALL & ~BOX_NY,
    BOX_SIDES = BOX_PX | BOX_NX | BOX_PZ | BOX_NZ,
};

/* ---- errors and temporary files ---------------------------------------- */

static void error(const char *fmt, ...)
{
    va_list ap;
    fputs("gen_scenes: error: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* The temp file being written, so Ctrl-C can remove it (unlink is
 * async-signal-safe; the path lives in a static buffer for that reason). */
static char g_tmp_path[4096];
static volatile sig_atomic_t g_tmp_active;

static void on_signal(int sig)
{
    if (g_tmp_active)
        unlink(g_tmp_path);
    signal(sig, SIG_DFL);
    raise(sig);
}

/* ---- growable byte buffer ---------------------------------------------- */

typedef struct {
    unsigned char *data;
    size_t len, cap;
    int failed; /* sticky: set on the first allocation failure */
} bytes;

static int bytes_reserve(bytes *b, size_t extra)
{
    if (b->failed)
        return -1;
    if (extra > SIZE_MAX - b->len) {
        b->failed = 1;
        return -1;
    }
    if (b->len + extra <= b->cap)
        return 0;
    size_t cap = b->cap ? b->cap : 1024;
    while (cap < b->len + extra) {
        if (cap > SIZE_MAX / 2) {
            b->failed = 1;
            return -1;
        }
        cap *= 2;
    }
    unsigned char *p = realloc(b->data, cap);
    if (!p) {
        b->failed = 1;
        return -1;
    }
    b->data = p;
    b->cap = cap;
    return 0;
}

static void bytes_append(bytes *b, const void *p, size_t n)
{
    if (n > 0 && bytes_reserve(b, n) == 0) {
        memcpy(b->data + b->len, p, n);
        b->len += n;
    }
}

static void bytes_fill(bytes *b, unsigned char c, size_t n)
{
    if (n > 0 && bytes_reserve(b, n) == 0) { /* n = 0: data may still be NULL */
        memset(b->data + b->len, c, n);
        b->len += n;
    }
}

static void bytes_pad(bytes *b, unsigned char c)
{
    bytes_fill(b, c, (4 - b->len % 4) % 4);
}

static void bytes_printf(bytes *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0) {
        b->failed = 1;
        return;
    }
    /* +1 for vsnprintf's terminator, which is then dropped */
    if (bytes_reserve(b, (size_t)n + 1) != 0)
        return;
    va_start(ap, fmt);
    vsnprintf((char *)b->data + b->len, (size_t)n + 1, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

/* Binary glTF is little-endian whatever the host is. */
static void put_u32(bytes *b, uint32_t v)
{
    unsigned char c[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                          (unsigned char)(v >> 24)};
    bytes_append(b, c, 4);
}

static void put_u16(bytes *b, uint16_t v)
{
    unsigned char c[2] = {(unsigned char)v, (unsigned char)(v >> 8)};
    bytes_append(b, c, 2);
}

static void put_f32(bytes *b, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    put_u32(b, u);
}

/* ---- the sky --------------------------------------------------------------- */

#define SKY_W 1024
#define SKY_H 512

/* Radiance (nits, RGB) toward unit direction d of the sky described at the
 * top of this file. */
static void sky_radiance(const double d[3], const double sun[3], double out[3])
{
    const double sky_tint[3] = {0.62, 0.79, 1.18};   /* luminance 1 */
    const double sun_tint[3] = {1.04, 1.0, 0.9};     /* luminance ~1 */
    const double ground_tint[3] = {1.08, 1.0, 0.82}; /* luminance ~1 */
    const double sun_radius = 1.5 * PI / 180.0;
    const double sun_lux = 80000.0, sky_lux = 15000.0;
    double e = asin(d[1] < -1 ? -1 : d[1] > 1 ? 1 : d[1]);
    double cos_sun = d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2];
    if (e < 0.0) {
        double l = 0.2 * (sun_lux * sin(40.0 * PI / 180.0) + sky_lux) / PI;
        for (int k = 0; k < 3; k++)
            out[k] = l * ground_tint[k];
        return;
    }
    if (cos_sun >= cos(sun_radius)) {
        double l = sun_lux / (PI * sin(sun_radius) * sin(sun_radius));
        for (int k = 0; k < 3; k++)
            out[k] = l * sun_tint[k];
        return;
    }
    double lz = sky_lux / (1.2 * PI);
    double l = lz * (1.6 - 0.6 * sin(e));
    for (int k = 0; k < 3; k++)
        out[k] = l * sky_tint[k];
}

/* The equirect as a PFM: header, then rows bottom to top, little-endian
 * floats (the PFM convention). */
static void make_sky(bytes *out)
{
    /* toward the retro scene's sun (its light travels the other way) */
    double el = 40.0 * PI / 180.0, az = 30.0 * PI / 180.0;
    double sun[3] = {-cos(el) * sin(az), sin(el), cos(el) * cos(az)};
    bytes_printf(out, "PF\n%d %d\n-1.0\n", SKY_W, SKY_H);
    for (int row = SKY_H - 1; row >= 0; row--)
        for (int col = 0; col < SKY_W; col++) {
            double sum[3] = {0, 0, 0};
            for (int sy = 0; sy < 4; sy++)
                for (int sx = 0; sx < 4; sx++) {
                    double u = (col + (sx + 0.5) / 4.0) / SKY_W;
                    double v = (row + (sy + 0.5) / 4.0) / SKY_H;
                    double phi = 2.0 * PI * (u - 0.5), theta = PI * v;
                    double d[3] = {sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi)};
                    double l[3];
                    sky_radiance(d, sun, l);
                    for (int k = 0; k < 3; k++)
                        sum[k] += l[k] / 16.0;
                }
            for (int k = 0; k < 3; k++)
                put_f32(out, (float)sum[k]);
        }
}

/* Shortest decimal that reads back as the same float (0.95, not
 * 0.949999988); 9 digits always do, which accessor min/max rely on. */
static void json_float(bytes *js, float f)
{
    char s[32];
    for (int prec = 6; prec <= 9; prec++) {
        snprintf(s, sizeof s, "%.*g", prec, (double)f);
        if (strtof(s, NULL) == f)
            break;
    }
    bytes_printf(js, "%s", s);
}

static void json_floats(bytes *js, const float *v, int n)
{
    bytes_printf(js, "[");
    for (int i = 0; i < n; i++) {
        if (i)
            bytes_printf(js, ",");
        json_float(js, v[i]);
    }
    bytes_printf(js, "]");
}

/* ---- scene description -------------------------------------------------- */

/* A planar rectangle o + a*u + b*v (a, b in 0..1), normal along u x v,
 * drawn as nu x nv quads that share one lightmap chart. */
typedef struct {
    float o[3], u[3], v[3];
    int nu, nv, prim;
} face;

typedef struct {
    char name[MAX_NAME];
    int material[MAX_PRIMS];
    int nprims;
    face faces[MAX_FACES];
    int nfaces;
} mesh;

typedef struct {
    char name[MAX_NAME];
    float color[3];
} material;

typedef enum { LIGHT_POINT, LIGHT_SPOT, LIGHT_DIRECTIONAL } light_type;

typedef struct {
    char name[MAX_NAME];
    light_type type;
    float color[3], intensity, range, inner, outer;
} light;

typedef struct {
    char name[MAX_NAME];
    int mesh, light;  /* -1 when absent */
    float t[3], r[4]; /* translation; rotation quaternion x, y, z, w */
} node;

typedef struct {
    const char *name;
    material mats[MAX_MATERIALS];
    mesh meshes[MAX_MESHES];
    light lights[MAX_LIGHTS];
    node nodes[MAX_NODES];
    int nmats, nmeshes, nlights, nnodes;
    int full; /* a builder ran out of room: a bug in this file */
} scene;

static int add_material(scene *sc, const char *name, float r, float g, float b)
{
    if (sc->nmats == MAX_MATERIALS) {
        sc->full = 1;
        return 0;
    }
    material *m = &sc->mats[sc->nmats];
    snprintf(m->name, sizeof m->name, "%s", name);
    m->color[0] = r;
    m->color[1] = g;
    m->color[2] = b;
    return sc->nmats++;
}

static mesh *add_mesh(scene *sc, const char *name, int *index)
{
    static mesh spare; /* absorbs writes after an overflow */
    if (sc->nmeshes == MAX_MESHES) {
        sc->full = 1;
        return &spare;
    }
    mesh *m = &sc->meshes[sc->nmeshes];
    snprintf(m->name, sizeof m->name, "%s", name);
    *index = sc->nmeshes++;
    return m;
}

static int mesh_prim(scene *sc, mesh *m, int mat)
{
    if (m->nprims == MAX_PRIMS) {
        sc->full = 1;
        return 0;
    }
    m->material[m->nprims] = mat;
    return m->nprims++;
}

static void add_face(scene *sc, mesh *m, int prim, const float o[3], const float u[3],
                     const float v[3], int nu, int nv)
{
    if (m->nfaces == MAX_FACES) {
        sc->full = 1;
        return;
    }
    face *f = &m->faces[m->nfaces++];
    memcpy(f->o, o, sizeof f->o);
    memcpy(f->u, u, sizeof f->u);
    memcpy(f->v, v, sizeof f->v);
    f->nu = nu;
    f->nv = nv;
    f->prim = prim;
}

/* Axis-aligned box with outward normals: x, z centred on (cx, cz), y from cy
 * to cy + sy; mask picks the faces. */
static void add_box(scene *sc, mesh *m, int prim, float cx, float cy, float cz, float sx, float sy,
                    float sz, int mask)
{
    float x0 = cx - 0.5f * sx, x1 = cx + 0.5f * sx;
    float y0 = cy, y1 = cy + sy;
    float z0 = cz - 0.5f * sz, z1 = cz + 0.5f * sz;
    const float up[3] = {0.0f, sy, 0.0f};
    if (mask & BOX_PX)
        add_face(sc, m, prim, (float[3]){x1, y0, z1}, (float[3]){0.0f, 0.0f, -sz}, up, 1, 1);
    if (mask & BOX_NX)
        add_face(sc, m, prim, (float[3]){x0, y0, z0}, (float[3]){0.0f, 0.0f, sz}, up, 1, 1);
    if (mask & BOX_PZ)
        add_face(sc, m, prim, (float[3]){x0, y0, z1}, (float[3]){sx, 0.0f, 0.0f}, up, 1, 1);
    if (mask & BOX_NZ)
        add_face(sc, m, prim, (float[3]){x1, y0, z0}, (float[3]){-sx, 0.0f, 0.0f}, up, 1, 1);
    if (mask & BOX_PY)
        add_face(sc, m, prim, (float[3]){x0, y1, z1}, (float[3]){sx, 0.0f, 0.0f},
                 (float[3]){0.0f, 0.0f, -sz}, 1, 1);
    if (mask & BOX_NY)
        add_face(sc, m, prim, (float[3]){x0, y0, z0}, (float[3]){sx, 0.0f, 0.0f},
                 (float[3]){0.0f, 0.0f, sz}, 1, 1);
}

static node *add_node(scene *sc, const char *name, float x, float y, float z)
{
    static node spare;
    if (sc->nnodes == MAX_NODES) {
        sc->full = 1;
        return &spare;
    }
    node *n = &sc->nodes[sc->nnodes++];
    snprintf(n->name, sizeof n->name, "%s", name);
    n->mesh = -1;
    n->light = -1;
    n->t[0] = x;
    n->t[1] = y;
    n->t[2] = z;
    n->r[3] = 1.0f;
    return n;
}

static void node_yaw(node *n, double degrees)
{
    double half = 0.5 * degrees * PI / 180.0;
    n->r[0] = 0.0f;
    n->r[1] = (float)sin(half);
    n->r[2] = 0.0f;
    n->r[3] = (float)cos(half);
}

/* Rotation taking local -Z to direction d, keeping local +X horizontal so
 * the light has no roll. */
static void node_aim(node *n, double dx, double dy, double dz)
{
    double len = sqrt(dx * dx + dy * dy + dz * dz);
    double z[3] = {-dx / len, -dy / len, -dz / len};
    double up[3] = {0.0, 1.0, 0.0};
    if (fabs(z[1]) > 0.999) { /* straight up or down: any horizontal x will do */
        up[1] = 0.0;
        up[2] = 1.0;
    }
    double x[3] = {up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2],
                   up[0] * z[1] - up[1] * z[0]};
    double xl = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int i = 0; i < 3; i++)
        x[i] /= xl;
    double y[3] = {z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]};
    /* matrix with columns x, y, z -> quaternion (Shepperd's method) */
    double m00 = x[0], m11 = y[1], m22 = z[2];
    double qx, qy, qz, qw, tr = m00 + m11 + m22;
    if (tr > 0.0) {
        double s = 2.0 * sqrt(tr + 1.0);
        qw = 0.25 * s;
        qx = (y[2] - z[1]) / s;
        qy = (z[0] - x[2]) / s;
        qz = (x[1] - y[0]) / s;
    } else if (m00 > m11 && m00 > m22) {
        double s = 2.0 * sqrt(1.0 + m00 - m11 - m22);
        qw = (y[2] - z[1]) / s;
        qx = 0.25 * s;
        qy = (y[0] + x[1]) / s;
        qz = (z[0] + x[2]) / s;
    } else if (m11 > m22) {
        double s = 2.0 * sqrt(1.0 + m11 - m00 - m22);
        qw = (z[0] - x[2]) / s;
        qx = (y[0] + x[1]) / s;
        qy = 0.25 * s;
        qz = (z[1] + y[2]) / s;
    } else {
        double s = 2.0 * sqrt(1.0 + m22 - m00 - m11);
        qw = (x[1] - y[0]) / s;
        qx = (z[0] + x[2]) / s;
        qy = (z[1] + y[2]) / s;
        qz = 0.25 * s;
    }
    n->r[0] = (float)qx;
    n->r[1] = (float)qy;
    n->r[2] = (float)qz;
    n->r[3] = (float)qw;
}

static void node_mesh(scene *sc, const char *name, int mesh_index, float x, float y, float z,
                      double yaw_degrees)
{
    node *n = add_node(sc, name, x, y, z);
    n->mesh = mesh_index;
    node_yaw(n, yaw_degrees);
}

static node *node_light(scene *sc, const char *name, light_type type, float r, float g, float b,
                        float intensity, float range, float x, float y, float z)
{
    static light spare;
    light *l = &spare;
    if (sc->nlights == MAX_LIGHTS)
        sc->full = 1;
    else
        l = &sc->lights[sc->nlights];
    snprintf(l->name, sizeof l->name, "%s", name);
    l->type = type;
    l->color[0] = r;
    l->color[1] = g;
    l->color[2] = b;
    l->intensity = intensity;
    l->range = range;
    node *n = add_node(sc, name, x, y, z);
    n->light = l == &spare ? -1 : sc->nlights++;
    return n;
}

/* ---- the two scenes ------------------------------------------------------ */

static void build_room(scene *sc)
{
    sc->name = "room";
    int white = add_material(sc, "white", 0.8f, 0.8f, 0.8f);
    int red = add_material(sc, "red", 0.63f, 0.065f, 0.05f);
    int green = add_material(sc, "green", 0.14f, 0.45f, 0.09f);

    /* The room's faces look inward: u x v points into the room. */
    int room_index = 0;
    mesh *room = add_mesh(sc, "room", &room_index);
    int pw = mesh_prim(sc, room, white);
    int pr = mesh_prim(sc, room, red);
    int pg = mesh_prim(sc, room, green);
    add_face(sc, room, pw, (float[3]){-2.0f, 0.0f, 2.0f}, (float[3]){4.0f, 0.0f, 0.0f},
             (float[3]){0.0f, 0.0f, -4.0f}, 1, 1); /* floor */
    add_face(sc, room, pw, (float[3]){-2.0f, 3.0f, -2.0f}, (float[3]){4.0f, 0.0f, 0.0f},
             (float[3]){0.0f, 0.0f, 4.0f}, 1, 1); /* ceiling */
    add_face(sc, room, pw, (float[3]){-2.0f, 0.0f, -2.0f}, (float[3]){4.0f, 0.0f, 0.0f},
             (float[3]){0.0f, 3.0f, 0.0f}, 1, 1); /* back wall */
    add_face(sc, room, pr, (float[3]){-2.0f, 0.0f, 2.0f}, (float[3]){0.0f, 0.0f, -4.0f},
             (float[3]){0.0f, 3.0f, 0.0f}, 1, 1); /* left wall */
    add_face(sc, room, pg, (float[3]){2.0f, 0.0f, -2.0f}, (float[3]){0.0f, 0.0f, 4.0f},
             (float[3]){0.0f, 3.0f, 0.0f}, 1, 1); /* right wall */
    node_mesh(sc, "room", room_index, 0.0f, 0.0f, 0.0f, 0.0);

    int tall_index = 0, short_index = 0;
    mesh *tall = add_mesh(sc, "tall_box", &tall_index);
    add_box(sc, tall, mesh_prim(sc, tall, white), 0.0f, 0.0f, 0.0f, 1.2f, 1.8f, 1.2f, BOX_ALL);
    node_mesh(sc, "tall_box", tall_index, -0.7f, 0.0f, -0.6f, 18.0);

    mesh *shrt = add_mesh(sc, "short_box", &short_index);
    add_box(sc, shrt, mesh_prim(sc, shrt, white), 0.0f, 0.0f, 0.0f, 0.9f, 0.9f, 0.9f, BOX_ALL);
    node_mesh(sc, "short_box", short_index, 0.8f, 0.0f, 0.7f, -17.0);

    node_light(sc, "ceiling_lamp", LIGHT_POINT, 1.0f, 0.95f, 0.85f, 150.0f, 12.0f, 0.0f, 2.7f,
               0.0f);
    node *spot =
        node_light(sc, "spot", LIGHT_SPOT, 1.0f, 1.0f, 1.0f, 400.0f, 15.0f, 1.5f, 2.8f, 1.5f);
    if (spot->light >= 0) {
        sc->lights[spot->light].inner = 0.35f;
        sc->lights[spot->light].outer = 0.6f;
    }
    node_aim(spot, -0.7 - 1.5, 1.8 - 2.8, -0.6 - 1.5); /* at the tall box's top */
}

/* Steps climbing in +z, local z from -n*run to 0, top step at n*rise; no
 * back face (it leans on a wall) and no bottom. */
static void add_stair(scene *sc, mesh *m, int prim, int n, float width, float rise, float run)
{
    float hw = 0.5f * width;
    for (int i = 0; i < n; i++) {
        float z0 = -(float)(n - i) * run, z1 = z0 + run;
        float y0 = (float)i * rise, y1 = y0 + rise;
        add_face(sc, m, prim, (float[3]){hw, y0, z0}, (float[3]){-width, 0.0f, 0.0f},
                 (float[3]){0.0f, rise, 0.0f}, 1, 1); /* riser, faces -z */
        add_face(sc, m, prim, (float[3]){-hw, y1, z1}, (float[3]){width, 0.0f, 0.0f},
                 (float[3]){0.0f, 0.0f, -run}, 1, 1); /* tread, faces +y */
        add_face(sc, m, prim, (float[3]){hw, 0.0f, z1}, (float[3]){0.0f, 0.0f, -run},
                 (float[3]){0.0f, y1, 0.0f}, 1, 1); /* side column, faces +x */
        add_face(sc, m, prim, (float[3]){-hw, 0.0f, z0}, (float[3]){0.0f, 0.0f, run},
                 (float[3]){0.0f, y1, 0.0f}, 1, 1); /* side column, faces -x */
    }
}

static void build_retro(scene *sc)
{
    sc->name = "retro";
    int grey = add_material(sc, "ground", 0.6f, 0.6f, 0.6f);
    int stone = add_material(sc, "stone", 0.55f, 0.52f, 0.48f);
    int sand = add_material(sc, "sandstone", 0.7f, 0.6f, 0.45f);
    int mi = 0;

    mesh *ground = add_mesh(sc, "ground", &mi);
    add_face(sc, ground, mesh_prim(sc, ground, grey), (float[3]){-12.0f, 0.0f, 12.0f},
             (float[3]){24.0f, 0.0f, 0.0f}, (float[3]){0.0f, 0.0f, -24.0f}, 4, 4);
    node_mesh(sc, "ground", mi, 0.0f, 0.0f, 0.0f, 0.0);

    static const float pillar_xz[4][2] = {
        {-5.0f, -5.0f}, {5.0f, -5.0f}, {-5.0f, 5.0f}, {5.0f, 5.0f}};
    for (int i = 0; i < 4; i++) {
        char name[MAX_NAME];
        snprintf(name, sizeof name, "pillar_%d", i);
        mesh *p = add_mesh(sc, name, &mi);
        add_box(sc, p, mesh_prim(sc, p, stone), 0.0f, 0.0f, 0.0f, 1.0f, 4.0f, 1.0f, BOX_NO_BOTTOM);
        node_mesh(sc, name, mi, pillar_xz[i][0], 0.0f, pillar_xz[i][1], 0.0);
    }

    mesh *wall = add_mesh(sc, "wall", &mi);
    add_box(sc, wall, mesh_prim(sc, wall, sand), 0.0f, 0.0f, 0.0f, 8.0f, 1.5f, 0.5f, BOX_NO_BOTTOM);
    node_mesh(sc, "wall", mi, 0.0f, 0.0f, 0.0f, 0.0);

    /* 6 x 0.25 m reaches the wall's 1.5 m top; the stair's open back sits
     * against the wall's -z face at z = -0.25. */
    mesh *stair = add_mesh(sc, "stair", &mi);
    add_stair(sc, stair, mesh_prim(sc, stair, sand), 6, 1.2f, 0.25f, 0.35f);
    node_mesh(sc, "stair", mi, 2.0f, 0.0f, -0.25f, 0.0);

    /* Posts lose top and bottom: the lintel and the ground cover them. */
    mesh *gate = add_mesh(sc, "gate", &mi);
    int pgate = mesh_prim(sc, gate, stone);
    add_box(sc, gate, pgate, -1.8f, 0.0f, 0.0f, 0.6f, 3.0f, 0.6f, BOX_SIDES);
    add_box(sc, gate, pgate, 1.8f, 0.0f, 0.0f, 0.6f, 3.0f, 0.6f, BOX_SIDES);
    add_box(sc, gate, pgate, 0.0f, 3.0f, 0.0f, 4.2f, 0.6f, 0.6f, BOX_ALL);
    node_mesh(sc, "gate", mi, 0.0f, 0.0f, 8.0f, 0.0);

    /* Sun light travels down at 40 degrees, heading towards -z and a little
     * +x, so the wall throws its shadow over the stair side. */
    double elev = 40.0 * PI / 180.0, azim = 30.0 * PI / 180.0;
    node *sun = node_light(sc, "sun", LIGHT_DIRECTIONAL, 1.0f, 0.9f, 0.75f, 10000.0f, 0.0f, 0.0f,
                           20.0f, 0.0f);
    node_aim(sun, cos(elev) * sin(azim), -sin(elev), -cos(elev) * cos(azim));

    /* Torches 0.3 m off the inner faces of pillars 3 and 0. */
    node_light(sc, "torch_a", LIGHT_POINT, 1.0f, 0.6f, 0.25f, 60.0f, 8.0f, 4.2f, 2.5f, 5.0f);
    node_light(sc, "torch_b", LIGHT_POINT, 1.0f, 0.6f, 0.25f, 60.0f, 8.0f, -4.2f, 2.5f, -5.0f);
}

/* ---- lightmap chart packing ---------------------------------------------- */

typedef struct {
    double x, y, w, h; /* top-left corner and size in UV */
    int rot;           /* 1: the face's u edge runs along the chart's v */
} chart;

static double vlen(const float v[3])
{
    return sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
}

/* Shelf packing at `scale` UV units per metre; 0 if everything fits. */
static int shelf_pack(const mesh *m, const int *order, double scale, chart *charts)
{
    const double g = LM_GUTTER;
    double x = g, y = g, shelf_h = 0.0;
    for (int k = 0; k < m->nfaces; k++) {
        chart *c = &charts[order[k]];
        const face *f = &m->faces[order[k]];
        double fw = vlen(f->u), fh = vlen(f->v);
        c->rot = fh > fw; /* lay charts landscape: shelves waste less */
        c->w = (c->rot ? fh : fw) * scale;
        c->h = (c->rot ? fw : fh) * scale;
        if (x > g && x + c->w + g > 1.0) { /* start the next shelf */
            y += shelf_h + g;
            x = g;
            shelf_h = 0.0;
        }
        if (x + c->w + g > 1.0)
            return -1;
        c->x = x;
        c->y = y;
        x += c->w + g;
        if (c->h > shelf_h)
            shelf_h = c->h;
    }
    return y + shelf_h + g <= 1.0 ? 0 : -1;
}

/* Largest common scale (within 0.2%) at which the shelf packer fits every
 * face of the mesh, so texel density is uniform within the mesh. */
static int pack_charts(const mesh *m, chart *charts)
{
    const double g = LM_GUTTER;
    int order[MAX_FACES];
    double area = 0.0, longest = 0.0;
    for (int i = 0; i < m->nfaces; i++) {
        double fw = vlen(m->faces[i].u), fh = vlen(m->faces[i].v);
        area += fw * fh;
        longest = fmax(longest, fmax(fw, fh));
        order[i] = i;
    }
    if (m->nfaces == 0 || area <= 0.0)
        return -1;
    /* tallest chart first (insertion sort: stable, so the output is fixed) */
    for (int i = 1; i < m->nfaces; i++) {
        int k = order[i], j = i;
        double hk = fmin(vlen(m->faces[k].u), vlen(m->faces[k].v));
        while (j > 0) {
            const face *p = &m->faces[order[j - 1]];
            if (fmin(vlen(p->u), vlen(p->v)) >= hk)
                break;
            order[j] = order[j - 1];
            j--;
        }
        order[j] = k;
    }
    /* upper bounds: the longest side fits, and the total area fits */
    double s = fmin((1.0 - 2.0 * g) / longest, (1.0 - 2.0 * g) / sqrt(area));
    for (int it = 0; it < 10000; it++, s *= 0.998)
        if (shelf_pack(m, order, s, charts) == 0)
            return 0;
    return -1;
}

/* ---- glTF/GLB writer ------------------------------------------------------ */

typedef struct {
    size_t offset, length;
    int target;
} view;

typedef struct {
    int view, component;
    size_t count;
    const char *type;
    int has_bounds;
    float min[3], max[3];
} accessor;

typedef struct {
    bytes bin;
    view views[MAX_ACCESSORS];
    accessor accs[MAX_ACCESSORS];
    int naccs;
} glb_data;

enum { GL_ARRAY_BUFFER = 34962, GL_ELEMENT_ARRAY_BUFFER = 34963 };
enum { GL_UNSIGNED_SHORT = 5123, GL_UNSIGNED_INT = 5125, GL_FLOAT = 5126 };

/* One bufferView per accessor, each starting 4-aligned. */
static int add_floats(glb_data *d, const float *v, size_t count, int ncomp, const char *type,
                      int bounds)
{
    if (d->naccs == MAX_ACCESSORS)
        return -1;
    int i = d->naccs++;
    accessor *a = &d->accs[i];
    bytes_pad(&d->bin, 0);
    d->views[i] = (view){d->bin.len, count * (size_t)ncomp * 4, GL_ARRAY_BUFFER};
    for (size_t k = 0; k < count * (size_t)ncomp; k++)
        put_f32(&d->bin, v[k]);
    *a = (accessor){.view = i, .component = GL_FLOAT, .count = count, .type = type};
    if (bounds) {
        a->has_bounds = 1;
        for (size_t c = 0; c < (size_t)ncomp; c++) {
            a->min[c] = a->max[c] = v[c];
            for (size_t k = 1; k < count; k++) {
                a->min[c] = fminf(a->min[c], v[k * (size_t)ncomp + c]);
                a->max[c] = fmaxf(a->max[c], v[k * (size_t)ncomp + c]);
            }
        }
    }
    return i;
}

static int add_indices(glb_data *d, const uint32_t *idx, size_t count, size_t nverts)
{
    if (d->naccs == MAX_ACCESSORS)
        return -1;
    int i = d->naccs++;
    int wide = nverts > 65535;
    bytes_pad(&d->bin, 0);
    d->views[i] = (view){d->bin.len, count * (wide ? 4 : 2), GL_ELEMENT_ARRAY_BUFFER};
    for (size_t k = 0; k < count; k++) {
        if (wide)
            put_u32(&d->bin, idx[k]);
        else
            put_u16(&d->bin, (uint16_t)idx[k]);
    }
    d->accs[i] = (accessor){.view = i,
                            .component = wide ? GL_UNSIGNED_INT : GL_UNSIGNED_SHORT,
                            .count = count,
                            .type = "SCALAR"};
    return i;
}

/* Vertex arrays of one primitive: 4 vertices and 6 indices per quad. */
static int emit_primitive(glb_data *d, const mesh *m, const chart *charts, int prim, int acc[5])
{
    size_t nquads = 0;
    for (int i = 0; i < m->nfaces; i++)
        if (m->faces[i].prim == prim)
            nquads += (size_t)m->faces[i].nu * (size_t)m->faces[i].nv;
    size_t nv = nquads * 4, ni = nquads * 6;
    float *pos = malloc(nv * 3 * sizeof *pos), *nrm = malloc(nv * 3 * sizeof *nrm);
    float *uv0 = malloc(nv * 2 * sizeof *uv0), *uv1 = malloc(nv * 2 * sizeof *uv1);
    uint32_t *idx = malloc(ni * sizeof *idx);
    int rc = -1;
    if (!pos || !nrm || !uv0 || !uv1 || !idx || nquads == 0)
        goto done;

    size_t v = 0, n = 0;
    for (int fi = 0; fi < m->nfaces; fi++) {
        const face *f = &m->faces[fi];
        const chart *c = &charts[fi];
        if (f->prim != prim)
            continue;
        double nx = (double)f->u[1] * f->v[2] - (double)f->u[2] * f->v[1];
        double ny = (double)f->u[2] * f->v[0] - (double)f->u[0] * f->v[2];
        double nz = (double)f->u[0] * f->v[1] - (double)f->u[1] * f->v[0];
        double nl = sqrt(nx * nx + ny * ny + nz * nz);
        for (int j = 0; j < f->nv; j++) {
            for (int i = 0; i < f->nu; i++) {
                static const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
                for (int k = 0; k < 4; k++) {
                    double a = (double)(i + corner[k][0]) / f->nu;
                    double b = (double)(j + corner[k][1]) / f->nv;
                    for (size_t e = 0; e < 3; e++)
                        pos[v * 3 + e] = (float)(f->o[e] + a * f->u[e] + b * f->v[e]);
                    nrm[v * 3 + 0] = (float)(nx / nl);
                    nrm[v * 3 + 1] = (float)(ny / nl);
                    nrm[v * 3 + 2] = (float)(nz / nl);
                    /* v runs down the image, so the face's "up" edge is v = 0 */
                    uv0[v * 2 + 0] = (float)corner[k][0];
                    uv0[v * 2 + 1] = (float)(1 - corner[k][1]);
                    if (c->rot) { /* a quarter turn keeps the chart unmirrored */
                        uv1[v * 2 + 0] = (float)(c->x + (1.0 - b) * c->w);
                        uv1[v * 2 + 1] = (float)(c->y + (1.0 - a) * c->h);
                    } else {
                        uv1[v * 2 + 0] = (float)(c->x + a * c->w);
                        uv1[v * 2 + 1] = (float)(c->y + (1.0 - b) * c->h);
                    }
                    v++;
                }
                uint32_t base = (uint32_t)(v - 4);
                const uint32_t tri[6] = {base, base + 1, base + 2, base, base + 2, base + 3};
                memcpy(&idx[n], tri, sizeof tri);
                n += 6;
            }
        }
    }
    acc[0] = add_floats(d, pos, nv, 3, "VEC3", 1);
    acc[1] = add_floats(d, nrm, nv, 3, "VEC3", 0);
    acc[2] = add_floats(d, uv0, nv, 2, "VEC2", 0);
    acc[3] = add_floats(d, uv1, nv, 2, "VEC2", 0);
    acc[4] = add_indices(d, idx, ni, nv);
    rc = (acc[0] < 0 || acc[1] < 0 || acc[2] < 0 || acc[3] < 0 || acc[4] < 0) ? -1 : 0;
done:
    free(pos);
    free(nrm);
    free(uv0);
    free(uv1);
    free(idx);
    return rc;
}

static void emit_json(bytes *js, const scene *sc, const glb_data *d,
                      int acc[MAX_MESHES][MAX_PRIMS][5])
{
    bytes_printf(js, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"luxel "
                     "examples/gen_scenes\"},\n");
    if (sc->nlights > 0) {
        bytes_printf(js, "\"extensionsUsed\":[\"KHR_lights_punctual\"],\n");
        bytes_printf(js, "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":[\n");
        for (int i = 0; i < sc->nlights; i++) {
            const light *l = &sc->lights[i];
            static const char *types[] = {"point", "spot", "directional"};
            bytes_printf(js, "%s {\"name\":\"%s\",\"type\":\"%s\",\"color\":", i ? ",\n" : "",
                         l->name, types[l->type]);
            json_floats(js, l->color, 3);
            bytes_printf(js, ",\"intensity\":");
            json_float(js, l->intensity);
            if (l->type != LIGHT_DIRECTIONAL) {
                bytes_printf(js, ",\"range\":");
                json_float(js, l->range);
            }
            if (l->type == LIGHT_SPOT) {
                bytes_printf(js, ",\"spot\":{\"innerConeAngle\":");
                json_float(js, l->inner);
                bytes_printf(js, ",\"outerConeAngle\":");
                json_float(js, l->outer);
                bytes_printf(js, "}");
            }
            bytes_printf(js, "}");
        }
        bytes_printf(js, "]}},\n");
    }

    bytes_printf(js, "\"scene\":0,\"scenes\":[{\"name\":\"%s\",\"nodes\":[", sc->name);
    for (int i = 0; i < sc->nnodes; i++)
        bytes_printf(js, "%s%d", i ? "," : "", i);
    bytes_printf(js, "]}],\n\"nodes\":[\n");
    for (int i = 0; i < sc->nnodes; i++) {
        const node *n = &sc->nodes[i];
        bytes_printf(js, "%s {\"name\":\"%s\"", i ? ",\n" : "", n->name);
        if (n->mesh >= 0)
            bytes_printf(js, ",\"mesh\":%d", n->mesh);
        if (n->t[0] != 0.0f || n->t[1] != 0.0f || n->t[2] != 0.0f) {
            bytes_printf(js, ",\"translation\":");
            json_floats(js, n->t, 3);
        }
        if (n->r[0] != 0.0f || n->r[1] != 0.0f || n->r[2] != 0.0f || n->r[3] != 1.0f) {
            bytes_printf(js, ",\"rotation\":");
            json_floats(js, n->r, 4);
        }
        if (n->light >= 0)
            bytes_printf(js, ",\"extensions\":{\"KHR_lights_punctual\":{\"light\":%d}}", n->light);
        bytes_printf(js, "}");
    }

    bytes_printf(js, "],\n\"meshes\":[\n");
    for (int i = 0; i < sc->nmeshes; i++) {
        const mesh *m = &sc->meshes[i];
        bytes_printf(js, "%s {\"name\":\"%s\",\"primitives\":[", i ? ",\n" : "", m->name);
        for (int p = 0; p < m->nprims; p++) {
            const int *a = acc[i][p];
            bytes_printf(js,
                         "%s{\"attributes\":{\"POSITION\":%d,\"NORMAL\":%d,"
                         "\"TEXCOORD_0\":%d,\"TEXCOORD_1\":%d},\"indices\":%d,"
                         "\"material\":%d,\"mode\":4}",
                         p ? "," : "", a[0], a[1], a[2], a[3], a[4], m->material[p]);
        }
        bytes_printf(js, "]}");
    }

    bytes_printf(js, "],\n\"materials\":[\n");
    for (int i = 0; i < sc->nmats; i++) {
        const material *m = &sc->mats[i];
        float rgba[4] = {m->color[0], m->color[1], m->color[2], 1.0f};
        bytes_printf(js, "%s {\"name\":\"%s\",\"pbrMetallicRoughness\":{\"baseColorFactor\":",
                     i ? ",\n" : "", m->name);
        json_floats(js, rgba, 4);
        bytes_printf(js, ",\"metallicFactor\":0,\"roughnessFactor\":1}}");
    }

    bytes_printf(js, "],\n\"accessors\":[\n");
    for (int i = 0; i < d->naccs; i++) {
        const accessor *a = &d->accs[i];
        bytes_printf(js,
                     "%s {\"bufferView\":%d,\"componentType\":%d,\"count\":%zu,"
                     "\"type\":\"%s\"",
                     i ? ",\n" : "", a->view, a->component, a->count, a->type);
        if (a->has_bounds) {
            bytes_printf(js, ",\"min\":");
            json_floats(js, a->min, 3);
            bytes_printf(js, ",\"max\":");
            json_floats(js, a->max, 3);
        }
        bytes_printf(js, "}");
    }

    bytes_printf(js, "],\n\"bufferViews\":[\n");
    for (int i = 0; i < d->naccs; i++)
        bytes_printf(js,
                     "%s {\"buffer\":0,\"byteOffset\":%zu,\"byteLength\":%zu,"
                     "\"target\":%d}",
                     i ? ",\n" : "", d->views[i].offset, d->views[i].length, d->views[i].target);
    bytes_printf(js, "],\n\"buffers\":[{\"byteLength\":%zu}]}\n", d->bin.len);
}

/* Whole .glb file of a scene into out. */
static int make_glb(const scene *sc, const char *file, bytes *out)
{
    static glb_data d; /* large; static keeps it off the stack */
    int acc[MAX_MESHES][MAX_PRIMS][5];
    bytes js = {0};
    int rc = -1;
    memset(&d, 0, sizeof d);

    if (sc->full) {
        error("%s: internal: scene exceeds the generator's fixed capacity", file);
        return -1;
    }
    for (int i = 0; i < sc->nmeshes; i++) {
        const mesh *m = &sc->meshes[i];
        chart charts[MAX_FACES];
        if (pack_charts(m, charts) != 0) {
            error("%s: mesh '%s': cannot pack %d lightmap charts", file, m->name, m->nfaces);
            goto done;
        }
        for (int p = 0; p < m->nprims; p++) {
            if (emit_primitive(&d, m, charts, p, acc[i][p]) != 0) {
                error("%s: mesh '%s': out of memory or empty primitive %d", file, m->name, p);
                goto done;
            }
        }
    }
    bytes_pad(&d.bin, 0);
    emit_json(&js, sc, &d, acc);
    bytes_pad(&js, ' ');
    if (d.bin.failed || js.failed) {
        error("%s: out of memory", file);
        goto done;
    }
    size_t total = 12 + 8 + js.len + 8 + d.bin.len;
    if (total > UINT32_MAX) {
        error("%s: %zu bytes exceeds the GLB size limit", file, total);
        goto done;
    }
    put_u32(out, 0x46546C67u); /* "glTF" */
    put_u32(out, 2);
    put_u32(out, (uint32_t)total);
    put_u32(out, (uint32_t)js.len);
    put_u32(out, 0x4E4F534Au); /* "JSON" */
    bytes_append(out, js.data, js.len);
    put_u32(out, (uint32_t)d.bin.len);
    put_u32(out, 0x004E4942u); /* "BIN\0" */
    bytes_append(out, d.bin.data, d.bin.len);
    if (out->failed) {
        error("%s: out of memory", file);
        goto done;
    }
    rc = 0;
done:
    free(js.data);
    free(d.bin.data);
    return rc;
}

/* ---- output ---------------------------------------------------------------- */

/* Write to OUTDIR/.NAME.XXXXXX, then rename over OUTDIR/NAME. */
static int write_atomic(const char *dir, const char *name, const bytes *b)
{
    char path[4096];
    int n1 = snprintf(path, sizeof path, "%s/%s", dir, name);
    int n2 = snprintf(g_tmp_path, sizeof g_tmp_path, "%s/.%s.XXXXXX", dir, name);
    if (n1 < 0 || n2 < 0 || (size_t)n1 >= sizeof path || (size_t)n2 >= sizeof g_tmp_path) {
        error("%s: output path too long", dir);
        return -1;
    }
    g_tmp_active = 0;
    int fd = mkstemp(g_tmp_path);
    if (fd < 0) {
        error("%s: cannot create a temporary file: %s", dir, strerror(errno));
        return -1;
    }
    g_tmp_active = 1;
    /* mkstemp makes the file 0600; give it the usual umask-based mode */
    mode_t um = umask(0);
    umask(um);
    FILE *f = fdopen(fd, "wb");
    int ok = f != NULL && fchmod(fd, 0666 & ~um) == 0;
    ok = ok && fwrite(b->data, 1, b->len, f) == b->len;
    ok = ok && fflush(f) == 0 && fsync(fd) == 0;
    int saved = errno;
    if (f ? fclose(f) != 0 : close(fd) != 0) {
        if (ok)
            saved = errno;
        ok = 0;
    }
    if (!ok) {
        error("%s: write failed: %s", path, strerror(saved));
    } else if (rename(g_tmp_path, path) != 0) {
        error("%s: cannot rename temporary file into place: %s", path, strerror(errno));
        ok = 0;
    }
    if (!ok)
        unlink(g_tmp_path);
    g_tmp_active = 0;
    return ok ? 0 : -1;
}

/* mkdir -p: `make demo` and the CLI tests name folders that may not exist. */
static int make_dirs(const char *dir)
{
    char path[4096];
    size_t n = strlen(dir);
    if (n >= sizeof path) {
        error("%s: path too long", dir);
        return -1;
    }
    memcpy(path, dir, n + 1);
    for (size_t i = 1; i <= n; i++) {
        if (path[i] != '/' && path[i] != '\0')
            continue;
        char saved = path[i];
        path[i] = '\0';
        struct stat st;
        if (stat(path, &st) != 0) {
            if (errno != ENOENT || (mkdir(path, 0777) != 0 && errno != EEXIST)) {
                error("%s: cannot create directory: %s", path, strerror(errno));
                return -1;
            }
        } else if (!S_ISDIR(st.st_mode)) {
            error("%s: not a directory", path);
            return -1;
        }
        path[i] = saved;
    }
    return 0;
}

static void usage(FILE *f)
{
    fprintf(f, "usage: gen_scenes OUTDIR\n"
               "Writes OUTDIR/room.glb and OUTDIR/retro.glb (binary glTF 2.0 example\n"
               "scenes with lightmap UVs in TEXCOORD_1 and KHR_lights_punctual lights),\n"
               "creating OUTDIR if needed.\n");
}

int main(int argc, char **argv)
{
    if (argc == 2 && (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help"))) {
        usage(stdout);
        return 0;
    }
    if (argc != 2 || argv[1][0] == '\0' || argv[1][0] == '-') {
        usage(stderr);
        return 2;
    }
    const char *dir = argv[1];
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);

    /* Build both files in memory first, so a failure writes neither. */
    static scene room, retro;
    build_room(&room);
    build_retro(&retro);
    bytes room_glb = {0}, retro_glb = {0}, sky = {0};
    make_sky(&sky);
    int rc = 1;
    if (make_glb(&room, "room.glb", &room_glb) == 0 &&
        make_glb(&retro, "retro.glb", &retro_glb) == 0 && make_dirs(dir) == 0 &&
        write_atomic(dir, "room.glb", &room_glb) == 0 &&
        write_atomic(dir, "retro.glb", &retro_glb) == 0 && write_atomic(dir, "sky.pfm", &sky) == 0)
        rc = 0;
    free(room_glb.data);
    free(retro_glb.data);
    free(sky.data);
    return rc;
}
