# End-to-end tests of `luxel bake` / `luxel info` on bad input: missing,
# unreadable and corrupt files,
# non-finite coordinates, zero-area triangles in space and in UV, overlapping
# lightmap UVs, impossible resolutions and memory requests, unknown options
# and malformed lights JSON. Every failure must exit with the exact status
# (1 failed run, 2 usage error), print exactly one "luxel: error:" line that
# names the file (or, for usage errors, the option) and the problem, and
# leave no file behind.
#
# Inputs are written here: scenes by gen_scenes, OBJ and glTF by heredoc and
# printf (tests/cli/common.sh), corrupt files with head -c.
#
# usage: bash test_cli_bad_input.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
RETRO=$WORK/scenes/retro.glb
IN=$WORK/in
mkdir -p "$IN" "$WORK/out" "$WORK/cwd"
cd "$WORK/cwd" || exit 1 # the default output folder (./lightmaps) would land here

CASE=0
# bad LABEL STATUS "NEEDLE|NEEDLE..." ARGS...: `luxel ARGS -o DIR` must exit
# with STATUS, print one error line holding every needle and leave DIR
# missing (or empty when PRECREATE made it first).
bad() {
    local label=$1 status=$2 needles=$3
    shift 3
    CASE=$((CASE + 1))
    local out=$WORK/out/case$CASE
    [ -n "${PRECREATE:-}" ] && mkdir -p "$out" # an existing, empty folder stays empty
    run "$LUXEL" "$@" -o "$out"
    expect_rc "$status" "$label"
    local list=()
    IFS='|' read -ra list <<<"$needles"
    expect_error "$label" "${list[@]}"
    expect_no_output "$label" "$out" ${PRECREATE:+existed}
}

# bad_info LABEL "NEEDLE|..." SCENE: `luxel info` fails with status 1, one
# error line and nothing on stdout.
bad_info() {
    local label=$1 needles=$2
    shift 2
    run "$LUXEL" info "$@"
    expect_rc 1 "info: $label"
    local list=()
    IFS='|' read -ra list <<<"$needles"
    expect_error "info: $label" "${list[@]}"
    check "info: $label: nothing on stdout" test ! -s "$OUT"
}

# ---- files that cannot be read -------------------------------------------------

bad "missing file" 1 "missing.glb" bake "$IN/missing.glb"
bad_info "missing file" "missing.glb" "$IN/missing.glb"
bad "missing .obj" 1 "gone.obj" bake "$IN/gone.obj"
PRECREATE=1 bad "missing file, -o folder already there" 1 "missing.glb" bake "$IN/missing.glb"

mkdir "$IN/folder.glb"
bad "a directory named like a scene" 1 "folder.glb" bake "$IN/folder.glb"
bad_info "a directory" "folder.glb" "$IN/folder.glb"

cp "$ROOM" "$IN/locked.glb"
chmod 000 "$IN/locked.glb"
if [ "$(id -u)" -eq 0 ]; then
    # root reads anything: read it as an unprivileged user instead, from a
    # copy of the binary and the file in a place that user can reach
    # (as_user_setup, common.sh)
    priv=$(mktemp -d /tmp/luxel-unreadable.XXXXXX)
    if as_user_setup "$priv"; then
        cp "$ROOM" "$priv/locked.glb" && chmod 000 "$priv/locked.glb"
        # an output folder that user may write in: the input is what fails
        mkdir "$priv/w" && chmod 777 "$priv/w"
        run "$priv/as_user" bake "$priv/locked.glb" --bounces 0 -o "$priv/w/out"
        expect_rc 1 "unreadable file (mode 000, read by an unprivileged user)"
        expect_error "unreadable file (mode 000)" "locked.glb" "cannot open"
        check "unreadable file (mode 000): no output" test -z "$(ls -A "$priv/w")"
        run "$priv/as_user" info "$priv/locked.glb"
        expect_rc 1 "info: unreadable file (mode 000, read by an unprivileged user)"
        expect_error "info: unreadable file (mode 000)" "locked.glb" "cannot open"
    else
        skip "unreadable file (mode 000): cannot run luxel as an unprivileged user (setpriv)"
    fi
    rm -rf "$priv"
else
    bad "unreadable file (mode 000)" 1 "locked.glb" bake "$IN/locked.glb"
    bad_info "unreadable file" "locked.glb" "$IN/locked.glb"
