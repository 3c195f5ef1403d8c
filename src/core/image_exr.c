/* OpenEXR reading and writing through OpenEXR 3's C API, OpenEXRCore (see
 * openexr.com, "Reading and Writing Image Files with the C-language API").
 * Reads part 0 of scanline or tiled files (level 0), channels R, G, B, A or
 * Y, A; writes one scanline part: 32-bit floats uncompressed, half floats
 * with ZIP, its chunks encoded on several threads (one encode pipeline per
 * thread, as OpenEXRCore's pipelines are meant to be used) and written in
 * order. Half floats are converted with round-to-nearest-even (IEEE
 * 754-2008 binary16). */
#define _POSIX_C_SOURCE 200809L
#include "image_internal.h"

#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include <openexr.h>

/* OpenEXRCore reports details through a callback (its default prints to
 * stderr, which a library must not do); the last one is kept for the
 * message luxel returns. */
static _Thread_local char exr_detail[512];

static void exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    snprintf(exr_detail, sizeof exr_detail, "%s", msg ? msg : exr_get_default_error_message(code));
}

static lx_status exr_failure(exr_result_t rv, lx_status status, const char *name, const char *doing)
{
    const char *detail = exr_detail[0] ? exr_detail : exr_get_default_error_message(rv);
    if (rv == EXR_ERR_OUT_OF_MEMORY)
        status = LX_ERR_NOMEM;
    return lx_fail(status, "%s: %s: %s", name, doing, detail);
}

/* ---- reading ------------------------------------------------------------- */

typedef struct exr_memory {
    const unsigned char *data;
    size_t size;
} exr_memory;

static int64_t memory_read(exr_const_context_t ctxt, void *user, void *buffer, uint64_t sz,
                           uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    (void)ctxt;
    (void)error_cb;
    const exr_memory *m = user;
    if (offset >= m->size)
        return 0;
    uint64_t n = m->size - offset;
    if (n > sz)
        n = sz;
    memcpy(buffer, m->data + offset, (size_t)n);
    return (int64_t)n;
}

static int64_t memory_size(exr_const_context_t ctxt, void *user)
{
    (void)ctxt;
    return (int64_t)((const exr_memory *)user)->size;
}

/* The file channel read into each image channel (NULL: none, reads 0). */
typedef struct channel_map {
    int channels;
    const char *names[4];
} channel_map;

static int map_slot(const channel_map *map, const char *name)
{
    for (int i = 0; i < map->channels; i++)
        if (map->names[i] && strcmp(map->names[i], name) == 0)
            return i;
    return -1;
}

static lx_status choose_channels(const exr_attr_chlist_t *list, const char *name, channel_map *map)
{
    bool has[5] = {false};
    static const char *const wanted[5] = {"R", "G", "B", "A", "Y"};
    for (int i = 0; i < list->num_channels; i++) {
        const exr_attr_chlist_entry_t *e = &list->entries[i];
        /* every channel is decoded (see decode_block), so none may be
         * subsampled */
        if (e->x_sampling != 1 || e->y_sampling != 1)
            return lx_fail(LX_ERR_UNSUPPORTED, "%s: channel %s is subsampled (%dx%d)", name,
                           e->name.str ? e->name.str : "?", e->x_sampling, e->y_sampling);
        for (int k = 0; k < 5; k++)
            if (e->name.str && strcmp(e->name.str, wanted[k]) == 0)
                has[k] = true;
    }
    memset(map, 0, sizeof *map);
    if (has[0] || has[1] || has[2]) {
        /* a missing colour channel reads as 0 */
        map->channels = has[3] ? 4 : 3;
        map->names[0] = has[0] ? "R" : NULL;
        map->names[1] = has[1] ? "G" : NULL;
        map->names[2] = has[2] ? "B" : NULL;
        map->names[3] = has[3] ? "A" : NULL;
    } else if (has[4]) {
        map->channels = has[3] ? 2 : 1;
        map->names[0] = "Y";
        map->names[1] = has[3] ? "A" : NULL;
    } else {
        char found[256] = "";
        for (int i = 0; i < list->num_channels && strlen(found) < 200; i++)
            snprintf(found + strlen(found), sizeof found - strlen(found), "%s%s", i ? ", " : "",
                     list->entries[i].name.str ? list->entries[i].name.str : "?");
        return lx_fail(LX_ERR_UNSUPPORTED,
                       "%s: no R, G, B or Y channel (the file has: %s); luxel reads RGB(A) or "
                       "Y(A) images",
                       name, found[0] ? found : "no channels");
    }
    return LX_OK;
}

