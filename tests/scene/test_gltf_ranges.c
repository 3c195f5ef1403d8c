/* Byte ranges checked before import (src/scene/gltf_ranges.c): a glTF
 * file written here - one triangle, its positions in tri.bin - with an
 * accessor or a bufferView made to run past what holds it must fail with
 * a message naming it and the overrun, worked out here from the sizes. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "helpers.h"

/* Writes dir/tri.gltf with the given accessor count and offset, view
 * length, and buffer length (tri.bin holds 36 bytes: three VEC3 floats). */
static const char *write_tri(const char *dir, int count, int acc_offset, int view_len,
                             int buf_len)
{
    static char path[1200];
    char bin[1200];
    snprintf(bin, sizeof bin, "%s/tri.bin", dir);
    FILE *f = fopen(bin, "wb");
    assert_non_null(f);
    const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    assert_int_equal(fwrite(p, sizeof p, 1, f), 1);
    fclose(f);
    snprintf(path, sizeof path, "%s/tri.gltf", dir);
    f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f,
            "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
            "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"primitives\":[{\"attributes\":"
            "{\"POSITION\":0}}]}],\"accessors\":[{\"bufferView\":0,\"byteOffset\":%d,"
            "\"componentType\":5126,\"count\":%d,\"type\":\"VEC3\",\"min\":[0,0,0],"
            "\"max\":[1,1,0]}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":%d}],"
            "\"buffers\":[{\"uri\":\"tri.bin\",\"byteLength\":%d}]}",
            acc_offset, count, view_len, buf_len);
    fclose(f);
    return path;
}

static void test_ranges(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gltf_ranges");
    lx_scene *s = NULL;
    /* well formed: loads */
    assert_int_equal(lx_scene_load(write_tri(dir, 3, 0, 36, 36), NULL, &s), LX_OK);
    lx_scene_destroy(s);
    s = NULL;
    /* 79 elements of 12 bytes: 948 bytes, 912 past the view's 36 */
    assert_int_equal(lx_scene_load(write_tri(dir, 79, 0, 36, 36), NULL, &s), LX_ERR_FORMAT);
    assert_null(s);
    assert_non_null(strstr(lx_last_error(), "tri.gltf: accessor 0: 912 bytes past the end of "
                                            "bufferView 0"));
    /* an offset of 4: 3 elements end at byte 40 */
    assert_int_equal(lx_scene_load(write_tri(dir, 3, 4, 36, 36), NULL, &s), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "accessor 0: 4 bytes past the end of bufferView 0"));
    /* a view of 48 bytes in a buffer of 36 */
    assert_int_equal(lx_scene_load(write_tri(dir, 3, 0, 48, 36), NULL, &s), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "bufferView 0: 12 bytes past the end of buffer 0"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_ranges)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
