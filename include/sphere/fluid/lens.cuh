#pragma once
/// \file
/// The volume common to two spheres (docs/fluid.md, *Lens volume*): the porosity estimator's
/// solid volume of a particle inside a fluid cell's sphere.
#include "../core/config.cuh"
#include "../core/constants.cuh"

namespace sphere {

/// Volume of a sphere of radius r (m): 4/3 pi r^3 (m^3).
template <class Real>
SPHERE_HD Real sphere_volume(Real r)
{
    return Real(4) / Real(3) * pi<Real> * r * r * r;
}

/// Volume (m^3) of the intersection of a sphere of radius R (m) and one of radius r (m) whose
/// centres are d >= 0 (m) apart; symmetric in R and r:
///   - d >= R + r (apart or touching): 0;
///   - d <= |R - r| (one inside the other, either way round): the smaller sphere's volume;
///   - otherwise the lens of two caps,
///       V = pi (R + r - d)^2 (d^2 + 2 d (R + r) - 3 (R - r)^2) / (12 d),
///     evaluated as pi (R + r - d)^2 (d + 2 (R + r) - 3 (R - r)^2 / d) / 12, where
///     (R - r)^2 / d < |R - r| never blows up.
/// Continuous at both switches (docs/fluid.md). The seed's version returns the lens formula
/// for a cell sphere inside a particle (d <= r - R); here that case is the cell sphere's
/// volume (../shared/VALIDATION.md, pitfall 6). Radii must be non-negative.
template <class Real>
SPHERE_HD Real lens_volume(Real R, Real r, Real d)
{
    const Real sum = R + r;
    if (!(d < sum)) return Real(0);
    const Real diff = R - r;
    if (d <= (diff < 0 ? -diff : diff)) return sphere_volume(R < r ? R : r);
    const Real gap = sum - d;
    return pi<Real> * gap * gap * (d + Real(2) * sum - Real(3) * diff * diff / d) / Real(12);
}

} // namespace sphere
