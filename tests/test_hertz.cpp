// The Hertz-Mindlin contact law (contact/hertz_mindlin.cuh), added through the contact-law
// interface: elastic head-on impacts against Hertz's closed forms (contact duration and
// maximum overlap, between unlike particles and against a wall of another material), the
// restitution of the damping model for unlike pairs and impact speeds, with and without
// tension, the time-step rule (a fraction of the Rayleigh time), the energy audit of a
// frictional pile and checkpoints that name the law. References: docs/physics.md,
// "Hertz-Mindlin". float, double and mixed.
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
namespace test_hertz {

namespace {

using sphere::vec3;
using sphere_test::user_real;
using hertz = sphere::contact::hertz_mindlin<>;
template <class P>
using hertz_sim = sphere::simulation<P, sphere_test::policy, hertz>;

constexpr double pi = 3.14159265358979323846;

// The material: E = 5e7 Pa, nu = 0.3 (a soft solid, so that overlaps are a few per cent of
// a radius and float resolves them), density 2500 kg/m^3.
constexpr double young = 5e7, poisson = 0.3, density = 2500;

template <class Real>
sphere::hertz_params<Real> material(double e, bool tension = false, double mu = 0)
{
    sphere::hertz_params<Real> p;
    p.youngs_modulus = Real(young);
    p.poisson_ratio = Real(poisson);
    p.restitution = Real(e);
    p.mu_s = p.mu_d = Real(mu);
    p.tension = tension;
    return p;
}

/// A closed box [-0.1, 0.1]^3 of the material, no gravity.
template <class P>
typename hertz_sim<P>::settings_type box(double e, bool tension = false)
{
    using Real = user_real<P>;
    typename hertz_sim<P>::settings_type s;
    s.box.lo = {Real(-0.1), Real(-0.1), Real(-0.1)};
    s.box.hi = {Real(0.1), Real(0.1), Real(0.1)};
    s.contact = material<Real>(e, tension);
    s.wall = s.contact;
    return s;
}

double mass_of(double r, double rho) { return 4.0 / 3.0 * pi * r * r * r * rho; }

/// Hertz's elastic head-on impact at relative speed v (K = 4/3 E* sqrt(R*)): the largest
/// overlap delta_max = (5 m* v^2 / (4 K))^(2/5) and the duration t_c = 2 I delta_max / v with
/// I = int_0^1 dx / sqrt(1 - x^(5/2)) = (2/5) B(2/5, 1/2).
struct hertz_impact {
    double delta_max, t_c;
};
hertz_impact hertz_reference(double m_eff, double r_eff, double e_star, double v)
{
    const double k = 4.0 / 3.0 * e_star * std::sqrt(r_eff);
    const double delta_max = std::pow(5 * m_eff * v * v / (4 * k), 0.4);
    const double integral = 0.4 * std::tgamma(0.4) * std::tgamma(0.5) / std::tgamma(0.9);
    return {delta_max, 2 * integral * delta_max / v};
}

/// One collision watched: the overlap crossings interpolated between steps (the contact's
/// duration), the largest overlap, and the normal relative velocity after it.
struct watched {
    double t_c = 0, max_overlap = 0, v_after = 0;
    bool ended = false;
};

/// Steps until two steps after the overlap `gap(snapshot)` (m, negative in contact) ended;
/// `speed(snapshot)` is the separation rate.
template <class Sim, class Gap, class Speed>
watched watch(Sim& sim, Gap gap, Speed speed, std::size_t max_steps)
{
    watched w;
    double g_prev = gap(sim.snapshot()), t_prev = sim.time(), t_in = 0;
    bool began = false;
    int after = 0;
    for (std::size_t k = 0; k < max_steps && after < 2; ++k) {
        sim.step();
        const auto s = sim.snapshot();
        const double g = gap(s), t = sim.time();
        w.max_overlap = std::fmax(w.max_overlap, -g);
        if (!began && g < 0) {
            began = true;
            t_in = t_prev + (t - t_prev) * g_prev / (g_prev - g);
        } else if (began && !w.ended && g >= 0) {
            w.ended = true;
            w.t_c = t_prev + (t - t_prev) * g_prev / (g_prev - g) - t_in;
        }
        if (w.ended) {
            ++after;
            w.v_after = speed(s);
        }
        g_prev = g;
        t_prev = t;
    }
    return w;
}

/// Two particles (radii r0, r1, densities rho0, rho1) meeting head-on along x at relative
/// speed v (zero momentum), at dt = the default / `refine`.
template <class P>
watched pair_impact(const typename hertz_sim<P>::settings_type& given, double r0, double r1, double rho0, double rho1,
                    double v, double refine)
{
    using Real = user_real<P>;
    const double m0 = mass_of(r0, rho0), m1 = mass_of(r1, rho1);
    const double gap = 1e-4; // m
    std::vector<sphere::particle<Real>> ps(2);
    ps[0].position = {Real(-(r0 + gap / 2)), 0, 0};
    ps[1].position = {Real(r1 + gap / 2), 0, 0};
    ps[0].radius = Real(r0);
    ps[1].radius = Real(r1);
    ps[0].density = Real(rho0);
    ps[1].density = Real(rho1);
    ps[0].velocity = {Real(v * m1 / (m0 + m1)), 0, 0};
    ps[1].velocity = {Real(-v * m0 / (m0 + m1)), 0, 0};
    typename hertz_sim<P>::settings_type s = given;
    s.dt = Real(hertz_sim<P>(s, ps).dt() / refine);
    hertz_sim<P> sim(s, ps);
    auto gap_of = [&](const sphere::particle_snapshot<Real>& snap) {
        return double(snap.x[1].x) - double(snap.x[0].x) - r0 - r1;
    };
    auto speed = [&](const sphere::particle_snapshot<Real>& snap) {
        return double(snap.v_sync[1].x) - double(snap.v_sync[0].x);
    };
    return watch(sim, gap_of, speed, 200000);
}

} // namespace

TEMPLATE_TEST_CASE("Hertz: an elastic head-on impact lasts and overlaps as Hertz's closed forms say", "[hertz]", float,
                   double, sphere::mixed)
{
    // Reference: hertz_reference; E* = E / (2 (1 - nu^2)) for two particles of one material.
    // dt = the default (0.2 T_R) / 10; tolerance 1%.
    const double e_star = young / (2 * (1 - poisson * poisson));
    struct pair_case {
        double r0, r1, rho0, rho1, v;
    };
    for (const pair_case& c : {pair_case{0.01, 0.01, density, density, 0.5}, pair_case{0.006, 0.012, 2000, 7800, 1.0},
                               pair_case{0.01, 0.005, 7800, 2500, 0.2}}) {
        const double m0 = mass_of(c.r0, c.rho0), m1 = mass_of(c.r1, c.rho1);
        const hertz_impact ref = hertz_reference(m0 * m1 / (m0 + m1), c.r0 * c.r1 / (c.r0 + c.r1), e_star, c.v);
        const watched w = pair_impact<TestType>(box<TestType>(1.0), c.r0, c.r1, c.rho0, c.rho1, c.v, 10);
        INFO("radii " << c.r0 << ", " << c.r1 << " m, densities " << c.rho0 << ", " << c.rho1 << ", v = " << c.v);
        REQUIRE(w.ended);
        CHECK(std::fabs(w.t_c / ref.t_c - 1) < 0.01);
        CHECK(std::fabs(w.max_overlap / ref.delta_max - 1) < 0.01);
        CHECK(std::fabs(w.v_after / c.v - 1) < 0.01); // elastic: the speed comes back
    }
}

TEMPLATE_TEST_CASE("Hertz: a particle bouncing on a wall of another material", "[hertz]", float, double,
                   sphere::mixed)
{
    // The wall's material mixes with the particle's: 1/E* = (1 - nu_p^2)/E_p + (1 - nu_w^2)/E_w,
    // R* = r, m* = m. Elastic: duration and overlap within 1% of hertz_reference at the
    // default dt / 10; damped: the wall's restitution within 1%.
    using Real = user_real<TestType>;
    const double r = 0.008, v = 0.6, e_w = 2e8, nu_w = 0.25;
    const double e_star = 1 / ((1 - poisson * poisson) / young + (1 - nu_w * nu_w) / e_w);
    for (const double restitution : {1.0, 0.6}) {
        typename hertz_sim<TestType>::settings_type s = box<TestType>(1.0);
        s.wall.youngs_modulus = Real(e_w);
        s.wall.poisson_ratio = Real(nu_w);
        s.wall.restitution = Real(restitution);
        std::vector<sphere::particle<Real>> ps(1);
        ps[0].position = {0, 0, Real(-0.1 + r + 1e-4)};
        ps[0].radius = Real(r);
        ps[0].density = Real(density);
        ps[0].velocity = {0, 0, Real(-v)};
        s.dt = Real(hertz_sim<TestType>(s, ps).dt() / 10);
        hertz_sim<TestType> sim(s, ps);
        const watched w = watch(
            sim, [&](const auto& snap) { return double(snap.x[0].z) + 0.1 - r; },
            [&](const auto& snap) { return double(snap.v_sync[0].z); }, 200000);
        REQUIRE(w.ended);
        INFO("restitution " << restitution);
        CHECK(std::fabs(w.v_after / (restitution * v) - 1) < 0.01);
        if (restitution == 1.0) {
            const hertz_impact ref = hertz_reference(mass_of(r, density), r, e_star, v);
            CHECK(std::fabs(w.t_c / ref.t_c - 1) < 0.01);
            CHECK(std::fabs(w.max_overlap / ref.delta_max - 1) < 0.01);
        }
    }
}

TEMPLATE_TEST_CASE("Hertz: the restitution asked for, whatever the sizes, masses and speed", "[hertz]", float, double,
                   sphere::mixed)
{
    // With tension, LIGGGHTS' damping alpha(e) gives e exactly; without, the library finds the
    // alpha that gives e (hertz_damping_from_restitution). The impact reduces to one scaled
    // equation, so e holds for every pair and speed: within 0.5% at the default dt / 10.
    struct pair_case {
        double r0, r1, rho0, rho1, v;
    };
    for (const bool tension : {false, true})
        for (const double e : {0.3, 0.7, 0.9})
            for (const pair_case& c : {pair_case{0.01, 0.01, density, density, 0.5},
                                       pair_case{0.005, 0.012, 7800, 2000, 0.1},
                                       pair_case{0.012, 0.007, 1200, 2500, 1.5}}) {
                const watched w = pair_impact<TestType>(box<TestType>(e, tension), c.r0, c.r1, c.rho0, c.rho1, c.v, 10);
                INFO("e = " << e << (tension ? ", tension" : ", clipped") << ", radii " << c.r0 << ", " << c.r1
                            << " m, v = " << c.v);
                REQUIRE(w.ended);
                CHECK(std::fabs(w.v_after / (e * c.v) - 1) < 0.005);
            }
}

TEST_CASE("Hertz: the damping for a restitution, against the scaled impact equation", "[hertz]")
{
    // hertz_restitution integrates the scaled impact; at alpha = 0 it is elastic, and it
    // inverts hertz_damping_from_restitution to 1e-6 in both modes. Clipping raises e, so the
    // clipped damping is the larger.
    CHECK(std::fabs(sphere::hertz_restitution(0, false) - 1) < 1e-6);
    for (const double e : {0.05, 0.4, 0.95}) {
        const double with = sphere::hertz_damping_from_restitution(e, true);
        const double clipped = sphere::hertz_damping_from_restitution(e, false);
        CHECK(std::fabs(sphere::hertz_restitution(with, true) - e) < 1e-6);
        CHECK(std::fabs(sphere::hertz_restitution(clipped, false) - e) < 1e-6);
        CHECK(clipped > with);
    }
    CHECK_THROWS_WITH(sphere::hertz_damping_from_restitution(0.0, true),
                      Catch::Contains("restitution coefficient e = 0: must lie in (0, 1]"));
}

TEMPLATE_TEST_CASE("Hertz: the time step is a fraction of the smallest Rayleigh time", "[hertz][time step]", float,
                   double, sphere::mixed)
{
    // T_R = pi r sqrt(rho / G) / (0.1631 nu + 0.8766), G = E / (2 (1 + nu)); dt = 0.2 min T_R,
    // at most 0.5 min T_R (docs/physics.md, "Time step").
    using Real = user_real<TestType>;
    typename hertz_sim<TestType>::settings_type s = box<TestType>(0.5);
    std::vector<sphere::particle<Real>> ps(3);
    const double radii[3] = {0.01, 0.004, 0.006}, densities[3] = {2500, 2500, 900};
    for (int i = 0; i < 3; ++i) {
        ps[i].position = {Real(-0.06 + 0.05 * i), 0, 0};
        ps[i].radius = Real(radii[i]);
        ps[i].density = Real(densities[i]);
    }
    const double g = young / (2 * (1 + poisson));
    auto rayleigh = [&](int i) {
        return pi * double(Real(radii[i])) * std::sqrt(double(Real(densities[i])) / g) / (0.1631 * poisson + 0.8766);
    };
    const double t_min = rayleigh(2); // 0.006 m at 900 kg/m^3: the smallest r sqrt(rho)
    REQUIRE(t_min < rayleigh(1));
    CHECK(std::fabs(double(hertz_sim<TestType>(s, ps).dt()) / (0.2 * t_min) - 1) < 1e-5);
    s.dt = Real(0.49 * t_min);
    CHECK_NOTHROW(hertz_sim<TestType>(s, ps));
    s.dt = Real(0.51 * t_min);
    CHECK_THROWS_WITH(hertz_sim<TestType>(s, ps),
                      Catch::Contains("exceeds the stable bound 0.5 T_R = ") &&
                          Catch::Contains("s of the contact law hertz_mindlin<elastic_viscous_frictional, "
                                          "elastic_viscous_frictional> (smallest at particle 2: r = "));
}

TEMPLATE_TEST_CASE("Hertz: bad parameters are refused by name", "[hertz][errors]", float, double)
{
    using Real = TestType;
    auto fmt = [](Real v) { return sphere::detail::text(v); };
    typename hertz_sim<Real>::settings_type s = box<Real>(0.5);
    const std::vector<sphere::particle<Real>> ps{sphere_test::ball<Real>({0, 0, 0})};
    auto refused = [&](const std::string& text) {
        CHECK_THROWS_WITH(hertz_sim<Real>(s, ps), Catch::Contains(text));
        s = box<Real>(0.5);
    };
    s.contact.youngs_modulus = Real(-1);
    refused("settings.contact.youngs_modulus = -1 Pa: must be positive and finite");
    s.wall.poisson_ratio = Real(0.6);
    refused("settings.wall.poisson_ratio = " + fmt(Real(0.6)) + ": must lie in (-1, 0.5]");
    s.contact.restitution = Real(0);
    refused("settings.contact.restitution = 0: must lie in (0, 1]");
    s.contact.mu_s = Real(0.1);
    s.contact.mu_d = Real(0.2);
    refused("settings.contact.mu_d = " + fmt(Real(0.2)) + " exceeds settings.contact.mu_s");
}

TEMPLATE_TEST_CASE("Hertz: the energy budget of a frictional, damped pile closes", "[hertz][energy]", float, double,
                   sphere::mixed)
{
    // 27 particles dropped as a loose 3 x 3 x 3 lattice onto the floor, e = 0.5, mu = 0.5, with
    // gravity, at dt = the default / 4, sampled every 400 steps. Mindlin's tangential stiffness
    // grows with the overlap without a force doing work; the law books that change with the
    // viscous dissipation, so that energy().total() stays constant: within 2e-3 of the
    // potential energy the pile loses (without the booking the budget is 2.6e-2 off in double).
    using Real = user_real<TestType>;
    typename hertz_sim<TestType>::settings_type s = box<TestType>(0.5);
    s.contact = material<Real>(0.5, false, 0.5);
    s.wall = s.contact;
    s.gravity = {0, 0, Real(-9.81)};
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 27; ++k) {
        sphere::particle<Real> p;
        const double jitter = 1e-3 * ((k * 7919) % 13 - 6) / 6.0;
        p.position = {Real(-0.025 + 0.025 * (k % 3) + jitter), Real(-0.025 + 0.025 * (k / 3 % 3) - jitter),
                      Real(-0.085 + 0.025 * (k / 9))};
        p.radius = Real(0.01 + 0.001 * (k % 3 - 1));
        p.density = Real(density);
        ps.push_back(p);
    }
    s.dt = Real(hertz_sim<TestType>(s, ps).dt() / 4);
    hertz_sim<TestType> sim(s, ps);
    const double total0 = double(sim.energy().total()), potential0 = double(sim.energy().potential);
    double worst = 0;
    for (int k = 0; k < 40; ++k) {
        sim.run(400);
        worst = std::fmax(worst, std::fabs(double(sim.energy().total()) - total0));
    }
    const double lost = potential0 - double(sim.energy().potential);
    REQUIRE(lost > 0);
    REQUIRE(double(sim.energy().dissipated_fric) > 0.05 * lost); // the pile did slide
    CHECK(worst < 2e-3 * lost);
}

