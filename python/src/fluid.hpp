#pragma once
// The class Fluid of one precision: the pore fluid coupled to a Simulation's particles
// (sphere::fluid_coupling on the host backend with the Gidaspow drag law), which
// python/sphere/fluid.py wraps. The model (navier_stokes or darcy) and the pressure solver (mg
// or cg) are chosen at run time: a FluidSettings becomes the library's coupling_setup, from
// which sphere::make_coupling (fluid/setup_coupling.cuh) builds the coupling.
#include "settings.hpp"

#include <sphere/fluid.cuh>
#include <sphere/io/vti.cuh>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace sphere_python {

template <>
inline const std::vector<std::string>& names_of<sphere::fluid_boundary_kind>()
{
    using sphere::fluid_boundary_kind;
    static const std::vector<std::string> names{sphere::name(fluid_boundary_kind::no_flow),
                                                sphere::name(fluid_boundary_kind::pressure),
                                                sphere::name(fluid_boundary_kind::inflow)};
    return names;
}
template <>
inline const std::vector<std::string>& names_of<sphere::poisson_criterion>()
{
    static const std::vector<std::string> names{sphere::name(sphere::poisson_criterion::relative_residual),
                                                sphere::name(sphere::poisson_criterion::normalized_change)};
    return names;
}
template <>
inline const std::vector<std::string>& names_of<sphere::porosity_method>()
{
    static const std::vector<std::string> names{sphere::name(sphere::porosity_method::cell_volume),
                                                sphere::name(sphere::porosity_method::cell_sphere)};
    return names;
}

/// A Python number that is a whole number from 1 to 2^32 - 1; a sphere::error naming `where`
/// for anything else.
inline unsigned positive_count(py::handle value, const std::string& where)
{
    const double v = number(value, where);
    if (!(v >= 1 && v <= 4294967295.0 && v == double(unsigned(v))))
        sphere::detail::fail(where, " = ", v, ": a whole number from 1 to 4294967295 is needed");
    return unsigned(v);
}

/// sphere.FluidBoundary to one end of the fluid grid.
template <class Real>
sphere::fluid_boundary<Real> fluid_boundary_from(py::handle b, const std::string& where)
{
    sphere::fluid_boundary<Real> out;
    out.kind = parse<sphere::fluid_boundary_kind>(b.attr("kind"), where + ".kind");
    out.pressure = Real(number(b.attr("pressure"), where + ".pressure"));
    out.amplitude = Real(number(b.attr("amplitude"), where + ".amplitude"));
    out.frequency = Real(number(b.attr("frequency"), where + ".frequency"));
    out.phase = Real(number(b.attr("phase"), where + ".phase"));
    out.velocity = Real(number(b.attr("velocity"), where + ".velocity"));
    return out;
}

/// The fluid part of sphere.FluidSettings (gravity already resolved by fluid.py).
template <class Real>
sphere::fluid_params<Real> fluid_params_from(py::handle s)
{
    sphere::fluid_params<Real> p;
    p.density = Real(number(s.attr("density"), "fluid.density"));
    p.viscosity = Real(number(s.attr("viscosity"), "fluid.viscosity"));
    p.beta = Real(number(s.attr("beta"), "fluid.beta"));
    p.gravity = vector3<Real>(s.attr("gravity"), "fluid.gravity");
    p.bottom = fluid_boundary_from<Real>(s.attr("bottom"), "fluid.bottom");
    p.top = fluid_boundary_from<Real>(s.attr("top"), "fluid.top");
    p.poisson.tolerance = number(s.attr("tolerance"), "fluid.tolerance");
    p.poisson.max_iterations = positive_count(s.attr("max_iterations"), "fluid.max_iterations");
    p.poisson.criterion = parse<sphere::poisson_criterion>(s.attr("criterion"), "fluid.criterion");
    return p;
}

/// sphere.FluidSettings as the library's coupling_setup (the drag law Gidaspow's).
template <class Real>
sphere::coupling_setup<Real> setup_from(py::handle s)
{
    sphere::coupling_setup<Real> c;
    c.model = s.attr("model").cast<std::string>();
    c.solver = s.attr("solver").cast<std::string>();
    c.drag = sphere::drag::gidaspow::name();
    c.options.dem_steps = positive_count(s.attr("dem_steps"), "fluid.dem_steps");
    c.options.pressure_force = flag(s.attr("pressure_force"), "fluid.pressure_force");
    c.options.porosity = parse<sphere::porosity_method>(s.attr("porosity"), "fluid.porosity");
    c.params.fluid = fluid_params_from<Real>(s);
    c.params.compressibility = Real(number(s.attr("compressibility"), "fluid.compressibility"));
    c.params.permeability_prefactor = Real(number(s.attr("permeability_prefactor"), "fluid.permeability_prefactor"));
    c.params.max_porosity = Real(number(s.attr("max_porosity"), "fluid.max_porosity"));
    return c;
}

