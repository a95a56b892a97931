#pragma once
/// \file
/// The Hertz-Mindlin contact law (the interface of contact/law.cuh) in the form of LIGGGHTS'
/// `hertz` / `tangential history` models and DEM-Engine: materials given by Young's modulus,
/// Poisson's ratio and a coefficient of restitution; normal and tangential stiffness that grow
/// with the square root of the overlap; dashpots that keep the restitution independent of the
/// impact velocity and of the particles' sizes and masses; a tangential spring with Coulomb
/// friction. Equations and units: docs/physics.md, "Hertz-Mindlin".
#include <cmath>
#include <string>

#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "law.cuh"
#include "linear.cuh"
#include "params.cuh"
#include "result.cuh"
#include "tangential.cuh"

namespace sphere {

/// One material's Hertz-Mindlin parameters, SI units. For walls (settings.wall) the wall's
/// material, and the restitution and friction of particle-wall contacts.
template <class Real>
struct hertz_params {
    Real youngs_modulus = 0; ///< E (Pa), > 0
    Real poisson_ratio = 0;  ///< nu, -1 < nu <= 0.5
    Real restitution = 1;    ///< coefficient of restitution e of a head-on impact, 0 < e <= 1
    Real mu_s = 0;           ///< static friction coefficient, >= 0
    Real mu_d = 0;           ///< dynamic friction coefficient, 0 <= mu_d <= mu_s
    bool tension = false;    ///< allow the dashpot to pull (false: |f_n| clipped at 0, as sphere does)

    /// Calls f(name, field, unit) for every field (contact/law.cuh).
    template <class Self, class F>
    static void fields(Self& p, F&& f)
    {
        f("youngs_modulus", p.youngs_modulus, "Pa");
        f("poisson_ratio", p.poisson_ratio, "");
        f("restitution", p.restitution, "");
        f("mu_s", p.mu_s, "");
        f("mu_d", p.mu_d, "");
        f("tension", p.tension, "");
    }
};

/// What the Hertz-Mindlin kernels receive for one kind of contact (pairs, or walls).
template <class Real>
struct hertz_contact {
    Real e_star;  ///< effective Young's modulus E* (Pa)
    Real g_star;  ///< effective shear modulus G* (Pa)
    Real damping; ///< alpha: gamma = alpha sqrt(S m_eff) for S = S_n, S_t (dimensionless)
    Real mu_s, mu_d;
    bool tension;
};

/// Restitution e of a head-on Hertz impact with the dashpot alpha sqrt(S_n m_eff): the
/// scaled equation xi'' = -xi^(3/2) - alpha sqrt(3/2) xi^(1/4) xi' (xi(0) = 0, xi'(0) = 1;
/// every impact reduces to it, so e does not depend on the sizes, masses or the velocity),
/// integrated by the classical Runge-Kutta method with step h until the contact ends. With
/// `tension` false the force is clipped at 0.
inline double hertz_restitution(double alpha, bool tension, double h = 2e-4)
{
    const double c = alpha * std::sqrt(1.5);
    auto accel = [&](double x, double v) {
        const double xp = x > 0 ? x : 0;
        const double f = xp * std::sqrt(xp) + c * std::sqrt(std::sqrt(xp)) * v; // repulsion (scaled)
        return -(tension || f > 0 ? f : 0);
    };
    double x = 0, v = 1;
    for (long k = 0; k < 100000000L; ++k) {
        const double a1 = accel(x, v);
        const double a2 = accel(x + h / 2 * v, v + h / 2 * a1);
        const double a3 = accel(x + h / 2 * (v + h / 2 * a1), v + h / 2 * a2);
        const double a4 = accel(x + h * (v + h / 2 * a2), v + h * a3);
        x += h * (v + h / 6 * (a1 + a2 + a3));
        v += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
        if (x < 0) return -v;
    }
    return 0; // never separates (not reached: every alpha >= 0 ends the contact)
}

/// The damping alpha that gives restitution e (0 < e <= 1). With tension, LIGGGHTS' closed
/// form alpha = 2 sqrt(5/6) (-ln e) / sqrt(ln^2 e + pi^2), which reproduces e exactly; clipped,
/// the root of hertz_restitution(alpha) = e (bisection to 1e-9 in e).
inline double hertz_damping_from_restitution(double e, bool tension)
{
    if (!(e > 0 && e <= 1)) detail::fail("restitution coefficient e = ", e, ": must lie in (0, 1]");
    const double l = std::log(e);
    const double closed = 2 * std::sqrt(5.0 / 6.0) * -l / std::sqrt(l * l + pi<double> * pi<double>);
    if (tension || e == 1) return closed;
    double lo = 0, hi = closed > 0 ? closed : 1; // clipping raises e: the root lies above the closed form
    while (hertz_restitution(hi, false) > e) lo = hi, hi *= 2;
    for (int k = 0; k < 100; ++k) {
        const double mid = (lo + hi) / 2, at = hertz_restitution(mid, false);
        if (std::fabs(at - e) < 1e-9) return mid;
        (at > e ? lo : hi) = mid;
    }
    return (lo + hi) / 2;
}

namespace contact {

/// The Hertz-Mindlin law. With delta > 0 the overlap, R* the effective radius and m* the
/// effective mass (docs/physics.md, "Hertz-Mindlin"):
///   f_n = 4/3 E* sqrt(R*) delta^(3/2) - gamma_n v_n,   gamma_n = alpha sqrt(S_n m*), S_n = 2 E* sqrt(R* delta)
///   f_t = -k_t delta_t - gamma_t v_t (Coulomb-limited), k_t = S_t = 8 G* sqrt(R* delta), gamma_t = alpha sqrt(S_t m*)
/// `PairTangential` and `WallTangential` are tangential policies (contact/tangential.cuh); both
/// default to the elastic spring, so that walls hold static loads.
template <class PairTangential = tangential::elastic_viscous_frictional,
          class WallTangential = tangential::elastic_viscous_frictional>
struct hertz_mindlin {
    using pair_tangential = PairTangential;
    using wall_tangential = WallTangential;
    template <class Real>
    using params = hertz_params<Real>;
    template <class Real>
    using kernel_params = hertz_contact<Real>;

