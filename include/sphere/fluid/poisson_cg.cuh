#pragma once
/// \file
/// The conjugate-gradient solver of the pressure-Poisson problem (docs/fluid.md, *Pressure
/// Poisson solvers*): the same problem, settings, result and interface as jacobi_poisson
/// (poisson.cuh, whose file comment defines the discrete equations, the boundaries, the
/// singular case and the criteria), so a projection solver can take either as a template
/// argument.
#include <cmath>
#include <cstddef>

#include "../core/config.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/for_each.cuh"
#include "grid.cuh"
#include "poisson.cuh"

namespace sphere {
namespace detail {

/// r = b - shift - A e at cell f (Real); e with filled ghosts.
template <class Real>
struct poisson_residual_field {
    poisson_stencil<Real> s;
    const Real* e;
    const Real* b;
    poisson_shift shift;
    Real* r;

    SPHERE_HD void operator()(std::size_t f) const
    {
        r[f] = Real(shift.from(double(b[f])) - s.laplacian(e, f));
    }
};

/// q = A p at cell f, in Real; p with filled ghosts and 0 on the Dirichlet layers.
template <class Real>
struct poisson_apply {
    poisson_stencil<Real> s;
    Real cx, cy, cz;
    const Real* p;
    Real* q;

    SPHERE_HD void operator()(std::size_t f) const
    {
        const Real c = p[f];
        q[f] = cx * ((p[f - 1] - c) + (p[f + 1] - c)) + cy * ((p[f - s.sy] - c) + (p[f + s.sy] - c)) +
               cz * ((p[f - s.sz] - c) + (p[f + s.sz] - c));
    }
};

/// a . b over the unknowns (each product in double).
template <class Real>
struct poisson_dot {
    const Real* a;
    const Real* b;

    SPHERE_HD double operator()(std::size_t f) const
    {
        return double(a[f]) * double(b[f]);
    }
};

/// x += alpha p and r -= alpha q at cell f.
template <class Real>
struct cg_step {
    Real alpha;
    const Real* p;
    const Real* q;
    Real* x;
    Real* r;

    SPHERE_HD void operator()(std::size_t f) const
    {
        x[f] += alpha * p[f];
        r[f] -= alpha * q[f];
    }
};

/// r -= mean (the singular case's projection; 0 otherwise) and p = r + beta p at cell f.
template <class Real>
struct cg_direction {
    Real beta;
    Real mean;
    Real* r;
    Real* p;

