// The two-way fluid-particle coupling (include/sphere/fluid/coupling.cuh; docs/fluid.md,
// *Coupling*), cases of ../shared/VALIDATION.md:
// - F6: one particle settling in a fluid column reaches the Schiller-Naumann terminal slip
//   velocity for its cell's porosity, with buoyancy from the pressure gradient, and the larger
//   one without it; its energy changes by the work the fluid did on it;
// - F8: the pressure drop through a fixed bed follows Ergun for the porosity the code computed,
//   and phi times Ergun when the pressure force is not exchanged; driven by a prescribed inflow
//   at the bottom, the bed carries that flux and the pressure drops by Ergun's gradient;
// - F10: particles moving through a fluid at rest exchange x-momentum with it, conserving the
//   total within 1%, and share the common final velocity;
// - hindered settling in a closed box: the fluid's flux through mid-height equals the
//   particles' volume flux through it (the porosity conserves the solid volume), and the
//   settling velocity is steady;
// - a coupled run is bit-identical when repeated with the same thread count;
// - a fluid step longer than a particle's response time is refused.
#include <catch2/catch.hpp>

#include <sphere/dem.cuh>
#include <sphere/fluid.cuh>

#include "support.hpp"

#include <omp.h>

#include <cmath>
#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_coupling {

namespace {

using sphere::vec3;
constexpr double pi = 3.14159265358979323846;

template <class Real>
using sim_t = sphere::simulation<Real, sphere::host>;
template <class Real, class Drag = sphere::drag::gidaspow>
using coupling_t = sphere::fluid_coupling<Real, sphere::host, Drag>;  // the default pressure solver (mg_poisson)

template <class Real>
sphere::settings<Real> periodic_column(double lx, double ly, double lz, double k_n)
{
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(lx), Real(ly), Real(lz)};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = s.wall.k_n = s.contact.k_t = s.wall.k_t = Real(k_n);
    return s;
}

} // namespace

TEST_CASE("F6 reference values: terminal_speed of the Wen-Yu law", "[coupling][F6]")
{
    // VALIDATION F6: d = 1 mm, rho_p = 2600, rho_f = 1000, mu = 0.1 Pa s.
    const double d = 1e-3, V = pi / 6 * d * d * d, g = 9.81;
    const double buoyant = (2600 - 1000) * g * V, heavy = 2600 * g * V;
    CHECK(sphere::drag::terminal_speed<sphere::drag::wen_yu>(buoyant, 1.0, d, 1000, 0.1) == Approx(8.48621e-3).epsilon(1e-5));
    CHECK(sphere::drag::terminal_speed<sphere::drag::wen_yu>(buoyant, 0.992, d, 1000, 0.1) == Approx(8.31185e-3).epsilon(1e-5));
    CHECK(sphere::drag::terminal_speed<sphere::drag::wen_yu>(heavy, 0.992, d, 1000, 0.1) == Approx(1.33709e-2).epsilon(1e-5));
}

