// The projection Navier-Stokes solver (include/sphere/fluid/navier_stokes.cuh; docs/fluid.md),
// on the fluid alone (porosity 1, no particles), cases of ../shared/VALIDATION.md:
// - F3: a quiescent fluid needs zero Poisson iterations and stays exactly at rest; a
//   hydrostatic column under a no-flow bottom and a prescribed top pressure, with and without a
//   sine-modulated top pressure, has the hydrostatic pressure and no velocity;
// - F4: a pressure difference between two prescribed-pressure layers accelerates the fluid
//   uniformly, with a linear pressure;
// - F5: a decaying shear wave decays at the rate of the discrete (3-point) viscous operator;
// - an inflow bottom (a prescribed superficial velocity) with a prescribed top pressure carries
//   its flux through every layer, whatever the porosity;
// - the time-step limits, a non-converged pressure solve and bad parameters are errors;
// - both Poisson solvers give the same flow.
#include <catch2/catch.hpp>

#include <sphere/fluid.cuh>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_fluid_solver {

namespace {

using sphere::vec3;

template <class Real>
sphere::fluid_grid<Real> column_grid(int nx, int ny, int nz, Real lx, Real ly, Real lz)
{
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    box.hi = {lx, ly, lz};
    return sphere::fluid_grid<Real>::make(box, nx, ny, nz);
}

template <class Real>
Real tolerance(double for_double, double for_float)
{
    return Real(sizeof(Real) == sizeof(double) ? for_double : for_float);
}

template <class Fluid>
double max_speed(const Fluid& s)
{
    double m = 0;
    for (int a = 0; a < 3; ++a)
        for (auto v : s.face_velocity(a)) m = std::max(m, std::fabs(double(v)));
    return m;
}

} // namespace

TEMPLATE_TEST_CASE("F3: a quiescent fluid stays at rest with zero Poisson iterations", "[fluid][F3]", float, double)
{
    using Real = TestType;
    const auto g = column_grid<Real>(4, 4, 10, Real(0.4), Real(0.4), Real(1));
    for (auto top : {sphere::fluid_boundary<Real>::no_flow(), sphere::fluid_boundary<Real>::prescribed_pressure(0)}) {
        sphere::fluid_params<Real> prm;
        prm.density = 1000;
        prm.top = top;
        for (auto criterion : {sphere::poisson_criterion::relative_residual, sphere::poisson_criterion::normalized_change}) {
            prm.poisson.criterion = criterion;
            sphere::navier_stokes<Real, sphere::host> fluid(g, prm);  // conjugate gradients
            sphere::navier_stokes<Real, sphere::host, sphere::jacobi_poisson<Real, sphere::host>> jacobi(g, prm);
            for (int n = 0; n < 5; ++n) {
                fluid.step(Real(1e-3));
                jacobi.step(Real(1e-3));
                CHECK(fluid.last_solve().iterations == 0u);
                CHECK(fluid.last_solve().converged);
                CHECK(jacobi.last_solve().iterations == 0u);
                CHECK(jacobi.last_solve().converged);
            }
            for (Real p : fluid.pressure()) REQUIRE(p == Real(0));
            for (Real p : jacobi.pressure()) REQUIRE(p == Real(0));
            CHECK(max_speed(fluid) == 0.0);
        }
    }
}

