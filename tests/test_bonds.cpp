// Parallel bonds (bonds/; docs/physics.md, "Bonds"). Particles of set P (r = 0.01 m,
// rho = 2500 kg/m^3) joined by bonds of radius r (radius_ratio 1), k_n = 1e9 Pa/m: axial
// K_n = k_n pi r^2, bending K_b = k_n pi r^4 / 4, twisting K_w = k_t pi r^4 / 2. A free pair
// oscillates axially at sqrt(2 K_n / m), in bending (k_t = 0) at sqrt(2 K_b / I) and in
// twisting at sqrt(2 K_w / I) (1%); a bond pulled, sheared, bent or twisted breaks where its
// strength says (1%); a chain of six bonded particles under its weight, clamped at one end,
// deflects as an Euler-Bernoulli cantilever of EI = K_b L (5%); the energy audit closes with
// bonds (and with a bond breaking); checkpoints restart bit for bit; bad input is refused by
// name. float, double, mixed.
#include <catch2/catch.hpp>

#include "support.hpp"
#include "temp_folder.hpp"

#include <sphere/io.cuh>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_bonds {

namespace {

using sphere_test::user_real;
template <class P, class Integrator = sphere::integrate::semi_implicit_euler>
using bonded_sim = sphere::simulation<P, sphere_test::policy, sphere::contact::linear<>, Integrator>;

constexpr double pi = 3.14159265358979323846;
constexpr double radius = 0.01, density = 2500, k_n = 1e9;
constexpr double mass = 4.0 / 3.0 * pi * radius * radius * radius * density;
constexpr double inertia = 0.4 * mass * radius * radius;
constexpr double area = pi * radius * radius, second_moment = pi * radius * radius * radius * radius / 4;

/// The box [-0.1, 0.1]^3, set-P contacts, and bonds of k_n = 1e9 Pa/m, k_t = k_t_ratio k_n.
template <class Real>
sphere::settings<Real> bond_box(double k_t_ratio, double damping = 0)
{
    sphere::settings<Real> s = sphere_test::box_settings<Real>();
    s.bond.k_n = Real(k_n);
    s.bond.k_t = Real(k_n * k_t_ratio);
    s.bond.damping = Real(damping);
    return s;
}

template <class Real>
sphere::particle<Real> ball(double x, double y = 0, double z = 0)
{
    sphere::particle<Real> b;
    b.position = {Real(x), Real(y), Real(z)};
    b.radius = Real(radius);
    b.density = Real(density);
    return b;
}

/// Two particles on the x axis, 2.2 r apart (not touching): 0 at -1.1 r, 1 at +1.1 r.
template <class Real>
std::vector<sphere::particle<Real>> pair()
{
    return {ball<Real>(-1.1 * radius), ball<Real>(1.1 * radius)};
}

/// The mean period (s) of a sampled signal from its upward zero crossings (interpolated).
double period_of(const std::vector<double>& t, const std::vector<double>& y)
{
    std::vector<double> crossings;
    for (std::size_t k = 1; k < y.size(); ++k)
        if (y[k - 1] < 0 && y[k] >= 0) crossings.push_back(t[k - 1] + (t[k] - t[k - 1]) * -y[k - 1] / (y[k] - y[k - 1]));
    REQUIRE(crossings.size() >= 5);
    return (crossings.back() - crossings.front()) / double(crossings.size() - 1);
}

/// Runs `sim` for about `periods` of `omega` (rad/s), sampling f(sim) every step, and
/// returns the measured period over the expected one.
template <class Sim, class F>
double period_ratio(Sim& sim, double omega, double periods, F f)
{
    const double expected = 2 * pi / omega;
    std::vector<double> t, y;
    const auto steps = std::size_t(periods * expected / double(sim.dt()));
    for (std::size_t k = 0; k < steps; ++k) {
        sim.step();
        t.push_back(sim.time());
        y.push_back(f(sim));
    }
    return period_of(t, y) / expected;
}

} // namespace

