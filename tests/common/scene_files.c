/* Scene files written by tests and a fingerprint of a loaded scene
 * (scene_files.h). */
#include "scene_files.h"

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

void lx_test_write_obj_grid(const char *path, const char *name, int n)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "o %s\n", name);
    for (int y = 0; y <= n; y++)
        for (int x = 0; x <= n; x++)
            fprintf(f, "v %g %g %g\n", x * 0.1, 0.02 * ((x * 7 + y * 13) % 5), y * 0.1);
    for (int y = 0; y <= n; y++)
        for (int x = 0; x <= n; x++)
            fprintf(f, "vt %g %g\n", x / (double)n, y / (double)n);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            int a = y * (n + 1) + x + 1, b = a + 1, c = a + n + 1, d = c + 1;
            fprintf(f, "f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n", a, a, c, c, b, b, b, b, c, c,
                    d, d);
        }
    assert_int_equal(fclose(f), 0);
}

static uint64_t fnv(uint64_t h, const void *data, size_t size)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; i++)
        h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

static uint64_t fnv_str(uint64_t h, const char *s)
{
    return s ? fnv(h, s, strlen(s) + 1) : fnv(h, "", 1);
}

uint64_t lx_test_scene_digest(const lx_scene *s)
{
    uint64_t h = 0xcbf29ce484222325ull;
    h = fnv(h, &s->mesh_count, sizeof s->mesh_count);
    for (uint32_t i = 0; i < s->mesh_count; i++) {
        const lx_mesh *m = &s->meshes[i];
        size_t nv = m->vertex_count;
        h = fnv_str(h, m->name);
        h = fnv(h, &m->vertex_count, sizeof m->vertex_count);
        h = fnv(h, &m->triangle_count, sizeof m->triangle_count);
        h = fnv(h, m->positions, nv * sizeof *m->positions);
        h = fnv(h, m->normals, nv * sizeof *m->normals);
        if (m->tangents)
            h = fnv(h, m->tangents, nv * sizeof *m->tangents);
        for (int k = 0; k < LX_MAX_UV_SETS; k++)
            if (m->uv[k])
                h = fnv(h, m->uv[k], nv * sizeof *m->uv[k]);
        h = fnv(h, m->indices, 3 * (size_t)m->triangle_count * sizeof *m->indices);
        h = fnv(h, &m->material, sizeof m->material);
    }
    h = fnv(h, &s->node_count, sizeof s->node_count);
    for (uint32_t i = 0; i < s->node_count; i++) {
        const lx_node *n = &s->nodes[i];
        h = fnv_str(h, n->name);
        h = fnv(h, &n->world, sizeof n->world);
        h = fnv(h, n->meshes, n->mesh_count * sizeof *n->meshes);
    }
    h = fnv(h, &s->material_count, sizeof s->material_count);
    for (uint32_t i = 0; i < s->material_count; i++)
        h = fnv_str(h, s->materials[i].name);
    return h;
}
