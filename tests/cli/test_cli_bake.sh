# End-to-end tests of `luxel bake` on the example scenes: the files it
# writes and their containers (EXR, PFM, Radiance HDR, PNG), the manifest,
# --texel-density sizing, determinism across thread counts, the lights
# JSON (docs/lights-json.md) and --quantity radiance.
#
# Expected values come from outside the baker: file format specifications
# (magic numbers, the PFM header), the generator's description of its scenes
# (examples/gen_scenes.c: node names, areas, the boxes' white 0.8 albedo),
# the texel-density rule R^2 * uv_area = T^2 * world_area with uv_area <= 1,
# and radiance = irradiance * albedo / pi for a Lambertian surface.
#
# usage: bash test_cli_bake.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
RETRO=$WORK/scenes/retro.glb
NODES="room tall_box short_box"

# manifest_get FILE NODE KEY: the value of KEY for NODE (docs/manifest.md):
# from its entry in "nodes", or, for a key of its page (file, preview,
# width, height, used_texels, overlap_texels), from "pages"[its page].
# cJSON prints one key per line; node entries start with "node", pages
# with "file".
manifest_get() {
    case $3 in
    file | preview | width | height | used_texels | overlap_texels)
        local page
        page=$(manifest_get "$1" "$2" page)
        [ -n "$page" ] || return 0
        awk -v want="$page" -v key="$3" '
            /"pages":/ { inside = 1; k = -1 }
            /"nodes":/ { inside = 0 }
            inside && /"file":/ { k++ }
            inside && k == want && $0 ~ "\"" key "\":" {
                v = $0; sub(/^[^:]*:[ \t]*/, "", v); sub(/,?[ \t]*$/, "", v); gsub(/"/, "", v)
                print v; exit
            }' "$1"
        ;;
    *)
        awk -v node="$2" -v key="$3" '
            /"node":/ { cur = $0; sub(/.*"node":[ \t]*"/, "", cur); sub(/".*/, "", cur) }
            cur == node && $0 ~ "\"" key "\":" {
                v = $0; sub(/^[^:]*:[ \t]*/, "", v); sub(/,?[ \t]*$/, "", v); gsub(/"/, "", v)
                print v; exit
            }' "$1"
        ;;
    esac
}

# ---- the default: EXR plus PNG previews plus manifest --------------------

run "$LUXEL" bake "$ROOM" --resolution 128 -o "$WORK/exr"
expect_rc 0 "bake room.glb"
expect_files "bake room.glb writes a lightmap and a preview per node and a manifest" \
    "$WORK/exr" room.exr room.png tall_box.exr tall_box.png short_box.exr short_box.png \
    manifest.json
expect_stdout_has "bake prints the manifest's path" "exr/manifest\.json$"
check "bake: no error or warning for room.glb" test -z "$(grep -E '^luxel: (error|warning)' "$ERR")"
for n in $NODES; do
    # OpenEXR magic 76 2f 31 01, PNG signature 89 50 4e 47 0d 0a 1a 0a
    check "$n.exr is an OpenEXR file" test "$(magic "$WORK/exr/$n.exr" 4)" = "762f3101"
    check "$n.png is a PNG file" test "$(magic "$WORK/exr/$n.png" 8)" = "89504e470d0a1a0a"
done

M=$WORK/exr/manifest.json
check "manifest: quantity irradiance" grep -Eq '"quantity":[[:space:]]*"irradiance"' "$M"
check "manifest: unit lx" grep -Eq '"unit":[[:space:]]*"lx"' "$M"
check "manifest: format exr" grep -Eq '"format":[[:space:]]*"exr"' "$M"
check "manifest: three entries" test "$(grep -c '"node":' "$M")" -eq 3
for n in $NODES; do
    check "manifest: node $n" grep -Eq "\"node\":[[:space:]]*\"$n\"" "$M"
    check "manifest: $n file $n.exr" test "$(manifest_get "$M" "$n" file)" = "$n.exr"
    check "manifest: $n preview $n.png" test "$(manifest_get "$M" "$n" preview)" = "$n.png"
    check "manifest: $n width 128" test "$(manifest_get "$M" "$n" width)" = 128
    check "manifest: $n height 128" test "$(manifest_get "$M" "$n" height)" = 128
    check "manifest: $n uv_set TEXCOORD_1" test "$(manifest_get "$M" "$n" uv_set)" = TEXCOORD_1
done

