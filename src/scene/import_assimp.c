/* Scene import through assimp's C API (glTF 2.0, OBJ, FBX, ...): meshes,
 * materials with their normal and base-colour textures, and the node
 * hierarchy flattened into world-space instances. From a glTF file's own
 * JSON (gltf_json.c) come what assimp drops or changes: KHR_lights_punctual
 * lights (gltf_lights.c), KHR_texture_transform and texCoord
 * (gltf_textures.c), and the triangle count of every primitive, so faces
 * assimp dropped for out-of-range indices are noticed and named. Both need
 * to know which of assimp's meshes and materials is which of the file's:
 * gltf_map below finds that through the node hierarchy. */
#define _GNU_SOURCE /* glibc's writer-preferring rwlock initializer */
#include "luxel/scene.h"
#include "core/internal.h"

#include "gltf_json.h"
#include "node_bake.h"
#include "import_checks.h"
#include "texture_size.h"
#include "json_text.h"
#include "node_graph.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/GltfMaterial.h>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <float.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#define LX_NAME_MAX 256
#define LX_NODE_DEPTH_MAX NODE_DEPTH_MAX
/* The stack assimp runs on: its readers recurse once per node level and
 * per level of a file's nesting, both bounded by import_checks.c. With
 * the bounds lifted, 32 MB held 20,000 levels of glTF, Collada and FBX
 * nodes (the main thread's 8 MB fell at 10,000 in Collada): 80 times the
 * 256 levels accepted, whatever stack the caller's thread has. */
#define IMPORT_STACK_BYTES ((size_t)32 << 20)

typedef struct gltf_map gltf_map;

typedef struct import_ctx {
    const char *path;
    const struct aiScene *ai;
    lx_scene *scene;
    const lx_scene_load_desc *desc;
    uint32_t *mesh_map; /* assimp mesh -> lx mesh index, UINT32_MAX if skipped */
    char *folder;
    const cJSON *gltf;   /* the file's glTF 2.0 JSON, or NULL */
    const gltf_map *map; /* assimp's meshes and materials in it, with gltf */
    bool log_watched;    /* assimp's log was watched during the import ... */
    bool log_dropped;    /* ... and told of faces dropped for bad indices */
    uint32_t dropped, dropped_meshes; /* zero-area triangles left out, and their meshes */
    char first_dropped[LX_NAME_MAX];  /* the first mesh with one ... */
    unsigned first_dropped_face;      /* ... and its face */
    /* textures named by materials, decoded once the geometry is known */
    struct texture_request *textures;
    size_t texture_count, texture_capacity;
} import_ctx;

/* A material's texture to decode: map slot (texture_size.h) of scene
 * material `material`, named as assimp names it ("*N" embedded). */
typedef struct texture_request {
    uint32_t material;
    int slot;
    bool raw;
    const char *what; /* "normal", "base colour", "emissive" */
    char *name;
} texture_request;

/* ---- running assimp ------------------------------------------------------ */

/* What assimp 5.2.5 shares between imports (its source: code/Common/
 * Assimp.cpp, DefaultLogger.cpp, Importer.cpp). aiImportFileExWithProperties
 * makes a fresh Assimp::Importer, with its own readers, post-processing
 * steps and IO system, for every call; the readers and steps luxel uses
 * keep no mutable static state. Two things are process-wide:
 *
 * - the last error: a failed aiImportFile* call assigns a static
 *   std::string that aiGetErrorString returns, with no lock. Two failed
 *   calls at once would assign it together (a data race that can free its
 *   buffer twice), so every call that can fail, which is every file read,
 *   runs under reader_lock, and the message is copied before it is let go.
 *   aiApplyPostProcessing does not touch the string.
 * - the logger: every log call in assimp (readers, steps, aiGetMaterial*
 *   on a property of the wrong type) reads DefaultLogger's global pointer
 *   without a lock, while aiAttachLogStream and aiDetachLogStream replace
 *   and delete the logger under a lock of assimp's own. An attached stream
 *   also hears every import running at the time. So every use of assimp
 *   holds assimp_lock shared, and an import that attaches a stream holds
 *   it exclusively, from before the attach to after the detach.
 *
 * Reading a file is the smaller part of an import: on a 180k-triangle OBJ
 * the reader took 0.7 s and luxel's post-processing (smooth normals,
 * joining vertices) 3.0 s; on the same mesh as glTF 32 ms and 0.52 s. An
 * import therefore reads the file under reader_lock with validation only
 * and post-processes with aiApplyPostProcessing outside it, so imports on
 * several threads overlap everywhere but in their readers. That call has
 * one flaw: when a step fails it releases the scene the step has already
 * deleted. With luxel's steps only an allocation fails, so before the
 * post-processing the memory it may take is compared with what the
 * process may use (lx_memory_available); a scene too large for that is
 * imported again in one aiImportFileExWithProperties call holding
 * assimp_lock exclusively, where a failure is reported as assimp's error.
 *
 * The one importer that reports dropped faces, assimp's glTF 2.0 reader
 * (faces with out-of-range indices), says so only through the log,
 * without naming the mesh; luxel checks each primitive against the
 * file's JSON instead (check_dropped_faces). Only when a triangle mesh
 * cannot be matched to its primitive is the file imported a second time,
 * exclusively, with a log stream attached (import_watched). */
#if defined(PTHREAD_RWLOCK_WRITER_NONRECURSIVE_INITIALIZER_NP)
/* a waiting exclusive import is not overtaken by new shared ones */
static pthread_rwlock_t assimp_lock = PTHREAD_RWLOCK_WRITER_NONRECURSIVE_INITIALIZER_NP;
#else
static pthread_rwlock_t assimp_lock = PTHREAD_RWLOCK_INITIALIZER;
#endif
static pthread_mutex_t reader_lock = PTHREAD_MUTEX_INITIALIZER;

#define POST_FLAGS                                                                                 \
    (aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_FlipUVs |                           \
     aiProcess_GenSmoothNormals)

/* Formats read face by face (OBJ...) get their vertices shared. glTF's are
 * already indexed, and assimp's joining would merge vertices that differ
 * only in TEXCOORD_1 (a lightmap set written by luxel unwrap). */
static unsigned post_flags(bool gltf2)
{
    return POST_FLAGS | (gltf2 ? 0u : (unsigned)aiProcess_JoinIdenticalVertices);
}

/* An assimp scene and how assimp_lock is held for it (until
 * assimp_release). */
typedef struct assimp_import {
    const struct aiScene *ai;
    bool exclusive;
    bool dropped; /* watched: the glTF 2.0 reader logged dropped faces */
} assimp_import;

static void on_assimp_log(const char *message, char *user)
{
    if (strstr(message, "out-of-range indices"))
        *(bool *)(void *)user = true;
}

/* Bytes the post-processing of ai may add at its peak: about twice the
 * address space it was measured to add (a 180k-triangle grid as OBJ,
 * 540k vertices as read, and as glTF, 91k: 300 bytes a vertex and 180 a
 * face, joining vertices keeping a 272-byte copy of each). */
static uint64_t post_processing_bytes(const struct aiScene *ai)
{
    uint64_t bytes = 0;
    for (unsigned i = 0; i < ai->mNumMeshes; i++) {
        const struct aiMesh *m = ai->mMeshes[i];
        bytes += (uint64_t)m->mNumVertices * 512u + (uint64_t)m->mNumFaces * 384u;
    }
    return bytes;
}

/* The estimates of the post-processing running now: a new one must fit
 * beside them. */
static _Atomic uint64_t post_processing_reserved;

/* ---- the files assimp opens ---------------------------------------------- */

/* Every import reads through these callbacks: one name may be served from
 * memory (a glTF file luxel has rewritten, gltf_rewrite.c), and a path
 * written with Windows backslashes (an OBJ's mtllib, a relative uri) that
 * does not exist as written is tried with slashes. */
typedef struct import_source {
    const char *read_path; /* the name assimp is given */
    const uint8_t *bytes;  /* served for read_path when not NULL */
    size_t size;
    const char *path;    /* the scene file, for messages */
    const char *folder;  /* other files must lie in it or below ... */
    bool allow_any_path; /* ... unless this is set (lx_path_confine) */
    bool text_others;    /* other files may be text assimp quotes (an OBJ's
                            mtllib; a glTF's are binary buffers) */
} import_source;

typedef struct io_file {
    FILE *fp;
    const uint8_t *bytes;
    size_t size, pos;
    struct aiFile *file;
    struct io_file *prev, *next; /* the import's open files */
} io_file;

/* One import's callbacks: the files assimp has open, so the ones it never
 * closes (its glTF reader loses streams when it gives up on a short
 * buffer) are closed after it returns. */
typedef struct io_state {
    const import_source *src;
    io_file *open;
    char refused[512]; /* why the first file outside the folder was refused */
    bool read_others;  /* a file besides the scene was opened (an OBJ's mtllib) */
} io_state;

static size_t io_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
    io_file *h = (io_file *)(void *)f->UserData;
    if (h->fp)
        return size ? fread(buf, size, count, h->fp) : 0;
    if (!size || h->pos >= h->size)
        return 0;
    size_t n = (h->size - h->pos) / size;
    if (n > count)
        n = count;
    memcpy(buf, h->bytes + h->pos, n * size);
    h->pos += n * size;
    return n;
}

static size_t io_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
    (void)f, (void)buf, (void)size, (void)count;
    return 0;
}

static size_t io_tell(struct aiFile *f)
{
    io_file *h = (io_file *)(void *)f->UserData;
    if (h->fp) {
        long at = ftell(h->fp);
        return at < 0 ? 0 : (size_t)at;
    }
    return h->pos;
}

static size_t io_size(struct aiFile *f)
{
    return ((io_file *)(void *)f->UserData)->size;
}

