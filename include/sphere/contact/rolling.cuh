#pragma once
/// \file
/// Rolling and twisting resistance (the seeds' mu_r, k_r, gamma_r) added to any contact law
/// (the interface of contact/law.cuh): elastic-plastic spring-dashpot torques on the relative
/// rotation of the two particles, the "type C" model of Ai et al. (2011), Powder Technol.
/// 206:269. Equations and units: docs/physics.md, "Rolling and twisting resistance".
#include <cmath>
#include <string>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "history.cuh"
#include "law.cuh"
#include "linear.cuh"
#include "params.cuh"
#include "result.cuh"
#include "tangential.cuh"

namespace sphere {

/// The parameters of a base law plus those of rolling and twisting resistance, SI units. In
/// settings.wall they are those of particle-wall contacts. A stiffness of 0 turns that
/// resistance off (its other two fields must then be 0).
template <class Real, class Base>
struct rolling_params : Base {
    Real mu_r = 0;        ///< rolling friction: the rolling torque is at most mu_r R* |f_n|, >= 0
    Real k_r = 0;         ///< rolling stiffness (N m/rad), >= 0
    Real gamma_r = 0;     ///< rolling viscosity (N m s/rad), >= 0
    Real mu_twist = 0;    ///< twisting friction: the twisting torque is at most mu_twist R* |f_n|, >= 0
    Real k_twist = 0;     ///< twisting stiffness (N m/rad), >= 0
    Real gamma_twist = 0; ///< twisting viscosity (N m s/rad), >= 0

    /// Calls f(name, field, unit) for every field: the base law's, then these.
    template <class Self, class F>
    static void fields(Self& p, F&& f)
    {
        Base::fields(p, f);
        f("mu_r", p.mu_r, "");
        f("k_r", p.k_r, "N m/rad");
        f("gamma_r", p.gamma_r, "N m s/rad");
        f("mu_twist", p.mu_twist, "");
        f("k_twist", p.k_twist, "N m/rad");
        f("gamma_twist", p.gamma_twist, "N m s/rad");
    }
};

/// What the kernels receive: the base law's kernel parameters and the resistances'.
template <class Real, class BaseKernel>
struct rolling_contact {
    BaseKernel base;
    Real mu_r, k_r, gamma_r, mu_twist, k_twist, gamma_twist;
};

namespace contact {

/// Rolling and twisting resistance on top of the contact law `Base` (whose history is the
/// plain vec4: wrap rolling in capillary, not the other way round). With w = omega_i - omega_j
/// split into its rolling part w_r (in the contact plane) and twisting part w_t = w . n, each
/// contact keeps a rolling angle theta_r (rad, a vector in the contact plane) and a twisting
/// angle theta_t (rad), and particle i feels the couple
///   M_r = -k_r theta_r - gamma_r w_r,   |M_r| <= mu_r R* |f_n|
///   M_t = (-k_twist theta_t - gamma_twist w_t) n,   |M_t| <= mu_twist R* |f_n|
/// (j feels the opposite), with the angles reset at the limits so that the springs alone carry
/// it, as the tangential spring does (contact/tangential.cuh).
template <class Base = linear<tangential::elastic_viscous_frictional, tangential::elastic_viscous_frictional>>
struct rolling {
    static_assert(law_history_shape<Base>::value.lanes == 0,
                  "contact::rolling needs a base law whose history is the plain vec4 (use capillary<rolling<...>>)");
    using base_law = Base;
    template <class Real>
    using params = rolling_params<Real, typename Base::template params<Real>>;
    template <class Real>
    using kernel_params = rolling_contact<Real, typename Base::template kernel_params<Real>>;

    static std::string name() { return "rolling<" + Base::name() + ">"; }
    static constexpr unsigned history_lanes = 4;
    static constexpr unsigned history_mirror = 0x7u; // theta_r reverses seen from j, theta_t does not
    template <class Real>
    using history = contact_history<Real, history_lanes>;
    static constexpr const char* history_layout =
        "tangential displacement (m) xyz, sliding flag w; lanes: rolling angle (rad) xyz, twisting angle (rad)";
    static constexpr time_step_rule time_step = Base::time_step;

    /// Throws sphere::error naming the first bad parameter (where: the settings they came from).
    template <class Real>
    static void validate(const params<Real>& pair, const params<Real>& wall,
                         const char* pair_where = "settings.contact", const char* wall_where = "settings.wall")
    {
        Base::validate(pair, wall, pair_where, wall_where);
        check(pair, pair_where);
        check(wall, wall_where);
    }

