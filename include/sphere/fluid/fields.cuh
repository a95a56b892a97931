#pragma once
/// \file
/// What the two fluid models (navier_stokes.cuh, darcy.cuh) share: the ghost nodes of a
/// cell-centred field, the report a fluid step leaves in the policy's memory and reads back
/// once (docs/fluid.md, *Solves without waiting*), and fluid_model_base, the state and the end
/// of a step that both keep alike.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "../core/config.cuh"
#include "../core/error.cuh"
#include "../exec/buffer.cuh"
#include "../exec/context.cuh"
#include "grid.cuh"
#include "poisson.cuh"
#include "snapshot.cuh"

namespace sphere {
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

/// Whether the step's fields advance: the solve is over, converged, and nothing held.
template <class Real>
struct fluid_commit {
    fluid_report<Real>* r;
    SPHERE_HD void operator()(std::size_t) const
    {
        r->commit = r->solve.finishing && r->solve.converged && r->hold == fluid_advances;
    }
};


/// The part of a fluid model that navier_stokes and darcy_flow keep alike: its pressure
/// solver, its execution context, the step's report (in the policy's memory and the host's
/// copy), the last solve's result, the time and the step count; the end of a step (read the
/// report back, resume an unfinished solve, advance the clock) and their snapshot entries.
template <class Real, class Policy, class Poisson>
class fluid_model_base {
public:
    double time() const { return time_; }
    /// Result of the last pressure solve (iterations, residual).
    const poisson_result& last_solve() const { return last_solve_; }
    /// The execution context (reductions, scratch, read-backs).
    execution_context<Policy>& context() { return context_; }
    /// The step's report in the policy's memory, for a caller that adds its own checks and
    /// sums to it (the coupling: the response time, the work).
    fluid_report<Real>* report() { return report_.data(); }

protected:
    explicit fluid_model_base(const fluid_grid<Real>& g) : poisson_(g), report_(1, initial_report()) {}

    /// The end of a step whose solve was launched: `finish()` launches what follows the solve
    /// (guarded by the report's flags), the report is read back (`what` names it), and while
    /// the solve has not finished it resumes and repeats; a step that advanced moves the clock
    /// by dt. Returns the host's copy of the report.
    template <class Finish>
    const fluid_report<Real>& conclude_step(Real dt, const char* what, Finish finish)
    {
        finish();
        context_.read_back(&host_report_, report_.data(), 1, what, steps_);
        while (!host_report_.solve.finished) {
            poisson_.resume(context_);
            finish();
            context_.read_back(&host_report_, report_.data(), 1, what, steps_);
        }
        if (host_report_.hold == fluid_advances) {
            last_solve_ = poisson_.learn(host_report_.solve);
            if (host_report_.commit) {
                time_ += double(dt);
                ++steps_;
            }
        }
        return host_report_;
    }

    /// Throws unless a porosity estimate's grid has the model's cell counts (`who` begins the
    /// message: "fluid" or "darcy").
    static void check_porosity_grid(const fluid_grid<Real>& porosity, const fluid_grid<Real>& model, const char* who)
    {
        for (int a = 0; a < 3; ++a)
            if (porosity.n[a] != model.n[a])
                fail(who, ": the porosity grid has ", porosity.n[a], " cells along axis ", a, ", the fluid grid ",
                     model.n[a]);
    }

    /// The snapshot entries of this part: the time, the step count and the last solve.
    void add_step_state(fluid_snapshot<Real>& s) const
    {
        s.add_number("time", time_);
        s.add_count("steps", steps_);
        s.add_count("last_solve_iterations", last_solve_.iterations);
        s.add_number("last_solve_residual", last_solve_.residual);
        s.add_count("last_solve_converged", last_solve_.converged ? 1 : 0);
    }
    static std::vector<std::string> step_numbers() { return {"time", "last_solve_residual"}; }
    static std::vector<std::string> step_counts() { return {"steps", "last_solve_iterations", "last_solve_converged"}; }

    /// What add_step_state stored, read and checked (throws naming `who`), to be applied by
    /// apply_step_state once the rest of the snapshot passed its checks too.
    struct step_state {
        double time;
        std::size_t steps;
        poisson_result solve;
    };
    static step_state read_step_state(const fluid_snapshot<Real>& s, const char* who)
    {
        step_state st;
        st.time = s.number_named(who, "time");
        if (!std::isfinite(st.time)) fail(who, ": the snapshot's time = ", st.time, " s is not finite");
        st.steps = std::size_t(s.count_named(who, "steps", std::uint64_t(std::size_t(-1))));
        st.solve.iterations = unsigned(s.count_named(who, "last_solve_iterations", 0xffffffffu));
        st.solve.residual = s.number_named(who, "last_solve_residual");
        st.solve.converged = s.count_named(who, "last_solve_converged", 1) == 1;
        return st;
    }
    void apply_step_state(const step_state& st)
    {
        time_ = st.time;
        steps_ = st.steps;
        last_solve_ = st.solve;
    }

    Poisson poisson_;
    execution_context<Policy> context_;
    buffer<fluid_report<Real>, Policy> report_;
    fluid_report<Real> host_report_{};
    poisson_result last_solve_{};
    double time_ = 0;
    std::size_t steps_ = 0; ///< steps taken (names a failed read-back)

private:
    static fluid_report<Real> initial_report()
    {
        fluid_report<Real> r{};
        r.lowest_porosity = 1;
        r.response = Real(1e30);
        return r;
    }
};

} // namespace detail
} // namespace sphere
