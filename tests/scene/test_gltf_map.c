/* Which of the file's meshes, primitives and materials each of assimp's is.
 * assimp's glTF 2.0 reader makes its meshes and materials in the order the
 * scene's nodes first reach them, not in the file's, so what luxel takes
 * from the JSON (KHR_texture_transform and texCoord per material, the
 * triangle count per primitive that reveals faces assimp dropped) must be
 * matched through the node hierarchy. Files written here reference meshes
 * and materials out of order, instance meshes, have several root nodes,
 * unnamed nodes, nested children, a mesh whose primitives have different
 * materials (one none, one a point primitive), transforms on some
 * materials only, a default scene other than the first, and a mesh only a
 * skin reaches (which no node of the scene lists). Each loaded mesh is
 * identified by the name assimp gives it ("mesh", or "mesh-p" for
 * primitive p of a mesh of several) and checked against what the JSON
 * written here states for that primitive: its triangle count, its
 * material's base colour and its material's KHR_texture_transform and UV
 * set. A dropped-face error must name the primitive the file breaks. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAXP 4  /* primitives per mesh */
#define MAXT 12 /* triangles per primitive */

/* A KHR_texture_transform as written and what it states. Dyadic values:
 * the JSON's decimals are exact in float, so comparisons are exact. */
typedef struct xform {
    const char *json;
    float offset[2], rotation, scale[2];
    int uv; /* the UV set the texture ends up on */
} xform;

static const xform XF[] = {
    {"{\"offset\":[0.25,0.5]}", {0.25f, 0.5f}, 0, {1, 1}, 0},
    {"{\"rotation\":0.5,\"scale\":[2,3],\"texCoord\":1}", {0, 0}, 0.5f, {2, 3}, 1},
    {"{\"offset\":[-0.125,0.75],\"scale\":[0.5,0.5]}", {-0.125f, 0.75f}, 0, {0.5f, 0.5f}, 0},
    {"{\"rotation\":-1.25,\"texCoord\":1}", {0, 0}, -1.25f, {1, 1}, 1},
};
#define NO_XF (-1)

typedef struct spec_material {
    const char *name; /* NULL: none */
    float rgb[3];
    int xform; /* index into XF or NO_XF */
} spec_material;

typedef struct spec_mesh {
    const char *name;
    int prim_count;
    int tris[MAXP];     /* triangles (points: points) of each primitive */
    int material[MAXP]; /* -1: none */
    int bad[MAXP];      /* trailing triangles with a vertex index out of range */
    bool points[MAXP];  /* a POINTS primitive (luxel skips it) */
    bool unloaded;      /* no node of the imported scene reaches it */
} spec_mesh;

typedef struct spec {
    const spec_mesh *meshes;
    int mesh_count;
    const spec_material *materials;
    int material_count;
} spec;

/* Writes the spec's materials (each with a base-colour texture) and meshes
 * into g, in spec order. Primitive p of a mesh is a strip of triangles
 * (v, v+1, v+2) over points zig-zagging along x at height y0 + p. */