    SPHERE_HD void operator()(std::size_t f) const
    {
        const Real v = r[f] - mean;
        r[f] = v;
        p[f] = v + beta * p[f];
    }
};

} // namespace detail

/// Conjugate gradients (Hestenes & Stiefel) for the pressure-Poisson problem of poisson.cuh.
///
/// The matrix A of the unknowns is symmetric (the 7-point stencil with periodic x, y, mirror
/// Neumann rows and Dirichlet neighbours moved to the right-hand side) and negative definite,
/// or negative semi-definite with the constants as null space when both z ends are Neumann.
/// CG is run on A x = b with the textbook recurrences (alpha = r.r / p.Ap, which is negative
/// here), which is step for step the same as CG on the positive (semi-)definite -A x = -b.
/// Unpreconditioned: the diagonal of A is constant except on the rows next to a Neumann wall,
/// so a diagonal (Jacobi) preconditioner changes almost nothing.
///
/// Singular case: b is replaced by b - mean(b), which lies in the range of A; the iterates then
/// stay in (initial guess + range of A), the constant component of eps never changes, and the
/// solution is returned with zero mean. CG converges on such a consistent semi-definite system
/// at the rate set by the smallest non-zero eigenvalue. In floating point the system is only
/// consistent to round-off, and CG on an inconsistent semi-definite system diverges (the
/// constant part of r, which no step reduces, keeps r.r up while p.Ap falls to 0, so alpha
/// explodes): the mean of b is removed as hi + lo (detail::poisson_shift: one double cannot
/// hold the mean of a fluid's b, ~1e3 with variations of ~1e-7), and the constant is projected
/// out of r at every restart and every iteration (one more reduction per iteration).
///
/// Breakdown: a step with p.Ap >= 0, or with |alpha| lambda_max beyond 1 / epsilon (more than
/// any condition number: p lies in the null space to round-off), is never taken; the solver
/// checks the true residual and restarts from it instead. With relative_residual, a solve whose
/// true residual fails the tolerance on three checks in a row without halving returns
/// converged = false with that residual (its round-off floor) before max_iterations.
///
/// Iterations: O(n) on an n-cell axis against O(n^2) for Jacobi (the error falls at least as
/// fast as 2 ((sqrt(kappa) - 1) / (sqrt(kappa) + 1))^k, kappa ~ (2 n / pi)^2 for a Dirichlet
/// axis). On 64^3 cubic cells with a pseudo-random right-hand side and a relative residual of
/// 1e-6: 228 iterations against 19139 Jacobi sweeps with Neumann ends, 226 against 31246 with
/// Dirichlet ends (tests/test_poisson.cpp). A CG iteration costs somewhat more than a Jacobi
/// sweep with its residual check (one stencil pass against two, but two dot products and two
/// vector updates); on the host the solve is 70-90x faster at this size.
///
/// Counting: one iteration = one application of A (plus two dot products, in the singular
/// case a sum, and two vector updates). A solve also applies the stencil once to evaluate the criterion on the initial
/// guess, once for the initial residual, and, with relative_residual, once per convergence
/// check: the recursively updated residual r decides when to look, but convergence is
/// declared only on the true residual b - A eps (computed in double); if that misses the
/// tolerance (round-off, mostly in float), CG restarts from the true residual and goes on.
///
/// normalized_change is evaluated on every iteration's step alpha p (as Jacobi does on every
/// sweep); it measures stagnation, and CG's steps are not monotone, so relative_residual is
/// the criterion to use with this solver.
///
/// Owns three scratch fields (residual r, direction p, A p), allocated once.
template <class Real, class Policy>
class cg_poisson {
public:
    explicit cg_poisson(const fluid_grid<Real>& g)
        : problem_(g), r_(g.field_size(), Real(0)), p_(g.field_size(), Real(0)), q_(g.field_size(), Real(0))
    {
    }

    const fluid_grid<Real>& grid() const { return problem_.grid(); }

