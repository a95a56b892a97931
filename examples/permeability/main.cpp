// permeability: a pressure difference drives fluid up through a fixed packing (the set-up of
// VALIDATION F8; docs/examples.md). A simple-cubic bed of fixed spheres fills a column periodic
// in x and y; the bottom and top cell layers hold prescribed pressures. The run goes on until
// the flow is steady and prints the superficial velocity U, the pressure profile, -dp/dz, the
// permeability k = mu U / (-dp/dz) and Ergun's predictions for the porosity the code computed.
// Writes the bed (.vtu), fluid frames (.vti) and a CSV series.
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
#include <limits>
#include <string>
#include <vector>

namespace {

struct options : example::run_options {
    double dp = 8;                   // bottom minus top pressure (Pa)
    double diameter = 1e-3;          // particle diameter = lattice spacing (m); fluid cells are 2 d wide
    double fluid_density = 1000;     // kg/m^3
    double viscosity = 1e-3;         // Pa s
    unsigned nx = 4;                 // fluid cells along x and y
    unsigned nz = 12;                // fluid cells along z
    double offset = 0.262886786;     // lattice offset from the cell centres (spacings)
    double dt = 5e-4;                // fluid (and DEM) time step (s)
    double duration = 0.2;           // longest simulated time (s)
    double steady = 1e-7;            // relative change of U per step that counts as steady
    double output_interval = 0.01;   // s
};

/// The measured state of the bed's interior: cells 2 .. nz - 4 (away from the prescribed
/// layers and the cells next to them).
struct bed_state {
    double U = 0;         ///< superficial velocity: mean of phi_f w over the interior z faces (m/s)
    double phi = 0;       ///< mean porosity of the interior cells
    double gradient = 0;  ///< -dp/dz between the mean pressures of layers 2 and nz - 3 (Pa/m)
    std::vector<double> p_layer, phi_layer;  ///< mean pressure (Pa) and porosity of every layer
};

template <class Coupling>
bed_state measure(Coupling& coupled)
{
    const auto& g = coupled.fluid().grid();
    const auto p = coupled.fluid().pressure();
    const auto w = coupled.fluid().face_velocity(2);
    const auto phi = coupled.fluid().porosity();
    const int nx = int(g.n[0]), ny = int(g.n[1]), nz = int(g.n[2]);
    const double per_layer = double(nx) * ny;
    bed_state s;
    s.p_layer.assign(nz, 0.0);
    s.phi_layer.assign(nz, 0.0);
    double count = 0;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const std::size_t c = g.field_index(i, j, k);
                s.p_layer[k] += double(p[c]) / per_layer;
                s.phi_layer[k] += double(phi[c]) / per_layer;
                if (k >= 2 && k < nz - 3) {
                    const double phi_f = 0.5 * (double(phi[c]) + double(phi[g.field_index(i, j, k + 1)]));
                    s.U += phi_f * double(w[c]);
                    s.phi += double(phi[c]);
                    count += 1;
                }
            }
    s.U /= count;
    s.phi /= count;
    s.gradient = (s.p_layer[2] - s.p_layer[nz - 3]) / ((nz - 5) * double(g.width.z));
    return s;
}

