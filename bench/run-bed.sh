#!/usr/bin/env bash
# Times sphere's bed benchmark (build/bench/bed) next to LAMMPS and LIGGGHTS
# (../shared/bench/bed/run-peers.sh) in the same minutes, interleaved, and prints each
# code's median particle-steps/s and sphere's ratios to the peers.
#
#   bash bench/run-bed.sh [repeats=3] [N list="10000 50000"] [threads list="1 2"] [precisions="double"]
#
# needs: the build (cmake --build build --target bed), and the peers' Debian packages
# (apt-get install lammps liggghts openmpi-bin xz-utils). The machine is shared: compare
# only figures measured in one run of this script.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
repeats=${1:-3}
sizes=${2:-"10000 50000"}
threads_list=${3:-"1 2"}
precisions=${4:-"double"}
peers=${SPHERE_BED_DIR:-../shared/bench/bed}
bed=build/bench/bed
[[ -x $bed ]] || { echo "run-bed: $bed is missing; build it with: cmake --build build --target bed" >&2; exit 1; }
[[ -f $peers/run-peers.sh ]] || { echo "run-bed: no $peers/run-peers.sh (set SPHERE_BED_DIR)" >&2; exit 1; }
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
log=$work/log
echo "# $(date -u +%FT%TZ) $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
for n in $sizes; do
    xz -dc "$peers/data/bed_$n.csv.xz" > "$work/bed_$n.csv"
    for t in $threads_list; do
        for ((r = 1; r <= repeats; ++r)); do
            for p in $precisions; do
                OMP_NUM_THREADS=$t "$bed" --csv "$work/bed_$n.csv" --threads "$t" --precision "$p" | tee -a "$log"
            done
            bash "$peers/run-peers.sh" "$n" "$t" | tee -a "$log"
        done
    done
done
echo "# load after: $(cut -d' ' -f1-3 /proc/loadavg)"
# Medians per code, N, ranks/threads (and sphere's precision), then the ratios.
awk '
    function key_of(line,   code, n, t, p) {
        code = $1
        match(line, /N=[0-9]+/); n = substr(line, RSTART + 2, RLENGTH - 2)
        if (match(line, /threads=[0-9]+/)) t = substr(line, RSTART + 8, RLENGTH - 8)
        else { match(line, /ranks=[0-9]+/); t = substr(line, RSTART + 6, RLENGTH - 6) }
        p = ""
        if (match(line, /precision=[a-z]+/)) p = " " substr(line, RSTART + 10, RLENGTH - 10)
        return code p " N=" n " x" t
    }
    /particle-steps\/s/ { # the timing lines (sphere also prints a memory line)
        for (i = 1; i <= NF; ++i) if ($i == "particle-steps/s") rate = $(i - 1)
        k = key_of($0); vals[k] = vals[k] " " rate; keys[k] = 1
    }
    function median(list,   a, m, i, j, t) {
        m = split(list, a, " ")
        for (i = 1; i <= m; ++i) for (j = i + 1; j <= m; ++j) if (a[j] + 0 < a[i] + 0) { t = a[i]; a[i] = a[j]; a[j] = t }
        return m % 2 ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
    }
    END {
        printf "\n%-32s %14s   %s\n", "code N threads/ranks", "median p-s/s", "(repeats)"
        for (k in keys) { med[k] = median(vals[k]); printf "%-32s %14.3e   (%s )\n", k, med[k], vals[k] }
        printf "\n"
        for (k in keys) if (k ~ /^sphere/) {
            split(k, f, " "); rest = k; sub(/^sphere [a-z]+ /, "", rest)
            printf "%-32s %6.2fx LAMMPS  %6.2fx LIGGGHTS\n", k, med[k] / med["lammps " rest], med[k] / med["liggghts " rest]
        }
    }' "$log"
