/* The memory a texture costs a bake (docs/bake.md, "Textures"). A 10 m
 * quad with a 4096 x 4096 JPEG base colour, baked by `luxel bake
 * --ambient 1000 --texel-density 10 --quantity radiance` (100 x 100
 * texels), once peaked at 540 MB, most of it float copies of the texture
 * at its file's size. Now:
 *
 * - the peak resident memory of the run (wait4's ru_maxrss of the child)
 *   stays within the same bake of the quad without a texture plus what
 *   docs/bake.md states a texture costs while it loads: its file, 2 bytes
 *   per decoded 8-bit sample (stb's samples and its own buffers) and 32
 *   bytes a pixel kept, the pixels kept worked out here from the rule in
 *   scene.h (the quad's world and UV areas, the density, and
 *   LX_TEXTURE_TEXELS_PER_TEXEL / LX_TEXTURE_MIN_PIXELS);
 * - the texture is still read, at its right colour: the lightmap's mean
 *   radiance is E rho / pi with E = 1000 lx and rho the mean linear
 *   albedo of the JPEG as stb decodes it, through the IEC sRGB curve
 *   written out here (within 1%).
 *
 * The CLI is the `luxel` next to this test's executable. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "texture_oracle.h"

#include <limits.h>
#include <math.h>
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#define TEX 4096
#define SIDE 10.0     /* metres */
#define DENSITY 10.0  /* texels per metre */
#define AMBIENT 1000.0 /* lux */

static const double PI = 3.14159265358979323846;

static char dir[PATH_MAX];

/* The quad, its UV sets the unit square, with or without the texture. */
static void write_quad(const char *name, bool textured)
{
    lx_test_quad q = {.o = {-SIDE / 2, 0, SIDE / 2},
                      .e1 = {SIDE, 0, 0},
                      .e2 = {0, 0, -SIDE},
                      .uv = {{{0, 0}, {1, 0}, {0, 1}}, {{0, 0}, {1, 0}, {0, 1}}}};
    const char *uris[] = {"albedo.jpg"};
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    lx_test_write_quad_gltf(path, &q,
                            textured ? "{\"name\":\"m\",\"pbrMetallicRoughness\":"
                                       "{\"baseColorTexture\":{\"index\":0}}}"
                                     : "{\"name\":\"m\"}",
                            uris, textured ? 1 : 0, NULL);
}

/* A smooth 4096 x 4096 RGB JPEG (quality 90), written by a child process:
 * Linux counts the memory this process ever held in the ru_maxrss of the
 * children it starts (exec records the old address space's peak), so the
 * 48 MiB of pixels must never be this process's. Returns the file's size. */
static long write_texture(void)
{
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/albedo.jpg", dir);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        uint8_t *px = malloc((size_t)TEX * TEX * 3);
        if (!px)
            _exit(1);
        for (int y = 0; y < TEX; y++)
            for (int x = 0; x < TEX; x++) {
                uint8_t *p = px + 3 * ((size_t)y * TEX + x);
                p[0] = (uint8_t)(30 + x * 200 / TEX);
                p[1] = (uint8_t)(60 + y * 150 / TEX);
                p[2] = (uint8_t)(128 + 100 * sin(2 * PI * (x + y) / (double)TEX));
            }
        _exit(stbi_write_jpg(path, TEX, TEX, 3, px, 90) ? 0 : 1);
    }
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    return (long)st.st_size;
}

/* The mean linear albedo of the JPEG as decoded, per channel. */
static void texture_mean(double mean[3])
{
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/albedo.jpg", dir);
    int w, h, c;
    uint8_t *px = stbi_load(path, &w, &h, &c, 3);
    assert_non_null(px);
    double sum[3] = {0, 0, 0};
    for (size_t i = 0; i < (size_t)w * h; i++)
        for (int k = 0; k < 3; k++)
            sum[k] += lx_test_srgb_decode(px[3 * i + k]);
    for (int k = 0; k < 3; k++)
        mean[k] = sum[k] / ((double)w * h);
    stbi_image_free(px);
}

/* Bakes name into out; returns the run's peak resident memory in bytes. */
static double bake(const char *name, const char *out)
{
    char scene[PATH_MAX + 64], output[PATH_MAX + 64], log[PATH_MAX + 64];
    snprintf(scene, sizeof scene, "%s/%s", dir, name);
    snprintf(output, sizeof output, "%s/%s", dir, out);
    snprintf(log, sizeof log, "%s/%s.log", dir, out);
    const char *args[] = {"bake",        scene,    "--ambient", "1000", "--texel-density", "10",
                          "--quantity",  "radiance", "--threads", "1",    "--format",        "pfm",
                          "-q",          "-o",     output,      NULL};
    long kb = 0;
    int rc = lx_test_run_luxel_rss(args, log, log, &kb);
    if (rc != 0) {
        char text[2048];
        lx_test_read_text(log, text, sizeof text);
        fail_msg("luxel bake %s: exit %d: %s", name, rc, text);
    }
    return (double)kb * 1024.0;
}

static void test_texture_memory(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("cli_texture_memory"));
    long file = write_texture();
    write_quad("plain.gltf", false);
    write_quad("textured.gltf", true);
    double plain = bake("plain.gltf", "plain_out");
    double textured = bake("textured.gltf", "textured_out");

    /* the pixels kept (scene.h's rule): k^2 density^2 x world area over
     * the UV area, at least LX_TEXTURE_MIN_PIXELS, by halvings from 4096 */
    double k = LX_TEXTURE_TEXELS_PER_TEXEL;
    double need = k * k * DENSITY * DENSITY * SIDE * SIDE / 1.0;
    if (need < (double)LX_TEXTURE_MIN_PIXELS)
        need = (double)LX_TEXTURE_MIN_PIXELS;
    double kept = (double)TEX * TEX;
    while (kept / 4.0 >= need)
        kept /= 4.0;
    /* docs/bake.md: the file, 2 bytes a decoded 8-bit sample, 32 bytes a
     * kept pixel while it loads */
    double texture = (double)file + 2.0 * TEX * TEX * 3 + 32.0 * kept;
    printf("peak: %.1f MiB without the texture, %.1f MiB with it; bound %.1f MiB "
           "(texture %.1f MiB: %.0f pixels kept)\n",
           plain / 1048576.0, textured / 1048576.0, (plain + texture) / 1048576.0,
           texture / 1048576.0, kept);
    if (textured > plain + texture)
        fail_msg("the textured bake peaked at %.1f MiB, above the %.1f MiB docs/bake.md allows",
                 textured / 1048576.0, (plain + texture) / 1048576.0);

    /* the texture read at its colour: mean radiance E rho / pi */
    double rho[3];
    texture_mean(rho);
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s/textured_out/quad.pfm", dir);
    lx_image img;
    if (lx_image_load(path, NULL, &img) != LX_OK)
        fail_msg("%s", lx_last_error());
    double sum[3] = {0, 0, 0};
    size_t n = (size_t)img.width * img.height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            sum[c] += img.data[i * (size_t)img.channels + c];
    for (int c = 0; c < 3; c++) {
        double want = AMBIENT * rho[c] / PI;
        printf("channel %d: mean radiance %.3f nits, E rho / pi = %.3f\n", c, sum[c] / n, want);
        lx_test_assert_rel(sum[c] / n, want, 0.01);
    }
    lx_image_free(&img);
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_texture_memory),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
