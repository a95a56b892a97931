// Precision policies (core/precision.cuh): what sphere::mixed keeps in double and why. A
// static pair 0.05-0.07 m from the origin with an overlap of 1e-8 m, as in a settled bed
// (../shared/bench/bed: overlaps 1e-8 - 2e-7 m at positions ~0.05 m): float positions
// cannot hold that overlap (one ulp of 0.05f is 3.7e-9 m), mixed and double can.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <cmath>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_precision {

using sphere::vec3;
using sphere_test::user_real;

namespace {

constexpr double overlap = 1e-8; // m
constexpr double k_n = 1e5;      // N/m

/// Two fixed set-P spheres touching with `overlap` along a skew direction, the first at
/// (0.0512345, 0.0498765, 0.0501234) m in a box [0, 0.1]^3.
template <class Real>
std::vector<sphere::particle<Real>> skew_pair(vec3<double>& a, vec3<double>& b)
{
    const double r = 0.01;
    const vec3<double> dir = vec3<double>{0.6, 0.48, 0.64} / std::sqrt(0.36 + 0.2304 + 0.4096);
    a = {0.0512345, 0.0498765, 0.0501234};
    b = a + dir * (2 * r - overlap);
    std::vector<sphere::particle<Real>> ps(2);
    for (int k = 0; k < 2; ++k) {
        const vec3<double>& x = k == 0 ? a : b;
        ps[k].position = {Real(x.x), Real(x.y), Real(x.z)};
        ps[k].radius = Real(r);
        ps[k].density = Real(2500);
        ps[k].kind = sphere::motion::fixed;
    }
    return ps;
}

template <class P>
double pair_force(const std::vector<sphere::particle<user_real<P>>>& ps)
{
    using Real = user_real<P>;
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(0.1), Real(0.1), Real(0.1)};
    s.contact.k_n = Real(k_n);
    s.contact.k_t = Real(k_n);
    s.wall = s.contact;
    sphere::simulation<P> sim(s, ps);
    sim.step();
    const auto snap = sim.snapshot();
    return sphere::norm(sphere::vec_cast<double>(snap.force[0]));
}

} // namespace

TEMPLATE_TEST_CASE("double and mixed resolve an overlap of 1e-8 m at 0.05 m from the origin", "[precision]", double,
                   sphere::mixed)
{
    using P = TestType;
    vec3<double> a, b;
    const auto ps = skew_pair<user_real<P>>(a, b);
    // k_n delta = 1e-3 N. Double: the overlap's rounding is ~1e-17 m / 1e-8 m. Mixed: the
    // separation and dist^2 - reach^2 are formed in double, the rest in float (relative
    // rounding ~1e-7 per operation): 1e-5 of the force.
    const double f = pair_force<P>(ps);
    INFO("force " << f << " N, expected " << k_n * overlap << " N");
    CHECK(std::abs(f - k_n * overlap) / (k_n * overlap) < (std::is_same_v<P, double> ? 1e-6 : 1e-5));
}

TEST_CASE("float positions round the overlap away: the force follows the rounded geometry", "[precision]")
{
    vec3<double> a, b;
    const auto ps = skew_pair<float>(a, b);
    // The overlap the float positions really describe, computed in double.
    vec3<double> fa = sphere::vec_cast<double>(ps[0].position), fb = sphere::vec_cast<double>(ps[1].position);
    const double rounded = 2 * double(ps[0].radius) - sphere::norm(fb - fa);
    const double f = pair_force<float>(ps);
    INFO("float: overlap " << rounded << " m (intended " << overlap << " m), force " << f << " N");
    // Rounding these inputs to float moves the overlap by 3 % (9.69e-9 m), and float arithmetic
    // on |x_a - x_b| ~ 0.02 m (ulp 1.9e-9 m) errs by as much again: the force is 7 % off, where
    // mixed is within 1e-5. (Deterministic: the same roundings every run.)
    CHECK(std::abs(rounded - overlap) > 0.02 * overlap);
    CHECK(std::abs(f - k_n * overlap) > 0.02 * k_n * overlap);
}

