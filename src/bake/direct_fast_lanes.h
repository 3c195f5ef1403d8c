/* The body of the lean light loop (direct_fast.h), compiled once per
 * instruction set: the including file names the function
 * (LX_FAST_LIGHT_TILE) and is built with that set's flags (-mavx512f,
 * -mavx2 or none). Whole files, not target_clones: GCC 12's AVX-512 clone
 * compared the lanes one by one in scalar code. Everything here is static but the
 * one function, so no code built for a wider set reaches another file.
 * Without FMA contraction (-ffp-contract=off) the wider units compute the
 * same bits. */
#include "direct_fast.h"

#include <string.h>

#ifndef LX_FAST_LIGHT_TILE
#error "define LX_FAST_LIGHT_TILE before including direct_fast_lanes.h"
#endif

/* LANES lanes as one value (GCC/Clang vector extensions: the compiler splits
 * them into the target's SIMD registers). Selects are bitwise, so no lane
 * computes anything a scalar evaluation would not. */
#if defined(__GNUC__)
/* the helpers below are static inline: no ABI is crossed */
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
/* Lanes per vector: the width whose comparisons the build's instruction
 * set does in registers (GCC 12 splits wider arithmetic but compares
 * lanes one by one in scalar code). A packet's 16 lanes are 16 / LANES
 * vectors. */
#if defined(__AVX512F__)
#define LANES 16
#elif defined(__AVX__)
#define LANES 8
#else
#define LANES 4
#endif
typedef float vf __attribute__((vector_size(4 * LANES)));
typedef int32_t vi __attribute__((vector_size(4 * LANES)));

static inline __attribute__((always_inline)) vf vload(const float *p)
{
    vf v;
    memcpy(&v, p, sizeof v);
    return v;
}

static inline __attribute__((always_inline)) void vstore(float *p, vf v)
{
    memcpy(p, &v, sizeof v);
}

static inline __attribute__((always_inline)) vf vsplat(float x)
{
    return (vf){0} + x;
}

/* m ? a : b, lane by lane (m is 0 or -1) */
static inline __attribute__((always_inline)) vf vsel(vi m, vf a, vf b)
{
    return (vf)(((vi)a & m) | ((vi)b & ~m));
}

/* The lanes [base, base + LANES) of a tile for one fast light, lanes
 * [at, at + LANES) of its packet: ambient into t->acc, the unshadowed
 * illuminance into e, lit (lane mask) where it lights, and the shadow
 * rays into pk: lx_light_evaluate and lx_shadow_ray, operation for
 * operation. directional, classic and spot are constants in each caller,
 * so each kind of light gets its own code. */
static inline __attribute__((always_inline)) void
shade_lanes(const fast_light *f, tile_soa *t, uint32_t base, uint32_t at, lx_ray_packet *pk,
            float e[3][LX_RAY_PACKET], int32_t lit[LX_RAY_PACKET], bool directional, bool classic,
            bool spot)
{
    vf px = vload(t->px + base), py = vload(t->py + base), pz = vload(t->pz + base);
    vf one = vsplat(1.0f), zero = vsplat(0.0f);
    vf tx, ty, tz, dist = vsplat(INFINITY), window = one, d2 = one;
    vi ok;
    if (directional) {
        tx = vsplat(f->px), ty = vsplat(f->py), tz = vsplat(f->pz);
    } else {
        tx = f->px - px, ty = f->py - py, tz = f->pz - pz;
        d2 = tx * tx + ty * ty + tz * tz;
        float d2s[LANES], ds[LANES];
        vstore(d2s, d2);
        for (int j = 0; j < LANES; j++)
            ds[j] = sqrtf(d2s[j]);
        dist = vload(ds);
        /* lx_light_range_window */
        if (f->range > 0.0f) {
            vf factor = d2 / f->range_sq;
            vf smooth = 1.0f - factor * factor;
            window = vsel(smooth > 0.0f, smooth * smooth, zero);
        }
    }
    vstore(t->acc[0] + base, vload(t->acc[0] + base) + f->mr * window);
    vstore(t->acc[1] + base, vload(t->acc[1] + base) + f->mg * window);
    vstore(t->acc[2] + base, vload(t->acc[2] + base) + f->mb * window);
    vf lx = tx, ly = ty, lz = tz;
    if (!directional) {
        vf inv = 1.0f / dist;
        lx = tx * inv, ly = ty * inv, lz = tz * inv;
    }
    vf ndotl = vload(t->nx + base) * lx + vload(t->ny + base) * ly + vload(t->nz + base) * lz;
    ok = ndotl > 0.0f;
    if (!directional)
        ok &= dist > 0.0f;
    vf att = one;
    if (spot) {
        vf c = -(f->ax * lx + f->ay * ly + f->az * lz);
        if (f->spot_hard) {
            att = vsel(c >= f->cos_outer, one, zero);
        } else {
            vf u = c * f->spot_scale + f->spot_offset;
            u = vsel(u < 0.0f, zero, vsel(u > 1.0f, one, u));
            att = u * u;
        }
        ok &= att > 0.0f;
    }
    vf en;
    if (directional && classic) {
        en = ndotl * ndotl * f->intensity;
    } else if (directional) {
        en = f->intensity * ndotl;
    } else if (classic) {
        ok &= dist < f->range;
        vf v = (1.0f - dist / f->range) * ndotl;
        en = v * v * f->intensity * att;
    } else {
        vf dc = vsel(d2 > 1e-4f, d2, vsplat(1e-4f)); /* LX_MIN_DISTANCE_SQ */
        en = f->intensity * window * att * ndotl / dc;
    }
    ok &= en > 0.0f;
    vstore(e[0] + at, f->cr * en);
    vstore(e[1] + at, f->cg * en);
    vstore(e[2] + at, f->cb * en);
    memcpy(lit + at, &ok, sizeof ok);
    /* lx_shadow_ray: off the surface on the light's side */
    vf gx = vload(t->gx + base), gy = vload(t->gy + base), gz = vload(t->gz + base);
    vf bias = vload(t->bias + base);
    vi front = gx * lx + gy * ly + gz * lz >= 0.0f;
    vf ox = gx * bias, oy = gy * bias, oz = gz * bias;
    vf origin_x = vsel(front, px + ox, px - ox), origin_y = vsel(front, py + oy, py - oy),
         origin_z = vsel(front, pz + oz, pz - oz);
    if (t->lifted) { /* lx_lift_shadow_ray: behind the facet, from the smooth surface */
        origin_x = vsel(front, origin_x, origin_x + vload(t->lfx + base));
        origin_y = vsel(front, origin_y, origin_y + vload(t->lfy + base));
        origin_z = vsel(front, origin_z, origin_z + vload(t->lfz + base));
    }
    vstore(pk->origin_x + at, origin_x);
    vstore(pk->origin_y + at, origin_y);
    vstore(pk->origin_z + at, origin_z);
    vstore(pk->dir_x + at, lx);
    vstore(pk->dir_y + at, ly);
    vstore(pk->dir_z + at, lz);
    vstore(pk->tmin + at, zero);
    vf tmax = directional ? dist : dist - 2.0f * bias;
    vstore(pk->tmax + at, vsel(tmax < 0.0f, zero, tmax));
}

