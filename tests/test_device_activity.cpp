// What a step costs a GPU in synchronisations, counted on the host (include/sphere/exec/
// activity.cuh, exec/context.cuh; docs/architecture.md, *Execution context*): the host backend
// counts the device allocations and read-backs at the places where the CUDA build makes them,
// so these counts are the CUDA build's.
// - the counters count: a buffer that grows, a copy to the host, a reduction returned to the
//   host, the context's scratch (once, however often it is reused) and its read-back;
// - a step with or without a rebuild, with an upper wall under stress control and a
//   prescribed particle (whose drive power the step sums), on both pair schedules (the gather
//   schedule is the one CUDA runs), with and without reordering the particles, with
//   semi-implicit Euler and velocity Verlet, allocates nothing after warm-up and reads back
//   exactly one struct (velocity Verlet on the host-only slab schedule: two);
// - a rebuild whose lists outgrow their capacity runs the step again with room, to the same
//   bits as a run that had the room from the start; a rebuild whose entries pass 2^32 - 1
//   (what the lists' 32-bit offsets hold) is found on the device and reported as an error;
// - a pressure solve reads its control back once when it needs no more passes than the last
//   one and a quarter; a fluid step (with either solver) reads back once and allocates
//   nothing after warm-up; a coupled step reads back once more than its DEM steps do, also
//   with velocity Verlet (whose check of the next drift comes back with the fluid's report).
#include <catch2/catch.hpp>

#include <random>
#include <vector>

#include <sphere/dem.cuh>
#include <sphere/fluid.cuh>

