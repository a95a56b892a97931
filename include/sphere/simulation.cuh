#pragma once
/// \file
/// `simulation`: composes particles, the neighbour grid, the contact lists, a contact law and
/// an integrator into sphere's DEM step, with observers and diagnostics.
#include <cmath>
#include <algorithm>
#include <cstddef>
#include <functional>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include "bonds/bond_forces.cuh"
#include "bonds/bond_set.cuh"
#include "bonds/bond_table.cuh"
#include "boundary/wall_control.cuh"
#include "boundary/walls.cuh"
#include "contact/contact_lists.cuh"
#include "contact/energy.cuh"
#include "contact/evaluate.cuh"
#include "contact/interact.cuh"
#include "contact/linear.cuh"
#include "core/error.cuh"
#include "exec/algorithms.cuh"
#include "exec/context.cuh"
#include "exec/for_each.cuh"
#include "exec/thread_governor.cuh"
#include "grid/neighbor_grid.cuh"
#include "integrate/integrate_particles.cuh"
#include "integrate/integrators.cuh"
#include "integrate/time_step.cuh"
#include "particles/state.cuh"
#include "particles/validate.cuh"
#include "settings.cuh"

namespace sphere {

namespace detail {
/// The power (W) of the agent that keeps prescribed particle i on its course, after
/// integration. The agent cancels whatever the contacts, the bonds and gravity would change:
/// its force is m a - f - m g and its torque -t (f and t of the contacts and bonds; a = 0 for
/// motion::prescribed, a = f_z / m along z for motion::prescribed_horizontal), and its power is
/// their product with the velocities at the positions' time (docs/physics.md, "Driven
/// particles").
template <class P>
struct drive_power {
    using Real = real_t<P>;
    particle_view<P> p;
    vec3<Real> gravity;
    const vec3<Real>* loads = nullptr;       ///< with bonds: their loads plus the external force
    const vec3<Real>* load_torques = nullptr; ///< with bonds: their torques
    const vec3<Real>* external = nullptr;    ///< the external forces in `loads` (not the agent's to cancel), or null
    SPHERE_HD double operator()(std::size_t i) const
    {
        const auto kind = static_cast<motion>(p.kind[i]);
        if (kind != motion::prescribed && kind != motion::prescribed_horizontal) return 0;
        vec3<Real> force = p.force[i], torque = p.torque[i];
        if (loads) {
            force += loads[i] - (external ? external[i] : vec3<Real>{0, 0, 0});
            torque += load_torques[i];
        }
        vec3<Real> agent = -(force + gravity * p.mass[i]);
        if (kind == motion::prescribed_horizontal) agent.z = -gravity.z * p.mass[i];
        return double(dot(agent, p.v_sync[i])) - double(dot(torque, p.omega_sync[i]));
    }
};

/// A particle kernel run by rank: index r runs `body` on the particle of rank r (the order of
/// the contact lists, contact/contact_lists.cuh), so that a reduction over it sums in the same
/// order whatever the storage order.
template <class Body, class Real>
struct by_rank {
    Body body;
    contact_view<Real> c;
    SPHERE_HDI auto operator()(std::size_t r) const { return body(c.slot(r)); }
};

/// What follows the pair sums on the host's slab schedule, for the particles of a block of
/// ranks, on the thread that summed most of their pairs and in the same parallel region
/// (contact/interact.cuh, sum_by_slabs): their wall contacts (each wall particle's loads into
/// `loads`, by its index in contact_lists::wall_ranks, for an ordered sum afterwards), then
/// `body` (the integration) and the particle check `Check` (check_particle, or
/// check_after_drift for an integrator that drifts first; the thread's largest result into
/// moved[thread]).
template <class P, class Walls, class Body, class Check>
struct finish_block {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    Walls walls;
    Body body;
    Check check;
    contact_view<Real> c;
    const unsigned* wall_ranks; ///< host memory
    std::size_t wall_count;
    wall_loads* loads;
    Coord* moved;
    const unsigned* halt; ///< `body` is not run when *halt (see unless_halted)

    void operator()(unsigned first, unsigned end, int thread) const
    {
        const unsigned* lo = std::lower_bound(wall_ranks, wall_ranks + wall_count, first);
        const unsigned* hi = std::lower_bound(lo, wall_ranks + wall_count, end);
        for (const unsigned* k = lo; k < hi; ++k) loads[k - wall_ranks] = walls(std::size_t(k - wall_ranks));
        Coord most = 0;
        if (*halt) end = first;
        for (unsigned begin = first; begin < end; begin += unsigned(host_chunk)) {
            const unsigned stop = end - begin > host_chunk ? begin + unsigned(host_chunk) : end;
            by_rank<then_check<Body, Check>, Real> f{{body, check}, c};
            Coord values[host_chunk];
            SPHERE_VECTORISE_LOOP
            for (unsigned r = begin; r < stop; ++r) values[r - begin] = f(r);
            for (unsigned r = begin; r < stop; ++r) most = max_op{}(most, values[r - begin]);
        }
        moved[thread] = most;
    }
};

/// The deepest overlap of particle pairs at setup, as a fraction of the smaller radius
/// (coincident centres count as +infinity), and the user indices of its pair (the smallest
/// pair among equal fractions, so the result does not depend on the order of the reduction).
struct deepest_overlap {
    static constexpr double coincident = 1e300; ///< the fraction of coincident centres
    double fraction;
    unsigned i, j;
    SPHERE_HD bool before(const deepest_overlap& o) const
    {
        if (fraction != o.fraction) return fraction > o.fraction;
        return i != o.i ? i < o.i : j < o.j;
    }
};
struct deepest_overlap_op {
    SPHERE_HD deepest_overlap operator()(const deepest_overlap& a, const deepest_overlap& b) const
    {
        return a.before(b) ? a : b;
    }
};

/// The deepest overlap among the pairs of rank r's row in the contact lists.
template <class P>
struct row_overlap {
    using Coord = coord_t<P>;
    particle_view<P> p;
    contact_view<real_t<P>> c;
    world<Coord> box;
    SPHERE_HD deepest_overlap operator()(std::size_t r) const
    {
        const std::size_t i = c.slot(r);
        const vec4<Coord> xi = p.x[i];
        const double coincident = deepest_overlap::coincident;
        deepest_overlap out{0, ~0u, ~0u};
        c.for_each_pair(r, [&](unsigned, unsigned j) {
            const vec4<Coord> xj = p.x[j];
            const vec3<Coord> d = box.nearest_image_inside(xi.xyz() - xj.xyz());
            const double dist = std::sqrt(double(norm2(d))), smaller = double(xi.w < xj.w ? xi.w : xj.w);
            const double fraction = dist == 0 ? coincident : (double(xi.w) + double(xj.w) - dist) / smaller;
            const unsigned ui = p.user[i], uj = p.user[j];
            const deepest_overlap here{fraction, ui < uj ? ui : uj, ui < uj ? uj : ui};
            if (here.before(out)) out = here;
        });
        return out;
    }
};

/// What the host reads back at the end of a step, in one copy (docs/architecture.md,
/// *Execution context*): the particles' loads on the walls (N), the particle check's largest
/// squared displacement since the last rebuild (m^2, +infinity when a particle failed it), the
/// power of whatever drives the prescribed particles (W) and the totals of the step's rebuild
/// (those of the last one in a step without).
template <class Coord>
struct step_report {
    wall_loads loads;
    Coord moved2;
    double drive_power;
    list_totals lists;
};

/// Runs `body` unless *halt: a rebuild in this step overflowed the lists' capacities, and the
/// step runs again once they have grown, so nothing that lasts may change. A body that
/// returns a value returns zero instead.
template <class Body>
struct unless_halted {
    Body body;
    const unsigned* halt;
    SPHERE_HDI auto operator()(std::size_t i) const
    {
        using R = decltype(body(i));
        if constexpr (std::is_void_v<R>) {
            if (!*halt) body(i);
        } else {
            return *halt ? R(0) : body(i);
        }
    }
};

/// Runs two particle kernels on particle i, one after the other.
template <class First, class Second>
struct both {
    First first;
    Second second;
    SPHERE_HDI void operator()(std::size_t i) const
    {
        first(i);
        second(i);
    }
};

template <class P>
struct set_kinematics {
    using Real = real_t<P>;
    particle_view<P> p;
    std::size_t index; ///< storage slot
    vec3<Real> v, omega;
    SPHERE_HD void operator()(std::size_t) const
    {
        p.v[index] = v;
        p.omega[index] = omega;
        p.v_sync[index] = v;
        p.omega_sync[index] = omega;
    }
};
} // namespace detail

/// Everything of a simulation that evolves in time (the settings and the time step stay).
template <class Real>
struct simulation_state {
    particle_snapshot<Real> particles;  ///< in user order
    contact_table<Real> contacts;        ///< the contact lists and their history (forces left out)
    bond_table<Real> bonds;              ///< the bonds and their state
    /// the reference positions (xyz; docs/architecture.md, *Reference positions*) and the radii
    /// (w) of the last rebuild, in user order
    std::vector<vec4<Real>> x_at_build;
    std::vector<unsigned> storage;       ///< the user index of each storage slot (the storage order)
    wall_set<Real> walls;
    wall_set<Real> walls_at_build; ///< the walls when the lists were built
    double drive_work = 0; ///< work done on the prescribed particles so far (J)
    std::size_t steps = 0, rebuilds = 0;
    bool needs_rebuild = false;
};

/// A DEM simulation of spheres.
///
/// \tparam Precision  float, double or sphere::mixed (core/precision.cuh): every value the
///                    simulation takes and hands out (settings, particles, snapshots, energies)
///                    is a real_type = coord_t<Precision>; with mixed, positions and walls are
///                    double and the particles' other fields and the contact laws float
/// \tparam Policy     sphere::host or sphere::cuda
/// \tparam Law        contact law policy, e.g. contact::linear<tangential::visco_frictional>
/// \tparam Integrator integrate::semi_implicit_euler (default), velocity_verlet, taylor2 or
///                    explicit_euler
///
/// One step: rebuild the grid and contact lists when some particle has moved more than half
/// the skin since the last rebuild (every step with skin 0), permuting the particles into the
/// grid's cell order; every particle gathers contact forces; integrate; check every particle (a
/// non-finite value or a particle outside the world on a wall axis stops the run with a
/// sphere::error naming the step and the particle's user index); advance time; call the
/// observers that are due. Velocity Verlet drifts the particles first; its check at the end of
/// a step is of the positions the next drift gives (docs/architecture.md, "One step"). A step
/// reads back from the device once (twice when its rebuild outgrows the contact lists, which
/// then grow, after the host changed what velocity Verlet's drift reads, and with velocity
/// Verlet on the host's slab schedule, where a read-back is a copy in memory).
template <class Precision, class Policy = host, class Law = contact::linear<>,
          class Integrator = integrate::semi_implicit_euler>
class simulation {
    using Real = real_t<Precision>;  ///< particle fields other than positions, contact laws
    using Coord = coord_t<Precision>; ///< positions, walls, the world, user-facing values
    using kernel_params = typename Law::template kernel_params<Real>;

public:
    using precision_type = Precision;
    using real_type = Coord;
    using policy_type = Policy;
    using law_type = Law;
    using settings_type = settings<Coord, typename Law::template params<Coord>>;
    using observer = std::function<void(const simulation&)>;

