/* The memory bound of the up-front checks (src/core/memory.c): a request
 * above the smallest of the machine's memory, the control group's limit
 * and the address-space and data-size limits fails with LX_ERR_NOMEM
 * before anything is allocated, and the message names the bound that
 * decided. The rlimits are set in forked children (they cannot be raised
 * again); the control groups are fake /proc and /sys trees in a test
 * folder, read through the same parser as the real ones. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/internal.h"
#include "helpers.h"

#define MIB (1024ull * 1024ull)
#define GIB (1024ull * MIB)

/* ---- rlimits ------------------------------------------------------------------- */

/* Address space and data of this process (/proc/self/statm), bytes. */
static void usage(uint64_t *vm, uint64_t *data)
{
    FILE *fp = fopen("/proc/self/statm", "r");
    unsigned long long f[6];
    if (!fp ||
        fscanf(fp, "%llu %llu %llu %llu %llu %llu", &f[0], &f[1], &f[2], &f[3], &f[4], &f[5]) != 6)
        _exit(90);
    fclose(fp);
    uint64_t page = (uint64_t)sysconf(_SC_PAGESIZE);
    *vm = f[0] * page;
    *data = f[5] * page;
}

/* In a child: fails (exit status `code`) unless the message has needle. */
static void child_expect(const char *needle, int code)
{
    if (!strstr(lx_last_error(), needle)) {
        fprintf(stderr, "message '%s' lacks '%s'\n", lx_last_error(), needle);
        _exit(code);
    }
}

/* With `resource` limited to 1 GiB above what the child has of it: the
 * bound is that limit; a 2 GiB check, a 4 GiB image and a 3 GiB lightmap
 * of a sort fail up front naming it; 64 MiB passes. */
static void child_limited(int resource, lx_memory_bound want, const char *phrase)
{
    uint64_t vm, data;
    usage(&vm, &data);
    uint64_t used = resource == RLIMIT_AS ? vm : data;
    struct rlimit rl = {(rlim_t)(used + GIB), (rlim_t)(used + GIB)};
    if (setrlimit(resource, &rl) != 0)
        _exit(2);
    lx_memory_limit m;
    uint64_t available = lx_memory_available(&m);
    if (m.bound != want || m.limit != used + GIB || available > GIB || available < GIB / 2)
        _exit(3);
    if (lx_check_memory(2 * GIB, "a test request") != LX_ERR_NOMEM)
        _exit(4);
    child_expect("a test request needs 2.0 GiB of memory, ", 5);
    child_expect(phrase, 6);
    child_expect("of it in use", 7);
    lx_image img;
    if (lx_image_alloc(&img, 16384, 16384, 4) != LX_ERR_NOMEM || img.data)
        _exit(8);
    child_expect("image 16384x16384 (4 channels) needs 4.0 GiB of memory", 9);
    child_expect(phrase, 10);
    if (lx_check_memory(64 * MIB, "a small request") != LX_OK)
        _exit(11);
    if (lx_image_alloc(&img, 1024, 1024, 4) != LX_OK)
        _exit(12);
    lx_image_free(&img);
    _exit(0);
}

static void run_child(int resource, lx_memory_bound want, const char *phrase)
{
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0)
        child_limited(resource, want, phrase);
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
}

static void address_space_limit(void **state)
{
    (void)state;
    run_child(RLIMIT_AS, LX_MEMORY_ADDRESS_SPACE,
              "the address-space limit (RLIMIT_AS, ulimit -v) is ");
}

static void data_size_limit(void **state)
{
    (void)state;
    run_child(RLIMIT_DATA, LX_MEMORY_DATA, "the data-size limit (RLIMIT_DATA, ulimit -d) is ");
}

/* Without limits below it, the machine's memory is the bound, as before. */
static void machine_bound(void **state)
{
    (void)state;
    lx_memory_limit m;
    uint64_t available = lx_memory_available(&m);
    assert_true(available > 0);
    assert_true(available <= lx_physical_memory());
    assert_int_equal(lx_check_memory(available + 1, "too much"), LX_ERR_NOMEM);
    char phrase[160];
    lx_memory_limit_describe(&m, phrase, sizeof phrase);
    if (!strstr(lx_last_error(), phrase))
        fail_msg("'%s' does not name the bound '%s'", lx_last_error(), phrase);
    if (m.bound == LX_MEMORY_PHYSICAL) {
        char want[64], have[32];
        lx_format_bytes(lx_physical_memory(), have, sizeof have);
        snprintf(want, sizeof want, "the machine has %s", have);
        assert_string_equal(phrase, want);
    }
}

static void descriptions(void **state)
{
    (void)state;
    char buf[160];
    lx_memory_limit m = {.limit = 8 * GIB, .used = GIB + GIB / 5, .bound = LX_MEMORY_PHYSICAL};
    lx_memory_limit_describe(&m, buf, sizeof buf);
    assert_string_equal(buf, "the machine has 8.0 GiB");
    m.bound = LX_MEMORY_CGROUP;
    lx_memory_limit_describe(&m, buf, sizeof buf);
    assert_string_equal(buf, "the memory limit of the process's control group is 8.0 GiB");
    m.bound = LX_MEMORY_ADDRESS_SPACE;
    lx_memory_limit_describe(&m, buf, sizeof buf);
    assert_string_equal(buf,
                        "the address-space limit (RLIMIT_AS, ulimit -v) is 8.0 GiB, 1.2 GiB of it "
                        "in use");
    m.bound = LX_MEMORY_DATA;
    lx_memory_limit_describe(&m, buf, sizeof buf);
    assert_string_equal(buf,
                        "the data-size limit (RLIMIT_DATA, ulimit -d) is 8.0 GiB, 1.2 GiB of it in "
                        "use");
}

