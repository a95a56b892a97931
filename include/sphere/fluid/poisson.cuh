#pragma once
/// \file
/// The pressure-Poisson problem of the projection step and its Jacobi solver
/// (docs/fluid.md, *Pressure Poisson solvers*); the faster conjugate-gradient solver with the
/// same interface is in poisson_cg.cuh.
///
/// **The discrete problem.** The unknown eps lives on the cells (i, j, k), 0 <= i < nx,
/// 0 <= j < ny, 0 <= k < nz, of a fluid_grid<Real>, stored in a field with ghost nodes
/// (`grid.field_index(i, j, k)`, each coordinate in [-1, n]). On every unknown cell it obeys
/// the compact 7-point Laplacian
///
///     (e[i+1,j,k] - 2 e[i,j,k] + e[i-1,j,k]) / dx^2
///   + (e[i,j+1,k] - 2 e[i,j,k] + e[i,j-1,k]) / dy^2
///   + (e[i,j,k+1] - 2 e[i,j,k] + e[i,j,k-1]) / dz^2  =  b[i,j,k]
///
/// with dx, dy, dz the cell widths (m) and b the right-hand side field (same layout; for the
/// projection step eps is a pressure in Pa and b is in Pa/m^2).
///
/// **Variable coefficients** (`poisson_coefficients`, the Darcy model's implicit pressure
/// diffusion, docs/fluid.md (D-4)): given a cell field K > 0 (with ghosts) and a cell field
/// S >= 0, the row of cell c is instead
///
///     sum over a of [K_a+ (e[c + a] - e[c]) - K_a- (e[c] - e[c - a])] / h_a^2  -  S[c] e[c]  =  b[c]
///
/// with K_a+- the harmonic mean of K on the two cells of the face, 2 K K' / (K + K'): the
/// conductance of two half cells in series. S > 0 makes the problem non-singular with any
/// boundaries. Without coefficients K = 1 and S = 0 (the Laplacian above). Boundaries:
///   - x and y are always periodic (as in the seeds, whatever the world box's axis types):
///     neighbour -1 is cell n - 1 and neighbour n is cell 0;
///   - each end of z is a `z_boundary`:
///       dirichlet: the whole cell layer k = 0 (bottom) or k = nz - 1 (top) is not an unknown:
///         it holds a prescribed value, given in eps on entry and never changed by the solver
///         (the Dirichlet value sits at that cell's centre). Needs nz >= 3.
///       neumann: the ghost layer k = -1 (or nz) equals the adjacent cell k = 0 (or nz - 1):
///         zero normal gradient at the wall face, so that row's z term is
///         (e[k+1] - e[k]) / dz^2 (bottom) or (e[k-1] - e[k]) / dz^2 (top).
///
/// **Singular case.** With Neumann at both ends (and periodic x, y) the operator annihilates
/// constants: b must have zero mean for a solution to exist, and a solution is defined up to a
/// constant. The solvers then solve the compatible problem with b replaced by b - mean(b) (the
/// mean over the cells; rhs itself is not modified; this is the least-squares solution), and
/// return the solution with zero mean over the cells (to round-off).
///
/// **On return** every ghost node of eps is filled consistently with the boundaries, so
/// callers can take centred differences anywhere: on x and y the periodic copies; on a Neumann
/// end the copy of the adjacent cell; on a Dirichlet end the linear extrapolation
/// e[-1] = 2 e[0] - e[1] (top: e[nz] = 2 e[nz-1] - e[nz-2]), which makes the centred gradient
/// at the Dirichlet cell the one-sided (e[1] - e[0]) / dz. Edge and corner ghosts combine the
/// rules (a z ghost of a periodic column is the z ghost of the wrapped column).
///
/// **Stopping criteria** (`poisson_criterion`):
///   - relative_residual (default): ||b - A eps||_2 / ||b_u||_2 over the unknowns, where b_u is
///     the right-hand side of the system for the unknowns: b (after the mean removal in the
///     singular case) minus the stencil terms that reach into a Dirichlet layer (so that a
///     problem driven by its boundary values alone, b = 0, is measured against them rather
///     than against round-off in b); evaluated in double precision whatever Real is; the
///     absolute residual ||b - A eps||_2 when ||b_u||_2 = 0 (so a fluid at rest, b = 0 and
///     eps = 0, gives exactly 0). It bounds the error of the solution
///     (||error|| <= ||A^-1|| ||b|| x residual). Precision: eps is stored in Real, and merely
///     rounding the exact solution to Real leaves a relative residual of about
///     epsilon_Real x (2/dx^2 + 2/dy^2 + 2/dz^2) max|eps| / rms(b); in float that is 1e-6 to
///     1e-4 (64^3 with a Dirichlet top and a right-hand side of non-zero mean: 1e-4), so a
///     float solve needs a tolerance above that floor, or it runs to max_iterations and
///     returns converged = false. The default 1e-8 is meant for double.
///   - normalized_change (the seeds' "normalized residual"): the largest over the unknowns of
///     (eps_new - eps_old)^2 / eps_new^2 between consecutive iterates. A cell with
///     eps_new = 0 and no change contributes 0; a cell with eps_new = 0 that changed uses the
///     largest eps_new^2 of the field as denominator (1 if the whole field is 0). The seeds
///     divided 0 by 0 there and produced NaN for a fluid at rest. This measures stagnation,
///     not accuracy: a slowly converging iteration makes small changes long before it is
///     close to the solution, and the value depends on the offset of eps.
/// Before the first iteration the criterion is evaluated on the initial guess (for
/// normalized_change: whether the true residual is exactly 0); if it is met, solve returns
/// iterations = 0 and converged = true. A solve that reaches max_iterations returns
/// converged = false with the iteration count and the last residual; it does not throw: the
/// caller decides (the projection step may accept the iterate, warn, or stop).
///
/// **Errors** (sphere::error): tolerance <= 0 or not finite, max_iterations = 0, nz < 3 with a
/// Dirichlet end, and a residual that becomes NaN or infinite (NaN/inf input or divergence).
///
/// **Determinism.** Every kernel writes only its own cells, and every reduction has a fixed
/// association order: on the host, fixed groups of whole rows are summed in order (in
/// parallel over groups) and the group sums in order, independent of the thread count; on
/// the GPU through transform_reduce_into (CUB, run-to-run deterministic). The same input on the
/// same backend gives bit-identical output (on the host, for any number of threads).
#include <cmath>
#include <cstddef>

#include "../core/config.cuh"
#include "../core/error.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "grid.cuh"