static enum aiReturn io_seek(struct aiFile *f, size_t offset, enum aiOrigin origin)
{
    io_file *h = (io_file *)(void *)f->UserData;
    size_t base = origin == aiOrigin_SET ? 0 : origin == aiOrigin_CUR ? io_tell(f) : h->size;
    if (offset > SIZE_MAX - base || base + offset > h->size)
        return aiReturn_FAILURE;
    if (h->fp)
        return fseek(h->fp, (long)(base + offset), SEEK_SET) == 0 ? aiReturn_SUCCESS
                                                                  : aiReturn_FAILURE;
    h->pos = base + offset;
    return aiReturn_SUCCESS;
}

static void io_flush(struct aiFile *f)
{
    (void)f;
}

static FILE *open_slashed(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (fp || !strchr(path, '\\'))
        return fp;
    char *alt = lx_strdup(path);
    if (!alt)
        return NULL;
    for (char *p = alt; *p; p++)
        if (*p == '\\')
            *p = '/';
    fp = fopen(alt, "rb");
    free(alt);
    return fp;
}

static struct aiFile *io_open(struct aiFileIO *io, const char *path, const char *mode)
{
    io_state *state = (io_state *)(void *)io->UserData;
    const import_source *src = state->src;
    if (!path || (mode && (strchr(mode, 'w') || strchr(mode, 'a'))))
        return NULL;
    io_file *h = calloc(1, sizeof *h);
    struct aiFile *f = calloc(1, sizeof *f);
    if (!h || !f) {
        free(h);
        free(f);
        return NULL;
    }
    if (src->bytes && strcmp(path, src->read_path) == 0) {
        h->bytes = src->bytes;
        h->size = src->size;
    } else {
        /* an OBJ's mtllib, a buffer: only inside the scene's folder */
        size_t n = strlen(src->folder);
        const char *named =
            strncmp(path, src->folder, n) == 0 && path[n] == '/' ? path + n + 1 : path;
        if (lx_path_confine(src->path, "file named by the scene", named, src->folder, path,
                            src->allow_any_path) != LX_OK) {
            if (!state->refused[0])
                snprintf(state->refused, sizeof state->refused, "%s", lx_last_error());
            free(h);
            free(f);
            return NULL;
        }
        struct stat sb;
        state->read_others = src->text_others;
        h->fp = open_slashed(path);
        if (!h->fp || fstat(fileno(h->fp), &sb) != 0 || !S_ISREG(sb.st_mode)) {
            if (h->fp)
                fclose(h->fp);
            free(h);
            free(f);
            return NULL;
        }
        h->size = (size_t)sb.st_size;
    }
    f->ReadProc = io_read;
    f->WriteProc = io_write;
    f->TellProc = io_tell;
    f->FileSizeProc = io_size;
    f->SeekProc = io_seek;
    f->FlushProc = io_flush;
    f->UserData = (aiUserData)(void *)h;
    h->file = f;
    h->next = state->open;
    if (state->open)
        state->open->prev = h;
    state->open = h;
    return f;
}

static void io_close(struct aiFileIO *io, struct aiFile *f)
{
    if (!f)
        return;
    io_state *state = (io_state *)(void *)io->UserData;
    io_file *h = (io_file *)(void *)f->UserData;
    if (h) {
        if (h->prev)
            h->prev->next = h->next;
        else
            state->open = h->next;
        if (h->next)
            h->next->prev = h->prev;
        if (h->fp)
            fclose(h->fp);
    }
    free(h);
    free(f);
}

static struct aiFileIO io_for(io_state *state, const import_source *src)
{
    state->src = src;
    state->open = NULL;
    state->refused[0] = '\0';
    state->read_others = false;
    struct aiFileIO io = {io_open, io_close, (aiUserData)(void *)state};
    return io;
}

/* The files assimp left open when its import returned. */
static void io_close_leftovers(struct aiFileIO *io)
{
    io_state *state = (io_state *)(void *)io->UserData;
    while (state->open)
        io_close(io, state->open->file);
}

/* assimp's message with what it quotes left out, when it may quote a
 * file other than the one being parsed (an OBJ's material library: a
 * message must not show another file's content). */
static void redact_quotes(char *why, size_t size)
{
    char out[512];
    size_t n = 0;
    for (const char *p = why; *p && n + 6 < sizeof out; p++) {
        const char *close = *p == '"' || *p == '\'' ? strchr(p + 1, *p) : NULL;
        if (close) {
            n += (size_t)snprintf(out + n, sizeof out - n, "%c...%c", *p, *p);
            p = close;
        } else {
            out[n++] = *p;
        }
    }
    out[n] = '\0';
    snprintf(why, size, "%s", out);
}

static lx_status import_failed(const char *path, const char *why)
{
    return lx_fail(LX_ERR_FORMAT, "%s: cannot import: %s", path,
                   why[0] ? why : "unknown format or corrupt file");
}

static struct aiPropertyStore *import_properties(void)
{
    struct aiPropertyStore *props = aiCreatePropertyStore();
    /* Smooth normals where a file has none, but keep hard edges hard. */
    aiSetImportPropertyFloat(props, AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, 60.0f);
    return props;
}

/* The whole import in one call holding assimp_lock exclusively, with the
 * log watched for dropped faces when watch_log. */
static lx_status import_exclusive(const char *path, const import_source *src, bool watch_log,
                                  bool gltf2, assimp_import *im)
{
    io_state state;
    struct aiFileIO io = io_for(&state, src);
    struct aiPropertyStore *props = import_properties();
    struct aiLogStream log = {on_assimp_log, (char *)(void *)&im->dropped};
    pthread_rwlock_wrlock(&assimp_lock);
    im->exclusive = true;
    if (watch_log)
        aiAttachLogStream(&log);
    im->ai = aiImportFileExWithProperties(src->read_path,
                                          post_flags(gltf2) | aiProcess_ValidateDataStructure, &io,
                                          props);
    io_close_leftovers(&io);
    if (watch_log)
        aiDetachLogStream(&log);
    char why[512];
    snprintf(why, sizeof why, "%s", im->ai ? "" : aiGetErrorString());
    if (state.read_others)
        redact_quotes(why, sizeof why);
    aiReleasePropertyStore(props);
    if (state.refused[0]) { /* assimp may have gone on without the file */
        if (im->ai)
            aiReleaseImport(im->ai);
        im->ai = NULL;
        pthread_rwlock_unlock(&assimp_lock);
        return lx_fail(LX_ERR_INVALID, "%s", state.refused);
    }
    if (!im->ai) {
        pthread_rwlock_unlock(&assimp_lock);
        return import_failed(path, why);
    }
    return LX_OK;
}

/* Imports path with luxel's post-processing into im->ai, holding
 * assimp_lock until assimp_release (also on failure, when im->ai is
 * NULL and the lock is already let go). */
static lx_status assimp_import_file(const char *path, const import_source *src, bool watch_log,
                                   bool gltf2, assimp_import *im)
{
    memset(im, 0, sizeof *im);
    if (watch_log)
        return import_exclusive(path, src, true, gltf2, im);
    io_state state;
    struct aiFileIO io = io_for(&state, src);
    struct aiPropertyStore *props = import_properties();
    pthread_rwlock_rdlock(&assimp_lock);
    pthread_mutex_lock(&reader_lock);
    const struct aiScene *ai =
        aiImportFileExWithProperties(src->read_path, aiProcess_ValidateDataStructure, &io, props);
    io_close_leftovers(&io);
    char why[512];
    snprintf(why, sizeof why, "%s", ai ? "" : aiGetErrorString());
    if (state.read_others)
        redact_quotes(why, sizeof why);
    pthread_mutex_unlock(&reader_lock);
    aiReleasePropertyStore(props);
    if (state.refused[0]) { /* assimp may have gone on without the file */
        if (ai)
            aiReleaseImport(ai);
        pthread_rwlock_unlock(&assimp_lock);
        return lx_fail(LX_ERR_INVALID, "%s", state.refused);
    }
    if (!ai) {
        pthread_rwlock_unlock(&assimp_lock);
        return import_failed(path, why);
    }
    uint64_t need = post_processing_bytes(ai);
    uint64_t others = atomic_fetch_add(&post_processing_reserved, need);
    if (need + others > lx_memory_available(NULL)) {
        atomic_fetch_sub(&post_processing_reserved, need);
        aiReleaseImport(ai);
        pthread_rwlock_unlock(&assimp_lock);
        return import_exclusive(path, src, false, gltf2, im);
    }
    im->ai = aiApplyPostProcessing(ai, post_flags(gltf2));
    atomic_fetch_sub(&post_processing_reserved, need);
    if (!im->ai) {
        pthread_rwlock_unlock(&assimp_lock);
        return lx_fail(LX_ERR_NOMEM, "%s: cannot import: assimp's post-processing failed", path);
    }
    return LX_OK;
}

static void assimp_release(assimp_import *im)
{
    if (!im->ai)
        return;
    aiReleaseImport(im->ai);
    im->ai = NULL;
    pthread_rwlock_unlock(&assimp_lock);
}

/* OBJ text numbers that assimp would silently read as 0 ("nan", "inf",
 * values beyond float range) are refused before import. */