TEMPLATE_TEST_CASE("Hertz: a checkpoint names its law and restarts bit for bit", "[hertz][io]", double)
{
    using Real = TestType;
    sphere_test::temp_folder dir("hertz_checkpoint");
    typename hertz_sim<Real>::settings_type s = box<Real>(0.5);
    s.contact = material<Real>(0.5, false, 0.4);
    s.wall = s.contact;
    s.gravity = {0, 0, Real(-9.81)};
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 8; ++k) {
        sphere::particle<Real> p;
        p.position = {Real(-0.012 + 0.024 * (k % 2)), Real(-0.012 + 0.024 * (k / 2 % 2)), Real(-0.09 + 0.021 * (k / 4))};
        p.radius = Real(0.01);
        p.density = Real(density);
        ps.push_back(p);
    }
    hertz_sim<Real> sim(s, ps);
    sim.run(300);
    const std::string path = dir / "hertz.ck";
    sphere::write_checkpoint(path, sim);
    hertz_sim<Real> again = sphere::restart<hertz_sim<Real>>(path);
    sim.run(300);
    again.run(300);
    const auto a = sim.snapshot(), b = again.snapshot();
    for (std::size_t i = 0; i < a.size(); ++i) {
        CHECK(a.x[i].x == b.x[i].x);
        CHECK(a.x[i].z == b.x[i].z);
        CHECK(a.v[i].z == b.v[i].z);
        CHECK(a.omega[i].y == b.omega[i].y);
    }
    // The header names the law (what a program that runs several laws picks the type by).
    const sphere::checkpoint_header header = sphere::read_checkpoint_header(path);
    CHECK(header.version == sphere::checkpoint_format_version);
    CHECK(header.written_precision == sizeof(Real));
    CHECK(header.law == hertz::name());
    CHECK(header.history_layout == std::string(hertz::history_layout));
    // The law's parameters come back by name; a reader with another law refuses the file.
    const auto back = sphere::read_checkpoint<Real, hertz>(path);
    CHECK(back.config.contact.youngs_modulus == s.contact.youngs_modulus);
    CHECK(back.config.wall.mu_d == s.wall.mu_d);
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(path),
                      Catch::Contains("written with the contact law hertz_mindlin<elastic_viscous_frictional, "
                                      "elastic_viscous_frictional> (history: tangential displacement (m) xyz, sliding "
                                      "flag w), but the reader uses linear<elastic_viscous_frictional, "
                                      "visco_frictional>") &&
                          Catch::Contains("restart it with the same law"));
}

} // namespace test_hertz