namespace sphere {

/// The condition at one end (bottom, k = 0, or top, k = nz - 1) of the z axis of a Poisson
/// problem (see the file comment).
enum class z_boundary {
    dirichlet, ///< the end cell layer holds a prescribed value (in eps on entry) and is no unknown
    neumann,   ///< zero normal gradient: the ghost layer equals the end cell layer
};

/// The z boundaries of a Poisson problem; x and y are always periodic.
struct poisson_boundaries {
    z_boundary bottom = z_boundary::neumann; ///< at k = 0
    z_boundary top = z_boundary::neumann;    ///< at k = nz - 1
};

/// How a solver decides that it has converged (see the file comment).
enum class poisson_criterion {
    relative_residual, ///< ||b - A eps||_2 / ||b||_2 <= tolerance (absolute when b = 0)
    normalized_change, ///< max (eps_new - eps_old)^2 / eps_new^2 <= tolerance (the seeds')
};

/// A criterion's name as written in C++ ("relative_residual", "normalized_change").
inline const char* name(poisson_criterion c)
{
    return c == poisson_criterion::normalized_change ? "normalized_change" : "relative_residual";
}

/// Settings of one solve.
struct poisson_settings {
    double tolerance = 1e-8;          ///< threshold of the criterion; positive and finite
    unsigned max_iterations = 100000; ///< at least 1; reaching it returns converged = false
    poisson_criterion criterion = poisson_criterion::relative_residual;
};

/// What a solve did.
struct poisson_result {
    unsigned iterations = 0; ///< iterations applied to the returned eps (0: the guess was accepted)
    double residual = 0;     ///< the criterion's value for the returned eps (relative_residual)
                             ///< or for the last iteration (normalized_change)
    bool converged = false;  ///< residual <= tolerance
};

/// Optional variable coefficients of a Poisson problem (poisson.cuh's file comment), in the
/// policy's memory: K with its ghosts filled, S on the cells. The bounds K_max >= max K and
/// S_max >= max S bound the operator's spectrum (CG's breakdown test).
template <class Real>
struct poisson_coefficients {
    const Real* conductance = nullptr; ///< K (same units as the caller's equation), or null: 1
    const Real* sink = nullptr;        ///< S (1/m^2 x K's unit), or null: 0
    double conductance_max = 1;
    double sink_max = 0;
};

namespace detail {

/// Geometry of a Poisson problem for the kernels: the grid, the unknown cell layers
/// k_first .. k_first + k_count - 1 (all nz layers but the Dirichlet ones), the field strides
/// and the stencil coefficients 1/dx^2, 1/dy^2, 1/dz^2 (1/m^2).
template <class Real>
struct poisson_stencil {
    fluid_grid<Real> grid;
    int k_first;                ///< first unknown layer: 1 with a Dirichlet bottom, else 0
    int k_count;                ///< number of unknown layers
    bool bottom_dirichlet;
    bool top_dirichlet;
    std::size_t sy, sz;         ///< field strides along y and z (x: 1)
    double cx, cy, cz;          ///< 1/dx^2, 1/dy^2, 1/dz^2 (1/m^2)
    const Real* conductance;    ///< K (cells and ghosts), or null: K = 1 (file comment)
    const Real* sink;           ///< S (cells), or null: S = 0
    double lambda_max;          ///< a bound on the largest |eigenvalue| of the operator

    /// Whether the operator has variable coefficients.
    SPHERE_HD bool variable() const { return conductance != nullptr || sink != nullptr; }

    /// Number of unknown cells.
    SPHERE_HD std::size_t unknowns() const { return std::size_t(grid.n[0]) * grid.n[1] * std::size_t(k_count); }

    /// Number of rows of unknowns along x (one per unknown (j, k)).
    SPHERE_HD std::size_t rows() const { return std::size_t(grid.n[1]) * std::size_t(k_count); }

    /// Field index of the first cell (i = 0) of row r (y fastest, then the unknown layers).
    SPHERE_HD std::size_t row_start(std::size_t r) const
    {
        return grid.field_index(0, static_cast<int>(r % grid.n[1]), static_cast<int>(r / grid.n[1]) + k_first);
    }

    /// Field index of unknown u (x fastest, then y, then the unknown layers).
    SPHERE_HD std::size_t field(std::size_t u) const
    {
        const int i = static_cast<int>(u % grid.n[0]);
        u /= grid.n[0];
        const int j = static_cast<int>(u % grid.n[1]);
        const int k = static_cast<int>(u / grid.n[1]) + k_first;
        return grid.field_index(i, j, k);
    }

    /// The conductance of the face between field indices f and g: the harmonic mean of K.
    SPHERE_HD double face(std::size_t f, std::size_t g) const
    {
        if (!conductance) return 1.0;
        const double a = double(conductance[f]), b = double(conductance[g]);
        return 2 * a * b / (a + b);
    }

    /// (A e) at field index f, in double, from a field whose ghosts are filled.
    SPHERE_HD double laplacian(const Real* e, std::size_t f) const
    {
        if (variable()) return variable_laplacian(e, f);
        const double c = double(e[f]);
        return cx * ((double(e[f - 1]) - c) + (double(e[f + 1]) - c)) +
               cy * ((double(e[f - sy]) - c) + (double(e[f + sy]) - c)) +
               cz * ((double(e[f - sz]) - c) + (double(e[f + sz]) - c));
    }

    /// (A e) at field index f with the coefficients (file comment), in double.
    SPHERE_HD double variable_laplacian(const Real* e, std::size_t f) const
    {
        const double c = double(e[f]);
        const std::size_t stride[3] = {1, sy, sz};
        const double weight[3] = {cx, cy, cz};
        double sum = sink ? -double(sink[f]) * c : 0.0;
        for (int a = 0; a < 3; ++a) {
            const std::size_t lo = f - stride[a], hi = f + stride[a];
            sum += weight[a] * (face(f, hi) * (double(e[hi]) - c) - face(lo, f) * (c - double(e[lo])));
        }
        return sum;
    }
};

/// Fills every ghost node of a field from its cells (see the file comment): periodic copies
/// on x and y, a copy of the end cell on a Neumann end, 2 e[0] - e[1] on a Dirichlet end. The
/// ghost nodes are numbered g = 0 .. count - 1 as: the two z ghost planes (k = -1, nz; all i, j in
/// [-1, n]), then for each layer k in [0, nz) the two y ghost rows (j = -1, ny; all i), then
/// for each (j, k) in the cells the two x ghosts. Ghosts are computed from cells only, so
/// they are independent. Each index of the loop fills `per_index` consecutive ghosts (host: see
/// host_cells_per_index; 1 on the GPU).
template <class Real>
struct fill_poisson_ghosts {
    poisson_stencil<Real> s;
    Real* e;
    std::size_t per_index;
    std::size_t count; ///< number of ghost nodes

    SPHERE_HD void operator()(std::size_t index) const
    {
        const std::size_t first = index * per_index, end = first + per_index < count ? first + per_index : count;
        for (std::size_t g = first; g < end; ++g) fill(g);
    }

    SPHERE_HD static int wrap(int i, int n) { return i < 0 ? n - 1 : (i >= n ? 0 : i); }

