/* luxel/unwrap.h - lightmap UVs made by luxel. The meshes of a scene's
 * nodes are cut into charts (regions grown over the faces whose normals
 * stay close to the chart's, at a cost for crossing hard edges and for
 * ragged shapes, as in the D-charts / xatlas family), each chart is
 * flattened (planar charts by projection, curved ones by least-squares
 * conformal maps), charts that fold, overlap themselves or stretch too much
 * are cut again, and every chart of every node is packed, rotated, into
 * atlas pages at a texel density, each chart owning `padding` rings of
 * texels so that bilinear filtering never mixes two charts.
 * lx_uv_health_mesh / _node say whether UVs a file brings can serve as
 * lightmap UVs (range, zero-area, flipped and overlapping triangles);
 * lx_uv_share_nodes judges the nodes' sets together (pieces of one UV
 * square that several nodes share, as objects sharing a texture atlas do).
 *
 * CONVENTIONS  Texel density in texels per metre of world space: a node's
 *   scale counts, so an instance scaled 2x gets twice the texels across.
 *   Page UVs are in [0,1] with the top-left origin of every UV in luxel;
 *   texel (x, y) of a page covers [x, x+1] x [y, y+1] / (width, height).
 *   A node keeps its own lightmap UVs (LX_UNWRAP_KEEP) by a scale and
 *   offset into its page, Unity's lightmapScaleOffset convention:
 *   page_uv = uv * (scale_offset[0], scale_offset[1])
 *           + (scale_offset[2], scale_offset[3]).
 *   A chart's "covered" texels are those its triangles overlap with a
 *   positive area (what the baker samples); the page's efficiency is
 *   covered texels / page texels.
 * ERRORS  lx_unwrap_scene fails with LX_ERR_INVALID for bad options or a
 *   node to keep without usable UVs, LX_ERR_NOMEM when the pages would not
 *   fit in memory (the GiB named), LX_ERR_CANCELLED when the progress
 *   callback says stop. Zero-area triangles are not an error: they get
 *   UVs of zero area and are counted in stats.degenerate_triangles.
 * MEMORY  lx_unwrap_scene allocates the result; lx_unwrap_destroy frees it.
 *   The scene is only read and may be destroyed afterwards.
 * THREADING  lx_unwrap_scene, the lx_uv_health_* functions,
 *   lx_uv_share_nodes and the *_desc_defaults are thread-safe;
 *   each call runs OpenMP over meshes and charts, at most desc.threads
 *   threads, and gives the same result for any thread count.
 *
 * USAGE
 *   lx_scene *scene;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK) return 1;
 *   lx_unwrap_desc d = lx_unwrap_desc_defaults(NULL);
 *   d.texel_density = 16.0f;                          // texels per metre
 *   d.padding = LX_UNWRAP_PADDING_RECOMMENDED;
 *   lx_unwrap *u;
 *   if (lx_unwrap_scene(scene, &d, &u) == LX_OK) {
 *       printf("%u charts on %u pages, %.0f%% covered\n", u->stats.charts,
 *              u->page_count, 100.0 * u->stats.efficiency);
 *       lx_unwrap_destroy(u);
 *   }
 *   lx_scene_destroy(scene);
 */
#ifndef LUXEL_UNWRAP_H
#define LUXEL_UNWRAP_H

#include "luxel/core.h"
#include "luxel/math.h"
#include "luxel/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Rings of texels each chart owns: what bilinear filtering of the page
 * needs, plus one for the baker's dilation. Matches the baker's
 * LX_PADDING_RECOMMENDED, so dilated texels never reach another chart. */
#define LX_UNWRAP_PADDING_RECOMMENDED 2
#define LX_UNWRAP_MAX_PADDING 64
#define LX_UNWRAP_MAX_ATLAS_SIZE 16384

/* What lx_unwrap_scene does with a node. */
typedef enum lx_unwrap_mode {
    LX_UNWRAP_GENERATE = 0, /* make new UVs for its meshes */
    LX_UNWRAP_KEEP,         /* place its own UV square in a page (scale/offset) */
    LX_UNWRAP_SKIP          /* leave it out (no page) */
} lx_unwrap_mode;

