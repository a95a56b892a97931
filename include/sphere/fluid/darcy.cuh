#pragma once
/// \file
/// The Darcy model of the pore fluid (docs/fluid.md, *Darcy model*): the cheap alternative to
/// navier_stokes.cuh for slow flow through a granular skeleton (consolidation, undrained
/// shear). The pore fluid is slightly compressible (compressibility beta_f), flows relative to
/// the solid by Darcy's law with a Kozeny-Carman permeability of the cell porosity, and its
/// pressure obeys the diffusion equation (D-3)
///
///     phi beta_f dp/dt = div( k/mu (grad p - rho_f g) ) - div v_s
///
/// (the mixture's volume balance: the fluid's and the solid's mass balances summed, with
/// Darcy's flux q = phi (v_f - v_s) = -k/mu (grad p - rho_f g) and v_s the cell's
/// volume-weighted mean particle velocity, 0 where it holds no solid; docs/fluid.md explains
/// why not the porosity's rate), solved implicitly (backward Euler) for the increment of p
/// over the step by a Poisson solver with variable coefficients (poisson.cuh): K = k/mu on the
/// cells (faces: the harmonic mean) and the sink
/// S = phi beta_f / dt. The particles feel the force (D-5)
///
///     f_i = V_i / (1 - phi) ( phi rho_f g - grad p )
///
/// (drag and buoyancy together: the fluid's whole force on the solid of a cell, -grad p +
/// phi rho_f g per unit volume of mixture, shared by solid volume). There is no fluid
/// velocity to advance and no momentum: the pressure step is unconditionally stable; the
/// coupling's explicit exchange is limited by the particles' response time (D-6).
///
/// Layout: pressure, porosity, the mean particle velocity and K live at cell centres in
/// fluid_grid::field_index layout (one ghost layer), like navier_stokes's.
#include <cmath>
#include <cstddef>
#include <cstdint>
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
#include "fields.cuh"
#include "fluid_params.cuh"
#include "grid.cuh"
#include "poisson.cuh"
#include "poisson_cg.cuh"
#include "porosity.cuh"
#include "snapshot.cuh"

namespace sphere {

/// Parameters of the Darcy model: the fluid's (density, viscosity, gravity, the two z ends and
/// the solve's settings; its projection weight beta is not used) and the porous medium's.
template <class Real>
struct darcy_params {
    fluid_params<Real> fluid{};
    Real compressibility = Real(4.5e-10); ///< beta_f (1/Pa): water at 25 C
    /// k_c (m^2) of the Kozeny-Carman permeability k = k_c phi^3 / (1 - phi)^2 (D-1): Carman's
    /// d^2 / 180 for spheres of diameter d, or Ergun's viscous term's d^2 / 150. No default.
    Real permeability_prefactor = 0;
    /// The permeability and the force use min(phi, max_porosity): Darcy's law describes a
    /// porous medium, not a suspension, and k grows without bound as phi -> 1.
    Real max_porosity = Real(0.9);

    /// Throws sphere::error naming the first invalid value.
    void validate() const
    {
        fluid.validate();
        if (!(compressibility > 0) || !std::isfinite(compressibility))
            detail::fail("darcy: compressibility = ", compressibility, " 1/Pa must be positive and finite");
        if (!(permeability_prefactor > 0) || !std::isfinite(permeability_prefactor))
            detail::fail("darcy: permeability_prefactor = ", permeability_prefactor,
                         " m^2 must be positive and finite (Carman: d^2/180 for spheres of diameter d)");
        if (!(max_porosity > 0 && max_porosity < 1))
            detail::fail("darcy: max_porosity = ", max_porosity, " must lie in (0, 1)");
    }

