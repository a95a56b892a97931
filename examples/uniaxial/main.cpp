// uniaxial: pours a sample under gravity into a box periodic in x and y, then compresses it
// with the upper wall moving down at a prescribed velocity (sphere's uniaxialStrainRate: the
// sample cannot widen, so this is uniaxial strain) and follows the axial stress, axial strain
// and porosity (docs/examples.md).
#include "../common/granular.hpp"

#include <cstdio>
#include <string>
#include <vector>

namespace {

struct options {
    granular::sample_options sample;
    double velocity = 0.05; // m/s, downwards
    double duration = 0.4;  // s
};

template <class Real>
int run(const options& o)
{
    using namespace sphere;
    using Sim = granular::granular_sim<Real>;
    Sim sim = granular::prepared_sample<Real>(o.sample, false, granular::contact_of<Real>(o.sample));
    const double z0 = sim.walls().face[5].position, floor = sim.walls().face[4].position;
    const double height0 = z0 - floor;
    std::printf("uniaxial: %zu particles (%s), sample at t = %.3f s; sample height %.6f m, porosity %.4f\n",
                sim.size(), o.sample.precision.c_str(), sim.time(), height0, bulk_porosity(sim).porosity);
    const double strain_end = o.velocity * o.duration / height0;
    if (!(strain_end < 0.5))
        throw error("--velocity " + std::to_string(o.velocity) + " m/s for --time " + std::to_string(o.duration) +
                    " s would compress the sample by " + std::to_string(100 * strain_end) +
                    "% of its height; at most 50% is allowed");
    sim.set_wall_control(5, granular::velocity_wall<Real>(o.velocity));

    const auto strain = [z0, height0](const Sim& s) { return (z0 - s.walls().face[5].position) / height0; };
    granular::run_output<Sim> out(o.sample, sim, {"axial_strain", "normal_stress_Pa", "porosity", "void_ratio"},
                                  [&](const Sim& s) {
                                      const porosity_result p = bulk_porosity(s);
                                      return std::vector<double>{strain(s), wall_normal_stress(s, 5), p.porosity,
                                                                 p.void_ratio};
                                  });
    out.attach(sim);
    granular::run_phase<Sim>(sim, "uniaxial", o.duration, o.sample.quiet, [&](const Sim& s) {
        char text[96];
        std::snprintf(text, sizeof text, "strain = %.4f, stress = %.0f Pa", strain(s), wall_normal_stress(s, 5));
        return std::string(text);
    });

    const porosity_result p = bulk_porosity(sim);
    std::printf("%-34s %14.6f\n", "axial strain", strain(sim));
    std::printf("%-34s %14.1f\n", "axial stress (Pa)", wall_normal_stress(sim, 5));
    std::printf("%-34s %14.1f\n", "floor stress (Pa)", wall_normal_stress(sim, 4));
    std::printf("%-34s %14.6f\n", "porosity", p.porosity);
    std::printf("%-34s %14.6f\n", "void ratio", p.void_ratio);
    out.finish(sim);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    o.sample.out = "uniaxial-output";
    CLI::App app{"uniaxial: pour a sample, then compress it with the upper wall at a prescribed velocity "
                 "(uniaxial strain); writes axial stress, strain and porosity against time"};
    granular::add_sample_options(app, o.sample);
    app.add_option("--velocity", o.velocity, "downward velocity of the upper wall (m/s)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--time", o.duration, "duration of the compression (s)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    return granular::run_in_precision(o.sample, [&](auto real) { return run<decltype(real)>(o); });
}
