#pragma once
/// \file
/// Two-way coupling of the pore fluid and the particles (docs/fluid.md, *Coupling*).
///
/// One coupled step of length dt_f = dem_steps x (DEM time step):
///   1. the porosity estimator bins the particles by fluid cell and computes each cell's
///      porosity, its rate, and the volume-weighted mean particle velocity and diameter;
///   2. every particle gets the fluid force of its cell (the cell holding its centre)
///        f_i = Drag::beta_per_solid(phi, d, |v_f - v_p|) (v_f - v_p) V_i  [ - V_i grad p ]
///      with the cell's porosity phi, fluid velocity v_f, mean particle velocity v_p and mean
///      diameter d (the particle's own velocity and diameter where the cell holds no
///      solid); the bracket is the optional pressure-gradient (buoyancy) force;
///   3. the fluid gets the opposite of the sum of its particles' forces, per unit cell volume,
///      so that momentum is exchanged exactly (summed per cell in particle order:
///      deterministic);
///   4. the fluid advances by dt_f (its own stability limits checked), then the DEM by
///      dem_steps steps with the forces held constant; the work the forces did on the free
///      particles (force times displacement) is added to work_on_particles().
/// The checks (porosity, response time, stability, the pressure solve) are taken on the device
/// and read back once, with the fluid step's report, before the DEM steps: a coupled step
/// waits for the device once more than its dem_steps DEM steps do (also with velocity Verlet,
/// whose check of its next drift, which the new forces change, comes back with that report).
/// The forces are explicit: dt_f must not exceed the shortest particle response time
/// m_i / (beta_per_solid V_i) (checked; the step throws naming the particle).
#include <cstddef>
#include <type_traits>

#include "../boundary/world.cuh"
#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/for_each.cuh"
#include "../grid/neighbor_grid.cuh"
#include "../particles/state.cuh"
#include "drag.cuh"
#include "navier_stokes.cuh"
#include "porosity.cuh"

namespace sphere {

/// How the fluid and the particles are coupled.
struct coupling_options {
    unsigned dem_steps = 10;     ///< DEM steps per fluid step
    bool pressure_force = true;  ///< apply -V_p grad p to the particles (and its reaction to the fluid)
    /// How the cells' solid volume is measured: cell_volume conserves the grid's solid volume
    /// (needed for a closed box); cell_sphere is the seeds' estimator.
    porosity_method porosity = porosity_method::cell_volume;
};

namespace detail {

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

/// values[i] (a reduction's transform over an array).
template <class T>
struct value_at {
    const T* values;
    SPHERE_HDI T operator()(std::size_t i) const { return values[i]; }
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

/// Copies the position of the particle in slot k to its user index.
template <class Real>
struct positions_by_user {
    particle_view<Real> p;
    vec4<Real>* by_user;
    SPHERE_HD void operator()(std::size_t k) const { by_user[p.user[k]] = p.x[k]; }
};

/// The work (J) the fluid force did on free particle i over a coupled step: the force, held
/// constant, times the particle's displacement (nearest periodic image) since the step began.
/// The start positions are kept by user index: the DEM steps may reorder the particles.
template <class Real>
struct fluid_work_on_particle {
    world<Real> box;
    const vec4<Real>* before; ///< position at the step's start, by user index
    particle_view<Real> p;
    const vec3<Real>* force;

    SPHERE_HD double operator()(std::size_t i) const
    {
        if (static_cast<motion>(p.kind[i]) != motion::free) return 0;
        const vec3<Real> d = box.nearest_image(p.x[i].xyz() - before[p.user[i]].xyz());
        return double(force[i].x) * double(d.x) + double(force[i].y) * double(d.y) + double(force[i].z) * double(d.z);
    }
};

/// Adds the last coupled step's work to the total (in the fluid's report).
template <class Real>
struct add_work {
    fluid_report<Real>* r;
    SPHERE_HD void operator()(std::size_t) const { r->work_total += r->work_step; }
};

} // namespace detail

/// The pore fluid coupled to a simulation's particles. `Drag` is a drag law of sphere::drag,
/// `Poisson` the pressure solver.
template <class Real, class Policy, class Drag = drag::gidaspow, class Poisson = mg_poisson<Real, Policy>>
class fluid_coupling {
public:
    fluid_coupling(const fluid_grid<Real>& g, const fluid_params<Real>& params, const coupling_options& options = {})
        : options_(options), porosity_(g, options.porosity), fluid_(g, params)
    {
        if (options.dem_steps < 1) detail::fail("coupling: dem_steps = 0; at least one DEM step per fluid step");
        Drag::validate();
    }