fi
chmod 644 "$IN/locked.glb"

# ---- corrupt and truncated files ------------------------------------------------

# formats luxel does not read are refused by name before assimp sees them
# (assimp sniffs the bytes, and its OpenGEX reader overruns a buffer on
# these 20 bytes)
for name in scene.ogex scene.txt scene; do
    printf 'vertexarray (attrib)' >"$IN/$name"
    bad "a '$name' file" 1 "$name|not a scene luxel reads" bake "$IN/$name"
    bad_info "a '$name' file" "$name" "$IN/$name"
done
# formats assimp reads besides glTF and OBJ go to their own readers by name
for name in scene.fbx scene.dae scene.ply scene.stl; do
    printf 'vertexarray (attrib)' >"$IN/$name"
    bad "a garbage '$name' file" 1 "$name|cannot import" bake "$IN/$name"
done

head -c 6000 /dev/urandom >"$IN/noise.glb"
bad "random bytes named .glb" 1 "noise.glb" bake "$IN/noise.glb"
bad_info "random bytes" "noise.glb" "$IN/noise.glb"
cp "$IN/noise.glb" "$IN/noise.obj"
bad "random bytes named .obj" 1 "noise.obj" bake "$IN/noise.obj"

size=$(stat -c %s "$ROOM")
head -c $((size / 2)) "$ROOM" >"$IN/half.glb"
bad "room.glb cut at half its size" 1 "half.glb" bake "$IN/half.glb"
bad_info "room.glb cut at half" "half.glb" "$IN/half.glb"
head -c $((size - 1)) "$ROOM" >"$IN/short.glb"
bad "room.glb one byte short" 1 "short.glb" bake "$IN/short.glb"
head -c 12 "$ROOM" >"$IN/header.glb"
bad "room.glb's 12-byte header alone" 1 "header.glb" bake "$IN/header.glb"
: >"$IN/empty.glb"
bad "empty .glb" 1 "empty.glb" bake "$IN/empty.glb"
: >"$IN/empty.obj"
bad "empty .obj" 1 "empty.obj" bake "$IN/empty.obj"

