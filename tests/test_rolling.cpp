// Rolling and twisting resistance (contact/rolling.cuh) on the linear law with elastic
// tangential springs at walls too. A ball of set P (r = 0.01 m, rho = 2500 kg/m^3, k_n = 1e5
// N/m) on the floor of the box under g = 9.81 m/s^2: rolling, it stops where a constant torque
// mu_r R m g says; on an incline below the rolling angle atan(mu_r) it stays, above it it
// accelerates as that torque says; spinning about the normal, it stops after the angle a
// constant twisting torque says. Then the history's lanes: seen from both particles in the
// contact table, carried through rebuilds (a spinning, bonded pair keeps its energy), through
// checkpoints bit for bit, and the audit of a pile. References: docs/physics.md, "Rolling and
// twisting resistance". float, double, mixed.
#include <catch2/catch.hpp>

#include "support.hpp"
#include "temp_folder.hpp"

#include <sphere/io.cuh>

#include <cmath>
#include <cstddef>
#include <type_traits>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_rolling {

namespace {

using sphere_test::user_real;
using rolling_law = sphere::contact::rolling<>;
template <class P>
using rolling_sim = sphere::simulation<P, sphere_test::policy, rolling_law>;

constexpr double g = 9.81, radius = 0.01, density = 2500, k_n = 1e5;
constexpr double mass = 4.0 / 3.0 * 3.14159265358979323846 * radius * radius * radius * density;

/// The box [-0.1, 0.1]^3, set-P springs, friction 0.5, light damping, rolling resistance
/// mu_r (k_r = 0.5 N m/rad, half its critical damping about the contact point) and twisting
/// resistance mu_twist, the same between particles and at walls; gravity along `down` (unit).
template <class P>
typename rolling_sim<P>::settings_type rolling_box(double mu_r, double mu_twist, sphere::vec3<double> down = {0, 0, -1})
{
    using Real = user_real<P>;
    typename rolling_sim<P>::settings_type s;
    s.box.lo = {Real(-0.1), Real(-0.1), Real(-0.1)};
    s.box.hi = {Real(0.1), Real(0.1), Real(0.1)};
    s.contact.k_n = Real(k_n);
    s.contact.k_t = Real(k_n * 2 / 7);
    s.contact.gamma_n = Real(2);
    s.contact.gamma_t = Real(2);
    s.contact.mu_s = s.contact.mu_d = Real(0.5);
    const double inertia_at_contact = 1.4 * mass * radius * radius, k_r = 0.5;
    s.contact.mu_r = Real(mu_r);
    s.contact.k_r = Real(k_r);
    s.contact.gamma_r = Real(std::sqrt(k_r * inertia_at_contact));
    if (mu_twist > 0) {
        s.contact.mu_twist = Real(mu_twist);
        s.contact.k_twist = Real(k_r);
        s.contact.gamma_twist = Real(std::sqrt(k_r * 0.4 * mass * radius * radius));
    }
    s.wall = s.contact;
    s.gravity = {Real(g * down.x), Real(g * down.y), Real(g * down.z)};
    return s;
}

/// A ball resting on the floor (z = -0.1) at its static overlap under gravity g cos(alpha).
template <class Real>
sphere::particle<Real> ball_on_floor(double x, double cos_alpha = 1)
{
    sphere::particle<Real> b;
    b.position = {Real(x), 0, Real(-0.1 + radius - mass * g * cos_alpha / k_n)};
    b.radius = Real(radius);
    b.density = Real(density);
    return b;
}

} // namespace

