// Analysis functions (include/sphere/analysis/porosity.cuh, stress.cuh, shear.cuh):
// - the exact volume of a sphere inside a box, against the cap formula, symmetry (halves,
//   quarters, octants), a partition of space into boxes, and an independent 2D quadrature;
// - porosity and void ratio of a simple cubic lattice, 1 - pi/6, for boxes that cut the spheres
//   anywhere, across periodic boundaries, and slice by slice against integrated disk areas;
// - a static simple-cubic column compressed by a stress-controlled upper wall (the D10 set-up
//   of ../shared/VALIDATION.md, with the lattice squeezed sideways too): the Love-Weber stress
//   against the wall stress and the analytic lateral stress, the coordination numbers and the
//   contact network against the lattice's exact contacts;
// - shear strain and velocity of a prescribed top layer over a fixed bottom layer.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_analysis {

namespace {

using sphere::vec3;
using sphere::vec4;
constexpr double pi = 3.14159265358979323846;

double ball_volume(double r) { return 4.0 / 3.0 * pi * r * r * r; }

/// Independent reference for sphere_box_volume: the midpoint rule on an n x n grid over the
/// box's footprint in x-y, integrating the length of the sphere's vertical chord inside
/// [lo.z, hi.z]. The chord has a square-root edge at the sphere's outline, so the error falls
/// as n^-1.5: ~1e-5 of the ball's volume at n = 1500.
double midpoint_volume(const vec3<double>& c, double r, const vec3<double>& lo, const vec3<double>& hi, int n)
{
    const double x0 = std::max(lo.x, c.x - r), x1 = std::min(hi.x, c.x + r);
    const double y0 = std::max(lo.y, c.y - r), y1 = std::min(hi.y, c.y + r);
    if (!(x1 > x0 && y1 > y0)) return 0;
    const double dx = (x1 - x0) / n, dy = (y1 - y0) / n;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
        const double x = x0 + (i + 0.5) * dx - c.x;
        for (int j = 0; j < n; ++j) {
            const double y = y0 + (j + 0.5) * dy - c.y;
            const double h2 = r * r - x * x - y * y;
            if (h2 <= 0) continue;
            const double h = std::sqrt(h2);
            const double len = std::min(hi.z, c.z + h) - std::max(lo.z, c.z - h);
            if (len > 0) sum += len;
        }
    }
    return sum * dx * dy;
}

/// Solid volume of a sphere (centre zc, radius r) between heights z0 and z1: the integral of
/// the disk area pi (r^2 - (z - zc)^2) over the overlap of [z0, z1] and [zc - r, zc + r].
double slab_volume(double zc, double r, double z0, double z1)
{
    const double a = std::max(z0, zc - r), b = std::min(z1, zc + r);
    if (!(b > a)) return 0;
    auto F = [&](double z) { return pi * (r * r * (z - zc) - (z - zc) * (z - zc) * (z - zc) / 3); };
    return F(b) - F(a);
}

/// x (centre, radius) of particles on an nx x ny x nz cubic lattice of spacing 2r.
template <class Real>
std::vector<vec4<Real>> lattice_x(std::size_t nx, std::size_t ny, std::size_t nz, Real r, vec3<Real> origin = {0, 0, 0})
{
    std::vector<vec4<Real>> x;
    for (const vec3<Real>& c : sphere::cubic_lattice(nx, ny, nz, Real(2) * r, origin)) x.push_back({c.x, c.y, c.z, r});
    return x;
}

/// Round-off allowance for porosities of Real positions: positions rounded to Real move each
/// cut sphere's volume by ~eps r / r of itself; 1e-12 in double, 2e-6 in float.
template <class Real>
double porosity_tolerance()
{
    return sizeof(Real) == sizeof(double) ? 1e-12 : 2e-6;
}

} // namespace