TEMPLATE_TEST_CASE("F6: one particle settles at the terminal slip velocity of its cell's porosity", "[coupling][F6]",
                   float, double)
{
    using Real = TestType;
    const double d = 1e-3, rho_p = 2600, rho_f = 1000, mu = 0.1, g = 9.81, cell = 5e-3;
    for (bool pressure_force : {true, false}) {
        CAPTURE(pressure_force);
        sphere::settings<Real> s = periodic_column<Real>(4 * cell, 4 * cell, 40 * cell, 100);
        s.gravity = {0, 0, Real(-g)};
        sphere::particle<Real> p;
        p.position = {Real(1.5 * cell), Real(1.5 * cell), Real(34.5 * cell)};
        p.radius = Real(d / 2);
        p.density = Real(rho_p);
        sim_t<Real> sim(s, {p});

        sphere::fluid_params<Real> prm;
        prm.density = Real(rho_f);
        prm.viscosity = Real(mu);
        prm.gravity = s.gravity;
        prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
        prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-4;
        sphere::coupling_options opt;
        opt.dem_steps = 20;
        opt.pressure_force = pressure_force;
        coupling_t<Real> coupled(sphere::fluid_grid<Real>::make(s.box, 4, 4, 40), prm, opt);
        // 0.03 s is 20 particle response times (1.44e-3 s).
        const double e0 = double(sim.energy().total());
        while (sim.time() < 0.03) coupled.step(sim);
        // Energy: what the particle gained (kinetic + potential) is the fluid's work on it, up to
        // the semi-implicit Euler step's -|F|^2 dt^2 / (2 m) per step, ~1e-4 of it here (most
        // of it while the particle accelerates: measured 6e-5 and 8e-5).
        const double gained = double(sim.energy().total()) - e0;
        CHECK(coupled.work_on_particles() < 0);
        INFO("energy gained " << gained << " J, fluid work " << coupled.work_on_particles() << " J, relative difference "
                              << (gained - coupled.work_on_particles()) / coupled.work_on_particles());
        CHECK(gained == Approx(coupled.work_on_particles()).epsilon(sizeof(Real) == 8 ? 2e-4 : 1e-3));

        const auto snap = sim.snapshot();
        const vec3<Real> x = snap.position(0);
        const auto& grid = coupled.fluid().grid();
        const int k = int(x.z / Real(cell));
        const std::size_t c = grid.field_index(1, 1, k);
        const double phi = coupled.fluid().porosity()[c];
        const double v_f = coupled.fluid().cell_velocity()[c].z;
        const double slip = v_f - snap.v[0].z;
        const double V = pi / 6 * d * d * d;
        const double force = (pressure_force ? rho_p - rho_f : rho_p) * g * V;
        const double expected = sphere::drag::terminal_speed<sphere::drag::gidaspow>(force, phi, d, rho_f, mu);
        INFO("particle at z = " << x.z << " m in cell " << k << " with porosity " << phi << "; v_p = " << snap.v[0].z
                                << ", v_f = " << v_f << " m/s");
        CHECK(phi > 0.99);
        CHECK(phi < 0.997);
        CHECK(slip == Approx(expected).epsilon(sizeof(Real) == 8 ? 0.02 : 0.03));
        // The particle falls (it has not reached the floor).
        CHECK(double(x.z) > 0.05);
    }
}

TEMPLATE_TEST_CASE("F8: the pressure drop through a fixed bed follows Ergun for the computed porosity", "[coupling][F8]",
                   float, double)
{
    using Real = TestType;
    // Simple cubic bed, d = 1 mm, spacing 1 mm (solid fraction pi/6), fluid cells of 2 mm. The
    // lattice sits 0.262887 spacings off the cell centres, where the cell-sphere porosity
    // equals the bed's 1 - pi/6 = 0.476401: then the solid volume the porosity sees in a cell
    // is that of the particles whose centres lie in it, which the per-particle force
    // f_d V_p / (1 - phi) assumes (docs/fluid.md, *Coupling*). Water; flow upwards.
    const double d = 1e-3, cell = 2e-3, mu = 1e-3, rho = 1000, offset = 1 - 0.262886786;
    const int nz = 12;
    sphere::settings<Real> s = periodic_column<Real>(4 * cell, 4 * cell, nz * cell, 1e-4);
    s.dt = Real(5e-4);
    const std::vector<sphere::particle<Real>> bed = sphere_test::fixed_lattice_bed<Real>(nz, d, offset);
    for (bool pressure_force : {true, false}) {
        CAPTURE(pressure_force);
        sim_t<Real> sim(s, bed);
        sphere::fluid_params<Real> prm;
        prm.density = Real(rho);
        prm.viscosity = Real(mu);
        prm.bottom = sphere::fluid_boundary<Real>::prescribed_pressure(Real(pressure_force ? 8 : 3));
        prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
        prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-4;
        sphere::coupling_options opt;
        opt.dem_steps = 1;
        opt.pressure_force = pressure_force;
        coupling_t<Real, sphere::drag::ergun> coupled(sphere::fluid_grid<Real>::make(s.box, 4, 4, nz), prm, opt);
        for (int n = 0; n < 100; ++n) coupled.step(sim);  // 0.05 s, ~10 fluid response times

        const auto& grid = coupled.fluid().grid();
        const auto p = coupled.fluid().pressure();
        const auto w = coupled.fluid().face_velocity(2);
        const auto phi = coupled.fluid().porosity();
        double U = 0, phi_bed = 0, count = 0;
        for (int k = 2; k < nz - 3; ++k)
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) {
                    const std::size_t c = grid.field_index(i, j, k);
                    const double phi_f = 0.5 * (phi[c] + phi[grid.field_index(i, j, k + 1)]);
                    U += phi_f * double(w[c]);
                    phi_bed += phi[c];
                    count += 1;
                }
        U /= count;
        phi_bed /= count;
        double p_lo = 0, p_hi = 0;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                p_lo += double(p[grid.field_index(i, j, 2)]) / 16;
                p_hi += double(p[grid.field_index(i, j, nz - 3)]) / 16;
            }
        const double gradient = (p_lo - p_hi) / ((nz - 5) * cell);
        const double ergun = 150 * mu * (1 - phi_bed) * (1 - phi_bed) * U / (phi_bed * phi_bed * phi_bed * d * d) +
                             1.75 * (1 - phi_bed) * rho * U * U / (phi_bed * phi_bed * phi_bed * d);
        INFO("U = " << U << " m/s, porosity " << phi_bed << ", -dp/dz = " << gradient << " Pa/m, Ergun " << ergun);
        CHECK(phi_bed == Approx(1 - pi / 6).epsilon(1e-4));
        CHECK(U > 3e-4);
        CHECK(U < 3e-3);
        CHECK(gradient == Approx(pressure_force ? ergun : phi_bed * ergun).epsilon(0.02));
    }
}