template <class Real>
int run(const options& o)
{
    using namespace sphere;
    using Coupling = fluid_coupling<Real, host, drag::ergun, cg_poisson<Real, host>>;
    const double d = o.diameter, cell = 2 * d, mu = o.viscosity, rho = o.fluid_density;
    const int nz = int(o.nz);

    settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(o.nx * cell), Real(o.nx * cell), Real(nz * cell)};
    s.box.axis[0] = s.box.axis[1] = boundary::periodic;
    s.contact.k_n = s.wall.k_n = s.contact.k_t = s.wall.k_t = Real(1e-4);  // fixed particles: no contacts act
    s.dt = Real(o.dt);
    // Simple cubic bed, spacing d, touching spheres (solid fraction pi/6), 2 per cell across and
    // along z; the lattice sits `offset` spacings off the cell centres (see docs/fluid.md,
    // Coupling: there the cell-sphere porosity equals the bed's 1 - pi/6).
    const double shift = 1 - o.offset;
    std::vector<particle<Real>> bed;
    for (int k = 0; k < 2 * nz - 1; ++k)
        for (unsigned j = 0; j < 2 * o.nx; ++j)
            for (unsigned i = 0; i < 2 * o.nx; ++i) {
                particle<Real> p;
                p.position = {Real((i + shift) * d), Real((j + shift) * d), Real((k + shift) * d)};
                p.radius = Real(d / 2);
                p.density = 2600;
                p.kind = motion::fixed;
                bed.push_back(p);
            }
    simulation<Real> sim(s, bed);

    fluid_params<Real> prm;
    prm.density = Real(rho);
    prm.viscosity = Real(mu);
    prm.bottom = fluid_boundary<Real>::prescribed_pressure(Real(o.dp));
    prm.top = fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-4;
    coupling_options opt;
    opt.dem_steps = 1;
    Coupling coupled(fluid_grid<Real>::make(s.box, o.nx, o.nx, nz), prm, opt);

    std::printf("permeability: %zu fixed spheres d = %g m (simple cubic, offset %.9g spacings), fluid rho = %g "
                "kg/m^3, mu = %g Pa s (%s)\n",
                bed.size(), d, o.offset, rho, mu, o.precision.c_str());
    std::printf("fluid grid %u x %u x %d cells of %g m; p = %g Pa at the bottom layer, 0 at the top; dt = %g s\n", o.nx,
                o.nx, nz, cell, o.dp, o.dt);

    const std::size_t per_output = std::max<std::size_t>(1, std::size_t(std::llround(o.output_interval / o.dt)));
    const std::size_t max_steps = std::max<std::size_t>(1, std::size_t(std::llround(o.duration / o.dt)));
    vtk_writer particles_out(o.out, "particles", 1);
    particles_out.write(sim);  // the bed does not move: one frame
    vti_writer fluid_out(o.out, "fluid");
    csv_series csv(o.out + "/series.csv",
                   {"time_s", "superficial_velocity_m_s", "pressure_gradient_Pa_m", "permeability_m2", "porosity"});
    auto output = [&](const bed_state& b) {
        fluid_out.write(coupled, sim.time());
        csv.add_row({sim.time(), b.U, b.gradient, b.gradient > 0 ? mu * b.U / b.gradient : 0.0, b.phi});
        csv.flush();
    };

    const auto start = std::chrono::steady_clock::now();
    auto last = start;
    bed_state b = measure(coupled);
    output(b);
    // In float, U cannot settle below a few rounding errors per step.
    const double steady_tolerance = std::max(o.steady, 10.0 * double(std::numeric_limits<Real>::epsilon()));
    std::size_t n = 0;
    bool steady = false;
    double change = 0;
    while (n < max_steps) {
        coupled.step(sim);
        ++n;
        const bed_state now = measure(coupled);
        change = std::fabs(now.U - b.U) / std::max(std::fabs(now.U), 1e-300);
        b = now;
        steady = n >= 10 && change < steady_tolerance;
        if (n % per_output == 0 || steady || n == max_steps) output(b);
        const auto clock = std::chrono::steady_clock::now();
        if (!o.quiet && (clock - last > std::chrono::seconds(1) || steady || n == max_steps)) {
            last = clock;
            std::fprintf(stderr, "\rpermeability: t = %.4f s  U = %.6e m/s  change %.1e/step  (%.0f s)   ", sim.time(),
                         b.U, change, std::chrono::duration<double>(clock - start).count());
        }
        if (steady) break;
    }
    if (!o.quiet) std::fprintf(stderr, "\n");
    csv.close();
    if (steady)
        std::printf("steady after %.4f s (%zu steps): U changed by %.2e of itself in the last step (< %.1e)\n",
                    sim.time(), n, change, steady_tolerance);
    else
        std::printf("NOT steady after %.4f s (%zu steps): U still changes by %.2e per step; use a longer --time\n",
                    sim.time(), n, change);

    std::printf("\n%5s %12s %14s %10s\n", "layer", "z (m)", "mean p (Pa)", "porosity");
    for (int k = 0; k < nz; ++k)
        std::printf("%5d %12.6f %14.6f %10.6f%s\n", k, (k + 0.5) * cell, b.p_layer[k], b.phi_layer[k],
                    k == 0 ? "  (prescribed)" : k == nz - 1 ? "  (prescribed)" : (k >= 2 && k <= nz - 3) ? "" : "  (edge)");
    std::printf("\n");

    const double phi = b.phi, U = b.U;
    const double k_code = mu * U / b.gradient;
    const double k_ergun = phi * phi * phi * d * d / (150 * (1 - phi) * (1 - phi));
    const double ergun_linear = mu * U / k_ergun;
    const double ergun = ergun_linear + 1.75 * (1 - phi) * rho * U * U / (phi * phi * phi * d);
    std::printf("%-44s %14.6f\n", "porosity of the bed (interior cells)", phi);
    std::printf("%-44s %14.6e\n", "superficial velocity U (m/s)", U);
    std::printf("%-44s %14.6e\n", "pressure gradient -dp/dz (Pa/m)", b.gradient);
    std::printf("%-44s %14.6e\n", "permeability k = mu U / (-dp/dz) (m^2)", k_code);
    std::printf("%-44s %14.6e  (k / k_Ergun = %.4f)\n", "Ergun k = phi^3 d^2 / (150 (1-phi)^2) (m^2)", k_ergun,
                k_code / k_ergun);
    std::printf("%-44s %14.6e  (measured / Ergun = %.4f)\n", "Ergun -dp/dz at U, full (Pa/m)", ergun,
                b.gradient / ergun);
    std::printf("%-44s %14.4g\n", "Reynolds number rho U d / (mu (1 - phi))", rho * U * d / (mu * (1 - phi)));
    std::printf("output in %s/: particles.pvd (%zu frames), fluid.pvd (%zu frames), series.csv (%zu rows)\n",
                o.out.c_str(), particles_out.collection().entries().size(), fluid_out.frames(), csv.rows());
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    o.out = "permeability-output";
    CLI::App app{"permeability: a pressure difference drives fluid through a fixed simple-cubic bed until the flow "
                 "is steady; prints the flux, the pressure profile, the permeability and Ergun's predictions"};
    app.add_option("--dp", o.dp, "pressure of the bottom layer minus that of the top layer (Pa)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("-d,--diameter", o.diameter, "particle diameter = lattice spacing (m); cells are 2 d wide")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--fluid-density", o.fluid_density, "fluid density (kg/m^3)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--viscosity", o.viscosity, "dynamic viscosity mu (Pa s)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--nx", o.nx, "fluid cells along x and y (periodic)")->check(CLI::Range(2, 1000))
        ->capture_default_str();
    app.add_option("--nz", o.nz, "fluid cells along z, the flow direction")->check(CLI::Range(7, 100000))
        ->capture_default_str();
    app.add_option("--offset", o.offset, "lattice offset from the cell centres (spacings)")
        ->check(CLI::Range(0.0, 1.0))->capture_default_str();
    app.add_option("--dt", o.dt, "time step (s)")->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--time", o.duration, "longest simulated time (s); the run stops earlier when steady")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--steady", o.steady, "steady when U changes by less than this fraction in one step (at least 10 epsilon of the precision)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--output-interval", o.output_interval, "simulated time between outputs (s)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    example::add_run_options(app, o);
    CLI11_PARSE(app, argc, argv);
    return example::run_in_precision(o, [&](auto real) { return run<decltype(real)>(o); });
}