run "$LUXEL" bake "$ROOM" --resolution 128 -o "$WORK/exr" -q
expect_rc 0 "bake again into the same folder"
check "bake -q: nothing on stderr" test ! -s "$ERR"
expect_files "baking again replaces the files" "$WORK/exr" room.exr room.png tall_box.exr \
    tall_box.png short_box.exr short_box.png manifest.json

run "$LUXEL" bake "$ROOM" --resolution 32 -q -o "$WORK/deep/er/folder"
expect_rc 0 "bake -o into a folder that does not exist yet"
check "the nested output folder was created" test -f "$WORK/deep/er/folder/manifest.json"

mkdir "$WORK/cwd" && cd "$WORK/cwd" && run "$LUXEL" bake "$ROOM" --resolution 32 -q
cd "$WORK" || exit 1
expect_rc 0 "bake without -o"
check "bake without -o writes ./lightmaps" test -f "$WORK/cwd/lightmaps/manifest.json"

mkdir -p "$WORK/my scenes" && cp "$ROOM" "$WORK/my scenes/the room.glb"
run "$LUXEL" bake "$WORK/my scenes/the room.glb" --resolution 16 -q -o "$WORK/with space/out"
expect_rc 0 "bake a scene whose path has spaces, into a folder with a space"
check "paths with spaces: the manifest is written" test -f "$WORK/with space/out/manifest.json"

# Node names become file names: one that climbs out of the folder must not.
mkdir -p "$WORK/escape"
write_gltf "$WORK/escape/scene.gltf" quad "../../x" "0 0 0  0 0 1  1 0 1" "0 0  0 1  1 1" || exit 1
run "$LUXEL" bake "$WORK/escape/scene.gltf" --resolution 16 --ambient 1,1,1 -q -o "$WORK/escape/a/b"
expect_rc 0 "a node named '../../x'"
check "'../../x': three files, all inside the output folder" \
    test "$(ls -A "$WORK/escape/a/b" | wc -l)" -eq 3
check "'../../x': nothing written beside the output folder" \
    test "$(ls -A "$WORK/escape" | LC_ALL=C sort | tr '\n' ' ')" = "a scene.bin scene.gltf "
check "'../../x': nothing written two levels up" test "$(ls -A "$WORK/escape/a")" = "b"

# ---- other formats ------------------------------------------------------------

run "$LUXEL" bake "$ROOM" --resolution 128 --format pfm -q -o "$WORK/pfm"
expect_rc 0 "--format pfm"
expect_files "--format pfm: .pfm, .png preview and manifest" "$WORK/pfm" room.pfm room.png \
    tall_box.pfm tall_box.png short_box.pfm short_box.png manifest.json
check "manifest: format pfm" grep -Eq '"format":[[:space:]]*"pfm"' "$WORK/pfm/manifest.json"
for n in $NODES; do
    f=$WORK/pfm/$n.pfm
    # PFM: "PF\n" (colour), "W H\n", then the scale, negative for little-endian
    check "$n.pfm starts with PF / 128 128" test "$(head -n 2 "$f" | tr '\n' '|')" = "PF|128 128|"
    scale=$(head -n 3 "$f" | tail -n 1)
    check "$n.pfm scale '$scale' is negative (little-endian)" \
        awk -v s="$scale" 'BEGIN { exit !(s ~ /^-[0-9.]+$/ && s + 0 < 0) }'
    hdr=$(head -n 3 "$f" | wc -c)
    check "$n.pfm holds exactly 128*128 RGB float32 after its header" \
        test "$(stat -c %s "$f")" -eq $((hdr + 128 * 128 * 3 * 4))
done

run "$LUXEL" bake "$ROOM" --resolution 64 --format hdr -q -o "$WORK/hdr"
expect_rc 0 "--format hdr"
expect_files "--format hdr: .hdr, .png preview and manifest" "$WORK/hdr" room.hdr room.png \
    tall_box.hdr tall_box.png short_box.hdr short_box.png manifest.json
for n in $NODES; do
    check "$n.hdr starts with #?RADIANCE" test "$(head -n 1 "$WORK/hdr/$n.hdr")" = "#?RADIANCE"
    check "$n.hdr has the size line -Y 64 +X 64" grep -aq '^-Y 64 +X 64$' "$WORK/hdr/$n.hdr"
done

run "$LUXEL" bake "$ROOM" --resolution 64 --format png -q -o "$WORK/png"
expect_rc 0 "--format png"
expect_files "--format png writes no separate preview" "$WORK/png" room.png tall_box.png \
    short_box.png manifest.json
