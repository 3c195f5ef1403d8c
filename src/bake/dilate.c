/* Dilation (padding): each pass gives every empty texel next to filled ones
 * the average of its filled 8-neighbours, growing charts by one ring, so
 * bilinear filtering and mip levels near chart borders do not fetch black.
 *
 * The work follows the charts' border, not the image. One scan of the mask
 * finds the first frontier: the empty texels with a filled neighbour. A
 * pass computes only its frontier's texels and claims their empty
 * neighbours as the next frontier. Every texel carries a state byte; a
 * frontier is labelled with one of three labels in turn, so within a pass
 * the texels filled before it (given, grown, or the previous frontier),
 * this frontier (not yet readable) and the next one (being claimed) are
 * told apart without waiting between the steps: one parallel loop a pass.
 * A pass reads only texels filled before it, so the order in which its
 * texels are computed, and which thread claims a neighbour, cannot change
 * a value: results are bit-identical for any thread count (the frontiers'
 * order in memory may differ). The run is O(pixels) once plus O(texels
 * filled), where passing over the whole image each time was
 * O(passes * pixels).
 *
 * Nothing is written when the run is cancelled or runs out of memory: the
 * mask is updated at the end only, and the texels the passes wrote are put
 * back (to zero, or from a copy kept of those whose old value was not
 * zero). */
#include "core/internal.h"
#include "luxel/bake.h"

#include <omp.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Per-texel states. A frontier is labelled FRONT + (pass mod 3). */
enum {
    EMPTY = 0,
    GIVEN = 1,   /* filled in the caller's mask */
    GROWN = 2,   /* filled by a pass before the previous one */
    SKIPPED = 3, /* a pass could not keep its old value (out of memory): untouched */
    FRONT = 4    /* FRONT, FRONT + 1, FRONT + 2 */
};
#define LABEL(pass) ((uint8_t)(FRONT + (pass) % 3))

/* Frontier texels per chunk of parallel work. */
#define CHUNK 1024
/* Below these sizes a loop is too short to gain from more threads: waking
 * and joining them costs more (on a busy machine, up to a time slice
 * each). A pass's frontier in texels; a scan of the image in pixels. */
#define PARALLEL_FRONT 16384
#define PARALLEL_SCAN (1u << 20)

typedef _Atomic uint8_t state_t;

/* What one thread appends during a parallel loop. */
typedef struct thread_out {
    uint32_t *front; /* texels claimed for the next frontier */
    size_t count, cap;
    uint32_t *saved_at; /* texels overwritten whose value was not zero */
    float *saved;       /* their old values, channels each */
    size_t saved_count, saved_at_cap, saved_cap;
} thread_out;

typedef struct dilation {
    float *data;
    state_t *state;
    int width, height, channels, threads;
    uint32_t *prev, *cur, *spare; /* the previous and this pass's frontier */
    size_t prev_count, cur_count, prev_cap, cur_cap, spare_cap;
    thread_out *out; /* one per thread */
    _Atomic bool nomem;
} dilation;

lx_dilate_desc lx_dilate_desc_defaults(const lx_dilate_desc *desc)
{
    lx_dilate_desc d = {0};
    if (desc)
        d = *desc;
    return d;
}

static inline uint8_t get(const state_t *s)
{
    return atomic_load_explicit(s, memory_order_relaxed);
}

static inline void set(state_t *s, uint8_t v)
{
    atomic_store_explicit(s, v, memory_order_relaxed);
}

/* Grows *buf to hold at least `need` elements of `size` bytes. */
static bool grow(void **buf, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return true;
    size_t n = *cap ? *cap : 1024;
    while (n < need)
        n = n > SIZE_MAX / 2 ? need : 2 * n;
    if (n > SIZE_MAX / size)
        return false;
    void *p = realloc(*buf, n * size);
    if (!p)
        return false;
    *buf = p;
    *cap = n;
    return true;
}

static bool push(thread_out *t, uint32_t p)
{
    if (t->count == t->cap && !grow((void **)&t->front, &t->cap, t->count + 1, sizeof(uint32_t)))
        return false;
    t->front[t->count++] = p;
    return true;
}

/* Keeps texel p's old value when it is not all zero bits; false when out of
 * memory. */
static bool keep(thread_out *t, uint32_t p, const float *v, int channels)
{
    uint32_t bits = 0;
    for (int c = 0; c < channels; c++) {
        uint32_t b;
        memcpy(&b, &v[c], sizeof b);
        bits |= b;
    }
    if (!bits)
        return true;
    size_t n = t->saved_count;
    if (!grow((void **)&t->saved_at, &t->saved_at_cap, n + 1, sizeof(uint32_t)) ||
        !grow((void **)&t->saved, &t->saved_cap, (n + 1) * (size_t)channels, sizeof(float)))
        return false;
    t->saved_at[n] = p;
    memcpy(&t->saved[n * (size_t)channels], v, sizeof(float) * (size_t)channels);
    t->saved_count = n + 1;
    return true;
}

