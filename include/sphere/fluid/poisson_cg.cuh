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
#include "../exec/context.cuh"
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
    const poisson_shift* shift; ///< policy memory
    Real* r;

    SPHERE_HD void operator()(std::size_t f) const
    {
        r[f] = Real(shift->from(double(b[f])) - s.laplacian(e, f));
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

/// q = A p at cell f with the variable coefficients (poisson.cuh), computed in double.
template <class Real>
struct poisson_apply_variable {
    poisson_stencil<Real> s;
    const Real* p;
    Real* q;
    SPHERE_HD void operator()(std::size_t f) const { q[f] = Real(s.variable_laplacian(p, f)); }
};

/// q = A p on the unknowns if *go: the constant-coefficient kernel, or the variable one.
template <class Problem, class Real>
void apply_operator(const Problem& problem, const int* go, const poisson_stencil<Real>& s, const Real* p, Real* q)
{
    if (s.variable())
        problem.for_each_unknown(go, poisson_apply_variable<Real>{s, p, q});
    else
        problem.for_each_unknown(go, poisson_apply<Real>{s, Real(s.cx), Real(s.cy), Real(s.cz), p, q});
}

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

/// x += alpha p and r -= alpha q at cell f (alpha from the control).
template <class Real>
struct cg_step {
    const poisson_control* c;
    const Real* p;
    const Real* q;
    Real* x;
    Real* r;

    SPHERE_HD void operator()(std::size_t f) const
    {
        const Real alpha = Real(c->alpha);
        x[f] += alpha * p[f];
        r[f] -= alpha * q[f];
    }
};

/// r -= mean (the singular case's projection; 0 otherwise) and p = r + beta p at cell f (beta
/// and mean from the control).
template <class Real>
struct cg_direction {
    const poisson_control* c;
    Real* r;
    Real* p;

    SPHERE_HD void operator()(std::size_t f) const
    {
        const Real v = r[f] - Real(c->mean);
        r[f] = v;
        p[f] = v + Real(c->beta) * p[f];
    }
};

/// The start of a pass: it applies A while the loop goes on below max_iterations.
struct cg_begin_pass {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        c->iterate = c->active && c->iterations < c->max_iterations;
        if (c->active && !c->iterate) c->active = 0;
        c->stepping = c->checking = c->directing = 0;
        if (c->iterate) ++c->passes;
    }
};

/// After A p (sum: p.Ap): the step alpha = r.r / p.Ap, or, where p.Ap ~ 0 (p has no component
/// that A sees: a step would be huge and meaningless), none: the true residual is checked.
struct cg_after_apply {
    poisson_control* c;
    double largest_step; ///< |alpha| lambda_max beyond 1 / epsilon: see cg_poisson

    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->iterate) return;
        const double pq = c->sum;
        if (stop_if_not_finite(*c, pq, c->iterations)) return;
        if (!(pq < 0) || !(c->rr < -pq * largest_step)) {
            if (!c->relative) {
                c->residual = 0;
                c->converged = c->found = 1;
                c->active = 0;
            } else {
                c->checking = 1;
            }
            return;
        }
        c->alpha = c->rr / pq;
        c->stepping = 1;
    }
};

/// After a step (sum2: the new r.r; sum: the sum of r in the singular case; change: the
/// normalized change's parts): the criterion, and the next direction's beta.
struct cg_after_step {
    poisson_control* c;
    int singular;
    double cells;

    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->stepping) return;
        ++c->iterations;
        double rr_new = c->sum2;
        if (stop_if_not_finite(*c, rr_new, c->iterations)) return;
        // Singular case: A q has zero mean only to round-off, so r picks up a constant that no
        // step can remove; it is projected out (r -= mean(r), applied with the next direction;
        // ||r - m||^2 = r.r - N m^2).
        double mean = 0;
        if (singular) {
            mean = c->sum / cells;
            rr_new -= cells * mean * mean;
            if (rr_new < 0) rr_new = 0;
        }
        if (c->relative) {
            if (sqrt(rr_new) <= c->threshold) {
                c->checking = 1;
                return;
            }
        } else {
            c->residual = normalized_change_value(c->change);
            if (stop_if_not_finite(*c, c->residual, c->iterations)) return;
            if (c->residual <= c->tolerance) {
                c->converged = c->found = 1;
                c->active = 0;
                return;
            }
        }
        c->beta = rr_new / c->rr;
        c->rr = rr_new;
        c->mean = mean;
        c->directing = 1;
    }
};

/// After the true residual (sum: its square): converged, stalled at the round-off floor (three
/// checks in a row that did not halve the best residual), or a restart from it.
struct cg_after_check {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->checking) return;
        const double res = sqrt(c->sum);
        c->residual = c->b_norm > 0 ? res / c->b_norm : res;
        if (stop_if_not_finite(*c, c->residual, c->iterations)) return;
        if (c->residual <= c->tolerance) {
            c->converged = c->found = 1;
            c->active = 0;
            return;
        }
        if (c->residual < 0.5 * c->best) {
            c->best = c->residual;
            c->stalls = 0;
        } else if (++c->stalls >= 3) {
            c->active = 0;
            return;
        }
        c->restarting = 1;
    }
};

/// A restart's mean of r (sum: its sum over the cells).
struct cg_restart_mean {
    poisson_control* c;
    double cells;
    SPHERE_HD void operator()(std::size_t) const
    {
        if (c->restarting) c->mean = c->sum / cells;
    }
};

