// Every error path of the library: each throws sphere::error whose message names the
// offending value and where it came from (include/sphere/core/error.cuh). Numbers in the
// messages are printed with 17 significant digits in Real (a float 0.1 reads
// 0.10000000149011612), so the expected text is formatted the same way (fmt below), and
// values in the set-ups are chosen exactly representable where they are matched literally.
// Valid neighbours of each bad input (e.g. k_t = 0 for a law that ignores it, a particle
// outside the box on a periodic axis) are checked to be accepted, so that each check is
// specific.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_errors {

using Catch::Contains;

/// The expression throws a sphere::error (and nothing else), and its message matches.
#define REQUIRE_SPHERE_ERROR(expr, matcher)        \
    do {                                           \
        REQUIRE_THROWS_AS(expr, sphere::error);    \
        REQUIRE_THROWS_WITH(expr, matcher);        \
    } while (false)

namespace {

using sphere::vec3;

/// A number as the library prints it (std::ostream, precision 17).
template <class T>
std::string fmt(T v)
{
    std::ostringstream o;
    o.precision(17);
    o << v;
    return o.str();
}

template <class Real>
Real nan_value()
{
    return std::numeric_limits<Real>::quiet_NaN();
}
template <class Real>
Real inf_value()
{
    return std::numeric_limits<Real>::infinity();
}

/// Three resting set-P particles in the box [-0.1, 0.1]^3, not touching.
template <class Real>
std::vector<sphere::particle<Real>> three()
{
    return {sphere_test::ball<Real>({Real(-0.05), 0, 0}), sphere_test::ball<Real>({0, Real(0.05), 0}),
            sphere_test::ball<Real>({Real(0.05), 0, 0})};
}

template <class Real, class Law = sphere::contact::linear<>>
void build(const sphere::settings<Real>& s, const std::vector<sphere::particle<Real>>& ps)
{
    sphere::simulation<Real, sphere::host, Law> sim(s, ps);
}

} // namespace

TEMPLATE_TEST_CASE("particle radius and density must be positive and finite", "[errors][particles]", float, double)
{
    using Real = TestType;
    const auto s = sphere_test::box_settings<Real>();
    auto ps = three<Real>();
    REQUIRE_NOTHROW(build(s, ps));

    SECTION("radius")
    {
        ps[1].radius = Real(-0.5);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 1: radius = -0.5 m must be positive and finite"));
        ps[1].radius = 0;
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 1: radius = 0 m must be positive and finite"));
        ps[1].radius = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 1: radius = ") && Contains("nan m must be positive"));
        ps[1].radius = inf_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 1: radius = inf m must be positive and finite"));
        ps[2].radius = Real(-2); // the first bad particle is named
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 1: radius = inf m"));
    }
    SECTION("density")
    {
        ps[2].density = Real(-2500);
        REQUIRE_SPHERE_ERROR(build(s, ps),
                             Contains("particle 2: density = -2500 kg/m^3 must be positive and finite"));
        ps[2].density = 0;
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 2: density = 0 kg/m^3 must be positive and finite"));
        ps[2].density = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 2: density = ") && Contains("nan kg/m^3"));
        ps[2].density = inf_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 2: density = inf kg/m^3 must be positive"));
    }
}

TEMPLATE_TEST_CASE("particle positions and velocities must be finite", "[errors][particles]", float, double)
{
    using Real = TestType;
    const auto s = sphere_test::box_settings<Real>();
    auto ps = three<Real>();
    SECTION("position")
    {
        ps[1].position.z = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps),
                             Contains("particle 1: position (0, 0.") && Contains("nan) m is not finite"));
        ps[1].position.z = inf_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 1: position (0, ") && Contains(", inf) m is not finite"));
    }
    SECTION("velocity")
    {
        ps[0].velocity = {Real(0.5), nan_value<Real>(), 0};
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 0: velocity (0.5, ") && Contains("nan, 0) m/s") &&
                                               Contains("is not finite"));
        ps[0].velocity = {0, 0, -inf_value<Real>()};
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 0: velocity (0, 0, -inf) m/s"));
    }
    SECTION("angular velocity")
    {
        ps[2].angular_velocity = {0, inf_value<Real>(), 0};
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 2: velocity (0, 0, 0) m/s or angular velocity (0, inf, 0) "
                                                    "rad/s is not finite"));
    }
}

