#pragma once
/// \file
/// Output and restart (docs/io.md): `#include <sphere/io.cuh>` brings in atomic file writing,
/// VTK XML files for ParaView (.vtu frames and a .pvd collection), CSV time series with the
/// standard diagnostics row, and versioned binary checkpoints with restart. Host-only code
/// (POSIX file calls); include it next to <sphere/dem.cuh>.
#include "io/atomic_file.cuh"
#include "io/checkpoint.cuh"
#include "io/csv.cuh"
#include "io/vtk.cuh"