    /// Validates everything and builds the first contact lists; throws sphere::error on bad input.
    /// `bonds` joins pairs of particles (user indices) with parallel bonds of settings.bond at
    /// their distance now (docs/physics.md, "Bonds"); their springs enter the time step.
    simulation(const settings_type& s, std::vector<particle<Coord>> particles, const std::vector<bond>& bonds = {})
        : settings_(s), gravity_(vec_cast<Real>(s.gravity))
    {
        validate_world(s.box);
        Law::validate(s.contact, s.wall);
        pair_params_ = Law::template pair_kernel<Real>(s.contact);
        wall_params_ = Law::template wall_kernel<Real>(s.contact, s.wall);
        range_ = law_range<Law, Coord>(pair_params_);
        if (!isfinite(s.gravity))
            detail::fail("settings.gravity (", s.gravity.x, ", ", s.gravity.y, ", ", s.gravity.z, ") m/s^2 is not finite");
        if (!(s.skin >= 0) || !std::isfinite(s.skin))
            detail::fail("settings.skin = ", s.skin, " m: must be non-negative and finite");
        if (!(s.max_initial_overlap >= 0))
            detail::fail("settings.max_initial_overlap = ", s.max_initial_overlap,
                         ": must be non-negative (a fraction of the smaller radius; infinity accepts any overlap)");
        if (!(s.cell_size >= 0) || !std::isfinite(s.cell_size))
            detail::fail("settings.cell_size = ", s.cell_size, " m: must be non-negative and finite (0 = automatic)");
        validate_wall_controls(s.walls, s.box);
        if (particles.empty()) detail::fail("no particles: a simulation needs at least one");
        validate_particles(particles, s.box);
        for (std::size_t i = 0; i < particles.size(); ++i) check_material(i, particles[i].material, "");
        check_fits_real(s);
        validate_bond_params(s.bond);
        bond_params_ = params_cast<Real>(s.bond);

        Coord max_radius = 0;
        for (std::size_t i = 0; i < particles.size(); ++i) {
            particle<Coord>& p = particles[i];
            for (int a = 0; a < 3; ++a) p.position[a] = s.box.wrap(p.position[a], a);
            if constexpr (!std::is_same_v<Real, Coord>) {
                fits_real(sphere_mass(p.radius, p.density), " kg", "particle ", i, ": mass (radius ", p.radius, " m, density ", p.density, " kg/m^3)");
                for (int a = 0; a < 3; ++a) {
                    fits_real(p.velocity[a], " m/s", "particle ", i, ": velocity[", a, "]");
                    fits_real(p.angular_velocity[a], " rad/s", "particle ", i, ": angular_velocity[", a, "]");
                }
            }
            refuse_unrepresentable_mass(i, p); // after fits_real, whose message names what overflows
            max_radius = p.radius > max_radius ? p.radius : max_radius;
            for (int a = 0; a < 3; ++a) { // overlaps with the walls
                if (s.box.periodic(a)) continue;
                for (const bool hi : {false, true}) {
                    const double gap = hi ? double(s.box.hi[a]) - double(p.position[a]) : double(p.position[a]) - double(s.box.lo[a]);
                    const double fraction = (double(p.radius) - gap) / double(p.radius);
                    initial_overlap_ = fraction > initial_overlap_ ? fraction : initial_overlap_;
                    if (fraction > s.max_initial_overlap)
                        detail::fail("particle ", i, " (radius ", p.radius, " m) starts overlapping wall face ", 2 * a + hi,
                                     " by ", fraction, " of its radius, more than settings.max_initial_overlap = ",
                                     s.max_initial_overlap, " (raise it to accept)");
                }
            }
        }
        largest_radius_ = max_radius;
        const bond_table<Coord> bonded = new_bonds(particles, {}, bonds, "");
        const time_scale_minimum<Coord> scale = smallest_time_scale<Law>(s.contact, s.wall, particles);
        const Coord bound = Coord(Law::time_step.bound_factor) * scale.scale;
        const time_scale_minimum<Coord> bond_scale = smallest_bond_time_scale(particles, bonded);
        if (s.dt == Coord(0)) {
            dt_ = Coord(Law::time_step.default_factor) * scale.scale;
            dt_ = std::min(dt_, Coord(bond_time_step::default_factor) * bond_scale.scale);
        } else if (!(s.dt > 0) || !std::isfinite(s.dt)) {
            detail::fail("settings.dt = ", s.dt, " s: must be positive and finite (0 = automatic)");
        } else if (s.dt > bound) {
            const particle<Coord>& p = particles[scale.particle];
            detail::fail("settings.dt = ", s.dt, " s exceeds the stable bound ", Law::time_step.bound_formula(), " = ", bound, " s of the contact law ", Law::name(), " (smallest at particle ",
                         scale.particle, ": ",
                         Law::time_scale_inputs(s.contact, s.wall, sphere_mass(p.radius, p.density), p.radius), ")");
        } else {
            dt_ = s.dt;
            refuse_bond_step(dt_, bond_scale, bonded, "settings.dt = ");
        }
        dt_ = Coord(Real(dt_)); // the kernels step velocities with dt in Real: one dt throughout
        if (!(dt_ >= Coord(smallest_time_step)))
            detail::fail("the time step ", dt_, " s is below 1e-15 s: a second of simulated time ",
                         "would take more than 1e15 steps; check the smallest radius and density (",
                         s.dt == Coord(0) ? "dt follows from them and the stiffness" : "and settings.dt", ")");
        for (int a = 0; a < 3; ++a) {
            const double reach = std::max(std::fabs(double(s.box.lo[a])), std::fabs(double(s.box.hi[a])));
            drift_margin_ = std::max(drift_margin_, 16 * double(std::numeric_limits<Coord>::epsilon()) * reach);
        }

        particles_ = particle_state<Precision, Policy>(particles, Integrator::distinct_synchronous_velocity,
                                                       s.energy_audit, s.angular_position,
                                                       s.accumulated_displacement);
        for (const particle<Coord>& p : particles) {
            kinds_.push_back(p.kind);
            if (p.kind == motion::prescribed || p.kind == motion::prescribed_horizontal) drive_ = true;
        }
        all_free_ = every_particle_free();
        const std::size_t n = particles.size();
        std::vector<particle<Coord>>().swap(particles); // copied: its memory is not held through the first build
        walls_ = wall_set<Coord>::from_world(s.box);
        lattice_ = position_lattice<Coord>::over(s.box);
        grid_ = neighbor_grid<Coord, Policy>(grid_geometry<Coord>::make(s.box, 2 * max_radius + s.skin + range_, s.cell_size));
        lists_ = contact_lists<Precision, Policy>(n, s.contact_forces, law_history_shape<Law>::value);
        summation_ = interaction<Precision, Policy>::resolve(s.pair_summation);
        x_at_build_.resize(n);
        report_.resize(1);
        const stream_scope<Policy> on_stream(context_);
        // The first build learns the lists' sizes and takes no more memory than they need (a
        // static bed never grows); later overflows grow the lists a quarter above their need.
        detail::step_report<Coord>* report = report_.data();
        for (list_totals t{};;) {
            rebuild_lists(&report->lists);
            context_.read_back(&t, &report->lists, 1, "the contact lists' totals", 0);
            if (settle_rebuild(t, false)) break;
        }
        refuse_initial_overlaps(s);
        set_bonds(bonded);
        // An integrator that kicks before the forces needs the forces of the start.
        if (Integrator::drifts_before_forces)
            settings_.contact_forces ? initial_forces<true>() : initial_forces<false>();
    }

