# Files an input names must lie in its folder or below (docs/ARCHITECTURE.md,
# "What luxel reads"): a glTF buffer or image URI that is absolute or climbs
# out with "..", a symbolic link inside the folder to a file outside, an OBJ
# mtllib and a material's texture path, an IES profile and a sky
# environment in the lights JSON, and a page a manifest names. Each is
# refused by every command that reads it with one error line naming the
# file and the URI, exit 1 and nothing written; --allow-any-path reads it,
# and unwrap then copies exactly the outside buffer's bytes. An assimp
# message about an OBJ's material library never quotes that file.
#
# usage: bash test_cli_paths.sh LUXEL GEN_SCENES WORKDIR
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

S=$WORK/scene # the scene's folder
OUTSIDE=$WORK/outside
mkdir -p "$S/sub" "$OUTSIDE" "$WORK/out"
TRI="0 0 0  0 0 1  1 0 1"
TRI_UV="0 0  0 1  1 1"
write_gltf "$S/base.gltf" tri_mesh tri "$TRI" "$TRI_UV" || exit 1
# the buffer moved outside, and URIs that reach it
mv "$S/base.bin" "$OUTSIDE/secret.bin"
with_uri() { sed "s#\"uri\": \"base.bin\"#\"uri\": \"$2\"#" "$S/base.gltf" >"$S/$1"; }
with_uri absolute.gltf "$OUTSIDE/secret.bin"
with_uri climbing.gltf "../outside/secret.bin"
with_uri escaped.gltf "sub/..%2F..%2Foutside/secret.bin"
ln -s "$OUTSIDE/secret.bin" "$S/link.bin"
with_uri link.gltf "link.bin"
cp "$OUTSIDE/secret.bin" "$S/sub/inside.bin"
with_uri inside.gltf "sub/./inside.bin"
# an image outside (the buffer inside)
sed 's#"meshes"#"images": [{"uri": "/etc/passwd"}], "textures": [{"source": 0}],\n  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],\n  "meshes"#; s#"mode": 4#"mode": 4, "material": 0#' \
    "$S/inside.gltf" >"$S/image.gltf"

refused() { # refused DESCRIPTION URI OUTPUT: the last run refused URI
    expect_rc 1 "$1"
    expect_error "$1" "$2" "is outside the folder" "--allow-any-path"
    check "$1: nothing written" test ! -e "$3"
}

for scene in absolute climbing escaped link image; do
    case $scene in
    absolute) uri=$OUTSIDE/secret.bin ;;
    climbing) uri=../outside/secret.bin ;;
    escaped) uri=sub/..%2F..%2Foutside/secret.bin ;;
    link) uri=link.bin ;;
    image) uri=/etc/passwd ;;
    esac
    run "$LUXEL" info "$S/$scene.gltf"
    refused "info $scene" "$uri" "$WORK/out/none"
    for cmd in unwrap tangents; do
        run "$LUXEL" "$cmd" "$S/$scene.gltf" -o "$WORK/out/$cmd-$scene.glb"
        refused "$cmd $scene" "$uri" "$WORK/out/$cmd-$scene.glb"
    done
    run "$LUXEL" bake "$S/$scene.gltf" --unwrap always --ambient 1 --resolution 16 \
        -o "$WORK/out/bake-$scene"
    refused "bake --unwrap always $scene" "$uri" "$WORK/out/bake-$scene"
done

run "$LUXEL" info "$S/inside.gltf"
expect_rc 0 "a buffer in a subfolder, named through ./"

# --allow-any-path: read, and the bytes copied are the outside file's
run "$LUXEL" unwrap "$S/climbing.gltf" --allow-any-path -o "$WORK/out/allowed.glb"
expect_rc 0 "unwrap --allow-any-path"
check "unwrap --allow-any-path: the positions copied" \
    grep -qF "$(od -An -tx1 -v "$OUTSIDE/secret.bin" | head -c 60 | tr -d ' \n')" \
    <(od -An -tx1 -v "$WORK/out/allowed.glb" | tr -d ' \n')

