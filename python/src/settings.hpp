#pragma once
// sphere.Settings (python/sphere/settings.py) to the library's settings<Real> and back. The
// Python objects are read by attribute name, so any object with the same attributes will do;
// values are converted to Real here, and every bad value is a sphere::error naming it.
#include "common.hpp"

#include <type_traits>

namespace sphere_python {

/// A Python truth value as a bool; a sphere::error naming `where` for anything else.
inline bool flag(py::handle value, const std::string& where)
{
    try {
        return value.cast<bool>();
    } catch (const py::cast_error&) {
        sphere::detail::fail(where, " = ", py::repr(value).cast<std::string>(), ": not True or False");
    }
}

/// sphere.ContactParams to the linear law's parameters, field by field (contact_params::fields).
template <class Real>
sphere::contact_params<Real> contact_from(py::handle p, const std::string& where)
{
    sphere::contact_params<Real> c;
    sphere::contact_params<Real>::fields(c, [&](const char* name, auto& field, const char*) {
        using T = std::decay_t<decltype(field)>;
        const py::object value = p.attr(name);
        const std::string at = where + "." + name;
        if constexpr (std::is_floating_point_v<T>) field = T(number(value, at));
        else if constexpr (std::is_same_v<T, bool>) field = flag(value, at);
        else field = parse<T>(value, at);
    });
    return c;
}

/// The linear law's parameters as a sphere.ContactParams.
template <class Real>
py::object contact_to(const sphere::contact_params<Real>& c)
{
    py::dict fields;
    sphere::contact_params<Real>::fields(c, [&](const char* name, const auto& field, const char*) {
        using T = std::decay_t<decltype(field)>;
        if constexpr (std::is_floating_point_v<T>) fields[name] = double(field);
        else if constexpr (std::is_same_v<T, bool>) fields[name] = field;
        else fields[name] = name_of(field);
    });
    return py::module_::import("sphere.settings").attr("ContactParams")(**fields);
}

/// sphere.WallControl to a wall control.
template <class Real>
sphere::wall_control<Real> wall_control_from(py::handle w, const std::string& where)
{
    sphere::wall_control<Real> c;
    c.mode = parse<sphere::wall_mode>(w.attr("mode"), where + ".mode");
    c.velocity = Real(number(w.attr("velocity"), where + ".velocity"));
    c.stress = Real(number(w.attr("stress"), where + ".stress"));
    c.amplitude = Real(number(w.attr("amplitude"), where + ".amplitude"));
    c.frequency = Real(number(w.attr("frequency"), where + ".frequency"));
    c.phase = Real(number(w.attr("phase"), where + ".phase"));
    c.mass = Real(number(w.attr("mass"), where + ".mass"));
    return c;
}

/// A wall control as a sphere.WallControl.
template <class Real>
py::object wall_control_to(const sphere::wall_control<Real>& c)
{
    return py::module_::import("sphere.settings")
        .attr("WallControl")(py::arg("mode") = name_of(c.mode), py::arg("velocity") = double(c.velocity),
                             py::arg("stress") = double(c.stress), py::arg("amplitude") = double(c.amplitude),
                             py::arg("frequency") = double(c.frequency), py::arg("phase") = double(c.phase),
                             py::arg("mass") = double(c.mass));
}

/// sphere.Settings to settings<Real> (the bonds' parameters stay at their defaults).
template <class Real>
sphere::settings<Real> settings_from(py::handle s)
{
    sphere::settings<Real> out;
    out.box.lo = vector3<Real>(s.attr("lo"), "settings.lo");
    out.box.hi = vector3<Real>(s.attr("hi"), "settings.hi");
    const py::object boundary = s.attr("boundary");
    if (!py::isinstance<py::sequence>(boundary) || py::isinstance<py::str>(boundary) || py::len(boundary) != 3)
        sphere::detail::fail("settings.boundary = ", py::repr(boundary).cast<std::string>(),
                             ": three names ('wall' or 'periodic', for x, y, z) are needed");
    for (int a = 0; a < 3; ++a)
        out.box.axis[a] =
            parse<sphere::boundary>(boundary[py::int_(a)], "settings.boundary[" + std::to_string(a) + "]");
    out.contact = contact_from<Real>(s.attr("contact"), "settings.contact");
    out.wall = contact_from<Real>(s.attr("wall"), "settings.wall");
    out.gravity = vector3<Real>(s.attr("gravity"), "settings.gravity");
    out.dt = Real(number(s.attr("dt"), "settings.dt"));
    out.skin = Real(number(s.attr("skin"), "settings.skin"));
    out.max_initial_overlap = Real(number(s.attr("max_initial_overlap"), "settings.max_initial_overlap"));
    out.cell_size = Real(number(s.attr("cell_size"), "settings.cell_size"));
    out.contact_forces = flag(s.attr("contact_forces"), "settings.contact_forces");
    out.energy_audit = flag(s.attr("energy_audit"), "settings.energy_audit");
    out.angular_position = flag(s.attr("angular_position"), "settings.angular_position");
    out.accumulated_displacement = flag(s.attr("accumulated_displacement"), "settings.accumulated_displacement");
    out.reorder = flag(s.attr("reorder"), "settings.reorder");
    out.pair_summation = parse<sphere::pair_summation>(s.attr("pair_summation"), "settings.pair_summation");
    const py::object walls = s.attr("walls");
    constexpr int faces = sphere::wall_set<Real>::count;
    if (!py::isinstance<py::sequence>(walls) || py::len(walls) != faces)
        sphere::detail::fail("settings.walls = ", py::repr(walls).cast<std::string>(),
                             ": six wall controls (faces x-, x+, y-, y+, z-, z+) are needed");
    for (int f = 0; f < faces; ++f)
        out.walls[f] = wall_control_from<Real>(walls[py::int_(f)], "settings.walls[" + std::to_string(f) + "]");
    return out;
}

/// settings<Real> as a sphere.Settings.
template <class Real>
py::object settings_to(const sphere::settings<Real>& s)
{
    py::list boundary, walls;
    for (int a = 0; a < 3; ++a) boundary.append(name_of(s.box.axis[a]));
    for (const sphere::wall_control<Real>& w : s.walls) walls.append(wall_control_to(w));
    return py::module_::import("sphere.settings")
        .attr("Settings")(py::arg("lo") = tuple3(s.box.lo), py::arg("hi") = tuple3(s.box.hi),
                          py::arg("boundary") = py::tuple(boundary), py::arg("contact") = contact_to(s.contact),
                          py::arg("wall") = contact_to(s.wall), py::arg("gravity") = tuple3(s.gravity),
                          py::arg("dt") = double(s.dt), py::arg("skin") = double(s.skin),
                          py::arg("max_initial_overlap") = double(s.max_initial_overlap),
                          py::arg("cell_size") = double(s.cell_size), py::arg("contact_forces") = s.contact_forces,
                          py::arg("energy_audit") = s.energy_audit, py::arg("angular_position") = s.angular_position,
                          py::arg("accumulated_displacement") = s.accumulated_displacement,
                          py::arg("reorder") = s.reorder, py::arg("pair_summation") = name_of(s.pair_summation),
                          py::arg("walls") = walls);
}

} // namespace sphere_python
