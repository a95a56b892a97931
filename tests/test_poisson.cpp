// The pressure-Poisson solvers (include/sphere/fluid/poisson.cuh, poisson_cg.cuh;
// docs/fluid.md, *Pressure Poisson solvers*):
// - both solvers against a direct sparse LU solve (Eigen) of the same discrete problem, built
//   independently here, with Dirichlet, Neumann (singular, compared at zero mean) and mixed
//   z boundaries, non-cubic cells, on 16^3 and on an odd-sized grid;
// - conjugate gradients need at least 10x fewer iterations than Jacobi on 64^3 ([slow]);
// - a fluid at rest converges in 0 iterations with both criteria; the iteration limit, bad
//   settings and NaN input; bit-identical repeated solves (also on 1 and 2 OpenMP threads);
//   the ghost nodes on return.
// - the singular case with the fluid's right-hand side (mean 1e10 times its variations) and a
//   guess of large constant offset: both solvers converge to 1e-10 and agree.
#include <catch2/catch.hpp>

#include <sphere/fluid/grid.cuh>
#include <sphere/fluid/poisson.cuh>
#include <sphere/fluid/poisson_cg.cuh>
#include <sphere/fluid/poisson_mg.cuh>

#include <omp.h>

// The direct reference solve needs Eigen 3 (tests/CMakeLists.txt links the test executable to
// Eigen3::Eigen). Without it, one test case fails and says so, and the rest still runs.
#if __has_include(<Eigen/Sparse>)
#include <Eigen/Sparse>
#define SPHERE_TEST_HAVE_EIGEN 1
#else
#define SPHERE_TEST_HAVE_EIGEN 0
#endif

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_poisson {

namespace {

using sphere::poisson_boundaries;
using sphere::poisson_criterion;
using sphere::poisson_result;
using sphere::poisson_settings;
using sphere::z_boundary;

template <class Real>
sphere::fluid_grid<Real> make_grid(int nx, int ny, int nz, double lx, double ly, double lz)
{
    sphere::world<Real> box;
    box.lo = {Real(0), Real(0), Real(0)};
    box.hi = {Real(lx), Real(ly), Real(lz)};
    box.axis[0] = box.axis[1] = sphere::boundary::periodic;
    return sphere::fluid_grid<Real>::make(box, nx, ny, nz);
}

int wrap(int i, int n) { return (i % n + n) % n; }

/// A Poisson problem in double, in the field layout of grid g: the right-hand side and the
/// initial eps holding the Dirichlet values (0 elsewhere).
struct problem {
    std::vector<double> rhs, eps;
};

/// Pseudo-random right-hand side of amplitude `amplitude` (not zero-mean), and smooth,
/// non-uniform Dirichlet values on the Dirichlet layers.
template <class Real>
problem make_problem(const sphere::fluid_grid<Real>& g, const poisson_boundaries& bc, double amplitude,
                     unsigned seed)
{
    const double two_pi = 6.283185307179586;
    problem p;
    p.rhs.assign(g.field_size(), 0.0);
    p.eps.assign(g.field_size(), 0.0);
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int nx = int(g.n[0]), ny = int(g.n[1]), nz = int(g.n[2]);
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) p.rhs[g.field_index(i, j, k)] = amplitude * (0.3 + u(gen));
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            if (bc.bottom == z_boundary::dirichlet)
                p.eps[g.field_index(i, j, 0)] = 1.0 + 0.3 * std::sin(two_pi * i / nx) + 0.2 * std::cos(two_pi * j / ny);
            if (bc.top == z_boundary::dirichlet)
                p.eps[g.field_index(i, j, nz - 1)] = -0.5 + 0.4 * std::cos(two_pi * (i + 2 * j) / nx) + 0.01 * j;
        }
    return p;
}