static lx_status check_obj_numbers(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return lx_fail(LX_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    char line[4096];
    char object[128] = "";
    unsigned long number = 0;
    lx_status st = LX_OK;
    while (st == LX_OK && fgets(line, sizeof line, fp)) {
        number++;
        if ((line[0] == 'o' || line[0] == 'g') && (line[1] == ' ' || line[1] == '\t')) {
            snprintf(object, sizeof object, "%s", line + 2);
            object[strcspn(object, "\r\n")] = '\0';
            continue;
        }
        const char *kind = NULL;
        if (strncmp(line, "v ", 2) == 0 || strncmp(line, "v\t", 2) == 0)
            kind = "v";
        else if (strncmp(line, "vt", 2) == 0 && (line[2] == ' ' || line[2] == '\t'))
            kind = "vt";
        else if (strncmp(line, "vn", 2) == 0 && (line[2] == ' ' || line[2] == '\t'))
            kind = "vn";
        if (!kind)
            continue;
        const char *p = line + strlen(kind);
        for (;;) {
            while (*p == ' ' || *p == '\t')
                p++;
            if (!*p || *p == '\n' || *p == '\r' || *p == '#')
                break;
            char *end;
            double v = strtod(p, &end);
            if (end == p)
                break; /* not a number: assimp reports it */
            if (!isfinite(v) || fabs(v) > FLT_MAX) {
                int len = (int)(end - p) < 32 ? (int)(end - p) : 32;
                st = lx_fail(LX_ERR_FORMAT, "%s: line %lu%s%s%s: '%s' value '%.*s' is not finite",
                             path, number, object[0] ? ": object '" : "", object,
                             object[0] ? "'" : "", kind, len, p);
                break;
            }
            p = end;
        }
    }
    fclose(fp);
    return st;
}

static lx_mat4 mat4_from_ai(const struct aiMatrix4x4 *a)
{
    /* aiMatrix4x4 is row-major (a1..a4 the first row); lx_mat4 column-major */
    lx_mat4 m = {{a->a1, a->b1, a->c1, a->d1, a->a2, a->b2, a->c2, a->d2, a->a3, a->b3, a->c3,
                  a->d3, a->a4, a->b4, a->c4, a->d4}};
    return m;
}

static bool has_extension(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && strcasecmp(path + n - e, ext) == 0;
}

/* A texture named by a material, for map slot of the material being
 * imported (the scene's next): with skip_textures only its name is kept,
 * else it is decoded with the others once the geometry is known
 * (decode_textures), at the size the desc's density needs. */
static lx_status request_texture(import_ctx *c, const struct aiString *tex_path, bool raw,
                                 const char *what, int slot, char **out_path)
{
    const char *p = tex_path->data;
    if (c->desc->skip_textures) {
        *out_path = p[0] == '*' ? lx_strdup(p) : lx_path_join(c->folder, p);
        return LX_OK;
    }
    if (c->texture_count == c->texture_capacity) {
        size_t cap = c->texture_capacity ? 2 * c->texture_capacity : 8;
        texture_request *t = realloc(c->textures, cap * sizeof *t);
        if (!t)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
        c->textures = t;
        c->texture_capacity = cap;
    }
    char *name = lx_strdup(p);
    if (!name)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
    c->textures[c->texture_count++] =
        (texture_request){c->scene->material_count, slot, raw, what, name};
    return LX_OK;
}

/* The material being imported goes without map slot after all. */
static void drop_texture(import_ctx *c, int slot)
{
    for (size_t i = 0; i < c->texture_count; i++) {
        texture_request *t = &c->textures[i];
        if (t->material == c->scene->material_count && t->slot == slot && t->name) {
            free(t->name);
            t->name = NULL;
        }
    }
}

static void free_textures(import_ctx *c)
{
    for (size_t i = 0; i < c->texture_count; i++)
        free(c->textures[i].name);
    free(c->textures);
    c->textures = NULL;
    c->texture_count = c->texture_capacity = 0;
}

/* Decodes a texture named by a material: "*N" is embedded in the file,
 * other paths are relative to the scene's folder; keep_pixels as
 * lx_image_load_desc's. Failures are warnings: the material then goes
 * without the map. */
static void load_texture(import_ctx *c, const char *p, bool raw, const char *what,
                         const char *material, uint64_t keep_pixels, lx_image *out,
                         char **out_path, int *halvings)
{
    lx_image_load_desc ld = {.raw_8bit = raw,
                             .channels = raw ? 3 : 4,
                             .max_pixels = LX_SCENE_TEXTURE_MAX_PIXELS,
                             .keep_pixels = keep_pixels};
    lx_status st;
    char *full = NULL;
    if (p[0] == '*') {
        char *end = NULL;
        long idx = strtol(p + 1, &end, 10);
        if (!end || *end || idx < 0 || (unsigned long)idx >= c->ai->mNumTextures) {
            lx_log(LX_LOG_WARN, "%s: material '%s': %s texture '%s' does not exist; ignored",
                   c->path, material, what, p);
            return;
        }
        const struct aiTexture *t = c->ai->mTextures[idx];
        if (t->mHeight != 0) {
            lx_log(LX_LOG_WARN,
                   "%s: material '%s': uncompressed embedded %s texture is not supported; "
                   "ignored",
                   c->path, material, what);
            return;
        }
        char name[LX_NAME_MAX];
        snprintf(name, sizeof name, "%s: embedded texture %ld", c->path, idx);
        st = lx_image_load_halved(NULL, t->pcData, t->mWidth, name, &ld, out, halvings);
    } else {
        full = lx_path_join(c->folder, p);
        if (!full)
            return;
        /* a texture outside the scene's folder is not read: a missing
         * texture's fate (a glTF image there failed the load up front,
         * lx_gltf_check_files, since writers would copy it) */
        if (lx_path_confine(c->path, "texture", p, c->folder, full, c->desc->allow_any_path) !=
            LX_OK) {
            lx_log(LX_LOG_WARN, "%s; material '%s' goes without it", lx_last_error(), material);
            free(full);
            return;
        }
        struct stat sb;
        if (stat(full, &sb) != 0 && strchr(full, '\\')) {
            /* written on Windows: textures\\wood.png */
            for (char *q = full + strlen(c->folder); *q; q++)
                if (*q == '\\')
                    *q = '/';
        }
        if (lx_lfs_pointer_file(full)) {
            lx_log(LX_LOG_WARN,
                   "%s: material '%s': %s texture %s is a Git LFS pointer, not the file: run git "
                   "lfs pull; ignored",
                   c->path, material, what, full);
            free(full);
            return;
        }
        st = lx_image_load_halved(full, NULL, 0, full, &ld, out, halvings);
    }
    if (st != LX_OK) {
        lx_log(LX_LOG_WARN, "%s: material '%s': %s texture not loaded (%s); ignored", c->path,
               material, what, lx_last_error());
        memset(out, 0, sizeof *out);
        free(full);
        return;
    }
    *out_path = full ? full : lx_strdup(p);
}

/* Decodes the textures the materials named, straight into the scene's
 * materials, now that its nodes and meshes say how finely each is read
 * (lx_texture_keep_pixels), one at a time: a texture is decoded and
 * reduced before the next one's file is read. */
static lx_status decode_textures(import_ctx *c)
{
    if (!c->texture_count)
        return LX_OK;
    lx_scene *s = c->scene;
    uint64_t *keep = calloc((size_t)s->material_count * LX_TEXTURE_SLOTS + 1, sizeof *keep);
    if (!keep)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
    lx_status st = lx_texture_keep_pixels(s, c->desc, keep);
    for (size_t i = 0; i < c->texture_count && st == LX_OK; i++) {
        const texture_request *t = &c->textures[i];
        if (!t->name || t->material >= s->material_count)
            continue;
        lx_material *m = &s->materials[t->material];
        lx_image *img = t->slot == LX_TEXTURE_NORMAL       ? &m->normal_map
                        : t->slot == LX_TEXTURE_BASE_COLOR ? &m->base_color_map
                                                           : &m->emissive_map;
        char **path = t->slot == LX_TEXTURE_NORMAL       ? &m->normal_map_path
                      : t->slot == LX_TEXTURE_BASE_COLOR ? &m->base_color_map_path
                                                         : &m->emissive_map_path;
        int *halvings = t->slot == LX_TEXTURE_NORMAL       ? &m->normal_map_halvings
                        : t->slot == LX_TEXTURE_BASE_COLOR ? &m->base_color_map_halvings
                                                           : &m->emissive_map_halvings;
        int set = t->slot == LX_TEXTURE_NORMAL       ? m->normal_uv_set
                  : t->slot == LX_TEXTURE_BASE_COLOR ? m->base_color_uv_set
                                                     : m->emissive_uv_set;
        load_texture(c, t->name, t->raw, t->what, m->name,
                     keep[(size_t)t->material * LX_TEXTURE_SLOTS + (size_t)t->slot], img, path,
                     halvings);
        /* the sets of the maps luxel samples are read too (as
         * lx_scene_add_material counts them) */
        if (img->width > 0 && set >= 0 && set < 32)
            m->uv_sets_read |= 1u << set;
    }
    free(keep);
    return st;
}

/* ---- assimp's glTF 2.0 meshes and materials in the file ----------------- */

/* assimp's glTF 2.0 reader loads meshes and materials lazily, in the order
 * the scene's nodes first reach them, so its mesh and material arrays
 * follow neither the file's order nor any other luxel could rely on. What
 * it keeps is the node hierarchy: each aiNode is one node of the imported
 * scene with its children in the file's order (under a synthetic root
 * when the scene has several root nodes), and a node with "mesh": m lists
 * one aiMesh per primitive of m, in primitive order, each with its
 * primitive's material. So the JSON nodes are walked alongside the aiNodes
 * and every pairing is checked: child and primitive counts (a primitive
 * assimp skipped shows as a count that differs), the node's name (when
 * the file gives one; assimp names an unnamed node itself) and each
 * primitive's type. Under a node that does not line up nothing is
 * paired: its aiMeshes are marked as not matched, and so is an aiMesh two
 * primitives claim. A mesh instanced by several nodes is paired at each.
 * The paired aiMeshes then give each aiMaterial its JSON material. */
#define PRIM_NONE SIZE_MAX         /* no paired node lists the aiMesh */
#define PRIM_SPOILT (SIZE_MAX - 1) /* listed where the structure does not line up */
#define MAT_UNKNOWN INT64_MIN      /* no paired aiMesh uses the aiMaterial */
#define MAT_SPOILT (INT64_MIN + 1) /* paired aiMeshes disagree, or name a bad index */

struct gltf_map {
    lx_gltf_primitives prims;
    const cJSON **nodes; /* the JSON nodes by index */
    size_t node_count;
    const cJSON **materials; /* the JSON materials by index */
    size_t material_count;
    size_t *prim_of;      /* per aiMesh: its primitive in prims, or PRIM_* */
    int64_t *material_of; /* per aiMaterial: a JSON material index, LX_GLTF_NO_MATERIAL
                           * (assimp's default material), or MAT_* */
    struct node_pair *pairs; /* aiNode -> JSON node, sorted by aiNode once built */
    size_t pair_count, pair_cap;
};

struct node_pair {
    const struct aiNode *ai;
    size_t json;
};

static void gltf_map_free(gltf_map *g)
{
    lx_gltf_primitives_free(&g->prims);
    free(g->nodes);
    free(g->materials);
    free(g->prim_of);
    free(g->material_of);
    free(g->pairs);
    memset(g, 0, sizeof *g);
}

/* The aiMeshes an aiNode and its descendants list cannot be matched. */
static void map_spoil(gltf_map *g, const struct aiScene *ai, const struct aiNode *an, int depth)
{
    for (unsigned k = 0; k < an->mNumMeshes; k++)
        if (an->mMeshes[k] < ai->mNumMeshes)
            g->prim_of[an->mMeshes[k]] = PRIM_SPOILT;
    /* deeper trees fail the import (import_node) */
    for (unsigned k = 0; depth < LX_NODE_DEPTH_MAX && k < an->mNumChildren; k++)
        map_spoil(g, ai, an->mChildren[k], depth + 1);
}

/* The node references of a "children" or scene "nodes" list as assimp
 * reads them: entries that are not unsigned integers are skipped (it
 * refuses the file over one out of range). */
static size_t count_node_refs(const gltf_map *g, const cJSON *list)
{
    size_t n = 0, index;
    for (const cJSON *e = cJSON_IsArray(list) ? list->child : NULL; e; e = e->next)
        n += lx_gltf_index(e, g->node_count, &index);
    return n;
}

/* Whether assimp's mesh has the primitive type of glTF mode (-1: unknown). */
static bool mode_matches(int mode, const struct aiMesh *am)
{
    unsigned want = mode < 0    ? 0
                    : mode == 0 ? aiPrimitiveType_POINT
                    : mode <= 3 ? aiPrimitiveType_LINE
                                : aiPrimitiveType_TRIANGLE;
    return want == 0 || (am->mPrimitiveTypes & want) != 0;
}

static void map_node(gltf_map *g, const struct aiScene *ai, size_t jn, const struct aiNode *an,
                     int depth)
{
    const cJSON *node = g->nodes[jn];
    const char *name = lx_gltf_get_string(node, "name");
    /* assimp keeps at most MAXLEN - 1 bytes of a name */
    if (depth > LX_NODE_DEPTH_MAX ||
        (name && name[0] && strncmp(name, an->mName.data, sizeof an->mName.data - 1) != 0)) {
        map_spoil(g, ai, an, depth);
        return;
    }
    if (g->pair_count == g->pair_cap) {
        size_t cap = g->pair_cap ? 2 * g->pair_cap : 64;
        struct node_pair *p = realloc(g->pairs, cap * sizeof *p);
        if (p) {
            g->pairs = p;
            g->pair_cap = cap;
        }
    }
    if (g->pair_count < g->pair_cap) /* out of memory: the node stays unmatched */
        g->pairs[g->pair_count++] = (struct node_pair){an, jn};
    const cJSON *mesh = lx_gltf_get(node, "mesh");
    size_t m = 0;
    bool lined_up = mesh ? lx_gltf_index(mesh, g->prims.mesh_count, &m) : an->mNumMeshes == 0;
    if (mesh && lined_up) {
        size_t first = g->prims.first[m], count = g->prims.first[m + 1] - first;
        lined_up = an->mNumMeshes == count;
        for (size_t p = 0; lined_up && p < count; p++)
            lined_up = an->mMeshes[p] < ai->mNumMeshes &&
                       mode_matches(g->prims.mode[first + p], ai->mMeshes[an->mMeshes[p]]);
        for (size_t p = 0; lined_up && p < count; p++) {
            size_t *slot = &g->prim_of[an->mMeshes[p]];
            if (*slot == PRIM_NONE)
                *slot = first + p;
            else if (*slot != first + p)
                *slot = PRIM_SPOILT;
        }
    }
    if (!lined_up)
        for (unsigned k = 0; k < an->mNumMeshes; k++)
            if (an->mMeshes[k] < ai->mNumMeshes)
                g->prim_of[an->mMeshes[k]] = PRIM_SPOILT;
    const cJSON *children = lx_gltf_get(node, "children");
    if (count_node_refs(g, children) != an->mNumChildren) {
        for (unsigned k = 0; k < an->mNumChildren; k++)
            map_spoil(g, ai, an->mChildren[k], depth + 1);
        return;
    }
    unsigned k = 0;
    size_t index;
    for (const cJSON *e = cJSON_IsArray(children) ? children->child : NULL; e; e = e->next)
        if (lx_gltf_index(e, g->node_count, &index))
            map_node(g, ai, index, an->mChildren[k++], depth + 1);
}

/* Pairs the nodes of the scene assimp imports ("scene", else scene 0). */
static void map_scene(gltf_map *g, const struct aiScene *ai, const cJSON *root)
{
    const struct aiNode *an = ai->mRootNode;
    const cJSON *scenes = lx_gltf_get(root, "scenes");
    size_t n_scenes = cJSON_IsArray(scenes) ? (size_t)cJSON_GetArraySize(scenes) : 0, si = 0;
    const cJSON *scene = lx_gltf_get(root, "scene");
    if ((scene && !lx_gltf_index(scene, n_scenes, &si)) || si >= n_scenes) {
        map_spoil(g, ai, an, 0);
        return;
    }
    const cJSON *list = lx_gltf_get(cJSON_GetArrayItem(scenes, (int)si), "nodes");
    size_t n = count_node_refs(g, list), index = 0;
    const cJSON *e = cJSON_IsArray(list) ? list->child : NULL;
    while (e && !lx_gltf_index(e, g->node_count, &index))
        e = e->next;
    if (n == 1) {
        map_node(g, ai, index, an, 0);
        return;
    }
    /* no root nodes or several: assimp's own root holds them */
    if (an->mNumMeshes != 0 || an->mNumChildren != n) {
        map_spoil(g, ai, an, 0);
        return;
    }
    unsigned k = 0;
    for (; e; e = e->next)
        if (lx_gltf_index(e, g->node_count, &index))
            map_node(g, ai, index, an->mChildren[k++], 1);
}

static int pair_order(const void *a, const void *b)
{
    uintptr_t x = (uintptr_t)((const struct node_pair *)a)->ai;
    uintptr_t y = (uintptr_t)((const struct node_pair *)b)->ai;
    return x < y ? -1 : x > y;
}

/* The JSON node an aiNode is, or -1 (unmatched, or paired twice). */
static int32_t map_node_index(const gltf_map *g, const struct aiNode *an)
{
    if (!g || !g->pair_count)
        return -1;
    size_t lo = 0, hi = g->pair_count;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if ((uintptr_t)g->pairs[mid].ai < (uintptr_t)an)
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo == g->pair_count || g->pairs[lo].ai != an ||
        (lo + 1 < g->pair_count && g->pairs[lo + 1].ai == an))
        return -1;
    return g->pairs[lo].json <= INT32_MAX ? (int32_t)g->pairs[lo].json : -1;
}

