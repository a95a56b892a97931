#pragma once
/// \file
/// The time-step rule and the stable bound (docs/physics.md, "Time step").
#include <cmath>

#include "../contact/params.cuh"

namespace sphere {

/// Factor of sphere's rule dt = 0.075 sqrt(m_min / k_max): about 40 steps per pair contact.
template <class Real> inline constexpr Real time_step_factor = Real(0.075);

/// Factor of the largest time step the library accepts, dt <= 0.3 sqrt(m_min / k_max): about
/// 10 steps per pair contact. The symplectic integrator is stable for omega dt < 2; a particle
/// pressed by 12 neighbours of its own mass has omega = sqrt(12 k / m), so it stays stable up
/// to dt = 0.58 sqrt(m / k); 0.3 leaves room for damping and for lighter neighbours.
template <class Real> inline constexpr Real time_step_bound_factor = Real(0.3);

/// The largest stiffness in use (N/m).
template <class Real>
Real stiffest(const contact_params<Real>& pair, const contact_params<Real>& wall)
{
    using std::fmax;
    return fmax(fmax(pair.k_n, pair.k_t), fmax(wall.k_n, wall.k_t));
}

/// sphere's time step 0.075 sqrt(m_min / max(k_n, k_t)) (s).
template <class Real>
Real default_time_step(Real min_mass, const contact_params<Real>& pair, const contact_params<Real>& wall)
{
    return time_step_factor<Real> * std::sqrt(min_mass / stiffest(pair, wall));
}

/// The largest accepted time step, 0.3 sqrt(m_min / max(k_n, k_t)) (s).
template <class Real>
Real stable_time_step_bound(Real min_mass, const contact_params<Real>& pair, const contact_params<Real>& wall)
{
    return time_step_bound_factor<Real> * std::sqrt(min_mass / stiffest(pair, wall));
}

} // namespace sphere
