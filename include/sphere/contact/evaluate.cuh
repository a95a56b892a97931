#pragma once
/// \file
/// One contact evaluated: a particle pair (`pair_contact`, for the pair's owner in the contact
/// lists) and a particle's walls (`wall_contacts`). The interaction (contact/interact.cuh)
/// decides which pairs to evaluate and where the results go.
///
/// Dashpots see the velocities at the time of the positions (v_sync, omega_sync); tangential
/// springs follow the displacement of the last step (v, omega times dt: the velocities that
/// moved the positions). With `OneVelocity` (velocity Verlet) the two are the same, and v,
/// omega are not read a second time. Equations: docs/physics.md.
///
/// A note for code that the host runs in SIMD lanes (this file, the contact laws, the tiles of
/// contact/interact.cuh, integrate/integrate_particles.cuh), so that g++ keeps vectorising it
/// (docs/architecture.md, "Vectorised host loops"): aggregate locals (a vec3, a result struct)
/// initialised by a call or a copy are not declared const, because g++ 12 then keeps them in
/// memory; conditionals on whole structs go through select(); no field is loaded or stored
/// only under a condition.
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../core/constants.cuh"
#include "../particles/state.cuh"
#include "contact_lists.cuh"
#include "law.cuh"
#include "result.cuh"

