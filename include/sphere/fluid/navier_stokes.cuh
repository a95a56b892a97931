#pragma once
/// \file
/// The fluid solver (docs/fluid.md, *Navier-Stokes solver*): the porosity-weighted
/// Navier-Stokes equations of the pore fluid on a staggered (MAC) grid, advanced by
/// Langtangen's operator splitting — an explicit predicted velocity, a Poisson equation for the
/// pressure increment epsilon, and the projection that makes the velocity satisfy continuity.
///
/// Layout: pressure, porosity, its rate and the interaction force live at cell centres;
/// velocity component a lives on the faces normal to axis a, face (i, j, k) of axis a being the
/// one between cell (i, j, k) and its neighbour in +a. All use fluid_grid::field_index (one
/// ghost layer). Along z, face k = -1 is the bottom of the grid and face nz - 1 its top.
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "fluid_params.cuh"
#include "grid.cuh"
#include "poisson.cuh"
#include "poisson_cg.cuh"
#include "poisson_mg.cuh"
#include "porosity.cuh"

namespace sphere {

/// Kernel view of the fluid fields (device pointers for the cuda policy).
template <class Real>
struct fluid_view {
    fluid_grid<Real> grid;
    Real* p;            ///< pressure (Pa), cells
    Real* u[3];         ///< face velocities (m/s), component a on the faces normal to a
    Real* phi;          ///< porosity (-), cells
    Real* dphi_dt;      ///< its rate of change (1/s), cells
    vec3<Real>* force;  ///< interaction force density on the fluid (N/m^3), cells
    long long stride[3];
    Real rho, mu;
    bool wall_bottom, wall_top;  ///< no-flow ends (else prescribed pressure or inflow)
    bool inflow_bottom, inflow_top; ///< inflow ends
    Real u_bottom, u_top;        ///< their superficial velocities along +z (m/s)

    /// fluid_grid::field_index, signed so that neighbours can be reached by subtraction.
    SPHERE_HD long long at(int i, int j, int k) const { return static_cast<long long>(grid.field_index(i, j, k)); }
    /// The field index of cell number `cell` (fluid_grid::index numbering), and its layer k.
    SPHERE_HD long long cell_field(std::size_t cell, int& k) const
    {
        int i, j;
        grid.coordinates(cell, i, j, k);
        return at(i, j, k);
    }
    /// Whether the face of axis a at field index of cell (i, j, k) carries an unknown velocity:
    /// every x and y face; the z faces between two cells.
    SPHERE_HD bool active_face(int a, int k) const { return a != 2 || (k >= 0 && k < int(grid.n[2]) - 1); }
    /// Porosity on face (c, a): the mean of the two cells it separates.
    SPHERE_HD Real phi_face(long long c, int a) const { return Real(0.5) * (phi[c] + phi[c + stride_of(a)]); }
    /// The face velocities of axis a and the field stride along it, chosen by selects for a
    /// run-time axis (see component() in core/vec.cuh).
    SPHERE_HDI const Real* velocity_of(int a) const { return a == 0 ? u[0] : (a == 1 ? u[1] : u[2]); }
    SPHERE_HDI long long stride_of(int a) const { return a == 0 ? stride[0] : (a == 1 ? stride[1] : stride[2]); }
    /// The fluid velocity at the centre of cell c: the mean of its two faces per axis.
    SPHERE_HD vec3<Real> cell_velocity(long long c) const
    {
        vec3<Real> v;
        for (int a = 0; a < 3; ++a) v[a] = Real(0.5) * (u[a][c] + u[a][c - stride[a]]);
        return v;
    }
    /// The pressure gradient (Pa/m) at the centre of cell c: the mean of the two face gradients
    /// per axis (the pressure ghosts along z are extrapolated linearly, so next to the top and
    /// bottom this is the one-sided gradient).
    SPHERE_HD vec3<Real> pressure_gradient(long long c) const
    {
        vec3<Real> g;
        for (int a = 0; a < 3; ++a) g[a] = (p[c + stride[a]] - p[c - stride[a]]) / (Real(2) * grid.width[a]);
        return g;
    }
};

namespace detail {

/// Source cell of ghost node (i, j, k): periodic in x and y, nearest cell in z.
template <class Real>
SPHERE_HD void ghost_source(const fluid_grid<Real>& g, int& i, int& j, int& k)
{
    const int nx = int(g.n[0]), ny = int(g.n[1]), nz = int(g.n[2]);
    i = i < 0 ? i + nx : (i >= nx ? i - nx : i);
    j = j < 0 ? j + ny : (j >= ny ? j - ny : j);
    k = k < 0 ? 0 : (k >= nz ? nz - 1 : k);
}

/// Fills the ghost nodes of a cell-centred field of T (Real or vec3<Real>): periodic copies in
/// x and y; along z a copy of the nearest cell, or (extrapolate_z) the linear extrapolation
/// 2 f(0) - f(1).
template <class Real, class T>
struct fill_cell_ghosts {
    fluid_grid<Real> g;
    T* f;
    bool extrapolate_z;

