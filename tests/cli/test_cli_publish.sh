# End-to-end tests of how bake and ibl put their outputs in place
# (tools/luxel/stage.c): files are staged, then moved into the output
# folder together.
# - A rename that fails half-way through publishing (injected with the test
#   hook LUXEL_TEST_FAIL_RENAME=N) must not lose the files it already
#   replaced: the folder ends exactly as it was before the run - also when
#   hard links are refused (LUXEL_TEST_FAIL_LINK=1: the replaced files are
#   moved aside instead). When putting one back fails too
#   (LUXEL_TEST_FAIL_RESTORE=N), that file is kept with its bytes where the
#   error says.
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
    expect_same "$label" "$before" "$WORK/out"
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

# ---- links refused: the replaced files are moved aside, and moved back ------------

# LUXEL_TEST_FAIL_LINK=1 refuses every hard link, as a file system without
# them does: publishing then moves each file it replaces aside (its name is
# empty until the new file is renamed in), so a rename failing half-way
# must move every one of them back.
before=$(snapshot "$WORK/out")
files=$(ls "$WORK/out" | wc -l)
for n in 1 4 $((files - 1)); do
    label="links refused, rename $n of publishing failing"
    LUXEL_TEST_FAIL_LINK=1 LUXEL_TEST_FAIL_RENAME=$n run "$LUXEL" bake "$RETRO" \
        --resolution 32 -q -o "$WORK/out"
    expect_rc 1 "$label"
    expect_error "$label" "cannot move into place"
    expect_same "$label" "$before" "$WORK/out"
done
LUXEL_TEST_FAIL_LINK=1 run "$LUXEL" bake "$RETRO" --resolution 32 -q -o "$WORK/out"
expect_rc 0 "links refused, nothing failing"
check "links refused, nothing failing: the lightmaps are the new size" \
    grep -q '"width":	32' "$WORK/out/manifest.json"
check "links refused, nothing failing: the user's file stays, nothing else is added" \
    test "$(ls -A "$WORK/out" | wc -l)" -eq "$files"

# ---- a restore failing: the replaced file is kept where the error says ------------