    /// Solves A eps = rhs; the same contract as jacobi_poisson::solve.
    poisson_result solve(Real* eps, const Real* rhs, const poisson_boundaries& bc, const poisson_settings& st)
    {
        problem_.prepare(bc, st);
        problem_.fill_ghosts(eps);
        problem_.remove_means(eps, rhs);
        const detail::poisson_stencil<Real>& s = problem_.stencil();
        const bool relative = st.criterion == poisson_criterion::relative_residual;
        const double b_norm = relative ? problem_.rhs_norm(eps, rhs) : 0.0;
        // |alpha| <= 1 / (smallest non-zero |eigenvalue|) for a direction in the range of A,
        // so |alpha| lambda_max is at most the condition number; a step beyond 1 / epsilon is
        // a direction that A does not see (round-off), never a useful step.
        const double lambda_max = 4 * (s.cx + s.cy + s.cz);
        const double largest_step = 1 / (lambda_max * 2.220446049250313e-16);
        const double cells = double(grid().cell_count());
        Real* r = r_.data();
        Real* p = p_.data();
        Real* q = q_.data();

        poisson_result result;
        // The criterion on the initial guess.
        {
            const double res = problem_.residual_norm(eps, rhs);
            problem_.check_finite(res, 0);
            if (relative) {
                result.residual = b_norm > 0 ? res / b_norm : res;
                problem_.check_finite(result.residual, 0);
            }
            if (relative ? result.residual <= st.tolerance : res == 0) {
                result.converged = true;
                problem_.finish(eps);
                return result;
            }
        }
        // r = p = b - A eps. r and p are zeroed first: their Dirichlet layers must be 0 (only
        // unknowns are written), and the previous solve may have had other boundaries.
        problem_.zero(r);
        problem_.zero(p);
        const double threshold = st.tolerance * (b_norm > 0 ? b_norm : 1.0);
        double rr = restart(eps, rhs);
        bool found = false;
        // With relative_residual: the true residual of eps, decides convergence; false when
        // CG should stop (converged, or the residual is at its round-off floor: `stalls`
        // restarts in a row did not halve the best true residual).
        double best = result.residual;
        unsigned stalls = 0;
        auto check = [&]() {
            problem_.fill_ghosts(eps);
            const double res = problem_.residual_norm(eps, rhs);
            result.residual = b_norm > 0 ? res / b_norm : res;
            problem_.check_finite(result.residual, result.iterations);
            if (result.residual <= st.tolerance) {
                result.converged = true;
                found = true;
                return false;
            }
            if (result.residual < 0.5 * best) {
                best = result.residual;
                stalls = 0;
            } else if (++stalls >= 3) {
                return false;
            }
            rr = restart(eps, rhs);
            return true;
        };
        while (result.iterations < st.max_iterations) {
            problem_.fill_ghosts(p);
            problem_.for_each_unknown(detail::poisson_apply<Real>{s, Real(s.cx), Real(s.cy), Real(s.cz), p, q});
            const double pq = problem_.sum_unknowns(detail::poisson_dot<Real>{p, q});
            problem_.check_finite(pq, result.iterations);
            if (!(pq < 0) || !(rr < -pq * largest_step)) {
                // p.Ap ~ 0: p has no component that A sees (r is at round-off); a step would be
                // huge and meaningless. Take none: check the true residual, restart from it.
                if (!relative) {
                    result.residual = 0;
                    result.converged = true;
                    found = true;
                    break;
                }
                if (check()) continue;
                break;
            }
            const double alpha = rr / pq;
            problem_.for_each_unknown(detail::cg_step<Real>{Real(alpha), p, q, eps, r});
            ++result.iterations;
            double rr_new = problem_.sum_unknowns(detail::poisson_dot<Real>{r, r});
            problem_.check_finite(rr_new, result.iterations);
            // Singular case: A q has zero mean only to round-off, so r picks up a constant that
            // no step can remove; it is projected out (r -= mean(r), applied with the next
            // direction; ||r - m||^2 = r.r - N m^2).
            double mean = 0;
            if (problem_.singular()) {
                mean = problem_.sum_unknowns(detail::field_cell_value<Real>{r}) / cells;
                rr_new -= cells * mean * mean;
                if (rr_new < 0) rr_new = 0;
            }
            if (relative) {
                if (std::sqrt(rr_new) <= threshold) {
                    if (check()) continue;
                    break;
                }
            } else {
                result.residual = problem_.normalized_change(eps, nullptr, p, alpha);
                problem_.check_finite(result.residual, result.iterations);
                if (result.residual <= st.tolerance) {
                    result.converged = true;
                    found = true;
                    break;
                }
            }
            const double beta = rr_new / rr;
            rr = rr_new;
            problem_.for_each_unknown(detail::cg_direction<Real>{Real(beta), Real(mean), r, p});
        }
        if (!found && relative) {
            problem_.fill_ghosts(eps);
            const double res = problem_.residual_norm(eps, rhs);
            result.residual = b_norm > 0 ? res / b_norm : res;
            problem_.check_finite(result.residual, result.iterations);
            result.converged = result.residual <= st.tolerance;
        }
        problem_.finish(eps);
        return result;
    }

private:
    /// r = p = b - A eps (eps's ghosts are refreshed first), with its mean removed in the
    /// singular case; returns r.r.
    double restart(Real* eps, const Real* rhs)
    {
        const detail::poisson_stencil<Real>& s = problem_.stencil();
        problem_.fill_ghosts(eps);
        problem_.for_each_unknown(detail::poisson_residual_field<Real>{s, eps, rhs, problem_.shift(), r_.data()});
        if (problem_.singular()) {
            const double mean =
                problem_.sum_unknowns(detail::field_cell_value<Real>{r_.data()}) / double(grid().cell_count());
            problem_.for_each_unknown(detail::subtract_from_cells<Real>{r_.data(), Real(mean)});
        }
        problem_.copy(r_.data(), p_.data());
        return problem_.sum_unknowns(detail::poisson_dot<Real>{r_.data(), r_.data()});
    }

    detail::poisson_problem<Real, Policy> problem_;
    buffer<Real, Policy> r_, p_, q_;
};

} // namespace sphere