typedef struct lx_unwrap_desc {
    float texel_density;         /* texels per metre; 0: the density at which the
                                    scene about fills one page of `resolution` */
    int resolution;              /* the page side to fill when texel_density is 0;
                                    0 = 1024 */
    int padding;                 /* texel rings each chart owns, 0..LX_UNWRAP_MAX_PADDING
                                    (a value: 0 = none; luxel uses
                                    LX_UNWRAP_PADDING_RECOMMENDED) */
    int atlas_size;              /* largest page side in texels, 0 = 4096 */
    float max_chart_angle;       /* degrees a face's normal may turn away from its
                                    chart's, 0 = 60 */
    float max_stretch;           /* a chart's largest tolerated L2 stretch (Sander et
                                    al.; 1 = isometric), 0 = 1.15; charts above it
                                    are cut again */
    const lx_unwrap_mode *modes; /* per scene node, NULL = generate for all */
    bool page_per_node;          /* no two nodes share a page: a lightmap per node
                                    (pages then hold one node's charts) */
    const int *keep_uv_sets;     /* per node, the UV set LX_UNWRAP_KEEP places
                                    (NULL = TEXCOORD_1 when the meshes have it,
                                    else TEXCOORD_0) */
    int threads;                 /* 0 = all cores */
    lx_progress_fn progress;
    void *progress_user;
} lx_unwrap_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_unwrap_desc lx_unwrap_desc_defaults(const lx_unwrap_desc *desc);

typedef struct lx_unwrap_page {
    int width, height;       /* texels, each a multiple of 4, at most atlas_size */
    uint32_t covered_texels; /* texels the triangles overlap */
    uint32_t chart_count;    /* charts (a kept node's square counts as one) */
} lx_unwrap_page;

/* Where a node's lightmap lives. */
typedef struct lx_unwrap_node {
    uint32_t page;         /* UINT32_MAX: skipped, or no triangles */
    lx_unwrap_mode mode;   /* what was done */
    int uv_set;            /* LX_UNWRAP_KEEP: the set placed */
    float scale_offset[4]; /* own UV -> page UV (KEEP); identity (1, 1, 0, 0)
                              for generated UVs, which are page UVs already */
} lx_unwrap_node;

/* The new UVs of one mesh of one generated node. Vertices are split where
 * a chart border runs (vertex_source says which mesh vertex each copies);
 * triangles keep their order. */
typedef struct lx_unwrap_mesh {
    uint32_t node, mesh; /* scene indices */
    uint32_t vertex_count;
    uint32_t *vertex_source; /* vertex_count: the mesh vertex this one copies */
    lx_vec2 *uv;             /* vertex_count: page UVs */
    uint32_t *indices;       /* 3 * the mesh's triangle_count */
} lx_unwrap_mesh;

typedef struct lx_unwrap_stats {
    uint32_t charts;               /* charts packed */
    uint32_t recut_charts;         /* charts cut again after flattening */
    uint32_t degenerate_triangles; /* zero-area triangles (UVs of zero area) */
    double stretch_mean;           /* area-weighted L2 stretch over every chart */
    double stretch_max;            /* the worst chart's L2 stretch */
    double efficiency;             /* covered texels / page texels, all pages */
} lx_unwrap_stats;

typedef struct lx_unwrap {
    float texel_density; /* the density used (texels per metre) */
    lx_unwrap_page *pages;
    uint32_t page_count;
    lx_unwrap_node *nodes; /* one per scene node */
    uint32_t node_count;
    lx_unwrap_mesh *meshes; /* one per (generated node, mesh of that node) */
    uint32_t mesh_count;
    lx_unwrap_stats stats;
} lx_unwrap;

/* Unwraps and packs the nodes of scene as desc says (NULL desc: defaults,
 * every node generated). A node too big for one page at the density is
 * scaled down to fit, with a warning naming it. */
lx_status lx_unwrap_scene(const lx_scene *scene, const lx_unwrap_desc *desc, lx_unwrap **out);
void lx_unwrap_destroy(lx_unwrap *unwrap);

/* Puts the generated UVs into the scene the unwrap was made from: every
 * generated node gets its own copy of each of its meshes, vertices split
 * as the unwrap says, with TEXCOORD_1 = the page UVs (the other attributes
 * copied); the node then points to the copies. Instances stop sharing
 * meshes; the originals stay in the scene. Kept and skipped nodes are
 * untouched. LX_ERR_INVALID when the unwrap was made for another scene;
 * not thread-safe with other users of the scene (it changes it). */
lx_status lx_unwrap_apply(lx_scene *scene, const lx_unwrap *unwrap);