#if SPHERE_TEST_HAVE_EIGEN
/// The discrete problem solved directly: the 7-point matrix of the unknown cells assembled
/// cell by cell from the definition (periodic x and y; Neumann: the ghost equals the cell, so
/// that face contributes nothing; Dirichlet: the end layer is known and moves to the
/// right-hand side), factorised by Eigen's SparseLU. In the singular case (Neumann at both
/// ends) the right-hand side loses its mean, one unknown is pinned to 0 (the remaining rows
/// imply the pinned row's equation, since the rows sum to zero), and the solution loses its
/// mean. Returns the field with the cells filled (the Dirichlet layers as given).
///
/// With coefficients K (cells) and S (cells), the variable-coefficient rows of poisson.cuh's
/// file comment: each face weighted by the harmonic mean of its two cells' K, S on the
/// diagonal; S > 0 makes the problem non-singular.
template <class Real>
std::vector<double> direct_solve(const sphere::fluid_grid<Real>& g, const poisson_boundaries& bc, const problem& p,
                                 const std::vector<double>* K = nullptr, const std::vector<double>* S = nullptr)
{
    const int nx = int(g.n[0]), ny = int(g.n[1]), nz = int(g.n[2]);
    const bool bottom = bc.bottom == z_boundary::dirichlet, top = bc.top == z_boundary::dirichlet;
    const int k0 = bottom ? 1 : 0, k1 = top ? nz - 2 : nz - 1;
    const double c[3] = {1.0 / (double(g.width.x) * double(g.width.x)), 1.0 / (double(g.width.y) * double(g.width.y)),
                         1.0 / (double(g.width.z) * double(g.width.z))};
    const bool singular = !bottom && !top && !S;
    auto unknown = [&](int i, int j, int k) { return (std::size_t(k - k0) * ny + j) * nx + i; };
    const std::size_t n = std::size_t(nx) * ny * (k1 - k0 + 1);
    double mean_b = 0;
    if (singular) {
        for (int k = 0; k < nz; ++k)
            for (int j = 0; j < ny; ++j)
                for (int i = 0; i < nx; ++i) mean_b += p.rhs[g.field_index(i, j, k)];
        mean_b /= double(nx) * ny * nz;
    }
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::VectorXd b(static_cast<Eigen::Index>(n));
    for (int k = k0; k <= k1; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const auto row = static_cast<int>(unknown(i, j, k));
                double rhs = p.rhs[g.field_index(i, j, k)] - mean_b;
                if (singular && row == 0) {
                    entries.emplace_back(row, row, 1.0);
                    b[row] = 0;
                    continue;
                }
                const int di[6] = {-1, 1, 0, 0, 0, 0}, dj[6] = {0, 0, -1, 1, 0, 0}, dk[6] = {0, 0, 0, 0, -1, 1};
                if (S) entries.emplace_back(row, row, -(*S)[g.field_index(i, j, k)]);
                for (int d = 0; d < 6; ++d) {
                    const int ni = wrap(i + di[d], nx), nj = wrap(j + dj[d], ny), nk = k + dk[d];
                    if (nk < 0 || nk >= nz) continue; // Neumann wall: ghost = cell, no contribution
                    double cd = c[d / 2];
                    if (K) {
                        const double a = (*K)[g.field_index(i, j, k)], o = (*K)[g.field_index(ni, nj, nk)];
                        cd *= 2 * a * o / (a + o);
                    }
                    entries.emplace_back(row, row, -cd);
                    if ((nk == 0 && bottom) || (nk == nz - 1 && top)) {
                        rhs -= cd * p.eps[g.field_index(ni, nj, nk)];
                    } else {
                        entries.emplace_back(row, static_cast<int>(unknown(ni, nj, nk)), cd);
                    }
                }
                b[row] = rhs;
            }
    Eigen::SparseMatrix<double> A(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
    A.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
    lu.compute(A);
    REQUIRE(lu.info() == Eigen::Success);
    const Eigen::VectorXd x = lu.solve(b);
    REQUIRE(lu.info() == Eigen::Success);
    std::vector<double> out = p.eps;
    double mean_x = singular ? x.mean() : 0.0;
    for (int k = k0; k <= k1; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) out[g.field_index(i, j, k)] = x[static_cast<Eigen::Index>(unknown(i, j, k))] - mean_x;
    return out;
}

#endif

template <class Real>
std::vector<Real> to_real(const std::vector<double>& v)
{
    return std::vector<Real>(v.begin(), v.end());
}

/// Max over the cells of |a - b| / max over the cells of |b|, each made zero-mean first when
/// `zero_mean` (the singular case).
template <class Real, class A, class B>
double relative_error(const sphere::fluid_grid<Real>& g, const std::vector<A>& a, const std::vector<B>& b,
                      bool zero_mean)
{
    double ma = 0, mb = 0;
    const double cells = double(g.cell_count());
    if (zero_mean)
        for (std::size_t c = 0; c < g.cell_count(); ++c) {
            int i, j, k;
            g.coordinates(c, i, j, k);
            ma += double(a[g.field_index(i, j, k)]) / cells;
            mb += double(b[g.field_index(i, j, k)]) / cells;
        }
    double err = 0, scale = 0;
    for (std::size_t c = 0; c < g.cell_count(); ++c) {
        int i, j, k;
        g.coordinates(c, i, j, k);
        const std::size_t f = g.field_index(i, j, k);
        err = std::max(err, std::abs((double(a[f]) - ma) - (double(b[f]) - mb)));
        scale = std::max(scale, std::abs(double(b[f]) - mb));
    }
    return err / scale;
}

/// Tolerance of the comparisons with the direct solve (max-norm error / max-norm solution),
/// and the relative residual the solvers are run to. Float: the relative residual of the best
/// float field is about float epsilon times the condition number (Jacobi stalls near 8e-6 on
/// the mixed 16^3 case), so float is run to 1e-5, which leaves up to 1.05e-4 of error in the
/// smoothest mode (Jacobi, Neumann ends): checked to 2e-4.
template <class Real>
double solve_tolerance()
{
    return sizeof(Real) == sizeof(double) ? 1e-12 : 1e-5;
}
template <class Real>
double agreement()
{
    return sizeof(Real) == sizeof(double) ? 1e-8 : 2e-4;
}

const poisson_boundaries dirichlet_both{z_boundary::dirichlet, z_boundary::dirichlet};
const poisson_boundaries neumann_both{z_boundary::neumann, z_boundary::neumann};
const poisson_boundaries mixed{z_boundary::neumann, z_boundary::dirichlet};
const poisson_boundaries mixed_other{z_boundary::dirichlet, z_boundary::neumann};

std::string describe(const poisson_boundaries& bc)
{
    auto name = [](z_boundary b) { return b == z_boundary::dirichlet ? std::string("dirichlet") : std::string("neumann"); };
    return "bottom " + name(bc.bottom) + ", top " + name(bc.top);
}

/// Runs one solver on a problem; returns the result and leaves the solution in eps.
template <class Solver, class Real>
poisson_result run(const sphere::fluid_grid<Real>& g, std::vector<Real>& eps, const std::vector<Real>& rhs,
                   const poisson_boundaries& bc, const poisson_settings& st)
{
    Solver solver(g);
    return solver.solve(eps.data(), rhs.data(), bc, st);
}

template <class T>
struct type_tag {
    using type = T;
};

template <class Real>
using jacobi = sphere::jacobi_poisson<Real, sphere::host>;
template <class Real>
using cg = sphere::cg_poisson<Real, sphere::host>;
template <class Real>
using mg = sphere::mg_poisson<Real, sphere::host>;

#if SPHERE_TEST_HAVE_EIGEN
/// Both solvers on one grid and set of boundaries against the direct solve.
template <class Real>
void check_against_direct(const sphere::fluid_grid<Real>& g, const poisson_boundaries& bc, unsigned seed)
{
    const problem p = make_problem(g, bc, 300.0, seed);
    const std::vector<double> reference = direct_solve(g, bc, p);
    const std::vector<Real> rhs = to_real<Real>(p.rhs);
    poisson_settings st;
    st.tolerance = solve_tolerance<Real>();
    const bool singular = bc.bottom == z_boundary::neumann && bc.top == z_boundary::neumann;
    INFO(describe(bc) << ", " << g.n[0] << " x " << g.n[1] << " x " << g.n[2] << " cells");

    std::vector<Real> eps = to_real<Real>(p.eps);
    const poisson_result rj = run<jacobi<Real>>(g, eps, rhs, bc, st);
    INFO("Jacobi: " << rj.iterations << " sweeps, residual " << rj.residual);
    CHECK(rj.converged);
    CHECK(rj.residual <= st.tolerance);
    CHECK(relative_error(g, eps, reference, singular) <= agreement<Real>());

    std::vector<Real> eps_cg = to_real<Real>(p.eps);
    const poisson_result rc = run<cg<Real>>(g, eps_cg, rhs, bc, st);
    INFO("CG: " << rc.iterations << " iterations, residual " << rc.residual);
    CHECK(rc.converged);
    CHECK(rc.residual <= st.tolerance);
    CHECK(relative_error(g, eps_cg, reference, singular) <= agreement<Real>());
    CHECK(rc.iterations < rj.iterations);

    std::vector<Real> eps_mg = to_real<Real>(p.eps);
    const poisson_result rm = run<mg<Real>>(g, eps_mg, rhs, bc, st);
    INFO("MG-PCG: " << rm.iterations << " iterations, residual " << rm.residual);
    CHECK(rm.converged);
    CHECK(rm.residual <= st.tolerance);
    CHECK(relative_error(g, eps_mg, reference, singular) <= agreement<Real>());
    CHECK(rm.iterations < rc.iterations);

    // The Dirichlet layers are never changed.
    const std::vector<Real> start = to_real<Real>(p.eps);
    for (int j = 0; j < int(g.n[1]); ++j)
        for (int i = 0; i < int(g.n[0]); ++i)
            for (int k : {0, int(g.n[2]) - 1}) {
                const bool fixed = (k == 0 && bc.bottom == z_boundary::dirichlet) ||
                                   (k == int(g.n[2]) - 1 && bc.top == z_boundary::dirichlet);
                if (!fixed) continue;
                const std::size_t f = g.field_index(i, j, k);
                CHECK(eps[f] == start[f]);
                CHECK(eps_cg[f] == start[f]);
                CHECK(eps_mg[f] == start[f]);
            }

    // Singular case: zero mean over the cells.
    if (singular) {
        double mean_j = 0, mean_c = 0, mean_m = 0, scale = 0;
        for (std::size_t c = 0; c < g.cell_count(); ++c) {
            int i, j, k;
            g.coordinates(c, i, j, k);
            const std::size_t f = g.field_index(i, j, k);
            mean_j += double(eps[f]);
            mean_c += double(eps_cg[f]);
            mean_m += double(eps_mg[f]);
            scale = std::max(scale, std::abs(reference[f]));
        }
        const double eps_mean = sizeof(Real) == sizeof(double) ? 1e-13 : 1e-6;
        CHECK(std::abs(mean_j / double(g.cell_count())) <= eps_mean * scale);
        CHECK(std::abs(mean_c / double(g.cell_count())) <= eps_mean * scale);
        CHECK(std::abs(mean_m / double(g.cell_count())) <= eps_mean * scale);
    }
}

/// Variable coefficients (poisson.cuh's file comment): K log-uniform in [1/3, 3] per cell, S
/// (if sink > 0) sink x 1/dz^2 x uniform in [0.5, 1.5]; every solver against the direct solve
/// (Jacobi unless `weak`: a nearly singular problem, which Jacobi would need ~1e7 sweeps for and
/// whose round-off floor is ~1e-10, so that it is solved to 1e-9).
template <class Real>
void check_variable_against_direct(const sphere::fluid_grid<Real>& g, const poisson_boundaries& bc, unsigned seed,
                                   double sink, bool weak = false)
{
    const problem p = make_problem(g, bc, 300.0, seed);
    std::vector<double> K(g.field_size(), 0.0), S(g.field_size(), 0.0);
    std::mt19937 gen(seed + 100);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int nx = int(g.n[0]), ny = int(g.n[1]), nz = int(g.n[2]);
    const double cz = 1.0 / (double(g.width.z) * double(g.width.z));
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                K[g.field_index(i, j, k)] = std::exp(std::log(3.0) * u(gen));
                S[g.field_index(i, j, k)] = sink * cz * (1.0 + 0.5 * u(gen));
            }
    // K's ghosts as the solvers need them: periodic copies, the nearest cell along z.
    for (int k = -1; k <= nz; ++k)
        for (int j = -1; j <= ny; ++j)
            for (int i = -1; i <= nx; ++i)
                K[g.field_index(i, j, k)] = K[g.field_index(wrap(i, nx), wrap(j, ny), std::clamp(k, 0, nz - 1))];
    const bool with_sink = sink > 0;
    const std::vector<double> reference = direct_solve(g, bc, p, &K, with_sink ? &S : nullptr);
    const std::vector<Real> rhs = to_real<Real>(p.rhs), k_real = to_real<Real>(K), s_real = to_real<Real>(S);
    sphere::poisson_coefficients<Real> coefficients;
    coefficients.conductance = k_real.data();
    coefficients.conductance_max = 3;
    if (with_sink) {
        coefficients.sink = s_real.data();
        coefficients.sink_max = 1.5 * sink * cz;
    }
    poisson_settings st;
    st.tolerance = weak ? 1e-9 : solve_tolerance<Real>();
    const bool singular = !with_sink && bc.bottom == z_boundary::neumann && bc.top == z_boundary::neumann;
    INFO(describe(bc) << ", sink " << sink << ", " << nx << " x " << ny << " x " << nz << " cells");
    auto check_solver = [&](auto tag, const char* name) {
        using Solver = typename decltype(tag)::type;
        std::vector<Real> eps = to_real<Real>(p.eps);
        Solver solver(g);
        const poisson_result r = solver.solve(eps.data(), rhs.data(), bc, st, coefficients);
        INFO(name << ": " << r.iterations << " iterations, residual " << r.residual);
        CHECK(r.converged);
        CHECK(r.residual <= st.tolerance);
        CHECK(relative_error(g, eps, reference, singular) <= agreement<Real>());
    };
    if (!weak) check_solver(type_tag<jacobi<Real>>{}, "Jacobi");
    check_solver(type_tag<cg<Real>>{}, "CG");
    check_solver(type_tag<mg<Real>>{}, "MG-PCG");
}

