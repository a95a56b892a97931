#pragma once
// What the experiments of python/sphere (consolidation.py, shear.py) need beyond Simulation, in
// one precision: a simulation started from a saved sample (the examples' --sample,
// granular::prepared_sample), the shear cell (setup/layers.cuh), the shear stress and the
// strain tracker (analysis/shear.cuh), the drive work and a wall's area.
#include "settings.hpp"

#include <pybind11/stl.h>

#include <limits>
#include <string>
#include <vector>

namespace sphere_python {

/// The simulation of a saved sample (a checkpoint), as the granular examples start from one with
/// --sample: its particles, contact parameters, world and wall positions, the particle-wall
/// parameters `wall`, every wall fixed, and no check of the initial overlaps (the state was
/// accepted when its run began). The sample must be periodic on x and y, or closed by walls on
/// both when `side_walls`.
template <class Real>
sphere::simulation<Real> simulation_of_sample(const std::string& path, py::handle wall, bool side_walls)
{
    sphere::checkpoint_data<Real> c = sphere::read_checkpoint<Real>(path);
    const bool walls_on_sides = !c.config.box.periodic(0) && !c.config.box.periodic(1);
    const bool periodic_sides = c.config.box.periodic(0) && c.config.box.periodic(1);
    if (side_walls ? !walls_on_sides : !periodic_sides)
        sphere::detail::fail("sample '", path, "': this experiment needs a sample ",
                             side_walls ? "closed by walls on x and y"
                                        : "periodic on x and y (as consolidate and shear deposit)");
    c.config.wall = contact_from<Real>(wall, "wall");
    for (sphere::wall_control<Real>& w : c.config.walls) w = sphere::wall_control<Real>{};
    c.config.max_initial_overlap = std::numeric_limits<Real>::infinity();
    sphere::simulation<Real> sim(c.config, c.particles());
    sim.restore(c.state);
    return sim;
}

/// The layers of a shear cell as a dict of `top` and `bottom` user indices.
inline py::dict layers_to(const sphere::shear_layers& l)
{
    py::dict d;
    d["top"] = l.top;
    d["bottom"] = l.bottom;
    return d;
}

/// sphere::shear_layers from a dict of `top` and `bottom` indices.
inline sphere::shear_layers layers_from(py::handle d)
{
    sphere::shear_layers l;
    l.top = d["top"].cast<std::vector<std::size_t>>();
    l.bottom = d["bottom"].cast<std::vector<std::size_t>>();
    return l;
}

/// Binds the experiments' helpers in precision Real into m (after bind_simulation).
template <class Real>
void bind_experiments(py::module_& m)
{
    using Sim = sphere::simulation<Real>;
    m.def("simulation_of_sample", &simulation_of_sample<Real>, py::arg("path"), py::arg("wall"),
          py::arg("side_walls"));
    m.def(
        "shear_cell_height",
        [](const Sim& sim, double thickness) {
            sphere::particle_snapshot<Real> probe = sim.state().particles;
            const sphere::vec3<Real> along_x{Real(1), Real(0), Real(0)}; // any velocity: the layers are the same
            return sphere::shear_height(probe, sphere::make_shear_cell(probe, Real(thickness), along_x));
        },
        py::arg("simulation"), py::arg("thickness"),
        "Height between the layers (m) a shear cell of this thickness would have (nothing changes).");
    m.def(
        "make_shear_cell",
        [](Sim& sim, double thickness, double velocity_x, double velocity_y) {
            sphere::simulation_state<Real> st = sim.state();
            const sphere::vec3<Real> velocity{Real(velocity_x), Real(velocity_y), Real(0)};
            const sphere::shear_layers l = sphere::make_shear_cell(st.particles, Real(thickness), velocity);
            sim.restore(st);
            return layers_to(l);
        },
        py::arg("simulation"), py::arg("thickness"), py::arg("velocity_x"), py::arg("velocity_y"));
    m.def(
        "shear_stress",
        [](const Sim& sim, py::handle layers, double area, int axis) {
            return sphere::shear_stress(sim.snapshot(), layers_from(layers), area, axis);
        },
        py::arg("simulation"), py::arg("layers"), py::arg("area"), py::arg("axis"));
    m.def("drive_work", [](const Sim& sim) { return sim.drive_work(); }, py::arg("simulation"));
    m.def(
        "wall_area",
        [](const Sim& sim, int face) {
            if (face < 0 || face > 5) sphere::detail::fail("wall_area: face ", face, " is not 0 to 5");
            return sphere::wall_area(sim.walls(), sim.config().box, face);
        },
        py::arg("simulation"), py::arg("face"));

    using Tracker = sphere::shear_tracker<Real>;
    py::class_<Tracker>(m, "ShearTracker", "sphere::shear_tracker")
        .def(py::init([](const Sim& sim, int axis) { return Tracker(sim, axis); }), py::arg("simulation"),
             py::arg("axis"))
        .def("update", [](Tracker& t, const Sim& sim) { t.update(sim); }, py::arg("simulation"))
        .def_property_readonly("strain", &Tracker::strain)
        .def_property_readonly("displacement", &Tracker::displacement)
        .def_property_readonly("height", &Tracker::height)
        .def_property_readonly("velocity", &Tracker::velocity)
        .def_property_readonly("strain_rate", &Tracker::strain_rate)
        .def_property_readonly("layers", [](const Tracker& t) { return layers_to(t.layers()); });
}

} // namespace sphere_python