/// Whether a fluid model type is the Darcy model.
template <class Model>
struct is_darcy_model : std::false_type {};
template <class Real, class Policy, class Poisson>
struct is_darcy_model<sphere::darcy_flow<Real, Policy, Poisson>> : std::true_type {};

/// The pore fluid coupled to a simulation<Real>: one of the four couplings of model and solver.
template <class Real>
class fluid_binding {
    using Sim = sphere::simulation<Real>;

public:
    /// A fluid on a grid of cells[0] x cells[1] x cells[2] cells over the simulation's world box,
    /// with the settings of a sphere.FluidSettings.
    fluid_binding(const Sim& sim, py::handle cells, py::handle s)
        : fluid_binding(grid_of(sim, cells), setup_from<Real>(s), "fluid")
    {
    }

    /// The fluid of a coupled run's checkpoint (read once): the coupling its setup describes on
    /// its fluid section's cells over the simulation's world box, restored from it (which
    /// checks the box); and the setup as a dict (setup_dict).
    static py::tuple from_checkpoint(const Sim& sim, const std::string& path)
    {
        const sphere::checkpoint_data<Real> c = sphere::read_checkpoint<Real>(path);
        if (!c.fluid) no_fluid_section(path, c.version);
        const std::string where = "checkpoint '" + path + "'";
        const sphere::coupling_setup<Real> setup = sphere::coupling_setup<Real>::read(*c.fluid, where.c_str());
        const unsigned* n = c.fluid->n;
        fluid_binding f(sphere::fluid_grid<Real>::make(sim.config().box, n[0], n[1], n[2]), setup, where + ": setup");
        f.visit([&](auto& coupling) { coupling.restore(*c.fluid); });
        py::dict d = setup_dict(setup, f.grid_);
        return py::make_tuple(std::move(f), std::move(d));
    }

    const std::string& model() const { return setup_.model; }
    const std::string& solver() const { return setup_.solver; }
    py::tuple cells() const { return py::make_tuple(grid_.n[0], grid_.n[1], grid_.n[2]); }
    py::tuple cell_width() const { return tuple3(grid_.width); }
    py::tuple lo() const { return tuple3(grid_.box.lo); }
    py::tuple hi() const { return tuple3(grid_.box.hi); }
    unsigned dem_steps() { return visit([](auto& c) { return c.options().dem_steps; }); }
    double time() { return visit([](auto& c) { return c.fluid().time(); }); }

    /// One coupled step: the fluid advances by dem_steps x sim.dt, then the simulation by
    /// dem_steps steps.
    void step(Sim& sim) { visit([&](auto& c) { c.step(sim); }); }

    /// The last pressure solve: iterations, residual, converged.
    py::dict last_solve()
    {
        const sphere::poisson_result r = visit([](auto& c) { return c.fluid().last_solve(); });
        py::dict d;
        d["iterations"] = r.iterations;
        d["residual"] = r.residual;
        d["converged"] = r.converged;
        return d;
    }
    double work_on_particles() { return visit([](auto& c) { return c.work_on_particles(); }); }

    /// The largest stable fluid time step (s) for the present state: Navier-Stokes' diffusive
    /// and advective limits; infinity for Darcy (unconditionally stable).
    double stable_time_step()
    {
        return visit([](auto& c) -> double {
            if constexpr (is_darcy<decltype(c)>()) return std::numeric_limits<double>::infinity();
            else return double(c.fluid().stable_time_step());
        });
    }