#endif

/// Checks every ghost node of a returned field against the boundary rules.
template <class Real>
void check_ghosts(const sphere::fluid_grid<Real>& g, const std::vector<Real>& e, const poisson_boundaries& bc)
{
    const int nx = int(g.n[0]), ny = int(g.n[1]), nz = int(g.n[2]);
    int checked = 0;
    for (int k = -1; k <= nz; ++k)
        for (int j = -1; j <= ny; ++j)
            for (int i = -1; i <= nx; ++i) {
                const bool ghost = i < 0 || i >= nx || j < 0 || j >= ny || k < 0 || k >= nz;
                if (!ghost) continue;
                const int si = wrap(i, nx), sj = wrap(j, ny);
                Real expected;
                if (k == -1)
                    expected = bc.bottom == z_boundary::dirichlet
                                   ? Real(2) * e[g.field_index(si, sj, 0)] - e[g.field_index(si, sj, 1)]
                                   : e[g.field_index(si, sj, 0)];
                else if (k == nz)
                    expected = bc.top == z_boundary::dirichlet
                                   ? Real(2) * e[g.field_index(si, sj, nz - 1)] - e[g.field_index(si, sj, nz - 2)]
                                   : e[g.field_index(si, sj, nz - 1)];
                else
                    expected = e[g.field_index(si, sj, k)];
                INFO("ghost (" << i << ", " << j << ", " << k << ")");
                CHECK(e[g.field_index(i, j, k)] == expected);
                ++checked;
            }
    CHECK(std::size_t(checked) == g.field_size() - g.cell_count());
}

} // namespace