TEMPLATE_TEST_CASE("inflow through a fixed bed: the prescribed superficial velocity and Ergun's pressure drop",
                   "[coupling][F8]", float, double)
{
    using Real = TestType;
    // F8's bed (simple cubic, d = 1 mm, solid fraction pi/6, cells of 2 mm), driven by a
    // prescribed superficial velocity U = 1 mm/s at the bottom with p = 0 on the top layer
    // instead of by two pressures: the flux through every interior face is U, and the pressure
    // drops by Ergun's gradient at U (VALIDATION F8: 860.156 Pa/m at phi = 0.4; here phi =
    // 1 - pi/6, 2%).
    const double d = 1e-3, cell = 2e-3, mu = 1e-3, rho = 1000, U = 1e-3;
    const int nz = 12;
    sphere::settings<Real> s = periodic_column<Real>(4 * cell, 4 * cell, nz * cell, 1e-4);
    s.dt = Real(5e-4);
    sim_t<Real> sim(s, sphere_test::fixed_lattice_bed<Real>(nz, d, 0.5));
    sphere::fluid_params<Real> prm;
    prm.density = Real(rho);
    prm.viscosity = Real(mu);
    prm.bottom = sphere::fluid_boundary<Real>::inflow(Real(U));
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-4;
    sphere::coupling_options opt;
    opt.dem_steps = 1;
    coupling_t<Real, sphere::drag::ergun> coupled(sphere::fluid_grid<Real>::make(s.box, 4, 4, nz), prm, opt);
    for (int n = 0; n < 100; ++n) coupled.step(sim);

    const auto& grid = coupled.fluid().grid();
    const auto p = coupled.fluid().pressure();
    const auto w = coupled.fluid().face_velocity(2);
    const auto phi = coupled.fluid().porosity();
    double phi_bed = 0, count = 0;
    for (int k = 2; k < nz - 3; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                const std::size_t c = grid.field_index(i, j, k);
                const double phi_f = 0.5 * (phi[c] + phi[grid.field_index(i, j, k + 1)]);
                CHECK(phi_f * double(w[c]) == Approx(U).epsilon(sizeof(Real) == 8 ? 1e-8 : 1e-3));
                phi_bed += phi[c];
                count += 1;
            }
    phi_bed /= count;
    double p_lo = 0, p_hi = 0;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            p_lo += double(p[grid.field_index(i, j, 2)]) / 16;
            p_hi += double(p[grid.field_index(i, j, nz - 3)]) / 16;
        }
    const double gradient = (p_lo - p_hi) / ((nz - 5) * cell);
    const double ergun = 150 * mu * (1 - phi_bed) * (1 - phi_bed) * U / (phi_bed * phi_bed * phi_bed * d * d) +
                         1.75 * (1 - phi_bed) * rho * U * U / (phi_bed * phi_bed * phi_bed * d);
    INFO("porosity " << phi_bed << ", -dp/dz = " << gradient << " Pa/m, Ergun " << ergun);
    CHECK(phi_bed == Approx(1 - pi / 6).epsilon(1e-4));
    CHECK(gradient == Approx(ergun).epsilon(0.02));
}

