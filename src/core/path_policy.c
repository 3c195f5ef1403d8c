/* Which files an input may make luxel read. A scene, a lights JSON or a
 * manifest names other files (buffers, textures, material libraries, IES
 * profiles, lightmap pages) and luxel copies some of their bytes into what
 * it writes, so a file downloaded from anywhere could otherwise pull
 * /etc/passwd or ~/.ssh/id_rsa into a .glb. By default a named file must
 * lie in the naming file's folder or below it, judged on the resolved
 * path (symbolic links followed, so a link inside the folder to a file
 * outside is refused too; a name that resolves to nothing cannot be read
 * and is left to its reader to report missing); a caller that trusts its inputs lifts the rule
 * (lx_scene_load_desc.allow_any_path and friends). */
#define _GNU_SOURCE /* realpath */
#include "internal.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool lx_path_within(const char *folder, const char *path)
{
    char *real = realpath(path, NULL);
    if (!real && strchr(path, '\\')) { /* the form readers retry: "..\\x.png" */
        char *slashed = lx_strdup(path);
        for (char *q = slashed; q && *q; q++)
            if (*q == '\\')
                *q = '/';
        real = slashed ? realpath(slashed, NULL) : NULL;
        free(slashed);
    }
    if (!real)
        return true; /* nothing there to read: its reader reports it missing */
    char *root = realpath(folder, NULL);
    bool inside = false;
    if (root) {
        size_t n = strlen(root);
        inside = strncmp(real, root, n) == 0 &&
                 (real[n] == '/' || real[n] == '\0' || (n == 1 && root[0] == '/'));
    }
    free(root);
    free(real);
    return inside;
}

lx_status lx_path_confine(const char *file, const char *what, const char *named, const char *folder,
                          const char *path, bool allow_any)
{
    if (allow_any || lx_path_within(folder, path))
        return LX_OK;
    return lx_fail(LX_ERR_INVALID,
                   "%s: %s '%.200s' is outside the folder '%s': refused (--allow-any-path "
                   "reads it)",
                   file, what, named, folder);
}
