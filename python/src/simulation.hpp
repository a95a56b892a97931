#pragma once
// The class Simulation of one precision (sphere::simulation<Real> with the linear contact law
// on the host backend), which python/sphere/simulation.py wraps.
#include "fields.hpp"
#include "settings.hpp"

#include <utility>

namespace sphere_python {

/// A one-byte-per-value array argument (the motion kinds).
using bytes = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;

/// A simulation of the particles the arrays describe: positions and velocities (N, 3), radii,
/// densities and motion kinds (N,).
template <class Real>
sphere::simulation<Real> make_simulation(py::handle settings, const doubles& positions, const doubles& radii,
                                         const doubles& densities, const doubles& velocities,
                                         const doubles& angular_velocities, const bytes& kinds)
{
    const std::size_t n = rows_of(positions, "positions");
    check_shape(radii, "radii", n, 0);
    check_shape(densities, "density", n, 0);
    check_shape(velocities, "velocities", n, 3);
    check_shape(angular_velocities, "angular_velocities", n, 3);
    check_shape(kinds, "kinds", n, 0);
    const auto x = positions.unchecked<2>(), v = velocities.unchecked<2>(), w = angular_velocities.unchecked<2>();
    std::vector<sphere::particle<Real>> particles(n);
    for (std::size_t i = 0; i < n; ++i) {
        sphere::particle<Real>& p = particles[i];
        for (int a = 0; a < 3; ++a) {
            p.position[a] = Real(x(i, a));
            p.velocity[a] = Real(v(i, a));
            p.angular_velocity[a] = Real(w(i, a));
        }
        p.radius = Real(radii.at(i));
        p.density = Real(densities.at(i));
        p.kind = static_cast<sphere::motion>(kinds.at(i));
    }
    return sphere::simulation<Real>(settings_from<Real>(settings), std::move(particles));
}

/// Binds sphere::simulation<Real> as `Simulation` into m.
template <class Real>
void bind_simulation(py::module_& m)
{
    using Sim = sphere::simulation<Real>;
    py::class_<Sim>(m, "Simulation", "sphere::simulation on the host backend with the linear contact law")
        .def(py::init(&make_simulation<Real>), py::arg("settings"), py::arg("positions"), py::arg("radii"),
             py::arg("densities"), py::arg("velocities"), py::arg("angular_velocities"), py::arg("kinds"))
        .def_static("restart", [](const std::string& path) { return sphere::restart<Sim>(path); }, py::arg("path"))
        .def("write_checkpoint", [](const Sim& s, const std::string& path) { sphere::write_checkpoint(path, s); },
             py::arg("path"))
        .def("write_vtk", [](const Sim& s, const std::string& path) { sphere::write_vtu(path, s); }, py::arg("path"))
        .def("run", &Sim::run, py::arg("steps"))
        .def(
            "add_observer",
            [](Sim& s, std::size_t every, py::function f) { s.add_observer(every, [f](const Sim&) { f(); }); },
            py::arg("every"), py::arg("observer"))
        .def_property_readonly("time", &Sim::time)
        .def_property_readonly("steps", &Sim::steps)
        .def_property_readonly("dt", [](const Sim& s) { return double(s.dt()); })
        .def_property_readonly("size", &Sim::size)
        .def_property_readonly("rebuilds", &Sim::rebuilds)
        .def_property_readonly("initial_overlap", &Sim::initial_overlap)
        .def_property_readonly("settings", [](const Sim& s) { return settings_to(s.config()); })
        .def("snapshot", [](const Sim& s) { return snapshot_of(s.snapshot()); })
        .def("walls", [](const Sim& s) { return walls_of(s.walls(), s.config().walls); })
        .def("contacts",
             [](const Sim& s) {
                 return contacts_of(s.contacts(), s.snapshot(), s.config().box, s.config().contact_forces);
             })
        .def("energy", [](const Sim& s) { return energy_of(s.energy()); })
        .def("momentum", [](const Sim& s) { return tuple3(s.momentum()); })
        .def("porosity", [](const Sim& s) { return porosity_of(sphere::bulk_porosity(s)); })
        .def("wall_normal_stress", [](const Sim& s, int face) { return sphere::wall_normal_stress(s, face); },
             py::arg("face"))
        .def(
            "set_wall_control",
            [](Sim& s, int face, py::handle control) {
                s.set_wall_control(face, wall_control_from<Real>(control, "set_wall_control: control"));
            },
            py::arg("face"), py::arg("control"))
        .def("set_wall_position", &Sim::set_wall_position, py::arg("face"), py::arg("position"))
        .def(
            "set_velocity",
            [](Sim& s, std::size_t i, py::handle v, py::handle omega) {
                s.set_velocity(i, vector3<Real>(v, "set_velocity: velocity"),
                               vector3<Real>(omega, "set_velocity: angular_velocity"));
            },
            py::arg("index"), py::arg("velocity"), py::arg("angular_velocity"))
        .def(
            "deposit",
            [](Sim& s, double threshold, std::size_t max_steps, std::size_t check_every, double min_time) {
                const sphere::deposition_result r = sphere::deposit(s, threshold, max_steps, check_every, min_time);
                py::dict d;
                d["steps"] = r.steps;
                d["time"] = r.time;
                d["kinetic"] = r.kinetic;
                return d;
            },
            py::arg("kinetic_threshold"), py::arg("max_steps"), py::arg("check_every"), py::arg("min_time"));
}

} // namespace sphere_python