    SPHERE_HD void fill(std::size_t g) const
    {
        const int nx = static_cast<int>(s.grid.n[0]), ny = static_cast<int>(s.grid.n[1]),
                  nz = static_cast<int>(s.grid.n[2]);
        const std::size_t row = std::size_t(nx) + 2, plane = row * (std::size_t(ny) + 2);
        int i, j, k;
        if (g < 2 * plane) {
            k = g < plane ? -1 : nz;
            const std::size_t r = g % plane;
            i = static_cast<int>(r % row) - 1;
            j = static_cast<int>(r / row) - 1;
        } else if (g - 2 * plane < 2 * row * std::size_t(nz)) {
            const std::size_t h = g - 2 * plane;
            k = static_cast<int>(h / (2 * row));
            const std::size_t r = h % (2 * row);
            j = r < row ? -1 : ny;
            i = static_cast<int>(r % row) - 1;
        } else {
            const std::size_t h = g - 2 * plane - 2 * row * std::size_t(nz);
            k = static_cast<int>(h / (2 * std::size_t(ny)));
            const std::size_t r = h % (2 * std::size_t(ny));
            j = static_cast<int>(r / 2);
            i = (r % 2) ? nx : -1;
        }
        const int si = wrap(i, nx), sj = wrap(j, ny);
        Real v;
        if (k == -1) {
            const Real e0 = e[s.grid.field_index(si, sj, 0)];
            v = s.bottom_dirichlet ? Real(2) * e0 - e[s.grid.field_index(si, sj, 1)] : e0;
        } else if (k == nz) {
            const Real e0 = e[s.grid.field_index(si, sj, nz - 1)];
            v = s.top_dirichlet ? Real(2) * e0 - e[s.grid.field_index(si, sj, nz - 2)] : e0;
        } else {
            v = e[s.grid.field_index(si, sj, k)];
        }
        e[s.grid.field_index(i, j, k)] = v;
    }
};

/// The singular case's mean of b, removed from b: the unevaluated sum hi + lo, where hi is the
/// mean of b over the cells and lo the mean of b - hi (0 and 0 outside the singular case).
/// A single double cannot hold the mean of a right-hand side whose mean is much larger than
/// its variations (a fluid's b: ~2e3 Pa/m^2 with variations of ~1e-7): b - hi keeps a
/// constant of up to ulp(hi) / 2 per cell, which A cannot remove (A annihilates constants),
/// so the residual could never fall below ~ulp(hi) / rms(b - hi) relative (1e-6 there).
/// (b - hi) - lo is zero-mean to the round-off of b - hi, which is exact when b is within a
/// factor 2 of hi.
struct poisson_shift {
    double hi = 0;
    double lo = 0;

    SPHERE_HD double from(double b) const { return (b - hi) - lo; }
};

/// (b - shift - A e)^2 at cell f, in double; e with filled ghosts. Summed: ||b - A e||^2.
template <class Real>
struct poisson_residual_squared {
    poisson_stencil<Real> s;
    const Real* e;
    const Real* b;
    const poisson_shift* shift; ///< mean of b in the singular case, else 0 (policy memory)

    SPHERE_HD double operator()(std::size_t f) const
    {
        const double r = shift->from(double(b[f])) - s.laplacian(e, f);
        return r * r;
    }
};

/// (b - shift - known)^2 at cell f, in double, where `known` are the terms of the stencil that
/// reach into a Dirichlet layer (cz times its value): the right-hand side of the system for the
/// unknowns. Summed: its squared norm, the scale of the relative residual, so that a problem
/// driven by its boundary values alone (b = 0, as a pressure difference between two
/// prescribed layers) is measured against them and not against round-off in b.
template <class Real>
struct poisson_rhs_squared {
    poisson_stencil<Real> s;
    const Real* e; ///< holds the Dirichlet values
    const Real* b;
    const poisson_shift* shift;

    SPHERE_HD double operator()(std::size_t f) const
    {
        double v = shift->from(double(b[f]));
        const int k = static_cast<int>(f / s.sz) - 1;
        if (s.bottom_dirichlet && k == s.k_first) v -= s.cz * s.face(f - s.sz, f) * double(e[f - s.sz]);
        if (s.top_dirichlet && k == s.k_first + s.k_count - 1) v -= s.cz * s.face(f, f + s.sz) * double(e[f + s.sz]);
        return v * v;
    }
};

/// The value of a cell of a field, in double. Summed over the cells: their sum.
template <class Real>
struct field_cell_value {
    const Real* v;
    SPHERE_HD double operator()(std::size_t f) const { return double(v[f]); }
};

/// The value of a cell of a field minus `*offset`, in double. Summed over the cells: their sum.
template <class Real>
struct field_cell_offset {
    const Real* v;
    const double* offset;
    SPHERE_HD double operator()(std::size_t f) const { return double(v[f]) - *offset; }
};

/// v -= Real(*value) on a cell (value in the policy's memory).
template <class Real>
struct subtract_from_cells {
    Real* v;
    const double* value;
    SPHERE_HD void operator()(std::size_t f) const { v[f] -= Real(*value); }
};

/// dst[i] = src[i].
template <class Real>
struct copy_values {
    const Real* src;
    Real* dst;
    SPHERE_HD void operator()(std::size_t i) const { dst[i] = src[i]; }
};

/// v[i] = value.
template <class Real>
struct set_values {
    Real* v;
    Real value;
    SPHERE_HD void operator()(std::size_t i) const { v[i] = value; }
};

/// Ingredients of the normalized change, combined by `normalized_change_max` into
/// max(ratio, zero_change2 / new2) (see normalized_change_value).
struct normalized_change_parts {
    double ratio;        ///< largest (new - old)^2 / new^2 over cells with new != 0
    double new2;         ///< largest new^2
    double zero_change2; ///< largest (new - old)^2 over cells with new = 0
};

/// Element-wise maximum of normalized_change_parts; a NaN in either operand wins.
struct normalized_change_max {
    SPHERE_HD static double nan_max(double a, double b) { return (a < b || b != b) ? b : a; }
    SPHERE_HD normalized_change_parts operator()(const normalized_change_parts& a,
                                                 const normalized_change_parts& b) const
    {
        return {nan_max(a.ratio, b.ratio), nan_max(a.new2, b.new2), nan_max(a.zero_change2, b.zero_change2)};
    }
};

/// The parts of the normalized change at cell f between the new iterate x and the
/// previous one: the change is x - old when `old` is given, else *step * p (a CG step).
template <class Real>
struct normalized_change_at {
    const Real* x;
    const Real* old;
    const Real* p;
    const double* step;

