/* The options every command spells the same way: --threads, -q, -v, and
 * the errors for a missing value and an unknown option, so that each
 * command's switch ends in one call and every command words them alike. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <getopt.h>

int cli_common_option(const char *command, int c, char **argv, int *threads, bool *quiet)
{
    long n;
    switch (c) {
    case CLI_OPT_THREADS:
        if (!threads)
            break;
        if (!cli_parse_int(optarg, 1, CLI_MAX_THREADS, &n))
            return cli_usage_error(command, "--threads must be an integer in 1..%d, not '%s'",
                                   CLI_MAX_THREADS, optarg);
        *threads = (int)n;
        return 0;
    case 'q':
        if (!quiet)
            break;
        *quiet = true;
        cli_set_quiet(true);
        return 0;
    case 'v':
        cli_set_verbose(true);
        return 0;
    case CLI_OPT_ANY_PATH:
        cli_set_allow_any_path(true);
        return 0;
    case ':':
        return cli_usage_error(command, "option '%s' needs a value", argv[optind - 1]);
    default:
        break;
    }
    return cli_usage_error(command, "unknown option '%s'", argv[optind - 1]);
}