static lx_status gltf_map_build(const import_ctx *c, gltf_map *g)
{
    memset(g, 0, sizeof *g);
    const struct aiScene *ai = c->ai;
    lx_status st = lx_gltf_primitives_read(c->path, c->gltf, &g->prims);
    if (st != LX_OK)
        return st;
    const cJSON *nodes = lx_gltf_get(c->gltf, "nodes");
    const cJSON *materials = lx_gltf_get(c->gltf, "materials");
    for (const cJSON *e = cJSON_IsArray(nodes) ? nodes->child : NULL; e; e = e->next)
        g->node_count++;
    for (const cJSON *e = cJSON_IsArray(materials) ? materials->child : NULL; e; e = e->next)
        g->material_count++;
    g->nodes = malloc((g->node_count ? g->node_count : 1) * sizeof *g->nodes);
    g->materials = malloc((g->material_count ? g->material_count : 1) * sizeof *g->materials);
    g->prim_of = malloc((ai->mNumMeshes ? ai->mNumMeshes : 1) * sizeof *g->prim_of);
    g->material_of = malloc((ai->mNumMaterials ? ai->mNumMaterials : 1) * sizeof *g->material_of);
    if (!g->nodes || !g->materials || !g->prim_of || !g->material_of) {
        size_t n = g->node_count;
        gltf_map_free(g);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory matching %zu glTF nodes", c->path, n);
    }
    size_t i = 0;
    for (const cJSON *e = cJSON_IsArray(nodes) ? nodes->child : NULL; e; e = e->next)
        g->nodes[i++] = e;
    i = 0;
    for (const cJSON *e = cJSON_IsArray(materials) ? materials->child : NULL; e; e = e->next)
        g->materials[i++] = e;
    for (unsigned k = 0; k < ai->mNumMeshes; k++)
        g->prim_of[k] = PRIM_NONE;
    for (unsigned k = 0; k < ai->mNumMaterials; k++)
        g->material_of[k] = MAT_UNKNOWN;
    map_scene(g, ai, c->gltf);
    qsort(g->pairs, g->pair_count, sizeof *g->pairs, pair_order);
    unsigned unmatched = 0;
    for (unsigned k = 0; k < ai->mNumMeshes; k++)
        unmatched += g->prim_of[k] >= g->prims.count;
    if (unmatched && c->log_watched)
        lx_log(LX_LOG_INFO,
               "%s: %u of %u meshes are not matched to the file's primitives through its nodes; "
               "faces assimp drops from them are noticed through its log",
               c->path, unmatched, ai->mNumMeshes);
    for (unsigned k = 0; k < ai->mNumMeshes; k++) {
        size_t f = g->prim_of[k];
        unsigned a = ai->mMeshes[k]->mMaterialIndex;
        if (f >= g->prims.count || a >= ai->mNumMaterials)
            continue;
        int64_t want = g->prims.material[f], *have = &g->material_of[a];
        if (want == LX_GLTF_BAD_MATERIAL)
            *have = MAT_SPOILT;
        else if (*have == MAT_UNKNOWN)
            *have = want;
        else if (*have != want)
            *have = MAT_SPOILT;
    }
    return LX_OK;
}

