#pragma once
// Shared by the granular examples (consolidation, uniaxial, triaxial, shear): their common
// command-line options, a sample deposited under gravity, the output folder (VTK frames, one
// CSV series, a final checkpoint), the progress lines and a saved sample to start from.
// docs/examples.md describes them.
#include <sphere/dem.cuh>
#include <sphere/io.cuh>

#include <CLI/CLI.hpp>

#include "run_options.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace granular {

/// Options every granular example takes. The defaults are the validation set P of
/// ../shared/VALIDATION.md (R = 1 cm, rho = 2500 kg/m^3, k_n = 1e5 N/m): stiff enough that a
/// 10 kPa load compresses a contact by ~0.2% of a diameter, coarse enough that the examples
/// finish in about a minute on 2 cores. Also the output folder, precision and quiet flag
/// (example::run_options).
struct sample_options : example::run_options {
    std::size_t particles = 800;
    double radius = 0.01;         ///< mean radius (m)
    double spread = 0.1;          ///< radii uniform in radius (1 +- spread)
    double density = 2500;        ///< (kg/m^3)
    double k_n = 1e5;             ///< normal stiffness (N/m); k_t = 2/7 k_n
    double friction = 0.5;        ///< static = dynamic friction coefficient, particles and walls
    double restitution = 0.5;     ///< normal restitution of two mean particles (sets gamma_n)
    std::uint64_t seed = 1;       ///< radii and initial positions
    double output_interval = 0.02; ///< simulated time between VTK frames and CSV rows (s)
    double wall_mass = 0.1;       ///< mass of a stress-controlled wall, in units of the total particle mass
    std::string saved_sample;     ///< a saved sample (checkpoint) to start from instead of depositing one
};

inline void add_sample_options(CLI::App& app, sample_options& o)
{
    app.add_option("-n,--particles", o.particles, "number of particles")->check(CLI::Range(10, 10000000))
        ->capture_default_str();
    app.add_option("--radius", o.radius, "mean particle radius (m)")->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--spread", o.spread, "radii uniform in radius x (1 +- spread)")->check(CLI::Range(0.0, 0.9))
        ->capture_default_str();
    app.add_option("--density", o.density, "particle density (kg/m^3)")->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--kn", o.k_n, "normal stiffness k_n (N/m); k_t = 2/7 k_n")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--mu", o.friction, "friction coefficient (static = dynamic)")->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--restitution", o.restitution, "normal restitution coefficient")->check(CLI::Range(0.01, 1.0))
        ->capture_default_str();
    app.add_option("--seed", o.seed, "seed of the radii and initial positions")->capture_default_str();
    app.add_option("--output-interval", o.output_interval, "simulated time between outputs (s)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--wall-mass", o.wall_mass, "mass of a stress-controlled wall / total particle mass")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--sample", o.saved_sample,
                   "start from this saved sample (a checkpoint: an example's sample.ck or checkpoint.ck) instead of "
                   "depositing one; its particles, contact parameters and world replace the sample options");
    example::add_run_options(app, o);
}

template <class Real>
using granular_sim = sphere::simulation<Real>;

/// Contact parameters of the options: k_t = 2/7 k_n, gamma_n for the restitution of two
/// particles of the mean radius (sphere's k_n, k_t, gamma_n, mu), no tangential viscosity.
template <class Real>
sphere::contact_params<Real> contact_of(const sample_options& o)
{
    const double m = sphere::sphere_mass(o.radius, o.density);
    sphere::contact_params<Real> c;
    c.k_n = Real(o.k_n);
    c.k_t = Real(o.k_n * 2 / 7);
    c.gamma_n = Real(sphere::gamma_n_from_restitution(o.restitution, m / 2, o.k_n));
    c.mu_s = c.mu_d = Real(o.friction);
    return c;
}

/// The particle-wall contact parameters of the examples with walls on the sides: those of
/// contact_of, and a tangential viscosity gamma_t = gamma_n, so that the walls' friction acts
/// (the wall law is viscous-frictional, sphere's: with gamma_t = 0 it has no tangential force,
/// whatever mu; a grain spinning in a corner of frictionless walls would never stop).
template <class Real>
sphere::contact_params<Real> frictional_wall_of(const sample_options& o)
{
    sphere::contact_params<Real> c = contact_of<Real>(o);
    c.gamma_t = c.gamma_n;
    return c;
}

