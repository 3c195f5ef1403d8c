/* IEEE 754-2008 binary32 -> binary16 conversion, rounding to nearest with
 * ties to even, subnormals included: the one conversion behind EXR half
 * channels and KTX RGBA16F levels. */
#include "internal.h"

#include <string.h>

uint16_t lx_float_to_half(float f)
{
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    uint16_t sign = (uint16_t)((x >> 16) & 0x8000u);
    uint32_t ax = x & 0x7fffffffu;
    if (ax > 0x7f800000u)
        return sign | 0x7e00u; /* NaN */
    if (ax >= 0x477ff000u)
        return sign | 0x7c00u; /* rounds beyond 65504: infinity */
    if (ax < 0x38800000u) {    /* below 2^-14: a subnormal half or zero */
        if (ax < 0x33000000u)  /* at most 2^-25: rounds to zero */
            return sign;
        uint32_t e = ax >> 23, m = (ax & 0x7fffffu) | 0x800000u;
        uint32_t shift = 126u - e; /* 14..24 */
        uint32_t q = m >> shift, rem = m & ((1u << shift) - 1u), halfway = 1u << (shift - 1u);
        if (rem > halfway || (rem == halfway && (q & 1u)))
            q++;
        return sign | (uint16_t)q;
    }
    /* normal: rebias the exponent (127 - 15 = 112), keep 10 mantissa bits;
     * a carry out of the mantissa bumps the exponent, as it should */
    uint32_t h = (ax - 0x38000000u) >> 13, rem = ax & 0x1fffu;
    if (rem > 0x1000u || (rem == 0x1000u && (h & 1u)))
        h++;
    return sign | (uint16_t)h;
}