    static std::string name()
    {
        return std::string("hertz_mindlin<") + PairTangential::name + ", " + WallTangential::name + ">";
    }
    static constexpr const char* history_layout = "tangential displacement (m) xyz, sliding flag w";

    /// A fraction of the Rayleigh time T_R = pi r sqrt(rho / G) / (0.1631 nu + 0.8766) of the
    /// particle material (docs/physics.md, "Time step").
    static constexpr time_step_rule time_step{0.2, 0.5, "T_R"};

    /// Throws sphere::error naming the first bad parameter (where: the settings they came from).
    template <class Real>
    static void validate(const hertz_params<Real>& pair, const hertz_params<Real>& wall,
                         const char* pair_where = "settings.contact", const char* wall_where = "settings.wall")
    {
        check(pair, pair_where);
        check(wall, wall_where);
    }

    /// A contact of materials a and b (E and nu of each) with the restitution and friction of
    /// `contact`: 1/E* = (1 - nu_a^2)/E_a + (1 - nu_b^2)/E_b, 1/G* = (2 - nu_a)/G_a + (2 - nu_b)/G_b.
    template <class Real, class From>
    static hertz_contact<Real> kernel(const hertz_params<From>& a, const hertz_params<From>& b,
                                      const hertz_params<From>& contact)
    {
        const double ea = double(a.youngs_modulus), na = double(a.poisson_ratio);
        const double eb = double(b.youngs_modulus), nb = double(b.poisson_ratio);
        const double ga = ea / (2 * (1 + na)), gb = eb / (2 * (1 + nb));
        const double e_star = 1 / ((1 - na * na) / ea + (1 - nb * nb) / eb);
        const double g_star = 1 / ((2 - na) / ga + (2 - nb) / gb);
        const double alpha = hertz_damping_from_restitution(double(contact.restitution), contact.tension);
        return {Real(e_star), Real(g_star), Real(alpha), Real(contact.mu_s), Real(contact.mu_d), contact.tension};
    }

