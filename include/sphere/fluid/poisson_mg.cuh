#pragma once
/// \file
/// The multigrid-preconditioned conjugate-gradient solver of the pressure-Poisson problem
/// (docs/fluid.md, *Multigrid-preconditioned CG*): the problem, settings, result and interface
/// of jacobi_poisson and cg_poisson (poisson.cuh, whose file comment defines the discrete
/// equations, the boundaries, the singular case and the criteria), with conjugate gradients
/// preconditioned by one geometric multigrid V-cycle per iteration, so that the iteration count
/// does not grow with the grid.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "../core/config.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "grid.cuh"
#include "poisson.cuh"
#include "poisson_cg.cuh"

namespace sphere {
namespace detail {

/// One level of the multigrid hierarchy: the unknowns of the problem (level 0) or of a
/// coarsened copy, stored compactly without ghosts (index (k n_y + j) n_x + i), periodic on x
/// and y. The operator is the 7-point Laplacian with coefficients c_a = 1/h_a^2 (0 on an axis
/// of one cell), and on the first and last layer a link to the boundary of coefficient z_lo,
/// z_hi: 0 for a Neumann end, 1/(delta h_z) for a Dirichlet end whose (homogeneous) value lies
/// delta below the first layer's centre (above the last one's).
struct mg_shape {
    unsigned n[3];
    double c[3];
    double z_lo, z_hi;

