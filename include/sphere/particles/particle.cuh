#pragma once
/// \file
/// The description of one particle that a user hands to a simulation.
#include <cstdint>

#include "../core/vec.cuh"

namespace sphere {

/// How the integrator treats a particle.
enum class motion : std::uint8_t {
    free = 0,       ///< moves under its forces, torques and gravity
    prescribed = 1, ///< moves at its own velocity and angular velocity, which never change by force
    fixed = 2,      ///< never moves; velocity and angular velocity are zero
    /// moves at its own x and y velocity and its own angular velocity, and along z under its
    /// contact forces alone, without gravity: sphere's `fixvel` top layer of a shear test, which
    /// is driven horizontally and free to dilate (docs/physics.md, "Driven particles")
    prescribed_horizontal = 3,
};

/// The largest valid motion value.
inline constexpr std::uint8_t last_motion = static_cast<std::uint8_t>(motion::prescribed_horizontal);

/// One sphere: SI units throughout.
template <class Real>
struct particle {
    vec3<Real> position{0, 0, 0};         ///< centre (m)
    Real radius = 0;                      ///< (m), > 0
    Real density = 0;                     ///< (kg/m^3), > 0; mass = 4/3 pi r^3 density
    vec3<Real> velocity{0, 0, 0};         ///< (m/s)
    vec3<Real> angular_velocity{0, 0, 0}; ///< (rad/s)
    motion kind = motion::free;
    std::uint8_t material = 0;            ///< material index, < the contact law's materials (contact::materials; 1 for other laws)
};

} // namespace sphere