/// A sample poured under gravity (-z, 9.81 m/s^2) and come to rest (kinetic energy below
/// 1e-4 of n m g d: low enough for a packing whose grains have stopped falling, high enough
/// that one grain still rolling on the bottom wall, which nothing slows down in the absence of
/// rolling resistance, does not keep the deposition running): random non-overlapping centres in a column about as wide as the settled
/// sample will be tall, filled to a solid fraction of 0.25, in a world periodic on x and y
/// (side_walls = false) or closed by walls on every side (the world then extends half a width
/// beyond the side walls, so that they can move out); the world is fitted to the column, and
/// the upper wall sits on the sample when this returns. `wall` are the
/// particle-wall contact parameters.
template <class Real>
granular_sim<Real> deposited_sample(const sample_options& o, bool side_walls, const sphere::contact_params<Real>& wall)
{
    using namespace sphere;
    const double r = o.radius, r_max = r * (1 + o.spread);
    const std::vector<Real> radii = uniform_radii(o.particles, Real(r * (1 - o.spread)), Real(r_max), o.seed);
    double volume = 0;
    for (Real ri : radii) volume += 4.0 / 3.0 * pi<double> * double(ri) * double(ri) * double(ri);
    const double width = std::cbrt(volume / 0.6); // a settled sample (solid fraction ~0.6) as tall as wide
    const double fill_height = volume / (0.25 * width * width) + 2 * r_max;

    settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(width), Real(width), Real(fill_height)};
    if (!side_walls) s.box.axis[0] = s.box.axis[1] = boundary::periodic;
    world<Real> region = s.box;
    std::vector<vec3<Real>> centres = random_packing(radii, region, o.seed + 1, Real(0.02 * r), 100000);
    std::vector<particle<Real>> ps = make_particles(centres, radii, Real(o.density));
    fit_world(s, ps, Real(1), Real(0));
    // Side walls start on the fitted box; the world leaves them room to move out by half the
    // width (a wall cannot leave the world).
    const world<Real> fitted = s.box;
    if (side_walls)
        for (int a = 0; a < 2; ++a) {
            s.box.lo[a] -= Real(width / 2);
            s.box.hi[a] += Real(width / 2);
        }
    s.contact = contact_of<Real>(o);
    s.wall = wall;
    s.gravity = {0, 0, Real(-9.81)};
    s.skin = Real(0.1 * r);
    granular_sim<Real> sim(s, ps);
    if (side_walls)
        for (int a = 0; a < 2; ++a) {
            sim.set_wall_position(2 * a, double(fitted.lo[a]));
            sim.set_wall_position(2 * a + 1, double(fitted.hi[a]));
        }
    const double m = sphere_mass(r, o.density);
    const double rest = 1e-4 * double(o.particles) * m * 9.81 * 2 * r;
    const auto start = std::chrono::steady_clock::now();
    auto shown = start;
    deposit(sim, rest, 2000000, 200, -1, [&](const deposition_result& d) {
        const auto now = std::chrono::steady_clock::now();
        if (o.quiet || now - shown < std::chrono::seconds(1)) return;
        shown = now;
        std::fprintf(stderr, "\rdeposition: t = %.4f s  kinetic energy %.3e J (at rest below %.3e J)  (%.0f s)   ",
                     d.time, d.kinetic, rest, std::chrono::duration<double>(now - start).count());
    });
    if (!o.quiet && shown != start) std::fprintf(stderr, "\n");
    sim.set_wall_position(5, sample_top(sim.snapshot()));
    return sim;
}

/// The sample an example starts from. With --sample, the saved one (a checkpoint written by an
/// example or the sphere program: its particles, contact parameters, world and wall positions),
/// with the example's particle-wall parameters `wall` and every wall fixed until the example
/// sets its controls; it must have side walls exactly when `side_walls` asks for them.
/// Otherwise deposited_sample(o, side_walls, wall), saved as <o.out>/sample.ck for the next
/// experiment of a chain (docs/examples.md, *Chained experiments*).
template <class Real>
granular_sim<Real> prepared_sample(const sample_options& o, bool side_walls, const sphere::contact_params<Real>& wall)
{
    using namespace sphere;
    if (o.saved_sample.empty()) {
        granular_sim<Real> sim = deposited_sample<Real>(o, side_walls, wall);
        std::error_code ec;
        std::filesystem::create_directories(o.out, ec);
        if (ec) throw sphere::error("cannot create the output folder '" + o.out + "': " + ec.message());
        write_checkpoint(o.out + "/sample.ck", sim);
        return sim;
    }
    checkpoint_data<Real> c = read_checkpoint<Real>(o.saved_sample);
    const bool has_side_walls = !c.config.box.periodic(0) && !c.config.box.periodic(1);
    const bool periodic_sides = c.config.box.periodic(0) && c.config.box.periodic(1);
    if (side_walls ? !has_side_walls : !periodic_sides)
        throw sphere::error("--sample '" + o.saved_sample + "': this example needs a sample " +
                            (side_walls ? "closed by walls on x and y (deposited by triaxial)"
                                        : "periodic on x and y (deposited by consolidation, uniaxial or shear)"));
    c.config.wall = wall;
    for (wall_control<Real>& w : c.config.walls) w = wall_control<Real>{};
    c.config.max_initial_overlap = std::numeric_limits<Real>::infinity(); // the state was accepted when it began
    granular_sim<Real> sim(c.config, c.particles());
    sim.restore(c.state);
    std::printf("sample: %zu particles from '%s' at t = %.6f s\n", sim.size(), o.saved_sample.c_str(), sim.time());
    return sim;
}

