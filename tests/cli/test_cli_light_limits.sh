# End-to-end tests of absurd light values (issue 27): an intensity, size,
# range, colour or position beyond the limits of docs/lights-json.md
# (LX_LIGHT_MAX_* in luxel/light.h: 1e12 of the light's unit, colour
# components 1e2, 1e7 m) fails before any baking, with exit status 1, one
# error line naming the file and the light, and no output folder; the same
# values as the largest accepted bake. Lights come from a lights JSON and
# from a glTF's KHR_lights_punctual, both written here.
#
# usage: bash test_cli_light_limits.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

IN=$WORK/in
mkdir -p "$IN" "$WORK/out"
# a 2 m floor quad with its own UVs, lit from above
write_gltf "$IN/floor.gltf" floor floor \
    "-1 0 -1  -1 0 1  1 0 1   -1 0 -1  1 0 1  1 0 -1" \
    "0 0  0 1  1 1   0 0  1 1  1 0" || exit 1

CASE=0
# refused LABEL FILE "NEEDLE|..." ARGS...: `luxel bake ARGS` exits 1 with
# one error line naming FILE and every needle, and writes no output folder.
refused() {
    local label=$1 file=$2 needles=$3
    shift 3
    CASE=$((CASE + 1))
    local out=$WORK/out/case$CASE
    run "$LUXEL" bake "$@" --resolution 16 -o "$out"
    expect_rc 1 "$label"
    local list=()
    IFS='|' read -ra list <<<"$needles"
    expect_error "$label" "$file" "${list[@]}"
    check "$label: nothing baked first" test -z "$(grep -i 'baked\|denois' "$ERR")"
    expect_no_output "$label" "$out"
}

# ---- lights JSON ---------------------------------------------------------------

# lights_json NAME LIGHT: a lights JSON holding the one light object LIGHT
lights_json() {
    printf '{"lights": [%s]}\n' "$2" >"$IN/$1.json"
}

lights_json huge_cd '{"name": "huge", "type": "point", "position": [0, 1, 0], "intensity": 1e38, "unit": "cd"}'
refused "a 1e38 cd point light" huge_cd.json "'huge'|intensity|1e+38" \
    "$IN/floor.gltf" --lights "$IN/huge_cd.json"

lights_json huge_lm '{"name": "flood", "type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "intensity": 1e30, "unit": "lm"}'
refused "a 1e30 lm spot light" huge_lm.json "'flood'|intensity" \
    "$IN/floor.gltf" --lights "$IN/huge_lm.json"

lights_json huge_sun '{"name": "sun", "type": "directional", "direction": [0, -1, 0], "intensity": 1e20}'
refused "a 1e20 lx sun" huge_sun.json "'sun'|intensity|lx" \
    "$IN/floor.gltf" --lights "$IN/huge_sun.json"

lights_json vast_sphere '{"name": "vast", "type": "sphere", "position": [0, 1, 0], "radius": 1e38, "intensity": 1000, "unit": "lm"}'
refused "a sphere light of radius 1e38 m (lm)" vast_sphere.json "'vast'|radius|1e+38" \
    "$IN/floor.gltf" --lights "$IN/vast_sphere.json"

lights_json vast_rect '{"name": "panel", "type": "rect", "position": [0, 1, 0], "direction": [0, -1, 0], "up": [0, 0, 1], "width": 1e20, "height": 1, "intensity": 40, "unit": "W"}'
refused "a rect light 1e20 m wide (W)" vast_rect.json "'panel'|width" \
    "$IN/floor.gltf" --lights "$IN/vast_rect.json"

lights_json long_tube '{"name": "tube", "type": "tube", "position": [0, 1, 0], "direction": [1, 0, 0], "length": 1e9, "radius": 0.02, "intensity": 1000}'
refused "a tube light 1e9 m long" long_tube.json "'tube'|length" \
    "$IN/floor.gltf" --lights "$IN/long_tube.json"

