/* libFuzzer harness for lx_scene_write_glb: the bytes become a .glb, .gltf
 * or .obj file (chosen by the first byte); a scene that loads is written
 * again with UVs for every mesh of every node (each vertex its own UV
 * vertex), which re-reads the file's JSON, buffers, data: URIs, accessors
 * (sparse ones too) and images through the writer's own code. */
#define _POSIX_C_SOURCE 200809L
#include "luxel/scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    static const char *ext[] = {".glb", ".gltf", ".obj"};
    char path[64], out[64];
    snprintf(path, sizeof path, "/tmp/lx_fuzz_write_%d%s", (int)getpid(), ext[data[0] % 3]);
    snprintf(out, sizeof out, "/tmp/lx_fuzz_write_%d_out.glb", (int)getpid());
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return 0;
    fwrite(data + 1, 1, size - 1, fp);
    fclose(fp);
    lx_scene *scene = NULL;
    lx_scene_load_desc desc = {.strict = (data[0] & 4) != 0};
    if (lx_scene_load(path, &desc, &scene) == LX_OK) {
        uint32_t n = 0;
        for (uint32_t i = 0; i < scene->node_count; i++)
            n += scene->nodes[i].mesh_count;
        lx_scene_uvs *uvs = calloc(n ? n : 1, sizeof *uvs);
        uint32_t **src = calloc(n ? n : 1, sizeof *src);
        lx_vec2 **uv = calloc(n ? n : 1, sizeof *uv);
        uint32_t k = 0;
        for (uint32_t i = 0; uvs && src && uv && i < scene->node_count; i++)
            for (uint32_t j = 0; j < scene->nodes[i].mesh_count; j++, k++) {
                const lx_mesh *m = &scene->meshes[scene->nodes[i].meshes[j]];
                src[k] = malloc(sizeof(uint32_t) * (m->vertex_count + 1));
                uv[k] = calloc(m->vertex_count + 1, sizeof(lx_vec2));
                for (uint32_t v = 0; src[k] && v < m->vertex_count; v++)
                    src[k][v] = v;
                uvs[k] = (lx_scene_uvs){.node = i,
                                        .mesh = scene->nodes[i].meshes[j],
                                        .vertex_count = m->vertex_count,
                                        .vertex_source = src[k],
                                        .uv = uv[k],
                                        .indices = m->indices};
            }
        lx_glb_write_desc d = {.uvs = uvs, .uv_count = k};
        lx_scene_write_glb(scene, out, &d);
        for (uint32_t i = 0; i < k; i++) {
            free(src[i]);
            free(uv[i]);
        }
        free(src);
        free(uv);
        free(uvs);
        lx_scene_destroy(scene);
        unlink(out);
    }
    unlink(path);
    return 0;
}
