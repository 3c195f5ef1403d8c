/* How much memory a request may take, and the up-front memory check
 * (declared in internal.h). The bound is the smallest of the machine's
 * physical memory, the memory limit of the process's control group
 * (cgroup v2 memory.max, v1 memory.limit_in_bytes, in its own group and
 * every group above it, as the kernel enforces them), and the
 * address-space and data-size limits (RLIMIT_AS, RLIMIT_DATA) less what
 * the process already has of them (/proc/self/statm). The control
 * groups are found as the kernel documents them: the process's group in
 * /proc/self/cgroup, the hierarchy's mount in /proc/self/mountinfo. */
#define _POSIX_C_SOURCE 200809L
#include "internal.h"

#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

uint64_t lx_physical_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES);
    long page_size = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page_size <= 0)
        return 0;
    return (uint64_t)pages * (uint64_t)page_size;
}

void lx_format_bytes(uint64_t bytes, char *buf, size_t size)
{
    const double gib = 1024.0 * 1024.0 * 1024.0;
    if (bytes >= (uint64_t)gib / 4)
        snprintf(buf, size, "%.1f GiB", (double)bytes / gib);
    else
        snprintf(buf, size, "%.1f MiB", (double)bytes / (1024.0 * 1024.0));
}

/* ---- control groups -------------------------------------------------------- */

/* The limit in a memory.max or memory.limit_in_bytes file: UINT64_MAX
 * for "max", a missing or unreadable file, or anything else that is not
 * a number. (cgroup v1 writes "no limit" as a number near 2^63, which
 * the machine's memory is below anyway.) */
static uint64_t read_limit_file(const char *path)
{
    FILE *fp = fopen(path, "r");
    if (!fp)
        return UINT64_MAX;
    char text[64] = "";
    bool got = fgets(text, sizeof text, fp) != NULL;
    fclose(fp);
    if (!got || text[0] < '0' || text[0] > '9')
        return UINT64_MAX;
    errno = 0;
    char *end;
    unsigned long long v = strtoull(text, &end, 10);
    if (errno || (*end && *end != '\n'))
        return UINT64_MAX;
    return (uint64_t)v;
}

/* Undoes mountinfo's octal escapes (\040 for a space) in place. */
static void unescape(char *s)
{
    char *d = s;
    for (; *s; s++) {
        if (s[0] == '\\' && s[1] >= '0' && s[1] <= '3' && s[2] >= '0' && s[2] <= '7' &&
            s[3] >= '0' && s[3] <= '7') {
            *d++ = (char)((s[1] - '0') * 64 + (s[2] - '0') * 8 + (s[3] - '0'));
            s += 3;
        } else {
            *d++ = *s;
        }
    }
    *d = '\0';
}

/* Whether the comma-separated list has the word. */
static bool list_has(const char *list, const char *word)
{
    size_t n = strlen(word);
    for (const char *p = list; p && *p;) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == n && strncmp(p, word, n) == 0)
            return true;
        p = comma ? comma + 1 : NULL;
    }
    return false;
}

/* The mount of the memory hierarchy (v2: the cgroup2 file system; v1: a
 * cgroup file system with the memory controller): its mount point and
 * the group it shows at that point, from mountinfo. */
static bool find_mount(const char *mountinfo, bool v2, char *point, char *root, size_t size)
{
    FILE *fp = fopen(mountinfo, "r");
    if (!fp)
        return false;
    char line[4096];
    bool found = false;
    while (!found && fgets(line, sizeof line, fp)) {
        /* id parent major:minor root point options [optional...] - type source super */
        char *field[6] = {0};
        char *save = NULL, *tok = strtok_r(line, " \n", &save);
        int k = 0;
        for (; tok && k < 6; tok = strtok_r(NULL, " \n", &save))
            field[k++] = tok;
        while (tok && strcmp(tok, "-") != 0)
            tok = strtok_r(NULL, " \n", &save);
        char *type = tok ? strtok_r(NULL, " \n", &save) : NULL;
        char *source = type ? strtok_r(NULL, " \n", &save) : NULL;
        char *super = source ? strtok_r(NULL, " \n", &save) : NULL;
        if (k < 5 || !type)
            continue;
        if (v2 ? strcmp(type, "cgroup2") != 0
               : strcmp(type, "cgroup") != 0 || !super || !list_has(super, "memory"))
            continue;
        if (strlen(field[3]) >= size || strlen(field[4]) >= size)
            continue;
        snprintf(root, size, "%s", field[3]);
        snprintf(point, size, "%s", field[4]);
        unescape(root);
        unescape(point);
        found = true;
    }
    fclose(fp);
    return found;
}

/* The smallest limit on the way from the process's group up to the
 * hierarchy's top, as far as the mount shows it; UINT64_MAX when none. */
static uint64_t hierarchy_limit(const char *mountinfo, bool v2, const char *group)
{
    char point[1024], root[1024];
    if (!find_mount(mountinfo, v2, point, root, sizeof point))
        return UINT64_MAX;
    /* the group relative to what the mount shows (a container sees its
     * own group at the mount point) */
    size_t rn = strcmp(root, "/") == 0 ? 0 : strlen(root);
    if (strncmp(group, root, rn) != 0 || (group[rn] != '/' && group[rn] != '\0'))
        return UINT64_MAX;
    char dir[2048];
    int n = snprintf(dir, sizeof dir, "%s%s", point, group + rn);
    if (n < 0 || (size_t)n >= sizeof dir)
        return UINT64_MAX;
    size_t top = strlen(point);
    while (n > 1 && dir[n - 1] == '/' && (size_t)n > top)
        dir[--n] = '\0';
    const char *file = v2 ? "memory.max" : "memory.limit_in_bytes";
    uint64_t limit = UINT64_MAX;
    for (;;) {
        char path[2100];
        snprintf(path, sizeof path, "%s/%s", dir, file);
        uint64_t v = read_limit_file(path);
        limit = v < limit ? v : limit;
        /* up to the mount point: v2 has no memory.max there, v1 its
         * unlimited one */
        char *slash = strlen(dir) > top ? strrchr(dir, '/') : NULL;
        if (!slash || (size_t)(slash - dir) < top)
            break;
        *slash = '\0';
    }
    return limit;
}

