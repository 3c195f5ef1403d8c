# End-to-end tests of `luxel ibl`: the files each option writes in each
# layout, values against closed forms (a constant environment L has
# irradiance pi L and SH coefficient L00 = 2 sqrt(pi) L, all others 0;
# every specular level of a constant environment is L), exact round trips
# cross -> faces -> cross and cross -> vertical cross -> faces, KTX headers
# against the KTX 1.1 specification, bit-identical results for any thread
# count, and every bad input of the issue: exit status 1 (failed run) or 2
# (usage error), one "luxel: error:" line naming the file or option, and
# no file left behind (an existing output folder keeps its old files).
#
# Inputs are written here: PFM files byte by byte with the float32 values
# of common.sh's f32 (rows in file order, bottom row first), constant
# environments as const:R,G,B. Float values are read back with od -tf4.
#
# usage: bash test_cli_ibl.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

IN=$WORK/in
mkdir -p "$IN" "$WORK/out"

# pfm FILE W H V...: an RGB PFM whose W*H pixels are grey V (one value per
# pixel, file order: bottom row first) - or per channel when 3*W*H values.
pfm() {
    local file=$1 w=$2 h=$3
    shift 3
    printf 'PF\n%d %d\n-1.0\n' "$w" "$h" >"$file"
    local v
    if [ $# -eq $((w * h)) ]; then
        for v in "$@"; do f32 "$v" >>"$file"; f32 "$v" >>"$file"; f32 "$v" >>"$file"; done
    else
        for v in "$@"; do f32 "$v" >>"$file"; done
    fi
}

# repeat N V: V printed N times
repeat() { local i; for ((i = 0; i < $1; i++)); do printf '%s ' "$2"; done; }

# the pixel data of a PFM (its last W*H*12 bytes), as hex
pfm_data() { tail -c "$2" "$1" | od -An -tx1 | tr -d ' \n'; }

# all float32 values of a PFM's data (W*H*3 of them), one per line
pfm_values() { tail -c "$2" "$1" | od -An -tf4 -v | tr -s ' ' '\n' | sed '/^$/d'; }

# every value within tol of want
all_near() { # all_near WANT TOL < values
    awk -v w="$1" -v t="$2" 'BEGIN { bad = 0; n = 0 }
        { n++; d = $1 - w; if (d < 0) d = -d; if (d > t || $1 != $1 + 0) bad++ }
        END { exit !(n > 0 && bad == 0) }'
}

CASE=0
# bad LABEL STATUS "NEEDLE|NEEDLE..." ARGS...: `luxel ibl ARGS -o DIR` must
# exit with STATUS, print one error line holding every needle and leave DIR
# missing.
bad() {
    local label=$1 status=$2 needles=$3
    shift 3
    CASE=$((CASE + 1))
    local out=$WORK/out/case$CASE
    run "$LUXEL" ibl "$@" -o "$out"
    expect_rc "$status" "$label"
    local list=()
    IFS='|' read -ra list <<<"$needles"
    expect_error "$label" "${list[@]}"
    expect_no_output "$label" "$out"
}

FACES="px nx py ny pz nz"

# ---- help ------------------------------------------------------------------------

run "$LUXEL" ibl --help
expect_rc 0 "ibl --help"
expect_stdout_has "ibl --help: usage on stdout" '^usage: luxel ibl ENV'
expect_stdout_has "ibl --help documents const:" 'const:R,G,B'
expect_stdout_has "ibl --help documents --layout" '--layout'
check "ibl --help: nothing on stderr" test ! -s "$ERR"
run "$LUXEL" --help
expect_stdout_has "luxel --help lists ibl" '^ +ibl ENV'

# ---- a constant environment: closed forms -------------------------------------------

D=$WORK/const
run "$LUXEL" ibl const:2,2,2 --size 8 --format pfm --samples 64 -o "$D"
expect_rc 0 "const:2,2,2 default outputs"
want=(dfg_lut.pfm sh.json)
for f in $FACES; do
    want+=("irradiance_$f.pfm")
    for m in 0 1 2 3; do want+=("specular_m${m}_$f.pfm"); done
done
expect_files "const:2,2,2: irradiance, sh, specular (4 levels of 8), lut" "$D" "${want[@]}"
for f in $FACES; do
    # irradiance pi L = 6.2832 lux (8x8: the size of the environment, at most 32)
    check "const: irradiance_$f = 2 pi" all_near 6.2831853 0.001 < <(pfm_values "$D/irradiance_$f.pfm" $((8 * 8 * 12)))
    for m in 0 1 2 3; do
        s=$((8 >> m))
        check "const: specular_m${m}_$f = L" all_near 2 0.0005 < <(pfm_values "$D/specular_m${m}_$f.pfm" $((s * s * 12)))
    done
done
# L00 = Y00 * 4 pi * L = 2 sqrt(pi) L = 7.0898; the other eight are 0
sh_ok() {
    awk 'BEGIN { RS = "\\]"; n = 0; bad = 0 }
        (n == 0 && /"coefficients"/) || (n > 0 && n < 9) {
            gsub(/.*\[/, ""); split($0, v, ","); 
            if (n == 0) { for (k = 1; k <= 3; k++) if (v[k] < 7.0888 || v[k] > 7.0908) bad++ }
            else { for (k = 1; k <= 3; k++) if (v[k] > 1e-4 || v[k] < -1e-4) bad++ }
            n++ }
        END { exit !(n == 9 && bad == 0) }' "$1"
}
check "const: sh.json L00 = 2 sqrt(pi) L, others 0" sh_ok "$D/sh.json"
check "const: sh.json order 2" grep -q '"order":[[:space:]]*2' "$D/sh.json"
check "const: sh.json has the five constants" grep -q '"irradiance_constants":[[:space:]]*\[0.429043, 0.511664, 0.743125, 0.886227, 0.247708\]' "$D/sh.json"
check "const: sh.json has a convention" grep -q '"convention":' "$D/sh.json"
# the DFG table: 128x128, scale + bias in [0, 1]
check "const: dfg_lut.pfm is 128x128" grep -q '^128 128$' "$D/dfg_lut.pfm"
expect_stdout_has "const: lists the files on stdout" "^$D/sh.json$"

# const:L is grey; --intensity scales it; --irradiance=sh from the SH terms
D=$WORK/const_sh
run "$LUXEL" ibl const:0.5 --intensity 4 --size 4 --irradiance=sh --format pfm -q -o "$D"
expect_rc 0 "const:0.5 --intensity 4 --irradiance=sh"
check "--quiet: nothing on stdout" test ! -s "$OUT"
check "--quiet: nothing on stderr" test ! -s "$ERR"
expect_files "--irradiance=sh alone" "$D" irradiance_px.pfm irradiance_nx.pfm irradiance_py.pfm \
    irradiance_ny.pfm irradiance_pz.pfm irradiance_nz.pfm
for f in $FACES; do
    check "const:0.5 x 4: SH irradiance_$f = 2 pi" all_near 6.2831853 0.001 < <(pfm_values "$D/irradiance_$f.pfm" $((4 * 4 * 12)))
done

# ---- layouts: exact round trips -----------------------------------------------------

# A horizontal cross with face size 2 (8x6), each face its own value:
# +X 0.5, -X 0.25, +Y 2, -Y 0.125, +Z 0.75, -Z 0.875, empty cells 0.
# File rows bottom first: rows 0-1 hold -Y, rows 2-3 -X +Z +X -Z, rows 4-5 +Y.
Y0="0 0 0.125 0.125 0 0 0 0"
MID="0.25 0.25 0.75 0.75 0.5 0.5 0.875 0.875"
Y1="0 0 2 2 0 0 0 0"
pfm "$IN/cross.pfm" 8 6 $Y0 $Y0 $MID $MID $Y1 $Y1
D=$WORK/faces
run "$LUXEL" ibl "$IN/cross.pfm" --environment --layout faces --format pfm -o "$D"
expect_rc 0 "cross -> faces"
expect_files "cross -> faces: six environment faces" "$D" environment_px.pfm environment_nx.pfm \
    environment_py.pfm environment_ny.pfm environment_pz.pfm environment_nz.pfm
face_value() { case $1 in px) echo 0.5 ;; nx) echo 0.25 ;; py) echo 2 ;; ny) echo 0.125 ;; pz) echo 0.75 ;; nz) echo 0.875 ;; esac; }
for f in $FACES; do
    pfm "$IN/want_$f.pfm" 2 2 $(repeat 4 "$(face_value $f)")
    check "cross -> faces: face $f holds $(face_value $f)" test "$(pfm_data "$D/environment_$f.pfm" 48)" = "$(pfm_data "$IN/want_$f.pfm" 48)"
