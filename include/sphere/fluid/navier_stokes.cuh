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

#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "../grid/neighbor_grid.cuh"
#include "../particles/state.cuh"
#include "drag.cuh"
#include "fields.cuh"
#include "fluid_params.cuh"
#include "grid.cuh"
#include "poisson.cuh"
#include "poisson_cg.cuh"
#include "poisson_mg.cuh"
#include "porosity.cuh"
#include "snapshot.cuh"

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

/// The fluid force on particle i (N), and its response time m / (drag coefficient) (s). A
/// kernel of its own, whose response times a plain reduction then takes the least of: inlined
/// into a CUB reduction (which unrolls several items per thread) the drag laws spill
/// registers (tests/check_ptxas.py).
template <class Real, class Drag>
struct fluid_particle_force {
    fluid_view<Real> f;
    porosity_view<Real> por;
    particle_view<Real> p;
    vec3<Real>* out;
    Real* response;
    bool pressure_force;

    SPHERE_HD void operator()(std::size_t i) const
    {
        const vec4<Real> x = p.x[i];
        int cell[3];
        f.grid.cell_of(x.xyz(), cell);
        const long long c = f.at(cell[0], cell[1], cell[2]);
        const Real r = x.w;
        const Real V = Real(4) / Real(3) * pi<Real> * r * r * r;
        const bool has_solid = por.d_p[c] > Real(0);
        const Real d = has_solid ? por.d_p[c] : Real(2) * r;
        const vec3<Real> v_p = has_solid ? por.v_p[c] : p.v_sync[i];
        const vec3<Real> rel = f.cell_velocity(c) - v_p;
        const Real phi = f.phi[c];
        const Real k = Drag::beta_per_solid(phi, d, norm(rel), f.rho, f.mu) * V;
        vec3<Real> force = rel * k;
        if (pressure_force) force += drag::pressure_gradient_force(V, f.pressure_gradient(c));
        out[i] = force;
        response[i] = k > Real(0) ? p.mass[i] / k : Real(1e30);
    }
};

/// The force density on the fluid in each cell (N/m^3): minus the sum of the forces on the
/// particles whose centres lie in it, over the cell volume, in bin order.
template <class Real>
struct fluid_reaction {
    fluid_view<Real> f;
    grid_view<Real> bins;
    const vec3<Real>* particle_force;

    SPHERE_HD void operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        vec3<Real> sum{0, 0, 0};
        for (unsigned s = bins.cell_start[cell]; s < bins.cell_start[cell + 1]; ++s) sum += particle_force[bins.order[s]];
        const Real volume = f.grid.width.x * f.grid.width.y * f.grid.width.z;
        f.force[c] = sum * (Real(-1) / volume);
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
class navier_stokes : public detail::fluid_model_base<Real, Policy, Poisson> {
    using base = detail::fluid_model_base<Real, Policy, Poisson>;

public:
    navier_stokes(const fluid_grid<Real>& g, const fluid_params<Real>& params)
        : base(g), grid_(g), params_(params), p_(g.field_size(), Real(0)), eps_(g.field_size(), Real(0)),
          rhs_(g.field_size(), Real(0)), phi_(g.field_size(), Real(1)), dphi_(g.field_size(), Real(0)),
          force_(g.field_size(), vec3<Real>{0, 0, 0})
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
        base::check_porosity_grid(in.grid, grid_, "fluid");
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
        return this->conclude_step(dt, "the fluid step's report", [&] { correct(dt, vs); });
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

    /// The coupling's hooks (fluid_coupling::step): writes the fluid force on each particle
    /// (detail::fluid_particle_force: the drag of its cell, and -V grad p if pressure_force) to
    /// out and its response time to the drag to response.
    template <class Drag>
    void particle_forces(const particle_view<Real>& p, const porosity_view<Real>& por, vec3<Real>* out,
                         Real* response, bool pressure_force)
    {
        for_each_index(Policy{}, p.n,
                       detail::fluid_particle_force<Real, Drag>{view(), por, p, out, response, pressure_force});
    }
    /// The particles' reaction on the fluid (detail::fluid_reaction), from their forces.
    void take_reaction(const grid_view<Real>& bins, const vec3<Real>* particle_force)
    {
        for_each_index(Policy{}, grid_.cell_count(), detail::fluid_reaction<Real>{view(), bins, particle_force});
    }