# LUXEL_TEST_FAIL_RESTORE=1 makes the first rename that puts a replaced file
# back fail. With rename 3 failing, outputs 1 and 2 are in place and are
# restored last first: output 2's old file cannot go back. It must be left
# where the error says (in the staging folder) with its bytes, and every
# other file restored. With links refused its name is then empty: the kept
# file is its only copy.
restore_fails() {
    local label=$1 link=$2 line target kept name want
    before=$(snapshot "$WORK/out")
    LUXEL_TEST_FAIL_LINK=$link LUXEL_TEST_FAIL_RENAME=3 LUXEL_TEST_FAIL_RESTORE=1 \
        run "$LUXEL" bake "$RETRO" --resolution 64 -q -o "$WORK/out"
    expect_rc 1 "$label"
    check "$label: two error lines, the failed move and the failed restore" \
        test "$(grep -c '^luxel: error:' "$ERR")" -eq 2 -a \
        "$(grep -c '^luxel: error: .*: cannot move into place' "$ERR")" -eq 1
    line=$(grep '^luxel: error: .*: could not put the previous file back (it is in ' "$ERR")
    if [ -z "$line" ]; then
        fail "$label: no error names where the previous file is"
        show_stderr
        return
    fi
    target=${line#luxel: error: }
    target=${target%%: could not put*}
    kept=${line#*(it is in }
    kept=${kept%%): *}
    name=$(basename "$target")
    want=$(echo "$before" | grep -F "./$name " | cut -d' ' -f2-)
    check "$label: the error names the output ($name) and a kept copy in the staging folder" \
        test "$target" = "$WORK/out/$name" -a "$(dirname "$(dirname "$kept")")" != "$WORK/out"
    check "$label: the kept copy holds the replaced file's bytes" \
        test -n "$want" -a "$(cksum <"$kept" 2>/dev/null)" = "$want"
    if [ "$link" = 1 ]; then
        check "$label: links refused: the output's name is empty (the kept file is the only copy)" \
            test ! -e "$target"
    else
        check "$label: the output's name holds the new file" \
            test -f "$target" -a "$(cksum <"$target")" != "$want"
    fi
    # every other file as before; with the kept copy moved back by hand and
    # the staging folder it was left in removed, the whole folder is
    mv "$kept" "$target" && rmdir "$(dirname "$kept")" "$(dirname "$(dirname "$kept")")"
    expect_same "$label, the kept copy moved back" "$before" "$WORK/out"
}
restore_fails "a restore failing" 0
restore_fails "links refused and a restore failing" 1

# ---- a bad output folder fails before the work starts ----------------------------

# state PATH: what is at PATH (type and mode), and a folder's snapshot.
state() {
    stat -c '%F %a' "$1" 2>/dev/null || echo "nothing"
    if [ -d "$1" ]; then snapshot "$1"; fi
}

# bad_folder LABEL NEEDLE OUT ARGS...: `luxel ARGS -o OUT` fails with exit
# status 1 and one error line naming NEEDLE, before its first long phase
# (PHASE, default "texel maps": LUXEL_TEST_PAUSE would stop the run there
# and say so), and leaves whatever was at OUT exactly as it was.
bad_folder() {
    local label=$1 needle=$2 out=$3 phase=${PHASE:-texel maps}
    shift 3
    local before after
    before=$(state "$out")
    : >"$ERR"
    LUXEL_TEST_PAUSE=$phase run "$LUXEL" "$@" -o "$out"
    expect_rc 1 "$label"
    expect_error "$label" "$needle"
    check "$label: fails before the $phase phase" \
        test -z "$(grep '^luxel: test: paused' "$ERR")"
    after=$(state "$out")
    if [ "$before" = "$after" ]; then
        pass "$label: $(basename "$out") is as it was"
    else
        fail "$label: $(basename "$out") changed" "$(diff <(echo "$before") <(echo "$after") | head -5)"
    fi
}

: >"$WORK/a_file"
bad_folder "bake -o a file" "a_file" "$WORK/a_file" bake "$RETRO" --resolution 32
bad_folder "bake -o under a file" "a_file" "$WORK/a_file/sub" bake "$RETRO" --resolution 32
check "bake -o a file: the file is untouched" test -f "$WORK/a_file" -a ! -s "$WORK/a_file"
# with a sky, before the sky is loaded (its progress phase is "environment")
PHASE=environment bad_folder "bake --sky -o a file" "a_file" "$WORK/a_file" \
    bake "$RETRO" --resolution 32 --sky "$SKY"
PHASE=environment bad_folder "bake --sky -o under a file" "a_file/sub" "$WORK/a_file/sub" \
    bake "$RETRO" --resolution 32 --sky "$SKY"

mkdir -p "$WORK/blocked/ground.exr"
PHASE=bake bad_folder "bake with a folder where an output goes" "blocked/ground.exr" \
    "$WORK/blocked" bake "$RETRO" --resolution 32

# ibl: every output's name is known from the layout, the format and the
# number of levels; each is checked before the environment is loaded (its
# first phase, "environment"), or, for specular levels past 0 whose count
# depends on the file's size, right after it, before the first filter ("sh")
mkdir -p "$WORK/ibl_blocked/specular_m0_px.exr"
PHASE=environment bad_folder "ibl with a folder where specular level 0 goes" \
    "ibl_blocked/specular_m0_px.exr" "$WORK/ibl_blocked" ibl "$SKY"
rmdir "$WORK/ibl_blocked/specular_m0_px.exr"
mkdir -p "$WORK/ibl_blocked/specular_m6_nz.exr"
PHASE=sh bad_folder "ibl with a folder where specular level 6 goes" \
    "ibl_blocked/specular_m6_nz.exr" "$WORK/ibl_blocked" ibl "$SKY"
PHASE=environment bad_folder "ibl --mips 7 with a folder where level 6 goes" \
    "ibl_blocked/specular_m6_nz.exr" "$WORK/ibl_blocked" ibl "$SKY" --mips 7
rmdir "$WORK/ibl_blocked/specular_m6_nz.exr"
mkdir -p "$WORK/ibl_blocked/specular.ktx" "$WORK/ibl_blocked/irradiance.hdr"
PHASE=environment bad_folder "ibl --layout ktx with a folder where specular.ktx goes" \
    "ibl_blocked/specular.ktx" "$WORK/ibl_blocked" ibl "$SKY" --layout ktx
PHASE=environment bad_folder "ibl --layout cross --format hdr with a folder in the way" \
    "ibl_blocked/irradiance.hdr" "$WORK/ibl_blocked" ibl "$SKY" --layout cross --format hdr
PHASE=environment bad_folder "ibl -o a file" "a_file" "$WORK/a_file" ibl "$SKY"

# no write permission; as root (who writes anywhere) luxel runs as an
# unprivileged user, from a copy of the binary in a place that user can reach
if [ "$(id -u)" -eq 0 ]; then
    # (as_user_setup, common.sh: the binary copied where that user can go)
    priv=$(mktemp -d /tmp/luxel-publish.XXXXXX)
    mkdir "$priv/readonly" && chmod 555 "$priv/readonly"
    readonly_dir=$priv/readonly
    if as_user_setup "$priv"; then
        cp "$RETRO" "$priv/retro.glb"
        LUXEL=$priv/as_user bad_folder "bake into a folder without write permission (unprivileged)" \
            "readonly/out: cannot create the output folder: Permission denied" \
            "$readonly_dir/out" bake "$priv/retro.glb" --resolution 32 --bounces 0
    else
        skip "bake into a folder without write permission: cannot run luxel as an unprivileged user (setpriv)"
    fi
else
    readonly_dir=$WORK/readonly
    mkdir -p "$readonly_dir" && chmod 555 "$readonly_dir"
    bad_folder "bake into a folder without write permission" \
        "readonly/out: cannot create the output folder: Permission denied" \
        "$readonly_dir/out" bake "$RETRO" --resolution 32
fi
check "bake into a folder without write permission: nothing was made in it" \
    test -z "$(ls -A "$readonly_dir")"
chmod 755 "$readonly_dir"
[ -n "${priv:-}" ] && rm -rf "$priv"

finish
