// The fluid grid and the porosity estimator (include/sphere/fluid/grid.cuh, lens.cuh,
// porosity.cuh; docs/fluid.md):
// - F1 of ../shared/VALIDATION.md: lens volumes of every row against an independent two-cap
//   formula, the table's printed digits, exact values at both switches, continuity across
//   them, monotonicity and symmetry in the two radii (and pitfall 6, a cell sphere inside a
//   particle);
// - F2: the porosity of a cell around one centred particle and of simple cubic lattices for
//   cells on a void and on a particle, two cell widths, with walls and across periodic
//   boundaries;
// - the lens-weighted particle velocity and diameter, dphi/dt by backward Euler, the cell
//   sphere of non-cubic cells, the binned particle search against a brute-force sum (these for
//   the seeds' cell-sphere estimator, porosity_method::cell_sphere);
// - porosity_method::cell_volume (the default): against a brute-force sum, the grid's and each
//   layer's solid volume conserved exactly (with particles across faces, periodic boundaries
//   and walls), a lattice's porosity wherever it sits, rates that sum to zero;
// - the grid's index spaces and the errors for bad input.
#include <catch2/catch.hpp>

#include <sphere/fluid.cuh>

#include <cmath>
#include <cstddef>
#include <limits>
#include <random>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_fluid_porosity {

namespace {

using sphere::vec3;
using sphere::vec4;
constexpr double pi = 3.14159265358979323846;

/// Independent reference for lens_volume (long double): the intersection as the sum of the two
/// caps cut off by the plane of the spheres' intersection circle, at distance
/// a = (d^2 + R^2 - r^2) / (2 d) from the centre of the R sphere; a cap of height h of a sphere
/// of radius rho has volume pi h^2 (3 rho - h) / 3.
long double two_caps(long double R, long double r, long double d)
{
    const long double p = 3.14159265358979323846264338327950288L;
    if (d >= R + r) return 0;
    if (d <= std::fabs(R - r)) {
        const long double m = R < r ? R : r;
        return 4 * p * m * m * m / 3;
    }
    const long double a = (d * d + R * R - r * r) / (2 * d);
    const long double hR = R - a, hr = r - (d - a);
    return p * hR * hR * (3 * R - hR) / 3 + p * hr * hr * (3 * r - hr) / 3;
}

template <class Real>
double lens_tolerance()
{
    return sizeof(Real) == sizeof(double) ? 1e-12 : 1e-5;
}

/// F2 tolerance on porosities (VALIDATION.md).
template <class Real>
double f2_tolerance()
{
    return sizeof(Real) == sizeof(double) ? 1e-6 : 1e-4;
}

template <class Real>
sphere::world<Real> make_box(vec3<Real> lo, vec3<Real> hi, bool px = false, bool py = false, bool pz = false)
{
    sphere::world<Real> box;
    box.lo = lo;
    box.hi = hi;
    box.axis[0] = px ? sphere::boundary::periodic : sphere::boundary::wall;
    box.axis[1] = py ? sphere::boundary::periodic : sphere::boundary::wall;
    box.axis[2] = pz ? sphere::boundary::periodic : sphere::boundary::wall;
    return box;
}

/// A snapshot holding only what the estimator reads: positions with radii, and velocities.
template <class Real>
sphere::particle_snapshot<Real> snapshot_of(const std::vector<vec4<Real>>& x, std::vector<vec3<Real>> v = {})
{
    sphere::particle_snapshot<Real> s;
    s.x = x;
    if (v.empty()) v.assign(x.size(), vec3<Real>{0, 0, 0});
    s.v_sync = v;
    return s;
}

/// Spheres of radius r on the integer points plus `offset` (a simple cubic lattice of spacing
/// 1) whose centres lie in [lo, hi) on every axis.
template <class Real>
std::vector<vec4<Real>> unit_lattice(double lo, double hi, double offset, double r)
{
    std::vector<vec4<Real>> x;
    const int first = static_cast<int>(std::ceil(lo - offset)), last = static_cast<int>(std::ceil(hi - offset)) - 1;
    for (int k = first; k <= last; ++k)
        for (int j = first; j <= last; ++j)
            for (int i = first; i <= last; ++i)
                x.push_back({Real(i + offset), Real(j + offset), Real(k + offset), Real(r)});
    return x;
}

} // namespace

TEMPLATE_TEST_CASE("lens_volume: F1 rows against two caps and the table", "[fluid][porosity]", float, double)
{
    using Real = TestType;
    struct row {
        double r, d, table;
    };
    // VALIDATION.md F1, R = 1. The table prints 6 decimals, so it is checked to half a unit of
    // the last one; the 1e-12 / 1e-5 tolerance applies against the exact two-cap value.
    const row rows[] = {{0.5, 0.3, 0.523599}, {0.5, 0.6, 0.498335}, {0.5, 1.0, 0.212712}, {0.5, 1.4, 0.010117},
                        {0.5, 1.6, 0.0},      {1.0, 1.0, 1.308997}, {2.0, 0.5, 4.188790}, {2.0, 1.5, 3.239767}};
    for (const row& w : rows) {
        const double exact = static_cast<double>(two_caps(1.0L, w.r, w.d));
        const double V = static_cast<double>(sphere::lens_volume<Real>(Real(1), Real(w.r), Real(w.d)));
        INFO("r = " << w.r << ", d = " << w.d << ": lens_volume " << V << ", two caps " << exact);
        CHECK(std::abs(exact - w.table) <= 5e-7);
        if (exact == 0) {
            CHECK(V == 0);
        } else {
            CHECK(std::abs(V - exact) <= lens_tolerance<Real>() * exact);
        }
    }
    // Pitfall 6: a cell sphere (R = 1) inside a particle (r = 2, d = 0.5) shares its own whole
    // volume. The seed's lens formula would give pi 6.25 * 0.25 / 6 = 0.818 here.
    CHECK(sphere::lens_volume<Real>(1, 2, Real(0.5)) == sphere::sphere_volume<Real>(1));
    // Many random (R, r, d) against the two caps.
    std::mt19937_64 gen(4);
    std::uniform_real_distribution<double> u(0.05, 2);
    for (int trial = 0; trial < 2000; ++trial) {
        const Real R = Real(u(gen)), r = Real(u(gen)), d = Real(u(gen) * 1.5);
        const double exact = static_cast<double>(two_caps(R, r, d));
        const double V = static_cast<double>(sphere::lens_volume(R, r, d));
        INFO("R = " << R << ", r = " << r << ", d = " << d);
        if (exact == 0) {
            CHECK(V == 0);
        } else {
            // Near a switch the caps themselves lose digits; compare against the scale of the
            // smaller sphere there.
            const double m = R < r ? R : r;
            CHECK(std::abs(V - exact) <= lens_tolerance<Real>() * 4.0 / 3.0 * pi * m * m * m);
        }
    }
}