TEST_CASE("sphere_box_volume: halves, quarters, octants and caps in closed form", "[analysis][porosity]")
{
    const double inf = HUGE_VAL, r = 0.7;
    const vec3<double> c{0.3, -0.2, 0.1};
    const double V = ball_volume(r);
    auto vol = [&](vec3<double> lo, vec3<double> hi) { return sphere::sphere_box_volume(c, r, lo, hi); };
    // Round-off of a few operations on O(r^3) terms: 1e-14 of V.
    const double tol = 1e-14 * V;
    CHECK(std::abs(vol({-inf, -inf, -inf}, {inf, inf, inf}) - V) < tol);
    CHECK(std::abs(vol({-10, -10, -10}, {10, 10, 10}) - V) < tol);
    CHECK(std::abs(vol({c.x, -inf, -inf}, {inf, inf, inf}) - V / 2) < tol);
    CHECK(std::abs(vol({-inf, -inf, -inf}, {inf, c.y, inf}) - V / 2) < tol);
    CHECK(std::abs(vol({c.x, c.y, -inf}, {inf, inf, inf}) - V / 4) < tol);
    CHECK(std::abs(vol({-inf, -inf, c.z}, {c.x, inf, inf}) - V / 4) < tol);
    CHECK(std::abs(vol({c.x, c.y, c.z}, {inf, inf, inf}) - V / 8) < tol);
    CHECK(std::abs(vol({-inf, -inf, -inf}, {c.x, c.y, c.z}) - V / 8) < tol);
    // A cap of height h on each side and axis: pi h^2 (3 r - h) / 3.
    for (double h : {0.01, 0.2, 0.7, 1.1, 1.39}) {
        const double cap = pi * h * h * (3 * r - h) / 3;
        CHECK(std::abs(vol({-inf, -inf, c.z + r - h}, {inf, inf, inf}) - cap) < tol);
        CHECK(std::abs(vol({-inf, -inf, -inf}, {c.x - r + h, inf, inf}) - cap) < tol);
    }
    // Outside, touching from outside, or an empty box: nothing.
    CHECK(vol({c.x + r, -inf, -inf}, {inf, inf, inf}) == 0);
    CHECK(vol({0, 0, 0}, {0, 1, 1}) == 0);
    CHECK(vol({5, 5, 5}, {6, 6, 6}) == 0);
}

TEST_CASE("sphere_box_volume: boxes that partition space add up to the ball", "[analysis][porosity]")
{
    // Random cuts through the ball on every axis make 5 x 5 x 5 boxes (the outer ones
    // unbounded); their volumes must add up to the ball's, whatever corners, wedges and caps
    // each one cuts off. Tolerance: round-off of 125 terms, 1e-13 of V.
    std::mt19937_64 gen(11);
    std::uniform_real_distribution<double> u(-1, 1);
    const double r = 1.3;
    for (int trial = 0; trial < 20; ++trial) {
        const vec3<double> c{u(gen), u(gen), u(gen)};
        std::vector<double> cuts[3];
        for (int a = 0; a < 3; ++a) {
            cuts[a] = {-HUGE_VAL, HUGE_VAL};
            for (int k = 0; k < 4; ++k) cuts[a].push_back(c[a] + r * 1.05 * u(gen));
            std::sort(cuts[a].begin(), cuts[a].end());
        }
        double sum = 0;
        for (int i = 0; i < 5; ++i)
            for (int j = 0; j < 5; ++j)
                for (int k = 0; k < 5; ++k)
                    sum += sphere::sphere_box_volume(c, r, {cuts[0][i], cuts[1][j], cuts[2][k]},
                                                     {cuts[0][i + 1], cuts[1][j + 1], cuts[2][k + 1]});
        CHECK(std::abs(sum - ball_volume(r)) < 1e-13 * ball_volume(r));
    }
}

TEST_CASE("sphere_box_volume agrees with an independent quadrature for random boxes", "[analysis][porosity]")
{
    // Boxes that cut the sphere on up to six faces (corners, edges, both sides of an axis).
    // Midpoint quadrature at n = 1500 is within ~1e-5 V of the truth (its error falls as
    // n^-1.5 from the chord's square-root edge); allow 5e-5 V.
    std::mt19937_64 gen(5);
    std::uniform_real_distribution<double> u(0, 1);
    const double r = 1.0, V = ball_volume(r);
    for (int trial = 0; trial < 12; ++trial) {
        const vec3<double> c{0, 0, 0};
        vec3<double> lo, hi;
        for (int a = 0; a < 3; ++a) {
            lo[a] = -1.3 + 1.5 * u(gen);
            hi[a] = lo[a] + 0.3 + 1.6 * u(gen);
        }
        const double exact = sphere::sphere_box_volume(c, r, lo, hi);
        const double reference = midpoint_volume(c, r, lo, hi, 1500);
        INFO("box [" << lo.x << ", " << hi.x << "] x [" << lo.y << ", " << hi.y << "] x [" << lo.z << ", " << hi.z
                     << "]: exact " << exact << ", quadrature " << reference);
        CHECK(std::abs(exact - reference) < 5e-5 * V);
    }
}

