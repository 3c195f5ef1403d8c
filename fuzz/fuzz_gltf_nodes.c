/* libFuzzer harness for the glTF node hierarchy: the bytes do not become
 * the file, they drive the graph of a well-formed glTF document (one
 * triangle mesh in a data: URI) written to a .gltf and loaded through
 * lx_scene_load, so every run reaches the hierarchy code in luxel and
 * assimp instead of dying in the JSON parser. The input picks
 *   byte 0      the number of free nodes (1..32)
 *   bytes 1-2   the length of a chain hung below them (capped, see below)
 *   byte 3      flags: scenes array, where the chain hangs, which nodes
 *               have the mesh, matrix or TRS, a chain closed into a loop
 *   byte 4      the node the chain hangs from
 *   then pairs  (parent, child) edges added to "children": duplicates,
 *               self-loops, cycles, two parents and (a child byte of 126
 *               '~' or more) an index out of range all come from here.
 * The seeds in fuzz/corpus/gltf_nodes/ are printable text for that reason.
 * Every input must end in LX_OK or a clean error, never a crash or leak. */
#define _POSIX_C_SOURCE 200809L
#include "luxel/scene.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Deepest hierarchy the harness generates (free nodes plus chain): past
 * the 256 levels lx_scene_load accepts, so the up-front check
 * (scene/import_checks.c) is what stops deep inputs before assimp, yet
 * small enough to keep many runs a second (30,000 gave 3). */
#define FUZZ_MAX_DEPTH 1000

#define FREE_NODES_MAX 32

enum {
    FLAG_SCENES = 1,      /* a "scenes" array listing the free nodes as roots */
    FLAG_CHAIN_HUNG = 2,  /* the chain hangs below a free node, else it is a root */
    FLAG_MESH_ALL = 4,    /* every node has the mesh, else every other one */
    FLAG_MATRIX = 8,      /* "matrix" transforms, else translation/rotation/scale */
    FLAG_CHAIN_LOOP = 16, /* the chain's last node lists its first as a child */
    FLAG_ZERO_SCALE = 32, /* a degenerate scale on the chain's nodes */
};

/* One triangle: 3 float positions, base64 in a data: URI. */
static char *triangle_uri(void)
{
    static const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 0, 1};
    static const char b64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const unsigned char *in = (const unsigned char *)positions;
    size_t n = sizeof positions; /* 36, a multiple of 3: no padding */
    static const char prefix[] = "data:application/octet-stream;base64,";
    char *uri = malloc(sizeof prefix + n / 3 * 4);
    if (!uri)
        return NULL;
    char *o = uri + sizeof prefix - 1;
    memcpy(uri, prefix, sizeof prefix - 1);
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = (unsigned)in[i] << 16 | (unsigned)in[i + 1] << 8 | in[i + 2];
        *o++ = b64[v >> 18 & 63];
        *o++ = b64[v >> 12 & 63];
        *o++ = b64[v >> 6 & 63];
        *o++ = b64[v & 63];
    }
    *o = '\0';
    return uri;
}

static void add_mesh_and_buffers(cJSON *root)
{
    char *uri = triangle_uri();
    cJSON *buffer = cJSON_CreateObject();
    cJSON_AddNumberToObject(buffer, "byteLength", 36);
    cJSON_AddStringToObject(buffer, "uri", uri ? uri : "");
    free(uri);
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "buffers"), buffer);
    cJSON *view = cJSON_CreateObject();
    cJSON_AddNumberToObject(view, "buffer", 0);
    cJSON_AddNumberToObject(view, "byteLength", 36);
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "bufferViews"), view);
    cJSON *acc = cJSON_CreateObject();
    cJSON_AddNumberToObject(acc, "bufferView", 0);
    cJSON_AddNumberToObject(acc, "componentType", 5126);
    cJSON_AddNumberToObject(acc, "count", 3);
    cJSON_AddStringToObject(acc, "type", "VEC3");
    const double lo[3] = {0, 0, 0}, hi[3] = {1, 0, 1};
    cJSON_AddItemToObject(acc, "min", cJSON_CreateDoubleArray(lo, 3));
    cJSON_AddItemToObject(acc, "max", cJSON_CreateDoubleArray(hi, 3));
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "accessors"), acc);
    cJSON *prim = cJSON_CreateObject();
    cJSON_AddNumberToObject(cJSON_AddObjectToObject(prim, "attributes"), "POSITION", 0);
    cJSON *mesh = cJSON_CreateObject();
    cJSON_AddStringToObject(mesh, "name", "triangle");
    cJSON_AddItemToArray(cJSON_AddArrayToObject(mesh, "primitives"), prim);
    cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "meshes"), mesh);
}

