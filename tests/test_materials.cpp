// Materials (contact/materials.cuh) on the linear law: the table of pairs chooses each
// contact's parameters. Two materials whose damping ratios give restitutions 0.9 and 0.5, a
// given unlike pair of 0.7 (or the mixing rule's value), and two wall materials on different
// faces, one with a given pair: a head-on collision or a bounce of every combination restitutes
// as its entry says, within 1% (damping ratios make e independent of sizes and masses:
// contact/restitution.cuh). Then the time step over all materials, the materials in
// checkpoints, snapshots and insertion, and the errors. docs/physics.md, "Materials".
// float, double, mixed.
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
namespace test_materials {

namespace {

using sphere_test::user_real;
using two_materials = sphere::contact::materials<sphere::contact::linear<>, 2>;
template <class P>
using material_sim = sphere::simulation<P, sphere_test::policy, two_materials>;

constexpr double k_n = 1e5;

/// Linear parameters with k_n = 1e5 N/m, no friction, and the damping ratio of restitution e
/// (no tension: Schwager & Poeschel's relation).
template <class Real>
sphere::contact_params<Real> restituting(double e)
{
    sphere::contact_params<Real> p;
    p.k_n = Real(k_n);
    p.k_t = Real(k_n * 2 / 7);
    p.damping = sphere::damping_convention::damping_ratio;
    p.gamma_n = Real(sphere::damping_ratio_from_restitution(e, false));
    return p;
}

/// Particle materials 0 (e = 0.9) and 1 (e = 0.5), their pair given 0.7 when `given`; wall
/// materials 0 (e = 0.8, every face but the floor) and 1 (e = 0.6, the floor), particles of
/// material 1 on wall material 1 given 0.3. The box [-0.1, 0.1]^3, no gravity.
template <class P>
typename material_sim<P>::settings_type two_material_box(bool given)
{
    using Real = user_real<P>;
    typename material_sim<P>::settings_type s;
    s.box.lo = {Real(-0.1), Real(-0.1), Real(-0.1)};
    s.box.hi = {Real(0.1), Real(0.1), Real(0.1)};
    s.contact.material[0] = restituting<Real>(0.9);
    s.contact.material[1] = restituting<Real>(0.5);
    if (given) s.contact.set_pair(0, 1, restituting<Real>(0.7));
    s.wall.material[0] = restituting<Real>(0.8);
    s.wall.material[1] = restituting<Real>(0.6);
    s.wall.face[4] = 1; // the floor, z = -0.1
    s.wall.set_pair(1, 1, restituting<Real>(0.3));
    return s;
}

/// Steps sim until the gap (m) that `gap` reads from a snapshot has closed and opened again, and
/// returns `speed` (m/s) of that snapshot.
template <class Sim, class Gap, class Speed>
double after_contact(Sim& sim, Gap gap, Speed speed)
{
    bool touched = false;
    for (int k = 0; k < 100000; ++k) {
        sim.step();
        const auto snap = sim.snapshot();
        touched = touched || gap(snap) < 0;
        if (touched && gap(snap) > 0) return speed(snap);
    }
    FAIL("the contact did not end");
    return 0;
}

/// The restitution of a head-on collision of a particle of material a (radius 1 cm) with one
/// of material b (radius 7 mm, another density), at the default dt / 10.
template <class P>
double pair_restitution(const typename material_sim<P>::settings_type& given, unsigned a, unsigned b)
{
    using Real = user_real<P>;
    std::vector<sphere::particle<Real>> ps(2);
    const double r[2] = {0.01, 0.007}, v = 0.5;
    for (int i = 0; i < 2; ++i) {
        ps[i].position = {Real(i == 0 ? -0.0101 : 0.0071), 0, 0};
        ps[i].radius = Real(r[i]);
        ps[i].density = Real(i == 0 ? 2500 : 7800);
        ps[i].velocity = {Real(i == 0 ? v : -v), 0, 0};
        ps[i].material = static_cast<std::uint8_t>(i == 0 ? a : b);
    }
    typename material_sim<P>::settings_type s = given;
    s.dt = Real(material_sim<P>(s, ps).dt() / 10);
    material_sim<P> sim(s, ps);
    return after_contact(
        sim, [&](const auto& snap) { return double(snap.x[1].x) - double(snap.x[0].x) - r[0] - r[1]; },
        [&](const auto& snap) { return (double(snap.v_sync[1].x) - double(snap.v_sync[0].x)) / (2 * v); });
}

/// The restitution of a particle of material a bouncing at 0.5 m/s on face f (4: the floor,
/// 0: x = -0.1), at the default dt / 10.
template <class P>
double wall_restitution(const typename material_sim<P>::settings_type& given, unsigned a, int f)
{
    using Real = user_real<P>;
    const int axis = f / 2;
    std::vector<sphere::particle<Real>> ps(1);
    ps[0].radius = Real(0.01);
    ps[0].density = Real(2500);
    ps[0].position[axis] = Real(-0.1 + 0.0101);
    ps[0].velocity[axis] = Real(-0.5);
    ps[0].material = static_cast<std::uint8_t>(a);
    typename material_sim<P>::settings_type s = given;
    s.dt = Real(material_sim<P>(s, ps).dt() / 10);
    material_sim<P> sim(s, ps);
    return after_contact(
        sim, [&](const auto& snap) { return double(snap.position(0)[axis]) + 0.1 - 0.01; },
        [&](const auto& snap) { return double(snap.v_sync[0][axis]) / 0.5; });
}

} // namespace

TEMPLATE_TEST_CASE("materials: each pair and wall contact restitutes as its entry in the table says", "[materials]",
                   float, double, sphere::mixed)
{
    const auto s = two_material_box<TestType>(true);
    CHECK(std::fabs(pair_restitution<TestType>(s, 0, 0) / 0.9 - 1) < 0.01);
    CHECK(std::fabs(pair_restitution<TestType>(s, 1, 1) / 0.5 - 1) < 0.01);
    CHECK(std::fabs(pair_restitution<TestType>(s, 0, 1) / 0.7 - 1) < 0.01);
    CHECK(std::fabs(pair_restitution<TestType>(s, 1, 0) / 0.7 - 1) < 0.01);
    CHECK(std::fabs(wall_restitution<TestType>(s, 0, 4) / 0.6 - 1) < 0.01); // wall material 1
    CHECK(std::fabs(wall_restitution<TestType>(s, 1, 4) / 0.3 - 1) < 0.01); // its given pair
    CHECK(std::fabs(wall_restitution<TestType>(s, 0, 0) / 0.8 - 1) < 0.01); // wall material 0
    CHECK(std::fabs(wall_restitution<TestType>(s, 1, 0) / 0.8 - 1) < 0.01);
}

TEMPLATE_TEST_CASE("materials: an unlike pair that is not given takes the mixing rule's parameters", "[materials]",
                   float, double, sphere::mixed)
{
    // Equal stiffnesses; the damping ratios zeta_0, zeta_1 mix as dashpots in series,
    // 2 zeta_0 zeta_1 / (zeta_0 + zeta_1): the collision restitutes as that ratio says (1%).
    const double z0 = sphere::damping_ratio_from_restitution(0.9, false);
    const double z1 = sphere::damping_ratio_from_restitution(0.5, false);
    const double expected = sphere::restitution_from_damping_ratio(2 * z0 * z1 / (z0 + z1), false);
    const auto s = two_material_box<TestType>(false);
    CHECK(std::fabs(pair_restitution<TestType>(s, 0, 1) / expected - 1) < 0.01);
    CHECK(std::fabs(pair_restitution<TestType>(s, 0, 0) / 0.9 - 1) < 0.01);
}

TEST_CASE("materials: the mixing rules of the linear law", "[materials]")
{
    sphere::contact_params<double> a, b;
    a.k_n = 1e5;
    b.k_n = 3e5;
    a.k_t = b.k_t = 2e4;
    a.gamma_n = 2;
    b.gamma_n = 0;
    a.mu_s = 0.4;
    b.mu_s = 0.9;
    const auto m = sphere::contact::linear<>::mix(a, b, "a", "b");
    CHECK(m.k_n == Approx(1.5e5).epsilon(1e-15));
    CHECK(m.k_t == 2e4); // like values stay exactly
    CHECK(m.gamma_n == 0);
    CHECK(m.mu_s == Approx(0.6).epsilon(1e-15));
    b.tension = true;
    CHECK_THROWS_WITH((sphere::contact::linear<>::mix(a, b, "settings.contact.material[0]", "settings.contact.material[1]")),
                      Catch::Contains("settings.contact.material[0].tension and settings.contact.material[1].tension "
                                      "differ: they have no mixing rule"));
}

TEMPLATE_TEST_CASE("materials: the time step covers the stiffest material", "[materials][time step]", float, double)
{
    using Real = TestType;
    auto s = two_material_box<TestType>(true);
    s.contact.material[1].k_n = Real(4e5);
    std::vector<sphere::particle<Real>> ps(1);
    ps[0].radius = Real(0.01);
    ps[0].density = Real(2500);
    const double m = 4.0 / 3.0 * 3.14159265358979323846 * 1e-6 * 2500;
    CHECK(double(material_sim<TestType>(s, ps).dt()) == Approx(0.075 * std::sqrt(m / 4e5)).epsilon(1e-5));
}

TEMPLATE_TEST_CASE("materials: checkpoints, snapshots and insertion keep each particle's material", "[materials][io]",
                   double, sphere::mixed)
{
    using Real = user_real<TestType>;
    auto s = two_material_box<TestType>(true);
    s.gravity = {0, 0, Real(-9.81)};
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 8; ++k) {
        sphere::particle<Real> p;
        p.position = {Real(-0.05 + 0.025 * (k % 4)), Real(-0.05 + 0.03 * (k / 4)), Real(-0.085)};
        p.radius = Real(0.01);
        p.density = Real(2500);
        p.material = static_cast<std::uint8_t>(k % 2);
        ps.push_back(p);
    }
    material_sim<TestType> sim(s, ps);
    sim.run(500);
    sphere::particle<Real> extra;
    extra.position = {Real(0.05), Real(0.05), Real(0.05)};
    extra.radius = Real(0.01);
    extra.density = Real(2500);
    extra.material = 1;
    sim.insert({extra});
    sim.run(200);
    const auto snap = sim.snapshot();
    for (std::size_t i = 0; i < 8; ++i) CHECK(snap.material[i] == i % 2);
    CHECK(snap.material[8] == 1);
    sphere_test::temp_folder dir("materials_checkpoint");
    const std::string path = dir / "materials.ck";
    sphere::write_checkpoint(path, sim);
    material_sim<TestType> again = sphere::restart<material_sim<TestType>>(path);
    CHECK(again.snapshot().material == snap.material);
    sim.run(300);
    again.run(300);
    const auto a = sim.snapshot(), b = again.snapshot();
    for (std::size_t i = 0; i < a.size(); ++i) {
        CHECK(a.x[i].x == b.x[i].x);
        CHECK(a.x[i].z == b.x[i].z);
    }
    const auto back = sphere::read_checkpoint<Real, two_materials>(path);
    CHECK(back.config.contact.given[0][1]);
    CHECK(back.config.wall.face[4] == 1);
    CHECK(back.config.wall.pair[1][1].gamma_n == s.wall.pair[1][1].gamma_n);
}

