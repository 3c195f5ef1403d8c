# End-to-end tests of `luxel ibl`: the files each option writes in each
# layout, values against closed forms (a constant environment L has
# irradiance pi L and SH coefficient L00 = 2 sqrt(pi) L, all others 0;
# every specular level of a constant environment is L), exact round trips
# cross -> faces -> cross and cross -> vertical cross -> faces, KTX headers
# against the KTX 1.1 specification, bit-identical results for any thread
# count, and every bad input: exit status 1 (failed run) or 2
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
expect_stdout_has "ibl --help documents --specular-size" '^ +--specular-size N'
# the defaults it shows are the library's, as ibl.h documents them
expect_stdout_has "ibl --help: the DFG table's default size" 'GGX table, 128x128'
expect_stdout_has "ibl --help: the irradiance's default size" 'irradiance cube, 32x32 faces'
expect_stdout_has "ibl --help: specular level 0 at most 256" "environment's, at most 256\)"
expect_stdout_has "ibl --help: the default samples" '\(default 256 and 1024\)'
expect_stdout_has "ibl --help: the default layout" 'default faces$'
expect_stdout_has "ibl --help: the default format" 'default exr$'
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
    # irradiance pi L = 6.2832 lux (8x8: the size of the environment, at most 32);
    # measured within 9.2e-5 (the split texels under the horizon, float sums), bound 3e-4
    check "const: irradiance_$f = 2 pi" all_near 6.2831853 3e-4 < <(pfm_values "$D/irradiance_$f.pfm" $((8 * 8 * 12)))
    for m in 0 1 2 3; do
        s=$((8 >> m))
        # measured exactly 2: a weighted mean of a constant, whose every term
        # L = 2 scales by a power of two, exactly in float; bound one float
        # ulp of 2 (2.4e-7; 3e-7 for od's 8 printed digits)
        check "const: specular_m${m}_$f = L" all_near 2 3e-7 < <(pfm_values "$D/specular_m${m}_$f.pfm" $((s * s * 12)))
    done