done
D2=$WORK/cross_again
run "$LUXEL" ibl "$D/environment_px.pfm" --environment --layout cross --format pfm -o "$D2"
expect_rc 0 "faces -> cross"
check "cross -> faces -> cross is exact" test "$(pfm_data "$D2/environment.pfm" 576)" = "$(pfm_data "$IN/cross.pfm" 576)"
D3=$WORK/vcross
run "$LUXEL" ibl "$IN/cross.pfm" --environment --layout vcross --format pfm -o "$D3"
expect_rc 0 "cross -> vertical cross"
check "vertical cross is 6x8" grep -q '^6 8$' "$D3/environment.pfm"
run "$LUXEL" ibl "$D3/environment.pfm" --environment --layout faces --format exr -o "$D3/faces"
expect_rc 0 "vertical cross -> faces (exr)"
run "$LUXEL" ibl "$D3/faces/environment_px.exr" --environment --layout cross --format pfm -o "$D3/back"
expect_rc 0 "exr faces -> cross"
check "cross -> vcross -> exr faces -> cross is exact" test "$(pfm_data "$D3/back/environment.pfm" 576)" = "$(pfm_data "$IN/cross.pfm" 576)"
# an equirect of a constant stays constant; its cube is width/4
pfm "$IN/eq.pfm" 16 8 $(repeat 128 0.75)
run "$LUXEL" ibl "$IN/eq.pfm" --environment --layout cross --format pfm -o "$WORK/eq"
expect_rc 0 "equirect -> cross"
check "equirect 16x8 -> cross 16x12" grep -q '^16 12$' "$WORK/eq/environment.pfm"
run "$LUXEL" ibl "$IN/eq.pfm" --environment --layout equirect --format pfm -o "$WORK/eq2"
expect_rc 0 "equirect -> equirect"
check "equirect -> cube -> equirect of a constant" all_near 0.75 1e-6 < <(pfm_values "$WORK/eq2/environment.pfm" $((16 * 8 * 12)))

