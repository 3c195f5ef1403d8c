/* lx_unwrap_scene: charts for every mesh of every node to unwrap (one
 * mesh under one linear map is unwrapped once, its instances share the
 * charts), flattened and cut again until each flattening is valid, then
 * packed by node into pages at the texel density; vertices are split
 * where chart borders run. */
#include "unwrap_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_RESOLUTION 1024
#define DEFAULT_ATLAS_SIZE 4096
#define DEFAULT_MAX_ANGLE 60.0f
#define DEFAULT_MAX_STRETCH 1.15f
#define MIN_KEPT_SIDE 4
#define DENSITY_TRIES 24

lx_unwrap_desc lx_unwrap_desc_defaults(const lx_unwrap_desc *desc)
{
    lx_unwrap_desc d = desc ? *desc : (lx_unwrap_desc){0};
    if (d.resolution == 0)
        d.resolution = DEFAULT_RESOLUTION;
    if (d.atlas_size == 0)
        d.atlas_size = DEFAULT_ATLAS_SIZE;
    if (d.max_chart_angle == 0.0f)
        d.max_chart_angle = DEFAULT_MAX_ANGLE;
    if (d.max_stretch == 0.0f)
        d.max_stretch = DEFAULT_MAX_STRETCH;
    return d;
}

/* One mesh under one linear map: charted and flattened once for every node
 * that places it so. */
typedef struct job {
    uint32_t mesh;
    double linear[9];
    uw_mesh m;
    uw_chart *charts; /* final, flattened */
    uint32_t chart_count;
    uint32_t *tri_chart; /* per triangle: its chart, UW_NONE when degenerate */
    uint32_t *tri_slot;  /* per triangle: its place in the chart's list */
    uint32_t recut;
    double *texel_uv; /* per chart: uv scaled to texels (one block) */
    size_t *texel_at; /* per chart: offset into texel_uv */
} job;

static void job_free(job *j)
{
    for (uint32_t c = 0; c < j->chart_count; c++)
        uw_chart_free(&j->charts[c]);
    free(j->charts);
    free(j->tri_chart);
    free(j->tri_slot);
    free(j->texel_uv);
    free(j->texel_at);
    uw_mesh_free(&j->m);
}

/* A node's linear part, row-major. */
static void linear_part(const lx_mat4 *w, double out[9])
{
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            out[3 * r + c] = w->m[4 * c + r]; /* column-major */
}

static bool report(const lx_unwrap_desc *d, float f)
{
    return !d->progress || d->progress(d->progress_user, f);
}

/* Flattens chart c, cutting it until every piece flattens; the pieces are
 * appended to *out (depth first, so the order does not depend on
 * threads). */
typedef struct piece_list {
    uw_chart *items;
    uint32_t count, capacity;
    uint32_t recut;
} piece_list;

static bool list_push(piece_list *l, const uw_chart *c)
{
    if (l->count == l->capacity) {
        uint32_t cap = l->capacity ? 2 * l->capacity : 4;
        uw_chart *p = realloc(l->items, sizeof *p * cap);
        if (!p)
            return false;
        l->items = p;
        l->capacity = cap;
    }
    l->items[l->count++] = *c;
    return true;
}

static lx_status flatten_and_cut(const uw_mesh *m, uw_chart *chart, double max_stretch,
                                 piece_list *out)
{
    piece_list stack = {0};
    lx_status st = LX_OK;
    if (!list_push(&stack, chart))
        return lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
    memset(chart, 0, sizeof *chart); /* owned by the stack now */
    while (stack.count > 0 && st == LX_OK) {
        uw_chart c = stack.items[--stack.count];
        if (uw_flatten(m, &c, max_stretch, &st) || c.triangle_count == 1) {
            if (st == LX_OK && !c.uv) /* a lone triangle always flattens */
                st = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
            if (st == LX_OK && !list_push(out, &c))
                st = lx_fail(LX_ERR_NOMEM, "out of memory flattening charts");
            if (st != LX_OK)
                uw_chart_free(&c);
            continue;
        }
        if (st != LX_OK) {
            uw_chart_free(&c);
            break;
        }
        uw_chart a, b;
        bool split = uw_split_chart(m, &c, &a, &b);
        uw_chart_free(&c);
        if (!split) {
            st = lx_fail(LX_ERR_NOMEM, "out of memory cutting charts");
            break;
        }
        out->recut++;
        if (!list_push(&stack, &b) || !list_push(&stack, &a)) {
            uw_chart_free(&a);
            uw_chart_free(&b);
            st = lx_fail(LX_ERR_NOMEM, "out of memory cutting charts");
        }
    }
    for (uint32_t i = 0; i < stack.count; i++)
        uw_chart_free(&stack.items[i]);
    free(stack.items);
    return st;
}

typedef struct work {
    job *jobs;
    uint32_t job_count;
    uint32_t *node_job_first; /* per node: its first job ref in refs */
    uint32_t *refs;           /* per (node, mesh slot): job index */
} work;