/// The end of a restart: r.r (sum2).
struct cg_after_restart {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->restarting) return;
        c->rr = c->sum2;
        c->restarting = 0;
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
/// The loop runs on the device without waiting (detail::poisson_control): each pass is the
/// body of the loop above, its branches decided by one-thread kernels and taken by kernels
/// guarded by the control's flags; `solve` launches as many passes as the larger of the last
/// two solves needed and a quarter more, reads the control back once, and only launches more
/// (doubling) if the solve had not finished. On the host a guarded kernel whose flag is 0 is
/// not started.
///
/// Owns three scratch fields (residual r, direction p, A p), allocated once.
template <class Real, class Policy>
class cg_poisson : public detail::poisson_solver_base<cg_poisson<Real, Policy>, Real, Policy> {
    using base = detail::poisson_solver_base<cg_poisson<Real, Policy>, Real, Policy>;
    friend base;

public:
    static const char* name() { return "cg"; }

    explicit cg_poisson(const fluid_grid<Real>& g)
        : base(g), r_(g.field_size(), Real(0)), p_(g.field_size(), Real(0)), q_(g.field_size(), Real(0))
    {
    }

private:
    static constexpr bool restarts = true;

    /// r and p are zeroed first: their Dirichlet layers must be 0 (only unknowns are written),
    /// and the previous solve may have had other boundaries.
    void begin()
    {
        problem_.zero(r_.data());
        problem_.zero(p_.data());
        restart();
    }

    void run_passes()
    {
        for (unsigned i = 0; i < passes_; ++i) pass();
        problem_.conclude(*ctx_, c_, eps_, rhs_, nullptr, true, true);
    }

    /// One pass of the loop (see the class comment).
    void pass()
    {
        detail::poisson_control* c = c_;
        execution_context<Policy>& ctx = *ctx_;
        const detail::poisson_stencil<Real>& s = problem_.stencil();
        Real* r = r_.data();
        Real* p = p_.data();
        Real* q = q_.data();
        // |alpha| <= 1 / (smallest non-zero |eigenvalue|) for a direction in the range of A,
        // so |alpha| lambda_max is at most the condition number; a step beyond 1 / epsilon is
        // a direction that A does not see (round-off), never a useful step.
        const double largest_step = 1 / (s.lambda_max * 2.220446049250313e-16);
        const double cells = double(problem_.grid().cell_count());

        for_each_index(Policy{}, 1, detail::cg_begin_pass{c});
        problem_.fill_ghosts(p, &c->iterate);
        detail::apply_operator(problem_, &c->iterate, s, p, q);
        problem_.sum_unknowns_into(ctx, &c->iterate, detail::poisson_dot<Real>{p, q}, &c->sum);
        for_each_index(Policy{}, 1, detail::cg_after_apply{c, largest_step});

        problem_.for_each_unknown(&c->stepping, detail::cg_step<Real>{c, p, q, eps_, r});
        problem_.sum_unknowns_into(ctx, &c->stepping, detail::poisson_dot<Real>{r, r}, &c->sum2);
        if (problem_.singular())
            problem_.sum_unknowns_into(ctx, &c->stepping, detail::field_cell_value<Real>{r}, &c->sum);
        if (!problem_.relative())
            problem_.normalized_change_into(ctx, &c->stepping, eps_, nullptr, p, &c->alpha, &c->change);
        for_each_index(Policy{}, 1, detail::cg_after_step{c, problem_.singular() ? 1 : 0, cells});
        problem_.for_each_unknown(&c->directing, detail::cg_direction<Real>{c, r, p});

        problem_.fill_ghosts(eps_, &c->checking);
        problem_.residual_squared_into(ctx, &c->checking, eps_, rhs_, c, &c->sum);
        for_each_index(Policy{}, 1, detail::cg_after_check{c});
        restart();
    }

    /// Where c->restarting: r = p = b - A eps (eps's ghosts are refreshed first), with its mean
    /// removed in the singular case; rr = r.r.
    void restart()
    {
        detail::poisson_control* c = c_;
        execution_context<Policy>& ctx = *ctx_;
        const int* go = &c->restarting;
        problem_.fill_ghosts(eps_, go);
        problem_.for_each_unknown(go, detail::poisson_residual_field<Real>{problem_.stencil(), eps_, rhs_, &c->shift,
                                                                            r_.data()});
        if (problem_.singular()) {
            problem_.sum_unknowns_into(ctx, go, detail::field_cell_value<Real>{r_.data()}, &c->sum);
            for_each_index(Policy{}, 1, detail::cg_restart_mean{c, double(problem_.grid().cell_count())});
            problem_.for_each_unknown(go, detail::subtract_from_cells<Real>{r_.data(), &c->mean});
        }
        problem_.copy(r_.data(), p_.data(), go);
        problem_.sum_unknowns_into(ctx, go, detail::poisson_dot<Real>{r_.data(), r_.data()}, &c->sum2);
        for_each_index(Policy{}, 1, detail::cg_after_restart{c});
    }

    using base::c_;
    using base::ctx_;
    using base::eps_;
    using base::passes_;
    using base::problem_;
    using base::rhs_;

    buffer<Real, Policy> r_, p_, q_;
};

} // namespace sphere