TEMPLATE_TEST_CASE("porosity of a simple cubic lattice is 1 - pi/6 for any box spanning whole periods",
                   "[analysis][porosity]", float, double)
{
    using Real = TestType;
    const Real r = Real(0.01), a = 2 * r;
    const double phi = 1 - pi / 6, tol = porosity_tolerance<Real>();
    const std::vector<vec4<Real>> x = lattice_x<Real>(5, 4, 6, r);

    // Between the walls of a closed box that the lattice fills exactly.
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    box.hi = {5 * a, 4 * a, 6 * a};
    const sphere::wall_set<Real> walls = sphere::wall_set<Real>::from_world(box);
    const sphere::porosity_result bulk = sphere::bulk_porosity(x, box, walls);
    CHECK(std::abs(bulk.porosity - phi) < tol);
    // Void ratio e = phi / (1 - phi) = 6 / pi - 1.
    CHECK(std::abs(bulk.void_ratio - (6 / pi - 1)) < 4 * tol);
    CHECK(std::abs(sphere::void_ratio(bulk.porosity) - bulk.porosity / (1 - bulk.porosity)) < 1e-15);
    CHECK(bulk.volume == Approx(double(box.hi.x) * double(box.hi.y) * double(box.hi.z)).epsilon(1e-12));

    // Boxes of 3 x 2 x 4 and 2 x 2 x 2 periods inside the lattice, offset so that their faces
    // cut the spheres off-centre: every face cuts the same total, so the fraction is exact.
    for (const vec3<double>& offset : {vec3<double>{0.3, 0.7, 0.45}, vec3<double>{0.91, 0.5, 1.13}}) {
        const vec3<double> lo{offset.x * double(a), offset.y * double(a), offset.z * double(a)};
        for (const vec3<double>& periods : {vec3<double>{3, 2, 4}, vec3<double>{2, 2, 2}}) {
            const vec3<double> hi{lo.x + periods.x * double(a), lo.y + periods.y * double(a), lo.z + periods.z * double(a)};
            const sphere::porosity_result p = sphere::porosity_in_box(x, box, lo, hi);
            INFO("offset " << offset.x << " " << offset.y << " " << offset.z);
            CHECK(std::abs(p.porosity - phi) < tol);
        }
    }

    // The same lattice in a simulation: bulk_porosity(sim) between its walls.
    sphere::settings<Real> s = sphere_test::box_settings<Real>();
    s.box = box;
    std::vector<sphere::particle<Real>> ps;
    for (const vec4<Real>& p : x) ps.push_back(sphere_test::ball<Real>({p.x, p.y, p.z}, {0, 0, 0}, r));
    sphere::simulation<Real> sim(s, ps);
    CHECK(std::abs(sphere::bulk_porosity(sim).porosity - phi) < tol);
}

TEMPLATE_TEST_CASE("porosity across periodic boundaries counts the particles' images", "[analysis][porosity]", float,
                   double)
{
    using Real = TestType;
    const Real r = Real(0.01), a = 2 * r;
    const double phi = 1 - pi / 6, tol = porosity_tolerance<Real>();
    // A 4 x 4 x 3 lattice shifted by a third of a period along x and y, wrapped into a world
    // periodic on x and y: the spheres near the x and y faces straddle the boundary.
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    box.hi = {4 * a, 4 * a, 3 * a};
    box.axis[0] = box.axis[1] = sphere::boundary::periodic;
    std::vector<vec4<Real>> x = lattice_x<Real>(4, 4, 3, r, {a / 3, a / 3, 0});
    for (vec4<Real>& p : x) {
        p.x = box.wrap(p.x, 0);
        p.y = box.wrap(p.y, 1);
    }
    const sphere::wall_set<Real> walls = sphere::wall_set<Real>::from_world(box);
    CHECK(std::abs(sphere::bulk_porosity(x, box, walls).porosity - phi) < tol);
    // A sub-box of 2 x 3 x 2 periods that wraps nothing but cuts spheres whose centres lie on
    // the far side of the periodic boundary (their images reach into it).
    const vec3<double> lo{0.1 * double(a), 0.05 * double(a), 0.5 * double(a)};
    const vec3<double> hi{lo.x + 2 * double(a), lo.y + 3 * double(a), lo.z + 2 * double(a)};
    CHECK(std::abs(sphere::porosity_in_box(x, box, lo, hi).porosity - phi) < tol);
    // A region beyond the period is refused.
    CHECK_THROWS_WITH(sphere::porosity_in_box(x, box, {-0.01, 0, 0}, {0.05, 0.05, 0.05}),
                      Catch::Contains("beyond the period"));
}