TEMPLATE_TEST_CASE("a particle outside the world on a wall axis is rejected at setup", "[errors][particles][world]",
                   float, double)
{
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>();
    auto ps = three<Real>();
    const std::string world_y = "lies outside the world [" + fmt(s.box.lo.y) + ", " + fmt(s.box.hi.y) + "] m on a wall axis";

    ps[2].position.y = Real(0.25);
    REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 2: position[1] = 0.25 m " + world_y));
    ps[2].position.y = Real(-0.125);
    REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 2: position[1] = -0.125 m " + world_y));

    // A centre exactly on a face is inside the world (overlapping the wall by its radius, which
    // settings.max_initial_overlap must then allow); on a periodic axis a centre outside the
    // box is accepted and wrapped into it.
    ps[2].position.y = s.box.hi.y;
    REQUIRE_SPHERE_ERROR(build(s, ps), Contains("particle 2 (radius " + fmt(ps[2].radius) + " m) starts overlapping wall face 3 by 1 "));
    s.max_initial_overlap = 1;
    REQUIRE_NOTHROW(build(s, ps));
    ps[2].position.y = Real(0.125);
    s.box.axis[1] = sphere::boundary::periodic;
    sphere::simulation<Real> sim(s, ps);
    CHECK(sim.snapshot().x[2].y == Approx(0.125 - 0.2).margin(1e-6));
}

TEMPLATE_TEST_CASE("the world box must be finite with hi > lo", "[errors][world]", float, double)
{
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>();
    const auto ps = three<Real>();
    SECTION("hi == lo")
    {
        s.box.lo.y = Real(0.5);
        s.box.hi.y = Real(0.5);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.box: axis 1 spans [0.5, 0.5] m; it must be finite with hi > lo"));
    }
    SECTION("hi < lo")
    {
        s.box.lo.z = Real(0.25);
        s.box.hi.z = Real(-0.25);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.box: axis 2 spans [0.25, -0.25] m"));
    }
    SECTION("not finite")
    {
        s.box.lo.x = -inf_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.box: axis 0 spans [-inf, ") && Contains("must be finite"));
        s.box.lo.x = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.box: axis 0 spans [") && Contains("nan, "));
    }
}

TEMPLATE_TEST_CASE("contact parameters are validated, naming settings.contact or settings.wall",
                   "[errors][contact]", float, double)
{
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>();
    const auto ps = three<Real>();
    s.contact.mu_s = Real(0.5);
    s.contact.mu_d = Real(0.25);
    s.wall = s.contact;
    REQUIRE_NOTHROW(build(s, ps));

    SECTION("k_n must be positive and finite")
    {
        s.contact.k_n = 0;
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.k_n = 0 N/m: must be positive and finite"));
        s.contact.k_n = Real(-1e5);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.k_n = -100000 N/m: must be positive and finite"));
        s.contact.k_n = inf_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.k_n = inf N/m: must be positive and finite"));
        s.contact.k_n = Real(1e5);
        s.wall.k_n = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.wall.k_n = ") && Contains("nan N/m: must be positive and finite"));
        s.wall.k_n = 0;
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.wall.k_n = 0 N/m: must be positive and finite"));
    }
    SECTION("k_t must be positive for the elastic tangential law, non-negative for the others")
    {
        s.contact.k_t = 0;
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.k_t = 0 N/m: the elastic tangential law needs a "
                                                    "positive, finite k_t"));
        s.contact.k_t = Real(-2);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.k_t = -2 N/m: must be non-negative and finite"));
        s.contact.k_t = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.k_t = ") && Contains("nan N/m"));
        // The visco-frictional law keeps no spring: k_t = 0 is fine for it (the default wall law).
        s.contact.k_t = 0;
        REQUIRE_NOTHROW(build<Real, sphere::contact::linear<sphere::tangential::visco_frictional>>(s, ps));
        s.contact.k_t = Real(1e4);
        s.wall.k_t = 0;
        REQUIRE_NOTHROW(build(s, ps));
        using elastic = sphere::tangential::elastic_viscous_frictional;
        REQUIRE_SPHERE_ERROR((build<Real, sphere::contact::linear<elastic, elastic>>(s, ps)),
                             Contains("settings.wall.k_t = 0 N/m: the elastic tangential law needs a positive, finite k_t"));
        s.wall.k_t = Real(-1);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.wall.k_t = -1 N/m: must be non-negative and finite"));
    }
    SECTION("gamma_n and gamma_t must be non-negative and finite")
    {
        s.contact.gamma_n = Real(-1);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.gamma_n = -1 N s/m: must be non-negative and finite"));
        s.contact.gamma_n = 0;
        s.contact.gamma_t = Real(-0.5);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.gamma_t = -0.5 N s/m: must be non-negative and finite"));
        s.contact.gamma_t = 0;
        s.wall.gamma_n = inf_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.wall.gamma_n = inf N s/m: must be non-negative and finite"));
        s.wall.gamma_n = 0;
        s.wall.gamma_t = Real(-3);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.wall.gamma_t = -3 N s/m: must be non-negative and finite"));
    }
    SECTION("friction must be non-negative and finite")
    {
        s.contact.mu_s = Real(-0.5);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.mu_s = -0.5 (friction): must be non-negative and finite"));
        s.contact.mu_s = Real(0.5);
        s.contact.mu_d = Real(-0.25);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.mu_d = -0.25 (friction): must be non-negative and finite"));
        s.contact.mu_d = Real(0.25);
        s.wall.mu_s = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.wall.mu_s = ") && Contains("(friction): must be non-negative"));
        s.wall.mu_s = Real(0.5);
        s.wall.mu_d = Real(-1);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.wall.mu_d = -1 (friction): must be non-negative and finite"));
    }
    SECTION("mu_d must not exceed mu_s")
    {
        s.contact.mu_s = Real(0.25);
        s.contact.mu_d = Real(0.5);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.contact.mu_d = 0.5 exceeds settings.contact.mu_s = 0.25: "
                                                    "dynamic friction must not exceed static friction"));
        s.contact.mu_d = Real(0.25); // equal is fine
        REQUIRE_NOTHROW(build(s, ps));
        s.wall.mu_s = 0;
        s.wall.mu_d = Real(0.125);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.wall.mu_d = 0.125 exceeds settings.wall.mu_s = 0"));
    }
}

