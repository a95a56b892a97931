#pragma once
/// \file
/// Two-way coupling of the pore fluid and the particles (docs/fluid.md, *Coupling*).
///
/// One coupled step of length dt_f = dem_steps x (DEM time step):
///   1. the porosity estimator bins the particles by fluid cell and computes each cell's
///      porosity, its rate, and the volume-weighted mean particle velocity and diameter;
///   2. every particle gets the fluid force of its cell (the cell holding its centre) from
///      the fluid model (its particle_forces): with navier_stokes
///        f_i = Drag::beta_per_solid(phi, d, |v_f - v_p|) (v_f - v_p) V_i  [ - V_i grad p ]
///      with the cell's porosity phi, fluid velocity v_f, mean particle velocity v_p and mean
///      diameter d (the particle's own velocity and diameter where the cell holds no
///      solid), the bracket the optional pressure-gradient (buoyancy) force; with darcy_flow
///      the Darcy force of darcy.cuh;
///   3. the model takes the reaction (take_reaction): navier_stokes gets the opposite of the
///      sum of its particles' forces, per unit cell volume, so that momentum is exchanged
///      exactly (summed per cell in particle order: deterministic); darcy_flow has no fluid
///      momentum (its pressure carries the exchange);
///   4. the fluid advances by dt_f (its own stability limits checked), then the DEM by
///      dem_steps steps with the forces held constant; the work the forces did on the free
///      particles (force times displacement) is added to work_on_particles().
/// The checks (porosity, response time, stability, the pressure solve) are taken on the device
/// and read back once, with the fluid step's report, before the DEM steps: a coupled step
/// waits for the device once more than its dem_steps DEM steps do (also with velocity Verlet,
/// whose check of its next drift, which the new forces change, comes back with that report).
/// The forces are explicit: dt_f must not exceed the shortest particle response time
/// m_i / (beta_per_solid V_i) (checked; the step throws naming the particle).
#include <cmath>
#include <cstddef>
#include <string>
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
#include "setup.cuh"
#include "snapshot.cuh"

namespace sphere {

namespace detail {

/// T::name() where T has one (the library's drag laws and pressure solvers), else "(other)".
template <class T, class = void>
struct name_or_other {
    static std::string get() { return "(other)"; }
};
template <class T>
struct name_or_other<T, std::void_t<decltype(T::name())>> {
    static std::string get() { return T::name(); }
};

/// values[i] (a reduction's transform over an array).
template <class T>
struct value_at {
    const T* values;
    SPHERE_HDI T operator()(std::size_t i) const { return values[i]; }
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
/// `Poisson` the pressure solver, `Model` the fluid model: navier_stokes (default; `params` a
/// fluid_params) or darcy_flow (`params` a darcy_params; the drag law is not used: the Darcy
/// model's force on the particles is its pressure gradient's, docs/fluid.md, *Darcy model*).
template <class Real, class Policy, class Drag = drag::gidaspow, class Poisson = mg_poisson<Real, Policy>,
          template <class, class, class> class Model = navier_stokes>
class fluid_coupling {
public:
    using model_type = Model<Real, Policy, Poisson>;

    template <class Params>
    fluid_coupling(const fluid_grid<Real>& g, const Params& params, const coupling_options& options = {})
        : options_(options), porosity_(g, options.porosity), fluid_(g, params)
    {
        if (options.dem_steps < 1) detail::fail("coupling: dem_steps = 0; at least one DEM step per fluid step");
        Drag::validate();
    }

    model_type& fluid() { return fluid_; }
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
        fluid_.template particle_forces<Drag>(p, porosity_.view(), forces, response_.data(), options_.pressure_force);
        detail::fluid_report<Real>* report = fluid_.report();
        transform_reduce_into(fluid_.context(), p.n, detail::value_at<Real>{response_.data()}, Real(1e30), min_op{},
                              &report->response);
        fluid_.take_reaction(porosity_.bins(), forces);
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

    /// What this coupling is built from (fluid/setup.cuh).
    coupling_setup<Real> setup() const
    {
        coupling_setup<Real> c;
        c.model = model_type::model_name();
        c.solver = detail::name_or_other<Poisson>::get();
        c.drag = detail::name_or_other<Drag>::get();
        if constexpr (std::is_same_v<std::decay_t<decltype(fluid_.params())>, darcy_params<Real>>) c.params = fluid_.params();
        else c.params.fluid = fluid_.params();
        c.options = options_;
        return c;
    }

    /// A host copy of the coupling's evolving state (fluid/snapshot.cuh; docs/fluid.md,
    /// *Restarting a coupled run*), for write_checkpoint(path, sim, coupling): the fluid
    /// model's snapshot (its entries under their own names, its model name the snapshot's),
    /// the porosity estimator's under "porosity.", the setup() under "setup." (what the
    /// coupling is built from: read by the sphere program, not by restore()), and
    /// work_on_particles() as the number "coupling.work_total". Nothing else carries over from
    /// one coupled step to the next: the particle forces, response times and start positions
    /// are written by each step before they are read.
    fluid_snapshot<Real> snapshot()
    {
        fluid_snapshot<Real> s = fluid_.snapshot();
        s.merge("porosity.", porosity_.snapshot());
        s.merge("setup.", setup().snapshot(porosity_.grid()));
        s.add_number("coupling.work_total", work_on_particles());
        return s;
    }

    /// Continues from a snapshot() of a coupling on the same grid with the same fluid model
    /// (and, the caller's to see to, the same parameters, options and drag law), next to a
    /// simulation restored to the same step (sphere::restart(path, coupling) does both): the
    /// next coupled steps give the bits the snapshotted coupling's gave. Throws sphere::error,
    /// with nothing changed, for a snapshot of another grid, for the reasons of the fluid
    /// model's and the porosity estimator's restore (another model, an entry missing or
    /// unknown, an array of another length, another porosity method) and for a missing or
    /// unknown "coupling." entry.
    void restore(const fluid_snapshot<Real>& s)
    {
        const char* who = "fluid_coupling::restore";
        s.check_grid(who, porosity_.grid());
        const fluid_snapshot<Real> own = s.part("coupling.", "coupling");
        own.check_only(who, {}, {"work_total"}, {});
        const double work = own.number_named(who, "work_total");
        if (!std::isfinite(work)) detail::fail(who, ": the snapshot's work_total = ", work, " J is not finite");
        const fluid_snapshot<Real> por = s.part("porosity.", porosity_.model_name());
        porosity_.check_snapshot(por);
        fluid_.restore(s.other_than({"porosity.", "coupling.", "setup."})); // checks everything before it changes anything
        porosity_.restore(por);
        for_each_index(Policy{}, 1, set_work_total{fluid_.report(), work});
    }

    /// Sets the work total in the fluid's report (restore()).
    struct set_work_total {
        detail::fluid_report<Real>* r;
        double total;
        SPHERE_HD void operator()(std::size_t) const { r->work_total = total; }
    };

private:
    coupling_options options_;
    porosity_estimator<Real, Policy> porosity_;
    model_type fluid_;
    buffer<vec4<Real>, Policy> x_before_;  ///< positions at the start of the DEM steps, by user index
    buffer<Real, Policy> response_;        ///< each particle's response time to the drag (s)
};

} // namespace sphere
