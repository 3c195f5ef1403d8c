# cases: main strict
# End-to-end checks of small CLI behaviours met running luxel on real files:
# --quiet and warnings, numbers printed as people write them, `luxel ies`
# reporting beam angles only in planes that carry the peak and a labelled
# plot, `luxel info` with IES lights and without assimp's unused
# DefaultMaterial, --ambient L, --texel-density with --resolution, trailing
# commas in JSON named, --pre-expose metering by itself, the --half overflow
# naming --pre-expose, and stale files of earlier bakes (--clean).
#
# Expected values come from closed forms worked out here:
# - an unshadowed constant ambient of E lux is E on every covered texel;
# - the meter (reflected light, K = 12.5) gives EV100 = log2(L * 100 / 12.5)
#   for the average luminance L = E / pi of a white surface, and
#   pre-exposure is 1 / (1.2 * 2^EV100) (Filament);
# - peak.ies (quadrant symmetric, 200 cd at the nadir, 1000 cd at 30 deg in
#   the C45 plane only, 0 from 60 deg; 100 cd at 30 deg in C0 and C90) has
#   its peak in C45-C225 alone; linear between the angles, that plane falls
#   to 500 cd at 30 + 15 = 45 deg outward and at 30 - 18.75 = 11.25 deg
#   toward the nadir (1000 - 800 t = 500): beam 33.75 deg.
# - washer.ies (1000 cd at 30 deg in C0, at most 100 cd in C90-C270) has no
#   beam angle in C90-C270, whose maximum is 10% of the peak.
#
# usage: bash test_cli_polish.sh LUXEL GEN_SCENES WORKDIR [main|strict]
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

# a floor triangle facing up (+Y), its UVs inside [0,1]
write_gltf alpha.gltf floor alpha "0 0 0  0 0 1  1 0 0" "0 0  0 1  1 0"
write_gltf beta.gltf floor beta "0 0 0  0 0 1  1 0 0" "0 0  0 1  1 0"

# The largest value of a PFM file (header of three lines, then float32).
pfm_max() {
    local skip
    skip=$(head -3 "$1" | wc -c)
    tail -c +$((skip + 1)) "$1" | od -An -v -tf4 | awk '{for (i = 1; i <= NF; i++) if ($i > m) m = $i} END {printf "%.9g\n", m}'
}
# A number field of a JSON manifest (one "key": value per line, cJSON style).
json_num() { sed -n "s/^[[:space:]]*\"$2\":[[:space:]]*\([-0-9.eE+]*\).*/\1/p" "$1" | head -1; }
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN {d = a - b; if (d < 0) d = -d; exit !(d <= t * (b < 0 ? -b : b) + 1e-30)}'; }

# the case "strict" alone: it skips while bake has no --strict
if [ "$CASE_NAME" = strict ]; then
    run "$LUXEL" bake alpha.gltf --ambient 1,1,1 --resolution 8 -q --strict -o "$WORK/dark_s"
    expect_rc 1 "--quiet --strict: the warning fails the bake"
    expect_stderr_has "--quiet --strict still shows the warning" '^luxel: warning: .*TEXCOORD_0'
    check "--quiet --strict: nothing written" test ! -e "$WORK/dark_s"
    finish
fi

# ---- --quiet and warnings -------------------------------------------------
# a mesh without TEXCOORD_1: "its lightmap uses TEXCOORD_0" is a warning
run "$LUXEL" bake alpha.gltf --ambient 1,1,1 --resolution 8 -o "$WORK/dark"
expect_rc 0 "a bake on TEXCOORD_0"
expect_stderr_has "without --quiet the warning prints" '^luxel: warning: .*TEXCOORD_0'
run "$LUXEL" bake alpha.gltf --ambient 1,1,1 --resolution 8 -q -o "$WORK/dark_q"
expect_rc 0 "--quiet bake on TEXCOORD_0"
check "--quiet silences the warning" test ! -s "$ERR"
run "$LUXEL" bake alpha.gltf --resolution 8 -q --lights "$WORK/missing.json" -o "$WORK/dark_e"
expect_rc 1 "--quiet with a missing lights file"
expect_error "--quiet still prints errors" "missing.json"
# ---- numbers for humans -----------------------------------------------------
run "$LUXEL" bake alpha.gltf --resolution 8 --ambient 1 -o "$WORK/one"
expect_rc 0 "one lightmap"
expect_stderr_has "one lightmap is singular" 'baked 1 lightmap \('
expect_stderr_has "no lights is plural" ', 0 lights\)'
run "$LUXEL" bake alpha.gltf --texel-density 1000 --ambient 1 -v -o "$WORK/density"
expect_rc 0 "--texel-density 1000"
check "no six-decimal or exponent numbers on stderr" \
    bash -c "! grep -Eq '[0-9]\.[0-9]{6}|[0-9]e[-+][0-9]' '$ERR'"

