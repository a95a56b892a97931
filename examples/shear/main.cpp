// shear: pours a sample under gravity into a box periodic in x and y, consolidates it under
// the upper wall at a normal stress, then turns it into a shear cell (sphere's shear()): the
// bottom particles are fixed, the top layer moves along x at the prescribed shear strain rate
// times the sample height while staying free to rise, and the upper wall keeps the normal
// stress. Follows the shear stress, the effective friction coefficient tau/sigma, dilation and
// shear strain (docs/examples.md). Walls are frictionless, as in sphere's shear().
#include "../common/granular.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace {

struct options {
    granular::sample_options sample;
    double stress = 1e4;                 // Pa
    double consolidation_duration = 0.3; // s
    double strain_rate = 0.25;           // 1/s
    double strain = 0.3;                 // total shear strain
};

/// Shear stress and normal stress averaged over the steps since the last reset (Pa).
struct stress_average {
    double tau = 0, sigma = 0;
    std::size_t samples = 0;
    void reset() { tau = sigma = 0, samples = 0; }
    double mean_tau() const { return samples ? tau / double(samples) : 0; }
    double mean_sigma() const { return samples ? sigma / double(samples) : 0; }
};

template <class Real>
int run(const options& o)
{
    using namespace sphere;
    using Sim = granular::granular_sim<Real>;
    contact_params<Real> wall = granular::contact_of<Real>(o.sample);
    wall.mu_s = wall.mu_d = 0;
    Sim sim = granular::prepared_sample<Real>(o.sample, false, wall);
    std::printf("shear: %zu particles (%s), sample at t = %.3f s; porosity %.4f\n", sim.size(),
                o.sample.precision.c_str(), sim.time(), bulk_porosity(sim).porosity);
    sim.set_wall_control(5, granular::stress_wall(o.sample, sim, o.stress));
    const double area = wall_area(sim.walls(), sim.config().box, 5);
    const auto status_consolidation = [](const Sim& s) {
        char text[96];
        std::snprintf(text, sizeof text, "wall z = %.6f m, stress = %.0f Pa", s.walls().face[5].position,
                      wall_normal_stress(s, 5));
        return std::string(text);
    };

    // Shear-phase state, read by the output columns (zero while consolidating).
    bool shearing = false;
    shear_layers layers;
    std::unique_ptr<shear_tracker<Real>> tracker;
    double z_start = 0;
    stress_average avg;
    granular::run_output<Sim> out(
        o.sample, sim,
        {"shear_strain", "shear_stress_Pa", "normal_stress_Pa", "friction_coefficient", "dilation_m", "porosity",
         "void_ratio"},
        [&](const Sim& s) {
            const porosity_result p = bulk_porosity(s);
            double strain = 0, tau = 0, sigma = wall_normal_stress(s, 5), dilation = 0;
            if (shearing) {
                tracker->update(s);
                strain = tracker->strain();
                tau = avg.mean_tau();
                sigma = avg.mean_sigma();
                dilation = s.walls().face[5].position - z_start;
                avg.reset();
            }
            return std::vector<double>{strain, tau, sigma, sigma > 0 ? tau / sigma : 0, dilation, p.porosity,
                                       p.void_ratio};
        });
    out.attach(sim);
    granular::run_phase<Sim>(sim, "consolidation", o.consolidation_duration, o.sample.quiet, status_consolidation);

    // The shear cell: fixed floor and driven top layer, each one largest diameter thick. The
    // strain rate is the velocity over the height between the layers' centres (shear_height),
    // the thickness that shears.
    simulation_state<Real> st = sim.state();
    Real largest = 0; // a saved sample's largest radius; a deposited one's is the options' nominal largest
    for (const auto& x : st.particles.x) largest = std::max(largest, x.w);
    const Real thickness =
        o.sample.saved_sample.empty() ? Real(2 * o.sample.radius * (1 + o.sample.spread)) : Real(2 * largest);
    particle_snapshot<Real> probe = st.particles;
    const double height = shear_height(probe, make_shear_cell(probe, thickness, vec3<Real>{1, 0, 0}));
    const double velocity = o.strain_rate * height;
    layers = make_shear_cell(st.particles, thickness, vec3<Real>{Real(velocity), 0, 0});
    sim.restore(st);
    tracker = std::make_unique<shear_tracker<Real>>(sim);
    z_start = sim.walls().face[5].position;
    shearing = true;
    std::printf("consolidated: %.6f m between the layers, porosity %.4f; shearing at %.4g m/s (%zu fixed, %zu driven "
                "particles)\n",
                height, bulk_porosity(sim).porosity, velocity, layers.bottom.size(), layers.top.size());
    sim.add_observer(10, [&](const Sim& s) {
        avg.tau += shear_stress(s.snapshot(), layers, area);
        avg.sigma += wall_normal_stress(s, 5);
        ++avg.samples;
    });
    granular::run_phase<Sim>(sim, "shear", o.strain / o.strain_rate, o.sample.quiet, [&](const Sim& s) {
        tracker->update(s);
        char text[128];
        std::snprintf(text, sizeof text, "strain %.4f, tau/sigma %.3f, dilation %.3e m", tracker->strain(),
                      avg.mean_sigma() > 0 ? avg.mean_tau() / avg.mean_sigma() : 0.0,
                      s.walls().face[5].position - z_start);
        return std::string(text);
    });

    tracker->update(sim);
    const energy_budget<Real> e = sim.energy();
    std::printf("%-34s %14.6f\n", "shear strain", tracker->strain());
    std::printf("%-34s %14.6e\n", "dilation (m)", sim.walls().face[5].position - z_start);
    std::printf("%-34s %14.6f\n", "porosity", bulk_porosity(sim).porosity);
    std::printf("%-34s %14.6e\n", "work of the driven layer (J)", sim.drive_work());
    std::printf("%-34s %14.6e\n", "frictional dissipation (J)", double(e.dissipated_fric));
    std::printf("%-34s %14.6e\n", "viscous dissipation (J)", double(e.dissipated_visc));
    std::printf("(tau/sigma against strain: the friction_coefficient column of series.csv; plot with "
                "scripts/plot_series.py)\n");
    out.finish(sim);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    o.sample.out = "shear-output";
    CLI::App app{"shear: pour a sample, consolidate it at a normal stress, then shear it by moving the top layer "
                 "while the upper wall holds the stress; writes shear stress, tau/sigma, dilation and strain"};
    granular::add_sample_options(app, o.sample);
    app.add_option("--stress", o.stress, "normal stress of the upper wall (Pa)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--consolidation-time", o.consolidation_duration, "duration of the consolidation (s)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--strain-rate", o.strain_rate, "shear strain rate: top layer velocity / sample height (1/s)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--strain", o.strain, "shear strain to reach")->check(CLI::PositiveNumber)->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    return granular::run_in_precision(o.sample, [&](auto real) { return run<decltype(real)>(o); });
}
