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

/// Advances particle i by dt: free particles under contact force, external force (when
/// `external` is not null: the pore fluid's), torque and gravity with the integrator policy (moment of inertia 2/5 m r^2), prescribed ones at their own velocities,
/// horizontally prescribed ones at their own x, y and angular velocities and along z under the
/// contact force alone, fixed ones not at all. Also stores the velocities at the new positions'
/// time. Coordinates on periodic axes are wrapped back into the box.
template <class Real, class Integrator>
struct integrate_particles {
    particle_view<Real> p;
    world<Real> box;
    vec3<Real> gravity;
    Real dt;
    const vec3<Real>* external; ///< external force on each particle (N), or null

    SPHERE_HD void operator()(std::size_t i) const
    {
        const auto kind = static_cast<motion>(p.kind[i]);
        if (kind == motion::fixed) return;
        vec4<Real> x = p.x[i];
        vec3<Real> pos = x.xyz();
        vec3<Real> v = p.v[i], w = p.omega[i], ang = p.angpos[i];
        vec3<Real> v_sync = v, w_sync = w;
        if (kind == motion::free) {
            const Real m = p.mass[i];
            const Real inertia = Real(0.4) * m * x.w * x.w;
            const vec3<Real> f = external ? p.force[i] + external[i] : p.force[i];
            const vec3<Real> a = f / m + gravity, alpha = p.torque[i] / inertia;
            Integrator::advance(pos, v, a, dt);
            Integrator::advance(ang, w, alpha, dt);
            v_sync = Integrator::synchronous_velocity(v, a, dt);
            w_sync = Integrator::synchronous_velocity(w, alpha, dt);
        } else if (kind == motion::prescribed_horizontal) {
            const vec3<Real> a{0, 0, p.force[i].z / p.mass[i]}; // x and y stay at their velocity
            Integrator::advance(pos, v, a, dt);
            v_sync = Integrator::synchronous_velocity(v, a, dt);
            ang += w * dt;
        } else {
            pos += v * dt;
            ang += w * dt;
        }
        p.x[i] = {box.wrap(pos.x, 0), box.wrap(pos.y, 1), box.wrap(pos.z, 2), x.w};
        p.v[i] = v;
        p.omega[i] = w;
        p.v_sync[i] = v_sync;
        p.omega_sync[i] = w_sync;
        p.angpos[i] = ang;
    }
};

/// Result of the post-step check: the largest squared displacement since the contact lists
/// were built (m^2), and the first particle that is non-finite or outside the walls on a wall
/// axis (~0 when none is).
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

template <class Real>
struct check_particle {
    particle_view<Real> p;
    const vec4<Real>* x_at_build;
    world<Real> box;
    wall_set<Real> walls;

    SPHERE_HD step_check<Real> operator()(std::size_t i) const
    {
        const vec3<Real> pos = p.x[i].xyz();
        bool bad = !isfinite(pos) || !isfinite(p.v_sync[i]) || !isfinite(p.omega_sync[i]);
        for (int a = 0; a < 3; ++a)
            if (!box.periodic(a) && !(pos[a] >= Real(walls.face[2 * a].position) && pos[a] <= Real(walls.face[2 * a + 1].position)))
                bad = true;
        const Real moved = norm2(box.nearest_image(pos - x_at_build[i].xyz()));
        return {bad ? Real(0) : moved, bad ? i : ~std::size_t(0)};
    }
};

} // namespace detail
} // namespace sphere
