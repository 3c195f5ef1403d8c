# End-to-end tests of `luxel horizonmap` and `luxel aomap`: the files each
# writes, values against closed forms (a flat height field has no horizon:
# codes 0 and an ambient factor of exactly 1; on a step, the top of the
# wall and texels a radius or more from it see nothing higher, the texel
# at its foot does), the same bytes for any --threads, and every bad
# input: exit status 1 (failed run) or 2 (usage error), one
# "luxel: error:" line naming the file or option, and nothing left behind
# (an existing output folder keeps its old files).
#
# Inputs are written here: PFM files byte by byte with common.sh's f32
# (rows in file order, bottom row first). Float values are read back with
# od -tf4.
#
# usage: bash test_cli_horizon.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

IN=$WORK/in
mkdir -p "$IN"

# grey_pfm FILE W H V...: a one-channel PFM (Pf), W*H values in file order
grey_pfm() {
    local file=$1 w=$2 h=$3
    shift 3
    printf 'Pf\n%d %d\n-1.0\n' "$w" "$h" >"$file"
    local v
    for v in "$@"; do f32 "$v" >>"$file"; done
}
repeat() { local i; for ((i = 0; i < $1; i++)); do printf '%s ' "$2"; done; }
# the float values of a one-channel PFM of N texels, one per line
pfm_values() { tail -c $(($2 * 4)) "$1" | od -An -tf4 -v | tr -s ' ' '\n' | sed '/^$/d'; }

# shellcheck disable=SC2046
grey_pfm "$IN/flat.pfm" 12 9 $(repeat 108 0.5)
# a step: columns 16.. are 1, the rest 0 (24 x 3)
row=$(printf '%s' "$(repeat 16 0)$(repeat 8 1)")
# shellcheck disable=SC2086
grey_pfm "$IN/step.pfm" 24 3 $row $row $row

# ---- help ---------------------------------------------------------------
for cmd in horizonmap aomap; do
    run "$LUXEL" $cmd --help
    expect_rc 0 "$cmd --help"
    expect_stdout_has "$cmd --help shows the usage" "usage: luxel $cmd HEIGHT"
done

# ---- horizonmap outputs ----------------------------------------------------
run "$LUXEL" horizonmap "$IN/flat.pfm" -o "$WORK/flat" --quiet
expect_rc 0 "horizonmap of a flat field"
expect_files "horizonmap writes its three files" "$WORK/flat" horizon0.png horizon1.png \
    horizon-weights.exr
check "horizon0.png is a PNG" [ "$(magic "$WORK/flat/horizon0.png" 8)" = 89504e470d0a1a0a ]
check "horizon-weights.exr is an EXR" [ "$(magic "$WORK/flat/horizon-weights.exr" 4)" = 762f3101 ]
# the same bytes for any thread count
run "$LUXEL" horizonmap "$IN/step.pfm" -o "$WORK/t1" --threads 1 -q --wrap clamp --strength 2
run "$LUXEL" horizonmap "$IN/step.pfm" -o "$WORK/t2" --threads 2 -q --wrap clamp --strength 2
for f in horizon0.png horizon1.png horizon-weights.exr; do
    check "$f: same bytes with 1 and 2 threads" cmp -s "$WORK/t1/$f" "$WORK/t2/$f"
done

# ---- aomap values ------------------------------------------------------------
run "$LUXEL" aomap "$IN/flat.pfm" -o "$WORK/flat-ao.pfm" --power 3 --quiet
expect_rc 0 "aomap of a flat field"
check "a flat field's ambient factor is 1 everywhere (the mean, not the sum)" \
    [ "$(pfm_values "$WORK/flat-ao.pfm" 108 | sort -u)" = 1 ]