TEMPLATE_TEST_CASE("bonds: a bonded pair oscillates axially, in bending and in twisting at the analytic frequencies",
                   "[bonds]", float, double, sphere::mixed)
{
    using Real = user_real<TestType>;
    SECTION("axial: omega = sqrt(2 K_n / m), K_n = k_n pi R^2")
    {
        std::vector<sphere::particle<Real>> p = pair<Real>();
        p[0].velocity = {Real(-0.05), 0, 0};
        p[1].velocity = {Real(0.05), 0, 0};
        bonded_sim<TestType> sim(bond_box<Real>(0.5), p, {{0, 1}});
        const double omega = std::sqrt(2 * k_n * area / mass);
        const double ratio = period_ratio(sim, omega, 10, [](const auto& s) {
            const auto x = s.snapshot();
            return double(x.position(1).x - x.position(0).x) - 2.2 * radius;
        });
        CHECK(ratio == Approx(1).margin(0.01));
    }
    SECTION("bending (k_t = 0): omega = sqrt(2 K_b / I), K_b = k_n pi R^4 / 4")
    {
        std::vector<sphere::particle<Real>> p = pair<Real>();
        p[0].angular_velocity = {0, 0, Real(2)};
        p[1].angular_velocity = {0, 0, Real(-2)};
        bonded_sim<TestType> sim(bond_box<Real>(0), p, {{0, 1}});
        const double omega = std::sqrt(2 * k_n * second_moment / inertia);
        const double ratio = period_ratio(sim, omega, 10, [](const auto& s) { return double(s.snapshot().omega_sync[0].z); });
        CHECK(ratio == Approx(1).margin(0.01));
        CHECK(sim.bonds().force[0].x == 0); // k_t = 0 and no stretch: a pure couple
    }
    SECTION("twisting: omega = sqrt(2 K_w / I), K_w = k_t pi R^4 / 2")
    {
        std::vector<sphere::particle<Real>> p = pair<Real>();
        p[0].angular_velocity = {Real(2), 0, 0};
        p[1].angular_velocity = {Real(-2), 0, 0};
        bonded_sim<TestType> sim(bond_box<Real>(0.5), p, {{0, 1}});
        const double omega = std::sqrt(2 * 0.5 * k_n * 2 * second_moment / inertia);
        const double ratio = period_ratio(sim, omega, 10, [](const auto& s) { return double(s.snapshot().omega_sync[0].x); });
        CHECK(ratio == Approx(1).margin(0.01));
    }
}

TEMPLATE_TEST_CASE("bonds: a bond breaks where its tensile or shear strength says", "[bonds]", float, double,
                   sphere::mixed)
{
    // Particle 0 fixed, particle 1 driven at a constant velocity or spin (motion::prescribed):
    // tension breaks at stretch sigma_c / k_n, shear at a shear displacement tau_c / k_t,
    // bending at an angle sigma_c / (k_n R), twisting at an angle tau_c / (k_t R); each
    // within 1% (a step moves 1e-3 of it).
    using Real = user_real<TestType>;
    const double sigma_c = 2e4, tau_c = 1e4, k_t = 0.5 * k_n;
    struct load {
        const char* name;
        sphere::vec3<double> v, w;
        double expected;   // the displacement (m) or angle (rad) at which the bond breaks
        bool tensile;      // which strength is finite
    };
    const double dt = 1e-6;
    const load loads[] = {
        {"tension", {sigma_c / k_n / 1000 / dt, 0, 0}, {0, 0, 0}, sigma_c / k_n, true},
        {"shear", {0, tau_c / k_t / 1000 / dt, 0}, {0, 0, 0}, tau_c / k_t, false},
        {"bending", {0, 0, 0}, {0, 0, sigma_c / (k_n * radius) / 1000 / dt}, sigma_c / (k_n * radius), true},
        {"twisting", {0, 0, 0}, {tau_c / (k_t * radius) / 1000 / dt, 0, 0}, tau_c / (k_t * radius), false},
    };
    for (const load& l : loads) {
        INFO(l.name);
        sphere::settings<Real> s = bond_box<Real>(0.5);
        s.dt = Real(dt);
        (l.tensile ? s.bond.tensile_strength : s.bond.shear_strength) = Real(l.tensile ? sigma_c : tau_c);
        std::vector<sphere::particle<Real>> p = pair<Real>();
        p[0].kind = sphere::motion::fixed;
        p[1].kind = sphere::motion::prescribed;
        p[1].velocity = {Real(l.v.x), Real(l.v.y), Real(l.v.z)};
        p[1].angular_velocity = {Real(l.w.x), Real(l.w.y), Real(l.w.z)};
        bonded_sim<TestType> sim(s, p, {{0, 1}});
        const double start = double(sim.energy().total());
        // How far particle 1 has moved or turned: the bond that breaks in a step saw the
        // positions before it.
        const auto moved = [&] {
            const auto x = sim.snapshot();
            const bool turns = norm(l.w) > 0;
            return turns ? double(norm(x.angpos[1])) : double(norm(x.position(1) - sphere::vec3<Real>{Real(1.1 * radius), 0, 0}));
        };
        double before = 0;
        for (std::size_t steps = 0; sim.broken_bonds() == 0 && steps < 3000; ++steps) {
            before = moved();
            sim.step();
        }
        REQUIRE(sim.broken_bonds() == 1);
        CHECK(sim.bonds().broken[0] == 1);
        CHECK(before / l.expected == Approx(1).margin(0.01));
        const sphere::energy_budget<Real> e = sim.energy();
        CHECK(e.bond_elastic == 0);
        CHECK(e.bond_broken > 0);
        // The drive's work went into the bond and was released when it broke: to 1% (a step's
        // share), 5% in float, whose positions near 0.011 m round each step's 2e-8 m by 2%.
        const double share = std::is_same_v<TestType, float> ? 0.05 : 0.01;
        CHECK(double(e.total()) == Approx(start).margin(share * double(e.bond_broken)));
        CHECK(sim.bonds().force[0].x == 0); // a broken bond pulls no more
    }
}

