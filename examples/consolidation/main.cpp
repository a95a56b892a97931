// consolidation: pours a sample under gravity into a box periodic in x and y, then loads it
// with the upper wall at a normal stress (sphere's consolidate(); optionally sine-modulated)
// and follows the wall position, porosity and void ratio in time (docs/examples.md).
#include "../common/granular.hpp"

#include <cstdio>
#include <string>
#include <vector>

namespace {

struct options {
    granular::sample_options sample;
    double stress = 1e4;   // Pa
    double amplitude = 0;  // Pa
    double frequency = 0;  // Hz
    double duration = 0.4; // s
};

template <class Real>
int run(const options& o)
{
    using namespace sphere;
    using Sim = granular::granular_sim<Real>;
    Sim sim = granular::prepared_sample<Real>(o.sample, false, granular::contact_of<Real>(o.sample));
    const double z0 = sim.walls().face[5].position;
    std::printf("consolidation: %zu particles (%s), sample at t = %.3f s; sample top at %.6f m, porosity %.4f\n",
                sim.size(), o.sample.precision.c_str(), sim.time(), z0, bulk_porosity(sim).porosity);

    wall_control<Real> top = granular::stress_wall(o.sample, sim, o.stress);
    top.amplitude = Real(o.amplitude);
    top.frequency = Real(o.frequency);
    sim.set_wall_control(5, top);

    granular::run_output<Sim> out(o.sample, sim, {"porosity", "void_ratio", "normal_stress_Pa"}, [](const Sim& s) {
        const porosity_result p = bulk_porosity(s);
        return std::vector<double>{p.porosity, p.void_ratio, wall_normal_stress(s, 5)};
    });
    out.attach(sim);
    // Time-average of the wall stress over the second half of the loading.
    double stress_sum = 0;
    std::size_t stress_count = 0;
    const double t_half = sim.time() + o.duration / 2;
    sim.add_observer(1, [&](const Sim& s) {
        if (s.time() < t_half) return;
        stress_sum += wall_normal_stress(s, 5);
        ++stress_count;
    });
    granular::run_phase<Sim>(sim, "consolidation", o.duration, o.sample.quiet, [](const Sim& s) {
        char text[96];
        std::snprintf(text, sizeof text, "wall z = %.6f m, stress = %.0f Pa", s.walls().face[5].position,
                      wall_normal_stress(s, 5));
        return std::string(text);
    });

    const porosity_result p = bulk_porosity(sim);
    std::printf("%-34s %14.6f\n", "upper wall position (m)", sim.walls().face[5].position);
    std::printf("%-34s %14.6e\n", "compression of the sample (m)", z0 - sim.walls().face[5].position);
    std::printf("%-34s %14.6f\n", "porosity", p.porosity);
    std::printf("%-34s %14.6f\n", "void ratio", p.void_ratio);
    std::printf("%-34s %14.1f  (target %.1f)\n", "mean wall stress, 2nd half (Pa)",
                stress_sum / double(stress_count), o.stress);
    out.finish(sim);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    o.sample.out = "consolidation-output";
    CLI::App app{"consolidation: pour a sample, then load it with the upper wall at a normal stress; writes the "
                 "wall position, porosity and void ratio against time"};
    granular::add_sample_options(app, o.sample);
    app.add_option("--stress", o.stress, "normal stress of the upper wall (Pa)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--amplitude", o.amplitude, "amplitude of a sine modulation of the stress (Pa)")
        ->check(CLI::NonNegativeNumber)->capture_default_str();
    app.add_option("--frequency", o.frequency, "frequency of the modulation (Hz)")->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--time", o.duration, "duration of the loading (s)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    return granular::run_in_precision(o.sample, [&](auto real) { return run<decltype(real)>(o); });
}
