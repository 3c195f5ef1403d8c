/* libFuzzer harness for the image loaders (lx_image_load_memory): PNG,
 * Radiance HDR, PFM, OpenEXR, TGA and JPEG, picked by the first byte so one
 * corpus reaches every decoder. Crashes found here become tests in
 * tests/core/test_image.c.
 *
 *   make fuzz   (or: clang -fsanitize=fuzzer,address ... ; ./fuzz_image corpus/) */
#include "luxel/core.h"

#include <stddef.h>
#include <stdint.h>

/* A header may claim any size; such requests are meant to fail cleanly
 * (LX_ERR_NOMEM), so let ASan return NULL for them instead of reporting
 * libFuzzer's malloc limit as a crash. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1:max_allocation_size_mb=1024";
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const names[] = {"f.png", "f.hdr", "f.pfm", "f.exr", "f.tga", "f.jpg"};
    if (size < 1)
        return 0;
    /* The name only matters when the content has no signature (TGA) or to
     * exercise the "not a PNG file" paths; the first byte chooses it and
     * still belongs to the file, so signatures stay reachable. */
    const char *name = names[data[0] % (sizeof names / sizeof names[0])];
    lx_image_load_desc desc = {.channels = (int)(size % 5), .raw_8bit = (size & 8) != 0};
    lx_image img;
    if (lx_image_load_memory(data, size, name, &desc, &img) == LX_OK)
        lx_image_free(&img);
    return 0;
}
