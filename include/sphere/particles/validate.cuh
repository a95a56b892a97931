#pragma once
/// \file
/// Setup checks of particle descriptions against the world box.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "../boundary/world.cuh"
#include "../core/error.cuh"
#include "particle.cuh"

namespace sphere {

/// Throws sphere::error naming the first particle with a non-positive or non-finite radius
/// or density, a non-finite position or velocity, or a centre outside the world on a wall axis.
template <class Real>
void validate_particles(const std::vector<particle<Real>>& particles, const world<Real>& box)
{
    if (particles.size() >= std::numeric_limits<unsigned>::max())
        detail::fail("too many particles: ", particles.size(), " (at most 2^32 - 2)");
    for (std::size_t i = 0; i < particles.size(); ++i) {
        const particle<Real>& p = particles[i];
        if (!(p.radius > 0) || !std::isfinite(p.radius))
            detail::fail("particle ", i, ": radius = ", p.radius, " m must be positive and finite");
        if (!(p.density > 0) || !std::isfinite(p.density))
            detail::fail("particle ", i, ": density = ", p.density, " kg/m^3 must be positive and finite");
        if (!isfinite(p.position))
            detail::fail("particle ", i, ": position (", p.position.x, ", ", p.position.y, ", ", p.position.z,
                         ") m is not finite");
        if (!isfinite(p.velocity) || !isfinite(p.angular_velocity))
            detail::fail("particle ", i, ": velocity (", p.velocity.x, ", ", p.velocity.y, ", ", p.velocity.z,
                         ") m/s or angular velocity (", p.angular_velocity.x, ", ", p.angular_velocity.y, ", ",
                         p.angular_velocity.z, ") rad/s is not finite");
        if (static_cast<std::uint8_t>(p.kind) > last_motion)
            detail::fail("particle ", i, ": motion kind ", unsigned(static_cast<std::uint8_t>(p.kind)), " is not one of ",
                         "free (0), prescribed (1), fixed (2) or prescribed_horizontal (3)");
        for (int a = 0; a < 3; ++a)
            if (!box.periodic(a) && !(p.position[a] >= box.lo[a] && p.position[a] <= box.hi[a]))
                detail::fail("particle ", i, ": position[", a, "] = ", p.position[a], " m lies outside the world [",
                             box.lo[a], ", ", box.hi[a], "] m on a wall axis");
    }
}

/// Throws sphere::error unless the world box is finite with hi > lo on every axis.
template <class Real>
void validate_world(const world<Real>& box)
{
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(box.lo[a]) || !std::isfinite(box.hi[a]) || !(box.hi[a] > box.lo[a]))
            detail::fail("settings.box: axis ", a, " spans [", box.lo[a], ", ", box.hi[a],
                         "] m; it must be finite with hi > lo");
}

} // namespace sphere
