#!/usr/bin/env bash
# Installs the Debian packages luxel builds and tests with, when any is missing.
# Runs as root (CI) or through sudo; does nothing when everything is present.
set -euo pipefail

packages=(
    build-essential cmake pkg-config
    libembree-dev      # ray queries (Embree 3)
    libassimp-dev      # scene import (glTF 2.0, OBJ, ...)
    libcjson-dev       # JSON
    libstb-dev         # PNG/JPEG/TGA/HDR codecs
    zlib1g-dev         # checks PNG data before stb decodes it
    libopenexr-dev     # OpenEXR (OpenEXRCore C API)
    libsuitesparse-dev # sparse Cholesky (CHOLMOD) for lightmap UV flattening
    libmeshoptimizer-dev # EXT_meshopt_compression glTF buffers
    libcmocka-dev      # unit tests
    clang libclang-rt-14-dev libomp-dev  # sanitizer and fuzzer builds (clang)
)

missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}"
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
