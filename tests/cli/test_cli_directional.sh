# End-to-end tests of `luxel bake --directional sh|dominant`: the files
# each mode writes beside the lightmaps (<name>_sh0..3.<ext> for sh, in
# EXR as signed irradiance and in PNG as L1 / L0 codes; <name>_dir.png for
# dominant) and the manifest naming them (page "sh" / "dir", top-level
# "directional" with the mode and the encoding); the same bytes for 1 and 2
# threads; `luxel render` reads them (the room has no normal maps: the
# view is the same bytes as without directional data); bad values are
# usage errors (exit 2, one error line, nothing written).
#
# usage: bash test_cli_directional.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
SMALL=(--resolution 24 --bounces 1 --gi-samples 9 -q)

# ---- sh, EXR ---------------------------------------------------------------------
run "$LUXEL" bake "$ROOM" "${SMALL[@]}" --directional sh --threads 1 -o "$WORK/sh1"
expect_rc 0 "bake --directional sh"
expect_files "sh: the lightmaps, previews and 4 coefficient files each" "$WORK/sh1" \
    manifest.json room.exr room.png tall_box.exr tall_box.png short_box.exr short_box.png \
    room_sh0.exr room_sh1.exr room_sh2.exr room_sh3.exr \
    tall_box_sh0.exr tall_box_sh1.exr tall_box_sh2.exr tall_box_sh3.exr \
    short_box_sh0.exr short_box_sh1.exr short_box_sh2.exr short_box_sh3.exr
check "sh0 is an EXR" test "$(magic "$WORK/sh1/room_sh0.exr" 4)" = 762f3101
check "manifest: the directional mode" \
    grep -Eq '"mode":[[:space:]]*"sh"' "$WORK/sh1/manifest.json"
check "manifest: EXR holds irradiance" \
    grep -Eq '"encoding":[[:space:]]*"irradiance"' "$WORK/sh1/manifest.json"
check "manifest: the page names its sh files" \
    grep -Fq '"sh":	["room_sh0.exr", "room_sh1.exr", "room_sh2.exr", "room_sh3.exr"]' \
    "$WORK/sh1/manifest.json"

run "$LUXEL" bake "$ROOM" "${SMALL[@]}" --directional sh --threads 2 -o "$WORK/sh2"
expect_rc 0 "bake --directional sh on 2 threads"
for n in room_sh0 room_sh1 room_sh2 room_sh3 tall_box_sh3; do
    check "$n.exr: same bytes with 1 and 2 threads" cmp -s "$WORK/sh1/$n.exr" "$WORK/sh2/$n.exr"
done

# ---- the view: no normal maps, nothing changes -------------------------------------
run "$LUXEL" bake "$ROOM" "${SMALL[@]}" --threads 1 -o "$WORK/plain"
expect_rc 0 "bake without directional data"
check "room.exr: a directional bake keeps the lightmap's bytes (no normal maps here)" \
    cmp -s "$WORK/plain/room.exr" "$WORK/sh1/room.exr"
run "$LUXEL" render "$ROOM" --lightmaps "$WORK/sh1" -o "$WORK/v_sh.png" --size 64x36
expect_rc 0 "render with sh data"
run "$LUXEL" render "$ROOM" --lightmaps "$WORK/plain" -o "$WORK/v_plain.png" --size 64x36
check "the view is the same without normal maps" cmp -s "$WORK/v_sh.png" "$WORK/v_plain.png"

# ---- sh, PNG: normalized codes -------------------------------------------------------
run "$LUXEL" bake "$ROOM" "${SMALL[@]}" --directional sh --format png -o "$WORK/shpng"
expect_rc 0 "bake --directional sh --format png"
check "room_sh1.png is a PNG" test "$(magic "$WORK/shpng/room_sh1.png" 8)" = 89504e470d0a1a0a
check "manifest: PNG holds normalized L1" \
    grep -Eq '"encoding":[[:space:]]*"normalized"' "$WORK/shpng/manifest.json"
run "$LUXEL" render "$ROOM" --lightmaps "$WORK/shpng" -o "$WORK/v_shpng.png" --size 64x36
expect_rc 0 "render with normalized sh data"

# ---- dominant -------------------------------------------------------------------------
run "$LUXEL" bake "$ROOM" "${SMALL[@]}" --directional dominant -o "$WORK/dom"
expect_rc 0 "bake --directional dominant"
expect_files "dominant: a _dir.png per lightmap" "$WORK/dom" \
    manifest.json room.exr room.png tall_box.exr tall_box.png short_box.exr short_box.png \
    room_dir.png tall_box_dir.png short_box_dir.png
check "room_dir.png is an RGBA PNG (colour type 6)" \
    test "$(od -An -tu1 -j25 -N1 "$WORK/dom/room_dir.png" | tr -d ' ')" = 6
check "manifest: the page names its dir file" \
    grep -Eq '"dir":[[:space:]]*"room_dir.png"' "$WORK/dom/manifest.json"
run "$LUXEL" render "$ROOM" --lightmaps "$WORK/dom" -o "$WORK/v_dom.png" --size 64x36
expect_rc 0 "render with dominant data"

# ---- bad values ------------------------------------------------------------------------
run "$LUXEL" bake "$ROOM" "${SMALL[@]}" --directional spherical -o "$WORK/bad1"
expect_rc 2 "--directional spherical"
expect_error "--directional spherical" "--directional" "off, sh or dominant" "spherical"
expect_no_output "--directional spherical" "$WORK/bad1"
run "$LUXEL" bake "$ROOM" "${SMALL[@]}" --directional sh --quantity radiance -o "$WORK/bad2"
expect_rc 2 "--directional with --quantity radiance"
expect_error "--directional with --quantity radiance" "--directional" "irradiance"
expect_no_output "--directional with --quantity radiance" "$WORK/bad2"
# a manifest that says sh but lists no files
mkdir -p "$WORK/broken" && cp "$WORK/plain/"* "$WORK/broken/"
awk '{print} /"quantity"/ && !done {print "\t\"directional\":\t{\"mode\": \"sh\", \"encoding\": \"irradiance\"},"; done=1}' \
    "$WORK/plain/manifest.json" >"$WORK/broken/manifest.json"
run "$LUXEL" render "$ROOM" --lightmaps "$WORK/broken" -o "$WORK/v_broken.png" --size 64x36
expect_rc 1 "render: a manifest with sh but no files"
expect_error "render: a manifest with sh but no files" "manifest.json" "\"sh\" must be 4 file names"
check "render: no view written" test ! -e "$WORK/v_broken.png"

finish
