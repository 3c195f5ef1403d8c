/* Scene files written by tests and a fingerprint of what lx_scene_load
 * made of one, for tests that compare loads (threads, locking paths). */
#ifndef LX_TEST_SCENE_FILES_H
#define LX_TEST_SCENE_FILES_H

#include "luxel/scene.h"

#include <stdint.h>

/* An n x n grid of quads as an OBJ object `name`: positions with a little
 * relief (so generated normals vary), texture coordinates, no normals
 * (assimp generates them). assimp reads it as 6 n^2 vertices and 2 n^2
 * triangles. */
void lx_test_write_obj_grid(const char *path, const char *name, int n);

/* A 64-bit hash (FNV-1a) of every byte of the scene luxel built: meshes
 * (names, counts, positions, normals, tangents, UV sets, indices,
 * materials), nodes (names, transforms, meshes) and material names. */
uint64_t lx_test_scene_digest(const lx_scene *s);

#endif
