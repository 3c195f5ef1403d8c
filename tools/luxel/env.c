/* The environment argument shared by `luxel ibl` and `luxel bake --sky`:
 * an image file in any layout lx_env_load reads, or a constant colour
 * written const:R,G,B or const:L (nits). */
#include "cli.h"

#include <string.h>

/* "const:R,G,B" or "const:L": true and *rgb when env names a constant;
 * *bad when it starts with const: but does not parse. */
static bool parse_constant(const char *env, lx_vec3 *rgb, bool *bad)
{
    *bad = false;
    if (strncmp(env, "const:", 6) != 0)
        return false;
    const char *v = env + 6;
    double l;
    if (cli_parse_rgb(v, rgb))
        return true;
    if (cli_parse_float(v, 0.0, 3.4e38, &l)) {
        *rgb = lx_v3((float)l, (float)l, (float)l);
        return true;
    }
    *bad = true;
    return false;
}

int cli_load_environment_run(const char *command, const char *env, float intensity, int size,
                             int threads, bool quiet, lx_cubemap *out)
{
    memset(out, 0, sizeof *out);
    lx_vec3 constant;
    bool bad_constant;
    if (parse_constant(env, &constant, &bad_constant)) {
        lx_env_load_desc given = {.intensity = intensity};
        constant = lx_scale(constant, lx_env_load_desc_defaults(&given).intensity);
        if (!lx_vec3_finite(constant)) {
            cli_error("%s: intensity %g overflows", env, (double)intensity);
            return EXIT_FAILED;
        }
        if (lx_env_constant(constant, size ? size : CLI_CONSTANT_ENV_SIZE, out) != LX_OK) {
            cli_error("%s: %s", env, lx_last_error());
            return EXIT_FAILED;
        }
        return EXIT_OK;
    }
    if (bad_constant)
        return cli_usage_error(command,
                               "a constant environment is const:R,G,B or const:L with finite "
                               "values >= 0, not '%s'",
                               env);
    cli_progress progress;
    cli_progress_init(&progress, "environment", quiet);
    lx_env_load_desc ld = {.intensity = intensity,
                           .size = size,
                           .threads = threads,
                           .progress = cli_progress_update,
                           .progress_user = &progress};
    lx_status st = lx_env_load(env, &ld, out);
    cli_progress_finish(&progress);
    if (st == LX_ERR_CANCELLED) {
        cli_report_interrupt(false);
        return EXIT_FAILED;
    }
    if (st != LX_OK) {
        cli_error("%s", lx_last_error());
        return EXIT_FAILED;
    }
    return EXIT_OK;
}

int cli_load_environment(const char *command, const char *env, float intensity, int size,
                         lx_cubemap *out)
{
    return cli_load_environment_run(command, env, intensity, size, 0, true, out);
}

int cli_environment_size(const char *env, int size)
{
    if (size)
        return size;
    lx_vec3 constant;
    bool bad;
    return parse_constant(env, &constant, &bad) ? CLI_CONSTANT_ENV_SIZE : 0;
}
