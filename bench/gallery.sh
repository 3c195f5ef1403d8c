#!/usr/bin/env bash
# The gallery (issue 28): public game-like glTF scenes that users bring,
# baked by `luxel bake` with its DEFAULT options and rendered (--render), so
# that someone looks at every picture. Not a test: nothing here passes or
# fails on the pictures; it records what each bake did.
#
#   bench/gallery.sh [--build DIR] [--out DIR] [--threads N] [NAME...]
#   bench/gallery.sh --fill-mirror DIR --from-git ROOT
#   bench/gallery.sh --list
#
# Each scene's files are downloaded at run time from their repositories,
# pinned to a commit, into OUT/cache/ and checked against the sha256 sums
# below; nothing downloaded is committed. Then, per scene, into OUT/NAME/:
#   info.txt   luxel info on the scene
#   lights.json (and sky.pfm, gen_scenes' clear day) where the scene has none
#   bake.log   luxel bake SCENE -o OUT/NAME --render [--lights lights.json]
#   view.png, the lightmaps and their PNG previews, manifest.json
#   view_close.png: luxel render from a camera closer in, for the scenes whose
#              default view shows little (an interior seen from outside)
# and a line in OUT/summary.txt: exit status, seconds, peak memory, texels,
# texel density, warnings. A lights JSON (bench/gallery/NAME.json) is given
# only to scenes that carry no lights of their own.
#
# Offline (no internet): LUXEL_GALLERY_MIRROR=DIR takes the files from DIR
# instead, laid out as the download URLs' paths (DIR/OWNER/REPO/COMMIT/PATH).
# --fill-mirror DIR --from-git ROOT fills such a DIR from local git copies of
# the repositories: ROOT/OWNER+REPO/repo (bare), ROOT/OWNER/REPO.git or
# ROOT/OWNER/REPO (a clone), each holding the pinned commit.
#
# Environment: LUXEL_GALLERY_MIRROR (above), LUXEL_GALLERY_THREADS (passed as
# --threads; default: luxel's, all cores), LUXEL_GALLERY_TIMEOUT (seconds a
# bake may take before it is interrupted, status "timeout"; default 1800).
# docs/gallery.md lists the scenes.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(dirname "$here")
build=$root/build
out=
threads=${LUXEL_GALLERY_THREADS:-}
time_limit=${LUXEL_GALLERY_TIMEOUT:-1800}
mirror=${LUXEL_GALLERY_MIRROR:-}
base_url=https://raw.githubusercontent.com

# name|scene file|repository|commit|folder in the repository|licence|author|
# a close-up camera (eye,target for luxel render --camera; empty: none)
scenes=(
    "cornell|CornellBox.glb|bevyengine/bevy|4805ca792c3e94eef07afd6fa9a2712f388c9a67|assets/models/CornellBox|MIT OR Apache-2.0|Bevy contributors (Blender export; lit by its emissive ceiling alone)|-278,274,1050,-278,274,-280"
    "mixed_lighting|MixedLightingExample.gltf|bevyengine/bevy|4805ca792c3e94eef07afd6fa9a2712f388c9a67|assets/models/MixedLightingExample|MIT OR Apache-2.0; SheenChair CC-BY-4.0|Bevy contributors; SheenChair (c) 2021 Wayfair LLC (glTF sample models)|"
    "circuit_board|DepthOfFieldExample.glb|bevyengine/bevy|4805ca792c3e94eef07afd6fa9a2712f388c9a67|assets/models/DepthOfFieldExample|MIT OR Apache-2.0|Bevy contributors (sun, emissive lava spheres)|"
    "fog_room|VolumetricFogExample.glb|bevyengine/bevy|4805ca792c3e94eef07afd6fa9a2712f388c9a67|assets/models/VolumetricFogExample|MIT OR Apache-2.0|Bevy contributors (sun through openings)|2.6,1.5,-6,-1.5,2,5"
    "zdm2|zdm2.glb|godotengine/godot-demo-projects|cae8dc567a56d3e7936f171bcb85f0ccb9634ad0|3d/global_illumination|CC-BY-4.0|Cube 2: Sauerbraten map zdm2, converted by Hugo Locurcio (Calinou)|8,10,20,-10,-4,2"
    "living_room|living_room.glb|godotengine/godot-demo-projects|cae8dc567a56d3e7936f171bcb85f0ccb9634ad0|3d/physical_light_camera_units|MIT|Godot Engine contributors|3.5,2.8,-1.7,-2.5,1.4,2"
    "truck_town|town_model.gltf|godotengine/godot-demo-projects|cae8dc567a56d3e7936f171bcb85f0ccb9634ad0|3d/truck_town/town/model|MIT|Godot Engine contributors (Godot glTF export, EXT_texture_webp)|60,45,70,-5,0,-20"
    "japanese_garden|scene.glb|gkjohnson/3d-demo-data|a79b5400ba8ed5bdeffebc10ce5adeecda7c3ebc|models/japanese-bridge-garden|CC-BY-4.0|\"Japanese Bridge Garden\" by kristenlee (Sketchfab), gltfpack -cc by Garrett Johnson|"
)

