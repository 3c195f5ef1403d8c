# End-to-end tests of `luxel shade`: a PNG written, the same bytes for any
# --threads, a linear PFM whose centre pixel on a flat height is the
# Lambert value base/pi * E * sin(el) (E = pi, base 0.8, no specular), and
# every bad input: exit status 1 (failed run) or 2 (usage error), one
# "luxel: error:" line naming the file or option, and no output file.
#
# usage: bash test_cli_shade.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

IN=$WORK/in
mkdir -p "$IN"

grey_pfm() {
    local file=$1 w=$2 h=$3
    shift 3
    printf 'Pf\n%d %d\n-1.0\n' "$w" "$h" >"$file"
    local v
    for v in "$@"; do f32 "$v" >>"$file"; done
}
repeat() { local i; for ((i = 0; i < $1; i++)); do printf '%s ' "$2"; done; }
# shellcheck disable=SC2046
grey_pfm "$IN/flat.pfm" 8 8 $(repeat 64 0.5)
# shellcheck disable=SC2046
grey_pfm "$IN/bumpy.pfm" 4 4 0 1 0 1 1 0 1 0 0.5 0 0.5 0 0 0 1 1

run "$LUXEL" shade --help
expect_rc 0 "shade --help"
expect_stdout_has "shade --help shows the usage" "usage: luxel shade"

run "$LUXEL" shade --height "$IN/flat.pfm" -o "$WORK/flat.png" --size 33x33 --quiet
expect_rc 0 "shade a flat height"
check "shade writes a PNG" [ "$(magic "$WORK/flat.png" 8)" = 89504e470d0a1a0a ]

run "$LUXEL" shade --height "$IN/bumpy.pfm" -o "$WORK/t1.png" --size 40x30 -q --threads 1 --shape sphere
run "$LUXEL" shade --height "$IN/bumpy.pfm" -o "$WORK/t2.png" --size 40x30 -q --threads 2 --shape sphere
expect_rc 0 "shade a sphere with 2 threads"
check "shade: the same bytes with 1 and 2 threads" cmp -s "$WORK/t1.png" "$WORK/t2.png"

# the centre pixel of a 33 x 33 linear PFM (row 16 of 33; PFM rows bottom up)
run "$LUXEL" shade --height "$IN/flat.pfm" -o "$WORK/flat.pfm" --size 33x33 -q \
    --light 20,30 --no-specular
expect_rc 0 "shade to PFM"
got=$(tail -c $((33 * 33 * 12)) "$WORK/flat.pfm" | od -An -tf4 -v -j $(((16 * 33 + 16) * 12)) -N 4 | tr -d ' ')
check "flat centre = 0.8 sin(30 deg) (E = pi cancels 1/pi)" \
    awk -v v="$got" 'BEGIN { exit !(v > 0.39999 && v < 0.40001) }'

# ---- bad input -------------------------------------------------------------------
run "$LUXEL" shade --height "$IN/missing.png" -o "$WORK/bad1.png"
expect_rc 1 "missing height image"
expect_error "missing height image" "missing.png"
check "missing height: no output" [ ! -e "$WORK/bad1.png" ]

: >"$IN/empty.png"
run "$LUXEL" shade --normal "$IN/empty.png" -o "$WORK/bad2.png"
expect_rc 1 "zero-size normal image"
expect_error "zero-size normal image" "empty.png"
check "zero-size normal image: no output" [ ! -e "$WORK/bad2.png" ]

run "$LUXEL" shade --height "$IN/flat.pfm" --base-color "$IN/flat.pfm" -o "$WORK/bad3.png"
expect_rc 1 "one-channel base colour"
expect_error "one-channel base colour" "flat.pfm"
check "one-channel base colour: no output" [ ! -e "$WORK/bad3.png" ]

grey_pfm "$IN/nan.pfm" 2 2 0 nan 0.5 1
run "$LUXEL" shade --height "$IN/nan.pfm" -o "$WORK/bad4.png"
expect_rc 1 "NaN height"
expect_error "NaN height" "nan.pfm"
check "NaN height: no output" [ ! -e "$WORK/bad4.png" ]

run "$LUXEL" shade -o "$WORK/bad5.png"
expect_rc 2 "no input"
run "$LUXEL" shade --height "$IN/flat.pfm" --normal "$IN/flat.pfm" -o "$WORK/bad6.png"
expect_rc 2 "both inputs"
run "$LUXEL" shade --height "$IN/flat.pfm" -o "$WORK/bad7.png" --light 10
expect_rc 2 "--light without elevation"
expect_error "--light 10" "--light" "10"
run "$LUXEL" shade --height "$IN/flat.pfm" -o "$WORK/bad8.png" --shape cube
expect_rc 2 "--shape cube"
run "$LUXEL" shade --height "$IN/flat.pfm" -o "$WORK/bad9.png" --size 0x4
expect_rc 2 "--size 0x4"
for f in bad5 bad6 bad7 bad8 bad9; do check "$f: no output" [ ! -e "$WORK/$f.png" ]; done

finish