/* A decoder and the image it fills; one block = one chunk (scanlines or a
 * tile) whose top-left pixel is (x0, y0) in image coordinates. */
typedef struct exr_reader {
    exr_context_t ctx;
    exr_decode_pipeline_t dec;
    bool started;
    channel_map map;
    lx_image *img;
    const char *name;
    const lx_img_budget *budget;
    float *planes; /* one chunk, channel after channel */
    size_t planes_size;
} exr_reader;

/* Every channel of the chunk is decoded, planar, into r->planes, and the
 * wanted ones are interleaved here. OpenEXRCore 3.1 crashes when some
 * channel of a half-float file is skipped (NULL pointer), and its
 * interleaving unpackers assume output pointers in the file's channel order
 * (A, B, G, R), which would swap luxel's R and A. */
static lx_status decode_block(exr_reader *r, const exr_chunk_info_t *ci, int64_t x0, int64_t y0)
{
    lx_image *img = r->img;
    if (x0 < 0 || y0 < 0 || ci->width < 1 || ci->height < 1 || x0 + ci->width > img->width ||
        y0 + ci->height > img->height)
        return lx_fail(LX_ERR_FORMAT,
                       "%s: chunk %d (%dx%d at %lld, %lld) lies outside the "
                       "data window",
                       r->name, ci->idx, ci->width, ci->height, (long long)x0, (long long)y0);
    exr_result_t rv = r->started ? exr_decoding_update(r->ctx, 0, ci, &r->dec)
                                 : exr_decoding_initialize(r->ctx, 0, ci, &r->dec);
    if (rv != EXR_ERR_SUCCESS)
        return exr_failure(rv, LX_ERR_FORMAT, r->name, "chunk");
    size_t plane = (size_t)ci->width * (size_t)ci->height;
    size_t need = plane * (size_t)(r->dec.channel_count > 0 ? r->dec.channel_count : 1);
    if (need > r->planes_size) {
        float *p = realloc(r->planes, need * sizeof(float));
        if (!p)
            return lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", r->name,
                           need * sizeof(float));
        r->planes = p;
        r->planes_size = need;
    }
    int nc = img->channels;
    int from[4] = {-1, -1, -1, -1}; /* image channel -> decoded plane */
    for (int c = 0; c < r->dec.channel_count; c++) {
        exr_coding_channel_info_t *ch = &r->dec.channels[c];
        if (ch->width != ci->width || ch->height != ci->height)
            return lx_fail(LX_ERR_FORMAT, "%s: chunk %d: channel %s is %dx%d, expected %dx%d",
                           r->name, ci->idx, ch->channel_name ? ch->channel_name : "?", ch->width,
                           ch->height, ci->width, ci->height);
        int slot = ch->channel_name ? map_slot(&r->map, ch->channel_name) : -1;
        if (slot >= 0 && from[slot] < 0)
            from[slot] = c;
        /* the library converts half/uint/float to float while unpacking */
        ch->user_data_type = EXR_PIXEL_FLOAT;
        ch->user_bytes_per_element = 4;
        ch->user_pixel_stride = 4;
        ch->user_line_stride = ci->width * 4;
        ch->decode_to_ptr = (uint8_t *)(r->planes + (size_t)c * plane);
    }
    if (!r->started) {
        rv = exr_decoding_choose_default_routines(r->ctx, 0, &r->dec);
        if (rv != EXR_ERR_SUCCESS)
            return exr_failure(rv, LX_ERR_UNSUPPORTED, r->name, "chunk");
        r->started = true;
    }
    rv = exr_decoding_run(r->ctx, 0, &r->dec);
    if (rv != EXR_ERR_SUCCESS) {
        char doing[64];
        snprintf(doing, sizeof doing, "chunk %d", ci->idx);
        return exr_failure(rv, LX_ERR_FORMAT, r->name, doing);
    }
    for (int s = 0; s < nc; s++) {
        if (from[s] < 0)
            continue; /* absent colour channel: stays 0 */
        const float *src = r->planes + (size_t)from[s] * plane;
        for (int y = 0; y < ci->height; y++) {
            float *dst = img->data + ((size_t)(y0 + y) * (size_t)img->width + (size_t)x0) * nc + s;
            for (int x = 0; x < ci->width; x++, dst += nc)
                *dst = *src++;
        }
    }
    return LX_OK;
}

