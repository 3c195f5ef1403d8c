/* libFuzzer harness for the IES LM-63 reader (lx_ies_parse). Every input
 * must end in LX_OK or a clean error with a message naming the file, never
 * a crash, leak or hang; a profile that parses must give finite, non-
 * negative candela everywhere and a finite flux. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "luxel/light.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lx_ies_profile *p = NULL;
    if (lx_ies_parse((const char *)data, size, "fuzz.ies", &p) != LX_OK) {
        if (p || strncmp(lx_last_error(), "fuzz.ies", 8) != 0)
            __builtin_trap(); /* a failure must leave no profile and name the file */
        return 0;
    }
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    for (int i = 0; i < info.keyword_count; i++)
        if (!lx_ies_keyword(p, i, NULL))
            __builtin_trap();
    static const float angles[] = {-400, -90, 0, 0.5f, 45, 89.99f, 90, 135, 180, 270, 359.9f, 721};
    const size_t n = sizeof angles / sizeof angles[0];
    for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < n; j++) {
            float c = lx_ies_candela(p, angles[i], angles[j]);
            if (!(c >= 0.0f) || !isfinite(c) || c > lx_ies_peak_candela(p) * 1.0001f + 1e-30f)
                __builtin_trap();
        }
    /* the flux walks 1.3 million directions: only for small tables */
    if (info.vertical_count * info.horizontal_count < 64) {
        double lm = lx_ies_total_lumens(p);
        if (!(lm >= 0.0) || !isfinite(lm))
            __builtin_trap();
    }
    lx_ies_free(p);
    return 0;
}