TEMPLATE_TEST_CASE("bonds: a bonded chain clamped at one end deflects under its weight as an Euler-Bernoulli "
                   "cantilever",
                   "[bonds][slow]", float, double, sphere::mixed)
{
    // Six particles on the x axis, 2.1 r apart, particle 0 fixed (its bond clamps the chain's
    // rotation too); gravity g along -z loads particles 1 to 5 with m g each. A cantilever of
    // bending stiffness EI = K_b L (each bond a beam of length L) deflects at its tip by
    // sum_p m g x_p^2 (3 L_tip - x_p) / (6 EI) (point loads at x_p = p L). Within 5%: the
    // chain concentrates each bond's bending at its centre and adds the shear springs' give
    // (each below 1% here). The bonds' dashpots (critical) settle it in about 350000 steps.
    using Real = user_real<TestType>;
    const double L = 2.1 * radius, g = 9.81;
    sphere::settings<Real> s = bond_box<Real>(1, 1);
    s.gravity = {0, 0, Real(-g)};
    s.skin = Real(0.002); // the lists need no rebuild: a step costs a fifth
    std::vector<sphere::particle<Real>> p;
    std::vector<sphere::bond> bonds;
    for (int k = 0; k < 6; ++k) {
        p.push_back(ball<Real>(-0.05 + k * L));
        if (k > 0) bonds.push_back({std::size_t(k - 1), std::size_t(k)});
    }
    p[0].kind = sphere::motion::fixed;
    bonded_sim<TestType, sphere::integrate::velocity_verlet> sim(s, p, bonds);
    const double EI = k_n * second_moment * L, tip = 5 * L;
    double expected = 0;
    for (int k = 1; k <= 5; ++k) expected += mass * g * (k * L) * (k * L) * (3 * tip - k * L) / (6 * EI);
    const auto deflection = [&] { return -double(sim.snapshot().position(5).z); };
    // Settled when the deflection changes by less than 1e-4 of itself in a thousand steps.
    double before = 0, now = 0;
    for (int k = 0; k < 2000; ++k) {
        sim.run(1000);
        now = deflection();
        if (k > 10 && std::fabs(now - before) < 1e-4 * now) break;
        before = now;
    }
    INFO("steps " << sim.steps() << ", tip deflection " << now << " m, Euler-Bernoulli " << expected << " m");
    CHECK(now / expected == Approx(1).margin(0.05));
    CHECK(sim.broken_bonds() == 0);
}

