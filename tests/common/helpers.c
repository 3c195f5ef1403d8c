/* Helpers shared by luxel's tests. */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE /* wait4 */
#include "helpers.h"
#include "core/internal.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>

#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

static void mkdirs(const char *path)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = buf + 1; *p; p++)
        if (*p == '/') {
            *p = '\0';
            mkdir(buf, 0777);
            *p = '/';
        }
    mkdir(buf, 0777);
}

static void remove_tree(const char *path)
{
    DIR *d = opendir(path);
    if (!d)
        return;
    struct dirent *e;
    char child[2048];
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(child, sizeof child, "%s/%s", path, e->d_name);
        struct stat st;
        if (lstat(child, &st) == 0 && S_ISDIR(st.st_mode))
            remove_tree(child);
        else
            unlink(child);
    }
    closedir(d);
    rmdir(path);
}

const char *lx_test_dir(const char *tag)
{
    static char path[1024];
    const char *base = getenv("LX_TEST_TMP");
    snprintf(path, sizeof path, "%s/%s", base && base[0] ? base : "/tmp/luxel-test", tag);
    remove_tree(path);
    mkdirs(path);
    return path;
}

int lx_test_count_files(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            n++;
    closedir(d);
    return n;
}

lx_mesh lx_test_plane(const char *name, float size, float height, float cx, float cz, int n)
{
    lx_mesh m = {0};
    m.name = lx_strdup(name);
    m.vertex_count = (uint32_t)((n + 1) * (n + 1));
    m.triangle_count = (uint32_t)(2 * n * n);
    m.positions = malloc(sizeof(lx_vec3) * m.vertex_count);
    m.normals = malloc(sizeof(lx_vec3) * m.vertex_count);
    m.uv[0] = malloc(sizeof(lx_vec2) * m.vertex_count);
    m.uv[1] = malloc(sizeof(lx_vec2) * m.vertex_count);
    m.indices = malloc(sizeof(uint32_t) * 3 * m.triangle_count);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            uint32_t v = (uint32_t)(j * (n + 1) + i);
            float u = (float)i / n, w = (float)j / n;
            m.positions[v] = lx_v3(cx - size / 2 + u * size, height, cz - size / 2 + w * size);
            m.normals[v] = lx_v3(0, 1, 0);
            m.uv[0][v] = m.uv[1][v] = lx_v2(u, w);
        }
    uint32_t t = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + 1, c = a + (uint32_t)(n + 1),
                     d = c + 1;
            /* counter-clockwise seen from +Y: a, c, b and b, c, d */
            uint32_t tri[6] = {a, c, b, b, c, d};
            memcpy(&m.indices[3 * t], tri, sizeof tri);
            t += 2;
        }
    return m;
}