# ---- KTX ------------------------------------------------------------------------------

u32() { od -An -tu4 -j "$2" -N 4 "$1" | tr -d ' '; } # little-endian machine
D=$WORK/ktx
run "$LUXEL" ibl const:1,0.5,0.25 --size 16 --specular ggx --mips 3 --samples 16 --irradiance --layout ktx -o "$D"
expect_rc 0 "--layout ktx"
expect_files "ktx: one file per cube" "$D" irradiance.ktx specular.ktx
K=$D/specular.ktx
check "ktx: identifier" test "$(magic "$K" 12)" = "ab4b5458203131bb0d0a1a0a"
check "ktx: endianness 0x04030201" test "$(magic "$K" 16 | tail -c 8)" = "01020304"
check "ktx: glType FLOAT" test "$(u32 "$K" 16)" = $((0x1406))
check "ktx: glTypeSize 4" test "$(u32 "$K" 20)" = 4
check "ktx: glFormat RGBA" test "$(u32 "$K" 24)" = $((0x1908))
check "ktx: glInternalFormat RGBA32F" test "$(u32 "$K" 28)" = $((0x8814))
check "ktx: glBaseInternalFormat RGBA" test "$(u32 "$K" 32)" = $((0x1908))
check "ktx: 16 x 16" test "$(u32 "$K" 36)-$(u32 "$K" 40)-$(u32 "$K" 44)" = "16-16-0"
check "ktx: 6 faces, 3 levels" test "$(u32 "$K" 48)-$(u32 "$K" 52)-$(u32 "$K" 56)" = "0-6-3"
KV=$(u32 "$K" 60)
check "ktx: file size = header + key/values + levels" test "$(stat -c %s "$K")" = $((64 + KV + 3 * 4 + 6 * 16 * (256 + 64 + 16)))
check "ktx: level 0 imageSize is one face" test "$(u32 "$K" $((64 + KV)))" = $((16 * 16 * 16))
check "ktx: irradiance has one level" test "$(u32 "$D/irradiance.ktx" 56)" = 1
run "$LUXEL" ibl const:1 --size 8 --specular ggx --samples 16 --layout ktx --half -o "$WORK/ktx16"
expect_rc 0 "--layout ktx --half"
K=$WORK/ktx16/specular.ktx
check "ktx --half: glType HALF_FLOAT" test "$(u32 "$K" 16)" = $((0x140B))
check "ktx --half: glInternalFormat RGBA16F" test "$(u32 "$K" 28)" = $((0x881A))
check "ktx --half: 4 levels down to 1x1" test "$(u32 "$K" 56)" = 4
# a constant 1 is 0x3C00 in every channel of the first texel
KV=$(u32 "$K" 60)
check "ktx --half: 1.0 is 0x3c00" test "$(od -An -tx1 -j $((64 + KV + 4)) -N 8 "$K" | tr -d ' \n')" = "003c003c003c003c"