    SPHERE_HD void operator()(std::size_t node) const
    {
        int i, j, k;
        g.field_coordinates(node, i, j, k);
        if (g.is_cell(i, j, k)) return;
        const int kz = k;
        ghost_source(g, i, j, k);
        const std::size_t s = g.field_index(i, j, k);
        if (extrapolate_z && kz != k && g.n[2] > 1) {
            const int inner = kz < 0 ? 1 : int(g.n[2]) - 2;
            f[node] = f[s] + (f[s] - f[g.field_index(i, j, inner)]);
        } else {
            f[node] = f[s];
        }
    }
};

/// Fills the ghost faces of the three face-velocity fields and sets the z faces at the top and
/// bottom of the grid: zero on a no-flow wall, U / phi at an inflow end (U the prescribed
/// superficial velocity, phi the porosity of the end cell), a copy of the adjacent inner face
/// at a prescribed-pressure end. Tangential components are copied from the nearest cell in z
/// (no shear stress at the ends: free slip).
template <class Real>
struct fill_velocity_ghosts {
    fluid_grid<Real> g;
    Real* u[3];
    bool wall_bottom, wall_top;
    bool inflow_bottom, inflow_top;
    Real u_bottom, u_top;
    const Real* phi; ///< porosity (cells)

    SPHERE_HD void operator()(std::size_t node) const
    {
        int i, j, k;
        g.field_coordinates(node, i, j, k);
        const int nz = int(g.n[2]);
        const bool ghost = !g.is_cell(i, j, k);
        // z faces: k = -1 and nz - 1 are the ends of the grid, nz lies beyond.
        if (k == -1 || k >= nz - 1) {
            int si = i, sj = j, sk = k;
            ghost_source(g, si, sj, sk);
            const bool bottom = k == -1;
            const bool wall = bottom ? wall_bottom : wall_top;
            const bool inflow = bottom ? inflow_bottom : inflow_top;
            const int inner = bottom ? 0 : nz - 2;
            if (inflow)
                u[2][node] = (bottom ? u_bottom : u_top) / phi[g.field_index(si, sj, bottom ? 0 : nz - 1)];
            else
                u[2][node] = (wall || nz < 2) ? Real(0) : u[2][g.field_index(si, sj, inner)];
        } else if (ghost) {
            int si = i, sj = j, sk = k;
            ghost_source(g, si, sj, sk);
            u[2][node] = u[2][g.field_index(si, sj, sk)];
        }
        if (ghost) {
            ghost_source(g, i, j, k);
            const std::size_t s = g.field_index(i, j, k);
            u[0][node] = u[0][s];
            u[1][node] = u[1][s];
        }
    }
};

/// The predicted velocity v* on every active face (seeds eq. for v*, docs/fluid.md (F-3)):
///   v*_a = v_a + dt [ -beta/(rho phi_f) d_a p + 1/(rho phi_f) (div(phi tau))_a
///                     + F_a/(rho phi_f) + g_a - v_a (dphi/dt)_f / phi_f - (div(phi v_a v))_a / phi_f ]
/// with the viscous stress tau_ab = mu (d_b v_a + d_a v_b) and the advective flux phi v_a v_b,
/// both in conservative form: normal fluxes at cell centres, shear fluxes on cell edges (the
/// porosity of an edge is the mean of its four cells). F is the force density the particles
/// exert on the fluid (the mean of the two cells of the face).
template <class Real>
struct predict_velocity {
    fluid_view<Real> f;
    Real* out[3];
    Real dt, beta;
    vec3<Real> g;

    SPHERE_HD void operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        for (int a = 0; a < 3; ++a) {
            if (!f.active_face(a, k)) continue;
            out[a][c] = f.u[a][c] + dt * acceleration(c, a);
        }
    }