/* Charts the jobs, in parallel over jobs, then flattens every chart, in
 * parallel over charts. */
static lx_status chart_jobs(job *jobs, uint32_t job_count, const lx_scene *scene,
                            const lx_unwrap_desc *d, int threads)
{
    double max_cos = cos((double)d->max_chart_angle * LX_PI / 180.0);
    lx_status *status = calloc(job_count ? job_count : 1, sizeof(lx_status));
    char(*message)[256] = calloc(job_count ? job_count : 1, 256);
    uw_chart **initial = calloc(job_count ? job_count : 1, sizeof(uw_chart *));
    uint32_t *initial_count = calloc(job_count ? job_count : 1, sizeof(uint32_t));
    if (!status || !message || !initial || !initial_count) {
        free(status);
        free(message);
        free(initial);
        free(initial_count);
        return lx_fail(LX_ERR_NOMEM, "out of memory unwrapping");
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (uint32_t j = 0; j < job_count; j++) {
        lx_status st = uw_mesh_build(&scene->meshes[jobs[j].mesh], jobs[j].linear, &jobs[j].m);
        if (st == LX_OK)
            st = uw_grow_charts(&jobs[j].m, max_cos, &initial[j], &initial_count[j]);
        status[j] = st;
        if (st != LX_OK)
            snprintf(message[j], sizeof message[j], "%s", lx_last_error());
    }
    lx_status st = LX_OK;
    for (uint32_t j = 0; j < job_count && st == LX_OK; j++)
        if (status[j] != LX_OK)
            st = lx_fail(status[j], "%s", message[j]);
    /* every initial chart is one task */
    uint32_t tasks = 0;
    for (uint32_t j = 0; j < job_count; j++)
        tasks += initial_count[j];
    piece_list *pieces = calloc(tasks ? tasks : 1, sizeof *pieces);
    uint32_t *task_job = malloc(sizeof(uint32_t) * (tasks ? tasks : 1));
    uw_chart **task_chart = malloc(sizeof(uw_chart *) * (tasks ? tasks : 1));
    lx_status *task_status = calloc(tasks ? tasks : 1, sizeof(lx_status));
    if (st == LX_OK && (!pieces || !task_job || !task_chart || !task_status))
        st = lx_fail(LX_ERR_NOMEM, "out of memory unwrapping");
    if (st == LX_OK) {
        uint32_t t = 0;
        for (uint32_t j = 0; j < job_count; j++)
            for (uint32_t c = 0; c < initial_count[j]; c++) {
                task_job[t] = j;
                task_chart[t] = &initial[j][c];
                t++;
            }
        _Atomic uint32_t done = 0;
        _Atomic int stop = 0;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads)
        for (uint32_t i = 0; i < tasks; i++) {
            if (stop)
                continue;
            task_status[i] =
                flatten_and_cut(&jobs[task_job[i]].m, task_chart[i], d->max_stretch, &pieces[i]);
            uint32_t n = ++done;
            if (d->progress && (n & 255) == 0 && omp_get_thread_num() == 0 &&
                !report(d, 0.1f + 0.5f * (float)n / (float)tasks))
                stop = 1;
        }
        for (uint32_t i = 0; i < tasks && st == LX_OK; i++)
            if (task_status[i] != LX_OK)
                st = task_status[i] == LX_ERR_NOMEM
                         ? lx_fail(LX_ERR_NOMEM, "out of memory flattening charts")
                         : task_status[i];
        if (st == LX_OK && stop)
            st = lx_fail(LX_ERR_CANCELLED, "cancelled");
    }
    /* gather each job's pieces in task order */
    if (st == LX_OK) {
        uint32_t t = 0;
        for (uint32_t j = 0; j < job_count && st == LX_OK; j++) {
            job *jb = &jobs[j];
            uint32_t total = 0;
            for (uint32_t c = 0; c < initial_count[j]; c++)
                total += pieces[t + c].count;
            jb->charts = calloc(total ? total : 1, sizeof(uw_chart));
            jb->tri_chart =
                malloc(sizeof(uint32_t) * (jb->m.triangle_count ? jb->m.triangle_count : 1));
            jb->tri_slot =
                malloc(sizeof(uint32_t) * (jb->m.triangle_count ? jb->m.triangle_count : 1));
            if (!jb->charts || !jb->tri_chart || !jb->tri_slot) {
                st = lx_fail(LX_ERR_NOMEM, "out of memory unwrapping");
                break;
            }
            memset(jb->tri_chart, 0xff, sizeof(uint32_t) * jb->m.triangle_count);
            for (uint32_t c = 0; c < initial_count[j]; c++, t++) {
                for (uint32_t k = 0; k < pieces[t].count; k++)
                    jb->charts[jb->chart_count++] = pieces[t].items[k];
                jb->recut += pieces[t].recut;
                pieces[t].count = 0;
            }
            for (uint32_t c = 0; c < jb->chart_count; c++)
                for (uint32_t k = 0; k < jb->charts[c].triangle_count; k++) {
                    jb->tri_chart[jb->charts[c].triangles[k]] = c;
                    jb->tri_slot[jb->charts[c].triangles[k]] = k;
                }
        }
    }
    if (pieces)
        for (uint32_t i = 0; i < tasks; i++) {
            for (uint32_t k = 0; k < pieces[i].count; k++)
                uw_chart_free(&pieces[i].items[k]);
            free(pieces[i].items);
        }
    for (uint32_t j = 0; j < job_count; j++) {
        for (uint32_t c = 0; c < initial_count[j]; c++)
            uw_chart_free(&initial[j][c]);
        free(initial[j]);
    }
    free(pieces);
    free(task_job);
    free(task_chart);
    free(task_status);
    free(initial);
    free(initial_count);
    free(status);
    free(message);
    return st;
}

