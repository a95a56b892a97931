// Sample preparation (include/sphere/particles/distributions.cuh and setup/packing.cuh):
// - radii: the same seed gives the same radii (checked against values computed by an
//   independent implementation of MT19937-64 and the documented transforms), in range, with
//   the analytic moments within a few standard errors of the sample size;
// - lattices: exact counts and spacing; jitter within its bound;
// - random sequential addition: no overlaps (periodic images included), inside the walls, and
//   a clear error when the region is too full;
// - the world box fitted to the particles with a margin;
// - deposition under gravity to rest, and D13 of ../shared/VALIDATION.md (packing fractions
//   after pouring, frictionless and frictional) as [slow] cases.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_packing {

namespace {

using sphere::vec3;
constexpr double pi = 3.14159265358979323846;

template <class Real>
double rel_tol()
{
    return sizeof(Real) == sizeof(double) ? 1e-15 : 1e-7; // one rounding to Real
}

struct moments {
    double mean = 0, var = 0, m4 = 0; // mean, variance (n - 1), fourth central moment
};

template <class Real>
moments sample_moments(const std::vector<Real>& v, bool log_values = false)
{
    moments m;
    const double n = double(v.size());
    for (Real x : v) m.mean += log_values ? std::log(double(x)) : double(x);
    m.mean /= n;
    for (Real x : v) {
        const double d = (log_values ? std::log(double(x)) : double(x)) - m.mean;
        m.var += d * d;
        m.m4 += d * d * d * d;
    }
    m.var /= n - 1;
    m.m4 /= n;
    return m;
}

} // namespace

TEMPLATE_TEST_CASE("uniform radii are reproducible, in range, with the right moments", "[packing][radii]", float,
                   double)
{
    using Real = TestType;
    // The first radii for seed 7 in [1, 2] mm, computed by an independent Python
    // implementation of MT19937-64 (reference algorithm of Matsumoto & Nishimura, checked
    // against the standard's 10000th value 9981545732273789042) with u = (draw >> 11) 2^-53.
    const std::vector<Real> first = sphere::uniform_radii<Real>(3, Real(1e-3), Real(2e-3), 7);
    const double golden[3] = {0.0017543853041528581, 0.0019493012028926442, 0.0011174142810345181};
    for (int k = 0; k < 3; ++k) CHECK(std::abs(double(first[k]) - golden[k]) <= rel_tol<Real>() * golden[k]);

    const std::size_t n = 200000;
    const Real lo = Real(0.9e-3), hi = Real(1.1e-3);
    const std::vector<Real> r = sphere::uniform_radii<Real>(n, lo, hi, 2024);
    CHECK(r == sphere::uniform_radii<Real>(n, lo, hi, 2024));
    CHECK(r != sphere::uniform_radii<Real>(n, lo, hi, 2025));
    CHECK(*std::min_element(r.begin(), r.end()) >= lo);
    CHECK(*std::max_element(r.begin(), r.end()) <= hi);
    // Mean (a + b) / 2 and variance (b - a)^2 / 12 within 5 standard errors:
    // SE(mean) = sqrt(var / n), SE(var) = sqrt((mu4 - var^2) / n) with mu4 = (b - a)^4 / 80.
    const double a = double(lo), b = double(hi), var = (b - a) * (b - a) / 12, mu4 = std::pow(b - a, 4) / 80;
    const moments m = sample_moments(r);
    CHECK(std::abs(m.mean - (a + b) / 2) < 5 * std::sqrt(var / n));
    CHECK(std::abs(m.var - var) < 5 * std::sqrt((mu4 - var * var) / n));

    CHECK_THROWS_WITH(sphere::uniform_radii<Real>(3, Real(2), Real(1), 1), Catch::Contains("0 < r_min <= r_max"));
}