/* ---- control groups ------------------------------------------------------------- */

static void put(const char *dir, const char *name, const char *text)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    /* make the folders on the way */
    for (char *p = path + strlen(dir) + 1; (p = strchr(p, '/')); p++) {
        *p = '\0';
        mkdir(path, 0777);
        *p = '/';
    }
    FILE *fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(text, fp);
    assert_int_equal(fclose(fp), 0);
}

/* The limit the fake /proc files in dir (cgroup and mountinfo, the mount
 * points under dir written in place of @) give. */
static uint64_t limit_of(const char *dir, const char *cgroup, const char *mountinfo)
{
    put(dir, "cgroup", cgroup);
    char text[2048] = "";
    for (const char *p = mountinfo; *p; p++) {
        if (*p == '@')
            strcat(text, dir);
        else
            strncat(text, p, 1);
    }
    put(dir, "mountinfo", text);
    char c[1024], m[1024];
    snprintf(c, sizeof c, "%s/cgroup", dir);
    snprintf(m, sizeof m, "%s/mountinfo", dir);
    return lx_cgroup_memory_limit(c, m);
}

static void cgroup_limits(void **state)
{
    (void)state;
    const char *base = lx_test_dir("test_memory_cgroup");
    char dir[512];

    /* v2: the smallest memory.max from the group up to the mount */
    snprintf(dir, sizeof dir, "%s/v2", base);
    mkdir(dir, 0777);
    put(dir, "cg2/user.slice/memory.max", "1073741824\n");
    put(dir, "cg2/user.slice/app/memory.max", "max\n");
    const char *v2_mounts = "22 1 0:20 / /proc rw - proc proc rw\n"
                            "30 25 0:26 / @/cg2 rw,nosuid shared:4 - cgroup2 cgroup2 rw\n";
    assert_int_equal(limit_of(dir, "0::/user.slice/app\n", v2_mounts), GIB);
    put(dir, "cg2/user.slice/app/memory.max", "536870912\n");
    assert_int_equal(limit_of(dir, "0::/user.slice/app\n", v2_mounts), GIB / 2);
    /* "max" everywhere, a missing file, text that is not a number: none */
    put(dir, "cg2/user.slice/memory.max", "max\n");
    put(dir, "cg2/user.slice/app/memory.max", "lots\n");
    assert_int_equal(limit_of(dir, "0::/user.slice/app\n", v2_mounts), UINT64_MAX);
    assert_int_equal(limit_of(dir, "0::/elsewhere\n", v2_mounts), UINT64_MAX);

    /* v1: memory.limit_in_bytes, the controller among others; the top's
     * "unlimited" is a number near 2^63 */
    snprintf(dir, sizeof dir, "%s/v1", base);
    mkdir(dir, 0777);
    put(dir, "cg1/memory.limit_in_bytes", "9223372036854771712\n");
    put(dir, "cg1/a/memory.limit_in_bytes", "2147483648\n");
    put(dir, "cg1/a/b/memory.limit_in_bytes", "9223372036854771712\n");
    const char *v1_mounts = "31 25 0:27 / @/cg1 rw,relatime - cgroup cgroup rw,cpu,memory\n"
                            "32 25 0:28 / @/cpu rw,relatime - cgroup cgroup rw,cpu\n";
    assert_int_equal(limit_of(dir, "5:cpu,memory:/a/b\n4:cpu:/x\n", v1_mounts), 2 * GIB);
    /* a group without the memory controller is no bound */
    assert_int_equal(limit_of(dir, "4:cpu:/a/b\n", v1_mounts), UINT64_MAX);

    /* both hierarchies (hybrid): the smaller */
    snprintf(dir, sizeof dir, "%s/hybrid", base);
    mkdir(dir, 0777);
    put(dir, "cg1/a/memory.limit_in_bytes", "3221225472\n");
    put(dir, "cg2/a/memory.max", "2147483648\n");
    assert_int_equal(limit_of(dir, "0::/a\n5:memory:/a\n",
                              "30 25 0:26 / @/cg2 rw - cgroup2 cgroup2 rw\n"
                              "31 25 0:27 / @/cg1 rw - cgroup cgroup rw,memory\n"),
                     2 * GIB);

    /* a container's view: the mount shows group /docker/x at its mount
     * point (whose own limit counts), and the path has a space (\040) */
    snprintf(dir, sizeof dir, "%s/container", base);
    mkdir(dir, 0777);
    put(dir, "cg 3/memory.max", "1073741824\n");
    put(dir, "cg 3/inner/memory.max", "2147483648\n");
    assert_int_equal(limit_of(dir, "0::/docker/x/inner\n",
                              "40 30 0:26 /docker/x @/cg\\0403 rw - cgroup2 cgroup2 rw\n"),
                     GIB);
    /* a group outside what the mount shows is not read */
    assert_int_equal(
        limit_of(dir, "0::/other\n", "40 30 0:26 /docker/x @/cg\\0403 rw - cgroup2 cgroup2 rw\n"),
        UINT64_MAX);

    /* no such files at all */
    assert_int_equal(lx_cgroup_memory_limit("/nonexistent/cgroup", "/nonexistent/mountinfo"),
                     UINT64_MAX);
}

int main(void)
{
    lx_test_watchdog(60);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(address_space_limit), cmocka_unit_test(data_size_limit),
        cmocka_unit_test(machine_bound),       cmocka_unit_test(descriptions),
        cmocka_unit_test(cgroup_limits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