lights_json far_reach '{"name": "reach", "type": "point", "position": [0, 1, 0], "intensity": 100, "range": 1e38}'
refused "a range of 1e38 m" far_reach.json "'reach'|range" \
    "$IN/floor.gltf" --lights "$IN/far_reach.json"

lights_json far_away '{"name": "far", "type": "point", "position": [0, 1e30, 0], "intensity": 100}'
refused "a light 1e30 m away" far_away.json "'far'|position" \
    "$IN/floor.gltf" --lights "$IN/far_away.json"

lights_json loud_colour '{"name": "tint", "type": "point", "position": [0, 1, 0], "intensity": 100, "color": [1e30, 1, 1]}'
refused "a colour component of 1e30" loud_colour.json "'tint'|color" \
    "$IN/floor.gltf" --lights "$IN/loud_colour.json"

lights_json loud_ambient '{"name": "glow", "type": "point", "position": [0, 1, 0], "intensity": 100, "range": 5, "ambient": [1e30, 0, 0]}'
refused "an ambient of 1e30 lx" loud_ambient.json "'glow'|ambient" \
    "$IN/floor.gltf" --lights "$IN/loud_ambient.json"

# the largest values accepted still bake (1e12 cd at 1 m: 1e12 lx below it)
lights_json at_limit '{"name": "limit", "type": "point", "position": [0, 1, 0], "intensity": 1e12, "range": 1e7}'
run "$LUXEL" bake "$IN/floor.gltf" --lights "$IN/at_limit.json" --resolution 16 -o "$WORK/out/at_limit"
expect_rc 0 "a 1e12 cd light with a range of 1e7 m (the limits)"
check "the limits: the lightmap is written" test -f "$WORK/out/at_limit/floor.exr"

# ---- glTF KHR_lights_punctual ----------------------------------------------------

# gltf_light NAME LIGHT TRANSLATION: floor.gltf's floor plus a node "lamp"
# at TRANSLATION carrying the one KHR_lights_punctual light LIGHT
gltf_light() {
    sed -e 's|"nodes": \[0\]|"nodes": [0, 1]|' \
        -e "s|\"nodes\": \[{\"name\": \"floor\", \"mesh\": 0}\],|\"nodes\": [{\"name\": \"floor\", \"mesh\": 0}, {\"name\": \"lamp\", \"translation\": $3, \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}], \"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [$2]}},|" \
        "$IN/floor.gltf" >"$IN/$1.gltf"
}

gltf_light lamp_ok '{"name": "bulb", "type": "point", "intensity": 100}' '[0, 1, 0]'
run "$LUXEL" bake "$IN/lamp_ok.gltf" --resolution 16 -o "$WORK/out/lamp_ok"
expect_rc 0 "glTF: a 100 cd lamp (the generated file is sound)"

gltf_light huge_bulb '{"name": "bulb", "type": "point", "intensity": 1e38}' '[0, 1, 0]'
refused "glTF: a 1e38 cd point light" huge_bulb.gltf "'bulb'|intensity|1e+38" "$IN/huge_bulb.gltf"

gltf_light far_spot '{"name": "beam", "type": "spot", "intensity": 100, "range": 1e20, "spot": {"outerConeAngle": 0.5}}' '[0, 1, 0]'
refused "glTF: a spot light with a range of 1e20 m" far_spot.gltf "'beam'|range" "$IN/far_spot.gltf"

gltf_light loud_sun '{"name": "sun", "type": "directional", "intensity": 1e15, "color": [1, 1, 1]}' '[0, 1, 0]'
refused "glTF: a 1e15 lx sun" loud_sun.gltf "'sun'|intensity" "$IN/loud_sun.gltf"

gltf_light far_lamp '{"name": "bulb", "type": "point", "intensity": 100}' '[0, 1e30, 0]'
refused "glTF: a lamp node 1e30 m away" far_lamp.gltf "'bulb'|position" "$IN/far_lamp.gltf"

finish
