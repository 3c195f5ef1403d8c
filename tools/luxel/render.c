/* luxel render: a camera view of a scene with its baked lightmaps applied,
 * written as a tone-mapped 8-bit PNG (or a float image of the radiance).
 * Nothing is written unless the whole view was rendered. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *render_usage =
    "usage: luxel render SCENE --lightmaps DIR [options]\n"
    "\n"
    "Renders SCENE from a camera with the lightmaps `luxel bake` wrote to DIR\n"
    "applied (DIR/manifest.json says where each node's lightmap is): every\n"
    "pixel is base colour x irradiance / pi plus what the material emits\n"
    "(nits, times the bake's --emissive-scale), exposed, tone mapped and written\n"
    "as an sRGB PNG. When the bake made lightmap UVs, the scene it wrote with\n"
    "them (the manifest's scene_with_uvs) is rendered instead of SCENE.\n"
    "\n"
    "options:\n"
    "  --lightmaps DIR         the bake's output folder (required)\n"
    "  -o, --output FILE       the image (default view.png); .exr, .hdr or .pfm\n"
    "                          keep the linear radiance in nits\n"
    "  --camera E,T[,U]        eye and target points (and an up vector), 6 or 9\n"
    "                          comma-separated numbers in metres\n"
    "  --gltf-camera N|NAME    a camera of the glTF file (perspective or\n"
    "                          orthographic), by its number in 'luxel info' or\n"
    "                          its name (default: the first, when it has one)\n"
    "  --view V                iso, front, back, left, right or top: framed on\n"
    "                          the scene's bounds (default without cameras: iso,\n"
    "                          or a view from inside when iso sees back faces)\n"
    "  --fov DEG               vertical field of view (default %g, or the glTF\n"
    "                          camera's yfov)\n"
    "  --size WxH              image size in pixels (default %dx%d)\n"
    "  --exposure EV100        exposure (default: metered on the view, the\n"
    "                          log-average luminance of what the camera sees\n"
    "                          made 0.18, Reinhard's key; 'bake' takes the\n"
    "                          bake's preview_ev100)\n"
    "  --tonemap T             filmic (default), aces or clamp\n"
    "  --filter F              lightmap lookups: bilinear (default) or bicubic\n"
    "  --samples N             rays per pixel, stratified (default %d)\n"
    "  --two-sided             draw back faces (default: culled, as glTF's\n"
    "                          single-sided materials; double-sided ones are\n"
    "                          drawn either way)\n"
    "  --threads N             worker threads (default: all cores)\n"
    "  -v, --verbose           the time of each phase\n"
    "  -q, --quiet             no progress bar or summary\n"
    "  --allow-any-path        read files the inputs name outside their folders\n"
    "  -h, --help              show this help\n";

/* The CLI's tone curve: the bake previews' (Hable's filmic), so a view and
 * its lightmaps' previews look alike; highlights roll off, not clip. */
#define CLI_RENDER_TONEMAP LX_TONEMAP_FILMIC
/* Face size the manifest's sky is loaded at for the background. */
#define CLI_RENDER_SKY_SIZE 512

enum {
    OPT_LIGHTMAPS = 256,
    OPT_CAMERA,
    OPT_VIEW,
    OPT_FOV,
    OPT_SIZE,
    OPT_EXPOSURE,
    OPT_TONEMAP,
    OPT_FILTER,
    OPT_SAMPLES,
    OPT_TWO_SIDED,
    OPT_GLTF_CAMERA
};

typedef struct render_args {
    const char *scene;
    const char *lightmaps;
    const char *output;
    bool has_camera, has_view, has_fov, has_exposure, bake_exposure, quiet;
    const char *gltf_camera; /* --gltf-camera, or NULL */
    bool no_summary; /* bake --render: the bake prints its own */
    const char *shown; /* the output as messages name it, when not `output`
                          (bake --render writes into its staging folder) */
    lx_view view;
    double fov_degrees;
    double exposure_ev100;
    lx_tonemap tonemap;
    lx_render_desc desc;
} render_args;

