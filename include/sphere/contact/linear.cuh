#pragma once
/// \file
/// The linear (Hookean, Kelvin-Voigt) contact model as a policy type: a normal spring-dashpot
/// and a swappable tangential law, one for particle pairs and one for walls.
/// Equations and units: docs/physics.md, "Normal force" and "Tangential force".
#include <cmath>
#include <limits>
#include <string>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "law.cuh"
#include "params.cuh"
#include "result.cuh"
#include "tangential.cuh"

namespace sphere {

namespace contact {

/// Normal force f_n = (-k_n delta_n - gamma_n d(delta_n)/dt) n, with delta_n < 0 the overlap
/// (m), n the unit normal from the partner to this particle, and d(delta_n)/dt = v_c . n
/// (negative while approaching). Unless tension is allowed the scalar is clipped at 0. The
/// viscous dissipation is the work of the non-conservative part of the applied force,
/// -(f_applied - (-k_n delta_n)) d(delta_n)/dt, which books clipping correctly
/// (VALIDATION pitfall 3).
template <class Real>
struct normal_force {
    Real magnitude;
    Real visc_rate;
};

template <class Real>
SPHERE_HDI normal_force<Real> linear_normal(const contact_params<Real>& p, Real delta_n, Real ddelta_n)
{
    const Real elastic = -p.k_n * delta_n;
    const Real trial = elastic - p.gamma_n * ddelta_n;
    const bool clipped = !p.tension && trial < Real(0);
    // -(f - elastic) d(delta_n)/dt, written per case so that it is exactly zero without
    // damping whatever the compiler contracts into fused multiply-adds
    const Real visc = clipped ? elastic * ddelta_n : p.gamma_n * ddelta_n * ddelta_n;
    return {clipped ? Real(0) : trial, visc};
}

/// The linear contact law (the interface of contact/law.cuh). `PairTangential` and
/// `WallTangential` are tangential policies (tangential::elastic_viscous_frictional or
/// tangential::visco_frictional); the defaults follow sphere: elastic tangential springs
/// between particles, viscous friction at walls.
template <class PairTangential = tangential::elastic_viscous_frictional,
          class WallTangential = tangential::visco_frictional>
struct linear {
    using pair_tangential = PairTangential;
    using wall_tangential = WallTangential;
    template <class Real>
    using params = contact_params<Real>;
    template <class Real>
    using kernel_params = contact_params<Real>;

    static std::string name()
    {
        return std::string("linear<") + PairTangential::name + ", " + WallTangential::name + ">";
    }
    static constexpr const char* history_layout = "tangential displacement (m) xyz, sliding flag w";

    /// sphere's rule: dt = 0.075 sqrt(m_min / k_max), about 40 steps per pair contact; at most
    /// 0.3 sqrt(m_min / k_max), about 10 steps, and never above the dashpots' stable step t_d
    /// (docs/physics.md, "Time step").
    static constexpr time_step_rule time_step{0.075, 0.3, "min(sqrt(m / k_max), t_d / 0.3)"};

    /// Throws sphere::error naming the first bad parameter (where: the settings they came from).
    template <class Real>
    static void validate(const contact_params<Real>& pair, const contact_params<Real>& wall,
                         const char* pair_where = "settings.contact", const char* wall_where = "settings.wall")
    {
        check(pair, pair_where);
        check(wall, wall_where);
        PairTangential::validate(pair, pair_where);
        WallTangential::validate(wall, wall_where);
    }

    /// A contact of materials a and b with the pair's parameters `contact`: those, as they
    /// are (the linear law has no material constants).
    template <class Real, class From>
    static contact_params<Real> kernel(const contact_params<From>&, const contact_params<From>&,
                                       const contact_params<From>& contact)
    {
        return params_cast<Real>(contact);
    }
    template <class Real, class From>
    static contact_params<Real> pair_kernel(const contact_params<From>& pair)
    {
        return kernel<Real>(pair, pair, pair);
    }
    template <class Real, class From>
    static contact_params<Real> wall_kernel(const contact_params<From>& pair, const contact_params<From>& wall)
    {
        return kernel<Real>(pair, wall, wall);
    }

