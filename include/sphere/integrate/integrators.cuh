#pragma once
/// \file
/// Explicit time integrators (policy types). Each advances one degree of freedom (a position
/// and its velocity, or an angular position and its angular velocity) by dt under a constant
/// acceleration a, and says what the velocity is at the time of the new position (contact
/// laws and diagnostics use that one). Errors at the default time step: docs/physics.md,
/// "Integration".
///
/// `distinct_synchronous_velocity` says whether synchronous_velocity can differ from v: when it
/// cannot, the particles keep one velocity array instead of two.
///
/// An integrator with `drifts_before_forces` (velocity Verlet) splits the step around the
/// force evaluation: `drift` before it (with the acceleration of the last forces), `advance`
/// after it. The others do all of their step in `advance`, after the forces.
///
/// Positions may be held in a wider type (Coord) than velocities (Real, precision mixed): the
/// step's displacement is formed in Real and added to the position in Coord.
#include "../core/vec.cuh"

namespace sphere {
namespace integrate {

/// Semi-implicit (symplectic) Euler: v += a dt; x += v dt. The default: it conserves the
/// energy of an elastic collision (e = 1.000 +- 0.001 at dt = 0.075 sqrt(m / k_n)).
struct semi_implicit_euler {
    static constexpr bool drifts_before_forces = false;
    /// the velocity at the positions' time differs from v (and is stored apart, v_sync)
    static constexpr bool distinct_synchronous_velocity = true;
    template <class Coord, class Real>
    SPHERE_HDI static void advance(vec3<Coord>& x, vec3<Real>& v, const vec3<Real>& a, Real dt)
    {
        v += a * dt;
        x += vec_cast<Coord>(v * dt);
    }

    /// v is the mid-step velocity v(t + dt/2); the velocity at the new position's time is
    /// v + a dt / 2 up to O(dt^2) (a from the step just taken).
    template <class Real>
    SPHERE_HDI static vec3<Real> synchronous_velocity(const vec3<Real>& v, const vec3<Real>& a, Real dt)
    {
        return v + a * (dt / 2);
    }
};

/// sphere's second-order Taylor scheme: x += v dt + a dt^2 / 2; v += a dt. Creates energy in
/// collisions (e = 1.087 for an elastic pair at the default time step).
struct taylor2 {
    static constexpr bool drifts_before_forces = false;
    static constexpr bool distinct_synchronous_velocity = false;
    template <class Coord, class Real>
    SPHERE_HDI static void advance(vec3<Coord>& x, vec3<Real>& v, const vec3<Real>& a, Real dt)
    {
        x += vec_cast<Coord>(v * dt + a * (dt * dt / 2));
        v += a * dt;
    }

    template <class Real>
    SPHERE_HDI static vec3<Real> synchronous_velocity(const vec3<Real>& v, const vec3<Real>&, Real)
    {
        return v;
    }
};

/// Explicit (forward) Euler: x += v dt; v += a dt. Creates energy (e = 1.181 for an elastic
/// pair at the default time step).
struct explicit_euler {
    static constexpr bool drifts_before_forces = false;
    static constexpr bool distinct_synchronous_velocity = false;
    template <class Coord, class Real>
    SPHERE_HDI static void advance(vec3<Coord>& x, vec3<Real>& v, const vec3<Real>& a, Real dt)
    {
        x += vec_cast<Coord>(v * dt);
        v += a * dt;
    }

    template <class Real>
    SPHERE_HDI static vec3<Real> synchronous_velocity(const vec3<Real>& v, const vec3<Real>&, Real)
    {
        return v;
    }
};

/// Velocity Verlet (LAMMPS' and LIGGGHTS' `fix nve/sphere`): a half kick with the last
/// forces and a drift, v += a dt / 2; x += v dt (`drift`, before the forces); then the other
/// half kick with the new forces, v += a dt / 2 (`advance`). The dashpots see the velocity
/// between the two kicks, as in those codes; after the step v is the velocity at the time of
/// the positions.
struct velocity_verlet {
    static constexpr bool drifts_before_forces = true;
    static constexpr bool distinct_synchronous_velocity = false;

    template <class Coord, class Real>
    SPHERE_HDI static void drift(vec3<Coord>& x, vec3<Real>& v, const vec3<Real>& a, Real dt)
    {
        v += a * (dt / 2);
        x += vec_cast<Coord>(v * dt);
    }

    template <class Coord, class Real>
    SPHERE_HDI static void advance(vec3<Coord>&, vec3<Real>& v, const vec3<Real>& a, Real dt)
    {
        v += a * (dt / 2);
    }

    template <class Real>
    SPHERE_HDI static vec3<Real> synchronous_velocity(const vec3<Real>& v, const vec3<Real>&, Real)
    {
        return v;
    }
};

} // namespace integrate
} // namespace sphere
