/* Checks made on a scene file itself before assimp reads it. assimp's
 * readers and post-processing walk the node hierarchy recursively (and its
 * Collada and FBX readers recurse over the file's own nesting), copying an
 * instanced subtree once per reference: a 410 KB glTF or Collada file of
 * 20,000 nested nodes overflowed the stack inside assimp before luxel's
 * own walk could refuse it. So each format's hierarchy is measured here,
 * without recursion (node_graph.c), and refused past NODE_DEPTH_MAX levels,
 * on a cycle, or past NODE_EXPANDED_MAX nodes once instances are copied:
 *
 * - glTF 2.0: "children" (one parent each, gltf_nodes.c); glTF 1.0: the
 *   same by node id;
 * - Collada: XML element nesting (at most XML_DEPTH_MAX), <node> nesting
 *   and <instance_node> references;
 * - FBX, binary and ASCII: record/brace nesting (at most FBX_NEST_MAX) and
 *   the Model objects' parent links from the "OO" connections.
 *
 * OBJ, PLY and STL have no hierarchy. What assimp does beyond these
 * bounds is contained by the import thread's stack (import_assimp.c),
 * sized for them. */
#define _GNU_SOURCE /* O_CLOEXEC */
#include "core/internal.h"

#include "gltf_json.h"
#include "import_checks.h"
#include "node_graph.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

/* Nodes a hierarchy may expand to with its instances copied. */
#define NODE_EXPANDED_MAX 1000000u
/* Nesting of XML elements and of FBX records or braces: well above what
 * exporters write (Collada ~12 plus the node levels, FBX ~6), well below
 * what assimp's recursive readers survive on the import thread's stack. */
#define XML_DEPTH_MAX (NODE_DEPTH_MAX + 64)
#define FBX_NEST_MAX 64

/* ---- the verdict on a measured graph ------------------------------------- */

typedef void (*node_namer)(const void *user, uint32_t node, char *buf, size_t size);

static lx_status judge_graph(const char *path, const node_graph *g, node_namer name,
                             const void *user)
{
    node_graph_shape shape;
    if (node_graph_measure(g, &shape) != LX_OK)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory measuring %zu nodes", path, g->nodes);
    char who[160];
    if (shape.cycle_at != UINT32_MAX) {
        name(user, shape.cycle_at, who, sizeof who);
        return lx_fail(LX_ERR_FORMAT, "%s: the node hierarchy has a cycle through %s", path, who);
    }
    if (shape.depth > NODE_DEPTH_MAX) {
        name(user, shape.deepest, who, sizeof who);
        return lx_fail(LX_ERR_FORMAT,
                       "%s: node hierarchy deeper than %d levels (a chain of %u nodes from %s)",
                       path, NODE_DEPTH_MAX, shape.depth, who);
    }
    if (shape.expanded > NODE_EXPANDED_MAX) {
        name(user, shape.largest, who, sizeof who);
        return lx_fail(LX_ERR_FORMAT,
                       "%s: %s expands to %s%llu nodes through its instances (at most %u)", path,
                       who, shape.expanded == NODE_GRAPH_SIZE_CAP ? "over " : "",
                       (unsigned long long)shape.expanded, NODE_EXPANDED_MAX);
    }
    return LX_OK;
}

/* ---- glTF ------------------------------------------------------------------ */

/* glTF 1.0 names its nodes by id: "nodes": {"id": {"children": ["id"]}}. */
typedef struct named_node {
    const char *id;
    uint32_t index;
} named_node;

static int by_id(const void *a, const void *b)
{
    return strcmp(((const named_node *)a)->id, ((const named_node *)b)->id);
}

/* The glTF nodes ("nodes": an array in 2.0, an object by id in 1.0) and
 * how a "children" entry names one. */
typedef struct gltf_nodes {
    const cJSON *nodes;
    size_t count;
    const named_node *ids; /* 1.0: sorted by id; NULL for 2.0 */
} gltf_nodes;

/* The node a "children" entry names, or false: entries that name no node
 * are the readers' to report. */
static bool gltf_child(const gltf_nodes *n, const cJSON *entry, uint32_t *out)
{
    size_t k;
    if (!n->ids) {
        if (!lx_gltf_index(entry, n->count, &k))
            return false;
        *out = (uint32_t)k;
        return true;
    }
    if (!cJSON_IsString(entry))
        return false;
    named_node key = {entry->valuestring, 0};
    const named_node *hit = bsearch(&key, n->ids, n->count, sizeof *n->ids, by_id);
    if (hit)
        *out = hit->index;
    return hit != NULL;
}

static void name_gltf(const void *user, uint32_t node, char *buf, size_t size)
{
    const gltf_nodes *n = user;
    const cJSON *it = n->nodes->child;
    for (uint32_t i = 0; it && i < node; i++)
        it = it->next;
    if (n->ids)
        snprintf(buf, size, "node '%.100s'", it && it->string ? it->string : "?");
    else
        lx_gltf_label(buf, size, "node", node, it);
}

/* "children", glTF 2.0 by index and 1.0 by id. (One parent each is
 * glTF's rule, checked with the transforms where lights and cameras are
 * placed; a subtree listed twice is counted twice here, as assimp copies
 * it.) */
