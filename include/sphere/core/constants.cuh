#pragma once
/// \file
/// Mathematical constants in the simulation's precision. (Not std::numeric_limits, whose
/// functions device code cannot call.)
#include <cfloat>
#include <cmath>

namespace sphere {

template <class Real> inline constexpr Real pi = static_cast<Real>(3.14159265358979323846264338327950288);

/// The largest finite value of Real (float or double).
template <class Real> inline constexpr Real largest = sizeof(Real) == sizeof(float) ? Real(FLT_MAX) : Real(DBL_MAX);

/// +infinity in Real.
template <class Real> inline constexpr Real infinity = sizeof(Real) == sizeof(float) ? Real(HUGE_VALF) : Real(HUGE_VAL);

/// Mass of a sphere of radius r (m) and density rho (kg/m^3): 4/3 pi r^3 rho (kg).
template <class Real> constexpr Real sphere_mass(Real r, Real rho)
{
    return Real(4) / Real(3) * pi<Real> * r * r * r * rho;
}

} // namespace sphere
