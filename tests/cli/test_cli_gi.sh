# End-to-end tests of `luxel bake`'s indirect light (--bounces,
# --gi-samples, --gi-sampling, --emissive-scale, --supersample,
# --double-sided), run on the real binary with its own
# defaults (LUXEL_REAL): the default bake has two bounces and says so in
# the manifest; --bounces 0 ignores the other GI settings, byte for byte;
# 1 and 2 threads give the same bytes; an emissive material alone lights a
# scene through the bounces (and a bake without bounces refuses it as
# dark); --emissive-scale 2 doubles every value exactly (the gather is
# linear in the emission and a power of two scales floats exactly); a
# scene without double-sided materials bakes the same bytes with
# --double-sided front as with the default auto, the manifest saying which; bad
# values are usage errors (exit 2, one error line, nothing written).
#
# usage: bash test_cli_gi.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
BIN=$LUXEL_REAL

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
ROOM=$WORK/scenes/room.glb
SMALL=(--resolution 24 --gi-samples 9 -q)

# ---- defaults and the manifest ---------------------------------------------
run "$BIN" bake "$ROOM" "${SMALL[@]}" -o "$WORK/default"
expect_rc 0 "bake with the default bounces"
check "manifest: two bounces by default" \
    grep -Eq '"bounces":[[:space:]]*2' "$WORK/default/manifest.json"
check "manifest: the gather's rays" grep -Eq '"gi_samples":[[:space:]]*9' \
    "$WORK/default/manifest.json"
check "manifest: guided gathers by default" grep -Eq '"gi_sampling":[[:space:]]*"guided"' \
    "$WORK/default/manifest.json"
run "$BIN" bake "$ROOM" --resolution 24 --gi-samples 9 -q --gi-sampling cosine -o "$WORK/cosine"
expect_rc 0 "--gi-sampling cosine"
check "manifest: --gi-sampling cosine" grep -Eq '"gi_sampling":[[:space:]]*"cosine"' \
    "$WORK/cosine/manifest.json"
# 9 rays a texel are too few to learn from: not guided, the same bytes
check "room.exr: 9 rays a texel are cosine-weighted either way" \
    cmp -s "$WORK/default/room.exr" "$WORK/cosine/room.exr"
check "manifest: double-sided auto by default" grep -Eq '"double_sided":[[:space:]]*"auto"' \
    "$WORK/default/manifest.json"
run "$BIN" bake "$ROOM" "${SMALL[@]}" --double-sided front -o "$WORK/front"
expect_rc 0 "--double-sided front"
check "manifest: --double-sided front" grep -Eq '"double_sided":[[:space:]]*"front"' \
    "$WORK/front/manifest.json"
check "room.exr: no double-sided material, the same bytes either way" \
    cmp -s "$WORK/default/room.exr" "$WORK/front/room.exr"
run "$BIN" bake "$ROOM" "${SMALL[@]}" --bounces 0 -o "$WORK/direct"
expect_rc 0 "--bounces 0"
check "manifest: no indirect entry without bounces" \
    sh -c "! grep -q '\"indirect\":' '$WORK/direct/manifest.json'"
check "bounces add light: room.exr differs from the direct bake" \
    sh -c "! cmp -s '$WORK/default/room.exr' '$WORK/direct/room.exr'"
run "$BIN" bake "$ROOM" --resolution 24 -q --bounces 0 --gi-samples 3 --emissive-scale 7 \
    -o "$WORK/direct2"
expect_rc 0 "--bounces 0 with other GI settings"
for n in room tall_box short_box; do
    check "$n.exr: --bounces 0 ignores --gi-samples and --emissive-scale" \
        cmp -s "$WORK/direct/$n.exr" "$WORK/direct2/$n.exr"
done

# ---- threads ------------------------------------------------------------------
run "$BIN" bake "$ROOM" "${SMALL[@]}" --threads 1 -o "$WORK/t1"
run "$BIN" bake "$ROOM" "${SMALL[@]}" --threads 2 -o "$WORK/t2"
for n in room tall_box short_box; do
    check "$n.exr: same bytes with 1 and 2 threads" cmp -s "$WORK/t1/$n.exr" "$WORK/t2/$n.exr"
done

# ---- emissive materials ----------------------------------------------------------
# a floor (y = 0, facing up) and a roof (y = 1, facing down), unit squares,
# one emissive material of 100 nits (emissiveFactor x emissiveStrength)
write_gltf "$WORK/glow.gltf" plates plates \
    "0 0 0  0 0 1  1 0 0   1 0 0  0 0 1  1 0 1   0 1 0  1 1 0  0 1 1   1 1 0  1 1 1  0 1 1" \
    "0 0  0 1  0.5 0   0.5 0  0 1  0.5 1   0.75 0  1 0  0.75 1   1 0  1 1  0.75 1"
