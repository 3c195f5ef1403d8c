# End-to-end tests of `luxel heightmap`: heights integrated from a normal
# map made by `luxel normalmap` from a Gaussian bump come back as the bump
# (lowest height 0, the bump's rise within the round trip's error); the
# PNG's printed strength makes `luxel normalmap --strength S` give the
# normals back; the same bytes for any --threads; and every bad input:
# exit status 1 (failed run) or 2 (usage error), one "luxel: error:" line
# naming the file or option, and nothing left behind (an existing output
# keeps its old bytes).
#
# Inputs are written here: PFM files with float32 bits made by awk.
#
# usage: bash test_cli_heightmap.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

IN=$WORK/in
mkdir -p "$IN"

# float_pfm FILE W H C AWK_EXPR: a PFM of C channels (1: Pf, 3: PF) whose
# channel c of texel (x, r), r the row from the top, is AWK_EXPR.
float_pfm() {
    local file=$1 w=$2 h=$3 ch=$4 expr=$5
    printf '%s\n%d %d\n-1.0\n' "$([ "$ch" = 1 ] && echo Pf || echo PF)" "$w" "$h" >"$file"
    printf '%b' "$(awk -v w="$w" -v h="$h" -v ch="$ch" '
        function byte(b) { printf "\\0%03o", b }
        function f32(v,   s, e, m, bits, i) {
            if (v == 0) { byte(0); byte(0); byte(0); byte(0); return }
            s = v < 0 ? 1 : 0; if (s) v = -v
            e = 0
            while (v >= 2) { v /= 2; e++ }
            while (v < 1) { v *= 2; e-- }
            m = int((v - 1) * 8388608 + 0.5)
            if (m == 8388608) { m = 0; e++ }
            bits = s * 2147483648 + (e + 127) * 8388608 + m
            for (i = 0; i < 4; i++) { byte(bits % 256); bits = int(bits / 256) }
        }
        BEGIN { for (r = h - 1; r >= 0; r--) for (x = 0; x < w; x++) for (c = 0; c < ch; c++)
                    f32('"$expr"') }')" >>"$file"
}
# the float values of a PFM of N floats, one per line
pfm_values() { tail -c $(($2 * 4)) "$1" | od -An -tf4 -v | tr -s ' ' '\n' | sed '/^$/d'; }
# largest |a - b| over two PFMs of N floats
max_diff() {
    paste <(pfm_values "$1" "$3") <(pfm_values "$2" "$3") |
        awk '{ d = $1 - $2; if (d < 0) d = -d; if (d > m) m = d } END { printf "%.9g\n", m }'
}
# awk -v v=X 'BEGIN { exit !(COND) }' as a check
holds() { awk -v v="$1" "BEGIN { exit !($2) }"; }

W=48
H=36
N=$((W * H))
# a bump of 0.5 on 0.2, sigma 5 texels, centre (22, 17)
float_pfm "$IN/bump.pfm" $W $H 1 '0.2 + 0.5 * exp(-((x - 22)^2 + (r - 17)^2) / 50)'

# ---- help ---------------------------------------------------------------------
run "$LUXEL" heightmap --help
expect_rc 0 "heightmap --help"
expect_stdout_has "heightmap --help shows the usage" "usage: luxel heightmap NORMALS"
run "$LUXEL" --help
expect_stdout_has "luxel --help lists heightmap" "heightmap NORMALS"

# ---- the bump back -----------------------------------------------------------------
run "$LUXEL" normalmap "$IN/bump.pfm" -o "$WORK/n.pfm" --strength 8 --wrap clamp -q
expect_rc 0 "normalmap of the bump"
run "$LUXEL" heightmap "$WORK/n.pfm" -o "$WORK/h.pfm" --wrap clamp
expect_rc 0 "heightmap of the bump's normals"
expect_stdout_has "float output: strength 1 printed" "^strength 1$"
expect_stderr_has "the summary names the size and wrap" "height map 48x36 \(clamp, green up\)"
lo=$(pfm_values "$WORK/h.pfm" $N | sort -g | head -1)
hi=$(pfm_values "$WORK/h.pfm" $N | sort -g | tail -1)
check "the lowest height is 0" holds "$lo" 'v == 0'
# the bump rises 8 * 0.5 (1 - exp(-(26^2 + 18^2)/50)) = 4.0 texels above
# the far corner; the round trip through central differences loses about
# 1% of a sigma-5 peak (measured 3.96)
check "the bump's rise comes back (4.0 texels, within 2.5%)" holds "$hi" 'v > 3.9 && v < 4.02'

