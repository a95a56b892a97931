#pragma once
/// \file
/// The fluid half of sphere: `#include <sphere/fluid.cuh>` brings in the fluid grid, the lens
/// volume, the porosity estimator and the drag laws (docs/fluid.md).
#include "fluid/drag.cuh"
#include "fluid/grid.cuh"
#include "fluid/lens.cuh"
#include "fluid/porosity.cuh"
