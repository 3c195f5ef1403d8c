# A scene nested 20,000 nodes deep (410 KB of glTF, and as Collada) once
# killed bake, info, unwrap, tangents and probes with SIGSEGV inside assimp,
# leaving the staging folder behind. Every command now refuses it before
# import: exit 1, one error line naming the file and the 256-level limit,
# no output and no staging folder. The files are written here.
#
# usage: bash test_cli_deep_hierarchy.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

IN=$WORK/in
mkdir -p "$IN" "$WORK/out"
LEVELS=20000

# glTF: node i's child is node i+1
{
    printf '{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":['
    awk -v n=$LEVELS 'BEGIN { for (i = 0; i < n - 1; i++) printf "{\"name\":\"n%d\",\"children\":[%d]},", i, i + 1; printf "{\"name\":\"leaf\"}" }'
    printf ']}'
} >"$IN/deep.gltf"
# Collada: <node> inside <node>
{
    printf '<?xml version="1.0"?>\n<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
    printf '<library_visual_scenes><visual_scene id="s">'
    awk -v n=$LEVELS 'BEGIN { for (i = 0; i < n; i++) printf "<node id=\"n%d\">", i; for (i = 0; i < n; i++) printf "</node>" }'
    printf '</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>\n'
} >"$IN/deep.dae"

for scene in deep.gltf deep.dae; do
    for cmd in bake info unwrap tangents probes; do
        out=$WORK/out/$cmd-${scene%.*}
        case $cmd in
        bake) args=(bake "$IN/$scene" --ambient 1 -o "$out") ;;
        info) args=(info "$IN/$scene") ;;
        unwrap | tangents) args=("$cmd" "$IN/$scene" -o "$out.glb") ;;
        probes) args=(probes "$IN/$scene" --ambient 1 --grid 2,2,2 -o "$out.json") ;;
        esac
        run "$LUXEL" "${args[@]}"
        expect_rc 1 "$cmd $scene"
        case $scene in
        deep.gltf) expect_error "$cmd $scene" "$scene" "deeper than 256 levels" ;;
        deep.dae) expect_error "$cmd $scene" "$scene" "nested deeper than" ;;
        esac
        expect_no_output "$cmd $scene" "$out"
        check "$cmd $scene: no file beside the output" test ! -e "$out.glb" -a ! -e "$out.json"
    done
done
check "no staging folder left" test -z "$(find "$WORK" -name '.luxel-*' -print -quit)"

# ---- an import assimp cannot be stopped in: a signal still ends the run ----------

# 100,000 vertices at one point (an accessor without a bufferView, one
# sparse value): assimp's normal generation compares every pair, half a
# minute or more. SIGTERM a second in ends each command at once (the import
# left running, the process ended by the signal): status 143, one line, no
# output, no staging folder. Before, the signal waited for the import.
sparse_one='AAAAAAAAgD8AAAAAAAAAAA==' # index 0, then the position (1, 0, 0)
printf '%s' '{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],' \
    '"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],' \
    '"buffers":[{"byteLength":16,"uri":"data:application/octet-stream;base64,'"$sparse_one"'"}],' \
    '"bufferViews":[{"buffer":0,"byteLength":4},{"buffer":0,"byteOffset":4,"byteLength":12}],' \
    '"accessors":[{"componentType":5126,"count":100000,"type":"VEC3","min":[0,0,0],"max":[1,0,0],' \
    '"sparse":{"count":1,"indices":{"bufferView":0,"componentType":5125},"values":{"bufferView":1}}}]}' \
    >"$IN/one_point.gltf"
for cmd in bake info unwrap; do
    out=$WORK/out/$cmd-one_point
    case $cmd in
    bake) args=(bake "$IN/one_point.gltf" --ambient 1 -o "$out") ;;
    info) args=(info "$IN/one_point.gltf") ;;
    unwrap) args=(unwrap "$IN/one_point.gltf" -o "$out.glb") ;;
    esac
    "$LUXEL" "${args[@]}" >"$OUT" 2>"$ERR" </dev/null &
    pid=$!
    sleep 1
    kill -TERM "$pid"
    start=$(date +%s%N)
    wait "$pid"
    RC=$?
    ms=$((($(date +%s%N) - start) / 1000000))
    label="$cmd of one_point.gltf, SIGTERM during the import"
    expect_rc 143 "$label"
    check "$label: ends within 2 s of the signal ($ms ms)" test "$ms" -lt 2000
    expect_error "$label" "interrupted"
    expect_no_output "$label" "$out"
    check "$label: no file beside the output" test ! -e "$out.glb"
done
check "no staging folder left after the interrupts" \
    test -z "$(find "$WORK" -name '.luxel-*' -print -quit)"

finish
