#pragma once
// What `sphere --dry` prints (docs/program.md): the key settings of a checkpoint and the plan of
// the run, so that a user sees the time step and the number of steps and outputs before a run.
#include <sphere/fluid/setup.cuh>
#include <sphere/io/checkpoint.cuh>

#include "run_plan.hpp"

#include <cstdio>
#include <sstream>
#include <string>

namespace program {

/// "name = value unit, ..." of a contact law's parameters (Params::fields).
template <class Params>
std::string describe_params(const Params& p)
{
    std::ostringstream s;
    s.precision(6);
    const char* separator = "";
    Params::fields(p, [&](const char* name, const auto& v, const char* unit) {
        using T = std::decay_t<decltype(v)>;
        s << separator << name << " = ";
        if constexpr (std::is_floating_point_v<T>) s << double(v);
        else if constexpr (std::is_same_v<T, bool>) s << (v ? "true" : "false");
        else s << static_cast<unsigned>(v);
        if (*unit) s << ' ' << unit;
        separator = ", ";
    });
    return s.str();
}

/// Prints the settings of checkpoint `c` (read from `input`) and the plan of the run on stdout.
template <class Real, class Law>
void describe(const std::string& input, const sphere::checkpoint_data<Real, Law>& c, const std::string& run,
              const run_plan& plan, const run_files& files)
{
    const auto& s = c.config;
    const double dt = double(s.dt);
    std::printf("input          %s (format %u, written in %s)\n", input.c_str(), c.version,
                c.written_precision == 4 ? "float" : "double");
    std::printf("contact law    %s\n", Law::name().c_str());
    std::printf("run            %s\n", run.c_str());
    std::printf("particles      %zu\n", c.state.particles.size());
    std::printf("world          [%g, %g] x [%g, %g] x [%g, %g] m; x %s, y %s, z %s\n", double(s.box.lo.x),
                double(s.box.hi.x), double(s.box.lo.y), double(s.box.hi.y), double(s.box.lo.z), double(s.box.hi.z),
                sphere::name(s.box.axis[0]), sphere::name(s.box.axis[1]), sphere::name(s.box.axis[2]));
    std::printf("gravity        (%g, %g, %g) m/s^2\n", double(s.gravity.x), double(s.gravity.y), double(s.gravity.z));
    std::printf("contacts       %s\n", describe_params(s.contact).c_str());
    std::printf("wall contacts  %s\n", describe_params(s.wall).c_str());
    for (int f = 0; f < 6; ++f) {
        const auto& face = c.state.walls.face[f];
        if (!face.active) continue;
        const auto& w = s.walls[f];
        std::printf("wall face %d    at %.9g m, %s", f, double(face.position), sphere::name(w.mode));
        if (w.mode == sphere::wall_mode::velocity) std::printf(" %g m/s inwards", double(w.velocity));
        if (w.mode == sphere::wall_mode::stress)
            std::printf(" %g Pa (amplitude %g Pa, %g Hz), mass %g kg", double(w.stress), double(w.amplitude),
                        double(w.frequency), double(w.mass));
        std::printf("\n");
    }
    std::printf("time step      %.9g s\n", dt);
    std::printf("skin           %g m\n", double(s.skin));
    std::printf("time           %.9g s (step %zu) to %.9g s (step %zu): %zu steps\n", double(plan.first) * dt,
                plan.first, double(plan.last) * dt, plan.last, plan.last - plan.first);
    std::printf("outputs        %zu, every %zu steps (%.9g s): %s/%s ... %s\n", plan.outputs(), plan.every,
                double(plan.every) * dt, files.folder.c_str(), files.numbered(0, ".ck").c_str(),
                files.numbered(plan.outputs() - 1, ".ck").c_str());
}

/// Prints a coupled checkpoint's fluid (its setup, fluid/setup.cuh, and the grid of its fluid
/// section `state`) for --dry; `dt` is the DEM time step (s).
template <class Real>
void describe_fluid(const sphere::coupling_setup<Real>& c, const sphere::fluid_snapshot<Real>& state, double dt)
{
    const auto& f = c.params.fluid;
    std::printf("fluid          %s (%s pressure solver, %s drag), %u x %u x %u cells over [%g, %g] x [%g, %g] x [%g, %g] m\n",
                c.model.c_str(), c.solver.c_str(), c.drag.c_str(), state.n[0], state.n[1], state.n[2], state.lo[0],
                state.hi[0], state.lo[1], state.hi[1], state.lo[2], state.hi[2]);
    std::printf("fluid step     %u DEM steps: %.9g s\n", c.options.dem_steps, c.options.dem_steps * dt);
    std::printf("fluid          density %g kg/m^3, viscosity %g Pa s, beta %g, gravity (%g, %g, %g) m/s^2\n",
                double(f.density), double(f.viscosity), double(f.beta), double(f.gravity.x), double(f.gravity.y),
                double(f.gravity.z));
    const sphere::fluid_boundary<Real>* ends[2] = {&f.bottom, &f.top};
    const char* names[2] = {"bottom", "top"};
    for (int e = 0; e < 2; ++e) {
        const auto& b = *ends[e];
        std::printf("fluid %-8s %s", names[e], sphere::name(b.kind));
        if (b.kind == sphere::fluid_boundary_kind::pressure)
            std::printf(" %g Pa (amplitude %g Pa, %g Hz)", double(b.pressure), double(b.amplitude),
                        double(b.frequency));
        if (b.kind == sphere::fluid_boundary_kind::inflow) std::printf(" %g m/s", double(b.velocity));
        std::printf("\n");
    }
    std::printf("fluid solver   tolerance %g (%s), at most %u iterations\n", double(f.poisson.tolerance),
                sphere::name(f.poisson.criterion), f.poisson.max_iterations);
    std::printf("coupling       porosity %s, pressure force %s\n", sphere::name(c.options.porosity),
                c.options.pressure_force ? "on" : "off");
    if (c.model == "darcy")
        std::printf("darcy          compressibility %g 1/Pa, permeability prefactor %g m^2, max porosity %g\n",
                    double(c.params.compressibility), double(c.params.permeability_prefactor),
                    double(c.params.max_porosity));
}

} // namespace program
