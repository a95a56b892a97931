#pragma once
/// \file
/// The interaction kernel: each particle gathers the forces and torques of its listed
/// partners and walls, with no atomics, so results are deterministic. Each pair is evaluated
/// from both sides; each side books half of the pair's dissipation. Dashpots see the
/// velocities at the time of the positions (v_sync, omega_sync); tangential springs follow the
/// displacement of the last step (v, omega times dt: the velocities that moved the positions).
///
/// Two compile-time switches drop work that nothing reads: `Book` (the per-particle pressure,
/// dissipation rates and dissipated energies of the energy audit) and `Record` (each entry's
/// force, for the stress and contact-network analyses). The simulation picks them from its
/// settings. A third, `OneVelocity`, says that the dashpots' velocities are the ones that moved
/// the positions (velocity Verlet): the step's displacement is then the contact velocity times
/// dt, and v, omega are not read a second time.
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../core/constants.cuh"
#include "../particles/state.cuh"
#include "contact_lists.cuh"
#include "params.cuh"
#include "result.cuh"

namespace sphere {
namespace detail {

/// The particles' forces on the six wall faces, along each face's axis (N), summed in double.
struct wall_loads {
    double force[6];
    SPHERE_HD wall_loads operator+(const wall_loads& b) const
    {
        wall_loads out;
        for (int f = 0; f < 6; ++f) out.force[f] = force[f] + b.force[f];
        return out;
    }
};

/// The normal overlap-distance delta_n = |d| - reach (m, negative in contact) from a
/// separation d, its squared length dist2 and the sum of radii, and the unit normal d / |d|.
/// When positions are held in a wider type than the contact law's (precision mixed), the
/// difference dist2 - reach^2 is formed in that type and divided by |d| + reach in the narrow
/// one: the overlap keeps its relative precision although |d| and reach agree to 1e-5.
template <class Real, class Coord>
SPHERE_HDI Real overlap_and_normal(const vec3<Coord>& d, Coord dist2, Coord reach, vec3<Real>& n)
{
    if constexpr (std::is_same_v<Real, Coord>) {
        const Real dist = std::sqrt(dist2);
        n = d * (Real(1) / dist);
        return dist - reach;
    } else {
        const Real dist = std::sqrt(Real(dist2));
        n = vec_cast<Real>(d) * (Real(1) / dist);
        return Real(dist2 - reach * reach) / (dist + Real(reach));
    }
}

/// Particle i's contacts: writes its force and torque (and what Book and Record ask for) and
/// returns its share of the wall loads. P is the precision policy: positions, the world and
/// the walls in coord_t<P>, everything the contact law sees in real_t<P>.
template <class P, class Law, bool Book, bool Record, bool OneVelocity>
struct interact {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    contact_view<Real> c;
    world<Coord> box;
    wall_set<Coord> walls;
    contact_params<Real> pair_params;
    contact_params<Real> wall_params;
    Real dt;
    bool update_history; ///< false for a force evaluation that must leave the contacts as they are

    SPHERE_HD wall_loads operator()(std::size_t i) const
    {
        wall_loads loads{{0, 0, 0, 0, 0, 0}};
        const vec4<Coord> xi = p.x[i];
        const Real ri = Real(xi.w);
        const vec3<Real> vi = p.v_sync[i], wi = p.omega_sync[i];
        // the last step's motion (unused with OneVelocity)
        const vec3<Real> si = OneVelocity ? vec3<Real>{0, 0, 0} : p.v[i] * dt;
        const vec3<Real> ti = OneVelocity ? vec3<Real>{0, 0, 0} : p.omega[i] * dt;
        const Real mi = p.mass[i];
        vec3<Real> force{0, 0, 0}, torque{0, 0, 0};
        Real fn_sum = 0, visc = 0, fric = 0;

        const unsigned end = c.offset[i + 1];
        for (unsigned e = c.offset[i]; e < end; ++e) {
            const unsigned j = c.partner[e];
            vec4<Real> h = c.history[e];
            contact_result<Real> r;
            Real arm;
            vec3<Real> n;
            bool touching;
            if (j < wall_partner_base) {
                const vec4<Coord> xj = p.x[j];
                const vec3<Coord> d = box.nearest_image_inside(xi.xyz() - xj.xyz());
                const Coord dist2 = norm2(d), reach = xi.w + xj.w;
                touching = dist2 < reach * reach && dist2 > Coord(0);
                if (touching) {
                    const Real delta_n = overlap_and_normal(d, dist2, reach, n);
                    arm = ri + delta_n / 2;
                    const Real arm_j = Real(xj.w) + delta_n / 2;
                    const Real mj = p.mass[j];
                    contact_motion<Real> m;
                    m.n = n;
                    m.delta_n = delta_n;
                    m.velocity = vi - p.v_sync[j] + arm * cross(n, wi) + arm_j * cross(n, p.omega_sync[j]);
                    m.step = OneVelocity ? m.velocity * dt
                                         : si - p.v[j] * dt + arm * cross(n, ti) + arm_j * cross(n, p.omega[j] * dt);
                    m.m_eff = mi * mj / (mi + mj);
                    r = Law::pair(pair_params, m, h, dt);
                    r.visc_rate /= 2;
                    r.fric_rate /= 2;
                }
            } else {
                const int f = static_cast<int>(j - wall_partner_base);
                const wall_face<Coord>& wall = walls.face[f];
                const int a = f / 2;
                n = wall_set<Real>::inward_normal(f);
                const Coord dist_c = (xi.xyz()[a] - Coord(wall.position)) * Coord(n[a]);
                const Real dist = Real(dist_c), delta_n = Real(dist_c - xi.w);
                touching = delta_n < Real(0);
                if (touching) {
                    arm = dist;
                    contact_motion<Real> m{n, delta_n, vi + dist * cross(n, wi), si + dist * cross(n, ti), mi};
                    m.velocity[a] -= Real(wall.velocity);
                    if (OneVelocity) m.step = m.velocity * dt;
                    else m.step[a] -= Real(wall.velocity) * dt;
                    r = Law::wall(wall_params, m, h, dt);
                    loads.force[f] = -double(r.normal[a] + r.tangential[a]);
                }
            }
            if (touching) {
                force += r.normal + r.tangential;
                torque -= arm * cross(n, r.tangential);
                if (Book) {
                    fn_sum += r.fn;
                    visc += r.visc_rate;
                    fric += r.fric_rate;
                }
                if (Record) c.force[e] = {r.tangential.x, r.tangential.y, r.tangential.z, dot(r.normal, n)};
                if (update_history) c.history[e] = h;
            } else {
                if (Record) c.force[e] = vec4<Real>{0, 0, 0, 0};
                // a contact that has ended forgets its history
                if (update_history && (h.x != Real(0) || h.y != Real(0) || h.z != Real(0) || h.w != Real(0)))
                    c.history[e] = vec4<Real>{0, 0, 0, 0};
            }
        }

        p.force[i] = force;
        p.torque[i] = torque;
        if (Book && update_history) {
            p.pressure[i] = fn_sum / (4 * pi<Real> * ri * ri);
            p.p_visc[i] = visc;
            p.p_fric[i] = fric;
            p.e_visc[i] += visc * dt;
            p.e_fric[i] += fric * dt;
        }
        return loads;
    }
};

} // namespace detail
} // namespace sphere