check "--format png: the manifest lists no preview" \
    test -z "$(grep '"preview"' "$WORK/png/manifest.json")"
for n in $NODES; do
    check "$n.png (format png) is a PNG" test "$(magic "$WORK/png/$n.png" 8)" = "89504e470d0a1a0a"
done

run "$LUXEL" bake "$ROOM" --resolution 64 --half -q -o "$WORK/half"
expect_rc 0 "--half"
check "--half writes EXR" test "$(magic "$WORK/half/room.exr" 4)" = "762f3101"

# ---- texel density -----------------------------------------------------------

run "$LUXEL" bake "$ROOM" --texel-density 13 -q -o "$WORK/td13"
expect_rc 0 "--texel-density 13"
run "$LUXEL" bake "$ROOM" --texel-density 26 -q -o "$WORK/td26"
expect_rc 0 "--texel-density 26"
# world areas (gen_scenes.c): room 4x4 floor + 4x4 ceiling + three 4x3 walls
# = 68 m^2; tall box 1.2x1.8x1.2 = 2*1.44 + 4*2.16 = 11.52 m^2; cube 0.9 m
# = 6*0.81 = 4.86 m^2. With uv_area <= 1: R >= T * sqrt(world_area).
for spec in room:68 tall_box:11.52 short_box:4.86; do
    n=${spec%%:*} area=${spec#*:}
    w13=$(manifest_get "$WORK/td13/manifest.json" "$n" width)
    h13=$(manifest_get "$WORK/td13/manifest.json" "$n" height)
    w26=$(manifest_get "$WORK/td26/manifest.json" "$n" width)
    check "--texel-density: $n width $w13 is a multiple of 4" test $((w13 % 4)) -eq 0
    check "--texel-density: $n height $h13 is a multiple of 4" test $((h13 % 4)) -eq 0
    check "--texel-density: $n width $w26 (T=26) is a multiple of 4" test $((w26 % 4)) -eq 0
    check "--texel-density 13: $n width $w13 >= 13 * sqrt($area)" \
        awk -v w="$w13" -v a="$area" 'BEGIN { exit !(w >= 13 * sqrt(a) - 1e-9) }'
    # R is proportional to T; each size is rounded to a multiple of 4
    check "--texel-density: doubling T doubles $n's size ($w13 -> $w26)" \
        test $((w26 - 2 * w13)) -le 4 -a $((w26 - 2 * w13)) -ge -4
done
check "--texel-density: the room (68 m^2) gets more texels than the cube (4.86 m^2)" \
    test "$(manifest_get "$WORK/td13/manifest.json" room width)" -gt \
    "$(manifest_get "$WORK/td13/manifest.json" short_box width)"

run "$LUXEL" bake "$ROOM" --texel-density 1000 --max-resolution 64 -q -o "$WORK/tdcap"
expect_rc 0 "--texel-density 1000 --max-resolution 64"
for n in $NODES; do
    w=$(manifest_get "$WORK/tdcap/manifest.json" "$n" width)
    check "--max-resolution 64 caps $n at 64 (got $w)" test "$w" -eq 64
done

run "$LUXEL" bake "$RETRO" --texel-density 8 -o "$WORK/retro"
expect_rc 0 "bake retro.glb --texel-density 8"
RN="ground pillar_0 pillar_1 pillar_2 pillar_3 wall stair gate"
want=(manifest.json)
for n in $RN; do want+=("$n.exr" "$n.png"); done
expect_files "retro: a lightmap and a preview for each of the 8 nodes" "$WORK/retro" "${want[@]}"
g=$(manifest_get "$WORK/retro/manifest.json" ground width)
check "retro: the 24 m ground gets >= 8*24 = 192 texels a side (got $g)" test "$g" -ge 192
check "retro: the ground's size $g is a multiple of 4" test $((g % 4)) -eq 0
expect_stderr_has "retro: the summary counts 8 lightmaps and 3 lights" \
    'baked 8 lightmaps .* 3 lights'

# ---- determinism --------------------------------------------------------------

for fmt in exr pfm; do
    run "$LUXEL" bake "$ROOM" --resolution 96 --format $fmt --threads 1 -q -o "$WORK/t1_$fmt"
    expect_rc 0 "--threads 1 --format $fmt"
    run "$LUXEL" bake "$ROOM" --resolution 96 --format $fmt --threads 2 -q -o "$WORK/t2_$fmt"
    expect_rc 0 "--threads 2 --format $fmt"
    run "$LUXEL" bake "$ROOM" --resolution 96 --format $fmt --threads 2 -q -o "$WORK/t2b_$fmt"
    for n in $NODES; do
        check "--threads 1 and 2 give byte-identical $n.$fmt" \
            cmp -s "$WORK/t1_$fmt/$n.$fmt" "$WORK/t2_$fmt/$n.$fmt"
        check "two runs give byte-identical $n.$fmt" \
            cmp -s "$WORK/t2_$fmt/$n.$fmt" "$WORK/t2b_$fmt/$n.$fmt"
        check "--threads 1 and 2 give byte-identical $n.png" \
            cmp -s "$WORK/t1_$fmt/$n.png" "$WORK/t2_$fmt/$n.png"
    done
done

# ---- lights JSON ---------------------------------------------------------------

# The example of docs/lights-json.md: a "key" point light, a spot with
# blurred shadows, a directional sun and a classic-model point light with
# its own ambient, plus scene ambient.
cat >"$WORK/lights.json" <<'EOF'
{"ambient": [0.02, 0.02, 0.02],
 "lights": [
   {"name": "key", "type": "point", "position": [0, 2, 0], "color": [1, 1, 1],
    "intensity": 800, "unit": "cd", "range": 10, "shadow": "hard", "dynamic": false},
   {"type": "spot", "position": [0, 3, 0], "direction": [0, -1, 0],
    "inner_angle": 20, "outer_angle": 30,
    "intensity": 1200, "unit": "cd", "shadow": "blur", "blur_power": 1.0, "blur_multiplier": 1.0},
   {"type": "directional", "direction": [0.3, -1, 0.2], "intensity": 100000, "unit": "lx",
    "shadow": "hard"},
   {"type": "point", "position": [2, 1, 0], "intensity": 1, "range": 5, "model": "classic",
    "ambient": [0.1, 0, 0]}]}
EOF
run "$LUXEL" info "$ROOM" --lights "$WORK/lights.json"
expect_rc 0 "info --lights (example)"
expect_stdout_has "info --lights: 2 scene + 4 file lights" '^lights: 6$'
expect_stdout_has "info --lights: key, 800 cd, range 10 m" '^ +point +key +800 cd .*at \(0, 2, 0\).*range 10 m'
expect_stdout_has "info --lights: spot with blurred shadows, cone 20..30 deg" \
    '^ +spot +([^ ]+ +)?1200 cd .*cone 20\.0\.\.30\.0 deg.*shadow blur'
expect_stdout_has "info --lights: the sun in lux" '^ +directional .* lx '
expect_stdout_has "info --lights: the classic light" 'classic'
expect_stdout_has "info --lights: scene ambient" '^ambient: \(0\.02, 0\.02, 0\.02\) lx'
expect_stdout_has "info --lights: the glTF lights stay" '^ +point +ceiling_lamp +150 cd'

run "$LUXEL" bake "$ROOM" --resolution 64 --lights "$WORK/lights.json" -o "$WORK/lights"
expect_rc 0 "bake --lights (example)"
expect_stderr_has "bake --lights: the summary counts 6 lights" 'baked 3 lightmaps .* 6 lights'
check "bake --lights wrote the manifest" test -f "$WORK/lights/manifest.json"
run "$LUXEL" bake "$ROOM" --resolution 64 -q -o "$WORK/nolights"
check "bake --lights: the file's lights change the lightmap" \
    test -n "$(cmp -s "$WORK/lights/room.exr" "$WORK/nolights/room.exr" || echo differs)"

# a light named like a glTF light replaces it (only the keys given change)
cat >"$WORK/spot.json" <<'EOF'
{"lights": [{"name": "spot", "type": "spot", "position": [0, 2.5, 0], "direction": [0, -1, 0],
             "inner_angle": 10, "outer_angle": 25, "intensity": 777, "unit": "cd"}]}
EOF
run "$LUXEL" info "$ROOM" --lights "$WORK/spot.json"
expect_rc 0 "info --lights (replacing spot)"
expect_stdout_has "the replaced scene still has 2 lights" '^lights: 2$'
expect_stdout_has "'spot' now has the file's values" \
    '^ +spot +spot +777 cd .*at \(0, 2\.5, 0\).*toward \(0, -1, 0\).*cone 10\.0\.\.25\.0 deg'
check "the glTF's 400 cd spot is gone" test -z "$(grep -E ' 400 cd' "$OUT")"
run "$LUXEL" bake "$ROOM" --resolution 32 --lights "$WORK/spot.json" -q -o "$WORK/spot"
expect_rc 0 "bake --lights (replacing spot)"

# an override that names only some keys keeps the rest (docs/lights-json.md)
printf '{"lights": [{"name": "ceiling_lamp", "intensity": 300, "shadow": "blur"}]}\n' \
    >"$WORK/lamp.json"
run "$LUXEL" info "$ROOM" --lights "$WORK/lamp.json"
expect_rc 0 "info --lights (partial override of ceiling_lamp)"
expect_stdout_has "ceiling_lamp: new intensity and shadows, same place, colour and range" \
    '^ +point +ceiling_lamp +300 cd +colour \(1, 0\.95, 0\.85\) +at \(0, 2\.7, 0\) +range 12 m +shadow blur'
expect_stdout_has "the partial override adds no light" '^lights: 2$'

# ---- radiance ------------------------------------------------------------------

# (--no-stitch: seam stitching solves each file's seams from its own
# values, exact only to the solver's precision, which dark texels beside
# bright ones feel beyond this bound)
run "$LUXEL" bake "$ROOM" --resolution 64 --format pfm -q --no-stitch -o "$WORK/irr"
expect_rc 0 "--quantity irradiance (explicit default) as pfm"
run "$LUXEL" bake "$ROOM" --resolution 64 --format pfm --quantity radiance -q --no-stitch \
    -o "$WORK/rad"
expect_rc 0 "--quantity radiance"
check "manifest: quantity radiance" grep -Eq '"quantity":[[:space:]]*"radiance"' "$WORK/rad/manifest.json"
check "manifest: radiance in nits" grep -Eq '"unit":[[:space:]]*"(nt|nits|cd/m2)"' "$WORK/rad/manifest.json"
# The boxes are white with albedo 0.8 (gen_scenes.c), so every texel's
# radiance is its irradiance * 0.8 / pi = 0.254648 * irradiance, and 0
# where the irradiance is 0. Measured: within 2.5e-7 relative (float
# rounding, and od's 8 printed digits); bound 1e-6.
pfm_floats() { # one float per line after the header
    od -An -v -tf4 -w4 -j "$(head -n 3 "$1" | wc -c)" "$1"
}
for n in tall_box short_box; do
    pfm_floats "$WORK/irr/$n.pfm" >"$WORK/irr_$n.txt"
    pfm_floats "$WORK/rad/$n.pfm" >"$WORK/rad_$n.txt"
    check "radiance = irradiance * 0.8 / pi on every texel of $n" \
        awk -v k=0.254647909 '
            { e = $1 + 0; l = $2 + 0
              if (e > 0) { if (e > 1e-3) lit++; if (l < k * e * (1 - 1e-6) || l > k * e * (1 + 1e-6)) bad++ }
              else if (l != 0) bad++ }
            END { if (bad || lit < 100) { printf "        %d bad of %d lit\n", bad, lit; exit 1 } }' \
        <(paste "$WORK/irr_$n.txt" "$WORK/rad_$n.txt")
done


# --pre-expose: every value times 1/(1.2 * 2^EV100) (seed 001); at EV100 0
# that is exactly 1/1.2 = 0.833333. Measured: within 1.3e-7 relative (float
# rounding and od's 8 digits); bound 5e-7.
run "$LUXEL" bake "$ROOM" --resolution 32 --format pfm -q -o "$WORK/pre" \
    --pre-expose --exposure 0
expect_rc 0 "--pre-expose --exposure 0"
check "manifest: pre_exposure 1/1.2" grep -Eq '"pre_exposure":[[:space:]]*0\.8333' \
    "$WORK/pre/manifest.json"
run "$LUXEL" bake "$ROOM" --resolution 32 --format pfm -q -o "$WORK/unexposed"
pfm_floats "$WORK/unexposed/room.pfm" >"$WORK/unexposed.txt"
pfm_floats "$WORK/pre/room.pfm" >"$WORK/pre.txt"
check "pre-exposed values = values / 1.2 on every texel" \
    awk '{ e = $1 + 0; p = $2 + 0
           if (e > 1e-3) { lit++; if (p < e / 1.2 * (1 - 5e-7) || p > e / 1.2 * (1 + 5e-7)) bad++ } }
         END { if (bad || lit < 100) { printf "        %d bad of %d lit\n", bad, lit; exit 1 } }' \
    <(paste "$WORK/unexposed.txt" "$WORK/pre.txt")
