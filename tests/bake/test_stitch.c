/* UV seams (lx_uv_seams) and seam stitching (lx_bake_desc.stitch_seams):
 * - a box whose six faces are six charts has its twelve edges as seams,
 *   each side's ends at the same places of the surface; a plane of one
 *   chart has none;
 * - a lit box baked with stitching: bilinear lookups (clamp to edge, done
 *   here) on the two sides of every seam, densely along it, agree to a
 *   small share of what they differed by without stitching; texels that
 *   no lookup along a seam reads are the same bytes as without; 1 and 2
 *   threads give the same bytes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Measured on this box: the RMS mismatch falls to 0.027 of the plain
 * bake's, the worst (where three charts meet at a corner) to 0.092. */
#define STITCH_RMS_FACTOR 0.06
#define STITCH_WORST_FACTOR 0.2

/* The vertex of triangle t of m whose UV in set is uv (exactly). */
static lx_vec3 position_at(const lx_mesh *m, int set, uint32_t t, lx_vec2 uv)
{
    for (int k = 0; k < 3; k++) {
        uint32_t v = m->indices[3 * t + k];
        if (m->uv[set][v].x == uv.x && m->uv[set][v].y == uv.y)
            return m->positions[v];
    }
    fail_msg("triangle %u has no corner at UV (%g, %g)", t, (double)uv.x, (double)uv.y);
    return lx_v3(0, 0, 0);
}

static void box_edges_are_seams(void **state)
{
    (void)state;
    lx_mesh box = lx_test_box("box", lx_v3(0, 0, 0), lx_v3(1, 2, 3), false);
    lx_uv_seam *seams;
    uint32_t n;
    assert_int_equal(lx_uv_seams(&box, 1, &seams, &n), LX_OK);
    assert_int_equal(n, 12);
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 2; k++) {
            lx_vec3 pa = position_at(&box, 1, seams[i].triangle_a, seams[i].a[k]);
            lx_vec3 pb = position_at(&box, 1, seams[i].triangle_b, seams[i].b[k]);
            assert_true(pa.x == pb.x && pa.y == pb.y && pa.z == pb.z);
        }
    free(seams);
    lx_mesh plane = lx_test_plane("plane", 1.0f, 0.0f, 0.0f, 0.0f, 4);
    assert_int_equal(lx_uv_seams(&plane, 1, &seams, &n), LX_OK);
    assert_int_equal(n, 0);
    assert_null(seams);
    free(plane.uv[1]); /* now a set it lacks */
    plane.uv[1] = NULL;
    assert_int_equal(lx_uv_seams(&plane, 1, &seams, &n), LX_ERR_INVALID);
    lx_test_mesh_free(&plane);
    lx_test_mesh_free(&box);
}

/* Bilinear lookup at page UV (u, v), clamp to edge, first channel. */
static double lookup(const lx_image *img, double u, double v)
{
    double x = u * img->width - 0.5, y = v * img->height - 0.5;
    int x0 = (int)floor(x), y0 = (int)floor(y);
    double fx = x - x0, fy = y - y0, sum = 0.0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            int xx = x0 + i, yy = y0 + j;
            xx = xx < 0 ? 0 : xx >= img->width ? img->width - 1 : xx;
            yy = yy < 0 ? 0 : yy >= img->height ? img->height - 1 : yy;
            sum += (i ? fx : 1 - fx) * (j ? fy : 1 - fy) *
                   img->data[3 * ((size_t)yy * img->width + xx)];
        }
    return sum;
}

static lx_scene *lit_box(void)
{
    lx_scene *scene = lx_test_new_scene("stitch");
    lx_mesh box = lx_test_box("box", lx_v3(0, 0, 0), lx_v3(1, 1, 1), false);
    lx_test_add(scene, &box);
    lx_test_mesh_free(&box);
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "bulb");
    l.position = lx_v3(1.6f, 1.9f, 1.3f);
    l.color = lx_v3(1, 1, 1);
    l.intensity = 10.0f;
    assert_int_equal(lx_scene_add_light(scene, &l), LX_OK);
    return scene;
}

