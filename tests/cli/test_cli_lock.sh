# End-to-end tests of the output folder's lock and of the staging folders
# runs leave behind (tools/luxel/stage.c):
# - bake and ibl hold an exclusive flock on their output folder for the
#   whole run: a second run into it fails at once, with one line naming the
#   folder, and the folder holds the first run's files only (before, two
#   bakes could leave one's manifest beside the other's lightmaps);
# - a run killed with SIGKILL leaves its staging folder .luxel-XXXXXX: the
#   next run into that folder names it in one warning, and --clean removes
#   it; a staging folder that a running run holds (its flock) is never
#   reported or removed, nor is a link or a folder luxel does not make.
# Runs are stopped at a known point with the test hook LUXEL_TEST_PAUSE.
#
# usage: bash test_cli_lock.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
SKY=$WORK/scenes/sky.pfm
BAKE=(bake "$ROOM" --resolution 16)
ROOM_FILES=(room.exr room.png tall_box.exr tall_box.png short_box.exr short_box.png
    manifest.json)

# start_paused PHASE ERRFILE ARGS...: runs luxel ARGS... in the background,
# stopped at PHASE; PAUSED_PID is its process id. False when it never
# paused.
start_paused() {
    local phase=$1 err=$2
    shift 2
    : >"$err"
    LUXEL_TEST_PAUSE=$phase "$LUXEL" "$@" >/dev/null 2>"$err" </dev/null &
    PAUSED_PID=$!
    wait_for_pause "$PAUSED_PID" "$err"
}

# staging_folders DIR: the names of the staging folders in DIR.
staging_folders() { (cd "$1" && ls -A | grep -E '^\.luxel-.{6}$'); }

not_paused() { ! grep -q '^luxel: test: paused at ' "$1"; }
not_grep() { ! grep -q -- "$1" "$2"; }

# ---- the lock held by another process: fails at once, nothing changes ------------

run "$LUXEL" "${BAKE[@]}" -q -o "$WORK/held"
expect_rc 0 "a first bake into held/"
before=$(snapshot "$WORK/held")
exec {held_fd}<"$WORK/held"
flock -n "$held_fd" || { echo "flock(1) cannot lock a folder here"; exit 1; }
label="bake into a folder another process holds"
: >"$ERR"
LUXEL_TEST_PAUSE="texel maps" run "$LUXEL" "${BAKE[@]}" -q -o "$WORK/held"
expect_rc 1 "$label"
expect_error "$label" "another luxel run is writing $WORK/held"
check "$label: fails before any work (never reaches the texel maps)" \
    not_paused "$ERR"
expect_same "$label" "$before" "$WORK/held"
label="ibl into a folder another process holds"
run "$LUXEL" ibl "$SKY" --sh -q -o "$WORK/held"
expect_rc 1 "$label"
expect_error "$label" "another luxel run is writing $WORK/held"
expect_same "$label" "$before" "$WORK/held"
exec {held_fd}<&-
run "$LUXEL" "${BAKE[@]}" -q -o "$WORK/held"
expect_rc 0 "bake into held/ once the lock is released"

# ---- two luxel runs: the second fails at once, and adds nothing ------------------

run "$LUXEL" "${BAKE[@]}" -q -o "$WORK/two"
expect_rc 0 "a first bake into two/"
before=$(snapshot "$WORK/two")
if start_paused write "$WORK/first.err" "${BAKE[@]}" --ao -o "$WORK/two"; then
    label="a second bake while the first is writing"
    run "$LUXEL" "${BAKE[@]}" --resolution 8 -q -o "$WORK/two"
    expect_rc 1 "$label"
    expect_error "$label" "another luxel run is writing $WORK/two"
    check "$label: the first run's staging folder alone is there" \
        test "$(staging_folders "$WORK/two" | wc -l)" -eq 1
    # the paused run waits for a signal: interrupted, it removes what it
    # staged, and the folder is the earlier bake's alone
    kill -TERM "$PAUSED_PID"
    wait "$PAUSED_PID"
    expect_same "$label, the first run interrupted" "$before" "$WORK/two"
    run "$LUXEL" "${BAKE[@]}" --resolution 8 -q -o "$WORK/two"
    expect_rc 0 "the second bake, once the first has ended"
else
    fail "the first bake never paused at 'write'"
fi

# ---- a killed run's staging folder: reported, kept, then removed by --clean ------

run "$LUXEL" "${BAKE[@]}" -q -o "$WORK/killed"
expect_rc 0 "a first bake into killed/"
if start_paused write "$WORK/killed.err" "${BAKE[@]}" -o "$WORK/killed"; then
    kill -KILL "$PAUSED_PID"
    wait "$PAUSED_PID" 2>/dev/null
    pass "a bake into killed/ stopped by SIGKILL while writing"
else
    fail "the bake into killed/ never paused at 'write'"
fi
left=$(staging_folders "$WORK/killed")
check "SIGKILL leaves one staging folder ($left)" test "$(echo "$left" | grep -c .)" -eq 1