    navier_stokes<Real, Policy, Poisson>& fluid() { return fluid_; }
    const porosity_estimator<Real, Policy>& porosity() const { return porosity_; }
    const coupling_options& options() const { return options_; }

    /// One coupled step (see the file comment): the fluid advances by dem_steps x sim.dt(), then
    /// the simulation by dem_steps steps. Throws sphere::error, before the fluid and the
    /// particles advance, when the fluid time step breaks a stability limit of the fluid or
    /// exceeds a particle's response time to the drag.
    template <class Simulation>
    void step(Simulation& sim)
    {
        static_assert(std::is_same_v<typename Simulation::precision_type, Real>,
                      "fluid_coupling<Real> couples a simulation<Real> (float or double); precision mixed is not "
                      "coupled to the pore fluid yet (docs/fluid.md)");
        const Real dt = Real(options_.dem_steps) * sim.dt();
        const particle_view<Real> p = sim.particle_data();
        porosity_.update(p, dt, sim.largest_radius());
        fluid_.set_porosity(porosity_.view());
        vec3<Real>* forces = sim.external_forces();
        if (response_.size() != p.n) response_ = buffer<Real, Policy>(p.n);
        for_each_index(Policy{}, p.n,
                       detail::fluid_particle_force<Real, Drag>{fluid_.view(), porosity_.view(), p, forces,
                                                                response_.data(), options_.pressure_force});
        detail::fluid_report<Real>* report = fluid_.report();
        transform_reduce_into(fluid_.context(), p.n, detail::value_at<Real>{response_.data()}, Real(1e30), min_op{},
                              &report->response);
        for_each_index(Policy{}, fluid_.grid().cell_count(),
                       detail::fluid_reaction<Real>{fluid_.view(), porosity_.bins(), forces});
        // New forces change where a drift-first integrator's next drift goes: its check comes
        // back with the fluid's report instead of with a read-back of its own.
        const bool predicted = sim.predict_drift_into(&report->next_drift);
        const detail::fluid_report<Real>& found = fluid_.advance(dt);
        if (found.hold == detail::fluid_hold_response)
            detail::fail("coupling: the fluid step ", dt, " s (", options_.dem_steps, " DEM steps of ", sim.dt(),
                         " s) exceeds the shortest particle response time m / (drag coefficient) = ", found.response,
                         " s; use fewer DEM steps per fluid step");
        fluid_.check(found, dt);
        if (predicted) sim.drift_checked(found.next_drift);
        if (x_before_.size() != p.n) x_before_ = buffer<vec4<Real>, Policy>(p.n);
        for_each_index(Policy{}, p.n, detail::positions_by_user<Real>{p, x_before_.data()});
        sim.run(options_.dem_steps);
        transform_reduce_into(
            fluid_.context(), p.n,
            detail::fluid_work_on_particle<Real>{sim.config().box, x_before_.data(), sim.particle_data(), forces}, 0.0,
            plus_op{}, &report->work_step);
        for_each_index(Policy{}, 1, detail::add_work<Real>{report});
    }

    /// Work done by the fluid on the free particles so far (J): the sum over coupled steps of
    /// each particle's fluid force times its displacement in that step (exact for forces held
    /// constant over the step). With it the particles' energy budget closes:
    /// sim.energy().total() - its initial value = work_on_particles(). The sum is kept on the
    /// device: this reads it back.
    double work_on_particles()
    {
        detail::fluid_report<Real> r;
        fluid_.context().read_back(&r, fluid_.report(), 1, "the coupling's work on the particles", 0);
        return r.work_total;
    }

private:
    coupling_options options_;
    porosity_estimator<Real, Policy> porosity_;
    navier_stokes<Real, Policy, Poisson> fluid_;
    buffer<vec4<Real>, Policy> x_before_;  ///< positions at the start of the DEM steps, by user index
    buffer<Real, Policy> response_;        ///< each particle's response time to the drag (s)
};

} // namespace sphere