# ---- PNG: normalized, strength printed ----------------------------------------------
run "$LUXEL" heightmap "$WORK/n.pfm" -o "$WORK/h16.png" --wrap clamp -q
expect_rc 0 "heightmap to PNG"
depth() { head -c 25 "$1" | tail -c 1 | od -An -tu1 | tr -d ' '; }
check "heightmap: a 16-bit PNG by default" [ "$(depth "$WORK/h16.png")" = 16 ]
S=$(awk '/^strength / { print $2 }' "$OUT")
check "--quiet still prints the strength, the PNG's highest height" holds "$S" \
    "v - $hi < 1e-5 && $hi - v < 1e-5"
run "$LUXEL" normalmap "$WORK/h16.png" --strength "$S" --wrap clamp -o "$WORK/back.pfm" -q
expect_rc 0 "normalmap of the height PNG with the printed strength"
# the normals again, but for 16-bit rounding of the heights and the fit's
# error (measured 0.0042)
d=$(max_diff "$WORK/n.pfm" "$WORK/back.pfm" $((N * 3)))
check "normalmap --strength S gives the normals back (max diff $d < 0.008)" holds "$d" 'v < 0.008'
run "$LUXEL" heightmap "$WORK/n.pfm" -o "$WORK/h8.png" --bits 8 -q
expect_rc 0 "heightmap --bits 8"
check "heightmap --bits 8: an 8-bit PNG" [ "$(depth "$WORK/h8.png")" = 8 ]
expect_stdout_has "--bits 8 prints the strength too" "^strength [0-9.]+$"

# ---- threads, green -----------------------------------------------------------------
run "$LUXEL" heightmap "$WORK/n.pfm" -o "$WORK/t1.pfm" --threads 1 -q
run "$LUXEL" heightmap "$WORK/n.pfm" -o "$WORK/t2.pfm" --threads 2 -q
check "same bytes with 1 and 2 threads" cmp -s "$WORK/t1.pfm" "$WORK/t2.pfm"
run "$LUXEL" normalmap "$IN/bump.pfm" -o "$WORK/nd.pfm" --strength 8 --wrap clamp --green down -q
run "$LUXEL" heightmap "$WORK/nd.pfm" -o "$WORK/hd.pfm" --wrap clamp --green down -q
expect_rc 0 "heightmap --green down"
# the same but for float rounding of the encoded green
d=$(max_diff "$WORK/h.pfm" "$WORK/hd.pfm" $N)
check "a DirectX map read with --green down gives the same heights ($d)" holds "$d" 'v < 1e-4'

# ---- bad input ----------------------------------------------------------------------
run "$LUXEL" heightmap "$IN/missing.png" -o "$WORK/bad1.png"
expect_rc 1 "missing normal map"
expect_error "missing normal map" "missing.png"
check "missing normal map: no output" [ ! -e "$WORK/bad1.png" ]

# rgb 0.5 everywhere decodes to a zero vector: not a normal
float_pfm "$IN/grey.pfm" 4 3 3 '0.5'
echo old >"$WORK/keep.pfm"
run "$LUXEL" heightmap "$IN/grey.pfm" -o "$WORK/keep.pfm"
expect_rc 1 "a texel that is no direction"
expect_error "a texel that is no direction" "grey.pfm"
check "a texel that is no direction: the old output is kept" [ "$(cat "$WORK/keep.pfm")" = old ]

float_pfm "$IN/h1.pfm" 4 3 1 '0.5'
run "$LUXEL" heightmap "$IN/h1.pfm" -o "$WORK/bad2.pfm"
expect_rc 1 "a one-channel image"
expect_error "a one-channel image" "h1.pfm"
check "a one-channel image: no output" [ ! -e "$WORK/bad2.pfm" ]

run "$LUXEL" heightmap "$WORK/n.pfm" -o "$WORK/bad3.png" --wrap tile
expect_rc 2 "--wrap tile"
expect_error "--wrap tile" "--wrap" "tile"
run "$LUXEL" heightmap "$WORK/n.pfm" -o "$WORK/bad4.exr" --bits 16
expect_rc 2 "--bits with exr"
expect_error "--bits with exr" "--bits"
run "$LUXEL" heightmap "$WORK/n.pfm" -o "$WORK/bad5.png" --bits 12
expect_rc 2 "--bits 12"
expect_error "--bits 12" "--bits" "12"
run "$LUXEL" heightmap "$WORK/n.pfm"
expect_rc 2 "no output"
expect_error "no output" "-o OUT"
run "$LUXEL" heightmap "$WORK/n.pfm" "$WORK/n.pfm" -o "$WORK/bad6.png"
expect_rc 2 "an extra input"
expect_error "an extra input" "extra"
run "$LUXEL" heightmap -o "$WORK/bad7.png"
expect_rc 2 "no input"
expect_error "no input" "no normal map"
for f in bad3.png bad4.exr bad5.png bad6.png bad7.png; do
    check "usage errors leave no $f" [ ! -e "$WORK/$f" ]
done

finish