    SPHERE_HD normalized_change_parts operator()(std::size_t f) const
    {
        const double n = double(x[f]);
        const double d = old ? n - double(old[f]) : *step * double(p[f]);
        const double n2 = n * n, d2 = d * d;
        if (n2 > 0) return {d2 / n2, n2, 0.0};
        return {0.0, 0.0, d2};
    }
};

/// The normalized change from its reduced parts: a cell with eps_new = 0 that changed is
/// measured against the largest eps_new^2 (1 when the whole field is 0). NaN propagates.
SPHERE_HD inline double normalized_change_value(const normalized_change_parts& m)
{
    if (m.ratio != m.ratio || m.new2 != m.new2 || m.zero_change2 != m.zero_change2)
        return m.ratio + m.new2 + m.zero_change2; // NaN
    if (m.zero_change2 == 0) return m.ratio;
    const double zero = m.new2 > 0 ? m.zero_change2 / m.new2 : 1.0;
    return m.ratio < zero ? zero : m.ratio;
}

/// One Jacobi sweep on cell f: the classic update of the seeds,
///   e_new = [dy^2 dz^2 (e_w + e_e) + dx^2 dz^2 (e_s + e_n) + dx^2 dy^2 (e_b + e_t)
///            - dx^2 dy^2 dz^2 b] / [2 (dx^2 dy^2 + dx^2 dz^2 + dy^2 dz^2)],
/// evaluated as wx (e_w + e_e) + wy (e_s + e_n) + wz (e_b + e_t) - wb b with the weights
/// divided through (wx = (1/dx^2) / D, ..., wb = 1 / D, D = 2 (1/dx^2 + 1/dy^2 + 1/dz^2)),
/// which is the same expression without the dx^6-sized products (float underflow).
template <class Real>
struct jacobi_sweep {
    poisson_stencil<Real> s;
    Real wx, wy, wz, wb;
    const poisson_shift* shift; ///< policy memory
    const Real* b;
    const Real* old;
    Real* out;

    SPHERE_HD void operator()(std::size_t f) const
    {
        out[f] = wx * (old[f - 1] + old[f + 1]) + wy * (old[f - s.sy] + old[f + s.sy]) +
                 wz * (old[f - s.sz] + old[f + s.sz]) - wb * (b[f] - Real(shift->hi + shift->lo));
    }
};

/// jacobi_sweep with the coefficients (file comment): each unknown satisfies its own row with
/// the neighbours' previous values,
///   e_new = [sum_a c_a (K_a+ e_a+ + K_a- e_a-) - b] / [sum_a c_a (K_a+ + K_a-) + S].
template <class Real>
struct jacobi_sweep_variable {
    poisson_stencil<Real> s;
    const poisson_shift* shift; ///< policy memory
    const Real* b;
    const Real* old;
    Real* out;

    SPHERE_HD void operator()(std::size_t f) const
    {
        const std::size_t stride[3] = {1, s.sy, s.sz};
        const double weight[3] = {s.cx, s.cy, s.cz};
        double sum = -shift->from(double(b[f])), diagonal = s.sink ? double(s.sink[f]) : 0.0;
        for (int a = 0; a < 3; ++a) {
            const std::size_t lo = f - stride[a], hi = f + stride[a];
            const double k_hi = weight[a] * s.face(f, hi), k_lo = weight[a] * s.face(lo, f);
            sum += k_hi * double(old[hi]) + k_lo * double(old[lo]);
            diagonal += k_hi + k_lo;
        }
        out[f] = Real(sum / diagonal);
    }
};

/// Host work unit of the cell loops: whole rows of nx cells along x, at least
/// `host_cells_per_index` cells per index, so that for_each_index (parallel from
/// host_parallel_threshold indices) starts threads only from about 32k cells: below that a
/// sweep takes microseconds, less than starting and joining a team (far less when the cores
/// are shared).
inline constexpr std::size_t host_cells_per_index = 128;

/// Rows per host index for rows of nx cells.
inline std::size_t host_rows_per_index(unsigned nx)
{
    return nx >= host_cells_per_index ? 1 : (host_cells_per_index + nx - 1) / nx;
}

/// Runs the cell kernel k(f) (f a field index) on every cell of the layers of s: on the host
/// one index per `per_index` consecutive rows of nx cells along x (no integer division per cell,
/// contiguous inner loops), on the GPU one index per cell (over_cells).
template <class Real, class Kernel>
struct over_rows {
    poisson_stencil<Real> s;
    Kernel k;
    std::size_t per_index; ///< rows per index

    SPHERE_HD void operator()(std::size_t g) const
    {
        const std::size_t first = g * per_index, last = s.rows(), n = s.grid.n[0];
        const std::size_t end = first + per_index < last ? first + per_index : last;
        for (std::size_t r = first; r < end; ++r) {
            const std::size_t f0 = s.row_start(r);
            for (std::size_t i = 0; i < n; ++i) k(f0 + i);
        }
    }
};

template <class Real, class Kernel>
struct over_cells {
    poisson_stencil<Real> s;
    Kernel k;
    SPHERE_HD void operator()(std::size_t u) const { k(s.field(u)); }
};

/// Writes op(f(first cell), ..., f(last cell)) of the rows of host index g, in order, to out[g].
template <class Real, class Transform, class T, class Op>
struct reduce_rows {
    poisson_stencil<Real> s;
    Transform f;
    Op op;
    std::size_t per_index; ///< rows per index
    T* out;