/* ---- kept nodes ---------------------------------------------------------- */

/* World and UV areas of node n's meshes in uv set `set`; false when a mesh
 * lacks the set. */
static bool kept_areas(const lx_scene *scene, uint32_t n, int set, double *world, double *uv)
{
    const lx_node *node = &scene->nodes[n];
    *world = *uv = 0.0;
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        const lx_mesh *mesh = &scene->meshes[node->meshes[k]];
        if (!mesh->uv[set])
            return false;
        for (uint32_t t = 0; t < mesh->triangle_count; t++) {
            const uint32_t *idx = &mesh->indices[3 * t];
            lx_vec3 a = lx_mat4_point(&node->world, mesh->positions[idx[0]]);
            lx_vec3 b = lx_mat4_point(&node->world, mesh->positions[idx[1]]);
            lx_vec3 c = lx_mat4_point(&node->world, mesh->positions[idx[2]]);
            *world += 0.5 * (double)lx_length(lx_cross(lx_sub(b, a), lx_sub(c, a)));
            lx_vec2 p = mesh->uv[set][idx[0]], q = mesh->uv[set][idx[1]], r = mesh->uv[set][idx[2]];
            *uv +=
                0.5 * fabs((double)(q.x - p.x) * (r.y - p.y) - (double)(r.x - p.x) * (q.y - p.y));
        }
    }
    return true;
}

/* lx_bake_uv_set's choice: luxel's own set above 1, else 1, else 0 */
int uw_auto_uv_set(const lx_scene *scene, uint32_t n)
{
    const lx_node *node = &scene->nodes[n];
    int own = lx_scene_lightmap_set(scene, n);
    bool all_own = node->mesh_count > 0 && own > 1, all1 = node->mesh_count > 0;
    for (uint32_t k = 0; k < node->mesh_count; k++) {
        all_own = all_own && scene->meshes[node->meshes[k]].uv[own];
        all1 = all1 && scene->meshes[node->meshes[k]].uv[1];
    }
    return all_own ? own : all1 ? 1 : 0;
}

static int kept_uv_set(const lx_scene *scene, uint32_t n, const lx_unwrap_desc *d)
{
    return d->keep_uv_sets ? d->keep_uv_sets[n] : uw_auto_uv_set(scene, n);
}

/* ---- the whole ----------------------------------------------------------- */

void lx_unwrap_destroy(lx_unwrap *u)
{
    if (!u)
        return;
    for (uint32_t i = 0; i < u->mesh_count; i++) {
        free(u->meshes[i].vertex_source);
        free(u->meshes[i].uv);
        free(u->meshes[i].indices);
    }
    free(u->meshes);
    free(u->nodes);
    free(u->pages);
    free(u);
}

static lx_status check_desc(const lx_scene *scene, const lx_unwrap_desc *d)
{
    if (!(d->texel_density >= 0.0f) || !isfinite(d->texel_density))
        return lx_fail(LX_ERR_INVALID, "texel density %g: must be positive (texels per metre)",
                       (double)d->texel_density);
    if (d->resolution < 4 || d->resolution > LX_UNWRAP_MAX_ATLAS_SIZE)
        return lx_fail(LX_ERR_INVALID, "resolution %d: must be 4..%d", d->resolution,
                       LX_UNWRAP_MAX_ATLAS_SIZE);
    if (d->atlas_size < 4 || d->atlas_size > LX_UNWRAP_MAX_ATLAS_SIZE)
        return lx_fail(LX_ERR_INVALID, "atlas size %d: must be 4..%d", d->atlas_size,
                       LX_UNWRAP_MAX_ATLAS_SIZE);
    if (d->padding < 0 || d->padding > LX_UNWRAP_MAX_PADDING)
        return lx_fail(LX_ERR_INVALID, "padding %d: must be 0..%d texels", d->padding,
                       LX_UNWRAP_MAX_PADDING);
    if (!(d->max_chart_angle > 0.0f && d->max_chart_angle < 90.0f))
        return lx_fail(LX_ERR_INVALID, "chart angle %g: must be between 0 and 90 degrees",
                       (double)d->max_chart_angle);
    if (!(d->max_stretch >= 1.0f) || !isfinite(d->max_stretch))
        return lx_fail(LX_ERR_INVALID, "stretch limit %g: must be at least 1",
                       (double)d->max_stretch);
    if (d->threads < 0)
        return lx_fail(LX_ERR_INVALID, "threads %d: must be 0 (all cores) or more", d->threads);
    for (uint32_t n = 0; n < scene->node_count && d->modes; n++)
        if (d->modes[n] > LX_UNWRAP_SKIP)
            return lx_fail(LX_ERR_INVALID, "node '%s': unknown unwrap mode %d",
                           scene->nodes[n].name, (int)d->modes[n]);
    return LX_OK;
}

