#pragma once
/// \file
/// The integration kernels and the post-step check of every particle. The bodies are written
/// with selects instead of branches (on the motion kind, the periodic axes, the check), so
/// that the host's loop over particles vectorises.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../boundary/position_lattice.cuh"
#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../core/constants.cuh"
#include "../particles/state.cuh"

namespace sphere {
namespace detail {

/// The accelerations of particle i (m/s^2, rad/s^2) by its motion kind: a free particle under
/// its contact force, external force (`External`: the pore fluid's, from `external`), torque
/// (moment of inertia 2/5 m r^2) and gravity; a horizontally prescribed one along z under its
/// contact force alone; none for the others.
///
/// The kinds scale the forces by 1/m or by 0 rather than select between accelerations: every
/// field is then loaded whatever the kind, which the compiler needs to vectorise the loop over
/// particles (it cannot load a particle's fields conditionally in SIMD lanes). Forces are
/// finite in any step the particle check lets through, so the zero scale gives exact zeros.
template <bool External, class P, class Real = real_t<P>>
SPHERE_HDI vec3<Real> linear_acceleration(const particle_view<P>& p, std::size_t i, motion kind,
                                          const vec3<Real>& gravity, const vec3<Real>* external)
{
    const Real m = p.mass[i];
    vec3<Real> contact = p.force[i], total = contact; // not const: see the note in contact/evaluate.cuh
    if constexpr (External) total += external[i];
    const bool free = kind == motion::free, horizontal = kind == motion::prescribed_horizontal;
    const Real inv_m = Real(1) / m;
    const Real free_scale = free ? inv_m : Real(0);
    const Real z_scale = free || horizontal ? inv_m : Real(0);
    vec3<Real> a;
    a.x = total.x * free_scale + (free ? gravity.x : Real(0));
    a.y = total.y * free_scale + (free ? gravity.y : Real(0));
    a.z = (free ? total.z : contact.z) * z_scale + (free ? gravity.z : Real(0));
    return a;
}

/// linear_acceleration and the angular acceleration (rad/s^2), with `External` the external
/// torque too where there is one (`external_torque` not null: the bonds').
template <bool External, class P, class Real = real_t<P>>
SPHERE_HDI void accelerations(const particle_view<P>& p, std::size_t i, motion kind, const vec3<Real>& gravity,
                              const vec3<Real>* external, const vec3<Real>* external_torque, vec3<Real>& a,
                              vec3<Real>& alpha)
{
    a = linear_acceleration<External>(p, i, kind, gravity, external);
    const Real m = p.mass[i], r = Real(p.x[i].w);
    vec3<Real> torque = p.torque[i]; // not const: see the note in contact/evaluate.cuh
    if constexpr (External) {
        if (external_torque) torque += external_torque[i];
    }
    alpha = torque * (kind == motion::free ? Real(1) / (Real(0.4) * m * r * r) : Real(0));
}

/// Particle i's motion kind, or motion::free without loading it when `AllFree` (every
/// particle is free). The kinds are bytes: a loop over particles that loads them is
/// vectorised by g++ with 64 lanes (one byte vector), whose spills and scalar remainder gave
/// the drift 60% more time on the dense bed (docs/performance.md); without them it takes 8.
template <bool AllFree, class P>
SPHERE_HDI motion kind_of(const particle_view<P>& p, std::size_t i)
{
    return AllFree ? motion::free : static_cast<motion>(p.kind[i]);
}

/// Advances particle i by dt after the forces: free particles with the integrator policy,
/// prescribed ones at their own velocities, horizontally prescribed ones at their own x, y and
/// angular velocities and along z under the contact force alone, fixed ones not at all. Also
/// stores the velocities at the new positions' time. Coordinates on periodic axes are wrapped
/// back into the box. For an integrator that drifts before the forces, the drift has moved
/// the particles already (drift_particles) and this is its second half kick.
///
/// Every kind goes through the integrator with its own accelerations: zero for prescribed and
/// fixed ones, whose velocities therefore stay (a fixed particle's are zero, so it stays where
/// it is). No kind selects what is stored: the compiler would turn that into conditional loads
/// and stores, which SIMD lanes cannot do. `AllFree`: every particle is free (kind_of).
template <class P, class Integrator, bool External = false, bool AllFree = false>
struct integrate_particles {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    world<Coord> box;
    vec3<Real> gravity;
    Real dt;
    const vec3<Real>* external; ///< external force on each particle (N), read with External
    const vec3<Real>* external_torque = nullptr; ///< external torque (N m), read with External unless null