#include "support.hpp"

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_device_activity {

namespace {

sphere::device_activity_counts since(const sphere::device_activity_counts& start)
{
    const sphere::device_activity_counts now = sphere::device_activity();
    return {now.allocations - start.allocations, now.read_backs - start.read_backs};
}

struct index_value {
    SPHERE_HD double operator()(std::size_t i) const { return double(i); }
};

/// 6 x 6 x 6 equal spheres, columns 2.2 R apart in x and y (jittered), layers 1.98 R apart in
/// z, pressed by 0.01 R onto the floor, each other and an upper wall held at 1 kPa; periodic
/// in x and y, with gravity; particle 0 is prescribed at rest (the step sums its drive's
/// power). The overlaps ring with amplitudes of ~0.01 R.
template <class P, class Integrator>
sphere::simulation<P, sphere::host, sphere::contact::linear<>, Integrator>
pressed_lattice(sphere::pair_summation how, double skin_in_radii, bool reorder)
{
    using Real = sphere_test::user_real<P>;
    const Real R = sphere_test::set_p<Real>::radius, spacing = Real(2.2) * R, layer = Real(1.98) * R;
    sphere::settings<Real> s = sphere_test::frictional_box<Real>(1);
    s.box.lo = {0, 0, 0};
    const Real top = Real(0.99) * R + 5 * layer + Real(0.99) * R;
    s.box.hi = {6 * spacing, 6 * spacing, 2 * top};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.walls[5].mode = sphere::wall_mode::stress;
    s.walls[5].stress = Real(1e3);
    s.walls[5].mass = Real(0.5);
    s.skin = Real(skin_in_radii) * R;
    s.pair_summation = how;
    s.reorder = reorder;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<sphere::particle<Real>> p;
    for (int k = 0; k < 6; ++k)
        for (int j = 0; j < 6; ++j)
            for (int i = 0; i < 6; ++i)
                p.push_back(sphere_test::ball<Real>({Real((i + 0.5 + 0.05 * u(rng)) * spacing),
                                                     Real((j + 0.5 + 0.05 * u(rng)) * spacing),
                                                     Real(0.99) * R + Real(k) * layer}));
    p[0].kind = sphere::motion::prescribed;
    sphere::simulation<P, sphere::host, sphere::contact::linear<>, Integrator> sim(s, p);
    sim.set_wall_position(5, double(top));
    return sim;
}

} // namespace

TEST_CASE("device activity: the counters count allocations and read-backs where CUDA makes them", "[activity]")
{
    const sphere::device_activity_counts start = sphere::device_activity();
    sphere::buffer<int, sphere::host> b(10);
    CHECK(since(start).allocations == 1);
    b.resize(5);
    b.resize(10); // within the capacity
    CHECK(since(start).allocations == 1);
    b.resize(1000);
    CHECK(since(start).allocations == 2);
    CHECK(b.to_host().size() == 1000);
    CHECK(since(start).read_backs == 1);

    const std::size_t n = 5000; // ten chunks of partial sums
    CHECK(sphere::transform_reduce(sphere::host{}, n, index_value{}, 0.0, sphere::plus_op{}) == 0.5 * n * (n - 1));
    CHECK(since(start).allocations == 4); // on CUDA: its array of values and the reduction's storage
    CHECK(since(start).read_backs == 2);  // its result

    sphere::execution_context<sphere::host> ctx;
    sphere::buffer<double, sphere::host> out(1);
    const sphere::device_activity_counts before = sphere::device_activity();
    for (int k = 0; k < 3; ++k) {
        sphere::transform_reduce_into(ctx, n, index_value{}, 1.0, sphere::plus_op{}, out.data());
        CHECK(since(before).read_backs == 0); // the result stays in the policy's memory
    }
    CHECK(since(before).allocations == 1); // the scratch, once
    double result = 0;
    ctx.read_back(&result, out.data(), 1, "test", 0);
    CHECK(result == 1 + 0.5 * n * (n - 1));
    CHECK(since(before).read_backs == 1);
}

/// Counts what `steps` steps of the pressed lattice cost after a warm-up of 20 (the step's
/// scratch, report and lists grow to what they need in it), and, with a skin, as many more as
/// it takes for the lists to give their far partners histories once (an allocation).
template <class P, class Integrator>
void count_steps(sphere::pair_summation how, double skin, bool reorder)
{
    auto sim = pressed_lattice<P, Integrator>(how, skin, reorder);
    sim.run(20);
    while (skin > 0 && sim.far_openings() == 0 && sim.steps() < 1000) sim.run(1);
    INFO("far rows opened at step " << sim.steps());
    REQUIRE((skin == 0 || sim.far_openings() == 1));
    const std::size_t rebuilds = sim.rebuilds(), overflows = sim.list_overflows(), steps = 100;
    const sphere::device_activity_counts start = sphere::device_activity();
    sim.run(steps);
    const sphere::device_activity_counts used = since(start);
    INFO("pair summation " << unsigned(how) << ", reorder " << reorder << ", skin " << skin << " R, rebuilds "
                           << rebuilds << " -> " << sim.rebuilds());
    // the window is what it claims to be
    REQUIRE(sim.rebuilds() == rebuilds + (skin > 0 ? 0 : steps));
    REQUIRE(sim.list_overflows() == overflows);
    CHECK(sim.walls().face[5].force > 0); // the loads are in the report: the wall is pushed up,
    CHECK(sim.walls().face[4].force < 0); // the floor down (forces along the axis)
    CHECK(used.allocations == 0);
    // Velocity Verlet on the host's slab schedule (which CUDA does not run) checks its drift in
    // the drift's pass and reads that back too: a copy in memory there, cheaper than predicting
    // it (docs/architecture.md, *Velocity Verlet, one read-back*).
    const bool drift_read = Integrator::drifts_before_forces && how == sphere::pair_summation::slabs;
    CHECK(used.read_backs == (drift_read ? 2 : 1) * steps);
}

TEMPLATE_TEST_CASE("device activity: a step allocates nothing after warm-up and reads back one struct, with or "
                   "without a rebuild",
                   "[activity]", float, double, sphere::mixed)
{
    const sphere::pair_summation how = GENERATE(sphere::pair_summation::slabs, sphere::pair_summation::gather);
    const bool reorder = GENERATE(true, false);
    // A skin of 0.5 R: no rebuild in the counted window (the overlaps ring far below it); a
    // skin of 0: a rebuild before every step.
    const double skin = GENERATE(0.5, 0.0);
    SECTION("semi-implicit Euler") { count_steps<TestType, sphere::integrate::semi_implicit_euler>(how, skin, reorder); }
    // on the gather schedule its report also checks where the next drift puts the particles,
    // so that the drift need not be checked and read back before the forces
    SECTION("velocity Verlet") { count_steps<TestType, sphere::integrate::velocity_verlet>(how, skin, reorder); }
}

TEMPLATE_TEST_CASE("contact lists that outgrow their capacity run the step again, to the same bits", "[activity]",
                   float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    const bool reorder = GENERATE(true, false);
    const double skin = GENERATE(0.1, 0.0);
    // 4 x 4 x 4 spheres 2.3 R apart, thrown at random velocities of up to 0.5 m/s into each
    // other and the walls of a closed box with gravity: the contacts, few at first, multiply.
    const Real R = sphere_test::set_p<Real>::radius;
    sphere::settings<Real> s = sphere_test::frictional_box<Real>(double(5 * R));
    s.skin = Real(skin) * R;
    s.reorder = reorder;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    std::vector<sphere::particle<Real>> p;
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i)
                p.push_back(sphere_test::ball<Real>({Real((i - 1.5) * 2.3) * R, Real((j - 1.5) * 2.3) * R,
                                                     Real((k - 1.5) * 2.3) * R},
                                                    {Real(u(rng)), Real(u(rng)), Real(u(rng))}));
    sphere::simulation<P> grows(s, p), roomy(s, p);
    roomy.reserve_contacts(2000); // ~30 neighbours each: more than 64 spheres can have
    const std::size_t first = grows.list_overflows();
    for (int k = 0; k < 2000; ++k) {
        grows.step();
        roomy.step();
    }
    INFO("reorder " << reorder << ", skin " << skin << " R: entries " << grows.contact_entries() << ", overflows "
                    << first << " -> " << grows.list_overflows() << ", rebuilds " << grows.rebuilds());
    CHECK(grows.list_overflows() > first); // the lists did outgrow their capacity
    CHECK(roomy.list_overflows() == first);
    CHECK(grows.rebuilds() == roomy.rebuilds());
    const sphere::particle_snapshot<Real> a = grows.snapshot(), b = roomy.snapshot();
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        differ += !(a.position(i) == b.position(i)) || !(a.v[i] == b.v[i]) || !(a.omega[i] == b.omega[i]);
    CHECK(differ == 0);
    const sphere::contact_table<Real> ca = grows.contacts(), cb = roomy.contacts();
    REQUIRE(ca.partner == cb.partner);
    std::size_t histories_differ = 0;
    for (std::size_t e = 0; e < ca.history.size(); ++e)
        histories_differ += !(ca.history[e].xyz() == cb.history[e].xyz()) || ca.history[e].w != cb.history[e].w;
    CHECK(histories_differ == 0);
}

