/* The names of luxel bake's output files (bake_names.c; private to
 * tools/luxel): every file planned before the bake, none taking another's
 * name or one of luxel's own. */
#ifndef LUXEL_BAKE_NAMES_H
#define LUXEL_BAKE_NAMES_H

#include "bake_setup.h"

/* Directional files a lightmap has at most (sh0..sh3), and all its files:
 * the map, its preview, its AO map and the directional maps. */
#define DIR_FILES 4
#define STEM_FILES (3 + DIR_FILES)

/* Every file name the bake writes, each once. Compared without case:
 * on macOS and Windows file systems X.png and x.png are one file. A hash
 * set, so that thousands of nodes plan in linear time. */
typedef struct output_names {
    char **names; /* in the order planned: luxel's own first */
    uint32_t count;
    uint32_t *slots; /* index + 1 into names, 0 = empty; a power of two */
    uint32_t slot_count;
} output_names;

/* The directional files of a lightmap with this stem: <stem>_sh0..3.<ext>
 * (sh) or <stem>_dir.png (dominant); returns how many (0 without
 * --directional). */
int bake_directional_names(const bake_args *a, const char *stem, char out[DIR_FILES][300]);

/* Plans every file of the bake before it: stems[m] (malloc'd) for
 * lightmap m - an atlas page is lightmap-<k>, a node's own lightmap is
 * named after the node - and every name into *on: luxel's own outputs
 * (manifest.json, and view.png whether or not --render is given, so that
 * a node's files do not change names with it) and uvs_name (the scene
 * with UVs, "" when none) first. A lightmap any of whose files would take
 * a name already planned gets the first free stem <stem>_2, _3, ... (in
 * node order, so a scene always gets the same names); one warning lists
 * those. false when out of memory (error printed); *on is freed with
 * bake_output_names_free either way. */
bool bake_plan_outputs(const bake_args *a, const lx_scene *scene, const lx_baker *baker, bool atlas,
                       const char *uvs_name, uint32_t maps, char **stems, output_names *on);
void bake_output_names_free(output_names *on);

/* The earlier bake's files in the output folder that this one does not
 * write (cli_stale_find), among the names planned (view.png counts as
 * written only with --render). */
bool bake_find_stale(const bake_args *a, const output_names *on, cli_stale *out);

#endif