uint64_t lx_cgroup_memory_limit(const char *cgroup_file, const char *mountinfo_file)
{
    FILE *fp = fopen(cgroup_file, "r");
    if (!fp)
        return UINT64_MAX;
    uint64_t limit = UINT64_MAX;
    char line[4096];
    while (fgets(line, sizeof line, fp)) {
        /* hierarchy-id:controllers:path; v2 is "0::path" */
        line[strcspn(line, "\n")] = '\0';
        char *c1 = strchr(line, ':');
        char *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
        if (!c2 || c2[1] != '/')
            continue;
        *c1 = '\0';
        *c2 = '\0';
        bool v2 = strcmp(line, "0") == 0 && c1[1] == '\0';
        if (!v2 && !list_has(c1 + 1, "memory"))
            continue;
        uint64_t v = hierarchy_limit(mountinfo_file, v2, c2 + 1);
        limit = v < limit ? v : limit;
    }
    fclose(fp);
    return limit;
}

/* ---- the bound ------------------------------------------------------------- */

/* Address space and data of the process in bytes (/proc/self/statm's
 * size and data fields); false when unknown. */
static bool process_usage(uint64_t *vm, uint64_t *data)
{
    FILE *fp = fopen("/proc/self/statm", "r");
    if (!fp)
        return false;
    unsigned long long size, resident, shared, text, lib, d;
    int n = fscanf(fp, "%llu %llu %llu %llu %llu %llu", &size, &resident, &shared, &text, &lib, &d);
    fclose(fp);
    long page = sysconf(_SC_PAGESIZE);
    if (n != 6 || page <= 0)
        return false;
    *vm = (uint64_t)size * (uint64_t)page;
    *data = (uint64_t)d * (uint64_t)page;
    return true;
}

/* Takes a candidate bound when it leaves less than the current one. */
static void consider(lx_memory_limit *m, lx_memory_bound bound, uint64_t limit, uint64_t used)
{
    uint64_t available = limit > used ? limit - used : 0;
    if (available < m->available) {
        m->available = available;
        m->limit = limit;
        m->used = used;
        m->bound = bound;
    }
}

uint64_t lx_memory_available(lx_memory_limit *out)
{
    lx_memory_limit m = {.available = UINT64_MAX, .bound = LX_MEMORY_UNKNOWN};
    uint64_t physical = lx_physical_memory();
    if (physical)
        consider(&m, LX_MEMORY_PHYSICAL, physical, 0);
    uint64_t group = lx_cgroup_memory_limit("/proc/self/cgroup", "/proc/self/mountinfo");
    if (group != UINT64_MAX)
        consider(&m, LX_MEMORY_CGROUP, group, 0);
    struct rlimit as, data;
    bool as_set = getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY;
    bool data_set = getrlimit(RLIMIT_DATA, &data) == 0 && data.rlim_cur != RLIM_INFINITY;
    uint64_t vm = 0, used_data = 0;
    if ((as_set || data_set) && process_usage(&vm, &used_data)) {
        if (as_set)
            consider(&m, LX_MEMORY_ADDRESS_SPACE, (uint64_t)as.rlim_cur, vm);
        if (data_set)
            consider(&m, LX_MEMORY_DATA, (uint64_t)data.rlim_cur, used_data);
    }
    if (out)
        *out = m;
    return m.available;
}

void lx_memory_limit_describe(const lx_memory_limit *m, char *buf, size_t size)
{
    char limit[32], used[32];
    lx_format_bytes(m->limit, limit, sizeof limit);
    lx_format_bytes(m->used, used, sizeof used);
    switch (m->bound) {
    case LX_MEMORY_PHYSICAL:
        snprintf(buf, size, "the machine has %s", limit);
        break;
    case LX_MEMORY_CGROUP:
        snprintf(buf, size, "the memory limit of the process's control group is %s", limit);
        break;
    case LX_MEMORY_ADDRESS_SPACE:
        snprintf(buf, size, "the address-space limit (RLIMIT_AS, ulimit -v) is %s, %s of it in use",
                 limit, used);
        break;
    case LX_MEMORY_DATA:
        snprintf(buf, size, "the data-size limit (RLIMIT_DATA, ulimit -d) is %s, %s of it in use",
                 limit, used);
        break;
    default:
        snprintf(buf, size, "the memory is unknown");
        break;
    }
}

lx_status lx_memory_check(uint64_t bytes, const char *what)
{
    return lx_check_memory(bytes, what ? what : "the request");
}

lx_status lx_check_memory(uint64_t bytes, const char *what)
{
    lx_memory_limit m;
    if (bytes <= lx_memory_available(&m))
        return LX_OK;
    char need[32], bound[160];
    lx_format_bytes(bytes, need, sizeof need);
    lx_memory_limit_describe(&m, bound, sizeof bound);
    return lx_fail(LX_ERR_NOMEM, "%s needs %s of memory, %s", what, need, bound);
}