/* "x,y,z,x,y,z[,x,y,z]": 6 or 9 finite numbers. */
static bool parse_camera(const char *s, lx_camera *cam)
{
    double v[9];
    int n = 0;
    const char *p = s;
    while (n < 9) {
        char *end;
        errno = 0;
        v[n] = strtod(p, &end);
        if (errno || end == p || !isfinite(v[n]))
            return false;
        n++;
        p = end;
        if (*p == '\0')
            break;
        if (*p != ',')
            return false;
        p++;
    }
    if (*p || (n != 6 && n != 9))
        return false;
    cam->eye = lx_v3((float)v[0], (float)v[1], (float)v[2]);
    cam->target = lx_v3((float)v[3], (float)v[4], (float)v[5]);
    cam->up = n == 9 ? lx_v3((float)v[6], (float)v[7], (float)v[8]) : lx_v3(0, 0, 0);
    return true;
}

static bool parse_size(const char *s, int *w, int *h)
{
    char *x = strchr(s, 'x');
    if (!x || x == s || strchr(x + 1, 'x'))
        return false;
    char buf[32];
    size_t n = (size_t)(x - s);
    if (n >= sizeof buf)
        return false;
    memcpy(buf, s, n);
    buf[n] = '\0';
    long a, b;
    if (!cli_parse_int(buf, 1, 16384, &a) || !cli_parse_int(x + 1, 1, 16384, &b))
        return false;
    *w = (int)a;
    *h = (int)b;
    return true;
}