    SPHERE_HD Real acceleration(long long c, int a) const
    {
        const long long sa = f.stride[a];
        const Real* ua = f.u[a];
        const Real ha = f.grid.width[a];
        const Real phi_f = f.phi_face(c, a);
        Real div_tau = 0, div_flux = 0;
        // normal stress and flux at the centres of the two cells of the face
        {
            const Real phi_hi = f.phi[c + sa], phi_lo = f.phi[c];
            const Real tau_hi = Real(2) * f.mu * (ua[c + sa] - ua[c]) / ha;
            const Real tau_lo = Real(2) * f.mu * (ua[c] - ua[c - sa]) / ha;
            const Real v_hi = Real(0.5) * (ua[c + sa] + ua[c]);
            const Real v_lo = Real(0.5) * (ua[c] + ua[c - sa]);
            div_tau += (phi_hi * tau_hi - phi_lo * tau_lo) / ha;
            div_flux += (phi_hi * v_hi * v_hi - phi_lo * v_lo * v_lo) / ha;
        }
        // shear stress and flux on the edges above and below along each other axis b
        for (int b = 0; b < 3; ++b) {
            if (b == a) continue;
            const long long sb = f.stride[b];
            const Real hb = f.grid.width[b];
            const Real* ub = f.u[b];
            const long long lo = c - sb;
            const Real phi_e_hi = Real(0.25) * (f.phi[c] + f.phi[c + sa] + f.phi[c + sb] + f.phi[c + sa + sb]);
            const Real phi_e_lo = Real(0.25) * (f.phi[lo] + f.phi[lo + sa] + f.phi[c] + f.phi[c + sa]);
            const Real tau_hi = f.mu * ((ua[c + sb] - ua[c]) / hb + (ub[c + sa] - ub[c]) / ha);
            const Real tau_lo = f.mu * ((ua[c] - ua[lo]) / hb + (ub[lo + sa] - ub[lo]) / ha);
            const Real flux_hi = phi_e_hi * Real(0.25) * (ua[c] + ua[c + sb]) * (ub[c] + ub[c + sa]);
            const Real flux_lo = phi_e_lo * Real(0.25) * (ua[lo] + ua[c]) * (ub[lo] + ub[lo + sa]);
            div_tau += (phi_e_hi * tau_hi - phi_e_lo * tau_lo) / hb;
            div_flux += (flux_hi - flux_lo) / hb;
        }
        const Real dp = (f.p[c + sa] - f.p[c]) / ha;
        const Real force = Real(0.5) * (f.force[c][a] + f.force[c + sa][a]);
        const Real dphi = Real(0.5) * (f.dphi_dt[c] + f.dphi_dt[c + sa]);
        return (-beta * dp + div_tau + force) / (f.rho * phi_f) + g[a] - ua[c] * dphi / phi_f - div_flux / phi_f;
    }
};

/// Right-hand side of the Poisson equation for epsilon on every cell (docs/fluid.md (F-5)):
///   b = rho/dt [ div(phi_f v*) + dphi/dt ]
/// (only the cells that are unknowns of the Poisson problem use it).
template <class Real>
struct poisson_rhs {
    fluid_view<Real> f;
    const Real* vs[3];
    Real* b;
    Real dt;

    SPHERE_HD void operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        Real div = 0;
        for (int a = 0; a < 3; ++a) {
            const long long lo = c - f.stride[a];
            div += (f.phi_face(c, a) * vs[a][c] - f.phi_face(lo, a) * vs[a][lo]) / f.grid.width[a];
        }
        b[c] = f.rho / dt * (div + f.dphi_dt[c]);
    }
};

/// Sets epsilon on a prescribed-pressure cell layer to p(t + dt) - beta p(t).
template <class Real>
struct set_boundary_increment {
    fluid_view<Real> f;
    Real* eps;
    int k;
    Real value;  ///< p(t + dt) at the layer
    Real beta;

    SPHERE_HD void operator()(std::size_t column) const
    {
        const int i = int(column % f.grid.n[0]), j = int(column / f.grid.n[0]);
        const long long c = f.at(i, j, k);
        eps[c] = value - beta * f.p[c];
    }
};

/// The projection (docs/fluid.md (F-6)): v = v* - dt/(rho phi_f) d_a epsilon on every active
/// face, and p = beta p + epsilon on every cell.
template <class Real>
struct correct_velocity {
    fluid_view<Real> f;
    const Real* vs[3];
    const Real* eps;
    Real dt, beta;