    /// The Kozeny-Carman permeability (m^2) at porosity phi (capped at max_porosity).
    SPHERE_HD Real permeability(Real phi) const
    {
        const Real f = phi < max_porosity ? phi : max_porosity;
        return permeability_prefactor * f * f * f / ((Real(1) - f) * (Real(1) - f));
    }
};

/// Kernel view of the Darcy model's fields (device pointers for the cuda policy).
template <class Real>
struct darcy_view {
    fluid_grid<Real> grid;
    Real* p;          ///< pressure (Pa)
    Real* phi;        ///< porosity (-)
    vec3<Real>* v_s;  ///< volume-weighted mean particle velocity (m/s), 0 where no solid
    Real* K;          ///< hydraulic conductivity k / mu (m^2 / (Pa s))
    long long stride[3];
    Real rho;         ///< fluid density (kg/m^3)
    vec3<Real> g;     ///< gravity (m/s^2)
    Real max_porosity;
    bool closed_bottom, closed_top; ///< no gravity flux through the end face (no-flow or inflow)
    Real q_bottom, q_top;           ///< prescribed superficial velocity through the end face (+z; 0: none)

    SPHERE_HD long long at(int i, int j, int k) const { return static_cast<long long>(grid.field_index(i, j, k)); }
    SPHERE_HD long long cell_field(std::size_t cell, int& k) const
    {
        int i, j;
        grid.coordinates(cell, i, j, k);
        return at(i, j, k);
    }
    /// Conductance of the face between field indices a and b: the harmonic mean of K.
    SPHERE_HD Real face(long long a, long long b) const { return Real(2) * K[a] * K[b] / (K[a] + K[b]); }
    /// Darcy's flux q_a = -K_f ((p_hi - p_lo) / h_a - rho_f g_a) (m/s) through the face of axis
    /// a above cell c (field index, in layer k): 0 through a closed end face of the grid, the
    /// prescribed U through an inflow one.
    SPHERE_HD Real flux(long long c, int a, int k) const
    {
        const long long hi = c + stride[a];
        if (a == 2 && k == int(grid.n[2]) - 1 && closed_top) return q_top;
        if (a == 2 && k == -1 && closed_bottom) return q_bottom;
        return -face(c, hi) * ((p[hi] - p[c]) / grid.width[a] - rho * g[a]);
    }
    /// The mean of the Darcy fluxes through the two faces of cell c per axis (m/s), the
    /// superficial velocity of the fluid relative to the solid at the cell's centre.
    SPHERE_HD vec3<Real> cell_flux(long long c, int k) const
    {
        vec3<Real> q;
        for (int a = 0; a < 3; ++a)
            q[a] = Real(0.5) * (flux(c, a, k) + flux(c - stride[a], a, a == 2 ? k - 1 : k));
        return q;
    }
};

namespace detail {

/// The porosity of a cell (a reduction's transform: the least porosity).
template <class Real>
struct darcy_cell_porosity {
    darcy_view<Real> f;
    SPHERE_HD Real operator()(std::size_t cell) const
    {
        int k;
        return f.phi[f.cell_field(cell, k)];
    }
};

/// Copies a porosity estimate into the Darcy fields and sets K = k(phi) / mu on the cells.
template <class Real>
struct darcy_take_porosity {
    darcy_view<Real> f;
    porosity_view<Real> in;
    darcy_params<Real> prm;

    SPHERE_HD void operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        f.phi[c] = in.phi[c];
        f.v_s[c] = in.v_p[c];
        f.K[c] = prm.permeability(in.phi[c]) / prm.fluid.viscosity;
    }
};

/// The right-hand side and the sink of the implicit step for the pressure increment
/// delta = p(t + dt) - p(t) on every cell (docs/fluid.md (D-4)): with S = phi beta_f / dt,
///   sum_faces K_f (delta_nb - delta) / h^2 - S delta = div q(p) + div v_s,
/// where q(p) is Darcy's flux of the current pressure (with gravity's part; 0 or U through a
/// closed or inflow end face) and div v_s the divergence of the solid's velocity (face
/// velocities the mean of the two cells', none through the z ends: the solid stays inside the
/// grid; summed over a closed box it vanishes exactly). Solving for the increment keeps its
/// precision in float, where p itself changes by less than its rounding in one step.
template <class Real>
struct darcy_rhs {
    darcy_view<Real> f;
    Real* rhs;
    Real* sink;
    Real* guess; ///< the solve's initial guess: 0
    Real beta_f, dt;

