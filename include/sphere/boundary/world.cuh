#pragma once
/// \file
/// The world box: an axis-aligned box whose every axis is either periodic or closed by two
/// planar walls (the faces of the box).
#include <cmath>
#include <cstdint>

#include "../core/vec.cuh"

namespace sphere {

/// What closes the world box along one axis.
enum class boundary : std::uint8_t {
    wall = 0,     ///< planar walls at lo and hi, with the wall contact parameters
    periodic = 1, ///< a particle leaving at hi re-enters at lo; contacts see the nearest image
};

template <class Real>
struct world {
    vec3<Real> lo{0, 0, 0}; ///< lower corner (m)
    vec3<Real> hi{1, 1, 1}; ///< upper corner (m)
    boundary axis[3] = {boundary::wall, boundary::wall, boundary::wall};

    SPHERE_HD Real length(int a) const { return hi[a] - lo[a]; }
    SPHERE_HD bool periodic(int a) const { return axis[a] == boundary::periodic; }

    /// The shortest image of a separation vector d (m): on periodic axes d - L round(d / L).
    SPHERE_HD vec3<Real> nearest_image(vec3<Real> d) const
    {
        for (int a = 0; a < 3; ++a)
            if (periodic(a)) d[a] -= length(a) * std::nearbyint(d[a] / length(a));
        return d;
    }

    /// Maps a coordinate on a periodic axis into [lo, hi), however many periods away it is;
    /// unchanged on wall axes.
    SPHERE_HD Real wrap(Real c, int a) const
    {
        if (!periodic(a) || !std::isfinite(c) || (c >= lo[a] && c < hi[a])) return c;
        c -= length(a) * std::floor((c - lo[a]) / length(a));
        return c >= lo[a] && c < hi[a] ? c : lo[a]; // round-off can land on hi or a hair below lo
    }
};

} // namespace sphere