    SPHERE_HD void operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        for (int a = 0; a < 3; ++a) {
            if (!f.active_face(a, k)) continue;
            const Real grad = (eps[c + f.stride[a]] - eps[c]) / f.grid.width[a];
            f.u[a][c] = vs[a][c] - dt / (f.rho * f.phi_face(c, a)) * grad;
        }
        f.p[c] = beta * f.p[c] + eps[c];
    }
};

/// Copies a porosity estimate (cells) into the solver's fields.
template <class Real>
struct copy_porosity {
    fluid_view<Real> f;
    porosity_view<Real> in;

    SPHERE_HD void operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        f.phi[c] = in.phi[c];
        f.dphi_dt[c] = in.dphi_dt[c];
    }
};

/// |v_x|/dx + |v_y|/dy + |v_z|/dz at the centre of a cell (1/s), for the advective time-step limit.
template <class Real>
struct advective_rate {
    fluid_view<Real> f;
    SPHERE_HD Real operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        Real r = 0;
        for (int a = 0; a < 3; ++a) {
            const Real hi = f.u[a][c], lo = f.u[a][c - f.stride[a]];
            const Real m = (hi < 0 ? -hi : hi) > (lo < 0 ? -lo : lo) ? (hi < 0 ? -hi : hi) : (lo < 0 ? -lo : lo);
            r += m / f.grid.width[a];
        }
        return r;
    }
};

/// Smallest porosity of a cell.
template <class Real>
struct cell_porosity {
    fluid_view<Real> f;
    SPHERE_HD Real operator()(std::size_t cell) const
    {
        int k;
        return f.phi[f.cell_field(cell, k)];
    }
};

/// x, y or z momentum per unit density of the face control volume of a cell: phi_f v_a V_cell.
template <class Real>
struct face_momentum {
    fluid_view<Real> f;
    int a;
    SPHERE_HD double operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        if (!f.active_face(a, k)) return 0;
        return double(f.phi_face(c, a)) * double(f.velocity_of(a)[c]);
    }
};

/// Why a fluid step held (did not advance): fluid_report::hold.
enum fluid_hold : int {
    fluid_advances = 0,
    fluid_hold_porosity = 1, ///< a cell's porosity is not in (0, 1]
    fluid_hold_response = 2, ///< dt exceeds the shortest particle response time (the coupling's)
    fluid_hold_stability = 3, ///< dt exceeds the stability limit
};

/// What a fluid step found, in the policy's memory; the step reads it back once, at its end
/// (docs/fluid.md, *Solves without waiting*).
template <class Real>
struct fluid_report {
    poisson_control solve;
    Real lowest_porosity; ///< the smallest cell porosity set_porosity was given
    Real response;        ///< the shortest particle response time (s) the coupling wrote (1e30 alone)
    Real phi_min, rate;   ///< the stability limit's reductions: least porosity, largest advective rate (1/s)
    Real limit;           ///< the stability limit (s)
    int hold;             ///< fluid_hold
    int commit;           ///< the solve converged and nothing held: the fields advance
    Real next_drift;      ///< the coupling's: the simulation's check of its next drift (predict_drift_into)
    double work_step;     ///< the coupling's: the fluid's work on the particles in the last step (J)
    double work_total;    ///< and its sum (J)
};

/// The checks before a fluid step of length dt: the stability limit from the reductions, and
/// why the step holds, if it does (the first failing check, in fluid_hold's order).
template <class Real>
struct fluid_precheck {
    fluid_report<Real>* r;
    Real dt, density, viscosity, inv_h2;

    SPHERE_HD void operator()(std::size_t) const
    {
        Real limit = r->phi_min * density / (Real(2) * viscosity * inv_h2);
        if (r->rate > 0 && Real(1) / r->rate < limit) limit = Real(1) / r->rate;
        r->limit = limit;
        r->hold = !(r->lowest_porosity > Real(0)) ? fluid_hold_porosity
                  : !(dt <= r->response)          ? fluid_hold_response
                  : !(dt <= limit)                ? fluid_hold_stability
                                                  : fluid_advances;
        r->commit = 0;
    }
};

/// Whether the step's fields advance: the solve is over, converged, and nothing held.
template <class Real>
struct fluid_commit {
    fluid_report<Real>* r;
    SPHERE_HD void operator()(std::size_t) const
    {
        r->commit = r->solve.finishing && r->solve.converged && r->hold == fluid_advances;
    }
};

} // namespace detail