TEMPLATE_TEST_CASE("F3: a hydrostatic column under a prescribed top pressure", "[fluid][F3]", float, double)
{
    using Real = TestType;
    const double rho = 1000, grav = 9.81, H = 1;
    const auto g = column_grid<Real>(4, 4, 10, Real(0.4), Real(0.4), Real(H));
    for (Real beta : {Real(0), Real(1)}) {
        for (Real amplitude : {Real(0), Real(250)}) {
            CAPTURE(beta, amplitude);
            sphere::fluid_params<Real> prm;
            prm.density = Real(rho);
            prm.beta = beta;
            prm.gravity = {0, 0, Real(-grav)};
            prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0, amplitude, Real(2), Real(0.3));
            prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-12 : 1e-4;
            sphere::navier_stokes<Real, sphere::host> fluid(g, prm);
            const Real dt = Real(1e-3);
            for (int n = 0; n < 40; ++n) fluid.step(dt);
            const double t = fluid.time();
            const double top = double(amplitude) * std::sin(2 * 3.14159265358979323846 * 2 * t + 0.3);
            const auto p = fluid.pressure();
            // The prescribed value sits at the centre of the top cell, 0.9 m above the bottom
            // cell's centre: 8829 Pa there with no modulation.
            for (int k = 0; k < 10; ++k) {
                const double expected = top + rho * grav * (0.95 - (k + 0.5) * 0.1);
                CAPTURE(k);
                CHECK(double(p[g.field_index(1, 2, k)]) ==
                      Approx(expected).margin(tolerance<Real>(1e-6, 1e-4) * rho * grav * H));
            }
            CHECK(double(p[g.field_index(0, 0, 0)]) == Approx(top + 8829.0).margin(tolerance<Real>(1e-6, 1e-4) * rho * grav * H));
            // float: the pressure solve stops at relative residual 1e-4 (its round-off floor
            // is ~2e-5), which leaves ~1e-3 of g dt in the velocity.
            CHECK(max_speed(fluid) < tolerance<Real>(1e-10, 1e-5));
        }
    }
}

TEMPLATE_TEST_CASE("F4: a pressure difference accelerates the fluid uniformly", "[fluid][F4]", float, double)
{
    using Real = TestType;
    const auto g = column_grid<Real>(4, 4, 10, Real(0.4), Real(0.4), Real(1));
    sphere::fluid_params<Real> prm;
    prm.density = 1000;
    prm.bottom = sphere::fluid_boundary<Real>::prescribed_pressure(10);
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-12 : 1e-4;
    sphere::navier_stokes<Real, sphere::host> fluid(g, prm);
    const Real dt = Real(1e-3);
    for (int n = 0; n < 100; ++n) fluid.step(dt);
    // 10 Pa over the 0.9 m between the centres of the two prescribed layers.
    const double v = 10.0 / 0.9 / 1000.0 * fluid.time();
    REQUIRE(fluid.time() == Approx(0.1));  // v = 0.0111111 t m/s
    const auto w = fluid.face_velocity(2);
    for (int k = -1; k < 10; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                CAPTURE(i, j, k);
                CHECK(double(w[g.field_index(i, j, k)]) == Approx(v).epsilon(tolerance<Real>(1e-6, 1e-4)));
            }
    for (int a = 0; a < 2; ++a)
        for (Real u : fluid.face_velocity(a)) CHECK(std::fabs(double(u)) < tolerance<Real>(1e-10, 1e-6));
    const auto p = fluid.pressure();
    for (int k = 0; k < 10; ++k) {
        CAPTURE(k);
        CHECK(double(p[g.field_index(3, 1, k)]) == Approx(10.0 * (1 - k / 9.0)).margin(tolerance<Real>(1e-6, 1e-4) * 10));
    }
}

