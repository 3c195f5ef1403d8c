/* Hostile node hierarchies (lx_scene_load): files nested deeper than the
 * 256 levels luxel accepts, cyclic through instances or links, or doubling
 * at every level through instances, in glTF 2.0 and 1.0, Collada and FBX
 * (binary and ASCII). Before the up-front checks, 20,000 nested nodes
 * overflowed the stack inside assimp. Each file is written here; the
 * expected outcome is the stated rule: 256 levels load, 257 fail with
 * LX_ERR_FORMAT and a message naming the file, and nothing crashes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "luxel/scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LEVELS_ACCEPTED 256

/* A growing text. */
typedef struct text {
    char *s;
    size_t len, cap;
} text;

static void put(text *t, const void *bytes, size_t n)
{
    if (t->len + n + 1 > t->cap) {
        t->cap = (t->len + n + 1) * 2;
        t->s = realloc(t->s, t->cap);
        assert_non_null(t->s);
    }
    memcpy(t->s + t->len, bytes, n);
    t->len += n;
    t->s[t->len] = '\0';
}

static void putf(text *t, const char *fmt, ...)
{
    char buf[2048];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    assert_true(n >= 0 && (size_t)n < sizeof buf);
    put(t, buf, (size_t)n);
}

static void save(const text *t, const char *path)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(t->s, 1, t->len, fp), t->len);
    assert_int_equal(fclose(fp), 0);
}

static const char *file_in(const char *tag, const char *name)
{
    static char path[1024];
    snprintf(path, sizeof path, "%s/%s", lx_test_dir(tag), name);
    return path;
}

static void loads(const char *path)
{
    lx_scene *s = NULL;
    lx_status st = lx_scene_load(path, NULL, &s);
    if (st != LX_OK)
        fail_msg("lx_scene_load(%s): %s", path, lx_last_error());
    lx_scene_destroy(s);
}

static void refused(const char *path, const char *needle)
{
    lx_scene *s = NULL;
    lx_status st = lx_scene_load(path, NULL, &s);
    if (st == LX_OK) {
        lx_scene_destroy(s);
        fail_msg("lx_scene_load(%s) succeeded", path);
    }
    assert_int_equal(st, LX_ERR_FORMAT);
    assert_null(s);
    const char *msg = lx_last_error();
    const char *base = strrchr(path, '/') + 1;
    if (!strstr(msg, base) || !strstr(msg, needle))
        fail_msg("'%s' does not name %s and say '%s'", msg, base, needle);
    if (strchr(msg, '\n'))
        fail_msg("'%s' is more than one line", msg);
}

/* ---- glTF ------------------------------------------------------------------- */

static const float TRIANGLE[] = {0, 0, 0, 1, 0, 0, 0, 0, 1};

