/* luxel/ibl.h - image-based lighting: environments as cube maps, diffuse
 * irradiance (brute force and order-2 spherical harmonics), prefiltered
 * specular environments (GGX with a mip chain, Phong lobes), the split-sum
 * DFG lookup table, seam handling, and the layouts engines read (faces,
 * cross, equirect, KTX 1.1) in and out.
 *
 * CONVENTIONS  +Y up, right-handed (glTF). Environment values are radiance
 *   in nits; irradiance outputs are in lux. An equirect pixel centre (u, v)
 *   in [0,1]^2 looks along d = (sin t sin p, cos t, -sin t cos p) with
 *   p = 2 pi (u - 0.5), t = pi v: row 0 looks up, the centre column looks
 *   down -Z. Cube faces are in the OpenGL/KTX order +X, -X, +Y, -Y, +Z, -Z
 *   and orientation: face texel (x, y), row 0 first, has the face
 *   coordinates s = (x + 0.5) / size, t = (y + 0.5) / size, and with
 *   sc = 2s - 1, tc = 2t - 1 looks along
 *     +X (1, -tc, -sc)   -X (-1, -tc, sc)   +Y (sc, 1, tc)
 *     -Y (sc, -1, -tc)   +Z (sc, -tc, 1)    -Z (-sc, -tc, -1)
 *   (the OpenGL specification's table read backwards). docs/ibl.md states
 *   them with pictures.
 * ERRORS  Every function that can fail returns lx_status and sets a message
 *   naming the file and the problem (non-2:1 equirect, unequal faces, NaN
 *   or negative texels with their count...). On failure or cancellation
 *   outputs are zeroed and no file is left behind.
 * MEMORY  lx_cubemap_alloc and every function filling an lx_cubemap or
 *   lx_image allocate; lx_cubemap_free / lx_image_free release. Each call
 *   that allocates a lot (loading, resampling, lx_prefilter, lx_env_write)
 *   first adds up its whole peak - its input, every buffer it will hold at
 *   once, its outputs - and fails with LX_ERR_NOMEM naming the GiB when
 *   that is more than the machine has, before allocating any of it.
 *   lx_prefilter_check and lx_env_write_check run the same test on sizes
 *   alone, to check a whole run before its environment is made. Making
 *   faces more than 4x finer than a source's own detail (an upsampled
 *   environment, specular level 0, an equirect) logs an LX_LOG_WARN naming
 *   the memory it takes.
 * THREADING  Every long call takes threads, a progress callback and its
 *   user pointer: lx_ibl_desc (threads 0 = all cores), or the call's own
 *   desc with the same three fields (lx_env_load_desc, lx_env_write_desc,
 *   lx_prefilter_desc). OpenMP runs at most that many threads; the
 *   callback is called from one thread at a time, a few times a second,
 *   and returning false cancels (LX_ERR_CANCELLED, outputs zeroed, no
 *   file written). Results are bit-identical for any thread count: every
 *   texel is computed alone, sums run in a fixed order, GGX samples come
 *   from one fixed Hammersley set. All functions are thread-safe on
 *   distinct outputs: they keep no state between calls and only read their
 *   inputs (lx_cubemap_fix_seams writes the cube map it is given, so one
 *   call per cube map at a time); lx_set_log_callback's callback hears the
 *   warnings from any thread.
 *
 * USAGE
 *   lx_cubemap env, irr, spec[LX_MAX_CUBE_MIPS];
 *   lx_sh9 sh;
 *   int levels;
 *   if (lx_env_load("sky.hdr", NULL, &env) != LX_OK)
 *       return 1;
 *   if (lx_sh_project(&env, NULL, &sh) != LX_OK ||
 *       lx_sh_irradiance_cube(&sh, 32, NULL, &irr) != LX_OK) {
 *       lx_cubemap_free(&env);
 *       return 1;
 *   }
 *   lx_prefilter_desc pd = {.filter = LX_SPECULAR_GGX, .size = 64};
 *   lx_status st = lx_prefilter(&env, &pd, spec, &levels);
 *   lx_env_write_desc wd = {.layout = LX_ENV_KTX};
 *   if (st == LX_OK)
 *       st = lx_env_write(".", "specular", spec, levels, &wd);
 *   printf("irradiance facing up: %g lux (%s)\n",
 *          lx_cubemap_texel(&irr, LX_FACE_PY, 16, 16)[1], lx_status_name(st));
 *   for (int i = 0; i < LX_MAX_CUBE_MIPS; i++) // zeroed if it failed
 *       lx_cubemap_free(&spec[i]);
 *   lx_cubemap_free(&irr);
 *   lx_cubemap_free(&env);
 *   if (st != LX_OK)
 *       return 1;
 */