TEMPLATE_TEST_CASE("porosity profile of a lattice matches the integrated disk areas slice by slice",
                   "[analysis][porosity]", float, double)
{
    using Real = TestType;
    const Real r = Real(0.01), a = 2 * r;
    const std::size_t nx = 3, ny = 4, nz = 3;
    const std::vector<vec4<Real>> x = lattice_x<Real>(nx, ny, nz, r);
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    box.hi = {Real(nx) * a, Real(ny) * a, Real(nz) * a};
    // 7 slices: they do not line up with the layers, so most cut spheres off-centre.
    const std::size_t slices = 7;
    const vec3<double> lo{0, 0, 0}, hi{double(box.hi.x), double(box.hi.y), double(box.hi.z)};
    const std::vector<sphere::porosity_slice> profile = sphere::porosity_profile(x, box, lo, hi, slices);
    REQUIRE(profile.size() == slices);
    const double area = hi.x * hi.y, h = hi.z / slices;
    for (std::size_t k = 0; k < slices; ++k) {
        const double z0 = k * h, z1 = (k + 1) * h;
        double solid = 0; // every layer's nx ny spheres, centred at (m + 1/2) a
        for (std::size_t m = 0; m < nz; ++m) solid += double(nx * ny) * slab_volume((m + 0.5) * double(a), double(r), z0, z1);
        const double expected = 1 - solid / (area * h);
        INFO("slice " << k << " [" << z0 << ", " << z1 << "] m");
        CHECK(std::abs(profile[k].z_lo - z0) < 1e-12);
        CHECK(std::abs(profile[k].porosity - expected) < 5 * porosity_tolerance<Real>());
    }
    CHECK_THROWS_WITH(sphere::porosity_profile(x, box, lo, hi, 0), Catch::Contains("slices = 0"));
}

namespace {

/// The column of the Love-Weber and coordination tests: a simple cubic lattice of 4 x 4 x nz
/// particles of set P (R = 0.01 m, k_n = 1e5 N/m), spacing 2R vertically and 2R - delta_x
/// sideways (periodic x and y: every lateral pair overlaps by delta_x = 2e-5 m, 2 N), a fixed
/// floor at z = 0 and an upper wall at the lattice's top, controlled at sigma0 = 1e4 Pa, no
/// gravity. The wall pushes the column down until each of the 16 columns carries
/// sigma0 A / 16 ~ 4 N, 4e-5 m per contact (D10).
///
/// Damping ratio 0.3 in the normal dashpots, friction 0.5 with tangential springs and no
/// tangential dashpot, a wall of a fifth of a layer's mass: after 0.5 s the column is static,
/// every particle's net force below 1e-3 of a contact force (in float some particles keep
/// velocities of ~3e-4 m/s whose steps, v dt ~ 6e-9 m, round away at positions ~0.1 m: a
/// kinetic energy floor of ~2e-8 J, 1e-6 of the wall's work). The lateral contacts' tangential springs keep the lattice from
/// buckling: without friction a sideways shift of a layer is resisted by nothing. (A
/// tangential dashpot as strong as the normal one, gamma_t dt (1/m + R^2/I) summed over six
/// contacts above 2, was found to be unstable: the explicit dashpot also drives the spins.)
template <class Real>
struct column {
    static constexpr std::size_t nz = 10, per_layer = 16;
    static constexpr double R = 0.01, k_n = 1e5, delta_x = 2e-5, sigma0 = 1e4;
    sphere::simulation<Real> sim;
    double kinetic = 0, wall_speed = 0, work = 0, max_force = 0;