/* One fast light on a tile (direct_fast.h): lx_light_evaluate,
 * lx_shadow_ray and light_tile's sums, a packet of 16 lanes at a time. */
void LX_FAST_LIGHT_TILE(const lx_tracer *tracer, const fast_light *f, tile_soa *t, lx_sh4 *sh,
                        uint64_t *shadows, uint64_t key)
{
    lx_ray_packet pk;
    float e[3][LX_RAY_PACKET];
    int32_t lit[LX_RAY_PACKET];
    for (uint32_t base = 0; base < TILE_TEXELS; base += LX_RAY_PACKET) {
        uint32_t lanes = t->lanes[base / LX_RAY_PACKET];
        if (!lanes)
            continue;
        for (uint32_t at = 0; at < LX_RAY_PACKET; at += LANES) {
            if (f->directional)
                shade_lanes(f, t, base + at, at, &pk, e, lit, true, f->classic, false);
            else if (f->classic)
                shade_lanes(f, t, base + at, at, &pk, e, lit, false, true, f->spot);
            else if (f->spot)
                shade_lanes(f, t, base + at, at, &pk, e, lit, false, false, true);
            else
                shade_lanes(f, t, base + at, at, &pk, e, lit, false, false, false);
        }
        uint32_t active = 0;
        for (uint32_t j = 0; j < LX_RAY_PACKET; j++)
            active |= (uint32_t)(lit[j] != 0) << j;
        active &= lanes;
        if (!active)
            continue;
        uint32_t blocked = f->shadowed ? lx_tracer_occluded_packet(tracer, &pk, active) : 0;
        uint32_t add = active & ~blocked;
        for (uint32_t j = 0; shadows && j < LX_RAY_PACKET; j++)
            if ((active & blocked) >> j & 1u)
                shadows[t->texel[base + j]] |= key;
        int32_t on[LX_RAY_PACKET];
        for (int j = 0; j < LX_RAY_PACKET; j++)
            on[j] = (add >> j) & 1u ? -1 : 0;
        for (uint32_t at = 0; at < LX_RAY_PACKET; at += LANES) {
            vi m;
            memcpy(&m, on + at, sizeof m);
            for (int c = 0; c < 3; c++) {
                vf a = vload(t->acc[c] + base + at);
                vstore(t->acc[c] + base + at, vsel(m, a + vload(e[c] + at), a));
            }
        }
        if (!sh)
            continue;
        /* the directions: scalar, lane by lane (a directional bake only) */
        for (uint32_t j = 0; j < LX_RAY_PACKET; j++) {
            if (!((add >> j) & 1u))
                continue;
            uint32_t k = base + j;
            lx_vec3 d = lx_v3(pk.dir_x[j], pk.dir_y[j], pk.dir_z[j]);
            lx_vec3 n = lx_v3(t->nx[k], t->ny[k], t->nz[k]);
            lx_sh4_add_lit(&sh[t->texel[k]], lx_v3(e[0][j], e[1][j], e[2][j]), n, d);
        }
    }
}
