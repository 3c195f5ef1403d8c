#!/usr/bin/env bash
# Installs the test oracles (never runtime dependencies): the Khronos
# glTF-Validator and MikkTSpace (npm mikktspace, a WASM build of the
# reference implementation) from npm into BUILD/oracles, and Node and npm from Debian
# when missing. Tests that need an oracle report themselves skipped when it
# is not there, so a machine without network still runs the rest.
# usage: scripts/install-test-oracles.sh [BUILD]   (default: build)
set -uo pipefail
build="${1:-build}"
dest="$build/oracles"

if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
    echo "install-test-oracles: installing nodejs and npm"
    sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -qq && $sudo apt-get install -y -qq --no-install-recommends nodejs npm ||
        { echo "install-test-oracles: could not install nodejs/npm; oracle tests will be skipped"; exit 0; }
fi

mkdir -p "$dest"
for pkg in gltf-validator mikktspace; do
    [ -f "$dest/node_modules/$pkg/package.json" ] && continue
    echo "install-test-oracles: npm install --prefix $dest $pkg"
    if ! npm install --prefix "$dest" --no-audit --no-fund --silent "$pkg"; then
        echo "install-test-oracles: npm install $pkg failed; its oracle tests will be skipped"
    fi
done
exit 0