    /// Particles of materials a and b with the pair's parameters `contact`.
    template <class Real, class From>
    static kernel_params<Real> kernel(const params<From>& a, const params<From>& b, const params<From>& contact)
    {
        return with<Real>(Base::template kernel<Real>(a, b, contact), contact);
    }
    template <class Real, class From>
    static kernel_params<Real> pair_kernel(const params<From>& pair)
    {
        return kernel<Real>(pair, pair, pair);
    }
    template <class Real, class From>
    static kernel_params<Real> wall_kernel(const params<From>& pair, const params<From>& wall)
    {
        return with<Real>(Base::template wall_kernel<Real>(pair, wall), wall);
    }

    /// Unlike materials (docs/physics.md, "Materials"): the base law's mixing; stiffnesses and
    /// viscosities in series, friction coefficients by their geometric mean.
    template <class Real>
    static params<Real> mix(const params<Real>& a, const params<Real>& b, const char* a_where, const char* b_where)
    {
        params<Real> out = a;
        static_cast<typename Base::template params<Real>&>(out) = Base::mix(a, b, a_where, b_where);
        out.mu_r = detail::geometric_mean(a.mu_r, b.mu_r);
        out.k_r = detail::series(a.k_r, b.k_r);
        out.gamma_r = detail::series(a.gamma_r, b.gamma_r);
        out.mu_twist = detail::geometric_mean(a.mu_twist, b.mu_twist);
        out.k_twist = detail::series(a.k_twist, b.k_twist);
        out.gamma_twist = detail::series(a.gamma_twist, b.gamma_twist);
        return out;
    }

    /// The base law's time scale, or sqrt(I / (2 k)) (s) with I = 2 m r^2 / 5 and k the stiffest
    /// of k_r and k_twist, if smaller: the period of two such particles twisted against each
    /// other is 2 pi times that.
    template <class Real>
    static Real time_scale(const params<Real>& pair, const params<Real>& wall, Real mass, Real radius)
    {
        const Real base = Base::time_scale(pair, wall, mass, radius), k = stiffest(pair, wall);
        const Real turning = k > 0 ? std::sqrt(Real(0.2) * mass * radius * radius / k) : base;
        return turning < base ? turning : base;
    }
    template <class Real>
    static std::string time_scale_inputs(const params<Real>& pair, const params<Real>& wall, Real mass, Real radius)
    {
        return Base::time_scale_inputs(pair, wall, mass, radius) +
               detail::text("; the rotation's sqrt(m r^2 / (5 k)) with r = ", radius,
                            " m, k = ", stiffest(pair, wall), " N m/rad");
    }

    template <class Real>
    SPHERE_HDI static contact_result<Real> pair(const kernel_params<Real>& p, const contact_motion<Real>& m,
                                               history<Real>& h, Real dt)
    {
        contact_result<Real> c = Base::pair(p.base, m, h.base, dt);
        resist(p, m, h, dt, c);
        return c;
    }

    template <class Real>
    SPHERE_HDI static contact_result<Real> wall(const kernel_params<Real>& p, const contact_motion<Real>& m,
                                               history<Real>& h, Real dt)
    {
        contact_result<Real> c = Base::wall(p.base, m, h.base, dt);
        resist(p, m, h, dt, c);
        return c;
    }

    /// The base law's energy plus the rolling and twisting springs',
    /// k_r |theta_r|^2 / 2 + k_twist theta_t^2 / 2 (J).
    template <class Real>
    SPHERE_HDI static Real pair_energy(const kernel_params<Real>& p, const contact_geometry<Real>& g,
                                      const history<Real>& h)
    {
        return Base::pair_energy(p.base, g, h.base) + springs(p, h);
    }
    template <class Real>
    SPHERE_HDI static Real wall_energy(const kernel_params<Real>& p, const contact_geometry<Real>& g,
                                      const history<Real>& h)
    {
        return Base::wall_energy(p.base, g, h.base) + springs(p, h);
    }

private:
    template <class Real, class BaseKernel, class From>
    static kernel_params<Real> with(const BaseKernel& base, const params<From>& q)
    {
        return {base,       Real(q.mu_r),    Real(q.k_r),        Real(q.gamma_r),
                Real(q.mu_twist), Real(q.k_twist), Real(q.gamma_twist)};
    }