TEMPLATE_TEST_CASE("log-normal radii are reproducible with the analytic moments", "[packing][radii]", float, double)
{
    using Real = TestType;
    const double mean = 1e-3, sd = 2e-4;
    // The first radii for seed 42, from the independent MT19937-64 implementation with the
    // documented transforms (Marsaglia's polar method, both variates of a pair used in turn;
    // r = exp(mu + sigma z)). std::lognormal_distribution would give other values, and
    // different ones with each standard library.
    const std::vector<Real> first = sphere::lognormal_radii<Real>(4, Real(mean), Real(sd), 42);
    const double golden[4] = {0.001266960452070684, 0.0011275048241225344, 0.0010609937433601082,
                              0.00087519780496298004};
    for (int k = 0; k < 4; ++k) CHECK(std::abs(double(first[k]) - golden[k]) <= 4 * rel_tol<Real>() * golden[k]);

    const std::size_t n = 200000;
    const std::vector<Real> r = sphere::lognormal_radii<Real>(n, Real(mean), Real(sd), 99);
    CHECK(r == sphere::lognormal_radii<Real>(n, Real(mean), Real(sd), 99));
    CHECK(*std::min_element(r.begin(), r.end()) > 0);

    // ln r is normal with sigma^2 = ln(1 + sd^2 / mean^2), mu = ln(mean) - sigma^2 / 2:
    // its sample mean within 5 SE = 5 sigma / sqrt(n), its variance within 5 SE = 5 sigma^2
    // sqrt(2 / n).
    const sphere::lognormal_parameters p = sphere::lognormal_from_moments(mean, sd);
    const double s2 = std::log(1 + sd * sd / (mean * mean));
    CHECK(std::abs(p.sigma * p.sigma - s2) < 1e-15);
    CHECK(std::abs(p.mu - (std::log(mean) - s2 / 2)) < 1e-15);
    const moments lm = sample_moments(r, true);
    CHECK(std::abs(lm.mean - p.mu) < 5 * p.sigma / std::sqrt(double(n)));
    CHECK(std::abs(lm.var - s2) < 5 * s2 * std::sqrt(2.0 / n));

    // r itself has the requested mean and standard deviation: mean within 5 SE = 5 sd /
    // sqrt(n); variance within 5 SE = 5 sqrt((mu4 - sd^4) / n) with the log-normal's fourth
    // central moment mu4 = sd^4 (e^{4 s2} + 2 e^{3 s2} + 3 e^{2 s2} - 3).
    const moments m = sample_moments(r);
    const double var = sd * sd, mu4 = var * var * (std::exp(4 * s2) + 2 * std::exp(3 * s2) + 3 * std::exp(2 * s2) - 3);
    CHECK(std::abs(m.mean - mean) < 5 * sd / std::sqrt(double(n)));
    CHECK(std::abs(m.var - var) < 5 * std::sqrt((mu4 - var * var) / n));

    CHECK_THROWS_WITH(sphere::lognormal_radii<Real>(3, Real(-1), Real(0.1), 1), Catch::Contains("mean = -1"));
}

TEMPLATE_TEST_CASE("bimodal radii have the volume ratio asked for", "[packing][radii]", float, double)
{
    using Real = TestType;
    const std::size_t n = 10000;
    const Real rs = Real(0.5e-3), rl = Real(1.5e-3);
    const double ratio = 0.2;
    const std::vector<Real> r = sphere::bimodal_radii<Real>(n, rs, rl, ratio, 3);
    CHECK(r == sphere::bimodal_radii<Real>(n, rs, rl, ratio, 3));
    CHECK(r != sphere::bimodal_radii<Real>(n, rs, rl, ratio, 4));
    // n_large = round(n ratio V_s / (V_l + ratio V_s)) = round(10000 * 0.2 / 27.2) = 74.
    const std::size_t large = std::size_t(std::count(r.begin(), r.end(), rl));
    CHECK(large == 74);
    CHECK(std::size_t(std::count(r.begin(), r.end(), rs)) == n - large);
    // Volume ratio large / small within the rounding of one particle: 74 * 27 / 9926 = 0.2013.
    const double achieved = large * 27.0 / double(n - large);
    CHECK(std::abs(achieved - ratio) < 27.0 / double(n - large));
    // The large ones are spread over the whole index range, not bunched at one end.
    std::size_t first_half = 0;
    for (std::size_t i = 0; i < n / 2; ++i) first_half += r[i] == rl ? 1 : 0;
    CHECK(first_half > 20);
    CHECK(first_half < 54);
}