# name|path under the scene's folder|sha256
files=(
    "cornell|CornellBox.glb|0715772da574fa6a2d6d9af2630251f01a3a52929962c3ca18e73a84df3a299d"
    "mixed_lighting|MixedLightingExample.gltf|24d6c984df9e5b546f963ddb06ecb89c9bf8ef0a62d7f4bf2eead77206148b09"
    "mixed_lighting|MixedLightingExample.bin|cc423cd25c96a75838c176618ff2d977cbe4f7b4e747e5ac91741e8ff5aa3818"
    "mixed_lighting|SheenChairBaseColor.jpg|43a2f60d56abf45f4aa9cd2cab78a4feeff99fdf6bb175b79e4252211ef401e2"
    "mixed_lighting|SheenChairFabricNormal.jpg|ae8f7bd0c3eff41f829c9af559addaa089745a4f8bc8b220a5304947df9d4fe7"
    "mixed_lighting|SheenChairFabricOcclusion.jpg|7bb745fe1273b740307597778579501addb4f7fd3a2173555efcf574bf86d443"
    "mixed_lighting|SheenChairLabelBaseColor.jpg|c5a792c98a9e8845716b2a89e2bd9ec9425444d0b0d3782dcd872b57de525559"
    "mixed_lighting|SheenChairOcclusion-SheenChairBaseColor.jpg|bd838931c9a29463c8d06204af141800f1ce26fb2d1e0602e0f0f42f152a98fd"
    "mixed_lighting|SheenChairOcclusion-SheenChairWoodMetallicRoughness.jpg|1e978314929c5c2dc81e032aad97407588c89cd9e12bdcd10ee98a94fc6da7d3"
    "mixed_lighting|SheenChairOcclusion.jpg|068aedb0f3d9d2fd1c14423c025e1a554bae6001f0772acd28c01f7c4a8e13e2"
    "mixed_lighting|SheenChairWoodBaseColor.jpg|f3c304f351504e3636ee8bfef7f383306ee744fb38aec7b506d807b2e838a4f9"
    "circuit_board|DepthOfFieldExample.glb|f1d6ff05ce69201b2a8cb5e03d9cdcc94f1100bc560e7462be59e00b8c0bb496"
    "fog_room|VolumetricFogExample.glb|8db4886743bd0e8a98d964328a1cc58d218cd7d12cdfcd6ed66d266e741cde71"
    "zdm2|zdm2.glb|d099555ac483c420f4bc7112e43f829f4394cef0152af35921c3f0e5ec998239"
    "living_room|living_room.glb|b6738302a0c653efc98b37c110e729beffbfdc45901b2fddc9ad8b1fa338f345"
    "truck_town|town_model.gltf|ef7ac60bfc849c882d6613f4d00e9226d2b3f521880c01955b2f84030bf98aac"
    "truck_town|town_model0.bin|9a598321b8010fc06f20236ead2c998e59d8a61c2f09950c4cdc1b53b0908913"
    "truck_town|textures/grass_lossy.webp|ae55098aa6472ca4b00bb90584a794d308e90190b8b8381062d3688accb869c6"
    "truck_town|textures/cement_lossy.webp|f4d960000c7de1f5d1354820da9392fbb4a6f175670ec70eac8c1ab0cc0981fb"
    "japanese_garden|scene.glb|2fd94024f4cdd294ed3758fd0dfd1d60854cbb995c065a736ad2a2b547b39669"
)

die() {
    echo "gallery: $*" >&2
    exit 1
}

usage() {
    sed -n '/^#   bench/p' "${BASH_SOURCE[0]}" | sed 's/^# *//' >&2
    exit 2
}

