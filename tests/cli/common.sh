# Shared pieces of the CLI end-to-end tests (sourced by tests/cli/test_*.sh;
# not a test itself). Each script is run as
#     bash test_X.sh LUXEL GEN_SCENES WORKDIR [CASE]
# and sources this file with its arguments: LUXEL and GEN become absolute
# paths, WORK is emptied and recreated, CASE (when given) names the one case
# to run, and the check functions below print one line per check. `finish`
# prints "N passed, M failed, K skipped" and exits 1 when any check failed,
# else 77 (CTest's SKIP_RETURN_CODE) when a case was skipped: a script whose
# cases may not run on every machine runs one case per CTest test.
#
# Only bash and coreutils (printf, head, od, cmp, stat...) plus awk are used:
# test inputs are written here by code, never downloaded or checked in.

if [ $# -ne 3 ] && [ $# -ne 4 ]; then
    echo "usage: bash $0 LUXEL GEN_SCENES WORKDIR [CASE]" >&2
    exit 2
fi
CASE_NAME=${4:-}

abspath() { # a path made absolute (the file need not exist)
    case $1 in
    /*) printf '%s\n' "$1" ;;
    *) printf '%s/%s\n' "$PWD" "$1" ;;
    esac
}

LUXEL=$(abspath "$1")
GEN=$(abspath "$2")
WORK=$(abspath "$3")
for exe in "$LUXEL" "$GEN"; do
    if [ ! -x "$exe" ]; then
        echo "$0: $exe is not an executable" >&2
        exit 2
    fi
done
case $WORK in
/ | "$HOME" | /tmp | /usr*)
    echo "$0: refusing to use $WORK as a scratch folder" >&2
    exit 2
    ;;
esac
chmod -R u+rwx "$WORK" 2>/dev/null
rm -rf "$WORK"
mkdir -p "$WORK" || exit 2
cd "$WORK" || exit 2

# luxel bake adds two bounces of indirect light by default. The scripts
# written before it check direct light against closed forms and bake many
# times: they get `--bounces 0` unless they give --bounces themselves,
# through a wrapper that execs the real binary (same process id, so
# signals reach it). LUXEL_REAL is the binary as given, with its defaults
# (test_cli_gi.sh).
LUXEL_REAL=$LUXEL
mkdir -p "$WORK/.bin" || exit 2
cat >"$WORK/.bin/luxel" <<WRAPPER
#!/bin/bash
if [ "\${1:-}" = bake ]; then
    for a in "\$@"; do
        case \$a in --bounces | --bounces=*) exec -a "$LUXEL_REAL" "$LUXEL_REAL" "\$@" ;; esac
    done
    shift
    exec -a "$LUXEL_REAL" "$LUXEL_REAL" bake --bounces 0 "\$@"
fi
exec -a "$LUXEL_REAL" "$LUXEL_REAL" "\$@"
WRAPPER
chmod +x "$WORK/.bin/luxel"
LUXEL=$WORK/.bin/luxel

PASSED=0
FAILED=0
SKIPPED=0
OUT=$WORK/.stdout # stdout, stderr and exit status of the last `run`
ERR=$WORK/.stderr
RC=0

pass() { PASSED=$((PASSED + 1)); printf 'ok    %s\n' "$1"; }
# skip DESCRIPTION: a case this machine cannot run (finish then exits 77).
skip() { SKIPPED=$((SKIPPED + 1)); printf 'skip  %s\n' "$1"; }
fail() {
    FAILED=$((FAILED + 1))
    printf 'FAIL  %s\n' "$1"
    shift
    local line
    for line in "$@"; do printf '        %s\n' "$line"; done
}

# run CMD ARGS...: runs a command, keeping its stdout, stderr and status.
run() {
    "$@" >"$OUT" 2>"$ERR" </dev/null
    RC=$?
}

show_stderr() { # the last run's stderr, indented, for failure messages
    sed -n '1,8s/^/        stderr: /p' "$ERR"
}

# check DESCRIPTION TEST-COMMAND...: a check passes when the command does.
check() {
    local what=$1
    shift
    if "$@"; then pass "$what"; else fail "$what"; fi
}

expect_rc() { # expect_rc WANT DESCRIPTION
    if [ "$RC" -eq "$1" ]; then
        pass "$2: exit status $1"
    else
        fail "$2: exit status $RC, want $1"
        show_stderr
    fi
}

# expect_error DESCRIPTION NEEDLE...: stderr has exactly one
# "luxel: error:" line and it contains every needle (fixed strings).
expect_error() {
    local what=$1
    shift
    local n
    n=$(grep -c '^luxel: error:' "$ERR")
    if [ "$n" -ne 1 ]; then
        fail "$what: $n 'luxel: error:' lines on stderr, want exactly 1"
        show_stderr
        return
    fi
    local line needle
    line=$(grep '^luxel: error:' "$ERR")
    for needle in "$@"; do
        case $line in
        *"$needle"*) ;;
        *)
            fail "$what: the error does not say '$needle'" "$line"
            return
            ;;
        esac
    done
    pass "$what: one error line naming: $*"
}

# expect_stderr_has / expect_stdout_has DESCRIPTION PATTERN: grep -E.
expect_stderr_has() {
    if grep -Eq -- "$2" "$ERR"; then
        pass "$1"
    else
        fail "$1: stderr lacks /$2/"
        show_stderr
    fi
}
expect_stdout_has() {
    if grep -Eq -- "$2" "$OUT"; then
        pass "$1"
    else
        fail "$1: stdout lacks /$2/"
        sed -n '1,12s/^/        stdout: /p' "$OUT"
    fi
}

# expect_no_output DESCRIPTION DIR [existed]: DIR is missing; when the test
# made it beforehand ("existed"), it is there and empty.
expect_no_output() {
    if [ ! -e "$2" ]; then
        if [ -n "${3:-}" ]; then
            fail "$1: the output folder that was there is gone"
        else
            pass "$1: no output folder"
        fi
    elif [ -d "$2" ] && [ -z "$(ls -A "$2")" ]; then
        if [ -n "${3:-}" ]; then
            pass "$1: output folder left empty"
        else
            fail "$1: an empty output folder $2 was left behind"
        fi
    else
        fail "$1: files left in $2" "$(ls -A "$2" | tr '\n' ' ')"
    fi
}

# expect_files DESCRIPTION DIR NAME...: DIR holds exactly these entries.
expect_files() {
    local what=$1 dir=$2
    shift 2
    local want got
    want=$(printf '%s\n' "$@" | LC_ALL=C sort)
    got=$(ls -A "$dir" 2>/dev/null | LC_ALL=C sort)
    if [ "$want" = "$got" ]; then
        pass "$what: $# files"
    else
        fail "$what: files differ" "want: ${want//$'\n'/ }" "got:  ${got//$'\n'/ }"
    fi
}

# The magic bytes of a file, as lowercase hex without spaces.
magic() { head -c "$2" "$1" | od -An -tx1 | tr -d ' \n'; }

# as_user_setup DIR: for tests that need luxel run by an unprivileged user
# (root reads and writes anything). The build and WORK may live where that
# user cannot go (a checkout in root's 0700 home), so the real binary (not
# the --bounces wrapper, which points back into the build) is copied into
# DIR, a fresh folder made traversable, with the shared libluxel it links
# to when there is one, and DIR/as_user runs it as nobody (65534). Returns
# 1 when that user cannot run it (no setpriv, no permission to switch).
as_user_setup() {
    local dir=$1 lib
    chmod 755 "$dir" || return 1
    cp "$LUXEL_REAL" "$dir/luxel" || return 1
    # a libluxel.so found through the build's RPATH would be out of reach
    for lib in $(ldd "$LUXEL_REAL" 2>/dev/null | awk '/libluxel/ { print $3 }'); do
        cp "$lib" "$dir/" || return 1
    done
    printf '#!/bin/sh\nLD_LIBRARY_PATH=%s exec setpriv --reuid=65534 --regid=65534 --clear-groups %s "$@"\n' \
        "$dir" "$dir/luxel" >"$dir/as_user" && chmod 755 "$dir/as_user" || return 1
    "$dir/as_user" --version >/dev/null 2>&1
}

# Little-endian float32 bytes as printf escapes, for the handful of exactly
# representable values the hand-written glTF buffers use (IEEE 754 binary32).
f32() {
    case $1 in
    0) printf '\x00\x00\x00\x00' ;;
    1) printf '\x00\x00\x80\x3f' ;;
    -1) printf '\x00\x00\x80\xbf' ;;
    2) printf '\x00\x00\x00\x40' ;;
    0.5) printf '\x00\x00\x00\x3f' ;;
    0.25) printf '\x00\x00\x80\x3e' ;;
    0.125) printf '\x00\x00\x00\x3e' ;;
    0.75) printf '\x00\x00\x40\x3f' ;;
    0.875) printf '\x00\x00\x60\x3f' ;;
    556) printf '\x00\x00\x0b\x44' ;;
    nan) printf '\x00\x00\xc0\x7f' ;;
    inf) printf '\x00\x00\x80\x7f' ;;
    *)
        echo "f32: no encoding for $1" >&2
        return 1
        ;;
    esac
}

# snapshot DIR: every entry with its checksum, hidden ones included.
snapshot() { (cd "$1" && find . -mindepth 1 | LC_ALL=C sort | while read -r f; do
    if [ -f "$f" ]; then echo "$f $(cksum <"$f")"; else echo "$f"; fi
done); }

# expect_same LABEL BEFORE DIR: DIR's snapshot is BEFORE.
expect_same() {
    local after
    after=$(snapshot "$3")
    if [ "$2" = "$after" ]; then
        pass "$1: the folder is exactly as before"
    else
        fail "$1: the folder changed" "$(diff <(echo "$2") <(echo "$after") | head -5)"
    fi
}

# wait_for_pause PID ERRFILE: waits (up to 60 s) until a run started with
# LUXEL_TEST_PAUSE says in ERRFILE that it paused; false when it ended first.
wait_for_pause() {
    local i
    for ((i = 0; i < 6000; i++)); do
        grep -qs '^luxel: test: paused at ' "$2" && return 0
        kill -0 "$1" 2>/dev/null || return 1
        sleep 0.01
    done
    return 1
}

# write_gltf FILE.gltf MESH NODE "x y z  x y z ..." "u v  u v ...": a glTF
# 2.0 file with one node NODE carrying mesh MESH, one non-indexed triangle
# list (POSITION and TEXCOORD_0 float32), its buffer in FILE.bin. The
# values must be ones f32 knows.
write_gltf() {
    local file=$1 mesh=$2 node=$3 pos=$4 uv=$5
    local bin=${file%.gltf}.bin
    local v n_pos=0 n_uv=0
    : >"$bin"
    for v in $pos; do f32 "$v" >>"$bin" || return 1; n_pos=$((n_pos + 1)); done
    for v in $uv; do f32 "$v" >>"$bin" || return 1; n_uv=$((n_uv + 1)); done
    local count=$((n_pos / 3)) pos_bytes=$((n_pos * 4)) uv_bytes=$((n_uv * 4))
    if [ $((n_pos % 9)) -ne 0 ] || [ $((n_uv / 2)) -ne "$count" ]; then
        echo "write_gltf: $n_pos position and $n_uv UV values do not make triangles" >&2
        return 1
    fi
    cat >"$file" <<EOF
{
  "asset": {"version": "2.0", "generator": "luxel tests/cli"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"name": "$node", "mesh": 0}],
  "meshes": [{"name": "$mesh", "primitives": [
    {"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "mode": 4}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": $count, "type": "VEC3"},
    {"bufferView": 1, "componentType": 5126, "count": $count, "type": "VEC2"}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": $pos_bytes},
    {"buffer": 0, "byteOffset": $pos_bytes, "byteLength": $uv_bytes}],
  "buffers": [{"uri": "$(basename "$bin")", "byteLength": $((pos_bytes + uv_bytes))}]
}
EOF
}

finish() {
    echo "$PASSED passed, $FAILED failed, $SKIPPED skipped"
    [ "$FAILED" -eq 0 ] || exit 1
    [ "$SKIPPED" -eq 0 ] || exit 77
    exit 0
}
