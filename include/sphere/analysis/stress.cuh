#pragma once
/// \file
/// Stresses and the contact network: the normal stress on a wall, the stress tensor of the
/// assembly by the Love-Weber sum over contacts, coordination numbers, and the list of
/// contacts with their forces (sphere's forcechains). Host-side functions on host copies of
/// the particles and contact lists (contact_snapshot), computed in double. Stresses are
/// compressive positive, like the wall controls' target stresses.
#include <cmath>
#include <cstddef>
#include <vector>

#include "../boundary/wall_control.cuh"
#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../simulation.cuh"

namespace sphere {

/// Normal stress (Pa) of the particles on wall face f, compressive positive: the force they
/// exert on it along its axis in the last step, against its inward normal, over its current
/// area (wall_area). Throws for a face out of range or on a periodic axis.
template <class Real>
double wall_normal_stress(const wall_set<Real>& walls, const world<Real>& box, int f)
{
    if (f < 0 || f >= wall_set<Real>::count) detail::fail("wall_normal_stress: face ", f, " out of range [0, 6)");
    if (!walls.face[f].active)
        detail::fail("wall_normal_stress: face ", f, " lies on periodic axis ", f / 2, " and is not a wall");
    const double inward = f % 2 == 0 ? 1.0 : -1.0;
    return -double(walls.face[f].force) * inward / wall_area(walls, box, f);
}

/// Normal stress (Pa) on wall face f of a simulation, compressive positive.
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
double wall_normal_stress(const simulation<P, Policy, Law, Integrator>& sim, int f)
{
    return wall_normal_stress(sim.walls(), sim.config().box, f);
}

/// Host copies of what the contact analyses need.
template <class Real>
struct contact_snapshot {
    std::vector<vec4<Real>> x;   ///< centre (m) in xyz, radius (m) in w
    contact_table<Real> table;   ///< the contact lists in user order, with each entry's force
    world<Real> box;             ///< the world (periodic axes for nearest images)
    wall_set<Real> walls;        ///< the walls, with their positions

    /// Number of particles.
    std::size_t size() const { return x.size(); }
    /// Whether entry e carries a force (a contact that touched in the last step).
    bool touching(std::size_t e) const
    {
        const vec4<Real>& f = table.force[e];
        return f.x != Real(0) || f.y != Real(0) || f.z != Real(0) || f.w != Real(0);
    }
    /// Whether a partner code names a wall face.
    static bool is_wall(unsigned partner) { return partner >= wall_partner_base; }
    /// The whole force (N) of wall entry e on its particle: friction plus normal.
    vec3<Real> wall_force(std::size_t e) const
    {
        const vec4<Real>& f = table.force[e];
        return f.xyz() + wall_set<Real>::inward_normal(int(table.partner[e] - wall_partner_base)) * f.w;
    }
};

/// Copies the particles, contact lists and walls of a simulation to the host. The forces are
/// those of the last step, the positions those after it: the analyses below are exact for a
/// static assembly. Throws when the simulation records no contact forces
/// (settings.contact_forces = false).
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
contact_snapshot<Real> take_contact_snapshot(const simulation<P, Policy, Law, Integrator>& sim)
{
    if (!sim.config().contact_forces)
        detail::fail("contact analyses need the contact forces: the simulation was set up with settings.contact_forces = false");
    contact_snapshot<Real> c;
    c.x = sim.positions();
    c.table = sim.contacts();
    c.box = sim.config().box;
    c.walls = sim.walls();
    return c;
}

/// A 3x3 tensor (Pa), s[i][j].
struct stress_tensor {
    double s[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}; ///< components (Pa), row i, column j
    /// Component ij (Pa).
    double operator()(int i, int j) const { return s[i][j]; }
    /// Mean normal stress, trace / 3 (Pa).
    double mean() const { return (s[0][0] + s[1][1] + s[2][2]) / 3; }
};

/// Volume (m^3) between the walls: current wall distance on wall axes, period on periodic ones.
template <class Real>
double volume_between_walls(const wall_set<Real>& walls, const world<Real>& box)
{
    double v = 1;
    for (int a = 0; a < 3; ++a)
        v *= box.periodic(a) ? double(box.length(a))
                             : double(walls.face[2 * a + 1].position) - double(walls.face[2 * a].position);
    return v;
}

/// Stress tensor of the assembly by the Love-Weber sum over contacts, compressive positive:
///
///     sigma_ij = -(1/V) sum_c f_i^c l_j^c
///
/// with f^c the force on a particle at contact c and l^c the branch vector from its centre to
/// the contact point, summed over both particles of every pair and over the particles' wall
/// contacts. A pair's two terms add up to f (on i) times the centre-to-centre vector
/// x_j - x_i (nearest periodic image), so each listed entry (every pair appears once from each
/// side) contributes half of that. A wall contact has its branch vector from the centre to the
/// wall plane along the wall's axis, and its whole force (normal and friction) counts. In a
/// static assembly without body forces, sigma_aa equals the walls' normal stress on a wall
/// axis.
/// V (m^3) must be positive.
template <class Real>
stress_tensor love_weber_stress(const contact_snapshot<Real>& c, double volume)
{
    if (!(volume > 0) || !std::isfinite(volume))
        detail::fail("love_weber_stress: volume = ", volume, " m^3 must be positive and finite");
    stress_tensor t;
    for (std::size_t i = 0; i < c.size(); ++i) {
        const vec3<Real> xi = c.x[i].xyz();
        for (std::size_t e = c.table.begin(i); e < c.table.end(i); ++e) {
            if (!c.touching(e)) continue;
            if (c.is_wall(c.table.partner[e])) {
                // branch vector from the centre to the wall plane, along the wall's axis
                const int f = int(c.table.partner[e] - wall_partner_base), a = f / 2;
                const vec3<Real> fw = c.wall_force(e);
                const double l = double(c.walls.face[f].position) - double(xi[a]);
                for (int b = 0; b < 3; ++b) t.s[b][a] -= double(fw[b]) * l;
                continue;
            }
            const vec3<Real> d = c.box.nearest_image(xi - c.x[c.table.partner[e]].xyz()); // x_i - x_j
            const double dist = double(norm(d));
            if (!(dist > 0)) continue;
            const vec3<Real> ft = c.table.force[e].xyz();
            double f[3], l[3];
            for (int a = 0; a < 3; ++a) {
                const double n = double(d[a]) / dist; // from j towards i
                f[a] = double(ft[a]) + double(c.table.force[e].w) * n;
                l[a] = -double(d[a]); // x_j - x_i
            }
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) t.s[a][b] -= f[a] * l[b] / 2;
        }
    }
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) t.s[a][b] /= volume;
    return t;
}

