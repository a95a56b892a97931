#pragma once
/// \file
/// The coupling a coupling_setup (setup.cuh) names, built at run time: the Gidaspow drag law
/// with the Navier-Stokes or Darcy model and the multigrid-preconditioned (mg) or conjugate
/// gradient (cg) pressure solver, the four couplings whose types a program or a binding that
/// chooses at run time compiles (the sphere program, apps/sphere/main.cpp; the Python package,
/// python/src/fluid.hpp). Other drag laws and solvers are built as fluid_coupling types in C++.
/// Host-only code (the couplings themselves run on `Policy`).
#include <memory>
#include <string>
#include <type_traits>
#include <variant>

#include "../core/error.cuh"
#include "coupling.cuh"
#include "darcy.cuh"
#include "drag.cuh"
#include "grid.cuh"
#include "navier_stokes.cuh"
#include "poisson_cg.cuh"
#include "poisson_mg.cuh"
#include "setup.cuh"

namespace sphere {

/// One of the four couplings a setup can name (see the file comment), owned.
template <class Real, class Policy>
using setup_coupling = std::variant<
    std::unique_ptr<fluid_coupling<Real, Policy, drag::gidaspow, mg_poisson<Real, Policy>, navier_stokes>>,
    std::unique_ptr<fluid_coupling<Real, Policy, drag::gidaspow, cg_poisson<Real, Policy>, navier_stokes>>,
    std::unique_ptr<fluid_coupling<Real, Policy, drag::gidaspow, mg_poisson<Real, Policy>, darcy_flow>>,
    std::unique_ptr<fluid_coupling<Real, Policy, drag::gidaspow, cg_poisson<Real, Policy>, darcy_flow>>>;

/// Builds the coupling `setup` names on `grid` (its fluid state fresh: restore a snapshot into
/// it to continue one). Throws sphere::error naming `where.model`, `where.solver` or
/// `where.drag` (`where` says where the setup came from) when it names something this
/// function does not build, and the fluid's own messages for bad parameters.
template <class Real, class Policy>
setup_coupling<Real, Policy> make_coupling(const coupling_setup<Real>& setup, const fluid_grid<Real>& grid,
                                           const std::string& where)
{
    const bool navier_stokes_model = setup.model == navier_stokes<Real, Policy, mg_poisson<Real, Policy>>::model_name();
    const bool darcy_model = setup.model == darcy_flow<Real, Policy, mg_poisson<Real, Policy>>::model_name();
    if (!navier_stokes_model && !darcy_model)
        detail::fail(where, ".model = '", setup.model, "': not one of 'navier_stokes', 'darcy'");
    const bool mg = setup.solver == mg_poisson<Real, Policy>::name();
    if (!mg && setup.solver != cg_poisson<Real, Policy>::name())
        detail::fail(where, ".solver = '", setup.solver, "': not one of 'mg', 'cg'");
    if (setup.drag != drag::gidaspow::name())
        detail::fail(where, ".drag = '", setup.drag, "': couplings built from a setup use 'gidaspow' (others: build ",
                     "the fluid_coupling type in C++)");
    const auto make = [&](auto* type, const auto& params) -> setup_coupling<Real, Policy> {
        using Coupling = std::remove_pointer_t<decltype(type)>;
        return std::make_unique<Coupling>(grid, params, setup.options);
    };
    using gidaspow = drag::gidaspow;
    using mg_solver = mg_poisson<Real, Policy>;
    using cg_solver = cg_poisson<Real, Policy>;
    if (navier_stokes_model) {
        if (mg)
            return make(static_cast<fluid_coupling<Real, Policy, gidaspow, mg_solver, navier_stokes>*>(nullptr),
                        setup.params.fluid);
        return make(static_cast<fluid_coupling<Real, Policy, gidaspow, cg_solver, navier_stokes>*>(nullptr),
                    setup.params.fluid);
    }
    if (mg)
        return make(static_cast<fluid_coupling<Real, Policy, gidaspow, mg_solver, darcy_flow>*>(nullptr), setup.params);
    return make(static_cast<fluid_coupling<Real, Policy, gidaspow, cg_solver, darcy_flow>*>(nullptr), setup.params);
}

} // namespace sphere