    SPHERE_HD std::size_t size() const { return std::size_t(n[0]) * n[1] * n[2]; }
};

/// The level's operator at compact index u = (k n_y + j) n_x + i: (A x)_u and its diagonal.
template <class Real>
SPHERE_HDI void mg_apply_at(const mg_shape& s, const Real* x, std::size_t u, int i, int j, int k, Real& ax, Real& diag)
{
    const std::size_t nx = s.n[0], ny = s.n[1], plane = nx * ny;
    const Real xc = x[u];
    const Real cx = Real(s.c[0]), cy = Real(s.c[1]), cz = Real(s.c[2]);
    const Real w = x[i == 0 ? u + nx - 1 : u - 1], e = x[i == int(nx) - 1 ? u + 1 - nx : u + 1];
    const Real so = x[j == 0 ? u + plane - nx : u - nx], no = x[j == int(ny) - 1 ? u + nx - plane : u + nx];
    Real sum = cx * ((w - xc) + (e - xc)) + cy * ((so - xc) + (no - xc));
    Real d = -Real(2) * (cx + cy);
    if (k > 0) {
        sum += cz * (x[u - plane] - xc);
        d -= cz;
    } else {
        sum -= Real(s.z_lo) * xc;
        d -= Real(s.z_lo);
    }
    if (k < int(s.n[2]) - 1) {
        sum += cz * (x[u + plane] - xc);
        d -= cz;
    } else {
        sum -= Real(s.z_hi) * xc;
        d -= Real(s.z_hi);
    }
    ax = sum;
    diag = d;
}

/// The level's diagonal at layer k.
template <class Real>
SPHERE_HDI Real mg_diagonal(const mg_shape& s, int k)
{
    const double d = 2 * (s.c[0] + s.c[1]) + (k > 0 ? s.c[2] : s.z_lo) + (k < int(s.n[2]) - 1 ? s.c[2] : s.z_hi);
    return Real(-d);
}

/// Runs kernel(u, i, j, k) on every cell of a level: on the host one index per `per_index`
/// rows along x (no division per cell; a kernel with `by_row` takes a whole row at once with
/// row(u of i = 0, j, k), so that what depends on j and k only is computed once per row), on
/// the GPU one index per cell (mg_cells).
template <class Kernel>
struct mg_rows {
    mg_shape s;
    Kernel kernel;
    std::size_t per_index;
    SPHERE_HD void operator()(std::size_t g) const
    {
        const std::size_t rows = std::size_t(s.n[1]) * s.n[2], nx = s.n[0];
        const std::size_t first = g * per_index, end = first + per_index < rows ? first + per_index : rows;
        for (std::size_t r = first; r < end; ++r) {
            const int j = int(r % s.n[1]), k = int(r / s.n[1]);
            if constexpr (Kernel::by_row) {
                kernel.row(r * nx, j, k);
            } else {
                for (std::size_t i = 0; i < nx; ++i) kernel(r * nx + i, int(i), j, k);
            }
        }
    }
};

template <class Kernel>
struct mg_cells {
    mg_shape s;
    Kernel kernel;
    SPHERE_HD void operator()(std::size_t u) const
    {
        const std::size_t plane = std::size_t(s.n[0]) * s.n[1];
        kernel(u, int(u % s.n[0]), int((u % plane) / s.n[0]), int(u / plane));
    }
};

template <class Kernel>
void mg_for_each_if(host, const int* go, const mg_shape& s, const Kernel& kernel)
{
    const std::size_t rows = std::size_t(s.n[1]) * s.n[2];
    const std::size_t per = host_rows_per_index(s.n[0]);
    for_each_index_if(host{}, go, (rows + per - 1) / per, mg_rows<Kernel>{s, kernel, per});
}

#if SPHERE_CUDA_COMPILER
template <class Kernel>
void mg_for_each_if(cuda, const int* go, const mg_shape& s, const Kernel& kernel)
{
    for_each_index_if(cuda{}, go, s.size(), mg_cells<Kernel>{s, kernel});
}
#endif

/// The first damped-Jacobi sweep from x = 0: x = omega b / diag.
template <class Real>
struct mg_first_sweep {
    static constexpr bool by_row = false;
    mg_shape s;
    Real omega;
    const Real* b;
    Real* x;
    SPHERE_HD void operator()(std::size_t u, int, int, int k) const { x[u] = omega * b[u] / mg_diagonal<Real>(s, k); }
};

/// One damped-Jacobi sweep: to = from + omega (b - A from) / diag.
template <class Real>
struct mg_sweep {
    static constexpr bool by_row = false;
    mg_shape s;
    Real omega;
    const Real* b;
    const Real* from;
    Real* to;
    SPHERE_HD void operator()(std::size_t u, int i, int j, int k) const
    {
        Real ax, d;
        mg_apply_at(s, from, u, i, j, k, ax, d);
        to[u] = from[u] + omega * (b[u] - ax) / d;
    }
};

/// r = b - A x.
template <class Real>
struct mg_residual {
    static constexpr bool by_row = false;
    mg_shape s;
    const Real* b;
    const Real* x;
    Real* r;
    SPHERE_HD void operator()(std::size_t u, int i, int j, int k) const
    {
        Real ax, d;
        mg_apply_at(s, x, u, i, j, k, ax, d);
        r[u] = b[u] - ax;
    }
};

/// The interpolation between a fine level and the next coarser one along one axis.
///   - cell (an even count n >= 4, coarse n / 2): fine cell c takes 3/4 of its own coarse cell
///     c / 2 and 1/4 of the coarse neighbour on its side (c even: below, odd: above); periodic
///     on x and y;
///   - vertex (z only, an odd count n >= 3, coarse (n - 1) / 2): coarse cell p sits on fine
///     layer 2 p + 1, which takes it whole; an even fine layer takes half of each coarse layer
///     beside it;
///   - neither (not coarsened): each cell maps to itself.
/// Along z a coarse neighbour beyond a Neumann end is the cell itself (its weight folds into
/// the own one), beyond a Dirichlet end the homogeneous boundary (dropped).
/// Restriction is the transpose: coarse cell p gathers the fine cells that take a weight of it.
struct mg_axis {
    enum kind_t : int { same = 0, cell = 1, vertex = 2 };
    int kind;
    int n_fine, n_coarse;
    bool periodic;
    bool neumann_lo, neumann_hi;

