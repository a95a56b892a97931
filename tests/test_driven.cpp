// Driven particles (issue 3): motion::prescribed_horizontal (sphere's fixvel top layer), the
// work of whatever drives prescribed particles (simulation::drive_work, part of the boundary
// work of the energy budget), and make_shear_cell / restore with edited motion kinds.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <cmath>
#include <random>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_driven {

namespace {

using sphere_test::ball;
using sphere_test::box_settings;
using sphere_test::rel_err;
using sphere_test::set_p;

/// Largest |a - b| over a vector's components.
template <class Real>
double max_abs_diff(const sphere::vec3<Real>& a, const sphere::vec3<double>& b)
{
    double d = 0;
    for (int k = 0; k < 3; ++k) d = std::fmax(d, std::abs(double(a[k]) - b[k]));
    return d;
}

} // namespace

TEMPLATE_TEST_CASE("a horizontally prescribed particle keeps its x, y and angular velocity and feels no gravity",
                   "[driven]", float, double)
{
    using Real = TestType;
    sphere::settings<Real> s = box_settings<Real>();
    s.gravity = {0, 0, Real(-9.81)};
    sphere::particle<Real> p = ball<Real>({Real(-0.05), Real(0.02), Real(0)}, {Real(0.1), Real(-0.05), Real(0.02)});
    p.angular_velocity = {1, 2, 3};
    p.kind = sphere::motion::prescribed_horizontal;
    sphere::simulation<Real> sim(s, {p});
    const std::size_t steps = 2000;
    sim.run(steps);
    const double t = sim.time();
    const auto snap = sim.snapshot();
    // No contact: x, y and z all move at the given velocity (gravity is off for this particle).
    // 2000 steps of float rounding on coordinates of ~0.05 m: 2e-5 m at most.
    const bool is_float = std::is_same<Real, float>::value;
    CHECK(max_abs_diff(snap.position(0), {-0.05 + 0.1 * t, 0.02 - 0.05 * t, 0.02 * t}) < (is_float ? 2e-5 : 1e-12));
    CHECK(max_abs_diff(snap.v[0], {double(Real(0.1)), double(Real(-0.05)), double(Real(0.02))}) == 0);
    CHECK(max_abs_diff(snap.omega[0], {1, 2, 3}) == 0);
    // The agent holds the particle against gravity, m g per unit of rise: W = m g v_z t, which
    // is the particle's gain in potential energy (total energy unchanged).
    const double m = double(set_p<Real>::mass()), w = m * 9.81 * 0.02 * t;
    CHECK(rel_err(Real(sim.drive_work()), w) < (is_float ? 1e-4 : 1e-10));
    const auto e = sim.energy();
    CHECK(rel_err(e.boundary_work, w) < (is_float ? 1e-4 : 1e-10));
    CHECK(std::abs(double(e.total()) - double(e.kinetic + e.rotational)) < (is_float ? 1e-3 : 1e-8) * w);
}