TEMPLATE_TEST_CASE("F5: a shear wave decays at the rate of the discrete viscous operator", "[fluid][F5]", float, double)
{
    using Real = TestType;
    const double L = 0.1, rho = 1000, mu = 1, amplitude = 0.01;
    const auto g = column_grid<Real>(20, 4, 4, Real(L), Real(0.02), Real(0.02));
    sphere::fluid_params<Real> prm;
    prm.density = Real(rho);
    prm.viscosity = Real(mu);
    sphere::navier_stokes<Real, sphere::host> fluid(g, prm);
    const double k = 2 * 3.14159265358979323846 / L;
    fluid.set_velocity([&](const vec3<Real>& x) {
        return vec3<Real>{0, Real(amplitude * std::sin(k * double(x.x))), 0};
    });
    const Real dt = Real(1e-4);
    for (int n = 0; n < 2500; ++n) fluid.step(dt);
    REQUIRE(fluid.time() == Approx(0.25));
    // Amplitude: least-squares projection of v_y on sin(k x) over the cell centres.
    const auto v = fluid.face_velocity(1);
    double num = 0, den = 0;
    for (int kz = 0; kz < 4; ++kz)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 20; ++i) {
                const double s = std::sin(k * (i + 0.5) * L / 20);
                num += double(v[g.field_index(i, j, kz)]) * s;
                den += s * s;
            }
    const double measured = num / den / amplitude;
    // Discrete decay rate nu (2 - 2 cos(k dx)) / dx^2 = 3.915479 1/s: exp(-0.25 rate) = 0.375736
    // (the continuum rate nu k^2 = 3.947842 1/s would give 0.372708).
    CHECK(measured == Approx(0.375736).epsilon(0.01));
    CHECK(std::fabs(measured - 0.375736) < std::fabs(measured - 0.372708));
    const auto p = fluid.pressure();
    double pmax = -1e300, pmin = 1e300;
    for (int kz = 0; kz < 4; ++kz)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 20; ++i) {
                pmax = std::max(pmax, double(p[g.field_index(i, j, kz)]));
                pmin = std::min(pmin, double(p[g.field_index(i, j, kz)]));
            }
    CHECK(pmax - pmin < tolerance<Real>(1e-9, 1e-4));
}

TEMPLATE_TEST_CASE("inflow: a prescribed superficial velocity at the bottom, the pressure at the top", "[fluid]", float,
                   double)
{
    using Real = TestType;
    // U = 2 mm/s enters a 4 x 4 x 10 column at the bottom and leaves through the prescribed
    // top layer, under gravity. Without a porosity (phi = 1) the flow is uniform at once: every
    // z face carries w = U and the pressure is hydrostatic. With a porosity that varies from layer
    // to layer (held, no particles) the superficial velocity phi_f w is U on every z face
    // (continuity), the interstitial w = U / phi_f.
    const double U = 2e-3, rho = 1000, grav = 9.81;
    const auto g = column_grid<Real>(4, 4, 10, Real(0.4), Real(0.4), Real(1));
    sphere::fluid_params<Real> prm;
    prm.density = Real(rho);
    prm.viscosity = Real(1e-3);
    prm.gravity = {0, 0, Real(-grav)};
    prm.bottom = sphere::fluid_boundary<Real>::inflow(Real(U));
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-12 : 1e-5;
    for (bool porous : {false, true}) {
        CAPTURE(porous);
        sphere::navier_stokes<Real, sphere::host> fluid(g, prm);
        std::vector<Real> phi(g.field_size(), Real(1)), rate(g.field_size(), Real(0)), d(g.field_size(), Real(0));
        std::vector<vec3<Real>> v(g.field_size(), vec3<Real>{0, 0, 0});
        if (porous)
            for (int k = 0; k < 10; ++k)
                for (int j = 0; j < 4; ++j)
                    for (int i = 0; i < 4; ++i) phi[g.field_index(i, j, k)] = Real(0.45 + 0.05 * (k % 3));
        fluid.set_porosity(sphere::porosity_view<Real>{g, Real(0.05), phi.data(), rate.data(), v.data(), d.data()});
        for (int n = 0; n < 20; ++n) fluid.step(Real(1e-3));
        const auto w = fluid.face_velocity(2);
        const auto por = fluid.porosity();
        // The inflow face and the faces between cells (the top face, above the prescribed
        // layer, copies the face below it).
        for (int k = -1; k < 9; ++k)
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) {
                    CAPTURE(i, j, k);
                    // The face's porosity: the mean of its two cells (the inflow face: the end cell's).
                    const double below = double(por[g.field_index(i, j, k < 0 ? 0 : k)]);
                    const double above = double(por[g.field_index(i, j, k + 1 > 9 ? 9 : k + 1)]);
                    const double phi_f = 0.5 * (below + above);
                    CHECK(phi_f * double(w[g.field_index(i, j, k)]) == Approx(U).epsilon(tolerance<Real>(1e-9, 2e-4)));
                }
        for (int a = 0; a < 2; ++a)
            for (Real u : fluid.face_velocity(a)) CHECK(std::fabs(double(u)) < tolerance<Real>(1e-12, 1e-6));
        if (!porous) {
            const auto p = fluid.pressure();
            for (int k = 0; k < 10; ++k) {
                CAPTURE(k);
                CHECK(double(p[g.field_index(2, 1, k)]) ==
                      Approx(rho * grav * (0.95 - (k + 0.5) * 0.1)).margin(tolerance<Real>(1e-6, 1e-3) * rho * grav));
            }
        }
    }

    // An inflow end needs the pressure prescribed at the other end; a velocity must be finite.
    sphere::fluid_params<Real> bad = prm;
    bad.top = sphere::fluid_boundary<Real>::no_flow();
    CHECK_THROWS_WITH((sphere::navier_stokes<Real, sphere::host>(g, bad)),
                      Catch::Contains("fluid: an inflow bottom (velocity 0.002") &&
                          Catch::Contains("m/s) needs a prescribed pressure at the top") && Catch::Contains("it is no_flow"));
    bad.top = sphere::fluid_boundary<Real>::inflow(Real(U));
    CHECK_THROWS_WITH((sphere::navier_stokes<Real, sphere::host>(g, bad)), Catch::Contains("it is inflow"));
    bad = prm;
    bad.bottom = sphere::fluid_boundary<Real>::inflow(std::numeric_limits<Real>::infinity());
    CHECK_THROWS_WITH((sphere::navier_stokes<Real, sphere::host>(g, bad)),
                      Catch::Contains("fluid: bottom.velocity = inf m/s is not finite"));
}