namespace sphere {
namespace detail {

/// The particles' forces on the six wall faces, along each face's axis (N), summed in double.
struct wall_loads {
    double force[6];
    SPHERE_HDI wall_loads operator+(const wall_loads& b) const
    {
        wall_loads out;
        for (int f = 0; f < 6; ++f) out.force[f] = force[f] + b.force[f];
        return out;
    }
};

/// A pair's separation as the contact law's arithmetic needs it: d = x_i - x_j (the nearest
/// image, m) and the radii (m) in the law's type Real, and, when positions are held in a wider
/// type Coord (precision mixed), the overlap's numerator excess = dist2 - (r_i + r_j)^2 (m^2)
/// formed in that type, where |d| and r_i + r_j still differ in their last digits.
template <class Real>
struct pair_separation {
    vec3<Real> d;
    Real r_i, r_j;
    Real excess; ///< unused (0) when Real is Coord
};

/// The separation of a pair whose positions (type Coord) are d = x_i - x_j apart, dist2 = |d|^2,
/// with radii r_i and r_j.
template <class Real, class Coord>
SPHERE_HDI pair_separation<Real> separation_of(const vec3<Coord>& d, Coord dist2, Coord r_i, Coord r_j)
{
    pair_separation<Real> s;
    s.d = vec_cast<Real>(d);
    s.r_i = Real(r_i);
    s.r_j = Real(r_j);
    const Coord reach = r_i + r_j;
    s.excess = std::is_same_v<Real, Coord> ? Real(0) : Real(dist2 - reach * reach);
    return s;
}

/// The normal overlap-distance delta_n = |d| - reach (m, negative in contact) of a separation
/// s, and the unit normal d / |d|. When positions are held in a wider type Coord than the
/// contact law's (precision mixed), delta_n = excess / (|d| + reach), the difference formed in
/// the wide type: the overlap keeps its relative precision although |d| and reach agree to 1e-5.
template <class Coord, class Real>
SPHERE_HDI Real overlap_and_normal(const pair_separation<Real>& s, vec3<Real>& n)
{
    const Real dist = std::sqrt(norm2(s.d)), reach = s.r_i + s.r_j;
    n = s.d * (Real(1) / dist);
    if constexpr (std::is_same_v<Real, Coord>)
        return dist - reach;
    else
        return s.excess / (dist + reach);
}

/// Whether Law with kernel parameters `params` acts on a pair at squared distance dist2 (m^2)
/// whose radii sum to reach (m): distinct centres that overlap, or for a law that acts apart
/// (contact/law.cuh) lie within its range of touching.
template <class Law, class KernelParams, class Coord>
SPHERE_HDI bool law_acts(const KernelParams& params, Coord dist2, Coord reach)
{
    const Coord cut = acts_apart<Law>::value ? reach + law_range<Law, Coord>(params) : reach;
    return dist2 < cut * cut && dist2 > Coord(0);
}

/// The separation s of particles at xi and xj (centre in xyz, radius in w; type Coord) in the
/// world box, the nearest image, and whether Law with kernel parameters `params` acts on them
/// (law_acts). s is filled either way, so that callers can sort pairs without a branch.
/// Without `Image`, x_i - x_j itself: for an owner whose acting partners cannot lie across a
/// periodic face (pair_contact::images_inside), the same verdict, and for a pair that acts
/// the same bits.
template <class Law, bool Image = true, class Real, class KernelParams, class Coord>
SPHERE_HDI bool separate(const KernelParams& params, const world<Coord>& box, const vec4<Coord>& xi,
                         const vec4<Coord>& xj, pair_separation<Real>& s)
{
    const vec3<Coord> d = Image ? box.nearest_image_inside(xi.xyz() - xj.xyz()) : xi.xyz() - xj.xyz();
    const Coord dist2 = norm2(d);
    s = separation_of<Real>(d, dist2, xi.w, xj.w);
    return law_acts<Law>(params, dist2, xi.w + xj.w);
}

/// Fills the geometry g of the contact of particles i and j of p (masses m_i and m_j), as seen
/// by i, from their separation s; with `Materials` (a law that tells materials apart,
/// contact/law.cuh) their material indices too, else 0.
template <bool Materials, class P>
SPHERE_HDI void pair_geometry(contact_geometry<real_t<P>>& g, const particle_view<P>& p, std::size_t i, std::size_t j,
                              const pair_separation<real_t<P>>& s, real_t<P> m_i, real_t<P> m_j)
{
    g.delta_n = overlap_and_normal<coord_t<P>>(s, g.n);
    g.r_i = s.r_i;
    g.r_j = s.r_j;
    g.r_eff = g.r_i * g.r_j / (g.r_i + g.r_j);
    g.m_i = m_i;
    g.m_j = m_j;
    g.m_eff = g.m_i * g.m_j / (g.m_i + g.m_j);
    g.material_i = Materials ? p.material[i] : 0u;
    g.material_j = Materials ? p.material[j] : 0u;
}

/// Fills the geometry g of particle i's contact with wall face f (unit normal n into the
/// world, overlap delta_n, m) as seen by i: the wall has r_j = m_j = 0, and material_j = f.
template <bool Materials, class P>
SPHERE_HDI void wall_geometry(contact_geometry<real_t<P>>& g, const particle_view<P>& p, std::size_t i, int f,
                              const vec3<real_t<P>>& n, real_t<P> delta_n)
{
    using Real = real_t<P>;
    g.n = n;
    g.delta_n = delta_n;
    g.r_i = g.r_eff = Real(p.x[i].w);
    g.r_j = Real(0);
    g.m_i = g.m_eff = p.mass[i];
    g.m_j = Real(0);
    g.material_i = Materials ? p.material[i] : 0u;
    g.material_j = static_cast<unsigned>(f);
}

/// What a pair contact reads of particle i's motion, from p: its velocity (m/s) and angular
/// velocity (rad/s) at the positions' time (v_sync, omega_sync), and its mass (kg). Read
/// where the law needs them, as the law's own loads would be (a copy into a struct first made
/// g++ vectorise the host's tiles worse in double: docs/performance.md, *Records in float*).
template <class P>
struct stored_motion {
    const particle_view<P>& p;
    std::size_t i;
    SPHERE_HDI vec3<real_t<P>> v() const { return p.v_sync[i]; }
    SPHERE_HDI vec3<real_t<P>> omega() const { return p.omega_sync[i]; }
    SPHERE_HDI real_t<P> mass() const { return p.mass[i]; }
};

/// One evaluated pair contact, for its owner i and its partner j.
template <class Real>
struct pair_result {
    vec3<Real> force{0, 0, 0};    ///< contact force on i (N); j feels -force
    vec3<Real> torque_i{0, 0, 0}; ///< torque on i (N m)
    vec3<Real> torque_j{0, 0, 0}; ///< torque on j (N m)
    Real fn = 0;                  ///< |f_n| (N)
    Real visc_rate = 0;           ///< viscous dissipation of the contact, normal + tangential (W)
    Real fric_rate = 0;           ///< frictional dissipation of the contact (W)
    vec4<Real> record{0, 0, 0, 0}; ///< f_t on i (N) in xyz, f_n . n (N) in w: the recorded contact force
};

/// Evaluates pair contacts of the particles p: positions, the world and the walls in
/// coord_t<P>, everything the contact law sees in real_t<P>.
template <class P, class Law, bool OneVelocity>
struct pair_contact {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    world<Coord> box;
    typename Law::template kernel_params<Real> params;
    Real dt;
    /// the largest radius plus the law's range (m): no pair acts whose centres lie farther apart
    /// than r_i + partner_reach
    Coord partner_reach;
    using history_type = law_history_t<Law, Real>;
    static constexpr bool materials = law_material_count<Law>::value > 1;