# scene_field NAME INDEX: one field of the scene's line
scene_field() {
    local line f
    for line in "${scenes[@]}"; do
        IFS='|' read -r -a f <<<"$line"
        if [[ ${f[0]} == "$1" ]]; then
            printf '%s\n' "${f[$2]:-}"
            return 0
        fi
    done
    return 1
}

# url_path NAME FILE: OWNER/REPO/COMMIT/FOLDER/FILE, the URL's path
url_path() {
    printf '%s/%s/%s/%s\n' "$(scene_field "$1" 2)" "$(scene_field "$1" 3)" \
        "$(scene_field "$1" 4)" "$2"
}

sha256_of() {
    sha256sum "$1" | cut -c1-64
}

# fetch_scene NAME: every file of the scene in OUT/cache/NAME/, checked
fetch_scene() {
    local name=$1 line f path dest sum tmp
    for line in "${files[@]}"; do
        IFS='|' read -r -a f <<<"$line"
        [[ ${f[0]} == "$name" ]] || continue
        path=$(url_path "$name" "${f[1]}")
        dest=$out/cache/$name/${f[1]}
        sum=${f[2]}
        if [[ -f $dest && $(sha256_of "$dest") == "$sum" ]]; then
            continue
        fi
        mkdir -p "$(dirname "$dest")"
        tmp=$dest.part
        if [[ -n $mirror ]]; then
            [[ -f $mirror/$path ]] || die "$name: $mirror/$path is missing (LUXEL_GALLERY_MIRROR)"
            cp "$mirror/$path" "$tmp"
        else
            curl -fsSL --retry 2 -o "$tmp" "$base_url/$path" ||
                die "$name: could not download $base_url/$path"
        fi
        if [[ $(sha256_of "$tmp") != "$sum" ]]; then
            rm -f "$tmp"
            die "$name: ${f[1]}: sha256 differs from the pinned $sum"
        fi
        mv "$tmp" "$dest"
    done
}

# git_dir ROOT OWNER/REPO: a git directory for the repository under ROOT
git_dir() {
    local owner=${2%%/*} repo=${2#*/} d
    for d in "$1/$owner+$repo/repo" "$1/$owner/$repo.git" "$1/$owner/$repo/.git" "$1/$repo/.git"; do
        if [[ -d $d ]]; then
            printf '%s\n' "$d"
            return 0
        fi
    done
    return 1
}

fill_mirror() {
    local dir=$1 from=$2 line f name repo commit folder gd dest
    for line in "${files[@]}"; do
        IFS='|' read -r -a f <<<"$line"
        name=${f[0]}
        repo=$(scene_field "$name" 2)
        commit=$(scene_field "$name" 3)
        folder=$(scene_field "$name" 4)
        gd=$(git_dir "$from" "$repo") || die "no git copy of $repo under $from"
        dest=$dir/$(url_path "$name" "${f[1]}")
        mkdir -p "$(dirname "$dest")"
        git --git-dir="$gd" cat-file blob "$commit:$folder/${f[1]}" >"$dest.part" ||
            die "$repo: $commit:$folder/${f[1]} not found in $gd"
        [[ $(sha256_of "$dest.part") == "${f[2]}" ]] ||
            die "$repo: $folder/${f[1]}: sha256 differs from the pinned ${f[2]}"
        mv "$dest.part" "$dest"
        echo "$dest"
    done
}

list_scenes() {
    local line f
    for line in "${scenes[@]}"; do
        IFS='|' read -r -a f <<<"$line"
        printf '%-16s %s\n  %s/%s/%s/%s/%s\n  licence: %s\n' "${f[0]}" "${f[6]}" \
            "https://github.com" "${f[2]}" "blob/${f[3]}" "${f[4]}" "${f[1]}" "${f[5]}"
    done
}

