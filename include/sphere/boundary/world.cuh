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

/// A boundary's name as written in C++ ("wall", "periodic").
inline const char* name(boundary b) { return b == boundary::periodic ? "periodic" : "wall"; }

template <class Real>
struct world {
    vec3<Real> lo{0, 0, 0}; ///< lower corner (m)
    vec3<Real> hi{1, 1, 1}; ///< upper corner (m)
    boundary axis[3] = {boundary::wall, boundary::wall, boundary::wall};

    SPHERE_HDI Real length(int a) const { return hi[a] - lo[a]; }
    /// Whether axis a is periodic (selects, not an index: see component() in core/vec.cuh).
    SPHERE_HDI bool periodic(int a) const
    {
        return (a == 0 ? axis[0] : (a == 1 ? axis[1] : axis[2])) == boundary::periodic;
    }

    /// The shortest image of a separation vector d (m): on periodic axes d - L round(d / L).
    SPHERE_HD vec3<Real> nearest_image(vec3<Real> d) const
    {
        for (int a = 0; a < 3; ++a)
            if (periodic(a)) d[a] -= length(a) * std::nearbyint(d[a] / length(a));
        return d;
    }

    /// The nearest image of the separation of two positions that both lie inside the box
    /// (wrapped): one conditional shift per periodic axis, no division. The same result as
    /// nearest_image for such separations (|d| < L), up to a tie at exactly L / 2. Written with
    /// selects only, so that it vectorises in a loop over pairs.
    SPHERE_HDI vec3<Real> nearest_image_inside(const vec3<Real>& d) const
    {
        return {shortest(d.x, hi.x - lo.x, periodic(0)), shortest(d.y, hi.y - lo.y, periodic(1)),
                shortest(d.z, hi.z - lo.z, periodic(2))};
    }

    /// d shifted by one period l towards zero when it is more than half a period away, on a
    /// periodic axis.
    SPHERE_HDI static Real shortest(Real d, Real l, bool periodic_axis)
    {
        const Real half = l / 2;
        const Real shifted = d > half ? d - l : (d < -half ? d + l : d);
        return periodic_axis ? shifted : d;
    }

    /// Maps a coordinate on a periodic axis into [lo, hi), however many periods away it is;
    /// unchanged on wall axes and when not finite. Written with selects only, so that it
    /// vectorises in a loop over particles.
    SPHERE_HDI Real wrap(Real c, int a) const
    {
        const Real l = length(a);
        const bool inside = c >= lo[a] && c < hi[a];
        const Real shifted = c - l * std::floor((c - lo[a]) / l);
        // round-off can land on hi or a hair below lo
        const Real back = shifted >= lo[a] && shifted < hi[a] ? shifted : lo[a];
        return periodic(a) && std::isfinite(c) && !inside ? back : c;
    }

    /// A position with wrap applied on every axis.
    SPHERE_HDI vec3<Real> wrap(const vec3<Real>& x) const { return {wrap(x.x, 0), wrap(x.y, 1), wrap(x.z, 2)}; }
};

} // namespace sphere
