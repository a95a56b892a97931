#pragma once
/// \file
/// Horizontal layers of a settled sample: its lowest and highest points, and turning it into a
/// shear cell (sphere's shear()): a rough floor of fixed particles and a top layer driven
/// horizontally (motion::prescribed_horizontal). Host-side, on particle snapshots; give the
/// edited state back with simulation::restore:
///
///     auto st = sim.state();
///     sphere::make_shear_cell(st.particles, 2 * r_max, {0.05, 0, 0});
///     sim.restore(st);
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../analysis/shear.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../particles/particle.cuh"
#include "../particles/state.cuh"

namespace sphere {

/// Lowest point of any particle, min(z - r) (m).
template <class Real>
double sample_bottom(const particle_snapshot<Real>& s)
{
    if (s.size() == 0) detail::fail("sample_bottom: no particles");
    double low = double(s.x[0].z) - double(s.x[0].w);
    for (std::size_t i = 1; i < s.size(); ++i) low = std::fmin(low, double(s.x[i].z) - double(s.x[i].w));
    return low;
}

/// Highest point of any particle, max(z + r) (m).
template <class Real>
double sample_top(const particle_snapshot<Real>& s)
{
    if (s.size() == 0) detail::fail("sample_top: no particles");
    double high = double(s.x[0].z) + double(s.x[0].w);
    for (std::size_t i = 1; i < s.size(); ++i) high = std::fmax(high, double(s.x[i].z) + double(s.x[i].w));
    return high;
}

/// Makes a shear cell of a settled sample: every particle whose bottom (z - r) lies within
/// `thickness` (m) of sample_bottom becomes motion::fixed and stops; every other particle
/// whose top (z + r) lies within `thickness` of sample_top becomes
/// motion::prescribed_horizontal with velocity (velocity.x, velocity.y, 0) (m/s) and no
/// rotation. The rest keep their motion. Returns the two layers; throws when the thickness is
/// not positive and finite, the velocity is not finite or horizontal, or either layer is empty.
template <class Real>
shear_layers make_shear_cell(particle_snapshot<Real>& s, Real thickness, const vec3<Real>& velocity)
{
    if (!(thickness > 0) || !std::isfinite(thickness))
        detail::fail("make_shear_cell: layer thickness = ", thickness, " m must be positive and finite");
    if (!isfinite(velocity) || velocity.z != Real(0))
        detail::fail("make_shear_cell: velocity (", velocity.x, ", ", velocity.y, ", ", velocity.z,
                     ") m/s must be finite and horizontal");
    const double bottom = sample_bottom(s), top = sample_top(s);
    shear_layers layers;
    const vec3<Real> rest{0, 0, 0};
    for (std::size_t i = 0; i < s.size(); ++i) {
        const double z = double(s.x[i].z), r = double(s.x[i].w);
        motion kind;
        vec3<Real> v = rest;
        if (z - r < bottom + double(thickness)) {
            kind = motion::fixed;
            layers.bottom.push_back(i);
        } else if (z + r > top - double(thickness)) {
            kind = motion::prescribed_horizontal;
            v = velocity;
            layers.top.push_back(i);
        } else {
            continue;
        }
        s.kind[i] = static_cast<std::uint8_t>(kind);
        s.v[i] = s.v_sync[i] = v;
        s.omega[i] = s.omega_sync[i] = rest;
    }
    if (layers.top.empty() || layers.bottom.empty())
        detail::fail("make_shear_cell: ", layers.bottom.size(), " particles in the floor and ", layers.top.size(),
                     " in the top layer for a thickness of ", thickness, " m; both must be non-empty");
    return layers;
}

} // namespace sphere