/* A chain of levels nodes, the last carrying a triangle. */
static void write_gltf_chain(const char *path, int levels)
{
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_primitive p = {.vertex_count = 3, .position = TRIANGLE, .material = -1};
    int mesh = lx_test_gltf_mesh(g, "tri", &p, 1);
    for (int i = 0; i < levels; i++) {
        char name[32], members[64] = "";
        snprintf(name, sizeof name, "n%d", i);
        if (i + 1 < levels)
            snprintf(members, sizeof members, "\"children\":[%d]", i + 1);
        lx_test_gltf_node_ex(g, name, i + 1 == levels ? mesh : -1, members, i == 0);
    }
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void test_gltf_depth(void **state)
{
    (void)state;
    const char *path = file_in("test_import_hierarchy_gltf", "chain.gltf");
    write_gltf_chain(path, LEVELS_ACCEPTED);
    loads(path);
    write_gltf_chain(path, LEVELS_ACCEPTED + 1);
    refused(path, "deeper than 256 levels");
    write_gltf_chain(path, 20000);
    refused(path, "deeper than 256 levels");
}

/* glTF 1.0 names nodes by id. */
static void test_gltf1_depth(void **state)
{
    (void)state;
    const char *path = file_in("test_import_hierarchy_gltf1", "chain1.gltf");
    text t = {0};
    putf(&t, "{\"asset\":{\"version\":\"1.0\"},\"scene\":\"s\",\"scenes\":{\"s\":{\"nodes\":"
             "[\"n0\"]}},\"nodes\":{");
    for (int i = 0; i < 20000; i++)
        putf(&t, "%s\"n%d\":{\"children\":[%s%d%s]}", i ? "," : "", i, i + 1 < 20000 ? "\"n" : "",
             i + 1, i + 1 < 20000 ? "\"" : "");
    put(&t, "}}", 2);
    /* the last node's children hold a number, which names no node */
    save(&t, path);
    refused(path, "deeper than 256 levels");
    /* the chain closed into a loop: n19999's child is n0 */
    t.len = 0;
    putf(&t, "{\"asset\":{\"version\":\"1.0\"},\"nodes\":{");
    for (int i = 0; i < 3; i++)
        putf(&t, "%s\"n%d\":{\"children\":[\"n%d\"]}", i ? "," : "", i, (i + 1) % 3);
    put(&t, "}}", 2);
    save(&t, path);
    refused(path, "cycle");
    free(t.s);
}

/* ---- Collada ------------------------------------------------------------------ */

static const char COLLADA_POSITIONS[] = "<float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 0 1"
                                        "</float_array>";
static const char COLLADA_TRIANGLE[] =
    "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
    "<p>0 1 2</p></triangles>";

/* A Collada file's head with one mesh "tri" of the given positions array
 * and primitives. */
static void collada_head_with(text *t, const char *positions, const char *primitives)
{
    putf(t,
         "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/"
         "COLLADASchema\" version=\"1.4.1\">\n<asset><unit meter=\"1\"/><up_axis>Y_UP"
         "</up_axis></asset>\n"
         "<library_geometries><geometry id=\"tri\"><mesh>"
         "<source id=\"p\">%s"
         "<technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\">"
         "<param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
         "<param name=\"Z\" type=\"float\"/></accessor></technique_common></source>"
         "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>"
         "%s</mesh></geometry></library_geometries>\n",
         positions, primitives);
}

static void collada_head(text *t)
{
    collada_head_with(t, COLLADA_POSITIONS, COLLADA_TRIANGLE);
}

static void collada_tail(text *t)
{
    putf(t, "</visual_scene></library_visual_scenes>\n<scene><instance_visual_scene "
            "url=\"#s\"/></scene></COLLADA>\n");
}

static void write_collada_chain(const char *path, int levels)
{
    text t = {0};
    collada_head(&t);
    putf(&t, "<library_visual_scenes><visual_scene id=\"s\">\n");
    for (int i = 0; i < levels; i++)
        putf(&t, "<node id=\"n%d\" name=\"n%d\">", i, i);
    putf(&t, "<instance_geometry url=\"#tri\"/>");
    for (int i = 0; i < levels; i++)
        put(&t, "</node>", 7);
    collada_tail(&t);
    save(&t, path);
    free(t.s);
}

static void test_collada_depth(void **state)
{
    (void)state;
    const char *path = file_in("test_import_hierarchy_dae", "chain.dae");
    write_collada_chain(path, LEVELS_ACCEPTED);
    loads(path);
    write_collada_chain(path, LEVELS_ACCEPTED + 1);
    refused(path, "deeper than 256 levels");
    /* past the XML nesting luxel reads before counting nodes */
    write_collada_chain(path, 20000);
    refused(path, "nested deeper");
}

/* <instance_node> makes a graph of nodes: a loop, and a chain of 40
 * library nodes each instancing the next twice (2^40 nodes once copied). */
static void test_collada_instances(void **state)
{
    (void)state;
    const char *path = file_in("test_import_hierarchy_dae_inst", "instances.dae");
    text t = {0};
    collada_head(&t);
    putf(&t, "<library_nodes><node id=\"a\"><instance_node url=\"#b\"/></node>"
             "<node id=\"b\"><instance_node url=\"#a\"/></node></library_nodes>\n"
             "<library_visual_scenes><visual_scene id=\"s\"><node id=\"root\">"
             "<instance_node url=\"#a\"/></node>");
    collada_tail(&t);
    save(&t, path);
    refused(path, "cycle through node");

    t.len = 0;
    collada_head(&t);
    put(&t, "<library_nodes>", 15);
    for (int i = 0; i < 40; i++)
        putf(&t,
             "<node id=\"L%d\"><instance_node url=\"#L%d\"/><instance_node url=\"#L%d\"/>"
             "</node>\n",
             i, i + 1, i + 1);
    putf(&t, "<node id=\"L40\"><instance_geometry url=\"#tri\"/></node></library_nodes>\n"
             "<library_visual_scenes><visual_scene id=\"s\"><node id=\"root\">"
             "<instance_node url=\"#L0\"/></node>");
    collada_tail(&t);
    save(&t, path);
    refused(path, "through its instances");

    /* a few instances of one node are fine */
    t.len = 0;
    collada_head(&t);
    putf(&t, "<library_nodes><node id=\"leaf\"><instance_geometry url=\"#tri\"/></node>"
             "</library_nodes>\n<library_visual_scenes><visual_scene id=\"s\">"
             "<node id=\"a\"><instance_node url=\"#leaf\"/></node>"
             "<node id=\"b\"><instance_node url=\"#leaf\"/></node>");
    collada_tail(&t);
    save(&t, path);
    loads(path);
    free(t.s);
}

/* The counts assimp sizes arrays by, and the integer lists it reads until
 * their text ends, against the text that holds them: each case a few
 * hundred bytes that asked assimp for gigabytes (or grew without end). */
static void write_collada_mesh(const char *path, const char *positions, const char *primitives)
{
    text t = {0};
    collada_head_with(&t, positions, primitives);
    putf(&t, "<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\">"
             "<instance_geometry url=\"#tri\"/></node>");
    collada_tail(&t);
    save(&t, path);
    free(t.s);
}

static void test_collada_data(void **state)
{
    (void)state;
    const char *path = file_in("test_import_hierarchy_dae_data", "mesh.dae");
    static const struct {
        const char *positions, *primitives, *says;
    } bad[] = {
        /* the fuzzer's case: a character assimp's index reader never passes */
        {COLLADA_POSITIONS,
         "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
         "<p>0 1) 2</p></triangles>",
         "<p> holds something other than integers"},
        {COLLADA_POSITIONS,
         "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
         "<p>0 1<![CDATA[x]]> 2</p></triangles>",
         "<p> holds something other than integers"},
        {"<float_array id=\"pa\" count=\"400000000\">0 0 0 1 0 0 0 0 1</float_array>",
         COLLADA_TRIANGLE, "count of more items beyond what the file holds"},
        {"<float_array id=\"pa\" count=\"90\">0 0 0 1 0 0 0 0 1</float_array>",
         COLLADA_TRIANGLE, "count 90 beyond the 17 bytes of its text"},
        {"<float_array id=\"pa\" count=\"-1\">0 0 0 1 0 0 0 0 1</float_array>",
         COLLADA_TRIANGLE, "count negative or huge"},
        /* the fuzzer's case: an array shorter than its accessor reads
         * (assimp read past it, a null pointer) */
        {"<float_array id=\"pa\" count=\"0\">0 0 0 1 0 0 0 0 1</float_array>",
         COLLADA_TRIANGLE, "<accessor> reads 9 values of array 'pa', which holds 0"},
        {"<float_array id=\"pa\" count=\"8\">0 0 0 1 0 0 0 0 1</float_array>",
         COLLADA_TRIANGLE, "<accessor> reads 9 values of array 'pa', which holds 8"},
        {COLLADA_POSITIONS,
         "<triangles count=\"300\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
         "<p>0 1 2</p></triangles>",
         "900 primitive vertices of 1 inputs each beyond the 5 bytes"},
        {COLLADA_POSITIONS,
         "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
         "<input semantic=\"NORMAL\" source=\"#p\" offset=\"4000\"/>"
         "<p>0 1 2</p></triangles>",
         "primitive vertices of 4001 inputs each"},
        {COLLADA_POSITIONS,
         "<triangles count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"9999\"/>"
         "<p>0 1 2</p></triangles>",
         "<input> offset beyond 4095"},
        {COLLADA_POSITIONS,
         "<polylist count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
         "<vcount>300</vcount><p>0 1 2</p></polylist>",
         "300 primitive vertices"},
        {COLLADA_POSITIONS,
         "<polylist count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
         "<vcount>4000000000</vcount><p>0 1 2</p></polylist>",
         "<vcount> counts more vertices than the file holds"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        write_collada_mesh(path, bad[i].positions, bad[i].primitives);
        refused(path, bad[i].says);
    }
    /* the same meshes written as exporters write them load */
    write_collada_mesh(path, COLLADA_POSITIONS, COLLADA_TRIANGLE);
    loads(path);
    write_collada_mesh(path,
                       "<float_array id=\"pa\" count=\"9\">\n  0 0 0\n  1 0 0\n  0 0 1\n"
                       "</float_array>",
                       "<polylist count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" "
                       "offset=\"0\"/><vcount>3 </vcount><p>\n0 1 2\n</p></polylist>");
    loads(path);
}

/* ---- FBX ------------------------------------------------------------------------ */

/* ASCII FBX 7.4: a chain of Model objects linked by "OO" connections,
 * closed into a loop when cyclic. */
static void write_fbx_ascii(const char *path, int levels, bool cyclic)
{
    text t = {0};
    putf(&t, "; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n"
             "\tFBXVersion: 7400\n}\nGlobalSettings:  {\n\tVersion: 1000\n}\nObjects:  {\n");
    for (int i = 0; i < levels; i++)
        putf(&t, "\tModel: %d, \"Model::n%d\", \"Null\" {\n\t\tVersion: 232\n\t}\n", 1000 + i, i);
    putf(&t, "}\nConnections:  {\n\tC: \"OO\",1000,0\n");
    for (int i = 1; i < levels; i++)
        putf(&t, "\tC: \"OO\",%d,%d\n", 1000 + i, 999 + i);
    if (cyclic)
        putf(&t, "\tC: \"OO\",1000,%d\n", 999 + levels);
    put(&t, "}\n", 2);
    save(&t, path);
    free(t.s);
}

static void test_fbx_ascii(void **state)
{
    (void)state;
    const char *path = file_in("test_import_hierarchy_fbx", "chain.fbx");
    /* the root counts as a level: 255 models below it */
    write_fbx_ascii(path, LEVELS_ACCEPTED - 1, false);
    loads(path);
    write_fbx_ascii(path, LEVELS_ACCEPTED, false);
    refused(path, "deeper than 256 levels");
    write_fbx_ascii(path, 20000, false);
    refused(path, "deeper than 256 levels");
    write_fbx_ascii(path, 4, true);
    refused(path, "cycle through Model");
    /* braces nested past what exporters write */
    text t = {0};
    putf(&t, "; FBX 7.4.0 project file\n");
    for (int i = 0; i < 100; i++)
        put(&t, "A: {\n", 5);
    for (int i = 0; i < 100; i++)
        put(&t, "}\n", 2);
    save(&t, path);
    refused(path, "nested deeper");
    free(t.s);
}

/* Binary FBX 7.4: records of 32-bit end offsets, property counts and
 * lengths, a name, properties and nested records closed by 13 zero bytes. */
typedef struct fbx_record {
    const char *name;
    const char *props; /* the properties' bytes */
    size_t props_len, prop_count;
    struct fbx_record *children;
    size_t child_count;
} fbx_record;

static void le32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put_record(text *t, const fbx_record *r)
{
    size_t at = t->len, name_len = strlen(r->name);
    uint8_t head[13] = {0};
    put(t, head, 13);
    put(t, r->name, name_len);
    put(t, r->props, r->props_len);
    for (size_t i = 0; i < r->child_count; i++)
        put_record(t, &r->children[i]);
    if (r->child_count)
        put(t, head, 13); /* zeros: the list's end */
    le32(head, (uint32_t)t->len);
    le32(head + 4, (uint32_t)r->prop_count);
    le32(head + 8, (uint32_t)r->props_len);
    head[12] = (uint8_t)name_len;
    memcpy(t->s + at, head, 13);
}

/* 'L' then a little-endian int64 */
static size_t prop_id(char *out, int64_t id)
{
    out[0] = 'L';
    for (int i = 0; i < 8; i++)
        out[1 + i] = (char)((uint64_t)id >> (8 * i));
    return 9;
}

static size_t prop_string(char *out, const char *s, size_t n)
{
    out[0] = 'S';
    le32((uint8_t *)out + 1, (uint32_t)n);
    memcpy(out + 5, s, n);
    return 5 + n;
}

/* levels Model objects in a chain, then a record nested nest deep. */
static void write_fbx_binary(const char *path, int levels, int nest)
{
    fbx_record *models = calloc((size_t)levels, sizeof *models);
    fbx_record *links = calloc((size_t)levels, sizeof *links);
    fbx_record *chain = calloc((size_t)nest + 1, sizeof *chain);
    char(*model_props)[64] = calloc((size_t)levels, sizeof *model_props);
    char(*link_props)[64] = calloc((size_t)levels, sizeof *link_props);
    assert_true(models && links && chain && model_props && link_props);
    for (int i = 0; i < levels; i++) {
        char name[32];
        size_t n = (size_t)snprintf(name, sizeof name, "n%d", i);
        memcpy(name + n, "\0\1Model", 7); /* FBX's "name\0\1Class" */
        size_t len = prop_id(model_props[i], 1000 + i);
        len += prop_string(model_props[i] + len, name, n + 7);
        len += prop_string(model_props[i] + len, "Null", 4);
        models[i] = (fbx_record){"Model", model_props[i], len, 3, NULL, 0};
        len = prop_string(link_props[i], "OO", 2);
        len += prop_id(link_props[i] + len, 1000 + i);
        len += prop_id(link_props[i] + len, i ? 999 + i : 0);
        links[i] = (fbx_record){"C", link_props[i], len, 3, NULL, 0};
    }
    for (int i = 0; i <= nest; i++)
        chain[i] = (fbx_record){
            "X", "I\1\0\0\0", 5, 1, i < nest ? &chain[i + 1] : NULL, i < nest ? 1u : 0u};
    fbx_record header_fields[] = {{"FBXHeaderVersion", "I\xeb\x03\0\0", 5, 1, NULL, 0},
                                  {"FBXVersion", "I\xe8\x1c\0\0", 5, 1, NULL, 0}};
    fbx_record settings_fields[] = {{"Version", "I\xe8\x03\0\0", 5, 1, NULL, 0}};
    fbx_record top[] = {{"FBXHeaderExtension", "", 0, 0, header_fields, 2},
                        {"GlobalSettings", "", 0, 0, settings_fields, 1},
                        {"Objects", "", 0, 0, models, (size_t)levels},
                        {"Connections", "", 0, 0, links, (size_t)levels},
                        chain[0]};
    text t = {0};
    put(&t, "Kaydara FBX Binary  \0\x1a\0", 23);
    uint8_t version[4];
    le32(version, 7400);
    put(&t, version, 4);
    for (size_t i = 0; i < (nest ? 5u : 4u); i++)
        put_record(&t, &top[i]);
    uint8_t zeros[176] = {0};
    put(&t, zeros, sizeof zeros); /* the list's end and a footer */
    save(&t, path);
    free(t.s);
    free(models), free(links), free(chain), free(model_props), free(link_props);
}

static void test_fbx_binary(void **state)
{
    (void)state;
    const char *path = file_in("test_import_hierarchy_fbxb", "chain.fbx");
    write_fbx_binary(path, LEVELS_ACCEPTED - 1, 0);
    loads(path);
    write_fbx_binary(path, LEVELS_ACCEPTED, 0);
    refused(path, "deeper than 256 levels");
    write_fbx_binary(path, 20000, 0);
    refused(path, "deeper than 256 levels");
    write_fbx_binary(path, 3, 40);
    loads(path);
    write_fbx_binary(path, 3, 100);
    refused(path, "nested deeper");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gltf_depth),    cmocka_unit_test(test_gltf1_depth),
        cmocka_unit_test(test_collada_depth), cmocka_unit_test(test_collada_instances),
        cmocka_unit_test(test_collada_data),
        cmocka_unit_test(test_fbx_ascii),     cmocka_unit_test(test_fbx_binary),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
