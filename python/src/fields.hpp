#pragma once
// A simulation's fields as dictionaries of NumPy arrays (copies, in user order), which
// python/sphere/fields.py wraps in Snapshot, Walls, Contacts and Energy.
#include "common.hpp"

namespace sphere_python {

/// Every particle field (particle_snapshot), in user order.
template <class Real>
py::dict snapshot_of(const sphere::particle_snapshot<Real>& s)
{
    std::vector<sphere::vec3<Real>> positions(s.size());
    std::vector<Real> radii(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        positions[i] = s.position(i);
        radii[i] = s.radius(i);
    }
    py::dict d;
    d["positions"] = rows(positions);
    d["radii"] = column(radii);
    d["velocities"] = rows(s.v_sync);
    d["angular_velocities"] = rows(s.omega_sync);
    d["integrator_velocities"] = rows(s.v);
    d["integrator_angular_velocities"] = rows(s.omega);
    d["angular_positions"] = rows(s.angpos);
    d["displacements"] = rows(s.displacement);
    d["forces"] = rows(s.force);
    d["torques"] = rows(s.torque);
    d["masses"] = column(s.mass);
    d["pressures"] = column(s.pressure);
    d["dissipated_viscous"] = column(s.e_visc);
    d["dissipated_friction"] = column(s.e_fric);
    d["power_viscous"] = column(s.p_visc);
    d["power_friction"] = column(s.p_fric);
    d["kinds"] = column(s.kind);
    d["materials"] = column(s.material);
    return d;
}

/// The six wall faces and their controls' modes.
template <class Real>
py::dict walls_of(const sphere::wall_set<Real>& w, const sphere::wall_control<Real> (&controls)[6])
{
    constexpr std::size_t faces = sphere::wall_set<Real>::count;
    py::array_t<double> position(faces), velocity(faces), force(faces), work(faces);
    py::array_t<bool> active(faces);
    py::list mode;
    for (std::size_t f = 0; f < faces; ++f) {
        position.mutable_at(f) = w.face[f].position;
        velocity.mutable_at(f) = w.face[f].velocity;
        force.mutable_at(f) = w.face[f].force;
        work.mutable_at(f) = w.face[f].work;
        active.mutable_at(f) = w.face[f].active;
        mode.append(name_of(controls[f].mode));
    }
    py::dict d;
    d["position"] = position;
    d["velocity"] = velocity;
    d["force"] = force;
    d["work"] = work;
    d["active"] = active;
    d["mode"] = mode;
    return d;
}

/// The contact lists (each particle pair once, as (i, j) with i < j, then each particle's wall
/// entries) and, when `forces` (the simulation keeps them), the forces of the last step on the
/// first particle (on the particle for walls): normal (f_n along the unit vector from j
/// towards i, at the current positions, or along the wall's inward normal), tangential and
/// their sum.
template <class Real>
py::dict contacts_of(const sphere::contact_table<Real>& t, const sphere::particle_snapshot<Real>& s,
                     const sphere::world<Real>& box, bool forces)
{
    std::vector<std::uint32_t> pairs, wall_particles;
    std::vector<std::uint8_t> wall_faces;
    std::vector<Real> normal, wall_normal;
    std::vector<sphere::vec3<Real>> tangential, total, wall_tangential, wall_total;
    std::vector<bool> touching, wall_touching;
    for (std::size_t i = 0; i < t.particles(); ++i)
        for (std::size_t e = t.begin(i); e < t.end(i); ++e) {
            const unsigned j = t.partner[e];
            const bool wall = j >= sphere::wall_partner_base;
            if (!wall && j < i) continue; // the pair's other entry
            sphere::vec3<Real> n;
            if (wall) {
                wall_particles.push_back(std::uint32_t(i));
                wall_faces.push_back(std::uint8_t(j - sphere::wall_partner_base));
                n = sphere::wall_set<Real>::inward_normal(int(j - sphere::wall_partner_base));
            } else {
                pairs.push_back(std::uint32_t(i));
                pairs.push_back(j);
                const sphere::vec3<Real> d = box.nearest_image(s.position(i) - s.position(j));
                n = d / std::sqrt(sphere::norm2(d));
            }
            if (!forces) continue;
            const sphere::vec4<Real> f = t.force[e];
            (wall ? wall_normal : normal).push_back(f.w);
            (wall ? wall_tangential : tangential).push_back(f.xyz());
            (wall ? wall_total : total).push_back(f.xyz() + n * f.w);
            (wall ? wall_touching : touching).push_back(f.x != 0 || f.y != 0 || f.z != 0 || f.w != 0);
        }
    auto flags = [](const std::vector<bool>& b) {
        py::array_t<bool> a(b.size());
        for (std::size_t k = 0; k < b.size(); ++k) a.mutable_at(k) = b[k];
        return a;
    };
    py::dict d;
    d["pairs"] = column(pairs).reshape({py::ssize_t(pairs.size() / 2), py::ssize_t(2)});
    d["wall_particles"] = column(wall_particles);
    d["wall_faces"] = column(wall_faces);
    const py::object none = py::none();
    d["normal_force"] = forces ? py::object(column(normal)) : none;
    d["tangential_force"] = forces ? py::object(rows(tangential)) : none;
    d["force"] = forces ? py::object(rows(total)) : none;
    d["touching"] = forces ? py::object(flags(touching)) : none;
    d["wall_normal_force"] = forces ? py::object(column(wall_normal)) : none;
    d["wall_tangential_force"] = forces ? py::object(rows(wall_tangential)) : none;
    d["wall_force"] = forces ? py::object(rows(wall_total)) : none;
    d["wall_touching"] = forces ? py::object(flags(wall_touching)) : none;
    return d;
}

/// The energy budget (J) and dissipation rates (W).
template <class Real>
py::dict energy_of(const sphere::energy_budget<Real>& e)
{
    py::dict d;
    d["kinetic"] = double(e.kinetic);
    d["rotational"] = double(e.rotational);
    d["potential"] = double(e.potential);
    d["elastic"] = double(e.elastic);
    d["dissipated_viscous"] = double(e.dissipated_visc);
    d["dissipated_friction"] = double(e.dissipated_fric);
    d["rate_viscous"] = double(e.rate_visc);
    d["rate_friction"] = double(e.rate_fric);
    d["boundary_work"] = double(e.boundary_work);
    d["bond_elastic"] = double(e.bond_elastic);
    d["bond_broken"] = double(e.bond_broken);
    d["total"] = double(e.total());
    return d;
}

/// A porosity result: porosity, void ratio, the solid and the whole volume (m^3).
inline py::dict porosity_of(const sphere::porosity_result& p)
{
    py::dict d;
    d["porosity"] = p.porosity;
    d["void_ratio"] = p.void_ratio;
    d["solid_volume"] = p.solid_volume;
    d["volume"] = p.volume;
    return d;
}

} // namespace sphere_python
