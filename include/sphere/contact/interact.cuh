#pragma once
/// \file
/// The interaction kernel: each particle gathers the forces and torques of its listed
/// partners and of the walls it touches, with no atomics, so results are deterministic.
/// Each pair is evaluated from both sides; each side books half of the pair's dissipation.
/// Dashpots see the velocities at the time of the positions (v_sync, omega_sync); tangential
/// springs follow the displacement of the last step (v, omega times dt: the velocities that
/// moved the positions).
#include <cstddef>

#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../particles/state.cuh"
#include "contact_lists.cuh"
#include "params.cuh"
#include "result.cuh"

namespace sphere {
namespace detail {

template <class Real, class Law>
struct interact {
    particle_view<Real> p;
    contact_view<Real> c;
    world<Real> box;
    wall_set<Real> walls;
    contact_params<Real> pair_params;
    contact_params<Real> wall_params;
    Real dt;

    SPHERE_HD void operator()(std::size_t i) const
    {
        const vec4<Real> xi = p.x[i];
        const vec3<Real> vi = p.v_sync[i];
        const vec3<Real> wi = p.omega_sync[i];
        vec3<Real> force{0, 0, 0}, torque{0, 0, 0};
        Real fn_sum = 0, visc = 0, fric = 0;

        const unsigned listed = c.count[i] < c.capacity ? c.count[i] : static_cast<unsigned>(c.capacity);
        for (unsigned k = 0; k < listed; ++k) {
            const std::size_t e = i * c.capacity + k;
            const unsigned j = c.partner[e];
            const vec4<Real> xj = p.x[j];
            const vec3<Real> d = box.nearest_image(xi.xyz() - xj.xyz());
            const Real dist = norm(d);
            const Real delta_n = dist - (xi.w + xj.w);
            vec4<Real> h = c.history[e];
            if (delta_n < Real(0) && dist > Real(0)) {
                const vec3<Real> n = d / dist;
                const Real arm_i = xi.w + delta_n / 2, arm_j = xj.w + delta_n / 2;
                const contact_motion<Real> m{
                    n, delta_n, vi - p.v_sync[j] + arm_i * cross(n, wi) + arm_j * cross(n, p.omega_sync[j]),
                    (p.v[i] - p.v[j] + arm_i * cross(n, p.omega[i]) + arm_j * cross(n, p.omega[j])) * dt};
                const contact_result<Real> r = Law::pair(pair_params, m, h, dt);
                force += r.normal + r.tangential;
                torque -= arm_i * cross(n, r.tangential);
                fn_sum += r.fn;
                visc += r.visc_rate / 2;
                fric += r.fric_rate / 2;
                c.force[e] = {r.tangential.x, r.tangential.y, r.tangential.z, dot(r.normal, n)};
            } else {
                h = vec4<Real>{0, 0, 0, 0}; // a contact that has ended forgets its history
                c.force[e] = vec4<Real>{0, 0, 0, 0};
            }
            c.history[e] = h;
        }

        for (int f = 0; f < wall_set<Real>::count; ++f) {
            const wall_face<Real>& wall = walls.face[f];
            if (!wall.active) continue;
            const std::size_t e = i * wall_set<Real>::count + static_cast<std::size_t>(f);
            const int a = f / 2;
            const vec3<Real> n = wall_set<Real>::inward_normal(f);
            const Real dist = (xi.xyz()[a] - Real(wall.position)) * n[a];
            const Real delta_n = dist - xi.w;
            vec4<Real> h = c.wall_history[e];
            vec3<Real> on_particle{0, 0, 0};
            if (delta_n < Real(0)) {
                contact_motion<Real> m{n, delta_n, vi + dist * cross(n, wi), (p.v[i] + dist * cross(n, p.omega[i])) * dt};
                m.velocity[a] -= Real(wall.velocity);
                m.step[a] -= Real(wall.velocity) * dt;
                const contact_result<Real> r = Law::wall(wall_params, m, h, dt);
                force += r.normal + r.tangential;
                torque -= dist * cross(n, r.tangential);
                fn_sum += r.fn;
                visc += r.visc_rate;
                fric += r.fric_rate;
                on_particle = r.normal + r.tangential;
            } else {
                h = vec4<Real>{0, 0, 0, 0};
            }
            c.wall_history[e] = h;
            c.wall_force[e] = on_particle;
        }

        p.force[i] = force;
        p.torque[i] = torque;
        p.pressure[i] = fn_sum / (4 * pi<Real> * xi.w * xi.w);
        p.p_visc[i] = visc;
        p.p_fric[i] = fric;
        p.e_visc[i] += visc * dt;
        p.e_fric[i] += fric * dt;
    }
};

} // namespace detail
} // namespace sphere