    /// One DEM step of length dt().
    void step()
    {
        const stream_scope<Policy> on_stream(context_);
        governor_.step();
        if (external_.size() || bonds_.size()) step_with<true>();
        else step_with<false>();
    }

    /// Runs `count` steps.
    void run(std::size_t count)
    {
        for (std::size_t k = 0; k < count; ++k) step();
    }

    /// Calls `f(*this)` after every `every`-th step.
    void add_observer(std::size_t every, observer f)
    {
        if (every == 0) detail::fail("observer interval 0: must be at least 1 step");
        observers_.emplace_back(every, std::move(f));
    }

    /// Sets the velocity (m/s) and angular velocity (rad/s) of particle i; a prescribed
    /// particle keeps them until set again. Throws for a fixed particle or non-finite values.
    void set_velocity(std::size_t i, const vec3<Coord>& v, const vec3<Coord>& omega)
    {
        if (i >= size()) detail::fail("set_velocity: particle index ", i, " out of range (", size(), " particles)");
        if (kinds_[i] == motion::fixed)
            detail::fail("set_velocity: particle ", i, " is fixed and cannot move; give it motion::prescribed instead");
        if (!isfinite(v) || !isfinite(omega))
            detail::fail("set_velocity: particle ", i, ": velocity (", v.x, ", ", v.y, ", ", v.z,
                         ") m/s or angular velocity (", omega.x, ", ", omega.y, ", ", omega.z, ") rad/s is not finite");
        const std::vector<unsigned> user = particles_.user_indices();
        const std::size_t slot = static_cast<std::size_t>(std::find(user.begin(), user.end(), unsigned(i)) - user.begin());
        const stream_scope<Policy> on_stream(context_);
        for_each_index(Policy{}, 1,
                       detail::set_kinematics<Precision>{particles_.view(), slot, vec_cast<Real>(v), vec_cast<Real>(omega)});
        drift_checked_ = false;
    }

    /// Changes how wall face f moves from the next step on (e.g. from consolidation at a
    /// stress to a fixed wall); validated like settings.walls.
    void set_wall_control(int f, const wall_control<Coord>& control)
    {
        if (f < 0 || f >= wall_set<Coord>::count) detail::fail("set_wall_control: face ", f, " out of range [0, 6)");
        wall_control<Coord> controls[wall_set<Coord>::count];
        for (int k = 0; k < wall_set<Coord>::count; ++k) controls[k] = k == f ? control : settings_.walls[k];
        validate_wall_controls(controls, settings_.box);
        settings_.walls[f] = control;
    }

    /// Moves wall face f (an active one) to `position` (m along its axis) and stops it there,
    /// e.g. down onto a deposited sample before it is loaded. Throws when the face is periodic,
    /// the position lies outside the world or beyond the opposite wall, or some particle's
    /// centre would be outside the wall.
    void set_wall_position(int f, double position)
    {
        if (f < 0 || f >= wall_set<Coord>::count) detail::fail("set_wall_position: face ", f, " out of range [0, 6)");
        const int a = f / 2;
        if (!walls_.face[f].active)
            detail::fail("set_wall_position: axis ", a, " is periodic, so face ", f, " has no wall");
        if (!(position >= double(settings_.box.lo[a]) && position <= double(settings_.box.hi[a])))
            detail::fail("set_wall_position: face ", f, " at ", position, " m lies outside the world [",
                         settings_.box.lo[a], ", ", settings_.box.hi[a], "] m on axis ", a);
        const double opposite = walls_.face[f ^ 1].position;
        if (f % 2 == 0 ? !(position < opposite) : !(position > opposite))
            detail::fail("set_wall_position: face ", f, " at ", position, " m would cross the opposite wall at ",
                         opposite, " m");
        const std::vector<vec4<Coord>> at = particles_.positions();
        for (std::size_t i = 0; i < at.size(); ++i) {
            const double x = double(at[i].xyz()[a]);
            if (f % 2 == 0 ? x < position : x > position)
                detail::fail("set_wall_position: particle ", i, " at ", x, " m on axis ", a, " would lie outside face ",
                             f, " at ", position, " m");
        }
        walls_.face[f].position = position;
        walls_.face[f].velocity = 0;
        needs_rebuild_ = true;
    }

    std::size_t size() const { return particles_.size(); }
    Coord dt() const { return dt_; }
    /// The largest particle radius (m), known on the host (the pore-fluid coupling's cell
    /// search reach, read without asking the device).
    Coord largest_radius() const { return largest_radius_; }
    /// Simulated time (s), steps() * dt() in double.
    double time() const { return time_; }
    std::size_t steps() const { return steps_; }
    /// How many times the grid and contact lists were built (including at setup).
    std::size_t rebuilds() const { return rebuilds_; }
    /// How many of this simulation object's steps summed the pair contacts walking only the
    /// lists' near rows (while no particle has moved half the near skin since the last
    /// rebuild, and on the gather schedule not at a step that rebuilds nor at the first after a
    /// restore: docs/architecture.md, *Near partners*). Not in the state.
    std::size_t near_walks() const { return near_walks_; }
    /// How many lists (from one rebuild to the next) gave their far partners histories, for a
    /// step that walked them because some particle had moved a sixteenth of the skin
    /// (docs/architecture.md, *Near partners*); the first time, an allocation. Not in the state.
    std::size_t far_openings() const { return far_openings_; }
    /// The deepest overlap the particles started with, as a fraction of the smaller radius (of
    /// the particle's at a wall); settings.max_initial_overlap bounds it.
    double initial_overlap() const { return initial_overlap_; }

    /// Joins more pairs of particles (user indices) with bonds of settings.bond at their
    /// distance now. Throws sphere::error, and adds none, for a pair that is invalid (see the
    /// constructor) or whose bond needs a shorter time step than dt() (docs/physics.md, "Bonds").
    void add_bonds(const std::vector<bond>& pairs)
    {
        if (pairs.empty()) return;
        const particle_snapshot<Coord> snap = particles_.snapshot();
        std::vector<particle<Coord>> described = snap.descriptions();
        const bond_table<Coord> all = new_bonds(described, bonds_.table(), pairs, "add_bonds: ");
        const time_scale_minimum<Coord> scale = smallest_bond_time_scale(described, all);
        refuse_bond_step(dt_, scale, all, "add_bonds: the time step dt() = ");
        const stream_scope<Policy> on_stream(context_);
        set_bonds(all);
        drift_checked_ = false; // the next drift sees the new bonds' loads
    }

    /// Every bond and its state, in the order of creation (user indices).
    bond_table<Coord> bonds() const { return bonds_.table(); }

    /// How many bonds the simulation has, broken ones included.
    std::size_t bond_count() const { return bonds_.size(); }

    /// How many bonds have broken so far.
    std::size_t broken_bonds() const { return bonds_.broken(); }
    const settings_type& config() const { return settings_; }
    const wall_set<Coord>& walls() const { return walls_; }
    /// Work done on the particles by whatever drives the prescribed ones, so far (J); part of
    /// energy().boundary_work, with the work of the walls.
    double drive_work() const { return drive_work_; }
    const grid_geometry<Coord>& grid() const { return grid_.geometry(); }

    /// A host copy of every particle field, in user order.
    particle_snapshot<Coord> snapshot() const { return particles_.snapshot(); }
    /// A host copy of the positions and radii alone (x, y, z, r in m), in user order: what
    /// snapshot().x holds, an eighth of a full snapshot's bytes in double.
    std::vector<vec4<Coord>> positions() const { return particles_.positions(); }
    /// A host copy of the contact lists, in user order (forces only with settings.contact_forces).
    contact_table<Coord> contacts() const { return lists_.table(particles_.user_indices()); }
    /// Entries in the contact lists (each pair once, and each particle's wall entries).
    std::size_t contact_entries() const { return lists_.entries(); }
    /// Makes room in the contact lists for `entries` entries (as contact_entries() counts them)
    /// and as many carried histories, so that rebuilds up to that size neither allocate nor run
    /// a step twice. Without it the lists grow by themselves (see list_overflows()).
    void reserve_contacts(std::size_t entries)
    {
        if (entries > std::numeric_limits<unsigned>::max())
            detail::fail("reserve_contacts(", entries, "): the contact lists hold at most 4294967295 entries (32-bit "
                         "offsets, as checkpoints store them)");
        lists_.reserve(entries, entries);
    }
    /// How many rebuilds found the lists too small, grew them and ran again (the first build's
    /// included): a step that does so reads back twice and allocates.
    std::size_t list_overflows() const { return lists_.overflows(); }

    /// Kernel view of the particle fields (policy memory, storage order: `user` names each
    /// slot's particle), for couplings that read positions and velocities between steps (the
    /// pore fluid). The storage order changes at rebuilds. Writing through it is undefined.
    particle_view<Precision> particle_data() { return particles_.view(); }

    /// External forces on the particles (N; policy memory, one per particle in storage order, which the
    /// simulation keeps in step with the particles when it reorders them), added
    /// to the contact force of every free particle at each step until overwritten; zero until
    /// written. The pore-fluid coupling writes them (docs/fluid.md, *Coupling*). Their work is
    /// not part of energy().boundary_work (the coupling books it: work_on_particles()).
    vec3<Real>* external_forces()
    {
        drift_checked_ = false; // the caller may write them: the next drift checks its own positions
        if (external_.size() != size()) external_ = buffer<vec3<Real>, Policy>(size(), vec3<Real>{0, 0, 0});
        return external_.data();
    }

