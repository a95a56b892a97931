#!/usr/bin/env bash
# Installs the dependencies, builds the collision example (Release) in build/
# and runs it there (its CSV lands in build/collision.csv). Extra arguments are
# passed to the example.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j 2 --target collision
cd build && ./examples/collision "$@"