#if SPHERE_TEST_HAVE_EIGEN
TEMPLATE_TEST_CASE("Poisson solvers reproduce a direct sparse solve (16^3, non-cubic cells)", "[fluid][poisson]",
                   float, double)
{
    using Real = TestType;
    // dx = 0.1, dy = 0.08, dz = 0.05 m.
    const auto g = make_grid<Real>(16, 16, 16, 1.6, 1.28, 0.8);
    SECTION("Dirichlet at both ends, non-uniform values") { check_against_direct(g, dirichlet_both, 1); }
    SECTION("Neumann at both ends (singular: compared at zero mean)") { check_against_direct(g, neumann_both, 2); }
    SECTION("Neumann bottom, Dirichlet top") { check_against_direct(g, mixed, 3); }
    SECTION("Dirichlet bottom, Neumann top") { check_against_direct(g, mixed_other, 4); }
}

TEMPLATE_TEST_CASE("Poisson solvers on an odd-sized grid (periodic wrap with odd counts)", "[fluid][poisson]", float,
                   double)
{
    using Real = TestType;
    const auto g = make_grid<Real>(7, 5, 6, 0.7, 0.6, 0.3);
    SECTION("Dirichlet at both ends") { check_against_direct(g, dirichlet_both, 5); }
    SECTION("Neumann at both ends") { check_against_direct(g, neumann_both, 6); }
    SECTION("mixed") { check_against_direct(g, mixed, 7); }
    SECTION("a single cell layer with Neumann ends") { check_against_direct(make_grid<Real>(6, 5, 1, 0.6, 0.5, 0.1), neumann_both, 8); }
}

TEMPLATE_TEST_CASE("Poisson solvers with variable coefficients (harmonic-mean conductances, a sink) reproduce a "
                   "direct sparse solve",
                   "[fluid][poisson]", float, double)
{
    using Real = TestType;
    const auto g = make_grid<Real>(8, 6, 10, 0.8, 0.48, 0.5);
    SECTION("conductances, Dirichlet at both ends") { check_variable_against_direct(g, dirichlet_both, 11, 0.0); }
    SECTION("conductances, Neumann at both ends (singular)") { check_variable_against_direct(g, neumann_both, 12, 0.0); }
    SECTION("conductances and a sink, mixed") { check_variable_against_direct(g, mixed, 13, 0.5); }
    SECTION("conductances and a sink, Neumann at both ends (not singular)")
    {
        check_variable_against_direct(g, neumann_both, 14, 0.5);
    }
    // The Darcy model's case: a sink a million times below the conductances (a nearly
    // incompressible pore fluid), closed ends; its condition number (~1e7) leaves float nothing.
    if (sizeof(Real) == sizeof(double))
        SECTION("a weak sink, Neumann at both ends") { check_variable_against_direct(g, neumann_both, 15, 1e-6, true); }
}

#else
TEST_CASE("Poisson solvers reproduce a direct sparse solve (needs Eigen 3)", "[fluid][poisson]")
{
    FAIL("Eigen 3 was not found: the comparison with a direct solve is not compiled. Add "
         "find_package(Eigen3 3.3 REQUIRED NO_MODULE) and "
         "target_link_libraries(test_poisson PRIVATE Eigen3::Eigen) to tests/CMakeLists.txt");
}
#endif