    SPHERE_HD void operator()(std::size_t g) const
    {
        const std::size_t first = g * per_index, last = s.rows(), n = s.grid.n[0];
        const std::size_t end = first + per_index < last ? first + per_index : last;
        T acc = f(s.row_start(first));
        for (std::size_t r = first; r < end; ++r) {
            const std::size_t f0 = s.row_start(r);
            for (std::size_t i = (r == first ? 1 : 0); i < n; ++i) acc = op(acc, f(f0 + i));
        }
        out[g] = acc;
    }
};

template <class Real, class Transform>
struct transform_cell {
    poisson_stencil<Real> s;
    Transform f;
    SPHERE_HD auto operator()(std::size_t u) const { return f(s.field(u)); }
};

/// A solve's state in the policy's memory (docs/fluid.md, *Solves without waiting*): the
/// solver's scalars and its decisions live on the device next to the fields, so that a solve
/// is launched without reading anything back, and its caller reads this struct once, inside its
/// own report. The solver's loop is launched as a number of passes; a pass whose flag is 0
/// launches kernels that do nothing (for_each_index_if). Flags are ints, pointed at by guards.
struct poisson_control {
    double tolerance;
    unsigned max_iterations;
    int relative; ///< criterion == relative_residual
    poisson_shift shift;
    double b_norm;    ///< ||b_u|| (relative_residual)
    double threshold; ///< CG: tolerance x b_norm (x 1 when b_norm = 0), where it checks the true residual
    // Reductions of the current pass, valid where the flag that launched them is set.
    double sum, sum2, sum3; ///< sum3: multigrid-preconditioned CG's r.z
    normalized_change_parts change;
    // Conjugate gradients: r.r (r.z with a preconditioner), the step, the direction's beta,
    // the mean projected out of r, the best true residual so far and the checks since it halved.
    double rr, alpha, beta, mean, best;
    unsigned stalls;
    int active;      ///< the loop goes on
    int iterate;     ///< this pass applies A (CG) or sweeps (Jacobi)
    int stepping;    ///< CG: this pass takes a step
    int checking;    ///< CG: this pass evaluates the true residual
    int restarting;  ///< CG: this pass restarts from the true residual
    int directing;   ///< CG: this pass updates the direction
    int finished;    ///< the loop is over (set by poisson_conclude)
    int finishing;   ///< the end of the solve applies (finished, not held, no error)
    int final_check; ///< CG: the end evaluates the true residual
    int odd;         ///< Jacobi: the iterate is in the scratch field
    int held;        ///< the caller's own checks failed before the solve: nothing ran
    int error;       ///< 1: the criterion became NaN, 2: infinite
    unsigned error_iterations;
    unsigned iterations;
    unsigned passes; ///< passes that did work (the next solve's budget)
    double residual;
    int converged;
    int found; ///< CG: converged inside the loop
};

/// The result of a finished solve, from the host's copy of its control; throws the error of a
/// criterion that became NaN or infinite.
inline poisson_result result_of(const poisson_control& c)
{
    if (c.error == 1)
        fail("Poisson solver: residual became NaN after ", c.error_iterations,
             " iterations (a NaN or infinite value in the right-hand side, the Dirichlet values or the "
             "initial guess, or divergence)");
    if (c.error == 2)
        fail("Poisson solver: residual became infinite after ", c.error_iterations,
             " iterations (an infinite value in the input, or divergence)");
    poisson_result r;
    r.iterations = c.iterations;
    r.residual = c.residual;
    r.converged = c.converged != 0;
    return r;
}

/// Records a criterion value that is NaN or infinite as the solve's error and stops the loop;
/// true if it was.
SPHERE_HD inline bool stop_if_not_finite(poisson_control& c, double value, unsigned iterations)
{
    const bool nan = value != value, infinite = !nan && !(value - value == 0);
    if (!nan && !infinite) return false;
    c.error = nan ? 1 : 2;
    c.error_iterations = iterations;
    c.active = 0;
    return true;
}

/// Starts a solve: the settings, every flag cleared; held (nothing runs) if *hold.
struct poisson_begin {
    poisson_control* c;
    double tolerance;
    unsigned max_iterations;
    int relative;
    const int* hold; ///< may be null

    SPHERE_HD void operator()(std::size_t) const
    {
        c->tolerance = tolerance;
        c->max_iterations = max_iterations;
        c->relative = relative;
        c->shift.hi = c->shift.lo = 0;
        c->b_norm = c->threshold = c->sum = c->sum2 = c->sum3 = 0;
        c->change = normalized_change_parts{0.0, 0.0, 0.0};
        c->rr = c->alpha = c->beta = c->mean = c->best = 0;
        c->stalls = 0;
        c->held = hold && *hold ? 1 : 0;
        c->active = !c->held;
        c->iterate = c->stepping = c->checking = c->restarting = c->directing = 0;
        c->finished = c->finishing = c->final_check = c->odd = c->error = 0;
        c->error_iterations = c->iterations = c->passes = 0;
        c->residual = 0;
        c->converged = c->found = 0;
    }
};

/// *to = c->sum / count (a mean of the cells), or c->shift.hi or .lo.
struct poisson_mean_of_sum {
    poisson_control* c;
    double* to;
    double count;
    SPHERE_HD void operator()(std::size_t) const { *to = c->sum / count; }
};

/// The criterion on the initial guess (the file comment): converged, or the loop starts
/// (CG: from a restart). sum holds ||b - A eps||^2, sum2 ||b_u||^2 (relative_residual).
struct poisson_initial_check {
    poisson_control* c;
    int restart; ///< CG: the loop begins with a restart

    SPHERE_HD void operator()(std::size_t) const
    {
        if (c->held) return;
        c->b_norm = c->relative ? sqrt(c->sum2) : 0.0;
        c->threshold = c->tolerance * (c->b_norm > 0 ? c->b_norm : 1.0);
        const double res = sqrt(c->sum);
        if (stop_if_not_finite(*c, res, 0)) return;
        if (c->relative) {
            c->residual = c->b_norm > 0 ? res / c->b_norm : res;
            if (stop_if_not_finite(*c, c->residual, 0)) return;
        }
        if (c->relative ? c->residual <= c->tolerance : res == 0) {
            c->converged = c->found = 1;
            c->active = 0;
            return;
        }
        c->best = c->residual;
        c->restarting = restart;
    }
};

/// After the last pass of a launch: the loop is over when it stopped or, where the loop does
/// not look at the criterion after its last iteration (`stop_at_max`), reached
/// max_iterations; then the end of the solve applies unless it was held or failed.
struct poisson_conclude {
    poisson_control* c;
    int stop_at_max;
    int check_unfound; ///< CG: a loop that did not find convergence checks the true residual

    SPHERE_HD void operator()(std::size_t) const
    {
        if (stop_at_max && c->active && c->iterations >= c->max_iterations) c->active = 0;
        if (c->active || c->finished) return;
        c->finished = 1;
        if (c->held || c->error) return;
        c->finishing = 1;
        c->final_check = check_unfound && !c->found && c->relative;
        c->odd = c->iterations % 2;
    }
};

/// The final true residual of a CG loop that did not find convergence (sum: its square).
struct poisson_final_check {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->final_check) return;
        const double res = sqrt(c->sum);
        c->residual = c->b_norm > 0 ? res / c->b_norm : res;
        if (stop_if_not_finite(*c, c->residual, c->iterations)) {
            c->finishing = 0;
            return;
        }
        c->converged = c->residual <= c->tolerance;
    }
};

template <class Real, class Kernel>
void for_each_cell(host, const poisson_stencil<Real>& s, const Kernel& k)
{
    const std::size_t rows = host_rows_per_index(s.grid.n[0]);
    for_each_index(host{}, (s.rows() + rows - 1) / rows, over_rows<Real, Kernel>{s, k, rows});
}

/// for_each_cell if *go (policy memory) is not 0 when its turn comes.
template <class Real, class Kernel>
void for_each_cell_if(host, const poisson_stencil<Real>& s, const int* go, const Kernel& k)
{
    if (*go) for_each_cell(host{}, s, k);
}