#ifndef LUXEL_IBL_H
#define LUXEL_IBL_H

#include "luxel/core.h"
#include "luxel/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- cube map geometry ----------------------------------------------- */

typedef enum lx_cube_face {
    LX_FACE_PX = 0,
    LX_FACE_NX,
    LX_FACE_PY,
    LX_FACE_NY,
    LX_FACE_PZ,
    LX_FACE_NZ
} lx_cube_face;

#define LX_MAX_CUBE_SIZE 16384
#define LX_MAX_CUBE_MIPS 15

/* "px", "nx", "py", "ny", "pz", "nz". */
const char *lx_cube_face_name(int face);

/* The unit direction through face coordinates (s, t) in [0,1]^2. */
lx_vec3 lx_cube_direction(int face, float s, float t);
/* The face a direction (not necessarily unit, not zero) leaves the cube
 * through and its face coordinates (s, t) in [0,1]^2. Ties go to X, then Y. */
void lx_cube_face_coords(lx_vec3 dir, int *face, float *s, float *t);
/* The texel (*face, *x, *y) of a size x size face map that a direction (not
 * zero) falls in: the face lx_cube_face_coords picks, x = floor(s size)
 * kept inside the face. */
void lx_cube_texel_at(lx_vec3 dir, int size, int *face, int *x, int *y);
/* The exact solid angle (steradians) of texel (x, y) on a face of size
 * texels per side; the 6*size^2 texels sum to 4 pi. */
double lx_cube_texel_solid_angle(int size, int x, int y);

/* The unit direction of equirect coordinates (u, v) in [0,1]^2 and back. */
lx_vec3 lx_equirect_direction(float u, float v);
void lx_equirect_coords(lx_vec3 dir, float *u, float *v);

/* Levels of a full mip chain from a face of size texels down to 1x1 (each
 * level half the one before, rounded down): 1 + floor(log2(size)). */
int lx_cube_mip_count(int size);

/* ---- threads and progress --------------------------------------------- */

/* What every long call without options of its own takes. desc may be NULL
 * (all cores, no progress). */
