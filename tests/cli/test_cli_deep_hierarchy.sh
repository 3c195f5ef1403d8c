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

finish