    /// For a caller that has just written the external forces and waits for the device before
    /// the next step anyway (the pore-fluid coupling, with its fluid step's report): launches
    /// the check of where the next drift will put the particles (as a step's end does,
    /// detail::check_after_drift) into `out` (policy memory, nothing read back) and returns
    /// true; returns false where the next drift checks itself (an integrator that drifts after
    /// the forces, or the host's slab schedule). Hand the value, read back, to drift_checked(),
    /// and the next drift need not wait for its own check.
    bool predict_drift_into(Coord* out)
    {
        if constexpr (!Integrator::drifts_before_forces) {
            (void)out;
            return false;
        } else {
            if (!predicts_drift()) return false;
            const stream_scope<Policy> on_stream(context_);
            if (bonds_.size() && external_.size()) bond_loads(nullptr); // the external forces just written
            if (external_.size() || bonds_.size())
                predict_drift_with<true>(out);
            else
                predict_drift_with<false>(out);
            return true;
        }
    }

    /// The check of the next drift, with or without external forces (predict_drift_into).
    template <bool External>
    void predict_drift_with(Coord* out)
    {
        const detail::drift_particles<Precision, Integrator, External> drift{
            particles_.view(), settings_.box, gravity_, Real(dt_), External ? external_loads() : nullptr};
        transform_reduce_into(context_, size(), detail::check_after_drift<Precision, Integrator, External>{drift, check()},
                              Coord(0), max_op{}, out);
    }

    /// Takes the check that predict_drift_into wrote, read back (the largest squared
    /// displacement after the next drift): a finite one decides the next rebuild now, and the
    /// drift does not check itself; a bad particle is left for the drift's own check to name.
    void drift_checked(Coord moved2)
    {
        drift_checked_ = std::isfinite(moved2);
        if (drift_checked_) judge(moved2, steps_ + 1, drift_margin_);
    }

    /// Kinetic, rotational, potential and elastic energies and the dissipated energies (J),
    /// summed in rank order (the same bits whatever the storage order).
    energy_budget<Coord> energy() const
    {
        auto& self = const_cast<simulation&>(*this); // views hand out mutable pointers; nothing is written
        const contact_view<Real> c = self.lists_.view();
        const detail::particle_energy<Precision, Law> each{self.particles_.view(), c, settings_.box, walls_,
                                                           pair_params_, wall_params_, settings_.gravity};
        energy_budget<Coord> e = transform_reduce(Policy{}, size(), detail::by_rank<decltype(each), Real>{each, c},
                                                  energy_budget<Coord>{}, plus_op{});
        if (bonds_.size())
            e = e + transform_reduce(Policy{}, bonds_.size(),
                                     detail::bond_energy<Precision>{self.particles_.view(), self.bonds_.view(),
                                                                    settings_.box, bond_params_},
                                     energy_budget<Coord>{}, plus_op{});
        double work = drive_work_;
        for (const wall_face<Coord>& w : walls_.face) work += w.work;
        e.boundary_work = Coord(work);
        return e;
    }

    /// Everything that evolves, for checkpoints: with the same settings, `restore(state())`
    /// continues bit-identically.
    simulation_state<Coord> state() const
    {
        const std::vector<unsigned> user = particles_.user_indices();
        contact_table<Coord> contacts = lists_.table(user);
        contacts.force.clear();
        simulation_state<Coord> st;
        st.particles = particles_.snapshot();
        // the reference positions of the last rebuild with the radii (which it was built with)
        const std::vector<reference_position> slots = x_at_build_.to_host();
        std::vector<vec4<Coord>> x_at_build(slots.size());
        for (std::size_t k = 0; k < slots.size(); ++k) {
            const vec3<Coord> a = lattice_.decode(slots[k]);
            x_at_build[user[k]] = {a.x, a.y, a.z, st.particles.x[user[k]].w};
        }
        st.contacts = std::move(contacts);
        st.bonds = bonds_.table();
        st.x_at_build = std::move(x_at_build);
        st.storage = user;
        st.walls = walls_;
        st.walls_at_build = walls_at_build_;
        st.drive_work = drive_work_;
        st.steps = steps_;
        st.rebuilds = rebuilds_;
        st.needs_rebuild = needs_rebuild_;
        return st;
    }

    /// Continues from a state taken from a simulation with the same settings and particle count,
    /// possibly edited on the host (e.g. particles turned into a shear cell's driven layers by
    /// make_shear_cell: the motion kinds are taken from the state).
    void restore(const simulation_state<Coord>& s)
    {
        if (s.particles.size() != size())
            detail::fail("restore: the state holds ", s.particles.size(), " particles, the simulation ", size());
        const particle_snapshot<Coord>& q = s.particles;
        const char* names[16] = {"v",      "omega",  "v_sync", "omega_sync", "angpos", "force", "torque", "mass",
                                 "pressure", "e_visc", "e_fric", "p_visc",     "p_fric", "kind",  "material",
                                 "displacement"};
        const std::size_t counts[16] = {q.v.size(),      q.omega.size(),  q.v_sync.size(), q.omega_sync.size(),
                                        q.angpos.size(), q.force.size(),  q.torque.size(), q.mass.size(),
                                        q.pressure.size(), q.e_visc.size(), q.e_fric.size(), q.p_visc.size(),
                                        q.p_fric.size(), q.kind.size(),   q.material.size(), q.displacement.size()};
        for (int k = 0; k < 16; ++k)
            if (counts[k] != size())
                detail::fail("restore: the state's particles.", names[k], " holds ", counts[k], " values for ", size(),
                             " particles");
        for (std::size_t i = 0; i < size(); ++i)
            if (s.particles.kind[i] > last_motion)
                detail::fail("restore: particle ", i, " has motion kind ", unsigned(s.particles.kind[i]), ", at most ",
                             unsigned(last_motion), " is valid");
        for (std::size_t i = 0; i < size(); ++i) kinds_[i] = static_cast<motion>(s.particles.kind[i]);
        all_free_ = every_particle_free();
        for (std::size_t i = 0; i < size(); ++i) check_material(i, s.particles.material[i], "restore: ");
        if (s.x_at_build.size() != size())
            detail::fail("restore: the state holds ", s.x_at_build.size(), " build positions for ", size(), " particles");
        for (std::size_t i = 0; i < size(); ++i)
            if (static_cast<motion>(s.particles.kind[i]) == motion::prescribed ||
                static_cast<motion>(s.particles.kind[i]) == motion::prescribed_horizontal)
                drive_ = true;
        if (s.storage.size() != size())
            detail::fail("restore: the state's storage order has ", s.storage.size(), " entries for ", size(), " particles");
        std::vector<char> seen(size(), 0);
        for (std::size_t k = 0; k < size(); ++k) {
            if (s.storage[k] >= size() || seen[s.storage[k]])
                detail::fail("restore: the state's storage order is not a permutation (slot ", k, " holds ", s.storage[k], ")");
            seen[s.storage[k]] = 1;
        }
        check_bond_table(s.bonds);
        const stream_scope<Policy> on_stream(context_);
        // The ranks of the last rebuild follow from its positions and the user indices: a grid
        // over those positions, in user order (held for the restore alone). The particles go
        // back into rank order (or stay in user order without settings.reorder), whatever
        // order the state was saved in.
        std::vector<unsigned> identity(size());
        for (std::size_t i = 0; i < size(); ++i) identity[i] = static_cast<unsigned>(i);
        // the state's build positions as reference positions (a state() gives them already,
        // which stay where they are)
        std::vector<reference_position> reference(size());
        std::vector<vec4<Coord>> on_lattice(size());
        for (std::size_t i = 0; i < size(); ++i) {
            reference[i] = reference_in_cell(grid_.geometry(), lattice_, s.x_at_build[i].xyz());
            const vec3<Coord> a = lattice_.decode(reference[i]);
            on_lattice[i] = {a.x, a.y, a.z, s.x_at_build[i].w};
        }
        buffer<vec4<Coord>, Policy> x_build;
        buffer<unsigned, Policy> users;
        x_build.assign(on_lattice);
        users.assign(identity);
        particle_view<Precision> at_build{};
        at_build.n = size();
        at_build.x = x_build.data();
        at_build.user = users.data();
        neighbor_grid<Coord, Policy> grid_at_build(grid_.geometry());
        grid_at_build.build(context_, at_build);
        const grid_view<Coord> g = grid_at_build.view();
        const std::vector<unsigned> before = particles_.user_indices();
        std::vector<unsigned> storage = identity;
        if (settings_.reorder) {
            buffer<unsigned, Policy> ranks(size());
            for_each_index(Policy{}, size(), detail::copy_back<unsigned>{g.order, ranks.data()});
            storage = ranks.to_host();
        }
        particles_.set_storage_order(storage);
        particle_snapshot<Coord> restored = s.particles;
        for (std::size_t i = 0; i < size(); ++i)
            if (kinds_[i] == motion::fixed) // a fixed particle has no velocity (motion::fixed)
                restored.v[i] = restored.omega[i] = restored.v_sync[i] = restored.omega_sync[i] = vec3<Coord>{0, 0, 0};
        particles_.restore(restored);
        largest_radius_ = 0;
        for (const vec4<Coord>& x : restored.x) largest_radius_ = x.w > largest_radius_ ? x.w : largest_radius_;
        lists_.restore(s.contacts, g, near_reach(), !settings_.reorder);
        far_clear_ = false; // the table's other partners may have histories
        moved_ = std::numeric_limits<double>::infinity(); // until the next particle check
        interaction_.lists_changed();
        wall_launch_ = lists_.wall_particles();
        detail::step_report<Coord> fresh{};
        fresh.lists.entries = unsigned(lists_.entries());
        fresh.lists.near_entries = unsigned(lists_.near_entries());
        fresh.lists.wall_particles = unsigned(wall_launch_);
        report_.assign(std::vector<detail::step_report<Coord>>{fresh});
        std::vector<reference_position> slots(size());
        for (std::size_t k = 0; k < size(); ++k) slots[k] = reference[storage[k]];
        x_at_build_.assign(slots);
        if (external_.size()) { // external forces follow their particles into the new slots
            const std::vector<vec3<Real>> old = external_.to_host();
            std::vector<vec3<Real>> by_user(size()), moved(size());
            for (std::size_t k = 0; k < size(); ++k) by_user[before[k]] = old[k];
            for (std::size_t k = 0; k < size(); ++k) moved[k] = by_user[storage[k]];
            external_.assign(moved);
        }
        walls_ = s.walls;
        walls_at_build_ = s.walls_at_build;
        drive_work_ = s.drive_work;
        steps_ = s.steps;
        rebuilds_ = s.rebuilds;
        needs_rebuild_ = s.needs_rebuild;
        time_ = static_cast<double>(steps_) * static_cast<double>(dt_);
        drift_checked_ = false;
        set_bonds(s.bonds, false); // with the loads of their last evaluation
    }