/// The pore-fluid solver. `Poisson` is the pressure solver: mg_poisson (default; conjugate
/// gradients with a multigrid preconditioner), cg_poisson (plain conjugate gradients, as fast
/// on small grids in time stepping) or jacobi_poisson (the seeds' method, 50-100x slower than
/// CG on 16^3-32^3 grids).
///
/// Each `step(dt)` advances the fluid from t to t + dt with the porosity, its rate and the
/// interaction force it was last given (set_porosity, interaction_force): a fluid on its own
/// has phi = 1 and no force. The step throws sphere::error, with no field advanced, when dt is
/// not positive, when a cell's porosity is not in (0, 1], when dt exceeds the diffusive limit
/// dt <= phi_min rho / (2 mu sum 1/h^2) or the advective limit
/// dt max(|v_x|/dx + |v_y|/dy + |v_z|/dz) <= 1, and when the pressure solve did not converge
/// within the iteration limit.
///
/// A step waits for the device once: its checks and the pressure solve's decisions are
/// taken on the device (detail::fluid_report, detail::poisson_control), the kernels that
/// advance the fields run only if they passed, and the host reads the report back at the end
/// (twice or more only when the solve needs more passes than the larger of the last two and a
/// quarter).
/// Its reductions and read-back go through the solver's own execution context; its kernels run
/// on the default stream, which the context's (blocking) stream stays ordered with.
template <class Real, class Policy, class Poisson = mg_poisson<Real, Policy>>
class navier_stokes {
public:
    navier_stokes(const fluid_grid<Real>& g, const fluid_params<Real>& params)
        : grid_(g), params_(params), p_(g.field_size(), Real(0)), eps_(g.field_size(), Real(0)),
          rhs_(g.field_size(), Real(0)), phi_(g.field_size(), Real(1)), dphi_(g.field_size(), Real(0)),
          force_(g.field_size(), vec3<Real>{0, 0, 0}), poisson_(g), report_(1, initial_report())
    {
        params_.validate();
        const bool pressure_end = params_.bottom.kind == fluid_boundary_kind::pressure ||
                                  params_.top.kind == fluid_boundary_kind::pressure;
        if (pressure_end && g.n[2] < 3)
            detail::fail("fluid: nz = ", g.n[2], " cells; a prescribed-pressure end needs nz >= 3");
        for (int a = 0; a < 3; ++a) {
            u_[a] = buffer<Real, Policy>(g.field_size(), Real(0));
            us_[a] = buffer<Real, Policy>(g.field_size(), Real(0));
        }
        set_boundary_pressure(0.0);
        fill_pressure_ghosts();
    }

    const fluid_grid<Real>& grid() const { return grid_; }
    const fluid_params<Real>& params() const { return params_; }
    double time() const { return time_; }
    /// Result of the last pressure solve (iterations, residual).
    const poisson_result& last_solve() const { return last_solve_; }

    fluid_view<Real> view()
    {
        fluid_view<Real> v;
        v.grid = grid_;
        v.p = p_.data();
        for (int a = 0; a < 3; ++a) v.u[a] = u_[a].data();
        v.phi = phi_.data();
        v.dphi_dt = dphi_.data();
        v.force = force_.data();
        v.stride[0] = 1;
        v.stride[1] = grid_.n[0] + 2;
        v.stride[2] = (long long)(grid_.n[0] + 2) * (grid_.n[1] + 2);
        v.rho = params_.density;
        v.mu = params_.viscosity;
        v.wall_bottom = params_.bottom.kind == fluid_boundary_kind::no_flow;
        v.wall_top = params_.top.kind == fluid_boundary_kind::no_flow;
        v.inflow_bottom = params_.bottom.kind == fluid_boundary_kind::inflow;
        v.inflow_top = params_.top.kind == fluid_boundary_kind::inflow;
        v.u_bottom = params_.bottom.velocity;
        v.u_top = params_.top.velocity;
        return v;
    }

    /// Takes the porosity and its rate from an estimator (same grid). The next step throws
    /// when a cell's porosity is not in (0, 1] (nothing is read back here).
    void set_porosity(const porosity_view<Real>& in)
    {
        for (int a = 0; a < 3; ++a)
            if (in.grid.n[a] != grid_.n[a])
                detail::fail("fluid: the porosity grid has ", in.grid.n[a], " cells along axis ", a, ", the fluid grid ",
                             grid_.n[a]);
        for_each_index(Policy{}, grid_.cell_count(), detail::copy_porosity<Real>{view(), in});
        transform_reduce_into(context_, grid_.cell_count(), detail::cell_porosity<Real>{view()}, Real(1), min_op{},
                              &report_.data()->lowest_porosity);
        fill_cell_ghosts(phi_, false);
        fill_cell_ghosts(dphi_, false);
    }

