# End-to-end tests of interrupting luxel (an error or Ctrl-C never leaves
# a partial or corrupt file). Each run is stopped at a
# known phase by the test hook LUXEL_TEST_PAUSE=PHASE (the CLI says
# "luxel: test: paused at PHASE" and waits for a signal), so the signal
# lands mid-run every time. An interrupted run must end by its signal (exit
# status 128 + N), print one error line saying it was interrupted, and
# leave the output folder as it was: missing when the run would have made
# it, with the previous run's files untouched when it was there.
#
# usage: bash test_cli_interrupt.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
RETRO=$WORK/scenes/retro.glb
SKY=$WORK/scenes/sky.pfm
BAKE=(bake "$RETRO" --resolution 64 --threads 2)

# interrupt LABEL PHASE SIGNAL OUTDIR ARGS...: runs luxel ARGS... -o OUTDIR
# paused at PHASE, sends SIGNAL, and checks how the run ended.
interrupt() {
    local label=$1 phase=$2 sig=$3 out=$4
    shift 4
    : >"$ERR" # empty before the run starts: a stale "paused" line would send the signal too early
    LUXEL_TEST_PAUSE=$phase "$LUXEL" "$@" -o "$out" >"$OUT" 2>"$ERR" </dev/null &
    local pid=$!
    if ! wait_for_pause "$pid" "$ERR"; then
        wait "$pid"
        fail "$label: the run never paused at '$phase' (exit $?)"
        show_stderr
        return 1
    fi
    local t0=${EPOCHREALTIME/./}
    kill -"$sig" "$pid"
    wait "$pid"
    RC=$?
    STOP_MS=$(((${EPOCHREALTIME/./} - t0) / 1000)) # from the signal to the exit
    local want=$((128 + $(kill -l "$sig")))
    if [ "$RC" -eq "$want" ]; then
        pass "$label: ended by SIG$sig (exit status $want)"
    else
        fail "$label: exit status $RC, want $want"
        show_stderr
    fi
    expect_error "$label" "interrupted"
}

# ---- while computing: nothing was written, so nothing is left --------------------

interrupt "SIGINT while building texel maps" "texel maps" INT "$WORK/o1" "${BAKE[@]}"
expect_no_output "SIGINT while building texel maps" "$WORK/o1"
check "SIGINT while building texel maps: says nothing was written" \
    grep -q 'interrupted; nothing written' "$ERR"

interrupt "SIGTERM while baking" bake TERM "$WORK/o2" "${BAKE[@]}"
expect_no_output "SIGTERM while baking" "$WORK/o2"

interrupt "SIGHUP while evaluating dynamic lights" "dynamic lights" HUP "$WORK/o3" "${BAKE[@]}"
expect_no_output "SIGHUP while evaluating dynamic lights" "$WORK/o3"

# Padding reports each dilation pass: the signal stops it within a pass, not
# after every lightmap is padded (64 passes over 8 maps of 512 x 512).
interrupt "SIGINT while padding the lightmaps" apply INT "$WORK/o7" bake "$RETRO" \
    --resolution 512 --padding 64 --threads 2
expect_no_output "SIGINT while padding the lightmaps" "$WORK/o7"
check "SIGINT while padding the lightmaps: says nothing was written" \
    grep -q 'interrupted; nothing written' "$ERR"
if [ "$STOP_MS" -lt 2000 ]; then
    pass "SIGINT while padding the lightmaps: ended ${STOP_MS} ms after the signal"
else
    fail "SIGINT while padding the lightmaps: ended ${STOP_MS} ms after the signal, want < 2000"
fi

interrupt "ibl: SIGINT while filtering specular" specular INT "$WORK/o4" ibl "$SKY"
expect_no_output "ibl: SIGINT while filtering specular" "$WORK/o4"

# ---- while writing: staged files are removed, the folders the run made too -------

interrupt "SIGINT while writing" write INT "$WORK/o5" "${BAKE[@]}"
expect_no_output "SIGINT while writing" "$WORK/o5"
check "SIGINT while writing: says the outputs were removed" \
    grep -q 'interrupted; outputs removed' "$ERR"

interrupt "SIGTERM while writing into new nested folders" write TERM "$WORK/n1/n2/out" \
    "${BAKE[@]}"
check "SIGTERM while writing into new nested folders: every folder it made is gone" \
    test ! -e "$WORK/n1"

interrupt "ibl: SIGTERM while writing" write TERM "$WORK/o6" ibl "$SKY" --layout ktx
expect_no_output "ibl: SIGTERM while writing" "$WORK/o6"

# ---- into a folder that holds an earlier run: it stays exactly as it was ---------

run "$LUXEL" "${BAKE[@]}" -q -o "$WORK/prev"
expect_rc 0 "a first bake into prev/"
echo "not luxel's" >"$WORK/prev/notes.txt"
before=$(cd "$WORK/prev" && ls -A | LC_ALL=C sort | xargs cksum)
for phase in bake write; do
    interrupt "SIGINT at '$phase' over an earlier run" "$phase" INT "$WORK/prev" \
        bake "$RETRO" --resolution 32 --threads 2
    after=$(cd "$WORK/prev" && ls -A | LC_ALL=C sort | xargs cksum)
    if [ "$before" = "$after" ]; then
        pass "SIGINT at '$phase' over an earlier run: every file as it was, nothing added"
    else
        fail "SIGINT at '$phase' over an earlier run: the folder changed" \
            "before: $(echo $before)" "after:  $(echo $after)"
    fi
done

finish