done
# L00 = Y00 * 4 pi * L = 2 sqrt(pi) L = 7.0898154, measured within 5.6e-6
# (float sums, 7 printed digits), bound 2e-5; the other eight are 0,
# measured within 1.3e-16 (the double sums' rounding), bound 5e-16
sh_ok() {
    awk 'BEGIN { RS = "\\]"; n = 0; bad = 0 }
        (n == 0 && /"coefficients"/) || (n > 0 && n < 9) {
            gsub(/.*\[/, ""); split($0, v, ","); 
            if (n == 0) { for (k = 1; k <= 3; k++) if (v[k] < 7.0897954 || v[k] > 7.0898354) bad++ }
            else { for (k = 1; k <= 3; k++) if (v[k] > 5e-16 || v[k] < -5e-16) bad++ }
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
    # measured within 5.4e-6 (float rounding), bound 2e-5
    check "const:0.5 x 4: SH irradiance_$f = 2 pi" all_near 6.2831853 2e-5 < <(pfm_values "$D/irradiance_$f.pfm" $((4 * 4 * 12)))
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
# measured exactly 0.75; bound one float ulp at 0.75 (6e-8; 1e-7 for od's digits)
check "equirect -> cube -> equirect of a constant" all_near 0.75 1e-7 < <(pfm_values "$WORK/eq2/environment.pfm" $((16 * 8 * 12)))

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

# ---- the seam fix and --no-seam-fix --------------------------------------------------------

# texel FILE N X Y: the three floats of texel (x, y), row 0 at the top, of an
# N x N PFM (whose rows are stored bottom first)
texel() { tail -c $(($2 * $2 * 12)) "$1" | od -An -tf4 -v -w12 | sed -n "$((($2 - 1 - $4) * $2 + $3 + 1))p"; }
first() { echo "$1" | awk '{ print $1 }'; }

# A horizontal cross of 4 x 4 faces, each face its own value (as above):
# file rows bottom first, -Y's four rows, the middle four, +Y's four.
row4() { printf '%s ' $(repeat 4 "$1") $(repeat 4 "$2") $(repeat 4 "$3") $(repeat 4 "$4"); }
pfm "$IN/cross4.pfm" 16 12 $(for i in 1 2 3 4; do row4 0 0.125 0 0; done) \
    $(for i in 1 2 3 4; do row4 0.25 0.75 0.5 0.875; done) $(for i in 1 2 3 4; do row4 0 2 0 0; done)
# specular level 0 is the environment itself: without the fix every +X texel
# keeps +X's 0.5 (the filter's value), though +Z across the edge is 0.75
run "$LUXEL" ibl "$IN/cross4.pfm" --specular ggx --mips 1 --irradiance --no-seam-fix --format pfm -q -o "$WORK/nofix"
expect_rc 0 "--no-seam-fix"
check "--no-seam-fix: +X keeps its value at every texel" all_near 0.5 0 < <(pfm_values "$WORK/nofix/specular_m0_px.pfm" $((4 * 4 * 12)))
check "--no-seam-fix: +Z across the edge is 0.75" test "$(first "$(texel "$WORK/nofix/specular_m0_pz.pfm" 4 3 1)")" = 0.75
run "$LUXEL" ibl "$IN/cross4.pfm" --specular ggx --mips 1 --irradiance --format pfm -q -o "$WORK/fix"
expect_rc 0 "the seam fix (default)"
check "seam fix: +X's edge texel by +Z is (0.5 + 0.75) / 2" test "$(first "$(texel "$WORK/fix/specular_m0_px.pfm" 4 0 1)")" = 0.625
check "seam fix: +X's edge texel by +Y is (0.5 + 2) / 2" test "$(first "$(texel "$WORK/fix/specular_m0_px.pfm" 4 1 0)")" = 1.25
check "seam fix: +X's inner texel keeps 0.5" test "$(first "$(texel "$WORK/fix/specular_m0_px.pfm" 4 1 1)")" = 0.5
# irradiance: the unfixed edge texels differ across the edge, the fixed
# ones are their mean, the inner texels are the same either way
a=$(first "$(texel "$WORK/nofix/irradiance_px.pfm" 4 0 2)")
b=$(first "$(texel "$WORK/nofix/irradiance_pz.pfm" 4 3 2)")
m=$(first "$(texel "$WORK/fix/irradiance_px.pfm" 4 0 2)")
check "--no-seam-fix: irradiance differs across the +X/+Z edge ($a, $b)" awk -v a="$a" -v b="$b" 'BEGIN { exit !(a != b) }'
# measured 2.6e-8 relative (float rounding of the mean, od's 8 digits), bound 1e-7
check "seam fix: the edge texel is the mean of the unfixed pair ($m)" awk -v a="$a" -v b="$b" -v m="$m" 'BEGIN { d = m - (a + b) / 2; exit !(d < 1e-7 * m && -d < 1e-7 * m) }'
check "the inner irradiance texels do not change" test "$(texel "$WORK/fix/irradiance_px.pfm" 4 1 2)" = "$(texel "$WORK/nofix/irradiance_px.pfm" 4 1 2)"

# ---- --lut alone: the DFG table against a quadrature -----------------------------------------

run "$LUXEL" ibl const:1 --lut --format pfm -q -o "$WORK/lut"
expect_rc 0 "--lut alone"
expect_files "--lut alone writes only the DFG table" "$WORK/lut" dfg_lut.pfm
check "--lut: 128 x 128" grep -q '^128 128$' "$WORK/lut/dfg_lut.pfm"
# A and B of the split-sum integral at N.V = nv, roughness r: the midpoint
# rule over (cos theta_l, phi_l in [0, pi]) of D G2 (1 - Fc or Fc) / (4 N.V),
# uniform in solid angle (GGX D, Smith's height-correlated G2, Schlick's Fc)
dfg_reference() {
    awk -v nv="$1" -v r="$2" -v nu=128 -v np=256 '
        function lam(c, a2) { return (sqrt(1 + a2 * (1 - c * c) / (c * c)) - 1) / 2 }
        BEGIN {
            pi = atan2(0, -1); a2 = r ^ 4; vx = sqrt(1 - nv * nv); vz = nv; lv = lam(nv, a2)
            for (i = 0; i < nu; i++) {
                cl = (i + 0.5) / nu; sl = sqrt(1 - cl * cl); g = 1 / (1 + lv + lam(cl, a2))
                for (j = 0; j < np; j++) {
                    phi = pi * (j + 0.5) / np; lx = sl * cos(phi); ly = sl * sin(phi)
                    hx = vx + lx; hz = vz + cl; hl = sqrt(hx * hx + ly * ly + hz * hz)
                    nh = hz / hl; vh = (vx * hx + vz * hz) / hl; q = nh * nh * (a2 - 1) + 1
                    f = a2 / (pi * q * q) * g / (4 * nv); fc = (1 - vh) ^ 5
                    sa += (1 - fc) * f; sb += fc * f
                }
            }
            dw = 2 * pi / (nu * np); printf "%.8f %.8f\n", sa * dw, sb * dw
        }'
}
# texels (x, y): N.V = (x + 0.5) / 128, roughness (y + 0.5) / 128; the
# table is within 9.1e-5 of A and 0.18% of B there (the rule's own error
# 3e-5): bounds 3e-4 on A and 0.5% of B
for xy in "40 80" "100 120" "20 64" "64 100"; do
    set -- $xy
    nv=$(awk -v x="$1" 'BEGIN { print (x + 0.5) / 128 }')
    r=$(awk -v y="$2" 'BEGIN { print (y + 0.5) / 128 }')
    got=$(echo $(texel "$WORK/lut/dfg_lut.pfm" 128 "$1" "$2"))
    want=$(dfg_reference "$nv" "$r")
    check "--lut: texel ($1, $2) = ($got) against ($want)" awk -v g="$got" -v w="$want" 'BEGIN {
        split(g, a, " "); split(w, b, " "); da = a[1] - b[1]; db = a[2] - b[2]
        exit !(da < 3e-4 && -da < 3e-4 && db < 0.005 * b[2] && -db < 0.005 * b[2] && a[3] == 0) }'
done

# ---- --specular phong --phong-exponents: each level's lobe --------------------------------

# A cross of 8 x 8 faces, black but for one texel of +Z, (5, 3), of 1 nit:
# each level's texel r is then Omega_b w(r.l_b) / sum_t Omega_t w(r.l_t)
# with w = max(0, r.l)^n for its exponent n, lights below 1e-4 of the peak
# left out; computed here over every source texel (the face table, texel
# centres, exact texel solid angles). At exponents 16 and 4 the lobes are
# wider than a texel, so both levels read the source itself.
pfm "$IN/onelight.pfm" 32 24 $(repeat 397 0) 1 $(repeat 370 0)
run "$LUXEL" ibl "$IN/onelight.pfm" --specular phong --phong-exponents 16,4 --no-seam-fix --format pfm -q -o "$WORK/phong"
expect_rc 0 "--specular phong --phong-exponents 16,4"
want=()
for f in $FACES; do want+=("specular_m0_$f.pfm" "specular_m1_$f.pfm"); done
expect_files "--phong-exponents 16,4: two levels" "$WORK/phong" "${want[@]}"
# phong_level N M FACE: the level of exponent N and face size M, texel values
# in PFM order (bottom row first)
phong_level() {
    awk -v n="$1" -v m="$2" -v face="$3" -v N=8 -v bf=4 -v bx=5 -v by=3 '
        function dir(f, sc, tc, d,   l) {
            if (f == 0) { d[1] = 1; d[2] = -tc; d[3] = -sc }
            else if (f == 1) { d[1] = -1; d[2] = -tc; d[3] = sc }
            else if (f == 2) { d[1] = sc; d[2] = 1; d[3] = tc }
            else if (f == 3) { d[1] = sc; d[2] = -1; d[3] = -tc }
            else if (f == 4) { d[1] = sc; d[2] = -tc; d[3] = 1 }
            else { d[1] = -sc; d[2] = -tc; d[3] = -1 }
            l = sqrt(d[1] * d[1] + d[2] * d[2] + d[3] * d[3]); d[1] /= l; d[2] /= l; d[3] /= l
        }
        function corner(a, b) { return atan2(a * b, sqrt(a * a + b * b + 1)) }
        BEGIN {
            cut = exp(log(1e-4) / n); k = 0
            for (f = 0; f < 6; f++) for (y = 0; y < N; y++) for (x = 0; x < N; x++) {
                dir(f, 2 * (x + 0.5) / N - 1, 2 * (y + 0.5) / N - 1, d)
                lx[k] = d[1]; ly[k] = d[2]; lz[k] = d[3]
                x0 = 2 * x / N - 1; x1 = 2 * (x + 1) / N - 1; y0 = 2 * y / N - 1; y1 = 2 * (y + 1) / N - 1
                om[k] = corner(x0, y0) - corner(x0, y1) - corner(x1, y0) + corner(x1, y1)
                if (f == bf && x == bx && y == by) b = k
                k++
            }
            for (y = m - 1; y >= 0; y--) for (x = 0; x < m; x++) {
                dir(face, 2 * (x + 0.5) / m - 1, 2 * (y + 0.5) / m - 1, r)
                den = 0; num = 0
                for (t = 0; t < k; t++) {
                    c = r[1] * lx[t] + r[2] * ly[t] + r[3] * lz[t]
                    if (c < cut) continue
                    w = om[t] * c ^ n; den += w; if (t == b) num = w
                }
                printf "%.9g\n", num / den
            }
        }'
}
# Measured: within 1.5e-6 relative (the float rounding of c^n), exactly 0
# where the lobe misses the light; bound 5e-6 relative.
phong_ok() { # phong_ok FILE N M FACE
    paste <(pfm_values "$1" $(($3 * $3 * 12)) | awk 'NR % 3 == 1') <(phong_level "$2" "$3" "$4") |
        awk '{ d = $1 - $2; if (d < 0) d = -d; if (d > 5e-6 * $2) bad++; if ($2 > peak) peak = $2 }
             END { exit !(bad == 0 && NR > 0) }'
}
for f in $FACES; do
    i=$(echo "$FACES" | tr ' ' '\n' | grep -n "^$f$" | cut -d: -f1)
    check "--phong-exponents: level 0 face $f is the lobe of exponent 16" phong_ok "$WORK/phong/specular_m0_$f.pfm" 16 8 $((i - 1))
    check "--phong-exponents: level 1 face $f is the lobe of exponent 4" phong_ok "$WORK/phong/specular_m1_$f.pfm" 4 4 $((i - 1))
done
# and the check tells lobes apart: level 0 is not the default's (2048)
not_phong_ok() { ! phong_ok "$@"; }
check "--phong-exponents: level 0 of +Z is not the default lobe of 2048" not_phong_ok "$WORK/phong/specular_m0_pz.pfm" 2048 8 4

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
bad "--specular-size 0" 2 "--specular-size|'0'" const:1 --specular ggx --specular-size 0
bad "--specular-size too large" 2 "--specular-size|99999" const:1 --specular ggx --specular-size 99999
bad "--specular-size not a number" 2 "--specular-size|abc" const:1 --specular ggx --specular-size abc
bad "--specular-size without --specular" 2 "--specular-size|add --specular" const:1 --sh --specular-size 64
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

# paused LABEL PHASE SIGNAL OUTDIR ARGS...: runs `luxel ibl ARGS -o OUTDIR`
# stopped at PHASE by the test hook LUXEL_TEST_PAUSE, runs the function
# named by AT_PAUSE (if set; $pid is the run) there, sends SIGNAL and
# requires the run to end by it (exit status 128 + N) saying it was
# interrupted, with no output folder left.
paused() {
    local label=$1 phase=$2 sig=$3 out=$4 i
    shift 4
    : >"$ERR" # empty before the run starts: a stale "paused" line would send the signal too early
    LUXEL_TEST_PAUSE=$phase "$LUXEL" ibl "$@" -o "$out" >"$OUT" 2>"$ERR" </dev/null &
    pid=$!
    for ((i = 0; i < 6000; i++)); do
        grep -q "^luxel: test: paused at $phase\$" "$ERR" && break
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.01
    done
    if ! grep -q "^luxel: test: paused at $phase\$" "$ERR"; then
        kill -KILL "$pid" 2>/dev/null
        wait "$pid"
        fail "$label: the run never reached '$phase' (exit $?)"
        show_stderr
        return 1
    fi
    pass "$label: reaches '$phase'"
    [ -n "${AT_PAUSE:-}" ] && "$AT_PAUSE"
    kill -"$sig" "$pid"
    wait "$pid"
    RC=$?
    expect_rc $((128 + $(kill -l "$sig"))) "$label: ended by SIG$sig"
    expect_error "$label" "interrupted"
    expect_no_output "$label" "$out"
}

# ---- memory: a run that cannot fit fails before it starts ---------------------------

# 15 Phong lobes of exponent 1e6 each take the whole 16384^2 environment
# as their lights: far more memory than any machine has. The library
# refuses it on the sizes alone, so the run fails at once, naming the GiB,
# before the 18 GiB environment is made.
E15=1e6$(for i in $(seq 14); do printf ',1e6'; done)
bad "a run that needs more memory than the machine" 1 "const:1|prefilter: a 16384 x 16384 source (18.0 GiB)|GiB of memory, " \
    const:1 --size 16384 --specular phong --phong-exponents "$E15" --specular-size 16384

# ---- upsampling: a warning at once, naming the memory ----------------------------------

# a 16 x 8 equirect holds 4 x 4 faces of detail: 64 x 64 faces upsample it
# 16x; the warning comes before the resampling starts (it is on stderr when
# the run reaches its first progress report)
pfm "$IN/small_eq.pfm" 16 8 $(repeat 128 0.5)
upsample_warned() {
    expect_stderr_has "upsampling: warned before the work" "^luxel: warning: .*small_eq.pfm: 64 x 64 faces from a 16 x 8 equirect upsample it 16x: the .*MiB cube map"
}
AT_PAUSE=upsample_warned paused "upsampling, interrupted" environment INT "$WORK/out_upsample" \
    "$IN/small_eq.pfm" --size 64 --irradiance=sh
run "$LUXEL" ibl const:1 --size 16 --specular ggx --specular-size 128 --samples 16 -o "$WORK/up_spec"
expect_rc 0 "--specular-size 8x the environment"
expect_stderr_has "--specular-size 8x: a warning" "^luxel: warning: prefilter: 128 x 128 specular faces from a 16 x 16 source upsample it 8x"

# ---- every phase: threads bounded, progress reported, an interrupt obeyed -----------------

# A 64 x 32 equirect, all of it filtered: LUXEL_TEST_PAUSE stops the run at
# the first progress report of each phase, and a SIGINT there must end it
# with nothing written. At the last phase ("write", after the first file
# is staged) every phase has run: with --threads 1 the process must never
# have started a second thread (OpenMP keeps the threads it starts).
pfm "$IN/eq64.pfm" 64 32 $(repeat 2048 0.5)
# threads_now: the run's thread count at the pause
threads_now() { awk '/^Threads:/ { print $2 }' "/proc/$pid/status" 2>/dev/null; }
one_thread() {
    local n
    n=$(threads_now)
    check "--threads 1: one thread through every phase (now $n)" test "$n" = 1
}
two_threads() {
    local n
    n=$(threads_now)
    check "--threads 2: at most two threads (now $n)" test "$n" -le 2
}
for phase in environment sh irradiance specular dfg write; do
    hook=
    [ "$phase" = write ] && hook=one_thread
    AT_PAUSE=$hook paused "phase $phase, SIGINT" "$phase" INT "$WORK/out_phase_$phase" \
        "$IN/eq64.pfm" --threads 1
done
# --threads 2 bounds the process at two threads (whether OpenMP started
# the second one for these small loops is its business)
AT_PAUSE=two_threads paused "--threads 2, SIGINT at write" write INT "$WORK/out_threads2" \
    "$IN/eq64.pfm" --threads 2

# ---- interrupts while writing many files: nothing left behind ----------------------------

# six faces per cube: SIGTERM once the first is staged removes them all and
# the folder the run made (a SIGINT while filtering is in test_cli_interrupt.sh)
paused "SIGTERM while writing faces" write TERM "$WORK/out_int_write" \
    const:1 --size 64 --environment --irradiance=sh --layout faces

finish
