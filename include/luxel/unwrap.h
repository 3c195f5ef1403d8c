/* luxel/unwrap.h - lightmap UVs made by luxel. The meshes of a scene's
 * nodes are cut into charts (regions grown over the faces whose normals
 * stay close to the chart's, at a cost for crossing hard edges and for
 * ragged shapes, as in the D-charts / xatlas family), each chart is
 * flattened (planar charts by projection, curved ones by least-squares
 * conformal maps), charts that fold, overlap themselves or stretch too much
 * are cut again, and every chart of every node is packed, rotated, into
 * atlas pages at a texel density, each chart owning `padding` rings of
 * texels so that bilinear filtering never mixes two charts.
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
 * THREADING  lx_unwrap_scene and lx_unwrap_desc_defaults are thread-safe;
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

#ifdef __cplusplus
}
#endif
#endif
