# Runs of `luxel bake` and `luxel info` that must not end in a silent black
# file: nothing emitting light, lightmap UVs one tile off (made anew under
# --unwrap auto, an error under --unwrap never: no texel covered), a spot
# cone typed in radians, scenes whose units look wrong, --strict, and the
# UV health `luxel info` reports.
#
# The scenes are written here; what they should do follows from their
# numbers: a quad with UVs in [1,2] x [0,1] covers no texel of [0,1]^2;
# a constant ambient of 1 lux lights every covered texel with exactly 1 lux
# (float bits 3f800000).
#
# usage: bash test_cli_failures.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

# a few more exact float32 encodings (powers of two: sign 0, exponent
# 127 + k, mantissa 0)
eval "$(declare -f f32 | sed '1s/^f32/f32_common/')"
f32() {
    case $1 in
    0.03125) printf '\x00\x00\x00\x3d' ;; # 2^-5
    16384) printf '\x00\x00\x80\x46' ;;   # 2^14
    *) f32_common "$1" ;;
    esac
}

IN=$WORK/in
mkdir -p "$IN" "$WORK/out"

# a 1 m square floor (two triangles facing +Y) with the UVs given
quad() { # FILE UVS [SIDE]
    local s=${3:-1}
    write_gltf "$1" floor_mesh floor "0 0 0  0 0 $s  $s 0 $s   0 0 0  $s 0 $s  $s 0 0" "$2"
}
GOOD_UV="0 0  0 1  1 1   0 0  1 1  1 0"
OFF_UV="1 0  1 1  2 1   1 0  2 1  2 0"
quad "$IN/good.gltf" "$GOOD_UV" || exit 1
quad "$IN/off.gltf" "$OFF_UV" || exit 1
# both triangles on the same UV triangle: everything they cover overlaps
quad "$IN/folded.gltf" "0 0  0 1  1 1   0 0  0 1  1 1" || exit 1
quad "$IN/tiny.gltf" "$GOOD_UV" 0.03125 || exit 1
quad "$IN/huge.gltf" "$GOOD_UV" 16384 || exit 1

warnings() { grep -c '^luxel: warning' "$ERR"; }
# how many texels of a PFM hold exactly 1.0 in every channel
ones() { od -An -tx4 -v -j "$(($(head -3 "$1" | wc -c)))" "$1" | tr -s ' ' '\n' | grep -c '^3f800000$'; }

# ---- nothing emits light -------------------------------------------------------

run "$LUXEL" bake "$IN/good.gltf" --resolution 16 --uv-set 0 -o "$WORK/out/dark"
expect_rc 1 "no lights, sky or ambient"
expect_error "no lights, sky or ambient" "good.gltf" "nothing emits light" "no lights" \
    "--lights" "--sky" "--ambient"
expect_no_output "no lights, sky or ambient" "$WORK/out/dark"

printf '{"lights": [{"type": "point", "position": [0, 1, 0], "intensity": 0}]}' \
    >"$IN/zero.json"
run "$LUXEL" bake "$IN/good.gltf" --resolution 16 --uv-set 0 --lights "$IN/zero.json" -o "$WORK/out/zero"
expect_rc 1 "only a zero-intensity light"
expect_error "only a zero-intensity light" "nothing emits light" "zero intensity" "--ambient"
expect_no_output "only a zero-intensity light" "$WORK/out/zero"

run "$LUXEL" bake "$IN/good.gltf" --resolution 16 --uv-set 0 --ambient 1,1,1 --format pfm -o "$WORK/out/lit"
expect_rc 0 "an ambient is light enough"
check "an ambient: no warning" test "$(warnings)" -eq 0
check "an ambient of 1 lux: all 256 texels hold 1 lux" test "$(ones "$WORK/out/lit/floor.pfm")" -eq 768

