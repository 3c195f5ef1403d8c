# End-to-end checks of the CLI's output folders and sky limits (a failed
# run leaves nothing behind, every bad input gets one error line):
# - an empty -o is a usage error for bake as for ibl (it read past the end
#   of the folder name);
# - a failed run removes every folder it created, missing parents of the
#   output folder included, not only the last one;
# - a sky whose intensity overflows a float is an error naming the sky,
#   not a bake that silently drops the sky (its SH turned NaN, clamped to 0).
#
# usage: bash test_cli_outputs.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb

# ---- -o "" -------------------------------------------------------------------------

run "$LUXEL" bake "$ROOM" --resolution 8 -q -o ""
expect_rc 2 "bake -o ''"
expect_error "bake -o ''" "-o needs a folder name"

# ---- folders a failed run created ----------------------------------------------------

# --half cannot hold values above 65504: the write fails after the output
# folder (and its missing parents) were made
run "$LUXEL" bake "$ROOM" --resolution 8 --ambient 1e6,1e6,1e6 --half -q -o "$WORK/new1/new2/out"
expect_rc 1 "bake: failed write into new nested folders"
expect_error "bake: failed write into new nested folders" "half-float range"
check "bake: failed write removes every folder it created" test ! -e "$WORK/new1"

run "$LUXEL" ibl const:1e6 --irradiance --half -q -o "$WORK/ibl1/ibl2/out"
expect_rc 1 "ibl: failed write into new nested folders"
expect_error "ibl: failed write into new nested folders" "half-float range"
check "ibl: failed write removes every folder it created" test ! -e "$WORK/ibl1"

# a parent that was there stays, with what it held
mkdir -p "$WORK/kept"
: >"$WORK/kept/file"
run "$LUXEL" bake "$ROOM" --resolution 8 --ambient 1e6,1e6,1e6 --half -q -o "$WORK/kept/a/b"
expect_rc 1 "bake: failed write under an existing parent"
check "bake: the existing parent stays" test -f "$WORK/kept/file"
check "bake: the folders under it go" test ! -e "$WORK/kept/a"

# a successful run into new nested folders keeps them
run "$LUXEL" bake "$ROOM" --resolution 8 -q -o "$WORK/ok1/ok2"
expect_rc 0 "bake into new nested folders"
check "bake: the manifest is there" test -f "$WORK/ok1/ok2/manifest.json"

# a failed run with more outputs than the CLI used to track (4096): 2100
# lightmaps and their previews, the last one too bright for --half (a
# point light under it, out of range of the others). The staging folder
# kept the files past the 4096th.
many=$WORK/many.gltf
{
    for v in 0 0 0 1 0 0 1 0 1 0 0 0 1 0 1 0 0 1; do f32 "$v"; done
    for v in 0 0 1 0 1 1 0 0 1 1 0 1; do f32 "$v"; done
} >"$WORK/many.bin"
{
    printf '{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": ['
    for ((i = 0; i < 2100; i++)); do
        [ "$i" -gt 0 ] && printf ','
        printf '%d' "$i"
    done
    printf ']}],\n "nodes": ['
    for ((i = 0; i < 2100; i++)); do
        [ "$i" -gt 0 ] && printf ','
        printf '{"name": "n%d", "mesh": 0, "translation": [%d, 0, %d]}' "$i" $((2 * (i % 50))) \
            $((2 * (i / 50)))
    done
    printf '],\n "meshes": [{"name": "q", "primitives": [{"attributes": {"POSITION": 0, '
    printf '"TEXCOORD_0": 1}, "mode": 4}]}],\n'
    printf ' "accessors": [{"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3", '
    printf '"min": [0, 0, 0], "max": [1, 0, 1]}, {"bufferView": 1, "componentType": 5126, '
    printf '"count": 6, "type": "VEC2"}],\n'
    printf ' "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 72}, '
    printf '{"buffer": 0, "byteOffset": 72, "byteLength": 48}],\n'
    printf ' "buffers": [{"uri": "many.bin", "byteLength": 120}]}\n'
} >"$many"
# the quads face -Y: the light is under the last one (at x 98..99, z 82..83)
printf '{"lights": [{"type": "point", "position": [98.5, -0.5, 82.5], "intensity": 1e7, ' >"$WORK/hot.json"
printf '"range": 1.5, "shadow": "none"}]}\n' >>"$WORK/hot.json"
run "$LUXEL" bake "$many" --lights "$WORK/hot.json" --resolution 4 --half -q -o "$WORK/many_out"
expect_rc 1 "bake of 2100 lightmaps failing at the last"
expect_error "bake of 2100 lightmaps failing at the last" "n2099.exr" "half-float range"
expect_no_output "bake of 2100 lightmaps failing at the last" "$WORK/many_out"

# ---- sky intensity overflow -----------------------------------------------------------

for shadows in "" --sky-shadows; do
    label="bake --sky const:1e30 --sky-intensity 1e30 ${shadows:-(no shadows)}"
    run "$LUXEL" bake "$ROOM" --resolution 8 -q --sky const:1e30 --sky-intensity 1e30 \
        $shadows -o "$WORK/bright"
    expect_rc 1 "$label"
    expect_error "$label" "sky: " "overflow"
    expect_no_output "$label" "$WORK/bright"
done

# The whole ibl run must fit in memory, not each allocation alone:
# tests/cli/test_cli_limits.sh (case ibl_run).

finish