typedef struct lx_ibl_desc {
    int threads;             /* at most this many threads, 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_ibl_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_ibl_desc lx_ibl_desc_defaults(const lx_ibl_desc *desc);

/* ---- cube maps ------------------------------------------------------- */

/* Six square RGB faces, each size*size*3 floats, face-major in the order of
 * lx_cube_face, rows top to bottom. */
typedef struct lx_cubemap {
    int size;
    float *data; /* 6 * size * size * 3 floats */
} lx_cubemap;

/* Allocates a zeroed cube map; checks size (1..LX_MAX_CUBE_SIZE) and memory. */
lx_status lx_cubemap_alloc(lx_cubemap *c, int size);
void lx_cubemap_free(lx_cubemap *c);

/* The 3 floats of texel (x, y) on a face. */
static inline float *lx_cubemap_texel(const lx_cubemap *c, int face, int x, int y)
{
    return c->data +
           (((size_t)face * (size_t)c->size + (size_t)y) * (size_t)c->size + (size_t)x) * 3;
}

/* A face as an image that borrows the cube map's memory (do not free). */
lx_image lx_cubemap_face_image(const lx_cubemap *c, int face);

/* Bilinear sample along dir (any length but zero); taps that fall off a
 * face are taken from the neighbouring face, so filtering has no seams. */
void lx_cubemap_sample(const lx_cubemap *c, lx_vec3 dir, float out[3]);

/* A smaller cube map of size texels a side (1..src->size; 0 = half, at
 * least 1): each texel the solid-angle weighted mean of the source texels
 * it covers, those it covers in part weighted by the covered fraction of
 * their side too; halving repeatedly gives the same when the sizes divide.
 * Rejects NaN or infinite texels. dst is allocated; free it with
 * lx_cubemap_free. desc may be NULL. */
lx_status lx_cubemap_downsample(const lx_cubemap *src, int size, const lx_ibl_desc *desc,
                                lx_cubemap *dst);

/* The seed's seam fix: texels that lie along a cube edge are replaced by
 * the mean of themselves and their neighbour across the edge (the texel
 * lx_cubemap_sample takes there), corner texels by the mean of the three
 * that meet there, so both sides agree. Touches 12 size texels: no desc. */
void lx_cubemap_fix_seams(lx_cubemap *c);

/* ---- environments in and out ---------------------------------------- */

typedef enum lx_env_layout {
    LX_ENV_AUTO = 0, /* in: from the shape (2:1 equirect, 4:3 or 3:4 cross, a
                        name ending in _px.<ext> for six faces); out: FACES */
    LX_ENV_EQUIRECT,
    LX_ENV_CROSS,         /* in: horizontal (4:3) or vertical (3:4); out: horizontal */
    LX_ENV_FACES,         /* in: path names the +X face <name>_px.<ext>; out: six files */
    LX_ENV_KTX,           /* out only: one KTX 1.1 file, the levels as its mips */
    LX_ENV_CROSS_VERTICAL /* in: as CROSS; out: a vertical cross */
} lx_env_layout;

typedef struct lx_env_load_desc {
    lx_env_layout layout;
    float intensity;         /* multiplier on every texel, 0 = 1 */
    int size;                /* cube face size; 0 = from the input (equirect: width/4) */
    int threads;             /* resampling threads, 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_env_load_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_env_load_desc lx_env_load_desc_defaults(const lx_env_load_desc *desc);

/* Loads an environment (any format lx_image_load reads; 8-bit files are
 * sRGB decoded) into a cube map at desc->size (resampled by a box filter:
 * each texel the mean of a grid of bilinear samples over it). Rejects a
 * non-2:1 equirect, a cross of the wrong proportions, faces of unequal
 * sizes, and NaN, infinite or negative texels (the message gives their
 * count). desc may be NULL. */
lx_status lx_env_load(const char *path, const lx_env_load_desc *desc, lx_cubemap *out);

/* The same for an image already in memory (1 to 4 channels; grey is
 * grey, alpha ignored): an equirect or a cross, as desc->layout says or
 * from its shape; name is used in messages. Six faces need files. */
lx_status lx_env_from_image(const lx_image *img, const char *name, const lx_env_load_desc *desc,
                            lx_cubemap *out);

/* A constant environment of radiance L (nits) per channel. */
lx_status lx_env_constant(lx_vec3 radiance, int size, lx_cubemap *out);

/* Layout conversions. From an equirect, each cube texel is the mean of a
 * stratified set of equirect bilinear samples over the texel; to an
 * equirect, each pixel is the mean of lx_cubemap_sample over the pixel.
 * desc may be NULL. */
lx_status lx_cubemap_from_equirect(const lx_image *equirect, int size, const lx_ibl_desc *desc,
                                   lx_cubemap *out);
lx_status lx_cubemap_to_equirect(const lx_cubemap *c, int width, const lx_ibl_desc *desc,
                                 lx_image *out);
lx_status lx_cubemap_from_cross(const lx_image *cross, const lx_ibl_desc *desc, lx_cubemap *out);
lx_status lx_cubemap_to_cross(const lx_cubemap *c, bool vertical, const lx_ibl_desc *desc,
                              lx_image *out);

/* Called by lx_env_write before it creates each file, with the file's
 * name (no folder); returning false stops the write (LX_ERR_CANCELLED). */
typedef bool (*lx_env_file_fn)(void *user, const char *name);

typedef struct lx_env_write_desc {
    lx_env_layout layout;    /* AUTO = FACES; FACES, CROSS, CROSS_VERTICAL, EQUIRECT, KTX */
    lx_image_format format;  /* of the images (not KTX); AUTO = EXR */
    bool half;               /* 16-bit floats: EXR half, KTX RGBA16F (else RGBA32F) */
    bool mip_names;          /* name levels <stem>_m<L> even when there is one */
    float exposure;          /* 8-bit formats (PNG, JPEG, TGA): multiplier on the
                                values, 0 = 1; float formats and KTX store the
                                values as they are */
    lx_tonemap tonemap;      /* 8-bit formats: the curve after exposure
                                (lx_image_write_desc.tonemap; CLAMP by default) */
    int threads;             /* conversion and encoding threads, 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
    lx_env_file_fn on_file; /* may be NULL: hears each file's name first */
    void *on_file_user;
} lx_env_write_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_env_write_desc lx_env_write_desc_defaults(const lx_env_write_desc *desc);

/* Writes levels[0..count) (a cube map and its mips) into folder, named from
 * stem: KTX one file <stem>.ktx (the levels must halve down from level 0,
 * RGBA16F or RGBA32F, A = 1); the image layouts one or six files per level
 * named <stem>[_m<L>][_<face>].<ext> - _m<L> when count > 1 or
 * desc->mip_names, _px ... _nz for FACES, an equirect 4N x 2N. Each file is
 * written atomically (a temporary name renamed when complete); on failure
 * or cancellation the files this call wrote are removed again (one it
 * replaced stays replaced: write into a fresh folder for all or nothing).
 * Rejects NaN or infinite values, and values beyond 65504 in half floats,
 * naming the file and texel. desc may be NULL. */
lx_status lx_env_write(const char *folder, const char *stem, const lx_cubemap *levels, int count,
                       const lx_env_write_desc *desc);

/* Checks, without a cube map, what lx_env_write of count levels from a
 * face size `size` down would be refused: the desc, and its peak memory
 * (the levels and the image each is written from). */
lx_status lx_env_write_check(int size, int count, const lx_env_write_desc *desc);

/* Tells desc->on_file the name of every file lx_env_write(folder, stem,
 * levels, count, desc) would write, in the order it would write them, and
 * writes nothing: a caller checks (or reserves) every name before the work
 * that makes the levels. Fails as lx_env_write does on a bad stem, count or
 * desc; LX_ERR_CANCELLED when on_file returns false. */
lx_status lx_env_write_names(const char *stem, int count, const lx_env_write_desc *desc);

/* Writes levels[0..count) (a cube map and its mips, each half the size of
 * the one before) as one KTX 1.1 file at path, RGBA16F when half else
 * RGBA32F, atomically (lx_env_write with LX_ENV_KTX, at a path of the
 * caller's choosing, on all cores and without progress: lx_env_write
 * takes threads and a progress callback). */
lx_status lx_ktx_write_cubemap(const char *path, const lx_cubemap *levels, int count, bool half);

/* ---- diffuse irradiance --------------------------------------------- */

/* The face size of an irradiance cube when none is asked for (size 0), and
 * what lx_irradiance_brute reduces its source to (source_size 0):
 * irradiance varies slowly, so 32 x 32 faces hold it. */
#define LX_IRRADIANCE_DEFAULT_SIZE 32

/* The seed's brute force: every source texel a directional light of
 * radiance * exact solid angle, weighted by the cosine. The cosine is
 * integrated exactly over each texel (its irradiance vector, Lambert's
 * formula); a texel the horizon cuts is split into sub-texels, so a
 * constant environment L gives pi L to ~2e-5. The source is first
 * downsampled (lx_cubemap_downsample, in one pass) to its size halved
 * until it is at most source_size (0 = LX_IRRADIANCE_DEFAULT_SIZE). out
 * gets a cube map of size texels per side (0 = LX_IRRADIANCE_DEFAULT_SIZE),
 * irradiance in lux. Cost: 6 size^2 x 6 source^2 texel pairs. Rejects NaN
 * or infinite texels. desc may be NULL. On failure or cancellation out is
 * left zeroed. */
lx_status lx_irradiance_brute(const lx_cubemap *src, int size, int source_size,
                              const lx_ibl_desc *desc, lx_cubemap *out);

/* Order-2 spherical harmonics (Ramamoorthi & Hanrahan 2001): radiance
 * coefficients L_lm, order L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22,
 * with Y1-1 = 0.488603 y, Y10 = 0.488603 z, Y11 = 0.488603 x ... */
typedef struct lx_sh9 {
    float c[9][3];
} lx_sh9;

/* The 9 basis functions at unit direction d:
 *   Y00 = 0.282095, Y1-1 = 0.488603 y, Y10 = 0.488603 z, Y11 = 0.488603 x,
 *   Y2-2 = 1.092548 xy, Y2-1 = 1.092548 yz, Y20 = 0.315392 (3z^2 - 1),
 *   Y21 = 1.092548 xz, Y22 = 0.546274 (x^2 - y^2)
 * with x, y, z luxel's axes (+Y up; the paper's formulas hold in any
 * orthonormal frame). */
void lx_sh9_basis(lx_vec3 d, float y[9]);
/* Projects a cube map (radiance, nits) with exact texel solid angles, sums
 * in double, the same result for any thread count. Fails with
 * LX_ERR_INVALID when the cube map holds NaN or infinite texels. desc may
 * be NULL. */
lx_status lx_sh_project(const lx_cubemap *c, const lx_ibl_desc *desc, lx_sh9 *out);
/* Irradiance (lux) at unit normal n: the paper's equation 13. NOT clamped:
 * the order-2 truncation rings, and an environment dominated by a small,
 * strong light comes out slightly negative about 120 degrees away from it
 * (down to -3.7% of the peak for a point light); clamp in the shader if
 * needed. */
void lx_sh_irradiance(const lx_sh9 *sh, lx_vec3 n, float out[3]);
/* The paper's constants c1..c5. */
extern const float lx_sh_irradiance_constants[5];
/* lx_sh_irradiance at every texel centre of a size^2 cube map (size 0 =
 * LX_IRRADIANCE_DEFAULT_SIZE; allocated, free with lx_cubemap_free). Not
 * clamped either: negative texels are kept, and a warning counting them
 * goes to the log callback. desc may be NULL. */
lx_status lx_sh_irradiance_cube(const lx_sh9 *sh, int size, const lx_ibl_desc *desc,
                                lx_cubemap *out);

/* ---- specular -------------------------------------------------------- */

typedef enum lx_specular_filter { LX_SPECULAR_GGX = 0, LX_SPECULAR_PHONG } lx_specular_filter;

/* Level 0's face size when none is asked for: the source's, at most this
 * (lx_prefilter_size). */
#define LX_PREFILTER_DEFAULT_SIZE 256
/* The most GGX samples per texel lx_prefilter_desc.samples may ask. */
#define LX_PREFILTER_MAX_SAMPLES 65536

typedef struct lx_prefilter_desc {
    lx_specular_filter filter;
    int size;                     /* level 0 face size, 0 = the source's, at most
                                     LX_PREFILTER_DEFAULT_SIZE (lx_prefilter_size) */
    int mips;                     /* levels, 0 = down to 1x1; at most log2(size) + 1 */
    int samples;                  /* GGX: importance samples per texel where sampled, and the
                                     per-texel budget that picks convolution
                                     (1..LX_PREFILTER_MAX_SAMPLES), 0 = 256 */
    const float *phong_exponents; /* PHONG: one per level, each in (0, 1e6];
                                     NULL = lx_phong_level_exponent */
    int threads;                  /* 0 = all cores */
    lx_progress_fn progress;
    void *progress_user;
} lx_prefilter_desc;

/* A copy of desc (or of zeros when NULL) with the defaults that do not
 * depend on the source filled in (size and mips are chosen by
 * lx_prefilter from the source). */
lx_prefilter_desc lx_prefilter_desc_defaults(const lx_prefilter_desc *desc);

/* The face size of level 0 that lx_prefilter makes from a source of face
 * size source_size: desc->size when set, else the source's, at most
 * LX_PREFILTER_DEFAULT_SIZE. desc may be NULL. The levels it makes, when
 * desc->mips is 0, are lx_cube_mip_count of that size. */
int lx_prefilter_size(int source_size, const lx_prefilter_desc *desc);

/* The GGX roughness (perceptual, alpha = roughness^2) of mip level of
 * count levels: level / (count - 1). */
float lx_ggx_level_roughness(int level, int count);

/* The default Phong exponent of mip level: 2048 / 4^level, at least 1
 * (2048, 512, 128, 32, 8, 2, 1, 1, ...): the lobe doubles its width as the
 * level halves its size. */
float lx_phong_level_exponent(int level);

/* Prefilters src into levels[0..*count) (the caller's array of
 * LX_MAX_CUBE_MIPS; level l has face size max(1, size >> l)). Each level is
 * allocated; the caller frees each with lx_cubemap_free. On failure or
 * cancellation *count is 0 and every entry is zeroed.
 * GGX (Karis 2013, N = V = R): level 0 is the source at roughness 0 (a
 * copy, or its solid-angle mip of that size, or bilinear when sizes do not
 * divide). A level l > 0 is the exact convolution, weight D(h) (N.L) per
 * texel of the source mip whose texels are at most a third of the lobe's
 * half-width, far texels grouped into lights at their flux centroid (the
 * mean error against a full-resolution convolution is about 0.2%) -
 * unless that costs more than desc.samples importance samples per texel;
 * then it averages desc.samples Hammersley samples weighted by N.L, read
 * trilinearly from the source's mip chain at lod = 0.5 log2(Omega_s /
 * Omega_p) + 1 (Colbert & Krivanek 2007, plus a one-level bias) so small
 * bright lights do not sparkle. A constant environment stays constant.
 * PHONG: the seed's lobe pow(max(0, R.L), n) normalised by its own sum
 * over the sphere (sum of weight x solid angle), so a constant environment
 * stays constant; computed on the source's mip whose texels are at most
 * half the lobe's half-width (each a light at the flux centroid of what it
 * covers), leaving out texels where the lobe is below 1e-4 of its peak.
 * Both read across face edges, so the levels have no seams. Threads,
 * progress and cancellation from desc (may be NULL); the result is the
 * same for any thread count. Rejects NaN or infinite source texels, and
 * (LX_ERR_NOMEM, before allocating) a run whose source, mips, padded
 * copies, convolution lights and levels together exceed the machine's
 * memory. A level 0 more than 4x the source's size logs a warning. */
lx_status lx_prefilter(const lx_cubemap *src, const lx_prefilter_desc *desc,
                       lx_cubemap levels[LX_MAX_CUBE_MIPS], int *count);

/* What lx_prefilter of a source of face size source_size with desc would
 * refuse, checked on the sizes alone (nothing large is allocated): the
 * desc and the peak memory, with lx_prefilter's messages. */
lx_status lx_prefilter_check(int source_size, const lx_prefilter_desc *desc);

/* The DFG table's side and samples per texel when none are asked for (0),
 * and the most lx_dfg_lut takes. */
#define LX_DFG_DEFAULT_SIZE 128
#define LX_DFG_MAX_SIZE 4096
#define LX_DFG_DEFAULT_SAMPLES 1024
#define LX_DFG_MAX_SAMPLES (1 << 20)

/* The split-sum DFG table for GGX (Karis 2013): texel (x, y), row 0 at the
 * top, holds N.V = (x + 0.5) / size and perceptual roughness
 * (y + 0.5) / size (alpha = roughness^2); channel 0 is the scale A and
 * channel 1 the bias B on F0 (specular = F0 * A + B). G is Smith's
 * height-correlated masking-shadowing (Heitz 2014); the integrals are
 * estimated from samples Hammersley-placed visible normals (Heitz 2018),
 * the same for every texel. size 0 = LX_DFG_DEFAULT_SIZE
 * (1..LX_DFG_MAX_SIZE), samples 0 = LX_DFG_DEFAULT_SAMPLES
 * (1..LX_DFG_MAX_SAMPLES). out is allocated (size*size*2 floats); free with
 * lx_image_free. desc may be NULL. */
lx_status lx_dfg_lut(int size, int samples, const lx_ibl_desc *desc, lx_image *out);

#ifdef __cplusplus
}
#endif

#endif