    /// The model's name in a fluid_snapshot.
    static const char* model_name() { return "navier_stokes"; }

    /// A host copy of the fluid's evolving state (fluid/snapshot.cuh; docs/fluid.md,
    /// *Restarting a coupled run*), for a checkpoint: the face velocities u_x, u_y, u_z and the
    /// pressure p (advanced by every step), the last pressure increment eps (the next solve's
    /// initial guess: it changes the bits of the next solution), the porosity phi, its rate
    /// dphi_dt and the interaction force (what a step on its own reads from the last
    /// set_porosity and interaction_force; a coupled step writes them first), the time (the
    /// prescribed pressures' p(t)) and the step count, and the last solve's result
    /// (last_solve(); read by nothing but the caller). Every field in field layout, ghosts
    /// included.
    fluid_snapshot<Real> snapshot() const
    {
        fluid_snapshot<Real> s = fluid_snapshot<Real>::of(model_name(), grid_);
        const char* u_names[3] = {"u_x", "u_y", "u_z"};
        for (int a = 0; a < 3; ++a) s.add(u_names[a], u_[a].to_host());
        s.add("p", p_.to_host());
        s.add("eps", eps_.to_host());
        s.add("phi", phi_.to_host());
        s.add("dphi_dt", dphi_.to_host());
        s.add("force", force_.to_host());
        this->add_step_state(s);
        return s;
    }

    /// Continues from a snapshot() of a navier_stokes on the same grid (with the same
    /// parameters: they are the caller's, not part of the snapshot): the next step gives the
    /// bits the snapshotted fluid's next step gave. Throws sphere::error, with nothing
    /// changed, when the snapshot is of another model or grid, lacks an entry or holds one
    /// this model does not have, or an array has another length than the grid's fields.
    void restore(const fluid_snapshot<Real>& s)
    {
        const char* who = "navier_stokes::restore";
        s.check_model_and_grid(who, model_name(), grid_);
        s.check_only(who, {"u_x", "u_y", "u_z", "p", "eps", "phi", "dphi_dt", "force"}, base::step_numbers(),
                     base::step_counts());
        const std::size_t size = grid_.field_size();
        const char* what = "the grid's field size, ghost nodes included";
        const char* u_names[3] = {"u_x", "u_y", "u_z"};
        const std::vector<Real>* u[3];
        for (int a = 0; a < 3; ++a) u[a] = &s.array_named(who, u_names[a], size, what);
        const std::vector<Real>& p = s.array_named(who, "p", size, what);
        const std::vector<Real>& eps = s.array_named(who, "eps", size, what);
        const std::vector<Real>& phi = s.array_named(who, "phi", size, what);
        const std::vector<Real>& dphi = s.array_named(who, "dphi_dt", size, what);
        const std::vector<vec3<Real>> force = s.vectors_named(who, "force", size, "3 per node of the grid's fields");
        const typename base::step_state st = base::read_step_state(s, who);
        for (int a = 0; a < 3; ++a) u_[a].assign(*u[a]);
        p_.assign(p);
        eps_.assign(eps);
        phi_.assign(phi);
        dphi_.assign(dphi);
        force_.assign(force);
        this->apply_step_state(st);
        // What set_porosity found (a step on its own checks it).
        transform_reduce_into(context_, grid_.cell_count(), detail::cell_porosity<Real>{view()}, Real(1), min_op{},
                              &report_.data()->lowest_porosity);
    }

private:
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

    using base::context_;
    using base::poisson_;
    using base::report_;
    using base::steps_;
    using base::time_;
    using base::last_solve_;

    fluid_grid<Real> grid_;
    fluid_params<Real> params_;
    buffer<Real, Policy> u_[3], us_[3];
    buffer<Real, Policy> p_, eps_, rhs_, phi_, dphi_;
    buffer<vec3<Real>, Policy> force_;
};

} // namespace sphere
