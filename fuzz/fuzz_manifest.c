/* libFuzzer harness for the bake manifest reader: the bytes become
 * manifest.json in a folder of the harness's own and are read the way
 * `luxel render` reads them (lx_lightmaps_load with no desc, pages
 * included), then bound to a small scene (lx_lightmaps_check). The folder
 * also holds 4x4 page images (page.pfm, page.png, dir.pfm, sh0..3.pfm) so
 * manifests that name them get past the page checks into the image code.
 * Every input must end in LX_OK or a clean error, never a crash or leak. */
#define _POSIX_C_SOURCE 200809L
#include "luxel/render.h"
#include "luxel/scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char folder[64];
static char manifest[96];

static void write_page(const char *name, int channels, float value)
{
    lx_image img;
    if (lx_image_alloc(&img, 4, 4, channels) != LX_OK)
        abort();
    for (size_t i = 0; i < (size_t)16 * channels; i++)
        img.data[i] = value;
    char path[128];
    snprintf(path, sizeof path, "%s/%s", folder, name);
    if (lx_image_write(path, &img, NULL) != LX_OK)
        abort();
    lx_image_free(&img);
}

/* The folder and its images, made once per process and removed at exit. */
static void remove_folder(void)
{
    static const char *names[] = {"manifest.json", "page.pfm", "page.png", "dir.pfm",
                                  "sh0.pfm", "sh1.pfm", "sh2.pfm", "sh3.pfm"};
    char path[128];
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        snprintf(path, sizeof path, "%s/%s", folder, names[i]);
        unlink(path);
    }
    rmdir(folder);
}

static void make_folder(void)
{
    snprintf(folder, sizeof folder, "/tmp/lx_fuzz_manifest_XXXXXX");
    if (!mkdtemp(folder))
        abort();
    snprintf(manifest, sizeof manifest, "%s/manifest.json", folder);
    write_page("page.pfm", 3, 1.0f);
    write_page("page.png", 3, 0.5f);
    write_page("dir.pfm", 4, 0.5f);
    for (int c = 0; c < 4; c++) {
        char name[16];
        snprintf(name, sizeof name, "sh%d.pfm", c);
        write_page(name, 3, 0.5f);
    }
    atexit(remove_folder);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!folder[0])
        make_folder();
    FILE *fp = fopen(manifest, "wb");
    if (!fp)
        return 0;
    fwrite(data, 1, size, fp);
    fclose(fp);
    lx_lightmaps lm;
    if (lx_lightmaps_load(folder, NULL, &lm) == LX_OK) {
        /* a scene with no nodes: binding must fail cleanly, not index it */
        lx_scene *scene = NULL;
        if (lx_scene_create("fuzz.gltf", &scene) == LX_OK) {
            lx_lightmaps_check(&lm, scene);
            lx_scene_destroy(scene);
        }
        lx_lightmaps_free(&lm);
    }
    return 0;
}