TEMPLATE_TEST_CASE("rolling: a ball rolling on a plane stops where a constant rolling torque says", "[rolling]", float,
                   double, sphere::mixed)
{
    // Rolling without slipping at v0 against M = mu_r R m g (R* = R at a wall): the centre
    // decelerates at 5 mu_r g / 7 and stops after s = 7 v0^2 / (10 mu_r g). Checked within 1%
    // at rest after 1.5 times the stopping time (the springs' give is ~1e-6 m of s = 1.4 cm).
    using Real = user_real<TestType>;
    for (const double mu_r : {0.05, 0.1}) {
        const double v0 = 0.1, s_ref = 7 * v0 * v0 / (10 * mu_r * g), t_stop = v0 / (5 * mu_r * g / 7);
        std::vector<sphere::particle<Real>> ps{ball_on_floor<Real>(-0.08)};
        ps[0].velocity = {Real(v0), 0, 0};
        ps[0].angular_velocity = {0, Real(v0 / radius), 0};
        rolling_sim<TestType> sim(rolling_box<TestType>(mu_r, 0), ps);
        sim.run(static_cast<std::size_t>(1.5 * t_stop / double(sim.dt())));
        const auto snap = sim.snapshot();
        INFO("mu_r " << mu_r);
        CHECK(std::fabs((double(snap.x[0].x) + 0.08) / s_ref - 1) < 0.01);
        CHECK(std::fabs(double(snap.v_sync[0].x)) < 1e-3 * v0);
        CHECK(std::fabs(double(snap.omega_sync[0].y)) < 1e-3 * v0 / radius);
    }
}

TEMPLATE_TEST_CASE("rolling: a ball on an incline stays below the rolling angle and rolls above it", "[rolling]", float,
                   double, sphere::mixed)
{
    // Gravity tilted by alpha along x. Below the rolling angle (tan alpha = 0.8 mu_r) the
    // springs hold the ball: after 0.5 s it has moved less than 1e-5 m (the springs' give is
    // ~1e-6 m) and is at rest. Above it (tan alpha = 1.2 mu_r) it rolls with
    // a = 5 g (sin alpha - mu_r cos alpha) / 7 once the rolling spring has reached its limit
    // (after ~2 ms): the velocity gained from 0.25 s to 0.5 s within 1%. Without rolling
    // resistance it would accelerate at 5 g sin alpha / 7, six times as fast.
    using Real = user_real<TestType>;
    const double mu_r = 0.05;
    for (const double ratio : {0.8, 1.2}) {
        const double alpha = std::atan(ratio * mu_r), sa = std::sin(alpha), ca = std::cos(alpha);
        std::vector<sphere::particle<Real>> ps{ball_on_floor<Real>(-0.05, ca)};
        rolling_sim<TestType> sim(rolling_box<TestType>(mu_r, 0, {sa, 0, -ca}), ps);
        const std::size_t quarter = static_cast<std::size_t>(0.25 / double(sim.dt()));
        sim.run(quarter);
        const double t1 = sim.time(), v1 = double(sim.snapshot().v_sync[0].x);
        sim.run(quarter);
        const auto snap = sim.snapshot();
        const double moved = double(snap.x[0].x) + 0.05, v2 = double(snap.v_sync[0].x);
        INFO("tan alpha / mu_r = " << ratio << ", moved " << moved << " m");
        if (ratio < 1) {
            CHECK(std::fabs(moved) < 1e-5);
            CHECK(std::fabs(v2) < 1e-5);
        } else {
            const double a = 5 * g * (sa - mu_r * ca) / 7;
            CHECK(std::fabs((v2 - v1) / (sim.time() - t1) / a - 1) < 0.01);
        }
    }
}

TEMPLATE_TEST_CASE("rolling: a ball spinning about the normal stops after the angle a constant twisting torque says",
                   "[rolling]", float, double, sphere::mixed)
{
    // Spin omega0 about z on the floor against M = mu_twist R m g: I omega0^2 / 2 = M theta,
    // theta = r omega0^2 / (5 mu_twist g) = 1.63 rad for omega0 = 20 rad/s, mu_twist = 0.05;
    // within 1%, and the ball neither moves nor keeps spinning.
    using Real = user_real<TestType>;
    const double omega0 = 20, mu_twist = 0.05;
    const double theta_ref = radius * omega0 * omega0 / (5 * mu_twist * g), t_stop = 0.4 * radius * omega0 / (mu_twist * g);
    std::vector<sphere::particle<Real>> ps{ball_on_floor<Real>(0)};
    ps[0].angular_velocity = {0, 0, Real(omega0)};
    rolling_sim<TestType> sim(rolling_box<TestType>(0.05, mu_twist), ps);
    sim.run(static_cast<std::size_t>(1.5 * t_stop / double(sim.dt())));
    const auto snap = sim.snapshot();
    CHECK(std::fabs(double(snap.angpos[0].z) / theta_ref - 1) < 0.01);
    CHECK(std::fabs(double(snap.omega_sync[0].z)) < 1e-3 * omega0);
    CHECK(std::fabs(double(snap.x[0].x)) < 1e-9);
}