static void add_spec(lx_test_gltf *g, const spec *sp)
{
    lx_test_gltf_texture(g, "t.png");
    lx_test_gltf_use_extension(g, "KHR_texture_transform");
    for (int j = 0; j < sp->material_count; j++) {
        const spec_material *m = &sp->materials[j];
        char name[96] = "", ext[256] = "", json[512];
        if (m->name)
            snprintf(name, sizeof name, "\"name\":\"%s\",", m->name);
        if (m->xform != NO_XF)
            snprintf(ext, sizeof ext, ",\"extensions\":{\"KHR_texture_transform\":%s}",
                     XF[m->xform].json);
        snprintf(json, sizeof json,
                 "{%s\"pbrMetallicRoughness\":{\"baseColorFactor\":[%g,%g,%g,1],"
                 "\"baseColorTexture\":{\"index\":0%s}}}",
                 name, m->rgb[0], m->rgb[1], m->rgb[2], ext);
        assert_int_equal(lx_test_gltf_material(g, json), j);
    }
    for (int k = 0; k < sp->mesh_count; k++) {
        const spec_mesh *m = &sp->meshes[k];
        static float pos[MAXP][3 * (MAXT + 2)];
        static uint32_t idx[MAXP][3 * MAXT];
        lx_test_primitive prims[MAXP];
        for (int p = 0; p < m->prim_count; p++) {
            int n = m->tris[p];
            assert_true(n >= 1 && n <= MAXT);
            int nv = m->points[p] ? n : n + 2;
            for (int v = 0; v < nv; v++) {
                pos[p][3 * v] = (float)(v / 2);
                pos[p][3 * v + 1] = (float)(k * MAXP + p);
                pos[p][3 * v + 2] = (float)(v % 2);
            }
            int ni = 0;
            if (m->points[p]) {
                for (int v = 0; v < nv; v++)
                    idx[p][ni++] = (uint32_t)v;
            } else {
                for (int t = 0; t < n; t++) {
                    idx[p][ni++] = (uint32_t)t;
                    idx[p][ni++] = (uint32_t)t + 1;
                    /* a bad triangle's third vertex is past the vertices */
                    idx[p][ni++] = t >= n - m->bad[p] ? (uint32_t)(nv + 7) : (uint32_t)t + 2;
                }
            }
            prims[p] = (lx_test_primitive){.vertex_count = nv,
                                           .position = pos[p],
                                           .index_count = ni,
                                           .indices = idx[p],
                                           .material = m->material[p],
                                           .points = m->points[p]};
        }
        assert_int_equal(lx_test_gltf_mesh(g, m->name, prims, m->prim_count), k);
    }
}

static void write_png(const char *dir)
{
    static const uint8_t px[2 * 2 * 3] = {200, 10, 10, 10, 200, 10, 10, 10, 200, 90, 90, 90};
    char png[1024];
    snprintf(png, sizeof png, "%s/t.png", dir);
    lx_test_write_png(png, 2, 2, 3, px);
}

static lx_scene *load(const char *path)
{
    lx_scene *s = NULL;
    if (lx_scene_load(path, NULL, &s) != LX_OK)
        fail_msg("%s: %s", path, lx_last_error());
    return s;
}

/* The load must fail with status want, naming the file and needle. */
static void load_fails(const char *path, lx_status want, const char *needle)
{
    lx_scene *s = NULL;
    lx_status st = lx_scene_load(path, NULL, &s);
    if (st == LX_OK)
        lx_scene_destroy(s);
    if (st != want)
        fail_msg("%s: status %d, want %d ('%s')", path, (int)st, (int)want,
                 st == LX_OK ? "" : lx_last_error());
    const char *msg = lx_last_error();
    const char *base = strrchr(path, '/') + 1;
    if (!strstr(msg, base) || !strstr(msg, needle))
        fail_msg("message '%s' does not name '%s' and say '%s'", msg, base, needle);
}

/* Every loaded mesh is a primitive of the spec (by assimp's name for it)
 * with its triangles and its material's base colour, transform and UV
 * set; every triangle primitive a scene node reaches is loaded once. */
