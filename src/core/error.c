/* Thread-local error messages and the process-wide log callback. */
#define _XOPEN_SOURCE 700
#include "internal.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define LX_ERROR_MAX 1024

static _Thread_local char error_message[LX_ERROR_MAX];

/* One lock guards the callback and its user pointer together and is held
 * while the callback runs: calls never overlap, a line never goes to one
 * callback with the other's user pointer, and lx_set_log_callback returns
 * only once no call to the old callback is in flight. It is recursive so a
 * callback that logs anyway does not deadlock. */
static pthread_mutex_t log_lock;
static pthread_once_t log_once = PTHREAD_ONCE_INIT;
static lx_log_fn log_fn;
static void *log_user;

static void log_lock_init(void)
{
    pthread_mutexattr_t attr;
    pthread_mutexattr_init(&attr);
    pthread_mutexattr_settype(&attr, PTHREAD_MUTEX_RECURSIVE);
    pthread_mutex_init(&log_lock, &attr);
    pthread_mutexattr_destroy(&attr);
}

const char *lx_version(void)
{
    return LX_VERSION;
}

const char *lx_last_error(void)
{
    return error_message;
}

void lx_clear_error(void)
{
    error_message[0] = '\0';
}

const char *lx_status_name(lx_status status)
{
    switch (status) {
    case LX_OK:
        return "LX_OK";
    case LX_ERR_IO:
        return "LX_ERR_IO";
    case LX_ERR_FORMAT:
        return "LX_ERR_FORMAT";
    case LX_ERR_INVALID:
        return "LX_ERR_INVALID";
    case LX_ERR_NOMEM:
        return "LX_ERR_NOMEM";
    case LX_ERR_UNSUPPORTED:
        return "LX_ERR_UNSUPPORTED";
    case LX_ERR_CANCELLED:
        return "LX_ERR_CANCELLED";
    }
    return "LX_ERR_UNKNOWN";
}

lx_status lx_fail(lx_status status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(error_message, sizeof error_message, fmt, ap);
    va_end(ap);
    return status;
}

lx_status lx_fail_null(const char *function, const char *param)
{
    return lx_fail(LX_ERR_INVALID, "%s: %s is NULL", function, param);
}

void lx_error_prefix(const char *prefix)
{
    char old[LX_ERROR_MAX];
    memcpy(old, error_message, sizeof old);
    snprintf(error_message, sizeof error_message, "%s: %s", prefix, old);
}

void lx_set_log_callback(lx_log_fn fn, void *user)
{
    pthread_once(&log_once, log_lock_init);
    pthread_mutex_lock(&log_lock);
    log_fn = fn;
    log_user = user;
    pthread_mutex_unlock(&log_lock);
}

/* Muted on this thread (lx_log_mute): messages are dropped. */
static _Thread_local int log_muted;

void lx_log_mute(bool mute)
{
    log_muted += mute ? 1 : -1;
}

bool lx_log_muted(void)
{
    return log_muted > 0;
}

void lx_log(lx_log_level level, const char *fmt, ...)
{
    if (log_muted > 0)
        return;
    char line[LX_ERROR_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    pthread_once(&log_once, log_lock_init);
    pthread_mutex_lock(&log_lock);
    if (log_fn)
        log_fn(log_user, level, line);
    pthread_mutex_unlock(&log_lock);
}