lx_mesh lx_test_box(const char *name, lx_vec3 lo, lx_vec3 hi, bool inward)
{
    lx_mesh m = {0};
    m.name = lx_strdup(name);
    m.vertex_count = 24;
    m.triangle_count = 12;
    m.positions = malloc(sizeof(lx_vec3) * 24);
    m.normals = malloc(sizeof(lx_vec3) * 24);
    m.uv[0] = malloc(sizeof(lx_vec2) * 24);
    m.uv[1] = malloc(sizeof(lx_vec2) * 24);
    m.indices = malloc(sizeof(uint32_t) * 36);
    /* each face: outward normal n, and axes s, t with s x t = n */
    const lx_vec3 normals[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    for (int f = 0; f < 6; f++) {
        lx_vec3 n = normals[f];
        lx_vec3 s = fabsf(n.y) > 0.5f ? lx_v3(1, 0, 0) : lx_v3(0, 1, 0);
        lx_vec3 t = lx_cross(n, s);
        s = lx_cross(t, n);
        lx_vec3 c = lx_scale(lx_add(lo, hi), 0.5f), e = lx_scale(lx_sub(hi, lo), 0.5f);
        lx_vec3 centre = lx_add(c, lx_mul(n, e));
        const float cs[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int k = 0; k < 4; k++) {
            lx_vec3 p = lx_add(
                centre, lx_add(lx_mul(lx_scale(s, cs[k][0]), e), lx_mul(lx_scale(t, cs[k][1]), e)));
            int v = f * 4 + k;
            m.positions[v] = p;
            m.normals[v] = inward ? lx_neg(n) : n;
            /* 3x2 grid of charts with a gutter */
            float cu = (float)(f % 3) / 3.0f, cv = (float)(f / 3) / 2.0f;
            float u = cu + (0.05f + 0.9f * (cs[k][0] + 1) / 2) / 3.0f;
            float w = cv + (0.05f + 0.9f * (cs[k][1] + 1) / 2) / 2.0f;
            m.uv[0][v] = m.uv[1][v] = lx_v2(u, w);
        }
        uint32_t b = (uint32_t)f * 4;
        uint32_t out[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        uint32_t in[6] = {b, b + 2, b + 1, b, b + 3, b + 2};
        memcpy(&m.indices[6 * f], inward ? in : out, sizeof out);
    }
    return m;
}

void lx_test_mesh_free(lx_mesh *m)
{
    free(m->name);
    free(m->positions);
    free(m->normals);
    free(m->tangents);
    for (int k = 0; k < LX_MAX_UV_SETS; k++)
        free(m->uv[k]);
    free(m->indices);
    memset(m, 0, sizeof *m);
}

void lx_test_add(lx_scene *scene, lx_mesh *mesh)
{
    if (scene->material_count == 0) {
        lx_material mat = {.name = "white", .base_color = {1, 1, 1, 1}};
        lx_scene_add_material(scene, &mat, NULL);
    }
    uint32_t idx;
    if (lx_scene_add_mesh(scene, mesh, &idx) != LX_OK) {
        fprintf(stderr, "lx_test_add: %s\n", lx_last_error());
        abort();
    }
    lx_mat4 id = lx_mat4_identity();
    if (lx_scene_add_node(scene, mesh->name, &id, &idx, 1, NULL) != LX_OK) {
        fprintf(stderr, "lx_test_add: %s\n", lx_last_error());
        abort();
    }
}

static void watchdog_fired(int sig)
{
    (void)sig;
    static const char msg[] = "lx_test_watchdog: the test did not finish in time (hang?)\n";
    ssize_t r = write(2, msg, sizeof msg - 1);
    (void)r;
    _exit(1);
}

void lx_test_watchdog(unsigned seconds)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = watchdog_fired;
    sigaction(SIGALRM, &sa, NULL);
    alarm(seconds);
}

lx_scene *lx_test_new_scene(const char *name)
{
    lx_scene *s = NULL;
    if (lx_scene_create(name, &s) != LX_OK)
        fail_msg("lx_scene_create: %s", lx_last_error());
    return s;
}

void lx_test_assert_vec3(lx_vec3 v, double x, double y, double z)
{
    if (!(fabs(v.x - x) <= 4e-7 * fmax(1.0, fabs(x)) &&
          fabs(v.y - y) <= 4e-7 * fmax(1.0, fabs(y)) && fabs(v.z - z) <= 4e-7 * fmax(1.0, fabs(z))))
        fail_msg("got [%g, %g, %g], want [%g, %g, %g]", v.x, v.y, v.z, x, y, z);
}

uint32_t lx_test_map_of(const lx_baker *b, uint32_t node)
{
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++)
        if (lx_baker_lightmap_info(b, m)->node == node)
            return m;
    fail_msg("no lightmap for node %u", node);
    return UINT32_MAX;
}

void lx_test_assert_rel(double got, double want, double tol)
{
    double scale = fabs(want) > 1e-30 ? fabs(want) : 1.0;
    if (!(fabs(got - want) <= tol * scale))
        fail_msg("got %.9g, want %.9g (relative tolerance %g)", got, want, tol);
}

lx_ies_profile *lx_test_parse_ies(const char *text)
{
    lx_ies_profile *p = NULL;
    lx_status st = lx_ies_parse(text, strlen(text), "t.ies", &p);
    if (st != LX_OK)
        fail_msg("parse failed: %s: %s", lx_status_name(st), lx_last_error());
    assert_non_null(p);
    return p;
}

uint32_t lx_test_grey_material(lx_scene *scene, const char *name, float rho, float le)
{
    lx_material mat = {.name = (char *)name,
                       .base_color = {rho, rho, rho, 1.0f},
                       .emissive = {le, le, le},
                       .normal_scale = 1.0f};
    uint32_t idx;
    assert_int_equal(lx_scene_add_material(scene, &mat, &idx), LX_OK);
    return idx;
}

