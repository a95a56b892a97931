#pragma once
/// \file
/// Parameters of the parallel bonds (Potyondy & Cundall 2004; docs/physics.md, "Bonds") and
/// the springs, dashpots and strengths they give a bond between two radii.
#include <cmath>
#include <limits>

#include "../core/config.cuh"
#include "../core/constants.cuh"
#include "../core/error.cuh"

namespace sphere {

/// A parallel bond is a disc of cement of radius R = radius_ratio * min(r_i, r_j) between two
/// particles: elastic in extension, shear, bending and twisting, with stiffnesses per area of
/// the disc, and broken for good once its largest tensile or shear stress exceeds a strength.
/// SI units; settings.bond holds them for every bond of a simulation.
template <class Real>
struct bond_params {
    Real radius_ratio = 1; ///< R / min(r_i, r_j), > 0 (Potyondy & Cundall's lambda)
    Real k_n = 0;          ///< normal stiffness per area (Pa/m): axial K_n = k_n A, bending K_b = k_n I
    Real k_t = 0;          ///< shear stiffness per area (Pa/m): shear K_t = k_t A, twisting K_w = k_t J
    Real tensile_strength = std::numeric_limits<Real>::infinity(); ///< sigma_c (Pa): tension plus bending
    Real shear_strength = std::numeric_limits<Real>::infinity();   ///< tau_c (Pa): shear plus twisting
    Real damping = 0; ///< each mode's dashpot as a fraction of its critical damping, >= 0

    /// Calls f(name, field, unit) for every field, in the order of checkpoints.
    template <class Self, class F>
    static void fields(Self& p, F&& f)
    {
        f("radius_ratio", p.radius_ratio, "");
        f("k_n", p.k_n, "Pa/m");
        f("k_t", p.k_t, "Pa/m");
        f("tensile_strength", p.tensile_strength, "Pa");
        f("shear_strength", p.shear_strength, "Pa");
        f("damping", p.damping, "");
    }
};

/// Refuses bond parameters that mean nothing, naming the field (`settings.bond.k_n = -1 Pa/m: ...`).
template <class Real>
void validate_bond_params(const bond_params<Real>& b)
{
    const auto finite = [](const char* name, Real v, const char* unit, bool positive) {
        if (!(positive ? v > 0 : v >= 0) || !std::isfinite(v))
            detail::fail("settings.bond.", name, " = ", v, unit, ": must be ", positive ? "positive" : "non-negative",
                         " and finite");
    };
    finite("radius_ratio", b.radius_ratio, "", true);
    finite("k_n", b.k_n, " Pa/m", false);
    finite("k_t", b.k_t, " Pa/m", false);
    finite("damping", b.damping, "", false);
    const char* names[2] = {"tensile_strength", "shear_strength"};
    const Real strengths[2] = {b.tensile_strength, b.shear_strength};
    for (int k = 0; k < 2; ++k)
        if (!(strengths[k] > 0))
            detail::fail("settings.bond.", names[k], " = ", strengths[k], " Pa: must be positive (infinity: unbreakable)");
}

/// A bond's springs (N/m, N m/rad), the geometry of its disc and its dashpots, for two radii
/// and two masses (kg); a fixed particle's mass counts as it is.
template <class Real>
struct bond_springs {
    Real radius;  ///< R (m)
    Real area;    ///< A = pi R^2 (m^2)
    Real inertia; ///< I = pi R^4 / 4 (m^4), bending
    Real polar;   ///< J = pi R^4 / 2 (m^4), twisting
    Real k_n, k_t, k_b, k_w; ///< K_n = k_n A, K_t = k_t A (N/m); K_b = k_n I, K_w = k_t J (N m/rad)
    Real c_n, c_t, c_b, c_w; ///< dashpots 2 zeta sqrt(K m*) (N s/m) and 2 zeta sqrt(K I*) (N m s/rad)

    SPHERE_HDI static bond_springs make(const bond_params<Real>& p, Real r_i, Real r_j, Real m_i, Real m_j)
    {
        bond_springs s;
        s.radius = p.radius_ratio * (r_i < r_j ? r_i : r_j);
        const Real r2 = s.radius * s.radius;
        s.area = pi<Real> * r2;
        s.inertia = pi<Real> * r2 * r2 / 4;
        s.polar = 2 * s.inertia;
        s.k_n = p.k_n * s.area;
        s.k_t = p.k_t * s.area;
        s.k_b = p.k_n * s.inertia;
        s.k_w = p.k_t * s.polar;
        const Real m = effective_mass(m_i, m_j);
        const Real moment = effective_moment(r_i, r_j, m_i, m_j);
        const Real z2 = 2 * p.damping;
        s.c_n = z2 * std::sqrt(s.k_n * m);
        s.c_t = z2 * std::sqrt(s.k_t * m);
        s.c_b = z2 * std::sqrt(s.k_b * moment);
        s.c_w = z2 * std::sqrt(s.k_w * moment);
        return s;
    }

    /// The bond's time scale (s): the shortest of sqrt(m* / K) over its translational modes
    /// and sqrt(I* / K) over its rotational ones (the shear spring turns a particle about its
    /// centre with stiffness K_t r^2), each shortened by its damping to
    /// (sqrt(1 + zeta^2) - zeta) times (docs/physics.md, "Bonds").
    static Real time_scale(const bond_params<Real>& p, Real r_i, Real r_j, Real m_i, Real m_j)
    {
        const bond_springs s = make(p, r_i, r_j, m_i, m_j);
        const Real m = effective_mass(m_i, m_j);
        const Real moment = effective_moment(r_i, r_j, m_i, m_j);
        const Real r = r_i > r_j ? r_i : r_j;
        const Real inf = std::numeric_limits<Real>::infinity();
        const auto scale = [&](Real inertia, Real k) { return k > 0 ? std::sqrt(inertia / k) : inf; };
        Real t = scale(m, s.k_n);
        const Real others[4] = {scale(m, s.k_t), scale(moment, s.k_b), scale(moment, s.k_w), scale(moment, s.k_t * r * r)};
        for (Real o : others) t = o < t ? o : t;
        return t * (std::sqrt(1 + p.damping * p.damping) - p.damping);
    }

    /// m* = m_i m_j / (m_i + m_j) (kg).
    SPHERE_HDI static Real effective_mass(Real m_i, Real m_j) { return m_i * m_j / (m_i + m_j); }

    /// I* = I_i I_j / (I_i + I_j) with I = 2/5 m r^2 (kg m^2).
    SPHERE_HDI static Real effective_moment(Real r_i, Real r_j, Real m_i, Real m_j)
    {
        const Real a = Real(0.4) * m_i * r_i * r_i, b = Real(0.4) * m_j * r_j * r_j;
        return a * b / (a + b);
    }
};

/// The bonds' time-step rule (docs/physics.md, "Time step"): dt = default_factor T unless the
/// user sets one, never above bound_factor T, T the smallest bond time scale.
struct bond_time_step {
    static constexpr double default_factor = 0.1;
    static constexpr double bound_factor = 0.5;
};

/// The same parameters in another precision.
template <class To, class From>
bond_params<To> params_cast(const bond_params<From>& p)
{
    return {To(p.radius_ratio), To(p.k_n), To(p.k_t), To(p.tensile_strength), To(p.shear_strength), To(p.damping)};
}

} // namespace sphere