    /// The weight of fine cell c's candidate parent e (0: its own coarse cell, 1: the coarse
    /// neighbour on its side), whose index goes to p; 0 where there is none.
    SPHERE_HDI double parent(int c, int e, int& p) const
    {
        p = 0;
        if (kind == same) {
            p = c;
            return e == 0 ? 1.0 : 0.0;
        }
        if (kind == cell) {
            const int own = c / 2;
            int other = (c % 2 == 0) ? own - 1 : own + 1;
            const bool beyond = other < 0 || other >= n_coarse;
            if (e == 0) {
                p = own;
                if (!beyond || periodic) return 0.75;
                return (other < 0 ? neumann_lo : neumann_hi) ? 1.0 : 0.75;
            }
            if (beyond && !periodic) return 0.0;
            p = other < 0 ? other + n_coarse : (other >= n_coarse ? other - n_coarse : other);
            return 0.25;
        }
        if (c % 2 == 1) {
            p = (c - 1) / 2;
            return e == 0 ? 1.0 : 0.0;
        }
        const int below = c / 2 - 1, above = c / 2;
        if (e == 0) {
            if (below < 0) return 0.0;
            p = below;
            return above >= n_coarse && neumann_hi ? 1.0 : 0.5;
        }
        if (above >= n_coarse) return 0.0;
        p = above;
        return below < 0 && neumann_lo ? 1.0 : 0.5;
    }

    /// The weight that fine cell 2 p + d (d in -1 .. 2; wrapped on a periodic axis, its index
    /// to c) takes of coarse cell p, or p's own cell for an axis not coarsened (d = 0); 0 where
    /// there is none. The transpose of `parent`.
    SPHERE_HDI double child(int p, int d, int& c) const
    {
        c = 0;
        if (kind == same) {
            c = p;
            return d == 0 ? 1.0 : 0.0;
        }
        const bool first = p == 0, last = p == n_coarse - 1;
        if (kind == cell) {
            const int f = 2 * p + d;
            if (d == -1 || d == 2) {
                if (!periodic && (d == -1 ? first : last)) return 0.0;
                c = f < 0 ? f + n_fine : (f >= n_fine ? f - n_fine : f);
                return 0.25;
            }
            c = f;
            if (periodic) return 0.75;
            return (d == 0 ? first && neumann_lo : last && neumann_hi) ? 1.0 : 0.75;
        }
        if (d == -1) return 0.0;
        c = 2 * p + d;
        if (d == 1) return 1.0;
        return (d == 0 ? first && neumann_lo : last && neumann_hi) ? 1.0 : 0.5;
    }
};

/// The transfers between a fine level and the next coarser one.
struct mg_transfer {
    mg_axis axis[3];
    double scale; ///< 1 / 2^(coarsened axes): restriction = scale x interpolation's transpose
};

/// Coarse right-hand side: b_c = scale P^T r_f, gathered over the fine cells that interpolate
/// from coarse cell u (mg_axis::child; loops of fixed length, which the GPU keeps in registers).
template <class Real>
struct mg_restrict {
    static constexpr bool by_row = true;
    mg_transfer t;
    mg_shape coarse;
    const Real* r;
    Real* b;

    SPHERE_HD void operator()(std::size_t u, int pi, int pj, int pk) const
    {
        const std::size_t nfx = std::size_t(t.axis[0].n_fine), nfy = std::size_t(t.axis[1].n_fine);
        double sum = 0;
        for (int dk = -1; dk <= 2; ++dk) {
            int k;
            const double wk = t.axis[2].child(pk, dk, k);
            if (wk == 0) continue;
            for (int dj = -1; dj <= 2; ++dj) {
                int j;
                const double wj = t.axis[1].child(pj, dj, j);
                if (wj == 0) continue;
                const Real* line = r + (std::size_t(k) * nfy + std::size_t(j)) * nfx;
                double acc = 0;
                for (int di = -1; di <= 2; ++di) {
                    int i;
                    const double wi = t.axis[0].child(pi, di, i);
                    if (wi != 0) acc += wi * double(line[i]);
                }
                sum += wk * wj * acc;
            }
        }
        b[u] = Real(t.scale * sum);
    }

