# End-to-end tests of `luxel ies`: the printed header, total lumens, peak
# candela and beam angles of hand-written IES files, --plot writing a PNG,
# bad files (exit 1, one error line naming the line, no plot left behind)
# and usage errors (exit 2).
#
# Expected values, worked out by hand: spot.ies is rotationally symmetric,
# 1000 cd from 0 to 20 degrees falling linearly to 0 at 40 degrees. Its
# 50% points are at +-30 degrees, so the beam angle is 60 degrees in every
# plane, and its flux is
#   2 pi 1000 [ (1 - cos a) + cos a - (sin b - sin a) / (b - a) ],
#   a = 20 deg, b = 40 deg (the linear ramp integrated against sin).
# quad.ies has the same C0 plane and a C90 plane 1000 at 0 falling to 0 at
# 20 degrees: 50% at 10 degrees, a 20 degree beam across C90-C270.
# flood.ies is photometric type B, 1000 cd a(V) b(H): a flat to |V| = 20
# falling to 0 at 40, b flat to |H| = 10 falling to 0 at 20 (horizontal
# angles 0..90: mirrored). Converted to type C its C0-C180 plane is V and its
# C90-C270 plane H (docs/ies.md): beams of 60 and 30 degrees. Its flux,
# with dOmega = cos H dH dV, is 1000 (60 deg) 2 (cos 10 - cos 20) / (10 deg).
#
# usage: bash test_cli_ies.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

cat >spot.ies <<'EOF'
IESNA:LM-63-2002
[TEST] luxel cli test
[MANUFAC] luxel
TILT=NONE
1 -1 1 4 1 1 2 0.1 0.1 0.05
1 1 12
0 20 40 90
0
1000 1000 0 0
EOF

cat >quad.ies <<'EOF'
IESNA:LM-63-1995
TILT=NONE
1 1000 1 4 3 1 2 0 0 0
1 1 12
0 20 40 90
0 45 90
1000 1000 0 0
1000 500 0 0
1000 0 0 0
EOF

cat >flood.ies <<'EOF'
IESNA:LM-63-2002
[TEST] luxel cli test, type B
TILT=NONE
1 -1 1 7 4 2 2 0 0 0
1 1 150
-90 -40 -20 0 20 40 90
0 10 20 90
0 0 1000 1000 1000 0 0
0 0 1000 1000 1000 0 0
0 0 0 0 0 0 0
0 0 0 0 0 0 0
EOF

# a number printed on a stdout line "LABEL: <number> ..."
value_of() { awk -F': ' -v k="$1" '$1 == k { split($2, a, " "); print a[1]; exit }' "$OUT"; }
# near GOT WANT RELTOL: |got - want| <= tol |want|
near() { awk -v g="$1" -v w="$2" -v t="$3" 'BEGIN { d = g - w; if (d < 0) d = -d;
    s = w < 0 ? -w : w; exit !(g != "" && d <= t * s) }'; }

# ---- help ------------------------------------------------------------------

run "$LUXEL" ies --help
expect_rc 0 "ies --help"
expect_stdout_has "ies --help: usage on stdout" '^usage: luxel ies FILE'
expect_stdout_has "ies --help documents --plot" '--plot'
check "ies --help: nothing on stderr" test ! -s "$ERR"

run "$LUXEL" --help
expect_stdout_has "luxel --help lists ies" '^ +ies FILE'

# ---- a good file -------------------------------------------------------------

run "$LUXEL" ies spot.ies
expect_rc 0 "ies spot.ies"
check "ies spot.ies: nothing on stderr" test ! -s "$ERR"
expect_stdout_has "version printed" '^version: LM-63-2002$'
expect_stdout_has "keywords printed" '^keyword: \[MANUFAC\] luxel$'
expect_stdout_has "absolute photometry named" '^lumens per lamp: -1 \(absolute photometry\)'
expect_stdout_has "photometric type C" '^photometric type: C$'
expect_stdout_has "symmetry rotational" '^symmetry: rotational$'
expect_stdout_has "angle ranges" '^vertical angles: 4 \(0\.\.90 deg\)$'
want=$(awk 'BEGIN { pi = atan2(0, -1); a = 20 * pi / 180; b = 40 * pi / 180;
    printf "%.6f", 2 * pi * 1000 * ((1 - cos(a)) + cos(a) - (sin(b) - sin(a)) / (b - a)) }')
