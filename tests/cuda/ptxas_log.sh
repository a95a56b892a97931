#!/usr/bin/env bash
# Compiler launcher of the CUDA instantiation targets (tests/CMakeLists.txt): runs the nvcc
# command it is given (compiled with -Xptxas=-v) and keeps its diagnostics, ptxas's resource
# report among them, in the log file named first, for tests/check_ptxas.py; shows them only
# when the compile fails.
set -u
log="$1"
shift
"$@" 2>"$log"
status=$?
if [ "$status" -ne 0 ]; then cat "$log" >&2; fi
exit "$status"