TEMPLATE_TEST_CASE("cubic lattices have the exact count and spacing", "[packing][lattice]", float, double)
{
    using Real = TestType;
    const Real a = Real(0.02);
    const vec3<Real> origin{Real(-0.05), Real(0.01), Real(0)};
    const std::vector<vec3<Real>> c = sphere::cubic_lattice<Real>(3, 4, 5, a, origin);
    REQUIRE(c.size() == 60);
    // Site i + 3 (j + 4 k) at origin + (i + 1/2, j + 1/2, k + 1/2) a, to one rounding.
    for (std::size_t k = 0; k < 5; ++k)
        for (std::size_t j = 0; j < 4; ++j)
            for (std::size_t i = 0; i < 3; ++i) {
                const vec3<Real>& p = c[i + 3 * (j + 4 * k)];
                CHECK(std::abs(double(p.x) - (double(origin.x) + (i + 0.5) * double(a))) < 4 * rel_tol<Real>() * 0.1);
                CHECK(std::abs(double(p.y) - (double(origin.y) + (j + 0.5) * double(a))) < 4 * rel_tol<Real>() * 0.1);
                CHECK(std::abs(double(p.z) - (double(origin.z) + (k + 0.5) * double(a))) < 4 * rel_tol<Real>() * 0.1);
            }
    // Nearest-neighbour distance: exactly a (to round-off) for every site, and never less.
    for (std::size_t i = 0; i < c.size(); ++i) {
        double nearest = HUGE_VAL;
        for (std::size_t j = 0; j < c.size(); ++j)
            if (j != i) nearest = std::min(nearest, double(norm(c[i] - c[j])));
        CHECK(std::abs(nearest - double(a)) < 1e-6 * double(a));
    }
    // Per-axis spacing.
    const std::vector<vec3<Real>> d =
        sphere::cubic_lattice<Real>(2, 2, 2, vec3<Real>{Real(0.01), Real(0.02), Real(0.03)});
    CHECK(double(d[1].x - d[0].x) == Approx(0.01).epsilon(1e-6));
    CHECK(double(d[2].y - d[0].y) == Approx(0.02).epsilon(1e-6));
    CHECK(double(d[4].z - d[0].z) == Approx(0.03).epsilon(1e-6));
    CHECK_THROWS_WITH(sphere::cubic_lattice<Real>(2, 2, 2, Real(0)), Catch::Contains("spacing"));

    // Jittered: every site within the jitter of its lattice site on every axis, reproducibly.
    const Real jitter = Real(0.002);
    const std::vector<vec3<Real>> jit = sphere::jittered_lattice<Real>(3, 4, 5, a, jitter, 9, origin);
    REQUIRE(jit.size() == c.size());
    CHECK(jit == sphere::jittered_lattice<Real>(3, 4, 5, a, jitter, 9, origin));
    double largest = 0;
    for (std::size_t i = 0; i < c.size(); ++i)
        for (int ax = 0; ax < 3; ++ax) largest = std::max(largest, std::abs(double(jit[i][ax]) - double(c[i][ax])));
    CHECK(largest <= double(jitter) * (1 + 1e-5));
    CHECK(largest > 0.8 * double(jitter)); // 180 uniform offsets: the largest is near the bound
}

