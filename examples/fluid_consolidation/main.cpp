// fluid_consolidation: consolidation with pore fluid (docs/examples.md). A sample poured under
// gravity (examples/common/granular.hpp, periodic in x and y) is saturated with a viscous pore
// fluid on a fluid grid over the world box (sphere::fluid_coupling, docs/fluid.md), drained at
// the top (p = 0 on the top cell layer, above the sample) and undrained at the bottom (no
// flow). After a short rest the upper wall loads the sample at a normal stress: the fluid
// cannot leave the pores at once, so the excess pore pressure (p minus the hydrostatic
// rho_f g (z_top - z)) rises and then decays as the fluid drains through the top while the
// sample settles (Terzaghi consolidation, time ~ H^2 mu / (k M)). Writes particle frames
// (.vtu), fluid frames (.vti) and a CSV series of the wall, the porosity and the excess pore
// pressures; prints the peak excess pressure at the bottom, its value at the end and the
// settlement.
#include "../common/granular.hpp"

#include <sphere/fluid.cuh>
#include <sphere/io/vti.cuh>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace {

struct options {
    granular::sample_options sample;
    double stress = 1e4;            // Pa
    double duration = 0.6;          // s of loading
    double rest = 0.02;             // s with the fluid before the load
    double viscosity = 10;          // Pa s
    double fluid_density = 1000;    // kg/m^3
    double cell_diameters = 2.5;    // fluid cell width in mean particle diameters
    unsigned dem_steps = 0;         // DEM steps per fluid step; 0: automatic
    double safety = 0.2;            // automatic fluid step: this fraction of the smallest limit
};

/// What one output row holds.
struct state {
    double time = 0;        ///< s
    double wall = 0;        ///< upper wall position (m)
    double wall_v = 0;      ///< its velocity (m/s, negative downwards)
    double porosity = 0;    ///< of the sample between the walls
    double bottom = 0;      ///< excess pore pressure, mean of the bottom cell layer (Pa)
    double mid = 0;         ///< ... of the layer holding the sample's mid-height (Pa)
    double mean = 0;        ///< ... mean of the layers whose centres lie in the sample (Pa)
};

