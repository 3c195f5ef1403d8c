/* luxel/luxel.h - the whole public API of libluxel, a lighting toolkit:
 * core (errors, images), scene import, the physical light model, ray
 * queries, texture-space maps, lightmap UV generation and the per-texel
 * lightmap baker, 2D shadowed lights.
 * Each header documents its units, errors, memory and threading rules. */
#ifndef LUXEL_H
#define LUXEL_H

#include "luxel/core.h"
#include "luxel/math.h"
#include "luxel/light.h"
#include "luxel/scene.h"
#include "luxel/trace.h"
#include "luxel/maps.h"
#include "luxel/bake.h"
#include "luxel/denoise.h"
#include "luxel/ibl.h"
#include "luxel/unwrap.h"
#include "luxel/render.h"
#include "luxel/light2d.h"

#endif
