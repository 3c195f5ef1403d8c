# End-to-end tests of interrupting `luxel bake` (DESIGN.md section 4: "an
# error or Ctrl-C never leaves a partial or corrupt file"): SIGINT while the
# lightmaps are computed, SIGINT and SIGTERM while the files are written.
# Each interrupted run must exit non-zero, say so on stderr, and leave the
# output folder missing (no finished files, no temporary files, no folder).
#
# usage: bash test_cli_interrupt.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
RETRO=$WORK/scenes/retro.glb
# 8 lightmaps of 1024^2: a few seconds of baking, then of writing
BIG=(bake "$RETRO" --resolution 1024 --threads 2)
ALL_FILES=17 # 8 lightmaps, 8 previews, the manifest

# wait_for CONDITION-COMMAND...: polls every 10 ms for up to 30 s.
wait_for() {
    local i
    for ((i = 0; i < 3000; i++)); do
        "$@" && return 0
        sleep 0.01
    done
    return 1
}
# files written so far, staged ones included (the CLI writes into a hidden
# staging folder inside the output folder and moves them out at the end)
has_files() { [ -d "$1" ] && [ "$(find "$1" -type f | wc -l)" -ge "$2" ]; }
alive() { kill -0 "$1" 2>/dev/null; }

# interrupted LABEL OUTDIR: checks after an interrupted run.
interrupted() {
    local label=$1 out=$2
    if [ "$RC" -eq 0 ]; then
        # the run won the race and finished: then every file must be there
        if [ "$(ls -A "$out" | wc -l)" -eq "$ALL_FILES" ]; then
            pass "$label: finished before the signal, with all $ALL_FILES files"
        else
            fail "$label: exit 0 but $(ls -A "$out" | wc -l) files, want $ALL_FILES"
        fi
        return
    fi
    pass "$label: exit status $RC (non-zero)"
    expect_stderr_has "$label: says it was interrupted" '^luxel: error: .*interrupt'
    expect_no_output "$label" "$out"
}

# ---- SIGINT while computing -------------------------------------------------------

out=$WORK/out_compute
"$LUXEL" "${BIG[@]}" -o "$out" >"$OUT" 2>"$ERR" &
pid=$!
sleep 0.3
if [ -e "$out" ]; then
    echo "skip  SIGINT while computing: the bake reached the writing stage within 0.3 s"
fi
kill -INT "$pid"
wait "$pid"
RC=$?
interrupted "SIGINT while computing" "$out"
check "SIGINT while computing: one error line" test "$(grep -c '^luxel: error:' "$ERR")" -eq 1

# ---- SIGINT / SIGTERM while writing ---------------------------------------------------

# SIG:N sends SIG once the output folder holds N entries: the folder is
# created just before the first file, so N = 0 most likely hits the first
# file half-written and N = 3 leaves finished files to remove.
for spec in INT:3 TERM:3 INT:0; do
    sig=${spec%:*} n=${spec#*:}
    out=$WORK/out_write_$sig$n
    "$LUXEL" "${BIG[@]}" -o "$out" >"$OUT" 2>"$ERR" &
    pid=$!
    if wait_for has_files "$out" "$n"; then
        kill -"$sig" "$pid" 2>/dev/null
        wait "$pid"
        RC=$?
        interrupted "SIG$sig while writing (after $n files)" "$out"
    else
        alive "$pid" && kill -KILL "$pid"
        wait "$pid"
        fail "SIG$sig while writing: the bake never started writing"
    fi
done

# ---- a normal run afterwards is complete ------------------------------------------------

run "$LUXEL" bake "$RETRO" --resolution 64 -q -o "$WORK/out_write_INT3"
expect_rc 0 "a new bake into the interrupted run's folder"
check "it writes all $ALL_FILES files" test "$(ls -A "$WORK/out_write_INT3" | wc -l)" -eq "$ALL_FILES"

finish
