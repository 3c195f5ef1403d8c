/* libFuzzer harness for scene import: the bytes become a .glb, .gltf,
 * .obj, .dae, .fbx, .ply or .stl file (chosen by the first byte) loaded
 * through lx_scene_load, which runs assimp plus luxel's own validation,
 * its glTF rewrite (meshopt, quantization), KHR_lights_punctual and camera
 * readers (fuzz/corpus/scene/cameras.gltf seeds the cameras), and the
 * hierarchy checks made before assimp (collada_instances.txt and
 * fbx_ascii_chain.txt: their first byte, 'B' and 'C', picks .dae and
 * .fbx). */
#define _POSIX_C_SOURCE 200809L
#include "luxel/scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1)
        return 0;
    static const char *ext[] = {".glb", ".gltf", ".obj", ".dae", ".fbx", ".ply", ".stl"};
    char path[64];
    snprintf(path, sizeof path, "/tmp/lx_fuzz_scene_%d%s", (int)getpid(), ext[data[0] % 7]);
    FILE *fp = fopen(path, "wb");
    if (!fp)
        return 0;
    fwrite(data + 1, 1, size - 1, fp);
    fclose(fp);
    lx_scene *scene = NULL;
    lx_scene_load_desc desc = {.strict = (data[0] & 4) != 0};
    if (lx_scene_load(path, &desc, &scene) == LX_OK)
        lx_scene_destroy(scene);
    unlink(path);
    return 0;
}