static lx_status check_gltf(const char *path, const cJSON *gltf)
{
    gltf_nodes n = {.nodes = lx_gltf_get(gltf, "nodes")};
    bool v2 = lx_gltf_is_v2(gltf);
    if (v2 ? !cJSON_IsArray(n.nodes) : !cJSON_IsObject(n.nodes))
        return LX_OK; /* no hierarchy to walk; the readers report what is malformed */
    for (const cJSON *it = n.nodes->child; it; it = it->next)
        n.count++;
    named_node *ids = NULL;
    if (!v2) {
        if (!(ids = malloc((n.count ? n.count : 1) * sizeof *ids)))
            return lx_fail(LX_ERR_NOMEM, "%s: out of memory for %zu nodes", path, n.count);
        uint32_t i = 0;
        for (const cJSON *it = n.nodes->child; it; it = it->next, i++)
            ids[i] = (named_node){it->string ? it->string : "", i};
        qsort(ids, n.count, sizeof *ids, by_id);
        n.ids = ids;
    }
    node_graph g = {.nodes = n.count};
    lx_status st = LX_OK;
    uint32_t i = 0;
    for (const cJSON *it = n.nodes->child; it && st == LX_OK; it = it->next, i++) {
        const cJSON *children = lx_gltf_get(it, "children");
        for (const cJSON *c = cJSON_IsArray(children) ? children->child : NULL; c; c = c->next) {
            uint32_t k;
            if (gltf_child(&n, c, &k) && !node_graph_add_edge(&g, i, k)) {
                st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", path);
                break;
            }
        }
    }
    if (st == LX_OK)
        st = judge_graph(path, &g, name_gltf, &n);
    free(ids);
    node_graph_free(&g);
    return st;
}

/* ---- a file's bytes ---------------------------------------------------------- */

typedef struct mapped_file {
    const char *bytes;
    size_t size;
} mapped_file;