    /// The interaction force density on the fluid (N/m^3), one vec3 per cell in field layout,
    /// in the policy's memory; zero until written. The coupling writes it before each step.
    vec3<Real>* interaction_force() { return force_.data(); }

    /// Sets the fluid velocity: v(x) for each face centre of each component (host function).
    template <class Field>
    void set_velocity(const Field& v)
    {
        for (int a = 0; a < 3; ++a) {
            std::vector<Real> h(grid_.field_size(), Real(0));
            for (int k = 0; k < int(grid_.n[2]); ++k)
                for (int j = 0; j < int(grid_.n[1]); ++j)
                    for (int i = 0; i < int(grid_.n[0]); ++i) {
                        vec3<Real> x = grid_.centre(i, j, k);
                        x[a] += Real(0.5) * grid_.width[a];
                        h[grid_.field_index(i, j, k)] = v(x)[a];
                    }
            u_[a].assign(h);
        }
        fill_velocity_ghosts();
    }

    /// Host copies: pressure (Pa), and the velocity component a on its faces (m/s), field layout.
    std::vector<Real> pressure() const { return p_.to_host(); }
    std::vector<Real> face_velocity(int a) const { return u_[a].to_host(); }
    std::vector<Real> porosity() const { return phi_.to_host(); }

    /// The fluid velocity at each cell centre (m/s; the mean of the two faces per axis), field layout.
    std::vector<vec3<Real>> cell_velocity() const
    {
        std::vector<Real> h[3] = {u_[0].to_host(), u_[1].to_host(), u_[2].to_host()};
        std::vector<vec3<Real>> out(grid_.field_size(), vec3<Real>{0, 0, 0});
        const long long stride[3] = {1, (long long)grid_.n[0] + 2, (long long)(grid_.n[0] + 2) * (grid_.n[1] + 2)};
        for (int k = 0; k < int(grid_.n[2]); ++k)
            for (int j = 0; j < int(grid_.n[1]); ++j)
                for (int i = 0; i < int(grid_.n[0]); ++i) {
                    const std::size_t c = grid_.field_index(i, j, k);
                    for (int a = 0; a < 3; ++a) out[c][a] = Real(0.5) * (h[a][c] + h[a][c - stride[a]]);
                }
        return out;
    }

    /// Momentum of the fluid (kg m/s): rho sum over the faces of phi_f v_a V_cell.
    vec3<double> momentum()
    {
        vec3<double> m{0, 0, 0};
        const double scale = double(params_.density) * double(grid_.width.x) * grid_.width.y * grid_.width.z;
        for (int a = 0; a < 3; ++a)
            m[a] = scale * transform_reduce(Policy{}, grid_.cell_count(), detail::face_momentum<Real>{view(), a}, 0.0,
                                            plus_op{});
        return m;
    }

    /// The largest stable time step (s) for the current velocity and porosity: the smaller of
    /// the diffusive limit phi_min rho / (2 mu (1/dx^2 + 1/dy^2 + 1/dz^2)) and the advective limit
    /// 1 / max(|v_x|/dx + |v_y|/dy + |v_z|/dz).
    Real stable_time_step()
    {
        const Real phi_min = transform_reduce(Policy{}, grid_.cell_count(), detail::cell_porosity<Real>{view()},
                                              Real(1), min_op{});
        Real inv_h2 = 0;
        for (int a = 0; a < 3; ++a) inv_h2 += Real(1) / (grid_.width[a] * grid_.width[a]);
        Real limit = phi_min * params_.density / (Real(2) * params_.viscosity * inv_h2);
        const Real rate = transform_reduce(Policy{}, grid_.cell_count(), detail::advective_rate<Real>{view()}, Real(0),
                                           max_op{});
        if (rate > 0 && Real(1) / rate < limit) limit = Real(1) / rate;
        return limit;
    }

    /// Advances the fluid by dt (s); see the class comment for what it checks.
    void step(Real dt) { check(advance(dt), dt); }