/* ---- UV health -------------------------------------------------------------
 * Whether a UV set can serve as lightmap UVs, and why not. Coverage is the
 * baker's: a triangle covers a texel it overlaps with a positive area; a
 * covered texel is overlapped when two triangles both cover more than a
 * thousandth of it (triangles that only share an edge never do). Zero-area
 * UV triangles follow the baker's rule (|e1 x e2| <= 1e-7 (longest edge)^2)
 * and are left out of the texels, as the baker skips them. Flipped
 * triangles are those wound against their mesh's majority in UV space
 * (counted, not a problem by themselves: a mirrored chart bakes fine). */
typedef enum lx_uv_problem {
    LX_UV_OK = 0,    /* usable */
    LX_UV_MISSING,   /* a mesh lacks the set */
    LX_UV_OUTSIDE,   /* a triangle reaches outside [0,1] (texels there are lost) */
    LX_UV_ZERO_AREA, /* triangles of zero UV area (the baker refuses them) */
    LX_UV_OVERLAP,   /* more than max_overlap of the covered texels overlapped */
    LX_UV_SPARSE,    /* the triangles cover less than min_coverage of the unit square
                        (a texture atlas's corner, not a lightmap layout) */
    LX_UV_SHARED     /* a piece of a UV square other nodes share (lx_uv_share_nodes
                        judges it across the scene; lx_uv_health_* never report it) */
} lx_uv_problem;

typedef struct lx_uv_health_desc {
    int resolution;      /* texels a side of the bitmap overlaps are counted on,
                            0 = 256 (the baker's default resolution) */
    float texel_density; /* > 0: lx_uv_health_node sizes the bitmap as the baker
                            sizes the node's lightmap at this density (texels per
                            metre: side^2 * uv_area = density^2 * world_area,
                            rounded up to a multiple of 4, 4..max_resolution) */
    int max_resolution;  /* cap of density sizes, 0 = 4096 */
    float max_overlap;   /* overlapped share of the covered texels above which
                            the set is not usable, 0 = 0.01 */
    float min_coverage;  /* UV area of the triangles (unit square = 1) below which
                            the set is not usable, 0 = 1/8 */
    int threads;         /* 0 = all cores */
    lx_progress_fn progress; /* hears the texels' tiles (0 to 1), from one thread
                                at a time; returning false stops the call with
                                LX_ERR_CANCELLED */
    void *progress_user;
} lx_uv_health_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_uv_health_desc lx_uv_health_desc_defaults(const lx_uv_health_desc *desc);

typedef struct lx_uv_health {
    int uv_set;                   /* the set looked at (0 = TEXCOORD_0) */
    bool present;                 /* every mesh has it (else nothing below is filled) */
    lx_vec2 min, max;             /* range of the triangles' UVs */
    uint32_t triangles;
    uint32_t zero_area_triangles;
    uint32_t flipped_triangles;   /* wound against their mesh's majority */
    int resolution;               /* side of the bitmap the texels were counted on */
    uint64_t covered_texels;      /* texels inside [0,1]^2 some triangle covers */
    uint64_t overlap_texels;      /* covered texels two triangles overlap */
    double overlap_share;         /* overlap_texels / covered_texels (0 if none) */
    double world_area;            /* m^2: world space for a node, object space for a mesh */
    double uv_area;               /* summed UV area of the triangles (unit square = 1) */
    bool usable;                  /* problem == LX_UV_OK */
    lx_uv_problem problem;        /* the first of missing, outside, zero area, overlap,
                                     sparse */
    char reason[96];              /* "" when usable, else e.g. "overlaps on 12.5% of its
                                     texels", "outside [0,1] (u 1..2, v 0..1)" */
} lx_uv_health;

/* UV set uv_set (below LX_MAX_UV_SETS) of one mesh, in its own space, on a bitmap of
 * desc->resolution. desc may be NULL. LX_ERR_INVALID for a bad set or
 * options, LX_ERR_NOMEM, LX_ERR_CANCELLED. Deterministic for any thread
 * count; the time follows the covered texels (plus, per texel, the pairs
 * of triangles that reach it). */
lx_status lx_uv_health_mesh(const lx_mesh *mesh, int uv_set, const lx_uv_health_desc *desc,
                            lx_uv_health *out);
/* The same for every mesh of scene node `node` together (they share the
 * node's lightmap), areas in world space, the bitmap sized as the baker
 * would (desc->texel_density) or desc->resolution. */
lx_status lx_uv_health_node(const lx_scene *scene, uint32_t node, int uv_set,
                            const lx_uv_health_desc *desc, lx_uv_health *out);
/* "usable", "missing", "outside [0,1]", "zero-area triangles", "overlapping",
 * "sparse", "shared". */
const char *lx_uv_problem_name(lx_uv_problem problem);