# ---- luxel ies: planes that carry the peak, the plot ------------------------
cat >peak.ies <<'EOF'
IESNA:LM-63-2002
[TEST] peak in C45
TILT=NONE
1 1000 1 4 3 1 2 0 0 0
1 1 10
0 30 60 90
0 45 90
200 100 0 0
200 1000 0 0
200 100 0 0
EOF
run "$LUXEL" ies peak.ies --plot "$WORK/peak.png"
expect_rc 0 "ies with the peak in C45"
expect_stdout_has "the C45-C225 plane's beam angle (33.75 deg)" '^beam angle C45-C225: 33\.75 deg$'
expect_stdout_has "C0-C180 is named as not carrying the peak" '^plane C0-C180: maximum 200 cd, 20% of the peak: no beam or field angle$'
check "no beam angle for C0-C180 or C90-C270" \
    bash -c "! grep -Eq '^(beam|field) angle C(0-C180|90-C270)' '$OUT'"
expect_stdout_has "lumens per lamp as written" '^lumens per lamp: 1000$'
expect_stdout_has "multiplier as written" '^candela multiplier: 1$'
check "the plot is a 600 x 660 PNG" test "$(magic "$WORK/peak.png" 24 | cut -c33-48)" = "0000025800000294"

cat >washer.ies <<'EOF'
IESNA:LM-63-2002
[TEST] wall washer
TILT=NONE
1 -1 1 4 3 1 2 0 0 0
1 1 10
0 30 60 90
0 90 180
50 1000 0 0
50 100 0 0
50 100 0 0
EOF
run "$LUXEL" ies washer.ies
expect_rc 0 "ies wall washer"
expect_stdout_has "C0-C180 carries the peak: a beam angle" '^beam angle C0-C180: '
expect_stdout_has "C90-C270 is 10% of the peak" '^plane C90-C270: maximum 100 cd, 10% of the peak'
check "no beam angle for C90-C270" bash -c "! grep -q '^beam angle C90-C270' '$OUT'"

# ---- luxel info: IES peak, no unused DefaultMaterial ------------------------
cat >ies_light.json <<'EOF'
{"lights": [{"type": "point", "position": [0, 2, 0], "ies": "peak.ies"}]}
EOF
run "$LUXEL" info alpha.gltf --lights ies_light.json
expect_rc 0 "info with an IES light"
expect_stdout_has "info shows the profile's peak candela" 'peak 1000 cd'
printf 'newmtl red\nKd 1 0 0\n' >red.mtl
printf 'mtllib red.mtl\nv 0 0 0\nv 0 0 1\nv 1 0 0\nvt 0 0\nvt 0 1\nvt 1 0\nusemtl red\nf 1/1 2/2 3/3\n' >red.obj
run "$LUXEL" info red.obj
expect_rc 0 "info on an OBJ with one material"
expect_stdout_has "one material listed" '^materials: 1$'
check "no unused DefaultMaterial" bash -c "! grep -q DefaultMaterial '$OUT'"
printf 'v 0 0 0\nv 0 0 1\nv 1 0 0\nf 1 2 3\n' >plain.obj
run "$LUXEL" info plain.obj
expect_stdout_has "a DefaultMaterial a mesh uses is listed" '^  DefaultMaterial'

# ---- --ambient L --------------------------------------------------------------
for form in 100 100,100,100 const:100; do
    run "$LUXEL" bake alpha.gltf --resolution 8 --padding 0 --format pfm --ambient "$form" -q -o "$WORK/amb_$form"
    expect_rc 0 "--ambient $form"
done
check "--ambient 100 is --ambient 100,100,100" cmp -s "$WORK/amb_100/alpha.pfm" "$WORK/amb_100,100,100/alpha.pfm"
check "--ambient const:100 is the same" cmp -s "$WORK/amb_100/alpha.pfm" "$WORK/amb_const:100/alpha.pfm"
check "covered texels hold 100 lx" near "$(pfm_max "$WORK/amb_100/alpha.pfm")" 100 1e-6
run "$LUXEL" bake alpha.gltf --ambient -1 -o "$WORK/amb_bad"
expect_rc 2 "--ambient -1"
expect_error "--ambient -1 is a usage error" "--ambient"