static void check_scene(const lx_scene *s, const spec *sp)
{
    int seen[16][MAXP] = {{0}};
    assert_true(sp->mesh_count <= 16);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const lx_mesh *lm = &s->meshes[i];
        int mk = -1, mp = -1;
        for (int k = 0; k < sp->mesh_count && mk < 0; k++)
            for (int p = 0; p < sp->meshes[k].prim_count; p++) {
                char want[96];
                if (sp->meshes[k].prim_count > 1)
                    snprintf(want, sizeof want, "%s-%d", sp->meshes[k].name, p);
                else
                    snprintf(want, sizeof want, "%s", sp->meshes[k].name);
                if (strcmp(want, lm->name) == 0) {
                    mk = k;
                    mp = p;
                    break;
                }
            }
        if (mk < 0)
            fail_msg("loaded mesh '%s' is none of the file's primitives", lm->name);
        const spec_mesh *m = &sp->meshes[mk];
        seen[mk][mp]++;
        if (m->unloaded || m->points[mp])
            fail_msg("mesh '%s' should not be loaded", lm->name);
        if ((int)lm->triangle_count != m->tris[mp])
            fail_msg("mesh '%s': %u triangles, the file has %d", lm->name, lm->triangle_count,
                     m->tris[mp]);
        assert_true(lm->material < s->material_count);
        const lx_material *mat = &s->materials[lm->material];
        int j = m->material[mp];
        float rgb[3] = {1, 1, 1}; /* glTF's default material */
        int xf = NO_XF;
        if (j >= 0) {
            memcpy(rgb, sp->materials[j].rgb, sizeof rgb);
            xf = sp->materials[j].xform;
        }
        if (mat->base_color.x != rgb[0] || mat->base_color.y != rgb[1] ||
            mat->base_color.z != rgb[2])
            fail_msg("mesh '%s': material '%s' has base colour (%g, %g, %g), the file (%g, %g, %g)",
                     lm->name, mat->name, mat->base_color.x, mat->base_color.y, mat->base_color.z,
                     rgb[0], rgb[1], rgb[2]);
        const lx_uv_transform *t = &mat->base_color_transform;
        if (xf == NO_XF) {
            if (t->enabled || mat->base_color_uv_set != 0)
                fail_msg("mesh '%s': material '%s' has a transform (offset %g, %g, rotation %g), "
                         "the file none",
                         lm->name, mat->name, t->offset.x, t->offset.y, t->rotation);
        } else {
            const xform *x = &XF[xf];
            if (!t->enabled || t->offset.x != x->offset[0] || t->offset.y != x->offset[1] ||
                t->rotation != x->rotation || t->scale.x != x->scale[0] ||
                t->scale.y != x->scale[1] || mat->base_color_uv_set != x->uv)
                fail_msg("mesh '%s': material '%s': transform %s offset (%g, %g) rotation %g "
                         "scale (%g, %g) on UV set %d, the file %s",
                         lm->name, mat->name, t->enabled ? "on" : "off", t->offset.x, t->offset.y,
                         t->rotation, t->scale.x, t->scale.y, mat->base_color_uv_set, x->json);
        }
    }
    for (int k = 0; k < sp->mesh_count; k++)
        for (int p = 0; p < sp->meshes[k].prim_count; p++) {
            int want = sp->meshes[k].unloaded || sp->meshes[k].points[p] ? 0 : 1;
            if (seen[k][p] != want)
                fail_msg("mesh '%s' primitive %d loaded %d times, want %d", sp->meshes[k].name, p,
                         seen[k][p], want);
        }
}

/* The loaded node's meshes are named as listed (assimp's names). */
static void node_has(const lx_scene *s, const char *node, const char *mesh)
{
    for (uint32_t i = 0; i < s->node_count; i++) {
        if (strcmp(s->nodes[i].name, node) != 0)
            continue;
        assert_int_equal(s->nodes[i].mesh_count, 1);
        const char *got = s->meshes[s->nodes[i].meshes[0]].name;
        if (strcmp(got, mesh) != 0)
            fail_msg("node '%s' carries mesh '%s', the file '%s'", node, got, mesh);
        return;
    }
    fail_msg("no node '%s'", node);
}

static uint32_t node_mesh(const lx_scene *s, const char *node)
{
    for (uint32_t i = 0; i < s->node_count; i++)
        if (strcmp(s->nodes[i].name, node) == 0)
            return s->nodes[i].meshes[0];
    fail_msg("no node '%s'", node);
    return 0;
}

static void path_in(char *out, size_t size, const char *dir, const char *name)
{
    snprintf(out, size, "%s/%s", dir, name);
}

/* ---- materials and meshes out of order ------------------------------------- */

static const spec_material MATS4[] = {
    {"red", {1, 0, 0}, 0},
    {"green", {0, 1, 0}, 1},
    {"blue", {0, 0, 1}, NO_XF},
    {"unused", {1, 1, 0}, 2},
};

/* Nodes reach the meshes in reverse, so assimp's meshes and materials come
 * reversed. With 1, 2 and 3 triangles, matching by position would also
 * take the 1-triangle primitive for a 3-triangle one that lost faces (the
 * false error 2CylinderEngine.glb gave). */
