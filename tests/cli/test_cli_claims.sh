# End-to-end checks of what `luxel bake` states about UV sets and light
# terms, on glTF files written here:
#
# - a mesh with only TEXCOORD_0 bakes on it with exactly one warning, and
#   the manifest says "uv_set": "TEXCOORD_0"; with TEXCOORD_1 present it
#   bakes on TEXCOORD_1 with no warning ("uv_set": "TEXCOORD_1"). The two
#   UV sets cover different shares of the square, so used_texels tells
#   which one the texels came from;
# - --ambient R,G,B adds exactly R,G,B lux to every texel (the same bake
#   with and without it, texel by texel);
# - --sky-intensity scales the sky term linearly: x2 gives exactly twice
#   (a scale by a power of two commutes with rounding), x3 three times up
#   to float rounding, alone and on top of a sun;
# - an unshadowed --sky const:L on an open floor facing up gives pi * L lux
#   in every texel (the SH of a constant are exact);
# - a malformed KHR_texture_transform fails with one error line naming the
#   file, the material and the field, and writes nothing.
#
# Expected values are closed forms (pi * L, the UV areas) and the
# invariants the options state; PFM values are decoded bit-exactly from
# their IEEE 754 binary32 words in awk (no decimal round trip).
#
# usage: bash test_cli_claims.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

IN=$WORK/in
mkdir -p "$IN"

# write_uv_quad FILE.gltf NODE UV0 [UV1]: a 1 m floor quad facing +Y (two
# non-indexed triangles over x, z in [0, 1]) with TEXCOORD_0 = UV0 and, when
# given, TEXCOORD_1 = UV1 (6 "u v" pairs each, values f32 knows).
write_uv_quad() {
    local file=$1 node=$2 uv0=$3 uv1=${4:-}
    local bin=${file%.gltf}.bin v
    local pos="0 0 0  0 0 1  1 0 1  0 0 0  1 0 1  1 0 0"
    : >"$bin"
    for v in $pos $uv0 $uv1; do f32 "$v" >>"$bin" || return 1; done
    local attrs='"POSITION": 0, "TEXCOORD_0": 1' acc views total=120
    acc='{"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3",
          "min": [0, 0, 0], "max": [1, 0, 1]},
         {"bufferView": 1, "componentType": 5126, "count": 6, "type": "VEC2"}'
    views='{"buffer": 0, "byteOffset": 0, "byteLength": 72},
           {"buffer": 0, "byteOffset": 72, "byteLength": 48}'
    if [ -n "$uv1" ]; then
        attrs="$attrs, \"TEXCOORD_1\": 2"
        acc="$acc, {\"bufferView\": 2, \"componentType\": 5126, \"count\": 6, \"type\": \"VEC2\"}"
        views="$views, {\"buffer\": 0, \"byteOffset\": 120, \"byteLength\": 48}"
        total=168
    fi
    cat >"$file" <<EOF
{"asset": {"version": "2.0", "generator": "luxel tests/cli"},
 "scene": 0, "scenes": [{"nodes": [0]}],
 "nodes": [{"name": "$node", "mesh": 0}],
 "meshes": [{"name": "$node", "primitives": [{"attributes": {$attrs}, "mode": 4}]}],
 "accessors": [$acc], "bufferViews": [$views],
 "buffers": [{"uri": "$(basename "$bin")", "byteLength": $total}]}
EOF
}

FULL="0 0  0 1  1 1  0 0  1 1  1 0" # the unit square
HALF="0 0  0 1  0.5 1  0 0  0.5 1  0.5 0" # its left half

# manifest_get FILE KEY: the first value of KEY in the manifest (one
# lightmap here), without quotes.
manifest_get() {
    awk -v key="$2" '$0 ~ "\"" key "\":" {
        v = $0; sub(/^[^:]*:[ \t]*/, "", v); sub(/,?[ \t]*$/, "", v); gsub(/"/, "", v)
        print v; exit }' "$1"
}

# pfm_floats FILE: every float of a little-endian PFM after its 3-line
# header, one per line, decoded exactly from its 32 bits.
pfm_floats() {
    od -An -v -tu4 -w4 -j "$(head -n 3 "$1" | wc -c)" "$1" | awk '
        { u = $1 + 0; s = 1
          if (u >= 2147483648) { s = -1; u -= 2147483648 }
          e = int(u / 8388608); m = u - e * 8388608
          if (e == 0) v = m * 2 ^ -149; else v = (1 + m / 8388608) * 2 ^ (e - 127)
          printf "%.17g\n", s * v }'
}

# compare A.pfm B.pfm AWK-CONDITION: true when the condition holds for every
# pair of values a (from A) and b (from B), c the channel (0, 1, 2); prints
# the first pair that fails.
compare() {
    pfm_floats "$1" >"$WORK/.a"
    pfm_floats "$2" >"$WORK/.b"
    paste "$WORK/.a" "$WORK/.b" | awk '
        { a = $1 + 0; b = $2 + 0; c = (NR - 1) % 3; n++ }
        '"$3"' { next }
        { printf "        value %d (channel %d): a = %.9g, b = %.9g\n", NR, c, a, b; bad = 1; exit }
        END { if (n == 0) { print "        no values"; bad = 1 } exit bad }'
}