TEMPLATE_TEST_CASE("bonds: the energy budget closes with damped bonds and with a bond that breaks", "[bonds][energy]",
                   float, double, sphere::mixed)
{
    // Velocity Verlet. A pair oscillating in every mode with dashpots at a tenth of critical:
    // energy().total() (kinetic, rotational, bond_elastic, the dashpots' dissipation) stays
    // within 1% of its start while the dashpots take most of it. A pair flying apart at
    // 0.5 m/s whose bond breaks in tension: the energy it held is booked as bond_broken, and
    // the total stays within 1%.
    using Real = user_real<TestType>;
    using sim_type = bonded_sim<TestType, sphere::integrate::velocity_verlet>;
    SECTION("damped oscillation")
    {
        std::vector<sphere::particle<Real>> p = pair<Real>();
        p[0].velocity = {Real(-0.05), Real(0.02), 0};
        p[1].velocity = {Real(0.05), Real(-0.01), Real(0.01)};
        p[0].angular_velocity = {Real(3), Real(-1), Real(2)};
        p[1].angular_velocity = {Real(-1), Real(2), 0};
        sim_type sim(bond_box<Real>(0.5, 0.1), p, {{0, 1}});
        const double start = double(sim.energy().total());
        double most_elastic = 0;
        for (int k = 0; k < 40; ++k) {
            sim.run(50);
            const sphere::energy_budget<Real> e = sim.energy();
            most_elastic = std::max(most_elastic, double(e.bond_elastic));
            CHECK(double(e.total()) == Approx(start).epsilon(0.01));
        }
        const sphere::energy_budget<Real> e = sim.energy();
        CHECK(most_elastic > 0.1 * start);
        CHECK(double(e.dissipated_visc) > 0.5 * start);
        CHECK(double(e.bond_broken) == 0);
    }
    SECTION("a bond breaking in tension")
    {
        // A bond breaks in the step whose stretch exceeds its strength, and the energy it held
        // then is booked, although the last half kick did not feel it: the audit closes to
        // about the stretch of one step over the breaking stretch (v dt / s = 2% here, with
        // a tenth of the default step).
        sphere::settings<Real> s = bond_box<Real>(0.5);
        s.bond.tensile_strength = Real(5e4);
        s.dt = Real(1e-6);
        std::vector<sphere::particle<Real>> p = pair<Real>();
        p[0].velocity = {Real(-0.5), 0, 0};
        p[1].velocity = {Real(0.5), 0, 0};
        sim_type sim(s, p, {{0, 1}});
        const double start = double(sim.energy().total());
        sim.run(200);
        REQUIRE(sim.broken_bonds() == 1);
        const sphere::energy_budget<Real> e = sim.energy();
        CHECK(double(e.bond_elastic) == 0);
        // The bond held about K_n (sigma_c / k_n)^2 / 2 when it broke (within a step's stretch).
        const double held = 0.5 * k_n * area * (5e4 / k_n) * (5e4 / k_n);
        CHECK(double(e.bond_broken) == Approx(held).epsilon(0.05));
        CHECK(double(e.total()) == Approx(start).epsilon(0.01));
    }
}

namespace {
/// 27 particles on a 3 x 3 x 3 lattice 2.4 r apart under gravity, about half of them bonded in
/// pairs (random_bond_pairs, touching), in a box with damped, frictional contacts.
template <class P>
struct bonded_sample {
    using Real = user_real<P>;
    sphere::settings<Real> settings;
    std::vector<sphere::particle<Real>> particles;
    std::vector<sphere::bond> bonds;
    explicit bonded_sample(std::uint64_t seed = 7)
    {
        settings = sphere_test::frictional_box<Real>(0.05);
        settings.bond.k_n = Real(1e9);
        settings.bond.k_t = Real(5e8);
        settings.bond.damping = Real(0.2);
        settings.bond.tensile_strength = Real(1e5);
        settings.skin = Real(0.002);
        for (int k = 0; k < 27; ++k)
            particles.push_back(ball<Real>((k % 3 - 1) * 2.4 * radius, (k / 3 % 3 - 1) * 2.4 * radius,
                                           (k / 9 - 1) * 2.4 * radius));
        bonds = sphere::random_bond_pairs(particles, settings.box, 0.5, seed, Real(0));
    }
};

using sphere_test::same_bits;

template <class Real>
void require_same_bonds(const sphere::bond_table<Real>& a, const sphere::bond_table<Real>& b)
{
    CHECK((same_bits(a.i, b.i) && same_bits(a.j, b.j) && same_bits(a.rest, b.rest)));
    CHECK((same_bits(a.shear, b.shear) && same_bits(a.bend, b.bend) && same_bits(a.broken, b.broken)));
    CHECK((same_bits(a.released, b.released) && same_bits(a.dissipated, b.dissipated)));
    CHECK((same_bits(a.force, b.force) && same_bits(a.torque_i, b.torque_i) && same_bits(a.torque_j, b.torque_j)));
}

template <class Real>
void require_same_particles(const sphere::particle_snapshot<Real>& a, const sphere::particle_snapshot<Real>& b)
{
    CHECK(same_bits(a.x, b.x));
    CHECK(same_bits(a.v, b.v));
    CHECK(same_bits(a.omega, b.omega));
    CHECK(same_bits(a.force, b.force));
    CHECK(same_bits(a.torque, b.torque));
}
} // namespace

