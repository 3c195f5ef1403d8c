/* libFuzzer harness for luxel's own JSON readers: the lights JSON
 * (lx_lights_json_apply_text, its "nodes" over two nodes) and glTF KHR_lights_punctual / GLB container
 * parsing (lx_gltf_lights_load_memory). Every input must end in LX_OK or a
 * clean error, never a crash, leak or hang. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "luxel/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lx_scene *scene;
    if (lx_scene_create("fuzz", &scene) != LX_OK)
        return 0;
    /* A named light first, so overrides by name are exercised too. */
    lx_light key = lx_light_defaults(LX_LIGHT_SPOT);
    strcpy(key.name, "key");
    lx_scene_add_light(scene, &key);
    /* and nodes, so the "nodes" section's names and globs meet some */
    lx_vec3 pos[3] = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}};
    uint32_t idx[3] = {0, 1, 2}, mesh;
    lx_mesh tri = {.name = "tri", .vertex_count = 3, .triangle_count = 1, .positions = pos,
                   .indices = idx, .source_mesh = -1, .source_primitive = -1};
    lx_mat4 world = lx_mat4_identity();
    if (lx_scene_add_mesh(scene, &tri, &mesh) == LX_OK) {
        lx_scene_add_node(scene, "Wall_1", &world, &mesh, 1, NULL);
        lx_scene_add_node(scene, "Sky[1]", &world, &mesh, 1, NULL);
    }
    lx_lights_json_apply_text(scene, (const char *)data, size, "fuzz.json");
    for (uint32_t i = 0; i < scene->node_count; i++)
        if (!(lx_node_lightmap_scale(&scene->nodes[i].bake) > 0.0f))
            __builtin_trap(); /* the reader let a bad scale through */
    for (uint32_t i = 0; i < scene->light_count; i++)
        if (lx_light_validate(&scene->lights[i]) != LX_OK)
            __builtin_trap(); /* the reader let an invalid light through */
    lx_gltf_lights_load_memory(scene, data, size, "fuzz.gltf");
    for (uint32_t i = 0; i < scene->light_count; i++)
        if (lx_light_validate(&scene->lights[i]) != LX_OK)
            __builtin_trap();
    lx_scene_destroy(scene);
    return 0;
}