SUN=$IN/sun.json
cat >"$SUN" <<'EOF'
{"lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "intensity": 1000, "unit": "lx",
             "color": [1, 0.75, 0.5]}]}
EOF
BELOW=$IN/below.json # shines upward: the floor gets none of it
cat >"$BELOW" <<'EOF'
{"lights": [{"type": "directional", "direction": [0, 1, 0], "intensity": 1000, "unit": "lx"}]}
EOF

# ---- TEXCOORD_0 fallback and the manifest's uv_set -----------------------

write_uv_quad "$IN/uv0.gltf" only_uv0 "$HALF" || exit 1
run "$LUXEL" bake "$IN/uv0.gltf" --lights "$SUN" --resolution 16 --format pfm -o "$WORK/uv0"
expect_rc 0 "a mesh with only TEXCOORD_0 bakes"
n=$(grep -c '^luxel: warning:' "$ERR")
check "only TEXCOORD_0: exactly one warning ($n)" test "$n" -eq 1
expect_stderr_has "only TEXCOORD_0: the warning names the mesh and TEXCOORD_0" \
    "^luxel: warning: .*uv0\.gltf.*'only_uv0' has no TEXCOORD_1; its lightmap uses TEXCOORD_0"
M=$WORK/uv0/manifest.json
check "only TEXCOORD_0: manifest uv_set TEXCOORD_0" test "$(manifest_get "$M" uv_set)" = TEXCOORD_0
# TEXCOORD_0 covers u in [0, 0.5]: texel centres x + 0.5 < 8 of 16 columns
check "only TEXCOORD_0: the texels are TEXCOORD_0's half of the square (128 of 256)" \
    test "$(manifest_get "$M" used_texels)" = 128

write_uv_quad "$IN/uv01.gltf" both_sets "$FULL" "$HALF" || exit 1
run "$LUXEL" bake "$IN/uv01.gltf" --lights "$SUN" --resolution 16 --format pfm -o "$WORK/uv01"
expect_rc 0 "a mesh with TEXCOORD_0 and TEXCOORD_1 bakes"
check "TEXCOORD_0 and _1: no warning" test -z "$(grep '^luxel: warning:' "$ERR")"
M=$WORK/uv01/manifest.json
check "TEXCOORD_0 and _1: manifest uv_set TEXCOORD_1" test "$(manifest_get "$M" uv_set)" = TEXCOORD_1
check "TEXCOORD_0 and _1: the texels are TEXCOORD_1's half (128), not TEXCOORD_0's 256" \
    test "$(manifest_get "$M" used_texels)" = 128

write_uv_quad "$IN/uv10.gltf" swapped "$HALF" "$FULL" || exit 1
run "$LUXEL" bake "$IN/uv10.gltf" --lights "$SUN" --resolution 16 --format pfm -q -o "$WORK/uv10"
expect_rc 0 "TEXCOORD_1 covering the square"
check "TEXCOORD_1 covering the square: 256 texels" \
    test "$(manifest_get "$WORK/uv10/manifest.json" used_texels)" = 256

# ---- --ambient -------------------------------------------------------------

write_uv_quad "$IN/floor.gltf" floor "$FULL" || exit 1
FLOOR=$IN/floor.gltf
bake_pfm() { # bake_pfm OUT ARGS...: a 16x16 PFM bake of the floor
    local out=$1
    shift
    run "$LUXEL" bake "$FLOOR" --resolution 16 --format pfm -q -o "$WORK/$out" "$@"
    expect_rc 0 "bake $out"
}
bake_pfm plain --lights "$SUN"
bake_pfm ambient --lights "$SUN" --ambient 0.5,2,7.25
# b - a must be the ambient: one float addition rounds it by at most half
# an ulp of b (2^-24 |b|); measured: exactly the ambient in every texel
check "--ambient 0.5,2,7.25 adds exactly that to every texel of a lit floor" \
    compare "$WORK/plain/floor.pfm" "$WORK/ambient/floor.pfm" \
    'function abs(x) { return x < 0 ? -x : x }
     { amb = c == 0 ? 0.5 : c == 1 ? 2 : 7.25 }
     abs((b - a) - amb) <= 2 ^ -23 * abs(b)'
bake_pfm dark --lights "$BELOW"
bake_pfm dark_ambient --lights "$BELOW" --ambient 0.5,2,7.25
check "--ambient alone (no light reaches the floor): every texel is exactly R,G,B" \
    compare "$WORK/dark/floor.pfm" "$WORK/dark_ambient/floor.pfm" \
    'a == 0 && b == (c == 0 ? 0.5 : c == 1 ? 2 : 7.25)'

# ---- --sky-intensity -----------------------------------------------------------