TEMPLATE_TEST_CASE("F10: particles and fluid exchange x-momentum and conserve it", "[coupling][F10]", float, double)
{
    using Real = TestType;
    // 2 cm cube, 4 x 4 x 4 fluid cells, 2000 particles d = 1 mm (solid fraction 0.1309) at
    // v_x = 0.01 m/s in water at rest, no gravity: 20 x 10 x 10 particles spaced 1 mm along x
    // (they move together) and 2 mm across.
    const double L = 0.02, d = 1e-3, v0 = 0.01, rho_p = 2600, rho_f = 1000;
    sphere::settings<Real> s = periodic_column<Real>(L, L, L, 10);
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 10; ++k)
        for (int j = 0; j < 10; ++j)
            for (int i = 0; i < 20; ++i) {
                sphere::particle<Real> p;
                p.position = {Real((i + 0.5) * 1e-3), Real((j + 0.5) * 2e-3), Real((k + 0.5) * 2e-3)};
                p.radius = Real(d / 2);
                p.density = Real(rho_p);
                p.velocity = {Real(v0), 0, 0};
                ps.push_back(p);
            }
    sim_t<Real> sim(s, ps);
    sphere::fluid_params<Real> prm;
    prm.density = Real(rho_f);
    prm.viscosity = Real(1e-2);  // particle response time ~0.01 s, so the exchange is over in 0.15 s
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-4;
    sphere::coupling_options opt;
    opt.dem_steps = 20;
    coupling_t<Real> coupled(sphere::fluid_grid<Real>::make(s.box, 4, 4, 4), prm, opt);

    const double M_p = 2000 * rho_p * pi / 6 * d * d * d;
    REQUIRE(M_p == Approx(2.7227e-3).epsilon(1e-4));
    const double P0 = M_p * v0;
    auto particle_momentum = [&] {
        double m = 0;
        const auto snap = sim.snapshot();
        for (std::size_t i = 0; i < snap.size(); ++i) m += double(snap.mass[i]) * double(snap.v[i].x);
        return m;
    };
    double worst = 0;
    while (sim.time() < 0.15) {
        coupled.step(sim);
        const double total = particle_momentum() + coupled.fluid().momentum().x;
        worst = std::max(worst, std::fabs(total - P0) / P0);
    }
    INFO("largest relative change of the total x-momentum " << worst);
    CHECK(worst < 0.01);
    // The particles end at the common velocity M_p v0 / (M_p + M_f) = 2.8140e-3 m/s
    // (VALIDATION F10; measured -0.04%). The seeds' cell-sphere porosity, which on this coarse
    // grid (5 particle diameters per cell) does not translate exactly with the particles, kept
    // a slip of 3% between them and the fluid; the default cell_volume porosity moves with them.
    const auto snap = sim.snapshot();
    double v_mean = 0;
    for (std::size_t i = 0; i < snap.size(); ++i) v_mean += double(snap.v[i].x) / double(snap.size());
    CHECK(v_mean == Approx(2.8140e-3).epsilon(0.005));
    CHECK(v_mean < 0.5 * v0);
}

TEMPLATE_TEST_CASE("the coupling refuses a fluid step longer than a particle's response time", "[coupling]", float,
                   double)
{
    using Real = TestType;
    sphere::settings<Real> s = periodic_column<Real>(0.02, 0.02, 0.2, 100);
    sphere::particle<Real> p;
    p.position = {Real(0.0075), Real(0.0075), Real(0.1)};
    p.radius = Real(5e-4);
    p.density = 2600;
    sim_t<Real> sim(s, {p});
    sphere::fluid_params<Real> prm;
    prm.viscosity = Real(0.1);
    sphere::coupling_options opt;
    opt.dem_steps = 400;  // 400 x 8.75e-6 s = 3.5e-3 s > 1.44e-3 s
    coupling_t<Real> coupled(sphere::fluid_grid<Real>::make(s.box, 4, 4, 40), prm, opt);
    CHECK_THROWS_WITH(coupled.step(sim), Catch::Contains("exceeds the shortest particle response time"));
    CHECK(sim.steps() == 0u);
    opt.dem_steps = 0;
    CHECK_THROWS_WITH((coupling_t<Real>(sphere::fluid_grid<Real>::make(s.box, 4, 4, 40), prm, opt)),
                      Catch::Contains("dem_steps = 0"));
}