// Measured (Release, g++ 13): Jacobi 19139 sweeps, CG 228 iterations; about 16 s on one core,
// nearly all of it Jacobi. With Dirichlet ends the same problem takes 31246 and 226.
TEST_CASE("CG needs at least 10x fewer iterations than Jacobi on 64^3", "[fluid][poisson][slow]")
{
    using Real = double;
    const auto g = make_grid<Real>(64, 64, 64, 1.0, 1.0, 1.0);
    const problem p = make_problem(g, neumann_both, 300.0, 1);
    const std::vector<Real> rhs = to_real<Real>(p.rhs);
    poisson_settings st;
    st.tolerance = 1e-6;
    std::vector<Real> eps_j = to_real<Real>(p.eps), eps_c = to_real<Real>(p.eps);
    const poisson_result rj = run<jacobi<Real>>(g, eps_j, rhs, neumann_both, st);
    const poisson_result rc = run<cg<Real>>(g, eps_c, rhs, neumann_both, st);
    INFO("Jacobi " << rj.iterations << " sweeps (residual " << rj.residual << "), CG " << rc.iterations
                   << " iterations (residual " << rc.residual << ")");
    REQUIRE(rj.converged);
    REQUIRE(rc.converged);
    CHECK(rj.residual <= 1e-6);
    CHECK(rc.residual <= 1e-6);
    CHECK(rj.iterations >= 10 * rc.iterations);
    // Both are close to the solution: within the error a 1e-6 residual allows.
    const double difference = relative_error(g, eps_j, eps_c, true);
    INFO("relative difference of the two solutions " << difference);
    CHECK(difference <= 5e-4);
}

TEMPLATE_TEST_CASE("A fluid at rest converges in 0 iterations with both criteria", "[fluid][poisson]", float, double)
{
    using Real = TestType;
    const auto g = make_grid<Real>(8, 6, 5, 0.8, 0.6, 0.5);
    for (const poisson_boundaries& bc : {dirichlet_both, neumann_both, mixed, mixed_other})
        for (poisson_criterion criterion : {poisson_criterion::relative_residual, poisson_criterion::normalized_change}) {
            INFO(describe(bc) << ", criterion " << (criterion == poisson_criterion::relative_residual ? "relative" : "change"));
            poisson_settings st;
            st.criterion = criterion;
            const std::vector<Real> rhs(g.field_size(), Real(0));
            std::vector<Real> e1(g.field_size(), Real(0)), e2(g.field_size(), Real(0)), e3(g.field_size(), Real(0));
            const poisson_result rj = run<jacobi<Real>>(g, e1, rhs, bc, st);
            const poisson_result rc = run<cg<Real>>(g, e2, rhs, bc, st);
            const poisson_result rm = run<mg<Real>>(g, e3, rhs, bc, st);
            for (const poisson_result& r : {rj, rc, rm}) {
                CHECK(r.iterations == 0);
                CHECK(r.converged);
                CHECK(r.residual == 0);
            }
            for (std::size_t f = 0; f < g.field_size(); ++f) {
                CHECK(e1[f] == Real(0));
                CHECK(e2[f] == Real(0));
                CHECK(e3[f] == Real(0));
            }
        }
}

TEMPLATE_TEST_CASE("A solved field is accepted in 0 iterations and the limit is reported", "[fluid][poisson]", float,
                   double)
{
    using Real = TestType;
    const auto g = make_grid<Real>(16, 16, 16, 1.6, 1.28, 0.8);
    const problem p = make_problem(g, mixed, 300.0, 21);
    const std::vector<Real> rhs = to_real<Real>(p.rhs);

    SECTION("max_iterations = 5 on a hard problem: not converged, 5 iterations, finite residual")
    {
        for (poisson_criterion criterion : {poisson_criterion::relative_residual, poisson_criterion::normalized_change}) {
            poisson_settings st;
            st.tolerance = 1e-10;
            st.max_iterations = 5;
            st.criterion = criterion;
            std::vector<Real> e1 = to_real<Real>(p.eps), e2 = to_real<Real>(p.eps), e3 = to_real<Real>(p.eps);
            const poisson_result rj = run<jacobi<Real>>(g, e1, rhs, mixed, st);
            const poisson_result rc = run<cg<Real>>(g, e2, rhs, mixed, st);
            const poisson_result rm = run<mg<Real>>(g, e3, rhs, mixed, st);
            for (const poisson_result& r : {rj, rc, rm}) {
                CHECK_FALSE(r.converged);
                CHECK(r.iterations == 5);
                CHECK(std::isfinite(r.residual));
                CHECK(r.residual > st.tolerance);
            }
        }
    }
    SECTION("the solution as initial guess: 0 iterations")
    {
        poisson_settings st;
        st.tolerance = sizeof(Real) == sizeof(double) ? 1e-9 : 1e-4;
        std::vector<Real> e = to_real<Real>(p.eps);
        const poisson_result first = run<cg<Real>>(g, e, rhs, mixed, st);
        REQUIRE(first.converged);
        const std::vector<Real> solved = e;
        const poisson_result rj = run<jacobi<Real>>(g, e, rhs, mixed, st);
        CHECK(rj.iterations == 0);
        CHECK(rj.converged);
        CHECK(rj.residual == Approx(first.residual));
        CHECK(e == solved);
        const poisson_result rc = run<cg<Real>>(g, e, rhs, mixed, st);
        CHECK(rc.iterations == 0);
        CHECK(rc.converged);
        CHECK(e == solved);
        const poisson_result rm = run<mg<Real>>(g, e, rhs, mixed, st);
        CHECK(rm.iterations == 0);
        CHECK(rm.converged);
        CHECK(e == solved);
    }
    SECTION("normalized_change: the seeds' criterion converges, and relative change stays consistent")
    {
        poisson_settings st;
        st.criterion = poisson_criterion::normalized_change;
        st.tolerance = sizeof(Real) == sizeof(double) ? 1e-20 : 1e-12;
        std::vector<Real> e = to_real<Real>(p.eps);
        const poisson_result rj = run<jacobi<Real>>(g, e, rhs, mixed, st);
        CHECK(rj.converged);
        CHECK(rj.residual <= st.tolerance);
        // Against a tight CG solve. A normalized change of 1e-20 (a relative change of 1e-10
        // per sweep) still leaves 3e-8 of error after 5536 sweeps: the criterion measures
        // stagnation, not accuracy (float: 1e-12 stops after 2645 sweeps, 2.6e-4 off).
        std::vector<Real> reference = to_real<Real>(p.eps);
        poisson_settings tight;
        tight.tolerance = sizeof(Real) == sizeof(double) ? 1e-13 : 1e-5;
        REQUIRE(run<cg<Real>>(g, reference, rhs, mixed, tight).converged);
        const double error = relative_error(g, e, reference, false);
        INFO("Jacobi " << rj.iterations << " sweeps, normalized change " << rj.residual << ", error " << error);
        CHECK(error <= (sizeof(Real) == sizeof(double) ? 1e-7 : 1e-3));
    }
}