    /// Host: a whole row of coarse cells, the y and z weights taken once.
    SPHERE_HD void row(std::size_t u0, int pj, int pk) const
    {
        const std::size_t nfx = std::size_t(t.axis[0].n_fine), nfy = std::size_t(t.axis[1].n_fine);
        const Real* lines[16];
        double wl[16];
        int n = 0;
        for (int dk = -1; dk <= 2; ++dk) {
            int k;
            const double wk = t.axis[2].child(pk, dk, k);
            if (wk == 0) continue;
            for (int dj = -1; dj <= 2; ++dj) {
                int j;
                const double wj = t.axis[1].child(pj, dj, j);
                if (wj == 0) continue;
                lines[n] = r + (std::size_t(k) * nfy + std::size_t(j)) * nfx;
                wl[n++] = wk * wj;
            }
        }
        for (int pi = 0; pi < int(coarse.n[0]); ++pi) {
            int ix[4];
            double wx[4];
            for (int d = 0; d < 4; ++d) wx[d] = t.axis[0].child(pi, d - 1, ix[d]);
            double sum = 0;
            for (int l = 0; l < n; ++l) {
                double acc = 0;
                for (int d = 0; d < 4; ++d)
                    if (wx[d] != 0) acc += wx[d] * double(lines[l][ix[d]]);
                sum += wl[l] * acc;
            }
            b[u0 + std::size_t(pi)] = Real(t.scale * sum);
        }
    }
};

/// x_f += P x_c at fine cell u (mg_axis::parent).
template <class Real>
struct mg_interpolate_add {
    static constexpr bool by_row = true;
    mg_transfer t;
    mg_shape fine, coarse;
    const Real* xc;
    Real* x;

    SPHERE_HD void operator()(std::size_t u, int ci, int cj, int ck) const
    {
        double sum = 0;
        for (int ek = 0; ek < 2; ++ek) {
            int k;
            const double wk = t.axis[2].parent(ck, ek, k);
            if (wk == 0) continue;
            for (int ej = 0; ej < 2; ++ej) {
                int j;
                const double wj = t.axis[1].parent(cj, ej, j);
                if (wj == 0) continue;
                const Real* line = xc + (std::size_t(k) * coarse.n[1] + std::size_t(j)) * coarse.n[0];
                double acc = 0;
                for (int ei = 0; ei < 2; ++ei) {
                    int i;
                    const double wi = t.axis[0].parent(ci, ei, i);
                    if (wi != 0) acc += wi * double(line[i]);
                }
                sum += wk * wj * acc;
            }
        }
        x[u] += Real(sum);
    }

