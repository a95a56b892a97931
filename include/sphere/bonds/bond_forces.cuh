#pragma once
/// \file
/// The kernels of the parallel bonds (docs/physics.md, "Bonds"): each bond evaluated once, by
/// itself, into its own results (`bond_forces`), then each particle's bond loads summed from
/// the results of its bonds in a fixed order (`bond_loads`). No two threads write the same
/// value, so the sums are the same bits whatever the thread count; and the energy kernel.
#include <cmath>
#include <cstddef>

#include "../boundary/world.cuh"
#include "../contact/energy.cuh"
#include "../core/config.cuh"
#include "../particles/state.cuh"
#include "bond_params.cuh"

namespace sphere {

/// Raw pointers to the bonds' arrays (bond_set); trivially copyable, handed to kernels by value.
template <class P>
struct bond_view {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    std::size_t count;
    const unsigned* ends;   ///< user indices of bond k's particles i and j at 2k and 2k + 1
    const Coord* rest;      ///< rest length (m)
    vec4<Real>* shear;      ///< shear displacement (m) in xyz, twist angle (rad) in w
    vec3<Real>* bend;       ///< bending rotation (rad)
    unsigned* broken;       ///< 1 once broken
    Real* released;         ///< elastic energy held when it broke (J)
    Real* dissipated;       ///< energy dissipated by its dashpots (J); null without the energy audit
    Real* rate;             ///< its dashpots' power in the last step (W); null without the energy audit
    vec3<Real>* force;      ///< the last evaluation's force on i (N)
    vec3<Real>* torque_i;   ///< and torque on i (N m)
    vec3<Real>* torque_j;   ///< and torque on j (N m)
    unsigned* slot_of;      ///< the storage slot of each user index
    const unsigned* first;  ///< per user index u, its entries in `entries` from first[u] to first[u + 1]
    const unsigned* entries; ///< 2 k for bond k's particle i, 2 k + 1 for its j, by user index, bonds in order
};

namespace detail {

/// v turned into the plane normal to n, keeping its length (a rigid rotation of the pair turns
/// the stored displacement with it).
template <class Real>
SPHERE_HDI vec3<Real> onto_plane(const vec3<Real>& v, const vec3<Real>& n)
{
    const vec3<Real> in_plane = v - n * dot(n, v);
    const Real before = norm2(v), after = norm2(in_plane);
    return after > Real(0) ? in_plane * std::sqrt(before / after) : in_plane;
}

/// Bond k's particles as stored now: their slots i and j, positions and radii, and the distance
/// of their centres (m; the nearest image) with the unit vector from j to i.
template <class P>
struct bond_ends {
    using Coord = coord_t<P>;
    std::size_t i, j;
    vec4<Coord> xi, xj;
    Coord dist;
    vec3<real_t<P>> n;

    SPHERE_HDI bond_ends(const particle_view<P>& p, const bond_view<P>& b, const world<Coord>& box, std::size_t k)
        : i(b.slot_of[b.ends[2 * k]]), j(b.slot_of[b.ends[2 * k + 1]]), xi(p.x[i]), xj(p.x[j])
    {
        const vec3<Coord> d = box.nearest_image_inside(xi.xyz() - xj.xyz());
        dist = std::sqrt(norm2(d));
        n = vec_cast<real_t<P>>(d * (Coord(1) / dist));
    }
};

/// slot_of[user[k]] = k, after the particles moved to other slots.
template <class P>
struct locate_bond_ends {
    particle_view<P> p;
    unsigned* slot_of;
    SPHERE_HD void operator()(std::size_t k) const { slot_of[p.user[k]] = static_cast<unsigned>(k); }
};

/// Evaluates bond k: with `update`, advances its shear, twist and bending by the step that led
/// to the positions (as a tangential contact spring, contact/evaluate.cuh) and breaks it when
/// its largest tensile stress exceeds the tensile strength or its largest shear stress the
/// shear strength; stores its loads on both particles. `OneVelocity` as in pair_contact;
/// `Book` keeps its dashpots' power and dissipated energy.
template <class P, bool OneVelocity, bool Book>
struct bond_forces {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    bond_view<P> b;
    world<Coord> box;
    bond_params<Real> params;
    Real dt;
    bool update; ///< false: the loads of the state as it is (a force evaluation that changes nothing)

