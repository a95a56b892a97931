#pragma once
/// \file
/// The time step of a contact law's rule (contact/law.cuh, time_step_rule; docs/physics.md,
/// "Time step"), from the particles.
#include <cstddef>
#include <vector>

#include "../core/constants.cuh"
#include "../particles/particle.cuh"

namespace sphere {

/// The smallest of a law's time scale over the particles (s) and the particle (user index)
/// that has it.
template <class Real>
struct time_scale_minimum {
    Real scale = 0;
    std::size_t particle = 0;
};

/// Law's time scale minimised over `particles` (masses from radius and density).
template <class Law, class Real, class Params>
time_scale_minimum<Real> smallest_time_scale(const Params& pair, const Params& wall,
                                             const std::vector<particle<Real>>& particles)
{
    time_scale_minimum<Real> out;
    for (std::size_t i = 0; i < particles.size(); ++i) {
        const Real t = Law::time_scale(pair, wall, sphere_mass(particles[i].radius, particles[i].density),
                                       particles[i].radius);
        if (i == 0 || t < out.scale) out = {t, i};
    }
    return out;
}

} // namespace sphere