TEMPLATE_TEST_CASE("bonds: results do not depend on the storage order, and a checkpoint restarts bit for bit",
                   "[bonds][io]", float, double, sphere::mixed)
{
    using Real = user_real<TestType>;
    using sim_type = bonded_sim<TestType, sphere::integrate::velocity_verlet>;
    const bonded_sample<TestType> sample;
    REQUIRE(sample.bonds.size() >= 4);
    sphere::settings<Real> kept = sample.settings;
    kept.reorder = false;
    sim_type sorted(sample.settings, sample.particles, sample.bonds), unsorted(kept, sample.particles, sample.bonds);
    sorted.run(300);
    unsorted.run(300);
    require_same_particles(sorted.snapshot(), unsorted.snapshot());
    require_same_bonds(sorted.bonds(), unsorted.bonds());
    CHECK(sorted.energy().bond_elastic > 0);

    sphere_test::temp_folder dir("bonds_checkpoint");
    const std::string path = dir / "bonded.ck";
    sphere::write_checkpoint(path, sorted);
    sim_type restarted = sphere::restart<sim_type>(path);
    require_same_bonds(restarted.bonds(), sorted.bonds());
    sorted.run(200);
    restarted.run(200);
    require_same_particles(restarted.snapshot(), sorted.snapshot());
    require_same_bonds(restarted.bonds(), sorted.bonds());
    CHECK(restarted.broken_bonds() == sorted.broken_bonds());

    // An insertion keeps the bonds and their state.
    const sphere::bond_table<Real> before = sorted.bonds();
    const auto snap = sorted.snapshot();
    sphere::particle<Real> added = ball<Real>(0, 0, 0);
    for (int corner = 0; corner < 8; ++corner) { // a free corner of the box
        added = ball<Real>(corner & 1 ? 0.039 : -0.039, corner & 2 ? 0.039 : -0.039, corner & 4 ? 0.039 : -0.039);
        bool free = true;
        for (std::size_t i = 0; i < snap.size(); ++i)
            free = free && double(norm(snap.position(i) - added.position)) > 2.01 * radius;
        if (free) break;
    }
    sorted.insert({added});
    require_same_bonds(sorted.bonds(), before);
}