# without --exposure the metered EV100 sets the factor (test_cli_polish.sh
# checks its value)
run "$LUXEL" bake "$ROOM" --resolution 32 -q -o "$WORK/pre_auto" --pre-expose
expect_rc 0 "--pre-expose without --exposure"


# Area lights end to end: a soft-shadowed rect replaces the ceiling lamp by
# name; 40 W over 1 m x 0.5 m is 40 * 683 / (pi * 0.5) = 17392.5 nt.
cat >"$WORK/soft.json" <<'JSON'
{"lights": [
  {"name": "ceiling_lamp", "type": "rect", "position": [0, 2.95, 0], "direction": [0, -1, 0],
   "up": [0, 0, 1], "width": 1.0, "height": 0.5, "intensity": 40, "unit": "W",
   "shadow": "soft", "samples": 16},
  {"type": "sphere", "position": [1, 1, 0], "radius": 0.1, "intensity": 1000, "unit": "lm",
   "shadow": "soft", "samples": 16},
  {"name": "bar", "type": "tube", "position": [0, 2, 0], "direction": [1, 0, 0], "length": 1.2,
   "radius": 0.02, "intensity": 3000, "unit": "lm", "shadow": "soft", "samples": 16},
  {"name": "strip", "type": "tube", "position": [0, 2.5, 1], "direction": [0, 0, 1], "length": 2,
   "radius": 0, "intensity": 3000, "unit": "lm", "shadow": "soft", "samples": 16}]}