TEMPLATE_TEST_CASE("device activity: a pressure solve reads its control back once, more only past its budget",
                   "[activity][fluid]", float, double)
{
    using Real = TestType;
    const sphere::fluid_grid<Real> g = sphere::fluid_grid<Real>::make(
        sphere::world<Real>{{0, 0, 0}, {Real(0.016), Real(0.016), Real(0.032)}}, 16, 16, 32);
    std::vector<Real> rhs(g.field_size(), Real(0)), eps(g.field_size(), Real(0));
    for (std::size_t c = 0; c < rhs.size(); ++c) rhs[c] = Real(std::sin(0.37 * double(c)) * 1e3);
    sphere::buffer<Real, sphere::host> b(rhs.size()), e(eps.size());
    b.assign(rhs);
    sphere::poisson_settings st;
    st.tolerance = sizeof(Real) == 8 ? 1e-8 : 1e-3;
    const sphere::poisson_boundaries bc{sphere::z_boundary::neumann, sphere::z_boundary::dirichlet};
    sphere::cg_poisson<Real, sphere::host> cg(g);
    sphere::jacobi_poisson<Real, sphere::host> jacobi(g);
    // The first solves start from 16 passes and double until they finish: several read-backs.
    e.assign(eps);
    sphere::device_activity_counts start = sphere::device_activity();
    const sphere::poisson_result first = cg.solve(e.data(), b.data(), bc, st);
    REQUIRE(first.converged);
    CHECK(first.iterations > 32u);
    CHECK(since(start).read_backs > 1);
    e.assign(eps);
    jacobi.solve(e.data(), b.data(), bc, st); // warms the Jacobi solver's scratch
    // The same solve again fits the budget the first one left: one read-back, no allocation.
    for (int solver = 0; solver < 2; ++solver) {
        CAPTURE(solver);
        e.assign(eps);
        start = sphere::device_activity();
        const sphere::poisson_result again =
            solver == 0 ? cg.solve(e.data(), b.data(), bc, st) : jacobi.solve(e.data(), b.data(), bc, st);
        CHECK(again.converged);
        CHECK(since(start).read_backs == 1);
        CHECK(since(start).allocations == 0);
    }
}