/* Per node: what to do and, for generated nodes, its meshes' jobs. */
typedef struct plan {
    lx_unwrap_mode *mode;
    int *uv_set;         /* kept nodes */
    double *kept_world;  /* kept nodes: world area */
    double *kept_uv;     /* kept nodes: UV area */
    uint32_t *ref_first; /* node_count + 1 offsets into ref_job */
    uint32_t *ref_job;   /* per (node, mesh slot) */
    job *jobs;
    uint32_t job_count;
    double *node_scale; /* density multiplier: the node's lightmap scale, lowered
                           for a node too big for a page */
} plan;

static void plan_free(plan *p)
{
    for (uint32_t j = 0; j < p->job_count; j++)
        job_free(&p->jobs[j]);
    free(p->jobs);
    free(p->mode);
    free(p->uv_set);
    free(p->kept_world);
    free(p->kept_uv);
    free(p->ref_first);
    free(p->ref_job);
    free(p->node_scale);
}

static lx_status make_plan(const lx_scene *scene, const lx_unwrap_desc *d, plan *p)
{
    memset(p, 0, sizeof *p);
    uint32_t nn = scene->node_count, refs = 0;
    for (uint32_t n = 0; n < nn; n++)
        refs += scene->nodes[n].mesh_count;
    p->mode = malloc(sizeof(lx_unwrap_mode) * (nn ? nn : 1));
    p->uv_set = calloc(nn ? nn : 1, sizeof(int));
    p->kept_world = calloc(nn ? nn : 1, sizeof(double));
    p->kept_uv = calloc(nn ? nn : 1, sizeof(double));
    p->ref_first = calloc((size_t)nn + 1, sizeof(uint32_t));
    p->ref_job = malloc(sizeof(uint32_t) * (refs ? refs : 1));
    p->jobs = calloc(refs ? refs : 1, sizeof(job));
    p->node_scale = malloc(sizeof(double) * (nn ? nn : 1));
    if (!p->mode || !p->uv_set || !p->kept_world || !p->kept_uv || !p->ref_first || !p->ref_job ||
        !p->jobs || !p->node_scale)
        return lx_fail(LX_ERR_NOMEM, "out of memory unwrapping");
    uint32_t r = 0;
    for (uint32_t n = 0; n < nn; n++) {
        const lx_node *node = &scene->nodes[n];
        p->node_scale[n] = lx_node_lightmap_scale(&node->bake);
        p->ref_first[n] = r;
        p->mode[n] = d->modes ? d->modes[n] : LX_UNWRAP_GENERATE;
        if (node->mesh_count == 0 || node->bake.no_lightmap)
            p->mode[n] = LX_UNWRAP_SKIP;
        if (p->mode[n] == LX_UNWRAP_KEEP) {
            int set = kept_uv_set(scene, n, d);
            if (set < 0 || set >= LX_MAX_UV_SETS)
                return lx_fail(LX_ERR_INVALID, "node '%s': UV set %d does not exist", node->name,
                               set);
            p->uv_set[n] = set;
            if (!kept_areas(scene, n, set, &p->kept_world[n], &p->kept_uv[n]))
                return lx_fail(LX_ERR_INVALID, "node '%s': a mesh has no TEXCOORD_%d to keep",
                               node->name, set);
            if (!(p->kept_uv[n] > 0.0) || !(p->kept_world[n] > 0.0))
                return lx_fail(LX_ERR_INVALID, "node '%s': its TEXCOORD_%d covers no area",
                               node->name, set);
        }
        if (p->mode[n] != LX_UNWRAP_GENERATE)
            continue;
        double lin[9];
        linear_part(&node->world, lin);
        for (uint32_t k = 0; k < node->mesh_count; k++, r++) {
            uint32_t mesh = node->meshes[k], j = 0;
            while (j < p->job_count &&
                   !(p->jobs[j].mesh == mesh && memcmp(p->jobs[j].linear, lin, sizeof lin) == 0))
                j++;
            if (j == p->job_count) {
                p->jobs[j].mesh = mesh;
                memcpy(p->jobs[j].linear, lin, sizeof lin);
                p->job_count++;
            }
            p->ref_job[r] = j;
        }
    }
    p->ref_first[nn] = r;
    return LX_OK;
}