# ---- OBJ: the material library and its texture ---------------------------------
obj() { printf 'mtllib %s\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n' "$2" >"$S/$1"; }
printf 'newmtl a\nKd 1 1 1\n' >"$OUTSIDE/lib.mtl"
obj mtl_out.obj ../outside/lib.mtl
run "$LUXEL" info "$S/mtl_out.obj"
refused "OBJ mtllib outside" "../outside/lib.mtl" "$WORK/out/none"
# a texture outside is not read: the material goes without it, as without
# a missing texture (a file there that is no image would have been named
# as unreadable had it been read)
printf 'SECRET_WORD\n' >"$OUTSIDE/wood.png"
printf 'newmtl a\nKd 1 1 1\nmap_Kd ../outside/wood.png\n' >"$S/tex.mtl"
obj tex_out.obj tex.mtl
run "$LUXEL" bake "$S/tex_out.obj" --ambient 1 --resolution 16 -o "$WORK/out/tex"
expect_rc 0 "OBJ texture outside: baked without it"
expect_stderr_has "OBJ texture outside: one warning naming it" \
    "^luxel: warning: .*tex_out.obj: texture '../outside/wood.png' is outside the folder"
check "OBJ texture outside: not read" bash -c "! grep -q -e SECRET_WORD -e 'not loaded' '$ERR'"
# an assimp error inside the material library: its text is not quoted
printf 'newmtl a\nKd 1 1 1\nmap_Kd -bm SECRET_WORD y z\n' >"$S/bad.mtl"
obj bad_mtl.obj bad.mtl
run "$LUXEL" info "$S/bad_mtl.obj"
check "an error reading the material library does not quote it" \
    bash -c "! grep -q SECRET_WORD '$ERR'"

# ---- the lights JSON -----------------------------------------------------------
cat >"$OUTSIDE/spot.ies" <<'IES'
IESNA:LM-63-2002
TILT=NONE
1 -1 1 2 1 1 2 0.1 0.1 0.05
1 1 12
0 90
0
1000 0
IES
printf '{"lights": [{"type": "point", "position": [0, 1, 0], "intensity": 10, "ies": "../outside/spot.ies"}]}' \
    >"$S/ies.json"
run "$LUXEL" bake "$S/inside.gltf" --lights "$S/ies.json" --resolution 16 -o "$WORK/out/ies"
refused "IES profile outside" "../outside/spot.ies" "$WORK/out/ies"
run "$LUXEL" bake "$S/inside.gltf" --lights "$S/ies.json" --allow-any-path --resolution 16 \
    -o "$WORK/out/ies-any"
expect_rc 0 "IES profile outside with --allow-any-path"
printf '{"sky": {"environment": "/etc/passwd"}}' >"$S/sky.json"
run "$LUXEL" bake "$S/inside.gltf" --lights "$S/sky.json" --resolution 16 -o "$WORK/out/sky"
refused "sky environment outside" "/etc/passwd" "$WORK/out/sky"

# ---- a manifest's pages ---------------------------------------------------------
run "$LUXEL" bake "$S/inside.gltf" --ambient 1 --resolution 16 -o "$WORK/out/lm"
expect_rc 0 "a bake to render"
M=$WORK/out/lm/manifest.json
page=$(grep -o '"file":[[:space:]]*"[^"]*"' "$M" | head -1 | sed 's/.*"\([^"]*\)"$/\1/')
cp "$WORK/out/lm/$page" "$OUTSIDE/$page"
sed -i "s#\"$page\"#\"../../outside/$page\"#" "$M"
run "$LUXEL" render "$S/inside.gltf" --lightmaps "$WORK/out/lm" -o "$WORK/out/view.png"
refused "render: a page outside the manifest's folder" "../../outside/$page" "$WORK/out/view.png"
run "$LUXEL" render "$S/inside.gltf" --lightmaps "$WORK/out/lm" --allow-any-path \
    -o "$WORK/out/view.png"
expect_rc 0 "render --allow-any-path"

finish