    SPHERE_HD void operator()(std::size_t cell) const
    {
        int k;
        const long long c = f.cell_field(cell, k);
        const int nz = int(f.grid.n[2]);
        Real div = 0;
        for (int a = 0; a < 3; ++a) {
            const long long s = f.stride[a];
            const bool lo_end = a == 2 && k == 0, hi_end = a == 2 && k == nz - 1;
            const Real solid_hi = hi_end ? Real(0) : Real(0.5) * (f.v_s[c][a] + f.v_s[c + s][a]);
            const Real solid_lo = lo_end ? Real(0) : Real(0.5) * (f.v_s[c][a] + f.v_s[c - s][a]);
            const Real fluid_hi = f.flux(c, a, k), fluid_lo = f.flux(c - s, a, a == 2 ? k - 1 : k);
            div += ((fluid_hi - fluid_lo) + (solid_hi - solid_lo)) / f.grid.width[a];
        }
        sink[c] = f.phi[c] * beta_f / dt;
        rhs[c] = div;
        guess[c] = 0;
    }
};

/// Sets layer k of a field to `value` minus the pressure there (the increment that brings a
/// prescribed-pressure layer to its value), or to `value` when `pressure` is null.
template <class Real>
struct set_layer {
    fluid_grid<Real> grid;
    Real* field;
    int k;
    Real value;
    const Real* pressure;
    SPHERE_HD void operator()(std::size_t column) const
    {
        const std::size_t c = grid.field_index(int(column % grid.n[0]), int(column / grid.n[0]), k);
        field[c] = pressure ? value - pressure[c] : value;
    }
};

/// p += delta on the whole field.
template <class Real>
struct add_increment {
    Real* p;
    const Real* delta;
    SPHERE_HD void operator()(std::size_t i) const { p[i] += delta[i]; }
};

/// The checks before a Darcy step: why it holds, if it does (a porosity outside (0, 1], a
/// step beyond the coupling's response time). The implicit step has no stability limit.
template <class Real>
struct darcy_precheck {
    fluid_report<Real>* r;
    Real dt;
    SPHERE_HD void operator()(std::size_t) const
    {
        r->limit = Real(1e30);
        r->hold = !(r->lowest_porosity > Real(0)) ? fluid_hold_porosity
                  : !(dt <= r->response)          ? fluid_hold_response
                                                  : fluid_advances;
        r->commit = 0;
    }
};

/// The Darcy force on particle i (D-5): V / (1 - phi) (phi rho_f g - grad p) with the porosity
/// of its cell (capped at max_porosity), or without pressure_force only the drag part,
/// V phi / (1 - phi) (rho_f g - grad p) (the whole less the buoyancy -V grad p). Its response
/// time (D-6): the drag part is C (v_f - v_s) with C = V phi^2 / (K (1 - phi)) (Darcy's law),
/// so m / C = m K (1 - phi) / (V phi^2), which the coupling's explicit step must not exceed.
template <class Real>
struct darcy_particle_force {
    darcy_view<Real> f;
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
        const Real phi = f.phi[c] < f.max_porosity ? f.phi[c] : f.max_porosity;
        // rho_f g - grad p from the cell's Darcy flux, q / K: the mean gradient of the faces'
        // fluxes, which a face to a more permeable cell (above a bed) does not dilute.
        const vec3<Real> seepage = f.cell_flux(c, cell[2]) * (Real(1) / f.K[c]);
        vec3<Real> force = seepage * (V * phi / (Real(1) - phi));
        if (pressure_force) force -= (f.g * f.rho - seepage) * V;
        out[i] = force;
        response[i] = p.mass[i] * f.K[c] * (Real(1) - phi) / (V * phi * phi);
    }
};

} // namespace detail