static bool ref_equal(const lx_gltf_texture_ref *a, const lx_gltf_texture_ref *b)
{
    const lx_uv_transform *s = &a->transform, *t = &b->transform;
    return a->present == b->present && a->tex_coord == b->tex_coord && s->enabled == t->enabled &&
           s->offset.x == t->offset.x && s->offset.y == t->offset.y && s->rotation == t->rotation &&
           s->scale.x == t->scale.x && s->scale.y == t->scale.y;
}

/* The file's texture references (texCoord, KHR_texture_transform) for
 * assimp's material i, whose base-colour and normal textures luxel reads
 * when has_base / has_normal; both zeroed when assimp's own are right. A
 * material matched through the nodes takes its JSON material's. One no
 * paired mesh uses is matched by what assimp copies, its name: when every
 * JSON material of that name (of any name if none has it) states the same
 * references for those textures, they are its; when none of them has a
 * KHR_texture_transform, assimp's texCoord is the file's. Otherwise its
 * transform cannot be told and the load fails rather than guess. */
/* The UV sets material i's textures read (lx_material.uv_sets_read):
 * assimp's for every texture it knows, the file's own for a glTF
 * material (extensions' textures, which assimp drops). */
static uint32_t texcoords_read(const import_ctx *c, const struct aiMaterial *am, unsigned i)
{
    uint32_t sets = 0;
    for (int type = aiTextureType_NONE + 1; type <= aiTextureType_UNKNOWN; type++) {
        unsigned count = aiGetMaterialTextureCount(am, (enum aiTextureType)type);
        for (unsigned k = 0; k < count && k < 64; k++) {
            struct aiString path;
            unsigned uv = 0;
            if (aiGetMaterialTexture(am, (enum aiTextureType)type, k, &path, NULL, &uv, NULL,
                                     NULL, NULL, NULL) == aiReturn_SUCCESS &&
                uv < 32)
                sets |= 1u << uv;
        }
    }
    if (c->map && c->map->material_of[i] >= 0 &&
        (size_t)c->map->material_of[i] < c->map->material_count)
        sets |= lx_gltf_texcoords_read(c->map->materials[c->map->material_of[i]]);
    return sets;
}

/* KHR_materials_unlit on glTF material i: the file's JSON when the
 * material is matched to it, else assimp's shading model (its glTF 2.0
 * reader sets aiShadingMode_Unlit for the extension). Other formats:
 * never (assimp's "no shading" also stands for OBJ's illum 0). */
static bool material_unlit(const import_ctx *c, const struct aiMaterial *am, unsigned i)
{
    if (!c->gltf)
        return false;
    if (c->map && c->map->material_of[i] >= 0 &&
        (size_t)c->map->material_of[i] < c->map->material_count)
        return lx_gltf_get(lx_gltf_get(c->map->materials[c->map->material_of[i]], "extensions"),
                           "KHR_materials_unlit") != NULL;
    int mode = 0;
    unsigned max = 1;
    return aiGetMaterialIntegerArray(am, AI_MATKEY_SHADING_MODEL, &mode, &max) ==
               aiReturn_SUCCESS &&
           mode == aiShadingMode_Unlit;
}

/* KHR_materials_pbrSpecularGlossiness on glTF material am: its diffuse
 * colour is the albedo (the extension's spec; a pbrMetallicRoughness beside
 * it is the fallback for readers without the extension, and three.js, as
 * luxel, prefers the extension). assimp 5.2.5's glTF 2.0 reader puts
 * diffuseFactor and diffuseTexture in the diffuse colour and texture while
 * its base-colour keys keep pbrMetallicRoughness's, and sets the
 * glossiness factor only for this extension (material.h: "If
 * AI_MATKEY_GLOSSINESS_FACTOR is set, then a Specular/Glossiness is
 * available"): that key tells, so the colour, the texture and its
 * reference (material_refs) always come from the same place. */
static bool material_spec_gloss(const import_ctx *c, const struct aiMaterial *am)
{
    ai_real gloss;
    return c->gltf && aiGetMaterialFloatArray(am, AI_MATKEY_GLOSSINESS_FACTOR, &gloss, NULL) ==
                          aiReturn_SUCCESS;
}

/* glTF's doubleSided on material i: the file's JSON when the material is
 * matched to it, else assimp's two-sided flag (its glTF 2.0 reader copies
 * doubleSided there; other readers set it for their own two-sided
 * materials). */
static bool material_double_sided(const import_ctx *c, const struct aiMaterial *am, unsigned i)
{
    if (c->gltf && c->map && c->map->material_of[i] >= 0 &&
        (size_t)c->map->material_of[i] < c->map->material_count)
        return cJSON_IsTrue(lx_gltf_get(c->map->materials[c->map->material_of[i]], "doubleSided"));
    int two = 0;
    unsigned max = 1;
    return aiGetMaterialIntegerArray(am, AI_MATKEY_TWOSIDED, &two, &max) == aiReturn_SUCCESS &&
           two != 0;
}

static lx_status material_refs(const import_ctx *c, unsigned i, const char *label, bool has_base,
                               bool has_normal, bool spec_gloss, lx_gltf_texture_ref *base,
                               lx_gltf_texture_ref *normal)
{
    memset(base, 0, sizeof *base);
    memset(normal, 0, sizeof *normal);
    if (!c->gltf || !c->map || (!has_base && !has_normal))
        return LX_OK;
    const gltf_map *g = c->map;
    int64_t j = g->material_of[i];
    if (j >= 0 && (size_t)j < g->material_count)
        return lx_gltf_material_textures(c->path, g->materials[j], (size_t)j, spec_gloss, base,
                                         normal);
    struct aiString name;
    bool named =
        aiGetMaterialString(c->ai->mMaterials[i], AI_MATKEY_NAME, &name) == aiReturn_SUCCESS &&
        name.length;
    size_t candidates = 0;
    bool any_transform = false, same = true;
    lx_gltf_texture_ref b0 = {0}, n0 = {0};
    for (int widen = 0; widen < 2 && candidates == 0; widen++) {
        for (size_t k = 0; k < g->material_count && (same || !any_transform); k++) {
            const char *jname = lx_gltf_get_string(g->materials[k], "name");
            bool match = named ? jname && strncmp(jname, name.data, sizeof name.data - 1) == 0
                               : !jname || !jname[0];
            if (!widen && !match)
                continue;
            lx_gltf_texture_ref b, nm;
            candidates++;
            if (lx_gltf_material_textures(c->path, g->materials[k], k, spec_gloss, &b, &nm) !=
                LX_OK) {
                /* a malformed candidate cannot vouch for anything */
                any_transform = true;
                same = false;
                continue;
            }
            if (!has_base)
                b = (lx_gltf_texture_ref){0};
            if (!has_normal)
                nm = (lx_gltf_texture_ref){0};
            any_transform |= b.transform.enabled || nm.transform.enabled;
            if (candidates == 1) {
                b0 = b;
                n0 = nm;
            } else {
                same &= ref_equal(&b, &b0) && ref_equal(&nm, &n0);
            }
        }
    }
    if (!any_transform)
        return LX_OK;
    if (same) {
        *base = b0;
        *normal = n0;
        return LX_OK;
    }
    return lx_fail(LX_ERR_UNSUPPORTED,
                   "%s: material '%s': its KHR_texture_transform cannot be told: no mesh matched "
                   "to the file's primitives uses it, and the file's materials it may be (by "
                   "name) differ in KHR_texture_transform or texCoord",
                   c->path, label);
}