run "$LUXEL" aomap "$IN/step.pfm" -o "$WORK/step-ao.pfm" --wrap clamp --strength 2 --cosine -q
expect_rc 0 "aomap of a step"
# first row of the file (all rows alike): x = 0 (16 texels from the wall:
# out of the default radius 16) and x >= 16 (the wall's top) are 1; x = 15,
# at the wall's foot, is less
vals=($(pfm_values "$WORK/step-ao.pfm" 72 | head -24))
check "step: the texel a radius from the wall sees nothing higher" [ "${vals[0]}" = 1 ]
check "step: the wall's top sees nothing higher" [ "$(printf '%s\n' "${vals[@]:16}" | sort -u)" = 1 ]
check "step: the foot of the wall is occluded" awk -v v="${vals[15]}" 'BEGIN { exit !(v < 0.9) }'
run "$LUXEL" aomap "$IN/flat.pfm" -o "$WORK/flat-ao.png" -q
check "aomap writes a PNG" [ "$(magic "$WORK/flat-ao.png" 8)" = 89504e470d0a1a0a ]
# PNG bit depth: byte 25 of the file (IHDR's bit depth, after the 8-byte
# signature, the chunk's length and type, width and height)
depth() { head -c 25 "$1" | tail -c 1 | od -An -tu1 | tr -d ' '; }
check "aomap: 8-bit PNG by default" [ "$(depth "$WORK/flat-ao.png")" = 8 ]
run "$LUXEL" aomap "$IN/flat.pfm" -o "$WORK/flat-ao16.png" -q --bits 16
expect_rc 0 "aomap --bits 16"
check "aomap --bits 16: a 16-bit PNG" [ "$(depth "$WORK/flat-ao16.png")" = 16 ]
# the 16-bit file is one luxel reads again
run "$LUXEL" aomap "$WORK/flat-ao16.png" -o "$WORK/reread.pfm" -q
check "a 16-bit PNG luxel wrote loads back as a height image" [ "$RC" -eq 0 ]
run "$LUXEL" horizonmap "$IN/step.pfm" -o "$WORK/h16" -q --bits 16
expect_rc 0 "horizonmap --bits 16"
for f in horizon0.png horizon1.png; do
    check "horizonmap --bits 16: $f is a 16-bit PNG" [ "$(depth "$WORK/h16/$f")" = 16 ]
done
run "$LUXEL" aomap "$IN/flat.pfm" -o "$WORK/bad5.png" --bits 12
expect_rc 2 "--bits 12"
expect_error "--bits 12" "--bits" "12"

# ---- bad input -------------------------------------------------------------------
run "$LUXEL" horizonmap "$IN/missing.png" -o "$WORK/bad1"
expect_rc 1 "missing height image"
expect_error "missing height image" "missing.png"
expect_no_output "missing height image" "$WORK/bad1"

: >"$IN/empty.png"
run "$LUXEL" aomap "$IN/empty.png" -o "$WORK/bad2.png"
expect_rc 1 "zero-size height image"
expect_error "zero-size height image" "empty.png"
check "zero-size height image: no output" [ ! -e "$WORK/bad2.png" ]

printf '\x89PNG\r\n\x1a\n\x00\x00\x00\x0dIHDR\x00\x00' >"$IN/cut.png"
run "$LUXEL" horizonmap "$IN/cut.png" -o "$WORK/bad3"
expect_rc 1 "truncated PNG"
expect_error "truncated PNG" "cut.png"
expect_no_output "truncated PNG" "$WORK/bad3"

grey_pfm "$IN/nan.pfm" 2 2 0 nan 0.5 1
mkdir -p "$WORK/keep" && echo old >"$WORK/keep/horizon0.png"
run "$LUXEL" horizonmap "$IN/nan.pfm" -o "$WORK/keep"
expect_rc 1 "NaN height"
expect_error "NaN height" "nan.pfm"
check "NaN height: the old output is kept" [ "$(cat "$WORK/keep/horizon0.png")" = old ]
expect_files "NaN height: nothing else in the folder" "$WORK/keep" horizon0.png

for bad in 8 24 48 abc; do
    run "$LUXEL" horizonmap "$IN/flat.pfm" -o "$WORK/bad4" --angles "$bad"
    expect_rc 2 "--angles $bad"
    expect_error "--angles $bad" "--angles" "$bad"
    expect_no_output "--angles $bad" "$WORK/bad4"
done
run "$LUXEL" aomap "$IN/flat.pfm" -o "$WORK/bad5.png" --angles 20
expect_rc 2 "aomap --angles 20"
expect_error "aomap --angles 20" "--angles" "20"
run "$LUXEL" aomap "$IN/flat.pfm" -o "$WORK/bad5.png" --wrap tile
expect_rc 2 "--wrap tile"
expect_error "--wrap tile" "--wrap" "tile"
run "$LUXEL" aomap "$IN/flat.pfm" -o "$WORK/bad5.txt"
expect_rc 2 "aomap to .txt"
expect_error "aomap to .txt" "bad5.txt"
run "$LUXEL" aomap "$IN/flat.pfm" -o "$WORK/bad5.png" --power -1
expect_rc 2 "--power -1"
run "$LUXEL" horizonmap "$IN/flat.pfm" -o "$WORK/bad6" --power 2
expect_rc 2 "horizonmap does not take --power"
expect_error "horizonmap --power" "--power"
run "$LUXEL" horizonmap "$IN/flat.pfm"
expect_rc 2 "horizonmap without -o"
run "$LUXEL" aomap -o "$WORK/bad5.png"
expect_rc 2 "aomap without a height image"
check "no aomap output after the usage errors" [ ! -e "$WORK/bad5.png" ]

finish