TEMPLATE_TEST_CASE("lens_volume: exact at both switches, continuous across them, monotone and symmetric",
                   "[fluid][porosity]", float, double)
{
    using Real = TestType;
    const double eps = std::numeric_limits<Real>::epsilon();
    const Real pairs[][2] = {{1, Real(0.5)}, {1, 2}, {Real(0.3), Real(0.3)}, {1, Real(0.2)}, {Real(0.7), Real(1.9)}};
    for (const auto& pr : pairs) {
        const Real R = pr[0], r = pr[1];
        const Real small = R < r ? R : r;
        const Real inner = R < r ? r - R : R - r, outer = R + r;
        const double scale = 4.0 / 3.0 * pi * double(small) * small * small;
        INFO("R = " << R << ", r = " << r);
        // Both ends exactly: nothing when touching from outside, the smaller sphere when
        // touching from inside (and at any closer distance).
        CHECK(sphere::lens_volume(R, r, outer) == Real(0));
        CHECK(sphere::lens_volume(R, r, outer * 2) == Real(0));
        CHECK(sphere::lens_volume(R, r, inner) == sphere::sphere_volume(small));
        CHECK(sphere::lens_volume(R, r, Real(0)) == sphere::sphere_volume(small));
        CHECK(sphere::lens_volume(R, r, inner / 2) == sphere::sphere_volume(small));
        // Just inside and just outside each switch (a few ulps away) agree to O(epsilon) of the
        // smaller sphere's volume.
        for (int ulps : {1, 4, 64}) {
            Real in = outer, out = outer;
            for (int s = 0; s < ulps; ++s) {
                in = std::nextafter(in, Real(0));
                out = std::nextafter(out, Real(10));
            }
            CHECK(sphere::lens_volume(R, r, out) == Real(0));
            CHECK(double(sphere::lens_volume(R, r, in)) <= 16 * eps * scale);
            Real a = inner, b = inner;
            for (int s = 0; s < ulps; ++s) {
                a = std::nextafter(a, Real(0));
                b = std::nextafter(b, Real(10));
            }
            CHECK(std::abs(double(sphere::lens_volume(R, r, b)) - double(sphere::lens_volume(R, r, a))) <=
                  16 * eps * scale);
        }
        // Non-increasing in d across both switches, and symmetric in the radii to the last bit
        // (R + r and (R - r)^2 do not depend on the order).
        Real previous = sphere::lens_volume(R, r, Real(0));
        for (int s = 1; s <= 1000; ++s) {
            const Real d = Real(s) * (outer * Real(1.1)) / Real(1000);
            const Real V = sphere::lens_volume(R, r, d);
            CHECK(V <= previous + Real(4 * eps * scale));
            CHECK(V == sphere::lens_volume(r, R, d));
            previous = V;
        }
    }
}

TEMPLATE_TEST_CASE("fluid_grid: cells, centres, widths and the ghost-node layout", "[fluid][porosity]", float,
                   double)
{
    using Real = TestType;
    const auto box = make_box<Real>({-1, 0, 2}, {3, 1, 5});
    const auto g = sphere::fluid_grid<Real>::make(box, 4, 2, 6);
    CHECK(g.n[0] == 4);
    CHECK(g.n[1] == 2);
    CHECK(g.n[2] == 6);
    CHECK(g.width.x == Real(1));
    CHECK(g.width.y == Real(0.5));
    CHECK(g.width.z == Real(0.5));
    CHECK(g.min_width() == Real(0.5));
    CHECK(g.cell_count() == 48);
    CHECK(g.field_size() == 6 * 4 * 8);
    const vec3<Real> c = g.centre(2, 1, 3);
    CHECK(c.x == Real(1.5));
    CHECK(c.y == Real(0.75));
    CHECK(c.z == Real(3.75));
    // Ghost centres lie half a cell outside the box.
    CHECK(g.centre(-1, 0, 0).x == Real(-1.5));
    CHECK(g.centre(0, 0, 6).z == Real(5.25));
    // index and coordinates are inverse; x runs fastest.
    CHECK(g.index(1, 0, 0) == 1);
    CHECK(g.index(0, 1, 0) == 4);
    CHECK(g.index(0, 0, 1) == 8);
    for (std::size_t cell = 0; cell < g.cell_count(); ++cell) {
        int i, j, k;
        g.coordinates(cell, i, j, k);
        CHECK(g.index(i, j, k) == cell);
    }
    // field_index maps [-1, n] on every axis one-to-one onto [0, field_size()), x fastest.
    std::vector<int> seen(g.field_size(), 0);
    for (int k = -1; k <= 6; ++k)
        for (int j = -1; j <= 2; ++j)
            for (int i = -1; i <= 4; ++i) {
                const std::size_t f = g.field_index(i, j, k);
                REQUIRE(f < g.field_size());
                ++seen[f];
            }
    for (int s : seen) CHECK(s == 1);
    CHECK(g.field_index(-1, -1, -1) == 0);
    CHECK(g.field_index(0, -1, -1) == 1);
    CHECK(g.field_index(0, 0, 0) == std::size_t((1 * 4 + 1) * 6 + 1));
    CHECK(g.field_index(4, 2, 6) == g.field_size() - 1);
}