# ---- determinism ------------------------------------------------------------------------

run "$LUXEL" ibl "$IN/cross.pfm" --size 8 --samples 32 --format pfm --threads 1 -q -o "$WORK/t1"
expect_rc 0 "--threads 1"
run "$LUXEL" ibl "$IN/cross.pfm" --size 8 --samples 32 --format pfm --threads 2 -q -o "$WORK/t2"
expect_rc 0 "--threads 2"
same=0
for f in "$WORK"/t1/*; do cmp -s "$f" "$WORK/t2/$(basename "$f")" || same=1; done
check "--threads 1 and 2 give identical files" test "$same" -eq 0

# ---- bad input: files ---------------------------------------------------------------------

bad "missing file" 1 "missing.hdr" "$IN/missing.hdr"
head -c 3000 /dev/urandom >"$IN/noise.hdr"
bad "random bytes named .hdr" 1 "noise.hdr" "$IN/noise.hdr"
head -c 300 "$IN/eq.pfm" >"$IN/cut.pfm"
bad "truncated PFM" 1 "cut.pfm" "$IN/cut.pfm"
pfm "$IN/wide.pfm" 12 4 $(repeat 48 1)
bad "3:1 image (not a 2:1 equirect)" 1 "wide.pfm|12x4|2:1" "$IN/wide.pfm"
pfm "$IN/flat.pfm" 10 6 $(repeat 60 1)
bad "5:3 image (not a 4:3 cross)" 1 "flat.pfm|10x6|4:3" "$IN/flat.pfm"
for f in $FACES; do pfm "$IN/sky_$f.pfm" 2 2 1 1 1 1; done
pfm "$IN/sky_ny.pfm" 1 1 1
bad "faces of unequal sizes" 1 "sky_ny.pfm|differ in size" "$IN/sky_px.pfm"
pfm "$IN/sky_ny.pfm" 2 1 1 1
bad "a face that is not square" 1 "sky_ny.pfm|square" "$IN/sky_px.pfm"
rm "$IN/sky_ny.pfm"
bad "a missing face" 1 "sky_ny.pfm" "$IN/sky_px.pfm"
# 2 NaN texels, 1 infinite and 1 negative in an 8x4 equirect
pfm "$IN/nan.pfm" 8 4 $(repeat 5 1) nan 1 1 inf $(repeat 10 1) -1 nan $(repeat 11 1)
bad "NaN, infinite and negative texels" 1 "nan.pfm|3 texels are NaN or infinite and 1 texel is negative" "$IN/nan.pfm"

# ---- bad input: options ---------------------------------------------------------------------

bad "--size 0" 2 "--size" const:1 --size 0
bad "--size too large" 2 "--size|99999" const:1 --size 99999
bad "--size not a number" 2 "--size|abc" const:1 --size abc
bad "--mips 0" 2 "--mips" const:1 --specular ggx --mips 0
bad "--mips 99" 2 "--mips" const:1 --specular ggx --mips 99
bad "--mips more than the size allows" 2 "--mips 6|only 5 levels" const:1 --size 16 --specular ggx --mips 6
bad "--mips without --specular" 2 "--specular" const:1 --sh --mips 3
bad "--phong-exponents with ggx" 2 "--specular phong" const:1 --specular ggx --phong-exponents 64,8
bad "--phong-exponents not numbers" 2 "--phong-exponents|64,x" const:1 --specular phong --phong-exponents 64,x
bad "--phong-exponents and --mips disagree" 2 "--mips 3|2 Phong" const:1 --specular phong --mips 3 --phong-exponents 64,8
bad "--specular unknown" 2 "--specular|blinn" const:1 --specular blinn
bad "--irradiance=unknown" 2 "--irradiance|fast" const:1 --irradiance=fast
bad "--layout unknown" 2 "--layout|sphere" const:1 --layout sphere
bad "--format unknown" 2 "--format|tiff" const:1 --format tiff
bad "--half with hdr" 2 "--half" const:1 --half --format hdr
bad "--intensity negative" 2 "--intensity|-1" const:1 --intensity -1
bad "--intensity nan" 2 "--intensity|nan" const:1 --intensity nan
bad "--samples 0" 2 "--samples" const:1 --specular ggx --samples 0
bad "--threads 0" 2 "--threads" const:1 --threads 0
bad "malformed const:" 2 "const:1,x" const:1,x
bad "negative const:" 2 "const:-1,1,1" const:-1,1,1
bad "unknown option" 2 "--frobnicate" const:1 --frobnicate
bad "two environments" 2 "extra" const:1 const:2
run "$LUXEL" ibl
expect_rc 2 "no environment"
expect_error "no environment" "no environment"

# ---- failures while writing: nothing half-written, old files kept ---------------------------

bad "KTX half overflow" 1 "specular.ktx|65504" const:70000 --size 4 --specular ggx --samples 4 --layout ktx --half
D=$WORK/keep
run "$LUXEL" ibl const:1 --size 4 --sh -q -o "$D"
expect_rc 0 "a first run"
cp "$D/sh.json" "$WORK/sh.before"
run "$LUXEL" ibl const:70000 --size 4 --sh --specular ggx --samples 4 --layout ktx --half -o "$D"
expect_rc 1 "a failing second run into the same folder"
expect_error "a failing second run" "65504"
expect_files "the failing run left the folder as it was" "$D" sh.json
check "the old sh.json is unchanged" cmp -s "$D/sh.json" "$WORK/sh.before"
printf 'x' >"$WORK/afile"
run "$LUXEL" ibl const:1 --size 4 --sh -o "$WORK/afile"
expect_rc 1 "-o names a file"
expect_error "-o names a file" "afile"

# ---- interrupts: nothing left behind ------------------------------------------------------

wait_for() { # polls every 10 ms for up to 30 s
    local i
    for ((i = 0; i < 3000; i++)); do
        "$@" && return 0
        sleep 0.01
    done
    return 1
}
has_files() { [ -d "$1" ] && [ "$(find "$1" -type f | wc -l)" -ge "$2" ]; }
# interrupted LABEL OUTDIR ALL: after a signal, a non-zero exit, a message
# and an empty folder - or, if the run won the race, all ALL files.
interrupted() {
    if [ "$RC" -eq 0 ]; then
        check "$1: finished before the signal, with all $3 files" test "$(ls -A "$2" | wc -l)" -eq "$3"
        return
    fi
    pass "$1: exit status $RC (non-zero)"
    expect_stderr_has "$1: says it was interrupted" '^luxel: error: .*interrupt'
    expect_no_output "$1" "$2"
}
out=$WORK/out_int_compute
"$LUXEL" ibl const:1 --size 256 --specular ggx --samples 65536 --threads 2 -o "$out" >"$OUT" 2>"$ERR" &
pid=$!
sleep 0.3
kill -INT "$pid"
wait "$pid"
RC=$?
interrupted "SIGINT while filtering" "$out" 54
out=$WORK/out_int_write
"$LUXEL" ibl const:1 --size 1024 --environment --irradiance=sh --layout faces -o "$out" >"$OUT" 2>"$ERR" &
pid=$!
if wait_for has_files "$out" 3; then
    kill -TERM "$pid" 2>/dev/null
    wait "$pid"
    RC=$?
    interrupted "SIGTERM while writing (after 3 files)" "$out" 12
else
    kill -KILL "$pid" 2>/dev/null
    wait "$pid"
    fail "SIGTERM while writing: luxel ibl never started writing"
fi

finish