    /// Host: a whole row of fine cells, the y and z weights taken once.
    SPHERE_HD void row(std::size_t u0, int cj, int ck) const
    {
        const Real* lines[4];
        double wl[4];
        int n = 0;
        for (int ek = 0; ek < 2; ++ek) {
            int k;
            const double wk = t.axis[2].parent(ck, ek, k);
            if (wk == 0) continue;
            for (int ej = 0; ej < 2; ++ej) {
                int j;
                const double wj = t.axis[1].parent(cj, ej, j);
                if (wj == 0) continue;
                lines[n] = xc + (std::size_t(k) * coarse.n[1] + std::size_t(j)) * coarse.n[0];
                wl[n++] = wk * wj;
            }
        }
        for (int ci = 0; ci < int(fine.n[0]); ++ci) {
            int i0, i1;
            const double w0 = t.axis[0].parent(ci, 0, i0), w1 = t.axis[0].parent(ci, 1, i1);
            double sum = 0;
            for (int l = 0; l < n; ++l) {
                double acc = w0 * double(lines[l][i0]);
                if (w1 != 0) acc += w1 * double(lines[l][i1]);
                sum += wl[l] * acc;
            }
            x[u0 + std::size_t(ci)] += Real(sum);
        }
    }
};

/// Level 0's right-hand side from a field (its unknown cells), or a field's unknown cells from
/// level 0's solution.
template <class Real>
struct mg_from_field {
    poisson_stencil<Real> s;
    const Real* field;
    Real* compact;
    SPHERE_HD void operator()(std::size_t u) const { compact[u] = field[s.field(u)]; }
};

template <class Real>
struct mg_to_field {
    poisson_stencil<Real> s;
    const Real* compact;
    Real* field;
    SPHERE_HD void operator()(std::size_t u) const { field[s.field(u)] = compact[u]; }
};

/// PCG after A p (sum: p.Ap): the step alpha = r.z / p.Ap, as cg_after_apply. The
/// preconditioner approximates A^-1, which is negative definite like A, so r.z < 0 and alpha > 0.
struct pcg_after_apply {
    poisson_control* c;
    double largest_step;

    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->iterate) return;
        const double pq = c->sum;
        if (stop_if_not_finite(*c, pq, c->iterations)) return;
        if (!(pq < 0) || !(fabs(c->rr) < -pq * largest_step)) {
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

/// PCG after a step (sum2: the new r.r; sum: the sum of r in the singular case; change: the
/// normalized change's parts): the criterion; else the mean to project out of r and the
/// preconditioning of the new direction.
struct pcg_after_step {
    poisson_control* c;
    int singular;
    double cells;

    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->stepping) return;
        ++c->iterations;
        double rr_new = c->sum2;
        if (stop_if_not_finite(*c, rr_new, c->iterations)) return;
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
        c->mean = mean;
        c->directing = 1;
    }
};

/// After the preconditioning of the new residual (sum3: r.z): beta = r.z / (previous r.z).
struct pcg_after_precondition {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->directing) return;
        if (stop_if_not_finite(*c, c->sum3, c->iterations)) return;
        c->beta = c->rr != 0 ? c->sum3 / c->rr : 0.0;
        c->rr = c->sum3;
    }
};

/// p = z + beta p at cell f.
template <class Real>
struct pcg_direction {
    const poisson_control* c;
    const Real* z;
    Real* p;
    SPHERE_HD void operator()(std::size_t f) const { p[f] = z[f] + Real(c->beta) * p[f]; }
};

/// The end of a restart: r.z (sum3) is the inner product of the new direction.
struct pcg_after_restart {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->restarting) return;
        c->rr = c->sum3;
        c->restarting = 0;
    }
};

} // namespace detail

/// Conjugate gradients preconditioned by a geometric multigrid V-cycle, for the
/// pressure-Poisson problem of poisson.cuh (docs/fluid.md, *Multigrid-preconditioned CG*).
///
/// **Hierarchy.** Level 0 holds the unknowns (the cells of every layer but the Dirichlet
/// ones). A level is coarsened along x or y when its count there is even and at least 4
/// (halved), along z when its count of layers is even and at least 4 (halved) or odd and at
/// least 3 (every second layer kept: the layers between Dirichlet ends are usually odd in
/// number); the cell widths along a coarsened axis double, and a Dirichlet end's distance from
/// the end layer's centre grows by half a fine width (halving) or a whole one (every second
/// layer). Coarsening stops when no axis can be coarsened (on grids of powers of two at 2 cells
/// per axis). The operators are rediscretised on every level (mg_shape); interpolation is the
/// tensor product of one-dimensional weights (mg_axis), restriction its transpose over
/// 2^(coarsened axes).
///
/// **V-cycle** (one per CG iteration, applied to the residual r from z = 0): on each level
/// two damped-Jacobi sweeps (omega = 6/7, the 7-point stencil's best smoothing factor), the
/// residual restricted to the next level, the next level's cycle, its interpolation added, two
/// more sweeps; the coarsest level takes 2 max(n)^2 sweeps (even, 8 to 4096). The cycle is
/// symmetric (equal sweeps before and after, restriction the scaled transpose of
/// interpolation) and definite like A (negative), so CG stays CG: alpha = r.z / p.Ap,
/// beta = r.z (new) / r.z (old), p = z + beta p. The singular case projects the constant out of
/// r as cg_poisson does; z's constant part only shifts eps, whose mean is removed at the end.
///
/// **Criteria, restarts, breakdown, counting**: those of cg_poisson (one iteration = one
/// application of A and one V-cycle). The iteration count does not grow with the grid: 9-10
/// iterations to a relative residual of 1e-8 at 32^3, 64^3 and 128^3 with every pair of z
/// boundaries (tests/test_poisson.cpp, bench/bench_fluid.cpp). An x or y count that is odd is
/// never coarsened, and the coarsest level then keeps those cells and takes more sweeps: on
/// such grids cg_poisson may be as fast.
///
/// Owns four scratch fields (r, p, A p, z), allocated at construction, and three arrays per
/// level (two iterates and the right-hand side), laid out by the first solve and again when a
/// solve's boundaries differ from the last one's.
template <class Real, class Policy>
class mg_poisson : public detail::poisson_solver_base<mg_poisson<Real, Policy>, Real, Policy> {
    using base = detail::poisson_solver_base<mg_poisson<Real, Policy>, Real, Policy>;
    friend base;

public:
    static const char* name() { return "mg"; }

