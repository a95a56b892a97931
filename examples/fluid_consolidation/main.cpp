// fluid_consolidation: consolidation with pore fluid (docs/examples.md). A sample poured under
// gravity (examples/common/granular.hpp, periodic in x and y) is saturated with a viscous pore
// fluid on a fluid grid over the world box (sphere::fluid_coupling, docs/fluid.md: the Darcy
// model by default, or Navier-Stokes), drained at the top (p = 0 on the top cell layer, above
// the sample) and undrained at the bottom (no flow). After a short rest the upper wall loads the sample at a normal stress: the fluid
// cannot leave the pores at once, so the excess pore pressure (p minus the hydrostatic
// rho_f g (z_top - z)) rises and then decays as the fluid drains through the top while the
// sample settles (Terzaghi consolidation, time ~ H^2 mu / (k M)). Writes particle frames
// (.vtu), fluid frames (.vti), a CSV series of the wall, the porosity and the excess pore
// pressures, and terzaghi.csv, the settlement and the bottom's excess pressure next to
// Terzaghi's for the sample's measured modulus; prints the peak excess pressure at the
// bottom, its value at the end and the settlement.
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
#include <type_traits>
#include <vector>

namespace {

struct options {
    granular::sample_options sample;
    double stress = 1e4;            // Pa: the load step, on top of the preload
    double preload = 1e4;           // Pa: the dry sample's stress before the fluid
    double preload_time = 0.1;      // s of dry preloading
    double duration = 0.6;          // s of loading
    double rest = 0.02;             // s with the fluid before the load
    double viscosity = 10;          // Pa s
    double fluid_density = 1000;    // kg/m^3
    double cell_diameters = 2.5;    // fluid cell width in mean particle diameters
    unsigned dem_steps = 0;         // DEM steps per fluid step; 0: automatic
    double safety = 0.2;            // automatic fluid step: this fraction of the smallest limit
    std::string model = "darcy";    // darcy or navier-stokes
    double compressibility = 4.5e-10; // Darcy: pore fluid compressibility (1/Pa)
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

/// Terzaghi's excess pore pressure over its initial value at the closed end of a layer
/// drained at the other, at time factor T = c_v t / H^2: sum 2/M sin(M) exp(-M^2 T).
double terzaghi_closed_end(double T)
{
    double sum = 0;
    for (int m = 0; m < 200; ++m) {
        const double M = sphere::pi<double> * (2 * m + 1) / 2;
        sum += 2 / M * std::sin(M) * std::exp(-M * M * T);
    }
    return sum;
}

/// Terzaghi's degree of consolidation U(T) = 1 - sum 2/M^2 exp(-M^2 T).
double terzaghi_degree(double T)
{
    double sum = 0;
    for (int m = 0; m < 200; ++m) {
        const double M = sphere::pi<double> * (2 * m + 1) / 2;
        sum += 2 / (M * M) * std::exp(-M * M * T);
    }
    return 1 - sum;
}

template <class Real, template <class, class, class> class Model>
int run(const options& o)
{
    using namespace sphere;
    using Sim = granular::granular_sim<Real>;
    using Drag = drag::gidaspow;
    using Coupling = fluid_coupling<Real, host, Drag, cg_poisson<Real, host>, Model>;
    constexpr bool darcy = std::is_same_v<typename Coupling::model_type, darcy_flow<Real, host, cg_poisson<Real, host>>>;
    const auto clock_start = std::chrono::steady_clock::now();

    Sim sim = granular::prepared_sample<Real>(o.sample, false, granular::contact_of<Real>(o.sample));
    const double deposited = sim.time();
    // The dry preload: the loose deposit compacts under it (most of its plastic strain), so
    // that the load step meets a stiffer, nearly elastic skeleton, Terzaghi's assumption.
    if (o.preload > 0) {
        sim.set_wall_control(5, granular::stress_wall(o.sample, sim, o.preload));
        granular::run_steps<Sim>(sim, "preload", std::size_t(std::ceil(o.preload_time / double(sim.dt()))),
                                 o.sample.quiet, [](const Sim& s) {
                                     char text[64];
                                     std::snprintf(text, sizeof text, "wall z = %.6f m", s.walls().face[5].position);
                                     return std::string(text);
                                 });
    }
    const world<Real> box = sim.config().box;
    const double z_bottom = sim.walls().face[4].position;
    const double z_sample = sim.walls().face[5].position;
    const double height = z_sample - z_bottom;
    const double d = 2 * o.sample.radius;
    const double g = -double(sim.config().gravity.z);
    std::printf("fluid_consolidation: %zu particles (%s), sample at t = %.3f s, preloaded dry at %.0f Pa for %.3f s; "
                "sample %.4f m high (walls at %.4f and %.4f m), porosity %.4f\n",
                sim.size(), o.sample.precision.c_str(), deposited, o.preload, o.preload > 0 ? o.preload_time : 0.0,
                height, z_bottom, z_sample, bulk_porosity(sim).porosity);

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

    // The Darcy model's parameters: Carman's Kozeny-Carman constant d^2 / 180 for the mean
    // diameter, the pore fluid's compressibility.
    const auto params = [&]() {
        if constexpr (darcy) {
            darcy_params<Real> dp;
            dp.fluid = prm;
            dp.compressibility = Real(o.compressibility);
            dp.permeability_prefactor = Real(d * d / 180);
            return dp;
        } else {
            return prm;
        }
    }();

    // The fluid time step, by the factor `safety` below the particle response time to the
    // fluid for the porosity of the deposited sample (the sample compacts; the collective
    // response of the pressure is faster than one particle's): m / (drag coefficient) for
    // Navier-Stokes, rho_s (1 - phi) k / (mu phi^2) for Darcy (docs/fluid.md (D-6)); and for
    // Navier-Stokes below its
    // diffusive limit (navier_stokes::stable_time_step()).
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
            double r = 0;
            if constexpr (darcy) {
                const double phi = std::min(double(por.phi[c]), double(params.max_porosity));
                r = o.sample.density * (1 - phi) * double(params.permeability(Real(phi))) / (o.viscosity * phi * phi);
            } else {
                r = o.sample.density /
                    double(Drag::beta_per_solid(por.phi[c], por.d_p[c], Real(0), prm.density, prm.viscosity));
            }
            response = std::min(response, r);
        }
    }
    coupling_options opt;
    double diffusive = std::numeric_limits<double>::infinity();
    if constexpr (!darcy) {
        Coupling probe(grid, params, opt);
        porosity_estimator<Real, host> est(grid);
        est.update(sim.snapshot(), Real(1));
        probe.fluid().set_porosity(est.view());
        diffusive = double(probe.fluid().stable_time_step());
    }
    const double dt = double(sim.dt());
    const double limit = std::min(response, diffusive);
    opt.dem_steps = o.dem_steps > 0 ? o.dem_steps : unsigned(std::max(1.0, std::floor(o.safety * limit / dt)));
    const double dt_f = opt.dem_steps * dt;
    Coupling coupled(grid, params, opt);