    /// Adds particles during a run (particle insertion): they take the user indices size() to
    /// size() + added.size() - 1, and every other particle, contact history, wall and
    /// observer carries on; the time step stays. Throws sphere::error (naming the added
    /// particle by its new index) for a particle that is invalid, lies outside the world or
    /// beyond a wall, overlaps any particle, or is lighter than the time step allows, and
    /// while external forces (a coupled fluid) act; the simulation is then unchanged. An
    /// insertion builds the simulation's arrays anew: O(N), meant for occasional batches
    /// (setup/insertion.cuh inserts at a rate).
    void insert(const std::vector<particle<Coord>>& added)
    {
        if (added.empty()) return;
        if (external_.size())
            detail::fail("insert: particles cannot be added while external forces act (a coupled fluid sizes them)");
        const std::size_t n = size();
        simulation_state<Coord> st = state();
        std::vector<particle<Coord>> all = st.particles.descriptions();
        all.insert(all.end(), added.begin(), added.end());
        validate_particles(all, settings_.box);
        for (std::size_t k = 0; k < added.size(); ++k) {
            const std::size_t i = n + k;
            const particle<Coord>& a = added[k];
            for (int f = 0; f < wall_set<Coord>::count; ++f) {
                const wall_face<Coord>& w = walls_.face[f];
                const int axis = f / 2;
                const double reach = f % 2 == 0 ? double(a.position[axis]) - w.position : w.position - double(a.position[axis]);
                if (w.active && reach < double(a.radius))
                    detail::fail("insert: particle ", i, " at ", a.position[axis], " m on axis ", axis, " (radius ",
                                 a.radius, " m) crosses wall face ", f, " at ", w.position, " m");
            }
            for (std::size_t j = 0; j < i; ++j) {
                const vec3<Coord> d = settings_.box.nearest_image_inside(a.position - all[j].position);
                const Coord reach = a.radius + all[j].radius;
                if (norm2(d) < reach * reach)
                    detail::fail("insert: particle ", i, " overlaps particle ", j, ": centres ", std::sqrt(double(norm2(d))),
                                 " m apart, radii ", a.radius, " and ", all[j].radius, " m");
            }
        }
        settings_type s = settings_;
        s.dt = dt_;
        s.max_initial_overlap = std::numeric_limits<Coord>::infinity(); // the added ones overlap nothing (above)
        simulation next(s, all);
        particle_snapshot<Coord>& ps = st.particles;
        for (const particle<Coord>& a : added) {
            ps.x.push_back({a.position.x, a.position.y, a.position.z, a.radius});
            ps.v.push_back(a.velocity);
            ps.omega.push_back(a.angular_velocity);
            ps.v_sync.push_back(a.velocity);
            ps.omega_sync.push_back(a.angular_velocity);
            for (auto* field : {&ps.angpos, &ps.force, &ps.torque, &ps.displacement}) field->push_back({0, 0, 0});
            ps.mass.push_back(sphere_mass(a.radius, a.density));
            for (auto* field : {&ps.pressure, &ps.e_visc, &ps.e_fric, &ps.p_visc, &ps.p_fric}) field->push_back(0);
            ps.kind.push_back(static_cast<std::uint8_t>(a.kind));
            ps.material.push_back(a.material);
            st.contacts.offset.push_back(st.contacts.offset.back());
            st.x_at_build.push_back(ps.x.back());
            st.storage.push_back(static_cast<unsigned>(st.storage.size()));
        }
        st.needs_rebuild = true;
        next.restore(st);
        next.observers_ = std::move(observers_);
        *this = std::move(next);
    }

    /// Total linear momentum, sum m v (kg m/s), summed in rank order.
    vec3<Coord> momentum() const
    {
        auto& self = const_cast<simulation&>(*this);
        const detail::particle_momentum<Precision> each{self.particles_.view()};
        return transform_reduce(Policy{}, size(), detail::by_rank<decltype(each), Real>{each, self.lists_.view()},
                                vec3<Coord>{0, 0, 0}, plus_op{});
    }

private:
    /// Hashes the particles into the grid, builds the new lists (carrying the history over by
    /// user index) and permutes every per-particle array into the grid's cell order, without
    /// waiting for the device: the lists' totals go to `totals` (policy memory), and
    /// settle_rebuild() takes them once read back.
    void rebuild_lists(list_totals* totals)
    {
        // The positions of this rebuild place the particles in the grid and decide which
        // partners are listed; their reference positions (x_at_build_, each in its particle's
        // cell: boundary/position_lattice.cuh, reference_in_cell) decide the near partners
        // (docs/architecture.md, *Reference positions*). With settings.reorder both are read in
        // place once they are permuted into rank order, without it the grid gathers them.
        const particle_view<Precision> p = particles_.view();
        for_each_index(Policy{}, p.n,
                       detail::place_references<Coord>{grid_.geometry(), lattice_, p.x, x_at_build_.data()});
        const position_source<Coord> at_build{p.x, x_at_build_.data(), lattice_};
        if (settings_.reorder) {
            grid_.order(context_, p.n, at_build, p.user);
            particles_.permute(grid_.view().order, external_, x_at_build_);
            grid_.sorted(at_build);
            bonds_.locate(p);
        } else {
            grid_.build(context_, p.n, at_build, p.user);
        }
        lists_.rebuild(context_, grid_.view(), walls_, settings_.skin + range_, near_reach(), !settings_.reorder,
                       totals);
        interaction_.lists_changed();
        wall_launch_ = size(); // the wall particles are known once the totals are read back
    }

    /// Takes the totals of rebuild_lists(), read back: true when the lists are complete, false
    /// when they overflowed their capacities, which have now grown, and the particles are back
    /// in their slots, for the rebuild to run again.
    bool settle_rebuild(const list_totals& t, bool headroom = true)
    {
        if (!lists_.settle(t, headroom)) {
            if (settings_.reorder) particles_.unpermute(grid_.view().order, external_, x_at_build_);
            return false;
        }
        wall_launch_ = t.wall_particles;
        walls_at_build_ = walls_;
        moved_ = 0;
        far_clear_ = true;
        ++rebuilds_;
        needs_rebuild_ = false;
        return true;
    }

    /// One step; `External`: the particles have external forces.
    template <bool External>
    void step_with()
    {
        if (settings_.energy_audit)
            settings_.contact_forces ? step_with<External, true, true>() : step_with<External, true, false>();
        else
            settings_.contact_forces ? step_with<External, false, true>() : step_with<External, false, false>();
    }

    /// Whether every particle's motion (kinds_) is motion::free.
    bool every_particle_free() const
    {
        return std::all_of(kinds_.begin(), kinds_.end(), [](motion k) { return k == motion::free; });
    }

    /// One step with the switches of the settings: `Book` the energy audit, `Record` each
    /// contact's force. On the host's slab schedule, a simulation whose particles are all free
    /// and without external forces integrates them without loading their kinds
    /// (detail::kind_of; the same bits). Each such variant of the step is compiled in full, so
    /// only that schedule gets one, and not the steps of the pore fluid and the bonds, which
    /// their own passes dominate.
    template <bool External, bool Book, bool Record>
    void step_with()
    {
        if constexpr (runs_in_blocks<Policy> && !External) {
            if (all_free_ && summation_ == pair_summation::slabs && !drift_checked_)
                return step_with<External, Book, Record, true>();
        }
        step_with<External, Book, Record, false>();
    }

