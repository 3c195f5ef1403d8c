# cases: gltf_sparse texture ibl_image light2d_image light2d_lights probes_count probes_write bake_plan
# End-to-end tests of inputs that ask for more memory than they are worth
# (issue 27, "memory taken before it is checked"): a few bytes of file
# that would make luxel or a decoder it calls allocate gigabytes must fail
# up front, before the allocation, with one line naming the file and the
# size asked, exit 1 and no output, and the run's peak memory stays small.
# The cases run under an address-space limit (ulimit -v), which the
# library counts as the memory it may use, so they fail the same on any
# machine; a build that cannot run under such a limit (a sanitizer's)
# reports them skipped, as test_cli_limits.sh does.
#
# usage: bash test_cli_input_memory.sh LUXEL GEN_SCENES WORKDIR CASE
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

IN=$WORK/in
mkdir -p "$IN"
LIMIT_KIB=2097152 # 2 GiB of address space
PEAK_KIB=0

# limited CMD ARGS...: runs the command under the address-space limit,
# with its peak resident memory in PEAK_KIB (from /usr/bin/time when the
# machine has it, else 0 and the RSS checks are skipped).
limited() {
    local peak=$WORK/.peak
    rm -f "$peak"
    if [ -x /usr/bin/time ]; then
        run /usr/bin/time -f %M -o "$peak" bash -c 'ulimit -v "$0" && exec "$@"' "$LIMIT_KIB" "$@"
        PEAK_KIB=$(tail -n 1 "$peak" 2>/dev/null)
    else
        run bash -c 'ulimit -v "$0" && exec "$@"' "$LIMIT_KIB" "$@"
        PEAK_KIB=0
    fi
}

# expect_peak_below DESCRIPTION MIB: the last limited run's peak RSS.
expect_peak_below() {
    if [ ! -x /usr/bin/time ]; then
        skip "$1: no /usr/bin/time to measure the peak memory"
    elif [ "${PEAK_KIB:-0}" -lt $(($2 * 1024)) ] 2>/dev/null; then
        pass "$1: peak memory $((PEAK_KIB / 1024)) MiB, below $2 MiB"
    else
        fail "$1: peak memory ${PEAK_KIB:-?} KiB, want below $2 MiB"
    fi
}

if ! bash -c 'ulimit -v "$0" && exec "$@"' "$LIMIT_KIB" "$LUXEL" --version >/dev/null 2>&1; then
    skip "luxel cannot run with a 2 GiB address-space limit (sanitizer build?)"
    finish
fi

# big_png FILE WIDTH HEIGHT: an 8-bit RGB PNG whose header claims
# WIDTH x HEIGHT, with an empty (valid) zlib stream for its data: what the
# size check reads is the header, before anything is decoded. (Neither stb
# nor luxel reads the chunks' CRCs, left zero here.)
be32() { printf "\\x%02x\\x%02x\\x%02x\\x%02x" $(($1 >> 24 & 255)) $(($1 >> 16 & 255)) \
    $(($1 >> 8 & 255)) $(($1 & 255)); }
big_png() {
    {
        printf '\x89PNG\r\n\x1a\n'
        printf '\x00\x00\x00\x0dIHDR'
        printf "$(be32 "$2")$(be32 "$3")"
        printf '\x08\x02\x00\x00\x00\x00\x00\x00\x00'           # 8 bits, RGB; CRC
        printf '\x00\x00\x00\x0bIDAT\x78\x01\x01\x00\x00\xff\xff\x00\x00\x00\x01'
        printf '\x00\x00\x00\x00'                                 # CRC
        printf '\x00\x00\x00\x00IEND\x00\x00\x00\x00'
    } >"$1"
}

