#pragma once
/// \file
/// How each wall of the world box moves: fixed, at a prescribed velocity, or under a
/// prescribed normal stress (optionally modulated as a sine), and the host-side update of the
/// walls after each step (docs/physics.md, "Dynamic walls").
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "walls.cuh"
#include "world.cuh"

namespace sphere {

enum class wall_mode : std::uint8_t {
    fixed = 0,    ///< the wall stays where it is
    velocity = 1, ///< the wall moves at `velocity`
    stress = 2,   ///< the wall has a mass and moves under its target stress and the particles' force
};

/// A wall mode's name as written in C++ ("fixed", "velocity", "stress").
inline const char* name(wall_mode m)
{
    switch (m) {
    case wall_mode::fixed: return "fixed";
    case wall_mode::velocity: return "velocity";
    case wall_mode::stress: return "stress";
    }
    return "?";
}

/// The motion of one wall face. Velocities and stresses are along the face's inward normal:
/// a positive velocity moves the wall into the world, a positive stress compresses.
template <class Real>
struct wall_control {
    wall_mode mode = wall_mode::fixed;
    Real velocity = 0;  ///< velocity mode: inward velocity (m/s)
    Real stress = 0;    ///< stress mode: mean target normal stress sigma_0 (Pa)
    Real amplitude = 0; ///< stress mode: amplitude of the sine modulation (Pa)
    Real frequency = 0; ///< stress mode: frequency of the modulation (Hz)
    Real phase = 0;     ///< stress mode: phase of the modulation (rad)
    Real mass = 0;      ///< stress mode: the wall's mass (kg), > 0

    /// sigma_0 + amplitude sin(2 pi frequency t + phase) (Pa).
    double target_stress(double t) const
    {
        return double(stress) + double(amplitude) * std::sin(2 * pi<double> * double(frequency) * t + double(phase));
    }
};

/// Throws sphere::error naming the first wall control that is inconsistent with the world box
/// or has a non-finite or non-positive value where one is needed.
template <class Real>
void validate_wall_controls(const wall_control<Real> (&controls)[wall_set<Real>::count], const world<Real>& box)
{
    for (int f = 0; f < wall_set<Real>::count; ++f) {
        const wall_control<Real>& c = controls[f];
        if (static_cast<unsigned>(c.mode) > static_cast<unsigned>(wall_mode::stress))
            detail::fail("settings.walls[", f, "].mode = ", static_cast<unsigned>(c.mode),
                         ": not a wall_mode (0 fixed, 1 velocity, 2 stress)");
        if (c.mode == wall_mode::fixed) continue;
        if (box.periodic(f / 2))
            detail::fail("settings.walls[", f, "]: axis ", f / 2, " is periodic, so face ", f, " has no wall to move");
        if (c.mode == wall_mode::velocity && !std::isfinite(c.velocity))
            detail::fail("settings.walls[", f, "].velocity = ", c.velocity, " m/s is not finite");
        if (c.mode == wall_mode::stress) {
            if (!(c.mass > 0) || !std::isfinite(c.mass))
                detail::fail("settings.walls[", f, "].mass = ", c.mass, " kg: a stress-controlled wall needs a positive, finite mass");
            if (!std::isfinite(c.stress) || !std::isfinite(c.amplitude) || !std::isfinite(c.frequency) ||
                !std::isfinite(c.phase))
                detail::fail("settings.walls[", f, "]: stress ", c.stress, " Pa, amplitude ", c.amplitude,
                             " Pa, frequency ", c.frequency, " Hz and phase ", c.phase, " rad must be finite");
        }
    }
}

/// Area of wall face f (m^2): the extent of the box across the other two axes, measured
/// between the current walls on wall axes.
template <class Real>
double wall_area(const wall_set<Real>& walls, const world<Real>& box, int f)
{
    double area = 1;
    for (int b = 0; b < 3; ++b) {
        if (b == f / 2) continue;
        area *= box.periodic(b) ? double(box.length(b))
                                : walls.face[2 * b + 1].position - walls.face[2 * b].position;
    }
    return area;
}

/// Moves every wall by one step of dt (s) at time t (s), given the force the particles exert
/// on each face along its axis (N). Records that force and the work the wall did on the
/// particles. Throws when a wall would leave the world box or cross the opposite wall.
template <class Real>
void advance_walls(wall_set<Real>& walls, const wall_control<Real> (&controls)[wall_set<Real>::count],
                   const world<Real>& box, const double (&particle_force)[wall_set<Real>::count], double t,
                   Real dt, std::size_t step)
{
    const wall_set<Real> before = walls;
    for (int f = 0; f < wall_set<Real>::count; ++f) {
        wall_face<Real>& w = walls.face[f];
        if (!w.active) continue;
        const int a = f / 2;
        const double inward = f % 2 == 0 ? 1.0 : -1.0; // inward normal along the axis
        w.force = particle_force[f];
        const wall_control<Real>& c = controls[f];
        double v_in = w.velocity * inward;
        if (c.mode == wall_mode::fixed) {
            v_in = 0;
        } else if (c.mode == wall_mode::velocity) {
            v_in = double(c.velocity);
        } else { // stress: the target stress pushes inward, the particles push back
            const double net = c.target_stress(t) * wall_area(before, box, f) + particle_force[f] * inward;
            v_in += net / double(c.mass) * double(dt);
        }
        const double moved = v_in * inward * double(dt);
        // The power of this step's force at this step's time, with the wall's velocity there
        // taken as the mean of the velocities before and after (as the particles' v_sync).
        const double v_sync = (w.velocity + v_in * inward) / 2;
        w.work -= particle_force[f] * v_sync * double(dt);
        w.velocity = v_in * inward;
        w.position += moved;
        if (!(w.position >= box.lo[a] && w.position <= box.hi[a]))
            detail::fail("step ", step, ": wall face ", f, " moved to ", w.position, " m, outside the world [",
                         box.lo[a], ", ", box.hi[a], "] m on axis ", a);
    }
    for (int a = 0; a < 3; ++a)
        if (walls.face[2 * a].active && !(walls.face[2 * a].position < walls.face[2 * a + 1].position))
            detail::fail("step ", step, ": the walls on axis ", a, " crossed (", walls.face[2 * a].position, " m and ",
                         walls.face[2 * a + 1].position, " m)");
}

} // namespace sphere