static void bake_box(lx_scene *scene, bool stitch, int threads, lx_image *out)
{
    lx_bake_desc d = {.resolution = 48, .padding = 2, .stitch_seams = stitch, .threads = threads};
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    assert_int_equal(lx_baker_apply_alloc(b, 0, out), LX_OK);
    lx_baker_destroy(b);
}

/* RMS and largest difference of the two sides' lookups over 64 points
 * along every seam. */
static void seam_mismatch(const lx_image *img, const lx_uv_seam *seams, uint32_t n, double *rms,
                          double *worst)
{
    double sum = 0.0;
    int count = 0;
    *worst = 0.0;
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k < 64; k++) {
            double t = (k + 0.5) / 64.0;
            double a = lookup(img, seams[i].a[0].x + t * (seams[i].a[1].x - seams[i].a[0].x),
                              seams[i].a[0].y + t * (seams[i].a[1].y - seams[i].a[0].y));
            double b = lookup(img, seams[i].b[0].x + t * (seams[i].b[1].x - seams[i].b[0].x),
                              seams[i].b[0].y + t * (seams[i].b[1].y - seams[i].b[0].y));
            sum += (a - b) * (a - b);
            *worst = fmax(*worst, fabs(a - b));
            count++;
        }
    *rms = sqrt(sum / count);
}

static void stitching_closes_seams(void **state)
{
    (void)state;
    lx_scene *scene = lit_box();
    lx_uv_seam *seams;
    uint32_t n;
    assert_int_equal(lx_uv_seams(&scene->meshes[0], 1, &seams, &n), LX_OK);
    lx_image plain, stitched, stitched1;
    bake_box(scene, false, 2, &plain);
    bake_box(scene, true, 2, &stitched);
    bake_box(scene, true, 1, &stitched1);
    size_t bytes = sizeof(float) * 3 * (size_t)plain.width * plain.height;
    assert_memory_equal(stitched.data, stitched1.data, bytes);
    double rms0, worst0, rms1, worst1;
    seam_mismatch(&plain, seams, n, &rms0, &worst0);
    seam_mismatch(&stitched, seams, n, &rms1, &worst1);
    printf("seams: RMS mismatch %.4g -> %.4g (x%.3g), worst %.4g -> %.4g\n", rms0, rms1,
           rms1 / rms0, worst0, worst1);
    assert_true(rms0 > 0.01); /* the light does change across the box's edges */
    assert_true(rms1 < STITCH_RMS_FACTOR * rms0);
    assert_true(worst1 < STITCH_WORST_FACTOR * worst0);
    /* texels two or more texels from every seam's lookups are untouched */
    int w = plain.width, h = plain.height;
    uint8_t *near = calloc((size_t)w * h, 1);
    for (uint32_t i = 0; i < n; i++)
        for (int k = 0; k <= 256; k++) {
            double t = k / 256.0;
            for (int side = 0; side < 2; side++) {
                const lx_vec2 *e = side ? seams[i].b : seams[i].a;
                double x = (e[0].x + t * (e[1].x - e[0].x)) * w - 0.5;
                double y = (e[0].y + t * (e[1].y - e[0].y)) * h - 0.5;
                for (int dy = -1; dy <= 2; dy++)
                    for (int dx = -1; dx <= 2; dx++) {
                        int xx = (int)floor(x) + dx, yy = (int)floor(y) + dy;
                        if (xx >= 0 && yy >= 0 && xx < w && yy < h)
                            near[(size_t)yy * w + xx] = 1;
                    }
            }
        }
    int far = 0;
    for (int p = 0; p < w * h; p++)
        if (!near[p]) {
            far++;
            assert_memory_equal(&plain.data[3 * p], &stitched.data[3 * p], 3 * sizeof(float));
        }
    printf("%d of %d texels away from the seams\n", far, w * h);
    assert_true(far > w * h / 4);
    free(near);
    free(seams);
    lx_image_free(&plain);
    lx_image_free(&stitched);
    lx_image_free(&stitched1);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(box_edges_are_seams),
        cmocka_unit_test(stitching_closes_seams),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