static lx_status read_scanlines(exr_reader *r, const exr_attr_box2i_t *dw)
{
    int32_t lines;
    exr_result_t rv = exr_get_scanlines_per_chunk(r->ctx, 0, &lines);
    if (rv != EXR_ERR_SUCCESS || lines < 1)
        return exr_failure(rv, LX_ERR_FORMAT, r->name, "scanlines per chunk");
    for (int64_t y = dw->min.y; y <= dw->max.y; y += lines) {
        exr_chunk_info_t ci;
        rv = exr_read_scanline_chunk_info(r->ctx, 0, (int)y, &ci);
        if (rv != EXR_ERR_SUCCESS) {
            char doing[64];
            snprintf(doing, sizeof doing, "scanline %lld", (long long)y);
            return exr_failure(rv, LX_ERR_FORMAT, r->name, doing);
        }
        lx_status s = decode_block(r, &ci, 0, (int64_t)ci.start_y - dw->min.y);
        if (s != LX_OK)
            return s;
    }
    return LX_OK;
}

static lx_status read_tiles(exr_reader *r)
{
    uint32_t tw, th;
    exr_tile_level_mode_t level_mode;
    exr_tile_round_mode_t round_mode;
    exr_result_t rv = exr_get_tile_descriptor(r->ctx, 0, &tw, &th, &level_mode, &round_mode);
    if (rv != EXR_ERR_SUCCESS || tw < 1 || th < 1)
        return exr_failure(rv, LX_ERR_FORMAT, r->name, "tile description");
    int64_t nx = ((int64_t)r->img->width + tw - 1) / tw;
    int64_t ny = ((int64_t)r->img->height + th - 1) / th;
    for (int64_t ty = 0; ty < ny; ty++) {
        for (int64_t tx = 0; tx < nx; tx++) {
            exr_chunk_info_t ci;
            rv = exr_read_tile_chunk_info(r->ctx, 0, (int)tx, (int)ty, 0, 0, &ci);
            if (rv != EXR_ERR_SUCCESS) {
                char doing[64];
                snprintf(doing, sizeof doing, "tile (%lld, %lld)", (long long)tx, (long long)ty);
                return exr_failure(rv, LX_ERR_FORMAT, r->name, doing);
            }
            lx_status s = decode_block(r, &ci, tx * tw, ty * th);
            if (s != LX_OK)
                return s;
        }
    }
    return LX_OK;
}