TEMPLATE_TEST_CASE("the fluid solver refuses unstable time steps, unconverged solves and bad parameters", "[fluid]", float,
                   double)
{
    using Real = TestType;
    const auto g = column_grid<Real>(4, 4, 10, Real(0.4), Real(0.4), Real(1));
    sphere::fluid_params<Real> prm;
    prm.viscosity = Real(1000);  // diffusive limit rho / (2 mu (3 / (0.1 m)^2)) = 1.66e-3 s
    sphere::navier_stokes<Real, sphere::host> fluid(g, prm);
    CHECK(double(fluid.stable_time_step()) == Approx(997.05 / (2 * 1000 * 300)).epsilon(1e-5));
    CHECK_THROWS_WITH(fluid.step(Real(0.01)), Catch::Contains("exceeds the stability limit"));
    CHECK_THROWS_WITH(fluid.step(Real(-1)), Catch::Contains("dt = -1"));
    CHECK(fluid.time() == 0.0);

    sphere::fluid_params<Real> hard;
    hard.gravity = {0, 0, Real(-9.81)};
    hard.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    hard.poisson.max_iterations = 2;
    sphere::navier_stokes<Real, sphere::host> limited(g, hard);
    CHECK_THROWS_WITH(limited.step(Real(1e-3)), Catch::Contains("did not converge") && Catch::Contains("after 2 iterations"));
    CHECK(limited.time() == 0.0);

    // A porosity outside (0, 1] is found by the next step (set_porosity reads nothing back),
    // and that step advances nothing: the velocity field stays as it was set.
    sphere::navier_stokes<Real, sphere::host> porous(g, sphere::fluid_params<Real>{});
    porous.set_velocity([](const vec3<Real>&) { return vec3<Real>{Real(1e-3), 0, 0}; });
    std::vector<Real> phi(g.field_size(), Real(0.5)), rate(g.field_size(), Real(0)), d(g.field_size(), Real(0));
    std::vector<vec3<Real>> v(g.field_size(), vec3<Real>{0, 0, 0});
    phi[g.field_index(2, 1, 7)] = Real(0);
    porous.set_porosity(sphere::porosity_view<Real>{g, Real(0.05), phi.data(), rate.data(), v.data(), d.data()});
    const std::vector<Real> u_before = porous.face_velocity(0);
    CHECK_THROWS_WITH(porous.step(Real(1e-3)), Catch::Contains("a cell has porosity 0"));
    CHECK(porous.face_velocity(0) == u_before);
    CHECK(porous.time() == 0.0);

    sphere::fluid_params<Real> bad;
    bad.viscosity = Real(-1);
    CHECK_THROWS_WITH((sphere::navier_stokes<Real, sphere::host>(g, bad)), Catch::Contains("viscosity = -1"));
    bad = {};
    bad.beta = Real(1.5);
    CHECK_THROWS_WITH((sphere::navier_stokes<Real, sphere::host>(g, bad)), Catch::Contains("beta = 1.5"));
    bad = {};
    bad.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    const auto flat = column_grid<Real>(4, 4, 2, Real(0.4), Real(0.4), Real(0.2));
    CHECK_THROWS_WITH((sphere::navier_stokes<Real, sphere::host>(flat, bad)), Catch::Contains("nz = 2"));
    bad = {};
    bad.top = sphere::fluid_boundary<Real>::prescribed_pressure(std::numeric_limits<Real>::quiet_NaN());
    CHECK_THROWS_WITH((sphere::navier_stokes<Real, sphere::host>(g, bad)), Catch::Contains("fluid: top.pressure = nan Pa is not finite"));
}