TEMPLATE_TEST_CASE("F2: one particle at the cell centre, r/R = 0.2, gives phi = 0.992", "[fluid][porosity]", float,
                   double)
{
    using Real = TestType;
    const auto g = sphere::fluid_grid<Real>::make(make_box<Real>({0, 0, 0}, {1, 1, 1}), 1, 1, 1);
    const auto f = sphere::estimate_porosity(snapshot_of<Real>({{Real(0.5), Real(0.5), Real(0.5), Real(0.1)}},
                                                               {{Real(1), Real(-2), Real(3)}}),
                                             g, sphere::porosity_method::cell_sphere);
    const std::size_t c = g.field_index(0, 0, 0);
    CHECK(std::abs(double(f.phi[c]) - 0.992) <= f2_tolerance<Real>());
    CHECK(f.v_p[c].x == Real(1));
    CHECK(f.v_p[c].y == Real(-2));
    CHECK(f.v_p[c].z == Real(3));
    CHECK(std::abs(double(f.d_p[c]) - 0.2) <= 1e-6);
    CHECK(f.dphi_dt[c] == Real(0));
}

TEMPLATE_TEST_CASE("F2: simple cubic lattice, cells on a void and on a particle, walls and periodic",
                   "[fluid][porosity]", float, double)
{
    using Real = TestType;
    // Lattice r = 0.5, spacing 1 (bulk porosity 1 - pi/6 = 0.476401). A cell of width w has
    // a cell sphere of radius w/2: "2 diameters" is w = 2 (R = 1), "4 diameters" w = 4 (R = 2).
    // With the grid's cell centres at (i + 1/2) w, integers, a lattice at the integers puts a
    // particle at every cell centre, a lattice at the half-integers a void (the centre of a
    // lattice cube) there.
    struct f2 {
        double width, offset, phi;
        const char* what;
    };
    const f2 cases[] = {{2, 0.5, 0.397114, "width 2 d, on a void"},
                        {2, 0.0, 0.548875, "width 2 d, on a particle"},
                        {4, 0.5, 0.452592, "width 4 d, on a void"},
                        {4, 0.0, 0.498822, "width 4 d, on a particle"}};
    const double tol = f2_tolerance<Real>();
    for (const f2& c : cases) {
        INFO(c.what);
        const double L = 3 * c.width;
        // The exact porosity (long double sum of two-cap lenses over the lattice around a cell
        // centre at the origin) agrees with the table to its printed digits, and the estimator
        // with it to round-off.
        long double solid = 0;
        const long double R = c.width / 2;
        for (int k = -5; k <= 5; ++k)
            for (int j = -5; j <= 5; ++j)
                for (int i = -5; i <= 5; ++i) {
                    const long double dx = i + c.offset, dy = j + c.offset, dz = k + c.offset;
                    solid += two_caps(R, 0.5L, std::sqrt(dx * dx + dy * dy + dz * dz));
                }
        const long double cell_sphere = 4 * 3.14159265358979323846264338327950288L * R * R * R / 3;
        const double exact = static_cast<double>(1 - solid / cell_sphere);
        CHECK(std::abs(exact - c.phi) <= 5e-7);
        const double exact_tol = sizeof(Real) == sizeof(double) ? 1e-12 : 2e-6;
        // Walls: the lattice fills the box [0, 3w]^3; the middle cell's sphere reaches
        // [w - 1/2, 2w + 1/2], all inside.
        {
            const auto box = make_box<Real>({0, 0, 0}, {Real(L), Real(L), Real(L)});
            const auto g = sphere::fluid_grid<Real>::make(box, 3, 3, 3);
            const auto f = sphere::estimate_porosity(snapshot_of(unit_lattice<Real>(0, L + 0.5, c.offset, 0.5)), g, sphere::porosity_method::cell_sphere);
            CHECK(std::abs(double(f.phi[g.field_index(1, 1, 1)]) - c.phi) <= tol);
            CHECK(std::abs(double(f.phi[g.field_index(1, 1, 1)]) - exact) <= exact_tol);
            CHECK(std::abs(double(f.d_p[g.field_index(1, 1, 1)]) - 1.0) <= 1e-6);
        }
        // Periodic on every axis with 3 cells a side (L = 6 or 12 lattice periods): every cell
        // is equivalent, so the 26 cells whose spheres cross a boundary (and whose particles
        // lie partly on the far side) give the same porosity as the middle one.
        {
            const auto box = make_box<Real>({0, 0, 0}, {Real(L), Real(L), Real(L)}, true, true, true);
            const auto g = sphere::fluid_grid<Real>::make(box, 3, 3, 3);
            const auto x = unit_lattice<Real>(0, L, c.offset, 0.5);
            const auto f = sphere::estimate_porosity(snapshot_of(x), g, sphere::porosity_method::cell_sphere);
            for (int k = 0; k < 3; ++k)
                for (int j = 0; j < 3; ++j)
                    for (int i = 0; i < 3; ++i) {
                        INFO("cell " << i << " " << j << " " << k);
                        CHECK(std::abs(double(f.phi[g.field_index(i, j, k)]) - c.phi) <= tol);
                        CHECK(std::abs(double(f.phi[g.field_index(i, j, k)]) - exact) <= exact_tol);
                    }
            // The same particles given one period away on x and back on y and z: wrapped first.
            std::vector<vec4<Real>> shifted = x;
            for (vec4<Real>& p : shifted) {
                p.x += Real(L);
                p.y -= Real(L);
                p.z -= Real(2 * L);
            }
            const auto h = sphere::estimate_porosity(snapshot_of(shifted), g, sphere::porosity_method::cell_sphere);
            CHECK(std::abs(double(h.phi[g.field_index(0, 2, 1)]) - c.phi) <= tol);
        }
        // Periodic on x and y only, walls on z, the box at negative coordinates: x, y in [-L, 0)
        // and z in [-w, 4w) with 5 cells; the lattice fills it. The middle layer's cells at the
        // x and y boundaries see the lattice through the periodic images.
        {
            const double w = c.width;
            const auto box = make_box<Real>({Real(-L), Real(-L), Real(-w)}, {0, 0, Real(4 * w)}, true, true, false);
            const auto g = sphere::fluid_grid<Real>::make(box, 3, 3, 5);
            std::vector<vec4<Real>> x;
            for (const vec4<Real>& p : unit_lattice<Real>(-L, 4 * w, c.offset, 0.5))
                if (p.x < Real(0) && p.y < Real(0) && p.z >= Real(-w)) x.push_back(p);
            const auto f = sphere::estimate_porosity(snapshot_of(x), g, sphere::porosity_method::cell_sphere);
            CHECK(std::abs(double(f.phi[g.field_index(0, 2, 2)]) - c.phi) <= tol);
            CHECK(std::abs(double(f.phi[g.field_index(2, 0, 2)]) - c.phi) <= tol);
            CHECK(std::abs(double(f.phi[g.field_index(0, 0, 2)]) - c.phi) <= tol);
            CHECK(std::abs(double(f.phi[g.field_index(1, 1, 2)]) - c.phi) <= tol);
        }
    }
}