static lx_status read_part(exr_reader *r)
{
    exr_storage_t storage;
    exr_result_t rv = exr_get_storage(r->ctx, 0, &storage);
    if (rv != EXR_ERR_SUCCESS)
        return exr_failure(rv, LX_ERR_FORMAT, r->name, "header");
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: deep EXR images are not supported", r->name);
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *list;
    rv = exr_get_data_window(r->ctx, 0, &dw);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_channels(r->ctx, 0, &list);
    if (rv != EXR_ERR_SUCCESS || !list)
        return exr_failure(rv, LX_ERR_FORMAT, r->name, "header");
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w < 1 || h < 1 || w > INT_MAX || h > INT_MAX)
        return lx_fail(LX_ERR_FORMAT, "%s: invalid data window (%d, %d)-(%d, %d)", r->name,
                       dw.min.x, dw.min.y, dw.max.x, dw.max.y);
    int parts = 1;
    exr_attr_box2i_t display;
    if (exr_get_count(r->ctx, &parts) == EXR_ERR_SUCCESS && parts > 1)
        lx_log(LX_LOG_INFO, "%s: %d parts, reading the first", r->name, parts);
    if (exr_get_display_window(r->ctx, 0, &display) == EXR_ERR_SUCCESS &&
        memcmp(&display, &dw, sizeof dw) != 0)
        lx_log(LX_LOG_INFO,
               "%s: reading the data window (%d, %d)-(%d, %d), not the display "
               "window",
               r->name, dw.min.x, dw.min.y, dw.max.x, dw.max.y);
    lx_status s = choose_channels(list, r->name, &r->map);
    if (s != LX_OK)
        return s;
    /* the decoder's buffers hold one chunk at a time: small beside the image */
    s = lx_img_check_size(r->budget, r->name, w, h, r->map.channels, 0, true);
    if (s != LX_OK)
        return s;
    s = lx_image_alloc(r->img, (int)w, (int)h, r->map.channels);
    if (s != LX_OK) {
        lx_error_prefix(r->name);
        return s;
    }
    return storage == EXR_STORAGE_TILED ? read_tiles(r) : read_scanlines(r, &dw);
}