void lx_test_add_with_material(lx_scene *scene, lx_mesh *mesh, uint32_t material)
{
    mesh->material = material;
    lx_test_add(scene, mesh);
    lx_test_mesh_free(mesh);
}

double lx_test_corner_form_factor(double a, double b, double c)
{
    double x = a / c, y = b / c;
    double sx = sqrt(1.0 + x * x), sy = sqrt(1.0 + y * y);
    return (x / sx * atan(y / sx) + y / sy * atan(x / sy)) / (2.0 * 3.14159265358979323846);
}

void lx_test_sibling(const char *name, char *out, size_t size)
{
    char self[4096];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    assert_true(len > 0);
    self[len] = '\0';
    char *slash = strrchr(self, '/');
    assert_non_null(slash);
    *slash = '\0';
    snprintf(out, size, "%s/%s", self, name);
    if (access(out, X_OK) != 0)
        fail_msg("no %s executable next to the test: %s", name, out);
}

int lx_test_run_luxel(const char *const *args, const char *out_log, const char *err_log)
{
    return lx_test_run_luxel_rss(args, out_log, err_log, NULL);
}

int lx_test_run_luxel_rss(const char *const *args, const char *out_log, const char *err_log,
                          long *max_rss_kb)
{
    char luxel[4096];
    lx_test_sibling("luxel", luxel, sizeof luxel);
    const char *argv[64] = {luxel};
    int n = 1;
    for (; *args && n < 63; args++)
        argv[n++] = *args;
    argv[n] = NULL;
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, out_log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (strcmp(out_log, err_log) == 0)
        posix_spawn_file_actions_adddup2(&fa, 1, 2);
    else
        posix_spawn_file_actions_addopen(&fa, 2, err_log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid;
    int rc = posix_spawn(&pid, luxel, &fa, NULL, (char *const *)argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0)
        fail_msg("cannot run %s", luxel);
    int status;
    struct rusage ru;
    assert_int_equal(wait4(pid, &status, 0, &ru), pid);
    if (max_rss_kb)
        *max_rss_kb = ru.ru_maxrss; /* kilobytes on Linux */
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

void lx_test_read_text(const char *path, char *buf, size_t size)
{
    FILE *f = fopen(path, "r");
    size_t got = f ? fread(buf, 1, size - 1, f) : 0;
    buf[got] = '\0';
    if (f)
        fclose(f);
}

static void log_to_book(void *user, lx_log_level level, const char *message)
{
    lx_test_logbook *b = user;
    if (level != LX_LOG_WARN)
        return;
    b->warnings++;
    size_t n = strlen(b->text);
    snprintf(b->text + n, sizeof b->text - n, "%s\n", message);
}

lx_scene *lx_test_load_logged(const char *path, const lx_scene_load_desc *desc,
                              lx_test_logbook *book)
{
    memset(book, 0, sizeof *book);
    lx_set_log_callback(log_to_book, book);
    lx_scene *s = NULL;
    lx_status st = lx_scene_load(path, desc, &s);
    lx_set_log_callback(NULL, NULL);
    if (st != LX_OK)
        fail_msg("lx_scene_load(%s): %s", path, lx_last_error());
    return s;
}

lx_scene *lx_test_load(const char *path)
{
    lx_scene *scene = NULL;
    if (lx_scene_load(path, NULL, &scene) != LX_OK)
        fail_msg("%s: %s", path, lx_last_error());
    return scene;
}

lx_image lx_test_bake_applied(const lx_scene *scene, const lx_bake_desc *desc,
                              uint32_t used_texels)
{
    lx_baker *baker;
    if (lx_baker_create(scene, desc, &baker) != LX_OK)
        fail_msg("lx_baker_create: %s", lx_last_error());
    assert_int_equal(lx_baker_lightmap_count(baker), 1);
    assert_int_equal(lx_baker_lightmap_info(baker, 0)->used_texels, used_texels);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(baker, 0, &img), LX_OK);
    lx_baker_destroy(baker);
    return img;
}

uint32_t lx_test_node_named(const lx_scene *scene, const char *name)
{
    for (uint32_t i = 0; i < scene->node_count; i++)
        if (strcmp(scene->nodes[i].name, name) == 0)
            return i;
    fail_msg("no node named '%s'", name);
    return 0;
}