TEST_CASE("The normalized change of a field that is zero somewhere", "[fluid][poisson]")
{
    using sphere::detail::normalized_change_parts;
    using sphere::detail::normalized_change_value;
    // Nothing changed anywhere (a fluid at rest): 0, not 0/0.
    CHECK(normalized_change_value(normalized_change_parts{0, 0, 0}) == 0);
    // A cell became 0 after a change of 0.5: measured against the largest eps_new^2 = 4.
    CHECK(normalized_change_value(normalized_change_parts{0.01, 4, 0.25}) == Approx(0.0625));
    CHECK(normalized_change_value(normalized_change_parts{0.5, 4, 0.25}) == Approx(0.5));
    // The whole new field is 0 but something changed: 1 (all of it changed).
    CHECK(normalized_change_value(normalized_change_parts{0, 0, 0.25}) == 1);
    CHECK(std::isnan(normalized_change_value(normalized_change_parts{std::nan(""), 1, 0})));
}

TEMPLATE_TEST_CASE("Poisson solvers refuse bad settings and NaN input", "[fluid][poisson]", float, double)
{
    using Real = TestType;
    const auto g = make_grid<Real>(6, 6, 6, 0.6, 0.6, 0.6);
    const problem p = make_problem(g, dirichlet_both, 10.0, 31);
    std::vector<Real> rhs = to_real<Real>(p.rhs);
    std::vector<Real> e = to_real<Real>(p.eps);
    jacobi<Real> js(g);
    cg<Real> cs(g);
    mg<Real> ms(g);
    auto both = [&](const poisson_boundaries& bc, const poisson_settings& st, const std::string& message) {
        CHECK_THROWS_WITH(js.solve(e.data(), rhs.data(), bc, st), Catch::Contains(message));
        CHECK_THROWS_WITH(cs.solve(e.data(), rhs.data(), bc, st), Catch::Contains(message));
        CHECK_THROWS_WITH(ms.solve(e.data(), rhs.data(), bc, st), Catch::Contains(message));
    };
    poisson_settings st;
    st.tolerance = 0;
    both(dirichlet_both, st, "Poisson solver: tolerance = 0 must be positive and finite");
    st.tolerance = -1e-3;
    both(dirichlet_both, st, "tolerance = -0.001");
    st.tolerance = std::numeric_limits<double>::quiet_NaN();
    both(dirichlet_both, st, "tolerance = nan");
    st.tolerance = std::numeric_limits<double>::infinity();
    both(neumann_both, st, "tolerance = inf");
    st = poisson_settings{};
    st.max_iterations = 0;
    both(mixed, st, "Poisson solver: max_iterations = 0 must be at least 1");

    const auto thin = make_grid<Real>(4, 4, 2, 0.4, 0.4, 0.2);
    jacobi<Real> jt(thin);
    cg<Real> ct(thin);
    mg<Real> mt(thin);
    std::vector<Real> et(thin.field_size(), Real(0)), rt(thin.field_size(), Real(1));
    for (const poisson_boundaries& bc : {dirichlet_both, mixed, mixed_other}) {
        CHECK_THROWS_WITH(jt.solve(et.data(), rt.data(), bc, poisson_settings{}), Catch::Contains("nz = 2 cells"));
        CHECK_THROWS_WITH(ct.solve(et.data(), rt.data(), bc, poisson_settings{}), Catch::Contains("needs nz >= 3"));
        CHECK_THROWS_WITH(mt.solve(et.data(), rt.data(), bc, poisson_settings{}), Catch::Contains("needs nz >= 3"));
    }
    CHECK_NOTHROW(jt.solve(et.data(), rt.data(), neumann_both, poisson_settings{}));

    // NaN in the right-hand side, in a Dirichlet value, in the initial guess.
    for (poisson_criterion criterion : {poisson_criterion::relative_residual, poisson_criterion::normalized_change}) {
        st = poisson_settings{};
        st.criterion = criterion;
        rhs[g.field_index(2, 3, 3)] = std::numeric_limits<Real>::quiet_NaN();
        both(dirichlet_both, st, "Poisson solver: residual became NaN after 0 iterations");
        rhs = to_real<Real>(p.rhs);
        e = to_real<Real>(p.eps);
        e[g.field_index(1, 1, 0)] = std::numeric_limits<Real>::quiet_NaN();
        both(dirichlet_both, st, "residual became NaN after 0 iterations");
        e = to_real<Real>(p.eps);
        e[g.field_index(1, 1, 2)] = std::numeric_limits<Real>::infinity();
        both(mixed, st, "after 0 iterations");
        e = to_real<Real>(p.eps);
    }
}

