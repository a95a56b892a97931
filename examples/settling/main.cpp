// settling: one sphere sinking through a column of viscous fluid (the set-up of VALIDATION F6;
// docs/examples.md). The fluid is coupled to the particle both ways (sphere::fluid_coupling,
// docs/fluid.md): the sphere accelerates until drag and buoyancy balance its weight. Prints
// the particle and fluid velocities against time, and at the end the terminal slip velocity
// next to Stokes' law and the Schiller-Naumann / Wen-Yu terminal velocity for the porosity of
// the particle's fluid cell. Writes particle frames (.vtu), fluid frames (.vti) and a CSV series.
#include <sphere/dem.cuh>
#include <sphere/fluid.cuh>
#include <sphere/io.cuh>
#include <sphere/io/vti.cuh>

#include <CLI/CLI.hpp>

#include "../common/run_options.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace {

constexpr double pi = 3.14159265358979323846;

struct options : example::run_options {
    double diameter = 1e-3;         // m
    double particle_density = 2600; // kg/m^3
    double fluid_density = 1000;    // kg/m^3
    double viscosity = 0.1;         // Pa s
    double gravity = 9.81;          // m/s^2
    double cell = 5e-3;             // fluid cell width (m)
    unsigned nx = 4;                // fluid cells along x and y (periodic)
    unsigned nz = 40;               // fluid cells along z
    double k_n = 100;               // N/m (k_t = k_n)
    unsigned dem_steps = 20;        // DEM steps per fluid step
    double duration = 0.04;         // s
    double output_interval = 0.002; // s
    bool no_pressure_force = false;
};