/* The items to pack at `density`: every chart of every generated node, a
 * square for every kept one. Each item owns its texel uv. */
static lx_status make_items(const lx_scene *scene, const plan *p, double density, uw_item **out,
                            uint32_t *count)
{
    *out = NULL;
    *count = 0;
    uint32_t n_items = 0;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        if (p->mode[n] == LX_UNWRAP_KEEP)
            n_items++;
        for (uint32_t r = p->ref_first[n]; r < p->ref_first[n + 1]; r++)
            n_items += p->jobs[p->ref_job[r]].chart_count;
    }
    uw_item *items = calloc(n_items ? n_items : 1, sizeof *items);
    if (!items)
        return lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
    uint32_t i = 0;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        double s = density * p->node_scale[n];
        if (p->mode[n] == LX_UNWRAP_KEEP) {
            double side = ceil(s * sqrt(p->kept_world[n] / p->kept_uv[n]));
            side = fmax(side, MIN_KEPT_SIDE);
            items[i++] = (uw_item){.node = n, .solid = true, .width = side, .height = side};
            continue;
        }
        for (uint32_t r = p->ref_first[n]; r < p->ref_first[n + 1]; r++) {
            const job *jb = &p->jobs[p->ref_job[r]];
            for (uint32_t c = 0; c < jb->chart_count; c++) {
                const uw_chart *ch = &jb->charts[c];
                double *uv = malloc(sizeof(double) * 2 * ch->vertex_count);
                if (!uv) {
                    for (uint32_t k = 0; k < i; k++)
                        free((void *)items[k].uv);
                    free(items);
                    return lx_fail(LX_ERR_NOMEM, "out of memory packing charts");
                }
                for (uint32_t v = 0; v < 2 * ch->vertex_count; v++)
                    uv[v] = ch->uv[v] * s;
                items[i++] = (uw_item){.node = n,
                                       .triangle_count = ch->triangle_count,
                                       .uv = uv,
                                       .corners = ch->corners,
                                       .width = ch->width * s,
                                       .height = ch->height * s};
            }
        }
    }
    *out = items;
    *count = i;
    return LX_OK;
}

static void items_free(uw_item *items, uint32_t count)
{
    for (uint32_t i = 0; i < count; i++)
        free((void *)items[i].uv);
    free(items);
}

/* The surface the unwrap places for node n (all nodes: UW_NONE), m^2,
 * each node's weighted by its lightmap scale squared (the texels it takes
 * at a density of 1). */
static double placed_area(const lx_scene *scene, const plan *p, uint32_t only)
{
    double area = 0.0;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        if (only != UW_NONE && n != only)
            continue;
        double s2 = p->node_scale[n] * p->node_scale[n]; /* 1 exactly by default */
        if (p->mode[n] == LX_UNWRAP_KEEP)
            area += p->kept_world[n] * s2;
        for (uint32_t r = p->ref_first[n]; r < p->ref_first[n + 1]; r++) {
            const job *jb = &p->jobs[p->ref_job[r]];
            for (uint32_t c = 0; c < jb->chart_count; c++)
                area += jb->charts[c].area * s2;
        }
    }
    return area;
}

static lx_status pack_at(const lx_scene *scene, plan *p, double density, const uw_pack_desc *pd,
                         bool may_scale, uw_item **items_out, uint32_t *item_count,
                         lx_unwrap_page **pages, uint32_t *page_count)
{
    for (int attempt = 0;; attempt++) {
        uw_item *items;
        uint32_t count;
        lx_status st = make_items(scene, p, density, &items, &count);
        if (st != LX_OK)
            return st;
        uint32_t too_big = UW_NONE;
        st = uw_pack(items, count, pd, pages, page_count, &too_big);
        if (st == LX_OK) {
            *items_out = items;
            *item_count = count;
            return LX_OK;
        }
        items_free(items, count);
        if (st != LX_ERR_UNSUPPORTED || too_big == UW_NONE || attempt > 64 || !may_scale)
            return st;
        if (p->node_scale[too_big] == (double)lx_node_lightmap_scale(&scene->nodes[too_big].bake))
            lx_log(LX_LOG_WARN,
                   "node '%s' does not fit in one %dx%d page at %g texels/m: its "
                   "density is lowered until it does",
                   scene->nodes[too_big].name, pd->atlas_size, pd->atlas_size, density);
        p->node_scale[too_big] *= 0.8;
    }
}

/* Output vertices of one generated (node, mesh): one per (file vertex,
 * chart) pair, in the order the triangles first use them. */
typedef struct vertex_key {
    uint32_t chart, id, next;
} vertex_key;

