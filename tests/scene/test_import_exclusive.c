/* The one-call exclusive import path (src/scene/import_assimp.c): when
 * less memory is left than the estimate of assimp's post-processing (512
 * bytes a vertex and 384 a face as assimp reads the file), the file is
 * imported again in one aiImportFileExWithProperties call holding the
 * lock alone, so that an allocation failure there is assimp's error, not
 * a crash in aiApplyPostProcessing. A 150 x 150 OBJ grid reads as 135000
 * vertices and 45000 faces: 86.4 MB of estimate. A child process whose
 * address-space limit leaves 1 MiB less than that takes the path; the
 * import needs about 70 MiB there, so it must give the serial scene.
 * (Loads on several threads: test_import_threads.c.) */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/internal.h"
#include "helpers.h"
#include "scene_files.h"
#include "luxel/scene.h"

#if defined(__SANITIZE_ADDRESS__)
#define LX_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define LX_ASAN 1
#endif
#endif

#ifdef LX_ASAN
/* AddressSanitizer keeps freed memory mapped (its quarantine) and ends
 * the process when C++ new cannot allocate, so under an address-space
 * limit it would need far more than the import: freed memory goes back at
 * once in this program. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "quarantine_size_mb=0";
}
#endif

static void exclusive_path_equals_serial(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_import_exclusive");
    char path[512];
    snprintf(path, sizeof path, "%s/grid.obj", dir);
    lx_test_write_obj_grid(path, "grid", 150);
    uint64_t estimate = 135000ull * 512u + 45000ull * 384u;
    lx_scene *s = NULL;
    if (lx_scene_load(path, NULL, &s) != LX_OK)
        fail_msg("%s: %s", path, lx_last_error());
    uint64_t serial = lx_test_scene_digest(s);
    lx_scene_destroy(s);
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        FILE *statm = fopen("/proc/self/statm", "r");
        unsigned long long pages = 0;
        if (!statm || fscanf(statm, "%llu", &pages) != 1)
            _exit(3);
        fclose(statm);
        uint64_t vm = (uint64_t)pages * (uint64_t)sysconf(_SC_PAGESIZE);
        rlim_t limit = (rlim_t)(vm + estimate - (1u << 20));
        struct rlimit rl = {limit, limit};
        if (setrlimit(RLIMIT_AS, &rl) != 0)
            _exit(4);
        if (lx_memory_available(NULL) >= estimate)
            _exit(5); /* not the exclusive path */
        lx_scene *got = NULL;
        if (lx_scene_load(path, NULL, &got) != LX_OK) {
            fprintf(stderr, "exclusive path: %s\n", lx_last_error());
            _exit(6);
        }
        bool same = lx_test_scene_digest(got) == serial;
        lx_scene_destroy(got);
        _exit(same ? 0 : 7);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
}

int main(void)
{
    lx_test_watchdog(120);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(exclusive_path_equals_serial),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