/// *out = init op (f over the cells of the layers of s), if *go; deterministic: on the host each
/// index's rows are reduced in order along x (indices in parallel) and the indices' results in
/// order; on the GPU through transform_reduce_into (CUB, run-to-run deterministic), where a
/// pass with *go = 0 writes init op ... op init, which no decision reads.
template <class Real, class T, class Transform, class Op>
void reduce_cells_into(execution_context<host>& ctx, const poisson_stencil<Real>& s, const int* go,
                       const Transform& f, T init, Op op, T* out)
{
    if (go && !*go) return;
    const std::size_t rows = host_rows_per_index(s.grid.n[0]), n = (s.rows() + rows - 1) / rows;
    T* partial = static_cast<T*>(ctx.scratch(n * sizeof(T)));
    for_each_index(host{}, n, reduce_rows<Real, Transform, T, Op>{s, f, op, rows, partial});
    T acc = init;
    for (std::size_t i = 0; i < n; ++i) acc = op(acc, partial[i]);
    *out = acc;
}

#if SPHERE_CUDA_COMPILER
template <class Real, class Kernel>
void for_each_cell(cuda, const poisson_stencil<Real>& s, const Kernel& k)
{
    for_each_index(cuda{}, s.unknowns(), over_cells<Real, Kernel>{s, k});
}

template <class Real, class Kernel>
void for_each_cell_if(cuda, const poisson_stencil<Real>& s, const int* go, const Kernel& k)
{
    for_each_index_if(cuda{}, go, s.unknowns(), over_cells<Real, Kernel>{s, k});
}

/// f(s.field(u)) where *go, else init.
template <class Real, class Transform, class T>
struct transform_cell_if {
    poisson_stencil<Real> s;
    Transform f;
    const int* go;
    T init;
    SPHERE_HD T operator()(std::size_t u) const { return (!go || *go) ? T(f(s.field(u))) : init; }
};

template <class Real, class T, class Transform, class Op>
void reduce_cells_into(execution_context<cuda>& ctx, const poisson_stencil<Real>& s, const int* go,
                       const Transform& f, T init, Op op, T* out)
{
    transform_reduce_into(ctx, s.unknowns(), transform_cell_if<Real, Transform, T>{s, f, go, init}, init, op, out);
}
#endif

/// The problem set-up shared by the solvers: the stencil, the boundaries, the host-side checks
/// of the settings, and the whole-field operations (ghosts, norms, means), each launched
/// without waiting, its scalars in a poisson_control.
template <class Real, class Policy>
class poisson_problem {
public:
    explicit poisson_problem(const fluid_grid<Real>& g) : grid_(g) {}

    const fluid_grid<Real>& grid() const { return grid_; }

    /// Checks the settings and the boundaries against the grid (throws), and sets the stencil.
    void prepare(const poisson_boundaries& bc, const poisson_settings& st, const poisson_coefficients<Real>& k)
    {
        if (!(st.tolerance > 0) || !std::isfinite(st.tolerance))
            fail("Poisson solver: tolerance = ", st.tolerance, " must be positive and finite");
        if (st.max_iterations == 0) fail("Poisson solver: max_iterations = 0 must be at least 1");
        const bool bottom = bc.bottom == z_boundary::dirichlet, top = bc.top == z_boundary::dirichlet;
        if ((bottom || top) && grid_.n[2] < 3)
            fail("Poisson solver: nz = ", grid_.n[2], " cells is too few for a Dirichlet boundary (",
                 bottom && top ? "bottom and top" : (bottom ? "bottom" : "top"), "), which needs nz >= 3");
        s_.grid = grid_;
        s_.bottom_dirichlet = bottom;
        s_.top_dirichlet = top;
        s_.k_first = bottom ? 1 : 0;
        s_.k_count = static_cast<int>(grid_.n[2]) - (bottom ? 1 : 0) - (top ? 1 : 0);
        s_.sy = std::size_t(grid_.n[0]) + 2;
        s_.sz = s_.sy * (std::size_t(grid_.n[1]) + 2);
        const double dx = double(grid_.width.x), dy = double(grid_.width.y), dz = double(grid_.width.z);
        s_.cx = 1.0 / (dx * dx);
        s_.cy = 1.0 / (dy * dy);
        s_.cz = 1.0 / (dz * dz);
        s_.conductance = k.conductance;
        s_.sink = k.sink;
        s_.lambda_max = 4 * (s_.cx + s_.cy + s_.cz) * (k.conductance ? k.conductance_max : 1.0) +
                        (k.sink ? k.sink_max : 0.0);
        all_ = s_;
        all_.k_first = 0;
        all_.k_count = static_cast<int>(grid_.n[2]);
        singular_ = !bottom && !top && !k.sink;
        relative_ = st.criterion == poisson_criterion::relative_residual;
    }

    const poisson_stencil<Real>& stencil() const { return s_; }
    /// Neumann at both ends and no sink: A annihilates the constants, and every cell is an unknown.
    bool singular() const { return singular_; }
    bool relative() const { return relative_; }

    /// The start of a solve of A eps = rhs with the settings of prepare: the control's begin,
    /// eps's ghosts, the singular case's means (shift = mean of b as hi + lo, see
    /// poisson_shift; eps made zero-mean), and the criterion on the initial guess
    /// (poisson_initial_check). Nothing is read back.
    void start(execution_context<Policy>& ctx, poisson_control* c, const int* hold, const poisson_settings& st,
               Real* eps, const Real* rhs, bool restart)
    {
        for_each_index(Policy{}, 1, poisson_begin{c, st.tolerance, st.max_iterations, relative_ ? 1 : 0, hold});
        fill_ghosts(eps, nullptr);
        if (singular_) {
            const double cells = double(grid_.cell_count());
            reduce_cells_into(ctx, all_, nullptr, field_cell_value<Real>{rhs}, 0.0, plus_op{}, &c->sum);
            for_each_index(Policy{}, 1, poisson_mean_of_sum{c, &c->shift.hi, cells});
            reduce_cells_into(ctx, all_, nullptr, field_cell_offset<Real>{rhs, &c->shift.hi}, 0.0, plus_op{}, &c->sum);
            for_each_index(Policy{}, 1, poisson_mean_of_sum{c, &c->shift.lo, cells});
            // subtract_mean changes the cells only: the ghosts are refilled, or stale ones would
            // keep the old offset in the stencil of the boundary cells.
            subtract_mean(ctx, c, nullptr, eps);
            fill_ghosts(eps, nullptr);
        }
        if (relative_)
            reduce_cells_into(ctx, s_, nullptr, poisson_rhs_squared<Real>{s_, eps, rhs, &c->shift}, 0.0, plus_op{},
                              &c->sum2);
        reduce_cells_into(ctx, s_, nullptr, poisson_residual_squared<Real>{s_, eps, rhs, &c->shift}, 0.0, plus_op{},
                          &c->sum);
        for_each_index(Policy{}, 1, poisson_initial_check{c, restart ? 1 : 0});
    }