static void out_of_order(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_gltf_map_order");
    write_png(dir);
    static const spec_mesh meshes[] = {
        {"one", 1, {1}, {0}, {0}, {0}, 0},
        {"two", 1, {2}, {1}, {0}, {0}, 0},
        {"three", 1, {3}, {2}, {0}, {0}, 0},
    };
    spec sp = {meshes, 3, MATS4, 4};
    lx_test_gltf *g = lx_test_gltf_new();
    add_spec(g, &sp);
    lx_test_gltf_node(g, "n0", 2, "");
    lx_test_gltf_node(g, "n1", 1, "");
    lx_test_gltf_node(g, "n2", 0, "");
    char path[1024];
    path_in(path, sizeof path, dir, "order.gltf");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = load(path);
    /* assimp makes "three" first: the order really differs from the file's */
    assert_string_equal(s->meshes[0].name, "three");
    check_scene(s, &sp);
    node_has(s, "n0", "three");
    node_has(s, "n1", "two");
    node_has(s, "n2", "one");
    lx_scene_destroy(s);
}

/* ---- hierarchy: several roots, unnamed nodes, children, instances ---------- */

static void hierarchy(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_gltf_map_tree");
    write_png(dir);
    static const spec_material mats[] = {
        {"m0", {1, 0, 0}, 0}, {"m1", {0, 1, 0}, 1}, {NULL, {0, 0, 1}, 3}, /* an unnamed material */
    };
    static const spec_mesh meshes[] = {
        {"A", 1, {1}, {1}, {0}, {0}, 0},
        {"B", 1, {2}, {0}, {0}, {0}, 0},
        {"C", 1, {3}, {2}, {0}, {0}, 0},
        {"D", 1, {4}, {-1}, {0}, {0}, 0},
    };
    spec sp = {meshes, 4, mats, 3};
    lx_test_gltf *g = lx_test_gltf_new();
    add_spec(g, &sp);
    /* scene roots 4, 0, 3; first reached: C, A, D, B */
    lx_test_gltf_node_ex(g, NULL, -1, "\"children\":[1,2]", false); /* 0 */
    lx_test_gltf_node_ex(g, "leafB", 1, "", false);                 /* 1 */
    lx_test_gltf_node_ex(g, NULL, 0, "", false);                    /* 2: A again */
    lx_test_gltf_node_ex(g, "soloB", 1, "", false);                 /* 3: B again */
    lx_test_gltf_node_ex(g, NULL, 2, "\"children\":[5]", false);    /* 4 */
    lx_test_gltf_node_ex(g, "deepA", 0, "\"children\":[6]", false); /* 5 */
    lx_test_gltf_node_ex(g, "deepD", 3, "", false);                 /* 6 */
    lx_test_gltf_scenes(g, "\"scene\":0,\"scenes\":[{\"nodes\":[4,0,3]}]");
    char path[1024];
    path_in(path, sizeof path, dir, "tree.gltf");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = load(path);
    check_scene(s, &sp);
    assert_int_equal(s->node_count, 6); /* the nodes with a mesh */
    node_has(s, "leafB", "B");
    node_has(s, "soloB", "B");
    assert_int_equal(node_mesh(s, "leafB"), node_mesh(s, "soloB"));
    node_has(s, "deepA", "A");
    node_has(s, "deepD", "D");
    lx_scene_destroy(s);
}

/* ---- a mesh of several primitives, materials shared and on some only ----- */

static void primitives(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_gltf_map_prims");
    write_png(dir);
    static const spec_material mats[] = {
        {"plain", {1, 1, 0}, NO_XF},
        {"shifted", {0, 1, 1}, 0},
        {"turned", {1, 0, 1}, 1},
        {"scaled", {0.5f, 0.5f, 1}, 2},
    };
    static const spec_mesh meshes[] = {
        {"other", 1, {2}, {3}, {0}, {0}, 0},
        {"multi", 4, {1, 2, 3, 1}, {2, -1, 0, 1}, {0}, {0}, 0},
        {"again", 2, {1, 3}, {2, 3}, {0}, {false, true}, 0},
    };
    spec sp = {meshes, 3, mats, 4};
    lx_test_gltf *g = lx_test_gltf_new();
    add_spec(g, &sp);
    lx_test_gltf_node(g, "first", 2, "");
    lx_test_gltf_node(g, "second", 1, "");
    lx_test_gltf_node(g, "third", 0, "");
    char path[1024];
    path_in(path, sizeof path, dir, "prims.gltf");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = load(path);
    check_scene(s, &sp);
    lx_scene_destroy(s);
}