static lx_status import_materials(import_ctx *c)
{
    for (unsigned i = 0; i < c->ai->mNumMaterials; i++) {
        const struct aiMaterial *am = c->ai->mMaterials[i];
        lx_material m = {0};
        struct aiString name;
        char name_buf[LX_NAME_MAX];
        if (aiGetMaterialString(am, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS && name.length)
            snprintf(name_buf, sizeof name_buf, "%s", name.data);
        else
            snprintf(name_buf, sizeof name_buf, "material%u", i);
        m.name = name_buf;
        struct aiColor4D col;
        bool spec_gloss = material_spec_gloss(c, am);
        m.base_color = lx_v4(1, 1, 1, 1);
        if (spec_gloss
                ? aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &col) == aiReturn_SUCCESS
                : aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &col) == aiReturn_SUCCESS ||
                      aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &col) == aiReturn_SUCCESS)
            m.base_color = lx_v4(col.r, col.g, col.b, col.a);
        if (!(isfinite(m.base_color.x) && isfinite(m.base_color.y) && isfinite(m.base_color.z)) ||
            m.base_color.x < 0 || m.base_color.y < 0 || m.base_color.z < 0)
            return lx_fail(LX_ERR_FORMAT,
                           "%s: material '%s': base colour is not a finite "
                           "non-negative colour",
                           c->path, name_buf);
        if (aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &col) == aiReturn_SUCCESS &&
            isfinite(col.r) && isfinite(col.g) && isfinite(col.b) && col.r >= 0 && col.g >= 0 &&
            col.b >= 0)
            m.emissive = lx_v3(col.r, col.g, col.b);
        if (c->map && c->map->material_of[i] >= 0 &&
            (size_t)c->map->material_of[i] < c->map->material_count) {
            /* assimp 5.2.5 drops KHR_materials_emissive_strength */
            size_t j = (size_t)c->map->material_of[i];
            lx_status est =
                lx_gltf_material_emissive(c->path, c->map->materials[j], j, &m.emissive);
            if (est != LX_OK)
                return est;
        }
        m.uv_sets_read = texcoords_read(c, am, i);
        m.unlit = material_unlit(c, am, i);
        m.double_sided = material_double_sided(c, am, i);
        struct aiString tex;
        bool has_normal = aiGetMaterialTexture(am, aiTextureType_NORMALS, 0, &tex, NULL, NULL, NULL,
                                               NULL, NULL, NULL) == aiReturn_SUCCESS;
        /* a spec-gloss material's texture is its diffuse one (assimp's
         * diffuse slot, which holds the fallback's baseColorTexture when the
         * extension has no diffuseTexture: the file's JSON tells then) */
        bool has_base =
            (!spec_gloss && aiGetMaterialTexture(am, aiTextureType_BASE_COLOR, 0, &tex, NULL, NULL,
                                                 NULL, NULL, NULL, NULL) == aiReturn_SUCCESS) ||
            aiGetMaterialTexture(am, aiTextureType_DIFFUSE, 0, &tex, NULL, NULL, NULL, NULL, NULL,
                                 NULL) == aiReturn_SUCCESS;
        lx_gltf_texture_ref ref_base = {0}, ref_normal = {0};
        lx_status st =
            material_refs(c, i, name_buf, has_base, has_normal, spec_gloss, &ref_base, &ref_normal);
        if (st != LX_OK)
            return st;
        if (spec_gloss && has_base && !ref_base.present && c->map && c->map->material_of[i] >= 0 &&
            (size_t)c->map->material_of[i] < c->map->material_count)
            has_base = false; /* the extension has no diffuseTexture */
        unsigned uv = 0;
        if (aiGetMaterialTexture(am, aiTextureType_NORMALS, 0, &tex, NULL, &uv, NULL, NULL, NULL,
                                 NULL) == aiReturn_SUCCESS) {
            st = request_texture(c, &tex, true, "normal", LX_TEXTURE_NORMAL, &m.normal_map_path);
            if (st != LX_OK)
                return st;
            if (ref_normal.present) {
                uv = ref_normal.tex_coord;
                m.normal_transform = ref_normal.transform;
            }
            /* checked unsigned: a huge texCoord must not wrap to -1 */
            m.normal_uv_set = uv < LX_MAX_UV_SETS ? (int)uv : LX_MAX_UV_SETS;
            /* glTF normalTexture.scale scales the map's x and y */
            ai_real scale = 1;
            if (aiGetMaterialFloatArray(am, AI_MATKEY_GLTF_TEXTURE_SCALE(aiTextureType_NORMALS, 0),
                                        &scale, NULL) == aiReturn_SUCCESS &&
                isfinite(scale))
                m.normal_scale = scale;
        }
        uv = 0;
        if (has_base &&
            ((!spec_gloss && aiGetMaterialTexture(am, aiTextureType_BASE_COLOR, 0, &tex, NULL, &uv,
                                                  NULL, NULL, NULL, NULL) == aiReturn_SUCCESS) ||
             aiGetMaterialTexture(am, aiTextureType_DIFFUSE, 0, &tex, NULL, &uv, NULL, NULL, NULL,
                                  NULL) == aiReturn_SUCCESS)) {
            st = request_texture(c, &tex, false, "base colour", LX_TEXTURE_BASE_COLOR,
                                 &m.base_color_map_path);
            if (st != LX_OK) {
                free(m.normal_map_path);
                return st;
            }
            if (ref_base.present) {
                uv = ref_base.tex_coord;
                m.base_color_transform = ref_base.transform;
            }
            m.base_color_uv_set = uv < LX_MAX_UV_SETS ? (int)uv : LX_MAX_UV_SETS;
        }
        /* the emissive texture (its KHR_texture_transform when the
         * material is matched to the file's) */
        uv = 0;
        if (aiGetMaterialTexture(am, aiTextureType_EMISSIVE, 0, &tex, NULL, &uv, NULL, NULL, NULL,
                                 NULL) == aiReturn_SUCCESS) {
            st = request_texture(c, &tex, false, "emissive", LX_TEXTURE_EMISSIVE,
                                 &m.emissive_map_path);
            if (st == LX_OK && c->gltf && c->map && c->map->material_of[i] >= 0 &&
                (size_t)c->map->material_of[i] < c->map->material_count) {
                size_t j = (size_t)c->map->material_of[i];
                lx_gltf_texture_ref ref;
                st = lx_gltf_material_emissive_texture(c->path, c->map->materials[j], j, &ref);
                if (st == LX_OK && ref.present) {
                    uv = ref.tex_coord;
                    m.emissive_transform = ref.transform;
                }
            }
            if (st != LX_OK) {
                free(m.normal_map_path);
                free(m.base_color_map_path);
                free(m.emissive_map_path);
                return st;
            }
            m.emissive_uv_set = uv < LX_MAX_UV_SETS ? (int)uv : LX_MAX_UV_SETS;
            if (m.emissive_uv_set >= LX_MAX_UV_SETS) {
                lx_log(LX_LOG_WARN,
                       "%s: material '%s': emissive texture on UV set %u is not supported "
                       "(0 to 7 are); ignored",
                       c->path, name_buf, uv);
                drop_texture(c, LX_TEXTURE_EMISSIVE);
                m.emissive_uv_set = 0;
                m.emissive_transform = (lx_uv_transform){0};
            }
        }
        if (m.normal_uv_set >= LX_MAX_UV_SETS || m.base_color_uv_set >= LX_MAX_UV_SETS) {
            lx_log(LX_LOG_WARN,
                   "%s: material '%s': textures on UV sets above 7 are not "
                   "supported; ignored",
                   c->path, name_buf);
            if (m.normal_uv_set >= LX_MAX_UV_SETS) {
                drop_texture(c, LX_TEXTURE_NORMAL);
                m.normal_uv_set = 0;
                m.normal_transform = (lx_uv_transform){0};
            }
            if (m.base_color_uv_set >= LX_MAX_UV_SETS) {
                drop_texture(c, LX_TEXTURE_BASE_COLOR);
                m.base_color_uv_set = 0;
                m.base_color_transform = (lx_uv_transform){0};
            }
        }
        if (m.normal_scale == 0.0f)
            m.normal_scale = 1.0f;
        st = lx_scene_add_material(c->scene, &m, NULL);
        free(m.normal_map_path);
        free(m.base_color_map_path);
        free(m.emissive_map_path);
        if (st != LX_OK)
            return st;
    }
    if (c->scene->material_count == 0) {
        lx_material m = {.name = "default", .base_color = {1, 1, 1, 1}, .normal_scale = 1};
        return lx_scene_add_material(c->scene, &m, NULL);
    }
    return LX_OK;
}

static lx_status import_mesh(import_ctx *c, unsigned i)
{
    const struct aiMesh *am = c->ai->mMeshes[i];
    char name[LX_NAME_MAX];
    if (am->mName.length)
        snprintf(name, sizeof name, "%s", am->mName.data);
    else
        snprintf(name, sizeof name, "mesh%u", i);
    c->mesh_map[i] = UINT32_MAX;
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || am->mNumFaces == 0) {
        lx_log(LX_LOG_WARN, "%s: mesh '%s' has no triangles (points or lines); skipped", c->path,
               name);
        return LX_OK;
    }
    uint32_t nv = am->mNumVertices;
    lx_mesh m = {0};
    m.name = name;
    m.vertex_count = nv;
    m.material = am->mMaterialIndex < c->scene->material_count ? am->mMaterialIndex : 0;
    lx_status st = LX_OK;
    m.positions = malloc(sizeof(lx_vec3) * (nv ? nv : 1));
    m.indices = malloc(sizeof(uint32_t) * 3 * (size_t)am->mNumFaces);
    if (!m.positions || !m.indices) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory reading mesh '%s'", c->path, name);
        goto done;
    }
    for (uint32_t v = 0; v < nv; v++)
        m.positions[v] = lx_v3(am->mVertices[v].x, am->mVertices[v].y, am->mVertices[v].z);
    if (am->mNormals) {
        m.normals = malloc(sizeof(lx_vec3) * nv);
        if (!m.normals) {
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
            goto done;
        }
        for (uint32_t v = 0; v < nv; v++)
            m.normals[v] = lx_v3(am->mNormals[v].x, am->mNormals[v].y, am->mNormals[v].z);
    }
    for (int k = 0; k < LX_MAX_UV_SETS; k++) {
        if (!am->mTextureCoords[k])
            continue;
        m.uv[k] = malloc(sizeof(lx_vec2) * nv);
        if (!m.uv[k]) {
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
            goto done;
        }
        /* aiProcess_FlipUVs already put the origin at the top-left */
        for (uint32_t v = 0; v < nv; v++)
            m.uv[k][v] = lx_v2(am->mTextureCoords[k][v].x, am->mTextureCoords[k][v].y);
    }
    if (am->mTangents && am->mBitangents && am->mNormals) {
        m.tangents = malloc(sizeof(lx_vec4) * nv);
        if (!m.tangents) {
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
            goto done;
        }
        for (uint32_t v = 0; v < nv; v++) {
            lx_vec3 t = lx_v3(am->mTangents[v].x, am->mTangents[v].y, am->mTangents[v].z);
            lx_vec3 b = lx_v3(am->mBitangents[v].x, am->mBitangents[v].y, am->mBitangents[v].z);
            float w = lx_dot(lx_cross(m.normals[v], t), b) < 0.0f ? -1.0f : 1.0f;
            m.tangents[v] = lx_v4(t.x, t.y, t.z, w);
        }
    }
    uint32_t tri = 0, skipped = 0, not_tri = 0;
    for (unsigned f = 0; f < am->mNumFaces; f++) {
        const struct aiFace *face = &am->mFaces[f];
        if (face->mNumIndices != 3) {
            not_tri++;
            continue;
        }
        uint32_t *dst = &m.indices[3 * tri];
        for (int k = 0; k < 3; k++) {
            dst[k] = face->mIndices[k];
            if (dst[k] >= nv) {
                st = lx_fail(LX_ERR_FORMAT,
                             "%s: mesh '%s': face %u: index %u out of range "
                             "(count %u)",
                             c->path, name, f, dst[k], nv);
                goto done;
            }
        }
        if (!lx_vec3_finite(m.positions[dst[0]]) || !lx_vec3_finite(m.positions[dst[1]]) ||
            !lx_vec3_finite(m.positions[dst[2]])) {
            st = lx_fail(LX_ERR_FORMAT, "%s: mesh '%s': face %u: position is not finite", c->path,
                         name, f);
            goto done;
        }
        if (lx_triangle_degenerate(m.positions[dst[0]], m.positions[dst[1]], m.positions[dst[2]])) {
            if (c->dropped == 0 && skipped == 0) {
                snprintf(c->first_dropped, sizeof c->first_dropped, "%s", name);
                c->first_dropped_face = f;
            }
            skipped++;
            continue;
        }
        tri++;
    }
    if (skipped) {
        c->dropped += skipped;
        c->dropped_meshes++;
    }
    if (not_tri)
        lx_log(LX_LOG_WARN, "%s: mesh '%s': %u point/line primitives skipped", c->path, name,
               not_tri);
    if (tri == 0) {
        lx_log(LX_LOG_WARN, "%s: mesh '%s' has no usable triangles; skipped", c->path, name);
        goto done;
    }
    m.triangle_count = tri;
    m.dropped_triangles = skipped;
    m.source_mesh = m.source_primitive = -1;
    if (c->map && c->map->prim_of[i] < c->map->prims.count) {
        size_t f = c->map->prim_of[i];
        m.source_mesh = (int32_t)c->map->prims.mesh[f];
        m.source_primitive = (int32_t)(f - c->map->prims.first[m.source_mesh]);
    }
    if (c->desc->strict && c->dropped)
        goto done; /* the load fails once every mesh is counted */
    st = lx_scene_add_mesh(c->scene, &m, &c->mesh_map[i]);