TEMPLATE_TEST_CASE("simulation settings are validated", "[errors][settings]", float, double)
{
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>();
    auto ps = three<Real>();
    SECTION("negative or non-finite skin")
    {
        s.skin = Real(-0.5);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.skin = -0.5 m: must be non-negative and finite"));
        s.skin = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.skin = ") && Contains("nan m: must be non-negative"));
    }
    SECTION("empty particle list")
    {
        REQUIRE_SPHERE_ERROR(build(s, std::vector<sphere::particle<Real>>{}),
                             Contains("no particles: a simulation needs at least one"));
    }
    SECTION("non-finite gravity")
    {
        s.gravity = {0, 0, nan_value<Real>()};
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.gravity (0, 0, ") && Contains("nan) m/s^2 is not finite"));
        s.gravity = {inf_value<Real>(), 0, 0};
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.gravity (inf, 0, 0) m/s^2 is not finite"));
    }
    SECTION("negative or non-finite cell size")
    {
        s.cell_size = Real(-1);
        REQUIRE_SPHERE_ERROR(build(s, ps),
                             Contains("settings.cell_size = -1 m: must be non-negative and finite (0 = automatic)"));
        s.cell_size = inf_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.cell_size = inf m: must be non-negative and finite"));
    }
    SECTION("observer interval 0")
    {
        sphere::simulation<Real> sim(s, ps);
        REQUIRE_SPHERE_ERROR(sim.add_observer(0, [](const sphere::simulation<Real>&) {}),
                             Contains("observer interval 0: must be at least 1 step"));
    }
    SECTION("set_velocity index out of range")
    {
        sphere::simulation<Real> sim(s, ps);
        REQUIRE_SPHERE_ERROR(sim.set_velocity(3, {0, 0, 0}, {0, 0, 0}),
                             Contains("set_velocity: particle index 3 out of range (3 particles)"));
    }
}

TEMPLATE_TEST_CASE("grid cells must hold the largest particle diameter plus skin", "[errors][grid]", float, double)
{
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>();
    auto ps = three<Real>();
    ps[1].radius = Real(0.0125); // the largest particle: diameter 0.025 m
    const Real r_max = ps[1].radius;

    SECTION("skin 0")
    {
        s.cell_size = Real(0.02);
        const Real reach = 2 * r_max + s.skin;
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.cell_size = " + fmt(s.cell_size) +
                                                    " m is smaller than the largest particle diameter plus skin and the contact law's range, " +
                                                    fmt(reach) + " m: contacts would be missed"));
        s.cell_size = reach; // exactly the reach is enough
        REQUIRE_NOTHROW(build(s, ps));
    }
    SECTION("with a skin")
    {
        s.skin = Real(0.005);
        s.cell_size = Real(0.0275); // > diameter 0.025, < diameter + skin 0.03
        const Real reach = 2 * r_max + s.skin;
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.cell_size = " + fmt(s.cell_size) +
                                                    " m is smaller than the largest particle diameter plus skin and the contact law's range, " +
                                                    fmt(reach) + " m"));
        s.cell_size = Real(0.04);
        REQUIRE_NOTHROW(build(s, ps));
    }
    SECTION("too many cells")
    {
        // 100 m box, 2 mm particles: 5e4 cells per axis, 1.25e14 in all (limit 2^28).
        s.box.lo = {Real(-50), Real(-50), Real(-50)};
        s.box.hi = {Real(50), Real(50), Real(50)};
        for (auto& p : ps) p.radius = Real(0.001);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("the neighbour grid would need ") &&
                                               Contains("set settings.cell_size larger or shrink the world"));
        s.cell_size = Real(1); // 1e6 cells
        REQUIRE_NOTHROW(build(s, ps));
    }
}

