/* Helpers shared by luxel's tests: temporary folders and small scenes built
 * in code (planes, boxes) with known geometry. */
#ifndef LX_TEST_HELPERS_H
#define LX_TEST_HELPERS_H

#include "luxel/luxel.h"

/* A fresh folder under $LX_TEST_TMP (or /tmp) named after tag; returned
 * path is static storage until the next call. */
const char *lx_test_dir(const char *tag);

/* Number of entries in a folder (excluding . and ..), -1 if missing. */
int lx_test_count_files(const char *dir);

/* A square of side `size` in the plane y = height, normal +Y, centred at
 * (cx, cz), with TEXCOORD_1 covering [0,1]^2 (u along +x, v along +z) and
 * TEXCOORD_0 equal to it. Split into 2*n*n triangles. */
lx_mesh lx_test_plane(const char *name, float size, float height, float cx, float cz, int n);

/* An axis-aligned box [lo, hi] with 6 faces; normals point outward, or
 * inward when `inward`; each face its own UV chart in a 3x2 grid. */
lx_mesh lx_test_box(const char *name, lx_vec3 lo, lx_vec3 hi, bool inward);

void lx_test_mesh_free(lx_mesh *m);

/* An empty scene named name; fails the test if it cannot be made. */
lx_scene *lx_test_new_scene(const char *name);

/* Fails the test unless got is within tol of want, relative to |want| (or
 * absolute when want is 0). */
void lx_test_assert_rel(double got, double want, double tol);

/* Parses IES text named "t.ies"; fails the test if it does not parse. */
lx_ies_profile *lx_test_parse_ies(const char *text);

/* Fails the test unless v equals (x, y, z) in each component to 4e-7 of
 * max(1, |component|): the vectors are floats (positions, colours and
 * directions the tests read back); the errors measured over every use are
 * 0 to 1.4e-7 (the largest against the published six-digit 0.214041). */
void lx_test_assert_vec3(lx_vec3 v, double x, double y, double z);

/* The lightmap index of scene node `node`; fails the test if it has none. */
uint32_t lx_test_map_of(const lx_baker *baker, uint32_t node);

/* Adds mesh as its own node named like the mesh with an identity transform
 * (and a default material when the scene has none). */
void lx_test_add(lx_scene *scene, lx_mesh *mesh);

/* A material of albedo rho (grey) and emission le (nits, grey); its index. */
uint32_t lx_test_grey_material(lx_scene *scene, const char *name, float rho, float le);

/* lx_test_add with the mesh's material set first; frees the mesh. */
void lx_test_add_with_material(lx_scene *scene, lx_mesh *mesh, uint32_t material);

/* Form factor from a point to a parallel rectangle of sides a, b with one
 * corner straight across at distance c (Howell's catalogue, C-11); odd in
 * a and in b, so signed sides superpose rectangles anywhere. */
double lx_test_corner_form_factor(double a, double b, double c);

/* Ends the process with a failure message on stderr (exit status 1) when
 * it is still running after `seconds`: a hang in the code under test then
 * fails the test instead of stalling the whole run. */
void lx_test_watchdog(unsigned seconds);

/* The path of the program `name` built beside the running test (luxel,
 * gen_scenes...) into out; fails the test when it is not an executable. */
void lx_test_sibling(const char *name, char *out, size_t size);

/* Runs the `luxel` built beside the running test with args (NULL-terminated,
 * after the program's name): stdout to out_log, stderr to err_log (the same
 * path: both into one file). Returns its exit status, -1 when a signal
 * ended it; fails the test when it cannot be started. */
int lx_test_run_luxel(const char *const *args, const char *out_log, const char *err_log);
/* lx_test_run_luxel that also gives the run's peak resident memory in KiB
 * (wait4's ru_maxrss of that child alone; max_rss_kb may be NULL). */
int lx_test_run_luxel_rss(const char *const *args, const char *out_log, const char *err_log,
                          long *max_rss_kb);
/* The start of the text file at path into buf (NUL-terminated; "" when it
 * cannot be read). */
void lx_test_read_text(const char *path, char *buf, size_t size);

/* The warnings the library logs while a scene loads: their count and text
 * (one a line). */
typedef struct lx_test_logbook {
    int warnings;
    char text[8192];
} lx_test_logbook;
/* The index of scene node `name`; fails the test when there is none. */
uint32_t lx_test_node_named(const lx_scene *scene, const char *name);

/* lx_scene_load(path) with the default desc; fails the test when the
 * load fails. */
lx_scene *lx_test_load(const char *path);

/* Bakes scene (desc) and applies its one lightmap into a new image,
 * asserting that the lightmap covers used_texels texels. */
lx_image lx_test_bake_applied(const lx_scene *scene, const lx_bake_desc *desc,
                              uint32_t used_texels);

/* lx_scene_load(path, desc) with its warnings kept in *book (cleared
 * first); fails the test when the load fails. */
lx_scene *lx_test_load_logged(const char *path, const lx_scene_load_desc *desc,
                              lx_test_logbook *book);

#endif