/// A wall control holding a normal stress (Pa), with a mass of o.wall_mass times the total
/// particle mass: a wall that responds on the time scale of the sample it loads.
template <class Sim>
sphere::wall_control<typename Sim::real_type> stress_wall(const sample_options& o, const Sim& sim, double stress)
{
    double m = 0;
    for (auto mi : sim.snapshot().mass) m += double(mi);
    sphere::wall_control<typename Sim::real_type> c;
    c.mode = sphere::wall_mode::stress;
    c.stress = typename Sim::real_type(stress);
    c.mass = typename Sim::real_type(o.wall_mass * m);
    return c;
}

/// A wall control moving inwards at `velocity` (m/s).
template <class Real>
sphere::wall_control<Real> velocity_wall(double velocity)
{
    sphere::wall_control<Real> c;
    c.mode = sphere::wall_mode::velocity;
    c.velocity = Real(velocity);
    return c;
}

/// The output folder of a run: VTK frames particles_NNNNNN.vtu with particles.pvd, the CSV
/// series series.csv (the diagnostics columns of sphere::diagnostics_series followed by the
/// example's own), and at the end checkpoint.ck. Frames and rows are written every
/// `output_interval` of simulated time, from the moment attach() is called.
template <class Sim>
class run_output {
public:
    using extra_row = std::function<std::vector<double>(const Sim&)>;

    run_output(const sample_options& o, const Sim& sim, const std::vector<std::string>& extra_columns, extra_row extra)
        : folder_(o.out), extra_(std::move(extra))
    {
        std::error_code ec;
        std::filesystem::create_directories(folder_, ec);
        if (ec) throw sphere::error("cannot create the output folder '" + folder_ + "': " + ec.message());
        every_ = static_cast<std::size_t>(std::llround(o.output_interval / double(sim.dt())));
        if (every_ == 0) every_ = 1;
        std::vector<std::string> columns = sphere::diagnostics_columns(sim.walls());
        columns.insert(columns.end(), extra_columns.begin(), extra_columns.end());
        csv_ = std::make_shared<sphere::csv_series>(folder_ + "/series.csv", columns);
    }

    /// Writes a frame and a row now and then at every multiple of the output interval.
    void attach(Sim& sim)
    {
        vtk_ = sphere::add_vtk_output(sim, folder_, every_);
        add_row(*csv_, extra_, sim);
        const std::size_t first = sim.steps(); // its row is written: no second one
        auto csv = csv_;
        auto extra = extra_;
        sim.add_observer(every_, [csv, extra, first](const Sim& s) {
            if (s.steps() != first) add_row(*csv, extra, s);
        });
    }

    /// Closes the CSV series and writes the final checkpoint; prints what is where.
    void finish(const Sim& sim)
    {
        csv_->close();
        sphere::write_checkpoint(folder_ + "/checkpoint.ck", sim);
        std::printf("output in %s/: particles.pvd (%zu frames), series.csv (%zu rows), checkpoint.ck\n",
                    folder_.c_str(), vtk_ ? vtk_->collection().entries().size() : 0, csv_->rows());
    }

private:
    static void add_row(sphere::csv_series& csv, const extra_row& extra, const Sim& sim)
    {
        std::vector<double> row = sphere::diagnostics_row(sim);
        const std::vector<double> more = extra(sim);
        row.insert(row.end(), more.begin(), more.end());
        csv.add_row(row);
        csv.flush();
    }

    std::string folder_;
    extra_row extra_;
    std::size_t every_ = 1;
    std::shared_ptr<sphere::csv_series> csv_;
    std::shared_ptr<sphere::vtk_writer> vtk_;
};

/// Runs `sim` for `steps` steps as phase `name`, printing a progress line on stderr about once
/// a second (unless quiet) with what `status` says.
template <class Sim>
void run_steps(Sim& sim, const char* name, std::size_t steps, bool quiet,
               const std::function<std::string(const Sim&)>& status)
{
    const auto start = std::chrono::steady_clock::now();
    auto last = start;
    const std::size_t chunk = 100;
    for (std::size_t done = 0; done < steps;) {
        const std::size_t n = std::min(chunk, steps - done);
        sim.run(n);
        done += n;
        const auto now = std::chrono::steady_clock::now();
        if (!quiet && (now - last > std::chrono::seconds(1) || done == steps)) {
            last = now;
            const double wall = std::chrono::duration<double>(now - start).count();
            std::fprintf(stderr, "\r%s: %5.1f%%  t = %.4f s  %s  (%.0f s)   ", name, 100.0 * double(done) / double(steps),
                         sim.time(), status(sim).c_str(), wall);
        }
    }
    if (!quiet) std::fprintf(stderr, "\n");
}

/// Runs `sim` for `duration` (s) of simulated time, rounded to whole steps, as phase `name`
/// (run_steps).
template <class Sim>
void run_phase(Sim& sim, const char* name, double duration, bool quiet,
               const std::function<std::string(const Sim&)>& status)
{
    run_steps<Sim>(sim, name, static_cast<std::size_t>(std::llround(duration / double(sim.dt()))), quiet, status);
}

/// Calls run<float>(o) or run<double>(o) by the --precision option and turns a sphere::error
/// (or any exception) into a message on stderr and exit status 1.
using example::run_in_precision;

} // namespace granular
