#!/usr/bin/env bash
# The GPU check, for a machine with an NVIDIA GPU: builds the CUDA test binary, the CUDA bed
# benchmark, the sphere program's CUDA build and the collision example's for this GPU in
# build-gpu/, runs the tests (they print the host-vs-CUDA comparison) and tests/test_program.py
# on sphere-cuda (a CUDA run killed and resumed equals an uninterrupted one byte for byte),
# compares collision_cuda's time series on both backends (scripts/compare_series.py),
# times bed_cuda on the dense bed at 1e5, 1e6 and 4e6 particles in float, mixed and double,
# profiles the step's passes at 1e6 with Nsight Compute where `ncu` is installed
# (scripts/ncu_table.py), and writes the figures with the date, commit and GPU into a markdown
# file that docs/performance.md can quote.
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
#                             apps/sphere-cuda, examples/consolidation and
#                             examples/collision_cuda as in a build tree
#   SPHERE_PYTHON=python3     the interpreter for tests/test_program.py (default /usr/bin/python3;
#                             it needs Pillow)
#   SPHERE_GPU_LOGS=DIR       write the full logs (tests, program, bed) into DIR as they grow
#   SPHERE_GPU_LIMITS="600 300 120"  seconds allowed to the tests, the program's check and one
#                             bed run (or one profile): each runs under `timeout`, so a hang is
#                             reported
#   SPHERE_GPU_PROFILE=0      skip the Nsight Compute profile
# A machine that returns only a few files (a lent one) can carry SPHERE_GPU_LOGS back as one
# archive: tar czf logs.tgz -C DIR .
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
    cmake --build build-gpu -j "$(nproc)" --target sphere_cuda_tests bed_cuda sphere_program_cuda consolidation collision_cuda
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

# The collision example on both backends of one binary (default options, both targets, both
# precisions): the time series agree to round-off. The CSV holds 10 significant digits, so
# double may differ in the last (1e-8 allowed); float differs by its own round-off, since nvcc
# contracts the device code into FMAs and the host build does not (1.2e-7 measured on an H200,
# docs/gpu-results.md; 1e-5 allowed).
collision=passed
for target in pair wall; do
    for precision in double float; do
        for backend in host cuda; do
            "$bin/examples/collision_cuda" --target $target --precision $precision --backend $backend \
                --csv "$work/collision_${target}_${precision}_$backend.csv" >> "$logs/collision.log" 2>&1 || collision=FAILED
        done
        tolerance=1e-8
        [[ $precision == float ]] && tolerance=1e-5
        verdict=$("$python" scripts/compare_series.py $tolerance "$work/collision_${target}_${precision}_host.csv" \
            "$work/collision_${target}_${precision}_cuda.csv" 2>&1) || { verdict+=" (FAILED)"; collision=FAILED; }
        echo "collision --target $target --precision $precision, cuda against host: $verdict" \
            | tee -a "$logs/collision.log" "$work/collision_summary"
    done
done

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

# Nsight Compute on the step's passes at 1e6 particles (the gather schedule's evaluate and
# gather, the drift, the integration with its check): eight launches after the first eight,
# each pass's time, memory throughput, registers and occupancy (scripts/ncu_table.py).
ncu_bin=$(command -v ncu || command -v /usr/local/cuda/bin/ncu || true) # the toolkit's place, if not on PATH
profile=""
if [[ ${SPHERE_GPU_PROFILE:-1} == 0 ]]; then
    profile="not run (SPHERE_GPU_PROFILE=0)"
elif [[ -z $ncu_bin ]]; then
    profile="not run (no ncu on this machine)"
else
    for precision in mixed double; do
        timeout "$limit_bed" "$ncu_bin" --kernel-name-base demangled \
            --kernel-name "regex:evaluate_owned_pairs|gather_pair_results|drift_particles|integrate_particles" \
            --launch-skip 8 --launch-count 8 --section SpeedOfLight --section MemoryWorkloadAnalysis \
            --section Occupancy --section LaunchStats --section ComputeWorkloadAnalysis \
            "$bin/bench/bed_cuda" --csv "$work/bed_50000.csv" --tile 4 5 --precision $precision --pre 4 --steps 6 \
            > "$logs/ncu_$precision.txt" 2>&1 || echo "ncu: exit status $?" >> "$logs/ncu_$precision.txt"
        profile+=$'\n'"$precision (\`$(basename "$ncu_bin") ... bed_cuda --tile 4 5 --precision $precision --pre 4 --steps 6\`):"$'\n\n'
        profile+=$("$python" scripts/ncu_table.py "$logs/ncu_$precision.txt" 2>&1 || tail -n 3 "$logs/ncu_$precision.txt")$'\n'
    done
fi

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
    echo "The collision example's time series, collision_cuda --backend cuda against --backend host: $collision."
    echo
    sed 's/^/- /' "$work/collision_summary"
    echo
    echo "Dense bed (bench/bed.cpp built as bed_cuda; ../shared/bench/bed, 200 untimed and 2000 timed steps),"
    echo "the 50,000-particle bed tiled 2 x 1, 4 x 5 and 8 x 10; particle-steps/s:"
    echo
    echo "$table"
    echo
    echo "bed_cuda's lines:"
    echo
    sed 's/^/    /' "$logs/bed.log"
    echo
    echo "Nsight Compute on the step's passes at 1e6 particles (two steps): $profile"
} > "$out"
echo "gpu-check: wrote $out"
[[ $tests == passed ]] || fail "sphere_cuda_tests: $tests (above)"
[[ $program == passed ]] || fail "tests/test_program.py failed on sphere-cuda (above)"
[[ $collision == passed ]] || fail "collision_cuda: the backends' time series differ, or a run failed (above)"
