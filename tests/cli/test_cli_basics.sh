# End-to-end tests of the luxel command line: help, version, usage errors
# (exit status 2) and `luxel info` on the example room. Expected scene
# facts come from the generator's own description (examples/gen_scenes.c):
# the room spans x -2..2, y 0..3, z -2..2; "ceiling_lamp" is a 150 cd point
# light with a 12 m range; "spot" a 400 cd spot with cone 0.35..0.6 rad
# (20.05..34.38 degrees); retro.glb's "sun" is a 10000 lux directional light.
#
# usage: bash test_cli_basics.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
RETRO=$WORK/scenes/retro.glb

# ---- help and version ------------------------------------------------------

for args in "--help" "-h"; do
    run "$LUXEL" $args
    expect_rc 0 "luxel $args"
    expect_stdout_has "luxel $args: usage on stdout" '^usage: luxel <command>'
    expect_stdout_has "luxel $args: lists bake" '^ +bake SCENE'
    expect_stdout_has "luxel $args: lists info" '^ +info SCENE'
    check "luxel $args: nothing on stderr" test ! -s "$ERR"
done

run "$LUXEL" bake --help
expect_rc 0 "luxel bake --help"
expect_stdout_has "bake --help: usage on stdout" '^usage: luxel bake SCENE'
for opt in --output --resolution --texel-density --max-resolution --lights --format \
    --quantity --threads --skip-degenerate --quiet; do
    expect_stdout_has "bake --help documents $opt" -- "$opt"
done
check "bake --help: nothing on stderr" test ! -s "$ERR"

run "$LUXEL" bake -h
expect_rc 0 "luxel bake -h"
expect_stdout_has "bake -h: usage on stdout" '^usage: luxel bake'

run "$LUXEL" info --help
expect_rc 0 "luxel info --help"
expect_stdout_has "info --help: usage on stdout" '^usage: luxel info SCENE'
expect_stdout_has "info --help documents --lights" '--lights'
check "info --help: nothing on stderr" test ! -s "$ERR"

# --help wins over a bad scene: nothing is loaded
run "$LUXEL" bake "$WORK/no_such.glb" --help
expect_rc 0 "bake MISSING --help"

run "$LUXEL" --version
expect_rc 0 "luxel --version"
check "--version prints exactly 'luxel 0.1.0'" test "$(cat "$OUT")" = "luxel 0.1.0"

# ---- usage errors: exit 2, one error line -------------------------------------

mkdir "$WORK/cwd" && cd "$WORK/cwd" || exit 1 # default output ./lightmaps lands here

run "$LUXEL"
expect_rc 2 "luxel without a command"
expect_stderr_has "luxel without a command: usage on stderr" '^usage: luxel'
check "luxel without a command: nothing on stdout" test ! -s "$OUT"

run "$LUXEL" frobnicate "$ROOM"
expect_rc 2 "unknown command"
expect_error "unknown command" "frobnicate"
check "unknown command: nothing on stdout" test ! -s "$OUT"

run "$LUXEL" --frobnicate
expect_rc 2 "unknown top-level option"
expect_error "unknown top-level option" "--frobnicate"

run "$LUXEL" bake "$ROOM" --frobnicate
expect_rc 2 "bake: unknown option"
expect_error "bake: unknown option" "--frobnicate"

run "$LUXEL" bake --frobnicate "$ROOM"
expect_rc 2 "bake: unknown option before the scene"
expect_error "bake: unknown option before the scene" "--frobnicate"

run "$LUXEL" bake "$ROOM" -Z
expect_rc 2 "bake: unknown short option"
expect_error "bake: unknown short option" "-Z"

run "$LUXEL" info "$ROOM" --frobnicate
expect_rc 2 "info: unknown option"
expect_error "info: unknown option" "--frobnicate"

run "$LUXEL" bake
expect_rc 2 "bake without a scene"
expect_error "bake without a scene" "scene"

run "$LUXEL" bake --resolution 64
expect_rc 2 "bake with options but no scene"
expect_error "bake with options but no scene" "scene"