template <class Real>
int run(const options& o)
{
    using namespace sphere;
    using Sim = simulation<Real>;
    using Coupling = fluid_coupling<Real, host, drag::wen_yu, cg_poisson<Real, host>>;

    settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(o.nx * o.cell), Real(o.nx * o.cell), Real(o.nz * o.cell)};
    s.box.axis[0] = s.box.axis[1] = boundary::periodic;
    s.contact.k_n = s.wall.k_n = s.contact.k_t = s.wall.k_t = Real(o.k_n);
    s.gravity = {0, 0, Real(-o.gravity)};
    particle<Real> p;
    const double x0 = (double(o.nx / 2) - 0.5) * o.cell;  // centre of a cell: 1.5 cells for nx = 4
    p.position = {Real(x0), Real(x0), Real((double(o.nz) - 5.5) * o.cell)};
    p.radius = Real(o.diameter / 2);
    p.density = Real(o.particle_density);
    Sim sim(s, {p});

    fluid_params<Real> prm;
    prm.density = Real(o.fluid_density);
    prm.viscosity = Real(o.viscosity);
    prm.gravity = s.gravity;
    prm.bottom = fluid_boundary<Real>::no_flow();
    prm.top = fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-4;
    coupling_options opt;
    opt.dem_steps = o.dem_steps;
    opt.pressure_force = !o.no_pressure_force;
    // VALIDATION F6's reference porosity (0.992) is the seeds' cell-sphere estimate.
    opt.porosity = porosity_method::cell_sphere;
    Coupling coupled(fluid_grid<Real>::make(s.box, o.nx, o.nx, o.nz), prm, opt);
    const fluid_grid<Real>& grid = coupled.fluid().grid();

    const double dt_f = double(sim.dt()) * o.dem_steps;
    const std::size_t per_output = std::max<std::size_t>(1, std::size_t(std::llround(o.output_interval / dt_f)));
    // Whole output intervals, so that the last step is an output (the duration rounded up).
    std::size_t fluid_steps = std::max<std::size_t>(1, std::size_t(std::llround(o.duration / dt_f)));
    fluid_steps = (fluid_steps + per_output - 1) / per_output * per_output;
    std::printf("settling: sphere d = %g m, rho_p = %g kg/m^3 in fluid rho_f = %g kg/m^3, mu = %g Pa s (%s)\n",
                o.diameter, o.particle_density, o.fluid_density, o.viscosity, o.precision.c_str());
    std::printf("fluid grid %u x %u x %u cells of %g m; DEM dt = %.4g s, fluid dt = %.4g s (%u DEM steps); "
                "%zu fluid steps; %s\n",
                o.nx, o.nx, o.nz, o.cell, double(sim.dt()), dt_f, o.dem_steps, fluid_steps,
                opt.pressure_force ? "with the pressure-gradient force" : "without the pressure-gradient force");

    vtk_writer particles_out(o.out, "particles", per_output * o.dem_steps);
    vti_writer fluid_out(o.out, "fluid");
    csv_series csv(o.out + "/series.csv",
                   {"time_s", "z_m", "v_p_m_s", "v_f_m_s", "slip_m_s", "porosity", "pressure_Pa"});

    struct sample {
        double z, v_p, v_f, slip, phi, p;
    };
    auto measure = [&]() {
        const particle_snapshot<Real> snap = sim.snapshot();
        int c[3];
        grid.cell_of(snap.position(0), c);
        const std::size_t f = grid.field_index(c[0], c[1], c[2]);
        sample m;
        m.z = double(snap.x[0].z);
        m.v_p = double(snap.v_sync[0].z);
        m.v_f = double(coupled.fluid().cell_velocity()[f].z);
        m.slip = m.v_f - m.v_p;
        m.phi = double(coupled.fluid().porosity()[f]);
        m.p = double(coupled.fluid().pressure()[f]);
        return m;
    };
    std::printf("%10s %12s %14s %14s %14s %10s\n", "t (s)", "z (m)", "v_p (m/s)", "v_f (m/s)", "slip (m/s)",
                "porosity");
    auto output = [&]() {
        const sample m = measure();
        particles_out.write(sim);
        fluid_out.write(coupled, sim.time());
        csv.add_row({sim.time(), m.z, m.v_p, m.v_f, m.slip, m.phi, m.p});
        csv.flush();
        if (!o.quiet) std::fprintf(stderr, "\r%79s\r", ""); // clear the progress line
        std::printf("%10.5f %12.6f %14.6e %14.6e %14.6e %10.6f\n", sim.time(), m.z, m.v_p, m.v_f, m.slip, m.phi);
        std::fflush(stdout);
    };

    const auto start = std::chrono::steady_clock::now();
    auto last = start;
    output();
    for (std::size_t n = 1; n <= fluid_steps; ++n) {
        coupled.step(sim);
        if (n % per_output == 0) output();
        const auto now = std::chrono::steady_clock::now();
        if (!o.quiet && (now - last > std::chrono::seconds(1) || n == fluid_steps)) {
            last = now;
            std::fprintf(stderr, "\rsettling: %5.1f%%  t = %.4f s  (%.0f s)   ", 100.0 * double(n) / double(fluid_steps),
                         sim.time(), std::chrono::duration<double>(now - start).count());
        }
    }
    if (!o.quiet) std::fprintf(stderr, "\n");
    csv.close();

    // Terminal velocity: the force balance with Wen-Yu (Schiller-Naumann C_d) at the porosity
    // of the particle's cell, at phi = 1 (an isolated sphere), and Stokes' law.
    const sample m = measure();
    const double d = o.diameter, V = pi / 6 * d * d * d, g = o.gravity;
    const double force = (opt.pressure_force ? o.particle_density - o.fluid_density : o.particle_density) * g * V;
    const double stokes = force / (3 * pi * o.viscosity * d);
    const double wen_yu = drag::terminal_speed<drag::wen_yu>(force, m.phi, d, o.fluid_density, o.viscosity);
    const double isolated = drag::terminal_speed<drag::wen_yu>(force, 1.0, d, o.fluid_density, o.viscosity);
    const double reynolds = m.phi * o.fluid_density * d * wen_yu / o.viscosity;
    const double response =
        o.particle_density / drag::wen_yu::beta_per_solid(m.phi, d, wen_yu, o.fluid_density, o.viscosity);
    std::printf("%-46s %14.6e\n", "terminal slip velocity v_f - v_p (m/s)", m.slip);
    std::printf("%-46s %14.6e  (%+.2f%%)\n",
                opt.pressure_force ? "Stokes (rho_p - rho_f) g d^2 / (18 mu) (m/s)" : "Stokes rho_p g d^2 / (18 mu) (m/s)",
                stokes, 100 * (m.slip / stokes - 1));
    std::printf("%-46s %14.6e  (%+.2f%%)\n", "Schiller-Naumann, isolated sphere (m/s)", isolated,
                100 * (m.slip / isolated - 1));
    char label[64];
    std::snprintf(label, sizeof label, "Wen-Yu at the cell porosity %.6f (m/s)", m.phi);
    std::printf("%-46s %14.6e  (%+.2f%%)\n", label, wen_yu, 100 * (m.slip / wen_yu - 1));
    std::printf("%-46s %14.4g\n", "particle Reynolds number phi rho_f d u / mu", reynolds);
    std::printf("%-46s %14.4g  (run: %.1f response times)\n", "particle response time m / drag coeff. (s)", response,
                sim.time() / response);
    if (sim.time() < 10 * response)
        std::printf("note: the run is shorter than 10 response times; the particle may not have reached its "
                    "terminal velocity (use a longer --time)\n");
    std::printf("output in %s/: particles.pvd (%zu frames), fluid.pvd (%zu frames), series.csv (%zu rows)\n",
                o.out.c_str(), particles_out.collection().entries().size(), fluid_out.frames(), csv.rows());
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    o.out = "settling-output";
    CLI::App app{"settling: one sphere sinking through a viscous fluid column (two-way coupled); prints its "
                 "velocity, the fluid's and the slip against time, and the terminal slip velocity against Stokes "
                 "and Schiller-Naumann/Wen-Yu"};
    app.add_option("-d,--diameter", o.diameter, "particle diameter (m)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--particle-density", o.particle_density, "particle density rho_p (kg/m^3)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--fluid-density", o.fluid_density, "fluid density rho_f (kg/m^3)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--viscosity", o.viscosity, "dynamic viscosity mu (Pa s)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--gravity", o.gravity, "gravitational acceleration, downwards (m/s^2)")
        ->check(CLI::NonNegativeNumber)->capture_default_str();
    app.add_option("--cell", o.cell, "fluid cell width (m)")->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--nx", o.nx, "fluid cells along x and y (periodic)")->check(CLI::Range(2, 1000))
        ->capture_default_str();
    app.add_option("--nz", o.nz, "fluid cells along z (no-flow bottom, p = 0 on top)")->check(CLI::Range(8, 100000))
        ->capture_default_str();
    app.add_option("--kn", o.k_n, "contact stiffness k_n = k_t (N/m); sets the DEM time step")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--dem-steps", o.dem_steps, "DEM steps per fluid step")->check(CLI::Range(1, 1000000))
        ->capture_default_str();
    app.add_option("--time", o.duration, "simulated time (s)")->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--output-interval", o.output_interval, "simulated time between outputs (s)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_flag("--no-pressure-force", o.no_pressure_force,
                 "leave out the pressure-gradient (buoyancy) force on the particle");
    example::add_run_options(app, o);
    CLI11_PARSE(app, argc, argv);
    return example::run_in_precision(o, [&](auto real) { return run<decltype(real)>(o); });
}