/// Love-Weber stress of a simulation over the volume between its walls.
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
stress_tensor love_weber_stress(const simulation<P, Policy, Law, Integrator>& sim)
{
    const contact_snapshot<Real> c = take_contact_snapshot(sim);
    return love_weber_stress(c, volume_between_walls(c.walls, c.box));
}

/// Love-Weber stress of a simulation over a given volume (m^3).
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
stress_tensor love_weber_stress(const simulation<P, Policy, Law, Integrator>& sim, double volume)
{
    return love_weber_stress(take_contact_snapshot(sim), volume);
}

/// Number of contacts of each particle that carried a force in the last step: its touching
/// pair contacts, plus its wall contacts when `with_walls`.
template <class Real>
std::vector<unsigned> contact_counts(const contact_snapshot<Real>& c, bool with_walls = false)
{
    std::vector<unsigned> z(c.size(), 0u);
    for (std::size_t i = 0; i < c.size(); ++i) {
        for (std::size_t e = c.table.begin(i); e < c.table.end(i); ++e)
            if (c.touching(e) && (with_walls || !c.is_wall(c.table.partner[e]))) ++z[i];
    }
    return z;
}

/// Mean coordination number: touching contacts per particle, each pair counted once from
/// each side (2 pairs / N), plus wall contacts when `with_walls`.
template <class Real>
double mean_coordination(const contact_snapshot<Real>& c, bool with_walls = false)
{
    if (c.size() == 0) return 0;
    double sum = 0;
    for (unsigned z : contact_counts(c, with_walls)) sum += z;
    return sum / double(c.size());
}

/// Mean coordination number of a simulation's particles.
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
double mean_coordination(const simulation<P, Policy, Law, Integrator>& sim, bool with_walls = false)
{
    return mean_coordination(take_contact_snapshot(sim), with_walls);
}

/// One touching pair of the contact network.
struct contact_force {
    std::size_t i = 0, j = 0;       ///< particle indices, i < j
    vec3<double> x_i{0, 0, 0};      ///< centre of i (m)
    vec3<double> x_j{0, 0, 0};      ///< centre of j (m), as stored (inside the period)
    vec3<double> branch{0, 0, 0};   ///< x_j - x_i to the nearest periodic image of j (m)
    double normal = 0;              ///< normal force (N): f_n . n on i, positive when repulsive
    vec3<double> tangential{0, 0, 0}; ///< tangential force on i (N)
};

/// Every pair that carried a force in the last step, once (i < j), with its forces as seen
/// by i: for force-chain plots (segment x_i to x_i + branch, width by `normal`).
template <class Real>
std::vector<contact_force> contact_network(const contact_snapshot<Real>& c)
{
    std::vector<contact_force> out;
    for (std::size_t i = 0; i < c.size(); ++i)
        for (std::size_t e = c.table.begin(i); e < c.table.end(i); ++e) {
            const std::size_t j = c.table.partner[e];
            if (c.is_wall(c.table.partner[e]) || j <= i || !c.touching(e)) continue;
            contact_force p;
            p.i = i;
            p.j = j;
            p.x_i = vec_cast<double>(c.x[i].xyz());
            p.x_j = vec_cast<double>(c.x[j].xyz());
            p.branch = vec_cast<double>(c.box.nearest_image(c.x[j].xyz() - c.x[i].xyz()));
            p.normal = double(c.table.force[e].w);
            p.tangential = {double(c.table.force[e].x), double(c.table.force[e].y), double(c.table.force[e].z)};
            out.push_back(p);
        }
    return out;
}

/// The contact network of a simulation.
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
std::vector<contact_force> contact_network(const simulation<P, Policy, Law, Integrator>& sim)
{
    return contact_network(take_contact_snapshot(sim));
}

} // namespace sphere