    // Consolidation time estimate: Kozeny-Carman permeability for the sample's porosity, the
    // 1D stiffness of the dry sample (measured at the end from the settlement).
    const double phi0 = bulk_porosity(sim).porosity;
    const double k_kc = phi0 * phi0 * phi0 * d * d / (180 * (1 - phi0) * (1 - phi0));
    std::printf("%s model; fluid rho_f = %g kg/m^3, mu = %g Pa s; grid %u x %u x %u cells of %.4g m (%.2f "
                "diameters); p = 0 on the top layer (z = %.4f m), no flow at the bottom\n",
                darcy ? "Darcy" : "Navier-Stokes", o.fluid_density, o.viscosity, nx, ny, nz, h, h / d, z_top_layer);
    std::printf("DEM dt = %.4g s; limits of the fluid step: particle response time %.4g s, fluid stability %.4g s "
                "(min porosity %.3f)\n",
                dt, response, diffusive, phi_min); // the Darcy step is unconditionally stable: inf
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
        if (n == rest_steps + 1) {  // the load step on the upper wall
            t_load = sim.time();
            z_load = sim.walls().face[5].position;
            sim.set_wall_control(5, granular::stress_wall(o.sample, sim, o.preload + o.stress));
            std::printf("load: %.0f Pa more on the upper wall (%.0f Pa) at t = %.4f s\n", o.stress, o.preload + o.stress,
                        t_load);
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

    // Terzaghi for this sample: height H at the load, K = k_KC / mu at its porosity, and the
    // 1D compressibility m_v that makes Terzaghi's settlement at the end the measured one,
    // m_v H ds U(T_end) (found by fixed-point iteration: T_end depends on m_v through c_v =
    // K / (m_v + phi beta_f); beta_f = 0 for the incompressible Navier-Stokes fluid).
    const double beta_f = darcy ? o.compressibility : 0.0;
    const double K = k_kc / o.viscosity, t_end = end.time - t_load;
    double m_v = strain / o.stress;
    for (int it = 0; it < 100 && strain > 0; ++it) {
        const double T_end = K / (m_v + phi0 * beta_f) * t_end / (height * height);
        m_v = strain / (o.stress * terzaghi_degree(T_end));
    }
    const double c_v = K / (m_v + phi0 * beta_f), p0 = o.stress * m_v / (m_v + phi0 * beta_f);
    csv_series terzaghi(o.sample.out + "/terzaghi.csv",
                        {"time_s", "settlement_m", "terzaghi_settlement_m", "excess_p_bottom_Pa",
                         "terzaghi_excess_p_bottom_Pa"});
    double worst_settlement = 0, worst_pressure = 0;
    for (const state& r : rows) {
        if (r.time < t_load) continue;
        const double T = c_v * (r.time - t_load) / (height * height);
        const double s_theory = m_v * height * (o.stress - p0 + p0 * terzaghi_degree(T));
        const double p_theory = p0 * terzaghi_closed_end(T);
        terzaghi.add_row({r.time - t_load, z_load - r.wall, s_theory, r.bottom, p_theory});
        if (r.time == t_load) continue; // the load's instant: the pressure has not risen yet
        worst_settlement = std::max(worst_settlement, std::abs(z_load - r.wall - s_theory));
        worst_pressure = std::max(worst_pressure, std::abs(r.bottom - p_theory));
    }
    terzaghi.close();
    std::printf("%-46s %14.4g  (c_v = %.4g m^2/s, m_v = %.4g 1/Pa)\n", "Terzaghi's consolidation time H^2 / c_v (s)",
                height * height / c_v, c_v, m_v);
    std::printf("%-46s %14.3f  of the settlement at the end (after the load's instant)\n",
                "largest settlement - Terzaghi's",
                settlement > 0 ? worst_settlement / settlement : 0.0);
    std::printf("%-46s %14.3f  of the load (after the load's instant)\n", "largest bottom excess pressure - Terzaghi's",
                worst_pressure / o.stress);
    std::printf("%-46s %14.1f\n", "wall-clock time (s)",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count());
    std::printf("output in %s/: particles.pvd (%zu frames), fluid.pvd (%zu frames), series.csv (%zu rows), "
                "terzaghi.csv (%zu rows)\n",
                o.sample.out.c_str(), particles_out.collection().entries().size(), fluid_out.frames(), csv.rows(),
                terzaghi.rows());
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
    app.add_option("--stress", o.stress, "the load step: normal stress added on the upper wall (Pa)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--preload", o.preload, "normal stress of the upper wall on the dry sample before the fluid (Pa; 0: none)")
        ->check(CLI::NonNegativeNumber)->capture_default_str();
    app.add_option("--preload-time", o.preload_time, "duration of the dry preload (s)")->check(CLI::PositiveNumber)
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
    app.add_option("--model", o.model, "fluid model: darcy (pore pressure) or navier-stokes")
        ->check(CLI::IsMember({"darcy", "navier-stokes"}))->capture_default_str();
    app.add_option("--compressibility", o.compressibility, "Darcy model: pore fluid compressibility (1/Pa)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--safety", o.safety, "automatic fluid step: this fraction of the smaller stability limit")
        ->check(CLI::Range(0.001, 1.0))->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    return granular::run_in_precision(o.sample, [&](auto real) {
        using Real = decltype(real);
        return o.model == "darcy" ? run<Real, sphere::darcy_flow>(o) : run<Real, sphere::navier_stokes>(o);
    });
}