cat >"$IN/broken.gltf" <<'EOF'
{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
 "nodes": [{"name": "n", "mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POS
EOF
bad "a .gltf with broken JSON" 1 "broken.gltf" bake "$IN/broken.gltf"
bad_info "a .gltf with broken JSON" "broken.gltf" "$IN/broken.gltf"

printf '{}' >"$IN/not_gltf.gltf"
bad "a .gltf that is JSON but not glTF" 1 "not_gltf.gltf" bake "$IN/not_gltf.gltf"

write_gltf "$IN/nobin.gltf" quad quad "0 0 0  0 0 1  1 0 1" "0 0  0 1  1 1" || exit 1
rm "$IN/nobin.bin"
bad "a .gltf whose .bin is missing" 1 "nobin" bake "$IN/nobin.gltf"

# ---- non-finite coordinates ---------------------------------------------------------

for v in nan inf -inf 1e39; do
    cat >"$IN/v_$v.obj" <<EOF
o tri
v $v 0 0
v 1 0 0
v 0 0 1
vt 0 0
vt 1 0
vt 0 1
f 1/1 2/2 3/3
EOF
    bad "OBJ with 'v $v 0 0'" 1 "v_$v.obj|not finite|tri" bake "$IN/v_$v.obj"
    bad "OBJ with 'v $v 0 0' and --skip-degenerate" 1 "v_$v.obj|not finite" \
        bake "$IN/v_$v.obj" --skip-degenerate
done
bad_info "OBJ with a NaN position" "v_nan.obj|not finite" "$IN/v_nan.obj"

write_gltf "$IN/nan_pos.gltf" nan_mesh nan_node "0 0 0  0 nan 1  1 0 1" "0 0  0 1  1 1" || exit 1
bad "glTF with a NaN position" 1 "nan_pos.gltf|not finite|nan_mesh" bake "$IN/nan_pos.gltf"
write_gltf "$IN/inf_uv.gltf" inf_mesh inf_node "0 0 0  0 0 1  1 0 1" "0 0  inf 1  1 1" || exit 1
bad "glTF with an infinite UV" 1 "inf_uv.gltf|not finite|inf_mesh" bake "$IN/inf_uv.gltf"

cat >"$IN/vt_nan.obj" <<'EOF'
o tri
v 0 0 0
v 1 0 0
v 0 0 1
vt 0 0
vt 1 nan
vt 0 1
f 1/1 2/2 3/3
EOF
bad "OBJ with 'vt 1 nan'" 1 "vt_nan.obj|not finite" bake "$IN/vt_nan.obj"

# ---- zero-area triangles -------------------------------------------------------------

# two good triangles and a third through three collinear points
cat >"$IN/sliver.obj" <<'EOF'
o floor
v 0 0 0
v 0 0 1
v 1 0 1
v 1 0 0
v 2 0 2
vt 0 0
vt 0 1
vt 1 1
vt 1 0
vt 0.5 0.5
f 1/1 2/2 3/3
f 1/1 3/3 4/4
f 1/1 3/3 5/5
EOF
# dropped by default, with one warning per load that counts them
run "$LUXEL" bake "$IN/sliver.obj" --ambient 1,1,1 --resolution 32 -o "$WORK/out/sliver_ok"
expect_rc 0 "the zero-area OBJ bakes"
expect_stderr_has "zero-area OBJ: a warning naming the file and the count" \
    "^luxel: warning: .*sliver\.obj: 1 zero-area triangles left out"
check "zero-area OBJ: no error line" test -z "$(grep '^luxel: error' "$ERR")"
check "zero-area OBJ: the lightmap is written" test -f "$WORK/out/sliver_ok/floor.exr"
run "$LUXEL" info "$IN/sliver.obj"
expect_rc 0 "info: the zero-area OBJ loads"
# --skip-degenerate is still accepted (it is the default)
run "$LUXEL" bake "$IN/sliver.obj" --ambient 1,1,1 --resolution 32 --skip-degenerate -o "$WORK/out/sliver_ok2"
expect_rc 0 "--skip-degenerate is accepted"

write_gltf "$IN/sliver.gltf" sliver_mesh sliver_node \
    "0 0 0  0 0 1  1 0 1   0 0 0  0.5 0 0.5  1 0 1" \
    "0 0  0 1  1 1   0 0  0.5 0.5  1 1" || exit 1
run "$LUXEL" bake "$IN/sliver.gltf" --ambient 1,1,1 --resolution 32 -o "$WORK/out/gsliver_ok"
expect_rc 0 "the zero-area glTF bakes"
expect_stderr_has "zero-area glTF: a warning with the count" \
    "^luxel: warning: .*sliver\.gltf: 1 zero-area triangles left out"

# a triangle whose three UVs are the same point: zero area in UV
cat >"$IN/flat_uv.obj" <<'EOF'
o floor
v 0 0 0
v 0 0 1
v 1 0 1
v 1 0 0
vt 0.125 0.875
vt 0.125 0.125
vt 0.875 0.125
vt 0.5 0.5
f 1/1 2/2 3/3
f 1/4 3/4 4/4
EOF
# by default luxel makes the node's UVs instead, and says so once
run "$LUXEL" bake "$IN/flat_uv.obj" --ambient 1,1,1 --resolution 32 -o "$WORK/out/flat_auto"
expect_rc 0 "a zero-UV-area OBJ bakes on luxel's UVs"
expect_stderr_has "a zero-UV-area OBJ: one warning says luxel makes the UVs" \
    "^luxel: warning: .*flat_uv\.obj: 1 of 1 nodes have no usable .*zero-area triangles 1.*luxel makes"
check "a zero-UV-area OBJ: the atlas page is written" test -f "$WORK/out/flat_auto/lightmap-0.exr"
# the file's UVs kept (--unwrap never): the triangle is left out with a warning
run "$LUXEL" bake "$IN/flat_uv.obj" --ambient 1,1,1 --resolution 32 --unwrap never -o "$WORK/out/flat_ok"
expect_rc 0 "the zero-UV-area OBJ bakes on its own UVs"
expect_stderr_has "a warning about the zero-UV-area triangle" \
    "^luxel: warning: .*flat_uv\.obj.*'floor'.*1 .*zero UV area"
check "zero UV area: the lightmap is written" test -f "$WORK/out/flat_ok/floor.exr"

# ---- overlapping lightmap UVs: a warning, not an error -------------------------------

# Both triangles of a quad mapped onto the same UV triangle A (1/8, 1/8),
# B (1/8, 3/4), C (7/8, 1/8) (luxel's top-left origin). At 30x30 no texel
# centre lies on an edge, so the overlap is every texel whose centre is
# inside ABC. Counted here with integer edge functions in units of 1/480
# (texel centre x + 1/2 is 16x + 8).
count_inside() { # AX AY BX BY CX CY
    local ax=$1 ay=$2 bx=$3 by=$4 cx=$5 cy=$6 n=0 x y px py e1 e2 e3
    for ((y = 0; y < 30; y++)); do
        for ((x = 0; x < 30; x++)); do
            px=$((16 * x + 8)) py=$((16 * y + 8))
            e1=$(((bx - ax) * (py - ay) - (by - ay) * (px - ax)))
            e2=$(((cx - bx) * (py - by) - (cy - by) * (px - bx)))
            e3=$(((ax - cx) * (py - cy) - (ay - cy) * (px - cx)))
            if { [ $e1 -gt 0 ] && [ $e2 -gt 0 ] && [ $e3 -gt 0 ]; } ||
                { [ $e1 -lt 0 ] && [ $e2 -lt 0 ] && [ $e3 -lt 0 ]; }; then
                n=$((n + 1))
            fi
        done
    done
    echo $n
}
OVERLAP=$(count_inside 60 60 60 360 420 60)

# OBJ: V bottom-up, so vt v = 1 - v
cat >"$IN/overlap.obj" <<'EOF'
o floor
v 0 0 0
v 0 0 1
v 1 0 1
v 1 0 0
vt 0.125 0.875
vt 0.125 0.25
vt 0.875 0.875
f 1/1 2/2 3/3
f 1/1 3/2 4/3
EOF
run "$LUXEL" bake "$IN/overlap.obj" --ambient 1,1,1 --resolution 30 --unwrap never -o "$WORK/out/overlap_obj"
expect_rc 0 "overlapping UVs (OBJ) still bake"
check "overlapping UVs (OBJ): no error line" test -z "$(grep '^luxel: error' "$ERR")"
expect_stderr_has "overlapping UVs (OBJ): a warning with the count, $OVERLAP texels" \
    "^luxel: warning: .*overlap\.obj.* $OVERLAP texels .*overlapping"
expect_stderr_has "overlapping UVs (OBJ): the warning names the mesh 'floor'" \
    "^luxel: warning: .*floor.*overlapping"
check "overlapping UVs (OBJ): the manifest records $OVERLAP overlapping texels" \
    grep -Eq "\"overlap_texels\":[[:space:]]*$OVERLAP\b" "$WORK/out/overlap_obj/manifest.json"

write_gltf "$IN/overlap.gltf" shared_mesh shared_node \
    "0 0 0  0 0 1  1 0 1   0 0 0  1 0 1  1 0 0" \
    "0.125 0.125  0.125 0.75  0.875 0.125   0.125 0.125  0.125 0.75  0.875 0.125" || exit 1
run "$LUXEL" bake "$IN/overlap.gltf" --ambient 1,1,1 --resolution 30 --unwrap never -o "$WORK/out/overlap_gltf"
expect_rc 0 "overlapping UVs (glTF) still bake"
check "overlapping UVs (glTF): the lightmap is written" \
    test -f "$WORK/out/overlap_gltf/shared_node.exr"
expect_stderr_has "overlapping UVs (glTF): a warning with the count, $OVERLAP texels" \
    "^luxel: warning: .*overlap\.gltf.* $OVERLAP texels .*overlapping"
expect_stderr_has "overlapping UVs (glTF): the warning names the mesh 'shared_mesh'" \
    "^luxel: warning: .*shared_mesh.*overlapping"

# ---- nothing to bake ----------------------------------------------------------------------

printf 'o bare\nv 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n' >"$IN/no_uv.obj"
bad "an OBJ without texture coordinates, --unwrap never" 1 "no_uv.obj" \
    bake "$IN/no_uv.obj" --ambient 1,1,1 --unwrap never
run "$LUXEL" bake "$IN/no_uv.obj" --ambient 1,1,1 -o "$WORK/out/no_uv_auto"
expect_rc 0 "an OBJ without texture coordinates bakes on luxel's UVs"
check "an OBJ without texture coordinates: its atlas page is written" \
    test -f "$WORK/out/no_uv_auto/lightmap-0.exr"

cat >"$IN/lights_only.gltf" <<'EOF'
{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
 "nodes": [{"name": "lamp", "translation": [0, 2, 0],
            "extensions": {"KHR_lights_punctual": {"light": 0}}}],
 "extensionsUsed": ["KHR_lights_punctual"],
 "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5}]}}}
EOF
bad "a glTF with lights but no meshes" 1 "lights_only.gltf" bake "$IN/lights_only.gltf"

# ---- resolutions and memory -------------------------------------------------------------

bad "--resolution 0" 2 "--resolution|'0'" bake "$ROOM" --resolution 0
bad "--resolution 99999" 2 "--resolution|'99999'" bake "$ROOM" --resolution 99999
bad "--resolution -1" 2 "--resolution|'-1'" bake "$ROOM" --resolution -1
bad "--max-resolution 99999" 2 "--max-resolution" bake "$ROOM" --texel-density 10 \
    --max-resolution 99999

# Requests too large for the machine's memory: tests/cli/test_cli_limits.sh
# (one CTest test per case, skipped where the machine has the memory).

# ---- options ---------------------------------------------------------------------------

bad "unknown option" 2 "--no-such-option" bake "$ROOM" --no-such-option
bad "unknown option with a value" 2 "--colour" bake "$ROOM" --colour=red
bad "--format given twice, second bad" 2 "--format|'gif'" bake "$ROOM" --format pfm --format gif

: >"$IN/plain_file"
run "$LUXEL" bake "$ROOM" --resolution 16 -o "$IN/plain_file/sub"
expect_rc 1 "-o below a regular file"
expect_error "-o below a regular file" "plain_file"
check "-o below a regular file: the file is untouched" test ! -s "$IN/plain_file"

# A failure while writing: tall_box.exr cannot be written because a folder
# of that name is in the way. The files already written for room must go
# again; the folder that was there before stays.
mkdir -p "$WORK/out/midway/tall_box.exr"
run "$LUXEL" bake "$ROOM" --resolution 16 -o "$WORK/out/midway"
expect_rc 1 "a write fails halfway"
expect_error "a write fails halfway" "tall_box.exr"
check "a write fails halfway: this run's files are removed, the old folder stays" \
    test "$(ls -A "$WORK/out/midway")" = "tall_box.exr"
check "a write fails halfway: no temporary file is left" \
    test -z "$(ls -A "$WORK/out/midway/tall_box.exr")"

# ---- malformed lights JSON ---------------------------------------------------------------

printf '{"lights": [\n  {"type": "point",, "position": [0, 1, 0], "intensity": 5}\n]}\n' \
    >"$IN/syntax.json"
PRECREATE=1 bad "lights JSON with a syntax error" 1 "syntax.json|line 2" \
    bake "$ROOM" --lights "$IN/syntax.json"
bad_info "lights JSON with a syntax error" "syntax.json|line 2" "$ROOM" --lights "$IN/syntax.json"

printf '{"lights": [{"type": "point", "position": [0, 1, 0], "intensity": 5,\n  "colour_temperature": 3000}]}\n' \
    >"$IN/unknown_key.json"
bad "lights JSON with an unknown key" 1 "unknown_key.json|colour_temperature" \
    bake "$ROOM" --lights "$IN/unknown_key.json"

printf '{"lights": [{"type": "point", "position": [0, 1, 0], "intensity": "bright"}]}\n' \
    >"$IN/wrong_type.json"
bad "lights JSON: intensity is a string" 1 "wrong_type.json|intensity" \
    bake "$ROOM" --lights "$IN/wrong_type.json"

printf '{"lights": [{"type": "point", "position": [0, 1, 0], "intensity": 1e999}]}\n' \
    >"$IN/huge.json"
bad "lights JSON: intensity 1e999" 1 "huge.json|intensity" bake "$ROOM" --lights "$IN/huge.json"

printf '{"lights": [{"type": "point", "position": [0, 1e999, 0], "intensity": 5}]}\n' \
    >"$IN/huge_pos.json"
bad "lights JSON: position 1e999" 1 "huge_pos.json|position" bake "$ROOM" --lights "$IN/huge_pos.json"

printf '{"lights": [{"type": "laser", "position": [0, 1, 0], "intensity": 5}]}\n' \
    >"$IN/bad_type.json"
bad "lights JSON: unknown light type" 1 "bad_type.json|type|laser" \
    bake "$ROOM" --lights "$IN/bad_type.json"

printf '{"materials": {"stone": {"height": "h.png"}}}\n' >"$IN/unknown_material.json"
bad "lights JSON: a material the scene does not have" 1 "unknown_material.json|stone" \
    bake "$ROOM" --lights "$IN/unknown_material.json"

printf '{"materials": {"red": {"height": "no_such_height.png", "strength": 4}}}\n' \
    >"$IN/missing_height.json"
bad "lights JSON: a material's height file is missing" 1 "no_such_height.png|red" \
    bake "$ROOM" --lights "$IN/missing_height.json"

printf '{"lights": [{"type": "point", "position": [0, 1], "intensity": 5}]}\n' >"$IN/short_vec.json"
bad "lights JSON: position with 2 numbers" 1 "short_vec.json|position" \
    bake "$ROOM" --lights "$IN/short_vec.json"

printf '{"ambient": [0.1, 0.1, 0.1], "lights": [{"type": "point", "position": [0, 1, 0], "intensity": -5}]}\n' \
    >"$IN/negative.json"
bad "lights JSON: negative intensity" 1 "negative.json|intensity" \
    bake "$ROOM" --lights "$IN/negative.json"

printf '' >"$IN/empty.json"
bad "empty lights JSON" 1 "empty.json" bake "$ROOM" --lights "$IN/empty.json"
bad "missing lights JSON" 1 "no_lights.json" bake "$ROOM" --lights "$IN/no_lights.json"
mkdir "$IN/folder.json"
bad "a folder as lights JSON" 1 "folder.json" bake "$ROOM" --lights "$IN/folder.json"

# ---- the sky ------------------------------------------------------------------

bad "--sky: missing environment" 1 "no_sky.hdr" bake "$ROOM" --sky "$IN/no_sky.hdr"
printf 'PF\n4 2\n-1.0\n' >"$IN/short.pfm"
head -c 40 /dev/zero >>"$IN/short.pfm"
bad "--sky: truncated PFM" 1 "short.pfm" bake "$ROOM" --sky "$IN/short.pfm"
# a 4 x 2 equirect with one NaN texel (0x7fc00000 little-endian)
{ printf 'PF\n4 2\n-1.0\n'; head -c 84 /dev/zero; printf '\000\000\300\177'; head -c 8 /dev/zero; } \
    >"$IN/nan_sky.pfm"
bad "--sky: NaN texel" 1 "nan_sky.pfm|NaN" bake "$ROOM" --sky "$IN/nan_sky.pfm"
printf 'PF\n6 2\n-1.0\n' >"$IN/wide.pfm"
head -c 144 /dev/zero >>"$IN/wide.pfm"
bad "--sky: 3:1 image" 1 "wide.pfm" bake "$ROOM" --sky "$IN/wide.pfm"
bad "--sky: bad constant" 2 "const:" bake "$ROOM" --sky const:bright
bad "--sky-shadows without a sky" 2 "--sky" bake "$ROOM" --sky-shadows
bad "--sky-samples 0" 2 "--sky-samples" bake "$ROOM" --sky const:1 --sky-shadows --sky-samples 0
bad "--sky-samples without sky shadows" 2 "--sky-samples needs sky shadows" \
    bake "$ROOM" --sky const:1 --sky-samples 8
bad "--sky-shadows and --no-sky-shadows" 2 "contradict" \
    bake "$ROOM" --sky const:1 --sky-shadows --no-sky-shadows
bad "--sky-intensity -1" 2 "--sky-intensity" bake "$ROOM" --sky const:1 --sky-intensity -1
printf '{"sky": {"environment": "nowhere.hdr"}}\n' >"$IN/sky_missing.json"
bad "lights JSON: sky file missing" 1 "nowhere.hdr" bake "$ROOM" --lights "$IN/sky_missing.json"
printf '{"sky": {"environment": "x.hdr", "samples": -3}}\n' >"$IN/sky_samples.json"
bad "lights JSON: sky samples" 1 "sky_samples.json|sky|samples" \
    bake "$ROOM" --lights "$IN/sky_samples.json"

check "no failing run wrote anything in the working folder" test -z "$(ls -A "$WORK/cwd")"
finish
