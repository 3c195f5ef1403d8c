#!/usr/bin/env bash
# The demo room baked by luxel and by Blender Cycles (bench/cycles_room.py),
# compared texel by texel, with both times. Needs Blender and NumPy for
# its Python (apt-get install blender python3-numpy); not part of make
# bench, which must run without them.
#
#   bash bench/cycles_room.sh [BUILD] [BOUNCES] [SAMPLES] [RESOLUTION] [LUXEL_SAMPLES]
#
# CYCLES_ROOM_ERRORS=DIR also writes DIR/<node>_error.ppm, the low-passed
# difference per texel (red: luxel brighter, blue: darker, full at 10%).
# SAMPLES are Cycles' samples a texel; luxel casts LUXEL_SAMPLES gather
# rays a texel a bounce (default SAMPLES) and denoises them as its CLI
# does by default (--denoise indirect).
set -euo pipefail
build=${1:-build}
bounces=${2:-2}
samples=${3:-1024}
res=${4:-128}
luxel_samples=${5:-$samples}
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
command -v blender > /dev/null || { echo "cycles_room: blender is not installed"; exit 1; }
/usr/bin/python3 -c 'import numpy' 2> /dev/null ||
    { echo "cycles_room: NumPy is not installed (apt-get install python3-numpy)"; exit 1; }
"$build/bin/gen_scenes" "$work/scenes" > /dev/null
extra=(--bounces "$bounces" --gi-samples "$luxel_samples")
start=$(date +%s.%N)
"$build/bin/luxel" bake "$work/scenes/room.glb" --lights "$here/cycles_room.json" \
    --resolution "$res" --padding 0 -o "$work/luxel" -q "${extra[@]}"
end=$(date +%s.%N)
echo "cycles_room: luxel baked in $(echo "$end - $start" | bc) s (${extra[*]})"
blender -b --factory-startup -P "$here/cycles_room.py" -- "$work/scenes/room.glb" "$work/luxel" \
    --bounces "$bounces" --samples "$samples" --resolution "$res" 2>&1 | grep '^cycles_room\|^  '