    /// The parameters of a contact between unlike materials a and b (docs/physics.md,
    /// "Materials"): stiffnesses and viscosities as two half-contacts in series (2 a b / (a + b)),
    /// friction coefficients by their geometric mean; tension and the damping convention must
    /// agree. a_where, b_where name them in an error.
    template <class Real>
    static contact_params<Real> mix(const contact_params<Real>& a, const contact_params<Real>& b, const char* a_where,
                                    const char* b_where)
    {
        detail::agree(a.tension, b.tension, "tension", a_where, b_where);
        detail::agree(a.damping, b.damping, "damping", a_where, b_where);
        contact_params<Real> out = a;
        out.k_n = detail::series(a.k_n, b.k_n);
        out.k_t = detail::series(a.k_t, b.k_t);
        out.gamma_n = detail::series(a.gamma_n, b.gamma_n);
        out.gamma_t = detail::series(a.gamma_t, b.gamma_t);
        out.mu_s = detail::geometric_mean(a.mu_s, b.mu_s);
        out.mu_d = detail::geometric_mean(a.mu_d, b.mu_d);
        return out;
    }

    /// sqrt(m / k_max) (s), k_max the largest of k_n and k_t of pairs and walls, or, if smaller,
    /// the dashpots' stable step divided by the bound's fraction (so that the bound is theirs).
    template <class Real>
    static Real time_scale(const contact_params<Real>& pair, const contact_params<Real>& wall, Real mass, Real)
    {
        const Real springs = std::sqrt(mass / stiffest(pair, wall));
        const Real dashpots = dashpot_limit(pair, wall, mass) / Real(time_step.bound_factor);
        return dashpots < springs ? dashpots : springs;
    }
    template <class Real>
    static std::string time_scale_inputs(const contact_params<Real>& pair, const contact_params<Real>& wall, Real mass,
                                         Real)
    {
        return detail::text("m = ", mass, " kg, k_max = ", stiffest(pair, wall), " N/m, t_d = ",
                            dashpot_limit(pair, wall, mass), " s");
    }

    /// Evaluates a pair contact with motion m, history entry h and time step dt (s).
    template <class Real>
    SPHERE_HDI static contact_result<Real> pair(const contact_params<Real>& p, const contact_motion<Real>& m,
                                               vec4<Real>& h, Real dt)
    {
        return evaluate<PairTangential>(p, m, h, dt);
    }

    /// Evaluates a wall contact (the wall is the partner).
    template <class Real>
    SPHERE_HDI static contact_result<Real> wall(const contact_params<Real>& p, const contact_motion<Real>& m,
                                               vec4<Real>& h, Real dt)
    {
        return evaluate<WallTangential>(p, m, h, dt);
    }

    /// Elastic energy stored in a pair contact: k_n delta_n^2 / 2 plus the tangential spring (J).
    template <class Real>
    SPHERE_HDI static Real pair_energy(const contact_params<Real>& p, const contact_geometry<Real>& g,
                                      const vec4<Real>& h)
    {
        return Real(0.5) * p.k_n * g.delta_n * g.delta_n + PairTangential::stored_energy(p, h);
    }

    /// Elastic energy stored in a wall contact (J).
    template <class Real>
    SPHERE_HDI static Real wall_energy(const contact_params<Real>& p, const contact_geometry<Real>& g,
                                      const vec4<Real>& h)
    {
        return Real(0.5) * p.k_n * g.delta_n * g.delta_n + WallTangential::stored_energy(p, h);
    }

private:
    /// What turns gamma into a dashpot coefficient, c = gamma scale: m_eff when mass-scaled,
    /// 2 sqrt(m_eff k_n) as a ratio to critical damping, else 1.
    template <class Real>
    SPHERE_HDI static Real dashpot_scale(damping_convention convention, Real m_eff, Real k_n)
    {
        if constexpr (SPHERE_DEVICE_CODE) {
            // a warp shares the convention: branches, and the square root only where it is used
            if (convention == damping_convention::mass_scaled) return m_eff;
            if (convention == damping_convention::damping_ratio) return Real(2) * std::sqrt(m_eff * k_n);
            return Real(1);
        } else {
            // selects: clang vectorises no loop over pairs whose body branches on the convention
            const Real ratio = Real(2) * std::sqrt(m_eff * k_n);
            const Real scale = convention == damping_convention::damping_ratio ? ratio : Real(1);
            return convention == damping_convention::mass_scaled ? m_eff : scale;
        }
    }