TEMPLATE_TEST_CASE("porosity estimator: lens-weighted particle velocity and diameter", "[fluid][porosity]", float,
                   double)
{
    using Real = TestType;
    // Two unit cells along x: R = 0.5, V_c = pi / 6. Cell 0 (centre (0.5, 0.5, 0.5)) holds
    // A: r = 0.1 at its centre, v = (9, 0, 0), wholly inside: V_A = 4/3 pi 0.001;
    // B: r = 0.2, 0.1 from the centre, v = (0, -9, 0), wholly inside: V_B = 4/3 pi 0.008 = 8 V_A;
    // C: r = 0.25 at 0.5 below the centre (z = 0), v = (0, 0, 3): a lens V_C = lens(0.5, 0.25, 0.5);
    // D: r = 0.1 touching the cell sphere from outside (1/2 + 0.1 from the centre, along -y):
    //    contributes nothing, not even to the averages.
    // Cell 1 (centre (1.5, 0.5, 0.5)) sees none of them: phi = 1, v_p = 0, d_p = 0.
    const auto g = sphere::fluid_grid<Real>::make(make_box<Real>({0, 0, 0}, {2, 1, 1}), 2, 1, 1);
    const std::vector<vec4<Real>> x = {{Real(0.5), Real(0.5), Real(0.5), Real(0.1)},
                                       {Real(0.5), Real(0.6), Real(0.5), Real(0.2)},
                                       {Real(0.5), Real(0.5), Real(0), Real(0.25)},
                                       {Real(0.5), Real(-0.1), Real(0.5), Real(0.1)}};
    const std::vector<vec3<Real>> v = {{9, 0, 0}, {0, -9, 0}, {0, 0, 3}, {100, 100, 100}};
    const auto f = sphere::estimate_porosity(snapshot_of(x, v), g, sphere::porosity_method::cell_sphere);

    const double VA = 4.0 / 3.0 * pi * 0.001, VB = 8 * VA, VC = static_cast<double>(two_caps(0.5L, 0.25L, 0.5L));
    const double Vs = VA + VB + VC, Vc = pi / 6;
    const std::size_t c0 = g.field_index(0, 0, 0), c1 = g.field_index(1, 0, 0);
    const double tol = sizeof(Real) == sizeof(double) ? 1e-13 : 1e-6;
    CHECK(std::abs(double(f.phi[c0]) - (1 - Vs / Vc)) <= tol);
    CHECK(std::abs(double(f.v_p[c0].x) - 9 * VA / Vs) <= tol * 10);
    CHECK(std::abs(double(f.v_p[c0].y) - (-9 * VB / Vs)) <= tol * 10);
    CHECK(std::abs(double(f.v_p[c0].z) - 3 * VC / Vs) <= tol * 10);
    CHECK(std::abs(double(f.d_p[c0]) - (0.2 * VA + 0.4 * VB + 0.5 * VC) / Vs) <= tol);
    CHECK(f.phi[c1] == Real(1));
    CHECK(f.v_p[c1].x == Real(0));
    CHECK(f.v_p[c1].y == Real(0));
    CHECK(f.v_p[c1].z == Real(0));
    CHECK(f.d_p[c1] == Real(0));

    // Without C the averages are hand-computable: V_B = 8 V_A, so v_p = (1, -8, 0) and
    // d_p = (0.2 + 8 * 0.4) / 9 = 0.377778 m; phi = 1 - 0.009 / 0.125 = 0.928.
    const auto h = sphere::estimate_porosity(snapshot_of<Real>({x[0], x[1], x[3]}, {v[0], v[1], v[3]}), g, sphere::porosity_method::cell_sphere);
    const double ftol = sizeof(Real) == sizeof(double) ? 1e-13 : 4e-6;
    CHECK(std::abs(double(h.v_p[c0].x) - 1) <= ftol);
    CHECK(std::abs(double(h.v_p[c0].y) + 8) <= 8 * ftol);
    CHECK(h.v_p[c0].z == Real(0));
    CHECK(std::abs(double(h.d_p[c0]) - 3.4 / 9) <= ftol);
    CHECK(std::abs(double(h.phi[c0]) - 0.928) <= ftol);
}

