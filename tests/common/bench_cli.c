/* Helpers of bench_bake's whole-process case (see bench_cli.h). */
#define _POSIX_C_SOURCE 200809L
#include "bench_cli.h"
#include "scenes.h"

#include <OpenEXR/openexr.h>
#include <fcntl.h>
#include <math.h>
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

/* ---- child processes ------------------------------------------------------ */

void lx_bench_sibling(const char *name, char *out, size_t size)
{
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0)
        lx_bench_die("readlink /proc/self/exe");
    self[n] = '\0';
    char *slash = strrchr(self, '/');
    if (slash)
        *slash = '\0';
    snprintf(out, size, "%s/%s", self, name);
}

lx_scene *lx_bench_load_room(const char *program, const char **path)
{
    char room[4200] = "", dir[256], cmd[8500];
    if (!*path) {
        char gen[4096];
        lx_bench_sibling("gen_scenes", gen, sizeof gen);
        snprintf(dir, sizeof dir, "/tmp/%s.XXXXXX", program);
        if (!mkdtemp(dir))
            lx_bench_die("mkdtemp");
        snprintf(cmd, sizeof cmd, "'%s' '%s' >/dev/null", gen, dir);
        if (system(cmd) != 0) {
            fprintf(stderr, "%s: %s failed\n", program, cmd);
            exit(1);
        }
        snprintf(room, sizeof room, "%s/room.glb", dir);
    }
    lx_scene *scene;
    if (lx_scene_load(room[0] ? room : *path, NULL, &scene) != LX_OK)
        lx_bench_die(room[0] ? room : *path);
    if (room[0]) {
        /* the generated files are no longer needed */
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "%s: could not remove %s\n", program, dir);
        *path = "room (gen_scenes)";
    }
    return scene;
}

int lx_bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double lx_bench_run_child(char *const argv[], const char *log)
{
    fflush(stdout);
    double t0 = lx_bench_now();
    pid_t pid = fork();
    if (pid < 0)
        lx_bench_die("fork");
    if (pid == 0) {
        /* the CLI's warnings (the occluders have no UVs) go to a file */
        int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 2);
            close(fd);
        }
        execv(argv[0], argv);
        _exit(127);
    }
    int status;
    if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fprintf(stderr, "bench: %s %s failed (status %d); its messages are in %s\n", argv[0],
                argv[1], status, log);
        exit(1);
    }
    return lx_bench_now() - t0;
}

/* ---- the phases of luxel bake --------------------------------------------- */

const char *const lx_bench_phase_names[LX_BENCH_PHASES] = {"import (assimp + lights JSON)",
                                                           "texel maps",
                                                           "BVH (Embree)",
                                                           "bake (static lights)",
                                                           "dynamic lights",
                                                           "apply + exposure meter",
                                                           "EXR encode + write",
                                                           "PNG encode + write"};

void lx_bench_phases_min(lx_bench_phases *best, const lx_bench_phases *p)
{
    best->import = fmin(best->import, p->import);
    best->texel_maps = fmin(best->texel_maps, p->texel_maps);
    best->bvh = fmin(best->bvh, p->bvh);
    best->bake = fmin(best->bake, p->bake);
    best->dynamic = fmin(best->dynamic, p->dynamic);
    best->apply = fmin(best->apply, p->apply);
    best->exr = fmin(best->exr, p->exr);
    best->png = fmin(best->png, p->png);
}

/* lx_baker_create reports progress after each node's texel map, then
 * builds the BVH: the last report's time splits the two. */
static bool note_progress(void *user, float done)
{
    (void)done;
    *(double *)user = lx_bench_now();
    return true;
}