/// The Darcy pore-pressure model (file comment), with the interface fluid_coupling uses (its
/// `Model` darcy_flow): set_porosity, advance / check / step, the particle-force hook. `Poisson`
/// solves the implicit step: cg_poisson (default) or mg_poisson (conjugate gradients
/// preconditioned by the constant-coefficient V-cycle; fewer iterations on large grids) or
/// jacobi_poisson.
///
/// The pressure starts hydrostatic from a prescribed-pressure end (rho_f g_z; 0 without one).
///
/// Boundaries (darcy_params::fluid.bottom / top): no_flow (no flux through the end face),
/// pressure (the end cell layer holds p(t), as navier_stokes), inflow (a prescribed
/// superficial velocity U = q through the end face; the other end must prescribe the
/// pressure). x and y are periodic. Each step waits for the device once, like navier_stokes.
template <class Real, class Policy, class Poisson = cg_poisson<Real, Policy>>
class darcy_flow : public detail::fluid_model_base<Real, Policy, Poisson> {
    using base = detail::fluid_model_base<Real, Policy, Poisson>;

public:
    darcy_flow(const fluid_grid<Real>& g, const darcy_params<Real>& params)
        : base(g), grid_(g), params_(params), p_(g.field_size(), Real(0)), eps_(g.field_size(), Real(0)),
          rhs_(g.field_size(), Real(0)), sink_(g.field_size(), Real(0)), phi_(g.field_size(), Real(1)),
          v_s_(g.field_size(), vec3<Real>{0, 0, 0}), K_(g.field_size(), Real(0))
    {
        params_.validate();
        const fluid_params<Real>& f = params_.fluid;
        const bool pressure_end =
            f.bottom.kind == fluid_boundary_kind::pressure || f.top.kind == fluid_boundary_kind::pressure;
        if (pressure_end && g.n[2] < 3)
            detail::fail("darcy: nz = ", g.n[2], " cells; a prescribed-pressure end needs nz >= 3");
        for_each_index(Policy{}, grid_.cell_count(),
                       detail::darcy_take_porosity<Real>{view(), empty_porosity(), params_});
        fill_ghosts();
        // The pressure starts hydrostatic from a prescribed-pressure end (the top's if both
        // are), 0 without one: a coupled run's first forces are then buoyancy, not a
        // seepage force of the whole weight of the fluid.
        const bool top = f.top.kind == fluid_boundary_kind::pressure;
        const int k_end = top ? int(g.n[2]) - 1 : 0;
        const double p_end = top ? double(f.top.value(0)) : double(f.bottom.value(0));
        const double z_end = double(g.centre(0, 0, k_end).z), rho_g = double(f.density) * double(f.gravity.z);
        set_pressure([&](const vec3<Real>& x) {
            return pressure_end ? Real(p_end + rho_g * (double(x.z) - z_end)) : Real(0);
        });
    }

    const fluid_grid<Real>& grid() const { return grid_; }
    const darcy_params<Real>& params() const { return params_; }

    darcy_view<Real> view()
    {
        darcy_view<Real> v;
        v.grid = grid_;
        v.p = p_.data();
        v.phi = phi_.data();
        v.v_s = v_s_.data();
        v.K = K_.data();
        v.stride[0] = 1;
        v.stride[1] = grid_.n[0] + 2;
        v.stride[2] = (long long)(grid_.n[0] + 2) * (grid_.n[1] + 2);
        const fluid_params<Real>& f = params_.fluid;
        v.rho = f.density;
        v.g = f.gravity;
        v.max_porosity = params_.max_porosity;
        v.closed_bottom = f.bottom.kind != fluid_boundary_kind::pressure;
        v.closed_top = f.top.kind != fluid_boundary_kind::pressure;
        v.q_bottom = f.bottom.kind == fluid_boundary_kind::inflow ? f.bottom.velocity : Real(0);
        v.q_top = f.top.kind == fluid_boundary_kind::inflow ? f.top.velocity : Real(0);
        return v;
    }