TEMPLATE_TEST_CASE("porosity estimator: dphi/dt by backward Euler, reset, ghosts untouched", "[fluid][porosity]",
                   float, double)
{
    using Real = TestType;
    const auto g = sphere::fluid_grid<Real>::make(make_box<Real>({0, 0, 0}, {1, 1, 1}), 1, 1, 1);
    sphere::porosity_estimator<Real, sphere::host> est(g, sphere::porosity_method::cell_sphere);
    CHECK(est.cell_sphere_radius() == Real(0.5));
    const std::size_t c = g.field_index(0, 0, 0);
    const double tol = sizeof(Real) == sizeof(double) ? 1e-12 : 2e-5;
    // A particle r = 0.1 at the centre (phi0 = 0.992), then moved 0.5 along x, half out of the
    // cell sphere (phi1 = 1 - lens(0.5, 0.1, 0.5) / V_c), then out of it (phi2 = 1).
    std::vector<vec4<Real>> x = {{Real(0.5), Real(0.5), Real(0.5), Real(0.1)}};
    est.update(snapshot_of(x), Real(0.25));
    auto f = est.fields();
    const double phi0 = 0.992;
    CHECK(std::abs(double(f.phi[c]) - phi0) <= tol);
    CHECK(f.dphi_dt[c] == Real(0)); // no previous porosity yet
    x[0].x = Real(1.0);
    est.update(snapshot_of(x), Real(0.25));
    f = est.fields();
    const double phi1 = 1 - static_cast<double>(two_caps(0.5L, 0.1L, 0.5L)) / (pi / 6);
    CHECK(std::abs(double(f.phi[c]) - phi1) <= tol);
    CHECK(std::abs(double(f.dphi_dt[c]) - (phi1 - phi0) / 0.25) <= 4 * tol / 0.25);
    x[0].x = Real(1.7);
    est.update(snapshot_of(x), Real(0.5));
    f = est.fields();
    CHECK(f.phi[c] == Real(1));
    CHECK(std::abs(double(f.dphi_dt[c]) - (1 - phi1) / 0.5) <= 4 * tol / 0.5);
    // After reset the next update has no previous porosity.
    est.reset();
    x[0].x = Real(0.5);
    est.update(snapshot_of(x), Real(0.5));
    f = est.fields();
    CHECK(std::abs(double(f.phi[c]) - phi0) <= tol);
    CHECK(f.dphi_dt[c] == Real(0));
    // The ghost nodes are the boundary conditions' business: never written here.
    for (int k = -1; k <= 1; ++k)
        for (int j = -1; j <= 1; ++j)
            for (int i = -1; i <= 1; ++i) {
                if (i == 0 && j == 0 && k == 0) continue;
                const std::size_t gi = g.field_index(i, j, k);
                CHECK(f.phi[gi] == Real(1));
                CHECK(f.dphi_dt[gi] == Real(0));
                CHECK(f.d_p[gi] == Real(0));
            }
    // The kernel view points at the same fields.
    const sphere::porosity_view<Real> view = est.view();
    CHECK(view.radius == Real(0.5));
    CHECK(view.phi[c] == f.phi[c]);
}

TEMPLATE_TEST_CASE("porosity estimator: non-cubic cells use R = half the smallest width", "[fluid][porosity]", float,
                   double)
{
    using Real = TestType;
    // Cells 1 x 2 x 0.5 m: R = 0.25 m; a particle r = 0.1 at a cell centre leaves
    // phi = 1 - (0.1 / 0.25)^3 = 0.936, and a particle 0.3 from that centre along x (outside
    // the sphere, though inside the cell) changes nothing.
    const auto g = sphere::fluid_grid<Real>::make(make_box<Real>({0, 0, 0}, {2, 2, 1}), 2, 1, 2);
    sphere::porosity_estimator<Real, sphere::host> est(g, sphere::porosity_method::cell_sphere);
    CHECK(est.cell_sphere_radius() == Real(0.25));
    const vec3<Real> c = g.centre(1, 0, 1);
    CHECK(c.x == Real(1.5));
    CHECK(c.y == Real(1));
    CHECK(c.z == Real(0.75));
    est.update(snapshot_of<Real>({{c.x, c.y, c.z, Real(0.1)}, {c.x - Real(0.4), c.y, c.z, Real(0.05)}}), Real(1));
    const auto f = est.fields();
    CHECK(std::abs(double(f.phi[g.field_index(1, 0, 1)]) - 0.936) <= f2_tolerance<Real>());
}