TEMPLATE_TEST_CASE("materials: bad material indices and parameters are refused by name", "[materials][errors]", float,
                   double)
{
    using Real = TestType;
    std::vector<sphere::particle<Real>> ps(2);
    for (int i = 0; i < 2; ++i) {
        ps[i].position = {Real(-0.05 + 0.05 * i), 0, 0};
        ps[i].radius = Real(0.01);
        ps[i].density = Real(2500);
    }
    ps[1].material = 2;
    const auto s = two_material_box<TestType>(true);
    CHECK_THROWS_WITH(material_sim<TestType>(s, ps),
                      Catch::Contains("particle 1: material = 2, but the contact law materials<linear<") &&
                          Catch::Contains("has materials 0 to 1"));
    ps[1].material = 1;
    CHECK_NOTHROW(material_sim<TestType>(s, ps));
    // a law without materials takes material 0 only
    sphere::settings<Real> plain = sphere_test::box_settings<Real>();
    CHECK_THROWS_WITH((sphere::simulation<TestType, sphere_test::policy>(plain, ps)),
                      Catch::Contains("particle 1: material = 1") && Catch::Contains("has materials 0 to 0"));
    auto refused = [&](auto change, const std::string& what) {
        auto t = s;
        change(t);
        CHECK_THROWS_WITH(material_sim<TestType>(t, ps), Catch::Contains(what));
    };
    refused([](auto& t) { t.contact.material[1].k_n = Real(-1); }, "settings.contact.material[1].k_n = -1");
    refused([](auto& t) { t.wall.pair[1][1].mu_s = Real(-2); }, "settings.wall.pair[1][1].mu_s = -2");
    refused([](auto& t) { t.wall.face[2] = 5; }, "settings.wall.face[2] = 5: not a wall material (0 to 1)");
    refused([](auto& t) { t.contact.face[0] = 1; }, "settings.contact.face[0] = 1: faces take their material from");
    refused([](auto& t) { t.contact.set_pair(1, 0, t.contact.material[0]); }, "settings.contact.given[1][0]");
    refused(
        [](auto& t) {
            t.contact.given[0][1] = false;
            t.contact.material[1].tension = true;
        },
        "settings.contact.material[0].tension and settings.contact.material[1].tension differ");
}

} // namespace test_materials