    /// Takes the porosity, its rate and the mean particle velocity from an estimator (same
    /// grid). The next step throws when a cell's porosity is not in (0, 1].
    void set_porosity(const porosity_view<Real>& in)
    {
        base::check_porosity_grid(in.grid, grid_, "darcy");
        for_each_index(Policy{}, grid_.cell_count(), detail::darcy_take_porosity<Real>{view(), in, params_});
        transform_reduce_into(context_, grid_.cell_count(), detail::darcy_cell_porosity<Real>{view()}, Real(1),
                              min_op{}, &report_.data()->lowest_porosity);
        fill_ghosts();
    }

    /// Sets the pressure (Pa) to p(x) at every cell centre (host function); the
    /// prescribed-pressure layers keep their boundary values.
    template <class Field>
    void set_pressure(const Field& p)
    {
        std::vector<Real> h = p_.to_host();
        for (int k = 0; k < int(grid_.n[2]); ++k)
            for (int j = 0; j < int(grid_.n[1]); ++j)
                for (int i = 0; i < int(grid_.n[0]); ++i) h[grid_.field_index(i, j, k)] = p(grid_.centre(i, j, k));
        p_.assign(h);
        set_layers(p_.data(), time_);
        fill_pressure_ghosts(p_.data(), nullptr);
    }

    /// Host copies (field layout): pressure (Pa), porosity, hydraulic conductivity k/mu.
    std::vector<Real> pressure() const { return p_.to_host(); }
    std::vector<Real> porosity() const { return phi_.to_host(); }
    std::vector<Real> conductivity() const { return K_.to_host(); }

    /// The Darcy flux q = -k/mu (grad p - rho_f g) at each cell centre (m/s; the mean of the
    /// two face fluxes per axis, those through closed end faces 0, inflow faces their U),
    /// field layout: the superficial velocity of the fluid relative to the solid.
    std::vector<vec3<Real>> darcy_flux()
    {
        std::vector<Real> p = p_.to_host(), K = K_.to_host();
        darcy_view<Real> v = view();
        v.p = p.data();
        v.K = K.data();
        std::vector<vec3<Real>> out(grid_.field_size(), vec3<Real>{0, 0, 0});
        for (std::size_t cell = 0; cell < grid_.cell_count(); ++cell) {
            int k;
            const long long c = v.cell_field(cell, k);
            out[c] = v.cell_flux(c, k);
        }
        return out;
    }

    /// The fluid velocity at each cell centre (m/s), field layout: v_f = v_s + q / phi, the
    /// cell's mean particle velocity plus Darcy's flux over the porosity.
    std::vector<vec3<Real>> cell_velocity()
    {
        std::vector<vec3<Real>> v = darcy_flux();
        const std::vector<vec3<Real>> v_s = v_s_.to_host();
        const std::vector<Real> phi = phi_.to_host();
        for (std::size_t c = 0; c < v.size(); ++c) v[c] = v_s[c] + v[c] * (Real(1) / phi[c]);
        return v;
    }

    /// Advances the pressure by dt (s); see check() for what it refuses.
    void step(Real dt) { check(advance(dt), dt); }

