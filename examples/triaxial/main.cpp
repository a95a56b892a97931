// triaxial: pours a sample under gravity into a box closed by walls on every side, holds the
// four side walls at a confining stress while the upper wall settles onto it at the same stress,
// then moves the upper wall down at a prescribed velocity (sphere's triaxial) and follows the
// axial and lateral stresses, axial and volumetric strain and porosity (docs/examples.md).
#include "../common/granular.hpp"

#include <cstdio>
#include <string>
#include <vector>

namespace {

struct options {
    granular::sample_options sample;
    double confining = 1e4;        // Pa, side walls
    double velocity = 0.02;        // m/s, upper wall downwards
    double confine_duration = 0.15; // s, isotropic phase
    double duration = 0.3;         // s, axial compression
};

/// Volume between the six walls (m^3).
template <class Sim>
double box_volume(const Sim& s)
{
    const auto& w = s.walls().face;
    return (w[1].position - w[0].position) * (w[3].position - w[2].position) * (w[5].position - w[4].position);
}

/// Mean normal stress on the four side walls (Pa).
template <class Sim>
double side_stress(const Sim& s)
{
    double sum = 0;
    for (int f = 0; f < 4; ++f) sum += sphere::wall_normal_stress(s, f);
    return sum / 4;
}

template <class Real>
int run(const options& o)
{
    using namespace sphere;
    using Sim = granular::granular_sim<Real>;
    Sim sim = granular::prepared_sample<Real>(o.sample, true, granular::frictional_wall_of<Real>(o.sample));
    std::printf("triaxial: %zu particles (%s), sample at t = %.3f s; porosity %.4f\n", sim.size(),
                o.sample.precision.c_str(), sim.time(), bulk_porosity(sim).porosity);
    for (int f : {0, 1, 2, 3, 5}) sim.set_wall_control(f, granular::stress_wall(o.sample, sim, o.confining));

    // Strains are measured from the end of the isotropic phase (compression positive).
    double z_ref = 0, height_ref = 1, volume_ref = 1;
    const auto axial = [&](const Sim& s) { return (z_ref - s.walls().face[5].position) / height_ref; };
    const auto volumetric = [&](const Sim& s) { return (volume_ref - box_volume(s)) / volume_ref; };
    granular::run_output<Sim> out(
        o.sample, sim,
        {"axial_strain", "volumetric_strain", "normal_stress_Pa", "side_stress_Pa", "porosity", "void_ratio"},
        [&](const Sim& s) {
            const porosity_result p = bulk_porosity(s);
            return std::vector<double>{axial(s), volumetric(s), wall_normal_stress(s, 5), side_stress(s), p.porosity,
                                       p.void_ratio};
        });
    out.attach(sim);
    const auto status = [&](const Sim& s) {
        char text[128];
        std::snprintf(text, sizeof text, "axial %.0f Pa, lateral %.0f Pa, strain %.4f", wall_normal_stress(s, 5),
                      side_stress(s), axial(s));
        return std::string(text);
    };
    granular::run_phase<Sim>(sim, "isotropic", o.confine_duration, o.sample.quiet, status);

    z_ref = sim.walls().face[5].position;
    height_ref = z_ref - sim.walls().face[4].position;
    volume_ref = box_volume(sim);
    std::printf("after the isotropic phase: axial %.1f Pa, lateral %.1f Pa, porosity %.4f\n",
                wall_normal_stress(sim, 5), side_stress(sim), bulk_porosity(sim).porosity);
    sim.set_wall_control(5, granular::velocity_wall<Real>(o.velocity));
    granular::run_phase<Sim>(sim, "triaxial", o.duration, o.sample.quiet, status);

    const porosity_result p = bulk_porosity(sim);
    const double q = wall_normal_stress(sim, 5) - side_stress(sim), pm = (wall_normal_stress(sim, 5) + 2 * side_stress(sim)) / 3;
    std::printf("%-34s %14.6f\n", "axial strain", axial(sim));
    std::printf("%-34s %14.6f\n", "volumetric strain", volumetric(sim));
    std::printf("%-34s %14.1f\n", "axial stress sigma_1 (Pa)", wall_normal_stress(sim, 5));
    std::printf("%-34s %14.1f  (target %.1f)\n", "lateral stress sigma_3 (Pa)", side_stress(sim), o.confining);
    std::printf("%-34s %14.1f\n", "deviatoric stress q (Pa)", q);
    std::printf("%-34s %14.4f\n", "stress ratio q / p", q / pm);
    std::printf("%-34s %14.6f\n", "porosity", p.porosity);
    out.finish(sim);
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    o.sample.out = "triaxial-output";
    CLI::App app{"triaxial: pour a sample, confine it by the side walls at a stress, then compress it with the "
                 "upper wall at a prescribed velocity; writes stresses, strains and porosity against time"};
    granular::add_sample_options(app, o.sample);
    app.add_option("--confining", o.confining, "normal stress of the side walls (Pa)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--velocity", o.velocity, "downward velocity of the upper wall (m/s)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--confine-time", o.confine_duration, "duration of the isotropic confinement (s)")
        ->check(CLI::PositiveNumber)->capture_default_str();
    app.add_option("--time", o.duration, "duration of the axial compression (s)")->check(CLI::PositiveNumber)
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    return granular::run_in_precision(o.sample, [&](auto real) { return run<decltype(real)>(o); });
}