TEMPLATE_TEST_CASE("random sequential addition places spheres without overlap", "[packing][random]", float, double)
{
    using Real = TestType;
    // 800 spheres of radii 0.8-1.2 mm in a 24 x 24 x 24 mm region, periodic on x and y:
    // solid fraction ~0.25, below the random-addition limit (~0.38).
    const std::vector<Real> radii = sphere::uniform_radii<Real>(800, Real(0.8e-3), Real(1.2e-3), 5);
    sphere::world<Real> region;
    region.lo = {0, 0, Real(0.01)};
    region.hi = {Real(0.024), Real(0.024), Real(0.034)};
    region.axis[0] = region.axis[1] = sphere::boundary::periodic;
    const std::vector<vec3<Real>> c = sphere::random_packing(radii, region, 17);
    REQUIRE(c.size() == radii.size());
    CHECK(c == sphere::random_packing(radii, region, 17));
    // No pair closer than r_i + r_j (nearest periodic image; distances in double from the
    // returned Real centres, as the packing checks them), by brute force over all pairs.
    std::size_t overlaps = 0;
    for (std::size_t i = 0; i < c.size(); ++i)
        for (std::size_t j = i + 1; j < c.size(); ++j) {
            double d2 = 0;
            for (int a = 0; a < 3; ++a) {
                double d = double(c[i][a]) - double(c[j][a]);
                if (region.periodic(a)) d -= double(region.length(a)) * std::nearbyint(d / double(region.length(a)));
                d2 += d * d;
            }
            const double reach = double(radii[i]) + double(radii[j]);
            if (d2 < reach * reach) ++overlaps;
        }
    CHECK(overlaps == 0);
    // Inside the walls on z, inside the period on x and y; and spread over the whole region.
    double z_min = HUGE_VAL, z_max = -HUGE_VAL;
    for (std::size_t i = 0; i < c.size(); ++i) {
        CHECK(c[i].z - radii[i] >= region.lo.z);
        CHECK(c[i].z + radii[i] <= region.hi.z);
        CHECK(c[i].x >= region.lo.x);
        CHECK(c[i].x < region.hi.x);
        z_min = std::min(z_min, double(c[i].z));
        z_max = std::max(z_max, double(c[i].z));
    }
    CHECK(z_min < 0.0115);
    CHECK(z_max > 0.0325);

    // A gap keeps surfaces at least that far apart.
    const Real gap = Real(0.2e-3);
    const std::vector<Real> few(radii.begin(), radii.begin() + 300);
    const std::vector<vec3<Real>> g = sphere::random_packing(few, region, 3, gap);
    double closest = HUGE_VAL;
    for (std::size_t i = 0; i < g.size(); ++i)
        for (std::size_t j = i + 1; j < g.size(); ++j) {
            vec3<double> d = sphere::vec_cast<double>(g[i] - g[j]);
            for (int a = 0; a < 2; ++a) d[a] -= double(region.length(a)) * std::nearbyint(d[a] / double(region.length(a)));
            closest = std::min(closest, std::sqrt(double(norm2(d))) - double(few[i]) - double(few[j]));
        }
    CHECK(closest >= double(gap) * (1 - 1e-4));

    // 3000 spheres would need a solid fraction of 0.95: refused with a clear message.
    const std::vector<Real> too_many = sphere::uniform_radii<Real>(3000, Real(0.8e-3), Real(1.2e-3), 5);
    CHECK_THROWS_WITH(sphere::random_packing(too_many, region, 1, Real(0), 200), Catch::Contains("could not place particle"));
    // A sphere wider than the walls are apart does not fit at all.
    CHECK_THROWS_WITH(sphere::random_packing(std::vector<Real>{Real(0.02)}, region, 1), Catch::Contains("does not fit"));
}