TEMPLATE_TEST_CASE("rolling: the contact table shows each contact's angles from both particles", "[rolling]", float,
                   double)
{
    // Two balls pressed together along x by gravity towards the -x wall, the outer one turned
    // about y and about x: the entry of (1, 0) holds the rolling angle of (0, 1) reversed and
    // the same twisting angle, both non-zero.
    using Real = user_real<TestType>;
    std::vector<sphere::particle<Real>> ps(2);
    for (int i = 0; i < 2; ++i) {
        ps[i].position = {Real(-0.1 + radius + 2 * radius * i), 0, 0};
        ps[i].radius = Real(radius);
        ps[i].density = Real(density);
    }
    ps[1].angular_velocity = {Real(0.5), Real(1), 0};
    rolling_sim<TestType> sim(rolling_box<TestType>(0.05, 0.05, {-1, 0, 0}), ps);
    sim.run(20);
    const sphere::contact_table<Real> t = sim.contacts();
    REQUIRE(t.shape.lanes == 4);
    const std::size_t a = t.find(0, 1), b = t.find(1, 0);
    REQUIRE(a != ~std::size_t(0));
    REQUIRE(b != ~std::size_t(0));
    CHECK(t.lane[4 * a + 1] != Real(0));
    CHECK(t.lane[4 * a + 3] != Real(0));
    for (int l = 0; l < 3; ++l) CHECK(t.lane[4 * b + l] == -t.lane[4 * a + l]);
    CHECK(t.lane[4 * b + 3] == t.lane[4 * a + 3]);
}

namespace {

/// What a pair held together by a liquid bridge did while turning against itself.
struct turning_pair {
    double worst;            ///< the largest error of the energy at any sample (J)
    double turning;          ///< the pair's rotational energy at the start (J)
    double spin;             ///< omega_y of particle 0 at the end (rad/s)
    std::size_t rebuilds;
};

/// Two balls held together by a liquid bridge (capillary<rolling<>>, no damping) in a
/// periodic box, both moving at `speed` (m/s) along x, y and z, while they turn against each
/// other about y (rolling) and x (twisting), for 10000 steps.
template <class P>
turning_pair turn_pair(double speed)
{
    using Real = user_real<P>;
    using wet_rolling = sphere::contact::capillary<rolling_law>;
    using sim_type = sphere::simulation<P, sphere_test::policy, wet_rolling>;
    typename sim_type::settings_type s;
    s.box.lo = {Real(-0.1), Real(-0.1), Real(-0.1)};
    s.box.hi = {Real(0.1), Real(0.1), Real(0.1)};
    for (int a = 0; a < 3; ++a) s.box.axis[a] = sphere::boundary::periodic;
    s.contact.k_n = Real(k_n);
    s.contact.k_t = Real(k_n * 2 / 7);
    s.contact.mu_s = s.contact.mu_d = Real(0.5);
    s.contact.mu_r = s.contact.mu_twist = Real(1);
    s.contact.k_r = s.contact.k_twist = Real(0.5);
    s.contact.surface_tension = Real(0.072);
    s.contact.bridge_volume = Real(1e-9);
    s.wall = s.contact;
    s.skin = Real(5e-4);
    const double pull = 2 * 3.14159265358979323846 * radius * 0.072; // F(0) for R = 2 R* = r
    std::vector<sphere::particle<Real>> ps(2);
    for (int i = 0; i < 2; ++i) {
        ps[i].position = {Real(-0.05 + (2 * radius - pull / k_n) * i), Real(0.01), Real(-0.02)};
        ps[i].radius = Real(radius);
        ps[i].density = Real(density);
        ps[i].velocity = {Real(speed), Real(speed), Real(speed)};
        ps[i].angular_velocity = {Real(i ? -2 : 2), Real(i ? -3 : 3), 0};
    }
    sim_type sim(s, ps);
    const double e0 = double(sim.energy().total());
    turning_pair out{0, double(sim.energy().rotational), 0, 0};
    for (int k = 0; k < 200; ++k) {
        sim.run(50);
        out.worst = std::fmax(out.worst, std::fabs(double(sim.energy().total()) - e0));
    }
    const auto snap = sim.snapshot();
    const double gap = std::sqrt(sphere::norm2(sphere::vec_cast<double>(snap.x[1].xyz() - snap.x[0].xyz()))) - 2 * radius;
    CHECK(gap < 0); // still together
    out.spin = double(snap.omega_sync[0].y);
    out.rebuilds = sim.rebuilds();
    return out;
}

} // namespace

