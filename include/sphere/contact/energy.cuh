#pragma once
/// \file
/// Energy and momentum diagnostics (docs/physics.md, "Energy budget"), from the velocities at
/// the time of the positions.
#include <cstddef>

#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../particles/state.cuh"
#include "contact_lists.cuh"
#include "evaluate.cuh"
#include "law.cuh"
#include "result.cuh"

namespace sphere {

/// Energies of the whole assembly (J) and dissipation rates (W).
template <class Real>
struct energy_budget {
    Real kinetic = 0;         ///< sum m |v|^2 / 2
    Real rotational = 0;      ///< sum I |omega|^2 / 2, I = 2/5 m r^2
    Real potential = 0;       ///< sum -m g . x (zero at the origin)
    Real elastic = 0;         ///< energy stored in the contact springs, normal and tangential
    Real dissipated_visc = 0; ///< total viscous dissipation so far (the bonds' dashpots' too)
    Real dissipated_fric = 0; ///< total frictional dissipation so far
    Real rate_visc = 0;       ///< viscous dissipation rate in the last step
    Real rate_fric = 0;       ///< frictional dissipation rate in the last step
    Real boundary_work = 0;   ///< work done on the particles by moving walls so far
    Real bond_elastic = 0;    ///< energy stored in the intact bonds (the seeds' 'bondpot')
    Real bond_broken = 0;     ///< elastic energy the bonds held when they broke, lost with them

    /// Mechanical energy plus everything dissipated, less the work the walls did: constant.
    SPHERE_HD Real total() const
    {
        return kinetic + rotational + potential + elastic + bond_elastic + dissipated_visc + dissipated_fric +
               bond_broken - boundary_work;
    }

    SPHERE_HD energy_budget operator+(const energy_budget& b) const
    {
        return {kinetic + b.kinetic,
                rotational + b.rotational,
                potential + b.potential,
                elastic + b.elastic,
                dissipated_visc + b.dissipated_visc,
                dissipated_fric + b.dissipated_fric,
                rate_visc + b.rate_visc,
                rate_fric + b.rate_fric,
                boundary_work + b.boundary_work,
                bond_elastic + b.bond_elastic,
                bond_broken + b.bond_broken};
    }
};

namespace detail {

/// Particle i's share of the energy budget: its own energies, its dissipation, the elastic
/// energy of the pair contacts it owns in the contact lists and of its wall contacts. Summed
/// in coord_t<P>, the user-facing type; overlaps formed as in the interaction.
template <class P, class Law>
struct particle_energy {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    particle_view<P> p;
    contact_view<Real> c;
    world<Coord> box;
    wall_set<Coord> walls;
    typename Law::template kernel_params<Real> pair_params;
    typename Law::template kernel_params<Real> wall_params;
    vec3<Coord> gravity;
    static constexpr bool materials = law_material_count<Law>::value > 1;

    SPHERE_HD energy_budget<Coord> operator()(std::size_t i) const
    {
        const vec4<Coord> xi = p.x[i];
        const Coord m = p.mass[i];
        energy_budget<Coord> e;
        e.kinetic = Coord(0.5) * m * Coord(norm2(p.v_sync[i]));
        e.rotational = Coord(0.2) * m * xi.w * xi.w * Coord(norm2(p.omega_sync[i]));
        e.potential = -m * dot(gravity, xi.xyz());
        const std::size_t r = c.rank(i);
        // the near row's partners, the far row's, then the near row's walls
        const unsigned walls_from = c.for_each_pair(r, [&](unsigned k, unsigned j) {
            pair_separation<Real> s;
            if (!separate<Law>(pair_params, box, xi, p.x[j], s)) return;
            contact_geometry<Real> g;
            pair_geometry<materials>(g, p, i, j, s, p.mass[i], p.mass[j]);
            law_history_t<Law, Real> h{}; // a far row's entry without a history has none
            if (c.has_history(k)) c.history.load(k, h);
            e.elastic += Coord(Law::pair_energy(pair_params, g, h));
        });
        for (unsigned k = walls_from; k < c.offset[r + 1]; ++k) {
            const int f = static_cast<int>(c.partner[k] - wall_partner_base);
            const int a = f / 2;
            const vec3<Real> n = wall_set<Real>::inward_normal(f);
            contact_geometry<Real> g;
            wall_geometry<materials>(g, p, i, f, n, Real((xi.xyz()[a] - Coord(walls.face[f].position)) * Coord(n[a]) - xi.w));
            law_history_t<Law, Real> h;
            c.history.load(k, h);
            if (g.delta_n < Real(0)) e.elastic += Coord(Law::wall_energy(wall_params, g, h));
        }
        if (p.e_visc) { // the energy audit is on
            e.dissipated_visc = p.e_visc[i];
            e.dissipated_fric = p.e_fric[i];
            e.rate_visc = p.p_visc[i];
            e.rate_fric = p.p_fric[i];
        }
        return e;
    }
};

template <class P>
struct particle_momentum {
    particle_view<P> p;
    SPHERE_HD vec3<coord_t<P>> operator()(std::size_t i) const
    {
        return vec_cast<coord_t<P>>(p.v_sync[i] * p.mass[i]);
    }
};

} // namespace detail
} // namespace sphere
