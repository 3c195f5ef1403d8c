/* Checks made on a scene file before assimp reads it (import_checks.c).
 * Private to scene. */
#ifndef LX_SCENE_IMPORT_CHECKS_H
#define LX_SCENE_IMPORT_CHECKS_H

#include "luxel/core.h"

#include <cjson/cJSON.h>

/* Refuses a node hierarchy that assimp's recursive readers could not
 * walk: deeper than NODE_DEPTH_MAX levels, cyclic, or expanding past a
 * million nodes through instances (glTF from its JSON, gltf; Collada and
 * FBX from the file at path; other formats have none). */
lx_status import_check_hierarchy(const char *path, const cJSON *gltf);

#endif