TEMPLATE_TEST_CASE("a periodic axis must hold at least 3 grid cells", "[errors][grid][world]", float, double)
{
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>();
    s.box.lo.x = Real(-0.25);
    s.box.hi.x = Real(0.25);
    s.box.axis[0] = sphere::boundary::periodic;
    std::vector<sphere::particle<Real>> ps = {sphere_test::ball<Real>({0, 0, 0}, {0, 0, 0}, Real(0.125))};
    // Reach 2 r = 0.25 m: the 0.5 m axis holds 2 cells.
    REQUIRE_SPHERE_ERROR(build(s, ps), Contains("periodic axis 0 of length 0.5 m holds 2 grid cells of at least 0.25 m: "
                                                "a periodic axis needs at least 3"));
    // A requested cell of 0.3 m leaves 1 cell.
    s.cell_size = Real(0.3);
    REQUIRE_SPHERE_ERROR(build(s, ps), Contains("periodic axis 0 of length 0.5 m holds 1 grid cells of at least " +
                                                fmt(s.cell_size) + " m"));
    // Walls on that axis need no minimum; a 0.8 m periodic axis holds 3 cells.
    s.cell_size = 0;
    s.box.axis[0] = sphere::boundary::wall;
    REQUIRE_NOTHROW(build(s, ps));
    s.box.axis[0] = sphere::boundary::periodic;
    s.box.lo.x = Real(-0.375);
    s.box.hi.x = Real(0.375);
    REQUIRE_NOTHROW(build(s, ps));
}

TEMPLATE_TEST_CASE("the time step must be positive, finite and within the stable bound", "[errors][time step]",
                   float, double)
{
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>();
    auto ps = three<Real>();
    ps[2].radius = Real(0.005); // the lightest particle sets m_min
    const double m_min = 4.0 / 3.0 * 3.14159265358979323846 * 0.005 * 0.005 * 0.005 * 2500; // 1.309e-3 kg

    SECTION("non-positive or non-finite")
    {
        s.dt = Real(-1);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.dt = -1 s: must be positive and finite (0 = automatic)"));
        s.dt = nan_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.dt = ") && Contains("nan s: must be positive and finite"));
        s.dt = inf_value<Real>();
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("settings.dt = inf s: must be positive and finite"));
    }
    SECTION("above 0.3 sqrt(m_min / k_max), with k_max over k_n, k_t and the walls")
    {
        // Reference bound (docs/physics.md, "Time step"): 0.3 sqrt(m_min / k_max).
        auto check_bound = [&](double k_max) {
            const double bound = 0.3 * std::sqrt(m_min / k_max);
            s.dt = Real(0.99 * bound);
            REQUIRE_NOTHROW(build(s, ps));
            s.dt = Real(1.01 * bound);
            REQUIRE_SPHERE_ERROR(build(s, ps),
                                 Contains("settings.dt = " + fmt(s.dt) +
                                          " s exceeds the stable bound 0.3 min(sqrt(m / k_max), t_d / 0.3) = ") &&
                                     Contains(" s of the contact law linear<elastic_viscous_frictional, "
                                              "visco_frictional> (smallest at particle 2: m = " +
                                              fmt(sphere::sphere_mass(ps[2].radius, ps[2].density)) +
                                              " kg, k_max = " + fmt(Real(k_max)) + " N/m, t_d = inf s)"));
        };
        check_bound(1e5); // k_n
        s.contact.k_t = Real(2e5);
        check_bound(2e5); // k_t of the pairs
        s.wall.k_n = Real(4e5);
        check_bound(4e5); // k_n of the walls
        s.wall.k_t = Real(8e5);
        check_bound(8e5); // k_t of the walls
    }
    SECTION("above the dashpots' stable step, for every damping convention")
    {
        // An explicit dashpot c on a contact of inverse effective mass w is stable for
        // dt < t_d = 2 / (c w) (docs/physics.md, "Time step"): the lightest particle's contact
        // with one like it, w = 2 / m_min along the normal. gamma_n = 1e6 N s/m (t_d = 1.3e-9 s)
        // is refused at any dt above t_d; the default, 0.075 T with T = t_d / 0.3, is t_d / 4.
        s.contact.gamma_n = Real(1e6);
        const double t_d = 2 / (1e6 * 2 / m_min);
        s.dt = Real(1.01 * t_d);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("exceeds the stable bound 0.3 min(sqrt(m / k_max), t_d / 0.3)") &&
                                               Contains("t_d = " + fmt(Real(t_d)) + " s"));
        s.dt = Real(0.99 * t_d);
        REQUIRE_NOTHROW(build(s, ps));
        s.dt = 0;
        CHECK(double(sphere::simulation<Real>(s, ps).dt()) == Approx(0.25 * t_d).epsilon(1e-5));
        // mass-scaled: c = gamma m_eff, so t_d = 2 / gamma along the normal of a pair; along the
        // tangent w = 7 / m with c = gamma_t m / 2: t_d = 4 / (7 gamma_t)
        s.contact.gamma_n = 0;
        s.contact.damping = sphere::damping_convention::mass_scaled;
        s.contact.gamma_t = Real(1e6);
        s.dt = Real(1.01 * 4 / 7e6);
        REQUIRE_SPHERE_ERROR(build(s, ps), Contains("t_d = " + fmt(Real(4 / 7e6)) + " s"));
        s.dt = Real(0.99 * 4 / 7e6);
        REQUIRE_NOTHROW(build(s, ps));
    }
}