    explicit mg_poisson(const fluid_grid<Real>& g)
        : base(g), r_(g.field_size(), Real(0)), p_(g.field_size(), Real(0)), q_(g.field_size(), Real(0)),
          z_(g.field_size(), Real(0))
    {
    }

    /// Cells per axis of every level, finest first, for the boundaries of the last solve.
    std::vector<std::vector<unsigned>> level_sizes() const
    {
        std::vector<std::vector<unsigned>> out;
        for (const level& l : levels_) out.push_back({l.shape.n[0], l.shape.n[1], l.shape.n[2]});
        return out;
    }

private:
    static constexpr bool restarts = true;
    static constexpr double omega = 6.0 / 7.0;

    struct level {
        detail::mg_shape shape;
        detail::mg_transfer to_coarser; ///< unused on the coarsest level
        buffer<Real, Policy> x, y, b;
    };

    /// r and p are zeroed first (their Dirichlet layers must be 0), the levels laid out for
    /// these boundaries, then the restart.
    void begin()
    {
        problem_.zero(r_.data());
        problem_.zero(p_.data());
        problem_.zero(z_.data());
        lay_out_levels();
        restart();
    }

    void run_passes()
    {
        for (unsigned i = 0; i < passes_; ++i) pass();
        problem_.conclude(*ctx_, c_, eps_, rhs_, nullptr, true, true);
    }

