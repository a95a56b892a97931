// Pictures of a simulation's particles (docs/render.md) for sphere.Simulation.render: the
// library's ray tracer (io/render_png.cuh) on the host, both precisions, in a translation unit of
// its own (libpng is needed only here). Built with SPHERE_PYTHON_PNG when CMake found libpng
// (target sphere::png); without it the call raises sphere.Error saying so.
#include "common.hpp"

#ifdef SPHERE_PYTHON_PNG
#include <sphere/io/render_png.cuh>
#endif

#include <cmath>
#include <string>

namespace sphere_python {

namespace {

#ifdef SPHERE_PYTHON_PNG
/// Writes the PNG picture of the simulation's particles coloured by `method` (normal, pres, vel,
/// angvel, xdisp) from `lower_cutoff` to `max_val`; max_val None is the largest value shown
/// (lower_cutoff + 1 when none lies above lower_cutoff, e.g. the zero pressures of a simulation
/// without an energy audit).
template <class Real>
void render(const sphere::simulation<Real>& sim, const std::string& path, const std::string& method,
            py::object max_val, double lower_cutoff)
{
    const sphere::render_method m = sphere::render_method_named(method);
    const sphere::particle_snapshot<Real> snap = sim.snapshot();
    sphere::render_options options;
    options.lower_cutoff = lower_cutoff;
    if (max_val.is_none()) {
        double top = -INFINITY;
        for (Real v : sphere::particle_values(snap, m))
            if (std::isfinite(double(v)) && double(v) > top) top = double(v);
        options.max_val = top > lower_cutoff ? top : lower_cutoff + 1;
    } else {
        options.max_val = number(max_val, "render: max_val");
    }
    sphere::render_png(path, snap, m, options);
}
#else
template <class Real>
void render(const sphere::simulation<Real>&, const std::string&, const std::string&, py::object, double)
{
    sphere::detail::fail("render: this build of the package has no libpng (CMake did not find it, so the target "
                         "sphere::png was missing): install libpng's development files (Debian's libpng-dev) and "
                         "build it again");
}
#endif

} // namespace

void bind_render(py::module_& m)
{
    m.attr("has_png") = py::bool_(
#ifdef SPHERE_PYTHON_PNG
        true
#else
        false
#endif
    );
    m.def("render_png", &render<float>, py::arg("simulation"), py::arg("path"), py::arg("method"),
          py::arg("max_val"), py::arg("lower_cutoff"));
    m.def("render_png", &render<double>, py::arg("simulation"), py::arg("path"), py::arg("method"),
          py::arg("max_val"), py::arg("lower_cutoff"),
          "Writes a PNG picture of the simulation's particles (sphere::render_png, docs/render.md).");
}

} // namespace sphere_python
