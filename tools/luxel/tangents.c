/* luxel tangents: TANGENT (xyz + handedness w) for every mesh of a scene
 * with normals and UVs, written with the scene as a .glb. Tangents are
 * computed per triangle corner (MikkTSpace or Lengyel, maps.h); a vertex
 * whose corners get different tangents is split, so each new vertex is a
 * (mesh vertex, tangent) pair and the triangles keep their order. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

static const char *tangents_usage =
    "usage: luxel tangents SCENE -o OUT.glb [options]\n"
    "\n"
    "Computes a tangent frame (TANGENT: xyz and the handedness w, bitangent =\n"
    "cross(normal, tangent) * w) for every primitive of SCENE (glTF 2.0 .gltf/.glb\n"
    "or OBJ) that has normals and UVs, from the UV set its material's normal\n"
    "texture reads (else TEXCOORD_0), and writes the scene as a glTF binary. A\n"
    "glTF scene keeps everything else as it was and its triangles in their\n"
    "order; vertices whose corners need different frames are split. Existing\n"
    "tangents are replaced.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE      the .glb to write (required)\n"
    "  --method M             mikktspace (default; what glTF specifies) or lengyel\n"
    "  --uv-set N             compute from TEXCOORD_N for every primitive\n"
    "  -q, --quiet            no summary\n"
    "  --allow-any-path       read files the inputs name outside their folders\n"
    "  -h, --help             show this help\n";

enum { OPT_METHOD = 256, OPT_UV_SET };

typedef struct tangents_args {
    const char *scene, *output;
    lx_tangent_method method;
    int uv_set; /* -1: per material */
    bool quiet;
} tangents_args;

static int parse_args(int argc, char **argv, tangents_args *a)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"method", required_argument, NULL, OPT_METHOD},
                                            {"uv-set", required_argument, NULL, OPT_UV_SET},
                                            {"quiet", no_argument, NULL, 'q'},
                                            CLI_ANY_PATH_OPTION,
                                            {"help", no_argument, NULL, 'h'},
                                            {NULL, 0, NULL, 0}};
    memset(a, 0, sizeof *a);
    a->uv_set = -1;
    opterr = 0;
    optind = 1;
    int c;
    long n;
    while ((c = getopt_long(argc, argv, ":o:qh", options, NULL)) != -1) {
        switch (c) {
        case 'o':
            a->output = optarg;
            break;
        case OPT_METHOD:
            if (!lx_tangent_method_parse(optarg, &a->method))
                return cli_usage_error("tangents",
                                       "--method must be mikktspace or lengyel, not '%s'", optarg);
            break;
        case OPT_UV_SET:
            if (!cli_parse_int(optarg, 0, LX_MAX_UV_SETS - 1, &n))
                return cli_usage_error("tangents", "--uv-set must be an integer in 0..%d, not '%s'",
                                       LX_MAX_UV_SETS - 1, optarg);
            a->uv_set = (int)n;
            break;
        case 'h':
            fputs(tangents_usage, stdout);
            return -1;
        default: {
            int rc = cli_common_option("tangents", c, argv, NULL, &a->quiet);
            if (rc != 0)
                return rc;
        }
        }
    }
    int one = cli_one_scene("tangents", argc, argv, &a->scene);
    if (one != 0)
        return one;
    if (!a->output)
        return cli_usage_error("tangents", "no output given (-o OUT.glb)");
    size_t len = strlen(a->output);
    if (len <= 4 || strcasecmp(a->output + len - 4, ".glb") != 0)
        return cli_usage_error("tangents",
                               "the output is a glTF binary: its name ends in .glb, not '%s'",
                               a->output);
    return 0;
}

/* One mesh's new vertices: a (vertex, tangent) pair per distinct corner. */
typedef struct mesh_out {
    uint32_t *source, *indices;
    float *tangent; /* 4 per new vertex */
    uint32_t count;
    lx_vertex_attribute attr;
} mesh_out;

static int corner_cmp_key(const lx_vec4 *t, uint32_t va, uint32_t vb, size_t a, size_t b)
{
    if (va != vb)
        return va < vb ? -1 : 1;
    return memcmp(&t[a], &t[b], sizeof *t);
}

typedef struct sort_item {
    uint32_t vertex;
    uint32_t corner;
} sort_item;

static const lx_vec4 *sort_tangents; /* the CLI is single-threaded here */

static int sort_cmp(const void *x, const void *y)
{
    const sort_item *a = x, *b = y;
    int c = corner_cmp_key(sort_tangents, a->vertex, b->vertex, a->corner, b->corner);
    if (c)
        return c;
    return a->corner < b->corner ? -1 : a->corner > b->corner;
}

