#pragma once
/// \file
/// What a coupled run is built from (docs/fluid.md, *Restarting a coupled run*): the fluid
/// model, the pressure solver and the drag law by name, the fluid's parameters and the
/// coupling's options. fluid_coupling::snapshot() stores them as the "setup." entries of its
/// snapshot, so that a checkpoint of a coupled run describes the coupling it continues with
/// (the sphere program builds it from them: apps/sphere/main.cpp); restore() does not read
/// them (the coupling is the caller's). Host-only code.
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "../core/error.cuh"
#include "darcy.cuh"
#include "fluid_params.cuh"
#include "porosity.cuh"
#include "snapshot.cuh"

namespace sphere {

/// How the fluid and the particles are coupled.
struct coupling_options {
    unsigned dem_steps = 10;     ///< DEM steps per fluid step
    bool pressure_force = true;  ///< apply -V_p grad p to the particles (and its reaction to the fluid)
    /// How the cells' solid volume is measured: cell_volume conserves the grid's solid volume
    /// (needed for a closed box); cell_sphere is the seeds' estimator.
    porosity_method porosity = porosity_method::cell_volume;
};

/// The names of the pressure solvers and drag laws a setup can name (their `name()`), in the
/// order of the codes a snapshot stores; a type of the caller's own is stored as the code
/// after the last.
inline const std::vector<std::string>& pressure_solver_names()
{
    static const std::vector<std::string> names{"jacobi", "cg", "mg"};
    return names;
}
inline const std::vector<std::string>& drag_law_names()
{
    static const std::vector<std::string> names{"ergun", "wen_yu", "gidaspow", "gidaspow_blended"};
    return names;
}

/// A coupled run's setup. For the Navier-Stokes model the Darcy fields of `params` (all but
/// `fluid`) are not used and keep their defaults.
template <class Real>
struct coupling_setup {
    std::string model;   ///< "navier_stokes" or "darcy" (the model's model_name())
    std::string solver;  ///< the pressure solver's name(): pressure_solver_names(), or "(other)"
    std::string drag;    ///< the drag law's name(): drag_law_names(), or "(other)"
    darcy_params<Real> params{};
    coupling_options options{};

    /// Calls number(name, field) for each floating field and count(name, field, largest) for
    /// each whole-number, flag and enumeration field, in the order a snapshot stores them.
    template <class Self, class Number, class Count>
    static void fields(Self& s, Number number, Count count)
    {
        auto& f = s.params.fluid;
        number("density", f.density);
        number("viscosity", f.viscosity);
        number("beta", f.beta);
        number("gravity_x", f.gravity.x);
        number("gravity_y", f.gravity.y);
        number("gravity_z", f.gravity.z);
        const auto end = [&](const std::string& e, auto& b) {
            count((e + "_kind").c_str(), b.kind, 2);
            number((e + "_pressure").c_str(), b.pressure);
            number((e + "_amplitude").c_str(), b.amplitude);
            number((e + "_frequency").c_str(), b.frequency);
            number((e + "_phase").c_str(), b.phase);
            number((e + "_velocity").c_str(), b.velocity);
        };
        end("bottom", f.bottom);
        end("top", f.top);
        number("tolerance", f.poisson.tolerance);
        count("max_iterations", f.poisson.max_iterations, 0xffffffffu);
        count("criterion", f.poisson.criterion, 1);
        number("compressibility", s.params.compressibility);
        number("permeability_prefactor", s.params.permeability_prefactor);
        number("max_porosity", s.params.max_porosity);
        count("dem_steps", s.options.dem_steps, 0xffffffffu);
        count("pressure_force", s.options.pressure_force, 1);
        count("porosity_method", s.options.porosity, 1);
    }

    /// The setup's snapshot entries (without the "setup." prefix): the fields, and the solver
    /// and the drag law as codes.
    fluid_snapshot<Real> snapshot(const fluid_grid<Real>& g) const
    {
        fluid_snapshot<Real> s = fluid_snapshot<Real>::of("setup", g);
        fields(
            *this, [&](const char* name, const auto& field) { s.add_number(name, double(field)); },
            [&](const char* name, const auto& field, std::uint64_t) { s.add_count(name, std::uint64_t(field)); });
        s.add_count("solver", code_of(solver, pressure_solver_names()));
        s.add_count("drag", code_of(drag, drag_law_names()));
        return s;
    }

    /// The setup stored in a coupling's snapshot (its "setup." entries), the model its
    /// snapshot's. Throws sphere::error, `who` first, when there is none (a checkpoint written
    /// before the setup was stored) or an entry is missing or out of range.
    static coupling_setup read(const fluid_snapshot<Real>& coupled, const char* who)
    {
        const fluid_snapshot<Real> s = coupled.part("setup.", "setup");
        if (s.numbers.empty() && s.counts.empty())
            detail::fail(who, ": the fluid section holds no setup (it was written before setups were stored): "
                              "the coupling cannot be built from it");
        coupling_setup c;
        c.model = coupled.model;
        fields(
            c, [&](const char* name, auto& field) { field = std::decay_t<decltype(field)>(s.number_named(who, name)); },
            [&](const char* name, auto& field, std::uint64_t largest) {
                field = static_cast<std::decay_t<decltype(field)>>(s.count_named(who, name, largest));
            });
        c.solver = name_of(s.count_named(who, "solver", pressure_solver_names().size()), pressure_solver_names());
        c.drag = name_of(s.count_named(who, "drag", drag_law_names().size()), drag_law_names());
        return c;
    }

private:
    static std::uint64_t code_of(const std::string& name, const std::vector<std::string>& names)
    {
        for (std::size_t k = 0; k < names.size(); ++k)
            if (names[k] == name) return k;
        return names.size();
    }
    static std::string name_of(std::uint64_t code, const std::vector<std::string>& names)
    {
        return code < names.size() ? names[code] : "(other)";
    }
};

} // namespace sphere