    /// Whether particle i at xi (centre in xyz, radius in w) has no partner the law can act on
    /// across a periodic face of the box: on each periodic axis it lies farther than
    /// r_i + partner_reach (and a sixteenth more, for rounding) from both faces. Then an acting
    /// partner's nearest image lies inside the box, where its (wrapped) position is, so that
    /// x_i - x_j is its separation to the bit, and every other pair, whose images are all
    /// farther than the nearest, stays apart: separate<Law, false> gives the same verdicts
    /// without the nearest image (docs/architecture.md, *Interaction*).
    SPHERE_HDI bool images_inside(const vec4<Coord>& xi) const
    {
        const Coord margin = (xi.w + partner_reach) * Coord(17) / Coord(16);
        bool inside = true;
        for (int a = 0; a < 3; ++a)
            inside = inside && (!box.periodic(a) || (xi.xyz()[a] - box.lo[a] > margin && box.hi[a] - xi.xyz()[a] > margin));
        return inside;
    }

    /// The separation s of particles at xi and xj (p.x) and whether the law acts on them:
    /// distinct centres that overlap, or for a law that acts apart (contact/law.cuh) lie
    /// within its range of touching.
    SPHERE_HDI bool separate(const vec4<Coord>& xi, const vec4<Coord>& xj, pair_separation<Real>& s) const
    {
        return sphere::detail::separate<Law>(params, box, xi, xj, s);
    }

    /// The contact of i (owner) and j (slots) with history h (updated): both particles'
    /// share, or zero when the law does not act on them (separate()), which also resets the
    /// history.
    SPHERE_HDI pair_result<Real> evaluate(std::size_t i, std::size_t j, history_type& h) const
    {
        pair_separation<Real> s;
        if (!separate(p.x[i], p.x[j], s)) {
            h = history_type{}; // a contact that has ended forgets its history
            return {};
        }
        return evaluate_touching(i, j, s, h);
    }

    /// The contact of i (owner) and j with separation s, on which the law acts (separate()), with
    /// history h (updated): both particles' share. For callers that have the separation already
    /// (the SIMD tiles of contact/interact.cuh).
    SPHERE_HDI pair_result<Real> evaluate_touching(std::size_t i, std::size_t j, const pair_separation<Real>& s,
                                                   history_type& h) const
    {
        return evaluate_moving(i, j, stored_motion<P>{p, i}, stored_motion<P>{p, j}, s, h);
    }

    /// evaluate_touching with the particles' motions read from mi and mj (stored_motion's
    /// interface): the host's tiles move them into the lanes as records in float
    /// (contact/interact.cuh).
    template <class MotionI, class MotionJ>
    SPHERE_HDI pair_result<Real> evaluate_moving(std::size_t i, std::size_t j, const MotionI& mi, const MotionJ& mj,
                                                 const pair_separation<Real>& s, history_type& h) const
    {
        contact_motion<Real> m;
        pair_geometry<materials>(m, p, i, j, s, mi.mass(), mj.mass());
        vec3<Real> n = m.n; // not const: see the note at the top
        const Real arm_i = s.r_i + m.delta_n / 2, arm_j = s.r_j + m.delta_n / 2;
        m.velocity = mi.v() - mj.v() + arm_i * cross(n, mi.omega()) + arm_j * cross(n, mj.omega());
        m.step = OneVelocity ? m.velocity * dt
                             : (p.v[i] - p.v[j]) * dt + arm_i * cross(n, p.omega[i] * dt) +
                                   arm_j * cross(n, p.omega[j] * dt);
        m.spin = mi.omega() - mj.omega();
        m.spin_step = OneVelocity ? m.spin * dt : (p.omega[i] - p.omega[j]) * dt;
        history_type updated = h;
        contact_result<Real> c = Law::pair(params, m, updated, dt);
        vec3<Real> lever = cross(n, c.tangential);
        pair_result<Real> r;
        r.force = c.normal + c.tangential;
        r.torque_i = c.couple - arm_i * lever;
        r.torque_j = -c.couple - arm_j * lever;
        r.fn = c.fn;
        r.visc_rate = c.visc_rate;
        r.fric_rate = c.fric_rate;
        r.record = {c.tangential.x, c.tangential.y, c.tangential.z, dot(c.normal, n)};
        h = updated;
        return r;
    }
};

/// The wall contacts of a particle that has some: the wall entries at the end of its row in
/// the contact lists (one index per entry of contact_lists::wall_ranks, the ranks of such
/// particles). Adds their forces and torques to the particle's, with `Book` their |f_n| and
/// dissipation rates to its audit sums (completed by finish_audit), with `Record` stores each
/// entry's force; returns the particle's loads on the walls.
template <class P, class Law, bool Book, bool Record, bool OneVelocity>
struct wall_contacts {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    contact_view<Real> c;
    const unsigned* ranks; ///< contact_lists::wall_ranks
    wall_set<Coord> walls;
    typename Law::template kernel_params<Real> params;
    Real dt;
    bool update_history; ///< false for a force evaluation that must leave the contacts as they are
    static constexpr bool materials = law_material_count<Law>::value > 1;