JSON
run "$LUXEL" info "$ROOM" --lights "$WORK/soft.json"
expect_rc 0 "info with area lights"
expect_stdout_has "info: the rect in nits" 'rect +ceiling_lamp +17392.5 nt'
expect_stdout_has "info: the sphere" 'sphere'
# 3000 lm over the capsule: 3000 / (pi (2 pi 0.02 1.2 + 4 pi 0.02^2)) = 6128.3 nt;
# linear: 3000 / (pi^2 2) = 151.982 cd per metre
expect_stdout_has "info: the tube in nits" 'tube +bar +6128.3 nt .*axis \(1, 0, 0\)  length 1.2 m  radius 0.02 m'
expect_stdout_has "info: the linear tube in cd/m" 'tube +strip +151.982 cd/m .*\(linear\)'
run "$LUXEL" bake "$ROOM" --resolution 32 --format pfm -q -o "$WORK/soft" --lights "$WORK/soft.json"
expect_rc 0 "bake with soft area lights"
check "soft bake: every lightmap written" test -s "$WORK/soft/room.pfm" -a -s "$WORK/soft/tall_box.pfm"
run "$LUXEL" bake "$ROOM" --resolution 32 --format pfm -q -o "$WORK/soft2" --threads 1 \
    --lights "$WORK/soft.json"