    SPHERE_HDI void operator()(std::size_t i) const
    {
        constexpr bool drifted = Integrator::drifts_before_forces;
        const auto kind = kind_of<AllFree>(p, i);
        vec4<Coord> x = p.x[i]; // aggregates not const: see the note in contact/evaluate.cuh
        vec3<Coord> pos = x.xyz();
        vec3<Real> v = p.v[i], w = p.omega[i], angle{0, 0, 0}; // angles are turn_particles' (not stored here)
        vec3<Real> a, alpha;
        accelerations<External>(p, i, kind, gravity, external, external_torque, a, alpha);
        Integrator::advance(pos, v, a, dt);
        Integrator::advance(angle, w, alpha, dt);
        if (!drifted) {
            pos = box.wrap(pos);
            p.x[i] = {pos.x, pos.y, pos.z, x.w};
        }
        p.v[i] = v;
        p.omega[i] = w;
        if (Integrator::distinct_synchronous_velocity) {
            p.v_sync[i] = Integrator::synchronous_velocity(v, a, dt);
            p.omega_sync[i] = Integrator::synchronous_velocity(w, alpha, dt);
        }
    }
};

/// The part of an integrator's step before the forces (velocity Verlet's first half kick,
/// with the forces of the last step, and its drift): every kind by Integrator::drift with its
/// own accelerations, as in integrate_particles. The dashpots of the next force evaluation see
/// the velocities between the kicks. `AllFree`: every particle is free (kind_of).
template <class P, class Integrator, bool External = false, bool AllFree = false>
struct drift_particles {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    world<Coord> box;
    vec3<Real> gravity;
    Real dt;
    const vec3<Real>* external; ///< external force on each particle (N), read with External
    const vec3<Real>* external_torque = nullptr; ///< external torque (N m), read with External unless null

    /// Particle i's position (wrapped) and velocity after the drift, from its fields now;
    /// nothing is stored (check_after_drift needs no more).
    SPHERE_HDI void drifted(std::size_t i, vec3<Coord>& pos, vec3<Real>& v) const
    {
        static_assert(!Integrator::distinct_synchronous_velocity, "a drifting integrator keeps one velocity");
        pos = p.x[i].xyz();
        v = p.v[i];
        const vec3<Real> a = linear_acceleration<External>(p, i, kind_of<AllFree>(p, i), gravity, external);
        Integrator::drift(pos, v, a, dt);
        pos = box.wrap(pos);
    }

    SPHERE_HDI void operator()(std::size_t i) const
    {
        vec3<Coord> pos;
        vec3<Real> v, w;
        drift(i, pos, v, w);
    }

    /// Drifts particle i and stores it, leaving its new position, velocity and angular
    /// velocity in `pos`, `v` and `w` too (drift_and_check checks them from there).
    SPHERE_HDI void drift(std::size_t i, vec3<Coord>& pos, vec3<Real>& v, vec3<Real>& w) const
    {
        drifted(i, pos, v);
        w = p.omega[i];
        vec3<Real> angle{0, 0, 0}, a, alpha; // angles are turn_particles' (not stored here)
        accelerations<External>(p, i, kind_of<AllFree>(p, i), gravity, external, external_torque, a, alpha);
        Integrator::drift(angle, w, alpha, dt);
        p.x[i] = {pos.x, pos.y, pos.z, p.x[i].w};
        p.v[i] = v;
        p.omega[i] = w;
    }
};

/// Advances particle i's angular position by omega dt, with the angular velocity that the
/// step has just set (semi-implicit Euler's rule; velocity Verlet's mid-step angular velocity
/// when run after its drift): a pass of its own, run only with settings.angular_position,
/// so that the motion's kernels neither load nor store angles (docs/physics.md, "Angular
/// position").
template <class P>
struct turn_particles {
    using Real = real_t<P>;
    particle_view<P> p;
    Real dt;
    SPHERE_HDI void operator()(std::size_t i) const { p.angpos[i] += p.omega[i] * dt; }
};

/// Adds v dt to particle i's accumulated displacement, with the velocity that the step has just
/// moved it by (semi-implicit Euler's new velocity; velocity Verlet's mid-step velocity when run
/// after its drift; Taylor's second-order term a dt^2 / 2 is not in it), in the positions'
/// precision: a pass of its own, run only with settings.accumulated_displacement
/// (docs/physics.md, "Accumulated displacement").
template <class P>
struct displace_particles {
    using Coord = coord_t<P>;
    particle_view<P> p;
    Coord dt;
    SPHERE_HDI void operator()(std::size_t i) const { p.displacement[i] += vec_cast<Coord>(p.v[i]) * dt; }
};

/// The post-step check of particle i: the squared displacement since the contact lists were
/// built (m^2), or +infinity when the particle is non-finite or outside the walls on a wall
/// axis (`bad`). The largest over all particles decides on a rebuild, and +infinity sends
/// the simulation looking for the particle to report.
template <class P>
struct check_particle {
    using Coord = coord_t<P>;
    particle_view<P> p;
    const typename position_lattice<Coord>::stored* x_at_build; ///< reference positions at the last rebuild
    position_lattice<Coord> lattice;
    world<Coord> box;
    wall_set<Coord> walls;

