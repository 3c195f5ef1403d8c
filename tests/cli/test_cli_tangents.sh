# cases: run usage bad validate
# End-to-end tests of `luxel tangents SCENE -o OUT.glb`: the output is read
# back by `luxel info`, its triangles (corner positions, in order) and
# attribute names are compared with the input's by glb_triangles.js (a
# reader of its own), and the Khronos glTF-Validator (npm gltf-validator in
# BUILD/oracles) must report no error. Cases needing node skip without it.
#
# usage: bash test_cli_tangents.sh LUXEL GEN_SCENES WORKDIR CASE
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
RETRO=$WORK/scenes/retro.glb
IN=$WORK/in
OUTD=$WORK/out
mkdir -p "$IN" "$OUTD"
no_match() { ! grep -Eq -- "$1" "$2"; }
HERE=$(abspath "$(dirname "${BASH_SOURCE[0]}")")
VALIDATE_JS=$HERE/../common/gltf_validate.js
TRIS_JS=$HERE/glb_triangles.js
ORACLES=$(dirname "$(dirname "$LUXEL_REAL")")/oracles

# a quad strip whose UVs are mirrored at x = 0 (one vertex row shared by
# both halves: its corners need two frames), with normals and UVs
cat >"$IN/mirror.obj" <<'OBJ'
o mirror
v -1 0 0
v 0 0 0
v 1 0 0
v -1 1 0
v 0 1 0
v 1 1 0
vt 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vt 1 1
vn 0 0 1
f 1/1/1 2/2/1 5/5/1
f 1/1/1 5/5/1 4/4/1
f 2/2/1 3/3/1 6/6/1
f 2/2/1 6/6/1 5/5/1
o bare
v 3 0 0
v 4 0 0
v 4 1 0
f 7 8 9
OBJ

case $CASE_NAME in
run)
    run "$LUXEL" tangents "$ROOM" -o "$OUTD/room.glb"
    expect_rc 0 "tangents room.glb"
    expect_stdout_has "one-line summary" "room.glb: tangents \(mikktspace\) for [0-9]+ primitives"
    run "$LUXEL" info "$OUTD/room.glb"
    expect_rc 0 "luxel info reads the output"
    run "$LUXEL" tangents "$RETRO" -o "$OUTD/retro.glb" --method lengyel
    expect_rc 0 "tangents --method lengyel"
    expect_stdout_has "the method is named" "\(lengyel\)"
    run "$LUXEL" tangents "$IN/mirror.obj" -o "$OUTD/mirror.glb"
    expect_rc 0 "tangents of an OBJ"
    expect_stdout_has "the mirror line's vertices are split" "for 1 primitive, 2 vertices added"
    expect_stderr_has "the bare mesh is counted in a warning" "1 primitive without normals or UVs"
    run "$LUXEL" tangents "$OUTD/room.glb" -o "$OUTD/again.glb"
    expect_rc 0 "tangents of a file with tangents"
    expect_stderr_has "replaced tangents are reported" "had tangents; replaced"
    if command -v node >/dev/null; then
        for f in room retro; do
            src=$WORK/scenes/$f.glb
            node "$TRIS_JS" "$src" TANGENT >"$OUTD/$f.in.txt"
            node "$TRIS_JS" "$OUTD/$f.glb" TANGENT >"$OUTD/$f.out.txt"
            check "$f: triangles in order, other attributes kept" cmp -s "$OUTD/$f.in.txt" "$OUTD/$f.out.txt"
            check "$f: every primitive has TANGENT" test "$(node "$TRIS_JS" "$OUTD/$f.glb" | grep -vc TANGENT)" = 0
        done
    else
        skip "node is not installed: triangle order not checked"
    fi
    ;;
usage)
    run "$LUXEL" tangents --help
    expect_rc 0 "--help"
    expect_stdout_has "--help shows the usage" "usage: luxel tangents SCENE -o OUT.glb"
    run "$LUXEL" tangents "$ROOM" -o "$OUTD/a.gltf"
    expect_rc 2 "an output not named .glb"
    run "$LUXEL" tangents "$ROOM" -o "$OUTD/a.glb" --method mikk
    expect_rc 2 "an unknown method"
    expect_error "an unknown method" "--method" "mikk"
    run "$LUXEL" tangents "$ROOM" -o "$OUTD/a.glb" --uv-set 9
    expect_rc 2 "--uv-set out of range"
    run "$LUXEL" tangents "$ROOM"
    expect_rc 2 "no -o"
    check "no output after usage errors" test -z "$(ls -A "$OUTD")"
    ;;
bad)
    run "$LUXEL" tangents "$IN/missing.glb" -o "$OUTD/m.glb"
    expect_rc 1 "a missing scene"
    expect_error "a missing scene" "missing.glb"
    printf 'glTF\002\000\000\000\377\000\000\000' >"$IN/cut.glb"
    run "$LUXEL" tangents "$IN/cut.glb" -o "$OUTD/c.glb"
    expect_rc 1 "a truncated GLB"
    expect_error "a truncated GLB" "cut.glb"
    run "$LUXEL" tangents "$ROOM" -o "$OUTD/no/such/dir/r.glb"
    expect_rc 1 "an output folder that does not exist"
    check "nothing left in the output folder" test -z "$(ls -A "$OUTD")"
    ;;
validate)
    if ! command -v node >/dev/null; then
        skip "node is not installed"
    else
        run "$LUXEL" tangents "$ROOM" -o "$OUTD/room.glb"
        run "$LUXEL" tangents "$RETRO" -o "$OUTD/retro.glb"
        run "$LUXEL" tangents "$IN/mirror.obj" -o "$OUTD/mirror.glb"
        run "$LUXEL" unwrap "$ROOM" -o "$OUTD/room_uv.glb" --texel-density 8
        for f in room.glb retro.glb mirror.glb room_uv.glb; do
            run node "$VALIDATE_JS" "$ORACLES" "$OUTD/$f"
            if [ "$RC" -eq 77 ]; then
                skip "glTF-Validator on $f: not installed (scripts/install-test-oracles.sh)"
            elif [ "$RC" -eq 0 ]; then
                pass "glTF-Validator: no error in $f"
            else
                fail "glTF-Validator reports errors in $f" "$(head -5 "$OUT")"
            fi
        done
        # the rewrite leaves no accessor or bufferView unused
        LX_VALIDATE_VERBOSE=1 node "$VALIDATE_JS" "$ORACLES" "$OUTD/room_uv.glb" "$OUTD/room.glb" >"$OUTD/v.txt" 2>&1
        check "no unused accessors or bufferViews" no_match "UNUSED_OBJECT /(accessors|bufferViews)" "$OUTD/v.txt"
    fi
    ;;
*)
    fail "unknown case '$CASE_NAME'"
    ;;
esac

finish