TEMPLATE_TEST_CASE("contact lists hold every partner they find, at setup and during the run", "[contacts]", float,
                   double)
{
    using Real = TestType;
    auto s = sphere_test::box_settings<Real>();
    const Real r = sphere_test::set_p<Real>::radius;
    // Particle 2 (fixed, at the origin) touches particles 0 (-x) and 1 (-y). Particle 3
    // approaches from +x at 0.5 m/s (prescribed: moves exactly x += v dt) and becomes its third
    // partner; no capacity limits the list.
    auto centre = sphere_test::ball<Real>({0, 0, 0});
    centre.kind = sphere::motion::fixed;
    std::vector<sphere::particle<Real>> ps = {sphere_test::ball<Real>({Real(-0.0199), 0, 0}),
                                              sphere_test::ball<Real>({0, Real(-0.0199), 0}), centre,
                                              sphere_test::ball<Real>({Real(0.0301), 0, 0})};
    for (auto& p : ps)
        if (p.kind == sphere::motion::free) p.kind = sphere::motion::prescribed;
    ps[3].velocity = {Real(-0.5), 0, 0};
    const std::vector<unsigned> two = {0, 1}, three = {0, 1, 3};

    SECTION("at setup")
    {
        REQUIRE(sphere::simulation<Real>(s, ps).contacts().partners_of(2) == two);
        ps[3].position.x = Real(0.0199); // already touching: 3 partners
        REQUIRE(sphere::simulation<Real>(s, ps).contacts().partners_of(2) == three);
    }
    SECTION("during the run")
    {
        // Particle 3 enters reach when its centre is closer than 2 r = 0.02 m, i.e. after
        // n > (0.0301 - 0.02) / (0.5 dt) steps; the lists are rebuilt at the start of the next step.
        sphere::simulation<Real> sim(s, ps);
        const double steps_to_reach = (0.0301 - 2 * double(r)) / (0.5 * double(sim.dt()));
        REQUIRE(steps_to_reach - std::floor(steps_to_reach) > 0.2); // well away from a step boundary
        const std::size_t n = static_cast<std::size_t>(std::floor(steps_to_reach)) + 1;
        sim.run(n);
        REQUIRE(sim.contacts().partners_of(2) == two);
        sim.run(1);
        REQUIRE(sim.contacts().partners_of(2) == three);
        REQUIRE(sim.contacts().partners_of(3) == std::vector<unsigned>{2});
    }
}