static cJSON *make_node(int index, unsigned flags, bool in_chain)
{
    cJSON *node = cJSON_CreateObject();
    char name[32];
    snprintf(name, sizeof name, "n%d", index);
    cJSON_AddStringToObject(node, "name", name);
    if ((flags & FLAG_MESH_ALL) || index % 2 == 0)
        cJSON_AddNumberToObject(node, "mesh", 0);
    float s = in_chain && (flags & FLAG_ZERO_SCALE) ? 0.0f : 1.0f;
    if (flags & FLAG_MATRIX) {
        const double m[16] = {s, 0, 0, 0, 0, s, 0, 0, 0, 0, s, 0, 0.5, 0.25, 0, 1};
        cJSON_AddItemToObject(node, "matrix", cJSON_CreateDoubleArray(m, 16));
    } else {
        const double t[3] = {0.5, 0.25, 0}, r[4] = {0, 0.38268343, 0, 0.92387953},
                     sc[3] = {s, s, s};
        cJSON_AddItemToObject(node, "translation", cJSON_CreateDoubleArray(t, 3));
        cJSON_AddItemToObject(node, "rotation", cJSON_CreateDoubleArray(r, 4));
        cJSON_AddItemToObject(node, "scale", cJSON_CreateDoubleArray(sc, 3));
    }
    return node;
}

static void add_child(cJSON *node, int child)
{
    cJSON *children = cJSON_GetObjectItemCaseSensitive(node, "children");
    if (!children)
        children = cJSON_AddArrayToObject(node, "children");
    cJSON_AddItemToArray(children, cJSON_CreateNumber(child));
}

/* The glTF text the input describes (see the top of the file). */
static char *build_document(const uint8_t *data, size_t size)
{
    int free_nodes = 1 + data[0] % FREE_NODES_MAX;
    int chain = (data[1] | data[2] << 8) % (FUZZ_MAX_DEPTH - free_nodes + 1);
    unsigned flags = data[3];
    int hang_from = data[4] % free_nodes;
    int total = free_nodes + chain;

    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(cJSON_AddObjectToObject(root, "asset"), "version", "2.0");
    add_mesh_and_buffers(root);
    cJSON *nodes = cJSON_AddArrayToObject(root, "nodes");
    cJSON **node = malloc(sizeof *node * (size_t)total);
    if (!node) {
        cJSON_Delete(root);
        return NULL;
    }
    for (int i = 0; i < total; i++) {
        node[i] = make_node(i, flags, i >= free_nodes);
        cJSON_AddItemToArray(nodes, node[i]);
    }
    for (int i = free_nodes; i + 1 < total; i++)
        add_child(node[i], i + 1);
    if (chain > 0 && (flags & FLAG_CHAIN_HUNG))
        add_child(node[hang_from], free_nodes);
    if (chain > 0 && (flags & FLAG_CHAIN_LOOP))
        add_child(node[total - 1], free_nodes);
    for (size_t k = 5; k + 1 < size; k += 2) {
        int parent = data[k] % total;
        int child = data[k + 1] >= '~' ? total + data[k] : data[k + 1] % total;
        add_child(node[parent], child);
    }
    if (flags & FLAG_SCENES) {
        cJSON *roots = cJSON_CreateArray();
        for (int i = 0; i < free_nodes; i++)
            cJSON_AddItemToArray(roots, cJSON_CreateNumber(i));
        if (chain > 0 && !(flags & FLAG_CHAIN_HUNG))
            cJSON_AddItemToArray(roots, cJSON_CreateNumber(free_nodes));
        cJSON *scene = cJSON_CreateObject();
        cJSON_AddItemToObject(scene, "nodes", roots);
        cJSON_AddItemToArray(cJSON_AddArrayToObject(root, "scenes"), scene);
        cJSON_AddNumberToObject(root, "scene", 0);
    }
    free(node);
    char *text = cJSON_PrintUnformatted(root);
    cJSON_Delete(root);
    return text;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 5)
        return 0;
    char *text = build_document(data, size);
    if (!text)
        return 0;
    char path[64];
    snprintf(path, sizeof path, "/tmp/lx_fuzz_nodes_%d.gltf", (int)getpid());
    FILE *fp = fopen(path, "wb");
    if (fp) {
        fputs(text, fp);
        fclose(fp);
        lx_scene *scene = NULL;
        if (lx_scene_load(path, NULL, &scene) == LX_OK)
            lx_scene_destroy(scene);
        unlink(path);
    }
    free(text);
    return 0;
}