TEMPLATE_TEST_CASE("Poisson solves are bit-identical when repeated", "[fluid][poisson]", float, double)
{
    using Real = TestType;
    const auto g = make_grid<Real>(24, 20, 18, 2.4, 1.6, 0.9);
    for (const poisson_boundaries& bc : {neumann_both, mixed}) {
        const problem p = make_problem(g, bc, 100.0, 41);
        const std::vector<Real> rhs = to_real<Real>(p.rhs);
        poisson_settings st;
        st.tolerance = sizeof(Real) == sizeof(double) ? 1e-10 : 1e-5;
        st.max_iterations = 2000;
        jacobi<Real> js(g);
        cg<Real> cs(g);
        mg<Real> ms(g);
        std::vector<std::vector<Real>> out;
        for (int run_index = 0; run_index < 2; ++run_index) {
            std::vector<Real> e1 = to_real<Real>(p.eps), e2 = to_real<Real>(p.eps), e3 = to_real<Real>(p.eps),
                              e4 = to_real<Real>(p.eps), e5 = to_real<Real>(p.eps);
            js.solve(e1.data(), rhs.data(), bc, st);
            cs.solve(e2.data(), rhs.data(), bc, st);
            // A fresh solver after the reused one solved other boundaries.
            run<cg<Real>>(g, e3, rhs, bc, st);
            ms.solve(e4.data(), rhs.data(), bc, st);
            run<mg<Real>>(g, e5, rhs, bc, st);
            for (auto* e : {&e1, &e2, &e3, &e4, &e5}) out.push_back(*e);
            // Reuse the solvers on other boundaries before the second round.
            std::vector<Real> other = to_real<Real>(p.eps);
            js.solve(other.data(), rhs.data(), dirichlet_both, st);
            cs.solve(other.data(), rhs.data(), dirichlet_both, st);
            ms.solve(other.data(), rhs.data(), dirichlet_both, st);
        }
        const std::size_t bytes = g.field_size() * sizeof(Real);
        for (std::size_t i = 0; i < 5; ++i) {
            INFO("solve " << i);
            CHECK(std::memcmp(out[i].data(), out[i + 5].data(), bytes) == 0);
        }
        CHECK(std::memcmp(out[1].data(), out[2].data(), bytes) == 0);
        CHECK(std::memcmp(out[3].data(), out[4].data(), bytes) == 0);
    }
}

TEMPLATE_TEST_CASE("Poisson solvers fill the ghost nodes on return", "[fluid][poisson]", float, double)
{
    using Real = TestType;
    const auto g = make_grid<Real>(7, 6, 5, 0.7, 0.3, 0.5);
    for (const poisson_boundaries& bc : {dirichlet_both, neumann_both, mixed, mixed_other}) {
        INFO(describe(bc));
        const problem p = make_problem(g, bc, 50.0, 51);
        const std::vector<Real> rhs = to_real<Real>(p.rhs);
        poisson_settings st;
        st.tolerance = 1e-4;
        std::vector<Real> e1 = to_real<Real>(p.eps), e2 = to_real<Real>(p.eps), e3 = to_real<Real>(p.eps);
        // Garbage in the ghosts on entry: the solvers must not depend on it.
        for (std::size_t f = 0; f < g.field_size(); ++f) {
            int i = int(f % (g.n[0] + 2)) - 1, j = int(f / (g.n[0] + 2) % (g.n[1] + 2)) - 1,
                k = int(f / ((g.n[0] + 2) * (g.n[1] + 2))) - 1;
            if (i < 0 || j < 0 || k < 0 || i >= int(g.n[0]) || j >= int(g.n[1]) || k >= int(g.n[2]))
                e1[f] = e2[f] = e3[f] = Real(1e6);
        }
        REQUIRE(run<jacobi<Real>>(g, e1, rhs, bc, st).converged);
        REQUIRE(run<cg<Real>>(g, e2, rhs, bc, st).converged);
        REQUIRE(run<mg<Real>>(g, e3, rhs, bc, st).converged);
        check_ghosts(g, e1, bc);
        check_ghosts(g, e2, bc);
        check_ghosts(g, e3, bc);
    }
}

namespace {
/// Restores the OpenMP thread count when a test leaves (also on failure).
struct thread_count_guard {
    int saved = omp_get_max_threads();
    ~thread_count_guard() { omp_set_num_threads(saved); }
};
} // namespace

TEMPLATE_TEST_CASE("Poisson solves are bit-identical on 1 and 2 OpenMP threads", "[fluid][poisson]", float, double)
{
    using Real = TestType;
    thread_count_guard guard;
    // 57600 cells: enough for the host loops to run in parallel (poisson.cuh,
    // host_cells_per_index).
    const auto g = make_grid<Real>(48, 40, 30, 2.4, 2.0, 1.2);
    for (const poisson_boundaries& bc : {neumann_both, mixed}) {
        INFO(describe(bc));
        const problem p = make_problem(g, bc, 100.0, 61);
        const std::vector<Real> rhs = to_real<Real>(p.rhs);
        std::vector<std::vector<Real>> out;
        std::vector<poisson_result> results;
        for (int threads : {1, 2, 2}) {
            omp_set_num_threads(threads);
            poisson_settings st;
            st.tolerance = 1e-12; // not reached: every solve stops at the limit
            st.max_iterations = 20;
            std::vector<Real> e1 = to_real<Real>(p.eps), e2 = to_real<Real>(p.eps), e3 = to_real<Real>(p.eps),
                              e4 = to_real<Real>(p.eps);
            results.push_back(run<jacobi<Real>>(g, e1, rhs, bc, st));
            st.criterion = poisson_criterion::normalized_change;
            results.push_back(run<jacobi<Real>>(g, e2, rhs, bc, st));
            st.criterion = poisson_criterion::relative_residual;
            st.max_iterations = 30;
            results.push_back(run<cg<Real>>(g, e3, rhs, bc, st));
            st.max_iterations = 4;
            results.push_back(run<mg<Real>>(g, e4, rhs, bc, st));
            for (auto* e : {&e1, &e2, &e3, &e4}) out.push_back(*e);
        }
        const std::size_t bytes = g.field_size() * sizeof(Real);
        for (std::size_t i = 0; i < 4; ++i) {
            INFO("solve " << i);
            CHECK(std::memcmp(out[i].data(), out[i + 4].data(), bytes) == 0);
            CHECK(std::memcmp(out[i].data(), out[i + 8].data(), bytes) == 0);
            CHECK(results[i].iterations == results[i + 4].iterations);
            CHECK(std::memcmp(&results[i].residual, &results[i + 4].residual, sizeof(double)) == 0);
            CHECK(std::memcmp(&results[i].residual, &results[i + 8].residual, sizeof(double)) == 0);
        }
    }
}