    /// The end of the passes launched so far: poisson_conclude, then, where the solve is over,
    /// the final residual (CG), the copy of the scratch iterate into eps (Jacobi), the singular
    /// case's zero mean, and eps's ghosts.
    void conclude(execution_context<Policy>& ctx, poisson_control* c, Real* eps, const Real* rhs,
                  const Real* scratch_iterate, bool stop_at_max, bool check_unfound)
    {
        for_each_index(Policy{}, 1, poisson_conclude{c, stop_at_max ? 1 : 0, check_unfound ? 1 : 0});
        if (check_unfound && relative_) {
            fill_ghosts(eps, &c->final_check);
            residual_squared_into(ctx, &c->final_check, eps, rhs, c, &c->sum);
            for_each_index(Policy{}, 1, poisson_final_check{c});
        }
        if (scratch_iterate)
            for_each_index_if(Policy{}, &c->odd, grid_.field_size(), copy_values<Real>{scratch_iterate, eps});
        if (singular_) subtract_mean(ctx, c, &c->finishing, eps);
        fill_ghosts(eps, &c->finishing);
    }

    /// Runs the cell kernel k(f) on every unknown cell if *go (always if go is null).
    template <class Kernel>
    void for_each_unknown(const int* go, const Kernel& k) const
    {
        if (go)
            for_each_cell_if(Policy{}, s_, go, k);
        else
            for_each_cell(Policy{}, s_, k);
    }

    /// *out = the sum (in double) of the cell transform f(f) over the unknown cells, if *go.
    template <class Transform>
    void sum_unknowns_into(execution_context<Policy>& ctx, const int* go, const Transform& f, double* out) const
    {
        reduce_cells_into(ctx, s_, go, f, 0.0, plus_op{}, out);
    }

    /// *out = ||b - shift - A e||^2 over the unknowns (double), if *go; e with filled ghosts.
    void residual_squared_into(execution_context<Policy>& ctx, const int* go, const Real* e, const Real* b,
                               const poisson_control* c, double* out) const
    {
        sum_unknowns_into(ctx, go, poisson_residual_squared<Real>{s_, e, b, &c->shift}, out);
    }

    /// *out = the parts of the normalized change between x and old (old != nullptr) or of the
    /// step *step p, if *go.
    void normalized_change_into(execution_context<Policy>& ctx, const int* go, const Real* x, const Real* old,
                                const Real* p, const double* step, normalized_change_parts* out) const
    {
        reduce_cells_into(ctx, s_, go, normalized_change_at<Real>{x, old, p, step},
                          normalized_change_parts{0.0, 0.0, 0.0}, normalized_change_max{}, out);
    }

    /// eps -= its mean over the cells, if *go (c->sum and c->mean are its scratch).
    void subtract_mean(execution_context<Policy>& ctx, poisson_control* c, const int* go, Real* eps) const
    {
        reduce_cells_into(ctx, all_, go, field_cell_value<Real>{eps}, 0.0, plus_op{}, &c->sum);
        const poisson_mean_of_sum mean{c, &c->mean, double(grid_.cell_count())};
        const subtract_from_cells<Real> subtract{eps, &c->mean};
        if (go) {
            for_each_index_if(Policy{}, go, 1, mean);
            for_each_cell_if(Policy{}, all_, go, subtract);
        } else {
            for_each_index(Policy{}, 1, mean);
            for_each_cell(Policy{}, all_, subtract);
        }
    }

    /// Fills e's ghosts (file comment) if *go (always if go is null).
    void fill_ghosts(Real* e, const int* go) const
    {
        const std::size_t count = grid_.field_size() - grid_.cell_count();
        const std::size_t per_index = runs_in_blocks<Policy> ? host_cells_per_index : 1;
        const fill_poisson_ghosts<Real> k{s_, e, per_index, count};
        const std::size_t n = (count + per_index - 1) / per_index;
        if (go)
            for_each_index_if(Policy{}, go, n, k);
        else
            for_each_index(Policy{}, n, k);
    }

    /// dst = src on the whole field (cells and ghosts), if *go.
    void copy(const Real* src, Real* dst, const int* go) const
    {
        for_each_index_if(Policy{}, go, grid_.field_size(), copy_values<Real>{src, dst});
    }

    /// v = 0 on the whole field.
    void zero(Real* v) const { for_each_index(Policy{}, grid_.field_size(), set_values<Real>{v, Real(0)}); }

private:
    fluid_grid<Real> grid_;
    poisson_stencil<Real> s_{};   ///< the unknown layers
    poisson_stencil<Real> all_{}; ///< every cell layer
    bool singular_ = false;
    bool relative_ = true;
};

/// How many passes a solve launches before it first reads its control back: the most passes
/// either of the last two solves used, a quarter more and 4, at least 16 (counts that
/// alternate, as Jacobi's do from one fluid step to the next with a steady source, still read
/// back once); a solve that has not finished doubles it for the next launch.
struct poisson_budget {
    unsigned passes = 16;
    unsigned previous = 0; ///< the passes the solve before the last one used
    void learn(unsigned used)
    {
        const unsigned most = used > previous ? used : previous;
        previous = used;
        passes = most + most / 4 + 4 < 16 ? 16 : most + most / 4 + 4;
    }
};

/// What both solvers share (CRTP: `Derived` is jacobi_poisson or cg_poisson): the problem,
/// the control and context of solve(), the pass budget and the pointers of the launch in
/// progress. Derived provides `static constexpr bool restarts` (poisson_problem::start's
/// restart), `begin()` (its fields' set-up after start) and `run_passes()` (passes_ passes,
/// then problem_.conclude).
template <class Derived, class Real, class Policy>
class poisson_solver_base {
public:
    const fluid_grid<Real>& grid() const { return problem_.grid(); }

    /// Solves A eps = rhs (jacobi_poisson's comment): launch, read the control back, resume
    /// until it finished. eps and rhs point to fields of grid().field_size() entries in the
    /// Policy's memory space; eps holds the initial guess and the Dirichlet values on entry
    /// and the solution, with every ghost filled, on return; `k` the optional variable
    /// coefficients (file comment). Throws on bad settings, nz < 3 with a Dirichlet end, or a
    /// residual that becomes NaN or infinite.
    poisson_result solve(Real* eps, const Real* rhs, const poisson_boundaries& bc, const poisson_settings& st,
                         const poisson_coefficients<Real>& k = {})
    {
        launch(context_, control_.data(), nullptr, eps, rhs, bc, st, k);
        poisson_control c{};
        context_.read_back(&c, control_.data(), 1, "the Poisson solve's control", 0);
        while (!c.finished) {
            resume(context_);
            context_.read_back(&c, control_.data(), 1, "the Poisson solve's control", 0);
        }
        return learn(c);
    }