TEMPLATE_TEST_CASE("a horizontally prescribed particle is pushed up by its contacts, not sideways", "[driven]",
                   float, double)
{
    using Real = TestType;
    // A rests on a fixed B, overlapping by delta, frictionless and undamped, and slides along x
    // at u. The normal force pushes A up only: it leaves with v_z = delta sqrt(k_n / m) (the
    // spring's energy k delta^2 / 2 turned into m v_z^2 / 2; B cannot move), and keeps v_x = u.
    sphere::settings<Real> s = box_settings<Real>();
    s.gravity = {0, 0, Real(-9.81)};
    const Real R = set_p<Real>::radius, delta = Real(1e-4), u = Real(0.01);
    sphere::particle<Real> b = ball<Real>({0, 0, -R});
    b.kind = sphere::motion::fixed;
    sphere::particle<Real> a = ball<Real>({0, 0, R - delta}, {u, 0, 0});
    a.kind = sphere::motion::prescribed_horizontal;
    sphere::simulation<Real> sim(s, {a, b});
    const double total0 = double(sim.energy().total());
    sphere_test::run_until_separated(sim, 20000);
    const auto snap = sim.snapshot();
    const double m = double(set_p<Real>::mass()), v_z = double(delta) * std::sqrt(double(set_p<Real>::k_n) / m);
    // 0.5%: the step in which the contact ends is not resolved (about 1/40 of a contact).
    CHECK(rel_err(snap.v[0].z, v_z) < 5e-3);
    CHECK(snap.v[0].x == u);
    CHECK(snap.v[0].y == Real(0));
    // The agent held A's x against nothing (frictionless) and its z against gravity only:
    // W = m g times the rise, booked with the velocity at the positions' time, which lags the
    // displacement by v_z dt / 2 at the end.
    const double rise = double(snap.position(0).z) - double(R - delta), g = 9.81;
    CHECK(std::abs(sim.drive_work() - m * g * rise) < m * g * v_z * double(sim.dt()));
    // The budget closes to 0.1% of the spring energy that launched A.
    CHECK(std::abs(double(sim.energy().total()) - total0) <
          1e-3 * 0.5 * double(set_p<Real>::k_n) * double(delta) * double(delta));
}

TEMPLATE_TEST_CASE("a prescribed particle striking a free one does the work the free one gains", "[driven]", float,
                   double)
{
    using Real = TestType;
    // A (prescribed, velocity u) hits B (free, at rest) head on, frictionless and undamped. In
    // A's frame B bounces off an immovable sphere: B leaves at 2u with kinetic energy
    // 2 m u^2, all of it the work of the agent that kept A at u.
    sphere::settings<Real> s = box_settings<Real>();
    const Real R = set_p<Real>::radius, u = Real(0.2);
    sphere::particle<Real> a = ball<Real>({-R - Real(0.001), 0, 0}, {u, 0, 0});
    a.kind = sphere::motion::prescribed;
    sphere::particle<Real> b = ball<Real>({R + Real(0.001), 0, 0});
    sphere::simulation<Real> sim(s, {a, b});
    sphere_test::run_until_separated(sim, 20000);
    const double m = double(set_p<Real>::mass()), w = 2 * m * double(u) * double(u);
    const auto snap = sim.snapshot();
    CHECK(rel_err(snap.v[1].x, 2 * double(u)) < 5e-3);
    CHECK(rel_err(Real(sim.drive_work()), w) < 1e-2);
    // The budget closes: the drive's work is B's kinetic energy (A's never changes).
    const auto e = sim.energy();
    const double ka = 0.5 * m * double(u) * double(u);
    CHECK(std::abs(double(e.kinetic) - ka - double(e.boundary_work)) < 1e-3 * w);
}