    /// Two particles of the material: E* = E / (2 (1 - nu^2)), G* = G / (2 (2 - nu)).
    template <class Real, class From>
    static hertz_contact<Real> pair_kernel(const hertz_params<From>& pair)
    {
        return kernel<Real>(pair, pair, pair);
    }
    /// A particle against the wall's material: 1/E* = (1 - nu_p^2)/E_p + (1 - nu_w^2)/E_w,
    /// 1/G* = (2 - nu_p)/G_p + (2 - nu_w)/G_w; restitution and friction of the wall's params.
    template <class Real, class From>
    static hertz_contact<Real> wall_kernel(const hertz_params<From>& pair, const hertz_params<From>& wall)
    {
        return kernel<Real>(pair, wall, wall);
    }

    /// The contact parameters of unlike materials a and b (docs/physics.md, "Materials"): the
    /// restitution and the friction coefficients by their geometric mean (E and nu stay each
    /// material's: kernel mixes them); tension must agree.
    template <class Real>
    static hertz_params<Real> mix(const hertz_params<Real>& a, const hertz_params<Real>& b, const char* a_where,
                                  const char* b_where)
    {
        detail::agree(a.tension, b.tension, "tension", a_where, b_where);
        hertz_params<Real> out = a;
        out.restitution = detail::geometric_mean(a.restitution, b.restitution);
        out.mu_s = detail::geometric_mean(a.mu_s, b.mu_s);
        out.mu_d = detail::geometric_mean(a.mu_d, b.mu_d);
        return out;
    }

    /// The Rayleigh time of a particle of the pairs' material (s).
    template <class Real>
    static Real time_scale(const hertz_params<Real>& pair, const hertz_params<Real>&, Real mass, Real radius)
    {
        const double r = double(radius), nu = double(pair.poisson_ratio);
        const double rho = double(mass) / (4.0 / 3.0 * pi<double> * r * r * r);
        const double g = double(pair.youngs_modulus) / (2 * (1 + nu));
        return Real(pi<double> * r * std::sqrt(rho / g) / (0.1631 * nu + 0.8766));
    }
    template <class Real>
    static std::string time_scale_inputs(const hertz_params<Real>& pair, const hertz_params<Real>&, Real mass,
                                         Real radius)
    {
        return detail::text("r = ", radius, " m, m = ", mass, " kg, E = ", pair.youngs_modulus,
                            " Pa, nu = ", pair.poisson_ratio);
    }

    template <class Real>
    SPHERE_HDI static contact_result<Real> pair(const hertz_contact<Real>& p, const contact_motion<Real>& m,
                                               vec4<Real>& h, Real dt)
    {
        return evaluate<PairTangential>(p, m, h, dt);
    }

    template <class Real>
    SPHERE_HDI static contact_result<Real> wall(const hertz_contact<Real>& p, const contact_motion<Real>& m,
                                               vec4<Real>& h, Real dt)
    {
        return evaluate<WallTangential>(p, m, h, dt);
    }

    /// 8/15 E* sqrt(R*) delta^(5/2) plus the tangential spring k_t |delta_t|^2 / 2 (J).
    template <class Real>
    SPHERE_HDI static Real pair_energy(const hertz_contact<Real>& p, const contact_geometry<Real>& g,
                                      const vec4<Real>& h)
    {
        return energy<PairTangential>(p, g, h);
    }

    template <class Real>
    SPHERE_HDI static Real wall_energy(const hertz_contact<Real>& p, const contact_geometry<Real>& g,
                                      const vec4<Real>& h)
    {
        return energy<WallTangential>(p, g, h);
    }

private:
    /// The stiffnesses at overlap delta (> 0): k_n with k_n delta the elastic normal force, and
    /// S_n, S_t (N/m).
    template <class Real>
    struct stiffness {
        Real k_n, s_n, s_t;
    };
    template <class Real>
    SPHERE_HDI static stiffness<Real> stiffness_at(const hertz_contact<Real>& p, Real r_eff, Real delta)
    {
        const Real root = std::sqrt(r_eff * delta);
        return {Real(4) / Real(3) * p.e_star * root, Real(2) * p.e_star * root, Real(8) * p.g_star * root};
    }