    /// One step (step_with above), `AllFree`: every particle is free, and the schedule is the
    /// slab schedule (the gather schedule's passes are left out). The particle check runs in
    /// the same pass as the motion: after the drift (velocity Verlet) or after the integration.
    template <bool External, bool Book, bool Record, bool AllFree>
    void step_with()
    {
        // Views hold raw pointers into arrays that a rebuild permutes in place (their
        // addresses stay), and external forces are permuted along with the particles.
        const particle_view<Precision> p = particles_.view();
        const std::size_t n = p.n;
        const vec3<Real>* external = External ? external_loads() : nullptr;
        const vec3<Real>* external_torque = External && bonds_.size() ? load_torque_.data() : nullptr;
        constexpr bool drifted = Integrator::drifts_before_forces;
        const detail::integrate_particles<Precision, Integrator, External, AllFree> integrate{
            p, settings_.box, gravity_, Real(dt_), external, external_torque};
        const detail::drift_particles<Precision, Integrator, External, AllFree> drift{
            p, settings_.box, gravity_, Real(dt_), external, external_torque};
        detail::step_report<Coord>* report = report_.data(); // policy memory
        const unsigned* halt = &report->lists.overflow;
        // The drift's loads: the bonds' of the last step with the external forces written since.
        if (drifted && bonds_.size() && external_.size()) bond_loads(nullptr);
        if constexpr (drifted) {
            // The last step's report checked the positions this drift gives (check_after_drift),
            // unless the host has changed something the drift reads since: then the drift
            // checks them itself, and the host waits for that check before deciding on a rebuild.
            if (drift_checked_) { // never in the all-free variant (step_with above)
                if constexpr (!AllFree) for_each_index(Policy{}, n, drift);
            } else {
                transform_reduce_into(context_, n,
                                      detail::drift_and_check<Precision, Integrator, External, AllFree>{drift, check()},
                                      Coord(0), max_op{}, &report->moved2);
                Coord moved2 = 0;
                context_.read_back(&moved2, &report->moved2, 1, "the particle check after the drift", steps_ + 1);
                judge(moved2, steps_ + 1, drift_margin_); // the margin as below: a restart decides alike
            }
            turn(halt);
        }
        // From here the step may run twice: when its rebuild overflows the lists' capacities,
        // nothing that lasts changes (the bodies see *halt), the capacities grow and it runs
        // again, to the same bits as with room from the start.
        const bool rebuild = needs_rebuild_;
        // Whether the lists' other partners are apart now, and whether the pair sums may then
        // walk the near ones alone (their histories are clear: docs/architecture.md).
        const bool apart = rebuild || near_holds();
        const bool near_only = walks_near_only(rebuild);
        detail::step_report<Coord> done{};
        do {
            if (rebuild) rebuild_lists(&report->lists);
            if (bonds_.size()) bond_pass<Book>(halt, true);
            // the check at the end: of where the particles are, or of where the next drift puts them
            const auto finish = [&](const auto& checks) {
                if constexpr (Book) {
                    const detail::both<detail::finish_audit<Precision>, decltype(integrate)> body{{p, Real(dt_)},
                                                                                                   integrate};
                    finish_step<Book, Record, AllFree>(body, checks, report, near_only);
                } else {
                    finish_step<Book, Record, AllFree>(integrate, checks, report, near_only);
                }
            };
            if constexpr (!drifted) {
                finish(check());
            } else if (predicts_drift()) { // never in the all-free variant (slab schedule)
                if constexpr (!AllFree) finish(detail::check_after_drift<Precision, Integrator, External>{drift, check()});
            } else {
                finish(detail::no_check<Coord>{});
            }
            if constexpr (!drifted) turn(halt);
            if (drive_)
                transform_reduce_into(context_, n,
                                      detail::by_rank<detail::drive_power<Precision>, Real>{
                                          {p, gravity_, bonds_.size() ? load_force_.data() : nullptr,
                                           bonds_.size() ? load_torque_.data() : nullptr,
                                           external_.size() ? external_.data() : nullptr},
                                          lists_.view()},
                                      0.0, plus_op{}, &report->drive_power);
            context_.read_back(&done, report, 1,
                               "the step's report (wall loads, particle check, drive power, list totals)", steps_ + 1);
        } while (rebuild && !settle_rebuild(done.lists));
        far_clear_ = apart; // the walk has cleared their histories, or found them touching
        if (interaction_.walked_near()) ++near_walks_;
        advance_walls(walls_, settings_.walls, settings_.box, done.loads.force, time_, dt_, steps_ + 1);
        if (drive_) drive_work_ += done.drive_power * double(dt_);
        ++steps_;
        time_ = static_cast<double>(steps_) * static_cast<double>(dt_);
        if constexpr (drifted) {
            // A bad particle after the next drift is left for that drift's own check to name;
            // a margin covers the rounding by which the drift may differ from the check's
            // copy of it (nvcc may contract them into different FMAs).
            drift_checked_ = predicts_drift() && std::isfinite(done.moved2);
            if (drift_checked_) judge(done.moved2, steps_ + 1, drift_margin_);
        } else {
            judge(done.moved2, steps_);
        }
        for (const auto& o : observers_)
            if (steps_ % o.first == 0) o.second(*this);
    }

    /// The pair sums (`near_only`: the near partners alone, interaction::sum_pairs), the walls,
    /// `body` (the integration after the forces) and the particle check `checks`: in one
    /// parallel region on the host's slab schedule, else pass after pass. Leaves the wall loads
    /// and the check's largest squared displacement in `report` (policy memory). `SlabsOnly`:
    /// the schedule is the slab schedule (the other passes are not compiled).
    template <bool Book, bool Record, bool SlabsOnly, class Body, class Check>
    void finish_step(const Body& body, const Check& checks, detail::step_report<Coord>* report, bool near_only)
    {
        const auto walls = wall_contacts<Book, Record>(true);
        const unsigned* halt = &report->lists.overflow;
        if constexpr (runs_in_blocks<Policy>) { // report is host memory, read in place
            const std::size_t count = report->lists.wall_particles;
            wall_loads_.assign(count, detail::wall_loads{{0, 0, 0, 0, 0, 0}});
            std::vector<Coord> moved(std::size_t(host_threads()), Coord(0));
            const detail::finish_block<Precision, decltype(walls), Body, Check> finish{
                walls, body, checks, lists_.view(), lists_.wall_ranks(), count, wall_loads_.data(), moved.data(), halt};
            if (interaction_.template sum_pairs<Book, Record>(context_, pair_contact(), lists_, summation_, true,
                                                              near_only, finish)) {
                report->loads = detail::wall_loads{{0, 0, 0, 0, 0, 0}};
                for (const detail::wall_loads& l : wall_loads_) report->loads = report->loads + l;
                report->moved2 = 0;
                for (Coord m : moved) report->moved2 = max_op{}(report->moved2, m);
                return;
            }
        } else {
            interaction_.template sum_pairs<Book, Record>(context_, pair_contact(), lists_, summation_, true, near_only);
        }
        if constexpr (!SlabsOnly) {
            transform_reduce_into(context_, wall_launch_, walls, detail::wall_loads{{0, 0, 0, 0, 0, 0}}, plus_op{},
                                  &report->loads);
            checked_into(detail::unless_halted<Body>{body, halt}, checks, &report->moved2);
        }
    }

    /// Whether velocity Verlet's step ends with the check of where its next drift puts the
    /// particles (check_after_drift), to spare the drift's own read-back: on the gather schedule
    /// (CUDA's). On the host's slab schedule a read-back is a copy in memory, and the drift's own
    /// check, in the drift's pass, costs less than a second copy of its arithmetic.
    bool predicts_drift() const { return summation_ == pair_summation::gather; }

    /// Advances the angular positions (settings.angular_position) and the accumulated
    /// displacements (settings.accumulated_displacement) with the velocities the step has just
    /// set, unless *halt (policy memory; detail::unless_halted).
    void turn(const unsigned* halt)
    {
        const particle_view<Precision> p = particles_.view();
        if (p.angpos)
            for_each_index(Policy{}, p.n,
                           detail::unless_halted<detail::turn_particles<Precision>>{{p, Real(dt_)}, halt});
        if (p.displacement)
            for_each_index(Policy{}, p.n,
                           detail::unless_halted<detail::displace_particles<Precision>>{{p, Coord(dt_)}, halt});
    }

    /// The forces of the current positions, leaving the contacts' histories and the energy
    /// audit as they are (for an integrator that needs the forces before its first step).
    template <bool Record>
    void initial_forces()
    {
        const bool near_only = walks_near_only(false);
        interaction_.template sum_pairs<false, Record>(context_, pair_contact(), lists_, summation_, false, near_only);
        transform_reduce_into(context_, wall_launch_, wall_contacts<false, Record>(false),
                              detail::wall_loads{{0, 0, 0, 0, 0, 0}}, plus_op{}, &report_.data()->loads);
    }

    detail::pair_contact<Precision, Law, Integrator::drifts_before_forces> pair_contact()
    {
        return {particles_.view(), settings_.box, pair_params_, Real(dt_), largest_radius_ + range_};
    }

    /// The wall contacts of the particles that have some (one index per wall particle, in rank
    /// order), adding to their forces and returning their loads on the walls.
    template <bool Book, bool Record>
    detail::wall_contacts<Precision, Law, Book, Record, Integrator::drifts_before_forces> wall_contacts(bool update_history)
    {
        return {particles_.view(), lists_.view(), lists_.wall_ranks(), walls_, wall_params_, Real(dt_), update_history};
    }

    /// Runs the particle kernel `body` on every particle and checks each one after it with
    /// `checks`, in one pass (a particle outside the walls, non-finite values, the largest
    /// displacement since the lists were built); leaves the largest squared displacement, +infinity when a
    /// particle failed the check, in `moved2` (policy memory).
    template <class Body, class Check>
    void checked_into(const Body& body, const Check& checks, Coord* moved2)
    {
        transform_reduce_into(context_, particles_.size(), detail::then_check<Body, Check>{body, checks}, Coord(0),
                              max_op{}, moved2);
    }

    detail::check_particle<Precision> check()
    {
        return {particles_.view(), x_at_build_.data(), lattice_, settings_.box, walls_};
    }