label="the next bake into killed/"
run "$LUXEL" "${BAKE[@]}" -o "$WORK/killed"
expect_rc 0 "$label"
warning="luxel: warning: $WORK/killed: a staging folder left by a luxel run that did not finish"
warning+=" (killed or crashed): $left; --clean removes it"
check "$label: one warning names the staging folder and --clean" \
    test "$(grep -cxF "$warning" "$ERR")" -eq 1
check "$label: keeps it" test -d "$WORK/killed/$left"

label="the next bake into killed/ with --clean"
run "$LUXEL" "${BAKE[@]}" --clean -o "$WORK/killed"
expect_rc 0 "$label"
check "$label: no warning about it" not_grep "staging folder" "$ERR"
expect_files "$label" "$WORK/killed" "${ROOM_FILES[@]}"

# ibl --clean too, on a leftover made by hand with a file set aside mid-publish
mkdir -p "$WORK/ibl/.luxel-Ab12Cd/.previous"
echo staged >"$WORK/ibl/.luxel-Ab12Cd/sh.json"
echo old >"$WORK/ibl/.luxel-Ab12Cd/.previous/sh.json"
label="ibl --clean into a folder with a leftover"
run "$LUXEL" ibl "$SKY" --sh --clean -o "$WORK/ibl"
expect_rc 0 "$label"
expect_files "$label" "$WORK/ibl" sh.json

# ---- what is not a leftover is never removed -------------------------------------

# a single-file command (normalmap) takes no folder lock, but holds its
# staging folder's: a bake --clean into that folder leaves it alone
mkdir -p "$WORK/shared"
if start_paused write "$WORK/nm.err" normalmap "$SKY" -o "$WORK/shared/n.png"; then
    live=$(staging_folders "$WORK/shared")
    label="bake --clean beside a running normalmap"
    run "$LUXEL" "${BAKE[@]}" --clean -o "$WORK/shared"
    expect_rc 0 "$label"
    check "$label: the running run's staging folder stays ($live)" test -d "$WORK/shared/$live"
    check "$label: and is not reported" not_grep "staging folder" "$ERR"
    kill -TERM "$PAUSED_PID"
    wait "$PAUSED_PID"
    check "the interrupted normalmap removes its own staging folder" \
        test -z "$(staging_folders "$WORK/shared")"
else
    fail "normalmap never paused at 'write'"
fi

# a link named like a staging folder, and a folder holding what luxel never
# writes there (a subfolder): neither is followed or emptied
mkdir -p "$WORK/odd" "$WORK/target"
echo "not luxel's" >"$WORK/target/keep.txt"
ln -s "$WORK/target" "$WORK/odd/.luxel-link00"
mkdir -p "$WORK/odd/.luxel-Zz99yy/user-folder"
echo "the user's" >"$WORK/odd/.luxel-Zz99yy/user-folder/f"
label="bake --clean beside a link and a foreign folder"
run "$LUXEL" "${BAKE[@]}" --clean -o "$WORK/odd"
expect_rc 0 "$label"
check "$label: the link's target keeps its file" test -f "$WORK/target/keep.txt"
check "$label: the link stays" test -L "$WORK/odd/.luxel-link00"
check "$label: the subfolder the user put there stays" \
    test -f "$WORK/odd/.luxel-Zz99yy/user-folder/f"
expect_stderr_has "$label: a warning says what could not be removed" \
    "could not remove all of .luxel-Zz99yy"

# ---- a single file's partial copy: out.glb.tmp.XXXXXX ----------------------------

# unwrap, tangents and the library's writers write <name>.tmp.XXXXXX beside
# the target under an flock and rename it over the target; a run killed
# mid-write leaves it. The next write of that target reports and removes
# the ones nobody holds; one a live writer holds (its flock), and names
# that are not its own, stay.
mkdir -p "$WORK/single"
echo partial >"$WORK/single/out.glb.tmp.abc123"
echo live >"$WORK/single/out.glb.tmp.zz9999"
echo "the user's" >"$WORK/single/out.glb.tmp.NotOurs"
echo "the user's" >"$WORK/single/other.glb.tmp.abc123"
exec {live_fd}<"$WORK/single/out.glb.tmp.zz9999"
flock -n "$live_fd" || { echo "flock(1) cannot lock a file here"; exit 1; }
for cmd in unwrap tangents; do
    label="$cmd into a folder with a partial out.glb of a stopped run"
    run "$LUXEL" "$cmd" "$ROOM" -o "$WORK/single/out.glb"
    expect_rc 0 "$label"
    expect_files "$label: the partial file gone, the others kept" "$WORK/single" out.glb \
        out.glb.tmp.zz9999 out.glb.tmp.NotOurs other.glb.tmp.abc123
    echo partial >"$WORK/single/out.glb.tmp.abc123"
done
check "the partial file was named in one warning" test "$(grep -cxF \
    "luxel: warning: $WORK/single/out.glb.tmp.abc123: removed, a partial file of out.glb left by a run that was stopped" \
    "$ERR")" -eq 1
exec {live_fd}<&-

finish