# ---- --texel-density with --resolution ----------------------------------------
run "$LUXEL" bake alpha.gltf --texel-density 10 --resolution 64 -o "$WORK/both"
expect_rc 2 "--texel-density with --resolution"
expect_error "--texel-density with --resolution: usage error" "--resolution" "--texel-density"
expect_no_output "--texel-density with --resolution" "$WORK/both"

# ---- trailing commas ----------------------------------------------------------
printf '{"lights": [\n  {"type": "point",\n   "position": [0, 2, 0],\n   "intensity": 100,\n  }]}\n' >trailing.json
run "$LUXEL" bake alpha.gltf --lights trailing.json -o "$WORK/trailing"
expect_rc 1 "a lights file with a trailing comma"
expect_error "the trailing comma is named with its line" "trailing.json: line 4: trailing comma before '}'"
expect_no_output "trailing comma" "$WORK/trailing"

# ---- --pre-expose without --exposure meters -------------------------------------
run "$LUXEL" bake alpha.gltf --resolution 8 --padding 0 --format pfm --ambient 100000 --pre-expose -q -o "$WORK/pre"
expect_rc 0 "--pre-expose without --exposure"
ev=$(json_num "$WORK/pre/manifest.json" preview_ev100)
pe=$(json_num "$WORK/pre/manifest.json" pre_exposure)
want_ev=$(awk 'BEGIN {printf "%.9g", log(100000 / 3.14159265358979 * 100 / 12.5) / log(2)}')
check "the metered EV100 is log2(E/pi x 100/12.5) ($want_ev)" near "$ev" "$want_ev" 1e-5
want_pe=$(awk -v e="$ev" 'BEGIN {printf "%.9g", 1 / (1.2 * 2 ^ e)}')
check "pre_exposure is 1/(1.2 x 2^EV100)" near "$pe" "$want_pe" 1e-5
check "the file holds E x pre_exposure" near "$(pfm_max "$WORK/pre/alpha.pfm")" "$(awk -v p="$pe" 'BEGIN {printf "%.9g", 100000 * p}')" 1e-5

# ---- --half overflow -------------------------------------------------------------
run "$LUXEL" bake alpha.gltf --resolution 8 --ambient 100000 --half -o "$WORK/half"
expect_rc 1 "--half with 100000 lx"
expect_error "the half overflow suggests --pre-expose" "alpha.exr" "65504" "--pre-expose"
expect_no_output "--half overflow" "$WORK/half"
run "$LUXEL" bake alpha.gltf --resolution 8 --ambient 100000 --half --pre-expose -q -o "$WORK/half_pre"
expect_rc 0 "--half --pre-expose with 100000 lx"

# ---- stale files of an earlier bake ------------------------------------------------
D=$WORK/stale
run "$LUXEL" bake alpha.gltf --resolution 8 --ambient 1 -q -o "$D"
expect_rc 0 "bake alpha"
echo "mine" >"$D/notes.txt"
run "$LUXEL" bake beta.gltf --resolution 8 --ambient 1 -o "$D"
expect_rc 0 "bake beta into alpha's folder"
expect_stderr_has "one warning names alpha's files and scene" \
    "^luxel: warning: .*holds 2 files of an earlier bake of alpha.gltf .*alpha.exr, alpha.png.*--clean"
check "one warning about them" test "$(grep -c '^luxel: warning: .*earlier bake' "$ERR")" -eq 1
expect_files "without --clean the old files stay" "$D" alpha.exr alpha.png beta.exr beta.png manifest.json notes.txt
run "$LUXEL" bake beta.gltf --resolution 8 --ambient 1 --clean -o "$D"
expect_rc 0 "bake beta --clean"
check "--clean does not warn about them" bash -c "! grep -q '^luxel: warning: .*earlier bake' '$ERR'"
expect_files "--clean removes alpha's files only (the manifest remembered them)" "$D" beta.exr beta.png manifest.json notes.txt
# a broken manifest: stale files are not checked, the reason named
printf '{"scene": "x.gltf",\n "pages": [],\n}\n' >"$D/manifest.json"
run "$LUXEL" bake beta.gltf --resolution 8 --ambient 1 -o "$D"
expect_rc 0 "bake over a manifest with a trailing comma"
expect_stderr_has "the old manifest's trailing comma is named" "manifest.json: line 2: trailing comma before '}'"

finish