    /// The levels for the current stencil's unknowns and boundaries (kept while they match).
    void lay_out_levels()
    {
        const detail::poisson_stencil<Real>& s = problem_.stencil();
        const unsigned n0[3] = {s.grid.n[0], s.grid.n[1], unsigned(s.k_count)};
        if (!levels_.empty() && levels_[0].shape.n[2] == n0[2] && laid_bottom_ == s.bottom_dirichlet &&
            laid_top_ == s.top_dirichlet)
            return;
        levels_.clear();
        laid_bottom_ = s.bottom_dirichlet;
        laid_top_ = s.top_dirichlet;
        double h[3] = {double(s.grid.width.x), double(s.grid.width.y), double(s.grid.width.z)};
        unsigned n[3] = {n0[0], n0[1], n0[2]};
        double delta_lo = h[2], delta_hi = h[2]; // a Dirichlet value's distance from the end layer's centre
        for (;;) {
            level l;
            for (int a = 0; a < 3; ++a) {
                l.shape.n[a] = n[a];
                l.shape.c[a] = n[a] > 1 ? 1 / (h[a] * h[a]) : 0.0;
            }
            l.shape.z_lo = s.bottom_dirichlet ? 1 / (delta_lo * h[2]) : 0.0;
            l.shape.z_hi = s.top_dirichlet ? 1 / (delta_hi * h[2]) : 0.0;
            // Along x and y (periodic) an even count of 4 or more halves; along z an even count
            // of 4 or more halves cell by cell, an odd count of 3 or more keeps every second
            // layer (mg_axis).
            int kind[3];
            int halved = 0;
            for (int a = 0; a < 3; ++a) {
                kind[a] = n[a] % 2 == 0 && n[a] >= 4 ? detail::mg_axis::cell
                          : a == 2 && n[a] % 2 == 1 && n[a] >= 3 ? detail::mg_axis::vertex
                                                                  : detail::mg_axis::same;
                halved += kind[a] != detail::mg_axis::same ? 1 : 0;
            }
            unsigned coarse_n[3];
            for (int a = 0; a < 3; ++a) {
                coarse_n[a] = kind[a] == detail::mg_axis::cell ? n[a] / 2
                              : kind[a] == detail::mg_axis::vertex ? (n[a] - 1) / 2
                                                                   : n[a];
                l.to_coarser.axis[a] = {kind[a], int(n[a]), int(coarse_n[a]), a < 2, !s.bottom_dirichlet,
                                        !s.top_dirichlet};
            }
            l.to_coarser.scale = 1.0 / double(1u << halved);
            const std::size_t size = l.shape.size();
            l.x = buffer<Real, Policy>(size, Real(0));
            l.y = buffer<Real, Policy>(size, Real(0));
            l.b = buffer<Real, Policy>(size, Real(0));
            levels_.push_back(std::move(l));
            if (halved == 0 || levels_.size() == max_levels) break;
            // A Dirichlet value's distance from the end layer's centre: the coarse end layer's
            // centre is half a fine width further (cell: the mean of two fine centres) or a
            // whole one (vertex: the second fine layer).
            if (kind[2] != detail::mg_axis::same) {
                const double further = kind[2] == detail::mg_axis::cell ? h[2] / 2 : h[2];
                delta_lo += further;
                delta_hi += further;
            }
            for (int a = 0; a < 3; ++a)
                if (kind[a] != detail::mg_axis::same) {
                    n[a] = coarse_n[a];
                    h[a] *= 2;
                }
        }
        const detail::mg_shape& coarsest = levels_.back().shape;
        const unsigned n_max = std::max(coarsest.n[0], std::max(coarsest.n[1], coarsest.n[2]));
        unsigned sweeps = 2 * n_max * n_max;
        sweeps = sweeps < 8 ? 8 : (sweeps > 4096 ? 4096 : sweeps);
        coarsest_sweeps_ = sweeps + sweeps % 2;
    }

    /// z = M r on the unknowns (one V-cycle from zero), if *go.
    void precondition(const int* go, const Real* r, Real* z)
    {
        const detail::poisson_stencil<Real>& s = problem_.stencil();
        for_each_index_if(Policy{}, go, s.unknowns(), detail::mg_from_field<Real>{s, r, levels_[0].b.data()});
        cycle(go, 0);
        for_each_index_if(Policy{}, go, s.unknowns(), detail::mg_to_field<Real>{s, levels_[0].y.data(), z});
    }

    /// The V-cycle on level l from zero, its right-hand side in b; the result in y.
    void cycle(const int* go, std::size_t l)
    {
        level& L = levels_[l];
        const Real w = Real(omega);
        const bool coarsest = l + 1 == levels_.size();
        const unsigned sweeps = coarsest ? coarsest_sweeps_ : 2;
        detail::mg_for_each_if(Policy{}, go, L.shape, detail::mg_first_sweep<Real>{L.shape, w, L.b.data(), L.x.data()});
        for (unsigned k = 1; k < sweeps; ++k) {
            const bool odd = k % 2 == 1;
            detail::mg_for_each_if(Policy{}, go, L.shape,
                                   detail::mg_sweep<Real>{L.shape, w, L.b.data(), odd ? L.x.data() : L.y.data(),
                                                          odd ? L.y.data() : L.x.data()});
        }
        if (coarsest) return;
        level& C = levels_[l + 1];
        detail::mg_for_each_if(Policy{}, go, L.shape, detail::mg_residual<Real>{L.shape, L.b.data(), L.y.data(), L.x.data()});
        detail::mg_for_each_if(Policy{}, go, C.shape,
                               detail::mg_restrict<Real>{L.to_coarser, C.shape, L.x.data(), C.b.data()});
        cycle(go, l + 1);
        detail::mg_for_each_if(Policy{}, go, L.shape,
                               detail::mg_interpolate_add<Real>{L.to_coarser, L.shape, C.shape, C.y.data(), L.y.data()});
        detail::mg_for_each_if(Policy{}, go, L.shape, detail::mg_sweep<Real>{L.shape, w, L.b.data(), L.y.data(), L.x.data()});
        detail::mg_for_each_if(Policy{}, go, L.shape, detail::mg_sweep<Real>{L.shape, w, L.b.data(), L.x.data(), L.y.data()});
    }

