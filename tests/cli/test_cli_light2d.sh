# End-to-end tests of `luxel light2d`: the demo scene of examples/gen_light2d.c
# lit to PNG and EXR with a light map, the same bytes on 1 and 2 threads,
# --frames reporting its rate, and bad input - images of different sizes,
# casters without alpha (accepted with --mask), bad lights (radius, arc,
# direction, unknown key, truncated JSON), bad options - each failing with
# its exit status, one error line naming the problem, and no output file.
#
# usage: bash test_cli_light2d.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

GEN2D=$(dirname "$LUXEL_REAL")/gen_light2d
if [ ! -x "$GEN2D" ]; then
    skip "gen_light2d is not built next to luxel"
    finish
fi
"$GEN2D" "$WORK/s" >/dev/null || { echo "gen_light2d failed"; exit 1; }
"$GEN2D" "$WORK/small" 128 96 >/dev/null || { echo "gen_light2d failed"; exit 1; }
S=$WORK/s

run "$LUXEL" light2d --casters "$S/casters.png" --albedo "$S/albedo.png" \
    --normals "$S/normals.png" --lights "$S/lights.json" -o "$WORK/a1.png" --threads 1 -q
expect_rc 0 "light2d on 1 thread"
check "a PNG" test "$(magic "$WORK/a1.png" 8)" = 89504e470d0a1a0a
run "$LUXEL" light2d --casters "$S/casters.png" --albedo "$S/albedo.png" \
    --normals "$S/normals.png" --lights "$S/lights.json" -o "$WORK/a2.png" --threads 2 -q
expect_rc 0 "light2d on 2 threads"
check "1 and 2 threads give the same bytes" cmp -s "$WORK/a1.png" "$WORK/a2.png"
run "$LUXEL" light2d --casters "$S/casters.png" --lights "$S/lights.json" -o "$WORK/b.exr" \
    --light-map "$WORK/lm.pfm" --frames 3 --green down
expect_rc 0 "light2d to EXR with a light map and --frames"
check "EXR written" test "$(magic "$WORK/b.exr" 4)" = 762f3101
check "PFM light map written" test "$(head -c 2 "$WORK/lm.pfm")" = PF
expect_stdout_has "--frames reports the rate" '^light2d: 3 frames in [0-9.]+ s \([0-9.]+ frames/s\)$'
check "no staging folder left" test -z "$(ls -A "$WORK" | grep '^\.luxel-')"

# a grey mask: refused as casters without --mask, accepted with it
run "$LUXEL" light2d --casters "$S/albedo.png" --lights "$S/lights.json" -o "$WORK/m.png"
expect_rc 1 "casters without alpha"
expect_error "casters without alpha" "albedo.png" "no alpha channel" "--mask"
check "no image after a failure" test ! -e "$WORK/m.png"
run "$LUXEL" light2d --casters "$S/albedo.png" --mask --lights "$S/lights.json" -o "$WORK/m.png" -q
expect_rc 0 "a grey mask with --mask"

# sizes that differ
run "$LUXEL" light2d --casters "$S/casters.png" --albedo "$WORK/small/albedo.png" \
    --lights "$S/lights.json" -o "$WORK/x.png"
expect_rc 1 "albedo of another size"
expect_error "albedo of another size" "small/albedo.png" "128x96" "480x270"
check "no image (albedo size)" test ! -e "$WORK/x.png"
run "$LUXEL" light2d --casters "$S/casters.png" --normals "$WORK/small/normals.png" \
    --lights "$S/lights.json" -o "$WORK/x.png" --light-map "$WORK/x.exr"
expect_rc 1 "normals of another size"
expect_error "normals of another size" "normals.png" "128x96"
check "no image (normals size)" test ! -e "$WORK/x.png"
check "no light map (normals size)" test ! -e "$WORK/x.exr"

# bad lights
bad_lights() { # NAME JSON NEEDLE...
    local name=$1 json=$2
    shift 2
    printf '%s' "$json" >"$WORK/$name.json"
    run "$LUXEL" light2d --casters "$S/casters.png" --lights "$WORK/$name.json" -o "$WORK/$name.png"
    expect_rc 1 "$name"
    expect_error "$name" "$name.json" "$@"
    check "$name: no image" test ! -e "$WORK/$name.png"
}
bad_lights radius '{"lights": [{"position": [10, 10], "radius": 0}]}' "lights[0]" "radius 0 must be > 0"
bad_lights negradius '{"lights": [{"position": [10, 10], "radius": -5}]}' "radius -5"
bad_lights arc '{"lights": [{"type": "spot", "position": [1, 1], "direction": [1, 0], "radius": 9, "arc": 0}]}' "arc 0 must be in (0, 360]"
bad_lights arc2 '{"lights": [{"type": "spot", "position": [1, 1], "direction": [1, 0], "radius": 9, "arc": 361}]}' "arc 361"
bad_lights direction '{"lights": [{"type": "spot", "position": [1, 1], "direction": [0, 0], "radius": 9}]}' "direction is zero"
bad_lights unknown '{"lights": [{"position": [1, 1], "radius": 9, "colour": [1, 1, 1]}]}' "unknown key 'colour'"
bad_lights truncated '{"lights": [{"position": [1, 1], "radius": 9' "truncated"
bad_lights falloff '{"lights": [{"position": [1, 1], "radius": 9, "falloff": "cubic"}]}' "unknown falloff 'cubic'"

# usage errors
run "$LUXEL" light2d --casters "$S/casters.png" -o "$WORK/u.png"
expect_rc 2 "no --lights"
expect_error "no --lights" "--lights is required"
run "$LUXEL" light2d --casters "$S/casters.png" --lights "$S/lights.json" -o "$WORK/u.jpg"
expect_rc 2 "-o of another format"
run "$LUXEL" light2d --casters "$S/casters.png" --lights "$S/lights.json" -o "$WORK/u.png" --threshold 2
expect_rc 2 "--threshold out of range"
run "$LUXEL" light2d --casters "$S/casters.png" --lights "$S/lights.json" -o "$WORK/u.png" --green sideways
expect_rc 2 "--green sideways"
check "no image after usage errors" test ! -e "$WORK/u.png"

finish