sed -i 's/"mode": 4}/"mode": 4, "material": 0}/;
        s/"accessors": \[/"materials": [{"name": "glow", "emissiveFactor": [1, 0.5, 0.25], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 100}}}],\n  "extensionsUsed": ["KHR_materials_emissive_strength"],\n  "accessors": [/' \
    "$WORK/glow.gltf"
# emitters are lights: their direct light is there without bounces
run "$BIN" bake "$WORK/glow.gltf" --bounces 0 --resolution 16 --gi-samples 16 --format pfm -q \
    -o "$WORK/glow0"
expect_rc 0 "an emissive scene without bounces"
run "$BIN" bake "$WORK/glow.gltf" --resolution 16 --gi-samples 16 --format pfm -q -o "$WORK/glow1"
expect_rc 0 "an emissive scene with bounces"
run "$BIN" bake "$WORK/glow.gltf" --resolution 16 --gi-samples 16 --format pfm -q \
    --emissive-scale 2 -o "$WORK/glow2"
expect_rc 0 "--emissive-scale 2"
# the PFM's floats (16 x 16 x 3 after its header)
values() { tail -c $((16 * 16 * 3 * 4)) "$1" | od -An -tf4 -v | tr -s ' ' '\n' | sed '/^$/d'; }
check "the emitters light each other" \
    awk 'BEGIN { m = 0 } { if ($1 > m) m = $1 } END { exit !(m > 10) }' \
    <(values "$WORK/glow1/plates.pfm")
check "the emitters light each other without bounces" \
    awk 'BEGIN { m = 0 } { if ($1 > m) m = $1 } END { exit !(m > 10) }' \
    <(values "$WORK/glow0/plates.pfm")
# the same floats' bits as unsigned integers: doubling a normal float adds
# one to its exponent, 2^23 to its bits (zero stays zero)
bits() { tail -c $((16 * 16 * 3 * 4)) "$1" | od -An -tu4 -v | tr -s ' ' '\n' | sed '/^$/d'; }
check "--emissive-scale 2 doubles every value exactly" \
    awk 'NR == FNR { a[FNR] = $1; next }
         { if (!($1 == 0 && a[FNR] == 0) && $1 != a[FNR] + 8388608) bad = 1 } END { exit bad }' \
    <(bits "$WORK/glow1/plates.pfm") <(bits "$WORK/glow2/plates.pfm")

# ---- supersampling -----------------------------------------------------------------
run "$BIN" bake "$ROOM" "${SMALL[@]}" --bounces 0 --supersample 3 -o "$WORK/ss3"
expect_rc 0 "--supersample 3"
check "manifest: the supersampling" grep -Eq '"supersample":[[:space:]]*3' \
    "$WORK/ss3/manifest.json"
check "--supersample 3 changes room.exr (its shadow edges)" \
    sh -c "! cmp -s '$WORK/direct/room.exr' '$WORK/ss3/room.exr'"
run "$BIN" bake "$ROOM" "${SMALL[@]}" --bounces 0 --supersample 1 -o "$WORK/ss1"
expect_rc 0 "--supersample 1"
for n in room tall_box short_box; do
    check "$n.exr: --supersample 1 is the plain bake" cmp -s "$WORK/direct/$n.exr" "$WORK/ss1/$n.exr"
done

# edge supersampling is on by default: only the texels a shadow edge crosses
# change, and --supersample takes its place
run "$BIN" bake "$ROOM" "${SMALL[@]}" --bounces 0 --edge-supersample 0 -o "$WORK/edge0"
expect_rc 0 "--edge-supersample 0"
check "--edge-supersample (default 4) changes room.exr (its shadow edges)" \
    sh -c "! cmp -s '$WORK/direct/room.exr' '$WORK/edge0/room.exr'"
check "manifest: the edge supersampling" grep -Eq '"edge_supersample":[[:space:]]*4' \
    "$WORK/direct/manifest.json"
check "manifest: no edge supersampling with --supersample 3" \
    sh -c "! grep -q edge_supersample '$WORK/ss3/manifest.json'"

# ---- bad values -------------------------------------------------------------------
for bad in "--bounces -1" "--bounces 65" "--bounces two" "--gi-samples 0" "--gi-samples 70000" \
    "--emissive-scale 0" "--emissive-scale -2" "--emissive-scale nan" "--supersample 0" \
    "--supersample 17" "--supersample two" "--edge-supersample -1" "--edge-supersample 17" \
    "--gi-sampling uniform" "--gi-sampling" "--double-sided sideways" "--double-sided"; do
    # shellcheck disable=SC2086
    run "$BIN" bake "$ROOM" $bad -q -o "$WORK/bad"
    expect_rc 2 "$bad"
    expect_error "$bad" "${bad%% *}"
    expect_no_output "$bad" "$WORK/bad"
done

finish
