#pragma once
// What `sphere --dry` prints (docs/program.md): the key settings of a checkpoint and the plan of
// the run, so that a user sees the time step and the number of steps and outputs before a run.
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

} // namespace program