TEST_CASE("Singular case: a right-hand side of large mean and a guess of large offset (the fluid's)",
          "[fluid][poisson]")
{
    // The projection step of a fluid at nearly uniform flow: b ~ 2.2e3 Pa/m^2 with variations
    // of ~1e-7 (the mean is 1e10 times the variations; rounding the mean to one double leaves a
    // constant of ~1e-13 per cell in b - mean(b), 1e-6 of its norm), and the previous pressure
    // as the initial guess, far from zero mean. Both solvers used to stall (Jacobi at 1e-6) or
    // diverge (CG: p.Ap -> 0 with r.r held up by the constant, alpha ~ -1e18, residual 1e12).
    using Real = double;
    for (const auto& g : {make_grid<Real>(4, 4, 4, 0.02, 0.02, 0.02), make_grid<Real>(8, 6, 5, 0.04, 0.03, 0.02)}) {
        INFO(g.n[0] << " x " << g.n[1] << " x " << g.n[2]);
        std::mt19937 gen(7);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        std::vector<Real> rhs(g.field_size(), 0.0), eps(g.field_size(), 0.0);
        for (std::size_t c = 0; c < g.cell_count(); ++c) {
            int i, j, k;
            g.coordinates(c, i, j, k);
            rhs[g.field_index(i, j, k)] = 2233.4227357 + 4e-7 * u(gen);
            eps[g.field_index(i, j, k)] = 1.0e5 + 1e-9 * u(gen);
        }
        poisson_settings st;
        st.tolerance = 1e-10;
        st.max_iterations = 20000;
        std::vector<Real> ej = eps, ec = eps, em = eps;
        const poisson_result rj = run<jacobi<Real>>(g, ej, rhs, neumann_both, st);
        const poisson_result rc = run<cg<Real>>(g, ec, rhs, neumann_both, st);
        const poisson_result rm = run<mg<Real>>(g, em, rhs, neumann_both, st);
        INFO("MG-PCG: " << rm.iterations << " iterations, residual " << rm.residual);
        CHECK(rm.converged);
        CHECK(rm.residual <= 1e-10);
        CHECK(relative_error(g, em, ej, true) < 1e-8);
        INFO("Jacobi: " << rj.iterations << " sweeps, residual " << rj.residual);
        INFO("CG: " << rc.iterations << " iterations, residual " << rc.residual);
        CHECK(rj.converged);
        CHECK(rj.residual <= 1e-10);
        CHECK(rc.converged);
        CHECK(rc.residual <= 1e-10);
        CHECK(rc.iterations < 200);
        CHECK(relative_error(g, ec, ej, true) < 1e-8);
        // Returned with zero mean.
        double mean = 0, scale = 0;
        for (std::size_t c = 0; c < g.cell_count(); ++c) {
            int i, j, k;
            g.coordinates(c, i, j, k);
            mean += ec[g.field_index(i, j, k)] / double(g.cell_count());
            scale = std::max(scale, std::abs(double(ec[g.field_index(i, j, k)])));
        }
        CHECK(std::abs(mean) <= 1e-12 * scale);
    }
}

// Multigrid-preconditioned CG: iterations that do not grow with the grid. Pseudo-random
// right-hand side on n^3 cubic cells (periodic x, y), relative residual 1e-8, double. Measured:
// 9 iterations at 32^3, 64^3 and 128^3 with every pair of z boundaries (bench/bench_fluid.cpp
// times it against CG).
TEST_CASE("MG-PCG iteration counts are independent of the grid: 32^3, 64^3, 128^3", "[fluid][poisson][slow]")
{
    using Real = double;
    for (const poisson_boundaries& bc : {neumann_both, mixed, dirichlet_both}) {
        std::vector<unsigned> counts;
        for (int n : {32, 64, 128}) {
            const auto g = make_grid<Real>(n, n, n, 1.0, 1.0, 1.0);
            const problem p = make_problem(g, bc, 300.0, 71);
            const std::vector<Real> rhs = to_real<Real>(p.rhs);
            std::vector<Real> e = to_real<Real>(p.eps);
            poisson_settings st;
            st.tolerance = 1e-8;
            const poisson_result r = run<mg<Real>>(g, e, rhs, bc, st);
            INFO(describe(bc) << ", " << n << "^3: " << r.iterations << " iterations, residual " << r.residual);
            CHECK(r.converged);
            CHECK(r.residual <= 1e-8);
            CHECK(r.iterations <= 15);
            counts.push_back(r.iterations);
        }
        INFO(describe(bc) << ": " << counts[0] << ", " << counts[1] << ", " << counts[2] << " iterations");
        const unsigned lo = *std::min_element(counts.begin(), counts.end()),
                       hi = *std::max_element(counts.begin(), counts.end());
        CHECK(double(hi) <= 1.2 * double(lo));
    }
}

TEMPLATE_TEST_CASE("MG-PCG's levels coarsen even counts by halves and odd layer counts by every second layer",
                   "[fluid][poisson]", float, double)
{
    using Real = TestType;
    // 12 x 10 x 16 cells: x 12 -> 6 -> 3, y 10 -> 5, z with a Dirichlet top (15 unknown layers)
    // 15 -> 7 -> 3 -> 1; with Neumann ends 16 -> 8 -> 4 -> 2.
    const auto g = make_grid<Real>(12, 10, 16, 1.2, 1.0, 1.6);
    mg<Real> solver(g);
    const problem p = make_problem(g, mixed, 10.0, 81);
    std::vector<Real> e = to_real<Real>(p.eps);
    const std::vector<Real> rhs = to_real<Real>(p.rhs);
    poisson_settings st;
    st.tolerance = sizeof(Real) == sizeof(double) ? 1e-8 : 1e-4;
    REQUIRE(solver.solve(e.data(), rhs.data(), mixed, st).converged);
    const std::vector<std::vector<unsigned>> mixed_levels = {{12, 10, 15}, {6, 5, 7}, {3, 5, 3}, {3, 5, 1}};
    CHECK(solver.level_sizes() == mixed_levels);
    e = to_real<Real>(p.eps);
    REQUIRE(solver.solve(e.data(), rhs.data(), neumann_both, st).converged);
    const std::vector<std::vector<unsigned>> neumann_levels = {{12, 10, 16}, {6, 5, 8}, {3, 5, 4}, {3, 5, 2}};
    CHECK(solver.level_sizes() == neumann_levels);
}

} // namespace test_poisson
