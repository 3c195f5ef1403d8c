/* Shared by light.c and units.c (private to src/light). */
#ifndef LX_LIGHT_INTERNAL_H
#define LX_LIGHT_INTERNAL_H

#include "luxel/light.h"

/* LX_ERR_INVALID naming the light and the field when a size (radius,
 * length, width, height) is beyond LX_LIGHT_MAX_DISTANCE: checked before a
 * power is spread over the light's area, so an absurd size is named as
 * such, not as the zero luminance it would give. */
lx_status light_check_sizes(const lx_light *light);

#endif