    SPHERE_HD void operator()(std::size_t k) const
    {
        const vec3<Real> zero{0, 0, 0};
        if (b.broken[k]) {
            b.force[k] = b.torque_i[k] = b.torque_j[k] = zero;
            if (Book) b.rate[k] = 0;
            return;
        }
        const bond_ends<P> at(p, b, box, k);
        const std::size_t i = at.i, j = at.j;
        const vec4<Coord> xi = at.xi, xj = at.xj;
        const vec3<Real> n = at.n; // from j towards i
        const Real stretch = Real(at.dist - b.rest[k]), gap = Real(at.dist - (xi.w + xj.w));
        const Real r_i = Real(xi.w), r_j = Real(xj.w);
        const Real arm_i = r_i + gap / 2, arm_j = r_j + gap / 2; // to the bond's centre
        const vec3<Real> velocity =
            p.v_sync[i] - p.v_sync[j] + arm_i * cross(n, p.omega_sync[i]) + arm_j * cross(n, p.omega_sync[j]);
        const vec3<Real> spin = p.omega_sync[i] - p.omega_sync[j];
        const bond_springs<Real> s = bond_springs<Real>::make(params, r_i, r_j, p.mass[i], p.mass[j]);
        const vec4<Real> stored = b.shear[k];
        vec3<Real> shear = stored.xyz(), bend = b.bend[k];
        Real twist = stored.w;
        if (update) {
            const vec3<Real> step = OneVelocity ? velocity * dt
                                                : (p.v[i] - p.v[j]) * dt + arm_i * cross(n, p.omega[i] * dt) +
                                                      arm_j * cross(n, p.omega[j] * dt);
            const vec3<Real> turn = OneVelocity ? spin * dt : (p.omega[i] - p.omega[j]) * dt;
            shear = onto_plane(shear, n) + (step - n * dot(n, step));
            bend = onto_plane(bend, n) + (turn - n * dot(n, turn));
            twist += dot(n, turn);
        }
        const Real tension = s.k_n * stretch; // > 0 pulls the particles together
        const vec3<Real> shear_force = -s.k_t * shear, bending = -s.k_b * bend;
        const Real twisting = -s.k_w * twist;
        if (update) {
            const Real sigma = tension / s.area + norm(bending) * s.radius / s.inertia;
            const Real tau = norm(shear_force) / s.area + std::fabs(twisting) * s.radius / s.polar;
            if (sigma > params.tensile_strength || tau > params.shear_strength) {
                b.broken[k] = 1;
                b.released[k] = Real(0.5) * (s.k_n * stretch * stretch + s.k_t * norm2(shear) + s.k_b * norm2(bend) +
                                             s.k_w * twist * twist);
                b.force[k] = b.torque_i[k] = b.torque_j[k] = zero;
                if (Book) b.rate[k] = 0;
                return;
            }
            b.shear[k] = {shear.x, shear.y, shear.z, twist};
            b.bend[k] = bend;
        }
        const Real vn = dot(n, velocity), wn = dot(n, spin);
        const vec3<Real> vt = velocity - n * vn, wt = spin - n * wn;
        const vec3<Real> tangential = shear_force - s.c_t * vt;
        const vec3<Real> couple = n * (twisting - s.c_w * wn) + bending - s.c_b * wt;
        const vec3<Real> lever = cross(n, tangential);
        b.force[k] = n * (-tension - s.c_n * vn) + tangential;
        b.torque_i[k] = couple - arm_i * lever;
        b.torque_j[k] = -couple - arm_j * lever;
        if (Book) {
            const Real power = s.c_n * vn * vn + s.c_t * norm2(vt) + s.c_w * wn * wn + s.c_b * norm2(wt);
            b.rate[k] = power;
            if (update) b.dissipated[k] += power * dt;
        }
    }
};

/// The bond loads of the particle in slot i, summed over its bonds in their order, plus its
/// external force when there is one: the force and torque the integrator adds to the contacts'.
template <class P>
struct bond_loads {
    using Real = real_t<P>;
    particle_view<P> p;
    bond_view<P> b;
    const vec3<Real>* external; ///< external forces by slot, or null
    vec3<Real>* force;
    vec3<Real>* torque;

    SPHERE_HD void operator()(std::size_t i) const
    {
        const unsigned u = p.user[i];
        vec3<Real> f = external ? external[i] : vec3<Real>{0, 0, 0}, t{0, 0, 0};
        for (unsigned e = b.first[u]; e < b.first[u + 1]; ++e) {
            const unsigned k = b.entries[e] >> 1;
            if (b.entries[e] & 1u) {
                f -= b.force[k];
                t += b.torque_j[k];
            } else {
                f += b.force[k];
                t += b.torque_i[k];
            }
        }
        force[i] = f;
        torque[i] = t;
    }
};

/// Bond k's share of the energy budget: its elastic energy (0 once broken), the energy it
/// released when it broke and its dashpots' dissipation (J, W).
template <class P>
struct bond_energy {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    bond_view<P> b;
    world<Coord> box;
    bond_params<Real> params;

    SPHERE_HD energy_budget<Coord> operator()(std::size_t k) const
    {
        energy_budget<Coord> e;
        e.bond_broken = Coord(b.released[k]);
        if (b.dissipated) {
            e.dissipated_visc = Coord(b.dissipated[k]);
            e.rate_visc = Coord(b.rate[k]);
        }
        if (b.broken[k]) return e;
        const bond_ends<P> at(p, b, box, k);
        const Real stretch = Real(at.dist - b.rest[k]);
        const bond_springs<Real> s =
            bond_springs<Real>::make(params, Real(at.xi.w), Real(at.xj.w), p.mass[at.i], p.mass[at.j]);
        const vec4<Real> shear = b.shear[k];
        const vec3<Real> bend = b.bend[k];
        e.bond_elastic = Coord(Real(0.5) * (s.k_n * stretch * stretch + s.k_t * norm2(shear.xyz()) +
                                            s.k_b * norm2(bend) + s.k_w * shear.w * shear.w));
        return e;
    }
};

/// 1 for a broken bond (a count by reduction).
struct broken_bond {
    const unsigned* broken;
    SPHERE_HD std::size_t operator()(std::size_t k) const { return broken[k]; }
};

} // namespace detail
} // namespace sphere