    /// Cell fields as (nx, ny, nz) arrays (copies, ghosts left out).
    py::array_t<Real> pressure() { return cells_of(visit([](auto& c) { return c.fluid().pressure(); })); }
    py::array_t<Real> porosity() { return cells_of(visit([](auto& c) { return c.porosity().fields().phi; })); }
    py::array_t<Real> porosity_rate()
    {
        return cells_of(visit([](auto& c) { return c.porosity().fields().dphi_dt; }));
    }
    py::array_t<Real> particle_diameter()
    {
        return cells_of(visit([](auto& c) { return c.porosity().fields().d_p; }));
    }
    py::array_t<Real> particle_velocity()
    {
        return vectors_of(visit([](auto& c) { return c.porosity().fields().v_p; }));
    }
    /// Navier-Stokes: the fluid velocity at the cell centres (nx, ny, nz, 3).
    py::array_t<Real> velocity()
    {
        return vectors_of(visit([&](auto& c) -> std::vector<sphere::vec3<Real>> {
            if constexpr (is_darcy<decltype(c)>()) wrong_model("velocity", "navier_stokes", "darcy_flux");
            else return c.fluid().cell_velocity();
        }));
    }
    /// Darcy: the Darcy flux at the cell centres (nx, ny, nz, 3).
    py::array_t<Real> darcy_flux()
    {
        return vectors_of(visit([&](auto& c) -> std::vector<sphere::vec3<Real>> {
            if constexpr (is_darcy<decltype(c)>()) return c.fluid().darcy_flux();
            else wrong_model("darcy_flux", "darcy", "velocity");
        }));
    }
    /// Darcy: the hydraulic conductivity k / mu (m^2 / (Pa s)), (nx, ny, nz).
    py::array_t<Real> conductivity()
    {
        return cells_of(visit([&](auto& c) -> std::vector<Real> {
            if constexpr (is_darcy<decltype(c)>()) return c.fluid().conductivity();
            else wrong_model("conductivity", "darcy", "velocity");
        }));
    }

    /// The fluid's cells as a VTK image (io/vti.cuh) at the fluid's time.
    void write_vtk(const std::string& path)
    {
        visit([&](auto& c) { sphere::write_vti(path, c, c.fluid().time()); });
    }

    void write_checkpoint(const std::string& path, const Sim& sim)
    {
        visit([&](auto& c) { sphere::write_checkpoint(path, sim, c); });
    }
    /// The fluid's state from the checkpoint at `path` (its fluid section), as
    /// sphere::restart(path, coupling) restores it.
    void restore(const std::string& path)
    {
        const sphere::checkpoint_data<Real> c = sphere::read_checkpoint<Real>(path);
        if (!c.fluid) no_fluid_section(path, c.version);
        visit([&](auto& coupling) { coupling.restore(*c.fluid); });
    }

private:
    fluid_binding(const sphere::fluid_grid<Real>& grid, const sphere::coupling_setup<Real>& setup,
                  const std::string& where)
        : grid_(grid), setup_(setup), c_(sphere::make_coupling<Real, sphere::host>(setup, grid, where))
    {
    }

    [[noreturn]] static void no_fluid_section(const std::string& path, unsigned version)
    {
        sphere::detail::fail("checkpoint '", path, "': no fluid section (format version ", version,
                             version >= 7 ? ", written without a fluid" : ", which has none",
                             "); Fluid.write_checkpoint writes one");
    }

    /// A setup as a dict: model, solver, drag, cells, and every field of coupling_setup::fields
    /// by its name (enumerations by name).
    static py::dict setup_dict(const sphere::coupling_setup<Real>& setup, const sphere::fluid_grid<Real>& grid)
    {
        py::dict d;
        d["model"] = setup.model;
        d["solver"] = setup.solver;
        d["drag"] = setup.drag;
        d["cells"] = py::make_tuple(grid.n[0], grid.n[1], grid.n[2]);
        sphere::coupling_setup<Real>::fields(
            setup, [&](const char* name, const auto& field) { d[name] = double(field); },
            [&](const char* name, const auto& field, std::uint64_t) {
                using T = std::decay_t<decltype(field)>;
                if constexpr (std::is_enum_v<T>) d[name] = name_of(field);
                else if constexpr (std::is_same_v<T, bool>) d[name] = field;
                else d[name] = std::uint64_t(field);
            });
        return d;
    }

    static sphere::fluid_grid<Real> grid_of(const Sim& sim, py::handle cells)
    {
        if (!py::isinstance<py::sequence>(cells) || py::isinstance<py::str>(cells) || py::len(cells) != 3)
            sphere::detail::fail("fluid: cells = ", py::repr(cells).cast<std::string>(),
                                 ": three whole numbers (cells along x, y, z) are needed");
        long long n[3];
        for (int a = 0; a < 3; ++a) {
            const double v = number(cells[py::int_(a)], "fluid: cells[" + std::to_string(a) + "]");
            if (!(std::abs(v) < 1e15) || v != std::floor(v)) // fluid_grid::make checks the range
                sphere::detail::fail("fluid: cells[", a, "] = ", v, " is not a whole number");
            n[a] = (long long)v;
        }
        return sphere::fluid_grid<Real>::make(sim.config().box, n[0], n[1], n[2]);
    }