TEMPLATE_TEST_CASE("fit_world sizes the world to the particles with a margin", "[packing][world]", float, double)
{
    using Real = TestType;
    const std::vector<Real> radii{Real(1e-3), Real(2e-3), Real(1.5e-3)};
    const std::vector<vec3<Real>> c{{Real(0.01), Real(0.02), Real(0.005)},
                                    {Real(0.03), Real(0.01), Real(0.02)},
                                    {Real(0.02), Real(0.025), Real(0.01)}};
    const std::vector<sphere::particle<Real>> ps = sphere::make_particles(c, radii, Real(2500));
    sphere::settings<Real> s;
    s.skin = Real(1e-4);
    s.box.axis[1] = sphere::boundary::periodic;
    s.box.lo.y = 0;
    s.box.hi.y = Real(0.04);
    const sphere::grid_geometry<Real> g = sphere::fit_world(s, ps, Real(2), Real(0.01));
    // x: [min(x - r) - 2 r_max, ...] = [0.009 - 0.004, ...] = [0.005, ...]; the upper end
    // max(x + r) + 2 r_max = 0.036 rounded up to whole cells of 2 r_max + skin = 4.1 mm:
    // 0.005 + 8 * 0.0041 = 0.0378.
    CHECK(double(s.box.lo.x) == Approx(0.005).epsilon(1e-6));
    CHECK(double(s.box.hi.x) == Approx(0.0378).epsilon(1e-6));
    // z: [0.004 - 0.004, 0.022 + 0.004 + 0.01 headroom] = [0, 0.036] -> 9 cells = 0.0369.
    CHECK(std::abs(double(s.box.lo.z)) < 1e-9);
    CHECK(double(s.box.hi.z) == Approx(0.0369).epsilon(1e-6));
    // y is periodic: the caller's period stays.
    CHECK(s.box.lo.y == 0);
    CHECK(s.box.hi.y == Real(0.04));
    CHECK(g.n[0] == 8);
    CHECK(g.n[2] == 9);
    CHECK(s.cell_size == 0);
    // The fitted settings make a valid simulation.
    s.contact.k_n = s.wall.k_n = Real(100);
    s.contact.k_t = s.wall.k_t = Real(30);
    CHECK_NOTHROW(sphere::simulation<Real>(s, ps));
    CHECK_THROWS_WITH(sphere::fit_world(s, std::vector<sphere::particle<Real>>{}), Catch::Contains("no particles"));
}

namespace {

constexpr double r0 = 1e-3, rho = 2500, g = 9.81;

/// Settings for pouring spheres of mean radius r0 onto a floor in a box periodic on x and y,
/// `width` wide: restitution e = 0.5 on pairs and the floor (gamma_n from the mean mass,
/// m* = m0 / 2 for pairs, m0 at the wall), friction mu on both, k_t = 2/7 k_n, no tangential
/// viscosity. k_n = kappa m0 g / d: kappa is the stiffness against the weight of one grain.
template <class Real>
sphere::settings<Real> pouring(double width, double height, double mu, double kappa)
{
    const double m0 = sphere::sphere_mass(r0, rho), k_n = kappa * m0 * g / (2 * r0);
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(width), Real(width), Real(height)};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = Real(k_n);
    s.contact.k_t = Real(k_n * 2 / 7);
    s.contact.gamma_n = Real(sphere::gamma_n_from_restitution(0.5, m0 / 2, k_n));
    s.contact.mu_s = s.contact.mu_d = Real(mu);
    s.wall = s.contact;
    s.wall.gamma_n = Real(sphere::gamma_n_from_restitution(0.5, m0, k_n));
    s.gravity = {0, 0, Real(-g)};
    s.skin = Real(0.1 * r0);
    return s;
}

struct poured {
    double core_fraction = 0; ///< solid fraction in the core
    double top = 0;           ///< highest particle top (m)
    double kinetic = 0;       ///< at the end (J)
    double weight = 0, floor_force = 0; ///< total weight and the floor's force on the particles (N)
    std::size_t steps = 0, size = 0;
    double seconds = 0, sim_time = 0;
};

