#pragma once
/// \file
/// The fluid half of sphere: `#include <sphere/fluid.cuh>` brings in the fluid grid, the lens
/// volume, the porosity estimator, the drag laws, the Poisson solvers, the Navier-Stokes
/// solver, the Darcy model, their coupling to the particles and the couplings built at run time
/// from a stored setup (docs/fluid.md).
#include "fluid/coupling.cuh"
#include "fluid/darcy.cuh"
#include "fluid/drag.cuh"
#include "fluid/fluid_params.cuh"
#include "fluid/grid.cuh"
#include "fluid/lens.cuh"
#include "fluid/navier_stokes.cuh"
#include "fluid/poisson.cuh"
#include "fluid/poisson_cg.cuh"
#include "fluid/poisson_mg.cuh"
#include "fluid/porosity.cuh"
#include "fluid/setup.cuh"
#include "fluid/setup_coupling.cuh"
#include "fluid/snapshot.cuh"
