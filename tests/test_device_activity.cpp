// What a step costs a GPU in synchronisations, counted on the host (include/sphere/exec/
// activity.cuh, exec/context.cuh; docs/architecture.md, *Execution context*): the host backend
// counts the device allocations and read-backs at the places where the CUDA build makes them,
// so these counts are the CUDA build's.
// - the counters count: a buffer that grows, a copy to the host, a reduction returned to the
//   host, the context's scratch (once, however often it is reused) and its read-back;
// - a step without a rebuild, with an upper wall under stress control and a prescribed
//   particle (whose drive power the step sums), on both pair schedules (the gather schedule is
//   the one CUDA runs), allocates nothing after warm-up and reads back exactly one struct.
#include <catch2/catch.hpp>

#include <random>
#include <vector>

#include <sphere/dem.cuh>

#include "support.hpp"

namespace {

sphere::device_activity_counts since(const sphere::device_activity_counts& start)
{
    const sphere::device_activity_counts now = sphere::device_activity();
    return {now.allocations - start.allocations, now.read_backs - start.read_backs};
}

struct index_value {
    SPHERE_HD double operator()(std::size_t i) const { return double(i); }
};

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

TEMPLATE_TEST_CASE("device activity: a step without a rebuild allocates nothing and reads back one struct",
                   "[activity]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    const sphere::pair_summation how = GENERATE(sphere::pair_summation::slabs, sphere::pair_summation::gather);
    // 6 x 6 x 6 equal spheres, columns 2.2 R apart in x and y (jittered), layers 1.98 R apart
    // in z, pressed by 0.01 R onto the floor, each other and an upper wall held at 1 kPa;
    // periodic in x and y, with gravity; particle 0 is prescribed at rest (the step sums its
    // drive's power). The overlaps ring with amplitudes of ~0.01 R, far below the skin.
    const Real R = sphere_test::set_p<Real>::radius, spacing = Real(2.2) * R, layer = Real(1.98) * R;
    sphere::settings<Real> s = sphere_test::frictional_box<Real>(1);
    s.box.lo = {0, 0, 0};
    const Real top = Real(0.99) * R + 5 * layer + Real(0.99) * R;
    s.box.hi = {6 * spacing, 6 * spacing, 2 * top};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.walls[5].mode = sphere::wall_mode::stress;
    s.walls[5].stress = Real(1e3);
    s.walls[5].mass = Real(0.5);
    s.skin = Real(0.5) * R; // no rebuild in the counted window
    s.pair_summation = how;
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
    sphere::simulation<P> sim(s, p);
    sim.set_wall_position(5, double(top));
    sim.run(20); // warm-up: the step's scratch and report are allocated once

    const std::size_t rebuilds = sim.rebuilds(), steps = 100;
    const sphere::device_activity_counts start = sphere::device_activity();
    sim.run(steps);
    const sphere::device_activity_counts used = since(start);
    INFO("pair summation " << unsigned(how) << ", rebuilds " << rebuilds << " -> " << sim.rebuilds());
    REQUIRE(sim.rebuilds() == rebuilds); // the window is what it claims to be
    CHECK(sim.walls().face[5].force > 0); // the loads are in the report: the wall is pushed up,
    CHECK(sim.walls().face[4].force < 0); // the floor down (forces along the axis)
    CHECK(used.allocations == 0);
    CHECK(used.read_backs == steps);
}