    /// The step without its checks' errors: solves for the pressure at t + dt if every check
    /// passes and the solve converges, and returns the host's copy of the step's report.
    /// Throws only when dt is not positive and finite, on bad solver settings, and when the
    /// solve's criterion became NaN or infinite.
    const detail::fluid_report<Real>& advance(Real dt)
    {
        if (!(dt > 0) || !std::isfinite(dt)) detail::fail("darcy: time step dt = ", dt, " s must be positive and finite");
        detail::fluid_report<Real>* r = report_.data();
        for_each_index(Policy{}, 1, detail::darcy_precheck<Real>{r, dt});
        for_each_index(Policy{}, grid_.cell_count(),
                       detail::darcy_rhs<Real>{view(), rhs_.data(), sink_.data(), eps_.data(), params_.compressibility, dt});
        set_layers(eps_.data(), time_ + double(dt), p_.data());
        const fluid_params<Real>& f = params_.fluid;
        poisson_boundaries bc;
        bc.bottom = f.bottom.kind == fluid_boundary_kind::pressure ? z_boundary::dirichlet : z_boundary::neumann;
        bc.top = f.top.kind == fluid_boundary_kind::pressure ? z_boundary::dirichlet : z_boundary::neumann;
        poisson_coefficients<Real> k;
        k.conductance = K_.data();
        k.sink = sink_.data();
        k.conductance_max = double(params_.permeability(params_.max_porosity)) / double(f.viscosity);
        k.sink_max = double(params_.compressibility) / double(dt);
        poisson_.launch(context_, &r->solve, &r->hold, eps_.data(), rhs_.data(), bc, f.poisson, k);
        return this->conclude_step(dt, "the Darcy step's report", [&] { commit(); });
    }

    /// Throws the error of a step that did not advance (report: advance's), naming the check.
    void check(const detail::fluid_report<Real>& report, Real dt) const
    {
        switch (report.hold) {
        case detail::fluid_hold_porosity:
            detail::fail("darcy: a cell has porosity ", report.lowest_porosity,
                         "; the fluid needs porosity in (0, 1] everywhere");
        case detail::fluid_hold_response:
            detail::fail("darcy: time step dt = ", dt, " s exceeds the shortest particle response time ",
                         report.response, " s");
        default:
            break;
        }
        if (!report.commit)
            detail::fail("darcy: the pressure solve did not converge at t = ", time_, " s: residual ",
                         last_solve_.residual, " after ", last_solve_.iterations, " iterations (tolerance ",
                         params_.fluid.poisson.tolerance, "); raise darcy_params::fluid.poisson.max_iterations");
    }

    /// The coupling's hooks (fluid_coupling::step): the Darcy force (D-5) on each particle and
    /// its response time (D-6). `Drag` is not used.
    template <class Drag>
    void particle_forces(const particle_view<Real>& p, const porosity_view<Real>&, vec3<Real>* out, Real* response,
                         bool pressure_force)
    {
        for_each_index(Policy{}, p.n, detail::darcy_particle_force<Real>{view(), p, out, response, pressure_force});
    }
    /// The Darcy model has no fluid momentum: the particles' reaction is in the pressure.
    void take_reaction(const grid_view<Real>&, const vec3<Real>*) {}


    /// The model's name in a fluid_snapshot.
    static const char* model_name() { return "darcy"; }

    /// A host copy of the model's evolving state (fluid/snapshot.cuh; docs/fluid.md,
    /// *Restarting a coupled run*): the pressure p (advanced by every step), the porosity phi,
    /// the mean particle velocity v_s and the conductivity K (what a step on its own reads
    /// from the last set_porosity; a coupled step writes them first), the time (the prescribed
    /// pressures' p(t)), the step count and the last solve's result. The solve starts from 0:
    /// no solver state carries over. Every field in field layout, ghosts included.
    fluid_snapshot<Real> snapshot() const
    {
        fluid_snapshot<Real> s = fluid_snapshot<Real>::of(model_name(), grid_);
        s.add("p", p_.to_host());
        s.add("phi", phi_.to_host());
        s.add("v_s", v_s_.to_host());
        s.add("K", K_.to_host());
        this->add_step_state(s);
        return s;
    }