TEST_CASE("mixed hands out double positions unrounded and float fields exactly", "[precision]")
{
    vec3<double> a, b;
    auto ps = skew_pair<double>(a, b);
    ps[0].kind = ps[1].kind = sphere::motion::prescribed;
    ps[0].velocity = {0.1, 0.2, 1.0 / 3.0};
    sphere::settings<double> s;
    s.box.hi = {0.1, 0.1, 0.1};
    s.contact.k_n = s.contact.k_t = k_n;
    s.wall = s.contact;
    sphere::simulation<sphere::mixed> sim(s, ps);
    const auto snap = sim.snapshot();
    CHECK(snap.position(0) == a);
    CHECK(snap.position(1) == b);
    // velocities are float: the snapshot shows the stored (rounded) value, not the input
    CHECK(snap.v[0].z == double(float(1.0 / 3.0)));
    CHECK(snap.v[0].z != 1.0 / 3.0);
    // the time step the kernels use is float too, and dt() says so
    CHECK(sim.dt() == double(float(sim.dt())));
    // state -> restore is exact
    sim.run(10);
    const auto st = sim.state();
    sphere::simulation<sphere::mixed> copy(s, ps);
    copy.restore(st);
    const auto again = copy.state();
    for (std::size_t i = 0; i < 2; ++i) {
        CHECK(again.particles.position(i) == st.particles.position(i));
        CHECK(again.particles.v[i] == st.particles.v[i]);
    }
}

TEST_CASE("mixed refuses values that float cannot hold, naming them", "[precision][errors]")
{
    vec3<double> a, b;
    const auto ps = skew_pair<double>(a, b);
    sphere::settings<double> s;
    s.box.hi = {0.1, 0.1, 0.1};
    s.contact.k_n = s.contact.k_t = k_n;
    s.wall = s.contact;
    using mixed_sim = sphere::simulation<sphere::mixed>;
    {
        sphere::settings<double> t = s;
        t.contact.k_n = 1e39; // a double, but above float's 3.4e38
        REQUIRE_THROWS_WITH(mixed_sim(t, ps), Catch::Contains("settings.contact.k_n = 9.99999") &&
                                                  Catch::Contains("e+38 N/m does not fit in float"));
    }
    {
        sphere::settings<double> t = s;
        t.wall.gamma_n = 1e-50; // rounds to zero in float
        REQUIRE_THROWS_WITH(mixed_sim(t, ps), Catch::Contains("settings.wall.gamma_n = 1") &&
                                                  Catch::Contains("e-50 does not fit in float"));
    }
    {
        auto heavy = ps;
        heavy[1].density = 1e45; // mass 4.2e39 kg: above float's 3.4e38
        REQUIRE_THROWS_WITH(mixed_sim(s, heavy), Catch::Contains("particle 1: mass (radius 0.01") &&
                                                     Catch::Contains("kg/m^3) = 4.18") &&
                                                     Catch::Contains("e+39 kg does not fit in float"));
    }
    {
        auto fast = ps;
        fast[0].kind = sphere::motion::free;
        fast[0].velocity = {0, 1e40, 0};
        REQUIRE_THROWS_WITH(mixed_sim(s, fast), Catch::Contains("particle 0: velocity[1] = 1") &&
                                                    Catch::Contains("e+40 m/s does not fit in float"));
    }
    // double holds the same values; only the time step they imply (2.4e-22 s) is refused, as
    // below the 1e-15 s every precision refuses
    sphere::settings<double> t = s;
    t.contact.k_n = t.contact.k_t = 1e39;
    t.wall = t.contact;
    CHECK_THROWS_WITH(sphere::simulation<double>(t, ps),
                      Catch::Contains("s is below 1e-15 s") && !Catch::Contains("float"));
}

} // namespace test_precision