/* ---- Shared UV squares ---------------------------------------------------------
 * Whether a node's lightmap UV set is a piece of a UV square that other
 * nodes share, judged across the scene. Objects sharing one texture atlas
 * each use a part of the unit square, side by side with or on top of the
 * other objects' parts; a lightmap of the node's own made of the whole
 * square would be mostly empty (a game level's 61 nodes so baked used
 * 1.3% of their pages). lx_uv_health's min_coverage sees a node whose
 * triangles cover under 1/8 of the square; this sees the parts larger
 * than that, and names the sharing.
 *
 * A node's UV box is the bounding box of its triangles' UVs in its set,
 * over all its meshes. A node counts when every mesh has the set, it has
 * triangles and the box lies in [0,1]^2 (a set reaching outside tiles,
 * it is no square). The span of a set is the bounding box of the boxes
 * of the counted nodes using that set; a node's share is its box's area
 * over its span's, and it is a piece of a shared square when the share
 * is at most max_share. So:
 * - a set every node fills (Blender's Lightmap Pack, Unity's generated
 *   lightmap UVs, xatlas and luxel's own reach every side of the square)
 *   gives every node a share near 1: not shared;
 * - instances (nodes placing the same meshes) have equal boxes: however
 *   many, they never make each other's share small;
 * - a node alone in its set, or whose set only it and its instances use,
 *   has share 1: min_coverage judges how much of the square it uses;
 * - objects laid side by side in one atlas, or overlapping there, have
 *   boxes that are each a small part of the span: shared. */
typedef struct lx_uv_share_desc {
    float max_share; /* a node's box area over its set's span area at or below
                        which it is a piece of a shared square, 0 = 1/2 (baked
                        as the whole square, at least half of its lightmap
                        would be empty), at most 1 */
} lx_uv_share_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_uv_share_desc lx_uv_share_desc_defaults(const lx_uv_share_desc *desc);

typedef struct lx_uv_share {
    int uv_set;                 /* the set judged (0 = TEXCOORD_0) */
    bool counted;               /* the node's box is part of its set's span (else
                                   nothing below is filled, shared is false) */
    lx_vec2 min, max;           /* the node's UV box */
    lx_vec2 span_min, span_max; /* the span: every counted box of the set together */
    uint32_t users;             /* counted nodes using the set, this one included */
    uint32_t boxes;             /* different boxes among them (instances share one) */
    double share;               /* box area / span area (1 when the span has none) */
    bool shared;                /* share <= max_share: a piece of a shared square */
    char reason[112];           /* "" unless shared, else e.g. "is a piece of a UV square
                                   8 nodes share (its UV box 12.5% of theirs; a texture
                                   atlas?)" */
} lx_uv_share;

/* Judges the lightmap UV set of every node of scene together into out,
 * which must hold scene->node_count entries (out[n] for node n).
 * uv_sets[n] is node n's set, below LX_MAX_UV_SETS (NULL: lx_bake_uv_set's
 * automatic choice, as lx_unwrap_desc.keep_uv_sets). desc may be NULL.
 * Nodes without meshes or a lightmap (bake.no_lightmap) are not counted.
 * LX_ERR_INVALID for a bad set or
 * option, LX_ERR_NOMEM. Reads each mesh's UVs once; thread-safe. */
lx_status lx_uv_share_nodes(const lx_scene *scene, const int *uv_sets,
                            const lx_uv_share_desc *desc, lx_uv_share *out);

/* ---- UV seams -----------------------------------------------------------------
 * Edges where the surface continues but its UVs do not: two triangles
 * share an edge by position (vertices welded where their positions are
 * equal) but not its UVs in the set. Bilinear lookups on the two sides
 * then read different texels for the same point of the surface, which
 * shows as a line unless the texels are made to agree (the baker's seam
 * stitching). a[k] and b[k] are the same point of the surface on side A
 * (triangle_a) and side B (triangle_b). */
typedef struct lx_uv_seam {
    lx_vec2 a[2], b[2];
    uint32_t triangle_a, triangle_b;
} lx_uv_seam;

/* The seams of one mesh's UV set, each edge once, in triangle order, into
 * *out (malloc'd, free with free(); NULL when there are none) and *count.
 * Only manifold edges count (two triangles, opposite directions);
 * degenerate triangles are left out. LX_ERR_INVALID for a set the mesh
 * lacks, LX_ERR_NOMEM. */
lx_status lx_uv_seams(const lx_mesh *mesh, int uv_set, lx_uv_seam **out, uint32_t *count);

#ifdef __cplusplus
}
#endif
#endif