TEMPLATE_TEST_CASE("bonds: random pairs, bond orientations and the bonds' VTK file", "[bonds]", double)
{
    using Real = TestType;
    SECTION("create_bond_pair puts j at (r_i + r_j)(1 + spacing) from i")
    {
        std::vector<sphere::particle<Real>> p = {ball<Real>(0), ball<Real>(0.05)};
        p[1].radius = Real(0.02);
        sphere::random_stream rng(3);
        const sphere::bond b = sphere::create_bond_pair(p, 0, 1, rng, Real(-0.1));
        CHECK((b.i == 0 && b.j == 1));
        CHECK(double(norm(p[1].position - p[0].position)) == Approx(0.03 * 0.9).epsilon(1e-12));
    }
    SECTION("random_bond_pairs bonds about the ratio, without overlaps, the same for the same seed")
    {
        const bonded_sample<double> a(11), b(11);
        CHECK(a.bonds.size() >= 4);
        CHECK(a.bonds.size() <= 13); // 27 particles, half of them: at most 13 pairs
        CHECK(a.bonds.size() == b.bonds.size());
        std::vector<int> used(27, 0);
        for (const sphere::bond& k : a.bonds) {
            ++used[k.i];
            ++used[k.j];
            CHECK(double(norm(a.particles[k.i].position - a.particles[k.j].position)) == Approx(2 * radius).epsilon(1e-9));
        }
        for (int u : used) CHECK(u <= 1);
        for (std::size_t i = 0; i < 27; ++i)
            for (std::size_t j = 0; j < i; ++j)
                CHECK(double(norm(a.particles[i].position - a.particles[j].position)) >= 2 * radius * (1 - 1e-9));
        std::vector<sphere::particle<Real>> copy = a.particles;
        CHECK_THROWS_WITH(sphere::random_bond_pairs(copy, a.settings.box, 0.0, 1),
                          Catch::Contains("random_bond_pairs: ratio = 0: must be in (0, 1]"));
    }
    SECTION("trend and plunge")
    {
        const sphere::bond_orientation north = sphere::orientation_of({0, 1, 0}), east = sphere::orientation_of({-1, 0, 0});
        CHECK((north.trend == Approx(0).margin(1e-12) && north.plunge == Approx(0).margin(1e-12)));
        CHECK((east.trend == Approx(90) && east.plunge == Approx(0).margin(1e-12)));
        const sphere::bond_orientation down = sphere::orientation_of({1, 1, -std::sqrt(2.0)});
        CHECK((down.trend == Approx(45) && down.plunge == Approx(45)));
        const sphere::bond_orientation up = sphere::orientation_of({1, 1, std::sqrt(2.0)}); // points down: trend 225
        CHECK((up.trend == Approx(225) && up.plunge == Approx(45)));
        CHECK(sphere::orientation_of({0, 0, 1}).plunge == Approx(90));
        const sphere::bond_rose rose = sphere::rose_of({north, east, down, up}, 4, 3);
        CHECK(rose.trend == std::vector<std::size_t>{2, 1, 1, 0});
        CHECK(rose.plunge == std::vector<std::size_t>{2, 2, 0});
        // A simulation's bonds: the pair along x has trend 90, plunge 0.
        bonded_sim<double> sim(bond_box<double>(0.5), pair<double>(), {{0, 1}});
        const std::vector<sphere::bond_orientation> o = sphere::bond_orientations(sim);
        REQUIRE(o.size() == 1);
        CHECK((o[0].trend == Approx(90) && o[0].plunge == Approx(0).margin(1e-12)));
    }
    SECTION("the VTK file holds the intact bonds as lines")
    {
        std::vector<sphere::particle<Real>> p = {ball<Real>(-2.2 * radius), ball<Real>(0), ball<Real>(2.2 * radius)};
        sphere::settings<Real> s = bond_box<Real>(0.5);
        s.bond.tensile_strength = Real(1e4);
        p[0].velocity = {Real(-1), 0, 0}; // pulls its bond apart
        bonded_sim<Real> sim(s, p, {{0, 1}, {1, 2}});
        sim.run(100);
        REQUIRE(sim.bonds().broken == std::vector<std::uint8_t>{1, 0});
        sphere_test::temp_folder dir("bonds_vtu");
        const std::string path = dir / "bonds.vtu";
        sphere::write_bonds_vtu(path, sim);
        const std::string text = sphere_test::read_bytes(path);
        CHECK_THAT(text, Catch::Contains("NumberOfPoints=\"3\" NumberOfCells=\"1\""));
        CHECK_THAT(text, Catch::Contains("Name=\"connectivity\" format=\"ascii\">\n          1 2\n"));
        CHECK_THAT(text, Catch::Contains("Name=\"bond\" format=\"ascii\">\n          1\n"));
        CHECK_THAT(text, Catch::Contains("Name=\"stretch\""));
        CHECK_THAT(text, Catch::Contains("Name=\"axis\" NumberOfComponents=\"3\" format=\"ascii\">\n          0.022"));
        // The diagnostics row of a bonded simulation ends with the bonds' energies and the
        // number of broken bonds.
        const std::vector<std::string> columns = sphere::diagnostics_columns(sim.walls(), sim.bond_count() > 0);
        const std::vector<double> row = sphere::diagnostics_row(sim);
        REQUIRE(row.size() == columns.size());
        CHECK(columns.back() == "broken_bonds");
        CHECK(row.back() == 1);
        CHECK(row[row.size() - 2] == Approx(double(sim.energy().bond_broken)));
        CHECK(row[row.size() - 3] == Approx(double(sim.energy().bond_elastic)));
    }
}

