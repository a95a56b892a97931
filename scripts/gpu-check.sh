#!/usr/bin/env bash
# The GPU check, for a machine with an NVIDIA GPU: builds the CUDA test binary, the CUDA bed
# benchmark and the sphere program's CUDA build for this GPU in build-gpu/, runs the tests (they
# print the host-vs-CUDA comparison) and tests/test_program.py on sphere-cuda (a CUDA run killed
# and resumed equals an uninterrupted one byte for byte),
# times bed_cuda on the dense bed at 1e5, 1e6 and 4e6 particles in float, mixed and double, and
# writes the figures with the date, commit and GPU into a markdown file that
# docs/performance.md can quote.
#
#   bash scripts/gpu-check.sh [output=docs/gpu-results.md]
#
# needs: nvcc, the NVIDIA driver (nvidia-smi), the build dependencies (scripts/install-deps.sh),
# xz, and ../shared/bench/bed/data/bed_50000.csv.xz (or SPHERE_BED_DIR; an unpacked
# bed_50000.csv beside it is read as is). Exits non-zero when there is no GPU, and after the
# benchmarks when a test failed.
#
# A GPU machine without the build dependencies can run binaries built elsewhere with the same
# nvcc for its architecture (e.g. -DCMAKE_CUDA_ARCHITECTURES=90 for an H100/H200):
#   SPHERE_GPU_PREBUILT=DIR   skip the build; DIR holds tests/sphere_cuda_tests, bench/bed_cuda,
#                             apps/sphere-cuda and examples/consolidation as in a build tree
#   SPHERE_PYTHON=python3     the interpreter for tests/test_program.py (default /usr/bin/python3;
#                             it needs Pillow)
#   SPHERE_GPU_LOGS=DIR       write the full logs (tests, program, bed) into DIR as they grow
#   SPHERE_GPU_LIMITS="600 300 120"  seconds allowed to the tests, the program's check and one
#                             bed run: each step runs under `timeout`, so a hang is reported
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:-docs/gpu-results.md}
bed_csv_xz=${SPHERE_BED_DIR:-../shared/bench/bed}/data/bed_50000.csv.xz
fail() { echo "gpu-check: $*" >&2; exit 1; }

command -v nvidia-smi >/dev/null || fail "no nvidia-smi: this machine has no NVIDIA driver, so no GPU to check"
gpu=$(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | head -n 1) || true
[[ -n $gpu ]] || fail "nvidia-smi lists no GPU"
[[ -f $bed_csv_xz || -f ${bed_csv_xz%.xz} ]] || fail "no $bed_csv_xz (set SPHERE_BED_DIR to the folder of the bed scenario)"

bin=${SPHERE_GPU_PREBUILT:-build-gpu}
python=${SPHERE_PYTHON:-/usr/bin/python3}
read -r limit_tests limit_program limit_bed <<< "${SPHERE_GPU_LIMITS:-600 300 120}"
if [[ -z ${SPHERE_GPU_PREBUILT:-} ]]; then
    cmake -S . -B build-gpu -DCMAKE_BUILD_TYPE=Release -DSPHERE_ENABLE_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=native
    cmake --build build-gpu -j "$(nproc)" --target sphere_cuda_tests bed_cuda sphere_program_cuda consolidation
fi

work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
logs=${SPHERE_GPU_LOGS:-$work}
mkdir -p "$logs"
tests=passed
timeout "$limit_tests" "$bin/tests/sphere_cuda_tests" --durations yes 2>&1 | tee "$logs/tests.log" \
    || { [[ ${PIPESTATUS[0]} == 124 ]] && tests="FAILED: stopped at its ${limit_tests} s limit" || tests=FAILED; }
grep -q "no CUDA device" "$logs/tests.log" && fail "the CUDA runtime finds no device although nvidia-smi lists $gpu"