    /// Launches a solve (solve's contract) without reading anything back: its state in the
    /// control `c` (policy memory); nothing runs if *hold (hold may be null). Throws on bad
    /// settings. When c->finished is 0 after the launch, resume() launches more passes.
    void launch(execution_context<Policy>& ctx, poisson_control* c, const int* hold, Real* eps, const Real* rhs,
                const poisson_boundaries& bc, const poisson_settings& st, const poisson_coefficients<Real>& k = {})
    {
        problem_.prepare(bc, st, k);
        ctx_ = &ctx;
        c_ = c;
        eps_ = eps;
        rhs_ = rhs;
        problem_.start(ctx, c, hold, st, eps, rhs, Derived::restarts);
        self().begin();
        passes_ = budget_.passes;
        self().run_passes();
    }

    /// Launches more passes of the last launch (twice as many as the last time) and its end.
    void resume(execution_context<Policy>&)
    {
        passes_ *= 2;
        self().run_passes();
    }

    /// The result of a finished solve from the host's copy of its control (throws its
    /// error); the passes it used set the next solve's budget.
    poisson_result learn(const poisson_control& c)
    {
        budget_.learn(c.passes);
        return result_of(c);
    }

protected:
    explicit poisson_solver_base(const fluid_grid<Real>& g) : problem_(g), control_(1) {}

    poisson_problem<Real, Policy> problem_;
    unsigned passes_ = 0;                ///< passes of the launch in progress
    execution_context<Policy>* ctx_ = nullptr;
    poisson_control* c_ = nullptr;
    Real* eps_ = nullptr;
    const Real* rhs_ = nullptr;

private:
    Derived& self() { return static_cast<Derived&>(*this); }

    buffer<poisson_control, Policy> control_; ///< solve()'s control
    execution_context<Policy> context_;        ///< solve()'s context
    poisson_budget budget_;
};

/// Jacobi decisions of one pass (relative_residual): the criterion of the current iterate
/// (sum: its squared residual), then a sweep unless converged or at max_iterations.
struct jacobi_residual_check {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        c->iterate = 0;
        if (!c->active) return;
        ++c->passes;
        const double r = sqrt(c->sum);
        c->residual = c->b_norm > 0 ? r / c->b_norm : r;
        if (stop_if_not_finite(*c, c->residual, c->iterations)) return;
        if (c->residual <= c->tolerance) {
            c->converged = 1;
            c->active = 0;
            return;
        }
        if (c->iterations == c->max_iterations) {
            c->active = 0;
            return;
        }
        c->iterate = 1;
    }
};

/// Jacobi with normalized_change: whether a pass sweeps.
struct jacobi_begin_pass {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        c->iterate = c->active && c->iterations < c->max_iterations;
        if (c->active && !c->iterate) c->active = 0;
        if (c->iterate) ++c->passes;
    }
};

/// After a sweep: its count and, with normalized_change, the criterion (change: its parts).
struct jacobi_after_sweep {
    poisson_control* c;
    SPHERE_HD void operator()(std::size_t) const
    {
        if (!c->iterate) return;
        ++c->iterations;
        if (c->relative) return;
        c->residual = normalized_change_value(c->change);
        if (stop_if_not_finite(*c, c->residual, c->iterations)) return;
        if (c->residual <= c->tolerance) {
            c->converged = 1;
            c->active = 0;
        }
    }
};

} // namespace detail

/// Jacobi iterations for the pressure-Poisson problem (file comment; docs/fluid.md), as in the
/// seeds: every sweep replaces each unknown by the value that satisfies its own equation with
/// the neighbours' previous values (detail::jacobi_sweep), then refreshes the ghosts. One
/// iteration = one sweep. With relative_residual the residual of the current iterate is
/// evaluated before every sweep (a second stencil pass); with normalized_change the change
/// of every sweep is reduced. Needs O(n^2) sweeps on an n-cell axis: it is the reference
/// method; cg_poisson (poisson_cg.cuh) needs O(n).
///
/// The loop runs on the device without waiting (detail::poisson_control): a pass is a sweep
/// (into the scratch field, then back), decided on the device; `solve` launches as many
/// passes as the larger of the last two solves needed and a quarter more, reads the control
/// back once, and only launches more (doubling) if the solve had not finished.
///
/// Owns one scratch field (the other iterate), allocated once. Usage:
///
///     sphere::jacobi_poisson<double, sphere::host> solver(grid);
///     sphere::poisson_result r = solver.solve(eps, rhs, {sphere::z_boundary::neumann,
///                                             sphere::z_boundary::dirichlet}, {});
///     if (!r.converged) ...
template <class Real, class Policy>
class jacobi_poisson : public detail::poisson_solver_base<jacobi_poisson<Real, Policy>, Real, Policy> {
    using base = detail::poisson_solver_base<jacobi_poisson<Real, Policy>, Real, Policy>;
    friend base;

public:
    static const char* name() { return "jacobi"; }

    explicit jacobi_poisson(const fluid_grid<Real>& g) : base(g), scratch_(g.field_size(), Real(0)) {}

private:
    static constexpr bool restarts = false;

    /// The Dirichlet layers of both fields.
    void begin() { problem_.copy(eps_, scratch_.data(), &c_->active); }

    /// passes_ sweeps (rounded up to pairs, so that a launch that does not finish leaves
    /// the iterate in eps), then the end.
    void run_passes()
    {
        for (unsigned i = 0; i < (passes_ + 1) / 2; ++i) {
            half_pass(eps_, scratch_.data());
            half_pass(scratch_.data(), eps_);
        }
        problem_.conclude(*ctx_, c_, eps_, rhs_, scratch_.data(), !problem_.relative(), false);
    }

    /// One sweep from `from` into `to` with its decisions.
    void half_pass(const Real* from, Real* to)
    {
        detail::poisson_control* c = c_;
        const detail::poisson_stencil<Real>& s = problem_.stencil();
        if (problem_.relative()) {
            problem_.residual_squared_into(*ctx_, &c->active, from, rhs_, c, &c->sum);
            for_each_index(Policy{}, 1, detail::jacobi_residual_check{c});
        } else {
            for_each_index(Policy{}, 1, detail::jacobi_begin_pass{c});
        }
        if (s.variable()) {
            problem_.for_each_unknown(&c->iterate, detail::jacobi_sweep_variable<Real>{s, &c->shift, rhs_, from, to});
        } else {
            const double D = 2 * (s.cx + s.cy + s.cz);
            const detail::jacobi_sweep<Real> k{s, Real(s.cx / D), Real(s.cy / D), Real(s.cz / D), Real(1 / D),
                                               &c->shift, rhs_, from, to};
            problem_.for_each_unknown(&c->iterate, k);
        }
        problem_.fill_ghosts(to, &c->iterate);
        if (!problem_.relative()) problem_.normalized_change_into(*ctx_, &c->iterate, to, from, nullptr, nullptr, &c->change);
        for_each_index(Policy{}, 1, detail::jacobi_after_sweep{c});
    }

    using base::c_;
    using base::ctx_;
    using base::eps_;
    using base::passes_;
    using base::problem_;
    using base::rhs_;

    buffer<Real, Policy> scratch_;
};

} // namespace sphere