lx_status lx_img_load_exr(const unsigned char *data, size_t size, const char *name,
                          const lx_img_budget *budget, lx_image *out)
{
    memset(out, 0, sizeof *out);
    exr_memory mem = {data, size};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_on_error;
    init.user_data = &mem;
    init.read_fn = memory_read;
    init.size_fn = memory_size;
    /* A damaged offset table is an error, not something to guess around. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    exr_detail[0] = '\0';

    exr_reader r = {
        .dec = EXR_DECODE_PIPELINE_INITIALIZER, .img = out, .name = name, .budget = budget};
    exr_result_t rv = exr_start_read(&r.ctx, name, &init);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&r.ctx);
        return exr_failure(rv, LX_ERR_FORMAT, name, "header");
    }
    lx_status s = read_part(&r);
    if (r.started || r.dec.channels)
        exr_decoding_destroy(r.ctx, &r.dec);
    exr_finish(&r.ctx);
    free(r.planes);
    if (s != LX_OK)
        lx_image_free(out);
    return s;
}

/* ---- writing ------------------------------------------------------------- */

typedef struct exr_out {
    FILE *fp;
    uint64_t pos; /* where the stream is */
    bool failed;
} exr_out;

/* OpenEXRCore writes with pwrite semantics: it comes back to fill in the
 * chunk offset table at the end. Writes in sequence skip the seek, which
 * would flush the stream on every chunk. */
static int64_t file_write(exr_const_context_t ctxt, void *user, const void *buffer, uint64_t sz,
                          uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    (void)ctxt;
    (void)error_cb;
    exr_out *o = user;
    if (offset > (uint64_t)INT64_MAX ||
        (offset != o->pos && fseeko(o->fp, (off_t)offset, SEEK_SET) != 0) ||
        fwrite(buffer, 1, (size_t)sz, o->fp) != sz) {
        o->failed = true;
        o->pos = UINT64_MAX;
        return -1;
    }
    o->pos = offset + sz;
    return (int64_t)sz;
}

/* Channels in the alphabetical order EXR stores them, each with its index
 * in luxel's interleaved pixel. */
static int exr_channel_layout(int channels, const char **names, int *index)
{
    static const char *const rgba[4] = {"A", "B", "G", "R"};
    static const int rgba_index[4] = {3, 2, 1, 0};
    switch (channels) {
    case 1:
        names[0] = "Y", index[0] = 0;
        return 1;
    case 2:
        names[0] = "A", index[0] = 1, names[1] = "Y", index[1] = 0;
        return 2;
    case 3:
        for (int i = 0; i < 3; i++)
            names[i] = rgba[i + 1], index[i] = rgba_index[i + 1];
        return 3;
    default:
        for (int i = 0; i < 4; i++)
            names[i] = rgba[i], index[i] = rgba_index[i];
        return 4;
    }
}

/* One chunk's compressed bytes, kept until the chunks are written in
 * order. */
typedef struct exr_chunk_bytes {
    uint8_t *data;
    uint64_t size;
} exr_chunk_bytes;

/* The encode pipeline's last stage, in place of writing: keep a copy of
 * the chunk (the pipeline reuses its buffers for the next chunk). */
static exr_result_t keep_chunk(exr_encode_pipeline_t *enc)
{
    exr_chunk_bytes *slot = enc->encoding_user_data;
    slot->data = malloc(enc->compressed_bytes ? enc->compressed_bytes : 1);
    if (!slot->data)
        return EXR_ERR_OUT_OF_MEMORY;
    memcpy(slot->data, enc->compressed_buffer, enc->compressed_bytes);
    slot->size = enc->compressed_bytes;
    return EXR_ERR_SUCCESS;
}

/* What the chunk encoders share; the first failure (in chunk order) is
 * the one reported. */
typedef struct exr_job {
    exr_context_t ctx;
    const lx_image *img;
    float exposure;
    bool half;
    int lines; /* scanlines per chunk */
    const char *names[4];
    int index[4];
    int count;
    exr_chunk_bytes *chunks;
    lx_img_progress *progress;
    int failed_chunk; /* INT32_MAX: none */
    exr_result_t failed_rv;
    char failed_detail[512];
} exr_job;

/* The chunk's rows as planes in file channel order, exposed (alpha is not
 * light) and converted to the file's type. */
static void pack_planes(const exr_job *job, int y0, int rows, uint8_t *planes)
{
    const lx_image *img = job->img;
    int nc = img->channels;
    size_t n = (size_t)img->width * (size_t)rows;
    bool has_alpha = nc == 2 || nc == 4;
    for (int k = 0; k < job->count; k++) {
        int c = job->index[k];
        float e = has_alpha && c == nc - 1 ? 1.0f : job->exposure;
        const float *src = img->data + (size_t)y0 * img->width * nc + c;
        if (job->half) {
            uint16_t *dst = (uint16_t *)planes + (size_t)k * n;
            for (size_t i = 0; i < n; i++, src += nc)
                dst[i] = lx_float_to_half(*src * e);
        } else {
            float *dst = (float *)planes + (size_t)k * n;
            for (size_t i = 0; i < n; i++, src += nc)
                dst[i] = *src * e;
        }
    }
}

static void note_failure(exr_job *job, int chunk, exr_result_t rv)
{
#pragma omp critical(lx_exr_failure)
    if (chunk < job->failed_chunk) {
        job->failed_chunk = chunk;
        job->failed_rv = rv;
        snprintf(job->failed_detail, sizeof job->failed_detail, "%s",
                 exr_detail[0] ? exr_detail : exr_get_default_error_message(rv));
    }
}

/* Packs and compresses chunks [0, chunk_count) on `threads` threads, each
 * with its own pipeline, into job->chunks. The bytes of a chunk depend on
 * its pixels alone, so the file does not depend on the thread count. */
static void encode_chunks(exr_job *job, int chunk_count, int threads)
{
    const lx_image *img = job->img;
    int bytes_per_value = job->half ? 2 : 4;
    size_t row_bytes = (size_t)img->width * (size_t)bytes_per_value;
#pragma omp parallel num_threads(threads)
    {
        exr_detail[0] = '\0';
        exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
        bool started = false;
        uint8_t *planes = malloc(row_bytes * (size_t)job->lines * (size_t)job->count);
#pragma omp for schedule(dynamic, 1)
        for (int c = 0; c < chunk_count; c++) {
            if (job->failed_chunk != INT32_MAX || lx_img_progress_stopped(job->progress))
                continue;
            if (!planes) {
                note_failure(job, c, EXR_ERR_OUT_OF_MEMORY);
                continue;
            }
            int y = c * job->lines;
            int rows = img->height - y < job->lines ? img->height - y : job->lines;
            exr_chunk_info_t ci;
            exr_result_t rv = exr_write_scanline_chunk_info(job->ctx, 0, y, &ci);
            if (rv == EXR_ERR_SUCCESS)
                rv = started ? exr_encoding_update(job->ctx, 0, &ci, &enc)
                             : exr_encoding_initialize(job->ctx, 0, &ci, &enc);
            if (rv != EXR_ERR_SUCCESS) {
                note_failure(job, c, rv);
                continue;
            }
            pack_planes(job, y, rows, planes);
            size_t plane_bytes = row_bytes * (size_t)rows;
            for (int ch = 0; ch < enc.channel_count; ch++) {
                exr_coding_channel_info_t *info = &enc.channels[ch];
                int k = 0;
                while (k < job->count - 1 && strcmp(info->channel_name, job->names[k]) != 0)
                    k++;
                info->user_data_type = job->half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;
                info->user_bytes_per_element = (int16_t)bytes_per_value;
                info->user_pixel_stride = bytes_per_value;
                info->user_line_stride = (int32_t)row_bytes;
                info->encode_from_ptr = planes + (size_t)k * plane_bytes;
            }
            if (!started) {
                rv = exr_encoding_choose_default_routines(job->ctx, 0, &enc);
                started = rv == EXR_ERR_SUCCESS;
            }
            /* no ordering wait and no write here: the chunks are written
             * in order once all are encoded */
            enc.yield_until_ready_fn = NULL;
            enc.write_fn = keep_chunk;
            enc.encoding_user_data = &job->chunks[c];
            if (rv == EXR_ERR_SUCCESS)
                rv = exr_encoding_run(job->ctx, 0, &enc);
            if (rv != EXR_ERR_SUCCESS)
                note_failure(job, c, rv);
            else
                lx_img_progress_add(job->progress, 1);
        }
        if (started || enc.channels)
            exr_encoding_destroy(job->ctx, &enc);
        free(planes);
    }
}

/* The compression luxel writes. 32-bit floats: none. The low mantissa
 * bytes of a lightmap are noise that no lossless method packs: ZIP saves 7%
 * on bench_bake's lightmap at any zlib level and costs 10-20 times the
 * time of writing the bytes as they are (PIZ saves 17%, at 12 times). Half
 * floats: ZIP (zlib deflate of 16-scanline chunks after EXR's byte-split
 * predictor), level 1: 44% of the raw size, 14% above level 6's size at a
 * third of its time. */
#define LX_EXR_ZIP_LEVEL 1

/* Progress: the chunks encoded cover [0, LX_EXR_ENCODED], writing them in
 * order the rest; uncompressed scanlines, each packed and written, all of
 * it. */
#define LX_EXR_ENCODED 0.9f

lx_status lx_img_write_exr(FILE *fp, const char *path, const lx_image *img, float exposure,
                           bool half, int threads, lx_img_progress *progress)
{
    if ((int64_t)img->width * 4 > INT32_MAX)
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: %d pixels per row is too wide for EXR", path,
                       img->width);
    exr_job job = {.img = img,
                   .exposure = exposure,
                   .half = half,
                   .progress = progress,
                   .failed_chunk = INT32_MAX};
    job.count = exr_channel_layout(img->channels, job.names, job.index);

    exr_out o = {fp, (uint64_t)ftello(fp), false};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_on_error;
    init.user_data = &o;
    init.write_fn = file_write;
    exr_detail[0] = '\0';

    int part = 0;
    exr_pixel_type_t type = half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT;
    exr_compression_t compression = half ? EXR_COMPRESSION_ZIP : EXR_COMPRESSION_NONE;
    exr_result_t rv = exr_start_write(&job.ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_add_part(job.ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(job.ctx, part, img->width, img->height,
                                                 compression);
    if (rv == EXR_ERR_SUCCESS && compression == EXR_COMPRESSION_ZIP)
        rv = exr_set_zip_compression_level(job.ctx, part, LX_EXR_ZIP_LEVEL);
    for (int k = 0; k < job.count && rv == EXR_ERR_SUCCESS; k++)
        rv = exr_add_channel(job.ctx, part, job.names[k], type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(job.ctx);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_scanlines_per_chunk(job.ctx, part, &job.lines);
    lx_status s = rv == EXR_ERR_SUCCESS && job.lines >= 1
                      ? LX_OK
                      : exr_failure(rv, LX_ERR_IO, path, "header");
    int chunk_count = s == LX_OK ? (img->height + job.lines - 1) / job.lines : 0;
    if (s == LX_OK && !(job.chunks = calloc((size_t)chunk_count, sizeof *job.chunks)))
        s = lx_fail(LX_ERR_NOMEM, "%s: out of memory for %d chunks", path, chunk_count);
    bool raw = compression == EXR_COMPRESSION_NONE && job.lines == 1 &&
               __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;
    if (s == LX_OK && raw) {
        /* uncompressed: a chunk is one scanline, its channels one after
         * another in file order, little-endian, which pack_planes makes;
         * no pipeline, no copy */
        size_t line = (size_t)img->width * (size_t)job.count * sizeof(float);
        uint8_t *buf = malloc(line);
        if (!buf)
            s = lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, line);
        lx_img_progress_phase(progress, 0.0f, 1.0f, (uint64_t)img->height);
        for (int y = 0; y < img->height && s == LX_OK; y++) {
            pack_planes(&job, y, 1, buf);
            rv = exr_write_scanline_chunk(job.ctx, part, y, buf, line);
            if (rv != EXR_ERR_SUCCESS)
                s = exr_failure(rv, LX_ERR_IO, path, "writing");
            else if (!lx_img_progress_add(progress, 1))
                s = lx_img_cancelled(path);
        }
        free(buf);
        chunk_count = 0;
    } else if (s == LX_OK) {
        int n = lx_thread_count(threads);
        lx_img_progress_phase(progress, 0.0f, LX_EXR_ENCODED, (uint64_t)chunk_count);
        encode_chunks(&job, chunk_count, n < chunk_count ? n : chunk_count);
        if (job.failed_chunk != INT32_MAX)
            s = lx_fail(job.failed_rv == EXR_ERR_OUT_OF_MEMORY ? LX_ERR_NOMEM : LX_ERR_IO,
                        "%s: writing chunk %d: %s", path, job.failed_chunk, job.failed_detail);
        else if (lx_img_progress_stopped(progress))
            s = lx_img_cancelled(path);
        lx_img_progress_phase(progress, LX_EXR_ENCODED, 1.0f - LX_EXR_ENCODED,
                              (uint64_t)chunk_count);
    }
    /* the chunks in order, as the file's increasing-y line order wants */
    for (int c = 0; c < chunk_count && s == LX_OK; c++) {
        rv = exr_write_scanline_chunk(job.ctx, part, c * job.lines, job.chunks[c].data,
                                      job.chunks[c].size);
        if (rv != EXR_ERR_SUCCESS)
            s = exr_failure(rv, LX_ERR_IO, path, "writing");
        else if (!lx_img_progress_add(progress, 1))
            s = lx_img_cancelled(path);
    }
    for (int c = 0; c < chunk_count && job.chunks; c++)
        free(job.chunks[c].data);
    free(job.chunks);
    rv = exr_finish(&job.ctx);
    if (s == LX_OK && rv != EXR_ERR_SUCCESS)
        s = exr_failure(rv, LX_ERR_IO, path, "finishing");
    if (s == LX_OK && o.failed)
        s = lx_fail(LX_ERR_IO, "%s: write failed", path);
    return s;
}