# an 8x4 equirect sky (PFM rows bottom first) whose radiance varies with
# row and column, so the SH carry more than a constant
{
    printf 'PF\n8 4\n-1.0\n'
    for row in 0.125 0.25 1 2; do
        for col in 0.5 1 2 0.75 0.25 0.875 1 0.5; do
            f32 "$row"
            f32 "$col"
            f32 0.5
        done
    done
} >"$IN/sky.pfm"
bake_pfm sky1 --sky "$IN/sky.pfm" --lights "$BELOW"
bake_pfm sky2 --sky "$IN/sky.pfm" --sky-intensity 2 --lights "$BELOW"
bake_pfm sky3 --sky "$IN/sky.pfm" --sky-intensity 3 --lights "$BELOW"
check "--sky-intensity 2: exactly twice the sky" \
    compare "$WORK/sky1/floor.pfm" "$WORK/sky2/floor.pfm" 'b == 2 * a && a > 0'
# measured: at most 6.8e-8 relative (float products)
check "--sky-intensity 3: three times the sky, up to float rounding" \
    compare "$WORK/sky1/floor.pfm" "$WORK/sky3/floor.pfm" \
    'function abs(x) { return x < 0 ? -x : x } abs(b - 3 * a) <= 2 ^ -22 * b && a > 0'
bake_pfm sun_sky1 --sky "$IN/sky.pfm" --lights "$SUN"
bake_pfm sun_sky2 --sky "$IN/sky.pfm" --sky-intensity 2 --lights "$SUN"
# with a sun: (sun + 2 sky) - sun = 2 ((sun + sky) - sun), each sum rounded
# once; measured: at most 8.6e-8 of the sun-lit value, allowed 2^-22
pfm_floats "$WORK/plain/floor.pfm" >"$WORK/.s0"
pfm_floats "$WORK/sun_sky1/floor.pfm" >"$WORK/.s1"
pfm_floats "$WORK/sun_sky2/floor.pfm" >"$WORK/.s2"
check "--sky-intensity 2 on top of a sun: the sky term doubles" \
    test "$(paste "$WORK/.s0" "$WORK/.s1" "$WORK/.s2" | awk '
        function abs(x) { return x < 0 ? -x : x }
        { d = abs(($3 - $1) - 2 * ($2 - $1)); if (!(d <= 2 ^ -22 * $3) || !($2 > $1)) bad++ }
        END { print bad + 0 }')" = 0

# ---- --sky const:L ---------------------------------------------------------------

bake_pfm const --sky const:0.75 --lights "$BELOW"
check "manifest: the sky is unshadowed" \
    grep -Eq '"shadows":[[:space:]]*false' "$WORK/const/manifest.json"
# pi * 0.75 = 2.35619449...; measured: at most 8.6e-7 relative (the SH
# projection summed over 6 x 256^2 texels, rounded to float)
check "--sky const:0.75, no sky shadows, open floor: pi * 0.75 lux in every texel" \
    compare "$WORK/const/floor.pfm" "$WORK/const/floor.pfm" \
    'function abs(x) { return x < 0 ? -x : x }
     abs(a - 3.14159265358979 * 0.75) <= 2.5e-6 * 3.14159265358979 * 0.75'
bake_pfm const_rgb --sky const:0.25,0.5,2 --lights "$BELOW"
check "--sky const:0.25,0.5,2: pi times each channel" \
    compare "$WORK/const_rgb/floor.pfm" "$WORK/const_rgb/floor.pfm" \
    'function abs(x) { return x < 0 ? -x : x }
     { L = c == 0 ? 0.25 : c == 1 ? 0.5 : 2 }
     abs(a - 3.14159265358979 * L) <= 2.5e-6 * 3.14159265358979 * L'

# ---- a malformed KHR_texture_transform ---------------------------------------------

write_uv_quad "$IN/bad_tt.gltf" bad_tt "$FULL" || exit 1
# the same quad with a material whose normal texture's transform has a
# three-number offset
awk '{ sub(/"mode": 4}/, "\"mode\": 4, \"material\": 0}") }
     /"buffers"/ { print " \"materials\": [{\"name\": \"tiles\", \"normalTexture\": {\"index\": 0,"
                   print "   \"extensions\": {\"KHR_texture_transform\": {\"offset\": [0, 0, 1]}}}}],"
                   print " \"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"n.png\"}]," }
     { print }' "$IN/bad_tt.gltf" >"$IN/bad_tt2.gltf" && mv "$IN/bad_tt2.gltf" "$IN/bad_tt.gltf"
run "$LUXEL" bake "$IN/bad_tt.gltf" --resolution 16 -o "$WORK/bad_tt"
expect_rc 1 "a malformed KHR_texture_transform"
expect_error "a malformed KHR_texture_transform" "bad_tt.gltf" "material 0 ('tiles')" \
    "normalTexture: KHR_texture_transform" "offset must be 2 finite numbers"
expect_no_output "a malformed KHR_texture_transform" "$WORK/bad_tt"

finish