run "$LUXEL" bake "$IN/good.gltf" --resolution 16 --uv-set 0 --ambient 1,1,1 --strict -o "$WORK/out/strict_ok"
expect_rc 0 "--strict on a clean run"
check "--strict on a clean run: the lightmap is written" test -f "$WORK/out/strict_ok/floor.exr"

# ---- a spot cone typed in radians ------------------------------------------------

printf '{"lights": [{"type": "spot", "position": [0.5, 1, 0.5], "direction": [0, -1, 0],
  "inner_angle": 0.2, "outer_angle": 0.5, "intensity": 100, "name": "narrow"}]}' >"$IN/spot.json"
run "$LUXEL" bake "$IN/good.gltf" --resolution 16 --uv-set 0 --lights "$IN/spot.json" --ambient 0.1,0.1,0.1 -o "$WORK/out/spot"
expect_rc 0 "a 0.5 degree spot still bakes"
expect_stderr_has "a 0.5 degree spot: a warning naming it and the likely slip" \
    "^luxel: warning: .*spot light 'narrow' has a cone of 0.5 degrees.*radians typed as degrees"
check "a 0.5 degree spot: one warning" test "$(warnings)" -eq 1
run "$LUXEL" bake "$IN/good.gltf" --resolution 16 --uv-set 0 --lights "$IN/spot.json" --strict --ambient 1,1,1 \
    -o "$WORK/out/spot_strict"
expect_rc 1 "a 0.5 degree spot with --strict"
expect_error "a 0.5 degree spot with --strict" "good.gltf" "1 warning" "--strict"
expect_no_output "a 0.5 degree spot with --strict" "$WORK/out/spot_strict"
run "$LUXEL" info "$IN/good.gltf" --lights "$IN/spot.json"
expect_rc 0 "info with a 0.5 degree spot"
expect_stderr_has "info: the same warning" "^luxel: warning: .*'narrow'.*radians typed as degrees"

# ---- UVs one tile off ---------------------------------------------------------------

run "$LUXEL" bake "$IN/off.gltf" --resolution 16 --uv-set 0 --ambient 1,1,1 --format pfm -o "$WORK/out/off_auto"
expect_rc 0 "UVs one tile off, --unwrap auto"
expect_stderr_has "UVs one tile off: the warning says why and that luxel makes UVs" \
    "^luxel: warning: .*off\.gltf: 1 of 1 nodes have no usable .*outside \[0,1\] 1.*luxel makes"
check "UVs one tile off: said once, and nothing else" test "$(warnings)" -eq 1
check "UVs one tile off: the page is written" test -f "$WORK/out/off_auto/lightmap-0.pfm"
if [ -f "$WORK/out/off_auto/lightmap-0.pfm" ]; then
    lit=$(ones "$WORK/out/off_auto/lightmap-0.pfm")
    check "UVs one tile off: the page is not black ($lit channels at 1 lux)" test "$lit" -gt 0
fi
run "$LUXEL" bake "$IN/off.gltf" --resolution 16 --uv-set 0 --ambient 1,1,1 --unwrap never -o "$WORK/out/off_never"
expect_rc 1 "UVs one tile off, --unwrap never"
expect_error "UVs one tile off, --unwrap never" "off.gltf" "'floor'" "cover no texel" "outside [0,1]"
expect_no_output "UVs one tile off, --unwrap never" "$WORK/out/off_never"

# two triangles on one UV triangle: overlapping everywhere they cover
run "$LUXEL" bake "$IN/folded.gltf" --resolution 16 --uv-set 0 --ambient 1,1,1 -o "$WORK/out/folded"
expect_rc 0 "overlapping UVs, --unwrap auto"
expect_stderr_has "overlapping UVs: the warning counts the node as overlapping" \
    "^luxel: warning: .*folded\.gltf: 1 of 1 nodes have no usable .*overlapping 1.*luxel makes"
check "overlapping UVs: one warning" test "$(warnings)" -eq 1

# ---- units -----------------------------------------------------------------------