/* The threads' claimed texels, in thread order, become this pass's
 * frontier; the previous frontier's list is reused. */
static bool gather(dilation *d)
{
    size_t n = 0;
    for (int t = 0; t < d->threads; t++)
        n += d->out[t].count;
    if (!grow((void **)&d->spare, &d->spare_cap, n, sizeof(uint32_t)))
        return false;
    size_t at = 0;
    for (int t = 0; t < d->threads; t++) {
        if (d->out[t].count)
            memcpy(d->spare + at, d->out[t].front, sizeof(uint32_t) * d->out[t].count);
        at += d->out[t].count;
        d->out[t].count = 0;
    }
    uint32_t *old = d->prev;
    size_t old_cap = d->prev_cap;
    d->prev = d->cur, d->prev_cap = d->cur_cap, d->prev_count = d->cur_count;
    d->cur = d->spare, d->cur_cap = d->spare_cap, d->cur_count = n;
    d->spare = old, d->spare_cap = old_cap;
    return true;
}

/* States of every texel and the first frontier (labelled for pass 0), in
 * pixel order: rows are split in one contiguous block per thread, and the
 * threads' lists joined in thread order. */
static bool first_front(dilation *d, const uint8_t *mask)
{
    int w = d->width, h = d->height;
    uint8_t label = LABEL(0);
#pragma omp parallel num_threads(d->threads) if ((size_t)w * (size_t)h >= PARALLEL_SCAN)
    {
        thread_out mine = d->out[omp_get_thread_num()], *t = &mine;
#pragma omp for schedule(static)
        for (int y = 0; y < h; y++) {
            const uint8_t *row = mask + (size_t)y * w;
            const uint8_t *up = y > 0 ? row - w : row;
            const uint8_t *down = y + 1 < h ? row + w : row;
            /* any filled texel in columns x-1..x+1 of rows y-1..y+1 */
            uint8_t left = 0, mid = up[0] | row[0] | down[0];
            for (int x = 0; x < w; x++) {
                uint8_t right = x + 1 < w ? (uint8_t)(up[x + 1] | row[x + 1] | down[x + 1]) : 0;
                size_t p = (size_t)y * w + x;
                uint8_t s = row[x] ? GIVEN : (left | mid | right) ? label : EMPTY;
                set(&d->state[p], s);
                if (s == label && !push(t, (uint32_t)p))
                    atomic_store(&d->nomem, true);
                left = mid;
                mid = right;
            }
        }
        d->out[omp_get_thread_num()] = mine;
    }
    return !atomic_load(&d->nomem) && gather(d);
}

/* Pass k: fills its frontier from the texels filled before it, summing the
 * neighbours in the order dy = -1..1, dx = -1..1 in float as the definition
 * reads, claims the empty neighbours for pass k + 1 when `more`, and marks
 * the previous frontier GROWN. False when out of memory (the frontier is
 * then partly filled: see undo). */
static bool pass(dilation *d, int k, bool more)
{
    int w = d->width, h = d->height, ch = d->channels;
    uint8_t prev = LABEL(k + 2), next = LABEL(k + 1);
    size_t chunks = (d->cur_count + CHUNK - 1) / CHUNK;
#pragma omp parallel num_threads(d->threads) if (d->cur_count + d->prev_count >= PARALLEL_FRONT)
    {
        /* a copy on this thread's stack: the shared array would bounce
         * between the cores' caches at every append */
        thread_out mine = d->out[omp_get_thread_num()], *t = &mine;
#pragma omp for schedule(dynamic) nowait
        for (size_t c = 0; c < chunks; c++) {
            size_t end = (c + 1) * CHUNK < d->cur_count ? (c + 1) * CHUNK : d->cur_count;
            for (size_t i = c * CHUNK; i < end; i++) {
                uint32_t p = d->cur[i];
                int px = (int)(p % (uint32_t)w), py = (int)(p / (uint32_t)w);
                float *v = &d->data[(size_t)p * ch];
                if (!keep(t, p, v, ch)) {
                    set(&d->state[p], SKIPPED);
                    atomic_store(&d->nomem, true);
                    continue;
                }
                float sum[4] = {0, 0, 0, 0};
                int n = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int nx = px + dx, ny = py + dy;
                        if (nx < 0 || ny < 0 || nx >= w || ny >= h)
                            continue;
                        size_t q = (size_t)ny * w + nx;
                        uint8_t s = get(&d->state[q]);
                        if (s != GIVEN && s != GROWN && s != prev)
                            continue;
                        for (int c2 = 0; c2 < ch; c2++)
                            sum[c2] += d->data[q * ch + c2];
                        n++;
                    }
                /* n >= 1: a frontier texel has a neighbour filled before */
                for (int c2 = 0; c2 < ch; c2++)
                    v[c2] = sum[c2] / (float)n;
                if (!more)
                    continue;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int nx = px + dx, ny = py + dy;
                        if (nx < 0 || ny < 0 || nx >= w || ny >= h)
                            continue;
                        size_t q = (size_t)ny * w + nx;
                        uint8_t empty = EMPTY;
                        if (get(&d->state[q]) == EMPTY &&
                            atomic_compare_exchange_strong_explicit(&d->state[q], &empty, next,
                                                                    memory_order_relaxed,
                                                                    memory_order_relaxed) &&
                            !push(t, (uint32_t)q))
                            atomic_store(&d->nomem, true);
                    }
            }
        }
        /* readable before and after: other threads may be reading them */