check "soft bake: the same bytes with 1 thread" cmp -s "$WORK/soft/room.pfm" "$WORK/soft2/room.pfm"

# Sky light: gen_scenes' sky through a lights JSON in another folder (the
# path is relative to the JSON, in its folder or below), with sky shadows;
# the manifest records it; 1 and 2 threads give the same bytes; --sky on
# the command line wins over the file's. A sky outside the JSON's folder
# is read with --allow-any-path only.
mkdir -p "$WORK/skycfg/hdri"
cp "$WORK/scenes/sky.pfm" "$WORK/skycfg/hdri/sky.pfm"
cat >"$WORK/skycfg/day.json" <<'JSON'
{"sky": {"environment": "hdri/sky.pfm", "shadows": true, "samples": 16},
 "lights": [{"name": "sun", "intensity": 0}]}
JSON
sed 's#hdri/sky.pfm#../scenes/sky.pfm#' "$WORK/skycfg/day.json" >"$WORK/skycfg/outside.json"
run "$LUXEL" bake "$RETRO" --texel-density 4 --format pfm -q -o "$WORK/sky0" --lights "$WORK/skycfg/outside.json"
expect_rc 1 "a sky outside the lights JSON's folder"
expect_error "a sky outside the lights JSON's folder" "outside.json" "../scenes/sky.pfm" "--allow-any-path"
run "$LUXEL" bake "$RETRO" --texel-density 4 --format pfm -q -o "$WORK/sky0" --lights "$WORK/skycfg/outside.json" \
    --allow-any-path
