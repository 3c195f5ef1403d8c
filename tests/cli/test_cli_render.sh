# End-to-end tests of `luxel render` and `luxel bake --render`: a view of
# the room baked here (a PNG of the asked size, the same bytes on 1 and 2
# threads), the view bake --render leaves beside the
# lightmaps, the manifest's scene_with_uvs taken over SCENE, luxel's own
# UVs made again when the scene with them is not there, and bad input - no manifest, the lightmaps of another scene, a
# missing page, a malformed --camera or --size - failing with the exact
# status, one error line naming the problem, and no image.
#
# usage: bash test_cli_render.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
RETRO=$WORK/scenes/retro.glb

run "$LUXEL" bake "$ROOM" --resolution 64 -q -o "$WORK/room" --render
expect_rc 0 "bake --render"
check "bake --render writes view.png" test -s "$WORK/room/view.png"
check "view.png is a PNG" test "$(magic "$WORK/room/view.png" 8)" = 89504e470d0a1a0a

# the PNG's width and height from its IHDR chunk
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{printf "%dx%d\n", $3*256+$4, $7*256+$8}'; }

run "$LUXEL" render "$ROOM" --lightmaps "$WORK/room" -o "$WORK/v1.png" --size 160x90 --threads 1
expect_rc 0 "render on 1 thread"
check "render: the asked size" test "$(png_size "$WORK/v1.png")" = 160x90
run "$LUXEL" render "$ROOM" --lightmaps "$WORK/room" -o "$WORK/v2.png" --size 160x90 --threads 2
expect_rc 0 "render on 2 threads"
check "1 and 2 threads give the same bytes" cmp -s "$WORK/v1.png" "$WORK/v2.png"
run "$LUXEL" render "$ROOM" --lightmaps "$WORK/room" -o "$WORK/v3.exr" --size 32x18 --view top \
    --filter bicubic --samples 2 -q
expect_rc 0 "render to EXR, top view, bicubic"
check "EXR written" test "$(magic "$WORK/v3.exr" 4)" = 762f3101

# luxel's UVs: without the scene that carries them they are made again
run "$LUXEL" bake "$ROOM" --unwrap always --texel-density 8 -q -o "$WORK/gen"
expect_rc 0 "bake with generated UVs"
swu=$(awk -F'"' '/"scene_with_uvs"/ {print $4}' "$WORK/gen/manifest.json")
[ -n "$swu" ] && rm -f "$WORK/gen/$swu"
run "$LUXEL" render "$ROOM" --lightmaps "$WORK/gen" -o "$WORK/gen.png" --size 64x36
expect_rc 0 "render of generated UVs, made again"
check "generated-UV view written" test -s "$WORK/gen.png"

# the manifest's scene_with_uvs is rendered instead of SCENE when it is there
cp -r "$WORK/room" "$WORK/room-swu"
cp "$ROOM" "$WORK/room-swu/with_uvs.glb"
awk '{print} /"quantity"/ && !done {print "\t\"scene_with_uvs\":\t\"with_uvs.glb\","; done=1}' \
    "$WORK/room/manifest.json" >"$WORK/room-swu/manifest.json"
run "$LUXEL" render "$RETRO" --lightmaps "$WORK/room-swu" -o "$WORK/swu.png" --size 64x36 -q
expect_rc 0 "scene_with_uvs used instead of SCENE"
check "scene_with_uvs view written" test -s "$WORK/swu.png"

# bad input: status, one error line, no image
badr() {
    local label=$1 status=$2 needles=$3 out=$4
    shift 4
    run "$LUXEL" render "$@" -o "$out"
    expect_rc "$status" "$label"
    local list=()
    IFS='|' read -ra list <<<"$needles"
    expect_error "$label" "${list[@]}"
    check "$label: no image" test ! -e "$out"
}
mkdir -p "$WORK/empty"
badr "no manifest" 1 "manifest.json" "$WORK/b1.png" "$ROOM" --lightmaps "$WORK/empty"
badr "lightmaps of another scene" 1 "another scene" "$WORK/b2.png" "$RETRO" --lightmaps "$WORK/room"
cp -r "$WORK/room" "$WORK/room-nopage"
rm -f "$WORK/room-nopage/tall_box.exr"
badr "missing page" 1 "tall_box.exr" "$WORK/b3.png" "$ROOM" --lightmaps "$WORK/room-nopage"
badr "bad --camera" 2 "--camera" "$WORK/b4.png" "$ROOM" --lightmaps "$WORK/room" --camera 1,2,3,4
badr "--camera eye = target" 2 "same point" "$WORK/b5.png" "$ROOM" --lightmaps "$WORK/room" \
    --camera 1,1,1,1,1,1
badr "bad --size" 2 "--size" "$WORK/b6.png" "$ROOM" --lightmaps "$WORK/room" --size 100x
badr "no --lightmaps" 2 "--lightmaps" "$WORK/b7.png" "$ROOM"
badr "--camera and --view" 2 "give one" "$WORK/b8.png" "$ROOM" --lightmaps "$WORK/room" \
    --view top --camera 0,1,5,0,0,0

finish