    static sphere::settings<Real> settings()
    {
        sphere::settings<Real> s = sphere_test::box_settings<Real>();
        const double lateral = 2 * R - delta_x;
        s.box.lo = {0, 0, 0};
        s.box.hi = {Real(4 * lateral), Real(4 * lateral), Real(nz * 2 * R)};
        s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
        const double m = sphere_test::set_p<double>::mass();
        s.contact.gamma_n = Real(2 * 0.3 * std::sqrt(m / 2 * k_n)); // damping ratio 0.3, m* = m / 2
        s.contact.mu_s = s.contact.mu_d = Real(0.5);
        s.wall = s.contact;
        s.wall.gamma_n = Real(2 * 0.3 * std::sqrt(m * k_n));
        s.walls[5].mode = sphere::wall_mode::stress;
        s.walls[5].stress = Real(sigma0);
        s.walls[5].mass = Real(0.2 * per_layer * m);
        return s;
    }

    static std::vector<sphere::particle<Real>> particles()
    {
        const double lateral = 2 * R - delta_x;
        std::vector<sphere::particle<Real>> ps;
        for (const vec3<Real>& c :
             sphere::cubic_lattice(4, 4, nz, vec3<Real>{Real(lateral), Real(lateral), Real(2 * R)}))
            ps.push_back(sphere_test::ball<Real>(c, {0, 0, 0}, Real(R)));
        return ps;
    }

    column() : sim(settings(), particles())
    {
        sim.run(static_cast<std::size_t>(0.5 / double(sim.dt())));
        const auto e = sim.energy();
        kinetic = double(e.kinetic) + double(e.rotational);
        wall_speed = std::abs(double(sim.walls().face[5].velocity));
        // The work the wall did on the way down, sigma0 A (11 x 4e-5 m) ~ 2.8e-2 J.
        work = sigma0 * sphere::wall_area(sim.walls(), sim.config().box, 5) * 4.4e-4;
        const sphere::particle_snapshot<Real> snap = sim.snapshot();
        for (const vec3<Real>& f : snap.force) max_force = std::max(max_force, std::sqrt(double(norm2(f))));
    }

    /// Static: every particle's net force below 1e-3 of the 4 N a vertical contact carries,
    /// and the kinetic energy below 1e-5 of the wall's work.
    bool at_rest() const { return max_force < 4e-3 && kinetic < 1e-5 * work; }
};

} // namespace

TEMPLATE_TEST_CASE("Love-Weber stress of a static compressed column equals the wall stress",
                   "[analysis][stress]", float, double)
{
    using Real = TestType;
    using C = column<Real>;
    C col;
    INFO("after " << col.sim.time() << " s (" << col.sim.steps() << " steps): kinetic " << col.kinetic
                  << " J (wall work " << col.work << " J), wall speed " << col.wall_speed
                  << " m/s, largest net force " << col.max_force << " N");
    REQUIRE(col.at_rest());

    // The upper wall holds its target, and the floor carries the same stress (no gravity):
    // static, so within 0.1% (measured 2e-5 in double, 2e-4 in float).
    const double top = sphere::wall_normal_stress(col.sim, 5), floor = sphere::wall_normal_stress(col.sim, 4);
    CHECK(std::abs(top - C::sigma0) < 1e-3 * C::sigma0);
    CHECK(std::abs(floor - top) < 1e-3 * C::sigma0);

    const sphere::stress_tensor s = sphere::love_weber_stress(col.sim);
    INFO("Love-Weber: zz " << s(2, 2) << ", xx " << s(0, 0) << ", yy " << s(1, 1) << ", xy " << s(0, 1) << ", xz "
                           << s(0, 2) << ", yz " << s(1, 2) << " Pa; wall " << top << " Pa");
    // sigma_zz = sum f_z l_z / V: in equilibrium the pair and wall terms of each column add up
    // to its force times the wall distance, so sigma_zz = F / A exactly; allow the 2% of the
    // issue (measured ~1e-6).
    CHECK(std::abs(s(2, 2) - top) < 0.02 * top);
    // Lateral: every particle has one +x and one +y contact at k_n delta_x over a branch of
    // 2R - delta_x, so sigma_xx = N k_n delta_x (2R - delta_x) / V; within 1% (delta_x is
    // fixed by the periodic lattice; float resolves it to ~1e-3).
    const double N = double(C::per_layer * C::nz);
    const double V = sphere::volume_between_walls(col.sim.walls(), col.sim.config().box);
    const double lateral = N * C::k_n * C::delta_x * (2 * C::R - C::delta_x) / V;
    CHECK(std::abs(s(0, 0) - lateral) < 0.01 * lateral);
    CHECK(std::abs(s(1, 1) - lateral) < 0.01 * lateral);
    // Forces act along the lattice axes: off-diagonal terms vanish up to the residual motion
    // and round-off (< 1e-3 of sigma_zz).
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (i != j) CHECK(std::abs(s(i, j)) < 1e-3 * s(2, 2));
    CHECK(s.mean() == Approx((s(0, 0) + s(1, 1) + s(2, 2)) / 3));
}

