#pragma once
/// \file
/// Mathematical constants in the simulation's precision.

namespace sphere {

template <class Real> inline constexpr Real pi = static_cast<Real>(3.14159265358979323846264338327950288);

/// Mass of a sphere of radius r (m) and density rho (kg/m^3): 4/3 pi r^3 rho (kg).
template <class Real> constexpr Real sphere_mass(Real r, Real rho)
{
    return Real(4) / Real(3) * pi<Real> * r * r * r * rho;
}

} // namespace sphere