void lx_bench_phases_child(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--phases-child") != 0)
        return;
    if (argc != 7)
        exit(2);
    const char *glb = argv[2], *json = argv[3], *dir = argv[4];
    int res = atoi(argv[5]);
    int threads = atoi(argv[6]);
    double t0 = lx_bench_now();
    lx_scene *scene;
    if (lx_scene_load(glb, NULL, &scene) != LX_OK || lx_lights_json_apply(scene, json) != LX_OK)
        lx_bench_die("load");
    double t1 = lx_bench_now(), t_maps = t1;
    lx_bake_desc desc = lx_bake_desc_defaults(NULL);
    desc.resolution = res;
    desc.threads = threads;
    desc.padding = LX_PADDING_RECOMMENDED;
    desc.progress = note_progress;
    desc.progress_user = &t_maps;
    lx_baker *b;
    if (lx_baker_create(scene, &desc, &b) != LX_OK)
        lx_bench_die("lx_baker_create");
    double t2 = lx_bench_now(), maps_end = t_maps; /* the bake reports progress too */
    if (lx_baker_bake(b) != LX_OK)
        lx_bench_die("lx_baker_bake");
    double t3 = lx_bench_now();
    if (lx_baker_update(b) != LX_OK)
        lx_bench_die("lx_baker_update");
    double t4 = lx_bench_now();
    lx_image img;
    if (lx_baker_apply_alloc(b, 0, &img) != LX_OK)
        lx_bench_die("lx_baker_apply_alloc");
    float ev;
    bool lit;
    lx_baker_meter_ev100(b, &ev, &lit);
    double t5 = lx_bench_now();
    char path[1100];
    snprintf(path, sizeof path, "%s/phase.exr", dir);
    lx_image_write_desc wd = {.format = LX_IMAGE_EXR, .threads = threads};
    if (lx_image_write(path, &img, &wd) != LX_OK)
        lx_bench_die("lx_image_write exr");
    double t6 = lx_bench_now();
    snprintf(path, sizeof path, "%s/phase.png", dir);
    lx_image_write_desc pd = {
        .format = LX_IMAGE_PNG, .exposure = lx_exposure_from_ev100(ev) / LX_PI, .threads = threads};
    if (lx_image_write(path, &img, &pd) != LX_OK)
        lx_bench_die("lx_image_write png");
    double t7 = lx_bench_now();
    printf("%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", t1 - t0, maps_end - t1, t2 - maps_end,
           t3 - t2, t4 - t3, t5 - t4, t6 - t5, t7 - t6);
    fflush(stdout);
    _exit(0); /* like the CLI, but the freeing is not a phase */
}

void lx_bench_phases_run(const char *glb, const char *json, const char *dir, int res, int threads,
                         lx_bench_phases *ph)
{
    char self[4096];
    ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
    if (len <= 0)
        lx_bench_die("readlink /proc/self/exe");
    self[len] = '\0';
    int fd[2];
    if (pipe(fd) != 0)
        lx_bench_die("pipe");
    char res_s[16], thr_s[16];
    snprintf(res_s, sizeof res_s, "%d", res);
    snprintf(thr_s, sizeof thr_s, "%d", threads);
    fflush(stdout);
    pid_t pid = fork();
    if (pid < 0)
        lx_bench_die("fork");
    if (pid == 0) {
        dup2(fd[1], 1);
        close(fd[0]);
        close(fd[1]);
        execl(self, self, "--phases-child", glb, json, dir, res_s, thr_s, (char *)NULL);
        _exit(127);
    }
    close(fd[1]);
    FILE *in = fdopen(fd[0], "r");
    double *v = &ph->import;
    int got = 0;
    for (int k = 0; k < 8 && in; k++)
        got += fscanf(in, "%lf", &v[k]) == 1;
    if (in)
        fclose(in);
    int status;
    if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0 ||
        got != 8) {
        fprintf(stderr, "bench: the phase-timing child failed (status %d)\n", status);
        exit(1);
    }
}

/* ---- the writers luxel had ----------------------------------------------- */

typedef struct file_sink {
    FILE *fp;
    uint64_t pos;
} file_sink;

static int64_t sink_write(exr_const_context_t ctxt, void *user, const void *buffer, uint64_t sz,
                          uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    (void)ctxt;
    (void)error_cb;
    file_sink *o = user;
    if (fseeko(o->fp, (off_t)offset, SEEK_SET) != 0 || fwrite(buffer, 1, sz, o->fp) != sz)
        return -1;
    return (int64_t)sz;
}

static void close_synced(FILE *fp)
{
    if (fflush(fp) != 0 || fsync(fileno(fp)) != 0 || fclose(fp) != 0)
        lx_bench_die("closing a baseline file");
}