/* ---- the default scene is not the first -------------------------------------- */

static void second_scene(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_gltf_map_scene");
    write_png(dir);
    static const spec_material mats[] = {
        {"a", {1, 0, 0}, 0},
        {"b", {0, 1, 0}, 1},
        {"c", {0, 0, 1}, 3},
    };
    static const spec_mesh meshes[] = {
        {"zero", 1, {1}, {0}, {0}, {0}, true}, /* only scene 0 has it */
        {"uno", 1, {2}, {1}, {0}, {0}, 0},
        {"dos", 1, {3}, {2}, {0}, {0}, 0},
    };
    spec sp = {meshes, 3, mats, 3};
    lx_test_gltf *g = lx_test_gltf_new();
    add_spec(g, &sp);
    lx_test_gltf_node_ex(g, "s0", 0, "", false);
    lx_test_gltf_node_ex(g, "s1a", 1, "", false);
    lx_test_gltf_node_ex(g, "s1b", 2, "", false);
    lx_test_gltf_scenes(g, "\"scene\":1,\"scenes\":[{\"nodes\":[0]},{\"nodes\":[2,1]}]");
    char path[1024];
    path_in(path, sizeof path, dir, "scene1.gltf");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = load(path);
    check_scene(s, &sp);
    node_has(s, "s1a", "uno");
    node_has(s, "s1b", "dos");
    lx_scene_destroy(s);
}

/* ---- dropped faces ------------------------------------------------------------ */

/* Out-of-range indices in primitive 1 of mesh 1, which nodes reach after
 * mesh 2 and also instance: the error names that primitive and its counts,
 * and, when mesh 2 breaks too, still the first broken one in file order. */
static void dropped_faces(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_gltf_map_faces");
    write_png(dir);
    for (int variant = 0; variant < 2; variant++) {
        spec_mesh meshes[] = {
            {"fine", 1, {4}, {-1}, {0}, {0}, 0},
            {"broken", 2, {2, 3}, {-1, -1}, {0, 1}, {0}, 0},
            {"also", 1, {5}, {-1}, {variant ? 2 : 0}, {0}, 0},
        };
        spec sp = {meshes, 3, MATS4, 0};
        lx_test_gltf *g = lx_test_gltf_new();
        add_spec(g, &sp);
        lx_test_gltf_node(g, "n0", 2, "");
        lx_test_gltf_node(g, "n1", 1, "");
        lx_test_gltf_node(g, "n2", 0, "");
        lx_test_gltf_node(g, "n3", 1, "");
        char path[1024];
        path_in(path, sizeof path, dir, variant ? "two.gltf" : "one.gltf");
        lx_test_gltf_write(g, path);
        lx_test_gltf_free(g);
        load_fails(path, LX_ERR_FORMAT,
                   "mesh 1 ('broken'): primitive 1: 1 of 3 triangles have vertex indices out of "
                   "range");
    }
}

/* ---- a mesh only a skin reaches ------------------------------------------------ */

/* assimp also loads the nodes a skin names as joints, and their meshes,
 * though no node of the scene lists them: such a mesh cannot be matched
 * through the nodes. Faces dropped from it are told by assimp's log; its
 * material, used by no matched mesh, is matched by name when that is
 * unambiguous or when the candidates agree, and the load fails naming the
 * material when they differ. */
