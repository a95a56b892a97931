#!/usr/bin/env bash
# Builds the unit tests with clang in build-clang/, warnings as errors, and runs the quick ones
# (not those labelled slow): the library is written for g++ and clang alike, and g++ accepts
# some code that clang rejects. The CI runs it after scripts/run-tests.sh
# (docs/getting-started.md, *Compilers*).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/install-deps.sh clang libomp-dev
CXX=clang++ cmake -S . -B build-clang -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS=-Werror \
    -DSPHERE_ENABLE_CUDA=OFF -DSPHERE_BUILD_EXAMPLES=OFF -DSPHERE_BUILD_BENCH=OFF -DSPHERE_BUILD_PYTHON=OFF
cmake --build build-clang --target sphere_tests -j 2
ctest --test-dir build-clang --output-on-failure -j2 -R '^test_' -LE slow