    SPHERE_HDI bool bad(std::size_t i) const { return bad_at(p.x[i].xyz(), p.v_sync[i], p.omega_sync[i]); }

    /// Whether a particle at `pos` (m) with synchronous velocity `v` (m/s) and angular velocity
    /// `w` (rad/s) fails the check.
    SPHERE_HDI bool bad_at(const vec3<Coord>& pos, const vec3<real_t<P>>& v, const vec3<real_t<P>>& w) const
    {
        const bool position_finite = isfinite(pos), velocity_finite = isfinite(v), spin_finite = isfinite(w);
        bool out = !(position_finite & velocity_finite & spin_finite);
        for (int a = 0; a < 3; ++a) {
            const Coord c = pos[a];
            const bool above = c >= Coord(walls.face[2 * a].position), below = c <= Coord(walls.face[2 * a + 1].position);
            const bool walled = !box.periodic(a);
            out = out | (walled & !(above & below));
        }
        return out;
    }

    SPHERE_HDI Coord operator()(std::size_t i) const { return at(i, p.x[i].xyz(), p.v_sync[i], p.omega_sync[i]); }

    /// The check of particle i, were it at `pos` (wrapped into the box) with synchronous
    /// velocity `v` and angular velocity `w`.
    SPHERE_HDI Coord at(std::size_t i, const vec3<Coord>& pos, const vec3<real_t<P>>& v, const vec3<real_t<P>>& w) const
    {
        // Written so that the displacement is computed whatever the outcome (the compiler
        // cannot load fields conditionally in SIMD lanes): a NaN becomes +infinity, and a bad
        // particle's +infinity wins the maximum.
        const Coord inf = infinity<Coord>;
        Coord moved = norm2(box.nearest_image_inside(pos - lattice.decode(x_at_build[i]))); // both wrapped
        moved = moved == moved ? moved : inf;
        const Coord flag = bad_at(pos, v, w) ? inf : Coord(0);
        return moved > flag ? moved : flag;
    }
};

/// The check of particle i at the position the next drift will give it (velocity Verlet, at
/// the end of a step: the host then decides the next step's rebuild without waiting for the
/// drift). Against the walls where they stand now, before they move.
template <class P, class Integrator, bool External>
struct check_after_drift {
    drift_particles<P, Integrator, External> drift;
    check_particle<P> check;
    SPHERE_HDI coord_t<P> operator()(std::size_t i) const
    {
        vec3<coord_t<P>> pos;
        vec3<real_t<P>> v;
        drift.drifted(i, pos, v);
        return check.at(i, pos, check.p.v_sync[i], check.p.omega_sync[i]); // the velocities before the drift
    }
};

/// Drifts particle i (drift_particles) and returns its check (check_particle) at the position
/// and velocities the drift has just stored, from the drift's registers: a check after the
/// drift as a separate body (then_check) loads them again, and the compiler cannot know that
/// the stores and loads name the same memory (the loop then transposes every field twice).
template <class P, class Integrator, bool External, bool AllFree>
struct drift_and_check {
    drift_particles<P, Integrator, External, AllFree> drift;
    check_particle<P> check;
    SPHERE_HDI coord_t<P> operator()(std::size_t i) const
    {
        vec3<coord_t<P>> pos;
        vec3<real_t<P>> v, w;
        drift.drift(i, pos, v, w);
        return check.at(i, pos, v, w);
    }
};

/// The user index of particle i when the check finds it bad, else ~0 (for the lowest one:
/// the particle a run-time error names).
template <class P>
struct bad_particle {
    check_particle<P> check;
    SPHERE_HD std::size_t operator()(std::size_t i) const { return check.bad(i) ? std::size_t(check.p.user[i]) : ~std::size_t(0); }
};

/// No check: 0 for every particle (velocity Verlet on the host's slab schedule, whose drift
/// checks the particles itself).
template <class Coord>
struct no_check {
    SPHERE_HDI Coord operator()(std::size_t) const { return Coord(0); }
};

/// Runs a particle kernel `body` on particle i, then returns the particle check `Check`
/// (check_particle, check_after_drift or no_check; kernel body of a transform_reduce: one parallel pass
/// instead of two).
template <class Body, class Check>
struct then_check {
    Body body;
    Check check;
    SPHERE_HDI auto operator()(std::size_t i) const
    {
        body(i);
        return check(i);
    }
};

} // namespace detail
} // namespace sphere