namespace {
/// Independent reference for porosity_method::cell_volume's fractions: the share of the volume
/// of a sphere of radius r centred at 0 that lies between the planes a < b (either may be
/// infinite), by Simpson's rule on its cross-section pi (r^2 - z^2), which is exact for that
/// quadratic.
double slab_fraction(double r, double a, double b)
{
    a = a < -r ? -r : a;
    b = b > r ? r : b;
    if (!(b > a)) return 0;
    const auto area = [r](double z) { return pi * (r * r - z * z); };
    return (b - a) / 6 * (area(a) + 4 * area(0.5 * (a + b)) + area(b)) / (4.0 / 3.0 * pi * r * r * r);
}

/// Runs the estimator on `n_particles` random particles (radii uniform in [r_lo, r_hi], one in
/// ten in [r_big_lo, r_big_hi]) and checks every cell's fields against a double-precision sum
/// over every particle (nearest image on periodic axes; two-cap lens for cell_sphere, Simpson
/// slab fractions for cell_volume); returns the number of cells that meet some particle.
template <class Real>
int check_against_brute_force(const sphere::fluid_grid<Real>& g, int n_particles, double r_lo, double r_hi,
                              double r_big_lo, double r_big_hi, unsigned seed,
                              sphere::porosity_method method = sphere::porosity_method::cell_sphere)
{
    std::mt19937_64 gen(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<vec4<Real>> x;
    std::vector<vec3<Real>> v;
    for (int p = 0; p < n_particles; ++p) {
        const double r = p % 10 == 0 ? r_big_lo + (r_big_hi - r_big_lo) * u(gen) : r_lo + (r_hi - r_lo) * u(gen);
        vec4<Real> xp{0, 0, 0, Real(r)};
        xp.x = Real(double(g.box.lo.x) + double(g.box.length(0)) * u(gen));
        xp.y = Real(double(g.box.lo.y) + double(g.box.length(1)) * u(gen));
        xp.z = Real(double(g.box.lo.z) + double(g.box.length(2)) * u(gen));
        x.push_back(xp);
        v.push_back({Real(u(gen) - 0.5), Real(u(gen) - 0.5), Real(u(gen) - 0.5)});
    }
    sphere::porosity_estimator<Real, sphere::host> est(g, method);
    est.update(snapshot_of(x, v), Real(1));
    const auto f = est.fields();
    const bool sphere_sample = method == sphere::porosity_method::cell_sphere;
    const double R = double(est.cell_sphere_radius());
    const double Vc = sphere_sample ? 4.0 / 3.0 * pi * R * R * R
                                    : double(g.width.x) * double(g.width.y) * double(g.width.z);
    // Round-off of sums of up to ~100 lenses relative to V_c.
    const double tol = sizeof(Real) == sizeof(double) ? 1e-12 : 1e-5;
    int touched = 0;
    for (int k = 0; k < int(g.n[2]); ++k)
        for (int j = 0; j < int(g.n[1]); ++j)
            for (int i = 0; i < int(g.n[0]); ++i) {
                const vec3<Real> c = g.centre(i, j, k);
                double Vs = 0, Vd = 0;
                vec3<double> Vv{0, 0, 0};
                for (std::size_t p = 0; p < x.size(); ++p) {
                    double d[3] = {double(x[p].x) - double(c.x), double(x[p].y) - double(c.y),
                                   double(x[p].z) - double(c.z)};
                    for (int a = 0; a < 3; ++a)
                        if (g.box.periodic(a)) {
                            const double L = double(g.box.length(a));
                            d[a] -= L * std::nearbyint(d[a] / L);
                        }
                    const double r = double(x[p].w);
                    double V = 4.0 / 3.0 * pi * r * r * r;
                    if (sphere_sample) {
                        V = static_cast<double>(two_caps(R, r, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])));
                    } else {
                        const int ijk[3] = {i, j, k};
                        for (int a = 0; a < 3; ++a) {
                            const double h = 0.5 * double(g.width[a]), inf = std::numeric_limits<double>::infinity();
                            const bool wall = !g.box.periodic(a);
                            const double lo = wall && ijk[a] == 0 ? -inf : -h - d[a];
                            const double hi = wall && ijk[a] == int(g.n[a]) - 1 ? inf : h - d[a];
                            V *= slab_fraction(r, lo, hi);
                        }
                    }
                    Vs += V;
                    Vd += V * 2 * double(x[p].w);
                    Vv += vec3<double>{double(v[p].x), double(v[p].y), double(v[p].z)} * V;
                }
                const std::size_t fi = g.field_index(i, j, k);
                INFO("cell " << i << " " << j << " " << k << ": solid fraction " << Vs / Vc);
                CHECK(std::abs(double(f.phi[fi]) - (1 - Vs / Vc)) <= tol);
                if (Vs > 0) {
                    ++touched;
                    CHECK(std::abs(double(f.d_p[fi]) - Vd / Vs) <= tol);
                    CHECK(std::abs(double(f.v_p[fi].x) - Vv.x / Vs) <= 10 * tol);
                    CHECK(std::abs(double(f.v_p[fi].y) - Vv.y / Vs) <= 10 * tol);
                    CHECK(std::abs(double(f.v_p[fi].z) - Vv.z / Vs) <= 10 * tol);
                } else {
                    CHECK(f.d_p[fi] == Real(0));
                }
            }
    return touched;
}
} // namespace

