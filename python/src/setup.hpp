#pragma once
// The set-up helpers of one precision (setup/packing.cuh, particles/distributions.cuh): radii,
// lattices, random packings and the world fitted to the particles, as NumPy arrays of Real.
#include "settings.hpp"

namespace sphere_python {

/// Binds the set-up helpers in precision Real into m.
template <class Real>
void bind_setup(py::module_& m)
{
    m.def(
        "uniform_radii",
        [](std::size_t n, double r_min, double r_max, std::uint64_t seed) {
            return column(sphere::uniform_radii(n, Real(r_min), Real(r_max), seed));
        },
        py::arg("n"), py::arg("r_min"), py::arg("r_max"), py::arg("seed"));
    m.def(
        "lognormal_radii",
        [](std::size_t n, double mean, double stddev, std::uint64_t seed) {
            return column(sphere::lognormal_radii(n, Real(mean), Real(stddev), seed));
        },
        py::arg("n"), py::arg("mean"), py::arg("stddev"), py::arg("seed"));
    m.def(
        "bimodal_radii",
        [](std::size_t n, double r_small, double r_large, double ratio, std::uint64_t seed) {
            return column(sphere::bimodal_radii(n, Real(r_small), Real(r_large), ratio, seed));
        },
        py::arg("n"), py::arg("r_small"), py::arg("r_large"), py::arg("ratio"), py::arg("seed"));
    m.def(
        "random_packing",
        [](const doubles& radii, py::handle settings, std::uint64_t seed, double gap, std::size_t max_tries) {
            check_shape(radii, "radii", std::size_t(radii.ndim() == 1 ? radii.shape(0) : 0), 0);
            std::vector<Real> r(std::size_t(radii.size()));
            for (std::size_t i = 0; i < r.size(); ++i) r[i] = Real(radii.at(i));
            const sphere::world<Real> region = settings_from<Real>(settings).box;
            return rows(sphere::random_packing(r, region, seed, Real(gap), max_tries));
        },
        py::arg("radii"), py::arg("settings"), py::arg("seed"), py::arg("gap"), py::arg("max_tries"));
    m.def(
        "cubic_lattice",
        [](std::size_t nx, std::size_t ny, std::size_t nz, py::handle spacing, py::handle origin) {
            return rows(sphere::cubic_lattice(nx, ny, nz, vector3<Real>(spacing, "cubic_lattice: spacing"),
                                              vector3<Real>(origin, "cubic_lattice: origin")));
        },
        py::arg("nx"), py::arg("ny"), py::arg("nz"), py::arg("spacing"), py::arg("origin"));
    m.def(
        "jittered_lattice",
        [](std::size_t nx, std::size_t ny, std::size_t nz, double spacing, double jitter, std::uint64_t seed,
           py::handle origin) {
            return rows(sphere::jittered_lattice(nx, ny, nz, Real(spacing), Real(jitter), seed,
                                                 vector3<Real>(origin, "jittered_lattice: origin")));
        },
        py::arg("nx"), py::arg("ny"), py::arg("nz"), py::arg("spacing"), py::arg("jitter"), py::arg("seed"),
        py::arg("origin"));
    m.def(
        "fit_world",
        [](py::handle settings, const doubles& positions, const doubles& radii, double margin, double headroom) {
            const std::size_t n = rows_of(positions, "positions");
            check_shape(radii, "radii", n, 0);
            sphere::settings<Real> s = settings_from<Real>(settings);
            std::vector<sphere::particle<Real>> particles(n);
            for (std::size_t i = 0; i < n; ++i) {
                for (int a = 0; a < 3; ++a) particles[i].position[a] = Real(positions.at(i, a));
                particles[i].radius = Real(radii.at(i));
            }
            sphere::fit_world(s, particles, Real(margin), Real(headroom));
            return py::make_tuple(tuple3(s.box.lo), tuple3(s.box.hi));
        },
        py::arg("settings"), py::arg("positions"), py::arg("radii"), py::arg("margin"), py::arg("headroom"));
}

} // namespace sphere_python