run "$LUXEL" info
expect_rc 2 "info without a scene"
expect_error "info without a scene" "scene"

run "$LUXEL" bake "$ROOM" "$RETRO"
expect_rc 2 "bake with two scenes"
expect_error "bake with two scenes" "retro.glb"

run "$LUXEL" bake "$ROOM" --resolution
expect_rc 2 "bake: --resolution without a value"
expect_error "bake: --resolution without a value" "--resolution"

for bad in 0 -4 abc 12x 1e3 99999 16385; do
    run "$LUXEL" bake "$ROOM" --resolution "$bad"
    expect_rc 2 "--resolution $bad"
    expect_error "--resolution $bad" "--resolution" "'$bad'"
done
for opt in "--format tiff" "--quantity luminance" "--threads 0" "--texel-density 0" \
    "--texel-density nan" "--max-resolution 2" "--ambient 1,2" "--ambient 1,-1,0" \
    "--padding 65" "--exposure inf" "--half --format pfm"; do
    run "$LUXEL" bake "$ROOM" $opt
    expect_rc 2 "bake $opt"
    expect_error "bake $opt" "${opt%% *}"
done
check "usage errors wrote nothing in the working folder" test -z "$(ls -A "$WORK/cwd")"
cd "$WORK" || exit 1

# ---- luxel info --------------------------------------------------------------

run "$LUXEL" info "$ROOM"
expect_rc 0 "info room.glb"
check "info room.glb: nothing on stderr" test ! -s "$ERR"
expect_stdout_has "info names the scene" "room\.glb"
expect_stdout_has "info: meshes section" '^meshes: [0-9]+'
expect_stdout_has "info: mesh tall_box, 12 triangles" '^ +tall_box +12 triangles'
expect_stdout_has "info: mesh short_box, 12 triangles" '^ +short_box +12 triangles'
expect_stdout_has "info: room meshes have TEXCOORD_1" '^ +room.*TEXCOORD_1'
expect_stdout_has "info: materials section" '^materials: [0-9]+'
expect_stdout_has "info: red wall colour" "^ +red +base colour \(0\.63, 0\.065, 0\.05\)"
expect_stdout_has "info: three nodes" '^nodes: 3$'
expect_stdout_has "info: node room" '^ +room +at \(0, 0, 0\)'
expect_stdout_has "info: node tall_box at (-0.7, 0, -0.6)" '^ +tall_box +at \(-0\.7, 0, -0\.6\)'
expect_stdout_has "info: node short_box at (0.8, 0, 0.7)" '^ +short_box +at \(0\.8, 0, 0\.7\)'
expect_stdout_has "info: two lights" '^lights: 2$'
expect_stdout_has "info: ceiling_lamp 150 cd point light" \
    '^ +point +ceiling_lamp +150 cd .*at \(0, 2\.7, 0\).*range 12 m'
expect_stdout_has "info: spot 400 cd, cone 20.1..34.4 deg" \
    '^ +spot +spot +400 cd .*at \(1\.5, 2\.8, 1\.5\).*cone 20\.1\.\.34\.4 deg.*range 15 m'
expect_stdout_has "info: bounds (-2,0,-2)..(2,3,2) m" \
    '^bounds: \(-2, 0, -2\) \.\. \(2, 3, 2\) m'
# 5 room faces (2 triangles each) + 2 boxes of 6 faces
expect_stdout_has "info: 34 triangles in all" '34 triangles$'

run "$LUXEL" info "$RETRO"
expect_rc 0 "info retro.glb"
expect_stdout_has "info retro: eight nodes" '^nodes: 8$'
expect_stdout_has "info retro: the sun is directional, in lux" '^ +directional +sun .* lx '
expect_stdout_has "info retro: torches in cd" '^ +point +torch_a +60 cd'

run "$LUXEL" info "$WORK/no_such.glb"
expect_rc 1 "info on a missing file"
expect_error "info on a missing file" "no_such.glb"
check "info on a missing file: nothing on stdout" test ! -s "$OUT"

finish
