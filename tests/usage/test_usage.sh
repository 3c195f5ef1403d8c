# Runs every public header's USAGE example (compiled by CMake from the
# header itself, tests/usage/extract_usage.awk) in a folder holding the
# files the examples read: room.glb (gen_scenes), sky.hdr (gen_scenes'
# sky, rewritten as Radiance HDR by make_usage_inputs) and lamp.ies.
# Each example must run to its end (exit 0) and, under the sanitizer build,
# free what it allocates.
#
# usage: bash test_usage.sh GEN_SCENES MAKE_INPUTS WORKDIR EXAMPLE...
set -u
gen=$1 make_inputs=$2 work=$3
shift 3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
"$gen" . >/dev/null || { echo "FAIL  gen_scenes"; exit 1; }
"$make_inputs" sky.pfm sky.hdr lamp.ies || { echo "FAIL  make_usage_inputs"; exit 1; }
failed=0
for example in "$@"; do
    name=$(basename "$example")
    if "$example" >"$name.out" 2>&1; then
        echo "ok    $name"
    else
        echo "FAIL  $name (exit $?)"
        sed 's/^/        /' "$name.out"
        failed=$((failed + 1))
    fi
done
echo "$(($# - failed)) passed, $failed failed"
[ "$failed" -eq 0 ]