done:
    free(m.positions);
    free(m.normals);
    free(m.tangents);
    free(m.indices);
    for (int k = 0; k < LX_MAX_UV_SETS; k++)
        free(m.uv[k]);
    return st;
}

/* A node name unique in the scene: the node's own, else "node<N>", with
 * "_2", "_3"... appended on collisions. */
static void unique_node_name(const lx_scene *s, const char *base, char *out, size_t size)
{
    snprintf(out, size, "%s", base);
    for (int n = 2;; n++) {
        bool taken = false;
        for (uint32_t i = 0; i < s->node_count && !taken; i++)
            taken = strcmp(s->nodes[i].name, out) == 0;
        if (!taken)
            return;
        snprintf(out, size, "%s_%d", base, n);
    }
}

static lx_status import_node(import_ctx *c, const struct aiNode *node, const lx_mat4 *parent,
                             int depth, uint32_t *counter)
{
    if (depth > LX_NODE_DEPTH_MAX)
        return lx_fail(LX_ERR_FORMAT, "%s: node hierarchy deeper than %d levels", c->path,
                       LX_NODE_DEPTH_MAX);
    lx_mat4 local = mat4_from_ai(&node->mTransformation);
    lx_mat4 world = lx_mat4_mul(parent, &local);
    (*counter)++;
    if (node->mNumMeshes) {
        uint32_t *meshes = malloc(sizeof(uint32_t) * node->mNumMeshes);
        if (!meshes)
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory", c->path);
        uint32_t n = 0;
        for (unsigned k = 0; k < node->mNumMeshes; k++) {
            unsigned mi = node->mMeshes[k];
            if (mi >= c->ai->mNumMeshes) {
                free(meshes);
                return lx_fail(LX_ERR_FORMAT, "%s: node '%s': mesh %u out of range (count %u)",
                               c->path, node->mName.data, mi, c->ai->mNumMeshes);
            }
            if (c->mesh_map[mi] != UINT32_MAX)
                meshes[n++] = c->mesh_map[mi];
        }
        lx_status st = LX_OK;
        if (n && lx_mat4_finite(&world) && !(fabsf(lx_mat4_det3(&world)) > 1e-20f)) {
            /* exporters hide objects with a zero scale: nothing to bake */
            lx_log(LX_LOG_WARN, "%s: node '%s' has a zero scale; skipped", c->path,
                   node->mName.data);
            n = 0;
        }
        if (n) {
            char base[LX_NAME_MAX], name[LX_NAME_MAX + 16];
            if (node->mName.length)
                snprintf(base, sizeof base, "%s", node->mName.data);
            else
                snprintf(base, sizeof base, "node%u", *counter - 1);
            unique_node_name(c->scene, base, name, sizeof name);
            uint32_t index;
            st = lx_scene_add_node(c->scene, name, &world, meshes, n, &index);
            if (st == LX_OK)
                c->scene->nodes[index].source_node = map_node_index(c->map, node);
        }
        free(meshes);
        if (st != LX_OK)
            return st;
    }
    for (unsigned k = 0; k < node->mNumChildren; k++) {
        lx_status st = import_node(c, node->mChildren[k], &world, depth + 1, counter);
        if (st != LX_OK)
            return st;
    }
    return LX_OK;
}

/* Faces assimp's glTF 2.0 importer dropped: it leaves out every triangle
 * with a vertex index past its primitive's vertices and says so only in
 * its log, without naming the mesh. A triangle aiMesh matched to its
 * primitive (gltf_map) that has fewer faces than the primitive's accessor
 * defines fails the load, naming the primitive (the first in file order).
 * Where no such count vouches for a triangle mesh (not matched, or the
 * accessor's count unknown), the log decides: an import that did not
 * watch it sets *need_log (the file is imported again, watched); a
 * watched one fails the load when the log told of dropped faces, naming
 * such a mesh. Point and line meshes, which luxel skips, fail nothing. */
static lx_status check_dropped_faces(const import_ctx *c, bool *need_log)
{
    const gltf_map *g = c->map;
    size_t worst = SIZE_MAX; /* the failing primitive first in file order */
    uint64_t worst_faces = 0;
    unsigned unproven = 0, first_unproven = 0;
    for (unsigned k = 0; k < c->ai->mNumMeshes; k++) {
        const struct aiMesh *am = c->ai->mMeshes[k];
        if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        size_t f = g->prim_of[k];
        if (f < g->prims.count && g->prims.triangles[f] != UINT64_MAX) {
            if ((uint64_t)am->mNumFaces < g->prims.triangles[f] &&
                (worst == SIZE_MAX || f < worst)) {
                worst = f;
                worst_faces = am->mNumFaces;
            }
            continue;
        }
        if (unproven++ == 0)
            first_unproven = k;
    }
    if (worst != SIZE_MAX) {
        uint32_t m = g->prims.mesh[worst];
        uint64_t want = g->prims.triangles[worst];
        char who[128];
        lx_gltf_label(who, sizeof who, "mesh", m,
                      cJSON_GetArrayItem(lx_gltf_get(c->gltf, "meshes"), (int)m));
        return lx_fail(LX_ERR_FORMAT,
                       "%s: %s: primitive %zu: %llu of %llu triangles have vertex indices out "
                       "of range",
                       c->path, who, worst - g->prims.first[m],
                       (unsigned long long)(want - worst_faces), (unsigned long long)want);
    }
    if (unproven && !c->log_watched) {
        *need_log = true;
        return LX_OK;
    }
    if (c->log_dropped && unproven) {
        const struct aiMesh *am = c->ai->mMeshes[first_unproven];
        return lx_fail(LX_ERR_FORMAT,
                       "%s: some triangles have vertex indices out of range (assimp dropped them "
                       "from mesh '%s'%s, which luxel could not match to the file's primitives)",
                       c->path, am->mName.data, unproven > 1 ? " or another" : "");
    }
    return LX_OK;
}

/* True when assimp's glTF 2.0 importer read the file (it names itself in
 * the scene's metadata), so its nodes follow the JSON's (gltf_map). */
static bool read_by_gltf2(const struct aiScene *ai)
{
    const struct aiMetadata *md = ai->mMetaData;
    for (unsigned i = 0; md && i < md->mNumProperties; i++)
        if (strcmp(md->mKeys[i].data, "SourceAsset_Format") == 0 &&
            md->mValues[i].mType == AI_AISTRING && md->mValues[i].mData)
            return strncmp(((const struct aiString *)md->mValues[i].mData)->data, "glTF2", 5) == 0;
    return false;
}

/* One import of path; gltf is its JSON or NULL. Unwatched (the first
 * try), a glTF 2.0 triangle mesh whose faces the JSON cannot vouch for
 * sets *need_log and ends the import early with LX_OK and no scene; the
 * caller then imports the file again with assimp's log watched. */