static void write_skin_file(const char *path, const spec *sp)
{
    lx_test_gltf *g = lx_test_gltf_new();
    add_spec(g, sp);
    lx_test_gltf_node(g, "root", 0, "");
    lx_test_gltf_node_ex(g, "bone", 1, "", false);
    lx_test_gltf_top(g, "\"skins\":[{\"joints\":[1]}]");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void skin_only_mesh(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_gltf_map_skin");
    write_png(dir);
    char path[1024];
    /* a valid file loads, the joint's material found by its name */
    static const spec_material named[] = {{"m0", {1, 0, 0}, 0}, {"only", {0, 1, 0}, 1}};
    spec_mesh meshes[] = {
        {"seen", 1, {2}, {0}, {0}, {0}, 0},
        {"joint", 1, {3}, {1}, {0}, {0}, 0},
    };
    spec sp = {meshes, 2, named, 2};
    path_in(path, sizeof path, dir, "valid.gltf");
    write_skin_file(path, &sp);
    lx_scene *s = load(path);
    check_scene(s, &sp);
    lx_scene_destroy(s);

    /* faces dropped from the joint's mesh: assimp's log tells */
    meshes[1].bad[0] = 1;
    path_in(path, sizeof path, dir, "dropped.gltf");
    write_skin_file(path, &sp);
    load_fails(path, LX_ERR_FORMAT, "mesh 'joint'");
    meshes[1].bad[0] = 0;

    /* two materials of one name whose transforms agree: either will do */
    static const spec_material agree[] = {{"dup", {1, 0, 0}, 2}, {"dup", {0, 1, 0}, 2}};
    sp.materials = agree;
    path_in(path, sizeof path, dir, "agree.gltf");
    write_skin_file(path, &sp);
    s = load(path);
    check_scene(s, &sp);
    lx_scene_destroy(s);

    /* ... and when they differ, the load fails rather than guess */
    static const spec_material differ[] = {{"dup", {1, 0, 0}, 0}, {"dup", {0, 1, 0}, 1}};
    sp.materials = differ;
    path_in(path, sizeof path, dir, "differ.gltf");
    write_skin_file(path, &sp);
    load_fails(path, LX_ERR_UNSUPPORTED, "material 'dup'");

    /* no KHR_texture_transform anywhere: assimp's texCoord is the file's */
    static const spec_material none[] = {{"dup", {1, 0, 0}, NO_XF}, {"dup", {0, 1, 0}, NO_XF}};
    sp.materials = none;
    path_in(path, sizeof path, dir, "none.gltf");
    write_skin_file(path, &sp);
    s = load(path);
    check_scene(s, &sp);
    lx_scene_destroy(s);
}

/* ---- a hierarchy that does not line up ------------------------------------------ */

/* assimp skips a "children" entry that is not an unsigned integer in its
 * JSON reader's terms, and 1.0 is a double to it, while to the glTF spec
 * (and cJSON) it is node 1: the node "top" has one child in assimp's tree
 * and two in the file. Nothing under it is matched then: faces dropped
 * there are told by assimp's log, and the material of the mesh under it
 * is matched by its (unique) name. */
static void write_mismatch(const char *path, const spec *sp)
{
    lx_test_gltf *g = lx_test_gltf_new();
    add_spec(g, sp);
    lx_test_gltf_node(g, "other", 0, "");
    lx_test_gltf_node(g, "top", -1, "\"children\":[2,2.0]");
    lx_test_gltf_node_ex(g, "kid", 1, "", false);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void structure_mismatch(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_gltf_map_mismatch");
    write_png(dir);
    static const spec_material mats[] = {{"first", {1, 0, 0}, 0}, {"kidmat", {0, 1, 0}, 3}};
    spec_mesh meshes[] = {
        {"m0", 1, {2}, {0}, {0}, {0}, 0},
        {"m1", 1, {3}, {1}, {0}, {0}, 0},
    };
    spec sp = {meshes, 2, mats, 2};
    char path[1024];
    path_in(path, sizeof path, dir, "valid.gltf");
    write_mismatch(path, &sp);
    lx_scene *s = load(path);
    check_scene(s, &sp);
    node_has(s, "kid", "m1");
    lx_scene_destroy(s);
    meshes[1].bad[0] = 2;
    path_in(path, sizeof path, dir, "dropped.gltf");
    write_mismatch(path, &sp);
    load_fails(path, LX_ERR_FORMAT, "mesh 'm1'");
}

int main(void)
{
    lx_test_watchdog(120);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(out_of_order),       cmocka_unit_test(hierarchy),
        cmocka_unit_test(primitives),         cmocka_unit_test(second_scene),
        cmocka_unit_test(dropped_faces),      cmocka_unit_test(skin_only_mesh),
        cmocka_unit_test(structure_mismatch),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