    /// Adds the rolling and twisting couples to c, with their dissipation, and updates the
    /// angles in h's lanes (written without branches, like the tangential laws).
    template <class Real>
    SPHERE_HDI static void resist(const kernel_params<Real>& p, const contact_motion<Real>& m, history<Real>& h,
                                  Real dt, contact_result<Real>& c)
    {
        const vec3<Real>& n = m.n;
        const Real arm = m.r_eff * c.fn; // R* |f_n| (N m)

        // Rolling: the tangential law's elastic-plastic spring-dashpot, on angles.
        const Real spin_n = dot(m.spin, n), turn_n = dot(m.spin_step, n);
        const vec3<Real> roll_rate = m.spin - n * spin_n, roll_step = m.spin_step - n * turn_n;
        contact_params<Real> spring;
        spring.k_t = p.k_r;
        spring.gamma_t = p.gamma_r;
        spring.mu_s = spring.mu_d = p.mu_r;
        vec4<Real> angle{h.lane[0], h.lane[1], h.lane[2], 0};
        tangential_force<Real> roll =
            tangential::elastic_viscous_frictional::evaluate(spring, n, roll_rate, roll_step, arm, angle, dt);
        const bool rolls = p.k_r > Real(0);
        const vec3<Real> zero{0, 0, 0};
        c.couple += select(rolls, roll.force, zero);
        c.visc_rate += rolls ? roll.visc_rate : Real(0);
        c.fric_rate += rolls ? roll.fric_rate : Real(0);
        h.lane[0] = rolls ? angle.x : Real(0);
        h.lane[1] = rolls ? angle.y : Real(0);
        h.lane[2] = rolls ? angle.z : Real(0);

        // Twisting: the same on the scalar angle about n.
        const bool twists = p.k_twist > Real(0);
        const Real before = h.lane[3], twist = before + turn_n;
        const Real trial = -p.k_twist * twist - p.gamma_twist * spin_n;
        const Real limit = p.mu_twist * arm;
        const bool slips = trial * trial > limit * limit;
        const Real torque = slips ? std::copysign(limit, trial) : trial;
        const Real slid = -torque / (twists ? p.k_twist : Real(1));
        const Real kept = slips ? slid : twist;
        c.couple += n * (twists ? torque : Real(0));
        c.visc_rate += twists && !slips ? p.gamma_twist * spin_n * spin_n : Real(0);
        c.fric_rate +=
            twists && slips ? -torque * spin_n - Real(0.5) * p.k_twist * (kept * kept - before * before) / dt : Real(0);
        h.lane[3] = twists ? kept : Real(0);
    }

    template <class Real>
    SPHERE_HDI static Real springs(const kernel_params<Real>& p, const history<Real>& h)
    {
        return Real(0.5) * (p.k_r * (h.lane[0] * h.lane[0] + h.lane[1] * h.lane[1] + h.lane[2] * h.lane[2]) +
                            p.k_twist * h.lane[3] * h.lane[3]);
    }

    template <class Real>
    static Real stiffest(const params<Real>& pair, const params<Real>& wall)
    {
        using std::fmax;
        return fmax(fmax(pair.k_r, pair.k_twist), fmax(wall.k_r, wall.k_twist));
    }

    template <class Real>
    static void check(const params<Real>& p, const char* where)
    {
        auto non_negative = [&](Real v, const char* name, const char* unit) {
            detail::require_non_negative(where, name, v, unit);
        };
        non_negative(p.mu_r, "mu_r", "(rolling friction)");
        non_negative(p.k_r, "k_r", "N m/rad");
        non_negative(p.gamma_r, "gamma_r", "N m s/rad");
        non_negative(p.mu_twist, "mu_twist", "(twisting friction)");
        non_negative(p.k_twist, "k_twist", "N m/rad");
        non_negative(p.gamma_twist, "gamma_twist", "N m s/rad");
        if (p.k_r == 0 && (p.mu_r != 0 || p.gamma_r != 0))
            detail::fail(where, ".k_r = 0 turns rolling resistance off, but ", where, ".mu_r = ", p.mu_r, " and ",
                         where, ".gamma_r = ", p.gamma_r, ": give a positive k_r (N m/rad)");
        if (p.k_twist == 0 && (p.mu_twist != 0 || p.gamma_twist != 0))
            detail::fail(where, ".k_twist = 0 turns twisting resistance off, but ", where, ".mu_twist = ", p.mu_twist,
                         " and ", where, ".gamma_twist = ", p.gamma_twist, ": give a positive k_twist (N m/rad)");
    }
};

} // namespace contact
} // namespace sphere