namespace {

/// A sphere settling in a periodic fluid column (VALIDATION F6's set-up) with a pressure top;
/// counts the read-backs of a fluid step alone, of dem_steps DEM steps and of a coupled step.
/// Velocity Verlet runs on the gather schedule (CUDA's; on the host's slab schedule its drift
/// reads its own check back).
template <class Real, class Poisson, class Integrator = sphere::integrate::semi_implicit_euler>
void count_coupled_step(double float_tolerance = 1e-3)
{
    const double cell = 5e-3;
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(4 * cell), Real(4 * cell), Real(40 * cell)};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = s.wall.k_n = s.contact.k_t = s.wall.k_t = Real(100);
    s.gravity = {0, 0, Real(-9.81)};
    sphere::particle<Real> p;
    p.position = {Real(1.5 * cell), Real(1.5 * cell), Real(34.5 * cell)};
    p.radius = Real(5e-4);
    p.density = 2600;
    if (Integrator::drifts_before_forces) s.pair_summation = sphere::pair_summation::gather;
    sphere::simulation<Real, sphere::host, sphere::contact::linear<>, Integrator> sim(s, {p});
    sphere::fluid_params<Real> prm;
    prm.viscosity = Real(0.1);
    prm.gravity = s.gravity;
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : float_tolerance; // near float's round-off floor: docs/fluid.md
    sphere::coupling_options opt;
    opt.dem_steps = 20;
    sphere::fluid_coupling<Real, sphere::host, sphere::drag::gidaspow, Poisson> coupled(
        sphere::fluid_grid<Real>::make(s.box, 4, 4, 40), prm, opt);
    for (int k = 0; k < 5; ++k) coupled.step(sim); // warm-up: buffers, scratch, the solver's budget

    sphere::device_activity_counts start = sphere::device_activity();
    sim.run(opt.dem_steps);
    const sphere::device_activity_counts dem = since(start);
    start = sphere::device_activity();
    coupled.step(sim);
    const sphere::device_activity_counts step = since(start);
    INFO("DEM steps: " << dem.read_backs << " read-backs; coupled step: " << step.read_backs << ", "
                       << step.allocations << " allocations; pressure solve: "
                       << coupled.fluid().last_solve().iterations << " iterations");
    CHECK(coupled.fluid().last_solve().iterations > 0u);
    CHECK(dem.read_backs == opt.dem_steps);
    CHECK(step.read_backs == dem.read_backs + 1);
    CHECK(step.allocations == 0);

    // The fluid on its own (after two steps that set its solver's budget for this problem; with
    // the porosity's rate held, Jacobi's counts alternate, e.g. 511, 109, 517 sweeps).
    const Real dt = Real(opt.dem_steps) * sim.dt();
    coupled.fluid().step(dt);
    coupled.fluid().step(dt);
    start = sphere::device_activity();
    coupled.fluid().step(dt);
    CHECK(since(start).read_backs == 1);
    CHECK(since(start).allocations == 0);
}

} // namespace

TEMPLATE_TEST_CASE("device activity: a fluid step reads back once, a coupled step once more than its DEM steps",
                   "[activity][fluid]", float, double)
{
    using Real = TestType;
    SECTION("conjugate gradients") { count_coupled_step<Real, sphere::cg_poisson<Real, sphere::host>>(); }
    SECTION("multigrid-preconditioned CG")
    {
        // At 1e-3 the last pressure already meets float's tolerance: 0 iterations, nothing to count.
        count_coupled_step<Real, sphere::mg_poisson<Real, sphere::host>>(1e-4);
    }
    SECTION("Jacobi") { count_coupled_step<Real, sphere::jacobi_poisson<Real, sphere::host>>(); }
    SECTION("velocity Verlet")
    {
        count_coupled_step<Real, sphere::cg_poisson<Real, sphere::host>, sphere::integrate::velocity_verlet>();
    }
}

TEST_CASE("device activity: a rebuild whose entries wrap the 32-bit offsets is an error", "[activity]")
{
    // The rows' offsets as the scan leaves them when the counts pass 2^32 - 1: a row ends
    // below its start.
    const std::vector<unsigned> wrapped{0, 4000000000u, 4294967295u, 5u, 9u};
    const std::vector<unsigned> whole{0, 4000000000u, 4294967295u, 4294967295u};
    const auto wraps = [](const std::vector<unsigned>& offsets) {
        sphere::buffer<unsigned, sphere::host> o(offsets.size());
        o.assign(offsets);
        return sphere::transform_reduce(sphere::host{}, offsets.size() - 1, sphere::detail::row_wraps{o.data()}, 0u,
                                        sphere::max_op{});
    };
    CHECK(wraps(wrapped) == 1u);
    CHECK(wraps(whole) == 0u);
    sphere::contact_lists<double, sphere::host> lists(4, false);
    sphere::list_totals t;
    t.overflow = t.wrapped = 1;
    CHECK_THROWS_WITH(lists.settle(t), Catch::Contains("more than 4294967295 contact entries"));
}

} // namespace test_device_activity