    template <class C>
    static constexpr bool is_darcy()
    {
        return is_darcy_model<typename std::decay_t<C>::model_type>::value;
    }

    [[noreturn]] void wrong_model(const char* what, const char* needs, const char* instead) const
    {
        sphere::detail::fail("fluid.", what, ": the ", needs, " model's field; this fluid is ", setup_.model,
                             " (its field is ", instead, ")");
    }

    template <class F>
    auto visit(F f)
    {
        return std::visit([&](auto& c) { return f(*c); }, c_);
    }

    /// A cell field in field layout as an (nx, ny, nz) array.
    py::array_t<Real> cells_of(const std::vector<Real>& field) const
    {
        py::array_t<Real> out({py::ssize_t(grid_.n[0]), py::ssize_t(grid_.n[1]), py::ssize_t(grid_.n[2])});
        auto o = out.template mutable_unchecked<3>();
        for (int k = 0; k < int(grid_.n[2]); ++k)
            for (int j = 0; j < int(grid_.n[1]); ++j)
                for (int i = 0; i < int(grid_.n[0]); ++i) o(i, j, k) = field[grid_.field_index(i, j, k)];
        return out;
    }
    /// A vector field in field layout as an (nx, ny, nz, 3) array.
    py::array_t<Real> vectors_of(const std::vector<sphere::vec3<Real>>& field) const
    {
        py::array_t<Real> out({py::ssize_t(grid_.n[0]), py::ssize_t(grid_.n[1]), py::ssize_t(grid_.n[2]), py::ssize_t(3)});
        auto o = out.template mutable_unchecked<4>();
        for (int k = 0; k < int(grid_.n[2]); ++k)
            for (int j = 0; j < int(grid_.n[1]); ++j)
                for (int i = 0; i < int(grid_.n[0]); ++i)
                    for (int a = 0; a < 3; ++a) o(i, j, k, a) = field[grid_.field_index(i, j, k)][a];
        return out;
    }

    sphere::fluid_grid<Real> grid_;
    sphere::coupling_setup<Real> setup_;
    sphere::setup_coupling<Real, sphere::host> c_;
};

/// Binds fluid_binding<Real> as `Fluid` into m, and fluid_from_checkpoint.
template <class Real>
void bind_fluid(py::module_& m)
{
    using F = fluid_binding<Real>;
    m.def("fluid_from_checkpoint", &F::from_checkpoint, py::arg("simulation"), py::arg("path"));
    using Sim = sphere::simulation<Real>;
    py::class_<F>(m, "Fluid", "the pore fluid coupled to a simulation (sphere::fluid_coupling, host backend)")
        .def(py::init<const Sim&, py::handle, py::handle>(), py::arg("simulation"), py::arg("cells"),
             py::arg("settings"))
        .def_property_readonly("model", &F::model)
        .def_property_readonly("solver", &F::solver)
        .def_property_readonly("cells", &F::cells)
        .def_property_readonly("cell_width", &F::cell_width)
        .def_property_readonly("lo", &F::lo)
        .def_property_readonly("hi", &F::hi)
        .def_property_readonly("dem_steps", &F::dem_steps)
        .def_property_readonly("time", &F::time)
        .def("step", &F::step, py::arg("simulation"))
        .def("last_solve", &F::last_solve)
        .def("work_on_particles", &F::work_on_particles)
        .def("stable_time_step", &F::stable_time_step)
        .def("pressure", &F::pressure)
        .def("porosity", &F::porosity)
        .def("porosity_rate", &F::porosity_rate)
        .def("particle_diameter", &F::particle_diameter)
        .def("particle_velocity", &F::particle_velocity)
        .def("velocity", &F::velocity)
        .def("darcy_flux", &F::darcy_flux)
        .def("conductivity", &F::conductivity)
        .def("write_vtk", &F::write_vtk, py::arg("path"))
        .def("write_checkpoint", &F::write_checkpoint, py::arg("path"), py::arg("simulation"))
        .def("restore", &F::restore, py::arg("path"));
}

} // namespace sphere_python
