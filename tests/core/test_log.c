/* The log callback while threads log (core.h's THREADING promise): worker
 * threads log without pause while the main thread swaps between two
 * callbacks with their own user pointers. Every line must reach exactly
 * one callback with that callback's own user pointer, calls must never
 * overlap, and once lx_set_log_callback returns the previous callback must
 * not be called again. Log levels are ordered by severity. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "luxel/core.h"

#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdbool.h>

typedef struct sink {
    _Atomic long lines;
    _Atomic bool retired; /* set once the main thread installed another */
    _Atomic long after_retired;
} sink;

static sink sink_a, sink_b;
static _Atomic int inside;
static _Atomic long overlaps, wrong_user;
static _Atomic bool stop;

static void on_a(void *user, lx_log_level level, const char *message)
{
    (void)level;
    (void)message;
    if (atomic_fetch_add(&inside, 1) != 0)
        atomic_fetch_add(&overlaps, 1);
    if (user != &sink_a)
        atomic_fetch_add(&wrong_user, 1);
    if (atomic_load(&sink_a.retired))
        atomic_fetch_add(&sink_a.after_retired, 1);
    atomic_fetch_add(&sink_a.lines, 1);
    atomic_fetch_sub(&inside, 1);
}

static void on_b(void *user, lx_log_level level, const char *message)
{
    (void)level;
    (void)message;
    if (atomic_fetch_add(&inside, 1) != 0)
        atomic_fetch_add(&overlaps, 1);
    if (user != &sink_b)
        atomic_fetch_add(&wrong_user, 1);
    if (atomic_load(&sink_b.retired))
        atomic_fetch_add(&sink_b.after_retired, 1);
    atomic_fetch_add(&sink_b.lines, 1);
    atomic_fetch_sub(&inside, 1);
}

static _Atomic long sent;

static void *worker(void *arg)
{
    (void)arg;
    while (!atomic_load(&stop)) {
        lx_log(LX_LOG_WARN, "line %ld", atomic_fetch_add(&sent, 1));
    }
    return NULL;
}

static void test_swapping_while_threads_log(void **state)
{
    (void)state;
    enum { WORKERS = 4, SWAPS = 2000 };
    pthread_t threads[WORKERS];
    lx_set_log_callback(on_a, &sink_a);
    for (int i = 0; i < WORKERS; i++)
        assert_int_equal(pthread_create(&threads[i], NULL, worker, NULL), 0);
    for (int k = 0; k < SWAPS; k++) {
        bool to_b = k % 2 == 0;
        /* let the workers log a few lines under each callback */
        long at = atomic_load(&sent);
        while (atomic_load(&sent) < at + WORKERS)
            sched_yield();
        /* un-retire the one being installed before it can be called */
        atomic_store(to_b ? &sink_b.retired : &sink_a.retired, false);
        lx_set_log_callback(to_b ? on_b : on_a, to_b ? (void *)&sink_b : (void *)&sink_a);
        /* from here on the other one must stay silent */
        atomic_store(to_b ? &sink_a.retired : &sink_b.retired, true);
    }
    lx_set_log_callback(NULL, NULL);
    atomic_store(&stop, true);
    for (int i = 0; i < WORKERS; i++)
        pthread_join(threads[i], NULL);
    long delivered = atomic_load(&sink_a.lines) + atomic_load(&sink_b.lines);
    assert_true(delivered >= (long)SWAPS * WORKERS);
    assert_true(delivered <= atomic_load(&sent)); /* lines after NULL are dropped */
    assert_int_equal(atomic_load(&overlaps), 0);
    assert_int_equal(atomic_load(&wrong_user), 0);
    assert_int_equal(atomic_load(&sink_a.after_retired), 0);
    assert_int_equal(atomic_load(&sink_b.after_retired), 0);
}

static void test_levels_ordered_by_severity(void **state)
{
    (void)state;
    assert_true(LX_LOG_DEBUG < LX_LOG_INFO);
    assert_true(LX_LOG_INFO < LX_LOG_WARN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_swapping_while_threads_log),
        cmocka_unit_test(test_levels_ordered_by_severity),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
