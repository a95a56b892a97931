#pragma once
// The analyses of include/sphere/analysis/ over a simulation of one precision, as NumPy arrays
// (python/sphere/analysis.py wraps them): porosity in a box and its profile along z
// (porosity.cuh), the Love-Weber stress tensor, coordination numbers and the contact network
// (stress.cuh). The precision-independent orientation and rose histogram (bond_rose.cuh) are
// bound by bind_orientations.
#include "common.hpp"
#include "fields.hpp"

#include <vector>

namespace sphere_python {

/// A 3-vector of doubles from a sequence of three numbers.
inline sphere::vec3<double> point(py::handle value, const std::string& where)
{
    return vector3<double>(value, where);
}

/// An (n, 3) float64 array of vectors given by `get(k)`.
template <class Get>
py::array_t<double> double_rows(std::size_t n, Get get)
{
    py::array_t<double> out({n, std::size_t(3)});
    auto o = out.mutable_unchecked<2>();
    for (std::size_t k = 0; k < n; ++k) {
        const sphere::vec3<double> v = get(k);
        for (int a = 0; a < 3; ++a) o(k, a) = v[a];
    }
    return out;
}

/// Binds the analyses in precision Real into m (after bind_simulation).
template <class Real>
void bind_analysis(py::module_& m)
{
    using Sim = sphere::simulation<Real>;
    m.def(
        "porosity_in_box",
        [](const Sim& sim, py::handle lo, py::handle hi) {
            return porosity_of(sphere::bulk_porosity(sim, point(lo, "lo"), point(hi, "hi")));
        },
        py::arg("simulation"), py::arg("lo"), py::arg("hi"));
    m.def(
        "porosity_profile",
        [](const Sim& sim, std::size_t slices, py::object lo, py::object hi) {
            std::vector<sphere::porosity_slice> p;
            if (lo.is_none())
                p = sphere::porosity_profile(sim, slices);
            else
                p = sphere::porosity_profile(sim.positions(), sim.config().box, point(lo, "lo"), point(hi, "hi"),
                                             slices);
            std::vector<double> z_lo(p.size()), z_hi(p.size()), phi(p.size());
            for (std::size_t k = 0; k < p.size(); ++k) {
                z_lo[k] = p[k].z_lo;
                z_hi[k] = p[k].z_hi;
                phi[k] = p[k].porosity;
            }
            return py::make_tuple(column(z_lo), column(z_hi), column(phi));
        },
        py::arg("simulation"), py::arg("slices"), py::arg("lo"), py::arg("hi"));
    m.def(
        "love_weber_stress",
        [](const Sim& sim, py::object volume) {
            const sphere::stress_tensor t = volume.is_none() ? sphere::love_weber_stress(sim)
                                                             : sphere::love_weber_stress(sim, number(volume, "volume"));
            py::array_t<double> out({std::size_t(3), std::size_t(3)});
            auto o = out.mutable_unchecked<2>();
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) o(i, j) = t.s[i][j];
            return out;
        },
        py::arg("simulation"), py::arg("volume"));
    m.def(
        "volume_between_walls",
        [](const Sim& sim) { return sphere::volume_between_walls(sim.walls(), sim.config().box); },
        py::arg("simulation"));
    m.def(
        "contact_counts",
        [](const Sim& sim, bool with_walls) {
            return column(sphere::contact_counts(sphere::take_contact_snapshot(sim), with_walls));
        },
        py::arg("simulation"), py::arg("with_walls"));
    m.def(
        "mean_coordination",
        [](const Sim& sim, bool with_walls) { return sphere::mean_coordination(sim, with_walls); },
        py::arg("simulation"), py::arg("with_walls"));
    m.def(
        "contact_network",
        [](const Sim& sim) {
            const std::vector<sphere::contact_force> c = sphere::contact_network(sim);
            std::vector<std::size_t> i(c.size()), j(c.size());
            std::vector<double> normal(c.size());
            for (std::size_t k = 0; k < c.size(); ++k) {
                i[k] = c[k].i;
                j[k] = c[k].j;
                normal[k] = c[k].normal;
            }
            py::dict d;
            d["i"] = column(i);
            d["j"] = column(j);
            d["x_i"] = double_rows(c.size(), [&](std::size_t k) { return c[k].x_i; });
            d["x_j"] = double_rows(c.size(), [&](std::size_t k) { return c[k].x_j; });
            d["branch"] = double_rows(c.size(), [&](std::size_t k) { return c[k].branch; });
            d["normal"] = column(normal);
            d["tangential"] = double_rows(c.size(), [&](std::size_t k) { return c[k].tangential; });
            return d;
        },
        py::arg("simulation"));
}

/// Binds the orientation of axes (trend and plunge) and their rose histogram into m.
inline void bind_orientations(py::module_& m)
{
    m.def(
        "orientations",
        [](const doubles& axes) {
            const std::size_t n = rows_of(axes, "axes");
            std::vector<double> trend(n), plunge(n);
            for (std::size_t k = 0; k < n; ++k) {
                const sphere::bond_orientation o =
                    sphere::orientation_of(sphere::vec3<double>{axes.at(k, 0), axes.at(k, 1), axes.at(k, 2)});
                trend[k] = o.trend;
                plunge[k] = o.plunge;
            }
            return py::make_tuple(column(trend), column(plunge));
        },
        py::arg("axes"));
    m.def(
        "rose",
        [](const doubles& trend, const doubles& plunge, std::size_t trend_bins, std::size_t plunge_bins) {
            const std::size_t n = std::size_t(trend.ndim() == 1 ? trend.shape(0) : 0);
            check_shape(trend, "trend", n, 0);
            check_shape(plunge, "plunge", n, 0);
            std::vector<sphere::bond_orientation> o(n);
            for (std::size_t k = 0; k < n; ++k) o[k] = {trend.at(k), plunge.at(k)};
            const sphere::bond_rose r = sphere::rose_of(o, trend_bins, plunge_bins);
            return py::make_tuple(column(r.trend), column(r.plunge));
        },
        py::arg("trend"), py::arg("plunge"), py::arg("trend_bins"), py::arg("plunge_bins"));
}

} // namespace sphere_python