TEMPLATE_TEST_CASE("coordination number and contact network of a compressed simple cubic lattice",
                   "[analysis][stress]", float, double)
{
    using Real = TestType;
    using C = column<Real>;
    C col;
    REQUIRE(col.at_rest());
    const sphere::contact_snapshot<Real> c = sphere::take_contact_snapshot(col.sim);
    const std::size_t N = c.size();

    // Every particle touches its 4 lateral neighbours and the ones above and below: 6 in the
    // interior layers, 5 in the bottom and top layers, which touch a wall instead (exactly).
    const std::vector<unsigned> z = sphere::contact_counts(c), zw = sphere::contact_counts(c, true);
    std::size_t interior = 0;
    for (std::size_t i = 0; i < N; ++i) {
        const std::size_t layer = i / C::per_layer;
        const bool boundary = layer == 0 || layer == C::nz - 1;
        CHECK(z[i] == (boundary ? 5u : 6u));
        CHECK(zw[i] == 6u);
        interior += boundary ? 0 : 1;
    }
    CHECK(interior == (C::nz - 2) * C::per_layer);
    // Mean over all particles: (6 N - 2 per_layer) / N = 6 - 2 / nz; with walls 6.
    CHECK(sphere::mean_coordination(c) == Approx(6.0 - 2.0 / C::nz).epsilon(1e-12));
    CHECK(sphere::mean_coordination(col.sim, true) == Approx(6.0).epsilon(1e-12));

    // The network: 2 lateral pairs per particle and per_layer (nz - 1) vertical pairs, each
    // once with i < j. Vertical pairs carry the wall force per column, lateral ones
    // k_n delta_x = 2 N (within 0.5%: static; float resolves the overlaps to ~1e-3), and no
    // tangential force (the lattice is symmetric: < 1e-6 of the normal force).
    const std::vector<sphere::contact_force> net = sphere::contact_network(c);
    CHECK(net.size() == 2 * N + C::per_layer * (C::nz - 1));
    const double column_force = double(col.sim.walls().face[5].force) / C::per_layer;
    std::size_t vertical = 0;
    for (const sphere::contact_force& f : net) {
        CHECK(f.i < f.j);
        const bool is_vertical = std::abs(f.branch.z) > C::R;
        vertical += is_vertical ? 1 : 0;
        const double expected = is_vertical ? column_force : C::k_n * C::delta_x;
        CHECK(std::abs(f.normal - expected) < 5e-3 * expected);
        CHECK(std::sqrt(f.tangential.x * f.tangential.x + f.tangential.y * f.tangential.y +
                        f.tangential.z * f.tangential.z) < 1e-6 * f.normal);
        // The branch is the nearest image: length 2R less the overlap, within 1e-3 R.
        const double len = std::sqrt(f.branch.x * f.branch.x + f.branch.y * f.branch.y + f.branch.z * f.branch.z);
        CHECK(std::abs(len - (2 * C::R - f.normal / C::k_n)) < 1e-3 * C::R);
    }
    CHECK(vertical == C::per_layer * (C::nz - 1));
}