    /// Continues from a snapshot() of a darcy_flow on the same grid (with the same parameters:
    /// they are the caller's): the next step gives the bits the snapshotted model's next step
    /// gave. Throws sphere::error, with nothing changed, when the snapshot is of another model
    /// or grid, lacks an entry or holds one this model does not have, or an array has another
    /// length than the grid's fields.
    void restore(const fluid_snapshot<Real>& s)
    {
        const char* who = "darcy_flow::restore";
        s.check_model_and_grid(who, model_name(), grid_);
        s.check_only(who, {"p", "phi", "v_s", "K"}, base::step_numbers(), base::step_counts());
        const std::size_t size = grid_.field_size();
        const char* what = "the grid's field size, ghost nodes included";
        const std::vector<Real>& p = s.array_named(who, "p", size, what);
        const std::vector<Real>& phi = s.array_named(who, "phi", size, what);
        const std::vector<vec3<Real>> v_s = s.vectors_named(who, "v_s", size, "3 per node of the grid's fields");
        const std::vector<Real>& K = s.array_named(who, "K", size, what);
        const typename base::step_state st = base::read_step_state(s, who);
        p_.assign(p);
        phi_.assign(phi);
        v_s_.assign(v_s);
        K_.assign(K);
        this->apply_step_state(st);
        transform_reduce_into(context_, grid_.cell_count(), detail::darcy_cell_porosity<Real>{view()}, Real(1),
                              min_op{}, &report_.data()->lowest_porosity);
    }

private:
    /// A porosity view of a grid without particles (phi = 1, no velocity), for the
    /// fields' initial values.
    porosity_view<Real> empty_porosity()
    {
        porosity_view<Real> v{};
        v.grid = grid_;
        v.phi = phi_.data();
        v.dphi_dt = nullptr;
        v.v_p = v_s_.data();
        v.d_p = nullptr;
        return v;
    }

    /// Where the step's solve finished and nothing held: p += the increment, its ghosts.
    void commit()
    {
        const int* go = &report_.data()->commit;
        for_each_index(Policy{}, 1, detail::fluid_commit<Real>{report_.data()});
        for_each_index_if(Policy{}, go, grid_.field_size(), detail::add_increment<Real>{p_.data(), eps_.data()});
        fill_pressure_ghosts(p_.data(), go);
    }

    void fill_ghosts()
    {
        const std::size_t n = grid_.field_size();
        for_each_index(Policy{}, n, detail::fill_cell_ghosts<Real, Real>{grid_, phi_.data(), false});
        for_each_index(Policy{}, n, detail::fill_cell_ghosts<Real, vec3<Real>>{grid_, v_s_.data(), false});
        for_each_index(Policy{}, n, detail::fill_cell_ghosts<Real, Real>{grid_, K_.data(), false});
    }
    /// The pressure's ghosts: extrapolated linearly along z (the gradient at an end cell is
    /// one-sided), periodic copies along x and y.
    void fill_pressure_ghosts(Real* p, const int* go)
    {
        const detail::fill_cell_ghosts<Real, Real> k{grid_, p, true};
        if (go)
            for_each_index_if(Policy{}, go, grid_.field_size(), k);
        else
            for_each_index(Policy{}, grid_.field_size(), k);
    }

    /// Sets the prescribed-pressure layers of a field to p(t) (minus `pressure` there if given).
    void set_layers(Real* field, double t, const Real* pressure = nullptr)
    {
        const fluid_params<Real>& f = params_.fluid;
        const std::size_t columns = std::size_t(grid_.n[0]) * grid_.n[1];
        if (f.bottom.kind == fluid_boundary_kind::pressure)
            for_each_index(Policy{}, columns, detail::set_layer<Real>{grid_, field, 0, f.bottom.value(t), pressure});
        if (f.top.kind == fluid_boundary_kind::pressure)
            for_each_index(Policy{}, columns,
                           detail::set_layer<Real>{grid_, field, int(grid_.n[2]) - 1, f.top.value(t), pressure});
    }

    using base::context_;
    using base::poisson_;
    using base::report_;
    using base::time_;
    using base::last_solve_;

    fluid_grid<Real> grid_;
    darcy_params<Real> params_;
    buffer<Real, Policy> p_, eps_, rhs_, sink_, phi_;
    buffer<vec3<Real>, Policy> v_s_;
    buffer<Real, Policy> K_;
};

} // namespace sphere