/* false when out of memory */
static bool split(const lx_mesh *m, lx_vec4 *t, mesh_out *o)
{
    size_t nc = 3 * (size_t)m->triangle_count;
    sort_item *items = malloc(sizeof *items * (nc ? nc : 1));
    o->source = malloc(sizeof(uint32_t) * (nc ? nc : 1));
    o->indices = malloc(sizeof(uint32_t) * (nc ? nc : 1));
    o->tangent = malloc(sizeof(float) * 4 * (nc ? nc : 1));
    if (!items || !o->source || !o->indices || !o->tangent) {
        free(items);
        return false;
    }
    for (size_t k = 0; k < nc; k++) {
        /* -0 and +0 alike, so that equal frames share a vertex */
        t[k].x += 0.0f, t[k].y += 0.0f, t[k].z += 0.0f;
        items[k] = (sort_item){m->indices[k], (uint32_t)k};
    }
    sort_tangents = t;
    qsort(items, nc, sizeof *items, sort_cmp);
    /* new vertices numbered in order of first use, so the output does not
     * depend on the sort */
    uint32_t *group_of = malloc(sizeof(uint32_t) * (nc ? nc : 1));
    uint32_t *first = malloc(sizeof(uint32_t) * (nc ? nc : 1));
    uint32_t *number = malloc(sizeof(uint32_t) * (nc ? nc : 1));
    if (!group_of || !first || !number) {
        free(items), free(group_of), free(first), free(number);
        return false;
    }
    uint32_t groups = 0;
    for (size_t i = 0; i < nc; i++) {
        if (i == 0 || corner_cmp_key(t, items[i].vertex, items[i - 1].vertex, items[i].corner,
                                     items[i - 1].corner) != 0)
            first[groups++] = items[i].corner;
        group_of[items[i].corner] = groups - 1;
    }
    for (uint32_t g = 0; g < groups; g++)
        number[g] = UINT32_MAX;
    o->count = 0;
    for (size_t k = 0; k < nc; k++) {
        uint32_t g = group_of[k];
        if (number[g] == UINT32_MAX) {
            number[g] = o->count;
            o->source[o->count] = m->indices[k];
            memcpy(&o->tangent[4 * (size_t)o->count], &t[first[g]], sizeof(float) * 4);
            o->count++;
        }
        o->indices[k] = number[g];
    }
    free(items), free(group_of), free(first), free(number);
    o->attr = (lx_vertex_attribute){"TANGENT", 4, o->tangent};
    return true;
}

int cmd_tangents(int argc, char **argv)
{
    tangents_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != 0)
        return rc < 0 ? EXIT_OK : rc;
    lx_scene *scene = NULL;
    mesh_out *outs = NULL;
    lx_scene_uvs *entries = NULL;
    int status = EXIT_FAILED;
    lx_scene_load_desc ld = {.allow_any_path = cli_allow_any_path()};
    if (!cli_scene_load(a.scene, &ld, &scene))
        goto done;
    outs = calloc(scene->mesh_count + 1, sizeof *outs);
    entries = calloc(scene->mesh_count + 1, sizeof *entries);
    if (!outs || !entries) {
        cli_error("out of memory");
        goto done;
    }
    uint32_t n = 0, left = 0, replaced = 0, split_vertices = 0;
    for (uint32_t i = 0; i < scene->mesh_count; i++) {
        const lx_mesh *m = &scene->meshes[i];
        int set = a.uv_set;
        if (set < 0) {
            const lx_material *mat =
                m->material < scene->material_count ? &scene->materials[m->material] : NULL;
            set = mat && mat->normal_map_path ? mat->normal_uv_set : 0;
        }
        if (!m->normals || set < 0 || set >= LX_MAX_UV_SETS || !m->uv[set]) {
            left++;
            continue;
        }
        if (m->tangents)
            replaced++;
        lx_vec4 *t = malloc(sizeof(lx_vec4) * (3 * (size_t)m->triangle_count + 1));
        if (!t) {
            cli_error("%s: out of memory", a.scene);
            goto done;
        }
        lx_status st = lx_compute_corner_tangents(m, a.method, set, t);
        bool ok = st == LX_OK && split(m, t, &outs[n]);
        free(t);
        if (st != LX_OK) {
            cli_error("%s: %s", a.scene, lx_last_error());
            goto done;
        }
        if (!ok) {
            cli_error("%s: out of memory", a.scene);
            goto done;
        }
        split_vertices += outs[n].count - (outs[n].count < m->vertex_count ? outs[n].count
                                                                            : m->vertex_count);
        entries[n] = (lx_scene_uvs){.node = LX_SCENE_EVERY_NODE,
                                    .mesh = i,
                                    .vertex_count = outs[n].count,
                                    .vertex_source = outs[n].source,
                                    .indices = outs[n].indices,
                                    .attributes = &outs[n].attr,
                                    .attribute_count = 1};
        n++;
    }
    if (replaced)
        lx_log(LX_LOG_WARN, "%s: %u primitive%s had tangents; replaced", a.scene, replaced,
               replaced == 1 ? "" : "s");
    if (left)
        lx_log(LX_LOG_WARN, "%s: %u primitive%s without normals or UVs left without tangents",
               a.scene, left, left == 1 ? "" : "s");
    lx_glb_write_desc d = {.uvs = entries, .uv_count = n};
    if (lx_scene_write_glb(scene, a.output, &d) != LX_OK) {
        cli_error("%s", lx_last_error());
        goto done;
    }
    if (!a.quiet)
        printf("%s: tangents (%s) for %u primitive%s, %u vertices added by splits\n", a.output,
               lx_tangent_method_name(a.method), n, n == 1 ? "" : "s", split_vertices);
    status = EXIT_OK;
done:
    for (uint32_t i = 0; outs && scene && i < scene->mesh_count; i++) {
        free(outs[i].source);
        free(outs[i].indices);
        free(outs[i].tangent);
    }
    free(outs);
    free(entries);
    lx_scene_destroy(scene);
    return status;
}
