# End-to-end tests of how bake and ibl put their outputs in place
# (tools/luxel/stage.c): files are staged, then moved into the output
# folder together.
# - A rename that fails half-way through publishing (injected with the test
#   hook LUXEL_TEST_FAIL_RENAME=N) must not lose the files it already
#   replaced: the folder ends exactly as it was before the run.
# - A bad output folder (a file in the way, a folder without write
#   permission, something that is not a file where an output goes) is
#   reported before the long work starts: the run never reaches its first
#   progress phase (LUXEL_TEST_PAUSE would stop it there and say so).
#
# usage: bash test_cli_publish.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
RETRO=$WORK/scenes/retro.glb
SKY=$WORK/scenes/sky.pfm

# snapshot DIR: every entry with its checksum, hidden ones included.
snapshot() { (cd "$1" && find . -mindepth 1 | LC_ALL=C sort | while read -r f; do
    if [ -f "$f" ]; then echo "$f $(cksum <"$f")"; else echo "$f"; fi
done); }

# ---- a rename failing half-way: the replaced files come back ----------------------

run "$LUXEL" bake "$RETRO" --resolution 32 -q -o "$WORK/out"
expect_rc 0 "first bake"
echo "a file of the user's" >"$WORK/out/notes.txt"
before=$(snapshot "$WORK/out")
files=$(ls "$WORK/out" | wc -l)
for n in 1 2 5 $((files - 1)); do
    label="bake with rename $n of publishing failing"
    LUXEL_TEST_FAIL_RENAME=$n run "$LUXEL" bake "$RETRO" --resolution 64 -q -o "$WORK/out"
    expect_rc 1 "$label"
    expect_error "$label" "cannot move into place"
    after=$(snapshot "$WORK/out")
    if [ "$before" = "$after" ]; then
        pass "$label: the folder is exactly as before (old lightmaps restored)"
    else
        fail "$label: the folder changed" "$(diff <(echo "$before") <(echo "$after") | head -5)"
    fi
done

run "$LUXEL" ibl "$SKY" --irradiance --sh -q -o "$WORK/ibl"
expect_rc 0 "first ibl"
before=$(snapshot "$WORK/ibl")
LUXEL_TEST_FAIL_RENAME=4 run "$LUXEL" ibl "$SKY" --irradiance --sh --intensity 2 -q \
    -o "$WORK/ibl"
expect_rc 1 "ibl with rename 4 of publishing failing"
after=$(snapshot "$WORK/ibl")
check "ibl with rename 4 failing: the folder is exactly as before" test "$before" = "$after"

# a rename failing into a new folder: nothing is left, the folder neither
LUXEL_TEST_FAIL_RENAME=3 run "$LUXEL" bake "$RETRO" --resolution 32 -q -o "$WORK/fresh/out"
expect_rc 1 "bake into a new folder with rename 3 failing"
check "bake into a new folder with rename 3 failing: no folder is left" test ! -e "$WORK/fresh"

# the same run without the failure replaces everything
run "$LUXEL" bake "$RETRO" --resolution 64 -q -o "$WORK/out"
expect_rc 0 "the bake again, no failure"
check "the bake again: the lightmaps are the new size" \
    grep -q '"width":	64' "$WORK/out/manifest.json"
check "the bake again: the user's file stays" test -f "$WORK/out/notes.txt"

# ---- a bad output folder fails before the work starts ----------------------------

# bad_folder LABEL NEEDLE OUT ARGS...: the run fails naming NEEDLE, before
# its first phase ("texel maps"; with PHASE=bake: before the bake, once the
# texel maps have named the lightmaps)
bad_folder() {
    local label=$1 needle=$2 out=$3
    shift 3
    LUXEL_TEST_PAUSE=${PHASE:-texel maps} run "$LUXEL" "$@" -o "$out"
    expect_rc 1 "$label"
    expect_error "$label" "$needle"
    check "$label: fails before the ${PHASE:-texel maps} phase" \
        test -z "$(grep '^luxel: test: paused' "$ERR")"
}

: >"$WORK/a_file"
bad_folder "bake -o a file" "a_file" "$WORK/a_file" bake "$RETRO" --resolution 32
bad_folder "bake -o under a file" "a_file" "$WORK/a_file/sub" bake "$RETRO" --resolution 32
check "bake -o a file: the file is untouched" test -f "$WORK/a_file" -a ! -s "$WORK/a_file"

mkdir -p "$WORK/blocked/ground.exr"
PHASE=bake bad_folder "bake with a folder where an output goes" "ground.exr" "$WORK/blocked" \
    bake "$RETRO" --resolution 32
check "bake with a folder in the way: the folder holds only what it held" \
    test "$(ls -A "$WORK/blocked")" = "ground.exr"

mkdir -p "$WORK/readonly"
chmod 555 "$WORK/readonly"
if [ "$(id -u)" -eq 0 ]; then
    # root writes anywhere: run luxel as an unprivileged user, from a copy
    # of the binary in a place that user can reach
    priv=$(mktemp -d /tmp/luxel-publish.XXXXXX)
    chmod 755 "$priv"
    cp "$LUXEL" "$priv/luxel" && cp "$RETRO" "$priv/retro.glb"
    mkdir "$priv/readonly" && chmod 555 "$priv/readonly"
    as_user=(setpriv --reuid=65534 --regid=65534 --clear-groups)
    if "${as_user[@]}" "$priv/luxel" --version >/dev/null 2>&1; then
        LUXEL_TEST_PAUSE="texel maps" run "${as_user[@]}" "$priv/luxel" bake \
            "$priv/retro.glb" --resolution 32 -o "$priv/readonly/out"
        expect_rc 1 "bake into a folder without write permission (as an unprivileged user)"
        expect_error "bake into a folder without write permission" "readonly/out" \
            "Permission denied"
        check "bake into a folder without write permission: fails before the bake starts" \
            test -z "$(grep '^luxel: test: paused' "$ERR")"
    else
        fail "cannot run luxel as an unprivileged user (setpriv) to test permissions"
    fi
    rm -rf "$priv"
else
    bad_folder "bake into a folder without write permission" "Permission denied" \
        "$WORK/readonly/out" bake "$RETRO" --resolution 32
fi
chmod 755 "$WORK/readonly"
check "bake into a folder without write permission: nothing was made in it" \
    test -z "$(ls -A "$WORK/readonly")"

LUXEL_TEST_PAUSE=environment run "$LUXEL" ibl "$SKY" -o "$WORK/a_file"
expect_rc 1 "ibl -o a file"
expect_error "ibl -o a file" "a_file"

finish
