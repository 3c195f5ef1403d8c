/* libFuzzer harness for luxel's own environment code (src/ibl/envmap.c):
 * an image decoded from the input after its first byte (PFM or Radiance
 * HDR, picked by that byte with the options) goes through layout
 * detection, the equirect and cross conversions and the texel checks of
 * lx_env_from_image, at a small cube size so each run stays fast. The
 * decoders themselves are fuzzed by fuzz_image.c.
 *
 *   make fuzz   (or: clang -fsanitize=fuzzer,address ... ; ./fuzz_env corpus/) */
#include "luxel/ibl.h"

#include <stddef.h>
#include <stdint.h>

const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "allocator_may_return_null=1:max_allocation_size_mb=1024";
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2)
        return 0;
    /* the first byte picks the decoder and the options; the rest is the file */
    const char *name = data[0] & 1 ? "f.hdr" : "f.pfm";
    lx_image img;
    if (lx_image_load_memory(data + 1, size - 1, name, NULL, &img) != LX_OK)
        return 0;
    /* layout from the shape, or forced; a small size bounds the work */
    lx_env_load_desc d = {.layout = (lx_env_layout)(data[0] >> 1) % 3,
                          .size = 1 + (data[0] >> 4),
                          .intensity = data[0] & 2 ? 1e30f : 0.0f};
    lx_cubemap c;
    if (lx_env_from_image(&img, name, &d, &c) == LX_OK)
        lx_cubemap_free(&c);
    lx_image_free(&img);
    return 0;
}
