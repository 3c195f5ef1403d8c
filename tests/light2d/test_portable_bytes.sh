#!/bin/bash
# The 2D lights give the same bytes on every CPU: l2_render_hash (the
# library as built: vector clones and AVX2 gathers where the CPU has them)
# and l2_render_hash_portable (src/light2d's portable scalar loops) must
# print the same hash for every scene. Skipped (77) on a CPU without AVX2,
# where both run the same loops and the comparison proves nothing.
set -euo pipefail
vector=$1 portable=$2
if ! grep -qw avx2 /proc/cpuinfo 2>/dev/null; then
    echo "SKIP: this CPU has no AVX2: the vector paths do not run"
    exit 77
fi
a=$("$vector")
b=$("$portable")
if [ "$a" != "$b" ]; then
    echo "FAIL: the vector and portable builds of src/light2d differ:"
    diff <(echo "$a") <(echo "$b") || true
    exit 1
fi
echo "$a" | wc -l | xargs echo "ok: scenes hashed alike:"