case $CASE_NAME in
gltf_sparse)
    # One triangle's worth of sparse values on an accessor of 30M VEC3
    # floats without a bufferView: 360 MB of zeros assimp would fill, and
    # about 2 GB it takes doing so (measured), from ~1 KB of JSON.
    {
        printf '\x00\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00' # indices 0 1 2
        for v in 0 0 0 1 0 0 0 1 0; do f32 "$v"; done
    } >"$IN/sparse.bin"
    sparse_gltf() { # sparse_gltf COUNT SPARSE_COUNT
        cat <<JSON
{
  "asset": {"version": "2.0", "generator": "luxel tests/cli"},
  "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"name": "zeros", "mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 4}]}],
  "accessors": [
    {"componentType": 5126, "count": $1, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0],
     "sparse": {"count": $2, "indices": {"bufferView": 0, "componentType": 5125},
                "values": {"bufferView": 1}}}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 12},
    {"buffer": 0, "byteOffset": 12, "byteLength": 36}],
  "buffers": [{"uri": "sparse.bin", "byteLength": 48}]
}
JSON
    }
    sparse_gltf 30000000 3 >"$IN/sparse.gltf"
    for cmd in bake unwrap; do
        out=$WORK/out_$cmd
        [ $cmd = unwrap ] && out=$out.glb
        limited "$LUXEL" $cmd "$IN/sparse.gltf" -q -o "$out"
        expect_rc 1 "$cmd: 30M elements without a bufferView"
        expect_error "$cmd: 30M elements without a bufferView" "sparse.gltf" "accessor 0" \
            "30000000 elements" "GiB of memory"
        expect_no_output "$cmd: 30M elements without a bufferView" "$out"
        expect_peak_below "$cmd: 30M elements without a bufferView" 256
    done
    # a sparse block larger than its accessor is malformed, whatever the memory
    sparse_gltf 2 3 >"$IN/over.gltf"
    run "$LUXEL" bake "$IN/over.gltf" -q -o "$WORK/out_over"
    expect_rc 1 "sparse count 3 on an accessor of 2"
    expect_error "sparse count 3 on an accessor of 2" "over.gltf" "accessor 0" \
        "sparse count 3 is more than the accessor's count 2"
    expect_no_output "sparse count 3 on an accessor of 2" "$WORK/out_over"
    # its indices must lie in their bufferView: 3 uint32 do not fit in 12 bytes at offset 4
    sparse_gltf 30 3 | sed 's/"componentType": 5125}/"componentType": 5125, "byteOffset": 4}/' \
        >"$IN/short.gltf"
    run "$LUXEL" bake "$IN/short.gltf" -q -o "$WORK/out_short"
    expect_rc 1 "sparse indices past their bufferView"
    expect_error "sparse indices past their bufferView" "short.gltf" "accessor 0" \
        "sparse indices: 4 bytes past the end of bufferView 0"
    expect_no_output "sparse indices past their bufferView" "$WORK/out_short"
    ;;
texture)
    # A base-colour texture of 16000^2 (the issue's 746 KB PNG took 7.8 GB
    # for a 32^2 bake): refused from its header, beyond the
    # 8192 x 8192 pixels a scene load decodes, with a warning naming its
    # size; the bake goes on with the material's factor.
    big_png "$IN/huge.png" 16000 16000
    write_gltf "$IN/plane.gltf" plane floor "0 0 0  1 0 0  1 0 1" "0 0  1 0  1 1" || exit 1
    sed -i 's/"mode": 4}/"mode": 4, "material": 0}/
        s/"buffers":/"materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],\
  "textures": [{"source": 0}], "images": [{"uri": "huge.png"}],\
  "buffers":/' "$IN/plane.gltf"
    limited "$LUXEL" bake "$IN/plane.gltf" --resolution 32 --ambient 1,1,1 -o "$WORK/out_tex"
    expect_rc 0 "bake with a 16000^2 base-colour texture"
    expect_stderr_has "the warning names the texture and its size" \
        "huge\.png: image 16000x16000 \(256000000 pixels\) is larger than the 67108864 pixels allowed"
    expect_peak_below "bake with a 16000^2 base-colour texture" 256
    ;;
ibl_image)
    # an environment of 16000 x 8000 RGB: 1.4 GiB of floats, and the
    # decoder's buffer beside it, beyond 2 GiB: refused from the header
    big_png "$IN/sky.png" 16000 8000
    limited "$LUXEL" ibl "$IN/sky.png" -q -o "$WORK/out_ibl"
    expect_rc 1 "ibl of a 16000x8000 PNG"
    expect_error "ibl of a 16000x8000 PNG" "sky.png" "image 16000x8000 (3 channels) needs" \
        "GiB of memory"
    expect_no_output "ibl of a 16000x8000 PNG" "$WORK/out_ibl"
    expect_peak_below "ibl of a 16000x8000 PNG" 256
    ;;
light2d_image)
    big_png "$IN/casters.png" 16000 16000
    printf '{"lights": [{"position": [8, 8], "radius": 10}]}\n' >"$IN/lights.json"
    limited "$LUXEL" light2d --casters "$IN/casters.png" --mask --lights "$IN/lights.json" -q \
        -o "$WORK/out_l2.png"
    expect_rc 1 "light2d casters of 16000x16000"
    expect_error "light2d casters of 16000x16000" "casters.png" \
        "image 16000x16000 (3 channels) needs" "GiB of memory"
    expect_no_output "light2d casters of 16000x16000" "$WORK/out_l2.png"
    expect_peak_below "light2d casters of 16000x16000" 256
    ;;