# bake_scene NAME: info, bake and render into OUT/NAME, one summary line
bake_scene() {
    local name=$1 file dir scene lights=() log start end secs status peak texels density warnings
    file=$(scene_field "$name" 1)
    dir=$out/$name
    scene=$out/cache/$name/$file
    mkdir -p "$dir"
    if [[ -f $here/gallery/$name.json ]]; then
        cp "$here/gallery/$name.json" "$dir/lights.json"
        lights=(--lights "$dir/lights.json")
        # the outdoor scenes' sky: gen_scenes' clear day (sun 40 degrees up)
        if grep -q '"sky.pfm"' "$dir/lights.json"; then
            [[ -f $out/gen/sky.pfm ]] || "$build/bin/gen_scenes" "$out/gen" >/dev/null
            cp "$out/gen/sky.pfm" "$dir/sky.pfm"
        fi
    fi
    "$luxel" info "$scene" >"$dir/info.txt" 2>&1 || true
    local thread_args=()
    [[ -z $threads ]] || thread_args=(--threads "$threads")
    log=$dir/bake.log
    echo "== $name: luxel bake $file -o $dir --render ${lights[*]:+--lights lights.json} ${thread_args[*]}"
    start=$(date +%s.%N)
    status=0
    local run=(timeout -s INT -k 60 "$time_limit")
    [[ -z $time_cmd ]] || run+=("$time_cmd" -f 'peak_kb %M' -o "$dir/time.txt")
    rm -f "$dir/time.txt"
    "${run[@]}" "$luxel" bake "$scene" -o "$dir" --render "${lights[@]}" "${thread_args[@]}" \
        >"$log" 2>&1 || status=$?
    # timeout's status, or the time command's report of luxel's Ctrl-C
    if [[ $status -eq 124 ]] || grep -q '^luxel: error: interrupted' "$log"; then
        [[ $status -eq 0 ]] || status=timeout
    fi
    end=$(date +%s.%N)
    secs=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')
    peak=-
    if [[ -f $dir/time.txt ]] && grep -q '^peak_kb' "$dir/time.txt"; then
        peak=$(awk '/^peak_kb/ { printf "%d", $2 / 1024 }' "$dir/time.txt")
    fi
    local camera
    camera=$(scene_field "$name" 7)
    if [[ $status == 0 && -n $camera ]]; then
        "$luxel" render "$scene" --lightmaps "$dir" --camera "$camera" -o "$dir/view_close.png" \
            "${thread_args[@]}" -q >>"$log" 2>&1 || echo "   luxel render --camera $camera failed" >&2
    fi
    texels=$(sed -n 's/.*luxel: baked .*(\([0-9]*\) texels\{0,1\}.*/\1/p' "$log" | tail -1)
    density=$(sed -n 's/.* at \([0-9.]*\) texels\/m.*/\1/p' "$log" | tail -1)
    warnings=$(grep -c '^luxel: warning:' "$log" || true)
    printf '%-16s %6s %8s %8s %10s %8s %9s  %s\n' "$name" "$status" "$secs" "$peak" \
        "${texels:--}" "${density:-$([[ -n $texels ]] && echo given || echo -)}" "$warnings" \
        "$([[ -f $dir/view.png ]] && echo "$name/view.png" || echo "no view")" >>"$summary"
    tail -n 3 "$log" | sed 's/^/   /'
}

only=()
action=bake
fill_dir=
from_git=
while [[ $# -gt 0 ]]; do
    case $1 in
    --build) build=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --fill-mirror) action=fill; fill_dir=$2; shift 2 ;;
    --from-git) from_git=$2; shift 2 ;;
    --list) action=list; shift ;;
    -h | --help) usage ;;
    -*) usage ;;
    *) only+=("$1"); shift ;;
    esac
done

case $action in
list)
    list_scenes
    exit 0
    ;;
fill)
    [[ -n $from_git ]] || die "--fill-mirror DIR needs --from-git ROOT"
    fill_mirror "$fill_dir" "$from_git"
    exit 0
    ;;
esac

out=${out:-$build/gallery}
luxel=$build/bin/luxel
for b in "$luxel" "$build/bin/gen_scenes"; do
    [[ -x $b ]] || die "$b not built (make gallery builds it)"
done
time_cmd=
if [[ -x /usr/bin/time ]]; then
    time_cmd=/usr/bin/time
fi

names=()
if [[ ${#only[@]} -gt 0 ]]; then
    for n in "${only[@]}"; do
        scene_field "$n" 0 >/dev/null || die "no scene named $n (--list names them)"
        names+=("$n")
    done
else
    for line in "${scenes[@]}"; do
        names+=("${line%%|*}")
    done
fi

mkdir -p "$out/cache"
summary=$out/summary.txt
{
    echo "# luxel gallery, $(date -u '+%Y-%m-%d %H:%M UTC'), $("$luxel" --version), threads ${threads:-all}"
    printf '%-16s %6s %8s %8s %10s %8s %9s  %s\n' scene exit seconds peak_MB texels texels/m warnings view
} >"$summary"
for n in "${names[@]}"; do
    fetch_scene "$n"
done
for n in "${names[@]}"; do
    bake_scene "$n"
done
echo
cat "$summary"