static lx_status import_scene(const char *path, const import_source *src,
                              const lx_scene_load_desc *desc, const cJSON *gltf, bool gltf2,
                              bool watch_log, bool *need_log, lx_scene **out)
{
    *need_log = false;
    assimp_import im;
    lx_status st = assimp_import_file(path, src, watch_log, gltf2, &im);
    if (st != LX_OK)
        return st;
    const struct aiScene *ai = im.ai;
    /* a glTF 2.0 file's primitives are checked one by one below; one its
     * JSON does not declare 2.x (assimp reads a version "2") only through
     * the log */
    bool read_gltf2 = read_by_gltf2(ai);
    bool by_gltf2 = gltf2 && read_gltf2;
    if (read_gltf2 && !by_gltf2 && !watch_log) {
        assimp_release(&im);
        *need_log = true;
        return LX_OK;
    }
    if (im.dropped && !by_gltf2) {
        assimp_release(&im);
        return lx_fail(LX_ERR_FORMAT, "%s: some faces have indices out of range", path);
    }
    /* assimp flags a scene without meshes incomplete; lights alone are fine */
    if (!ai->mRootNode) {
        assimp_release(&im);
        return lx_fail(LX_ERR_FORMAT, "%s: cannot import: the file has no scene", path);
    }
    import_ctx c = {.path = path,
                    .ai = ai,
                    .desc = desc,
                    .gltf = by_gltf2 ? gltf : NULL,
                    .log_watched = watch_log,
                    .log_dropped = im.dropped};
    gltf_map map = {0};
    st = lx_scene_create(path, &c.scene);
    if (st != LX_OK) {
        assimp_release(&im);
        return st;
    }
    c.folder = lx_path_dirname(path);
    c.mesh_map = malloc(sizeof(uint32_t) * (ai->mNumMeshes ? ai->mNumMeshes : 1));
    if (!c.folder || !c.mesh_map)
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    if (st == LX_OK && c.gltf) {
        st = gltf_map_build(&c, &map);
        c.map = &map;
    }
    if (st == LX_OK && c.gltf)
        st = check_dropped_faces(&c, need_log);
    if (st == LX_OK && *need_log) {
        assimp_release(&im);
        gltf_map_free(&map);
        free_textures(&c);
        free(c.mesh_map);
        free(c.folder);
        lx_scene_destroy(c.scene);
        return LX_OK;
    }
    if (st == LX_OK)
        st = import_materials(&c);
    for (unsigned i = 0; st == LX_OK && i < ai->mNumMeshes; i++)
        st = import_mesh(&c, i);
    if (st == LX_OK && c.dropped && desc->strict)
        st = lx_fail(LX_ERR_FORMAT,
                     "%s: %u zero-area triangles in %u meshes, the first in mesh '%s' (face %u)",
                     path, c.dropped, c.dropped_meshes, c.first_dropped, c.first_dropped_face);
    else if (st == LX_OK && c.dropped)
        lx_log(LX_LOG_WARN, "%s: %u zero-area triangles left out (of %u meshes)", path, c.dropped,
               c.dropped_meshes);
    if (st == LX_OK) {
        lx_mat4 root = lx_mat4_identity();
        uint32_t counter = 0;
        st = import_node(&c, ai->mRootNode, &root, 0, &counter);
    }
    /* per-node bake settings from the file, then sky domes and a backdrop
     * among the nodes whose extras do not say */
    if (st == LX_OK) {
        bool *decided = calloc(c.scene->node_count + 1, sizeof *decided);
        if (!decided)
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
        if (st == LX_OK && c.gltf)
            st = lx_gltf_node_extras_read(c.scene, path, c.gltf, decided);
        if (st == LX_OK)
            lx_scene_mark_sky_domes_except(c.scene, decided);
        if (st == LX_OK)
            lx_scene_mark_backdrops_except(c.scene, decided);
        free(decided);
    }
    if (st == LX_OK)
        st = decode_textures(&c);
    if (st == LX_OK && gltf)
        st = lx_gltf_lights_from_json(c.scene, path, gltf);
    if (st == LX_OK && gltf)
        st = lx_gltf_cameras_from_json(c.scene, path, gltf);
    else if (st == LX_OK && ai->mNumLights)
        lx_log(LX_LOG_WARN,
               "%s: %u lights left out: luxel reads lights from glTF files only (give them with "
               "--lights)",
               path, ai->mNumLights);
    assimp_release(&im);
    gltf_map_free(&map);
    free_textures(&c);
    free(c.mesh_map);
    free(c.folder);
    if (st != LX_OK) {
        lx_scene_destroy(c.scene);
        return st;
    }
    *out = c.scene;
    return LX_OK;
}

/* One scene import, run on a thread of its own (run_import). */
typedef struct import_job {
    const char *path;
    const import_source *src;
    const lx_scene_load_desc *desc;
    const cJSON *gltf;
    bool gltf2;
    lx_scene **out;
    bool log_muted; /* the caller's thread's lx_log_mute */
    lx_status status;
    char error[1024]; /* the import thread's lx_last_error */
} import_job;

static void *import_job_run(void *arg)
{
    import_job *job = arg;
    if (job->log_muted)
        lx_log_mute(true);
    bool need_log = false;
    job->status = import_scene(job->path, job->src, job->desc, job->gltf, job->gltf2, false,
                               &need_log, job->out);
    /* a mesh the JSON cannot vouch for: assimp's log must tell */
    if (job->status == LX_OK && need_log)
        job->status = import_scene(job->path, job->src, job->desc, job->gltf, job->gltf2, true,
                                   &need_log, job->out);
    if (job->status != LX_OK)
        snprintf(job->error, sizeof job->error, "%s", lx_last_error());
    return NULL;
}

/* Runs the import on a thread with IMPORT_STACK_BYTES of stack and hands
 * its error message over to the caller's thread. Log messages go through
 * the process-wide callback, as from any thread. */
static lx_status run_import(import_job *job)
{
    pthread_attr_t attr;
    pthread_t thread;
    if (pthread_attr_init(&attr) != 0)
        return lx_fail(LX_ERR_NOMEM, "%s: cannot start the import thread", job->path);
    int err = pthread_attr_setstacksize(&attr, IMPORT_STACK_BYTES);
    if (err == 0)
        err = pthread_create(&thread, &attr, import_job_run, job);
    pthread_attr_destroy(&attr);
    if (err != 0)
        return lx_fail(LX_ERR_NOMEM, "%s: cannot start the import thread (%zu MB of stack): %s",
                       job->path, IMPORT_STACK_BYTES >> 20, strerror(err));
    pthread_join(thread, NULL);
    if (job->status != LX_OK)
        return lx_fail(job->status, "%s", job->error);
    return LX_OK;
}

lx_scene_load_desc lx_scene_load_desc_defaults(const lx_scene_load_desc *desc)
{
    lx_scene_load_desc d = {0};
    if (desc)
        d = *desc;
    return d; /* every field's zero is its default */
}

lx_status lx_scene_load(const char *path, const lx_scene_load_desc *in, lx_scene **out)
{
    if (!path)
        return lx_fail_null(__func__, "path");
    if (!out)
        return lx_fail_null(__func__, "out");
    *out = NULL;
    lx_scene_load_desc defaults = lx_scene_load_desc_defaults(in);
    const lx_scene_load_desc *desc = &defaults;
    struct stat st_buf;
    if (stat(path, &st_buf) != 0)
        return lx_fail(LX_ERR_IO, "%s: cannot open: no such file", path);
    if (!S_ISREG(st_buf.st_mode))
        return lx_fail(LX_ERR_IO, "%s: not a regular file", path);
    FILE *probe = fopen(path, "rb");
    if (!probe)
        return lx_fail(LX_ERR_IO, "%s: cannot open: permission denied or unreadable", path);
    fclose(probe);
    if (lx_lfs_pointer_file(path))
        return lx_fail(LX_ERR_FORMAT, "%s is a Git LFS pointer, not the file: run git lfs pull",
                       path);
    /* assimp picks a reader by the name and, failing that, by sniffing the
     * bytes, and some of its readers overrun buffers on malformed input
     * (OpenGEX on 20 bytes of "vertexarray (attrib)"): it only gets the
     * formats luxel lists, the glTF and OBJ ones checked below first */
    static const char *const formats[] = {".gltf", ".glb", ".obj", ".dae", ".fbx", ".ply", ".stl"};
    bool listed = false;
    for (size_t i = 0; i < sizeof formats / sizeof formats[0] && !listed; i++)
        listed = has_extension(path, formats[i]);
    if (!listed)
        return lx_fail(LX_ERR_UNSUPPORTED,
                       "%s: not a scene luxel reads (it reads .gltf, .glb, .obj, .dae, .fbx, .ply "
                       "and .stl files)",
                       path);

    if (has_extension(path, ".obj")) {
        lx_status st = check_obj_numbers(path);
        if (st != LX_OK)
            return st;
    }
    /* glTF by content, not by name: assimp recognises it either way */
    lx_gltf_kind kind = lx_gltf_sniff(path);
    if (kind == LX_GLTF_GLB || has_extension(path, ".glb")) {
        lx_status st = lx_glb_check_file(path);
        if (st != LX_OK)
            return st;
    }
    /* a .gltf that is not JSON would be handed to whichever assimp reader
     * claims its bytes (its OpenGEX reader overruns a buffer on 20 bytes
     * of "vertexarray (attrib)") */
    if (kind == LX_GLTF_NONE && has_extension(path, ".gltf"))
        return lx_fail(LX_ERR_FORMAT, "%s: not glTF: the file is not JSON text", path);
    cJSON *gltf = NULL;
    uint8_t *glb = NULL;
    size_t glb_size = 0;
    char *read_path = NULL;
    if (kind != LX_GLTF_NONE) {
        lx_status st = lx_gltf_json_read(path, &gltf);
        if (st == LX_OK)
            st = lx_gltf_check_required(path, gltf);
        if (st == LX_OK)
            st = lx_gltf_check_files(path, gltf, desc->allow_any_path);
        if (st == LX_OK)
            st = import_check_hierarchy(path, gltf);
        if (st == LX_OK && lx_gltf_is_v2(gltf))
            st = lx_gltf_check_cameras(path, gltf);
        if (st == LX_OK && lx_gltf_is_v2(gltf))
            st = lx_gltf_rewrite(path, gltf, &glb, &glb_size);
        /* assimp tells GLB from glTF text by the name */
        if (st == LX_OK && glb && !has_extension(path, ".glb")) {
            size_t n = strlen(path);
            if ((read_path = malloc(n + 5)) != NULL)
                memcpy(read_path, path, n), memcpy(read_path + n, ".glb", 5);
            else
                st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
        }
        if (st != LX_OK) {
            cJSON_Delete(gltf);
            free(glb);
            return st;
        }
    }
    if (!gltf) {
        lx_status st = import_check_hierarchy(path, NULL);
        if (st != LX_OK)
            return st;
    }
    char *folder = lx_path_dirname(path);
    if (!folder) {
        cJSON_Delete(gltf);
        free(glb);
        free(read_path);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    }
    import_source src = {.read_path = read_path ? read_path : path,
                         .bytes = glb,
                         .size = glb_size,
                         .path = path,
                         .folder = folder,
                         .allow_any_path = desc->allow_any_path,
                         .text_others = gltf == NULL};
    import_job job = {.path = path,
                      .src = &src,
                      .desc = desc,
                      .gltf = gltf,
                      .gltf2 = gltf && lx_gltf_is_v2(gltf),
                      .out = out,
                      .log_muted = lx_log_muted()};
    lx_status st = run_import(&job);
    if (st == LX_OK)
        (*out)->allow_any_path = desc->allow_any_path;
    free(folder);
    cJSON_Delete(gltf);
    free(glb);
    free(read_path);
    return st;
}