expect_rc 0 "a sky outside the lights JSON's folder with --allow-any-path"
run "$LUXEL" bake "$RETRO" --texel-density 4 --format pfm -q -o "$WORK/sky1" --lights "$WORK/skycfg/day.json"
expect_rc 0 "bake with a sky from the lights JSON"
check "sky bake: manifest names the environment" grep -q '"environment":.*skycfg/hdri/sky.pfm' "$WORK/sky1/manifest.json"
check "sky bake: the same bytes as the sky outside" cmp -s "$WORK/sky0/ground.pfm" "$WORK/sky1/ground.pfm"
# the lights JSON named from its own folder: the manifest still finds the
# sky from anywhere (an absolute path), so a render elsewhere has its sky
(cd "$WORK/skycfg" && "$LUXEL" bake "$RETRO" --texel-density 4 --format pfm -q -o "$WORK/sky1r" \
    --lights day.json) >/dev/null 2>&1
check "sky bake from the JSON's folder: the manifest's sky is absolute" \
    grep -q "\"environment\":[[:space:]]*\"$WORK/skycfg/hdri/sky.pfm\"" "$WORK/sky1r/manifest.json"
sky_block=$(grep -A4 '"sky"' "$WORK/sky1/manifest.json")
check "sky bake: manifest says shadows" grep -q '"shadows":.*true' <<<"$sky_block"
check "sky bake: manifest says 16 samples" grep -q '"samples":.*16' <<<"$sky_block"
run "$LUXEL" info "$RETRO" --lights "$WORK/skycfg/day.json"
expect_stdout_has "info: the sky" '^sky: .*hdri/sky.pfm x 1, shadows \(16 samples\)$'
run "$LUXEL" bake "$RETRO" --texel-density 4 --format pfm -q -o "$WORK/sky2" --threads 1 \
    --lights "$WORK/skycfg/day.json"
check "sky bake: the same bytes with 1 thread" cmp -s "$WORK/sky1/ground.pfm" "$WORK/sky2/ground.pfm"
run "$LUXEL" bake "$RETRO" --texel-density 4 --format pfm -q -o "$WORK/sky3" \
    --lights "$WORK/skycfg/day.json" --sky const:100 --sky-samples 4
expect_rc 0 "bake with --sky over the file's sky"
check "sky bake: --sky wins" grep -q '"environment":.*const:100' "$WORK/sky3/manifest.json"
run "$LUXEL" bake "$RETRO" --texel-density 4 --format pfm -q -o "$WORK/sky4" \
    --lights "$WORK/skycfg/day.json" --no-sky-shadows
expect_rc 0 "bake with --no-sky-shadows over the file's shadows"
check "sky bake: --no-sky-shadows wins" grep -q '"shadows":.*false' "$WORK/sky4/manifest.json"

# ---- lightmap UVs made by luxel, atlas pages -----------------------------------
# --unwrap always: every node on luxel's UVs, packed into one atlas page;
# the manifest's nodes say so and point at page 0 with the identity
# scale/offset (the generated UVs are page UVs).
run "$LUXEL" bake "$ROOM" --unwrap always -q -o "$WORK/atlas"
expect_rc 0 "bake --unwrap always"
expect_files "--unwrap always: one atlas page, its preview, the manifest and the scene with UVs" \
    "$WORK/atlas" lightmap-0.exr lightmap-0.png manifest.json room.glb
M=$WORK/atlas/manifest.json
for n in $NODES; do
    check "atlas: $n's UVs are generated" test "$(manifest_get "$M" "$n" uvs)" = generated
    check "atlas: $n is on page 0" test "$(manifest_get "$M" "$n" page)" = 0
    check "atlas: $n reads TEXCOORD_1" test "$(manifest_get "$M" "$n" uv_set)" = TEXCOORD_1
    check "atlas: $n's page is lightmap-0.exr" test "$(manifest_get "$M" "$n" file)" = lightmap-0.exr
done
w=$(manifest_get "$M" room width)
h=$(manifest_get "$M" room height)
check "atlas: the page is a multiple of 4 and at most 1024 (${w}x${h})" \
    test $((w % 4)) -eq 0 -a $((h % 4)) -eq 0 -a "$w" -le 1024 -a "$h" -le 1024
# no --resolution or --texel-density: the density comes from the scene,
# 2^20 texels over its area held to 4..40 texels/m (docs/bake.md); the
# room's surfaces (a room a few metres a side and two boxes) are far under
# the 655 m^2 below which that budget gives more than 40, so 40
check "atlas: the manifest records the scene's density, 40 texels/m" \
    grep -Eq '"texel_density":[[:space:]]*40[,}]' "$M"