TEST_CASE("a coupled run repeats bit-identically with the same thread count", "[coupling]")
{
    using Real = double;
    struct restore_threads {
        int saved = omp_get_max_threads();
        ~restore_threads() { omp_set_num_threads(saved); }
    } guard;
    omp_set_num_threads(2);
    auto run = [] {
        // 1000 particles falling through a closed fluid box: binning, reductions and the
        // pressure solve all run in parallel.
        sphere::settings<Real> s = periodic_column<Real>(0.02, 0.02, 0.04, 100);
        s.gravity = {0, 0, Real(-9.81)};
        std::vector<sphere::particle<Real>> ps;
        for (int k = 0; k < 10; ++k)
            for (int j = 0; j < 10; ++j)
                for (int i = 0; i < 10; ++i) {
                    sphere::particle<Real> p;
                    p.position = {Real((i + 0.5) * 2e-3), Real((j + 0.5) * 2e-3), Real(0.015 + (k + 0.5) * 2e-3)};
                    p.radius = Real(4e-4 + 1e-5 * ((i * 7 + j * 3 + k) % 10));
                    p.density = 2600;
                    ps.push_back(p);
                }
        sim_t<Real> sim(s, ps);
        sphere::fluid_params<Real> prm;
        prm.viscosity = Real(0.01);
        prm.gravity = s.gravity;
        prm.poisson.tolerance = 1e-10;
        sphere::coupling_options opt;
        opt.dem_steps = 5;
        coupling_t<Real> coupled(sphere::fluid_grid<Real>::make(s.box, 4, 4, 8), prm, opt);
        for (int n = 0; n < 40; ++n) coupled.step(sim);
        return std::make_pair(sim.snapshot(), coupled.fluid().pressure());
    };
    const auto a = run(), b = run();
    REQUIRE(a.first.size() == b.first.size());
    CHECK(std::memcmp(a.first.x.data(), b.first.x.data(), a.first.x.size() * sizeof(a.first.x[0])) == 0);
    CHECK(std::memcmp(a.first.v.data(), b.first.v.data(), a.first.v.size() * sizeof(a.first.v[0])) == 0);
    CHECK(std::memcmp(a.second.data(), b.second.data(), a.second.size() * sizeof(Real)) == 0);
    // The particles did move through the fluid.
    CHECK(double(a.first.v[0].z) < -1e-3);
}

namespace {
/// The volume (m^3) of the parts of the particles of `snap` that lie below the plane z = h:
/// each sphere's cross-section pi (r^2 - z^2) integrated by Simpson's rule (exact for it).
template <class Real>
double volume_below(const sphere::particle_snapshot<Real>& snap, double h)
{
    double v = 0;
    for (std::size_t i = 0; i < snap.size(); ++i) {
        const double r = double(snap.x[i].w), z = double(snap.x[i].z);
        const double a = -r, b = std::min(r, h - z);
        if (!(b > a)) continue;
        const auto area = [r](double t) { return pi * (r * r - t * t); };
        v += (b - a) / 6 * (area(a) + 4 * area(0.5 * (a + b)) + area(b));
    }
    return v;
}
} // namespace