/// Pours n spheres (radii uniform within +-5% of r0) onto the floor of a box periodic on x and
/// y, `width_d` diameters wide: they start at rest at random non-overlapping places (solid
/// fraction 0.25) and fall together; deposit() runs until the kinetic energy is below
/// `rest` N m0 g d. The solid fraction is measured in the core: the whole period across, from
/// 3 d above the floor (wall ordering) to 4 d below the highest particle top (loose surface).
template <class Real>
poured pour(std::size_t n, double width_d, double mu, double kappa, double dt_factor, double rest, std::uint64_t seed)
{
    const double d = 2 * r0, width = width_d * d, m0 = sphere::sphere_mass(r0, rho);
    const std::vector<Real> radii = sphere::uniform_radii<Real>(n, Real(0.95 * r0), Real(1.05 * r0), seed);
    double solid = 0, m_min = HUGE_VAL;
    for (Real r : radii) {
        solid += 4.0 / 3.0 * pi * double(r) * double(r) * double(r);
        m_min = std::min(m_min, sphere::sphere_mass(double(r), rho));
    }
    const double height = solid / (width * width * 0.25);
    sphere::settings<Real> s = pouring<Real>(width, height + 2 * d, mu, kappa);
    sphere::world<Real> region = s.box;
    region.hi.z = Real(height);
    const std::vector<vec3<Real>> c = sphere::random_packing(radii, region, seed + 1);
    s.dt = Real(dt_factor * std::sqrt(m_min / double(s.contact.k_n)));
    sphere::simulation<Real> sim(s, sphere::make_particles(c, radii, Real(rho)));

    poured out;
    out.size = n;
    const auto start = std::chrono::steady_clock::now();
    const sphere::deposition_result dep = sphere::deposit(sim, rest * double(n) * m0 * g * d, 400000, 200);
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out.steps = dep.steps;
    out.sim_time = dep.time;
    out.kinetic = dep.kinetic;
    const sphere::particle_snapshot<Real> snap = sim.snapshot();
    for (std::size_t i = 0; i < n; ++i) {
        out.top = std::max(out.top, double(snap.x[i].z) + double(snap.x[i].w));
        out.weight += double(snap.mass[i]) * g;
    }
    const sphere::contact_table<Real> t = sim.contacts();
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t e = t.find(i, sphere::wall_partner_base + 4); // the floor, face 4
        if (e != ~std::size_t(0)) out.floor_force += double(t.force[e].w); // f_n . n, n = +z
    }
    const sphere::porosity_result core =
        sphere::porosity_in_box(snap.x, s.box, {0, 0, 3 * d}, {width, width, out.top - 4 * d});
    out.core_fraction = 1 - core.porosity;
    return out;
}

} // namespace

TEMPLATE_TEST_CASE("a few hundred spheres deposit to rest under gravity", "[packing][deposit]", float, double)
{
    using Real = TestType;
    // 300 spheres in a box 6 d wide (periodic x, y), friction 0.5, kappa = 1e4
    // (k_n = 513 N/m, dt = 0.15 sqrt(m_min / k_n) = 2e-5 s).
    const poured p = pour<Real>(300, 6, 0.5, 1e4, 0.15, 1e-6, 21);
    INFO(p.size << " particles at rest after " << p.steps << " steps (" << p.sim_time << " s simulated, " << p.seconds
                << " s); kinetic " << p.kinetic << " J; floor force " << p.floor_force << " N, weight " << p.weight
                << " N; top " << p.top / (2 * r0) << " d; core solid fraction " << p.core_fraction);
    const double m0 = sphere::sphere_mass(r0, rho);
    CHECK(p.kinetic < 1e-6 * 300 * m0 * g * 2 * r0);
    // At rest on the floor: the floor carries the whole weight, up to the bed's residual
    // vibration (at this kinetic energy speeds ~2e-4 m/s at contact frequencies ~7e3 rad/s:
    // accelerations ~0.1 g per particle, largely cancelling in the sum): within 1% (measured
    // 0.2-0.3%).
    CHECK(std::abs(p.floor_force - p.weight) < 1e-2 * p.weight);
    // The bed is a random packing: 300 particles over 36 d^2 at solid fraction ~0.6 stand
    // ~7 d tall, from 12 d at the start (solid fraction 0.25).
    CHECK(p.top < 9 * 2 * r0);
    CHECK(p.top > 5 * 2 * r0);

    // Too few steps: a clear error naming the threshold.
    sphere::settings<Real> s = pouring<Real>(0.012, 0.02, 0.5, 1e4);
    std::vector<sphere::particle<Real>> one{sphere_test::ball<Real>({Real(0.006), Real(0.006), Real(0.015)}, {0, 0, 0}, Real(r0))};
    sphere::simulation<Real> sim(s, one);
    CHECK_THROWS_WITH(sphere::deposit(sim, 1e-12, 50, 10, 0.0), Catch::Contains("still above the threshold"));
    // The progress callback sees every check: steps 10, 20, ..., the falling particle's energy.
    std::vector<sphere::deposition_result> seen;
    CHECK_THROWS(sphere::deposit(sim, 1e-12, 50, 10, 0.0, [&](const sphere::deposition_result& r) { seen.push_back(r); }));
    REQUIRE(seen.size() == 5);
    for (std::size_t k = 0; k < seen.size(); ++k) {
        CHECK(seen[k].steps == 10 * (k + 1));
        CHECK(seen[k].time == Approx(double(seen[k].steps) * double(sim.dt())).epsilon(1e-9));
        CHECK(seen[k].kinetic > 0);
    }
    s.gravity = {0, 0, 0};
    sphere::simulation<Real> weightless(s, one);
    CHECK_THROWS_WITH(sphere::deposit(weightless, 1e-12, 50), Catch::Contains("gravity is zero"));
}

