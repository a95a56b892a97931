#pragma once
/// \file
/// The integration kernel and the post-step check of every particle.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../particles/state.cuh"

namespace sphere {
namespace detail {

/// The accelerations of free particle i (m/s^2, rad/s^2) under its contact force, external
/// force (when `external` is not null: the pore fluid's), torque (moment of inertia 2/5 m r^2)
/// and gravity.
template <class P, class Real = real_t<P>>
SPHERE_HD void free_accelerations(const particle_view<P>& p, std::size_t i, const vec3<Real>& gravity,
                                  const vec3<Real>* external, vec3<Real>& a, vec3<Real>& alpha)
{
    const Real m = p.mass[i], r = Real(p.x[i].w);
    const vec3<Real> f = external ? p.force[i] + external[i] : p.force[i];
    a = f / m + gravity;
    alpha = p.torque[i] / (Real(0.4) * m * r * r);
}

/// Advances particle i by dt after the forces: free particles with the integrator policy,
/// prescribed ones at their own velocities, horizontally prescribed ones at their own x, y and
/// angular velocities and along z under the contact force alone, fixed ones not at all. Also
/// stores the velocities at the new positions' time. Coordinates on periodic axes are wrapped
/// back into the box. For an integrator that drifts before the forces, the drift has moved
/// the particles already (drift_particles) and this is its second half kick.
template <class P, class Integrator>
struct integrate_particles {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    world<Coord> box;
    vec3<Real> gravity;
    Real dt;
    const vec3<Real>* external; ///< external force on each particle (N), or null

    SPHERE_HD void operator()(std::size_t i) const
    {
        const auto kind = static_cast<motion>(p.kind[i]);
        if (kind == motion::fixed) return;
        const vec4<Coord> x = p.x[i];
        vec3<Coord> pos = x.xyz();
        vec3<Real> v = p.v[i], w = p.omega[i], ang = p.angpos[i];
        vec3<Real> v_sync = v, w_sync = w;
        constexpr bool drifted = Integrator::drifts_before_forces;
        if (kind == motion::free) {
            vec3<Real> a, alpha;
            free_accelerations(p, i, gravity, external, a, alpha);
            Integrator::advance(pos, v, a, dt);
            Integrator::advance(ang, w, alpha, dt);
            v_sync = Integrator::synchronous_velocity(v, a, dt);
            w_sync = Integrator::synchronous_velocity(w, alpha, dt);
        } else if (kind == motion::prescribed_horizontal) {
            const vec3<Real> a{0, 0, p.force[i].z / p.mass[i]}; // x and y stay at their velocity
            Integrator::advance(pos, v, a, dt);
            v_sync = Integrator::synchronous_velocity(v, a, dt);
            if (!drifted) ang += w * dt;
        } else if (!drifted) {
            pos += vec_cast<Coord>(v * dt);
            ang += w * dt;
        }
        if (!drifted) {
            p.x[i] = {box.wrap(pos.x, 0), box.wrap(pos.y, 1), box.wrap(pos.z, 2), x.w};
            p.angpos[i] = ang;
        }
        p.v[i] = v;
        p.omega[i] = w;
        p.v_sync[i] = v_sync;
        p.omega_sync[i] = w_sync;
    }
};

/// The part of an integrator's step before the forces (velocity Verlet's first half kick,
/// with the forces of the last step, and its drift): free and horizontally prescribed
/// particles by Integrator::drift, prescribed ones at their own velocities. The dashpots of
/// the next force evaluation see the velocities between the kicks.
template <class P, class Integrator>
struct drift_particles {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    world<Coord> box;
    vec3<Real> gravity;
    Real dt;
    const vec3<Real>* external; ///< external force on each particle (N), or null

    SPHERE_HD void operator()(std::size_t i) const
    {
        const auto kind = static_cast<motion>(p.kind[i]);
        if (kind == motion::fixed) return;
        const vec4<Coord> x = p.x[i];
        vec3<Coord> pos = x.xyz();
        vec3<Real> v = p.v[i], w = p.omega[i], ang = p.angpos[i];
        if (kind == motion::free) {
            vec3<Real> a, alpha;
            free_accelerations(p, i, gravity, external, a, alpha);
            Integrator::drift(pos, v, a, dt);
            Integrator::drift(ang, w, alpha, dt);
        } else if (kind == motion::prescribed_horizontal) {
            Integrator::drift(pos, v, vec3<Real>{0, 0, p.force[i].z / p.mass[i]}, dt);
            ang += w * dt;
        } else {
            pos += vec_cast<Coord>(v * dt);
            ang += w * dt;
        }
        p.x[i] = {box.wrap(pos.x, 0), box.wrap(pos.y, 1), box.wrap(pos.z, 2), x.w};
        p.v[i] = v;
        p.omega[i] = w;
        p.v_sync[i] = v;
        p.omega_sync[i] = w;
        p.angpos[i] = ang;
    }
};

/// Result of the post-step check: the largest squared displacement since the contact lists
/// were built (m^2), and the lowest user index of a particle that is non-finite or outside the
/// walls on a wall axis (~0 when none is).
template <class Real>
struct step_check {
    Real max_displacement2;
    std::size_t first_bad;
};

struct combine_checks {
    template <class Real>
    SPHERE_HD step_check<Real> operator()(const step_check<Real>& a, const step_check<Real>& b) const
    {
        return {a.max_displacement2 < b.max_displacement2 ? b.max_displacement2 : a.max_displacement2,
                b.first_bad < a.first_bad ? b.first_bad : a.first_bad};
    }
};

template <class P>
struct check_particle {
    using Coord = coord_t<P>;
    particle_view<P> p;
    const vec4<Coord>* x_at_build;
    world<Coord> box;
    wall_set<Coord> walls;

    SPHERE_HD step_check<Coord> operator()(std::size_t i) const
    {
        const vec3<Coord> pos = p.x[i].xyz();
        bool bad = !isfinite(pos) || !isfinite(p.v_sync[i]) || !isfinite(p.omega_sync[i]);
        for (int a = 0; a < 3; ++a)
            if (!box.periodic(a) && !(pos[a] >= Coord(walls.face[2 * a].position) && pos[a] <= Coord(walls.face[2 * a + 1].position)))
                bad = true;
        const Coord moved = norm2(box.nearest_image(pos - x_at_build[i].xyz()));
        return {bad ? Coord(0) : moved, bad ? std::size_t(p.user[i]) : ~std::size_t(0)};
    }
};

/// Runs a particle kernel `body` on particle i, then checks the particle (kernel body of a
/// transform_reduce: one parallel pass instead of two).
template <class Body, class P>
struct then_check {
    Body body;
    check_particle<P> check;
    SPHERE_HD step_check<coord_t<P>> operator()(std::size_t i) const
    {
        body(i);
        return check(i);
    }
};

} // namespace detail
} // namespace sphere