TEMPLATE_TEST_CASE("bonds: bad bond parameters and bad bonds are refused by name", "[bonds][errors]", float, double)
{
    using Real = TestType;
    const auto refuses = [](const sphere::settings<Real>& s, const std::vector<sphere::particle<Real>>& p,
                            const std::vector<sphere::bond>& b, const std::string& message) {
        INFO(message);
        CHECK_THROWS_WITH(bonded_sim<Real>(s, p, b), Catch::Contains(message));
    };
    const std::vector<sphere::particle<Real>> two = pair<Real>();
    sphere::settings<Real> s = bond_box<Real>(0.5);
    s.bond.k_n = Real(-1);
    refuses(s, two, {}, "settings.bond.k_n = -1 Pa/m: must be non-negative and finite");
    s = bond_box<Real>(0.5);
    s.bond.radius_ratio = 0;
    refuses(s, two, {}, "settings.bond.radius_ratio = 0: must be positive and finite");
    s = bond_box<Real>(0.5);
    s.bond.damping = std::numeric_limits<Real>::quiet_NaN();
    refuses(s, two, {}, "settings.bond.damping = nan: must be non-negative and finite");
    s = bond_box<Real>(0.5);
    s.bond.tensile_strength = 0;
    refuses(s, two, {}, "settings.bond.tensile_strength = 0 Pa: must be positive (infinity: unbreakable)");
    s = bond_box<Real>(0.5);
    s.bond.k_n = 0;
    refuses(s, two, {{0, 1}}, "settings.bond.k_n = 0 Pa/m: bonds need a positive normal stiffness");
    s = bond_box<Real>(0.5);
    refuses(s, two, {{0, 5}}, "bond 0 joins particles 0 and 5, but there are 2 particles");
    refuses(s, two, {{1, 1}}, "bond 0 joins particle 1 to itself");
    refuses(s, two, {{0, 1}, {1, 0}}, "bond 1: particles 1 and 0 are bonded already");
    std::vector<sphere::particle<Real>> apart = {ball<Real>(-0.05), ball<Real>(0.05)};
    refuses(s, apart, {{0, 1}}, "m apart, more than twice the sum of their radii");
    s.dt = Real(7e-5); // below the contact law's bound (9.7e-5 s), above the bond's (5.8e-5 s)
    refuses(s, two, {{0, 1}}, "exceeds the stable bound 0.5 T_bond = ");
    refuses(s, two, {{0, 1}}, "s of bond 0 (particles 0 and 1; T_bond = ");
    // Bonds added later must fit the time step the simulation has.
    s = bond_box<Real>(0.5);
    s.bond.k_n = Real(1e11);
    bonded_sim<Real> later(s, two);
    CHECK_THROWS_WITH(later.add_bonds({{0, 1}}), Catch::Contains("add_bonds: the time step dt() = "));
    CHECK(later.bonds().size() == 0);
    // A state whose bond joins a particle to itself.
    bonded_sim<Real> sim(bond_box<Real>(0.5), two, {{0, 1}});
    sphere::simulation_state<Real> st = sim.state();
    st.bonds.j[0] = 0;
    CHECK_THROWS_WITH(sim.restore(st), Catch::Contains("restore: bond 0 joins particles 0 and 0 (2 particles)"));
}

TEMPLATE_TEST_CASE("bonds: add_bonds joins particles during a run", "[bonds]", float, double, sphere::mixed)
{
    // A pair approaching at 0.1 m/s each is bonded when it touches: the bond then holds it
    // (a strong bond: the pair oscillates about the rest length instead of parting).
    using Real = user_real<TestType>;
    std::vector<sphere::particle<Real>> p = pair<Real>();
    p[0].velocity = {Real(0.1), 0, 0};
    p[1].velocity = {Real(-0.1), 0, 0};
    sphere::settings<Real> s = bond_box<Real>(0.5, 0.5);
    bonded_sim<TestType> probe(s, p, {{0, 1}}); // the time step bonds need
    s.dt = Real(probe.dt());
    bonded_sim<TestType> sim(s, p);
    sim.run(std::size_t(0.1 * radius / 0.2 / double(sim.dt()))); // halfway: 2.1 r apart
    sim.add_bonds({{0, 1}});
    REQUIRE(sim.bonds().size() == 1);
    const double rest = double(sim.bonds().rest[0]);
    sim.run(2000);
    const auto x = sim.snapshot();
    CHECK(double(x.position(1).x - x.position(0).x) == Approx(rest).epsilon(0.01));
}

} // namespace test_bonds
