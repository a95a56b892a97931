// Particle insertion during a run (simulation::insert, setup/insertion.cuh): inserted
// particles get the next user indices and their given state while the others carry on; bad
// insertions are refused by name and leave the simulation as it was; an inserter fills a box
// at its rate without overlap at insertion, deterministically; a run with insertions restarts
// from a checkpoint bit for bit. float and double.
#include <catch2/catch.hpp>

#include "support.hpp"
#include "temp_folder.hpp"

#include <sphere/io.cuh>

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_insertion {

namespace {

template <class Real>
using host_sim = sphere::simulation<Real, sphere_test::policy, sphere::contact::linear<>,
                                    sphere::integrate::velocity_verlet>;

/// A closed box [-0.05, 0.05]^2 x [0, 0.2] with gravity, the frictional, damped set P contacts.
template <class Real>
sphere::settings<Real> silo()
{
    auto s = sphere_test::box_settings<Real>();
    s.box.lo = {Real(-0.05), Real(-0.05), 0};
    s.box.hi = {Real(0.05), Real(0.05), Real(0.2)};
    s.contact.gamma_n = Real(5);
    s.contact.mu_s = s.contact.mu_d = Real(0.5);
    s.wall = s.contact;
    s.gravity = {0, 0, Real(-9.81)};
    s.skin = Real(0.002);
    s.dt = Real(2e-5);
    return s;
}

template <class Real>
std::vector<sphere::particle<Real>> two_on_the_floor()
{
    std::vector<sphere::particle<Real>> ps(2);
    for (int i = 0; i < 2; ++i) {
        ps[i].position = {Real(-0.02 + 0.04 * i), 0, Real(0.0099)};
        ps[i].radius = Real(0.01);
        ps[i].density = Real(2500);
    }
    return ps;
}

/// The smallest gap (m) between a particle from index `first` on and any other.
template <class Real>
double smallest_gap(const sphere::particle_snapshot<Real>& s, std::size_t first)
{
    double gap = 1e30;
    for (std::size_t i = first; i < s.size(); ++i)
        for (std::size_t j = 0; j < i; ++j) {
            const sphere::vec3<Real> d = s.position(i) - s.position(j);
            gap = std::fmin(gap, std::sqrt(double(norm2(d))) - double(s.radius(i)) - double(s.radius(j)));
        }
    return gap;
}

} // namespace

TEMPLATE_TEST_CASE("insert: added particles take the next indices and their state, the rest carries on",
                   "[insertion]", float, double)
{
    // Two particles resting on the floor; after 100 steps one falling particle is added above
    // them. Its index is 2 and it starts as given; the resting ones keep their state (their
    // contacts' histories included: the energy budget carries on within 1e-6 of the new
    // particle's potential energy) and the new one falls freely until it lands (z(t) to 1e-6).
    using Real = TestType;
    host_sim<Real> sim(silo<Real>(), two_on_the_floor<Real>());
    sim.run(100);
    const auto before = sim.snapshot();
    const double total_before = double(sim.energy().total());
    std::vector<sphere::particle<Real>> added(1);
    added[0].position = {0, 0, Real(0.15)};
    added[0].radius = Real(0.008);
    added[0].density = Real(2500);
    added[0].velocity = {0, 0, Real(-0.1)};
    sim.insert(added);
    REQUIRE(sim.size() == 3);
    const auto after = sim.snapshot();
    for (std::size_t i = 0; i < 2; ++i) {
        CHECK(after.x[i].x == before.x[i].x);
        CHECK(after.x[i].z == before.x[i].z);
        CHECK(after.v[i].z == before.v[i].z);
    }
    CHECK(after.x[2].z == Real(0.15));
    CHECK(after.v[2].z == Real(-0.1));
    const double m = sphere::sphere_mass(0.008, 2500.0);
    const double added_energy = 0.5 * m * 0.01 + m * 9.81 * double(Real(0.15));
    CHECK(std::fabs(double(sim.energy().total()) - total_before - added_energy) < 1e-6 * added_energy);
    const double t0 = sim.time();
    sim.run(1000);
    const double t = sim.time() - t0, z = double(Real(0.15)) - 0.1 * t - 0.5 * 9.81 * t * t;
    CHECK(std::fabs(double(sim.snapshot().x[2].z) - z) < 1e-6);
}

TEMPLATE_TEST_CASE("insert: overlapping or misplaced particles are refused, and nothing changes", "[insertion][errors]",
                   float, double)
{
    using Real = TestType;
    host_sim<Real> sim(silo<Real>(), two_on_the_floor<Real>());
    sim.run(10);
    const auto before = sim.snapshot();
    std::vector<sphere::particle<Real>> added(2);
    added[0].position = {0, 0, Real(0.1)};
    added[1].position = {Real(0.005), 0, Real(0.1)};
    for (auto& p : added) {
        p.radius = Real(0.005);
        p.density = Real(2500);
    }
    CHECK_THROWS_WITH(sim.insert(added), Catch::Contains("insert: particle 3 overlaps particle 2"));
    added.resize(1);
    added[0].position = {Real(-0.02), 0, Real(0.015)};
    CHECK_THROWS_WITH(sim.insert(added), Catch::Contains("insert: particle 2 overlaps particle 0"));
    added[0].position = {Real(0.048), 0, Real(0.1)};
    CHECK_THROWS_WITH(sim.insert(added), Catch::Contains("insert: particle 2 at ") &&
                                             Catch::Contains("crosses wall face 1"));
    added[0].radius = Real(-1);
    CHECK_THROWS_WITH(sim.insert(added), Catch::Contains("particle 2"));
    added[0].position = {0, 0, Real(0.1)};
    added[0].radius = Real(1e-4); // lighter than the time step allows
    CHECK_THROWS_WITH(sim.insert(added), Catch::Contains("exceeds the stable bound"));
    REQUIRE(sim.size() == 2);
    const auto after = sim.snapshot();
    CHECK(after.x[0].z == before.x[0].z);
    sim.run(10); // and it still runs
}

TEMPLATE_TEST_CASE("inserter: fills a silo at its rate, without overlap, the same way every time", "[insertion]", float,
                   double)
{
    // 2000 particles/s into the top of the box for 0.1 s, called every 50 steps (1 ms): 200
    // particles, radii in [4, 6] mm, each inserted clear of every other particle (smallest gap
    // >= 0 at its insertion) and within the region; the same seed gives the same bits.
    using Real = TestType;
    auto fill = [](std::vector<sphere::vec4<Real>>& out) {
        host_sim<Real> sim(silo<Real>(), two_on_the_floor<Real>());
        sphere::insertion_settings<Real> s;
        s.lo = {Real(-0.05), Real(-0.05), Real(0.1)};
        s.hi = {Real(0.05), Real(0.05), Real(0.2)};
        s.rate = 2000;
        s.radius_min = Real(0.004);
        s.radius_max = Real(0.006);
        s.density = Real(2500);
        s.seed = 7;
        sphere::inserter<host_sim<Real>> in(s, sim.time());
        double worst_gap = 1e30;
        for (int k = 0; k < 100; ++k) {
            sim.run(50);
            const std::size_t first = sim.size();
            if (!in(sim)) continue;
            const auto snap = sim.snapshot();
            worst_gap = std::fmin(worst_gap, smallest_gap(snap, first));
            for (std::size_t i = first; i < snap.size(); ++i)
                for (int a = 0; a < 3; ++a) {
                    CHECK(snap.position(i)[a] - snap.radius(i) >= s.lo[a]);
                    CHECK(snap.position(i)[a] + snap.radius(i) <= s.hi[a]);
                }
        }
        CHECK(worst_gap >= 0);
        CHECK(in.inserted() + in.waiting() == std::size_t(2000 * sim.time() + 1e-9));
        CHECK(in.waiting() == 0);
        const auto snap = sim.snapshot();
        for (std::size_t i = 2; i < snap.size(); ++i) {
            CHECK(snap.radius(i) >= Real(0.004));
            CHECK(snap.radius(i) <= Real(0.006));
        }
        out = snap.x;
        return in.inserted();
    };
    std::vector<sphere::vec4<Real>> a, b;
    const std::size_t n = fill(a);
    CHECK(n >= 199); // floor(2000 t) at t = 5000 dt
    fill(b);
    REQUIRE(a.size() == b.size());
    bool same = true;
    for (std::size_t i = 0; i < a.size(); ++i) same = same && a[i].x == b[i].x && a[i].z == b[i].z && a[i].w == b[i].w;
    CHECK(same);
}

TEMPLATE_TEST_CASE("insert: a run with insertions restarts from a checkpoint bit for bit", "[insertion][io]", double)
{
    using Real = TestType;
    sphere_test::temp_folder dir("insertion_checkpoint");
    host_sim<Real> sim(silo<Real>(), two_on_the_floor<Real>());
    sphere::insertion_settings<Real> s;
    s.lo = {Real(-0.05), Real(-0.05), Real(0.05)};
    s.hi = {Real(0.05), Real(0.05), Real(0.15)};
    s.rate = 5000;
    s.radius_min = s.radius_max = Real(0.005);
    s.density = Real(2500);
    sphere::inserter<host_sim<Real>> in(s, sim.time());
    for (int k = 0; k < 20; ++k) {
        sim.run(100);
        in(sim);
    }
    REQUIRE(sim.size() > 40);
    const std::string path = dir / "filled.ck";
    sphere::write_checkpoint(path, sim);
    host_sim<Real> again = sphere::restart<host_sim<Real>>(path);
    sim.run(500);
    again.run(500);
    const auto a = sim.snapshot(), b = again.snapshot();
    bool same = true;
    for (std::size_t i = 0; i < a.size(); ++i) same = same && a.x[i].z == b.x[i].z && a.v[i].x == b.v[i].x;
    CHECK(same);
}

TEMPLATE_TEST_CASE("inserter: log-normal radii within their range", "[insertion]", float, double)
{
    // 1500 particles into a large empty box at once: radii log-normal with mean 5 mm and standard
    // deviation 1 mm, kept in [2, 9] mm (beyond 3 sigma: the truncation moves the moments by
    // < 0.1%); the sample mean within 2% and the standard deviation within 8% (about 4 standard
    // errors), every radius in the range.
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>(Real(0.5));
    s.dt = Real(1e-5);
    std::vector<sphere::particle<Real>> one(1);
    one[0].position = {0, 0, 0};
    one[0].radius = Real(0.01);
    one[0].density = Real(2500);
    host_sim<Real> sim(s, one);
    sphere::insertion_settings<Real> in_s;
    in_s.lo = {Real(-0.45), Real(-0.45), Real(-0.45)};
    in_s.hi = {Real(0.45), Real(0.45), Real(0.45)};
    in_s.rate = 1e9;
    in_s.total = 1500;
    in_s.radius_min = Real(0.002);
    in_s.radius_max = Real(0.009);
    in_s.distribution = sphere::radius_distribution::lognormal;
    in_s.radius_mean = Real(0.005);
    in_s.radius_stddev = Real(0.001);
    in_s.density = Real(2500);
    sphere::inserter<host_sim<Real>> in(in_s, sim.time());
    sim.step();
    REQUIRE(in(sim) == 1500);
    const auto snap = sim.snapshot();
    double sum = 0, sum2 = 0;
    for (std::size_t i = 1; i < snap.size(); ++i) {
        const double r = double(snap.radius(i));
        CHECK(r >= 0.002 - 1e-12);
        CHECK(r <= 0.009 + 1e-12);
        sum += r;
        sum2 += r * r;
    }
    const double mean = sum / 1500, sd = std::sqrt(sum2 / 1500 - mean * mean);
    CHECK(std::fabs(mean / 0.005 - 1) < 0.02);
    CHECK(std::fabs(sd / 0.001 - 1) < 0.08);
    in_s.radius_mean = Real(0.01);
    CHECK_THROWS_WITH(sphere::inserter<host_sim<Real>>(in_s, 0.0),
                      Catch::Contains("insertion_settings.radius_mean = ") && Catch::Contains("lies outside"));
}

} // namespace test_insertion