/// A particle leaving the world during a run with `Integrator` (velocity Verlet checks the
/// particles in its drift, at the start of a step; semi-implicit Euler at the end).
template <class Real, class Integrator>
void check_leaving_world()
{
    using sim_type = sphere::simulation<Real, sphere::host, sphere::contact::linear<>, Integrator>;
    auto s = sphere_test::box_settings<Real>();
    auto ps = three<Real>();
    // Particle 1 at (0, 0.05, 0) flies towards the +y wall (at 0.1 m) at 1000 m/s: 0.024 m
    // per step, so it passes through in a few steps (the wall's spring, k_n delta ~ 1e3 N on
    // 0.01 kg, changes its velocity by ~2 m/s per step: negligible).
    ps[1].velocity = {0, Real(1000), 0};
    const double dt = double(sim_type(s, ps).dt());
    const double steps_out = (0.1 - 0.05) / (1000 * dt); // 2.06
    REQUIRE(steps_out - std::floor(steps_out) > 0.03);
    const std::size_t n = static_cast<std::size_t>(std::floor(steps_out)) + 1; // 3
    auto run = [&] {
        sim_type sim(s, ps);
        sim.run(10);
    };
    REQUIRE_SPHERE_ERROR(run(), Contains("step " + std::to_string(n) + ": particle 1 left the world: position (0, ") &&
                                    Contains("world [" + fmt(s.box.lo.x) + ", " + fmt(s.box.hi.x) + "] x [" +
                                             fmt(s.box.lo.y) + ", " + fmt(s.box.hi.y) + "] x [" + fmt(s.box.lo.z) +
                                             ", " + fmt(s.box.hi.z) + "] m"));
    // On a periodic axis the same particle re-enters at the other side.
    s.box.axis[1] = sphere::boundary::periodic;
    sim_type sim(s, ps);
    REQUIRE_NOTHROW(sim.run(10));
}

TEMPLATE_TEST_CASE("a particle leaving the world during the run names the step and the particle",
                   "[errors][run][world]", float, double)
{
    SECTION("semi-implicit Euler") { check_leaving_world<TestType, sphere::integrate::semi_implicit_euler>(); }
    SECTION("velocity Verlet") { check_leaving_world<TestType, sphere::integrate::velocity_verlet>(); }
}

/// A non-finite state during a run with `Integrator`.
template <class Real, class Integrator>
void check_non_finite_state()
{
    // A velocity that overflows: a huge (finite) gravity and a time step that the stable
    // bound allows because the springs are extremely soft (bound 0.3 sqrt(m / k) = 3e4 s).
    // All axes are periodic, so the particle cannot leave the world first.
    auto s = sphere_test::box_settings<Real>();
    for (auto& axis : s.box.axis) axis = sphere::boundary::periodic;
    s.contact.k_n = s.contact.k_t = Real(1e-12);
    s.wall = s.contact;
    s.dt = Real(1e4);
    s.gravity = {0, 0, -std::numeric_limits<Real>::max() / 2};
    auto run = [&] {
        sphere::simulation<Real, sphere::host, sphere::contact::linear<>, Integrator> sim(s, three<Real>());
        sim.run(3);
    };
    REQUIRE_SPHERE_ERROR(run(), Contains("step 1: particle 0 became non-finite (position (") &&
                                    Contains("inf") && Contains("reduce the time step"));
}

TEMPLATE_TEST_CASE("a non-finite state during the run names the step and the particle", "[errors][run]", float,
                   double)
{
    SECTION("semi-implicit Euler") { check_non_finite_state<TestType, sphere::integrate::semi_implicit_euler>(); }
    SECTION("velocity Verlet") { check_non_finite_state<TestType, sphere::integrate::velocity_verlet>(); }
}

TEMPLATE_TEST_CASE("set_velocity refuses non-finite values and fixed particles", "[errors][run]", float, double)
{
    using Real = TestType;
    const auto s = sphere_test::box_settings<Real>();
    auto ps = three<Real>();
    ps[1].kind = sphere::motion::fixed;
    sphere::simulation<Real> sim(s, ps);
    REQUIRE_SPHERE_ERROR(sim.set_velocity(2, {nan_value<Real>(), 0, 0}, {0, 0, 0}),
                         Contains("set_velocity: particle 2: velocity (nan, 0, 0) m/s or angular velocity (0, 0, 0) "
                                  "rad/s is not finite"));
    REQUIRE_SPHERE_ERROR(sim.set_velocity(0, {0, 0, 0}, {0, inf_value<Real>(), 0}),
                         Contains("set_velocity: particle 0: velocity (0, 0, 0) m/s or angular velocity (0, inf, 0)"));
    REQUIRE_SPHERE_ERROR(sim.set_velocity(1, {1, 0, 0}, {0, 0, 0}),
                         Contains("set_velocity: particle 1 is fixed and cannot move"));
    // A valid call on a free particle is accepted and takes effect.
    REQUIRE_NOTHROW(sim.set_velocity(2, {Real(0.5), 0, 0}, {0, 0, 0}));
    CHECK(sim.snapshot().v[2].x == Real(0.5));
}