TEMPLATE_TEST_CASE("porosity estimator: the binned search matches a brute-force sum over all particles",
                   "[fluid][porosity]", float, double)
{
    using Real = TestType;
    SECTION("periodic x and z, walls on y; some particles wider than a cell")
    {
        // Cell widths 0.4, 0.5 and 0.3 m (R = 0.15 m), radii 0.02-0.12 m and 0.3-0.45 m: the
        // big ones need bins two cells away.
        const auto box =
            make_box<Real>({Real(-1), Real(0), Real(2)}, {Real(1.4), Real(2), Real(3.8)}, true, false, true);
        CHECK(check_against_brute_force(sphere::fluid_grid<Real>::make(box, 6, 4, 6), 300, 0.02, 0.12, 0.3, 0.45, 17) >
              100);
    }
    SECTION("short periodic axes: the bin range covers the whole period")
    {
        // 2 cells along a periodic x (1 m) and 3 along a periodic y (1.2 m), walls and 4 cells on
        // z: R = 0.2 m, radii up to 0.28 m <= L_x / 2 - R, so every cell scans every bin along x
        // and y, each once.
        const auto box = make_box<Real>({0, 0, 0}, {Real(1), Real(1.2), Real(1.6)}, true, true, false);
        CHECK(check_against_brute_force(sphere::fluid_grid<Real>::make(box, 2, 3, 4), 60, 0.02, 0.1, 0.2, 0.28, 5) >
              20);
    }
    SECTION("no particles")
    {
        const auto box = make_box<Real>({0, 0, 0}, {1, 1, 1});
        CHECK(check_against_brute_force(sphere::fluid_grid<Real>::make(box, 2, 2, 2), 0, 0.1, 0.1, 0.1, 0.1, 1) == 0);
    }
    SECTION("cell_volume: periodic x and z, walls on y; some particles wider than a cell")
    {
        // Half-widths 0.2, 0.25, 0.15 m; radii up to 0.45 m <= L_z / 2 - 0.15 = 0.75 m.
        const auto box =
            make_box<Real>({Real(-1), Real(0), Real(2)}, {Real(1.4), Real(2), Real(3.8)}, true, false, true);
        CHECK(check_against_brute_force(sphere::fluid_grid<Real>::make(box, 6, 4, 6), 300, 0.02, 0.12, 0.3, 0.45, 17,
                                        sphere::porosity_method::cell_volume) > 100);
    }
    SECTION("cell_volume: short periodic axes, walls on z")
    {
        // Half-widths 0.25 and 0.2 m on the periodic axes, radii up to 0.25 m.
        const auto box = make_box<Real>({0, 0, 0}, {Real(1), Real(1.2), Real(1.6)}, true, true, false);
        CHECK(check_against_brute_force(sphere::fluid_grid<Real>::make(box, 2, 3, 4), 60, 0.02, 0.1, 0.2, 0.25, 5,
                                        sphere::porosity_method::cell_volume) > 20);
    }
}

namespace {
/// Random particles over `box` (centres up to `overhang` metres beyond its wall faces), with
/// radii in [r_lo, r_hi].
template <class Real>
std::vector<vec4<Real>> random_particles(const sphere::world<Real>& box, int n, double r_lo, double r_hi,
                                         double overhang, unsigned seed)
{
    std::mt19937_64 gen(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<vec4<Real>> x;
    for (int p = 0; p < n; ++p) {
        double c[3];
        for (int a = 0; a < 3; ++a) {
            const double extra = box.periodic(a) ? 0 : overhang;
            c[a] = double(box.lo[a]) - extra + (double(box.length(a)) + 2 * extra) * u(gen);
            if (box.periodic(a) && c[a] >= double(box.hi[a])) c[a] = double(box.lo[a]);
        }
        x.push_back({Real(c[0]), Real(c[1]), Real(c[2]), Real(r_lo + (r_hi - r_lo) * u(gen))});
    }
    return x;
}

template <class Real>
double total_volume(const std::vector<vec4<Real>>& x)
{
    double v = 0;
    for (const vec4<Real>& p : x) v += 4.0 / 3.0 * pi * double(p.w) * double(p.w) * double(p.w);
    return v;
}

/// Solid volume of the cells of layers [k_lo, k_hi] along z: sum of (1 - phi) V_cell (m^3).
template <class Real>
double solid_in_layers(const sphere::porosity_fields<Real>& f, int k_lo, int k_hi)
{
    const auto& g = f.grid;
    const double Vc = double(g.width.x) * double(g.width.y) * double(g.width.z);
    double s = 0;
    for (int k = k_lo; k <= k_hi; ++k)
        for (int j = 0; j < int(g.n[1]); ++j)
            for (int i = 0; i < int(g.n[0]); ++i) s += (1 - double(f.phi[g.field_index(i, j, k)])) * Vc;
    return s;
}
} // namespace

TEMPLATE_TEST_CASE("cell_volume porosity conserves the solid volume: the grid's and every layer's", "[fluid][porosity]",
                   float, double)
{
    using Real = TestType;
    // 400 particles crossing cell faces, periodic boundaries on x and y, and poking through the
    // walls at the bottom and top (centres up to 0.05 m beyond them): the cells hold the
    // particles' total volume, and each layer of cells exactly the volume between its planes
    // (the outermost layers what lies beyond the walls too), against slab_fraction.
    const auto box = make_box<Real>({Real(-0.5), Real(0), Real(0)}, {Real(0.7), Real(1), Real(1.5)}, true, true, false);
    const auto g = sphere::fluid_grid<Real>::make(box, 4, 5, 6);
    const auto x = random_particles(box, 400, 0.01, 0.09, 0.05, 3);
    const auto f = sphere::estimate_porosity(snapshot_of(x), g);
    const double total = total_volume(x);
    const double tol = sizeof(Real) == sizeof(double) ? 1e-12 : 2e-5;
    INFO("particle volume " << total << " m^3");
    CHECK(std::abs(solid_in_layers(f, 0, 5) - total) <= tol * total);
    const double w = double(g.width.z), inf = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 6; ++k) {
        const double lo = k == 0 ? -inf : k * w, hi = k == 5 ? inf : (k + 1) * w;
        double expected = 0;
        for (const vec4<Real>& p : x) {
            const double r = double(p.w), V = 4.0 / 3.0 * pi * r * r * r;
            expected += V * slab_fraction(r, lo - double(p.z), hi - double(p.z));
        }
        INFO("layer " << k);
        CHECK(std::abs(solid_in_layers(f, k, k) - expected) <= tol * total);
    }
    // A simple cubic lattice of spacing 1, r = 0.5, in cells of two periods: every cell holds 8
    // particles' worth of volume, phi = 1 - pi/6 wherever the lattice sits.
    for (double offset : {0.0, 0.3, 0.5}) {
        const auto lattice_box = make_box<Real>({0, 0, 0}, {6, 6, 6}, true, true, true);
        const auto lg = sphere::fluid_grid<Real>::make(lattice_box, 3, 3, 3);
        const auto lf = sphere::estimate_porosity(snapshot_of(unit_lattice<Real>(0, 6, offset, 0.5)), lg);
        for (int k = 0; k < 3; ++k)
            for (int j = 0; j < 3; ++j)
                for (int i = 0; i < 3; ++i) {
                    INFO("offset " << offset << ", cell " << i << " " << j << " " << k);
                    CHECK(std::abs(double(lf.phi[lg.field_index(i, j, k)]) - (1 - pi / 6)) <= 10 * tol);
                }
    }
}