# lumens printed to 0.001 lm: measured 1.3e-6 relative off, bound 4e-6; the
# peak is the file's own 1000, printed exactly; beam angles are exact
# (test_ies_spread) and printed to 0.1 deg: the printed value must be it
got=$(value_of "total lumens")
check "total lumens $got ~ $want" near "$got" "$want" 4e-6
got=$(value_of "peak candela")
check "peak candela $got = 1000" near "$got" 1000 0
got=$(value_of "beam angle C0-C180")
check "beam angle C0-C180 $got = 60" near "$got" 60 0
got=$(value_of "beam angle C90-C270")
check "beam angle C90-C270 $got = 60" near "$got" 60 0

# luxel info shows a light's profile: a masked 1500 lm point light scales
# the profile by 1500 / its flux.
"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
cat >profiled.json <<'EOF'
{"lights": [{"name": "downlight", "type": "point", "position": [0, 2.9, 0],
  "direction": [0, -1, 0], "ies": "spot.ies", "masked": true, "intensity": 1500, "unit": "lm"}]}
EOF
run "$LUXEL" info "$WORK/scenes/room.glb" --lights profiled.json
expect_rc 0 "info with a profiled light"
expect_stdout_has "info: the profile" 'downlight .* profile LM-63-2002 rotational, '
flux=$(awk 'BEGIN { pi = atan2(0, -1); a = 20 * pi / 180; b = 40 * pi / 180;
    printf "%.6f", 2 * pi * 1000 * ((1 - cos(a)) + cos(a) - (sin(b) - sin(a)) / (b - a)) }')
got=$(sed -n 's/.*profile LM-63-2002 rotational, [0-9.e+]* lm, peak [0-9.e+]* cd x \([0-9.e+-]*\).*/\1/p' "$OUT")
want=$(awk -v f="$flux" 'BEGIN { printf "%.6f", 1500 / f }')
# printed to four digits: half the last one is 2.9e-4 of 1.725 (measured
# 2.2e-4, the rounding)
check "info: profile scale $got ~ 1500 / flux = $want" near "$got" "$want" 2.9e-4

run "$LUXEL" ies quad.ies
expect_rc 0 "ies quad.ies"
expect_stdout_has "version 1995" '^version: LM-63-1995$'
expect_stdout_has "symmetry quadrant" '^symmetry: quadrant$'
got=$(value_of "beam angle C0-C180")
check "quad: beam angle C0-C180 $got = 60" near "$got" 60 0
got=$(value_of "beam angle C90-C270")
check "quad: beam angle C90-C270 $got = 20" near "$got" 20 0

run "$LUXEL" ies flood.ies
expect_rc 0 "ies flood.ies (type B)"
check "ies flood.ies: nothing on stderr" test ! -s "$ERR"
expect_stdout_has "photometric type B" '^photometric type: B$'
expect_stdout_has "type B: the file's angles" '^vertical angles: 7 \(-90\.\.90 deg\)$'
expect_stdout_has "type B: symmetry after conversion" \
    '^symmetry: bilateral 0-180 \(after conversion to type C\)$'
want=$(awk 'BEGIN { r = atan2(0, -1) / 180;
    printf "%.6f", 1000 * 60 * r * 2 * (cos(10 * r) - cos(20 * r)) / (10 * r) }')