    SPHERE_HD wall_loads operator()(std::size_t k) const
    {
        wall_loads loads{{0, 0, 0, 0, 0, 0}};
        if (ranks[k] == no_rank) return loads; // past the ranks with walls (a launch over all ranks)
        const std::size_t r = ranks[k], i = c.slot(r);
        const unsigned first = c.offset[r];
        const vec4<Coord> xi = p.x[i];
        const vec3<Real> vi = p.v_sync[i], wi = p.omega_sync[i];
        const vec3<Real> si = OneVelocity ? vec3<Real>{0, 0, 0} : p.v[i] * dt;
        const vec3<Real> ti = OneVelocity ? vec3<Real>{0, 0, 0} : p.omega[i] * dt;
        vec3<Real> force = p.force[i], torque = p.torque[i];
        Real fn_sum = 0, visc = 0, fric = 0;
        for (unsigned e = c.offset[r + 1]; e > first && c.partner[e - 1] >= wall_partner_base; --e) {
            const unsigned k = e - 1;
            const int f = static_cast<int>(c.partner[k] - wall_partner_base);
            // The face's fields by constant indices (SPHERE_UNROLL) and the axis's components
            // by selects: run-time indexing would put this kernel's parameters in local memory
            // on CUDA.
            double position = 0, wall_velocity = 0;
            SPHERE_UNROLL
            for (int g = 0; g < wall_set<Coord>::count; ++g) {
                position = g == f ? walls.face[g].position : position;
                wall_velocity = g == f ? walls.face[g].velocity : wall_velocity;
            }
            const int a = f / 2;
            const vec3<Real> n = wall_set<Real>::inward_normal(f);
            const Coord dist_c = (component(xi.xyz(), a) - Coord(position)) * Coord(component(n, a));
            const Real dist = Real(dist_c), delta_n = Real(dist_c - xi.w);
            law_history_t<Law, Real> h;
            c.history.load(k, h);
            if (delta_n < Real(0)) {
                contact_motion<Real> m;
                wall_geometry<materials>(m, p, i, f, n, delta_n);
                m.velocity = vi + dist * cross(n, wi);
                m.step = si + dist * cross(n, ti);
                m.spin = wi;
                m.spin_step = OneVelocity ? wi * dt : ti;
                m.velocity -= along_axis(a, Real(wall_velocity)); // 0 subtracted on the other axes
                if (OneVelocity) m.step = m.velocity * dt;
                else m.step -= along_axis(a, Real(wall_velocity) * dt);
                contact_result<Real> r = Law::wall(params, m, h, dt);
                const double load = -double(component(r.normal, a) + component(r.tangential, a));
                SPHERE_UNROLL
                for (int g = 0; g < wall_set<Coord>::count; ++g) loads.force[g] = g == f ? load : loads.force[g];
                force += r.normal + r.tangential;
                torque += r.couple - dist * cross(n, r.tangential);
                if (Book) {
                    fn_sum += r.fn;
                    visc += r.visc_rate;
                    fric += r.fric_rate;
                }
                if (Record) c.force[k] = {r.tangential.x, r.tangential.y, r.tangential.z, dot(r.normal, n)};
            } else {
                h = law_history_t<Law, Real>{}; // a contact that has ended forgets its history
                if (Record) c.force[k] = vec4<Real>{0, 0, 0, 0};
            }
            if (update_history) c.history.store(k, h);
        }
        p.force[i] = force;
        p.torque[i] = torque;
        if (Book) {
            p.pressure[i] += fn_sum;
            p.p_visc[i] += visc;
            p.p_fric[i] += fric;
        }
        return loads;
    }
};

/// Completes the energy audit of particle i once its contacts are summed: the sum of |f_n|
/// becomes a pressure over the surface, 4 pi r^2 (Pa), and the step's dissipation rates are
/// booked as energies (J).
template <class P>
struct finish_audit {
    using Real = real_t<P>;
    particle_view<P> p;
    Real dt;
    SPHERE_HDI void operator()(std::size_t i) const
    {
        const Real r = Real(p.x[i].w);
        p.pressure[i] = p.pressure[i] / (4 * pi<Real> * r * r);
        p.e_visc[i] += p.p_visc[i] * dt;
        p.e_fric[i] += p.p_fric[i] * dt;
    }
};

} // namespace detail
} // namespace sphere