TEMPLATE_TEST_CASE("shear strain and velocity of a prescribed top layer over a fixed bottom layer",
                   "[analysis][shear]", float, double)
{
    using Real = TestType;
    // Four fixed particles at z = 0.02 m and four prescribed ones at z = 0.07 m moving at
    // 0.5 m/s along x through a periodic x of 0.1 m; none touch. After 0.8 s the top layer has
    // moved 0.4 m = 4 periods: strain 0.4 / 0.05 = 8.
    sphere::settings<Real> s = sphere_test::box_settings<Real>();
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(0.1), Real(0.1), Real(0.1)};
    s.box.axis[0] = sphere::boundary::periodic;
    std::vector<sphere::particle<Real>> ps;
    const double v = 0.5, h = 0.05;
    for (int k = 0; k < 4; ++k) {
        sphere::particle<Real> bottom = sphere_test::ball<Real>({Real(0.01 + 0.025 * k), Real(0.05), Real(0.02)});
        bottom.kind = sphere::motion::fixed;
        sphere::particle<Real> top =
            sphere_test::ball<Real>({Real(0.0125 + 0.025 * k), Real(0.05), Real(0.02 + h)}, {Real(v), 0, 0});
        top.kind = sphere::motion::prescribed;
        ps.push_back(bottom);
        ps.push_back(top);
    }
    sphere::simulation<Real> sim(s, ps);
    sphere::shear_tracker<Real> tracker(sim);
    CHECK(tracker.layers().top.size() == 4);
    CHECK(tracker.layers().bottom.size() == 4);
    CHECK(tracker.strain() == 0);
    // Updates every 100 steps: the layer moves 1.2e-3 m between them, far below half a period.
    while (sim.time() < 0.8) {
        sim.run(100);
        tracker.update(sim);
    }
    const double moved = v * sim.time();
    // Double: exact to round-off (1e-9). Float: each step adds v dt to a float position, whose
    // rounding (6e-9 m at 0.1 m) accumulates over 33000 steps to < 2e-4 m: 1e-3 relative.
    const double tol = sizeof(Real) == sizeof(double) ? 1e-9 : 1e-3;
    CHECK(std::abs(tracker.displacement() - moved) < tol * moved);
    CHECK(std::abs(tracker.height() - h) < 1e-6);
    CHECK(std::abs(tracker.strain() - moved / h) < 2 * tol * moved / h + 1e-5);
    CHECK(tracker.velocity() == Approx(v).epsilon(1e-6));
    CHECK(tracker.strain_rate() == Approx(v / h).epsilon(1e-5));

    // Without prescribed or fixed particles there is no shear experiment.
    std::vector<sphere::particle<Real>> free_only{sphere_test::ball<Real>({Real(0.05), Real(0.05), Real(0.05)})};
    sphere::simulation<Real> plain(s, free_only);
    CHECK_THROWS_WITH(sphere::shear_tracker<Real>(plain), Catch::Contains("needs both"));
}

TEMPLATE_TEST_CASE("Love-Weber counts the friction of wall contacts", "[analysis][stress]", float, double)
{
    using Real = TestType;
    // One set-P sphere pressed 1e-4 m into the floor (f_n = k_n 1e-4 = 10 N, undamped) and
    // dragged along x at 0.1 m/s: the floor's viscous friction (gamma_t 0.1 m/s = 10 N) is
    // capped at mu f_n = 3 N against the motion. Both act at the contact point, l = r - 1e-4
    // below the centre: sigma_ab = -(1/V) f_a l_b with f = (-mu f_n, 0, f_n), l = (0, 0, -l),
    // so sigma_zz = f_n l / V and sigma_xz = -mu f_n l / V.
    const Real R = sphere_test::set_p<Real>::radius;
    sphere::settings<Real> s = sphere_test::box_settings<Real>();
    s.wall.gamma_t = Real(100);
    s.wall.mu_s = s.wall.mu_d = Real(0.3);
    sphere::particle<Real> p = sphere_test::ball<Real>({0, 0, Real(-0.1) + R - Real(1e-4)}, {Real(0.1), 0, 0});
    p.kind = sphere::motion::prescribed;
    sphere::simulation<Real> sim(s, {p});
    sim.step();
    const double volume = 0.2 * 0.2 * 0.2;
    const sphere::stress_tensor t = sphere::love_weber_stress(sim, volume);
    const double l = double(R) - 1e-4, fn = 1e5 * 1e-4;
    const double tol = std::is_same<Real, float>::value ? 1e-4 : 1e-9;
    CHECK(t.s[2][2] == Approx(fn * l / volume).epsilon(tol));
    CHECK(t.s[0][2] == Approx(-0.3 * fn * l / volume).epsilon(tol));
    CHECK(t.s[2][0] == 0); // the branch vector has no x component
    CHECK(t.s[0][0] == 0);
}

} // namespace test_analysis