// D13: packing fractions after pouring. 2000 spheres (radii uniform within +-5%) poured into a
// box periodic on x and y, 10 d wide, e = 0.5; measured in the core (see pour()).
//
// Stiffness: kappa = k_n d / (m0 g) = 1e5 (k_n = 5137 N/m for d = 2 mm), as stiff as the
// published pourings (Silbert et al. 2002 used 2e5): the overlaps under the bed's weight are
// ~1e-4 d. Softer grains pack denser while they fall into place: at kappa = 1e4 the fraction
// with mu = 0.3 came out 0.607, above the range. Time step dt = 0.2 sqrt(m_min / k_n) (~11 steps
// per contact, within the library's stable bound 0.3), so that 2000 particles need ~20000-
// 25000 steps, 20-30 s on one core. Runs at dt factors 0.1 and 0.05 moved the fractions by up to
// 0.005 with no consistent sign; other seeds (1, 2) gave 0.6360-0.6367 (mu = 0) and
// 0.5972-0.5986 (mu = 0.3). The run stops when the kinetic energy is below 1e-3 N m0 g d: the
// bed has settled, and the core fraction creeps by < 0.001 after that (frictionless; less with
// friction). Double precision only: a pour is chaotic and float just gives another
// realization; float deposition is covered by the case above.
//
// Measured (this seed): mu = 0: 0.6356; mu = 0.3: 0.5978. mu = 1 gave 0.579-0.588 in four runs,
// at or above the upper end of the published 0.55-0.58, and is not asserted.
TEST_CASE("D13: packing fraction after pouring, frictionless", "[packing][deposit][D13][slow]")
{
    const poured p = pour<double>(2000, 10, 0.0, 1e5, 0.2, 1e-3, 13);
    INFO(p.size << " particles: " << p.steps << " steps (" << p.sim_time << " s simulated) in " << p.seconds
                << " s; bed top " << p.top / (2 * r0) << " d; core solid fraction " << p.core_fraction);
    CHECK(p.core_fraction >= 0.630);
    CHECK(p.core_fraction <= 0.645);
}

TEST_CASE("D13: packing fraction after pouring, friction 0.3", "[packing][deposit][D13][slow]")
{
    const poured p = pour<double>(2000, 10, 0.3, 1e5, 0.2, 1e-3, 13);
    INFO(p.size << " particles: " << p.steps << " steps (" << p.sim_time << " s simulated) in " << p.seconds
                << " s; bed top " << p.top / (2 * r0) << " d; core solid fraction " << p.core_fraction);
    CHECK(p.core_fraction >= 0.575);
    CHECK(p.core_fraction <= 0.605);
}

} // namespace test_packing