TEMPLATE_TEST_CASE("cell_volume porosity: a moving particle's rate sums to zero over the grid", "[fluid][porosity]",
                   float, double)
{
    using Real = TestType;
    // Particles move across faces and through a periodic boundary between two updates: the
    // rates change the porosity of single cells by up to ~1e-2/s, but sum (dphi/dt) V_cell over
    // the grid to round-off, the closed box's compatibility condition.
    const auto box = make_box<Real>({0, 0, 0}, {Real(1), Real(1), Real(2)}, true, true, false);
    const auto g = sphere::fluid_grid<Real>::make(box, 4, 4, 8);
    sphere::porosity_estimator<Real, sphere::host> est(g);
    auto x = random_particles(box, 200, 0.02, 0.1, 0, 11);
    est.update(snapshot_of(x), Real(0.1));
    for (vec4<Real>& p : x) {
        p.x = box.wrap(p.x + Real(0.13), 0);
        p.z = p.z - Real(0.07);
    }
    est.update(snapshot_of(x), Real(0.1));
    const auto f = est.fields();
    double sum = 0, largest = 0;
    for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const double rate = double(f.dphi_dt[g.field_index(i, j, k)]);
                sum += rate;
                largest = std::max(largest, std::abs(rate));
            }
    INFO("largest cell rate " << largest << " 1/s, sum " << sum);
    CHECK(largest > 1e-2);
    CHECK(std::abs(sum) <= (sizeof(Real) == sizeof(double) ? 1e-12 : 1e-4) * largest * 128);
}

TEMPLATE_TEST_CASE("fluid grid and porosity estimator: errors name the bad value", "[fluid][porosity]", float, double)
{
    using Real = TestType;
    using grid = sphere::fluid_grid<Real>;
    const auto box = make_box<Real>({0, 0, 0}, {1, 1, 1});
    CHECK_THROWS_WITH(grid::make(box, 0, 4, 4), Catch::Contains("nx = 0 cells: every axis needs at least 1"));
    CHECK_THROWS_WITH(grid::make(box, 4, -3, 4), Catch::Contains("ny = -3 cells"));
    CHECK_THROWS_WITH(grid::make(box, 4, 4, 0), Catch::Contains("nz = 0 cells"));
    CHECK_THROWS_WITH(grid::make(box, 1024, 1024, 1024), Catch::Contains("more than the 2^28 allowed"));
    auto flat = box;
    flat.hi.z = flat.lo.z;
    CHECK_THROWS_WITH(grid::make(flat, 4, 4, 4), Catch::Contains("the world box along z is [0, 0] m"));
    auto infinite = box;
    infinite.hi.y = std::numeric_limits<Real>::infinity();
    CHECK_THROWS_WITH(grid::make(infinite, 4, 4, 4), Catch::Contains("along y is [0, inf] m"));

    sphere::porosity_estimator<Real, sphere::host> est(grid::make(box, 2, 2, 2));
    const auto s = snapshot_of<Real>({{Real(0.5), Real(0.5), Real(0.5), Real(0.1)}});
    CHECK_THROWS_WITH(est.update(s, Real(0)), Catch::Contains("dt = 0 s must be positive and finite"));
    CHECK_THROWS_WITH(est.update(s, Real(-1)), Catch::Contains("dt = -1 s"));
    CHECK_THROWS_WITH(est.update(s, std::numeric_limits<Real>::quiet_NaN()), Catch::Contains("dt = nan s"));
    auto no_velocity = s;
    no_velocity.v_sync.clear();
    CHECK_THROWS_WITH(est.update(no_velocity, Real(1)),
                      Catch::Contains("the snapshot has 1 positions but 0 velocities (v_sync)"));

    // One cell along a periodic x: R = 0.5 of a 1 m period, so any particle could meet the cell
    // sphere through two images; 2 cells (R = 0.25) with r = 0.1 are fine, r = 0.3 is not.
    const auto periodic = make_box<Real>({0, 0, 0}, {1, 1, 1}, true, false, false);
    sphere::porosity_estimator<Real, sphere::host> one(grid::make(periodic, 1, 1, 1), sphere::porosity_method::cell_sphere);
    CHECK_THROWS_WITH(one.update(s, Real(1)), Catch::Contains("periodic axis x of length 1 m is shorter than twice"));
    sphere::porosity_estimator<Real, sphere::host> two(grid::make(periodic, 2, 2, 2), sphere::porosity_method::cell_sphere);
    CHECK_NOTHROW(two.update(s, Real(1)));
    const auto big = snapshot_of<Real>({{Real(0.5), Real(0.5), Real(0.5), Real(0.3)}});
    CHECK_THROWS_WITH(two.update(big, Real(1)), Catch::Contains("use more fluid cells along x"));
    // cell_volume reaches half a cell width: 2 cells (0.25 m) with r = 0.3 > 0.5 - 0.25.
    sphere::porosity_estimator<Real, sphere::host> volume(grid::make(periodic, 2, 2, 2));
    CHECK(volume.method() == sphere::porosity_method::cell_volume);
    CHECK_THROWS_WITH(volume.update(big, Real(1)),
                      Catch::Contains("periodic axis x of length 1 m is shorter than twice half the cell width 0.25 m"));
}

} // namespace test_fluid_porosity