TEMPLATE_TEST_CASE("restitution helpers reject values outside their domain", "[errors][restitution]", float, double)
{
    using Real = TestType;
    const Real m = sphere_test::set_p<Real>::mass(), k = sphere_test::set_p<Real>::k_n;
    SECTION("e outside (0, 1]")
    {
        for (const bool tension : {false, true}) {
            INFO("tension " << tension);
            REQUIRE_SPHERE_ERROR(sphere::damping_ratio_from_restitution(Real(0), tension),
                                 Contains("restitution coefficient e = 0: must lie in (0, 1]"));
            REQUIRE_SPHERE_ERROR(sphere::damping_ratio_from_restitution(Real(-0.5), tension),
                                 Contains("restitution coefficient e = -0.5: must lie in (0, 1]"));
            REQUIRE_SPHERE_ERROR(sphere::gamma_n_from_restitution(Real(1.5), m, k, tension),
                                 Contains("restitution coefficient e = 1.5: must lie in (0, 1]"));
            REQUIRE_SPHERE_ERROR(sphere::gamma_n_from_restitution(nan_value<Real>(), m, k, tension),
                                 Contains("restitution coefficient e = ") && Contains("nan: must lie in (0, 1]"));
            // e = 1 is elastic: no damping (to the bisection's resolution, 1e-6 of critical).
            CHECK(sphere::gamma_n_from_restitution(Real(1), m, k, tension) <= 1e-6 * 2 * std::sqrt(m * k));
        }
    }
    SECTION("without tension e must exceed exp(-2)")
    {
        REQUIRE_SPHERE_ERROR(sphere::gamma_n_from_restitution(Real(0.125), m, k),
                             Contains("restitution coefficient e = 0.125: without tension e must exceed exp(-2) = 0.1353"));
        REQUIRE_NOTHROW(sphere::gamma_n_from_restitution(Real(0.125), m, k, true));
    }
    SECTION("damping ratio outside [0, 1)")
    {
        REQUIRE_SPHERE_ERROR(sphere::restitution_from_damping_ratio(Real(1), false),
                             Contains("damping ratio zeta = 1: the restitution relations hold for 0 <= zeta < 1"));
        REQUIRE_SPHERE_ERROR(sphere::restitution_from_damping_ratio(Real(-0.25), true),
                             Contains("damping ratio zeta = -0.25"));
        REQUIRE_SPHERE_ERROR(sphere::contact_duration(Real(1.5), m, k),
                             Contains("damping ratio zeta = 1.5: the restitution relations hold for 0 <= zeta < 1"));
    }
}

TEMPLATE_TEST_CASE("coincident centres and deep initial overlaps are refused, naming both particles", "[errors]", float,
                   double, sphere::mixed)
{
    // Four balls of set P in a row along x; particle 3 is moved onto particle 1. A contact of
    // coincident centres has no normal: always refused. An overlap beyond
    // settings.max_initial_overlap (0.5 of the smaller radius by default) is refused unless
    // raised, and initial_overlap() reports the deepest; walls likewise.
    using Real = sphere_test::user_real<TestType>;
    using Sim = sphere::simulation<TestType, sphere_test::policy>;
    auto s = sphere_test::box_settings<Real>();
    const double r = 0.01;
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 4; ++k) ps.push_back(sphere_test::ball<Real>({Real(-0.06 + 0.03 * k), 0, 0}));
    ps[3].position = ps[1].position;
    REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("particles 1 and 3 have the same centre: their contact has no normal"));
    ps[3].position.y = Real(2 * r - 0.6 * r); // overlap 0.6 r with particle 1 (along y), apart from the others
    REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("particles 1 and 3 (radii " + fmt(ps[1].radius) + " and " +
                                              fmt(ps[3].radius) + " m) start overlapping by 0.") &&
                                         Contains("of the smaller radius, more than settings.max_initial_overlap = 0.5 "
                                                  "(raise it to accept)"));
    s.max_initial_overlap = 1;
    CHECK(Sim(s, ps).initial_overlap() == Approx(0.6).epsilon(1e-4));
    ps[3].position.y = Real(2 * r - 0.4 * r); // within the default
    s.max_initial_overlap = Real(0.5);
    CHECK(Sim(s, ps).initial_overlap() == Approx(0.4).epsilon(1e-4));
    ps[0].position.x = Real(-0.1 + 0.3 * r); // 0.7 r into the wall at x = -0.1 (face 0)
    const double into_wall = (double(ps[0].radius) - (double(ps[0].position.x) - double(s.box.lo.x))) / double(ps[0].radius);
    REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("particle 0 (radius " + fmt(ps[0].radius) + " m) starts overlapping wall face 0 by " +
                                              fmt(into_wall) + " of its radius, more than settings.max_initial_overlap = 0.5"));
    s.max_initial_overlap = Real(-1);
    REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("settings.max_initial_overlap = -1: must be non-negative"));
}