static lx_status emit_mesh(const lx_scene *scene, const plan *p, uint32_t node, uint32_t slot,
                           const uw_item *items, uint32_t first_item, const lx_unwrap_page *pages,
                           lx_unwrap_mesh *out)
{
    const job *jb = &p->jobs[p->ref_job[p->ref_first[node] + slot]];
    const lx_mesh *mesh = &scene->meshes[jb->mesh];
    memset(out, 0, sizeof *out);
    out->node = node;
    out->mesh = jb->mesh;
    uint32_t nv = mesh->vertex_count, nt = mesh->triangle_count;
    size_t ncorner = 3 * (size_t)nt;
    uint32_t *head = malloc(sizeof(uint32_t) * (nv ? nv : 1));
    vertex_key *keys = malloc(sizeof(vertex_key) * (ncorner ? ncorner : 1));
    out->vertex_source = malloc(sizeof(uint32_t) * (ncorner ? ncorner : 1));
    out->uv = malloc(sizeof(lx_vec2) * (ncorner ? ncorner : 1));
    out->indices = malloc(sizeof(uint32_t) * (ncorner ? ncorner : 1));
    if (!head || !keys || !out->vertex_source || !out->uv || !out->indices) {
        free(head);
        free(keys);
        return lx_fail(LX_ERR_NOMEM, "out of memory writing UVs");
    }
    memset(head, 0xff, sizeof(uint32_t) * nv);
    uint32_t count = 0;
    for (int pass = 0; pass < 2; pass++) /* degenerate triangles last: they reuse */
        for (uint32_t t = 0; t < nt; t++) {
            uint32_t c = jb->tri_chart[t];
            if ((pass == 0) != (c != UW_NONE))
                continue;
            for (int k = 0; k < 3; k++) {
                uint32_t v = mesh->indices[3 * t + k];
                uint32_t e = head[v];
                while (e != UW_NONE && c != UW_NONE && keys[e].chart != c)
                    e = keys[e].next;
                if (e != UW_NONE) {
                    out->indices[3 * t + k] = keys[e].id;
                    continue;
                }
                uint32_t id = count++;
                keys[id] = (vertex_key){c, id, head[v]};
                head[v] = id;
                out->vertex_source[id] = v;
                out->indices[3 * t + k] = id;
                lx_vec2 uv = lx_v2(0.0f, 0.0f);
                if (c != UW_NONE) {
                    const uw_item *it = &items[first_item + c];
                    const uw_chart *ch = &jb->charts[c];
                    uint32_t cv = ch->corners[3 * jb->tri_slot[t] + (uint32_t)k];
                    double s = it->width / (ch->width > 0.0 ? ch->width : 1.0);
                    double u = ch->uv[2 * cv] * s, w = ch->uv[2 * cv + 1] * s;
                    double pu = it->turned ? it->height - w : u;
                    double pv = it->turned ? u : w;
                    const lx_unwrap_page *pg = &pages[it->page];
                    uv = lx_v2((float)((it->x + it->dx + pu) / pg->width),
                               (float)((it->y + it->dy + pv) / pg->height));
                }
                out->uv[id] = uv;
            }
        }
    free(head);
    free(keys);
    out->vertex_count = count;
    uint32_t *vs = realloc(out->vertex_source, sizeof(uint32_t) * (count ? count : 1));
    lx_vec2 *uvs = realloc(out->uv, sizeof(lx_vec2) * (count ? count : 1));
    if (vs)
        out->vertex_source = vs;
    if (uvs)
        out->uv = uvs;
    return LX_OK;
}