static lx_status map_file(const char *path, mapped_file *m)
{
    m->bytes = NULL;
    m->size = 0;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return lx_fail(LX_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat sb;
    if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
        close(fd);
        return lx_fail(LX_ERR_IO, "%s: not a regular file", path);
    }
    if (sb.st_size > 0) {
        void *p = mmap(NULL, (size_t)sb.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
        if (p == MAP_FAILED) {
            close(fd);
            return lx_fail(LX_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
        }
        m->bytes = p;
        m->size = (size_t)sb.st_size;
    }
    close(fd);
    return LX_OK;
}

static void unmap_file(mapped_file *m)
{
    if (m->bytes)
        munmap((void *)(uintptr_t)m->bytes, m->size);
}

/* Ids of nodes, kept in the order met, found again by a sorted copy. */
typedef struct id_table {
    char **ids; /* by node index */
    size_t count, capacity;
    named_node *sorted;
} id_table;

static bool id_table_add(id_table *t, const char *id, size_t len)
{
    if (t->count == t->capacity) {
        size_t cap = t->capacity ? t->capacity * 2 : 64;
        char **ids = realloc(t->ids, cap * sizeof *ids);
        if (!ids)
            return false;
        t->ids = ids;
        t->capacity = cap;
    }
    char *copy = malloc(len + 1);
    if (!copy)
        return false;
    memcpy(copy, id, len);
    copy[len] = '\0';
    t->ids[t->count++] = copy;
    return true;
}

static bool id_table_sort(id_table *t)
{
    t->sorted = malloc((t->count ? t->count : 1) * sizeof *t->sorted);
    if (!t->sorted)
        return false;
    for (size_t i = 0; i < t->count; i++)
        t->sorted[i] = (named_node){t->ids[i], (uint32_t)i};
    qsort(t->sorted, t->count, sizeof *t->sorted, by_id);
    return true;
}

static const named_node *id_table_find(const id_table *t, const char *id)
{
    named_node key = {id, 0};
    return bsearch(&key, t->sorted, t->count, sizeof *t->sorted, by_id);
}

static void id_table_free(id_table *t)
{
    for (size_t i = 0; i < t->count; i++)
        free(t->ids[i]);
    free(t->ids);
    free(t->sorted);
    memset(t, 0, sizeof *t);
}

/* ---- Collada ----------------------------------------------------------------- */

/* An edge of the Collada node graph by the instanced node's id, resolved
 * once every id is known. */
typedef struct collada_scan {
    const char *path;
    id_table nodes;        /* <node id=...>, in document order */
    node_graph graph;      /* nesting edges, then the resolved instances */
    uint32_t *instance_of; /* the node holding each <instance_node> */
    char **instance_url;   /* and the id it names */
    size_t instances, instance_cap;
    id_table arrays;       /* <float_array id=...> and the other arrays */
    uint64_t *array_count; /* their count attributes, by table index */
    size_t array_cap;
    struct collada_accessor *accessors;
    size_t accessor_count, accessor_cap;
} collada_scan;

/* An <accessor>: the array it reads (its source without '#') and how
 * many of its values: offset + count x stride. assimp reads them without
 * looking at the array's length (a count="0" array read by a 3-value
 * accessor crashed it on a null pointer). */
typedef struct collada_accessor {
    char *source;
    uint64_t reads;
    size_t line;
} collada_accessor;

static void name_collada(const void *user, uint32_t node, char *buf, size_t size)
{
    const collada_scan *s = user;
    snprintf(buf, size, "node '%.100s'", s->nodes.ids[node]);
}

static size_t line_at(const char *bytes, const char *at)
{
    size_t line = 1;
    for (const char *p = bytes; p < at; p++)
        line += *p == '\n';
    return line;
}

/* The value of attribute name in the tag text [p, end), or NULL. */
static const char *xml_attribute(const char *p, const char *end, const char *name, size_t *len)
{
    size_t n = strlen(name);
    while (p < end) {
        while (p < end && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n'))
            p++;
        const char *key = p;
        while (p < end && *p != '=' && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n')
            p++;
        size_t key_len = (size_t)(p - key);
        while (p < end && *p != '=' && *p != '"' && *p != '\'')
            p++;
        if (p >= end || *p != '=')
            return NULL;
        p++;
        while (p < end && *p != '"' && *p != '\'')
            p++;
        if (p >= end)
            return NULL;
        char quote = *p++;
        const char *value = p;
        while (p < end && *p != quote)
            p++;
        if (p >= end)
            return NULL;
        if (key_len == n && memcmp(key, name, n) == 0) {
            *len = (size_t)(p - value);
            return value;
        }
        p++;
    }
    return NULL;
}

/* The end of a construct starting at p that closes with the string close. */
static const char *skip_past(const char *p, const char *end, const char *close)
{
    size_t n = strlen(close);
    for (; p + n <= end; p++)
        if (memcmp(p, close, n) == 0)
            return p + n;
    return end;
}

static bool name_is(const char *name, size_t len, const char *want)
{
    /* a namespace prefix (<c:node>) is ignored */
    const char *colon = memchr(name, ':', len);
    if (colon) {
        len -= (size_t)(colon + 1 - name);
        name = colon + 1;
    }
    return len == strlen(want) && memcmp(name, want, len) == 0;
}

/* ---- Collada data that assimp sizes its arrays by ------------------------- */

/* assimp's Collada reader reserves arrays by the file's own counts (an
 * array's count, a primitive's count times its vertices and inputs, the
 * sum of a <vcount>) before reading the numbers they count, and reads the
 * integers of a <p> until the text ends, never advancing past a character
 * it cannot read: "<p>0 1) 2</p>" grew an index array until 3 GB failed.
 * So each count is held to what the text it counts could hold (a number
 * and a separator, two bytes at least) and integer lists to the
 * characters assimp's reader steps over. */
typedef struct collada_primitive {
    bool open;              /* inside <triangles>, <polylist>, ... */
    uint64_t count;         /* its count attribute */
    uint64_t vertices;      /* indices per primitive assimp expects (0: none) */
    uint64_t inputs;        /* the largest <input> offset + 1 */
    uint64_t vcount_sum;    /* a <polylist>'s vertices, from its <vcount> */
} collada_primitive;

/* The decimal value of attribute name, UINT64_MAX past 2^63 or negative;
 * 0 when absent. */
static uint64_t xml_count(const char *p, const char *end, const char *name)
{
    size_t len = 0;
    const char *v = xml_attribute(p, end, name, &len);
    if (!v)
        return 0;
    while (len > 0 && (*v == ' ' || *v == '\t' || *v == '\r' || *v == '\n'))
        v++, len--;
    if (len > 0 && *v == '-') {
        for (size_t i = 1; i < len; i++)
            if (v[i] != '0')
                return UINT64_MAX;
        return 0;
    }
    if (len > 0 && *v == '+')
        v++, len--;
    uint64_t value = 0;
    for (size_t i = 0; i < len && v[i] >= '0' && v[i] <= '9'; i++) {
        if (value > (UINT64_MAX / 2) / 10)
            return UINT64_MAX;
        value = value * 10 + (uint64_t)(v[i] - '0');
    }
    return value;
}

/* The largest number of items text of len bytes can hold. */
static uint64_t items_in(size_t len)
{
    return (uint64_t)len / 2 + 1;
}

/* The text of an integer list from p up to its closing tag: only what
 * assimp's reader steps over (digits, signs, spaces and line ends). Returns
 * the bad character's position, or NULL; *len is the text's length and
 * *sum the sum of its numbers (saturating). */
static const char *integer_list(const char *p, const char *end, size_t *len, uint64_t *sum)
{
    const char *start = p;
    *sum = 0;
    uint64_t value = 0;
    for (; p < end && *p != '<'; p++) {
        char c = *p;
        if (c >= '0' && c <= '9') {
            value = value > UINT64_MAX / 20 ? UINT64_MAX / 2 : value * 10 + (uint64_t)(c - '0');
            continue;
        }
        if (c != ' ' && c != '\t' && c != '\r' && c != '\n' && c != '\f' && c != '+' &&
            c != '-')
            return p;
        *sum = *sum + value < *sum ? UINT64_MAX : *sum + value;
        value = 0;
    }
    *sum = *sum + value < *sum ? UINT64_MAX : *sum + value;
    *len = (size_t)(p - start);
    /* the list ends at its own closing tag, not in a comment or CDATA */
    if (p < end && (end - p < 2 || p[1] != '/'))
        return p;
    return NULL;
}

static bool is_primitive(const char *name, size_t len, uint64_t *vertices)
{
    static const struct {
        const char *name;
        uint64_t vertices;
    } kinds[] = {{"triangles", 3}, {"lines", 2},     {"polylist", 0},  {"polygons", 0},
                 {"tristrips", 0}, {"trifans", 0},   {"linestrips", 0}};
    for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++)
        if (name_is(name, len, kinds[i].name)) {
            *vertices = kinds[i].vertices;
            return true;
        }
    return false;
}

static bool name_ends_with(const char *name, size_t len, const char *tail)
{
    size_t n = strlen(tail);
    return len >= n && memcmp(name + len - n, tail, n) == 0;
}

/* The checks above for the element opened by the tag [name, tag_end),
 * its text starting at text (NULL for an empty element). */
/* items (of *cap entries of size bytes) with room for entry `count`,
 * its capacity doubled when full; NULL when out of memory (items is
 * then left as it was). */
static void *reserve_one(void *items, size_t *cap, size_t count, size_t size)
{
    if (count < *cap)
        return items;
    size_t grown = *cap ? *cap * 2 : 64;
    void *more = realloc(items, grown * size);
    if (more)
        *cap = grown;
    return more;
}

/* Keeps an array's id and count, or an accessor's reads, for
 * check_accessors. */
static lx_status collada_note_array(collada_scan *s, const char *attrs, const char *tag_end,
                                    uint64_t count)
{
    size_t len = 0;
    const char *id = xml_attribute(attrs, tag_end, "id", &len);
    if (!id)
        return LX_OK;
    uint64_t *counts =
        reserve_one(s->array_count, &s->array_cap, s->arrays.count, sizeof *s->array_count);
    if (!counts)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the arrays", s->path);
    s->array_count = counts;
    s->array_count[s->arrays.count] = count;
    if (!id_table_add(&s->arrays, id, len))
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the arrays", s->path);
    return LX_OK;
}

static lx_status collada_note_accessor(collada_scan *s, const char *attrs, const char *tag_end,
                                       uint64_t count, size_t line)
{
    size_t len = 0;
    const char *source = xml_attribute(attrs, tag_end, "source", &len);
    if (!source || len < 2 || source[0] != '#')
        return LX_OK; /* assimp finds no array: it reports that */
    uint64_t stride = xml_count(attrs, tag_end, "stride");
    uint64_t offset = xml_count(attrs, tag_end, "offset");
    stride = stride ? stride : 1;
    uint64_t reads = UINT64_MAX; /* saturating: huge is too many anyway */
    if (stride < UINT64_MAX / 2 && offset < UINT64_MAX / 2 &&
        (count == 0 || stride <= (UINT64_MAX / 2) / count))
        reads = offset + count * stride;
    collada_accessor *accessors =
        reserve_one(s->accessors, &s->accessor_cap, s->accessor_count, sizeof *s->accessors);
    if (!accessors)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the accessors", s->path);
    s->accessors = accessors;
    char *copy = malloc(len);
    if (!copy)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the accessors", s->path);
    memcpy(copy, source + 1, len - 1);
    copy[len - 1] = '\0';
    s->accessors[s->accessor_count++] = (collada_accessor){copy, reads, line};
    return LX_OK;
}

/* Every accessor reads within the array it names (an id given twice
 * counts as its smallest array). arrays must be sorted. */
static lx_status check_accessors(const collada_scan *s)
{
    const id_table *t = &s->arrays;
    /* per sorted entry: the least count of its id's run */
    uint64_t *least = malloc((t->count ? t->count : 1) * sizeof *least);
    if (!least)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the arrays", s->path);
    for (size_t i = 0, run = 0; i < t->count; i = run) {
        uint64_t m = UINT64_MAX;
        for (run = i; run < t->count && strcmp(t->sorted[run].id, t->sorted[i].id) == 0; run++)
            m = s->array_count[t->sorted[run].index] < m ? s->array_count[t->sorted[run].index] : m;
        for (size_t k = i; k < run; k++)
            least[k] = m;
    }
    lx_status st = LX_OK;
    for (size_t i = 0; i < s->accessor_count && st == LX_OK; i++) {
        const collada_accessor *a = &s->accessors[i];
        const named_node *hit = id_table_find(t, a->source);
        if (!hit)
            continue; /* no such array: assimp reports it */
        uint64_t have = least[hit - t->sorted];
        if (a->reads <= have)
            continue;
        char reads[32] = "more than 2^63";
        if (a->reads != UINT64_MAX)
            snprintf(reads, sizeof reads, "%llu", (unsigned long long)a->reads);
        st = lx_fail(LX_ERR_FORMAT,
                     "%s: line %zu: <accessor> reads %s values of array '%.100s', which holds %llu",
                     s->path, a->line, reads, a->source, (unsigned long long)have);
    }
    free(least);
    return st;
}

static lx_status collada_check_data(collada_scan *s, const mapped_file *f,
                                    collada_primitive *prim, const char *tag, const char *name,
                                    size_t name_len, const char *attrs, const char *tag_end,
                                    const char *text)
{
    const char *end = f->bytes + f->size;
    uint64_t count = xml_count(attrs, tag_end, "count");
    uint64_t vertices = 0;
    if (count > (uint64_t)f->size)
        return lx_fail(LX_ERR_FORMAT, "%s: line %zu: <%.*s> count %s beyond what the file holds",
                       s->path, line_at(f->bytes, tag), (int)name_len, name,
                       count == UINT64_MAX ? "negative or huge" : "of more items");
    if (name_ends_with(name, name_len, "_array")) {
        const char *close = text ? memchr(text, '<', (size_t)(end - text)) : NULL;
        size_t len = text ? (size_t)((close ? close : end) - text) : 0;
        if (count > items_in(len))
            return lx_fail(LX_ERR_FORMAT,
                           "%s: line %zu: <%.*s> count %llu beyond the %zu bytes of its text",
                           s->path, line_at(f->bytes, tag), (int)name_len, name,
                           (unsigned long long)count, len);
        return collada_note_array(s, attrs, tag_end, count);
    } else if (name_is(name, name_len, "accessor")) {
        return collada_note_accessor(s, attrs, tag_end, count, line_at(f->bytes, tag));
    } else if (is_primitive(name, name_len, &vertices)) {
        *prim = (collada_primitive){.open = true, .count = count, .vertices = vertices,
                                    .inputs = 1};
    } else if (prim->open && name_is(name, name_len, "input")) {
        uint64_t offset = xml_count(attrs, tag_end, "offset");
        if (offset >= 4096)
            return lx_fail(LX_ERR_FORMAT, "%s: line %zu: <input> offset %s", s->path,
                           line_at(f->bytes, tag),
                           offset == UINT64_MAX ? "negative or huge" : "beyond 4095");
        if (offset + 1 > prim->inputs)
            prim->inputs = offset + 1;
    } else if (name_is(name, name_len, "p") || name_is(name, name_len, "h") ||
               name_is(name, name_len, "v") || name_is(name, name_len, "vcount")) {
        size_t len = 0;
        uint64_t sum = 0;
        const char *bad = text ? integer_list(text, end, &len, &sum) : NULL;
        if (bad)
            return lx_fail(LX_ERR_FORMAT, "%s: line %zu: <%.*s> holds something other than "
                                          "integers",
                           s->path, line_at(f->bytes, bad), (int)name_len, name);
        if (name_is(name, name_len, "vcount")) {
            /* each vertex it counts is an index (or a weight) in the file */
            if (sum > (uint64_t)f->size)
                return lx_fail(LX_ERR_FORMAT,
                               "%s: line %zu: <vcount> counts more vertices than the file holds",
                               s->path, line_at(f->bytes, tag));
            if (prim->open)
                prim->vcount_sum = sum;
        } else if (name_is(name, name_len, "p") && prim->open) {
            uint64_t expected = prim->vertices ? prim->count * prim->vertices : prim->vcount_sum;
            if (expected > items_in(len) / prim->inputs)
                return lx_fail(LX_ERR_FORMAT,
                               "%s: line %zu: %llu primitive vertices of %llu inputs each "
                               "beyond the %zu bytes of the <p> holding them",
                               s->path, line_at(f->bytes, tag), (unsigned long long)expected,
                               (unsigned long long)prim->inputs, len);
        }
    }
    return LX_OK;
}

static lx_status collada_scan_tags(collada_scan *s, const mapped_file *f)
{
    collada_primitive prim = {0};
    const char *p = f->bytes, *end = f->bytes + f->size;
    uint32_t innermost[XML_DEPTH_MAX]; /* the nearest enclosing <node> */
    size_t depth = 0;
    while ((p = memchr(p, '<', (size_t)(end - p))) != NULL) {
        const char *tag = p;
        p++;
        if (end - p >= 3 && memcmp(p, "!--", 3) == 0) {
            p = skip_past(p + 3, end, "-->");
            continue;
        }
        if (end - p >= 8 && memcmp(p, "![CDATA[", 8) == 0) {
            p = skip_past(p + 8, end, "]]>");
            continue;
        }
        if (p < end && (*p == '?' || *p == '!')) {
            p = skip_past(p, end, ">");
            continue;
        }
        /* the tag's end: the first '>' outside quotes */
        const char *q = p;
        char quote = 0;
        for (; q < end; q++) {
            if (quote) {
                if (*q == quote)
                    quote = 0;
            } else if (*q == '"' || *q == '\'') {
                quote = *q;
            } else if (*q == '>') {
                break;
            }
        }
        if (q >= end)
            break; /* unterminated: assimp's XML parser reports it */
        bool closing = p < end && *p == '/';
        bool empty = q > p && q[-1] == '/';
        if (closing) {
            const char *close_name = p + 1;
            size_t close_len = 0;
            while (close_name + close_len < q && close_name[close_len] != ' ' &&
                   close_name[close_len] != '\t' && close_name[close_len] != '\r' &&
                   close_name[close_len] != '\n')
                close_len++;
            uint64_t vertices;
            if (is_primitive(close_name, close_len, &vertices))
                prim.open = false;
            if (depth > 0)
                depth--;
            p = q + 1;
            continue;
        }
        const char *name = p;
        while (p < q && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n' && *p != '/')
            p++;
        size_t name_len = (size_t)(p - name);
        uint32_t parent_node = depth > 0 ? innermost[depth - 1] : UINT32_MAX;
        uint32_t this_node = UINT32_MAX;
        if (name_is(name, name_len, "node")) {
            size_t len = 0;
            const char *id = xml_attribute(p, empty ? q - 1 : q, "id", &len);
            this_node = (uint32_t)s->nodes.count;
            if (!id_table_add(&s->nodes, id ? id : "", id ? len : 0))
                return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", s->path);
            if (parent_node != UINT32_MAX &&
                !node_graph_add_edge(&s->graph, parent_node, this_node))
                return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", s->path);
        } else if (name_is(name, name_len, "instance_node") && parent_node != UINT32_MAX) {
            size_t len = 0;
            const char *url = xml_attribute(p, empty ? q - 1 : q, "url", &len);
            if (url && len > 0 && url[0] == '#') {
                if (s->instances == s->instance_cap) {
                    size_t cap = s->instance_cap ? s->instance_cap * 2 : 64;
                    uint32_t *of = realloc(s->instance_of, cap * sizeof *of);
                    if (of)
                        s->instance_of = of;
                    char **urls = of ? realloc(s->instance_url, cap * sizeof *urls) : NULL;
                    if (!urls)
                        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy",
                                       s->path);
                    s->instance_url = urls;
                    s->instance_cap = cap;
                }
                char *copy = malloc(len);
                if (!copy)
                    return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy",
                                   s->path);
                memcpy(copy, url + 1, len - 1);
                copy[len - 1] = '\0';
                s->instance_of[s->instances] = parent_node;
                s->instance_url[s->instances++] = copy;
            }
        }
        lx_status st = collada_check_data(s, f, &prim, tag, name, name_len, p,
                                          empty ? q - 1 : q, empty ? NULL : q + 1);
        if (st != LX_OK)
            return st;
        p = q + 1;
        if (empty)
            continue;
        if (depth == XML_DEPTH_MAX)
            return lx_fail(LX_ERR_FORMAT, "%s: line %zu: XML elements nested deeper than %d",
                           s->path, line_at(f->bytes, tag), XML_DEPTH_MAX);
        innermost[depth] = this_node != UINT32_MAX ? this_node : parent_node;
        depth++;
    }
    return LX_OK;
}

static lx_status check_collada(const char *path)
{
    mapped_file f;
    lx_status st = map_file(path, &f);
    if (st != LX_OK)
        return st;
    collada_scan s = {.path = path};
    st = collada_scan_tags(&s, &f);
    unmap_file(&f);
    if (st == LX_OK && !id_table_sort(&s.nodes))
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", path);
    /* instances of ids the file lacks: assimp warns and skips them */
    for (size_t i = 0; st == LX_OK && i < s.instances; i++) {
        const named_node *hit = id_table_find(&s.nodes, s.instance_url[i]);
        if (hit && !node_graph_add_edge(&s.graph, s.instance_of[i], hit->index))
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", path);
    }
    s.graph.nodes = s.nodes.count;
    if (st == LX_OK && !id_table_sort(&s.arrays))
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for the arrays", path);
    if (st == LX_OK)
        st = check_accessors(&s);
    if (st == LX_OK)
        st = judge_graph(path, &s.graph, name_collada, &s);
    for (size_t i = 0; i < s.accessor_count; i++)
        free(s.accessors[i].source);
    free(s.accessors);
    free(s.array_count);
    id_table_free(&s.arrays);
    for (size_t i = 0; i < s.instances; i++)
        free(s.instance_url[i]);
    free(s.instance_url);
    free(s.instance_of);
    id_table_free(&s.nodes);
    node_graph_free(&s.graph);
    return st;
}

/* ---- FBX ---------------------------------------------------------------------- */

/* FBX links objects by 64-bit ids: "OO" connections (child, parent)
 * between objects, 0 the scene's root. assimp's converter walks from the
 * root to the Model objects connected under it, recursively. */
typedef struct fbx_scan {
    const char *path;
    int64_t *models; /* Model object ids, sorted once read */
    size_t model_count, model_cap;
    int64_t *link; /* child, parent pairs of "OO" connections */
    size_t link_count, link_cap;
} fbx_scan;

static bool push_id(int64_t **list, size_t *count, size_t *cap, int64_t id)
{
    if (*count == *cap) {
        size_t c = *cap ? *cap * 2 : 64;
        int64_t *l = realloc(*list, c * sizeof *l);
        if (!l)
            return false;
        *list = l;
        *cap = c;
    }
    (*list)[(*count)++] = id;
    return true;
}

static int by_int64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

static void name_fbx(const void *user, uint32_t node, char *buf, size_t size)
{
    const fbx_scan *s = user;
    if (node == 0)
        snprintf(buf, size, "the root");
    else
        snprintf(buf, size, "Model %lld", (long long)s->models[node - 1]);
}

/* The graph of the Model objects (node 0 the root, model k node k+1). */
static lx_status judge_fbx(fbx_scan *s)
{
    if (s->model_count == 0)
        return LX_OK; /* no nodes (and no array to sort) */
    qsort(s->models, s->model_count, sizeof *s->models, by_int64);
    node_graph g = {.nodes = s->model_count + 1};
    lx_status st = LX_OK;
    for (size_t i = 0; i + 1 < s->link_count && st == LX_OK; i += 2) {
        int64_t child = s->link[i], parent = s->link[i + 1];
        const int64_t *c = bsearch(&child, s->models, s->model_count, sizeof child, by_int64);
        const int64_t *p =
            parent == 0 ? NULL
                        : bsearch(&parent, s->models, s->model_count, sizeof parent, by_int64);
        if (!c || (parent != 0 && !p))
            continue; /* not a link between nodes */
        uint32_t from = p ? (uint32_t)(p - s->models) + 1 : 0;
        if (!node_graph_add_edge(&g, from, (uint32_t)(c - s->models) + 1))
            st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", s->path);
    }
    if (st == LX_OK)
        st = judge_graph(s->path, &g, name_fbx, s);
    node_graph_free(&g);
    return st;
}

static uint64_t read_le(const unsigned char *p, int bytes)
{
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

/* The first n properties of a binary record that are 64-bit ids ('L') or
 * strings ('S'), in order; others are skipped. Returns how many were
 * read. */
static int fbx_binary_properties(const unsigned char *p, const unsigned char *end, int n,
                                 int64_t *ids, const char **strings, size_t *string_len)
{
    int got = 0;
    for (int k = 0; k < n && p < end; k++) {
        char type = (char)*p++;
        size_t skip = 0;
        switch (type) {
        case 'Y':
            skip = 2;
            break;
        case 'C':
            skip = 1;
            break;
        case 'I':
        case 'F':
            skip = 4;
            break;
        case 'D':
            skip = 8;
            break;
        case 'L':
            if (end - p < 8)
                return got;
            ids[k] = (int64_t)read_le(p, 8);
            skip = 8;
            got = k + 1;
            break;
        case 'S':
        case 'R':
            if (end - p < 4)
                return got;
            skip = 4 + (size_t)read_le(p, 4);
            if (type == 'S' && skip <= (size_t)(end - p)) {
                strings[k] = (const char *)p + 4;
                string_len[k] = skip - 4;
                got = k + 1;
            }
            break;
        case 'f':
        case 'd':
        case 'l':
        case 'i':
        case 'b':
            if (end - p < 12)
                return got;
            skip = 12 + (size_t)read_le(p + 8, 4);
            break;
        default:
            return got;
        }
        if (skip > (size_t)(end - p))
            return got;
        p += skip;
    }
    return got;
}

static lx_status check_fbx_binary(fbx_scan *s, const mapped_file *f)
{
    const unsigned char *base = (const unsigned char *)f->bytes;
    uint32_t version = (uint32_t)read_le(base + 23, 4);
    int wide = version >= 7500 ? 8 : 4; /* offsets and counts */
    size_t header = (size_t)wide * 3 + 1;
    size_t ends[FBX_NEST_MAX + 1];
    int top_block = 0; /* 1 Objects, 2 Connections: the top-level record we are in */
    size_t depth = 0, pos = 27;
    for (;;) {
        size_t limit = depth ? ends[depth - 1] : f->size;
        if (pos + header > limit) {
            if (depth == 0)
                break; /* the footer */
            pos = limit;
            depth--;
            continue;
        }
        const unsigned char *r = base + pos;
        uint64_t end_offset = read_le(r, wide), props = read_le(r + wide, wide);
        uint64_t props_len = read_le(r + 2 * wide, wide);
        size_t name_len = r[3 * wide];
        if (end_offset == 0) { /* the record list's terminator */
            if (depth == 0)
                break;
            pos = limit;
            depth--;
            continue;
        }
        if (end_offset <= pos || end_offset > limit || props_len > end_offset - pos ||
            header + name_len > end_offset - pos - props_len)
            return lx_fail(LX_ERR_FORMAT, "%s: FBX record at byte %zu runs past its parent",
                           s->path, pos);
        const char *name = (const char *)r + header;
        const unsigned char *prop = r + header + name_len;
        if (depth == 0)
            top_block = name_is(name, name_len, "Objects")       ? 1
                        : name_is(name, name_len, "Connections") ? 2
                                                                 : 0;
        if (depth == 1 && props > 0) {
            int64_t ids[3] = {0};
            const char *str[3] = {0};
            size_t str_len[3] = {0};
            const unsigned char *prop_end = prop + props_len;
            if (top_block == 1 && name_is(name, name_len, "Model") &&
                fbx_binary_properties(prop, prop_end, 1, ids, str, str_len) >= 1 &&
                !push_id(&s->models, &s->model_count, &s->model_cap, ids[0]))
                return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", s->path);
            if (top_block == 2 && name_is(name, name_len, "C") &&
                fbx_binary_properties(prop, prop_end, 3, ids, str, str_len) == 3 && str[0] &&
                str_len[0] == 2 && memcmp(str[0], "OO", 2) == 0 &&
                (!push_id(&s->link, &s->link_count, &s->link_cap, ids[1]) ||
                 !push_id(&s->link, &s->link_count, &s->link_cap, ids[2])))
                return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", s->path);
        }
        size_t nested = pos + header + name_len + (size_t)props_len;
        if (nested < end_offset) {
            if (depth == FBX_NEST_MAX)
                return lx_fail(LX_ERR_FORMAT, "%s: FBX records nested deeper than %d (byte %zu)",
                               s->path, FBX_NEST_MAX, pos);
            ends[depth++] = (size_t)end_offset;
            pos = nested;
        } else {
            pos = (size_t)end_offset;
        }
    }
    return judge_fbx(s);
}

/* ASCII FBX: "Key: value, value {" lines, ';' comments, quoted strings. */
static lx_status check_fbx_ascii(fbx_scan *s, const mapped_file *f)
{
    const char *p = f->bytes, *end = f->bytes + f->size;
    size_t depth = 0;
    int top_block = 0;
    char key[32] = ""; /* the last key read */
    int values = 0;    /* values read since it */
    const char *first_value = NULL;
    int64_t link[3] = {0};
    bool oo = false;
    char pending_top[32] = ""; /* the key of the block a '{' opens */
    while (p < end) {
        char c = *p;
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == ',') {
            p++;
            continue;
        }
        if (c == ';') {
            const char *nl = memchr(p, '\n', (size_t)(end - p));
            p = nl ? nl + 1 : end;
            continue;
        }
        if (c == '{') {
            if (depth == 0)
                top_block = strcmp(pending_top, "Objects") == 0       ? 1
                            : strcmp(pending_top, "Connections") == 0 ? 2
                                                                      : 0;
            if (++depth > FBX_NEST_MAX)
                return lx_fail(LX_ERR_FORMAT, "%s: line %zu: FBX blocks nested deeper than %d",
                               s->path, line_at(f->bytes, p), FBX_NEST_MAX);
            key[0] = '\0';
            p++;
            continue;
        }
        /* an unbalanced brace or an unclosed string: assimp's parser
         * throws on them and leaks what it has built (fuzz_scene) */
        if (c == '}') {
            if (depth == 0)
                return lx_fail(LX_ERR_FORMAT, "%s: line %zu: '}' closes no FBX block", s->path,
                               line_at(f->bytes, p));
            depth--;
            key[0] = '\0';
            p++;
            continue;
        }
        const char *tok = p;
        bool quoted = c == '"';
        if (quoted) {
            const char *close = memchr(p + 1, '"', (size_t)(end - p - 1));
            if (!close)
                return lx_fail(LX_ERR_FORMAT, "%s: line %zu: an FBX string is not closed",
                               s->path, line_at(f->bytes, p));
            p = close + 1;
        } else {
            while (p < end && !strchr(" \t\r\n,{};:\"", *p))
                p++;
            if (p == tok)
                p++; /* a stray ':' or the like */
        }
        size_t len = (size_t)(p - tok);
        if (!quoted && p < end && *p == ':') { /* a key */
            p++;
            snprintf(key, sizeof key, "%.*s", (int)(len < 31 ? len : 31), tok);
            if (depth == 0)
                snprintf(pending_top, sizeof pending_top, "%s", key);
            values = 0;
            first_value = NULL;
            oo = false;
            continue;
        }
        if (depth != 1 || !key[0])
            continue;
        values++;
        if (values == 1)
            first_value = tok;
        if (top_block == 1 && values == 1 && strcmp(key, "Model") == 0 && !quoted) {
            if (!push_id(&s->models, &s->model_count, &s->model_cap, strtoll(tok, NULL, 10)))
                return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", s->path);
        } else if (top_block == 2 && strcmp(key, "C") == 0) {
            if (values == 1)
                oo = quoted && len == 4 && memcmp(first_value, "\"OO\"", 4) == 0;
            else if (values <= 3 && !quoted)
                link[values - 1] = strtoll(tok, NULL, 10);
            if (values == 3 && oo &&
                (!push_id(&s->link, &s->link_count, &s->link_cap, link[1]) ||
                 !push_id(&s->link, &s->link_count, &s->link_cap, link[2])))
                return lx_fail(LX_ERR_NOMEM, "%s: out of memory for the node hierarchy", s->path);
        }
    }
    if (depth > 0)
        return lx_fail(LX_ERR_FORMAT, "%s: %zu FBX block%s not closed at the end of the file",
                       s->path, depth, depth == 1 ? "" : "s");
    return judge_fbx(s);
}

static lx_status check_fbx(const char *path)
{
    mapped_file f;
    lx_status st = map_file(path, &f);
    if (st != LX_OK)
        return st;
    fbx_scan s = {.path = path};
    static const char magic[] = "Kaydara FBX Binary  ";
    if (f.size >= 27 && memcmp(f.bytes, magic, sizeof magic - 1) == 0)
        st = check_fbx_binary(&s, &f);
    else
        st = check_fbx_ascii(&s, &f);
    unmap_file(&f);
    free(s.models);
    free(s.link);
    return st;
}

/* ---- by format --------------------------------------------------------------- */

static bool ends_with(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n >= e && strcasecmp(path + n - e, ext) == 0;
}

lx_status import_check_hierarchy(const char *path, const cJSON *gltf)
{
    if (gltf)
        return check_gltf(path, gltf);
    if (ends_with(path, ".dae"))
        return check_collada(path);
    if (ends_with(path, ".fbx"))
        return check_fbx(path);
    return LX_OK;
}