TEMPLATE_TEST_CASE("rolling: a pair flying across the grid turns as it does at rest, through rebuilds",
                   "[rolling][energy]", float, double, sphere::mixed)
{
    // The pair of turn_pair at rest (one list build) and flying at 1 m/s (a rebuild every
    // ~0.3 ms, over 1600 of them): the springs' angles are carried through every rebuild, so
    // the flying pair turns as the resting one does (its final spin within 1e-9 in double and
    // mixed) and keeps its energy as well (within 1e-3 of the turning energy at the default time
    // step; a lost angle would release up to all of it). In float the flying pair's positions
    // (0.1 m, resolved to ~6e-9 m) resolve its 4.5e-8 m overlap to ~10%: its normal spring
    // jitters, so its spin is not compared and its energy holds to 2e-2.
    const turning_pair rest = turn_pair<TestType>(0), flying = turn_pair<TestType>(1);
    INFO("rebuilds " << flying.rebuilds << ", worst energy errors " << rest.worst << " and " << flying.worst
                     << " J of " << rest.turning << ", spins " << rest.spin << " and " << flying.spin);
    CHECK(rest.rebuilds == 1);
    CHECK(flying.rebuilds > 1000);
    CHECK(rest.worst < 1e-3 * rest.turning);
    if constexpr (std::is_same_v<TestType, float>) {
        CHECK(flying.worst < 2e-2 * rest.turning);
    } else {
        CHECK(flying.worst < 1e-3 * rest.turning);
        CHECK(std::fabs(flying.spin - rest.spin) < 1e-9 * 3);
    }
}

TEMPLATE_TEST_CASE("rolling: the energy budget of a damped, rolling pile closes", "[rolling][energy]", float, double,
                   sphere::mixed)
{
    // 27 spinning balls dropped into a corner of the box with friction, rolling and twisting
    // resistance between particles and at walls, at dt = the default / 4 for 0.5 s, sampled every
    // 800 steps: energy().total() (kinetic, rotational, potential, springs, dissipated) stays
    // within 2e-3 of the potential energy the pile loses, as for the other laws, with rolling
    // and twisting springs loaded in the contacts at the end. (The frictional dissipation booked may go
    // negative here, as for the tangential spring: docs/physics.md, "Rolling and twisting
    // resistance".)
    using Real = user_real<TestType>;
    std::vector<sphere::particle<Real>> ps;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) {
                sphere::particle<Real> b;
                b.position = {Real(-0.085 + 0.022 * i + 0.001 * k), Real(-0.085 + 0.022 * j), Real(-0.085 + 0.022 * k)};
                b.radius = Real(radius * (0.9 + 0.05 * ((i + 2 * j + k) % 3)));
                b.density = Real(density);
                b.angular_velocity = {Real(5 * (j - 1)), Real(5 * (k - 1)), Real(5 * (i - 1))};
                ps.push_back(b);
            }
    typename rolling_sim<TestType>::settings_type s = rolling_box<TestType>(0.1, 0.05);
    s.energy_audit = true;
    s.dt = Real(rolling_sim<TestType>(s, ps).dt() / 4);
    rolling_sim<TestType> sim(s, ps);
    const auto e0 = sim.energy();
    double worst = 0;
    for (int k = 0; k < 100; ++k) {
        sim.run(800);
        worst = std::fmax(worst, std::fabs(double(sim.energy().total()) - double(e0.total())));
    }
    const auto e = sim.energy();
    const double lost = double(e0.potential) - double(e.potential);
    INFO("worst " << worst << " J, lost " << lost << " J");
    REQUIRE(lost > 0);
    CHECK(worst < 2e-3 * lost);
    const sphere::contact_table<Real> t = sim.contacts();
    std::size_t rolling = 0, twisting = 0;
    for (std::size_t e = 0; e < t.partner.size(); ++e) {
        rolling += t.lane[4 * e] != Real(0) || t.lane[4 * e + 1] != Real(0);
        twisting += t.lane[4 * e + 3] != Real(0);
    }
    // The pile ends with 10-13 pair contacts (float, double and mixed sum in different
    // orders and settle differently); nearly all carry loaded springs.
    INFO(t.partner.size() << " contacts, " << rolling << " with a rolling, " << twisting << " with a twisting spring");
    CHECK(t.partner.size() >= 8);
    CHECK(rolling >= 0.8 * double(t.partner.size()));
    CHECK(twisting >= 0.8 * double(t.partner.size()));
}