lx_status lx_unwrap_scene(const lx_scene *scene, const lx_unwrap_desc *desc, lx_unwrap **out)
{
    if (!scene)
        return lx_fail_null(__func__, "scene");
    if (!out)
        return lx_fail_null(__func__, "out");
    *out = NULL;
    lx_unwrap_desc d = lx_unwrap_desc_defaults(desc);
    lx_status st = check_desc(scene, &d);
    if (st != LX_OK)
        return st;
    int threads = lx_thread_count(d.threads);
    if (!report(&d, 0.0f))
        return lx_fail(LX_ERR_CANCELLED, "cancelled");
    plan p;
    uw_item *items = NULL;
    uint32_t item_count = 0;
    lx_unwrap_page *pages = NULL;
    uint32_t page_count = 0;
    lx_unwrap *u = NULL;
    st = make_plan(scene, &d, &p);
    if (st == LX_OK)
        st = chart_jobs(p.jobs, p.job_count, scene, &d, threads);
    if (st == LX_OK && !report(&d, 0.6f))
        st = lx_fail(LX_ERR_CANCELLED, "cancelled");
    if (st != LX_OK)
        goto fail;
    uw_pack_desc pd = {d.padding,   d.atlas_size,       d.page_per_node, threads,
                       d.progress, d.progress_user, 0.6f,            0.95f};
    double density = d.texel_density;
    if (density > 0.0) {
        st = pack_at(scene, &p, density, &pd, true, &items, &item_count, &pages, &page_count);
    } else {
        /* the density that fills one page of `resolution` (with
         * page_per_node: at which the largest node fills its page): from
         * the area, then down while it takes more than a page, up while
         * it leaves much of it empty (a few packs at most) */
        pd.atlas_size = d.resolution < d.atlas_size ? d.resolution : d.atlas_size;
        double area = placed_area(scene, &p, UW_NONE);
        if (d.page_per_node) { /* the largest node fills its page */
            area = 0.0;
            for (uint32_t n = 0; n < scene->node_count; n++)
                area = fmax(area, placed_area(scene, &p, n));
        }
        density = area > 0.0 ? sqrt(0.5 * (double)pd.atlas_size * pd.atlas_size / area) : 1.0;
        double fits = 0.0, fails = INFINITY;
        for (int attempt = 0; attempt < DENSITY_TRIES; attempt++) {
            uw_item *it;
            uint32_t ic;
            lx_unwrap_page *pg;
            uint32_t pc;
            st = pack_at(scene, &p, density, &pd, false, &it, &ic, &pg, &pc);
            if (st != LX_OK && st != LX_ERR_UNSUPPORTED)
                goto fail;
            bool one = st == LX_OK && (d.page_per_node || pc <= 1);
            if (st != LX_OK)
                it = NULL, ic = 0, pg = NULL, pc = 0;
            st = LX_OK;
            int side = 0;
            for (uint32_t k = 0; k < pc; k++) {
                side = pg[k].width > side ? pg[k].width : side;
                side = pg[k].height > side ? pg[k].height : side;
            }
            if (one) {
                fits = density;
                items_free(items, item_count);
                free(pages);
                items = it, item_count = ic, pages = pg, page_count = pc;
            } else {
                fails = density;
                items_free(it, ic);
                free(pg);
            }
            if (one && side >= 0.97 * pd.atlas_size)
                break; /* close enough to full */
            if (isinf(fails))
                density *= one ? fmin(1.5, 0.99 * pd.atlas_size / fmax(side, 1.0)) : 0.5;
            else if (fits == 0.0)
                density *= 0.8;
            else
                density = sqrt(fits * fails);
            if (fits > 0.0 && fails / fits < 1.02)
                break;
        }
        density = fits;
        if (!items && st == LX_OK)
            st = lx_fail(LX_ERR_UNSUPPORTED, "the scene does not fit one %dx%d page", pd.atlas_size,
                         pd.atlas_size);
    }
    if (st != LX_OK)
        goto fail;
    u = calloc(1, sizeof *u);
    if (!u) {
        st = lx_fail(LX_ERR_NOMEM, "out of memory unwrapping");
        goto fail;
    }
    u->texel_density = (float)density;
    u->pages = pages;
    u->page_count = page_count;
    pages = NULL;
    u->node_count = scene->node_count;
    u->nodes = calloc(scene->node_count ? scene->node_count : 1, sizeof *u->nodes);
    uint32_t mesh_total = p.ref_first[scene->node_count];
    u->meshes = calloc(mesh_total ? mesh_total : 1, sizeof *u->meshes);
    if (!u->nodes || !u->meshes) {
        st = lx_fail(LX_ERR_NOMEM, "out of memory unwrapping");
        goto fail;
    }
    /* items were made node by node, mesh by mesh, chart by chart */
    uint32_t first = 0;
    for (uint32_t n = 0; n < scene->node_count; n++) {
        lx_unwrap_node *un = &u->nodes[n];
        un->mode = p.mode[n];
        un->page = UW_NONE;
        un->scale_offset[0] = un->scale_offset[1] = 1.0f;
        if (p.mode[n] == LX_UNWRAP_KEEP) {
            const uw_item *it = &items[first++];
            const lx_unwrap_page *pg = &u->pages[it->page];
            un->page = it->page;
            un->uv_set = p.uv_set[n];
            un->scale_offset[0] = (float)(it->width / pg->width);
            un->scale_offset[1] = (float)(it->height / pg->height);
            un->scale_offset[2] = (float)it->x / (float)pg->width;
            un->scale_offset[3] = (float)it->y / (float)pg->height;
            continue;
        }
        for (uint32_t r = p.ref_first[n]; r < p.ref_first[n + 1]; r++) {
            const job *jb = &p.jobs[p.ref_job[r]];
            if (jb->chart_count)
                un->page = items[first].page;
            st = emit_mesh(scene, &p, n, r - p.ref_first[n], items, first, u->pages,
                           &u->meshes[u->mesh_count++]);
            if (st != LX_OK)
                goto fail;
            first += jb->chart_count;
        }
    }
    /* statistics: charts once per unique mesh and map */
    double stretch_sum = 0.0, area_sum = 0.0;
    for (uint32_t j = 0; j < p.job_count; j++) {
        const job *jb = &p.jobs[j];
        u->stats.recut_charts += jb->recut;
        u->stats.degenerate_triangles += jb->m.degenerate_count;
        for (uint32_t c = 0; c < jb->chart_count; c++) {
            const uw_chart *ch = &jb->charts[c];
            stretch_sum += ch->stretch * ch->stretch * ch->area;
            area_sum += ch->area;
            u->stats.stretch_max = fmax(u->stats.stretch_max, ch->stretch);
        }
    }
    u->stats.stretch_mean = area_sum > 0.0 ? sqrt(stretch_sum / area_sum) : 1.0;
    double covered = 0.0, texels = 0.0;
    for (uint32_t i = 0; i < item_count; i++)
        u->stats.charts += !items[i].solid;
    for (uint32_t k = 0; k < u->page_count; k++) {
        covered += u->pages[k].covered_texels;
        texels += (double)u->pages[k].width * u->pages[k].height;
    }
    u->stats.efficiency = texels > 0.0 ? covered / texels : 0.0;
    items_free(items, item_count);
    plan_free(&p);
    if (!report(&d, 1.0f)) {
        lx_unwrap_destroy(u);
        return lx_fail(LX_ERR_CANCELLED, "cancelled");
    }
    *out = u;
    return LX_OK;
fail:
    items_free(items, item_count);
    free(pages);
    lx_unwrap_destroy(u);
    plan_free(&p);
    return st;
}

