/* libFuzzer harness for luxel's own JSON readers: the lights JSON
 * (lx_lights_json_apply_text) and glTF KHR_lights_punctual / GLB container
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
    lx_lights_json_apply_text(scene, (const char *)data, size, "fuzz.json");
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