run "$LUXEL" bake "$ROOM" --ambient 0.5 --bounces 0 -o "$WORK/density"
expect_stderr_has "the summary line states the scene's density" \
    "^luxel: baked 3 lightmaps \\([0-9]+ texels at 40 texels/m,"
# a 556 m floor (a Cornell box in millimetres read as metres): the budget
# holds, 309,136 m^2 at sqrt(2^20 / 309136) = 1.84, 1.8 texels/m (no floor
# at 4 to ask for 2224^2 texels), with a warning about the units
write_gltf "$WORK/huge.gltf" floor floor \
    "0 0 0  0 0 556  556 0 0   556 0 0  0 0 556  556 0 556" "0 0  0 1  1 0   1 0  0 1  1 1"
run "$LUXEL" bake "$WORK/huge.gltf" --ambient 1 --bounces 0 -o "$WORK/huge"
expect_rc 0 "a 556 m floor with the default density"
expect_stderr_has "the 556 m floor: the budget's density, 1.8 texels/m" \
    "^luxel: baked 1 lightmap \\(1[0-9]{6} texels at 1\\.8 texels/m,"
expect_stderr_has "the 556 m floor: a warning about its units" \
    "309136 m\\^2 of lightmapped surface: the default budget of 1048576 texels gives it 1\\.8 texels/m .*are its units metres"
# the same bytes for any thread count
run "$LUXEL" bake "$ROOM" --unwrap always -q --threads 1 -o "$WORK/atlas1"
check "atlas: the same page with 1 thread" cmp -s "$WORK/atlas/lightmap-0.exr" \
    "$WORK/atlas1/lightmap-0.exr"

# --atlas with the file's own UVs: each node's square on a shared page,
# placed by a scale and offset
run "$LUXEL" bake "$ROOM" --atlas --texel-density 20 -q -o "$WORK/atlas_own"
expect_rc 0 "bake --atlas with the file's UVs"
M=$WORK/atlas_own/manifest.json
for n in $NODES; do
    check "own-UV atlas: $n keeps its UVs" test "$(manifest_get "$M" "$n" uvs)" = own
done
check "own-UV atlas: one page" test "$(grep -c '"file":' "$M")" -eq 1
check "own-UV atlas: a scale/offset other than the identity" \
    grep -Eq '"scale_offset":.*0\.[0-9]' "$M"

# --unwrap always --no-atlas: a lightmap per node, named after it
run "$LUXEL" bake "$ROOM" --unwrap always --no-atlas -q -o "$WORK/noatlas"
expect_rc 0 "bake --unwrap always --no-atlas"
expect_files "--no-atlas: a lightmap per node, the scene with UVs" "$WORK/noatlas" room.exr \
    room.png tall_box.exr tall_box.png short_box.exr short_box.png manifest.json room.glb
check "--no-atlas: the room's UVs are generated" \
    test "$(manifest_get "$WORK/noatlas/manifest.json" room uvs)" = generated

# --uv-set 0 reads TEXCOORD_0 (kept with --unwrap never)
run "$LUXEL" bake "$ROOM" --uv-set 0 --unwrap never -q -o "$WORK/uv0"
expect_rc 0 "bake --uv-set 0"
check "--uv-set 0: the manifest says TEXCOORD_0" \
    test "$(manifest_get "$WORK/uv0/manifest.json" room uv_set)" = TEXCOORD_0
# the room's TEXCOORD_0 spans [0,1] on every face (gen_scenes.c): the faces
# overlap, so --unwrap auto makes the lightmap UVs instead
run "$LUXEL" bake "$ROOM" --uv-set 0 -o "$WORK/uv0_auto"
expect_rc 0 "bake --uv-set 0, --unwrap auto"
expect_stderr_has "--uv-set 0: the faces' shared [0,1] squares count as overlapping" \
    "^luxel: warning: .*3 of 3 nodes have no usable .*overlapping 3.*luxel makes"
check "--uv-set 0, --unwrap auto: the room's UVs are generated" \
    test "$(manifest_get "$WORK/uv0_auto/manifest.json" room uvs)" = generated

# usage errors name the option
for args in "--unwrap sometimes" "--uv-set 2" "--atlas --no-atlas" "--atlas-size 3" \
    "--resolution 64 --texel-density 8" "--no-atlas --atlas-size 512"; do
    # shellcheck disable=SC2086
    run "$LUXEL" bake "$ROOM" $args -o "$WORK/usage"
    expect_rc 2 "bake $args"
    expect_error "bake $args" "bake"
    expect_no_output "bake $args" "$WORK/usage"
done

finish