template <class Real>
int run(const options& o)
{
    using namespace sphere;
    using Sim = granular::granular_sim<Real>;
    using Drag = drag::gidaspow;
    using Coupling = fluid_coupling<Real, host, Drag, cg_poisson<Real, host>>;
    const auto clock_start = std::chrono::steady_clock::now();

    Sim sim = granular::deposited_sample<Real>(o.sample, false, granular::contact_of<Real>(o.sample));
    const world<Real> box = sim.config().box;
    const double z_bottom = sim.walls().face[4].position;
    const double z_sample = sim.walls().face[5].position;
    const double height = z_sample - z_bottom;
    const double d = 2 * o.sample.radius;
    const double g = -double(sim.config().gravity.z);
    std::printf("fluid_consolidation: %zu particles (%s), deposited in %.3f s; sample %.4f m high "
                "(walls at %.4f and %.4f m), porosity %.4f\n",
                sim.size(), o.sample.precision.c_str(), sim.time(), height, z_bottom, z_sample,
                bulk_porosity(sim).porosity);

    // Fluid grid over the world box: near-cubic cells of about cell_diameters mean diameters,
    // at least 3 across (the porosity estimator's periodic check) and along z.
    const double width_x = double(box.hi.x - box.lo.x), width_y = double(box.hi.y - box.lo.y);
    const double box_height = double(box.hi.z - box.lo.z);
    const double target = o.cell_diameters * d;
    const unsigned nx = std::max(3u, unsigned(std::lround(width_x / target)));
    const unsigned ny = std::max(3u, unsigned(std::lround(width_y / target)));
    const unsigned nz = std::max(3u, unsigned(std::lround(box_height / (width_x / nx))));
    const fluid_grid<Real> grid = fluid_grid<Real>::make(box, nx, ny, nz);
    const double h = double(grid.width.z);
    const double z_top_layer = double(box.hi.z) - h / 2;  // where p = 0 is held
    if (double(box.hi.z) - h <= z_sample)
        throw error("fluid_consolidation: the top cell layer (from " + std::to_string(double(box.hi.z) - h) +
                    " m) reaches into the sample (top at " + std::to_string(z_sample) +
                    " m); use smaller cells (--cell-diameters)");

    fluid_params<Real> prm;
    prm.density = Real(o.fluid_density);
    prm.viscosity = Real(o.viscosity);
    prm.gravity = sim.config().gravity;
    prm.bottom = fluid_boundary<Real>::no_flow();
    prm.top = fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-4;

    // The fluid time step: below the diffusive limit of the fluid (navier_stokes::
    // stable_time_step() for the sample's porosity) and the particle response time
    // m / (drag coefficient) the coupling checks, both for the porosity of the deposited
    // sample, by the factor `safety` (the sample compacts; the collective response of the
    // pressure is faster than one particle's).
    double response = std::numeric_limits<double>::infinity(), phi_min = 1;
    {
        const particle_snapshot<Real> snap = sim.snapshot();
        const porosity_fields<Real> por = estimate_porosity(snap, grid);
        for (int k = 0; k < int(nz); ++k)
            for (int j = 0; j < int(ny); ++j)
                for (int i = 0; i < int(nx); ++i) phi_min = std::min(phi_min, double(por.phi[grid.field_index(i, j, k)]));
        for (std::size_t i = 0; i < snap.size(); ++i) {
            int cell[3];
            grid.cell_of(snap.position(i), cell);
            const std::size_t c = grid.field_index(cell[0], cell[1], cell[2]);
            const double beta = double(Drag::beta_per_solid(por.phi[c], por.d_p[c], Real(0), prm.density, prm.viscosity));
            response = std::min(response, o.sample.density / beta);
        }
    }
    coupling_options opt;
    Coupling probe(grid, prm, opt);
    {
        porosity_estimator<Real, host> est(grid);
        est.update(sim.snapshot(), Real(1));
        probe.fluid().set_porosity(est.view());
    }
    const double diffusive = double(probe.fluid().stable_time_step());
    const double dt = double(sim.dt());
    const double limit = std::min(response, diffusive);
    opt.dem_steps = o.dem_steps > 0 ? o.dem_steps : unsigned(std::max(1.0, std::floor(o.safety * limit / dt)));
    const double dt_f = opt.dem_steps * dt;
    Coupling coupled(grid, prm, opt);

    // Consolidation time estimate: Kozeny-Carman permeability for the sample's porosity, the
    // 1D stiffness of the dry sample (measured at the end from the settlement).
    const double phi0 = bulk_porosity(sim).porosity;
    const double k_kc = phi0 * phi0 * phi0 * d * d / (180 * (1 - phi0) * (1 - phi0));
    std::printf("fluid rho_f = %g kg/m^3, mu = %g Pa s; grid %u x %u x %u cells of %.4g m (%.2f diameters); "
                "p = 0 on the top layer (z = %.4f m), no flow at the bottom\n",
                o.fluid_density, o.viscosity, nx, ny, nz, h, h / d, z_top_layer);
    std::printf("DEM dt = %.4g s; limits of the fluid step: particle response time %.4g s, fluid stability %.4g s "
                "(min porosity %.3f)\n",
                dt, response, diffusive, phi_min);
    std::printf("fluid dt = %.4g s = %u DEM steps (%s); Kozeny-Carman k = %.4g m^2 at porosity %.4f\n", dt_f,
                opt.dem_steps, o.dem_steps > 0 ? "--dem-steps" : "automatic", k_kc, phi0);
    if (dt_f > limit)
        std::printf("warning: the fluid step exceeds the smaller limit %.4g s; the run may fail\n", limit);

    // Outputs every output interval (whole fluid steps).
    const std::size_t per_output =
        std::max<std::size_t>(1, std::size_t(std::llround(o.sample.output_interval / dt_f)));
    const std::size_t rest_steps = std::max<std::size_t>(1, std::size_t(std::llround(o.rest / dt_f)));
    std::size_t load_steps = std::max<std::size_t>(1, std::size_t(std::llround(o.duration / dt_f)));
    load_steps = (rest_steps + load_steps + per_output - 1) / per_output * per_output - rest_steps;
    const std::size_t fluid_steps = rest_steps + load_steps;

    vtk_writer particles_out(o.sample.out, "particles", per_output * opt.dem_steps);
    vti_writer fluid_out(o.sample.out, "fluid");
    csv_series csv(o.sample.out + "/series.csv",
                   {"time_s", "wall_z_m", "wall_velocity_m_s", "porosity", "excess_p_bottom_Pa", "excess_p_mid_Pa",
                    "excess_p_mean_Pa"});

    auto measure = [&]() {
        state s;
        s.time = sim.time();
        s.wall = sim.walls().face[5].position;
        s.wall_v = sim.walls().face[5].velocity;
        s.porosity = bulk_porosity(sim).porosity;
        const std::vector<Real> p = coupled.fluid().pressure();
        const double z_lo = sim.walls().face[4].position, z_hi = s.wall, z_mid = 0.5 * (z_lo + z_hi);
        const double rho_g = o.fluid_density * g;
        double sum = 0;
        int layers = 0;
        for (int k = 0; k < int(nz); ++k) {
            double mean = 0;
            for (int j = 0; j < int(ny); ++j)
                for (int i = 0; i < int(nx); ++i) mean += double(p[grid.field_index(i, j, k)]);
            mean /= double(nx) * ny;
            const double z = double(box.lo.z) + (k + 0.5) * h;
            const double excess = mean - rho_g * (z_top_layer - z);
            if (k == 0) s.bottom = excess;
            if (z_mid >= z - h / 2 && z_mid < z + h / 2) s.mid = excess;
            if (z >= z_lo && z <= z_hi) {
                sum += excess;
                ++layers;
            }
        }
        s.mean = layers > 0 ? sum / layers : s.bottom;
        return s;
    };

    double t_load = 0, z_load = z_sample;
    state peak;
    peak.bottom = -std::numeric_limits<double>::infinity();
    std::vector<state> rows;
    std::printf("%9s %10s %11s %9s %12s %12s %12s\n", "t (s)", "wall (m)", "v (m/s)", "porosity", "bottom (Pa)",
                "mid (Pa)", "mean (Pa)");
    auto output = [&](bool loaded) {
        const state s = measure();
        particles_out.write(sim);
        fluid_out.write(coupled, s.time);
        csv.add_row({s.time, s.wall, s.wall_v, s.porosity, s.bottom, s.mid, s.mean});
        csv.flush();
        rows.push_back(s);
        if (loaded && s.bottom > peak.bottom) peak = s;
        if (!o.sample.quiet) std::fprintf(stderr, "\r%79s\r", "");  // clear the progress line
        std::printf("%9.4f %10.6f %11.3e %9.5f %12.2f %12.2f %12.2f\n", s.time, s.wall, s.wall_v, s.porosity, s.bottom,
                    s.mid, s.mean);
        std::fflush(stdout);
    };

    const auto start = std::chrono::steady_clock::now();
    auto last = start;
    for (std::size_t n = 1; n <= fluid_steps; ++n) {
        if (n == rest_steps + 1) {  // the load: the upper wall is stress-controlled from here
            t_load = sim.time();
            z_load = sim.walls().face[5].position;
            sim.set_wall_control(5, granular::stress_wall(o.sample, sim, o.stress));
            std::printf("load: %.0f Pa on the upper wall at t = %.4f s\n", o.stress, t_load);
        }
        coupled.step(sim);
        // The first row after the first step (before it the fluid has no pressure yet).
        if (n == 1 || n % per_output == 0) output(n > rest_steps);
        const auto now = std::chrono::steady_clock::now();
        if (!o.sample.quiet && (now - last > std::chrono::seconds(1) || n == fluid_steps)) {
            last = now;
            std::fprintf(stderr, "\rfluid_consolidation: %5.1f%%  t = %.4f s  wall z = %.6f m  (%.0f s)   ",
                         100.0 * double(n) / double(fluid_steps), sim.time(), sim.walls().face[5].position,
                         std::chrono::duration<double>(now - start).count());
        }
    }
    if (!o.sample.quiet) std::fprintf(stderr, "\n");
    csv.close();

    // Summary: the peak excess pressure at the bottom, its decay, the settlement, and the
    // consolidation time H^2 mu / (k M) with M = stress / strain of the settlement from the
    // peak on (what the draining fluid allowed; the part before it happens at once).
    const state end = rows.back();
    const double settlement = z_load - end.wall;
    const double strain = settlement / (z_load - z_bottom);
    const double strain_drained = (peak.wall - end.wall) / (z_load - z_bottom);
    const double modulus = strain_drained > 0 ? o.stress / strain_drained : 0;
    const double t_c = modulus > 0 ? height * height * o.viscosity / (k_kc * modulus) : 0;
    // Decay: the first rows after which the bottom excess stays below 50% and 10% of the peak;
    // Terzaghi's late-time decay exp(-pi^2/4 t/T) between them gives a measured T.
    auto settled_below = [&](double fraction) -> const state* {
        const state* found = nullptr;
        for (auto it = rows.rbegin(); it != rows.rend() && it->time > peak.time; ++it) {
            if (it->bottom >= fraction * peak.bottom) break;
            found = &*it;
        }
        return found;
    };
    const state* s50 = settled_below(0.5);
    const state* s10 = settled_below(0.1);
    const double t_decay = s10 ? s10->time - t_load : -1;
    const double t_fit = (s50 && s10 && s10->time > s50->time && s10->bottom > 0)
                             ? pi<double> * pi<double> / 4 * (s10->time - s50->time) / std::log(s50->bottom / s10->bottom)
                             : 0;
    std::printf("%-46s %14.2f  at t = %.4f s (%.4f s after the load; load %.0f Pa)\n",
                "peak excess pore pressure at the bottom (Pa)", peak.bottom, peak.time, peak.time - t_load, o.stress);
    std::printf("%-46s %14.2f  (%.1f%% of the peak) at t = %.4f s\n", "excess pore pressure at the bottom, end (Pa)",
                end.bottom, peak.bottom != 0 ? 100 * end.bottom / peak.bottom : 0.0, end.time);
    if (t_decay >= 0)
        std::printf("%-46s %14.4f  (after the load)\n", "below 10% of the peak from (s)", t_decay);
    else
        std::printf("%-46s %14s  (use a longer --time)\n", "below 10% of the peak from (s)", "not yet");
    std::printf("%-46s %14.6e  (strain %.4f; %.4f from the peak on)\n", "settlement of the upper wall (m)", settlement,
                strain, strain_drained);
    std::printf("%-46s %14.4g\n", "1D modulus M = stress / strain from the peak (Pa)", modulus);
    std::printf("%-46s %14.4g\n", "consolidation time H^2 mu / (k_KC M) (s)", t_c);
    if (t_fit > 0)
        std::printf("%-46s %14.4g  (pi^2/4 dt / ln(p50/p10))\n", "consolidation time from the decay (s)", t_fit);
    std::printf("%-46s %14.1f\n", "wall-clock time (s)",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count());
    std::printf("output in %s/: particles.pvd (%zu frames), fluid.pvd (%zu frames), series.csv (%zu rows)\n",
                o.sample.out.c_str(), particles_out.collection().entries().size(), fluid_out.frames(), csv.rows());
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    o.sample.out = "fluid_consolidation-output";
    o.sample.particles = 500;
    CLI::App app{"fluid_consolidation: pour a sample, saturate it with a viscous pore fluid (drained top, undrained "
                 "bottom), then load it with the upper wall at a normal stress; writes the wall, the porosity and the "
                 "excess pore pressure against time"};
    granular::add_sample_options(app, o.sample);
    app.add_option("--stress", o.stress, "normal stress of the upper wall (Pa)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--time", o.duration, "duration of the loading (s)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--rest", o.rest, "time with the fluid before the load (s)")->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--viscosity", o.viscosity, "dynamic viscosity of the pore fluid (Pa s)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--fluid-density", o.fluid_density, "density of the pore fluid (kg/m^3)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--cell-diameters", o.cell_diameters, "fluid cell width in mean particle diameters")
        ->check(CLI::Range(1.0, 100.0))->capture_default_str();
    app.add_option("--dem-steps", o.dem_steps, "DEM steps per fluid step (0: automatic)")->capture_default_str();
    app.add_option("--safety", o.safety, "automatic fluid step: this fraction of the smaller stability limit")
        ->check(CLI::Range(0.001, 1.0))->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    return granular::run_in_precision(o.sample, [&](auto real) { return run<decltype(real)>(o); });
}