#pragma omp for schedule(static)
        for (size_t i = 0; i < d->prev_count; i++)
            set(&d->state[d->prev[i]], GROWN);
        d->out[omp_get_thread_num()] = mine;
    }
    return !atomic_load(&d->nomem) && gather(d);
}

/* True for a texel some pass filled, once pass `last` has run. */
static inline bool filled_here(uint8_t s, int last)
{
    return s == GROWN || s == LABEL(last);
}

/* Puts back every texel passes 0..last wrote. */
static void undo(dilation *d, int last)
{
    int w = d->width, h = d->height, ch = d->channels;
#pragma omp parallel for schedule(static)                                                          \
    num_threads(d->threads) if ((size_t)w * (size_t)h >= PARALLEL_SCAN)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            if (filled_here(get(&d->state[p]), last))
                memset(&d->data[p * ch], 0, sizeof(float) * (size_t)ch);
        }
    for (int t = 0; t < d->threads; t++)
        for (size_t i = 0; i < d->out[t].saved_count; i++)
            memcpy(&d->data[(size_t)d->out[t].saved_at[i] * ch], &d->out[t].saved[i * ch],
                   sizeof(float) * (size_t)ch);
}

lx_status lx_dilate(float *data, uint8_t *mask, int width, int height, int channels, int passes,
                    const lx_dilate_desc *in)
{
    lx_dilate_desc desc = lx_dilate_desc_defaults(in);
    if (!data || !mask)
        return lx_fail(LX_ERR_INVALID, "dilate: %s is NULL", data ? "mask" : "data");
    if (width < 1 || height < 1)
        return lx_fail(LX_ERR_INVALID, "dilate: size %d x %d is not positive", width, height);
    if ((uint64_t)width * (uint64_t)height > UINT32_MAX)
        return lx_fail(LX_ERR_INVALID, "dilate: size %d x %d is over %u texels", width, height,
                       UINT32_MAX);
    if (channels < 1 || channels > 4)
        return lx_fail(LX_ERR_INVALID, "dilate: %d channels is outside 1..4", channels);
    if (passes < 0)
        return lx_fail(LX_ERR_INVALID, "dilate: %d passes is negative", passes);
    if (desc.threads < 0 || desc.threads > 1024)
        return lx_fail(LX_ERR_INVALID, "dilate: thread count %d is outside 0..1024", desc.threads);
    if (passes == 0)
        return LX_OK;

    size_t pixels = (size_t)width * (size_t)height;
    dilation d = {.data = data,
                  .width = width,
                  .height = height,
                  .channels = channels,
                  .threads = lx_thread_count(desc.threads)};
    lx_status st = LX_OK;
    d.state = malloc(pixels * sizeof(state_t));
    d.out = calloc((size_t)d.threads, sizeof(thread_out));
    if (!d.state || !d.out || !first_front(&d, mask)) {
        st = lx_fail(LX_ERR_NOMEM, "dilate: out of memory for the frontier of a %d x %d image",
                     width, height);
        goto done;
    }
    /* nothing to grow (no texel filled, or none empty): one report, the last */
    if (d.cur_count == 0 && desc.progress && !desc.progress(desc.progress_user, 1.0f))
        st = lx_fail(LX_ERR_CANCELLED, "dilation cancelled");
    int last = -1;
    for (int k = 0; st == LX_OK && k < passes && d.cur_count > 0; k++) {
        last = k;
        if (!pass(&d, k, k + 1 < passes)) {
            st = lx_fail(LX_ERR_NOMEM, "dilate: out of memory in pass %d of %d (%dx%d texels)",
                         k + 1, passes, width, height);
            break;
        }
        /* the last report is 1 also when the charts stop growing early */
        float f = d.cur_count > 0 ? (float)(k + 1) / (float)passes : 1.0f;
        if (desc.progress && !desc.progress(desc.progress_user, f))
            st = lx_fail(LX_ERR_CANCELLED, "dilation cancelled");
    }
    if (last < 0)
        goto done;
    if (st != LX_OK) {
        undo(&d, last);
        goto done;
    }
#pragma omp parallel for schedule(static) num_threads(d.threads) if (pixels >= PARALLEL_SCAN)
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            size_t p = (size_t)y * width + x;
            if (filled_here(get(&d.state[p]), last))
                mask[p] = 1;
        }
done:
    if (d.out)
        for (int t = 0; t < d.threads; t++) {
            free(d.out[t].front);
            free(d.out[t].saved_at);
            free(d.out[t].saved);
        }
    free(d.out);
    free(d.state);
    free(d.prev);
    free(d.cur);
    free(d.spare);
    return st;
}
