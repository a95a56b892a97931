// Google Benchmark micro-benchmarks of the pore fluid on the host backend: one pressure solve
// by Jacobi, by conjugate gradients and by multigrid-preconditioned CG on n^3 grids (counter:
// iterations), one fluid step, and one coupled step with particles, in float and double.
// Run: build/bench/bench_fluid --benchmark_counters_tabular=true   (docs/performance.md)
#include <sphere/dem.cuh>
#include <sphere/fluid.cuh>

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

namespace {

template <class Real>
sphere::fluid_grid<Real> cube_grid(int n)
{
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    box.hi = {Real(0.01) * Real(n), Real(0.01) * Real(n), Real(0.01) * Real(n)};
    return sphere::fluid_grid<Real>::make(box, n, n, n);
}

/// One solve of a Poisson problem with a pseudo-random right-hand side, Dirichlet top and
/// Neumann bottom, from a zero guess, to relative residual 1e-8 (double) or 1e-4 (float, whose
/// round-off floor is near 1e-5).
template <class Real, class Solver>
void poisson_solve(benchmark::State& state)
{
    const int n = static_cast<int>(state.range(0));
    const auto g = cube_grid<Real>(n);
    std::vector<Real> rhs(g.field_size(), Real(0));
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) rhs[g.field_index(i, j, k)] = Real(unit(rng));
    Solver solver(g);
    sphere::poisson_settings s;
    s.tolerance = sizeof(Real) == 8 ? 1e-8 : 1e-4;
    s.max_iterations = 1000000;
    const sphere::poisson_boundaries bc{sphere::z_boundary::neumann, sphere::z_boundary::dirichlet};
    unsigned iterations = 0;
    for (auto _ : state) {
        std::vector<Real> eps(g.field_size(), Real(0));
        iterations = solver.solve(eps.data(), rhs.data(), bc, s).iterations;
        benchmark::DoNotOptimize(eps.data());
    }
    state.counters["iterations"] = iterations;
    state.counters["cells"] = double(g.cell_count());
}

/// One step of a fluid on its own (a shear wave under gravity, Dirichlet top), with the
/// Poisson solver `Solver`.
template <class Real, class Solver>
void fluid_step(benchmark::State& state)
{
    const int n = static_cast<int>(state.range(0));
    sphere::fluid_params<Real> prm;
    prm.gravity = {0, 0, Real(-9.81)};
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-8 : 1e-4;
    sphere::navier_stokes<Real, sphere::host, Solver> fluid(cube_grid<Real>(n), prm);
    fluid.set_velocity([](const sphere::vec3<Real>& x) {
        return sphere::vec3<Real>{0, Real(0.01) * std::sin(Real(20) * x.x), 0};
    });
    for (auto _ : state) fluid.step(Real(1e-3));
    state.counters["cells/s"] = benchmark::Counter(double(fluid.grid().cell_count()), benchmark::Counter::kIsIterationInvariantRate);
}

/// One coupled step (10 DEM steps) of 8000 particles settling through 16 x 16 x 32 fluid cells
/// in a closed box, with the Poisson solver `Solver`.
template <class Real, class Solver>
void coupled_step(benchmark::State& state)
{
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(0.04), Real(0.04), Real(0.08)};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = s.contact.k_t = Real(100);
    s.wall = s.contact;
    s.gravity = {0, 0, Real(-9.81)};
    s.skin = Real(2e-4);
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 20; ++k)
        for (int j = 0; j < 20; ++j)
            for (int i = 0; i < 20; ++i) {
                sphere::particle<Real> p;
                p.position = {Real((i + 0.5) * 2e-3), Real((j + 0.5) * 2e-3), Real(0.03 + (k + 0.5) * 2e-3)};
                p.radius = Real(5e-4);
                p.density = 2600;
                ps.push_back(p);
            }
    sphere::simulation<Real, sphere::host> sim(s, ps);
    sphere::fluid_params<Real> prm;
    prm.viscosity = Real(0.01);
    prm.gravity = s.gravity;
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-8 : 1e-4;
    sphere::coupling_options opt;
    opt.dem_steps = 10;
    sphere::fluid_coupling<Real, sphere::host, sphere::drag::gidaspow, Solver> coupled(
        sphere::fluid_grid<Real>::make(s.box, 16, 16, 32), prm, opt);
    for (auto _ : state) coupled.step(sim);
    state.counters["particle-steps/s"] =
        benchmark::Counter(double(ps.size()) * opt.dem_steps, benchmark::Counter::kIsIterationInvariantRate);
}

} // namespace

BENCHMARK_TEMPLATE(poisson_solve, double, sphere::jacobi_poisson<double, sphere::host>)->Arg(16)->Arg(32)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(poisson_solve, double, sphere::cg_poisson<double, sphere::host>)->Arg(16)->Arg(32)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(poisson_solve, double, sphere::mg_poisson<double, sphere::host>)->Arg(16)->Arg(32)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(poisson_solve, float, sphere::cg_poisson<float, sphere::host>)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(poisson_solve, float, sphere::mg_poisson<float, sphere::host>)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(fluid_step, float, sphere::cg_poisson<float, sphere::host>)->Arg(32)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(fluid_step, double, sphere::cg_poisson<double, sphere::host>)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(fluid_step, double, sphere::mg_poisson<double, sphere::host>)->Arg(32)->Arg(64)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(coupled_step, float, sphere::cg_poisson<float, sphere::host>)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(coupled_step, double, sphere::cg_poisson<double, sphere::host>)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(coupled_step, double, sphere::mg_poisson<double, sphere::host>)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