    /// Acts on the particle check of step `step` (the largest squared displacement from the
    /// reference positions): a sphere::error naming the step and the particle (the lowest user
    /// index) when one failed it; marks the lists for a rebuild when a particle and a wall may
    /// have come closer than the skin, with each displacement taken `margin` (m) longer, and
    /// longer by the reference positions' rounding (the lists were built from the positions
    /// they round: docs/architecture.md, *Reference positions*).
    void judge(Coord moved2, std::size_t step, double margin = 0)
    {
        if (!std::isfinite(moved2))
            report_bad_particle(transform_reduce(Policy{}, size(), detail::bad_particle<Precision>{check()},
                                                 ~std::size_t(0), min_op{}),
                                step);
        const double moved = std::sqrt(double(moved2)) + margin + double(lattice_.rounding()),
                     skin = double(settings_.skin);
        moved_ = moved;
        bool rebuild = 2 * moved > skin;
        for (int f = 0; f < wall_set<Coord>::count; ++f)
            if (walls_.face[f].active && std::fabs(walls_.face[f].position - walls_at_build_.face[f].position) + moved > skin)
                rebuild = true;
        needs_rebuild_ = needs_rebuild_ || rebuild;
    }

    /// Whether the pair sums of a step (`rebuild`: one that rebuilds the lists first) may walk
    /// the near rows alone: at a rebuild, or while the far partners are apart and without
    /// history. When not, gives the far rows histories (until the next rebuild).
    bool walks_near_only(bool rebuild)
    {
        const bool near_only = rebuild || (near_holds() && far_clear_);
        if (!near_only && lists_.open_far_rows()) ++far_openings_;
        return near_only;
    }

    /// The near skin (m): the lists' near rows hold the partners within r_i + r_j + near skin
    /// (+ the law's range) at the rebuild, an eighth of the skin (docs/architecture.md, *Near
    /// partners*).
    Coord near_skin() const { return settings_.skin / 8; }

    /// What the lists' near rows add to r_a + r_b between reference positions (m): the near
    /// skin, the law's range and twice the reference positions' rounding, so that a pair
    /// within r_a + r_b + near skin + range of the positions of the rebuild is a near pair
    /// (docs/architecture.md, *Reference positions*).
    Coord near_reach() const { return near_skin() + range_ + 2 * lattice_.rounding(); }

    /// Whether the other partners of the lists are still apart: no particle has moved a half
    /// near skin since the rebuild (moved_, from the last particle check), less a margin for the
    /// rounding of the positions and distances the tests compare: 16 units of Coord's last
    /// place of the largest coordinate (drift_margin_; the walls stay inside the box) for each
    /// of the three axes, and of the largest diameter and skin.
    bool near_holds() const
    {
        const double margin = 3 * drift_margin_ + 16 * double(std::numeric_limits<Coord>::epsilon()) *
                                                      (2 * double(largest_radius_) + double(settings_.skin));
        return 2 * moved_ + margin < double(near_skin());
    }

    /// Refuses a value that the particle fields and contact laws cannot hold in Real when Real
    /// is narrower than the user's type (precision mixed): it overflows float, or a non-zero
    /// value rounds to zero. `where...` names it.
    template <class... Where>
    static void fits_real(Coord value, const char* unit, const Where&... where)
    {
        const Real narrowed = Real(value);
        if (!std::isfinite(narrowed) || (value != Coord(0) && narrowed == Real(0)))
            detail::fail(where..., " = ", value, unit,
                         " does not fit in float, the precision of the particle fields and contact laws of "
                         "sphere::mixed (magnitudes from 1.2e-38 to 3.4e38)");
    }

    /// fits_real for every contact parameter and gravity (precision mixed).
    static void check_fits_real(const settings_type& s)
    {
        if constexpr (!std::is_same_v<Real, Coord>) {
            using params = typename Law::template params<Coord>;
            for (const auto& given : {std::pair{&s.contact, "settings.contact"}, std::pair{&s.wall, "settings.wall"}})
                params::fields(*given.first, [&, where = given.second](const char* name, const auto& value, const char* unit) {
                    if constexpr (std::is_floating_point_v<std::decay_t<decltype(value)>>)
                        fits_real(value, (*unit ? std::string(" ") + unit : std::string()).c_str(), where, ".", name);
                });
            for (int a = 0; a < 3; ++a) fits_real(s.gravity[a], " m/s^2", "settings.gravity[", a, "]");
            bond_params<Coord>::fields(s.bond, [&](const char* name, Coord value, const char* unit) {
                if (std::isfinite(value)) // an infinite strength is a strength never reached
                    fits_real(value, (*unit ? std::string(" ") + unit : std::string()).c_str(), "settings.bond.", name);
            });
        }
    }

    /// Refuses a material index that the contact law does not have (`before` prefixes the message).
    static void check_material(std::size_t i, unsigned material, const char* before)
    {
        constexpr unsigned count = law_material_count<Law>::value;
        if (material >= count)
            detail::fail(before, "particle ", i, ": material = ", material, ", but the contact law ", Law::name(),
                         " has materials 0 to ", count - 1, count == 1 ? " (contact::materials<Law, Count> has more)" : "");
    }

    /// The smallest time step a simulation accepts (s): below it a second of simulated time
    /// takes more than 1e15 steps (docs/physics.md, "Time step").
    static constexpr double smallest_time_step = 1e-15;

    /// Refuses particle i (a user index) when its mass or moment of inertia is not a normal
    /// number in the type the kernels compute in (zero, subnormal or infinite: a radius of
    /// 1e-30 m, a density of 1e300 kg/m^3 in float).
    static void refuse_unrepresentable_mass(std::size_t i, const particle<Coord>& p)
    {
        const double m = double(sphere_mass(p.radius, p.density));
        const double inertia = 0.4 * m * double(p.radius) * double(p.radius);
        const Real m_real = Real(m), inertia_real = Real(inertia);
        if (!std::isnormal(m_real) || !std::isnormal(inertia_real))
            detail::fail("particle ", i, ": radius ", p.radius, " m and density ", p.density, " kg/m^3 give a mass of ", m,
                         " kg and a moment of inertia of ", inertia, " kg m^2, which ",
                         sizeof(Real) == 4 ? "float" : "double", " cannot hold as normal numbers");
    }

    /// Finds the deepest initial overlap of a pair (in the first lists, which hold every pair
    /// within reach) and of a particle with a wall, and refuses coincident centres and any
    /// overlap deeper than s.max_initial_overlap (docs/physics.md, "Initial overlaps").
    void refuse_initial_overlaps(const settings_type& s)
    {
        auto& self = *this;
        const detail::deepest_overlap pairs = transform_reduce(
            Policy{}, size(), detail::row_overlap<Precision>{self.particles_.view(), self.lists_.view(), s.box},
            detail::deepest_overlap{0, ~0u, ~0u}, detail::deepest_overlap_op{});
        if (pairs.fraction >= detail::deepest_overlap::coincident)
            detail::fail("particles ", pairs.i, " and ", pairs.j, " have the same centre: their contact has no normal");
        initial_overlap_ = pairs.fraction > initial_overlap_ ? pairs.fraction : initial_overlap_;
        if (pairs.fraction > s.max_initial_overlap) {
            const std::vector<vec4<Coord>> at = particles_.positions();
            detail::fail("particles ", pairs.i, " and ", pairs.j, " (radii ", at[pairs.i].w, " and ", at[pairs.j].w,
                         " m) start overlapping by ", pairs.fraction,
                         " of the smaller radius, more than settings.max_initial_overlap = ", s.max_initial_overlap,
                         " (raise it to accept)");
        }
    }

    /// Throws the error for particle i (a user index) at step `step`.
    [[noreturn]] void report_bad_particle(std::size_t i, std::size_t step) const
    {
        const particle_snapshot<Coord> s = particles_.snapshot();
        const vec3<Coord> x = s.position(i), v = s.v_sync[i], w = s.omega_sync[i];
        if (!isfinite(x) || !isfinite(v) || !isfinite(s.omega_sync[i]))
            detail::fail("step ", step, ": particle ", i, " became non-finite (position (", x.x, ", ", x.y, ", ",
                         x.z, ") m, velocity (", v.x, ", ", v.y, ", ", v.z, ") m/s, angular velocity (", w.x, ", ",
                         w.y, ", ", w.z, ") rad/s); reduce the time step");
        detail::fail("step ", step, ": particle ", i, " left the world: position (", x.x, ", ", x.y, ", ", x.z,
                     ") m, world [", settings_.box.lo.x, ", ", settings_.box.hi.x, "] x [", settings_.box.lo.y, ", ",
                     settings_.box.hi.y, "] x [", settings_.box.lo.z, ", ", settings_.box.hi.z,
                     "] m, walls at x [", walls_.face[0].position, ", ", walls_.face[1].position, "], y [",
                     walls_.face[2].position, ", ", walls_.face[3].position, "], z [", walls_.face[4].position, ", ",
                     walls_.face[5].position, "] m");
    }