TEMPLATE_TEST_CASE("hindered settling in a closed box: the fluid's flux through mid-height balances the particles'",
                   "[coupling][slow]", float, double)
{
    using Real = TestType;
    // 3000 particles d = 1 mm (rho_p = 2600) at random in a 20 x 20 x 40 mm box (porosity 0.90),
    // periodic sides, no-flow bottom and top, mu = 0.1 Pa s, 8 x 8 x 16 fluid cells (2.5 d).
    // The mixture is incompressible and the box closed, so the fluid's flux up through the
    // plane at mid-height equals the particles' volume flux down through it, which the test
    // measures independently: the particles' volume below the plane (volume_below) at the
    // starts of two fluid steps, over the step. The porosity estimator conserves the solid
    // volume (porosity_method::cell_volume), so the pressure solve's compatibility condition
    // holds and no source spoils the balance: 1% is asked, round-off and the solver's tolerance
    // are what remain (measured: 8e-11 in double, 5e-4 in float; the seeds' cell-sphere
    // estimator misses by up to 149%, docs/fluid.md). And the settling velocity is steady: it rises
    // from 5.6 to 6.3 mm/s over the first 0.1 s (ten times the particles' response time: the
    // fluid's convection cells grow on the viscous time of a few cells) and then stays within 1%.
    const double d = 1e-3, Lx = 0.02, Lz = 0.04, mu = 0.1;
    sphere::settings<Real> s = periodic_column<Real>(Lx, Lx, Lz, 100);
    s.gravity = {0, 0, Real(-9.81)};
    s.skin = Real(0.1 * d);  // contact lists rebuilt every ~100 steps rather than every step
    std::vector<sphere::particle<Real>> ps;
    std::mt19937_64 gen(7);
    std::uniform_real_distribution<double> u(0, 1);
    while (ps.size() < 3000) {
        const double x = Lx * u(gen), y = Lx * u(gen), z = d + (Lz - 2 * d) * u(gen);
        bool free = true;
        for (const auto& q : ps) {
            double dx = double(q.position.x) - x, dy = double(q.position.y) - y, dz = double(q.position.z) - z;
            dx -= Lx * std::nearbyint(dx / Lx);
            dy -= Lx * std::nearbyint(dy / Lx);
            if (dx * dx + dy * dy + dz * dz < 1.1 * d * 1.1 * d) {
                free = false;
                break;
            }
        }
        if (!free) continue;
        sphere::particle<Real> p;
        p.position = {Real(x), Real(y), Real(z)};
        p.radius = Real(d / 2);
        p.density = 2600;
        ps.push_back(p);
    }
    sim_t<Real> sim(s, ps);
    sphere::fluid_params<Real> prm;
    prm.density = 1000;
    prm.viscosity = Real(mu);
    prm.gravity = s.gravity;
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-5;
    sphere::coupling_options opt;
    opt.dem_steps = unsigned(std::ceil(2e-4 / double(sim.dt())));
    coupling_t<Real, sphere::drag::wen_yu> coupled(sphere::fluid_grid<Real>::make(s.box, 8, 8, 16), prm, opt);
    const auto& grid = coupled.fluid().grid();
    const double dt = double(opt.dem_steps) * double(sim.dt()), mid = Lz / 2, face = Lx * Lx / 64;

    double below_previous = volume_below(sim.snapshot(), mid), worst = 0, flux_mean = 0;
    int compared = 0;
    std::vector<double> settling;  // mean v_z (m/s) of the particles in the middle half, every 10 steps
    for (int n = 1; sim.time() < 0.14; ++n) {
        const auto start = sim.snapshot();
        const double below = volume_below(start, mid);
        coupled.step(sim);
        // Step n's fluid saw the porosity at its start against the one at the start of step n - 1.
        const double particles = (below - below_previous) / dt;
        below_previous = below;
        const auto phi = coupled.fluid().porosity();
        const auto w = coupled.fluid().face_velocity(2);
        double fluid = 0;
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) {
                const std::size_t lo = grid.field_index(i, j, 7), hi = grid.field_index(i, j, 8);
                fluid += 0.5 * (double(phi[lo]) + double(phi[hi])) * double(w[lo]) * face;
            }
        if (n >= 5) {
            worst = std::max(worst, std::abs(fluid - particles) / std::abs(particles));
            flux_mean += particles;
            ++compared;
        }
        if (n % 10 == 0 && sim.time() > 0.1) {
            double v = 0, count = 0;
            for (std::size_t i = 0; i < start.size(); ++i)
                if (std::abs(double(start.x[i].z) - mid) < Lz / 4) {
                    v += double(start.v[i].z);
                    count += 1;
                }
            settling.push_back(v / count);
        }
    }
    flux_mean /= compared;
    INFO("particle volume flux down through mid-height " << flux_mean << " m^3/s on average; largest relative difference "
                                                          << "of the fluid's flux up from it " << worst);
    CHECK(flux_mean > 1e-7);
    CHECK(worst < 0.01);
    double v_mean = 0, v_spread = 0;
    for (double v : settling) v_mean += v / double(settling.size());
    for (double v : settling) v_spread = std::max(v_spread, std::abs(v - v_mean));
    INFO("settling velocity " << v_mean << " m/s over " << settling.size() << " samples, largest departure " << v_spread);
    CHECK(v_mean < -1e-3);
    CHECK(v_spread < 0.02 * std::abs(v_mean));
}

} // namespace test_coupling
