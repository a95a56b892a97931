// Drag laws of include/sphere/fluid/drag.cuh (issue 4, test 4): the Reynolds number and the
// Schiller-Naumann C_d, the momentum-exchange coefficient beta of drag::ergun, drag::wen_yu,
// drag::gidaspow and drag::gidaspow_blended against hand-computed values at three porosities
// and three Reynolds numbers, the jump of the switched law at phi = 0.8 (VALIDATION pitfall 5),
// the continuity of the blend, the dilute (phi -> 1) and Stokes limits of the per-particle
// force, zero relative velocity, the equal and opposite force on the fluid, the F6 force balance
// and the F8 Ergun pressure drop of ../shared/VALIDATION.md, and the host-side checks.
//
// phi is the POROSITY (fluid fraction). Re = phi rho_f d u / mu_f, u = |v_f - v_p|.
//
// Expected values are decimal literals computed independently with python3 + mpmath at 40
// digits from the formulas in the comments (the inputs are the decimal numbers written here).
// Tolerances: 1e-10 relative in double, 1e-5 in float (the float inputs themselves are rounded
// by ~6e-8, amplified at most ~10 times by the powers in the laws).
#include <catch2/catch.hpp>

#include <sphere/fluid/drag.cuh>

#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_drag {

namespace {

using sphere::vec3;
namespace drag = sphere::drag;
using Catch::Contains;

constexpr double pi = 3.14159265358979323846;

template <class Real>
double tol()
{
    return std::is_same<Real, float>::value ? 1e-5 : 1e-10;
}

template <class Real>
double rel_err(Real a, double b)
{
    return std::abs(static_cast<double>(a) - b) / std::abs(b);
}

template <class Real>
bool finite(const vec3<Real>& a)
{
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

template <class Real>
double norm_d(const vec3<Real>& a)
{
    const double x = a.x, y = a.y, z = a.z;
    return std::sqrt(x * x + y * y + z * z);
}

// Water-like fluid and 2 mm grains for the beta tables.
constexpr double d_w = 0.002;   // m
constexpr double rho_w = 1000;  // kg/m^3
constexpr double mu_w = 0.001;  // Pa s

// One row of the beta table (all betas in N s/m^4).
struct beta_row {
    double phi, u, re, ergun, wen_yu, gidaspow, blended;
};

// d = 0.002 m, rho_f = 1000 kg/m^3, mu_f = 0.001 Pa s, so Re = phi * 2000 * u.
//
// Ergun: beta = 150 mu (1-phi)^2/(phi d^2) + 1.75 (1-phi) rho u / d, i.e.
//   phi = 0.4: 150e-3 * 0.36 / (0.4 * 4e-6) = 33750   plus 1.75 * 0.6 * 1000 / 0.002 = 525000 u
//   phi = 0.7: 150e-3 * 0.09 / (0.7 * 4e-6) = 4821.428571428571 plus 262500 u
//   phi = 0.9: 150e-3 * 0.01 / (0.9 * 4e-6) = 416.6666666666667 plus 87500 u
//   e.g. phi = 0.4, u = 0.01: 33750 + 5250 = 39000.
// Wen-Yu: beta = 3/4 C_d rho phi (1-phi) u / d phi^-2.65 = 3/4 (C_d Re) mu (1-phi) phi^-2.65 / d^2,
//   C_d Re = 24 (1 + 0.15 Re^0.687); phi^-2.65 = 11.3381193168 (0.4), 2.57329866065 (0.7),
//   1.32207882668 (0.9). E.g. phi = 0.4, u = 0.01: Re = 8, C_d Re = 39.0219157468,
//   beta = 0.75 * 39.0219157468 * 1e-3 * 0.6 * 11.3381193168 / 4e-6 = 49773.9528796.
//   phi = 0.9, u = 0.4: Re = 720, C_d = 0.492486336655, beta = 0.75 * 0.492486336655 * 1000 *
//   0.9 * 0.1 * 0.4 / 0.002 * 1.32207882668 = 8789.92773466.
// Gidaspow: Ergun at 0.4 and 0.7, Wen-Yu at 0.9.
// Blend: w = 1/2 + atan(262.5 (phi - 0.8)) / pi = 0.00303143107453 (0.4), 0.0121202300197 (0.7),
//   0.98787976998 (0.9); beta = (1 - w) Ergun + w Wen-Yu, e.g. phi = 0.9, u = 0.4:
//   0.01212023002 * 35416.6667 + 0.98787977 * 8789.92773 = 9112.64993519.
const beta_row table[] = {
    {0.4, 0.0001, 0.08, 33802.5, 31422.798785774781, 33802.5, 33795.286099791097},
    {0.4, 0.01, 8.0, 39000.0, 49773.952879617694, 39000.0, 39032.660495554814},
    {0.4, 0.4, 320.0, 243750.0, 272177.96169582673, 243750.0, 243836.17740647033},
    {0.7, 0.0001, 0.14, 4847.6785714285714, 3608.9443060961116, 4847.6785714285714, 4832.6648271994203},
    {0.7, 0.01, 14.0, 7446.4285714285714, 6667.7345529908061, 7446.4285714285714, 7436.9906208101176},
    {0.7, 0.4, 560.0, 109821.42857142857, 43738.275705797562, 109821.42857142857, 109020.48555826812},
    {0.9, 0.0001, 0.18, 425.41666666666667, 622.4101957202408, 622.4101957202408, 620.02258883571304},
    {0.9, 0.01, 18.0, 1291.6666666666667, 1244.9653721474662, 1244.9653721474662, 1245.5314025792581},
    {0.9, 0.4, 720.0, 35416.666666666667, 8789.9277346591627, 8789.9277346591627, 9112.6499351904034},
};

template <class Law, class Real>
Real beta_w(double phi, double u)
{
    return Law::beta(Real(phi), Real(d_w), Real(u), Real(rho_w), Real(mu_w));
}

} // namespace

TEMPLATE_TEST_CASE("Reynolds number and Schiller-Naumann drag coefficient", "[drag]", float, double)
{
    using Real = TestType;
    // Re = phi rho d u / mu = 0.7 * 1000 * 0.002 * 0.01 / 0.001 = 14.
    CHECK(rel_err(drag::reynolds(Real(0.7), Real(d_w), Real(0.01), Real(rho_w), Real(mu_w)), 14.0) < tol<Real>());
    // The porosity is part of the definition: phi = 1 gives 20.
    CHECK(rel_err(drag::reynolds(Real(1), Real(d_w), Real(0.01), Real(rho_w), Real(mu_w)), 20.0) < tol<Real>());

    // C_d = 24/Re (1 + 0.15 Re^0.687): Re = 0.1: 240 * (1 + 0.15 * 0.1^0.687) = 247.401206145543;
    // Re = 10: 4.15106594048926; Re = 500: 0.562665301629113; Re >= 1000: 0.44.
    CHECK(rel_err(drag::drag_coefficient(Real(0.1)), 247.40120614554291) < tol<Real>());
    CHECK(rel_err(drag::drag_coefficient(Real(10)), 4.1510659404892617) < tol<Real>());
    CHECK(rel_err(drag::drag_coefficient(Real(500)), 0.56266530162911319) < tol<Real>());
    CHECK(drag::drag_coefficient(Real(1000)) == Real(0.44));
    CHECK(drag::drag_coefficient(Real(2000)) == Real(0.44));
    // C_d Re at the same points, and its Stokes limit 24 at Re = 0 (where C_d itself is infinite).
    CHECK(rel_err(drag::cd_times_reynolds(Real(10)), 41.510659404892617) < tol<Real>());
    CHECK(rel_err(drag::cd_times_reynolds(Real(2000)), 880.0) < tol<Real>());
    CHECK(drag::cd_times_reynolds(Real(0)) == Real(24));
    CHECK(std::isinf(drag::drag_coefficient(Real(0))));
}

TEMPLATE_TEST_CASE("beta of each law at three porosities and three Reynolds numbers", "[drag]", float, double)
{
    using Real = TestType;
    for (const beta_row& r : table) {
        CAPTURE(r.phi, r.u);
        CHECK(rel_err(drag::reynolds(Real(r.phi), Real(d_w), Real(r.u), Real(rho_w), Real(mu_w)), r.re) < tol<Real>());
        CHECK(rel_err(beta_w<drag::ergun, Real>(r.phi, r.u), r.ergun) < tol<Real>());
        CHECK(rel_err(beta_w<drag::wen_yu, Real>(r.phi, r.u), r.wen_yu) < tol<Real>());
        CHECK(rel_err(beta_w<drag::gidaspow, Real>(r.phi, r.u), r.gidaspow) < tol<Real>());
        CHECK(rel_err(beta_w<drag::gidaspow_blended, Real>(r.phi, r.u), r.blended) < tol<Real>());
    }
}

TEMPLATE_TEST_CASE("Wen-Yu above Re = 1000 uses C_d = 0.44", "[drag]", float, double)
{
    using Real = TestType;
    // phi = 0.9, u = 1 m/s: Re = 1800; beta = 0.75 * 0.44 * 1000 * 0.9 * 0.1 * 1 / 0.002 *
    // 1.32207882668 = 14850 * 1.32207882668 = 19632.8705763.
    CHECK(rel_err(beta_w<drag::wen_yu, Real>(0.9, 1.0), 19632.870576261421) < tol<Real>());
    CHECK(rel_err(beta_w<drag::gidaspow, Real>(0.9, 1.0), 19632.870576261421) < tol<Real>());
}

TEMPLATE_TEST_CASE("the switched law jumps by x1.1533 at phi = 0.8 in the Stokes limit", "[drag]", float, double)
{
    using Real = TestType;
    const Real below = Real(0.8);                                    // Ergun side (phi <= 0.8)
    const Real above = std::nextafter(below, Real(1));               // Wen-Yu side
    auto beta = [&](Real phi, double u) {
        return drag::gidaspow::beta(phi, Real(d_w), Real(u), Real(rho_w), Real(mu_w));
    };
    // The switch is at phi <= 0.8: phi = 0.8 itself is Ergun.
    CHECK(beta(below, 0.01) == beta_w<drag::ergun, Real>(0.8, 0.01));
    CHECK(rel_err(beta(above, 0.01), static_cast<double>(beta_w<drag::wen_yu, Real>(0.8, 0.01))) < tol<Real>());

    // u -> 0 (Re -> 0, C_d Re -> 24): Ergun 150 mu 0.04 / (0.8 d^2) = 7.5 mu/d^2 = 1875;
    // Wen-Yu 3/4 * 24 * mu * 0.2 * 0.8^-2.65 / d^2 = 3.6 * 1.80640 mu/d^2 = 1625.75105276728;
    // below / above = 7.5 / (3.6 * 0.8^-2.65) = 1.153313108306748: beta DROPS by this factor
    // when phi rises through 0.8 (above / below = 0.867067).
    const double stokes_ratio = 1.153313108306748;
    CHECK(rel_err(beta(below, 0.0), 1875.0) < tol<Real>());
    CHECK(rel_err(beta(above, 0.0), 1625.7510527672804) < tol<Real>());
    CHECK(rel_err(beta(below, 0.0) / beta(above, 0.0), stokes_ratio) < tol<Real>());
    CHECK(std::abs(static_cast<double>(beta(below, 0.0) / beta(above, 0.0)) - 1.1533) < 5e-5); // VALIDATION's figure

    // The factor holds only as Re -> 0: at finite Re the ratio is different
    // (Re = 16, u = 0.01: 3625 / 3263.98428320221 = 1.11060583798020; Re = 640, u = 0.4: 3.22611456737251).
    CHECK(rel_err(beta(below, 0.01) / beta(above, 0.01), 1.1106058379802015) < tol<Real>());
    CHECK(rel_err(beta(below, 0.4) / beta(above, 0.4), 3.226114567372507) < tol<Real>());
}

TEMPLATE_TEST_CASE("the blended law is continuous at phi = 0.8 and tends to Ergun and Wen-Yu", "[drag]", float,
                   double)
{
    using Real = TestType;
    // w(0.8) = 1/2: beta is the mean of Ergun and Wen-Yu there.
    // u = 0: (1875 + 1625.75105276728) / 2 = 1750.37552638364; u = 0.01: (3625 + 3263.98428320221) / 2.
    CHECK(drag::gidaspow_blended::weight(Real(0.8)) == Real(0.5));
    CHECK(rel_err(beta_w<drag::gidaspow_blended, Real>(0.8, 0.0), 1750.3755263836402) < tol<Real>());
    CHECK(rel_err(beta_w<drag::gidaspow_blended, Real>(0.8, 0.01), 3444.4921416011059) < tol<Real>());

    // The weight, w = 1/2 + atan(262.5 (phi - 0.8)) / pi (absolute: float cancels in 1/2 - 0.497).
    const double w_tol = std::is_same<Real, float>::value ? 1e-7 : 1e-14;
    CHECK(std::abs(drag::gidaspow_blended::weight(Real(0.4)) - 0.0030314310745317806) < w_tol);
    CHECK(std::abs(drag::gidaspow_blended::weight(Real(0.7)) - 0.012120230019730367) < w_tol);
    CHECK(std::abs(drag::gidaspow_blended::weight(Real(0.9)) - 0.98787976998026963) < w_tol);
    // 10% to 90% over phi = 0.8 -+ tan(0.4 pi) / 262.5 = 0.8 -+ 0.011724509.
    CHECK(std::abs(drag::gidaspow_blended::weight(Real(0.8 - 0.011724509)) - 0.1) < 1e-5);
    CHECK(std::abs(drag::gidaspow_blended::weight(Real(0.8 + 0.011724509)) - 0.9) < 1e-5);

    // Continuity: across 0.8 -+ h the blend changes by O(h); the switched law jumps by >= 11%.
    const double h = std::is_same<Real, float>::value ? 1e-4 : 1e-7;
    for (double u : {0.0, 0.0001, 0.01, 0.4}) {
        CAPTURE(u);
        const double lo = beta_w<drag::gidaspow_blended, Real>(0.8 - h, u);
        const double hi = beta_w<drag::gidaspow_blended, Real>(0.8 + h, u);
        // |d beta / d phi| / beta < 200 here (the weight's slope is 262.5 / pi = 83.6 times a
        // relative difference <= 2.3, plus Ergun's own (1-phi)^-2 dependence, ~11).
        CHECK(std::abs(hi - lo) / lo < 200 * 2 * h + (std::is_same<Real, float>::value ? 1e-5 : 0.0));
        const double s_lo = beta_w<drag::gidaspow, Real>(0.8 - h, u);
        const double s_hi = beta_w<drag::gidaspow, Real>(0.8 + h, u);
        CHECK(std::abs(s_hi - s_lo) / s_lo > 0.09); // 1 - 1/1.1106 = 0.0996 at Re = 16, more elsewhere
    }

    // Far from 0.8 the blend is Ergun (below) or Wen-Yu (above) up to the weight's tail,
    // |blend / law - 1| = w' |other / law - 1| with w' <= 1 / (262.5 pi |phi - 0.8|).
    for (double u : {0.0001, 0.01, 0.4}) {
        for (double phi : {0.3, 0.4, 0.5}) {
            CAPTURE(u, phi);
            const double er = beta_w<drag::ergun, Real>(phi, u), wy = beta_w<drag::wen_yu, Real>(phi, u);
            const double bl = beta_w<drag::gidaspow_blended, Real>(phi, u);
            const double bound = std::abs(wy / er - 1) / (262.5 * pi * std::abs(phi - 0.8));
            CHECK(std::abs(bl / er - 1) <= bound + 10 * tol<Real>());
            CHECK(std::abs(bl / er - 1) < 0.0025); // at most 0.21% (phi = 0.3, Re = 240)
        }
        for (double phi : {0.95, 0.99, 1.0}) {
            CAPTURE(u, phi);
            const double er = beta_w<drag::ergun, Real>(phi, u), wy = beta_w<drag::wen_yu, Real>(phi, u);
            const double bl = beta_w<drag::gidaspow_blended, Real>(phi, u);
            if (wy == 0) { // phi = 1: both laws give zero
                CHECK(bl == 0);
                continue;
            }
            const double bound = std::abs(er / wy - 1) / (262.5 * pi * std::abs(phi - 0.8));
            CHECK(std::abs(bl / wy - 1) <= bound + 10 * tol<Real>());
            CHECK(std::abs(bl / wy - 1) < 0.03); // at most 2.8% (phi = 0.95, Re = 760)
        }
    }
}

TEMPLATE_TEST_CASE("Wen-Yu per particle tends to the single-sphere Schiller-Naumann drag as phi -> 1", "[drag]",
                   float, double)
{
    using Real = TestType;
    // d = 1 mm, mu = 0.1 Pa s, rho = 1000, u = 0.01 m/s (Re = 0.1 phi), V_p = pi/6 d^3.
    // Per particle, beta u V_p / (1-phi) = (pi/8) C_d rho d^2 u^2 phi^-1.65
    //   = 3 pi mu d u (1 + 0.15 Re^0.687) phi^-2.65   with Re = phi rho d u / mu (our Re);
    // VALIDATION pitfall 5 writes it 3 pi mu d v (1 + 0.15 Re^0.687) phi^-1.65, which is the same
    // expression with the phi-free Re = rho d u / mu: both agree at phi = 1 and their ratio,
    // phi^-1 (1 + 0.15 Re_phi^0.687) / (1 + 0.15 Re_1^0.687), lies in (1, 1/phi].
    const Real d = Real(0.001), mu = Real(0.1), rho = Real(1000), u = Real(0.01);
    const Real V_p = Real(pi / 6 * 1e-9);
    const vec3<Real> rel{Real(0), u, Real(0)};
    struct row {
        double phi, ours, pitfall;
    };
    const row rows[] = {
        {1.0, 9.7154226464511452e-6, 9.7154226464511452e-6},   // 3 pi 1e-4 0.01 (1 + 0.15 0.1^0.687)
        {0.999, 9.7410153412637488e-6, 9.7314743600330432e-6}, // Re = 0.0999
        {0.99, 9.9755999925402967e-6, 9.8778773006615581e-6},  // Re = 0.099
        {0.9, 1.2817723906342316e-5, 1.1560099115845731e-5},   // Re = 0.09
    };
    for (const row& r : rows) {
        CAPTURE(r.phi);
        const vec3<Real> f = drag::particle_drag_force<drag::wen_yu>(Real(r.phi), d, V_p, rel, rho, mu);
        CHECK(f.x == Real(0));
        CHECK(f.z == Real(0));
        CHECK(rel_err(f.y, r.ours) < tol<Real>());
        const double ratio = static_cast<double>(f.y) / r.pitfall;
        CHECK(ratio - 1 >= -tol<Real>());
        CHECK(ratio - 1 <= (1 - r.phi) / r.phi + tol<Real>());
        // Below phi = 1 the cell form beta V_p / (1 - phi) agrees with the per-particle form.
        if (r.phi < 1) {
            const Real beta = drag::wen_yu::beta(Real(r.phi), d, u, rho, mu);
            CHECK(rel_err(drag::drag_force(beta, Real(r.phi), V_p, rel).y, r.ours) < 10 * tol<Real>());
        }
    }
}

TEMPLATE_TEST_CASE("per-particle force equals the cell form for every law", "[drag]", float, double)
{
    using Real = TestType;
    // f = beta (v_f - v_p) V_p / (1 - phi), along the relative velocity (0.3, -0.4, 1.2) u / 1.3.
    const Real V_p = Real(pi / 6 * 8e-9); // d = 2 mm
    for (const beta_row& r : table) {
        CAPTURE(r.phi, r.u);
        const vec3<Real> rel = vec3<Real>{Real(0.3), Real(-0.4), Real(1.2)} * Real(r.u / 1.3);
        auto same = [&](const vec3<Real>& f, double beta) {
            // |(0.3, -0.4, 1.2)| = 1.3, so |v_f - v_p| = u and f = beta V_p / (1 - phi) u / 1.3 (0.3, -0.4, 1.2).
            const double k = beta * (pi / 6 * 8e-9) / (1 - r.phi) * r.u / 1.3;
            CHECK(rel_err(f.x, 0.3 * k) < 10 * tol<Real>());
            CHECK(rel_err(f.y, -0.4 * k) < 10 * tol<Real>());
            CHECK(rel_err(f.z, 1.2 * k) < 10 * tol<Real>());
        };
        same(drag::particle_drag_force<drag::ergun>(Real(r.phi), Real(d_w), V_p, rel, Real(rho_w), Real(mu_w)), r.ergun);
        same(drag::particle_drag_force<drag::wen_yu>(Real(r.phi), Real(d_w), V_p, rel, Real(rho_w), Real(mu_w)),
             r.wen_yu);
        same(drag::particle_drag_force<drag::gidaspow>(Real(r.phi), Real(d_w), V_p, rel, Real(rho_w), Real(mu_w)),
             r.gidaspow);
        same(drag::particle_drag_force<drag::gidaspow_blended>(Real(r.phi), Real(d_w), V_p, rel, Real(rho_w),
                                                               Real(mu_w)),
             r.blended);
        same(drag::drag_force(beta_w<drag::gidaspow, Real>(r.phi, r.u), Real(r.phi), V_p, rel), r.gidaspow);
    }
}

TEMPLATE_TEST_CASE("Stokes drag on a single particle at low Re", "[drag]", float, double)
{
    using Real = TestType;
    // phi = 1, d = 1 mm, mu = 0.1 Pa s, rho = 1000, u = 1e-5 m/s: Re = 1e-4,
    // F = 3 pi mu d u (1 + 0.15 Re^0.687) = 9.42477796076938e-9 * 1.00026797314 = 9.42730354807778e-9 N.
    const Real d = Real(0.001), mu = Real(0.1), rho = Real(1000);
    const Real V_p = Real(pi / 6 * 1e-9);
    const vec3<Real> rel{Real(-6e-6), Real(0), Real(8e-6)}; // |rel| = 1e-5
    for (auto f : {drag::particle_drag_force<drag::wen_yu>(Real(1), d, V_p, rel, rho, mu),
                   drag::particle_drag_force<drag::gidaspow>(Real(1), d, V_p, rel, rho, mu)}) {
        const double stokes = 3 * pi * 0.1 * 0.001 * 1e-5; // 9.42477796076938e-9 N
        const double ratio = norm_d(f) / stokes;
        CHECK(ratio >= 1);
        CHECK(ratio <= 1 + 0.15 * std::pow(1e-4, 0.687) + tol<Real>()); // within the S-N correction, 2.7e-4
        CHECK(rel_err(Real(norm_d(f)), 9.4273035480777778e-9) < 10 * tol<Real>());
        // Along the relative velocity: f x rel = 0 and f . rel > 0.
        CHECK(std::abs(static_cast<double>(f.x) * 8e-6 - static_cast<double>(f.z) * -6e-6) < 1e-6 * norm_d(f) * 1e-5);
        CHECK(f.y == Real(0));
        CHECK(static_cast<double>(f.x) * -6e-6 + static_cast<double>(f.z) * 8e-6 > 0);
    }
}

TEMPLATE_TEST_CASE("F6: drag, buoyancy and weight balance at the terminal velocities", "[drag]", float, double)
{
    using Real = TestType;
    // VALIDATION F6: d = 1 mm, rho_p = 2600, rho_f = 1000, mu = 0.1 Pa s, g = 9.81. The sphere
    // sinks at -v: v_f - v_p = (0, 0, v), drag up. Net weight (2600 - 1000) 9.81 pi/6 1e-9 =
    // 8.2184063817909e-6 N; weight alone 1.33549103704102e-5 N. The terminal velocities 8.48621e-3 (phi = 1),
    // 8.31185e-3 (cell phi = 0.992) and 1.33709e-2 (phi = 0.992, no -grad p V_p term) are given to
    // 6 digits, so the forces balance to ~3e-6 (python: 3.4e-7, 4.5e-8 and -2.4e-6).
    const Real d = Real(0.001), mu = Real(0.1), rho_f = Real(1000), rho_p = Real(2600), g = Real(9.81);
    const Real V_p = Real(pi / 6 * 1e-9);
    const vec3<Real> grad_p{Real(0), Real(0), -rho_f * g}; // hydrostatic, p rising downwards
    const vec3<Real> weight{Real(0), Real(0), -rho_p * g * V_p};
    struct row {
        double phi, v;
        bool pressure;
    };
    for (const row& r : {row{1.0, 8.48621e-3, true}, row{0.992, 8.31185e-3, true}, row{0.992, 1.33709e-2, false}}) {
        CAPTURE(r.phi, r.v, r.pressure);
        const vec3<Real> rel{Real(0), Real(0), Real(r.v)};
        vec3<Real> sum = drag::particle_drag_force<drag::gidaspow>(Real(r.phi), d, V_p, rel, rho_f, mu) + weight;
        if (r.pressure) sum += drag::pressure_gradient_force(V_p, grad_p);
        const double scale = r.pressure ? 8.2184063817909e-6 : 1.33549103704102e-5;
        CHECK(std::abs(static_cast<double>(sum.z)) / scale < 1e-5);
        CHECK(sum.x == Real(0));
        CHECK(sum.y == Real(0));
    }
    // Buoyancy alone: -V_p grad p = rho_f g V_p = 1000 * 9.81 * 5.23598775598299e-10 = 5.13650398861931e-6 N up.
    const vec3<Real> b = drag::pressure_gradient_force(V_p, grad_p);
    CHECK(rel_err(b.z, 5.13650398861931e-6) < tol<Real>());
    CHECK(b.x == Real(0));
}

TEMPLATE_TEST_CASE("F8: the Ergun beta gives the Ergun pressure drop of a fixed bed", "[drag]", float, double)
{
    using Real = TestType;
    // d = 1 mm, phi = 0.4, water (mu = 1e-3, rho = 1000); superficial velocity U, interstitial
    // u = U / phi. The force per unit volume on the fluid, beta u, balances phi (-dp/dz), so
    // -dp/dz = beta u / phi. U = 1e-3: u = 2.5e-3, beta = 150e-3 0.36/(0.4 1e-6) + 1.75 0.6 1000
    // 2.5e-3 / 1e-3 = 135000 + 2625 = 137625, beta u = 344.0625 (= phi x Ergun), / phi = 860.15625
    // (VALIDATION 860.156). U = 1e-2: beta = 161250, beta u = 4031.25, / phi = 10078.125 (10078).
    for (auto c : {std::pair<double, double>{1e-3, 860.15625}, std::pair<double, double>{1e-2, 10078.125}}) {
        const double U = c.first, u = U / 0.4;
        const Real beta = drag::ergun::beta(Real(0.4), Real(0.001), Real(u), Real(1000), Real(0.001));
        CHECK(rel_err(beta * Real(u), 0.4 * c.second) < tol<Real>());
        CHECK(rel_err(beta * Real(u) / Real(0.4), c.second) < tol<Real>());
    }
}

TEMPLATE_TEST_CASE("zero relative velocity gives zero force and no NaN", "[drag]", float, double)
{
    using Real = TestType;
    const vec3<Real> zero{Real(0), Real(0), Real(0)};
    const Real V_p = Real(pi / 6 * 8e-9);
    for (double phi : {0.4, 0.8, 0.9, 1.0}) {
        CAPTURE(phi);
        const Real b[] = {beta_w<drag::ergun, Real>(phi, 0), beta_w<drag::wen_yu, Real>(phi, 0),
                          beta_w<drag::gidaspow, Real>(phi, 0), beta_w<drag::gidaspow_blended, Real>(phi, 0)};
        for (Real beta : b) {
            CHECK(std::isfinite(beta));
            if (phi < 1) {
                CHECK(beta > 0);
            } else {
                CHECK(beta == 0);
            }
            const vec3<Real> f = drag::drag_force(beta, Real(phi), V_p, zero);
            CHECK(finite(f));
            CHECK(f == zero);
        }
        const vec3<Real> f[] = {
            drag::particle_drag_force<drag::ergun>(Real(phi), Real(d_w), V_p, zero, Real(rho_w), Real(mu_w)),
            drag::particle_drag_force<drag::wen_yu>(Real(phi), Real(d_w), V_p, zero, Real(rho_w), Real(mu_w)),
            drag::particle_drag_force<drag::gidaspow>(Real(phi), Real(d_w), V_p, zero, Real(rho_w), Real(mu_w)),
            drag::particle_drag_force<drag::gidaspow_blended>(Real(phi), Real(d_w), V_p, zero, Real(rho_w),
                                                              Real(mu_w))};
        for (const vec3<Real>& fi : f) {
            CHECK(finite(fi));
            CHECK(fi == zero);
        }
        CHECK(drag::fluid_force_density(beta_w<drag::wen_yu, Real>(phi, 0), zero) == zero);
    }
    // Wen-Yu's Stokes limit: 18 mu (1-phi) phi^-2.65 / d^2 = 18e-3 * 0.1 * 1.32207882668 / 4e-6
    // = 594.935472008 at phi = 0.9; Ergun: 150e-3 * 0.01 / (0.9 * 4e-6) = 416.666666667.
    CHECK(rel_err(beta_w<drag::wen_yu, Real>(0.9, 0), 594.93547200792185) < tol<Real>());
    CHECK(rel_err(beta_w<drag::ergun, Real>(0.9, 0), 416.66666666666667) < tol<Real>());
    // The cell form at phi = 1 (beta = 0 and 1 - phi = 0) returns zero rather than 0/0.
    const vec3<Real> f1 = drag::drag_force(Real(0), Real(1), V_p, vec3<Real>{Real(1), Real(0), Real(0)});
    CHECK(finite(f1));
    CHECK(f1 == zero);
}

TEMPLATE_TEST_CASE("the fluid receives the equal and opposite force", "[drag]", float, double)
{
    using Real = TestType;
    // One cell of V_cell = (5 mm)^3 = 1.25e-7 m^3 at phi = 0.7 holds solids of 3.75e-8 m^3 in
    // three particles (1.5e-8, 1.25e-8, 1e-8 m^3). beta = Gidaspow at phi = 0.7, u = 0.01:
    // 7446.42857142857 N s/m^4; v_f - v_p = (0.006, 0, -0.008).
    // Particles: sum_i beta (v_f - v_p) V_i / 0.3 = beta (v_f - v_p) V_cell
    //   = 7446.42857142857 * 1.25e-7 * (0.006, 0, -0.008) = (5.58482142857e-6, 0, -7.44642857143e-6) N;
    // fluid: fluid_force_density * V_cell = the negative.
    const Real phi = Real(0.7), V_cell = Real(1.25e-7);
    const vec3<Real> rel{Real(0.006), Real(0), Real(-0.008)};
    const Real beta = beta_w<drag::gidaspow, Real>(0.7, 0.01);
    vec3<Real> on_particles{Real(0), Real(0), Real(0)};
    for (double V : {1.5e-8, 1.25e-8, 1e-8}) on_particles += drag::drag_force(beta, phi, Real(V), rel);
    const vec3<Real> on_fluid = drag::fluid_force_density(beta, rel) * V_cell;
    CHECK(rel_err(on_particles.x, 5.5848214285714286e-6) < 10 * tol<Real>());
    CHECK(rel_err(on_particles.z, -7.4464285714285714e-6) < 10 * tol<Real>());
    CHECK(on_particles.y == Real(0));
    CHECK(rel_err(on_fluid.x, -5.5848214285714286e-6) < 10 * tol<Real>());
    CHECK(rel_err(on_fluid.z, 7.4464285714285714e-6) < 10 * tol<Real>());
    const vec3<Real> total = on_particles + on_fluid;
    CHECK(std::abs(static_cast<double>(total.x)) < 10 * tol<Real>() * 5.58e-6);
    CHECK(std::abs(static_cast<double>(total.z)) < 10 * tol<Real>() * 7.45e-6);
    // The force on the particle points along v_f - v_p, on the fluid against it.
    CHECK(dot(on_particles, rel) > 0);
    CHECK(dot(on_fluid, rel) < 0);
}

TEMPLATE_TEST_CASE("drag inputs are checked on the host with messages naming the value", "[drag][errors]", float,
                   double)
{
    using Real = TestType;
    const Real d = Real(0.5), rho = Real(1000), mu = Real(0.5);
    CHECK_NOTHROW(drag::check(Real(1), d, rho, mu));
    CHECK_NOTHROW(drag::check(Real(0.5), d, rho, mu));
    CHECK_NOTHROW(drag::ergun::validate());
    CHECK_NOTHROW(drag::gidaspow_blended::validate());

    CHECK_THROWS_AS(drag::check(Real(1.5), d, rho, mu), sphere::error);
    CHECK_THROWS_WITH(drag::check(Real(1.5), d, rho, mu), "sphere: drag: porosity phi = 1.5 is outside (0, 1]");
    CHECK_THROWS_WITH(drag::check(Real(0), d, rho, mu), "sphere: drag: porosity phi = 0 is outside (0, 1]");
    CHECK_THROWS_WITH(drag::check(Real(-0.5), d, rho, mu), "sphere: drag: porosity phi = -0.5 is outside (0, 1]");
    CHECK_THROWS_WITH(drag::check(std::numeric_limits<Real>::quiet_NaN(), d, rho, mu),
                      Contains("porosity phi = ") && Contains("nan is outside (0, 1]"));
    CHECK_THROWS_WITH(drag::check(Real(0.5), Real(-0.5), rho, mu),
                      "sphere: drag: particle diameter d = -0.5 m must be positive and finite");
    CHECK_THROWS_WITH(drag::check(Real(0.5), Real(0), rho, mu),
                      "sphere: drag: particle diameter d = 0 m must be positive and finite");
    CHECK_THROWS_WITH(drag::check(Real(0.5), std::numeric_limits<Real>::infinity(), rho, mu),
                      "sphere: drag: particle diameter d = inf m must be positive and finite");
    CHECK_THROWS_WITH(drag::check(Real(0.5), d, Real(0), mu),
                      "sphere: drag: fluid density rho_f = 0 kg/m^3 must be positive and finite");
    CHECK_THROWS_WITH(drag::check(Real(0.5), d, rho, Real(-2)),
                      "sphere: drag: fluid viscosity mu_f = -2 Pa s must be positive and finite");
    CHECK_THROWS_WITH(drag::check_fluid(rho, std::numeric_limits<Real>::quiet_NaN()),
                      Contains("fluid viscosity mu_f = ") && Contains("nan Pa s"));
    CHECK_THROWS_WITH(drag::check(Real(2), d, rho, mu, "fluid cell (1, 2, 3)"),
                      "sphere: fluid cell (1, 2, 3): porosity phi = 2 is outside (0, 1]");
    CHECK_THROWS_WITH(drag::check_porosity(Real(1.25), "cell 7"), "sphere: cell 7: porosity phi = 1.25 is outside (0, 1]");
    CHECK_THROWS_WITH(drag::check_diameter(Real(-1)), "sphere: drag: particle diameter d = -1 m must be positive and finite");
}

} // namespace test_drag