light2d_lights)
    # 5000 static shadowed lights of radius 1000 over 400 x 400 pixels: each
    # caches its lit box (400^2 x 3 floats, 1.8 MiB) and keeps a polar
    # shadow map; 190 KB of JSON asked for 9.3 GB before the check.
    # The casters: a grey PFM (--mask) of zeros, no caster at all.
    { printf 'Pf\n400 400\n-1.0\n'; head -c $((400 * 400 * 4)) /dev/zero; } >"$IN/casters.pfm"
    {
        printf '{"lights": ['
        for ((i = 0; i < 5000; i++)); do
            [ $i -gt 0 ] && printf ','
            printf '{"position": [%d, %d], "radius": 1000}\n' $((i % 400)) $((i / 400))
        done
        printf ']}\n'
    } >"$IN/many.json"
    limited "$LUXEL" light2d --casters "$IN/casters.pfm" --mask --lights "$IN/many.json" -q \
        -o "$WORK/out_many.png"
    expect_rc 1 "light2d with 5000 lights"
    expect_error "light2d with 5000 lights" "many.json" \
        "the caches and shadow maps of 5000 lights needs" "GiB of memory"
    expect_no_output "light2d with 5000 lights" "$WORK/out_many.png"
    expect_peak_below "light2d with 5000 lights" 256
    # the same lights, 50 of them, fit
    {
        printf '{"lights": ['
        for ((i = 0; i < 50; i++)); do
            [ $i -gt 0 ] && printf ','
            printf '{"position": [%d, 200], "radius": 1000}\n' $((i * 8))
        done
        printf ']}\n'
    } >"$IN/fifty.json"
    limited "$LUXEL" light2d --casters "$IN/casters.pfm" --mask --lights "$IN/fifty.json" -q \
        -o "$WORK/out_fifty.png"
    expect_rc 0 "light2d with 50 lights"
    check "light2d with 50 lights: the image is written" test -s "$WORK/out_fifty.png"
    ;;
probes_count)
    # 2^24 probes (the most --grid allows) hold 2 GiB of points and
    # results: refused before the bake
    "$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
    limited "$LUXEL" probes "$WORK/scenes/room.glb" --grid 1024,1024,16 -q -o "$WORK/grid.json"
    expect_rc 1 "probes --grid 1024,1024,16"
    expect_error "probes --grid 1024,1024,16" "room.glb" "the buffers of 16777216 light probes needs" \
        "GiB of memory"
    expect_no_output "probes --grid 1024,1024,16" "$WORK/grid.json"
    expect_peak_below "probes --grid 1024,1024,16" 256
    ;;
probes_write)
    # 200k probes at the points of a 3.7 MB file: the file is written as
    # it is made (a JSON tree of them took 804 MB and 11 s)
    "$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
    awk 'BEGIN {
        printf "{\"points\": ["
        for (i = 0; i < 200000; i++) {
            if (i) printf ","
            printf "[%g, 1.5, %g]", (i % 100) * 0.03 - 1.5, int(i / 100) % 100 * 0.03 - 1.5
        }
        printf "]}\n"
    }' >"$IN/points.json"
    limited "$LUXEL" probes "$WORK/scenes/room.glb" --points "$IN/points.json" --resolution 16 \
        --bounces 1 --gi-samples 4 --samples 16 -q -o "$WORK/many.json"
    expect_rc 0 "probes at 200000 points"
    check "probes at 200000 points: every probe is in the file" \
        test "$(grep -c '"position":' "$WORK/many.json")" -eq 200000
    check "probes at 200000 points: the file ends its JSON" \
        cmp -s <(tail -c 4 "$WORK/many.json") <(printf '}]\n}')
    expect_peak_below "probes at 200000 points" 300
    ;;
bake_plan)
    # Under ulimit -v the bake's plan counts what the run will reserve
    # (Embree's device, the threads' stacks and arenas) as well as its
    # buffers: a run given what a failing run said it needs (plus a little
    # for the rounding) bakes to the end, it does not pass the plan and
    # fail later (in a tile's rebuild or the denoiser, as it did).
    "$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
    PLAN=(bake "$WORK/scenes/room.glb" --resolution 128 --denoise all --threads 1 -q)
    # 250 MiB: room for the malloc arena of the scene's import thread
    # (glibc maps 128 MiB to align a 64 MiB arena, and makes none where the
    # limit leaves no room for that), so both runs below hold one
    LIMIT_KIB=$((250 * 1024))
    limited "$LUXEL" "${PLAN[@]}" -o "$WORK/out_small"
    expect_rc 1 "bake under 250 MiB of address space"
    expect_error "bake under 250 MiB of address space" "room.glb" "MiB of memory, the address-space limit"
    expect_no_output "bake under 250 MiB of address space" "$WORK/out_small"
    line=$(grep '^luxel: error:' "$ERR")
    need=$(printf '%s\n' "$line" | sed -n 's/.* needs \([0-9.]*\) MiB of memory.*/\1/p')
    used=$(printf '%s\n' "$line" | sed -n 's/.*, \([0-9.]*\) MiB of it in use.*/\1/p')
    if [ -z "$need" ] || [ -z "$used" ]; then
        fail "the error states the memory needed and in use in MiB" "$line"
        finish
    fi
    LIMIT_KIB=$(awk -v n="$need" -v u="$used" 'BEGIN { printf "%d", (n + u + 2) * 1024 }')
    limited "$LUXEL" "${PLAN[@]}" -o "$WORK/out_fits"
    expect_rc 0 "bake under the $LIMIT_KIB KiB the plan asked for"
    check "the bake under the plan's limit wrote its lightmaps" test -s "$WORK/out_fits/room.exr"
    ;;
*)
    fail "unknown case '$CASE_NAME'"
    ;;
esac

finish
