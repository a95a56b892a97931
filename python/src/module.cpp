// The extension module sphere._sphere (docs/python.md): the library's error as sphere.Error,
// the project's version, the precision-independent helpers and a submodule per precision
// (float.cpp, double.cpp), and the pictures (render.cpp).
#include "analysis.hpp"

#include <pybind11/stl.h>

namespace sphere_python {
void bind_render(py::module_& m); // render.cpp
} // namespace sphere_python

PYBIND11_MODULE(_sphere, m)
{
    namespace py = pybind11;
    m.doc() = "sphere's C++ library (host backend), bound for the Python package sphere";
    m.attr("__version__") = SPHERE_VERSION;
    // std::runtime_error's Python counterpart is RuntimeError; the message is what() ("sphere: ...").
    py::register_exception<sphere::error>(m, "Error", PyExc_RuntimeError);
    m.def(
        "gamma_n_from_restitution",
        [](double e, double m_eff, double k_n, bool tension) {
            return sphere::gamma_n_from_restitution(e, m_eff, k_n, tension);
        },
        py::arg("restitution"), py::arg("effective_mass"), py::arg("k_n"), py::arg("tension") = false,
        "Normal viscosity gamma_n (N s/m) that gives a contact of effective mass m_eff (kg) and normal stiffness "
        "k_n (N/m) the restitution coefficient e (contact/restitution.cuh).");
    m.def(
        "write_csv",
        [](const std::string& path, const std::vector<std::string>& columns, const sphere_python::doubles& rows) {
            if (rows.ndim() != 2 || std::size_t(rows.shape(1)) != columns.size())
                sphere::detail::fail("write_csv: rows has shape ", sphere_python::shape_text(rows), "; (rows, ",
                                     columns.size(), ") is needed for ", columns.size(), " columns");
            sphere::csv_series csv(path, columns);
            const auto r = rows.unchecked<2>();
            for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
                std::vector<double> row(columns.size());
                for (std::size_t c = 0; c < columns.size(); ++c) row[c] = r(i, py::ssize_t(c));
                csv.add_row(row);
            }
            csv.close();
        },
        py::arg("path"), py::arg("columns"), py::arg("rows"),
        "Writes a CSV time series (sphere::csv_series: the header, then the rows with 17 significant digits) to "
        "path atomically.");
    sphere_python::bind_orientations(m);
    sphere_python::bind_float(m);
    sphere_python::bind_double(m);
    sphere_python::bind_render(m);
}