TEST_CASE("Jacobi and conjugate gradients give the same flow", "[fluid]")
{
    using Real = double;
    // A column driven by a sine-modulated bottom pressure under gravity, with a shear wave: every
    // term of the predictor and a non-trivial pressure solve at each step.
    const auto g = column_grid<Real>(8, 4, 12, Real(0.08), Real(0.04), Real(0.12));
    sphere::fluid_params<Real> prm;
    prm.density = 1000;
    prm.viscosity = Real(0.05);
    prm.gravity = {0, 0, Real(-9.81)};
    prm.bottom = sphere::fluid_boundary<Real>::prescribed_pressure(Real(1200), Real(50), Real(5), Real(0));
    prm.poisson.tolerance = 1e-12;
    sphere::navier_stokes<Real, sphere::host, sphere::jacobi_poisson<Real, sphere::host>> jacobi(g, prm);
    sphere::navier_stokes<Real, sphere::host, sphere::cg_poisson<Real, sphere::host>> cg(g, prm);
    const auto shear = [](const vec3<Real>& x) {
        return vec3<Real>{0, Real(0.01) * std::sin(2 * 3.14159265358979323846 * x.x / 0.08), 0};
    };
    jacobi.set_velocity(shear);
    cg.set_velocity(shear);
    for (int n = 0; n < 20; ++n) {
        jacobi.step(Real(1e-3));
        cg.step(Real(1e-3));
    }
    CHECK(cg.last_solve().iterations < jacobi.last_solve().iterations);
    const auto pj = jacobi.pressure(), pc = cg.pressure();
    for (int k = 0; k < 12; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 8; ++i) {
                const std::size_t c = g.field_index(i, j, k);
                REQUIRE(double(pc[c]) == Approx(double(pj[c])).epsilon(1e-9).margin(1e-9));
            }
    for (int a = 0; a < 3; ++a) {
        const auto vj = jacobi.face_velocity(a), vc = cg.face_velocity(a);
        for (std::size_t c = 0; c < vj.size(); ++c) REQUIRE(double(vc[c]) == Approx(double(vj[c])).margin(1e-12));
    }
}

} // namespace test_fluid_solver