run "$LUXEL" bake "$IN/tiny.gltf" --resolution 16 --uv-set 0 --ambient 1,1,1 -o "$WORK/out/tiny"
expect_rc 0 "a 3 cm scene still bakes"
expect_stderr_has "a 3 cm scene: a warning with its bounds and a density" \
    "^luxel: warning: .*tiny\.gltf: the scene spans 0.0312 x 0 x 0.0312 m.*smaller than 5 cm.*units metres.*--texel-density [0-9]"
run "$LUXEL" bake "$IN/tiny.gltf" --resolution 16 --uv-set 0 --ambient 1,1,1 --strict -o "$WORK/out/tiny_strict"
expect_rc 1 "a 3 cm scene with --strict"
expect_error "a 3 cm scene with --strict" "tiny.gltf" "--strict"
expect_no_output "a 3 cm scene with --strict" "$WORK/out/tiny_strict"

run "$LUXEL" bake "$IN/huge.gltf" --resolution 16 --uv-set 0 --ambient 1,1,1 -o "$WORK/out/huge"
expect_rc 0 "a 16 km scene still bakes"
expect_stderr_has "a 16 km scene: a warning with its bounds" \
    "^luxel: warning: .*huge\.gltf: the scene spans 1.64e\+04 x 0 x 1.64e\+04 m.*larger than 10 km"

# 1 m^2 at 2 texels/m: 2 x 2 texels; 8 texels/m would give it 8 x 8
run "$LUXEL" bake "$IN/good.gltf" --texel-density 2 --uv-set 0 --ambient 1,1,1 -o "$WORK/out/sparse"
expect_rc 0 "2 texels/m on a 1 m floor still bakes"
expect_stderr_has "2 texels/m: a warning naming the node, its texels and a density" \
    "^luxel: warning: .*at 2 texels/m node 'floor' gets about 2 x 2 texels \(1 node under 8x8\).*--texel-density 8 "

# ---- luxel info: UV health ---------------------------------------------------------

run "$LUXEL" info "$IN/off.gltf"
expect_rc 0 "info on UVs one tile off"
expect_stdout_has "info: the off-tile set's range and why it is not usable" \
    "floor_mesh +TEXCOORD_0 +u 1\.\.2 +v 0\.\.1 +overlap 0% +zero-area 0 +flipped 0 +not usable: outside \[0,1\]"
run "$LUXEL" info "$IN/good.gltf"
expect_stdout_has "info: a clean set is usable" \
    "floor_mesh +TEXCOORD_0 +u 0\.\.1 +v 0\.\.1 +overlap 0% +zero-area 0 +flipped 0 +usable"
run "$LUXEL" info "$IN/folded.gltf" --resolution 8
expect_stdout_has "info: two triangles on one: every covered texel overlapped" \
    "overlaps at 8x8 texels"
expect_stdout_has "info: two triangles on one: 100% overlap, not usable" \
    "floor_mesh +TEXCOORD_0 .*overlap 100% .*not usable: overlaps on 100% of its texels"

# a zero-area triangle in space: info drops it with a warning and goes on;
# --strict refuses the file
write_gltf "$IN/sliver.gltf" sliver_mesh sliver_node \
    "0 0 0  0 0 1  1 0 1   0 0 0  0.5 0 0.5  1 0 1" \
    "0 0  0 1  1 1   0 0  0.5 0.5  1 1" || exit 1
run "$LUXEL" info "$IN/sliver.gltf"
expect_rc 0 "info on a zero-area triangle"
expect_stderr_has "info on a zero-area triangle: a warning" "^luxel: warning: .*sliver"
expect_stdout_has "info on a zero-area triangle: the mesh is listed" "sliver_mesh"
run "$LUXEL" info "$IN/sliver.gltf" --strict
expect_rc 1 "info --strict on a zero-area triangle"
expect_error "info --strict on a zero-area triangle" "sliver.gltf" "zero-area triangles"

finish
