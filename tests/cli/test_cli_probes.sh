# End-to-end tests of `luxel probes`: the demo room's probes on a grid and
# at the points of a file (a point inside the tall box is "valid": false,
# the room's middle is lit), the JSON's layout (9 RGB coefficients a
# probe, the convention named), the same bytes for 1 and 2 threads, and
# every bad --grid / --points / --samples: exit status 2, one
# "luxel: error:" line naming the option or file, and no output written
# (an existing file keeps its bytes when a run fails).
#
# usage: bash test_cli_probes.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
BIN=$LUXEL_REAL

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
SMALL=(--resolution 24 --gi-samples 9 --samples 64 -q)

# ---- a grid ------------------------------------------------------------------
run "$BIN" probes "$ROOM" "${SMALL[@]}" --grid 2,3,2 -o "$WORK/grid/probes.json"
expect_rc 0 "probes on a 2x3x2 grid"
J=$WORK/grid/probes.json
check "12 probes" test "$(grep -c '"position":' "$J")" -eq 12
check "9 coefficients a probe (12 x 9 triples in the sh arrays)" \
    test "$(awk '/"sh":/ { n += gsub(/\[[^][]*\]/, "") } END { print n }' "$J")" -eq 108
check "radiance coefficients named" grep -Eq '"coefficients":[[:space:]]*"radiance"' "$J"
check "the grid's counts" grep -Eq '"counts":[[:space:]]*\[2, 3, 2\]' "$J"
check "cell centres named" grep -Eq '"placement":[[:space:]]*"cell centres"' "$J"
# the cell centres inside the boxes: the tall box (1.2 x 1.8 x 1.2 m at
# (-0.7, 0, -0.6), turned 18 degrees) holds (-1, 0.5, -1) and (-1, 1.5, -1),
# the short one (0.9 m at (0.8, 0, 0.7)) holds (1, 0.5, 1)
check "the three probes inside the boxes are invalid, the others valid" \
    test "$(awk '/"position":/ { p = $0; sub(/.*\[/, "", p); sub(/\].*/, "", p) }
                 /"valid":[[:space:]]*false/ { printf "%s;", p }' "$J")" = \
    "-1, 0.5, -1;-1, 1.5, -1;1, 0.5, 1;"
check "-q: nothing on stderr" test ! -s "$ERR"

# ---- points ------------------------------------------------------------------
printf '{"points": [[0, 1.5, 0], [-0.7, 0.5, -0.6]]}\n' >"$WORK/points.json"
run "$BIN" probes "$ROOM" "${SMALL[@]}" --points "$WORK/points.json" -o "$WORK/pts/p.json"
expect_rc 0 "probes at the points of a file"
P=$WORK/pts/p.json
check "2 probes" test "$(grep -c '"position":' "$P")" -eq 2
check "the point inside the tall box is invalid, the room's middle valid" \
    awk '/"valid":/ { v[++n] = $0 } END { exit !(n == 2 && v[1] ~ /true/ && v[2] ~ /false/) }' "$P"
# the room's middle is lit: its L00's red above 1 nit x 2 sqrt(pi)
check "the room's middle is lit" \
    awk '/"sh":/ { getline; gsub(/[][,]/, " "); exit !($1 > 3.5) }' "$P"

# ---- threads -------------------------------------------------------------------
run "$BIN" probes "$ROOM" "${SMALL[@]}" --grid 2,2,2 --threads 1 -o "$WORK/t1.json"
expect_rc 0 "--threads 1"
run "$BIN" probes "$ROOM" "${SMALL[@]}" --grid 2,2,2 --threads 2 -o "$WORK/t2.json"
expect_rc 0 "--threads 2"
check "the same bytes with 1 and 2 threads" cmp -s "$WORK/t1.json" "$WORK/t2.json"

# ---- help, and Ctrl-C ------------------------------------------------------------
run "$BIN" probes --help
expect_rc 0 "luxel probes --help"
expect_stdout_has "probes --help: usage" '^usage: luxel probes SCENE'
for opt in --grid --points --samples --threads --lights --sky --bounces; do
    expect_stdout_has "probes --help names $opt" -- "$opt"
done
run "$BIN" --help
expect_stdout_has "luxel --help lists probes" '^  probes SCENE'

# stopped by the test hook while the probes are computed, then SIGINT
: >"$ERR"
LUXEL_TEST_PAUSE=probes "$BIN" probes "$ROOM" "${SMALL[@]}" -o "$WORK/int/p.json" \
    >"$OUT" 2>"$ERR" </dev/null &
pid=$!
for ((i = 0; i < 6000; i++)); do
    grep -qs '^luxel: test: paused at probes' "$ERR" && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.01
done
kill -INT "$pid"
wait "$pid"
RC=$?
expect_rc 130 "SIGINT while computing probes"
expect_error "SIGINT while computing probes" "interrupted"
expect_no_output "SIGINT while computing probes" "$WORK/int"

# ---- bad input -------------------------------------------------------------------
printf '{"points": [[0, 1, 0],]}' >"$WORK/comma.json"
printf '{"points": [[0, 1]]}' >"$WORK/short.json"
printf '{"points": [[0, 1, "a"]]}' >"$WORK/text.json"
printf '{"points": []}' >"$WORK/empty.json"
printf '[[0, 1, 0]]' >"$WORK/array.json"
for bad in "--grid 0,2,2|--grid" "--grid 2,2|--grid" "--grid 2,2,2,2|--grid" "--grid a,b,c|--grid" \
    "--grid 2,,2|--grid" "--grid 2000,2,2|--grid" "--samples 0|--samples" \
    "--samples 70000|--samples" "--grid 2,2,2 --points $WORK/points.json|--points" \
    "--points $WORK/missing.json|missing.json" "--points $WORK/comma.json|comma.json" \
    "--points $WORK/short.json|points[0]" "--points $WORK/text.json|points[0]" \
    "--points $WORK/empty.json|empty" "--points $WORK/array.json|array.json"; do
    args=${bad%%|*}
    needle=${bad#*|}
    # shellcheck disable=SC2086
    run "$BIN" probes "$ROOM" $args -q -o "$WORK/bad/p.json"
    expect_rc 2 "$args"
    expect_error "$args" "$needle"
    expect_no_output "$args" "$WORK/bad"
done

# a failed run leaves an existing file as it was
cp "$J" "$WORK/keep.json"
run "$BIN" probes "$WORK/scenes/none.glb" -q -o "$J"
expect_rc 1 "a missing scene"
expect_error "a missing scene" "none.glb"
check "the earlier probes file keeps its bytes" cmp -s "$J" "$WORK/keep.json"
check "no staging folder left" test -z "$(ls -A "$WORK/grid" | grep -v '^probes.json$')"

finish