    /// The bonds of `existing` and of `pairs` (user indices into `particles`, whose positions
    /// and radii give the rest lengths): refuses an index out of range, a particle bonded to
    /// itself, a pair bonded twice, centres farther apart than twice the sum of radii, and
    /// bonds without a normal stiffness; `before` prefixes the message.
    bond_table<Coord> new_bonds(const std::vector<particle<Coord>>& particles, bond_table<Coord> existing,
                                const std::vector<bond>& pairs, const char* before) const
    {
        if (pairs.empty()) return existing;
        if (!(settings_.bond.k_n > 0))
            detail::fail(before, "settings.bond.k_n = ", settings_.bond.k_n, " Pa/m: bonds need a positive normal stiffness");
        std::vector<std::pair<unsigned, unsigned>> known;
        for (std::size_t k = 0; k < existing.size(); ++k)
            known.emplace_back(std::min(existing.i[k], existing.j[k]), std::max(existing.i[k], existing.j[k]));
        std::sort(known.begin(), known.end());
        for (std::size_t k = 0; k < pairs.size(); ++k) {
            const bond b = pairs[k];
            if (b.i >= particles.size() || b.j >= particles.size())
                detail::fail(before, "bond ", k, " joins particles ", b.i, " and ", b.j, ", but there are ",
                             particles.size(), " particles");
            if (b.i == b.j) detail::fail(before, "bond ", k, " joins particle ", b.i, " to itself");
            const std::pair<unsigned, unsigned> key{unsigned(std::min(b.i, b.j)), unsigned(std::max(b.i, b.j))};
            const auto at = std::lower_bound(known.begin(), known.end(), key);
            if (at != known.end() && *at == key)
                detail::fail(before, "bond ", k, ": particles ", b.i, " and ", b.j, " are bonded already");
            known.insert(at, key);
            const particle<Coord>& a = particles[b.i];
            const particle<Coord>& c = particles[b.j];
            const Coord length = std::sqrt(norm2(settings_.box.nearest_image_inside(a.position - c.position)));
            if (!(length <= 2 * (a.radius + c.radius)))
                detail::fail(before, "bond ", k, ": particles ", b.i, " and ", b.j, " are ", length,
                             " m apart, more than twice the sum of their radii (", a.radius + c.radius,
                             " m): bonds join neighbours");
            existing.add(unsigned(b.i), unsigned(b.j), length);
        }
        return existing;
    }

    /// The smallest bond time scale (bond_springs::time_scale) over the bonds of t, with the
    /// bond's index in `particle` (0 and +infinity without bonds).
    time_scale_minimum<Coord> smallest_bond_time_scale(const std::vector<particle<Coord>>& particles,
                                                       const bond_table<Coord>& t) const
    {
        time_scale_minimum<Coord> out{infinity<Coord>, 0};
        for (std::size_t k = 0; k < t.size(); ++k) {
            const particle<Coord>& a = particles[t.i[k]];
            const particle<Coord>& b = particles[t.j[k]];
            const Coord scale = bond_springs<Coord>::time_scale(settings_.bond, a.radius, b.radius,
                                                                sphere_mass(a.radius, a.density),
                                                                sphere_mass(b.radius, b.density));
            if (scale < out.scale) out = {scale, k};
        }
        return out;
    }

    /// Refuses a time step dt above the bonds' bound (bond_time_step) of their smallest time
    /// scale `scale`; `before` names dt.
    static void refuse_bond_step(Coord dt, const time_scale_minimum<Coord>& scale, const bond_table<Coord>& t,
                                 const char* before)
    {
        const Coord bound = Coord(bond_time_step::bound_factor) * scale.scale;
        if (dt > bound)
            detail::fail(before, dt, " s exceeds the stable bound ", bond_time_step::bound_factor, " T_bond = ", bound,
                         " s of bond ", scale.particle, " (particles ", t.i[scale.particle], " and ", t.j[scale.particle],
                         "; T_bond = ", scale.scale, " s from settings.bond's stiffnesses, the radii and masses)");
    }

    /// Refuses a state's bond table whose arrays disagree or whose bonds join particles that
    /// the simulation does not have.
    void check_bond_table(const bond_table<Coord>& t) const
    {
        const std::size_t count = t.size();
        for (std::size_t n : {t.j.size(), t.rest.size(), t.shear.size(), t.bend.size(), t.broken.size(), t.released.size(),
                              t.dissipated.size(), t.force.size(), t.torque_i.size(), t.torque_j.size()})
            if (n != count) detail::fail("restore: the state's bond table has arrays of ", count, " and ", n, " bonds");
        for (std::size_t k = 0; k < count; ++k)
            if (t.i[k] >= size() || t.j[k] >= size() || t.i[k] == t.j[k])
                detail::fail("restore: bond ", k, " joins particles ", t.i[k], " and ", t.j[k], " (", size(),
                             " particles)");
    }

    /// Makes `t` the bonds and sets every particle's bond loads: evaluated now from the state
    /// as it is (`evaluate`), or summed from the loads the table holds (a restore, for the
    /// same bits as the run that saved them).
    void set_bonds(const bond_table<Coord>& t, bool evaluate = true)
    {
        bonds_.assign(t, size(), settings_.energy_audit);
        if (!bonds_.size()) {
            load_force_ = buffer<vec3<Real>, Policy>();
            load_torque_ = buffer<vec3<Real>, Policy>();
            return;
        }
        load_force_.resize(size());
        load_torque_.resize(size());
        bonds_.locate(particles_.view());
        if (evaluate) bond_pass<false>(nullptr, false);
        else bond_loads(nullptr);
    }

    /// Evaluates every bond (`update`: advancing and breaking them, bond_forces) and sums each
    /// particle's bond loads, unless *halt (policy memory; null: run).
    template <bool Book>
    void bond_pass(const unsigned* halt, bool update)
    {
        using forces = detail::bond_forces<Precision, Integrator::drifts_before_forces, Book>;
        const forces f{particles_.view(), bonds_.view(), settings_.box, bond_params_, Real(dt_), update};
        if (halt) for_each_index(Policy{}, bonds_.size(), detail::unless_halted<forces>{f, halt});
        else for_each_index(Policy{}, bonds_.size(), f);
        bond_loads(halt);
    }

    /// Sums each particle's bond loads and external force (bond_loads) from the bonds' last
    /// evaluation, unless *halt (null: run).
    void bond_loads(const unsigned* halt)
    {
        const particle_view<Precision> p = particles_.view();
        const detail::bond_loads<Precision> loads{p, bonds_.view(), external_.size() ? external_.data() : nullptr,
                                                  load_force_.data(), load_torque_.data()};
        if (halt) for_each_index(Policy{}, p.n, detail::unless_halted<detail::bond_loads<Precision>>{loads, halt});
        else for_each_index(Policy{}, p.n, loads);
    }

    /// What the integrator adds to the contact forces: the external forces, with the bonds'
    /// loads when there are bonds.
    const vec3<Real>* external_loads() { return bonds_.size() ? load_force_.data() : external_.data(); }

    settings_type settings_;
    kernel_params pair_params_, wall_params_; ///< what the law's kernels receive for settings_.contact and .wall
    Coord range_ = 0; ///< the largest gap at which the law acts (contact/law.cuh): the lists reach that much further
    vec3<Real> gravity_;                             ///< settings_.gravity in the particles' precision
    Coord dt_ = 0;
    Coord largest_radius_ = 0; ///< largest_radius()
    double time_ = 0;
    double drive_work_ = 0; ///< work done on the prescribed particles so far (J)
    std::size_t steps_ = 0, rebuilds_ = 0;
    bool needs_rebuild_ = true;
    particle_state<Precision, Policy> particles_;
    wall_set<Coord> walls_;
    neighbor_grid<Coord, Policy> grid_;
    contact_lists<Precision, Policy> lists_;
    interaction<Precision, Policy> interaction_;
    pair_summation summation_ = pair_summation::slabs; ///< settings_.pair_summation, resolved for the backend
    using reference_position = typename position_lattice<Coord>::stored;
    position_lattice<Coord> lattice_; ///< of the reference positions, over settings_.box
    /// the reference position of each slot at the last rebuild (boundary/position_lattice.cuh)
    buffer<reference_position, Policy> x_at_build_;
    execution_context<Policy> context_;
    buffer<detail::step_report<Coord>, Policy> report_; ///< one, written by the step's reductions
    wall_set<Coord> walls_at_build_;      ///< the walls when the lists were built
    bool drive_ = false;                  ///< some particle is prescribed: book the drive's work
    buffer<vec3<Real>, Policy> external_; ///< external forces (empty until external_forces() is called)
    double initial_overlap_ = 0;          ///< initial_overlap()
    std::vector<detail::wall_loads> wall_loads_; ///< each wall particle's loads of the step (host)
    std::size_t wall_launch_ = 0; ///< wall contact threads: the wall particles, or all after a rebuild not yet read back
    /// Velocity Verlet: the last step's report holds the check of the positions the next drift
    /// gives (false at the start and after the host changed what the drift reads), and the
    /// margin (m) that covers the rounding between the two (16 ulp of the largest coordinate).
    bool drift_checked_ = false;
    double drift_margin_ = 0;
    double moved_ = 0;           ///< the largest displacement since the last rebuild (m), by the last particle check
    bool far_clear_ = true;      ///< the lists' other partners (not near) have no history
    std::size_t near_walks_ = 0; ///< near_walks()
    std::size_t far_openings_ = 0; ///< far_openings()
    std::vector<motion> kinds_; ///< host copy of each particle's motion (it never changes)
    bool all_free_ = false;     ///< every particle's motion is motion::free
    std::vector<std::pair<std::size_t, observer>> observers_;
    thread_governor governor_; ///< all threads or one, whichever is faster on this machine now
    bond_params<Real> bond_params_; ///< settings_.bond in the particles' precision
    bond_set<Precision, Policy> bonds_;
    buffer<vec3<Real>, Policy> load_force_, load_torque_; ///< with bonds: each slot's bond loads and external force
};

} // namespace sphere