    /// The step without its checks' errors: advances the fluid by dt if every check passes and
    /// the solve converges, and returns the host's copy of the step's report (hold: why it did
    /// not advance). Throws only when dt is not positive and finite, on bad solver settings, and
    /// when the solve's criterion became NaN or infinite. `check` throws the rest.
    const detail::fluid_report<Real>& advance(Real dt)
    {
        if (!(dt > 0) || !std::isfinite(dt)) detail::fail("fluid: time step dt = ", dt, " s must be positive and finite");
        detail::fluid_report<Real>* r = report_.data();
        Real inv_h2 = 0;
        for (int a = 0; a < 3; ++a) inv_h2 += Real(1) / (grid_.width[a] * grid_.width[a]);
        transform_reduce_into(context_, grid_.cell_count(), detail::cell_porosity<Real>{view()}, Real(1), min_op{},
                              &r->phi_min);
        transform_reduce_into(context_, grid_.cell_count(), detail::advective_rate<Real>{view()}, Real(0), max_op{},
                              &r->rate);
        for_each_index(Policy{}, 1, detail::fluid_precheck<Real>{r, dt, params_.density, params_.viscosity, inv_h2});
        for_each_index(Policy{}, grid_.field_size(),
                       detail::fill_cell_ghosts<Real, vec3<Real>>{grid_, force_.data(), false});
        const fluid_view<Real> f = view();
        Real* out[3] = {us_[0].data(), us_[1].data(), us_[2].data()};
        for_each_index(Policy{}, grid_.cell_count(),
                       detail::predict_velocity<Real>{f, {out[0], out[1], out[2]}, dt, params_.beta, params_.gravity});
        fill_velocity_ghosts(out);
        const Real* vs[3] = {out[0], out[1], out[2]};
        for_each_index(Policy{}, grid_.cell_count(), detail::poisson_rhs<Real>{f, {vs[0], vs[1], vs[2]}, rhs_.data(), dt});
        set_boundary_increment(time_ + double(dt));
        poisson_boundaries bc;
        bc.bottom = params_.bottom.kind == fluid_boundary_kind::pressure ? z_boundary::dirichlet : z_boundary::neumann;
        bc.top = params_.top.kind == fluid_boundary_kind::pressure ? z_boundary::dirichlet : z_boundary::neumann;
        poisson_.launch(context_, &r->solve, &r->hold, eps_.data(), rhs_.data(), bc, params_.poisson);
        correct(dt, vs);
        context_.read_back(&host_report_, r, 1, "the fluid step's report", steps_);
        while (!host_report_.solve.finished) {
            poisson_.resume(context_);
            correct(dt, vs);
            context_.read_back(&host_report_, r, 1, "the fluid step's report", steps_);
        }
        if (host_report_.hold == detail::fluid_advances) {
            last_solve_ = poisson_.learn(host_report_.solve);
            if (host_report_.commit) {
                time_ += double(dt);
                ++steps_;
            }
        }
        return host_report_;
    }

    /// Throws the error of a step that did not advance (report: advance's), naming the check.
    void check(const detail::fluid_report<Real>& report, Real dt) const
    {
        switch (report.hold) {
        case detail::fluid_hold_porosity:
            detail::fail("fluid: a cell has porosity ", report.lowest_porosity,
                         "; the fluid needs porosity in (0, 1] everywhere");
        case detail::fluid_hold_response:
            detail::fail("fluid: time step dt = ", dt, " s exceeds the shortest particle response time ",
                         report.response, " s");
        case detail::fluid_hold_stability:
            detail::fail("fluid: time step dt = ", dt, " s exceeds the stability limit ", report.limit,
                         " s (diffusive phi rho h^2/(6 mu) or advective h/|v|); reduce dt or coarsen the grid");
        default:
            break;
        }
        if (!report.commit)
            detail::fail("fluid: the pressure solve did not converge at t = ", time_, " s: residual ",
                         last_solve_.residual, " after ", last_solve_.iterations, " iterations (tolerance ",
                         params_.poisson.tolerance, "); raise fluid_params::poisson.max_iterations or reduce dt");
    }

    /// The fluid's execution context (its reductions, scratch and read-backs).
    execution_context<Policy>& context() { return context_; }
    /// The step's report in the policy's memory, for a caller that adds its own checks and
    /// sums to it (the coupling: the response time, the work).
    detail::fluid_report<Real>* report() { return report_.data(); }

private:
    static detail::fluid_report<Real> initial_report()
    {
        detail::fluid_report<Real> r{};
        r.lowest_porosity = 1;
        r.response = Real(1e30);
        return r;
    }