# resampled to type C: measured 2.5e-4 relative off, bound 8e-4
got=$(value_of "total lumens")
check "type B: total lumens $got ~ $want" near "$got" "$want" 8e-4
got=$(value_of "peak candela")
check "type B: peak candela $got = 1000" near "$got" 1000 0
got=$(value_of "beam angle C0-C180")
check "type B: beam angle C0-C180 $got = 60" near "$got" 60 0
got=$(value_of "beam angle C90-C270")
check "type B: beam angle C90-C270 $got = 30" near "$got" 30 0
sed 's/^1 -1 1 7 4 2 2 /1 -1 1 7 4 3 2 /' flood.ies >flood_a.ies
run "$LUXEL" ies flood_a.ies
expect_rc 0 "ies flood_a.ies (type A)"
expect_stdout_has "photometric type A" '^photometric type: A$'

# ---- --plot ---------------------------------------------------------------------

mkdir plots
run "$LUXEL" ies quad.ies --plot plots/quad.png
expect_rc 0 "ies --plot"
expect_files "ies --plot writes only the PNG" plots quad.png
check "plot has the PNG signature" test "$(magic plots/quad.png 8)" = 89504e470d0a1a0a
# IHDR: 600 x 660
check "plot is 600 x 660" test "$(head -c 24 plots/quad.png | tail -c 8 | od -An -tx1 | tr -d ' \n')" \
    = 0000025800000294

# ---- bad files: exit 1, one error line, no plot --------------------------------

head -n 8 spot.ies >truncated.ies
printf '1000 1000\n' >>truncated.ies
run "$LUXEL" ies truncated.ies --plot plots/bad.png
expect_rc 1 "truncated file"
expect_error "truncated file" "truncated.ies" "line 9" "expected 4 candela values, found 2"
check "truncated file: no plot" test ! -e plots/bad.png
check "truncated file: nothing on stdout" test ! -s "$OUT"

sed 's/^1000 1000 0 0$/1000 nan 0 0/' spot.ies >nan.ies
run "$LUXEL" ies nan.ies --plot plots/bad.png
expect_rc 1 "NaN candela"
expect_error "NaN candela" "nan.ies" "line 9" "not a finite number"

sed 's/^0 20 40 90$/0 40 20 90/' spot.ies >order.ies
run "$LUXEL" ies order.ies --plot plots/bad.png
expect_rc 1 "angles out of order"
expect_error "angles out of order" "order.ies" "line 7" "out of order"

sed 's/^TILT=NONE$/TILT=lamp.tlt/' spot.ies >tilt.ies
run "$LUXEL" ies tilt.ies --plot plots/bad.png
expect_rc 1 "TILT=<file>"
expect_error "TILT=<file>" "tilt.ies" "line 4" "not supported"

sed 's/^-90 -40 -20 0 20 40 90$/-90 -40 -20 0 20 40 95/' flood.ies >steep.ies
run "$LUXEL" ies steep.ies --plot plots/bad.png
expect_rc 1 "type B vertical angle above 90"
expect_error "type B vertical angle above 90" "steep.ies" "line 6" "outside -90..90"
check "type B vertical angle above 90: no plot" test ! -e plots/bad.png

printf 'just some text\n' >garbage.ies
run "$LUXEL" ies garbage.ies
expect_rc 1 "garbage"
expect_error "garbage" "garbage.ies" "no TILT= line"

run "$LUXEL" ies missing.ies --plot plots/bad.png
expect_rc 1 "missing file"
expect_error "missing file" "missing.ies"
expect_files "bad files left only the good plot" plots quad.png

# ---- usage errors: exit 2 -------------------------------------------------------------

run "$LUXEL" ies
expect_rc 2 "ies without a file"
expect_error "ies without a file" "no IES file given"
run "$LUXEL" ies spot.ies quad.ies
expect_rc 2 "ies with two files"
run "$LUXEL" ies spot.ies --bogus
expect_rc 2 "ies --bogus"
expect_error "ies --bogus" "unknown option '--bogus'"
run "$LUXEL" ies spot.ies --plot
expect_rc 2 "ies --plot without a value"
expect_error "ies --plot without a value" "needs a value"

finish