TEMPLATE_TEST_CASE("allocations that cannot succeed are sphere::errors that say how much was asked", "[errors]", float,
                   double)
{
    // 2^40 doubles (8 TiB) cannot be had on any build machine: std::bad_alloc becomes a
    // sphere::error; 2^62 values are more than a std::vector holds (std::length_error); the
    // contact lists refuse more entries than their 32-bit offsets (and checkpoints) hold before
    // allocating anything.
    sphere::buffer<TestType, sphere::host> b;
    REQUIRE_SPHERE_ERROR(b.resize(std::size_t(1) << 40),
                         Contains("host memory: allocating 1099511627776 values of " + std::to_string(sizeof(TestType)) +
                                  " B (") &&
                             Contains(" GiB) failed"));
    REQUIRE_SPHERE_ERROR(b.resize(std::size_t(1) << 62), Contains("values of " + std::to_string(sizeof(TestType)) +
                                                                  " B are more than one array can hold"));
    auto s = sphere_test::box_settings<TestType>();
    sphere::simulation<TestType> sim(s, three<TestType>());
    REQUIRE_SPHERE_ERROR(sim.reserve_contacts(std::size_t(1) << 33),
                         Contains("reserve_contacts(8589934592): the contact lists hold at most 4294967295 entries"));
}

TEMPLATE_TEST_CASE("radii and densities whose mass or time step make no sense are refused with the reason",
                   "[errors][time step]", float, double, sphere::mixed)
{
    // A radius of 1e-30 m: in float its mass underflows; in double it is a number, but the
    // time step 0.075 sqrt(m / k) = 2.4e-47 s would never end a run. A density of 1e300 kg/m^3
    // overflows the mass in mixed, whose kernels compute in float (in float it is infinite).
    using Real = sphere_test::user_real<TestType>;
    using Sim = sphere::simulation<TestType, sphere_test::policy>;
    constexpr bool single = sphere_test::single_fields<TestType>;
    auto s = sphere_test::box_settings<Real>();
    std::vector<sphere::particle<Real>> ps{sphere_test::ball<Real>({0, 0, 0})};
    ps[0].radius = Real(1e-30);
    if (std::is_same_v<TestType, float>) {
        REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("particle 0: radius ") &&
                                             Contains("float cannot hold as normal numbers"));
    } else if (single) { // mixed: the mass does not fit the kernels' float
        REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("particle 0: mass (radius 1") && Contains("does not fit in float"));
    } else {
        REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("s is below 1e-15 s: a second of simulated time would take more "
                                                  "than 1e15 steps; check the smallest radius and density"));
    }
    ps[0].radius = Real(0.01);
    ps[0].density = Real(1e300);
    if (std::is_same_v<TestType, float>) { // 1e300 is already infinite in float
        REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("particle 0: density = inf kg/m^3 must be positive and finite"));
    } else if (single) { // mixed: the mass does not fit the kernels' float
        REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("particle 0: mass (radius 0.01") && Contains("does not fit in float"));
    } else {
        CHECK_NOTHROW(Sim(s, ps));
    }
    // a user time step below the floor
    ps[0].density = Real(2500);
    s.dt = Real(1e-16);
    REQUIRE_SPHERE_ERROR(Sim(s, ps), Contains("s is below 1e-15 s") && Contains("and settings.dt"));
}

TEMPLATE_TEST_CASE("the last gaps: a wall mode out of range, a state with short arrays, an unbounded insertion region",
                   "[errors]", float, double)
{
    // Found by writing docs/errors.md: each is refused naming the value.
    using Real = TestType;
    using Sim = sphere::simulation<Real, sphere_test::policy>;
    auto s = sphere_test::box_settings<Real>();
    s.walls[5].mode = static_cast<sphere::wall_mode>(7);
    REQUIRE_SPHERE_ERROR(Sim(s, three<Real>()), Contains("settings.walls[5].mode = 7: not a wall_mode (0 fixed, 1 velocity, 2 stress)"));

    Sim sim(sphere_test::box_settings<Real>(), three<Real>());
    sphere::simulation_state<Real> st = sim.state();
    st.particles.omega_sync.pop_back();
    REQUIRE_SPHERE_ERROR(sim.restore(st), Contains("restore: the state's particles.omega_sync holds 2 values for 3 particles"));

    sphere::insertion_settings<Real> in;
    in.lo = {Real(-0.05), Real(-0.05), Real(0)};
    in.hi = {Real(0.05), Real(0.05), inf_value<Real>()};
    in.rate = 100;
    in.radius_min = in.radius_max = Real(0.01);
    in.density = Real(2500);
    REQUIRE_SPHERE_ERROR((sphere::inserter<Sim>(in, 0.0)),
                         Contains("insertion_settings: the region spans [0, inf] m on axis 2: its bounds must be finite"));
}

} // namespace test_errors
