// D15 of ../shared/VALIDATION.md (issue 3): a shear cell of 2000 spheres consolidated at
// sigma_0 = 1e4 Pa and sheared by a top layer moving at 0.05 m/s with friction 0.5. Over the
// steady window the boundary work (the driven layer's and the stress wall's) equals the change
// of the elastic, kinetic and potential energy plus the frictional and viscous dissipation
// within 3%; tau/sigma lies in 0.35-0.50; the sample dilates at the start of shearing.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <cmath>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_shear {

namespace {

/// Everything the window balance needs, at one moment.
struct budget_point {
    double boundary_work, mechanical, dissipated;
};

template <class Sim>
budget_point budget_now(const Sim& sim)
{
    const auto e = sim.energy();
    return {double(e.boundary_work), double(e.kinetic + e.rotational + e.potential + e.elastic),
            double(e.dissipated_visc + e.dissipated_fric)};
}

} // namespace

TEST_CASE("D15: a shear cell balances boundary work against energy change and dissipation, tau/sigma 0.35-0.50, "
          "dilation at the start",
          "[shear][D15][slow]")
{
    using Real = double;
    // Set-P spheres (R = 1 cm, radii +-10%, rho = 2500, k_n = 1e5 N/m, k_t = 2/7 k_n),
    // restitution 0.5, friction 0.5 between particles, frictionless walls (sphere's shear()),
    // gravity. k_n / (sigma_0 d) = 500: a contact under the load is compressed by ~0.2% of d.
    const std::size_t n = 2000;
    const double r = 0.01, r_max = 1.1 * r, rho = 2500, k_n = 1e5, sigma0 = 1e4, u = 0.05;
    const std::vector<Real> radii = sphere::uniform_radii(n, 0.9 * r, r_max, 15);
    double volume = 0;
    for (Real ri : radii) volume += 4.0 / 3.0 * sphere::pi<double> * ri * ri * ri;
    const double width = std::cbrt(volume / 0.6); // settled sample about as tall as wide
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {width, width, volume / (0.3 * width * width) + 2 * r_max};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    const std::vector<sphere::vec3<Real>> centres = sphere::random_packing(radii, s.box, 16, 0.02 * r, 100000);
    std::vector<sphere::particle<Real>> ps = sphere::make_particles(centres, radii, Real(rho));
    sphere::fit_world(s, ps, Real(1), Real(0));
    const double m = sphere::sphere_mass(r, rho);
    s.contact.k_n = k_n;
    s.contact.k_t = k_n * 2 / 7;
    s.contact.gamma_n = sphere::gamma_n_from_restitution(0.5, m / 2, k_n);
    s.contact.mu_s = s.contact.mu_d = 0.5;
    s.wall = s.contact;
    s.wall.mu_s = s.wall.mu_d = 0;
    s.gravity = {0, 0, -9.81};
    s.skin = 0.1 * r;
    // Twice sphere's time step, 0.15 sqrt(m_min / k_n) (~20 steps per contact, half the
    // stable bound): the balance is second order in dt, and the run takes half as long.
    s.dt = 0.15 * std::sqrt(sphere::sphere_mass(0.9 * r, rho) / k_n);
    sphere::simulation<Real> sim(s, ps);
    sphere::deposit(sim, 1e-5 * double(n) * m * 9.81 * 2 * r, 2000000, 200);

    // Consolidation: the upper wall (a tenth of the sample's mass) lowered onto the sample at
    // sigma_0 until it rests.
    sim.set_wall_position(5, sphere::sample_top(sim.snapshot()));
    sphere::wall_control<Real> top;
    top.mode = sphere::wall_mode::stress;
    top.stress = sigma0;
    top.mass = 0.1 * double(n) * m;
    sim.set_wall_control(5, top);
    sim.run(std::size_t(0.2 / sim.dt()));
    REQUIRE(std::abs(sphere::wall_normal_stress(sim, 5) / sigma0 - 1) < 0.1);

    // Shear: floor and top layer one largest diameter thick; the top layer moves at u.
    auto st = sim.state();
    const sphere::shear_layers layers = sphere::make_shear_cell(st.particles, 2 * r_max, {u, 0, 0});
    sim.restore(st);
    sphere::shear_tracker<Real> tracker(sim);
    const double area = sphere::wall_area(sim.walls(), sim.config().box, 5), z_start = sim.walls().face[5].position;
    const double height = tracker.height();
    INFO("sample: " << layers.bottom.size() << " fixed, " << layers.top.size() << " driven, " << height
                    << " m between the layers, porosity " << sphere::bulk_porosity(sim).porosity);

    // tau/sigma averaged over the steady window, strain 0.1 to 0.4, sampled every 10 steps.
    const double strain_steady = 0.1, strain_end = 0.4;
    const std::size_t chunk = 10, steps_per_update = 500;
    double tau_sum = 0, sigma_sum = 0, dilation_start = 0;
    std::size_t samples = 0;
    budget_point at_steady{}, at_end{};
    bool steady = false;
    for (std::size_t k = 0;; k += chunk) {
        sim.run(chunk);
        if (k % steps_per_update == 0) tracker.update(sim);
        if (!steady && tracker.strain() >= strain_steady) {
            steady = true;
            at_steady = budget_now(sim);
            dilation_start = sim.walls().face[5].position - z_start;
        }
        if (steady) {
            tau_sum += sphere::shear_stress(sim.snapshot(), layers, area);
            sigma_sum += sphere::wall_normal_stress(sim, 5);
            ++samples;
        }
        if (tracker.strain() >= strain_end) break;
    }
    at_end = budget_now(sim);

    const double work = at_end.boundary_work - at_steady.boundary_work;
    const double change = at_end.mechanical - at_steady.mechanical, dissipated = at_end.dissipated - at_steady.dissipated;
    const double mu_eff = tau_sum / sigma_sum;
    INFO("window: boundary work " << work << " J, energy change " << change << " J, dissipated " << dissipated
                                  << " J; tau/sigma " << mu_eff << ", dilation at strain 0.1: " << dilation_start << " m");
    CHECK(work > 0);
    CHECK(std::abs(work - change - dissipated) < 0.03 * work);
    CHECK(mu_eff > 0.35);
    CHECK(mu_eff < 0.50);
    // The consolidated sample dilates from the start: by strain 0.1 the wall has risen by more
    // than 2% of a diameter (it stays within a hundredth of that while consolidated).
    CHECK(dilation_start > 0.02 * 2 * r);
    // The wall kept the normal stress within 5% (time-averaged) over the window.
    CHECK(std::abs(sigma_sum / double(samples) / sigma0 - 1) < 0.05);
}

} // namespace test_shear
