# End-to-end tests of `luxel bake --memory-limit`: a limit too small for
# the demo room's lightmaps together bakes them in tiles (the verbose log
# says how many) and writes the same bytes as the bake without a limit,
# every file of it (lightmaps, previews, AO maps, manifest), across thread
# counts; a limit below what must stay in memory for the whole bake fails
# up front with one line naming the memory needed and the limit, and
# writes nothing; directional maps, supersampling and light probes tile to
# the same bytes too; malformed sizes are usage errors (exit 2, one line,
# nothing written). The tiled limit is read from the failing run's own
# message (its "needs N MiB", plus 0.1 MiB for the rounding), so the test
# does not repeat the per-texel figures.
#
# usage: bash test_cli_memory.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
BIN=$LUXEL_REAL

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
ARGS=(--resolution 48 --gi-samples 9 --bounces 2 --ao --ao-samples 9 --format exr -q)

# ---- below the resident part: one line, nothing written -------------------------
run "$BIN" bake "$ROOM" "${ARGS[@]}" --memory-limit 64K -o "$WORK/small"
expect_rc 1 "--memory-limit 64K"
expect_error "--memory-limit 64K" "room.glb" "needs" "of memory, the memory limit asked for is"
expect_no_output "--memory-limit 64K" "$WORK/small"
need=$(grep '^luxel: error:' "$ERR" | sed -n 's/.* needs \([0-9.]*\) MiB of memory.*/\1/p')
if [ -z "$need" ]; then
    fail "the error states the memory needed in MiB"
    finish
fi
limit=$(awk -v n="$need" 'BEGIN { printf "%d", (n + 0.1) * 1048576 }')

# ---- tiles: the same bytes ------------------------------------------------------
run "$BIN" bake "$ROOM" "${ARGS[@]}" --threads 1 -o "$WORK/whole"
expect_rc 0 "bake without a limit"
run "$BIN" bake "$ROOM" "${ARGS[@]}" --threads 2 --memory-limit "$limit" -v -o "$WORK/tiled"
expect_rc 0 "bake under --memory-limit $limit"
tiles=$(sed -n 's/.*baking them in \([0-9]*\) tiles.*/\1/p' "$ERR")
check "the verbose log says the bake ran in tiles (${tiles:-none})" \
    test "${tiles:-0}" -ge 2
files=0
for f in "$WORK/whole"/*; do
    n=$(basename "$f")
    files=$((files + 1))
    check "$n: the same bytes tiled and whole" cmp -s "$f" "$WORK/tiled/$n"
done
check "the bakes wrote several lightmaps and AO maps ($files files)" test "$files" -ge 7
check "the tiled bake wrote no other file" \
    test "$(ls "$WORK/tiled" | wc -l)" -eq "$files"

# ---- directional maps, supersampling and probes under their own limits ---------------
# (each read from its own failing run, as above)
limit_of() {
    run "$BIN" "$@" --memory-limit 64K -o "$WORK/small"
    local n
    n=$(grep '^luxel: error:' "$ERR" | sed -n 's/.* needs \([0-9.]*\) MiB of memory.*/\1/p')
    awk -v n="${n:-0}" 'BEGIN { printf "%d", (n + 0.1) * 1048576 }'
}
MORE=(--directional sh --supersample 2)
more_limit=$(limit_of bake "$ROOM" "${ARGS[@]}" "${MORE[@]}")
run "$BIN" bake "$ROOM" "${ARGS[@]}" "${MORE[@]}" --threads 2 -o "$WORK/whole_sh"
expect_rc 0 "bake --directional sh --supersample 2 without a limit"
run "$BIN" bake "$ROOM" "${ARGS[@]}" "${MORE[@]}" --threads 1 --memory-limit "$more_limit" \
    -o "$WORK/tiled_sh"
expect_rc 0 "bake --directional sh --supersample 2 under --memory-limit $more_limit"
for f in "$WORK/whole_sh"/*; do
    n=$(basename "$f")
    check "$n: the same bytes tiled and whole (directional, supersampled)" \
        cmp -s "$f" "$WORK/tiled_sh/$n"
done
check "the directional bake wrote SH maps" test -f "$WORK/tiled_sh/room_sh0.exr"
PROBES=(--resolution 48 --gi-samples 9 --bounces 2 --grid 2,2,2 --samples 16 -q)
probe_limit=$(limit_of probes "$ROOM" "${PROBES[@]}")
run "$BIN" probes "$ROOM" "${PROBES[@]}" -o "$WORK/probes_whole.json"
expect_rc 0 "probes without a limit"
run "$BIN" probes "$ROOM" "${PROBES[@]}" --memory-limit "$probe_limit" -v \
    -o "$WORK/probes_tiled.json"
expect_rc 0 "probes under --memory-limit $probe_limit"
check "probes: the verbose log says the bake ran in tiles" grep -q "baking them in" "$ERR"
check "probes: the same file tiled and whole" \
    cmp -s "$WORK/probes_whole.json" "$WORK/probes_tiled.json"

# ---- Ctrl-C in a tiled bake: the run stops, nothing written ----------------------
# paused at the bake's first report (the test hook LUXEL_TEST_PAUSE, as
# test_cli_interrupt.sh uses it), then SIGINT
: >"$ERR"
LUXEL_TEST_PAUSE=bake "$BIN" bake "$ROOM" "${ARGS[@]}" --memory-limit "$limit" \
    -o "$WORK/stopped" >"$OUT" 2>"$ERR" </dev/null &
pid=$!
for ((i = 0; i < 6000; i++)); do
    grep -qs '^luxel: test: paused at ' "$ERR" && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.01
done
kill -INT "$pid" 2>/dev/null
wait "$pid"
RC=$?
expect_rc 130 "SIGINT in a tiled bake"
expect_error "SIGINT in a tiled bake" "interrupted"
expect_no_output "SIGINT in a tiled bake" "$WORK/stopped"

# ---- sizes --------------------------------------------------------------------------
run "$BIN" bake "$ROOM" --resolution 16 --bounces 0 -q --memory-limit 1.5G -o "$WORK/big"
expect_rc 0 "--memory-limit 1.5G"
for bad in abc 0 -5 12Q 4GG "" 1e99T; do
    run "$BIN" bake "$ROOM" --resolution 16 -q --memory-limit "$bad" -o "$WORK/bad"
    expect_rc 2 "--memory-limit '$bad'"
    expect_error "--memory-limit '$bad'" "--memory-limit"
    expect_no_output "--memory-limit '$bad'" "$WORK/bad"
done

finish
