#pragma once
/// \file
/// Fluid-particle drag laws (policy types) and the interaction force on one particle.
///
/// Notation: phi is the POROSITY of the fluid cell (its fluid volume fraction, in (0, 1]), so
/// 1 - phi is its solid fraction; d is the (cell-averaged) particle diameter (m); u = |v_f - v_p|
/// the magnitude of the fluid velocity relative to the (cell-averaged) particle velocity (m/s);
/// rho_f the fluid density (kg/m^3) and mu_f its dynamic viscosity (Pa s).
///
/// Every law gives the momentum-exchange coefficient beta (N s/m^4 = kg/(m^3 s)): the fluid
/// exerts the force per unit (cell) volume beta (v_f - v_p) on the particles, and the particles
/// exert -beta (v_f - v_p) on the fluid. One particle of volume V_p in the cell receives
/// beta (v_f - v_p) V_p / (1 - phi) (the particles of a cell hold the volume (1 - phi) V_cell
/// between them, so the per-particle forces add up to beta (v_f - v_p) V_cell).
///
/// Laws (Gidaspow 1994, "Multiphase flow and fluidization", the form the seeds cite, with the
/// Wen-Yu expression corrected as in VALIDATION.md pitfall 5):
///   Reynolds number   Re  = phi rho_f d u / mu_f           (the fluid fraction is included)
///   Schiller-Naumann  C_d = 24/Re (1 + 0.15 Re^0.687) for Re < 1000, 0.44 for Re >= 1000
///   drag::ergun       beta = 150 mu_f (1-phi)^2 / (phi d^2) + 1.75 (1-phi) rho_f u / d
///   drag::wen_yu      beta = 3/4 C_d rho_f phi (1-phi) u / d * phi^-2.65
///                          = 3/4 (C_d Re) mu_f (1-phi) phi^-2.65 / d^2   (the form evaluated)
///   drag::gidaspow    Ergun for phi <= 0.8, Wen-Yu above (the switched law of the seeds)
///   drag::gidaspow_blended  (1 - w) Ergun + w Wen-Yu, w = 1/2 + arctan(262.5 (phi - 0.8)) / pi
///                          (Lu Huilin & Gidaspow 2003, Chem. Eng. Sci. 58:3777)
///
/// Wen-Yu is evaluated through the product C_d Re, which tends to 24 (the Stokes limit) as
/// u -> 0, so beta stays finite and positive at zero relative velocity instead of 0 * inf.
///
/// The functions called inside kernels never throw; check() validates the inputs on the host.
/// Equations, units and the departures from the seeds: docs/fluid.md, "Drag laws".
#include <cmath>

#include "../core/config.cuh"
#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"

