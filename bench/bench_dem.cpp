// Google Benchmark micro-benchmarks of the DEM core on the host backend: the neighbour-grid
// and contact-list rebuild, and one full DEM step, for 1e4 and 1e5 particles in a random
// dense packing, in float and double. Counters report particle-steps per second.
// Run: build/bench/bench_dem --benchmark_counters_tabular=true   (docs/performance.md)
#include <sphere/dem.cuh>

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

namespace {

/// A dense random packing: a cubic lattice of spacing 2 r_max, radii uniform in
/// [0.8, 1.0] r_max, each centre jittered by up to 0.1 r_max, random velocities of 0.1 m/s
/// scale; walls on all sides, gravity, friction and damping. Solid fraction about 0.32-0.5.
template <class Real>
struct dense_packing {
    sphere::settings<Real> settings;
    std::vector<sphere::particle<Real>> particles;

    explicit dense_packing(std::size_t n, Real skin)
    {
        const Real r = Real(1e-3);
        const std::size_t side = static_cast<std::size_t>(std::ceil(std::cbrt(static_cast<double>(n))));
        const Real spacing = 2 * r;
        std::mt19937 rng(42);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        for (std::size_t k = 0; k < n; ++k) {
            const std::size_t ix = k % side, iy = (k / side) % side, iz = k / (side * side);
            sphere::particle<Real> p;
            p.radius = r * Real(0.8 + 0.2 * unit(rng));
            p.density = Real(2600);
            p.position = {Real((ix + 0.5) * spacing + 0.1 * r * (2 * unit(rng) - 1)),
                          Real((iy + 0.5) * spacing + 0.1 * r * (2 * unit(rng) - 1)),
                          Real((iz + 0.5) * spacing + 0.1 * r * (2 * unit(rng) - 1))};
            p.velocity = {Real(0.1 * (2 * unit(rng) - 1)), Real(0.1 * (2 * unit(rng) - 1)),
                          Real(0.1 * (2 * unit(rng) - 1))};
            particles.push_back(p);
        }
        settings.box.lo = {0, 0, 0};
        settings.box.hi = {Real(side * spacing), Real(side * spacing), Real(side * spacing)};
        settings.contact = {Real(1e4), Real(1e4 * 2 / 7.0), Real(0.05), Real(0), Real(0.5), Real(0.5), false};
        settings.wall = settings.contact;
        settings.gravity = {0, 0, Real(-9.81)};
        settings.skin = skin;
    }
};

/// Rebuild of the grid and the contact lists (every step of sphere's loop).
template <class Real>
void grid_rebuild(benchmark::State& state)
{
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    dense_packing<Real> setup(n, 0);
    sphere::particle_state<Real, sphere::host> particles(setup.particles);
    const sphere::particle_view<Real> view = particles.view();
    sphere::neighbor_grid<Real, sphere::host> grid(
        sphere::grid_geometry<Real>::make(setup.settings.box, Real(2e-3), Real(0)));
    sphere::contact_lists<Real, sphere::host> lists(n, true);
    const sphere::wall_set<Real> walls = sphere::wall_set<Real>::from_world(setup.settings.box);
    sphere::execution_context<sphere::host> context;
    sphere::buffer<sphere::list_totals, sphere::host> totals(1);
    for (auto _ : state) {
        do {
            grid.build(context, view);
            lists.rebuild(context, grid.view(), walls, Real(0), Real(0), true, totals.data());
        } while (!lists.settle(totals.data()[0])); // the first grows the lists
        benchmark::DoNotOptimize(lists.entries());
    }
    state.counters["particle_steps_per_s"] =
        benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
}

/// One full DEM step (rebuild, interact, integrate, check); range(1) is the skin in units of
/// 1e-5 m (0: rebuild every step, as sphere does).
template <class Real>
void dem_step(benchmark::State& state)
{
    const std::size_t n = static_cast<std::size_t>(state.range(0));
    dense_packing<Real> setup(n, Real(state.range(1)) * Real(1e-5));
    sphere::simulation<Real, sphere::host> sim(setup.settings, setup.particles);
    for (auto _ : state) sim.step();
    state.counters["particle_steps_per_s"] =
        benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["rebuilds_per_step"] = static_cast<double>(sim.rebuilds()) / static_cast<double>(sim.steps() + 1);
}

BENCHMARK_TEMPLATE(grid_rebuild, float)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(grid_rebuild, double)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(dem_step, float)->Args({10000, 0})->Args({100000, 0})->Args({100000, 10})->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(dem_step, double)->Args({10000, 0})->Args({100000, 0})->Args({100000, 10})->Unit(benchmark::kMillisecond);

} // namespace

BENCHMARK_MAIN();
