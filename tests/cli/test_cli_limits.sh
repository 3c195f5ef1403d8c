# cases: bake_nodes bake_retro bake_density ibl_run
# End-to-end tests of requests too large for the memory (a 100000^2
# lightmap fails up front with a message that says how much was asked). The bake cases run under a 2 GiB address-space limit, which
# the library counts as the memory it may use, so they fail up front on any
# machine, naming that limit; a build that cannot run under such a limit
# (a sanitizer's) reports them skipped. The ibl case runs without a limit
# and depends on the machine: one with the memory for the request cannot
# show the failure, so each case is its own CTest test (the "# cases:"
# line above) and reports itself skipped (exit 77) there.
#
# usage: bash test_cli_limits.sh LUXEL GEN_SCENES WORKDIR CASE
set -u
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

"$GEN" "$WORK/scenes" >/dev/null || { echo "gen_scenes failed"; exit 1; }
RETRO=$WORK/scenes/retro.glb
IN=$WORK/in
mkdir -p "$IN" "$WORK/out"
CASE=0

# A scene of 1024 separate unit quads (one node each): every lightmap of
# N x N texels holds at least its N*N RGB float32 results (12 bytes a
# texel), all at once since nothing is written before everything is baked.
{
    for ((i = 0; i < 1024; i++)); do
        x=$((i % 32 * 2)) z=$((i / 32 * 2)) b=$((i * 4))
        printf 'o quad_%d\nv %d 0 %d\nv %d 0 %d\nv %d 0 %d\nv %d 0 %d\n' "$i" \
            $x $z $x $((z + 1)) $((x + 1)) $((z + 1)) $((x + 1)) $z
        printf 'vt 0.125 0.875\nvt 0.125 0.125\nvt 0.875 0.125\nvt 0.875 0.875\n'
        printf 'f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n' $((b + 1)) $((b + 1)) \
            $((b + 2)) $((b + 2)) $((b + 3)) $((b + 3)) $((b + 1)) $((b + 1)) \
            $((b + 3)) $((b + 3)) $((b + 4)) $((b + 4))
    done
} >"$IN/many.obj"
MEM_BYTES=$(($(awk '/^MemTotal:/ { print $2 }' /proc/meminfo) * 1024))

# oom_case LABEL NODES SIDE ARGS...: NODES maps of SIDE^2 texels cannot fit
# in a 2 GiB address space: under that limit (ulimit -v) the bake must fail
# up front saying how much it needs and naming the limit (or the machine's
# memory on a machine with less).
oom_case() {
    local label=$1 nodes=$2 side=$3
    shift 3
    local floor=$((nodes * side * side * 12))
    if [ "$floor" -le $((2 * 1024 * 1024 * 1024)) ]; then
        fail "$label: the request ($floor bytes) fits in the 2 GiB limit"
        return
    fi
    if ! bash -c 'ulimit -v 2097152 && "$@"; exit $?' probe "$LUXEL" --version >/dev/null 2>&1; then
        skip "$label: luxel cannot run with a 2 GiB address-space limit (sanitizer build?)"
        return
    fi
    CASE=$((CASE + 1))
    local out=$WORK/out/case$CASE
    run bash -c 'ulimit -v 2097152 && exec "$@"' oom "$LUXEL" "$@" -o "$out"
    expect_rc 1 "$label"
    local scene
    scene=$(basename "$2")
    if [ "$MEM_BYTES" -gt $((4 * 1024 * 1024 * 1024)) ]; then
        expect_error "$label" "$scene" "needs" "GiB of memory, the address-space limit"
    else
        expect_error "$label" "$scene" "needs" "GiB of memory"
    fi
    expect_no_output "$label" "$out"
}
case $CASE_NAME in
bake_nodes)
    oom_case "--resolution 16384 on 1024 nodes" 1024 16384 bake "$IN/many.obj" --resolution 16384 --ambient 1,1,1
    ;;
bake_retro)
    oom_case "--resolution 16384 on retro.glb (8 nodes)" 8 16384 bake "$RETRO" --resolution 16384
    ;;
bake_density)
    # 1024 maps of 2048^2 are >= 48 GiB together though each alone is
    # small: the sum must be checked up front, not discovered by running out
    oom_case "--texel-density 1e6 --max-resolution 2048 on 1024 nodes" 1024 2048 \
        bake "$IN/many.obj" --texel-density 1000000 --max-resolution 2048 --ambient 1,1,1 -q
    ;;
ibl_run)
    # a 16384^2 constant environment is 18 GiB; its specular chain at that
    # size holds it, its mips (6 GiB) and 24 GiB of levels at once, each of
    # which alone would fit: an error up front naming the size and the
    # memory, before the environment is made (on a machine with less than
    # 48 GiB, where the run cannot fit)
    if [ "$MEM_BYTES" -ge $((48 * 1024 * 1024 * 1024)) ]; then
        skip "ibl --size 16384 --specular-size 16384: this machine has $MEM_BYTES bytes, the run may fit"
    else
        run "$LUXEL" ibl const:1 --size 16384 --specular ggx --specular-size 16384 -q -o "$WORK/huge"
        expect_rc 1 "ibl --size 16384 --specular-size 16384"
        expect_error "ibl --size 16384 --specular-size 16384" "16384 x 16384" "GiB of memory"
        expect_no_output "ibl --size 16384 --specular-size 16384" "$WORK/huge"
    fi
    ;;
*)
    fail "unknown case '$CASE_NAME'"
    ;;
esac

finish