lx_status lx_unwrap_apply(lx_scene *scene, const lx_unwrap *u)
{
    if (!scene)
        return lx_fail_null(__func__, "scene");
    if (!u)
        return lx_fail_null(__func__, "unwrap");
    if (u->node_count != scene->node_count)
        return lx_fail(LX_ERR_INVALID, "%s: the unwrap places %u nodes, the scene has %u",
                       scene->path, u->node_count, scene->node_count);
    uint32_t *slot_of = calloc(scene->node_count ? scene->node_count : 1, sizeof(uint32_t));
    if (!slot_of)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory applying lightmap UVs", scene->path);
    lx_status st = LX_OK;
    for (uint32_t k = 0; k < u->mesh_count && st == LX_OK; k++) {
        const lx_unwrap_mesh *um = &u->meshes[k];
        if (um->node >= scene->node_count || um->mesh >= scene->mesh_count ||
            slot_of[um->node] >= scene->nodes[um->node].mesh_count ||
            scene->nodes[um->node].meshes[slot_of[um->node]] != um->mesh) {
            st = lx_fail(LX_ERR_INVALID, "%s: the unwrap was made for another scene", scene->path);
            break;
        }
        const lx_mesh *src = &scene->meshes[um->mesh];
        if (um->vertex_count && um->vertex_source[0] >= src->vertex_count) {
            st = lx_fail(LX_ERR_INVALID, "%s: the unwrap was made for another scene", scene->path);
            break;
        }
        /* the node's own copy: split vertices, the page's UVs in the
         * node's lightmap set, its other sets kept */
        int set = lx_scene_lightmap_set(scene, um->node);
        if (set < 0) {
            st = lx_fail(LX_ERR_UNSUPPORTED,
                         "%s: node '%s': its materials read textures through every UV set from "
                         "1 to %d: no set is left for the lightmap",
                         scene->path, scene->nodes[um->node].name, LX_MAX_UV_SETS - 1);
            break;
        }
        lx_mesh m = {.name = src->name,
                     .vertex_count = um->vertex_count,
                     .triangle_count = src->triangle_count,
                     .indices = um->indices,
                     .material = src->material};
        size_t nv = um->vertex_count ? um->vertex_count : 1;
        m.positions = malloc(sizeof(lx_vec3) * nv);
        m.normals = src->normals ? malloc(sizeof(lx_vec3) * nv) : NULL;
        m.tangents = src->tangents ? malloc(sizeof(lx_vec4) * nv) : NULL;
        bool ok = m.positions && (!src->normals || m.normals) && (!src->tangents || m.tangents);
        for (int q = 0; q < LX_MAX_UV_SETS; q++) {
            m.uv[q] = q != set && src->uv[q] ? malloc(sizeof(lx_vec2) * nv) : NULL;
            ok = ok && (q == set || !src->uv[q] || m.uv[q]);
        }
        m.uv[set] = um->uv;
        for (uint32_t v = 0; ok && v < um->vertex_count; v++) {
            uint32_t from = um->vertex_source[v];
            if (from >= src->vertex_count) {
                ok = false;
                break;
            }
            m.positions[v] = src->positions[from];
            if (m.normals)
                m.normals[v] = src->normals[from];
            if (m.tangents)
                m.tangents[v] = src->tangents[from];
            for (int q = 0; q < LX_MAX_UV_SETS; q++)
                if (q != set && m.uv[q])
                    m.uv[q][v] = src->uv[q][from];
        }
        uint32_t index = 0;
        if (!ok)
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory applying lightmap UVs", scene->path);
        else
            st = lx_scene_add_mesh(scene, &m, &index);
        free(m.positions);
        free(m.normals);
        free(m.tangents);
        for (int q = 0; q < LX_MAX_UV_SETS; q++)
            if (q != set)
                free(m.uv[q]);
        if (st == LX_OK)
            scene->nodes[um->node].meshes[slot_of[um->node]++] = index;
    }
    free(slot_of);
    return st;
}
