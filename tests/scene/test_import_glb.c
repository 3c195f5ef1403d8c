/* The GLB container is checked before assimp sees the file: a chunk length
 * beyond the file (found by fuzzing: assimp then allocated 3 GB) and a
 * header length beyond the file fail with a message, quickly. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <stdio.h>
#include <string.h>

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v, p[1] = (uint8_t)(v >> 8), p[2] = (uint8_t)(v >> 16),
    p[3] = (uint8_t)(v >> 24);
}

/* A GLB of one JSON chunk "{}" padded to 4 bytes, with header and chunk
 * lengths as given. */
static const char *write_glb(const char *name, uint32_t header_length, uint32_t chunk_length)
{
    static char path[1024];
    snprintf(path, sizeof path, "%s/%s", lx_test_dir("test_import_glb"), name);
    uint8_t b[24];
    put32(b, 0x46546C67u); /* "glTF" */
    put32(b + 4, 2);
    put32(b + 8, header_length);
    put32(b + 12, chunk_length);
    put32(b + 16, 0x4E4F534Au); /* "JSON" */
    memcpy(b + 20, "{}  ", 4);
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(b, 1, sizeof b, fp), sizeof b);
    fclose(fp);
    return path;
}

static void forged_chunk_length(void **state)
{
    (void)state;
    lx_scene *scene = NULL;
    const char *path = write_glb("chunk.glb", 24, 3019904304u);
    assert_int_equal(lx_scene_load(path, NULL, &scene), LX_ERR_FORMAT);
    assert_null(scene);
    assert_non_null(strstr(lx_last_error(), "chunk.glb"));
    assert_non_null(strstr(lx_last_error(), "runs past the end"));
}

static void forged_header_length(void **state)
{
    (void)state;
    lx_scene *scene = NULL;
    const char *path = write_glb("header.glb", 1u << 30, 4);
    assert_int_equal(lx_scene_load(path, NULL, &scene), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "header.glb"));
    assert_non_null(strstr(lx_last_error(), "truncated GLB"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(forged_chunk_length),
        cmocka_unit_test(forged_header_length),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