# The program on the GPU: its input is the consolidation example's checkpoint, as in CTest.
program=passed
"$bin/examples/consolidation" -n 150 --time 0.05 --output-interval 0.01 --precision float -q -o "$work/consolidation" \
    > "$logs/program.log" 2>&1 || program=FAILED
timeout "$limit_program" "$python" tests/test_program.py "$bin/apps/sphere-cuda" "$work/consolidation/checkpoint.ck" "$work/program" \
    2>&1 | tee -a "$logs/program.log" || program=FAILED

# The 50,000-particle bed is periodic in x and y: tiled 2 x 1, 4 x 5 and 8 x 10 it holds 1e5,
# 1e6 and 4e6 particles.
if [[ -f ${bed_csv_xz%.xz} ]]; then cp "${bed_csv_xz%.xz}" "$work/bed_50000.csv"; else xz -dc "$bed_csv_xz" > "$work/bed_50000.csv"; fi
for tile in "2 1" "4 5" "8 10"; do
    for precision in float mixed double; do
        # shellcheck disable=SC2086 # the tile is two arguments
        timeout "$limit_bed" "$bin/bench/bed_cuda" --csv "$work/bed_50000.csv" --tile $tile --precision "$precision" 2>&1 \
            | tee -a "$logs/bed.log" || echo "bed_cuda --tile $tile --precision $precision: FAILED (exit ${PIPESTATUS[0]})" | tee -a "$logs/bed.log"
    done
done

# The table: one row per N, particle-steps/s per precision (the number before "particle-steps/s").
table=$(awk '
    /^sphere / {
        match($0, /N=[0-9]+/); n = substr($0, RSTART + 2, RLENGTH - 2)
        match($0, /precision=[a-z]+/); p = substr($0, RSTART + 10, RLENGTH - 10)
        for (i = 1; i <= NF; ++i) if ($i == "particle-steps/s") rate[n, p] = $(i - 1)
        if (!(n in seen)) { seen[n] = 1; order[++rows] = n }
    }
    END {
        print "| N | float | mixed | double |"
        print "|---|---|---|---|"
        for (r = 1; r <= rows; ++r) {
            n = order[r]
            print "| " n " | " rate[n, "float"] " | " rate[n, "mixed"] " | " rate[n, "double"] " |"
        }
    }' "$logs/bed.log")
commit=$(git rev-parse --short HEAD 2>/dev/null) || commit="(not a git checkout)"
git diff --quiet HEAD 2>/dev/null || commit="$commit with local changes"
nvcc_version=$(nvcc --version 2>/dev/null | tail -n 1) || nvcc_version="no nvcc here"
{
    echo "# CUDA results (scripts/gpu-check.sh)"
    echo
    echo "Measured $(date -u +%FT%TZ), commit $commit, GPU $gpu (name, driver), ${nvcc_version:-no nvcc here}."
    echo
    echo "sphere_cuda_tests: $tests ($(grep -E "All tests passed|test cases:" "$logs/tests.log" | tail -n 1))."
    echo
    grep "^host vs CUDA" "$logs/tests.log" || echo "(no host-vs-CUDA comparison line)"
    echo
    echo "tests/test_program.py on sphere-cuda (--backend cuda killed and resumed): $program ($(tail -n 1 "$logs/program.log"))."
    echo
    echo "Dense bed (bench/bed.cpp built as bed_cuda; ../shared/bench/bed, 200 untimed and 2000 timed steps),"
    echo "the 50,000-particle bed tiled 2 x 1, 4 x 5 and 8 x 10; particle-steps/s:"
    echo
    echo "$table"
    echo
    echo "bed_cuda's lines:"
    echo
    sed 's/^/    /' "$logs/bed.log"
} > "$out"
echo "gpu-check: wrote $out"
[[ $tests == passed ]] || fail "sphere_cuda_tests: $tests (above)"
[[ $program == passed ]] || fail "tests/test_program.py failed on sphere-cuda (above)"