namespace sphere {
namespace drag {

/// Porosity at which drag::gidaspow switches from Ergun (phi <= 0.8) to Wen-Yu (phi > 0.8),
/// and about which drag::gidaspow_blended blends.
template <class Real> inline constexpr Real switch_porosity = Real(0.8);

/// Reynolds number above which the Schiller-Naumann C_d is replaced by the constant 0.44.
template <class Real> inline constexpr Real newton_reynolds = Real(1000);

/// Particle Reynolds number Re = phi rho_f d u / mu_f (dimensionless), with the porosity phi,
/// diameter d (m), relative speed u = |v_f - v_p| (m/s), fluid density rho_f (kg/m^3) and
/// viscosity mu_f (Pa s). This is the definition of the seeds and of Gidaspow's Wen-Yu form.
template <class Real>
SPHERE_HD Real reynolds(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
{
    return phi * rho_f * d * speed / mu_f;
}

/// C_d Re for the Schiller-Naumann drag coefficient: 24 (1 + 0.15 Re^0.687) for Re < 1000,
/// 0.44 Re above. Finite at Re = 0 (24, the Stokes limit); the form the kernels evaluate.
template <class Real>
SPHERE_HD Real cd_times_reynolds(Real re)
{
    if (re < newton_reynolds<Real>) return Real(24) * (Real(1) + Real(0.15) * std::pow(re, Real(0.687)));
    return Real(0.44) * re;
}

/// Schiller-Naumann drag coefficient C_d = 24/Re (1 + 0.15 Re^0.687) for Re < 1000, 0.44 for
/// Re >= 1000 (dimensionless). Infinite at Re = 0: kernels use cd_times_reynolds instead.
template <class Real>
SPHERE_HD Real drag_coefficient(Real re)
{
    if (re < newton_reynolds<Real>) return Real(24) / re * (Real(1) + Real(0.15) * std::pow(re, Real(0.687)));
    return Real(0.44);
}

/// Ergun (1952) momentum-exchange coefficient for packed beds, at every porosity.
struct ergun {
    static const char* name() { return "ergun"; }
    /// No parameters.
    static void validate() {}

    /// beta = 150 mu_f (1-phi)^2 / (phi d^2) + 1.75 (1-phi) rho_f u / d (N s/m^4).
    template <class Real>
    SPHERE_HD static Real beta(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
    {
        return (Real(1) - phi) * beta_per_solid(phi, d, speed, rho_f, mu_f);
    }

    /// beta / (1 - phi) = 150 mu_f (1-phi) / (phi d^2) + 1.75 rho_f u / d (N s/m^4): the
    /// coefficient of one particle's force per particle volume, finite up to phi = 1.
    template <class Real>
    SPHERE_HD static Real beta_per_solid(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
    {
        return Real(150) * mu_f * (Real(1) - phi) / (phi * d * d) + Real(1.75) * rho_f * speed / d;
    }
};

/// Wen & Yu (1966) momentum-exchange coefficient for dilute suspensions, in Gidaspow's
/// dimensionally correct form, at every porosity.
struct wen_yu {
    static const char* name() { return "wen_yu"; }
    /// No parameters.
    static void validate() {}

    /// beta = 3/4 C_d rho_f phi (1-phi) u / d phi^-2.65 = 3/4 (C_d Re) mu_f (1-phi) phi^-2.65 / d^2
    /// (N s/m^4), Re = phi rho_f d u / mu_f; 18 mu_f (1-phi) phi^-2.65 / d^2 at u = 0.
    template <class Real>
    SPHERE_HD static Real beta(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
    {
        return (Real(1) - phi) * beta_per_solid(phi, d, speed, rho_f, mu_f);
    }

    /// beta / (1 - phi) = 3/4 (C_d Re) mu_f phi^-2.65 / d^2 (N s/m^4); at phi = 1 one particle
    /// gets the single-sphere Schiller-Naumann drag 3 pi mu_f d u (1 + 0.15 Re^0.687).
    template <class Real>
    SPHERE_HD static Real beta_per_solid(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
    {
        const Real cdre = cd_times_reynolds(reynolds(phi, d, speed, rho_f, mu_f));
        return Real(0.75) * cdre * mu_f * std::pow(phi, Real(-2.65)) / (d * d);
    }
};

/// Gidaspow's switched law, the one the seeds document: Ergun for phi <= 0.8, Wen-Yu for
/// phi > 0.8. beta is discontinuous at phi = 0.8: in the Stokes limit (u -> 0) it drops by the
/// factor 1.153313 from just below to just above (VALIDATION pitfall 5); at finite Re the
/// factor differs (1.1106 at Re = 16, 3.23 at Re = 640, see docs/fluid.md).
struct gidaspow {
    static const char* name() { return "gidaspow"; }
    /// No parameters.
    static void validate() {}

    template <class Real>
    SPHERE_HD static Real beta(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
    {
        return phi <= switch_porosity<Real> ? ergun::beta(phi, d, speed, rho_f, mu_f)
                                            : wen_yu::beta(phi, d, speed, rho_f, mu_f);
    }

    template <class Real>
    SPHERE_HD static Real beta_per_solid(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
    {
        return phi <= switch_porosity<Real> ? ergun::beta_per_solid(phi, d, speed, rho_f, mu_f)
                                            : wen_yu::beta_per_solid(phi, d, speed, rho_f, mu_f);
    }
};

/// Ergun and Wen-Yu blended smoothly across phi = 0.8 (Lu Huilin & D. Gidaspow 2003,
/// "Hydrodynamics of binary fluidization in a riser: CFD simulation using two granular
/// temperatures", Chem. Eng. Sci. 58:3777-3792):
///   beta = (1 - w) beta_Ergun + w beta_WenYu,  w = 1/2 + arctan(262.5 (phi - 0.8)) / pi,
/// the slope 262.5 = 150 * 1.75 of the paper (written there with the solid fraction
/// eps_s = 1 - phi as 262.5 (0.2 - eps_s)). w = 1/2 at phi = 0.8 and runs from 0.1 to 0.9
/// over phi = 0.8 -+ 0.01173 (tan(0.4 pi) / 262.5); its tails are slow, 1 - w (or w)
/// ~ 1 / (262.5 pi |phi - 0.8|): 0.30% at phi = 0.4, 1.2% at 0.7 and 0.9.
struct gidaspow_blended {
    static const char* name() { return "gidaspow_blended"; }
    /// The slope of the arctan in w (dimensionless).
    template <class Real> static constexpr Real slope = Real(262.5);

    /// No parameters.
    static void validate() {}

    /// The weight w of Wen-Yu, in (0, 1).
    template <class Real>
    SPHERE_HD static Real weight(Real phi)
    {
        return Real(0.5) + std::atan(slope<Real> * (phi - switch_porosity<Real>)) / pi<Real>;
    }

    template <class Real>
    SPHERE_HD static Real beta(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
    {
        const Real w = weight(phi);
        return (Real(1) - w) * ergun::beta(phi, d, speed, rho_f, mu_f) + w * wen_yu::beta(phi, d, speed, rho_f, mu_f);
    }

    template <class Real>
    SPHERE_HD static Real beta_per_solid(Real phi, Real d, Real speed, Real rho_f, Real mu_f)
    {
        const Real w = weight(phi);
        return (Real(1) - w) * ergun::beta_per_solid(phi, d, speed, rho_f, mu_f) +
               w * wen_yu::beta_per_solid(phi, d, speed, rho_f, mu_f);
    }
};

/// Drag force on one particle of volume V_p (m^3) in a cell of porosity phi with the cell's
/// coefficient beta (N s/m^4) and relative velocity v_f - v_p (m/s):
///   f = beta (v_f - v_p) V_p / (1 - phi)  (N).
/// The fluid receives -f. For phi >= 1 every law has beta = 0 and the quotient is 0/0: this
/// returns zero there; particle_drag_force, which divides analytically, gives the finite limit
/// (the single-particle drag) and is the form a solver should use.
template <class Real>
SPHERE_HD vec3<Real> drag_force(Real beta, Real phi, Real V_p, const vec3<Real>& relative_velocity)
{
    if (!(phi < Real(1))) return {Real(0), Real(0), Real(0)};
    return relative_velocity * (beta * V_p / (Real(1) - phi));
}

/// The drag force on one particle with law `Law`, f = Law::beta_per_solid(...) (v_f - v_p) V_p
/// (N), from the cell porosity phi, the cell-averaged diameter d (m), the particle volume V_p
/// (m^3), the relative velocity v_f - v_p (m/s), rho_f (kg/m^3) and mu_f (Pa s). Equal to
/// drag_force(Law::beta(...), phi, V_p, v_f - v_p) for phi < 1, finite at phi = 1. The fluid
/// receives -f.
template <class Law, class Real>
SPHERE_HD vec3<Real> particle_drag_force(Real phi, Real d, Real V_p, const vec3<Real>& relative_velocity, Real rho_f,
                                         Real mu_f)
{
    const Real k = Law::beta_per_solid(phi, d, norm(relative_velocity), rho_f, mu_f);
    return relative_velocity * (k * V_p);
}

/// The optional pressure-gradient force on one particle, -V_p grad p (N), with V_p in m^3 and
/// grad p in Pa/m (buoyancy rho_f |g| V_p upwards in a hydrostatic fluid). A solver that applies
/// it passes the reaction back to the fluid as well (VALIDATION F8: without it the pressure drop
/// through a fixed bed is phi times Ergun's).
template <class Real>
SPHERE_HD vec3<Real> pressure_gradient_force(Real V_p, const vec3<Real>& grad_p)
{
    return grad_p * (-V_p);
}

/// The drag force per unit cell volume on the fluid, -beta (v_f - v_p) (N/m^3): the sum of the
/// reactions -f of the cell's particles divided by the cell volume.
template <class Real>
SPHERE_HD vec3<Real> fluid_force_density(Real beta, const vec3<Real>& relative_velocity)
{
    return relative_velocity * (-beta);
}

/// Terminal slip speed u (m/s) of one sphere of diameter d (m) under the net force F (N) with
/// Law's per-particle drag at porosity phi: the root of F = Law::beta_per_solid(phi, d, u) V u,
/// V = pi d^3 / 6, by bisection (the drag grows monotonically with u). Host only. For a
/// settling sphere F = (rho_p - rho_f) g V (with buoyancy) or rho_p g V (without).
template <class Law>
double terminal_speed(double F, double phi, double d, double rho_f, double mu_f)
{
    const double V = pi<double> / 6 * d * d * d;
    const auto drag_at = [&](double u) { return Law::beta_per_solid(phi, d, u, rho_f, mu_f) * V * u; };
    double lo = 0, hi = 1;
    while (drag_at(hi) < F && hi < 1e12) hi *= 2;
    for (int it = 0; it < 200; ++it) {
        const double u = 0.5 * (lo + hi);
        (drag_at(u) < F ? lo : hi) = u;
    }
    return 0.5 * (lo + hi);
}

/// Host-side checks of the drag inputs (kernels never throw). Each throws sphere::error naming
/// the value: `where` prefixes the message (e.g. "fluid cell (1, 2, 3)").
template <class Real>
void check_porosity(Real phi, const char* where = "drag")
{
    if (!(phi > Real(0) && phi <= Real(1)))
        detail::fail(where, ": porosity phi = ", phi, " is outside (0, 1]");
}

template <class Real>
void check_diameter(Real d, const char* where = "drag")
{
    if (!(d > Real(0)) || !std::isfinite(d))
        detail::fail(where, ": particle diameter d = ", d, " m must be positive and finite");
}

template <class Real>
void check_fluid(Real rho_f, Real mu_f, const char* where = "drag")
{
    if (!(rho_f > Real(0)) || !std::isfinite(rho_f))
        detail::fail(where, ": fluid density rho_f = ", rho_f, " kg/m^3 must be positive and finite");
    if (!(mu_f > Real(0)) || !std::isfinite(mu_f))
        detail::fail(where, ": fluid viscosity mu_f = ", mu_f, " Pa s must be positive and finite");
}

/// All of the above: phi in (0, 1], d, rho_f and mu_f positive and finite.
template <class Real>
void check(Real phi, Real d, Real rho_f, Real mu_f, const char* where = "drag")
{
    check_porosity(phi, where);
    check_diameter(d, where);
    check_fluid(rho_f, mu_f, where);
}

} // namespace drag
} // namespace sphere
