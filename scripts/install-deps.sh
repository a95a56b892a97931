#!/usr/bin/env bash
# Installs the Debian/Ubuntu packages that building and testing sphere needs.
# Idempotent: installs only what is missing, and runs `apt-get update` only
# when something is missing. Uses sudo when not run as root.
#
# Arguments name further packages to install the same way (scripts/check-clang.sh: clang).
# Set SPHERE_SKIP_DEPS=1 to skip this step entirely.
set -euo pipefail

if [[ "${SPHERE_SKIP_DEPS:-0}" == "1" ]]; then
    echo "install-deps: SPHERE_SKIP_DEPS=1, skipping"
    exit 0
fi

packages=(
    cmake make g++
    catch2 libeigen3-dev libcli11-dev libbenchmark-dev
    python3-vtk9 python3-matplotlib python3-numpy
    libpng-dev python3-pil
    pybind11-dev python3-pybind11 python3-pytest python3-dev python3-pip
    "$@"
)

# Thrust/CUB headers: the CUDA toolkit ships them; otherwise use Debian's.
# Same places as cmake/sphereThrust.cmake looks in.
have_cuda_thrust() {
    local roots=()
    [[ -n "${CUDAToolkit_ROOT:-}" ]] && roots+=("$CUDAToolkit_ROOT")
    if command -v nvcc >/dev/null 2>&1; then
        roots+=("$(dirname "$(dirname "$(command -v nvcc)")")")
    fi
    roots+=(/usr/local/cuda)
    local r
    for r in "${roots[@]}"; do
        if [[ -f "$r/include/cccl/thrust/version.h" || -f "$r/include/thrust/version.h" ]]; then
            return 0
        fi
    done
    return 1
}
if ! have_cuda_thrust; then
    packages+=(libthrust-dev libcub-dev)
fi

if ! command -v dpkg-query >/dev/null 2>&1 || ! command -v apt-get >/dev/null 2>&1; then
    echo "install-deps: not a Debian-based system; please install the equivalents of:" >&2
    echo "  ${packages[*]}" >&2
    exit 0
fi

missing=()
for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
        missing+=("$p")
    fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
    echo "install-deps: all packages present"
    exit 0
fi

sudo_cmd=()
if [[ $(id -u) -ne 0 ]]; then
    if command -v sudo >/dev/null 2>&1; then
        sudo_cmd=(sudo)
    else
        echo "install-deps: need root (or sudo) to install: ${missing[*]}" >&2
        exit 1
    fi
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
"${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