TEMPLATE_TEST_CASE("rolling: a checkpoint keeps the angles and restarts bit for bit", "[rolling][io]", double,
                   sphere::mixed)
{
    using Real = user_real<TestType>;
    std::vector<sphere::particle<Real>> ps{ball_on_floor<Real>(-0.08), ball_on_floor<Real>(-0.06)};
    ps[0].velocity = {Real(0.1), 0, 0};
    ps[0].angular_velocity = {0, Real(10), Real(5)};
    const typename rolling_sim<TestType>::settings_type s = rolling_box<TestType>(0.05, 0.05);
    rolling_sim<TestType> straight(s, ps);
    straight.run(300);
    sphere_test::temp_folder dir("rolling_checkpoint");
    const std::string path = dir / "rolling.ck";
    sphere::write_checkpoint(path, straight);
    straight.run(300);
    rolling_sim<TestType> restarted = sphere::restart<rolling_sim<TestType>>(path);
    restarted.run(300);
    const auto a = straight.snapshot(), b = restarted.snapshot();
    for (std::size_t i = 0; i < 2; ++i) {
        CHECK(a.x[i].x == b.x[i].x);
        CHECK(a.x[i].z == b.x[i].z);
        CHECK(a.omega[i].y == b.omega[i].y);
        CHECK(a.omega[i].z == b.omega[i].z);
    }
    const sphere::contact_table<Real> ta = straight.contacts(), tb = restarted.contacts();
    CHECK(ta.lane == tb.lane);
    // another law refuses it by name
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(path), Catch::Contains("rolling<"));
}

TEMPLATE_TEST_CASE("rolling: bad parameters are refused by name", "[rolling][errors]", float, double)
{
    using Real = TestType;
    std::vector<sphere::particle<Real>> ps{ball_on_floor<Real>(0)};
    auto refused = [&](auto change, const char* what) {
        typename rolling_sim<Real>::settings_type s = rolling_box<Real>(0.05, 0.05);
        change(s);
        CHECK_THROWS_WITH(rolling_sim<Real>(s, ps), Catch::Contains(what));
    };
    refused([](auto& s) { s.contact.mu_r = Real(-1); }, "settings.contact.mu_r = -1");
    refused([](auto& s) { s.wall.k_r = Real(NAN); }, "settings.wall.k_r = nan");
    refused([](auto& s) { s.contact.gamma_twist = Real(-2); }, "settings.contact.gamma_twist = -2");
    refused([](auto& s) { s.contact.k_r = 0; }, "settings.contact.k_r = 0 turns rolling resistance off");
    refused([](auto& s) { s.wall.k_twist = 0; }, "settings.wall.k_twist = 0 turns twisting resistance off");
    // turned off altogether, and the time step: the rotation's scale when it is the smaller
    typename rolling_sim<Real>::settings_type off = rolling_box<Real>(0, 0);
    off.contact.k_r = off.contact.gamma_r = off.wall.k_r = off.wall.gamma_r = 0;
    CHECK_NOTHROW(rolling_sim<Real>(off, ps));
    typename rolling_sim<Real>::settings_type stiff = rolling_box<Real>(0.05, 0);
    stiff.wall.k_r = Real(100);
    const double turning = std::sqrt(0.2 * mass * radius * radius / 100);
    CHECK(std::fabs(double(rolling_sim<Real>(stiff, ps).dt()) / (0.075 * turning) - 1) < 1e-5);
}

} // namespace test_rolling