    template <class Tangential, class Real>
    SPHERE_HDI static contact_result<Real> evaluate(const hertz_contact<Real>& p, const contact_motion<Real>& m,
                                                   vec4<Real>& h, Real dt)
    {
        const Real delta = -m.delta_n;
        stiffness<Real> s = stiffness_at(p, m.r_eff, delta);
        // The linear law's pieces with the stiffnesses and dashpots of this overlap.
        contact_params<Real> q;
        q.k_n = s.k_n;
        q.k_t = s.s_t;
        q.gamma_n = p.damping * std::sqrt(s.s_n * m.m_eff);
        q.gamma_t = p.damping * std::sqrt(s.s_t * m.m_eff);
        q.mu_s = p.mu_s;
        q.mu_d = p.mu_d;
        q.tension = p.tension;
        const vec3<Real>& n = m.n;
        const Real ddelta_n = dot(m.velocity, n);
        normal_force<Real> fn = linear_normal(q, m.delta_n, ddelta_n);
        const vec3<Real> vt = m.velocity - n * ddelta_n;
        const Real step_n = dot(m.step, n);
        const vec3<Real> step_t = m.step - n * step_n;
        const Real fn_abs = fn.magnitude < Real(0) ? -fn.magnitude : fn.magnitude;
        // The spring held h at the stiffness of the overlap before the step, delta + step_n;
        // k_t has changed since without any force doing work (Mindlin's spring is not
        // conservative): that change of its energy is booked with the viscous dissipation, so
        // that the energy budget closes (docs/physics.md, "Hertz-Mindlin").
        const Real before = delta + step_n;
        const Real k_t_before = Real(8) * p.g_star * std::sqrt(m.r_eff * (before > Real(0) ? before : Real(0)));
        const Real held2 = h.x * h.x + h.y * h.y + h.z * h.z;
        tangential_force<Real> ft = Tangential::evaluate(q, n, vt, step_t, fn_abs, h, dt);
        contact_result<Real> out;
        out.normal = n * fn.magnitude;
        out.tangential = ft.force;
        out.fn = fn_abs;
        out.visc_rate = fn.visc_rate + ft.visc_rate - Real(0.5) * (s.s_t - k_t_before) * held2 / dt;
        out.fric_rate = ft.fric_rate;
        return out;
    }

    template <class Tangential, class Real>
    SPHERE_HDI static Real energy(const hertz_contact<Real>& p, const contact_geometry<Real>& g, const vec4<Real>& h)
    {
        const Real delta = -g.delta_n;
        stiffness<Real> s = stiffness_at(p, g.r_eff, delta);
        contact_params<Real> q;
        q.k_t = s.s_t;
        return Real(0.4) * s.k_n * delta * delta + Tangential::stored_energy(q, h);
    }

    template <class Real>
    static void check(const hertz_params<Real>& p, const char* where)
    {
        detail::require_positive(where, "youngs_modulus", p.youngs_modulus, "Pa");
        if (!(p.poisson_ratio > -1 && p.poisson_ratio <= Real(0.5)))
            detail::fail(where, ".poisson_ratio = ", p.poisson_ratio, ": must lie in (-1, 0.5]");
        if (!(p.restitution > 0 && p.restitution <= 1))
            detail::fail(where, ".restitution = ", p.restitution, ": must lie in (0, 1]");
        detail::require_non_negative(where, "mu_s", p.mu_s, "(friction)");
        detail::require_non_negative(where, "mu_d", p.mu_d, "(friction)");
        if (p.mu_d > p.mu_s)
            detail::fail(where, ".mu_d = ", p.mu_d, " exceeds ", where, ".mu_s = ", p.mu_s,
                         ": dynamic friction must not exceed static friction");
    }
};

} // namespace contact
} // namespace sphere