    /// One pass of the loop: cg_poisson's, with the direction from the preconditioned residual.
    void pass()
    {
        detail::poisson_control* c = c_;
        execution_context<Policy>& ctx = *ctx_;
        const detail::poisson_stencil<Real>& s = problem_.stencil();
        Real* r = r_.data();
        Real* p = p_.data();
        Real* q = q_.data();
        const double largest_step = 1 / (s.lambda_max * 2.220446049250313e-16);
        const double cells = double(problem_.grid().cell_count());

        for_each_index(Policy{}, 1, detail::cg_begin_pass{c});
        problem_.fill_ghosts(p, &c->iterate);
        detail::apply_operator(problem_, &c->iterate, s, p, q);
        problem_.sum_unknowns_into(ctx, &c->iterate, detail::poisson_dot<Real>{p, q}, &c->sum);
        for_each_index(Policy{}, 1, detail::pcg_after_apply{c, largest_step});

        problem_.for_each_unknown(&c->stepping, detail::cg_step<Real>{c, p, q, eps_, r});
        problem_.sum_unknowns_into(ctx, &c->stepping, detail::poisson_dot<Real>{r, r}, &c->sum2);
        if (problem_.singular())
            problem_.sum_unknowns_into(ctx, &c->stepping, detail::field_cell_value<Real>{r}, &c->sum);
        if (!problem_.relative())
            problem_.normalized_change_into(ctx, &c->stepping, eps_, nullptr, p, &c->alpha, &c->change);
        for_each_index(Policy{}, 1, detail::pcg_after_step{c, problem_.singular() ? 1 : 0, cells});
        if (problem_.singular()) problem_.for_each_unknown(&c->directing, detail::subtract_from_cells<Real>{r, &c->mean});
        precondition(&c->directing, r, z_.data());
        problem_.sum_unknowns_into(ctx, &c->directing, detail::poisson_dot<Real>{r, z_.data()}, &c->sum3);
        for_each_index(Policy{}, 1, detail::pcg_after_precondition{c});
        problem_.for_each_unknown(&c->directing, detail::pcg_direction<Real>{c, z_.data(), p});

        problem_.fill_ghosts(eps_, &c->checking);
        problem_.residual_squared_into(ctx, &c->checking, eps_, rhs_, c, &c->sum);
        for_each_index(Policy{}, 1, detail::cg_after_check{c});
        restart();
    }

    /// Where c->restarting: r = b - A eps (eps's ghosts refreshed first), its mean removed in
    /// the singular case; z = M r, p = z, rr = r.z.
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
        precondition(go, r_.data(), z_.data());
        problem_.copy(z_.data(), p_.data(), go);
        problem_.sum_unknowns_into(ctx, go, detail::poisson_dot<Real>{r_.data(), z_.data()}, &c->sum3);
        for_each_index(Policy{}, 1, detail::pcg_after_restart{c});
    }

    using base::c_;
    using base::ctx_;
    using base::eps_;
    using base::passes_;
    using base::problem_;
    using base::rhs_;

    static constexpr std::size_t max_levels = 24;

    buffer<Real, Policy> r_, p_, q_, z_;
    std::vector<level> levels_;
    bool laid_bottom_ = false, laid_top_ = false;
    unsigned coarsest_sweeps_ = 8;
};

} // namespace sphere