    /// Where the step's solve finished and nothing held: the projection of the predicted
    /// velocities vs (detail::correct_velocity) and the ghosts.
    void correct(Real dt, const Real* const* vs)
    {
        const int* go = &report_.data()->commit;
        for_each_index(Policy{}, 1, detail::fluid_commit<Real>{report_.data()});
        for_each_index_if(Policy{}, go, grid_.cell_count(),
                          detail::correct_velocity<Real>{view(), {vs[0], vs[1], vs[2]}, eps_.data(), dt, params_.beta});
        const fluid_view<Real> f = view();
        for_each_index_if(Policy{}, go, grid_.field_size(), velocity_ghosts(f, {f.u[0], f.u[1], f.u[2]}));
        for_each_index_if(Policy{}, go, grid_.field_size(), detail::fill_cell_ghosts<Real, Real>{grid_, p_.data(), true});
    }

    void fill_cell_ghosts(buffer<Real, Policy>& b, bool extrapolate_z)
    {
        for_each_index(Policy{}, grid_.field_size(),
                       detail::fill_cell_ghosts<Real, Real>{grid_, b.data(), extrapolate_z});
    }
    void fill_pressure_ghosts() { fill_cell_ghosts(p_, true); }
    void fill_velocity_ghosts(Real* const* u)
    {
        for_each_index(Policy{}, grid_.field_size(), velocity_ghosts(view(), {u[0], u[1], u[2]}));
    }
    detail::fill_velocity_ghosts<Real> velocity_ghosts(const fluid_view<Real>& f, std::array<Real*, 3> u) const
    {
        return {grid_, {u[0], u[1], u[2]}, f.wall_bottom, f.wall_top, f.inflow_bottom, f.inflow_top,
                f.u_bottom, f.u_top, f.phi};
    }
    void fill_velocity_ghosts()
    {
        Real* u[3] = {u_[0].data(), u_[1].data(), u_[2].data()};
        fill_velocity_ghosts(u);
    }

    /// On the prescribed-pressure layers: epsilon = p(t) - beta p, with p the current pressure
    /// there (called with t = time + dt before the solve); at construction (beta irrelevant,
    /// p = 0) it also sets the layer's pressure to p(0).
    void set_boundary_increment(double t)
    {
        const fluid_view<Real> f = view();
        const std::size_t columns = std::size_t(grid_.n[0]) * grid_.n[1];
        if (params_.bottom.kind == fluid_boundary_kind::pressure)
            for_each_index(Policy{}, columns,
                           detail::set_boundary_increment<Real>{f, eps_.data(), 0, params_.bottom.value(t), params_.beta});
        if (params_.top.kind == fluid_boundary_kind::pressure)
            for_each_index(Policy{}, columns,
                           detail::set_boundary_increment<Real>{f, eps_.data(), int(grid_.n[2]) - 1,
                                                                 params_.top.value(t), params_.beta});
    }
    void set_boundary_pressure(double t)
    {
        set_boundary_increment(t);
        const fluid_view<Real> f = view();
        const std::size_t columns = std::size_t(grid_.n[0]) * grid_.n[1];
        // p = 0 here, so epsilon on the layers is p(t): copy it into the pressure.
        if (params_.bottom.kind == fluid_boundary_kind::pressure)
            for_each_index(Policy{}, columns,
                           detail::set_boundary_increment<Real>{f, p_.data(), 0, params_.bottom.value(t), Real(0)});
        if (params_.top.kind == fluid_boundary_kind::pressure)
            for_each_index(Policy{}, columns,
                           detail::set_boundary_increment<Real>{f, p_.data(), int(grid_.n[2]) - 1,
                                                                 params_.top.value(t), Real(0)});
    }

    fluid_grid<Real> grid_;
    fluid_params<Real> params_;
    buffer<Real, Policy> u_[3], us_[3];
    buffer<Real, Policy> p_, eps_, rhs_, phi_, dphi_;
    buffer<vec3<Real>, Policy> force_;
    Poisson poisson_;
    execution_context<Policy> context_;
    buffer<detail::fluid_report<Real>, Policy> report_;
    detail::fluid_report<Real> host_report_{};
    poisson_result last_solve_{};
    double time_ = 0;
    std::size_t steps_ = 0; ///< steps taken (names a failed read-back)
};

} // namespace sphere