static int parse_args(int argc, char **argv, render_args *a)
{
    static const struct option options[] = {
        {"lightmaps", required_argument, NULL, OPT_LIGHTMAPS},
        {"output", required_argument, NULL, 'o'},
        {"camera", required_argument, NULL, OPT_CAMERA},
        {"view", required_argument, NULL, OPT_VIEW},
        {"gltf-camera", required_argument, NULL, OPT_GLTF_CAMERA},
        {"fov", required_argument, NULL, OPT_FOV},
        {"size", required_argument, NULL, OPT_SIZE},
        {"exposure", required_argument, NULL, OPT_EXPOSURE},
        {"tonemap", required_argument, NULL, OPT_TONEMAP},
        {"filter", required_argument, NULL, OPT_FILTER},
        {"samples", required_argument, NULL, OPT_SAMPLES},
        {"two-sided", no_argument, NULL, OPT_TWO_SIDED},
        {"threads", required_argument, NULL, CLI_OPT_THREADS},
        {"quiet", no_argument, NULL, 'q'},
        {"verbose", no_argument, NULL, 'v'},
        CLI_ANY_PATH_OPTION,
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->desc = lx_render_desc_defaults(NULL);
    a->output = "view.png";
    a->fov_degrees = LX_RENDER_DEFAULT_FOV_DEGREES;
    a->tonemap = CLI_RENDER_TONEMAP;
    opterr = 0;
    optind = 1;
    int c;
    long n;
    double f;
    while ((c = getopt_long(argc, argv, ":o:qvh", options, NULL)) != -1) {
        switch (c) {
        case OPT_LIGHTMAPS:
            if (!*optarg)
                return cli_usage_error("render", "--lightmaps needs a folder name");
            a->lightmaps = optarg;
            break;
        case 'o':
            if (!*optarg)
                return cli_usage_error("render", "-o needs a file name");
            a->output = optarg;
            break;
        case OPT_CAMERA:
            if (!parse_camera(optarg, &a->desc.camera))
                return cli_usage_error("render",
                                       "--camera must be EYE,TARGET or EYE,TARGET,UP: 6 or 9 "
                                       "comma-separated finite numbers, not '%s'",
                                       optarg);
            a->has_camera = true;
            break;
        case OPT_VIEW:
            if (!lx_view_parse(optarg, &a->view))
                return cli_usage_error("render",
                                       "--view must be iso, front, back, left, right or top, not "
                                       "'%s'",
                                       optarg);
            a->has_view = true;
            break;
        case OPT_GLTF_CAMERA:
            if (!*optarg)
                return cli_usage_error("render", "--gltf-camera needs a camera number or name");
            a->gltf_camera = optarg;
            break;
        case OPT_FOV:
            if (!cli_parse_float(optarg, 0.01, 179.0, &f))
                return cli_usage_error("render", "--fov must be degrees in 0.01..179, not '%s'",
                                       optarg);
            a->fov_degrees = f;
            a->has_fov = true;
            break;
        case OPT_SIZE:
            if (!parse_size(optarg, &a->desc.width, &a->desc.height))
                return cli_usage_error(
                    "render", "--size must be WxH with each side in 1..16384, not '%s'", optarg);
            break;
        case OPT_EXPOSURE:
            if (strcmp(optarg, "bake") == 0) {
                a->bake_exposure = true;
                a->has_exposure = false;
                break;
            }
            a->bake_exposure = false;
            if (!cli_parse_float(optarg, -64, 64, &f))
                return cli_usage_error("render",
                                       "--exposure must be an EV100 in -64..64 or 'bake', not "
                                       "'%s'",
                                       optarg);
            a->exposure_ev100 = f;
            a->has_exposure = true;
            break;
        case OPT_TONEMAP:
            if (!lx_tonemap_parse(optarg, &a->tonemap))
                return cli_usage_error("render",
                                       "--tonemap must be aces, filmic or clamp, not '%s'", optarg);
            break;
        case OPT_FILTER:
            if (strcmp(optarg, "bilinear") == 0)
                a->desc.filter = LX_LIGHTMAP_BILINEAR;
            else if (strcmp(optarg, "bicubic") == 0)
                a->desc.filter = LX_LIGHTMAP_BICUBIC;
            else
                return cli_usage_error("render", "--filter must be bilinear or bicubic, not '%s'",
                                       optarg);
            break;
        case OPT_SAMPLES:
            if (!cli_parse_int(optarg, 1, 4096, &n))
                return cli_usage_error("render",
                                       "--samples must be an integer in 1..4096, not '%s'", optarg);
            a->desc.samples = (int)n;
            break;
        case OPT_TWO_SIDED:
            a->desc.two_sided = true;
            break;
        case 'h': {
            lx_render_desc d = lx_render_desc_defaults(NULL);
            printf(render_usage, (double)LX_RENDER_DEFAULT_FOV_DEGREES, d.width, d.height,
                   d.samples);
            return -1;
        }
        default: {
            int rc = cli_common_option("render", c, argv, &a->desc.threads, &a->quiet);
            if (rc != 0)
                return rc;
        }
        }
    }
    int one = cli_one_scene("render", argc, argv, &a->scene);
    if (one != 0)
        return one;
    if (!a->lightmaps)
        return cli_usage_error("render", "--lightmaps DIR is required (the bake's output folder)");
    if (a->has_camera + a->has_view + (a->gltf_camera != NULL) > 1)
        return cli_usage_error("render", "%s place the camera: give one",
                               a->gltf_camera ? (a->has_camera ? "--camera and --gltf-camera both"
                                                               : "--view and --gltf-camera both")
                                              : "--camera and --view both");
    a->desc.camera.fov = LX_DEG2RAD((float)a->fov_degrees);
    if (a->has_camera && lx_camera_check(&a->desc.camera) != LX_OK)
        return cli_usage_error("render", "--camera: %s", lx_last_error());
    if (lx_image_format_from_path(a->output) == LX_IMAGE_AUTO)
        return cli_usage_error("render",
                               "%s: the output must end in .png, .jpg, .tga, .exr, .hdr "
                               "or .pfm",
                               a->output);
    return 0;
}

/* ---- making the bake's UVs again ------------------------------------------ */

static bool file_exists(const char *path)
{
    return access(path, R_OK) == 0;
}

/* When the bake made UVs and the scene it wrote with them is missing: the
 * same unwrap again (the manifest's density, padding and atlas size), with
 * a check that it gives the pages the manifest lists. */
static int unwrap_again(const lx_lightmaps *lm, lx_scene *scene, const char *scene_path,
                        int threads, bool quiet)
{
    const char *why = lm->scene_with_uvs ? "is missing" : "is not named in the manifest";
    if (!(lm->texel_density > 0.0f)) {
        cli_error("%s/manifest.json: luxel made lightmap UVs for this bake, the scene with them "
                  "%s and the manifest has no texel_density to make them again: bake again",
                  lm->dir, why);
        return EXIT_FAILED;
    }
    uint32_t nn = scene->node_count;
    lx_unwrap_mode *modes = calloc(nn ? nn : 1, sizeof *modes);
    int *sets = calloc(nn ? nn : 1, sizeof *sets);
    uint32_t *page_of = calloc(nn ? nn : 1, sizeof *page_of);
    if (!modes || !sets || !page_of) {
        free(modes);
        free(sets);
        free(page_of);
        cli_error("out of memory");
        return EXIT_FAILED;
    }
    for (uint32_t n = 0; n < nn; n++) {
        modes[n] = LX_UNWRAP_SKIP;
        page_of[n] = UINT32_MAX;
        for (uint32_t k = 0; k < lm->node_count; k++)
            if (scene->nodes[n].name && strcmp(scene->nodes[n].name, lm->nodes[k].name) == 0) {
                modes[n] = lm->nodes[k].generated ? LX_UNWRAP_GENERATE : LX_UNWRAP_KEEP;
                sets[n] = lm->nodes[k].uv_set;
                page_of[n] = lm->nodes[k].page;
                break;
            }
    }
    /* the bake names shared atlas pages lightmap-<k> and a node's own page
     * after the node */
    bool atlas = false;
    for (uint32_t p = 0; p < lm->page_count; p++) {
        const char *base = strrchr(lm->pages[p].file, '/');
        base = base ? base + 1 : lm->pages[p].file;
        atlas |= strncmp(base, "lightmap-", 9) == 0;
    }
    lx_unwrap_desc ud = lx_unwrap_desc_defaults(NULL);
    ud.texel_density = lm->texel_density;
    ud.padding = lm->padding >= 0 ? lm->padding : LX_UNWRAP_PADDING_RECOMMENDED;
    if (lm->atlas_size)
        ud.atlas_size = lm->atlas_size;
    ud.modes = modes;
    ud.keep_uv_sets = sets;
    ud.page_per_node = !atlas;
    ud.threads = threads;
    cli_progress progress;
    cli_progress_init(&progress, "unwrap", quiet);
    ud.progress = cli_progress_update;
    ud.progress_user = &progress;
    lx_unwrap *u = NULL;
    lx_status st = lx_unwrap_scene(scene, &ud, &u);
    cli_progress_finish(&progress);
    int status = EXIT_OK;
    if (st != LX_OK) {
        if (st == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s: %s", scene_path, lx_last_error());
        status = EXIT_FAILED;
    } else {
        char diff[200] = "";
        if (u->page_count != lm->page_count)
            snprintf(diff, sizeof diff, "%u pages, the manifest lists %u", u->page_count,
                     lm->page_count);
        for (uint32_t p = 0; !diff[0] && p < u->page_count; p++)
            if (u->pages[p].width != lm->pages[p].width ||
                u->pages[p].height != lm->pages[p].height)
                snprintf(diff, sizeof diff, "page %u is %dx%d, the manifest says %dx%d", p,
                         u->pages[p].width, u->pages[p].height, lm->pages[p].width,
                         lm->pages[p].height);
        for (uint32_t n = 0; !diff[0] && n < nn; n++)
            if (page_of[n] != UINT32_MAX && u->nodes[n].page != page_of[n])
                snprintf(diff, sizeof diff, "node '%s' lands on page %u, the manifest says %u",
                         scene->nodes[n].name, u->nodes[n].page, page_of[n]);
        if (diff[0]) {
            cli_error("%s/manifest.json: luxel made lightmap UVs for this bake and the scene with "
                      "them %s; making them again from %s gives other pages (%s): bake again",
                      lm->dir, why, scene_path, diff);
            status = EXIT_FAILED;
        } else if (lx_unwrap_apply(scene, u) != LX_OK) {
            cli_error("%s: %s", scene_path, lx_last_error());
            status = EXIT_FAILED;
        }
    }
    lx_unwrap_destroy(u);
    free(modes);
    free(sets);
    free(page_of);
    return status;
}

/* ---- rendering ------------------------------------------------------------- */

static bool any_generated(const lx_lightmaps *lm)
{
    for (uint32_t n = 0; n < lm->node_count; n++)
        if (lm->nodes[n].generated)
            return true;
    return false;
}

/* Reinhard's key: the log-average luminance of what the view sees is
 * exposed to this. */
#define CLI_RENDER_KEY 0.18

/* The EV100 that exposes the log-average luminance of the pixels wholly
 * on the scene to CLI_RENDER_KEY; *seen counts the pixels with any of the
 * scene, *lit those with light. False when none is lit. */
static bool meter_view(const lx_image *img, const float *coverage, double *ev100, size_t *seen,
                       size_t *lit)
{
    double sum = 0.0;
    size_t n = 0, count = (size_t)img->width * (size_t)img->height;
    *seen = *lit = 0;
    for (size_t i = 0; i < count; i++) {
        double l = lx_luminance(img->data + 3 * i);
        *seen += coverage[i] > 0.0f;
        *lit += coverage[i] > 0.0f && l > 0.0;
        if (coverage[i] == 1.0f && l > 0.0) {
            sum += log(l);
            n++;
        }
    }
    if (n == 0)
        return false;
    double avg = exp(sum / (double)n);
    /* lx_exposure_from_ev100: exposure = 1 / (1.2 * 2^EV100) = key / avg */
    *ev100 = log2(avg / (1.2 * CLI_RENDER_KEY));
    return isfinite(*ev100);
}

/* ---- the camera ------------------------------------------------------------- */

/* "camera 1 'Side' (node 'CamNode')" */
static void camera_label(char *buf, size_t size, const lx_scene *scene, uint32_t i)
{
    const lx_scene_camera *c = &scene->cameras[i];
    if (c->node_name && strcmp(c->node_name, c->name) != 0)
        snprintf(buf, size, "camera %u '%s' (node '%s')", i, c->name, c->node_name);
    else
        snprintf(buf, size, "camera %u '%s'", i, c->name);
}

/* The scene camera --gltf-camera names: a number in 0..count-1, else a
 * camera name, else the name of the node that places it. */
static bool find_camera(const lx_scene *scene, const char *spec, uint32_t *out)
{
    long n;
    if (cli_parse_int(spec, 0, (long)UINT32_MAX, &n)) {
        if ((uint32_t)n >= scene->camera_count)
            return false;
        *out = (uint32_t)n;
        return true;
    }
    for (uint32_t i = 0; i < scene->camera_count; i++)
        if (strcmp(scene->cameras[i].name, spec) == 0) {
            *out = i;
            return true;
        }
    for (uint32_t i = 0; i < scene->camera_count; i++)
        if (scene->cameras[i].node_name && strcmp(scene->cameras[i].node_name, spec) == 0) {
            *out = i;
            return true;
        }
    return false;
}

/* "2 cameras: 0 'Main', 1 'Side'" (the first few) */
static void camera_list(char *buf, size_t size, const lx_scene *scene)
{
    size_t len = (size_t)snprintf(buf, size, "%u %s", scene->camera_count,
                                  cli_plural(scene->camera_count, "camera", "cameras"));
    for (uint32_t i = 0; i < scene->camera_count && len + 1 < size; i++) {
        if (i == 8) {
            snprintf(buf + len, size - len, ", ...");
            break;
        }
        len += (size_t)snprintf(buf + len, size - len, "%s%u '%s'", i ? ", " : ": ", i,
                                scene->cameras[i].name);
    }
}

/* Places a->desc.camera unless --camera did: --view's framing, the glTF
 * camera --gltf-camera names or else the file's first camera,
 * or lx_camera_auto. Says which on stderr (unless quiet). */
static int choose_camera(render_args *a, const lx_scene *scene, const lx_lightmaps *lm,
                         const lx_tracer *tracer)
{
    if (a->has_camera)
        return EXIT_OK;
    float aspect = (float)a->desc.width / (float)a->desc.height;
    lx_vec3 lo, hi;
    lx_scene_bounds(scene, &lo, &hi);
    if (a->has_view) {
        a->desc.camera = lx_camera_frame(lo, hi, a->view, a->desc.camera.fov, aspect);
        return EXIT_OK;
    }
    char label[300], list[400];
    uint32_t pick = UINT32_MAX;
    if (a->gltf_camera) {
        camera_list(list, sizeof list, scene);
        if (scene->camera_count == 0) {
            cli_error("%s: --gltf-camera %s: the scene has no cameras", a->scene, a->gltf_camera);
            return EXIT_USAGE;
        }
        if (!find_camera(scene, a->gltf_camera, &pick)) {
            cli_error("%s: --gltf-camera %s: no such camera; the scene has %s", a->scene,
                      a->gltf_camera, list);
            return EXIT_USAGE;
        }
    } else if (scene->camera_count) {
        pick = 0;
    }
    if (pick != UINT32_MAX) {
        const lx_scene_camera *c = &scene->cameras[pick];
        float fov = a->desc.camera.fov;
        a->desc.camera = lx_camera_from_scene(c);
        bool ortho = c->type == LX_SCENE_CAMERA_ORTHOGRAPHIC;
        if (a->has_fov && ortho)
            lx_log(LX_LOG_WARN, "%s: --fov does not apply to an orthographic camera: ignored",
                   a->scene);
        else if (a->has_fov)
            a->desc.camera.fov = fov;
        if (lx_camera_check(&a->desc.camera) != LX_OK) {
            camera_label(label, sizeof label, scene, pick);
            cli_error("%s: %s: %s", a->scene, label, lx_last_error());
            return EXIT_FAILED;
        }
        if (!a->quiet) {
            camera_label(label, sizeof label, scene, pick);
            char what[80];
            if (ortho)
                snprintf(what, sizeof what, "orthographic, %s m tall",
                         cli_num_digits(a->desc.camera.ortho_height, 4));
            else
                snprintf(what, sizeof what, "%s field of view %s degrees",
                         a->has_fov ? "--fov" : "its",
                         cli_num_digits(LX_RAD2DEG(a->desc.camera.fov), 4));
            bool others = !a->gltf_camera && scene->camera_count > 1;
            fprintf(stderr, "luxel: %s of %s, %s%s\n", label, a->scene, what,
                    others ? " (luxel render --gltf-camera picks another)" : "");
        }
        return EXIT_OK;
    }
    lx_camera_auto_info info;
    if (lx_camera_auto(scene, lm, tracer, a->desc.camera.fov, aspect, &a->desc.camera, &info) !=
        LX_OK) {
        cli_error("%s: %s", a->scene, lx_last_error());
        return EXIT_FAILED;
    }
    if (info.enclosed && !a->quiet) {
        fprintf(stderr,
                "luxel: the scene is a closed room (walls all round): the camera is placed %s "
                "(--view iso shows it from outside)\n",
                info.placement);
    } else if (info.moved && !a->quiet) {
        char what[160];
        if (info.outside_unlit > 0.0f && info.outside_back > 0.0f)
            snprintf(what, sizeof what, "back faces (%s%%) and unlit surfaces (%s%%)",
                     cli_num_digits(100.0 * info.outside_back, 2),
                     cli_num_digits(100.0 * info.outside_unlit, 2));
        else if (info.outside_unlit > 0.0f)
            snprintf(what, sizeof what, "unlit surfaces (%s%%)",
                     cli_num_digits(100.0 * info.outside_unlit, 2));
        else
            snprintf(what, sizeof what, "back faces (%s%%)",
                     cli_num_digits(100.0 * info.outside_back, 2));
        fprintf(stderr,
                "luxel: the default view from outside sees mostly %s of what it meets: a "
                "closed room? %s%s%s (--view iso keeps it)\n",
                what, info.inside ? "The camera is placed " : "The view from the ",
                info.placement, info.inside ? "" : " is taken instead");
    }
    return EXIT_OK;
}

/* Renders scene (already carrying the lightmaps' UVs) and writes output. */
static int render_and_write(render_args *a, const lx_lightmaps *lm, const lx_scene *scene)
{
    if (lx_lightmaps_check(lm, scene) != LX_OK) {
        cli_error("%s", lx_last_error());
        return EXIT_FAILED;
    }
    bool lit = false;
    for (uint32_t p = 0; p < lm->page_count && !lit; p++) {
        const lx_image *img = &lm->pages[p].image;
        size_t n = (size_t)img->width * (size_t)img->height * 3;
        for (size_t k = 0; k < n && !lit; k++)
            lit = img->data[k] > 0.0f;
    }
    if (!lit)
        lx_log(LX_LOG_WARN, "%s: every lightmap is black: the scene will be", lm->dir);
    lx_vec3 lo, hi;
    if (!a->has_camera && !lx_scene_bounds(scene, &lo, &hi)) {
        cli_error("%s: the scene is empty: nothing to render", a->scene);
        return EXIT_FAILED;
    }
    lx_tracer *tracer = NULL;
    lx_tracer_desc td = {.threads = a->desc.threads};
    if (lx_tracer_create(scene, &td, &tracer) != LX_OK) {
        cli_error("%s: %s", a->scene, lx_last_error());
        return EXIT_FAILED;
    }
    int chosen = choose_camera(a, scene, lm, tracer);
    if (chosen != EXIT_OK) {
        lx_tracer_destroy(tracer);
        return chosen;
    }
    /* the sky the bake was lit by, as the background */
    lx_cubemap sky = {0};
    bool have_sky = false;
    if (lm->sky) {
        bool constant = strncmp(lm->sky, "const:", 6) == 0;
        if (constant || file_exists(lm->sky)) {
            int loaded = cli_load_environment_run("render", lm->sky, 0.0f, CLI_RENDER_SKY_SIZE,
                                                  a->desc.threads, a->quiet, &sky);
            if (loaded != EXIT_OK) {
                lx_tracer_destroy(tracer);
                return loaded;
            }
            a->desc.sky = &sky;
            a->desc.sky_intensity = lm->sky_intensity;
            have_sky = true;
        } else {
            lx_log(LX_LOG_WARN, "%s: the sky the bake used is not here: a grey background",
                   lm->sky);
        }
    }
    cli_phase("lightmaps and sky");
    cli_progress progress;
    cli_progress_init(&progress, "render", a->quiet);
    a->desc.progress = cli_progress_update;
    a->desc.progress_user = &progress;
    lx_image img = {0};
    bool meter = !a->has_exposure && !a->bake_exposure;
    float *coverage = NULL;
    if (!(coverage = malloc((size_t)a->desc.width * (size_t)a->desc.height * sizeof *coverage))) {
        lx_cubemap_free(&sky);
        lx_tracer_destroy(tracer);
        cli_error("out of memory");
        return EXIT_FAILED;
    }
    a->desc.coverage = coverage;
    lx_status st = lx_render_view(scene, lm, tracer, &a->desc, &img);
    lx_tracer_destroy(tracer);
    cli_progress_finish(&progress);
    lx_cubemap_free(&sky);
    a->desc.sky = NULL;
    a->desc.coverage = NULL;
    double ev = a->has_exposure ? a->exposure_ev100 : lm->preview_ev100;
    const char *ev_from = a->has_exposure ? "" : " (the bake's)";
    if (st == LX_OK) {
        double metered;
        size_t seen, lit_pixels;
        bool ok = meter_view(&img, coverage, &metered, &seen, &lit_pixels);
        if (seen == 0)
            lx_log(LX_LOG_WARN, "%s: the camera sees none of the scene",
                   a->shown ? a->shown : a->output);
        else if (lit_pixels == 0)
            lx_log(LX_LOG_WARN, "%s: all the camera sees of the scene is black",
                   a->shown ? a->shown : a->output);
        if (meter && ok) {
            ev = metered;
            ev_from = " (metered)";
        } else if (meter && seen) {
            lx_log(LX_LOG_WARN, "%s: nothing lit to meter: exposed as the bake's previews",
                   a->shown ? a->shown : a->output);
        }
    }
    /* without a sky, a neutral grey behind the scene at half the key: it
     * follows the exposure, so it never outshines the view */
    if (st == LX_OK && !have_sky) {
        float grey = (float)(0.5 * CLI_RENDER_KEY) / lx_exposure_from_ev100((float)ev);
        size_t count = (size_t)img.width * (size_t)img.height;
        for (size_t i = 0; i < count; i++)
            for (int k = 0; k < 3; k++)
                img.data[3 * i + k] += (1.0f - coverage[i]) * grey;
    }
    free(coverage);
    if (st != LX_OK) {
        if (st == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s", lx_last_error());
        return EXIT_FAILED;
    }
    lx_image_format format = lx_image_format_from_path(a->output);
    bool eight_bit = format == LX_IMAGE_PNG || format == LX_IMAGE_JPG || format == LX_IMAGE_TGA;
    cli_progress_init(&progress, "write", a->quiet);
    lx_image_write_desc wd = {.exposure = eight_bit ? lx_exposure_from_ev100((float)ev) : 0.0f,
                              .tonemap = a->tonemap,
                              .threads = a->desc.threads,
                              .progress = cli_progress_update,
                              .progress_user = &progress};
    st = lx_image_write(a->output, &img, &wd);
    cli_progress_finish(&progress);
    lx_image_free(&img);
    if (st != LX_OK) {
        if (st == LX_ERR_CANCELLED)
            cli_report_interrupt(false);
        else
            cli_error("%s", lx_last_error());
        return EXIT_FAILED;
    }
    if (!a->quiet && !a->no_summary) {
        if (eight_bit)
            fprintf(stderr,
                    "luxel: rendered %dx%d, %d samples a pixel, in %.2f s; EV100 %.2f%s, %s\n",
                    a->desc.width, a->desc.height, a->desc.samples, cli_elapsed(), ev, ev_from,
                    lx_tonemap_name(a->tonemap));
        else
            fprintf(stderr,
                    "luxel: rendered %dx%d, %d samples a pixel, in %.2f s (radiance, nits)\n",
                    a->desc.width, a->desc.height, a->desc.samples, cli_elapsed());
        printf("%s\n", a->output);
    }
    return EXIT_OK;
}

int cmd_render(int argc, char **argv)
{
    render_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    lx_lightmaps lm;
    lx_lightmaps_load_desc lmd = {.allow_any_path = cli_allow_any_path()};
    if (lx_lightmaps_load(a.lightmaps, &lmd, &lm) != LX_OK) {
        cli_error("%s", lx_last_error());
        return EXIT_FAILED;
    }
    /* the scene with the bake's generated UVs, when it is there */
    bool with_uvs = lm.scene_with_uvs && file_exists(lm.scene_with_uvs);
    const char *path = with_uvs ? lm.scene_with_uvs : a.scene;
    lx_scene *scene = NULL;
    int status = EXIT_FAILED;
    lx_scene_load_desc ld = {.allow_any_path = cli_allow_any_path()};
    if (!cli_scene_load(path, &ld, &scene))
        goto done;
    cli_phase("import");
    /* the bake's per-node settings its lights JSON gave */
    lx_lightmaps_apply_settings(&lm, scene);
    if (!with_uvs && any_generated(&lm)) {
        if (unwrap_again(&lm, scene, a.scene, a.desc.threads, a.quiet) != EXIT_OK)
            goto done;
        cli_phase("unwrap");
    }
    status = render_and_write(&a, &lm, scene);
done:
    lx_scene_destroy(scene);
    lx_lightmaps_free(&lm);
    return status;
}

int cli_render_bake(const char *dir, const char *out, const char *shown, const lx_scene *scene,
                    int threads, bool quiet)
{
    render_args a;
    memset(&a, 0, sizeof a);
    a.desc = lx_render_desc_defaults(NULL);
    a.desc.threads = threads;
    a.desc.camera.fov = LX_DEG2RAD(LX_RENDER_DEFAULT_FOV_DEGREES);
    a.tonemap = CLI_RENDER_TONEMAP;
    a.scene = scene->path;
    a.lightmaps = dir;
    a.quiet = quiet;
    a.no_summary = true;
    a.output = out;
    a.shown = shown;
    lx_lightmaps lm;
    int status = EXIT_FAILED;
    lx_lightmaps_load_desc lmd = {.allow_any_path = cli_allow_any_path()};
    if (lx_lightmaps_load(dir, &lmd, &lm) != LX_OK)
        cli_error("%s", lx_last_error());
    else
        status = render_and_write(&a, &lm, scene);
    lx_lightmaps_free(&lm);
    return status;
}
