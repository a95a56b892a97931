#pragma once
/// \file
/// Conversions between the coefficient of restitution e and the normal viscosity gamma_n of
/// the linear contact model, for a pair of effective mass m* (docs/physics.md, "Restitution").
///
/// With the damping ratio zeta = gamma_n / (2 sqrt(m* k_n)) and omega_0 = sqrt(k_n / m*):
/// - tension allowed: e = exp(-pi zeta / sqrt(1 - zeta^2)), t_c = pi / (omega_0 sqrt(1 - zeta^2));
/// - no tension (force clipped at 0, the default): Schwager & Poeschel (2007, Granular Matter
///   9:465), e = exp(-zeta / sqrt(1 - zeta^2) (pi - theta)) with
///   theta = atan2(2 zeta sqrt(1 - zeta^2), 1 - 2 zeta^2), t_c = (pi - theta) / (omega_0 sqrt(1 - zeta^2)).
/// Both are for under-damped contacts, 0 <= zeta < 1.
#include <cmath>
#include <limits>

#include "../core/constants.cuh"
#include "../core/error.cuh"

namespace sphere {

/// Effective mass of a pair, m_i m_j / (m_i + m_j) (kg). For a wall contact use the particle's mass.
template <class Real>
Real effective_mass(Real m_i, Real m_j)
{
    return m_i * m_j / (m_i + m_j);
}

namespace detail {
template <class Real>
void check_damping_ratio(Real zeta)
{
    if (!(zeta >= 0 && zeta < 1))
        fail("damping ratio zeta = ", zeta, ": the restitution relations hold for 0 <= zeta < 1");
}
template <class Real>
Real clipped_phase(Real zeta)
{
    const Real s = std::sqrt(1 - zeta * zeta);
    return pi<Real> - std::atan2(2 * zeta * s, 1 - 2 * zeta * zeta);
}
} // namespace detail

/// Coefficient of restitution of a linear contact with damping ratio zeta.
template <class Real>
Real restitution_from_damping_ratio(Real zeta, bool tension)
{
    detail::check_damping_ratio(zeta);
    const Real s = std::sqrt(1 - zeta * zeta);
    return std::exp(-zeta / s * (tension ? pi<Real> : detail::clipped_phase(zeta)));
}

/// Damping ratio that gives restitution e. Throws for e outside (0, 1] (tension) or
/// (exp(-2), 1] (no tension: lower values need an over-damped contact).
template <class Real>
Real damping_ratio_from_restitution(Real e, bool tension)
{
    if (!(e > 0 && e <= 1)) detail::fail("restitution coefficient e = ", e, ": must lie in (0, 1]");
    if (tension) {
        const Real l = std::log(e);
        return -l / std::sqrt(pi<Real> * pi<Real> + l * l);
    }
    if (!(e > std::exp(Real(-2))))
        detail::fail("restitution coefficient e = ", e, ": without tension e must exceed exp(-2) = 0.1353");
    Real lo = 0, hi = 1; // e(zeta) decreases monotonically on [0, 1)
    for (int it = 0; it < 200 && hi - lo > std::numeric_limits<Real>::epsilon(); ++it) {
        const Real mid = (lo + hi) / 2;
        if (restitution_from_damping_ratio(mid, false) > e) lo = mid;
        else hi = mid;
    }
    return (lo + hi) / 2;
}

/// Normal viscosity gamma_n (N s/m) giving restitution e for effective mass m_eff (kg) and
/// normal stiffness k_n (N/m).
template <class Real>
Real gamma_n_from_restitution(Real e, Real m_eff, Real k_n, bool tension = false)
{
    return 2 * damping_ratio_from_restitution(e, tension) * std::sqrt(m_eff * k_n);
}

/// Contact duration t_c (s) of a linear contact with damping ratio zeta.
template <class Real>
Real contact_duration(Real zeta, Real m_eff, Real k_n, bool tension = false)
{
    detail::check_damping_ratio(zeta);
    const Real omega_d = std::sqrt(k_n / m_eff) * std::sqrt(1 - zeta * zeta);
    return (tension ? pi<Real> : detail::clipped_phase(zeta)) / omega_d;
}

} // namespace sphere