    template <class Tangential, class Real>
    SPHERE_HDI static contact_result<Real> evaluate(const contact_params<Real>& given, const contact_motion<Real>& m,
                                                   vec4<Real>& h, Real dt)
    {
        contact_params<Real> p = given;
        // gamma in 1/s when mass-scaled: c = gamma m_eff; a ratio to critical damping:
        // c = 2 gamma sqrt(m_eff k_n) (N s/m; docs/physics.md, "Normal force")
        const Real scale = dashpot_scale(p.damping, m.m_eff, p.k_n);
        p.gamma_n *= scale;
        p.gamma_t *= scale;
        const vec3<Real>& n = m.n;
        const Real ddelta_n = dot(m.velocity, n);
        normal_force<Real> fn = linear_normal(p, m.delta_n, ddelta_n);
        const vec3<Real> vt = m.velocity - n * ddelta_n;
        const vec3<Real> step_t = m.step - n * dot(m.step, n);
        const Real fn_abs = fn.magnitude < Real(0) ? -fn.magnitude : fn.magnitude; // < 0 only with tension
        tangential_force<Real> ft = Tangential::evaluate(p, n, vt, step_t, fn_abs, h, dt);
        contact_result<Real> out;
        out.normal = n * fn.magnitude;
        out.tangential = ft.force;
        out.fn = fn_abs;
        out.visc_rate = fn.visc_rate + ft.visc_rate;
        out.fric_rate = ft.fric_rate;
        return out;
    }

    /// The largest step (s) at which every dashpot of a particle of mass m is stable in explicit
    /// integration, dt < 2 / (c w), with c its coefficient (N s/m) and w the contact's inverse
    /// effective mass: 2 / m with a particle like it and 1 / m at a wall along the normal, 7 / m
    /// and 3.5 / m along the tangent, where rotation adds r^2 / I = 2.5 / m per particle
    /// (docs/physics.md, "Time step"). +infinity without dashpots.
    template <class Real>
    static Real dashpot_limit(const contact_params<Real>& pair, const contact_params<Real>& wall, Real mass)
    {
        const Real limits[4] = {stable_step(pair, pair.gamma_n, mass / 2, Real(2) / mass),
                                stable_step(wall, wall.gamma_n, mass, Real(1) / mass),
                                stable_step(pair, pair.gamma_t, mass / 2, Real(7) / mass),
                                stable_step(wall, wall.gamma_t, mass, Real(3.5) / mass)};
        Real out = std::numeric_limits<Real>::infinity();
        for (const Real t : limits) out = t < out ? t : out;
        return out;
    }
    /// 2 / (c w) for the dashpot gamma of parameters p on a contact of effective mass m_eff and
    /// inverse effective mass w.
    template <class Real>
    static Real stable_step(const contact_params<Real>& p, Real gamma, Real m_eff, Real w)
    {
        Real c = gamma;
        if (p.damping == damping_convention::mass_scaled) c = gamma * m_eff;
        else if (p.damping == damping_convention::damping_ratio) c = Real(2) * gamma * std::sqrt(m_eff * p.k_n);
        return c > Real(0) ? Real(2) / (c * w) : std::numeric_limits<Real>::infinity();
    }

    template <class Real>
    static Real stiffest(const contact_params<Real>& pair, const contact_params<Real>& wall)
    {
        using std::fmax;
        return fmax(fmax(pair.k_n, pair.k_t), fmax(wall.k_n, wall.k_t));
    }

    template <class Real>
    static void check(const contact_params<Real>& p, const char* where)
    {
        auto positive = [&](Real v, const char* name, const char* unit) { detail::require_positive(where, name, v, unit); };
        auto non_negative = [&](Real v, const char* name, const char* unit) {
            detail::require_non_negative(where, name, v, unit);
        };
        positive(p.k_n, "k_n", "N/m");
        non_negative(p.k_t, "k_t", "N/m");
        const bool scaled = p.damping == damping_convention::mass_scaled;
        const bool ratio = p.damping == damping_convention::damping_ratio;
        if (p.damping != damping_convention::absolute && !scaled && !ratio)
            detail::fail(where, ".damping = ", unsigned(p.damping), ": not a damping_convention");
        const char* unit = scaled ? "1/s (mass-scaled)" : (ratio ? "(ratio to critical damping)" : "N s/m");
        non_negative(p.gamma_n, "gamma_n", unit);
        non_negative(p.gamma_t, "gamma_t", unit);
        non_negative(p.mu_s, "mu_s", "(friction)");
        non_negative(p.mu_d, "mu_d", "(friction)");
        if (p.mu_d > p.mu_s)
            detail::fail(where, ".mu_d = ", p.mu_d, " exceeds ", where, ".mu_s = ", p.mu_s,
                         ": dynamic friction must not exceed static friction");
    }
};

} // namespace contact
} // namespace sphere