TEMPLATE_TEST_CASE("shearing a small sample under a stress wall closes the energy budget", "[driven][energy]", float,
                   double)
{
    using Real = TestType;
    // A 4 x 4 periodic column of set-P spheres: a fixed floor layer, four free layers of radii
    // 0.9-1.0 R and a top layer driven along x at 0.05 m/s, under a stress wall at 1e4 Pa, with
    // gravity, friction 0.5 and damping (e = 0.5). The drive and the wall do work; the energy
    // they put in is what the springs store, the dashpots and sliding dissipate and the motion
    // carries. Checked to 1% of the boundary work at every output.
    const Real R = set_p<Real>::radius, d = 2 * R;
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {4 * d, 4 * d, 7 * d};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = set_p<Real>::k_n;
    s.contact.k_t = set_p<Real>::k_n * 2 / 7;
    s.contact.gamma_n = sphere::gamma_n_from_restitution(Real(0.5), set_p<Real>::mass() / 2, set_p<Real>::k_n);
    s.contact.mu_s = s.contact.mu_d = Real(0.5);
    s.wall = s.contact;
    s.wall.mu_s = s.wall.mu_d = 0; // sphere's shear(): no wall friction
    s.gravity = {0, 0, Real(-9.81)};
    std::mt19937 gen(7u);
    std::uniform_real_distribution<double> size(0.9, 1.0);
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 6; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                sphere::particle<Real> p = ball<Real>({R + i * d, R + j * d, R + k * d});
                if (k == 0) {
                    p.kind = sphere::motion::fixed;
                } else if (k == 5) {
                    p.kind = sphere::motion::prescribed_horizontal;
                    p.velocity = {Real(0.05), 0, 0};
                } else {
                    p.radius = Real(double(R) * size(gen));
                }
                ps.push_back(p);
            }
    s.walls[5].mode = sphere::wall_mode::stress;
    s.walls[5].stress = Real(1e4);
    s.walls[5].mass = Real(1);
    sphere::simulation<Real> sim(s, ps);
    sim.set_wall_position(5, 6 * double(d));
    const double total0 = double(sim.energy().total());
    double worst = 0, work = 0;
    for (int out = 0; out < 40; ++out) {
        sim.run(500);
        const auto e = sim.energy();
        work = double(e.boundary_work);
        worst = std::fmax(worst, std::abs(double(e.total()) - total0) / std::abs(work));
    }
    INFO("drive work " << sim.drive_work() << " J, boundary work " << work << " J, worst imbalance " << worst);
    CHECK(sim.drive_work() > 0);
    CHECK(worst < 1e-2);
    // The sample was sheared (the top layer moved ~1.2 diameters) and held under the wall.
    CHECK(sim.walls().face[5].position < 6 * double(d));
}

TEMPLATE_TEST_CASE("make_shear_cell fixes the floor and drives the top layer, and restore takes the new kinds",
                   "[driven][layers]", float, double)
{
    using Real = TestType;
    sphere::settings<Real> s = box_settings<Real>();
    s.gravity = {0, 0, Real(-9.81)};
    const Real R = set_p<Real>::radius;
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 4; ++k) ps.push_back(ball<Real>({Real(-0.05) + k * Real(0.03), 0, Real(-0.09) + k * 2 * R}));
    sphere::simulation<Real> sim(s, ps);
    auto st = sim.state();
    CHECK(sphere::sample_bottom(st.particles) == Approx(-0.09 - 0.01).margin(1e-7));
    CHECK(sphere::sample_top(st.particles) == Approx(-0.09 + 6 * 0.01 + 0.01).margin(1e-7));
    const sphere::shear_layers l = sphere::make_shear_cell(st.particles, R, {Real(0.05), 0, 0});
    CHECK(l.bottom == std::vector<std::size_t>{0});
    CHECK(l.top == std::vector<std::size_t>{3});
    sim.restore(st);
    sim.run(1000);
    const auto snap = sim.snapshot();
    CHECK(snap.position(0).z == ps[0].position.z); // fixed
    CHECK(snap.v[3].x == Real(0.05));             // driven along x, no gravity on it
    CHECK(snap.position(3).z == ps[3].position.z);
    CHECK(snap.position(1).z < ps[1].position.z); // free: falls
    CHECK_THROWS_WITH(sim.set_velocity(0, {1, 0, 0}, {0, 0, 0}), Catch::Contains("particle 0 is fixed"));

    auto bad = sim.state();
    CHECK_THROWS_WITH(sphere::make_shear_cell(bad.particles, Real(0), {1, 0, 0}),
                      Catch::Contains("layer thickness = 0 m"));
    CHECK_THROWS_WITH(sphere::make_shear_cell(bad.particles, R, {0, 0, 1}), Catch::Contains("must be finite and horizontal"));
    bad.particles.kind[2] = 9;
    CHECK_THROWS_WITH(sim.restore(bad), Catch::Contains("particle 2 has motion kind 9"));
}

} // namespace test_driven
