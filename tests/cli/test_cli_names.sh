# End-to-end tests of how luxel bake names its files (tools/luxel/bake.c,
# plan_outputs): every name is planned before the bake, a node's files
# never take a name luxel uses for its own outputs (view.png,
# manifest.json) or for another lightmap's maps (<name>_ao.png,
# <name>_sh0..3, <name>_dir.png), and the manifest points at the right file
# for each. Before, a node named `view` with --render had its preview
# overwritten by the render (exit 0, manifest wrong), and nodes `x` and
# `x_ao` with --ao failed after the whole bake with a false "could not put
# the previous file back".
#
# The scenes are written here: quads of 1 m facing up, one per node, side
# by side, each with its own TEXCOORD_0 over the whole [0,1] square, lit by
# a uniform ambient. Identical quads under a uniform light bake to
# identical lightmaps, which tells a lightmap from an AO or SH map.
#
# usage: bash test_cli_names.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

# write_quads FILE.gltf NODE...: one quad per node, named NODE, 2 m apart
# along x, all sharing one mesh.
write_quads() {
    local file=$1
    shift
    local bin=${file%.gltf}.bin v i=0
    {
        for v in 0 0 0 0 0 1 1 0 1 0 0 0 1 0 1 1 0 0; do f32 "$v"; done
        for v in 0 0 0 1 1 1 0 0 1 1 1 0; do f32 "$v"; done
    } >"$bin"
    {
        printf '{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": ['
        for ((i = 0; i < $#; i++)); do
            [ "$i" -gt 0 ] && printf ','
            printf '%d' "$i"
        done
        printf ']}],\n "nodes": ['
        i=0
        for v in "$@"; do
            [ "$i" -gt 0 ] && printf ','
            printf '{"name": "%s", "mesh": 0, "translation": [%d, 0, 0]}' "$v" $((2 * i))
            i=$((i + 1))
        done
        printf '],\n "meshes": [{"name": "q", "primitives": [{"attributes": {"POSITION": 0, '
        printf '"TEXCOORD_0": 1}, "mode": 4}]}],\n'
        printf ' "accessors": [{"bufferView": 0, "componentType": 5126, "count": 6, '
        printf '"type": "VEC3", "min": [0, 0, 0], "max": [1, 0, 1]}, {"bufferView": 1, '
        printf '"componentType": 5126, "count": 6, "type": "VEC2"}],\n'
        printf ' "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 72}, '
        printf '{"buffer": 0, "byteOffset": 72, "byteLength": 48}],\n'
        printf ' "buffers": [{"uri": "%s", "byteLength": 120}]}\n' "$(basename "$bin")"
    } >"$file"
}

# page_of FIELD NODE MANIFEST: FIELD of the page that node NODE's lightmap
# is on, as the manifest says it (quotes removed; an array as [a, b]).
# cJSON prints each key of an object on its own line.
page_of() {
    awk -v field="$1" -v node="$2" '
        function value(line) {
            sub(/^[^:]*:[ \t]*/, "", line)
            sub(/,$/, "", line)
            gsub(/"/, "", line)
            return line
        }
        /^\t"pages":/ { section = "pages"; n = -1; next }
        /^\t"nodes":/ { section = "nodes"; next }
        /^\t"/ { section = "" }
        section == "pages" && /^\t+"file":/ { n++ }
        section == "pages" && $0 ~ "^\t+\"" field "\":" { v[n] = value($0) }
        section == "nodes" && /^\t+"node":/ { current = value($0) }
        section == "nodes" && /^\t+"page":/ && current == node { page = value($0) }
        END { if (page != "") print v[page] }' "$3"
}

# expect_page LABEL DIR NODE FIELD WANT: the manifest in DIR gives WANT
# as FIELD of NODE's page, and the file is there.
expect_page() {
    local got
    got=$(page_of "$4" "$3" "$2/manifest.json")
    if [ "$got" = "$5" ]; then
        pass "$1: node '$3' has $4 $5"
    else
        fail "$1: node '$3' has $4 '$got', want '$5'"
    fi
}

# A PNG's colour type (0 grey, 2 RGB, 6 RGBA) and width, from its IHDR.
png_colour_type() { od -An -tu1 -j25 -N1 "$1" | tr -d ' '; }
png_width() { od -An -tu1 -j16 -N4 "$1" | awk '{ print (($1 * 256 + $2) * 256 + $3) * 256 + $4 }'; }

# expect_one_warning LABEL NEEDLE...: exactly one warning line on stderr
# says the files were renamed, and it names every needle.
expect_rename_warning() {
    local what=$1 line needle
    shift
    line=$(grep 'would share file names' "$ERR")
    if [ "$(grep -c 'would share file names' "$ERR")" -ne 1 ]; then
        fail "$what: want one warning about renamed files" "$line"
        return
    fi
    for needle in "$@"; do
        case $line in
        *"$needle"*) ;;
        *)
            fail "$what: the warning does not say '$needle'" "$line"
            return
            ;;
        esac
    done
    pass "$what: one warning naming $*"
}

# not --quiet: the warnings are checked
BAKE=(bake --ambient 1 --resolution 16 --no-atlas --unwrap never --uv-set 0)

# ---- a node named view, with --render --------------------------------------------

write_quads "$WORK/view.gltf" view floor
label="node 'view' with --render"
run "$LUXEL" "${BAKE[@]}" "$WORK/view.gltf" --render -o "$WORK/view"
expect_rc 0 "$label"
expect_files "$label" "$WORK/view" view_2.exr view_2.png floor.exr floor.png view.png \
    manifest.json
expect_rename_warning "$label" "'view' as view_2"
expect_page "$label" "$WORK/view" view file view_2.exr
expect_page "$label" "$WORK/view" view preview view_2.png
check "$label: the manifest names the render" \
    grep -Eq '^\s"render":\s*"view.png"' "$WORK/view/manifest.json"
# the render is the camera's picture, not the 16 x 16 preview of a lightmap
check "$label: view.png is the render (wider than a lightmap)" \
    test "$(png_width "$WORK/view/view.png")" -gt 16
check "$label: view_2.png is node view's preview (16 wide)" \
    test "$(png_width "$WORK/view/view_2.png")" -eq 16
check "$label: the two quads' lightmaps are alike (same light)" \
    cmp -s "$WORK/view/view_2.exr" "$WORK/view/floor.exr"

# without --render the node's files keep the same names, and view.png is
# not written
run "$LUXEL" "${BAKE[@]}" "$WORK/view.gltf" -o "$WORK/view_norender"
expect_rc 0 "node 'view' without --render"
expect_files "node 'view' without --render" "$WORK/view_norender" view_2.exr view_2.png \
    floor.exr floor.png manifest.json

# ---- x and x_ao, with --ao ---------------------------------------------------------

for order in "x x_ao" "x_ao x"; do
    write_quads "$WORK/ao.gltf" $order
    label="nodes ${order/ / and } with --ao"
    out=$WORK/ao_${order// /_}
    run "$LUXEL" "${BAKE[@]}" "$WORK/ao.gltf" --ao -o "$out"
    expect_rc 0 "$label"
    if [ "$order" = "x x_ao" ]; then
        # x comes first and keeps its names; x_ao's lightmap would be x_ao.png's
        expect_files "$label" "$out" x.exr x.png x_ao.png x_ao_2.exr x_ao_2.png \
            x_ao_2_ao.png manifest.json
        expect_rename_warning "$label" "'x_ao' as x_ao_2"
        expect_page "$label" "$out" x ao x_ao.png
        expect_page "$label" "$out" x_ao file x_ao_2.exr
        expect_page "$label" "$out" x_ao preview x_ao_2.png
        expect_page "$label" "$out" x_ao ao x_ao_2_ao.png
        ao_of_x=$out/x_ao.png
        preview_of_x_ao=$out/x_ao_2.png
    else
        # x_ao comes first: x's AO map would take its preview's name
        expect_files "$label" "$out" x_ao.exr x_ao.png x_ao_ao.png x_2.exr x_2.png \
            x_2_ao.png manifest.json
        expect_rename_warning "$label" "'x' as x_2"
        expect_page "$label" "$out" x_ao preview x_ao.png
        expect_page "$label" "$out" x ao x_2_ao.png
        ao_of_x=$out/x_2_ao.png
        preview_of_x_ao=$out/x_ao.png
    fi
    # AO maps are written grey, previews RGB: each name holds what it says
    check "$label: node x's AO map is a grey PNG" test "$(png_colour_type "$ao_of_x")" = 0
    check "$label: node x_ao's preview is an RGB PNG" \
        test "$(png_colour_type "$preview_of_x_ao")" = 2
done

# ---- x and x_sh0, with --directional sh; x and x_dir with dominant ------------------

write_quads "$WORK/sh.gltf" x x_sh0
label="nodes x and x_sh0 with --directional sh"
run "$LUXEL" "${BAKE[@]}" "$WORK/sh.gltf" --directional sh -o "$WORK/sh"
expect_rc 0 "$label"
expect_files "$label" "$WORK/sh" x.exr x.png x_sh0.exr x_sh1.exr x_sh2.exr x_sh3.exr \
    x_sh0_2.exr x_sh0_2.png x_sh0_2_sh0.exr x_sh0_2_sh1.exr x_sh0_2_sh2.exr x_sh0_2_sh3.exr \
    manifest.json
expect_rename_warning "$label" "'x_sh0' as x_sh0_2"
expect_page "$label" "$WORK/sh" x sh "[x_sh0.exr, x_sh1.exr, x_sh2.exr, x_sh3.exr]"
expect_page "$label" "$WORK/sh" x_sh0 file x_sh0_2.exr
# the two quads see the same light: their lightmaps are one file's bytes,
# and node x's SH maps are its own (the same as node x_sh0's)
check "$label: node x_sh0's lightmap is the lightmap (as node x's)" \
    cmp -s "$WORK/sh/x.exr" "$WORK/sh/x_sh0_2.exr"
check "$label: node x's sh0 is an SH map (as node x_sh0's)" \
    cmp -s "$WORK/sh/x_sh0.exr" "$WORK/sh/x_sh0_2_sh0.exr"

write_quads "$WORK/dir.gltf" x x_dir
label="nodes x and x_dir with --directional dominant"
run "$LUXEL" "${BAKE[@]}" "$WORK/dir.gltf" --directional dominant -o "$WORK/dir"
expect_rc 0 "$label"
expect_files "$label" "$WORK/dir" x.exr x.png x_dir.png x_dir_2.exr x_dir_2.png \
    x_dir_2_dir.png manifest.json
expect_page "$label" "$WORK/dir" x dir x_dir.png
expect_page "$label" "$WORK/dir" x_dir preview x_dir_2.png
check "$label: node x's dominant direction is RGBA" \
    test "$(png_colour_type "$WORK/dir/x_dir.png")" = 6
check "$label: node x_dir's preview is RGB" \
    test "$(png_colour_type "$WORK/dir/x_dir_2.png")" = 2

# ---- names that differ only in case, or after path characters are replaced --------

write_quads "$WORK/case.gltf" Floor floor "a/b" a_b
label="nodes Floor, floor, a/b and a_b"
run "$LUXEL" "${BAKE[@]}" "$WORK/case.gltf" -o "$WORK/case"
expect_rc 0 "$label"
expect_files "$label" "$WORK/case" Floor.exr Floor.png floor_2.exr floor_2.png a_b.exr \
    a_b.png a_b_2.exr a_b_2.png manifest.json
expect_page "$label" "$WORK/case" floor file floor_2.exr
expect_page "$label" "$WORK/case" a_b file a_b_2.exr

# the same scene names its files the same way every time
run "$LUXEL" "${BAKE[@]}" "$WORK/case.gltf" -o "$WORK/case"
expect_rc 0 "$label, again into the same folder"
expect_files "$label, again into the same folder" "$WORK/case" Floor.exr Floor.png \
    floor_2.exr floor_2.png a_b.exr a_b.png a_b_2.exr a_b_2.png manifest.json

finish