double lx_bench_old_exr(const lx_image *img, const char *path)
{
    double t0 = lx_bench_now();
    size_t plane = (size_t)img->width * img->height;
    float *planes = malloc(plane * 3 * sizeof(float));
    if (!planes)
        lx_bench_die("malloc");
    for (int k = 0; k < 3; k++) /* B, G, R: file order */
        for (size_t i = 0; i < plane; i++)
            planes[(size_t)k * plane + i] = img->data[3 * i + (2 - k)];
    file_sink o = {fopen(path, "wb"), 0};
    if (!o.fp)
        lx_bench_die(path);
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = &o;
    init.write_fn = sink_write;
    exr_context_t ctx;
    int part;
    static const char *names[3] = {"B", "G", "R"};
    bool ok = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init) == EXR_ERR_SUCCESS &&
              exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part) == EXR_ERR_SUCCESS &&
              exr_initialize_required_attr_simple(ctx, part, img->width, img->height,
                                                  EXR_COMPRESSION_ZIP) == EXR_ERR_SUCCESS;
    for (int k = 0; k < 3 && ok; k++)
        ok = exr_add_channel(ctx, part, names[k], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1,
                             1) == EXR_ERR_SUCCESS;
    ok = ok && exr_write_header(ctx) == EXR_ERR_SUCCESS;
    int32_t lines = 16;
    ok = ok && exr_get_scanlines_per_chunk(ctx, part, &lines) == EXR_ERR_SUCCESS;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    for (int y = 0; y < img->height && ok; y += lines) {
        exr_chunk_info_t ci;
        ok = exr_write_scanline_chunk_info(ctx, part, y, &ci) == EXR_ERR_SUCCESS &&
             (y ? exr_encoding_update(ctx, part, &ci, &enc)
                : exr_encoding_initialize(ctx, part, &ci, &enc)) == EXR_ERR_SUCCESS;
        for (int c = 0; c < enc.channel_count && ok; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int k = ch->channel_name[0] == 'B' ? 0 : ch->channel_name[0] == 'G' ? 1 : 2;
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 4;
            ch->user_line_stride = img->width * 4;
            ch->encode_from_ptr =
                (const uint8_t *)(planes + (size_t)k * plane + (size_t)y * img->width);
        }
        if (ok && y == 0)
            ok = exr_encoding_choose_default_routines(ctx, part, &enc) == EXR_ERR_SUCCESS;
        ok = ok && exr_encoding_run(ctx, part, &enc) == EXR_ERR_SUCCESS;
    }
    exr_encoding_destroy(ctx, &enc);
    ok = exr_finish(&ctx) == EXR_ERR_SUCCESS && ok;
    free(planes);
    if (!ok)
        lx_bench_die("the baseline EXR writer");
    close_synced(o.fp);
    return lx_bench_now() - t0;
}

static void stb_sink(void *context, void *data, int size)
{
    fwrite(data, 1, (size_t)size, (FILE *)context);
}

double lx_bench_old_png(const lx_image *img, float exposure, const char *path)
{
    double t0 = lx_bench_now();
    double th[255];
    for (int k = 1; k <= 255; k++) {
        double c = ((double)k - 0.5) / 255.0;
        th[k - 1] = c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
    }
    size_t n = (size_t)img->width * img->height * 3;
    unsigned char *bytes = malloc(n);
    if (!bytes)
        lx_bench_die("malloc");
    for (size_t i = 0; i < n; i++) {
        double v = (double)(img->data[i] * exposure);
        int lo = 0, hi = 255;
        while (lo < hi) {
            int mid = (lo + hi + 1) / 2;
            if (v >= th[mid - 1])
                lo = mid;
            else
                hi = mid - 1;
        }
        bytes[i] = (unsigned char)lo;
    }
    FILE *fp = fopen(path, "wb");
    if (!fp ||
        !stbi_write_png_to_func(stb_sink, fp, img->width, img->height, 3, bytes, img->width * 3))
        lx_bench_die("the baseline PNG writer");
    close_synced(fp);
    free(bytes);
    return lx_bench_now() - t0;
}

long lx_bench_file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? (long)st.st_size : -1;
}
